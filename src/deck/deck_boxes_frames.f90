!> Boxes, coordinate systems and vectors: *DEFINE_BOX(_LOCAL), *DEFINE_COORDINATE_SYSTEM,
!> *DEFINE_COORDINATE_NODES, *DEFINE_COORDINATE_VECTOR and *DEFINE_VECTOR. The readers keep
!> them as written; resolve_frames turns coordinate systems and vectors into global unit
!> vectors once the nodes are known, and the cross-check asks here which nodes lie in a box and
!> what the axes of a system or the direction of a vector are.
module deck_boxes_frames
  use kinds, only: wp
  use error_handling, only: error_list_t
  use deck_problems, only: problem_log_t
  use text_format, only: integer_text, real_text
  use deck_lexer, only: deck_t, line_location
  use deck_keywords, only: keyword_t
  use deck_numbers, only: to_upper
  use deck_fields, only: card_t, next_definition, require_card, get_integer, get_real, get_text, &
                         card_problem, located_problem, located_warning
  use deck_input, only: deck_input_t, box_input_t, frame_input_t, vector_input_t, &
                        frame_by_points, frame_by_nodes, frame_by_vectors
  use deck_id_index, only: id_index_t, find_id
  implicit none
  private

  public :: read_boxes, read_local_boxes, read_point_frames, read_node_frames
  public :: read_vector_frames, read_vectors
  public :: resolve_frames, frame_axes, vector_direction, mark_nodes_in_box, axes_from_vectors

  integer, parameter :: standard_widths(8) = 10

contains

  !> *DEFINE_BOX: BOXID XMN XMX YMN YMX ZMN ZMX per definition.
  subroutine read_boxes(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_box_cards(deck, block, keyword, .false., input, log)
  end subroutine read_boxes

  !> *DEFINE_BOX_LOCAL: card 1 as *DEFINE_BOX (the bounds in local axes), card 2 XX YX ZX XV
  !> YV ZV (local x axis and a vector in the local x-y plane), card 3 CX CY CZ (local origin).
  subroutine read_local_boxes(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_box_cards(deck, block, keyword, .true., input, log)
  end subroutine read_local_boxes

  subroutine read_box_cards(deck, block, keyword, local, input, log)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    logical, intent(in) :: local
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(card_t) :: card
    type(box_input_t) :: box
    character(len=:), allocatable :: title
    character(len=3), parameter :: low(3) = ["XMN", "YMN", "ZMN"], high(3) = ["XMX", "YMX", "ZMX"]
    real(wp) :: vectors(3, 2)
    integer :: line, k
    logical :: usable

    line = 0
    do while (next_definition(deck, block, keyword%title, line, standard_widths, card, title, &
                              log, "card 1 (BOXID XMN XMX YMN YMX ZMN ZMX)", "BOXID"))
      box = box_input_t(title=title, line=line)
      call get_integer(deck, card, 1, "BOXID", box%id, log)
      do k = 1, 3
        call get_real(deck, card, 2*k, low(k), box%minimum(k), log)
        call get_real(deck, card, 2*k + 1, high(k), box%maximum(k), log)
      end do
      if (.not. card%failed) then
        if (box%id <= 0) call card_problem(deck, log, card, "BOXID", "box id must be > 0, "// &
                                           "found "//integer_text(box%id))
        do k = 1, 3
          if (box%maximum(k) < box%minimum(k)) call card_problem(deck, log, card, high(k), &
            "the box's upper bound "//real_text(box%maximum(k))//" is below its lower bound "// &
            low(k)//" = "//real_text(box%minimum(k)))
        end do
      end if
      if (local) then
        if (.not. require_card(deck, block, line, standard_widths, card, log, &
                               "card 2 (XX YX ZX XV YV ZV)", "XX")) exit
        call read_triple(deck, card, 1, ["XX", "YX", "ZX"], vectors(:, 1), log)
        call read_triple(deck, card, 4, ["XV", "YV", "ZV"], vectors(:, 2), log)
        if (.not. card%failed) then
          call axes_from_vectors(vectors(:, 1), vectors(:, 2), box%axes, usable)
          if (.not. usable) call card_problem(deck, log, card, "XX", "the local x axis (XX YX "// &
            "ZX) is zero or parallel to the vector XV YV ZV, so the axes are not defined")
        end if
        if (.not. require_card(deck, block, line, standard_widths, card, log, &
                               "card 3 (CX CY CZ)", "CX")) exit
        call read_triple(deck, card, 1, ["CX", "CY", "CZ"], box%origin, log)
      end if
      input%box_count = input%box_count + 1
      input%boxes(input%box_count) = box
    end do
  end subroutine read_box_cards

  !> *DEFINE_COORDINATE_SYSTEM: card 1 CID XO YO ZO XL YL ZL CIDL, card 2 XP YP ZP: the
  !> origin, a point on the local x axis and a point in the local x-y plane.
  subroutine read_point_frames(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    type(frame_input_t) :: frame
    character(len=:), allocatable :: title
    integer :: line, system

    line = 0
    do while (next_definition(deck, block, keyword%title, line, standard_widths, card, title, &
                              log, "card 1 (CID XO YO ZO XL YL ZL CIDL)", "CID"))
      frame = frame_input_t(title=title, kind=frame_by_points, line=line)
      call get_integer(deck, card, 1, "CID", frame%id, log)
      call read_triple(deck, card, 2, ["XO", "YO", "ZO"], frame%points(:, 1), log)
      call read_triple(deck, card, 5, ["XL", "YL", "ZL"], frame%points(:, 2), log)
      call get_integer(deck, card, 8, "CIDL", system, log)
      call check_frame_id(deck, card, frame%id, log)
      if (system /= 0) call card_problem(deck, log, card, "CIDL", "points given in another "// &
        "coordinate system are not available; give them in global coordinates (CIDL blank or 0)")
      if (.not. require_card(deck, block, line, standard_widths, card, log, "card 2 (XP YP ZP)", &
                             "XP")) exit
      call read_triple(deck, card, 1, ["XP", "YP", "ZP"], frame%points(:, 3), log)
      call add_frame(input, frame)
    end do
  end subroutine read_point_frames

  !> *DEFINE_COORDINATE_NODES: CID N1 N2 N3 FLAG DIR: origin N1, local x towards N2, N3 in the
  !> local x-y plane. FLAG = 1 (the system follows the nodes) is taken at the nodes' initial
  !> positions, with a warning; DIR other than X is refused.
  subroutine read_node_frames(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    type(frame_input_t) :: frame
    character(len=:), allocatable :: title
    character(len=:), allocatable :: direction
    integer :: line, k, flag

    line = 0
    do while (next_definition(deck, block, keyword%title, line, standard_widths, card, title, &
                              log, "card 1 (CID N1 N2 N3 FLAG DIR)", "CID"))
      frame = frame_input_t(title=title, kind=frame_by_nodes, line=line)
      call get_integer(deck, card, 1, "CID", frame%id, log)
      do k = 1, 3
        call get_integer(deck, card, k + 1, "N"//integer_text(k), frame%nodes(k), log)
      end do
      call get_integer(deck, card, 5, "FLAG", flag, log)
      call get_text(deck, card, 6, "DIR", direction, log)
      call check_frame_id(deck, card, frame%id, log)
      if (.not. card%failed) then
        do k = 1, 3
          if (frame%nodes(k) <= 0) call card_problem(deck, log, card, "N"//integer_text(k), &
            "node id must be > 0, found "//integer_text(frame%nodes(k)))
        end do
        if (flag == 1) then
          frame%follows_nodes = .true.
          call located_warning(deck, warnings, line, "FLAG", "1 (update the system as the "// &
            "nodes move) is taken as 0: crashfree uses the system at the nodes' initial positions")
        else if (flag /= 0) then
          call card_problem(deck, log, card, "FLAG", "must be 0 or 1, found "//integer_text(flag))
        end if
        if (len(direction) > 0) then
          if (to_upper(direction) /= "X") call card_problem(deck, log, card, "DIR", """"// &
            direction//""" is not available: N1-N2 must be the local x axis (DIR blank or X)")
        end if
      end if
      call add_frame(input, frame)
    end do
  end subroutine read_node_frames

  !> *DEFINE_COORDINATE_VECTOR: CID XX YX ZX XV YV ZV NID: the local x axis, a vector in the
  !> local x-y plane, and the node at the origin (0: the global origin).
  subroutine read_vector_frames(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    type(frame_input_t) :: frame
    character(len=:), allocatable :: title
    integer :: line

    line = 0
    do while (next_definition(deck, block, keyword%title, line, standard_widths, card, title, &
                              log, "card 1 (CID XX YX ZX XV YV ZV NID)", "CID"))
      frame = frame_input_t(title=title, kind=frame_by_vectors, line=line)
      call get_integer(deck, card, 1, "CID", frame%id, log)
      call read_triple(deck, card, 2, ["XX", "YX", "ZX"], frame%points(:, 2), log)
      call read_triple(deck, card, 5, ["XV", "YV", "ZV"], frame%points(:, 3), log)
      call get_integer(deck, card, 8, "NID", frame%origin_node, log)
      call check_frame_id(deck, card, frame%id, log)
      if (frame%origin_node < 0 .and. .not. card%failed) call card_problem(deck, log, card, &
        "NID", "node id must be >= 0, found "//integer_text(frame%origin_node))
      call add_frame(input, frame)
    end do
  end subroutine read_vector_frames

  !> *DEFINE_VECTOR: VID XT YT ZT XH YH ZH CID: the vector from tail to head, in coordinate
  !> system CID (0: global).
  subroutine read_vectors(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    type(vector_input_t) :: vector
    character(len=:), allocatable :: title
    integer :: line

    line = 0
    do while (next_definition(deck, block, keyword%title, line, standard_widths, card, title, &
                              log, "card 1 (VID XT YT ZT XH YH ZH CID)", "VID"))
      vector = vector_input_t(title=title, line=line)
      call get_integer(deck, card, 1, "VID", vector%id, log)
      call read_triple(deck, card, 2, ["XT", "YT", "ZT"], vector%tail, log)
      call read_triple(deck, card, 5, ["XH", "YH", "ZH"], vector%head, log)
      call get_integer(deck, card, 8, "CID", vector%frame_id, log)
      if (.not. card%failed) then
        if (vector%id <= 0) call card_problem(deck, log, card, "VID", "vector id must be > 0, "// &
                                              "found "//integer_text(vector%id))
        if (norm2(vector%head - vector%tail) == 0.0_wp) call card_problem(deck, log, card, "XH", &
          "the vector from the tail (XT YT ZT) to the head (XH YH ZH) has zero length")
        if (vector%frame_id < 0) call card_problem(deck, log, card, "CID", "must be >= 0, "// &
                                                   "found "//integer_text(vector%frame_id))
      end if
      input%vector_count = input%vector_count + 1
      input%vectors(input%vector_count) = vector
    end do
  end subroutine read_vectors

  !> Axes and origin of every coordinate system, then every vector's global direction; a
  !> repeated id, an undefined node or system, or axes that are not defined are reported.
  subroutine resolve_frames(deck, input, node_index, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(id_index_t), intent(in) :: node_index
    type(problem_log_t), intent(inout) :: log
    integer :: k, j, position(3)
    real(wp) :: axes(3, 3)
    logical :: usable

    call report_repeated_ids(deck, [(input%frames(k)%id, k=1, input%frame_count)], &
      [(input%frames(k)%line, k=1, input%frame_count)], "CID", "coordinate system", log)
    call report_repeated_ids(deck, [(input%boxes(k)%id, k=1, input%box_count)], &
      [(input%boxes(k)%line, k=1, input%box_count)], "BOXID", "box", log)
    call report_repeated_ids(deck, [(input%vectors(k)%id, k=1, input%vector_count)], &
      [(input%vectors(k)%line, k=1, input%vector_count)], "VID", "vector", log)
    do k = 1, input%frame_count
      associate (frame => input%frames(k))
        select case (frame%kind)
        case (frame_by_nodes)
          do j = 1, 3
            position(j) = find_id(node_index, frame%nodes(j))
            if (position(j) == 0 .and. frame%nodes(j) > 0) call located_problem(deck, log, &
              frame%line, "N"//integer_text(j), "node "//integer_text(frame%nodes(j))// &
              " is not defined")
          end do
          if (any(position == 0)) cycle
          frame%points = input%model%coordinates(:, position)
        case (frame_by_vectors)
          frame%points(:, 1) = 0.0_wp
          if (frame%origin_node > 0) then
            position(1) = find_id(node_index, frame%origin_node)
            if (position(1) == 0) then
              call located_problem(deck, log, frame%line, "NID", "node "// &
                integer_text(frame%origin_node)//" is not defined")
              cycle
            end if
            frame%points(:, 1) = input%model%coordinates(:, position(1))
          end if
          ! the vectors as points relative to the origin
          frame%points(:, 2) = frame%points(:, 1) + frame%points(:, 2)
          frame%points(:, 3) = frame%points(:, 1) + frame%points(:, 3)
        end select
        call axes_from_vectors(frame%points(:, 2) - frame%points(:, 1), &
                               frame%points(:, 3) - frame%points(:, 1), axes, usable)
        if (.not. usable) then
          call located_problem(deck, log, frame%line, trim(merge("N2", "XL", &
            frame%kind == frame_by_nodes)), "the local x axis has zero length or the third "// &
            "point lies on it, so coordinate system "//integer_text(frame%id)//" is not defined")
          cycle
        end if
        frame%axes = axes
        frame%origin = frame%points(:, 1)
        frame%usable = .true.
      end associate
    end do
    do k = 1, input%vector_count
      associate (vector => input%vectors(k))
        vector%direction = vector%head - vector%tail
        if (norm2(vector%direction) == 0.0_wp) cycle       ! reported by the reader
        if (vector%frame_id > 0) then
          if (.not. frame_axes(deck, input, vector%frame_id, vector%line, "CID", axes, log)) cycle
          vector%direction = matmul(axes, vector%direction)
        end if
        vector%direction = vector%direction/norm2(vector%direction)
        vector%usable = .true.
      end associate
    end do
  end subroutine resolve_frames

  !> The axes (columns: local x, y, z in global components) of coordinate system `id`. False,
  !> with a problem at `line`, field `field`, when it is not defined (or its axes are not).
  logical function frame_axes(deck, input, id, line, field, axes, log) result(found)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(in) :: input
    integer, intent(in) :: id, line
    character(len=*), intent(in) :: field
    real(wp), intent(out) :: axes(3, 3)
    type(problem_log_t), intent(inout) :: log
    integer :: k
    found = .false.
    axes = 0.0_wp
    do k = 1, input%frame_count
      if (input%frames(k)%id /= id) cycle
      ! a system whose axes are not defined has been reported where it is defined
      if (.not. input%frames(k)%usable) return
      axes = input%frames(k)%axes
      found = .true.
      return
    end do
    call located_problem(deck, log, line, field, "coordinate system "//integer_text(id)// &
      " is not defined (no *DEFINE_COORDINATE_SYSTEM, _NODES or _VECTOR with this CID)")
  end function frame_axes

  !> The global unit direction of *DEFINE_VECTOR `id`; false, with a problem at `line`, field
  !> `field`, when it is not defined.
  logical function vector_direction(deck, input, id, line, field, direction, log) result(found)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(in) :: input
    integer, intent(in) :: id, line
    character(len=*), intent(in) :: field
    real(wp), intent(out) :: direction(3)
    type(problem_log_t), intent(inout) :: log
    integer :: k
    found = .false.
    direction = 0.0_wp
    do k = 1, input%vector_count
      if (input%vectors(k)%id /= id) cycle
      if (.not. input%vectors(k)%usable) return
      direction = input%vectors(k)%direction
      found = .true.
      return
    end do
    call located_problem(deck, log, line, field, "vector "//integer_text(id)//" is not "// &
                         "defined (no *DEFINE_VECTOR with this VID)")
  end function vector_direction

  !> Set `inside(i)` to `value` for every node i inside box `id` (bounds included). False,
  !> with a problem at `line`, field `field`, when the box is not defined.
  logical function mark_nodes_in_box(deck, input, id, line, field, value, inside, log) &
    result(found)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(in) :: input
    integer, intent(in) :: id, line
    character(len=*), intent(in) :: field
    logical, intent(in) :: value
    logical, intent(inout) :: inside(:)
    type(problem_log_t), intent(inout) :: log
    integer :: k, node
    real(wp) :: local(3)
    found = .false.
    do k = 1, input%box_count
      if (input%boxes(k)%id /= id) cycle
      associate (box => input%boxes(k))
        do node = 1, input%node_count
          local = matmul(transpose(box%axes), input%model%coordinates(:, node) - box%origin)
          if (all(local >= box%minimum .and. local <= box%maximum)) inside(node) = value
        end do
      end associate
      found = .true.
      return
    end do
    call located_problem(deck, log, line, field, "box "//integer_text(id)//" is not defined "// &
                         "(no *DEFINE_BOX with this BOXID)")
  end function mark_nodes_in_box

  !> Right-handed unit axes from a local x direction and a vector in the local x-y plane:
  !> x = along/|along|, z = x cross plane (normalised), y = z cross x. `usable` is false when
  !> `along` is zero or `plane` is parallel to it (relative tolerance 1e-10).
  pure subroutine axes_from_vectors(along, plane, axes, usable)
    real(wp), intent(in) :: along(3), plane(3)
    real(wp), intent(out) :: axes(3, 3)
    logical, intent(out) :: usable
    real(wp) :: normal(3)
    axes = 0.0_wp
    usable = .false.
    if (norm2(along) == 0.0_wp) return
    axes(:, 1) = along/norm2(along)
    normal = cross(axes(:, 1), plane)
    if (norm2(normal) <= 1.0e-10_wp*norm2(plane)) return
    axes(:, 3) = normal/norm2(normal)
    axes(:, 2) = cross(axes(:, 3), axes(:, 1))
    usable = .true.
  end subroutine axes_from_vectors

  pure function cross(a, b) result(c)
    real(wp), intent(in) :: a(3), b(3)
    real(wp) :: c(3)
    c = [a(2)*b(3) - a(3)*b(2), a(3)*b(1) - a(1)*b(3), a(1)*b(2) - a(2)*b(1)]
  end function cross

  !> A second definition with an id already used is reported at its line.
  subroutine report_repeated_ids(deck, ids, lines, field, noun, log)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: ids(:), lines(:)
    character(len=*), intent(in) :: field, noun
    type(problem_log_t), intent(inout) :: log
    integer :: k, j
    do k = 2, size(ids)
      do j = 1, k - 1
        if (ids(j) /= ids(k) .or. ids(k) <= 0) cycle
        call located_problem(deck, log, lines(k), field, noun//" id "//integer_text(ids(k))// &
                             " is defined twice (first at "//line_location(deck, lines(j))//")")
        exit
      end do
    end do
  end subroutine report_repeated_ids

  subroutine check_frame_id(deck, card, id, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(in) :: card
    integer, intent(in) :: id
    type(problem_log_t), intent(inout) :: log
    if (id <= 0 .and. .not. card%failed) call card_problem(deck, log, card, "CID", &
      "coordinate system id must be > 0, found "//integer_text(id))
  end subroutine check_frame_id

  subroutine add_frame(input, frame)
    type(deck_input_t), intent(inout) :: input
    type(frame_input_t), intent(in) :: frame
    input%frame_count = input%frame_count + 1
    input%frames(input%frame_count) = frame
  end subroutine add_frame

  !> Three consecutive real fields from field `first`.
  subroutine read_triple(deck, card, first, names, values, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    integer, intent(in) :: first
    character(len=*), intent(in) :: names(3)
    real(wp), intent(out) :: values(3)
    type(problem_log_t), intent(inout) :: log
    integer :: k
    do k = 1, 3
      call get_real(deck, card, first + k - 1, trim(names(k)), values(k), log)
    end do
  end subroutine read_triple
end module deck_boxes_frames
