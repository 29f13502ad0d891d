!> The meshfree (EFG) shell parts (*SECTION_SHELL ELFORM 41) as an element group
!> (element_group): one efg_shell_solver_t per part that has shells, set up once on the
!> undeformed mesh (efg_shell_setup) and updated every cycle by efg_shell_forces. Its elements
!> are the background cells (shell elements of the deck): the time step, failures, messages and
!> results name them as "meshfree shell cell 12 (part 3)".
!>
!> Gamma nodes: besides the part's boundary edges (the set-up finds them), every node that the
!> rest of the model holds by its own value stays a Gamma node (physical unknowns): supports,
!> prescribed motions, nodal loads and lumped masses, rigid bodies (and extra nodes), spot
!> welds, tied contacts (their tied nodes and segment corners), and nodes that elements of any
!> other part (solids, shells, beams) use. Interior particles carry generalized values; output
!> and contact see their physical values (to_physical, forces_to_generalized).
!>
!> Masses: row-sum translational masses and rotary inertias scaled as the FE shells'
!> (efg_shell_nodal_masses). Mass scaling (DT2MS) leaves them alone, as it leaves the meshfree
!> solids (their mass counts as physical).
module efg_shell_group
  use kinds, only: wp
  use error_handling, only: error_t
  use run_summary, only: run_summary_t
  use text_format, only: integer_text
  use restart_file, only: restart_store_t, exchange_restart, exchange_restart_count
  use model, only: model_t, formulation_efg
  use nodal_state, only: nodal_state_t
  use element_group, only: element_group_t, element_results_t, distinct_nodes, family_shell, block_energy_values
  use particle_rows, only: particle_rows_t, append_particle_rows
  use element_work, only: booked_energy, lane_energy_sums, add_kinetic_energy
  use efg_shell_part, only: efg_shell_part_t
  use efg_shell_setup, only: build_efg_shell_part
  use efg_shell_forces, only: efg_shell_solver_t, set_up_efg_shell_solver, compute_efg_shell_forces, &
                              efg_shell_cell_results, efg_shell_nodal_masses, transform_shell_to_physical, &
                              transpose_shell_to_generalized, raise_corner_plastic_strain, stations_per_cell, &
                              efg_shell_cell_time_steps
  implicit none
  private

  public :: efg_shell_group_t, new_efg_shell_group

  !> Row-sum masses and rotary inertias one part gave its nodes (mass_node order).
  type :: part_masses_t
    real(wp), allocatable :: mass(:), inertia(:)
  end type part_masses_t

  type, extends(element_group_t) :: efg_shell_group_t
    type(efg_shell_solver_t), allocatable :: parts(:)
    type(part_masses_t), allocatable :: masses(:)
  contains
    procedure :: element_count
    procedure :: block_count
    procedure :: block_nodes
    procedure :: block_elements
    procedure :: scale_masses
    procedure :: lump_masses
    procedure :: add_internal_forces
    procedure :: sum_block_energies
    procedure :: add_energies
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
    procedure :: thinnest
    procedure :: raise_nodal_plastic_strain
    procedure :: list_time_steps
    procedure :: distributes_blocks, adds_moments
    procedure :: exchange_block_state
  end type efg_shell_group_t

contains

  !> A new group of this kind (its constructor for element_groups).
  subroutine new_efg_shell_group(model, group, error)
    type(model_t), intent(in) :: model
    class(element_group_t), allocatable, intent(out) :: group
    type(error_t), allocatable, intent(out) :: error
    allocate (efg_shell_group_t :: group)
    select type (group)
    type is (efg_shell_group_t)
      call build_group(model, group, error)
    end select
  end subroutine new_efg_shell_group

  !> Every EFG part that some shell element uses (a part no element uses has nothing to set up).
  subroutine build_group(model, group, error)
    type(model_t), intent(in) :: model
    type(efg_shell_group_t), intent(inout) :: group
    type(error_t), allocatable, intent(out) :: error
    type(efg_shell_part_t) :: geometry
    logical, allocatable :: used(:), extra_gamma_nodes(:)
    integer :: part, count, k

    group%name = "meshfree shell"
    group%element_family = family_shell
    allocate (used(size(model%parts)))
    used = .false.
    if (allocated(model%shell_part)) then
      do k = 1, size(model%shell_part)
        used(model%shell_part(k)) = .true.
      end do
    end if
    count = 0
    do part = 1, size(model%parts)
      if (model%parts(part)%formulation == formulation_efg .and. used(part)) count = count + 1
    end do
    allocate (group%parts(count), group%masses(count))
    if (count == 0) then
      allocate (group%block_energy(block_energy_values, 0))
      return
    end if
    count = 0
    do part = 1, size(model%parts)
      if (model%parts(part)%formulation /= formulation_efg .or. .not. used(part)) cycle
      count = count + 1
      call held_nodes(model, part, extra_gamma_nodes)
      call build_efg_shell_part(model, part, extra_gamma_nodes, geometry, error)
      if (allocated(error)) return
      call set_up_efg_shell_solver(model, geometry, group%parts(count))
      call efg_shell_nodal_masses(group%parts(count), size(model%coordinates, 2), group%masses(count)%mass, &
                                  group%masses(count)%inertia)
    end do
    allocate (group%block_energy(block_energy_values, group%block_count()), source=0.0_wp)
  end subroutine build_group

  !> The nodes of `part` that must keep physical unknowns (module comment).
  subroutine held_nodes(model, part, held)
    type(model_t), intent(in) :: model
    integer, intent(in) :: part
    logical, allocatable, intent(out) :: held(:)
    integer :: k, b
    allocate (held(size(model%coordinates, 2)))
    held = .false.
    if (allocated(model%spcs)) then
      do k = 1, size(model%spcs)
        held(model%spcs(k)%node) = .true.
      end do
    end if
    if (allocated(model%local_spcs)) then
      do k = 1, size(model%local_spcs)
        held(model%local_spcs(k)%node) = .true.
      end do
    end if
    if (allocated(model%motions)) then
      do k = 1, size(model%motions)
        held(model%motions(k)%node) = .true.
      end do
    end if
    if (allocated(model%loads)) then
      do k = 1, size(model%loads)
        if (model%loads(k)%node > 0) held(model%loads(k)%node) = .true.
      end do
    end if
    if (allocated(model%node_masses)) held = held .or. model%node_masses > 0.0_wp
    if (allocated(model%rigid_bodies)) then
      do b = 1, size(model%rigid_bodies)
        if (allocated(model%rigid_bodies(b)%nodes)) held(model%rigid_bodies(b)%nodes) = .true.
      end do
    end if
    if (allocated(model%spot_welds)) then
      do b = 1, size(model%spot_welds)
        if (allocated(model%spot_welds(b)%nodes)) held(model%spot_welds(b)%nodes) = .true.
      end do
    end if
    if (allocated(model%tied_contacts)) then
      do b = 1, size(model%tied_contacts)
        if (allocated(model%tied_contacts(b)%nodes)) held(model%tied_contacts(b)%nodes) = .true.
        if (allocated(model%tied_contacts(b)%segments)) then
          do k = 1, size(model%tied_contacts(b)%segments, 2)
            held(model%tied_contacts(b)%segments(:, k)) = .true.
          end do
        end if
      end do
    end if
    ! nodes of other parts' elements
    if (allocated(model%solid_part)) then
      do k = 1, size(model%solid_part)
        held(model%solid_nodes(:, k)) = .true.
      end do
    end if
    if (allocated(model%shell_part)) then
      do k = 1, size(model%shell_part)
        if (model%shell_part(k) /= part) held(model%shell_nodes(:, k)) = .true.
      end do
    end if
    if (allocated(model%beam_part)) then
      do k = 1, size(model%beam_part)
        held(model%beam_nodes(1:2, k)) = .true.
      end do
    end if
  end subroutine held_nodes

  integer function element_count(self)
    class(efg_shell_group_t), intent(in) :: self
    integer :: k
    element_count = 0
    do k = 1, size(self%parts)
      element_count = element_count + size(self%parts(k)%geometry%cells)
    end do
  end function element_count

  !> Meshfree shells keep their density (as the meshfree solids); their mass counts as physical.
  subroutine scale_masses(self, model, nodes, target_step, physical_mass, added_mass)
    class(efg_shell_group_t), intent(inout) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(in) :: nodes
    real(wp), intent(in) :: target_step
    real(wp), intent(inout) :: physical_mass, added_mass
    integer :: k
    do k = 1, size(self%parts)
      physical_mass = physical_mass + sum(self%masses(k)%mass)
    end do
  end subroutine scale_masses

  !> Row-sum masses and rotary inertias, part by part in mass_node order; the interior particles.
  subroutine lump_masses(self, model, nodes)
    class(efg_shell_group_t), intent(inout) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(inout) :: nodes
    integer :: k, j, node
    do k = 1, size(self%parts)
      associate (geometry => self%parts(k)%geometry)
        do j = 1, size(geometry%mass_node)
          node = geometry%mass_node(j)
          nodes%mass(node) = nodes%mass(node) + self%masses(k)%mass(j)
          nodes%rotary_inertia(node) = nodes%rotary_inertia(node) + self%masses(k)%inertia(j)
        end do
        nodes%is_particle(geometry%particles) = .true.
      end associate
    end do
  end subroutine lump_masses

  !> Part after part; the cell with the smallest step (the first block on a tie: the same for
  !> any thread or rank count) and the first failed cell. A distributed run (docs/parallel.md)
  !> computes the blocks of `computed` only, and the header covers them (the solver makes it
  !> global); the group's blocks are numbered part after part (block_count).
  subroutine add_internal_forces(self, model, nodes, step)
    class(efg_shell_group_t), intent(inout) :: self
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
          call compute_efg_shell_forces(model%materials(efg%geometry%material), efg, nodes%coordinates, &
                                        nodes%velocity, nodes%angular_velocity, step, nodes%internal_force, &
                                        nodes%internal_moment, nodes%shell_normal_sum, nodes%shell_area_sum, &
                                        self%computed(before + 1:before + size(efg%blocks)))
        else
          call compute_efg_shell_forces(model%materials(efg%geometry%material), efg, nodes%coordinates, &
                                        nodes%velocity, nodes%angular_velocity, step, nodes%internal_force, &
                                        nodes%internal_moment, nodes%shell_normal_sum, nodes%shell_area_sum)
        end if
        do b = 1, size(efg%blocks)
          ! (a block another rank computes holds an old step)
          if (.not. self%computes(before + b)) cycle
          if (efg%block_time_step(b) < self%stable_time_step) then
            self%stable_time_step = efg%block_time_step(b)
            self%critical_element = efg%geometry%cells(efg%block_critical_cell(b))
            self%critical_block = before + b
          end if
          if (self%failed_element == 0 .and. efg%block_failed_cell(b) /= 0) then
            self%failed_element = efg%geometry%cells(efg%block_failed_cell(b))
            self%failed_block = before + b
          end if
          if (efg%block_time_step(b) /= efg%block_time_step(b)) self%step_not_finite = .true.
        end do
        before = before + size(efg%blocks)
      end associate
    end do
  end subroutine add_internal_forces

  !> Internal energy: membrane, bending and transverse shear work (no hourglass energy: the
  !> sub-cell points leave no membrane or bending mode free).
  !> Per cell block (the group's numbers, part after part): its points' internal energy and
  !> its power, its cells' transverse shear energy and its power in the rows of the hourglass
  !> energy (add_energies counts it as internal energy: the kind has no hourglass modes).
  subroutine sum_block_energies(self)
    class(efg_shell_group_t), intent(inout) :: self
    real(wp) :: membrane(3), shear(3)
    integer :: k, b, before
    before = 0
    do k = 1, size(self%parts)
      do b = 1, size(self%parts(k)%blocks)
        if (.not. self%computes(before + b)) cycle
        associate (block => self%parts(k)%blocks(b))
          membrane = lane_energy_sums(block%internal_energy, block%force_power, block%point_count)
          shear = lane_energy_sums(block%shear_energy, block%shear_power, block%cell_count)
        end associate
        self%block_energy(:, before + b) = [membrane(1:2), shear(1:2), 0.0_wp, 0.0_wp]
      end do
      before = before + size(self%parts(k)%blocks)
    end do
  end subroutine sum_block_energies

  subroutine add_energies(self, step_correction, internal, hourglass)
    class(efg_shell_group_t), intent(in) :: self
    real(wp), intent(in) :: step_correction
    real(wp), intent(inout) :: internal, hourglass
    integer :: k, before
    before = 0
    do k = 1, size(self%parts)
      internal = internal + part_internal_energy(self, before, size(self%parts(k)%blocks), step_correction)
      before = before + size(self%parts(k)%blocks)
    end do
  end subroutine add_energies

  !> A part's internal energy from the sums of its blocks, the group's blocks before + 1 to
  !> before + blocks.
  real(wp) function part_internal_energy(group, before, blocks, step_correction) result(energy)
    type(efg_shell_group_t), intent(in) :: group
    integer, intent(in) :: before, blocks
    real(wp), intent(in) :: step_correction
    integer :: b
    energy = 0.0_wp
    do b = before + 1, before + blocks
      energy = energy + booked_energy(group%block_energy(1, b), group%block_energy(2, b), step_correction) &
               + booked_energy(group%block_energy(3, b), group%block_energy(4, b), step_correction)
    end do
  end function part_internal_energy

  subroutine add_part_energies(self, nodes, average_step, step_correction, kinetic, internal, hourglass)
    class(efg_shell_group_t), intent(in) :: self
    type(nodal_state_t), intent(in) :: nodes
    real(wp), intent(in) :: average_step, step_correction
    real(wp), intent(inout) :: kinetic(:), internal(:), hourglass(:)
    integer :: k, j, node, before
    before = 0
    do k = 1, size(self%parts)
      associate (efg => self%parts(k), part => self%parts(k)%geometry%part)
        internal(part) = internal(part) + part_internal_energy(self, before, size(efg%blocks), step_correction)
        before = before + size(efg%blocks)
        do j = 1, size(efg%geometry%mass_node)
          node = efg%geometry%mass_node(j)
          call add_kinetic_energy(self%masses(k)%mass(j), nodes%velocity(:, node), nodes%acceleration(:, node), &
                                  average_step, kinetic(part), internal(part))
          call add_kinetic_energy(self%masses(k)%inertia(j), nodes%angular_velocity(:, node), &
                                  nodes%angular_acceleration(:, node), average_step, kinetic(part), internal(part))
        end do
      end associate
    end do
  end subroutine add_part_energies

  subroutine add_part_momenta(self, nodes, half_step, momentum, mass)
    class(efg_shell_group_t), intent(in) :: self
    type(nodal_state_t), intent(in) :: nodes
    real(wp), intent(in) :: half_step
    real(wp), intent(inout) :: momentum(:, :), mass(:)
    integer :: k, j, node
    do k = 1, size(self%parts)
      associate (efg => self%parts(k), part => self%parts(k)%geometry%part)
        do j = 1, size(efg%geometry%mass_node)
          node = efg%geometry%mass_node(j)
          momentum(:, part) = momentum(:, part) + self%masses(k)%mass(j)*(nodes%velocity(:, node) + &
                                                                          half_step*nodes%acceleration(:, node))
          mass(part) = mass(part) + self%masses(k)%mass(j)
        end do
      end associate
    end do
  end subroutine add_part_momenta

  !> Per cell, into the shell rows: the mean stress of its points, the peak point, plastic strains.
  subroutine element_results(self, model, results)
    class(efg_shell_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    type(element_results_t), intent(inout) :: results
    integer :: k
    do k = 1, size(self%parts)
      if (allocated(results%shell_point_stress)) then
        call efg_shell_cell_results(model%materials(self%parts(k)%geometry%material), self%parts(k), &
                                    results%shell_stress, results%shell_stress_peak, results%shell_plastic_strain, &
                                    results%shell_plastic_strain_peak, results%shell_point_stress, &
                                    results%shell_point_plastic_strain, results%shell_point_count, &
                                    results%shell_resultant, results%shell_thickness, results%shell_energy_density)
      else
        call efg_shell_cell_results(model%materials(self%parts(k)%geometry%material), self%parts(k), &
                                    results%shell_stress, results%shell_stress_peak, results%shell_plastic_strain, &
                                    results%shell_plastic_strain_peak)
      end if
    end do
  end subroutine element_results

  !> A cell is named by its shell element of the deck.
  function describe(self, model, element) result(text)
    class(efg_shell_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    integer, intent(in) :: element
    character(len=:), allocatable :: text
    text = "meshfree shell cell "//integer_text(model%shell_ids(element))//" (part "// &
           integer_text(model%parts(model%shell_part(element))%id)//")"
  end function describe

  function failure_text(self, model) result(text)
    class(efg_shell_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    character(len=:), allocatable :: text
    text = self%describe(model, self%failed_element)//": an integration point's surface stretch det F is no "// &
           "longer positive (the cell folded over or lost its area)"
  end function failure_text

  subroutine to_physical(self, field, physical)
    class(efg_shell_group_t), intent(in) :: self
    real(wp), intent(in) :: field(:, :)
    real(wp), intent(inout) :: physical(:, :)
    integer :: k
    do k = 1, size(self%parts)
      call transform_shell_to_physical(self%parts(k), field, physical)
    end do
  end subroutine to_physical

  !> Each part's rows of eq. 16 (walls and initial velocities act on the physical values).
  subroutine add_particle_rows(self, rows)
    class(efg_shell_group_t), intent(in) :: self
    type(particle_rows_t), intent(inout) :: rows
    integer :: k
    do k = 1, size(self%parts)
      associate (geometry => self%parts(k)%geometry)
        call append_particle_rows(rows, geometry%particles, geometry%transform_offsets, geometry%transform_node, &
                                  geometry%transform_value)
      end associate
    end do
  end subroutine add_particle_rows

  subroutine forces_to_generalized(self, physical, generalized)
    class(efg_shell_group_t), intent(in) :: self
    real(wp), intent(in) :: physical(:, :)
    real(wp), intent(inout) :: generalized(:, :)
    integer :: k
    do k = 1, size(self%parts)
      call transpose_shell_to_generalized(self%parts(k), physical, generalized)
    end do
  end subroutine forces_to_generalized

  !> The largest plastic strain of the cells around each node of a spot weld that fails by EP.
  subroutine raise_nodal_plastic_strain(self, model, wanted, strain)
    class(efg_shell_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    logical, intent(in) :: wanted(:)
    real(wp), intent(inout) :: strain(:)
    integer :: k, before
    ! (a distributed run takes the largest over the ranks: each has its computed blocks current)
    before = 0
    do k = 1, size(self%parts)
      associate (efg => self%parts(k))
        if (allocated(self%computed)) then
          call raise_corner_plastic_strain(model%materials(efg%geometry%material), efg, wanted, strain, &
                                           self%computed(before + 1:before + size(efg%blocks)))
        else
          call raise_corner_plastic_strain(model%materials(efg%geometry%material), efg, wanted, strain)
        end if
        before = before + size(efg%blocks)
      end associate
    end do
  end subroutine raise_nodal_plastic_strain

  real(wp) function thinnest(self)
    class(efg_shell_group_t), intent(in) :: self
    integer :: k
    thinnest = huge(1.0_wp)
    do k = 1, size(self%parts)
      thinnest = min(thinnest, minval(self%parts(k)%geometry%cell_thickness))
    end do
  end function thinnest

  !> Cells, particles, dofs, the set-up seconds and the force calls' seconds (set, not added:
  !> called before and after the run).
  subroutine add_to_summary(self, summary)
    class(efg_shell_group_t), intent(in) :: self
    type(run_summary_t), intent(inout) :: summary
    integer :: k
    summary%efg_shell_cells = 0
    summary%efg_shell_particles = 0
    summary%dofs_efg_shell = 0
    summary%efg_shell_setup_s = 0.0_wp
    do k = 1, size(self%parts)
      summary%efg_shell_cells = summary%efg_shell_cells + size(self%parts(k)%geometry%cells)
      summary%efg_shell_particles = summary%efg_shell_particles + size(self%parts(k)%geometry%particles)
      summary%dofs_efg_shell = summary%dofs_efg_shell + 6*size(self%parts(k)%geometry%mass_node)
      summary%efg_shell_setup_s = summary%efg_shell_setup_s + self%parts(k)%geometry%setup_seconds
    end do
    summary%efg_shell_s = self%timer%seconds
  end subroutine add_to_summary

  !> Each part's blocks and the per-point and per-cell forces of the last call (the geometry is
  !> rebuilt from the deck).
  subroutine exchange_state(self, store, path, error)
    class(efg_shell_group_t), intent(inout) :: self
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(inout) :: error
    integer :: k
    call exchange_restart_count(store, path//"/count", "meshfree shell parts", size(self%parts), error)
    do k = 1, size(self%parts)
      call exchange_part(store, path//"/"//integer_text(k), self%parts(k), error)
    end do
    call exchange_restart(store, path//"/seconds", self%timer%seconds, error)
  end subroutine exchange_state

  !> Blocks of all its parts, part after part (the order of its force call).
  subroutine exchange_part(store, path, solver, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(efg_shell_solver_t), intent(inout) :: solver
    type(error_t), allocatable, intent(inout) :: error
    integer :: b
    character(len=:), allocatable :: block_path
    call exchange_restart_count(store, path//"/block_count", "cell blocks in "//path, size(solver%blocks), error)
    call exchange_restart(store, path//"/cell_frame", solver%cell_frame, error)
    call exchange_restart(store, path//"/cell_area", solver%cell_area, error)
    call exchange_restart(store, path//"/point_membrane", solver%point_membrane, error)
    call exchange_restart(store, path//"/point_moment", solver%point_moment, error)
    call exchange_restart(store, path//"/point_force", solver%point_force, error)
    call exchange_restart(store, path//"/point_couple", solver%point_couple, error)
    call exchange_restart(store, path//"/station_force", solver%station_force, error)
    call exchange_restart(store, path//"/block_time_step", solver%block_time_step, error)
    call exchange_restart(store, path//"/block_critical_cell", solver%block_critical_cell, error)
    call exchange_restart(store, path//"/block_failed_cell", solver%block_failed_cell, error)
    do b = 1, size(solver%blocks)
      block_path = path//"/blocks/"//integer_text(b)
      call exchange_restart(store, block_path//"/stress", solver%blocks(b)%stress, error)
      call exchange_restart(store, block_path//"/history", solver%blocks(b)%history, error)
      call exchange_restart(store, block_path//"/shear_stress", solver%blocks(b)%shear_stress, error)
      call exchange_restart(store, block_path//"/internal_energy", solver%blocks(b)%internal_energy, error)
      call exchange_restart(store, block_path//"/force_power", solver%blocks(b)%force_power, error)
      call exchange_restart(store, block_path//"/shear_energy", solver%blocks(b)%shear_energy, error)
      call exchange_restart(store, block_path//"/shear_power", solver%blocks(b)%shear_power, error)
      call exchange_restart(store, block_path//"/previous_time_step", solver%blocks(b)%previous_time_step, error)
    end do
  end subroutine exchange_part

  !> d3hsp's table: each cell's stable step on the current coordinates (a shell of the deck,
  !> LS-DYNA's "shell"; efg_shell_cell_time_steps), part after part, in cell order.
  subroutine list_time_steps(self, model, nodes, kind, element_ids, part_ids, steps)
    class(efg_shell_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(in) :: nodes
    character(len=:), allocatable, intent(out) :: kind
    integer, allocatable, intent(out) :: element_ids(:), part_ids(:)
    real(wp), allocatable, intent(out) :: steps(:)
    integer :: k, c, count
    kind = "shell"
    count = 0
    do k = 1, size(self%parts)
      count = count + size(self%parts(k)%geometry%cells)
    end do
    allocate (element_ids(count), part_ids(count), steps(count))
    count = 0
    do k = 1, size(self%parts)
      associate (efg => self%parts(k))
        call efg_shell_cell_time_steps(model%materials(efg%geometry%material), efg, nodes%coordinates, &
                                       steps(count + 1:count + size(efg%geometry%cells)))
        do c = 1, size(efg%geometry%cells)
          element_ids(count + c) = model%shell_ids(efg%geometry%cells(c))
          part_ids(count + c) = model%parts(model%shell_part(efg%geometry%cells(c)))%id
        end do
        count = count + size(efg%geometry%cells)
      end associate
    end do
  end subroutine list_time_steps

  !> Its cell blocks are shared out among the ranks of a distributed run (docs/parallel.md).
  logical function distributes_blocks(self)
    class(efg_shell_group_t), intent(in) :: self
    distributes_blocks = .true.
  end function distributes_blocks

  logical function adds_moments(self)
    class(efg_shell_group_t), intent(in) :: self
    adds_moments = .true.
  end function adds_moments

  !> One cell block's state (a store in memory: the ranks of a distributed run bring their
  !> blocks together): its entries of the part's per-block step arrays, its stresses, history,
  !> energies, powers and last step, and what its force call keeps per cell, point and station
  !> (frames, areas, resultants, the point and station forces: the next call and the output
  !> read them).
  subroutine exchange_block_state(self, store, block, error)
    class(efg_shell_group_t), intent(inout) :: self
    type(restart_store_t), intent(inout) :: store
    integer, intent(in) :: block
    type(error_t), allocatable, intent(inout) :: error
    integer :: p, local, first_cell, last_cell, first_point, last_point
    call find_block(self, block, p, local)
    associate (solver => self%parts(p))
      associate (cells => solver%blocks(local))
        first_cell = cells%first_cell
        last_cell = cells%first_cell + cells%cell_count - 1
        first_point = cells%first_point
        last_point = cells%first_point + cells%point_count - 1
        call exchange_restart(store, "time_step", solver%block_time_step(local), error)
        call exchange_restart(store, "critical_cell", solver%block_critical_cell(local), error)
        call exchange_restart(store, "failed_cell", solver%block_failed_cell(local), error)
        call exchange_restart(store, "cell_frame", solver%cell_frame(:, :, first_cell:last_cell), error)
        call exchange_restart(store, "cell_area", solver%cell_area(first_cell:last_cell), error)
        call exchange_restart(store, "point_membrane", solver%point_membrane(:, first_point:last_point), error)
        call exchange_restart(store, "point_moment", solver%point_moment(:, first_point:last_point), error)
        call exchange_restart(store, "point_force", solver%point_force(:, :, first_point:last_point), error)
        call exchange_restart(store, "point_couple", solver%point_couple(:, :, first_point:last_point), error)
        call exchange_restart(store, "station_force", solver%station_force(:, :, first_cell:last_cell), error)
        call exchange_restart(store, "stress", cells%stress, error)
        call exchange_restart(store, "history", cells%history, error)
        call exchange_restart(store, "shear_stress", cells%shear_stress, error)
        call exchange_restart(store, "internal_energy", cells%internal_energy, error)
        call exchange_restart(store, "force_power", cells%force_power, error)
        call exchange_restart(store, "shear_energy", cells%shear_energy, error)
        call exchange_restart(store, "shear_power", cells%shear_power, error)
        call exchange_restart(store, "previous_time_step", cells%previous_time_step, error)
      end associate
    end associate
  end subroutine exchange_block_state

  integer function block_count(self)
    class(efg_shell_group_t), intent(in) :: self
    integer :: p
    block_count = 0
    do p = 1, size(self%parts)
      block_count = block_count + size(self%parts(p)%blocks)
    end do
  end function block_count

  !> The pair nodes of all the block's points, its cells' corners and station rows: its force
  !> call reads and adds into them.
  subroutine block_nodes(self, block, nodes)
    class(efg_shell_group_t), intent(in) :: self
    integer, intent(in) :: block
    integer, allocatable, intent(out) :: nodes(:)
    integer :: p, local
    call find_block(self, block, p, local)
    associate (geometry => self%parts(p)%geometry, first => self%parts(p)%blocks(local)%first_point, &
               points => self%parts(p)%blocks(local)%point_count)
      associate (solver => self%parts(p), cells => self%parts(p)%blocks(local))
        nodes = distinct_nodes([geometry%pair_node(geometry%point_offsets(first):geometry%point_offsets(first + points) - 1), &
                                solver%station_node(solver%station_offsets(stations_per_cell*(cells%first_cell - 1) + 1): &
                                                    solver%station_offsets(stations_per_cell*(cells%first_cell + &
                                                                                              cells%cell_count - 1) + 1) - 1), &
                                reshape(solver%cell_nodes(:, cells%first_cell:cells%first_cell + cells%cell_count - 1), &
                                        [4*cells%cell_count])])
      end associate
    end associate
  end subroutine block_nodes

  !> The background cell (model shell index) of each point of the block.
  subroutine block_elements(self, block, elements)
    class(efg_shell_group_t), intent(in) :: self
    integer, intent(in) :: block
    integer, allocatable, intent(out) :: elements(:)
    integer :: p, local
    call find_block(self, block, p, local)
    associate (geometry => self%parts(p)%geometry, first => self%parts(p)%blocks(local)%first_point, &
               points => self%parts(p)%blocks(local)%point_count)
      elements = geometry%cells(geometry%point_cell(first:first + points - 1))
    end associate
  end subroutine block_elements

  !> The part and its own block number of the group's block `block`.
  subroutine find_block(self, block, part, local)
    type(efg_shell_group_t), intent(in) :: self
    integer, intent(in) :: block
    integer, intent(out) :: part, local
    local = block
    do part = 1, size(self%parts)
      if (local <= size(self%parts(part)%blocks)) return
      local = local - size(self%parts(part)%blocks)
    end do
    error stop "efg_shell_group: block number beyond the group's blocks"
  end subroutine find_block
end module efg_shell_group
