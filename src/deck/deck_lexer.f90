!> Reads a deck and everything it includes into memory and cuts it into keyword blocks.
!>
!> Comment lines (`$`), `*COMMENT` blocks, `*KEYWORD`, `*INCLUDE`, `*PARAMETER` and `*END` are
!> handled here, so the keyword readers see only keyword blocks whose data lines are cards.
!> Every line kept has an entry in the line table (file, line number, place in the file's text),
!> which is how every later message can say `file:line`.
!>
!> Files are read whole (stream access) and lines point into their text: a deck of a million
!> nodes is one read and a scan for newlines, not a million formatted reads.
module deck_lexer
  use kinds, only: wp
  use error_handling, only: error_list_t, add_error
  use deck_problems, only: problem_log_t, report_problem
  use deck_numbers, only: to_upper, parse_integer, parse_real, number_ok, integer_text
  use deck_columns, only: field_spans_t, split_fields, format_standard, format_long, format_i10
  implicit none
  private

  public :: deck_t, keyword_block_t, deck_parameter_t, load_deck
  public :: line_location, find_parameter, trim_blanks, is_blank_line, card_text, block_of_line

  !> One file of the deck, read whole.
  type :: source_file_t
    character(len=:), allocatable :: path      !< as opened (include paths resolved)
    character(len=:), allocatable :: text
  end type source_file_t

  !> One keyword and its data lines (indices into the line table; none when last < first).
  type :: keyword_block_t
    character(len=:), allocatable :: name      !< upper case, without `*` and format suffix
    integer :: keyword_line = 0
    integer :: first_line = 1
    integer :: last_line = 0
    integer :: format = format_standard
  end type keyword_block_t

  !> One *PARAMETER: `kind` R (real), I (integer) or C (character).
  type :: deck_parameter_t
    character(len=:), allocatable :: name      !< upper case (names are case-insensitive)
    character :: kind = "R"
    real(wp) :: real_value = 0.0_wp
    integer :: integer_value = 0
    character(len=:), allocatable :: text_value
    integer :: line = 0
  end type deck_parameter_t

  !> The whole deck as text: files, the line table and the keyword blocks in reading order.
  type :: deck_t
    integer :: file_count = 0
    type(source_file_t), allocatable :: files(:)
    integer :: line_count = 0
    integer, allocatable :: line_file(:), line_number(:), line_first(:), line_last(:)
    integer :: block_count = 0
    type(keyword_block_t), allocatable :: blocks(:)
    integer :: parameter_count = 0
    type(deck_parameter_t), allocatable :: parameters(:)
  end type deck_t

  !> What the keyword line being read starts: a block for the keyword readers, or one of the
  !> keywords handled here.
  integer, parameter :: block_none = 0, block_regular = 1, block_include = 2, &
                        block_parameter = 3, block_ignored = 4, block_comment = 5

  !> The block being collected while a file is scanned.
  type :: open_block_t
    integer :: kind = block_none
    integer :: keyword_line = 0
    integer :: first_line = 1
    integer :: last_line = 0
    integer :: format = format_standard
  end type open_block_t

  !> Deepest include nesting accepted (a deeper chain is almost surely a file including itself).
  integer, parameter :: max_include_depth = 30

contains

  !> Read the deck `path` with its includes. Problems go to `log`; duplicate parameters to
  !> `warnings`.
  subroutine load_deck(path, deck, log, warnings)
    character(len=*), intent(in) :: path
    type(deck_t), intent(out) :: deck
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    integer :: chain(0)
    allocate (deck%files(4), deck%blocks(64), deck%parameters(8))
    allocate (deck%line_file(1024), deck%line_number(1024), deck%line_first(1024), &
              deck%line_last(1024))
    call load_file(deck, path, format_standard, 0, chain, log, warnings)
  end subroutine load_deck

  !> Read one file and scan it line by line; `include_line` is the *INCLUDE card that named it
  !> (0 for the main deck), `chain` the files that include it.
  recursive subroutine load_file(deck, path, format, include_line, chain, log, warnings)
    type(deck_t), intent(inout) :: deck
    character(len=*), intent(in) :: path
    integer, intent(in) :: format, include_line
    integer, intent(in) :: chain(:)
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(open_block_t) :: block
    integer :: file, position, newline, last, next, number, file_format, text_length
    logical :: ended, outside_reported

    call read_whole_file(deck, path, include_line, file, log)
    if (file == 0) return
    file_format = format
    text_length = len(deck%files(file)%text)
    position = 1
    number = 0
    outside_reported = .false.
    do while (position <= text_length)
      newline = position_of_newline(deck%files(file)%text(position:))
      if (newline == 0) then
        last = text_length
        next = text_length + 1
      else
        last = position + newline - 2
        next = position + newline
      end if
      number = number + 1
      if (last >= position) then
        if (deck%files(file)%text(last:last) == achar(13)) last = last - 1
      end if
      call take_line(deck, file, number, position, last, file_format, chain, block, ended, &
                     outside_reported, log, warnings)
      if (ended) exit
      position = next
    end do
    call close_block(deck, file, file_format, chain, block, log, warnings)
  end subroutine load_file

  !> Classify one physical line: comment, keyword line, or data line of the open block.
  recursive subroutine take_line(deck, file, number, first, last, file_format, chain, block, &
                                 ended, outside_reported, log, warnings)
    type(deck_t), intent(inout) :: deck
    integer, intent(in) :: file, number, first, last
    integer, intent(inout) :: file_format
    integer, intent(in) :: chain(:)
    type(open_block_t), intent(inout) :: block
    logical, intent(out) :: ended
    logical, intent(inout) :: outside_reported
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    integer :: leading
    character :: lead

    ended = .false.
    leading = first_nonblank(deck%files(file)%text(first:last))
    if (leading > 0) then
      lead = deck%files(file)%text(first + leading - 1:first + leading - 1)
    else
      lead = " "
    end if
    if (lead == "$") return
    if (leading == 1 .and. lead == "*") then
      call close_block(deck, file, file_format, chain, block, log, warnings)
      call add_line(deck, file, number, first, last)
      call open_keyword(deck, deck%line_count, file_format, block, ended, log)
      return
    end if
    if (block%kind == block_comment) return
    if (leading == 0 .and. block%kind == block_none) return
    call add_line(deck, file, number, first, last)
    if (lead == "*") then
      call report_problem(log, line_location(deck, deck%line_count)// &
        ": a keyword must start in column 1 (found '*' in column "//integer_text(leading)//")", &
        unreadable=.true.)
      return
    end if
    if (block%kind == block_none) then
      if (.not. outside_reported) call report_problem(log, line_location(deck, deck%line_count)// &
        ": data line before the first keyword of the file", unreadable=.true.)
      outside_reported = .true.
      return
    end if
    block%last_line = deck%line_count
  end subroutine take_line

  !> Start the block of the keyword on line `line`.
  subroutine open_keyword(deck, line, file_format, block, ended, log)
    type(deck_t), intent(inout) :: deck
    integer, intent(in) :: line
    integer, intent(inout) :: file_format
    type(open_block_t), intent(out) :: block
    logical, intent(out) :: ended
    type(problem_log_t), intent(inout) :: log
    character(len=:), allocatable :: text, name
    integer :: name_end, suffix_format

    ended = .false.
    text = card_text(deck, line)
    name_end = scan(text, " "//achar(9)) - 1
    if (name_end < 0) name_end = len(text)
    name = to_upper(text(2:name_end))
    suffix_format = -1
    if (len(name) > 0) then
      select case (name(len(name):len(name)))
      case ("+")
        suffix_format = format_long
      case ("-")
        suffix_format = format_standard
      case ("%")
        suffix_format = format_i10
      end select
      if (suffix_format >= 0) name = name(:len(name) - 1)
    end if
    block%keyword_line = line
    block%first_line = line + 1
    block%last_line = line
    block%format = file_format
    if (suffix_format >= 0) block%format = suffix_format
    select case (name)
    case ("KEYWORD")
      block%kind = block_ignored
      call read_keyword_options(deck, line, text(name_end + 1:), file_format, log)
    case ("INCLUDE")
      block%kind = block_include
    case ("PARAMETER")
      block%kind = block_parameter
    case ("COMMENT")
      block%kind = block_comment
    case ("END")
      block%kind = block_none
      ended = .true.
    case default
      block%kind = block_regular
      call add_block(deck, name, block)
    end select
  end subroutine open_keyword

  !> `*KEYWORD LONG=Y`, `LONG=S|K|N`, `I10=Y|N`; a memory size (a bare number, MEMORY=...) and
  !> NCPU=... are accepted and ignored. The setting holds for the rest of this file and for
  !> the files it includes.
  subroutine read_keyword_options(deck, line, options, file_format, log)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: line
    character(len=*), intent(in) :: options
    integer, intent(inout) :: file_format
    type(problem_log_t), intent(inout) :: log
    character(len=:), allocatable :: rest, token
    integer :: token_end, status, memory

    rest = to_upper(trim_blanks(options))
    do while (len(rest) > 0)
      token_end = scan(rest, " "//achar(9)) - 1
      if (token_end < 0) token_end = len(rest)
      token = rest(:token_end)
      rest = trim_blanks(rest(token_end + 1:))
      select case (token)
      case ("LONG=Y")
        file_format = format_long
      case ("LONG=S", "LONG=K", "LONG=N", "I10=N")
        file_format = format_standard
      case ("I10=Y")
        file_format = format_i10
      case default
        call parse_integer(token, memory, status)
        if (index(token, "MEMORY") == 1 .or. index(token, "NCPU") == 1) status = number_ok
        if (status /= number_ok .and. verify(token(len(token):), "MGK") /= 0) then
          call report_problem(log, line_location(deck, line)//": *KEYWORD: option '"//token// &
            "' is not understood (LONG=Y|S|K, I10=Y|N or a memory size)")
        end if
      end select
    end do
  end subroutine read_keyword_options

  !> Finish the open block: trim trailing blank lines, run *INCLUDE and *PARAMETER.
  recursive subroutine close_block(deck, file, file_format, chain, block, log, warnings)
    type(deck_t), intent(inout) :: deck
    integer, intent(in) :: file, file_format
    integer, intent(in) :: chain(:)
    type(open_block_t), intent(inout) :: block
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings

    ! Trailing blank lines only separate keywords; a block of nothing but blank lines keeps
    ! one, which then reads as a card of defaults.
    do while (block%last_line > block%first_line)
      if (.not. is_blank_line(deck, block%last_line)) exit
      block%last_line = block%last_line - 1
    end do
    select case (block%kind)
    case (block_regular)
      deck%blocks(deck%block_count)%last_line = block%last_line
    case (block_include)
      call run_includes(deck, file, file_format, chain, block, log, warnings)
    case (block_parameter)
      call read_parameters(deck, block, log, warnings)
    end select
    block%kind = block_none
  end subroutine close_block

  !> Each *INCLUDE data line names a file (a name ending in " +" continues on the next line).
  recursive subroutine run_includes(deck, file, file_format, chain, block, log, warnings)
    type(deck_t), intent(inout) :: deck
    integer, intent(in) :: file, file_format
    integer, intent(in) :: chain(:)
    type(open_block_t), intent(in) :: block
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    character(len=:), allocatable :: name, piece, resolved
    integer :: line, name_line, child_format, parameter
    logical :: continued

    child_format = file_format
    if (block%format /= file_format) child_format = block%format
    name = ""
    name_line = 0
    do line = block%first_line, block%last_line
      piece = trim_blanks(card_text(deck, line))
      if (name_line == 0) name_line = line
      continued = .false.
      if (len(piece) >= 2) continued = piece(len(piece) - 1:) == " +"
      if (continued) then
        name = name//trim_blanks(piece(:len(piece) - 2))
        cycle
      end if
      name = name//piece
      if (len(name) == 0) then
        name_line = 0
        cycle
      end if
      if (name(1:1) == "&") then
        parameter = find_parameter(deck, name(2:))
        if (parameter == 0) then
          call report_problem(log, line_location(deck, name_line)//": *INCLUDE: field "// &
            "FILENAME: parameter &"//name(2:)//" is not defined", unreadable=.true.)
          name = ""
          name_line = 0
          cycle
        end if
        name = deck%parameters(parameter)%text_value
      end if
      name = unquoted(name)
      resolved = resolve_path(deck%files(file)%path, name)
      if (any_file_matches(deck, chain, resolved) .or. resolved == deck%files(file)%path) then
        call report_problem(log, line_location(deck, name_line)//": *INCLUDE: field "// &
          "FILENAME: """//name//""" includes itself (through "//resolved//")", unreadable=.true.)
      else if (size(chain) >= max_include_depth) then
        call report_problem(log, line_location(deck, name_line)//": *INCLUDE: field FILENAME: "// &
          "includes nested deeper than "//integer_text(max_include_depth)//" files", &
          unreadable=.true.)
      else
        call load_file(deck, resolved, child_format, name_line, [chain, file], log, warnings)
      end if
      name = ""
      name_line = 0
    end do
    if (len(name) > 0) call report_problem(log, line_location(deck, name_line)// &
      ": *INCLUDE: field FILENAME: the name continues (' +') past the last line", unreadable=.true.)
  end subroutine run_includes

  logical function any_file_matches(deck, chain, path)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: chain(:)
    character(len=*), intent(in) :: path
    integer :: k
    any_file_matches = .false.
    do k = 1, size(chain)
      if (deck%files(chain(k))%path == path) any_file_matches = .true.
    end do
  end function any_file_matches

  !> `name` relative to the directory of `including` (unchanged when absolute).
  pure function resolve_path(including, name) result(path)
    character(len=*), intent(in) :: including, name
    character(len=:), allocatable :: path
    integer :: slash
    ! `name` is empty for *INCLUDE '' (quotes removed): name(1:1) would read past its end
    if (len(name) > 0) then
      if (name(1:1) == "/") then
        path = name
        return
      end if
    end if
    slash = index(including, "/", back=.true.)
    path = including(:slash)//name
  end function resolve_path

  pure function unquoted(text) result(bare)
    character(len=*), intent(in) :: text
    character(len=:), allocatable :: bare
    bare = text
    if (len(text) >= 2) then
      if ((text(1:1) == '"' .and. text(len(text):) == '"') .or. &
          (text(1:1) == "'" .and. text(len(text):) == "'")) bare = text(2:len(text) - 1)
    end if
  end function unquoted

  !> *PARAMETER cards: four name/value pairs of 10 columns each; the first character of a
  !> name field is its type (R, I or C), the rest is the name.
  subroutine read_parameters(deck, block, log, warnings)
    type(deck_t), intent(inout) :: deck
    type(open_block_t), intent(in) :: block
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(field_spans_t) :: spans
    integer :: line, pair
    character(len=:), allocatable :: text

    do line = block%first_line, block%last_line
      text = card_text(deck, line)
      call split_fields(text, [10, 10, 10, 10, 10, 10, 10, 10], block%format, spans)
      do pair = 1, 4
        if (2*pair - 1 > spans%count) exit
        call define_parameter(deck, line, pair, span_text(text, spans, 2*pair - 1), &
                              span_text(text, spans, 2*pair), log, warnings)
      end do
    end do
  end subroutine read_parameters

  subroutine define_parameter(deck, line, pair, name_field, value_field, log, warnings)
    type(deck_t), intent(inout) :: deck
    integer, intent(in) :: line, pair
    character(len=*), intent(in) :: name_field, value_field
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(deck_parameter_t) :: parameter
    character(len=:), allocatable :: prefix
    integer :: status, existing

    if (len(name_field) == 0 .and. len(value_field) == 0) return
    prefix = line_location(deck, line)//": *PARAMETER: field PRMR"//integer_text(pair)//": "
    if (len(name_field) == 0) then
      call report_problem(log, prefix//"the name is blank but VAL"//integer_text(pair)// &
                          " is given", unreadable=.true.)
      return
    end if
    parameter%kind = to_upper(name_field(1:1))
    parameter%name = to_upper(trim_blanks(name_field(2:)))
    parameter%line = line
    if (index("RIC", parameter%kind) == 0) then
      call report_problem(log, prefix//"""" //name_field//""" must start with its type "// &
                          "letter R (real), I (integer) or C (character)", unreadable=.true.)
      return
    end if
    if (len(parameter%name) == 0) then
      call report_problem(log, prefix//"""" //name_field//""" has a type letter but no name", &
                          unreadable=.true.)
      return
    end if
    prefix = line_location(deck, line)//": *PARAMETER: field VAL"//integer_text(pair)//": "
    status = number_ok
    select case (parameter%kind)
    case ("R")
      if (len(value_field) > 0) call parse_real(value_field, parameter%real_value, status)
      parameter%integer_value = nint(max(min(parameter%real_value, 2.0e9_wp), -2.0e9_wp))
    case ("I")
      if (len(value_field) > 0) call parse_integer(value_field, parameter%integer_value, status)
      parameter%real_value = parameter%integer_value
    end select
    parameter%text_value = value_field
    if (status /= number_ok) then
      call report_problem(log, prefix//""""//value_field//""" is not a valid value for "// &
        trim(merge("real   ", "integer", parameter%kind == "R"))//" parameter "//parameter%name, &
        unreadable=.true.)
      return
    end if
    existing = find_parameter(deck, parameter%name)
    if (existing > 0) then
      call add_error(warnings, line_location(deck, line)//": *PARAMETER: field PRMR"// &
        integer_text(pair)//": parameter "//parameter%name//" is already defined at "// &
        line_location(deck, deck%parameters(existing)%line)//"; the first definition is kept")
      return
    end if
    if (deck%parameter_count == size(deck%parameters)) call grow_parameters(deck)
    deck%parameter_count = deck%parameter_count + 1
    deck%parameters(deck%parameter_count) = parameter
  end subroutine define_parameter

  !> Index of parameter `name` (case-insensitive), 0 when not defined.
  pure integer function find_parameter(deck, name)
    type(deck_t), intent(in) :: deck
    character(len=*), intent(in) :: name
    character(len=len(name)) :: upper
    integer :: k
    upper = to_upper(name)
    find_parameter = 0
    do k = 1, deck%parameter_count
      if (deck%parameters(k)%name == upper) then
        find_parameter = k
        return
      end if
    end do
  end function find_parameter

  !> Text of field `k` of a split card, blanks (and tabs) around it removed.
  pure function span_text(text, spans, k) result(field)
    character(len=*), intent(in) :: text
    type(field_spans_t), intent(in) :: spans
    integer, intent(in) :: k
    character(len=:), allocatable :: field
    if (k > spans%count) then
      field = ""
    else if (spans%last(k) < spans%first(k)) then
      field = ""
    else
      field = trim_blanks(text(spans%first(k):spans%last(k)))
    end if
  end function span_text

  !> Read `path` whole into a new entry of `deck%files` (`file` = 0 when it cannot be read).
  subroutine read_whole_file(deck, path, include_line, file, log)
    type(deck_t), intent(inout) :: deck
    character(len=*), intent(in) :: path
    integer, intent(in) :: include_line
    integer, intent(out) :: file
    type(problem_log_t), intent(inout) :: log
    integer :: unit, status, file_size
    character(len=:), allocatable :: text

    file = 0
    open (newunit=unit, file=path, access="stream", form="unformatted", status="old", &
          action="read", iostat=status)
    if (status == 0) then
      inquire (unit=unit, size=file_size)
      if (file_size < 0) status = 1
    end if
    if (status == 0) then
      allocate (character(len=file_size) :: text)
      if (file_size > 0) read (unit, iostat=status) text
      close (unit)
    end if
    if (status /= 0) then
      if (include_line == 0) then
        call report_problem(log, path//": cannot open the deck file (missing, unreadable or "// &
                            "a directory)", unreadable=.true.)
      else
        call report_problem(log, line_location(deck, include_line)//": *INCLUDE: field "// &
          "FILENAME: cannot open """//path//""" (missing, unreadable or a directory; a "// &
          "relative name is taken from the directory of the including file)", unreadable=.true.)
      end if
      return
    end if
    if (deck%file_count == size(deck%files)) call grow_files(deck)
    deck%file_count = deck%file_count + 1
    file = deck%file_count
    deck%files(file)%path = path
    call move_alloc(text, deck%files(file)%text)
  end subroutine read_whole_file

  subroutine add_line(deck, file, number, first, last)
    type(deck_t), intent(inout) :: deck
    integer, intent(in) :: file, number, first, last
    integer :: n
    if (deck%line_count == size(deck%line_file)) then
      n = 2*size(deck%line_file)
      call grow_integers(deck%line_file, n)
      call grow_integers(deck%line_number, n)
      call grow_integers(deck%line_first, n)
      call grow_integers(deck%line_last, n)
    end if
    n = deck%line_count + 1
    deck%line_count = n
    deck%line_file(n) = file
    deck%line_number(n) = number
    deck%line_first(n) = first
    deck%line_last(n) = last
  end subroutine add_line

  subroutine add_block(deck, name, block)
    type(deck_t), intent(inout) :: deck
    character(len=*), intent(in) :: name
    type(open_block_t), intent(in) :: block
    type(keyword_block_t), allocatable :: larger(:)
    integer :: k
    if (deck%block_count == size(deck%blocks)) then
      allocate (larger(2*size(deck%blocks)))
      do k = 1, deck%block_count
        call move_alloc(deck%blocks(k)%name, larger(k)%name)
        larger(k)%keyword_line = deck%blocks(k)%keyword_line
        larger(k)%first_line = deck%blocks(k)%first_line
        larger(k)%last_line = deck%blocks(k)%last_line
        larger(k)%format = deck%blocks(k)%format
      end do
      call move_alloc(larger, deck%blocks)
    end if
    deck%block_count = deck%block_count + 1
    deck%blocks(deck%block_count)%name = name
    deck%blocks(deck%block_count)%keyword_line = block%keyword_line
    deck%blocks(deck%block_count)%first_line = block%first_line
    deck%blocks(deck%block_count)%last_line = block%last_line
    deck%blocks(deck%block_count)%format = block%format
  end subroutine add_block

  subroutine grow_files(deck)
    type(deck_t), intent(inout) :: deck
    type(source_file_t), allocatable :: larger(:)
    integer :: k
    allocate (larger(2*size(deck%files)))
    do k = 1, deck%file_count
      call move_alloc(deck%files(k)%path, larger(k)%path)
      call move_alloc(deck%files(k)%text, larger(k)%text)
    end do
    call move_alloc(larger, deck%files)
  end subroutine grow_files

  subroutine grow_parameters(deck)
    type(deck_t), intent(inout) :: deck
    type(deck_parameter_t), allocatable :: larger(:)
    allocate (larger(2*size(deck%parameters)))
    larger(1:deck%parameter_count) = deck%parameters(1:deck%parameter_count)
    call move_alloc(larger, deck%parameters)
  end subroutine grow_parameters

  subroutine grow_integers(values, new_size)
    integer, allocatable, intent(inout) :: values(:)
    integer, intent(in) :: new_size
    integer, allocatable :: larger(:)
    allocate (larger(new_size))
    larger(1:size(values)) = values
    call move_alloc(larger, values)
  end subroutine grow_integers

  !> `file:line` of line `line` of the line table.
  function line_location(deck, line) result(location)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: line
    character(len=:), allocatable :: location
    location = deck%files(deck%line_file(line))%path//":"//integer_text(deck%line_number(line))
  end function line_location

  !> The block whose keyword line or data holds line `line` (blocks are stored in line order).
  pure integer function block_of_line(deck, line)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: line
    integer :: low, high, middle
    low = 1
    high = deck%block_count
    block_of_line = 0
    do while (low <= high)
      middle = (low + high)/2
      if (deck%blocks(middle)%keyword_line <= line) then
        block_of_line = middle
        low = middle + 1
      else
        high = middle - 1
      end if
    end do
  end function block_of_line

  !> The text of line `line` of the line table.
  function card_text(deck, line) result(text)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: line
    character(len=:), allocatable :: text
    text = deck%files(deck%line_file(line))%text(deck%line_first(line):deck%line_last(line))
  end function card_text

  !> True when line `line` holds only blanks and tabs.
  logical function is_blank_line(deck, line)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: line
    is_blank_line = first_nonblank(deck%files(deck%line_file(line))% &
                                   text(deck%line_first(line):deck%line_last(line))) == 0
  end function is_blank_line

  !> Position of the first line feed in `text` (0 if none); a plain loop, which compilers
  !> turn into a fast scan, unlike the general substring search behind `index`.
  pure integer function position_of_newline(text)
    character(len=*), intent(in) :: text
    integer :: k
    position_of_newline = 0
    do k = 1, len(text)
      if (text(k:k) == achar(10)) then
        position_of_newline = k
        return
      end if
    end do
  end function position_of_newline

  !> Position of the first character that is neither blank nor tab (0 if none).
  pure integer function first_nonblank(text)
    character(len=*), intent(in) :: text
    first_nonblank = verify(text, " "//achar(9))
  end function first_nonblank

  !> `text` without leading and trailing blanks and tabs.
  pure function trim_blanks(text) result(trimmed)
    character(len=*), intent(in) :: text
    character(len=:), allocatable :: trimmed
    integer :: first, last
    first = verify(text, " "//achar(9))
    if (first == 0) then
      trimmed = ""
      return
    end if
    last = verify(text, " "//achar(9), back=.true.)
    trimmed = text(first:last)
  end function trim_blanks
end module deck_lexer
