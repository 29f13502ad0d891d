!> Planar rigid walls (*RIGIDWALL_PLANAR, _MOVING, _FINITE): the constraint method.
!>
!> LS-DYNA treats deformable nodes against a planar wall by a kinematic constraint (RWPNAL = 0):
!> a node that would cross the wall during the coming step gets the normal velocity that puts
!> it exactly on the wall at the end of the step. The velocity change is an impulse; its sum over
!> the nodes is the force on the wall (Hallquist, LS-DYNA Theory Manual, "Stonewalls").
!> A moving wall has a mass and a speed along its normal and receives the opposite impulse.
!> The wall ("stonewall") energy is the work the wall does on the nodes, counted as energy taken
!> out: for central differences the work of an impulse J applied at t^n is J . (v^{n-1/2} +
!> v^{n+1/2}) / 2, which removes a striking node's kinetic energy and is zero for a node that
!> rests on the wall.
module planar_rigid_walls
  use kinds, only: wp
  use model, only: rigid_wall_t, wall_planar
  use wall_state, only: wall_state_t
  implicit none
  private

  public :: initialise_wall_states, enforce_planar_walls, apply_wall_friction

contains

  !> Start each wall with its initial speed.
  subroutine initialise_wall_states(walls, states)
    type(rigid_wall_t), intent(in) :: walls(:)
    type(wall_state_t), allocatable, intent(out) :: states(:)
    integer :: w
    allocate (states(size(walls)))
    do w = 1, size(walls)
      states(w)%speed = merge(walls(w)%initial_speed, 0.0_wp, walls(w)%moving)
      states(w)%mass = merge(walls(w)%mass, 0.0_wp, walls(w)%moving)
      states(w)%normal = walls(w)%normal
    end do
  end subroutine initialise_wall_states

  !> Correct the half-step velocities of the nodes that would cross a wall during the step
  !> `dt` starting at `time`. `velocity` holds v^{n+1/2} computed from `acceleration` a^n with
  !> the step `average_dt`. Returns the energy the walls took (wall energy increment).
  subroutine enforce_planar_walls(walls, states, time, dt, average_dt, coordinates, acceleration, mass, &
                                  velocity, energy_removed)
    type(rigid_wall_t), intent(in) :: walls(:)
    type(wall_state_t), intent(inout) :: states(:)
    real(wp), intent(in) :: time, dt, average_dt
    real(wp), intent(in) :: coordinates(:, :)   !< x^n
    real(wp), intent(in) :: acceleration(:, :)  !< a^n
    real(wp), intent(in) :: mass(:)
    real(wp), intent(inout) :: velocity(:, :)   !< v^{n+1/2}
    real(wp), intent(out) :: energy_removed
    integer :: w, k, node
    real(wp) :: wall_point(3), wall_start(3), start_gap, normal(3), gap, normal_speed, target_speed, impulse(3)
    real(wp) :: old_velocity(3), total_impulse(3), wall_speed

    energy_removed = 0.0_wp
    do w = 1, size(walls)
      if (walls(w)%kind /= wall_planar) cycle   ! cylinders: cylinder_walls
      states(w)%force = 0.0_wp
      if (time < walls(w)%birth .or. time > walls(w)%death) cycle
      normal = walls(w)%normal
      wall_speed = states(w)%speed
      ! wall position at the end of the step
      wall_start = walls(w)%point + normal*states(w)%displacement
      wall_point = wall_start + normal*wall_speed*dt
      total_impulse = 0.0_wp
      do k = 1, size(walls(w)%nodes)
        node = walls(w)%nodes(k)
        gap = dot_product(coordinates(:, node) + velocity(:, node)*dt - wall_point, normal)
        if (gap >= 0.0_wp) cycle
        ! A node already behind the wall at the start of the step (further than it could have
        ! moved in one step, plus round-off) started there: LS-DYNA leaves such nodes alone.
        start_gap = dot_product(coordinates(:, node) - wall_start, normal)
        if (start_gap < -(abs(dot_product(velocity(:, node), normal) - wall_speed)*dt &
                          + 1.0e-9_wp*max(1.0_wp, norm2(coordinates(:, node))))) cycle
        if (walls(w)%finite) then
          if (.not. inside_finite_wall(walls(w), wall_start, coordinates(:, node))) cycle
        end if
        old_velocity = velocity(:, node)
        normal_speed = dot_product(old_velocity, normal)
        ! the normal speed that lands the node on the wall at the end of the step
        target_speed = normal_speed - gap/dt
        velocity(:, node) = old_velocity + (target_speed - normal_speed)*normal
        call apply_wall_friction(walls(w)%friction, normal, old_velocity, velocity(:, node))
        impulse = mass(node)*(velocity(:, node) - old_velocity)
        total_impulse = total_impulse + impulse
        energy_removed = energy_removed - 0.5_wp*dot_product(impulse, velocity(:, node) + old_velocity &
                                                             - average_dt*acceleration(:, node))
      end do
      ! the wall receives the opposite impulse
      states(w)%force = -total_impulse/dt
      states(w)%impulse = states(w)%impulse - total_impulse
      if (walls(w)%moving) then
        states(w)%displacement = states(w)%displacement + wall_speed*dt
        if (walls(w)%mass > 0.0_wp) then
          ! the wall's kinetic energy counts as the model's: the wall energy is what the walls
          ! took from the nodes less what they kept as motion (the dissipated part)
          states(w)%speed = wall_speed - dot_product(total_impulse, normal)/walls(w)%mass
          energy_removed = energy_removed - 0.5_wp*walls(w)%mass*(states(w)%speed**2 - wall_speed**2)
        end if
      end if
    end do
  end subroutine enforce_planar_walls

  !> Coulomb friction on the tangential velocity relative to the wall: FRIC = 0 frictionless,
  !> 0 < FRIC < 1 Coulomb (tangential impulse at most FRIC times the normal impulse), FRIC >= 1
  !> no sliding (the weld options 2 and 3 act as no sliding here).
  pure subroutine apply_wall_friction(friction, normal, old_velocity, velocity)
    real(wp), intent(in) :: friction, normal(3), old_velocity(3)
    real(wp), intent(inout) :: velocity(3)
    real(wp) :: tangential(3), tangential_speed, normal_change, allowed
    if (friction <= 0.0_wp) return
    tangential = velocity - dot_product(velocity, normal)*normal
    tangential_speed = norm2(tangential)
    if (tangential_speed <= 0.0_wp) return
    if (friction >= 1.0_wp) then
      velocity = velocity - tangential
      return
    end if
    normal_change = abs(dot_product(velocity - old_velocity, normal))
    allowed = friction*normal_change
    velocity = velocity - tangential*min(1.0_wp, allowed/tangential_speed)
  end subroutine apply_wall_friction

  !> Whether the projection of `point` on a finite wall lies within its edges.
  pure function inside_finite_wall(wall, wall_origin, point) result(inside)
    type(rigid_wall_t), intent(in) :: wall
    real(wp), intent(in) :: wall_origin(3), point(3)
    logical :: inside
    real(wp) :: edge_m(3), along_l, along_m
    edge_m = [wall%normal(2)*wall%edge_direction(3) - wall%normal(3)*wall%edge_direction(2), &
              wall%normal(3)*wall%edge_direction(1) - wall%normal(1)*wall%edge_direction(3), &
              wall%normal(1)*wall%edge_direction(2) - wall%normal(2)*wall%edge_direction(1)]
    along_l = dot_product(point - wall_origin, wall%edge_direction)
    along_m = dot_product(point - wall_origin, edge_m)
    inside = .true.
    if (wall%length_l > 0.0_wp) inside = inside .and. along_l >= 0.0_wp .and. along_l <= wall%length_l
    if (wall%length_m > 0.0_wp) inside = inside .and. along_m >= 0.0_wp .and. along_m <= wall%length_m
  end function inside_finite_wall
end module planar_rigid_walls
