!> The meshfree (EFG) parts as an element group (element_group): one efg_solver_t per part,
!> set up once on the undeformed mesh (shape functions, smoothed gradients, row-sum masses,
!> formulation sections 2-5). Their elements are the integration points, reported by their
!> background cell (a solid element of the deck). Interior particles carry generalized values;
!> `to_physical` transforms a nodal field for output (eq. 16). Mass scaling leaves them alone.
module efg_group
  use kinds, only: wp
  use error_handling, only: error_t, make_error
  use run_summary, only: run_summary_t
  use text_format, only: integer_text
  use restart_file, only: restart_store_t, exchange_restart, exchange_restart_count
  use model, only: model_t, formulation_efg, boundary_full_transformation, integration_gauss_conventional
  use nodal_state, only: nodal_state_t
  use element_group, only: element_group_t, element_results_t, distinct_nodes, family_solid, block_energy_values
  use particle_rows, only: particle_rows_t, append_particle_rows
  use element_work, only: booked_energy, lane_energy_sums, add_kinetic_energy
  use efg_part, only: efg_part_t
  use efg_setup, only: build_efg_part
  use efg_forces, only: efg_solver_t, set_up_efg_solver, compute_efg_forces, efg_point_results, &
                        transform_to_physical, efg_point_time_steps
  implicit none
  private

  public :: efg_group_t, new_efg_group

  type, extends(element_group_t) :: efg_group_t
    type(efg_solver_t), allocatable :: parts(:)
  contains
    procedure :: element_count
    procedure :: block_count
    procedure :: block_nodes
    procedure :: block_elements
    procedure :: scale_masses
    procedure :: lump_masses
    procedure :: add_internal_forces
    procedure :: sum_block_energies
    procedure :: add_part_energies
    procedure :: add_part_momenta
    procedure :: element_results
    procedure :: describe
    procedure :: add_to_summary
    procedure :: exchange_state
    procedure :: failure_text
    procedure :: to_physical
    procedure :: forces_to_generalized
    procedure :: add_particle_rows
    procedure :: list_time_steps
    procedure :: distributes_blocks
    procedure :: exchange_block_state
  end type efg_group_t

contains

  !> Every EFG part some solid element uses. (A part no element uses has nothing to set up, as
  !> in the static analysis: found by fuzzing, an unused *PART on an EFG section stopped the run
  !> with a message naming no deck line, where an unused FE part is accepted.)
  !> A new group of this kind (its constructor for element_groups).
  subroutine new_efg_group(model, group, error)
    type(model_t), intent(in) :: model
    class(element_group_t), allocatable, intent(out) :: group
    type(error_t), allocatable, intent(out) :: error
    allocate (efg_group_t :: group)
    select type (group)
    type is (efg_group_t)
      call build_group(model, group, error)
    end select
  end subroutine new_efg_group

  subroutine build_group(model, group, error)
    type(model_t), intent(in) :: model
    type(efg_group_t), intent(inout) :: group
    type(error_t), allocatable, intent(out) :: error
    type(efg_part_t) :: geometry
    integer :: part, count, k
    logical, allocatable :: used(:)

    group%name = "meshfree"
    group%element_family = family_solid
    allocate (used(size(model%parts)))
    used = .false.
    do k = 1, size(model%solid_part)
      used(model%solid_part(k)) = .true.
    end do
    count = 0
    do part = 1, size(model%parts)
      if (model%parts(part)%formulation == formulation_efg .and. used(part)) count = count + 1
    end do
    allocate (group%parts(count))
    count = 0
    do part = 1, size(model%parts)
      if (model%parts(part)%formulation /= formulation_efg .or. .not. used(part)) cycle
      count = count + 1
      if (model%sections(model%parts(part)%section)%boundary_treatment == boundary_full_transformation) then
        call make_error(error, "part "//integer_text(model%parts(part)%id)//": IEBT = 1 (full transformation) is "// &
                        "a verification variant of the linear static analysis; explicit runs need the coupled "// &
                        "boundary treatment IEBT = 3 (the default)")
        return
      end if
      ! the explicit update assumes 8 integration points per cell (sub-cells or 2x2x2 Gauss)
      if (model%sections(model%parts(part)%section)%domain_integration == integration_gauss_conventional) then
        call make_error(error, "part "//integer_text(model%parts(part)%id)//": IDIM = 4 (conventional EFG, "// &
                        "4x4x4 Gauss points) is a verification variant of the linear static analysis; explicit "// &
                        "runs use IDIM = 1 (the default) or 2")
        return
      end if
      call build_efg_part(model, part, geometry, error)
      if (allocated(error)) return
      call set_up_efg_solver(model, geometry, group%parts(count))
    end do
    allocate (group%block_energy(block_energy_values, group%block_count()), source=0.0_wp)
  end subroutine build_group

  integer function element_count(self)
    class(efg_group_t), intent(in) :: self
    integer :: k, b
    element_count = 0
    do k = 1, size(self%parts)
      do b = 1, size(self%parts(k)%blocks)
        element_count = element_count + self%parts(k)%blocks(b)%point_count
      end do
    end do
  end function element_count

  !> Meshfree parts keep their density (the warning of explicit_setup says so); their mass
  !> counts as physical.
  subroutine scale_masses(self, model, nodes, target_step, physical_mass, added_mass)
    class(efg_group_t), intent(inout) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(in) :: nodes
    real(wp), intent(in) :: target_step
    real(wp), intent(inout) :: physical_mass, added_mass
    integer :: k
    do k = 1, size(self%parts)
      physical_mass = physical_mass + self%parts(k)%density*sum(self%parts(k)%geometry%mass_volume)
    end do
  end subroutine scale_masses

  !> Row-sum masses (eq. 29) and the interior particles.
  subroutine lump_masses(self, model, nodes)
    class(efg_group_t), intent(inout) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(inout) :: nodes
    integer :: k, j
    do k = 1, size(self%parts)
      associate (efg => self%parts(k))
        do j = 1, size(efg%geometry%mass_node)
          nodes%mass(efg%geometry%mass_node(j)) = nodes%mass(efg%geometry%mass_node(j)) + &
                                                  efg%density*efg%geometry%mass_volume(j)
        end do
        nodes%is_particle(efg%geometry%particles) = .true.
      end associate
    end do
  end subroutine lump_masses

  !> Part after part (a Gamma node shared with an FE part receives the finite elements' forces
  !> first, then these, always in this order). A distributed run (docs/parallel.md) computes
  !> the blocks of `computed` only, and the header covers them (the solver makes it global);
  !> the group's blocks are numbered part after part (block_count).
  subroutine add_internal_forces(self, model, nodes, step)
    class(efg_group_t), intent(inout) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(inout) :: nodes
    real(wp), intent(in) :: step
    integer :: k, b, before
    self%stable_time_step = huge(1.0_wp)
    self%critical_element = 0
    self%critical_block = 0
    self%failed_element = 0
    self%failed_block = 0
    self%step_not_finite = .false.
    ! the group's blocks of the parts before this one
    before = 0
    do k = 1, size(self%parts)
      associate (efg => self%parts(k))
        if (allocated(self%computed)) then
          call compute_efg_forces(model%materials(efg%geometry%material), efg, nodes%displacement, nodes%velocity, &
                                  step, nodes%internal_force, self%computed(before + 1:before + size(efg%blocks)))
        else
          call compute_efg_forces(model%materials(efg%geometry%material), efg, nodes%displacement, nodes%velocity, &
                                  step, nodes%internal_force)
        end if
        ! meshfree integration points follow the FE rule of their background cell; the first
        ! block on a tie (the same for any thread or rank count)
        do b = 1, size(efg%blocks)
          ! (a block another rank computes holds an old step)
          if (.not. self%computes(before + b)) cycle
          if (efg%block_time_step(b) < self%stable_time_step) then
            self%stable_time_step = efg%block_time_step(b)
            self%critical_element = efg%geometry%point_cell(efg%block_critical_point(b))
            self%critical_block = before + b
          end if
          if (self%failed_element == 0 .and. efg%block_inverted_point(b) /= 0) then
            self%failed_element = efg%geometry%point_cell(efg%block_inverted_point(b))
            self%failed_block = before + b
          end if
          if (efg%block_time_step(b) /= efg%block_time_step(b)) self%step_not_finite = .true.
        end do
        before = before + size(efg%blocks)
      end associate
    end do
  end subroutine add_internal_forces

  !> Per point block (the group's numbers, part after part): its points' internal energy and
  !> its power (no hourglass energy, no erosion).
  subroutine sum_block_energies(self)
    class(efg_group_t), intent(inout) :: self
    real(wp) :: internal(3)
    integer :: k, b, before
    before = 0
    do k = 1, size(self%parts)
      do b = 1, size(self%parts(k)%blocks)
        if (.not. self%computes(before + b)) cycle
        associate (block => self%parts(k)%blocks(b))
          internal = lane_energy_sums(block%internal_energy, block%force_power, block%point_count)
          self%block_energy(:, before + b) = [internal(1:2), 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp]
        end associate
      end do
      before = before + size(self%parts(k)%blocks)
    end do
  end subroutine sum_block_energies

  subroutine add_part_energies(self, nodes, average_step, step_correction, kinetic, internal, hourglass)
    class(efg_group_t), intent(in) :: self
    type(nodal_state_t), intent(in) :: nodes
    real(wp), intent(in) :: average_step, step_correction
    real(wp), intent(inout) :: kinetic(:), internal(:), hourglass(:)
    integer :: k, b, j, node, before
    before = 0
    do k = 1, size(self%parts)
      associate (efg => self%parts(k), part => self%parts(k)%geometry%part)
        do b = before + 1, before + size(efg%blocks)
          internal(part) = internal(part) + booked_energy(self%block_energy(1, b), self%block_energy(2, b), &
                                                          step_correction)
        end do
        before = before + size(efg%blocks)
        do j = 1, size(efg%geometry%mass_node)
          node = efg%geometry%mass_node(j)
          call add_kinetic_energy(efg%density*efg%geometry%mass_volume(j), nodes%velocity(:, node), &
                                  nodes%acceleration(:, node), average_step, kinetic(part), internal(part))
        end do
      end associate
    end do
  end subroutine add_part_energies

  subroutine add_part_momenta(self, nodes, half_step, momentum, mass)
    class(efg_group_t), intent(in) :: self
    type(nodal_state_t), intent(in) :: nodes
    real(wp), intent(in) :: half_step
    real(wp), intent(inout) :: momentum(:, :), mass(:)
    integer :: k, j, node
    real(wp) :: particle_mass
    do k = 1, size(self%parts)
      associate (efg => self%parts(k), part => self%parts(k)%geometry%part)
        do j = 1, size(efg%geometry%mass_node)
          node = efg%geometry%mass_node(j)
          particle_mass = efg%density*efg%geometry%mass_volume(j)
          momentum(:, part) = momentum(:, part) + particle_mass*(nodes%velocity(:, node) + &
                                                                 half_step*nodes%acceleration(:, node))
          mass(part) = mass(part) + particle_mass
        end do
      end associate
    end do
  end subroutine add_part_momenta

  subroutine element_results(self, model, results)
    class(efg_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    type(element_results_t), intent(inout) :: results
    integer :: k
    do k = 1, size(self%parts)
      call efg_point_results(model%materials(self%parts(k)%geometry%material), self%parts(k), results%solid_stress, &
                             results%solid_plastic_strain)
    end do
  end subroutine element_results

  !> A point is named by its background cell, a solid element of the deck.
  function describe(self, model, element) result(text)
    class(efg_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    integer, intent(in) :: element
    character(len=:), allocatable :: text
    text = "solid element "//integer_text(model%solid_ids(element))//" (part "// &
           integer_text(model%parts(model%solid_part(element))%id)//")"
  end function describe

  !> The part from the failed block (the header a distributed run made global names the block,
  !> which another rank may have computed).
  function failure_text(self, model) result(text)
    class(efg_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    character(len=:), allocatable :: text
    integer :: p, local
    call find_block(self, self%failed_block, p, local)
    text = "negative volume at an integration point of meshfree part "// &
           integer_text(model%parts(self%parts(p)%geometry%part)%id)//" (background cell "// &
           integer_text(model%solid_ids(self%failed_element))//")"
  end function failure_text

  subroutine to_physical(self, field, physical)
    class(efg_group_t), intent(in) :: self
    real(wp), intent(in) :: field(:, :)
    real(wp), intent(inout) :: physical(:, :)
    integer :: k
    do k = 1, size(self%parts)
      call transform_to_physical(self%parts(k)%geometry, field, physical)
    end do
  end subroutine to_physical

  !> Each part's rows of eq. 16 (walls and initial velocities act on the physical values).
  subroutine add_particle_rows(self, rows)
    class(efg_group_t), intent(in) :: self
    type(particle_rows_t), intent(inout) :: rows
    integer :: k
    do k = 1, size(self%parts)
      associate (geometry => self%parts(k)%geometry)
        call append_particle_rows(rows, geometry%particles, geometry%transform_offsets, geometry%transform_node, &
                                  geometry%transform_value)
      end associate
    end do
  end subroutine add_particle_rows

  !> The transpose of to_physical for forces (contact on physical positions): a particle's own
  !> entry is replaced by what the rows give it, its physical force goes to the nodes of its row
  !> with the row's weights, particle by particle (a fixed order).
  subroutine forces_to_generalized(self, physical, generalized)
    class(efg_group_t), intent(in) :: self
    real(wp), intent(in) :: physical(:, :)
    real(wp), intent(inout) :: generalized(:, :)
    integer :: k, j, n
    do k = 1, size(self%parts)
      associate (geometry => self%parts(k)%geometry)
        do j = 1, size(geometry%particles)
          generalized(:, geometry%particles(j)) = 0.0_wp
        end do
        do j = 1, size(geometry%particles)
          do n = geometry%transform_offsets(j), geometry%transform_offsets(j + 1) - 1
            generalized(:, geometry%transform_node(n)) = generalized(:, geometry%transform_node(n)) &
              + geometry%transform_value(n)*physical(:, geometry%particles(j))
          end do
        end do
      end associate
    end do
  end subroutine forces_to_generalized

  !> Particles, their dofs and the set-up time of the shape functions as well (set, not added:
  !> called before and after the run).
  subroutine add_to_summary(self, summary)
    class(efg_group_t), intent(in) :: self
    type(run_summary_t), intent(inout) :: summary
    integer :: k
    summary%efg_setup_s = 0.0_wp
    summary%efg_particles = 0
    summary%dofs_efg = 0
    do k = 1, size(self%parts)
      summary%efg_setup_s = summary%efg_setup_s + self%parts(k)%geometry%setup_seconds
      summary%efg_particles = summary%efg_particles + size(self%parts(k)%geometry%particles)
      summary%dofs_efg = summary%dofs_efg + 3*size(self%parts(k)%geometry%mass_node)
    end do
    summary%efg_s = self%timer%seconds
  end subroutine add_to_summary

  !> Each part's point blocks (the geometry, shape functions and gradients are rebuilt).
  subroutine exchange_state(self, store, path, error)
    class(efg_group_t), intent(inout) :: self
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(inout) :: error
    integer :: k
    call exchange_restart_count(store, path//"/count", "meshfree parts", size(self%parts), error)
    do k = 1, size(self%parts)
      call exchange_meshfree(store, path//"/"//integer_text(k), self%parts(k), error)
    end do
    call exchange_restart(store, path//"/seconds", self%timer%seconds, error)
  end subroutine exchange_state

  !> Blocks of all its parts, part after part (the order of its force call).
  !> One meshfree part: each point block's stresses, history, energies and powers, the points'
  !> W P, and the blocks' last steps (the geometry, shape functions and gradients are rebuilt).
  subroutine exchange_meshfree(store, path, solver, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(efg_solver_t), intent(inout) :: solver
    type(error_t), allocatable, intent(inout) :: error
    integer :: b
    character(len=:), allocatable :: block_path
    call exchange_restart_count(store, path//"/block_count", "integration point blocks in "//path, size(solver%blocks), error)
    call exchange_restart(store, path//"/point_stress", solver%point_stress, error)
    call exchange_restart(store, path//"/block_time_step", solver%block_time_step, error)
    call exchange_restart(store, path//"/block_critical_point", solver%block_critical_point, error)
    call exchange_restart(store, path//"/block_inverted_point", solver%block_inverted_point, error)
    do b = 1, size(solver%blocks)
      block_path = path//"/blocks/"//integer_text(b)
      call exchange_restart(store, block_path//"/stress", solver%blocks(b)%stress, error)
      call exchange_restart(store, block_path//"/history", solver%blocks(b)%history, error)
      call exchange_restart(store, block_path//"/internal_energy", solver%blocks(b)%internal_energy, error)
      call exchange_restart(store, block_path//"/force_power", solver%blocks(b)%force_power, error)
      call exchange_restart(store, block_path//"/previous_time_step", solver%blocks(b)%previous_time_step, error)
    end do
  end subroutine exchange_meshfree

  !> d3hsp's table: per background cell (a solid of the deck, LS-DYNA's "solid") the smallest
  !> step of its integration points at the current displacement, at rest (efg_point_time_steps),
  !> part after part, in the order of the points.
  subroutine list_time_steps(self, model, nodes, kind, element_ids, part_ids, steps)
    class(efg_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(in) :: nodes
    character(len=:), allocatable, intent(out) :: kind
    integer, allocatable, intent(out) :: element_ids(:), part_ids(:)
    real(wp), allocatable, intent(out) :: steps(:)
    real(wp), allocatable :: point_step(:)
    integer :: k, g, count, cell
    kind = "solid"
    count = 0
    do k = 1, size(self%parts)
      count = count + size(self%parts(k)%geometry%point_cell)
    end do
    allocate (element_ids(count), part_ids(count), steps(count))
    count = 0
    do k = 1, size(self%parts)
      associate (efg => self%parts(k))
        allocate (point_step(size(efg%geometry%point_cell)))
        call efg_point_time_steps(model%materials(efg%geometry%material), efg, nodes%displacement, point_step)
        cell = 0
        do g = 1, size(point_step)
          ! a cell's points are consecutive
          if (efg%geometry%point_cell(g) /= cell) then
            cell = efg%geometry%point_cell(g)
            count = count + 1
            element_ids(count) = model%solid_ids(cell)
            part_ids(count) = model%parts(model%solid_part(cell))%id
            steps(count) = point_step(g)
          else
            steps(count) = min(steps(count), point_step(g))
          end if
        end do
        deallocate (point_step)
      end associate
    end do
    element_ids = element_ids(1:count)
    part_ids = part_ids(1:count)
    steps = steps(1:count)
  end subroutine list_time_steps

  !> Its point blocks are shared out among the ranks of a distributed run (docs/parallel.md).
  logical function distributes_blocks(self)
    class(efg_group_t), intent(in) :: self
    distributes_blocks = .true.
  end function distributes_blocks

  !> One point block's state (a store in memory: the ranks of a distributed run bring their
  !> blocks together): its entries of the part's per-block step arrays, its stresses, history,
  !> energies, powers and last step, and its points' W P (the next force call's old power).
  subroutine exchange_block_state(self, store, block, error)
    class(efg_group_t), intent(inout) :: self
    type(restart_store_t), intent(inout) :: store
    integer, intent(in) :: block
    type(error_t), allocatable, intent(inout) :: error
    integer :: p, local
    call find_block(self, block, p, local)
    associate (solver => self%parts(p))
      associate (cells => solver%blocks(local))
        call exchange_restart(store, "time_step", solver%block_time_step(local), error)
        call exchange_restart(store, "critical_point", solver%block_critical_point(local), error)
        call exchange_restart(store, "inverted_point", solver%block_inverted_point(local), error)
        call exchange_restart(store, "point_stress", &
                              solver%point_stress(:, cells%first_point:cells%first_point + cells%point_count - 1), error)
        call exchange_restart(store, "stress", cells%stress, error)
        call exchange_restart(store, "history", cells%history, error)
        call exchange_restart(store, "internal_energy", cells%internal_energy, error)
        call exchange_restart(store, "force_power", cells%force_power, error)
        call exchange_restart(store, "previous_time_step", cells%previous_time_step, error)
      end associate
    end associate
  end subroutine exchange_block_state

  integer function block_count(self)
    class(efg_group_t), intent(in) :: self
    integer :: p
    block_count = 0
    do p = 1, size(self%parts)
      block_count = block_count + size(self%parts(p)%blocks)
    end do
  end function block_count

  !> The pair nodes of all the block's points: its force call reads and adds into them.
  subroutine block_nodes(self, block, nodes)
    class(efg_group_t), intent(in) :: self
    integer, intent(in) :: block
    integer, allocatable, intent(out) :: nodes(:)
    integer :: p, local
    call find_block(self, block, p, local)
    associate (geometry => self%parts(p)%geometry, first => self%parts(p)%blocks(local)%first_point, &
               points => self%parts(p)%blocks(local)%point_count)
      nodes = distinct_nodes(geometry%pair_node(geometry%point_offsets(first):geometry%point_offsets(first + points) - 1))
    end associate
  end subroutine block_nodes

  !> The background cell (model solid index) of each point of the block.
  subroutine block_elements(self, block, elements)
    class(efg_group_t), intent(in) :: self
    integer, intent(in) :: block
    integer, allocatable, intent(out) :: elements(:)
    integer :: p, local
    call find_block(self, block, p, local)
    associate (geometry => self%parts(p)%geometry, first => self%parts(p)%blocks(local)%first_point, &
               points => self%parts(p)%blocks(local)%point_count)
      elements = geometry%point_cell(first:first + points - 1)
    end associate
  end subroutine block_elements

  !> The part and its own block number of the group's block `block`.
  subroutine find_block(self, block, part, local)
    type(efg_group_t), intent(in) :: self
    integer, intent(in) :: block
    integer, intent(out) :: part, local
    local = block
    do part = 1, size(self%parts)
      if (local <= size(self%parts(part)%blocks)) return
      local = local - size(self%parts(part)%blocks)
    end do
    error stop "efg_group: block number beyond the group's blocks"
  end subroutine find_block
end module efg_group
