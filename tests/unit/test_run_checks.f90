!> Unit tests of the checks that stop a run whose state is no longer physical (run_checks) and
!> of the progress line's durations: on a model of one part and a hand-made state, each check
!> passes a sound state and stops the faulty one with a message naming the node or element.
program test_run_checks
  use kinds, only: wp
  use error_handling, only: error_t
  use model, only: model_t, part_t, material_t
  use material_laws, only: law_elastic
  use explicit_state, only: explicit_state_t
  use nodal_state, only: allocate_nodal_state
  use run_checks, only: set_up_run_checks, check_runaway_motion, check_time_step, check_energy
  use progress_report, only: format_duration
  use testing, only: test_suite_t, check, check_close, finish_suite
  implicit none

  type(test_suite_t) :: suite
  type(model_t) :: model
  type(explicit_state_t) :: state

  suite%name = "run_checks"
  call build_model(model)
  call build_state(state)
  call test_wave_speed_limit()
  call test_runaway_motion()
  call test_time_step_growth_and_dtmin()
  call test_energy_explosion()
  call test_durations()
  call finish_suite(suite)

contains

  !> Two nodes joined by nothing (the checks only read nodal arrays and the materials); one part
  !> of steel-like elastic material: E = 210, nu = 0.3, rho = 7.85e-6 (mm, ms, kg, GPa).
  subroutine build_model(model)
    type(model_t), intent(out) :: model
    model%node_ids = [11, 12]
    allocate (model%solid_ids(0), model%shell_ids(0), model%solid_nodes(8, 0), model%shell_nodes(4, 0))
    allocate (model%solid_part(0), model%shell_part(0))
    allocate (model%parts(1), model%materials(1))
    model%parts(1)%id = 7
    model%parts(1)%material = 1
    model%materials(1)%law = law_elastic
    model%materials(1)%youngs_modulus = 210.0_wp
    model%materials(1)%poissons_ratio = 0.3_wp
    model%materials(1)%density = 7.85e-6_wp
    model%end_time = 1.0_wp
  end subroutine build_model

  subroutine build_state(state)
    type(explicit_state_t), intent(out) :: state
    real(wp) :: zero(3, 2)
    zero = 0.0_wp
    call allocate_nodal_state(state%nodes, zero, zero)
    allocate (state%groups(0), state%rigid(0), state%walls(0))
    allocate (state%chunk_sums(5, 1))
    state%nodes%mass = 1.0_wp
    state%physical_mass = 2.0_wp
  end subroutine build_state

  !> The limit is 100 times sqrt((K + 4G/3)/rho) = 100 sqrt(E (1 - nu) / ((1 + nu)(1 - 2 nu) rho)).
  subroutine test_wave_speed_limit()
    type(error_t), allocatable :: error
    real(wp) :: speed
    call set_up_run_checks(model, state, error)
    call check(suite, "set-up passes without mass scaling", .not. allocated(error))
    speed = sqrt(210.0_wp*0.7_wp/(1.3_wp*0.4_wp*7.85e-6_wp))
    call check_close(suite, "fastest wave speed", state%watch%largest_wave_speed, speed, rel=1.0e-14_wp)
    call check_close(suite, "velocity limit", state%watch%velocity_limit, 100.0_wp*speed, rel=1.0e-14_wp)
    state%added_mass = 1.0e7_wp*state%physical_mass
    model%mass_change_limit = 1.0e8_wp
    call set_up_run_checks(model, state, error)
    call check(suite, "added mass above ENDMAS stops the run", allocated(error))
    if (allocated(error)) call check(suite, "ENDMAS message", index(error%message, "ENDMAS") > 0, error%message)
    state%added_mass = 0.0_wp
    call set_up_run_checks(model, state, error)
  end subroutine test_wave_speed_limit

  subroutine test_runaway_motion()
    type(error_t), allocatable :: error
    real(wp) :: nan
    state%cycle = 5
    state%nodes%velocity(:, 1) = [1.0_wp, 2.0_wp, 3.0_wp]
    state%nodes%acceleration(:, 2) = [0.0_wp, 0.0_wp, 1.0e3_wp]
    call check_runaway_motion(model, state, 1.0e-3_wp, error)
    call check(suite, "moderate motion passes", .not. allocated(error))
    ! 0.999 and 1.001 times the limit after the step
    state%nodes%acceleration(3, 2) = 0.999_wp*state%watch%velocity_limit/1.0e-3_wp
    call check_runaway_motion(model, state, 1.0e-3_wp, error)
    call check(suite, "just below the limit passes", .not. allocated(error))
    state%nodes%acceleration(3, 2) = 1.001_wp*state%watch%velocity_limit/1.0e-3_wp
    call check_runaway_motion(model, state, 1.0e-3_wp, error)
    call check(suite, "just above the limit stops", allocated(error))
    if (allocated(error)) call check(suite, "names node 12 and part", &
                                     index(error%message, "node 12 (on no element)") > 0 .and. &
                                     index(error%message, "cycle 5") > 0, error%message)
    call check(suite, "the state is left as it was", state%nodes%velocity(3, 2) == 0.0_wp)
    state%nodes%acceleration(3, 2) = 0.0_wp
    nan = ieee_nan()
    state%nodes%velocity(2, 1) = nan
    call check_runaway_motion(model, state, 1.0e-3_wp, error)
    call check(suite, "a NaN velocity stops", allocated(error))
    if (allocated(error)) call check(suite, "names node 11", index(error%message, "node 11") > 0, error%message)
    state%nodes%velocity(2, 1) = 0.0_wp
  end subroutine test_runaway_motion

  subroutine test_time_step_growth_and_dtmin()
    type(error_t), allocatable :: error
    state%controlling_group = 0
    state%controlling_element = 0
    model%time_step_scale = 0.9_wp
    call step_check(0, 1.0e-3_wp, error)
    call check(suite, "first step accepted", .not. allocated(error))
    call check_close(suite, "first step remembered", state%watch%first_time_step, 0.9e-3_wp, rel=1.0e-15_wp)
    call step_check(1, 50.0e-3_wp, error)
    call check(suite, "a fifty-fold growth is accepted", .not. allocated(error))
    call step_check(2, 50.0e-3_wp*101.0_wp, error)
    call check(suite, "a hundred-fold growth in one cycle stops", allocated(error))
    if (allocated(error)) call check(suite, "growth message", index(error%message, "grew from") > 0, error%message)
    state%watch%last_stable_step = 1.0e-3_wp
    model%minimum_time_step_factor = 0.01_wp
    call step_check(3, 0.011e-3_wp, error)
    call check(suite, "above DTMIN passes", .not. allocated(error))
    call check(suite, "the fall below a hundredth reported", state%watch%step_decades_reported == 1)
    call step_check(4, 0.009e-3_wp, error)
    call check(suite, "below DTMIN stops", allocated(error))
    if (allocated(error)) call check(suite, "DTMIN message", index(error%message, "DTMIN") > 0, error%message)
    model%minimum_time_step_factor = 0.0_wp
    call step_check(5, 1.0e-3_wp, error)
    state%next_time_step = 2.01e-3_wp
    call check_time_step(model, state, 1.0e-3_wp, error)
    call check(suite, "a step beyond twice the stable one stops", allocated(error))
    state%next_time_step = -huge(1.0_wp)
    call check_time_step(model, state, -huge(1.0_wp), error)
    call check(suite, "no finite step stops", allocated(error))
  end subroutine test_time_step_growth_and_dtmin

  !> check_time_step at `cycle` with the stable step `stable` and TSSFAC times it as the next step.
  subroutine step_check(cycle, stable, error)
    integer, intent(in) :: cycle
    real(wp), intent(in) :: stable
    type(error_t), allocatable, intent(out) :: error
    state%cycle = cycle
    state%stable_time_step = stable
    state%next_time_step = model%time_step_scale*stable
    call check_time_step(model, state, stable, error)
  end subroutine step_check

  !> Two unit masses: kinetic energy 1/2 (v.v) each (v constant: no acceleration).
  subroutine test_energy_explosion()
    type(error_t), allocatable :: error
    real(wp) :: scratch(5, 1)
    state%time_step = 1.0e-3_wp
    state%next_time_step = 1.0e-3_wp
    state%nodes%velocity = 0.0_wp
    state%nodes%velocity(1, 1) = 1.0_wp
    state%energy%initial_total = 0.5_wp
    state%energy%external_work = 0.0_wp
    call check_energy(model, state, scratch, error)
    call check(suite, "balanced energy passes", .not. allocated(error))
    call check_close(suite, "kinetic energy", state%energy%kinetic, 0.5_wp, rel=1.0e-15_wp)
    state%nodes%velocity(1, 2) = 3.0_wp     ! 4.5 more than was given: 9 times the energy put in
    call check_energy(model, state, scratch, error)
    call check(suite, "nine times the energy given passes", .not. allocated(error))
    state%nodes%velocity(1, 2) = 3.5_wp     ! 6.125 more: above ten times
    call check_energy(model, state, scratch, error)
    call check(suite, "energy created beyond ten times the given stops", allocated(error))
    state%nodes%velocity(1, 2) = 0.0_wp
    model%energy_ratio_change_limit = 1.0_wp
    state%nodes%velocity(1, 1) = 1.004_wp   ! ratio 1.008
    call check_energy(model, state, scratch, error)
    call check(suite, "ratio within ENDENG passes", .not. allocated(error))
    state%nodes%velocity(1, 1) = 1.006_wp   ! ratio 1.012
    call check_energy(model, state, scratch, error)
    call check(suite, "ratio beyond ENDENG stops", allocated(error))
    model%energy_ratio_change_limit = 0.0_wp
    state%nodes%velocity = 0.0_wp
  end subroutine test_energy_explosion

  subroutine test_durations()
    call check(suite, "seconds", format_duration(12.34_wp) == "12.3s", format_duration(12.34_wp))
    call check(suite, "hours", format_duration(3725.0_wp) == "1h 02m", format_duration(3725.0_wp))
    call check(suite, "huge estimates do not overflow", format_duration(1.0e30_wp) == "> 100000h", &
               format_duration(1.0e30_wp))
    call check(suite, "infinite estimates", format_duration(huge(1.0_wp)) == "> 100000h")
  end subroutine test_durations

  !> A quiet NaN without arithmetic (the checked build traps invalid operations).
  function ieee_nan() result(value)
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
    real(wp) :: value
    value = ieee_value(value, ieee_quiet_nan)
  end function ieee_nan
end program test_run_checks
