!> Rigid bodies in the deck: *MAT_RIGID (*MAT_020), *BOUNDARY_PRESCRIBED_MOTION_RIGID,
!> *CONSTRAINED_NODAL_RIGID_BODY and *ELEMENT_MASS: the readers, and the cross-check step that
!> turns them into `model%rigid_bodies`, `model%rigid_motions` and `model%node_masses`.
!>
!> A part whose material is *MAT_RIGID gets `formulation_rigid`: its elements give the body
!> its mass and inertia and get no finite-element block (LS-DYNA Keyword Manual, *MAT_RIGID;
!> LS-DYNA Theory Manual, "Rigid Body Dynamics"). The readers are those of the keyword table's
!> rows (deck_keyword_table); their lists are sized from the keywords' data lines (deck_input).
module deck_rigid_bodies
  use kinds, only: wp
  use error_handling, only: error_list_t
  use model, only: material_t, rigid_body_t, rigid_motion_t, spot_weld_t, formulation_rigid, motion_velocity, &
                   motion_acceleration, motion_displacement
  use material_laws, only: law_rigid
  use deck_problems, only: problem_log_t, report_problem
  use text_format, only: integer_text, real_text
  use deck_lexer, only: deck_t
  use deck_keywords, only: keyword_t
  use deck_fields, only: card_t, next_definition, next_line, open_card, get_integer, get_real, &
                         card_problem, field_is_blank, warn_if_set, id_heading, located_problem
  use deck_id_index, only: id_index_t, build_id_index, find_id
  use deck_input, only: deck_input_t
  use deck_materials, only: append_material
  use deck_rigid_input, only: rigid_material_input_t, rigid_motion_input_t, nodal_rigid_input_t, &
                              element_mass_input_t, spot_weld_input_t, rigid_link_input_t, link_extra_node, &
                              link_extra_set, link_merge
  implicit none
  private

  public :: read_rigid_materials, read_rigid_motions, read_nodal_rigid_bodies, read_element_masses
  public :: build_rigid_bodies, read_spot_welds, read_generalized_spot_welds
  public :: read_extra_nodes, read_extra_node_sets, read_rigid_body_merges

  integer, parameter :: standard_widths(8) = 10
  integer, parameter :: mass_widths(4) = [8, 8, 16, 8]
  !> Dofs switched on by the CON1 / CON2 codes 0-7 (x, y, z).
  logical, parameter :: code_dofs(3, 0:7) = reshape([ &
    .false., .false., .false., .true., .false., .false., .false., .true., .false., &
    .false., .false., .true., .true., .true., .false., .false., .true., .true., &
    .true., .false., .true., .true., .true., .true.], [3, 8])
  character(len=2), parameter :: dof_names(6) = ["x ", "y ", "z ", "rx", "ry", "rz"]

contains

  !> *MAT_RIGID: card 1 MID RO E PR N COUPLE M ALIAS; card 2 CMO CON1 CON2 SPCNID XSPC YSPC
  !> ZSPC; card 3 LCO/A1 A2 A3 V1 V2 V3 BNDLCO (read over: output axes only). Cards 2 and 3
  !> may be left out at the end of the keyword. E and PR give the time step of the rigid
  !> elements (LS-DYNA uses them for contact stiffness).
  subroutine read_rigid_materials(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    type(rigid_material_input_t) :: entry
    integer :: line, n, spc_node
    real(wp) :: mode, translations, rotations, coupling
    character(len=:), allocatable :: title

    line = 0
    do while (next_definition(deck, block, keyword%title, line, standard_widths, card, title, &
                              log, "card 1 (MID RO E PR N COUPLE M ALIAS)", "MID"))
      n = append_material(input, line, law_rigid, title)
      entry = rigid_material_input_t(material=n)
      associate (material => input%model%materials(n))
        call get_integer(deck, card, 1, "MID", material%id, log)
        call get_real(deck, card, 2, "RO", material%density, log)
        call get_real(deck, card, 3, "E", material%youngs_modulus, log)
        call get_real(deck, card, 4, "PR", material%poissons_ratio, log)
        if (.not. card%failed) then
          if (material%id <= 0) call card_problem(deck, log, card, "MID", "must be a positive id, found "// &
                                                  integer_text(material%id))
          if (.not. material%density > 0.0_wp) call card_problem(deck, log, card, "RO", &
            "the density must be positive (it gives the rigid body its mass), found "//real_text(material%density))
          if (.not. material%youngs_modulus > 0.0_wp) call card_problem(deck, log, card, "E", &
            "must be positive (it sets the time step of the rigid elements; give a realistic value), found "// &
            real_text(material%youngs_modulus))
          if (.not. (material%poissons_ratio >= 0.0_wp .and. material%poissons_ratio < 0.5_wp)) &
            call card_problem(deck, log, card, "PR", "must lie in [0, 0.5), found "// &
                              real_text(material%poissons_ratio))
        end if
        ! N COUPLE M: 0 (or blank) is "no coupling", as LS-DYNA reads it
        call get_real(deck, card, 5, "N", coupling, log)
        if (coupling /= 0.0_wp) call no_coupling("N")
        call get_real(deck, card, 6, "COUPLE", coupling, log)
        if (coupling /= 0.0_wp) call no_coupling("COUPLE")
        call get_real(deck, card, 7, "M", coupling, log)
        if (coupling /= 0.0_wp) call no_coupling("M")
      end associate
      ! card 2 (optional at the end of the keyword)
      if (next_line(deck, block, line, .false.)) then
        call open_card(deck, block, line, standard_widths, card, log)
        entry%line = line
        call get_real(deck, card, 1, "CMO", mode, log)
        call get_real(deck, card, 2, "CON1", translations, log)
        call get_real(deck, card, 3, "CON2", rotations, log)
        call get_integer(deck, card, 4, "SPCNID", spc_node, log)
        if (.not. card%failed) then
          ! clamped: nint of a huge CMO overflowed, a floating-point trap, before the value
          ! could be reported (found by fuzzing)
          entry%constraint_mode = nint(max(min(mode, 2.0e9_wp), -2.0e9_wp))
          ! CMO is a code: 0.5 is not "1" (found by fuzzing)
          if (mode /= real(entry%constraint_mode, wp)) entry%constraint_mode = huge(1)
          select case (entry%constraint_mode)
          case (0)
          case (1)
            entry%translations = check_code(translations, "CON1")
            entry%rotations = check_code(rotations, "CON2")
          case (-1)
            call card_problem(deck, log, card, "CMO", "-1 (constraints in a local coordinate system CON1 "// &
              "with the mask CON2) is not available; use CMO = 1 with global codes in CON1 and CON2")
          case (2, -2)
            if (spc_node /= 0) then
              call card_problem(deck, log, card, "SPCNID", "constraints at a node (|CMO| = 2) are not "// &
                "available; use CMO = 1 (constraints at the centre of mass)")
            else
              call card_problem(deck, log, card, "XSPC", "constraints at a point (|CMO| = 2, XSPC YSPC "// &
                "ZSPC) are not available; use CMO = 1 (constraints at the centre of mass)")
            end if
          case default
            call card_problem(deck, log, card, "CMO", "must be 0 (no constraint) or 1 (global "// &
                              "constraints), found "//real_text(mode))
          end select
        end if
        ! card 3: output axes and airbag vectors only
        if (next_line(deck, block, line, .false.)) then
          call open_card(deck, block, line, standard_widths, card, log)
          call warn_if_set(deck, card, 8, "BNDLCO", "bndout is not written", warnings)
        end if
      end if
      call append_rigid_material(input, entry)
    end do
  contains
    subroutine no_coupling(name)
      character(len=*), intent(in) :: name
      call card_problem(deck, log, card, name, "MADYMO/CAL3D coupling is not available; leave "// &
                        name//" blank")
    end subroutine no_coupling

    integer function check_code(value, name)
      real(wp), intent(in) :: value
      character(len=*), intent(in) :: name
      check_code = nint(max(min(value, 2.0e9_wp), -2.0e9_wp))   ! a huge value overflowed nint
      if (check_code < 0 .or. check_code > 7 .or. real(check_code, wp) /= value) then
        call card_problem(deck, log, card, name, "must be a code 0-7 (0 none, 1 x, 2 y, 3 z, 4 xy, "// &
                          "5 yz, 6 zx, 7 xyz), found "//real_text(value))
        check_code = 0
      end if
    end function check_code
  end subroutine read_rigid_materials

  !> *BOUNDARY_PRESCRIBED_MOTION_RIGID(_ID): PID DOF VAD LCID SF VID DEATH BIRTH per line.
  subroutine read_rigid_motions(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    type(rigid_motion_input_t) :: motion
    integer :: line, vector, id
    character(len=:), allocatable :: heading

    line = 0
    if (keyword%id) then
      if (.not. next_line(deck, block, line, .false.)) return
      call id_heading(deck, block, line, "ID", id, heading, log)
    end if
    do while (next_line(deck, block, line, .true.))
      call open_card(deck, block, line, standard_widths, card, log)
      motion = rigid_motion_input_t(line=line)
      call get_integer(deck, card, 1, "PID", motion%part_id, log)
      call get_integer(deck, card, 2, "DOF", motion%dof, log)
      call get_integer(deck, card, 3, "VAD", motion%kind, log)
      call get_integer(deck, card, 4, "LCID", motion%curve_id, log)
      call get_real(deck, card, 5, "SF", motion%scale, log)
      call get_integer(deck, card, 6, "VID", vector, log)
      call get_real(deck, card, 7, "DEATH", motion%death, log)
      call get_real(deck, card, 8, "BIRTH", motion%birth, log)
      if (motion%scale == 0.0_wp) motion%scale = 1.0_wp
      if (motion%death == 0.0_wp) motion%death = 1.0e28_wp
      if (card%failed) cycle
      if (motion%part_id <= 0) call card_problem(deck, log, card, "PID", "must be the id of a rigid part, found "// &
                                                 integer_text(motion%part_id))
      select case (motion%dof)
      case (1:3, 5:7)
      case (4, -4, 8, -8)
        call card_problem(deck, log, card, "DOF", integer_text(motion%dof)//" (motion along or about a "// &
          "vector VID) is not available; use DOF 1-3 (x, y, z translation) or 5-7 (rotation about x, y, z)")
      case default
        call card_problem(deck, log, card, "DOF", "must be 1, 2, 3 (x, y, z translation) or 5, 6, 7 "// &
          "(rotation about x, y, z through the centre of mass), found "//integer_text(motion%dof))
      end select
      select case (motion%kind)
      case (motion_velocity, motion_acceleration, motion_displacement)
      case (3, 4)
        call card_problem(deck, log, card, "VAD", integer_text(motion%kind)//" (velocity against "// &
          "displacement, relative displacement) is not available; use 0 (velocity), 1 (acceleration) "// &
          "or 2 (displacement)")
      case default
        call card_problem(deck, log, card, "VAD", "must be 0 (velocity), 1 (acceleration) or 2 "// &
                          "(displacement), found "//integer_text(motion%kind))
      end select
      if (motion%curve_id <= 0) call card_problem(deck, log, card, "LCID", "a load curve id is required, found "// &
                                                  integer_text(motion%curve_id))
      if (vector /= 0) call card_problem(deck, log, card, "VID", "vectors and local coordinate systems "// &
                                         "are not available; leave VID blank")
      if (motion%death <= motion%birth) call card_problem(deck, log, card, "DEATH", "death time "// &
        real_text(motion%death)//" must be later than the birth time "//real_text(motion%birth))
      call append_rigid_motion(input, motion)
    end do
  end subroutine read_rigid_motions

  !> *CONSTRAINED_NODAL_RIGID_BODY(_TITLE): PID CID NSID PNODE IPRT DRFLAG RRFLAG per body.
  subroutine read_nodal_rigid_bodies(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    type(nodal_rigid_input_t) :: body
    integer :: line, release
    character(len=:), allocatable :: title

    line = 0
    do while (next_definition(deck, block, keyword%title, line, standard_widths, card, title, &
                              log, "card 1 (PID CID NSID PNODE IPRT DRFLAG RRFLAG)", "PID"))
      body = nodal_rigid_input_t(line=line)
      call get_integer(deck, card, 1, "PID", body%id, log)
      call get_integer(deck, card, 3, "NSID", body%node_set, log)
      call warn_if_set(deck, card, 2, "CID", "rbdout is written in global axes", warnings)
      call warn_if_set(deck, card, 4, "PNODE", "rbdout is written at the centre of mass", warnings)
      call warn_if_set(deck, card, 5, "IPRT", "rbdout is always written", warnings)
      call get_integer(deck, card, 6, "DRFLAG", release, log)
      if (release /= 0) call card_problem(deck, log, card, "DRFLAG", "displacement release is not "// &
                                          "available; leave DRFLAG blank")
      call get_integer(deck, card, 7, "RRFLAG", release, log)
      if (release /= 0) call card_problem(deck, log, card, "RRFLAG", "rotation release is not "// &
                                          "available; leave RRFLAG blank")
      if (card%failed) cycle
      if (body%id <= 0) then
        call card_problem(deck, log, card, "PID", "must be a positive rigid body id, found "// &
                          integer_text(body%id))
        cycle
      end if
      if (body%node_set == 0) body%node_set = body%id
      call append_nodal_body(input, body)
    end do
  end subroutine read_nodal_rigid_bodies

  !> *ELEMENT_MASS: EID (8) NID (8) MASS (16) PID (8) per line.
  subroutine read_element_masses(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    type(element_mass_input_t) :: mass
    integer :: line
    line = 0
    do while (next_line(deck, block, line, .true.))
      call open_card(deck, block, line, mass_widths, card, log)
      mass = element_mass_input_t(line=line)
      call get_integer(deck, card, 1, "EID", mass%id, log)
      call get_integer(deck, card, 2, "NID", mass%node_id, log)
      call get_real(deck, card, 3, "MASS", mass%mass, log)
      call warn_if_set(deck, card, 4, "PID", "the mass counts in no part's matsum", warnings)
      if (card%failed) cycle
      if (.not. mass%mass >= 0.0_wp) then
        call card_problem(deck, log, card, "MASS", "must not be negative, found "//real_text(mass%mass))
        cycle
      end if
      call append_element_mass(input, mass)
    end do
  end subroutine read_element_masses

  !> *CONSTRAINED_SPOTWELD(_ID): with _ID a card WID before each weld; card 1 N1 N2 SN SS N M TF
  !> EP. SN or SS 0 leaves that term out of the failure criterion; N and M 0 take 2; TF 0 takes
  !> 1e20 (never). EP > 0: the weld fails once a shell at one of its nodes reaches that effective
  !> plastic strain.
  subroutine read_spot_welds(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    type(spot_weld_input_t) :: weld
    integer :: line, id
    line = 0
    do while (next_line(deck, block, line, .true.))
      id = 0
      if (keyword%id) then
        call open_card(deck, block, line, standard_widths, card, log)
        call get_integer(deck, card, 1, "WID", id, log)
        if (.not. card%failed .and. id <= 0) call card_problem(deck, log, card, "WID", &
          "must be a positive weld id, found "//integer_text(id))
        if (.not. next_line(deck, block, line, .true.)) then
          call located_problem(deck, log, line, "N1", "card 1 (N1 N2 SN SS N M TF EP) of weld "// &
                               integer_text(id)//" is missing")
          return
        end if
      end if
      call open_card(deck, block, line, standard_widths, card, log)
      weld = spot_weld_input_t(id=id, line=line)
      call get_integer(deck, card, 1, "N1", weld%node_ids(1), log)
      call get_integer(deck, card, 2, "N2", weld%node_ids(2), log)
      call read_weld_strengths(deck, card, 3, weld, log)
      call get_real(deck, card, 7, "TF", weld%failure_time, log)
      call get_real(deck, card, 8, "EP", weld%failure_plastic_strain, log)
      if (weld%failure_plastic_strain < 0.0_wp) call card_problem(deck, log, card, "EP", &
        "must be >= 0 (0: no failure by plastic strain), found "//real_text(weld%failure_plastic_strain))
      if (card%failed) cycle
      if (weld%failure_time == 0.0_wp) weld%failure_time = 1.0e20_wp
      if (any(weld%node_ids <= 0)) then
        call card_problem(deck, log, card, merge("N1", "N2", weld%node_ids(1) <= 0), &
                          "a spot weld needs two node ids, found "//integer_text(weld%node_ids(1))//" and "// &
                          integer_text(weld%node_ids(2)))
        cycle
      end if
      if (weld%node_ids(1) == weld%node_ids(2)) then
        call card_problem(deck, log, card, "N2", "the weld joins node "//integer_text(weld%node_ids(1))// &
                          " to itself")
        cycle
      end if
      call append_spot_weld(input, weld)
    end do
  end subroutine read_spot_welds

  !> *CONSTRAINED_GENERALIZED_WELD_SPOT(_ID): with _ID a card WID; card 1 NSID CID FILTER WINDOW
  !> NPR NPRT; card 2 TFAIL EPSF SN SS N M. The node set is held as one rigid body until the
  !> weld fails. CID (a local system for the failure forces) is refused; FILTER, WINDOW, NPR,
  !> NPRT (force filtering and printing) are read but not used; EPSF as EP of *CONSTRAINED_SPOTWELD.
  subroutine read_generalized_spot_welds(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    type(spot_weld_input_t) :: weld
    integer :: line, id, system
    line = 0
    do while (next_line(deck, block, line, .true.))
      id = 0
      if (keyword%id) then
        call open_card(deck, block, line, standard_widths, card, log)
        call get_integer(deck, card, 1, "WID", id, log)
        if (.not. card%failed .and. id <= 0) call card_problem(deck, log, card, "WID", &
          "must be a positive weld id, found "//integer_text(id))
        if (.not. next_line(deck, block, line, .true.)) then
          call located_problem(deck, log, line, "NSID", "card 1 (NSID CID FILTER WINDOW NPR NPRT) of weld "// &
                               integer_text(id)//" is missing")
          return
        end if
      end if
      call open_card(deck, block, line, standard_widths, card, log)
      weld = spot_weld_input_t(id=id, line=line)
      call get_integer(deck, card, 1, "NSID", weld%node_set, log)
      call get_integer(deck, card, 2, "CID", system, log)
      if (system /= 0) call card_problem(deck, log, card, "CID", "local coordinate systems are not available "// &
        "for welds (the failure forces are taken along and across the weld); leave CID blank")
      call warn_if_set(deck, card, 3, "FILTER", "weld forces are not filtered", warnings)
      call warn_if_set(deck, card, 4, "WINDOW", "weld forces are not filtered", warnings)
      call warn_if_set(deck, card, 5, "NPR", "weld forces are not printed to a file", warnings)
      call warn_if_set(deck, card, 6, "NPRT", "weld forces are not printed to a file", warnings)
      if (.not. card%failed .and. weld%node_set <= 0) call card_problem(deck, log, card, "NSID", &
        "must be the id of a node set, found "//integer_text(weld%node_set))
      if (.not. next_line(deck, block, line, .true.)) then
        call located_problem(deck, log, line, "TFAIL", "card 2 (TFAIL EPSF SN SS N M) is missing")
        return
      end if
      call open_card(deck, block, line, standard_widths, card, log)
      call get_real(deck, card, 1, "TFAIL", weld%failure_time, log)
      call get_real(deck, card, 2, "EPSF", weld%failure_plastic_strain, log)
      if (weld%failure_plastic_strain < 0.0_wp) call card_problem(deck, log, card, "EPSF", &
        "must be >= 0 (0: no failure by plastic strain), found "//real_text(weld%failure_plastic_strain))
      call read_weld_strengths(deck, card, 3, weld, log)
      if (card%failed) cycle
      if (weld%node_set <= 0) cycle
      if (weld%failure_time == 0.0_wp) weld%failure_time = 1.0e20_wp
      call append_spot_weld(input, weld)
    end do
  end subroutine read_generalized_spot_welds

  !> SN SS N M from fields first .. first + 3: strengths not negative, exponents positive (0: 2).
  subroutine read_weld_strengths(deck, card, first, weld, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    integer, intent(in) :: first
    type(spot_weld_input_t), intent(inout) :: weld
    type(problem_log_t), intent(inout) :: log
    call get_real(deck, card, first, "SN", weld%normal_strength, log)
    call get_real(deck, card, first + 1, "SS", weld%shear_strength, log)
    call get_real(deck, card, first + 2, "N", weld%normal_exponent, log)
    call get_real(deck, card, first + 3, "M", weld%shear_exponent, log)
    if (card%failed) return
    if (weld%normal_exponent == 0.0_wp) weld%normal_exponent = 2.0_wp
    if (weld%shear_exponent == 0.0_wp) weld%shear_exponent = 2.0_wp
    if (.not. weld%normal_strength >= 0.0_wp) call card_problem(deck, log, card, "SN", &
      "the normal force at failure must not be negative (0: no normal-force failure), found "// &
      real_text(weld%normal_strength))
    if (.not. weld%shear_strength >= 0.0_wp) call card_problem(deck, log, card, "SS", &
      "the shear force at failure must not be negative (0: no shear-force failure), found "// &
      real_text(weld%shear_strength))
    if (.not. (weld%normal_exponent > 0.0_wp .and. weld%normal_exponent <= 100.0_wp)) call card_problem(deck, log, &
      card, "N", "the exponent must lie in (0, 100], found "//real_text(weld%normal_exponent))
    if (.not. (weld%shear_exponent > 0.0_wp .and. weld%shear_exponent <= 100.0_wp)) call card_problem(deck, log, &
      card, "M", "the exponent must lie in (0, 100], found "//real_text(weld%shear_exponent))
  end subroutine read_weld_strengths

  !> *CONSTRAINED_EXTRA_NODES_NODE: PID NID per line; the node joins rigid body PID.
  subroutine read_extra_nodes(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_links(deck, block, input, log, warnings, link_extra_node, "PID", "NID")
  end subroutine read_extra_nodes

  !> *CONSTRAINED_EXTRA_NODES_SET: PID NSID IFLAG per line; the set's nodes join rigid body PID.
  subroutine read_extra_node_sets(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_links(deck, block, input, log, warnings, link_extra_set, "PID", "NSID")
  end subroutine read_extra_node_sets

  !> *CONSTRAINED_RIGID_BODIES: PIDM PIDS IFLAG per line; rigid part PIDS joins rigid part PIDM.
  subroutine read_rigid_body_merges(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_links(deck, block, input, log, warnings, link_merge, "PIDM", "PIDS")
  end subroutine read_rigid_body_merges

  !> Lines of two ids and IFLAG (which only matters for *PART_INERTIA, not available: the
  !> nodes' masses always join the body).
  subroutine read_links(deck, block, input, log, warnings, kind, first_name, second_name)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    integer, intent(in) :: kind
    character(len=*), intent(in) :: first_name, second_name
    type(card_t) :: card
    type(rigid_link_input_t) :: link
    integer :: line
    line = 0
    do while (next_line(deck, block, line, .true.))
      call open_card(deck, block, line, standard_widths, card, log)
      link = rigid_link_input_t(kind=kind, line=line)
      call get_integer(deck, card, 1, first_name, link%body_id, log)
      call get_integer(deck, card, 2, second_name, link%other_id, log)
      if (kind /= link_extra_node) call warn_if_set(deck, card, 3, "IFLAG", "it matters only with "// &
        "*PART_INERTIA (not available): the masses of the nodes always join the body", warnings)
      if (card%failed) cycle
      if (link%body_id <= 0) then
        call card_problem(deck, log, card, first_name, "must be the id of a rigid body, found "// &
                          integer_text(link%body_id))
        cycle
      end if
      if (link%other_id <= 0) then
        call card_problem(deck, log, card, second_name, "must be a positive id, found "//integer_text(link%other_id))
        cycle
      end if
      input%rigid%link_count = input%rigid%link_count + 1
      input%rigid%links(input%rigid%link_count) = link
    end do
  end subroutine read_links

  !> Cross-check: rigid parts, nodal rigid bodies, their constraints and prescribed motions,
  !> and lumped masses. Call after parts, node sets and curves are resolved.
  subroutine build_rigid_bodies(deck, input, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    integer, allocatable :: owner(:), body_lines(:), main_part(:)
    type(rigid_body_t), allocatable :: bodies(:)
    integer :: k, part, body_count, node_count

    node_count = input%node_count
    associate (model => input%model)
      ! rigid parts
      body_count = 0
      do part = 1, size(model%parts)
        if (is_rigid_part(part)) then
          model%parts(part)%formulation = formulation_rigid
          body_count = body_count + 1
        end if
      end do
      allocate (bodies(body_count + input%rigid%nodal_count), body_lines(body_count + input%rigid%nodal_count))
      allocate (owner(node_count))
      owner = 0
      call merge_rigid_parts(main_part)
      body_count = 0
      do part = 1, size(model%parts)
        if (model%parts(part)%formulation /= formulation_rigid) cycle
        if (main_part(part) /= part) cycle
        body_count = body_count + 1
        bodies(body_count)%id = model%parts(part)%id
        bodies(body_count)%part = part
        body_lines(body_count) = input%part_lines(part)
        call set_constraints(part, bodies(body_count))
        call collect_part_nodes(part, body_count)
        ! parts merged into it (*CONSTRAINED_RIGID_BODIES): their elements and nodes
        bodies(body_count)%merged_parts = pack([(k, k=1, size(model%parts))], &
                                               main_part == part .and. [(k, k=1, size(model%parts))] /= part)
        bodies(body_count)%merged_ids = [(model%parts(bodies(body_count)%merged_parts(k))%id, &
                                          k=1, size(bodies(body_count)%merged_parts))]
        do k = 1, size(bodies(body_count)%merged_parts)
          call collect_part_nodes(bodies(body_count)%merged_parts(k), body_count)
        end do
      end do
      do k = 1, input%rigid%nodal_count
        call add_nodal_body(input%rigid%nodal(k))
      end do
      call add_extra_nodes()
      call move_alloc(bodies, model%rigid_bodies)
      model%rigid_bodies = model%rigid_bodies(1:body_count)
      call build_spot_welds()
      call build_rigid_motions()
      allocate (model%node_masses(node_count))
      model%node_masses = 0.0_wp
      call apply_element_masses()
      if (model%implicit_static .and. body_count > 0) call located_problem(deck, log, body_lines(1), "MID", &
        "rigid bodies are not available in the linear static analysis (*CONTROL_IMPLICIT_GENERAL IMFLAG = 1)")
    end associate
  contains
    logical function is_rigid_part(part)
      integer, intent(in) :: part
      integer :: material
      material = input%model%parts(part)%material
      is_rigid_part = .false.
      if (material > 0) is_rigid_part = input%model%materials(material)%law == law_rigid
    end function is_rigid_part

    !> *CONSTRAINED_RIGID_BODIES: for every part the rigid part whose body it joins (itself when
    !> it joins none); chains (C into B, B into A) end at their first main part.
    subroutine merge_rigid_parts(main)
      integer, allocatable, intent(out) :: main(:)
      integer :: k, j, first, second
      allocate (main(size(input%model%parts)))
      main = [(j, j=1, size(input%model%parts))]
      do k = 1, input%rigid%link_count
        associate (link => input%rigid%links(k))
          if (link%kind /= link_merge) cycle
          first = rigid_part(link%body_id, link%line, "PIDM")
          second = rigid_part(link%other_id, link%line, "PIDS")
          if (first == 0 .or. second == 0) cycle
          do while (main(first) /= first)
            first = main(first)
          end do
          do while (main(second) /= second)
            second = main(second)
          end do
          if (first == second) cycle
          main(second) = first
        end associate
      end do
      ! every part straight to its main part (a chain ends where main(j) = j)
      do j = 1, size(main)
        first = j
        do while (main(first) /= first)
          first = main(first)
        end do
        main(j) = first
      end do
    end subroutine merge_rigid_parts

    !> The index of rigid part `id`, or 0 with the problem reported.
    integer function rigid_part(id, line, field)
      integer, intent(in) :: id, line
      character(len=*), intent(in) :: field
      integer :: j
      rigid_part = 0
      do j = 1, size(input%model%parts)
        if (input%model%parts(j)%id == id) rigid_part = j
      end do
      if (rigid_part == 0) then
        call located_problem(deck, log, line, field, "part "//integer_text(id)//" is not defined")
      else if (input%model%parts(rigid_part)%formulation /= formulation_rigid) then
        call located_problem(deck, log, line, field, "part "//integer_text(id)//" is not rigid (its material "// &
                             "is not *MAT_RIGID)")
        rigid_part = 0
      end if
    end function rigid_part

    !> *CONSTRAINED_EXTRA_NODES_NODE / _SET: the nodes join the rigid body of part PID (or the
    !> nodal rigid body PID, or the body a merged part PID joined).
    subroutine add_extra_nodes()
      type(id_index_t) :: node_index
      integer :: k, j, body, set, node
      integer, allocatable :: added(:)
      logical :: changed(body_count)
      if (input%rigid%link_count == 0) return
      call build_id_index(input%model%node_ids, node_index)
      changed = .false.
      do k = 1, input%rigid%link_count
        associate (link => input%rigid%links(k))
          if (link%kind == link_merge) cycle
          body = 0
          do j = 1, body_count
            if (bodies(j)%id == link%body_id) body = j
            if (allocated(bodies(j)%merged_ids)) then
              if (any(bodies(j)%merged_ids == link%body_id)) body = j
            end if
          end do
          if (body == 0) then
            call located_problem(deck, log, link%line, "PID", "rigid body "//integer_text(link%body_id)// &
              " is not defined (a *MAT_RIGID part or a *CONSTRAINED_NODAL_RIGID_BODY)")
            cycle
          end if
          if (link%kind == link_extra_node) then
            node = find_id(node_index, link%other_id)
            if (node == 0) then
              call located_problem(deck, log, link%line, "NID", "node "//integer_text(link%other_id)// &
                                   " is not defined")
              cycle
            end if
            added = [node]
          else
            set = 0
            do j = 1, size(input%model%node_sets)
              if (input%model%node_sets(j)%id == link%other_id) set = j
            end do
            if (set == 0) then
              call located_problem(deck, log, link%line, "NSID", "node set "//integer_text(link%other_id)// &
                                   " is not defined")
              cycle
            end if
            added = input%model%node_sets(set)%nodes
          end if
          do j = 1, size(added)
            node = added(j)
            if (owner(node) == body) cycle
            if (owner(node) /= 0) then
              call located_problem(deck, log, link%line, trim(merge("NID ", "NSID", link%kind == link_extra_node)), &
                "node "//integer_text(input%model%node_ids(node))//" belongs to rigid body "// &
                integer_text(bodies(owner(node))%id)//" and to rigid body "//integer_text(bodies(body)%id)// &
                "; a node joins one rigid body only")
              cycle
            end if
            owner(node) = body
            changed(body) = .true.
          end do
        end associate
      end do
      do body = 1, body_count
        if (changed(body)) bodies(body)%nodes = pack([(node, node=1, node_count)], owner == body)
      end do
    end subroutine add_extra_nodes

    subroutine set_constraints(part, body)
      integer, intent(in) :: part
      type(rigid_body_t), intent(inout) :: body
      integer :: m
      do m = 1, input%rigid%material_count
        if (input%rigid%materials(m)%material /= input%model%parts(part)%material) cycle
        if (input%rigid%materials(m)%constraint_mode /= 1) cycle
        body%fixed(1:3) = code_dofs(:, input%rigid%materials(m)%translations)
        body%fixed(4:6) = code_dofs(:, input%rigid%materials(m)%rotations)
      end do
    end subroutine set_constraints

    !> The nodes of the part's solids and shells, ascending; a node already in another body is
    !> reported.
    subroutine collect_part_nodes(part, body)
      integer, intent(in) :: part, body
      integer :: element, corner, count
      count = 0
      do element = 1, size(input%model%solid_part)
        if (input%model%solid_part(element) /= part) cycle
        do corner = 1, 8
          call take_node(input%model%solid_nodes(corner, element), body, count)
        end do
      end do
      do element = 1, size(input%model%shell_part)
        if (input%model%shell_part(element) /= part) cycle
        do corner = 1, 4
          call take_node(input%model%shell_nodes(corner, element), body, count)
        end do
      end do
      if (count == 0) call located_problem(deck, log, body_lines(body), "PID", "rigid part "// &
        integer_text(bodies(body)%id)//" has no elements (a rigid body needs mass)")
      bodies(body)%nodes = pack([(corner, corner=1, node_count)], owner == body)
    end subroutine collect_part_nodes

    !> Node `node` (0: an unresolved one, skipped) joins body `body` unless another has it.
    subroutine take_node(node, body, count)
      integer, intent(in) :: node, body
      integer, intent(inout) :: count
      if (node <= 0) return
      if (owner(node) == body) return
      if (owner(node) /= 0) then
        call shared_node(node, owner(node), body)
        return
      end if
      owner(node) = body
      count = count + 1
    end subroutine take_node

    subroutine shared_node(node, first, second)
      integer, intent(in) :: node, first, second
      call located_problem(deck, log, body_lines(second), "PID", "node "// &
        integer_text(input%model%node_ids(node))//" belongs to rigid body "//integer_text(bodies(first)%id)// &
        " and to rigid body "//integer_text(bodies(second)%id)//"; merge rigid parts with *CONSTRAINED_RIGID_BODIES")
    end subroutine shared_node

    subroutine add_nodal_body(given)
      type(nodal_rigid_input_t), intent(in) :: given
      integer :: set, j, node, body
      do j = 1, body_count
        if (bodies(j)%id == given%id) then
          call located_problem(deck, log, given%line, "PID", "rigid body "//integer_text(given%id)// &
            " is already defined (a rigid part or another *CONSTRAINED_NODAL_RIGID_BODY has this id)")
          return
        end if
      end do
      set = 0
      do j = 1, size(input%model%node_sets)
        if (input%model%node_sets(j)%id == given%node_set) then
          set = j
          exit
        end if
      end do
      if (set == 0) then
        call located_problem(deck, log, given%line, "NSID", "node set "//integer_text(given%node_set)// &
                             " is not defined")
        return
      end if
      if (size(input%model%node_sets(set)%nodes) == 0) then
        call located_problem(deck, log, given%line, "NSID", "node set "//integer_text(given%node_set)// &
                             " has no nodes")
        return
      end if
      body_count = body_count + 1
      body = body_count
      bodies(body)%id = given%id
      bodies(body)%part = 0
      body_lines(body) = given%line
      do j = 1, size(input%model%node_sets(set)%nodes)
        node = input%model%node_sets(set)%nodes(j)
        if (owner(node) == body) cycle
        if (owner(node) /= 0) then
          call shared_node(node, owner(node), body)
          cycle
        end if
        owner(node) = body
      end do
      bodies(body)%nodes = pack([(node, node=1, node_count)], owner == body)
    end subroutine add_nodal_body

    !> Spot welds: nodes resolved, a node in at most one weld or rigid body (a weld sharing a
    !> node with another would be applied after it and undo part of it), ids unique.
    subroutine build_spot_welds()
      type(id_index_t) :: nodes
      type(spot_weld_t), allocatable :: welds(:)
      integer :: k, j, count, set, node
      logical :: good
      allocate (welds(input%rigid%weld_count))
      count = 0
      if (input%rigid%weld_count > 0) call build_id_index(input%model%node_ids, nodes)
      do k = 1, input%rigid%weld_count
        associate (given => input%rigid%welds(k))
          welds(count + 1) = spot_weld_t(id=given%id, normal_strength=given%normal_strength, &
                                         shear_strength=given%shear_strength, normal_exponent=given%normal_exponent, &
                                         shear_exponent=given%shear_exponent, failure_time=given%failure_time, &
                                         failure_plastic_strain=given%failure_plastic_strain)
          if (welds(count + 1)%id == 0) welds(count + 1)%id = k
          good = .true.
          if (given%node_set == 0) then
            allocate (welds(count + 1)%nodes(2))
            do j = 1, 2
              welds(count + 1)%nodes(j) = find_id(nodes, given%node_ids(j))
              if (welds(count + 1)%nodes(j) == 0) then
                call located_problem(deck, log, given%line, merge("N1", "N2", j == 1), "node "// &
                                     integer_text(given%node_ids(j))//" is not defined")
                good = .false.
              end if
            end do
          else
            set = 0
            do j = 1, size(input%model%node_sets)
              if (input%model%node_sets(j)%id == given%node_set) set = j
            end do
            if (set == 0) then
              call located_problem(deck, log, given%line, "NSID", "node set "//integer_text(given%node_set)// &
                                   " is not defined")
              cycle
            end if
            welds(count + 1)%nodes = input%model%node_sets(set)%nodes
            if (size(welds(count + 1)%nodes) < 2) then
              call located_problem(deck, log, given%line, "NSID", "node set "//integer_text(given%node_set)// &
                                   " has fewer than two nodes: a weld joins at least two")
              good = .false.
            end if
          end if
          if (.not. good) cycle
          do j = 1, count
            if (welds(j)%id == welds(count + 1)%id) then
              call located_problem(deck, log, given%line, trim(merge("NSID", "N1  ", given%node_set /= 0)), "weld "// &
                integer_text(welds(j)%id)//" is defined twice")
              good = .false.
              exit
            end if
          end do
          if (.not. good) cycle
          do j = 1, size(welds(count + 1)%nodes)
            node = welds(count + 1)%nodes(j)
            if (owner(node) > 0) then
              call located_problem(deck, log, given%line, trim(merge("NSID", "N1  ", given%node_set /= 0)), "node "// &
                integer_text(input%model%node_ids(node))//" of weld "//integer_text(welds(count + 1)%id)// &
                " belongs to rigid body "//integer_text(input%model%rigid_bodies(owner(node))%id)// &
                "; a weld cannot join a rigid body (add the node to the body instead)")
              good = .false.
            else if (owner(node) < 0) then
              call located_problem(deck, log, given%line, trim(merge("NSID", "N1  ", given%node_set /= 0)), "node "// &
                integer_text(input%model%node_ids(node))//" is in weld "//integer_text(welds(-owner(node))%id)// &
                " and in weld "//integer_text(welds(count + 1)%id)//"; a node may be in one weld only "// &
                "(join a stack of sheets with one *CONSTRAINED_GENERALIZED_WELD_SPOT on all its nodes)")
              good = .false.
            end if
          end do
          if (.not. good) cycle
          count = count + 1
          owner(welds(count)%nodes) = -count
        end associate
      end do
      input%model%spot_welds = welds(1:count)
      if (input%model%implicit_static .and. input%rigid%weld_count > 0) call located_problem(deck, log, &
        input%rigid%welds(1)%line, trim(merge("NSID", "N1  ", input%rigid%welds(1)%node_set /= 0)), &
        "spot welds are not available in the linear static analysis (*CONTROL_IMPLICIT_GENERAL IMFLAG = 1)")
    end subroutine build_spot_welds

    subroutine build_rigid_motions()
      type(rigid_motion_t), allocatable :: motions(:)
      integer :: k, j, body, curve, dof, count, other
      allocate (motions(input%rigid%motion_count))
      count = 0
      do k = 1, input%rigid%motion_count
        associate (given => input%rigid%motions(k), model => input%model)
          body = 0
          do j = 1, size(model%rigid_bodies)
            if (model%rigid_bodies(j)%id == given%part_id) body = j
            if (allocated(model%rigid_bodies(j)%merged_ids)) then
              if (any(model%rigid_bodies(j)%merged_ids == given%part_id)) body = j
            end if
          end do
          if (body == 0) then
            if (any([(model%parts(j)%id, j=1, size(model%parts))] == given%part_id)) then
              call located_problem(deck, log, given%line, "PID", "part "//integer_text(given%part_id)// &
                " is not rigid (its material is not *MAT_RIGID)")
            else
              call located_problem(deck, log, given%line, "PID", "rigid part "//integer_text(given%part_id)// &
                " is not defined")
            end if
            cycle
          end if
          curve = 0
          do j = 1, size(model%curves)
            if (model%curves(j)%id == given%curve_id) curve = j
          end do
          if (curve == 0) then
            call located_problem(deck, log, given%line, "LCID", "curve "//integer_text(given%curve_id)// &
                                 " is not defined")
            cycle
          end if
          ! A DOF other than 1-3, 5-7 was reported by the reader but the motion was still kept:
          ! it must not index the body's dofs (found by fuzzing: DOF -1 stopped the cross-check
          ! with an out-of-bounds index instead of listing the problem).
          if (all(given%dof /= [1, 2, 3, 5, 6, 7])) cycle
          dof = merge(given%dof, given%dof - 1, given%dof <= 3)
          if (model%rigid_bodies(body)%fixed(dof)) then
            call located_problem(deck, log, given%line, "DOF", "rigid part "//integer_text(given%part_id)// &
              " is constrained twice: its "//trim(dof_names(dof))//" dof is already fixed by CMO/CON1/CON2 "// &
              "of its *MAT_RIGID")
            cycle
          end if
          other = 0
          do j = 1, count
            if (motions(j)%body == body .and. motions(j)%dof == dof) other = j
          end do
          if (other > 0) then
            call located_problem(deck, log, given%line, "DOF", "rigid part "//integer_text(given%part_id)// &
              " is constrained twice: its "//trim(dof_names(dof))//" dof already has a prescribed motion")
            cycle
          end if
          count = count + 1
          motions(count) = rigid_motion_t(body=body, dof=dof, kind=given%kind, curve=curve, &
                                          scale=given%scale, birth=given%birth, death=given%death)
        end associate
      end do
      input%model%rigid_motions = motions(1:count)
    end subroutine build_rigid_motions

    subroutine apply_element_masses()
      type(id_index_t) :: nodes
      integer :: k, node
      if (input%rigid%mass_count == 0) return
      call build_id_index(input%model%node_ids, nodes)
      do k = 1, input%rigid%mass_count
        associate (given => input%rigid%masses(k))
          node = find_id(nodes, given%node_id)
          if (node == 0) then
            call located_problem(deck, log, given%line, "NID", "node "//integer_text(given%node_id)// &
                                 " is not defined")
            cycle
          end if
          input%model%node_masses(node) = input%model%node_masses(node) + given%mass
        end associate
      end do
    end subroutine apply_element_masses
  end subroutine build_rigid_bodies

  subroutine append_rigid_material(input, entry)
    type(deck_input_t), intent(inout) :: input
    type(rigid_material_input_t), intent(in) :: entry
    input%rigid%material_count = input%rigid%material_count + 1
    input%rigid%materials(input%rigid%material_count) = entry
  end subroutine append_rigid_material

  subroutine append_rigid_motion(input, entry)
    type(deck_input_t), intent(inout) :: input
    type(rigid_motion_input_t), intent(in) :: entry
    input%rigid%motion_count = input%rigid%motion_count + 1
    input%rigid%motions(input%rigid%motion_count) = entry
  end subroutine append_rigid_motion

  subroutine append_nodal_body(input, entry)
    type(deck_input_t), intent(inout) :: input
    type(nodal_rigid_input_t), intent(in) :: entry
    input%rigid%nodal_count = input%rigid%nodal_count + 1
    input%rigid%nodal(input%rigid%nodal_count) = entry
  end subroutine append_nodal_body

  subroutine append_spot_weld(input, entry)
    type(deck_input_t), intent(inout) :: input
    type(spot_weld_input_t), intent(in) :: entry
    input%rigid%weld_count = input%rigid%weld_count + 1
    input%rigid%welds(input%rigid%weld_count) = entry
  end subroutine append_spot_weld

  subroutine append_element_mass(input, entry)
    type(deck_input_t), intent(inout) :: input
    type(element_mass_input_t), intent(in) :: entry
    input%rigid%mass_count = input%rigid%mass_count + 1
    input%rigid%masses(input%rigid%mass_count) = entry
  end subroutine append_element_mass
end module deck_rigid_bodies
