!> *MAT_ADD_EROSION: failure criteria added to a material (erosion_criteria applies them).
!>
!> Card 1 MID EXCL MXPRES MNEPS EFFEPS VOLEPS NUMFIP NCS, card 2 MNPRES SIGP1 SIGVM MXEPS EPSSH
!> SIGTH IMPULSE FAILTM. As in LS-DYNA a blank or zero criterion is off, and a field equal to
!> EXCL (when EXCL is not 0) is off too. Read and applied: EFFEPS, MXEPS, MNEPS, NUMFIP, NCS = 0
!> or 1. The other criteria (pressure, stresses, volumetric and shear strain, impulse, failure
!> time) and NCS > 1 are refused: an element the user expects to erode would not. The damage
!> cards (card 3 on, IDAM) are refused. One material per keyword.
module deck_add_erosion
  use kinds, only: wp
  use error_handling, only: error_list_t
  use text_format, only: real_text, integer_text
  use deck_problems, only: problem_log_t
  use deck_lexer, only: deck_t
  use deck_keywords, only: keyword_t
  use deck_fields, only: card_t, require_card, next_line, get_integer, get_real, card_problem, line_problem, &
                         located_problem, located_warning
  use model, only: formulation_efg
  use erosion_criteria, only: erodes_on_strain
  use deck_input, only: deck_input_t, add_erosion_input_t
  use deck_id_index, only: id_index_t, find_id
  implicit none
  private

  public :: read_add_erosions, apply_add_erosions, warn_parts_that_do_not_erode

  integer, parameter :: standard_widths(8) = 10

contains

  !> Read one *MAT_ADD_EROSION block into input%add_erosions.
  subroutine read_add_erosions(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    type(add_erosion_input_t) :: erosion
    real(wp) :: exclusion, value, required_criteria
    integer :: line, extra
    line = 0
    if (keyword%title) then
      ! the title line
      if (.not. next_line(deck, block, line, .false.)) return
    end if
    if (.not. require_card(deck, block, line, standard_widths, card, log, &
                           "card 1 (MID EXCL MXPRES MNEPS EFFEPS VOLEPS NUMFIP NCS)", "MID")) return
    erosion%line = line
    call get_integer(deck, card, 1, "MID", erosion%material_id, log)
    call get_real(deck, card, 2, "EXCL", exclusion, log)
    call refuse(card, 3, "MXPRES", "erosion on the maximum pressure is not available")
    call get_criterion(card, 4, "MNEPS", erosion%min_principal)
    call get_criterion(card, 5, "EFFEPS", erosion%plastic_strain)
    call refuse(card, 6, "VOLEPS", "erosion on the volumetric strain is not available")
    call get_criterion(card, 7, "NUMFIP", erosion%failed_points)
    call get_criterion(card, 8, "NCS", required_criteria)
    if (.not. card%failed) then
      if (erosion%material_id <= 0) call card_problem(deck, log, card, "MID", &
        "must be the id (> 0) of a material, found "//integer_text(erosion%material_id))
      if (erosion%min_principal > 0.0_wp) call card_problem(deck, log, card, "MNEPS", &
        "the smallest principal strain at failure must be < 0 (0: off), found "//real_text(erosion%min_principal))
      if (erosion%plastic_strain < 0.0_wp) call card_problem(deck, log, card, "EFFEPS", &
        "the effective plastic strain at failure must be > 0 (0: off), found "//real_text(erosion%plastic_strain))
      if (erosion%failed_points < -100.0_wp) call card_problem(deck, log, card, "NUMFIP", &
        "must be a count of points (> 0) or a percentage of a shell's points (-100 to 0), found "// &
        real_text(erosion%failed_points))
      if (required_criteria > 1.0_wp) call card_problem(deck, log, card, "NCS", &
        "an element erodes when any one criterion is met; NCS > 1 is not available, found "// &
        real_text(required_criteria))
    end if
    if (require_card(deck, block, line, standard_widths, card, log, &
                     "card 2 (MNPRES SIGP1 SIGVM MXEPS EPSSH SIGTH IMPULSE FAILTM)", "MNPRES")) then
      call refuse(card, 1, "MNPRES", "erosion on the minimum pressure is not available")
      call refuse(card, 2, "SIGP1", "erosion on the principal stress is not available")
      call refuse(card, 3, "SIGVM", "erosion on the equivalent stress is not available")
      call get_criterion(card, 4, "MXEPS", erosion%max_principal)
      call refuse(card, 5, "EPSSH", "erosion on the shear strain is not available")
      call refuse(card, 6, "SIGTH", "the Tuler-Butcher criterion (SIGTH, IMPULSE) is not available")
      call refuse(card, 7, "IMPULSE", "the Tuler-Butcher criterion (SIGTH, IMPULSE) is not available")
      call refuse(card, 8, "FAILTM", "erosion at a failure time is not available")
      if (.not. card%failed .and. erosion%max_principal < 0.0_wp) call card_problem(deck, log, card, "MXEPS", &
        "the largest principal strain at failure must be > 0 (0: off), found "//real_text(erosion%max_principal))
    end if
    extra = line
    if (next_line(deck, block, extra, .true.)) call line_problem(deck, log, extra, block, "IDAM", &
      "damage models (card 3 on) are not available, and one *MAT_ADD_EROSION holds one material: "// &
      "repeat the keyword for the next")
    if (.not. allocated(input%add_erosions)) allocate (input%add_erosions(0))
    input%add_erosions = [input%add_erosions, erosion]

  contains

    !> A criterion: blank or 0 off, and a value equal to EXCL off.
    subroutine get_criterion(card, k, name, criterion)
      type(card_t), intent(inout) :: card
      integer, intent(in) :: k
      character(len=*), intent(in) :: name
      real(wp), intent(out) :: criterion
      call get_real(deck, card, k, name, criterion, log)
      if (exclusion /= 0.0_wp .and. criterion == exclusion) criterion = 0.0_wp
    end subroutine get_criterion

    !> A criterion that is not available: an error when it is on.
    subroutine refuse(card, k, name, reason)
      type(card_t), intent(inout) :: card
      integer, intent(in) :: k
      character(len=*), intent(in) :: name, reason
      call get_criterion(card, k, name, value)
      if (value /= 0.0_wp .and. .not. card%failed) call card_problem(deck, log, card, name, reason// &
        "; leave it blank or 0, found "//real_text(value))
    end subroutine refuse
  end subroutine read_add_erosions

  !> Give each *MAT_ADD_EROSION's criteria to its material (`materials`: the index of the
  !> material ids); an unknown MID or a second definition for one material is an error.
  subroutine apply_add_erosions(deck, input, materials, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(id_index_t), intent(in) :: materials
    type(problem_log_t), intent(inout) :: log
    integer :: k, m
    if (.not. allocated(input%add_erosions)) return
    do k = 1, size(input%add_erosions)
      associate (erosion => input%add_erosions(k))
        if (erosion%material_id <= 0) cycle
        m = find_id(materials, erosion%material_id)
        if (m <= 0) then
          call located_problem(deck, log, erosion%line, "MID", "no material "//integer_text(erosion%material_id)// &
                               " in the deck")
          cycle
        end if
        associate (material => input%model%materials(m))
          if (material%has_add_erosion) then
            call located_problem(deck, log, erosion%line, "MID", "material "//integer_text(erosion%material_id)// &
                                 " has a *MAT_ADD_EROSION already")
            cycle
          end if
          material%has_add_erosion = .true.
          material%erosion_plastic_strain = erosion%plastic_strain
          material%erosion_max_principal_strain = erosion%max_principal
          material%erosion_min_principal_strain = erosion%min_principal
          material%erosion_failed_points = erosion%failed_points
        end associate
      end associate
    end do
  end subroutine apply_add_erosions

  !> A warning at each part whose material has failure criteria (FS, FAIL, TDEL, *MAT_ADD_EROSION)
  !> that its elements do not apply: meshfree (EFG) parts, and every part of the linear static
  !> analysis.
  subroutine warn_parts_that_do_not_erode(deck, input, warnings)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(in) :: input
    type(error_list_t), intent(inout) :: warnings
    integer :: k
    do k = 1, input%part_count
      associate (part => input%model%parts(k))
        if (part%material <= 0) cycle
        associate (material => input%model%materials(part%material))
          if (.not. (erodes_on_strain(material) .or. material%failure_time_step > 0.0_wp)) cycle
          if (input%model%implicit_static) then
            call located_warning(deck, warnings, input%part_lines(k), "MID", "the failure criteria of material "// &
              integer_text(material%id)//" are ignored: the linear static analysis does not erode elements")
          else if (part%formulation == formulation_efg) then
            call located_warning(deck, warnings, input%part_lines(k), "MID", "the failure criteria of material "// &
              integer_text(material%id)//" are ignored for part "//integer_text(part%id)// &
              ": meshfree (EFG) parts do not erode")
          end if
        end associate
      end associate
    end do
  end subroutine warn_parts_that_do_not_erode
end module deck_add_erosion
