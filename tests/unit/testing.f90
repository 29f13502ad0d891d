!> A small test harness shaped like test-drive: named checks with tolerances, a summary line
!> `N passed, N failed` and a non-zero exit status when anything failed.
!>
!> Each tests/unit/test_<area>.f90 is a program that creates a `test_suite_t`, runs its checks
!> and calls `finish_suite`; `make unit` runs every program and adds the counts up.
module testing
  use kinds, only: wp
  implicit none
  private

  public :: test_suite_t, check, check_close, finish_suite

  type :: test_suite_t
    character(len=:), allocatable :: name
    integer :: passed = 0
    integer :: failed = 0
  end type test_suite_t

  interface check_close
    module procedure check_close_scalar
    module procedure check_close_array
  end interface check_close

contains

  !> A logical condition; `detail` is shown when it fails.
  subroutine check(suite, name, condition, detail)
    type(test_suite_t), intent(inout) :: suite
    character(len=*), intent(in) :: name
    logical, intent(in) :: condition
    character(len=*), intent(in), optional :: detail
    if (condition) then
      suite%passed = suite%passed + 1
    else
      suite%failed = suite%failed + 1
      if (present(detail)) then
        write (*, '(a)') "FAIL "//suite%name//": "//name//": "//detail
      else
        write (*, '(a)') "FAIL "//suite%name//": "//name
      end if
    end if
  end subroutine check

  !> |actual - expected| <= max(rel * |expected|, thr). Give `rel`, `thr` or both.
  subroutine check_close_scalar(suite, name, actual, expected, rel, thr)
    type(test_suite_t), intent(inout) :: suite
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: actual, expected
    real(wp), intent(in), optional :: rel, thr
    real(wp) :: tolerance
    character(len=200) :: detail
    tolerance = 0.0_wp
    if (present(rel)) tolerance = rel*abs(expected)
    if (present(thr)) tolerance = max(tolerance, thr)
    write (detail, '(a,es23.15,a,es23.15,a,es10.3)') "actual ", actual, " expected ", expected, &
      " tolerance ", tolerance
    call check(suite, name, abs(actual - expected) <= tolerance .and. actual == actual, trim(detail))
  end subroutine check_close_scalar

  !> Element-wise version; reports the worst entry.
  subroutine check_close_array(suite, name, actual, expected, rel, thr)
    type(test_suite_t), intent(inout) :: suite
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: actual(:), expected(:)
    real(wp), intent(in), optional :: rel, thr
    real(wp) :: tolerance(size(actual)), excess(size(actual))
    integer :: worst
    character(len=240) :: detail
    tolerance = 0.0_wp
    if (present(rel)) tolerance = rel*abs(expected)
    if (present(thr)) tolerance = max(tolerance, thr)
    excess = abs(actual - expected) - tolerance
    worst = maxloc(excess, dim=1)
    write (detail, '(a,i0,a,es23.15,a,es23.15,a,es10.3)') "worst entry ", worst, ": actual ", &
      actual(worst), " expected ", expected(worst), " tolerance ", tolerance(worst)
    call check(suite, name, all(excess <= 0.0_wp) .and. all(actual == actual), trim(detail))
  end subroutine check_close_array

  !> Print the summary line and stop with status 1 if any check failed.
  subroutine finish_suite(suite)
    type(test_suite_t), intent(in) :: suite
    write (*, '(i0,a,i0,a)') suite%passed, " passed, ", suite%failed, " failed"
    if (suite%failed > 0) error stop 1
  end subroutine finish_suite
end module testing
