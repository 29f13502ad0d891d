!> *MAT_PIECEWISE_LINEAR_PLASTICITY (LS-DYNA material 24) for solids: von Mises plasticity
!> with isotropic hardening from a curve of yield stress against effective plastic strain
!> (LCSS, or the EPS1-8 / ES1-8 table), or bilinear from SIGY and ETAN, and a strain-rate
!> scale factor (Cowper-Symonds C, P, or the curve LCSR). LS-DYNA Keyword User's Manual
!> Vol. II, *MAT_024; LS-DYNA Theory Manual, "Material Model 24: Piecewise Linear
!> Isotropic Plasticity"; radial return after Krieg & Key (1976).
!>
!>   static yield   Y(eps_p) = LCSS(eps_p), or SIGY + E_p eps_p with E_p = E ETAN / (E - ETAN)
!>   yield stress   sigma_y = k Y(eps_p + d eps_p)
!>   VP = 0         k = k(rate), rate = sqrt(2/3 D:D) the effective TOTAL strain rate of the
!>                  step (the whole tensor, as LS-DYNA's VP = 0; VP = -1 would take D')
!>   VP = 1         k = k(d eps_p / dt), the plastic strain rate (viscoplastic: the rate
!>                  factor enters the consistency condition and is solved with it)
!>   k(rate)        LCSR(rate) when LCSR is given, else 1 + (rate / C)^(1/P) when C, P > 0,
!>                  else 1
!>
!> The module also holds the scalar return shared with the plane-stress kernels
!> (plane_stress_plasticity): `solve_plastic_multiplier` solves the consistency condition
!>
!>   phi(dgamma) = sbar(dgamma) - k Y(eps_p + d eps_p(dgamma)) = 0,
!>   sbar(dgamma)^2 = sum_m q_m / (1 + a_m dgamma)^2,   d eps_p = 2/3 dgamma sbar(dgamma)
!>
!> in which the relative stress is split into modes that the elastic predictor and the flow
!> rule scale independently (one mode, a = 2G, in 3D: sbar = sbar_trial - 3 G d eps_p; three in
!> plane stress, Simo & Taylor 1986). A safeguarded Newton iteration (bisection whenever a
!> step leaves the bracket) converges in a few steps for the piecewise-linear curves and stays
!> robust for softening segments and the infinite slope of (rate/C)^(1/P) at zero rate.
module material_piecewise_linear
  use kinds, only: wp, block_size
  use curves, only: curve_t, curve_value, curve_slope, curve_value_and_slope
  implicit none
  private

  public :: piecewise_linear_update, solve_plastic_multiplier, static_yield_stress, rate_scale_factor
  public :: effective_strain_rate

  ! History variables per integration point (1 in all: law_table in material_laws): the
  ! effective plastic strain.
  !> Slot of the effective plastic strain in the history.
  integer, parameter, public :: piecewise_plastic_strain_slot = 1

  !> Iteration limit of the scalar return; Newton needs a handful, bisection (rare) 2^-100.
  integer, parameter :: return_iterations = 100
  !> Relative size of the consistency residual at which the iteration stops.
  real(wp), parameter :: return_tolerance = 1.0e-14_wp
  !> Below this rate / C the Cowper-Symonds slope (rate/C)^(1/P - 1) is treated as infinite.
  real(wp), parameter :: smallest_rate_ratio = 1.0e-100_wp

contains

  !> Radial-return update of lanes 1..nel. `strain_increment` holds TENSOR components (de_xy,
  !> not 2 de_xy), order xx, yy, zz, xy, yz, zx; `stress` enters rotated to the end of the step
  !> and leaves updated; `plastic_strain` is this law's history. `hardening_curve` is LCSS (or
  !> the EPS/ES table); when it holds no points the hardening is bilinear, SIGY = `initial_yield`
  !> and E_p = `hardening_modulus`. `rate_curve` is LCSR (no points: Cowper-Symonds `rate_c`,
  !> `rate_p`, off when either is 0). `viscoplastic` selects VP = 1. `time_step` = 0: no rate effect.
  subroutine piecewise_linear_update(nel, bulk_modulus, shear_modulus, hardening_curve, initial_yield, &
                                     hardening_modulus, rate_curve, rate_c, rate_p, viscoplastic, time_step, &
                                     strain_increment, stress, plastic_strain)
    integer, intent(in) :: nel
    real(wp), intent(in) :: bulk_modulus, shear_modulus
    type(curve_t), intent(in) :: hardening_curve, rate_curve
    real(wp), intent(in) :: initial_yield, hardening_modulus, rate_c, rate_p
    logical, intent(in) :: viscoplastic
    real(wp), intent(in) :: time_step
    real(wp), intent(in) :: strain_increment(block_size, 6)
    real(wp), intent(inout) :: stress(block_size, 6)
    real(wp), intent(inout) :: plastic_strain(block_size)

    real(wp) :: deviator(block_size, 6), effective(block_size), new_mean(block_size)
    real(wp) :: rate_factor, rate_slope, yield, slope, multiplier, increment, scale, mean_increment, old_mean
    real(wp) :: mode_squares(3), mode_stiffness(3)
    logical :: rate_effects
    integer :: i, k

    rate_effects = has_rate_effect(rate_curve, rate_c, rate_p) .and. time_step > 0.0_wp
    mode_stiffness = 2.0_wp*shear_modulus

    ! Elastic predictor: deviatoric trial stress and the new mean stress.
    do i = 1, nel
      mean_increment = (strain_increment(i, 1) + strain_increment(i, 2) + strain_increment(i, 3))/3.0_wp
      old_mean = (stress(i, 1) + stress(i, 2) + stress(i, 3))/3.0_wp
      new_mean(i) = old_mean + 3.0_wp*bulk_modulus*mean_increment
      do k = 1, 3
        deviator(i, k) = stress(i, k) - old_mean + 2.0_wp*shear_modulus*(strain_increment(i, k) - mean_increment)
      end do
      do k = 4, 6
        deviator(i, k) = stress(i, k) + 2.0_wp*shear_modulus*strain_increment(i, k)
      end do
      effective(i) = sqrt(1.5_wp*(deviator(i, 1)**2 + deviator(i, 2)**2 + deviator(i, 3)**2) &
                          + 3.0_wp*(deviator(i, 4)**2 + deviator(i, 5)**2 + deviator(i, 6)**2))
    end do

    ! Return to the yield surface, lane by lane where the trial state lies outside it.
    do i = 1, nel
      ! VP = 0: k of the step's strain rate; VP = 1: the elastic limit is k at zero plastic rate.
      rate_factor = 1.0_wp
      if (rate_effects) call rate_scale_factor(rate_curve, rate_c, rate_p, &
        merge(0.0_wp, effective_strain_rate(strain_increment, i, time_step), viscoplastic), rate_factor, rate_slope)
      call static_yield_stress(hardening_curve, initial_yield, hardening_modulus, plastic_strain(i), yield, slope)
      scale = 1.0_wp
      if (effective(i) > rate_factor*yield) then
        mode_squares = [effective(i)**2, 0.0_wp, 0.0_wp]
        call solve_plastic_multiplier(mode_squares, mode_stiffness, plastic_strain(i), hardening_curve, &
                                      initial_yield, hardening_modulus, rate_curve, rate_c, rate_p, &
                                      rate_effects .and. viscoplastic, time_step, rate_factor, multiplier, increment)
        scale = 1.0_wp/(1.0_wp + mode_stiffness(1)*multiplier)
        plastic_strain(i) = plastic_strain(i) + increment
      end if
      do k = 1, 3
        stress(i, k) = scale*deviator(i, k) + new_mean(i)
      end do
      do k = 4, 6
        stress(i, k) = scale*deviator(i, k)
      end do
    end do
  end subroutine piecewise_linear_update

  !> Effective strain rate sqrt(2/3 D:D) of lane `lane` of a block of TENSOR strain increments
  !> (xx, yy, zz, xy, yz, zx) over `time_step` > 0.
  pure function effective_strain_rate(strain_increment, lane, time_step) result(rate)
    real(wp), intent(in) :: strain_increment(block_size, 6), time_step
    integer, intent(in) :: lane
    real(wp) :: rate
    rate = sqrt(2.0_wp/3.0_wp*(strain_increment(lane, 1)**2 + strain_increment(lane, 2)**2 &
                               + strain_increment(lane, 3)**2 + 2.0_wp*(strain_increment(lane, 4)**2 &
                               + strain_increment(lane, 5)**2 + strain_increment(lane, 6)**2)))/time_step
  end function effective_strain_rate

  !> True when a rate factor applies: an LCSR curve, or both Cowper-Symonds constants > 0.
  pure logical function has_rate_effect(rate_curve, rate_c, rate_p)
    type(curve_t), intent(in) :: rate_curve
    real(wp), intent(in) :: rate_c, rate_p
    has_rate_effect = allocated(rate_curve%abscissa)
    if (.not. has_rate_effect) has_rate_effect = rate_c > 0.0_wp .and. rate_p > 0.0_wp
  end function has_rate_effect

  !> Static yield stress Y(eps_p) and its slope: the hardening curve where it has points
  !> (linear extrapolation beyond its ends, as every crashfree curve), else the bilinear
  !> SIGY + E_p eps_p.
  pure subroutine static_yield_stress(hardening_curve, initial_yield, hardening_modulus, plastic_strain, &
                                      yield, slope)
    type(curve_t), intent(in) :: hardening_curve
    real(wp), intent(in) :: initial_yield, hardening_modulus, plastic_strain
    real(wp), intent(out) :: yield, slope
    if (allocated(hardening_curve%abscissa)) then
      call curve_value_and_slope(hardening_curve, plastic_strain, yield, slope)
    else
      yield = initial_yield + hardening_modulus*plastic_strain
      slope = hardening_modulus
    end if
  end subroutine static_yield_stress

  !> Rate scale factor k(rate) and dk/drate: LCSR(rate) when the curve has points, else
  !> Cowper-Symonds 1 + (rate/C)^(1/P) (C, P > 0), else 1. The Cowper-Symonds slope is
  !> infinite at rate 0 for P > 1; it is then returned as -1 (callers bisect instead).
  pure subroutine rate_scale_factor(rate_curve, rate_c, rate_p, rate, factor, slope)
    type(curve_t), intent(in) :: rate_curve
    real(wp), intent(in) :: rate_c, rate_p, rate
    real(wp), intent(out) :: factor, slope
    real(wp) :: ratio
    if (allocated(rate_curve%abscissa)) then
      call curve_value_and_slope(rate_curve, rate, factor, slope)
    else if (rate_c > 0.0_wp .and. rate_p > 0.0_wp) then
      ratio = max(rate, 0.0_wp)/rate_c
      factor = 1.0_wp
      if (ratio > 0.0_wp) factor = 1.0_wp + ratio**(1.0_wp/rate_p)
      if (ratio > smallest_rate_ratio .or. rate_p <= 1.0_wp) then
        slope = 0.0_wp
        if (ratio > 0.0_wp .or. rate_p == 1.0_wp) slope = ratio**(1.0_wp/rate_p - 1.0_wp)/(rate_p*rate_c)
      else
        slope = -1.0_wp
      end if
    else
      factor = 1.0_wp
      slope = 0.0_wp
    end if
  end subroutine rate_scale_factor

  !> Plastic multiplier `multiplier` (dgamma >= 0) and effective plastic strain increment
  !> `plastic_increment` = 2/3 dgamma sbar of one point whose trial state lies outside the
  !> yield surface: the root of
  !>   phi(dgamma) = sbar(dgamma) - k Y(plastic_strain + 2/3 dgamma sbar(dgamma)),
  !>   sbar(dgamma)^2 = sum_m mode_squares(m) / (1 + mode_stiffness(m) dgamma)^2.
  !> k is `fixed_rate_factor` unless `viscoplastic`, where k = k(d eps_p / time_step) (see
  !> rate_scale_factor). phi decreases for hardening curves; the bracket starts at
  !> [0, dgamma with sbar = k(0) Y(plastic_strain)] and doubles its upper end until phi <= 0
  !> there, which also covers softening segments.
  pure subroutine solve_plastic_multiplier(mode_squares, mode_stiffness, plastic_strain, hardening_curve, &
                                           initial_yield, hardening_modulus, rate_curve, rate_c, rate_p, &
                                           viscoplastic, time_step, fixed_rate_factor, multiplier, plastic_increment)
    real(wp), intent(in) :: mode_squares(3), mode_stiffness(3), plastic_strain
    type(curve_t), intent(in) :: hardening_curve, rate_curve
    real(wp), intent(in) :: initial_yield, hardening_modulus, rate_c, rate_p
    logical, intent(in) :: viscoplastic
    real(wp), intent(in) :: time_step, fixed_rate_factor
    real(wp), intent(out) :: multiplier, plastic_increment
    real(wp) :: lower, upper, residual, slope, candidate, trial_effective, yield0, slope0, factor0, unused
    logical :: singular
    integer :: iteration

    trial_effective = sqrt(sum(mode_squares))
    call static_yield_stress(hardening_curve, initial_yield, hardening_modulus, plastic_strain, yield0, slope0)
    factor0 = fixed_rate_factor
    if (viscoplastic) call rate_scale_factor(rate_curve, rate_c, rate_p, 0.0_wp, factor0, unused)
    ! sbar(dgamma) <= trial / (1 + min(a) dgamma): this dgamma brings sbar to k(0) Y(eps_p).
    upper = max(trial_effective/max(factor0*yield0, tiny(1.0_wp)) - 1.0_wp, 0.0_wp)/minval(mode_stiffness)
    ! with a yield stress that never falls as the plastic strain grows, phi(upper) <= 0 by
    ! construction; only a softening curve needs the bracket searched
    if (softening(hardening_curve) .or. hardening_modulus < 0.0_wp) then
      do iteration = 1, 200
        call evaluate(upper, residual, slope, singular)
        if (residual <= 0.0_wp) exit
        upper = 2.0_wp*upper + tiny(1.0_wp)
      end do
    end if

    lower = 0.0_wp
    multiplier = 0.0_wp
    do iteration = 1, return_iterations
      call evaluate(multiplier, residual, slope, singular)
      if (residual > 0.0_wp) then
        lower = multiplier
      else
        upper = multiplier
      end if
      if (abs(residual) <= return_tolerance*trial_effective) exit
      if (upper - lower <= 4.0_wp*epsilon(1.0_wp)*upper) exit
      candidate = 0.5_wp*(lower + upper)
      if (.not. singular .and. slope < 0.0_wp) then
        if (abs(residual) < abs(slope)*(upper - lower)) candidate = multiplier - residual/slope
        if (candidate <= lower .or. candidate >= upper) candidate = 0.5_wp*(lower + upper)
      end if
      ! a Newton step at round-off ends it: the residual cannot fall below the rounding of
      ! sbar (and the bracket does not shrink when Newton approaches from one side)
      if (abs(candidate - multiplier) <= 4.0_wp*epsilon(1.0_wp)*abs(multiplier)) then
        multiplier = candidate
        exit
      end if
      multiplier = candidate
    end do
    plastic_increment = 2.0_wp/3.0_wp*multiplier*effective_stress(multiplier)

  contains

    pure logical function softening(curve)
      type(curve_t), intent(in) :: curve
      integer :: k
      softening = .false.
      if (.not. allocated(curve%ordinate)) return
      do k = 2, size(curve%ordinate)
        if (curve%ordinate(k) < curve%ordinate(k - 1)) then
          softening = .true.
          return
        end if
      end do
    end function softening

    pure function effective_stress(gamma) result(sbar)
      real(wp), intent(in) :: gamma
      real(wp) :: sbar
      sbar = sqrt(sum(mode_squares/(1.0_wp + mode_stiffness*gamma)**2))
    end function effective_stress

    !> phi(gamma) and d phi / d gamma; `singular` when the rate factor's slope is infinite.
    pure subroutine evaluate(gamma, phi, dphi, singular)
      real(wp), intent(in) :: gamma
      real(wp), intent(out) :: phi, dphi
      logical, intent(out) :: singular
      real(wp) :: sbar, dsbar, increment, dincrement, yield, dyield, factor, dfactor
      sbar = effective_stress(gamma)
      dsbar = -sum(mode_stiffness*mode_squares/(1.0_wp + mode_stiffness*gamma)**3)/max(sbar, tiny(1.0_wp))
      increment = 2.0_wp/3.0_wp*gamma*sbar
      dincrement = 2.0_wp/3.0_wp*(sbar + gamma*dsbar)
      call static_yield_stress(hardening_curve, initial_yield, hardening_modulus, plastic_strain + increment, &
                               yield, dyield)
      singular = .false.
      if (viscoplastic) then
        call rate_scale_factor(rate_curve, rate_c, rate_p, increment/time_step, factor, dfactor)
        singular = dfactor < 0.0_wp .and. .not. allocated(rate_curve%abscissa)
        if (singular) dfactor = 0.0_wp
        phi = sbar - factor*yield
        dphi = dsbar - (dfactor/time_step*yield + factor*dyield)*dincrement
      else
        phi = sbar - fixed_rate_factor*yield
        dphi = dsbar - fixed_rate_factor*dyield*dincrement
      end if
    end subroutine evaluate
  end subroutine solve_plastic_multiplier
end module material_piecewise_linear
