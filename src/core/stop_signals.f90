!> SIGINT and SIGTERM end the time loop cleanly; SIGUSR1 asks for a restart dump; SIGUSR2 asks
!> for a progress line (LS-DYNA's sense switches sw1, sw3 and sw2).
!>
!> The handlers are installed when the time loop starts (before, while the deck is read and the
!> model set up, the signals keep their default action and end the process at once: nothing is
!> written yet). A batch system's kill (SIGTERM) or a Ctrl-C (SIGINT) during the loop sets a flag that the time
!> loop reads once per cycle: it finishes the cycle, writes the state, closes the results and
!> ends with error termination (exit 1), so the results are complete up to that time; it also
!> writes a restart dump, from which `r=` continues the run (sw1). Further
!> SIGINT or SIGTERM while that is done are the same request (a second Ctrl-C would otherwise
!> kill the process halfway through its last writes); SIGQUIT (Ctrl-\) or SIGKILL end it at
!> once. A signal that the parent had set to be ignored (a job started in the background by a
!> non-interactive shell) stays ignored, as for any command-line tool. `kill -USR1 <pid>` writes
!> a restart dump after the next cycle and the run goes on (sw3); `kill -USR2 <pid>` prints the
!> progress line at the next cycle (sw2).
!>
!> The flags are the one piece of process-wide state in crashfree: the operating system delivers
!> a signal to the process, not to a caller that could pass state down.
module stop_signals
  use, intrinsic :: iso_c_binding, only: c_int, c_intptr_t, c_funptr, c_funloc
  implicit none
  private

  public :: catch_stop_signals, received_stop_signal, progress_line_requested, dump_requested, signal_name
  public :: signal_terminate

  !> Linux signal numbers (x86-64, aarch64).
  integer(c_int), parameter :: signal_interrupt = 2, signal_terminate = 15, signal_user1 = 10, &
                               signal_user2 = 12

  !> Set by the handlers, read by the time loop.
  integer(c_int), volatile :: stop_signal = 0
  integer(c_int), volatile :: progress_signal = 0
  integer(c_int), volatile :: dump_signal = 0

  interface
    !> The C library's signal(): installs `handler` for `number` (BSD semantics on glibc: the
    !> handler stays installed and interrupted system calls restart).
    function c_signal(number, handler) bind(c, name="signal") result(previous)
      import :: c_int, c_funptr
      integer(c_int), value :: number
      type(c_funptr), value :: handler
      type(c_funptr) :: previous
    end function c_signal
  end interface

contains

  !> Install the handlers (once, before the run starts).
  subroutine catch_stop_signals()
    type(c_funptr) :: stop_handler, progress_handler, dump_handler
    ! (addresses taken at run time: as constant arguments they would sit in read-only data that
    ! the position-independent executable must relocate)
    stop_handler = c_funloc(on_stop_signal)
    progress_handler = c_funloc(on_progress_signal)
    dump_handler = c_funloc(on_dump_signal)
    call catch(signal_interrupt, stop_handler)
    call catch(signal_terminate, stop_handler)
    call catch(signal_user1, dump_handler)
    call catch(signal_user2, progress_handler)
  end subroutine catch_stop_signals

  !> Install `handler` for `number` unless the signal is ignored (SIG_IGN, the address 1), which
  !> is then put back.
  subroutine catch(number, handler)
    integer(c_int), intent(in) :: number
    type(c_funptr), intent(in) :: handler
    integer(c_intptr_t), parameter :: ignored = 1
    type(c_funptr) :: previous
    previous = c_signal(number, handler)
    if (transfer(previous, 0_c_intptr_t) == ignored) previous = c_signal(number, previous)
  end subroutine catch

  !> The number of the SIGINT or SIGTERM received (0: none).
  integer function received_stop_signal()
    received_stop_signal = int(stop_signal)
  end function received_stop_signal

  !> Whether SIGUSR2 came since the last call (the request is then taken).
  logical function progress_line_requested()
    progress_line_requested = progress_signal /= 0
    if (progress_line_requested) progress_signal = 0
  end function progress_line_requested

  !> Whether SIGUSR1 came since the last call (the request is then taken).
  logical function dump_requested()
    dump_requested = dump_signal /= 0
    if (dump_requested) dump_signal = 0
  end function dump_requested

  !> "SIGINT", "SIGTERM", ... for messages.
  function signal_name(number) result(name)
    integer, intent(in) :: number
    character(len=:), allocatable :: name
    character(len=12) :: buffer
    select case (number)
    case (signal_interrupt)
      name = "SIGINT"
    case (signal_terminate)
      name = "SIGTERM"
    case (signal_user1)
      name = "SIGUSR1"
    case default
      write (buffer, '(a,i0)') "signal ", number
      name = trim(buffer)
    end select
  end function signal_name

  !> Only async-signal-safe work: store the number.
  subroutine on_stop_signal(number) bind(c)
    integer(c_int), value :: number
    stop_signal = number
  end subroutine on_stop_signal

  subroutine on_progress_signal(number) bind(c)
    integer(c_int), value :: number
    progress_signal = number
  end subroutine on_progress_signal

  subroutine on_dump_signal(number) bind(c)
    integer(c_int), value :: number
    dump_signal = number
  end subroutine on_dump_signal
end module stop_signals
