!> The motion and the accumulated force of one rigid wall during a run.
module wall_state
  use kinds, only: wp
  implicit none
  private

  public :: wall_state_t

  !> A planar wall, or a cylinder (`displacement` and `speed` then along its motion direction,
  !> and `mass` stays 0 as the motion is prescribed).
  type :: wall_state_t
    real(wp) :: displacement = 0.0_wp        !< along the normal (moving walls)
    real(wp) :: speed = 0.0_wp               !< along the normal (moving walls)
    real(wp) :: mass = 0.0_wp                !< of a moving wall (its kinetic energy is the model's)
    real(wp) :: normal(3) = 0.0_wp           !< direction of its motion
    real(wp) :: force(3) = 0.0_wp            !< force on the wall in the last cycle
    real(wp) :: impulse(3) = 0.0_wp          !< impulse on the wall since the start of the run
    !> The tracked nodes that are interior particles of meshfree parts: their rows (particle_rows),
    !> in the order of the wall's node list (set up once, not part of a restart dump)
    integer, allocatable :: particle_rows(:)
    !> Scratch of one step: the normal impulse each of those particles has received (planar
    !> walls; -1: left alone in this step, as a node that started behind the wall)
    real(wp), allocatable :: particle_impulse(:)
    real(wp), allocatable :: particle_friction(:, :)   !< (3, particles) their friction impulse of the step
  end type wall_state_t
end module wall_state
