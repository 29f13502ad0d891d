!> Colouring of element blocks for the race-free force assembly: blocks of one colour share no
!> node, so their elements can add into the nodal forces in parallel, colour after colour.
module block_colouring
  use gather_list, only: gather_list_t, build_gather_list
  implicit none
  private

  public :: colour_blocks_by_nodes, colour_blocks_by_node_lists

contains

  !> Greedy colouring: a block takes the lowest colour that no earlier block sharing a node
  !> with it has taken. `block_nodes(lane, corner, block)` are the node indices of the lanes
  !> 1..element_count(block). Returns colour -> blocks as a CSR list (blocks in index order
  !> within a colour).
  subroutine colour_blocks_by_nodes(node_count, block_nodes, element_count, colours)
    integer, intent(in) :: node_count
    integer, intent(in) :: block_nodes(:, :, :)
    integer, intent(in) :: element_count(:)
    type(gather_list_t), intent(out) :: colours
    integer, allocatable :: offsets(:), listed(:)
    integer :: block_count, b, corner, lane, count

    ! every block as the list of its lanes' corner nodes (a node shared by lanes is listed more
    ! than once, which the colouring tolerates: a hexahedral node has at most 8 elements)
    block_count = size(block_nodes, 3)
    allocate (offsets(block_count + 1), listed(size(block_nodes)))
    count = 0
    do b = 1, block_count
      offsets(b) = count + 1
      do corner = 1, size(block_nodes, 2)
        do lane = 1, element_count(b)
          count = count + 1
          listed(count) = block_nodes(lane, corner, b)
        end do
      end do
    end do
    offsets(block_count + 1) = count + 1
    call colour_blocks_by_node_lists(node_count, offsets, listed(1:count), colours)
  end subroutine colour_blocks_by_nodes

  !> The greedy colouring for blocks given as node lists: the nodes of block b are
  !> block_nodes(offsets(b) : offsets(b+1)-1). A node listed twice in a block only costs time:
  !> meshfree blocks touch hundreds of nodes through their points' pairs, and a node a few
  !> hundred pairs, so they list each node once per block (linear in the (block, node)
  !> incidences).
  subroutine colour_blocks_by_node_lists(node_count, offsets, block_nodes, colours)
    integer, intent(in) :: node_count
    integer, intent(in) :: offsets(:), block_nodes(:)
    type(gather_list_t), intent(out) :: colours
    type(gather_list_t) :: node_blocks
    integer, allocatable :: slot_block(:), colour(:), taken_by(:)
    integer :: block_count, b, k, slot, other, chosen, colour_count

    block_count = size(offsets) - 1
    allocate (slot_block(size(block_nodes)))
    do b = 1, block_count
      slot_block(offsets(b):offsets(b + 1) - 1) = b
    end do
    call build_gather_list(node_count, block_nodes, node_blocks)

    allocate (colour(block_count), taken_by(block_count + 1))
    taken_by = 0
    colour_count = 0
    do b = 1, block_count
      do slot = offsets(b), offsets(b + 1) - 1
        do k = node_blocks%offsets(block_nodes(slot)), node_blocks%offsets(block_nodes(slot) + 1) - 1
          other = slot_block(node_blocks%corners(k))
          if (other < b) taken_by(colour(other)) = b
        end do
      end do
      chosen = 1
      do while (taken_by(chosen) == b)
        chosen = chosen + 1
      end do
      colour(b) = chosen
      colour_count = max(colour_count, chosen)
    end do
    call list_blocks_by_colour(colour, colour_count, colours)
  end subroutine colour_blocks_by_node_lists

  !> colour -> blocks as a CSR list, blocks in index order within a colour.
  subroutine list_blocks_by_colour(colour, colour_count, colours)
    integer, intent(in) :: colour(:), colour_count
    type(gather_list_t), intent(out) :: colours
    integer, allocatable :: count_of(:), blocks(:)
    integer :: block_count, b, k
    block_count = size(colour)
    allocate (count_of(colour_count + 1), blocks(block_count))
    count_of = 0
    do b = 1, block_count
      count_of(colour(b) + 1) = count_of(colour(b) + 1) + 1
    end do
    count_of(1) = 1
    do k = 1, colour_count
      count_of(k + 1) = count_of(k + 1) + count_of(k)
    end do
    colours%offsets = count_of
    do b = 1, block_count
      blocks(count_of(colour(b))) = b
      count_of(colour(b)) = count_of(colour(b)) + 1
    end do
    call move_alloc(blocks, colours%corners)
  end subroutine list_blocks_by_colour
end module block_colouring
