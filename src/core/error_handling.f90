!> Error reporting shared by the deck reader, the model checks and the solver.
!>
!> Follows fpm's pattern: a procedure that can fail takes `type(error_t), allocatable, intent(out)`;
!> it is allocated only on failure. Several problems found in one pass (cross-reference checks)
!> are collected in an `error_list_t` and reported together.
module error_handling
  implicit none
  private

  public :: error_t, error_list_t, make_error, add_error, take_errors

  !> One failure with a message ready for the user.
  type :: error_t
    character(len=:), allocatable :: message
  end type error_t

  !> Messages collected by a checking pass, reported all at once.
  type :: error_list_t
    integer :: count = 0
    character(len=:), allocatable :: text
  end type error_list_t

contains

  !> Allocate `error` with `message`.
  subroutine make_error(error, message)
    type(error_t), allocatable, intent(out) :: error
    character(len=*), intent(in) :: message
    allocate (error)
    error%message = message
  end subroutine make_error

  !> Append one message (one line) to a list.
  subroutine add_error(list, message)
    type(error_list_t), intent(inout) :: list
    character(len=*), intent(in) :: message
    if (list%count == 0) then
      list%text = message
    else
      list%text = list%text//new_line('a')//message
    end if
    list%count = list%count + 1
  end subroutine add_error

  !> Turn a non-empty list into an error (all messages, one per line); leave `error`
  !> unallocated when the list is empty.
  subroutine take_errors(list, error)
    type(error_list_t), intent(inout) :: list
    type(error_t), allocatable, intent(inout) :: error
    if (list%count == 0) return
    if (.not. allocated(error)) allocate (error)
    if (allocated(error%message)) then
      error%message = error%message//new_line('a')//list%text
    else
      error%message = list%text
    end if
    list%count = 0
    deallocate (list%text)
  end subroutine take_errors
end module error_handling
