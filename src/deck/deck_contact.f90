!> Contact keywords: *CONTACT_AUTOMATIC_NODES_TO_SURFACE, _SURFACE_TO_SURFACE and
!> _SINGLE_SURFACE (each with _ID / _TITLE), *CONTROL_CONTACT and *DATABASE_RCFORC, and the
!> cross-check that resolves the contact sides and stores the segment sets in the model.
!>
!> The readers are those of the keyword table's rows (deck_keyword_table); the contacts list
!> holds one entry per contact keyword block (deck_input).
module deck_contact
  use kinds, only: wp
  use error_handling, only: error_list_t
  use model, only: contact_t, contact_surface_t, segment_set_t, contact_nodes_to_surface, &
                   contact_surface_to_surface, contact_single_surface, surface_segment_set, &
                   surface_part_set, surface_part, surface_node_set, surface_all_parts
  use deck_problems, only: problem_log_t
  use text_format, only: integer_text, real_text
  use deck_lexer, only: deck_t, line_location
  use deck_keywords, only: keyword_t
  use deck_fields, only: card_t, open_card, next_line, require_card, get_integer, get_real, &
                         card_problem, warn_if_set, id_heading, line_problem, located_problem, &
                         located_warning, keyword_label
  use deck_input, only: deck_input_t
  use deck_contact_input, only: contact_entry_t
  use deck_database, only: check_binary
  use contact_surfaces, only: find_segment_owners, find_shell_owners
  implicit none
  private

  public :: read_nodes_to_surface_contacts, read_surface_to_surface_contacts, read_single_surface_contacts
  public :: read_control_contact, read_rcforc, build_contacts

  integer, parameter :: standard_widths(8) = 10

contains

  !> *CONTACT_AUTOMATIC_NODES_TO_SURFACE: see read_contact_cards.
  subroutine read_nodes_to_surface_contacts(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_contact_cards(deck, block, keyword, contact_nodes_to_surface, input, log, warnings)
  end subroutine read_nodes_to_surface_contacts

  !> *CONTACT_AUTOMATIC_SURFACE_TO_SURFACE: see read_contact_cards.
  subroutine read_surface_to_surface_contacts(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_contact_cards(deck, block, keyword, contact_surface_to_surface, input, log, warnings)
  end subroutine read_surface_to_surface_contacts

  !> *CONTACT_AUTOMATIC_SINGLE_SURFACE: see read_contact_cards.
  subroutine read_single_surface_contacts(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_contact_cards(deck, block, keyword, contact_single_surface, input, log, warnings)
  end subroutine read_single_surface_contacts

  !> One contact: [ID card] C1 C2 C3 [A] (cards B-G are read over with a warning).
  subroutine read_contact_cards(deck, block, keyword, kind, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    integer, intent(in) :: kind
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    type(contact_entry_t) :: entry
    character(len=:), allocatable :: heading
    integer :: line, value, types(2), k
    real(wp) :: number
    character(len=8), parameter :: type_names(2) = ["SURFATYP", "SURFBTYP"]

    line = 0
    entry%contact%kind = kind
    if (keyword%id .or. keyword%title) then
      if (.not. next_line(deck, block, line, .false.)) then
        call line_problem(deck, log, deck%blocks(block)%keyword_line, block, "CID", &
                          "the ID card (CID HEADING) is missing: the keyword has no cards", unreadable=.true.)
        return
      end if
      call id_heading(deck, block, line, "CID", entry%contact%id, heading, log)
      entry%contact%title = heading
      entry%numbered = .true.
      entry%id_line = line
      if (entry%contact%id <= 0) call line_problem(deck, log, line, block, "CID", &
        "contact id must be > 0, found "//integer_text(entry%contact%id))
    end if
    if (.not. require_card(deck, block, line, standard_widths, card, log, &
                           "card 1 (SURFA SURFB SURFATYP SURFBTYP)", "SURFA")) return
    entry%surface_line = line
    call get_integer(deck, card, 1, "SURFA", entry%contact%side_a%id, log)
    call get_integer(deck, card, 2, "SURFB", entry%contact%side_b%id, log)
    call get_integer(deck, card, 3, "SURFATYP", types(1), log)
    call get_integer(deck, card, 4, "SURFBTYP", types(2), log)
    call get_integer(deck, card, 5, "SABOXID", value, log)
    if (value /= 0) call card_problem(deck, log, card, "SABOXID", "contact boxes are not available; leave it blank")
    call get_integer(deck, card, 6, "SBBOXID", value, log)
    if (value /= 0) call card_problem(deck, log, card, "SBBOXID", "contact boxes are not available; leave it blank")
    call warn_if_set(deck, card, 7, "SAPR", "no ncforc/intfor output", warnings)
    call warn_if_set(deck, card, 8, "SBPR", "no ncforc/intfor output", warnings)
    if (.not. card%failed) then
      do k = 1, 2
        if (k == 2 .and. kind == contact_single_surface) exit
        if (.not. type_allowed(kind, k, types(k))) call card_problem(deck, log, card, &
          trim(type_names(k)), "surface type "//integer_text(types(k))//" is not available for this "// &
          "contact; use "//allowed_text(kind, k))
      end do
      entry%contact%side_a%kind = types(1)
      entry%contact%side_b%kind = types(2)
      if (kind == contact_single_surface .and. entry%contact%side_a%id == 0) &
        entry%contact%side_a%kind = surface_all_parts
      if (kind /= contact_single_surface .and. entry%contact%side_a%kind /= surface_all_parts .and. &
          entry%contact%side_a%id <= 0) call card_problem(deck, log, card, "SURFA", &
          "must be a set or part id > 0, found "//integer_text(entry%contact%side_a%id))
      if (kind /= contact_single_surface .and. entry%contact%side_b%id <= 0) call card_problem(deck, &
          log, card, "SURFB", "must be a set or part id > 0, found "//integer_text(entry%contact%side_b%id))
    end if
    ! C2: FS FD DC VC VDC PENCHK BT DT
    if (next_line(deck, block, line, .false.)) then
      call open_card(deck, block, line, standard_widths, card, log)
      call get_real(deck, card, 1, "FS", entry%contact%static_friction, log)
      call get_real(deck, card, 2, "FD", entry%contact%dynamic_friction, log)
      call get_real(deck, card, 3, "DC", entry%contact%decay, log)
      call get_real(deck, card, 4, "VC", entry%contact%viscous_friction, log)
      call get_real(deck, card, 5, "VDC", entry%contact%viscous_damping, log)
      call warn_if_set(deck, card, 6, "PENCHK", "no small-penetration check", warnings)
      call get_real(deck, card, 7, "BT", entry%contact%birth, log)
      call get_real(deck, card, 8, "DT", entry%contact%death, log)
      if (.not. card%failed) then
        associate (c => entry%contact)
          if (c%static_friction < 0.0_wp .or. c%static_friction == 2.0_wp) call card_problem(deck, log, card, &
            "FS", "friction from *PART_CONTACT or a table is not available; give FS >= 0")
          if (c%dynamic_friction < 0.0_wp) call card_problem(deck, log, card, "FD", "must be >= 0, found "// &
            real_text(c%dynamic_friction))
          if (c%decay < 0.0_wp) call card_problem(deck, log, card, "DC", "must be >= 0, found "// &
            real_text(c%decay))
          if (c%viscous_friction < 0.0_wp) call card_problem(deck, log, card, "VC", "must be >= 0, found "// &
            real_text(c%viscous_friction))
          if (c%viscous_damping < 0.0_wp .or. c%viscous_damping > 100.0_wp) call card_problem(deck, log, &
            card, "VDC", "must be 0 to 100 (percent of critical), found "//real_text(c%viscous_damping))
          c%birth = abs(c%birth)
          if (c%death < 0.0_wp) call card_problem(deck, log, card, "DT", "a death time curve or "// &
            "dynamic-relaxation flag is not available; give DT >= 0")
          if (c%death == 0.0_wp) c%death = 1.0e20_wp
          ! LS-DYNA: FD is ignored (taken equal to FS) when the decay coefficient is zero
          if (c%decay == 0.0_wp .and. c%dynamic_friction == 0.0_wp) c%dynamic_friction = c%static_friction
        end associate
      end if
    end if
    ! C3: SFSA SFSB SAST SBST SFSAT SFSBT FSF VSF
    if (line == entry%surface_line + 1 .and. next_line(deck, block, line, .false.)) then
      call open_card(deck, block, line, standard_widths, card, log)
      call get_real(deck, card, 1, "SFSA", entry%contact%scale_a, log, 1.0_wp)
      call get_real(deck, card, 2, "SFSB", entry%contact%scale_b, log, 1.0_wp)
      call warn_if_set(deck, card, 3, "SAST", "contact thickness applies to shells only", warnings)
      call warn_if_set(deck, card, 4, "SBST", "contact thickness applies to shells only", warnings)
      call get_real(deck, card, 7, "FSF", entry%contact%friction_scale, log, 1.0_wp)
      call get_real(deck, card, 8, "VSF", entry%contact%viscous_scale, log, 1.0_wp)
      if (.not. card%failed) then
        if (entry%contact%scale_a < 0.0_wp) call card_problem(deck, log, card, "SFSA", &
          "must be >= 0 (a curve is for mortar contact), found "//real_text(entry%contact%scale_a))
        if (entry%contact%scale_b < 0.0_wp) call card_problem(deck, log, card, "SFSB", &
          "must be >= 0, found "//real_text(entry%contact%scale_b))
        if (entry%contact%scale_a == 0.0_wp) entry%contact%scale_a = 1.0_wp
        if (entry%contact%scale_b == 0.0_wp) entry%contact%scale_b = 1.0_wp
        if (entry%contact%friction_scale == 0.0_wp) entry%contact%friction_scale = 1.0_wp
        if (entry%contact%viscous_scale == 0.0_wp) entry%contact%viscous_scale = 1.0_wp
      end if
      ! *CONTACT_ERODING_...: its card ISYM EROSOP IADJ comes before the optional cards
      if (index(keyword_label(deck, block), "CONTACT_ERODING_") == 1) then
        if (next_line(deck, block, line, .false.)) then
          call open_card(deck, block, line, standard_widths, card, log)
          call warn_if_set(deck, card, 1, "ISYM", "no symmetry planes in contact", warnings)
          call warn_if_set(deck, card, 3, "IADJ", "the faces of all remaining solids are exposed", warnings)
        end if
      end if
      ! optional card A: SOFT SOFSCL LCIDAB MAXPAR SBOPT DEPTH BSORT FRCFRQ
      if (next_line(deck, block, line, .false.)) then
        call open_card(deck, block, line, standard_widths, card, log)
        call get_integer(deck, card, 1, "SOFT", entry%contact%soft, log)
        call get_real(deck, card, 2, "SOFSCL", number, log)
        call warn_if_set(deck, card, 3, "LCIDAB", "no airbag thickness", warnings)
        call get_integer(deck, card, 7, "BSORT", entry%contact%bucket_interval, log)
        call get_integer(deck, card, 8, "FRCFRQ", value, log)
        if (.not. card%failed) then
          if (entry%contact%soft /= 0 .and. entry%contact%soft /= 1) call card_problem(deck, log, card, &
            "SOFT", "only 0 (penalty) and 1 (soft constraint) are available, found "// &
            integer_text(entry%contact%soft))
          if (number < 0.0_wp) call card_problem(deck, log, card, "SOFSCL", "must be >= 0, found "// &
                                                 real_text(number))
          if (number > 0.0_wp) entry%contact%soft_scale = number
          if (entry%contact%bucket_interval < 0) call card_problem(deck, log, card, "BSORT", &
            "a curve for the bucket sort interval is not available; give BSORT >= 0")
          if (value > 1) call located_warning(deck, warnings, line, "FRCFRQ", &
            "ignored (contact forces are updated every cycle)")
        end if
        if (next_line(deck, block, line, .true.)) call located_warning(deck, warnings, line, "PENMAX", &
          "optional cards B to G are read over (their options are not available)")
      end if
    end if
    call append_contact(entry)
  contains
    subroutine append_contact(new_entry)
      type(contact_entry_t), intent(in) :: new_entry
      input%contact%count = input%contact%count + 1
      input%contact%entries(input%contact%count) = new_entry
    end subroutine append_contact
  end subroutine read_contact_cards

  !> Whether surface type `code` may be given for side `side` (1 SURFA, 2 SURFB) of `kind`.
  pure logical function type_allowed(kind, side, code)
    integer, intent(in) :: kind, side, code
    select case (code)
    case (surface_segment_set, surface_part_set, surface_part)
      type_allowed = .true.
    case (surface_node_set)
      type_allowed = kind == contact_nodes_to_surface .and. side == 1
    case (surface_all_parts)
      type_allowed = kind == contact_single_surface .and. side == 1
    case default
      type_allowed = .false.
    end select
  end function type_allowed

  pure function allowed_text(kind, side) result(text)
    integer, intent(in) :: kind, side
    character(len=:), allocatable :: text
    text = "0 (segment set), 2 (part set) or 3 (part)"
    if (kind == contact_nodes_to_surface .and. side == 1) text = "0 (segment set), 2 (part set), "// &
      "3 (part) or 4 (node set)"
    if (kind == contact_single_surface) text = "0 (segment set), 2 (part set), 3 (part) or 5 (all)"
  end function allowed_text

  !> *CONTROL_CONTACT card 1: SLSFAC is used; the options that change LS-DYNA's behaviour but
  !> are not available give warnings. Card 2: NSBCS (bucket sort interval of contacts whose
  !> BSORT is 0). Further cards are read over.
  subroutine read_control_contact(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, value
    real(wp) :: scale
    line = 0
    if (.not. require_card(deck, block, line, standard_widths, card, log, &
                           "card 1 (SLSFAC RWPNAL ISLCHK SHLTHK PENOPT THKCHG ORIEN ENMASS)", "SLSFAC")) return
    call get_real(deck, card, 1, "SLSFAC", scale, log)
    call warn_if_set(deck, card, 2, "RWPNAL", "rigid walls use the constraint method", warnings)
    call warn_if_set(deck, card, 4, "SHLTHK", "no shells: solid faces have no thickness offset", warnings)
    call get_integer(deck, card, 5, "PENOPT", value, log)
    if (value > 2) call located_warning(deck, warnings, line, "PENOPT", "ignored (the stiffness "// &
      "is the segment's, as PENOPT = 2)")
    call warn_if_set(deck, card, 7, "ORIEN", "segment sets keep the orientation of their solid", warnings)
    if (card%failed) return
    if (scale < 0.0_wp) call card_problem(deck, log, card, "SLSFAC", "must be >= 0, found "// &
                                          real_text(scale))
    if (scale > 0.0_wp) input%model%contact_penalty_scale = scale
    ! card 2: USRSTR USRFRC NSBCS INTERM XPENE SSTHK ECDT TIEDPRJ; only NSBCS is used
    if (.not. next_line(deck, block, line, .false.)) return
    call open_card(deck, block, line, standard_widths, card, log)
    call get_integer(deck, card, 3, "NSBCS", value, log)
    if (card%failed) return
    if (value < 0) then
      call card_problem(deck, log, card, "NSBCS", "must be >= 0 (0: automatic), found "//integer_text(value))
      return
    end if
    input%model%contact_sort_interval = value
  end subroutine read_control_contact

  !> *DATABASE_RCFORC: DT BINARY LCUR IOOPT, as the other history databases.
  subroutine read_rcforc(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, interval_curve, binary
    real(wp) :: interval
    line = 0
    if (.not. require_card(deck, block, line, standard_widths, card, log, &
                           "card 1 (DT BINARY LCUR IOOPT)", "DT")) return
    call get_real(deck, card, 1, "DT", interval, log)
    call get_integer(deck, card, 2, "BINARY", binary, log)
    call get_integer(deck, card, 3, "LCUR", interval_curve, log)
    if (card%failed) return
    call check_binary(deck, card, binary, log)
    input%model%output%rcforc_binary = binary
    if (interval < 0.0_wp) call card_problem(deck, log, card, "DT", "output interval must "// &
      "be >= 0 (0: no output), found "//real_text(interval))
    if (interval_curve /= 0) call card_problem(deck, log, card, "LCUR", "output intervals from a "// &
      "curve are not available; give DT")
    input%model%output%rcforc_interval = interval
  end subroutine read_rcforc

  !> Cross-check: store the segment sets in the model, number the contacts without an id,
  !> resolve each side (part, part set, segment set, node set, all parts) and list every id
  !> that does not exist.
  subroutine build_contacts(deck, input, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    integer :: k, j, next_id
    logical, allocatable :: owners_checked(:)
    allocate (owners_checked(input%segment_set_count))
    owners_checked = .false.
    associate (model => input%model)
      allocate (model%segment_sets(input%segment_set_count))
      do k = 1, input%segment_set_count
        associate (given => input%segment_sets(k))
          model%segment_sets(k)%id = given%id
          if (allocated(given%title)) model%segment_sets(k)%title = given%title
          if (allocated(given%nodes) .and. allocated(given%usable)) then
            model%segment_sets(k)%nodes = given%nodes(:, pack([(j, j=1, given%count)], &
                                                               given%usable(1:given%count)))
          else
            allocate (model%segment_sets(k)%nodes(4, 0))
          end if
        end associate
      end do
      allocate (model%contacts(input%contact%count))
      next_id = 0
      do k = 1, input%contact%count
        if (input%contact%entries(k)%numbered) next_id = max(next_id, input%contact%entries(k)%contact%id)
      end do
      do k = 1, input%contact%count
        associate (entry => input%contact%entries(k))
          if (.not. entry%numbered) then
            next_id = next_id + 1
            entry%contact%id = next_id
          end if
          do j = 1, k - 1
            if (input%contact%entries(j)%contact%id == entry%contact%id .and. entry%numbered) then
              call located_problem(deck, log, entry%id_line, "CID", "contact id "// &
                integer_text(entry%contact%id)//" is defined twice")
              exit
            end if
          end do
          call resolve_side(entry%contact%side_a, entry%surface_line, "SURFA")
          if (entry%contact%kind /= contact_single_surface) &
            call resolve_side(entry%contact%side_b, entry%surface_line, "SURFB")
          model%contacts(k) = entry%contact
          if (model%implicit_static) call located_problem(deck, log, entry%surface_line, "SURFA", &
            "contact is not available in the linear static analysis (*CONTROL_IMPLICIT_GENERAL IMFLAG = 1)")
        end associate
      end do
    end associate
  contains
    subroutine resolve_side(side, line, field)
      type(contact_surface_t), intent(inout) :: side
      integer, intent(in) :: line
      character(len=*), intent(in) :: field
      integer :: m, found
      associate (model => input%model)
        found = 0
        select case (side%kind)
        case (surface_all_parts)
          side%parts = [(m, m=1, size(model%parts))]
          return
        case (surface_part)
          do m = 1, size(model%parts)
            if (model%parts(m)%id == side%id) found = m
          end do
          if (found > 0) side%parts = [found]
          if (found == 0) call located_problem(deck, log, line, field, "part "//integer_text(side%id)// &
            " is not defined (no *PART with this PID)")
        case (surface_part_set)
          do m = 1, size(model%part_sets)
            if (model%part_sets(m)%id == side%id) found = m
          end do
          if (found > 0) side%parts = model%part_sets(found)%parts
          if (found == 0) call located_problem(deck, log, line, field, "part set "//integer_text(side%id)// &
            " is not defined (no *SET_PART_LIST with this SID)")
        case (surface_segment_set)
          do m = 1, size(model%segment_sets)
            if (model%segment_sets(m)%id == side%id) found = m
          end do
          if (found > 0) side%segments = model%segment_sets(found)%nodes
          if (found > 0) call check_segment_owners(found, line, field)
          if (found == 0) call located_problem(deck, log, line, field, "segment set "// &
            integer_text(side%id)//" is not defined (no *SET_SEGMENT with this SID)")
        case (surface_node_set)
          do m = 1, size(model%node_sets)
            if (model%node_sets(m)%id == side%id) found = m
          end do
          if (found > 0) side%nodes = model%node_sets(found)%nodes
          if (found == 0) call located_problem(deck, log, line, field, "node set "//integer_text(side%id)// &
            " is not defined (no *SET_NODE_LIST with this SID)")
        end select
      end associate
    end subroutine resolve_side

    !> A contact segment must be a face of a solid or a shell: the set-up takes its stiffness
    !> and orientation from that element. One that is neither stopped the set-up with a message
    !> naming no line (found by fuzzing), so it is reported here, at its *SET_SEGMENT line,
    !> once per set, with the same search the set-up uses.
    subroutine check_segment_owners(set, contact_line, field)
      integer, intent(in) :: set, contact_line
      character(len=*), intent(in) :: field
      integer, allocatable :: segments(:, :), owners(:), kept(:)
      integer :: s
      if (owners_checked(set)) return
      owners_checked(set) = .true.
      associate (model => input%model, given => input%segment_sets(set))
        if (.not. allocated(given%usable)) return         ! its header was missing (reported)
        ! elements with an undefined node (index 0, reported before) cannot own a segment
        if (any(model%solid_nodes <= 0) .or. any(model%shell_nodes <= 0)) return
        kept = pack([(s, s=1, given%count)], given%usable(1:given%count))
        segments = model%segment_sets(set)%nodes   ! a copy: the search turns segments outwards
        allocate (owners(size(segments, 2)))
        call find_segment_owners(model%solid_nodes, size(model%node_ids), model%coordinates, &
                                 segments, owners)
        call find_shell_owners(model%shell_nodes, size(model%node_ids), segments, owners)
        do s = 1, size(owners)
          if (owners(s) /= 0) cycle
          call located_problem(deck, log, given%lines(kept(s)), "N1-N4", "the segment (nodes "// &
            integer_text(model%node_ids(segments(1, s)))//" "//integer_text(model%node_ids(segments(2, s)))// &
            " "//integer_text(model%node_ids(segments(3, s)))//" "// &
            integer_text(model%node_ids(segments(4, s)))//") of segment set "//integer_text(given%id)// &
            " is neither a face of a solid element nor a shell; a contact surface ("//field// &
            " of the contact at "//line_location(deck, contact_line)//") needs segments on elements")
        end do
      end associate
    end subroutine check_segment_owners
  end subroutine build_contacts
end module deck_contact
