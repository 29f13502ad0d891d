!> *NODE, *ELEMENT_SOLID and *ELEMENT_SHELL(_THICKNESS): the mesh, read as fast as the cards
!> allow (one pass, no lookups; ids are resolved in the cross-check).
module deck_nodes_elements
  use kinds, only: wp
  use deck_problems, only: problem_log_t
  use deck_columns, only: field_width
  use text_format, only: integer_text, real_text
  use deck_lexer, only: deck_t, card_text, trim_blanks, is_blank_line
  use deck_fields, only: card_t, open_card, next_line, require_card, get_integer, get_real, &
                         card_problem
  use deck_input, only: deck_input_t
  use deck_keywords, only: keyword_t
  use error_handling, only: error_list_t
  implicit none
  private

  public :: read_nodes, read_solid_elements, read_shell_elements, read_thick_shell_elements

  !> *NODE columns: NID 8, X Y Z 16 each, TC 8, RC 8.
  integer, parameter :: node_widths(6) = [8, 16, 16, 16, 8, 8]
  !> Element cards: 8-column ids, up to 10 per line.
  integer, parameter :: element_widths(10) = 8
  integer, parameter :: element_id_widths(2) = 8
  !> The thickness card of *ELEMENT_SHELL_THICKNESS: THIC1-4 and BETA, 16 columns each.
  integer, parameter :: thickness_widths(5) = 16
  character(len=2), parameter :: corner_names(8) = ["N1", "N2", "N3", "N4", "N5", "N6", "N7", &
                                                    "N8"]
  character(len=5), parameter :: thickness_names(4) = ["THIC1", "THIC2", "THIC3", "THIC4"]

contains

  !> *NODE: one node per line (NID X Y Z TC RC). TC and RC codes become constraints of the
  !> translations and rotations, as in LS-DYNA (rotations act on shell nodes only; the
  !> cross-check warns about RC on a node of no shell).
  subroutine read_nodes(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, n, id, constraint, rotation

    line = 0
    do while (next_line(deck, block, line, .true.))
      call open_card(deck, block, line, node_widths, card, log)
      n = input%node_count + 1
      input%node_count = n
      call get_integer(deck, card, 1, "NID", id, log)
      call get_real(deck, card, 2, "X", input%model%coordinates(1, n), log)
      call get_real(deck, card, 3, "Y", input%model%coordinates(2, n), log)
      call get_real(deck, card, 4, "Z", input%model%coordinates(3, n), log)
      call get_integer(deck, card, 5, "TC", constraint, log)
      call get_integer(deck, card, 6, "RC", rotation, log)
      if (id <= 0 .and. .not. card%failed) call card_problem(deck, log, card, "NID", &
        "node id must be > 0, found "//integer_text(id))
      if (constraint < 0 .or. constraint > 7) then
        call card_problem(deck, log, card, "TC", "translational constraint code must be 0-7 "// &
          "(0 none, 1 x, 2 y, 3 z, 4 xy, 5 yz, 6 zx, 7 xyz), found "//integer_text(constraint))
        constraint = 0
      end if
      if (rotation < 0 .or. rotation > 7) then
        call card_problem(deck, log, card, "RC", "rotational constraint code must be 0-7 "// &
          "(0 none, 1 x, 2 y, 3 z, 4 xy, 5 yz, 6 zx, 7 xyz), found "//integer_text(rotation))
        rotation = 0
      end if
      input%model%node_ids(n) = id
      input%node_constraints(n) = constraint
      input%node_rotation_constraints(n) = rotation
      input%node_lines(n) = line
    end do
  end subroutine read_nodes

  !> *ELEMENT_SOLID: EID PID N1..N8 on one line, or EID PID on one line and N1..N10 on the
  !> next (LS-DYNA's "ten nodes" layout, N9 and N10 blank for hexahedra). As in LS-DYNA the
  !> layout is decided from the first line of the keyword. Degenerate shapes repeat nodes.
  subroutine read_solid_elements(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, n, first_node_field
    logical :: one_line

    one_line = is_one_line_layout(deck, block)
    line = 0
    do while (next_line(deck, block, line, .true.))
      n = input%solid_count + 1
      input%solid_count = n
      input%solid_lines(n) = line
      if (one_line) then
        call open_card(deck, block, line, element_widths, card, log)
      else
        call open_card(deck, block, line, element_id_widths, card, log)
      end if
      call get_integer(deck, card, 1, "EID", input%model%solid_ids(n), log)
      call get_integer(deck, card, 2, "PID", input%model%solid_part(n), log)
      if (input%model%solid_ids(n) <= 0 .and. .not. card%failed) call card_problem(deck, log, &
        card, "EID", "element id must be > 0, found "//integer_text(input%model%solid_ids(n)))
      if (input%model%solid_part(n) <= 0 .and. .not. card%failed) call card_problem(deck, log, &
        card, "PID", "every element needs a part id > 0, found "// &
        integer_text(input%model%solid_part(n)))
      first_node_field = 3
      if (.not. one_line) then
        if (.not. require_card(deck, block, line, element_widths, card, log, &
                               "the node card (N1-N8) of element "// &
                               integer_text(input%model%solid_ids(n)), "N1")) then
          input%model%solid_nodes(:, n) = 0
          input%solid_node_lines(n) = input%solid_lines(n)
          exit
        end if
        first_node_field = 1
        call check_no_extra_nodes(deck, card, log)
      end if
      input%solid_node_lines(n) = line
      call read_corner_nodes(deck, card, first_node_field, input%model%solid_nodes(:, n), log)
    end do
  end subroutine read_solid_elements

  !> *ELEMENT_SHELL: see read_shells.
  subroutine read_shell_elements(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_shells(deck, block, .false., input, log)
  end subroutine read_shell_elements

  !> *ELEMENT_SHELL_THICKNESS: see read_shells.
  subroutine read_thick_shell_elements(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_shells(deck, block, .true., input, log)
  end subroutine read_thick_shell_elements

  !> *ELEMENT_SHELL: EID PID N1 N2 N3 N4 N5 N6 N7 N8 on one line per element (8 columns each, or
  !> comma separated). N4 blank or 0 is a triangle and becomes N3, LS-DYNA's way of writing
  !> one; N5-N8 must be blank (8-node shells are not available). With `with_thickness`
  !> (*ELEMENT_SHELL_THICKNESS) a second line holds THIC1 THIC2 THIC3 THIC4 BETA, 16 columns
  !> each: a THIC of 0 takes the section's thickness in the cross-check; BETA (a material angle,
  !> which no available shell material uses) is read and not used.
  subroutine read_shells(deck, block, with_thickness, input, log)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    logical, intent(in) :: with_thickness
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(card_t) :: card
    integer :: line, n, k
    logical :: eight_nodes
    real(wp) :: angle

    line = 0
    do while (next_line(deck, block, line, .true.))
      n = input%shell_count + 1
      input%shell_count = n
      input%shell_lines(n) = line
      input%shell_thickness_lines(n) = line
      input%model%shell_thickness(:, n) = 0.0_wp
      call open_card(deck, block, line, element_widths, card, log)
      call get_integer(deck, card, 1, "EID", input%model%shell_ids(n), log)
      call get_integer(deck, card, 2, "PID", input%model%shell_part(n), log)
      if (input%model%shell_ids(n) <= 0 .and. .not. card%failed) call card_problem(deck, log, &
        card, "EID", "element id must be > 0, found "//integer_text(input%model%shell_ids(n)))
      if (input%model%shell_part(n) <= 0 .and. .not. card%failed) call card_problem(deck, log, &
        card, "PID", "every element needs a part id > 0, found "// &
        integer_text(input%model%shell_part(n)))
      call read_shell_nodes(deck, card, input%model%shell_nodes(:, n), eight_nodes, log)
      if (.not. with_thickness) cycle
      if (.not. require_card(deck, block, line, thickness_widths, card, log, "the thickness "// &
                             "card (THIC1 THIC2 THIC3 THIC4 BETA) of shell "// &
                             integer_text(input%model%shell_ids(n)), "THIC1")) exit
      input%shell_thickness_lines(n) = line
      do k = 1, 4
        call get_real(deck, card, k, thickness_names(k), input%model%shell_thickness(k, n), log)
        if (input%model%shell_thickness(k, n) < 0.0_wp) then
          call card_problem(deck, log, card, thickness_names(k), "thickness must be >= 0 (0 "// &
            "or blank: the section's T"//corner_names(k)(2:2)//"), found "// &
            real_text(input%model%shell_thickness(k, n)))
          input%model%shell_thickness(k, n) = 0.0_wp
        end if
      end do
      call get_real(deck, card, 5, "BETA", angle, log)
      ! an 8-node shell (reported) has a third line, THIC5-THIC8: step over it
      if (eight_nodes) then
        if (.not. next_line(deck, block, line, .false.)) exit
      end if
    end do
  end subroutine read_shells

  !> N1-N4 of a shell from fields 3-6, and the check that N5-N8 (fields 7-10) are blank;
  !> `eight_nodes` tells that one of N5-N8 was given (and reported). Node ids <= 0 and nodes
  !> repeated other than N4 = N3 are reported here, where no lookup is needed.
  subroutine read_shell_nodes(deck, card, nodes, eight_nodes, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    integer, intent(out) :: nodes(4)
    logical, intent(out) :: eight_nodes
    type(problem_log_t), intent(inout) :: log
    integer :: k, earlier, extra
    logical :: failed_before

    failed_before = card%failed
    card%failed = .false.
    eight_nodes = .false.
    do k = 1, 4
      call get_integer(deck, card, 2 + k, corner_names(k), nodes(k), log)
    end do
    do k = 5, 8
      call get_integer(deck, card, 2 + k, corner_names(k), extra, log)
      if (extra == 0 .or. eight_nodes) cycle
      eight_nodes = .true.
      call card_problem(deck, log, card, corner_names(k), "8-node shells are not available; "// &
        "4-node shells and triangles leave N5-N8 blank, found "//integer_text(extra))
    end do
    if (card%failed) return
    card%failed = failed_before
    do k = 1, 3
      if (nodes(k) > 0) cycle
      call card_problem(deck, log, card, corner_names(k), "node id must be > 0, found "// &
        integer_text(nodes(k))//" (a shell needs N1, N2 and N3; N4 blank or 0 makes a triangle)")
      return
    end do
    if (nodes(4) < 0) then
      call card_problem(deck, log, card, "N4", "node id must be > 0 (blank or 0: a triangle, "// &
                        "N4 = N3), found "//integer_text(nodes(4)))
      return
    end if
    if (nodes(4) == 0) nodes(4) = nodes(3)
    do k = 2, 4
      do earlier = 1, k - 1
        if (nodes(earlier) /= nodes(k) .or. (earlier == 3 .and. k == 4)) cycle
        call card_problem(deck, log, card, corner_names(k), "the shell repeats node "// &
          integer_text(nodes(k))//" ("//corner_names(earlier)//" and "//corner_names(k)// &
          "); only N4 may repeat N3 (a triangle)")
        return
      end do
    end do
  end subroutine read_shell_nodes

  !> N1..N8 from fields `first`..`first`+7; every one must be a node id > 0.
  subroutine read_corner_nodes(deck, card, first, nodes, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    integer, intent(in) :: first
    integer, intent(out) :: nodes(8)
    type(problem_log_t), intent(inout) :: log
    integer :: corner
    do corner = 1, 8
      call get_integer(deck, card, first + corner - 1, corner_names(corner), nodes(corner), log)
      if (nodes(corner) <= 0 .and. .not. card%failed) then
        call card_problem(deck, log, card, corner_names(corner), "node id "// &
          integer_text(nodes(corner))//" (an 8-node solid needs all 8 nodes; degenerate "// &
          "shapes repeat nodes, e.g. a tetrahedron N1 N2 N3 N4 N4 N4 N4 N4)")
        exit
      end if
    end do
  end subroutine read_corner_nodes

  !> N9 and N10 of the ten-node layout belong to 10-node tetrahedra, which are not available.
  subroutine check_no_extra_nodes(deck, card, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    type(problem_log_t), intent(inout) :: log
    integer :: extra(2), k
    call get_integer(deck, card, 9, "N9", extra(1), log)
    call get_integer(deck, card, 10, "N10", extra(2), log)
    do k = 1, 2
      if (extra(k) /= 0) then
        call card_problem(deck, log, card, trim(merge("N9 ", "N10", k == 1)), "10-node "// &
          "tetrahedra are not available; hexahedra leave N9 and N10 blank")
        exit
      end if
    end do
  end subroutine check_no_extra_nodes

  !> One-line layout when the first data line reaches past the EID and PID fields (or has
  !> more than two comma-separated entries), as LS-DYNA and pydyna decide it.
  logical function is_one_line_layout(deck, block)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    character(len=:), allocatable :: text
    integer :: line, comma
    is_one_line_layout = .true.
    line = 0
    if (.not. next_line(deck, block, line, .true.)) return
    text = card_text(deck, line)
    comma = index(text, ",")
    if (comma > 0) then
      is_one_line_layout = index(text(comma + 1:), ",") > 0
    else
      is_one_line_layout = len(trim_blanks(text)) > 0 .and. &
        verify(text, " "//achar(9), back=.true.) > 2*field_width(8, deck%blocks(block)%format)
    end if
    if (is_blank_line(deck, line)) is_one_line_layout = .true.
  end function is_one_line_layout
end module deck_nodes_elements
