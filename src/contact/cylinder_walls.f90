!> Geometric cylinder rigid walls (*RIGIDWALL_GEOMETRIC_CYLINDER, _MOTION): the constraint
!> method of the planar walls (planar_rigid_walls) applied to a rigid solid cylinder.
!>
!> The cylinder has radius RADCYL about the axis from the tail (XT YT ZT) toward the head and
!> length LENCYL from the tail (LENCYL <= 0: infinite). A tracked node that would end the step
!> inside the cylinder gets the velocity that puts it on the surface at the end of the step:
!> on the side (radially outward) or on an end cap, whichever surface is closest to the node's
!> position at the start of the step (the largest of the signed distances rho - R, -h, h - L).
!> The velocity change is along that surface's normal; friction (FRIC) then acts on the
!> tangential velocity relative to the wall as for planar walls. The sum of the impulses is the
!> (negated) force on the wall.
!>
!> `_MOTION` moves the cylinder along the unit direction (VX VY VZ) with the curve LCID as its
!> speed (OPT 0, evaluated at the half step) or its displacement (OPT 1, relative to the
!> curve's value at t = 0). The motion is prescribed: the wall has infinite mass and the nodes
!> do not change it.
!>
!> Energy (central-difference form, as for planar walls): an impulse J applied at t^n changes
!> a node's kinetic energy by W = J . (v^{n-1/2} + v^{n+1/2}) / 2. A wall moving with velocity
!> v_w does the work E = J . v_w on the nodes; that is external work (the prescribed motion
!> feeds it). The rigid-wall energy is what the walls took out, E - W (the energy dissipated by
!> the inelastic constraint; for a stationary wall E = 0 and it is -W as for planar walls).
!> The balance kinetic + internal + rigid-wall = initial + external work then closes.
!>
!> Interior particles of meshfree parts are held by their physical motion as by the planar
!> walls (planar_rigid_walls): physical position and velocity from their rows, the correction
!> along the surface normal made with the smallest change of the generalized velocities in the
!> mass norm, particle after particle in the order of the wall's node list, in sweeps until no
!> particle ends inside by more than round-off (a correction only pushes out: the surface normal
!> changes from point to point, so no impulse is given back).
module cylinder_walls
  use kinds, only: wp
  use curves, only: curve_t, curve_value
  use model, only: rigid_wall_t, wall_cylinder
  use wall_state, only: wall_state_t
  use particle_rows, only: particle_rows_t, row_value, row_mass_weight
  use planar_rigid_walls, only: apply_wall_friction, add_row_impulse, particle_sweep_limit
  implicit none
  private

  public :: enforce_cylinder_walls

  integer, parameter :: surface_side = 1, surface_bottom = 2, surface_top = 3

contains

  !> Correct the half-step velocities of the nodes that would end the step `dt` starting at
  !> `time` inside a cylinder wall, and advance the cylinders' prescribed motion. `velocity`
  !> holds v^{n+1/2} computed from `acceleration` a^n with the step `average_dt`. Returns the
  !> rigid-wall energy increment (energy dissipated) and the work the moving walls did on the
  !> nodes (external work).
  subroutine enforce_cylinder_walls(walls, curves, rows, states, time, dt, average_dt, reference, displacement, &
                                    coordinates, acceleration, mass, velocity, energy_removed, wall_work)
    type(rigid_wall_t), intent(in) :: walls(:)
    type(curve_t), intent(in) :: curves(:)
    type(particle_rows_t), intent(in) :: rows
    type(wall_state_t), intent(inout) :: states(:)
    real(wp), intent(in) :: time, dt, average_dt
    real(wp), intent(in) :: reference(:, :)     !< X
    real(wp), intent(in) :: displacement(:, :)  !< u^n (generalized at particles)
    real(wp), intent(in) :: coordinates(:, :)   !< x^n
    real(wp), intent(in) :: acceleration(:, :)  !< a^n
    real(wp), intent(in) :: mass(:)
    real(wp), intent(inout) :: velocity(:, :)   !< v^{n+1/2}
    real(wp), intent(out) :: energy_removed     !< rigid-wall (dissipated) energy increment
    real(wp), intent(out) :: wall_work          !< work of the moving walls on the nodes
    integer :: w, k, node
    real(wp) :: start_shift, end_shift, speed, wall_velocity(3), tail_start(3), tail_end(3)
    real(wp) :: old_velocity(3), impulse(3), total_impulse(3), normal(3), depth, work
    real(wp) :: end_point(3), relative(3), height, outside_squared

    energy_removed = 0.0_wp
    wall_work = 0.0_wp
    do w = 1, size(walls)
      if (walls(w)%kind /= wall_cylinder) cycle
      states(w)%force = 0.0_wp
      ! the prescribed motion over the step (it goes on before the birth and after the death)
      start_shift = states(w)%displacement
      speed = 0.0_wp
      end_shift = start_shift
      if (walls(w)%motion_curve > 0) then
        associate (curve => curves(walls(w)%motion_curve))
          if (walls(w)%motion_option == 1) then
            end_shift = curve_value(curve, time + dt) - curve_value(curve, 0.0_wp)
            speed = (end_shift - start_shift)/dt
          else
            speed = curve_value(curve, time + 0.5_wp*dt)
            end_shift = start_shift + speed*dt
          end if
        end associate
      end if
      wall_velocity = speed*walls(w)%motion_direction
      tail_start = walls(w)%point + start_shift*walls(w)%motion_direction
      tail_end = walls(w)%point + end_shift*walls(w)%motion_direction
      states(w)%displacement = end_shift
      states(w)%speed = speed
      if (time < walls(w)%birth .or. time > walls(w)%death) cycle
      total_impulse = 0.0_wp
      ! squared distance from the axis beyond which a node is surely outside (the margin keeps
      ! nodes on the surface to within round-off for the exact test of surface_correction)
      outside_squared = (1.0_wp + 1.0e-8_wp)*walls(w)%radius**2
      do k = 1, size(walls(w)%nodes)
        node = walls(w)%nodes(k)
        if (rows%count > 0) then
          if (rows%row_of_node(node) > 0) cycle   ! particles: below
        end if
        ! most tracked nodes are far from the cylinder: a test without square roots first
        end_point = coordinates(:, node) + velocity(:, node)*dt
        relative = end_point - tail_end
        height = dot_product(relative, walls(w)%normal)
        if (dot_product(relative, relative) - height**2 >= outside_squared) cycle
        call surface_correction(walls(w), tail_start, tail_end, coordinates(:, node), end_point, normal, depth)
        if (depth <= 0.0_wp) cycle
        old_velocity = velocity(:, node)
        velocity(:, node) = old_velocity + (depth/dt)*normal
        ! friction on the velocity relative to the wall
        velocity(:, node) = velocity(:, node) - wall_velocity
        call apply_wall_friction(walls(w)%friction, normal, old_velocity - wall_velocity, velocity(:, node))
        velocity(:, node) = velocity(:, node) + wall_velocity
        impulse = mass(node)*(velocity(:, node) - old_velocity)
        total_impulse = total_impulse + impulse
        work = dot_product(impulse, wall_velocity)
        wall_work = wall_work + work
        energy_removed = energy_removed + work - 0.5_wp*dot_product(impulse, velocity(:, node) + old_velocity &
                                                                    - average_dt*acceleration(:, node))
      end do
      if (size(states(w)%particle_rows) > 0) &
        call hold_particles(walls(w), rows, states(w)%particle_rows, dt, average_dt, tail_start, tail_end, &
                            wall_velocity, outside_squared, reference, displacement, acceleration, mass, velocity, &
                            total_impulse, energy_removed, wall_work)
      ! the wall receives the opposite impulse; its prescribed motion does not change
      states(w)%force = -total_impulse/dt
      states(w)%impulse = states(w)%impulse - total_impulse
    end do
  end subroutine enforce_cylinder_walls

  !> The tracked meshfree particles of one cylinder (see above): sweeps in the list's order until
  !> no particle would end the step inside by more than 1e-12 of the radius (round-off).
  subroutine hold_particles(wall, rows, particle_rows, dt, average_dt, tail_start, tail_end, wall_velocity, &
                            outside_squared, reference, displacement, acceleration, mass, velocity, total_impulse, &
                            energy_removed, wall_work)
    type(rigid_wall_t), intent(in) :: wall
    type(particle_rows_t), intent(in) :: rows
    integer, intent(in) :: particle_rows(:)
    real(wp), intent(in) :: dt, average_dt, tail_start(3), tail_end(3), wall_velocity(3), outside_squared
    real(wp), intent(in) :: reference(:, :), displacement(:, :), acceleration(:, :), mass(:)
    real(wp), intent(inout) :: velocity(:, :), total_impulse(3), energy_removed, wall_work
    real(wp) :: position(3), physical_velocity(3), end_point(3), relative(3), height, normal(3), depth
    real(wp) :: new_velocity(3), weight, largest, tolerance
    integer :: sweep, k, row
    logical :: near
    tolerance = 1.0e-12_wp*max(1.0_wp, wall%radius)
    ! most steps no particle comes near the cylinder: find out in parallel (a logical, the same
    ! answer for any thread count), and only then take the particles one by one
    near = .false.
    !$omp parallel do schedule(static) default(shared) private(k, row, position, physical_velocity, end_point, &
    !$omp relative, height) reduction(.or.:near)
    do k = 1, size(particle_rows)
      row = particle_rows(k)
      position = reference(:, rows%particle(row)) + row_value(rows, row, displacement)
      physical_velocity = row_value(rows, row, velocity)
      end_point = position + physical_velocity*dt
      relative = end_point - tail_end
      height = dot_product(relative, wall%normal)
      if (dot_product(relative, relative) - height**2 < outside_squared) near = .true.
    end do
    !$omp end parallel do
    if (.not. near) return
    do sweep = 1, particle_sweep_limit
      largest = 0.0_wp
      do k = 1, size(particle_rows)
        row = particle_rows(k)
        position = reference(:, rows%particle(row)) + row_value(rows, row, displacement)
        physical_velocity = row_value(rows, row, velocity)
        end_point = position + physical_velocity*dt
        relative = end_point - tail_end
        height = dot_product(relative, wall%normal)
        if (dot_product(relative, relative) - height**2 >= outside_squared) cycle
        call surface_correction(wall, tail_start, tail_end, position, end_point, normal, depth)
        if (depth <= 0.0_wp .or. (sweep > 1 .and. depth <= tolerance)) cycle
        weight = row_mass_weight(rows, row, mass)
        if (weight <= 0.0_wp) cycle
        largest = max(largest, depth)
        new_velocity = physical_velocity + (depth/dt)*normal - wall_velocity
        call apply_wall_friction(wall%friction, normal, physical_velocity - wall_velocity, new_velocity)
        new_velocity = new_velocity + wall_velocity
        call add_row_impulse(rows, row, (new_velocity - physical_velocity)/weight, wall_velocity, average_dt, &
                             acceleration, mass, velocity, total_impulse, energy_removed, wall_work)
      end do
      if (largest <= tolerance) exit
    end do
  end subroutine hold_particles

  !> Whether `end_point` lies inside the cylinder placed at `tail_end`; if so, the outward unit
  !> `normal` of the surface the node is pushed to and the `depth` to move along it (depth <= 0:
  !> outside). The surface is the one closest to `start_point` relative to the cylinder placed
  !> at `tail_start`.
  pure subroutine surface_correction(wall, tail_start, tail_end, start_point, end_point, normal, depth)
    type(rigid_wall_t), intent(in) :: wall
    real(wp), intent(in) :: tail_start(3), tail_end(3), start_point(3), end_point(3)
    real(wp), intent(out) :: normal(3), depth
    real(wp) :: axis(3), relative(3), radial(3), height, rho, start_radial(3), start_height
    real(wp) :: start_rho, distance, best
    integer :: surface
    logical :: finite

    normal = 0.0_wp
    depth = 0.0_wp
    axis = wall%normal
    finite = wall%length > 0.0_wp
    relative = end_point - tail_end
    height = dot_product(relative, axis)
    radial = relative - height*axis
    rho = norm2(radial)
    if (rho >= wall%radius) return
    if (finite) then
      if (height <= 0.0_wp .or. height >= wall%length) return
    end if
    ! the surface closest to the start position: the largest signed distance
    relative = start_point - tail_start
    start_height = dot_product(relative, axis)
    start_radial = relative - start_height*axis
    start_rho = norm2(start_radial)
    surface = surface_side
    best = start_rho - wall%radius
    if (finite) then
      distance = -start_height
      if (distance > best) then
        surface = surface_bottom
        best = distance
      end if
      distance = start_height - wall%length
      if (distance > best) surface = surface_top
    end if
    select case (surface)
    case (surface_bottom)
      normal = -axis
      depth = height
    case (surface_top)
      normal = axis
      depth = wall%length - height
    case default
      if (rho > 0.0_wp) then
        normal = radial/rho
      else if (start_rho > 0.0_wp) then
        normal = start_radial/start_rho
      else
        normal = any_perpendicular(axis)
      end if
      depth = wall%radius - rho
    end select
  end subroutine surface_correction

  !> A unit vector perpendicular to the unit vector `axis`.
  pure function any_perpendicular(axis) result(perpendicular)
    real(wp), intent(in) :: axis(3)
    real(wp) :: perpendicular(3)
    if (abs(axis(1)) < 0.9_wp) then
      perpendicular = [0.0_wp, axis(3), -axis(2)]
    else
      perpendicular = [-axis(3), 0.0_wp, axis(1)]
    end if
    perpendicular = perpendicular - dot_product(perpendicular, axis)*axis
    perpendicular = perpendicular/norm2(perpendicular)
  end function any_perpendicular
end module cylinder_walls
