!> Set-up of one meshfree (EFG) shell part (*SECTION_SHELL ELFORM 41): everything the explicit
!> update needs, computed once on the undeformed background shells (Lagrangian kernel); the
!> shells' counterpart of efg_setup. See docs/efg_shells.md.
!>
!> Steps: nodes, Gamma nodes, particles, frames and supports (efg_shell_supports) -> bins over
!> the supports (efg_neighbour_search) -> per background cell, independently and in parallel:
!> * membrane and bending points, one per sub-cell (4 per quadrilateral: the quarter of the
!>   parametric square holding each vertex; 3 per triangle: vertex, two edge midpoints,
!>   centroid). Each sub-cell is a straight-edged quadrilateral in the cell's plane (its edges
!>   are iso-parametric lines), of exact area W_g (shoelace). Its smoothed gradients
!>     bbar_I(g) = (1/W_g) sum_edges sum_q Psi_I(y_q) n_e L_e omega_q
!>   with 2 Gauss points per straight edge (exact for linear fields, since the functions
!>   reproduce them), components along e1, e2 of the cell. The sub-cell edges on a cell edge are
!>   its halves, the same pieces from either cell, so the sums telescope: sum_g bbar_I W_g is the
!>   integral of Psi_I n over the part's boundary edges, where every particle function vanishes
!>   (the integration constraint, to round-off on flat parts);
!> * one transverse shear point at the cell centre: Psi there, and the cell-averaged smoothed
!>   gradient sum_g bbar_I(g) W_g / A (consistent for linear fields, no extra evaluation);
!> * row-sum masses: Psi at the centre of each sub-cell times W_g times the cell's thickness
!>   (the masses then add up to sum of A t exactly, since sum_I Psi_I = 1);
!> * the transformation rows Psi_J(X_I) of the particles the cell owns (first cell having them)
!> -> assembly in cell order (independent of the thread count) -> checks (sub-cell areas,
!> moment residuals at round-off, positive masses). Every step is linear in the number of cells.
module efg_shell_setup
  use kinds, only: wp
  use error_handling, only: error_t, make_error
  use text_format, only: integer_text, scientific_text
  use wall_clock, only: seconds_now
  use model, only: model_t, formulation_efg, section_shell, kernel_cubic_box, kernel_quadratic_box, &
                   kernel_cubic_sphere, boundary_coupled, integration_local_boundary
  use efg_shell_part, only: efg_shell_part_t
  use efg_shell_supports, only: shell_supports_t, build_shell_supports, corner_count
  use efg_neighbour_search, only: particle_grid_t, build_particle_grid
  use efg_shell_functions, only: shell_cell_context_t, prepare_shell_cell, evaluate_shell_functions, &
                                 corner_functions
  implicit none
  private

  public :: build_efg_shell_part

  !> Largest |M alpha - b| accepted as round-off (as for the solids).
  real(wp), parameter, public :: shell_moment_residual_tolerance = 1.0e-10_wp

  !> Parametric corners of the quadrilateral and of the triangle (area coordinates).
  real(wp), parameter :: quad_corners(2, 4) = reshape([-1.0_wp, -1.0_wp, 1.0_wp, -1.0_wp, &
                                                       1.0_wp, 1.0_wp, -1.0_wp, 1.0_wp], [2, 4])
  real(wp), parameter :: triangle_corners(2, 3) = reshape([0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, &
                                                           0.0_wp, 1.0_wp], [2, 3])
  !> Two-point Gauss rule on [0, 1] (abscissae; the weights are 1/2).
  real(wp), parameter :: gauss_fraction(2) = [0.5_wp - 0.5_wp/sqrt(3.0_wp), 0.5_wp + 0.5_wp/sqrt(3.0_wp)]

  !> What one background cell contributes, kept until the cells are assembled in order.
  type :: cell_result_t
    real(wp) :: frame(3, 3) = 0.0_wp
    real(wp) :: area = 0.0_wp
    real(wp) :: thickness = 0.0_wp
    real(wp), allocatable :: point_area(:)
    integer, allocatable :: pair_count(:)
    integer, allocatable :: pair_node(:)
    real(wp), allocatable :: pair_gradient(:, :)
    integer :: shear_count = 0
    integer, allocatable :: shear_node(:)
    real(wp), allocatable :: shear_value(:)
    real(wp), allocatable :: shear_gradient(:, :)
    integer, allocatable :: mass_node(:)
    real(wp), allocatable :: mass_volume(:)
    integer :: midpoint_count(4) = 0               !< entries of each edge midpoint's row
    integer, allocatable :: midpoint_node(:)
    real(wp), allocatable :: midpoint_value(:)
    integer :: row_count = 0
    integer, allocatable :: row_particle(:)
    integer, allocatable :: row_length(:)
    integer, allocatable :: row_node(:)
    real(wp), allocatable :: row_value(:)
    integer :: singular_points = 0
    real(wp) :: worst_residual = 0.0_wp
  end type cell_result_t

contains

  !> Build the precomputed data `geometry` of meshfree shell part `part` (an index into
  !> model%parts whose section is a *SECTION_SHELL with ELFORM 41). `extra_gamma_nodes` (one per
  !> model node) are kept as Gamma nodes besides those on the part's boundary edges: supports,
  !> constraints, spot welds, nodes shared with beams or solids. On failure `error` names the
  !> part and, where it applies, the element or node and the likely cause.
  subroutine build_efg_shell_part(model, part, extra_gamma_nodes, geometry, error)
    type(model_t), intent(in) :: model
    integer, intent(in) :: part
    logical, intent(in) :: extra_gamma_nodes(:)
    type(efg_shell_part_t), intent(out) :: geometry
    type(error_t), allocatable, intent(out) :: error
    type(shell_supports_t) :: supports
    type(particle_grid_t) :: grid
    type(cell_result_t), allocatable :: results(:)
    real(wp) :: started
    integer :: k

    started = seconds_now()
    call check_section(model, part, extra_gamma_nodes, error)
    if (allocated(error)) return
    call check_cells(model, part, error)
    if (allocated(error)) return
    associate (section => model%sections(model%parts(part)%section))
      geometry%part = part
      geometry%material = model%parts(part)%material
      call build_shell_supports(model, part, section%support_scale(1:2), section%kernel, extra_gamma_nodes, &
                                supports)
    end associate
    if (size(supports%cells) == 0) then
      call make_error(error, "EFG shell part "//integer_text(model%parts(part)%id)//" has no shell elements")
      return
    end if
    geometry%gamma_nodes = supports%gamma_nodes
    geometry%particles = supports%particles
    geometry%cells = supports%cells
    call build_particle_grid(supports%particle_coordinates, supports%search_radius, grid)

    ! cells are independent; each writes only its own result
    allocate (results(size(supports%cells)))
    !$omp parallel do schedule(dynamic, 16)
    do k = 1, size(supports%cells)
      call process_cell(model, supports, grid, k, results(k))
    end do
    !$omp end parallel do

    call assemble(supports, results, geometry)
    call check_results(model, part, supports, results, geometry, error)
    geometry%setup_seconds = seconds_now() - started
  end subroutine build_efg_shell_part

  !> Everything cell number `k` (model shell supports%cells(k)) contributes.
  subroutine process_cell(model, supports, grid, k, result)
    type(model_t), intent(in) :: model
    type(shell_supports_t), intent(in) :: supports
    type(particle_grid_t), intent(in) :: grid
    integer, intent(in) :: k
    type(cell_result_t), intent(inout) :: result
    type(shell_cell_context_t) :: context
    real(wp), allocatable :: gradients(:, :, :), values(:), mass_volume(:), row_value(:), cell_gradient(:, :)
    integer, allocatable :: row_node(:)
    real(wp) :: parametric(2, 4), polygon(2, 4), planar(2), start(2), finish(2), edge(2), point(2)
    real(wp) :: normal_length(2)
    integer :: cell, corners, g, e, q, n, rank, total, pair, a, particle, row_total
    real(wp) :: residual

    cell = supports%cells(k)
    call prepare_shell_cell(supports, grid, model%coordinates, model%shell_nodes(:, cell), context)
    corners = context%corners
    n = context%node_count
    result%frame = context%frame
    result%thickness = sum(model%shell_thickness(1:corners, cell))/corners
    parametric = 0.0_wp
    if (corners == 3) then
      parametric(:, 1:3) = triangle_corners
    else
      parametric = quad_corners
    end if
    allocate (gradients(2, n, corners), values(n), mass_volume(n), cell_gradient(2, n), result%point_area(corners))
    gradients = 0.0_wp
    mass_volume = 0.0_wp

    do g = 1, corners
      polygon = subcell_polygon(parametric, corners, g)
      ! the sub-cell's area in the cell's plane: its edges are straight there
      result%point_area(g) = polygon_area(context, polygon)
      if (result%point_area(g) <= 0.0_wp) cycle
      do e = 1, 4
        start = polygon(:, e)
        finish = polygon(:, modulo(e, 4) + 1)
        edge = planar_point(context, finish) - planar_point(context, start)
        ! outward normal times length of a counter-clockwise polygon
        normal_length = [edge(2), -edge(1)]
        do q = 1, 2
          point = start + gauss_fraction(q)*(finish - start)
          call evaluate_shell_functions(context, point, planar, values, rank, residual)
          call note_point(result, rank, residual)
          do pair = 1, n
            gradients(:, pair, g) = gradients(:, pair, g) + 0.5_wp*values(pair)*normal_length
          end do
        end do
      end do
      gradients(:, :, g) = gradients(:, :, g)/result%point_area(g)
      ! row-sum mass share at the sub-cell's centre
      point = 0.25_wp*sum(polygon, dim=2)
      call evaluate_shell_functions(context, point, planar, values, rank, residual)
      call note_point(result, rank, residual)
      mass_volume = mass_volume + values*result%point_area(g)*result%thickness
    end do
    result%area = sum(result%point_area)
    if (any(result%point_area <= 0.0_wp)) then
      ! a degenerate or inverted cell is reported by the caller
      allocate (result%pair_count(corners), result%pair_node(0), result%pair_gradient(2, 0), result%shear_node(0), &
                result%shear_value(0), result%shear_gradient(2, 0), result%mass_node(0), result%mass_volume(0), &
                result%row_particle(0), result%row_length(0), result%row_node(0), result%row_value(0), &
                result%midpoint_node(0), result%midpoint_value(0))
      result%pair_count = 0
      return
    end if

    ! membrane and bending points: every node whose gradient is not exactly zero
    allocate (result%pair_count(corners))
    total = count(gradients(1, :, :) /= 0.0_wp .or. gradients(2, :, :) /= 0.0_wp)
    allocate (result%pair_node(total), result%pair_gradient(2, total))
    total = 0
    do g = 1, corners
      result%pair_count(g) = 0
      do pair = 1, n
        if (all(gradients(:, pair, g) == 0.0_wp)) cycle
        total = total + 1
        result%pair_count(g) = result%pair_count(g) + 1
        result%pair_node(total) = context%nodes(pair)
        result%pair_gradient(:, total) = gradients(:, pair, g)
      end do
    end do

    ! transverse shear point at the centre: values there, the cell-averaged smoothed gradient
    point = sum(parametric(:, 1:corners), dim=2)/corners
    call evaluate_shell_functions(context, point, planar, values, rank, residual)
    call note_point(result, rank, residual)
    cell_gradient = 0.0_wp
    do g = 1, corners
      cell_gradient = cell_gradient + gradients(:, :, g)*result%point_area(g)
    end do
    cell_gradient = cell_gradient/result%area
    result%shear_count = count(values /= 0.0_wp .or. cell_gradient(1, :) /= 0.0_wp .or. cell_gradient(2, :) /= 0.0_wp)
    allocate (result%shear_node(result%shear_count), result%shear_value(result%shear_count), &
              result%shear_gradient(2, result%shear_count))
    total = 0
    do pair = 1, n
      if (values(pair) == 0.0_wp .and. all(cell_gradient(:, pair) == 0.0_wp)) cycle
      total = total + 1
      result%shear_node(total) = context%nodes(pair)
      result%shear_value(total) = values(pair)
      result%shear_gradient(:, total) = cell_gradient(:, pair)
    end do

    ! the edge midpoints (the transverse shear's edge averages, Simpson's rule): edge e from
    ! corner e to the next one (a triangle's third edge back to corner 1; its fourth row empty)
    allocate (row_node(4*n), row_value(4*n))
    row_total = 0
    result%midpoint_count = 0
    do e = 1, corners
      point = 0.5_wp*(parametric(:, e) + parametric(:, modulo(e, corners) + 1))
      call evaluate_shell_functions(context, point, planar, values, rank, residual)
      call note_point(result, rank, residual)
      result%midpoint_count(e) = count(values(1:n) /= 0.0_wp)
      call append_row(context%nodes, values, n, row_node, row_value, row_total)
    end do
    result%midpoint_node = row_node(1:row_total)
    result%midpoint_value = row_value(1:row_total)
    deallocate (row_node, row_value)

    result%mass_node = pack(context%nodes(1:n), mass_volume /= 0.0_wp)
    result%mass_volume = pack(mass_volume, mass_volume /= 0.0_wp)

    ! transformation rows of the particles this cell owns, at their corners
    result%row_count = 0
    allocate (result%row_particle(4), result%row_length(4), row_node(4*n), row_value(4*n))
    row_total = 0
    do a = 1, corners
      particle = supports%particle_of_node(model%shell_nodes(a, cell))
      if (particle == 0) cycle
      if (supports%owner_cell(particle) /= k) cycle
      if (any(result%row_particle(1:result%row_count) == particle)) cycle
      call evaluate_shell_functions(context, parametric(:, a), planar, values, rank, residual)
      call note_point(result, rank, residual)
      result%row_count = result%row_count + 1
      result%row_particle(result%row_count) = particle
      result%row_length(result%row_count) = count(values(1:n) /= 0.0_wp)
      call append_row(context%nodes, values, n, row_node, row_value, row_total)
    end do
    result%row_node = row_node(1:row_total)
    result%row_value = row_value(1:row_total)
  end subroutine process_cell

  !> Append the non-zero values(1:n) and their nodes to a row list that holds `total` entries.
  pure subroutine append_row(nodes, values, n, row_node, row_value, total)
    integer, intent(in) :: nodes(:), n
    real(wp), intent(in) :: values(:)
    integer, intent(inout) :: row_node(:)
    real(wp), intent(inout) :: row_value(:)
    integer, intent(inout) :: total
    integer :: pair
    do pair = 1, n
      if (values(pair) == 0.0_wp) cycle
      total = total + 1
      row_node(total) = nodes(pair)
      row_value(total) = values(pair)
    end do
  end subroutine append_row

  !> Counts a rank-deficient moment matrix and keeps the worst residual.
  subroutine note_point(result, rank, residual)
    type(cell_result_t), intent(inout) :: result
    integer, intent(in) :: rank
    real(wp), intent(in) :: residual
    if (rank > 0 .and. rank < 3) result%singular_points = result%singular_points + 1
    result%worst_residual = max(result%worst_residual, residual)
  end subroutine note_point

  !> Sub-cell g in parametric coordinates, counter-clockwise: corner g, the midpoint of the edge
  !> to the next corner, the centre, the midpoint of the edge from the previous corner.
  pure function subcell_polygon(parametric, corners, g) result(polygon)
    real(wp), intent(in) :: parametric(2, 4)
    integer, intent(in) :: corners, g
    real(wp) :: polygon(2, 4)
    integer :: next, previous
    next = modulo(g, corners) + 1
    previous = modulo(g - 2, corners) + 1
    polygon(:, 1) = parametric(:, g)
    polygon(:, 2) = 0.5_wp*(parametric(:, g) + parametric(:, next))
    polygon(:, 3) = sum(parametric(:, 1:corners), dim=2)/corners
    polygon(:, 4) = 0.5_wp*(parametric(:, g) + parametric(:, previous))
  end function subcell_polygon

  !> Planar coordinates of the parametric point `parametric` of the context's cell.
  pure function planar_point(context, parametric) result(planar)
    type(shell_cell_context_t), intent(in) :: context
    real(wp), intent(in) :: parametric(2)
    real(wp) :: planar(2)
    real(wp) :: phi(4)
    phi = corner_functions(context%corners, parametric)
    planar = matmul(context%planar, phi)
  end function planar_point

  !> Signed area (shoelace) in the cell's plane of a parametric polygon with straight images.
  pure real(wp) function polygon_area(context, polygon)
    type(shell_cell_context_t), intent(in) :: context
    real(wp), intent(in) :: polygon(2, 4)
    real(wp) :: corner(2, 4)
    integer :: e
    do e = 1, 4
      corner(:, e) = planar_point(context, polygon(:, e))
    end do
    polygon_area = 0.0_wp
    do e = 1, 4
      polygon_area = polygon_area + corner(1, e)*corner(2, modulo(e, 4) + 1) - corner(2, e)*corner(1, modulo(e, 4) + 1)
    end do
    polygon_area = 0.5_wp*polygon_area
  end function polygon_area

  !> Concatenate the cells' results in cell order; masses summed per node.
  subroutine assemble(supports, results, geometry)
    type(shell_supports_t), intent(in) :: supports
    type(cell_result_t), intent(in) :: results(:)
    type(efg_shell_part_t), intent(inout) :: geometry
    integer :: cell_count, point_count, pair_total, shear_total, k, g, point, offset, shear, j, row, e
    integer :: midpoint_total, midpoint
    integer, allocatable :: node_slot(:), row_start(:), row_size(:), row_owner(:), row_position(:)
    real(wp), allocatable :: mass(:)

    cell_count = size(results)
    point_count = 0
    pair_total = 0
    shear_total = 0
    midpoint_total = 0
    do k = 1, cell_count
      point_count = point_count + size(results(k)%point_area)
      pair_total = pair_total + size(results(k)%pair_node)
      shear_total = shear_total + size(results(k)%shear_node)
      midpoint_total = midpoint_total + size(results(k)%midpoint_node)
    end do
    allocate (geometry%cell_frame(3, 3, cell_count), geometry%cell_area(cell_count), &
              geometry%cell_thickness(cell_count), geometry%point_cell(point_count), &
              geometry%point_area(point_count), geometry%point_offsets(point_count + 1), &
              geometry%pair_node(pair_total), geometry%pair_gradient(2, pair_total), &
              geometry%shear_offsets(cell_count + 1), geometry%shear_node(shear_total), &
              geometry%shear_value(shear_total), geometry%shear_gradient(2, shear_total))
    point = 0
    offset = 1
    shear = 1
    geometry%point_offsets(1) = 1
    do k = 1, cell_count
      geometry%cell_frame(:, :, k) = results(k)%frame
      geometry%cell_area(k) = results(k)%area
      geometry%cell_thickness(k) = results(k)%thickness
      do g = 1, size(results(k)%point_area)
        point = point + 1
        geometry%point_cell(point) = k
        geometry%point_area(point) = results(k)%point_area(g)
        geometry%point_offsets(point + 1) = geometry%point_offsets(point) + results(k)%pair_count(g)
      end do
      j = size(results(k)%pair_node)
      geometry%pair_node(offset:offset + j - 1) = results(k)%pair_node
      geometry%pair_gradient(:, offset:offset + j - 1) = results(k)%pair_gradient
      offset = offset + j
      geometry%shear_offsets(k) = shear
      j = size(results(k)%shear_node)
      geometry%shear_node(shear:shear + j - 1) = results(k)%shear_node
      geometry%shear_value(shear:shear + j - 1) = results(k)%shear_value
      geometry%shear_gradient(:, shear:shear + j - 1) = results(k)%shear_gradient
      shear = shear + j
    end do
    geometry%shear_offsets(cell_count + 1) = shear

    ! edge midpoint rows, 4 per cell in cell order
    allocate (geometry%midpoint_offsets(4*cell_count + 1), geometry%midpoint_node(midpoint_total), &
              geometry%midpoint_value(midpoint_total))
    midpoint = 1
    do k = 1, cell_count
      offset = 1
      do e = 1, 4
        geometry%midpoint_offsets(4*(k - 1) + e) = midpoint
        j = results(k)%midpoint_count(e)
        geometry%midpoint_node(midpoint:midpoint + j - 1) = results(k)%midpoint_node(offset:offset + j - 1)
        geometry%midpoint_value(midpoint:midpoint + j - 1) = results(k)%midpoint_value(offset:offset + j - 1)
        offset = offset + j
        midpoint = midpoint + j
      end do
    end do
    geometry%midpoint_offsets(4*cell_count + 1) = midpoint

    ! row-sum masses: each node of the part once, ascending
    allocate (node_slot(size(supports%particle_of_node)), mass(size(supports%nodes)))
    node_slot = 0
    do j = 1, size(supports%nodes)
      node_slot(supports%nodes(j)) = j
    end do
    mass = 0.0_wp
    do k = 1, cell_count
      do j = 1, size(results(k)%mass_node)
        mass(node_slot(results(k)%mass_node(j))) = mass(node_slot(results(k)%mass_node(j))) + results(k)%mass_volume(j)
      end do
    end do
    geometry%mass_node = supports%nodes
    geometry%mass_volume = mass

    ! transformation rows in particle order
    allocate (row_size(size(supports%particles)), row_owner(size(supports%particles)), &
              row_position(size(supports%particles)))
    row_size = 0
    row_owner = 0
    row_position = 0
    do k = 1, cell_count
      offset = 1
      do row = 1, results(k)%row_count
        j = results(k)%row_particle(row)
        row_size(j) = results(k)%row_length(row)
        row_owner(j) = k
        row_position(j) = offset
        offset = offset + results(k)%row_length(row)
      end do
    end do
    allocate (row_start(size(supports%particles) + 1))
    row_start(1) = 1
    do j = 1, size(supports%particles)
      row_start(j + 1) = row_start(j) + row_size(j)
    end do
    geometry%transform_offsets = row_start
    allocate (geometry%transform_node(row_start(size(row_start)) - 1), &
              geometry%transform_value(row_start(size(row_start)) - 1))
    do j = 1, size(supports%particles)
      if (row_owner(j) == 0) cycle
      associate (from => results(row_owner(j)))
        geometry%transform_node(row_start(j):row_start(j + 1) - 1) = &
          from%row_node(row_position(j):row_position(j) + row_size(j) - 1)
        geometry%transform_value(row_start(j):row_start(j + 1) - 1) = &
          from%row_value(row_position(j):row_position(j) + row_size(j) - 1)
      end associate
    end do

    geometry%singular_moment_points = 0
    do k = 1, cell_count
      geometry%singular_moment_points = geometry%singular_moment_points + results(k)%singular_points
    end do
  end subroutine assemble

  !> The part must be a meshfree shell part with a section the set-up builds.
  subroutine check_section(model, part, extra_gamma_nodes, error)
    type(model_t), intent(in) :: model
    integer, intent(in) :: part
    logical, intent(in) :: extra_gamma_nodes(:)
    type(error_t), allocatable, intent(out) :: error
    character(len=:), allocatable :: where

    if (part < 1 .or. part > size(model%parts)) then
      call make_error(error, "EFG shell set-up: part index "//integer_text(part)//" is not a part of the model")
      return
    end if
    where = "EFG shell part "//integer_text(model%parts(part)%id)
    if (size(extra_gamma_nodes) /= size(model%coordinates, 2)) then
      call make_error(error, where//": the list of extra Gamma nodes has "//integer_text(size(extra_gamma_nodes))// &
                      " entries for "//integer_text(size(model%coordinates, 2))//" nodes")
      return
    end if
    if (model%parts(part)%formulation /= formulation_efg) then
      call make_error(error, where//": the part is not meshfree (its section is not ELFORM 41)")
      return
    end if
    if (model%parts(part)%section < 1) then
      call make_error(error, where//": the part has no section")
      return
    end if
    associate (section => model%sections(model%parts(part)%section))
      if (section%kind /= section_shell) then
        call make_error(error, where//": the part's section is not a *SECTION_SHELL")
      else if (any(section%support_scale(1:2) <= 1.0_wp)) then
        call make_error(error, where//": DX and DY must be greater than 1 (at 1.0 a vertex weight vanishes on "// &
                        "the cell's far corner)")
      else if (section%kernel /= kernel_cubic_box .and. section%kernel /= kernel_quadratic_box .and. &
               section%kernel /= kernel_cubic_sphere) then
        call make_error(error, where//": ISPLINE must be 0, 1 or 2")
      else if (section%dilation_basis /= 0) then
        call make_error(error, where//": IDILA must be 0 (support from the nodes sharing an element)")
      else if (section%boundary_treatment /= boundary_coupled) then
        call make_error(error, where//": IEBT must be 3 (coupled FE/EFG)")
      else if (section%domain_integration /= integration_local_boundary) then
        call make_error(error, where//": IDIM must be 1 (local boundary integration)")
      end if
    end associate
  end subroutine check_section

  !> Cells without a frame (coincident corners, or all on one line) cannot be set up; the deck's
  !> own check refuses them first, this keeps a model built otherwise from dividing by zero.
  subroutine check_cells(model, part, error)
    type(model_t), intent(in) :: model
    integer, intent(in) :: part
    type(error_t), allocatable, intent(out) :: error
    real(wp) :: corners(3, 4), diagonal_1(3), diagonal_2(3), normal(3), side(3), size_squared
    integer :: cell

    do cell = 1, size(model%shell_part)
      if (model%shell_part(cell) /= part) cycle
      corners = model%coordinates(:, model%shell_nodes(:, cell))
      diagonal_1 = corners(:, 3) - corners(:, 1)
      diagonal_2 = corners(:, 4) - corners(:, 2)
      normal = [diagonal_1(2)*diagonal_2(3) - diagonal_1(3)*diagonal_2(2), &
                diagonal_1(3)*diagonal_2(1) - diagonal_1(1)*diagonal_2(3), &
                diagonal_1(1)*diagonal_2(2) - diagonal_1(2)*diagonal_2(1)]
      side = corners(:, 2) - corners(:, 1)
      size_squared = max(dot_product(diagonal_1, diagonal_1), dot_product(diagonal_2, diagonal_2))
      if (norm2(normal) <= 1.0e-12_wp*size_squared .or. norm2(side)**2 <= 1.0e-24_wp*size_squared .or. &
          size_squared <= 0.0_wp) then
        call make_error(error, "EFG shell part "//integer_text(model%parts(part)%id)//": element "// &
                        integer_text(model%shell_ids(cell))//" has no area: its corners coincide or lie on one line")
        return
      end if
    end do
  end subroutine check_cells

  !> Degenerate cells, moment residuals above round-off, non-positive masses.
  subroutine check_results(model, part, supports, results, geometry, error)
    type(model_t), intent(in) :: model
    integer, intent(in) :: part
    type(shell_supports_t), intent(in) :: supports
    type(cell_result_t), intent(in) :: results(:)
    type(efg_shell_part_t), intent(in) :: geometry
    type(error_t), allocatable, intent(out) :: error
    character(len=:), allocatable :: where, listed
    real(wp) :: worst
    integer :: k, worst_cell, bad, j

    where = "EFG shell part "//integer_text(model%parts(part)%id)
    do k = 1, size(results)
      if (any(results(k)%point_area <= 0.0_wp)) then
        call make_error(error, where//": element "//integer_text(model%shell_ids(supports%cells(k)))// &
                        " has a sub-cell of non-positive area: it is degenerate or folded over ("// &
                        integer_text(corner_count(model%shell_nodes(:, supports%cells(k))))//" corners)")
        return
      end if
    end do
    worst = 0.0_wp
    worst_cell = 1
    do k = 1, size(results)
      if (results(k)%worst_residual > worst) then
        worst = results(k)%worst_residual
        worst_cell = k
      end if
    end do
    if (worst > shell_moment_residual_tolerance) then
      call make_error(error, where//": element "//integer_text(model%shell_ids(supports%cells(worst_cell)))// &
                      ": the moment equations M alpha = b are not solved to round-off (residual "// &
                      scientific_text(worst, 3)//"): an interior vertex of the cell does not cover it; check "// &
                      "for a strongly warped or folded cell")
      return
    end if
    bad = 0
    listed = ""
    do j = 1, size(geometry%mass_volume)
      if (geometry%mass_volume(j) > 0.0_wp) cycle
      bad = bad + 1
      if (bad <= 5) listed = listed//" "//integer_text(model%node_ids(geometry%mass_node(j)))// &
                             " ("//scientific_text(geometry%mass_volume(j), 3)//")"
    end do
    if (bad > 0) call make_error(error, where//": "//integer_text(bad)//" node(s) get a non-positive "// &
                                 "row-sum mass; node id (volume share):"//listed//". Likely cause: supports "// &
                                 "much larger than the cells (reduce DX, DY)")
  end subroutine check_results
end module efg_shell_setup
