!> The run state: everything an explicit run carries from one cycle to the next, in one type.
!> The physics state (clock, nodes, element groups, rigid bodies, walls, contacts, energy
!> ledger: explicit_state), what the output has written and will write (the output plan, the
!> history rows, the distortion record) and the wall-clock time of each phase. The deck's
!> model is not part of it: a restart rebuilds the model from the deck and continues from a
!> run state read back whole.
module run_state
  use kinds, only: wp
  use explicit_state, only: explicit_state_t
  use output_plan, only: output_plan_t
  use history_buffer, only: history_set_t
  use element_group, only: distortion_t
  use wall_clock, only: phase_timer_t
  use progress_report, only: progress_t
  use domain_partition, only: domain_partition_t
  use domain_exchange, only: domain_exchange_t
  implicit none
  private

  public :: run_state_t, phase_names, phase_count
  public :: phase_velocities, phase_constraints, phase_walls, phase_rigid_bodies, phase_positions, &
            phase_internal_forces, phase_contact, phase_external_forces, phase_accelerations, phase_time_step, &
            phase_checks, phase_output, phase_erosion

  !> The phases of a cycle, in order (explicit_solver), each with its timer.
  integer, parameter :: phase_velocities = 1, phase_constraints = 2, phase_walls = 3, phase_rigid_bodies = 4, &
                        phase_positions = 5, phase_internal_forces = 6, phase_contact = 7, &
                        phase_external_forces = 8, phase_accelerations = 9, phase_time_step = 10, &
                        phase_checks = 11, phase_output = 12, phase_erosion = 13, phase_count = 13
  character(len=16), parameter :: phase_names(phase_count) = [character(len=16) :: "velocities", "constraints", &
    "walls", "rigid_bodies", "positions", "internal_forces", "contact", "external_forces", "accelerations", &
    "time_step", "checks", "output", "erosion"]

  type :: run_state_t
    type(explicit_state_t) :: state
    type(output_plan_t) :: plan
    type(history_set_t) :: histories
    type(distortion_t) :: distortion                !< FE solids folded at a corner, checked at each state
    real(wp), allocatable :: energy_scratch(:, :)   !< (5, chunks of nodes) for measured energies
    type(phase_timer_t) :: timers(phase_count)
    type(progress_t) :: progress
    type(domain_partition_t) :: partition
    !> the exchanges among the ranks of a distributed run (docs/parallel.md; none with one rank)
    type(domain_exchange_t) :: exchange
  end type run_state_t
end module run_state
