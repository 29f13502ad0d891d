!> The Belytschko-Tsay shells as an element group (element_group): the blocks of shell_block,
!> their colouring, corner masses and rotary inertias, and the per-block results of the last
!> force call. Besides forces the shells add moments and, for the drilling-rate removal of the
!> time loop, each node's sums of area x normal and area.
module shell_group
  use kinds, only: wp, block_size
  use gather_list, only: gather_list_t
  use block_colouring, only: colour_blocks_by_nodes
  use model, only: model_t
  use plane_stress_dispatch, only: plane_stress_plastic_strain
  use error_handling, only: error_t
  use text_format, only: integer_text
  use restart_file, only: restart_store_t, exchange_restart, exchange_restart_count
  use run_summary, only: run_summary_t
  use nodal_state, only: nodal_state_t
  use element_group, only: element_group_t, element_results_t, distinct_nodes, family_shell, block_energy_values
  use element_work, only: append_marked_lanes, mark_lanes, booked_energy, block_energy_column, add_kinetic_energy, &
                          scale_block_density, raise_largest_scaling
  use shell_block, only: shell_block_t, build_shell_blocks, shell_block_masses, shell_block_time_steps, &
                         compute_shell_block, shell_block_element_results
  implicit none
  private

  public :: shell_group_t, new_shell_group

  type, extends(element_group_t) :: shell_group_t
    type(shell_block_t), allocatable :: blocks(:)
    real(wp), allocatable :: corner_mass(:, :, :)        !< (block_size, 4, blocks)
    real(wp), allocatable :: corner_inertia(:, :, :)
    real(wp), allocatable :: block_time_step(:)
    integer, allocatable :: block_critical_element(:)
    integer, allocatable :: block_degenerate_element(:)
    type(gather_list_t) :: colours
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
    procedure :: distributes_blocks, adds_moments
    procedure :: exchange_block_state
    procedure :: failure_text
    procedure :: most_scaled
    procedure :: thinnest
    procedure :: newly_eroded_elements
    procedure :: mark_eroded
    procedure :: list_time_steps
    procedure :: raise_nodal_plastic_strain
  end type shell_group_t

contains

  !> A new group of this kind (its constructor for element_groups).
  subroutine new_shell_group(model, group)
    type(model_t), intent(in) :: model
    class(element_group_t), allocatable, intent(out) :: group
    allocate (shell_group_t :: group)
    select type (group)
    type is (shell_group_t)
      call build_group(model, group)
    end select
  end subroutine new_shell_group

  subroutine build_group(model, group)
    type(model_t), intent(in) :: model
    type(shell_group_t), intent(inout) :: group
    integer :: count
    group%name = "shell"
    group%element_family = family_shell
    call build_shell_blocks(model, group%blocks)
    count = size(group%blocks)
    allocate (group%corner_mass(block_size, 4, count), group%corner_inertia(block_size, 4, count), &
              group%block_time_step(count), group%block_critical_element(count), &
              group%block_degenerate_element(count))
    group%corner_mass = 0.0_wp
    group%corner_inertia = 0.0_wp
    allocate (group%block_energy(block_energy_values, count), source=0.0_wp)
    group%block_time_step = huge(1.0_wp)
    group%block_critical_element = 0
    group%block_degenerate_element = 0
  end subroutine build_group

  integer function element_count(self)
    class(shell_group_t), intent(in) :: self
    integer :: b
    element_count = 0
    do b = 1, size(self%blocks)
      element_count = element_count + self%blocks(b)%element_count
    end do
  end function element_count

  subroutine scale_masses(self, model, nodes, target_step, physical_mass, added_mass)
    class(shell_group_t), intent(inout) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(in) :: nodes
    real(wp), intent(in) :: target_step
    real(wp), intent(inout) :: physical_mass, added_mass
    real(wp) :: element_time_step(block_size), volume(block_size)
    integer :: b, nel
    element_time_step = huge(1.0_wp)
    do b = 1, size(self%blocks)
      associate (shell => self%blocks(b))
        nel = shell%element_count
        volume(1:nel) = shell%thickness(1:nel)*shell%reference_area(1:nel)
        if (target_step > 0.0_wp) &
          call shell_block_time_steps(shell, model%materials(shell%material), nodes%coordinates, element_time_step)
        call scale_block_density(nel, volume, target_step, element_time_step, shell%density, physical_mass, &
                                 added_mass)
      end associate
    end do
  end subroutine scale_masses

  !> Colour the blocks, then add the corner masses and rotary inertias to the nodes (serially,
  !> in block, corner and lane order).
  subroutine lump_masses(self, model, nodes)
    class(shell_group_t), intent(inout) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(inout) :: nodes
    integer, allocatable :: block_nodes(:, :, :), counts(:)
    integer :: b, corner, lane, node
    allocate (block_nodes(block_size, 4, size(self%blocks)), counts(size(self%blocks)))
    do b = 1, size(self%blocks)
      block_nodes(:, :, b) = self%blocks(b)%nodes
      counts(b) = self%blocks(b)%element_count
    end do
    call colour_blocks_by_nodes(nodes%count, block_nodes, counts, self%colours)
    do b = 1, size(self%blocks)
      call shell_block_masses(self%blocks(b), self%corner_mass(:, :, b), self%corner_inertia(:, :, b))
      do corner = 1, 4
        do lane = 1, self%blocks(b)%element_count
          node = self%blocks(b)%nodes(lane, corner)
          nodes%mass(node) = nodes%mass(node) + self%corner_mass(lane, corner, b)
          nodes%rotary_inertia(node) = nodes%rotary_inertia(node) + self%corner_inertia(lane, corner, b)
        end do
      end do
    end do
  end subroutine lump_masses

  !> Forces and moments, colour by colour as the solids (solid_group).
  subroutine add_internal_forces(self, model, nodes, step)
    class(shell_group_t), intent(inout) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(inout) :: nodes
    real(wp), intent(in) :: step
    real(wp) :: shell_force(block_size, 4, 6)
    integer :: colour, k, b
    do b = 1, size(self%blocks)
      ! ERODE's step, or the material's TDEL (MAT_024), whichever is larger
      self%blocks(b)%erosion_time_step = max(merge(self%erosion_time_step, 0.0_wp, model%erode_shells_on_step), &
                                             model%materials(self%blocks(b)%material)%failure_time_step)
    end do
    do colour = 1, size(self%colours%offsets) - 1
      !$omp parallel do schedule(dynamic, 2) default(shared) private(k, b, shell_force)
      do k = self%colours%offsets(colour), self%colours%offsets(colour + 1) - 1
        b = self%colours%corners(k)
        if (.not. self%computes(b)) cycle
        call compute_shell_block(self%blocks(b), model%materials(self%blocks(b)%material), nodes%coordinates, &
                                 nodes%velocity, nodes%angular_velocity, step, shell_force, self%block_time_step(b), &
                                 self%block_critical_element(b), self%block_degenerate_element(b))
        call add_shell_forces(self%blocks(b), shell_force, nodes%internal_force, nodes%internal_moment, &
                              nodes%shell_normal_sum, nodes%shell_area_sum)
      end do
      !$omp end parallel do
    end do
    call self%header_from_blocks(self%block_time_step, self%block_critical_element, self%block_degenerate_element)
    self%newly_eroded = 0
    ! (distributed: the blocks this rank owns; the solver adds the ranks' counts)
    do b = 1, size(self%blocks)
      if (.not. self%owns(b)) cycle
      self%newly_eroded = self%newly_eroded + count(self%blocks(b)%newly_eroded)
    end do
    self%eroded_count = self%eroded_count + self%newly_eroded
  end subroutine add_internal_forces

  !> The largest effective plastic strain over the points of its shells, raised into the nodes
  !> `wanted` flags (the nodes of spot welds that fail by EP / EPSF).
  subroutine raise_nodal_plastic_strain(self, model, wanted, strain)
    class(shell_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    logical, intent(in) :: wanted(:)
    real(wp), intent(inout) :: strain(:)
    real(wp) :: point_strain(block_size), largest(block_size)
    integer :: b, point, lane, corner, node
    do b = 1, size(self%blocks)
      ! (a distributed run takes the largest over the ranks: each has its computed blocks current)
      if (.not. self%computes(b)) cycle
      associate (block => self%blocks(b))
        largest = 0.0_wp
        do point = 1, block%point_count
          call plane_stress_plastic_strain(model%materials(block%material), block%element_count, &
                                           block%history(:, :, point), point_strain)
          largest(1:block%element_count) = max(largest(1:block%element_count), point_strain(1:block%element_count))
        end do
        do lane = 1, block%element_count
          do corner = 1, 4
            node = block%nodes(lane, corner)
            if (wanted(node)) strain(node) = max(strain(node), largest(lane))
          end do
        end do
      end associate
    end do
  end subroutine raise_nodal_plastic_strain

  !> Its shells eroded by the last force call, block by block.
  function newly_eroded_elements(self) result(elements)
    class(shell_group_t), intent(in) :: self
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
    class(shell_group_t), intent(in) :: self
    logical, intent(inout) :: solid_eroded(:), shell_eroded(:)
    integer :: b
    do b = 1, size(self%blocks)
      call mark_lanes(self%blocks(b)%element_count, self%blocks(b)%eroded, self%blocks(b)%elements, shell_eroded)
    end do
  end subroutine mark_eroded

  !> internal_force and internal_moment of the block's nodes += the shells' nodal forces and
  !> moments, corner by corner, lane by lane; and each node's sums of area x normal and area of
  !> its shells (for the drilling projection of the time loop).
  subroutine add_shell_forces(block, shell_force, internal_force, internal_moment, normal_sum, area_sum)
    type(shell_block_t), intent(in) :: block
    real(wp), intent(in) :: shell_force(block_size, 4, 6)
    real(wp), intent(inout) :: internal_force(:, :), internal_moment(:, :), normal_sum(:, :), area_sum(:)
    integer :: corner, lane, node
    do corner = 1, 4
      do lane = 1, block%element_count
        if (.not. (corner == 4 .and. block%nodes(lane, 4) == block%nodes(lane, 3))) then
          node = block%nodes(lane, corner)
          normal_sum(:, node) = normal_sum(:, node) + block%area(lane)*block%frame(lane, 3, :)
          area_sum(node) = area_sum(node) + block%area(lane)
        end if
        node = block%nodes(lane, corner)
        internal_force(:, node) = internal_force(:, node) + shell_force(lane, corner, 1:3)
        internal_moment(:, node) = internal_moment(:, node) + shell_force(lane, corner, 4:6)
      end do
    end do
  end subroutine add_shell_forces

  !> Each computed block's energy sums (element_group's block_energy).
  subroutine sum_block_energies(self)
    class(shell_group_t), intent(inout) :: self
    integer :: b
    do b = 1, size(self%blocks)
      if (.not. self%computes(b)) cycle
      associate (shell => self%blocks(b))
        self%block_energy(:, b) = block_energy_column(shell%internal_energy, shell%force_power, shell%hourglass_energy, &
                                                      shell%hourglass_power, shell%element_count, shell%eroded)
      end associate
    end do
  end subroutine sum_block_energies

  subroutine add_part_energies(self, nodes, average_step, step_correction, kinetic, internal, hourglass)
    class(shell_group_t), intent(in) :: self
    type(nodal_state_t), intent(in) :: nodes
    real(wp), intent(in) :: average_step, step_correction
    real(wp), intent(inout) :: kinetic(:), internal(:), hourglass(:)
    integer :: b, corner, lane, node
    do b = 1, size(self%blocks)
      associate (shell => self%blocks(b))
        internal(shell%part) = internal(shell%part) + booked_energy(self%block_energy(1, b), self%block_energy(2, b), &
                                                                    step_correction)
        hourglass(shell%part) = hourglass(shell%part) + booked_energy(self%block_energy(3, b), self%block_energy(4, b), &
                                                                      step_correction)
        do corner = 1, 4
          do lane = 1, shell%element_count
            node = shell%nodes(lane, corner)
            call add_kinetic_energy(self%corner_mass(lane, corner, b), nodes%velocity(:, node), &
                                    nodes%acceleration(:, node), average_step, kinetic(shell%part), internal(shell%part))
            call add_kinetic_energy(self%corner_inertia(lane, corner, b), nodes%angular_velocity(:, node), &
                                    nodes%angular_acceleration(:, node), average_step, kinetic(shell%part), &
                                    internal(shell%part))
          end do
        end do
      end associate
    end do
  end subroutine add_part_energies

  subroutine add_part_momenta(self, nodes, half_step, momentum, mass)
    class(shell_group_t), intent(in) :: self
    type(nodal_state_t), intent(in) :: nodes
    real(wp), intent(in) :: half_step
    real(wp), intent(inout) :: momentum(:, :), mass(:)
    integer :: b, corner, lane, node
    do b = 1, size(self%blocks)
      associate (shell => self%blocks(b))
        do corner = 1, 4
          do lane = 1, shell%element_count
            node = shell%nodes(lane, corner)
            momentum(:, shell%part) = momentum(:, shell%part) + self%corner_mass(lane, corner, b)* &
                                      (nodes%velocity(:, node) + half_step*nodes%acceleration(:, node))
            mass(shell%part) = mass(shell%part) + self%corner_mass(lane, corner, b)
          end do
        end do
      end associate
    end do
  end subroutine add_part_momenta

  subroutine element_results(self, model, results)
    class(shell_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    type(element_results_t), intent(inout) :: results
    integer :: b, lane
    do b = 1, size(self%blocks)
      if (allocated(results%shell_point_stress)) then
        call shell_block_element_results(self%blocks(b), model%materials(self%blocks(b)%material), &
                                         results%shell_stress, results%shell_stress_peak, &
                                         results%shell_plastic_strain, results%shell_plastic_strain_peak, &
                                         results%shell_point_stress, results%shell_point_plastic_strain, &
                                         results%shell_point_count, results%shell_resultant, &
                                         results%shell_thickness, results%shell_energy_density)
      else
        call shell_block_element_results(self%blocks(b), model%materials(self%blocks(b)%material), &
                                         results%shell_stress, results%shell_stress_peak, &
                                         results%shell_plastic_strain, results%shell_plastic_strain_peak)
      end if
      if (.not. allocated(results%shell_eroded)) cycle
      do lane = 1, self%blocks(b)%element_count
        results%shell_eroded(self%blocks(b)%elements(lane)) = merge(1, 0, self%blocks(b)%eroded(lane))
      end do
    end do
  end subroutine element_results

  function describe(self, model, element) result(text)
    class(shell_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    integer, intent(in) :: element
    character(len=:), allocatable :: text
    character(len=32) :: id, part
    write (id, '(i0)') model%shell_ids(element)
    write (part, '(i0)') model%parts(model%shell_part(element))%id
    text = "shell element "//trim(id)//" (part "//trim(part)//")"
  end function describe

  function failure_text(self, model) result(text)
    class(shell_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    character(len=:), allocatable :: text
    text = self%describe(model, self%failed_element)//" has lost its area"
  end function failure_text

  subroutine most_scaled(self, model, largest, element)
    class(shell_group_t), intent(in) :: self
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

  real(wp) function thinnest(self)
    class(shell_group_t), intent(in) :: self
    integer :: b
    thinnest = huge(1.0_wp)
    do b = 1, size(self%blocks)
      thinnest = min(thinnest, minval(self%blocks(b)%thickness(1:self%blocks(b)%element_count)))
    end do
  end function thinnest

  !> Its element count and the seconds of its force calls (set, not added: called before and
  !> after the run).
  subroutine add_to_summary(self, summary)
    class(shell_group_t), intent(in) :: self
    type(run_summary_t), intent(inout) :: summary
    summary%fe_shells = self%element_count()
    summary%fe_shell_s = self%timer%seconds
  end subroutine add_to_summary

  !> The blocks' steps and critical and degenerate elements of the last force call, then each block.
  subroutine exchange_state(self, store, path, error)
    class(shell_group_t), intent(inout) :: self
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(inout) :: error
    integer :: b
    call exchange_restart_count(store, path//"/count", "shell blocks", size(self%blocks), error)
    call exchange_restart(store, path//"/time_step", self%block_time_step, error)
    call exchange_restart(store, path//"/critical_element", self%block_critical_element, error)
    call exchange_restart(store, path//"/degenerate_element", self%block_degenerate_element, error)
    call exchange_restart(store, path//"/newly_eroded_count", self%newly_eroded, error)
    call exchange_restart(store, path//"/eroded_count", self%eroded_count, error)
    do b = 1, size(self%blocks)
      call exchange_shell_block(store, path//"/"//integer_text(b), self%blocks(b), error)
    end do
    call exchange_restart(store, path//"/seconds", self%timer%seconds, error)
  end subroutine exchange_state

  !> One block of shells: the solid block's quantities, plus the corotational frame and the
  !> nodal forces and moments of the last call (their work over the next step).
  subroutine exchange_shell_block(store, path, block, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(shell_block_t), intent(inout) :: block
    type(error_t), allocatable, intent(inout) :: error
    call exchange_restart_count(store, path//"/element_count", "elements in "//path, block%element_count, error)
    call exchange_restart(store, path//"/area", block%area, error)
    call exchange_restart(store, path//"/internal_energy", block%internal_energy, error)
    call exchange_restart(store, path//"/hourglass_energy", block%hourglass_energy, error)
    call exchange_restart(store, path//"/force_power", block%force_power, error)
    call exchange_restart(store, path//"/hourglass_power", block%hourglass_power, error)
    call exchange_restart(store, path//"/previous_time_step", block%previous_time_step, error)
    call exchange_restart(store, path//"/hourglass_force", block%hourglass_force, error)
    call exchange_restart(store, path//"/previous_force", block%previous_force, error)
    call exchange_restart(store, path//"/previous_hourglass_force", block%previous_hourglass_force, error)
    call exchange_restart(store, path//"/frame", block%frame, error)
    call exchange_restart(store, path//"/stress", block%stress, error)
    call exchange_restart(store, path//"/history", block%history, error)
    call exchange_restart(store, path//"/eroded", block%eroded, error)
    call exchange_restart(store, path//"/newly_eroded", block%newly_eroded, error)
    call exchange_restart(store, path//"/point_failed", block%point_failed, error)
  end subroutine exchange_shell_block

  !> d3hsp's table: each shell's stable step at the current configuration (the routine of mass
  !> scaling and of the force call), in block and lane order; eroded elements are left out.
  subroutine list_time_steps(self, model, nodes, kind, element_ids, part_ids, steps)
    class(shell_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(in) :: nodes
    character(len=:), allocatable, intent(out) :: kind
    integer, allocatable, intent(out) :: element_ids(:), part_ids(:)
    real(wp), allocatable, intent(out) :: steps(:)
    real(wp) :: lane_step(block_size)
    integer :: b, lane, count
    kind = "shell"
    count = 0
    do b = 1, size(self%blocks)
      count = count + self%blocks(b)%element_count
    end do
    allocate (element_ids(count), part_ids(count), steps(count))
    count = 0
    do b = 1, size(self%blocks)
      associate (block => self%blocks(b))
        call shell_block_time_steps(block, model%materials(block%material), nodes%coordinates, lane_step)
        do lane = 1, block%element_count
          if (block%eroded(lane)) cycle
          count = count + 1
          element_ids(count) = model%shell_ids(block%elements(lane))
          part_ids(count) = model%parts(model%shell_part(block%elements(lane)))%id
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
    class(shell_group_t), intent(in) :: self
    distributes_blocks = .true.
  end function distributes_blocks

  logical function adds_moments(self)
    class(shell_group_t), intent(in) :: self
    adds_moments = .true.
  end function adds_moments

  !> One block's state and its entries of the per-block step arrays (a store in memory: the
  !> ranks of a distributed run bring their blocks together).
  subroutine exchange_block_state(self, store, block, error)
    class(shell_group_t), intent(inout) :: self
    type(restart_store_t), intent(inout) :: store
    integer, intent(in) :: block
    type(error_t), allocatable, intent(inout) :: error
    call exchange_restart(store, "time_step", self%block_time_step(block), error)
    call exchange_restart(store, "critical_element", self%block_critical_element(block), error)
    call exchange_restart(store, "degenerate_element", self%block_degenerate_element(block), error)
    call exchange_shell_block(store, "block", self%blocks(block), error)
  end subroutine exchange_block_state

  integer function block_count(self)
    class(shell_group_t), intent(in) :: self
    block_count = size(self%blocks)
  end function block_count

  !> The corner nodes of the block's elements (a degenerate element's repeated node once).
  subroutine block_nodes(self, block, nodes)
    class(shell_group_t), intent(in) :: self
    integer, intent(in) :: block
    integer, allocatable, intent(out) :: nodes(:)
    associate (lanes => self%blocks(block)%element_count)
      nodes = distinct_nodes(reshape(self%blocks(block)%nodes(1:lanes, 1:4), [lanes*4]))
    end associate
  end subroutine block_nodes

  subroutine block_elements(self, block, elements)
    class(shell_group_t), intent(in) :: self
    integer, intent(in) :: block
    integer, allocatable, intent(out) :: elements(:)
    elements = self%blocks(block)%elements(1:self%blocks(block)%element_count)
  end subroutine block_elements
end module shell_group
