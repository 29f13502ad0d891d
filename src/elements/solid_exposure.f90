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
!> exposed (the safe side). A degenerate element (repeated nodes) adds at each of its nodes the
!> solid angle of its own shape there (degenerate_solid_angles): tetrahedra and wedges fill a
!> mesh's interior like hexahedra, and only those at its corners and edges are exposed.
module solid_exposure
  use kinds, only: wp
  use hex8_geometry, only: distinct_corner_count, tetrahedron_corner_order
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
      if (distinct_corner_count(solid_nodes(:, solid)) < 8) then
        call degenerate_solid_angles(coordinates, solid_nodes(:, solid), filled)
        cycle
      end if
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

  !> Adds to `filled` the solid angle a degenerate element fills at each of its nodes. Its
  !> edges are the hexahedron's edges between different nodes (a tetrahedron first put in the
  !> form N1 N2 N3 N3 N4 N4 N4 N4). A node with three neighbours along them (every node of a
  !> tetrahedron or a wedge, a pyramid's base) sits at a trihedron; a pyramid's apex (four
  !> neighbours, in the order around its base) at two trihedra that split the base along a
  !> diagonal. Any other shape adds nothing at that node (it stays exposed: the safe side).
  subroutine degenerate_solid_angles(coordinates, element_nodes, filled)
    real(wp), intent(in) :: coordinates(:, :)
    integer, intent(in) :: element_nodes(8)
    real(wp), intent(inout) :: filled(:)
    integer :: nodes(8), order(8), neighbour(4), found, corner, k, other, node
    call tetrahedron_corner_order(element_nodes, coordinates(:, element_nodes), order)
    nodes = element_nodes(order)
    do corner = 1, 8
      node = nodes(corner)
      if (any(nodes(1:corner - 1) == node)) cycle
      ! the distinct neighbours of this node, over all its corners, in corner order
      found = 0
      do other = 1, 8
        if (nodes(other) /= node) cycle
        do k = 1, 3
          if (nodes(edge_neighbours(k, other)) == node) cycle
          if (any(neighbour(1:found) == nodes(edge_neighbours(k, other)))) cycle
          if (found == 4) then
            found = 5
            exit
          end if
          found = found + 1
          neighbour(found) = nodes(edge_neighbours(k, other))
        end do
        if (found > 4) exit
      end do
      if (found == 3) then
        filled(node) = filled(node) + trihedron_angle(coordinates(:, node), coordinates(:, neighbour(1)), &
                                                      coordinates(:, neighbour(2)), coordinates(:, neighbour(3)))
      else if (found == 4) then
        ! the apex of a pyramid: neighbours in the order of corners 1-4 go around the base
        filled(node) = filled(node) + trihedron_angle(coordinates(:, node), coordinates(:, neighbour(1)), &
                                                      coordinates(:, neighbour(2)), coordinates(:, neighbour(3))) &
                       + trihedron_angle(coordinates(:, node), coordinates(:, neighbour(1)), &
                                         coordinates(:, neighbour(3)), coordinates(:, neighbour(4)))
      end if
    end do
  end subroutine degenerate_solid_angles

  !> Solid angle of the trihedron at `apex` spanned by the points p, q, r (Van Oosterom &
  !> Strackee); 0 for a flat one.
  pure real(wp) function trihedron_angle(apex, p, q, r)
    real(wp), intent(in) :: apex(3), p(3), q(3), r(3)
    real(wp) :: a(3), b(3), c(3), length_a, length_b, length_c, triple, denominator
    a = p - apex
    b = q - apex
    c = r - apex
    length_a = norm2(a)
    length_b = norm2(b)
    length_c = norm2(c)
    triple = abs(a(1)*(b(2)*c(3) - b(3)*c(2)) + a(2)*(b(3)*c(1) - b(1)*c(3)) + a(3)*(b(1)*c(2) - b(2)*c(1)))
    denominator = length_a*length_b*length_c + dot_product(a, b)*length_c + dot_product(a, c)*length_b &
                  + dot_product(b, c)*length_a
    trihedron_angle = 0.0_wp
    if (triple > 0.0_wp .or. denominator /= 0.0_wp) trihedron_angle = 2.0_wp*atan2(triple, denominator)
  end function trihedron_angle
end module solid_exposure
