!> The list of problems found while reading a deck, capped so that a systematic mistake
!> (a shifted column in a million node cards) gives a readable report instead of a million lines.
module deck_problems
  use error_handling, only: error_t, error_list_t, add_error, take_errors
  implicit none
  private

  public :: problem_log_t, report_problem, has_problems, problems_to_error

  !> Most messages listed; the rest are only counted.
  integer, parameter :: listed_limit = 100

  !> Problems collected in one pass. `unreadable` is set when a card could not be read at all
  !> (a letter in a number, a missing card): the cross-reference pass is then skipped because
  !> its messages would only echo the first ones.
  type :: problem_log_t
    type(error_list_t) :: list
    integer :: total = 0
    logical :: unreadable = .false.
  end type problem_log_t

contains

  !> Record one problem (one line of text, already prefixed with `file:line: *KEYWORD:`).
  subroutine report_problem(log, message, unreadable)
    type(problem_log_t), intent(inout) :: log
    character(len=*), intent(in) :: message
    logical, intent(in), optional :: unreadable
    log%total = log%total + 1
    if (log%total <= listed_limit) call add_error(log%list, message)
    if (present(unreadable)) log%unreadable = log%unreadable .or. unreadable
  end subroutine report_problem

  !> True when at least one problem was recorded.
  pure logical function has_problems(log)
    type(problem_log_t), intent(in) :: log
    has_problems = log%total > 0
  end function has_problems

  !> Move every listed problem into `error` (allocated only when there is a problem).
  subroutine problems_to_error(log, error)
    type(problem_log_t), intent(inout) :: log
    type(error_t), allocatable, intent(inout) :: error
    character(len=24) :: count_text
    if (log%total > listed_limit) then
      write (count_text, '(i0)') log%total - listed_limit
      call add_error(log%list, "... and "//trim(count_text)//" more problems not listed")
    end if
    call take_errors(log%list, error)
    log%total = 0
  end subroutine problems_to_error
end module deck_problems
