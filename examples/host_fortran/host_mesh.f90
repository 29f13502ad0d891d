!> The host's mesh: a block of hexahedra in LS-DYNA's node order, regular or with its interior
!> nodes moved by a reproducible integer generator. The C host (examples/host_c) builds the same
!> mesh with the same integer arithmetic, so the two hosts run the same part.
module host_mesh
  use, intrinsic :: iso_c_binding, only: c_double, c_int, c_int64_t
  implicit none
  private

  public :: host_mesh_t, block_mesh, node_index, on_block_boundary

  !> Nodes and hexahedra of a block of cells(1) x cells(2) x cells(3) cubes of edge cell_size.
  type :: host_mesh_t
    integer :: cells(3) = 0
    real(c_double) :: cell_size = 1.0_c_double
    real(c_double), allocatable :: coordinates(:, :)   !< (3, nodes)
    integer(c_int), allocatable :: hexahedra(:, :)     !< (8, cells), 1-based node indices
  end type host_mesh_t

contains

  !> The node at grid position (i, j, k), 0-based positions, 1-based index (x runs fastest).
  pure integer function node_index(mesh, i, j, k)
    type(host_mesh_t), intent(in) :: mesh
    integer, intent(in) :: i, j, k
    node_index = 1 + i + (mesh%cells(1) + 1)*(j + (mesh%cells(2) + 1)*k)
  end function node_index

  !> Whether grid position (i, j, k) lies on the block's outer surface.
  pure logical function on_block_boundary(mesh, i, j, k)
    type(host_mesh_t), intent(in) :: mesh
    integer, intent(in) :: i, j, k
    on_block_boundary = i == 0 .or. j == 0 .or. k == 0 .or. i == mesh%cells(1) .or. j == mesh%cells(2) &
                        .or. k == mesh%cells(3)
  end function on_block_boundary

  !> A block of cubes of edge `cell_size`; each interior node moves by up to `perturbation`
  !> times the cell size in each direction, in steps of 1/256 of that range (the coordinates stay
  !> short binary fractions, which a keyword deck writes exactly). `seed` starts the generator
  !> state = (1103515245 state + 12345) mod 2^31.
  subroutine block_mesh(cells, cell_size, perturbation, seed, mesh)
    integer, intent(in) :: cells(3)
    real(c_double), intent(in) :: cell_size, perturbation
    integer, intent(in) :: seed
    type(host_mesh_t), intent(out) :: mesh
    integer :: i, j, k, direction, node, element
    integer(c_int64_t) :: state
    real(c_double) :: fraction

    mesh%cells = cells
    mesh%cell_size = cell_size
    allocate (mesh%coordinates(3, product(cells + 1)), mesh%hexahedra(8, product(cells)))
    state = int(seed, c_int64_t)
    do k = 0, cells(3)
      do j = 0, cells(2)
        do i = 0, cells(1)
          node = node_index(mesh, i, j, k)
          mesh%coordinates(:, node) = cell_size*real([i, j, k], c_double)
          if (on_block_boundary(mesh, i, j, k)) cycle
          do direction = 1, 3
            state = modulo(1103515245_c_int64_t*state + 12345_c_int64_t, 2147483648_c_int64_t)
            fraction = real(state/8388608_c_int64_t, c_double)/256.0_c_double
            mesh%coordinates(direction, node) = mesh%coordinates(direction, node) &
                                                + perturbation*cell_size*(2.0_c_double*fraction - 1.0_c_double)
          end do
        end do
      end do
    end do
    do k = 0, cells(3) - 1
      do j = 0, cells(2) - 1
        do i = 0, cells(1) - 1
          element = 1 + i + cells(1)*(j + cells(2)*k)
          mesh%hexahedra(:, element) = [node_index(mesh, i, j, k), node_index(mesh, i + 1, j, k), &
                                        node_index(mesh, i + 1, j + 1, k), node_index(mesh, i, j + 1, k), &
                                        node_index(mesh, i, j, k + 1), node_index(mesh, i + 1, j, k + 1), &
                                        node_index(mesh, i + 1, j + 1, k + 1), node_index(mesh, i, j + 1, k + 1)]
        end do
      end do
    end do
  end subroutine block_mesh
end module host_mesh
