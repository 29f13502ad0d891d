!> Wall-clock timers for the per-phase timing in `/timing` and the end-of-run summary.
module wall_clock
  use kinds, only: wp, long_int
  implicit none
  private

  public :: phase_timer_t, seconds_now, start_phase, stop_phase

  !> Accumulated seconds of one phase of the run.
  type :: phase_timer_t
    real(wp) :: seconds = 0.0_wp
    integer(long_int) :: started = -1
  end type phase_timer_t

contains

  !> Seconds since an arbitrary origin, from the system clock.
  function seconds_now() result(seconds)
    real(wp) :: seconds
    integer(long_int) :: count, rate
    call system_clock(count, rate)
    seconds = real(count, wp)/real(rate, wp)
  end function seconds_now

  subroutine start_phase(timer)
    type(phase_timer_t), intent(inout) :: timer
    integer(long_int) :: count
    call system_clock(count)
    timer%started = count
  end subroutine start_phase

  subroutine stop_phase(timer)
    type(phase_timer_t), intent(inout) :: timer
    integer(long_int) :: count, rate
    call system_clock(count, rate)
    if (timer%started >= 0) timer%seconds = timer%seconds + real(count - timer%started, wp)/real(rate, wp)
    timer%started = -1
  end subroutine stop_phase
end module wall_clock
