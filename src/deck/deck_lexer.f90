!> Reads a deck and everything it includes and cuts it into keyword blocks.
!>
!> Comment lines (`$`), `*COMMENT` blocks, `*KEYWORD`, `*INCLUDE`, `*PARAMETER` and `*END` are
!> handled here, so the keyword readers see only keyword blocks whose data lines are cards.
!> Every line kept has an entry in the line table (file, line number, byte offset), which is
!> how every later message can say `file:line`.
!>
!> Files of any size are read without holding them in memory: each file is scanned once in
!> chunks of a megabyte to build the line table, and the keyword readers then get each card's
!> text through a small window that re-reads the file at the card's 64-bit offset (sequential
!> reading refills it every quarter megabyte). Memory is the line table (about 4 bytes per
!> line) and the model, not the deck's text.
module deck_lexer
  use kinds, only: wp
  use, intrinsic :: iso_fortran_env, only: int64
  use error_handling, only: error_list_t, add_error
  use deck_problems, only: problem_log_t, report_problem, control_character_name
  use deck_numbers, only: to_upper, parse_integer, parse_real, number_ok
  use text_format, only: integer_text
  use deck_columns, only: field_spans_t, split_fields, format_standard, format_long, format_i10
  use deck_line_table, only: line_table_t, start_table, append_line, line_file, line_number, &
                             line_place
  use deck_file_io, only: file_handle_t, inspect_file, open_file, read_bytes, close_file, &
                          file_missing, file_regular, file_directory, file_fifo, file_device
  implicit none
  private

  public :: deck_t, keyword_block_t, deck_parameter_t, load_deck, check_files_unchanged, release_deck
  public :: line_location, find_parameter, trim_blanks, is_blank_line, card_text, block_of_line
  public :: load_line_text

  !> Longest line read (a comment line may be longer: it is skipped unread).
  integer, parameter, public :: max_line_length = 1048576

  !> One file of the deck.
  type :: source_file_t
    character(len=:), allocatable :: path      !< as opened (include paths resolved)
    integer(int64) :: size = 0                 !< bytes
    integer(int64) :: modified = 0             !< modification time when scanned (ns since 1970)
  end type source_file_t

  !> One keyword and its data lines (indices into the line table; none when last < first).
  !> `last_line` is the last line that is not blank; the blank lines after it, up to
  !> `end_line`, separate it from the next keyword. They are cards only where a definition
  !> still needs a card (a blank card: all its fields take their defaults), never the start
  !> of another definition.
  type :: keyword_block_t
    character(len=:), allocatable :: name      !< upper case, without `*` and format suffix
    integer :: keyword_line = 0
    integer :: first_line = 1
    integer :: last_line = 0
    integer :: end_line = 0                    !< last line, trailing blank lines included
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

  !> The bytes of one file held for reading cards back: bytes first .. first + length - 1
  !> (0 = the file's first byte) of file `file` (0: none yet). The line found last is kept
  !> too, since a reader usually asks for a line twice (is it blank? then its fields).
  type :: text_window_t
    integer :: file = 0
    type(file_handle_t) :: handle
    integer(int64) :: first = 0
    integer :: length = 0
    character(len=:), allocatable :: buffer
    integer :: line = 0                        !< the line found last (0: none)
    integer :: line_first = 1, line_last = 0   !< its text in the buffer
  end type text_window_t

  !> The whole deck: files, the line table and the keyword blocks in reading order.
  type :: deck_t
    integer :: file_count = 0
    type(source_file_t), allocatable :: files(:)
    type(line_table_t) :: lines
    integer :: block_count = 0
    type(keyword_block_t), allocatable :: blocks(:)
    integer :: parameter_count = 0
    type(deck_parameter_t), allocatable :: parameters(:)
    integer :: keyword_lines = 0               !< keyword lines read, in all files
    logical :: main_file_read = .false.        !< the main deck's text was scanned
    !> The text window. A pointer, so that the readers, which get the deck with intent(in),
    !> can still move it: it only caches what the files hold, the deck itself does not change.
    type(text_window_t), pointer :: window => null()
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

  !> What the scan of one file has found so far.
  type :: scan_state_t
    integer :: file = 0
    integer :: number = 0                       !< physical lines read
    integer :: file_format = format_standard
    logical :: ended = .false.                  !< *END read, or the file cannot be read on
    logical :: outside_reported = .false.       !< data before the first keyword was reported
    integer :: control_lines = 0                !< lines holding control characters
    integer :: long_lines = 0                   !< lines longer than max_line_length
    type(open_block_t) :: block
  end type scan_state_t

  !> Deepest include nesting accepted (a deeper chain is almost surely a file including itself).
  integer, parameter :: max_include_depth = 30
  !> Bytes read per step of the scan, and the window's first size.
  integer, parameter :: scan_chunk = 1048576, window_chunk = 262144
  !> How far into a file NUL bytes mark it as binary (as grep and git decide it).
  integer, parameter :: binary_probe = 8000
  character, parameter :: line_feed = achar(10), carriage_return = achar(13), tab = achar(9)

contains

  !> Read the deck `path` with its includes. Problems go to `log`; duplicate parameters and
  !> notes on the deck's form to `warnings`. Call `release_deck` when done with `deck`.
  subroutine load_deck(path, deck, log, warnings)
    character(len=*), intent(in) :: path
    type(deck_t), intent(out) :: deck
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    integer :: chain(0), problems_before

    problems_before = log%total
    allocate (deck%files(4), deck%blocks(64), deck%parameters(8))
    call start_table(deck%lines, 1024)
    allocate (deck%window)
    allocate (character(len=window_chunk) :: deck%window%buffer)
    call load_file(deck, path, format_standard, 0, chain, log, warnings)
    if (.not. deck%main_file_read) return
    if (deck%keyword_lines == 0) then
      call report_problem(log, path//": the file holds no keyword line (a keyword deck starts "// &
        "with *KEYWORD in column 1 and holds keywords such as *NODE); is it a keyword deck?", &
        unreadable=.true.)
    else if (log%total == problems_before .and. .not. starts_with_keyword(deck)) then
      ! (only for a deck read without problems: a damaged first line says more itself)
      call add_error(warnings, path//": the deck does not start with *KEYWORD, as an LS-DYNA "// &
        "keyword deck does (is it an include file?); it is read as a keyword deck")
    end if
  end subroutine load_deck

  !> Close the file the text window holds and free it; `deck` keeps its line table and blocks
  !> (for messages) but its text can no longer be read.
  subroutine release_deck(deck)
    type(deck_t), intent(inout) :: deck
    if (.not. associated(deck%window)) return
    call close_file(deck%window%handle)
    deallocate (deck%window)
  end subroutine release_deck

  !> True when the main deck's first keyword line is *KEYWORD.
  logical function starts_with_keyword(deck)
    type(deck_t), intent(in) :: deck
    character(len=:), allocatable :: text
    integer :: line
    starts_with_keyword = .false.
    do line = 1, deck%lines%count
      if (line_file(deck%lines, line) /= 1) cycle
      text = card_text(deck, line)
      if (len(text) == 0) cycle
      if (text(1:1) /= "*") cycle
      text = to_upper(text)
      if (len(text) >= 8) starts_with_keyword = text(1:8) == "*KEYWORD" .and. &
        verify(text(9:min(len(text), 9)), " "//tab) == 0
      return
    end do
  end function starts_with_keyword

  !> Scan one file line by line; `include_line` is the *INCLUDE card that named it (0 for the
  !> main deck), `chain` the files that include it.
  recursive subroutine load_file(deck, path, format, include_line, chain, log, warnings)
    type(deck_t), intent(inout) :: deck
    character(len=*), intent(in) :: path
    integer, intent(in) :: format, include_line
    integer, intent(in) :: chain(:)
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(scan_state_t) :: state
    type(file_handle_t) :: handle
    character(len=:), allocatable :: buffer
    integer(int64) :: buffer_start
    integer :: filled, position, newline, remainder, count
    logical :: end_of_file, unusual, read_failed

    call open_source(deck, path, include_line, state%file, handle, log, warnings)
    if (state%file == 0) return
    state%file_format = format
    allocate (character(len=scan_chunk + max_line_length) :: buffer)
    buffer_start = 0
    call read_bytes(handle, buffer_start, buffer(1:scan_chunk), filled, read_failed)
    end_of_file = filled < scan_chunk .or. read_failed
    call check_file_start(deck, path, include_line, buffer(1:filled), position, state%ended, &
                          log)
    if (include_line == 0) deck%main_file_read = .not. state%ended
    do while (.not. state%ended)
      call find_line_end(buffer(position:filled), newline, unusual)
      if (newline > max_line_length + 1) then
        call note_long_line(deck, buffer(position:position + newline - 2), state, log)
        position = position + newline
        cycle
      else if (newline > 0) then
        call take_line(deck, buffer(position:position + newline - 2), &
                       buffer_start + position - 1, unusual, chain, state, log, warnings)
        position = position + newline
        cycle
      end if
      if (end_of_file) then
        if (filled - position + 1 > max_line_length) then
          call note_long_line(deck, buffer(position:filled), state, log)
        else if (position <= filled) then
          call take_line(deck, buffer(position:filled), buffer_start + position - 1, unusual, &
                         chain, state, log, warnings)
        end if
        exit
      end if
      remainder = filled - position + 1
      if (remainder > max_line_length) then
        call skip_long_line(deck, handle, buffer, buffer_start, position, filled, &
                            end_of_file, state, log)
        cycle
      end if
      ! keep the start of the line, read on behind it
      buffer(1:remainder) = buffer(position:filled)
      buffer_start = buffer_start + (position - 1)
      position = 1
      call read_bytes(handle, buffer_start + remainder, buffer(remainder + 1:remainder + &
                      scan_chunk), count, read_failed)
      filled = remainder + count
      end_of_file = count < scan_chunk .or. read_failed
    end do
    call close_file(handle)
    ! a read error, or a file that changed size while it was scanned, must not leave a silently
    ! shorter deck
    if (read_failed) then
      call report_problem(log, deck%files(state%file)%path//": a read error after "// &
                          integer_text(buffer_start + filled)//" of its "//integer_text(deck%files(state%file)%size)// &
                          " bytes", unreadable=.true.)
    else if (buffer_start + filled /= deck%files(state%file)%size) then
      call report_problem(log, deck%files(state%file)%path//": it changed while it was read ("// &
                          integer_text(buffer_start + filled)//" bytes read, "// &
                          integer_text(deck%files(state%file)%size)//" expected); run again", unreadable=.true.)
    end if
    deallocate (buffer)
    call close_block(deck, state%file, state%file_format, chain, state%block, log, warnings)
    call report_file_totals(deck, state, log)
  end subroutine load_file

  !> Check that `path` is a regular file that can be read and add it to the deck's files
  !> (`file` = 0 when it cannot be read, after reporting why).
  subroutine open_source(deck, path, include_line, file, handle, log, warnings)
    type(deck_t), intent(inout) :: deck
    character(len=*), intent(in) :: path
    integer, intent(in) :: include_line
    integer, intent(out) :: file
    type(file_handle_t), intent(out) :: handle
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    integer :: kind
    integer(int64) :: file_size, modified
    logical :: opened

    file = 0
    call inspect_file(path, kind, file_size, modified)
    select case (kind)
    case (file_missing)
      call source_problem(deck, path, include_line, "does not exist (or a directory on its "// &
                          "path cannot be read)", log)
      return
    case (file_directory)
      call source_problem(deck, path, include_line, "is a directory", log)
      return
    case (file_fifo)
      call source_problem(deck, path, include_line, "is a FIFO (named pipe), not a regular "// &
                          "file; decks are read from regular files", log)
      return
    case (file_device)
      call source_problem(deck, path, include_line, "is a device (such as /dev/zero), not a "// &
                          "regular file; decks are read from regular files", log)
      return
    case (file_regular)
    case default
      call source_problem(deck, path, include_line, "is not a regular file (a socket?); decks "// &
                          "are read from regular files", log)
      return
    end select
    call open_file(path, handle, opened)
    if (.not. opened) then
      call source_problem(deck, path, include_line, "cannot be opened for reading (check its "// &
                          "permissions)", log)
      return
    end if
    if (file_size == 0) then
      call close_file(handle)
      if (include_line == 0) then
        call report_problem(log, path//": the deck file is empty", unreadable=.true.)
      else
        call add_error(warnings, line_location(deck, include_line)//": *INCLUDE: field "// &
                       "FILENAME: """//path//""" is empty; nothing was read from it")
      end if
      return
    end if
    if (deck%file_count == size(deck%files)) call grow_files(deck)
    deck%file_count = deck%file_count + 1
    file = deck%file_count
    deck%files(file)%path = path
    deck%files(file)%size = file_size
    deck%files(file)%modified = modified
  end subroutine open_source

  !> A file that cannot be read: `path: what` for the main deck, at the *INCLUDE card for an
  !> included file.
  subroutine source_problem(deck, path, include_line, what, log)
    type(deck_t), intent(in) :: deck
    character(len=*), intent(in) :: path, what
    integer, intent(in) :: include_line
    type(problem_log_t), intent(inout) :: log
    if (include_line == 0) then
      call report_problem(log, path//": the deck file "//what, unreadable=.true.)
    else
      call report_problem(log, line_location(deck, include_line)//": *INCLUDE: field "// &
        "FILENAME: cannot open """//path//""": it "//what//" (a relative name is taken from "// &
        "the directory of the including file)", unreadable=.true.)
    end if
  end subroutine source_problem

  !> The first bytes of a file: a UTF-8 byte-order mark is skipped (`position` is where the
  !> first line starts); UTF-16 text, compressed and binary files are reported (`stop`).
  subroutine check_file_start(deck, path, include_line, bytes, position, stop, log)
    type(deck_t), intent(in) :: deck
    character(len=*), intent(in) :: path, bytes
    integer, intent(in) :: include_line
    integer, intent(out) :: position
    logical, intent(out) :: stop
    type(problem_log_t), intent(inout) :: log
    position = 1
    stop = .true.
    if (starts_with(bytes, [255, 254]) .or. starts_with(bytes, [254, 255])) then
      call source_problem(deck, path, include_line, "is UTF-16 text; save it as plain text "// &
                          "(ASCII or UTF-8)", log)
    else if (starts_with(bytes, [31, 139])) then
      call source_problem(deck, path, include_line, "is compressed (gzip); unpack it first", log)
    else
      if (starts_with(bytes, [239, 187, 191])) position = 4
      stop = index(bytes(1:min(len(bytes), binary_probe)), achar(0)) > 0
      if (stop) call source_problem(deck, path, include_line, "holds NUL bytes near its "// &
        "start: it is a binary file (a d3plot, an archive?), not a keyword deck", log)
    end if
  end subroutine check_file_start

  pure logical function starts_with(bytes, codes)
    character(len=*), intent(in) :: bytes
    integer, intent(in) :: codes(:)
    integer :: k
    starts_with = len(bytes) >= size(codes)
    if (.not. starts_with) return
    do k = 1, size(codes)
      starts_with = starts_with .and. iachar(bytes(k:k)) == codes(k)
    end do
  end function starts_with

  !> The line at `position` of `buffer` runs on for max_line_length bytes or more: report it
  !> (unless it is a comment, which is skipped unread) and read on past its end.
  subroutine skip_long_line(deck, handle, buffer, buffer_start, position, filled, end_of_file, &
                            state, log)
    type(deck_t), intent(in) :: deck
    type(file_handle_t), intent(in) :: handle
    character(len=*), intent(inout) :: buffer
    integer(int64), intent(inout) :: buffer_start
    integer, intent(inout) :: position, filled
    logical, intent(inout) :: end_of_file
    type(scan_state_t), intent(inout) :: state
    type(problem_log_t), intent(inout) :: log
    integer :: newline

    call note_long_line(deck, buffer(position:filled), state, log)
    if (state%ended) return
    do
      newline = line_feed_position(buffer(position:filled))
      if (newline > 0) then
        position = position + newline
        return
      end if
      if (end_of_file) then
        position = filled + 1
        return
      end if
      buffer_start = buffer_start + filled
      call read_bytes(handle, buffer_start, buffer(1:scan_chunk), filled)
      position = 1
      end_of_file = filled < scan_chunk
    end do
  end subroutine skip_long_line

  !> A line longer than max_line_length, which starts with `text`: reported (once per file,
  !> then counted) unless it is a comment, and not read.
  subroutine note_long_line(deck, text, state, log)
    type(deck_t), intent(in) :: deck
    character(len=*), intent(in) :: text
    type(scan_state_t), intent(inout) :: state
    type(problem_log_t), intent(inout) :: log
    integer :: leading
    logical :: comment
    call count_line(deck, state, log)
    if (state%ended) return
    leading = first_nonblank(text)
    comment = state%block%kind == block_comment
    if (leading > 0) comment = comment .or. text(leading:leading) == "$"
    if (comment) return
    state%long_lines = state%long_lines + 1
    if (state%long_lines == 1) call report_problem(log, deck%files(state%file)%path//":"// &
      integer_text(state%number)//": the line is longer than "//integer_text(max_line_length)// &
      " characters, the longest line read (is this a keyword deck?)", unreadable=.true.)
  end subroutine note_long_line

  !> One more physical line of the file being scanned (a file of more lines than a default
  !> integer counts is reported and read no further).
  subroutine count_line(deck, state, log)
    type(deck_t), intent(in) :: deck
    type(scan_state_t), intent(inout) :: state
    type(problem_log_t), intent(inout) :: log
    if (state%number == huge(state%number)) then
      call report_problem(log, deck%files(state%file)%path//": the file has more than "// &
        integer_text(huge(state%number))//" lines; the rest is not read", unreadable=.true.)
      state%ended = .true.
      return
    end if
    state%number = state%number + 1
  end subroutine count_line

  !> Position of the first line feed in `text` (0 if none), and whether a control character
  !> other than a tab comes before it (`unusual`: a carriage return, or one to report). One
  !> plain loop over the bytes, the only pass the scan makes over a file's text; the general
  !> substring search behind `index` takes three times as long.
  pure subroutine find_line_end(text, newline, unusual)
    character(len=*), intent(in) :: text
    integer, intent(out) :: newline
    logical, intent(out) :: unusual
    integer :: k, code
    unusual = .false.
    newline = 0
    do k = 1, len(text)
      code = iachar(text(k:k))
      if (code >= 32 .and. code /= 127) cycle
      if (code == 10) then
        newline = k
        return
      end if
      if (code /= 9) unusual = .true.
    end do
  end subroutine find_line_end

  !> Position of the first line feed in `text` (0 if none).
  pure integer function line_feed_position(text)
    character(len=*), intent(in) :: text
    integer :: k
    line_feed_position = 0
    do k = 1, len(text)
      if (text(k:k) == line_feed) then
        line_feed_position = k
        return
      end if
    end do
  end function line_feed_position

  !> Classify one physical line (`text`, its line feed removed, starting at byte `start`;
  !> `unusual` when it may hold control characters): comment, keyword line, or data line of
  !> the open block.
  recursive subroutine take_line(deck, text, start, unusual, chain, state, log, warnings)
    type(deck_t), intent(inout) :: deck
    character(len=*), intent(in) :: text
    integer(int64), intent(in) :: start
    logical, intent(in) :: unusual
    integer, intent(in) :: chain(:)
    type(scan_state_t), intent(inout) :: state
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    integer :: leading, last
    character :: lead

    call count_line(deck, state, log)
    if (state%ended) return
    ! CRLF line ends (decks written on Windows) read as LF ones
    last = len(text)
    do while (last > 0)
      if (text(last:last) /= carriage_return) exit
      last = last - 1
    end do
    leading = first_nonblank(text(1:last))
    if (leading > 0) then
      lead = text(leading:leading)
    else
      lead = " "
    end if
    if (lead == "$") return
    if (leading == 1 .and. lead == "*") then
      call close_block(deck, state%file, state%file_format, chain, state%block, log, warnings)
      call add_line(deck, start, state, log)
      if (state%ended) return
      if (unusual) call check_characters(deck, text(1:last), state, log)
      deck%keyword_lines = deck%keyword_lines + 1
      call open_keyword(deck, deck%lines%count, text(1:last), state%file_format, state%block, &
                        state%ended, log, warnings)
      return
    end if
    if (state%block%kind == block_comment) return
    if (leading == 0 .and. state%block%kind == block_none) return
    call add_line(deck, start, state, log)
    if (state%ended) return
    if (unusual) call check_characters(deck, text(1:last), state, log)
    if (lead == "*") then
      call report_problem(log, line_location(deck, deck%lines%count)// &
        ": a keyword must start in column 1 (found '*' in column "//integer_text(leading)//")", &
        unreadable=.true.)
      return
    end if
    if (state%block%kind == block_none) then
      if (.not. state%outside_reported) call report_problem(log, line_location(deck, &
        deck%lines%count)//": data line before the first keyword of the file", unreadable=.true.)
      state%outside_reported = .true.
      return
    end if
    state%block%last_line = deck%lines%count
  end subroutine take_line

  !> Report the first line of a file that holds a control character other than a tab (the
  !> others are counted and reported at the end of the file).
  subroutine check_characters(deck, text, state, log)
    type(deck_t), intent(in) :: deck
    character(len=*), intent(in) :: text
    type(scan_state_t), intent(inout) :: state
    type(problem_log_t), intent(inout) :: log
    character(len=:), allocatable :: hint
    integer :: k, code
    do k = 1, len(text)
      code = iachar(text(k:k))
      if ((code < 32 .and. code /= 9) .or. code == 127) exit
    end do
    if (k > len(text)) return
    state%control_lines = state%control_lines + 1
    if (state%control_lines > 1) return
    if (code == iachar(carriage_return)) then
      hint = " (lines ended by CR alone, as in old Mac files, are not line ends: save the "// &
             "file with LF or CRLF line ends)"
    else
      hint = ""
    end if
    call report_problem(log, line_location(deck, deck%lines%count)//": column "// &
      integer_text(k)//" holds the control character "//control_character_name(code)// &
      " (byte "//integer_text(code)//"); a keyword deck is plain text (blanks, tabs or commas "// &
      "between fields)"//hint, unreadable=.true.)
  end subroutine check_characters

  !> At the end of a file: how many more lines held control characters or were too long.
  subroutine report_file_totals(deck, state, log)
    type(deck_t), intent(in) :: deck
    type(scan_state_t), intent(in) :: state
    type(problem_log_t), intent(inout) :: log
    if (state%control_lines > 1) call report_problem(log, deck%files(state%file)%path//": "// &
      integer_text(state%control_lines - 1)//" more lines hold control characters", &
      unreadable=.true.)
    if (state%long_lines > 1) call report_problem(log, deck%files(state%file)%path//": "// &
      integer_text(state%long_lines - 1)//" more lines are longer than "// &
      integer_text(max_line_length)//" characters", unreadable=.true.)
  end subroutine report_file_totals

  !> Start the block of the keyword on line `line`, whose text is `text`.
  subroutine open_keyword(deck, line, text, file_format, block, ended, log, warnings)
    type(deck_t), intent(inout) :: deck
    integer, intent(in) :: line
    character(len=*), intent(in) :: text
    integer, intent(inout) :: file_format
    type(open_block_t), intent(out) :: block
    logical, intent(out) :: ended
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    character(len=:), allocatable :: name
    integer :: name_end, suffix_format

    ended = .false.
    name_end = scan(text, " "//tab) - 1
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
      call read_keyword_options(deck, line, text(name_end + 1:), file_format, log, warnings)
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
  !> NCPU=... are accepted and not used, with one warning naming them. The format setting holds
  !> for the rest of this file and for the files it includes.
  subroutine read_keyword_options(deck, line, options, file_format, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: line
    character(len=*), intent(in) :: options
    integer, intent(inout) :: file_format
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    character(len=:), allocatable :: rest, token, unused
    integer :: token_end, status, memory

    unused = ""
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
        else
          unused = unused//" "//token
        end if
      end select
    end do
    if (len(unused) > 0) call add_error(warnings, line_location(deck, line)//": *KEYWORD:"// &
      unused//": read, not acted upon (memory is sized from the model; threads are set with "// &
      "ncpu= on the command line, and results are the same for any thread count)")
  end subroutine read_keyword_options

  !> Finish the open block: trim trailing blank lines, run *INCLUDE and *PARAMETER.
  recursive subroutine close_block(deck, file, file_format, chain, block, log, warnings)
    type(deck_t), intent(inout) :: deck
    integer, intent(in) :: file, file_format
    integer, intent(in) :: chain(:)
    type(open_block_t), intent(inout) :: block
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    integer :: end_line

    ! Trailing blank lines separate keywords and start no definition; they are kept (end_line)
    ! for a definition that still needs a card, which is then a blank card of defaults. A
    ! block of nothing but blank lines keeps one, which reads as a card of defaults.
    end_line = block%last_line
    do while (block%last_line > block%first_line)
      if (.not. is_blank_line(deck, block%last_line)) exit
      block%last_line = block%last_line - 1
    end do
    select case (block%kind)
    case (block_regular)
      deck%blocks(deck%block_count)%last_line = block%last_line
      deck%blocks(deck%block_count)%end_line = end_line
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

  !> Add the line being scanned, which starts at byte `start`, to the line table.
  subroutine add_line(deck, start, state, log)
    type(deck_t), intent(inout) :: deck
    integer(int64), intent(in) :: start
    type(scan_state_t), intent(inout) :: state
    type(problem_log_t), intent(inout) :: log
    logical :: added
    call append_line(deck%lines, state%file, state%number, start, added)
    if (added) return
    call report_problem(log, deck%files(state%file)%path//":"//integer_text(state%number)// &
      ": the deck has more than "//integer_text(huge(state%number))//" lines; the rest is "// &
      "not read", unreadable=.true.)
    state%ended = .true.
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
        larger(k)%end_line = deck%blocks(k)%end_line
        larger(k)%format = deck%blocks(k)%format
      end do
      call move_alloc(larger, deck%blocks)
    end if
    deck%block_count = deck%block_count + 1
    deck%blocks(deck%block_count)%name = name
    deck%blocks(deck%block_count)%keyword_line = block%keyword_line
    deck%blocks(deck%block_count)%first_line = block%first_line
    deck%blocks(deck%block_count)%last_line = block%last_line
    deck%blocks(deck%block_count)%end_line = block%last_line
    deck%blocks(deck%block_count)%format = block%format
  end subroutine add_block

  subroutine grow_files(deck)
    type(deck_t), intent(inout) :: deck
    type(source_file_t), allocatable :: larger(:)
    integer :: k
    allocate (larger(2*size(deck%files)))
    do k = 1, deck%file_count
      call move_alloc(deck%files(k)%path, larger(k)%path)
      larger(k)%size = deck%files(k)%size
      larger(k)%modified = deck%files(k)%modified
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

  !> `file:line` of line `line` of the line table.
  function line_location(deck, line) result(location)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: line
    character(len=:), allocatable :: location
    location = deck%files(line_file(deck%lines, line))%path//":"// &
               integer_text(line_number(deck%lines, line))
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

  !> The text of line `line` of the line table (without its line end).
  function card_text(deck, line) result(text)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: line
    character(len=:), allocatable :: text
    integer :: first, last
    call locate_line(deck, line, first, last)
    text = deck%window%buffer(first:last)
  end function card_text

  !> Put the text of line `line` into `text`; its memory is reused when the length does not
  !> change, as for the cards of a *NODE block.
  subroutine load_line_text(deck, line, text)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: line
    character(len=:), allocatable, intent(inout) :: text
    integer :: first, last
    call locate_line(deck, line, first, last)
    text = deck%window%buffer(first:last)
  end subroutine load_line_text

  !> True when line `line` holds only blanks and tabs.
  logical function is_blank_line(deck, line)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: line
    integer :: first, last
    call locate_line(deck, line, first, last)
    is_blank_line = first_nonblank(deck%window%buffer(first:last)) == 0
  end function is_blank_line

  !> Make the text window hold line `line`; its text is then window%buffer(first:last) (line
  !> end removed).
  subroutine locate_line(deck, line, first, last)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: line
    integer, intent(out) :: first, last
    type(text_window_t), pointer :: window
    character(len=:), allocatable :: larger
    integer(int64) :: start, file_end
    integer :: file, newline

    window => deck%window
    if (window%line == line) then
      first = window%line_first
      last = window%line_last
      return
    end if
    call line_place(deck%lines, line, file, start)
    file_end = deck%files(file)%size
    if (window%file /= file .or. start < window%first .or. &
        start >= window%first + window%length) call fill_window(deck, window, file, start)
    first = int(start - window%first) + 1
    newline = line_feed_position(window%buffer(first:window%length))
    if (newline == 0 .and. first > 1 .and. window%first + window%length < file_end) then
      ! the line runs past the bytes held: read from its start
      call fill_window(deck, window, file, start)
      first = 1
      newline = line_feed_position(window%buffer(1:window%length))
    end if
    if (newline == 0 .and. window%first + window%length < file_end .and. &
        len(window%buffer) <= max_line_length) then
      ! a line longer than the window (up to max_line_length): widen the window once
      allocate (character(len=max_line_length + 1) :: larger)
      call move_alloc(larger, window%buffer)
      call fill_window(deck, window, file, start)
      first = 1
      newline = line_feed_position(window%buffer(1:window%length))
    end if
    if (newline == 0) then
      last = window%length
    else
      last = first + newline - 2
    end if
    do while (last >= first)
      if (window%buffer(last:last) /= carriage_return) exit
      last = last - 1
    end do
    window%line = line
    window%line_first = first
    window%line_last = last
  end subroutine locate_line

  !> Read the bytes of file `file` from byte `start` on into the window (none when the file
  !> can no longer be opened or has become shorter).
  subroutine fill_window(deck, window, file, start)
    type(deck_t), intent(in) :: deck
    type(text_window_t), intent(inout) :: window
    integer, intent(in) :: file
    integer(int64), intent(in) :: start
    logical :: opened
    if (window%file /= file) then
      call close_file(window%handle)
      call open_file(deck%files(file)%path, window%handle, opened)
      window%file = file
      if (.not. opened) window%file = 0
    end if
    window%line = 0
    window%first = start
    window%length = 0
    if (window%file == file) call read_bytes(window%handle, start, window%buffer, window%length)
  end subroutine fill_window

  !> Whether any file of the deck changed (size or modification time) since it was scanned: its
  !> cards, read again at their byte offsets, would no longer be the ones scanned. Checked after
  !> the keyword readers ran; a changed file is reported and the deck refused.
  subroutine check_files_unchanged(deck, log)
    type(deck_t), intent(in) :: deck
    type(problem_log_t), intent(inout) :: log
    integer :: file, kind
    integer(int64) :: size, modified
    do file = 1, deck%file_count
      call inspect_file(deck%files(file)%path, kind, size, modified)
      if (kind == file_regular .and. size == deck%files(file)%size .and. modified == deck%files(file)%modified) cycle
      call report_problem(log, deck%files(file)%path//": the file changed (or went away) while the deck was "// &
                          "read; run again once it is written", unreadable=.true.)
    end do
  end subroutine check_files_unchanged

  !> Position of the first character that is neither blank nor tab (0 if none).
  pure integer function first_nonblank(text)
    character(len=*), intent(in) :: text
    first_nonblank = verify(text, " "//tab)
  end function first_nonblank

  !> `text` without leading and trailing blanks and tabs.
  pure function trim_blanks(text) result(trimmed)
    character(len=*), intent(in) :: text
    character(len=:), allocatable :: trimmed
    integer :: first, last
    first = verify(text, " "//tab)
    if (first == 0) then
      trimmed = ""
      return
    end if
    last = verify(text, " "//tab, back=.true.)
    trimmed = text(first:last)
  end function trim_blanks
end module deck_lexer
