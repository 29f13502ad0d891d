!> Colouring of element blocks for the race-free force assembly: blocks of one colour share no
!> node, so their elements can add into the nodal forces in parallel, colour after colour.
module block_colouring
  use kinds, only: block_size
  use gather_list, only: gather_list_t, build_gather_list
  implicit none
  private

  public :: colour_blocks_by_nodes

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
    type(gather_list_t) :: node_blocks
    integer, allocatable :: slot_node(:), colour(:), taken_by(:), count_of(:), blocks(:)
    integer :: block_count, corner_count, slots_per_block, b, corner, lane, node, k, other, chosen, colour_count

    block_count = size(block_nodes, 3)
    corner_count = size(block_nodes, 2)
    slots_per_block = block_size*corner_count
    ! node -> blocks touching it (a slot is one corner of one lane of one block)
    allocate (slot_node(slots_per_block*block_count))
    slot_node = 0
    do b = 1, block_count
      do corner = 1, corner_count
        do lane = 1, element_count(b)
          slot_node(lane + (corner - 1)*block_size + (b - 1)*slots_per_block) = block_nodes(lane, corner, b)
        end do
      end do
    end do
    call build_gather_list(node_count, slot_node, node_blocks)

    allocate (colour(block_count), taken_by(block_count + 1))
    taken_by = 0
    colour_count = 0
    do b = 1, block_count
      do corner = 1, corner_count
        do lane = 1, element_count(b)
          node = block_nodes(lane, corner, b)
          do k = node_blocks%offsets(node), node_blocks%offsets(node + 1) - 1
            other = (node_blocks%corners(k) - 1)/slots_per_block + 1
            if (other < b) taken_by(colour(other)) = b
          end do
        end do
      end do
      chosen = 1
      do while (taken_by(chosen) == b)
        chosen = chosen + 1
      end do
      colour(b) = chosen
      colour_count = max(colour_count, chosen)
    end do

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
  end subroutine colour_blocks_by_nodes
end module block_colouring
