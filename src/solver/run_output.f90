!> What the run writes and when: states (d3plot), glstat, matsum, nodout and rwforc histories.
!>
!> Every output has an interval; it is written at t = 0, whenever the time passes the next
!> multiple of its interval, and at the last cycle. Without a *DATABASE card, glstat and matsum
!> (and rwforc for walls) are still recorded at ENDTIM/200 and states at ENDTIM/20, so every run
!> can be plotted; nodout needs history nodes and *DATABASE_NODOUT.
module run_output
  use kinds, only: wp
  use error_handling, only: error_t
  use model, only: model_t
  use explicit_state, only: explicit_state_t
  use history_buffer, only: history_set_t, add_history_series, append_history_row
  use energy_balance, only: update_energy_totals, part_energies, total_energy, energy_ratio
  use solid_block, only: solid_block_element_results
  use shell_block, only: shell_block_element_results
  use efg_forces, only: efg_point_results, transform_to_physical
  use results_file, only: results_file_t, write_state
  use rigid_bodies, only: rigid_body_history_row
  use distortion_check, only: distortion_t, check_solid_distortion
  implicit none
  private

  public :: output_plan_t, plan_output, write_due_output

  !> One periodic output.
  type :: output_clock_t
    real(wp) :: interval = 0.0_wp
    real(wp) :: next_time = 0.0_wp
    logical :: active = .false.
  end type output_clock_t

  !> Clocks and the positions of the history series.
  type :: output_plan_t
    type(output_clock_t) :: states, glstat, matsum, nodout, rwforc, rbdout, rcforc
    integer :: glstat_series = 0
    integer, allocatable :: matsum_series(:)     !< per part
    integer, allocatable :: nodout_series(:)     !< per history node
    integer, allocatable :: rwforc_series(:)     !< per wall
    integer, allocatable :: rbdout_series(:)     !< per rigid body
    integer, allocatable :: rcforc_series(:)     !< per contact
    real(wp) :: last_rcforc_time = 0.0_wp
    real(wp) :: last_rbdout_time = 0.0_wp
    real(wp) :: last_rwforc_time = 0.0_wp
    ! work arrays for the element results of a state, allocated once
    real(wp), allocatable :: solid_stress(:, :), solid_plastic_strain(:)
    real(wp), allocatable :: shell_stress(:, :), shell_stress_peak(:, :)      !< (6, shells)
    real(wp), allocatable :: shell_plastic_strain(:), shell_plastic_strain_peak(:)
    real(wp), allocatable :: node_velocity(:, :)     !< physical integer-step velocities of a state
    real(wp), allocatable :: node_displacement(:, :) !< physical displacements of a state
    real(wp), allocatable :: generalized_velocity(:, :) !< integer-step solver velocities (work array)
    real(wp), allocatable :: node_acceleration(:, :) !< physical accelerations (nodout)
    real(wp), allocatable :: part_kinetic(:), part_internal(:), part_hourglass(:)
    type(distortion_t) :: distortion             !< FE solids folded at a corner, checked at each state
  end type output_plan_t

  character(len=32), parameter :: glstat_columns(12) = [character(len=32) :: "time", "time_step", &
    "kinetic_energy", "internal_energy", "hourglass_energy", "contact_energy", "external_work", &
    "total_energy", "rigid_wall_energy", "energy_ratio", "added_mass", "momentum"]
  integer, parameter :: glstat_widths(12) = [1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 3]

contains

  !> Set the clocks from the deck and create the history series.
  subroutine plan_output(model, histories, plan)
    type(model_t), intent(in) :: model
    type(history_set_t), intent(inout) :: histories
    type(output_plan_t), intent(out) :: plan
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
    call add_history_series(histories, "glstat", glstat_columns, glstat_widths, &
                            capacity, plan%glstat_series)
    capacity = expected_rows(model, plan%matsum)
    allocate (plan%matsum_series(size(model%parts)))
    do k = 1, size(model%parts)
      write (label, '(i0)') model%parts(k)%id
      call add_history_series(histories, "matsum/"//trim(label), [character(len=32) :: "time", &
                              "kinetic_energy", "internal_energy", "hourglass_energy"], [1, 1, 1, 1], &
                              capacity, plan%matsum_series(k))
    end do
    allocate (plan%nodout_series(0), plan%rwforc_series(0))
    if (plan%nodout%active) then
      capacity = expected_rows(model, plan%nodout)
      deallocate (plan%nodout_series)
      allocate (plan%nodout_series(size(model%output%history_nodes)))
      do k = 1, size(model%output%history_nodes)
        write (label, '(i0)') model%node_ids(model%output%history_nodes(k))
        call add_history_series(histories, "nodout/"//trim(label), [character(len=32) :: "time", &
                                "displacement", "velocity", "acceleration"], [1, 3, 3, 3], capacity, &
                                plan%nodout_series(k))
      end do
    end if
    if (plan%rwforc%active) then
      capacity = expected_rows(model, plan%rwforc)
      deallocate (plan%rwforc_series)
      allocate (plan%rwforc_series(size(model%walls)))
      do k = 1, size(model%walls)
        write (label, '(i0)') model%walls(k)%id
        call add_history_series(histories, "rwforc/"//trim(label), [character(len=32) :: "time", "force"], &
                                [1, 3], capacity, plan%rwforc_series(k))
      end do
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
          call add_history_series(histories, "rcforc/"//trim(label), [character(len=32) :: "time", "force"], &
                                  [1, 3], capacity, plan%rcforc_series(k))
        end do
      end if
    end if
    ! rbdout: every rigid body, at the glstat interval
    allocate (plan%rbdout_series(0))
    if (allocated(model%rigid_bodies)) then
      call set_clock(plan%rbdout, 0.0_wp, plan%glstat%interval, size(model%rigid_bodies) > 0)
      if (plan%rbdout%active) then
        capacity = expected_rows(model, plan%rbdout)
        deallocate (plan%rbdout_series)
        allocate (plan%rbdout_series(size(model%rigid_bodies)))
        do k = 1, size(model%rigid_bodies)
          write (label, '(i0)') model%rigid_bodies(k)%id
          call add_history_series(histories, "rbdout/"//trim(label), [character(len=32) :: "time", &
                                  "displacement", "velocity", "force", "angular_momentum"], [1, 3, 3, 3, 3], &
                                  capacity, plan%rbdout_series(k))
        end do
      end if
    end if
    allocate (plan%solid_stress(6, size(model%solid_ids)), plan%solid_plastic_strain(size(model%solid_ids)))
    ! the solids of rigid parts have no stress: zero, not whatever the memory held
    plan%solid_stress = 0.0_wp
    plan%solid_plastic_strain = 0.0_wp
    allocate (plan%shell_stress(6, size(model%shell_ids)), plan%shell_stress_peak(6, size(model%shell_ids)), &
              plan%shell_plastic_strain(size(model%shell_ids)), plan%shell_plastic_strain_peak(size(model%shell_ids)))
    plan%shell_stress = 0.0_wp
    plan%shell_stress_peak = 0.0_wp
    plan%shell_plastic_strain = 0.0_wp
    plan%shell_plastic_strain_peak = 0.0_wp
    allocate (plan%node_velocity(3, size(model%node_ids)), plan%node_displacement(3, size(model%node_ids)), &
              plan%generalized_velocity(3, size(model%node_ids)), plan%node_acceleration(3, size(model%node_ids)))
    allocate (plan%part_kinetic(size(model%parts)), plan%part_internal(size(model%parts)), &
              plan%part_hourglass(size(model%parts)))
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

  !> Record the histories and write the state that are due at the state's time. `last` marks
  !> the final cycle (normal or error termination): everything is written then.
  subroutine write_due_output(model, state, plan, histories, results, last, wrote_state, error)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    type(output_plan_t), intent(inout) :: plan
    type(history_set_t), intent(inout) :: histories
    type(results_file_t), intent(inout) :: results
    logical, intent(in) :: last
    logical, intent(out) :: wrote_state
    type(error_t), allocatable, intent(out) :: error
    logical :: glstat_due, matsum_due, nodout_due, states_due
    integer :: k

    wrote_state = .false.
    glstat_due = clock_due(plan%glstat, state%time, last)
    matsum_due = clock_due(plan%matsum, state%time, last)
    if (glstat_due .or. matsum_due) call update_energy_totals(model, state)
    if (glstat_due) then
      call append_history_row(histories%series(plan%glstat_series), [state%time, &
        merge(state%next_time_step, state%time_step, state%cycle == 0), &
        state%energy%kinetic, state%energy%internal, state%energy%hourglass, state%energy%contact, &
        state%energy%external_work, total_energy(state), state%energy%rigid_wall, energy_ratio(state), &
        state%added_mass, state%energy%momentum])
    end if
    if (matsum_due) then
      call part_energies(model, state, size(model%parts), plan%part_kinetic, plan%part_internal, plan%part_hourglass)
      do k = 1, size(model%parts)
        call append_history_row(histories%series(plan%matsum_series(k)), [state%time, plan%part_kinetic(k), &
                                plan%part_internal(k), plan%part_hourglass(k)])
      end do
    end if
    nodout_due = clock_due(plan%nodout, state%time, last)
    states_due = clock_due(plan%states, state%time, last)
    if (nodout_due .or. states_due) call physical_node_fields(state, plan)
    if (nodout_due) then
      do k = 1, size(plan%nodout_series)
        associate (node => model%output%history_nodes(k))
          call append_history_row(histories%series(plan%nodout_series(k)), [state%time, &
            plan%node_displacement(:, node), plan%node_velocity(:, node), plan%node_acceleration(:, node)])
        end associate
      end do
    end if
    if (clock_due(plan%rwforc, state%time, last)) call record_wall_forces(state, plan, histories)
    if (clock_due(plan%rcforc, state%time, last)) call record_contact_forces(state, plan, histories)
    if (clock_due(plan%rbdout, state%time, last)) call record_rigid_bodies(model, state, plan, histories)
    if (states_due) then
      call check_solid_distortion(model, state%blocks, state%coordinates, state%time, plan%distortion)
      ! the state and the history rows recorded since the previous one, as one commit
      call write_current_state(model, state, plan, histories, results, error)
      wrote_state = .not. allocated(error)
    end if
  end subroutine write_due_output

  !> Wall force averaged over the sampling interval (impulse / interval), so that integrating
  !> the rwforc history gives the impulse exactly; at t = 0 the force of the first cycle is 0.
  subroutine record_wall_forces(state, plan, histories)
    type(explicit_state_t), intent(inout) :: state
    type(output_plan_t), intent(inout) :: plan
    type(history_set_t), intent(inout) :: histories
    integer :: k
    real(wp) :: interval, force(3)
    interval = state%time - plan%last_rwforc_time
    do k = 1, size(plan%rwforc_series)
      force = 0.0_wp
      if (interval > 0.0_wp) force = state%walls(k)%impulse/interval
      call append_history_row(histories%series(plan%rwforc_series(k)), [state%time, force])
      state%walls(k)%impulse = 0.0_wp
    end do
    plan%last_rwforc_time = state%time
  end subroutine record_wall_forces

  !> Contact force on the SURFA side averaged over the sampling interval (impulse / interval),
  !> as rwforc; at t = 0 the force is 0.
  subroutine record_contact_forces(state, plan, histories)
    type(explicit_state_t), intent(inout) :: state
    type(output_plan_t), intent(inout) :: plan
    type(history_set_t), intent(inout) :: histories
    integer :: k
    real(wp) :: interval, force(3)
    interval = state%time - plan%last_rcforc_time
    do k = 1, size(plan%rcforc_series)
      force = 0.0_wp
      if (interval > 0.0_wp) force = state%contacts(k)%impulse/interval
      call append_history_row(histories%series(plan%rcforc_series(k)), [state%time, force])
      state%contacts(k)%impulse = 0.0_wp
    end do
    plan%last_rcforc_time = state%time
  end subroutine record_contact_forces

  !> One rbdout row per rigid body (the force is the impulse since the last row / interval).
  subroutine record_rigid_bodies(model, state, plan, histories)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    type(output_plan_t), intent(inout) :: plan
    type(history_set_t), intent(inout) :: histories
    real(wp) :: row(13)
    integer :: k
    do k = 1, size(plan%rbdout_series)
      call rigid_body_history_row(model, k, state%rigid(k), state%acceleration, state%mass, state%time, &
                                  0.5_wp*state%time_step, state%time - plan%last_rbdout_time, row)
      call append_history_row(histories%series(plan%rbdout_series(k)), row)
    end do
    plan%last_rbdout_time = state%time
  end subroutine record_rigid_bodies

  !> Physical nodal displacements, integer-step velocities and accelerations: the solver's values, with the
  !> interior particles of meshfree parts transformed (eq. 16) so that the output shows the
  !> real deformed shape.
  subroutine physical_node_fields(state, plan)
    type(explicit_state_t), intent(in) :: state
    type(output_plan_t), intent(inout) :: plan
    integer :: k
    plan%generalized_velocity = state%velocity + 0.5_wp*state%time_step*state%acceleration
    plan%node_displacement = state%displacement
    plan%node_velocity = plan%generalized_velocity
    plan%node_acceleration = state%acceleration
    do k = 1, size(state%efg)
      call transform_to_physical(state%efg(k), state%displacement, plan%node_displacement)
      call transform_to_physical(state%efg(k), plan%generalized_velocity, plan%node_velocity)
      call transform_to_physical(state%efg(k), state%acceleration, plan%node_acceleration)
    end do
  end subroutine physical_node_fields

  subroutine write_current_state(model, state, plan, histories, results, error)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    type(output_plan_t), intent(inout) :: plan
    type(history_set_t), intent(in) :: histories
    type(results_file_t), intent(inout) :: results
    type(error_t), allocatable, intent(out) :: error
    integer :: b, k
    do b = 1, size(state%blocks)
      call solid_block_element_results(state%blocks(b), plan%solid_stress, plan%solid_plastic_strain)
    end do
    do k = 1, size(state%efg)
      call efg_point_results(model%materials(state%efg(k)%geometry%material), state%efg(k), plan%solid_stress, &
                             plan%solid_plastic_strain)
    end do
    do b = 1, size(state%shells)
      call shell_block_element_results(state%shells(b), model%materials(state%shells(b)%material), &
                                       plan%shell_stress, plan%shell_stress_peak, plan%shell_plastic_strain, &
                                       plan%shell_plastic_strain_peak)
    end do
    if (size(model%shell_ids) > 0) then
      call write_state(results, state%time, plan%node_displacement, plan%node_velocity, plan%solid_stress, &
                       plan%solid_plastic_strain, error, plan%shell_stress, plan%shell_plastic_strain, &
                       plan%shell_stress_peak, plan%shell_plastic_strain_peak, histories=histories)
    else
      call write_state(results, state%time, plan%node_displacement, plan%node_velocity, plan%solid_stress, &
                       plan%solid_plastic_strain, error, histories=histories)
    end if
  end subroutine write_current_state
end module run_output
