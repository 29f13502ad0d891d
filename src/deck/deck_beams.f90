!> *ELEMENT_BEAM (with _THICKNESS and _OFFSET when their card sets nothing), *SECTION_BEAM
!> (ELFORM 1 Hughes-Liu, 9 spot weld beam; 0 means 1) and *MAT_SPOTWELD (*MAT_100), and the
!> cross-check of the beams (their part, nodes, orientation node and section). docs/beams.md.
module deck_beams
  use kinds, only: wp
  use error_handling, only: error_list_t
  use model, only: section_beam, cross_section_rectangular, cross_section_tubular, beam_resultant_formulation
  use material_laws, only: law_spotweld, law_plastic_kinematic, law_elastic
  use deck_problems, only: problem_log_t
  use text_format, only: integer_text, real_text
  use deck_lexer, only: deck_t, line_location
  use deck_keywords, only: keyword_t
  use deck_fields, only: card_t, open_card, next_line, require_card, next_definition, get_integer, get_real, &
                         card_problem, warn_if_set, card_is_empty, located_problem, located_warning
  use deck_input, only: deck_input_t
  use deck_id_index, only: id_index_t, build_id_index, find_id
  use deck_materials, only: append_material
  implicit none
  private

  public :: read_beam_elements, read_beam_elements_with_card, read_beam_sections, read_spotweld_materials
  public :: resolve_beams

  integer, parameter :: standard_widths(8) = 10
  !> *ELEMENT_BEAM: EID PID N1 N2 N3 RT1 RR1 RT2 RR2 LOCAL, 8 columns each.
  integer, parameter :: element_widths(10) = 8
  character(len=3), parameter :: release_names(4) = ["RT1", "RR1", "RT2", "RR2"]

contains

  !> *ELEMENT_BEAM: see read_beams.
  subroutine read_beam_elements(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_beams(deck, block, .false., input, log)
  end subroutine read_beam_elements

  !> *ELEMENT_BEAM_THICKNESS and *ELEMENT_BEAM_OFFSET: see read_beams.
  subroutine read_beam_elements_with_card(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_beams(deck, block, .true., input, log)
  end subroutine read_beam_elements_with_card

  !> One beam per card: EID PID N1 N2 N3 RT1 RR1 RT2 RR2 LOCAL. N3 (the orientation node) may be
  !> blank; the end releases RT1-RR2 are not available and must be blank or 0 (LOCAL then means
  !> nothing). With `second_card` each beam has a second card (_THICKNESS: PARM1-5 per-element
  !> section sizes; _OFFSET: WX1-WZ2 offsets) that must set nothing: crashfree takes the section
  !> from *SECTION_BEAM and keeps the axis on the nodes.
  subroutine read_beams(deck, block, second_card, input, log)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    logical, intent(in) :: second_card
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(card_t) :: card
    integer :: line, n, k, release
    line = 0
    do while (next_line(deck, block, line, .true.))
      n = input%beam_count + 1
      input%beam_count = n
      input%beam_lines(n) = line
      call open_card(deck, block, line, element_widths, card, log)
      call get_integer(deck, card, 1, "EID", input%model%beam_ids(n), log)
      call get_integer(deck, card, 2, "PID", input%model%beam_part(n), log)
      call get_integer(deck, card, 3, "N1", input%model%beam_nodes(1, n), log)
      call get_integer(deck, card, 4, "N2", input%model%beam_nodes(2, n), log)
      call get_integer(deck, card, 5, "N3", input%model%beam_nodes(3, n), log)
      if (.not. card%failed) then
        associate (beam_id => input%model%beam_ids(n), part => input%model%beam_part(n), &
                   nodes => input%model%beam_nodes(:, n))
          if (beam_id <= 0) call card_problem(deck, log, card, "EID", "element id must be > 0, found "// &
                                              integer_text(beam_id))
          if (part <= 0) call card_problem(deck, log, card, "PID", "every element needs a part id > 0, found "// &
                                           integer_text(part))
          if (nodes(1) <= 0) call card_problem(deck, log, card, "N1", "a beam needs nodes N1 and N2 > 0, found "// &
                                               integer_text(nodes(1)))
          if (nodes(2) <= 0) call card_problem(deck, log, card, "N2", "a beam needs nodes N1 and N2 > 0, found "// &
                                               integer_text(nodes(2)))
        end associate
        if (input%model%beam_nodes(1, n) == input%model%beam_nodes(2, n) .and. input%model%beam_nodes(1, n) > 0) &
          call card_problem(deck, log, card, "N2", "the beam's two nodes are the same node "// &
                            integer_text(input%model%beam_nodes(1, n)))
        if (input%model%beam_nodes(3, n) < 0) call card_problem(deck, log, card, "N3", "orientation node must "// &
          "be > 0 (or blank: an orientation normal to the axis and the global z axis), found "// &
          integer_text(input%model%beam_nodes(3, n)))
      end if
      do k = 1, 4
        call get_integer(deck, card, 5 + k, release_names(k), release, log)
        if (release /= 0 .and. .not. card%failed) call card_problem(deck, log, card, release_names(k), &
          "end releases are not available (the beam's ends are rigidly attached to its nodes); leave "// &
          "RT1 RR1 RT2 RR2 blank or 0, found "//integer_text(release))
      end do
      if (second_card) then
        if (.not. require_card(deck, block, line, standard_widths, card, log, "the second card of beam "// &
                               integer_text(input%model%beam_ids(n)), "PARM1")) exit
        if (.not. card_is_empty(card)) call card_problem(deck, log, card, "PARM1", "per-element section "// &
          "sizes (_THICKNESS) and offsets (_OFFSET) are not available: the beam takes its section from "// &
          "*SECTION_BEAM and its axis from N1-N2; leave this card blank or 0")
      end if
    end do
  end subroutine read_beams

  !> *SECTION_BEAM: C1 SECID ELFORM SHRF QR/IRID CST SCOOR NSM NAUPD; C2 (ELFORM 1, 9) TS1 TS2
  !> TT1 TT2 NSLOC NTLOC. ELFORM 0 or blank is 1 (Hughes-Liu); 9 is the spot weld beam. SHRF
  !> 0 or blank is 1; QR 0 or blank is 2 (2 x 2 Gauss). CST 0 rectangular (TS along s, TT
  !> along t), 1 tubular (TS outer diameter, TT wall; TT 0 a solid circle). TS2, TT2 blank take
  !> TS1, TT1.
  subroutine read_beam_sections(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, n, k
    real(wp) :: mass, offset
    character(len=:), allocatable :: title
    character(len=3), parameter :: size_names(4) = ["TS1", "TS2", "TT1", "TT2"]
    character(len=5), parameter :: offset_names(2) = ["NSLOC", "NTLOC"]

    line = 0
    do while (next_definition(deck, block, keyword%title, line, standard_widths, card, title, &
                              log, "card 1 (SECID ELFORM SHRF QR/IRID CST SCOOR NSM)", "SECID"))
      n = input%section_count + 1
      input%section_count = n
      input%section_lines(n) = line
      associate (section => input%model%sections(n))
        section%kind = section_beam
        section%title = title
        call get_integer(deck, card, 1, "SECID", section%id, log)
        call get_integer(deck, card, 2, "ELFORM", section%element_formulation, log, default=1)
        call get_real(deck, card, 3, "SHRF", section%shear_factor, log)
        call get_integer(deck, card, 4, "QR/IRID", section%beam_rule, log)
        call get_integer(deck, card, 5, "CST", section%cross_section, log)
        call get_real(deck, card, 7, "NSM", mass, log)
        if (.not. card%failed) then
          if (section%id <= 0) call card_problem(deck, log, card, "SECID", "section id must be > 0, found "// &
                                                 integer_text(section%id))
          if (section%element_formulation == 0) section%element_formulation = 1
          if (all(section%element_formulation /= [1, beam_resultant_formulation, 9])) &
            call card_problem(deck, log, card, "ELFORM", "beam formulation "// &
              integer_text(section%element_formulation)//" is not available; crashfree has ELFORM 1 "// &
              "(Hughes-Liu with cross-section integration, 0 or blank), 2 (resultant beam, elastic) and 9 "// &
              "(spot weld beam)")
          if (section%shear_factor < 0.0_wp) call card_problem(deck, log, card, "SHRF", "shear factor must "// &
            "be > 0 (0 or blank: 1.0; 5/6 is usual for a rectangle), found "//real_text(section%shear_factor))
          if (section%beam_rule == 0) section%beam_rule = 2
          if (section%beam_rule < 0) then
            call card_problem(deck, log, card, "QR/IRID", "user integration rules (*INTEGRATION_BEAM, "// &
              "QR < 0) are not available; use 1 (one point), 2 (2 x 2 Gauss), 3 (3 x 3 Gauss), "// &
              "4 (3 x 3 Lobatto) or 5 (4 x 4 Gauss), found "//integer_text(section%beam_rule))
          else if (section%beam_rule > 5) then
            call card_problem(deck, log, card, "QR/IRID", "must be 1-5 (0 or blank: 2), found "// &
                              integer_text(section%beam_rule))
          else if (section%beam_rule == 1 .and. section%cross_section == cross_section_rectangular .and. &
                   section%element_formulation /= beam_resultant_formulation) then
            call card_problem(deck, log, card, "QR/IRID", "one point on a rectangular section gives the "// &
              "beam no bending stiffness; use 2 (2 x 2 Gauss, the default) or more")
          end if
          if (section%cross_section /= cross_section_rectangular .and. &
              section%cross_section /= cross_section_tubular) call card_problem(deck, log, card, "CST", &
            "cross-section type must be 0 (rectangular) or 1 (tubular); arbitrary sections (2) are not "// &
            "available, found "//integer_text(section%cross_section))
          if (mass /= 0.0_wp) call card_problem(deck, log, card, "NSM", "non-structural mass per length is "// &
            "not available (add it with *ELEMENT_MASS or in the density), found "//real_text(mass))
        end if
        if (section%shear_factor == 0.0_wp) section%shear_factor = 1.0_wp
        call warn_if_set(deck, card, 6, "SCOOR", "the beam's frame is always at its mid-length", warnings)
        call warn_if_set(deck, card, 8, "NAUPD", "the section's sizes do not change", warnings)
        if (section%element_formulation == beam_resultant_formulation) then
          if (.not. require_card(deck, block, line, standard_widths, card, log, "card 2 (A ISS ITT J SA IST) "// &
                                 "of section "//integer_text(section%id), "A")) exit
          call read_resultant_card(deck, card, section%beam_properties, log)
          cycle
        end if
        if (.not. require_card(deck, block, line, standard_widths, card, log, "card 2 (TS1 TS2 TT1 TT2 "// &
                               "NSLOC NTLOC) of section "//integer_text(section%id), "TS1")) exit
        do k = 1, 4
          call get_real(deck, card, k, size_names(k), section%beam_size(k), log)
        end do
        if (section%beam_size(2) == 0.0_wp) section%beam_size(2) = section%beam_size(1)
        if (section%beam_size(4) == 0.0_wp) section%beam_size(4) = section%beam_size(3)
        if (.not. card%failed) then
          if (any(section%beam_size(1:2) <= 0.0_wp)) call card_problem(deck, log, card, "TS1", &
            trim(merge("outer diameter", "size along s  ", section%cross_section == cross_section_tubular))// &
            " must be > 0, found "//real_text(minval(section%beam_size(1:2))))
          if (section%cross_section == cross_section_rectangular .and. any(section%beam_size(3:4) <= 0.0_wp)) &
            call card_problem(deck, log, card, "TT1", "size along t must be > 0, found "// &
                              real_text(minval(section%beam_size(3:4))))
          if (any(section%beam_size(3:4) < 0.0_wp)) call card_problem(deck, log, card, "TT1", "wall "// &
            "thickness must be >= 0 (0: a solid circle), found "//real_text(minval(section%beam_size(3:4))))
        end if
        do k = 1, 2
          call get_real(deck, card, 4 + k, offset_names(k), offset, log)
          if (offset /= 0.0_wp .and. .not. card%failed) call card_problem(deck, log, card, offset_names(k), &
            "reference-axis offsets are not available: the beam's axis is on its nodes (0 or blank), found "// &
            real_text(offset))
        end do
      end associate
    end do
  end subroutine read_beam_sections

  !> Card 2 of ELFORM 2: A ISS ITT J SA IST; A, ISS, ITT > 0, J and SA >= 0 (0: ISS + ITT, A),
  !> IST (product of inertia) must be 0.
  subroutine read_resultant_card(deck, card, properties, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    real(wp), intent(out) :: properties(5)
    type(problem_log_t), intent(inout) :: log
    character(len=3), parameter :: names(5) = ["A  ", "ISS", "ITT", "J  ", "SA "]
    real(wp) :: product_of_inertia
    integer :: k
    do k = 1, 5
      call get_real(deck, card, k, trim(names(k)), properties(k), log)
    end do
    call get_real(deck, card, 6, "IST", product_of_inertia, log)
    if (card%failed) return
    do k = 1, 3
      if (.not. properties(k) > 0.0_wp) call card_problem(deck, log, card, trim(names(k)), "must be > 0, found "// &
                                                          real_text(properties(k)))
    end do
    do k = 4, 5
      if (properties(k) < 0.0_wp) call card_problem(deck, log, card, trim(names(k)), "must be >= 0 (0: "// &
        trim(merge("ISS + ITT", "A        ", k == 4))//"), found "//real_text(properties(k)))
    end do
    if (product_of_inertia /= 0.0_wp) call card_problem(deck, log, card, "IST", "a product of inertia "// &
      "(unsymmetric section) is not available; the section's axes s, t must be principal (0 or blank), found "// &
      real_text(product_of_inertia))
    if (properties(4) == 0.0_wp) properties(4) = properties(2) + properties(3)
    if (properties(5) == 0.0_wp) properties(5) = properties(1)
  end subroutine read_resultant_card

  !> *MAT_SPOTWELD (*MAT_100): C1 MID RO E PR SIGY ET DT TFAIL; C2 EFAIL NRR NRS NRT MRR MSS MTT
  !> NF. DT (a mass-scaling step for the welds) and NF (force filtering) are read and not used.
  subroutine read_spotweld_materials(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, n, k
    character(len=:), allocatable :: title
    character(len=3), parameter :: resultant_names(6) = ["NRR", "NRS", "NRT", "MRR", "MSS", "MTT"]

    line = 0
    do while (next_definition(deck, block, keyword%title, line, standard_widths, card, title, &
                              log, "card 1 (MID RO E PR SIGY ET DT TFAIL)", "MID"))
      n = append_material(input, line, law_spotweld, title)
      associate (material => input%model%materials(n))
        call get_integer(deck, card, 1, "MID", material%id, log)
        call get_real(deck, card, 2, "RO", material%density, log)
        call get_real(deck, card, 3, "E", material%youngs_modulus, log)
        call get_real(deck, card, 4, "PR", material%poissons_ratio, log)
        call get_real(deck, card, 5, "SIGY", material%yield_stress, log)
        call get_real(deck, card, 6, "ET", material%tangent_modulus, log)
        call get_real(deck, card, 8, "TFAIL", material%failure_time, log)
        if (.not. card%failed) then
          if (material%id <= 0) call card_problem(deck, log, card, "MID", "material id must be > 0, found "// &
                                                  integer_text(material%id))
          if (material%density <= 0.0_wp) call card_problem(deck, log, card, "RO", "density must be > 0, "// &
                                                            "found "//real_text(material%density))
          if (material%youngs_modulus <= 0.0_wp) call card_problem(deck, log, card, "E", "Young's modulus "// &
            "must be > 0, found "//real_text(material%youngs_modulus))
          if (material%poissons_ratio <= -1.0_wp .or. material%poissons_ratio >= 0.5_wp) &
            call card_problem(deck, log, card, "PR", "Poisson's ratio must lie in (-1, 0.5), found "// &
                              real_text(material%poissons_ratio))
          if (material%yield_stress < 0.0_wp) call card_problem(deck, log, card, "SIGY", "yield stress must "// &
            "be >= 0 (0: elastic), found "//real_text(material%yield_stress))
          if (material%tangent_modulus < 0.0_wp .or. (material%tangent_modulus >= material%youngs_modulus &
              .and. material%youngs_modulus > 0.0_wp)) call card_problem(deck, log, card, "ET", "tangent "// &
            "modulus must lie in [0, E), found "//real_text(material%tangent_modulus))
          if (material%failure_time < 0.0_wp) call card_problem(deck, log, card, "TFAIL", "failure time "// &
            "must be >= 0 (0: none), found "//real_text(material%failure_time))
        end if
        call warn_if_set(deck, card, 7, "DT", "no separate mass scaling of the welds (use "// &
                         "*CONTROL_TIMESTEP DT2MS)", warnings)
        if (.not. require_card(deck, block, line, standard_widths, card, log, &
                               "card 2 (EFAIL NRR NRS NRT MRR MSS MTT NF)", "EFAIL")) exit
        call get_real(deck, card, 1, "EFAIL", material%failure_plastic_strain, log)
        do k = 1, 6
          call get_real(deck, card, 1 + k, resultant_names(k), material%failure_resultants(k), log)
        end do
        if (.not. card%failed) then
          if (material%failure_plastic_strain < 0.0_wp) call card_problem(deck, log, card, "EFAIL", &
            "plastic strain at failure must be >= 0 (0: none), found "//real_text(material%failure_plastic_strain))
          do k = 1, 6
            if (material%failure_resultants(k) < 0.0_wp) call card_problem(deck, log, card, resultant_names(k), &
              "resultant at failure must be >= 0 (0: left out of the criterion), found "// &
              real_text(material%failure_resultants(k)))
          end do
        end if
        call warn_if_set(deck, card, 8, "NF", "the resultants of the failure criterion are not filtered", &
                         warnings)
      end associate
    end do
  end subroutine read_spotweld_materials

  !> The beams: ids unique, part and nodes (N3 too) resolved to indices, the part's section a
  !> *SECTION_BEAM, a length > 0 and N3 off the axis. `node_index` and `part_index` are the
  !> cross-check's indices. Runs before the constraints are built (rotations of beam nodes).
  !> A *MAT_PLASTIC_KINEMATIC on beams with kinematic hardening (BETA < 1) or rate effects
  !> (SRC, SRP) gets a warning: beam points harden isotropically, without rate effects.
  subroutine resolve_beams(deck, input, node_index, part_index, log, warnings)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(id_index_t), intent(in) :: node_index, part_index
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(id_index_t) :: beam_index
    integer :: beam, k, index, first, section, material
    logical, allocatable :: reported_resultant_part(:)
    logical :: resolved
    real(wp) :: axis(3), toward(3), length
    character(len=2), parameter :: node_names(3) = ["N1", "N2", "N3"]

    associate (model => input%model)
      model%beam_ids = model%beam_ids(1:input%beam_count)
      model%beam_part = model%beam_part(1:input%beam_count)
      model%beam_nodes = model%beam_nodes(:, 1:input%beam_count)
      input%beam_lines = input%beam_lines(1:input%beam_count)
      call build_id_index(model%beam_ids, beam_index)
      allocate (reported_resultant_part(input%part_count))
      reported_resultant_part = .false.
      first = 1
      do k = 2, size(beam_index%ids)
        if (beam_index%ids(k) /= beam_index%ids(k - 1)) then
          first = k
        else if (beam_index%ids(k) > 0) then
          call located_problem(deck, log, input%beam_lines(beam_index%positions(k)), "EID", "beam id "// &
            integer_text(beam_index%ids(k))//" is defined twice (first at "// &
            line_location(deck, input%beam_lines(beam_index%positions(first)))//")")
        end if
      end do
      if (input%beam_count > 0 .and. model%implicit_static) call located_problem(deck, log, &
        input%beam_lines(1), "EID", "the linear static analysis (*CONTROL_IMPLICIT_GENERAL) has no beam "// &
        "elements; beams run in explicit analyses")
      do beam = 1, input%beam_count
        resolved = .true.
        index = find_id(part_index, model%beam_part(beam))
        if (index == 0 .and. model%beam_part(beam) > 0) call located_problem(deck, log, input%beam_lines(beam), &
          "PID", "part "//integer_text(model%beam_part(beam))//" of beam "//integer_text(model%beam_ids(beam))// &
          " is not defined")
        model%beam_part(beam) = index
        do k = 1, 3
          if (model%beam_nodes(k, beam) <= 0) then
            model%beam_nodes(k, beam) = 0
            resolved = resolved .and. k == 3
            cycle
          end if
          index = find_id(node_index, model%beam_nodes(k, beam))
          if (index == 0) then
            call located_problem(deck, log, input%beam_lines(beam), node_names(k), "node "// &
              integer_text(model%beam_nodes(k, beam))//" of beam "//integer_text(model%beam_ids(beam))// &
              " is not defined")
            resolved = .false.
          end if
          model%beam_nodes(k, beam) = index
        end do
        if (model%beam_part(beam) > 0) then
          section = model%parts(model%beam_part(beam))%section
          material = model%parts(model%beam_part(beam))%material
          if (section > 0) then
            if (model%sections(section)%kind /= section_beam) then
              call located_problem(deck, log, input%beam_lines(beam), "PID", "part "// &
                integer_text(model%parts(model%beam_part(beam))%id)//" of beam "// &
                integer_text(model%beam_ids(beam))//" has section "//integer_text(model%sections(section)%id)// &
                ", which is not a *SECTION_BEAM; beams need one")
            else if (model%sections(section)%element_formulation == beam_resultant_formulation .and. material > 0 &
                     .and. .not. reported_resultant_part(model%beam_part(beam))) then
              reported_resultant_part(model%beam_part(beam)) = .true.
              if (model%materials(material)%law /= law_elastic) call located_problem(deck, log, &
                input%part_lines(model%beam_part(beam)), "MID", "part "// &
                integer_text(model%parts(model%beam_part(beam))%id)//": the resultant beam (ELFORM 2) is "// &
                "elastic and takes *MAT_ELASTIC only; use ELFORM 1 (integrated section) for plasticity and welds")
            end if
          end if
        end if
        if (.not. resolved) cycle
        axis = model%coordinates(:, model%beam_nodes(2, beam)) - model%coordinates(:, model%beam_nodes(1, beam))
        length = norm2(axis)
        if (.not. length > 0.0_wp) then
          call located_problem(deck, log, input%beam_lines(beam), "N2", "beam "// &
            integer_text(model%beam_ids(beam))//" has no length (its nodes N1 and N2 are at the same place)")
          cycle
        end if
        if (model%beam_nodes(3, beam) > 0) then
          toward = model%coordinates(:, model%beam_nodes(3, beam)) - model%coordinates(:, model%beam_nodes(1, beam))
          if (norm2(toward - dot_product(toward, axis)*axis/length**2) <= 1.0e-6_wp*max(length, norm2(toward))) &
            call located_problem(deck, log, input%beam_lines(beam), "N3", "orientation node "// &
              integer_text(model%node_ids(model%beam_nodes(3, beam)))//" of beam "// &
              integer_text(model%beam_ids(beam))//" lies on the beam's axis: it cannot orient the section")
        end if
      end do
      call warn_beam_plasticity(deck, input, warnings)
    end associate
  end subroutine resolve_beams

  !> The warning of resolve_beams, once per material.
  subroutine warn_beam_plasticity(deck, input, warnings)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(in) :: input
    type(error_list_t), intent(inout) :: warnings
    logical, allocatable :: on_beams(:)
    integer :: beam, material
    allocate (on_beams(input%material_count))
    on_beams = .false.
    do beam = 1, input%beam_count
      if (input%model%beam_part(beam) <= 0) cycle
      material = input%model%parts(input%model%beam_part(beam))%material
      if (material > 0) on_beams(material) = .true.
    end do
    do material = 1, input%material_count
      if (.not. on_beams(material)) cycle
      associate (law => input%model%materials(material))
        if (law%law /= law_plastic_kinematic) cycle
        if (law%hardening_beta < 1.0_wp) call located_warning(deck, warnings, input%material_lines(material), &
          "BETA", "beams harden isotropically (as BETA = 1): kinematic hardening is not available on beams")
        if (law%rate_c > 0.0_wp .or. law%rate_p > 0.0_wp) call located_warning(deck, warnings, &
          input%material_lines(material), "SRC", "strain-rate effects are not applied on beams")
      end associate
    end do
  end subroutine warn_beam_plasticity
end module deck_beams
