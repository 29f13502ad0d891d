!> The spline kernels of the meshfree (EFG) parts and their box and spherical supports
!> (formulation section 2; Wang et al. 2009, eqs. 2-4; LS-DYNA ISPLINE 0, 1 and 2).
!>
!> Cubic B-spline (ISPLINE 0 and 2):
!>   w(r) = 2/3 - 4 r^2 + 4 r^3             for 0 <= r <= 1/2
!>   w(r) = 4/3 - 4 r + 4 r^2 - 4/3 r^3     for 1/2 < r <= 1   (= 4/3 (1 - r)^3)
!>   w(r) = 0                               beyond
!> Quadratic spline (ISPLINE 1, box support; meshfree shells): the C1 piecewise quadratic with
!> the cubic's knot at r = 1/2,
!>   w(r) = 1 - 2 r^2                       for 0 <= r <= 1/2
!>   w(r) = 2 (1 - r)^2                     for 1/2 < r <= 1
!>   w(r) = 0                               beyond
!> (only ratios of weights enter the MLS functions, so the kernels' scales do not matter).
!>
!> Box support: w_I(X) = w(r_1) w(r_2) w(r_3) with r_k = |X_k - X_Ik| / a_Ik.
!> Spherical support: w_I(X) = w(r) with r = |X - X_I| / a_I (a_I stored in all three
!> components of the radius). The gradient is taken with respect to the evaluation point X,
!> which is what the direct MLS derivatives of the Gauss variant (IDIM 2) need.
module efg_kernel
  use kinds, only: wp
  use model, only: kernel_cubic_box, kernel_quadratic_box, kernel_cubic_sphere
  implicit none
  private

  public :: cubic_spline, quadratic_spline, kernel_weight, kernel_weights, kernel_weight_gradient

contains

  !> The cubic B-spline w(r) and its derivative dw/dr. Both vanish for r >= 1, so a point
  !> exactly on the edge of a support gets a zero weight and is not covered.
  pure subroutine cubic_spline(r, value, derivative)
    real(wp), intent(in) :: r
    real(wp), intent(out) :: value, derivative
    real(wp) :: rest

    if (r <= 0.5_wp) then
      value = 2.0_wp/3.0_wp - 4.0_wp*r*r + 4.0_wp*r*r*r
      derivative = -8.0_wp*r + 12.0_wp*r*r
    else if (r < 1.0_wp) then
      ! written as 4/3 (1 - r)^3 so that the weight keeps its relative accuracy near the
      ! edge of the support, where the moment matrix may depend on it alone
      rest = 1.0_wp - r
      value = 4.0_wp/3.0_wp*rest*rest*rest
      derivative = -4.0_wp*rest*rest
    else
      value = 0.0_wp
      derivative = 0.0_wp
    end if
  end subroutine cubic_spline

  !> The quadratic spline w(r) (ISPLINE 1) and its derivative dw/dr; both vanish for r >= 1.
  pure subroutine quadratic_spline(r, value, derivative)
    real(wp), intent(in) :: r
    real(wp), intent(out) :: value, derivative
    real(wp) :: rest

    if (r <= 0.5_wp) then
      value = 1.0_wp - 2.0_wp*r*r
      derivative = -4.0_wp*r
    else if (r < 1.0_wp) then
      rest = 1.0_wp - r
      value = 2.0_wp*rest*rest
      derivative = -4.0_wp*rest
    else
      value = 0.0_wp
      derivative = 0.0_wp
    end if
  end subroutine quadratic_spline

  !> The quadratic spline value alone, without branches (see spline_value).
  elemental function quadratic_value(r) result(value)
    real(wp), intent(in) :: r
    real(wp) :: value
    real(wp) :: clamped, rest

    clamped = min(r, 1.0_wp)
    rest = 1.0_wp - clamped
    value = merge(1.0_wp - 2.0_wp*clamped*clamped, 2.0_wp*rest*rest, clamped <= 0.5_wp)
  end function quadratic_value

  !> The spline of `kernel` (cubic or quadratic) and its derivative.
  pure subroutine kernel_spline(kernel, r, value, derivative)
    integer, intent(in) :: kernel
    real(wp), intent(in) :: r
    real(wp), intent(out) :: value, derivative
    if (kernel == kernel_quadratic_box) then
      call quadratic_spline(r, value, derivative)
    else
      call cubic_spline(r, value, derivative)
    end if
  end subroutine kernel_spline

  !> The cubic B-spline value alone, without branches (both pieces computed, r clamped at 1 where
  !> the outer piece vanishes) so that the loop of `kernel_weights` vectorizes.
  elemental function spline_value(r) result(value)
    real(wp), intent(in) :: r
    real(wp) :: value
    real(wp) :: clamped, rest

    clamped = min(r, 1.0_wp)
    rest = 1.0_wp - clamped
    value = merge(2.0_wp/3.0_wp - 4.0_wp*clamped*clamped*rest, 4.0_wp/3.0_wp*rest*rest*rest, clamped <= 0.5_wp)
  end function spline_value

  !> Kernel weights of many particles at one point: the inner loop of every shape-function
  !> evaluation. `inverse_radius` (3, n) holds 1/a_Ik (sphere: 1/a_I in component 1).
  pure subroutine kernel_weights(kernel, centres, inverse_radius, point, weights)
    integer, intent(in) :: kernel
    real(wp), intent(in) :: centres(:, :), inverse_radius(:, :), point(3)
    real(wp), intent(out) :: weights(:)
    integer :: i

    if (kernel == kernel_cubic_sphere) then
      do i = 1, size(weights)
        weights(i) = spline_value(sqrt((point(1) - centres(1, i))**2 + (point(2) - centres(2, i))**2 &
                                       + (point(3) - centres(3, i))**2)*inverse_radius(1, i))
      end do
    else if (kernel == kernel_quadratic_box) then
      do i = 1, size(weights)
        weights(i) = quadratic_value(abs(point(1) - centres(1, i))*inverse_radius(1, i)) &
                     *quadratic_value(abs(point(2) - centres(2, i))*inverse_radius(2, i)) &
                     *quadratic_value(abs(point(3) - centres(3, i))*inverse_radius(3, i))
      end do
    else
      do i = 1, size(weights)
        weights(i) = spline_value(abs(point(1) - centres(1, i))*inverse_radius(1, i)) &
                     *spline_value(abs(point(2) - centres(2, i))*inverse_radius(2, i)) &
                     *spline_value(abs(point(3) - centres(3, i))*inverse_radius(3, i))
      end do
    end if
  end subroutine kernel_weights

  !> Kernel weight w_I(X) of a particle at `centre` with support radii `radius` (box:
  !> a_I1, a_I2, a_I3; sphere: a_I in every component) at `point`.
  pure function kernel_weight(kernel, centre, radius, point) result(weight)
    integer, intent(in) :: kernel
    real(wp), intent(in) :: centre(3), radius(3), point(3)
    real(wp) :: weight
    real(wp) :: value, derivative
    integer :: k

    weight = 0.0_wp
    select case (kernel)
    case (kernel_cubic_sphere)
      call cubic_spline(norm2(point - centre)/radius(1), weight, derivative)
    case (kernel_cubic_box, kernel_quadratic_box)
      weight = 1.0_wp
      do k = 1, 3
        call kernel_spline(kernel, abs(point(k) - centre(k))/radius(k), value, derivative)
        weight = weight*value
        if (weight == 0.0_wp) return
      end do
    end select
  end function kernel_weight

  !> Kernel weight and its gradient with respect to the evaluation point X.
  pure subroutine kernel_weight_gradient(kernel, centre, radius, point, weight, gradient)
    integer, intent(in) :: kernel
    real(wp), intent(in) :: centre(3), radius(3), point(3)
    real(wp), intent(out) :: weight, gradient(3)
    real(wp) :: value(3), derivative(3), distance, difference(3)
    integer :: k

    weight = 0.0_wp
    gradient = 0.0_wp
    difference = point - centre
    select case (kernel)
    case (kernel_cubic_sphere)
      distance = norm2(difference)
      call cubic_spline(distance/radius(1), weight, derivative(1))
      ! dw/dr vanishes at r = 0, so the direction is irrelevant there
      if (distance > 0.0_wp) then
        gradient = derivative(1)*difference/(distance*radius(1))
      else
        gradient = 0.0_wp
      end if
    case (kernel_cubic_box, kernel_quadratic_box)
      do k = 1, 3
        call kernel_spline(kernel, abs(difference(k))/radius(k), value(k), derivative(k))
        ! dr_k/dX_k = sign(X_k - X_Ik) / a_Ik
        if (difference(k) < 0.0_wp) derivative(k) = -derivative(k)
        derivative(k) = derivative(k)/radius(k)
      end do
      weight = value(1)*value(2)*value(3)
      gradient(1) = derivative(1)*value(2)*value(3)
      gradient(2) = value(1)*derivative(2)*value(3)
      gradient(3) = value(1)*value(2)*derivative(3)
    end select
  end subroutine kernel_weight_gradient
end module efg_kernel
