!> Compressed (CSR) lists from items (nodes, colours) to the slots that belong to them.
!>
!> Used wherever something is summed per node in a fixed order (a meshfree node gathering its
!> pairs, LULESH nodeElemCornerList, OpenRadioss Parith/ON) and for the colour -> blocks list of
!> the element step: the order of a list does not depend on the thread count, so results are
!> bit-identical for any `ncpu`.
module gather_list
  implicit none
  private

  public :: gather_list_t, build_gather_list

  !> `corners(offsets(n):offsets(n+1)-1)` are the slots that belong to item n (for a node, the
  !> element corners or meshfree pairs that touch it).
  type :: gather_list_t
    integer, allocatable :: offsets(:)
    integer, allocatable :: corners(:)
  end type gather_list_t

contains

  !> Build the item -> slot list for `slot_node(k)`, the item of slot k (0 = unused slot).
  !> Slots of one item appear in increasing slot order.
  subroutine build_gather_list(node_count, slot_node, list)
    integer, intent(in) :: node_count
    integer, intent(in) :: slot_node(:)
    type(gather_list_t), intent(out) :: list
    integer, allocatable :: fill(:)
    integer :: slot, node

    allocate (list%offsets(node_count + 1))
    list%offsets = 0
    do slot = 1, size(slot_node)
      node = slot_node(slot)
      if (node > 0) list%offsets(node + 1) = list%offsets(node + 1) + 1
    end do
    list%offsets(1) = 1
    do node = 1, node_count
      list%offsets(node + 1) = list%offsets(node + 1) + list%offsets(node)
    end do
    allocate (list%corners(list%offsets(node_count + 1) - 1))
    allocate (fill(node_count))
    fill = list%offsets(1:node_count)
    do slot = 1, size(slot_node)
      node = slot_node(slot)
      if (node <= 0) cycle
      list%corners(fill(node)) = slot
      fill(node) = fill(node) + 1
    end do
  end subroutine build_gather_list
end module gather_list
