!> Set-up of one meshfree (EFG) part: everything the explicit update needs, computed once on the
!> undeformed background mesh (Lagrangian kernel; formulation sections 1-5, Wang et al. 2009).
!>
!> Steps: nodes, Gamma nodes, particles and supports (efg_supports) -> bins over the supports
!> (efg_neighbour_search) -> per background cell, independently and in parallel: the coupled
!> shape functions (efg_shape_functions) at the sub-cell face points, the smoothed gradients
!> (efg_smoothed_gradient; or the direct gradients at 2x2x2 or 4x4x4 Gauss points for the
!> variants IDIM 2 and 4), the row-sum mass shares (efg_mass) and the transformation rows of the
!> particles the cell owns (efg_transformation) -> assembly in cell order (so the result does not
!> depend on the thread count) -> checks (moment residuals at round-off, positive masses).
!> Every step is linear in the number of cells. See docs/efg.md.
module efg_setup
  use kinds, only: wp
  use error_handling, only: error_t, make_error
  use text_format, only: integer_text, scientific_text, fixed_text
  use wall_clock, only: seconds_now
  use model, only: model_t, formulation_efg, kernel_cubic_box, kernel_cubic_sphere, boundary_full_transformation, &
                   boundary_coupled, integration_local_boundary, integration_gauss, &
                   integration_gauss_conventional
  use efg_part, only: efg_part_t
  use efg_cell_geometry, only: subcell_volumes, largest_face_area, vertex_parametric, cell_gauss_rule
  use efg_supports, only: part_supports_t, build_cell_supports
  use efg_neighbour_search, only: particle_grid_t, build_particle_grid
  use efg_shape_functions, only: cell_shape_context_t, prepare_cell_context
  use efg_smoothed_gradient, only: cell_smoothed_gradients, cell_gauss_gradients
  use efg_mass, only: cell_mass_volumes
  use efg_transformation, only: particle_transformation_row
  implicit none
  private

  public :: build_efg_part, build_cell_efg_part

  !> Largest |M alpha - b| accepted as round-off. It is about 1e-15 when the support rule of
  !> formulation section 2 holds; anything near this bound means a particle needed by b does not
  !> cover the point.
  real(wp), parameter, public :: moment_residual_tolerance = 1.0e-10_wp

  !> What one background cell contributes, kept until the cells are assembled in order.
  type :: cell_result_t
    real(wp), allocatable :: point_volume(:)       !< W_g of the cell's points (8 or 64)
    real(wp) :: point_length = 0.0_wp
    integer, allocatable :: pair_count(:)          !< pairs of each point
    integer, allocatable :: pair_node(:)
    real(wp), allocatable :: pair_gradient(:, :)
    integer, allocatable :: mass_node(:)
    real(wp), allocatable :: mass_volume(:)
    integer :: row_count = 0                       !< particles whose transformation row is here
    integer, allocatable :: row_particle(:)
    integer, allocatable :: row_length(:)
    integer, allocatable :: row_node(:)
    real(wp), allocatable :: row_value(:)
    integer :: singular_points = 0
    real(wp) :: worst_residual = 0.0_wp
  end type cell_result_t

contains

  !> Build the precomputed data `efg` of part `part` (an index into model%parts whose formulation
  !> is EFG). On failure `error` names the part and, where it applies, the element or node and the
  !> likely cause; `efg` is then still filled as far as it was built. The part's solids go to
  !> build_cell_efg_part, the one set-up of every meshfree solid part (the library crashfree_efg
  !> calls it with a host code's arrays).
  subroutine build_efg_part(model, part, efg, error)
    type(model_t), intent(in) :: model
    integer, intent(in) :: part
    type(efg_part_t), intent(out) :: efg
    type(error_t), allocatable, intent(out) :: error
    integer, allocatable :: cells(:)
    integer :: cell

    call check_section(model, part, error)
    if (allocated(error)) return
    cells = pack([(cell, cell=1, size(model%solid_part))], model%solid_part == part)
    if (size(cells) == 0) then
      call make_error(error, "EFG part "//integer_text(model%parts(part)%id)//" has no solid elements")
      return
    end if
    associate (section => model%sections(model%parts(part)%section))
      call build_cell_efg_part(model%coordinates, model%solid_nodes(:, cells), cells, section%support_scale, &
                               section%kernel, section%domain_integration, &
                               section%boundary_treatment == boundary_full_transformation, [integer ::], &
                               "EFG part "//integer_text(model%parts(part)%id), "element", &
                               model%solid_ids(cells), model%node_ids, efg, error)
    end associate
    efg%part = part
    efg%material = model%parts(part)%material
  end subroutine build_efg_part

  !> Build the precomputed data `efg` of the meshfree part made of the cells `hexahedra(8, m)`
  !> (indices into `coordinates(3, :)`, LS-DYNA node order). The nodes keep their index into
  !> `coordinates`; each cell's points are labelled `cell_labels(k)` (`point_cell`). `marked`
  !> nodes are Gamma nodes besides the surface. Messages start with `where` and name a cell
  !> `cell_word` `cell_ids(k)` and a node `node_ids(j)`. On failure `error` says what is wrong;
  !> `efg` is then still filled as far as it was built.
  subroutine build_cell_efg_part(coordinates, hexahedra, cell_labels, support_scale, kernel, domain_integration, &
                                 full_transformation, marked, where, cell_word, cell_ids, node_ids, efg, error)
    real(wp), intent(in) :: coordinates(:, :)
    integer, intent(in) :: hexahedra(:, :), cell_labels(:)
    real(wp), intent(in) :: support_scale(3)
    integer, intent(in) :: kernel, domain_integration
    logical, intent(in) :: full_transformation
    integer, intent(in) :: marked(:)
    character(len=*), intent(in) :: where, cell_word
    integer, intent(in) :: cell_ids(:), node_ids(:)
    type(efg_part_t), intent(out) :: efg
    type(error_t), allocatable, intent(out) :: error
    type(part_supports_t) :: supports
    type(particle_grid_t) :: grid
    type(cell_result_t), allocatable :: results(:)
    real(wp) :: started
    integer :: k

    started = seconds_now()
    call build_cell_supports(coordinates, hexahedra, support_scale, kernel, full_transformation, marked, supports)
    efg%gamma_nodes = supports%gamma_nodes
    efg%particles = supports%particles
    efg%surface_nodes = supports%surface_nodes
    efg%surface_rows = supports%particle_of_node(supports%surface_nodes)
    call build_particle_grid(supports%particle_coordinates, supports%particle_radius, grid)

    ! cells are independent; each writes only its own result
    allocate (results(size(supports%cells)))
    !$omp parallel do schedule(dynamic, 4)
    do k = 1, size(supports%cells)
      call process_cell(coordinates, hexahedra, supports, grid, domain_integration, supports%cells(k), results(k))
    end do
    !$omp end parallel do

    call assemble(supports, cell_labels, results, efg)
    call check_results(where, cell_word, cell_ids, node_ids, support_scale, kernel, supports, results, efg, error)
    efg%setup_seconds = seconds_now() - started
  end subroutine build_cell_efg_part

  !> Everything one cell contributes: points, pairs, mass shares and transformation rows.
  subroutine process_cell(coordinates, hexahedra, supports, grid, domain_integration, cell, result)
    real(wp), intent(in) :: coordinates(:, :)
    integer, intent(in) :: hexahedra(:, :)
    type(part_supports_t), intent(in) :: supports
    type(particle_grid_t), intent(in) :: grid
    integer, intent(in) :: domain_integration, cell
    type(cell_result_t), intent(inout) :: result
    type(cell_shape_context_t) :: context
    real(wp), allocatable :: gradients(:, :, :), mass_volume(:), row_value(:), mass_parametric(:, :), rule_weight(:)
    integer, allocatable :: row_node(:)
    real(wp) :: volumes(8), largest_area
    integer :: n, g, k, pair, vertex, particle, row_count, total, order, points

    call prepare_cell_context(supports, grid, coordinates, hexahedra(:, cell), cell, context)
    n = context%node_count
    volumes = subcell_volumes(context%vertices)
    largest_area = largest_face_area(context%vertices)
    ! points per direction: IDIM 1 has 2x2x2 sub-cells, IDIM 2 2x2x2 and IDIM 4 4x4x4 Gauss points
    select case (domain_integration)
    case (integration_gauss_conventional)
      order = 4
    case default
      order = 2
    end select
    points = order**3
    allocate (result%point_volume(points), result%pair_count(points))
    result%pair_count = 0
    ! an inverted or degenerate cell is reported by the caller; nothing else is computed for it
    if (any(volumes <= 0.0_wp) .or. largest_area <= 0.0_wp) then
      result%point_volume = min(minval(volumes), 0.0_wp)
      allocate (result%pair_node(0), result%pair_gradient(3, 0), result%mass_node(0), result%mass_volume(0))
      allocate (result%row_particle(0), result%row_length(0), result%row_node(0), result%row_value(0))
      return
    end if

    allocate (gradients(3, n, points), mass_parametric(3, points), rule_weight(points))
    if (domain_integration == integration_local_boundary) then
      result%point_volume = volumes
      call cell_smoothed_gradients(context, volumes, gradients, result%singular_points, result%worst_residual)
      ! masses at the sub-cell centres with the sub-cell volumes
      mass_parametric = 0.5_wp*vertex_parametric
    else
      call cell_gauss_gradients(context, order, gradients, result%point_volume, result%singular_points, &
                                result%worst_residual)
      ! masses at the Gauss points themselves, with their W_g
      call cell_gauss_rule(order, mass_parametric, rule_weight)
    end if
    result%point_length = sum(volumes)/largest_area
    ! pairs: every local node whose gradient is not exactly zero, in ascending node order
    do g = 1, points
      result%pair_count(g) = count(any(gradients(:, 1:n, g) /= 0.0_wp, dim=1))
    end do
    allocate (result%pair_node(sum(result%pair_count)), result%pair_gradient(3, sum(result%pair_count)))
    pair = 0
    do g = 1, points
      do k = 1, n
        if (all(gradients(:, k, g) == 0.0_wp)) cycle
        pair = pair + 1
        result%pair_node(pair) = context%nodes(k)
        result%pair_gradient(:, pair) = gradients(:, k, g)
      end do
    end do

    allocate (mass_volume(n))
    call cell_mass_volumes(context, mass_parametric, result%point_volume, mass_volume, result%singular_points, &
                           result%worst_residual)
    result%mass_node = pack(context%nodes(1:n), mass_volume /= 0.0_wp)
    result%mass_volume = pack(mass_volume, mass_volume /= 0.0_wp)

    ! transformation rows of the particles this cell owns
    row_count = 0
    do vertex = 1, 8
      particle = supports%particle_of_node(hexahedra(vertex, cell))
      if (particle == 0) cycle
      if (supports%owner_cell(particle) == cell) row_count = row_count + 1
    end do
    result%row_count = row_count
    allocate (result%row_particle(row_count), result%row_length(row_count))
    allocate (row_node(n*max(row_count, 1)), row_value(n*max(row_count, 1)))
    row_count = 0
    total = 0
    do vertex = 1, 8
      particle = supports%particle_of_node(hexahedra(vertex, cell))
      if (particle == 0) cycle
      if (supports%owner_cell(particle) /= cell) cycle
      if (any(result%row_particle(1:row_count) == particle)) cycle
      row_count = row_count + 1
      result%row_particle(row_count) = particle
      call particle_transformation_row(context, vertex, row_node(total + 1:), row_value(total + 1:), &
                                       result%row_length(row_count), result%singular_points, result%worst_residual)
      total = total + result%row_length(row_count)
    end do
    result%row_count = row_count
    result%row_node = row_node(1:total)
    result%row_value = row_value(1:total)
  end subroutine process_cell

  !> Concatenate the cells' contributions in cell order.
  subroutine assemble(supports, cell_labels, results, efg)
    type(part_supports_t), intent(in) :: supports
    integer, intent(in) :: cell_labels(:)
    type(cell_result_t), intent(in) :: results(:)
    type(efg_part_t), intent(inout) :: efg
    integer, allocatable :: part_node(:), row_start(:), row_length(:), row_cell(:)
    integer :: cell_count, point_count, pair_count, k, g, point, pair, first, j, particle, r, start

    cell_count = size(results)
    point_count = 0
    do k = 1, cell_count
      point_count = point_count + size(results(k)%point_volume)
    end do
    pair_count = 0
    do k = 1, cell_count
      pair_count = pair_count + sum(results(k)%pair_count)
    end do
    allocate (efg%point_cell(point_count), efg%point_volume(point_count), efg%point_length(point_count))
    allocate (efg%point_offsets(point_count + 1), efg%pair_node(pair_count), efg%pair_gradient(3, pair_count))
    point = 0
    pair = 0
    efg%point_offsets(1) = 1
    do k = 1, cell_count
      first = pair + 1
      pair = pair + sum(results(k)%pair_count)
      efg%pair_node(first:pair) = results(k)%pair_node
      efg%pair_gradient(:, first:pair) = results(k)%pair_gradient
      do g = 1, size(results(k)%point_volume)
        point = point + 1
        efg%point_cell(point) = cell_labels(supports%cells(k))
        efg%point_volume(point) = results(k)%point_volume(g)
        efg%point_length(point) = results(k)%point_length
        efg%point_offsets(point + 1) = efg%point_offsets(point) + results(k)%pair_count(g)
      end do
    end do

    ! row-sum mass shares, every node of the part once, ascending
    allocate (part_node(maxval(supports%nodes)))
    part_node = 0
    do j = 1, size(supports%nodes)
      part_node(supports%nodes(j)) = j
    end do
    efg%mass_node = supports%nodes
    allocate (efg%mass_volume(size(supports%nodes)))
    efg%mass_volume = 0.0_wp
    do k = 1, cell_count
      do j = 1, size(results(k)%mass_node)
        associate (local => part_node(results(k)%mass_node(j)))
          efg%mass_volume(local) = efg%mass_volume(local) + results(k)%mass_volume(j)
        end associate
      end do
    end do

    ! transformation rows in particle order
    allocate (row_start(size(supports%particles)), row_length(size(supports%particles)))
    allocate (row_cell(size(supports%particles)))
    row_length = 0
    row_cell = 0
    row_start = 0
    do k = 1, cell_count
      start = 1
      do r = 1, results(k)%row_count
        particle = results(k)%row_particle(r)
        row_cell(particle) = k
        row_start(particle) = start
        row_length(particle) = results(k)%row_length(r)
        start = start + results(k)%row_length(r)
      end do
    end do
    allocate (efg%transform_offsets(size(supports%particles) + 1))
    efg%transform_offsets(1) = 1
    do particle = 1, size(supports%particles)
      efg%transform_offsets(particle + 1) = efg%transform_offsets(particle) + row_length(particle)
    end do
    allocate (efg%transform_node(efg%transform_offsets(size(supports%particles) + 1) - 1))
    allocate (efg%transform_value(size(efg%transform_node)))
    do particle = 1, size(supports%particles)
      if (row_cell(particle) == 0) cycle
      first = efg%transform_offsets(particle)
      associate (source => results(row_cell(particle)))
        efg%transform_node(first:first + row_length(particle) - 1) = &
          source%row_node(row_start(particle):row_start(particle) + row_length(particle) - 1)
        efg%transform_value(first:first + row_length(particle) - 1) = &
          source%row_value(row_start(particle):row_start(particle) + row_length(particle) - 1)
      end associate
    end do

    efg%singular_moment_points = 0
    do k = 1, cell_count
      efg%singular_moment_points = efg%singular_moment_points + results(k)%singular_points
    end do
  end subroutine assemble

  !> The section's EFG fields must select what is built (the deck reader checks them too; a
  !> model built otherwise is checked here).
  subroutine check_section(model, part, error)
    type(model_t), intent(in) :: model
    integer, intent(in) :: part
    type(error_t), allocatable, intent(out) :: error
    character(len=:), allocatable :: where

    if (part < 1 .or. part > size(model%parts)) then
      call make_error(error, "EFG set-up: part index "//integer_text(part)//" is not a part of the model")
      return
    end if
    where = "EFG part "//integer_text(model%parts(part)%id)
    if (model%parts(part)%formulation /= formulation_efg) then
      call make_error(error, where//": the part is not meshfree (its section is not ELFORM 41)")
      return
    end if
    if (model%parts(part)%section < 1 .or. model%parts(part)%section > size(model%sections)) then
      call make_error(error, where//": the part has no section")
      return
    end if
    associate (section => model%sections(model%parts(part)%section))
      where = where//", section "//integer_text(section%id)
      if (any(section%support_scale <= 1.0_wp)) then
        call make_error(error, where//": DX, DY and DZ must be greater than 1 (at 1.0 a vertex "// &
                        "weight vanishes on the cell's far corner)")
      else if (section%kernel /= kernel_cubic_box .and. section%kernel /= kernel_cubic_sphere) then
        call make_error(error, where//": ISPLINE must be 0 (cubic spline, box) or 2 (cubic spline, sphere)")
      else if (section%dilation_basis /= 0) then
        call make_error(error, where//": IDILA must be 0 (support from the nodes sharing an element)")
      else if (section%kernel_tolerance /= 0.0_wp) then
        call make_error(error, where//": TOLDEF must be 0 (Lagrangian kernel)")
      else if (section%boundary_treatment /= boundary_coupled .and. &
               section%boundary_treatment /= boundary_full_transformation) then
        call make_error(error, where//": IEBT must be 3 (coupled FE/EFG) or 1 (full transformation)")
      else if (section%domain_integration /= integration_local_boundary .and. &
               section%domain_integration /= integration_gauss .and. &
               section%domain_integration /= integration_gauss_conventional) then
        call make_error(error, where//": IDIM must be 1 (local boundary integration), 2 (2x2x2 Gauss) or 4 "// &
                        "(4x4x4 Gauss, conventional EFG for verification)")
      end if
    end associate
  end subroutine check_section

  !> Inverted cells, moment residuals above round-off, non-positive masses.
  subroutine check_results(where, cell_word, cell_ids, node_ids, support_scale, kernel, supports, results, efg, error)
    character(len=*), intent(in) :: where, cell_word
    integer, intent(in) :: cell_ids(:), node_ids(:)
    real(wp), intent(in) :: support_scale(3)
    integer, intent(in) :: kernel
    type(part_supports_t), intent(in) :: supports
    type(cell_result_t), intent(in) :: results(:)
    type(efg_part_t), intent(in) :: efg
    type(error_t), allocatable, intent(out) :: error
    character(len=:), allocatable :: listed
    real(wp) :: worst
    integer :: k, worst_cell, bad, j

    do k = 1, size(results)
      if (any(results(k)%point_volume <= 0.0_wp)) then
        call make_error(error, where//": "//cell_word//" "//integer_text(cell_ids(supports%cells(k)))// &
                        " has a non-positive (sub-)cell volume: it is inverted or degenerate")
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
    if (worst > moment_residual_tolerance) then
      call make_error(error, where//": "//cell_word//" "//integer_text(cell_ids(supports%cells(worst_cell)))// &
                      ": the moment equations M alpha = b are not solved to round-off (residual "// &
                      scientific_text(worst, 3)//"): b(X) is not in the range of M(X), so an interior vertex of "// &
                      "the cell does not cover it; each particle's support must be DX times the largest "// &
                      "distance to the nodes sharing an element with it (formulation section 2)")
      return
    end if

    bad = 0
    listed = ""
    do j = 1, size(efg%mass_volume)
      if (efg%mass_volume(j) > 0.0_wp) cycle
      bad = bad + 1
      if (bad <= 5) listed = listed//" "//integer_text(node_ids(efg%mass_node(j)))// &
                             " ("//scientific_text(efg%mass_volume(j), 3)//")"
    end do
    if (bad > 0) then
      call make_error(error, where//": "//integer_text(bad)//" node(s) get a non-positive row-sum mass; "// &
                      "node id (volume share):"//listed//". Likely cause: the supports are too large "// &
                      "for the part's thickness (DX "//fixed_text(support_scale(1), 2)//", "// &
                      trim(merge("spherical", "box      ", kernel == kernel_cubic_sphere))// &
                      " kernel): reduce DX or use the box kernel (ISPLINE 0)")
    end if
  end subroutine check_results
end module efg_setup
