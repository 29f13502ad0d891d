!> Geometry of one background cell of a meshfree part: the trilinear map of the 8-node
!> hexahedron, its FE functions and their gradients, exact sub-cell volumes and the
!> characteristic length, and the Gauss-Legendre rules of the Gauss variants (formulation
!> sections 3 and 4).
!>
!> Vertices are in LS-DYNA order (nodes 1-4 the bottom face counterclockwise seen from the
!> top, 5-8 above them); `vertex_parametric(:, a)` are the parametric coordinates (s, t, u) of
!> vertex a. Sub-cell g is the octant of the parametric cube that holds vertex g.
module efg_cell_geometry
  use kinds, only: wp
  implicit none
  private

  public :: trilinear_functions, trilinear_natural_derivatives, cell_jacobian
  public :: determinant_3, inverse_3, subcell_volumes, largest_face_area, mean_edge_length
  public :: gauss_legendre, cell_gauss_rule

  !> Parametric coordinates (s, t, u) of the eight vertices.
  real(wp), parameter, public :: vertex_parametric(3, 8) = reshape([ &
                                  -1.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp, &
                                  -1.0_wp, 1.0_wp, -1.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp, 1.0_wp, &
                                  1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp], [3, 8])

  !> The six faces, four vertices each in order around the face (outward normal by the
  !> right-hand rule for a positively oriented cell).
  integer, parameter, public :: cell_faces(4, 6) = reshape([1, 4, 3, 2, 5, 6, 7, 8, 1, 2, 6, 5, &
                                                            2, 3, 7, 6, 3, 4, 8, 7, 4, 1, 5, 8], [4, 6])

  !> The twelve edges as vertex pairs.
  integer, parameter :: cell_edges(2, 12) = reshape([1, 2, 2, 3, 3, 4, 4, 1, 5, 6, 6, 7, 7, 8, 8, 5, &
                                                     1, 5, 2, 6, 3, 7, 4, 8], [2, 12])

  !> 2-point Gauss abscissa on [-1, 1].
  real(wp), parameter, public :: gauss_abscissa = 0.57735026918962576450914878050196_wp

contains

  !> The n-point Gauss-Legendre rule on [-1, 1] (exact for polynomials of degree 2n - 1):
  !> abscissae ascending, the roots of the Legendre polynomial P_n found by Newton's method from
  !> the estimates cos(pi (i - 1/4) / (n + 1/2)), weights 2 / ((1 - x^2) P_n'(x)^2).
  pure subroutine gauss_legendre(order, abscissae, weights)
    integer, intent(in) :: order
    real(wp), intent(out) :: abscissae(order), weights(order)
    real(wp), parameter :: pi = 3.14159265358979323846264338327950_wp
    real(wp) :: root, previous, current, older, derivative, step
    integer :: i, j, iteration

    do i = 1, (order + 1)/2
      root = cos(pi*(real(i, wp) - 0.25_wp)/(real(order, wp) + 0.5_wp))
      do iteration = 1, 100
        ! P_n(root) by the three-term recurrence, P_n' from P_n and P_(n-1)
        current = 1.0_wp
        previous = 0.0_wp
        do j = 1, order
          older = previous
          previous = current
          current = (real(2*j - 1, wp)*root*previous - real(j - 1, wp)*older)/real(j, wp)
        end do
        derivative = real(order, wp)*(root*current - previous)/(root*root - 1.0_wp)
        step = current/derivative
        root = root - step
        if (abs(step) <= 4.0_wp*epsilon(1.0_wp)) exit
      end do
      ! one more recurrence at the converged root for the weight
      current = 1.0_wp
      previous = 0.0_wp
      do j = 1, order
        older = previous
        previous = current
        current = (real(2*j - 1, wp)*root*previous - real(j - 1, wp)*older)/real(j, wp)
      end do
      derivative = real(order, wp)*(root*current - previous)/(root*root - 1.0_wp)
      abscissae(i) = -root
      abscissae(order + 1 - i) = root
      weights(i) = 2.0_wp/((1.0_wp - root*root)*derivative*derivative)
      weights(order + 1 - i) = weights(i)
    end do
    if (modulo(order, 2) == 1) abscissae((order + 1)/2) = 0.0_wp
  end subroutine gauss_legendre

  !> The order x order x order Gauss points of a cell in its parametric space, with their
  !> weights (they add up to 8, the parametric volume; W_g = weight * det J). Order 2 lists point
  !> g next to vertex g with weights 1 (the IDIM 2 variant, unchanged); other orders list the
  !> tensor product with s running fastest, then t, then u (order 4: the 64 points of the
  !> conventional EFG variant, IDIM 4). det J of a trilinear map has degree 2 in each parametric
  !> coordinate, so every order from 2 on integrates the cell volume exactly.
  pure subroutine cell_gauss_rule(order, parametric, weights)
    integer, intent(in) :: order
    real(wp), intent(out) :: parametric(3, order**3), weights(order**3)
    real(wp) :: abscissae(order), line_weights(order)
    integer :: g, i, j, k

    if (order == 2) then
      do g = 1, 8
        parametric(:, g) = gauss_abscissa*vertex_parametric(:, g)
      end do
      weights = 1.0_wp
      return
    end if
    call gauss_legendre(order, abscissae, line_weights)
    g = 0
    do k = 1, order
      do j = 1, order
        do i = 1, order
          g = g + 1
          parametric(:, g) = [abscissae(i), abscissae(j), abscissae(k)]
          weights(g) = line_weights(i)*line_weights(j)*line_weights(k)
        end do
      end do
    end do
  end subroutine cell_gauss_rule

  !> Trilinear FE functions Phi_a = (1 + s s_a)(1 + t t_a)(1 + u u_a) / 8. On a face
  !> (a coordinate exactly +-1) the functions of the vertices off that face are exactly zero,
  !> which is what makes the interface constraint (eq. 8) hold exactly.
  pure subroutine trilinear_functions(parametric, values)
    real(wp), intent(in) :: parametric(3)
    real(wp), intent(out) :: values(8)
    integer :: a

    do a = 1, 8
      values(a) = 0.125_wp*(1.0_wp + parametric(1)*vertex_parametric(1, a)) &
                  *(1.0_wp + parametric(2)*vertex_parametric(2, a)) &
                  *(1.0_wp + parametric(3)*vertex_parametric(3, a))
    end do
  end subroutine trilinear_functions

  !> Derivatives dPhi_a / d(s, t, u), as (3, 8).
  pure subroutine trilinear_natural_derivatives(parametric, derivatives)
    real(wp), intent(in) :: parametric(3)
    real(wp), intent(out) :: derivatives(3, 8)
    real(wp) :: factor(3)
    integer :: a

    do a = 1, 8
      factor = 1.0_wp + parametric*vertex_parametric(:, a)
      derivatives(1, a) = 0.125_wp*vertex_parametric(1, a)*factor(2)*factor(3)
      derivatives(2, a) = 0.125_wp*factor(1)*vertex_parametric(2, a)*factor(3)
      derivatives(3, a) = 0.125_wp*factor(1)*factor(2)*vertex_parametric(3, a)
    end do
  end subroutine trilinear_natural_derivatives

  !> Jacobian J(i, a) = dX_i / ds_a of the trilinear map.
  pure function cell_jacobian(vertices, parametric) result(jacobian)
    real(wp), intent(in) :: vertices(3, 8), parametric(3)
    real(wp) :: jacobian(3, 3)
    real(wp) :: derivatives(3, 8)

    call trilinear_natural_derivatives(parametric, derivatives)
    jacobian = matmul(vertices, transpose(derivatives))
  end function cell_jacobian

  !> Determinant of a 3x3 matrix (det J: the volume density of the trilinear map).
  pure function determinant_3(matrix) result(determinant)
    real(wp), intent(in) :: matrix(3, 3)
    real(wp) :: determinant
    determinant = matrix(1, 1)*(matrix(2, 2)*matrix(3, 3) - matrix(2, 3)*matrix(3, 2)) &
                  - matrix(1, 2)*(matrix(2, 1)*matrix(3, 3) - matrix(2, 3)*matrix(3, 1)) &
                  + matrix(1, 3)*(matrix(2, 1)*matrix(3, 2) - matrix(2, 2)*matrix(3, 1))
  end function determinant_3

  !> Inverse of a 3x3 matrix by cofactors (the caller checks the determinant).
  pure function inverse_3(matrix) result(inverse)
    real(wp), intent(in) :: matrix(3, 3)
    real(wp) :: inverse(3, 3)
    inverse(1, 1) = matrix(2, 2)*matrix(3, 3) - matrix(2, 3)*matrix(3, 2)
    inverse(1, 2) = matrix(1, 3)*matrix(3, 2) - matrix(1, 2)*matrix(3, 3)
    inverse(1, 3) = matrix(1, 2)*matrix(2, 3) - matrix(1, 3)*matrix(2, 2)
    inverse(2, 1) = matrix(2, 3)*matrix(3, 1) - matrix(2, 1)*matrix(3, 3)
    inverse(2, 2) = matrix(1, 1)*matrix(3, 3) - matrix(1, 3)*matrix(3, 1)
    inverse(2, 3) = matrix(1, 3)*matrix(2, 1) - matrix(1, 1)*matrix(2, 3)
    inverse(3, 1) = matrix(2, 1)*matrix(3, 2) - matrix(2, 2)*matrix(3, 1)
    inverse(3, 2) = matrix(1, 2)*matrix(3, 1) - matrix(1, 1)*matrix(3, 2)
    inverse(3, 3) = matrix(1, 1)*matrix(2, 2) - matrix(1, 2)*matrix(2, 1)
    inverse = inverse/determinant_3(matrix)
  end function inverse_3

  !> Exact reference volumes W_g of the eight sub-cells (octants of the parametric cube, sub-cell
  !> g holding vertex g): det J of a trilinear map has degree at most 2 in each parametric
  !> coordinate, so 2x2x2 Gauss points per octant integrate it exactly (formulation section 4:
  !> V_cell / 8 or a one-point det J are wrong on distorted cells).
  pure function subcell_volumes(vertices) result(volumes)
    real(wp), intent(in) :: vertices(3, 8)
    real(wp) :: volumes(8)
    real(wp) :: centre(3), offset(3)
    integer :: g, q

    do g = 1, 8
      centre = 0.5_wp*vertex_parametric(:, g)
      volumes(g) = 0.0_wp
      do q = 1, 8
        ! octant of side 1: Gauss points at centre +- 1/(2 sqrt 3), weights 1/8
        offset = 0.5_wp*gauss_abscissa*vertex_parametric(:, q)
        volumes(g) = volumes(g) + 0.125_wp*determinant_3(cell_jacobian(vertices, centre + offset))
      end do
    end do
  end function subcell_volumes

  !> Largest face area, each face as half the cross product of its diagonals (the rule of the
  !> FE solids, so that L = V / A_max gives the same time step as a hexahedron).
  pure function largest_face_area(vertices) result(area)
    real(wp), intent(in) :: vertices(3, 8)
    real(wp) :: area
    real(wp) :: first(3), second(3), normal(3)
    integer :: face

    area = 0.0_wp
    do face = 1, 6
      first = vertices(:, cell_faces(3, face)) - vertices(:, cell_faces(1, face))
      second = vertices(:, cell_faces(4, face)) - vertices(:, cell_faces(2, face))
      normal = [first(2)*second(3) - first(3)*second(2), first(3)*second(1) - first(1)*second(3), &
                first(1)*second(2) - first(2)*second(1)]
      area = max(area, 0.5_wp*norm2(normal))
    end do
  end function largest_face_area

  !> Mean length of the twelve edges: the scale h of the shifted basis coordinates
  !> xi = (X_I - X) / h (conditioning only; formulation section 2).
  pure function mean_edge_length(vertices) result(length)
    real(wp), intent(in) :: vertices(3, 8)
    real(wp) :: length
    integer :: edge

    length = 0.0_wp
    do edge = 1, 12
      length = length + norm2(vertices(:, cell_edges(2, edge)) - vertices(:, cell_edges(1, edge)))
    end do
    length = length/12.0_wp
  end function mean_edge_length
end module efg_cell_geometry
