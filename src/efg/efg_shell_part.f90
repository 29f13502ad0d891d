!> The precomputed data of one meshfree (EFG) shell part (*SECTION_SHELL ELFORM 41): everything
!> the explicit update needs, built once on the undeformed background quadrilateral mesh
!> (Lagrangian kernel), the shells' counterpart of efg_part.
!>
!> Nodes of the part are Gamma nodes (on the part's boundary edges: free edges, edges shared with
!> FE shells or other parts, nodes with supports or constraints; they keep their bilinear FE shell
!> functions and their unknowns are nodal displacements and rotations) or interior particles
!> (their unknowns are generalized displacements and rotations).
!>
!> Every background cell (a shell element of the deck) has a reference frame `cell_frame`
!> (shell_cell_frame of its undeformed corners) and two kinds of integration points:
!> * membrane and bending points: one per sub-cell (4 per quadrilateral, 3 per triangle), with
!>   smoothed gradients (local boundary integration over the sub-cell's edges) of every node's
!>   function, in the cell's reference frame (components along e1 and e2);
!> * one point per cell at its centre, with the functions' values and gradients there. The
!>   explicit update takes its transverse shear from the cells' physical corner and
!>   edge-midpoint values instead (an assumed strain, efg_shell_forces: the MLS w of a linear
!>   basis gives a Kirchhoff mode a spurious shear); it uses these points' pairs only for the
!>   nodes' rotary-inertia areas.
!> The points of one cell are consecutive and the cells come in ascending order.
module efg_shell_part
  use kinds, only: wp
  implicit none
  private

  public :: efg_shell_part_t, shell_cell_frame

  type :: efg_shell_part_t
    integer :: part = 0                          !< index into model%parts
    integer :: material = 0                      !< index into model%materials
    ! nodes of the part
    integer, allocatable :: gamma_nodes(:)       !< node indices of the Gamma nodes, ascending
    integer, allocatable :: particles(:)         !< node indices of the interior particles, ascending
    ! background cells (model shell indices, ascending)
    integer, allocatable :: cells(:)             !< model shell index of each cell
    real(wp), allocatable :: cell_frame(:, :, :) !< (3, 3, cells): frame(:, a, c) = e_a of cell c, undeformed
    real(wp), allocatable :: cell_area(:)        !< reference area of each cell
    real(wp), allocatable :: cell_thickness(:)   !< mean of the cell's corner thicknesses
    ! membrane and bending points (sub-cells)
    integer, allocatable :: point_cell(:)        !< cell number (index into cells) of each point
    real(wp), allocatable :: point_area(:)       !< W_g, reference area of each sub-cell
    integer, allocatable :: point_offsets(:)     !< pairs of point g: point_offsets(g) : point_offsets(g+1)-1
    integer, allocatable :: pair_node(:)         !< node index of each pair, ascending within a point
    real(wp), allocatable :: pair_gradient(:, :) !< (2, pairs): smoothed gradient along e1, e2 of the cell
    ! centre points (one per cell; rotary-inertia areas, see above)
    integer, allocatable :: shear_offsets(:)     !< pairs of cell c: shear_offsets(c) : shear_offsets(c+1)-1
    integer, allocatable :: shear_node(:)        !< node index of each pair, ascending within a cell
    real(wp), allocatable :: shear_value(:)      !< Psi_node at the cell centre
    real(wp), allocatable :: shear_gradient(:, :) !< (2, pairs): its gradient along e1, e2 of the cell
    ! edge midpoints of the cells (transverse shear, efg_shell_forces): the physical value at the
    ! midpoint of edge e (corner e to the next corner; a triangle's edge 3 goes back to corner 1
    ! and its row 4 is empty) of cell c is the sum over midpoint_offsets(4 (c - 1) + e) :
    ! midpoint_offsets(4 (c - 1) + e + 1) - 1 of midpoint_value times the solver's value at
    ! midpoint_node
    integer, allocatable :: midpoint_offsets(:)
    integer, allocatable :: midpoint_node(:)
    real(wp), allocatable :: midpoint_value(:)
    ! row-sum lumped mass: m(node) += density * mass_volume(k) (sum over points of Psi W t)
    integer, allocatable :: mass_node(:)         !< node indices (each node of the part once)
    real(wp), allocatable :: mass_volume(:)
    ! physical values of interior particles (eq. 16), one row per particle:
    !   uhat(particles(j)) = sum over k in transform_offsets(j) : transform_offsets(j+1)-1
    !                        of transform_value(k) * d(transform_node(k))
    ! (the same rows turn generalized rotations into physical ones)
    integer, allocatable :: transform_offsets(:)
    integer, allocatable :: transform_node(:)
    real(wp), allocatable :: transform_value(:)
    ! set-up figures
    real(wp) :: setup_seconds = 0.0_wp
    integer :: singular_moment_points = 0        !< points whose moment matrix was rank-deficient
  end type efg_shell_part_t

contains

  !> The corotational frame of a shell cell from its corner positions (3, 4): e3 normal to the
  !> diagonals, e1 along side 1-2 projected on the cell's plane, e2 = e3 x e1 (the
  !> Belytschko-Tsay frame; a triangle repeats corner 3). frame(:, a) = e_a. The reference frames
  !> of the set-up and the current frames of the explicit update both come from here, so that
  !> the undeformed state has no strain.
  pure function shell_cell_frame(corners) result(frame)
    real(wp), intent(in) :: corners(3, 4)
    real(wp) :: frame(3, 3)
    real(wp) :: diagonal_1(3), diagonal_2(3), side(3)

    diagonal_1 = corners(:, 3) - corners(:, 1)
    diagonal_2 = corners(:, 4) - corners(:, 2)
    frame(:, 3) = cross(diagonal_1, diagonal_2)
    frame(:, 3) = frame(:, 3) / norm2(frame(:, 3))
    side = corners(:, 2) - corners(:, 1)
    frame(:, 1) = side - dot_product(side, frame(:, 3)) * frame(:, 3)
    frame(:, 1) = frame(:, 1) / norm2(frame(:, 1))
    frame(:, 2) = cross(frame(:, 3), frame(:, 1))
  end function shell_cell_frame

  pure function cross(a, b) result(c)
    real(wp), intent(in) :: a(3), b(3)
    real(wp) :: c(3)
    c = [a(2) * b(3) - a(3) * b(2), a(3) * b(1) - a(1) * b(3), a(1) * b(2) - a(2) * b(1)]
  end function cross
end module efg_shell_part
