!> The explicit update of the meshfree shells (efg_shell_forces) on a hand-built part in the
!> all-Gamma limit: every node keeps its bilinear function, the pairs of a sub-cell point are
!> the cell's four corners with the smoothed (boundary-integrated) gradients over the sub-cell,
!> the shear point has the centre values 1/4 and the one-point gradients. That limit is an FE
!> shell with 4-point membrane and bending and 1-point transverse shear, which must pass the
!> membrane and bending patch tests on an irregular mesh, turned out of the global axes:
!> - membrane: a linear velocity field (stretch and spin) for several steps gives the same
!>   global stress at every cell (1e-9) equal to the plane-stress value (1e-3, the rotation of
!>   the finite steps), and no force at interior nodes (1e-10 of the boundary forces);
!> - bending: a linear angular velocity field gives the same moments at every point, equal to
!>   D kappa, and no moment at interior nodes;
!> - a rigid rotation of 1 rad in finite steps leaves no stress;
!> - a free vibration (central differences with the lumped masses and rotary inertias, the
!>   kernel's own stable step) keeps its energy within 1% over many periods, and stays stable
!>   at the full stable step, and the one-point shear shows no growing zero-energy mode.
program test_efg_shell_forces
  use kinds, only: wp
  use model, only: model_t, formulation_efg
  use material_laws, only: law_elastic
  use efg_shell_part, only: efg_shell_part_t, shell_cell_frame
  use efg_shell_forces, only: efg_shell_solver_t, set_up_efg_shell_solver, compute_efg_shell_forces, &
                              efg_shell_nodal_masses
  use element_work, only: booked_energy, lane_energy_sums, add_kinetic_energy
  use fixtures, only: random_uniform
  use testing, only: test_suite_t, check, check_close, finish_suite
  implicit none

  type(test_suite_t) :: suite
  integer, parameter :: cells_x = 4, cells_y = 3
  real(wp), parameter :: youngs = 210000.0_wp, poisson = 0.3_wp, thickness = 0.8_wp, density = 7.85e-9_wp

  suite%name = "efg_shell_forces"
  call membrane_patch_test(suite)
  call bending_patch_test(suite)
  call rigid_rotation_test(suite)
  call free_vibration_test(suite)
  call finish_suite(suite)

contains

  !> The plate's rotation out of the global axes (rows: the plate's local axes).
  function plate_rotation() result(rotation)
    real(wp) :: rotation(3, 3), a, b
    a = 0.5_wp
    b = 0.3_wp
    ! a turn about z by a, then about the new x by b
    rotation(1, :) = [cos(a), sin(a), 0.0_wp]
    rotation(2, :) = [-sin(a)*cos(b), cos(a)*cos(b), sin(b)]
    rotation(3, :) = [sin(a)*sin(b), -cos(a)*sin(b), cos(b)]
  end function plate_rotation

  !> An irregular cells_x x cells_y quadrilateral plate (interior nodes moved by up to 20% of
  !> the spacing), turned by plate_rotation, and its all-Gamma part.
  subroutine build_plate(model, geometry, points)
    type(model_t), intent(out) :: model
    type(efg_shell_part_t), intent(out) :: geometry
    integer, intent(in) :: points
    integer :: i, j, node, cell, node_count, cell_count, state
    real(wp) :: local(3), rotation(3, 3)
    rotation = plate_rotation()
    state = 4711
    node_count = (cells_x + 1)*(cells_y + 1)
    cell_count = cells_x*cells_y
    allocate (model%coordinates(3, node_count), model%node_ids(node_count))
    do j = 0, cells_y
      do i = 0, cells_x
        node = j*(cells_x + 1) + i + 1
        local = [10.0_wp*i, 8.0_wp*j, 0.0_wp]
        if (i > 0 .and. i < cells_x .and. j > 0 .and. j < cells_y) then
          local(1) = local(1) + 2.0_wp*(random_uniform(state) - 0.5_wp)*2.0_wp
          local(2) = local(2) + 1.6_wp*(random_uniform(state) - 0.5_wp)*2.0_wp
        end if
        model%coordinates(:, node) = matmul(transpose(rotation), local)
        model%node_ids(node) = 100 + node
      end do
    end do
    allocate (model%shell_nodes(4, cell_count), model%shell_part(cell_count), model%shell_ids(cell_count), &
              model%shell_thickness(4, cell_count))
    do j = 0, cells_y - 1
      do i = 0, cells_x - 1
        cell = j*cells_x + i + 1
        node = j*(cells_x + 1) + i + 1
        model%shell_nodes(:, cell) = [node, node + 1, node + cells_x + 2, node + cells_x + 1]
        model%shell_part(cell) = 1
        model%shell_ids(cell) = cell
        model%shell_thickness(:, cell) = thickness
      end do
    end do
    allocate (model%parts(1), model%sections(1), model%materials(1))
    model%materials(1)%law = law_elastic
    model%materials(1)%density = density
    model%materials(1)%youngs_modulus = youngs
    model%materials(1)%poissons_ratio = poisson
    model%sections(1)%element_formulation = 41
    model%sections(1)%integration_points = points
    model%sections(1)%shear_factor = 5.0_wp/6.0_wp
    model%parts(1)%section = 1
    model%parts(1)%material = 1
    model%parts(1)%formulation = formulation_efg
    call all_gamma_part(model, geometry)
  end subroutine build_plate

  !> The all-Gamma part of the model's shells (module comment).
  subroutine all_gamma_part(model, geometry)
    type(model_t), intent(in) :: model
    type(efg_shell_part_t), intent(out) :: geometry
    real(wp), parameter :: vertex(2, 4) = reshape([-1.0_wp, -1.0_wp, 1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp, 1.0_wp], &
                                                  [2, 4])
    real(wp), parameter :: gauss(2) = [0.5_wp - 0.5_wp/sqrt(3.0_wp), 0.5_wp + 0.5_wp/sqrt(3.0_wp)]
    real(wp) :: corners(3, 4), frame(3, 3), xl(4), yl(4), sub(2, 4), physical(2, 4), area, twice_area
    real(wp) :: start(2), finish(2), p(2), edge(2), shape(4), integral(2, 4)
    integer :: cell_count, node_count, c, s, e, q, corner, g, k
    cell_count = size(model%shell_part)
    node_count = size(model%coordinates, 2)
    geometry%part = 1
    geometry%material = 1
    geometry%gamma_nodes = [(k, k=1, node_count)]
    allocate (geometry%particles(0), geometry%transform_node(0), geometry%transform_value(0))
    geometry%transform_offsets = [1]
    geometry%cells = [(c, c=1, cell_count)]
    allocate (geometry%cell_frame(3, 3, cell_count), geometry%cell_area(cell_count), &
              geometry%cell_thickness(cell_count), geometry%point_cell(4*cell_count), geometry%point_area(4*cell_count), &
              geometry%point_offsets(4*cell_count + 1), geometry%pair_node(16*cell_count), &
              geometry%pair_gradient(2, 16*cell_count), geometry%shear_offsets(cell_count + 1), &
              geometry%shear_node(4*cell_count), geometry%shear_value(4*cell_count), &
              geometry%shear_gradient(2, 4*cell_count))
    geometry%mass_node = [(k, k=1, node_count)]
    allocate (geometry%mass_volume(node_count))
    geometry%mass_volume = 0.0_wp
    g = 0
    do c = 1, cell_count
      do corner = 1, 4
        corners(:, corner) = model%coordinates(:, model%shell_nodes(corner, c))
      end do
      frame = shell_cell_frame(corners)
      do corner = 1, 4
        xl(corner) = dot_product(frame(:, 1), corners(:, corner) - corners(:, 1))
        yl(corner) = dot_product(frame(:, 2), corners(:, corner) - corners(:, 1))
      end do
      twice_area = (xl(3) - xl(1))*(yl(4) - yl(2)) - (xl(4) - xl(2))*(yl(3) - yl(1))
      geometry%cell_frame(:, :, c) = frame
      geometry%cell_area(c) = 0.5_wp*twice_area
      geometry%cell_thickness(c) = thickness
      ! sub-cell s: the quarter (in the parametric square) that holds vertex s, counter-clockwise
      do s = 1, 4
        g = g + 1
        sub(:, 1) = vertex(:, s)
        sub(:, 2) = 0.5_wp*(vertex(:, s) + vertex(:, modulo(s, 4) + 1))
        sub(:, 3) = 0.0_wp
        sub(:, 4) = 0.5_wp*(vertex(:, s) + vertex(:, modulo(s + 2, 4) + 1))
        do k = 1, 4
          physical(:, k) = map(xl, yl, sub(:, k))
        end do
        area = 0.0_wp
        integral = 0.0_wp
        do e = 1, 4
          area = area + 0.5_wp*(physical(1, e)*physical(2, modulo(e, 4) + 1) - physical(1, modulo(e, 4) + 1)*physical(2, e))
          start = sub(:, e)
          finish = sub(:, modulo(e, 4) + 1)
          ! a sub-cell edge lies on a line of constant xi or eta: straight, and the bilinear
          ! functions are quadratic along it (two Gauss points are exact)
          edge = map(xl, yl, finish) - map(xl, yl, start)
          do q = 1, 2
            p = start + gauss(q)*(finish - start)
            shape = bilinear(p)
            do corner = 1, 4
              integral(:, corner) = integral(:, corner) + 0.5_wp*shape(corner)*[edge(2), -edge(1)]
            end do
          end do
        end do
        geometry%point_cell(g) = c
        geometry%point_area(g) = area
        geometry%point_offsets(g) = 4*(g - 1) + 1
        do corner = 1, 4
          geometry%pair_node(4*(g - 1) + corner) = model%shell_nodes(corner, c)
          geometry%pair_gradient(:, 4*(g - 1) + corner) = integral(:, corner)/area
        end do
      end do
      geometry%shear_offsets(c) = 4*(c - 1) + 1
      do corner = 1, 4
        k = 4*(c - 1) + corner
        geometry%shear_node(k) = model%shell_nodes(corner, c)
        geometry%shear_value(k) = 0.25_wp
        geometry%mass_volume(model%shell_nodes(corner, c)) = geometry%mass_volume(model%shell_nodes(corner, c)) &
                                                             + 0.25_wp*thickness*geometry%cell_area(c)
      end do
      geometry%shear_gradient(1, 4*c - 3:4*c) = [yl(2) - yl(4), yl(3) - yl(1), yl(4) - yl(2), yl(1) - yl(3)]/twice_area
      geometry%shear_gradient(2, 4*c - 3:4*c) = [xl(4) - xl(2), xl(1) - xl(3), xl(2) - xl(4), xl(3) - xl(1)]/twice_area
    end do
    geometry%point_offsets(4*cell_count + 1) = 16*cell_count + 1
    geometry%shear_offsets(cell_count + 1) = 4*cell_count + 1
    ! edge midpoints: bilinear functions, half of each end corner
    allocate (geometry%midpoint_offsets(4*cell_count + 1), geometry%midpoint_node(8*cell_count), &
              geometry%midpoint_value(8*cell_count))
    do c = 1, cell_count
      do corner = 1, 4
        k = 4*(c - 1) + corner
        geometry%midpoint_offsets(k) = 2*k - 1
        geometry%midpoint_node(2*k - 1:2*k) = [model%shell_nodes(corner, c), model%shell_nodes(modulo(corner, 4) + 1, c)]
        geometry%midpoint_value(2*k - 1:2*k) = 0.5_wp
      end do
    end do
    geometry%midpoint_offsets(4*cell_count + 1) = 8*cell_count + 1
  end subroutine all_gamma_part

  !> The local point of a cell with corners (xl, yl) at parametric coordinates.
  pure function map(xl, yl, parametric) result(point)
    real(wp), intent(in) :: xl(4), yl(4), parametric(2)
    real(wp) :: point(2), values(4)
    values = bilinear(parametric)
    point = [sum(values*xl), sum(values*yl)]
  end function map

  pure function bilinear(parametric) result(shape)
    real(wp), intent(in) :: parametric(2)
    real(wp) :: shape(4)
    shape(1) = 0.25_wp*(1.0_wp - parametric(1))*(1.0_wp - parametric(2))
    shape(2) = 0.25_wp*(1.0_wp + parametric(1))*(1.0_wp - parametric(2))
    shape(3) = 0.25_wp*(1.0_wp + parametric(1))*(1.0_wp + parametric(2))
    shape(4) = 0.25_wp*(1.0_wp - parametric(1))*(1.0_wp + parametric(2))
  end function bilinear

  logical function interior(node)
    integer, intent(in) :: node
    integer :: i, j
    i = modulo(node - 1, cells_x + 1)
    j = (node - 1)/(cells_x + 1)
    interior = i > 0 .and. i < cells_x .and. j > 0 .and. j < cells_y
  end function interior

  !> One force call of the part at the given state; forces, moments, and the part's energy.
  subroutine force_call(model, solver, coordinates, velocity, angular_velocity, dt, force, moment)
    type(model_t), intent(in) :: model
    type(efg_shell_solver_t), intent(inout) :: solver
    real(wp), intent(in), contiguous :: coordinates(:, :), velocity(:, :), angular_velocity(:, :)
    real(wp), intent(in) :: dt
    real(wp), intent(out), contiguous :: force(:, :), moment(:, :)
    real(wp), allocatable :: normal_sum(:, :), area_sum(:)
    allocate (normal_sum(3, size(force, 2)), area_sum(size(force, 2)))
    force = 0.0_wp
    moment = 0.0_wp
    normal_sum = 0.0_wp
    area_sum = 0.0_wp
    call compute_efg_shell_forces(model%materials(1), solver, coordinates, velocity, angular_velocity, dt, force, &
                                  moment, normal_sum, area_sum)
  end subroutine force_call

  !> The global membrane stress tensor (3 x 3) of point lane i of block b (mean over the
  !> thickness points), from its cell's frame.
  function point_global_stress(solver, b, i) result(stress)
    type(efg_shell_solver_t), intent(in) :: solver
    integer, intent(in) :: b, i
    real(wp) :: stress(3, 3), local(2, 2), mean(3), e(3, 2)
    integer :: point, cell
    mean = 0.0_wp
    do point = 1, solver%thickness_points
      mean = mean + solver%point_weight(point)*solver%blocks(b)%stress(i, :, point)
    end do
    local = reshape([mean(1), mean(3), mean(3), mean(2)], [2, 2])
    cell = solver%geometry%point_cell(solver%blocks(b)%first_point + i - 1)
    e = solver%cell_frame(:, 1:2, cell)
    stress = matmul(e, matmul(local, transpose(e)))
  end function point_global_stress

  subroutine membrane_patch_test(suite)
    type(test_suite_t), intent(inout) :: suite
    type(model_t) :: model
    type(efg_shell_part_t) :: geometry
    type(efg_shell_solver_t) :: solver
    real(wp), allocatable :: x(:, :), v(:, :), w(:, :), force(:, :), moment(:, :)
    real(wp) :: rotation(3, 3), gradient(3, 3), stress(3, 3), first(3, 3), expected(3, 3), strain(2, 2)
    real(wp) :: worst, interior_force, boundary_force, dt, factor
    integer :: node, step, b, i, steps
    call build_plate(model, geometry, 2)
    call set_up_efg_shell_solver(model, geometry, solver)
    rotation = plate_rotation()
    ! a linear in-plane velocity field in the plate's axes: stretch, shear and spin
    gradient = 0.0_wp
    gradient(1, 1:2) = [2.0_wp, 0.7_wp]
    gradient(2, 1:2) = [-0.3_wp, -1.0_wp]
    gradient = matmul(transpose(rotation), matmul(gradient, rotation))
    allocate (x(3, size(model%coordinates, 2)), v(3, size(model%coordinates, 2)), w(3, size(model%coordinates, 2)), &
              force(3, size(model%coordinates, 2)), &
              moment(3, size(model%coordinates, 2)))
    x = model%coordinates
    w = 0.0_wp
    dt = 1.0e-5_wp
    steps = 10
    do node = 1, size(x, 2)
      v(:, node) = matmul(gradient, model%coordinates(:, node))
    end do
    call force_call(model, solver, x, v, w, 0.0_wp, force, moment)
    do step = 1, steps
      x = x + dt*v
      call force_call(model, solver, x, v, w, dt, force, moment)
    end do
    first = point_global_stress(solver, 1, 1)
    worst = 0.0_wp
    do b = 1, size(solver%blocks)
      do i = 1, solver%blocks(b)%point_count
        stress = point_global_stress(solver, b, i)
        worst = max(worst, maxval(abs(stress - first)))
      end do
    end do
    call check(suite, "membrane patch: the same global stress at every point (1e-9)", &
               worst <= 1.0e-9_wp*maxval(abs(first)))
    ! plane stress of the total strain steps x dt x sym(L) in the plate's axes (small strain)
    gradient = matmul(rotation, matmul(gradient, transpose(rotation)))
    strain = steps*dt*0.5_wp*(gradient(1:2, 1:2) + transpose(gradient(1:2, 1:2)))
    factor = youngs/(1.0_wp - poisson**2)
    expected = 0.0_wp
    expected(1, 1) = factor*(strain(1, 1) + poisson*strain(2, 2))
    expected(2, 2) = factor*(strain(2, 2) + poisson*strain(1, 1))
    expected(1, 2) = factor*(1.0_wp - poisson)*strain(1, 2)
    expected(2, 1) = expected(1, 2)
    expected = matmul(transpose(rotation), matmul(expected, rotation))
    call check_close(suite, "membrane patch: the plane-stress value (1e-3)", reshape(first, [9]), &
                     reshape(expected, [9]), thr=1.0e-3_wp*maxval(abs(expected)))
    interior_force = 0.0_wp
    boundary_force = 0.0_wp
    do node = 1, size(x, 2)
      if (interior(node)) then
        interior_force = max(interior_force, norm2(force(:, node)), norm2(moment(:, node)))
      else
        boundary_force = max(boundary_force, norm2(force(:, node)))
      end if
    end do
    call check(suite, "membrane patch: no force at interior nodes (1e-10)", &
               interior_force <= 1.0e-10_wp*boundary_force .and. boundary_force > 0.0_wp)
  end subroutine membrane_patch_test

  subroutine bending_patch_test(suite)
    type(test_suite_t), intent(inout) :: suite
    type(model_t) :: model
    type(efg_shell_part_t) :: geometry
    type(efg_shell_solver_t) :: solver
    real(wp), allocatable :: x(:, :), v(:, :), w(:, :), force(:, :), moment(:, :)
    real(wp) :: rotation(3, 3), local(3), kappa(2), moment_tensor(2, 2), global(3, 3), first(3, 3), expected(3, 3)
    real(wp) :: worst, interior_moment, boundary_moment, dt, bending_stiffness, jacobian_area, e(3, 2), shear
    integer :: node, b, i, g
    call build_plate(model, geometry, 3)
    call set_up_efg_shell_solver(model, geometry, solver)
    ! the bending alone: no transverse shear stiffness
    solver%shear_factor = 0.0_wp
    rotation = plate_rotation()
    kappa = [0.02_wp, -0.01_wp]
    allocate (x(3, size(model%coordinates, 2)), v(3, size(model%coordinates, 2)), w(3, size(model%coordinates, 2)), &
              force(3, size(model%coordinates, 2)), &
              moment(3, size(model%coordinates, 2)))
    x = model%coordinates
    v = 0.0_wp
    do node = 1, size(x, 2)
      local = matmul(rotation, model%coordinates(:, node))
      ! k_x = d w_y / dx, k_y = -d w_x / dy
      w(:, node) = matmul(transpose(rotation), [-kappa(2)*local(2), kappa(1)*local(1), 0.0_wp])
    end do
    dt = 1.0e-3_wp
    call force_call(model, solver, x, v, w, 0.0_wp, force, moment)
    call force_call(model, solver, x, v, w, dt, force, moment)
    bending_stiffness = youngs*thickness**3/(12.0_wp*(1.0_wp - poisson**2))
    expected = 0.0_wp
    expected(1, 1) = bending_stiffness*dt*(kappa(1) + poisson*kappa(2))
    expected(2, 2) = bending_stiffness*dt*(kappa(2) + poisson*kappa(1))
    expected = matmul(transpose(rotation), matmul(expected, rotation))
    worst = 0.0_wp
    do b = 1, size(solver%blocks)
      do i = 1, solver%blocks(b)%point_count
        g = solver%blocks(b)%first_point + i - 1
        jacobian_area = solver%geometry%point_area(g)
        associate (m => solver%point_moment(:, g))
          moment_tensor = reshape([m(1), m(3), m(3), m(2)], [2, 2])/jacobian_area
        end associate
        e = solver%cell_frame(:, 1:2, solver%geometry%point_cell(g))
        global = matmul(e, matmul(moment_tensor, transpose(e)))
        if (g == 1) first = global
        worst = max(worst, maxval(abs(global - expected)))
      end do
    end do
    ! three Gauss points through the thickness integrate the linear stress exactly
    call check(suite, "bending patch: M = D kappa at every point (1e-9)", worst <= 1.0e-9_wp*maxval(abs(expected)))
    interior_moment = 0.0_wp
    boundary_moment = 0.0_wp
    do node = 1, size(x, 2)
      if (interior(node)) then
        interior_moment = max(interior_moment, norm2(moment(:, node)), norm2(force(:, node)))
      else
        boundary_moment = max(boundary_moment, norm2(moment(:, node)))
      end if
    end do
    call check(suite, "bending patch: no moment at interior nodes (1e-10)", &
               interior_moment <= 1.0e-10_wp*boundary_moment .and. boundary_moment > 0.0_wp)
    ! the Kirchhoff mode of the same curvature (w quadratic, theta its gradient) with transverse
    ! shear stiffness: the assumed-strain shear sees no shear on the irregular mesh
    call set_up_efg_shell_solver(model, geometry, solver)
    do node = 1, size(x, 2)
      local = matmul(rotation, model%coordinates(:, node))
      v(:, node) = matmul(transpose(rotation), [0.0_wp, 0.0_wp, -0.5_wp*(kappa(1)*local(1)**2 + kappa(2)*local(2)**2)])
    end do
    ! the step's mid-point configuration is the flat plate (the rates are taken there)
    x = model%coordinates + 0.5_wp*dt*v
    call force_call(model, solver, x, v, w, 0.0_wp, force, moment)
    call force_call(model, solver, x, v, w, dt, force, moment)
    shear = 0.0_wp
    do b = 1, size(solver%blocks)
      shear = max(shear, maxval(abs(solver%blocks(b)%shear_stress)))
    end do
    write (*, '(a,es10.3,a,es10.3)') "  efg shell Kirchhoff mode: largest shear stress ", shear, " bending stress ", &
      bending_stiffness*dt*maxval(abs(kappa))*12.0_wp/thickness**2
    call check(suite, "Kirchhoff mode: no transverse shear on the irregular mesh (1e-10 of the bending stress)", &
               shear <= 1.0e-10_wp*bending_stiffness*dt*maxval(abs(kappa))*12.0_wp/thickness**2)
  end subroutine bending_patch_test

  !> Exact rotation steps about an axis through the plate (chord velocities): no strain.
  subroutine rigid_rotation_test(suite)
    type(test_suite_t), intent(inout) :: suite
    type(model_t) :: model
    type(efg_shell_part_t) :: geometry
    type(efg_shell_solver_t) :: solver
    real(wp), allocatable :: x(:, :), v(:, :), w(:, :), force(:, :), moment(:, :), next(:, :)
    real(wp) :: axis(3), angle_step, turn(3, 3), largest, energy, dt, kinetic
    integer :: step, node, b, steps
    call build_plate(model, geometry, 2)
    call set_up_efg_shell_solver(model, geometry, solver)
    axis = [0.3_wp, -0.5_wp, 0.8_wp]
    axis = axis/norm2(axis)
    steps = 100
    angle_step = 1.0_wp/steps
    dt = 1.0e-4_wp
    turn = rotation_matrix(axis, angle_step)
    allocate (x(3, size(model%coordinates, 2)), v(3, size(model%coordinates, 2)), w(3, size(model%coordinates, 2)), &
              force(3, size(model%coordinates, 2)), &
              moment(3, size(model%coordinates, 2)), next(3, size(model%coordinates, 2)))
    x = model%coordinates
    v = 0.0_wp
    w = 0.0_wp
    call force_call(model, solver, x, v, w, 0.0_wp, force, moment)
    do step = 1, steps
      next = matmul(turn, x)
      v = (next - x)/dt
      x = next
      do node = 1, size(x, 2)
        ! the angular velocity that matches chord velocities at mid-step (Cayley: 2 tan(theta/2))
        w(:, node) = axis*2.0_wp*tan(0.5_wp*angle_step)/dt
      end do
      call force_call(model, solver, x, v, w, dt, force, moment)
    end do
    largest = 0.0_wp
    energy = 0.0_wp
    do b = 1, size(solver%blocks)
      largest = max(largest, maxval(abs(solver%blocks(b)%stress)))
      energy = energy + lanes_booked(solver%blocks(b)%internal_energy, solver%blocks(b)%force_power, &
                                      solver%blocks(b)%point_count, 0.0_wp)
    end do
    write (*, '(a,es10.3,a,es10.3,a,es10.3)') "  efg shell rigid rotation: largest stress ", largest, " energy ", energy, &
      " largest shear stress ", maxval([(maxval(abs(solver%blocks(b)%shear_stress)), b=1, size(solver%blocks))])
    call check(suite, "rigid rotation of 1 rad: no membrane, bending or shear stress (1e-9 E)", &
               max(largest, maxval([(maxval(abs(solver%blocks(b)%shear_stress)), b=1, size(solver%blocks))])) &
               <= 1.0e-9_wp*youngs)
    ! against the kinetic energy of the rotation (round-off of the forces times the large speeds)
    kinetic = 0.0_wp
    do node = 1, size(x, 2)
      kinetic = kinetic + 0.5_wp*density*geometry%mass_volume(node)*sum(v(:, node)**2)
    end do
    call check(suite, "rigid rotation of 1 rad: no strain energy (1e-10 of the kinetic)", &
               abs(energy) <= 1.0e-10_wp*kinetic)
  end subroutine rigid_rotation_test

  pure function rotation_matrix(axis, angle) result(r)
    real(wp), intent(in) :: axis(3), angle
    real(wp) :: r(3, 3), k(3, 3)
    integer :: i
    k = reshape([0.0_wp, axis(3), -axis(2), -axis(3), 0.0_wp, axis(1), axis(2), -axis(1), 0.0_wp], [3, 3])
    r = sin(angle)*k + (1.0_wp - cos(angle))*matmul(k, k)
    do i = 1, 3
      r(i, i) = r(i, i) + 1.0_wp
    end do
  end function rotation_matrix

  !> Central differences with the lumped masses: a free plate set moving with a bending and a
  !> membrane velocity field (and a checkerboard of out-of-plane velocity, the mode the
  !> one-point shear cannot see); the energy (kinetic + internal) keeps its initial value.
  subroutine free_vibration_test(suite)
    type(test_suite_t), intent(inout) :: suite
    type(model_t) :: model
    type(efg_shell_part_t) :: geometry
    type(efg_shell_solver_t) :: solver
    real(wp), allocatable :: x(:, :), v(:, :), w(:, :), force(:, :), moment(:, :), mass(:), inertia(:)
    real(wp), allocatable :: acceleration(:, :), angular_acceleration(:, :)
    real(wp) :: rotation(3, 3), local(3), dt, step, kinetic, internal, initial, worst, checker, average
    integer :: node, cycle, b, cycles, i, j
    call build_plate(model, geometry, 3)
    call set_up_efg_shell_solver(model, geometry, solver)
    call efg_shell_nodal_masses(solver, size(model%coordinates, 2), mass, inertia)
    rotation = plate_rotation()
    allocate (x(3, size(model%coordinates, 2)), v(3, size(model%coordinates, 2)), w(3, size(model%coordinates, 2)), &
              force(3, size(model%coordinates, 2)), &
              moment(3, size(model%coordinates, 2)), acceleration(3, size(model%coordinates, 2)), &
              angular_acceleration(3, size(model%coordinates, 2)))
    x = model%coordinates
    do node = 1, size(x, 2)
      local = matmul(rotation, model%coordinates(:, node))
      i = modulo(node - 1, cells_x + 1)
      j = (node - 1)/(cells_x + 1)
      checker = merge(1.0_wp, -1.0_wp, modulo(i + j, 2) == 0)
      v(:, node) = matmul(transpose(rotation), [100.0_wp*sin(local(2)/10.0_wp), 0.0_wp, &
                                                 500.0_wp*sin(local(1)/12.0_wp) + 50.0_wp*checker])
      w(:, node) = 0.0_wp
    end do
    call force_call(model, solver, x, v, w, 0.0_wp, force, moment)
    step = 0.0_wp
    dt = minval(solver%block_time_step)*0.9_wp
    cycles = 4000
    worst = 0.0_wp
    initial = 0.0_wp
    do cycle = 0, cycles
      do node = 1, size(x, 2)
        acceleration(:, node) = -force(:, node)/mass(node)
        angular_acceleration(:, node) = -moment(:, node)/inertia(node)
      end do
      ! energies at t^n as the solver measures them (energy_balance, add_kinetic_energy)
      average = 0.5_wp*(step + dt)
      kinetic = 0.0_wp
      internal = 0.0_wp
      do node = 1, size(x, 2)
        call add_kinetic_energy(mass(node), v(:, node), acceleration(:, node), average, kinetic, internal)
        call add_kinetic_energy(inertia(node), w(:, node), angular_acceleration(:, node), average, kinetic, internal)
      end do
      do b = 1, size(solver%blocks)
        internal = internal + lanes_booked(solver%blocks(b)%internal_energy, solver%blocks(b)%force_power, &
                                            solver%blocks(b)%point_count, 0.25_wp*(dt - step)) &
                   + lanes_booked(solver%blocks(b)%shear_energy, solver%blocks(b)%shear_power, &
                                   solver%blocks(b)%cell_count, 0.25_wp*(dt - step))
      end do
      if (cycle == 0) initial = kinetic + internal
      worst = max(worst, abs(kinetic + internal - initial))
      if (cycle == cycles) exit
      v = v + average*acceleration
      w = w + average*angular_acceleration
      x = x + dt*v
      step = dt
      call force_call(model, solver, x, v, w, step, force, moment)
    end do
    write (*, '(a,es10.3,a,es10.3,a,es10.3)') "  efg shell free vibration: step ", dt, " energy drift ", &
      worst/initial, " largest speed ", maxval(abs(v))
    call check(suite, "free vibration at 0.9 of the kernel's step: energy within 1% over 4000 cycles", &
               worst <= 0.01_wp*initial)
    call check(suite, "free vibration: no growing mode (speeds stay bounded)", maxval(abs(v)) < 2000.0_wp)
  end subroutine free_vibration_test

  !> The energy of a block's first `count` lanes as the solver books it.
  pure real(wp) function lanes_booked(energy, power, count, step_correction)
    real(wp), intent(in) :: energy(:), power(:), step_correction
    integer, intent(in) :: count
    real(wp) :: sums(3)
    sums = lane_energy_sums(energy, power, count)
    lanes_booked = booked_energy(sums(1), sums(2), step_correction)
  end function lanes_booked
end program test_efg_shell_forces
