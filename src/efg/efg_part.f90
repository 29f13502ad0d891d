!> The precomputed data of one meshfree (EFG) part: everything the explicit update needs,
!> built once on the undeformed background mesh (Lagrangian kernel).
!>
!> Nodes of the part are Gamma nodes (on the part's boundary surface: free surface, interface
!> with FE parts, essential boundaries; they keep FE functions and their unknowns are nodal
!> displacements) or interior particles (their unknowns are generalized displacements).
!> Each background cell holds integration points (8 sub-cells for the local boundary
!> integration, 8 Gauss points for the Gauss variant). For every point the compressed list of
!> (node, smoothed gradient) pairs gives
!>   Fbar = I + sum over pairs of d(node) (x) gradient,
!>   f(node) += W P gradient      (P the first Piola-Kirchhoff stress),
!> see ../../docs/efg.md and the formulation (Wang et al. 2009, eqs. 19-34).
module efg_part
  use kinds, only: wp
  implicit none
  private

  public :: efg_part_t

  type :: efg_part_t
    integer :: part = 0                          !< index into model%parts
    integer :: material = 0                      !< index into model%materials
    ! nodes of the part
    integer, allocatable :: gamma_nodes(:)       !< node indices of the Gamma nodes
    integer, allocatable :: particles(:)         !< node indices of the interior particles
    ! integration points
    integer, allocatable :: point_cell(:)        !< model solid index of each point's background cell
    real(wp), allocatable :: point_volume(:)     !< W_g, reference volume of each point
    real(wp), allocatable :: point_length(:)     !< characteristic length (L = V / A_max) of its cell
    integer, allocatable :: point_offsets(:)     !< pairs of point g: point_offsets(g) : point_offsets(g+1)-1
    integer, allocatable :: pair_node(:)         !< node index of each pair
    real(wp), allocatable :: pair_gradient(:, :) !< (3, pairs): smoothed gradient of that node's function
    ! row-sum lumped mass, as a volume share: m(node) += density * mass_volume(k)
    integer, allocatable :: mass_node(:)         !< node indices (each node of the part once)
    real(wp), allocatable :: mass_volume(:)      !< sum over points of Psi_node(X_g) W_g
    ! physical displacement of interior particles (eq. 16):
    !   uhat(particles(j)) = sum over k in transform_offsets(j) : transform_offsets(j+1)-1
    !                        of transform_value(k) * d(transform_node(k))
    integer, allocatable :: transform_offsets(:)
    integer, allocatable :: transform_node(:)
    real(wp), allocatable :: transform_value(:)
    ! set-up figures
    real(wp) :: setup_seconds = 0.0_wp
    integer :: singular_moment_points = 0        !< points whose moment matrix was rank-deficient
  end type efg_part_t
end module efg_part
