!> Unit tests of the linear static analysis (static_analysis and its static_* modules) on
!> hand-built models:
!> - one hexahedron in uniaxial tension, by nodal loads and by a segment load (exact field,
!>   stress, energies), for ELFORM 1 and 2;
!> - linear patch tests (formulation section 7, property 5) with u = A X + c prescribed on the
!>   boundary of perturbed meshes: FE, EFG (IEBT 3, IDIM 1, several supports and both kernels),
!>   coupled EFG/FE (exact to 1e-10); EFG IDIM 2 and IEBT 1 (not exact, errors above 1e-4; IEBT 1
!>   holds its conditions through the transformation exactly);
!> - consistent loads of segment loads: uniform pressure on a warped quadrilateral and a triangle
!>   (total force and moment exact), a traction, a bilinear pressure;
!> - the cantilever of property 7 (Timoshenko-Goodier, nu = 0 so that the plane solution is exact
!>   in 3D): the tip deflection converges under refinement for FE, EFG and coupled models;
!> - reverse Cuthill-McKee on a shuffled numbering; singular models rejected with a message;
!>   a complete run into a results file.
program test_static
  use kinds, only: wp
  use error_handling, only: error_t
  use model, only: model_t, formulation_fe, formulation_efg, kernel_cubic_box, kernel_cubic_sphere, &
                   boundary_coupled, boundary_full_transformation, integration_local_boundary, &
                   integration_gauss, integration_gauss_conventional, motion_displacement, &
                   motion_velocity, prescribed_motion_t, spc_t, nodal_load_t, segment_load_t
  use material_laws, only: law_elastic
  use static_solution, only: static_solution_t
  use static_analysis, only: solve_static, run_static
  use static_loads, only: segment_consistent_forces
  use static_ordering, only: node_groups_t, add_node_group, reverse_cuthill_mckee
  use results_file, only: results_file_t, open_results, close_results
  use run_summary, only: run_summary_t, status_normal
  use file_system, only: make_directory
  use deck_reader, only: read_deck
  use error_handling, only: error_list_t
  use static_stiffness, only: add_point_stiffness, strain_displacement_matrix, elasticity_matrix
  use testing, only: test_suite_t, check, check_close, finish_suite
  use fixtures, only: random_uniform, cross, error_message
  implicit none

  type(test_suite_t) :: suite
  integer :: random_state = 20090321
  real(wp), parameter :: youngs_modulus = 210000.0_wp, poissons_ratio = 0.3_wp
  !> The linear field u = A X + c of the patch tests.
  real(wp), parameter :: field_gradient(3, 3) = reshape([0.7_wp, -0.2_wp, 0.4_wp, 0.3_wp, -0.5_wp, 0.1_wp, &
                                                         -0.6_wp, 0.2_wp, 0.9_wp], [3, 3])*1.0e-3_wp
  real(wp), parameter :: field_offset(3) = [0.3_wp, -1.1_wp, 0.6_wp]*1.0e-3_wp
  !> The cantilever: length, depth, width, total load, Young's modulus (nu = 0), I = b D^3 / 12.
  real(wp), parameter :: beam_length = 50.0_wp, beam_depth = 10.0_wp, beam_width = 2.0_wp, beam_load = 1.0e-3_wp, &
                         beam_modulus = 1.0_wp, beam_inertia = beam_width*beam_depth**3/12.0_wp

  suite%name = "static"
  call test_uniaxial_hexahedron(1)
  call test_uniaxial_hexahedron(2)
  call test_uniaxial_segment_load()
  call test_point_stiffness()
  call test_deck()
  call test_segment_loads()
  call test_fe_patch()
  call test_efg_patch(kernel_cubic_box, 1.2_wp, integration_local_boundary, boundary_coupled, 0, .true.)
  call test_efg_patch(kernel_cubic_box, 1.5_wp, integration_local_boundary, boundary_coupled, 0, .true.)
  call test_efg_patch(kernel_cubic_box, 2.0_wp, integration_local_boundary, boundary_coupled, 0, .true.)
  call test_efg_patch(kernel_cubic_sphere, 1.2_wp, integration_local_boundary, boundary_coupled, 0, .true.)
  call test_efg_patch(kernel_cubic_sphere, 1.5_wp, integration_local_boundary, boundary_coupled, 0, .true.)
  call test_efg_patch(kernel_cubic_box, 1.5_wp, integration_local_boundary, boundary_coupled, 2, .true.)
  call test_efg_patch(kernel_cubic_box, 1.5_wp, integration_gauss, boundary_coupled, 0, .false.)
  call test_efg_patch(kernel_cubic_box, 1.5_wp, integration_local_boundary, boundary_full_transformation, 0, .false.)
  call test_efg_patch(kernel_cubic_box, 1.5_wp, integration_gauss_conventional, boundary_full_transformation, 0, &
                      .false.)
  call test_efg_patch(kernel_cubic_box, 1.5_wp, integration_gauss_conventional, boundary_coupled, 0, .false.)
  call test_ordering()
  call test_singular_models()
  call test_rejected_models()
  call test_cantilever()
  call test_results_written()
  call finish_suite(suite)

contains

  ! ----------------------------------------------------------------------------------------
  ! model building

  pure integer function node_at(cells, i, j, k)
    integer, intent(in) :: cells(3), i, j, k
    node_at = 1 + i + (cells(1) + 1)*(j + (cells(2) + 1)*k)
  end function node_at

  !> A block of cells(1) x cells(2) x cells(3) hexahedra over [0, lengths], interior nodes moved
  !> randomly by up to `perturbation` of the cell size. Cells with i < efg_cells belong to part 1
  !> (id 11, EFG section: kernel, DX, IDIM, IEBT as given), the others to part 2 (id 12, solid
  !> ELFORM `element_formulation`). Node ids 100 + index, solid ids 5000 + index; one elastic
  !> material; curve 1 ramps from 0 at t = 0 to 1 at t = 1; end time 1; no conditions or loads.
  subroutine build_block(cells, lengths, perturbation, efg_cells, model, kernel, scale, domain_integration, &
                         boundary_treatment, element_formulation)
    integer, intent(in) :: cells(3)
    real(wp), intent(in) :: lengths(3), perturbation
    integer, intent(in) :: efg_cells
    type(model_t), intent(out) :: model
    integer, intent(in), optional :: kernel, domain_integration, boundary_treatment, element_formulation
    real(wp), intent(in), optional :: scale
    integer :: i, j, k, node, cell, index(3)
    real(wp) :: spacing(3)

    random_state = 20090321
    spacing = lengths/real(cells, wp)
    allocate (model%coordinates(3, product(cells + 1)), model%node_ids(product(cells + 1)))
    allocate (model%initial_velocity(3, product(cells + 1)))
    model%initial_velocity = 0.0_wp
    do k = 0, cells(3)
      do j = 0, cells(2)
        do i = 0, cells(1)
          index = [i, j, k]
          node = node_at(cells, i, j, k)
          model%node_ids(node) = 100 + node
          model%coordinates(:, node) = real(index, wp)*spacing
          if (all(index > 0 .and. index < cells)) model%coordinates(:, node) = model%coordinates(:, node) + &
            perturbation*spacing*[random_uniform(random_state), random_uniform(random_state), random_uniform(random_state)]
        end do
      end do
    end do
    allocate (model%solid_nodes(8, product(cells)), model%solid_part(product(cells)), model%solid_ids(product(cells)))
    do k = 0, cells(3) - 1
      do j = 0, cells(2) - 1
        do i = 0, cells(1) - 1
          cell = 1 + i + cells(1)*(j + cells(2)*k)
          model%solid_ids(cell) = 5000 + cell
          model%solid_nodes(:, cell) = [node_at(cells, i, j, k), node_at(cells, i + 1, j, k), &
                                        node_at(cells, i + 1, j + 1, k), node_at(cells, i, j + 1, k), &
                                        node_at(cells, i, j, k + 1), node_at(cells, i + 1, j, k + 1), &
                                        node_at(cells, i + 1, j + 1, k + 1), node_at(cells, i, j + 1, k + 1)]
          model%solid_part(cell) = merge(1, 2, i < efg_cells)
        end do
      end do
    end do
    allocate (model%materials(1), model%sections(2), model%parts(2), model%curves(1))
    model%materials(1)%id = 3
    model%materials(1)%law = law_elastic
    model%materials(1)%density = 7.85e-9_wp
    model%materials(1)%youngs_modulus = youngs_modulus
    model%materials(1)%poissons_ratio = poissons_ratio
    model%sections(1)%id = 21
    model%sections(1)%element_formulation = 41
    model%sections(1)%support_scale = 1.5_wp
    if (present(scale)) model%sections(1)%support_scale = scale
    if (present(kernel)) model%sections(1)%kernel = kernel
    if (present(domain_integration)) model%sections(1)%domain_integration = domain_integration
    if (present(boundary_treatment)) model%sections(1)%boundary_treatment = boundary_treatment
    model%sections(2)%id = 22
    model%sections(2)%element_formulation = 1
    if (present(element_formulation)) model%sections(2)%element_formulation = element_formulation
    model%parts(1)%id = 11
    model%parts(1)%section = 1
    model%parts(1)%material = 1
    model%parts(1)%material_id = 3
    model%parts(1)%formulation = formulation_efg
    model%parts(2)%id = 12
    model%parts(2)%section = 2
    model%parts(2)%material = 1
    model%parts(2)%material_id = 3
    model%parts(2)%formulation = formulation_fe
    model%curves(1)%id = 1
    model%curves(1)%abscissa = [0.0_wp, 1.0_wp]
    model%curves(1)%ordinate = [0.0_wp, 1.0_wp]
    model%end_time = 1.0_wp
    allocate (model%spcs(0), model%motions(0), model%loads(0), model%segment_loads(0), model%walls(0))
    allocate (model%node_sets(0), model%part_sets(0), model%hourglasses(0))
    allocate (model%output%history_nodes(0))
  end subroutine build_block

  !> Prescribe displacement `values` (3) on `node` (VAD 2, the ramp curve scaled: full value at
  !> the end time).
  subroutine prescribe(model, node, values)
    type(model_t), intent(inout) :: model
    integer, intent(in) :: node
    real(wp), intent(in) :: values(3)
    integer :: direction
    do direction = 1, 3
      model%motions = [model%motions, motion_of(node, direction, values(direction))]
    end do
  end subroutine prescribe

  function motion_of(node, direction, value) result(motion)
    integer, intent(in) :: node, direction
    real(wp), intent(in) :: value
    type(prescribed_motion_t) :: motion
    motion%node = node
    motion%direction = direction
    motion%kind = motion_displacement
    motion%curve = 1
    motion%scale = value
  end function motion_of

  !> Fix the chosen directions of `node`.
  subroutine support(model, node, fixed)
    type(model_t), intent(inout) :: model
    integer, intent(in) :: node
    logical, intent(in) :: fixed(3)
    type(spc_t) :: spc
    spc%node = node
    spc%fixed = fixed
    model%spcs = [model%spcs, spc]
  end subroutine support

  !> A nodal load of `value` in `direction` on `node`, through the ramp curve.
  subroutine load_node(model, node, direction, value)
    type(model_t), intent(inout) :: model
    integer, intent(in) :: node, direction
    real(wp), intent(in) :: value
    type(nodal_load_t) :: load
    load%node = node
    load%direction = direction
    load%curve = 1
    load%scale = value
    model%loads = [model%loads, load]
  end subroutine load_node

  !> Whether the node of grid index (i, j, k) lies on the block's boundary.
  pure logical function on_boundary(cells, i, j, k)
    integer, intent(in) :: cells(3), i, j, k
    on_boundary = any([i, j, k] == 0) .or. i == cells(1) .or. j == cells(2) .or. k == cells(3)
  end function on_boundary

  !> Prescribe u = A X + c on every boundary node of the block.
  subroutine prescribe_linear_field(model, cells)
    type(model_t), intent(inout) :: model
    integer, intent(in) :: cells(3)
    integer :: i, j, k, node
    do k = 0, cells(3)
      do j = 0, cells(2)
        do i = 0, cells(1)
          if (.not. on_boundary(cells, i, j, k)) cycle
          node = node_at(cells, i, j, k)
          call prescribe(model, node, linear_field(model%coordinates(:, node)))
        end do
      end do
    end do
  end subroutine prescribe_linear_field

  pure function linear_field(position) result(value)
    real(wp), intent(in) :: position(3)
    real(wp) :: value(3)
    value = matmul(field_gradient, position) + field_offset
  end function linear_field

  !> Cauchy stress of the linear field, D sym(A), in output order.
  pure function linear_field_stress() result(stress)
    real(wp) :: stress(6)
    real(wp) :: lambda, mu, strain(3, 3)
    integer :: i
    mu = youngs_modulus/(2.0_wp*(1.0_wp + poissons_ratio))
    lambda = youngs_modulus*poissons_ratio/((1.0_wp + poissons_ratio)*(1.0_wp - 2.0_wp*poissons_ratio))
    strain = 0.5_wp*(field_gradient + transpose(field_gradient))
    do i = 1, 3
      stress(i) = lambda*(strain(1, 1) + strain(2, 2) + strain(3, 3)) + 2.0_wp*mu*strain(i, i)
    end do
    stress(4) = 2.0_wp*mu*strain(1, 2)
    stress(5) = 2.0_wp*mu*strain(2, 3)
    stress(6) = 2.0_wp*mu*strain(3, 1)
  end function linear_field_stress

  function label_of(kernel, scale, domain_integration, boundary_treatment, fe_cells) result(text)
    integer, intent(in) :: kernel, domain_integration, boundary_treatment, fe_cells
    real(wp), intent(in) :: scale
    character(len=:), allocatable :: text
    character(len=96) :: buffer
    write (buffer, '(a,f4.2,a,i0,a,i0,a,i0)') merge("box DX    ", "sphere DX ", kernel == kernel_cubic_box), scale, &
      " IDIM ", domain_integration, " IEBT ", boundary_treatment, " FE cells in x ", fe_cells
    text = trim(buffer)
  end function label_of

  ! ----------------------------------------------------------------------------------------
  ! tests

  !> One box-shaped hexahedron pulled along x by F on its x = Lx face: u_x = F x / (E A),
  !> u_y = -nu F y / (E A), u_z = -nu F z / (E A) exactly, sigma_xx = F / A, strain energy
  !> F^2 Lx / (2 E A). Supports: u_x = 0 on x = 0, plus y and z at two nodes against rotation.
  subroutine test_uniaxial_hexahedron(element_formulation)
    integer, intent(in) :: element_formulation
    type(model_t) :: model
    type(static_solution_t) :: solution
    type(error_t), allocatable :: error
    real(wp), parameter :: lengths(3) = [2.0_wp, 1.5_wp, 1.2_wp], force = 300.0_wp
    real(wp) :: area, expected(3), worst, strain_energy
    integer :: node
    character(len=:), allocatable :: name

    name = "uniaxial hexahedron ELFORM "//achar(48 + element_formulation)//": "
    call build_block([1, 1, 1], lengths, 0.0_wp, 0, model, element_formulation=element_formulation)
    area = lengths(2)*lengths(3)
    do node = 1, 8
      if (model%coordinates(1, node) == 0.0_wp) then
        call support(model, node, [.true., .false., .false.])
      else
        call load_node(model, node, 1, 0.25_wp*force)
      end if
    end do
    call support(model, node_at([1, 1, 1], 0, 0, 0), [.true., .true., .true.])
    call support(model, node_at([1, 1, 1], 0, 1, 0), [.false., .false., .true.])
    call support(model, node_at([1, 1, 1], 0, 0, 1), [.false., .true., .false.])
    call solve_static(model, solution, error)
    call check(suite, name//"solves", .not. allocated(error), error_message(error, "no error"))
    if (allocated(error)) return
    worst = 0.0_wp
    do node = 1, 8
      expected = force/(youngs_modulus*area)*[1.0_wp, -poissons_ratio, -poissons_ratio]*model%coordinates(:, node)
      worst = max(worst, maxval(abs(solution%displacement(:, node) - expected)))
    end do
    call check_close(suite, name//"exact displacements", worst, 0.0_wp, &
                     thr=1.0e-12_wp*force*lengths(1)/(youngs_modulus*area))
    call check_close(suite, name//"stress", solution%solid_stress(:, 1), [force/area, 0.0_wp, 0.0_wp, 0.0_wp, &
                     0.0_wp, 0.0_wp], thr=1.0e-11_wp*force/area)
    strain_energy = force**2*lengths(1)/(2.0_wp*youngs_modulus*area)
    call check_close(suite, name//"strain energy", solution%internal_energy, strain_energy, rel=1.0e-12_wp)
    call check_close(suite, name//"external work", solution%external_work, strain_energy, rel=1.0e-12_wp)
    call check(suite, name//"Cholesky without multipliers", solution%cholesky .and. solution%multipliers == 0)
    call check(suite, name//"equilibrium residual at round-off", solution%residual < 1.0e-12_wp)
  end subroutine test_uniaxial_hexahedron

  !> The same bar pulled by a uniform traction -p (a negative pressure) on its x = Lx face, the
  !> face written so that its right-hand normal points out of the solid, and by a traction along
  !> +x: both give the exact uniaxial field.
  subroutine test_uniaxial_segment_load()
    type(model_t) :: model
    type(static_solution_t) :: solution
    type(error_t), allocatable :: error
    real(wp), parameter :: lengths(3) = [2.0_wp, 1.5_wp, 1.2_wp], stress = 100.0_wp
    real(wp) :: expected(3), worst
    integer :: node, variant
    character(len=:), allocatable :: name

    do variant = 1, 2
      name = "uniaxial hexahedron, "//trim(merge("pressure -p ", "traction +x ", variant == 1))//": "
      call build_block([1, 1, 1], lengths, 0.0_wp, 0, model)
      do node = 1, 8
        if (model%coordinates(1, node) == 0.0_wp) call support(model, node, [.true., .false., .false.])
      end do
      call support(model, node_at([1, 1, 1], 0, 0, 0), [.true., .true., .true.])
      call support(model, node_at([1, 1, 1], 0, 1, 0), [.false., .false., .true.])
      call support(model, node_at([1, 1, 1], 0, 0, 1), [.false., .true., .false.])
      deallocate (model%segment_loads)
      allocate (model%segment_loads(1))
      ! outward normal +x: (y, z) counterclockwise seen from +x
      model%segment_loads(1)%nodes = [node_at([1, 1, 1], 1, 0, 0), node_at([1, 1, 1], 1, 1, 0), &
                                      node_at([1, 1, 1], 1, 1, 1), node_at([1, 1, 1], 1, 0, 1)]
      model%segment_loads(1)%curve = 1
      if (variant == 1) then
        model%segment_loads(1)%nodal_values = -stress
      else
        model%segment_loads(1)%nodal_values = stress
        model%segment_loads(1)%along_normal = .false.
        model%segment_loads(1)%direction = [1.0_wp, 0.0_wp, 0.0_wp]
      end if
      call solve_static(model, solution, error)
      call check(suite, name//"solves", .not. allocated(error), error_message(error, "no error"))
      if (allocated(error)) return
      worst = 0.0_wp
      do node = 1, 8
        expected = stress/youngs_modulus*[1.0_wp, -poissons_ratio, -poissons_ratio]*model%coordinates(:, node)
        worst = max(worst, maxval(abs(solution%displacement(:, node) - expected)))
      end do
      call check_close(suite, name//"exact displacements", worst, 0.0_wp, &
                       thr=1.0e-12_wp*stress*lengths(1)/youngs_modulus)
      call check_close(suite, name//"stress xx", solution%solid_stress(1, 1), stress, rel=1.0e-12_wp)
    end do
  end subroutine test_uniaxial_segment_load

  !> The node-pair form of the point stiffness equals the dense W B^T D B.
  subroutine test_point_stiffness()
    real(wp) :: gradients(3, 5), b(6, 15), d(6, 6), dense(15, 15), paired(15, 15), bulk, shear, lambda
    integer :: a, c
    do a = 1, 5
      do c = 1, 3
        gradients(c, a) = random_uniform(random_state)
      end do
    end do
    shear = youngs_modulus/(2.0_wp*(1.0_wp + poissons_ratio))
    bulk = youngs_modulus/(3.0_wp*(1.0_wp - 2.0_wp*poissons_ratio))
    lambda = bulk - 2.0_wp*shear/3.0_wp
    d = elasticity_matrix(bulk, shear)
    call strain_displacement_matrix(gradients, b)
    dense = 0.7_wp*matmul(transpose(b), matmul(d, b))
    paired = 0.0_wp
    call add_point_stiffness(0.7_wp, gradients, [1, 2, 3, 4, 5], lambda, shear, paired)
    call check_close(suite, "point stiffness: node pairs equal W B^T D B", reshape(paired, [225]), &
                     reshape(dense, [225]), thr=1.0e-12_wp*maxval(abs(dense)))
    paired = 0.0_wp
    call add_point_stiffness(0.7_wp, gradients(:, [3, 1]), [5, 2], lambda, shear, paired)
    call check_close(suite, "point stiffness: blocks at the given positions", &
                     [paired(13:15, 4:6), paired(4:6, 13:15)], [dense(7:9, 1:3), dense(1:3, 7:9)], &
                     thr=1.0e-12_wp*maxval(abs(dense)))
  end subroutine test_point_stiffness

  !> A deck read by read_deck: *CONTROL_IMPLICIT_GENERAL IMFLAG 1, ENDTIM 2 with a curve that
  !> reaches 1 at t = 2, *BOUNDARY_SPC_NODE and a negative *LOAD_SEGMENT pressure pulling a
  !> 2 x 1 x 1 bar of two solids: the exact uniaxial field.
  subroutine test_deck()
    type(model_t) :: model
    type(static_solution_t) :: solution
    type(error_t), allocatable :: error
    type(error_list_t) :: warnings
    character(len=:), allocatable :: path
    character(len=1024) :: value
    integer :: length, status, unit, i, j, k, node
    real(wp) :: expected(3), worst
    real(wp), parameter :: stress = 100.0_wp

    call get_environment_variable("TMPDIR", value, length, status)
    if (status /= 0 .or. length == 0) value = "/tmp"
    path = trim(value)//"/crashfree_test_static_deck.k"
    open (newunit=unit, file=path, status="replace", action="write", iostat=status)
    call check(suite, "deck: written", status == 0, path)
    if (status /= 0) return
    write (unit, '(a)') "*KEYWORD", "*TITLE", "static bar", "*CONTROL_IMPLICIT_GENERAL", "         1", &
      "*CONTROL_TERMINATION", "       2.0", "*PART", "bar", "         1         1         1", "*SECTION_SOLID", &
      "         1         2", "*MAT_ELASTIC", "         1   7.85e-9  210000.0       0.3", "*DEFINE_CURVE", &
      "         1", "                 0.0                 0.0", "                 2.0                 1.0", "*NODE"
    do k = 0, 1
      do j = 0, 1
        do i = 0, 2
          write (unit, '(i8,3f16.6)') node_at([2, 1, 1], i, j, k), real(i, wp), real(j, wp), real(k, wp)
        end do
      end do
    end do
    write (unit, '(a)') "*ELEMENT_SOLID"
    do i = 0, 1
      write (unit, '(10i8)') i + 1, 1, node_at([2, 1, 1], i, 0, 0), node_at([2, 1, 1], i + 1, 0, 0), &
        node_at([2, 1, 1], i + 1, 1, 0), node_at([2, 1, 1], i, 1, 0), node_at([2, 1, 1], i, 0, 1), &
        node_at([2, 1, 1], i + 1, 0, 1), node_at([2, 1, 1], i + 1, 1, 1), node_at([2, 1, 1], i, 1, 1)
    end do
    write (unit, '(a)') "*BOUNDARY_SPC_NODE"
    do k = 0, 1
      do j = 0, 1
        write (unit, '(6i10)') node_at([2, 1, 1], 0, j, k), 0, 1, merge(1, 0, k == 1 .and. j == 0 .or. &
          j == 0 .and. k == 0), merge(1, 0, j == 1 .and. k == 0 .or. j == 0 .and. k == 0)
      end do
    end do
    ! the x = 2 face, counterclockwise seen from +x
    write (unit, '(a)') "*LOAD_SEGMENT"
    write (unit, '(i10,f10.1,f10.1,4i10)') 1, -stress, 0.0_wp, node_at([2, 1, 1], 2, 0, 0), &
      node_at([2, 1, 1], 2, 1, 0), node_at([2, 1, 1], 2, 1, 1), node_at([2, 1, 1], 2, 0, 1)
    write (unit, '(a)') "*END"
    close (unit)

    call read_deck(path, model, warnings, error, .false.)
    call check(suite, "deck: read", .not. allocated(error), error_message(error, "no error"))
    open (newunit=unit, file=path, status="old", iostat=status)
    if (status == 0) close (unit, status="delete")
    if (allocated(error)) return
    call check(suite, "deck: IMFLAG 1 selects the static analysis", model%implicit_static)
    call solve_static(model, solution, error)
    call check(suite, "deck: solves", .not. allocated(error), error_message(error, "no error"))
    if (allocated(error)) return
    call check_close(suite, "deck: loads at the end time ENDTIM", solution%time, 2.0_wp, thr=0.0_wp)
    worst = 0.0_wp
    do node = 1, size(model%node_ids)
      expected = stress/youngs_modulus*[1.0_wp, -poissons_ratio, -poissons_ratio]*model%coordinates(:, node)
      worst = max(worst, maxval(abs(solution%displacement(:, node) - expected)))
    end do
    call check_close(suite, "deck: exact uniaxial displacements", worst, 0.0_wp, &
                     thr=1.0e-12_wp*2.0_wp*stress/youngs_modulus)
    call check_close(suite, "deck: stress xx of both solids", solution%solid_stress(1, :), [stress, stress], &
                     rel=1.0e-12_wp)
  end subroutine test_deck

  !> Consistent forces of segment loads against closed forms: a uniform pressure on a warped
  !> quadrilateral (total -p times the vector area (x3 - x1) x (x4 - x2) / 2, exact on any bilinear
  !> surface), its moment on a plane distorted quadrilateral (-p A c x n, c the centroid), a
  !> triangle, a traction along a direction, and a pressure linear in x on a plane quadrilateral
  !> (total -n times the integral of p).
  subroutine test_segment_loads()
    real(wp), parameter :: pressure = 2.5_wp
    real(wp) :: warped(3, 4), plane(3, 4), triangle(3, 4), forces(3, 4), expected(3), normal(3), area
    real(wp) :: centroid(3), moment(3), first_area, second_area, values(4), integral
    integer :: a

    warped = reshape([0.1_wp, -0.2_wp, 0.05_wp, 2.3_wp, 0.1_wp, -0.3_wp, 2.0_wp, 1.7_wp, 0.4_wp, &
                      -0.4_wp, 1.2_wp, 0.1_wp], [3, 4])
    call segment_consistent_forces(warped, [pressure, pressure, pressure, pressure], .true., [0.0_wp, 0.0_wp, 0.0_wp], &
                                   forces)
    expected = -pressure*0.5_wp*cross(warped(:, 3) - warped(:, 1), warped(:, 4) - warped(:, 2))
    call check_close(suite, "segment load: uniform pressure on a warped quadrilateral, total force", &
                     sum(forces, dim=2), expected, thr=1.0e-13_wp*norm2(expected))

    ! a plane quadrilateral, distorted, tilted out of the coordinate planes
    plane(:, 1) = [0.0_wp, 0.0_wp, 0.0_wp]
    plane(:, 2) = [3.0_wp, 0.4_wp, 0.0_wp]
    plane(:, 3) = [2.2_wp, 2.5_wp, 0.0_wp]
    plane(:, 4) = [-0.5_wp, 1.6_wp, 0.0_wp]
    do a = 1, 4
      plane(:, a) = [plane(1, a), 0.8_wp*plane(2, a), 0.6_wp*plane(2, a)] + [1.0_wp, -2.0_wp, 0.5_wp]
    end do
    call segment_consistent_forces(plane, [pressure, pressure, pressure, pressure], .true., [0.0_wp, 0.0_wp, 0.0_wp], &
                                   forces)
    normal = cross(plane(:, 3) - plane(:, 1), plane(:, 4) - plane(:, 2))
    area = 0.5_wp*norm2(normal)
    normal = normal/norm2(normal)
    first_area = 0.5_wp*norm2(cross(plane(:, 2) - plane(:, 1), plane(:, 3) - plane(:, 1)))
    second_area = 0.5_wp*norm2(cross(plane(:, 3) - plane(:, 1), plane(:, 4) - plane(:, 1)))
    centroid = (first_area*(plane(:, 1) + plane(:, 2) + plane(:, 3)) + &
                second_area*(plane(:, 1) + plane(:, 3) + plane(:, 4)))/(3.0_wp*(first_area + second_area))
    moment = 0.0_wp
    do a = 1, 4
      moment = moment + cross(plane(:, a), forces(:, a))
    end do
    call check_close(suite, "segment load: uniform pressure on a plane quadrilateral, total force", &
                     sum(forces, dim=2), -pressure*area*normal, thr=1.0e-13_wp*pressure*area)
    call check_close(suite, "segment load: uniform pressure on a plane quadrilateral, moment", moment, &
                     cross(centroid, -pressure*area*normal), thr=1.0e-13_wp*pressure*area*norm2(centroid))

    ! traction along a direction on the plane quadrilateral
    call segment_consistent_forces(plane, [pressure, pressure, pressure, pressure], .false., &
                                   [0.0_wp, 0.6_wp, -0.8_wp], forces)
    call check_close(suite, "segment load: traction along a direction, total force", sum(forces, dim=2), &
                     pressure*area*[0.0_wp, 0.6_wp, -0.8_wp], thr=1.0e-13_wp*pressure*area)

    ! pressure linear in the first coordinate: its corner values are exact, and the total force is
    ! the pressure at the centroid times the area
    do a = 1, 4
      values(a) = pressure*(1.0_wp + 0.3_wp*plane(1, a))
    end do
    call segment_consistent_forces(plane, values, .true., [0.0_wp, 0.0_wp, 0.0_wp], forces)
    integral = pressure*(1.0_wp + 0.3_wp*centroid(1))*area
    call check_close(suite, "segment load: linear pressure, total force", sum(forces, dim=2), -integral*normal, &
                     thr=1.0e-13_wp*integral)

    ! a triangle (corner 4 repeats corner 3)
    triangle(:, 1:3) = warped(:, 1:3)
    triangle(:, 4) = warped(:, 3)
    call segment_consistent_forces(triangle, [pressure, pressure, pressure, pressure], .true., &
                                   [0.0_wp, 0.0_wp, 0.0_wp], forces)
    expected = -pressure*0.5_wp*cross(triangle(:, 2) - triangle(:, 1), triangle(:, 3) - triangle(:, 1))
    call check_close(suite, "segment load: uniform pressure on a triangle, total force", sum(forces, dim=2), &
                     expected, thr=1.0e-13_wp*norm2(expected))
    call check_close(suite, "segment load: uniform pressure on a triangle, a third per corner", &
                     [forces(:, 1), forces(:, 2), forces(:, 3) + forces(:, 4)], [expected, expected, expected]/3.0_wp, &
                     thr=1.0e-13_wp*norm2(expected))
  end subroutine test_segment_loads

  !> Linear patch test on a perturbed 4x4x4 FE block (ELFORM 1, integrated fully): interior
  !> displacements and every element stress exact.
  subroutine test_fe_patch()
    type(model_t) :: model
    type(static_solution_t) :: solution
    type(error_t), allocatable :: error
    integer, parameter :: cells(3) = [4, 4, 4]
    real(wp) :: worst, reference, stress_error
    integer :: node, solid

    call build_block(cells, [1.2_wp, 1.0_wp, 0.8_wp], 0.25_wp, 0, model)
    call prescribe_linear_field(model, cells)
    call solve_static(model, solution, error)
    call check(suite, "FE patch test: solves", .not. allocated(error), error_message(error, "no error"))
    if (allocated(error)) return
    worst = 0.0_wp
    reference = 0.0_wp
    do node = 1, size(model%node_ids)
      worst = max(worst, maxval(abs(solution%displacement(:, node) - linear_field(model%coordinates(:, node)))))
      reference = max(reference, maxval(abs(linear_field(model%coordinates(:, node)))))
    end do
    call check_close(suite, "FE patch test: displacements exact to 1e-10", worst/reference, 0.0_wp, thr=1.0e-10_wp)
    stress_error = 0.0_wp
    do solid = 1, size(model%solid_ids)
      stress_error = max(stress_error, maxval(abs(solution%solid_stress(:, solid) - linear_field_stress())))
    end do
    stress_error = stress_error/maxval(abs(linear_field_stress()))
    call check_close(suite, "FE patch test: stresses exact to 1e-10", stress_error, 0.0_wp, thr=1.0e-10_wp)
    write (*, '(a,es9.2,a,es9.2)') "  FE patch test: largest relative displacement error ", worst/reference, &
      ", stress error ", stress_error
  end subroutine test_fe_patch

  !> Linear patch test on a perturbed 5x4x4 block whose first `5 - fe_cells` cells in x are EFG
  !> (the rest FE): exact to 1e-10 with the full method (IEBT 3, IDIM 1), not exact (error above
  !> 1e-4) with the Gauss variant or the full transformation. With IEBT 1 the conditions act on
  !> the transformed displacements of the boundary particles and must hold exactly.
  subroutine test_efg_patch(kernel, scale, domain_integration, boundary_treatment, fe_cells, exact)
    integer, intent(in) :: kernel, domain_integration, boundary_treatment, fe_cells
    real(wp), intent(in) :: scale
    logical, intent(in) :: exact
    type(model_t) :: model
    type(static_solution_t) :: solution
    type(error_t), allocatable :: error
    integer, parameter :: cells(3) = [5, 4, 4]
    real(wp) :: worst, worst_boundary, reference, stress_error
    integer :: node, solid, i, j, k
    character(len=:), allocatable :: name

    name = "EFG patch test, "//label_of(kernel, scale, domain_integration, boundary_treatment, fe_cells)//": "
    call build_block(cells, [1.5_wp, 1.0_wp, 0.8_wp], 0.25_wp, cells(1) - fe_cells, model, kernel=kernel, &
                     scale=scale, domain_integration=domain_integration, boundary_treatment=boundary_treatment)
    call prescribe_linear_field(model, cells)
    call solve_static(model, solution, error)
    call check(suite, name//"solves", .not. allocated(error), error_message(error, "no error"))
    if (allocated(error)) return
    worst = 0.0_wp
    worst_boundary = 0.0_wp
    reference = 0.0_wp
    do k = 0, cells(3)
      do j = 0, cells(2)
        do i = 0, cells(1)
          node = node_at(cells, i, j, k)
          associate (difference => maxval(abs(solution%displacement(:, node) - &
                                              linear_field(model%coordinates(:, node)))))
            if (on_boundary(cells, i, j, k)) then
              worst_boundary = max(worst_boundary, difference)
            else
              worst = max(worst, difference)
            end if
          end associate
          reference = max(reference, maxval(abs(linear_field(model%coordinates(:, node)))))
        end do
      end do
    end do
    stress_error = 0.0_wp
    do solid = 1, size(model%solid_ids)
      stress_error = max(stress_error, maxval(abs(solution%solid_stress(:, solid) - linear_field_stress())))
    end do
    stress_error = stress_error/maxval(abs(linear_field_stress()))
    write (*, '(a,es9.2,a,es9.2,a,i0,a,i0,a,i0)') "  "//name//"interior error ", worst/reference, ", stress error ", &
      stress_error, ", half bandwidth ", solution%half_bandwidth, " (node order ", solution%natural_half_bandwidth, &
      "), multipliers ", solution%multipliers
    call check_close(suite, name//"boundary conditions hold", worst_boundary/reference, 0.0_wp, thr=1.0e-10_wp)
    if (exact) then
      call check_close(suite, name//"interior displacements exact to 1e-10", worst/reference, 0.0_wp, thr=1.0e-10_wp)
      call check_close(suite, name//"stresses exact to 1e-10", stress_error, 0.0_wp, thr=1.0e-10_wp)
    else
      call check(suite, name//"not exact (interior error above 1e-4)", worst/reference > 1.0e-4_wp)
    end if
    if (boundary_treatment == boundary_full_transformation) then
      call check(suite, name//"conditions by multipliers (banded LU)", &
                 solution%multipliers == 3*count([(on_boundary_index(cells, node), node=1, size(model%node_ids))]) &
                 .and. .not. solution%cholesky)
    else
      call check(suite, name//"conditions eliminated (banded Cholesky)", &
                 solution%multipliers == 0 .and. solution%cholesky)
    end if
    call check(suite, name//"strain energy equals external work", &
               abs(solution%internal_energy - solution%external_work) <= 1.0e-9_wp*solution%internal_energy)
  end subroutine test_efg_patch

  pure logical function on_boundary_index(cells, node)
    integer, intent(in) :: cells(3), node
    integer :: i, j, k
    i = mod(node - 1, cells(1) + 1)
    j = mod((node - 1)/(cells(1) + 1), cells(2) + 1)
    k = (node - 1)/((cells(1) + 1)*(cells(2) + 1))
    on_boundary_index = on_boundary(cells, i, j, k)
  end function on_boundary_index

  !> Reverse Cuthill-McKee restores a narrow band on a block whose node numbers were shuffled,
  !> and the solution does not depend on the numbering.
  subroutine test_ordering()
    type(model_t) :: model, shuffled
    type(static_solution_t) :: solution, shuffled_solution
    type(error_t), allocatable :: error
    type(node_groups_t) :: groups
    integer, parameter :: cells(3) = [8, 3, 3]
    integer, allocatable :: permutation(:), inverse(:), order(:)
    integer :: k, swap, other, solid, node

    call build_block(cells, [4.0_wp, 1.5_wp, 1.5_wp], 0.2_wp, 0, model)
    do node = 1, size(model%node_ids)
      if (model%coordinates(1, node) == 0.0_wp) call support(model, node, [.true., .true., .true.])
      if (model%coordinates(1, node) == 4.0_wp) call load_node(model, node, 2, 1.0_wp)
    end do
    ! a random permutation of the node indices
    permutation = [(k, k=1, size(model%node_ids))]
    do k = size(permutation), 2, -1
      other = 1 + int(0.5_wp*(random_uniform(random_state) + 1.0_wp)*real(k, wp))
      other = min(max(other, 1), k)
      swap = permutation(k)
      permutation(k) = permutation(other)
      permutation(other) = swap
    end do
    allocate (inverse(size(permutation)))
    inverse(permutation) = [(k, k=1, size(permutation))]
    shuffled = model
    shuffled%coordinates(:, inverse) = model%coordinates
    shuffled%node_ids(inverse) = model%node_ids
    do solid = 1, size(model%solid_ids)
      shuffled%solid_nodes(:, solid) = inverse(model%solid_nodes(:, solid))
    end do
    do k = 1, size(model%spcs)
      shuffled%spcs(k)%node = inverse(model%spcs(k)%node)
    end do
    do k = 1, size(model%loads)
      shuffled%loads(k)%node = inverse(model%loads(k)%node)
    end do

    call solve_static(model, solution, error)
    call check(suite, "ordering: ordered block solves", .not. allocated(error), error_message(error, "no error"))
    call solve_static(shuffled, shuffled_solution, error)
    call check(suite, "ordering: shuffled block solves", .not. allocated(error), error_message(error, "no error"))
    if (allocated(error)) return
    write (*, '(a,3(i0,a))') "  ordering, shuffled 8x3x3 block: half bandwidth reverse Cuthill-McKee ", &
      shuffled_solution%rcm_half_bandwidth, ", coordinate order ", shuffled_solution%coordinate_half_bandwidth, &
      ", deck order ", shuffled_solution%natural_half_bandwidth, ""
    call check(suite, "ordering: RCM narrows the shuffled band at least threefold", &
               3*shuffled_solution%rcm_half_bandwidth <= shuffled_solution%natural_half_bandwidth)
    ! 9 x 4 x 4 nodes: RCM levels are about a cross-section of 16 nodes (48 dofs) thick, and a
    ! hexahedron spans two of them
    call check(suite, "ordering: RCM band within two cross-sections", &
               shuffled_solution%rcm_half_bandwidth <= 2*3*(cells(2) + 1)*(cells(3) + 1))
    call check(suite, "ordering: the narrowest candidate is used", shuffled_solution%half_bandwidth == &
               min(shuffled_solution%rcm_half_bandwidth, shuffled_solution%coordinate_half_bandwidth, &
                   shuffled_solution%natural_half_bandwidth))
    call check(suite, "ordering: the coordinate order does not depend on the numbering", &
               shuffled_solution%coordinate_half_bandwidth == solution%coordinate_half_bandwidth)
    call check_close(suite, "ordering: the solution does not depend on the numbering", &
                     reshape(shuffled_solution%displacement(:, inverse), [3*size(inverse)]), &
                     reshape(solution%displacement, [3*size(inverse)]), &
                     thr=1.0e-10_wp*maxval(abs(solution%displacement)))

    ! the ordering alone, on two separate components and an unused node
    call add_node_group(groups, [1, 2, 3])
    call add_node_group(groups, [3, 4])
    call add_node_group(groups, [6, 7])
    call reverse_cuthill_mckee(7, groups, order)
    call check(suite, "ordering: every grouped node once, unused nodes left out", size(order) == 6 .and. &
               all([(count(order == node) == 1, node=1, 4)]) .and. count(order == 6) == 1 .and. &
               count(order == 7) == 1 .and. count(order == 5) == 0)
  end subroutine test_ordering

  !> Models that can move without straining are rejected with a message, not a crash: no
  !> supports at all (Cholesky), a block held in x only, and an IEBT 1 part without conditions
  !> (banded LU).
  subroutine test_singular_models()
    type(model_t) :: model
    type(static_solution_t) :: solution
    type(error_t), allocatable :: error
    integer :: node

    call build_block([2, 1, 1], [2.0_wp, 1.0_wp, 1.0_wp], 0.0_wp, 0, model)
    call load_node(model, 1, 1, 10.0_wp)
    call solve_static(model, solution, error)
    call check(suite, "singular: a free block is rejected", allocated(error))
    if (allocated(error)) write (*, '(a)') "  "//error%message
    if (allocated(error)) call check(suite, "singular: the message names the cause", &
                                     index(error%message, "singular") > 0 .and. &
                                     index(error%message, "rigid-body") > 0, error%message)

    do node = 1, size(model%node_ids)
      if (model%coordinates(1, node) == 0.0_wp) call support(model, node, [.true., .false., .false.])
    end do
    call solve_static(model, solution, error)
    call check(suite, "singular: a block held in x only is rejected", allocated(error))
    if (allocated(error)) write (*, '(a)') "  "//error%message(1:min(len(error%message), 110))

    call build_block([3, 3, 3], [1.0_wp, 1.0_wp, 1.0_wp], 0.1_wp, 3, model, &
                     boundary_treatment=boundary_full_transformation)
    call load_node(model, 1, 1, 10.0_wp)
    model%motions = [motion_of(node_at([3, 3, 3], 3, 3, 3), 1, 0.0_wp)]
    call solve_static(model, solution, error)
    call check(suite, "singular: a free IEBT 1 part is rejected (LU)", allocated(error))
    if (allocated(error)) write (*, '(a)') "  "//error%message(1:min(len(error%message), 110))
    if (allocated(error)) call check(suite, "singular: the LU message names the cause", &
                                     index(error%message, "singular") > 0, error%message)
  end subroutine test_singular_models

  !> What a static analysis does not take is named: velocity conditions, rigid walls, an IEBT 1
  !> part sharing nodes with an FE part, a load on a node of no element.
  subroutine test_rejected_models()
    type(model_t) :: model
    type(static_solution_t) :: solution
    type(error_t), allocatable :: error
    real(wp), allocatable :: coordinates(:, :)
    integer, allocatable :: node_ids(:)

    call build_block([2, 2, 2], [1.0_wp, 1.0_wp, 1.0_wp], 0.0_wp, 0, model)
    call prescribe_linear_field(model, [2, 2, 2])
    model%motions(1)%kind = motion_velocity
    call solve_static(model, solution, error)
    call check(suite, "rejected: a velocity condition", allocated(error))
    if (allocated(error)) call check(suite, "rejected: the message names VAD", index(error%message, "VAD 0") > 0, &
                                     error%message)

    call build_block([2, 2, 2], [1.0_wp, 1.0_wp, 1.0_wp], 0.0_wp, 0, model)
    call prescribe_linear_field(model, [2, 2, 2])
    deallocate (model%walls)
    allocate (model%walls(1))
    call solve_static(model, solution, error)
    call check(suite, "rejected: a rigid wall", allocated(error))

    call build_block([4, 3, 3], [1.0_wp, 1.0_wp, 1.0_wp], 0.0_wp, 3, model, &
                     boundary_treatment=boundary_full_transformation)
    call prescribe_linear_field(model, [4, 3, 3])
    call solve_static(model, solution, error)
    call check(suite, "rejected: an IEBT 1 part sharing nodes with an FE part", allocated(error))
    if (allocated(error)) call check(suite, "rejected: the message names IEBT", index(error%message, "IEBT") > 0, &
                                     error%message)

    call build_block([2, 2, 2], [1.0_wp, 1.0_wp, 1.0_wp], 0.0_wp, 0, model)
    call prescribe_linear_field(model, [2, 2, 2])
    coordinates = model%coordinates
    node_ids = model%node_ids
    deallocate (model%coordinates, model%node_ids, model%initial_velocity)
    allocate (model%coordinates(3, size(node_ids) + 1), model%initial_velocity(3, size(node_ids) + 1))
    model%coordinates(:, 1:size(node_ids)) = coordinates
    model%coordinates(:, size(node_ids) + 1) = 5.0_wp
    model%initial_velocity = 0.0_wp
    model%node_ids = [node_ids, 999]
    call load_node(model, size(node_ids) + 1, 2, 1.0_wp)
    call solve_static(model, solution, error)
    call check(suite, "rejected: a load on a node of no element", allocated(error))
    if (allocated(error)) call check(suite, "rejected: the message names the node", &
                                     index(error%message, "node 999") > 0, error%message)
  end subroutine test_rejected_models

  !> Cantilever of formulation section 7, property 7, with nu = 0: the Timoshenko-Goodier plane
  !> solution is then an exact 3D solution (u_z = 0, no lateral stress). Length L, depth D, width
  !> b; the exact displacements are prescribed on the support x = 0 and the parabolic shear
  !> traction of total P acts on x = L through segment loads whose corner values are the L2
  !> projection of the parabola on each segment (so the consistent forces are exact). The tip
  !> deflection v(L, 0) = P L^3 / (3 E I) + 4 P D^2 L / (24 E I) must converge under refinement.
  subroutine test_cantilever()
    integer, parameter :: levels(3) = [1, 2, 4]
    character(len=8), parameter :: names(3) = [character(len=8) :: "FE", "EFG", "coupled"]
    real(wp) :: errors(size(levels), 3)
    integer :: variant, level

    do variant = 1, 3
      do level = 1, size(levels)
        errors(level, variant) = cantilever_tip_error(levels(level), variant)
      end do
      write (*, '(a,3es10.2)') "  cantilever "//names(variant)//" tip deflection (computed - exact) / exact, "// &
        "2, 4, 8 cells over the depth:", errors(:, variant)
      call check(suite, "cantilever "//trim(names(variant))//": the tip error decreases under refinement", &
                 abs(errors(2, variant)) < abs(errors(1, variant)) .and. &
                 abs(errors(3, variant)) < abs(errors(2, variant)))
    end do
    call check(suite, "cantilever FE: error below 1% with 8 cells over the depth", abs(errors(3, 1)) < 0.01_wp)
    call check(suite, "cantilever EFG: error below 0.5% with 4 and 8 cells over the depth", &
               all(abs(errors(2:3, 2)) < 0.005_wp))
    call check(suite, "cantilever coupled: error below 1% with 4 and 8 cells over the depth", &
               all(abs(errors(2:3, 3)) < 0.01_wp))
  end subroutine test_cantilever

  !> Signed relative error of the tip deflection of the cantilever with 2 n cells over the depth, 10 n
  !> along the length and 2 across; variant 1 FE (ELFORM 2), 2 EFG (DX 1.5 box, IEBT 3, IDIM 1),
  !> 3 EFG for x < L/2 and FE beyond.
  function cantilever_tip_error(n, variant) result(relative_error)
    integer, intent(in) :: n, variant
    real(wp) :: relative_error
    type(model_t) :: model
    type(static_solution_t) :: solution
    type(error_t), allocatable :: error
    integer :: cells(3), j, k, node, efg_cells, segment
    real(wp) :: exact_tip, tip, y_low, y_high
    type(segment_load_t), allocatable :: segments(:)

    cells = [10*n, 2*n, 2]
    select case (variant)
    case (1)
      efg_cells = 0
    case (2)
      efg_cells = cells(1)
    case default
      efg_cells = cells(1)/2
    end select
    call build_block(cells, [beam_length, beam_depth, beam_width], 0.0_wp, efg_cells, model, element_formulation=2)
    model%materials(1)%youngs_modulus = beam_modulus
    model%materials(1)%poissons_ratio = 0.0_wp
    model%coordinates(2, :) = model%coordinates(2, :) - 0.5_wp*beam_depth
    model%coordinates(3, :) = model%coordinates(3, :) - 0.5_wp*beam_width
    do k = 0, cells(3)
      do j = 0, cells(2)
        node = node_at(cells, 0, j, k)
        call prescribe(model, node, timoshenko_goodier(model%coordinates(:, node)))
      end do
    end do
    allocate (segments(cells(2)*cells(3)))
    segment = 0
    do k = 0, cells(3) - 1
      do j = 0, cells(2) - 1
        segment = segment + 1
        ! outward normal +x: (y, z) counterclockwise seen from +x
        segments(segment)%nodes = [node_at(cells, cells(1), j, k), node_at(cells, cells(1), j + 1, k), &
                                   node_at(cells, cells(1), j + 1, k + 1), node_at(cells, cells(1), j, k + 1)]
        y_low = model%coordinates(2, segments(segment)%nodes(1))
        y_high = model%coordinates(2, segments(segment)%nodes(2))
        segments(segment)%nodal_values = projected_shear(y_low, y_high, [1, 2, 2, 1])
        segments(segment)%along_normal = .false.
        segments(segment)%direction = [0.0_wp, 1.0_wp, 0.0_wp]
        segments(segment)%curve = 1
      end do
    end do
    call move_alloc(segments, model%segment_loads)
    call solve_static(model, solution, error)
    call check(suite, "cantilever: solves", .not. allocated(error), error_message(error, "no error"))
    relative_error = huge(1.0_wp)
    if (allocated(error)) return
    exact_tip = beam_load*beam_length**3/(3.0_wp*beam_modulus*beam_inertia) + &
                4.0_wp*beam_load*beam_depth**2*beam_length/(24.0_wp*beam_modulus*beam_inertia)
    tip = 0.0_wp
    do k = 0, cells(3)
      tip = tip + solution%displacement(2, node_at(cells, cells(1), n, k))/real(cells(3) + 1, wp)
    end do
    relative_error = (tip - exact_tip)/exact_tip
  end function cantilever_tip_error

  !> Timoshenko-Goodier displacements of the cantilever (plane stress, nu = 0) at a point, origin
  !> at the centre of the supported end.
  pure function timoshenko_goodier(position) result(displacement)
    real(wp), intent(in) :: position(3)
    real(wp) :: displacement(3)
    real(wp) :: x, y, factor
    x = position(1)
    y = position(2)
    factor = beam_load/(6.0_wp*beam_modulus*beam_inertia)
    displacement(1) = -factor*y*((6.0_wp*beam_length - 3.0_wp*x)*x + 2.0_wp*(y**2 - beam_depth**2/4.0_wp))
    displacement(2) = factor*(beam_depth**2*x + (3.0_wp*beam_length - x)*x**2)
    displacement(3) = 0.0_wp
  end function timoshenko_goodier

  !> Corner values (by the corners' y side: 1 low, 2 high) of the linear L2 projection on
  !> [y_low, y_high] of the shear traction tau(y) = P / (2 I) (D^2/4 - y^2).
  pure function projected_shear(y_low, y_high, corner_side) result(values)
    real(wp), intent(in) :: y_low, y_high
    integer, intent(in) :: corner_side(4)
    real(wp) :: values(4)
    real(wp) :: h, moments(2), ends(2), points(3), weights(3), y, s
    integer :: q
    h = y_high - y_low
    points = [-sqrt(0.6_wp), 0.0_wp, sqrt(0.6_wp)]
    weights = [5.0_wp, 8.0_wp, 5.0_wp]/9.0_wp
    moments = 0.0_wp
    do q = 1, 3
      s = 0.5_wp*(points(q) + 1.0_wp)
      y = y_low + s*h
      moments = moments + 0.5_wp*h*weights(q)*beam_load/(2.0_wp*beam_inertia)*(beam_depth**2/4.0_wp - y**2)* &
                [1.0_wp - s, s]
    end do
    ! the mass matrix of the two linear functions is h/6 [2 1; 1 2], its inverse 2/h [2 -1; -1 2]
    ends = 2.0_wp/h*[2.0_wp*moments(1) - moments(2), -moments(1) + 2.0_wp*moments(2)]
    values = ends(corner_side)
  end function projected_shear

  !> A complete run into a results file: run_static writes the state and histories, the summary
  !> is filled, and the file closes with a normal status.
  subroutine test_results_written()
    type(model_t) :: model
    type(results_file_t) :: results
    type(run_summary_t) :: summary
    type(error_t), allocatable :: error
    character(len=:), allocatable :: directory
    character(len=1024) :: value
    integer :: length, status, unit

    call get_environment_variable("TMPDIR", value, length, status)
    if (status /= 0 .or. length == 0) value = "/tmp"
    directory = trim(value)//"/crashfree_test_static"
    call make_directory(directory, error)
    call check(suite, "results: temporary directory", .not. allocated(error), error_message(error, "no error"))
    if (allocated(error)) return
    call build_block([3, 2, 2], [1.0_wp, 1.0_wp, 1.0_wp], 0.2_wp, 2, model)
    call prescribe_linear_field(model, [3, 2, 2])
    call open_results(results, directory, "static", model, 1, error)
    call check(suite, "results: file opened", .not. allocated(error), error_message(error, "no error"))
    if (allocated(error)) return
    call run_static(model, results, summary, error)
    call check(suite, "results: run_static succeeds", .not. allocated(error), error_message(error, "no error"))
    summary%status = status_normal
    summary%message = ""
    call close_results(results, summary, error)
    call check(suite, "results: file closed", .not. allocated(error), error_message(error, "no error"))
    call check(suite, "results: summary filled", summary%cycles == 1 .and. summary%end_time == 1.0_wp .and. &
               summary%fe_elements == 4 .and. summary%efg_particles > 0 .and. &
               summary%dofs_total == 3*size(model%node_ids))
    open (newunit=unit, file=directory//"/static.h5", status="old", iostat=status)
    call check(suite, "results: static.h5 exists", status == 0)
    if (status == 0) close (unit, status="delete")
    open (newunit=unit, file=directory//"/static.xdmf", status="old", iostat=status)
    if (status == 0) close (unit, status="delete")
  end subroutine test_results_written

end program test_static
