!> Unit tests of the hexahedral solid elements through the block API (solid_block) and the
!> geometry kernels: volumes and time steps, patch tests (linear velocity fields on distorted
!> elements give the exact D and spin and no hourglass force), objectivity under rigid rotation,
!> free flight (no strain, and the step at rest, in every build),
!> bulk viscosity, hourglass forces and energies, conservation of linear and angular momentum,
!> inverted elements, block building, the elements at a mesh's corners and edges (which get the
!> eigenvalue bound on their step) and element results.
program test_solid_elements
  use kinds, only: wp, block_size
  use model, only: model_t, material_t, formulation_fe, formulation_efg
  use material_laws, only: law_elastic, law_plastic_kinematic
  use material_dispatch, only: elastic_moduli
  use objective_rotation, only: incremental_rotation
  use hex8_geometry, only: hex8_volume_derivatives, hex8_velocity_gradient, hex8_gauss_natural_derivatives, &
                           largest_eigenvalue_bounds, hex8_gradient_invariants, hex8_largest_face_area
  use element_time_step, only: solid_element_time_steps
  use hex8_one_point, only: hourglass_base
  use solid_block, only: solid_block_t, build_solid_blocks, solid_block_corner_masses, solid_block_time_steps, &
                         compute_solid_block, solid_block_element_results
  use testing, only: test_suite_t, check, check_close, finish_suite
  use fixtures, only: random_uniform, cross
  use element_work, only: lane_energy_sums, booked_energy
  implicit none

  type(test_suite_t) :: suite
  integer :: random_state = 12345
  real(wp), parameter :: youngs = 210000.0_wp, poisson = 0.3_wp, density = 7.85e-9_wp
  real(wp), parameter :: unit_cube(3, 8) = reshape([0.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, &
                                                    1.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, &
                                                    0.0_wp, 0.0_wp, 1.0_wp, 1.0_wp, 0.0_wp, 1.0_wp, &
                                                    1.0_wp, 1.0_wp, 1.0_wp, 0.0_wp, 1.0_wp, 1.0_wp], [3, 8])

  suite%name = "solid_elements"
  call test_unit_cube()
  call test_largest_eigenvalue_bounds()
  call test_gradient_invariants()
  call test_distorted_volumes()
  call test_incremental_rotation()
  call test_patch_single_elements()
  call test_patch_irregular_block()
  call test_rigid_rotation()
  call test_free_flight()
  call test_selective_reduced_pressure()
  call test_bulk_viscosity()
  call test_hourglass_forces()
  call test_conservation()
  call test_energy_balance()
  call test_block_energy_sums()
  call test_inverted_elements()
  call test_build_blocks()
  call test_exposed_elements()
  call test_element_results()
  call finish_suite(suite)

contains

  ! ----------------------------------------------------------------------------------------
  ! helpers

  function elastic_steel() result(material)
    type(material_t) :: material
    material%law = law_elastic
    material%density = density
    material%youngs_modulus = youngs
    material%poissons_ratio = poisson
  end function elastic_steel

  function plastic_steel() result(material)
    type(material_t) :: material
    material = elastic_steel()
    material%law = law_plastic_kinematic
    material%yield_stress = 250.0_wp
    material%tangent_modulus = 2100.0_wp
    material%hardening_beta = 0.5_wp
  end function plastic_steel

  !> LS-DYNA's step L / c, L = V / largest face area, of one element at rest (elastic steel).
  function lsdyna_step(coordinates) result(step)
    real(wp), intent(in) :: coordinates(3, 8)
    real(wp) :: step
    real(wp) :: x(block_size, 8), y(block_size, 8), z(block_size, 8), steps(block_size)
    real(wp) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8), volume(block_size), area(block_size)
    real(wp) :: modulus(block_size), density_lanes(block_size), rates(block_size)
    x = 0.0_wp
    y = 0.0_wp
    z = 0.0_wp
    x(1, :) = coordinates(1, :)
    y(1, :) = coordinates(2, :)
    z(1, :) = coordinates(3, :)
    call hex8_volume_derivatives(1, x, y, z, bx, by, bz, volume)
    call hex8_largest_face_area(1, x, y, z, area)
    modulus = density*wave_speed(elastic_steel())**2
    density_lanes = density
    rates = 0.0_wp
    call solid_element_time_steps(1, 1.5_wp, 0.06_wp, volume, area, modulus, density_lanes, rates, steps)
    step = steps(1)
  end function lsdyna_step

  pure real(wp) function lame_lambda()
    lame_lambda = youngs*poisson/((1.0_wp + poisson)*(1.0_wp - 2.0_wp*poisson))
  end function lame_lambda

  pure real(wp) function lame_mu()
    lame_mu = youngs/(2.0_wp*(1.0_wp + poisson))
  end function lame_mu

  function wave_speed(material) result(speed)
    type(material_t), intent(in) :: material
    real(wp) :: speed, bulk, shear
    call elastic_moduli(material, bulk, shear)
    speed = sqrt((bulk + 4.0_wp*shear/3.0_wp)/material%density)
  end function wave_speed

  !> A model of one part with the given nodes and hexahedra.
  subroutine make_model(model, coordinates, connectivity, material, formulation, hourglass_type)
    type(model_t), intent(out) :: model
    real(wp), intent(in) :: coordinates(:, :)
    integer, intent(in) :: connectivity(:, :)
    type(material_t), intent(in) :: material
    integer, intent(in) :: formulation, hourglass_type
    integer :: solid
    model%coordinates = coordinates
    allocate (model%initial_velocity(3, size(coordinates, 2)), source=0.0_wp)
    model%solid_nodes = connectivity
    model%solid_ids = [(solid, solid=1, size(connectivity, 2))]
    allocate (model%solid_part(size(connectivity, 2)), source=1)
    allocate (model%parts(1), model%sections(1), model%materials(1))
    model%materials(1) = material
    model%sections(1)%element_formulation = formulation
    model%parts(1)%section = 1
    model%parts(1)%material = 1
    model%parts(1)%hourglass_type = hourglass_type
    model%parts(1)%hourglass_coefficient = 0.1_wp
  end subroutine make_model

  !> The eight corners of element `lane` of a block, coordinates(3, nodes) -> (block_size, 8).
  subroutine corners(block, coordinates, x, y, z)
    type(solid_block_t), intent(in) :: block
    real(wp), intent(in) :: coordinates(:, :)
    real(wp), intent(out) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    integer :: lane, node
    x = 0.0_wp
    y = 0.0_wp
    z = 0.0_wp
    do node = 1, 8
      do lane = 1, block%element_count
        x(lane, node) = coordinates(1, block%nodes(lane, node))
        y(lane, node) = coordinates(2, block%nodes(lane, node))
        z(lane, node) = coordinates(3, block%nodes(lane, node))
      end do
    end do
  end subroutine corners

  !> Corner forces of a uniform stress minus bulk viscosity, (sigma - q I) b, at the given
  !> configuration (the stress-divergence part the element must produce).
  subroutine uniform_stress_forces(block, coordinates, stress, bulk_viscosity, force)
    type(solid_block_t), intent(in) :: block
    real(wp), intent(in) :: coordinates(:, :), stress(block_size, 6), bulk_viscosity(block_size)
    real(wp), intent(out) :: force(block_size, 8, 3)
    real(wp) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8), volume(block_size)
    real(wp) :: sigma(3, 3), row(6)
    integer :: lane, node
    call corners(block, coordinates, x, y, z)
    call hex8_volume_derivatives(block_size, x, y, z, bx, by, bz, volume)
    force = 0.0_wp
    do lane = 1, block%element_count
      row = stress(lane, :)
      sigma = to_matrix(row)
      do node = 1, 3
        sigma(node, node) = sigma(node, node) - bulk_viscosity(lane)
      end do
      do node = 1, 8
        force(lane, node, :) = matmul(sigma, [bx(lane, node), by(lane, node), bz(lane, node)])
      end do
    end do
  end subroutine uniform_stress_forces

  pure function to_matrix(vector) result(matrix)
    real(wp), intent(in) :: vector(6)
    real(wp) :: matrix(3, 3)
    matrix = reshape([vector(1), vector(4), vector(6), vector(4), vector(2), vector(5), &
                      vector(6), vector(5), vector(3)], [3, 3])
  end function to_matrix

  pure function to_vector(matrix) result(vector)
    real(wp), intent(in) :: matrix(3, 3)
    real(wp) :: vector(6)
    vector = [matrix(1, 1), matrix(2, 2), matrix(3, 3), matrix(1, 2), matrix(2, 3), matrix(3, 1)]
  end function to_vector

  pure function inverse3(a) result(b)
    real(wp), intent(in) :: a(3, 3)
    real(wp) :: b(3, 3), determinant
    b(1, 1) = a(2, 2)*a(3, 3) - a(2, 3)*a(3, 2)
    b(1, 2) = a(1, 3)*a(3, 2) - a(1, 2)*a(3, 3)
    b(1, 3) = a(1, 2)*a(2, 3) - a(1, 3)*a(2, 2)
    b(2, 1) = a(2, 3)*a(3, 1) - a(2, 1)*a(3, 3)
    b(2, 2) = a(1, 1)*a(3, 3) - a(1, 3)*a(3, 1)
    b(2, 3) = a(1, 3)*a(2, 1) - a(1, 1)*a(2, 3)
    b(3, 1) = a(2, 1)*a(3, 2) - a(2, 2)*a(3, 1)
    b(3, 2) = a(1, 2)*a(3, 1) - a(1, 1)*a(3, 2)
    b(3, 3) = a(1, 1)*a(2, 2) - a(1, 2)*a(2, 1)
    determinant = a(1, 1)*b(1, 1) + a(1, 2)*b(2, 1) + a(1, 3)*b(3, 1)
    b = b/determinant
  end function inverse3

  pure function determinant3(a) result(value)
    real(wp), intent(in) :: a(3, 3)
    real(wp) :: value
    value = a(1, 1)*(a(2, 2)*a(3, 3) - a(2, 3)*a(3, 2)) - a(1, 2)*(a(2, 1)*a(3, 3) - a(2, 3)*a(3, 1)) &
            + a(1, 3)*(a(2, 1)*a(3, 2) - a(2, 2)*a(3, 1))
  end function determinant3

  pure function identity3() result(a)
    real(wp) :: a(3, 3)
    integer :: k
    a = 0.0_wp
    do k = 1, 3
      a(k, k) = 1.0_wp
    end do
  end function identity3

  !> Rotation about unit axis n by angle theta (Rodrigues).
  pure function axis_rotation(n, theta) result(r)
    real(wp), intent(in) :: n(3), theta
    real(wp) :: r(3, 3), k(3, 3)
    k = reshape([0.0_wp, n(3), -n(2), -n(3), 0.0_wp, n(1), n(2), -n(1), 0.0_wp], [3, 3])
    r = identity3() + sin(theta)*k + (1.0_wp - cos(theta))*matmul(k, k)
  end function axis_rotation

  !> Expected one-step stress of the hypoelastic law for a uniform velocity gradient L:
  !> rotate by the Cayley transform of W dt (computed here with a general inverse), then add
  !> lambda tr(de) I + 2 mu de.
  function expected_elastic_stress(material, stress, gradient, dt) result(updated)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: stress(6), gradient(3, 3), dt
    real(wp) :: updated(6)
    real(wp) :: spin(3, 3), strain(3, 3), rotation(3, 3), sigma(3, 3), bulk, shear
    spin = 0.5_wp*(gradient - transpose(gradient))*dt
    strain = 0.5_wp*(gradient + transpose(gradient))*dt
    rotation = matmul(inverse3(identity3() - 0.5_wp*spin), identity3() + 0.5_wp*spin)
    sigma = matmul(rotation, matmul(to_matrix(stress), transpose(rotation)))
    call elastic_moduli(material, bulk, shear)
    sigma = sigma + (bulk - 2.0_wp*shear/3.0_wp)*(strain(1, 1) + strain(2, 2) + strain(3, 3))*identity3() &
            + 2.0_wp*shear*strain
    updated = to_vector(sigma)
  end function expected_elastic_stress

  function random_symmetric(scale) result(vector)
    real(wp), intent(in) :: scale
    real(wp) :: vector(6)
    integer :: k
    do k = 1, 6
      vector(k) = scale*random_uniform(random_state)
    end do
  end function random_symmetric

  function random_matrix(scale) result(a)
    real(wp), intent(in) :: scale
    real(wp) :: a(3, 3)
    integer :: i, j
    do j = 1, 3
      do i = 1, 3
        a(i, j) = scale*random_uniform(random_state)
      end do
    end do
  end function random_matrix

  !> A unit cube with every node moved randomly by up to `amount` in each direction.
  function distorted_cube(amount) result(coordinates)
    real(wp), intent(in) :: amount
    real(wp) :: coordinates(3, 8)
    integer :: node, k
    coordinates = unit_cube
    do node = 1, 8
      do k = 1, 3
        coordinates(k, node) = coordinates(k, node) + amount*random_uniform(random_state)
      end do
    end do
  end function distorted_cube

  !> Volume by the 2x2x2 Gauss rule written out here (independent of the kernels).
  function gauss_volume(coordinates) result(volume)
    real(wp), intent(in) :: coordinates(3, 8)
    real(wp) :: volume, natural(8, 3, 8), jacobian(3, 3)
    integer :: point
    call hex8_gauss_natural_derivatives(natural)
    volume = 0.0_wp
    do point = 1, 8
      jacobian = matmul(coordinates, natural(:, :, point))
      volume = volume + determinant3(jacobian)
    end do
  end function gauss_volume

  ! ----------------------------------------------------------------------------------------
  ! tests

  subroutine test_unit_cube()
    type(model_t) :: model
    type(solid_block_t), allocatable :: blocks(:)
    real(wp) :: corner_mass(block_size, 8), time_step(block_size)
    call make_model(model, unit_cube, reshape([1, 2, 3, 4, 5, 6, 7, 8], [8, 1]), elastic_steel(), 1, 1)
    call build_solid_blocks(model, blocks)
    call check(suite, "unit cube: one block of one element", size(blocks) == 1 .and. blocks(1)%element_count == 1)
    call check_close(suite, "unit cube: reference volume", blocks(1)%reference_volume(1), 1.0_wp, rel=1e-15_wp)
    call solid_block_corner_masses(blocks(1), corner_mass)
    call check_close(suite, "unit cube: corner mass rho V / 8", corner_mass(1, :), spread(density/8.0_wp, 1, 8), &
                     rel=1e-15_wp)
    call check(suite, "unit cube: unused lanes have no mass", all(corner_mass(2:, :) == 0.0_wp))
    call solid_block_time_steps(blocks(1), model%materials(1), model%coordinates, time_step)
    ! the volumetric mode (omega^2 = 4 (3 lambda + 2 mu) / (rho L^2)) sets it, below L / c = 1 / c
    call check_close(suite, "unit cube: time step 2 / omega of the volumetric mode", time_step(1), &
                     sqrt(density/(3.0_wp*lame_lambda() + 2.0_wp*lame_mu())), rel=1e-6_wp)
    call check(suite, "unit cube: below LS-DYNA's L / c", time_step(1) < 0.74_wp/wave_speed(elastic_steel()))
    call check(suite, "unit cube: unused lanes get a huge step", all(time_step(2:) == huge(1.0_wp)))
  end subroutine test_unit_cube

  !> Upper bounds within 0.5% on the largest eigenvalue of symmetric 3 x 3 matrices with known
  !> eigenvalues, turned by a fixed rotation: distinct, two largest equal, all equal, rank one.
  subroutine test_largest_eigenvalue_bounds()
    real(wp), parameter :: eigenvalues(3, 5) = reshape([3.0_wp, 2.0_wp, 1.0_wp, 2.0_wp, 2.0_wp, 0.5_wp, &
                                                        1.0_wp, 1.0_wp, 1.0_wp, 5.0_wp, 0.0_wp, 0.0_wp, &
                                                        1.0e-6_wp, 1.0e-6_wp, 1.0e-6_wp*(1.0_wp - 1.0e-4_wp)], [3, 5])
    real(wp) :: rotation(3, 3), matrix(3, 3), packed(block_size, 6), bound(block_size)
    integer :: k
    rotation = reshape([0.36_wp, 0.48_wp, -0.8_wp, -0.8_wp, 0.6_wp, 0.0_wp, 0.48_wp, 0.64_wp, 0.6_wp], [3, 3])
    packed = 0.0_wp
    do k = 1, 5
      matrix = matmul(rotation, matmul(diagonal(eigenvalues(:, k)), transpose(rotation)))
      packed(k, :) = [matrix(1, 1), matrix(2, 2), matrix(3, 3), matrix(1, 2), matrix(2, 3), matrix(1, 3)]
    end do
    call largest_eigenvalue_bounds(5, packed, bound)
    do k = 1, 5
      call check(suite, "largest eigenvalue bound: at or above it", bound(k) >= maxval(eigenvalues(:, k)))
      call check(suite, "largest eigenvalue bound: within 0.5%", bound(k) <= 1.005_wp*maxval(eigenvalues(:, k)))
    end do
  end subroutine test_largest_eigenvalue_bounds

  pure function diagonal(values) result(matrix)
    real(wp), intent(in) :: values(3)
    real(wp) :: matrix(3, 3)
    integer :: i
    matrix = 0.0_wp
    do i = 1, 3
      matrix(i, i) = values(i)
    end do
  end function diagonal

  !> The geometry behind the element eigenvalue bound: a brick 1 x 2 x 4 has tr G = sum
  !> 1 / (2 a^2), lambda_max(G) = 1/2 and no overlap between its strain and hourglass modes; a
  !> distorted element has some.
  subroutine test_gradient_invariants()
    real(wp) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8), volume(block_size)
    real(wp) :: g(block_size, 6), trace_g(block_size), largest_g(block_size), overlap(block_size)
    integer :: node
    x = 0.0_wp
    y = 0.0_wp
    z = 0.0_wp
    do node = 1, 8
      x(1:2, node) = unit_cube(1, node)
      y(1:2, node) = 2.0_wp*unit_cube(2, node)
      z(1:2, node) = 4.0_wp*unit_cube(3, node)
    end do
    x(2, 7) = 1.3_wp
    y(2, 7) = 2.2_wp
    call hex8_volume_derivatives(2, x, y, z, bx, by, bz, volume)
    call hex8_gradient_invariants(2, x, y, z, bx, by, bz, volume, g, trace_g, largest_g, overlap, .true.)
    call check_close(suite, "gradient invariants: brick tr G", trace_g(1), 0.5_wp*(1.0_wp + 0.25_wp + 0.0625_wp), &
                     rel=1e-12_wp)
    call check_close(suite, "gradient invariants: brick lambda_max(G)", largest_g(1), 0.5_wp, rel=5e-3_wp)
    call check(suite, "gradient invariants: brick lambda_max(G) bound", largest_g(1) >= 0.5_wp)
    call check(suite, "gradient invariants: brick has no overlap", abs(overlap(1)) < 1e-12_wp)
    call check(suite, "gradient invariants: distorted element overlaps", overlap(2) > 1e-4_wp .and. overlap(2) < 1.0_wp)
  end subroutine test_gradient_invariants

  subroutine test_distorted_volumes()
    type(model_t) :: model
    type(solid_block_t), allocatable :: blocks(:)
    real(wp) :: time_step(block_size), prism(3, 8), mapped(3, 8), map(3, 3), general(3, 8)
    real(wp) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8), volume(block_size)
    real(wp) :: moments(3, 3)
    integer :: node, trial
    ! A right prism with a trapezoidal section: x from 0..2 at z = 0 to 0..1 at z = 1, depth 1.
    ! Volume 1.5, largest face the bottom (area 2): L = 0.75.
    prism = reshape([0.0_wp, 0.0_wp, 0.0_wp, 2.0_wp, 0.0_wp, 0.0_wp, 2.0_wp, 1.0_wp, 0.0_wp, &
                     0.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 1.0_wp, 0.0_wp, 1.0_wp, &
                     1.0_wp, 1.0_wp, 1.0_wp, 0.0_wp, 1.0_wp, 1.0_wp], [3, 8])
    call make_model(model, prism, reshape([1, 2, 3, 4, 5, 6, 7, 8], [8, 1]), elastic_steel(), 1, 1)
    call build_solid_blocks(model, blocks)
    call check_close(suite, "trapezoidal prism: volume 3/2", blocks(1)%reference_volume(1), 1.5_wp, rel=1e-15_wp)
    call check_close(suite, "trapezoidal prism: LS-DYNA's step 0.75/c", lsdyna_step(prism), &
                     0.75_wp/wave_speed(elastic_steel()), rel=1e-14_wp)
    ! the element's eigenvalue bound sets the step below it (nu = 0.3)
    call solid_block_time_steps(blocks(1), model%materials(1), model%coordinates, time_step)
    call check(suite, "trapezoidal prism: step below LS-DYNA's", time_step(1) < 0.75_wp/wave_speed(elastic_steel()) &
               .and. time_step(1) > 0.6_wp*0.75_wp/wave_speed(elastic_steel()))

    ! An affine image of the unit cube: volume det(A), largest face area |A e_i x A e_j| max.
    map = reshape([1.3_wp, 0.2_wp, -0.1_wp, 0.4_wp, 0.9_wp, 0.3_wp, -0.2_wp, 0.1_wp, 1.1_wp], [3, 3])
    mapped = matmul(map, unit_cube) + spread([5.0_wp, -2.0_wp, 1.0_wp], 2, 8)
    call make_model(model, mapped, reshape([1, 2, 3, 4, 5, 6, 7, 8], [8, 1]), elastic_steel(), 1, 1)
    call build_solid_blocks(model, blocks)
    call check_close(suite, "affine hexahedron: volume det(A)", blocks(1)%reference_volume(1), determinant3(map), &
                     rel=1e-14_wp)
    call check_close(suite, "affine hexahedron: LS-DYNA's step V/(A_max c)", lsdyna_step(mapped), determinant3(map) &
                     /max(norm2(cross(map(:, 1), map(:, 2))), norm2(cross(map(:, 2), map(:, 3))), &
                          norm2(cross(map(:, 3), map(:, 1))))/wave_speed(elastic_steel()), rel=1e-14_wp)
    call solid_block_time_steps(blocks(1), model%materials(1), model%coordinates, time_step)
    call check(suite, "affine hexahedron: step at most LS-DYNA's", time_step(1) <= lsdyna_step(mapped))

    ! General distorted hexahedra: exact volume against an independent Gauss rule, and the
    ! identities sum_I b_I = 0, sum_I x_I (x) b_I = V I of the exact volume derivatives.
    do trial = 1, 5
      general = distorted_cube(0.25_wp)
      x = 0.0_wp
      y = 0.0_wp
      z = 0.0_wp
      x(1, :) = general(1, :)
      y(1, :) = general(2, :)
      z(1, :) = general(3, :)
      call hex8_volume_derivatives(1, x, y, z, bx, by, bz, volume)
      call check_close(suite, "distorted hexahedron: volume equals the 2x2x2 Gauss volume", volume(1), &
                       gauss_volume(general), rel=1e-14_wp)
      call check_close(suite, "distorted hexahedron: sum of b is zero", [sum(bx(1, :)), sum(by(1, :)), &
                       sum(bz(1, :))], [0.0_wp, 0.0_wp, 0.0_wp], thr=1e-14_wp)
      do node = 1, 3
        moments(node, :) = [sum(general(node, :)*bx(1, :)), sum(general(node, :)*by(1, :)), &
                            sum(general(node, :)*bz(1, :))]
      end do
      call check_close(suite, "distorted hexahedron: sum x_I b_I = V I", reshape(moments, [9]), &
                       reshape(volume(1)*identity3(), [9]), thr=1e-14_wp)
    end do
  end subroutine test_distorted_volumes

  subroutine test_incremental_rotation()
    real(wp) :: spin(block_size, 3), rotation(block_size, 9), r(3, 3), omega(3, 3), expected(3, 3)
    integer :: lane
    do lane = 1, block_size
      spin(lane, :) = 0.7_wp*[random_uniform(random_state), random_uniform(random_state), random_uniform(random_state)]
    end do
    call incremental_rotation(block_size, spin, rotation)
    do lane = 1, 4
      r = transpose(reshape(rotation(lane, :), [3, 3]))
      call check_close(suite, "incremental rotation is orthogonal", reshape(matmul(r, transpose(r)), [9]), &
                       reshape(identity3(), [9]), thr=1e-15_wp)
      call check_close(suite, "incremental rotation has det +1", determinant3(r), 1.0_wp, rel=1e-15_wp)
      omega = reshape([0.0_wp, spin(lane, 3), -spin(lane, 2), -spin(lane, 3), 0.0_wp, spin(lane, 1), &
                       spin(lane, 2), -spin(lane, 1), 0.0_wp], [3, 3])
      expected = matmul(inverse3(identity3() - 0.5_wp*omega), identity3() + 0.5_wp*omega)
      call check_close(suite, "incremental rotation is the Cayley transform of W dt", reshape(r, [9]), &
                       reshape(expected, [9]), thr=1e-15_wp)
    end do
  end subroutine test_incremental_rotation

  !> Linear velocity field v = A x + c on the mid-step configuration of a distorted element:
  !> the mean velocity gradient is A, the stress update is exactly the rotated prestress plus
  !> the elastic response to sym(A) dt, and the corner forces are exactly those of the uniform
  !> stress (no hourglass force) for IHQ 2-5 and ELFORM 2.
  subroutine patch_check(label, coordinates_mid, connectivity, gradient, formulation, hourglass_type, steps)
    character(len=*), intent(in) :: label
    real(wp), intent(in) :: coordinates_mid(:, :)
    integer, intent(in) :: connectivity(:, :)
    real(wp), intent(in) :: gradient(3, 3)
    integer, intent(in) :: formulation, hourglass_type, steps
    type(model_t) :: model
    type(solid_block_t), allocatable :: blocks(:)
    real(wp), allocatable :: velocities(:, :), coordinates(:, :), middle(:, :)
    real(wp) :: force(block_size, 8, 3), stress_force(block_size, 8, 3), prestress(6), expected(6)
    real(wp) :: x(block_size, 8), y(block_size, 8), z(block_size, 8), vx(block_size, 8), vy(block_size, 8)
    real(wp) :: vz(block_size, 8), computed(block_size, 9), volume(block_size), translation(3)
    real(wp) :: critical, scale, hourglass_excess, stress_excess, gradient_excess
    integer :: critical_element, inverted, node, lane, point, step
    real(wp), parameter :: dt = 1.0e-3_wp

    call make_model(model, coordinates_mid, connectivity, elastic_steel(), formulation, hourglass_type)
    call build_solid_blocks(model, blocks)
    prestress = random_symmetric(100.0_wp)
    do point = 1, blocks(1)%point_count
      do lane = 1, blocks(1)%element_count
        blocks(1)%stress(lane, :, point) = prestress
      end do
    end do
    translation = [0.3_wp, -0.2_wp, 0.1_wp]
    middle = coordinates_mid
    allocate (velocities, mold=middle)
    hourglass_excess = 0.0_wp
    stress_excess = 0.0_wp
    gradient_excess = 0.0_wp
    do step = 1, steps
      do node = 1, size(middle, 2)
        velocities(:, node) = matmul(gradient, middle(:, node)) + translation
      end do
      coordinates = middle + 0.5_wp*dt*velocities

      ! the kernel's mean velocity gradient on the mid-step configuration
      call corners(blocks(1), middle, x, y, z)
      call corners(blocks(1), velocities, vx, vy, vz)
      call hex8_velocity_gradient(block_size, 0.0_wp, x, y, z, vx, vy, vz, computed, volume)
      do lane = 1, blocks(1)%element_count
        gradient_excess = max(gradient_excess, maxval(abs(computed(lane, :) - reshape(transpose(gradient), [9]))) &
                              /maxval(abs(gradient)))
      end do

      call compute_solid_block(blocks(1), model%materials(1), coordinates, velocities, dt, force, critical, &
                               critical_element, inverted)
      expected = expected_elastic_stress(model%materials(1), prestress, gradient, dt)
      do point = 1, blocks(1)%point_count
        do lane = 1, blocks(1)%element_count
          stress_excess = max(stress_excess, maxval(abs(blocks(1)%stress(lane, :, point) - expected)) &
                              /maxval(abs(expected)))
        end do
      end do
      prestress = expected
      call uniform_stress_forces(blocks(1), coordinates, blocks(1)%stress(:, :, 1), blocks(1)%bulk_viscosity, &
                                 stress_force)
      scale = maxval(abs(stress_force))
      hourglass_excess = max(hourglass_excess, maxval(abs(force - stress_force))/scale)
      middle = coordinates + 0.5_wp*dt*velocities
    end do
    call check(suite, label//": no inverted element", inverted == 0)
    call check_close(suite, label//": mean velocity gradient equals A", gradient_excess, 0.0_wp, thr=1e-12_wp)
    call check_close(suite, label//": stress = R sigma R^T + C:(sym(A) dt) at every point", stress_excess, &
                     0.0_wp, thr=1e-12_wp)
    if (formulation == 1 .and. hourglass_type == 1) then
      call check(suite, label//": IHQ 1 is not orthogonal to linear fields (test has teeth)", &
                 hourglass_excess > 1e-6_wp)
    else
      call check_close(suite, label//": no hourglass force (relative to the stress forces)", hourglass_excess, &
                       0.0_wp, thr=1e-12_wp)
      call check_close(suite, label//": no hourglass energy", maxval(abs(blocks(1)%hourglass_energy)), 0.0_wp, &
                       thr=1e-12_wp*maxval(abs(blocks(1)%internal_energy)))
    end if
  end subroutine patch_check

  subroutine test_patch_single_elements()
    real(wp) :: coordinates(3, 8), gradient(3, 3)
    integer :: trial, hourglass_type
    character(len=64) :: label
    do trial = 1, 4
      coordinates = distorted_cube(0.25_wp)
      gradient = random_matrix(1.0_wp)
      do hourglass_type = 1, 5
        write (label, '(a,i0,a,i0)') "patch single element ", trial, ", ELFORM 1 IHQ ", hourglass_type
        call patch_check(trim(label), coordinates, reshape([1, 2, 3, 4, 5, 6, 7, 8], [8, 1]), gradient, 1, &
                         hourglass_type, 3)
      end do
      write (label, '(a,i0,a)') "patch single element ", trial, ", ELFORM 2"
      call patch_check(trim(label), coordinates, reshape([1, 2, 3, 4, 5, 6, 7, 8], [8, 1]), gradient, 2, 1, 3)
    end do
  end subroutine test_patch_single_elements

  !> 2 x 2 x 2 elements on [0, 2]^3 with every node moved randomly (the mesh of the classic 3D
  !> patch test is irregular in the same way).
  subroutine irregular_mesh(coordinates, connectivity)
    real(wp), intent(out) :: coordinates(3, 27)
    integer, intent(out) :: connectivity(8, 8)
    integer :: i, j, k, node, element
    do k = 0, 2
      do j = 0, 2
        do i = 0, 2
          node = 1 + i + 3*j + 9*k
          coordinates(:, node) = real([i, j, k], wp) + 0.2_wp*[random_uniform(random_state), &
                                 random_uniform(random_state), random_uniform(random_state)]
        end do
      end do
    end do
    element = 0
    do k = 0, 1
      do j = 0, 1
        do i = 0, 1
          element = element + 1
          node = 1 + i + 3*j + 9*k
          connectivity(:, element) = [node, node + 1, node + 4, node + 3, node + 9, node + 10, node + 13, node + 12]
        end do
      end do
    end do
  end subroutine irregular_mesh

  subroutine test_patch_irregular_block()
    real(wp) :: coordinates(3, 27), gradient(3, 3)
    integer :: connectivity(8, 8), hourglass_type
    character(len=64) :: label
    call irregular_mesh(coordinates, connectivity)
    gradient = random_matrix(1.0_wp)
    do hourglass_type = 2, 5
      write (label, '(a,i0)') "patch irregular block, ELFORM 1 IHQ ", hourglass_type
      call patch_check(trim(label), coordinates, connectivity, gradient, 1, hourglass_type, 4)
    end do
    call patch_check("patch irregular block, ELFORM 2", coordinates, connectivity, gradient, 2, 1, 4)
  end subroutine test_patch_irregular_block

  !> A prestressed element turned rigidly by a quarter turn in 40 steps, with the central
  !> difference velocities v(n+1/2) = (x(n+1) - x(n)) / dt: the stress must be exactly the
  !> rotated prestress, its invariants unchanged, and no energy created.
  subroutine test_rigid_rotation()
    type(model_t) :: model
    type(solid_block_t), allocatable :: blocks(:)
    real(wp) :: reference(3, 8), previous(3, 8), current(3, 8), velocities(3, 8), axis(3), centre(3)
    real(wp) :: force(block_size, 8, 3), prestress(6), sigma(3, 3), rotated(3, 3), critical
    real(wp) :: invariants_before(3), invariants_after(3), row(6), scale
    integer :: step, node, critical_element, inverted, formulation, point
    integer, parameter :: steps = 40
    real(wp), parameter :: dt = 1.0e-6_wp, quarter = 2.0_wp*atan(1.0_wp)
    character(len=32) :: label

    reference = distorted_cube(0.2_wp)
    axis = [1.0_wp, 2.0_wp, 2.0_wp]/3.0_wp
    centre = [0.4_wp, 0.5_wp, 0.6_wp]
    prestress = [120.0_wp, -40.0_wp, 75.0_wp, 30.0_wp, -15.0_wp, 50.0_wp]
    invariants_before = invariants(to_matrix(prestress))
    do formulation = 1, 2
      label = merge("rigid rotation, ELFORM 1", "rigid rotation, ELFORM 2", formulation == 1)
      call make_model(model, reference, reshape([1, 2, 3, 4, 5, 6, 7, 8], [8, 1]), elastic_steel(), formulation, 5)
      call build_solid_blocks(model, blocks)
      do point = 1, blocks(1)%point_count
        blocks(1)%stress(1, :, point) = prestress
      end do
      ! the solver's start: a call with no step taken (the body already turning)
      do node = 1, 8
        current(:, node) = centre + matmul(axis_rotation(axis, quarter/steps), reference(:, node) - centre)
      end do
      velocities = (current - reference)/dt
      call compute_solid_block(blocks(1), model%materials(1), reference, velocities, 0.0_wp, force, critical, &
                               critical_element, inverted)
      previous = reference
      do step = 1, steps
        do node = 1, 8
          current(:, node) = centre + matmul(axis_rotation(axis, quarter*step/steps), reference(:, node) - centre)
        end do
        velocities = (current - previous)/dt
        call compute_solid_block(blocks(1), model%materials(1), current, velocities, dt, force, critical, &
                                 critical_element, inverted)
        previous = current
      end do
      rotated = matmul(axis_rotation(axis, quarter), matmul(to_matrix(prestress), transpose(axis_rotation(axis, quarter))))
      do point = 1, blocks(1)%point_count
        row = blocks(1)%stress(1, :, point)
        sigma = to_matrix(row)
        invariants_after = invariants(sigma)
        ! invariant k is homogeneous of degree k in the stress: compare at that scale
        scale = maxval(abs(prestress))
        call check_close(suite, trim(label)//": first invariant unchanged", invariants_after(1), &
                         invariants_before(1), thr=1e-12_wp*scale)
        call check_close(suite, trim(label)//": second invariant unchanged", invariants_after(2), &
                         invariants_before(2), thr=1e-12_wp*scale**2)
        call check_close(suite, trim(label)//": third invariant unchanged", invariants_after(3), &
                         invariants_before(3), thr=1e-12_wp*scale**3)
        call check_close(suite, trim(label)//": stress is the rotated prestress", blocks(1)%stress(1, :, point), &
                         to_vector(rotated), thr=1e-12_wp*maxval(abs(prestress)))
      end do
      call check_close(suite, trim(label)//": no internal energy created", blocks(1)%internal_energy(1), 0.0_wp, &
                       thr=1e-12_wp*maxval(abs(prestress))*blocks(1)%reference_volume(1))
      call check_close(suite, trim(label)//": no hourglass energy created", blocks(1)%hourglass_energy(1), 0.0_wp, &
                       thr=1e-12_wp*maxval(abs(prestress))*blocks(1)%reference_volume(1))
      call check_close(suite, trim(label)//": volume kept", blocks(1)%volume(1), blocks(1)%reference_volume(1), &
                       rel=1e-13_wp)
    end do
  end subroutine test_rigid_rotation

  !> Distorted hexahedra far from the origin in free flight (every node at the same velocity):
  !> the velocity gradient is exactly zero, so no stress arises, and the stable step is the step
  !> at rest. With the absolute velocities in the gradient sums, tr D was the round-off
  !> v . sum_I b_I / V, of either sign and different with and without FMA contraction; when
  !> negative it switched on the linear bulk viscosity's term of the step (6% at Q2 = 0.06), and
  !> the release and the debug build of the contact model of test_threads took different steps
  !> before the impact (docs/solver.md, "Why two builds differ").
  subroutine test_free_flight()
    integer, parameter :: elements = 32, steps = 12
    real(wp), parameter :: dt = 1.0e-7_wp
    ! mm/s: the plate's and the block's 20 m/s of test_threads' contact model, and sideways
    real(wp), parameter :: flight(3) = [5300.0_wp, -1700.0_wp, -20100.0_wp]
    integer, parameter :: variants = 3
    integer, parameter :: formulations(variants) = [1, 1, 2], hourglass_types(variants) = [1, 5, 1]
    type(model_t) :: model
    type(solid_block_t), allocatable :: blocks(:)
    real(wp) :: reference(3, 8*elements), current(3, 8*elements), velocities(3, 8*elements)
    real(wp) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp) :: vx(block_size, 8), vy(block_size, 8), vz(block_size, 8)
    real(wp) :: gradient(block_size, 9), volume(block_size), at_rest(block_size), recent(3)
    real(wp) :: force(block_size, 8, 3), critical, deviation
    integer :: connectivity(8, elements), element, node, step, variant, critical_element, inverted
    character(len=40) :: label

    do element = 1, elements
      reference(:, 8*element - 7:8*element) = distorted_cube(0.2_wp) &
                                               + spread([101.3_wp, -47.9_wp, 55.7_wp + 1.1_wp*element], 2, 8)
      connectivity(:, element) = [(8*(element - 1) + node, node=1, 8)]
    end do
    velocities = spread(flight, 2, 8*elements)

    ! the one-point element's gradient kernel, on the mid-step configuration
    x = 0.0_wp; y = 0.0_wp; z = 0.0_wp; vx = 0.0_wp; vy = 0.0_wp; vz = 0.0_wp
    do element = 1, elements
      x(element, :) = reference(1, connectivity(:, element))
      y(element, :) = reference(2, connectivity(:, element))
      z(element, :) = reference(3, connectivity(:, element))
      vx(element, :) = flight(1)
      vy(element, :) = flight(2)
      vz(element, :) = flight(3)
    end do
    call hex8_velocity_gradient(elements, -0.5_wp*dt, x, y, z, vx, vy, vz, gradient, volume)
    call check(suite, "free flight: velocity gradient exactly zero", all(gradient(1:elements, :) == 0.0_wp))

    do variant = 1, variants
      write (label, '(a, i0, a, i0)') "free flight, ELFORM ", formulations(variant), ", IHQ ", hourglass_types(variant)
      call make_model(model, reference, connectivity, elastic_steel(), formulations(variant), hourglass_types(variant))
      call build_solid_blocks(model, blocks)
      call check(suite, trim(label)//": one block, every element exposed", &
                 size(blocks) == 1 .and. blocks(1)%exposed_count == elements)
      ! the solver's start (no step taken), then steps of free flight
      call compute_solid_block(blocks(1), model%materials(1), reference, velocities, 0.0_wp, force, critical, &
                               critical_element, inverted)
      recent = huge(1.0_wp)
      deviation = 0.0_wp
      do step = 1, steps
        current = reference + (step*dt)*velocities
        call compute_solid_block(blocks(1), model%materials(1), current, velocities, dt, force, critical, &
                                 critical_element, inverted)
        ! the block's step is the smallest of its last three calls (solid_block), each at rest
        call solid_block_time_steps(blocks(1), model%materials(1), current, at_rest)
        recent = [minval(at_rest(1:elements)), recent(1:2)]
        deviation = max(deviation, abs(critical/minval(recent) - 1.0_wp))
      end do
      ! (round-off of the configuration about 100 mm from the origin moves the steps by ~1e-12)
      call check_close(suite, trim(label)//": stable step is the step at rest", deviation, 0.0_wp, thr=1e-9_wp)
      call check(suite, trim(label)//": no stress", all(blocks(1)%stress(1:elements, :, :) == 0.0_wp))
      call check_close(suite, trim(label)//": no internal energy", &
                       maxval(abs(blocks(1)%internal_energy(1:elements))), 0.0_wp, thr=1e-30_wp)
    end do
  end subroutine test_free_flight

  !> ELFORM 2 under a non-linear velocity field: the volumetric strain comes from the element
  !> mean, so the pressure is the same at all eight points and equals K tr(L_mean) dt with
  !> tr(L_mean) = (1/V) sum_I v_I . b_I on the mid-step configuration; the deviatoric stress,
  !> fully integrated, differs between the points.
  subroutine test_selective_reduced_pressure()
    type(model_t) :: model
    type(solid_block_t), allocatable :: blocks(:)
    real(wp) :: middle(3, 8), current(3, 8), velocities(3, 8), force(block_size, 8, 3), critical
    real(wp) :: x(block_size, 8), y(block_size, 8), z(block_size, 8), bx(block_size, 8), by(block_size, 8)
    real(wp) :: bz(block_size, 8), volume(block_size), pressures(8), deviatoric_xx(8), mean_trace, bulk, shear
    integer :: node, point, critical_element, inverted
    real(wp), parameter :: dt = 1.0e-6_wp
    middle = distorted_cube(0.15_wp)
    do node = 1, 8
      velocities(:, node) = 30.0_wp*[middle(1, node)*middle(2, node), middle(2, node)*middle(3, node)**2, &
                                     -middle(3, node)*middle(1, node)]
    end do
    current = middle + 0.5_wp*dt*velocities
    call make_model(model, middle, reshape([1, 2, 3, 4, 5, 6, 7, 8], [8, 1]), elastic_steel(), 2, 1)
    call build_solid_blocks(model, blocks)
    call compute_solid_block(blocks(1), model%materials(1), current, velocities, dt, force, critical, &
                             critical_element, inverted)
    do point = 1, 8
      pressures(point) = sum(blocks(1)%stress(1, 1:3, point))/3.0_wp
      deviatoric_xx(point) = blocks(1)%stress(1, 1, point) - pressures(point)
    end do
    x = 0.0_wp
    y = 0.0_wp
    z = 0.0_wp
    x(1, :) = middle(1, :)
    y(1, :) = middle(2, :)
    z(1, :) = middle(3, :)
    call hex8_volume_derivatives(1, x, y, z, bx, by, bz, volume)
    mean_trace = sum(velocities(1, :)*bx(1, :) + velocities(2, :)*by(1, :) + velocities(3, :)*bz(1, :))/volume(1)
    call elastic_moduli(elastic_steel(), bulk, shear)
    call check_close(suite, "ELFORM 2: pressure from the mean dilatation at every point", pressures, &
                     spread(bulk*mean_trace*dt, 1, 8), rel=1e-12_wp)
    call check(suite, "ELFORM 2: deviatoric stress varies between the points (full integration)", &
               maxval(deviatoric_xx) - minval(deviatoric_xx) > 0.01_wp*maxval(abs(deviatoric_xx)))
  end subroutine test_selective_reduced_pressure

  pure function invariants(sigma) result(values)
    real(wp), intent(in) :: sigma(3, 3)
    real(wp) :: values(3), trace
    trace = sigma(1, 1) + sigma(2, 2) + sigma(3, 3)
    values(1) = trace
    values(2) = 0.5_wp*(trace**2 - sum(sigma*transpose(sigma)))
    values(3) = determinant3(sigma)
  end function invariants

  !> Uniform compression of a cube (side h) about its centre, v = -a (x - centre) on the mid-step
  !> configuration, from zero stress: tr D = -3a exactly and
  !> q = rho l (Q1^2 l (tr D)^2 - Q2 c tr D), rho = rho0 V0 / V, l = V^(1/3), c = sqrt(M / rho0).
  subroutine test_bulk_viscosity()
    type(model_t) :: model
    type(solid_block_t), allocatable :: blocks(:)
    real(wp) :: reference(3, 8), middle(3, 8), current(3, 8), velocities(3, 8), centre(3)
    real(wp) :: force(block_size, 8, 3), stress_force(block_size, 8, 3), critical
    real(wp) :: rate, volume, length, current_density, speed, expected_q, trace
    real(wp) :: expected_energy, characteristic, viscous, q1, q2, frequency_squared, damping
    integer :: node, critical_element, inverted, formulation
    real(wp), parameter :: dt = 1.0e-6_wp, side = 2.0_wp
    character(len=32) :: label

    reference = side*unit_cube
    centre = [1.0_wp, 1.0_wp, 1.0_wp]
    rate = 200.0_wp
    do node = 1, 8
      middle(:, node) = centre + 0.999_wp*(reference(:, node) - centre)
      velocities(:, node) = -rate*(middle(:, node) - centre)
      current(:, node) = middle(:, node) + 0.5_wp*dt*velocities(:, node)
    end do
    do formulation = 1, 2
      label = merge("bulk viscosity, ELFORM 1", "bulk viscosity, ELFORM 2", formulation == 1)
      call make_model(model, reference, reshape([1, 2, 3, 4, 5, 6, 7, 8], [8, 1]), elastic_steel(), formulation, 3)
      call build_solid_blocks(model, blocks)
      q1 = blocks(1)%bulk_quadratic
      q2 = blocks(1)%bulk_linear
      call compute_solid_block(blocks(1), model%materials(1), current, velocities, dt, force, critical, &
                               critical_element, inverted)
      trace = -3.0_wp*rate
      volume = (side*0.999_wp*(1.0_wp - 0.5_wp*dt*rate))**3
      length = volume**(1.0_wp/3.0_wp)
      current_density = density*side**3/volume
      speed = wave_speed(elastic_steel())
      expected_q = current_density*length*(q1**2*length*trace**2 - q2*speed*trace)
      call check_close(suite, trim(label)//": q = rho l (Q1^2 l trD^2 - Q2 c trD)", blocks(1)%bulk_viscosity(1), &
                       expected_q, rel=1e-12_wp)
      ! the corner forces carry q as an added pressure: f = (sigma - q I) b
      call uniform_stress_forces(blocks(1), current, blocks(1)%stress(:, :, 1), [(expected_q, node=1, block_size)], &
                                 stress_force)
      call check_close(suite, trim(label)//": forces include -q b", reshape(force(1, :, :), [24]), &
                       reshape(stress_force(1, :, :), [24]), rel=1e-12_wp, thr=1e-12_wp*maxval(abs(force)))
      ! internal energy of a first step from rest: half the work of the new forces,
      ! dt/2 (sigma - q I) : sum_I v_I (x) b_I(n+1) = dt/2 V (tr sigma - 3 q) tr(L(n+1)) / 3, where
      ! v = -a/(1 - a dt/2) (x(n+1) - centre) on the end-of-step configuration
      expected_energy = 0.5_wp*dt*volume*(sum(blocks(1)%stress(1, 1:3, 1)) - 3.0_wp*expected_q) &
                        *(-rate/(1.0_wp - 0.5_wp*rate*dt))
      call check_close(suite, trim(label)//": internal energy includes the bulk viscosity work", &
                       blocks(1)%internal_energy(1), expected_energy, rel=1e-10_wp)
      call check(suite, trim(label)//": bulk viscosity work is positive in compression", &
                 -expected_q*trace > 0.0_wp .and. expected_energy > 0.5_wp*dt*volume*sum(blocks(1)%stress(1, 1:3, 1)) &
                 *(-rate/(1.0_wp - 0.5_wp*rate*dt)))
      ! time step with the bulk viscosity: LS-DYNA's L / (Q + sqrt(Q^2 + c^2)), Q = Q2 c +
      ! Q1 L |trD|, or the element's bound if smaller: on a cube (side L) the volumetric mode
      ! has omega^2 = 4 (V / V0) (3 lambda + 2 mu) / (rho0 L^2), damped as LS-DYNA's rule
      ! damps a row of elements, beta = 2 Q2 omega + 4 Q1 |trD|: 4 / (beta + sqrt(beta^2 +
      ! 4 omega^2)); the hourglass (IHQ 3) and extra deviatoric (ELFORM 2) modes are slower
      characteristic = volume/(volume**(2.0_wp/3.0_wp))
      viscous = q2*speed + q1*characteristic*abs(trace)
      frequency_squared = 4.0_wp*(volume/side**3)*(3.0_wp*lame_lambda() + 2.0_wp*lame_mu()) &
                          /(density*characteristic**2)
      damping = 2.0_wp*q2*sqrt(frequency_squared) + 4.0_wp*q1*abs(trace)
      call check_close(suite, trim(label)//": time step with bulk viscosity", critical, &
                       min(characteristic/(viscous + sqrt(viscous**2 + speed**2)), &
                           4.0_wp/(damping + sqrt(damping**2 + 4.0_wp*frequency_squared))), rel=1e-6_wp)
      call check(suite, trim(label)//": the element's bound sets it", &
                 critical < 0.8_wp*characteristic/(viscous + sqrt(viscous**2 + speed**2)))
      call check(suite, trim(label)//": critical element is the model solid", critical_element == 1)
    end do
    ! expansion: no bulk viscosity, plain time step
    velocities = -velocities
    do node = 1, 8
      current(:, node) = middle(:, node) + 0.5_wp*dt*velocities(:, node)
    end do
    call make_model(model, reference, reshape([1, 2, 3, 4, 5, 6, 7, 8], [8, 1]), elastic_steel(), 1, 3)
    call build_solid_blocks(model, blocks)
    call compute_solid_block(blocks(1), model%materials(1), current, velocities, dt, force, critical, &
                             critical_element, inverted)
    call check_close(suite, "bulk viscosity: none in expansion", blocks(1)%bulk_viscosity(1), 0.0_wp, thr=0.0_wp)
    volume = blocks(1)%volume(1)
    ! no damping: 2 / omega of the volumetric mode
    call check_close(suite, "time step in expansion: 2 / omega", critical, volume**(1.0_wp/3.0_wp) &
                     *sqrt(density*side**3/volume/(3.0_wp*lame_lambda() + 2.0_wp*lame_mu())), rel=1e-6_wp)
  end subroutine test_bulk_viscosity

  !> A pure hourglass velocity v_x = u h1 on a unit cube at x(n+1): q_x1 = 8u and, with the
  !> shape vectors equal to h on a cube for every IHQ,
  !>   viscous    f = a_h q gamma,         a_h = QM rho c V^(2/3)/4
  !>   stiffness  f = k dt q gamma,        k = QM (lambda + 2 mu) sum(b.b) / (3V) = QM M / 2
  !> and, for a first step from rest, an energy of half the work of the new force, f . v dt / 2.
  subroutine test_hourglass_forces()
    type(model_t) :: model
    type(solid_block_t), allocatable :: blocks(:)
    real(wp) :: current(3, 8), velocities(3, 8), force(block_size, 8, 3), stress_force(block_size, 8, 3)
    real(wp) :: expected(8), generalized, modulus, bulk, shear, critical, coefficient, energy
    integer :: hourglass_type, critical_element, inverted, node
    real(wp), parameter :: dt = 1.0e-6_wp, amplitude = 0.5_wp
    character(len=48) :: label

    current = unit_cube
    velocities = 0.0_wp
    velocities(1, :) = amplitude*hourglass_base(:, 1)
    call elastic_moduli(elastic_steel(), bulk, shear)
    modulus = bulk + 4.0_wp*shear/3.0_wp
    do hourglass_type = 1, 5
      write (label, '(a,i0)') "hourglass mode on a cube, IHQ ", hourglass_type
      call make_model(model, current - 0.5_wp*dt*velocities, reshape([1, 2, 3, 4, 5, 6, 7, 8], [8, 1]), &
                      elastic_steel(), 1, hourglass_type)
      call build_solid_blocks(model, blocks)
      coefficient = blocks(1)%hourglass_coefficient
      call compute_solid_block(blocks(1), model%materials(1), current, velocities, dt, force, critical, &
                               critical_element, inverted)
      call uniform_stress_forces(blocks(1), current, blocks(1)%stress(:, :, 1), blocks(1)%bulk_viscosity, &
                                 stress_force)
      if (hourglass_type <= 3) then
        generalized = 0.25_wp*coefficient*density*blocks(1)%reference_volume(1)*sqrt(modulus/density) &
                      *8.0_wp*amplitude
        ! first step from rest: half the work of the new force, dt/2 a_h q . q
        energy = 0.5_wp*0.25_wp*coefficient*density*blocks(1)%reference_volume(1)*sqrt(modulus/density) &
                 *(8.0_wp*amplitude)**2*dt
      else
        generalized = 0.5_wp*coefficient*modulus*dt*8.0_wp*amplitude
        ! first step from rest: dt/2 (k dt q) . q
        energy = 0.5_wp*0.5_wp*coefficient*modulus*dt*(8.0_wp*amplitude)**2*dt
      end if
      expected = generalized*hourglass_base(:, 1)
      call check_close(suite, trim(label)//": x forces", force(1, :, 1) - stress_force(1, :, 1), expected, &
                       rel=1e-9_wp, thr=1e-9_wp*generalized)
      call check_close(suite, trim(label)//": no y, z forces", [(force(1, node, 2) - stress_force(1, node, 2), &
                       node=1, 8), (force(1, node, 3) - stress_force(1, node, 3), node=1, 8)], &
                       [(0.0_wp, node=1, 16)], thr=1e-9_wp*generalized)
      call check_close(suite, trim(label)//": hourglass energy", blocks(1)%hourglass_energy(1), energy, rel=1e-9_wp)
    end do
  end subroutine test_hourglass_forces

  !> Random distorted elements, random (non-linear) velocities, prestress and plasticity: the
  !> corner forces of every element sum to zero and have no moment about the centroid.
  subroutine test_conservation()
    type(model_t) :: model
    type(solid_block_t), allocatable :: blocks(:)
    real(wp) :: mesh(3, 27), force(block_size, 8, 3), critical, resultant(3), moment(3), centroid(3)
    real(wp), allocatable :: current(:, :), velocities(:, :)
    real(wp) :: worst_resultant, worst_moment, scale, arm(3), corner_force(3)
    integer :: connectivity(8, 8), hourglass_type, formulation, step, lane, node, critical_element, inverted
    integer :: variant, point
    real(wp), parameter :: dt = 1.0e-6_wp
    character(len=48) :: label

    call irregular_mesh(mesh, connectivity)
    allocate (velocities(3, 27))
    do variant = 1, 6
      formulation = merge(2, 1, variant == 6)
      hourglass_type = merge(1, variant, variant == 6)
      if (formulation == 1) then
        write (label, '(a,i0)') "conservation, ELFORM 1 IHQ ", hourglass_type
      else
        label = "conservation, ELFORM 2"
      end if
      call make_model(model, mesh, connectivity, plastic_steel(), formulation, hourglass_type)
      call build_solid_blocks(model, blocks)
      do point = 1, blocks(1)%point_count
        do lane = 1, blocks(1)%element_count
          blocks(1)%stress(lane, :, point) = random_symmetric(200.0_wp)
        end do
      end do
      current = mesh
      worst_resultant = 0.0_wp
      worst_moment = 0.0_wp
      do step = 1, 3
        do node = 1, 27
          velocities(:, node) = 50.0_wp*[random_uniform(random_state), random_uniform(random_state), random_uniform(random_state)]
        end do
        current = current + dt*velocities
        call compute_solid_block(blocks(1), model%materials(1), current, velocities, dt, force, critical, &
                                 critical_element, inverted)
        do lane = 1, blocks(1)%element_count
          scale = maxval(abs(force(lane, :, :)))
          centroid = sum(current(:, connectivity(:, lane)), dim=2)/8.0_wp
          resultant = sum(force(lane, :, :), dim=1)
          moment = 0.0_wp
          do node = 1, 8
            arm = current(:, connectivity(node, lane)) - centroid
            corner_force = force(lane, node, :)
            moment = moment + cross(arm, corner_force)
          end do
          worst_resultant = max(worst_resultant, maxval(abs(resultant))/scale)
          worst_moment = max(worst_moment, maxval(abs(moment))/scale)
        end do
      end do
      call check_close(suite, trim(label)//": sum of corner forces zero", worst_resultant, 0.0_wp, thr=1e-12_wp)
      if (formulation == 1 .and. hourglass_type == 1) then
        call check(suite, trim(label)//": IHQ 1 forces have a moment on distorted elements", worst_moment > 1e-8_wp)
      else
        call check_close(suite, trim(label)//": moment about the centroid zero", worst_moment, 0.0_wp, thr=1e-12_wp)
      end if
      call check(suite, trim(label)//": plastic flow happened", maxval(blocks(1)%history(:, 1, :)) > 0.0_wp)
      call check(suite, trim(label)//": unused lanes have zero force", all(force(9:, :, :) == 0.0_wp))
    end do
  end subroutine test_conservation

  !> A block's energy sums (what a distributed run hands between ranks instead of the lanes'
  !> energies): the live lanes' energy and power, the eroded lanes' energy; booked as energy +
  !> step correction x power. Checked against the lane-by-lane values of a block with eroded
  !> lanes, and against a block without any.
  subroutine test_block_energy_sums()
    real(wp) :: energy(block_size), power(block_size), sums(3), live_energy, live_power, eroded_energy
    logical :: eroded(block_size)
    integer :: lane, count
    count = 50
    do lane = 1, block_size
      energy(lane) = 5.0_wp*(1.0_wp + random_uniform(random_state))
      power(lane) = 5.0_wp*random_uniform(random_state)
    end do
    eroded = .false.
    eroded([3, 17, 40, 60]) = .true.      ! lane 60 lies beyond the block's 50 elements
    live_energy = 0.0_wp
    live_power = 0.0_wp
    eroded_energy = 0.0_wp
    do lane = 1, count
      if (eroded(lane)) then
        eroded_energy = eroded_energy + energy(lane)
      else
        live_energy = live_energy + energy(lane)
        live_power = live_power + power(lane)
      end if
    end do
    sums = lane_energy_sums(energy, power, count, eroded)
    call check_close(suite, "block energy sums: live lanes' energy", sums(1), live_energy, rel=1e-14_wp)
    call check_close(suite, "block energy sums: live lanes' power", sums(2), live_power, rel=1e-14_wp)
    call check_close(suite, "block energy sums: eroded lanes' energy (lanes 3, 17, 40)", sums(3), &
                     energy(3) + energy(17) + energy(40), rel=1e-14_wp)
    call check_close(suite, "block energy sums: booked energy = energy + step correction x power", &
                     booked_energy(sums(1), sums(2), 0.25_wp), live_energy + 0.25_wp*live_power, rel=1e-14_wp)
    sums = lane_energy_sums(energy, power, count)
    call check_close(suite, "block energy sums: no eroded lanes, all energy live", sums(1), sum(energy(1:count)), &
                     rel=1e-14_wp)
    call check(suite, "block energy sums: no eroded lanes, no eroded energy", sums(3) == 0.0_wp)
  end subroutine test_block_energy_sums

  !> Central differences with a varying step on the irregular 8-element mesh (free, elastic,
  !> with bulk viscosity and hourglass control): kinetic energy 1/2 m v(n-1/2) . v(n+1/2) plus
  !> the elements' internal and hourglass energies stays constant to round-off, once the last
  !> forces' work is completed with the next step, 1/4 (dt(n+1/2) - dt(n-1/2)) (force_power +
  !> hourglass_power). This is the balance the solver reports.
  subroutine test_energy_balance()
    type(model_t) :: model
    type(solid_block_t), allocatable :: blocks(:)
    real(wp) :: mesh(3, 27), mass(27), corner_mass(block_size, 8), force(block_size, 8, 3), nodal_force(3, 27)
    real(wp) :: coordinates(3, 27), previous_velocity(3, 27), next_velocity(3, 27), critical
    real(wp) :: previous_step, next_step, kinetic, total, initial_total, worst
    integer :: connectivity(8, 8), step, node, lane, corner, variant, critical_element, inverted
    character(len=40) :: label
    call irregular_mesh(mesh, connectivity)
    do variant = 1, 3
      select case (variant)
      case (1)
        call make_model(model, mesh, connectivity, elastic_steel(), 1, 4)
        label = "energy balance, ELFORM 1 IHQ 4"
      case (2)
        call make_model(model, mesh, connectivity, elastic_steel(), 1, 2)
        label = "energy balance, ELFORM 1 IHQ 2"
      case default
        call make_model(model, mesh, connectivity, plastic_steel(), 2, 1)
        label = "energy balance, ELFORM 2 plastic"
      end select
      call build_solid_blocks(model, blocks)
      call solid_block_corner_masses(blocks(1), corner_mass)
      mass = 0.0_wp
      do corner = 1, 8
        do lane = 1, blocks(1)%element_count
          mass(connectivity(corner, lane)) = mass(connectivity(corner, lane)) + corner_mass(lane, corner)
        end do
      end do
      coordinates = mesh
      do node = 1, 27
        previous_velocity(:, node) = 2.0e4_wp*[cos(mesh(1, node)), sin(2.0_wp*mesh(2, node)), &
                                               cos(mesh(3, node) + mesh(1, node))]
      end do
      ! start: forces at t = 0 with no step taken
      call compute_solid_block(blocks(1), model%materials(1), coordinates, previous_velocity, 0.0_wp, force, &
                               critical, critical_element, inverted)
      previous_step = 0.0_wp
      worst = 0.0_wp
      initial_total = 0.0_wp
      do step = 0, 200
        call gather_forces(connectivity, force, nodal_force)
        next_step = 0.5_wp*critical*(1.0_wp + 0.3_wp*sin(0.7_wp*step))
        do node = 1, 27
          next_velocity(:, node) = previous_velocity(:, node) - 0.5_wp*(previous_step + next_step) &
                                   *nodal_force(:, node)/mass(node)
        end do
        kinetic = 0.5_wp*sum(spread(mass, 1, 3)*previous_velocity*next_velocity)
        total = kinetic + sum(blocks(1)%internal_energy(1:8)) + sum(blocks(1)%hourglass_energy(1:8)) &
                + 0.25_wp*(next_step - previous_step)*sum(blocks(1)%force_power(1:8) + blocks(1)%hourglass_power(1:8))
        if (step == 0) initial_total = total
        worst = max(worst, abs(total - initial_total))
        coordinates = coordinates + next_step*next_velocity
        call compute_solid_block(blocks(1), model%materials(1), coordinates, next_velocity, next_step, force, &
                                 critical, critical_element, inverted)
        previous_velocity = next_velocity
        previous_step = next_step
      end do
      call check_close(suite, trim(label)//": kinetic + internal + hourglass energy constant", worst/initial_total, &
                       0.0_wp, thr=1e-12_wp)
      call check(suite, trim(label)//": energy was exchanged", sum(blocks(1)%internal_energy(1:8)) > 1e-3_wp*initial_total)
      if (variant == 3) call check(suite, trim(label)//": plastic flow happened", &
                                   maxval(blocks(1)%history(1:8, 1, :)) > 0.0_wp)
    end do
  end subroutine test_energy_balance

  !> Nodal forces of the 8-element mesh from its corner forces.
  subroutine gather_forces(connectivity, corner_forces, nodal)
    integer, intent(in) :: connectivity(8, 8)
    real(wp), intent(in) :: corner_forces(block_size, 8, 3)
    real(wp), intent(out) :: nodal(3, 27)
    integer :: lane, corner
    nodal = 0.0_wp
    do corner = 1, 8
      do lane = 1, 8
        nodal(:, connectivity(corner, lane)) = nodal(:, connectivity(corner, lane)) + corner_forces(lane, corner, :)
      end do
    end do
  end subroutine gather_forces

  subroutine test_inverted_elements()
    type(model_t) :: model
    type(solid_block_t), allocatable :: blocks(:)
    real(wp) :: nodes(3, 12), original(3, 12), velocities(3, 12), force(block_size, 8, 3), critical, bowtie(3, 8)
    real(wp) :: natural(8, 3, 8), smallest
    integer :: connectivity(8, 2), critical_element, inverted, point
    ! two cubes side by side; the second has its top face pushed through its bottom
    nodes(:, 1:8) = unit_cube
    nodes(:, 9:12) = unit_cube(:, [2, 3, 6, 7]) + spread([1.0_wp, 0.0_wp, 0.0_wp], 2, 4)
    connectivity(:, 1) = [1, 2, 3, 4, 5, 6, 7, 8]
    connectivity(:, 2) = [2, 9, 10, 3, 6, 11, 12, 7]
    original = nodes
    call make_model(model, original, connectivity, elastic_steel(), 1, 2)
    call build_solid_blocks(model, blocks)
    velocities = 0.0_wp
    nodes(3, [11, 12]) = -1.5_wp
    nodes(3, [6, 7]) = -1.5_wp
    call compute_solid_block(blocks(1), model%materials(1), nodes, velocities, 1.0e-6_wp, force, critical, &
                             critical_element, inverted)
    call check(suite, "inverted element reported (ELFORM 1)", inverted == 1)
    nodes(3, [6, 7]) = 1.0_wp
    call make_model(model, original, connectivity, elastic_steel(), 1, 2)
    call build_solid_blocks(model, blocks)
    call compute_solid_block(blocks(1), model%materials(1), nodes, velocities, 1.0e-6_wp, force, critical, &
                             critical_element, inverted)
    call check(suite, "inverted second element reported by its solid index", inverted == 2)

    ! ELFORM 2 also checks the Gauss point Jacobians: a cube with node 7 pulled in to near
    ! node 1 keeps a positive volume but a negative Jacobian near node 7.
    bowtie = unit_cube
    bowtie(:, 7) = [0.15_wp, 0.15_wp, 0.15_wp]
    call hex8_gauss_natural_derivatives(natural)
    smallest = huge(1.0_wp)
    do point = 1, 8
      smallest = min(smallest, determinant3(matmul(bowtie, natural(:, :, point))))
    end do
    call check(suite, "bow-tie hexahedron: positive volume, a negative Gauss Jacobian", &
               gauss_volume(bowtie) > 0.0_wp .and. smallest < 0.0_wp)
    call make_model(model, bowtie, reshape([1, 2, 3, 4, 5, 6, 7, 8], [8, 1]), elastic_steel(), 2, 1)
    call build_solid_blocks(model, blocks)
    call compute_solid_block(blocks(1), model%materials(1), bowtie, velocities(:, 1:8), 1.0e-6_wp, force, critical, &
                             critical_element, inverted)
    call check(suite, "ELFORM 2: negative Gauss Jacobian reported", inverted == 1)
    call make_model(model, bowtie, reshape([1, 2, 3, 4, 5, 6, 7, 8], [8, 1]), elastic_steel(), 1, 1)
    call build_solid_blocks(model, blocks)
    call compute_solid_block(blocks(1), model%materials(1), bowtie, velocities(:, 1:8), 1.0e-6_wp, force, critical, &
                             critical_element, inverted)
    call check(suite, "ELFORM 1: positive volume is not inverted", inverted == 0)
  end subroutine test_inverted_elements

  !> Three parts: 100 solids of part 1 and 50 of part 3 interleaved with them, and 10 solids of
  !> an EFG part 2 (no blocks). Blocks: part 1 (64 + 36 lanes), then part 3 (50 lanes).
  subroutine test_build_blocks()
    type(model_t) :: model
    type(solid_block_t), allocatable :: blocks(:)
    integer :: solid, count_solids, lane, first_part3
    logical :: order_kept
    count_solids = 160
    allocate (model%coordinates(3, 8*count_solids), model%solid_nodes(8, count_solids), &
              model%solid_part(count_solids), model%solid_ids(count_solids))
    do solid = 1, count_solids
      model%coordinates(:, 8*(solid - 1) + 1:8*solid) = unit_cube + spread([2.0_wp*solid, 0.0_wp, 0.0_wp], 2, 8)
      model%solid_nodes(:, solid) = [(8*(solid - 1) + lane, lane=1, 8)]
      model%solid_ids(solid) = 1000 + solid
      if (solid <= 150) then
        model%solid_part(solid) = merge(3, 1, mod(solid, 3) == 0)
      else
        model%solid_part(solid) = 2
      end if
    end do
    allocate (model%parts(3), model%sections(2), model%materials(2))
    model%materials(1) = elastic_steel()
    model%materials(2) = plastic_steel()
    model%materials(2)%density = 2.7e-9_wp
    model%sections(1)%element_formulation = 1
    model%sections(2)%element_formulation = 2
    model%parts(1)%section = 1
    model%parts(1)%material = 2
    model%parts(1)%hourglass_type = 4
    model%parts(1)%hourglass_coefficient = 0.05_wp
    model%parts(1)%bulk_quadratic = 1.2_wp
    model%parts(1)%bulk_linear = 0.05_wp
    model%parts(2)%formulation = formulation_efg
    model%parts(2)%section = 1
    model%parts(2)%material = 1
    model%parts(3)%section = 2
    model%parts(3)%material = 1
    model%parts(3)%formulation = formulation_fe
    call build_solid_blocks(model, blocks)
    call check(suite, "blocks: three blocks (EFG part has none)", size(blocks) == 3)
    if (size(blocks) /= 3) return
    call check(suite, "blocks: part order and lane counts", blocks(1)%part == 1 .and. blocks(2)%part == 1 .and. &
               blocks(3)%part == 3 .and. blocks(1)%element_count == 64 .and. blocks(2)%element_count == 36 .and. &
               blocks(3)%element_count == 50)
    order_kept = all(blocks(1)%elements(2:64) > blocks(1)%elements(1:63)) .and. &
                 blocks(2)%elements(1) > blocks(1)%elements(64) .and. &
                 all(blocks(3)%elements(2:50) > blocks(3)%elements(1:49))
    call check(suite, "blocks: input order kept", order_kept)
    first_part3 = blocks(3)%elements(1)
    call check(suite, "blocks: right solids", blocks(1)%elements(1) == 1 .and. first_part3 == 3 .and. &
               all(model%solid_part(blocks(3)%elements(1:50)) == 3))
    call check(suite, "blocks: node lists copied", all(blocks(3)%nodes(2, :) == model%solid_nodes(:, blocks(3)%elements(2))))
    call check(suite, "blocks: settings of the part", blocks(1)%material == 2 .and. blocks(1)%formulation == 1 .and. &
               blocks(1)%hourglass_type == 4 .and. blocks(1)%hourglass_coefficient == 0.05_wp .and. &
               blocks(1)%bulk_quadratic == 1.2_wp .and. blocks(1)%bulk_linear == 0.05_wp .and. &
               blocks(3)%formulation == 2 .and. blocks(3)%material == 1)
    call check(suite, "blocks: state sizes", size(blocks(1)%stress, 3) == 1 .and. size(blocks(1)%history, 2) == 7 .and. &
               size(blocks(3)%stress, 3) == 8 .and. size(blocks(3)%history, 2) == 0 .and. &
               size(blocks(1)%hourglass_force, 3) == 4 .and. size(blocks(3)%hourglass_force, 3) == 0)
    call check_close(suite, "blocks: density from the material", blocks(1)%density(1:64), &
                     [(2.7e-9_wp, lane=1, 64)], rel=0.0_wp)
    call check_close(suite, "blocks: reference volumes", blocks(2)%reference_volume(1:36), [(1.0_wp, lane=1, 36)], &
                     rel=1e-15_wp)
    call check_close(suite, "blocks: Gauss point volumes of ELFORM 2", blocks(3)%point_volume(7, :), &
                     [(0.125_wp, lane=1, 8)], rel=1e-14_wp)
    call check(suite, "blocks: zero state", all(blocks(1)%stress == 0.0_wp) .and. all(blocks(1)%history == 0.0_wp) &
               .and. all(blocks(1)%internal_energy == 0.0_wp) .and. all(blocks(1)%hourglass_energy == 0.0_wp))
  end subroutine test_build_blocks

  !> A 3 x 3 x 3 block of unit cubes: the 8 corner and 12 edge elements have a node where the
  !> solids fill pi / 2 or pi (solid_exposure) and get the eigenvalue bound; the 6 face-centre
  !> elements (their nodes on a flat surface, 2 pi) and the centre one keep LS-DYNA's rule. The
  !> block lists the exposed lanes first, each group in input order.
  subroutine test_exposed_elements()
    type(model_t) :: model
    type(solid_block_t), allocatable :: blocks(:)
    real(wp) :: coordinates(3, 64), time_step(block_size), rule(block_size)
    integer :: connectivity(8, 27), i, j, k, lane, solid, outer_faces(27)
    logical :: expected(27)
    do k = 0, 3
      do j = 0, 3
        do i = 0, 3
          coordinates(:, 1 + i + 4*j + 16*k) = [real(i, wp), real(j, wp), real(k, wp)]
        end do
      end do
    end do
    do k = 0, 2
      do j = 0, 2
        do i = 0, 2
          solid = 1 + i + 3*j + 9*k
          connectivity(:, solid) = 1 + [i + 4*j + 16*k, i + 1 + 4*j + 16*k, i + 1 + 4*(j + 1) + 16*k, &
                                        i + 4*(j + 1) + 16*k, i + 4*j + 16*(k + 1), i + 1 + 4*j + 16*(k + 1), &
                                        i + 1 + 4*(j + 1) + 16*(k + 1), i + 4*(j + 1) + 16*(k + 1)]
          ! an element on two or three outer faces of the block is at an edge or a corner
          outer_faces(solid) = count([i /= 1, j /= 1, k /= 1])
        end do
      end do
    end do
    expected = outer_faces >= 2
    call make_model(model, coordinates, connectivity, elastic_steel(), 1, 1)
    call build_solid_blocks(model, blocks)
    call check(suite, "exposure: 20 of 27 exposed", blocks(1)%exposed_count == 20 .and. count(expected) == 20)
    call check(suite, "exposure: exposed lanes first", all(blocks(1)%exposed(1:20)) .and. &
               .not. any(blocks(1)%exposed(21:)))
    call check(suite, "exposure: the corner and edge elements, in input order", &
               all(expected(blocks(1)%elements(1:20))) .and. all(blocks(1)%elements(2:20) > blocks(1)%elements(1:19)))
    call check(suite, "exposure: the others, in input order", .not. any(expected(blocks(1)%elements(21:27))) .and. &
               all(blocks(1)%elements(22:27) > blocks(1)%elements(21:26)))
    call solid_block_time_steps(blocks(1), model%materials(1), model%coordinates, time_step)
    do lane = 1, 27
      rule(lane) = lsdyna_step(coordinates(:, connectivity(:, blocks(1)%elements(lane))))
    end do
    call check_close(suite, "exposure: LS-DYNA's rule L / c inside and on flat faces", time_step(21:27), rule(21:27), &
                     rel=1e-12_wp)
    ! the volumetric mode of the free cube: 2 / omega = sqrt(rho / (3 lambda + 2 mu)) < 0.74 L / c
    call check_close(suite, "exposure: the cube's bound at corners and edges", time_step(1:20), &
                     [(sqrt(density/(3.0_wp*lame_lambda() + 2.0_wp*lame_mu())), lane=1, 20)], rel=1e-6_wp)
  end subroutine test_exposed_elements


  !> Element results: volume-weighted stress over the Gauss points, mean plastic strain, written
  !> to the element's column.
  subroutine test_element_results()
    type(model_t) :: model
    type(solid_block_t), allocatable :: blocks(:)
    real(wp) :: stress(6, 3), plastic_strain(3), expected(6), reference(3, 8)
    integer :: point
    reference = unit_cube
    reference(1, [2, 3, 6, 7]) = 3.0_wp  ! a 3 x 1 x 1 box with one corner pulled out, so that
    reference(:, 7) = reference(:, 7) + [0.4_wp, 0.3_wp, 0.2_wp] ! the point volumes differ
    call make_model(model, reference, reshape([1, 2, 3, 4, 5, 6, 7, 8], [8, 1]), plastic_steel(), 2, 1)
    model%solid_nodes(:, 1) = [1, 2, 3, 4, 5, 6, 7, 8]
    call build_solid_blocks(model, blocks)
    blocks(1)%elements(1) = 2   ! write into column 2 of a 3-solid result array
    expected = 0.0_wp
    do point = 1, 8
      blocks(1)%stress(1, :, point) = real(point, wp)*[1.0_wp, 2.0_wp, 3.0_wp, 4.0_wp, 5.0_wp, 6.0_wp]
      blocks(1)%history(1, 1, point) = 0.01_wp*point
      expected = expected + blocks(1)%point_volume(1, point)*blocks(1)%stress(1, :, point)
    end do
    expected = expected/sum(blocks(1)%point_volume(1, :))
    stress = -1.0_wp
    plastic_strain = -1.0_wp
    call solid_block_element_results(blocks(1), stress, plastic_strain)
    call check_close(suite, "results: volume-averaged stress", stress(:, 2), expected, rel=1e-14_wp)
    call check_close(suite, "results: mean plastic strain", plastic_strain(2), 0.045_wp, rel=1e-14_wp)
    call check(suite, "results: other columns untouched", all(stress(:, [1, 3]) == -1.0_wp) .and. &
               plastic_strain(1) == -1.0_wp .and. plastic_strain(3) == -1.0_wp)
    call check(suite, "results: point volumes differ (weighting matters)", &
               maxval(blocks(1)%point_volume(1, :)) > 1.1_wp*minval(blocks(1)%point_volume(1, :)))
  end subroutine test_element_results
end program test_solid_elements
