!> The precomputed data of one meshfree (EFG) part: everything the explicit update needs,
!> built once on the undeformed background mesh (Lagrangian kernel).
!>
!> Nodes of the part are Gamma nodes (on the part's boundary surface: free surface, interface
!> with FE parts, essential boundaries; they keep FE functions and their unknowns are nodal
!> displacements) or interior particles (their unknowns are generalized displacements).
!> Each background cell holds integration points: 8 sub-cells for the local boundary integration
!> (IDIM 1), 8 Gauss points for the 2x2x2 Gauss variant (IDIM 2), 64 Gauss points for the
!> conventional 4x4x4 Gauss variant (IDIM 4, linear static verification). The points of one cell
!> are consecutive and the cells come in ascending order; every point of a cell has the same
!> `point_cell` and `point_length`, and the `point_volume` of a cell's points add up to its
!> reference volume whatever the variant. For every point the compressed list of (node,
!> gradient) pairs gives
!>   Fbar = I + sum over pairs of d(node) (x) gradient,
!>   f(node) += W P gradient      (P the first Piola-Kirchhoff stress),
!> see ../../docs/efg.md and the formulation (Wang et al. 2009, eqs. 19-34).
!>
!> Essential conditions u = g on the surface for a static solver: a node J of `surface_nodes`
!> with `surface_rows(j) = 0` is a Gamma node, u_J = d_J (impose directly); otherwise (IEBT 1)
!> it is a particle whose physical displacement is row surface_rows(j) of the transformation,
!> u_J = sum_k transform_value(k) d(transform_node(k)) = g_J: one linear constraint per
!> component (or, with every row, the full transformation u = Lambda d of all nodes).
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
                                                 !< (IEBT 1: every node of the part)
    integer, allocatable :: surface_nodes(:)     !< node indices on the part's boundary surface,
                                                 !< ascending (= gamma_nodes for IEBT 3)
    integer, allocatable :: surface_rows(:)      !< transformation row (particle number) of each
                                                 !< surface node; 0 for a Gamma node (u = d)
    ! integration points
    integer, allocatable :: point_cell(:)        !< model solid index of each point's background cell
    real(wp), allocatable :: point_volume(:)     !< W_g, reference volume of each point
    real(wp), allocatable :: point_length(:)     !< characteristic length (L = V / A_max) of its cell
    integer, allocatable :: point_offsets(:)     !< pairs of point g: point_offsets(g) : point_offsets(g+1)-1
    integer, allocatable :: pair_node(:)         !< node index of each pair
    real(wp), allocatable :: pair_gradient(:, :) !< (3, pairs): gradient of that node's function
                                                 !< (smoothed: IDIM 1; direct: IDIM 2, 4)
    ! row-sum lumped mass, as a volume share: m(node) += density * mass_volume(k)
    integer, allocatable :: mass_node(:)         !< node indices (each node of the part once)
    real(wp), allocatable :: mass_volume(:)      !< sum over points of Psi_node(X_g) W_g
    ! physical displacement of interior particles (eq. 16), one row per particle (IEBT 1: per
    ! node of the part):
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
