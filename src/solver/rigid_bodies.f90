!> Rigid bodies in the explicit time loop: *MAT_RIGID parts and *CONSTRAINED_NODAL_RIGID_BODY
!> node sets move as one body with six degrees of freedom (LS-DYNA Theory Manual, "Rigid Body
!> Dynamics"; Benson & Hallquist, "The application of DYNA3D in large scale crashworthiness
!> calculations", 1986).
!>
!> Set-up: mass, centre of mass and inertia tensor from the rigid elements (density times
!> volume, 2x2x2 Gauss points per hexahedron) plus the lumped masses of the body's nodes (the
!> deformable elements' corner masses and *ELEMENT_MASS), which move with the body.
!>
!> Each cycle, after the ordinary velocity update and the walls have acted on every node, the
!> body collects what happened to its nodes as impulses, J_i = m_i (v_i - v_i^body), i.e. the
!> external minus internal forces times the step plus every velocity correction (walls). Their
!> sum and moment about the centre update the linear momentum and the global angular momentum
!> L (central differences). The rotation follows L: with no rotational constraint, the body-frame
!> angular momentum is advanced by the implicit midpoint rule of Euler's equations,
!> Pi+ = Pi + dt (Pi + Pi+)/2 x I^-1 (Pi + Pi+)/2, and R+ = R cay(dt Omega) with the Cayley
!> transform: this is the Lie-Poisson midpoint scheme (Simo & Wong, "Unconditionally stable
!> algorithms for rigid body dynamics that exactly preserve energy and momentum", IJNME 31,
!> 1991), which keeps R orthogonal and conserves |L| and the kinetic energy of a free body
!> exactly (the midpoint rule conserves quadratic invariants). With rotational constraints or
!> prescribed rotations, omega solves the mixed system (I omega)_free = L_free,
!> omega_fixed = target with the current inertia R I R^T, and R+ = cay(dt [omega]) R.
!> Constrained dofs (CMO = 1, CON1, CON2) and prescribed motions act at the centre of mass in
!> global axes; their support work J (v- + v+)/2 is booked as external work, as for nodes.
!> Finally every node gets the velocity that takes it from x^n to x_c+ + R+ X_i over the step,
!> so the ordinary position update moves it rigidly.
module rigid_bodies
  use kinds, only: wp, block_size
  use curves, only: curve_value
  use model, only: model_t, formulation_rigid, motion_velocity, motion_acceleration, motion_displacement
  use hex8_geometry, only: hex8_largest_face_area
  use rigid_body_state, only: rigid_body_state_t
  implicit none
  private

  public :: set_up_rigid_bodies, advance_rigid_bodies, rigid_body_energy, rigid_body_history_row
  public :: add_node_masses, set_up_body, advance_body

  real(wp), parameter :: identity(3, 3) = reshape([1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, &
                                                   0.0_wp, 0.0_wp, 1.0_wp], [3, 3])

contains

  !> *ELEMENT_MASS: lumped masses added to the nodes (before the rigid bodies take theirs).
  subroutine add_node_masses(model, mass)
    type(model_t), intent(in) :: model
    real(wp), intent(inout) :: mass(:)
    if (.not. allocated(model%node_masses)) return
    if (size(model%node_masses) /= size(mass)) return
    mass = mass + model%node_masses
  end subroutine add_node_masses

  !> Mass properties, stable step and initial motion of every rigid body. `mass` holds the
  !> nodal masses of the deformable elements and *ELEMENT_MASS on entry; the rigid elements'
  !> corner masses are added (walls and the velocity update use them). The initial velocity
  !> of a body is the least-squares rigid fit of its nodes' initial velocities: the velocity of
  !> the centre of mass and the rotation about it (exact for the field of a rigid motion, as
  !> *INITIAL_VELOCITY_GENERATION gives); its nodes' velocities are replaced by that field.
  subroutine set_up_rigid_bodies(model, reference, mass, rotary_inertia, velocity, is_rigid_node, bodies, rigid_mass)
    type(model_t), intent(in) :: model
    real(wp), intent(in) :: reference(:, :)
    real(wp), intent(inout) :: mass(:)
    real(wp), intent(in) :: rotary_inertia(:)     !< of the nodes (shells'); the body carries them
    real(wp), intent(inout) :: velocity(:, :)
    logical, intent(out) :: is_rigid_node(:)
    type(rigid_body_state_t), allocatable, intent(out) :: bodies(:)
    real(wp), intent(out) :: rigid_mass
    real(wp), allocatable :: corner_mass(:)
    integer :: b, count

    is_rigid_node = .false.
    rigid_mass = 0.0_wp
    count = 0
    if (allocated(model%rigid_bodies)) count = size(model%rigid_bodies)
    allocate (bodies(count), corner_mass(size(mass)))
    corner_mass = 0.0_wp
    do b = 1, count
      is_rigid_node(model%rigid_bodies(b)%nodes) = .true.
      if (allocated(model%rigid_bodies(b)%merged_parts)) then
        call set_up_body(model, model%rigid_bodies(b)%part, model%rigid_bodies(b)%nodes, reference, mass, &
                         rotary_inertia, velocity, corner_mass, bodies(b), model%rigid_bodies(b)%merged_parts)
      else
        call set_up_body(model, model%rigid_bodies(b)%part, model%rigid_bodies(b)%nodes, reference, mass, &
                         rotary_inertia, velocity, corner_mass, bodies(b))
      end if
      rigid_mass = rigid_mass + bodies(b)%rigid_element_mass
    end do
  end subroutine set_up_rigid_bodies

  !> Mass properties and initial motion of one body: the rigid elements of `part` (0: none, a
  !> nodal rigid body or a weld) and of `merged_parts` and the masses and rotary inertias of `nodes`. The nodes'
  !> rotary inertias (shell nodes) join the inertia tensor as point inertias, so that the body
  !> takes the moments the shells put on its nodes. A body whose nodes lie on a line (two
  !> nodes without rotary inertia) has no inertia about that line: a small isotropic term
  !> (1e-6 of the mean principal inertia) keeps the tensor invertible; forces at nodes on the
  !> line have no moment about it, so the spin it allows stays at round-off level.
  subroutine set_up_body(model, part, nodes, reference, mass, rotary_inertia, velocity, corner_mass, body, &
                         merged_parts)
    type(model_t), intent(in) :: model
    integer, intent(in) :: part
    integer, intent(in) :: nodes(:)
    real(wp), intent(in) :: reference(:, :)
    real(wp), intent(inout) :: mass(:)
    real(wp), intent(in) :: rotary_inertia(:)
    real(wp), intent(inout) :: velocity(:, :)
    real(wp), intent(inout) :: corner_mass(:)     !< scratch (nodes), zero on entry and on return
    type(rigid_body_state_t), intent(inout) :: body
    integer, intent(in), optional :: merged_parts(:)   !< more rigid parts whose elements it has
    integer :: k, node
    real(wp) :: nodal_inertia
    if (present(merged_parts)) then
      call integrate_rigid_elements(model, [part, merged_parts], reference, body, corner_mass)
    else
      call integrate_rigid_elements(model, [part], reference, body, corner_mass)
    end if
    body%rigid_element_mass = body%mass
    call add_point_masses(nodes, reference, mass, body)
    allocate (body%offsets(3, size(nodes)), body%node_mass(size(nodes)), body%node_velocity(3, size(nodes)))
    nodal_inertia = 0.0_wp
    do k = 1, size(nodes)
      node = nodes(k)
      mass(node) = mass(node) + corner_mass(node)
      corner_mass(node) = 0.0_wp
      body%node_mass(k) = mass(node)
      body%offsets(:, k) = reference(:, node) - body%centre
      nodal_inertia = nodal_inertia + rotary_inertia(node)
    end do
    body%inertia = body%inertia + nodal_inertia*identity
    body%inertia = body%inertia + degenerate_inertia(body%inertia)*identity
    body%initial_centre = body%centre
    body%inverse_inertia = inverse3(body%inertia)
    call fit_initial_motion(nodes, body, velocity)
    do k = 1, size(nodes)
      body%node_velocity(:, k) = body%velocity + cross(body%angular_velocity, body%offsets(:, k))
      velocity(:, nodes(k)) = body%node_velocity(:, k)
    end do
  end subroutine set_up_body

  !> The isotropic inertia to add to `inertia` so that it can be inverted: none for a tensor
  !> whose determinant is at least 1e-9 of (trace/3)^3 (principal inertias within a factor of
  !> about 1e-9 of each other at worst); else 1e-6 of the mean principal inertia. A body of one
  !> node without rotary inertia (zero tensor) keeps it: it cannot turn.
  pure real(wp) function degenerate_inertia(inertia)
    real(wp), intent(in) :: inertia(3, 3)
    real(wp) :: mean
    mean = (inertia(1, 1) + inertia(2, 2) + inertia(3, 3))/3.0_wp
    degenerate_inertia = 0.0_wp
    if (mean <= 0.0_wp) return
    if (determinant3(inertia) >= 1.0e-9_wp*mean**3) return
    degenerate_inertia = 1.0e-6_wp*mean
  end function degenerate_inertia

  !> Mass, first and second moments of the part's hexahedra by 2x2x2 Gauss points and of its
  !> shells by 2x2 points on their mid-surface (thickness terms neglected), the centre of mass
  !> and (before the nodal masses) the inertia about it; corner masses rho V / 8 for the
  !> hexahedra's nodes and rho t A / 4 for the shells'; the stable step of the elements from E,
  !> PR and RO.
  subroutine integrate_rigid_elements(model, parts, reference, body, corner_mass)
    type(model_t), intent(in) :: model
    integer, intent(in) :: parts(:)               !< part indices (0: none)
    real(wp), intent(in) :: reference(:, :)
    type(rigid_body_state_t), intent(inout) :: body
    real(wp), intent(inout) :: corner_mass(:)
    real(wp), parameter :: g = 1.0_wp/sqrt(3.0_wp)
    real(wp), parameter :: corner_xi(3, 8) = reshape([-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, &
                                                      -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1], [3, 8])
    real(wp) :: x(3, 8), natural(3), shape(8), derivative(3, 8), jacobian(3, 3), weight, point(3)
    real(wp) :: element_volume, density, wave_modulus, nu, youngs, length
    real(wp) :: xs(block_size, 8), ys(block_size, 8), zs(block_size, 8), area(block_size)
    real(wp) :: first(3), second(3, 3), origin(3)
    integer :: solid, shell, a, i, j, k, material, part, p
    logical :: started

    body%mass = 0.0_wp
    first = 0.0_wp
    second = 0.0_wp
    origin = 0.0_wp
    started = .false.
    do p = 1, size(parts)
      part = parts(p)
      if (part <= 0) cycle
      material = model%parts(part)%material
      density = model%materials(material)%density
      youngs = model%materials(material)%youngs_modulus
      nu = model%materials(material)%poissons_ratio
      wave_modulus = youngs*(1.0_wp - nu)/((1.0_wp + nu)*(1.0_wp - 2.0_wp*nu))
      xs = 0.0_wp
      ys = 0.0_wp
      zs = 0.0_wp
      do solid = 1, size(model%solid_part)
        if (model%solid_part(solid) /= part) cycle
        x = reference(:, model%solid_nodes(:, solid))
        if (.not. started) then
          origin = x(:, 1)
          started = .true.
        end if
        element_volume = 0.0_wp
        do k = 1, 2
          do j = 1, 2
            do i = 1, 2
              natural = g*[real(2*i - 3, wp), real(2*j - 3, wp), real(2*k - 3, wp)]
              do a = 1, 8
                shape(a) = 0.125_wp*product(1.0_wp + natural*corner_xi(:, a))
                derivative(1, a) = 0.125_wp*corner_xi(1, a)*(1.0_wp + natural(2)*corner_xi(2, a))* &
                                   (1.0_wp + natural(3)*corner_xi(3, a))
                derivative(2, a) = 0.125_wp*corner_xi(2, a)*(1.0_wp + natural(1)*corner_xi(1, a))* &
                                   (1.0_wp + natural(3)*corner_xi(3, a))
                derivative(3, a) = 0.125_wp*corner_xi(3, a)*(1.0_wp + natural(1)*corner_xi(1, a))* &
                                   (1.0_wp + natural(2)*corner_xi(2, a))
              end do
              jacobian = matmul(x, transpose(derivative))
              weight = determinant3(jacobian)
              point = matmul(x, shape) - origin
              element_volume = element_volume + weight
              body%mass = body%mass + density*weight
              first = first + density*weight*point
              second = second + density*weight*outer(point, point)
            end do
          end do
        end do
        do a = 1, 8
          corner_mass(model%solid_nodes(a, solid)) = corner_mass(model%solid_nodes(a, solid)) + &
                                                     0.125_wp*density*element_volume
        end do
        xs(1, :) = x(1, :)
        ys(1, :) = x(2, :)
        zs(1, :) = x(3, :)
        call hex8_largest_face_area(1, xs, ys, zs, area)
        length = element_volume/max(area(1), tiny(1.0_wp))
        body%time_step = min(body%time_step, length/sqrt(wave_modulus/density))
      end do
      if (allocated(model%shell_part)) then
        do shell = 1, size(model%shell_part)
          if (model%shell_part(shell) /= part) cycle
          if (.not. started) then
            origin = reference(:, model%shell_nodes(1, shell))
            started = .true.
          end if
          call add_rigid_shell(reference(:, model%shell_nodes(:, shell)), &
                               density*0.25_wp*sum(model%shell_thickness(:, shell)), origin, body%mass, first, second, &
                               element_volume, length)
          ! element_volume: the shell's area here; corner masses as the deformable shells lump them
          do a = 1, 4
            if (a == 4 .and. model%shell_nodes(3, shell) == model%shell_nodes(4, shell)) cycle
            corner_mass(model%shell_nodes(a, shell)) = corner_mass(model%shell_nodes(a, shell)) + &
              density*0.25_wp*sum(model%shell_thickness(:, shell))*element_volume* &
              merge(1.0_wp/3.0_wp, 0.25_wp, model%shell_nodes(3, shell) == model%shell_nodes(4, shell))
          end do
          body%time_step = min(body%time_step, length/sqrt(youngs/(density*(1.0_wp - nu*nu))))
        end do
      end if
    end do
    ! kept as moments about `origin` until the nodal masses are added
    body%centre = origin
    body%angular_momentum = first
    body%inertia = second
  end subroutine integrate_rigid_elements

  !> Mass, first and second moments (about `origin`) of one shell of mass per area
  !> `areal_density` with corners x(3, 4), by 2x2 Gauss points on the bilinear surface; its
  !> area and its time-step length (area / longest side).
  pure subroutine add_rigid_shell(x, areal_density, origin, mass, first, second, area, length)
    real(wp), intent(in) :: x(3, 4), areal_density, origin(3)
    real(wp), intent(inout) :: mass, first(3), second(3, 3)
    real(wp), intent(out) :: area, length
    real(wp), parameter :: g = 1.0_wp/sqrt(3.0_wp)
    real(wp), parameter :: corner_xi(2, 4) = reshape([-1, -1, 1, -1, 1, 1, -1, 1], [2, 4])
    real(wp) :: natural(2), shape(4), tangent_xi(3), tangent_eta(3), normal(3), weight, point(3)
    integer :: a, i, j
    area = 0.0_wp
    do j = 1, 2
      do i = 1, 2
        natural = g*[real(2*i - 3, wp), real(2*j - 3, wp)]
        tangent_xi = 0.0_wp
        tangent_eta = 0.0_wp
        do a = 1, 4
          shape(a) = 0.25_wp*(1.0_wp + natural(1)*corner_xi(1, a))*(1.0_wp + natural(2)*corner_xi(2, a))
          tangent_xi = tangent_xi + 0.25_wp*corner_xi(1, a)*(1.0_wp + natural(2)*corner_xi(2, a))*x(:, a)
          tangent_eta = tangent_eta + 0.25_wp*corner_xi(2, a)*(1.0_wp + natural(1)*corner_xi(1, a))*x(:, a)
        end do
        normal = cross(tangent_xi, tangent_eta)
        weight = norm2(normal)
        point = matmul(x, shape) - origin
        area = area + weight
        mass = mass + areal_density*weight
        first = first + areal_density*weight*point
        second = second + areal_density*weight*outer(point, point)
      end do
    end do
    length = 0.0_wp
    do a = 1, 4
      length = max(length, norm2(x(:, modulo(a, 4) + 1) - x(:, a)))
    end do
    length = area/max(length, tiny(1.0_wp))
  end subroutine add_rigid_shell

  !> Add the nodal masses as point masses, then turn the moments into the centre of mass and
  !> the inertia tensor about it: I = tr(S) 1 - S, S = sum m r r^T about the centre.
  subroutine add_point_masses(nodes, reference, mass, body)
    integer, intent(in) :: nodes(:)
    real(wp), intent(in) :: reference(:, :), mass(:)
    type(rigid_body_state_t), intent(inout) :: body
    real(wp) :: origin(3), first(3), second(3, 3), point(3), centre(3)
    integer :: k
    origin = body%centre
    if (body%mass <= 0.0_wp .and. size(nodes) > 0) origin = reference(:, nodes(1))
    first = body%angular_momentum
    second = body%inertia
    do k = 1, size(nodes)
      point = reference(:, nodes(k)) - origin
      body%mass = body%mass + mass(nodes(k))
      first = first + mass(nodes(k))*point
      second = second + mass(nodes(k))*outer(point, point)
    end do
    centre = 0.0_wp
    if (body%mass > 0.0_wp) centre = first/body%mass
    second = second - body%mass*outer(centre, centre)
    body%inertia = (second(1, 1) + second(2, 2) + second(3, 3))*identity - second
    body%centre = origin + centre
    body%angular_momentum = 0.0_wp
  end subroutine add_point_masses

  !> V and omega minimising sum m |v_i - V_w - omega x (x_i - x_w)|^2 (x_w: mass-weighted centre
  !> of the nodes), then V at the centre of mass and L = I omega.
  subroutine fit_initial_motion(nodes, body, velocity)
    integer, intent(in) :: nodes(:)
    type(rigid_body_state_t), intent(inout) :: body
    real(wp), intent(in) :: velocity(:, :)
    real(wp) :: weight, centre(3), mean_velocity(3), normal(3, 3), moment(3), r(3)
    integer :: k
    weight = sum(body%node_mass)
    body%velocity = 0.0_wp
    body%angular_velocity = 0.0_wp
    if (weight <= 0.0_wp) return
    centre = 0.0_wp
    mean_velocity = 0.0_wp
    do k = 1, size(nodes)
      centre = centre + body%node_mass(k)*body%offsets(:, k)
      mean_velocity = mean_velocity + body%node_mass(k)*velocity(:, nodes(k))
    end do
    centre = centre/weight
    mean_velocity = mean_velocity/weight
    normal = 0.0_wp
    moment = 0.0_wp
    do k = 1, size(nodes)
      r = body%offsets(:, k) - centre
      normal = normal + body%node_mass(k)*(dot_product(r, r)*identity - outer(r, r))
      moment = moment + body%node_mass(k)*cross(r, velocity(:, nodes(k)) - mean_velocity)
    end do
    ! a line of nodes (a two-node body) cannot spin about itself: no rotation is fitted then
    if (abs(determinant3(normal)) > 1.0e-12_wp*max(tiny(1.0_wp), (normal(1, 1) + normal(2, 2) + normal(3, 3))**3)) &
      body%angular_velocity = matmul(inverse3(normal), moment)
    body%velocity = mean_velocity - cross(body%angular_velocity, centre)
    body%angular_momentum = matmul(body%inertia, body%angular_velocity)
  end subroutine fit_initial_motion

  !> One step of every body (see the module header). `velocity` holds v^{n+1/2} of every node
  !> after the ordinary update and the walls; on return the bodies' nodes hold the velocities
  !> of the rigid motion over the step. `support_work` is the work of the constraints and
  !> prescribed motions (external work).
  subroutine advance_rigid_bodies(model, bodies, time, dt, average_dt, coordinates, angular_acceleration, &
                                  rotary_inertia, velocity, support_work)
    type(model_t), intent(in) :: model
    type(rigid_body_state_t), intent(inout) :: bodies(:)
    real(wp), intent(in) :: time, dt, average_dt
    real(wp), intent(in) :: coordinates(:, :)   !< x^n
    real(wp), intent(in) :: angular_acceleration(:, :), rotary_inertia(:)
    real(wp), intent(inout) :: velocity(:, :)
    real(wp), intent(out) :: support_work
    real(wp) :: work
    integer :: b
    support_work = 0.0_wp
    do b = 1, size(bodies)
      call advance_body(model, b, model%rigid_bodies(b)%nodes, bodies(b), time, dt, average_dt, coordinates, &
                        angular_acceleration, rotary_inertia, velocity, work)
      support_work = support_work + work
    end do
  end subroutine advance_rigid_bodies

  !> One step of one body `b` (0: a body with no constraints or prescribed motions, a weld) made
  !> of `nodes`. The impulse of the model on a node is m (v - v_body) for the translations (the
  !> forces, walls and supports of this velocity update) and I dt_avg alpha for the rotations of
  !> shell nodes (their moments; the shells' drilling constraint does not act on a body). With
  !> `constraint_impulse`, each node's impulse from the body, m (v_rigid - v), is returned: what
  !> the rigid link exerted on the node (a weld measures its force from it).
  subroutine advance_body(model, b, nodes, body, time, dt, average_dt, coordinates, angular_acceleration, &
                          rotary_inertia, velocity, support_work, constraint_impulse)
    type(model_t), intent(in) :: model
    integer, intent(in) :: b
    integer, intent(in) :: nodes(:)
    type(rigid_body_state_t), intent(inout) :: body
    real(wp), intent(in) :: time, dt, average_dt
    real(wp), intent(in) :: coordinates(:, :)   !< x^n
    real(wp), intent(in) :: angular_acceleration(:, :), rotary_inertia(:)
    real(wp), intent(inout) :: velocity(:, :)
    real(wp), intent(out) :: support_work
    real(wp), intent(out), optional :: constraint_impulse(:, :)   !< (3, nodes)
    real(wp) :: impulse(3), angular_impulse(3), node_impulse(3), free_velocity(3), free_momentum(3)
    real(wp) :: target(6), new_rotation(3, 3), position(3), previous_velocity(3), previous_omega(3)
    logical :: held(6)
    integer :: k, node, d

    support_work = 0.0_wp
    ! impulses the model gave the body's nodes during this velocity update
    impulse = 0.0_wp
    angular_impulse = 0.0_wp
    do k = 1, size(nodes)
      node = nodes(k)
      node_impulse = body%node_mass(k)*(velocity(:, node) - body%node_velocity(:, k))
      impulse = impulse + node_impulse
      angular_impulse = angular_impulse + cross(coordinates(:, node) - body%centre, node_impulse)
      if (rotary_inertia(node) > 0.0_wp) &
        angular_impulse = angular_impulse + average_dt*rotary_inertia(node)*angular_acceleration(:, node)
    end do
    body%force = impulse/average_dt
    body%moment = angular_impulse/average_dt
    body%impulse = body%impulse + impulse
    previous_velocity = body%velocity
    previous_omega = body%angular_velocity
    ! (a weld of nodes without mass, a beam's before its mass is lumped, has nothing to move)
    free_velocity = body%velocity
    if (body%mass > 0.0_wp) free_velocity = body%velocity + impulse/body%mass
    free_momentum = body%angular_momentum + angular_impulse

    call kinematic_targets(model, b, body, time, dt, average_dt, held, target, body%held_acceleration)
    body%held = held
    ! translations
    body%velocity = free_velocity
    do d = 1, 3
      if (.not. held(d)) cycle
      support_work = support_work + 0.5_wp*body%mass*(target(d) - free_velocity(d))*(target(d) + previous_velocity(d))
      body%velocity(d) = target(d)
    end do
    ! rotations
    if (any(held(4:6))) then
      call constrained_rotation(body, free_momentum, held(4:6), target(4:6), dt, new_rotation)
      support_work = support_work + 0.5_wp*dot_product(body%angular_momentum - free_momentum, &
                                                       previous_omega + body%angular_velocity)
    else
      body%angular_momentum = free_momentum
      call free_rotation(body, dt, new_rotation)
    end if
    body%rotation_angle = body%rotation_angle + dt*body%angular_velocity
    ! new position and the nodes' velocities over the step
    body%centre = body%centre + dt*body%velocity
    body%rotation = new_rotation
    do k = 1, size(nodes)
      node = nodes(k)
      position = body%centre + matmul(new_rotation, body%offsets(:, k))
      body%node_velocity(:, k) = (position - coordinates(:, node))/dt
      if (present(constraint_impulse)) &
        constraint_impulse(:, k) = body%node_mass(k)*(body%node_velocity(:, k) - velocity(:, node))
      velocity(:, node) = body%node_velocity(:, k)
    end do
  end subroutine advance_body

  !> Which dofs (x, y, z, rx, ry, rz) are held this step and at what velocity: CMO constraints
  !> (zero) and active prescribed motions (VAD 0 velocity at mid-step, 2 displacement at the
  !> end of the step, 1 acceleration at the start).
  subroutine kinematic_targets(model, b, body, time, dt, average_dt, held, target, acceleration)
    type(model_t), intent(in) :: model
    integer, intent(in) :: b
    type(rigid_body_state_t), intent(in) :: body
    real(wp), intent(in) :: time, dt, average_dt
    logical, intent(out) :: held(6)
    real(wp), intent(out) :: target(6)
    real(wp), intent(out) :: acceleration(6)  !< of the held dofs (VAD = 1), for the integer-step values
    real(wp) :: local_time, value, current(6), position(6)
    integer :: k, d
    held = .false.
    target = 0.0_wp
    acceleration = 0.0_wp
    if (b <= 0) return
    held = model%rigid_bodies(b)%fixed
    if (.not. allocated(model%rigid_motions)) return
    current(1:3) = body%velocity
    current(4:6) = body%angular_velocity
    position(1:3) = body%centre - body%initial_centre
    position(4:6) = body%rotation_angle
    do k = 1, size(model%rigid_motions)
      associate (motion => model%rigid_motions(k))
        if (motion%body /= b) cycle
        d = motion%dof
        select case (motion%kind)
        case (motion_velocity)
          local_time = time + 0.5_wp*dt
        case (motion_acceleration)
          local_time = time
        case default
          local_time = time + dt
        end select
        if (local_time < motion%birth .or. local_time > motion%death) cycle
        value = motion%scale*curve_value(model%curves(motion%curve), local_time - motion%birth)
        held(d) = .true.
        select case (motion%kind)
        case (motion_velocity)
          target(d) = value
        case (motion_acceleration)
          target(d) = current(d) + average_dt*value
          acceleration(d) = value
        case (motion_displacement)
          target(d) = (value - position(d))/dt
        end select
      end associate
    end do
  end subroutine kinematic_targets

  !> Free rotation over dt with constant L (Lie-Poisson midpoint, see the module header).
  subroutine free_rotation(body, dt, new_rotation)
    type(rigid_body_state_t), intent(inout) :: body
    real(wp), intent(in) :: dt
    real(wp), intent(out) :: new_rotation(3, 3)
    real(wp) :: start(3), finish(3), middle(3), omega(3), change
    integer :: iteration
    start = matmul(transpose(body%rotation), body%angular_momentum)
    finish = start
    do iteration = 1, 100
      middle = 0.5_wp*(start + finish)
      omega = matmul(body%inverse_inertia, middle)
      change = norm2(start + dt*cross(middle, omega) - finish)
      finish = start + dt*cross(middle, omega)
      if (change <= 4.0_wp*epsilon(1.0_wp)*norm2(start)) exit
    end do
    middle = 0.5_wp*(start + finish)
    omega = matmul(body%inverse_inertia, middle)
    new_rotation = matmul(body%rotation, cayley(dt*omega))
    body%angular_velocity = matmul(body%rotation, omega)
  end subroutine free_rotation

  !> Rotation with some global components of omega held: (I omega)_i = L_i for the free i,
  !> omega_i = target_i for the held i, with I = R I0 R^T; L follows, R+ = cay(dt [omega]) R.
  subroutine constrained_rotation(body, free_momentum, held, target, dt, new_rotation)
    type(rigid_body_state_t), intent(inout) :: body
    real(wp), intent(in) :: free_momentum(3), target(3), dt
    logical, intent(in) :: held(3)
    real(wp), intent(out) :: new_rotation(3, 3)
    real(wp) :: inertia(3, 3), system(3, 3), inverse(3, 3), right(3), omega(3)
    integer :: i
    system = 0.0_wp
    right = 0.0_wp
    inertia = matmul(body%rotation, matmul(body%inertia, transpose(body%rotation)))
    do i = 1, 3
      if (held(i)) then
        system(i, :) = identity(i, :)
        right(i) = target(i)
      else
        system(i, :) = inertia(i, :)
        right(i) = free_momentum(i)
      end if
    end do
    inverse = inverse3(system)
    omega = matmul(inverse, right)
    body%angular_velocity = omega
    body%angular_momentum = matmul(inertia, body%angular_velocity)
    new_rotation = matmul(cayley(dt*body%angular_velocity), body%rotation)
  end subroutine constrained_rotation

  !> Kinetic energy, linear momentum and angular momentum of a body at the integer step
  !> between the half steps (as the nodal energies are measured): translation
  !> 1/2 M V- . V+, rotation 1/2 Pi . I^-1 Pi with Pi = R^T L, L = L- + dt/2 (moment now).
  subroutine rigid_body_energy(model, b, body, acceleration, mass, half_step, average_step, kinetic, momentum, &
                               angular_momentum, velocity, body_force, body_moment)
    type(model_t), intent(in) :: model
    integer, intent(in) :: b
    type(rigid_body_state_t), intent(in) :: body
    real(wp), intent(in) :: acceleration(:, :), mass(:), half_step, average_step
    real(wp), intent(out) :: kinetic, momentum(3), angular_momentum(3), velocity(3)
    !> the resultant force and moment about the centre now (held dofs: their motion's)
    real(wp), intent(out), optional :: body_force(3), body_moment(3)
    real(wp) :: force(3), moment(3), nodal(3), body_frame(3)
    integer :: k, node
    force = 0.0_wp
    moment = 0.0_wp
    do k = 1, size(model%rigid_bodies(b)%nodes)
      node = model%rigid_bodies(b)%nodes(k)
      nodal = mass(node)*acceleration(:, node)
      force = force + nodal
      moment = moment + cross(matmul(body%rotation, body%offsets(:, k)), nodal)
    end do
    ! held dofs follow their constraint or motion, not the forces
    where (body%held(1:3)) force = body%mass*body%held_acceleration(1:3)
    if (any(body%held(4:6))) moment = 0.0_wp
    if (present(body_force)) body_force = force
    if (present(body_moment)) body_moment = moment
    velocity = body%velocity + half_step*force/body%mass
    momentum = body%mass*velocity
    angular_momentum = body%angular_momentum + half_step*moment
    body_frame = matmul(transpose(body%rotation), angular_momentum)
    kinetic = 0.5_wp*body%mass*dot_product(body%velocity, body%velocity + average_step*force/body%mass) + &
              0.5_wp*dot_product(body_frame, matmul(body%inverse_inertia, body_frame))
  end subroutine rigid_body_energy

  !> One rbdout row: time, displacement and velocity of the centre of mass, the force of the
  !> model on the body averaged over the interval since the last row (impulse / interval, so
  !> that the history integrates to the impulse), angular momentum about the centre; then
  !> (LS-DYNA's rbdout) the centre's coordinates and acceleration, the rotation (the integral
  !> of the angular velocity), the angular velocity and acceleration (global axes; Euler's
  !> equations, I alpha = M - omega x L) and the body axes in global axes (direction cosines,
  !> row by row: the global axes at the start, turned with the body).
  subroutine rigid_body_history_row(model, b, body, acceleration, mass, time, half_step, interval, sampled_impulse, &
                                    row)
    type(model_t), intent(in) :: model
    integer, intent(in) :: b
    type(rigid_body_state_t), intent(in) :: body
    real(wp), intent(in) :: acceleration(:, :), mass(:), time, half_step, interval
    real(wp), intent(inout) :: sampled_impulse(3)   !< the body's impulse at the last row; now at this one
    real(wp), intent(out) :: row(37)
    real(wp) :: kinetic, momentum(3), angular_momentum(3), velocity(3), force(3), moment(3), omega(3)
    real(wp) :: global_inverse_inertia(3, 3)
    call rigid_body_energy(model, b, body, acceleration, mass, half_step, 0.0_wp, kinetic, momentum, &
                           angular_momentum, velocity, force, moment)
    row(1) = time
    row(2:4) = body%centre - body%initial_centre
    row(5:7) = velocity
    row(8:10) = 0.0_wp
    if (interval > 0.0_wp) row(8:10) = (body%impulse - sampled_impulse)/interval
    row(11:13) = angular_momentum
    sampled_impulse = body%impulse
    global_inverse_inertia = matmul(body%rotation, matmul(body%inverse_inertia, transpose(body%rotation)))
    omega = matmul(global_inverse_inertia, angular_momentum)
    row(14:16) = body%centre
    row(17:19) = force/body%mass
    row(20:22) = body%rotation_angle
    row(23:25) = omega
    row(26:28) = matmul(global_inverse_inertia, moment - cross(omega, angular_momentum))
    ! row k of the direction cosines: body axis k in global axes (column k of the rotation)
    row(29:37) = reshape(body%rotation, [9])
  end subroutine rigid_body_history_row

  !> Cayley transform of the rotation vector a: (1 - [a]/2)^-1 (1 + [a]/2), orthogonal.
  pure function cayley(a) result(rotation)
    real(wp), intent(in) :: a(3)
    real(wp) :: rotation(3, 3), skew(3, 3)
    skew = reshape([0.0_wp, a(3), -a(2), -a(3), 0.0_wp, a(1), a(2), -a(1), 0.0_wp], [3, 3])
    rotation = matmul(inverse3(identity - 0.5_wp*skew), identity + 0.5_wp*skew)
  end function cayley

  pure function cross(a, b) result(c)
    real(wp), intent(in) :: a(3), b(3)
    real(wp) :: c(3)
    c = [a(2)*b(3) - a(3)*b(2), a(3)*b(1) - a(1)*b(3), a(1)*b(2) - a(2)*b(1)]
  end function cross

  pure function outer(a, b) result(c)
    real(wp), intent(in) :: a(3), b(3)
    real(wp) :: c(3, 3)
    c = spread(a, 2, 3)*spread(b, 1, 3)
  end function outer

  pure real(wp) function determinant3(a)
    real(wp), intent(in) :: a(3, 3)
    determinant3 = a(1, 1)*(a(2, 2)*a(3, 3) - a(2, 3)*a(3, 2)) - a(1, 2)*(a(2, 1)*a(3, 3) - a(2, 3)*a(3, 1)) &
                   + a(1, 3)*(a(2, 1)*a(3, 2) - a(2, 2)*a(3, 1))
  end function determinant3

  !> Inverse of a 3x3 matrix by cofactors (zero for a singular one).
  pure function inverse3(a) result(b)
    real(wp), intent(in) :: a(3, 3)
    real(wp) :: b(3, 3), det
    det = determinant3(a)
    b = 0.0_wp
    if (det == 0.0_wp) return
    b(1, 1) = a(2, 2)*a(3, 3) - a(2, 3)*a(3, 2)
    b(1, 2) = a(1, 3)*a(3, 2) - a(1, 2)*a(3, 3)
    b(1, 3) = a(1, 2)*a(2, 3) - a(1, 3)*a(2, 2)
    b(2, 1) = a(2, 3)*a(3, 1) - a(2, 1)*a(3, 3)
    b(2, 2) = a(1, 1)*a(3, 3) - a(1, 3)*a(3, 1)
    b(2, 3) = a(1, 3)*a(2, 1) - a(1, 1)*a(2, 3)
    b(3, 1) = a(2, 1)*a(3, 2) - a(2, 2)*a(3, 1)
    b(3, 2) = a(1, 2)*a(3, 1) - a(1, 1)*a(3, 2)
    b(3, 3) = a(1, 1)*a(2, 2) - a(1, 2)*a(2, 1)
    b = b/det
  end function inverse3
end module rigid_bodies
