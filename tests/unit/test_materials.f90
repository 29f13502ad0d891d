!> Unit tests of the material laws through the block dispatch: *MAT_ELASTIC increments,
!> *MAT_PLASTIC_KINEMATIC uniaxial-stress paths (bilinear curve, isotropic and kinematic
!> reverse yield), Cowper-Symonds factors (VP = 0 and VP = 1), history rotation and layout;
!> *MAT_HONEYCOMB / *MAT_MODIFIED_HONEYCOMB single-point crush along each material axis (yield
!> curves, compaction, unloading modulus, uncoupled shear, rotating axes) and
!> *MAT_LOW_DENSITY_FOAM loading / hysteretic unloading; *MAT_PIECEWISE_LINEAR_PLASTICITY
!> uniaxial-stress paths on an LCSS curve and bilinear, Cowper-Symonds / LCSR factors (VP = 0)
!> and the viscoplastic consistency (VP = 1); *MAT_NULL carries no stress.
program test_materials
  use kinds, only: wp, block_size
  use model, only: material_t, piecewise_hardening_curve, piecewise_rate_curve
  use material_laws, only: law_elastic, law_plastic_kinematic, law_honeycomb, &
                           law_modified_honeycomb, law_low_density_foam, law_piecewise_linear, &
                           law_null, law_rigid, law_table, find_law, law_keyword_name, law_number_name, &
                           law_curve_field, no_plane_stress_kernel
  use material_plastic_kinematic, only: plastic_strain_slot, back_stress_first_slot
  use material_piecewise_linear, only: piecewise_plastic_strain_slot
  use material_low_density_foam, only: foam_left_cauchy_green_first_slot, foam_largest_compression_slot
  use material_honeycomb, only: honeycomb_strain_first_slot
  use plane_stress_dispatch, only: plane_stress_plastic_strain_slot, plane_stress_back_stress_first_slot
  use curves, only: curve_t, curve_value, smallest_magnitude_from
  use material_dispatch, only: material_wave_modulus
  use material_honeycomb, only: honeycomb_log_volume_slot, honeycomb_compacted_slot, honeycomb_axes_first_slot
  use material_dispatch, only: material_history_count, initialize_material_history, update_material_block, &
                               rotate_material_history, material_plastic_strain, elastic_moduli, &
                               plastic_hardening_modulus
  use objective_rotation, only: incremental_rotation
  use testing, only: test_suite_t, check, check_close, finish_suite
  use fixtures, only: piecewise_steel, make_curve
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
  call test_honeycomb_axes_crush()
  call test_honeycomb_026_expansion()
  call test_honeycomb_compaction_and_unloading()
  call test_honeycomb_shear_uncoupled()
  call test_modified_honeycomb_strain_abscissa()
  call test_honeycomb_axes_rotate()
  call test_foam_loading_unloading()
  call test_piecewise_uniaxial_curve()
  call test_piecewise_uniaxial_bilinear()
  call test_piecewise_rate_factors()
  call test_piecewise_viscoplastic()
  call test_null_no_stress()
  call test_curve_lower_bound()
  call test_law_table()
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
  !> Honeycomb with distinct yield curves per axis (plateaus 1.0, 0.5, 2.0 rising towards
  !> compaction; shear 0.3, 0.2, 0.1), compacted E = 1000, PR = 0.3, VF = 0.2, material axes
  !> a = (1, 1, 0)/sqrt 2, b = (-1, 1, 0)/sqrt 2, c = z (AOPT 2).
  function honeycomb(law) result(material)
    integer, intent(in) :: law
    type(material_t) :: material
    real(wp), parameter :: strain(4) = [0.0_wp, 0.3_wp, 0.7_wp, 1.0_wp]
    real(wp), parameter :: shape(4) = [1.0_wp, 1.1_wp, 1.5_wp, 3.0_wp]
    material%law = law
    material%density = 1.0e-10_wp
    material%youngs_modulus = 1000.0_wp
    material%poissons_ratio = 0.3_wp
    material%yield_stress = 1.0e6_wp
    material%compaction_volume = 0.2_wp
    material%viscosity = 0.0_wp
    material%uncompacted_moduli = [100.0_wp, 80.0_wp, 120.0_wp, 40.0_wp, 30.0_wp, 20.0_wp]
    material%axes_option = 2
    material%axis_a = [1.0_wp, 1.0_wp, 0.0_wp]
    material%axis_d = [-1.0_wp, 1.0_wp, 0.0_wp]
    material%curve_ids = [1, 2, 3, 4, 5, 6, 0]
    allocate (material%curves(7))
    material%curves(1) = make_curve(1, strain, 1.0_wp*shape)
    material%curves(2) = make_curve(2, strain, 0.5_wp*shape)
    material%curves(3) = make_curve(3, strain, 2.0_wp*shape)
    material%curves(4) = make_curve(4, strain, 0.3_wp*shape)
    material%curves(5) = make_curve(5, strain, 0.2_wp*shape)
    material%curves(6) = make_curve(6, strain, 0.1_wp*shape)
  end function honeycomb

  !> Global strain increment of the material-axis tensor `local` (aa bb cc ab bc ca, tensor shear).
  function global_increment(local) result(increment)
    real(wp), intent(in) :: local(6)
    real(wp) :: increment(6)
    real(wp) :: q(3, 3), m(3, 3)
    q(1, :) = [1.0_wp, 1.0_wp, 0.0_wp]/sqrt(2.0_wp)
    q(2, :) = [-1.0_wp, 1.0_wp, 0.0_wp]/sqrt(2.0_wp)
    q(3, :) = [0.0_wp, 0.0_wp, 1.0_wp]
    m = reshape([local(1), local(4), local(6), local(4), local(2), local(5), local(6), local(5), local(3)], [3, 3])
    m = matmul(transpose(q), matmul(m, q))
    increment = [m(1, 1), m(2, 2), m(3, 3), m(1, 2), m(2, 3), m(3, 1)]
  end function global_increment

  !> Stress in the material axes of the test honeycomb.
  function local_stress(stress) result(local)
    real(wp), intent(in) :: stress(:)
    real(wp) :: local(6)
    real(wp) :: q(3, 3), m(3, 3)
    q(1, :) = [1.0_wp, 1.0_wp, 0.0_wp]/sqrt(2.0_wp)
    q(2, :) = [-1.0_wp, 1.0_wp, 0.0_wp]/sqrt(2.0_wp)
    q(3, :) = [0.0_wp, 0.0_wp, 1.0_wp]
    m = reshape([stress(1), stress(4), stress(6), stress(4), stress(2), stress(5), stress(6), stress(5), stress(3)], &
                [3, 3])
    m = matmul(q, matmul(m, transpose(q)))
    local = [m(1, 1), m(2, 2), m(3, 3), m(1, 2), m(2, 3), m(3, 1)]
  end function local_stress

  !> One step of the test honeycomb with the material-axis increment `local`.
  subroutine honeycomb_step(material, local, stress, history)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: local(6)
    real(wp), intent(inout) :: stress(block_size, 6), history(block_size, 23)
    real(wp) :: increment(block_size, 6), wave(block_size)
    increment = 0.0_wp
    increment(1, :) = global_increment(local)
    call update_material_block(material, 1, 1.0e-6_wp, increment, stress, history, wave)
  end subroutine honeycomb_step

  !> Uniaxial-strain crush along a, b and c in turn: the crushed component follows that axis'
  !> curve at the volumetric strain 1 - V/V0 within 1%, the others stay zero.
  subroutine test_honeycomb_axes_crush()
    type(material_t) :: material
    real(wp) :: stress(block_size, 6), history(block_size, 23), local(6), increment(6), worst, expected
    real(wp) :: others
    integer :: axis, step
    character(len=1), parameter :: names(3) = ["a", "b", "c"]
    material = honeycomb(law_honeycomb)
    call check(suite, "honeycomb: 23 history variables", material_history_count(material) == 23)
    do axis = 1, 3
      stress = 0.0_wp
      call initialize_material_history(material, 1, history)
      increment = 0.0_wp
      increment(axis) = -1.0e-3_wp
      worst = 0.0_wp
      others = 0.0_wp
      do step = 1, 1000       ! to V/V0 = exp(-1) = 0.37 > VF
        call honeycomb_step(material, increment, stress, history)
        local = local_stress(stress(1, :))
        if (step >= 100) then
          expected = -curve_value(material%curves(axis), 1.0_wp - exp(history(1, honeycomb_log_volume_slot)))
          worst = max(worst, abs(local(axis)/expected - 1.0_wp))
        end if
        others = max(others, sum(abs(local)) - abs(local(axis)))
      end do
      call check(suite, "honeycomb 026: sigma_"//names(axis)//names(axis)//" follows its curve within 1%", &
                 worst < 0.01_wp, "worst relative difference "//real_image(worst))
      call check(suite, "honeycomb 026: crush along "//names(axis)//" leaves the other components zero", &
                 others < 1.0e-12_wp, "largest other "//real_image(others))
    end do
  end subroutine test_honeycomb_axes_crush

  !> Unloading before compaction with E_aa(V); past VF the compacted moduli (uniaxial strain:
  !> K + 4G/3 on the crushed axis, lambda on the others).
  !> *MAT_026 in expansion: the abscissa 1 - V/V0 is negative and the yield curve is extrapolated
  !> below its first point, to values under the curve's least from 0 (the honeycomb's shortcut
  !> for trial stresses below that least must not apply here).
  subroutine test_honeycomb_026_expansion()
    type(material_t) :: material
    real(wp) :: stress(block_size, 6), history(block_size, 23), local(6), increment(6), expected
    integer :: step
    material = honeycomb(law_honeycomb)
    stress = 0.0_wp
    call initialize_material_history(material, 1, history)
    increment = global_increment([1.0e-4_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp])
    do step = 1, 2000       ! to V/V0 = exp(0.2): abscissa -0.22, curve 1 extrapolated to 0.927
      call honeycomb_step(material, increment, stress, history)
    end do
    local = local_stress(stress(1, :))
    expected = curve_value(material%curves(1), 1.0_wp - exp(history(1, honeycomb_log_volume_slot)))
    call check(suite, "honeycomb 026: in expansion sigma_aa follows the extrapolated curve", &
               abs(local(1) - expected) < 1.0e-12_wp .and. expected < 0.95_wp, &
               "sigma_aa "//real_image(local(1))//", curve "//real_image(expected))
  end subroutine test_honeycomb_026_expansion

  subroutine test_honeycomb_compaction_and_unloading()
    type(material_t) :: material
    real(wp) :: stress(block_size, 6), history(block_size, 23), increment(6), before(6), after(6)
    real(wp) :: relative_volume, beta, bulk, shear, wave(block_size)
    integer :: step
    material = honeycomb(law_honeycomb)
    stress = 0.0_wp
    call initialize_material_history(material, 1, history)
    increment = [-1.0e-3_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp]
    do step = 1, 600
      call honeycomb_step(material, increment, stress, history)
    end do
    ! unload one step
    before = local_stress(stress(1, :))
    call honeycomb_step(material, -increment, stress, history)
    after = local_stress(stress(1, :))
    relative_volume = exp(history(1, honeycomb_log_volume_slot))
    beta = (1.0_wp - relative_volume)/(1.0_wp - 0.2_wp)
    call check_close(suite, "honeycomb: unloads with E_aa(V) = EAAU + beta (E - EAAU)", &
                     (after(1) - before(1))/1.0e-3_wp, 100.0_wp + beta*(1000.0_wp - 100.0_wp), rel=1e-9_wp)
    call check(suite, "honeycomb: not compacted at V/V0 = 0.55", history(1, honeycomb_compacted_slot) == 0.0_wp)
    ! crush on to past VF = 0.2 (ln 0.2 = -1.609)
    do step = 1, 1100
      call honeycomb_step(material, increment, stress, history)
    end do
    call check(suite, "honeycomb: compacted past VF", history(1, honeycomb_compacted_slot) == 1.0_wp)
    before = local_stress(stress(1, :))
    call honeycomb_step(material, increment, stress, history)
    after = local_stress(stress(1, :))
    call elastic_moduli(material, bulk, shear)
    call check_close(suite, "honeycomb compacted: d sigma_aa / d eps = K + 4G/3", &
                     (after(1) - before(1))/(-1.0e-3_wp), bulk + 4.0_wp*shear/3.0_wp, rel=1e-9_wp)
    call check_close(suite, "honeycomb compacted: d sigma_bb / d eps = lambda", &
                     (after(2) - before(2))/(-1.0e-3_wp), bulk - 2.0_wp*shear/3.0_wp, rel=1e-9_wp)
    call check_close(suite, "honeycomb compacted: unloads with K + 4G/3 too", &
                     compacted_unload_slope(material, stress, history), bulk + 4.0_wp*shear/3.0_wp, rel=1e-9_wp)
    call material_wave_modulus(material, 1, wave)
    call check_close(suite, "honeycomb: wave modulus of the compacted material", wave(1), &
                     bulk + 4.0_wp*shear/3.0_wp, rel=1e-14_wp)
  end subroutine test_honeycomb_compaction_and_unloading

  function compacted_unload_slope(material, stress, history) result(slope)
    type(material_t), intent(in) :: material
    real(wp), intent(inout) :: stress(block_size, 6), history(block_size, 23)
    real(wp) :: slope, before(6), after(6)
    before = local_stress(stress(1, :))
    call honeycomb_step(material, [1.0e-3_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp], stress, history)
    after = local_stress(stress(1, :))
    slope = (after(1) - before(1))/1.0e-3_wp
  end function compacted_unload_slope

  !> Pure shear in each material plane: elastic with 2 G_u up to its shear curve, then held
  !> there; no normal stress, the other shear components stay zero.
  subroutine test_honeycomb_shear_uncoupled()
    type(material_t) :: material
    real(wp) :: stress(block_size, 6), history(block_size, 23), increment(6), local(6), first(6)
    integer :: component, step
    character(len=2), parameter :: names(3) = ["ab", "bc", "ca"]
    real(wp), parameter :: shear_moduli(3) = [40.0_wp, 30.0_wp, 20.0_wp], limits(3) = [0.3_wp, 0.2_wp, 0.1_wp]
    material = honeycomb(law_honeycomb)
    do component = 4, 6
      stress = 0.0_wp
      call initialize_material_history(material, 1, history)
      increment = 0.0_wp
      increment(component) = 1.0e-4_wp
      call honeycomb_step(material, increment, stress, history)
      first = local_stress(stress(1, :))
      do step = 2, 400
        call honeycomb_step(material, increment, stress, history)
      end do
      local = local_stress(stress(1, :))
      call check_close(suite, "honeycomb shear "//names(component - 3)//": elastic with 2 G_u", &
                       first(component)/1.0e-4_wp, 2.0_wp*shear_moduli(component - 3), rel=1e-9_wp)
      call check_close(suite, "honeycomb shear "//names(component - 3)//": held at its curve", &
                       local(component), limits(component - 3), rel=1e-9_wp)
      call check(suite, "honeycomb shear "//names(component - 3)//": uncoupled", &
                 sum(abs(local)) - abs(local(component)) < 1.0e-12_wp)
    end do
  end subroutine test_honeycomb_shear_uncoupled

  !> *MAT_126 (LCA > 0): the curves are read at the component's own logarithmic strain.
  subroutine test_modified_honeycomb_strain_abscissa()
    type(material_t) :: material
    real(wp) :: stress(block_size, 6), history(block_size, 23), increment(6), local(6), worst, expected
    integer :: step
    material = honeycomb(law_modified_honeycomb)
    stress = 0.0_wp
    call initialize_material_history(material, 1, history)
    increment = [0.0_wp, 0.0_wp, -1.0e-3_wp, 0.0_wp, 0.0_wp, 0.0_wp]
    worst = 0.0_wp
    do step = 1, 900
      call honeycomb_step(material, increment, stress, history)
      local = local_stress(stress(1, :))
      if (step >= 100) then
        expected = -curve_value(material%curves(3), 1.0e-3_wp*step)
        worst = max(worst, abs(local(3)/expected - 1.0_wp))
      end if
    end do
    call check(suite, "honeycomb 126: sigma_cc follows LCC at |eps_cc| within 1%", worst < 0.01_wp, &
               "worst relative difference "//real_image(worst))
  end subroutine test_modified_honeycomb_strain_abscissa

  !> The material axes turn with the element: after a quarter turn about z, a = (-1, 1, 0)/sqrt 2.
  subroutine test_honeycomb_axes_rotate()
    type(material_t) :: material
    real(wp) :: history(block_size, 23), spin(block_size, 3), rotation(block_size, 9)
    material = honeycomb(law_honeycomb)
    call initialize_material_history(material, 1, history)
    spin = 0.0_wp
    spin(1, 3) = 2.0_wp*tan(acos(-1.0_wp)/4.0_wp)
    call incremental_rotation(1, spin, rotation)
    call rotate_material_history(material, 1, rotation, history)
    call check_close(suite, "honeycomb: axes a, b, c rotate with the element", &
                     history(1, honeycomb_axes_first_slot:honeycomb_axes_first_slot + 8), &
                     [-1.0_wp, 1.0_wp, 0.0_wp, -1.0_wp, -1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, sqrt(2.0_wp)]/sqrt(2.0_wp), &
                     thr=1e-14_wp)
  end subroutine test_honeycomb_axes_rotate

  !> Uniaxial-strain compression to 60% nominal strain and back: loading on the curve within
  !> 1%, unloading below it (HU = 0.2, SHAPE = 2), zero stress at zero strain.
  subroutine test_foam_loading_unloading()
    type(material_t) :: material
    real(wp) :: stress(block_size, 6), history(block_size, 7), increment(block_size, 6), wave(block_size)
    real(wp) :: loading(0:600), nominal, worst, below, largest_lateral
    integer :: step
    material%law = law_low_density_foam
    material%density = 1.0e-10_wp
    material%youngs_modulus = 1.0_wp
    material%hysteretic_unloading = 0.2_wp
    material%unloading_shape = 2.0_wp
    material%curve_ids = [1]
    allocate (material%curves(1))
    material%curves(1) = make_curve(1, [0.0_wp, 0.05_wp, 0.5_wp, 0.7_wp], [0.0_wp, 0.1_wp, 0.15_wp, 1.0_wp])
    call check(suite, "foam: 7 history variables", material_history_count(material) == 7)
    call initialize_material_history(material, 1, history)
    stress = 0.0_wp
    increment = 0.0_wp
    worst = 0.0_wp
    largest_lateral = 0.0_wp
    loading(0) = 0.0_wp
    do step = 1, 600
      nominal = -1.0e-3_wp*step
      increment(1, 1) = log((1.0_wp + nominal)/(1.0_wp - 1.0e-3_wp*(step - 1)))
      call update_material_block(material, 1, 1.0e-6_wp, increment, stress, history, wave)
      loading(step) = stress(1, 1)
      worst = max(worst, abs(stress(1, 1) + curve_value(material%curves(1), -nominal)) &
                  /curve_value(material%curves(1), -nominal))
      largest_lateral = max(largest_lateral, maxval(abs(stress(1, 2:6))))
    end do
    call check(suite, "foam: loading follows the curve within 1%", worst < 0.01_wp, &
               "worst relative difference "//real_image(worst))
    call check(suite, "foam: Poisson's ratio zero (no lateral stress)", largest_lateral < 1.0e-12_wp)
    below = huge(1.0_wp)
    do step = 599, 0, -1
      nominal = -1.0e-3_wp*step
      increment(1, 1) = log((1.0_wp + nominal)/(1.0_wp - 1.0e-3_wp*(step + 1)))
      call update_material_block(material, 1, 1.0e-6_wp, increment, stress, history, wave)
      if (step > 0 .and. step < 590) below = min(below, abs(loading(step)) - abs(stress(1, 1)))
    end do
    call check(suite, "foam: unloading lies below loading", below > 0.0_wp, "smallest gap "//real_image(below))
    call check_close(suite, "foam: unloading ends at zero stress", stress(1, 1), 0.0_wp, thr=1.0e-9_wp)
    call check_close(suite, "foam: wave modulus = steepest curve slope", wave(1), 0.85_wp/0.2_wp, rel=1e-12_wp)
  end subroutine test_foam_loading_unloading

  function real_image(value) result(text)
    real(wp), intent(in) :: value
    character(len=:), allocatable :: text
    character(len=24) :: buffer
    write (buffer, '(es12.4)') value
    text = trim(adjustl(buffer))
  end function real_image

  ! ---------------------------------------------------------------- *MAT_024, *MAT_NULL

  !> Static yield Y(eps_p) of a *MAT_024 material.
  function piecewise_yield(material, eps) result(value)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: eps
    real(wp) :: value
    if (allocated(material%curves(piecewise_hardening_curve)%abscissa)) then
      value = curve_value(material%curves(piecewise_hardening_curve), eps)
    else
      value = yield + plastic_hardening_modulus(material)*eps
    end if
  end function piecewise_yield

  !> Uniaxial stress at total strain `strain`: strain = Y(eps_p)/E + eps_p (bisection).
  function piecewise_uniaxial_stress(material, strain) result(stress)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: strain
    real(wp) :: stress, low, high, middle
    integer :: iteration
    if (youngs*strain <= piecewise_yield(material, 0.0_wp)) then
      stress = youngs*strain
      return
    end if
    low = 0.0_wp
    high = strain
    do iteration = 1, 200
      middle = 0.5_wp*(low + high)
      if (piecewise_yield(material, middle)/youngs + middle > strain) then
        high = middle
      else
        low = middle
      end if
    end do
    stress = piecewise_yield(material, 0.5_wp*(low + high))
  end function piecewise_uniaxial_stress

  !> Lateral stress sigma_yy after a trial increment (axial, lateral, lateral) of lane 1 from
  !> the given state (which is not changed).
  function piecewise_lateral_stress(material, axial, lateral, stress, history) result(value)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: axial, lateral, stress(block_size, 6), history(block_size, 1)
    real(wp) :: value
    real(wp) :: trial_stress(block_size, 6), trial_history(block_size, 1), strain(block_size, 6), wave(block_size)
    trial_stress = stress
    trial_history = history
    strain = 0.0_wp
    strain(1, 1:3) = [axial, lateral, lateral]
    call update_material_block(material, 1, 1.0e-6_wp, strain, trial_stress, trial_history, wave)
    value = trial_stress(1, 2)
  end function piecewise_lateral_stress

  !> Uniaxial stress path of a *MAT_024 solid point to `peak_strain`: the lateral increments
  !> (equal) are found by a secant iteration so that sigma_yy = sigma_zz = 0. Compares
  !> sigma_xx with the uniaxial curve at every step and the plastic strain at the end.
  subroutine check_piecewise_uniaxial(material, label, peak_strain)
    type(material_t), intent(in) :: material
    character(len=*), intent(in) :: label
    real(wp), intent(in) :: peak_strain
    real(wp) :: stress(block_size, 6), history(block_size, 1), strain(block_size, 6), wave(block_size)
    real(wp) :: actual(steps), expected(steps), total, axial, lateral(2), residual(2), next
    integer :: step, iteration
    call check(suite, label//": one history variable", material_history_count(material) == 1)
    history = 1.0_wp
    call initialize_material_history(material, block_size, history)
    stress = 0.0_wp
    total = 0.0_wp
    axial = peak_strain/steps
    do step = 1, steps
      lateral = [-poisson*axial, -0.5_wp*axial]
      residual = [piecewise_lateral_stress(material, axial, lateral(1), stress, history), &
                  piecewise_lateral_stress(material, axial, lateral(2), stress, history)]
      do iteration = 1, 60
        if (abs(residual(2)) <= 1.0e-12_wp*yield .or. residual(2) == residual(1)) exit
        next = lateral(2) - residual(2)*(lateral(2) - lateral(1))/(residual(2) - residual(1))
        lateral = [lateral(2), next]
        residual = [residual(2), piecewise_lateral_stress(material, axial, next, stress, history)]
      end do
      strain = 0.0_wp
      strain(1, 1:3) = [axial, lateral(2), lateral(2)]
      call update_material_block(material, 1, 1.0e-6_wp, strain, stress, history, wave)
      total = total + axial
      actual(step) = stress(1, 1)
      expected(step) = piecewise_uniaxial_stress(material, total)
    end do
    call check_close(suite, label//": uniaxial sigma_xx on the hardening curve (1% of SIGY)", actual, expected, &
                     thr=0.01_wp*yield)
    call check_close(suite, label//": uniaxial sigma_xx on the hardening curve (1e-9 of SIGY)", actual, expected, &
                     thr=1.0e-9_wp*yield)
    call check_close(suite, label//": plastic strain eps - sigma/E", history(1, 1), total - stress(1, 1)/youngs, &
                     rel=1e-9_wp)
    call check_close(suite, label//": lateral stress zero", stress(1, 2:3), [0.0_wp, 0.0_wp], thr=1e-9_wp*yield)
  end subroutine check_piecewise_uniaxial

  !> LCSS curve (250 at 0, 300 at 0.02, 340 at 0.05, 400 at 0.1, extrapolated beyond) on the
  !> uniaxial path to 12%; the plastic strain output reads the history.
  subroutine test_piecewise_uniaxial_curve()
    type(material_t) :: material
    real(wp) :: history(block_size, 1), plastic_strain(block_size)
    material = piecewise_steel(0.0_wp)
    material%curves(piecewise_hardening_curve) = make_curve(7, [0.0_wp, 0.02_wp, 0.05_wp, 0.1_wp], &
                                                            [250.0_wp, 300.0_wp, 340.0_wp, 400.0_wp])
    call check_piecewise_uniaxial(material, "MAT_024 LCSS curve", 0.12_wp)
    history = 0.0625_wp
    call material_plastic_strain(law_piecewise_linear, 2, history, plastic_strain)
    call check_close(suite, "MAT_024: plastic strain output from the history", plastic_strain(1:2), &
                     [0.0625_wp, 0.0625_wp], thr=0.0_wp)
  end subroutine test_piecewise_uniaxial_curve

  !> SIGY, ETAN without a curve: the bilinear curve with slopes E and ETAN.
  subroutine test_piecewise_uniaxial_bilinear()
    call check_piecewise_uniaxial(piecewise_steel(tangent), "MAT_024 bilinear SIGY/ETAN", 10.0_wp*yield/youngs)
    call check_piecewise_uniaxial(piecewise_steel(0.0_wp), "MAT_024 perfectly plastic", 10.0_wp*yield/youngs)
  end subroutine test_piecewise_uniaxial_bilinear

  !> Isochoric extension de = a dt diag(1, -1/2, -1/2): the effective strain rate is exactly a.
  !> Once plastic, sbar = k Y(eps_p) with k = 1 + (a/C)^(1/P) (C, P) or LCSR(a) (LCSR given,
  !> which overrides C and P). Three rates in three lanes of one block.
  subroutine test_piecewise_rate_factors()
    type(material_t) :: material
    real(wp) :: stress(block_size, 6), history(block_size, 1), strain(block_size, 6), wave(block_size)
    real(wp) :: rates(3), factor, effective, time_step
    integer :: step, lane, rate_case
    rates = [30.0_wp, 100.0_wp, 300.0_wp]
    time_step = 1.0e-5_wp
    do rate_case = 1, 2
      material = piecewise_steel(tangent)
      material%rate_c = 40.0_wp
      material%rate_p = 5.0_wp
      if (rate_case == 2) material%curves(piecewise_rate_curve) = make_curve(9, [0.0_wp, 100.0_wp, 1000.0_wp], &
                                                                             [1.0_wp, 1.2_wp, 1.5_wp])
      stress = 0.0_wp
      history = 0.0_wp
      strain = 0.0_wp
      do lane = 1, 3
        strain(lane, 1:3) = rates(lane)*time_step*[1.0_wp, -0.5_wp, -0.5_wp]
      end do
      do step = 1, 100
        call update_material_block(material, 3, time_step, strain, stress, history, wave)
      end do
      do lane = 1, 3
        if (rate_case == 1) then
          factor = 1.0_wp + (rates(lane)/material%rate_c)**(1.0_wp/material%rate_p)
        else
          factor = curve_value(material%curves(piecewise_rate_curve), rates(lane))
        end if
        effective = von_mises(stress, lane)
        call check(suite, "MAT_024 rate factor: path is plastic", history(lane, 1) > 1.0e-3_wp)
        call check_close(suite, "MAT_024 "//trim(merge("1 + (rate/C)^(1/P) (VP=0)", "LCSR(rate) over C, P     ", &
                         rate_case == 1))//": sbar / Y(eps_p)", effective/piecewise_yield(material, history(lane, 1)), &
                         factor, rel=1e-6_wp)
      end do
    end do
    call check_close(suite, "MAT_024: wave modulus K + 4G/3", wave(1), &
                     youngs*(1.0_wp - poisson)/((1.0_wp + poisson)*(1.0_wp - 2.0_wp*poisson)), rel=1e-14_wp)
  end subroutine test_piecewise_rate_factors

  !> VP = 1: the step's plastic increment d satisfies sbar = [1 + (d/(dt C))^(1/P)] Y(eps_p) on
  !> the LCSS curve, and sbar = LCSR(d/dt) Y(eps_p) with LCSR.
  subroutine test_piecewise_viscoplastic()
    type(material_t) :: material
    real(wp) :: stress(block_size, 6), history(block_size, 1), strain(block_size, 6), wave(block_size)
    real(wp) :: time_step, previous, increment, factor
    integer :: step, rate_case
    time_step = 1.0e-5_wp
    do rate_case = 1, 2
      material = piecewise_steel(0.0_wp)
      material%curves(piecewise_hardening_curve) = make_curve(7, [0.0_wp, 0.02_wp, 0.05_wp, 0.1_wp], &
                                                              [250.0_wp, 300.0_wp, 340.0_wp, 400.0_wp])
      material%rate_formulation = 1.0_wp
      material%rate_c = 40.0_wp
      material%rate_p = 5.0_wp
      if (rate_case == 2) material%curves(piecewise_rate_curve) = make_curve(9, [0.0_wp, 100.0_wp, 1000.0_wp], &
                                                                             [1.0_wp, 1.2_wp, 1.5_wp])
      stress = 0.0_wp
      history = 0.0_wp
      strain = 0.0_wp
      strain(1, 1:3) = 300.0_wp*time_step*[1.0_wp, -0.5_wp, -0.5_wp]
      strain(1, 4) = 100.0_wp*time_step
      previous = 0.0_wp
      do step = 1, 30
        previous = history(1, 1)
        call update_material_block(material, 1, time_step, strain, stress, history, wave)
      end do
      increment = history(1, 1) - previous
      if (rate_case == 1) then
        factor = 1.0_wp + (increment/(time_step*material%rate_c))**(1.0_wp/material%rate_p)
      else
        factor = curve_value(material%curves(piecewise_rate_curve), increment/time_step)
      end if
      call check(suite, "MAT_024 viscoplastic: path is plastic", increment > 0.0_wp)
      call check_close(suite, "MAT_024 viscoplastic (VP=1): sbar = k(d eps_p/dt) Y(eps_p), "// &
                       trim(merge("C, P", "LCSR", rate_case == 1)), von_mises(stress, 1), &
                       factor*piecewise_yield(material, history(1, 1)), rel=1e-10_wp)
    end do
  end subroutine test_piecewise_viscoplastic

  !> von Mises stress of lane `lane` of a block of stresses (xx, yy, zz, xy, yz, zx).
  pure function von_mises(stress, lane) result(value)
    real(wp), intent(in) :: stress(:, :)
    integer, intent(in) :: lane
    real(wp) :: value, deviator(3)
    deviator = stress(lane, 1:3) - sum(stress(lane, 1:3))/3.0_wp
    value = sqrt(1.5_wp*sum(deviator**2) + 3.0_wp*sum(stress(lane, 4:6)**2))
  end function von_mises

  !> *MAT_NULL through the solid dispatch: no stress, no history.
  subroutine test_null_no_stress()
    type(material_t) :: material
    real(wp) :: stress(block_size, 6), strain(block_size, 6), wave(block_size), history(block_size, 0)
    material%law = law_null
    material%youngs_modulus = youngs
    material%poissons_ratio = poisson
    stress = 3.0_wp
    strain = 1.0e-3_wp
    call update_material_block(material, 2, 1.0e-6_wp, strain, stress, history, wave)
    call check(suite, "MAT_NULL: no stress, no history", all(stress(1:2, :) == 0.0_wp) .and. &
               material_history_count(material) == 0)
  end subroutine test_null_no_stress

  !> The honeycomb skips yield-curve evaluations below the least |value| a curve can reach: that
  !> bound must never exceed the curve anywhere from its start on.
  subroutine test_curve_lower_bound()
    type(curve_t) :: rising, falling_end, crossing
    real(wp) :: x, lowest
    integer :: k
    rising = curve_t(id=1, abscissa=[0.0_wp, 1.0_wp, 2.0_wp, 3.0_wp], ordinate=[1.0_wp, 3.0_wp, 3.0_wp, 4.0_wp])
    falling_end = curve_t(id=2, abscissa=[0.0_wp, 1.0_wp, 2.0_wp], ordinate=[1.0_wp, 3.0_wp, 2.0_wp])
    crossing = curve_t(id=3, abscissa=[0.0_wp, 1.0_wp], ordinate=[-1.0_wp, 1.0_wp])
    call check_close(suite, "curve bound: rising curve from 0", smallest_magnitude_from(rising, 0.0_wp), 1.0_wp, 0.0_wp)
    call check_close(suite, "curve bound: rising curve from 1.5", smallest_magnitude_from(rising, 1.5_wp), 3.0_wp, &
                     0.0_wp)
    call check(suite, "curve bound: a curve falling beyond its last point has none", &
               smallest_magnitude_from(falling_end, 0.0_wp) == 0.0_wp)
    call check(suite, "curve bound: a curve through zero has none", smallest_magnitude_from(crossing, 0.0_wp) == 0.0_wp)
    ! the bound holds at every point of the rising curve, past its end too
    lowest = huge(1.0_wp)
    do k = 0, 1000
      x = 0.005_wp*k
      lowest = min(lowest, abs(curve_value(rising, x)))
    end do
    call check(suite, "curve bound: below every value of the curve", smallest_magnitude_from(rising, 0.0_wp) <= lowest)
  end subroutine test_curve_lower_bound
  !> The law table: codes unique, keyword names, curve fields, and the history counts matching
  !> the last slot of each kernel's layout.
  subroutine test_law_table()
    integer :: k
    logical :: unique
    unique = .true.
    do k = 1, size(law_table)
      if (count(law_table%code == law_table(k)%code) /= 1) unique = .false.
      if (find_law(law_table(k)%code) /= k) unique = .false.
    end do
    call check(suite, "law table: one row per code", unique .and. find_law(2) == 0)
    call check(suite, "law table: keyword names", law_keyword_name(find_law(law_elastic)) == "MAT_ELASTIC" &
               .and. law_number_name(find_law(law_elastic)) == "MAT_001" .and. &
               law_number_name(find_law(law_modified_honeycomb)) == "MAT_126" .and. &
               law_keyword_name(find_law(law_piecewise_linear)) == "MAT_PIECEWISE_LINEAR_PLASTICITY")
    call check(suite, "law table: curve fields", law_curve_field(find_law(law_honeycomb), 1) == "LCA" .and. &
               law_curve_field(find_law(law_honeycomb), 7) == "LCSR" .and. &
               law_curve_field(find_law(law_low_density_foam), 1) == "LCID" .and. &
               law_curve_field(find_law(law_piecewise_linear), 2) == "LCSR")
    associate (laws => law_table)
      call check(suite, "law table: history counts match the kernels' layouts", &
                 laws(find_law(law_plastic_kinematic))%history_count == back_stress_first_slot + 5 .and. &
                 plastic_strain_slot == 1 .and. &
                 laws(find_law(law_piecewise_linear))%history_count == piecewise_plastic_strain_slot .and. &
                 laws(find_law(law_low_density_foam))%history_count == foam_largest_compression_slot .and. &
                 foam_left_cauchy_green_first_slot + 5 < foam_largest_compression_slot .and. &
                 laws(find_law(law_honeycomb))%history_count == honeycomb_strain_first_slot + 5 .and. &
                 laws(find_law(law_modified_honeycomb))%history_count == honeycomb_strain_first_slot + 5 .and. &
                 laws(find_law(law_plastic_kinematic))%shell_history_count == &
                   plane_stress_back_stress_first_slot + 2 .and. &
                 laws(find_law(law_piecewise_linear))%shell_history_count == plane_stress_plastic_strain_slot)
      call check(suite, "law table: families", laws(find_law(law_null))%shells .and. &
                 .not. laws(find_law(law_null))%solids .and. .not. laws(find_law(law_honeycomb))%shells .and. &
                 laws(find_law(law_rigid))%shells .and. &
                 laws(find_law(law_rigid))%shell_history_count == no_plane_stress_kernel)
    end associate
  end subroutine test_law_table
end program test_materials
