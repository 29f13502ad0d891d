!> The explicit time loop (central differences) as a list of named phases, in the manner of
!> LULESH's LagrangeLeapFrog. One cycle from t^n to t^{n+1}:
!>
!>   advance_velocities       v^{n+1/2} = v^{n-1/2} + dt a^n (and the shells' drilling rates removed)
!>   impose_constraints       supports and prescribed motions
!>   enforce_walls            rigid walls (planar, cylinders)
!>   advance_rigid_bodies     rigid bodies and the shell nodes that turn with them
!>   advance_positions        x^{n+1} = x^n + dt v^{n+1/2}; the clock
!>   internal_forces          every element group, in one call that clears and fills
!>   erode_elements           the elements that failed in that call: masks, messages, counts
!>   contact_forces           penalty contacts
!>   external_forces          nodal loads at t^{n+1}
!>   accelerations            a = (f_ext - f_int + f_contact) / m (a distributed run: at the nodes
!>                            each rank owns, then exchanged), prescribed motions held, tied
!>                            contacts (tied nodes move with their segments)
!>   next_time_step           TSSFAC times the smallest stable step, cut at ENDTIM
!>   state checks             runaway motion, failed elements, time step, energy (run_checks)
!>   output                   whatever the output plan says is due (run_output)
!>
!> Cycle 0 runs the phases from internal_forces to the checks on the initial state (start_run).
!> Each phase owns its timer and books its share of energy in the state's ledger
!> (state%energy). The run itself, cycle after cycle with the output and the stop signals in
!> between, is driven from above (app/explicit_run): the physics does not know the files.
module explicit_solver
  use kinds, only: wp
  use message_log, only: log_message
  use fixed_order_sum, only: sum_chunk_size, sum_in_order
  use error_handling, only: error_t
  use model, only: model_t
  use nodal_state, only: nodal_state_t
  use explicit_state, only: explicit_state_t
  use run_state, only: run_state_t, phase_count, phase_velocities, phase_constraints, phase_walls, phase_rigid_bodies, &
                       phase_positions, phase_internal_forces, phase_contact, phase_external_forces, &
                       phase_accelerations, phase_time_step, phase_checks, phase_output, phase_erosion, phase_names
  use element_groups, only: compute_internal_forces, smallest_group_step, eroded_element_masks
  use contact_erosion, only: remove_eroded_elements
  use boundary_conditions, only: assemble_nodal_loads, load_work, impose_kinematic_conditions, &
                                 hold_prescribed_accelerations
  use planar_rigid_walls, only: enforce_planar_walls
  use cylinder_walls, only: enforce_cylinder_walls
  use rigid_bodies, only: advance_rigid_bodies
  use spot_weld_constraints, only: advance_spot_welds
  use tied_contact, only: distribute_tied_nodes, follow_segments
  use penalty_contact, only: find_contact_pairs, apply_contact_pairs, report_initial_penetrations
  use energy_balance, only: measured_energies, total_energy
  use run_checks, only: set_up_run_checks, check_runaway_motion, check_elements, check_time_step, check_energy, &
                        energy_check_interval
  use output_plan, only: clock_is_due
  use run_summary, only: run_summary_t
  use text_format, only: integer_text
  use wall_clock, only: start_phase, stop_phase
  use domain_exchange, only: domain_exchange_t, exchange_accelerations, combine_group_headers, &
                             share_block_energies, exchange_contact_pairs
  use rank_communication, only: largest_over_ranks, gather_fixed_reals
  implicit none
  private

  public :: start_run, advance_and_check, reached_end, check_distortion, summarise

contains

  !> Cycle 0: the checks of the initial motion and of mass scaling, then the force phases on the
  !> initial state, the initial energy and the checks of its state.
  subroutine start_run(model, run, error)
    type(model_t), intent(in) :: model
    type(run_state_t), intent(inout) :: run
    type(error_t), allocatable, intent(out) :: error
    call set_up_run_checks(model, run%state, error)
    if (.not. allocated(error)) call check_runaway_motion(model, run%state, 0.0_wp, error)
    if (allocated(error)) return
    call forces_and_next_step(model, run, 0.0_wp)
    call share_block_energies(run%state%groups, run%partition, run%exchange, run%state%cycle)
    call measured_energies(model, run%state, run%energy_scratch, run%state%energy)
    run%state%energy%initial_total = total_energy(run%state%energy)
    call check_state(model, run, .true., error)
  end subroutine start_run

  !> One cycle and its checks, unless the motion the next velocity update would give is already
  !> beyond any physical run; `finished` when it reached ENDTIM or ENDCYC.
  subroutine advance_and_check(model, run, finished, error)
    type(model_t), intent(in) :: model
    type(run_state_t), intent(inout) :: run
    logical, intent(out) :: finished
    type(error_t), allocatable, intent(out) :: error
    finished = .false.
    call check_runaway_motion(model, run%state, 0.5_wp*(run%state%time_step + run%state%next_time_step), error)
    if (allocated(error)) return
    call advance_one_cycle(model, run)
    finished = reached_end(model, run%state)
    call check_state(model, run, finished, error)
  end subroutine advance_and_check

  !> Whether the run has reached ENDTIM (to round-off) or ENDCYC.
  logical function reached_end(model, state)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    reached_end = state%time >= model%end_time*(1.0_wp - 1.0e-12_wp) .or. &
                  (model%end_cycle > 0 .and. state%cycle >= model%end_cycle)
  end function reached_end

  !> One central-difference cycle from t^n to t^{n+1} = t^n + dt, dt = state%next_time_step.
  subroutine advance_one_cycle(model, run)
    type(model_t), intent(in) :: model
    type(run_state_t), intent(inout) :: run
    real(wp) :: step, average_step
    step = run%state%next_time_step
    average_step = 0.5_wp*(run%state%time_step + step)
    call start_phase(run%timers(phase_velocities))
    call release_failed_weld_nodes(model, run%state)
    call advance_velocities(run%state, average_step)
    call stop_phase(run%timers(phase_velocities))
    call start_phase(run%timers(phase_constraints))
    call impose_constraints(model, run%state, step, average_step)
    call stop_phase(run%timers(phase_constraints))
    call start_phase(run%timers(phase_walls))
    call enforce_walls(model, run%state, step, average_step)
    call stop_phase(run%timers(phase_walls))
    call start_phase(run%timers(phase_rigid_bodies))
    call move_rigid_bodies(model, run%state, step, average_step)
    call stop_phase(run%timers(phase_rigid_bodies))
    call start_phase(run%timers(phase_positions))
    call advance_positions(model, run%state, step)
    call stop_phase(run%timers(phase_positions))
    call forces_and_next_step(model, run, step)
  end subroutine advance_one_cycle

  !> The phases at t^{n+1} (also cycle 0's, with step 0): internal, contact and external forces,
  !> accelerations and the next step.
  subroutine forces_and_next_step(model, run, step)
    type(model_t), intent(in) :: model
    type(run_state_t), intent(inout) :: run
    real(wp), intent(in) :: step           !< the step just taken (0 at cycle 0)
    call start_phase(run%timers(phase_internal_forces))
    call compute_internal_forces(model, run%state%groups, run%state%nodes, step)
    call stop_phase(run%timers(phase_internal_forces))
    ! a distributed run: the groups' headers made global (each rank's forces are complete at the
    ! nodes it owns; the accelerations of those go to every rank below)
    call combine_group_headers(run%state%groups, run%partition, run%exchange, run%state%cycle)
    call start_phase(run%timers(phase_erosion))
    call erode_elements(model, run%state)
    call stop_phase(run%timers(phase_erosion))
    call start_phase(run%timers(phase_contact))
    call contact_forces(model, run%state, run%exchange, step)
    call stop_phase(run%timers(phase_contact))
    call start_phase(run%timers(phase_external_forces))
    call external_forces(model, run%state, step)
    call stop_phase(run%timers(phase_external_forces))
    call start_phase(run%timers(phase_accelerations))
    call nodal_accelerations(run%state%nodes, run%exchange)
    call stop_phase(run%timers(phase_accelerations))
    ! a distributed run: the owned nodes' accelerations (and the shells' normal sums) to every rank
    call exchange_accelerations(run%state%nodes, run%exchange)
    call start_phase(run%timers(phase_accelerations))
    call constrain_accelerations(model, run%state)
    call stop_phase(run%timers(phase_accelerations))
    call start_phase(run%timers(phase_time_step))
    call next_time_step(model, run%state)
    call stop_phase(run%timers(phase_time_step))
  end subroutine forces_and_next_step

  !> Erosion phase, after the force call in which elements failed (the groups took them out of
  !> their force loops there: element_group). Keeps the model-indexed masks `solid_eroded` and
  !> `shell_eroded` (allocated at the first call, also after a restart, from the groups' own
  !> masks), sets `eroded_this_cycle`, counts, and writes one line per eroded element as
  !> LS-DYNA's messag file does. With *CONTROL_TIMESTEP ERODE the groups get their erosion step,
  !> DTMIN times the first step (before TSSFAC), once that step is known. The energy eroded
  !> elements took along is measured with the others (energy_balance), nothing is booked here.
  subroutine erode_elements(model, state)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    integer, allocatable :: elements(:)
    integer :: k, n
    character(len=24) :: time_text
    if (.not. allocated(state%solid_eroded)) &
      call eroded_element_masks(model, state%groups, state%solid_eroded, state%shell_eroded)
    if (state%watch%first_time_step > 0.0_wp .and. model%minimum_time_step_factor > 0.0_wp .and. &
        (model%erode_solids_on_step .or. model%erode_shells_on_step)) then
      do k = 1, size(state%groups)
        state%groups(k)%group%erosion_time_step = model%minimum_time_step_factor*state%watch%first_time_step &
                                                  /model%time_step_scale
      end do
    end if
    state%eroded_this_cycle = .false.
    state%eroded_count = 0
    do k = 1, size(state%groups)
      state%eroded_count = state%eroded_count + state%groups(k)%group%eroded_count
      if (state%groups(k)%group%newly_eroded == 0) cycle
      state%eroded_this_cycle = .true.
      call state%groups(k)%group%mark_eroded(state%solid_eroded, state%shell_eroded)
      elements = state%groups(k)%group%newly_eroded_elements()
      write (time_text, '(es12.5)') state%time
      do n = 1, size(elements)
        call log_message(state%messages, state%groups(k)%group%describe(model, elements(n))//" failed at time "// &
                         trim(adjustl(time_text))//", cycle "//integer_text(state%cycle))
      end do
    end do
    ! the contacts drop the eroded elements' segments before their forces of this cycle
    if (state%eroded_this_cycle) &
      call remove_eroded_elements(model, state%contacts, state%solid_eroded, state%shell_eroded)
  end subroutine erode_elements

  !> v^{n+1/2} = v^{n-1/2} + a^n (dt^{n-1/2} + dt^{n+1/2}) / 2, and the same for the angular
  !> velocities (their rotations need no update: the shells take their frame from the nodes);
  !> then the shells' drilling rates go (remove_drilling_rates).
  subroutine advance_velocities(state, average_step)
    type(explicit_state_t), intent(inout) :: state
    real(wp), intent(in) :: average_step
    integer :: node
    associate (nodes => state%nodes)
      !$omp parallel do schedule(static) default(shared) private(node)
      do node = 1, nodes%count
        nodes%velocity(:, node) = nodes%velocity(:, node) + average_step*nodes%acceleration(:, node)
      end do
      !$omp end parallel do
      ! (no node accelerates its rotations in a model without shells)
      if (.not. nodes%rotational) return
      !$omp parallel do schedule(static) default(shared) private(node)
      do node = 1, nodes%count
        nodes%angular_velocity(:, node) = nodes%angular_velocity(:, node) + &
                                          average_step*nodes%angular_acceleration(:, node)
      end do
      !$omp end parallel do
    end associate
    call remove_drilling_rates(state, average_step)
  end subroutine advance_velocities

  !> Shells have no stiffness about their normal, so the nodes' rotation about it (drilling)
  !> means nothing; left free, it can be fed where a node's shells tilt as they bend (a node of
  !> a single element keeps a free direction that turns with the element) and spin up. Where a
  !> node's shells are nearly coplanar (their area-weighted normals agree within about 20
  !> degrees: not at folds, corners or T-joints, where one shell's drilling is another's
  !> bending) the half-step angular velocity loses its component along the mean normal. The
  !> constraint's impulse J = -I (w . n) n does the work J . (w^{n-1/2} + w^{n+1/2}) / 2, booked
  !> as external work like a support's. Rotations fixed by an SPC are left out of n (a node
  !> whose drilling direction is mostly fixed keeps its rates).
  subroutine remove_drilling_rates(state, average_step)
    type(explicit_state_t), intent(inout) :: state
    real(wp), intent(in) :: average_step        !< the step of the velocity update just done
    real(wp), parameter :: coplanar = 0.94_wp   ! cos 20 degrees
    real(wp) :: normal(3), length, drilling, previous(3)
    integer :: node, chunk
    ! the work is summed over fixed chunks of nodes, then chunk by chunk: the same sum for any
    ! thread count (an OpenMP reduction would add in an order that depends on it)
    associate (partial => state%chunk_sums(1, :), nodes => state%nodes)
      !$omp parallel do schedule(static) default(shared) private(chunk, node, normal, length, drilling, previous)
      do chunk = 1, size(partial)
        partial(chunk) = 0.0_wp
        do node = (chunk - 1)*sum_chunk_size + 1, min(chunk*sum_chunk_size, nodes%count)
          if (nodes%rotary_inertia(node) <= 0.0_wp .or. nodes%shell_area_sum(node) <= 0.0_wp) cycle
          ! a rigid body or weld sets the rotation of its nodes (and takes their moments)
          if (nodes%is_rigid_node(node) .or. state%held_by_weld(node)) cycle
          length = norm2(nodes%shell_normal_sum(:, node))
          if (length < coplanar*nodes%shell_area_sum(node)) cycle
          ! within the rotations an SPC leaves free (fixed ones stay zero)
          normal = merge(0.0_wp, nodes%shell_normal_sum(:, node)/length, nodes%fixed_rotation(:, node))
          length = dot_product(normal, normal)
          if (length < 0.25_wp) cycle
          normal = normal/sqrt(length)
          drilling = dot_product(nodes%angular_velocity(:, node), normal)
          previous = nodes%angular_velocity(:, node) - average_step*nodes%angular_acceleration(:, node)
          nodes%angular_velocity(:, node) = nodes%angular_velocity(:, node) - drilling*normal
          partial(chunk) = partial(chunk) - 0.5_wp*nodes%rotary_inertia(node)*drilling*dot_product(previous, normal)
        end do
      end do
      !$omp end parallel do
      state%energy%external_work = state%energy%external_work + sum_in_order(partial)
    end associate
  end subroutine remove_drilling_rates

  !> SPCs and prescribed motions set their dofs' half-step velocities; the kinetic energy they
  !> add is external work.
  subroutine impose_constraints(model, state, step, average_step)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    real(wp), intent(in) :: step, average_step
    real(wp) :: work
    call impose_kinematic_conditions(model, state%nodes%fixed, state%time, step, average_step, &
                                     state%nodes%displacement, state%nodes%acceleration, state%free_acceleration, &
                                     state%nodes%mass, state%nodes%velocity, work)
    state%energy%external_work = state%energy%external_work + work
  end subroutine impose_constraints

  !> Rigid walls stop the nodes that would pass them, meshfree particles by their physical
  !> position and velocity (the rows of state%rows): the energy they take is the rigid-wall
  !> energy; a cylinder's prescribed motion does external work.
  subroutine enforce_walls(model, state, step, average_step)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    real(wp), intent(in) :: step, average_step
    real(wp) :: work, cylinder_work
    if (size(model%walls) == 0) return
    call enforce_planar_walls(model%walls, state%rows, state%walls, state%time, step, average_step, &
                              state%nodes%reference, state%nodes%displacement, state%nodes%coordinates, &
                              state%nodes%acceleration, state%nodes%mass, state%nodes%velocity, work)
    state%energy%rigid_wall = state%energy%rigid_wall + work
    call enforce_cylinder_walls(model%walls, model%curves, state%rows, state%walls, state%time, step, average_step, &
                                state%nodes%reference, state%nodes%displacement, state%nodes%coordinates, &
                                state%nodes%acceleration, state%nodes%mass, state%nodes%velocity, work, cylinder_work)
    state%energy%rigid_wall = state%energy%rigid_wall + work
    state%energy%external_work = state%energy%external_work + cylinder_work
  end subroutine enforce_walls

  !> Rigid bodies move their nodes (their prescribed motions and constraints do external work);
  !> shell nodes of a body turn with it, and the moments that deformable shells put on such
  !> nodes act on the body (rigid_bodies). Then the spot welds that hold move their nodes as
  !> small rigid bodies and fail by their forces or time (spot_weld_constraints).
  subroutine move_rigid_bodies(model, state, step, average_step)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    real(wp), intent(in) :: step, average_step
    real(wp) :: work
    integer :: b, k
    if (size(state%rigid) > 0) then
      call advance_rigid_bodies(model, state%rigid, state%time, step, average_step, state%nodes%coordinates, &
                                state%nodes%angular_acceleration, state%nodes%rotary_inertia, state%nodes%velocity, &
                                work)
      state%energy%external_work = state%energy%external_work + work
      do b = 1, size(state%rigid)
        do k = 1, size(model%rigid_bodies(b)%nodes)
          state%nodes%angular_velocity(:, model%rigid_bodies(b)%nodes(k)) = state%rigid(b)%angular_velocity
        end do
      end do
    end if
    if (size(state%welds) == 0) return
    ! welds that fail by plastic strain: the largest of the shells on their nodes
    if (any(model%spot_welds%failure_plastic_strain > 0.0_wp)) then
      where (state%plastic_weld_node) state%weld_node_plastic_strain = 0.0_wp
      do k = 1, size(state%groups)
        call state%groups(k)%group%raise_nodal_plastic_strain(model, state%plastic_weld_node, &
                                                              state%weld_node_plastic_strain)
      end do
      ! a distributed run: each rank raised with the blocks it computes (a maximum: exact)
      call largest_over_ranks(state%weld_node_plastic_strain)
    end if
    call advance_spot_welds(model, state%welds, state%time, step, average_step, state%nodes%coordinates, &
                            state%nodes%angular_acceleration, state%nodes%rotary_inertia, state%nodes%velocity, &
                            state%nodes%angular_velocity, state%weld_node_plastic_strain, state%messages)
  end subroutine move_rigid_bodies

  !> The nodes of failed welds are free (drilling constraint included) from the step after the
  !> failure; set before the velocity update, so that a run continued from a dump does the same.
  subroutine release_failed_weld_nodes(model, state)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    integer :: w
    do w = 1, size(state%welds)
      if (state%welds(w)%failed) state%held_by_weld(model%spot_welds(w)%nodes) = .false.
    end do
  end subroutine release_failed_weld_nodes

  !> u^{n+1} = u^n + dt v^{n+1/2}; x = X + u; the loads' work over the first half of the step;
  !> the clock moves to t^{n+1} (the step cut at ENDTIM lands on it exactly).
  subroutine advance_positions(model, state, step)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    real(wp), intent(in) :: step
    integer :: node
    associate (nodes => state%nodes)
      !$omp parallel do schedule(static) default(shared) private(node)
      do node = 1, nodes%count
        nodes%displacement(:, node) = nodes%displacement(:, node) + step*nodes%velocity(:, node)
        nodes%coordinates(:, node) = nodes%reference(:, node) + nodes%displacement(:, node)
      end do
      !$omp end parallel do
      state%energy%external_work = state%energy%external_work + &
                                   0.5_wp*load_work(model, nodes%external_force, nodes%velocity, step)
    end associate
    state%time = state%time + step
    if (model%end_time > 0.0_wp .and. state%time > model%end_time) state%time = model%end_time
    state%time_step = step
    state%cycle = state%cycle + 1
  end subroutine advance_positions

  !> Penalty contact forces at t^{n+1} and their energy (initial penetrations are reported once).
  !> Meshfree particles take part with their physical values: the contacts see x = X + A d and
  !> A v, and their forces f on those come back to the generalized unknowns as A^T f (the
  !> groups' to_physical and forces_to_generalized; consistent, and momentum is kept because the
  !> rows of A sum to one). Contact energy is the work on the physical motion, which A^T makes
  !> the same as on the generalized one. In a distributed run each rank computes the pairs of its
  !> share of the secondary nodes, and the ranks exchange them before the forces are added
  !> (penalty_contact, domain_exchange).
  subroutine contact_forces(model, state, exchange, step)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    type(domain_exchange_t), intent(inout) :: exchange
    real(wp), intent(in) :: step
    real(wp) :: work, work_before
    integer :: k
    if (size(state%contacts) == 0) return
    if (.not. any(state%nodes%is_particle)) then
      call find_contact_pairs(model, state%contacts, state%time, step, state%nodes%coordinates, &
                              state%nodes%velocity, state%nodes%mass, work_before, exchange%rank, exchange%rank_count)
      call exchange_contact_pairs(state%contacts, exchange)
      call apply_contact_pairs(state%contacts, step, state%nodes%velocity, state%nodes%contact_force, &
                               work_before, work)
    else
      call physical_contact_values(state)
      call find_contact_pairs(model, state%contacts, state%time, step, state%contact_coordinates, &
                              state%contact_velocity, state%nodes%mass, work_before, exchange%rank, exchange%rank_count)
      call exchange_contact_pairs(state%contacts, exchange)
      call apply_contact_pairs(state%contacts, step, state%contact_velocity, state%nodes%contact_force, &
                               work_before, work)
      state%contact_physical_force = state%nodes%contact_force
      do k = 1, size(state%groups)
        call state%groups(k)%group%forces_to_generalized(state%contact_physical_force, state%nodes%contact_force)
      end do
    end if
    state%energy%contact = state%energy%contact + work
    call report_initial_penetrations(model, state%contacts, state%time, state%messages)
  end subroutine contact_forces

  !> The physical positions and velocities of every node for the contacts: the solver's values,
  !> with the meshfree groups' interior particles transformed (to_physical).
  subroutine physical_contact_values(state)
    type(explicit_state_t), intent(inout) :: state
    integer :: k, node
    associate (nodes => state%nodes)
      if (.not. allocated(state%contact_coordinates)) &
        allocate (state%contact_coordinates(3, nodes%count), state%contact_velocity(3, nodes%count), &
                  state%contact_physical_force(3, nodes%count))
      ! other nodes keep the solver's values exactly; a particle's displacement becomes its position
      state%contact_coordinates = nodes%coordinates
      state%contact_velocity = nodes%velocity
      do k = 1, size(state%groups)
        call state%groups(k)%group%to_physical(nodes%displacement, state%contact_coordinates)
        call state%groups(k)%group%to_physical(nodes%velocity, state%contact_velocity)
      end do
      do node = 1, nodes%count
        if (nodes%is_particle(node)) &
          state%contact_coordinates(:, node) = nodes%reference(:, node) + state%contact_coordinates(:, node)
      end do
    end associate
  end subroutine physical_contact_values

  !> Nodal loads at t^{n+1} and their work over the second half of the step.
  subroutine external_forces(model, state, step)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    real(wp), intent(in) :: step
    call assemble_nodal_loads(model, state%time, state%nodes%mass, state%nodes%external_force)
    state%energy%external_work = state%energy%external_work + &
                                 0.5_wp*load_work(model, state%nodes%external_force, state%nodes%velocity, step)
  end subroutine external_forces

  !> a = (f_ext - f_int + f_contact) / m, and for the rotations of shell nodes alpha = -m_int / I;
  !> constrained dofs do not accelerate. A distributed run: at the nodes this rank owns, where
  !> its internal forces are complete (the exchange then brings the others').
  subroutine nodal_accelerations(nodes, exchange)
    type(nodal_state_t), intent(inout) :: nodes
    type(domain_exchange_t), intent(in) :: exchange
    integer :: node, k, first, last
    ! (one loop for both, its body written once and inline: the hot nodal loop of the cycle)
    first = 1
    last = nodes%count
    if (exchange%rank_count > 1) then
      first = exchange%node_offsets(exchange%rank + 1)
      last = exchange%node_offsets(exchange%rank + 2) - 1
    end if
    !$omp parallel do schedule(static) default(shared) private(k, node)
    do k = first, last
      node = k
      if (exchange%rank_count > 1) node = exchange%rank_nodes(k)
      if (nodes%mass(node) > 0.0_wp) then
        nodes%acceleration(:, node) = (nodes%external_force(:, node) - nodes%internal_force(:, node) + &
                                       nodes%contact_force(:, node))/nodes%mass(node)
      else
        nodes%acceleration(:, node) = 0.0_wp
      end if
      where (nodes%fixed(:, node)) nodes%acceleration(:, node) = 0.0_wp
      if (nodes%rotary_inertia(node) > 0.0_wp) then
        nodes%angular_acceleration(:, node) = -nodes%internal_moment(:, node)/nodes%rotary_inertia(node)
      else
        nodes%angular_acceleration(:, node) = 0.0_wp
      end if
      where (nodes%fixed_rotation(:, node)) nodes%angular_acceleration(:, node) = 0.0_wp
    end do
    !$omp end parallel do
  end subroutine nodal_accelerations

  !> Tied contacts: the tied nodes' masses and forces to their segments; after the prescribed
  !> motions are held, the tied nodes move with their points of the segments (every rank alike,
  !> on every node's acceleration).
  subroutine constrain_accelerations(model, state)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    associate (nodes => state%nodes)
      call distribute_tied_nodes(model, state%ties, nodes%mass, nodes%rotary_inertia, nodes%fixed, &
                                 nodes%fixed_rotation, nodes%acceleration, nodes%angular_acceleration)
      call hold_prescribed_accelerations(model, state%time, nodes%acceleration, state%free_acceleration)
      call follow_segments(model, nodes%rotary_inertia, nodes%acceleration, nodes%angular_acceleration, &
                           nodes%velocity, nodes%angular_velocity)
    end associate
  end subroutine constrain_accelerations

  !> Next step: TSSFAC times the smallest stable step of the element groups and the rigid
  !> bodies, cut so that the last step ends at ENDTIM; DTINIT caps the first step.
  subroutine next_time_step(model, state)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    real(wp) :: smallest
    integer :: group, element
    logical :: not_finite
    call smallest_group_step(state%groups, smallest, group, element, not_finite)
    ! every element eroded: the free nodes fly on with the last stable step
    if (smallest >= huge(1.0_wp) .and. state%eroded_count > 0 .and. state%stable_time_step > 0.0_wp) &
      smallest = state%stable_time_step
    ! rigid elements: the step of an elastic element with their E, PR and RO (constant)
    if (state%rigid_time_step < smallest) then
      smallest = state%rigid_time_step
      group = 0
      element = 0
    end if
    state%stable_time_step = smallest
    state%next_time_step = model%time_step_scale*smallest
    state%controlling_group = group
    state%controlling_element = element
    if (state%cycle == 0 .and. model%initial_time_step > 0.0_wp) &
      state%next_time_step = min(state%next_time_step, model%initial_time_step)
    ! a step that no element set, or a NaN that the comparisons above skipped, is not a step
    if (smallest >= huge(1.0_wp) .or. not_finite .or. state%rigid_time_step /= state%rigid_time_step) then
      state%next_time_step = -huge(1.0_wp)
      state%stable_time_step = -huge(1.0_wp)
    end if
    ! the last step ends at ENDTIM; at ENDTIM the energies of the last state take the step just
    ! taken as the next one (the run does not go on; TSSFAC times the stable step may be
    ! meaningless, as with a TSSFAC far above 1)
    if (model%end_time > state%time) then
      state%next_time_step = min(state%next_time_step, model%end_time - state%time)
    else if (state%cycle > 0) then
      state%next_time_step = min(state%next_time_step, state%time_step)
    end if
  end subroutine next_time_step

  !> The checks after a cycle: elements, the time step, and every few cycles and at the last
  !> one the energy.
  subroutine check_state(model, run, last, error)
    type(model_t), intent(in) :: model
    type(run_state_t), intent(inout) :: run
    logical, intent(in) :: last
    type(error_t), allocatable, intent(out) :: error
    type(error_t), allocatable :: node_error
    call start_phase(run%timers(phase_checks))
    call check_elements(model, run%state, error)
    if (.not. allocated(error)) call check_time_step(model, run%state, run%state%stable_time_step, error)
    if (.not. allocated(error) .and. (last .or. mod(run%state%cycle, energy_check_interval) == 0)) then
      call share_block_energies(run%state%groups, run%partition, run%exchange, run%state%cycle)
      call check_energy(model, run%state, run%energy_scratch, error)
      ! energies gone wrong in this cycle because a node ran away: name the node, as the next
      ! cycle's check would, rather than only the energies
      if (allocated(error)) call check_runaway_motion(model, run%state, &
                                                      0.5_wp*(run%state%time_step + run%state%next_time_step), node_error)
      if (allocated(node_error)) call move_alloc(node_error, error)
    end if
    call stop_phase(run%timers(phase_checks))
  end subroutine check_state

  !> At every output state: the solids folded inside out at a corner (a warning, and the worst
  !> of the run for the summary).
  subroutine check_distortion(model, run, last)
    type(model_t), intent(in) :: model
    type(run_state_t), intent(inout) :: run
    logical, intent(in) :: last
    integer :: k
    if (.not. clock_is_due(run%plan%states, run%state%time, last)) return
    call start_phase(run%timers(phase_checks))
    do k = 1, size(run%state%groups)
      run%distortion%message = ""
      call run%state%groups(k)%group%check_distortion(model, run%state%nodes, run%state%time, run%distortion)
      if (len(run%distortion%message) > 0) call log_message(run%state%messages, run%distortion%message)
    end do
    call stop_phase(run%timers(phase_checks))
  end subroutine check_distortion

  !> The run summary's times (per element kind, contact with the walls, output; with several
  !> ranks every rank's phases, brought to all: every rank must call this) and the distortion
  !> record. (The groups' counts went in before the run, describe_model of job; their times are
  !> added here.)
  subroutine summarise(model, run, summary)
    type(model_t), intent(in) :: model
    type(run_state_t), intent(in) :: run
    type(run_summary_t), intent(inout) :: summary
    integer :: k
    summary%end_time = run%state%time
    summary%cycles = run%state%cycle
    do k = 1, size(run%state%groups)
      call run%state%groups(k)%group%add_to_summary(summary)
    end do
    summary%contact_s = run%timers(phase_contact)%seconds + run%timers(phase_walls)%seconds
    summary%output_s = run%timers(phase_output)%seconds
    summary%phase_names = phase_names
    summary%phase_seconds = run%timers%seconds
    ! a distributed run: every rank's seconds, for the balance (the first rank prints and writes)
    if (run%exchange%rank_count > 1) then
      allocate (summary%rank_seconds(phase_count + 4, run%exchange%rank_count))
      call gather_fixed_reals([run%timers%seconds, run%exchange%timer%seconds, run%exchange%wait_timer%seconds, &
                               run%exchange%contact_timer%seconds, run%exchange%contact_wait_timer%seconds], &
                              summary%rank_seconds)
      summary%rank_column_names = [character(len=24) :: phase_names, "nodal_exchange", "nodal_exchange_wait", &
                                   "contact_pair_exchange", "contact_pair_wait"]
    end if
    summary%tangled_solids = run%distortion%tangled
    summary%worst_corner_jacobian_ratio = run%distortion%worst_ratio
    if (run%distortion%worst_element > 0) &
      summary%worst_corner_jacobian_element = model%solid_ids(run%distortion%worst_element)
  end subroutine summarise
end module explicit_solver
