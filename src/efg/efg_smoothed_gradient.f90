!> Smoothed gradients of the coupled shape functions at the integration points of one
!> background cell: the modified SCNI of formulation section 4 (Wang et al. 2009, eqs. 21,
!> 26-27), and the Gauss variants kept for comparison (Table 1; IDIM 2 and 4).
!>
!> Modified SCNI (IDIM 1): the cell is split in its parametric space into 8 sub-cells (sub-cell
!> g is the octant holding vertex g, one per 2-point Gauss point). For sub-cell g of exact
!> reference volume W_g,
!>   bbar_I(g) = (1/W_g) sum_faces sum_q Psi_I(X_q) n(X_q) dA_q,
!> a boundary integral of shape-function values only. Each sub-cell face is a quarter of one of
!> the nine parametric planes s, t, u = -1, 0, +1, mapped through the cell's trilinear map with
!> n dA = dX/da x dX/db da db, (a, b) the two other parametric directions in cyclic order; 2x2
!> Gauss points per quarter (2x2 is needed for linear consistency, 1x1 is not enough). A face
!> between two sub-cells of the cell is evaluated once and enters both with opposite signs; a
!> face between two cells has the same physical points and weights from either side (the 2x2
!> quarter points are symmetric under every re-parametrization of the face), so the sums
!> telescope: sum_g bbar_I(g) W_g = integral of Psi_I n over the part's outer boundary, which is
!> zero for interior particles because Psi_I vanishes there (the integration constraints,
!> eqs. 19/27 and 23-24).
!>
!> Gauss variants: the n x n x n Gauss-Legendre points of the cell in its parametric space,
!> W_g = weight_g det J(g), and the direct gradients of the shape functions (not smoothed). IDIM 2:
!> 2x2x2 points (unit weights); IDIM 4 (a crashfree extension for the verification of Table 1 of
!> the paper): 4x4x4 points, with IEBT 1 the conventional EFG of the paper's method (a). Neither
!> satisfies the integration constraint; 4x4x4 points only make its error smaller.
module efg_smoothed_gradient
  use kinds, only: wp
  use efg_cell_geometry, only: vertex_parametric, gauss_abscissa, cell_jacobian, determinant_3, cell_gauss_rule
  use efg_shape_functions, only: cell_shape_context_t, evaluate_shape_functions
  implicit none
  private

  public :: cell_smoothed_gradients, cell_gauss_gradients

contains

  !> Modified SCNI gradients bbar (3, local node, sub-cell) of the context's cell, given the
  !> exact sub-cell volumes. `singular_points` counts the face points whose moment matrix was
  !> rank-deficient; `worst_residual` is the largest |M alpha - b| met.
  subroutine cell_smoothed_gradients(context, subcell_volume, gradients, singular_points, worst_residual)
    type(cell_shape_context_t), intent(in) :: context
    real(wp), intent(in) :: subcell_volume(8)
    real(wp), intent(out) :: gradients(:, :, :)
    integer, intent(inout) :: singular_points
    real(wp), intent(inout) :: worst_residual
    real(wp) :: values(context%node_count), parametric(3), point(3), jacobian(3, 3), area_vector(3)
    real(wp) :: residual, plane
    integer :: direction, first, second, plane_index, quarter_first, quarter_second, point_first
    integer :: point_second, negative_subcell, positive_subcell, rank, k, n

    n = context%node_count
    gradients(:, 1:n, 1:8) = 0.0_wp
    do direction = 1, 3
      first = modulo(direction, 3) + 1
      second = modulo(direction + 1, 3) + 1
      do plane_index = -1, 1
        plane = real(plane_index, wp)
        do quarter_second = -1, 1, 2
          do quarter_first = -1, 1, 2
            ! the sub-cells on either side of this quarter of the plane
            negative_subcell = subcell_of(direction, -1, first, quarter_first, second, quarter_second)
            positive_subcell = subcell_of(direction, 1, first, quarter_first, second, quarter_second)
            do point_second = -1, 1, 2
              do point_first = -1, 1, 2
                ! quarter [0, 1]^2 (up to sign): Gauss points at 1/2 +- 1/(2 sqrt 3), weights 1/4
                parametric(direction) = plane
                parametric(first) = 0.5_wp*(real(quarter_first, wp) + gauss_abscissa*real(point_first, wp))
                parametric(second) = 0.5_wp*(real(quarter_second, wp) + gauss_abscissa*real(point_second, wp))
                call evaluate_shape_functions(context, parametric, point, values, rank, residual)
                if (rank > 0 .and. rank < 4) singular_points = singular_points + 1
                worst_residual = max(worst_residual, residual)
                jacobian = cell_jacobian(context%vertices, parametric)
                ! n dA along +direction for a positively oriented cell
                area_vector = 0.25_wp*cross(jacobian(:, first), jacobian(:, second))
                ! the sub-cell below a plane (octant [-1, 0] in `direction`) has it as its
                ! outward +direction face, the one above as its outward -direction face; on the
                ! planes -1 and +1 only one of them exists
                do k = 1, n
                  if (values(k) == 0.0_wp) cycle
                  select case (plane_index)
                  case (-1)
                    gradients(:, k, negative_subcell) = gradients(:, k, negative_subcell) - values(k)*area_vector
                  case (0)
                    gradients(:, k, negative_subcell) = gradients(:, k, negative_subcell) + values(k)*area_vector
                    gradients(:, k, positive_subcell) = gradients(:, k, positive_subcell) - values(k)*area_vector
                  case default
                    gradients(:, k, positive_subcell) = gradients(:, k, positive_subcell) + values(k)*area_vector
                  end select
                end do
              end do
            end do
          end do
        end do
      end do
    end do
    do k = 1, 8
      gradients(:, 1:n, k) = gradients(:, 1:n, k)/subcell_volume(k)
    end do
  contains
    !> The octant with sign `side_direction` in `direction` (-1: parametric [-1, 0], +1: [0, 1])
    !> and the quarter's signs in the other two directions.
    integer function subcell_of(direction, side_direction, first, sign_first, second, sign_second)
      integer, intent(in) :: direction, side_direction, first, sign_first, second, sign_second
      real(wp) :: signs(3)
      integer :: g

      signs(direction) = real(side_direction, wp)
      signs(first) = real(sign_first, wp)
      signs(second) = real(sign_second, wp)
      subcell_of = 0
      do g = 1, 8
        if (all(vertex_parametric(:, g) == signs)) subcell_of = g
      end do
    end function subcell_of
  end subroutine cell_smoothed_gradients

  !> Gauss variants: direct gradients of the shape functions (3, local node, point) at the
  !> order**3 Gauss points of the cell (efg_cell_geometry's cell_gauss_rule: order 2 puts point g
  !> next to vertex g, other orders run s fastest) and their weights W_g = weight_g det J(g).
  subroutine cell_gauss_gradients(context, order, gradients, point_volume, singular_points, worst_residual)
    type(cell_shape_context_t), intent(in) :: context
    integer, intent(in) :: order
    real(wp), intent(out) :: gradients(:, :, :)
    real(wp), intent(out) :: point_volume(:)
    integer, intent(inout) :: singular_points
    real(wp), intent(inout) :: worst_residual
    real(wp) :: values(context%node_count), parametric(3, order**3), weights(order**3), point(3), residual
    integer :: g, rank

    call cell_gauss_rule(order, parametric, weights)
    do g = 1, order**3
      call evaluate_shape_functions(context, parametric(:, g), point, values, rank, residual, gradients(:, :, g))
      if (rank > 0 .and. rank < 4) singular_points = singular_points + 1
      worst_residual = max(worst_residual, residual)
      point_volume(g) = weights(g)*determinant_3(cell_jacobian(context%vertices, parametric(:, g)))
    end do
  end subroutine cell_gauss_gradients

  pure function cross(a, b) result(c)
    real(wp), intent(in) :: a(3), b(3)
    real(wp) :: c(3)
    c = [a(2)*b(3) - a(3)*b(2), a(3)*b(1) - a(1)*b(3), a(1)*b(2) - a(2)*b(1)]
  end function cross
end module efg_smoothed_gradient
