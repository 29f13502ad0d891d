!> Eroded elements leave the penalty contacts (LS-DYNA's *CONTACT_ERODING_... behaviour for the
!> automatic contacts): in a cycle where elements eroded, every contact is built again from the
!> model without them (penalty_contact's set_up_contact), and what each secondary node carried
!> from cycle to cycle (its pair, the depth and side of its penetration, the friction spring,
!> the ignored initial penetration) moves over to the new passes. A pair whose segment left ends;
!> the node is free until it meets the next surface. The search lists are rebuilt at the next
!> contact evaluation.
module contact_erosion
  use error_handling, only: error_t
  use model, only: model_t
  use penalty_contact, only: contact_state_t, contact_pass_t, set_up_contact
  implicit none
  private

  public :: remove_eroded_elements

contains

  !> Remove the segments of eroded elements from every pass of every contact, add the faces of
  !> remaining solids that became exterior (sides given by parts), and stop checking secondary
  !> nodes with no remaining element. `solid_eroded` and `shell_eroded` are cumulative, by
  !> model element index. Called only in cycles where some element eroded: it allocates.
  subroutine remove_eroded_elements(model, contacts, solid_eroded, shell_eroded)
    type(model_t), intent(in) :: model
    type(contact_state_t), intent(inout) :: contacts(:)
    logical, intent(in) :: solid_eroded(:), shell_eroded(:)
    type(contact_state_t) :: rebuilt
    type(error_t), allocatable :: error
    logical, allocatable :: is_particle(:)
    integer :: k, p
    allocate (is_particle(size(model%node_ids)))
    do k = 1, size(contacts)
      is_particle = .false.
      if (allocated(contacts(k)%excluded_nodes)) is_particle(contacts(k)%excluded_nodes) = .true.
      call set_up_contact(model, is_particle, k, solid_eroded, shell_eroded, rebuilt, error)
      ! the same surfaces were accepted at set-up, and leaving elements out raises no new
      ! problem; should it ever, the contact keeps its surfaces
      if (allocated(error)) then
        deallocate (error)
        cycle
      end if
      do p = 1, rebuilt%pass_count
        call carry_over(contacts(k)%passes(p), rebuilt%passes(p), size(model%node_ids))
      end do
      rebuilt%force = contacts(k)%force
      rebuilt%impulse = contacts(k)%impulse
      contacts(k) = rebuilt
    end do
  end subroutine remove_eroded_elements

  !> Move the per-node state of `old` into the rebuilt pass `new`: by node, with each pair's
  !> segment found again by its corners (0 when it left).
  subroutine carry_over(old, new, node_count)
    type(contact_pass_t), intent(in) :: old
    type(contact_pass_t), intent(inout) :: new
    integer, intent(in) :: node_count
    integer, allocatable :: slot(:), segment_map(:)
    integer :: i, j, segment
    new%initial_checked = old%initial_checked
    new%initial_count = old%initial_count
    new%initial_deepest = old%initial_deepest
    new%initial_node = old%initial_node
    new%initial_reported = old%initial_reported
    call map_segments(old%segments, new%segments, node_count, segment_map)
    allocate (slot(node_count))
    slot = 0
    do i = 1, old%node_count
      slot(old%nodes(i)) = i
    end do
    do i = 1, new%node_count
      j = slot(new%nodes(i))
      if (j == 0) cycle
      new%initial_depth(i) = old%initial_depth(j)
      if (old%pair_segment(j) == 0) cycle
      segment = segment_map(old%pair_segment(j))
      if (segment == 0) cycle
      new%pair_segment(i) = segment
      new%pair_side(i) = old%pair_side(j)
      new%pair_depth(i) = old%pair_depth(j)
      new%pair_weights(:, i) = old%pair_weights(:, j)
      new%pair_force(:, i) = old%pair_force(:, j)
      new%tangential(:, i) = old%tangential(:, j)
    end do
  end subroutine carry_over

  !> For each segment of `old`: the index of the segment of `new` with the same corners in the
  !> same order, or 0. Grouped by the first corner, so the cost is linear.
  subroutine map_segments(old, new, node_count, map)
    integer, intent(in) :: old(:, :), new(:, :), node_count
    integer, allocatable, intent(out) :: map(:)
    integer, allocatable :: first(:), members(:)
    integer :: s, n, k
    allocate (map(size(old, 2)), first(node_count + 1), members(size(new, 2)))
    map = 0
    first = 0
    do s = 1, size(new, 2)
      first(new(1, s) + 1) = first(new(1, s) + 1) + 1
    end do
    first(1) = 1
    do n = 1, node_count
      first(n + 1) = first(n + 1) + first(n)
    end do
    do s = 1, size(new, 2)
      n = new(1, s)
      members(first(n)) = s
      first(n) = first(n) + 1
    end do
    do n = node_count, 1, -1
      first(n + 1) = first(n)
    end do
    first(1) = 1
    do s = 1, size(old, 2)
      n = old(1, s)
      do k = first(n), first(n + 1) - 1
        if (all(new(:, members(k)) == old(:, s))) then
          map(s) = members(k)
          exit
        end if
      end do
    end do
  end subroutine map_segments
end module contact_erosion
