!> Shape check of a hexahedron in the reference configuration: the 8 corner Jacobians and the
!> volume. An element numbered inside out (mirrored node order) gives negative corner
!> Jacobians; a degenerate shape (wedge, tetrahedron written as a hexahedron) has collapsed
!> corners with zero Jacobian, which is fine as long as the volume is positive.
module deck_element_check
  use kinds, only: wp
  use hex8_geometry, only: tetrahedron_corner_order
  use deck_input, only: deck_input_t
  implicit none
  private

  public :: check_hexahedron, order_tetrahedra

  !> Results of `check_hexahedron`.
  integer, parameter, public :: shape_valid = 0, shape_inside_out = 1, shape_flat = 2

  ! Node k sits at (xi, eta, zeta) = (xi_sign(k), eta_sign(k), zeta_sign(k)); its neighbour
  ! along each direction is the node with that sign flipped.
  integer, parameter :: xi_sign(8) = [-1, 1, 1, -1, -1, 1, 1, -1]
  integer, parameter :: eta_sign(8) = [-1, -1, 1, 1, -1, -1, 1, 1]
  integer, parameter :: zeta_sign(8) = [-1, -1, -1, -1, 1, 1, 1, 1]
  integer, parameter :: xi_neighbour(8) = [2, 1, 4, 3, 6, 5, 8, 7]
  integer, parameter :: eta_neighbour(8) = [4, 3, 2, 1, 8, 7, 6, 5]
  integer, parameter :: zeta_neighbour(8) = [5, 6, 7, 8, 1, 2, 3, 4]

contains

  !> Check the hexahedron with corner coordinates `x(3, 8)`. `status` is shape_valid,
  !> shape_inside_out (`corner` = the corner with the most negative Jacobian) or shape_flat
  !> (a collapsed corner and no positive volume). A tetrahedron (four distinct corners) is
  !> checked in the form the elements use, N1 N2 N3 N3 N4 N4 N4 N4 with a positive volume
  !> (tetrahedron_corner_order): it is flat or valid, never inside out.
  pure subroutine check_hexahedron(corners, status, corner)
    real(wp), intent(in) :: corners(3, 8)
    integer, intent(out) :: status, corner
    real(wp) :: x(3, 8), tolerance, lowest, jacobian, extent, volume
    integer :: k, l, same(8), order(8)

    ! corners at one place stand for one node
    do k = 1, 8
      same(k) = findloc([(all(corners(:, l) == corners(:, k)), l=1, 8)], .true., dim=1)
    end do
    call tetrahedron_corner_order(same, corners, order)
    ! Work relative to node 1 and in units of the element's size: the tolerances are then
    ! plain numbers and no product can overflow, whatever the units of the deck.
    do k = 1, 8
      x(:, k) = corners(:, order(k)) - corners(:, order(1))
    end do
    extent = maxval(abs(x))
    status = shape_flat
    corner = 1
    if (extent == 0.0_wp) return
    x = x/extent
    tolerance = 1.0e-10_wp
    status = shape_valid
    corner = 0
    lowest = huge(1.0_wp)
    do k = 1, 8
      jacobian = triple_product(xi_sign(k)*(x(:, k) - x(:, xi_neighbour(k))), &
                                eta_sign(k)*(x(:, k) - x(:, eta_neighbour(k))), &
                                zeta_sign(k)*(x(:, k) - x(:, zeta_neighbour(k))))
      if (jacobian < lowest) then
        lowest = jacobian
        corner = k
      end if
    end do
    if (lowest < -tolerance) then
      status = shape_inside_out
    else if (lowest <= tolerance) then
      ! a collapsed corner: acceptable only when the element still has a volume
      volume = gauss_volume(x)
      if (volume <= tolerance) status = shape_flat
    end if
  end subroutine check_hexahedron

  !> Put every tetrahedron of the deck (4 distinct nodes among the 8) in the form N1 N2 N3 N3
  !> N4 N4 N4 N4 with a positive volume (tetrahedron_corner_order), whichever of LS-DYNA's two
  !> forms the deck used: the elements, the static analysis, contact and the output then all
  !> see the tetrahedron itself. Needs resolved node indices.
  subroutine order_tetrahedra(input)
    type(deck_input_t), intent(inout) :: input
    integer :: element, order(8)
    associate (model => input%model)
      do element = 1, input%solid_count
        call tetrahedron_corner_order(model%solid_nodes(:, element), &
                                      model%coordinates(:, model%solid_nodes(:, element)), order)
        model%solid_nodes(:, element) = model%solid_nodes(order, element)
      end do
    end associate
  end subroutine order_tetrahedra

  !> Volume of the trilinear hexahedron: det J summed over the 2x2x2 Gauss points (exact,
  !> since det J is at most quadratic in each coordinate).
  pure real(wp) function gauss_volume(x)
    real(wp), intent(in) :: x(3, 8)
    real(wp), parameter :: g = 0.577350269189625764509148780502_wp   ! 1/sqrt(3)
    real(wp) :: point(3), derivative(3, 8), jacobian(3, 3)
    integer :: i, j, l, k
    gauss_volume = 0.0_wp
    do i = -1, 1, 2
      do j = -1, 1, 2
        do l = -1, 1, 2
          point = g*[real(i, wp), real(j, wp), real(l, wp)]
          do k = 1, 8
            derivative(1, k) = xi_sign(k)*(1.0_wp + eta_sign(k)*point(2))* &
                               (1.0_wp + zeta_sign(k)*point(3))/8.0_wp
            derivative(2, k) = eta_sign(k)*(1.0_wp + xi_sign(k)*point(1))* &
                               (1.0_wp + zeta_sign(k)*point(3))/8.0_wp
            derivative(3, k) = zeta_sign(k)*(1.0_wp + xi_sign(k)*point(1))* &
                               (1.0_wp + eta_sign(k)*point(2))/8.0_wp
          end do
          jacobian = matmul(x, transpose(derivative))
          gauss_volume = gauss_volume + triple_product(jacobian(:, 1), jacobian(:, 2), &
                                                       jacobian(:, 3))
        end do
      end do
    end do
  end function gauss_volume

  pure real(wp) function triple_product(a, b, c)
    real(wp), intent(in) :: a(3), b(3), c(3)
    triple_product = a(1)*(b(2)*c(3) - b(3)*c(2)) + a(2)*(b(3)*c(1) - b(1)*c(3)) + &
                     a(3)*(b(1)*c(2) - b(2)*c(1))
  end function triple_product
end module deck_element_check
