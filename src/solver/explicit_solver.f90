!> The explicit time loop (central difference), as a short sequence of named steps:
!> velocities -> kinematic conditions and walls -> positions -> element forces -> contact ->
!> external loads -> accelerations -> next time step -> output.
module explicit_solver
  use kinds, only: wp
  use fixed_order_sum, only: sum_chunk_size, sum_in_order
  use error_handling, only: error_t, make_error
  use model, only: model_t
  use explicit_state, only: explicit_state_t
  use element_forces, only: compute_element_forces, compute_shell_forces, compute_meshfree_forces
  use boundary_conditions, only: assemble_nodal_loads, load_work, impose_kinematic_conditions, &
                                 hold_prescribed_accelerations
  use planar_rigid_walls, only: enforce_planar_walls
  use cylinder_walls, only: enforce_cylinder_walls
  use rigid_bodies, only: advance_rigid_bodies
  use penalty_contact, only: compute_contact_forces, report_initial_penetrations
  use energy_balance, only: update_energy_totals, total_energy
  use run_checks, only: set_up_run_checks, check_runaway_motion, check_elements, check_time_step, check_energy, &
                        energy_check_interval
  use stop_signals, only: received_stop_signal, progress_line_requested, signal_name
  use run_output, only: output_plan_t, plan_output, write_due_output
  use history_buffer, only: history_set_t
  use results_file, only: results_file_t
  use run_summary, only: run_summary_t
  use progress_report, only: progress_t, start_progress, report_progress
  use wall_clock, only: phase_timer_t, start_phase, stop_phase
  use restart_control, only: restart_control_t, write_due_dumps, resume_run
  implicit none
  private

  public :: run_explicit

  !> The timed phases of the loop (the run summary's columns).
  integer, parameter :: phase_solids = 1, phase_shells = 2, phase_meshfree = 3, phase_contact = 4, &
                        phase_output = 5, phase_count = 5

contains

  !> Run from t = 0 to the end time (or end cycle). On a run-time error (inverted element,
  !> runaway motion, exploding energy, collapsing time step, a stop signal) the last state is
  !> written and `error` says what, where and when. `restart`: the run's restart dumps
  !> (restart_control); with `restart%resuming` the run continues from the dump being read.
  subroutine run_explicit(model, state, results, summary, error, restart)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    type(results_file_t), intent(inout) :: results
    type(run_summary_t), intent(inout) :: summary
    type(error_t), allocatable, intent(out) :: error
    type(restart_control_t), intent(inout), optional :: restart
    type(history_set_t) :: histories
    type(output_plan_t) :: plan
    type(progress_t) :: progress
    type(phase_timer_t) :: timers(phase_count)
    type(error_t), allocatable :: output_error
    real(wp) :: previous_step, step
    logical :: finished, wrote_state, resuming, clean

    call plan_output(model, histories, plan)

    resuming = .false.
    if (present(restart)) resuming = restart%resuming
    if (resuming) then
      ! the state, clock, plan and histories at the end of the dump's cycle, before its output
      call resume_run(restart, state, plan, histories, previous_step, timers, error)
      if (allocated(error)) return
      finished = reached_end(model, state)
    else
      ! cycle 0: forces and accelerations of the initial state (unless its motion is already
      ! beyond any physical run, or mass scaling added more than ENDMAS allows)
      call set_up_run_checks(model, state, error)
      if (.not. allocated(error)) call check_runaway_motion(model, state, 0.0_wp, error)
      if (.not. allocated(error)) then
        call compute_forces(model, state, 0.0_wp, timers)
        call compute_accelerations(state)
        call hold_prescribed_accelerations(model, 0.0_wp, state%acceleration, state%free_acceleration)
        call select_time_step(model, state, is_first=.true.)
        call update_energy_totals(model, state)
        state%energy%initial_total = total_energy(state)
        call check_cycle(model, state, .true., error)
      end if
      finished = allocated(error) .or. model%end_time <= 0.0_wp .and. model%end_cycle <= 0
      previous_step = 0.0_wp
    end if
    call start_phase(timers(phase_output))
    call write_due_output(model, state, plan, histories, results, finished, wrote_state, output_error)
    call stop_phase(timers(phase_output))
    if (allocated(output_error)) then
      finished = .true.
      if (.not. allocated(error)) call move_alloc(output_error, error)
    end if
    call start_progress(progress, model%end_time, model%end_cycle)

    do while (.not. finished)
      step = state%next_time_step
      call check_runaway_motion(model, state, 0.5_wp*(previous_step + step), error)
      if (.not. allocated(error)) then
        call advance_one_cycle(model, state, previous_step, step, timers)
        previous_step = step
        finished = reached_end(model, state)
        call check_cycle(model, state, finished, error)
      end if
      clean = .not. allocated(error)
      if (clean) call check_stop_signal(state, error)
      finished = finished .or. allocated(error)
      call start_phase(timers(phase_output))
      ! restart dumps: the state of this cycle before its output (none after a run-time error)
      if (present(restart) .and. clean) &
        call write_due_dumps(restart, state, plan, histories, previous_step, timers, summary%setup_s, &
                             results, allocated(error), finished, error)
      call write_due_output(model, state, plan, histories, results, finished, wrote_state, output_error)
      call stop_phase(timers(phase_output))
      if (allocated(output_error)) exit
      call report_progress(progress, state%cycle, state%time, state%time_step, &
                           finished .or. progress_line_requested())
    end do

    if (allocated(output_error) .and. .not. allocated(error)) call move_alloc(output_error, error)
    summary%end_time = state%time
    summary%cycles = state%cycle
    summary%fe_solid_s = timers(phase_solids)%seconds
    summary%fe_shell_s = timers(phase_shells)%seconds
    summary%efg_s = timers(phase_meshfree)%seconds
    summary%contact_s = timers(phase_contact)%seconds
    summary%output_s = timers(phase_output)%seconds
    summary%tangled_solids = plan%distortion%tangled
    summary%worst_corner_jacobian_ratio = plan%distortion%worst_ratio
    if (plan%distortion%worst_element > 0) &
      summary%worst_corner_jacobian_element = model%solid_ids(plan%distortion%worst_element)
  end subroutine run_explicit

  !> Whether the run has reached ENDTIM (to round-off) or ENDCYC.
  logical function reached_end(model, state)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    reached_end = state%time >= model%end_time*(1.0_wp - 1.0e-12_wp) .or. &
                  (model%end_cycle > 0 .and. state%cycle >= model%end_cycle)
  end function reached_end

  !> One central-difference cycle from t^n to t^{n+1} = t^n + step: velocities at the half step,
  !> supports, walls and rigid bodies, positions, then the forces and accelerations at t^{n+1}
  !> and the next stable step. `previous_step` is t^n - t^{n-1}.
  subroutine advance_one_cycle(model, state, previous_step, step, timers)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    real(wp), intent(in) :: previous_step, step
    type(phase_timer_t), intent(inout) :: timers(phase_count)
    real(wp) :: average_step, work, cylinder_work

    average_step = 0.5_wp*(previous_step + step)
    ! velocities at the half step, then the supports and walls correct them
    call update_velocities(state, average_step)
    if (size(state%shells) > 0) then
      call remove_drilling_rates(state, average_step, work)
      state%energy%external_work = state%energy%external_work + work
    end if
    call impose_kinematic_conditions(model, state%fixed, state%time, step, average_step, &
                                     state%displacement, state%acceleration, state%free_acceleration, &
                                     state%mass, state%velocity, work)
    state%energy%external_work = state%energy%external_work + work
    if (size(model%walls) > 0) then
      call start_phase(timers(phase_contact))
      call enforce_planar_walls(model%walls, state%walls, state%time, step, average_step, &
                                state%coordinates, state%acceleration, state%mass, state%velocity, work)
      state%energy%rigid_wall = state%energy%rigid_wall + work
      call enforce_cylinder_walls(model%walls, model%curves, state%walls, state%time, step, average_step, &
                                  state%coordinates, state%acceleration, state%mass, state%velocity, work, &
                                  cylinder_work)
      call stop_phase(timers(phase_contact))
      state%energy%rigid_wall = state%energy%rigid_wall + work
      state%energy%external_work = state%energy%external_work + cylinder_work
    end if
    if (size(state%rigid) > 0) then
      call advance_rigid_bodies(model, state%rigid, state%time, step, average_step, &
                                state%coordinates, state%velocity, work)
      state%energy%external_work = state%energy%external_work + work
      if (size(state%shells) > 0) call rotate_with_rigid_bodies(model, state)
    end if
    call update_positions(state, step)
    state%energy%external_work = state%energy%external_work + &
                                 0.5_wp*load_work(model, state%external_force, state%velocity, step)
    state%time = state%time + step
    ! the step that was cut at ENDTIM lands on it exactly
    if (model%end_time > 0.0_wp .and. state%time > model%end_time) state%time = model%end_time
    state%time_step = step
    state%cycle = state%cycle + 1

    call compute_forces(model, state, step, timers)
    if (size(state%contacts) > 0) then
      call start_phase(timers(phase_contact))
      call compute_contact_forces(model, state%contacts, state%time, step, state%coordinates, state%velocity, &
                                  state%mass, state%contact_force, work)
      call stop_phase(timers(phase_contact))
      state%energy%contact = state%energy%contact + work
      call report_initial_penetrations(model, state%contacts, state%time)
    end if
    call assemble_nodal_loads(model, state%time, state%external_force)
    state%energy%external_work = state%energy%external_work + &
                                 0.5_wp*load_work(model, state%external_force, state%velocity, step)
    call compute_accelerations(state)
    call hold_prescribed_accelerations(model, state%time, state%acceleration, state%free_acceleration)
    call select_time_step(model, state, is_first=.false.)
  end subroutine advance_one_cycle

  !> Internal forces of the solids, shells and meshfree parts at the current configuration
  !> (`step` is the step just taken, 0 at the start); the solids clear the force array first.
  subroutine compute_forces(model, state, step, timers)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    real(wp), intent(in) :: step
    type(phase_timer_t), intent(inout) :: timers(phase_count)
    call start_phase(timers(phase_solids))
    call compute_element_forces(model, state, step)
    call stop_phase(timers(phase_solids))
    call start_phase(timers(phase_shells))
    call compute_shell_forces(model, state, step)
    call stop_phase(timers(phase_shells))
    call start_phase(timers(phase_meshfree))
    call compute_meshfree_forces(model, state, step)
    call stop_phase(timers(phase_meshfree))
  end subroutine compute_forces

  !> The checks after a cycle: elements, the time step, and every few cycles and at the last
  !> one the energy.
  subroutine check_cycle(model, state, last, error)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    logical, intent(in) :: last
    type(error_t), allocatable, intent(out) :: error
    call check_elements(model, state, error)
    if (allocated(error)) return
    call check_time_step(model, state, state%stable_time_step, error)
    if (allocated(error)) return
    if (last .or. mod(state%cycle, energy_check_interval) == 0) call check_energy(model, state, error)
  end subroutine check_cycle

  !> A SIGINT or SIGTERM ends the run after the cycle: the state is written and the run ends
  !> with error termination.
  subroutine check_stop_signal(state, error)
    type(explicit_state_t), intent(in) :: state
    type(error_t), allocatable, intent(out) :: error
    character(len=40) :: text
    integer :: number
    number = received_stop_signal()
    if (number == 0) return
    write (text, '(es12.5,a,i0)') state%time, ", cycle ", state%cycle
    call make_error(error, "stopped by "//signal_name(number)//" at time "//trim(adjustl(text))// &
                    ": the results hold the run up to this time")
  end subroutine check_stop_signal

  !> a = (f_ext - f_int) / m, and for the rotations of shell nodes alpha = -m_int / I;
  !> constrained dofs do not accelerate.
  subroutine compute_accelerations(state)
    type(explicit_state_t), intent(inout) :: state
    integer :: node
    !$omp parallel do schedule(static) default(shared) private(node)
    do node = 1, state%node_count
      if (state%mass(node) > 0.0_wp) then
        state%acceleration(:, node) = (state%external_force(:, node) - state%internal_force(:, node) + &
                                       state%contact_force(:, node))/state%mass(node)
      else
        state%acceleration(:, node) = 0.0_wp
      end if
      where (state%fixed(:, node)) state%acceleration(:, node) = 0.0_wp
      if (state%rotary_inertia(node) > 0.0_wp) then
        state%angular_acceleration(:, node) = -state%internal_moment(:, node)/state%rotary_inertia(node)
      else
        state%angular_acceleration(:, node) = 0.0_wp
      end if
      where (state%fixed_rotation(:, node)) state%angular_acceleration(:, node) = 0.0_wp
    end do
    !$omp end parallel do
  end subroutine compute_accelerations

  !> Shell nodes that belong to a rigid body turn with it. (The moments that deformable shells
  !> put on such nodes are not passed on to the body: a shell tied to a rigid part transmits
  !> forces only.)
  subroutine rotate_with_rigid_bodies(model, state)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    integer :: b, k
    do b = 1, size(state%rigid)
      do k = 1, size(model%rigid_bodies(b)%nodes)
        state%angular_velocity(:, model%rigid_bodies(b)%nodes(k)) = state%rigid(b)%angular_velocity
      end do
    end do
  end subroutine rotate_with_rigid_bodies

  !> Shells have no stiffness about their normal, so the nodes' rotation about it (drilling)
  !> means nothing; left free, it can be fed where a node's shells tilt as they bend (a node of
  !> a single element keeps a free direction that turns with the element) and spin up. Where a
  !> node's shells are nearly coplanar (their area-weighted normals agree within about 20
  !> degrees: not at folds, corners or T-joints, where one shell's drilling is another's
  !> bending) the half-step angular velocity loses its component along the mean normal. The
  !> constraint's impulse J = -I (w . n) n does the work J . (w^{n-1/2} + w^{n+1/2}) / 2, booked
  !> as external work like a support's. Rotations fixed by an SPC are left out of n (a node
  !> whose drilling direction is mostly fixed keeps its rates).
  subroutine remove_drilling_rates(state, average_step, work)
    type(explicit_state_t), intent(inout) :: state
    real(wp), intent(in) :: average_step        !< the step of the velocity update just done
    real(wp), intent(out) :: work
    real(wp), parameter :: coplanar = 0.94_wp   ! cos 20 degrees
    real(wp) :: normal(3), length, drilling, previous(3)
    integer :: node, chunk
    ! the work is summed over fixed chunks of nodes, then chunk by chunk: the same sum for any
    ! thread count (an OpenMP reduction would add in an order that depends on it)
    associate (partial => state%chunk_sums(1, :))
      !$omp parallel do schedule(static) default(shared) private(chunk, node, normal, length, drilling, previous)
      do chunk = 1, size(partial)
        partial(chunk) = 0.0_wp
        do node = (chunk - 1)*sum_chunk_size + 1, min(chunk*sum_chunk_size, state%node_count)
          if (state%rotary_inertia(node) <= 0.0_wp .or. state%shell_area_sum(node) <= 0.0_wp) cycle
          length = norm2(state%shell_normal_sum(:, node))
          if (length < coplanar*state%shell_area_sum(node)) cycle
          ! within the rotations an SPC leaves free (fixed ones stay zero)
          normal = merge(0.0_wp, state%shell_normal_sum(:, node)/length, state%fixed_rotation(:, node))
          length = dot_product(normal, normal)
          if (length < 0.25_wp) cycle
          normal = normal/sqrt(length)
          drilling = dot_product(state%angular_velocity(:, node), normal)
          previous = state%angular_velocity(:, node) - average_step*state%angular_acceleration(:, node)
          state%angular_velocity(:, node) = state%angular_velocity(:, node) - drilling*normal
          partial(chunk) = partial(chunk) - 0.5_wp*state%rotary_inertia(node)*drilling*dot_product(previous, normal)
        end do
      end do
      !$omp end parallel do
      work = sum_in_order(partial)
    end associate
  end subroutine remove_drilling_rates

  !> v^{n+1/2} = v^{n-1/2} + a^n (dt^{n-1/2} + dt^{n+1/2}) / 2, and the same for the angular
  !> velocities (their rotations need no update: the shells take their frame from the nodes).
  subroutine update_velocities(state, average_step)
    type(explicit_state_t), intent(inout) :: state
    real(wp), intent(in) :: average_step
    integer :: node
    !$omp parallel do schedule(static) default(shared) private(node)
    do node = 1, state%node_count
      state%velocity(:, node) = state%velocity(:, node) + average_step*state%acceleration(:, node)
      state%angular_velocity(:, node) = state%angular_velocity(:, node) + &
                                        average_step*state%angular_acceleration(:, node)
    end do
    !$omp end parallel do
  end subroutine update_velocities

  !> u^{n+1} = u^n + dt v^{n+1/2}; x = X + u.
  subroutine update_positions(state, step)
    type(explicit_state_t), intent(inout) :: state
    real(wp), intent(in) :: step
    integer :: node
    !$omp parallel do schedule(static) default(shared) private(node)
    do node = 1, state%node_count
      state%displacement(:, node) = state%displacement(:, node) + step*state%velocity(:, node)
      state%coordinates(:, node) = state%reference(:, node) + state%displacement(:, node)
    end do
    !$omp end parallel do
  end subroutine update_positions

  !> Whether a meshfree block's stable step is NaN (the comparisons that find the smallest skip it).
  logical function meshfree_step_not_a_number(state)
    type(explicit_state_t), intent(in) :: state
    integer :: k
    meshfree_step_not_a_number = .false.
    do k = 1, size(state%efg)
      if (any(state%efg(k)%block_time_step /= state%efg(k)%block_time_step)) meshfree_step_not_a_number = .true.
    end do
  end function meshfree_step_not_a_number

  !> Next step: TSSFAC times the smallest stable element step, cut so that the last step ends
  !> at ENDTIM (never below |DT2MS| times TSSFAC
  !> while mass scaling holds it there); DTINIT caps the first step.
  subroutine select_time_step(model, state, is_first)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    logical, intent(in) :: is_first
    integer :: b, k, critical
    real(wp) :: smallest
    smallest = huge(1.0_wp)
    critical = 0
    do b = 1, size(state%blocks)
      if (state%block_time_step(b) < smallest) then
        smallest = state%block_time_step(b)
        critical = state%block_critical_element(b)
      end if
    end do
    do b = 1, size(state%shells)
      if (state%shell_time_step(b) < smallest) then
        smallest = state%shell_time_step(b)
        critical = -state%shell_critical_element(b)
      end if
    end do
    ! meshfree integration points follow the FE rule of their background cell
    do k = 1, size(state%efg)
      do b = 1, size(state%efg(k)%blocks)
        if (state%efg(k)%block_time_step(b) < smallest) then
          smallest = state%efg(k)%block_time_step(b)
          critical = state%efg(k)%geometry%point_cell(state%efg(k)%block_critical_point(b))
        end if
      end do
    end do
    ! rigid elements: the step of an elastic element with their E, PR and RO (constant)
    if (state%rigid_time_step < smallest) then
      smallest = state%rigid_time_step
      critical = 0
    end if
    state%stable_time_step = smallest
    state%next_time_step = model%time_step_scale*smallest
    state%controlling_element = critical
    if (is_first .and. model%initial_time_step > 0.0_wp) &
      state%next_time_step = min(state%next_time_step, model%initial_time_step)
    ! a step that no element set, or a NaN that the comparisons above skipped, is not a step
    if (smallest >= huge(1.0_wp) .or. any(state%block_time_step /= state%block_time_step) .or. &
        any(state%shell_time_step /= state%shell_time_step) .or. &
        state%rigid_time_step /= state%rigid_time_step .or. meshfree_step_not_a_number(state)) then
      state%next_time_step = -huge(1.0_wp)
      state%stable_time_step = -huge(1.0_wp)
    end if
    ! the last step ends at ENDTIM; at ENDTIM the energies of the last state take the step just
    ! taken as the next one (the run does not go on; TSSFAC times the stable step may be
    ! meaningless, as with a TSSFAC far above 1)
    if (model%end_time > state%time) then
      state%next_time_step = min(state%next_time_step, model%end_time - state%time)
    else if (.not. is_first) then
      state%next_time_step = min(state%next_time_step, state%time_step)
    end if
  end subroutine select_time_step

end module explicit_solver
