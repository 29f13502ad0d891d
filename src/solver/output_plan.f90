!> When the run writes what: the clocks of states (d3plot), glstat, matsum, nodout, rwforc,
!> rcforc and rbdout, the positions of their history series, and the work arrays of an output
!> state. Part of the run state (explicit_state): a restart continues the same schedule.
!>
!> Every output has an interval; it is written at t = 0, whenever the time passes the next
!> multiple of its interval, and at the last cycle. Without a *DATABASE card, glstat and matsum
!> (and rwforc for walls) are still recorded at ENDTIM/200 and states at ENDTIM/20, so every run
!> can be plotted; nodout needs history nodes and *DATABASE_NODOUT.
module output_plan
  use kinds, only: wp
  use model, only: model_t, formulation_efg
  use history_buffer, only: history_set_t, add_history_series
  use element_group, only: element_results_t, shell_output_points
  implicit none
  private

  public :: output_clock_t, output_plan_t, plan_output, clock_due, clock_is_due

  !> One periodic output.
  type :: output_clock_t
    real(wp) :: interval = 0.0_wp
    real(wp) :: next_time = 0.0_wp
    logical :: active = .false.
  end type output_clock_t

  !> Clocks and the positions of the history series.
  type :: output_plan_t
    type(output_clock_t) :: states, glstat, matsum, nodout, rwforc, rbdout, rcforc
    !> Whether this rank records the histories and writes the states: the other ranks of a
    !> distributed run only keep the clocks (the first rank writes every file), and hold none
    !> of the work arrays below.
    logical :: records = .true.
    integer :: glstat_series = 0
    integer :: weld_series = 0                   !< swforc: failed spot welds (0: the model has none)
    integer, allocatable :: matsum_series(:)     !< per part
    integer, allocatable :: nodout_series(:)     !< per history node
    integer, allocatable :: rwforc_series(:)     !< per wall
    integer, allocatable :: rbdout_series(:)     !< per rigid body
    integer, allocatable :: rcforc_series(:)     !< per contact
    ! the impulses of walls, contacts and rigid bodies (cumulative in the state) at their last
    ! sample: a history's force is the impulse since then over the interval
    real(wp), allocatable :: wall_impulse(:, :), contact_impulse(:, :), rigid_impulse(:, :)   !< (3, each)
    real(wp) :: last_rcforc_time = 0.0_wp
    real(wp) :: last_rbdout_time = 0.0_wp
    real(wp) :: last_rwforc_time = 0.0_wp
    ! work arrays for the element results of a state, allocated once
    type(element_results_t) :: element_results
    real(wp), allocatable :: node_velocity(:, :)     !< physical integer-step velocities of a state
    real(wp), allocatable :: node_displacement(:, :) !< physical displacements of a state
    real(wp), allocatable :: generalized_velocity(:, :) !< integer-step solver velocities (work array; meshfree models)
    real(wp), allocatable :: node_acceleration(:, :) !< physical accelerations (nodout)
    real(wp), allocatable :: part_kinetic(:), part_internal(:), part_hourglass(:)
    real(wp), allocatable :: part_momentum(:, :), part_mass(:), part_rigid_velocity(:, :)   !< matsum
    !> d3hsp's tables of the smallest stable steps at cycle 0 (ascii_run_summary; not kept in
    !> restart dumps: a continued run's d3hsp has the last cycle's only)
    character(len=:), allocatable :: initial_time_steps
  end type output_plan_t

  ! the columns after eroded_elements came with LS-DYNA's glstat lines (appended, so that the
  ! earlier ones keep their place); the element that set the step (glstat's "dt of cycle ... is
  ! controlled by"): its family (1 solid, 2 shell, 3 beam; 0: a rigid body's step or none), deck id
  ! and part id
  character(len=32), parameter :: glstat_columns(26) = [character(len=32) :: "time", "time_step", &
    "kinetic_energy", "internal_energy", "hourglass_energy", "contact_energy", "external_work", &
    "total_energy", "rigid_wall_energy", "energy_ratio", "added_mass", "momentum", &
    "eroded_internal_energy", "eroded_hourglass_energy", "eroded_kinetic_energy", "eroded_elements", &
    "spring_damper_energy", "system_damping_energy", "energy_ratio_without_eroded", "percent_mass_increase", &
    "global_velocity", "cycle", "physical_mass", "controlling_element_family", "controlling_element", &
    "controlling_part"]
  integer, parameter :: glstat_widths(26) = [1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 3, 1, 1, 1, 1, 1, 1, 1, 1, 3, 1, 1, &
                                             1, 1, 1]


contains

  !> Set the clocks from the deck and create the history series.
  subroutine plan_output(model, histories, plan, records)
    type(model_t), intent(in) :: model
    type(history_set_t), intent(inout) :: histories
    type(output_plan_t), intent(out) :: plan
    logical, intent(in) :: records     !< output_plan_t's records
    real(wp) :: default_history
    integer :: capacity, k
    character(len=32) :: label

    default_history = model%end_time/200.0_wp
    call set_clock(plan%states, model%output%state_interval, model%end_time/20.0_wp, .true.)
    call set_clock(plan%glstat, model%output%glstat_interval, default_history, .true.)
    call set_clock(plan%matsum, model%output%matsum_interval, plan%glstat%interval, .true.)
    call set_clock(plan%rwforc, model%output%rwforc_interval, plan%glstat%interval, size(model%walls) > 0)
    ! nodout as LS-DYNA: history nodes and a *DATABASE_NODOUT interval (the reader warns otherwise)
    call set_clock(plan%nodout, model%output%nodout_interval, plan%glstat%interval, &
                   size(model%output%history_nodes) > 0 .and. model%output%nodout_interval > 0.0_wp)

    capacity = expected_rows(model, plan%glstat)
    call add_series(histories, "glstat", glstat_columns, glstat_widths, &
                            capacity, plan%glstat_series)
    capacity = expected_rows(model, plan%matsum)
    allocate (plan%matsum_series(size(model%parts)))
    do k = 1, size(model%parts)
      write (label, '(i0)') model%parts(k)%id
      call add_series(histories, "matsum/"//trim(label), [character(len=32) :: "time", &
                              "kinetic_energy", "internal_energy", "hourglass_energy", "momentum", &
                              "rigid_body_velocity", "mass"], [1, 1, 1, 1, 3, 3, 1], &
                              capacity, plan%matsum_series(k))
    end do
    allocate (plan%nodout_series(0), plan%rwforc_series(0))
    if (plan%nodout%active) then
      capacity = expected_rows(model, plan%nodout)
      deallocate (plan%nodout_series)
      allocate (plan%nodout_series(size(model%output%history_nodes)))
      do k = 1, size(model%output%history_nodes)
        write (label, '(i0)') model%node_ids(model%output%history_nodes(k))
        call add_series(histories, "nodout/"//trim(label), [character(len=32) :: "time", &
                                "displacement", "velocity", "acceleration", "cycle"], [1, 3, 3, 3, 1], capacity, &
                                plan%nodout_series(k))
      end do
    end if
    if (plan%rwforc%active) then
      capacity = expected_rows(model, plan%rwforc)
      deallocate (plan%rwforc_series)
      allocate (plan%rwforc_series(size(model%walls)))
      do k = 1, size(model%walls)
        write (label, '(i0)') model%walls(k)%id
        call add_series(histories, "rwforc/"//trim(label), [character(len=32) :: "time", "force", &
                                "normal_force"], [1, 3, 1], capacity, plan%rwforc_series(k))
      end do
    end if
    ! swforc: how many spot welds have failed, at the glstat interval
    if (allocated(model%spot_welds)) then
      if (size(model%spot_welds) > 0) call add_series(histories, "swforc", [character(len=32) :: "time", &
                                        "failed_welds"], [1, 1], expected_rows(model, plan%glstat), plan%weld_series)
    end if
    ! rcforc: every contact, at the *DATABASE_RCFORC interval (else the glstat one)
    allocate (plan%rcforc_series(0))
    if (allocated(model%contacts)) then
      call set_clock(plan%rcforc, model%output%rcforc_interval, plan%glstat%interval, size(model%contacts) > 0)
      if (plan%rcforc%active) then
        capacity = expected_rows(model, plan%rcforc)
        deallocate (plan%rcforc_series)
        allocate (plan%rcforc_series(size(model%contacts)))
        do k = 1, size(model%contacts)
          write (label, '(i0)') model%contacts(k)%id
          call add_series(histories, "rcforc/"//trim(label), [character(len=32) :: "time", "force", &
                                  "surfb_force", "mass", "surfb_mass"], [1, 3, 3, 1, 1], capacity, &
                                  plan%rcforc_series(k))
        end do
      end if
    end if
    ! rbdout: every rigid body, at the *DATABASE_RBDOUT interval (else the glstat one)
    allocate (plan%rbdout_series(0))
    if (allocated(model%rigid_bodies)) then
      call set_clock(plan%rbdout, model%output%rbdout_interval, plan%glstat%interval, size(model%rigid_bodies) > 0)
      if (plan%rbdout%active) then
        capacity = expected_rows(model, plan%rbdout)
        deallocate (plan%rbdout_series)
        allocate (plan%rbdout_series(size(model%rigid_bodies)))
        do k = 1, size(model%rigid_bodies)
          write (label, '(i0)') model%rigid_bodies(k)%id
          ! (the columns after angular_momentum came with LS-DYNA's rbdout file, appended)
          call add_series(histories, "rbdout/"//trim(label), [character(len=32) :: "time", &
                                  "displacement", "velocity", "force", "angular_momentum", "coordinates", &
                                  "acceleration", "rotation", "angular_velocity", "angular_acceleration", &
                                  "direction_cosines", "cycle"], [1, 3, 3, 3, 3, 3, 3, 3, 3, 3, 9, 1], &
                                  capacity, plan%rbdout_series(k))
        end do
      end if
    end if
    allocate (plan%wall_impulse(3, size(plan%rwforc_series)), plan%contact_impulse(3, size(plan%rcforc_series)), &
              plan%rigid_impulse(3, size(plan%rbdout_series)))
    plan%wall_impulse = 0.0_wp
    plan%contact_impulse = 0.0_wp
    plan%rigid_impulse = 0.0_wp
    plan%records = records
    if (.not. records) return
    associate (results => plan%element_results)
      allocate (results%solid_stress(6, size(model%solid_ids)), results%solid_plastic_strain(size(model%solid_ids)))
      allocate (results%shell_stress(6, size(model%shell_ids)), results%shell_stress_peak(6, size(model%shell_ids)), &
                results%shell_plastic_strain(size(model%shell_ids)), &
                results%shell_plastic_strain_peak(size(model%shell_ids)))
      ! elements of no group (rigid parts) keep zero rows
      results%solid_stress = 0.0_wp
      results%solid_plastic_strain = 0.0_wp
      results%shell_stress = 0.0_wp
      results%shell_stress_peak = 0.0_wp
      results%shell_plastic_strain = 0.0_wp
      results%shell_plastic_strain_peak = 0.0_wp
      if (allocated(model%beam_ids)) then
        allocate (results%beam_resultant(6, size(model%beam_ids)), results%beam_plastic_strain(size(model%beam_ids)), &
                  results%beam_failed(size(model%beam_ids)))
        results%beam_resultant = 0.0_wp
        results%beam_plastic_strain = 0.0_wp
        results%beam_failed = 0.0_wp
      end if
      allocate (results%solid_eroded(size(model%solid_ids)), results%shell_eroded(size(model%shell_ids)))
      results%solid_eroded = 0
      results%shell_eroded = 0
      ! the d3plot's layers through the thickness
      allocate (results%shell_point_stress(6, shell_output_points(model), size(model%shell_ids)), &
                results%shell_point_plastic_strain(shell_output_points(model), size(model%shell_ids)), &
                results%shell_point_count(size(model%shell_ids)))
      results%shell_point_stress = 0.0_wp
      results%shell_point_plastic_strain = 0.0_wp
      results%shell_point_count = 0
      allocate (results%shell_resultant(8, size(model%shell_ids)), results%shell_thickness(size(model%shell_ids)), &
                results%shell_energy_density(size(model%shell_ids)))
      results%shell_resultant = 0.0_wp
      results%shell_thickness = 0.0_wp
      results%shell_energy_density = 0.0_wp
    end associate
    allocate (plan%node_velocity(3, size(model%node_ids)), plan%node_displacement(3, size(model%node_ids)), &
              plan%node_acceleration(3, size(model%node_ids)))
    ! (the solver's velocities go through to_physical only where meshfree parts transform them)
    if (any(model%parts%formulation == formulation_efg)) allocate (plan%generalized_velocity(3, size(model%node_ids)))
    allocate (plan%part_kinetic(size(model%parts)), plan%part_internal(size(model%parts)), &
              plan%part_hourglass(size(model%parts)))
    allocate (plan%part_momentum(3, size(model%parts)), plan%part_mass(size(model%parts)), &
              plan%part_rigid_velocity(3, size(model%parts)))
  contains
    !> A history series on the rank that records them (the others: none, index 0).
    subroutine add_series(set, group, names, widths, capacity, index)
      type(history_set_t), intent(inout) :: set
      character(len=*), intent(in) :: group
      character(len=*), intent(in) :: names(:)
      integer, intent(in) :: widths(:)
      integer, intent(in) :: capacity
      integer, intent(out) :: index
      index = 0
      if (records) call add_history_series(set, group, names, widths, capacity, index)
    end subroutine add_series
  end subroutine plan_output

  subroutine set_clock(clock, interval, default_interval, active)
    type(output_clock_t), intent(out) :: clock
    real(wp), intent(in) :: interval, default_interval
    logical, intent(in) :: active
    clock%active = active
    clock%interval = interval
    if (clock%interval <= 0.0_wp) clock%interval = default_interval
    clock%next_time = 0.0_wp
  end subroutine set_clock

  integer function expected_rows(model, clock)
    type(model_t), intent(in) :: model
    type(output_clock_t), intent(in) :: clock
    ! a first guess only (the series grow by doubling): at most 4096 rows, so that many parts
    ! with a tiny interval do not reserve gigabytes; compared before dividing and without
    ! multiplying the interval, as the end time and the default intervals may be huge (ENDCYC only)
    expected_rows = 16
    if (clock%interval > 0.0_wp) then
      if (model%end_time/4096.0_wp < clock%interval) then
        expected_rows = int(model%end_time/clock%interval) + 16
      else
        expected_rows = 4096 + 16
      end if
    end if
  end function expected_rows

  !> Whether a clock is due at `time` (and advance it); `last` forces every active output.
  logical function clock_due(clock, time, last)
    type(output_clock_t), intent(inout) :: clock
    real(wp), intent(in) :: time
    logical, intent(in) :: last
    clock_due = .false.
    if (.not. clock%active) return
    if (time >= clock%next_time*(1.0_wp - 1.0e-12_wp) .or. last) then
      clock_due = .true.
      if (clock%interval > 0.0_wp) then
        ! the first multiple of the interval after this time (no loop: the interval may be far
        ! shorter than the time step)
        clock%next_time = max(clock%next_time, (aint(time*(1.0_wp + 1.0e-12_wp)/clock%interval) + 1.0_wp)* &
                                               clock%interval)
      else
        clock%next_time = huge(1.0_wp)
      end if
    end if
  end function clock_due

  !> Whether a clock would be due at `time` (clock_due without advancing it).
  logical function clock_is_due(clock, time, last)
    type(output_clock_t), intent(in) :: clock
    real(wp), intent(in) :: time
    logical, intent(in) :: last
    clock_is_due = clock%active .and. (time >= clock%next_time*(1.0_wp - 1.0e-12_wp) .or. last)
  end function clock_is_due
end module output_plan
