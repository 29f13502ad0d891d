!> What a run reports about itself: termination status, counts and the time per phase
!> (the `/run` and `/timing` attributes of results.h5, and the end-of-run summary).
module run_summary
  use kinds, only: wp
  implicit none
  private

  public :: run_summary_t, partition_summary_t

  character(len=*), parameter, public :: status_normal = "normal termination"
  character(len=*), parameter, public :: status_error = "error termination"

  !> The domain partition of an MPI run, or of `partition=N` (domain_partition): what the
  !> set-up prints and results.h5 (/run/partition) and d3hsp record. Per rank (0-based, index
  !> rank + 1) and per element of the model's lists; empty for one rank.
  type :: partition_summary_t
    integer :: rank_count = 1
    logical :: by_metis = .false.                !< METIS k-way (else one rank, or the contiguous split)
    !> "metis_kway_elements", "metis_kway_blocks" (domain_partition's choose_owners), "contiguous",
    !> "one rank"
    character(len=24) :: method = "one rank"
    !> the element kinds counted per rank, in engine order ("solid", "shell", "meshfree", ...)
    character(len=16), allocatable :: kind_names(:)
    integer, allocatable :: rank_elements(:, :)  !< (kinds, ranks) elements owned (meshfree: cells)
    integer, allocatable :: rank_blocks(:)       !< blocks owned
    integer, allocatable :: rank_ghost_blocks(:) !< blocks computed but owned by another rank
    !> (kinds, ranks) blocks computed: owned and ghost blocks of a kind that shares its blocks
    !> out (element_group's distributes_blocks), every block of one computed whole on every rank
    integer, allocatable :: rank_computed_blocks(:, :)
    integer, allocatable :: kind_blocks(:)       !< (kinds) the blocks of each kind, all ranks together
    integer, allocatable :: rank_owned_nodes(:)  !< nodes owned (their forces sent each cycle)
    !> nodes on the domain's interface: touched by a block it owns and by a block another rank
    !> owns (a neighbour exchange would send or receive these each cycle)
    integer, allocatable :: rank_interface_nodes(:)
    real(wp), allocatable :: rank_cost(:)        !< estimated ns per cycle of its owned blocks
    real(wp), allocatable :: rank_computed_cost(:) !< the same with its ghost blocks
    real(wp) :: imbalance = 1.0_wp               !< max / mean of rank_cost
    real(wp) :: computed_imbalance = 1.0_wp      !< max / mean of rank_computed_cost
    !> rank computing each model solid, shell and beam (-1: in no block, e.g. of a rigid part:
    !> every rank does the rigid bodies)
    integer, allocatable :: solid_rank(:), shell_rank(:), beam_rank(:)
    integer, allocatable :: node_rank(:)         !< rank owning each node (the model's order)
  end type partition_summary_t

  type :: run_summary_t
    character(len=:), allocatable :: status      !< status_normal or status_error
    character(len=:), allocatable :: message     !< empty, or the error message
    !> every warning the run printed (deck, set-up), one per line as printed: /run/warnings
    character(len=:), allocatable :: warnings
    real(wp) :: end_time = 0.0_wp                !< simulation time reached
    integer :: cycles = 0
    integer :: threads = 1
    ! seconds
    real(wp) :: wall_s = 0.0_wp, setup_s = 0.0_wp, output_s = 0.0_wp
    real(wp) :: fe_solid_s = 0.0_wp, fe_shell_s = 0.0_wp, efg_s = 0.0_wp, contact_s = 0.0_wp
    real(wp) :: efg_setup_s = 0.0_wp             !< part of setup_s: EFG neighbours, shape functions, gradients
    ! sizes
    integer :: fe_elements = 0, efg_particles = 0, dofs_total = 0, dofs_efg = 0
    integer :: fe_solids = 0, fe_shells = 0      !< fe_elements = fe_solids + fe_shells + fe_beams
    integer :: fe_beams = 0                      !< beam elements (beam_group)
    real(wp) :: fe_beam_s = 0.0_wp               !< seconds of the beams' force calls
    ! meshfree shells (efg_shell_group): background cells, interior particles, their dofs
    ! (translations and rotations of the part's nodes), set-up and force-call seconds
    integer :: efg_shell_cells = 0, efg_shell_particles = 0, dofs_efg_shell = 0
    real(wp) :: efg_shell_setup_s = 0.0_wp, efg_shell_s = 0.0_wp
    integer :: failed_beams = 0                  !< beams failed by their material (*MAT_SPOTWELD)
    ! FE solids folded inside out at a corner (checked at each state)
    integer :: tangled_solids = 0                !< at the last state
    real(wp) :: worst_corner_jacobian_ratio = 1.0_wp !< smallest corner Jacobian ratio of the run
    integer :: worst_corner_jacobian_element = 0 !< its solid ID (0: no FE solid)
    !> seconds of each phase of the explicit cycle (/timing phase_<name>_s; none for a static run)
    character(len=16), allocatable :: phase_names(:)
    real(wp), allocatable :: phase_seconds(:)
    !> a distributed run: every rank's seconds (rank_column_names' columns, ranks): the phases,
    !> then the nodal exchange (accelerations) and the wait for the slowest rank before it (outside the phases),
    !> the contact pair exchange and the wait before it (inside the contact phase)
    character(len=24), allocatable :: rank_column_names(:)
    real(wp), allocatable :: rank_seconds(:, :)
    type(partition_summary_t) :: partition       !< MPI domains (one rank: rank_count 1, nothing else)
  end type run_summary_t
end module run_summary
