!> Unit tests of the embedding library crashfree_efg, through its interface alone (no model,
!> no deck): an irregular block of 4 x 4 x 4 hexahedra in the unit cube (interior nodes moved),
!> - linear patch test: for a linear displacement field the stress is constant, so the forces
!>   at interior nodes and particles vanish (1e-10 of the boundary forces), the forces on the
!>   faces x = 0 and x = 1 equal the traction resultants -P N A and P N A of the uniaxial stress,
!>   and all forces add up to zero;
!> - partition of unity and linear reproduction of the transformation (cf_efg_to_physical), exact
!>   mass (sum of lumped masses = density x volume to 1e-12);
!> - a host law through the callback gives the forces of the built-in elastic law;
!> - misuse: wrong sizes, a node out of range, an inside-out hexahedron, support <= 1, calls in
!>   the wrong order, a destroyed handle: each a status and a message naming the argument;
!> - 1 and 3 threads give bit-identical masses and forces (the test sets the thread count; the
!>   library never does).
program test_crashfree_efg
  use, intrinsic :: iso_c_binding, only: c_int, c_double, c_ptr, c_loc, c_f_pointer
  use kinds, only: wp
  use testing, only: test_suite_t, check, check_close, finish_suite
  use crashfree_efg, only: cf_efg_part, cf_efg_create, cf_efg_mark_boundary, cf_efg_set_up, cf_efg_counts, &
                           cf_efg_lumped_mass, cf_efg_set_elastic, cf_efg_set_plastic_kinematic, &
                           cf_efg_set_material_callback, cf_efg_set_bulk_viscosity, cf_efg_internal_force, &
                           cf_efg_to_physical, &
                           cf_efg_internal_energy, cf_efg_destroy, cf_efg_last_error, cf_efg_is_null, cf_efg_ok, &
                           cf_efg_error_argument, cf_efg_error_order, cf_efg_error_handle, cf_efg_error_geometry, &
                           cf_efg_error_singular, cf_efg_error_material, &
                           cf_efg_material_law
  !$ use omp_lib, only: omp_get_max_threads, omp_set_num_threads
  implicit none

  integer, parameter :: cells_per_side = 4, side_nodes = cells_per_side + 1
  integer, parameter :: node_count = side_nodes**3, cell_count = cells_per_side**3
  real(wp), parameter :: young = 210.0_wp, poisson = 0.3_wp, density = 7.85e-3_wp
  type(test_suite_t) :: suite
  procedure(cf_efg_material_law) :: host_elastic_law, host_failing_law
  real(wp), target :: coordinates(3, node_count)
  integer :: hexahedra(8, cell_count)

  suite%name = "crashfree_efg"
  call block_mesh(coordinates, hexahedra)
  call test_counts_and_mass()
  call test_transformation()
  call test_patch([integer ::])
  ! interior nodes marked as boundary (Gamma) nodes: FE functions inside the part
  call test_patch([node_at(2, 2, 2), node_at(1, 2, 3), node_at(3, 1, 2)])
  call test_callback()
  call test_bulk_viscosity()
  call test_plastic_energy()
  call test_misuse()
  call test_threads()
  call finish_suite(suite)

contains

  !> The unit cube in 4 x 4 x 4 hexahedra; interior nodes moved by up to 0.15 h (a fixed
  !> pattern), the boundary nodes stay on the faces.
  subroutine block_mesh(coordinates, hexahedra)
    real(wp), intent(out) :: coordinates(3, node_count)
    integer, intent(out) :: hexahedra(8, cell_count)
    real(wp) :: h
    integer :: i, j, k, node, cell
    h = 1.0_wp/cells_per_side
    do k = 0, cells_per_side
      do j = 0, cells_per_side
        do i = 0, cells_per_side
          node = 1 + i + side_nodes*(j + side_nodes*k)
          coordinates(:, node) = h*[real(i, wp), real(j, wp), real(k, wp)]
          if (i > 0 .and. i < cells_per_side .and. j > 0 .and. j < cells_per_side .and. k > 0 .and. &
              k < cells_per_side) then
            coordinates(:, node) = coordinates(:, node) + 0.15_wp*h*[sin(1.7_wp*node), cos(2.3_wp*node), &
                                                                     sin(0.9_wp*node + 1.0_wp)]
          end if
        end do
      end do
    end do
    cell = 0
    do k = 0, cells_per_side - 1
      do j = 0, cells_per_side - 1
        do i = 0, cells_per_side - 1
          cell = cell + 1
          node = 1 + i + side_nodes*(j + side_nodes*k)
          hexahedra(:, cell) = [node, node + 1, node + 1 + side_nodes, node + side_nodes, &
                                node + side_nodes**2, node + 1 + side_nodes**2, node + 1 + side_nodes + side_nodes**2, &
                                node + side_nodes + side_nodes**2]
        end do
      end do
    end do
  end subroutine block_mesh

  pure integer function node_at(i, j, k)
    integer, intent(in) :: i, j, k
    node_at = 1 + i + side_nodes*(j + side_nodes*k)
  end function node_at

  !> A part of the block, set up, with the given kernel and integration (support 1.4 for the
  !> box kernel, 1.1 for the sphere: its radius already reaches the cells' far corners).
  subroutine new_part(part, kernel, integration, marked)
    type(cf_efg_part), intent(inout) :: part
    integer, intent(in) :: kernel, integration
    integer, intent(in), optional :: marked(:)
    integer(c_int) :: status
    real(wp) :: support
    support = merge(1.1_wp, 1.4_wp, kernel == 2)
    call cf_efg_create(part, coordinates, hexahedra, [support, support, support], kernel, integration, status)
    call check(suite, "create: status ok", status == cf_efg_ok, error_text(part))
    if (present(marked)) then
      call cf_efg_mark_boundary(part, marked, status)
      call check(suite, "mark boundary: status ok", status == cf_efg_ok, error_text(part))
    end if
    call cf_efg_set_up(part, status)
    call check(suite, "set up: status ok", status == cf_efg_ok, error_text(part))
  end subroutine new_part

  function error_text(part) result(text)
    type(cf_efg_part), intent(in) :: part
    character(len=:), allocatable :: text
    call cf_efg_last_error(part, text)
  end function error_text

  logical function on_boundary(x)
    real(wp), intent(in) :: x(3)
    on_boundary = any(abs(x) < 1.0e-12_wp) .or. any(abs(x - 1.0_wp) < 1.0e-12_wp)
  end function on_boundary

  subroutine test_counts_and_mass()
    type(cf_efg_part) :: part
    integer(c_int) :: nodes, particles, boundary_nodes, points, status, integration, kernel
    real(wp) :: mass(node_count)
    do integration = 1, 2
      do kernel = 0, 2, 2
        call new_part(part, kernel, integration)
        call cf_efg_counts(part, nodes, particles, boundary_nodes, points, status)
        call check(suite, "counts: nodes", nodes == node_count .and. status == cf_efg_ok)
        ! the free surface: every node of the cube's faces; the 27 inside are particles
        call check(suite, "counts: particles are the interior nodes", particles == (cells_per_side - 1)**3)
        call check(suite, "counts: boundary nodes", boundary_nodes == node_count - (cells_per_side - 1)**3)
        call check(suite, "counts: 8 points per hexahedron", points == 8*cell_count)
        call cf_efg_lumped_mass(part, density, mass, status)
        call check(suite, "lumped mass: status", status == cf_efg_ok)
        call check_close(suite, "lumped mass: sum = density x volume (unit cube)", sum(mass), density, rel=1.0e-12_wp)
        call check(suite, "lumped mass: positive", all(mass > 0.0_wp))
        call cf_efg_destroy(part, status)
        call check(suite, "destroy: ok and null", status == cf_efg_ok .and. cf_efg_is_null(part))
      end do
    end do
  end subroutine test_counts_and_mass

  !> Partition of unity and linear reproduction of the particles' physical values (eq. 16).
  subroutine test_transformation()
    type(cf_efg_part) :: part
    real(wp) :: generalized(3, node_count), physical(3, node_count), expected(3, node_count)
    integer(c_int) :: status
    integer :: j
    call new_part(part, 0, 1)
    generalized(1, :) = 1.0_wp
    generalized(2, :) = -2.0_wp
    generalized(3, :) = 0.5_wp
    call cf_efg_to_physical(part, generalized, physical, status)
    call check(suite, "to_physical: status", status == cf_efg_ok)
    call check_close(suite, "to_physical: partition of unity", reshape(physical, [3*node_count]), &
                     reshape(generalized, [3*node_count]), thr=1.0e-13_wp)
    do j = 1, node_count
      expected(:, j) = linear_field(coordinates(:, j))
    end do
    call cf_efg_to_physical(part, expected, physical, status)
    call check_close(suite, "to_physical: a linear field is reproduced", reshape(physical, [3*node_count]), &
                     reshape(expected, [3*node_count]), thr=1.0e-13_wp)
    call cf_efg_destroy(part, status)
  end subroutine test_transformation

  pure function linear_field(x) result(u)
    real(wp), intent(in) :: x(3)
    real(wp) :: u(3)
    u = [0.1_wp + 0.3_wp*x(1) - 0.2_wp*x(2) + 0.1_wp*x(3), -0.05_wp + 0.1_wp*x(1) + 0.25_wp*x(2), &
         0.2_wp - 0.15_wp*x(3) + 0.05_wp*x(1)]
  end function linear_field

  !> Uniaxial stress sigma_xx = E e from one step of a diagonal linear field whose mid-step
  !> strain increments are (e, -nu e, -nu e): the forces of the nodes on x = 1 add up to
  !> P_xx A = F_yy F_zz E e, those on x = 0 to minus that, interior forces vanish (at the
  !> particles and at the interior nodes `marked` as boundary nodes).
  subroutine test_patch(marked)
    integer, intent(in) :: marked(:)
    type(cf_efg_part) :: part
    integer(c_int) :: nodes, particles, boundary_nodes, points
    real(wp), parameter :: strain = 1.0e-3_wp, dt = 1.0e-4_wp
    real(wp) :: displacement(3, node_count), velocity(3, node_count), force(3, node_count), mass(node_count)
    real(wp) :: increment(3), stretch(3), stable_dt, right(3), left(3), interior, largest, expected, energy
    integer(c_int) :: status
    integer :: j
    ! mid-step increments d = a / (1 + a / 2) for a stretch 1 + a
    increment = [strain, -poisson*strain, -poisson*strain]
    stretch = increment/(1.0_wp - 0.5_wp*increment)
    do j = 1, node_count
      displacement(:, j) = stretch*coordinates(:, j)
    end do
    velocity = displacement/dt
    call new_part(part, 0, 1, marked)
    call cf_efg_counts(part, nodes, particles, boundary_nodes, points, status)
    call check(suite, "patch: marked nodes are boundary nodes", particles == (cells_per_side - 1)**3 - size(marked) &
               .and. boundary_nodes == node_count - particles)
    call cf_efg_lumped_mass(part, density, mass, status)
    call cf_efg_set_elastic(part, young, poisson, status)
    call check(suite, "patch: set_elastic", status == cf_efg_ok)
    force = 0.0_wp
    call cf_efg_internal_force(part, displacement, velocity, dt, force, stable_dt, status)
    call check(suite, "patch: internal force status", status == cf_efg_ok, error_text(part))
    right = 0.0_wp
    left = 0.0_wp
    interior = 0.0_wp
    largest = maxval(abs(force))
    do j = 1, node_count
      if (abs(coordinates(1, j) - 1.0_wp) < 1.0e-12_wp) right = right + force(:, j)
      if (abs(coordinates(1, j)) < 1.0e-12_wp) left = left + force(:, j)
      if (.not. on_boundary(coordinates(:, j))) interior = max(interior, maxval(abs(force(:, j))))
    end do
    expected = (1.0_wp + stretch(2))*(1.0_wp + stretch(3))*young*strain
    call check(suite, "patch: interior nodes and particles carry no force", interior <= 1.0e-10_wp*largest)
    call check_close(suite, "patch: face x = 1, traction resultant P_xx A", right(1), expected, rel=1.0e-10_wp)
    call check_close(suite, "patch: face x = 0, traction resultant -P_xx A", left(1), -expected, rel=1.0e-10_wp)
    call check_close(suite, "patch: face x = 1, no shear resultant", right(2:3), [0.0_wp, 0.0_wp], &
                     thr=1.0e-10_wp*expected)
    call check_close(suite, "patch: forces add up to zero", sum(force, dim=2), [0.0_wp, 0.0_wp, 0.0_wp], &
                     thr=1.0e-12_wp*expected)
    ! the stable step of the smallest cell: at least L / c with L the smallest edge / 2
    call check(suite, "patch: stable step positive and of the cells' order", stable_dt > 0.0_wp .and. &
               stable_dt < 0.25_wp/sqrt(young/density))
    call cf_efg_internal_energy(part, energy, status)
    ! half the new forces' power is booked with the step: dt/2 f . v = 1/2 sigma e V
    call check_close(suite, "patch: internal energy 1/2 sigma_xx e V after one step", energy, &
                     0.5_wp*young*strain*strain, rel=2.0e-3_wp)
    call cf_efg_destroy(part, status)
  end subroutine test_patch

  !> Uniaxial compression in one step: without bulk viscosity (Q1 = Q2 = 0) the face x = 1 gets
  !> the resultant of the elastic stress exactly; with LS-DYNA's defaults the viscous pressure
  !> adds to it (compression only).
  subroutine test_bulk_viscosity()
    type(cf_efg_part) :: part
    real(wp), parameter :: strain = -1.0e-3_wp, dt = 1.0e-4_wp
    real(wp) :: displacement(3, node_count), velocity(3, node_count), force(3, node_count), mass(node_count)
    real(wp) :: increment(3), stretch(3), stable_dt(2), right(2), expected
    integer(c_int) :: status
    integer :: j, run
    increment = [strain, -poisson*strain, -poisson*strain]
    stretch = increment/(1.0_wp - 0.5_wp*increment)
    do j = 1, node_count
      displacement(:, j) = stretch*coordinates(:, j)
    end do
    velocity = displacement/dt
    do run = 1, 2
      call new_part(part, 0, 1)
      call cf_efg_lumped_mass(part, density, mass, status)
      call cf_efg_set_elastic(part, young, poisson, status)
      if (run == 1) call cf_efg_set_bulk_viscosity(part, 0.0_wp, 0.0_wp, status)
      call check(suite, "bulk viscosity: set", status == cf_efg_ok, error_text(part))
      force = 0.0_wp
      call cf_efg_internal_force(part, displacement, velocity, dt, force, stable_dt(run), status)
      right(run) = 0.0_wp
      do j = 1, node_count
        if (abs(coordinates(1, j) - 1.0_wp) < 1.0e-12_wp) right(run) = right(run) + force(1, j)
      end do
      call cf_efg_destroy(part, status)
    end do
    expected = (1.0_wp + stretch(2))*(1.0_wp + stretch(3))*young*strain
    call check_close(suite, "bulk viscosity off: compression resultant P_xx A", right(1), expected, rel=1.0e-10_wp)
    call check(suite, "bulk viscosity on: the viscous pressure adds to the compression", right(2) < right(1))
    call check(suite, "bulk viscosity on: a smaller stable step", stable_dt(2) < stable_dt(1))
  end subroutine test_bulk_viscosity

  !> A host's linear elastic law through the callback: the same forces as the built-in law.
  subroutine test_callback()
    type(cf_efg_part) :: built_in, hosted
    real(wp), target :: constants(2)
    real(wp) :: displacement(3, node_count), velocity(3, node_count), force(3, node_count, 2), mass(node_count)
    real(wp) :: stable(2), dt
    integer(c_int) :: status
    integer :: j, step
    constants = [young, poisson]
    call new_part(built_in, 0, 1)
    call new_part(hosted, 0, 1)
    call cf_efg_lumped_mass(built_in, density, mass, status)
    call cf_efg_lumped_mass(hosted, density, mass, status)
    call cf_efg_set_elastic(built_in, young, poisson, status)
    call cf_efg_set_material_callback(hosted, host_elastic_law, c_loc(constants), 1, &
                                      young*(1.0_wp - poisson)/((1.0_wp + poisson)*(1.0_wp - 2.0_wp*poisson)), status)
    call check(suite, "callback: set", status == cf_efg_ok, error_text(hosted))
    dt = 1.0e-4_wp
    do step = 1, 3
      do j = 1, node_count
        velocity(:, j) = step*1.0e-2_wp*[sin(3.0_wp*coordinates(2, j)), coordinates(1, j)*coordinates(3, j), &
                                         cos(coordinates(1, j) + coordinates(2, j))]
        displacement(:, j) = step*dt*velocity(:, j)
      end do
      force = 0.0_wp
      call cf_efg_internal_force(built_in, displacement, velocity, dt, force(:, :, 1), stable(1), status)
      call cf_efg_internal_force(hosted, displacement, velocity, dt, force(:, :, 2), stable(2), status)
      call check(suite, "callback: internal force status", status == cf_efg_ok, error_text(hosted))
    end do
    call check_close(suite, "callback: forces equal the built-in elastic law's", reshape(force(:, :, 2), &
                     [3*node_count]), reshape(force(:, :, 1), [3*node_count]), thr=1.0e-12_wp*maxval(abs(force)))
    call check_close(suite, "callback: stable step equals the built-in law's", stable(2), stable(1), rel=1.0e-12_wp)
    call cf_efg_destroy(built_in, status)
    call cf_efg_destroy(hosted, status)
    ! a host law that fails (a stress that is not a number) gives a status, not NaN forces
    call new_part(hosted, 0, 1)
    call cf_efg_lumped_mass(hosted, density, mass, status)
    call cf_efg_set_material_callback(hosted, host_failing_law, c_loc(constants), 0, young, status)
    force = 0.0_wp
    call cf_efg_internal_force(hosted, displacement, velocity, dt, force(:, :, 2), stable(2), status)
    call expect("a host law returning NaN", hosted, status, cf_efg_error_material, &
                "the host's material law returned a stress that is not a finite number")
    call cf_efg_destroy(hosted, status)
  end subroutine test_callback

  !> The built-in plastic law: a stretch beyond yield stores less energy than the elastic law.
  subroutine test_plastic_energy()
    type(cf_efg_part) :: part
    real(wp) :: displacement(3, node_count), velocity(3, node_count), force(3, node_count), mass(node_count)
    real(wp) :: stable_dt, energy, dt
    integer(c_int) :: status
    integer :: j, step
    call new_part(part, 0, 1)
    call cf_efg_lumped_mass(part, density, mass, status)
    call cf_efg_set_plastic_kinematic(part, young, poisson, 0.2_wp, 1.0_wp, 0.0_wp, status)
    call check(suite, "plastic: set", status == cf_efg_ok, error_text(part))
    dt = 1.0e-3_wp
    do step = 1, 10
      do j = 1, node_count
        velocity(:, j) = [1.0_wp*coordinates(1, j), 0.0_wp, 0.0_wp]
        displacement(:, j) = step*dt*velocity(:, j)
      end do
      force = 0.0_wp
      call cf_efg_internal_force(part, displacement, velocity, dt, force, stable_dt, status)
    end do
    call check(suite, "plastic: internal force status", status == cf_efg_ok, error_text(part))
    call cf_efg_internal_energy(part, energy, status)
    ! strain 0.01 in uniaxial strain: elastically (lambda + 2 mu) e^2 / 2 = 0.0141; yielding at
    ! 0.2 caps the deviatoric part
    call check(suite, "plastic: energy below the elastic one", energy > 0.0_wp .and. energy < &
               0.5_wp*young*(1.0_wp - poisson)/((1.0_wp + poisson)*(1.0_wp - 2.0_wp*poisson))*1.0e-4_wp)
    call cf_efg_destroy(part, status)
  end subroutine test_plastic_energy

  !> Each misuse: its status and a message naming the argument.
  subroutine test_misuse()
    type(cf_efg_part) :: part
    integer :: bad_hexahedra(8, cell_count)
    real(wp) :: mass(node_count), field(3, node_count), stable_dt, energy
    real(wp) :: bad_coordinates(4, node_count)
    integer(c_int) :: status
    character(len=:), allocatable :: message

    ! wrong sizes
    bad_coordinates = 0.0_wp
    call cf_efg_create(part, bad_coordinates, hexahedra, [1.4_wp, 1.4_wp, 1.4_wp], 0, 1, status)
    call expect("create: coordinates of 4 rows", part, status, cf_efg_error_argument, "coordinates has shape (4, ")
    call cf_efg_set_up(part, status)
    call expect("set_up after a failed create", part, status, cf_efg_error_order, "coordinates")
    call cf_efg_destroy(part, status)
    call cf_efg_create(part, coordinates, hexahedra(1:7, :), [1.4_wp, 1.4_wp, 1.4_wp], 0, 1, status)
    call expect("create: hexahedra of 7 rows", part, status, cf_efg_error_argument, "hexahedra has shape (7, ")
    call cf_efg_destroy(part, status)
    call cf_efg_create(part, coordinates, hexahedra, [1.4_wp, 1.4_wp], 0, 1, status)
    call expect("create: support of 2 values", part, status, cf_efg_error_argument, "support has 2 values")
    call cf_efg_destroy(part, status)
    ! a node out of range
    bad_hexahedra = hexahedra
    bad_hexahedra(3, 17) = node_count + 7
    call cf_efg_create(part, coordinates, bad_hexahedra, [1.4_wp, 1.4_wp, 1.4_wp], 0, 1, status)
    call expect("create: node out of range", part, status, cf_efg_error_argument, &
                "hexahedra(3, 17) = 132 names no node (coordinates has 125 nodes)")
    call cf_efg_destroy(part, status)
    ! an inside-out hexahedron (faces swapped)
    bad_hexahedra = hexahedra
    bad_hexahedra(:, 5) = [hexahedra(5:8, 5), hexahedra(1:4, 5)]
    call cf_efg_create(part, coordinates, bad_hexahedra, [1.4_wp, 1.4_wp, 1.4_wp], 0, 1, status)
    call expect("create: inside-out hexahedron", part, status, cf_efg_error_geometry, "hexahedra(:, 5) is inside out")
    call cf_efg_destroy(part, status)
    ! support <= 1, kernel, integration
    call cf_efg_create(part, coordinates, hexahedra, [1.4_wp, 1.0_wp, 1.4_wp], 0, 1, status)
    call expect("create: support <= 1", part, status, cf_efg_error_argument, "support(2) =")
    call cf_efg_destroy(part, status)
    call cf_efg_create(part, coordinates, hexahedra, [1.4_wp, 1.4_wp, 1.4_wp], 1, 1, status)
    call expect("create: kernel 1", part, status, cf_efg_error_argument, "kernel = 1")
    call cf_efg_destroy(part, status)
    call cf_efg_create(part, coordinates, hexahedra, [1.4_wp, 1.4_wp, 1.4_wp], 0, 4, status)
    call expect("create: integration 4", part, status, cf_efg_error_argument, "integration = 4")
    call cf_efg_destroy(part, status)
    ! spheres of 1.4 times the body diagonal reach too far for this block: a node's mass share
    ! turns negative, the set-up refuses the part
    call cf_efg_create(part, coordinates, hexahedra, [1.4_wp, 1.4_wp, 1.4_wp], 2, 1, status)
    call cf_efg_set_up(part, status)
    call expect("set-up: supports too large", part, status, cf_efg_error_singular, &
                "cf_efg_set_up: 1 node(s) get a non-positive row-sum mass")
    call cf_efg_destroy(part, status)

    ! wrong order
    call cf_efg_create(part, coordinates, hexahedra, [1.4_wp, 1.4_wp, 1.4_wp], 0, 1, status)
    call check(suite, "misuse: a good create", status == cf_efg_ok)
    call cf_efg_create(part, coordinates, hexahedra, [1.4_wp, 1.4_wp, 1.4_wp], 0, 1, status)
    call expect("create on a live handle", part, status, cf_efg_error_order, "part is already created")
    call cf_efg_mark_boundary(part, [1, 0], status)
    call expect("mark_boundary: node 0", part, status, cf_efg_error_argument, "nodes(2) = 0 names no node")
    field = 0.0_wp
    call cf_efg_internal_force(part, field, field, 0.0_wp, field, stable_dt, status)
    call expect("internal force before set-up", part, status, cf_efg_error_order, "call cf_efg_set_up first")
    call cf_efg_lumped_mass(part, density, mass, status)
    call expect("lumped mass before set-up", part, status, cf_efg_error_order, "cf_efg_lumped_mass")
    call cf_efg_set_up(part, status)
    call check(suite, "misuse: set-up", status == cf_efg_ok)
    call cf_efg_last_error(part, message)
    call check(suite, "misuse: no message after a success", message == "")
    call cf_efg_set_up(part, status)
    call expect("set-up twice", part, status, cf_efg_error_order, "cf_efg_set_up: wrong order")
    call cf_efg_mark_boundary(part, [1], status)
    call expect("mark_boundary after set-up", part, status, cf_efg_error_order, "before cf_efg_set_up")
    call cf_efg_internal_force(part, field, field, 0.0_wp, field, stable_dt, status)
    call expect("internal force without a law", part, status, cf_efg_error_order, "no material law")
    call cf_efg_set_elastic(part, young, 0.5_wp, status)
    call expect("set_elastic: poisson 0.5", part, status, cf_efg_error_argument, "poisson =")
    call cf_efg_set_bulk_viscosity(part, 1.5_wp, -0.06_wp, status)
    call expect("set_bulk_viscosity: negative Q2", part, status, cf_efg_error_argument, "linear =")
    call cf_efg_set_elastic(part, young, poisson, status)
    call cf_efg_internal_force(part, field, field, 0.0_wp, field, stable_dt, status)
    call expect("internal force without a density", part, status, cf_efg_error_order, "no density")
    call cf_efg_lumped_mass(part, density, mass(1:node_count - 1), status)
    call expect("lumped mass: mass too short", part, status, cf_efg_error_argument, "mass has 124 values")
    call cf_efg_lumped_mass(part, density, mass, status)
    call cf_efg_internal_force(part, field(:, 1:node_count - 1), field, 0.0_wp, field, stable_dt, status)
    call expect("internal force: displacement too short", part, status, cf_efg_error_argument, &
                "displacement has shape (3, 124)")
    call cf_efg_internal_force(part, field, field, -1.0_wp, field, stable_dt, status)
    call expect("internal force: negative dt", part, status, cf_efg_error_argument, "dt =")
    call cf_efg_internal_force(part, field, field, 0.0_wp, field, stable_dt, status)
    call check(suite, "misuse: internal force", status == cf_efg_ok, error_text(part))
    call cf_efg_set_elastic(part, young, poisson, status)
    call expect("law changed after the first internal force", part, status, cf_efg_error_order, "are fixed once")
    call cf_efg_set_bulk_viscosity(part, 1.0_wp, 0.0_wp, status)
    call expect("bulk viscosity changed after the first internal force", part, status, cf_efg_error_order, &
                "are fixed once")

    ! a destroyed handle
    call cf_efg_destroy(part, status)
    call check(suite, "misuse: destroy", status == cf_efg_ok)
    call cf_efg_set_up(part, status)
    call expect("set-up of a destroyed handle", part, status, cf_efg_error_handle, "part: the handle is null")
    call cf_efg_internal_energy(part, energy, status)
    call check(suite, "misuse: energy of a destroyed handle", status == cf_efg_error_handle)
    call cf_efg_destroy(part, status)
    call check(suite, "misuse: destroy twice", status == cf_efg_error_handle)
  end subroutine test_misuse

  !> The status is `expected` and the message contains `words`.
  subroutine expect(name, part, status, expected, words)
    character(len=*), intent(in) :: name
    type(cf_efg_part), intent(in) :: part
    integer(c_int), intent(in) :: status, expected
    character(len=*), intent(in) :: words
    character(len=:), allocatable :: message
    call cf_efg_last_error(part, message)
    call check(suite, "misuse: "//name//": status", status == expected)
    call check(suite, "misuse: "//name//": message names the argument", index(message, words) > 0, message)
  end subroutine expect

  !> Masses and three calls' forces with 1 and 3 threads: bit-identical. Then two parts at the
  !> same time on two threads of the caller (each part from one thread): the same results again.
  subroutine test_threads()
    real(wp) :: mass(node_count, 4), force(3, node_count, 4), stable(4), energy(4)
    integer(c_int) :: status(4)
    integer :: run, threads
    mass = 0.0_wp
    force = 0.0_wp
    stable = 0.0_wp
    energy = 0.0_wp
    threads = 1
    !$ threads = omp_get_max_threads()
    do run = 1, 2
      !$ call omp_set_num_threads(merge(1, 3, run == 1))
      call forces_of_three_calls(mass(:, run), force(:, :, run), stable(run), energy(run), status(run))
    end do
    !$ call omp_set_num_threads(2)
    !$omp parallel sections default(shared)
    !$omp section
    call forces_of_three_calls(mass(:, 3), force(:, :, 3), stable(3), energy(3), status(3))
    !$omp section
    call forces_of_three_calls(mass(:, 4), force(:, :, 4), stable(4), energy(4), status(4))
    !$omp end parallel sections
    !$ call omp_set_num_threads(threads)
    call check(suite, "threads: every call succeeded", all(status == cf_efg_ok))
    call check(suite, "threads: masses bit-identical for 1 and 3 threads", all(mass(:, 1) == mass(:, 2)))
    call check(suite, "threads: forces bit-identical for 1 and 3 threads", all(force(:, :, 1) == force(:, :, 2)))
    call check(suite, "threads: stable step and energy bit-identical", stable(1) == stable(2) .and. &
               energy(1) == energy(2))
    call check(suite, "threads: two parts on two threads at once, bit-identical", &
               all(force(:, :, 3) == force(:, :, 1)) .and. all(force(:, :, 4) == force(:, :, 1)) .and. &
               all(mass(:, 3) == mass(:, 1)) .and. all(mass(:, 4) == mass(:, 1)) .and. &
               all(energy(3:4) == energy(1)) .and. all(stable(3:4) == stable(1)))
  end subroutine test_threads

  !> Set up a part, its masses, the plastic law and three internal-force calls (no check here:
  !> it runs on several threads at once).
  subroutine forces_of_three_calls(mass, force, stable_dt, energy, status)
    real(wp), intent(out) :: mass(node_count), force(3, node_count), stable_dt, energy
    integer(c_int), intent(out) :: status
    type(cf_efg_part) :: part
    real(wp) :: displacement(3, node_count), velocity(3, node_count), dt
    integer(c_int) :: call_status(7)
    integer :: j, step
    call cf_efg_create(part, coordinates, hexahedra, [1.1_wp, 1.1_wp, 1.1_wp], 2, 1, call_status(1))
    call cf_efg_set_up(part, call_status(2))
    call cf_efg_lumped_mass(part, density, mass, call_status(3))
    call cf_efg_set_plastic_kinematic(part, young, poisson, 0.2_wp, 1.0_wp, 0.5_wp, call_status(4))
    dt = 1.0e-3_wp
    force = 0.0_wp
    stable_dt = 0.0_wp
    do step = 1, 3
      do j = 1, node_count
        velocity(:, j) = [coordinates(2, j)**2, -coordinates(1, j)*coordinates(3, j), sin(coordinates(1, j))]
        displacement(:, j) = step*dt*velocity(:, j)
      end do
      call cf_efg_internal_force(part, displacement, velocity, dt, force, stable_dt, call_status(5))
    end do
    call cf_efg_internal_energy(part, energy, call_status(6))
    call cf_efg_destroy(part, call_status(7))
    status = maxval(call_status)
  end subroutine forces_of_three_calls
end program test_crashfree_efg

!> A host's law for test_callback (external: an internal procedure passed as an argument would
!> need an executable stack).
!> sigma += lambda tr(de) I + 2 mu de; history(:, 1) counts the calls of each point.
subroutine host_elastic_law(n, strain_increment, spin, stress, history, context) bind(c)
  use, intrinsic :: iso_c_binding, only: c_int, c_double, c_ptr, c_f_pointer
  use kinds, only: wp
  implicit none
  integer(c_int), value, intent(in) :: n
  real(c_double), intent(in) :: strain_increment(n, 6), spin(n, 3)
  real(c_double), intent(inout) :: stress(n, 6), history(n, *)
  type(c_ptr), value, intent(in) :: context
  real(c_double), pointer :: constants(:)
  real(wp) :: lame, shear, trace
  integer :: i
  call c_f_pointer(context, constants, [2])
  lame = constants(1)*constants(2)/((1.0_wp + constants(2))*(1.0_wp - 2.0_wp*constants(2)))
  shear = 0.5_wp*constants(1)/(1.0_wp + constants(2))
  do i = 1, n
    trace = strain_increment(i, 1) + strain_increment(i, 2) + strain_increment(i, 3)
    stress(i, 1:3) = stress(i, 1:3) + lame*trace + 2.0_wp*shear*strain_increment(i, 1:3)
    stress(i, 4:6) = stress(i, 4:6) + 2.0_wp*shear*strain_increment(i, 4:6)
    history(i, 1) = history(i, 1) + 1.0_wp + 0.0_wp*spin(i, 1)
  end do
end subroutine host_elastic_law

!> A host's law that fails: the stress of its first point is not a number.
subroutine host_failing_law(n, strain_increment, spin, stress, history, context) bind(c)
  use, intrinsic :: iso_c_binding, only: c_int, c_double, c_ptr, c_associated
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  implicit none
  integer(c_int), value, intent(in) :: n
  real(c_double), intent(in) :: strain_increment(n, 6), spin(n, 3)
  real(c_double), intent(inout) :: stress(n, 6), history(n, *)
  type(c_ptr), value, intent(in) :: context
  ! it reads its arguments as a law would, then fails
  if (c_associated(context)) history(1, 1) = history(1, 1) + 0.0_c_double*(strain_increment(1, 1) + spin(1, 1))
  stress(1, 1) = ieee_value(stress(1, 1), ieee_quiet_nan)
end subroutine host_failing_law
