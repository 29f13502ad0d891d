!> Benchmark of the solid element kernels: nanoseconds per element per call of
!> compute_solid_block on one thread, for a mesh of 100 000 slightly distorted hexahedra of
!> *MAT_PLASTIC_KINEMATIC under a compressive velocity field (plastic after a few cycles).
!> Not a unit test (no pass/fail); build it against the release library, e.g.
!>   gfortran -O3 -march=native -fopenmp -Ibuild/release/mod tests/unit/bench_solid_kernels.f90 \
!>            build/release/lib/libcrashfree.a -lmetis -o build/release/bench_solid_kernels
program bench_solid_kernels
  use, intrinsic :: iso_fortran_env, only: int64, output_unit
  use kinds, only: wp, block_size
  use model, only: model_t
  use material_laws, only: law_plastic_kinematic
  use solid_block, only: solid_block_t, build_solid_blocks, compute_solid_block
  implicit none

  integer, parameter :: cells(3) = [50, 50, 40], cycles = 40
  real(wp), parameter :: time_step = 1.0e-7_wp
  type(model_t) :: model
  real(wp), allocatable :: coordinates(:, :), velocities(:, :)
  integer :: variant, only_variant, status
  character(len=16) :: argument

  ! optional argument: run only variant 1-5 (ELFORM 1 with that IHQ) or 6 (ELFORM 2)
  only_variant = 0
  call get_command_argument(1, argument, status=status)
  if (status == 0 .and. len_trim(argument) > 0) read (argument, *) only_variant
  call make_mesh(model)
  write (output_unit, '(a,i0,a,i0,a)') "solid kernels: ", size(model%solid_part), " hexahedra, ", cycles, &
    " cycles, 1 thread, *MAT_PLASTIC_KINEMATIC"
  do variant = 1, 6
    if (only_variant /= 0 .and. variant /= only_variant) cycle
    select case (variant)
    case (1:5)
      model%sections(1)%element_formulation = 1
      model%parts(1)%hourglass_type = variant
    case default
      model%sections(1)%element_formulation = 2
      model%parts(1)%hourglass_type = 1
    end select
    call run_variant(model)
  end do

contains

  subroutine make_mesh(model)
    type(model_t), intent(out) :: model
    integer :: i, j, k, node, element, nodes_per_line(3)
    real(wp) :: jitter
    nodes_per_line = cells + 1
    allocate (model%coordinates(3, product(nodes_per_line)), model%solid_nodes(8, product(cells)))
    do k = 0, cells(3)
      do j = 0, cells(2)
        do i = 0, cells(1)
          node = 1 + i + nodes_per_line(1)*(j + nodes_per_line(2)*k)
          jitter = 0.1_wp*sin(real(7*i + 13*j + 17*k, wp))
          model%coordinates(:, node) = [real(i, wp) + jitter, real(j, wp) - jitter, real(k, wp) + 0.5_wp*jitter]
        end do
      end do
    end do
    element = 0
    do k = 0, cells(3) - 1
      do j = 0, cells(2) - 1
        do i = 0, cells(1) - 1
          element = element + 1
          node = 1 + i + nodes_per_line(1)*(j + nodes_per_line(2)*k)
          model%solid_nodes(:, element) = [node, node + 1, node + 1 + nodes_per_line(1), node + nodes_per_line(1), &
                                           node + nodes_per_line(1)*nodes_per_line(2), &
                                           node + 1 + nodes_per_line(1)*nodes_per_line(2), &
                                           node + 1 + nodes_per_line(1) + nodes_per_line(1)*nodes_per_line(2), &
                                           node + nodes_per_line(1) + nodes_per_line(1)*nodes_per_line(2)]
        end do
      end do
    end do
    allocate (model%solid_part(element), source=1)
    allocate (model%parts(1), model%sections(1), model%materials(1))
    model%parts(1)%section = 1
    model%parts(1)%material = 1
    model%materials(1)%law = law_plastic_kinematic
    model%materials(1)%density = 7.85e-9_wp
    model%materials(1)%youngs_modulus = 210000.0_wp
    model%materials(1)%poissons_ratio = 0.3_wp
    model%materials(1)%yield_stress = 250.0_wp
    model%materials(1)%tangent_modulus = 2100.0_wp
    model%materials(1)%hardening_beta = 0.5_wp
  end subroutine make_mesh

  subroutine run_variant(model)
    type(model_t), intent(in) :: model
    type(solid_block_t), allocatable :: blocks(:)
    real(wp), allocatable :: corner_force(:, :, :, :)
    real(wp) :: critical, smallest, work, cycle_seconds(cycles), per_element, fastest, median
    integer :: b, cycle_index, critical_element, inverted, node
    integer(int64) :: start, finish, rate

    call build_solid_blocks(model, blocks)
    allocate (corner_force(block_size, 8, 3, size(blocks)))
    coordinates = model%coordinates
    allocate (velocities, mold=coordinates)
    do node = 1, size(coordinates, 2)
      ! compression along z and shear, plus a small non-linear part that excites hourglass modes
      velocities(:, node) = [0.3_wp*coordinates(2, node), 0.1_wp*sin(coordinates(1, node)), &
                             -1.0_wp*coordinates(3, node)]*1000.0_wp
    end do
    work = 0.0_wp
    do cycle_index = 1, cycles
      coordinates = coordinates + time_step*velocities
      smallest = huge(1.0_wp)
      call system_clock(start, rate)
      do b = 1, size(blocks)
        call compute_solid_block(blocks(b), model%materials(1), coordinates, velocities, time_step, &
                                 corner_force(:, :, :, b), critical, critical_element, inverted)
        smallest = min(smallest, critical)
      end do
      call system_clock(finish)
      cycle_seconds(cycle_index) = real(finish - start, wp)/real(rate, wp)
      work = work + smallest
    end do
    ! The machine may be shared: report the fastest cycle and the median.
    per_element = 1.0e9_wp/size(model%solid_part)
    fastest = minval(cycle_seconds)*per_element
    median = median_of(cycle_seconds)*per_element
    write (output_unit, '(a,i0,a,i0,a,f7.1,a,f7.1,a,es10.3,a,f8.5,a)') "  ELFORM ", &
      model%sections(1)%element_formulation, " IHQ ", model%parts(1)%hourglass_type, ": ", fastest, &
      " ns/element/call (fastest cycle), ", median, " (median)   [dt ", work/cycles, &
      ", max plastic strain ", maxval(blocks(1)%history(:, 1, :)), "]"
    deallocate (velocities)
  end subroutine run_variant

  !> Median of a short array (insertion sort of a copy).
  function median_of(values) result(median)
    real(wp), intent(in) :: values(:)
    real(wp) :: median, sorted(size(values)), key
    integer :: i, j
    sorted = values
    do i = 2, size(sorted)
      key = sorted(i)
      j = i - 1
      do while (j >= 1)
        if (sorted(j) <= key) exit
        sorted(j + 1) = sorted(j)
        j = j - 1
      end do
      sorted(j + 1) = key
    end do
    median = sorted((size(sorted) + 1)/2)
  end function median_of
end program bench_solid_kernels
