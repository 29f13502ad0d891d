!> Plane-stress kernels for shells (sigma_zz = 0 at each through-thickness integration point):
!> isotropic elasticity and von Mises plasticity with mixed isotropic / kinematic hardening,
!> in the element's corotational local frame.
!>
!> Plasticity is a true plane-stress return (Simo & Taylor 1986, "A return mapping algorithm
!> for plane stress elastoplasticity", IJNME 22; Simo & Hughes, Computational Inelasticity,
!> sec. 3.4): the elastic predictor and the associative flow rule are taken within the
!> plane-stress subspace, so sigma_zz stays exactly zero and the thickness strain follows.
!> With xi = sigma - beta (the relative stress; xx, yy, xy) and the modes
!>
!>   a = (xi_xx + xi_yy) / sqrt 2,   b = (xi_xx - xi_yy) / sqrt 2,   c = xi_xy,
!>   sbar^2 = xi_xx^2 + xi_yy^2 - xi_xx xi_yy + 3 xi_xy^2 = a^2/2 + 3 b^2/2 + 3 c^2,
!>
!> the plane-stress elasticity and the flow d eps^p = dgamma dev(xi) (3D deviator of the
!> plane tensor) are diagonal in a, b, c, and the return is closed-form in dgamma:
!>
!>   a = a_trial / (1 + (E / (3 (1 - nu)) + 2/3 H_k) dgamma)
!>   b = b_trial / (1 + (2 G + 2/3 H_k) dgamma),   c likewise
!>   d eps_p = 2/3 dgamma sbar,   beta += 2/3 H_k dgamma xi
!>
!> The scalar dgamma solves sbar(dgamma) = k Y(eps_p + d eps_p) (material_piecewise_linear's
!> safeguarded Newton iteration). H_k = (1 - BETA) E_p is the Prager modulus of
!> *MAT_PLASTIC_KINEMATIC. The 3D back stress alpha is deviatoric; `beta` stores it shifted by
!> alpha_zz I so that beta_zz = 0 (then dev(sigma) - alpha = dev(sigma - beta) and the yield
!> function needs the plane components only); alpha = dev(beta). Its rate 2/3 H_k d eps^p
!> becomes 2/3 H_k dgamma xi for beta.
!>
!> Strain increments are d eps_xx, d eps_yy and the ENGINEERING shear d gamma_xy. The thickness
!> increment making sigma_zz = 0 is the elastic -nu/E (d sigma_xx + d sigma_yy) plus the plastic
!> -(d eps^p_xx + d eps^p_yy) (plastic incompressibility). For the rate factor (VP = 0) the
!> effective strain rate sqrt(2/3 D:D) is taken with D_zz = -(D_xx + D_yy): the thickness rate
!> is an output of this update, and incompressibility is what it tends to once plastic.
module plane_stress_plasticity
  use kinds, only: wp, block_size
  use curves, only: curve_t
  use material_piecewise_linear, only: solve_plastic_multiplier, static_yield_stress, rate_scale_factor
  implicit none
  private

  public :: plane_stress_elastic_update, plane_stress_plasticity_update, in_plane_strain_rate

contains

  !> sigma <- sigma + C de (plane-stress elasticity) for lanes 1..nel; the thickness increment
  !> is -nu/(1 - nu) (de_xx + de_yy).
  subroutine plane_stress_elastic_update(nel, youngs_modulus, poissons_ratio, strain_increment, stress, &
                                         thickness_strain_increment)
    integer, intent(in) :: nel
    real(wp), intent(in) :: youngs_modulus, poissons_ratio
    real(wp), intent(in) :: strain_increment(block_size, 3)
    real(wp), intent(inout) :: stress(block_size, 3)
    real(wp), intent(out) :: thickness_strain_increment(block_size)
    real(wp) :: stiffness, shear_modulus
    integer :: i
    stiffness = youngs_modulus/(1.0_wp - poissons_ratio**2)
    shear_modulus = youngs_modulus/(2.0_wp*(1.0_wp + poissons_ratio))
    do i = 1, nel
      stress(i, 1) = stress(i, 1) + stiffness*(strain_increment(i, 1) + poissons_ratio*strain_increment(i, 2))
      stress(i, 2) = stress(i, 2) + stiffness*(strain_increment(i, 2) + poissons_ratio*strain_increment(i, 1))
      stress(i, 3) = stress(i, 3) + shear_modulus*strain_increment(i, 3)
      thickness_strain_increment(i) = -poissons_ratio/(1.0_wp - poissons_ratio) &
                                      *(strain_increment(i, 1) + strain_increment(i, 2))
    end do
  end subroutine plane_stress_elastic_update

  !> Effective strain rate sqrt(2/3 D:D) of lane `lane` of a block of plane increments
  !> (d eps_xx, d eps_yy, engineering d gamma_xy) over `time_step` > 0, with D_zz = -(D_xx + D_yy).
  pure function in_plane_strain_rate(strain_increment, lane, time_step) result(rate)
    real(wp), intent(in) :: strain_increment(block_size, 3), time_step
    integer, intent(in) :: lane
    real(wp) :: rate
    rate = sqrt(2.0_wp/3.0_wp*(strain_increment(lane, 1)**2 + strain_increment(lane, 2)**2 &
                               + (strain_increment(lane, 1) + strain_increment(lane, 2))**2 &
                               + 0.5_wp*strain_increment(lane, 3)**2))/time_step
  end function in_plane_strain_rate

  !> Elastic predictor and plane-stress return of lanes 1..nel.
  !> Hardening: Y(eps_p) from `hardening_curve` where it has points, else `initial_yield` +
  !> `isotropic_modulus` eps_p; kinematic (Prager) modulus `kinematic_modulus`, used only with
  !> `back_stress` (beta_xx, beta_yy, beta_xy; see the module notes). Rate factor k: LCSR
  !> (`rate_curve` with points) or Cowper-Symonds (`rate_c`, `rate_p` > 0), on the effective
  !> strain rate of the step (VP = 0) or on the plastic strain rate (`viscoplastic`, VP = 1);
  !> `time_step` = 0: no rate effect.
  subroutine plane_stress_plasticity_update(nel, youngs_modulus, poissons_ratio, hardening_curve, initial_yield, &
                                            isotropic_modulus, kinematic_modulus, rate_curve, rate_c, rate_p, &
                                            viscoplastic, time_step, strain_increment, stress, plastic_strain, &
                                            thickness_strain_increment, back_stress)
    integer, intent(in) :: nel
    real(wp), intent(in) :: youngs_modulus, poissons_ratio
    type(curve_t), intent(in) :: hardening_curve, rate_curve
    real(wp), intent(in) :: initial_yield, isotropic_modulus, kinematic_modulus, rate_c, rate_p
    logical, intent(in) :: viscoplastic
    real(wp), intent(in) :: time_step
    real(wp), intent(in) :: strain_increment(block_size, 3)
    real(wp), intent(inout) :: stress(block_size, 3)
    real(wp), intent(inout) :: plastic_strain(block_size)
    real(wp), intent(out) :: thickness_strain_increment(block_size)
    real(wp), intent(inout), optional :: back_stress(block_size, 3)

    real(wp), parameter :: root_half = sqrt(0.5_wp)
    real(wp) :: old_stress(block_size, 3), relative(3), mode_squares(3), mode_stiffness(3)
    real(wp) :: shear_modulus, kinematic, rate_factor, rate_slope, yield, slope, effective
    real(wp) :: mode_a, mode_b, mode_c, multiplier, increment, plastic_sum
    logical :: rate_effects, with_back_stress
    integer :: i

    with_back_stress = present(back_stress)
    kinematic = 0.0_wp
    if (with_back_stress) kinematic = kinematic_modulus
    shear_modulus = youngs_modulus/(2.0_wp*(1.0_wp + poissons_ratio))
    mode_stiffness = [youngs_modulus/(3.0_wp*(1.0_wp - poissons_ratio)), 2.0_wp*shear_modulus, &
                      2.0_wp*shear_modulus] + 2.0_wp/3.0_wp*kinematic
    rate_effects = time_step > 0.0_wp .and. (allocated(rate_curve%abscissa) .or. &
                                             (rate_c > 0.0_wp .and. rate_p > 0.0_wp))

    old_stress(1:nel, :) = stress(1:nel, :)
    call plane_stress_elastic_update(nel, youngs_modulus, poissons_ratio, strain_increment, stress, &
                                     thickness_strain_increment)

    do i = 1, nel
      relative = [stress(i, 1), stress(i, 2), stress(i, 3)]
      if (with_back_stress) relative = relative - [back_stress(i, 1), back_stress(i, 2), back_stress(i, 3)]
      mode_a = root_half*(relative(1) + relative(2))
      mode_b = root_half*(relative(1) - relative(2))
      mode_c = relative(3)
      mode_squares = [0.5_wp*mode_a**2, 1.5_wp*mode_b**2, 3.0_wp*mode_c**2]
      effective = sqrt(sum(mode_squares))
      ! VP = 0: k of the step's strain rate; VP = 1: the elastic limit is k at zero plastic rate.
      rate_factor = 1.0_wp
      if (rate_effects) call rate_scale_factor(rate_curve, rate_c, rate_p, &
        merge(0.0_wp, in_plane_strain_rate(strain_increment, i, time_step), viscoplastic), rate_factor, rate_slope)
      call static_yield_stress(hardening_curve, initial_yield, isotropic_modulus, plastic_strain(i), yield, slope)
      if (effective <= rate_factor*yield) cycle

      call solve_plastic_multiplier(mode_squares, mode_stiffness, plastic_strain(i), hardening_curve, &
                                    initial_yield, isotropic_modulus, rate_curve, rate_c, rate_p, &
                                    rate_effects .and. viscoplastic, time_step, rate_factor, multiplier, increment)
      mode_a = mode_a/(1.0_wp + mode_stiffness(1)*multiplier)
      mode_b = mode_b/(1.0_wp + mode_stiffness(2)*multiplier)
      mode_c = mode_c/(1.0_wp + mode_stiffness(3)*multiplier)
      relative = [root_half*(mode_a + mode_b), root_half*(mode_a - mode_b), mode_c]
      ! d eps^p_xx + d eps^p_yy = dgamma (xi_xx + xi_yy) / 3
      plastic_sum = multiplier*(relative(1) + relative(2))/3.0_wp
      if (with_back_stress) then
        back_stress(i, :) = back_stress(i, :) + 2.0_wp/3.0_wp*kinematic*multiplier*relative
        stress(i, :) = relative + back_stress(i, :)
      else
        stress(i, :) = relative
      end if
      plastic_strain(i) = plastic_strain(i) + increment
      thickness_strain_increment(i) = -poissons_ratio/youngs_modulus &
        *(stress(i, 1) - old_stress(i, 1) + stress(i, 2) - old_stress(i, 2)) - plastic_sum
    end do
  end subroutine plane_stress_plasticity_update
end module plane_stress_plasticity
