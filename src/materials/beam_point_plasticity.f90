!> The stress update of one beam integration point: the axial stress s_11 and the two
!> transverse shears s_12, s_13 in the beam's corotational frame (Hughes & Liu 1981; LS-DYNA
!> Theory Manual, "Hughes-Liu beam": the other stresses are zero).
!>
!> Elastic: s_11 += E d_11 dt, s_1k += SHRF G gamma_1k dt. Plastic (*MAT_PLASTIC_KINEMATIC and
!> *MAT_SPOTWELD on beams): von Mises on the beam's stress state, s_eq = sqrt(s_11^2 + 3 (s_12^2 +
!> s_13^2)), with linear isotropic hardening s_y = SIGY + H eps_p, H = E ET / (E - ET). The return
!> follows the normal: with plastic multiplier dl (= the increment of eps_p),
!> s_11 = s_11* / (1 + E dl / s_y), s_1k = s_1k* / (1 + 3 SHRF G dl / s_y), and dl solves
!> s_eq(dl) = SIGY + H (eps_p + dl) (bisection, see below).
module beam_point_plasticity
  use kinds, only: wp
  use model, only: material_t
  use material_laws, only: law_plastic_kinematic, law_spotweld
  implicit none
  private

  public :: update_beam_point, beam_shear_modulus

contains

  !> G = E / (2 (1 + nu)).
  pure real(wp) function beam_shear_modulus(material)
    type(material_t), intent(in) :: material
    beam_shear_modulus = material%youngs_modulus/(2.0_wp*(1.0_wp + material%poissons_ratio))
  end function beam_shear_modulus

  !> One point: `increment` = (d_11, gamma_12, gamma_13) dt; `stress` and `plastic_strain`
  !> updated in place.
  pure subroutine update_beam_point(material, shear_factor, increment, stress, plastic_strain)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: shear_factor, increment(3)
    real(wp), intent(inout) :: stress(3), plastic_strain
    real(wp) :: youngs, shear, hardening, yield, trial(3), equivalent, change, low, high, current_yield
    integer :: iteration
    youngs = material%youngs_modulus
    shear = shear_factor*beam_shear_modulus(material)
    trial(1) = stress(1) + youngs*increment(1)
    trial(2) = stress(2) + shear*increment(2)
    trial(3) = stress(3) + shear*increment(3)
    stress = trial
    if (material%law /= law_plastic_kinematic .and. material%law /= law_spotweld) return
    if (.not. material%yield_stress > 0.0_wp) return
    hardening = 0.0_wp
    if (material%tangent_modulus > 0.0_wp .and. material%tangent_modulus < youngs) &
      hardening = youngs*material%tangent_modulus/(youngs - material%tangent_modulus)
    yield = material%yield_stress + hardening*plastic_strain
    equivalent = sqrt(trial(1)**2 + 3.0_wp*(trial(2)**2 + trial(3)**2))
    if (equivalent <= yield) return
    ! the return's multiplier lies between the uniaxial (E) and pure-shear (3 SHRF G) returns,
    ! whose stiffnesses bound the factors above: bisection between them (fixed count: the same
    ! result on every run)
    low = (equivalent - yield)/(max(youngs, 3.0_wp*shear) + hardening)
    high = (equivalent - yield)/(min(youngs, 3.0_wp*shear) + hardening)
    do iteration = 1, 40
      change = 0.5_wp*(low + high)
      if (return_residual(trial, youngs, shear, yield + hardening*change, change) > 0.0_wp) then
        low = change
      else
        high = change
      end if
    end do
    change = 0.5_wp*(low + high)
    current_yield = yield + hardening*change
    stress(1) = trial(1)/(1.0_wp + youngs*change/current_yield)
    stress(2:3) = trial(2:3)/(1.0_wp + 3.0_wp*shear*change/current_yield)
    plastic_strain = plastic_strain + change
  end subroutine update_beam_point

  !> s_eq of the returned stress minus the yield stress `current_yield`, for multiplier `change`.
  pure real(wp) function return_residual(trial, youngs, shear, current_yield, change)
    real(wp), intent(in) :: trial(3), youngs, shear, current_yield, change
    return_residual = sqrt((trial(1)/(1.0_wp + youngs*change/current_yield))**2 + &
                           3.0_wp*(trial(2)**2 + trial(3)**2)/(1.0_wp + 3.0_wp*shear*change/current_yield)**2) &
                      - current_yield
  end function return_residual
end module beam_point_plasticity
