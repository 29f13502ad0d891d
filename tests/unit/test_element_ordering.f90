!> Unit tests of element_ordering (the spatially coherent order of each part's elements that
!> the element blocks are cut from):
!> - the order is a permutation grouped by part, the same on every call, and leaves parts not
!>   wanted, parts of at most block_size elements and parts whose elements share no node in
!>   input order;
!> - a 20 x 20 x 5 hexahedral mesh numbered at random gives, cut into blocks in this order and
!>   coloured like the solver does (block_colouring), about as few colours as the naturally
!>   numbered mesh cut in input order (at most twice as many plus three), where input order
!>   needs many times more; the same for a quadrilateral shell mesh with triangles (node 4 =
!>   node 3) and for wedges given as degenerate hexahedra;
!> - a plate numbered through its thickness first keeps its input order (its blocks meet fewer
!>   others than compact pieces);
!> - a row of hexahedra joined only at edges is ordered through the nodes they share (colours
!>   as above), and a one-element part is left alone;
!> - leading elements come first, and the blocks of the ordered renumbered mesh gather fewer
!>   distinct nodes than the slabs of natural input order;
!> - build_solid_blocks keeps the exposed elements first and few colours on the renumbered
!>   mesh.
program test_element_ordering
  use kinds, only: wp, long_int, block_size
  use gather_list, only: gather_list_t
  use block_colouring, only: colour_blocks_by_nodes
  use element_ordering, only: spatial_element_order
  use model, only: model_t, formulation_fe
  use material_laws, only: law_elastic
  use solid_block, only: solid_block_t, build_solid_blocks
  use testing, only: test_suite_t, check, finish_suite
  implicit none

  type(test_suite_t) :: suite
  integer :: random_state = 20240611

  suite%name = "element_ordering"
  call test_renumbered_hexahedra()
  call test_wedges()
  call test_shells()
  call test_parts_and_small_cases()
  call test_leading_and_compact_blocks()
  call test_disconnected_and_edge_chain()
  call test_solid_blocks()
  call finish_suite(suite)

contains

  !> Natural numbering, x fastest: the blocks of input order are slabs through the mesh.
  subroutine hexahedral_mesh(cells, element_nodes, coordinates)
    integer, intent(in) :: cells(3)
    integer, allocatable, intent(out) :: element_nodes(:, :)
    real(wp), allocatable, intent(out), optional :: coordinates(:, :)
    integer :: i, j, k, element
    allocate (element_nodes(8, product(cells)))
    element = 0
    do k = 0, cells(3) - 1
      do j = 0, cells(2) - 1
        do i = 0, cells(1) - 1
          element = element + 1
          element_nodes(:, element) = [node_at(cells, i, j, k), node_at(cells, i + 1, j, k), &
                                       node_at(cells, i + 1, j + 1, k), node_at(cells, i, j + 1, k), &
                                       node_at(cells, i, j, k + 1), node_at(cells, i + 1, j, k + 1), &
                                       node_at(cells, i + 1, j + 1, k + 1), node_at(cells, i, j + 1, k + 1)]
        end do
      end do
    end do
    if (present(coordinates)) then
      allocate (coordinates(3, product(cells + 1)))
      do k = 0, cells(3)
        do j = 0, cells(2)
          do i = 0, cells(1)
            coordinates(:, node_at(cells, i, j, k)) = real([i, j, k], wp)
          end do
        end do
      end do
    end if
  end subroutine hexahedral_mesh

  pure integer function node_at(cells, i, j, k)
    integer, intent(in) :: cells(3), i, j, k
    node_at = 1 + i + (cells(1) + 1)*(j + (cells(2) + 1)*k)
  end function node_at

  !> The same mesh as a mesher numbering at random would write it: elements in a random order
  !> and nodes renamed by a random permutation. `element_of(k)` is the original element of
  !> column k, `node_of(n)` the original node now numbered n.
  subroutine renumber_mesh(element_nodes, node_count, renumbered, element_of, node_of)
    integer, intent(in) :: element_nodes(:, :), node_count
    integer, allocatable, intent(out) :: renumbered(:, :), element_of(:), node_of(:)
    integer, allocatable :: new_name(:)
    integer :: k, node
    element_of = random_permutation(size(element_nodes, 2))
    node_of = random_permutation(node_count)
    allocate (new_name(node_count))
    do node = 1, node_count
      new_name(node_of(node)) = node
    end do
    allocate (renumbered(size(element_nodes, 1), size(element_nodes, 2)))
    do k = 1, size(element_nodes, 2)
      renumbered(:, k) = new_name(element_nodes(:, element_of(k)))
    end do
  end subroutine renumber_mesh

  !> Fisher-Yates with a Park-Miller generator (repeatable on every compiler).
  function random_permutation(n) result(permutation)
    integer, intent(in) :: n
    integer, allocatable :: permutation(:)
    integer :: k, other, kept
    permutation = [(k, k=1, n)]
    do k = n, 2, -1
      random_state = int(mod(16807_long_int*int(random_state, long_int), 2147483647_long_int))
      other = 1 + int(mod(int(random_state, long_int), int(k, long_int)))
      kept = permutation(k)
      permutation(k) = permutation(other)
      permutation(other) = kept
    end do
  end function random_permutation

  !> Colours the solver's greedy colouring gives to the blocks of block_size consecutive
  !> elements of `order`.
  integer function colour_count(element_nodes, order) result(colours_used)
    integer, intent(in) :: element_nodes(:, :), order(:)
    integer, allocatable :: block_nodes(:, :, :), element_count(:)
    type(gather_list_t) :: colours
    integer :: block_count, k, block, lane
    block_count = (size(order) + block_size - 1)/block_size
    allocate (block_nodes(block_size, size(element_nodes, 1), block_count), element_count(block_count))
    block_nodes = 0
    element_count = 0
    do k = 1, size(order)
      block = (k - 1)/block_size + 1
      lane = k - (block - 1)*block_size
      block_nodes(lane, :, block) = element_nodes(:, order(k))
      element_count(block) = lane
    end do
    call colour_blocks_by_nodes(maxval(element_nodes), block_nodes, element_count, colours)
    colours_used = size(colours%offsets) - 1
  end function colour_count

  logical function is_permutation(order, n)
    integer, intent(in) :: order(:), n
    logical :: seen(n)
    integer :: k
    is_permutation = size(order) == n
    if (.not. is_permutation) return
    seen = .false.
    do k = 1, n
      if (order(k) < 1 .or. order(k) > n) then
        is_permutation = .false.
        return
      end if
      seen(order(k)) = .true.
    end do
    is_permutation = all(seen)
  end function is_permutation

  !> The colour counts of natural input order, random input order and the ordered random mesh.
  subroutine check_colours(label, element_nodes, renumbered, face_nodes)
    character(len=*), intent(in) :: label
    integer, intent(in) :: element_nodes(:, :), renumbered(:, :), face_nodes
    integer, allocatable :: order(:), again(:), parts(:)
    integer :: natural, unordered, ordered, n, k
    character(len=120) :: counts
    n = size(element_nodes, 2)
    allocate (parts(n))
    parts = 1
    order = spatial_element_order(renumbered, parts, [.true.], face_nodes)
    again = spatial_element_order(renumbered, parts, [.true.], face_nodes)
    call check(suite, label//": a permutation", is_permutation(order, n))
    call check(suite, label//": deterministic", all(order == again))
    natural = colour_count(element_nodes, [(k, k=1, n)])
    unordered = colour_count(renumbered, [(k, k=1, n)])
    ordered = colour_count(renumbered, order)
    write (counts, '(3(a,i0))') "colours: natural ", natural, ", renumbered ", unordered, &
      ", renumbered and ordered ", ordered
    write (*, '(a)') "  "//label//" "//trim(counts)
    call check(suite, label//": ordered colours close to the natural ones", ordered <= 2*natural + 3, trim(counts))
    call check(suite, label//": the renumbering alone needs many colours", unordered > 2*natural + 3, trim(counts))
  end subroutine check_colours

  !> The renumbered mesh is ordered. A plate of 4 x 40 x 40 cells numbered through its
  !> thickness first keeps its order: its blocks are slabs through the thickness (4 x 16 x 1),
  !> which meet fewer other blocks than compact pieces would.
  subroutine test_renumbered_hexahedra()
    integer, allocatable :: element_nodes(:, :), renumbered(:, :), element_of(:), node_of(:), order(:)
    integer, allocatable :: plate(:, :), identity(:), parts(:)
    integer :: k
    call hexahedral_mesh([20, 20, 5], element_nodes)
    call renumber_mesh(element_nodes, 21*21*6, renumbered, element_of, node_of)
    call check_colours("hexahedra 20x20x5", element_nodes, renumbered, 3)
    call hexahedral_mesh([4, 40, 40], plate)
    allocate (identity(size(plate, 2)), parts(size(plate, 2)))
    do k = 1, size(plate, 2)
      identity(k) = k
    end do
    parts = 1
    order = spatial_element_order(plate, parts, [.true.], 3)
    call check(suite, "plate numbered through its thickness keeps its order", all(order == identity))
  end subroutine test_renumbered_hexahedra

  !> Every cell of a 20 x 20 x 4 mesh cut into two wedges, each a hexahedron with nodes 3 = 4
  !> and 7 = 8: neighbours share triangles (3 nodes) or quadrilaterals.
  subroutine test_wedges()
    integer, allocatable :: cells(:, :), wedges(:, :), renumbered(:, :), element_of(:), node_of(:)
    integer :: cell
    call hexahedral_mesh([20, 20, 4], cells)
    allocate (wedges(8, 2*size(cells, 2)))
    do cell = 1, size(cells, 2)
      associate (c => cells(:, cell))
        wedges(:, 2*cell - 1) = [c(1), c(2), c(3), c(3), c(5), c(6), c(7), c(7)]
        wedges(:, 2*cell) = [c(1), c(3), c(4), c(4), c(5), c(7), c(8), c(8)]
      end associate
    end do
    call renumber_mesh(wedges, 21*21*5, renumbered, element_of, node_of)
    call check_colours("wedges 20x20x4", wedges, renumbered, 3)
  end subroutine test_wedges

  !> A 60 x 40 quadrilateral mesh whose every fifth cell is two triangles (node 4 = node 3).
  subroutine test_shells()
    integer, parameter :: nx = 60, ny = 40
    integer, allocatable :: shells(:, :), renumbered(:, :), element_of(:), node_of(:)
    integer :: i, j, count, n1, n2, n3, n4
    allocate (shells(4, 2*nx*ny))
    count = 0
    do j = 0, ny - 1
      do i = 0, nx - 1
        n1 = 1 + i + (nx + 1)*j
        n2 = n1 + 1
        n3 = n2 + nx + 1
        n4 = n1 + nx + 1
        if (mod(i + j*nx, 5) == 0) then
          shells(:, count + 1) = [n1, n2, n3, n3]
          shells(:, count + 2) = [n1, n3, n4, n4]
          count = count + 2
        else
          shells(:, count + 1) = [n1, n2, n3, n4]
          count = count + 1
        end if
      end do
    end do
    call renumber_mesh(shells(:, 1:count), (nx + 1)*(ny + 1), renumbered, element_of, node_of)
    call check_colours("shells 60x40", shells(:, 1:count), renumbered, 2)
  end subroutine test_shells

  !> Three parts interleaved: part 1 (1,000 hexahedra) ordered, part 2 (not wanted) and part 3
  !> (64 elements: one block) in input order; a part of one element.
  subroutine test_parts_and_small_cases()
    integer, allocatable :: element_nodes(:, :), renumbered(:, :), element_of(:), node_of(:), parts(:), order(:)
    integer, allocatable :: expected_second(:), expected_third(:)
    integer :: k, first_of_second
    call hexahedral_mesh([10, 10, 12], element_nodes)
    call renumber_mesh(element_nodes, 11*11*13, renumbered, element_of, node_of)
    allocate (parts(size(renumbered, 2)))
    parts = 1
    parts(2:200:2) = 2       ! 100 elements
    parts(201:328:2) = 3     ! 64 elements
    order = spatial_element_order(renumbered, parts, [.true., .false., .true.], 3)
    call check(suite, "parts: a permutation", is_permutation(order, size(parts)))
    call check(suite, "parts: grouped by part in part order", all(parts(order(2:)) >= parts(order(:size(order) - 1))))
    first_of_second = count(parts == 1) + 1
    expected_second = [(k, k=2, 200, 2)]
    expected_third = [(k, k=201, 328, 2)]
    call check(suite, "parts: a part not wanted keeps its input order", &
               all(order(first_of_second:first_of_second + 99) == expected_second))
    call check(suite, "parts: a part of one block keeps its input order", all(order(size(order) - 63:) == expected_third))
    call check(suite, "parts: the wanted part is reordered", &
               any(order(1:first_of_second - 1) /= pack([(k, k=1, size(parts))], parts == 1)))

    order = spatial_element_order(element_nodes(:, 1:1), [1], [.true.], 3)
    call check(suite, "one element", size(order) == 1 .and. order(1) == 1)
    order = spatial_element_order(element_nodes(:, 1:65), [(1, k=1, 65)], [.true.], 3)
    call check(suite, "65 elements: a permutation", is_permutation(order, 65))
  end subroutine test_parts_and_small_cases

  !> Leading elements (here every tenth of the renumbered 20 x 20 x 5 mesh) come first; the
  !> blocks of the ordered mesh are compact: they gather fewer distinct nodes than the blocks of
  !> the natural numbering cut in input order (slabs of 3.2 rows).
  subroutine test_leading_and_compact_blocks()
    integer, allocatable :: element_nodes(:, :), renumbered(:, :), element_of(:), node_of(:), order(:)
    logical, allocatable :: leading(:)
    integer :: n, k, leading_count
    real(wp) :: natural_nodes, ordered_nodes
    character(len=80) :: counts
    call hexahedral_mesh([20, 20, 5], element_nodes)
    call renumber_mesh(element_nodes, 21*21*6, renumbered, element_of, node_of)
    n = size(renumbered, 2)
    leading = [(mod(element_of(k), 10) == 0, k=1, n)]
    leading_count = count(leading)
    order = spatial_element_order(renumbered, [(1, k=1, n)], [.true.], 3, leading)
    call check(suite, "leading: a permutation", is_permutation(order, n))
    call check(suite, "leading: leading elements first", all(leading(order(1:leading_count))) .and. &
               .not. any(leading(order(leading_count + 1:))))
    natural_nodes = mean_block_nodes(element_nodes, [(k, k=1, n)])
    order = spatial_element_order(renumbered, [(1, k=1, n)], [.true.], 3)
    ordered_nodes = mean_block_nodes(renumbered, order)
    write (counts, '(a,f6.1,a,f6.1)') "distinct nodes per block: natural ", natural_nodes, ", ordered ", ordered_nodes
    write (*, '(a)') "  hexahedra 20x20x5 "//trim(counts)
    call check(suite, "compact blocks", ordered_nodes < natural_nodes, trim(counts))
  end subroutine test_leading_and_compact_blocks

  !> Mean number of distinct nodes of the full blocks of block_size consecutive elements of
  !> `order`.
  real(wp) function mean_block_nodes(element_nodes, order)
    integer, intent(in) :: element_nodes(:, :), order(:)
    logical :: seen(maxval(element_nodes))
    integer :: block, total
    total = 0
    do block = 1, size(order)/block_size
      seen = .false.
      seen(reshape(element_nodes(:, order((block - 1)*block_size + 1:block*block_size)), [8*block_size])) = .true.
      total = total + count(seen)
    end do
    mean_block_nodes = real(total, wp)/real(max(1, size(order)/block_size), wp)
  end function mean_block_nodes

  !> 100 separate hexahedra keep their input order; 2,000 hexahedra in a row, each joined to
  !> the next along one edge only (no common face), are ordered through their shared nodes.
  subroutine test_disconnected_and_edge_chain()
    integer, parameter :: chain_length = 2000
    integer, allocatable :: separate(:, :), chain(:, :), order(:), renumbered(:, :), element_of(:), node_of(:)
    integer :: k, corner
    allocate (separate(8, 100), chain(8, chain_length))
    do k = 1, 100
      separate(:, k) = [(8*(k - 1) + corner, corner=1, 8)]
    end do
    order = spatial_element_order(separate, [(1, k=1, 100)], [.true.], 3)
    call check(suite, "separate elements keep their input order", all(order == [(k, k=1, 100)]))
    ! the edge 6-7 of element k is the edge 1-4 of element k + 1; nodes 2, 3, 5, 8 its own
    do k = 1, chain_length
      chain(:, k) = [2*k - 1, 2*chain_length + 4*k - 1, 2*chain_length + 4*k, 2*k, 2*chain_length + 4*k + 1, &
                     2*k + 1, 2*k + 2, 2*chain_length + 4*k + 2]
    end do
    call renumber_mesh(chain, maxval(chain), renumbered, element_of, node_of)
    call check_colours("hexahedra joined at edges", chain, renumbered, 3)
  end subroutine test_disconnected_and_edge_chain

  !> build_solid_blocks on the renumbered 20 x 20 x 5 mesh: every element once, the exposed
  !> lanes first within the part, and few colours.
  subroutine test_solid_blocks()
    type(model_t) :: model
    type(solid_block_t), allocatable :: blocks(:)
    integer, allocatable :: element_nodes(:, :), renumbered(:, :), element_of(:), node_of(:), listed(:)
    integer, allocatable :: block_nodes(:, :, :), element_count(:)
    real(wp), allocatable :: coordinates(:, :)
    type(gather_list_t) :: colours
    integer :: b, n, k
    logical :: exposed_first, seen_interior
    call hexahedral_mesh([20, 20, 5], element_nodes, coordinates)
    call renumber_mesh(element_nodes, 21*21*6, renumbered, element_of, node_of)
    n = size(renumbered, 2)
    model%coordinates = coordinates(:, node_of)
    model%solid_nodes = renumbered
    model%solid_part = [(1, k=1, n)]
    model%solid_ids = [(k, k=1, n)]
    allocate (model%parts(1), model%sections(1), model%materials(1))
    model%materials(1)%law = law_elastic
    model%materials(1)%density = 7.85e-9_wp
    model%materials(1)%youngs_modulus = 210000.0_wp
    model%materials(1)%poissons_ratio = 0.3_wp
    model%sections(1)%element_formulation = 1
    model%parts(1)%section = 1
    model%parts(1)%material = 1
    model%parts(1)%formulation = formulation_fe
    call build_solid_blocks(model, blocks)
    listed = [(blocks(b)%elements(1:blocks(b)%element_count), b=1, size(blocks))]
    call check(suite, "solid blocks: every element once", is_permutation(listed, n))
    exposed_first = .true.
    seen_interior = .false.
    do b = 1, size(blocks)
      do k = 1, blocks(b)%element_count
        if (blocks(b)%exposed(k) .and. seen_interior) exposed_first = .false.
        if (.not. blocks(b)%exposed(k)) seen_interior = .true.
      end do
    end do
    call check(suite, "solid blocks: exposed elements first", exposed_first .and. seen_interior .and. &
               any(blocks(1)%exposed))
    allocate (block_nodes(block_size, 8, size(blocks)), element_count(size(blocks)))
    do b = 1, size(blocks)
      block_nodes(:, :, b) = blocks(b)%nodes
      element_count(b) = blocks(b)%element_count
    end do
    call colour_blocks_by_nodes(size(model%coordinates, 2), block_nodes, element_count, colours)
    call check(suite, "solid blocks: few colours on the renumbered mesh", &
               size(colours%offsets) - 1 <= 2*colour_count(element_nodes, [(k, k=1, n)]) + 3)
  end subroutine test_solid_blocks
end program test_element_ordering
