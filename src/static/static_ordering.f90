!> Bandwidth-reducing node orderings for the banded solver of the linear static analysis:
!> reverse Cuthill-McKee (Cuthill & McKee 1969; George & Liu, "Computer Solution of Large Sparse
!> Positive Definite Systems", 1981, for the reversal and the pseudo-peripheral start node), and a
!> coordinate order along the model's longest extent.
!>
!> Reverse Cuthill-McKee numbers the nodes by level sets (graph distance from a peripheral node),
!> so its band is about the width of two levels. EFG supports couple nodes two or three layers
!> apart, which makes each level two or three layers thick; on slender structured meshes a plain
!> layer-by-layer numbering (nodes sorted along the longest extent) is then narrower, by a factor
!> of up to two. The caller tries the candidates and keeps the narrowest band.
!>
!> The couplings are given as *groups*: lists of nodes that all couple with each other (the eight
!> nodes of a finite element, the support nodes of an EFG integration point, a particle and the
!> nodes of its transformation row). Two nodes are adjacent when they share a group. A banded
!> Cholesky factor costs n kd^2 operations and n kd storage, so the bandwidth kd is what matters;
!> a fill-reducing nested dissection (METIS_NodeND) orders separators last and gives a wide band,
!> which suits a sparse factorization, not this one.
module static_ordering
  use kinds, only: wp
  use integer_lists, only: reserve_integers
  implicit none
  private

  public :: node_groups_t, add_node_group, reverse_cuthill_mckee, coordinate_order

  !> Groups of mutually coupled nodes, as a compressed list: group g holds
  !> nodes(offsets(g) : offsets(g + 1) - 1).
  type :: node_groups_t
    integer :: count = 0
    integer, allocatable :: offsets(:)
    integer, allocatable :: nodes(:)
  end type node_groups_t

contains

  !> Append one group (storage grows geometrically).
  pure subroutine add_node_group(groups, nodes)
    type(node_groups_t), intent(inout) :: groups
    integer, intent(in) :: nodes(:)
    integer :: used

    if (.not. allocated(groups%offsets)) then
      allocate (groups%offsets(1025), groups%nodes(max(8192, size(nodes))))
      groups%offsets(1) = 1
      groups%count = 0
    end if
    call reserve_integers(groups%offsets, groups%count + 1, groups%count + 2)
    used = groups%offsets(groups%count + 1) - 1
    call reserve_integers(groups%nodes, used, used + size(nodes))
    groups%nodes(used + 1:used + size(nodes)) = nodes
    groups%count = groups%count + 1
    groups%offsets(groups%count + 1) = used + size(nodes) + 1
  end subroutine add_node_group

  !> Reverse Cuthill-McKee order of the nodes 1..node_count that belong to at least one group:
  !> `order(k)` is the k-th node of the new numbering (nodes in no group are not listed). Each
  !> connected component starts from a pseudo-peripheral node; neighbours are numbered by
  !> increasing degree; the whole sequence is reversed at the end.
  subroutine reverse_cuthill_mckee(node_count, groups, order)
    integer, intent(in) :: node_count
    type(node_groups_t), intent(in) :: groups
    integer, allocatable, intent(out) :: order(:)
    integer, allocatable :: adjacency_offsets(:), adjacency(:), degree(:), level(:), queue(:)
    logical, allocatable :: numbered(:)
    integer :: active_count, numbered_count, node, start, head, current, k, neighbour, first_new

    call build_adjacency(node_count, groups, adjacency_offsets, adjacency, degree)
    allocate (numbered(node_count), level(node_count), queue(node_count))
    numbered = degree < 0
    level = 0
    active_count = count(degree >= 0)
    allocate (order(active_count))
    numbered_count = 0
    do while (numbered_count < active_count)
      ! next component: its unnumbered node of smallest degree, moved to a pseudo-peripheral node
      start = 0
      do node = 1, node_count
        if (numbered(node)) cycle
        if (start == 0) then
          start = node
        else if (degree(node) < degree(start)) then
          start = node
        end if
      end do
      start = pseudo_peripheral_node(start, adjacency_offsets, adjacency, degree, numbered, level, queue)

      ! Cuthill-McKee: breadth first, neighbours by increasing degree
      numbered_count = numbered_count + 1
      order(numbered_count) = start
      numbered(start) = .true.
      head = numbered_count
      do while (head <= numbered_count)
        current = order(head)
        head = head + 1
        first_new = numbered_count + 1
        do k = adjacency_offsets(current), adjacency_offsets(current + 1) - 1
          neighbour = adjacency(k)
          if (numbered(neighbour)) cycle
          numbered(neighbour) = .true.
          numbered_count = numbered_count + 1
          order(numbered_count) = neighbour
        end do
        call sort_by_degree(order(first_new:numbered_count), degree)
      end do
    end do
    order = order(active_count:1:-1)
  end subroutine reverse_cuthill_mckee

  !> Node adjacency (without the node itself) from the groups; degree -1 marks nodes in no group.
  !> Each node's neighbours are collected by stamping, so the cost is the sum over nodes of the
  !> sizes of their groups, with no sorting.
  subroutine build_adjacency(node_count, groups, adjacency_offsets, adjacency, degree)
    integer, intent(in) :: node_count
    type(node_groups_t), intent(in) :: groups
    integer, allocatable, intent(out) :: adjacency_offsets(:), adjacency(:), degree(:)
    integer, allocatable :: node_group_offsets(:), node_groups(:), fill(:), stamp(:)
    integer :: g, k, node, m, other, total, pass, position

    ! node -> groups
    allocate (node_group_offsets(node_count + 1), fill(node_count))
    node_group_offsets = 0
    do g = 1, groups%count
      do k = groups%offsets(g), groups%offsets(g + 1) - 1
        node = groups%nodes(k)
        node_group_offsets(node + 1) = node_group_offsets(node + 1) + 1
      end do
    end do
    node_group_offsets(1) = 1
    do node = 1, node_count
      node_group_offsets(node + 1) = node_group_offsets(node + 1) + node_group_offsets(node)
    end do
    allocate (node_groups(node_group_offsets(node_count + 1) - 1))
    fill = node_group_offsets(1:node_count)
    do g = 1, groups%count
      do k = groups%offsets(g), groups%offsets(g + 1) - 1
        node = groups%nodes(k)
        node_groups(fill(node)) = g
        fill(node) = fill(node) + 1
      end do
    end do

    ! two passes: count the distinct neighbours, then list them
    allocate (stamp(node_count), degree(node_count), adjacency_offsets(node_count + 1))
    degree = -1
    do pass = 1, 2
      stamp = 0
      if (pass == 2) then
        adjacency_offsets(1) = 1
        do node = 1, node_count
          adjacency_offsets(node + 1) = adjacency_offsets(node) + max(degree(node), 0)
        end do
        allocate (adjacency(adjacency_offsets(node_count + 1) - 1))
      end if
      do node = 1, node_count
        if (node_group_offsets(node + 1) == node_group_offsets(node)) cycle
        stamp(node) = node
        total = 0
        position = 0
        if (pass == 2) position = adjacency_offsets(node)
        do m = node_group_offsets(node), node_group_offsets(node + 1) - 1
          g = node_groups(m)
          do k = groups%offsets(g), groups%offsets(g + 1) - 1
            other = groups%nodes(k)
            if (stamp(other) == node) cycle
            stamp(other) = node
            total = total + 1
            if (pass == 2) then
              adjacency(position) = other
              position = position + 1
            end if
          end do
        end do
        degree(node) = total
      end do
    end do
  end subroutine build_adjacency

  !> George & Liu's pseudo-peripheral node of the component of `start` among the unnumbered
  !> nodes: repeat a breadth-first level structure from the node of smallest degree in the last
  !> level while the number of levels grows. `level` is zero on entry and on return.
  function pseudo_peripheral_node(start, adjacency_offsets, adjacency, degree, numbered, level, queue) &
    result(root)
    integer, intent(in) :: start
    integer, intent(in) :: adjacency_offsets(:), adjacency(:), degree(:)
    logical, intent(in) :: numbered(:)
    integer, intent(inout) :: level(:), queue(:)
    integer :: root
    integer :: depth, new_depth, candidate, tail, k, attempt

    root = start
    call level_structure(root, adjacency_offsets, adjacency, numbered, level, queue, tail, depth)
    do attempt = 1, 20
      candidate = queue(tail)
      do k = tail, 1, -1
        if (level(queue(k)) /= depth) exit
        if (degree(queue(k)) < degree(candidate)) candidate = queue(k)
      end do
      level(queue(1:tail)) = 0
      call level_structure(candidate, adjacency_offsets, adjacency, numbered, level, queue, tail, new_depth)
      if (new_depth <= depth) exit
      root = candidate
      depth = new_depth
    end do
    level(queue(1:tail)) = 0
  end function pseudo_peripheral_node

  !> Breadth-first search from `root` over unnumbered nodes whose level is 0 on entry:
  !> queue(1:tail) in visiting order, level(node) the distance + 1 (1 for the root), depth the
  !> largest level.
  subroutine level_structure(root, adjacency_offsets, adjacency, numbered, level, queue, tail, depth)
    integer, intent(in) :: root
    integer, intent(in) :: adjacency_offsets(:), adjacency(:)
    logical, intent(in) :: numbered(:)
    integer, intent(inout) :: level(:), queue(:)
    integer, intent(out) :: tail, depth
    integer :: head, current, k, neighbour

    level(root) = 1
    queue(1) = root
    tail = 1
    head = 1
    depth = 1
    do while (head <= tail)
      current = queue(head)
      head = head + 1
      do k = adjacency_offsets(current), adjacency_offsets(current + 1) - 1
        neighbour = adjacency(k)
        if (numbered(neighbour) .or. level(neighbour) /= 0) cycle
        level(neighbour) = level(current) + 1
        depth = max(depth, level(neighbour))
        tail = tail + 1
        queue(tail) = neighbour
      end do
    end do
  end subroutine level_structure

  !> The nodes `nodes` sorted by their coordinates, lexicographically with the axes taken from
  !> the longest extent of their bounding box to the shortest (merge sort, stable).
  subroutine coordinate_order(coordinates, nodes, order)
    real(wp), intent(in) :: coordinates(:, :)
    integer, intent(in) :: nodes(:)
    integer, allocatable, intent(out) :: order(:)
    integer, allocatable :: buffer(:)
    real(wp) :: extent(3)
    integer :: axes(3), width, first, middle, last, n

    n = size(nodes)
    order = nodes
    if (n < 2) return
    extent = maxval(coordinates(:, nodes), dim=2) - minval(coordinates(:, nodes), dim=2)
    axes(1) = maxloc(extent, dim=1)
    axes(3) = minloc(extent, dim=1)
    if (axes(3) == axes(1)) axes(3) = merge(2, 3, axes(1) /= 2 .and. axes(1) /= 3)
    axes(2) = 6 - axes(1) - axes(3)
    allocate (buffer(n))
    ! bottom-up merge sort of runs of doubling width
    width = 1
    do while (width < n)
      do first = 1, n, 2*width
        middle = min(first + width - 1, n)
        last = min(first + 2*width - 1, n)
        if (middle < last) call merge_runs(order(first:middle), order(middle + 1:last), buffer(first:last))
        if (middle < last) order(first:last) = buffer(first:last)
      end do
      width = 2*width
    end do

  contains

    !> Merge two sorted runs into `merged`.
    subroutine merge_runs(left, right, merged)
      integer, intent(in) :: left(:), right(:)
      integer, intent(out) :: merged(:)
      integer :: i, j, m
      i = 1
      j = 1
      do m = 1, size(merged)
        if (j > size(right)) then
          merged(m) = left(i)
          i = i + 1
        else if (i > size(left)) then
          merged(m) = right(j)
          j = j + 1
        else if (precedes(right(j), left(i))) then
          merged(m) = right(j)
          j = j + 1
        else
          merged(m) = left(i)
          i = i + 1
        end if
      end do
    end subroutine merge_runs

    !> Whether node a comes strictly before node b.
    logical function precedes(a, b)
      integer, intent(in) :: a, b
      integer :: axis
      precedes = .false.
      do axis = 1, 3
        if (coordinates(axes(axis), a) < coordinates(axes(axis), b)) then
          precedes = .true.
          return
        else if (coordinates(axes(axis), a) > coordinates(axes(axis), b)) then
          return
        end if
      end do
    end function precedes
  end subroutine coordinate_order

  !> Insertion sort of a short list of nodes by increasing degree (ties keep their order).
  pure subroutine sort_by_degree(nodes, degree)
    integer, intent(inout) :: nodes(:)
    integer, intent(in) :: degree(:)
    integer :: i, j, held
    do i = 2, size(nodes)
      held = nodes(i)
      j = i - 1
      do while (j >= 1)
        if (degree(nodes(j)) <= degree(held)) exit
        nodes(j + 1) = nodes(j)
        j = j - 1
      end do
      nodes(j + 1) = held
    end do
  end subroutine sort_by_degree
end module static_ordering
