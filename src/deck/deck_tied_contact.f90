!> Tied contacts in the deck: *CONTACT_TIED_NODES_TO_SURFACE, _SURFACE_TO_SURFACE and
!> _SHELL_EDGE_TO_SURFACE (each also _OFFSET) and *CONTACT_SPOTWELD; their readers and the
!> set-up search that turns them into `model%tied_contacts`.
!>
!> LS-DYNA's constraint formulation (Keyword Manual, *CONTACT_TIED_...; Theory Manual, "Tied
!> interfaces"): at set-up each secondary node within the search distance of a primary segment
!> is projected on it (parametric coordinates, shape functions). The non-_OFFSET forms move the
!> node onto the segment; the _OFFSET forms keep it where it is, the offset held constant (a
!> constraint here, where LS-DYNA uses a penalty: the offset does not turn with the segment).
!> Each cycle the tie itself is applied by the solver (tied_contact).
!>
!> The search distance of a segment is the larger of its shell's thickness (SBST when given)
!> plus the secondary side's SAST, and 5% of its diagonal; a node is on the segment when its
!> parametric coordinates lie within [-1.02, 1.02]. Of several segments the nearest wins. A
!> node tied by an earlier tied contact is not tied again.
module deck_tied_contact
  use kinds, only: wp
  use error_handling, only: error_list_t
  use model, only: tied_contact_t, tied_nodes_to_surface, tied_surface_to_surface, tied_shell_edge_to_surface, &
                   tied_spotweld, surface_segment_set, surface_part_set, surface_part, surface_node_set
  use deck_problems, only: problem_log_t
  use text_format, only: integer_text, real_text
  use deck_lexer, only: deck_t
  use deck_keywords, only: keyword_t
  use deck_fields, only: card_t, next_line, open_card, get_integer, get_real, card_problem, warn_if_set, &
                         id_heading, located_problem, located_warning, require_card
  use deck_input, only: deck_input_t
  use deck_tied_input, only: tied_entry_t
  use contact_surfaces, only: append_exterior_faces, append_part_shells
  implicit none
  private

  public :: read_tied_nodes_to_surface, read_tied_nodes_to_surface_offset, read_tied_surface_to_surface, &
            read_tied_surface_to_surface_offset, read_tied_shell_edge_to_surface, &
            read_tied_shell_edge_to_surface_offset, read_spotweld_contacts, build_tied_contacts

  integer, parameter :: standard_widths(8) = 10
  !> Parametric tolerance of "on the segment" and the share of its diagonal in the search distance.
  real(wp), parameter :: parametric_tolerance = 1.02_wp, diagonal_share = 0.05_wp

contains

  !> *CONTACT_TIED_NODES_TO_SURFACE (_ID, _TITLE).
  subroutine read_tied_nodes_to_surface(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_tied_cards(deck, block, keyword, tied_nodes_to_surface, .false., input, log, warnings)
  end subroutine read_tied_nodes_to_surface

  !> *CONTACT_TIED_NODES_TO_SURFACE_OFFSET (_ID, _TITLE).
  subroutine read_tied_nodes_to_surface_offset(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_tied_cards(deck, block, keyword, tied_nodes_to_surface, .true., input, log, warnings)
  end subroutine read_tied_nodes_to_surface_offset

  !> *CONTACT_TIED_SURFACE_TO_SURFACE (_ID, _TITLE).
  subroutine read_tied_surface_to_surface(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_tied_cards(deck, block, keyword, tied_surface_to_surface, .false., input, log, warnings)
  end subroutine read_tied_surface_to_surface

  !> *CONTACT_TIED_SURFACE_TO_SURFACE_OFFSET (_ID, _TITLE).
  subroutine read_tied_surface_to_surface_offset(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_tied_cards(deck, block, keyword, tied_surface_to_surface, .true., input, log, warnings)
  end subroutine read_tied_surface_to_surface_offset

  !> *CONTACT_TIED_SHELL_EDGE_TO_SURFACE (_ID, _TITLE): rotations tied too.
  subroutine read_tied_shell_edge_to_surface(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_tied_cards(deck, block, keyword, tied_shell_edge_to_surface, .false., input, log, warnings)
  end subroutine read_tied_shell_edge_to_surface

  !> *CONTACT_TIED_SHELL_EDGE_TO_SURFACE_OFFSET (_ID, _TITLE): rotations tied too.
  subroutine read_tied_shell_edge_to_surface_offset(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_tied_cards(deck, block, keyword, tied_shell_edge_to_surface, .true., input, log, warnings)
  end subroutine read_tied_shell_edge_to_surface_offset

  !> *CONTACT_SPOTWELD (_ID, _TITLE): the nodes of spot-weld beams tied to the sheets, their
  !> rotations too; the offset is kept (the beam ends are not moved).
  subroutine read_spotweld_contacts(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_tied_cards(deck, block, keyword, tied_spotweld, .true., input, log, warnings)
  end subroutine read_spotweld_contacts

  !> One tied contact: [ID card CID HEADING] card 1 SURFA SURFB SURFATYP SURFBTYP SABOXID SBBOXID
  !> SAPR SBPR; card 2 FS FD DC VC VDC PENCHK BT DT (read over: a tie has no friction; BT DT
  !> warned); card 3 SFSA SFSB SAST SBST ... (SAST SBST: thicknesses of the search).
  subroutine read_tied_cards(deck, block, keyword, kind, offset, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    integer, intent(in) :: kind
    logical, intent(in) :: offset
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    type(tied_entry_t) :: entry
    character(len=:), allocatable :: heading
    integer :: line, value, k, first_line
    character(len=8), parameter :: type_names(2) = ["SURFATYP", "SURFBTYP"], id_names(2) = ["SURFA   ", "SURFB   "]

    line = 0
    entry = tied_entry_t(kind=kind, offset=offset)
    if (keyword%id .or. keyword%title) then
      if (.not. require_card(deck, block, line, [10, 150], card, log, "the ID card (CID HEADING)", "CID")) return
      call id_heading(deck, block, line, "CID", entry%id, heading, log)
      if (entry%id <= 0) call located_problem(deck, log, line, "CID", "contact id must be > 0, found "// &
                                              integer_text(entry%id))
    end if
    if (.not. require_card(deck, block, line, standard_widths, card, log, &
                           "card 1 (SURFA SURFB SURFATYP SURFBTYP)", "SURFA")) return
    entry%line = line
    first_line = line
    call get_integer(deck, card, 1, "SURFA", entry%side_ids(1), log)
    call get_integer(deck, card, 2, "SURFB", entry%side_ids(2), log)
    call get_integer(deck, card, 3, "SURFATYP", entry%side_types(1), log)
    call get_integer(deck, card, 4, "SURFBTYP", entry%side_types(2), log)
    call get_integer(deck, card, 5, "SABOXID", value, log)
    if (value /= 0) call card_problem(deck, log, card, "SABOXID", "contact boxes are not available; leave it blank")
    call get_integer(deck, card, 6, "SBBOXID", value, log)
    if (value /= 0) call card_problem(deck, log, card, "SBBOXID", "contact boxes are not available; leave it blank")
    call warn_if_set(deck, card, 7, "SAPR", "no ncforc/intfor output", warnings)
    call warn_if_set(deck, card, 8, "SBPR", "no ncforc/intfor output", warnings)
    if (.not. card%failed) then
      do k = 1, 2
        if (entry%side_ids(k) <= 0) call card_problem(deck, log, card, trim(id_names(k)), &
          "must be a set or part id > 0, found "//integer_text(entry%side_ids(k)))
      end do
      select case (entry%side_types(1))
      case (surface_segment_set, surface_part_set, surface_part, surface_node_set)
      case default
        call card_problem(deck, log, card, type_names(1), "surface type "//integer_text(entry%side_types(1))// &
          " is not available for a tied contact; use 0 (segment set), 2 (part set), 3 (part) or 4 (node set)")
      end select
      select case (entry%side_types(2))
      case (surface_segment_set, surface_part_set, surface_part)
      case default
        call card_problem(deck, log, card, type_names(2), "surface type "//integer_text(entry%side_types(2))// &
          " is not available for the primary side of a tied contact; use 0 (segment set), 2 (part set) or 3 (part)")
      end select
    end if
    ! card 2: FS FD DC VC VDC PENCHK BT DT
    if (next_line(deck, block, line, .false.)) then
      call open_card(deck, block, line, standard_widths, card, log)
      do k = 1, 5
        call warn_if_set(deck, card, k, trim(card2_name(k)), "a tie has no friction or damping", warnings)
      end do
      call warn_if_set(deck, card, 6, "PENCHK", "a tie has no penetration check", warnings)
      call warn_if_set(deck, card, 7, "BT", "ties act from the start to the end of the run", warnings)
      call warn_if_set(deck, card, 8, "DT", "ties act from the start to the end of the run", warnings)
    end if
    ! card 3: SFSA SFSB SAST SBST SFSAT SFSBT FSF VSF
    if (line == first_line + 1 .and. next_line(deck, block, line, .false.)) then
      call open_card(deck, block, line, standard_widths, card, log)
      call warn_if_set(deck, card, 1, "SFSA", "a tie is a constraint, not a penalty", warnings)
      call warn_if_set(deck, card, 2, "SFSB", "a tie is a constraint, not a penalty", warnings)
      call get_real(deck, card, 3, "SAST", entry%thickness(1), log)
      call get_real(deck, card, 4, "SBST", entry%thickness(2), log)
      if (.not. card%failed) then
        if (entry%thickness(1) < 0.0_wp) call card_problem(deck, log, card, "SAST", &
          "must be >= 0 (a thickness), found "//real_text(entry%thickness(1)))
        if (entry%thickness(2) < 0.0_wp) call card_problem(deck, log, card, "SBST", &
          "must be >= 0 (a thickness), found "//real_text(entry%thickness(2)))
      end if
      if (next_line(deck, block, line, .true.)) call located_warning(deck, warnings, line, "SOFT", &
        "optional cards A to G are read over (a tie uses none of their options)")
    end if
    input%tied%count = input%tied%count + 1
    input%tied%entries(input%tied%count) = entry
  contains
    pure function card2_name(k) result(name)
      integer, intent(in) :: k
      character(len=3) :: name
      character(len=3), parameter :: names(5) = ["FS ", "FD ", "DC ", "VC ", "VDC"]
      name = names(k)
    end function card2_name
  end subroutine read_tied_cards

  !> Cross-check and set-up search of every tied contact (after the segment sets are in the
  !> model, build_contacts): sides resolved, nodes projected, non-_OFFSET nodes moved onto
  !> their segments. A contact that ties no node is reported.
  subroutine build_tied_contacts(deck, input, log, warnings)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(tied_contact_t), allocatable :: ties(:)
    integer, allocatable :: secondary(:), segments(:, :), owners(:)
    logical, allocatable :: tied_before(:)
    integer :: k, j, next_id, count
    logical :: good

    allocate (ties(input%tied%count), tied_before(input%node_count))
    tied_before = .false.
    next_id = 0
    do k = 1, input%tied%count
      next_id = max(next_id, input%tied%entries(k)%id)
    end do
    do k = 1, size(input%model%contacts)
      next_id = max(next_id, input%model%contacts(k)%id)
    end do
    count = 0
    do k = 1, input%tied%count
      associate (entry => input%tied%entries(k))
        count = count + 1
        ties(count)%id = entry%id
        if (ties(count)%id == 0) then
          next_id = next_id + 1
          ties(count)%id = next_id
        end if
        ties(count)%kind = entry%kind
        ties(count)%offset = entry%offset
        ties(count)%rotations = entry%kind == tied_shell_edge_to_surface .or. entry%kind == tied_spotweld
        do j = 1, count - 1
          if (ties(j)%id == ties(count)%id .and. entry%id /= 0) then
            call located_problem(deck, log, entry%line, "SURFA", "tied contact id "//integer_text(entry%id)// &
                                 " is defined twice")
            exit
          end if
        end do
        if (input%model%implicit_static) call located_problem(deck, log, entry%line, "SURFA", &
          "tied contacts are not available in the linear static analysis (*CONTROL_IMPLICIT_GENERAL IMFLAG = 1)")
        call secondary_nodes(entry, secondary, good)
        if (good) call primary_segments(entry, segments, owners, good)
        if (.not. good) then
          count = count - 1
          cycle
        end if
        call tie_nodes(entry, secondary, segments, owners, ties(count))
        if (size(ties(count)%nodes) == 0) then
          call located_problem(deck, log, entry%line, "SURFA", "tied contact "//integer_text(ties(count)%id)// &
            " ties no node: no secondary node lies within the search distance of a primary segment "// &
            "(the larger of the shell thicknesses, SAST + SBST, and 5% of the segment's diagonal)")
        else if (size(ties(count)%nodes) < size(secondary)) then
          call located_warning(deck, warnings, entry%line, "SURFA", integer_text(size(secondary) - &
            size(ties(count)%nodes))//" of the "//integer_text(size(secondary))//" secondary nodes of tied "// &
            "contact "//integer_text(ties(count)%id)//" are not tied (no primary segment within the search "// &
            "distance, or tied by an earlier tied contact)")
        end if
      end associate
    end do
    input%model%tied_contacts = ties(1:count)
  contains
    !> The secondary side's nodes, ascending.
    subroutine secondary_nodes(entry, nodes, good)
      type(tied_entry_t), intent(in) :: entry
      integer, allocatable, intent(out) :: nodes(:)
      logical, intent(out) :: good
      logical, allocatable :: chosen(:)
      integer :: j, set, m
      allocate (chosen(input%node_count))
      chosen = .false.
      good = .true.
      associate (model => input%model)
        select case (entry%side_types(1))
        case (surface_node_set)
          set = find_node_set(entry%side_ids(1))
          if (set == 0) then
            call located_problem(deck, log, entry%line, "SURFA", "node set "//integer_text(entry%side_ids(1))// &
                                 " is not defined")
            good = .false.
          else
            chosen(model%node_sets(set)%nodes) = .true.
          end if
        case (surface_segment_set)
          set = find_segment_set(entry%side_ids(1))
          if (set == 0) then
            call located_problem(deck, log, entry%line, "SURFA", "segment set "//integer_text(entry%side_ids(1))// &
                                 " is not defined")
            good = .false.
          else
            do j = 1, size(model%segment_sets(set)%nodes, 2)
              chosen(model%segment_sets(set)%nodes(:, j)) = .true.
            end do
          end if
        case (surface_part, surface_part_set)
          do m = 1, size(model%parts)
            if (.not. side_has_part(entry, 1, m, good)) cycle
            do j = 1, size(model%solid_part)
              if (model%solid_part(j) == m) chosen(model%solid_nodes(:, j)) = .true.
            end do
            do j = 1, size(model%shell_part)
              if (model%shell_part(j) == m) chosen(model%shell_nodes(:, j)) = .true.
            end do
            ! beams: their two nodes (spot weld beams of *CONTACT_SPOTWELD), not the
            ! orientation node
            if (allocated(model%beam_part)) then
              do j = 1, size(model%beam_part)
                if (model%beam_part(j) == m) chosen(model%beam_nodes(1:2, j)) = .true.
              end do
            end if
          end do
        end select
      end associate
      nodes = pack([(j, j=1, input%node_count)], chosen)
    end subroutine secondary_nodes

    !> The primary side's segments and their owners (minus a shell's index, a solid's index).
    subroutine primary_segments(entry, segments, owners, good)
      type(tied_entry_t), intent(in) :: entry
      integer, allocatable, intent(out) :: segments(:, :), owners(:)
      logical, intent(out) :: good
      integer :: set, m, used
      good = .true.
      allocate (segments(4, 0), owners(0))
      used = 0
      associate (model => input%model)
        if (entry%side_types(2) == surface_segment_set) then
          set = find_segment_set(entry%side_ids(2))
          if (set == 0) then
            call located_problem(deck, log, entry%line, "SURFB", "segment set "//integer_text(entry%side_ids(2))// &
                                 " is not defined")
            good = .false.
            return
          end if
          segments = model%segment_sets(set)%nodes
          allocate (owners(size(segments, 2)))
          owners = 0
          return
        end if
        do m = 1, size(model%parts)
          if (.not. side_has_part(entry, 2, m, good)) cycle
          call append_part_shells(model%shell_nodes, model%shell_part, m, segments, owners, used)
          call append_exterior_faces(model%solid_nodes, model%solid_part, m, input%node_count, segments, owners, used)
        end do
        segments = segments(:, 1:used)
        owners = owners(1:used)
      end associate
    end subroutine primary_segments

    !> Whether part `m` is on side `side` (a part or a part set); reports an unknown id once
    !> (on the first part) and sets good false.
    logical function side_has_part(entry, side, m, good)
      type(tied_entry_t), intent(in) :: entry
      integer, intent(in) :: side, m
      logical, intent(inout) :: good
      integer :: set, j
      character(len=5), parameter :: names(2) = ["SURFA", "SURFB"]
      side_has_part = .false.
      associate (model => input%model)
        if (entry%side_types(side) == surface_part) then
          side_has_part = model%parts(m)%id == entry%side_ids(side)
          if (m == 1 .and. .not. any([(model%parts(set)%id, set=1, size(model%parts))] == entry%side_ids(side))) then
            call located_problem(deck, log, entry%line, names(side), "part "//integer_text(entry%side_ids(side))// &
                                 " is not defined")
            good = .false.
          end if
        else
          set = 0
          do j = 1, size(model%part_sets)
            if (model%part_sets(j)%id == entry%side_ids(side)) set = j
          end do
          if (set == 0) then
            if (m == 1) then
              call located_problem(deck, log, entry%line, names(side), "part set "// &
                                   integer_text(entry%side_ids(side))//" is not defined")
              good = .false.
            end if
            return
          end if
          side_has_part = any(model%part_sets(set)%parts == m)
        end if
      end associate
    end function side_has_part

    integer function find_node_set(id)
      integer, intent(in) :: id
      integer :: j
      find_node_set = 0
      do j = 1, size(input%model%node_sets)
        if (input%model%node_sets(j)%id == id) find_node_set = j
      end do
    end function find_node_set

    integer function find_segment_set(id)
      integer, intent(in) :: id
      integer :: j
      find_segment_set = 0
      do j = 1, size(input%model%segment_sets)
        if (input%model%segment_sets(j)%id == id) find_segment_set = j
      end do
    end function find_segment_set

    !> Project every secondary node on the nearest segment within its search distance. The
    !> segments are sorted into a grid of cells of the largest search box, so the search is
    !> linear in the number of nodes and segments.
    subroutine tie_nodes(entry, secondary, segments, owners, tie)
      type(tied_entry_t), intent(in) :: entry
      integer, intent(in) :: secondary(:), segments(:, :), owners(:)
      type(tied_contact_t), intent(inout) :: tie
      real(wp), allocatable :: reach(:), weights(:, :), low(:, :), high(:, :)
      integer, allocatable :: chosen(:), cell_first(:), cell_next(:), tied_nodes(:)
      real(wp) :: x(3, 4), point(3), best, distance, shape(4), best_shape(4), thickness, origin(3), cell, span(3)
      integer :: s, n, node, best_segment, used, cells(3), c(3), i, a, b, d, index, lower(3), upper(3)
      associate (model => input%model)
        allocate (reach(size(segments, 2)), low(3, size(segments, 2)), high(3, size(segments, 2)))
        do s = 1, size(segments, 2)
          x = model%coordinates(:, segments(:, s))
          thickness = entry%thickness(1) + entry%thickness(2)
          if (entry%thickness(2) <= 0.0_wp .and. owners(s) < 0) &
            thickness = entry%thickness(1) + sum(model%shell_thickness(:, -owners(s)))/4.0_wp
          reach(s) = max(thickness, diagonal_share*max(norm2(x(:, 3) - x(:, 1)), norm2(x(:, 4) - x(:, 2))))
          low(:, s) = minval(x, dim=2) - reach(s)
          high(:, s) = maxval(x, dim=2) + reach(s)
        end do
        allocate (chosen(size(secondary)), weights(4, size(secondary)), tied_nodes(size(secondary)))
        used = 0
        if (size(segments, 2) > 0 .and. size(secondary) > 0) then
          ! a grid of cubic cells no smaller than the largest segment box
          origin = minval(low, dim=2)
          span = maxval(high, dim=2) - origin
          cell = max(maxval(high - low), maxval(span)/200.0_wp, tiny(1.0_wp))
          cells = max(1, min(200, int(span/cell) + 1))
          allocate (cell_first(product(cells)), cell_next(size(segments, 2)))
          cell_first = 0
          do s = size(segments, 2), 1, -1
            c = cell_of(0.5_wp*(low(:, s) + high(:, s)), origin, cell, cells)
            index = c(1) + cells(1)*(c(2) - 1 + cells(2)*(c(3) - 1))
            cell_next(s) = cell_first(index)
            cell_first(index) = s
          end do
          do n = 1, size(secondary)
            node = secondary(n)
            if (tied_before(node)) cycle
            point = model%coordinates(:, node)
            best = huge(1.0_wp)
            best_segment = 0
            c = cell_of(point, origin, cell, cells)
            lower = max(1, c - 1)
            upper = min(cells, c + 1)
            do a = lower(1), upper(1)
              do b = lower(2), upper(2)
                do d = lower(3), upper(3)
                  s = cell_first(a + cells(1)*(b - 1 + cells(2)*(d - 1)))
                  do while (s > 0)
                    if (all(point >= low(:, s)) .and. all(point <= high(:, s)) .and. &
                        all(segments(:, s) /= node)) then
                      call project(model%coordinates(:, segments(:, s)), point, shape, distance)
                      if (distance <= reach(s) .and. (distance < best .or. (distance == best .and. &
                                                                             s < best_segment))) then
                        best = distance
                        best_segment = s
                        best_shape = shape
                      end if
                    end if
                    s = cell_next(s)
                  end do
                end do
              end do
            end do
            if (best_segment == 0) cycle
            used = used + 1
            chosen(used) = best_segment
            weights(:, used) = best_shape
            tied_nodes(used) = node
            tied_before(node) = .true.
            ! non-_OFFSET: the node moves onto the segment
            if (.not. entry%offset) &
              model%coordinates(:, node) = matmul(model%coordinates(:, segments(:, best_segment)), best_shape)
          end do
        end if
        tie%nodes = tied_nodes(1:used)
        tie%segments = reshape([(segments(:, chosen(i)), i=1, used)], [4, used])
        tie%weights = weights(:, 1:used)
      end associate
    end subroutine tie_nodes
  end subroutine build_tied_contacts

  !> The grid cell (1-based, clamped to the grid) of point p.
  pure function cell_of(p, origin, cell, cells) result(cell_index)
    real(wp), intent(in) :: p(3), origin(3), cell
    integer, intent(in) :: cells(3)
    integer :: cell_index(3)
    cell_index = min(cells, max(1, int((p - origin)/cell) + 1))
  end function cell_of

  !> The point of the bilinear segment x(3, 4) nearest to `point` (Newton on the squared
  !> distance from the centre, clamped to the parametric square at the end): its shape
  !> functions and the distance. A point beyond the segment's edges by more than the
  !> parametric tolerance gets a huge distance.
  pure subroutine project(x, point, shape, distance)
    real(wp), intent(in) :: x(3, 4), point(3)
    real(wp), intent(out) :: shape(4), distance
    real(wp), parameter :: corner(2, 4) = reshape([-1, -1, 1, -1, 1, 1, -1, 1], [2, 4])
    real(wp) :: xi(2), residual(3), tangents(3, 2), normal_matrix(2, 2), right(2), determinant, step(2)
    integer :: iteration, a
    xi = 0.0_wp
    do iteration = 1, 20
      do a = 1, 4
        shape(a) = 0.25_wp*(1.0_wp + xi(1)*corner(1, a))*(1.0_wp + xi(2)*corner(2, a))
      end do
      tangents = 0.0_wp
      do a = 1, 4
        tangents(:, 1) = tangents(:, 1) + 0.25_wp*corner(1, a)*(1.0_wp + xi(2)*corner(2, a))*x(:, a)
        tangents(:, 2) = tangents(:, 2) + 0.25_wp*corner(2, a)*(1.0_wp + xi(1)*corner(1, a))*x(:, a)
      end do
      residual = matmul(x, shape) - point
      normal_matrix = matmul(transpose(tangents), tangents)
      right = -matmul(transpose(tangents), residual)
      determinant = normal_matrix(1, 1)*normal_matrix(2, 2) - normal_matrix(1, 2)*normal_matrix(2, 1)
      if (abs(determinant) <= tiny(1.0_wp)) exit
      step = [normal_matrix(2, 2)*right(1) - normal_matrix(1, 2)*right(2), &
              normal_matrix(1, 1)*right(2) - normal_matrix(2, 1)*right(1)]/determinant
      xi = max(-2.0_wp, min(2.0_wp, xi + step))
      if (maxval(abs(step)) < 1.0e-12_wp) exit
    end do
    if (any(abs(xi) > parametric_tolerance)) then
      distance = huge(1.0_wp)
      shape = 0.0_wp
      return
    end if
    xi = max(-1.0_wp, min(1.0_wp, xi))
    do a = 1, 4
      shape(a) = 0.25_wp*(1.0_wp + xi(1)*corner(1, a))*(1.0_wp + xi(2)*corner(2, a))
    end do
    distance = norm2(matmul(x, shape) - point)
  end subroutine project
end module deck_tied_contact
