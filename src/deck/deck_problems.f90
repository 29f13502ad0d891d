!> The list of problems found while reading a deck, capped so that a systematic mistake
!> (a shifted column in a million node cards) gives a readable report instead of a million lines.
module deck_problems
  use error_handling, only: error_t, error_list_t, add_error, take_errors
  use text_format, only: integer_text
  implicit none
  private

  public :: problem_log_t, report_problem, has_problems, problems_to_error, printable
  public :: control_character_name

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
    if (log%total <= listed_limit) call add_error(log%list, printable(message))
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
    if (log%total > listed_limit) then
      call add_error(log%list, "... and "//integer_text(log%total - listed_limit)//" more problems not listed")
    end if
    call take_errors(log%list, error)
    log%total = 0
  end subroutine problems_to_error

  !> `text` with every control character other than a tab written as its name in angle
  !> brackets (`<NUL>`, `<ESC>`), so that a message quoting a damaged card prints as text.
  pure function printable(text) result(shown)
    character(len=*), intent(in) :: text
    character(len=:), allocatable :: shown
    integer :: k, code, start
    if (.not. any_control(text)) then
      shown = text
      return
    end if
    shown = ""
    start = 1
    do k = 1, len(text)
      code = iachar(text(k:k))
      if (.not. is_control(code)) cycle
      shown = shown//text(start:k - 1)//"<"//control_character_name(code)//">"
      start = k + 1
    end do
    shown = shown//text(start:)
  end function printable

  pure logical function any_control(text)
    character(len=*), intent(in) :: text
    integer :: k
    any_control = .false.
    do k = 1, len(text)
      if (is_control(iachar(text(k:k)))) any_control = .true.
    end do
  end function any_control

  !> True for the ASCII control characters other than a tab.
  pure logical function is_control(code)
    integer, intent(in) :: code
    is_control = (code < 32 .and. code /= 9) .or. code == 127
  end function is_control

  !> The usual name of the ASCII control character `code` (0-31, 127), such as NUL or ESC.
  pure function control_character_name(code) result(name)
    integer, intent(in) :: code
    character(len=:), allocatable :: name
    character(len=3), parameter :: names(0:31) = [character(len=3) :: "NUL", "SOH", "STX", &
      "ETX", "EOT", "ENQ", "ACK", "BEL", "BS", "TAB", "LF", "VT", "FF", "CR", "SO", "SI", "DLE", &
      "DC1", "DC2", "DC3", "DC4", "NAK", "SYN", "ETB", "CAN", "EM", "SUB", "ESC", "FS", "GS", &
      "RS", "US"]
    if (code >= 0 .and. code <= 31) then
      name = trim(names(code))
    else
      name = "DEL"
    end if
  end function control_character_name
end module deck_problems
