!> *SET_NODE(_LIST), *SET_NODE_LIST_GENERATE, *SET_NODE_GENERAL, *SET_NODE_ADD, *SET_PART(_LIST),
!> *SET_PART_LIST_GENERATE, *SET_PART_ADD, *SET_SEGMENT and *DEFINE_CURVE. Sets are kept as
!> written; the cross-check resolves them (sets of sets in any order of the deck).
module deck_sets_curves
  use kinds, only: wp
  use error_handling, only: error_list_t
  use deck_problems, only: problem_log_t
  use deck_numbers, only: to_upper, digit
  use text_format, only: integer_text, real_text
  use deck_lexer, only: deck_t
  use deck_keywords, only: keyword_t
  use deck_fields, only: card_t, open_card, next_line, next_definition, get_integer, get_real, &
                         get_text, card_problem, warn_if_set
  use deck_input, only: deck_input_t, set_input_t, append_id, set_general, set_added, &
                        general_all, general_node, general_part, general_box, &
                        general_remove_node, general_remove_part, general_remove_box
  use deck_segments, only: read_segment_nodes
  implicit none
  private

  public :: read_node_set, read_generated_node_set, read_part_set, read_segment_set, read_curve
  public :: read_generated_part_set, read_general_node_set, read_added_node_set, read_added_part_set

  integer, parameter :: standard_widths(8) = 10
  !> *DEFINE_CURVE points: abscissa and ordinate, 20 columns each.
  integer, parameter :: point_widths(2) = 20

contains

  !> *SET_NODE_LIST: see read_node_set_cards.
  subroutine read_node_set(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_node_set_cards(deck, block, keyword, .false., input, log, warnings)
  end subroutine read_node_set

  !> *SET_NODE_LIST_GENERATE: see read_node_set_cards.
  subroutine read_generated_node_set(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_node_set_cards(deck, block, keyword, .true., input, log, warnings)
  end subroutine read_generated_node_set

  !> *SET_NODE_LIST (ids, 8 per line) or *SET_NODE_LIST_GENERATE (`generated`: up to four
  !> ranges B1BEG B1END ... per line).
  subroutine read_node_set_cards(deck, block, keyword, generated, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    logical, intent(in) :: generated
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    integer :: line
    line = 0
    input%node_set_count = input%node_set_count + 1
    associate (set => input%node_sets(input%node_set_count))
      set%generated = generated
      if (.not. read_set_header(deck, block, keyword, line, set, log, warnings)) return
      if (generated) then
        call read_ranges(deck, block, line, set, log, "B")
      else
        call read_members(deck, block, line, "NID", set, log)
      end if
    end associate
  end subroutine read_node_set_cards

  !> *SET_PART_LIST: SID card, then part ids 8 per line.
  subroutine read_part_set(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    integer :: line
    line = 0
    input%part_set_count = input%part_set_count + 1
    associate (set => input%part_sets(input%part_set_count))
      if (.not. read_set_header(deck, block, keyword, line, set, log, warnings)) return
      call read_members(deck, block, line, "PID", set, log)
    end associate
  end subroutine read_part_set

  !> *SET_PART_LIST_GENERATE: SID card, then up to four ranges P1BEG P1END ... per line; a
  !> range takes every defined part with an id in it.
  subroutine read_generated_part_set(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    integer :: line
    line = 0
    input%part_set_count = input%part_set_count + 1
    associate (set => input%part_sets(input%part_set_count))
      set%generated = .true.
      if (.not. read_set_header(deck, block, keyword, line, set, log, warnings)) return
      call read_ranges(deck, block, line, set, log, "P")
    end associate
  end subroutine read_generated_part_set

  !> *SET_NODE_ADD: SID card, then node set ids 8 per line (sets of sets may nest, in any
  !> order of the deck).
  subroutine read_added_node_set(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    integer :: line
    line = 0
    input%node_set_count = input%node_set_count + 1
    associate (set => input%node_sets(input%node_set_count))
      set%kind = set_added
      if (.not. read_set_header(deck, block, keyword, line, set, log, warnings)) return
      call read_members(deck, block, line, "DSID", set, log)
    end associate
  end subroutine read_added_node_set

  !> *SET_PART_ADD: SID card, then part set ids 8 per line.
  subroutine read_added_part_set(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    integer :: line
    line = 0
    input%part_set_count = input%part_set_count + 1
    associate (set => input%part_sets(input%part_set_count))
      set%kind = set_added
      if (.not. read_set_header(deck, block, keyword, line, set, log, warnings)) return
      call read_members(deck, block, line, "DSID", set, log)
    end associate
  end subroutine read_added_part_set

  !> *SET_NODE_GENERAL: SID card, then one operation per line: OPTION E1 ... E7. ALL takes
  !> every node; NODE the nodes E1-E7; PART the nodes of the elements of parts E1-E7; BOX the
  !> nodes inside boxes E1-E7; DNODE, DPART and DBOX remove those again. The operations apply
  !> in deck order.
  subroutine read_general_node_set(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    character(len=:), allocatable :: option
    integer :: line, k, id, operation, added

    line = 0
    input%node_set_count = input%node_set_count + 1
    associate (set => input%node_sets(input%node_set_count))
      set%kind = set_general
      if (.not. read_set_header(deck, block, keyword, line, set, log, warnings)) return
      do while (next_line(deck, block, line, .true.))
        call open_card(deck, block, line, standard_widths, card, log)
        call get_text(deck, card, 1, "OPTION", option, log)
        select case (to_upper(option))
        case ("ALL")
          operation = general_all
        case ("NODE")
          operation = general_node
        case ("PART")
          operation = general_part
        case ("BOX")
          operation = general_box
        case ("DNODE")
          operation = general_remove_node
        case ("DPART")
          operation = general_remove_part
        case ("DBOX")
          operation = general_remove_box
        case default
          call card_problem(deck, log, card, "OPTION", """"//option//""" is not available; "// &
                            "use ALL, NODE, PART, BOX, DNODE, DPART or DBOX")
          cycle
        end select
        added = 0
        do k = 2, 8
          call get_integer(deck, card, k, "E"//digit(k - 1), id, log)
          if (id < 0) then
            call card_problem(deck, log, card, "E"//digit(k - 1), "id must be > 0 (blank or "// &
                              "0 entries are skipped), found "//integer_text(id))
          else if (id > 0 .and. operation == general_all) then
            call card_problem(deck, log, card, "E"//digit(k - 1), "ALL takes no ids, found "// &
                              integer_text(id))
          else if (id > 0) then
            call append_id(set%members, id, line, k)
            added = added + 1
          end if
        end do
        call append_id(set%operations, operation, line, added)
      end do
    end associate
  end subroutine read_general_node_set

  !> *SET_SEGMENT: SID card, then one segment per line: N1 N2 N3 N4 A1 A2 A3 A4. N4 blank or
  !> 0 (or equal to N3) is a triangle; the attributes A1-A4 are not used.
  subroutine read_segment_set(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, k, n

    line = 0
    input%segment_set_count = input%segment_set_count + 1
    associate (set => input%segment_sets(input%segment_set_count))
      if (.not. read_set_header(deck, block, keyword, line, set%set_input_t, log, warnings)) return
      ! at most one segment per remaining line
      n = deck%blocks(block)%last_line - line
      allocate (set%nodes(4, n), set%lines(n), set%usable(n))
      do while (next_line(deck, block, line, .true.))
        call open_card(deck, block, line, standard_widths, card, log)
        set%count = set%count + 1
        set%lines(set%count) = line
        call read_segment_nodes(deck, card, 1, set%nodes(:, set%count), set%usable(set%count), log)
        do k = 1, 4
          call warn_if_set(deck, card, k + 4, "A"//digit(k), "segment attributes are not used", &
                           warnings)
        end do
      end do
    end associate
  end subroutine read_segment_set

  !> [title] and card 1: SID DA1 DA2 DA3 DA4 SOLVER (ITS). False when the card is missing.
  logical function read_set_header(deck, block, keyword, line, set, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    integer, intent(inout) :: line
    type(set_input_t), intent(inout) :: set
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    character(len=:), allocatable :: solver
    integer :: k

    read_set_header = next_definition(deck, block, keyword%title, line, standard_widths, card, &
                                      set%title, log, "card 1 (SID DA1 DA2 DA3 DA4 SOLVER)", "SID")
    if (.not. read_set_header) return
    set%line = line
    call get_integer(deck, card, 1, "SID", set%id, log)
    call get_text(deck, card, 6, "SOLVER", solver, log)
    if (.not. card%failed .and. set%id <= 0) call card_problem(deck, log, card, "SID", &
      "set id must be > 0, found "//integer_text(set%id))
    if (len(solver) > 0 .and. to_upper(solver) /= "MECH") call card_problem(deck, log, card, &
      "SOLVER", """"//solver//""" is not available; only MECH (blank) sets are read")
    do k = 1, 4
      call warn_if_set(deck, card, k + 1, "DA"//digit(k), "set attributes are not used", warnings)
    end do
  end function read_set_header

  !> Member ids, 8 per line; blank and 0 entries are skipped.
  subroutine read_members(deck, block, line, prefix, set, log)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    integer, intent(inout) :: line
    character(len=*), intent(in) :: prefix
    type(set_input_t), intent(inout) :: set
    type(problem_log_t), intent(inout) :: log
    type(card_t) :: card
    integer :: k, id

    do while (next_line(deck, block, line, .true.))
      call open_card(deck, block, line, standard_widths, card, log)
      do k = 1, 8
        call get_integer(deck, card, k, prefix//digit(k), id, log)
        if (id < 0) then
          call card_problem(deck, log, card, prefix//digit(k), "id must be > 0 (blank or 0 "// &
                            "entries are skipped), found "//integer_text(id))
        else if (id > 0) then
          call append_id(set%members, id, line, k)
        end if
      end do
    end do
  end subroutine read_members

  !> Ranges B1BEG B1END ... B4BEG B4END (`letter` B; P for parts: P1BEG ...); a range takes
  !> every defined node (part) with an id in it.
  subroutine read_ranges(deck, block, line, set, log, letter)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    integer, intent(inout) :: line
    type(set_input_t), intent(inout) :: set
    type(problem_log_t), intent(inout) :: log
    character(len=1), intent(in) :: letter
    type(card_t) :: card
    integer :: k, first, last
    character(len=5) :: first_name, last_name

    do while (next_line(deck, block, line, .true.))
      call open_card(deck, block, line, standard_widths, card, log)
      do k = 1, 4
        first_name = letter//digit(k)//"BEG"
        last_name = letter//digit(k)//"END"
        call get_integer(deck, card, 2*k - 1, first_name, first, log)
        call get_integer(deck, card, 2*k, last_name, last, log)
        if (first == 0 .and. last == 0) cycle
        if (first <= 0) then
          call card_problem(deck, log, card, first_name, "range start must be > 0, found "// &
                            integer_text(first))
        else if (last < first) then
          call card_problem(deck, log, card, last_name, "range end "//integer_text(last)// &
                            " is smaller than its start "//integer_text(first))
        else
          call append_id(set%members, first, line, 2*k - 1)
          call append_id(set%members, last, line, 2*k)
        end if
      end do
    end do
  end subroutine read_ranges

  !> *DEFINE_CURVE: [title], LCID SIDR SFA SFO OFFA OFFO DATTYP LCINT, then one point per line
  !> (A, O in 20 columns each). Stored points are SFA*(A + OFFA), SFO*(O + OFFO), LS-DYNA's
  !> rule (scale after offset); SFA, SFO of 0 mean 1.
  subroutine read_curve(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, relaxation, data_type, n
    real(wp) :: scale(2), offset(2)
    character(len=:), allocatable :: title

    line = 0
    if (.not. next_definition(deck, block, keyword%title, line, standard_widths, card, title, log, &
                              "card 1 (LCID SIDR SFA SFO OFFA OFFO DATTYP LCINT)", "LCID")) return
    n = input%curve_count + 1
    input%curve_count = n
    input%curve_lines(n) = line
    associate (curve => input%model%curves(n))
      curve%title = title
      call get_integer(deck, card, 1, "LCID", curve%id, log)
      call get_integer(deck, card, 2, "SIDR", relaxation, log)
      call get_real(deck, card, 3, "SFA", scale(1), log)
      call get_real(deck, card, 4, "SFO", scale(2), log)
      call get_real(deck, card, 5, "OFFA", offset(1), log)
      call get_real(deck, card, 6, "OFFO", offset(2), log)
      call get_integer(deck, card, 7, "DATTYP", data_type, log)
      where (scale == 0.0_wp) scale = 1.0_wp
      if (.not. card%failed) then
        if (curve%id <= 0) call card_problem(deck, log, card, "LCID", "curve id must be > 0, "// &
                                             "found "//integer_text(curve%id))
        if (relaxation == 1) then
          call card_problem(deck, log, card, "SIDR", "1 (dynamic relaxation only) is not "// &
            "available: crashfree does no dynamic relaxation; use 0")
        else if (relaxation /= 0 .and. relaxation /= 2) then
          call card_problem(deck, log, card, "SIDR", "must be 0, 1 or 2, found "// &
                            integer_text(relaxation))
        end if
        if (data_type /= 0) call card_problem(deck, log, card, "DATTYP", "only 0 (a general "// &
          "curve with non-decreasing abscissae) is available, found "//integer_text(data_type))
      end if
      call read_points(deck, block, line, card, scale, offset, curve%abscissa, curve%ordinate, log)
    end associate
  end subroutine read_curve

  !> The points of a curve, scaled and offset, checked to have non-decreasing abscissae.
  subroutine read_points(deck, block, line, header, scale, offset, abscissa, ordinate, log)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    integer, intent(inout) :: line
    type(card_t), intent(in) :: header
    real(wp), intent(in) :: scale(2), offset(2)
    real(wp), allocatable, intent(out) :: abscissa(:), ordinate(:)
    type(problem_log_t), intent(inout) :: log
    type(card_t) :: card
    integer :: count
    real(wp) :: a, o

    ! at most one point per remaining line
    allocate (abscissa(deck%blocks(block)%last_line - line), &
              ordinate(deck%blocks(block)%last_line - line))
    count = 0
    do while (next_line(deck, block, line, .true.))
      call open_card(deck, block, line, point_widths, card, log)
      call get_real(deck, card, 1, "A", a, log)
      call get_real(deck, card, 2, "O", o, log)
      count = count + 1
      abscissa(count) = scale(1)*(a + offset(1))
      ordinate(count) = scale(2)*(o + offset(2))
      if (count > 1 .and. .not. card%failed) then
        if (abscissa(count) < abscissa(count - 1)) call card_problem(deck, log, card, "A", &
          "abscissa "//real_text(abscissa(count))//" is smaller than the previous one, "// &
          real_text(abscissa(count - 1))//" (values after SFA and OFFA); abscissae must not "// &
          "decrease")
      end if
    end do
    abscissa = abscissa(1:count)
    ordinate = ordinate(1:count)
    if (count == 0) call card_problem(deck, log, header, "A", "the curve has no points "// &
      "(one line A O per point must follow card 1)", unreadable=.true.)
  end subroutine read_points
end module deck_sets_curves
