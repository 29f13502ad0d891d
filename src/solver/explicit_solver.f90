!> The explicit time loop (central difference), as a short sequence of named steps:
!> velocities -> kinematic conditions and walls -> positions -> element forces -> contact ->
!> external loads -> accelerations -> next time step -> output.
module explicit_solver
  use kinds, only: wp
  use fixed_order_sum, only: sum_chunk_size, chunk_count, sum_in_order
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
  use run_output, only: output_plan_t, plan_output, write_due_output
  use history_buffer, only: history_set_t
  use results_file, only: results_file_t
  use run_summary, only: run_summary_t
  use progress_report, only: progress_t, start_progress, report_progress
  use wall_clock, only: phase_timer_t, start_phase, stop_phase
  implicit none
  private

  public :: run_explicit

contains

  !> Run from t = 0 to the end time (or end cycle). On a run-time error (inverted element,
  !> non-finite state) the last state is written and `error` says what, where and when.
  subroutine run_explicit(model, state, results, summary, error)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    type(results_file_t), intent(inout) :: results
    type(run_summary_t), intent(inout) :: summary
    type(error_t), allocatable, intent(out) :: error
    type(history_set_t) :: histories
    type(output_plan_t) :: plan
    type(progress_t) :: progress
    type(phase_timer_t) :: element_timer, shell_timer, meshfree_timer, output_timer, contact_timer
    type(error_t), allocatable :: output_error
    real(wp) :: previous_step, step, work, cylinder_work
    logical :: finished, wrote_state

    call plan_output(model, histories, plan)

    ! cycle 0: forces and accelerations of the initial state
    call start_phase(element_timer)
    call compute_element_forces(model, state, 0.0_wp)
    call stop_phase(element_timer)
    call start_phase(shell_timer)
    call compute_shell_forces(model, state, 0.0_wp)
    call stop_phase(shell_timer)
    call start_phase(meshfree_timer)
    call compute_meshfree_forces(model, state, 0.0_wp)
    call stop_phase(meshfree_timer)
    call assemble_nodal_loads(model, 0.0_wp, state%external_force)
    call compute_accelerations(state)
    call hold_prescribed_accelerations(model, 0.0_wp, state%acceleration, state%free_acceleration)
    call select_time_step(model, state, is_first=.true.)
    call update_energy_totals(model, state)
    state%energy%initial_total = total_energy(state)
    call check_state(model, state, error)
    finished = allocated(error) .or. model%end_time <= 0.0_wp .and. model%end_cycle <= 0
    call start_phase(output_timer)
    call write_due_output(model, state, plan, histories, results, finished, wrote_state, output_error)
    call stop_phase(output_timer)
    if (allocated(output_error)) then
      finished = .true.
      if (.not. allocated(error)) call move_alloc(output_error, error)
    end if
    call start_progress(progress, model%end_time, model%end_cycle)
    previous_step = 0.0_wp

    do while (.not. finished)
      step = state%next_time_step
      ! velocities at the half step, then the supports and walls correct them
      call update_velocities(state, 0.5_wp*(previous_step + step))
      if (size(state%shells) > 0) then
        call remove_drilling_rates(state, 0.5_wp*(previous_step + step), work)
        state%energy%external_work = state%energy%external_work + work
      end if
      call impose_kinematic_conditions(model, state%fixed, state%time, step, 0.5_wp*(previous_step + step), &
                                       state%displacement, state%acceleration, state%free_acceleration, &
                                       state%mass, state%velocity, work)
      state%energy%external_work = state%energy%external_work + work
      if (size(model%walls) > 0) then
        call start_phase(contact_timer)
        call enforce_planar_walls(model%walls, state%walls, state%time, step, 0.5_wp*(previous_step + step), &
                                  state%coordinates, state%acceleration, state%mass, &
                                  state%velocity, work)
        state%energy%rigid_wall = state%energy%rigid_wall + work
        call enforce_cylinder_walls(model%walls, model%curves, state%walls, state%time, step, &
                                    0.5_wp*(previous_step + step), state%coordinates, state%acceleration, &
                                    state%mass, state%velocity, work, cylinder_work)
        call stop_phase(contact_timer)
        state%energy%rigid_wall = state%energy%rigid_wall + work
        state%energy%external_work = state%energy%external_work + cylinder_work
      end if
      if (size(state%rigid) > 0) then
        call advance_rigid_bodies(model, state%rigid, state%time, step, 0.5_wp*(previous_step + step), &
                                  state%coordinates, state%velocity, work)
        state%energy%external_work = state%energy%external_work + work
        if (size(state%shells) > 0) call rotate_with_rigid_bodies(model, state)
      end if
      call update_positions(state, step)
      state%energy%external_work = state%energy%external_work + &
                                   0.5_wp*load_work(model, state%external_force, state%velocity, step)
      state%time = state%time + step
      state%time_step = step
      state%cycle = state%cycle + 1
      previous_step = step

      call start_phase(element_timer)
      call compute_element_forces(model, state, step)
      call stop_phase(element_timer)
      call start_phase(shell_timer)
      call compute_shell_forces(model, state, step)
      call stop_phase(shell_timer)
      call start_phase(meshfree_timer)
      call compute_meshfree_forces(model, state, step)
      call stop_phase(meshfree_timer)
      if (size(state%contacts) > 0) then
        call start_phase(contact_timer)
        call compute_contact_forces(model, state%contacts, state%time, step, state%coordinates, state%velocity, &
                                    state%mass, state%contact_force, work)
        call stop_phase(contact_timer)
        state%energy%contact = state%energy%contact + work
        call report_initial_penetrations(model, state%contacts, state%time)
      end if
      call assemble_nodal_loads(model, state%time, state%external_force)
      state%energy%external_work = state%energy%external_work + &
                                   0.5_wp*load_work(model, state%external_force, state%velocity, step)
      call compute_accelerations(state)
      call hold_prescribed_accelerations(model, state%time, state%acceleration, state%free_acceleration)
      call select_time_step(model, state, is_first=.false.)
      call check_state(model, state, error)

      finished = allocated(error) .or. state%time >= model%end_time*(1.0_wp - 1.0e-12_wp) .or. &
                 (model%end_cycle > 0 .and. state%cycle >= model%end_cycle)
      call start_phase(output_timer)
      call write_due_output(model, state, plan, histories, results, finished, wrote_state, output_error)
      call stop_phase(output_timer)
      if (allocated(output_error)) exit
      call report_progress(progress, state%cycle, state%time, step, finished)
    end do

    if (allocated(output_error) .and. .not. allocated(error)) call move_alloc(output_error, error)
    summary%end_time = state%time
    summary%cycles = state%cycle
    summary%fe_solid_s = element_timer%seconds
    summary%fe_shell_s = shell_timer%seconds
    summary%efg_s = meshfree_timer%seconds
    summary%contact_s = contact_timer%seconds
    summary%output_s = output_timer%seconds
    summary%tangled_solids = plan%distortion%tangled
    summary%worst_corner_jacobian_ratio = plan%distortion%worst_ratio
    if (plan%distortion%worst_element > 0) &
      summary%worst_corner_jacobian_element = model%solid_ids(plan%distortion%worst_element)
  end subroutine run_explicit

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
    real(wp) :: partial(chunk_count(state%node_count))
    integer :: node, chunk
    ! the work is summed over fixed chunks of nodes, then chunk by chunk: the same sum for any
    ! thread count (an OpenMP reduction would add in an order that depends on it)
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

  !> Next step: TSSFAC times the smallest stable element step (never below |DT2MS| times TSSFAC
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
    state%next_time_step = model%time_step_scale*smallest
    state%controlling_element = critical
    if (is_first .and. model%initial_time_step > 0.0_wp) &
      state%next_time_step = min(state%next_time_step, model%initial_time_step)
    ! a step that no element set, or a NaN that the comparisons above skipped, is not a step
    if (smallest >= huge(1.0_wp) .or. any(state%block_time_step /= state%block_time_step) .or. &
        any(state%shell_time_step /= state%shell_time_step)) &
      state%next_time_step = -huge(1.0_wp)
  end subroutine select_time_step

  !> Run-time failures, found after the parallel loops: an inverted element or a state that
  !> is no longer finite.
  subroutine check_state(model, state, error)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    type(error_t), allocatable, intent(out) :: error
    integer :: b, k, element, point
    character(len=256) :: text
    do b = 1, size(state%blocks)
      element = state%block_inverted_element(b)
      if (element == 0) cycle
      write (text, '(a,i0,a,i0,a,es12.5,a,i0)') "negative volume in solid element ", model%solid_ids(element), &
        " (part ", model%parts(model%solid_part(element))%id, ") at time ", state%time, ", cycle ", state%cycle
      call make_error(error, trim(text))
      return
    end do
    do b = 1, size(state%shells)
      element = state%shell_degenerate_element(b)
      if (element == 0) cycle
      write (text, '(a,i0,a,i0,a,es12.5,a,i0)') "shell element ", model%shell_ids(element), " (part ", &
        model%parts(model%shell_part(element))%id, ") has lost its area at time ", state%time, ", cycle ", state%cycle
      call make_error(error, trim(text))
      return
    end do
    do k = 1, size(state%efg)
      do b = 1, size(state%efg(k)%blocks)
        point = state%efg(k)%block_inverted_point(b)
        if (point == 0) cycle
        element = state%efg(k)%geometry%point_cell(point)
        write (text, '(a,i0,a,i0,a,es12.5,a,i0)') "negative volume at an integration point of meshfree part ", &
          model%parts(state%efg(k)%geometry%part)%id, " (background cell ", model%solid_ids(element), &
          ") at time ", state%time, ", cycle ", state%cycle
        call make_error(error, trim(text))
        return
      end do
    end do
    ! rigid bodies set no element step: their motion must be finite too
    do b = 1, size(state%rigid)
      if (all(abs(state%rigid(b)%velocity) < huge(1.0_wp)) .and. &
          all(abs(state%rigid(b)%angular_velocity) < huge(1.0_wp))) cycle
      write (text, '(a,i0,a,es12.5,a,i0)') "the motion of rigid body ", model%rigid_bodies(b)%id, &
        " is no longer finite at time ", state%time, ", cycle ", state%cycle
      call make_error(error, trim(text))
      return
    end do
    if (.not. (state%next_time_step > 0.0_wp .and. state%next_time_step < huge(1.0_wp))) then
      element = state%controlling_element
      if (element < 0) then
        write (text, '(a,i0,a,i0,a,es12.5,a,i0)') "no finite stable time step (the smallest is set by shell ", &
          model%shell_ids(-element), ", part ", model%parts(model%shell_part(-element))%id, ") at time ", &
          state%time, ", cycle ", state%cycle
      else if (element > 0) then
        write (text, '(a,i0,a,i0,a,es12.5,a,i0)') "no finite stable time step (the smallest is set by element ", &
          model%solid_ids(element), ", part ", model%parts(model%solid_part(element))%id, ") at time ", &
          state%time, ", cycle ", state%cycle
      else
        write (text, '(a,es12.5,a,i0,a)') "no finite stable time step at time ", state%time, ", cycle ", &
          state%cycle, ": the state is no longer finite"
      end if
      call make_error(error, trim(text))
    end if
  end subroutine check_state
end module explicit_solver
