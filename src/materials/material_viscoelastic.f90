!> *MAT_VISCOELASTIC (LS-DYNA material 6) for solids and plane stress (shells): elastic bulk
!> behaviour and a shear relaxation modulus G(t) = GI + (G0 - GI) exp(-BETA t) acting on the
!> deviatoric rate of deformation in Jaumann rate form, s' = 2 int G(t - tau) D'(tau) d tau
!> (LS-DYNA Keyword User's Manual Vol. II, *MAT_VISCOELASTIC; LS-DYNA Theory Manual,
!> "Material Model 6: Viscoelastic"; see docs/materials.md).
!>
!> The hereditary integral splits into a long-term spring 2 GI D' and one Maxwell branch h with
!> h' = 2 (G0 - GI) D' - BETA h. Over a step with D' constant the branch is integrated
!> exactly: h(n+1) = e h(n) + 2 (G0 - GI) phi D' dt, e = exp(-BETA dt), phi = (1 - e) / (BETA dt)
!> (phi = 1 for BETA dt -> 0). The pressure is hypoelastic, dp = -K tr(D) dt. The stress and
!> the branch h (history) are both rotated objectively by the elements, so
!> sigma(n+1) = sigma(n) + K tr(D dt) I + 2 GI dev(D dt) + h(n+1) - h(n).
!>
!> Plane stress: the thickness strain increment making sigma_zz(n+1) = 0 solves a linear
!> equation (no iteration): (K + 4/3 G*) d eps_zz = -(K - 2/3 G*) (d eps_xx + d eps_yy)
!> - (e - 1) h_zz, G* = GI + (G0 - GI) phi.
module material_viscoelastic
  use kinds, only: wp, block_size
  implicit none
  private

  public :: viscoelastic_update, viscoelastic_plane_stress_update, viscoelastic_step_factors

contains

  !> Decay e = exp(-beta dt) and mean factor phi = (1 - e) / (beta dt) of the Maxwell branch.
  pure subroutine viscoelastic_step_factors(decay_constant, dt, decay, mean)
    real(wp), intent(in) :: decay_constant, dt
    real(wp), intent(out) :: decay, mean
    real(wp) :: exponent
    exponent = decay_constant*dt
    decay = exp(-exponent)
    if (exponent > 1.0e-8_wp) then
      mean = (1.0_wp - decay)/exponent
    else
      mean = 1.0_wp - 0.5_wp*exponent
    end if
  end subroutine viscoelastic_step_factors

  !> Solid update of lanes 1..nel (strain increments with TENSOR shear components, xx yy zz xy
  !> yz zx); history(:, 1:6): the Maxwell branch's deviatoric stress h.
  subroutine viscoelastic_update(nel, bulk_modulus, short_term_shear, long_term_shear, decay_constant, dt, &
                                 strain_increment, stress, history)
    integer, intent(in) :: nel
    real(wp), intent(in) :: bulk_modulus, short_term_shear, long_term_shear, decay_constant, dt
    real(wp), intent(in) :: strain_increment(block_size, 6)
    real(wp), intent(inout) :: stress(block_size, 6)
    real(wp), intent(inout), contiguous :: history(:, :)
    real(wp) :: decay, mean, branch_modulus, volumetric, deviator(6), change(6)
    integer :: i
    call viscoelastic_step_factors(decay_constant, dt, decay, mean)
    branch_modulus = 2.0_wp*(short_term_shear - long_term_shear)*mean
    do i = 1, nel
      volumetric = strain_increment(i, 1) + strain_increment(i, 2) + strain_increment(i, 3)
      deviator = strain_increment(i, :)
      deviator(1:3) = deviator(1:3) - volumetric/3.0_wp
      change = (decay - 1.0_wp)*history(i, 1:6) + branch_modulus*deviator
      history(i, 1:6) = history(i, 1:6) + change
      stress(i, :) = stress(i, :) + 2.0_wp*long_term_shear*deviator + change
      stress(i, 1:3) = stress(i, 1:3) + bulk_modulus*volumetric
    end do
  end subroutine viscoelastic_update

  !> Plane-stress update of lanes 1..nel in the shell's local frame: d eps_xx, d eps_yy,
  !> d gamma_xy (ENGINEERING shear); history(:, 1:4) = h_xx, h_yy, h_zz, h_xy.
  subroutine viscoelastic_plane_stress_update(nel, bulk_modulus, short_term_shear, long_term_shear, &
                                              decay_constant, dt, strain_increment, stress, history, &
                                              thickness_strain_increment)
    integer, intent(in) :: nel
    real(wp), intent(in) :: bulk_modulus, short_term_shear, long_term_shear, decay_constant, dt
    real(wp), intent(in) :: strain_increment(block_size, 3)
    real(wp), intent(inout) :: stress(block_size, 3)
    real(wp), intent(inout), contiguous :: history(:, :)
    real(wp), intent(out) :: thickness_strain_increment(block_size)
    real(wp) :: decay, mean, branch_modulus, step_shear, in_plane, thickness, volumetric, deviator(4), change(4)
    integer :: i
    call viscoelastic_step_factors(decay_constant, dt, decay, mean)
    branch_modulus = 2.0_wp*(short_term_shear - long_term_shear)*mean
    step_shear = long_term_shear + 0.5_wp*branch_modulus
    do i = 1, nel
      in_plane = strain_increment(i, 1) + strain_increment(i, 2)
      thickness = (-(bulk_modulus - 2.0_wp*step_shear/3.0_wp)*in_plane - (decay - 1.0_wp)*history(i, 3))/ &
                  (bulk_modulus + 4.0_wp*step_shear/3.0_wp)
      volumetric = in_plane + thickness
      deviator = [strain_increment(i, 1) - volumetric/3.0_wp, strain_increment(i, 2) - volumetric/3.0_wp, &
                  thickness - volumetric/3.0_wp, 0.5_wp*strain_increment(i, 3)]
      change = (decay - 1.0_wp)*history(i, 1:4) + branch_modulus*deviator
      history(i, 1:4) = history(i, 1:4) + change
      stress(i, 1) = stress(i, 1) + bulk_modulus*volumetric + 2.0_wp*long_term_shear*deviator(1) + change(1)
      stress(i, 2) = stress(i, 2) + bulk_modulus*volumetric + 2.0_wp*long_term_shear*deviator(2) + change(2)
      stress(i, 3) = stress(i, 3) + 2.0_wp*long_term_shear*deviator(4) + change(4)
      thickness_strain_increment(i) = thickness
    end do
  end subroutine viscoelastic_plane_stress_update
end module material_viscoelastic
