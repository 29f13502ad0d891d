!> The physics state of an explicit run at one cycle, in structure-of-arrays form: the clock,
!> the nodal arrays, the element groups (element_group) and the rigid bodies, walls and
!> contacts, with the energy ledger every phase of the cycle books its share in. Together
!> with the output plan, histories and timers it makes the run state (run_state), which is
!> everything the next cycle needs and nothing the deck already holds.
module explicit_state
  use kinds, only: wp
  use message_log, only: message_log_t
  use nodal_state, only: nodal_state_t
  use element_group, only: group_holder_t
  use rigid_body_state, only: rigid_body_state_t
  use spot_weld_constraints, only: spot_weld_state_t
  use tied_contact, only: tied_state_t
  use wall_state, only: wall_state_t
  use penalty_contact, only: contact_state_t
  use particle_rows, only: particle_rows_t
  implicit none
  private

  public :: explicit_state_t, energy_totals_t, run_watch_t

  !> The energy ledger (glstat): running totals of the work each phase books, and the energies
  !> measured from the state (energy_balance).
  type :: energy_totals_t
    real(wp) :: kinetic = 0.0_wp
    real(wp) :: internal = 0.0_wp
    real(wp) :: hourglass = 0.0_wp
    real(wp) :: contact = 0.0_wp
    real(wp) :: rigid_wall = 0.0_wp          !< energy taken out by rigid walls (stonewall energy)
    real(wp) :: external_work = 0.0_wp       !< loads, prescribed motions, supports, drilling constraint
    real(wp) :: initial_total = 0.0_wp
    real(wp) :: momentum(3) = 0.0_wp         !< linear momentum of all nodes
    !> Energy eroded elements took along (glstat's eroded energies), measured from the groups:
    !> their internal and hourglass energy at erosion. Their nodes stay in the model with their
    !> mass, so their kinetic energy stays in `kinetic` and the eroded kinetic energy is 0.
    real(wp) :: eroded_internal = 0.0_wp
    real(wp) :: eroded_hourglass = 0.0_wp
    real(wp) :: eroded_kinetic = 0.0_wp
  end type energy_totals_t

  !> What the run checks (run_checks) compare against and remember from cycle to cycle.
  type :: run_watch_t
    real(wp) :: largest_wave_speed = 0.0_wp       !< of the model's materials (0: none has one)
    real(wp) :: velocity_limit = huge(1.0_wp)     !< a node faster than this stops the run
    real(wp) :: angular_velocity_limit = huge(1.0_wp)
    real(wp) :: first_time_step = 0.0_wp          !< the step of the first cycle
    real(wp) :: last_stable_step = 0.0_wp         !< the stable step (before TSSFAC) of the last cycle
    integer :: step_decades_reported = 0          !< the step has been reported below 10^-k of the first
    real(wp) :: largest_energy_supplied = 0.0_wp  !< largest |initial energy|, |external work| so far
  end type run_watch_t

  type :: explicit_state_t
    !> what the run printed while it went (messag, /run/warnings; not in restart dumps)
    type(message_log_t) :: messages
    ! the clock
    integer :: cycle = 0
    real(wp) :: time = 0.0_wp
    real(wp) :: time_step = 0.0_wp                       !< t^{n} - t^{n-1}: the step just taken
    real(wp) :: next_time_step = 0.0_wp                  !< for the coming cycle (TSSFAC, DTINIT, ENDTIM applied)
    real(wp) :: stable_time_step = 0.0_wp                !< the smallest stable element step it comes from
    integer :: controlling_group = 0                     !< the group (0: the rigid bodies or none) and
    integer :: controlling_element = 0                   !< its element that set it
    ! nodes and elements
    type(nodal_state_t) :: nodes
    type(group_holder_t), allocatable :: groups(:)
    !> The transformation rows of every meshfree particle (set up once from the groups): walls
    !> and initial velocities act on the physical values
    type(particle_rows_t) :: rows
    real(wp), allocatable :: free_acceleration(:)        !< per prescribed motion: the acceleration the
                                                         !< forces would give its dof (for the support's work)
    ! rigid bodies (indexed like model%rigid_bodies); their nodes move with them
    type(rigid_body_state_t), allocatable :: rigid(:)
    real(wp) :: rigid_time_step = huge(1.0_wp)           !< smallest stable step of the rigid elements
    type(spot_weld_state_t), allocatable :: welds(:)     !< indexed like model%spot_welds
    logical, allocatable :: held_by_weld(:)              !< (nodes) in a weld that has not failed
    !> (nodes) the nodes of welds that fail by plastic strain (EP / EPSF), and the largest plastic
    !> strain of the shells on each (recomputed every cycle from the shells)
    logical, allocatable :: plastic_weld_node(:)
    real(wp), allocatable :: weld_node_plastic_strain(:)
    type(tied_state_t) :: ties                           !< work arrays of the tied contacts
    type(wall_state_t), allocatable :: walls(:)          !< indexed like model%walls
    type(contact_state_t), allocatable :: contacts(:)    !< indexed like model%contacts
    ! erosion (the erosion phase of explicit_solver): model-indexed masks of the eroded solids
    ! and shells (for the contacts), whether an element eroded in this cycle, and how many so far
    logical, allocatable :: solid_eroded(:), shell_eroded(:)
    logical :: eroded_this_cycle = .false.
    integer :: eroded_count = 0
    !> Contact on physical values (explicit_solver's contact phase, models with meshfree
    !> particles): the positions and velocities the contacts see and their forces on them,
    !> (3, nodes) each, allocated at the first contact phase and reused
    real(wp), allocatable :: contact_coordinates(:, :), contact_velocity(:, :), contact_physical_force(:, :)
    ! bookkeeping
    real(wp), allocatable :: chunk_sums(:, :)            !< (5, chunks of nodes): scratch of the fixed-order
                                                         !< sums (fixed_order_sum), allocated once
    type(energy_totals_t) :: energy
    type(run_watch_t) :: watch
    real(wp) :: added_mass = 0.0_wp                      !< by mass scaling
    real(wp) :: physical_mass = 0.0_wp
  end type explicit_state_t
end module explicit_state
