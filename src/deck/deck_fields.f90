!> The one field-reading routine family every keyword reader shares.
!>
!> A card is one data line split into fields; `get_integer`, `get_real` and `get_text` read
!> field `k`, give blank fields their default, replace `&name` / `-&name` parameter references
!> and report any problem as `file:line: *KEYWORD: field NAME: what is wrong`, then return the
!> default so the reader can go on and list further problems.
module deck_fields
  use kinds, only: wp
  use error_handling, only: error_list_t, add_error
  use deck_problems, only: problem_log_t, report_problem
  use deck_numbers, only: parse_integer, parse_real, number_ok, number_not_integral, &
                          number_out_of_range
  use text_format, only: integer_text, real_text
  use deck_columns, only: field_spans_t, split_fields
  use deck_lexer, only: deck_t, line_location, find_parameter, trim_blanks, is_blank_line, &
                        block_of_line, load_line_text, card_text
  implicit none
  private

  public :: card_t, open_card, next_line, require_card, next_definition, get_integer, get_real
  public :: get_text, has_data, card_is_empty
  public :: field_is_blank, card_problem, line_problem, line_title, id_heading, warn_if_set
  public :: keyword_label, located_problem, located_warning, note_not_acted_upon

  !> One data line split into fields, and the block (keyword) it belongs to.
  type :: card_t
    integer :: line = 0
    integer :: block = 0
    character(len=:), allocatable :: text   !< the line (field positions refer to it)
    type(field_spans_t) :: spans
    logical :: failed = .false.     !< a field could not be read
  end type card_t

contains

  !> Split line `line` of block `block` with the standard `widths` of its layout. `card` is
  !> inout so that a reader going through many cards reuses the memory of its text.
  subroutine open_card(deck, block, line, widths, card, log)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block, line
    integer, intent(in) :: widths(:)
    type(card_t), intent(inout) :: card
    type(problem_log_t), intent(inout) :: log
    card%line = line
    card%block = block
    card%failed = .false.
    call load_line_text(deck, line, card%text)
    call split_fields(card%text, widths, deck%blocks(block)%format, card%spans)
    if (card%spans%has_tab .and. .not. card%spans%free) then
      call report_problem(log, line_location(deck, line)//": *"//keyword_label(deck, block)// &
        ": the card holds a tab character (column "//integer_text(card%spans%tab_column)// &
        "); fixed columns need blanks (or separate the fields with commas)", unreadable=.true.)
      card%failed = .true.
    end if
  end subroutine open_card

  !> Advance `line` to the next data line of `block` (skipping blank lines when
  !> `skip_blank`); false at the end of the block.
  logical function next_line(deck, block, line, skip_blank)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    integer, intent(inout) :: line
    logical, intent(in) :: skip_blank
    next_line = .false.
    line = max(line, deck%blocks(block)%first_line - 1)
    do while (line < deck%blocks(block)%last_line)
      line = line + 1
      if (skip_blank) then
        if (is_blank_line(deck, line)) cycle
      end if
      next_line = .true.
      return
    end do
  end function next_line

  !> Advance to the next card of a definition and split it. A blank line is a card (its fields
  !> take their defaults), also one of the blank lines between the block's last data line and
  !> the next keyword: LS-DYNA reads a card left blank as a card of defaults. When the block
  !> ends first, report `field FIRST_FIELD: card LABEL is missing` at the last line read (the
  !> keyword line when no card was read yet) and return false.
  logical function require_card(deck, block, line, widths, card, log, label, first_field)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    integer, intent(inout) :: line
    integer, intent(in) :: widths(:)
    type(card_t), intent(out) :: card
    type(problem_log_t), intent(inout) :: log
    character(len=*), intent(in) :: label, first_field
    integer :: previous
    previous = max(line, deck%blocks(block)%keyword_line)
    require_card = next_line(deck, block, line, .false.)
    if (.not. require_card .and. line < deck%blocks(block)%end_line) then
      ! a blank line after the last data line, where this definition still needs a card
      line = line + 1
      require_card = .true.
    end if
    if (require_card) then
      call open_card(deck, block, line, widths, card, log)
    else
      call line_problem(deck, log, previous, block, first_field, label// &
        " is missing: the keyword ends after this line", unreadable=.true.)
    end if
  end function require_card

  !> The next definition of a keyword whose definitions may repeat: with `has_title` a title
  !> line and then the first card, otherwise just the first card. False at the end of the
  !> block, or when the title is the last line or the keyword has no line at all (the missing
  !> card is then reported).
  logical function next_definition(deck, block, has_title, line, widths, card, title, log, &
                                   label, first_field)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    logical, intent(in) :: has_title
    integer, intent(inout) :: line
    integer, intent(in) :: widths(:)
    type(card_t), intent(out) :: card
    character(len=:), allocatable, intent(out) :: title
    type(problem_log_t), intent(inout) :: log
    character(len=*), intent(in) :: label, first_field
    title = ""
    if (line == 0) then
      next_definition = has_data(deck, block, log, label, first_field)
      if (.not. next_definition) return
    end if
    next_definition = next_line(deck, block, line, .false.)
    if (.not. next_definition) return
    if (has_title) then
      title = line_title(deck, line)
      next_definition = require_card(deck, block, line, widths, card, log, label, first_field)
    else
      call open_card(deck, block, line, widths, card, log)
    end if
  end function next_definition

  !> True when `block` has at least one data line; otherwise report `field FIRST_FIELD: LABEL
  !> is missing` at the keyword line, for keywords that are meaningless without a card.
  logical function has_data(deck, block, log, label, first_field)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(problem_log_t), intent(inout) :: log
    character(len=*), intent(in) :: label, first_field
    has_data = deck%blocks(block)%last_line >= deck%blocks(block)%first_line
    if (.not. has_data) call line_problem(deck, log, deck%blocks(block)%keyword_line, block, &
      first_field, label//" is missing: the keyword has no cards", unreadable=.true.)
  end function has_data

  !> Integer field `k`; blank gives `default` (0 when absent), and so does 0 with
  !> `zero_is_default` (LS-DYNA's "EQ.0: default" fields, such as ELFORM).
  subroutine get_integer(deck, card, k, name, value, log, default, zero_is_default)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    integer, intent(in) :: k
    character(len=*), intent(in) :: name
    integer, intent(out) :: value
    type(problem_log_t), intent(inout) :: log
    integer, intent(in), optional :: default
    logical, intent(in), optional :: zero_is_default
    call read_integer_field(deck, card, k, name, value, log, default)
    if (.not. present(zero_is_default) .or. .not. present(default)) return
    if (zero_is_default .and. value == 0) value = default
  end subroutine get_integer

  subroutine read_integer_field(deck, card, k, name, value, log, default)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    integer, intent(in) :: k
    character(len=*), intent(in) :: name
    integer, intent(out) :: value
    type(problem_log_t), intent(inout) :: log
    integer, intent(in), optional :: default
    integer :: first, last, status, parameter
    real(wp) :: real_value

    value = 0
    if (present(default)) value = default
    call field_bounds(card, k, first, last)
    if (last < first) return
    associate (text => card%text(first:last))
      if (is_reference(text)) then
        call resolve_reference(deck, card, name, text, parameter, log)
        if (parameter == 0) return
        select case (deck%parameters(parameter)%kind)
        case ("I")
          value = deck%parameters(parameter)%integer_value
        case ("R")
          real_value = deck%parameters(parameter)%real_value
          if (real_value /= aint(real_value) .or. abs(real_value) > 2.0e9_wp) then
            call reference_problem(deck, card, name, text, "holds "//real_text(real_value)// &
                                   ", not an integer", log)
            return
          end if
          value = nint(real_value)
        case default
          call reference_problem(deck, card, name, text, "is a character parameter, not "// &
                                 "a number", log)
          return
        end select
        if (text(1:1) == "-") value = -value
        return
      end if
      call parse_integer(text, value, status)
      if (status /= number_ok) then
        select case (status)
        case (number_not_integral)
          call field_problem(deck, card, k, name, """"//text//""" is not an integer", log)
        case (number_out_of_range)
          call field_problem(deck, card, k, name, """"//text//""" is out of range", log)
        case default
          call field_problem(deck, card, k, name, """"//text//""" is not an integer", log)
        end select
        value = 0
        if (present(default)) value = default
      end if
    end associate
  end subroutine read_integer_field

  !> Real field `k`; blank gives `default` (0 when absent).
  subroutine get_real(deck, card, k, name, value, log, default)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    integer, intent(in) :: k
    character(len=*), intent(in) :: name
    real(wp), intent(out) :: value
    type(problem_log_t), intent(inout) :: log
    real(wp), intent(in), optional :: default
    integer :: first, last, status, parameter

    value = 0.0_wp
    if (present(default)) value = default
    call field_bounds(card, k, first, last)
    if (last < first) return
    associate (text => card%text(first:last))
      if (is_reference(text)) then
        call resolve_reference(deck, card, name, text, parameter, log)
        if (parameter == 0) return
        if (deck%parameters(parameter)%kind == "C") then
          call reference_problem(deck, card, name, text, "is a character parameter, not "// &
                                 "a number", log)
          return
        end if
        value = deck%parameters(parameter)%real_value
        if (text(1:1) == "-") value = -value
        return
      end if
      call parse_real(text, value, status)
      if (status /= number_ok) then
        if (status == number_out_of_range) then
          call field_problem(deck, card, k, name, """"//text//""" is out of range (a real "// &
                             "value is 0 or of a magnitude between 1e-30 and 1e30)", log)
        else
          call field_problem(deck, card, k, name, """"//text//""" is not a number", log)
        end if
        value = 0.0_wp
        if (present(default)) value = default
      end if
    end associate
  end subroutine get_real

  !> Text field `k`, trimmed; a `&name` reference to a C parameter is replaced by its value.
  subroutine get_text(deck, card, k, name, value, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    integer, intent(in) :: k
    character(len=*), intent(in) :: name
    character(len=:), allocatable, intent(out) :: value
    type(problem_log_t), intent(inout) :: log
    integer :: first, last, parameter
    value = ""
    call field_bounds(card, k, first, last)
    if (last < first) return
    value = card%text(first:last)
    if (value(1:1) == "&") then
      call resolve_reference(deck, card, name, value, parameter, log)
      if (parameter > 0) value = trim_blanks(deck%parameters(parameter)%text_value)
    end if
  end subroutine get_text

  !> True when field `k` is blank (the field's default applies).
  pure logical function field_is_blank(card, k)
    type(card_t), intent(in) :: card
    integer, intent(in) :: k
    integer :: first, last
    call field_bounds(card, k, first, last)
    field_is_blank = last < first
  end function field_is_blank

  !> True when every field of `card` is blank or a number equal to zero: a card that sets
  !> nothing (such as the unconditional user-element cards some writers add to a keyword).
  logical function card_is_empty(card)
    type(card_t), intent(in) :: card
    integer :: k, first, last, status
    real(wp) :: value
    card_is_empty = .false.
    do k = 1, card%spans%count
      call field_bounds(card, k, first, last)
      if (last < first) cycle
      call parse_real(card%text(first:last), value, status)
      if (status /= number_ok .or. value /= 0.0_wp) return
    end do
    card_is_empty = .true.
  end function card_is_empty

  !> Add a warning when field `k` holds a value other than blank or zero: crashfree reads
  !> the field but does not use it (`reason` says why).
  subroutine warn_if_set(deck, card, k, name, reason, warnings)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(in) :: card
    integer, intent(in) :: k
    character(len=*), intent(in) :: name, reason
    type(error_list_t), intent(inout) :: warnings
    integer :: first, last, status
    real(wp) :: value
    call field_bounds(card, k, first, last)
    if (last < first) return
    call parse_real(card%text(first:last), value, status)
    if (status == number_ok .and. value == 0.0_wp) return
    call add_error(warnings, line_location(deck, card%line)//": *"// &
      keyword_label(deck, card%block)//": field "//name//": ignored ("//reason//")")
  end subroutine warn_if_set

  !> A keyword read but not acted upon (display or bookkeeping): one warning at its keyword
  !> line, `*KEYWORD: read, not acted upon (reason)`, naming the fields the deck sets (not
  !> blank, not zero) with their values. `field_names(c)` names the fields of card c (blank-
  !> separated, LS-DYNA's names); cards past the last named one are read over, whatever
  !> their number.
  subroutine note_not_acted_upon(deck, block, field_names, reason, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    character(len=*), intent(in) :: field_names(:)
    character(len=*), intent(in) :: reason
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    type(problem_log_t) :: unused_log
    character(len=:), allocatable :: set_fields, names, name
    integer :: line, card_index, k, first, last, status, name_end
    real(wp) :: value

    set_fields = ""
    line = 0
    card_index = 0
    do while (card_index < size(field_names))
      if (.not. next_line(deck, block, line, .false.)) exit
      card_index = card_index + 1
      ! (a tab in fixed columns is no problem here: nothing of the card is used)
      call open_card(deck, block, line, [10, 10, 10, 10, 10, 10, 10, 10], card, unused_log)
      names = trim_blanks(field_names(card_index))
      do k = 1, 8
        if (len(names) == 0) exit
        name_end = index(names, " ") - 1
        if (name_end < 0) name_end = len(names)
        name = names(:name_end)
        names = trim_blanks(names(name_end + 1:))
        call field_bounds(card, k, first, last)
        if (last < first) cycle
        call parse_real(card%text(first:last), value, status)
        if (status == number_ok .and. value == 0.0_wp) cycle
        set_fields = set_fields//" "//name//"="//card%text(first:last)
      end do
    end do
    if (len(set_fields) > 0) set_fields = "; fields set, not used:"//set_fields
    call add_error(warnings, line_location(deck, deck%blocks(block)%keyword_line)//": *"// &
      keyword_label(deck, block)//": read, not acted upon ("//reason//")"//set_fields)
  end subroutine note_not_acted_upon

  !> Report `field NAME: message` for the line of `card`.
  subroutine card_problem(deck, log, card, name, message, unreadable)
    type(deck_t), intent(in) :: deck
    type(problem_log_t), intent(inout) :: log
    type(card_t), intent(in) :: card
    character(len=*), intent(in) :: name, message
    logical, intent(in), optional :: unreadable
    call line_problem(deck, log, card%line, card%block, name, message, unreadable)
  end subroutine card_problem

  !> Report `file:line: *KEYWORD: field NAME: message` for line `line` of block `block`.
  subroutine line_problem(deck, log, line, block, name, message, unreadable)
    type(deck_t), intent(in) :: deck
    type(problem_log_t), intent(inout) :: log
    integer, intent(in) :: line, block
    character(len=*), intent(in) :: name, message
    logical, intent(in), optional :: unreadable
    call report_problem(log, line_location(deck, line)//": *"//keyword_label(deck, block)// &
                        ": field "//name//": "//message, unreadable)
  end subroutine line_problem

  !> Report `file:line: *KEYWORD: field NAME: message` for line `line`, finding its keyword.
  subroutine located_problem(deck, log, line, name, message)
    type(deck_t), intent(in) :: deck
    type(problem_log_t), intent(inout) :: log
    integer, intent(in) :: line
    character(len=*), intent(in) :: name, message
    call line_problem(deck, log, line, block_of_line(deck, line), name, message)
  end subroutine located_problem

  !> Add the warning `file:line: *KEYWORD: field NAME: message` for line `line`, finding its
  !> keyword.
  subroutine located_warning(deck, warnings, line, name, message)
    type(deck_t), intent(in) :: deck
    type(error_list_t), intent(inout) :: warnings
    integer, intent(in) :: line
    character(len=*), intent(in) :: name, message
    call add_error(warnings, line_location(deck, line)//": *"// &
      keyword_label(deck, block_of_line(deck, line))//": field "//name//": "//message)
  end subroutine located_warning

  !> The keyword of block `block` as the deck writes it (upper case, options included).
  function keyword_label(deck, block) result(label)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    character(len=:), allocatable :: label
    label = deck%blocks(block)%name
  end function keyword_label

  !> A whole line as a title (A80 heading), trimmed.
  function line_title(deck, line) result(title)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: line
    character(len=:), allocatable :: title
    title = trim_blanks(card_text(deck, line))
  end function line_title

  !> An `_ID` card: the id (I10) and the heading (the rest of the line).
  subroutine id_heading(deck, block, line, name, id, heading, log)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block, line
    character(len=*), intent(in) :: name
    integer, intent(out) :: id
    character(len=:), allocatable, intent(out) :: heading
    type(problem_log_t), intent(inout) :: log
    type(card_t) :: card
    call open_card(deck, block, line, [10, 150], card, log)
    call get_integer(deck, card, 1, name, id, log)
    call get_text(deck, card, 2, "HEADING", heading, log)
  end subroutine id_heading

  !> Positions of field `k` in the text of `card`, blanks trimmed (last < first: blank).
  pure subroutine field_bounds(card, k, first, last)
    type(card_t), intent(in) :: card
    integer, intent(in) :: k
    integer, intent(out) :: first, last
    integer :: start, finish
    first = 1
    last = 0
    if (k > card%spans%count) return
    if (card%spans%last(k) < card%spans%first(k)) return
    ! plain loops: `verify` with a set is a general search, and this runs for every field
    do start = card%spans%first(k), card%spans%last(k)
      if (card%text(start:start) /= " " .and. card%text(start:start) /= achar(9)) exit
    end do
    if (start > card%spans%last(k)) return
    do finish = card%spans%last(k), start, -1
      if (card%text(finish:finish) /= " " .and. card%text(finish:finish) /= achar(9)) exit
    end do
    first = start
    last = finish
  end subroutine field_bounds

  pure logical function is_reference(text)
    character(len=*), intent(in) :: text
    is_reference = text(1:1) == "&"
    if (len(text) >= 2) is_reference = is_reference .or. text(1:2) == "-&"
  end function is_reference

  !> Index of the parameter `text` (`&name` or `-&name`) refers to; 0 after reporting it.
  subroutine resolve_reference(deck, card, name, text, parameter, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    character(len=*), intent(in) :: name, text
    integer, intent(out) :: parameter
    type(problem_log_t), intent(inout) :: log
    integer :: ampersand
    ampersand = index(text, "&")
    parameter = find_parameter(deck, trim_blanks(text(ampersand + 1:)))
    if (parameter == 0) call reference_problem(deck, card, name, text, "is not defined "// &
                                               "(no *PARAMETER of that name)", log)
  end subroutine resolve_reference

  subroutine reference_problem(deck, card, name, text, message, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    character(len=*), intent(in) :: name, text, message
    type(problem_log_t), intent(inout) :: log
    integer :: ampersand
    ampersand = index(text, "&")
    call card_problem(deck, log, card, name, "parameter "//text(ampersand:)//" "//message, &
                      unreadable=.true.)
    card%failed = .true.
  end subroutine reference_problem

  !> A field that cannot be read: name the field, show its text and where it was taken from.
  subroutine field_problem(deck, card, k, name, message, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    integer, intent(in) :: k
    character(len=*), intent(in) :: name, message
    type(problem_log_t), intent(inout) :: log
    character(len=:), allocatable :: where
    if (card%spans%free) then
      where = " (entry "//integer_text(k)//" of the comma-separated card)"
    else
      where = " (columns "//integer_text(card%spans%column_first(k))//"-"// &
              integer_text(card%spans%column_last(k))//")"
    end if
    call card_problem(deck, log, card, name, message//where, unreadable=.true.)
    card%failed = .true.
  end subroutine field_problem
end module deck_fields
