!> Everything that changes during an explicit run, in structure-of-arrays form.
!>
!> Nodal arrays are `(3, nodes)`; element data lives in blocks (`solid_block_t`). Blocks are
!> coloured so that no two blocks of one colour share a node: the blocks of a colour run in
!> parallel and add their corner forces straight into the nodal forces, colour after colour.
!> Every node then receives its contributions in the same order whatever the thread count,
!> so results are bit-identical for any `ncpu`, without atomics and without a per-corner force
!> array to write and read back.
module explicit_state
  use kinds, only: wp, block_size
  use gather_list, only: gather_list_t
  use solid_block, only: solid_block_t
  use shell_block, only: shell_block_t
  use efg_forces, only: efg_solver_t
  use rigid_body_state, only: rigid_body_state_t
  use penalty_contact, only: contact_state_t
  implicit none
  private

  public :: explicit_state_t, wall_state_t, energy_totals_t, run_watch_t

  !> Running totals for the energy balance (glstat).
  type :: energy_totals_t
    real(wp) :: kinetic = 0.0_wp
    real(wp) :: internal = 0.0_wp
    real(wp) :: hourglass = 0.0_wp
    real(wp) :: contact = 0.0_wp
    real(wp) :: rigid_wall = 0.0_wp          !< energy taken out by rigid walls (stonewall energy)
    real(wp) :: external_work = 0.0_wp       !< loads and prescribed motions
    real(wp) :: initial_total = 0.0_wp
    real(wp) :: momentum(3) = 0.0_wp         !< linear momentum of all nodes
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

  !> Motion and accumulated force of one rigid wall (planar, or cylinder: `displacement` and
  !> `speed` then along its motion direction, and `mass` stays 0 as the motion is prescribed).
  type :: wall_state_t
    real(wp) :: displacement = 0.0_wp        !< along the normal (moving walls)
    real(wp) :: speed = 0.0_wp               !< along the normal (moving walls)
    real(wp) :: mass = 0.0_wp                !< of a moving wall (its kinetic energy is the model's)
    real(wp) :: normal(3) = 0.0_wp           !< direction of its motion
    real(wp) :: force(3) = 0.0_wp            !< force on the wall in the last cycle
    real(wp) :: impulse(3) = 0.0_wp          !< impulse on the wall since the last rwforc sample
  end type wall_state_t

  !> The state of the whole model at one cycle.
  type :: explicit_state_t
    integer :: node_count = 0
    integer :: cycle = 0
    real(wp) :: time = 0.0_wp
    real(wp) :: time_step = 0.0_wp                       !< t^{n+1} - t^n of the last step
    real(wp) :: next_time_step = 0.0_wp                  !< step for the coming cycle (TSSFAC, DTINIT applied)
    real(wp) :: stable_time_step = 0.0_wp                !< the smallest stable element step it comes from
    integer :: controlling_element = 0                   !< solid index that set next_time_step
                                                         !< (a shell: minus its shell index)
    ! nodal arrays (3, nodes) and (nodes)
    real(wp), allocatable :: reference(:, :)             !< X
    real(wp), allocatable :: coordinates(:, :)           !< x = X + u
    real(wp), allocatable :: displacement(:, :)
    real(wp), allocatable :: velocity(:, :)              !< v^{n+1/2} during the cycle
    real(wp), allocatable :: acceleration(:, :)
    real(wp), allocatable :: internal_force(:, :)
    real(wp), allocatable :: external_force(:, :)
    real(wp), allocatable :: free_acceleration(:)        !< per prescribed motion: the acceleration the
                                                         !< forces would give its dof (for the support's work)
    real(wp), allocatable :: mass(:)
    logical, allocatable :: fixed(:, :)                  !< SPC per dof
    ! element blocks and their corner forces
    type(solid_block_t), allocatable :: blocks(:)
    real(wp), allocatable :: corner_mass(:, :, :)        !< (block_size, 8, blocks)
    real(wp), allocatable :: block_time_step(:)          !< per block, from its kernel
    integer, allocatable :: block_critical_element(:)
    integer, allocatable :: block_inverted_element(:)
    type(gather_list_t) :: block_colors                  !< colour -> blocks (same CSR form as a gather list)
    ! shell blocks (coloured among themselves, added after the solids) and the rotational dofs,
    ! which only shell nodes have (rotary_inertia 0 elsewhere)
    type(shell_block_t), allocatable :: shells(:)
    real(wp), allocatable :: shell_corner_mass(:, :, :)  !< (block_size, 4, shell blocks)
    real(wp), allocatable :: shell_corner_inertia(:, :, :)
    real(wp), allocatable :: shell_time_step(:)
    integer, allocatable :: shell_critical_element(:)
    integer, allocatable :: shell_degenerate_element(:)
    type(gather_list_t) :: shell_colors
    real(wp), allocatable :: angular_velocity(:, :)      !< (3, nodes), w^{n+1/2}
    real(wp), allocatable :: angular_acceleration(:, :)
    real(wp), allocatable :: internal_moment(:, :)
    real(wp), allocatable :: rotary_inertia(:)
    logical, allocatable :: fixed_rotation(:, :)         !< SPC per rotational dof
    real(wp), allocatable :: shell_normal_sum(:, :)      !< (3, nodes): sum of area x normal of the node's shells
    real(wp), allocatable :: shell_area_sum(:)           !< sum of their areas
    ! meshfree parts: their interior particles carry generalized displacements
    type(efg_solver_t), allocatable :: efg(:)
    logical, allocatable :: is_particle(:)               !< interior particle of an EFG part
    ! walls
    type(wall_state_t), allocatable :: walls(:)
    ! penalty contacts (indexed like model%contacts) and their nodal forces (3, nodes)
    type(contact_state_t), allocatable :: contacts(:)
    real(wp), allocatable :: contact_force(:, :)
    ! rigid bodies (indexed like model%rigid_bodies); their nodes move with them
    type(rigid_body_state_t), allocatable :: rigid(:)
    logical, allocatable :: is_rigid_node(:)
    real(wp) :: rigid_time_step = huge(1.0_wp)           !< smallest stable step of the rigid elements
    ! bookkeeping
    real(wp), allocatable :: chunk_sums(:, :)            !< (5, chunks of nodes): scratch of the fixed-order
                                                         !< sums (fixed_order_sum), allocated once
    type(energy_totals_t) :: energy
    type(run_watch_t) :: watch
    real(wp) :: added_mass = 0.0_wp                      !< by mass scaling
    real(wp) :: physical_mass = 0.0_wp
  end type explicit_state_t
end module explicit_state
