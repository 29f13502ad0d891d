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
!>
!> Interior particles of meshfree parts carry generalized values: the wall sees their physical
!> position x_I = X_I + sum_J A_IJ u_J and velocity sum_J A_IJ v_J (particle_rows). A physical
!> velocity change dv at particle I is made with the smallest change of the generalized
!> velocities in the mass norm, dv_J = A_IJ dv / (m_J S), S = sum_J A_IJ^2 / m_J: the particle's
!> effective mass is 1 / S and the impulse P = dv / S goes to the nodes of its row as A_IJ P
!> (rows sum to one: the total is P). Particles share nodes J, so a correction moves its
!> neighbours too: the particles are corrected one after the other in the order of the wall's
!> node list, in sweeps, each particle keeping the normal impulse it has received in the step
!> non-negative and its friction impulse within the Coulomb cone (projected Gauss-Seidel),
!> until no particle moves by more than round-off. The
!> order is fixed and the sweeps serial: the same result for any thread count. The impulses
!> on the generalized values give the wall force and energy exactly as a node's.
module planar_rigid_walls
  use kinds, only: wp
  use model, only: rigid_wall_t, wall_planar
  use wall_state, only: wall_state_t
  use particle_rows, only: particle_rows_t, row_value, row_mass_weight
  implicit none
  private

  public :: initialise_wall_states, enforce_planar_walls, apply_wall_friction, add_row_impulse, &
            particle_sweep_limit

  !> Sweeps over a wall's particles in one step at most (the tests need up to 28; what is left
  !> after the last stays).
  integer, parameter :: particle_sweep_limit = 200

contains

  !> Start each wall with its initial speed, and list the meshfree particles it tracks.
  subroutine initialise_wall_states(walls, rows, states)
    type(rigid_wall_t), intent(in) :: walls(:)
    type(particle_rows_t), intent(in) :: rows
    type(wall_state_t), allocatable, intent(out) :: states(:)
    integer :: w
    allocate (states(size(walls)))
    do w = 1, size(walls)
      states(w)%speed = merge(walls(w)%initial_speed, 0.0_wp, walls(w)%moving)
      states(w)%mass = merge(walls(w)%mass, 0.0_wp, walls(w)%moving)
      states(w)%normal = walls(w)%normal
      if (allocated(walls(w)%nodes) .and. rows%count > 0) then
        states(w)%particle_rows = pack(rows%row_of_node(walls(w)%nodes), rows%row_of_node(walls(w)%nodes) > 0)
      else
        allocate (states(w)%particle_rows(0))
      end if
      allocate (states(w)%particle_impulse(size(states(w)%particle_rows)), &
                states(w)%particle_friction(3, size(states(w)%particle_rows)))
      states(w)%particle_impulse = 0.0_wp
      states(w)%particle_friction = 0.0_wp
    end do
  end subroutine initialise_wall_states

  !> Correct the half-step velocities of the nodes that would cross a wall during the step
  !> `dt` starting at `time`. `velocity` holds v^{n+1/2} computed from `acceleration` a^n with
  !> the step `average_dt`. Returns the energy the walls took (wall energy increment).
  !> Meshfree particles among the tracked nodes are held by their physical motion (see above);
  !> the other nodes by their own.
  subroutine enforce_planar_walls(walls, rows, states, time, dt, average_dt, reference, displacement, coordinates, &
                                  acceleration, mass, velocity, energy_removed)
    type(rigid_wall_t), intent(in) :: walls(:)
    type(particle_rows_t), intent(in) :: rows
    type(wall_state_t), intent(inout) :: states(:)
    real(wp), intent(in) :: time, dt, average_dt
    real(wp), intent(in) :: reference(:, :)     !< X
    real(wp), intent(in) :: displacement(:, :)  !< u^n (generalized at particles)
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
        if (rows%count > 0) then
          if (rows%row_of_node(node) > 0) cycle   ! particles: below
        end if
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
      if (size(states(w)%particle_rows) > 0) &
        call hold_particles(walls(w), rows, states(w), dt, average_dt, wall_start, wall_point, reference, &
                            displacement, acceleration, mass, velocity, total_impulse, energy_removed)
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

  !> The tracked meshfree particles of one planar wall (projected Gauss-Seidel, see above): each
  !> particle whose physical position would end the step behind the wall gets the physical
  !> normal velocity that lands it on the wall; a particle pushed off the wall by its neighbours'
  !> corrections gives back what it received (never more). Friction: the tangential impulse of
  !> the step that stops the particle's tangential physical velocity, kept within FRIC times its
  !> normal impulse (the Coulomb cone; a single node's rule, apply_wall_friction, for one
  !> correction), corrected in the same sweeps. Sweeps until the largest correction of a sweep
  !> moves a particle by less than 1e-12 max(1, |wall point|) (round-off).
  subroutine hold_particles(wall, rows, state, dt, average_dt, wall_start, wall_point, reference, displacement, &
                            acceleration, mass, velocity, total_impulse, energy_removed)
    type(rigid_wall_t), intent(in) :: wall
    type(particle_rows_t), intent(in) :: rows
    type(wall_state_t), intent(inout) :: state
    real(wp), intent(in) :: dt, average_dt, wall_start(3), wall_point(3)
    real(wp), intent(in) :: reference(:, :), displacement(:, :), acceleration(:, :), mass(:)
    real(wp), intent(inout) :: velocity(:, :), total_impulse(3), energy_removed
    real(wp) :: normal(3), position(3), physical_velocity(3), gap, start_gap, weight, received, change
    real(wp) :: largest, tolerance, no_work, now_received, impulse(3), friction(3), limit, moved
    integer :: sweep, k, row
    logical :: crossing
    normal = wall%normal
    tolerance = 1.0e-12_wp*max(1.0_wp, norm2(wall_point))
    state%particle_impulse = 0.0_wp
    state%particle_friction = 0.0_wp
    no_work = 0.0_wp
    ! most steps no particle comes near the wall: find out in parallel (a logical, the same
    ! answer for any thread count), and only then take the particles one by one
    crossing = .false.
    !$omp parallel do schedule(static) default(shared) private(k, row, position, physical_velocity) &
    !$omp reduction(.or.:crossing)
    do k = 1, size(state%particle_rows)
      row = state%particle_rows(k)
      position = reference(:, rows%particle(row)) + row_value(rows, row, displacement)
      physical_velocity = row_value(rows, row, velocity)
      if (dot_product(position + physical_velocity*dt - wall_point, normal) < 0.0_wp) crossing = .true.
    end do
    !$omp end parallel do
    if (.not. crossing) return
    do sweep = 1, particle_sweep_limit
      largest = 0.0_wp
      do k = 1, size(state%particle_rows)
        received = state%particle_impulse(k)
        if (received < 0.0_wp) cycle
        row = state%particle_rows(k)
        position = reference(:, rows%particle(row)) + row_value(rows, row, displacement)
        physical_velocity = row_value(rows, row, velocity)
        gap = dot_product(position + physical_velocity*dt - wall_point, normal)
        if (received == 0.0_wp) then
          if (gap >= 0.0_wp) cycle
          ! as for nodes: one that started behind the wall, or beside a finite wall, is left alone
          start_gap = dot_product(position - wall_start, normal)
          if (start_gap < -(abs(dot_product(physical_velocity, normal) - state%speed)*dt &
                            + 1.0e-9_wp*max(1.0_wp, norm2(position)))) then
            state%particle_impulse(k) = -1.0_wp
            cycle
          end if
          if (wall%finite) then
            if (.not. inside_finite_wall(wall, wall_start, position)) then
              state%particle_impulse(k) = -1.0_wp
              cycle
            end if
          end if
        end if
        weight = row_mass_weight(rows, row, mass)
        if (weight <= 0.0_wp) cycle
        ! the normal speed change that lands it on the wall, kept to a non-negative impulse
        change = max(-gap/dt, -received*weight)
        now_received = received + change/weight
        impulse = (change/weight)*normal
        ! friction: the tangential impulse that stops its tangential physical velocity, kept
        ! within FRIC times the normal impulse (FRIC >= 1: no sliding, no limit; none once it
        ! has left the wall)
        friction = state%particle_friction(:, k)
        if (wall%friction > 0.0_wp) then
          friction = friction - (physical_velocity - dot_product(physical_velocity, normal)*normal)/weight
          if (wall%friction < 1.0_wp) then
            limit = wall%friction*now_received
            if (norm2(friction) > limit) friction = friction*(limit/norm2(friction))
          else if (now_received <= 0.0_wp) then
            friction = 0.0_wp
          end if
          impulse = impulse + (friction - state%particle_friction(:, k))
        end if
        moved = norm2(impulse)*weight*dt
        if (moved == 0.0_wp .or. (sweep > 1 .and. moved <= tolerance)) cycle
        largest = max(largest, moved)
        state%particle_impulse(k) = now_received
        state%particle_friction(:, k) = friction
        call add_row_impulse(rows, row, impulse, [0.0_wp, 0.0_wp, 0.0_wp], average_dt, acceleration, mass, velocity, &
                             total_impulse, energy_removed, no_work)
      end do
      if (largest <= tolerance) exit
    end do
  end subroutine hold_particles

  !> The physical impulse `impulse` at the particle of row `row` on the generalized velocities:
  !> A_IJ impulse to each node J of the row. Adds the impulses to `total_impulse` and the energy
  !> the wall takes to `energy_removed`: the work J . (v^{n-1/2} + v^{n+1/2}) / 2 of each node's
  !> impulse (exact for several impulses on one node: their terms telescope), less the work
  !> J . wall_velocity that a wall with a prescribed velocity does (the caller books that as
  !> external work and gets it added to `work`; planar walls pass a zero velocity: a moving
  !> planar wall's own kinetic energy is the model's).
  subroutine add_row_impulse(rows, row, impulse, wall_velocity, average_dt, acceleration, mass, velocity, &
                             total_impulse, energy_removed, work)
    type(particle_rows_t), intent(in) :: rows
    integer, intent(in) :: row
    real(wp), intent(in) :: impulse(3), wall_velocity(3), average_dt
    real(wp), intent(in) :: acceleration(:, :), mass(:)
    real(wp), intent(inout) :: velocity(:, :), total_impulse(3), energy_removed, work
    real(wp) :: previous(3), node_impulse(3), node_work
    integer :: k, node
    do k = rows%offsets(row), rows%offsets(row + 1) - 1
      node = rows%node(k)
      if (mass(node) <= 0.0_wp) cycle
      previous = velocity(:, node)
      velocity(:, node) = previous + (rows%value(k)/mass(node))*impulse
      node_impulse = mass(node)*(velocity(:, node) - previous)
      total_impulse = total_impulse + node_impulse
      node_work = dot_product(node_impulse, wall_velocity)
      work = work + node_work
      energy_removed = energy_removed + node_work - 0.5_wp*dot_product(node_impulse, velocity(:, node) + previous &
                                                                       - average_dt*acceleration(:, node))
    end do
  end subroutine add_row_impulse

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
