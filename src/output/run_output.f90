!> The output step of the time loop: records the history rows and writes the state that the
!> output plan (output_plan) says are due, reading the run state and changing only the plan,
!> the histories and the results file.
module run_output
  use kinds, only: wp
  use error_handling, only: error_t
  use model, only: model_t, wall_planar
  use element_group, only: family_solid, family_shell, family_beam
  use explicit_state, only: explicit_state_t, energy_totals_t
  use output_plan, only: output_plan_t, clock_due
  use history_buffer, only: history_set_t, append_history_row
  use element_groups, only: collect_element_results
  use energy_balance, only: measured_energies, part_energies, part_momenta, total_energy, energy_ratio, &
                            energy_ratio_without_eroded
  use results_file, only: results_file_t, write_state
  use rigid_bodies, only: rigid_body_history_row
  use spot_weld_constraints, only: failed_weld_count
  use penalty_contact, only: mass_in_contact
  use ascii_databases, only: c_exponential
  use binout_file, only: binout_requested, binout_name, write_binout
  use ascii_run_summary, only: initial_time_step_tables
  implicit none
  private

  public :: write_due_output

contains

  !> Record the histories and write the state that are due at the state's time. `last` marks
  !> the final cycle (normal or error termination): everything is written then.
  subroutine write_due_output(model, state, plan, histories, scratch, results, last, error)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    type(output_plan_t), intent(inout) :: plan
    type(history_set_t), intent(inout) :: histories
    real(wp), intent(inout) :: scratch(:, :)     !< (5, chunks of nodes) for the energy sums
    type(results_file_t), intent(inout) :: results
    logical, intent(in) :: last
    type(error_t), allocatable, intent(out) :: error
    type(energy_totals_t) :: energy
    real(wp) :: total_mass
    logical :: glstat_due, matsum_due, nodout_due, states_due, rwforc_due, rcforc_due, rbdout_due
    integer :: k

    ! every clock moves on, on every rank (the states, glstat and matsum clocks decide when a
    ! distributed run gathers: the ranks must agree); only the first rank records
    glstat_due = clock_due(plan%glstat, state%time, last)
    matsum_due = clock_due(plan%matsum, state%time, last)
    nodout_due = clock_due(plan%nodout, state%time, last)
    states_due = clock_due(plan%states, state%time, last)
    rwforc_due = clock_due(plan%rwforc, state%time, last)
    rcforc_due = clock_due(plan%rcforc, state%time, last)
    rbdout_due = clock_due(plan%rbdout, state%time, last)
    if (.not. plan%records) return
    if (state%cycle == 0 .and. .not. allocated(plan%initial_time_steps)) &
      plan%initial_time_steps = initial_time_step_tables(model, state)
    if (glstat_due) then
      energy = state%energy
      call measured_energies(model, state, scratch, energy)
      ! glstat's global velocity: the momentum over the mass that carries it (physical and added)
      total_mass = max(state%physical_mass + state%added_mass, tiny(1.0_wp))
      call append_history_row(histories%series(plan%glstat_series), [state%time, &
        merge(state%next_time_step, state%time_step, state%cycle == 0), &
        energy%kinetic, energy%internal, energy%hourglass, energy%contact, &
        energy%external_work, total_energy(energy), energy%rigid_wall, energy_ratio(energy), &
        state%added_mass, energy%momentum, energy%eroded_internal, energy%eroded_hourglass, &
        energy%eroded_kinetic, real(state%eroded_count, wp), 0.0_wp, 0.0_wp, energy_ratio_without_eroded(energy), &
        100.0_wp*state%added_mass/max(state%physical_mass, tiny(1.0_wp)), energy%momentum/total_mass, &
        real(state%cycle, wp), state%physical_mass, controlling_element_row(model, state)])
      if (plan%weld_series > 0) call append_history_row(histories%series(plan%weld_series), &
                                                        [state%time, real(failed_weld_count(state%welds), wp)])
    end if
    if (matsum_due) then
      call part_energies(model, state, size(model%parts), plan%part_kinetic, plan%part_internal, plan%part_hourglass)
      call part_momenta(model, state, size(model%parts), plan%part_momentum, plan%part_mass, plan%part_rigid_velocity)
      do k = 1, size(model%parts)
        call append_history_row(histories%series(plan%matsum_series(k)), [state%time, plan%part_kinetic(k), &
                                plan%part_internal(k), plan%part_hourglass(k), plan%part_momentum(:, k), &
                                plan%part_rigid_velocity(:, k), plan%part_mass(k)])
      end do
    end if
    if (nodout_due .or. states_due) call physical_node_fields(state, plan)
    if (nodout_due) then
      do k = 1, size(plan%nodout_series)
        associate (node => model%output%history_nodes(k))
          call append_history_row(histories%series(plan%nodout_series(k)), [state%time, &
            plan%node_displacement(:, node), plan%node_velocity(:, node), plan%node_acceleration(:, node), &
            real(state%cycle, wp)])
        end associate
      end do
    end if
    if (rwforc_due) call record_wall_forces(model, state, plan, histories)
    if (rcforc_due) call record_contact_forces(state, plan, histories)
    if (rbdout_due) call record_rigid_bodies(model, state, plan, histories)
    ! the state and the history rows recorded since the previous one, as one commit (a file the
    ! run has open: in a distributed run only the first rank writes)
    if (.not. results%is_open) return
    if (states_due) call write_current_state(model, state, plan, histories, results, &
                                             d3plot_globals(model, state, plan, scratch), error)
    ! binout (BINARY 2 or 3), written whole: at the last output and the states 1, 2, 4, 8, ...
    if (states_due .and. .not. allocated(error) .and. binout_requested(model)) then
      if (last .or. iand(results%state_count, results%state_count - 1) == 0) &
        call write_binout(model, histories, binout_path(results), error)
    end if
  end subroutine write_due_output

  !> binout beside the results file (results_file's DIR/JOBID.h5), named as LS-DYNA names it.
  function binout_path(results) result(path)
    type(results_file_t), intent(in) :: results
    character(len=:), allocatable :: path
    integer :: name_start
    name_start = len(results%h5_path) - len(results%h5_name) + 1
    path = results%h5_path(1:name_start - 1)//binout_name(results%h5_name(1:len(results%h5_name) - 3))
  end function binout_path

  !> The d3plot's global values of the state: kinetic, internal and total energy, the velocity
  !> of the centre of mass (momentum / mass), then per part the internal and the kinetic energy.
  function d3plot_globals(model, state, plan, scratch) result(globals)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    type(output_plan_t), intent(inout) :: plan
    real(wp), intent(inout) :: scratch(:, :)
    real(wp), allocatable :: globals(:)
    type(energy_totals_t) :: energy
    real(wp) :: mass
    integer :: parts, node
    parts = size(model%parts)
    allocate (globals(6 + 2*parts), source=0.0_wp)
    energy = state%energy
    call measured_energies(model, state, scratch, energy)
    call part_energies(model, state, parts, plan%part_kinetic, plan%part_internal, plan%part_hourglass)
    mass = 0.0_wp
    do node = 1, size(state%nodes%mass)
      mass = mass + state%nodes%mass(node)
    end do
    globals(1) = energy%kinetic
    globals(2) = energy%internal
    globals(3) = total_energy(energy)
    if (mass > 0.0_wp) globals(4:6) = energy%momentum/mass
    globals(7:6 + parts) = plan%part_internal
    globals(7 + parts:6 + 2*parts) = plan%part_kinetic
  end function d3plot_globals

  !> Wall force averaged over the sampling interval (impulse / interval), so that integrating
  !> the rwforc history gives the impulse exactly; at t = 0 the force of the first cycle is 0.
  !> LS-DYNA's sign: the force the wall exerts on the structure (the state's impulse is the
  !> one the wall received); the normal force is its component along a planar wall's normal
  !> (which points to the structure's side, so a wall pushing is positive), for a cylinder its
  !> radial part.
  subroutine record_wall_forces(model, state, plan, histories)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    type(output_plan_t), intent(inout) :: plan
    type(history_set_t), intent(inout) :: histories
    integer :: k
    real(wp) :: interval, force(3), normal_force
    interval = state%time - plan%last_rwforc_time
    do k = 1, size(plan%rwforc_series)
      force = 0.0_wp
      ! (0 - x: a wall without force writes +0, not -0)
      if (interval > 0.0_wp) force = 0.0_wp - (state%walls(k)%impulse - plan%wall_impulse(:, k))/interval
      if (model%walls(k)%kind == wall_planar) then
        normal_force = dot_product(force, model%walls(k)%normal)
      else
        ! a cylinder's (model%walls(k)%normal: its axis): the radial part, what presses on its side
        normal_force = norm2(force - dot_product(force, model%walls(k)%normal)*model%walls(k)%normal)
      end if
      call append_history_row(histories%series(plan%rwforc_series(k)), [state%time, force, normal_force])
      plan%wall_impulse(:, k) = state%walls(k)%impulse
    end do
    plan%last_rwforc_time = state%time
  end subroutine record_wall_forces

  !> Contact force on the SURFA side averaged over the sampling interval (impulse / interval),
  !> as rwforc, and on the SURFB side (the opposite: LS-DYNA's master line); at t = 0 both are 0.
  !> Then each side's nodal mass in contact at the sample (LS-DYNA's rcforc mass).
  subroutine record_contact_forces(state, plan, histories)
    type(explicit_state_t), intent(in) :: state
    type(output_plan_t), intent(inout) :: plan
    type(history_set_t), intent(inout) :: histories
    integer :: k
    real(wp) :: interval, force(3)
    interval = state%time - plan%last_rcforc_time
    do k = 1, size(plan%rcforc_series)
      force = 0.0_wp
      if (interval > 0.0_wp) force = (state%contacts(k)%impulse - plan%contact_impulse(:, k))/interval
      call append_history_row(histories%series(plan%rcforc_series(k)), [state%time, force, 0.0_wp - force, &
                              mass_in_contact(state%contacts(k), state%nodes%mass)])
      plan%contact_impulse(:, k) = state%contacts(k)%impulse
    end do
    plan%last_rcforc_time = state%time
  end subroutine record_contact_forces

  !> One rbdout row per rigid body (the force is the impulse since the last row / interval).
  subroutine record_rigid_bodies(model, state, plan, histories)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    type(output_plan_t), intent(inout) :: plan
    type(history_set_t), intent(inout) :: histories
    real(wp) :: row(37)
    integer :: k
    do k = 1, size(plan%rbdout_series)
      call rigid_body_history_row(model, k, state%rigid(k), state%nodes%acceleration, state%nodes%mass, state%time, &
                                  0.5_wp*state%time_step, state%time - plan%last_rbdout_time, plan%rigid_impulse(:, k), &
                                  row)
      call append_history_row(histories%series(plan%rbdout_series(k)), [row, real(state%cycle, wp)])
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
    plan%node_velocity = state%nodes%velocity + 0.5_wp*state%time_step*state%nodes%acceleration
    plan%node_displacement = state%nodes%displacement
    plan%node_acceleration = state%nodes%acceleration
    ! (a model without meshfree parts: the solver's values are the physical ones)
    if (.not. allocated(plan%generalized_velocity)) return
    plan%generalized_velocity = plan%node_velocity
    do k = 1, size(state%groups)
      call state%groups(k)%group%to_physical(state%nodes%displacement, plan%node_displacement)
      call state%groups(k)%group%to_physical(plan%generalized_velocity, plan%node_velocity)
      call state%groups(k)%group%to_physical(state%nodes%acceleration, plan%node_acceleration)
    end do
  end subroutine physical_node_fields

  subroutine write_current_state(model, state, plan, histories, results, globals, error)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    type(output_plan_t), intent(inout) :: plan
    type(history_set_t), intent(in) :: histories
    type(results_file_t), intent(inout) :: results
    real(wp), intent(in), contiguous :: globals(:)   !< the d3plot's global values
    type(error_t), allocatable, intent(out) :: error
    call collect_element_results(model, state%groups, plan%element_results)
    associate (fields => plan%element_results)
      if (size(model%shell_ids) > 0) then
        call write_state(results, state%time, plan%node_displacement, plan%node_velocity, fields%solid_stress, &
                         fields%solid_plastic_strain, error, fields%shell_stress, fields%shell_plastic_strain, &
                         fields%shell_stress_peak, fields%shell_plastic_strain_peak, histories=histories, &
                         beam_resultant=fields%beam_resultant, beam_plastic_strain=fields%beam_plastic_strain, &
                         beam_failed=fields%beam_failed, &
                         solid_eroded=fields%solid_eroded, shell_eroded=fields%shell_eroded, &
                         eroded_count=state%eroded_count, acceleration=plan%node_acceleration, globals=globals, &
                         shell_point_stress=fields%shell_point_stress, &
                         shell_point_plastic_strain=fields%shell_point_plastic_strain, &
                         shell_point_count=fields%shell_point_count, shell_resultant=fields%shell_resultant, &
                         shell_thickness=fields%shell_thickness, shell_energy_density=fields%shell_energy_density, &
                         reference_coordinates=model%coordinates)
      else
        ! (beam fields not allocated: a model without beams; the dummies are then absent)
        call write_state(results, state%time, plan%node_displacement, plan%node_velocity, fields%solid_stress, &
                         fields%solid_plastic_strain, error, histories=histories, &
                         beam_resultant=fields%beam_resultant, beam_plastic_strain=fields%beam_plastic_strain, &
                         beam_failed=fields%beam_failed, &
                         solid_eroded=fields%solid_eroded, eroded_count=state%eroded_count, &
                         acceleration=plan%node_acceleration, globals=globals, &
                         reference_coordinates=model%coordinates)
      end if
    end associate
  end subroutine write_current_state
  !> glstat's controlling element: the family of the element that set the stable step (1 solid,
  !> 2 shell, 3 beam; 0 when a rigid body's step or nothing set it), its deck id and its part id.
  function controlling_element_row(model, state) result(row)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    real(wp) :: row(3)
    integer :: element
    row = 0.0_wp
    if (state%controlling_group <= 0 .or. state%controlling_element <= 0) return
    element = state%controlling_element
    associate (family => state%groups(state%controlling_group)%group%element_family)
      row(1) = real(family, wp)
      select case (family)
      case (family_solid)
        row(2:3) = [real(model%solid_ids(element), wp), real(model%parts(model%solid_part(element))%id, wp)]
      case (family_shell)
        row(2:3) = [real(model%shell_ids(element), wp), real(model%parts(model%shell_part(element))%id, wp)]
      case (family_beam)
        row(2:3) = [real(model%beam_ids(element), wp), real(model%parts(model%beam_part(element))%id, wp)]
      case default
        row = 0.0_wp
      end select
    end associate
  end function controlling_element_row

end module run_output
