!> The messages a run prints while it goes (failed elements and welds, folded solids, initial
!> penetrations, a falling time step): each is printed at once, flushed, and kept, so that the
!> run's messag file and results.h5's /run/warnings list them after the set-up's.
module message_log
  use, intrinsic :: iso_fortran_env, only: output_unit
  implicit none
  private

  public :: message_log_t, log_message

  !> Lines printed so far, each ended by a new line.
  type :: message_log_t
    character(len=:), allocatable :: text
    !> kept, not printed: the ranks other than the first of a distributed run, which print nothing
    logical :: quiet = .false.
  end type message_log_t

contains

  !> Print `line` on standard output (flushed, so that a log redirected to a file keeps the
  !> order of events) and keep it.
  subroutine log_message(log, line)
    type(message_log_t), intent(inout) :: log
    character(len=*), intent(in) :: line
    if (.not. log%quiet) then
      write (output_unit, '(a)') line
      flush (output_unit)
    end if
    if (.not. allocated(log%text)) log%text = ""
    log%text = log%text//line//new_line("a")
  end subroutine log_message
end module message_log
