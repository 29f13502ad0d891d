!> The nodal arrays of an explicit run, in structure-of-arrays form: what every element kind
!> reads (positions, velocities) and adds into (forces, moments, masses).
!>
!> Vectors are `(3, nodes)`. Rotational dofs exist for every node but only shell nodes have a
!> rotary inertia (0 elsewhere). Meshfree particles carry generalized values in the same
!> arrays (`is_particle` marks them; output transforms them to physical values).
module nodal_state
  use kinds, only: wp
  implicit none
  private

  public :: nodal_state_t, allocate_nodal_state

  type :: nodal_state_t
    integer :: count = 0
    logical :: rotational = .false.                      !< some node has a rotary inertia (shells)
    real(wp), allocatable :: reference(:, :)             !< X
    real(wp), allocatable :: coordinates(:, :)           !< x = X + u
    real(wp), allocatable :: displacement(:, :)
    real(wp), allocatable :: velocity(:, :)              !< v^{n+1/2} during the cycle
    real(wp), allocatable :: acceleration(:, :)
    real(wp), allocatable :: internal_force(:, :)
    real(wp), allocatable :: external_force(:, :)
    real(wp), allocatable :: contact_force(:, :)
    real(wp), allocatable :: mass(:)
    logical, allocatable :: fixed(:, :)                  !< SPC per dof
    real(wp), allocatable :: angular_velocity(:, :)      !< w^{n+1/2}
    real(wp), allocatable :: angular_acceleration(:, :)
    real(wp), allocatable :: internal_moment(:, :)
    real(wp), allocatable :: rotary_inertia(:)
    logical, allocatable :: fixed_rotation(:, :)         !< SPC per rotational dof
    !> Sum of area x normal and of the areas of the shells on each node (the drilling-rate
    !> removal of the time loop needs the mean normal).
    real(wp), allocatable :: shell_normal_sum(:, :)
    real(wp), allocatable :: shell_area_sum(:)
    logical, allocatable :: is_particle(:)               !< interior particle of a meshfree part
    logical, allocatable :: is_rigid_node(:)             !< moves with a rigid body
  end type nodal_state_t

contains

  !> Every array for `count` nodes, zero (positions and velocities given).
  subroutine allocate_nodal_state(nodes, coordinates, velocity)
    type(nodal_state_t), intent(out) :: nodes
    real(wp), intent(in) :: coordinates(:, :), velocity(:, :)
    integer :: count
    count = size(coordinates, 2)
    nodes%count = count
    nodes%reference = coordinates
    nodes%coordinates = coordinates
    nodes%velocity = velocity
    allocate (nodes%displacement(3, count), nodes%acceleration(3, count), nodes%internal_force(3, count), &
              nodes%external_force(3, count), nodes%contact_force(3, count), nodes%mass(count), &
              nodes%fixed(3, count), nodes%angular_velocity(3, count), nodes%angular_acceleration(3, count), &
              nodes%internal_moment(3, count), nodes%rotary_inertia(count), nodes%fixed_rotation(3, count), &
              nodes%shell_normal_sum(3, count), nodes%shell_area_sum(count), nodes%is_particle(count), &
              nodes%is_rigid_node(count))
    nodes%displacement = 0.0_wp
    nodes%acceleration = 0.0_wp
    nodes%internal_force = 0.0_wp
    nodes%external_force = 0.0_wp
    nodes%contact_force = 0.0_wp
    nodes%mass = 0.0_wp
    nodes%fixed = .false.
    nodes%angular_velocity = 0.0_wp
    nodes%angular_acceleration = 0.0_wp
    nodes%internal_moment = 0.0_wp
    nodes%rotary_inertia = 0.0_wp
    nodes%fixed_rotation = .false.
    nodes%shell_normal_sum = 0.0_wp
    nodes%shell_area_sum = 0.0_wp
    nodes%is_particle = .false.
    nodes%is_rigid_node = .false.
  end subroutine allocate_nodal_state
end module nodal_state
