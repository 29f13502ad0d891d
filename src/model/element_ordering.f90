!> Spatially coherent order of the elements of each part, taken before the elements are cut into
!> blocks of `block_size` lanes (OpenRadioss's starter does the same with METIS).
!>
!> Blocks are coloured so that the blocks of one colour share no node (block_colouring), and the
!> colours run one after the other. Cut in deck order, a mesh numbered at random gives blocks
!> whose elements lie all over the part: every block then shares nodes with almost every other,
!> and a block of 100,000 hexahedra needed 241 colours instead of 6. Ordered here, each block is
!> a compact patch of the part whatever the deck's numbering: it shares nodes only with the
!> patches around it and gathers fewer distinct nodes.
!>
!> The order: recursive bisection of the part's dual graph (elements adjacent when they share a
!> face), each cut made by METIS (Karypis & Kumar, SIAM J. Sci. Comput. 20 (1998) 359) and then
!> made exact by moving the elements nearest the cut, so that every piece is one whole block:
!> the caller cuts a block every block_size elements from the start of the part, and a piece
!> that straddled two blocks would make both of them two patches. The left half of every cut
!> comes first, so pieces of consecutive numbers are neighbours in space. Within a piece the
!> elements keep their input order. Elements marked `leading` (solid_block puts the exposed
!> solids first) are ordered the same way among themselves before the others, and the others'
!> first piece fills the block the leading ones left unfinished.
!>
!> The deck's order is kept unless these blocks share nodes with fewer other blocks
!> (block_conflicts, the graph the colouring works on): a deck numbered by a structured mesher
!> has slabs or rings for blocks, which meet fewer neighbours than compact pieces in 3D, colour
!> in fewer colours and sweep through memory. On the naturally numbered 100 x 100 x 10 bench
!> block compact pieces took 9% longer with one thread and 12% with two (11 colours, not 6);
!> on the square tube of 6,400 shells 1% and 4% (6 colours, not 4).
!>
!> METIS is serial and seeded with a fixed value, so the order depends on the model only, not on
!> the thread count. A part of at most block_size elements is one block whatever its order and
!> keeps its input order (leading elements first); so do elements that share no node (nothing
!> to keep apart), and a cut that METIS refuses falls back to input order. Elements that share
!> nodes but no face (a row of hexahedra joined at edges) are ordered on the graph of shared
!> nodes instead. SIGTERM is held back while METIS runs, which would catch it (signal_hold).
module element_ordering
  use, intrinsic :: iso_c_binding, only: c_int, c_ptr, c_null_ptr, c_associated, c_f_pointer
  use metis_library, only: idx_t, real_t, metis_ok, metis_option_count, metis_option_seed, metis_option_numbering, &
                           metis_set_default_options, metis_mesh_to_dual, metis_part_graph_recursive, metis_free
  use kinds, only: block_size
  use signal_hold, only: signal_mask_t, hold_termination_signal, release_held_signals
  implicit none
  private

  public :: spatial_element_order

  !> Any fixed seed makes METIS's randomized matching repeatable; this one is arbitrary.
  integer(idx_t), parameter :: metis_seed = 20240611_idx_t

  !> A graph in METIS's compressed form: the neighbours of vertex v (from 0) are
  !> neighbours(offsets(v+1)+1 : offsets(v+2)), numbered from 0.
  type :: graph_t
    integer(idx_t), allocatable :: offsets(:)
    integer(idx_t), allocatable :: neighbours(:)
  end type graph_t

contains

  !> All elements (columns of `element_nodes`, node indices >= 1), grouped by part in increasing
  !> part index; within a part the `leading` elements (if given) first, then the others; each
  !> group in a spatially coherent order (module comment; input order where that is as good) in
  !> the parts for which `part_wanted` is true, in input order in the others. `face_nodes` is the number of nodes two elements of
  !> a face-connected mesh share across a face: 3 for solids (a quadrilateral face, or the
  !> triangle of a wedge or tetrahedron given as a degenerate hexahedron), 2 for shells (an
  !> edge).
  function spatial_element_order(element_nodes, element_part, part_wanted, face_nodes, leading) result(order)
    integer, intent(in) :: element_nodes(:, :), element_part(:)
    logical, intent(in) :: part_wanted(:)
    integer, intent(in) :: face_nodes
    logical, intent(in), optional :: leading(:)
    integer, allocatable :: order(:)
    integer, allocatable :: first_of_part(:), next_slot(:), local_node(:)
    logical, allocatable :: first(:)
    type(signal_mask_t) :: signal_mask
    integer :: element, part, part_count, pass

    allocate (first(size(element_part)))
    first = .false.
    if (present(leading)) first = leading
    part_count = size(part_wanted)
    ! Counting sort by part, leading elements first (stable: input order within each group).
    allocate (first_of_part(part_count + 1), next_slot(part_count), order(size(element_part)))
    first_of_part = 0
    do element = 1, size(element_part)
      first_of_part(element_part(element) + 1) = first_of_part(element_part(element) + 1) + 1
    end do
    first_of_part(1) = 1
    do part = 1, part_count
      first_of_part(part + 1) = first_of_part(part + 1) + first_of_part(part)
    end do
    next_slot = first_of_part(1:part_count)
    do pass = 1, 2
      do element = 1, size(element_part)
        if (first(element) .neqv. pass == 1) cycle
        order(next_slot(element_part(element))) = element
        next_slot(element_part(element)) = next_slot(element_part(element)) + 1
      end do
    end do

    ! a work array over all nodes, so that each part costs only its own size
    allocate (local_node(max(0, maxval(element_nodes))))
    local_node = 0
    ! METIS would catch a SIGTERM and carry on (signal_hold)
    call hold_termination_signal(signal_mask)
    do part = 1, part_count
      if (.not. part_wanted(part)) cycle
      if (first_of_part(part + 1) - first_of_part(part) <= block_size) cycle
      associate (elements => order(first_of_part(part):first_of_part(part + 1) - 1))
        call order_part(element_nodes, face_nodes, first(elements), elements, local_node)
      end associate
    end do
    call release_held_signals(signal_mask)
  end function spatial_element_order

  !> Reorder the elements of one part in place (leading ones first, as they come in). `local_node`
  !> is zero on entry and on return.
  subroutine order_part(element_nodes, face_nodes, leading, elements, local_node)
    integer, intent(in) :: element_nodes(:, :), face_nodes
    logical, intent(in) :: leading(:)
    integer, intent(inout) :: elements(:)
    integer, intent(inout) :: local_node(:)
    type(graph_t) :: graph, leading_graph, other_graph
    integer(idx_t) :: options(metis_option_count)
    integer, allocatable :: order(:), members(:), group(:), used_nodes(:)
    integer :: status, filled, k, corner, node, node_count, leading_count

    ! the part's nodes numbered from 1 in order of appearance
    allocate (used_nodes(size(element_nodes, 1)*size(elements)))
    node_count = 0
    do k = 1, size(elements)
      do corner = 1, size(element_nodes, 1)
        node = element_nodes(corner, elements(k))
        if (local_node(node) > 0) cycle
        node_count = node_count + 1
        used_nodes(node_count) = node
        local_node(node) = node_count
      end do
    end do

    call part_dual_graph(element_nodes, face_nodes, elements, local_node, node_count, graph)
    status = metis_set_default_options(options)
    options(metis_option_seed + 1) = metis_seed
    options(metis_option_numbering + 1) = 0

    allocate (members(size(elements)))
    do k = 1, size(elements)
      members(k) = k
    end do
    group = merge(0, 1, leading)
    leading_count = count(leading)
    call split_graph(graph, group, leading_graph, other_graph)
    allocate (order(size(elements)))
    filled = 0
    call cut_into_pieces(leading_graph, members(1:leading_count), block_size, options, order, filled)
    ! the others start by finishing the block the leading elements left open
    call cut_into_pieces(other_graph, members(leading_count + 1:), block_size - mod(filled, block_size), &
                         options, order, filled)
    ! a deck numbered by a structured mesher may already have better blocks: keep them then
    if (block_conflicts(element_nodes, elements(order), local_node, node_count) < &
        block_conflicts(element_nodes, elements, local_node, node_count)) elements = elements(order)
    local_node(used_nodes(1:node_count)) = 0
  end subroutine order_part

  !> Pairs of blocks (of block_size consecutive `elements`) that share a node, each pair counted
  !> from both sides: the edges of the graph that the colouring works on. Few when each block
  !> is a compact patch of the mesh; with blocks spread over the part every block meets nearly
  !> every other. `local_node` numbers the part's `node_count` nodes from 1.
  integer function block_conflicts(element_nodes, elements, local_node, node_count)
    integer, intent(in) :: element_nodes(:, :), elements(:), local_node(:), node_count
    integer, allocatable :: node_offsets(:), node_blocks(:), last_block(:), next_slot(:), met_by(:)
    integer :: k, corner, node, block, slot, pass, other

    ! node -> the blocks around it (each once), in two passes: count, then fill
    allocate (node_offsets(node_count + 1), last_block(node_count), next_slot(node_count))
    node_offsets = 0
    do pass = 1, 2
      last_block = 0
      do k = 1, size(elements)
        block = (k - 1)/block_size + 1
        do corner = 1, size(element_nodes, 1)
          node = local_node(element_nodes(corner, elements(k)))
          if (last_block(node) == block) cycle
          last_block(node) = block
          if (pass == 1) then
            node_offsets(node + 1) = node_offsets(node + 1) + 1
          else
            node_blocks(next_slot(node)) = block
            next_slot(node) = next_slot(node) + 1
          end if
        end do
      end do
      if (pass == 2) exit
      node_offsets(1) = 1
      do node = 1, node_count
        node_offsets(node + 1) = node_offsets(node + 1) + node_offsets(node)
      end do
      allocate (node_blocks(node_offsets(node_count + 1) - 1))
      next_slot = node_offsets(1:node_count)
    end do

    allocate (met_by((size(elements) + block_size - 1)/block_size))
    met_by = 0
    block_conflicts = 0
    do k = 1, size(elements)
      block = (k - 1)/block_size + 1
      do corner = 1, size(element_nodes, 1)
        node = local_node(element_nodes(corner, elements(k)))
        do slot = node_offsets(node), node_offsets(node + 1) - 1
          other = node_blocks(slot)
          if (other == block .or. met_by(other) == block) cycle
          met_by(other) = block
          block_conflicts = block_conflicts + 1
        end do
      end do
    end do
  end function block_conflicts

  !> The part's dual graph: elements adjacent when they share a face (`face_nodes` nodes), or,
  !> when no two share a face, when they share a node. Vertices are the positions in `elements`;
  !> `local_node` numbers the part's `part_node_count` nodes from 1.
  subroutine part_dual_graph(element_nodes, face_nodes, elements, local_node, part_node_count, graph)
    integer, intent(in) :: element_nodes(:, :), face_nodes, elements(:), local_node(:), part_node_count
    type(graph_t), intent(out) :: graph
    integer(idx_t), allocatable :: element_offsets(:), part_nodes(:)
    integer(idx_t) :: element_count, node_count, shared_nodes
    type(c_ptr) :: metis_offsets, metis_neighbours
    integer(idx_t), pointer :: offsets(:), neighbours(:)
    integer :: k, corner, node, slot, attempt
    integer(c_int) :: status

    ! The part as a METIS mesh: nodes numbered from 0, each element's distinct nodes (a node
    ! listed twice would count twice among the shared ones).
    element_count = size(elements)
    node_count = part_node_count
    allocate (element_offsets(element_count + 1), part_nodes(size(element_nodes, 1)*element_count))
    slot = 0
    element_offsets(1) = 0
    do k = 1, size(elements)
      do corner = 1, size(element_nodes, 1)
        node = element_nodes(corner, elements(k))
        if (any(element_nodes(1:corner - 1, elements(k)) == node)) cycle
        slot = slot + 1
        part_nodes(slot) = local_node(node) - 1
      end do
      element_offsets(k + 1) = slot
    end do

    allocate (graph%offsets(element_count + 1), graph%neighbours(0))
    graph%offsets = 0
    do attempt = 1, 2
      shared_nodes = int(merge(face_nodes, 1, attempt == 1), idx_t)
      status = metis_mesh_to_dual(element_count, node_count, element_offsets, part_nodes, shared_nodes, 0_idx_t, &
                                  metis_offsets, metis_neighbours)
      if (status /= metis_ok) return ! no edges: input order
      call c_f_pointer(metis_offsets, offsets, [element_count + 1])
      if (offsets(element_count + 1) > 0) then
        call c_f_pointer(metis_neighbours, neighbours, [offsets(element_count + 1)])
        graph%offsets = offsets
        graph%neighbours = neighbours
      end if
      if (c_associated(metis_offsets)) status = metis_free(metis_offsets)
      if (c_associated(metis_neighbours)) status = metis_free(metis_neighbours)
      if (size(graph%neighbours) > 0) exit
    end do
  end subroutine part_dual_graph

  !> Append the vertices of `graph` (positions `members`, ascending) to `order` in pieces: the
  !> first of `first_piece` vertices, then of block_size, each a compact piece of the graph and
  !> in ascending position within. Recursive bisection: the cut falls on a piece boundary near
  !> the middle, METIS makes it and move_across makes it exact, and the left side comes first.
  !> Releases the graph.
  recursive subroutine cut_into_pieces(graph, members, first_piece, options, order, filled)
    type(graph_t), intent(inout) :: graph
    integer, intent(in) :: members(:), first_piece
    integer(idx_t), intent(in) :: options(:)
    integer, intent(inout) :: order(:), filled
    type(graph_t) :: left, right
    integer, allocatable :: side(:)
    integer :: vertex_count, piece_count, left_count

    vertex_count = size(members)
    if (vertex_count <= first_piece) then
      order(filled + 1:filled + vertex_count) = members
      filled = filled + vertex_count
      deallocate (graph%offsets, graph%neighbours)
      return
    end if
    piece_count = 1 + (vertex_count - first_piece + block_size - 1)/block_size
    left_count = first_piece + (piece_count/2 - 1)*block_size
    call bisect(graph, left_count, options, side)
    call split_graph(graph, side, left, right)
    deallocate (graph%offsets, graph%neighbours)
    call cut_into_pieces(left, pack(members, side == 0), first_piece, options, order, filled)
    call cut_into_pieces(right, pack(members, side == 1), block_size, options, order, filled)
  end subroutine cut_into_pieces

  !> side(v) = 0 for exactly `left_count` vertices, 1 for the others, with few edges between.
  subroutine bisect(graph, left_count, options, side)
    type(graph_t), intent(inout) :: graph
    integer, intent(in) :: left_count
    integer(idx_t), intent(in) :: options(:)
    integer, allocatable, intent(out) :: side(:)
    integer(idx_t), allocatable :: piece(:)
    integer(idx_t) :: vertex_count, edge_cut
    real(real_t) :: target_weights(2)
    integer :: k
    integer(c_int) :: status

    vertex_count = int(size(graph%offsets) - 1, idx_t)
    ! without edges (or if METIS refuses) the cut follows input order
    side = [(merge(0, 1, k <= left_count), k=1, vertex_count)]
    if (size(graph%neighbours) == 0) return
    target_weights(1) = real(left_count, real_t)/real(vertex_count, real_t)
    target_weights(2) = 1.0_real_t - target_weights(1)
    allocate (piece(vertex_count))
    status = metis_part_graph_recursive(vertex_count, 1_idx_t, graph%offsets, graph%neighbours, c_null_ptr, &
                                        c_null_ptr, c_null_ptr, 2_idx_t, target_weights, c_null_ptr, options, &
                                        edge_cut, piece)
    if (status /= metis_ok) return
    side = int(piece)
    if (count(side == 0) > left_count) then
      call move_across(graph, 0, count(side == 0) - left_count, side)
    else if (count(side == 0) < left_count) then
      call move_across(graph, 1, left_count - count(side == 0), side)
    end if
  end subroutine bisect

  !> Move `moves` vertices from side `from` to the other, those nearest the other side first
  !> (breadth-first from the vertices that touch it, within side `from`); vertices it cannot
  !> reach (a component of their own) follow in index order.
  subroutine move_across(graph, from, moves, side)
    type(graph_t), intent(in) :: graph
    integer, intent(in) :: from, moves
    integer, intent(inout) :: side(:)
    integer, allocatable :: queue(:)
    logical, allocatable :: queued(:)
    integer :: vertex, k, head, tail, neighbour

    allocate (queue(size(side)), queued(size(side)))
    queued = .false.
    tail = 0
    do vertex = 1, size(side)
      if (side(vertex) /= from) cycle
      do k = graph%offsets(vertex) + 1, graph%offsets(vertex + 1)
        if (side(graph%neighbours(k) + 1) /= from) then
          tail = tail + 1
          queue(tail) = vertex
          queued(vertex) = .true.
          exit
        end if
      end do
    end do
    head = 0
    do while (head < tail .and. tail < moves)
      head = head + 1
      vertex = queue(head)
      do k = graph%offsets(vertex) + 1, graph%offsets(vertex + 1)
        neighbour = graph%neighbours(k) + 1
        if (side(neighbour) /= from .or. queued(neighbour)) cycle
        tail = tail + 1
        queue(tail) = neighbour
        queued(neighbour) = .true.
      end do
    end do
    do vertex = 1, size(side)
      if (tail >= moves) exit
      if (side(vertex) /= from .or. queued(vertex)) cycle
      tail = tail + 1
      queue(tail) = vertex
    end do
    side(queue(1:moves)) = 1 - from
  end subroutine move_across

  !> The subgraphs of the vertices with side 0 and side 1 (each keeps the edges within it;
  !> vertices renumbered in their order).
  subroutine split_graph(graph, side, left, right)
    type(graph_t), intent(in) :: graph
    integer, intent(in) :: side(:)
    type(graph_t), intent(out) :: left, right
    integer, allocatable :: renumbered(:), edge_count(:)
    integer :: vertex, k, neighbour, vertex_count(0:1), sub

    allocate (renumbered(size(side)), edge_count(size(side)))
    vertex_count = 0
    do vertex = 1, size(side)
      renumbered(vertex) = vertex_count(side(vertex))
      vertex_count(side(vertex)) = vertex_count(side(vertex)) + 1
    end do
    edge_count = 0
    if (size(graph%neighbours) > 0) then
      do vertex = 1, size(side)
        do k = graph%offsets(vertex) + 1, graph%offsets(vertex + 1)
          if (side(graph%neighbours(k) + 1) == side(vertex)) edge_count(vertex) = edge_count(vertex) + 1
        end do
      end do
    end if
    allocate (left%offsets(vertex_count(0) + 1), right%offsets(vertex_count(1) + 1))
    left%offsets(1) = 0
    right%offsets(1) = 0
    do vertex = 1, size(side)
      sub = renumbered(vertex) + 1
      if (side(vertex) == 0) then
        left%offsets(sub + 1) = left%offsets(sub) + edge_count(vertex)
      else
        right%offsets(sub + 1) = right%offsets(sub) + edge_count(vertex)
      end if
    end do
    allocate (left%neighbours(left%offsets(vertex_count(0) + 1)), right%neighbours(right%offsets(vertex_count(1) + 1)))
    if (size(graph%neighbours) == 0) return
    do vertex = 1, size(side)
      sub = renumbered(vertex) + 1
      edge_count(vertex) = 0
      do k = graph%offsets(vertex) + 1, graph%offsets(vertex + 1)
        neighbour = graph%neighbours(k) + 1
        if (side(neighbour) /= side(vertex)) cycle
        if (side(vertex) == 0) then
          left%neighbours(left%offsets(sub) + edge_count(vertex) + 1) = int(renumbered(neighbour), idx_t)
        else
          right%neighbours(right%offsets(sub) + edge_count(vertex) + 1) = int(renumbered(neighbour), idx_t)
        end if
        edge_count(vertex) = edge_count(vertex) + 1
      end do
    end do
  end subroutine split_graph
end module element_ordering
