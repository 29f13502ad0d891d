!> Unit tests of the rubbers (*MAT_MOONEY-RIVLIN_RUBBER, *MAT_BLATZ-KO_RUBBER) and of
!> *MAT_VISCOELASTIC, driven through the material dispatch (solids) and the plane-stress dispatch
!> (shells) along stretch paths:
!> - uniaxial stress to stretch 2.0 and to 0.6 in compression (solid: the lateral stretch found
!>   by a secant iteration in the test so that the lateral stress vanishes; shell: the same on
!>   sigma_yy, sigma_zz = 0 by the law itself), equibiaxial to 2.0: nominal stress against the
!>   analytical curve (principal-stretch formulas evaluated directly, with the lateral stretch
!>   solved independently; the classical incompressible Mooney-Rivlin curves as PR -> 0.5;
!>   Blatz-Ko's exact lateral stretch lambda^-0.463), within 1%;
!> - the Mooney-Rivlin stress against the numerical derivative of its strain energy;
!> - objectivity: a rigid rotation in the middle of a loading path changes nothing but the
!>   orientation of the final stress;
!> - small-strain limits: E and nu from G = 2 (A + B) and PR, from G and 0.463;
!> - viscoelastic shear relaxation against the hereditary integral of G(t), solid and shell, and
!>   the shell's sigma_zz = 0.
program test_rubber
  use kinds, only: wp, block_size
  use model, only: material_t
  use material_laws, only: law_mooney_rivlin, law_blatz_ko, law_viscoelastic
  use material_dispatch, only: update_material_block, rotate_material_history, material_history_count, &
                               rubber_constants
  use plane_stress_dispatch, only: update_plane_stress_block, plane_stress_history_count, &
                                   rotate_plane_stress_history
  use material_rubber, only: rubber_cauchy_stress, rubber_plane_stress_update, rubber_mooney_rivlin, &
                             mooney_rivlin_constants, rubber_thickness_tolerance, &
                             mooney_rivlin_fit
  use testing, only: test_suite_t, check, check_close, finish_suite
  implicit none

  type(test_suite_t) :: suite
  real(wp), parameter :: mooney_a = 0.4_wp, mooney_b = 0.1_wp   ! MPa (G = 1 MPa)
  real(wp), parameter :: blatz_shear = 1.0_wp, blatz_ratio = 0.463_wp
  integer, parameter :: steps = 400

  suite%name = "rubber"
  call test_history_layout()
  call test_energy_derivative()
  call test_small_strain_limits()
  call test_solid_uniaxial(mooney_rivlin(0.49_wp), 2.0_wp, "Mooney-Rivlin solid uniaxial tension")
  call test_solid_uniaxial(mooney_rivlin(0.49_wp), 0.6_wp, "Mooney-Rivlin solid uniaxial compression")
  call test_solid_uniaxial(blatz_ko(), 2.0_wp, "Blatz-Ko solid uniaxial tension")
  call test_solid_uniaxial(blatz_ko(), 0.6_wp, "Blatz-Ko solid uniaxial compression")
  call test_solid_equibiaxial(mooney_rivlin(0.49_wp), "Mooney-Rivlin solid equibiaxial")
  call test_solid_equibiaxial(blatz_ko(), "Blatz-Ko solid equibiaxial")
  call test_incompressible_limit()
  call test_shell_uniaxial(mooney_rivlin(0.49_wp), 2.0_wp, "Mooney-Rivlin shell uniaxial tension")
  call test_shell_uniaxial(mooney_rivlin(0.49_wp), 0.6_wp, "Mooney-Rivlin shell uniaxial compression")
  call test_shell_uniaxial(blatz_ko(), 2.0_wp, "Blatz-Ko shell uniaxial tension")
  call test_shell_uniaxial(blatz_ko(), 0.6_wp, "Blatz-Ko shell uniaxial compression")
  call test_shell_equibiaxial(mooney_rivlin(0.49_wp), "Mooney-Rivlin shell equibiaxial")
  call test_shell_equibiaxial(blatz_ko(), "Blatz-Ko shell equibiaxial")
  call test_solid_objectivity(mooney_rivlin(0.49_wp), "Mooney-Rivlin")
  call test_solid_objectivity(blatz_ko(), "Blatz-Ko")
  call test_shell_objectivity(mooney_rivlin(0.49_wp), "Mooney-Rivlin")
  call test_viscoelastic_solid_relaxation()
  call test_viscoelastic_shell()
  call test_mooney_rivlin_fit()
  call finish_suite(suite)

contains

  function mooney_rivlin(poissons_ratio) result(material)
    real(wp), intent(in) :: poissons_ratio
    type(material_t) :: material
    material%law = law_mooney_rivlin
    material%density = 1.0e-9_wp
    material%mooney_rivlin_a = mooney_a
    material%mooney_rivlin_b = mooney_b
    material%poissons_ratio = poissons_ratio
    material%youngs_modulus = 4.0_wp*(mooney_a + mooney_b)*(1.0_wp + poissons_ratio)
  end function mooney_rivlin

  function blatz_ko() result(material)
    type(material_t) :: material
    material%law = law_blatz_ko
    material%density = 1.0e-9_wp
    material%poissons_ratio = blatz_ratio
    material%youngs_modulus = 2.0_wp*blatz_shear*(1.0_wp + blatz_ratio)
  end function blatz_ko

  !> Principal Cauchy stresses from principal stretches (the laws' formulas in principal form).
  function principal_stress(material, stretch) result(stress)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: stretch(3)
    real(wp) :: stress(3)
    real(wp) :: c(4), squared(3), first, third, volume, beta
    squared = stretch**2
    third = product(squared)
    volume = sqrt(third)
    if (material%law == law_mooney_rivlin) then
      c = mooney_rivlin_constants(mooney_a, mooney_b, material%poissons_ratio)
      first = sum(squared)
      stress = (2.0_wp/volume)*((c(1) + first*c(2))*squared - c(2)*squared**2 + &
               third*(-2.0_wp*c(3)/third**3 + 2.0_wp*c(4)*(third - 1.0_wp)))
    else
      beta = 1.0_wp/(1.0_wp - 2.0_wp*blatz_ratio)
      stress = (blatz_shear/volume)*(squared**2/volume - volume**(-beta)*squared)
    end if
  end function principal_stress

  !> Lateral stretch making principal stress k zero when the other stretches are given
  !> (`stretch(k)` is overwritten; bisection, independent of the laws' own solvers).
  function free_stretch(material, stretch, k, equal) result(value)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: stretch(3)
    integer, intent(in) :: k
    logical, intent(in) :: equal     ! the two lateral stretches are equal (uniaxial)
    real(wp) :: value
    real(wp) :: low, high, trial(3), stress(3)
    integer :: iteration
    low = 0.05_wp
    high = 5.0_wp
    do iteration = 1, 200
      value = 0.5_wp*(low + high)
      trial = stretch
      trial(k) = value
      if (equal) trial(3) = value
      stress = principal_stress(material, trial)
      if (stress(k) > 0.0_wp) then
        high = value
      else
        low = value
      end if
    end do
  end function free_stretch

  !> Strain increment that takes a stretch from `old` to `new` exactly with the mid-point update.
  pure real(wp) function increment(old, new)
    real(wp), intent(in) :: old, new
    increment = 2.0_wp*(new - old)/(new + old)
  end function increment

  subroutine solid_step(material, history, stress, strain)
    type(material_t), intent(in) :: material
    real(wp), intent(inout) :: history(block_size, 6), stress(block_size, 6)
    real(wp), intent(in) :: strain(6)
    real(wp) :: strain_increment(block_size, 6), wave_modulus(block_size)
    strain_increment = 0.0_wp
    strain_increment(1, :) = strain
    call update_material_block(material, 1, 1.0e-6_wp, strain_increment, stress, history, wave_modulus)
  end subroutine solid_step

  subroutine test_history_layout()
    call check(suite, "history: 6 per solid point, 4 per shell point (rubbers, viscoelastic)", &
      material_history_count(mooney_rivlin(0.49_wp)) == 6 .and. plane_stress_history_count(mooney_rivlin(0.49_wp)) == 4 &
      .and. material_history_count(blatz_ko()) == 6 .and. plane_stress_history_count(blatz_ko()) == 4)
  end subroutine test_history_layout

  !> sigma_i = lambda_i / J dW / d lambda_i for Mooney-Rivlin's W (central differences).
  subroutine test_energy_derivative()
    real(wp) :: stretch(3), stress(3), expected(3), h, plus(3), minus(3), b(3, 3), full(3, 3)
    integer :: k
    stretch = [1.7_wp, 0.8_wp, 0.9_wp]
    h = 1.0e-6_wp
    do k = 1, 3
      plus = stretch
      minus = stretch
      plus(k) = plus(k) + h
      minus(k) = minus(k) - h
      expected(k) = stretch(k)/product(stretch)*(energy(plus) - energy(minus))/(2.0_wp*h)
    end do
    stress = principal_stress(mooney_rivlin(0.49_wp), stretch)
    call check_close(suite, "Mooney-Rivlin: sigma_i = lambda_i / J dW/dlambda_i", stress, expected, rel=1.0e-6_wp)
    b = 0.0_wp
    do k = 1, 3
      b(k, k) = stretch(k)**2
    end do
    full = rubber_cauchy_stress(rubber_mooney_rivlin, rubber_constants(mooney_rivlin(0.49_wp)), b)
    call check_close(suite, "Mooney-Rivlin: tensor form = principal form", [full(1, 1), full(2, 2), full(3, 3)], &
                     stress, rel=1.0e-12_wp)
  end subroutine test_energy_derivative

  real(wp) function energy(stretch)
    real(wp), intent(in) :: stretch(3)
    real(wp) :: c(4), squared(3), third
    c = mooney_rivlin_constants(mooney_a, mooney_b, 0.49_wp)
    squared = stretch**2
    third = product(squared)
    energy = c(1)*(sum(squared) - 3.0_wp) + &
             c(2)*(squared(1)*squared(2) + squared(2)*squared(3) + squared(3)*squared(1) - 3.0_wp) + &
             c(3)*(1.0_wp/third**2 - 1.0_wp) + c(4)*(third - 1.0_wp)**2
  end function energy

  !> A stretch of 1e-7: E = sigma_xx / eps_xx and nu = -eps_yy / eps_xx from the lateral stretch.
  subroutine test_small_strain_limits()
    type(material_t) :: materials(3)
    real(wp) :: stretch, lateral, stress(3), youngs, ratio
    integer :: k
    character(len=16) :: names(3)
    materials = [mooney_rivlin(0.49_wp), mooney_rivlin(0.45_wp), blatz_ko()]
    names = [character(len=16) :: "MR PR 0.49", "MR PR 0.45", "Blatz-Ko"]
    stretch = 1.0_wp + 1.0e-7_wp
    do k = 1, 3
      lateral = free_stretch(materials(k), [stretch, 1.0_wp, 1.0_wp], 2, .true.)
      stress = principal_stress(materials(k), [stretch, lateral, lateral])
      youngs = stress(1)/1.0e-7_wp
      ratio = -(lateral - 1.0_wp)/1.0e-7_wp
      call check_close(suite, "small strain E = 2 G (1 + nu), "//trim(names(k)), youngs, &
                       materials(k)%youngs_modulus, rel=1.0e-5_wp)
      call check_close(suite, "small strain nu, "//trim(names(k)), ratio, materials(k)%poissons_ratio, rel=1.0e-5_wp)
    end do
  end subroutine test_small_strain_limits

  !> Uniaxial stress of a solid point to axial stretch `final`: the lateral stretch by a secant
  !> iteration on sigma_yy = 0 (sigma_zz = sigma_yy by symmetry); nominal stress P = sigma_xx
  !> lambda_y^2 against the analytical value along the whole path.
  subroutine test_solid_uniaxial(material, final, name)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: final
    character(len=*), intent(in) :: name
    real(wp) :: history(block_size, 6), stress(block_size, 6), trial_history(block_size, 6), trial_stress(block_size, 6)
    real(wp) :: axial, previous_axial, lateral, nominal, expected, worst, scale, guesses(2), residuals(2), next
    real(wp) :: expected_lateral
    integer :: step, iteration
    history = 0.0_wp
    stress = 0.0_wp
    axial = 1.0_wp
    lateral = 1.0_wp
    worst = 0.0_wp
    scale = material%youngs_modulus/(2.0_wp*(1.0_wp + material%poissons_ratio))
    do step = 1, steps
      previous_axial = axial
      axial = 1.0_wp + (final - 1.0_wp)*real(step, wp)/real(steps, wp)
      guesses = [lateral, lateral*(previous_axial/axial)**0.5_wp]
      do iteration = 1, 2
        call solid_lateral_trial(material, history, stress, previous_axial, axial, lateral, guesses(iteration), &
                                 trial_history, trial_stress, residuals(iteration))
      end do
      do iteration = 1, 40
        if (abs(residuals(2)) < 1.0e-12_wp*scale .or. residuals(2) == residuals(1)) exit
        next = guesses(2) - residuals(2)*(guesses(2) - guesses(1))/(residuals(2) - residuals(1))
        guesses(1) = guesses(2)
        residuals(1) = residuals(2)
        guesses(2) = next
        call solid_lateral_trial(material, history, stress, previous_axial, axial, lateral, guesses(2), &
                                 trial_history, trial_stress, residuals(2))
      end do
      call solid_lateral_trial(material, history, stress, previous_axial, axial, lateral, guesses(2), &
                                 trial_history, trial_stress, residuals(2))
      lateral = guesses(2)
      history = trial_history
      stress = trial_stress
      nominal = stress(1, 1)*lateral**2
      expected_lateral = free_stretch(material, [axial, 1.0_wp, 1.0_wp], 2, .true.)
      expected = expected_nominal(material, [axial, expected_lateral, expected_lateral])
      worst = max(worst, abs(nominal - expected)/max(abs(expected), 1.0e-3_wp*scale))
    end do
    write (*, '(a)') "  "//name//": worst relative error of the nominal stress "//real_text(worst)
    call check(suite, name//": nominal stress within 1% of the analytical curve", worst < 0.01_wp, &
               "worst relative error "//real_text(worst))
    call check(suite, name//": (and within 1e-6: the b update is exact for a stretch)", worst < 1.0e-6_wp, &
               "worst relative error "//real_text(worst))
    if (material%law == law_blatz_ko) call check_close(suite, name//": lateral stretch lambda^-0.463", lateral, &
                                                       axial**(-blatz_ratio), rel=1.0e-8_wp)
  end subroutine test_solid_uniaxial

  !> One trial step of the solid uniaxial path with lateral stretch `guess`: sigma_yy.
  subroutine solid_lateral_trial(material, history, stress, previous_axial, axial, lateral, guess, &
                                 trial_history, trial_stress, residual)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: history(block_size, 6), stress(block_size, 6), previous_axial, axial, lateral, guess
    real(wp), intent(out) :: trial_history(block_size, 6), trial_stress(block_size, 6), residual
    real(wp) :: strain(6)
    trial_history = history
    trial_stress = stress
    strain = [increment(previous_axial, axial), increment(lateral, guess), increment(lateral, guess), &
              0.0_wp, 0.0_wp, 0.0_wp]
    call solid_step(material, trial_history, trial_stress, strain)
    residual = trial_stress(1, 2)
  end subroutine solid_lateral_trial

  function expected_nominal(material, stretch) result(value)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: stretch(3)
    real(wp) :: value
    real(wp) :: stress(3)
    stress = principal_stress(material, stretch)
    value = stress(1)*stretch(2)*stretch(3)
  end function expected_nominal

  !> Equibiaxial stretch of a solid point to 2.0 (sigma_zz = 0 by the thickness stretch found in
  !> the test): nominal stress sigma_xx lambda lambda_z against the analytical value.
  subroutine test_solid_equibiaxial(material, name)
    type(material_t), intent(in) :: material
    character(len=*), intent(in) :: name
    real(wp) :: history(block_size, 6), stress(block_size, 6), stretch, previous, thickness, expected_thickness
    real(wp) :: worst, strain(6), expected
    integer :: step
    history = 0.0_wp
    stress = 0.0_wp
    stretch = 1.0_wp
    thickness = 1.0_wp
    worst = 0.0_wp
    do step = 1, steps
      previous = stretch
      stretch = 1.0_wp + real(step, wp)/real(steps, wp)
      ! the thickness stretch of the analytical solution drives the point: then sigma_zz = 0
      ! must come out of the law (checked) and sigma_xx must match
      expected_thickness = free_stretch(material, [stretch, stretch, 1.0_wp], 3, .false.)
      strain = [increment(previous, stretch), increment(previous, stretch), increment(thickness, expected_thickness), &
                0.0_wp, 0.0_wp, 0.0_wp]
      thickness = expected_thickness
      call solid_step(material, history, stress, strain)
      expected = expected_nominal(material, [stretch, stretch, thickness])
      worst = max(worst, abs(stress(1, 1)*stretch*thickness - expected)/abs(expected))
      worst = max(worst, abs(stress(1, 3))/abs(stress(1, 1)))
    end do
    write (*, '(a)') "  "//name//": worst relative error of the nominal stress "//real_text(worst)
    call check(suite, name//": nominal stress within 1% of the analytical curve, sigma_zz = 0", worst < 0.01_wp, &
               "worst relative error "//real_text(worst))
    call check(suite, name//": (and within 1e-6)", worst < 1.0e-6_wp, "worst relative error "//real_text(worst))
  end subroutine test_solid_equibiaxial

  !> PR -> 0.5: the classical incompressible Mooney-Rivlin curves, uniaxial
  !> P = 2 (lambda - lambda^-2) (A + B / lambda) and equibiaxial P = 2 (lambda - lambda^-5) (A + B lambda^2).
  subroutine test_incompressible_limit()
    type(material_t) :: material
    real(wp) :: stretch, lateral, worst_uniaxial, worst_biaxial, classical
    integer :: k
    material = mooney_rivlin(0.4995_wp)
    worst_uniaxial = 0.0_wp
    worst_biaxial = 0.0_wp
    do k = 1, 20
      stretch = 0.6_wp + 1.4_wp*real(k, wp)/20.0_wp
      if (abs(stretch - 1.0_wp) < 1.0e-9_wp) cycle
      lateral = free_stretch(material, [stretch, 1.0_wp, 1.0_wp], 2, .true.)
      classical = 2.0_wp*(stretch - stretch**(-2))*(mooney_a + mooney_b/stretch)
      worst_uniaxial = max(worst_uniaxial, abs(expected_nominal(material, [stretch, lateral, lateral]) - classical)/ &
                           abs(classical))
      lateral = free_stretch(material, [stretch, stretch, 1.0_wp], 3, .false.)
      classical = 2.0_wp*(stretch - stretch**(-5))*(mooney_a + mooney_b*stretch**2)
      worst_biaxial = max(worst_biaxial, abs(expected_nominal(material, [stretch, stretch, lateral]) - classical)/ &
                          abs(classical))
    end do
    write (*, '(a)') "  Mooney-Rivlin PR 0.4995 against the incompressible curves: uniaxial "// &
      real_text(worst_uniaxial)//", equibiaxial "//real_text(worst_biaxial)
    call check(suite, "Mooney-Rivlin PR 0.4995: uniaxial curve within 1% of the incompressible one", &
               worst_uniaxial < 0.01_wp, "worst relative error "//real_text(worst_uniaxial))
    call check(suite, "Mooney-Rivlin PR 0.4995: equibiaxial curve within 1% of the incompressible one", &
               worst_biaxial < 0.01_wp, "worst relative error "//real_text(worst_biaxial))
  end subroutine test_incompressible_limit

  !> Uniaxial stress of a shell point: d eps_yy by a secant iteration on sigma_yy = 0, sigma_zz = 0
  !> by the law (its thickness stretch against the analytical one).
  subroutine test_shell_uniaxial(material, final, name)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: final
    character(len=*), intent(in) :: name
    real(wp) :: history(block_size, 4), stress(block_size, 3), trial_history(block_size, 4), trial_stress(block_size, 3)
    real(wp) :: axial, previous_axial, lateral, thickness, expected, worst, worst_thickness, scale, guesses(2)
    real(wp) :: residuals(2), next, expected_lateral
    integer :: step, iteration, most_iterations, used
    history = 0.0_wp
    stress = 0.0_wp
    axial = 1.0_wp
    lateral = 1.0_wp
    worst = 0.0_wp
    worst_thickness = 0.0_wp
    most_iterations = 0
    scale = material%youngs_modulus/(2.0_wp*(1.0_wp + material%poissons_ratio))
    do step = 1, steps
      previous_axial = axial
      axial = 1.0_wp + (final - 1.0_wp)*real(step, wp)/real(steps, wp)
      guesses = [lateral, lateral*(previous_axial/axial)**0.5_wp]
      do iteration = 1, 2
        call shell_lateral_trial(material, history, stress, previous_axial, axial, lateral, guesses(iteration), &
                                 trial_history, trial_stress, residuals(iteration), used)
      end do
      do iteration = 1, 40
        if (abs(residuals(2)) < 1.0e-12_wp*scale .or. residuals(2) == residuals(1)) exit
        next = guesses(2) - residuals(2)*(guesses(2) - guesses(1))/(residuals(2) - residuals(1))
        guesses(1) = guesses(2)
        residuals(1) = residuals(2)
        guesses(2) = next
        call shell_lateral_trial(material, history, stress, previous_axial, axial, lateral, guesses(2), &
                                 trial_history, trial_stress, residuals(2), used)
      end do
      call shell_lateral_trial(material, history, stress, previous_axial, axial, lateral, guesses(2), &
                                 trial_history, trial_stress, residuals(2), used)
      most_iterations = max(most_iterations, used)
      lateral = guesses(2)
      history = trial_history
      stress = trial_stress
      thickness = sqrt(history(1, 4) + 1.0_wp)
      expected_lateral = free_stretch(material, [axial, 1.0_wp, 1.0_wp], 2, .true.)
      expected = expected_nominal(material, [axial, expected_lateral, expected_lateral])
      worst = max(worst, abs(stress(1, 1)*lateral*thickness - expected)/max(abs(expected), 1.0e-3_wp*scale))
      worst_thickness = max(worst_thickness, abs(thickness - expected_lateral))
    end do
    write (*, '(a)') "  "//name//": worst relative error of the nominal stress "//real_text(worst)
    call check(suite, name//": nominal stress within 1% of the analytical curve", worst < 0.01_wp, &
               "worst relative error "//real_text(worst))
    call check(suite, name//": (and within 1e-6)", worst < 1.0e-6_wp, "worst relative error "//real_text(worst))
    call check(suite, name//": thickness stretch = the lateral one (1e-8)", worst_thickness < 1.0e-8_wp, &
               "worst "//real_text(worst_thickness))
    if (material%law == law_mooney_rivlin) then
      call check(suite, name//": Newton iterations on sigma_zz = 0 per step <= 4", most_iterations <= 4, &
                 "most "//integer_text(most_iterations))
      write (*, '(a,i0,a,es8.1)') "  "//name//": at most ", most_iterations, &
        " Newton iterations per step for sigma_zz = 0, relative tolerance ", rubber_thickness_tolerance
    end if
  end subroutine test_shell_uniaxial

  !> One trial step of the shell uniaxial path with lateral stretch `guess`: sigma_yy and the
  !> law's iterations for sigma_zz = 0.
  subroutine shell_lateral_trial(material, history, stress, previous_axial, axial, lateral, guess, &
                                 trial_history, trial_stress, residual, iterations)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: history(block_size, 4), stress(block_size, 3), previous_axial, axial, lateral, guess
    real(wp), intent(out) :: trial_history(block_size, 4), trial_stress(block_size, 3), residual
    integer, intent(out) :: iterations
    real(wp) :: strain(block_size, 3), thickness_increment(block_size)
    trial_history = history
    trial_stress = stress
    strain = 0.0_wp
    strain(1, :) = [increment(previous_axial, axial), increment(lateral, guess), 0.0_wp]
    if (material%law == law_mooney_rivlin) then
      call rubber_plane_stress_update(1, rubber_mooney_rivlin, rubber_constants(material), strain, trial_stress, &
                                      trial_history, thickness_increment, iterations)
    else
      call update_plane_stress_block(material, 1, 1.0e-6_wp, strain, trial_stress, trial_history, &
                                     thickness_increment)
      iterations = 0
    end if
    residual = trial_stress(1, 2)
  end subroutine shell_lateral_trial

  !> Equibiaxial stretch of a shell point to 2.0: the law's thickness stretch and nominal stress.
  subroutine test_shell_equibiaxial(material, name)
    type(material_t), intent(in) :: material
    character(len=*), intent(in) :: name
    real(wp) :: history(block_size, 4), stress(block_size, 3), strain(block_size, 3), thickness_increment(block_size)
    real(wp) :: stretch, previous, thickness, expected_thickness, expected, worst, logarithmic
    integer :: step
    history = 0.0_wp
    stress = 0.0_wp
    stretch = 1.0_wp
    worst = 0.0_wp
    logarithmic = 0.0_wp
    do step = 1, steps
      previous = stretch
      stretch = 1.0_wp + real(step, wp)/real(steps, wp)
      strain = 0.0_wp
      strain(1, 1:2) = increment(previous, stretch)
      call update_plane_stress_block(material, 1, 1.0e-6_wp, strain, stress, history, thickness_increment)
      logarithmic = logarithmic + thickness_increment(1)
      thickness = sqrt(history(1, 4) + 1.0_wp)
      expected_thickness = free_stretch(material, [stretch, stretch, 1.0_wp], 3, .false.)
      expected = expected_nominal(material, [stretch, stretch, expected_thickness])
      worst = max(worst, abs(stress(1, 1)*stretch*thickness - expected)/abs(expected))
      worst = max(worst, abs(stress(1, 1) - stress(1, 2))/abs(stress(1, 1)))
    end do
    write (*, '(a)') "  "//name//": worst relative error of the nominal stress "//real_text(worst)
    call check(suite, name//": nominal stress within 1% of the analytical curve", worst < 0.01_wp, &
               "worst relative error "//real_text(worst))
    call check(suite, name//": (and within 1e-6)", worst < 1.0e-6_wp, "worst relative error "//real_text(worst))
    call check_close(suite, name//": thickness strain increments sum to ln(lambda_z)", logarithmic, log(thickness), &
                     rel=1.0e-10_wp)
  end subroutine test_shell_equibiaxial

  !> A general stretch-and-shear path; in the middle the point and its path turn rigidly by R:
  !> the final stress must be R sigma R^T of the path without the turn.
  subroutine test_solid_objectivity(material, name)
    type(material_t), intent(in) :: material
    character(len=*), intent(in) :: name
    real(wp) :: history(block_size, 6), stress(block_size, 6), turned_history(block_size, 6)
    real(wp) :: turned_stress(block_size, 6), rotation(block_size, 9), r(3, 3), strain(6), turned(6)
    real(wp) :: expected(3, 3)
    integer :: step
    r = rotation_matrix([0.3_wp, -0.5_wp, 0.8_wp], 1.1_wp)
    rotation = 0.0_wp
    rotation(1, :) = [r(1, 1), r(1, 2), r(1, 3), r(2, 1), r(2, 2), r(2, 3), r(3, 1), r(3, 2), r(3, 3)]
    history = 0.0_wp
    stress = 0.0_wp
    turned_history = 0.0_wp
    turned_stress = 0.0_wp
    strain = [3.0e-3_wp, -1.0e-3_wp, -1.2e-3_wp, 1.5e-3_wp, 0.5e-3_wp, -0.7e-3_wp]
    do step = 1, 200
      if (step == 101) then
        call rotate_material_history(material, 1, rotation, turned_history)
        turned = turned_stress(1, :)
        turned_stress(1, :) = packed(matmul(r, matmul(unpacked(turned), transpose(r))))
      end if
      call solid_step(material, history, stress, strain)
      if (step > 100) then
        turned = packed(matmul(r, matmul(unpacked(strain), transpose(r))))
      else
        turned = strain
      end if
      call solid_step(material, turned_history, turned_stress, turned)
    end do
    turned = stress(1, :)
    expected = matmul(r, matmul(unpacked(turned), transpose(r)))
    call check_close(suite, name//" solid: a rigid rotation mid-path changes nothing (1e-10)", turned_stress(1, :), &
                     packed(expected), thr=1.0e-10_wp*maxval(abs(stress(1, :))))
  end subroutine test_solid_objectivity

  !> The same in plane stress, with the in-plane turn of rotate_plane_stress_history.
  subroutine test_shell_objectivity(material, name)
    type(material_t), intent(in) :: material
    character(len=*), intent(in) :: name
    real(wp) :: history(block_size, 4), stress(block_size, 3), turned_history(block_size, 4)
    real(wp) :: turned_stress(block_size, 3), strain(block_size, 3), turned(block_size, 3), thickness(block_size)
    real(wp) :: c, s, expected(3), tensor(2, 2), r(2, 2)
    integer :: step
    c = cos(0.7_wp)
    s = sin(0.7_wp)
    r = reshape([c, s, -s, c], [2, 2])
    history = 0.0_wp
    stress = 0.0_wp
    turned_history = 0.0_wp
    turned_stress = 0.0_wp
    strain = 0.0_wp
    strain(1, :) = [3.0e-3_wp, -1.0e-3_wp, 2.0e-3_wp]
    do step = 1, 200
      if (step == 101) then
        call rotate_plane_stress_history(material%law, c, s, turned_history(1, :))
        tensor = reshape([turned_stress(1, 1), turned_stress(1, 3), turned_stress(1, 3), turned_stress(1, 2)], [2, 2])
        tensor = matmul(r, matmul(tensor, transpose(r)))
        turned_stress(1, :) = [tensor(1, 1), tensor(2, 2), tensor(1, 2)]
      end if
      call update_plane_stress_block(material, 1, 1.0e-6_wp, strain, stress, history, thickness)
      turned = strain
      if (step > 100) then
        tensor = reshape([strain(1, 1), 0.5_wp*strain(1, 3), 0.5_wp*strain(1, 3), strain(1, 2)], [2, 2])
        tensor = matmul(r, matmul(tensor, transpose(r)))
        turned(1, :) = [tensor(1, 1), tensor(2, 2), 2.0_wp*tensor(1, 2)]
      end if
      call update_plane_stress_block(material, 1, 1.0e-6_wp, turned, turned_stress, turned_history, thickness)
    end do
    tensor = reshape([stress(1, 1), stress(1, 3), stress(1, 3), stress(1, 2)], [2, 2])
    tensor = matmul(r, matmul(tensor, transpose(r)))
    expected = [tensor(1, 1), tensor(2, 2), tensor(1, 2)]
    call check_close(suite, name//" shell: an in-plane rigid rotation mid-path changes nothing (1e-10)", &
                     turned_stress(1, :), expected, thr=1.0e-10_wp*maxval(abs(stress(1, :))))
    call check_close(suite, name//" shell: and the thickness stretch", turned_history(1, 4), history(1, 4), &
                     thr=1.0e-12_wp)
  end subroutine test_shell_objectivity

  function viscoelastic() result(material)
    type(material_t) :: material
    real(wp), parameter :: bulk = 20.0_wp, short_term = 3.0_wp
    material%law = law_viscoelastic
    material%density = 1.0e-9_wp
    material%youngs_modulus = 9.0_wp*bulk*short_term/(3.0_wp*bulk + short_term)
    material%poissons_ratio = (3.0_wp*bulk - 2.0_wp*short_term)/(2.0_wp*(3.0_wp*bulk + short_term))
    material%long_term_shear_modulus = 1.0_wp
    material%decay_constant = 50.0_wp
  end function viscoelastic

  !> tau(t) = int_0^t G(t - s) gamma'(s) ds for a shear ramp at rate `rate` over [0, ramp], held after.
  pure real(wp) function hereditary_shear(rate, ramp, t)
    real(wp), intent(in) :: rate, ramp, t
    real(wp), parameter :: short_term = 3.0_wp, long_term = 1.0_wp, beta = 50.0_wp
    real(wp) :: upper
    upper = min(t, ramp)
    hereditary_shear = rate*(long_term*upper + (short_term - long_term)/beta*(exp(-beta*(t - upper)) - exp(-beta*t)))
  end function hereditary_shear

  !> Shear ramp then hold: sigma_xy(t) against the hereditary integral (1e-9 relative; the
  !> Maxwell branch is integrated exactly for a piecewise constant rate), and the bulk response.
  subroutine test_viscoelastic_solid_relaxation()
    type(material_t) :: material
    real(wp) :: history(block_size, 6), stress(block_size, 6), strain_increment(block_size, 6)
    real(wp) :: wave_modulus(block_size), dt, t, rate, ramp, worst
    integer :: step
    material = viscoelastic()
    history = 0.0_wp
    stress = 0.0_wp
    dt = 1.0e-4_wp
    ramp = 0.01_wp
    rate = 0.1_wp           ! engineering shear rate: gamma = 1e-3 at the end of the ramp
    t = 0.0_wp
    worst = 0.0_wp
    do step = 1, 1000
      strain_increment = 0.0_wp
      if (t < ramp - 0.5_wp*dt) strain_increment(1, 4) = 0.5_wp*rate*dt
      call update_material_block(material, 1, dt, strain_increment, stress, history, wave_modulus)
      t = t + dt
      worst = max(worst, abs(stress(1, 4) - hereditary_shear(rate, ramp, t))/hereditary_shear(rate, ramp, t))
    end do
    call check(suite, "viscoelastic solid: shear relaxation follows G(t) (1e-9)", worst < 1.0e-9_wp, &
               "worst relative error "//real_text(worst))
    call check_close(suite, "viscoelastic solid: relaxed to within 2% of GI gamma after 4.5 / BETA", stress(1, 4), &
                     1.0_wp*rate*ramp, rel=0.02_wp)
    ! a volumetric increment: pressure K tr(de), no deviatoric stress
    history = 0.0_wp
    stress = 0.0_wp
    strain_increment = 0.0_wp
    strain_increment(1, 1:3) = 1.0e-4_wp
    call update_material_block(material, 1, dt, strain_increment, stress, history, wave_modulus)
    call check_close(suite, "viscoelastic solid: elastic bulk response", stress(1, 1:3), [6.0e-3_wp, 6.0e-3_wp, 6.0e-3_wp], &
                     rel=1.0e-12_wp)
  end subroutine test_viscoelastic_solid_relaxation

  !> Shell: in-plane shear relaxation as for the solid; for a stretch-then-hold, the returned
  !> thickness increments fed to the solid kernel give sigma_zz = 0 and the same in-plane stress.
  subroutine test_viscoelastic_shell()
    type(material_t) :: material
    real(wp) :: history(block_size, 4), stress(block_size, 3), strain(block_size, 3), thickness(block_size)
    real(wp) :: solid_history(block_size, 6), solid_stress(block_size, 6), solid_strain(block_size, 6)
    real(wp) :: wave_modulus(block_size), dt, t, rate, ramp, worst, worst_zz
    integer :: step
    material = viscoelastic()
    history = 0.0_wp
    stress = 0.0_wp
    dt = 1.0e-4_wp
    ramp = 0.01_wp
    rate = 0.1_wp
    t = 0.0_wp
    worst = 0.0_wp
    do step = 1, 1000
      strain = 0.0_wp
      if (t < ramp - 0.5_wp*dt) strain(1, 3) = rate*dt
      call update_plane_stress_block(material, 1, dt, strain, stress, history, thickness)
      t = t + dt
      worst = max(worst, abs(stress(1, 3) - hereditary_shear(rate, ramp, t))/hereditary_shear(rate, ramp, t))
    end do
    call check(suite, "viscoelastic shell: shear relaxation follows G(t) (1e-9)", worst < 1.0e-9_wp, &
               "worst relative error "//real_text(worst))
    history = 0.0_wp
    stress = 0.0_wp
    solid_history = 0.0_wp
    solid_stress = 0.0_wp
    t = 0.0_wp
    worst = 0.0_wp
    worst_zz = 0.0_wp
    do step = 1, 500
      strain = 0.0_wp
      if (t < ramp - 0.5_wp*dt) strain(1, 1:2) = [0.1_wp*dt, -0.02_wp*dt]
      call update_plane_stress_block(material, 1, dt, strain, stress, history, thickness)
      solid_strain = 0.0_wp
      solid_strain(1, 1:3) = [strain(1, 1), strain(1, 2), thickness(1)]
      call update_material_block(material, 1, dt, solid_strain, solid_stress, solid_history, wave_modulus)
      t = t + dt
      worst = max(worst, maxval(abs(solid_stress(1, 1:2) - stress(1, 1:2))))
      worst_zz = max(worst_zz, abs(solid_stress(1, 3)))
    end do
    call check(suite, "viscoelastic shell: sigma_zz = 0 and the solid's in-plane stress (1e-12 MPa)", &
               worst < 1.0e-12_wp .and. worst_zz < 1.0e-12_wp, &
               "in-plane "//real_text(worst)//", sigma_zz "//real_text(worst_zz))
  end subroutine test_viscoelastic_shell

  !> LCID1's least-squares fit: exact incompressible uniaxial data (stretch 0.7 to 2.5, a point at
  !> stretch 1 included) give A and B back to 1e-12; one stretch only is not enough.
  subroutine test_mooney_rivlin_fit()
    real(wp) :: stretch(13), nominal(13), a, b
    logical :: fitted
    integer :: k
    do k = 1, 13
      stretch(k) = 0.7_wp + 0.15_wp*real(k - 1, wp)
      if (k == 3) stretch(k) = 1.0_wp
      nominal(k) = 2.0_wp*(stretch(k) - stretch(k)**(-2))*(mooney_a + mooney_b/stretch(k))
    end do
    call mooney_rivlin_fit(stretch, nominal, a, b, fitted)
    call check(suite, "Mooney-Rivlin fit: fitted", fitted)
    call check_close(suite, "Mooney-Rivlin fit: A and B recovered (1e-12)", [a, b], [mooney_a, mooney_b], &
                     rel=1.0e-12_wp)
    call mooney_rivlin_fit([1.0_wp, 1.5_wp, 1.5_wp], [0.0_wp, 1.0_wp, 1.0_wp], a, b, fitted)
    call check(suite, "Mooney-Rivlin fit: one stretch besides 1 is not enough", .not. fitted)
  end subroutine test_mooney_rivlin_fit

  function rotation_matrix(axis, angle) result(r)
    real(wp), intent(in) :: axis(3), angle
    real(wp) :: r(3, 3), n(3), k(3, 3)
    integer :: i
    n = axis/norm2(axis)
    k = reshape([0.0_wp, n(3), -n(2), -n(3), 0.0_wp, n(1), n(2), -n(1), 0.0_wp], [3, 3])
    r = sin(angle)*k + (1.0_wp - cos(angle))*matmul(k, k)
    do i = 1, 3
      r(i, i) = r(i, i) + 1.0_wp
    end do
  end function rotation_matrix

  pure function unpacked(tensor) result(matrix)
    real(wp), intent(in) :: tensor(6)
    real(wp) :: matrix(3, 3)
    matrix = reshape([tensor(1), tensor(4), tensor(6), tensor(4), tensor(2), tensor(5), &
                      tensor(6), tensor(5), tensor(3)], [3, 3])
  end function unpacked

  pure function packed(matrix) result(tensor)
    real(wp), intent(in) :: matrix(3, 3)
    real(wp) :: tensor(6)
    tensor = [matrix(1, 1), matrix(2, 2), matrix(3, 3), matrix(1, 2), matrix(2, 3), matrix(3, 1)]
  end function packed

  function real_text(value) result(text)
    real(wp), intent(in) :: value
    character(len=:), allocatable :: text
    character(len=24) :: buffer
    write (buffer, '(es12.4)') value
    text = trim(adjustl(buffer))
  end function real_text

  function integer_text(value) result(text)
    integer, intent(in) :: value
    character(len=:), allocatable :: text
    character(len=12) :: buffer
    write (buffer, '(i0)') value
    text = trim(buffer)
  end function integer_text
end program test_rubber
