!> Which hexahedra sit at a corner or an edge of the solid mesh, found once before the first
!> cycle from the solid angle that the solids fill around each node.
!>
!> The stable step of a solid is LS-DYNA's rule L / (Q + sqrt(Q^2 + c^2)) and, for the exposed
!> elements found here, also the element's eigenvalue bound (element_time_step). The rule is
!> the critical step of a regular mesh's interior, but not of a free element: its volumetric
!> mode (every node out along its diagonal) is faster. In a mesh, neighbours share the nodes and
!> hold that mode back except where the solids leave a node much room: the lumped-mass
!> eigenvalues of free meshes of cubes put the critical step at 0.82-0.86 L / c for nu = 0.49,
!> the fastest mode at the mesh's corners, and with the corners held, edges alone at 0.95; a
!> flat free surface stays above L / c (1.03-1.06), like the interior (docs/solver.md, "Time
!> step and mass scaling"). The solid angle filled at a node is 4 pi inside, 2 pi on a flat or
!> gently curved surface, pi on a right-angled edge and pi / 2 at the corner of a box; a node
!> below `exposed_solid_angle` (an edge sharper than 157.5 degrees) exposes every element
!> around it. Every solid counts (finite element, meshfree and rigid parts alike); shells,
!> contact, constraints and symmetry planes do not, so an element held only by them stays
!> exposed (the safe side).
module solid_exposure
  use kinds, only: wp
  implicit none
  private

  public :: exposed_elements

  real(wp), parameter :: pi = 3.14159265358979323846_wp
  !> A node where the solids fill less than this solid angle exposes its elements: 7 pi / 4,
  !> the solid angle of an edge of 157.5 degrees (a cylinder meshed with fewer than 16
  !> elements around is exposed all along).
  real(wp), parameter :: exposed_solid_angle = 1.75_wp*pi
  !> The three corners joined to each corner by an edge of the hexahedron (LS-DYNA's order).
  integer, parameter :: edge_neighbours(3, 8) = reshape([2, 4, 5, 3, 1, 6, 4, 2, 7, 1, 3, 8, &
                                                         8, 6, 1, 5, 7, 2, 6, 8, 3, 7, 5, 4], [3, 8])

contains

  !> exposed(e) is true when solid e (column e of `solid_nodes`, nodes as columns of
  !> `coordinates`) has a node around which all solids together fill less than
  !> exposed_solid_angle. Each element contributes at each corner the solid angle of the
  !> trihedron of its three edges there (Van Oosterom & Strackee, IEEE Trans. Biomed. Eng. 30
  !> (1983) 125); the trihedra of the elements around a node share their faces' planes at the
  !> node, so they add up to 4 pi inside a mesh and to 2 pi on a flat surface. The corners of a
  !> degenerate element (a repeated node: wedges and tetrahedra given as hexahedra) add
  !> nothing, which only exposes more.
  function exposed_elements(coordinates, solid_nodes) result(exposed)
    real(wp), intent(in) :: coordinates(:, :)
    integer, intent(in) :: solid_nodes(:, :)
    logical, allocatable :: exposed(:)
    real(wp), allocatable :: filled(:)
    real(wp) :: a(3), b(3), c(3), length_a, length_b, length_c, triple, denominator
    integer :: solid, corner, node

    allocate (filled(size(coordinates, 2)), exposed(size(solid_nodes, 2)))
    filled = 0.0_wp
    do solid = 1, size(solid_nodes, 2)
      do corner = 1, 8
        node = solid_nodes(corner, solid)
        a = coordinates(:, solid_nodes(edge_neighbours(1, corner), solid)) - coordinates(:, node)
        b = coordinates(:, solid_nodes(edge_neighbours(2, corner), solid)) - coordinates(:, node)
        c = coordinates(:, solid_nodes(edge_neighbours(3, corner), solid)) - coordinates(:, node)
        length_a = norm2(a)
        length_b = norm2(b)
        length_c = norm2(c)
        triple = abs(a(1)*(b(2)*c(3) - b(3)*c(2)) + a(2)*(b(3)*c(1) - b(1)*c(3)) + a(3)*(b(1)*c(2) - b(2)*c(1)))
        denominator = length_a*length_b*length_c + dot_product(a, b)*length_c + dot_product(a, c)*length_b &
                      + dot_product(b, c)*length_a
        ! a degenerate corner (a zero edge) has triple = denominator = 0 and adds nothing
        ! (atan2(0, 0) is not defined)
        if (triple > 0.0_wp .or. denominator /= 0.0_wp) &
          filled(node) = filled(node) + 2.0_wp*atan2(triple, denominator)
      end do
    end do
    do solid = 1, size(solid_nodes, 2)
      exposed(solid) = any(filled(solid_nodes(:, solid)) < exposed_solid_angle)
    end do
  end function exposed_elements
end module solid_exposure
