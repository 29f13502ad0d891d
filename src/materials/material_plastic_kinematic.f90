!> *MAT_PLASTIC_KINEMATIC (LS-DYNA material 3): bilinear von Mises plasticity with mixed
!> isotropic/kinematic hardening and an optional Cowper-Symonds rate factor, integrated by
!> radial return (Krieg & Key 1976; LS-DYNA Theory Manual, "Material model 3: Elastic
!> plastic with kinematic hardening"; Hallquist, DYNA3D).
!>
!> With E_p = E Etan / (E - Etan) the plastic hardening modulus and beta the mixing parameter:
!>
!>   yield stress   sigma_y = k(rate) (SIGY + beta E_p eps_p)
!>   back stress    d alpha = (2/3) (1 - beta) E_p d eps^p     (deviatoric)
!>   rate factor    k = 1 + (rate / C)^(1/P)    only when C > 0 and P > 0, else 1
!>
!> VP = 0 (default) scales the yield stress with the effective total strain rate
!> rate = sqrt(2/3 D':D') (D' the deviatoric rate of deformation). VP = 1 (viscoplastic) uses
!> the plastic strain rate d eps_p / dt inside the consistency condition instead, solved per
!> lane by a safeguarded Newton iteration.
!>
!> Radial return: xi = s_trial - alpha, sbar = sqrt(3/2 xi:xi). If sbar > sigma_y the plastic
!> increment follows from the consistency condition at the end of the step,
!>   sbar - (3 G + (1 - beta) E_p) d eps_p = k (SIGY + beta E_p (eps_p + d eps_p)),
!> i.e. d eps_p = (sbar - sigma_y) / (3 G + (1 - beta) E_p + k beta E_p), which for k = 1 is the
!> classical (sbar - sigma_y) / (3 G + E_p); then s = s_trial - 3 G d eps_p xi / sbar and
!> alpha = alpha + (1 - beta) E_p d eps_p xi / sbar. Linear hardening makes this exact along
!> proportional paths: the uniaxial curve is bilinear with slopes E and Etan.
module material_plastic_kinematic
  use kinds, only: wp, block_size
  implicit none
  private

  public :: plastic_kinematic_update

  ! History variables per integration point (7 in all: law_table in material_laws): effective
  ! plastic strain, then the back stress.
  !> Slot of the effective plastic strain in the history.
  integer, parameter, public :: plastic_strain_slot = 1
  !> First of the six slots of the back stress (xx, yy, zz, xy, yz, zx).
  integer, parameter, public :: back_stress_first_slot = 2

  !> Newton iterations of the viscoplastic (VP = 1) consistency condition; the iteration is
  !> bracketed and converges to round-off well within this count for P >= 1.
  integer, parameter :: viscoplastic_iterations = 40

contains

  !> Radial-return update of lanes 1..nel. `strain_increment` holds TENSOR components
  !> (de_xy, not 2 de_xy), order xx, yy, zz, xy, yz, zx; `stress` enters rotated to the end of
  !> the step and leaves updated; `plastic_strain` and `back_stress` are this law's history.
  !> `hardening_modulus` is E_p = E Etan / (E - Etan). `viscoplastic` selects VP = 1.
  subroutine plastic_kinematic_update(nel, bulk_modulus, shear_modulus, yield_stress, hardening_modulus, &
                                      hardening_beta, rate_c, rate_p, viscoplastic, time_step, &
                                      strain_increment, stress, plastic_strain, back_stress)
    integer, intent(in) :: nel
    real(wp), intent(in) :: bulk_modulus, shear_modulus, yield_stress, hardening_modulus, hardening_beta
    real(wp), intent(in) :: rate_c, rate_p
    logical, intent(in) :: viscoplastic
    real(wp), intent(in) :: time_step
    real(wp), intent(in) :: strain_increment(block_size, 6)
    real(wp), intent(inout) :: stress(block_size, 6)
    real(wp), intent(inout) :: plastic_strain(block_size)
    real(wp), intent(inout) :: back_stress(block_size, 6)

    real(wp) :: rate_factor(block_size), increment(block_size)
    real(wp) :: relative(block_size, 6), effective(block_size), static_yield(block_size)
    real(wp) :: twice_shear, three_shear, kinematic_modulus, isotropic_modulus
    real(wp) :: mean_increment, old_mean, new_mean, deviatoric_increment
    real(wp) :: ratio, stress_scale, back_scale
    logical :: rate_effects
    integer :: i, k

    twice_shear = 2.0_wp*shear_modulus
    three_shear = 3.0_wp*shear_modulus
    isotropic_modulus = hardening_beta*hardening_modulus
    kinematic_modulus = (1.0_wp - hardening_beta)*hardening_modulus
    rate_effects = rate_c > 0.0_wp .and. rate_p > 0.0_wp .and. time_step > 0.0_wp

    ! Trial state: elastic predictor of the deviatoric stress relative to the back stress.
    do i = 1, nel
      mean_increment = (strain_increment(i, 1) + strain_increment(i, 2) + strain_increment(i, 3))/3.0_wp
      old_mean = (stress(i, 1) + stress(i, 2) + stress(i, 3))/3.0_wp
      do k = 1, 3
        deviatoric_increment = strain_increment(i, k) - mean_increment
        relative(i, k) = stress(i, k) - old_mean + twice_shear*deviatoric_increment - back_stress(i, k)
      end do
      do k = 4, 6
        relative(i, k) = stress(i, k) + twice_shear*strain_increment(i, k) - back_stress(i, k)
      end do
      effective(i) = sqrt(1.5_wp*(relative(i, 1)**2 + relative(i, 2)**2 + relative(i, 3)**2) &
                          + 3.0_wp*(relative(i, 4)**2 + relative(i, 5)**2 + relative(i, 6)**2))
      static_yield(i) = yield_stress + isotropic_modulus*plastic_strain(i)
    end do

    if (rate_effects .and. viscoplastic) then
      call viscoplastic_increment(nel, three_shear + kinematic_modulus, isotropic_modulus, rate_c, rate_p, &
                                  time_step, effective, static_yield, increment)
    else
      if (rate_effects) then
        call total_strain_rate_factor(nel, rate_c, rate_p, time_step, strain_increment, rate_factor)
      else
        rate_factor(1:nel) = 1.0_wp
      end if
      do i = 1, nel
        increment(i) = max(effective(i) - rate_factor(i)*static_yield(i), 0.0_wp) &
                       /(three_shear + kinematic_modulus + rate_factor(i)*isotropic_modulus)
      end do
    end if

    ! Return to the yield surface along xi (zero increment leaves the trial state).
    do i = 1, nel
      mean_increment = (strain_increment(i, 1) + strain_increment(i, 2) + strain_increment(i, 3))/3.0_wp
      new_mean = (stress(i, 1) + stress(i, 2) + stress(i, 3))/3.0_wp + 3.0_wp*bulk_modulus*mean_increment
      ratio = increment(i)/max(effective(i), tiny(1.0_wp))
      stress_scale = 1.0_wp - three_shear*ratio
      back_scale = kinematic_modulus*ratio
      ! s = s_trial - 3 G ratio xi with s_trial = alpha_old + xi
      do k = 1, 3
        stress(i, k) = back_stress(i, k) + stress_scale*relative(i, k) + new_mean
      end do
      do k = 4, 6
        stress(i, k) = back_stress(i, k) + stress_scale*relative(i, k)
      end do
      do k = 1, 6
        back_stress(i, k) = back_stress(i, k) + back_scale*relative(i, k)
      end do
      plastic_strain(i) = plastic_strain(i) + increment(i)
    end do
  end subroutine plastic_kinematic_update

  !> Cowper-Symonds factor from the effective total strain rate sqrt(2/3 D':D') (VP = 0).
  subroutine total_strain_rate_factor(nel, rate_c, rate_p, time_step, strain_increment, rate_factor)
    integer, intent(in) :: nel
    real(wp), intent(in) :: rate_c, rate_p, time_step
    real(wp), intent(in) :: strain_increment(block_size, 6)
    real(wp), intent(out) :: rate_factor(block_size)
    real(wp) :: mean_increment, d1, d2, d3, effective_rate, exponent
    integer :: i
    exponent = 1.0_wp/rate_p
    do i = 1, nel
      mean_increment = (strain_increment(i, 1) + strain_increment(i, 2) + strain_increment(i, 3))/3.0_wp
      d1 = strain_increment(i, 1) - mean_increment
      d2 = strain_increment(i, 2) - mean_increment
      d3 = strain_increment(i, 3) - mean_increment
      effective_rate = sqrt(2.0_wp/3.0_wp*(d1*d1 + d2*d2 + d3*d3 + 2.0_wp*(strain_increment(i, 4)**2 &
                            + strain_increment(i, 5)**2 + strain_increment(i, 6)**2)))/time_step
      rate_factor(i) = 1.0_wp + (effective_rate/rate_c)**exponent
    end do
  end subroutine total_strain_rate_factor

  !> VP = 1: solve g(d) = sbar - a d - (1 + (d/(dt C))^(1/P)) (sigma0 + b d) = 0 for the plastic
  !> increment d >= 0 (a = 3G + (1-beta) E_p, b = beta E_p, sigma0 the static yield stress).
  !> With u = d^(1/P) the function is smooth at u = 0 and decreasing; Newton runs inside the
  !> bracket [0, d_static^(1/P)] (d_static the rate-free increment, where g <= 0) and falls back
  !> to bisection whenever a step leaves it.
  subroutine viscoplastic_increment(nel, a, b, rate_c, rate_p, time_step, effective, static_yield, increment)
    integer, intent(in) :: nel
    real(wp), intent(in) :: a, b, rate_c, rate_p, time_step
    real(wp), intent(in) :: effective(block_size), static_yield(block_size)
    real(wp), intent(out) :: increment(block_size)
    real(wp) :: lower(block_size), upper(block_size), root(block_size)
    real(wp) :: scale, u, up, g, slope, candidate
    integer :: i, iteration
    scale = 1.0_wp/(time_step*rate_c)**(1.0_wp/rate_p)
    do i = 1, nel
      lower(i) = 0.0_wp
      upper(i) = (max(effective(i) - static_yield(i), 0.0_wp)/(a + b))**(1.0_wp/rate_p)
      root(i) = upper(i)
    end do
    do iteration = 1, viscoplastic_iterations
      do i = 1, nel
        u = root(i)
        up = u**rate_p
        g = effective(i) - a*up - (1.0_wp + scale*u)*(static_yield(i) + b*up)
        ! d(u^P)/du = P u^(P-1), written as P up / u (u > 0 inside the bracket)
        slope = -(a + (1.0_wp + scale*u)*b)*rate_p*up/max(u, tiny(1.0_wp)) - scale*(static_yield(i) + b*up)
        lower(i) = merge(u, lower(i), g > 0.0_wp)
        upper(i) = merge(upper(i), u, g > 0.0_wp)
        candidate = u - g/min(slope, -tiny(1.0_wp))
        root(i) = merge(candidate, 0.5_wp*(lower(i) + upper(i)), &
                        candidate >= lower(i) .and. candidate <= upper(i))
      end do
    end do
    do i = 1, nel
      increment(i) = root(i)**rate_p
    end do
  end subroutine viscoplastic_increment
end module material_plastic_kinematic
