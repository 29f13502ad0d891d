!> One entry point per plane-stress material operation for a block of lanes (shell
!> through-thickness integration points of one material), selecting the law by
!> `material%law`. The shell element calls these per integration point in its corotational
!> local frame; transverse shear is elastic and stays with the element.
!>
!> Conventions shared by every law:
!> - strain_increment (block_size, 3): d eps_xx, d eps_yy, d gamma_xy (ENGINEERING shear,
!>   2 D_xy dt), in the local frame;
!> - stress (block_size, 3): sigma_xx, sigma_yy, sigma_xy in the same frame (sigma_zz = 0);
!> - history (block_size, plane_stress_history_count(material)), the law's own layout; tensor
!>   history lives in the same corotational frame as the stress. When the element turns its
!>   stress about the normal (the material spin), it calls rotate_plane_stress_history, which
!>   turns the rubbers' b and the viscoelastic branch (the back stress of law 3 is left as it is);
!> - thickness_strain_increment (block_size): d eps_zz making sigma_zz = 0.
!>
!> Laws: *MAT_ELASTIC (1), *MAT_PLASTIC_KINEMATIC (3: history eps_p, beta_xx, beta_yy, beta_xy),
!> *MAT_PIECEWISE_LINEAR_PLASTICITY (24: history eps_p), *MAT_VISCOELASTIC (6: h_xx, h_yy, h_zz,
!> h_xy), *MAT_BLATZ-KO_RUBBER (7) and *MAT_MOONEY-RIVLIN_RUBBER (27: b_xx - 1, b_yy - 1, b_xy,
!> b_zz - 1; material_rubber) and *MAT_NULL (9: no stress, no
!> thickness change, so that a null shell keeps the thickness its contact uses). Any other law
!> has no plane-stress kernel: plane_stress_history_count returns -1, and the caller (the
!> deck check of shell parts) must reject it; update_plane_stress_block stops on it.
module plane_stress_dispatch
  use kinds, only: wp, block_size
  use curves, only: curve_t
  use model, only: material_t, piecewise_hardening_curve, piecewise_rate_curve
  use material_laws, only: law_table, find_law, no_plane_stress_kernel, law_elastic, law_plastic_kinematic, &
                           law_piecewise_linear, law_null, law_viscoelastic, law_blatz_ko, law_mooney_rivlin
  use material_dispatch, only: plastic_hardening_modulus, elastic_moduli, rubber_constants
  use material_rubber, only: rubber_plane_stress_update, rubber_mooney_rivlin, rubber_blatz_ko
  use material_viscoelastic, only: viscoelastic_plane_stress_update
  use plane_stress_plasticity, only: plane_stress_elastic_update, plane_stress_plasticity_update
  implicit none
  private

  public :: plane_stress_history_count, initialize_plane_stress_history, update_plane_stress_block
  public :: plane_stress_plastic_strain, rotate_plane_stress_history

  !> History count returned for a law without a plane-stress kernel.
  integer, parameter, public :: plane_stress_unsupported = no_plane_stress_kernel
  !> Slot of the effective plastic strain (laws 3 and 24).
  integer, parameter, public :: plane_stress_plastic_strain_slot = 1
  !> First of the three back-stress slots of law 3 (beta_xx, beta_yy, beta_xy; beta_zz = 0 and
  !> the deviatoric 3D back stress is dev(beta)).
  integer, parameter, public :: plane_stress_back_stress_first_slot = 2

contains

  !> History variables per integration point for shells of this material (law_table: 0 for
  !> laws 1, 9, 4 for law 3, 1 for law 24), or plane_stress_unsupported (-1) for a law without
  !> a plane-stress kernel (the shell part must then be rejected).
  pure integer function plane_stress_history_count(material)
    type(material_t), intent(in) :: material
    integer :: law
    law = find_law(material%law)
    plane_stress_history_count = plane_stress_unsupported
    if (law > 0) plane_stress_history_count = law_table(law)%shell_history_count
  end function plane_stress_history_count

  !> Virgin history for lanes 1..nel: no plastic strain, no back stress.
  subroutine initialize_plane_stress_history(material, nel, history)
    type(material_t), intent(in) :: material
    integer, intent(in) :: nel
    real(wp), intent(inout), contiguous :: history(:, :)
    if (plane_stress_history_count(material) > 0 .and. size(history, 2) > 0) history(1:nel, :) = 0.0_wp
  end subroutine initialize_plane_stress_history

  !> One step of plane-stress update of lanes 1..nel in the element's corotational local frame
  !> over `dt` (used for rates; dt = 0: no rate effect). See the module notes for the arrays.
  !> Law 24 reads material%curves(piecewise_hardening_curve) and (piecewise_rate_curve), which
  !> the deck's cross-check allocates (a curve without points: bilinear SIGY/ETAN, no LCSR).
  subroutine update_plane_stress_block(material, nel, dt, strain_increment, stress, history, &
                                       thickness_strain_increment)
    type(material_t), intent(in) :: material
    integer, intent(in) :: nel
    real(wp), intent(in) :: dt
    real(wp), intent(in) :: strain_increment(block_size, 3)
    real(wp), intent(inout) :: stress(block_size, 3)
    real(wp), intent(inout), contiguous :: history(:, :)
    real(wp), intent(out) :: thickness_strain_increment(block_size)
    type(curve_t) :: no_curve
    real(wp) :: hardening_modulus, bulk_modulus, shear_modulus

    ! A select case on the integer law code, as in update_material_block (material_dispatch).
    select case (material%law)
    case (law_elastic)
      call plane_stress_elastic_update(nel, material%youngs_modulus, material%poissons_ratio, strain_increment, &
                                       stress, thickness_strain_increment)
    case (law_plastic_kinematic)
      hardening_modulus = plastic_hardening_modulus(material)
      call plane_stress_plasticity_update(nel, material%youngs_modulus, material%poissons_ratio, no_curve, &
        material%yield_stress, material%hardening_beta*hardening_modulus, &
        (1.0_wp - material%hardening_beta)*hardening_modulus, no_curve, material%rate_c, material%rate_p, &
        material%rate_formulation > 0.5_wp, dt, strain_increment, stress, &
        history(:, plane_stress_plastic_strain_slot), thickness_strain_increment, &
        history(:, plane_stress_back_stress_first_slot:plane_stress_back_stress_first_slot + 2))
    case (law_piecewise_linear)
      call plane_stress_plasticity_update(nel, material%youngs_modulus, material%poissons_ratio, &
        material%curves(piecewise_hardening_curve), material%yield_stress, plastic_hardening_modulus(material), &
        0.0_wp, material%curves(piecewise_rate_curve), material%rate_c, material%rate_p, &
        material%rate_formulation > 0.5_wp, dt, strain_increment, stress, &
        history(:, plane_stress_plastic_strain_slot), thickness_strain_increment)
    case (law_mooney_rivlin)
      call rubber_plane_stress_update(nel, rubber_mooney_rivlin, rubber_constants(material), strain_increment, &
                                      stress, history, thickness_strain_increment)
    case (law_blatz_ko)
      call rubber_plane_stress_update(nel, rubber_blatz_ko, rubber_constants(material), strain_increment, &
                                      stress, history, thickness_strain_increment)
    case (law_viscoelastic)
      call elastic_moduli(material, bulk_modulus, shear_modulus)
      call viscoelastic_plane_stress_update(nel, bulk_modulus, shear_modulus, material%long_term_shear_modulus, &
                                            material%decay_constant, dt, strain_increment, stress, history, &
                                            thickness_strain_increment)
    case (law_null)
      ! A null shell carries no membrane or bending stress and keeps its thickness.
      stress(1:nel, :) = 0.0_wp
      thickness_strain_increment(1:nel) = 0.0_wp
    case default
      error stop "update_plane_stress_block: the material's law has no plane-stress kernel "// &
        "(plane_stress_history_count returned -1: the deck check must reject the shell part)"
    end select
  end subroutine update_plane_stress_block

  !> Turn the in-plane tensor history of one point with the stress, when the shell rotates its
  !> stress by the material spin about the normal (angle with cosine c and sine s, the same
  !> transformation as the stress): the rubbers' b_xx - 1, b_yy - 1, b_xy (slots 1-3; b_zz
  !> stays), the viscoelastic branch h_xx, h_yy, h_xy (slots 1, 2, 4; h_zz stays). The other
  !> laws keep their history as it is. `history`: the point's history row of one lane.
  pure subroutine rotate_plane_stress_history(law, c, s, history)
    integer, intent(in) :: law
    real(wp), intent(in) :: c, s
    real(wp), intent(inout) :: history(:)
    select case (law)
    case (law_mooney_rivlin, law_blatz_ko)
      call rotate_in_plane(c, s, history(1), history(2), history(3))
    case (law_viscoelastic)
      call rotate_in_plane(c, s, history(1), history(2), history(4))
    case default
      continue
    end select
  end subroutine rotate_plane_stress_history

  !> (xx, yy, xy) of a symmetric 2x2 tensor turned by the angle with cosine c and sine s.
  pure subroutine rotate_in_plane(c, s, xx, yy, xy)
    real(wp), intent(in) :: c, s
    real(wp), intent(inout) :: xx, yy, xy
    real(wp) :: old_xx, old_yy, old_xy
    old_xx = xx
    old_yy = yy
    old_xy = xy
    xx = c*c*old_xx - 2.0_wp*c*s*old_xy + s*s*old_yy
    yy = s*s*old_xx + 2.0_wp*c*s*old_xy + c*c*old_yy
    xy = c*s*(old_xx - old_yy) + (c*c - s*s)*old_xy
  end subroutine rotate_in_plane

  !> Effective plastic strain of lanes 1..nel (0 for the elastic and null laws).
  subroutine plane_stress_plastic_strain(material, nel, history, plastic_strain)
    type(material_t), intent(in) :: material
    integer, intent(in) :: nel
    real(wp), intent(in), contiguous :: history(:, :)
    real(wp), intent(out) :: plastic_strain(block_size)
    select case (material%law)
    case (law_plastic_kinematic, law_piecewise_linear)
      plastic_strain(1:nel) = history(1:nel, plane_stress_plastic_strain_slot)
    case default
      plastic_strain(1:nel) = 0.0_wp
    end select
  end subroutine plane_stress_plastic_strain
end module plane_stress_dispatch
