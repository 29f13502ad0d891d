!> The FE solid hexahedra as an element group (element_group): the blocks of solid_block, their
!> colouring, corner masses and the per-block results of the last force call.
module solid_group
  use kinds, only: wp, block_size
  use gather_list, only: gather_list_t
  use block_colouring, only: colour_blocks_by_nodes
  use model, only: model_t
  use error_handling, only: error_t
  use text_format, only: integer_text
  use restart_file, only: restart_store_t, exchange_restart, exchange_restart_count
  use run_summary, only: run_summary_t
  use nodal_state, only: nodal_state_t
  use element_group, only: element_group_t, element_results_t, distortion_t, distinct_nodes, family_solid, &
                           block_energy_values
  use element_work, only: append_marked_lanes, mark_lanes, booked_energy, block_energy_column, add_kinetic_energy, &
                          scale_block_density, raise_largest_scaling
  use solid_block, only: solid_block_t, build_solid_blocks, solid_block_corner_masses, solid_block_time_steps, &
                         compute_solid_block, solid_block_element_results
  use distortion_check, only: check_solid_distortion
  implicit none
  private

  public :: solid_group_t, new_solid_group

  type, extends(element_group_t) :: solid_group_t
    type(solid_block_t), allocatable :: blocks(:)
    real(wp), allocatable :: corner_mass(:, :, :)        !< (block_size, 8, blocks)
    real(wp), allocatable :: block_time_step(:)          !< per block, from its kernel
    integer, allocatable :: block_critical_element(:)
    integer, allocatable :: block_inverted_element(:)
    type(gather_list_t) :: colours                       !< colour -> blocks (CSR)
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
    procedure :: distributes_blocks
    procedure :: exchange_block_state
    procedure :: failure_text
    procedure :: most_scaled
    procedure :: check_distortion
    procedure :: newly_eroded_elements
    procedure :: mark_eroded
    procedure :: list_time_steps
  end type solid_group_t

contains

  !> The model's FE solids in blocks (solid_block's order), nothing computed yet.
  !> A new group of this kind (its constructor for element_groups).
  subroutine new_solid_group(model, group)
    type(model_t), intent(in) :: model
    class(element_group_t), allocatable, intent(out) :: group
    allocate (solid_group_t :: group)
    select type (group)
    type is (solid_group_t)
      call build_group(model, group)
    end select
  end subroutine new_solid_group

  subroutine build_group(model, group)
    type(model_t), intent(in) :: model
    type(solid_group_t), intent(inout) :: group
    integer :: count
    group%name = "solid"
    group%element_family = family_solid
    call build_solid_blocks(model, group%blocks)
    count = size(group%blocks)
    allocate (group%corner_mass(block_size, 8, count), group%block_time_step(count), &
              group%block_critical_element(count), group%block_inverted_element(count))
    group%corner_mass = 0.0_wp
    allocate (group%block_energy(block_energy_values, count), source=0.0_wp)
    group%block_time_step = huge(1.0_wp)
    group%block_critical_element = 0
    group%block_inverted_element = 0
  end subroutine build_group

  integer function element_count(self)
    class(solid_group_t), intent(in) :: self
    integer :: b
    element_count = 0
    do b = 1, size(self%blocks)
      element_count = element_count + self%blocks(b)%element_count
    end do
  end function element_count

  !> Mass scaling (*CONTROL_TIMESTEP DT2MS): each element whose stable step on the undeformed
  !> mesh is below `target_step` gets the density that brings its step to it.
  subroutine scale_masses(self, model, nodes, target_step, physical_mass, added_mass)
    class(solid_group_t), intent(inout) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(in) :: nodes
    real(wp), intent(in) :: target_step
    real(wp), intent(inout) :: physical_mass, added_mass
    real(wp) :: element_time_step(block_size)
    integer :: b
    element_time_step = huge(1.0_wp)
    do b = 1, size(self%blocks)
      associate (block => self%blocks(b))
        if (target_step > 0.0_wp) &
          call solid_block_time_steps(block, model%materials(block%material), nodes%coordinates, element_time_step)
        call scale_block_density(block%element_count, block%reference_volume, target_step, element_time_step, &
                                 block%density, physical_mass, added_mass)
      end associate
    end do
  end subroutine scale_masses

  !> Colour the blocks, then add their corner masses to the nodes (serially, in block, corner
  !> and lane order).
  subroutine lump_masses(self, model, nodes)
    class(solid_group_t), intent(inout) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(inout) :: nodes
    integer, allocatable :: block_nodes(:, :, :), counts(:)
    integer :: b, corner, lane, node
    allocate (block_nodes(block_size, 8, size(self%blocks)), counts(size(self%blocks)))
    do b = 1, size(self%blocks)
      block_nodes(:, :, b) = self%blocks(b)%nodes
      counts(b) = self%blocks(b)%element_count
    end do
    call colour_blocks_by_nodes(nodes%count, block_nodes, counts, self%colours)
    do b = 1, size(self%blocks)
      call solid_block_corner_masses(self%blocks(b), self%corner_mass(:, :, b))
      do corner = 1, 8
        do lane = 1, self%blocks(b)%element_count
          node = self%blocks(b)%nodes(lane, corner)
          nodes%mass(node) = nodes%mass(node) + self%corner_mass(lane, corner, b)
        end do
      end do
    end do
  end subroutine lump_masses

  !> The blocks of a colour compute their corner forces in parallel and add them straight into
  !> the nodal forces; colours follow one another. Each node receives its contributions in a
  !> fixed order (colour, then lane and corner): the same sum for any thread count, with no
  !> atomics and no per-corner force array in memory.
  subroutine add_internal_forces(self, model, nodes, step)
    class(solid_group_t), intent(inout) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(inout) :: nodes
    real(wp), intent(in) :: step
    real(wp) :: block_force(block_size, 8, 3)
    integer :: colour, k, b
    do b = 1, size(self%blocks)
      ! ERODE's step, or the material's TDEL (MAT_024), whichever is larger
      self%blocks(b)%erosion_time_step = max(merge(self%erosion_time_step, 0.0_wp, model%erode_solids_on_step), &
                                             model%materials(self%blocks(b)%material)%failure_time_step)
    end do
    do colour = 1, size(self%colours%offsets) - 1
      !$omp parallel do schedule(dynamic, 2) default(shared) private(k, b, block_force)
      do k = self%colours%offsets(colour), self%colours%offsets(colour + 1) - 1
        b = self%colours%corners(k)
        if (.not. self%computes(b)) cycle
        call compute_solid_block(self%blocks(b), model%materials(self%blocks(b)%material), &
                                 nodes%coordinates, nodes%velocity, step, block_force, &
                                 self%block_time_step(b), self%block_critical_element(b), &
                                 self%block_inverted_element(b))
        call add_block_forces(self%blocks(b)%element_count, self%blocks(b)%nodes, block_force, &
                              nodes%internal_force)
      end do
      !$omp end parallel do
    end do
    call self%header_from_blocks(self%block_time_step, self%block_critical_element, self%block_inverted_element)
    self%newly_eroded = 0
    ! (distributed: the blocks this rank owns; the solver adds the ranks' counts)
    do b = 1, size(self%blocks)
      if (.not. self%owns(b)) cycle
      self%newly_eroded = self%newly_eroded + count(self%blocks(b)%newly_eroded)
    end do
    self%eroded_count = self%eroded_count + self%newly_eroded
  end subroutine add_internal_forces

  !> Its solids eroded by the last force call, block by block.
  function newly_eroded_elements(self) result(elements)
    class(solid_group_t), intent(in) :: self
    integer, allocatable :: elements(:)
    integer :: b, n
    allocate (elements(self%newly_eroded))
    n = 0
    do b = 1, size(self%blocks)
      call append_marked_lanes(self%blocks(b)%element_count, self%blocks(b)%newly_eroded, self%blocks(b)%elements, &
                               elements, n)
    end do
  end function newly_eroded_elements

  subroutine mark_eroded(self, solid_eroded, shell_eroded)
    class(solid_group_t), intent(in) :: self
    logical, intent(inout) :: solid_eroded(:), shell_eroded(:)
    integer :: b
    do b = 1, size(self%blocks)
      call mark_lanes(self%blocks(b)%element_count, self%blocks(b)%eroded, self%blocks(b)%elements, solid_eroded)
    end do
  end subroutine mark_eroded

  !> Each computed block's energy sums (element_group's block_energy).
  subroutine sum_block_energies(self)
    class(solid_group_t), intent(inout) :: self
    integer :: b
    do b = 1, size(self%blocks)
      if (.not. self%computes(b)) cycle
      associate (block => self%blocks(b))
        self%block_energy(:, b) = block_energy_column(block%internal_energy, block%force_power, block%hourglass_energy, &
                                                      block%hourglass_power, block%element_count, block%eroded)
      end associate
    end do
  end subroutine sum_block_energies

  !> A node's kinetic energy is shared among parts in proportion to the corner masses.
  subroutine add_part_energies(self, nodes, average_step, step_correction, kinetic, internal, hourglass)
    class(solid_group_t), intent(in) :: self
    type(nodal_state_t), intent(in) :: nodes
    real(wp), intent(in) :: average_step, step_correction
    real(wp), intent(inout) :: kinetic(:), internal(:), hourglass(:)
    integer :: b, corner, lane, node
    do b = 1, size(self%blocks)
      associate (block => self%blocks(b))
        internal(block%part) = internal(block%part) + booked_energy(self%block_energy(1, b), self%block_energy(2, b), &
                                                                    step_correction)
        hourglass(block%part) = hourglass(block%part) + booked_energy(self%block_energy(3, b), self%block_energy(4, b), &
                                                                      step_correction)
        do corner = 1, 8
          do lane = 1, block%element_count
            node = block%nodes(lane, corner)
            call add_kinetic_energy(self%corner_mass(lane, corner, b), nodes%velocity(:, node), &
                                    nodes%acceleration(:, node), average_step, kinetic(block%part), internal(block%part))
          end do
        end do
      end associate
    end do
  end subroutine add_part_energies

  subroutine add_part_momenta(self, nodes, half_step, momentum, mass)
    class(solid_group_t), intent(in) :: self
    type(nodal_state_t), intent(in) :: nodes
    real(wp), intent(in) :: half_step
    real(wp), intent(inout) :: momentum(:, :), mass(:)
    integer :: b, corner, lane, node
    do b = 1, size(self%blocks)
      associate (block => self%blocks(b))
        do corner = 1, 8
          do lane = 1, block%element_count
            node = block%nodes(lane, corner)
            momentum(:, block%part) = momentum(:, block%part) + self%corner_mass(lane, corner, b)* &
                                      (nodes%velocity(:, node) + half_step*nodes%acceleration(:, node))
            mass(block%part) = mass(block%part) + self%corner_mass(lane, corner, b)
          end do
        end do
      end associate
    end do
  end subroutine add_part_momenta

  subroutine element_results(self, model, results)
    class(solid_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    type(element_results_t), intent(inout) :: results
    integer :: b, lane
    do b = 1, size(self%blocks)
      call solid_block_element_results(self%blocks(b), results%solid_stress, results%solid_plastic_strain)
      if (.not. allocated(results%solid_eroded)) cycle
      do lane = 1, self%blocks(b)%element_count
        results%solid_eroded(self%blocks(b)%elements(lane)) = merge(1, 0, self%blocks(b)%eroded(lane))
      end do
    end do
  end subroutine element_results

  function describe(self, model, element) result(text)
    class(solid_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    integer, intent(in) :: element
    character(len=:), allocatable :: text
    character(len=32) :: id, part
    write (id, '(i0)') model%solid_ids(element)
    write (part, '(i0)') model%parts(model%solid_part(element))%id
    text = "solid element "//trim(id)//" (part "//trim(part)//")"
  end function describe

  function failure_text(self, model) result(text)
    class(solid_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    character(len=:), allocatable :: text
    text = "negative volume in "//self%describe(model, self%failed_element)
  end function failure_text

  subroutine most_scaled(self, model, largest, element)
    class(solid_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    real(wp), intent(inout) :: largest
    integer, intent(inout) :: element
    integer :: b
    do b = 1, size(self%blocks)
      associate (block => self%blocks(b))
        call raise_largest_scaling(block%element_count, block%density, model%materials(block%material)%density, &
                                   block%elements, largest, element)
      end associate
    end do
  end subroutine most_scaled

  subroutine check_distortion(self, model, nodes, time, distortion)
    class(solid_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(in) :: nodes
    real(wp), intent(in) :: time
    type(distortion_t), intent(inout) :: distortion
    call check_solid_distortion(model, self%blocks, nodes%coordinates, time, distortion)
  end subroutine check_distortion

  !> internal_force(:, node) += the block's corner forces, corner by corner, lane by lane.
  subroutine add_block_forces(element_count, nodes, block_force, internal_force)
    integer, intent(in) :: element_count
    integer, intent(in) :: nodes(block_size, 8)
    real(wp), intent(in) :: block_force(block_size, 8, 3)
    real(wp), intent(inout) :: internal_force(:, :)
    integer :: corner, lane, node
    do corner = 1, 8
      do lane = 1, element_count
        node = nodes(lane, corner)
        internal_force(1, node) = internal_force(1, node) + block_force(lane, corner, 1)
        internal_force(2, node) = internal_force(2, node) + block_force(lane, corner, 2)
        internal_force(3, node) = internal_force(3, node) + block_force(lane, corner, 3)
      end do
    end do
  end subroutine add_block_forces

  !> Its element count and the seconds of its force calls (set, not added: called before and
  !> after the run).
  subroutine add_to_summary(self, summary)
    class(solid_group_t), intent(in) :: self
    type(run_summary_t), intent(inout) :: summary
    summary%fe_solids = self%element_count()
    summary%fe_solid_s = self%timer%seconds
  end subroutine add_to_summary

  !> The blocks' steps and critical and inverted elements of the last force call, then each block.
  subroutine exchange_state(self, store, path, error)
    class(solid_group_t), intent(inout) :: self
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(inout) :: error
    integer :: b
    call exchange_restart_count(store, path//"/count", "solid blocks", size(self%blocks), error)
    call exchange_restart(store, path//"/time_step", self%block_time_step, error)
    call exchange_restart(store, path//"/critical_element", self%block_critical_element, error)
    call exchange_restart(store, path//"/inverted_element", self%block_inverted_element, error)
    call exchange_restart(store, path//"/newly_eroded_count", self%newly_eroded, error)
    call exchange_restart(store, path//"/eroded_count", self%eroded_count, error)
    do b = 1, size(self%blocks)
      call exchange_solid_block(store, path//"/"//integer_text(b), self%blocks(b), error)
    end do
    call exchange_restart(store, path//"/seconds", self%timer%seconds, error)
  end subroutine exchange_state

  !> One block of solids: stresses, material history, energies and the powers of the last
  !> forces (for the work of the next step), volumes, bulk viscosity, hourglass forces, the
  !> last steps.
  subroutine exchange_solid_block(store, path, block, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(solid_block_t), intent(inout) :: block
    type(error_t), allocatable, intent(inout) :: error
    call exchange_restart_count(store, path//"/element_count", "elements in "//path, block%element_count, error)
    call exchange_restart(store, path//"/internal_energy", block%internal_energy, error)
    call exchange_restart(store, path//"/hourglass_energy", block%hourglass_energy, error)
    call exchange_restart(store, path//"/volume", block%volume, error)
    call exchange_restart(store, path//"/bulk_viscosity", block%bulk_viscosity, error)
    call exchange_restart(store, path//"/force_power", block%force_power, error)
    call exchange_restart(store, path//"/hourglass_power", block%hourglass_power, error)
    call exchange_restart(store, path//"/previous_time_step", block%previous_time_step, error)
    call exchange_restart(store, path//"/recent_time_step", block%recent_time_step, error)
    call exchange_restart(store, path//"/recent_critical_element", block%recent_critical_element, error)
    call exchange_restart(store, path//"/stress", block%stress, error)
    call exchange_restart(store, path//"/history", block%history, error)
    call exchange_restart(store, path//"/point_volume", block%point_volume, error)
    call exchange_restart(store, path//"/hourglass_force", block%hourglass_force, error)
    call exchange_restart(store, path//"/eroded", block%eroded, error)
    call exchange_restart(store, path//"/newly_eroded", block%newly_eroded, error)
  end subroutine exchange_solid_block

  !> d3hsp's table: each solid's stable step at the current configuration at rest (no bulk
  !> viscosity; the routine of mass scaling, the force call's solid step without its rates), in
  !> block and lane order; eroded elements are left out.
  subroutine list_time_steps(self, model, nodes, kind, element_ids, part_ids, steps)
    class(solid_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(in) :: nodes
    character(len=:), allocatable, intent(out) :: kind
    integer, allocatable, intent(out) :: element_ids(:), part_ids(:)
    real(wp), allocatable, intent(out) :: steps(:)
    real(wp) :: lane_step(block_size)
    integer :: b, lane, count
    kind = "solid"
    count = 0
    do b = 1, size(self%blocks)
      count = count + self%blocks(b)%element_count
    end do
    allocate (element_ids(count), part_ids(count), steps(count))
    count = 0
    do b = 1, size(self%blocks)
      associate (block => self%blocks(b))
        call solid_block_time_steps(block, model%materials(block%material), nodes%coordinates, lane_step)
        do lane = 1, block%element_count
          if (block%eroded(lane)) cycle
          count = count + 1
          element_ids(count) = model%solid_ids(block%elements(lane))
          part_ids(count) = model%parts(model%solid_part(block%elements(lane)))%id
          steps(count) = lane_step(lane)
        end do
      end associate
    end do
    element_ids = element_ids(1:count)
    part_ids = part_ids(1:count)
    steps = steps(1:count)
  end subroutine list_time_steps

  !> Its blocks are shared out among the ranks of a distributed run (docs/parallel.md).
  logical function distributes_blocks(self)
    class(solid_group_t), intent(in) :: self
    distributes_blocks = .true.
  end function distributes_blocks

  !> One block's state and its entries of the per-block step arrays (a store in memory: the
  !> ranks of a distributed run bring their blocks together).
  subroutine exchange_block_state(self, store, block, error)
    class(solid_group_t), intent(inout) :: self
    type(restart_store_t), intent(inout) :: store
    integer, intent(in) :: block
    type(error_t), allocatable, intent(inout) :: error
    call exchange_restart(store, "time_step", self%block_time_step(block), error)
    call exchange_restart(store, "critical_element", self%block_critical_element(block), error)
    call exchange_restart(store, "inverted_element", self%block_inverted_element(block), error)
    call exchange_solid_block(store, "block", self%blocks(block), error)
  end subroutine exchange_block_state

  integer function block_count(self)
    class(solid_group_t), intent(in) :: self
    block_count = size(self%blocks)
  end function block_count

  !> The corner nodes of the block's elements (a degenerate element's repeated node once).
  subroutine block_nodes(self, block, nodes)
    class(solid_group_t), intent(in) :: self
    integer, intent(in) :: block
    integer, allocatable, intent(out) :: nodes(:)
    associate (lanes => self%blocks(block)%element_count)
      nodes = distinct_nodes(reshape(self%blocks(block)%nodes(1:lanes, 1:8), [lanes*8]))
    end associate
  end subroutine block_nodes

  subroutine block_elements(self, block, elements)
    class(solid_group_t), intent(in) :: self
    integer, intent(in) :: block
    integer, allocatable, intent(out) :: elements(:)
    elements = self%blocks(block)%elements(1:self%blocks(block)%element_count)
  end subroutine block_elements
end module solid_group
