!> The beams (Hughes-Liu, spot weld beams) as an element group (element_group): the blocks of
!> beam_block, their colouring, nodal masses and rotary inertias, and the per-block results of
!> the last force call. Failed welds are masked in their blocks (beam_block_t%failed: no stress,
!> no force from the cycle they fail in) and are the group's eroded elements (element_group's
!> erosion contract: a message line each, glstat's count, their energy as eroded internal
!> energy); `failed_beams` counts them (run summary, /timing).
module beam_group
  use kinds, only: wp, block_size
  use gather_list, only: gather_list_t
  use block_colouring, only: colour_blocks_by_nodes
  use model, only: model_t
  use error_handling, only: error_t
  use text_format, only: integer_text
  use restart_file, only: restart_store_t, exchange_restart, exchange_restart_count
  use run_summary, only: run_summary_t
  use nodal_state, only: nodal_state_t
  use element_group, only: element_group_t, element_results_t, distinct_nodes, family_beam, block_energy_values
  use element_work, only: append_marked_lanes, booked_energy, lane_energy_sums, add_kinetic_energy, &
                          scale_block_density, raise_largest_scaling
  use beam_block, only: beam_block_t, build_beam_blocks, beam_block_masses, beam_block_time_steps, &
                        compute_beam_block
  implicit none
  private

  public :: beam_group_t, new_beam_group, failed_beams

  type, extends(element_group_t) :: beam_group_t
    type(beam_block_t), allocatable :: blocks(:)
    real(wp), allocatable :: nodal_mass(:, :)          !< (block_size, blocks), at each of the two nodes
    real(wp), allocatable :: nodal_inertia(:, :)
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
    procedure :: newly_eroded_elements
    procedure :: list_time_steps
  end type beam_group_t

contains

  !> A new group of this kind (its constructor for element_groups).
  subroutine new_beam_group(model, group)
    type(model_t), intent(in) :: model
    class(element_group_t), allocatable, intent(out) :: group
    integer :: count
    allocate (beam_group_t :: group)
    select type (group)
    type is (beam_group_t)
      group%name = "beam"
      group%element_family = family_beam
      call build_beam_blocks(model, group%blocks)
      count = size(group%blocks)
      allocate (group%nodal_mass(block_size, count), group%nodal_inertia(block_size, count), &
                group%block_time_step(count), group%block_critical_element(count), &
                group%block_degenerate_element(count))
      group%nodal_mass = 0.0_wp
      group%nodal_inertia = 0.0_wp
      allocate (group%block_energy(block_energy_values, count), source=0.0_wp)
      group%block_time_step = huge(1.0_wp)
      group%block_critical_element = 0
      group%block_degenerate_element = 0
    end select
  end subroutine new_beam_group

  integer function element_count(self)
    class(beam_group_t), intent(in) :: self
    integer :: b
    element_count = 0
    do b = 1, size(self%blocks)
      element_count = element_count + self%blocks(b)%element_count
    end do
  end function element_count

  !> The number of failed beams of `group` (0 for a group of another kind).
  integer function failed_beams(group)
    class(element_group_t), intent(in) :: group
    integer :: b
    failed_beams = 0
    select type (group)
    type is (beam_group_t)
      do b = 1, size(group%blocks)
        failed_beams = failed_beams + count(group%blocks(b)%failed(1:group%blocks(b)%element_count))
      end do
    end select
  end function failed_beams

  subroutine scale_masses(self, model, nodes, target_step, physical_mass, added_mass)
    class(beam_group_t), intent(inout) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(in) :: nodes
    real(wp), intent(in) :: target_step
    real(wp), intent(inout) :: physical_mass, added_mass
    real(wp) :: element_time_step(block_size), volume(block_size)
    integer :: b, nel
    element_time_step = huge(1.0_wp)
    do b = 1, size(self%blocks)
      associate (beam => self%blocks(b))
        nel = beam%element_count
        volume = 0.0_wp
        volume(1:nel) = beam%area*beam%reference_length(1:nel)
        if (target_step > 0.0_wp) &
          call beam_block_time_steps(beam, model%materials(beam%material), nodes%coordinates, element_time_step)
        call scale_block_density(nel, volume, target_step, element_time_step, beam%density, physical_mass, &
                                 added_mass)
      end associate
    end do
  end subroutine scale_masses

  !> Colour the blocks, then add the nodal masses and rotary inertias (serially, in block, node
  !> and lane order).
  subroutine lump_masses(self, model, nodes)
    class(beam_group_t), intent(inout) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(inout) :: nodes
    integer, allocatable :: block_nodes(:, :, :), counts(:)
    integer :: b, end, lane, node
    allocate (block_nodes(block_size, 2, size(self%blocks)), counts(size(self%blocks)))
    do b = 1, size(self%blocks)
      block_nodes(:, :, b) = self%blocks(b)%nodes
      counts(b) = self%blocks(b)%element_count
    end do
    call colour_blocks_by_nodes(nodes%count, block_nodes, counts, self%colours)
    do b = 1, size(self%blocks)
      call beam_block_masses(self%blocks(b), self%nodal_mass(:, b), self%nodal_inertia(:, b))
      do end = 1, 2
        do lane = 1, self%blocks(b)%element_count
          node = self%blocks(b)%nodes(lane, end)
          nodes%mass(node) = nodes%mass(node) + self%nodal_mass(lane, b)
          nodes%rotary_inertia(node) = nodes%rotary_inertia(node) + self%nodal_inertia(lane, b)
        end do
      end do
    end do
  end subroutine lump_masses

  !> Forces and moments, colour by colour as the shells (shell_group).
  subroutine add_internal_forces(self, model, nodes, step)
    class(beam_group_t), intent(inout) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(inout) :: nodes
    real(wp), intent(in) :: step
    real(wp) :: beam_force(block_size, 2, 6)
    integer :: colour, k, b
    do colour = 1, size(self%colours%offsets) - 1
      !$omp parallel do schedule(dynamic, 2) default(shared) private(k, b, beam_force)
      do k = self%colours%offsets(colour), self%colours%offsets(colour + 1) - 1
        b = self%colours%corners(k)
        if (.not. self%computes(b)) cycle
        call compute_beam_block(self%blocks(b), model%materials(self%blocks(b)%material), nodes%coordinates, &
                                nodes%velocity, nodes%angular_velocity, step, beam_force, self%block_time_step(b), &
                                self%block_critical_element(b), self%block_degenerate_element(b))
        call add_beam_forces(self%blocks(b), beam_force, nodes%internal_force, nodes%internal_moment)
      end do
      !$omp end parallel do
    end do
    call self%header_from_blocks(self%block_time_step, self%block_critical_element, self%block_degenerate_element)
    ! a failed weld is an eroded element of the group (element_group's erosion contract)
    self%newly_eroded = 0
    do b = 1, size(self%blocks)
      if (.not. self%owns(b)) cycle
      self%newly_eroded = self%newly_eroded + count(self%blocks(b)%newly_failed(1:self%blocks(b)%element_count))
    end do
    self%eroded_count = self%eroded_count + self%newly_eroded
  end subroutine add_internal_forces

  !> Its beams failed in the last force call, block by block.
  function newly_eroded_elements(self) result(elements)
    class(beam_group_t), intent(in) :: self
    integer, allocatable :: elements(:)
    integer :: b, n
    allocate (elements(self%newly_eroded))
    n = 0
    do b = 1, size(self%blocks)
      call append_marked_lanes(self%blocks(b)%element_count, self%blocks(b)%newly_failed, self%blocks(b)%elements, &
                               elements, n)
    end do
  end function newly_eroded_elements

  subroutine add_beam_forces(block, beam_force, internal_force, internal_moment)
    type(beam_block_t), intent(in) :: block
    real(wp), intent(in) :: beam_force(block_size, 2, 6)
    real(wp), intent(inout) :: internal_force(:, :), internal_moment(:, :)
    integer :: end, lane, node
    do end = 1, 2
      do lane = 1, block%element_count
        node = block%nodes(lane, end)
        internal_force(:, node) = internal_force(:, node) + beam_force(lane, end, 1:3)
        internal_moment(:, node) = internal_moment(:, node) + beam_force(lane, end, 4:6)
      end do
    end do
  end subroutine add_beam_forces

  !> Per block: the live beams' internal energy and its power, the failed beams' internal
  !> energy (reported apart, as eroded energy); beams have no hourglass energy.
  subroutine sum_block_energies(self)
    class(beam_group_t), intent(inout) :: self
    real(wp) :: internal(3)
    integer :: b
    do b = 1, size(self%blocks)
      if (.not. self%computes(b)) cycle
      associate (beam => self%blocks(b))
        internal = lane_energy_sums(beam%internal_energy, beam%force_power, beam%element_count, beam%failed)
        self%block_energy(:, b) = [internal(1:2), 0.0_wp, 0.0_wp, internal(3), 0.0_wp]
      end associate
    end do
  end subroutine sum_block_energies

  subroutine add_part_energies(self, nodes, average_step, step_correction, kinetic, internal, hourglass)
    class(beam_group_t), intent(in) :: self
    type(nodal_state_t), intent(in) :: nodes
    real(wp), intent(in) :: average_step, step_correction
    real(wp), intent(inout) :: kinetic(:), internal(:), hourglass(:)
    integer :: b, end, lane, node
    do b = 1, size(self%blocks)
      associate (beam => self%blocks(b))
        internal(beam%part) = internal(beam%part) + booked_energy(self%block_energy(1, b), self%block_energy(2, b), &
                                                                  step_correction)
        do end = 1, 2
          do lane = 1, beam%element_count
            node = beam%nodes(lane, end)
            call add_kinetic_energy(self%nodal_mass(lane, b), nodes%velocity(:, node), &
                                    nodes%acceleration(:, node), average_step, kinetic(beam%part), internal(beam%part))
            call add_kinetic_energy(self%nodal_inertia(lane, b), nodes%angular_velocity(:, node), &
                                    nodes%angular_acceleration(:, node), average_step, kinetic(beam%part), &
                                    internal(beam%part))
          end do
        end do
      end associate
    end do
  end subroutine add_part_energies

  subroutine add_part_momenta(self, nodes, half_step, momentum, mass)
    class(beam_group_t), intent(in) :: self
    type(nodal_state_t), intent(in) :: nodes
    real(wp), intent(in) :: half_step
    real(wp), intent(inout) :: momentum(:, :), mass(:)
    integer :: b, end, lane, node
    do b = 1, size(self%blocks)
      associate (beam => self%blocks(b))
        do end = 1, 2
          do lane = 1, beam%element_count
            node = beam%nodes(lane, end)
            momentum(:, beam%part) = momentum(:, beam%part) + self%nodal_mass(lane, b)* &
                                     (nodes%velocity(:, node) + half_step*nodes%acceleration(:, node))
            mass(beam%part) = mass(beam%part) + self%nodal_mass(lane, b)
          end do
        end do
      end associate
    end do
  end subroutine add_part_momenta

  !> Per beam: the resultants N, Q_s, Q_t, T, M_s, M_t in its local axes, the largest plastic
  !> strain of its section points, and 1 for a failed beam (0 otherwise).
  subroutine element_results(self, model, results)
    class(beam_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    type(element_results_t), intent(inout) :: results
    integer :: b, lane, beam
    if (.not. allocated(results%beam_resultant)) return
    do b = 1, size(self%blocks)
      associate (block => self%blocks(b))
        do lane = 1, block%element_count
          beam = block%elements(lane)
          results%beam_resultant(:, beam) = block%resultant(lane, :)
          results%beam_plastic_strain(beam) = 0.0_wp
          if (block%point_count > 0) results%beam_plastic_strain(beam) = maxval(block%plastic_strain(lane, :))
          results%beam_failed(beam) = merge(1.0_wp, 0.0_wp, block%failed(lane))
        end do
      end associate
    end do
  end subroutine element_results

  function describe(self, model, element) result(text)
    class(beam_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    integer, intent(in) :: element
    character(len=:), allocatable :: text
    text = "beam element "//integer_text(model%beam_ids(element))//" (part "// &
           integer_text(model%parts(model%beam_part(element))%id)//")"
  end function describe

  function failure_text(self, model) result(text)
    class(beam_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    character(len=:), allocatable :: text
    text = self%describe(model, self%failed_element)//" has lost its length (its two nodes met)"
  end function failure_text

  subroutine most_scaled(self, model, largest, element)
    class(beam_group_t), intent(in) :: self
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

  !> Its element count and the seconds of its force calls.
  subroutine add_to_summary(self, summary)
    class(beam_group_t), intent(in) :: self
    type(run_summary_t), intent(inout) :: summary
    summary%fe_beams = self%element_count()
    summary%fe_beam_s = self%timer%seconds
    summary%failed_beams = failed_beams(self)
  end subroutine add_to_summary

  !> The blocks' steps and critical and degenerate elements of the last force call, then each block.
  subroutine exchange_state(self, store, path, error)
    class(beam_group_t), intent(inout) :: self
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(inout) :: error
    integer :: b
    call exchange_restart_count(store, path//"/count", "beam blocks", size(self%blocks), error)
    call exchange_restart(store, path//"/time_step", self%block_time_step, error)
    call exchange_restart(store, path//"/critical_element", self%block_critical_element, error)
    call exchange_restart(store, path//"/degenerate_element", self%block_degenerate_element, error)
    call exchange_restart(store, path//"/newly_eroded_count", self%newly_eroded, error)
    call exchange_restart(store, path//"/eroded_count", self%eroded_count, error)
    do b = 1, size(self%blocks)
      call exchange_beam_block(store, path//"/"//integer_text(b), self%blocks(b), error)
    end do
    call exchange_restart(store, path//"/seconds", self%timer%seconds, error)
  end subroutine exchange_state

  !> One block of beams: what it carries from cycle to cycle (the density and section come from
  !> the deck and its mass scaling again).
  subroutine exchange_beam_block(store, path, block, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(beam_block_t), intent(inout) :: block
    type(error_t), allocatable, intent(inout) :: error
    call exchange_restart_count(store, path//"/element_count", "elements in "//path, block%element_count, error)
    call exchange_restart(store, path//"/frame", block%frame, error)
    call exchange_restart(store, path//"/internal_energy", block%internal_energy, error)
    call exchange_restart(store, path//"/force_power", block%force_power, error)
    call exchange_restart(store, path//"/previous_time_step", block%previous_time_step, error)
    call exchange_restart(store, path//"/previous_force", block%previous_force, error)
    call exchange_restart(store, path//"/resultant", block%resultant, error)
    call exchange_restart(store, path//"/failed", block%failed, error)
    call exchange_restart(store, path//"/newly_failed", block%newly_failed, error)
    call exchange_restart(store, path//"/time", block%time, error)
    call exchange_restart(store, path//"/stress", block%stress, error)
    call exchange_restart(store, path//"/plastic_strain", block%plastic_strain, error)
  end subroutine exchange_beam_block

  !> d3hsp's table: each beam's stable step at the current configuration (the routine of mass
  !> scaling and of the force call), in block and lane order; failed welds keep theirs, as
  !> they keep setting the step (beam_block).
  subroutine list_time_steps(self, model, nodes, kind, element_ids, part_ids, steps)
    class(beam_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(in) :: nodes
    character(len=:), allocatable, intent(out) :: kind
    integer, allocatable, intent(out) :: element_ids(:), part_ids(:)
    real(wp), allocatable, intent(out) :: steps(:)
    real(wp) :: lane_step(block_size)
    integer :: b, lane, count
    kind = "beam"
    count = 0
    do b = 1, size(self%blocks)
      count = count + self%blocks(b)%element_count
    end do
    allocate (element_ids(count), part_ids(count), steps(count))
    count = 0
    do b = 1, size(self%blocks)
      associate (block => self%blocks(b))
        call beam_block_time_steps(block, model%materials(block%material), nodes%coordinates, lane_step)
        do lane = 1, block%element_count
          count = count + 1
          element_ids(count) = model%beam_ids(block%elements(lane))
          part_ids(count) = model%parts(model%beam_part(block%elements(lane)))%id
          steps(count) = lane_step(lane)
        end do
      end associate
    end do
  end subroutine list_time_steps

  !> Its blocks are shared out among the ranks of a distributed run (docs/parallel.md).
  logical function distributes_blocks(self)
    class(beam_group_t), intent(in) :: self
    distributes_blocks = .true.
  end function distributes_blocks

  logical function adds_moments(self)
    class(beam_group_t), intent(in) :: self
    adds_moments = .true.
  end function adds_moments

  !> One block's state and its entries of the per-block step arrays (a store in memory: the
  !> ranks of a distributed run bring their blocks together).
  subroutine exchange_block_state(self, store, block, error)
    class(beam_group_t), intent(inout) :: self
    type(restart_store_t), intent(inout) :: store
    integer, intent(in) :: block
    type(error_t), allocatable, intent(inout) :: error
    call exchange_restart(store, "time_step", self%block_time_step(block), error)
    call exchange_restart(store, "critical_element", self%block_critical_element(block), error)
    call exchange_restart(store, "degenerate_element", self%block_degenerate_element(block), error)
    call exchange_beam_block(store, "block", self%blocks(block), error)
  end subroutine exchange_block_state

  integer function block_count(self)
    class(beam_group_t), intent(in) :: self
    block_count = size(self%blocks)
  end function block_count

  !> Both end nodes of the block's beams (the orientation node N3 serves the set-up only).
  subroutine block_nodes(self, block, nodes)
    class(beam_group_t), intent(in) :: self
    integer, intent(in) :: block
    integer, allocatable, intent(out) :: nodes(:)
    associate (lanes => self%blocks(block)%element_count)
      nodes = distinct_nodes(reshape(self%blocks(block)%nodes(1:lanes, 1:2), [lanes*2]))
    end associate
  end subroutine block_nodes

  subroutine block_elements(self, block, elements)
    class(beam_group_t), intent(in) :: self
    integer, intent(in) :: block
    integer, allocatable, intent(out) :: elements(:)
    elements = self%blocks(block)%elements(1:self%blocks(block)%element_count)
  end subroutine block_elements
end module beam_group
