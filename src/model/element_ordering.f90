!> Spatially coherent order of the elements of each part, taken before the elements are cut into
!> blocks of `block_size` lanes (OpenRadioss's starter does the same with METIS).
!>
!> Blocks are coloured so that the blocks of one colour share no node (block_colouring), and the
!> colours run one after the other. Cut in deck order, a mesh numbered at random gives blocks
!> whose elements lie all over the part: every block then shares nodes with almost every other
!> and a 100,000-element block needed 248 colours instead of 5, which left one thread's worth of
!> work per colour. Ordered here, each block is a compact patch of the part whatever the deck's
!> numbering, shares nodes only with the patches around it, and gathers nodes that sit close
!> together in the element's neighbourhood.
!>
!> The order: METIS (Karypis & Kumar, SIAM J. Sci. Comput. 20 (1998) 359) cuts the part's dual
!> graph (elements adjacent when they share a face) into ceil(n / block_size) pieces of about
!> block_size elements by recursive bisection, and the elements follow piece by piece, in input
!> order within a piece. Recursive bisection numbers its pieces down a binary tree, so pieces
!> of consecutive numbers are neighbours in space: a block that straddles two pieces (their
!> sizes are balanced only to a few percent) is still compact, and so is any subset of the
!> elements taken in this order (the exposed elements that solid_block puts first). K-way
!> partitioning makes pieces as compact but numbers them without that locality; it needed more
!> colours here (docs/solver.md, "Element order and blocks").
!>
!> METIS is serial and seeded with a fixed value, so the order depends on the model only, not
!> on the thread count. A part of at most block_size elements is one block whatever its order,
!> and keeps its input order; so does a part whose elements share no node (nothing to colour
!> apart) and, as a fallback, a part METIS refuses. Elements that share nodes but no face (a
!> chain of hexahedra joined at edges) are ordered by the graph of shared nodes instead.
module element_ordering
  use, intrinsic :: iso_c_binding, only: c_int, c_int32_t, c_ptr, c_null_ptr, c_associated, c_f_pointer
  use kinds, only: block_size
  implicit none
  private

  public :: spatial_element_order

  !> METIS's idx_t: 32 bits in Debian's libmetis-dev 5.1.0 (IDXTYPEWIDTH 32 in metis.h).
  integer, parameter :: idx_t = c_int32_t
  integer(c_int), parameter :: metis_ok = 1
  integer, parameter :: metis_option_count = 40          !< METIS_NOPTIONS
  integer, parameter :: metis_option_seed = 8            !< METIS_OPTION_SEED (0-based index)
  integer, parameter :: metis_option_numbering = 17      !< METIS_OPTION_NUMBERING (0-based index)
  !> Any fixed seed makes METIS's randomized matching repeatable; this one is arbitrary.
  integer(idx_t), parameter :: metis_seed = 20240611_idx_t

  interface
    function metis_set_default_options(options) bind(c, name="METIS_SetDefaultOptions") result(status)
      import :: c_int, idx_t
      integer(idx_t), intent(out) :: options(*)
      integer(c_int) :: status
    end function metis_set_default_options

    !> The dual graph of a mesh: elements adjacent when they share at least `shared_nodes`
    !> nodes (or all but one of either element's nodes). METIS allocates the two arrays.
    function metis_mesh_to_dual(element_count, node_count, element_offsets, element_nodes, shared_nodes, &
                                numbering, graph_offsets, graph_neighbours) bind(c, name="METIS_MeshToDual") &
      result(status)
      import :: c_int, c_ptr, idx_t
      integer(idx_t), intent(in) :: element_count, node_count, shared_nodes, numbering
      integer(idx_t), intent(in) :: element_offsets(*), element_nodes(*)
      type(c_ptr), intent(out) :: graph_offsets, graph_neighbours
      integer(c_int) :: status
    end function metis_mesh_to_dual

    function metis_part_graph_recursive(vertex_count, constraint_count, graph_offsets, graph_neighbours, &
                                        vertex_weights, vertex_sizes, edge_weights, piece_count, target_weights, &
                                        imbalance, options, edge_cut, piece) &
      bind(c, name="METIS_PartGraphRecursive") result(status)
      import :: c_int, c_ptr, idx_t
      integer(idx_t), intent(in) :: vertex_count, constraint_count, piece_count
      type(c_ptr), value :: graph_offsets, graph_neighbours, vertex_weights, vertex_sizes, edge_weights
      type(c_ptr), value :: target_weights, imbalance
      integer(idx_t), intent(in) :: options(*)
      integer(idx_t), intent(out) :: edge_cut
      integer(idx_t), intent(out) :: piece(*)
      integer(c_int) :: status
    end function metis_part_graph_recursive

    function metis_free(memory) bind(c, name="METIS_Free") result(status)
      import :: c_int, c_ptr
      type(c_ptr), value :: memory
      integer(c_int) :: status
    end function metis_free
  end interface

contains

  !> All elements (columns of `element_nodes`, node indices >= 1), grouped by part in increasing
  !> part index; within each part for which `part_wanted` is true in a spatially coherent order
  !> (module comment), within the others in input order. `face_nodes` is the number of nodes
  !> two elements of a face-connected mesh share across a face: 3 for solids (a quadrilateral
  !> face, or the triangle of a wedge or tetrahedron given as a degenerate hexahedron), 2 for
  !> shells (an edge).
  function spatial_element_order(element_nodes, element_part, part_wanted, face_nodes) result(order)
    integer, intent(in) :: element_nodes(:, :), element_part(:)
    logical, intent(in) :: part_wanted(:)
    integer, intent(in) :: face_nodes
    integer, allocatable :: order(:)
    integer, allocatable :: first_of_part(:), next_slot(:), local_node(:)
    integer :: element, part, part_count

    part_count = size(part_wanted)
    ! Counting sort by part (stable: input order within a part).
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
    do element = 1, size(element_part)
      order(next_slot(element_part(element))) = element
      next_slot(element_part(element)) = next_slot(element_part(element)) + 1
    end do

    allocate (local_node(max(0, maxval(element_nodes))))
    local_node = 0
    do part = 1, part_count
      if (.not. part_wanted(part)) cycle
      if (first_of_part(part + 1) - first_of_part(part) <= block_size) cycle
      call order_part(element_nodes, face_nodes, order(first_of_part(part):first_of_part(part + 1) - 1), local_node)
    end do
  end function spatial_element_order

  !> Reorder the elements of one part (in place) piece by piece. `local_node` is zero on entry
  !> and on return (a work array over all nodes, so that each part costs only its own size).
  subroutine order_part(element_nodes, face_nodes, elements, local_node)
    integer, intent(in) :: element_nodes(:, :), face_nodes
    integer, intent(inout) :: elements(:)
    integer, intent(inout) :: local_node(:)
    integer(idx_t), allocatable :: element_offsets(:), part_nodes(:), piece(:)
    integer, allocatable :: used_nodes(:)
    integer(idx_t) :: element_count, node_count, options(metis_option_count), edge_cut, piece_count
    type(c_ptr) :: graph_offsets, graph_neighbours
    integer(idx_t), pointer :: offsets(:)
    integer :: k, corner, node, edge_count, slot, attempt
    integer(c_int) :: status

    ! The part as a METIS mesh: its nodes numbered from 0 in order of appearance, and each
    ! element's distinct nodes (a node listed twice would count twice among the shared ones).
    element_count = size(elements)
    allocate (element_offsets(element_count + 1), part_nodes(size(element_nodes, 1)*element_count), &
              used_nodes(size(element_nodes, 1)*element_count))
    node_count = 0
    slot = 0
    element_offsets(1) = 0
    do k = 1, size(elements)
      do corner = 1, size(element_nodes, 1)
        node = element_nodes(corner, elements(k))
        if (any(element_nodes(1:corner - 1, elements(k)) == node)) cycle
        if (local_node(node) == 0) then
          node_count = node_count + 1
          used_nodes(node_count) = node
          local_node(node) = node_count
        end if
        slot = slot + 1
        part_nodes(slot) = local_node(node) - 1
      end do
      element_offsets(k + 1) = slot
    end do
    local_node(used_nodes(1:node_count)) = 0

    ! Face neighbours; node neighbours when the elements share no face.
    edge_count = 0
    do attempt = 1, 2
      status = metis_mesh_to_dual(element_count, node_count, element_offsets, part_nodes, &
                                  int(merge(face_nodes, 1, attempt == 1), idx_t), 0_idx_t, graph_offsets, &
                                  graph_neighbours)
      if (status /= metis_ok) return
      call c_f_pointer(graph_offsets, offsets, [element_count + 1])
      edge_count = offsets(element_count + 1)
      if (edge_count > 0) exit
      call free_graph(graph_offsets, graph_neighbours)
    end do
    if (edge_count == 0) return

    status = metis_set_default_options(options)
    options(metis_option_seed + 1) = metis_seed
    options(metis_option_numbering + 1) = 0
    piece_count = int((size(elements) + block_size - 1)/block_size, idx_t)
    allocate (piece(element_count))
    status = metis_part_graph_recursive(element_count, 1_idx_t, graph_offsets, graph_neighbours, c_null_ptr, &
                                        c_null_ptr, c_null_ptr, piece_count, c_null_ptr, c_null_ptr, options, &
                                        edge_cut, piece)
    call free_graph(graph_offsets, graph_neighbours)
    if (status /= metis_ok) return
    call sort_by_piece(piece, int(piece_count), elements)
  end subroutine order_part

  !> Stable counting sort of `elements` by their piece (0-based).
  subroutine sort_by_piece(piece, piece_count, elements)
    integer(idx_t), intent(in) :: piece(:)
    integer, intent(in) :: piece_count
    integer, intent(inout) :: elements(:)
    integer, allocatable :: next_slot(:), sorted(:)
    integer :: k, p
    allocate (next_slot(0:piece_count), sorted(size(elements)))
    next_slot = 0
    do k = 1, size(elements)
      next_slot(piece(k) + 1) = next_slot(piece(k) + 1) + 1
    end do
    next_slot(0) = 1
    do p = 1, piece_count
      next_slot(p) = next_slot(p) + next_slot(p - 1)
    end do
    do k = 1, size(elements)
      sorted(next_slot(piece(k))) = elements(k)
      next_slot(piece(k)) = next_slot(piece(k)) + 1
    end do
    elements = sorted
  end subroutine sort_by_piece

  !> Give the arrays of a METIS graph back to METIS.
  subroutine free_graph(graph_offsets, graph_neighbours)
    type(c_ptr), intent(inout) :: graph_offsets, graph_neighbours
    integer(c_int) :: status
    if (c_associated(graph_offsets)) status = metis_free(graph_offsets)
    if (c_associated(graph_neighbours)) status = metis_free(graph_neighbours)
    graph_offsets = c_null_ptr
    graph_neighbours = c_null_ptr
  end subroutine free_graph
end module element_ordering
