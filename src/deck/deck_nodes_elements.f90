!> *NODE and *ELEMENT_SOLID: the mesh, read as fast as the cards allow (one pass, no lookups;
!> ids are resolved in the cross-check).
module deck_nodes_elements
  use error_handling, only: error_list_t
  use deck_problems, only: problem_log_t
  use deck_columns, only: field_width
  use deck_numbers, only: integer_text
  use deck_lexer, only: deck_t, card_text, trim_blanks, is_blank_line
  use deck_fields, only: card_t, open_card, next_line, require_card, get_integer, get_real, &
                         card_problem, warn_if_set
  use deck_input, only: deck_input_t
  implicit none
  private

  public :: read_nodes, read_solid_elements

  !> *NODE columns: NID 8, X Y Z 16 each, TC 8, RC 8.
  integer, parameter :: node_widths(6) = [8, 16, 16, 16, 8, 8]
  !> Element cards: 8-column ids, up to 10 per line.
  integer, parameter :: element_widths(10) = 8
  integer, parameter :: element_id_widths(2) = 8
  character(len=2), parameter :: corner_names(8) = ["N1", "N2", "N3", "N4", "N5", "N6", "N7", &
                                                    "N8"]

contains

  !> *NODE: one node per line (NID X Y Z TC RC). A TC code becomes a constraint, as in
  !> LS-DYNA; RC is ignored (solid nodes have no rotations).
  subroutine read_nodes(deck, block, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
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
        call card_problem(deck, log, card, "RC", "rotational constraint code must be 0-7, "// &
                          "found "//integer_text(rotation))
      else
        call warn_if_set(deck, card, 6, "RC", "solid nodes have no rotations", warnings)
      end if
      input%model%node_ids(n) = id
      input%node_constraints(n) = constraint
      input%node_lines(n) = line
    end do
  end subroutine read_nodes

  !> *ELEMENT_SOLID: EID PID N1..N8 on one line, or EID PID on one line and N1..N10 on the
  !> next (LS-DYNA's "ten nodes" layout, N9 and N10 blank for hexahedra). As in LS-DYNA the
  !> layout is decided from the first line of the keyword. Degenerate shapes repeat nodes.
  subroutine read_solid_elements(deck, block, input, log)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
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
