!> Unit tests of the material laws through the block dispatch: *MAT_ELASTIC increments,
!> *MAT_PLASTIC_KINEMATIC uniaxial-stress paths (bilinear curve, isotropic and kinematic
!> reverse yield), Cowper-Symonds factors (VP = 0 and VP = 1), history rotation and layout.
program test_materials
  use kinds, only: wp, block_size
  use model, only: material_t, law_elastic, law_plastic_kinematic
  use material_dispatch, only: material_history_count, initialize_material_history, update_material_block, &
                               rotate_material_history, material_plastic_strain, elastic_moduli, &
                               plastic_hardening_modulus
  use objective_rotation, only: incremental_rotation
  use testing, only: test_suite_t, check, check_close, finish_suite
  implicit none

  type(test_suite_t) :: suite
  integer, parameter :: steps = 200
  real(wp), parameter :: youngs = 210000.0_wp, poisson = 0.3_wp, yield = 250.0_wp, tangent = 2100.0_wp

  suite%name = "materials"
  call test_elastic_increment()
  call test_history_layout()
  call test_uniaxial_isotropic()
  call test_uniaxial_kinematic()
  call test_cowper_symonds_scaled_yield()
  call test_cowper_symonds_viscoplastic()
  call test_back_stress_rotation()
  call finish_suite(suite)

contains

  function steel(beta) result(material)
    real(wp), intent(in) :: beta
    type(material_t) :: material
    material%law = law_plastic_kinematic
    material%density = 7.85e-9_wp
    material%youngs_modulus = youngs
    material%poissons_ratio = poisson
    material%yield_stress = yield
    material%tangent_modulus = tangent
    material%hardening_beta = beta
  end function steel

  subroutine test_elastic_increment()
    type(material_t) :: material
    real(wp) :: strain(block_size, 6), stress(block_size, 6), expected(6), wave(block_size)
    real(wp) :: history(block_size, 0)
    real(wp) :: bulk, shear, lambda
    integer :: lane
    material%law = law_elastic
    material%youngs_modulus = youngs
    material%poissons_ratio = poisson
    call elastic_moduli(material, bulk, shear)
    call check_close(suite, "shear modulus E/(2(1+nu))", shear, youngs/2.6_wp, rel=1e-14_wp)
    call check_close(suite, "bulk modulus E/(3(1-2nu))", bulk, youngs/1.2_wp, rel=1e-14_wp)
    lambda = bulk - 2.0_wp*shear/3.0_wp
    do lane = 1, block_size
      strain(lane, :) = 1.0e-4_wp*[1.0_wp, -0.3_wp, 0.2_wp, 0.5_wp, -0.7_wp, 0.25_wp]*lane
    end do
    stress = 1.0_wp
    call update_material_block(material, 3, 1.0e-6_wp, strain, stress, history, wave)
    do lane = 1, 3
      expected(1:3) = 1.0_wp + lambda*sum(strain(lane, 1:3)) + 2.0_wp*shear*strain(lane, 1:3)
      expected(4:6) = 1.0_wp + 2.0_wp*shear*strain(lane, 4:6)
      call check_close(suite, "elastic: lambda tr(de) I + 2 mu de (tensor shear)", stress(lane, :), expected, &
                       rel=1e-14_wp)
    end do
    call check(suite, "elastic: lanes beyond nel untouched", all(stress(4:, :) == 1.0_wp))
    call check_close(suite, "elastic: wave modulus K + 4G/3", wave(1), bulk + 4.0_wp*shear/3.0_wp, rel=1e-14_wp)
    call check(suite, "elastic: no history", material_history_count(material) == 0)
  end subroutine test_elastic_increment

  subroutine test_history_layout()
    type(material_t) :: material
    real(wp) :: history(block_size, 7), plastic_strain(block_size)
    material = steel(1.0_wp)
    call check(suite, "plastic kinematic: 7 history variables", material_history_count(material) == 7)
    history = 5.0_wp
    call initialize_material_history(material, block_size, history)
    call check(suite, "plastic kinematic: history starts at zero", all(history == 0.0_wp))
    history(:, 1) = 0.125_wp
    call material_plastic_strain(law_plastic_kinematic, 4, history, plastic_strain)
    call check_close(suite, "plastic strain read from the history", plastic_strain(1:4), [0.125_wp, 0.125_wp, 0.125_wp, 0.125_wp], &
                     thr=0.0_wp)
    call material_plastic_strain(law_elastic, 4, history, plastic_strain)
    call check_close(suite, "plastic strain of an elastic law is zero", plastic_strain(1:4), [0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp], &
                     thr=0.0_wp)
    call check_close(suite, "hardening modulus E Et/(E - Et)", plastic_hardening_modulus(material), &
                     youngs*tangent/(youngs - tangent), rel=1e-15_wp)
  end subroutine test_history_layout

  !> One strain increment in uniaxial stress: the axial increment is given, the two lateral
  !> increments (equal) are found so that the lateral stress vanishes (secant iteration on the
  !> piecewise linear response, restarting from the saved state each time).
  subroutine uniaxial_step(material, time_step, axial_increment, stress, history)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: time_step, axial_increment
    real(wp), intent(inout) :: stress(block_size, 6), history(block_size, 7)
    real(wp) :: lateral(2), residual(2), next
    integer :: iteration
    lateral = [0.0_wp, -poisson*axial_increment]
    do iteration = 1, 2
      residual(iteration) = lateral_stress(material, time_step, axial_increment, lateral(iteration), stress, history)
    end do
    do iteration = 1, 60
      if (abs(residual(2)) <= 1.0e-13_wp*yield .or. residual(2) == residual(1)) exit
      next = lateral(2) - residual(2)*(lateral(2) - lateral(1))/(residual(2) - residual(1))
      lateral = [lateral(2), next]
      residual = [residual(2), lateral_stress(material, time_step, axial_increment, next, stress, history)]
    end do
    call uniaxial_trial(material, time_step, axial_increment, lateral(2), stress, history)
  end subroutine uniaxial_step

  !> Lateral stress after a trial increment from the given state (the state is not changed).
  function lateral_stress(material, time_step, axial_increment, lateral_increment, stress, history) result(value)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: time_step, axial_increment, lateral_increment
    real(wp), intent(in) :: stress(block_size, 6), history(block_size, 7)
    real(wp) :: value
    real(wp) :: trial_stress(block_size, 6), trial_history(block_size, 7)
    trial_stress = stress
    trial_history = history
    call uniaxial_trial(material, time_step, axial_increment, lateral_increment, trial_stress, trial_history)
    value = trial_stress(1, 2)
  end function lateral_stress

  subroutine uniaxial_trial(material, time_step, axial_increment, lateral_increment, stress, history)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: time_step, axial_increment, lateral_increment
    real(wp), intent(inout) :: stress(block_size, 6), history(block_size, 7)
    real(wp) :: strain(block_size, 6), wave(block_size)
    strain = 0.0_wp
    strain(1, 1:3) = [axial_increment, lateral_increment, lateral_increment]
    call update_material_block(material, 1, time_step, strain, stress, history, wave)
  end subroutine uniaxial_trial

  !> Drive a uniaxial-stress path through `targets` (axial strains) in `steps` increments per
  !> leg and compare with the piecewise linear `expected_stress` at every increment.
  subroutine test_uniaxial_isotropic()
    type(material_t) :: material
    real(wp) :: stress(block_size, 6), history(block_size, 7)
    real(wp) :: strain, increment, expected(steps), actual(steps), peak, yield_strain, reverse_yield
    integer :: step
    material = steel(1.0_wp)
    stress = 0.0_wp
    history = 0.0_wp
    yield_strain = yield/youngs
    strain = 0.0_wp
    ! loading to 10 yield strains
    increment = 10.0_wp*yield_strain/steps
    do step = 1, steps
      call uniaxial_step(material, 1.0e-6_wp, increment, stress, history)
      strain = strain + increment
      expected(step) = merge(youngs*strain, yield + tangent*(strain - yield_strain), strain <= yield_strain)
      actual(step) = stress(1, 1)
    end do
    call check_close(suite, "isotropic: loading curve bilinear (E, Etan)", actual, expected, rel=1e-6_wp, thr=1e-6_wp*yield)
    peak = stress(1, 1)
    call check_close(suite, "isotropic: peak stress", peak, yield + tangent*9.0_wp*yield_strain, rel=1e-6_wp)
    call check_close(suite, "isotropic: effective plastic strain eps - sigma/E at the peak", history(1, 1), &
                     strain - peak/youngs, rel=1e-6_wp)
    call check_close(suite, "isotropic: lateral stress zero", stress(1, 2), 0.0_wp, thr=1e-9_wp*yield)
    ! reverse loading to -10 yield strains: elastic down to -peak, then hardening with Etan
    reverse_yield = strain - 2.0_wp*peak/youngs
    increment = -20.0_wp*yield_strain/steps
    do step = 1, steps
      call uniaxial_step(material, 1.0e-6_wp, increment, stress, history)
      strain = strain + increment
      expected(step) = merge(peak - youngs*(10.0_wp*yield_strain - strain), -peak - tangent*(reverse_yield - strain), &
                       strain >= reverse_yield)
      actual(step) = stress(1, 1)
    end do
    call check_close(suite, "isotropic: reverse path (yield at -peak)", actual, expected, rel=1e-6_wp, thr=1e-6_wp*yield)
  end subroutine test_uniaxial_isotropic

  subroutine test_uniaxial_kinematic()
    type(material_t) :: material
    real(wp) :: stress(block_size, 6), history(block_size, 7)
    real(wp) :: strain, increment, expected(steps), actual(steps), peak, yield_strain, reverse_yield, peak_strain
    integer :: step
    material = steel(0.0_wp)
    stress = 0.0_wp
    history = 0.0_wp
    yield_strain = yield/youngs
    strain = 0.0_wp
    increment = 10.0_wp*yield_strain/steps
    do step = 1, steps
      call uniaxial_step(material, 1.0e-6_wp, increment, stress, history)
      strain = strain + increment
      expected(step) = merge(youngs*strain, yield + tangent*(strain - yield_strain), strain <= yield_strain)
      actual(step) = stress(1, 1)
    end do
    call check_close(suite, "kinematic: loading curve bilinear (E, Etan)", actual, expected, rel=1e-6_wp, thr=1e-6_wp*yield)
    peak = stress(1, 1)
    peak_strain = strain
    ! back stress after uniaxial loading: alpha_xx = (2/3)(sigma - SIGY), deviatoric
    call check_close(suite, "kinematic: back stress alpha_xx = 2/3 (peak - SIGY)", history(1, 2), &
                     2.0_wp/3.0_wp*(peak - yield), rel=1e-6_wp)
    call check_close(suite, "kinematic: back stress deviatoric", sum(history(1, 2:4)), 0.0_wp, thr=1e-9_wp*yield)
    ! reverse: yield again at peak - 2 SIGY
    reverse_yield = peak_strain - 2.0_wp*yield/youngs
    increment = -20.0_wp*yield_strain/steps
    do step = 1, steps
      call uniaxial_step(material, 1.0e-6_wp, increment, stress, history)
      strain = strain + increment
      expected(step) = merge(peak - youngs*(peak_strain - strain), peak - 2.0_wp*yield - tangent*(reverse_yield - strain), &
                       strain >= reverse_yield)
      actual(step) = stress(1, 1)
    end do
    call check_close(suite, "kinematic: reverse path (yield at peak - 2 SIGY)", actual, expected, rel=1e-6_wp, thr=1e-6_wp*yield)
  end subroutine test_uniaxial_kinematic

  !> Isochoric extension de = a dt diag(1, -1/2, -1/2): the effective total strain rate
  !> sqrt(2/3 D':D') is exactly a, so k = 1 + (a/C)^(1/P) and, once plastic, the effective
  !> stress of s - alpha equals k (SIGY + beta E_p eps_p).
  subroutine test_cowper_symonds_scaled_yield()
    type(material_t) :: material
    real(wp) :: stress(block_size, 6), history(block_size, 7), strain(block_size, 6), wave(block_size)
    real(wp) :: relative(6), effective, factor, rate, time_step, hardening
    integer :: step, lane
    real(wp), parameter :: betas(3) = [1.0_wp, 0.5_wp, 0.0_wp]
    rate = 100.0_wp
    time_step = 1.0e-5_wp
    do lane = 1, 3
      material = steel(betas(lane))
      material%rate_c = 40.0_wp
      material%rate_p = 5.0_wp
      hardening = plastic_hardening_modulus(material)
      factor = 1.0_wp + (rate/material%rate_c)**(1.0_wp/material%rate_p)
      stress = 0.0_wp
      history = 0.0_wp
      strain = 0.0_wp
      strain(1, 1:3) = rate*time_step*[1.0_wp, -0.5_wp, -0.5_wp]
      do step = 1, 20
        call update_material_block(material, 1, time_step, strain, stress, history, wave)
      end do
      relative = stress(1, :) - history(1, 2:7)
      relative(1:3) = relative(1:3) - sum(stress(1, 1:3))/3.0_wp
      effective = sqrt(1.5_wp*sum(relative(1:3)**2) + 3.0_wp*sum(relative(4:6)**2))
      call check(suite, "Cowper-Symonds: path is plastic", history(1, 1) > 1.0e-3_wp)
      call check_close(suite, "Cowper-Symonds (VP=0): sbar = [1 + (rate/C)^(1/P)] (SIGY + beta Ep eps_p)", &
                       effective, factor*(yield + betas(lane)*hardening*history(1, 1)), rel=1e-12_wp)
    end do
    ! without SRC/SRP the same path yields at the static stress
    material = steel(1.0_wp)
    stress = 0.0_wp
    history = 0.0_wp
    do step = 1, 20
      call update_material_block(material, 1, time_step, strain, stress, history, wave)
    end do
    relative = stress(1, :)
    relative(1:3) = relative(1:3) - sum(stress(1, 1:3))/3.0_wp
    effective = sqrt(1.5_wp*sum(relative(1:3)**2) + 3.0_wp*sum(relative(4:6)**2))
    call check_close(suite, "no rate parameters: static yield", effective, &
                     yield + plastic_hardening_modulus(material)*history(1, 1), rel=1e-12_wp)
  end subroutine test_cowper_symonds_scaled_yield

  !> VP = 1: the plastic increment d of a step satisfies
  !> sbar = [1 + (d/(dt C))^(1/P)] (SIGY + beta E_p eps_p).
  subroutine test_cowper_symonds_viscoplastic()
    type(material_t) :: material
    real(wp) :: stress(block_size, 6), history(block_size, 7), strain(block_size, 6), wave(block_size)
    real(wp) :: relative(6), effective, time_step, previous, increment
    integer :: step
    time_step = 1.0e-5_wp
    material = steel(1.0_wp)
    material%rate_c = 40.0_wp
    material%rate_p = 5.0_wp
    material%rate_formulation = 1.0_wp
    stress = 0.0_wp
    history = 0.0_wp
    strain = 0.0_wp
    strain(1, 1:3) = 100.0_wp*time_step*[1.0_wp, -0.5_wp, -0.5_wp]
    previous = 0.0_wp
    do step = 1, 20
      previous = history(1, 1)
      call update_material_block(material, 1, time_step, strain, stress, history, wave)
    end do
    increment = history(1, 1) - previous
    relative = stress(1, :)
    relative(1:3) = relative(1:3) - sum(stress(1, 1:3))/3.0_wp
    effective = sqrt(1.5_wp*sum(relative(1:3)**2) + 3.0_wp*sum(relative(4:6)**2))
    call check(suite, "viscoplastic: path is plastic", increment > 0.0_wp)
    call check_close(suite, "viscoplastic (VP=1): consistency with the plastic strain rate", effective, &
                     (1.0_wp + (increment/(time_step*material%rate_c))**(1.0_wp/material%rate_p)) &
                     *(yield + plastic_hardening_modulus(material)*history(1, 1)), rel=1e-10_wp)
    call check(suite, "viscoplastic: overstress above the static yield", &
               effective > yield + plastic_hardening_modulus(material)*history(1, 1))
  end subroutine test_cowper_symonds_viscoplastic

  !> A spin increment with axial vector (0, 0, 2 tan(45 deg)) is an exact quarter turn about z:
  !> the back stress components xx and yy swap, xy changes sign, yz' = zx and zx' = -yz.
  subroutine test_back_stress_rotation()
    type(material_t) :: material
    real(wp) :: spin(block_size, 3), rotation(block_size, 9), history(block_size, 7)
    material = steel(0.0_wp)
    spin = 0.0_wp
    spin(:, 3) = 2.0_wp
    call incremental_rotation(block_size, spin, rotation)
    history = 0.0_wp
    history(1, :) = [0.5_wp, 10.0_wp, 20.0_wp, -30.0_wp, 4.0_wp, 5.0_wp, 6.0_wp]
    call rotate_material_history(material, 1, rotation, history)
    call check_close(suite, "back stress rotates with the element (quarter turn about z)", history(1, :), &
                     [0.5_wp, 20.0_wp, 10.0_wp, -30.0_wp, -4.0_wp, 6.0_wp, -5.0_wp], thr=1e-13_wp)
  end subroutine test_back_stress_rotation
end program test_materials
