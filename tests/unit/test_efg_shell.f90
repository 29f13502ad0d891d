!> Unit tests of the meshfree (EFG) shell set-up (docs/efg_shells.md) on hand-built plates: an
!> irregular flat quadrilateral mesh, the same with triangles mixed in, and a curved
!> (cylindrical) patch, with the three kernels (ISPLINE 0, 1, 2):
!> * the coupled functions at random points of every cell: partition of unity and linear
!>   reproduction in the cell's plane (1e-12), and of the 3D position on the cell (1e-12: on the
!>   cylinder too, where the basis has the height term), Kronecker delta at the Gamma vertices,
!>   particle functions exactly zero on every edge between two Gamma nodes (the boundary edges);
!> * the smoothed gradients of a linear field exact at every membrane/bending point and at the
!>   shear points (1e-10); the smoothed gradient of the 3D position equal to that of the cell's
!>   own bilinear surface at every point (1e-10; on a flat cell its in-plane axes: a rigid
!>   rotation gives the membrane strain of the FE shell, none on a flat cell, also on the
!>   cylinder); the integration constraint sum_g bbar_I(g) W_g = 0 for every interior particle on
!>   flat meshes (1e-12 relative);
!> * sub-cell areas adding up to the cell areas and to the plate's area; row-sum masses adding up
!>   to t A; transformation rows summing to 1 and reproducing the particle's 3D position;
!> * node classes (boundary edges and extra Gamma nodes), point counts, and error messages;
!> * identical parts for one and three threads (flat and cylinder);
!> * the set-up seconds of a 100 x 100 plate, flat and wrapped on a cylinder (printed; linear in
!>   the number of cells).
!> Interior nodes are moved randomly by up to 25% of the cell size; the plate's outline stays a
!> rectangle (2 x 1), so its area is known exactly.
program test_efg_shell
  use kinds, only: wp
  use error_handling, only: error_t
  use model, only: model_t, formulation_efg, formulation_fe, section_shell, kernel_cubic_box, &
                   kernel_quadratic_box, kernel_cubic_sphere, boundary_coupled, integration_local_boundary
  use material_laws, only: law_elastic
  use efg_kernel, only: quadratic_spline
  use efg_shell_part, only: efg_shell_part_t
  use efg_shell_setup, only: build_efg_shell_part
  use efg_shell_supports, only: shell_supports_t, build_shell_supports, corner_count
  use efg_shell_functions, only: shell_cell_context_t, prepare_shell_cell, evaluate_shell_functions, &
                                 corner_functions
  use efg_neighbour_search, only: particle_grid_t, build_particle_grid
  use testing, only: test_suite_t, check, check_close, finish_suite
  use fixtures, only: random_uniform
  use omp_lib, only: omp_get_max_threads, omp_set_num_threads
  implicit none

  type(test_suite_t) :: suite
  integer :: random_state = 20041104
  real(wp), parameter :: tight = 1.0e-12_wp
  real(wp), parameter :: plate_length = 2.0_wp, plate_width = 1.0_wp, thickness = 0.1_wp
  !> A linear field u = c + g . y in a cell's plane.
  real(wp), parameter :: field_gradient(2) = [0.7_wp, -0.4_wp], field_constant = 0.3_wp

  suite%name = "efg_shell"
  call test_quadratic_spline()
  call test_mesh("flat quads, cubic box", 8, 6, .false., 0.0_wp, kernel_cubic_box, [1.1_wp, 1.1_wp])
  call test_mesh("flat mixed, quadratic box", 8, 6, .true., 0.0_wp, kernel_quadratic_box, [1.3_wp, 1.2_wp])
  call test_mesh("flat mixed, circle", 8, 6, .true., 0.0_wp, kernel_cubic_sphere, [1.5_wp, 1.5_wp])
  call test_mesh("cylinder quads, cubic box", 8, 6, .false., 1.5_wp, kernel_cubic_box, [1.1_wp, 1.1_wp])
  call test_mesh("cylinder mixed, circle", 8, 6, .true., 1.5_wp, kernel_cubic_sphere, [1.3_wp, 1.3_wp])
  call test_node_classes()
  call test_errors()
  call test_thread_counts()
  call test_setup_time()
  call finish_suite(suite)

contains

  !> A plate of nx x ny cells over [0, 2] x [0, 1] with interior nodes moved by up to 25% of a
  !> cell; with `triangles`, every third cell is split into two triangles; with radius > 0 the
  !> plate is wrapped on a cylinder of that radius about the y axis.
  function plate_model(nx, ny, triangles, radius, kernel, scale) result(model)
    integer, intent(in) :: nx, ny, kernel
    logical, intent(in) :: triangles
    real(wp), intent(in) :: radius, scale(2)
    type(model_t) :: model
    real(wp) :: x, y
    integer :: i, j, node, cell, cell_count

    allocate (model%coordinates(3, (nx + 1)*(ny + 1)), model%node_ids((nx + 1)*(ny + 1)))
    do i = 0, nx
      do j = 0, ny
        node = grid_node(i, j, ny)
        model%node_ids(node) = 1000 + node
        x = plate_length*i/nx
        y = plate_width*j/ny
        if (i > 0 .and. i < nx .and. j > 0 .and. j < ny) then
          x = x + 0.25_wp*plate_length/nx*random_uniform(random_state)
          y = y + 0.25_wp*plate_width/ny*random_uniform(random_state)
        end if
        if (radius > 0.0_wp) then
          model%coordinates(:, node) = [radius*sin(x/radius), y, radius*(1.0_wp - cos(x/radius))]
        else
          model%coordinates(:, node) = [x, y, 0.0_wp]
        end if
      end do
    end do
    cell_count = nx*ny
    if (triangles) cell_count = cell_count + count([((modulo(i + j, 3) == 0, j=0, ny - 1), i=0, nx - 1)])
    allocate (model%shell_nodes(4, cell_count), model%shell_part(cell_count), model%shell_ids(cell_count), &
              model%shell_thickness(4, cell_count))
    cell = 0
    do i = 0, nx - 1
      do j = 0, ny - 1
        if (triangles .and. modulo(i + j, 3) == 0) then
          cell = cell + 1
          model%shell_nodes(:, cell) = [grid_node(i, j, ny), grid_node(i + 1, j, ny), &
                                        grid_node(i + 1, j + 1, ny), grid_node(i + 1, j + 1, ny)]
          cell = cell + 1
          model%shell_nodes(:, cell) = [grid_node(i, j, ny), grid_node(i + 1, j + 1, ny), &
                                        grid_node(i, j + 1, ny), grid_node(i, j + 1, ny)]
        else
          cell = cell + 1
          model%shell_nodes(:, cell) = [grid_node(i, j, ny), grid_node(i + 1, j, ny), &
                                        grid_node(i + 1, j + 1, ny), grid_node(i, j + 1, ny)]
        end if
      end do
    end do
    model%shell_ids = [(500 + cell, cell=1, cell_count)]
    model%shell_part = 1
    model%shell_thickness = thickness
    allocate (model%solid_nodes(8, 0), model%solid_part(0), model%solid_ids(0))
    allocate (model%parts(2), model%sections(2), model%materials(1))
    model%materials(1)%id = 1
    model%materials(1)%law = law_elastic
    model%materials(1)%density = 7.85e-9_wp
    model%materials(1)%youngs_modulus = 210000.0_wp
    model%materials(1)%poissons_ratio = 0.3_wp
    model%sections(1)%id = 3
    model%sections(1)%kind = section_shell
    model%sections(1)%element_formulation = 41
    model%sections(1)%support_scale = [scale(1), scale(2), scale(1)]
    model%sections(1)%kernel = kernel
    model%sections(1)%boundary_treatment = boundary_coupled
    model%sections(1)%domain_integration = integration_local_boundary
    model%sections(1)%thickness = thickness
    model%sections(2)%id = 4
    model%sections(2)%kind = section_shell
    model%sections(2)%element_formulation = 2
    model%parts(1)%id = 7
    model%parts(1)%section = 1
    model%parts(1)%material = 1
    model%parts(1)%formulation = formulation_efg
    model%parts(2)%id = 8
    model%parts(2)%section = 2
    model%parts(2)%material = 1
    model%parts(2)%formulation = formulation_fe
  end function plate_model

  !> Node number of grid point (i, j) of a plate with ny cells across.
  pure integer function grid_node(i, j, ny)
    integer, intent(in) :: i, j, ny
    grid_node = i*(ny + 1) + j + 1
  end function grid_node

  !> The quadratic spline (ISPLINE 1): 1 at 0, C1 at the knot 1/2, zero from 1 on.
  subroutine test_quadratic_spline()
    real(wp) :: value(4), derivative(4)
    call quadratic_spline(0.0_wp, value(1), derivative(1))
    call quadratic_spline(0.5_wp, value(2), derivative(2))
    call quadratic_spline(0.5_wp + 1.0e-9_wp, value(3), derivative(3))
    call quadratic_spline(1.0_wp, value(4), derivative(4))
    call check_close(suite, "quadratic spline: values", value, [1.0_wp, 0.5_wp, 0.5_wp, 0.0_wp], thr=1.0e-8_wp)
    call check_close(suite, "quadratic spline: slopes, continuous at 1/2", derivative, &
                     [0.0_wp, -2.0_wp, -2.0_wp, 0.0_wp], thr=1.0e-8_wp)
  end subroutine test_quadratic_spline

  !> Every check of the functions and of the built part on one mesh.
  subroutine test_mesh(label, nx, ny, triangles, radius, kernel, scale)
    character(len=*), intent(in) :: label
    integer, intent(in) :: nx, ny, kernel
    logical, intent(in) :: triangles
    real(wp), intent(in) :: radius, scale(2)
    type(model_t) :: model
    type(efg_shell_part_t) :: geometry
    type(error_t), allocatable :: error
    logical, allocatable :: extra(:)
    logical :: flat

    flat = radius == 0.0_wp
    model = plate_model(nx, ny, triangles, radius, kernel, scale)
    allocate (extra(size(model%coordinates, 2)))
    extra = .false.
    call check_functions(label, model, kernel, scale, extra)
    call build_efg_shell_part(model, 1, extra, geometry, error)
    if (allocated(error)) then
      call check(suite, label//": set-up succeeds", .false., error%message)
      return
    end if
    call check_part(label, model, geometry, radius)
  end subroutine test_mesh

  !> Partition of unity, linear reproduction, Kronecker delta and vanishing particle functions
  !> on Gamma-Gamma edges, at random points of every cell.
  subroutine check_functions(label, model, kernel, scale, extra)
    character(len=*), intent(in) :: label
    type(model_t), intent(in) :: model
    integer, intent(in) :: kernel
    real(wp), intent(in) :: scale(2)
    logical, intent(in) :: extra(:)
    type(shell_supports_t) :: supports
    type(particle_grid_t) :: grid
    type(shell_cell_context_t) :: context
    real(wp), allocatable :: values(:), node_planar(:, :), node_position(:, :)
    real(wp) :: parametric(2), planar(2), residual, unity, reproduction, kronecker, edge_value, worst_residual
    real(wp) :: spatial_reproduction
    real(wp) :: corners_parametric(2, 4), fraction
    integer :: k, cell, sample, rank, a, b, n, next
    logical :: particle_on_edge

    call build_shell_supports(model, 1, scale, kernel, extra, supports)
    call build_particle_grid(supports%particle_coordinates, supports%search_radius, grid)
    unity = 0.0_wp
    reproduction = 0.0_wp
    spatial_reproduction = 0.0_wp
    kronecker = 0.0_wp
    edge_value = 0.0_wp
    worst_residual = 0.0_wp
    particle_on_edge = .false.
    do k = 1, size(supports%cells)
      cell = supports%cells(k)
      call prepare_shell_cell(supports, grid, model%coordinates, model%shell_nodes(:, cell), context)
      n = context%node_count
      if (allocated(values)) deallocate (values, node_planar, node_position)
      allocate (values(n), node_planar(2, n), node_position(3, n))
      do a = 1, context%particle_count
        node_planar(:, context%particle_local(a)) = context%particle_planar(:, a)
        node_position(:, context%particle_local(a)) = context%particle_position(:, a)
      end do
      do a = 1, context%corners
        node_planar(:, context%corner_local(a)) = context%planar(:, a)
        node_position(:, context%corner_local(a)) = context%positions(:, a)
      end do
      if (context%corners == 3) then
        corners_parametric = reshape([0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, 1.0_wp], [2, 4])
      else
        corners_parametric = reshape([-1.0_wp, -1.0_wp, 1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp, 1.0_wp], [2, 4])
      end if
      ! random interior points
      do sample = 1, 6
        if (context%corners == 3) then
          parametric = 0.5_wp + 0.5_wp*[random_uniform(random_state), random_uniform(random_state)]
          if (sum(parametric) > 1.0_wp) parametric = 1.0_wp - parametric
        else
          parametric = [random_uniform(random_state), random_uniform(random_state)]
        end if
        call evaluate_shell_functions(context, parametric, planar, values, rank, residual)
        worst_residual = max(worst_residual, residual)
        unity = max(unity, abs(sum(values) - 1.0_wp))
        reproduction = max(reproduction, maxval(abs(matmul(node_planar, values) - planar))/context%scale_length)
        spatial_reproduction = max(spatial_reproduction, maxval(abs(matmul(node_position, values) - &
          matmul(context%positions, corner_functions(context%corners, parametric))))/context%scale_length)
      end do
      ! corners: Kronecker delta at Gamma corners (and PU at particle corners)
      do a = 1, context%corners
        call evaluate_shell_functions(context, corners_parametric(:, a), planar, values, rank, residual)
        unity = max(unity, abs(sum(values) - 1.0_wp))
        if (.not. context%corner_is_particle(a)) then
          values(context%corner_local(a)) = values(context%corner_local(a)) - 1.0_wp
          kronecker = max(kronecker, maxval(abs(values)))
        end if
      end do
      ! edges whose two corners are Gamma nodes: every particle function is exactly zero there
      do a = 1, context%corners
        next = modulo(a, context%corners) + 1
        if (context%corner_is_particle(a) .or. context%corner_is_particle(next)) cycle
        do sample = 1, 3
          fraction = 0.5_wp + 0.5_wp*random_uniform(random_state)
          parametric = corners_parametric(:, a) + fraction*(corners_parametric(:, next) - corners_parametric(:, a))
          call evaluate_shell_functions(context, parametric, planar, values, rank, residual)
          do b = 1, context%particle_count
            particle_on_edge = particle_on_edge .or. abs(values(context%particle_local(b))) > 0.0_wp
            edge_value = max(edge_value, abs(values(context%particle_local(b))))
          end do
        end do
      end do
    end do
    write (*, '(a)') "efg_shell: "//label//": |sum Psi - 1| "//trim(real_text(unity))//", linear "// &
      "reproduction "//trim(real_text(reproduction))//", Kronecker "//trim(real_text(kronecker))// &
      ", moment residual "//trim(real_text(worst_residual))//", 3D position "//trim(real_text(spatial_reproduction))
    call check(suite, label//": interior particles exist", size(supports%particles) > 0)
    call check(suite, label//": moment residual at round-off", worst_residual < 1.0e-12_wp, real_text(worst_residual))
    call check(suite, label//": partition of unity", unity < tight, real_text(unity))
    call check(suite, label//": linear reproduction in the cell's plane", reproduction < tight, real_text(reproduction))
    call check(suite, label//": the 3D position on the cell reproduced", spatial_reproduction < tight, &
               real_text(spatial_reproduction))
    call check(suite, label//": Kronecker delta at Gamma vertices", kronecker < tight, real_text(kronecker))
    call check(suite, label//": particle functions exactly zero on Gamma edges", .not. particle_on_edge, &
               real_text(edge_value))
  end subroutine check_functions

  !> The built part: points, gradients of a linear field, integration constraint (flat), areas,
  !> masses and transformation rows.
  subroutine check_part(label, model, geometry, radius)
    character(len=*), intent(in) :: label
    type(model_t), intent(in) :: model
    type(efg_shell_part_t), intent(in) :: geometry
    real(wp), intent(in) :: radius                  !< of the cylinder; 0 for a flat plate
    logical :: flat
    real(wp), allocatable :: constraint(:, :), scale(:)
    integer, allocatable :: slot(:)
    real(wp) :: gradient(2), origin(3), error_gradient, error_shear, worst, value_sum, planar(2), position(3)
    real(wp) :: transform_sum, transform_position, expected_points, position_gradient(3, 2), error_tangent
    integer :: g, pair, c, k, j, node, points, particle
    logical :: ascending, pairs_listed

    flat = radius == 0.0_wp
    ! point counts and ascending pairs
    expected_points = 0
    do c = 1, size(geometry%cells)
      expected_points = expected_points + corner_count(model%shell_nodes(:, geometry%cells(c)))
    end do
    points = size(geometry%point_cell)
    call check(suite, label//": one point per sub-cell (4 per quad, 3 per triangle)", points == nint(expected_points))
    ascending = .true.
    pairs_listed = .true.
    do g = 1, points
      pairs_listed = pairs_listed .and. geometry%point_offsets(g + 1) > geometry%point_offsets(g)
      do pair = geometry%point_offsets(g) + 1, geometry%point_offsets(g + 1) - 1
        ascending = ascending .and. geometry%pair_node(pair) > geometry%pair_node(pair - 1)
      end do
    end do
    call check(suite, label//": pairs ascending within each point", ascending .and. pairs_listed)

    ! smoothed gradients of a linear field of each cell's plane, at every point
    error_gradient = 0.0_wp
    do g = 1, points
      c = geometry%point_cell(g)
      origin = model%coordinates(:, model%shell_nodes(1, geometry%cells(c)))
      gradient = 0.0_wp
      do pair = geometry%point_offsets(g), geometry%point_offsets(g + 1) - 1
        gradient = gradient + geometry%pair_gradient(:, pair)*field_value(geometry, c, origin, &
                                                                          model%coordinates(:, geometry%pair_node(pair)))
      end do
      error_gradient = max(error_gradient, maxval(abs(gradient - field_gradient)))
    end do
    ! smoothed gradient of the 3D position: that of the cell's bilinear surface (the FE shell's;
    ! on a flat cell its in-plane axes e1, e2, with no component along the normal), so that a
    ! rigid rotation gives no membrane strain rate beyond the FE shell's
    error_tangent = 0.0_wp
    do g = 1, points
      c = geometry%point_cell(g)
      position_gradient = 0.0_wp
      do pair = geometry%point_offsets(g), geometry%point_offsets(g + 1) - 1
        position_gradient(:, 1) = position_gradient(:, 1) + &
                                  geometry%pair_gradient(1, pair)*model%coordinates(:, geometry%pair_node(pair))
        position_gradient(:, 2) = position_gradient(:, 2) + &
                                  geometry%pair_gradient(2, pair)*model%coordinates(:, geometry%pair_node(pair))
      end do
      error_tangent = max(error_tangent, maxval(abs(position_gradient - &
        bilinear_position_gradient(model, geometry%cells(c), geometry%cell_frame(:, :, c), g - first_point(geometry, c) + 1))))
    end do
    write (*, '(a)') "efg_shell: "//label//": smoothed gradient error "//trim(real_text(error_gradient))// &
      ", position gradient against the cell surface's "//trim(real_text(error_tangent))
    call check(suite, label//": smoothed gradient of the position is the cell surface's", &
               error_tangent < 1.0e-10_wp, real_text(error_tangent))
    call check(suite, label//": smoothed gradients of a linear field exact at every point", error_gradient < 1.0e-10_wp, &
               real_text(error_gradient))
    ! shear points: values reproduce the field at the centre, gradients exact
    error_shear = 0.0_wp
    value_sum = 0.0_wp
    do c = 1, size(geometry%cells)
      origin = model%coordinates(:, model%shell_nodes(1, geometry%cells(c)))
      gradient = 0.0_wp
      planar = 0.0_wp
      value_sum = max(value_sum, abs(sum(geometry%shear_value(geometry%shear_offsets(c):geometry%shear_offsets(c + 1) - 1)) &
                                     - 1.0_wp))
      do pair = geometry%shear_offsets(c), geometry%shear_offsets(c + 1) - 1
        gradient = gradient + geometry%shear_gradient(:, pair)*field_value(geometry, c, origin, &
                                                                           model%coordinates(:, geometry%shear_node(pair)))
      end do
      error_shear = max(error_shear, maxval(abs(gradient - field_gradient)))
    end do
    call check(suite, label//": shear point values sum to 1", value_sum < tight, real_text(value_sum))
    call check(suite, label//": shear point gradients of a linear field exact", error_shear < 1.0e-10_wp, &
               real_text(error_shear))

    ! areas
    worst = 0.0_wp
    do c = 1, size(geometry%cells)
      worst = max(worst, abs(sum(geometry%point_area, mask=geometry%point_cell == c) - geometry%cell_area(c)))
    end do
    call check(suite, label//": sub-cell areas add up to the cell's", worst < tight, real_text(worst))
    if (flat) call check_close(suite, label//": cell areas add up to the plate's", sum(geometry%cell_area), &
                               plate_length*plate_width, rel=tight)
    ! masses
    call check_close(suite, label//": row-sum masses add up to t A", sum(geometry%mass_volume), &
                     thickness*sum(geometry%cell_area), rel=tight)
    call check(suite, label//": every mass positive", all(geometry%mass_volume > 0.0_wp))
    call check(suite, label//": every node of the part has a mass", size(geometry%mass_node) == &
               size(geometry%gamma_nodes) + size(geometry%particles))

    ! integration constraint for every particle, in 3D (cells' frames differ by rotations); on
    ! the cylinder the cells' planes differ, so the figure is only printed there
    block
      allocate (slot(size(model%coordinates, 2)), constraint(3, size(geometry%particles)), scale(size(geometry%particles)))
      slot = 0
      do k = 1, size(geometry%particles)
        slot(geometry%particles(k)) = k
      end do
      constraint = 0.0_wp
      scale = 0.0_wp
      do g = 1, points
        c = geometry%point_cell(g)
        do pair = geometry%point_offsets(g), geometry%point_offsets(g + 1) - 1
          k = slot(geometry%pair_node(pair))
          if (k == 0) cycle
          constraint(:, k) = constraint(:, k) + geometry%point_area(g)*matmul(geometry%cell_frame(:, 1:2, c), &
                                                                              geometry%pair_gradient(:, pair))
          scale(k) = scale(k) + geometry%point_area(g)*norm2(geometry%pair_gradient(:, pair))
        end do
      end do
      worst = 0.0_wp
      do k = 1, size(geometry%particles)
        if (.not. flat) then
          ! the part along the cylinder's surface at the particle (its normal points to the axis)
          origin = model%coordinates(:, geometry%particles(k)) - [0.0_wp, model%coordinates(2, geometry%particles(k)), &
                                                                  radius]
          origin = origin/norm2(origin)
          constraint(:, k) = constraint(:, k) - dot_product(constraint(:, k), origin)*origin
        end if
        worst = max(worst, norm2(constraint(:, k))/scale(k))
      end do
      write (*, '(a)') "efg_shell: "//label//": integration constraint (relative, along the surface) "// &
        trim(real_text(worst))
      if (flat) call check(suite, label//": integration constraint sum_g bbar W_g = 0 (relative)", worst < tight, &
                           real_text(worst))
    end block

    ! transformation rows: sum to 1 and reproduce the particle's 3D position (the height term of
    ! the basis on the cylinder)
    transform_sum = 0.0_wp
    transform_position = 0.0_wp
    call check(suite, label//": one transformation row per particle", &
               size(geometry%transform_offsets) == size(geometry%particles) + 1)
    do j = 1, size(geometry%particles)
      particle = geometry%particles(j)
      position = 0.0_wp
      do k = geometry%transform_offsets(j), geometry%transform_offsets(j + 1) - 1
        node = geometry%transform_node(k)
        position = position + geometry%transform_value(k)*model%coordinates(:, node)
      end do
      transform_sum = max(transform_sum, abs(sum(geometry%transform_value(geometry%transform_offsets(j): &
                                                                          geometry%transform_offsets(j + 1) - 1)) - 1.0_wp))
      transform_position = max(transform_position, norm2(position - model%coordinates(:, particle)))
    end do
    call check(suite, label//": transformation rows sum to 1", transform_sum < tight, real_text(transform_sum))
    call check(suite, label//": transformation rows reproduce the particle's position", &
               transform_position < tight, real_text(transform_position))

    ! edge midpoint rows (the transverse shear's Simpson rule): sum to 1, reproduce the midpoint
    block
      real(wp) :: midpoint_sum, midpoint_position, corner_mid(3)
      integer :: c, e, row, corners
      midpoint_sum = 0.0_wp
      midpoint_position = 0.0_wp
      call check(suite, label//": four edge midpoint rows per cell", &
                 size(geometry%midpoint_offsets) == 4*size(geometry%cells) + 1)
      do c = 1, size(geometry%cells)
        corners = merge(3, 4, model%shell_nodes(3, geometry%cells(c)) == model%shell_nodes(4, geometry%cells(c)))
        do e = 1, 4
          row = 4*(c - 1) + e
          if (e > corners) then
            call check(suite, label//": a triangle's fourth midpoint row is empty", &
                       geometry%midpoint_offsets(row + 1) == geometry%midpoint_offsets(row))
            cycle
          end if
          position = 0.0_wp
          do k = geometry%midpoint_offsets(row), geometry%midpoint_offsets(row + 1) - 1
            position = position + geometry%midpoint_value(k)*model%coordinates(:, geometry%midpoint_node(k))
          end do
          midpoint_sum = max(midpoint_sum, abs(sum(geometry%midpoint_value(geometry%midpoint_offsets(row): &
                                                                            geometry%midpoint_offsets(row + 1) - 1)) - 1.0_wp))
          corner_mid = 0.5_wp*(model%coordinates(:, model%shell_nodes(e, geometry%cells(c))) + &
                               model%coordinates(:, model%shell_nodes(modulo(e, corners) + 1, geometry%cells(c))))
          midpoint_position = max(midpoint_position, norm2(position - corner_mid))
        end do
      end do
      write (*, '(a)') "efg_shell: "//label//": edge midpoint rows: sum - 1 "//trim(real_text(midpoint_sum))// &
        ", position "//trim(real_text(midpoint_position))
      call check(suite, label//": edge midpoint rows sum to 1", midpoint_sum < tight, real_text(midpoint_sum))
      call check(suite, label//": edge midpoint rows reproduce the midpoint", midpoint_position < tight, &
                 real_text(midpoint_position))
    end block
  end subroutine check_part

  !> Index of the first point of cell c.
  pure integer function first_point(geometry, c)
    type(efg_shell_part_t), intent(in) :: geometry
    integer, intent(in) :: c
    first_point = findloc(geometry%point_cell, c, dim=1)
  end function first_point

  !> Smoothed gradient (in the cell's plane) of the cell's own bilinear (or linear) surface
  !> X(xi) = sum_a Phi_a X_a over sub-cell g: (1 / W_g) sum over its edges of X n_e L_e, two
  !> Gauss points per edge, the set-up's rule with the FE functions.
  function bilinear_position_gradient(model, cell, frame, g) result(gradient)
    type(model_t), intent(in) :: model
    integer, intent(in) :: cell, g
    real(wp), intent(in) :: frame(3, 3)
    real(wp) :: gradient(3, 2)
    real(wp) :: parametric(2, 4), polygon(2, 4), corners(3, 4), planar(2, 4), edge(2), area, point(2)
    integer :: n, e, q, next, previous
    real(wp), parameter :: fraction(2) = [0.5_wp - 0.5_wp/sqrt(3.0_wp), 0.5_wp + 0.5_wp/sqrt(3.0_wp)]
    n = corner_count(model%shell_nodes(:, cell))
    corners = model%coordinates(:, model%shell_nodes(:, cell))
    if (n == 3) then
      parametric = reshape([0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, 1.0_wp], [2, 4])
    else
      parametric = reshape([-1.0_wp, -1.0_wp, 1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp, 1.0_wp], [2, 4])
    end if
    next = modulo(g, n) + 1
    previous = modulo(g - 2, n) + 1
    polygon(:, 1) = parametric(:, g)
    polygon(:, 2) = 0.5_wp*(parametric(:, g) + parametric(:, next))
    polygon(:, 3) = sum(parametric(:, 1:n), dim=2)/n
    polygon(:, 4) = 0.5_wp*(parametric(:, g) + parametric(:, previous))
    do e = 1, 4
      planar(:, e) = matmul(transpose(frame(:, 1:2)), matmul(corners, corner_functions(n, polygon(:, e))) - corners(:, 1))
    end do
    area = 0.0_wp
    do e = 1, 4
      next = modulo(e, 4) + 1
      area = area + 0.5_wp*(planar(1, e)*planar(2, next) - planar(2, e)*planar(1, next))
    end do
    gradient = 0.0_wp
    do e = 1, 4
      next = modulo(e, 4) + 1
      edge = planar(:, next) - planar(:, e)
      do q = 1, 2
        point = polygon(:, e) + fraction(q)*(polygon(:, next) - polygon(:, e))
        gradient(:, 1) = gradient(:, 1) + 0.5_wp*edge(2)*matmul(corners, corner_functions(n, point))
        gradient(:, 2) = gradient(:, 2) - 0.5_wp*edge(1)*matmul(corners, corner_functions(n, point))
      end do
    end do
    gradient = gradient/area
  end function bilinear_position_gradient

  !> The linear field of cell c's plane at `position`: c + g . y, y the projection on e1, e2.
  pure real(wp) function field_value(geometry, c, origin, position)
    type(efg_shell_part_t), intent(in) :: geometry
    integer, intent(in) :: c
    real(wp), intent(in) :: origin(3), position(3)
    field_value = field_constant + dot_product(field_gradient, matmul(position - origin, geometry%cell_frame(:, 1:2, c)))
  end function field_value

  !> Boundary-edge nodes and extra Gamma nodes are Gamma nodes; the others are particles.
  subroutine test_node_classes()
    type(model_t) :: model
    type(efg_shell_part_t) :: geometry
    type(error_t), allocatable :: error
    logical, allocatable :: extra(:)
    integer :: node, on_outline
    model = plate_model(4, 3, .false., 0.0_wp, kernel_cubic_box, [1.1_wp, 1.1_wp])
    allocate (extra(size(model%coordinates, 2)))
    extra = .false.
    call build_efg_shell_part(model, 1, extra, geometry, error)
    if (allocated(error)) then
      call check(suite, "node classes: set-up", .false., error%message)
      return
    end if
    on_outline = 0
    do node = 1, size(model%coordinates, 2)
      if (abs(model%coordinates(1, node)) < 1e-12_wp .or. abs(model%coordinates(1, node) - plate_length) < 1e-12_wp &
          .or. abs(model%coordinates(2, node)) < 1e-12_wp .or. abs(model%coordinates(2, node) - plate_width) < 1e-12_wp) &
        on_outline = on_outline + 1
    end do
    call check(suite, "node classes: Gamma nodes are the outline's", size(geometry%gamma_nodes) == on_outline .and. &
               size(geometry%particles) == 3*2)
    extra(geometry%particles(1)) = .true.
    call build_efg_shell_part(model, 1, extra, geometry, error)
    call check(suite, "node classes: an extra Gamma node is kept", .not. allocated(error) .and. &
               size(geometry%gamma_nodes) == on_outline + 1 .and. size(geometry%particles) == 5)
    ! an FE shell of part 2 on corners of the part's first cell (a T-junction inside the part):
    ! its nodes keep FE functions without being listed by the caller
    extra = .false.
    model%shell_nodes = reshape([model%shell_nodes, model%shell_nodes(:, 6)], [4, size(model%shell_part) + 1])
    model%shell_part = [model%shell_part, 2]
    model%shell_ids = [model%shell_ids, 999]
    model%shell_thickness = reshape([model%shell_thickness, model%shell_thickness(:, 6)], [4, size(model%shell_part)])
    call build_efg_shell_part(model, 1, extra, geometry, error)
    call check(suite, "node classes: nodes shared with another part's shell are Gamma nodes", .not. allocated(error) &
               .and. size(geometry%particles) == 6 - count(is_interior(model, model%shell_nodes(:, 6))) .and. &
               count(is_interior(model, model%shell_nodes(:, 6))) > 0 .and. &
               .not. any([(any(geometry%particles == model%shell_nodes(node, 6)), node=1, 4)]))
  end subroutine test_node_classes

  !> Which of `nodes` lie inside the plate's outline.
  function is_interior(model, nodes) result(inside)
    type(model_t), intent(in) :: model
    integer, intent(in) :: nodes(:)
    logical :: inside(size(nodes))
    integer :: k
    do k = 1, size(nodes)
      associate (x => model%coordinates(:, nodes(k)))
        inside(k) = x(1) > 1e-12_wp .and. x(1) < plate_length - 1e-12_wp .and. x(2) > 1e-12_wp .and. &
                    x(2) < plate_width - 1e-12_wp
      end associate
    end do
  end function is_interior

  !> Parts the set-up does not take are refused with the part named.
  subroutine test_errors()
    type(model_t) :: model
    type(efg_shell_part_t) :: geometry
    type(error_t), allocatable :: error
    logical, allocatable :: extra(:)
    model = plate_model(3, 3, .false., 0.0_wp, kernel_cubic_box, [1.1_wp, 1.1_wp])
    allocate (extra(size(model%coordinates, 2)))
    extra = .false.
    call build_efg_shell_part(model, 2, extra, geometry, error)
    call check(suite, "errors: an FE part is refused", allocated(error))
    if (allocated(error)) call check(suite, "errors: the FE part named", &
                                     index(error%message, "EFG shell part 8: the part is not meshfree") > 0, error%message)
    model%sections(1)%support_scale(1) = 1.0_wp
    call build_efg_shell_part(model, 1, extra, geometry, error)
    call check(suite, "errors: DX 1 refused", allocated(error))
    model%sections(1)%support_scale(1) = 1.1_wp
    model%shell_part = 2
    model%parts(2)%formulation = formulation_efg
    model%parts(2)%section = 1
    model%shell_part(1) = 1
    ! a part of one cell has no particle: all FE, still a valid set-up
    call build_efg_shell_part(model, 1, extra, geometry, error)
    call check(suite, "errors: a one-cell part has no particle and is built", .not. allocated(error) .and. &
               size(geometry%particles) == 0 .and. size(geometry%point_cell) == 4)
    model%shell_nodes(:, 1) = [1, 1, 2, 2]
    call build_efg_shell_part(model, 1, extra, geometry, error)
    call check(suite, "errors: a degenerate cell is refused", allocated(error))
    if (allocated(error)) call check(suite, "errors: the degenerate cell named", &
                                     index(error%message, "element 501") > 0, error%message)
  end subroutine test_errors

  !> One and three threads build bit-identical parts (cells are assembled in order).
  subroutine test_thread_counts()
    type(model_t) :: model
    type(efg_shell_part_t) :: single, several
    type(error_t), allocatable :: error
    logical, allocatable :: extra(:)
    integer :: threads, shape
    real(wp), parameter :: radii(2) = [0.0_wp, 1.5_wp]       ! flat, and on a cylinder (curved cells)
    character(len=*), parameter :: names(2) = ["flat    ", "cylinder"]
    do shape = 1, 2
      model = plate_model(12, 9, .true., radii(shape), kernel_quadratic_box, [1.3_wp, 1.2_wp])
      if (allocated(extra)) deallocate (extra)
      allocate (extra(size(model%coordinates, 2)))
      extra = .false.
      threads = omp_get_max_threads()
      call omp_set_num_threads(1)
      call build_efg_shell_part(model, 1, extra, single, error)
      call omp_set_num_threads(3)
      call build_efg_shell_part(model, 1, extra, several, error)
      call omp_set_num_threads(threads)
      call check(suite, "threads ("//trim(names(shape))//"): 1 and 3 threads give identical parts", &
                 all(single%point_offsets == several%point_offsets) .and. all(single%pair_node == several%pair_node) &
                 .and. all(single%pair_gradient == several%pair_gradient) .and. &
                 all(single%shear_value == several%shear_value) .and. &
                 all(single%shear_gradient == several%shear_gradient) .and. &
                 all(single%mass_volume == several%mass_volume) .and. &
                 all(single%transform_value == several%transform_value))
    end do
  end subroutine test_thread_counts

  !> Set-up of a 100 x 100 plate: its seconds are printed (tests never assert wall-clock time;
  !> tools/bench figures do); what is asserted is that every point's pair list stays local (a
  !> support of DX 1.1 reaches the cells around the point's own: at most 5 x 5 nodes).
  subroutine test_setup_time()
    type(model_t) :: model
    type(efg_shell_part_t) :: geometry
    type(error_t), allocatable :: error
    logical, allocatable :: extra(:)
    character(len=80) :: line
    model = plate_model(100, 100, .false., 0.0_wp, kernel_cubic_box, [1.1_wp, 1.1_wp])
    allocate (extra(size(model%coordinates, 2)))
    extra = .false.
    call build_efg_shell_part(model, 1, extra, geometry, error)
    call check(suite, "100 x 100 plate: set-up succeeds", .not. allocated(error))
    write (line, '(a,f0.3,a,i0,a)') "efg_shell: 100 x 100 plate set-up ", geometry%setup_seconds, " s (", &
      geometry%point_offsets(size(geometry%point_offsets)) - 1, " pairs)"
    write (*, '(a)') trim(line)
    call check(suite, "100 x 100 plate: at most 25 pairs per point", &
               maxval(geometry%point_offsets(2:) - geometry%point_offsets(:size(geometry%point_offsets) - 1)) <= 25)
    ! the same wrapped on a cylinder (radius 1.5, the plate's length turns by 76 degrees): the
    ! basis has its height term in every cell
    model = plate_model(100, 100, .false., 1.5_wp, kernel_cubic_box, [1.1_wp, 1.1_wp])
    call build_efg_shell_part(model, 1, extra, geometry, error)
    call check(suite, "100 x 100 cylinder: set-up succeeds", .not. allocated(error))
    write (line, '(a,f0.3,a,i0,a)') "efg_shell: 100 x 100 cylinder set-up ", geometry%setup_seconds, " s (", &
      geometry%point_offsets(size(geometry%point_offsets)) - 1, " pairs)"
    write (*, '(a)') trim(line)
  end subroutine test_setup_time

  function real_text(value) result(text)
    real(wp), intent(in) :: value
    character(len=24) :: text
    write (text, '(es10.3)') value
  end function real_text
end program test_efg_shell
