!> *MAT_ELASTIC (*MAT_001) and *MAT_PLASTIC_KINEMATIC (*MAT_003), with the checks that catch
!> physically impossible values before they become a NaN in the first cycle.
module deck_materials
  use kinds, only: wp
  use error_handling, only: error_list_t
  use model, only: material_t, law_elastic, law_plastic_kinematic
  use deck_problems, only: problem_log_t
  use deck_numbers, only: integer_text, real_text
  use deck_lexer, only: deck_t
  use deck_keywords, only: keyword_t
  use deck_fields, only: card_t, require_card, next_definition, get_integer, get_real, &
                         card_problem, field_is_blank, warn_if_set
  use deck_input, only: deck_input_t
  implicit none
  private

  public :: read_elastic_materials, read_plastic_kinematic_materials

  integer, parameter :: standard_widths(8) = 10

contains

  !> *MAT_ELASTIC: MID RO E PR DA DB K, one card per material (DA, DB: beams; K: fluids).
  subroutine read_elastic_materials(deck, block, keyword, input, log)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(card_t) :: card
    integer :: line, n
    character(len=:), allocatable :: title

    line = 0
    do while (next_definition(deck, block, keyword%title, line, standard_widths, card, title, &
                              log, "card 1 (MID RO E PR DA DB K)", "MID"))
      n = input%material_count + 1
      input%material_count = n
      input%material_lines(n) = line
      associate (material => input%model%materials(n))
        material%law = law_elastic
        material%title = title
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
      n = input%material_count + 1
      input%material_count = n
      input%material_lines(n) = line
      associate (material => input%model%materials(n))
        material%law = law_plastic_kinematic
        material%title = title
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
        if (.not. card%failed) call check_rate(deck, card, material, log)
      end associate
      call warn_if_set(deck, card, 3, "FS", "elements do not erode", warnings)
    end do
  end subroutine read_plastic_kinematic_materials

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
    if (material%id <= 0) call card_problem(deck, log, card, "MID", "material id must be "// &
                                            "> 0, found "//integer_text(material%id))
    if (material%density <= 0.0_wp) call card_problem(deck, log, card, "RO", "density must "// &
      "be > 0, found "//shown(deck, card, 2, material%density))
    if (material%youngs_modulus < 0.0_wp) then
      call card_problem(deck, log, card, "E", "Young's modulus must be > 0, found "// &
        shown(deck, card, 3, material%youngs_modulus)//" (E < 0, a curve of E, is not available)")
    else if (material%youngs_modulus == 0.0_wp) then
      call card_problem(deck, log, card, "E", "Young's modulus must be > 0, found "// &
                        shown(deck, card, 3, material%youngs_modulus))
    end if
    if (material%poissons_ratio <= -1.0_wp .or. material%poissons_ratio >= 0.5_wp) &
      call card_problem(deck, log, card, "PR", "Poisson's ratio must lie in (-1, 0.5), "// &
                        "found "//shown(deck, card, 4, material%poissons_ratio))
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

  subroutine check_rate(deck, card, material, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(in) :: card
    type(material_t), intent(in) :: material
    type(problem_log_t), intent(inout) :: log
    if (material%rate_c < 0.0_wp) then
      call card_problem(deck, log, card, "SRC", "Cowper-Symonds C must be >= 0 (0: no rate "// &
                        "effect), found "//real_text(material%rate_c))
    else if (material%rate_p < 0.0_wp) then
      call card_problem(deck, log, card, "SRP", "Cowper-Symonds P must be >= 0 (0: no rate "// &
                        "effect), found "//real_text(material%rate_p))
    else if ((material%rate_c > 0.0_wp) .neqv. (material%rate_p > 0.0_wp)) then
      call card_problem(deck, log, card, trim(merge("SRP", "SRC", material%rate_c > 0.0_wp)), &
        "Cowper-Symonds rate effects need both SRC and SRP > 0 (or both 0 for none), found "// &
        "SRC = "//real_text(material%rate_c)//", SRP = "//real_text(material%rate_p))
    end if
    if (material%rate_formulation /= 0.0_wp .and. material%rate_formulation /= 1.0_wp) &
      call card_problem(deck, log, card, "VP", "must be 0 (scale the yield stress) or 1 "// &
                        "(viscoplastic), found "//real_text(material%rate_formulation))
  end subroutine check_rate

  !> A value for a message, saying when it came from a blank field.
  function shown(deck, card, k, value) result(text)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(in) :: card
    integer, intent(in) :: k
    real(wp), intent(in) :: value
    character(len=:), allocatable :: text
    text = real_text(value)
    if (field_is_blank(deck, card, k)) text = text//" (the field is blank)"
  end function shown
end module deck_materials
