!> Nodes, node classes and support radii of one meshfree part (formulation sections 1-2).
!>
!> Gamma nodes are the nodes on the part's boundary surface: on a face of a part cell that no
!> other cell of the same part shares (free surface, FE/EFG interface, contact and essential
!> boundaries alike). They keep their trilinear FE functions. Interior particles are the other
!> nodes of the part and carry MLS functions. With the full transformation (IEBT 1) every node is
!> a particle; the surface nodes are still listed (`surface_nodes`), because that is where a
!> static solver imposes the essential conditions through the transformation.
!>
!> Support radius (section 2): a_Ik = DX_k * max |X_Jk - X_Ik| over every node J that shares a
!> cell of the part with I (face and body diagonals included), per direction for the box kernel;
!> a_I = DX * max |X_J - X_I| for the spherical kernel. With this rule each interior vertex of a
!> cell covers the whole cell, which keeps b(X) in the range of M(X) (section 3).
!>
!> Everything here is linear in the number of cells: faces are matched within buckets keyed by
!> their smallest vertex.
module efg_supports
  use kinds, only: wp
  use model, only: model_t, kernel_cubic_sphere
  use efg_cell_geometry, only: cell_faces
  implicit none
  private

  public :: part_supports_t, build_part_supports, build_cell_supports

  !> The nodes of one meshfree part, their classes and the particles' supports.
  type :: part_supports_t
    integer :: kernel = 0                            !< ISPLINE
    logical :: full_transformation = .false.         !< IEBT 1: every node is a particle
    integer, allocatable :: cells(:)                 !< the part's cells, ascending (model solid indices;
                                                     !< build_cell_supports: 1..m)
    integer, allocatable :: nodes(:)                 !< model node indices of the part, ascending
    integer, allocatable :: surface_nodes(:)         !< model node indices on the part's surface, ascending
    integer, allocatable :: gamma_nodes(:)           !< model node indices, ascending
    integer, allocatable :: particles(:)             !< model node indices, ascending
    integer, allocatable :: particle_of_node(:)      !< (model nodes): particle number, 0 for others
    integer, allocatable :: owner_cell(:)            !< (particles): first part cell having it as a vertex
                                                     !< (numbered as `cells`)
    real(wp), allocatable :: particle_coordinates(:, :) !< (3, particles)
    real(wp), allocatable :: particle_radius(:, :)   !< (3, particles): a_Ik (sphere: a_I three times)
  end type part_supports_t

contains

  !> Cells, nodes, Gamma nodes, particles and support radii of part `part` of `model`, with the
  !> section's DX DY DZ, ISPLINE and IEBT: the part's solids handed to build_cell_supports, whose
  !> local cell numbers are turned back into model solid indices (`cells`, `owner_cell`).
  subroutine build_part_supports(model, part, support_scale, kernel, full_transformation, supports)
    type(model_t), intent(in) :: model
    integer, intent(in) :: part
    real(wp), intent(in) :: support_scale(3)
    integer, intent(in) :: kernel
    logical, intent(in) :: full_transformation
    type(part_supports_t), intent(out) :: supports
    integer, allocatable :: cells(:)
    integer :: cell

    cells = pack([(cell, cell=1, size(model%solid_part))], model%solid_part == part)
    call build_cell_supports(model%coordinates, model%solid_nodes(:, cells), support_scale, kernel, &
                             full_transformation, [integer ::], supports)
    supports%cells = cells(supports%cells)
    where (supports%owner_cell > 0) supports%owner_cell = cells(max(supports%owner_cell, 1))
  end subroutine build_part_supports

  !> Cells, nodes, Gamma nodes, particles and support radii of the part made of the cells
  !> `hexahedra(8, m)` (indices into `coordinates(3, :)`, LS-DYNA node order): the cells are
  !> numbered 1..m (`cells`, `owner_cell`), the nodes keep their index into `coordinates`.
  !> The nodes `marked` (indices into `coordinates`) are Gamma nodes besides the part's surface
  !> (a host code's interfaces and supports inside the part); unless `full_transformation`.
  subroutine build_cell_supports(coordinates, hexahedra, support_scale, kernel, full_transformation, marked, &
                                 supports)
    real(wp), intent(in) :: coordinates(:, :)
    integer, intent(in) :: hexahedra(:, :)
    real(wp), intent(in) :: support_scale(3)
    integer, intent(in) :: kernel
    logical, intent(in) :: full_transformation
    integer, intent(in) :: marked(:)
    type(part_supports_t), intent(out) :: supports
    integer, allocatable :: node_local(:)
    logical, allocatable :: on_boundary(:)
    real(wp), allocatable :: extent(:, :)
    integer :: cell, model_node_count, k, count, particle, j, a

    supports%kernel = kernel
    supports%full_transformation = full_transformation
    supports%cells = [(cell, cell=1, size(hexahedra, 2))]
    model_node_count = size(coordinates, 2)

    ! part nodes, ascending, and the model -> part numbering
    allocate (node_local(model_node_count))
    node_local = 0
    do k = 1, size(supports%cells)
      node_local(hexahedra(:, k)) = 1
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

    call find_boundary_nodes(hexahedra, supports%cells, node_local, count, on_boundary)
    ! nodes of the part a caller marks keep FE functions as well
    do k = 1, size(marked)
      if (node_local(marked(k)) > 0) on_boundary(node_local(marked(k))) = .true.
    end do
    ! the surface is kept for the essential conditions of IEBT 1, where it holds no Gamma node
    supports%surface_nodes = pack(supports%nodes, on_boundary)
    if (full_transformation) on_boundary = .false.
    supports%gamma_nodes = pack(supports%nodes, on_boundary)
    supports%particles = pack(supports%nodes, .not. on_boundary)

    allocate (supports%particle_of_node(model_node_count))
    supports%particle_of_node = 0
    do particle = 1, size(supports%particles)
      supports%particle_of_node(supports%particles(particle)) = particle
    end do

    call neighbour_extents(coordinates, hexahedra, supports%cells, node_local, count, kernel, extent)
    allocate (supports%particle_coordinates(3, size(supports%particles)))
    allocate (supports%particle_radius(3, size(supports%particles)))
    do particle = 1, size(supports%particles)
      j = supports%particles(particle)
      supports%particle_coordinates(:, particle) = coordinates(:, j)
      if (kernel == kernel_cubic_sphere) then
        supports%particle_radius(:, particle) = support_scale(1)*extent(1, node_local(j))
      else
        supports%particle_radius(:, particle) = support_scale*extent(:, node_local(j))
      end if
    end do

    ! the cell in which the transformation (eq. 16) of each particle is evaluated
    allocate (supports%owner_cell(size(supports%particles)))
    supports%owner_cell = 0
    do k = 1, size(supports%cells)
      do a = 1, 8
        particle = supports%particle_of_node(hexahedra(a, k))
        if (particle > 0) then
          if (supports%owner_cell(particle) == 0) supports%owner_cell(particle) = k
        end if
      end do
    end do
  end subroutine build_cell_supports

  !> Mark the part nodes (part numbering) that lie on a face of a part cell that no other part
  !> cell shares. Faces are bucketed by their smallest node so matching stays linear.
  subroutine find_boundary_nodes(solid_nodes, cells, node_local, node_count, on_boundary)
    integer, intent(in) :: solid_nodes(:, :), cells(:), node_local(:), node_count
    logical, allocatable, intent(out) :: on_boundary(:)
    integer, allocatable :: face_key(:, :), bucket_offsets(:), bucket_faces(:), fill(:)
    logical, allocatable :: shared(:)
    integer :: face_count, f, k, side, first, second, bucket

    face_count = 6*size(cells)
    allocate (face_key(4, face_count), shared(face_count))
    do k = 1, size(cells)
      do side = 1, 6
        f = 6*(k - 1) + side
        face_key(:, f) = sorted_four(node_local(solid_nodes(cell_faces(:, side), cells(k))))
      end do
    end do

    allocate (bucket_offsets(node_count + 1), fill(node_count))
    bucket_offsets = 0
    do f = 1, face_count
      bucket_offsets(face_key(1, f) + 1) = bucket_offsets(face_key(1, f) + 1) + 1
    end do
    bucket_offsets(1) = 1
    do k = 1, node_count
      bucket_offsets(k + 1) = bucket_offsets(k + 1) + bucket_offsets(k)
    end do
    allocate (bucket_faces(face_count))
    fill = bucket_offsets(1:node_count)
    do f = 1, face_count
      bucket_faces(fill(face_key(1, f))) = f
      fill(face_key(1, f)) = fill(face_key(1, f)) + 1
    end do

    shared = .false.
    do bucket = 1, node_count
      do first = bucket_offsets(bucket), bucket_offsets(bucket + 1) - 1
        do second = first + 1, bucket_offsets(bucket + 1) - 1
          if (all(face_key(:, bucket_faces(first)) == face_key(:, bucket_faces(second)))) then
            shared(bucket_faces(first)) = .true.
            shared(bucket_faces(second)) = .true.
          end if
        end do
      end do
    end do

    allocate (on_boundary(node_count))
    on_boundary = .false.
    do f = 1, face_count
      if (.not. shared(f)) on_boundary(face_key(:, f)) = .true.
    end do
  end subroutine find_boundary_nodes

  !> Largest coordinate distance (box: per direction) or distance (sphere: in component 1) from
  !> each part node to the nodes that share a part cell with it.
  subroutine neighbour_extents(coordinates, solid_nodes, cells, node_local, node_count, kernel, extent)
    real(wp), intent(in) :: coordinates(:, :)
    integer, intent(in) :: solid_nodes(:, :), cells(:), node_local(:), node_count, kernel
    real(wp), allocatable, intent(out) :: extent(:, :)
    real(wp) :: difference(3)
    integer :: k, a, b, node_a, node_b

    allocate (extent(3, node_count))
    extent = 0.0_wp
    do k = 1, size(cells)
      do a = 1, 8
        node_a = solid_nodes(a, cells(k))
        do b = 1, 8
          node_b = solid_nodes(b, cells(k))
          difference = abs(coordinates(:, node_b) - coordinates(:, node_a))
          if (kernel == kernel_cubic_sphere) then
            extent(1, node_local(node_a)) = max(extent(1, node_local(node_a)), norm2(difference))
          else
            extent(:, node_local(node_a)) = max(extent(:, node_local(node_a)), difference)
          end if
        end do
      end do
    end do
  end subroutine neighbour_extents

  !> The four values in ascending order.
  pure function sorted_four(values) result(sorted)
    integer, intent(in) :: values(4)
    integer :: sorted(4)
    integer :: i, j, held

    sorted = values
    do i = 2, 4
      held = sorted(i)
      j = i - 1
      do while (j >= 1)
        if (sorted(j) <= held) exit
        sorted(j + 1) = sorted(j)
        j = j - 1
      end do
      sorted(j + 1) = held
    end do
  end function sorted_four
end module efg_supports
