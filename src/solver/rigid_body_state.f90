!> The motion of one rigid body during an explicit run (LS-DYNA Theory Manual, "Rigid Body
!> Dynamics"): translation of the centre of mass, rotation R (body axes -> global axes),
!> angular momentum in the global frame, and what the body needs to turn the nodal forces of
!> a cycle into a resultant and to move its nodes afterwards. Everything is allocated once,
!> at set-up.
module rigid_body_state
  use kinds, only: wp
  implicit none
  private

  !> One rigid body (indexed like model%rigid_bodies).
  type, public :: rigid_body_state_t
    real(wp) :: mass = 0.0_wp                    !< elements' mass plus the nodal masses of its nodes
    real(wp) :: rigid_element_mass = 0.0_wp      !< the rigid elements' share of it (physical mass)
    real(wp) :: inertia(3, 3) = 0.0_wp           !< about the centre of mass, in body axes (= global at t = 0)
    real(wp) :: inverse_inertia(3, 3) = 0.0_wp
    real(wp) :: initial_centre(3) = 0.0_wp
    real(wp) :: centre(3) = 0.0_wp               !< x_c at the current time
    real(wp) :: velocity(3) = 0.0_wp             !< V at the half step (the integer step at cycle 0)
    real(wp) :: angular_momentum(3) = 0.0_wp     !< L about the centre, global frame, at the half step
    real(wp) :: angular_velocity(3) = 0.0_wp     !< omega, global frame, at the half step
    real(wp) :: rotation(3, 3) = reshape([1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, &
                                          0.0_wp, 0.0_wp, 1.0_wp], [3, 3]) !< R: body -> global
    real(wp) :: rotation_angle(3) = 0.0_wp       !< integral of omega (prescribed rotations, VAD = 2)
    real(wp) :: force(3) = 0.0_wp                !< resultant of the model's forces on it, last step
    real(wp) :: moment(3) = 0.0_wp               !< their moment about the centre, last step
    real(wp) :: impulse(3) = 0.0_wp              !< impulse of those forces since the start of the run
    logical :: held(6) = .false.                 !< dofs held by a constraint or motion in the last step
    real(wp) :: held_acceleration(6) = 0.0_wp    !< their acceleration (VAD = 1; zero otherwise)
    real(wp) :: time_step = huge(1.0_wp)         !< smallest stable step of its elements (E, PR, RO)
    real(wp), allocatable :: offsets(:, :)       !< (3, nodes): X - X_c in body axes
    real(wp), allocatable :: node_mass(:)        !< lumped mass of each node (solver's nodal mass)
    real(wp), allocatable :: node_velocity(:, :) !< (3, nodes): the velocities the body gave its nodes
  end type rigid_body_state_t
end module rigid_body_state
