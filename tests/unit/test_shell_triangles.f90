!> Unit tests of the triangular shell (N4 = N3) through the shell block API: the bending patch
!> test on a mixed mesh of parallelogram quadrilaterals and triangles (a constant curvature
!> without transverse shear gives every element the same stress, no shear, and no force or
!> moment at the interior nodes), the shear operator's exactness for constant shear, and the
!> triangle's time step and masses.
program test_shell_triangles
  use kinds, only: wp, block_size
  use model, only: model_t, material_t, formulation_fe, section_shell
  use material_laws, only: law_elastic
  use shell_block, only: shell_block_t, build_shell_blocks, shell_block_masses, shell_block_time_steps, &
                         compute_shell_block
  use shell_triangle, only: triangle_shear_operator
  use testing, only: test_suite_t, check, finish_suite
  implicit none

  type(test_suite_t) :: suite
  real(wp), parameter :: youngs = 210000.0_wp, poisson = 0.3_wp, density = 7.85e-9_wp, thickness = 0.1_wp
  integer, parameter :: cells = 4, node_count = (cells + 1)**2

  suite%name = "shell_triangles"
  call test_bending_patch()
  call test_constant_shear()
  call test_triangle_masses_and_step()
  call finish_suite(suite)

contains

  function elastic_steel() result(material)
    type(material_t) :: material
    material%law = law_elastic
    material%density = density
    material%youngs_modulus = youngs
    material%poissons_ratio = poisson
  end function elastic_steel

  !> A 4 x 4 mesh of the unit square under an affine map (parallelograms), every other cell
  !> split into two triangles along alternating diagonals; node k at column i, row j is
  !> i (cells + 1) + j + 1.
  subroutine mixed_mesh(model)
    type(model_t), intent(out) :: model
    real(wp), parameter :: map(2, 2) = reshape([1.0_wp, 0.15_wp, 0.3_wp, 0.9_wp], [2, 2])
    integer :: i, j, shell, a, b, c, d, count
    allocate (model%coordinates(3, node_count))
    do i = 0, cells
      do j = 0, cells
        model%coordinates(1:2, i*(cells + 1) + j + 1) = matmul(map, [real(i, wp), real(j, wp)]/cells)
        model%coordinates(3, i*(cells + 1) + j + 1) = 0.0_wp
      end do
    end do
    count = cells*cells + cells*cells/2
    allocate (model%shell_nodes(4, count), model%shell_part(count), model%shell_ids(count), &
              model%shell_thickness(4, count))
    shell = 0
    do i = 0, cells - 1
      do j = 0, cells - 1
        a = i*(cells + 1) + j + 1
        b = a + cells + 1
        c = b + 1
        d = a + 1
        if (mod(i + j, 2) == 0) then
          shell = shell + 1
          model%shell_nodes(:, shell) = [a, b, c, d]
        else if (mod(i, 2) == 0) then
          model%shell_nodes(:, shell + 1) = [a, b, c, c]
          model%shell_nodes(:, shell + 2) = [a, c, d, d]
          shell = shell + 2
        else
          model%shell_nodes(:, shell + 1) = [a, b, d, d]
          model%shell_nodes(:, shell + 2) = [b, c, d, d]
          shell = shell + 2
        end if
      end do
    end do
    model%shell_part = 1
    model%shell_ids = [(shell, shell=1, count)]
    model%shell_thickness = thickness
    allocate (model%parts(1), model%sections(1), model%materials(1))
    model%materials(1) = elastic_steel()
    model%sections(1)%kind = section_shell
    model%sections(1)%element_formulation = 2
    model%sections(1)%integration_points = 3
    model%sections(1)%shear_factor = 5.0_wp/6.0_wp
    model%sections(1)%thickness = thickness
    model%parts(1)%section = 1
    model%parts(1)%material = 1
    model%parts(1)%formulation = formulation_fe
    model%parts(1)%hourglass_type = 4
    ! the quadrilaterals' out-of-plane hourglass control resists the twist's v_z ~ x y, the
    ! bilinear mode their one point cannot see: off here, so that the patch test sees the
    ! element's own forces
    model%parts(1)%hourglass_coefficient = 0.0_wp
  end subroutine mixed_mesh

  !> v_z = -(a x^2 + 2 b x y + c y^2) / 2, w_x = -(b x + c y), w_y = a x + b y: curvature rates
  !> (a, c, 2 b) and no transverse shear (Kirchhoff). One call on a mid-step configuration that
  !> is the flat mesh: every element must get the same bending stress and no shear stress (the
  !> quadrilaterals because they are parallelograms, the triangles through their edges), and the
  !> interior nodes no force and no moment.
  subroutine test_bending_patch()
    type(model_t) :: model
    type(shell_block_t), allocatable :: blocks(:)
    real(wp), parameter :: a = 0.02_wp, b = -0.01_wp, c = 0.015_wp, dt = 1.0e-6_wp
    real(wp) :: velocity(3, node_count), angular(3, node_count), coordinates(3, node_count)
    real(wp) :: nodal_force(block_size, 4, 6), total(6, node_count), step, scale, bending, spread, shear, residual
    real(wp) :: x, y
    real(wp) :: local(2, 2), global(2, 2, block_size, 3)
    integer :: node, lane, corner, critical, degenerate, i, j, triangles, point
    call mixed_mesh(model)
    do node = 1, node_count
      x = model%coordinates(1, node)
      y = model%coordinates(2, node)
      velocity(:, node) = [0.0_wp, 0.0_wp, -0.5_wp*(a*x*x + 2.0_wp*b*x*y + c*y*y)]
      angular(:, node) = [-(b*x + c*y), a*x + b*y, 0.0_wp]
    end do
    call build_shell_blocks(model, blocks)
    call check(suite, "bending patch: one block of 24 shells", size(blocks) == 1)
    if (size(blocks) /= 1) return
    triangles = count(blocks(1)%nodes(1:blocks(1)%element_count, 3) == blocks(1)%nodes(1:blocks(1)%element_count, 4))
    call check(suite, "bending patch: 16 triangles and 8 quadrilaterals", triangles == 16 .and. &
               blocks(1)%element_count == 24)
    ! x(n+1) such that the mid-step configuration x(n+1) - dt/2 v is the flat mesh
    coordinates = model%coordinates + 0.5_wp*dt*velocity
    call compute_shell_block(blocks(1), model%materials(1), coordinates, velocity, angular, dt, nodal_force, &
                             step, critical, degenerate)
    ! in-plane stresses in global axes (each element keeps its own frame)
    do lane = 1, blocks(1)%element_count
      do point = 1, blocks(1)%point_count
        associate (s => blocks(1)%stress(lane, :, point), e => blocks(1)%frame(lane, 1:2, 1:2))
          local = reshape([s(1), s(3), s(3), s(2)], [2, 2])
          global(:, :, lane, point) = matmul(transpose(e), matmul(local, e))
        end associate
      end do
    end do
    associate (n => blocks(1)%element_count, points => blocks(1)%point_count)
      bending = maxval(abs(global(:, :, 1:n, 1)))
      spread = 0.0_wp
      do lane = 2, n
        spread = max(spread, maxval(abs(global(:, :, lane, 1:points) - global(:, :, 1, 1:points))))
      end do
      shear = maxval(abs(blocks(1)%stress(1:n, 4:5, 1:points)))
    end associate
    call check(suite, "bending patch: the same bending stress in every element (1e-10)", &
               bending > 0.0_wp .and. spread <= 1.0e-10_wp*bending)
    call check(suite, "bending patch: no transverse shear stress (1e-10)", shear <= 1.0e-10_wp*bending)
    total = 0.0_wp
    do lane = 1, blocks(1)%element_count
      do corner = 1, 4
        node = blocks(1)%nodes(lane, corner)
        total(:, node) = total(:, node) + nodal_force(lane, corner, :)
      end do
    end do
    scale = maxval(abs(nodal_force(1:blocks(1)%element_count, :, 4:5)))
    residual = 0.0_wp
    do i = 1, cells - 1
      do j = 1, cells - 1
        node = i*(cells + 1) + j + 1
        residual = max(residual, maxval(abs(total(:, node))))
      end do
    end do
    call check(suite, "bending patch: no force or moment at the interior nodes (1e-10)", &
               scale > 0.0_wp .and. residual <= 1.0e-10_wp*scale)
  end subroutine test_bending_patch

  !> v_z linear and constant rotations: the edge-based shear is the exact constant shear.
  subroutine test_constant_shear()
    real(wp) :: xl(3), yl(3), vz_weight(3, 2), wx_weight(3, 2), wy_weight(3, 2), vz(3), wx(3), wy(3), gamma(2)
    real(wp), parameter :: slope(2) = [0.3_wp, -0.7_wp], rotation(2) = [0.2_wp, 0.5_wp]
    xl = [0.0_wp, 2.0_wp, 0.4_wp]
    yl = [0.0_wp, 0.3_wp, 1.7_wp]
    vz = slope(1)*xl + slope(2)*yl
    wx = rotation(1)
    wy = rotation(2)
    call triangle_shear_operator(xl, yl, vz_weight, wx_weight, wy_weight)
    gamma = matmul(vz, vz_weight) + matmul(wx, wx_weight) + matmul(wy, wy_weight)
    ! 2 d_xz = dv_z/dx + w_y, 2 d_yz = dv_z/dy - w_x
    call check(suite, "triangle shear: exact for a constant shear", &
               maxval(abs(gamma - [slope(1) + rotation(2), slope(2) - rotation(1)])) < 1.0e-14_wp)
  end subroutine test_constant_shear

  !> A lone triangle: a third of its mass at each node, none at corner 4, and the membrane step
  !> 2 A / longest side / c (LS-DYNA's triangle) unless the eigenvalue bound of a lone shell asks
  !> for less.
  subroutine test_triangle_masses_and_step()
    type(model_t) :: model
    type(shell_block_t), allocatable :: blocks(:)
    real(wp) :: corner_mass(block_size, 4), corner_inertia(block_size, 4), step(block_size), area, longest, speed
    allocate (model%coordinates(3, 3), model%shell_nodes(4, 1), model%shell_part(1), model%shell_ids(1), &
              model%shell_thickness(4, 1))
    model%coordinates = reshape([0.0_wp, 0.0_wp, 0.0_wp, 4.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 3.0_wp, 0.0_wp], [3, 3])
    model%shell_nodes(:, 1) = [1, 2, 3, 3]
    model%shell_part = 1
    model%shell_ids = 7
    model%shell_thickness = thickness
    allocate (model%parts(1), model%sections(1), model%materials(1))
    model%materials(1) = elastic_steel()
    model%sections(1)%kind = section_shell
    model%sections(1)%integration_points = 2
    model%sections(1)%thickness = thickness
    model%parts(1)%section = 1
    model%parts(1)%material = 1
    call build_shell_blocks(model, blocks)
    call shell_block_masses(blocks(1), corner_mass, corner_inertia)
    area = 6.0_wp
    call check(suite, "triangle: a third of rho t A at each node", &
               all(abs(corner_mass(1, 1:3)/(density*thickness*area/3.0_wp) - 1.0_wp) < 1.0e-14_wp) .and. &
               corner_mass(1, 4) == 0.0_wp)
    call shell_block_time_steps(blocks(1), model%materials(1), model%coordinates, step)
    longest = sqrt(18.0_wp)
    speed = sqrt(youngs/(density*(1.0_wp - poisson**2)))
    call check(suite, "triangle: step at most 2 A / longest side / c, and not far below", &
               step(1) <= 2.0_wp*area/longest/speed*(1.0_wp + 1.0e-12_wp) .and. &
               step(1) >= 0.5_wp*2.0_wp*area/longest/speed)
  end subroutine test_triangle_masses_and_step
end program test_shell_triangles
