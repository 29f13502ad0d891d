!> Everything done once before the first cycle: nodal arrays, element groups, mass scaling and
!> lumped masses, rigid bodies, walls, contacts and the output plan: the run state of cycle 0
!> (forces and the first step come from the time loop's own cycle 0).
module explicit_setup
  use kinds, only: wp
  use text_format, only: integer_text
  use fixed_order_sum, only: chunk_count
  use error_handling, only: error_t, make_error
  use model, only: model_t
  use nodal_state, only: allocate_nodal_state
  use explicit_state, only: explicit_state_t
  use run_state, only: run_state_t
  use element_groups, only: build_element_groups, set_up_group_masses
  use output_plan, only: plan_output
  use boundary_conditions, only: fixed_dof_mask, fixed_rotation_mask
  use planar_rigid_walls, only: initialise_wall_states
  use particle_rows, only: start_particle_rows, solve_particle_rows
  use penalty_contact, only: set_up_contacts
  use rigid_bodies, only: set_up_rigid_bodies, add_node_masses
  use spot_weld_constraints, only: set_up_spot_welds
  use tied_contact, only: set_up_tied_contacts
  use domain_exchange, only: set_up_domains
  implicit none
  private

  public :: set_up_run_state, set_up_warnings

contains

  !> Build the run state of cycle 0 from the checked model.
  subroutine set_up_run_state(model, run, error)
    type(model_t), intent(in) :: model
    type(run_state_t), intent(out) :: run
    type(error_t), allocatable, intent(out) :: error
    call set_up_explicit_state(model, run%state, error)
    if (allocated(error)) return
    ! the ranks of a distributed run share out the element blocks (one rank: all of them)
    call set_up_domains(model, run%state%groups, run%state%nodes, run%partition, run%exchange, error)
    if (allocated(error)) return
    ! (the first rank records the histories and writes the files)
    call plan_output(model, run%histories, run%plan, run%exchange%rank == 0)
    allocate (run%energy_scratch(5, chunk_count(run%state%nodes%count)))
    ! (the first rank prints what the run says; the others keep it quietly)
    run%state%messages%quiet = run%exchange%rank /= 0
  end subroutine set_up_run_state

  subroutine set_up_explicit_state(model, state, error)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    type(error_t), allocatable, intent(out) :: error
    integer :: k

    call allocate_nodal_state(state%nodes, model%coordinates, model%initial_velocity)
    allocate (state%free_acceleration(size(model%motions)))
    state%free_acceleration = 0.0_wp
    call fixed_dof_mask(model, state%nodes%fixed)
    where (state%nodes%fixed) state%nodes%velocity = 0.0_wp
    call fixed_rotation_mask(model, state%nodes%fixed_rotation)
    allocate (state%chunk_sums(5, chunk_count(state%nodes%count)))

    call build_element_groups(model, state%groups, error)
    if (allocated(error)) return
    state%physical_mass = 0.0_wp
    state%added_mass = 0.0_wp
    call set_up_group_masses(model, state%groups, state%nodes, abs(model%mass_scaled_time_step), &
                             state%physical_mass, state%added_mass)
    state%nodes%rotational = any(state%nodes%rotary_inertia > 0.0_wp)
    call start_particle_rows(state%rows, state%nodes%count)
    do k = 1, size(state%groups)
      call state%groups(k)%group%add_particle_rows(state%rows)
    end do
    call set_up_particle_velocities(model, state, error)
    if (allocated(error)) return
    call set_up_rigid_state(model, state)
    call initialise_wall_states(model%walls, state%rows, state%walls)
    call set_up_contacts(model, state%nodes%is_particle, state%contacts, error)
    if (allocated(error)) return
    if (sum(state%nodes%mass) <= 0.0_wp) then
      call make_error(error, "model: the elements give no mass (check densities and element volumes)")
      return
    end if
  end subroutine set_up_explicit_state

  !> Initial velocities of meshfree parts: the solver's values at interior particles are
  !> generalized, and the physical velocity there is A v (the rows). For a uniform or linear
  !> field A v_deck = v_deck, but not for others: the particles get the generalized velocities v
  !> with A v = v_deck (BiCGSTAB on the rows to 1e-12 of the largest particle speed), so that
  !> every node starts with the deck's velocity. Dofs fixed by a support stay at rest.
  subroutine set_up_particle_velocities(model, state, error)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    type(error_t), allocatable, intent(out) :: error
    real(wp), parameter :: tolerance = 1.0e-12_wp
    integer, parameter :: iteration_limit = 2000
    logical :: converged
    real(wp) :: residual
    integer :: iterations
    character(len=16) :: residual_text
    if (state%rows%count == 0 .or. .not. allocated(model%initial_velocity)) return
    if (maxval(abs(model%initial_velocity)) <= 0.0_wp) return
    call solve_particle_rows(state%rows, model%initial_velocity, tolerance, iteration_limit, state%nodes%velocity, &
                             converged, residual, iterations)
    if (.not. converged) then
      write (residual_text, '(es10.3)') residual
      call make_error(error, "initial velocities (*INITIAL_VELOCITY...): the generalized velocities of the "// &
                      "meshfree particles that give the deck's velocities were not found (BiCGSTAB on the "// &
                      "transformation rows: relative residual "//trim(adjustl(residual_text))//" after "// &
                      integer_text(iterations)//" iterations, wanted 1e-12); give meshfree parts a uniform or "// &
                      "linear initial velocity field")
      return
    end if
    where (state%nodes%fixed) state%nodes%velocity = 0.0_wp
  end subroutine set_up_particle_velocities

  !> *ELEMENT_MASS and the rigid bodies: their mass properties, stable step and initial motion
  !> (rigid_bodies), once the elements have lumped their masses.
  subroutine set_up_rigid_state(model, state)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    real(wp) :: rigid_mass
    integer :: b
    call add_node_masses(model, state%nodes%mass)
    if (allocated(model%node_masses)) state%physical_mass = state%physical_mass + sum(model%node_masses)
    call set_up_rigid_bodies(model, state%nodes%reference, state%nodes%mass, state%nodes%rotary_inertia, &
                             state%nodes%velocity, state%nodes%is_rigid_node, state%rigid, rigid_mass)
    call set_up_spot_welds(model, state%nodes%reference, state%nodes%mass, state%nodes%rotary_inertia, &
                           state%nodes%velocity, state%welds)
    allocate (state%held_by_weld(state%nodes%count))
    state%held_by_weld = .false.
    allocate (state%plastic_weld_node(state%nodes%count), state%weld_node_plastic_strain(state%nodes%count))
    state%plastic_weld_node = .false.
    state%weld_node_plastic_strain = 0.0_wp
    do b = 1, size(state%welds)
      if (model%spot_welds(b)%failure_plastic_strain > 0.0_wp) &
        state%plastic_weld_node(model%spot_welds(b)%nodes) = .true.
      state%held_by_weld(model%spot_welds(b)%nodes) = .true.
    end do
    call set_up_tied_contacts(model, state%nodes%mass, state%nodes%rotary_inertia, state%nodes%velocity, &
                              state%nodes%angular_velocity, state%ties)
    state%physical_mass = state%physical_mass + rigid_mass
    state%rigid_time_step = huge(1.0_wp)
    do b = 1, size(state%rigid)
      state%rigid_time_step = min(state%rigid_time_step, state%rigid(b)%time_step)
    end do
  end subroutine set_up_rigid_state

  !> Things the user should know before the run starts, one per line (empty: nothing):
  !> segment loads are applied by the static analysis only; conditions and loads on interior
  !> particles of meshfree parts act on generalized displacements; mass scaling leaves meshfree
  !> parts alone. (Rigid walls and initial velocities act on the particles' physical values, and
  !> wide supports no longer stiffen curved meshfree shells: nothing to say.)
  function set_up_warnings(model, state) result(text)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    character(len=:), allocatable :: text
    integer :: count, first, k
    text = ""
    if (allocated(model%segment_loads)) then
      if (size(model%segment_loads) > 0) text = "warning: the deck's "//trim(integer_text(size(model%segment_loads)))// &
        " segment load(s) (*LOAD_SEGMENT, _SET, _NONUNIFORM) are applied by the linear static analysis "// &
        "(*CONTROL_IMPLICIT_GENERAL) only: this explicit run does not apply them"
    end if
    if (.not. any(state%nodes%is_particle)) return
    count = 0
    first = 0
    do k = 1, size(model%spcs)
      call note_particle(model%spcs(k)%node)
    end do
    do k = 1, size(model%motions)
      call note_particle(model%motions(k)%node)
    end do
    do k = 1, size(model%loads)
      call note_particle(model%loads(k)%node)
    end do
    if (count > 0) then
      if (len(text) > 0) text = text//new_line('a')
      text = text//"warning: "//trim(integer_text(count))//" constraint(s) or load(s) act on interior "// &
        "particles of meshfree parts (node "//trim(integer_text(model%node_ids(first)))//" first): they act on "// &
        "generalized displacements, not on the nodes' own motion; put them on the parts' surfaces"
    end if
    if (model%mass_scaled_time_step /= 0.0_wp) then
      if (len(text) > 0) text = text//new_line('a')
      text = text//"warning: mass scaling (DT2MS) applies to finite elements only; meshfree parts keep their density"
    end if
  contains
    subroutine note_particle(node)
      integer, intent(in) :: node
      if (.not. state%nodes%is_particle(node)) return
      count = count + 1
      if (first == 0) first = node
    end subroutine note_particle
  end function set_up_warnings
end module explicit_setup
