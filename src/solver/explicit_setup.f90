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
  use penalty_contact, only: set_up_contacts
  use rigid_bodies, only: set_up_rigid_bodies, add_node_masses
  use spot_weld_constraints, only: set_up_spot_welds
  use tied_contact, only: set_up_tied_contacts
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
    call plan_output(model, run%histories, run%plan)
    allocate (run%energy_scratch(5, chunk_count(run%state%nodes%count)))
  end subroutine set_up_run_state

  subroutine set_up_explicit_state(model, state, error)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    type(error_t), allocatable, intent(out) :: error

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
    call set_up_rigid_state(model, state)
    call initialise_wall_states(model%walls, state%walls)
    call set_up_contacts(model, state%nodes%is_particle, state%contacts, error)
    if (allocated(error)) return
    if (sum(state%nodes%mass) <= 0.0_wp) then
      call make_error(error, "model: the elements give no mass (check densities and element volumes)")
      return
    end if
  end subroutine set_up_explicit_state

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
  !> particles of meshfree parts act on generalized displacements, and so does an initial
  !> velocity field that is not linear across a meshfree part; mass scaling leaves meshfree
  !> parts alone, and rigid walls act on the generalized positions of meshfree particles.
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
    call note_initial_velocities()
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
    ! meshfree shells (efg_shell_group): walls see their particles' generalized positions
    do k = 1, size(model%walls)
      if (.not. allocated(model%walls(k)%nodes)) cycle
      if (.not. any(state%nodes%is_particle(model%walls(k)%nodes))) cycle
      if (len(text) > 0) text = text//new_line('a')
      text = text//"warning: rigid wall "//trim(integer_text(model%walls(k)%id))//" tracks interior particles "// &
        "of meshfree parts: it acts on their generalized positions, not their physical ones (a contact with a "// &
        "rigid part does)"
    end do
  contains
    !> Initial velocities are given to the solver's values, which at interior particles are
    !> generalized: the physical initial velocity is A v, equal to the deck's for a uniform or
    !> linear field (a translation, a rotation) only. Warn, naming the first node, when A v
    !> differs from the deck's velocity at a particle.
    subroutine note_initial_velocities()
      real(wp), allocatable :: physical(:, :)
      real(wp) :: scale
      integer :: group, node, worst
      if (.not. allocated(model%initial_velocity)) return
      scale = maxval(abs(model%initial_velocity))
      if (scale <= 0.0_wp) return
      physical = model%initial_velocity
      do group = 1, size(state%groups)
        call state%groups(group)%group%to_physical(model%initial_velocity, physical)
      end do
      worst = 0
      do node = 1, size(physical, 2)
        if (.not. state%nodes%is_particle(node)) cycle
        if (maxval(abs(physical(:, node) - model%initial_velocity(:, node))) > 1.0e-9_wp*scale) then
          worst = node
          exit
        end if
      end do
      if (worst == 0) return
      if (len(text) > 0) text = text//new_line('a')
      text = text//"warning: the initial velocities are not a uniform or linear field across a meshfree part: "// &
        "at interior particles they set generalized velocities, so the physical initial velocity differs (node "// &
        trim(integer_text(model%node_ids(worst)))//" first); give meshfree parts a uniform or rotational "// &
        "initial velocity"
    end subroutine note_initial_velocities

    subroutine note_particle(node)
      integer, intent(in) :: node
      if (.not. state%nodes%is_particle(node)) return
      count = count + 1
      if (first == 0) first = node
    end subroutine note_particle
  end function set_up_warnings
end module explicit_setup
