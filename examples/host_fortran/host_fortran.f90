!> An explicit host code of its own (hexahedra, central differences, a support and a prescribed
!> velocity) that makes one region of its mesh meshfree through crashfree's API (module
!> crashfree_efg, docs/embedding.md). Units: mm, ms, kg, kN (GPa for stresses). Modes:
!>   host_fortran patch [support kernel [host-law]]
!>                                         explicit patch test: v = A X on every node and on the
!>                                         block's surface; prints the largest velocity error
!>                                         after 100 cycles and the error of the part's mass
!>   host_fortran bar [host-law]           a stress pulse runs along a bar, finite elements for
!>                                         x < 50 mm, meshfree beyond, the far end supported;
!>                                         prints the probes' velocities in time
!>   (host-law: the part uses the host's own elastic law through the material callback instead
!>   of the library's)
!>   host_fortran forces DT                one internal force call of an all-meshfree block with
!>                                         a velocity on its surface nodes, displacement DT v;
!>                                         prints the hexahedra and each node's mass, force and
!>                                         acceleration (DT 0: no call, forces 0)
!>   host_fortran bench CELLS CALLS        the cost of cf_efg_internal_force on a block of
!>                                         CELLS^3 meshfree cells: ns per integration point per call
program host_fortran
  use, intrinsic :: iso_c_binding, only: c_double, c_int, c_int64_t
  use crashfree_efg, only: cf_efg_internal_force
  use host_mesh, only: host_mesh_t, block_mesh, node_index, on_block_boundary
  use host_hexahedra, only: host_solids_t, set_up_solids
  use host_coupling, only: host_model_t, set_up_model, compute_forces, physical_field, check, destroy_model
  implicit none

  real(c_double), parameter :: density = 7.85e-6_c_double, young = 210.0_c_double
  character(len=32) :: mode

  call get_command_argument(1, mode)
  select case (trim(mode))
  case ("patch")
    call patch_test(real_argument(2, 1.5_c_double), int(real_argument(3, 0.0_c_double), c_int), host_law_argument(4))
  case ("bar")
    call coupled_bar(host_law_argument(2))
  case ("forces")
    call one_force_call(real_argument(2, 0.0_c_double))
  case ("bench")
    call bench(int(real_argument(2, 20.0_c_double)), int(real_argument(3, 50.0_c_double)))
  case default
    write (*, '(a)') "usage: host_fortran patch [support kernel [host-law]] | bar [host-law] | forces DT | "// &
      "bench CELLS CALLS"
    error stop 2
  end select

contains

  !> Command-line argument `position` as a real number (`default` if absent).
  real(c_double) function real_argument(position, default)
    integer, intent(in) :: position
    real(c_double), intent(in) :: default
    character(len=64) :: argument
    integer :: length, read_status
    call get_command_argument(position, argument, length)
    real_argument = default
    if (length == 0) return
    read (argument, *, iostat=read_status) real_argument
    if (read_status /= 0) then
      write (*, '(a)') "host_fortran: argument "//trim(argument)//" is not a number"
      error stop 2
    end if
  end function real_argument

  !> Whether argument `position` asks for the host's own law ("host-law") instead of the
  !> library's elastic law.
  logical function host_law_argument(position)
    integer, intent(in) :: position
    character(len=32) :: argument
    call get_command_argument(position, argument)
    host_law_argument = trim(argument) == "host-law"
  end function host_law_argument

  !> v = A X on every node at the start and on the block's surface throughout: the exact motion
  !> keeps v = A X everywhere (uniform stress, interior forces vanish). tr A > 0, so no bulk
  !> viscosity acts and both sides see the same uniform stress.
  subroutine patch_test(support, kernel, host_law)
    real(c_double), intent(in) :: support
    integer(c_int), intent(in) :: kernel
    logical, intent(in) :: host_law
    real(c_double), parameter :: gradient(3, 3) = reshape([0.010_c_double, 0.003_c_double, -0.001_c_double, &
                                                           0.004_c_double, -0.006_c_double, 0.002_c_double, &
                                                           -0.002_c_double, 0.005_c_double, 0.008_c_double], [3, 3])
    type(host_mesh_t) :: mesh
    type(host_model_t) :: model
    type(host_solids_t) :: meshfree_cells
    logical, allocatable :: meshfree(:), driven(:)
    real(c_double), allocatable :: exact(:, :), physical(:, :)
    real(c_double) :: stable_dt, dt, previous_dt, part_volume
    integer :: i, j, k, cycle_number, e

    call block_mesh([6, 5, 5], 0.25_c_double, 0.25_c_double, 11, mesh)
    allocate (meshfree(size(mesh%hexahedra, 2)), driven(size(mesh%coordinates, 2)))
    ! cells with x < 0.75 mm (the first three layers) are meshfree
    do e = 1, size(meshfree)
      meshfree(e) = mod(e - 1, mesh%cells(1)) < 3
    end do
    driven = .false.
    do k = 0, mesh%cells(3)
      do j = 0, mesh%cells(2)
        do i = 0, mesh%cells(1)
          driven(node_index(mesh, i, j, k)) = on_block_boundary(mesh, i, j, k)
        end do
      end do
    end do
    call set_up_model(mesh, meshfree, driven, density, young, 0.3_c_double, support, kernel, host_law, model)
    ! the part's mass against density times its cells' volume (the host integrates them)
    call set_up_solids(mesh%coordinates, mesh%hexahedra(:, pack([(e, e=1, size(meshfree))], meshfree)), density, &
                       young, 0.3_c_double, meshfree_cells)
    part_volume = sum(meshfree_cells%weight)
    write (*, '(a, 4(1x, i0))') "counts", model%counts
    write (*, '(a, es25.16e3)') "mass_error", abs(sum(model%part_mass) - density*part_volume)/(density*part_volume)

    ! linear fields are reproduced: the generalized values of A X are A X
    exact = matmul(gradient, mesh%coordinates)
    model%velocity = exact
    call compute_forces(model, 0.0_c_double, stable_dt)
    previous_dt = 0.0_c_double
    do cycle_number = 1, 100
      dt = 0.9_c_double*stable_dt
      call advance(model, 0.5_c_double*(previous_dt + dt))
      where (spread(driven, 1, 3)) model%velocity = exact
      model%displacement = model%displacement + dt*model%velocity
      call compute_forces(model, dt, stable_dt)
      previous_dt = dt
    end do
    allocate (physical(3, size(exact, 2)))
    call physical_field(model, model%velocity, physical)
    write (*, '(a, es25.16e3)') "velocity_error", maxval(abs(physical - exact))/maxval(abs(exact))
    call destroy_model(model)
  end subroutine patch_test

  !> v += step a with a = -f / m (no external forces here).
  subroutine advance(model, step)
    type(host_model_t), intent(inout) :: model
    real(c_double), intent(in) :: step
    integer :: node
    do node = 1, size(model%mass)
      model%velocity(:, node) = model%velocity(:, node) - step*model%force(:, node)/model%mass(node)
    end do
  end subroutine advance

  !> A bar of 100 x 2 x 2 mm (1 mm cells, nu = 0: one-dimensional waves), host elements for
  !> x < 50, meshfree beyond, supported at x = 100. The end x = 0 is driven with a smooth
  !> velocity pulse of 0.004 ms (about 20 mm, 20 cells long). Probes: the host node at x = 20
  !> (incident pulse, then whatever the interface reflects) and the interior particle at x = 75
  !> (transmitted pulse, physical velocity).
  subroutine coupled_bar(host_law)
    logical, intent(in) :: host_law
    real(c_double), parameter :: duration = 0.004_c_double, end_time = 0.023_c_double
    real(c_double), parameter :: pi = 3.14159265358979323846_c_double
    type(host_mesh_t) :: mesh
    type(host_model_t) :: model
    logical, allocatable :: meshfree(:), supported(:), driven(:)
    real(c_double), allocatable :: physical(:, :)
    real(c_double) :: stable_dt, dt, previous_dt, time, pulse
    integer :: e, j, k, incident_probe, transmitted_probe

    call block_mesh([100, 2, 2], 1.0_c_double, 0.0_c_double, 1, mesh)
    allocate (meshfree(size(mesh%hexahedra, 2)), supported(size(mesh%coordinates, 2)), &
              driven(size(mesh%coordinates, 2)), physical(3, size(mesh%coordinates, 2)))
    do e = 1, size(meshfree)
      meshfree(e) = mod(e - 1, mesh%cells(1)) >= 50
    end do
    supported = .false.
    driven = .false.
    do k = 0, 2
      do j = 0, 2
        supported(node_index(mesh, 100, j, k)) = .true.
        driven(node_index(mesh, 0, j, k)) = .true.
      end do
    end do
    ! the supported nodes are the part's: marked as boundary nodes (nodal values)
    call set_up_model(mesh, meshfree, supported, density, young, 0.0_c_double, 1.5_c_double, 0_c_int, host_law, &
                      model)
    incident_probe = node_index(mesh, 20, 0, 0)
    transmitted_probe = node_index(mesh, 75, 1, 1)
    write (*, '(a, 4(1x, i0))') "counts", model%counts
    write (*, '(a, es25.16e3)') "wave_speed", sqrt(young/density)
    write (*, '(a, 4(1x, es25.16e3))') "probes_interface_pulse", 20.0_c_double, 75.0_c_double, 50.0_c_double, duration

    call compute_forces(model, 0.0_c_double, stable_dt)
    previous_dt = 0.0_c_double
    time = 0.0_c_double
    do while (time < end_time)
      dt = 0.9_c_double*stable_dt
      call advance(model, 0.5_c_double*(previous_dt + dt))
      ! the velocity of the step from time to time + dt, at its middle
      pulse = 0.0_c_double
      if (time + 0.5_c_double*dt < duration) pulse = sin(pi*(time + 0.5_c_double*dt)/duration)**2
      where (spread(supported, 1, 3)) model%velocity = 0.0_c_double
      do k = 1, size(driven)
        if (driven(k)) model%velocity(:, k) = [pulse, 0.0_c_double, 0.0_c_double]
      end do
      model%displacement = model%displacement + dt*model%velocity
      time = time + dt
      call compute_forces(model, dt, stable_dt)
      previous_dt = dt
      call physical_field(model, model%velocity, physical)
      write (*, '(a, 3(1x, es25.16e3))') "sample", time - 0.5_c_double*dt, physical(1, incident_probe), &
        physical(1, transmitted_probe)
    end do
    call destroy_model(model)
  end subroutine coupled_bar

  !> An all-meshfree block of 5 x 4 x 4 perturbed 1 mm cells (box kernel, DX 1.5) at rest, a
  !> quadratic velocity field on its surface nodes (the interior particles at rest), the
  !> displacement after one step DT: the forces of that one call, as the solver computes them in
  !> its first cycle of the same deck (tests/regression/test_embedding.py).
  subroutine one_force_call(step)
    real(c_double), intent(in) :: step
    type(host_mesh_t) :: mesh
    type(host_model_t) :: model
    logical, allocatable :: meshfree(:), marked(:)
    real(c_double), allocatable :: acceleration(:, :), physical(:, :)
    real(c_double) :: stable_dt, x, y, z
    integer :: i, j, k, node, e

    call block_mesh([5, 4, 4], 1.0_c_double, 0.25_c_double, 7, mesh)
    allocate (meshfree(size(mesh%hexahedra, 2)), marked(size(mesh%coordinates, 2)))
    meshfree = .true.
    marked = .false.
    call set_up_model(mesh, meshfree, marked, density, young, 0.3_c_double, 1.5_c_double, 0_c_int, .false., model)
    do k = 0, mesh%cells(3)
      do j = 0, mesh%cells(2)
        do i = 0, mesh%cells(1)
          if (.not. on_block_boundary(mesh, i, j, k)) cycle
          node = node_index(mesh, i, j, k)
          x = mesh%coordinates(1, node)
          y = mesh%coordinates(2, node)
          z = mesh%coordinates(3, node)
          ! multiples of 1/1024 mm/ms: a keyword deck writes them exactly
          model%velocity(:, node) = real(nint(1024.0_c_double*[0.5_c_double*(x*x - y*z), 0.8_c_double*x*z - 0.3_c_double*y*y, &
                                                             0.6_c_double*x*y + z]), c_double)/1024.0_c_double
        end do
      end do
    end do
    call compute_forces(model, 0.0_c_double, stable_dt)
    write (*, '(a, 4(1x, i0))') "counts", model%counts
    write (*, '(a, es25.16e3)') "stable_dt", stable_dt
    ! step 0: the mesh and the velocities only (to write the same part as a keyword deck)
    if (step > 0.0_c_double) then
      model%displacement = step*model%velocity
      call compute_forces(model, step, stable_dt)
    end if
    allocate (acceleration(3, size(model%mass)), physical(3, size(model%mass)))
    do node = 1, size(model%mass)
      acceleration(:, node) = -model%force(:, node)/model%mass(node)
    end do
    call physical_field(model, acceleration, physical)
    do e = 1, size(mesh%hexahedra, 2)
      write (*, '(a, 9(1x, i0))') "hexahedron", e, mesh%hexahedra(:, e)
    end do
    do node = 1, size(model%mass)
      write (*, '(a, 1x, i0, 13(1x, es25.16e3))') "node", node, mesh%coordinates(:, node), model%velocity(:, node), &
        model%mass(node), model%force(:, node), physical(:, node)
    end do
    call destroy_model(model)
  end subroutine one_force_call

  !> ns per integration point per call of cf_efg_internal_force on a block of cells^3 meshfree
  !> cells (box kernel, DX 1.2, interior nodes moved by up to 10% of a cell) under a small
  !> smooth displacement: the median and the mean of `calls` timed calls after a first untimed
  !> one (tools/bench_api.py runs the solver on the same part).
  subroutine bench(cells, calls)
    integer, intent(in) :: cells, calls
    type(host_mesh_t) :: mesh
    type(host_model_t) :: model
    logical, allocatable :: meshfree(:), marked(:)
    real(c_double), allocatable :: seconds(:)
    real(c_double) :: part_dt
    integer(c_int) :: status
    integer(c_int64_t) :: start, finish, rate
    integer :: call_number

    call block_mesh([cells, cells, cells], 1.0_c_double, 0.1_c_double, 11, mesh)
    allocate (meshfree(size(mesh%hexahedra, 2)), marked(size(mesh%coordinates, 2)), seconds(calls))
    meshfree = .true.
    marked = .false.
    call set_up_model(mesh, meshfree, marked, density, young, 0.3_c_double, 1.2_c_double, 0_c_int, .false., model)
    model%part_displacement = 1.0e-3_c_double*sin(mesh%coordinates)
    model%part_velocity = 1.0e-1_c_double*cos(mesh%coordinates)
    ! the first call builds the part's run-time state (blocks, their colours, stresses): untimed,
    ! as the solver builds it before its first cycle
    call cf_efg_internal_force(model%part, model%part_displacement, model%part_velocity, 0.0_c_double, &
                               model%part_force, part_dt, status)
    call check(model, status, "cf_efg_internal_force")
    do call_number = 1, calls
      model%part_force = 0.0_c_double
      call system_clock(start, rate)
      call cf_efg_internal_force(model%part, model%part_displacement, model%part_velocity, 1.0e-5_c_double, &
                                 model%part_force, part_dt, status)
      call system_clock(finish)
      call check(model, status, "cf_efg_internal_force")
      seconds(call_number) = real(finish - start, c_double)/real(rate, c_double)
    end do
    call sort(seconds)
    write (*, '(a, 1x, i0)') "integration_points", model%counts(4)
    write (*, '(a, f12.3)') "ns_per_point_call", 1.0e9_c_double*seconds((calls + 1)/2)/model%counts(4)
    write (*, '(a, f12.3)') "ns_per_point_call_mean", 1.0e9_c_double*sum(seconds)/calls/model%counts(4)
    call destroy_model(model)
  end subroutine bench

  !> Insertion sort (a few hundred values).
  pure subroutine sort(values)
    real(c_double), intent(inout) :: values(:)
    real(c_double) :: value
    integer :: i, j
    do i = 2, size(values)
      value = values(i)
      j = i - 1
      do while (j >= 1)
        if (values(j) <= value) exit
        values(j + 1) = values(j)
        j = j - 1
      end do
      values(j + 1) = value
    end do
  end subroutine sort
end program host_fortran
