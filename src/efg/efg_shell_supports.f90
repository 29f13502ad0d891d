!> Nodes, node classes and support sizes of one meshfree shell part (docs/efg_shells.md,
!> "Nodes" and "Supports"): the shells' counterpart of efg_supports, one dimension lower.
!>
!> Gamma nodes are the nodes on the part's boundary edges (an edge that only one cell of the part
!> uses: free edges, and interfaces with FE shells or other parts; also an edge that three or
!> more cells share, a junction), the nodes that elements of other parts use (shells, solids,
!> beams), and the nodes the caller asks to keep (supports, constraints, spot welds). They keep
!> their FE shell functions. The other nodes of the part's cells are interior particles.
!>
!> Each particle I has its own tangent frame T_I = (t1, t2, n): n the mean of the normals e3 of
!> its cells (made to agree in sign), t1 the global axis least aligned with n projected on the
!> tangent plane, t2 = n x t1. A flat part therefore gives every particle the same frame, so
!> that the kernel weights, which are measured in the particles' frames from 3D positions, do not
!> depend on the cell in which a point is evaluated (the integration constraint across cells).
!>
!> Support (IDILA 0): with d = X_J - X_I over every corner J of every cell of I,
!>   box (ISPLINE 0, 1): a_1 = DX max |d.t1|, a_2 = DY max |d.t2|, a_3 = DX max |d| (a cut-off
!>     along the normal, so that a folded part's far side is not covered);
!>   circle (ISPLINE 2): a = DX max |d| (3D distance).
!> A point of a cell is a convex combination of its corners (also on a warped cell), so each
!> component of its distance to a vertex I is at most the largest corner's: with DX, DY > 1 every
!> interior vertex covers its whole cell with a positive weight, which keeps b(X) in the range
!> of M(X) (the solids' consistency argument, docs/efg.md section 2).
!>
!> Everything is linear in the number of cells: edges are matched in buckets keyed by their
!> smaller node.
module efg_shell_supports
  use kinds, only: wp
  use model, only: model_t, kernel_cubic_sphere
  use efg_shell_part, only: shell_cell_frame
  implicit none
  private

  public :: shell_supports_t, build_shell_supports, corner_count

  !> The nodes of one meshfree shell part, their classes and the particles' supports.
  type :: shell_supports_t
    integer :: kernel = 0                            !< ISPLINE
    integer, allocatable :: cells(:)                 !< model shell indices of the part, ascending
    integer, allocatable :: nodes(:)                 !< model node indices of the part, ascending
    integer, allocatable :: gamma_nodes(:)           !< model node indices, ascending
    integer, allocatable :: particles(:)             !< model node indices, ascending
    integer, allocatable :: particle_of_node(:)      !< (model nodes): particle number, 0 for others
    integer, allocatable :: owner_cell(:)            !< (particles): first cell (index into cells) having it
    real(wp), allocatable :: particle_coordinates(:, :) !< (3, particles)
    real(wp), allocatable :: particle_frame(:, :, :) !< (3, 3, particles): t1, t2, n
    !> (3, particles): box a_1, a_2 (along t1, t2) and the normal cut-off a_3; circle a, a, a
    real(wp), allocatable :: particle_radius(:, :)
    !> (3, particles): half-widths along the global axes of a box holding the support (search)
    real(wp), allocatable :: search_radius(:, :)
  end type shell_supports_t

contains

  !> 3 for a triangle (N4 = N3), else 4.
  pure integer function corner_count(corners)
    integer, intent(in) :: corners(4)
    corner_count = merge(3, 4, corners(4) == corners(3))
  end function corner_count

  !> Cells, nodes, Gamma nodes, particles, frames and supports of shell part `part`, with the
  !> section's DX DY and ISPLINE; `extra_gamma_nodes` (model nodes) are kept as Gamma nodes.
  subroutine build_shell_supports(model, part, support_scale, kernel, extra_gamma_nodes, supports)
    type(model_t), intent(in) :: model
    integer, intent(in) :: part
    real(wp), intent(in) :: support_scale(2)
    integer, intent(in) :: kernel
    logical, intent(in) :: extra_gamma_nodes(:)
    type(shell_supports_t), intent(out) :: supports
    integer, allocatable :: node_local(:)
    logical, allocatable :: on_boundary(:)
    real(wp), allocatable :: normal_sum(:, :), extent(:, :)
    real(wp) :: frame(3, 3), corners(3, 4), difference(3), local(3)
    integer :: cell, model_node_count, k, count, particle, j, a, b, n, node_a, node_b

    supports%kernel = kernel
    supports%cells = pack([(cell, cell=1, size(model%shell_part))], model%shell_part == part)
    model_node_count = size(model%coordinates, 2)
    allocate (node_local(model_node_count))
    node_local = 0
    do k = 1, size(supports%cells)
      node_local(model%shell_nodes(:, supports%cells(k))) = 1
    end do
    count = 0
    do j = 1, model_node_count
      if (node_local(j) /= 0) then
        count = count + 1
        node_local(j) = count
      end if
    end do
    allocate (supports%nodes(count))
    do j = 1, model_node_count
      if (node_local(j) /= 0) supports%nodes(node_local(j)) = j
    end do

    call find_boundary_edge_nodes(model%shell_nodes, supports%cells, node_local, count, on_boundary)
    do j = 1, count
      if (extra_gamma_nodes(supports%nodes(j))) on_boundary(j) = .true.
    end do
    call mark_shared_nodes(model, part, node_local, on_boundary)
    supports%gamma_nodes = pack(supports%nodes, on_boundary)
    supports%particles = pack(supports%nodes, .not. on_boundary)
    allocate (supports%particle_of_node(model_node_count))
    supports%particle_of_node = 0
    do particle = 1, size(supports%particles)
      supports%particle_of_node(supports%particles(particle)) = particle
    end do
    n = size(supports%particles)

    ! normals of the particles: the cells' e3, each turned to agree with the sum so far
    allocate (normal_sum(3, n), supports%owner_cell(n))
    normal_sum = 0.0_wp
    supports%owner_cell = 0
    do k = 1, size(supports%cells)
      corners = model%coordinates(:, model%shell_nodes(:, supports%cells(k)))
      frame = shell_cell_frame(corners)
      do a = 1, corner_count(model%shell_nodes(:, supports%cells(k)))
        particle = supports%particle_of_node(model%shell_nodes(a, supports%cells(k)))
        if (particle == 0) cycle
        if (supports%owner_cell(particle) == 0) supports%owner_cell(particle) = k
        if (dot_product(normal_sum(:, particle), frame(:, 3)) < 0.0_wp) then
          normal_sum(:, particle) = normal_sum(:, particle) - frame(:, 3)
        else
          normal_sum(:, particle) = normal_sum(:, particle) + frame(:, 3)
        end if
      end do
    end do
    allocate (supports%particle_frame(3, 3, n), supports%particle_coordinates(3, n))
    do particle = 1, n
      supports%particle_coordinates(:, particle) = model%coordinates(:, supports%particles(particle))
      supports%particle_frame(:, :, particle) = tangent_frame(normal_sum(:, particle))
    end do

    ! extents in each particle's frame over the corners of its cells
    allocate (extent(3, n))
    extent = 0.0_wp
    do k = 1, size(supports%cells)
      associate (cell_nodes => model%shell_nodes(:, supports%cells(k)))
        do a = 1, corner_count(cell_nodes)
          node_a = cell_nodes(a)
          particle = supports%particle_of_node(node_a)
          if (particle == 0) cycle
          do b = 1, corner_count(cell_nodes)
            node_b = cell_nodes(b)
            difference = model%coordinates(:, node_b) - model%coordinates(:, node_a)
            local = matmul(difference, supports%particle_frame(:, :, particle))
            extent(1, particle) = max(extent(1, particle), abs(local(1)))
            extent(2, particle) = max(extent(2, particle), abs(local(2)))
            extent(3, particle) = max(extent(3, particle), norm2(difference))
          end do
        end do
      end associate
    end do

    allocate (supports%particle_radius(3, n), supports%search_radius(3, n))
    do particle = 1, n
      if (kernel == kernel_cubic_sphere) then
        supports%particle_radius(:, particle) = support_scale(1)*extent(3, particle)
        supports%search_radius(:, particle) = supports%particle_radius(:, particle)
      else
        ! a cell spans both tangent directions, so neither extent vanishes on a proper mesh;
        ! the floor only keeps a degenerate one (reported by the set-up) from dividing by zero
        supports%particle_radius(1, particle) = support_scale(1)*max(extent(1, particle), &
                                                                     1.0e-6_wp*extent(3, particle))
        supports%particle_radius(2, particle) = support_scale(2)*max(extent(2, particle), &
                                                                     1.0e-6_wp*extent(3, particle))
        supports%particle_radius(3, particle) = support_scale(1)*extent(3, particle)
        ! the support box in the particle's frame, seen along the global axes
        supports%search_radius(:, particle) = matmul(abs(supports%particle_frame(:, :, particle)), &
                                                     supports%particle_radius(:, particle))
      end if
    end do
  end subroutine build_shell_supports

  !> Mark the part nodes (part numbering) that an element of another part also uses: shells of
  !> other parts (also where they meet the part along a line of its interior, not at an edge),
  !> solids, and beams (N1, N2). Such nodes couple the part to its neighbours and keep FE
  !> functions whatever the caller lists.
  subroutine mark_shared_nodes(model, part, node_local, on_boundary)
    type(model_t), intent(in) :: model
    integer, intent(in) :: part, node_local(:)
    logical, intent(inout) :: on_boundary(:)
    integer :: element, a, node

    if (allocated(model%shell_part)) then
      do element = 1, size(model%shell_part)
        if (model%shell_part(element) == part) cycle
        do a = 1, 4
          node = model%shell_nodes(a, element)
          if (node_local(node) > 0) on_boundary(node_local(node)) = .true.
        end do
      end do
    end if
    if (allocated(model%solid_nodes)) then
      do element = 1, size(model%solid_nodes, 2)
        do a = 1, 8
          node = model%solid_nodes(a, element)
          if (node_local(node) > 0) on_boundary(node_local(node)) = .true.
        end do
      end do
    end if
    if (allocated(model%beam_nodes)) then
      do element = 1, size(model%beam_nodes, 2)
        do a = 1, 2
          node = model%beam_nodes(a, element)
          if (node > 0) then
            if (node_local(node) > 0) on_boundary(node_local(node)) = .true.
          end if
        end do
      end do
    end if
  end subroutine mark_shared_nodes

  !> Frame (t1, t2, n) from a normal direction: t1 is the global axis least aligned with n,
  !> projected on the tangent plane (the first such axis on a tie, so flat parts in a
  !> coordinate plane get coordinate axes).
  pure function tangent_frame(normal_direction) result(frame)
    real(wp), intent(in) :: normal_direction(3)
    real(wp) :: frame(3, 3)
    real(wp) :: axis(3)
    integer :: k

    frame(:, 3) = normal_direction/norm2(normal_direction)
    k = minloc(abs(frame(:, 3)), dim=1)
    axis = 0.0_wp
    axis(k) = 1.0_wp
    frame(:, 1) = axis - frame(k, 3)*frame(:, 3)
    frame(:, 1) = frame(:, 1)/norm2(frame(:, 1))
    frame(:, 2) = [frame(2, 3)*frame(3, 1) - frame(3, 3)*frame(2, 1), &
                   frame(3, 3)*frame(1, 1) - frame(1, 3)*frame(3, 1), &
                   frame(1, 3)*frame(2, 1) - frame(2, 3)*frame(1, 1)]
  end function tangent_frame

  !> Mark the part nodes (part numbering) on an edge that only one cell of the part uses, or
  !> three and more (a junction of the surface: no side of it is interior). Edges are bucketed
  !> by their smaller node so matching stays linear.
  subroutine find_boundary_edge_nodes(shell_nodes, cells, node_local, node_count, on_boundary)
    integer, intent(in) :: shell_nodes(:, :), cells(:), node_local(:), node_count
    logical, allocatable, intent(out) :: on_boundary(:)
    integer, allocatable :: edge_key(:, :), bucket_offsets(:), bucket_edges(:), fill(:), uses(:)
    integer :: edge_count, e, k, a, first, second, bucket, corners, low, high

    allocate (edge_key(2, 4*size(cells)))
    edge_count = 0
    do k = 1, size(cells)
      corners = corner_count(shell_nodes(:, cells(k)))
      do a = 1, corners
        low = node_local(shell_nodes(a, cells(k)))
        high = node_local(shell_nodes(modulo(a, corners) + 1, cells(k)))
        edge_count = edge_count + 1
        edge_key(:, edge_count) = [min(low, high), max(low, high)]
      end do
    end do
    allocate (bucket_offsets(node_count + 1), fill(node_count), bucket_edges(edge_count), uses(edge_count))
    bucket_offsets = 0
    do e = 1, edge_count
      bucket_offsets(edge_key(1, e) + 1) = bucket_offsets(edge_key(1, e) + 1) + 1
    end do
    bucket_offsets(1) = 1
    do k = 1, node_count
      bucket_offsets(k + 1) = bucket_offsets(k + 1) + bucket_offsets(k)
    end do
    fill = bucket_offsets(1:node_count)
    do e = 1, edge_count
      bucket_edges(fill(edge_key(1, e))) = e
      fill(edge_key(1, e)) = fill(edge_key(1, e)) + 1
    end do
    uses = 1
    do bucket = 1, node_count
      do first = bucket_offsets(bucket), bucket_offsets(bucket + 1) - 1
        do second = first + 1, bucket_offsets(bucket + 1) - 1
          if (edge_key(2, bucket_edges(first)) == edge_key(2, bucket_edges(second))) then
            uses(bucket_edges(first)) = uses(bucket_edges(first)) + 1
            uses(bucket_edges(second)) = uses(bucket_edges(second)) + 1
          end if
        end do
      end do
    end do
    allocate (on_boundary(node_count))
    on_boundary = .false.
    do e = 1, edge_count
      if (uses(e) /= 2) on_boundary(edge_key(:, e)) = .true.
    end do
  end subroutine find_boundary_edge_nodes
end module efg_shell_supports
