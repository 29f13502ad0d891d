!> The one place that knows which element kinds exist and visits them: it builds the groups
!> (the registration point of a new kind), sets up their masses, computes the internal forces
!> of all of them and gathers what the engine needs from their headers.
!>
!> Order is part of the results: groups are visited solids, shells, meshfree parts, meshfree
!> shells, beams, always, so a node shared by several kinds receives their forces in the same
!> order on every run, and the smallest stable step goes to the first group on a tie.
module element_groups
  use kinds, only: wp
  use error_handling, only: error_t
  use model, only: model_t
  use nodal_state, only: nodal_state_t
  use element_group, only: element_group_t, group_holder_t, element_results_t
  use solid_group, only: new_solid_group
  use shell_group, only: new_shell_group
  use efg_group, only: new_efg_group
  use efg_shell_group, only: new_efg_shell_group
  use beam_group, only: new_beam_group
  use wall_clock, only: start_phase, stop_phase
  implicit none
  private

  public :: build_element_groups, set_up_group_masses, compute_internal_forces, smallest_group_step
  public :: collect_element_results, group_failure, eroded_element_masks

contains

  !> The element groups of the model, kinds in engine order; kinds with no element are left out.
  !> A new element kind is registered here (one `add` line) and nowhere else in the engine.
  subroutine build_element_groups(model, groups, error)
    type(model_t), intent(in) :: model
    type(group_holder_t), allocatable, intent(out) :: groups(:)
    type(error_t), allocatable, intent(out) :: error
    class(element_group_t), allocatable :: group

    allocate (groups(0))
    call new_solid_group(model, group)
    call add(group)
    call new_shell_group(model, group)
    call add(group)
    call new_efg_group(model, group, error)
    if (allocated(error)) return
    call add(group)
    call new_efg_shell_group(model, group, error)
    if (allocated(error)) return
    call add(group)
    call new_beam_group(model, group)
    call add(group)
  contains
    subroutine add(group)
      class(element_group_t), allocatable, intent(inout) :: group
      type(group_holder_t), allocatable :: grown(:)
      integer :: k
      if (group%element_count() == 0) return
      allocate (grown(size(groups) + 1))
      do k = 1, size(groups)
        call move_alloc(groups(k)%group, grown(k)%group)
      end do
      call move_alloc(group, grown(size(grown))%group)
      call move_alloc(grown, groups)
    end subroutine add
  end subroutine build_element_groups

  !> Mass scaling of every group (DT2MS), then each colours its blocks and lumps its masses.
  subroutine set_up_group_masses(model, groups, nodes, target_step, physical_mass, added_mass)
    type(model_t), intent(in) :: model
    type(group_holder_t), intent(inout) :: groups(:)
    type(nodal_state_t), intent(inout) :: nodes
    real(wp), intent(in) :: target_step
    real(wp), intent(inout) :: physical_mass, added_mass
    integer :: k
    do k = 1, size(groups)
      call groups(k)%group%scale_masses(model, nodes, target_step, physical_mass, added_mass)
    end do
    do k = 1, size(groups)
      call groups(k)%group%lump_masses(model, nodes)
    end do
  end subroutine set_up_group_masses

  !> The internal forces and moments of every group at the current configuration: clears the
  !> nodal arrays the groups add into, then each group adds, timed on its own.
  subroutine compute_internal_forces(model, groups, nodes, step)
    type(model_t), intent(in) :: model
    type(group_holder_t), intent(inout) :: groups(:)
    type(nodal_state_t), intent(inout) :: nodes
    real(wp), intent(in) :: step          !< the step just taken (0 at the start)
    integer :: node, k
    ! (the rotational arrays only where some node has rotations: a pass over memory that a model
    ! of solids would pay every cycle for nothing)
    if (nodes%rotational) then
      !$omp parallel do schedule(static) default(shared) private(node)
      do node = 1, nodes%count
        nodes%internal_force(:, node) = 0.0_wp
        nodes%internal_moment(:, node) = 0.0_wp
        nodes%shell_normal_sum(:, node) = 0.0_wp
        nodes%shell_area_sum(node) = 0.0_wp
      end do
      !$omp end parallel do
    else
      !$omp parallel do schedule(static) default(shared) private(node)
      do node = 1, nodes%count
        nodes%internal_force(:, node) = 0.0_wp
      end do
      !$omp end parallel do
    end if
    do k = 1, size(groups)
      call start_phase(groups(k)%group%timer)
      call groups(k)%group%add_internal_forces(model, nodes, step)
      call stop_phase(groups(k)%group%timer)
    end do
  end subroutine compute_internal_forces

  !> The smallest stable step of the groups' last force calls, the group and element that set
  !> it (0, 0 and huge when none), and whether some group's step was not a number.
  subroutine smallest_group_step(groups, step, group, element, not_finite)
    type(group_holder_t), intent(in) :: groups(:)
    real(wp), intent(out) :: step
    integer, intent(out) :: group, element
    logical, intent(out) :: not_finite
    integer :: k
    step = huge(1.0_wp)
    group = 0
    element = 0
    not_finite = .false.
    do k = 1, size(groups)
      if (groups(k)%group%stable_time_step < step) then
        step = groups(k)%group%stable_time_step
        group = k
        element = groups(k)%group%critical_element
      end if
      if (groups(k)%group%step_not_finite) not_finite = .true.
    end do
  end subroutine smallest_group_step

  !> The first group (in engine order) with a failed element: its index, or 0.
  integer function group_failure(groups)
    type(group_holder_t), intent(in) :: groups(:)
    integer :: k
    group_failure = 0
    do k = 1, size(groups)
      if (groups(k)%group%failed_element /= 0) then
        group_failure = k
        return
      end if
    end do
  end function group_failure

  !> The element fields of an output state from every group.
  subroutine collect_element_results(model, groups, results)
    type(model_t), intent(in) :: model
    type(group_holder_t), intent(in) :: groups(:)
    type(element_results_t), intent(inout) :: results
    integer :: k
    do k = 1, size(groups)
      call groups(k)%group%element_results(model, results)
    end do
  end subroutine collect_element_results
  !> The model-indexed masks of eroded solids and shells (what contacts read), from the groups'
  !> own masks: at the first erosion phase of a run, and when a restart dump is read.
  subroutine eroded_element_masks(model, groups, solid_eroded, shell_eroded)
    type(model_t), intent(in) :: model
    type(group_holder_t), intent(in) :: groups(:)
    logical, allocatable, intent(out) :: solid_eroded(:), shell_eroded(:)
    integer :: k, solids, shells
    solids = 0
    shells = 0
    if (allocated(model%solid_part)) solids = size(model%solid_part)
    if (allocated(model%shell_part)) shells = size(model%shell_part)
    allocate (solid_eroded(solids), shell_eroded(shells))
    solid_eroded = .false.
    shell_eroded = .false.
    do k = 1, size(groups)
      call groups(k)%group%mark_eroded(solid_eroded, shell_eroded)
    end do
  end subroutine eroded_element_masks
end module element_groups
