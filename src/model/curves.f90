!> Load curves (*DEFINE_CURVE): piecewise-linear functions of time or of a material variable.
module curves
  use kinds, only: wp
  implicit none
  private

  public :: curve_t, curve_value, curve_slope, curve_value_and_slope, smallest_magnitude_from

  !> One curve with its scale and offset factors already applied to the stored points:
  !> stored abscissa = SFA * (A + OFFA), stored ordinate = SFO * (O + OFFO) (LS-DYNA's rule:
  !> the offset is added before scaling).
  type :: curve_t
    integer :: id = 0
    character(len=:), allocatable :: title
    real(wp), allocatable :: abscissa(:)
    real(wp), allocatable :: ordinate(:)
  end type curve_t

contains

  !> Value of the curve at `x`: linear interpolation between points and linear extrapolation
  !> from the last two (first two) points beyond the ends, as LS-DYNA does for load curves.
  pure function curve_value(curve, x) result(value)
    type(curve_t), intent(in) :: curve
    real(wp), intent(in) :: x
    real(wp) :: value
    integer :: segment
    if (size(curve%abscissa) == 1) then
      value = curve%ordinate(1)
      return
    end if
    segment = find_segment(curve%abscissa, x)
    value = curve%ordinate(segment) + curve_slope_on(curve, segment)*(x - curve%abscissa(segment))
  end function curve_value

  !> Value and slope of the curve at `x` with one search for the segment (the plasticity
  !> kernels need both at every iteration of their return).
  pure subroutine curve_value_and_slope(curve, x, value, slope)
    type(curve_t), intent(in) :: curve
    real(wp), intent(in) :: x
    real(wp), intent(out) :: value, slope
    integer :: segment
    if (size(curve%abscissa) == 1) then
      value = curve%ordinate(1)
      slope = 0.0_wp
      return
    end if
    segment = find_segment(curve%abscissa, x)
    slope = curve_slope_on(curve, segment)
    value = curve%ordinate(segment) + slope*(x - curve%abscissa(segment))
  end subroutine curve_value_and_slope

  !> Slope of the curve at `x` (of the segment containing `x`).
  pure function curve_slope(curve, x) result(slope)
    type(curve_t), intent(in) :: curve
    real(wp), intent(in) :: x
    real(wp) :: slope
    if (size(curve%abscissa) == 1) then
      slope = 0.0_wp
      return
    end if
    slope = curve_slope_on(curve, find_segment(curve%abscissa, x))
  end function curve_slope

  pure function curve_slope_on(curve, segment) result(slope)
    type(curve_t), intent(in) :: curve
    integer, intent(in) :: segment
    real(wp) :: slope, width
    width = curve%abscissa(segment + 1) - curve%abscissa(segment)
    if (width > 0.0_wp) then
      slope = (curve%ordinate(segment + 1) - curve%ordinate(segment))/width
    else
      slope = 0.0_wp
    end if
  end function curve_slope_on

  !> The smallest |value| the curve takes for x >= `start`, or 0 where it may reach zero (a
  !> change of sign, or a fall toward zero beyond the last point). A caller that only needs the
  !> value when some quantity exceeds it can skip the evaluation below this bound.
  pure function smallest_magnitude_from(curve, start) result(bound)
    type(curve_t), intent(in) :: curve
    real(wp), intent(in) :: start
    real(wp) :: bound, previous
    integer :: k, n
    n = size(curve%abscissa)
    if (n == 1) then
      bound = abs(curve%ordinate(1))
      return
    end if
    previous = curve_value(curve, start)
    bound = abs(previous)
    do k = find_segment(curve%abscissa, start) + 1, n
      if (curve%abscissa(k) < start) cycle
      if (previous*curve%ordinate(k) <= 0.0_wp) then
        bound = 0.0_wp
        return
      end if
      bound = min(bound, abs(curve%ordinate(k)))
      previous = curve%ordinate(k)
    end do
    ! linear extrapolation beyond the last point: toward zero means no bound
    if (curve_slope_on(curve, n - 1)*curve%ordinate(n) < 0.0_wp) bound = 0.0_wp
  end function smallest_magnitude_from

  !> Index i of the segment [a(i), a(i+1)] holding x (bisection; ends extend outward).
  pure function find_segment(abscissa, x) result(low)
    real(wp), intent(in) :: abscissa(:)
    real(wp), intent(in) :: x
    integer :: low, high, middle
    low = 1
    high = size(abscissa)
    do while (high - low > 1)
      middle = (low + high)/2
      if (x >= abscissa(middle)) then
        low = middle
      else
        high = middle
      end if
    end do
  end function find_segment
end module curves
