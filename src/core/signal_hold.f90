!> SIGTERM held back while a library runs that would catch it itself.
!>
!> METIS (through its GKlib) installs its own SIGTERM handler for the length of every call and
!> turns the signal into an error return. A batch system's kill while the elements are ordered
!> was swallowed: the run went on, and the cut METIS was making fell back to input order, so the
!> order depended on when the signal came. Held back, the signal stays pending and takes its
!> normal course as soon as the library has returned and put the previous handler back: before
!> the time loop (stop_signals) its default action ends the process, as for the rest of the
!> set-up; a SIGTERM that the parent set to be ignored is dropped. SIGINT (Ctrl-C) is not held:
!> GKlib leaves it alone.
module signal_hold
  use, intrinsic :: iso_c_binding, only: c_int, c_long
  implicit none
  private

  public :: signal_mask_t, hold_termination_signal, release_held_signals

  !> A set of signals as the C library keeps it (glibc's sigset_t: 1024 bits).
  type, bind(c) :: signal_mask_t
    integer(c_long) :: words(16)
  end type signal_mask_t

  !> SIG_BLOCK, SIG_SETMASK and SIGTERM on Linux (x86-64, aarch64).
  integer(c_int), parameter :: add_to_mask = 0, set_mask = 2, signal_terminate = 15

  interface
    function c_sigemptyset(set) bind(c, name="sigemptyset") result(status)
      import :: c_int, signal_mask_t
      type(signal_mask_t), intent(out) :: set
      integer(c_int) :: status
    end function c_sigemptyset

    function c_sigaddset(set, number) bind(c, name="sigaddset") result(status)
      import :: c_int, signal_mask_t
      type(signal_mask_t), intent(inout) :: set
      integer(c_int), value :: number
      integer(c_int) :: status
    end function c_sigaddset

    !> The calling thread's signal mask (the set-up runs on one thread).
    function c_pthread_sigmask(how, set, previous) bind(c, name="pthread_sigmask") result(status)
      import :: c_int, signal_mask_t
      integer(c_int), value :: how
      type(signal_mask_t), intent(in) :: set
      type(signal_mask_t), intent(out) :: previous
      integer(c_int) :: status
    end function c_pthread_sigmask
  end interface

contains

  !> Hold SIGTERM back; `previous` is the mask to give back to release_held_signals.
  subroutine hold_termination_signal(previous)
    type(signal_mask_t), intent(out) :: previous
    type(signal_mask_t) :: held
    integer(c_int) :: status
    status = c_sigemptyset(held)
    status = c_sigaddset(held, signal_terminate)
    status = c_pthread_sigmask(add_to_mask, held, previous)
  end subroutine hold_termination_signal

  !> Put the mask back: a signal held meanwhile is delivered now.
  subroutine release_held_signals(previous)
    type(signal_mask_t), intent(in) :: previous
    type(signal_mask_t) :: replaced
    integer(c_int) :: status
    status = c_pthread_sigmask(set_mask, previous, replaced)
  end subroutine release_held_signals
end module signal_hold
