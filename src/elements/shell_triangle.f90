!> Transverse shear of the triangular shell (a shell with N4 = N3, shell_block).
!>
!> Membrane and bending of the triangle are those of the one-point quadrilateral collapsed at
!> corner 3, which are exactly the constant-strain triangle's (the gradients of corners 3 and 4
!> add up to the triangle's). Its transverse shear cannot be taken the same way: with the
!> deflection's gradient and the rotations at the centroid (2 d_xz = B1 v_z + w_y / 3 ...), a
!> constant curvature with zero shear (w quadratic, the rotations linear) gives the triangle
!> a shear strain, and a strip of triangles bent by an end load came out at 46% of the beam's
!> deflection (shear locking). Here, as in the edge-based triangles (Belytschko, Stolarski &
!> Carpenter 1984 project the shear on the same idea; MITC3, DSG3), the shear along each edge
!> is taken at the edge's middle, where the secant slope of the nodal deflections and the mean of
!> the end rotations are exact for such a state:
!>   gamma_k = (v_z,j - v_z,i) / L_k + t_k . (w_y, -w_x) at the mid-edge,
!> t_k the edge's unit tangent (local axes), and the constant shear (2 d_xz, 2 d_yz) is the
!> least-squares fit to the three edge values: gamma = A^-1 sum_k t_k gamma_k, A = sum_k t_k t_k^T.
!> It is exact for every constant shear (linear v_z, constant rotations: the patch test) and
!> zero for every constant curvature without shear.
module shell_triangle
  use kinds, only: wp
  implicit none
  private

  public :: triangle_shear_operator, triangle_edge_fit

contains

  !> The shear operator of a triangle with local corner coordinates xl(1:3), yl(1:3): for shear
  !> component a (1: 2 d_xz, 2: 2 d_yz), gamma_a = sum_c vz_weight(c, a) v_z,c +
  !> wx_weight(c, a) w_x,c + wy_weight(c, a) w_y,c (local velocities and angular velocities).
  pure subroutine triangle_shear_operator(xl, yl, vz_weight, wx_weight, wy_weight)
    ! (assumed shape: callers pass a lane's row of the block arrays without copying it)
    real(wp), intent(in) :: xl(:), yl(:)
    real(wp), intent(out) :: vz_weight(3, 2), wx_weight(3, 2), wy_weight(3, 2)
    real(wp) :: tangent(2, 3), length(3), fit(2, 3)
    integer :: edge, first, second
    call triangle_edge_fit(xl, yl, tangent, length, fit)
    vz_weight = 0.0_wp
    wx_weight = 0.0_wp
    wy_weight = 0.0_wp
    do edge = 1, 3
      first = edge
      second = modulo(edge, 3) + 1
      vz_weight(first, :) = vz_weight(first, :) - fit(:, edge)/length(edge)
      vz_weight(second, :) = vz_weight(second, :) + fit(:, edge)/length(edge)
      wy_weight(first, :) = wy_weight(first, :) + 0.5_wp*tangent(1, edge)*fit(:, edge)
      wy_weight(second, :) = wy_weight(second, :) + 0.5_wp*tangent(1, edge)*fit(:, edge)
      wx_weight(first, :) = wx_weight(first, :) - 0.5_wp*tangent(2, edge)*fit(:, edge)
      wx_weight(second, :) = wx_weight(second, :) - 0.5_wp*tangent(2, edge)*fit(:, edge)
    end do
  end subroutine triangle_shear_operator

  !> The edges of a triangle (edge k from corner k to the next): unit tangents, lengths, and
  !> fit(:, k) = A^-1 t_k, what edge k's shear strain adds to the least-squares constant shear.
  pure subroutine triangle_edge_fit(xl, yl, tangent, length, fit)
    real(wp), intent(in) :: xl(:), yl(:)
    real(wp), intent(out) :: tangent(2, 3), length(3), fit(2, 3)
    real(wp) :: a11, a22, a12, determinant
    integer :: edge, first, second
    do edge = 1, 3
      first = edge
      second = modulo(edge, 3) + 1
      tangent(:, edge) = [xl(second) - xl(first), yl(second) - yl(first)]
      length(edge) = max(norm2(tangent(:, edge)), tiny(1.0_wp))
      tangent(:, edge) = tangent(:, edge)/length(edge)
    end do
    a11 = sum(tangent(1, :)**2)
    a22 = sum(tangent(2, :)**2)
    a12 = sum(tangent(1, :)*tangent(2, :))
    ! three edge directions of a triangle with area span the plane: A is positive definite (a
    ! flat triangle is reported by the caller; it keeps finite weights)
    determinant = max(a11*a22 - a12*a12, tiny(1.0_wp))
    do edge = 1, 3
      fit(1, edge) = (a22*tangent(1, edge) - a12*tangent(2, edge))/determinant
      fit(2, edge) = (a11*tangent(2, edge) - a12*tangent(1, edge))/determinant
    end do
  end subroutine triangle_edge_fit
end module shell_triangle
