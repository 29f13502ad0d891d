!> The progress line of a running job: cycle, time, time step, percent done, time left.
!>
!> Printed as whole lines (batch logs stay readable): at every tenth of the run and at least
!> every 10 s of wall time.
module progress_report
  use kinds, only: wp
  use wall_clock, only: seconds_now
  implicit none
  private

  public :: progress_t, start_progress, report_progress, format_duration

  type :: progress_t
    real(wp) :: end_time = 0.0_wp
    integer :: end_cycle = 0
    real(wp) :: started = 0.0_wp
    real(wp) :: last_report = 0.0_wp
    integer :: next_tenth = 1
  end type progress_t

contains

  subroutine start_progress(progress, end_time, end_cycle)
    type(progress_t), intent(out) :: progress
    real(wp), intent(in) :: end_time
    integer, intent(in) :: end_cycle
    progress%end_time = end_time
    progress%end_cycle = end_cycle
    progress%started = seconds_now()
    progress%last_report = progress%started
    write (*, '(a)') "      cycle          time     time step    done     time left"
  end subroutine start_progress

  subroutine report_progress(progress, cycle, time, time_step, finished)
    type(progress_t), intent(inout) :: progress
    integer, intent(in) :: cycle
    real(wp), intent(in) :: time, time_step
    logical, intent(in) :: finished
    real(wp) :: fraction, now, left
    fraction = 0.0_wp
    if (progress%end_time > 0.0_wp) fraction = time/progress%end_time
    if (progress%end_cycle > 0) fraction = max(fraction, real(cycle, wp)/real(progress%end_cycle, wp))
    fraction = min(fraction, 1.0_wp)
    now = seconds_now()
    if (.not. (finished .or. fraction*10.0_wp >= progress%next_tenth .or. now - progress%last_report >= 10.0_wp)) return
    do while (fraction*10.0_wp >= progress%next_tenth)
      progress%next_tenth = progress%next_tenth + 1
    end do
    progress%last_report = now
    left = 0.0_wp
    if (fraction > 0.0_wp) left = (now - progress%started)*(1.0_wp - fraction)/fraction
    write (*, '(i11,2es14.5,f7.1,"%",a14)') cycle, time, time_step, 100.0_wp*fraction, format_duration(left)
    flush (6)
  end subroutine report_progress

  !> "1h 02m", "3m 05s", "12.3s"; "> 100000h" for longer (or not finite) estimates, which a
  !> collapsing time step gives and a default integer would overflow on.
  function format_duration(seconds) result(text)
    real(wp), intent(in) :: seconds
    character(len=:), allocatable :: text
    character(len=32) :: buffer
    integer :: whole
    if (.not. (seconds < 3.6e8_wp)) then
      text = "> 100000h"
      return
    end if
    whole = int(max(seconds, 0.0_wp))
    if (seconds >= 3600.0_wp) then
      write (buffer, '(i0,"h ",i2.2,"m")') whole/3600, mod(whole, 3600)/60
    else if (seconds >= 60.0_wp) then
      write (buffer, '(i0,"m ",i2.2,"s")') whole/60, mod(whole, 60)
    else
      write (buffer, '(f6.1,"s")') seconds
      buffer = adjustl(buffer)
    end if
    text = trim(buffer)
  end function format_duration
end module progress_report
