!> The EFG cards of a meshfree solid section (ELFORM 41): the EFG card DX DY DZ ISPLINE IDILA
!> IEBT IDIM TOLDEF and the optional card 3 IPS STIME IKEN SF CMID IBR DS ECUT.
!>
!> Blank fields take crashfree's defaults, which are the method of the paper (Wang et al. 2009)
!> and differ from LS-DYNA's where docs/keywords.md says so: IDIM blank is 1 (local boundary
!> integration; LS-DYNA: 2) and TOLDEF blank is 0 (Lagrangian kernel; LS-DYNA: 0.01). A value
!> that selects something crashfree does not have is an error naming its field, never a
!> silent substitution. IDIM 4 is crashfree's own value (no LS-DYNA meaning): conventional EFG,
!> 4x4x4 Gauss points per cell with direct MLS gradients, kept for the verification of Table 1
!> of the paper.
!>
!> The EFG card of a meshfree shell section (*SECTION_SHELL ELFORM 41): DX DY ISPLINE IDILA
!> IEBT IDIM. Blank or 0 DX, DY take LS-DYNA's default for the shell card, 1.1 (the keyword
!> schema's value; the solids' 1.01 is the solid card's). IEBT blank is 3 and IDIM blank is 1,
!> the coupled local-boundary method crashfree builds, where LS-DYNA's schema says 1 and 1
!> (its help text: -1 and 2); every other value is refused.
module deck_efg_cards
  use kinds, only: wp
  use error_handling, only: error_list_t
  use model, only: section_t, kernel_cubic_box, kernel_quadratic_box, kernel_cubic_sphere, &
                   boundary_full_transformation, boundary_coupled, integration_local_boundary, &
                   integration_gauss, integration_gauss_conventional
  use deck_problems, only: problem_log_t
  use text_format, only: integer_text, real_text
  use deck_lexer, only: deck_t
  use deck_fields, only: card_t, get_integer, get_real, card_problem, warn_if_set
  implicit none
  private

  public :: read_efg_card, read_efg_options_card, read_efg_shell_card

  !> ELFORM of the meshfree (EFG) solid, and of LS-DYNA's adaptive 4-node EFG solid, which
  !> crashfree does not have. Both are followed by the EFG card.
  integer, parameter, public :: elform_efg = 41, elform_adaptive_efg = 42

  !> Normalized support for a blank or zero DX, DY, DZ (LS-DYNA's default too).
  real(wp), parameter :: default_support_scale = 1.01_wp
  !> Normalized support for a blank or zero DX, DY of the shell's EFG card (LS-DYNA's default
  !> for *SECTION_SHELL ELFORM 41/42).
  real(wp), parameter :: default_shell_support_scale = 1.1_wp

  character(len=2), parameter :: support_names(3) = ["DX", "DY", "DZ"]

  !> The widest normalized support read: the set-up's pair lists grow with the square (shells)
  !> or cube (solids) of the support, and a support of many element neighbour distances makes
  !> every particle cover most of the part (a 40 x 40 shell plate at DX 1e29 needed 870 MB).
  !> LS-DYNA's manuals suggest values between 1.0 and 2.0.
  real(wp), parameter :: widest_support_scale = 4.0_wp

contains

  !> The EFG card into `section`: DX DY DZ ISPLINE IDILA IEBT IDIM TOLDEF.
  subroutine read_efg_card(deck, card, section, log, warnings)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    type(section_t), intent(inout) :: section
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    integer :: k, kernel, dilation_basis, boundary_treatment, domain_integration
    real(wp) :: support_scale(3), kernel_tolerance

    do k = 1, 3
      call get_real(deck, card, k, support_names(k), support_scale(k), log)
    end do
    call get_integer(deck, card, 4, "ISPLINE", kernel, log)
    call get_integer(deck, card, 5, "IDILA", dilation_basis, log)
    call get_integer(deck, card, 6, "IEBT", boundary_treatment, log, default=boundary_coupled)
    call get_integer(deck, card, 7, "IDIM", domain_integration, log, &
                     default=integration_local_boundary)
    call get_real(deck, card, 8, "TOLDEF", kernel_tolerance, log)
    if (card%failed) return

    do k = 1, 3
      if (support_scale(k) == 0.0_wp) then
        support_scale(k) = default_support_scale
      else if (support_scale(k) <= 1.0_wp) then
        call card_problem(deck, log, card, support_names(k), support_names(k)//" must be "// &
          "greater than 1: at 1.0 a vertex weight vanishes on the cell's far corner; found "// &
          real_text(support_scale(k))//" (blank or 0 means 1.01)")
      else if (support_scale(k) > widest_support_scale) then
        call card_problem(deck, log, card, support_names(k), too_wide_text(support_names(k), support_scale(k)))
      end if
    end do
    section%support_scale = support_scale

    select case (kernel)
    case (kernel_cubic_box)
      section%kernel = kernel
    case (kernel_cubic_sphere)
      section%kernel = kernel
      ! a sphere has one radius, scaled by DX
      do k = 2, 3
        if (support_scale(k) /= support_scale(1)) call warn_if_set(deck, card, k, &
          support_names(k), "a spherical support (ISPLINE 2) has one radius, scaled by DX", &
          warnings)
      end do
    case (1)
      call card_problem(deck, log, card, "ISPLINE", "the quadratic spline kernel (ISPLINE 1) "// &
        "is not available; use 0 (cubic spline, box support) or 2 (cubic spline, spherical "// &
        "support)")
    case default
      call card_problem(deck, log, card, "ISPLINE", "must be 0 (cubic spline, box support) "// &
        "or 2 (cubic spline, spherical support), found "//integer_text(kernel))
    end select

    select case (dilation_basis)
    case (0)
      section%dilation_basis = dilation_basis
    case (1)
      call card_problem(deck, log, card, "IDILA", "IDILA 1 (support size from the "// &
        "surrounding nodes) is not available: crashfree sizes each particle's support from "// &
        "the nodes that share an element with it (IDILA 0); leave IDILA blank or 0")
    case default
      call card_problem(deck, log, card, "IDILA", "must be 0 (support size from the "// &
        "background elements), found "//integer_text(dilation_basis))
    end select

    select case (boundary_treatment)
    case (boundary_coupled, boundary_full_transformation)
      section%boundary_treatment = boundary_treatment
    case default
      call card_problem(deck, log, card, "IEBT", "essential boundary treatment "// &
        integer_text(boundary_treatment)//" is not available; crashfree has IEBT 3 (coupled "// &
        "FE/EFG, the default for a blank field) and 1 (full transformation)"// &
        zero_note(boundary_treatment))
    end select

    select case (domain_integration)
    case (integration_local_boundary, integration_gauss, integration_gauss_conventional)
      section%domain_integration = domain_integration
    case default
      call card_problem(deck, log, card, "IDIM", "domain integration "// &
        integer_text(domain_integration)//" is not available; crashfree has IDIM 1 (local "// &
        "boundary integration, the default for a blank field), 2 (2x2x2 Gauss points per "// &
        "cell, for comparison) and 4 (crashfree's extension: conventional EFG, 4x4x4 Gauss "// &
        "points per cell with direct MLS gradients)"//zero_note(domain_integration))
    end select

    if (kernel_tolerance /= 0.0_wp) then
      call card_problem(deck, log, card, "TOLDEF", "semi-Lagrangian and Eulerian kernels "// &
        "(TOLDEF /= 0) are not available; use 0 (found "//real_text(kernel_tolerance)//")")
    else
      section%kernel_tolerance = 0.0_wp
    end if
  end subroutine read_efg_card

  !> The EFG card of a meshfree shell section (ELFORM 41) into `section`: DX DY ISPLINE IDILA
  !> IEBT IDIM.
  subroutine read_efg_shell_card(deck, card, section, log, warnings)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    type(section_t), intent(inout) :: section
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    integer :: k, kernel, dilation_basis, boundary_treatment, domain_integration
    real(wp) :: support_scale(2)

    do k = 1, 2
      call get_real(deck, card, k, support_names(k), support_scale(k), log)
    end do
    call get_integer(deck, card, 3, "ISPLINE", kernel, log)
    call get_integer(deck, card, 4, "IDILA", dilation_basis, log)
    call get_integer(deck, card, 5, "IEBT", boundary_treatment, log, default=boundary_coupled)
    call get_integer(deck, card, 6, "IDIM", domain_integration, log, &
                     default=integration_local_boundary)
    if (card%failed) return

    do k = 1, 2
      if (support_scale(k) == 0.0_wp) then
        support_scale(k) = default_shell_support_scale
      else if (support_scale(k) <= 1.0_wp) then
        call card_problem(deck, log, card, support_names(k), support_names(k)//" must be "// &
          "greater than 1: at 1.0 a vertex weight vanishes on the cell's far corner; found "// &
          real_text(support_scale(k))//" (blank or 0 means 1.1)")
      else if (support_scale(k) > widest_support_scale) then
        call card_problem(deck, log, card, support_names(k), too_wide_text(support_names(k), support_scale(k)))
      end if
    end do
    section%support_scale(1:2) = support_scale
    section%support_scale(3) = support_scale(1)

    select case (kernel)
    case (kernel_cubic_box, kernel_quadratic_box)
      section%kernel = kernel
    case (kernel_cubic_sphere)
      section%kernel = kernel
      ! a circle has one radius, scaled by DX
      if (support_scale(2) /= support_scale(1)) call warn_if_set(deck, card, 2, "DY", &
        "a circular support (ISPLINE 2) has one radius, scaled by DX", warnings)
    case default
      call card_problem(deck, log, card, "ISPLINE", "must be 0 (cubic spline, box support), "// &
        "1 (quadratic spline, box support) or 2 (cubic spline, circular support), found "// &
        integer_text(kernel))
    end select

    select case (dilation_basis)
    case (0)
      section%dilation_basis = dilation_basis
    case (1)
      call card_problem(deck, log, card, "IDILA", "IDILA 1 (support size from the "// &
        "surrounding nodes) is not available: crashfree sizes each particle's support from "// &
        "the nodes that share a shell with it (IDILA 0); leave IDILA blank or 0")
    case default
      call card_problem(deck, log, card, "IDILA", "must be 0 (support size from the "// &
        "background elements), found "//integer_text(dilation_basis))
    end select

    if (boundary_treatment == boundary_coupled) then
      section%boundary_treatment = boundary_treatment
    else
      call card_problem(deck, log, card, "IEBT", "essential boundary treatment "// &
        integer_text(boundary_treatment)//" is not available for meshfree shells; crashfree "// &
        "has IEBT 3 (coupled FE/EFG: the nodes on the part's boundary keep FE functions), the "// &
        "default for a blank field"//zero_note(boundary_treatment))
    end if

    if (domain_integration == integration_local_boundary) then
      section%domain_integration = domain_integration
    else
      call card_problem(deck, log, card, "IDIM", "domain integration "// &
        integer_text(domain_integration)//" is not available for meshfree shells; crashfree "// &
        "has IDIM 1 (local boundary integration on sub-cells, with one transverse shear point "// &
        "per cell), the default for a blank field"//zero_note(domain_integration))
    end if
    section%kernel_tolerance = 0.0_wp
  end subroutine read_efg_shell_card

  !> Card 3 of *SECTION_SOLID_EFG: IPS STIME IKEN SF CMID IBR DS ECUT. Each field belongs to a
  !> feature crashfree does not have (pressure smoothing, stabilized EFG, the maximum-entropy
  !> approximation, EFG fracture), so only the values that leave the feature off are accepted:
  !> blank, 0, or LS-DYNA's default for the field. Nothing is stored.
  subroutine read_efg_options_card(deck, card, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    type(problem_log_t), intent(inout) :: log
    integer :: pressure_smoothing, approximation, cohesive_material, branching
    real(wp) :: switch_time, failure_strain, jump_support, cut_distance

    call get_integer(deck, card, 1, "IPS", pressure_smoothing, log)
    call get_real(deck, card, 2, "STIME", switch_time, log)
    call get_integer(deck, card, 3, "IKEN", approximation, log)
    call get_real(deck, card, 4, "SF", failure_strain, log)
    call get_integer(deck, card, 5, "CMID", cohesive_material, log)
    call get_integer(deck, card, 6, "IBR", branching, log)
    call get_real(deck, card, 7, "DS", jump_support, log)
    call get_real(deck, card, 8, "ECUT", cut_distance, log)
    if (card%failed) return

    if (pressure_smoothing /= 0) call card_problem(deck, log, card, "IPS", "pressure "// &
      "smoothing is not available; leave IPS blank or 0, found "//integer_text(pressure_smoothing))
    if (switch_time /= 0.0_wp .and. .not. is_value(switch_time, 1.0e20_wp)) &
      call card_problem(deck, log, card, "STIME", "the switch from stabilized to standard "// &
        "EFG belongs to stabilized EFG integration (IDIM -1), which is not available; leave "// &
        "STIME blank (1e20), found "//real_text(switch_time))
    if (approximation /= 0) call card_problem(deck, log, card, "IKEN", "the maximum-entropy "// &
      "approximation is not available: crashfree uses moving least squares (IKEN 0), found "// &
      integer_text(approximation))
    if (failure_strain /= 0.0_wp) call card_problem(deck, log, card, "SF", "EFG fracture "// &
      "(crack initiation at the failure strain SF) is not available; leave SF blank or 0, "// &
      "found "//real_text(failure_strain))
    if (cohesive_material /= 0) call card_problem(deck, log, card, "CMID", "EFG fracture "// &
      "(the cohesive material CMID) is not available; leave CMID blank, found "// &
      integer_text(cohesive_material))
    if (branching /= 0 .and. branching /= 1) call card_problem(deck, log, card, "IBR", &
      "crack branching belongs to EFG fracture, which is not available; leave IBR blank or "// &
      "1, found "//integer_text(branching))
    if (jump_support /= 0.0_wp .and. .not. is_value(jump_support, 0.01_wp)) &
      call card_problem(deck, log, card, "DS", "the support of the displacement jump belongs "// &
        "to EFG fracture, which is not available; leave DS blank (0.01), found "// &
        real_text(jump_support))
    if (cut_distance /= 0.0_wp .and. .not. is_value(cut_distance, 0.01_wp)) &
      call card_problem(deck, log, card, "ECUT", "the smallest crack-cut distance belongs to "// &
        "EFG fracture, which is not available; leave ECUT blank (0.01), found "// &
        real_text(cut_distance))
  end subroutine read_efg_options_card

  !> For IEBT and IDIM, where 0 is none of LS-DYNA's values and a blank field is what selects
  !> the default.
  pure function zero_note(value) result(note)
    integer, intent(in) :: value
    character(len=:), allocatable :: note
    note = ""
    if (value == 0) note = "; 0 is not a default here: leave the field blank"
  end function zero_note

  !> True when `value` is `expected` as written in a deck (`1.0E+20`, `1e20`, `0.0100`).
  pure logical function is_value(value, expected)
    real(wp), intent(in) :: value, expected
    is_value = abs(value - expected) <= 1.0e-9_wp*abs(expected)
  end function is_value
  !> The message for a normalized support above widest_support_scale.
  function too_wide_text(name, value) result(text)
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: value
    character(len=:), allocatable :: text
    text = name//" must be at most "//trim(real_text(widest_support_scale))//" (the support in element "// &
      "neighbour distances; 1.0 to 2.0 is usual, and wider supports cover most of the part); found "//real_text(value)
  end function too_wide_text
end module deck_efg_cards
