!> Shape quality of a hexahedron: its corner Jacobians, the triple products of the three edges
!> that meet at each corner. They turn negative when the element is folded inside out at a
!> corner, which the one-point volume of a tangled element does not show (LS-DYNA reports such
!> elements only once a volume turns negative).
module hex8_quality
  use kinds, only: wp
  implicit none
  private

  public :: corner_jacobian_ratio

  !> For each corner, its three neighbours along the edges, in the order that gives a positive
  !> triple product for a properly numbered element (corners 1-4 one face, 5-8 the other).
  integer, parameter :: corner_edges(3, 8) = reshape([2, 4, 5, 3, 1, 6, 4, 2, 7, 1, 3, 8, &
                                                      8, 6, 1, 5, 7, 2, 6, 8, 3, 7, 5, 4], [3, 8])

contains

  !> Smallest corner Jacobian over the largest in magnitude: 1 for a parallelepiped, below 0
  !> once a corner is inverted, 0 for an element collapsed to nothing. A corner with a
  !> zero edge (a repeated node: a wedge, pyramid or tetrahedron given as a hexahedron) has a
  !> zero Jacobian by construction and is left out; the other corners of such an element are
  !> the corners of its own shape.
  pure real(wp) function corner_jacobian_ratio(corners) result(ratio)
    real(wp), intent(in) :: corners(3, 8)
    real(wp) :: a(3), b(3), c(3), jacobian, smallest, largest
    integer :: k
    smallest = huge(1.0_wp)
    largest = 0.0_wp
    do k = 1, 8
      a = corners(:, corner_edges(1, k)) - corners(:, k)
      b = corners(:, corner_edges(2, k)) - corners(:, k)
      c = corners(:, corner_edges(3, k)) - corners(:, k)
      if (all(a == 0.0_wp) .or. all(b == 0.0_wp) .or. all(c == 0.0_wp)) cycle
      jacobian = (a(2)*b(3) - a(3)*b(2))*c(1) + (a(3)*b(1) - a(1)*b(3))*c(2) + (a(1)*b(2) - a(2)*b(1))*c(3)
      smallest = min(smallest, jacobian)
      largest = max(largest, abs(jacobian))
    end do
    ratio = 0.0_wp
    if (largest > 0.0_wp) ratio = smallest/largest
  end function corner_jacobian_ratio
end module hex8_quality
