!> *MAT_ELASTIC (*MAT_001), *MAT_PLASTIC_KINEMATIC (*MAT_003), *MAT_HONEYCOMB (*MAT_026),
!> *MAT_MODIFIED_HONEYCOMB (*MAT_126), *MAT_LOW_DENSITY_FOAM (*MAT_057),
!> *MAT_PIECEWISE_LINEAR_PLASTICITY (*MAT_024), *MAT_NULL (*MAT_009), *MAT_VISCOELASTIC
!> (*MAT_006), *MAT_BLATZ-KO_RUBBER (*MAT_007) and *MAT_MOONEY-RIVLIN_RUBBER (*MAT_027), with the checks
!> that catch physically impossible values before they become a NaN in the first cycle, and
!> errors naming each field whose LS-DYNA feature crashfree does not build (docs/materials.md).
!> Curve ids are resolved by deck_material_curves after all keywords are read.
!>
!> Each reader is the reader of its law's row in the keyword table (deck_keyword_table), and
!> has the table's reader interface. The materials list is sized from the data lines of every
!> material keyword, *MAT_RIGID's too (deck_input).
module deck_materials
  use kinds, only: wp
  use error_handling, only: error_list_t
  use model, only: material_t, piecewise_hardening_curve
  use material_laws, only: law_elastic, law_plastic_kinematic, law_honeycomb, law_modified_honeycomb, &
                           law_low_density_foam, law_piecewise_linear, law_null, law_viscoelastic, &
                           law_blatz_ko, law_mooney_rivlin
  use curves, only: curve_t
  use deck_problems, only: problem_log_t
  use text_format, only: integer_text, real_text
  use deck_lexer, only: deck_t
  use deck_keywords, only: keyword_t
  use deck_fields, only: card_t, require_card, next_definition, get_integer, get_real, &
                         card_problem, field_is_blank, warn_if_set, next_line, open_card
  use deck_input, only: deck_input_t
  implicit none
  private

  public :: read_elastic_materials, read_plastic_kinematic_materials, read_honeycomb_materials
  public :: read_modified_honeycomb_materials, read_low_density_foam_materials
  public :: read_piecewise_linear_materials, read_null_materials, append_material
  public :: read_mooney_rivlin_materials, read_blatz_ko_materials, read_viscoelastic_materials
  public :: mooney_rivlin_check

  !> Poisson's ratio of *MAT_BLATZ-KO_RUBBER (LS-DYNA Theory Manual, Material Model 7).
  real(wp), parameter, public :: blatz_ko_poissons_ratio = 0.463_wp

  integer, parameter :: standard_widths(8) = 10

contains

  !> Index of a new material of law `law` whose card 1 is at `line`.
  integer function append_material(input, line, law, title) result(n)
    type(deck_input_t), intent(inout) :: input
    integer, intent(in) :: line, law
    character(len=*), intent(in) :: title
    n = input%material_count + 1
    input%material_count = n
    input%material_lines(n) = line
    input%model%materials(n)%law = law
    input%model%materials(n)%title = title
  end function append_material

  !> *MAT_PIECEWISE_LINEAR_PLASTICITY: C1 MID RO E PR SIGY ETAN FAIL TDEL; C2 C P LCSS LCSR VP
  !> (unused) RFILTF; C3 EPS1-EPS8; C4 ES1-ES8. Cards 3 and 4 may be left out at the end of the
  !> keyword (no table). LS-DYNA's precedence: LCSS overrides EPS/ES, which override SIGY and
  !> ETAN; LCSR overrides C and P. The EPS/ES table becomes the curve in slot
  !> piecewise_hardening_curve (curve id 0); LCSS and LCSR are resolved by the cross-check.
  subroutine read_piecewise_linear_materials(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card, first_card, strain_card, stress_card
    integer :: line, n, k, hardening_curve, rate_curve, points
    real(wp) :: strains(8), stresses(8)
    logical :: has_table, table_cards
    character(len=:), allocatable :: title

    line = 0
    do while (next_definition(deck, block, keyword%title, line, standard_widths, card, title, &
                              log, "card 1 (MID RO E PR SIGY ETAN FAIL TDEL)", "MID"))
      n = append_material(input, line, law_piecewise_linear, title)
      associate (material => input%model%materials(n))
        call read_elastic_constants(deck, card, material, log)
        call get_real(deck, card, 5, "SIGY", material%yield_stress, log)
        call get_real(deck, card, 6, "ETAN", material%tangent_modulus, log)
        call get_real(deck, card, 7, "FAIL", material%failure_strain, log, default=1.0e21_wp)
        call get_real(deck, card, 8, "TDEL", material%failure_time_step, log)
        if (material%failure_strain == 0.0_wp) material%failure_strain = 1.0e21_wp
        if (material%failure_strain < 0.0_wp .and. .not. card%failed) call card_problem(deck, log, card, "FAIL", &
          "FAIL < 0 (a user failure subroutine) is not available; give 0 or a plastic failure strain, found "// &
          real_text(material%failure_strain))
        if (material%failure_time_step < 0.0_wp .and. .not. card%failed) call card_problem(deck, log, card, &
          "TDEL", "the smallest element step before erosion must be >= 0 (0: off), found "// &
          real_text(material%failure_time_step))
        first_card = card

        if (.not. require_card(deck, block, line, standard_widths, card, log, &
                               "card 2 (C P LCSS LCSR VP)", "C")) exit
        call get_real(deck, card, 1, "C", material%rate_c, log)
        call get_real(deck, card, 2, "P", material%rate_p, log)
        call get_integer(deck, card, 3, "LCSS", hardening_curve, log)
        call get_integer(deck, card, 4, "LCSR", rate_curve, log)
        call get_real(deck, card, 5, "VP", material%rate_formulation, log)
        call warn_if_set(deck, card, 7, "RFILTF", "rate filtering belongs to VP = 4, not available", warnings)
        if (.not. card%failed) then
          if (hardening_curve < 0) call card_problem(deck, log, card, "LCSS", "curve id must be >= 0 (0: "// &
            "EPS1-8 / ES1-8 or SIGY, ETAN), found "//integer_text(hardening_curve))
          if (rate_curve < 0) call card_problem(deck, log, card, "LCSR", "curve id must be >= 0 (0: C, P), "// &
            "found "//integer_text(rate_curve))
          if (rate_curve > 0) then
            call warn_if_set(deck, card, 1, "C", "LCSR overrides C and P", warnings)
            call warn_if_set(deck, card, 2, "P", "LCSR overrides C and P", warnings)
          else
            call check_rate(deck, card, material, log, "C", "P")
          end if
          if (material%rate_formulation /= 0.0_wp .and. material%rate_formulation /= 1.0_wp) &
            call card_problem(deck, log, card, "VP", "must be 0 (scale the yield stress) or 1 (viscoplastic), "// &
              "found "//real_text(material%rate_formulation)//"; VP = -1 (deviatoric rate), 3 and 4 "// &
              "(filtered rates) are not available")
        end if
        material%curve_ids = [max(hardening_curve, 0), max(rate_curve, 0)]
        allocate (material%curves(size(material%curve_ids)))

        ! Cards 3 and 4: the EPS / ES table (optional at the end of the keyword).
        strains = 0.0_wp
        stresses = 0.0_wp
        table_cards = next_line(deck, block, line, .false.)
        if (table_cards) then
          call open_card(deck, block, line, standard_widths, strain_card, log)
          do k = 1, 8
            call get_real(deck, strain_card, k, "EPS"//achar(iachar("0") + k), strains(k), log)
          end do
          if (.not. require_card(deck, block, line, standard_widths, stress_card, log, &
                                 "card 4 (ES1 ... ES8)", "ES1")) exit
          do k = 1, 8
            call get_real(deck, stress_card, k, "ES"//achar(iachar("0") + k), stresses(k), log)
          end do
        end if
        has_table = any(stresses /= 0.0_wp) .or. any(strains /= 0.0_wp)
        if (has_table .and. hardening_curve > 0) then
          do k = 1, 8
            call warn_if_set(deck, strain_card, k, "EPS"//achar(iachar("0") + k), "LCSS overrides EPS1-8", warnings)
            call warn_if_set(deck, stress_card, k, "ES"//achar(iachar("0") + k), "LCSS overrides ES1-8", warnings)
          end do
        else if (has_table .and. .not. (strain_card%failed .or. stress_card%failed)) then
          call check_table(deck, strain_card, stress_card, strains, stresses, points, log)
          if (points > 0) then
            material%curves(piecewise_hardening_curve) = curve_t(id=0, title="EPS1-ES8 of material "// &
              integer_text(material%id), abscissa=strains(1:points), ordinate=stresses(1:points))
          end if
        end if
        if (.not. first_card%failed .and. hardening_curve <= 0 .and. .not. has_table) &
          call check_bilinear(deck, first_card, material, log)
      end associate
    end do
  end subroutine read_piecewise_linear_materials

  !> The EPS1-8 / ES1-8 table: the points up to the last one given (a blank or zero pair ends
  !> it), with ES1 > 0, increasing plastic strains from EPS1 >= 0 and positive yield stresses.
  !> `points` is 0 when the table was rejected.
  subroutine check_table(deck, strain_card, stress_card, strains, stresses, points, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(in) :: strain_card, stress_card
    real(wp), intent(in) :: strains(8), stresses(8)
    integer, intent(out) :: points
    type(problem_log_t), intent(inout) :: log
    integer :: k, problems
    character(len=1) :: digit, previous

    problems = log%total
    points = 1
    do k = 2, 8
      if (strains(k) /= 0.0_wp .or. stresses(k) /= 0.0_wp) points = k
    end do
    if (stresses(1) <= 0.0_wp) call card_problem(deck, log, stress_card, "ES1", "the EPS / ES table needs "// &
      "ES1 > 0 (the initial yield stress), found "//real_text(stresses(1))//"; without a table leave "// &
      "EPS1-8 and ES1-8 blank and give SIGY and ETAN")
    if (strains(1) < 0.0_wp) call card_problem(deck, log, strain_card, "EPS1", "effective plastic strain "// &
      "must be >= 0, found "//real_text(strains(1)))
    do k = 2, points
      digit = achar(iachar("0") + k)
      previous = achar(iachar("0") + k - 1)
      if (strains(k) <= strains(k - 1)) call card_problem(deck, log, strain_card, "EPS"//digit, &
        "effective plastic strains must increase: EPS"//digit//" = "//real_text(strains(k))// &
        " is not above EPS"//previous//" = "//real_text(strains(k - 1)))
      if (stresses(k) <= 0.0_wp .and. stresses(1) > 0.0_wp) call card_problem(deck, log, stress_card, &
        "ES"//digit, "yield stress must be > 0, found "//real_text(stresses(k)))
    end do
    if (log%total > problems) points = 0
  end subroutine check_table

  !> SIGY > 0 and 0 <= ETAN < E when they define the hardening (no LCSS, no table).
  subroutine check_bilinear(deck, card, material, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(in) :: card
    type(material_t), intent(in) :: material
    type(problem_log_t), intent(inout) :: log
    if (material%yield_stress <= 0.0_wp) call card_problem(deck, log, card, "SIGY", "yield stress must be "// &
      "> 0 when neither LCSS nor the EPS1-8 / ES1-8 table is given, found "// &
      shown(card, 5, material%yield_stress))
    if (material%tangent_modulus < 0.0_wp) then
      call card_problem(deck, log, card, "ETAN", "tangent modulus must be >= 0, found "// &
                        real_text(material%tangent_modulus))
    else if (material%tangent_modulus >= material%youngs_modulus .and. material%youngs_modulus > 0.0_wp) then
      call card_problem(deck, log, card, "ETAN", "tangent modulus must be smaller than E = "// &
        real_text(material%youngs_modulus)//", found "//real_text(material%tangent_modulus))
    end if
  end subroutine check_bilinear

  !> *MAT_NULL: MID RO PC MU TEROD CEROD YM PR, one card per material. crashfree takes it on
  !> shell parts (contact surfaces without stress); YM and PR give those shells their time step
  !> and contact stiffness. PC and MU act through an equation of state, which is not read.
  subroutine read_null_materials(deck, block, keyword, input, log, warnings)
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
                              log, "card 1 (MID RO PC MU TEROD CEROD YM PR)", "MID"))
      n = append_material(input, line, law_null, title)
      associate (material => input%model%materials(n))
        call get_integer(deck, card, 1, "MID", material%id, log)
        call get_real(deck, card, 2, "RO", material%density, log)
        call get_real(deck, card, 3, "PC", material%pressure_cutoff, log)
        call get_real(deck, card, 4, "MU", material%viscosity, log)
        call get_real(deck, card, 7, "YM", material%youngs_modulus, log)
        call get_real(deck, card, 8, "PR", material%poissons_ratio, log)
        if (.not. card%failed) then
          call check_id_and_density(deck, card, material, log)
          if (material%pressure_cutoff > 0.0_wp) call card_problem(deck, log, card, "PC", "pressure "// &
            "cut-off must be <= 0, found "//real_text(material%pressure_cutoff))
          if (material%viscosity < 0.0_wp) call card_problem(deck, log, card, "MU", "viscosity "// &
            "coefficient must be >= 0, found "//real_text(material%viscosity))
          if (material%youngs_modulus < 0.0_wp) call card_problem(deck, log, card, "YM", "Young's "// &
            "modulus must be >= 0, found "//real_text(material%youngs_modulus))
          if (material%poissons_ratio <= -1.0_wp .or. material%poissons_ratio >= 0.5_wp) &
            call card_problem(deck, log, card, "PR", "Poisson's ratio must lie in (-1, 0.5), "// &
                              "found "//real_text(material%poissons_ratio))
        end if
        call warn_if_set(deck, card, 3, "PC", "no equation of state: a null shell carries no pressure", warnings)
        call warn_if_set(deck, card, 4, "MU", "no equation of state: a null shell carries no viscous stress", &
                         warnings)
        call warn_if_set(deck, card, 5, "TEROD", "null shells do not erode by volume strain", warnings)
        call warn_if_set(deck, card, 6, "CEROD", "null shells do not erode by volume strain", warnings)
      end associate
    end do
  end subroutine read_null_materials

  !> *MAT_ELASTIC: MID RO E PR DA DB K, one card per material (DA, DB: beams; K: fluids).
  subroutine read_elastic_materials(deck, block, keyword, input, log, warnings)
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
                              log, "card 1 (MID RO E PR DA DB K)", "MID"))
      n = append_material(input, line, law_elastic, title)
      associate (material => input%model%materials(n))
        call read_elastic_constants(deck, card, material, log)
      end associate
    end do
  end subroutine read_elastic_materials

  !> *MAT_PLASTIC_KINEMATIC: card 1 MID RO E PR SIGY ETAN BETA, card 2 SRC SRP FS VP.
  subroutine read_plastic_kinematic_materials(deck, block, keyword, input, log, warnings)
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
                              log, "card 1 (MID RO E PR SIGY ETAN BETA)", "MID"))
      n = append_material(input, line, law_plastic_kinematic, title)
      associate (material => input%model%materials(n))
        call read_elastic_constants(deck, card, material, log)
        call get_real(deck, card, 5, "SIGY", material%yield_stress, log)
        call get_real(deck, card, 6, "ETAN", material%tangent_modulus, log)
        call get_real(deck, card, 7, "BETA", material%hardening_beta, log)
        if (.not. card%failed) call check_hardening(deck, card, material, log)
        if (.not. require_card(deck, block, line, standard_widths, card, log, &
                               "card 2 (SRC SRP FS VP)", "SRC")) exit
        call get_real(deck, card, 1, "SRC", material%rate_c, log)
        call get_real(deck, card, 2, "SRP", material%rate_p, log)
        call get_real(deck, card, 3, "FS", material%failure_strain, log)
        call get_real(deck, card, 4, "VP", material%rate_formulation, log)
        if (.not. card%failed) then
          if (material%failure_strain < 0.0_wp) call card_problem(deck, log, card, "FS", "the effective "// &
            "plastic strain at failure must be > 0 (0: no failure), found "//real_text(material%failure_strain))
          call check_rate(deck, card, material, log, "SRC", "SRP")
          if (material%rate_formulation /= 0.0_wp .and. material%rate_formulation /= 1.0_wp) &
            call card_problem(deck, log, card, "VP", "must be 0 (scale the yield stress) or 1 "// &
                              "(viscoplastic), found "//real_text(material%rate_formulation))
        end if
      end associate
    end do
  end subroutine read_plastic_kinematic_materials

  !> *MAT_HONEYCOMB (026): see read_honeycombs.
  subroutine read_honeycomb_materials(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_honeycombs(deck, block, keyword, .false., input, log)
  end subroutine read_honeycomb_materials

  !> *MAT_MODIFIED_HONEYCOMB (126): see read_honeycombs.
  subroutine read_modified_honeycomb_materials(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_honeycombs(deck, block, keyword, .true., input, log)
  end subroutine read_modified_honeycomb_materials

  !> *MAT_HONEYCOMB (026, `modified` false) and *MAT_MODIFIED_HONEYCOMB (126): cards 1-5
  !> (126: 1-8, cards 6-8 optional; a 126 keyword therefore holds one material).
  !> C1 MID RO E PR SIGY VF MU BULK; C2 LCA LCB LCC LCS LCAB LCBC LCCA LCSR;
  !> C3 EAAU EBBU ECCU GABU GBCU GCAU AOPT MACF; C4 XP YP ZP A1 A2 A3 (126: RFAC PRU);
  !> C5 D1 D2 D3 TSEF SSEF (026: V1 V2 V3; 126: VREF TREF SHDFLG); 126: C6 V1 V2 V3,
  !> C7 LCSRA ... LCSRCA, C8 PRUAB ... PRUCB.
  subroutine read_honeycombs(deck, block, keyword, modified, input, log)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    logical, intent(in) :: modified
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(card_t) :: card
    integer :: line, n, k, ids(8), macf
    real(wp) :: value, aopt
    character(len=:), allocatable :: title
    character(len=4), parameter :: curve_names(8) = ["LCA ", "LCB ", "LCC ", "LCS ", "LCAB", "LCBC", "LCCA", "LCSR"]
    character(len=4), parameter :: modulus_names(6) = ["EAAU", "EBBU", "ECCU", "GABU", "GBCU", "GCAU"]
    character(len=6), parameter :: rate_names(6) = ["LCSRA ", "LCSRB ", "LCSRC ", "LCSRAB", "LCSRBC", "LCSRCA"]
    character(len=5), parameter :: poisson_names(6) = ["PRUAB", "PRUAC", "PRUBC", "PRUBA", "PRUCA", "PRUCB"]

    line = 0
    do while (next_definition(deck, block, keyword%title, line, standard_widths, card, title, &
                              log, "card 1 (MID RO E PR SIGY VF MU BULK)", "MID"))
      n = append_material(input, line, merge(law_modified_honeycomb, law_honeycomb, modified), title)
      associate (material => input%model%materials(n))
        call read_elastic_constants(deck, card, material, log)
        call get_real(deck, card, 5, "SIGY", material%yield_stress, log)
        call get_real(deck, card, 6, "VF", material%compaction_volume, log)
        call get_real(deck, card, 7, "MU", material%viscosity, log, default=0.05_wp)
        ! LS-DYNA reads 0 as the default, as for a blank field
        if (material%viscosity == 0.0_wp) material%viscosity = 0.05_wp
        call get_real(deck, card, 8, "BULK", value, log)
        if (.not. card%failed) then
          if (material%yield_stress < 0.0_wp) call card_problem(deck, log, card, "SIGY", "yield stress of the "// &
            "compacted material must be >= 0, found "//real_text(material%yield_stress))
          if (material%compaction_volume <= 0.0_wp .or. material%compaction_volume > 1.0_wp) &
            call card_problem(deck, log, card, "VF", "relative volume at full compaction must lie in (0, 1], "// &
                              "found "//shown(card, 6, material%compaction_volume))
          if (material%viscosity < 0.0_wp) call card_problem(deck, log, card, "MU", "viscosity coefficient "// &
            "must be >= 0, found "//real_text(material%viscosity))
          if (value /= 0.0_wp .and. value /= 1.0_wp) call card_problem(deck, log, card, "BULK", "must be 0 "// &
            "or 1, found "//real_text(value))
          material%bulk_viscosity = value == 1.0_wp
        end if

        if (.not. require_card(deck, block, line, standard_widths, card, log, &
                               "card 2 (LCA LCB LCC LCS LCAB LCBC LCCA LCSR)", "LCA")) exit
        do k = 1, 8
          call get_integer(deck, card, k, trim(curve_names(k)), ids(k), log)
        end do
        if (.not. card%failed) then
          if (ids(1) < 0 .and. modified) then
            call card_problem(deck, log, card, "LCA", "LCA < 0 (the alternative formulation with yield "// &
                              "against the angle off the material axis) is not available; give LCA > 0")
          else if (ids(1) <= 0) then
            call card_problem(deck, log, card, "LCA", "a yield curve id > 0 is required, found "// &
                              integer_text(ids(1)))
          end if
          do k = 2, 7
            if (ids(k) < 0) call card_problem(deck, log, card, trim(curve_names(k)), "curve id must be >= 0 "// &
              "(0: the default curve), found "//integer_text(ids(k)))
          end do
          if (ids(8) == -1 .and. modified) then
            call card_problem(deck, log, card, "LCSR", "LCSR = -1 (per-direction rate curves on card 7) is "// &
                              "not available; give one scale-factor curve or 0")
          else if (ids(8) < 0) then
            call card_problem(deck, log, card, "LCSR", "curve id must be >= 0, found "//integer_text(ids(8)))
          end if
        end if
        ! LS-DYNA's defaults: LCB, LCC, LCS -> LCA; LCAB, LCBC, LCCA -> LCS.
        if (ids(2) == 0) ids(2) = ids(1)
        if (ids(3) == 0) ids(3) = ids(1)
        if (ids(4) == 0) ids(4) = ids(1)
        do k = 5, 7
          if (ids(k) == 0) ids(k) = ids(4)
        end do
        material%curve_ids = [ids(1:3), ids(5:7), max(ids(8), 0)]

        if (.not. require_card(deck, block, line, standard_widths, card, log, &
                               "card 3 (EAAU EBBU ECCU GABU GBCU GCAU AOPT MACF)", "EAAU")) exit
        do k = 1, 6
          call get_real(deck, card, k, trim(modulus_names(k)), material%uncompacted_moduli(k), log)
        end do
        call get_real(deck, card, 7, "AOPT", aopt, log)
        call get_integer(deck, card, 8, "MACF", macf, log, default=1)
        if (.not. card%failed) then
          do k = 1, 6
            if (material%uncompacted_moduli(k) <= 0.0_wp) call card_problem(deck, log, card, &
              trim(modulus_names(k)), "uncompacted modulus must be > 0, found "// &
              shown(card, k, material%uncompacted_moduli(k)))
          end do
          if (aopt /= 0.0_wp .and. aopt /= 2.0_wp) call card_problem(deck, log, card, "AOPT", "material "// &
            "axes option "//real_text(aopt)//" is not available: use 0 (element nodes 1-2-4) or 2 "// &
            "(global vectors a and d)")
          ! clamped: nint of a huge AOPT (reported above) overflowed, a floating-point trap
          ! (found by fuzzing)
          material%axes_option = nint(max(min(aopt, 2.0e9_wp), -2.0e9_wp))
          if (macf /= 1 .and. macf /= 0) call card_problem(deck, log, card, "MACF", "axis swaps are not "// &
            "available: MACF must be 1 (none), found "//integer_text(macf))
        end if

        if (.not. require_card(deck, block, line, standard_widths, card, log, &
                               "card 4 (XP YP ZP A1 A2 A3)", "XP")) exit
        do k = 1, 3
          call get_real(deck, card, 3 + k, "A"//achar(iachar("0") + k), material%axis_a(k), log)
        end do
        if (modified) then
          call require_zero(deck, card, 7, "RFAC", "strain-rate filtering is not available", log)
          call require_zero(deck, card, 8, "PRU", "the uncompacted Poisson effect is not available "// &
                            "(the uncompacted components are uncoupled)", log)
        end if

        if (.not. require_card(deck, block, line, standard_widths, card, log, &
                               "card 5 (D1 D2 D3 TSEF SSEF ...)", "D1")) exit
        do k = 1, 3
          call get_real(deck, card, k, "D"//achar(iachar("0") + k), material%axis_d(k), log)
        end do
        call require_zero(deck, card, 4, "TSEF", "honeycomb failure strains are not available (tensile failure strain)", log)
        call require_zero(deck, card, 5, "SSEF", "honeycomb failure strains are not available (shear failure strain)", log)
        if (modified) then
          call require_zero(deck, card, 6, "VREF", "the reference-geometry update is not available", log)
          call require_zero(deck, card, 7, "TREF", "the reference-geometry update is not available", log)
          call require_zero(deck, card, 8, "SHDFLG", "shear damage belongs to LCA < 0, not available", log)
        end if
        if (material%axes_option == 2 .and. .not. card%failed) then
          if (norm2(material%axis_a) == 0.0_wp) then
            call card_problem(deck, log, card, "A1", "AOPT 2 needs a non-zero vector a (A1 A2 A3 on card 4)")
          else if (norm2(cross(material%axis_a, material%axis_d)) <= 1.0e-10_wp*norm2(material%axis_a)* &
                   norm2(material%axis_d)) then
            call card_problem(deck, log, card, "D1", "AOPT 2 needs a vector d (D1 D2 D3) not parallel to a")
          end if
        end if

        if (modified) then
          ! Optional cards 6 (V1 V2 V3: AOPT 3, 4 only), 7 (rate curves), 8 (Poisson's ratios).
          if (.not. next_line(deck, block, line, .false.)) exit
          call open_card(deck, block, line, standard_widths, card, log)
          if (.not. next_line(deck, block, line, .false.)) exit
          call open_card(deck, block, line, standard_widths, card, log)
          do k = 1, 6
            call require_zero(deck, card, k, trim(rate_names(k)), "per-direction rate curves belong to "// &
                              "LCSR = -1, not available", log)
          end do
          if (.not. next_line(deck, block, line, .false.)) exit
          call open_card(deck, block, line, standard_widths, card, log)
          do k = 1, 6
            call require_zero(deck, card, k, trim(poisson_names(k)), "user uncompacted Poisson's ratios "// &
                              "belong to PRU = 2, not available", log)
          end do
        end if
      end associate
    end do
  end subroutine read_honeycombs

  !> *MAT_LOW_DENSITY_FOAM: C1 MID RO E LCID TC HU BETA DAMP; C2 (optional; a keyword with
  !> card 2 holds one material) SHAPE FAIL BVFLAG ED BETA1 KCON REF.
  subroutine read_low_density_foam_materials(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, n, curve
    real(wp) :: value
    character(len=:), allocatable :: title

    line = 0
    do while (next_definition(deck, block, keyword%title, line, standard_widths, card, title, &
                              log, "card 1 (MID RO E LCID TC HU BETA DAMP)", "MID"))
      n = append_material(input, line, law_low_density_foam, title)
      associate (material => input%model%materials(n))
        material%bulk_viscosity = .false.
        call get_integer(deck, card, 1, "MID", material%id, log)
        call get_real(deck, card, 2, "RO", material%density, log)
        call get_real(deck, card, 3, "E", material%youngs_modulus, log)
        call get_integer(deck, card, 4, "LCID", curve, log)
        call get_real(deck, card, 5, "TC", material%tension_cutoff, log, default=1.0e20_wp)
        call get_real(deck, card, 6, "HU", material%hysteretic_unloading, log, default=1.0_wp)
        call require_zero(deck, card, 7, "BETA", "unloading creep (rate effects) is not available", log)
        call get_real(deck, card, 8, "DAMP", material%viscosity, log)
        material%curve_ids = [max(curve, 0)]
        if (.not. card%failed) then
          call check_id_and_density(deck, card, material, log)
          if (material%youngs_modulus <= 0.0_wp) call card_problem(deck, log, card, "E", "Young's "// &
            "modulus (tension, unloading) must be > 0, found "//shown(card, 3, material%youngs_modulus))
          if (curve <= 0) call card_problem(deck, log, card, "LCID", "a loading curve id > 0 is required, "// &
                                            "found "//integer_text(curve))
          if (material%tension_cutoff == 0.0_wp) material%tension_cutoff = 1.0e20_wp
          ! LS-DYNA reads 0 as the default (1: no hysteresis), as for a blank field
          if (material%hysteretic_unloading == 0.0_wp) material%hysteretic_unloading = 1.0_wp
          if (material%tension_cutoff < 0.0_wp) call card_problem(deck, log, card, "TC", "tension cut-off "// &
            "must be > 0 (blank or 0: 1e20), found "//real_text(material%tension_cutoff))
          if (material%hysteretic_unloading < 0.0_wp .or. material%hysteretic_unloading > 1.0_wp) &
            call card_problem(deck, log, card, "HU", "hysteretic unloading factor must lie in [0, 1], found "// &
                              real_text(material%hysteretic_unloading))
          if (material%viscosity < 0.0_wp) call card_problem(deck, log, card, "DAMP", "viscous coefficient "// &
            "must be >= 0, found "//real_text(material%viscosity))
        end if
        if (.not. next_line(deck, block, line, .false.)) exit
        call open_card(deck, block, line, standard_widths, card, log)
        call get_real(deck, card, 1, "SHAPE", material%unloading_shape, log, default=1.0_wp)
        if (material%unloading_shape == 0.0_wp) material%unloading_shape = 1.0_wp
        if (material%unloading_shape < 0.0_wp .and. .not. card%failed) call card_problem(deck, log, card, &
          "SHAPE", "unloading shape factor must be > 0, found "//real_text(material%unloading_shape))
        call require_zero(deck, card, 2, "FAIL", "resetting the stress after the tension cut-off is not "// &
                          "available (the stress is held at TC)", log)
        call get_real(deck, card, 3, "BVFLAG", value, log)
        if (value /= 0.0_wp .and. value /= 1.0_wp .and. .not. card%failed) call card_problem(deck, log, card, &
          "BVFLAG", "must be 0 or 1, found "//real_text(value))
        material%bulk_viscosity = value == 1.0_wp
        call require_zero(deck, card, 4, "ED", "relaxation (rate effects) is not available", log)
        call require_zero(deck, card, 5, "BETA1", "relaxation (rate effects) is not available", log)
        call require_zero(deck, card, 7, "REF", "initialisation from a reference geometry is not available", log)
      end associate
      call warn_if_set(deck, card, 6, "KCON", "contact stiffness comes from the contact definition", warnings)
    end do
  end subroutine read_low_density_foam_materials

  !> *MAT_MOONEY-RIVLIN_RUBBER: C1 MID RO PR A B REF; C2 (optional at the end of the keyword)
  !> SGL SW ST LCID1 DATA LCID2 BSTART TRAMP. With LCID1 > 0, A and B are fitted to the uniaxial
  !> test curve (force against change of gauge length of a SGL x SW x ST specimen) by the
  !> cross-check once the curve is resolved (deck_material_curves); else they are taken from card
  !> 1. E and PR of the material are set to the small-strain moduli (E = 2 G (1 + PR),
  !> G = 2 (A + B)) for the time step, the hourglass and transverse shear stiffness and the
  !> contact stiffness. Not built, so rejected when given: DATA other than uniaxial, the
  !> viscoelastic relaxation curve (LCID2, BSTART, TRAMP) and the reference geometry (REF).
  subroutine read_mooney_rivlin_materials(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card, first_card
    integer :: line, n, curve, test_curve, k
    real(wp) :: value
    logical :: more
    character(len=:), allocatable :: title, field, problem
    character(len=3), parameter :: specimen_fields(3) = ["SGL", "SW ", "ST "]

    line = 0
    do while (next_definition(deck, block, keyword%title, line, standard_widths, card, title, &
                              log, "card 1 (MID RO PR A B REF)", "MID"))
      n = append_material(input, line, law_mooney_rivlin, title)
      associate (material => input%model%materials(n))
        call get_integer(deck, card, 1, "MID", material%id, log)
        call get_real(deck, card, 2, "RO", material%density, log)
        call get_real(deck, card, 3, "PR", material%poissons_ratio, log)
        call get_real(deck, card, 4, "A", material%mooney_rivlin_a, log)
        call get_real(deck, card, 5, "B", material%mooney_rivlin_b, log)
        call require_zero(deck, card, 6, "REF", "initialisation from a reference geometry "// &
                          "(*INITIAL_FOAM_REFERENCE_GEOMETRY) is not available", log)
        if (.not. card%failed) then
          call check_id_and_density(deck, card, material, log)
          if (material%poissons_ratio >= 0.5_wp) call card_problem(deck, log, card, "PR", "Poisson's ratio "// &
            "must be < 0.5 (0.49 to 0.495 are usual for rubber), found "//shown(card, 3, material%poissons_ratio))
        end if
        first_card = card
        test_curve = 0
        more = next_line(deck, block, line, .false.)
        if (more) then
          call open_card(deck, block, line, standard_widths, card, log)
          do k = 1, 3
            call get_real(deck, card, k, trim(specimen_fields(k)), material%specimen_dimensions(k), log)
          end do
          call get_integer(deck, card, 4, "LCID1", test_curve, log)
          call get_real(deck, card, 5, "DATA", value, log)
          if (.not. card%failed) then
            if (test_curve < 0) call card_problem(deck, log, card, "LCID1", "curve id must be >= 0 (0: A and B "// &
              "from card 1), found "//integer_text(test_curve))
            if (test_curve > 0) then
              do k = 1, 3
                if (.not. material%specimen_dimensions(k) > 0.0_wp) call card_problem(deck, log, card, &
                  trim(specimen_fields(k)), "the specimen's gauge length, width and thickness must be > 0 with "// &
                  "LCID1, found "//shown(card, k, material%specimen_dimensions(k)))
              end do
              if (value /= 0.0_wp .and. value /= 1.0_wp) call card_problem(deck, log, card, "DATA", "must be "// &
                "blank, 0 or 1 (uniaxial test data, the only fit built), found "//real_text(value))
              call warn_if_set(deck, first_card, 4, "A", "fitted to LCID1", warnings)
              call warn_if_set(deck, first_card, 5, "B", "fitted to LCID1", warnings)
            else
              call warn_if_set(deck, card, 1, "SGL", "specimen gauge length: used only with LCID1", warnings)
              call warn_if_set(deck, card, 2, "SW", "specimen width: used only with LCID1", warnings)
              call warn_if_set(deck, card, 3, "ST", "specimen thickness: used only with LCID1", warnings)
              call warn_if_set(deck, card, 5, "DATA", "used only with LCID1", warnings)
            end if
          end if
          call get_integer(deck, card, 6, "LCID2", curve, log)
          if (curve /= 0 .and. .not. card%failed) call card_problem(deck, log, card, "LCID2", "must be blank "// &
            "or 0, found "//integer_text(curve)//": viscoelastic relaxation of this rubber is not available "// &
            "(use *MAT_VISCOELASTIC for a viscoelastic part)")
          call require_zero(deck, card, 7, "BSTART", "used only with LCID2, which is not available", log)
          call require_zero(deck, card, 8, "TRAMP", "used only with LCID2, which is not available", log)
        end if
        material%curve_ids = [max(test_curve, 0)]
        if (test_curve == 0 .and. .not. first_card%failed) then
          call mooney_rivlin_check(material, field, problem)
          if (len(problem) > 0) call card_problem(deck, log, first_card, field, problem)
        end if
      end associate
      if (.not. more) exit
    end do
  end subroutine read_mooney_rivlin_materials

  !> The checks of Mooney-Rivlin's A, B and PR (`problem` empty when they pass; `field` names
  !> the field to blame) and, when they pass, its E = 2 G (1 + PR), G = 2 (A + B). Shared by the
  !> reader and, for A and B fitted to LCID1, the cross-check (deck_material_curves).
  subroutine mooney_rivlin_check(material, field, problem)
    type(material_t), intent(inout) :: material
    character(len=:), allocatable, intent(out) :: field, problem
    real(wp) :: lowest_ratio
    field = "A"
    problem = ""
    if (.not. material%mooney_rivlin_a + material%mooney_rivlin_b > 0.0_wp) then
      problem = "the shear modulus 2 (A + B) must be > 0, found A = "//real_text(material%mooney_rivlin_a)// &
                ", B = "//real_text(material%mooney_rivlin_b)
      return
    end if
    if (material%poissons_ratio >= 0.5_wp) return    ! reported by the reader
    ! D >= 0 (the volumetric term convex, sigma_33 = 0 solvable in shells) needs
    ! PR >= (2 A + 5 B) / (5 A + 11 B)
    lowest_ratio = (2.0_wp*material%mooney_rivlin_a + 5.0_wp*material%mooney_rivlin_b)/ &
                   (5.0_wp*material%mooney_rivlin_a + 11.0_wp*material%mooney_rivlin_b)
    if (material%poissons_ratio < lowest_ratio) then
      field = "PR"
      problem = "Poisson's ratio must lie in ["//real_text(lowest_ratio)//", 0.5) for A = "// &
        real_text(material%mooney_rivlin_a)//", B = "//real_text(material%mooney_rivlin_b)//" (below, the "// &
        "volumetric term D (I3 - 1)^2 has D < 0); rubber is nearly incompressible (0.49 to 0.495), found "// &
        real_text(material%poissons_ratio)
      return
    end if
    material%youngs_modulus = 4.0_wp*(material%mooney_rivlin_a + material%mooney_rivlin_b)* &
                              (1.0_wp + material%poissons_ratio)
  end subroutine mooney_rivlin_check

  !> *MAT_BLATZ-KO_RUBBER: MID RO G REF, one card per material. Poisson's ratio is 0.463 (the
  !> law's); E = 2 G (1 + 0.463) is kept for the time step and the element stiffnesses.
  subroutine read_blatz_ko_materials(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, n
    real(wp) :: shear_modulus
    character(len=:), allocatable :: title

    line = 0
    do while (next_definition(deck, block, keyword%title, line, standard_widths, card, title, &
                              log, "card 1 (MID RO G REF)", "MID"))
      n = append_material(input, line, law_blatz_ko, title)
      associate (material => input%model%materials(n))
        call get_integer(deck, card, 1, "MID", material%id, log)
        call get_real(deck, card, 2, "RO", material%density, log)
        call get_real(deck, card, 3, "G", shear_modulus, log)
        call require_zero(deck, card, 4, "REF", "initialisation from a reference geometry "// &
                          "(*INITIAL_FOAM_REFERENCE_GEOMETRY) is not available", log)
        material%poissons_ratio = blatz_ko_poissons_ratio
        material%youngs_modulus = 2.0_wp*shear_modulus*(1.0_wp + blatz_ko_poissons_ratio)
        if (.not. card%failed) then
          call check_id_and_density(deck, card, material, log)
          if (.not. shear_modulus > 0.0_wp) call card_problem(deck, log, card, "G", "shear modulus must "// &
            "be > 0, found "//shown(card, 3, shear_modulus))
        end if
      end associate
    end do
  end subroutine read_blatz_ko_materials

  !> *MAT_VISCOELASTIC: MID RO BULK G0 GI BETA, one card per material. E and PR of the material
  !> are set from BULK and G0 (the instantaneous response) for the time step and the element
  !> stiffnesses; GI and BETA are kept for the relaxation.
  subroutine read_viscoelastic_materials(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, n
    real(wp) :: bulk_modulus, short_term_shear
    character(len=:), allocatable :: title

    line = 0
    do while (next_definition(deck, block, keyword%title, line, standard_widths, card, title, &
                              log, "card 1 (MID RO BULK G0 GI BETA)", "MID"))
      n = append_material(input, line, law_viscoelastic, title)
      associate (material => input%model%materials(n))
        call get_integer(deck, card, 1, "MID", material%id, log)
        call get_real(deck, card, 2, "RO", material%density, log)
        call get_real(deck, card, 3, "BULK", bulk_modulus, log)
        call get_real(deck, card, 4, "G0", short_term_shear, log)
        call get_real(deck, card, 5, "GI", material%long_term_shear_modulus, log)
        call get_real(deck, card, 6, "BETA", material%decay_constant, log)
        call require_zero(deck, card, 7, "REF", "initialisation from a reference geometry is not available", log)
        if (.not. card%failed) then
          call check_id_and_density(deck, card, material, log)
          if (.not. bulk_modulus > 0.0_wp) call card_problem(deck, log, card, "BULK", "bulk modulus must "// &
            "be > 0, found "//shown(card, 3, bulk_modulus))
          if (.not. short_term_shear > 0.0_wp) call card_problem(deck, log, card, "G0", "short-time shear "// &
            "modulus must be > 0, found "//shown(card, 4, short_term_shear))
          if (material%long_term_shear_modulus < 0.0_wp .or. material%long_term_shear_modulus > short_term_shear) &
            call card_problem(deck, log, card, "GI", "long-time shear modulus must lie in [0, G0 = "// &
              real_text(short_term_shear)//"], found "//real_text(material%long_term_shear_modulus))
          if (material%decay_constant < 0.0_wp) call card_problem(deck, log, card, "BETA", "decay constant "// &
            "must be >= 0, found "//real_text(material%decay_constant))
          if (bulk_modulus > 0.0_wp .and. short_term_shear > 0.0_wp) then
            material%youngs_modulus = 9.0_wp*bulk_modulus*short_term_shear/(3.0_wp*bulk_modulus + short_term_shear)
            material%poissons_ratio = (3.0_wp*bulk_modulus - 2.0_wp*short_term_shear)/ &
                                      (2.0_wp*(3.0_wp*bulk_modulus + short_term_shear))
          end if
        end if
      end associate
    end do
  end subroutine read_viscoelastic_materials

  !> An error naming field `k` when it holds anything but blank or 0: the feature is not built.
  subroutine require_zero(deck, card, k, name, reason, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    integer, intent(in) :: k
    character(len=*), intent(in) :: name, reason
    type(problem_log_t), intent(inout) :: log
    real(wp) :: value
    call get_real(deck, card, k, name, value, log)
    if (value /= 0.0_wp .and. .not. card%failed) call card_problem(deck, log, card, name, &
      "must be blank or 0, found "//real_text(value)//": "//reason)
  end subroutine require_zero

  pure function cross(u, v) result(w)
    real(wp), intent(in) :: u(3), v(3)
    real(wp) :: w(3)
    w = [u(2)*v(3) - u(3)*v(2), u(3)*v(1) - u(1)*v(3), u(1)*v(2) - u(2)*v(1)]
  end function cross

  !> MID RO E PR (fields 1-4 of card 1 of both laws) and their physical limits.
  subroutine read_elastic_constants(deck, card, material, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    type(material_t), intent(inout) :: material
    type(problem_log_t), intent(inout) :: log
    call get_integer(deck, card, 1, "MID", material%id, log)
    call get_real(deck, card, 2, "RO", material%density, log)
    call get_real(deck, card, 3, "E", material%youngs_modulus, log)
    call get_real(deck, card, 4, "PR", material%poissons_ratio, log)
    if (card%failed) return
    call check_id_and_density(deck, card, material, log)
    if (material%youngs_modulus < 0.0_wp) then
      call card_problem(deck, log, card, "E", "Young's modulus must be > 0, found "// &
        shown(card, 3, material%youngs_modulus)//" (E < 0, a curve of E, is not available)")
    else if (material%youngs_modulus == 0.0_wp) then
      call card_problem(deck, log, card, "E", "Young's modulus must be > 0, found "// &
                        shown(card, 3, material%youngs_modulus))
    end if
    if (material%poissons_ratio <= -1.0_wp .or. material%poissons_ratio >= 0.5_wp) &
      call card_problem(deck, log, card, "PR", "Poisson's ratio must lie in (-1, 0.5), "// &
                        "found "//shown(card, 4, material%poissons_ratio))
  end subroutine read_elastic_constants

  subroutine check_hardening(deck, card, material, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(in) :: card
    type(material_t), intent(in) :: material
    type(problem_log_t), intent(inout) :: log
    if (material%yield_stress < 0.0_wp) call card_problem(deck, log, card, "SIGY", "yield "// &
      "stress must be >= 0, found "//real_text(material%yield_stress))
    if (material%tangent_modulus < 0.0_wp) then
      call card_problem(deck, log, card, "ETAN", "tangent modulus must be >= 0, found "// &
                        real_text(material%tangent_modulus))
    else if (material%tangent_modulus >= material%youngs_modulus .and. &
             material%youngs_modulus > 0.0_wp) then
      call card_problem(deck, log, card, "ETAN", "tangent modulus must be smaller than E = "// &
        real_text(material%youngs_modulus)//", found "//real_text(material%tangent_modulus))
    end if
    if (material%hardening_beta < 0.0_wp .or. material%hardening_beta > 1.0_wp) &
      call card_problem(deck, log, card, "BETA", "hardening parameter must lie in [0, 1] "// &
        "(0 kinematic, 1 isotropic), found "//real_text(material%hardening_beta))
  end subroutine check_hardening

  !> Cowper-Symonds C and P (fields named `c_name`, `p_name`): both >= 0, and both > 0 or both 0.
  subroutine check_rate(deck, card, material, log, c_name, p_name)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(in) :: card
    type(material_t), intent(in) :: material
    type(problem_log_t), intent(inout) :: log
    character(len=*), intent(in) :: c_name, p_name
    if (material%rate_c < 0.0_wp) then
      call card_problem(deck, log, card, c_name, "Cowper-Symonds C must be >= 0 (0: no rate "// &
                        "effect), found "//real_text(material%rate_c))
    else if (material%rate_p < 0.0_wp) then
      call card_problem(deck, log, card, p_name, "Cowper-Symonds P must be >= 0 (0: no rate "// &
                        "effect), found "//real_text(material%rate_p))
    else if ((material%rate_c > 0.0_wp) .neqv. (material%rate_p > 0.0_wp)) then
      if (material%rate_c > 0.0_wp) then
        call card_problem(deck, log, card, p_name, "Cowper-Symonds rate effects need both "//c_name//" and "// &
          p_name//" > 0 (or both 0 for none), found "//c_name//" = "//real_text(material%rate_c)//", "// &
          p_name//" = "//real_text(material%rate_p))
      else
        call card_problem(deck, log, card, c_name, "Cowper-Symonds rate effects need both "//c_name//" and "// &
          p_name//" > 0 (or both 0 for none), found "//c_name//" = "//real_text(material%rate_c)//", "// &
          p_name//" = "//real_text(material%rate_p))
      end if
    end if
  end subroutine check_rate

  !> A value for a message, saying when it came from a blank field.
  !> MID > 0 and RO > 0 (fields 1 and 2 of card 1, the same on every material keyword read here).
  subroutine check_id_and_density(deck, card, material, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(in) :: card
    type(material_t), intent(in) :: material
    type(problem_log_t), intent(inout) :: log
    if (material%id <= 0) call card_problem(deck, log, card, "MID", "material id must be > 0, found "// &
                                            integer_text(material%id))
    if (material%density <= 0.0_wp) call card_problem(deck, log, card, "RO", "density must be > 0, found "// &
                                                      shown(card, 2, material%density))
  end subroutine check_id_and_density

  function shown(card, k, value) result(text)
    type(card_t), intent(in) :: card
    integer, intent(in) :: k
    real(wp), intent(in) :: value
    character(len=:), allocatable :: text
    text = real_text(value)
    if (field_is_blank(card, k)) text = text//" (the field is blank)"
  end function shown
end module deck_materials
