!> *PART, *SECTION_SOLID(_EFG), *SECTION_SHELL and *HOURGLASS: what each part is made of and how
!> it is integrated.
module deck_parts_sections
  use kinds, only: wp
  use error_handling, only: error_list_t
  use model, only: formulation_fe, section_solid, section_shell
  use deck_problems, only: problem_log_t
  use text_format, only: integer_text, real_text
  use deck_lexer, only: deck_t
  use deck_keywords, only: keyword_t
  use deck_fields, only: card_t, open_card, next_line, require_card, next_definition, &
                         has_data, get_integer, get_real, card_problem, warn_if_set, line_title, &
                         card_is_empty, field_is_blank
  use deck_efg_cards, only: read_efg_card, read_efg_options_card, read_efg_shell_card, &
                            elform_efg, elform_adaptive_efg
  use deck_input, only: deck_input_t
  implicit none
  private

  public :: read_parts, read_solid_sections, read_efg_sections, read_shell_sections, read_hourglasses

  integer, parameter :: standard_widths(8) = 10

contains

  !> *PART: a heading line, then PID SECID MID EOSID HGID GRAV ADPOPT TMID; repeated. With
  !> _CONTACT a third card FS FD DC VC OPTT SFT SSF CPARM8 follows, which is read over (a
  !> warning names the fields set): its values act only through contacts that take friction
  !> and thickness per part, which crashfree's contacts do not.
  subroutine read_parts(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, n, equation_of_state, adaptivity, k
    logical :: stepped
    character(len=:), allocatable :: title
    character(len=6), parameter :: contact_names(8) = ["FS    ", "FD    ", "DC    ", "VC    ", &
                                                       "OPTT  ", "SFT   ", "SSF   ", "CPARM8"]

    line = 0
    if (.not. has_data(deck, block, log, "the heading line and the data card", "PID")) return
    do while (next_line(deck, block, line, .false.))
      title = line_title(deck, line)
      if (.not. require_card(deck, block, line, standard_widths, card, log, "the data card "// &
          "(PID SECID MID EOSID HGID GRAV ADPOPT TMID) after the heading line", "PID")) exit
      n = input%part_count + 1
      input%part_count = n
      input%part_lines(n) = line
      associate (part => input%model%parts(n))
        part%title = title
        part%formulation = formulation_fe
        call get_integer(deck, card, 1, "PID", part%id, log)
        call get_integer(deck, card, 2, "SECID", part%section_id, log)
        call get_integer(deck, card, 3, "MID", part%material_id, log)
        call get_integer(deck, card, 4, "EOSID", equation_of_state, log)
        call get_integer(deck, card, 5, "HGID", part%hourglass_id, log)
        call get_integer(deck, card, 7, "ADPOPT", adaptivity, log)
        if (card%failed) then
          ! step over the contact card, which is not the next part's heading line
          if (keyword%contact) stepped = next_line(deck, block, line, .false.)
          cycle
        end if
        if (part%id <= 0) call card_problem(deck, log, card, "PID", "part id must be > 0, "// &
                                            "found "//integer_text(part%id))
        if (part%section_id < 0) call card_problem(deck, log, card, "SECID", &
          "section id must be > 0, found "//integer_text(part%section_id))
        if (part%material_id < 0) call card_problem(deck, log, card, "MID", &
          "material id must be > 0, found "//integer_text(part%material_id))
        if (part%hourglass_id < 0) call card_problem(deck, log, card, "HGID", "hourglass id "// &
          "must be >= 0 (0: the *CONTROL_HOURGLASS defaults), found "// &
          integer_text(part%hourglass_id))
        if (equation_of_state /= 0) call card_problem(deck, log, card, "EOSID", "equations "// &
          "of state (*EOS) are not available; leave EOSID blank")
        if (adaptivity /= 0) call card_problem(deck, log, card, "ADPOPT", "adaptive "// &
          "remeshing is not available; leave ADPOPT blank")
      end associate
      call warn_if_set(deck, card, 6, "GRAV", "*LOAD_DENSITY_DEPTH is not read", warnings)
      call warn_if_set(deck, card, 8, "TMID", "no thermal analysis", warnings)
      if (keyword%contact) then
        if (.not. require_card(deck, block, line, standard_widths, card, log, "the contact "// &
            "card (FS FD DC VC OPTT SFT SSF CPARM8) of *PART_CONTACT", "FS")) exit
        do k = 1, 8
          call warn_if_set(deck, card, k, trim(contact_names(k)), "part-wise contact values are "// &
                           "not available; give them on the *CONTACT_ card", warnings)
        end do
      end if
    end do
  end subroutine read_parts

  !> *SECTION_SOLID: see read_solid_section_cards.
  subroutine read_solid_sections(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_solid_section_cards(deck, block, keyword, .false., input, log, warnings)
  end subroutine read_solid_sections

  !> *SECTION_SOLID_EFG: see read_solid_section_cards.
  subroutine read_efg_sections(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_solid_section_cards(deck, block, keyword, .true., input, log, warnings)
  end subroutine read_efg_sections

  !> *SECTION_SOLID and *SECTION_SOLID_EFG (with _TITLE: a title line before card 1).
  !>
  !> Card 1 is SECID ELFORM AET. ELFORM 1 (0 or blank) and 2 are finite elements; 41 is the meshfree
  !> (EFG) solid and is followed by the EFG card (DX DY DZ ISPLINE IDILA IEBT IDIM TOLDEF), as
  !> is ELFORM 42, which is rejected. Where the cards of one section end:
  !> * *SECTION_SOLID repeats its sections until the next keyword: card 1, plus the EFG card
  !>   when ELFORM is 41 or 42. Card 3 is never read here, since an optional card inside a
  !>   repeating set could not be told from the next section's card 1.
  !> * *SECTION_SOLID_EFG holds one section, as in LS-DYNA: card 1 (ELFORM must be 41), the EFG
  !>   card, and an optional card 3 (IPS STIME IKEN SF CMID IBR DS ECUT). Further cards are
  !>   accepted only when they set nothing (the user-element cards that pydyna writes for
  !>   every section); any other further card is an error.
  subroutine read_solid_section_cards(deck, block, keyword, meshfree_keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    logical, intent(in) :: meshfree_keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, n, id, formulation
    logical :: follows_efg_card, defaulted
    character(len=:), allocatable :: title

    line = 0
    follows_efg_card = .false.
    do while (next_definition(deck, block, keyword%title, line, standard_widths, card, title, &
                              log, "card 1 (SECID ELFORM AET)", "SECID"))
      call get_integer(deck, card, 1, "SECID", id, log)
      if (follows_efg_card .and. id == 0 .and. .not. card%failed) then
        call card_problem(deck, log, card, "SECID", "section id must be > 0, found 0 (this "// &
          "card follows an EFG card; card 3, IPS STIME IKEN SF CMID IBR DS ECUT, is read only "// &
          "under *SECTION_SOLID_EFG)")
        follows_efg_card = .false.
        cycle
      end if
      call get_integer(deck, card, 2, "ELFORM", formulation, log, default=1)
      ! LS-DYNA: ELFORM 0 (or blank) is the default, 1
      defaulted = formulation == 0 .or. field_is_blank(card, 2)
      if (formulation == 0) formulation = 1
      n = input%section_count + 1
      input%section_count = n
      input%section_lines(n) = line
      input%model%sections(n)%id = id
      input%model%sections(n)%title = title
      input%model%sections(n)%kind = section_solid
      input%model%sections(n)%element_formulation = formulation
      if (.not. card%failed) then
        if (id <= 0) call card_problem(deck, log, card, "SECID", "section id must be > 0, "// &
                                       "found "//integer_text(id))
        call check_solid_formulation(deck, log, card, formulation, defaulted, meshfree_keyword)
      end if
      call warn_if_set(deck, card, 3, "AET", "ambient elements are not available", warnings)
      follows_efg_card = meshfree_keyword .or. formulation == elform_efg .or. &
                         formulation == elform_adaptive_efg
      if (follows_efg_card) then
        if (.not. require_card(deck, block, line, standard_widths, card, log, "the EFG card "// &
            "(DX DY DZ ISPLINE IDILA IEBT IDIM TOLDEF) of section "//integer_text(id), "DX")) exit
        call read_efg_card(deck, card, input%model%sections(n), log, warnings)
      end if
      if (meshfree_keyword) then
        call read_efg_closing_cards(deck, block, line, log)
        exit
      end if
    end do
  end subroutine read_solid_section_cards

  !> *SECTION_SHELL (with _TITLE: a title line before each section). Sections repeat until the
  !> next keyword; each is two cards:
  !> card 1 SECID ELFORM SHRF NIP PROPT QR/IRID ICOMP SETYP, card 2 T1 T2 T3 T4 NLOC MAREA IDOF
  !> EDGSET, and with ELFORM 41 (the meshfree EFG shell) the EFG card DX DY ISPLINE IDILA IEBT
  !> IDIM (read_efg_shell_card). Only what the Belytschko-Tsay shell and the meshfree shell
  !> model is accepted: ELFORM 2 (0 or blank: 2) or 41 (42, the global EFG shell, is refused), Gauss
  !> integration through the thickness (QR/IRID 0) with 1-10 points, no composite angles
  !> (ICOMP 0), the mid surface as reference (NLOC 0) and no non-structural mass (MAREA 0,
  !> rejected rather than ignored since it would change the mass). T2-T4 blank or 0 take T1,
  !> as in LS-DYNA. PROPT and SETYP (printout, 2D solids) are not used.
  subroutine read_shell_sections(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, n, k, rule, composite, angle_cards
    real(wp) :: reference_surface, area_mass
    character(len=:), allocatable :: title
    character(len=2), parameter :: thickness_names(4) = ["T1", "T2", "T3", "T4"]

    line = 0
    do while (next_definition(deck, block, keyword%title, line, standard_widths, card, title, &
                              log, "card 1 (SECID ELFORM SHRF NIP PROPT QR/IRID ICOMP SETYP)", &
                              "SECID"))
      n = input%section_count + 1
      input%section_count = n
      input%section_lines(n) = line
      associate (section => input%model%sections(n))
        section%kind = section_shell
        section%title = title
        call get_integer(deck, card, 1, "SECID", section%id, log)
        call get_integer(deck, card, 2, "ELFORM", section%element_formulation, log, default=2, &
                         zero_is_default=.true.)
        call get_real(deck, card, 3, "SHRF", section%shear_factor, log)
        call get_integer(deck, card, 4, "NIP", section%integration_points, log)
        call get_integer(deck, card, 6, "QR/IRID", rule, log)
        call get_integer(deck, card, 7, "ICOMP", composite, log)
        if (.not. card%failed) then
          if (section%id <= 0) call card_problem(deck, log, card, "SECID", "section id must "// &
                                                 "be > 0, found "//integer_text(section%id))
          call check_shell_formulation(deck, log, card, section%element_formulation)
          if (section%shear_factor < 0.0_wp) call card_problem(deck, log, card, "SHRF", &
            "shear factor must be > 0 (0 or blank: 1.0; 5/6 is usual), found "// &
            real_text(section%shear_factor))
          if (section%integration_points < 0 .or. section%integration_points > 10) &
            call card_problem(deck, log, card, "NIP", "integration points through the "// &
              "thickness must be 1-10 (0 or blank: 2), found "// &
              integer_text(section%integration_points))
          if (rule /= 0) call card_problem(deck, log, card, "QR/IRID", "only Gauss "// &
            "integration through the thickness (0) is available; trapezoidal (1) and "// &
            "*INTEGRATION_SHELL rules (< 0) are not, found "//integer_text(rule))
          if (composite == 1) then
            call card_problem(deck, log, card, "ICOMP", "composite layers with one material "// &
              "angle per integration point (ICOMP 1) are not available; leave ICOMP blank or 0")
          else if (composite /= 0) then
            call card_problem(deck, log, card, "ICOMP", "must be 0 (or 1, composite angles, "// &
                              "which are not available), found "//integer_text(composite))
          end if
        end if
        if (section%shear_factor == 0.0_wp) section%shear_factor = 1.0_wp
        ! (the angle cards of ICOMP 1, one angle per point and 8 per card, are stepped over)
        angle_cards = 0
        if (composite == 1) angle_cards = (max(section%integration_points, 2) + 7)/8
        if (section%integration_points == 0) section%integration_points = 2
        if (.not. require_card(deck, block, line, standard_widths, card, log, "card 2 (T1 T2 "// &
            "T3 T4 NLOC MAREA IDOF EDGSET) of section "//integer_text(section%id), "T1")) exit
        do k = 1, 4
          call get_real(deck, card, k, thickness_names(k), section%thickness(k), log)
          if (section%thickness(k) < 0.0_wp) then
            call card_problem(deck, log, card, thickness_names(k), "thickness must be >= 0, "// &
                              "found "//real_text(section%thickness(k)))
            section%thickness(k) = 0.0_wp
          end if
        end do
        where (section%thickness(2:4) == 0.0_wp) section%thickness(2:4) = section%thickness(1)
        call get_real(deck, card, 5, "NLOC", reference_surface, log)
        call get_real(deck, card, 6, "MAREA", area_mass, log)
        section%reference_surface = reference_surface
        if (reference_surface /= 0.0_wp) call card_problem(deck, log, card, "NLOC", &
          "reference surface offsets are not available: shells lie on their mid surface "// &
          "(NLOC 0 or blank), found "//real_text(reference_surface))
        if (area_mass /= 0.0_wp) call card_problem(deck, log, card, "MAREA", "non-structural "// &
          "mass per area is not available (add it with *ELEMENT_MASS or in the density), "// &
          "found "//real_text(area_mass))
        call warn_if_set(deck, card, 7, "IDOF", "thickness stretch belongs to other shell "// &
                         "formulations", warnings)
        call warn_if_set(deck, card, 8, "EDGSET", "seatbelt shells are not available", warnings)
      end associate
      do k = 1, angle_cards
        if (.not. next_line(deck, block, line, .false.)) exit
      end do
      ! the EFG card of a meshfree shell (and of ELFORM 42, refused on card 1, read over so that
      ! the next section is read in place)
      associate (section => input%model%sections(n))
        if (section%element_formulation == elform_efg .or. &
            section%element_formulation == elform_adaptive_efg) then
          if (.not. require_card(deck, block, line, standard_widths, card, log, "the EFG card "// &
              "(DX DY ISPLINE IDILA IEBT IDIM) of section "//integer_text(section%id), "DX")) exit
          call read_efg_shell_card(deck, card, section, log, warnings)
        end if
      end associate
    end do
  end subroutine read_shell_sections

  !> ELFORM of a shell section: 2 (Belytschko-Tsay) and 41 (meshfree EFG shell, LS-DYNA's local
  !> approach for crash).
  subroutine check_shell_formulation(deck, log, card, formulation)
    type(deck_t), intent(in) :: deck
    type(problem_log_t), intent(inout) :: log
    type(card_t), intent(inout) :: card
    integer, intent(in) :: formulation

    select case (formulation)
    case (2, elform_efg)
    case (elform_adaptive_efg)
      call card_problem(deck, log, card, "ELFORM", "the global meshfree shell (ELFORM 42, "// &
        "LS-DYNA's EFG shell for metal forming) is not available; use ELFORM 41 (meshfree "// &
        "EFG shell, local approach) or 2 (Belytschko-Tsay)")
    case default
      call card_problem(deck, log, card, "ELFORM", "shell formulation "// &
        integer_text(formulation)//" is not available; crashfree has ELFORM 2 "// &
        "(Belytschko-Tsay) and 41 (meshfree EFG shell)")
    end select
  end subroutine check_shell_formulation

  !> ELFORM of a solid section: 1 and 2 (finite elements) and 41 (EFG); 41 only under
  !> *SECTION_SOLID_EFG.
  subroutine check_solid_formulation(deck, log, card, formulation, blank, meshfree_keyword)
    type(deck_t), intent(in) :: deck
    type(problem_log_t), intent(inout) :: log
    type(card_t), intent(in) :: card
    integer, intent(in) :: formulation
    logical, intent(in) :: blank             !< ELFORM was blank or 0 (LS-DYNA's default, 1)
    logical, intent(in) :: meshfree_keyword
    character(len=:), allocatable :: reason
    if (meshfree_keyword) then
      if (formulation == elform_efg) return
      select case (formulation)
      case (elform_adaptive_efg)
        reason = "; adaptive EFG (ELFORM 42) is not available"
      case (1, 2)
        reason = " (a finite element formulation: use *SECTION_SOLID)"
        if (blank) reason = " (the field is blank or 0, which means 1)"
      case default
        reason = ""
      end select
      call card_problem(deck, log, card, "ELFORM", "*SECTION_SOLID_EFG needs ELFORM 41 "// &
        "(meshfree EFG solid), found "//integer_text(formulation)//reason)
      return
    end if
    select case (formulation)
    case (1, 2, elform_efg)
    case (elform_adaptive_efg)
      call card_problem(deck, log, card, "ELFORM", "adaptive EFG (ELFORM 42, 4-node "// &
        "background cells) is not available; use ELFORM 41 (EFG solid on hexahedral cells)")
    case default
      call card_problem(deck, log, card, "ELFORM", "element formulation "// &
        integer_text(formulation)//" is not available; crashfree has ELFORM 1 (one-point, "// &
        "constant stress), 2 (fully integrated, selective reduced) and 41 (meshfree EFG)")
    end select
  end subroutine check_solid_formulation

  !> The cards of *SECTION_SOLID_EFG after the EFG card: the optional card 3, then only
  !> cards that set nothing.
  subroutine read_efg_closing_cards(deck, block, line, log)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    integer, intent(inout) :: line
    type(problem_log_t), intent(inout) :: log
    type(card_t) :: card
    if (.not. next_line(deck, block, line, .false.)) return
    call open_card(deck, block, line, standard_widths, card, log)
    call read_efg_options_card(deck, card, log)
    do while (next_line(deck, block, line, .false.))
      call open_card(deck, block, line, standard_widths, card, log)
      if (card_is_empty(card)) cycle
      call card_problem(deck, log, card, "SECID", "*SECTION_SOLID_EFG holds one section "// &
        "(card 1, the EFG card and the optional card 3); give the next section its own "// &
        "*SECTION_SOLID_EFG", unreadable=.true.)
      exit
    end do
  end subroutine read_efg_closing_cards

  !> *HOURGLASS: HGID IHQ QM IBQ Q1 Q2 QB/VDC QW, one card per definition. Values are kept as
  !> written (blank = 0); the cross-check turns IHQ 0 and blank QM, Q1, Q2 into the global
  !> defaults.
  subroutine read_hourglasses(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, n
    character(len=:), allocatable :: title

    line = 0
    do while (next_definition(deck, block, keyword%title, line, standard_widths, card, title, &
                              log, "card 1 (HGID IHQ QM IBQ Q1 Q2 QB QW)", "HGID"))
      n = input%hourglass_count + 1
      input%hourglass_count = n
      input%hourglass_lines(n) = line
      associate (hourglass => input%model%hourglasses(n))
        hourglass%title = title
        call get_integer(deck, card, 1, "HGID", hourglass%id, log)
        call get_integer(deck, card, 2, "IHQ", hourglass%hourglass_type, log)
        call get_real(deck, card, 3, "QM", hourglass%coefficient, log)
        call get_real(deck, card, 5, "Q1", hourglass%bulk_quadratic, log)
        call get_real(deck, card, 6, "Q2", hourglass%bulk_linear, log)
        if (card%failed) cycle
        if (hourglass%id <= 0) call card_problem(deck, log, card, "HGID", "hourglass id "// &
                                                 "must be > 0, found "//integer_text(hourglass%id))
        if (hourglass%hourglass_type < 0 .or. hourglass%hourglass_type > 10) &
          call card_problem(deck, log, card, "IHQ", "hourglass type must be 0-10, found "// &
                            integer_text(hourglass%hourglass_type))
        call check_not_negative(deck, log, card, "QM", hourglass%coefficient)
        call check_not_negative(deck, log, card, "Q1", hourglass%bulk_quadratic)
        call check_not_negative(deck, log, card, "Q2", hourglass%bulk_linear)
      end associate
    end do
  end subroutine read_hourglasses

  subroutine check_not_negative(deck, log, card, name, value)
    type(deck_t), intent(in) :: deck
    type(problem_log_t), intent(inout) :: log
    type(card_t), intent(in) :: card
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: value
    if (value < 0.0_wp) call card_problem(deck, log, card, name, "must be >= 0, found "// &
                                          real_text(value))
  end subroutine check_not_negative
end module deck_parts_sections
