!> Which hexahedra sit at a corner or an edge of the solid mesh, found once before the first
!> cycle from the number of solids around each node.
!>
!> The stable step of a solid is LS-DYNA's rule L / (Q + sqrt(Q^2 + c^2)) and, for the exposed
!> elements found here, also the element's eigenvalue bound (element_time_step). The rule is
!> the critical step of a regular mesh's interior, but not of a free element: its volumetric
!> mode (every node out along its diagonal) is faster. In a mesh, neighbours share the nodes and
!> hold that mode back except where few solids meet: the lumped-mass eigenvalues of free meshes
!> of cubes put the critical step at 0.82-0.86 L / c for nu = 0.49 with the fastest mode at the
!> mesh's corners, and edges alone (corners held) at 0.95; a flat free surface (its nodes shared
!> by four solids) stays above L / c (1.03-1.06), like the interior (docs/solver.md, "Time step
!> and mass scaling"). An element is exposed when one of its nodes is shared by fewer than four
!> solids: a convex corner (one solid) or edge (two) of the mesh, an irregular surface node
!> (three), and every element of a model of one or two elements or a single row. Every solid
!> counts (finite element, meshfree and rigid parts alike); shells, contact and constraints do
!> not, so an element held only by them stays exposed (the safe side).
module solid_exposure
  implicit none
  private

  public :: exposed_elements

  !> Solids around a node of a flat free surface of a regular mesh; fewer mark a corner or edge.
  integer, parameter, public :: surface_node_solids = 4

contains

  !> exposed(e) is true when solid e (column e of `solid_nodes`, node indices 1..node_count) has
  !> a node shared by fewer than surface_node_solids solids (a node repeated within one solid,
  !> as in wedges and tetrahedra given as hexahedra, counts that solid once).
  function exposed_elements(node_count, solid_nodes) result(exposed)
    integer, intent(in) :: node_count
    integer, intent(in) :: solid_nodes(:, :)
    logical, allocatable :: exposed(:)
    integer, allocatable :: solids_around(:)
    integer :: solid, corner, node

    allocate (solids_around(node_count), exposed(size(solid_nodes, 2)))
    solids_around = 0
    do solid = 1, size(solid_nodes, 2)
      do corner = 1, 8
        if (any(solid_nodes(1:corner - 1, solid) == solid_nodes(corner, solid))) cycle
        node = solid_nodes(corner, solid)
        solids_around(node) = solids_around(node) + 1
      end do
    end do
    do solid = 1, size(solid_nodes, 2)
      exposed(solid) = any(solids_around(solid_nodes(:, solid)) < surface_node_solids)
    end do
  end function exposed_elements
end module solid_exposure
