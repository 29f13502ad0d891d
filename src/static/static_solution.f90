!> What a linear static analysis produces: the fields at its end time, its energies, and the
!> figures that describe the solve (sizes, bandwidth, pivots, residual, seconds per phase).
module static_solution
  use kinds, only: wp
  implicit none
  private

  public :: static_solution_t

  !> The solution of one linear static analysis.
  type :: static_solution_t
    real(wp) :: time = 0.0_wp                      !< the end time at which loads and conditions were taken
    real(wp), allocatable :: displacement(:, :)    !< (3, nodes): physical displacements (eq. 16 for particles)
    real(wp), allocatable :: generalized(:, :)     !< (3, nodes): the unknowns d (nodal displacements or
                                                   !< generalized displacements of particles)
    real(wp), allocatable :: solid_stress(:, :)    !< (6, solids): volume-averaged Cauchy stress, xx yy zz xy yz zx
    real(wp), allocatable :: part_energy(:)        !< (parts): strain energy
    real(wp) :: internal_energy = 0.0_wp           !< d.K.d / 2
    real(wp) :: load_work = 0.0_wp                 !< f.u / 2: work of the loads, applied in proportion from zero
    real(wp) :: support_work = 0.0_wp              !< r.g / 2: work of the support reactions on the prescribed values
    real(wp) :: external_work = 0.0_wp             !< load_work + support_work (= internal_energy up to the residual)
    real(wp) :: residual = 0.0_wp                  !< max |K d - f - constraint forces| / max |K d| over the unknowns
    ! sizes
    integer :: unknowns = 0                        !< equations of displacement unknowns
    integer :: multipliers = 0                     !< equations of Lagrange multipliers
    character(len=:), allocatable :: ordering      !< the node order used (the narrowest band of three)
    integer :: half_bandwidth = 0                  !< of the order used
    integer :: rcm_half_bandwidth = 0              !< with reverse Cuthill-McKee
    integer :: coordinate_half_bandwidth = 0       !< with nodes sorted along the longest extent
    integer :: natural_half_bandwidth = 0          !< with the nodes in index (deck) order
    integer :: fe_elements = 0, efg_parts = 0, efg_particles = 0, efg_nodes = 0
    logical :: cholesky = .true.                   !< banded Cholesky (else banded LU of the augmented system)
    real(wp) :: band_megabytes = 0.0_wp
    real(wp) :: pivot_ratio = 0.0_wp               !< smallest pivot ratio of the factorization
    ! seconds
    real(wp) :: efg_setup_s = 0.0_wp, ordering_s = 0.0_wp, fe_assembly_s = 0.0_wp, efg_assembly_s = 0.0_wp
    real(wp) :: factor_s = 0.0_wp, solve_s = 0.0_wp, recovery_s = 0.0_wp
  end type static_solution_t
end module static_solution
