!> The LS-DYNA keyword deck reader: `read_deck` turns a deck file (with its includes) into a
!> checked `model_t`, or into one error listing every problem found.
!>
!> Three passes, none of which aborts at the first problem:
!> 1. the lexer reads the files, follows *INCLUDE, collects *PARAMETER and cuts the text into
!>    keyword blocks (deck_lexer);
!> 2. each block goes to the reader of its keyword's row in the keyword table
!>    (deck_keyword_table), which turns cards into values, checking each field; the readers
!>    live in one module per keyword family (deck_nodes_elements, deck_parts_sections,
!>    deck_materials, deck_sets_curves, deck_loads_bcs, deck_controls, deck_database,
!>    deck_rigid_bodies, deck_contact);
!> 3. the cross-check resolves every id, expands sets and checks the mesh (deck_cross_check).
!> Pass 3 is skipped when a card could not be read at all, since its messages would only
!> repeat the first ones.
module deck_reader
  use error_handling, only: error_t, error_list_t, add_error
  use model, only: model_t
  use deck_problems, only: problem_log_t, report_problem, has_problems, problems_to_error, &
                           printable
  use text_format, only: integer_text
  use deck_lexer, only: deck_t, load_deck, release_deck, line_location, check_files_unchanged
  use deck_keywords, only: keyword_t, keyword_unknown
  use deck_keyword_table, only: keyword_entry_t, keyword_table, identify_keyword, handled_by_lexer, &
                                suggest_known_keyword, list_capacity
  use deck_input, only: deck_input_t, prepare_input
  use deck_cross_check, only: check_and_build
  use deck_signature, only: deck_source_t
  implicit none
  private

  public :: read_deck

contains

  !> Read the deck `path` into `model`. On any problem `error` is allocated and its message
  !> lists every problem found, one per line, as `file:line: *KEYWORD: field NAME: what is
  !> wrong`; `model` is then not usable. Unknown keywords are errors, or with
  !> `ignore_unknown` warnings in `warnings` (which also lists fields read but not used).
  !> `sources`: the files read (main deck and includes, in reading order), for a restart's check.
  subroutine read_deck(path, model, warnings, error, ignore_unknown, sources)
    character(len=*), intent(in) :: path
    type(model_t), intent(out) :: model
    type(error_list_t), intent(out) :: warnings
    type(error_t), allocatable, intent(out) :: error
    logical, intent(in) :: ignore_unknown
    type(deck_source_t), allocatable, intent(out), optional :: sources(:)
    type(deck_t) :: deck
    type(deck_input_t) :: input
    type(problem_log_t) :: log
    type(keyword_entry_t), allocatable :: table(:)
    type(keyword_t), allocatable :: keywords(:)
    integer, allocatable :: lines(:)
    integer :: block, file

    call load_deck(path, deck, log, warnings)
    table = keyword_table()
    allocate (keywords(deck%block_count), lines(deck%block_count))
    do block = 1, deck%block_count
      keywords(block) = identify_keyword(deck%blocks(block)%name, table)
      lines(block) = max(0, deck%blocks(block)%last_line - deck%blocks(block)%first_line + 1)
      if (keywords(block)%entry == keyword_unknown) call report_unknown(deck, block, table, &
        ignore_unknown, log, warnings)
    end do
    call prepare_input(list_capacity(table, keywords, lines), input)
    do block = 1, deck%block_count
      if (keywords(block)%entry == keyword_unknown) cycle
      call table(keywords(block)%entry)%reader(deck, block, keywords(block), input, log, warnings)
    end do
    call check_files_unchanged(deck, log)
    if (.not. log%unreadable) call check_and_build(deck, input, model, log, warnings)
    if (present(sources)) then
      allocate (sources(deck%file_count))
      do file = 1, deck%file_count
        sources(file)%path = deck%files(file)%path
        sources(file)%size = deck%files(file)%size
        sources(file)%modified = deck%files(file)%modified
      end do
    end if
    call release_deck(deck)
    if (has_problems(log)) then
      call problems_to_error(log, error)
      return
    end if
    model%deck_path = path
  end subroutine read_deck

  !> An unknown keyword: an error (with a spelling hint), or a warning with `ignore_unknown`.
  subroutine report_unknown(deck, block, table, ignore_unknown, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_entry_t), intent(in) :: table(:)
    logical, intent(in) :: ignore_unknown
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    character(len=:), allocatable :: where, hint, suggestion, base, name
    type(keyword_t) :: suggested
    integer :: data_lines
    where = line_location(deck, deck%blocks(block)%keyword_line)//": *"//deck%blocks(block)%name
    data_lines = deck%blocks(block)%last_line - deck%blocks(block)%first_line + 1
    name = deck%blocks(block)%name
    base = known_base(name, table)
    if (ignore_unknown .and. len(base) > 0) then
      ! a keyword crashfree reads, with an option it does not have: skipping it would drop
      ! definitions the deck relies on (a part, a load, an include)
      call report_problem(log, where//": crashfree reads *"//base//", but not with the "// &
        "option "//name(len(base) + 2:)//"; --ignore-unknown skips only keywords crashfree "// &
        "does not read at all, so remove the option or the keyword", unreadable=.true.)
      return
    end if
    if (ignore_unknown .and. index(name, "CASE_BEGIN_") == 1) then
      ! the keywords between *CASE_BEGIN_n and *CASE_END_n belong to case n only: skipping the
      ! markers would read every case's keywords into one run
      call report_problem(log, where//": *CASE blocks are not available, and --ignore-unknown "// &
        "cannot skip them: the keywords inside would be read into every case; keep one case's "// &
        "keywords and remove the *CASE_BEGIN_/*CASE_END_ lines", unreadable=.true.)
      return
    end if
    if (ignore_unknown) then
      call add_error(warnings, printable(where)//": unknown keyword skipped ("// &
                     integer_text(data_lines)//" data lines not read)")
      return
    end if
    call suggest_known_keyword(name, suggestion, base)
    ! the options may not all go together (*CONTACT_..._ID_TITLE): then the name alone
    if (len(suggestion) > 0) then
      suggested = identify_keyword(suggestion, table)
      if (suggested%entry == keyword_unknown .and. .not. handled_by_lexer(suggestion, table)) &
        suggestion = base
    end if
    hint = ""
    if (len(base) > 0 .and. len(name) > len(base) + 1) then
      if (name(:len(base) + 1) == base//"_" .and. suggestion == base) hint = &
        " (crashfree reads *"//base//", but not with "//name(len(base) + 1:)//")"
    end if
    if (len(hint) == 0 .and. len(suggestion) > 0) hint = " (did you mean *"//suggestion//"?)"
    call report_problem(log, where//": unknown keyword"//hint//"; crashfree reads the "// &
      "keywords listed in docs/keywords.md (--ignore-unknown skips the others)", unreadable=.true.)
  end subroutine report_unknown

  !> The longest keyword name (or alias) of `table` that `name` extends by options
  !> (`name` = BASE_OPTIONS), "" when none.
  function known_base(name, table) result(base)
    character(len=*), intent(in) :: name
    type(keyword_entry_t), intent(in) :: table(:)
    character(len=:), allocatable :: base
    character(len=:), allocatable :: candidate
    integer :: k, which
    base = ""
    do k = 1, size(table)
      do which = 1, 2
        if (which == 1) then
          candidate = trim(table(k)%name)
        else
          candidate = trim(table(k)%alias)
        end if
        if (len(candidate) == 0 .or. len(candidate) <= len(base)) cycle
        if (len(name) <= len(candidate) + 1) cycle
        if (name(:len(candidate) + 1) == candidate//"_") base = candidate
      end do
    end do
  end function known_base
end module deck_reader
