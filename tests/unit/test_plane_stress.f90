!> Unit tests of the plane-stress (shell) material kernels through plane_stress_dispatch:
!> uniaxial stress (sigma_yy = 0 found by iteration on d eps_yy) along the hardening curve of
!> *MAT_PLASTIC_KINEMATIC (isotropic, kinematic with reverse yield), *MAT_024 with an LCSS
!> curve and with the EPS1-8 / ES1-8 table (both read from a deck); the returned stress on the
!> yield surface, the plastic thickness strain -(d eps^p_xx + d eps^p_yy) and normality along a
!> non-proportional path; equibiaxial and pure-shear yield; Cowper-Symonds and LCSR rate
!> factors (VP = 0 and VP = 1); the elastic and null laws; the history layout and the
!> unsupported-law contract.
program test_plane_stress
  use kinds, only: wp, block_size
  use curves, only: curve_t, curve_value
  use error_handling, only: error_t, error_list_t
  use model, only: model_t, material_t, piecewise_hardening_curve, piecewise_rate_curve
  use material_laws, only: law_elastic, law_plastic_kinematic, law_piecewise_linear, law_null, &
                           law_honeycomb
  use deck_reader, only: read_deck
  use plane_stress_dispatch, only: plane_stress_history_count, initialize_plane_stress_history, &
                                   update_plane_stress_block, plane_stress_plastic_strain
  use testing, only: test_suite_t, check, check_close, finish_suite
  use fixtures, only: piecewise_steel, make_curve
  implicit none

  type(test_suite_t) :: suite
  real(wp), parameter :: youngs = 210000.0_wp, poisson = 0.3_wp, yield = 250.0_wp, tangent = 2100.0_wp
  real(wp), parameter :: time_step = 1.0e-6_wp
  integer, parameter :: steps = 200

  suite%name = "plane stress"
  call test_history_layout()
  call test_elastic_and_null()
  call test_uniaxial_plastic_kinematic()
  call test_uniaxial_kinematic_reverse()
  call test_uniaxial_piecewise_curves()
  call test_non_proportional_path()
  call test_equibiaxial_yield()
  call test_pure_shear_yield()
  call test_rate_factors()
  call test_viscoplastic()
  call finish_suite(suite)

contains

  ! ---------------------------------------------------------------- materials

  function kinematic_steel(beta) result(material)
    real(wp), intent(in) :: beta
    type(material_t) :: material
    material%law = law_plastic_kinematic
    material%density = 7.85e-9_wp
    material%youngs_modulus = youngs
    material%poissons_ratio = poisson
    material%yield_stress = yield
    material%tangent_modulus = tangent
    material%hardening_beta = beta
  end function kinematic_steel

  !> Static yield stress of a material at effective plastic strain `eps`.
  function static_yield(material, eps) result(value)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: eps
    real(wp) :: value
    real(wp) :: modulus
    modulus = youngs*material%tangent_modulus/(youngs - material%tangent_modulus)
    if (material%law == law_piecewise_linear) then
      if (allocated(material%curves(piecewise_hardening_curve)%abscissa)) then
        value = curve_value(material%curves(piecewise_hardening_curve), eps)
        return
      end if
      value = yield + modulus*eps
    else
      value = yield + material%hardening_beta*modulus*eps
    end if
  end function static_yield

  !> Uniaxial stress-strain curve of a material with isotropic hardening: the stress at total
  !> axial strain `strain` from strain = Y(eps_p)/E + eps_p (bisection on eps_p).
  function uniaxial_curve_stress(material, strain) result(stress)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: strain
    real(wp) :: stress
    real(wp) :: low, high, middle
    integer :: iteration
    if (youngs*strain <= monotonic_yield(material, 0.0_wp)) then
      stress = youngs*strain
      return
    end if
    low = 0.0_wp
    high = strain
    do iteration = 1, 200
      middle = 0.5_wp*(low + high)
      if (monotonic_yield(material, middle)/youngs + middle > strain) then
        high = middle
      else
        low = middle
      end if
    end do
    stress = monotonic_yield(material, 0.5_wp*(low + high))
  end function uniaxial_curve_stress

  !> Axial stress of monotonic uniaxial loading at plastic strain `eps`: the static yield
  !> stress plus, for law 3, the kinematic part (back stress 2/3 (1 - BETA) E_p eps_p as a
  !> deviator, i.e. (1 - BETA) E_p eps_p axially): SIGY + E_p eps_p whatever BETA.
  function monotonic_yield(material, eps) result(value)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: eps
    real(wp) :: value
    value = static_yield(material, eps)
    if (material%law == law_plastic_kinematic) value = value + (1.0_wp - material%hardening_beta)* &
      youngs*material%tangent_modulus/(youngs - material%tangent_modulus)*eps
  end function monotonic_yield

  !> von Mises stress of the plane stress (xx, yy, xy) of lane `lane` minus the stored back
  !> stress (law 3).
  function effective_stress(material, stress, history, lane) result(value)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: stress(:, :), history(:, :)
    integer, intent(in) :: lane
    real(wp) :: value
    real(wp) :: relative(3)
    relative = stress(lane, :)
    if (material%law == law_plastic_kinematic) relative = relative - history(lane, 2:4)
    value = sqrt(relative(1)**2 + relative(2)**2 - relative(1)*relative(2) + 3.0_wp*relative(3)**2)
  end function effective_stress

  ! ---------------------------------------------------------------- drivers

  !> One step of lane 1 with the increment (dxx, dyy, dgamma).
  subroutine plane_step(material, dt, increment, stress, history, thickness)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: dt, increment(3)
    real(wp), intent(inout) :: stress(block_size, 3)
    real(wp), intent(inout), contiguous :: history(:, :)
    real(wp), intent(out) :: thickness
    real(wp) :: strain(block_size, 3), thickness_increment(block_size)
    strain = 0.0_wp
    strain(1, :) = increment
    call update_plane_stress_block(material, 1, dt, strain, stress, history, thickness_increment)
    thickness = thickness_increment(1)
  end subroutine plane_step

  !> One uniaxial-stress step: d eps_xx given, d eps_yy found (secant) so that sigma_yy = 0.
  !> Returns the d eps_yy used.
  subroutine uniaxial_step(material, dt, axial, stress, history, thickness, lateral)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: dt, axial
    real(wp), intent(inout) :: stress(block_size, 3)
    real(wp), intent(inout), contiguous :: history(:, :)
    real(wp), intent(out) :: thickness, lateral
    real(wp) :: guesses(2), residuals(2), next
    integer :: iteration
    guesses = [-poisson*axial, -0.5_wp*axial]
    do iteration = 1, 2
      residuals(iteration) = lateral_stress(material, dt, axial, guesses(iteration), stress, history)
    end do
    do iteration = 1, 60
      if (abs(residuals(2)) <= 1.0e-12_wp*yield .or. residuals(2) == residuals(1)) exit
      next = guesses(2) - residuals(2)*(guesses(2) - guesses(1))/(residuals(2) - residuals(1))
      guesses = [guesses(2), next]
      residuals = [residuals(2), lateral_stress(material, dt, axial, next, stress, history)]
    end do
    lateral = guesses(2)
    call plane_step(material, dt, [axial, lateral, 0.0_wp], stress, history, thickness)
  end subroutine uniaxial_step

  !> sigma_yy after a trial step from the given state (the state is not changed).
  function lateral_stress(material, dt, axial, trial_lateral, stress, history) result(value)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: dt, axial, trial_lateral
    real(wp), intent(in) :: stress(block_size, 3)
    real(wp), intent(in), contiguous :: history(:, :)
    real(wp) :: value
    real(wp) :: trial_stress(block_size, 3), trial_history(block_size, size(history, 2)), unused
    trial_stress = stress
    trial_history = history
    call plane_step(material, dt, [axial, trial_lateral, 0.0_wp], trial_stress, trial_history, unused)
    value = trial_stress(1, 2)
  end function lateral_stress

  !> Load in uniaxial stress to `peak_strain` in `steps` increments; compare sigma_xx with the
  !> uniaxial curve (strain = Y(eps_p)/E + eps_p) and check the yield surface, sigma_yy = 0,
  !> the thickness increment and the effective plastic strain at every step.
  subroutine check_uniaxial_loading(material, label, peak_strain)
    type(material_t), intent(in) :: material
    character(len=*), intent(in) :: label
    real(wp), intent(in) :: peak_strain
    real(wp) :: stress(block_size, 3), actual(steps), expected(steps), lateral_stresses(steps)
    real(wp), allocatable :: history(:, :)
    real(wp) :: strain, thickness, lateral, worst_surface, worst_thickness, worst_plastic
    integer :: step
    allocate (history(block_size, plane_stress_history_count(material)))
    call initialize_plane_stress_history(material, block_size, history)
    stress = 0.0_wp
    strain = 0.0_wp
    worst_surface = 0.0_wp
    worst_thickness = 0.0_wp
    worst_plastic = 0.0_wp
    do step = 1, steps
      call checked_step(material, [peak_strain/steps, 0.0_wp, 0.0_wp], .true., stress, history, &
                        worst_surface, worst_thickness, worst_plastic, thickness, lateral)
      strain = strain + peak_strain/steps
      actual(step) = stress(1, 1)
      lateral_stresses(step) = stress(1, 2)
      expected(step) = uniaxial_curve_stress(material, strain)
    end do
    call check_close(suite, label//": uniaxial sigma_xx on the hardening curve (1% of SIGY)", actual, expected, &
                     thr=0.01_wp*yield)
    call check_close(suite, label//": uniaxial sigma_xx on the hardening curve (1e-9 of SIGY)", actual, expected, &
                     thr=1.0e-9_wp*yield)
    call check_close(suite, label//": sigma_yy = 0", lateral_stresses, 0.0_wp*lateral_stresses, thr=1.0e-9_wp*yield)
    call check(suite, label//": path is plastic", history(1, 1) > 5.0_wp*yield/youngs)
    call check_close(suite, label//": returned stress on the yield surface (relative)", worst_surface, 0.0_wp, &
                     thr=1.0e-10_wp)
    call check_close(suite, label//": thickness increment = elastic - (d eps^p_xx + d eps^p_yy) (relative)", &
                     worst_thickness, 0.0_wp, thr=1.0e-10_wp)
    call check_close(suite, label//": d eps_p = sqrt(2/3 d eps^p : d eps^p) (relative)", worst_plastic, 0.0_wp, &
                     thr=1.0e-10_wp)
  end subroutine check_uniaxial_loading

  !> One step (uniaxial with `uniaxial`: increment(2) is found so that sigma_yy = 0), then the
  !> checks of the returned state, accumulated as worst relative errors:
  !> - yield surface: |sbar - k Y(eps_p)| / Y on plastic steps (k = 1: no rates here);
  !> - thickness: d eps_zz = -nu/E (d sigma_xx + d sigma_yy) - (d eps^p_xx + d eps^p_yy), with
  !>   d eps^p = d eps - C^-1 d sigma (plane-stress compliance);
  !> - d eps_p = sqrt(2/3 d eps^p : d eps^p) with d eps^p_zz = -(d eps^p_xx + d eps^p_yy).
  subroutine checked_step(material, increment, uniaxial, stress, history, worst_surface, worst_thickness, &
                          worst_plastic, thickness, lateral)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: increment(3)
    logical, intent(in) :: uniaxial
    real(wp), intent(inout) :: stress(block_size, 3)
    real(wp), intent(inout), contiguous :: history(:, :)
    real(wp), intent(inout) :: worst_surface, worst_thickness, worst_plastic
    real(wp), intent(out) :: thickness, lateral
    real(wp) :: old_stress(3), change(3), plastic(3), used(3), old_plastic, plastic_increment, expected
    real(wp) :: shear_modulus
    shear_modulus = youngs/(2.0_wp*(1.0_wp + poisson))
    old_stress = stress(1, :)
    old_plastic = history(1, 1)
    used = increment
    if (uniaxial) then
      call uniaxial_step(material, time_step, increment(1), stress, history, thickness, lateral)
      used(2) = lateral
    else
      call plane_step(material, time_step, increment, stress, history, thickness)
      lateral = increment(2)
    end if
    change = stress(1, :) - old_stress
    plastic(1) = used(1) - (change(1) - poisson*change(2))/youngs
    plastic(2) = used(2) - (change(2) - poisson*change(1))/youngs
    plastic(3) = used(3) - change(3)/shear_modulus
    plastic_increment = history(1, 1) - old_plastic
    expected = -poisson/youngs*(change(1) + change(2)) - (plastic(1) + plastic(2))
    worst_thickness = max(worst_thickness, abs(thickness - expected)/max(abs(used(1)), abs(used(2)), abs(used(3))))
    if (plastic_increment > 0.0_wp) then
      worst_surface = max(worst_surface, abs(effective_stress(material, stress, history, 1) &
                                             - static_yield(material, history(1, 1)))/yield)
      worst_plastic = max(worst_plastic, abs(plastic_increment - sqrt(2.0_wp/3.0_wp*(plastic(1)**2 + plastic(2)**2 &
        + (plastic(1) + plastic(2))**2 + 0.5_wp*plastic(3)**2)))/plastic_increment)
    end if
  end subroutine checked_step

  ! ---------------------------------------------------------------- tests

  subroutine test_history_layout()
    type(material_t) :: material
    real(wp) :: history(block_size, 4), plastic_strain(block_size)
    call check(suite, "history count: elastic 0", plane_stress_history_count(material_t(law=law_elastic)) == 0)
    call check(suite, "history count: null 0", plane_stress_history_count(material_t(law=law_null)) == 0)
    call check(suite, "history count: plastic kinematic 4 (eps_p, beta_xx, beta_yy, beta_xy)", &
               plane_stress_history_count(kinematic_steel(0.5_wp)) == 4)
    call check(suite, "history count: piecewise linear 1 (eps_p)", &
               plane_stress_history_count(piecewise_steel(tangent)) == 1)
    call check(suite, "history count: unsupported law (honeycomb) -1", &
               plane_stress_history_count(material_t(law=law_honeycomb)) == -1)
    material = kinematic_steel(0.5_wp)
    history = 7.0_wp
    call initialize_plane_stress_history(material, block_size, history)
    call check(suite, "virgin history is zero", all(history == 0.0_wp))
    history(1:3, 1) = [0.1_wp, 0.2_wp, 0.3_wp]
    call plane_stress_plastic_strain(material, 3, history, plastic_strain)
    call check_close(suite, "plastic strain from the history (law 3)", plastic_strain(1:3), &
                     [0.1_wp, 0.2_wp, 0.3_wp], thr=0.0_wp)
    call plane_stress_plastic_strain(piecewise_steel(tangent), 3, history(:, 1:1), plastic_strain)
    call check_close(suite, "plastic strain from the history (law 24)", plastic_strain(1:3), &
                     [0.1_wp, 0.2_wp, 0.3_wp], thr=0.0_wp)
    call plane_stress_plastic_strain(material_t(law=law_elastic), 3, history(:, 1:0), plastic_strain)
    call check_close(suite, "plastic strain of the elastic law is zero", plastic_strain(1:3), [0.0_wp, 0.0_wp, 0.0_wp], &
                     thr=0.0_wp)
  end subroutine test_history_layout

  !> Elastic: sigma += E/(1-nu^2) [[1, nu], [nu, 1]] de, tau += G dgamma, d eps_zz =
  !> -nu/(1-nu)(de_xx + de_yy), lane by lane. Null: no stress, no thickness change.
  subroutine test_elastic_and_null()
    type(material_t) :: material
    real(wp) :: strain(block_size, 3), stress(block_size, 3), thickness(block_size), history(block_size, 0)
    real(wp) :: stiffness, shear_modulus
    integer :: lane
    material%law = law_elastic
    material%youngs_modulus = youngs
    material%poissons_ratio = poisson
    stiffness = youngs/(1.0_wp - poisson**2)
    shear_modulus = youngs/(2.0_wp*(1.0_wp + poisson))
    do lane = 1, block_size
      strain(lane, :) = 1.0e-4_wp*lane*[1.0_wp, -0.4_wp, 0.7_wp]
    end do
    stress = 2.0_wp
    thickness = 5.0_wp
    call update_plane_stress_block(material, 3, time_step, strain, stress, history, thickness)
    do lane = 1, 3
      call check_close(suite, "elastic: plane-stress increment", stress(lane, :), 2.0_wp + [ &
        stiffness*(strain(lane, 1) + poisson*strain(lane, 2)), stiffness*(strain(lane, 2) + poisson*strain(lane, 1)), &
        shear_modulus*strain(lane, 3)], rel=1e-14_wp)
      call check_close(suite, "elastic: thickness -nu/(1-nu)(de_xx + de_yy)", thickness(lane), &
                       -poisson/(1.0_wp - poisson)*(strain(lane, 1) + strain(lane, 2)), rel=1e-14_wp)
    end do
    call check(suite, "elastic: lanes beyond nel untouched", all(stress(4:, :) == 2.0_wp))
    material%law = law_null
    stress = 2.0_wp
    call update_plane_stress_block(material, 3, time_step, strain, stress, history, thickness)
    call check(suite, "null: no stress, no thickness change", all(stress(1:3, :) == 0.0_wp) .and. &
               all(thickness(1:3) == 0.0_wp))
  end subroutine test_elastic_and_null

  subroutine test_uniaxial_plastic_kinematic()
    call check_uniaxial_loading(kinematic_steel(1.0_wp), "law 3 isotropic", 10.0_wp*yield/youngs)
    call check_uniaxial_loading(kinematic_steel(0.0_wp), "law 3 kinematic", 10.0_wp*yield/youngs)
    call check_uniaxial_loading(kinematic_steel(0.4_wp), "law 3 mixed", 10.0_wp*yield/youngs)
    call check_uniaxial_loading(piecewise_steel(tangent), "law 24 bilinear", 10.0_wp*yield/youngs)
  end subroutine test_uniaxial_plastic_kinematic

  !> Kinematic hardening (BETA = 0): after loading to the peak, reverse yield at peak - 2 SIGY,
  !> and the back stress beta_xx = peak - SIGY (its deviator alpha_xx = 2/3 (peak - SIGY)).
  subroutine test_uniaxial_kinematic_reverse()
    type(material_t) :: material
    real(wp) :: stress(block_size, 3), history(block_size, 4), actual(steps), expected(steps)
    real(wp) :: strain, increment, peak, peak_strain, reverse_yield, thickness, lateral
    integer :: step
    material = kinematic_steel(0.0_wp)
    stress = 0.0_wp
    history = 0.0_wp
    strain = 0.0_wp
    increment = 10.0_wp*yield/youngs/steps
    do step = 1, steps
      call uniaxial_step(material, time_step, increment, stress, history, thickness, lateral)
      strain = strain + increment
    end do
    peak = stress(1, 1)
    peak_strain = strain
    call check_close(suite, "law 3 kinematic: back stress beta_xx = peak - SIGY", history(1, 2), peak - yield, rel=1e-9_wp)
    call check_close(suite, "law 3 kinematic: back stress beta_yy, beta_xy = 0", history(1, 3:4), [0.0_wp, 0.0_wp], &
                     thr=1e-9_wp*yield)
    reverse_yield = peak_strain - 2.0_wp*yield/youngs
    increment = -20.0_wp*yield/youngs/steps
    do step = 1, steps
      call uniaxial_step(material, time_step, increment, stress, history, thickness, lateral)
      strain = strain + increment
      expected(step) = merge(peak - youngs*(peak_strain - strain), &
                             peak - 2.0_wp*yield - tangent*(reverse_yield - strain), strain >= reverse_yield)
      actual(step) = stress(1, 1)
    end do
    call check_close(suite, "law 3 kinematic: reverse yield at peak - 2 SIGY, then slope ETAN", actual, expected, &
                     thr=1e-9_wp*yield)
  end subroutine test_uniaxial_kinematic_reverse

  !> *MAT_024 read from a deck, with an LCSS curve and with the EPS / ES table (the same
  !> hardening in both), on the uniaxial path to 12% strain, past every point of the curve.
  subroutine test_uniaxial_piecewise_curves()
    type(model_t) :: model
    integer :: k
    call read_piecewise_deck(model)
    if (.not. allocated(model%materials)) return
    do k = 1, size(model%materials)
      if (model%materials(k)%law /= law_piecewise_linear) cycle
      select case (model%materials(k)%id)
      case (24)
        call check(suite, "deck: LCSS curve copied", model%materials(k)%curves(piecewise_hardening_curve)%id == 7)
        call check_uniaxial_loading(model%materials(k), "law 24 LCSS curve", 0.12_wp)
      case (25)
        call check(suite, "deck: EPS/ES table as a curve of 4 points", &
                   size(model%materials(k)%curves(piecewise_hardening_curve)%abscissa) == 4)
        call check_uniaxial_loading(model%materials(k), "law 24 EPS/ES table", 0.12_wp)
      end select
    end do
  end subroutine test_uniaxial_piecewise_curves

  !> A deck with *MAT_024 24 (LCSS 7) and *MAT_024 25 (EPS/ES), both with yield 250, 300 at
  !> 0.02, 340 at 0.05, 400 at 0.1 (linear extrapolation beyond).
  subroutine read_piecewise_deck(model)
    type(model_t), intent(out) :: model
    type(error_list_t) :: warnings
    type(error_t), allocatable :: error
    character(len=:), allocatable :: path
    integer :: unit, k
    character(len=80), parameter :: lines(*) = [character(len=80) :: &
      "*KEYWORD", "*CONTROL_TERMINATION", "1.0", "*NODE", &
      "1,0.0,0.0,0.0", "2,1.0,0.0,0.0", "3,1.0,1.0,0.0", "4,0.0,1.0,0.0", &
      "5,0.0,0.0,1.0", "6,1.0,0.0,1.0", "7,1.0,1.0,1.0", "8,0.0,1.0,1.0", &
      "*ELEMENT_SOLID", "1,1,1,2,3,4,5,6,7,8", "*PART", "cube", "1,1,24", "*SECTION_SOLID", "1,1", &
      "*MAT_PIECEWISE_LINEAR_PLASTICITY_TITLE", "curve", "24,7.85e-9,210000.0,0.3,250.0", "0.0,0.0,7,0,0.0", &
      "*MAT_024", "25,7.85e-9,210000.0,0.3,100.0,1000.0", "0.0,0.0,0,0,0.0", &
      "0.0,0.02,0.05,0.1", "250.0,300.0,340.0,400.0", &
      "*DEFINE_CURVE", "7", "0.0,250.0", "0.02,300.0", "0.05,340.0", "0.1,400.0", "*END"]
    path = "/tmp/crashfree_test_plane_stress.k"
    open (newunit=unit, file=path, status="replace", action="write")
    do k = 1, size(lines)
      write (unit, '(a)') trim(lines(k))
    end do
    close (unit)
    call read_deck(path, model, warnings, error, .false.)
    open (newunit=unit, file=path, status="old")
    close (unit, status="delete")
    if (allocated(error)) then
      call check(suite, "deck with *MAT_024 curve and table is accepted", .false., error%message)
    else
      call check(suite, "deck with *MAT_024 curve and table is accepted", size(model%materials) == 2)
    end if
  end subroutine read_piecewise_deck

  !> A non-proportional path (the strain increment turns through tension, shear and
  !> compression) with the LCSS-like hardening: every plastic step ends on the yield surface,
  !> with the thickness and normality relations, for laws 24 (curve) and 3 (mixed).
  subroutine test_non_proportional_path()
    type(material_t) :: material
    integer :: case_number
    do case_number = 1, 2
      if (case_number == 1) then
        material = piecewise_steel(0.0_wp)
        material%curves(piecewise_hardening_curve) = make_curve(7, [0.0_wp, 0.02_wp, 0.05_wp, 0.1_wp], &
                                                                [250.0_wp, 300.0_wp, 340.0_wp, 400.0_wp])
        call run_path(material, "law 24 curve, non-proportional")
      else
        call run_path(kinematic_steel(0.4_wp), "law 3 mixed, non-proportional")
      end if
    end do
  end subroutine test_non_proportional_path

  subroutine run_path(material, label)
    type(material_t), intent(in) :: material
    character(len=*), intent(in) :: label
    real(wp) :: stress(block_size, 3), increment(3), angle, worst_surface, worst_thickness, worst_plastic
    real(wp) :: thickness, lateral
    real(wp), allocatable :: history(:, :)
    integer :: step
    allocate (history(block_size, plane_stress_history_count(material)))
    call initialize_plane_stress_history(material, block_size, history)
    stress = 0.0_wp
    worst_surface = 0.0_wp
    worst_thickness = 0.0_wp
    worst_plastic = 0.0_wp
    do step = 1, 400
      angle = 0.02_wp*step
      increment = 2.0e-4_wp*[cos(angle), 0.5_wp*sin(1.7_wp*angle), 1.3_wp*sin(angle)]
      call checked_step(material, increment, .false., stress, history, worst_surface, worst_thickness, &
                        worst_plastic, thickness, lateral)
    end do
    call check(suite, label//": path is plastic", history(1, 1) > 0.02_wp)
    call check_close(suite, label//": every plastic step on the yield surface (relative)", worst_surface, 0.0_wp, &
                     thr=1.0e-10_wp)
    call check_close(suite, label//": thickness = elastic - (d eps^p_xx + d eps^p_yy) (relative)", worst_thickness, &
                     0.0_wp, thr=1.0e-10_wp)
    call check_close(suite, label//": d eps_p = sqrt(2/3 d eps^p : d eps^p) (relative)", worst_plastic, 0.0_wp, &
                     thr=1.0e-10_wp)
  end subroutine run_path

  !> Equibiaxial stretching d eps_xx = d eps_yy of a perfectly plastic *MAT_024 (ETAN = 0):
  !> sigma_xx = sigma_yy reaches SIGY and stays there; the plastic thickness strain is
  !> -2 d eps^p_xx, and d eps_p = |d eps^p_zz| (von Mises, equibiaxial).
  subroutine test_equibiaxial_yield()
    type(material_t) :: material
    real(wp) :: stress(block_size, 3), history(block_size, 1), thickness, plastic_thickness, increment
    real(wp) :: first_yield(2), last_plastic, yield_strain
    integer :: step
    logical :: found
    material = piecewise_steel(0.0_wp)
    stress = 0.0_wp
    history = 0.0_wp
    yield_strain = yield*(1.0_wp - poisson)/youngs    ! sigma = E/(1 - nu) eps in equibiaxial stress
    increment = 3.0_wp*yield_strain/steps
    found = .false.
    do step = 1, steps
      last_plastic = history(1, 1)
      call plane_step(material, time_step, [increment, increment, 0.0_wp], stress, history, thickness)
      if (.not. found .and. history(1, 1) > 0.0_wp) then
        first_yield = stress(1, 1:2)
        found = .true.
      end if
    end do
    call check(suite, "equibiaxial: yields", found)
    call check_close(suite, "equibiaxial: yields at sigma_xx = sigma_yy = SIGY", first_yield, [yield, yield], rel=1e-10_wp)
    call check_close(suite, "equibiaxial: stays at SIGY (perfect plasticity)", stress(1, 1:3), [yield, yield, 0.0_wp], &
                     thr=1e-10_wp*yield)
    ! last step fully plastic: d eps^p_xx = d eps^p_yy = increment (stress unchanged)
    plastic_thickness = thickness
    call check_close(suite, "equibiaxial: thickness increment -2 d eps^p_xx", plastic_thickness, &
                     -2.0_wp*increment, rel=1e-10_wp)
    call check_close(suite, "equibiaxial: d eps_p = 2 d eps^p_xx", history(1, 1) - last_plastic, 2.0_wp*increment, &
                     rel=1e-10_wp)
  end subroutine test_equibiaxial_yield

  !> Pure shear d gamma_xy of a perfectly plastic *MAT_024: tau reaches SIGY / sqrt(3), the
  !> plastic flow is pure shear (no thickness change).
  subroutine test_pure_shear_yield()
    type(material_t) :: material
    real(wp) :: stress(block_size, 3), history(block_size, 1), thickness, increment, shear_modulus
    integer :: step
    material = piecewise_steel(0.0_wp)
    shear_modulus = youngs/(2.0_wp*(1.0_wp + poisson))
    stress = 0.0_wp
    history = 0.0_wp
    increment = 3.0_wp*yield/sqrt(3.0_wp)/shear_modulus/steps
    do step = 1, steps
      call plane_step(material, time_step, [0.0_wp, 0.0_wp, increment], stress, history, thickness)
    end do
    call check(suite, "pure shear: yields", history(1, 1) > 0.0_wp)
    call check_close(suite, "pure shear: tau = SIGY / sqrt(3)", stress(1, 3), yield/sqrt(3.0_wp), rel=1e-10_wp)
    call check_close(suite, "pure shear: sigma_xx = sigma_yy = 0", stress(1, 1:2), [0.0_wp, 0.0_wp], thr=1e-10_wp*yield)
    call check_close(suite, "pure shear: no thickness change", thickness, 0.0_wp, thr=1e-16_wp)
    call check_close(suite, "pure shear: d eps_p = d gamma^p / sqrt(3)", history(1, 1), &
                     (steps*increment - yield/sqrt(3.0_wp)/shear_modulus)/sqrt(3.0_wp), rel=1e-10_wp)
  end subroutine test_pure_shear_yield

  !> The rate-dependent materials of the rate tests: 1 law 3 with C = 40, P = 5; 2 law 24 with
  !> the same C, P; 3 law 24 with LCSR (1 at rate 0, 1.2 at 100, 1.5 at 1000).
  function rate_material(law_case) result(material)
    integer, intent(in) :: law_case
    type(material_t) :: material
    select case (law_case)
    case (1)
      material = kinematic_steel(1.0_wp)
    case (2)
      material = piecewise_steel(tangent)
    case default
      material = piecewise_steel(tangent)
      material%curves(piecewise_rate_curve) = make_curve(9, [0.0_wp, 100.0_wp, 1000.0_wp], [1.0_wp, 1.2_wp, 1.5_wp])
    end select
    if (law_case /= 3) then
      material%rate_c = 40.0_wp
      material%rate_p = 5.0_wp
    end if
  end function rate_material

  !> VP = 0: d eps = rate dt (1, -1/2, 0) (so D_zz = -1/2 rate and the effective strain rate
  !> is exactly `rate`). Once plastic, sbar / Y(eps_p) = 1 + (rate/C)^(1/P) (laws 3 and 24) or
  !> LCSR(rate) (law 24). Lanes 1-3 run three rates in one block. dt = 0: no rate effect.
  subroutine test_rate_factors()
    type(material_t) :: material
    real(wp) :: stress(block_size, 3), history(block_size, 4), strain(block_size, 3), thickness(block_size)
    real(wp) :: rates(3), factor, expected
    integer :: step, lane, law_case
    rates = [30.0_wp, 100.0_wp, 300.0_wp]
    do law_case = 1, 3
      material = rate_material(law_case)
      stress = 0.0_wp
      history = 0.0_wp
      strain = 0.0_wp
      do lane = 1, 3
        strain(lane, :) = rates(lane)*1.0e-5_wp*[1.0_wp, -0.5_wp, 0.0_wp]
      end do
      do step = 1, 100
        call update_plane_stress_block(material, 3, 1.0e-5_wp, strain, stress, history, thickness)
      end do
      do lane = 1, 3
        if (law_case == 3) then
          factor = curve_value(material%curves(piecewise_rate_curve), rates(lane))
        else
          factor = 1.0_wp + (rates(lane)/material%rate_c)**(1.0_wp/material%rate_p)
        end if
        expected = effective_stress(material, stress, history, lane)/static_yield(material, history(lane, 1))
        call check(suite, "rate factor: path is plastic", history(lane, 1) > 1.0e-3_wp)
        call check_close(suite, trim(merge("LCSR(rate)               ", "1 + (rate/C)^(1/P) (VP=0)", law_case == 3))// &
                         ": sbar / Y(eps_p), law "//trim(merge("3 ", "24", law_case == 1)), expected, factor, rel=1e-6_wp)
      end do
    end do
    ! dt = 0: the same increments give the static yield stress
    material = piecewise_steel(tangent)
    material%rate_c = 40.0_wp
    material%rate_p = 5.0_wp
    stress = 0.0_wp
    history = 0.0_wp
    do step = 1, 20
      call update_plane_stress_block(material, 3, 0.0_wp, strain, stress, history, thickness)
    end do
    call check_close(suite, "dt = 0: no rate effect", effective_stress(material, stress, history, 1), &
                     static_yield(material, history(1, 1)), rel=1e-12_wp)
  end subroutine test_rate_factors

  !> VP = 1: the step's plastic increment d satisfies sbar = [1 + (d/(dt C))^(1/P)] Y(eps_p)
  !> (laws 3 and 24), or sbar = LCSR(d/dt) Y(eps_p) (law 24).
  subroutine test_viscoplastic()
    type(material_t) :: material
    real(wp) :: stress(block_size, 3), history(block_size, 4), strain(block_size, 3), thickness(block_size)
    real(wp) :: previous, increment, factor, dt
    integer :: step, law_case
    dt = 1.0e-5_wp
    do law_case = 1, 3
      material = rate_material(law_case)
      material%rate_formulation = 1.0_wp
      stress = 0.0_wp
      history = 0.0_wp
      strain = 0.0_wp
      strain(1, :) = 100.0_wp*dt*[1.0_wp, -0.5_wp, 0.3_wp]
      previous = 0.0_wp
      do step = 1, 20
        previous = history(1, 1)
        call update_plane_stress_block(material, 1, dt, strain, stress, history, thickness)
      end do
      increment = history(1, 1) - previous
      if (law_case == 3) then
        factor = curve_value(material%curves(piecewise_rate_curve), increment/dt)
      else
        factor = 1.0_wp + (increment/(dt*material%rate_c))**(1.0_wp/material%rate_p)
      end if
      call check(suite, "viscoplastic: path is plastic", increment > 0.0_wp)
      call check_close(suite, "viscoplastic (VP=1) law "//trim(merge("3 ", "24", law_case == 1))// &
                       ": sbar = k(d eps_p/dt) Y(eps_p)", effective_stress(material, stress, history, 1), &
                       factor*static_yield(material, history(1, 1)), rel=1e-10_wp)
      call check(suite, "viscoplastic: overstress above the static yield", &
                 effective_stress(material, stress, history, 1) > static_yield(material, history(1, 1)))
    end do
  end subroutine test_viscoplastic
end program test_plane_stress
