!> Everything done once before the first cycle: element blocks, mass scaling, lumped nodal
!> masses, the node -> corner gather list, the initial state and the first stable time step.
module explicit_setup
  use kinds, only: wp, block_size
  use fixed_order_sum, only: chunk_count
  use error_handling, only: error_t, make_error
  use block_colouring, only: colour_blocks_by_nodes
  use model, only: model_t, formulation_efg, boundary_full_transformation, integration_gauss_conventional
  use efg_part, only: efg_part_t
  use efg_setup, only: build_efg_part
  use efg_forces, only: set_up_efg_solver
  use solid_block, only: solid_block_t, build_solid_blocks, solid_block_corner_masses, &
                         solid_block_time_steps
  use shell_block, only: build_shell_blocks, shell_block_masses, shell_block_time_steps
  use explicit_state, only: explicit_state_t
  use boundary_conditions, only: fixed_dof_mask, fixed_rotation_mask
  use planar_rigid_walls, only: initialise_wall_states
  use penalty_contact, only: set_up_contacts
  use rigid_bodies, only: set_up_rigid_bodies, add_node_masses
  implicit none
  private

  public :: set_up_explicit_state, set_up_warnings

contains

  !> Build the state of cycle 0 from the checked model.
  subroutine set_up_explicit_state(model, state, error)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(out) :: state
    type(error_t), allocatable, intent(out) :: error
    integer :: node_count, block_count

    node_count = size(model%node_ids)
    state%node_count = node_count
    state%reference = model%coordinates
    state%coordinates = model%coordinates
    state%velocity = model%initial_velocity
    allocate (state%displacement(3, node_count), state%acceleration(3, node_count), &
              state%internal_force(3, node_count), state%external_force(3, node_count), &
              state%free_acceleration(size(model%motions)), state%mass(node_count), state%fixed(3, node_count))
    state%displacement = 0.0_wp
    state%acceleration = 0.0_wp
    state%internal_force = 0.0_wp
    state%external_force = 0.0_wp
    state%free_acceleration = 0.0_wp
    call fixed_dof_mask(model, state%fixed)
    where (state%fixed) state%velocity = 0.0_wp

    call build_solid_blocks(model, state%blocks)
    block_count = size(state%blocks)
    allocate (state%corner_mass(block_size, 8, block_count), &
              state%block_time_step(block_count), state%block_critical_element(block_count), &
              state%block_inverted_element(block_count))
    state%block_time_step = huge(1.0_wp)
    state%block_critical_element = 0
    state%block_inverted_element = 0
    call build_shell_blocks(model, state%shells)
    block_count = size(state%shells)
    allocate (state%shell_corner_mass(block_size, 4, block_count), &
              state%shell_corner_inertia(block_size, 4, block_count), &
              state%shell_time_step(block_count), state%shell_critical_element(block_count), &
              state%shell_degenerate_element(block_count))
    state%shell_time_step = huge(1.0_wp)
    state%shell_critical_element = 0
    state%shell_degenerate_element = 0
    allocate (state%angular_velocity(3, node_count), state%angular_acceleration(3, node_count), &
              state%internal_moment(3, node_count), state%rotary_inertia(node_count), &
              state%fixed_rotation(3, node_count))
    state%angular_velocity = 0.0_wp
    state%angular_acceleration = 0.0_wp
    state%internal_moment = 0.0_wp
    call fixed_rotation_mask(model, state%fixed_rotation)
    allocate (state%shell_normal_sum(3, node_count), state%shell_area_sum(node_count))
    state%shell_normal_sum = 0.0_wp
    state%shell_area_sum = 0.0_wp
    allocate (state%chunk_sums(5, chunk_count(node_count)))

    call scale_masses(model, state)
    call colour_blocks(state)
    call lump_nodal_masses(state)
    call set_up_meshfree_parts(model, state, error)
    if (allocated(error)) return
    call set_up_rigid_state(model, state)
    call initialise_wall_states(model%walls, state%walls)
    allocate (state%contact_force(3, node_count))
    state%contact_force = 0.0_wp
    call set_up_contacts(model, state%is_particle, state%contacts, error)
    if (allocated(error)) return
    if (sum(state%mass) <= 0.0_wp) then
      call make_error(error, "model: the elements give no mass (check densities and element volumes)")
      return
    end if
  end subroutine set_up_explicit_state

  !> Mass scaling (*CONTROL_TIMESTEP DT2MS): raise the density of every element whose stable
  !> step is below |DT2MS| so that its step equals |DT2MS| (the step scales with 1/sqrt(rho)).
  !> Done once, on the undeformed mesh; the added mass is reported.
  subroutine scale_masses(model, state)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    real(wp) :: element_time_step(block_size), target_step, volume(block_size)
    integer :: b, nel

    state%physical_mass = 0.0_wp
    state%added_mass = 0.0_wp
    target_step = abs(model%mass_scaled_time_step)
    element_time_step = huge(1.0_wp)
    do b = 1, size(state%blocks)
      associate (block => state%blocks(b))
        if (target_step > 0.0_wp) &
          call solid_block_time_steps(block, model%materials(block%material), state%coordinates, element_time_step)
        call scale_block_density(block%element_count, block%reference_volume, target_step, element_time_step, &
                                 block%density, state%physical_mass, state%added_mass)
      end associate
    end do
    do b = 1, size(state%shells)
      associate (shell => state%shells(b))
        nel = shell%element_count
        volume(1:nel) = shell%thickness(1:nel)*shell%reference_area(1:nel)
        if (target_step > 0.0_wp) &
          call shell_block_time_steps(shell, model%materials(shell%material), state%coordinates, element_time_step)
        call scale_block_density(nel, volume, target_step, element_time_step, shell%density, state%physical_mass, &
                                 state%added_mass)
      end associate
    end do
  end subroutine scale_masses

  !> One block of mass scaling: its physical mass, then each lane whose step is below
  !> `target_step` (> 0) gets the density that brings its step to it (the step scales with
  !> 1/sqrt(rho)), and the mass added.
  subroutine scale_block_density(nel, volume, target_step, element_time_step, density, physical_mass, added_mass)
    integer, intent(in) :: nel
    real(wp), intent(in) :: volume(block_size), target_step, element_time_step(block_size)
    real(wp), intent(inout) :: density(block_size), physical_mass, added_mass
    real(wp) :: factor
    integer :: i
    physical_mass = physical_mass + sum(density(1:nel)*volume(1:nel))
    if (target_step <= 0.0_wp) return
    do i = 1, nel
      if (element_time_step(i) >= target_step) cycle
      factor = (target_step/element_time_step(i))**2
      added_mass = added_mass + (factor - 1.0_wp)*density(i)*volume(i)
      density(i) = density(i)*factor
    end do
  end subroutine scale_block_density

  !> Colour the solid blocks and the shell blocks (each kind among itself: the solver adds the
  !> solids' forces first, then the shells').
  subroutine colour_blocks(state)
    type(explicit_state_t), intent(inout) :: state
    integer, allocatable :: nodes(:, :, :), counts(:)
    integer :: b
    allocate (nodes(block_size, 8, size(state%blocks)), counts(size(state%blocks)))
    do b = 1, size(state%blocks)
      nodes(:, :, b) = state%blocks(b)%nodes
      counts(b) = state%blocks(b)%element_count
    end do
    call colour_blocks_by_nodes(state%node_count, nodes, counts, state%block_colors)
    deallocate (nodes, counts)
    allocate (nodes(block_size, 4, size(state%shells)), counts(size(state%shells)))
    do b = 1, size(state%shells)
      nodes(:, :, b) = state%shells(b)%nodes
      counts(b) = state%shells(b)%element_count
    end do
    call colour_blocks_by_nodes(state%node_count, nodes, counts, state%shell_colors)
  end subroutine colour_blocks

  !> Lumped nodal masses: each block adds its corner masses to its nodes (serially, in block,
  !> corner and lane order), solids first, then shells with their rotary inertias.
  subroutine lump_nodal_masses(state)
    type(explicit_state_t), intent(inout) :: state
    integer :: b, corner, lane, node

    state%mass = 0.0_wp
    do b = 1, size(state%blocks)
      call solid_block_corner_masses(state%blocks(b), state%corner_mass(:, :, b))
      do corner = 1, 8
        do lane = 1, state%blocks(b)%element_count
          node = state%blocks(b)%nodes(lane, corner)
          state%mass(node) = state%mass(node) + state%corner_mass(lane, corner, b)
        end do
      end do
    end do
    state%rotary_inertia = 0.0_wp
    do b = 1, size(state%shells)
      call shell_block_masses(state%shells(b), state%shell_corner_mass(:, :, b), state%shell_corner_inertia(:, :, b))
      do corner = 1, 4
        do lane = 1, state%shells(b)%element_count
          node = state%shells(b)%nodes(lane, corner)
          state%mass(node) = state%mass(node) + state%shell_corner_mass(lane, corner, b)
          state%rotary_inertia(node) = state%rotary_inertia(node) + state%shell_corner_inertia(lane, corner, b)
        end do
      end do
    end do
  end subroutine lump_nodal_masses

  !> *ELEMENT_MASS and the rigid bodies: their mass properties, stable step and initial motion
  !> (rigid_bodies), once the elements have lumped their masses.
  subroutine set_up_rigid_state(model, state)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    real(wp) :: rigid_mass
    integer :: b
    call add_node_masses(model, state%mass)
    if (allocated(model%node_masses)) state%physical_mass = state%physical_mass + sum(model%node_masses)
    allocate (state%is_rigid_node(state%node_count))
    call set_up_rigid_bodies(model, state%reference, state%mass, state%velocity, state%is_rigid_node, &
                             state%rigid, rigid_mass)
    state%physical_mass = state%physical_mass + rigid_mass
    state%rigid_time_step = huge(1.0_wp)
    do b = 1, size(state%rigid)
      state%rigid_time_step = min(state%rigid_time_step, state%rigid(b)%time_step)
    end do
  end subroutine set_up_rigid_state

  !> Shape functions, smoothed gradients and row-sum masses of every EFG part (formulation
  !> sections 2-5), once, on the undeformed mesh.
  subroutine set_up_meshfree_parts(model, state, error)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    type(error_t), allocatable, intent(out) :: error
    type(efg_part_t) :: geometry
    integer :: part, count, k
    logical, allocatable :: used(:)

    allocate (state%is_particle(state%node_count))
    state%is_particle = .false.
    ! A part no element uses has nothing to set up, as in the static analysis (found by
    ! fuzzing: an unused *PART on an EFG section stopped the run with "EFG part N has no solid
    ! elements", a message naming no deck line, where an unused FE part is accepted).
    allocate (used(size(model%parts)))
    used = .false.
    do k = 1, size(model%solid_part)
      used(model%solid_part(k)) = .true.
    end do
    count = 0
    do part = 1, size(model%parts)
      if (model%parts(part)%formulation == formulation_efg .and. used(part)) count = count + 1
    end do
    allocate (state%efg(count))
    count = 0
    do part = 1, size(model%parts)
      if (model%parts(part)%formulation /= formulation_efg .or. .not. used(part)) cycle
      count = count + 1
      if (model%sections(model%parts(part)%section)%boundary_treatment == boundary_full_transformation) then
        call make_error(error, "part "//trim(id_text(model%parts(part)%id))//": IEBT = 1 (full transformation) is "// &
                        "a verification variant of the linear static analysis; explicit runs need the coupled "// &
                        "boundary treatment IEBT = 3 (the default)")
        return
      end if
      ! the explicit update assumes 8 integration points per cell (sub-cells or 2x2x2 Gauss)
      if (model%sections(model%parts(part)%section)%domain_integration == integration_gauss_conventional) then
        call make_error(error, "part "//trim(id_text(model%parts(part)%id))//": IDIM = 4 (conventional EFG, "// &
                        "4x4x4 Gauss points) is a verification variant of the linear static analysis; explicit "// &
                        "runs use IDIM = 1 (the default) or 2")
        return
      end if
      call build_efg_part(model, part, geometry, error)
      if (allocated(error)) return
      call set_up_efg_solver(model, geometry, state%efg(count))
      associate (efg => state%efg(count))
        do k = 1, size(efg%geometry%mass_node)
          state%mass(efg%geometry%mass_node(k)) = state%mass(efg%geometry%mass_node(k)) + &
                                                  efg%density*efg%geometry%mass_volume(k)
        end do
        state%physical_mass = state%physical_mass + efg%density*sum(efg%geometry%mass_volume)
        state%is_particle(efg%geometry%particles) = .true.
      end associate
    end do
  end subroutine set_up_meshfree_parts

  !> Things the user should know before the run starts, one per line (empty: nothing):
  !> conditions and loads on interior particles of meshfree parts act on generalized
  !> displacements, and mass scaling leaves meshfree parts alone.
  function set_up_warnings(model, state) result(text)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    character(len=:), allocatable :: text
    integer :: count, first, k
    text = ""
    if (size(state%efg) == 0) return
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
    if (count > 0) text = "warning: "//trim(id_text(count))//" constraint(s) or load(s) act on interior "// &
      "particles of meshfree parts (node "//trim(id_text(model%node_ids(first)))//" first): they act on "// &
      "generalized displacements, not on the nodes' own motion; put them on the parts' surfaces"
    if (model%mass_scaled_time_step /= 0.0_wp) then
      if (len(text) > 0) text = text//new_line('a')
      text = text//"warning: mass scaling (DT2MS) applies to finite elements only; meshfree parts keep their density"
    end if
  contains
    subroutine note_particle(node)
      integer, intent(in) :: node
      if (.not. state%is_particle(node)) return
      count = count + 1
      if (first == 0) first = node
    end subroutine note_particle
  end function set_up_warnings

  pure function id_text(id) result(text)
    integer, intent(in) :: id
    character(len=12) :: text
    write (text, '(i0)') id
  end function id_text

end module explicit_setup
