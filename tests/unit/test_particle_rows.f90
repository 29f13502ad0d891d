!> Unit tests of the particles' transformation rows (particle_rows): the rows of two parts
!> appended into one structure, a row's physical value and mass-norm weight, and the solve
!> A x = target of the initial velocities (BiCGSTAB): a quadratic field on a chain of particles
!> whose end rows reach nodes that are no particles is matched to 1e-12, a linear one needs no
!> iteration, and a singular system is reported as not converged.
program test_particle_rows
  use kinds, only: wp
  use particle_rows, only: particle_rows_t, start_particle_rows, append_particle_rows, row_value, row_mass_weight, &
                           solve_particle_rows
  use testing, only: test_suite_t, check, check_close, finish_suite
  implicit none

  type(test_suite_t) :: suite

  suite%name = "particle_rows"
  call test_chain()
  call test_singular_rows()
  call finish_suite(suite)

contains

  !> Nodes 1 .. 22 at x = 0 .. 21; particles 2 .. 21, rows 0.25 / 0.5 / 0.25 of the neighbours
  !> (sum one, linear fields reproduced), appended as two parts (2 .. 11 and 12 .. 21).
  subroutine test_chain()
    type(particle_rows_t) :: rows
    integer, parameter :: node_count = 22
    integer :: particles(10), offsets(11), nodes(30), j, k, node, iterations
    real(wp) :: values(30), target(3, node_count), field(3, node_count), mass(node_count), x
    real(wp) :: residual, largest
    logical :: converged
    call start_particle_rows(rows, node_count)
    do k = 0, 1
      do j = 1, 10
        node = 10*k + j + 1
        particles(j) = node
        offsets(j) = 3*(j - 1) + 1
        nodes(3*j - 2:3*j) = [node - 1, node, node + 1]
        values(3*j - 2:3*j) = [0.25_wp, 0.5_wp, 0.25_wp]
      end do
      offsets(11) = 31
      call append_particle_rows(rows, particles, offsets, nodes, values)
    end do
    call check(suite, "20 rows, nodes 1 and 22 are no particles", rows%count == 20 .and. &
               rows%row_of_node(1) == 0 .and. rows%row_of_node(22) == 0 .and. rows%row_of_node(12) == 11 .and. &
               rows%particle(20) == 21 .and. rows%offsets(21) == 61)
    do node = 1, node_count
      mass(node) = real(node, wp)
      x = real(node - 1, wp)
      target(:, node) = [x, 2.0_wp*x + 1.0_wp, -x]
    end do
    field = target
    call check_close(suite, "row value of a linear field", row_value(rows, 5, field), &
                     target(:, 6), rel=1.0e-15_wp)
    call check_close(suite, "mass-norm weight of a row", row_mass_weight(rows, 5, mass), &
                     0.0625_wp/5.0_wp + 0.25_wp/6.0_wp + 0.0625_wp/7.0_wp, rel=1.0e-15_wp)
    call solve_particle_rows(rows, target, 1.0e-12_wp, 100, field, converged, residual, iterations)
    call check(suite, "a linear field needs no iteration", converged .and. iterations == 0)
    ! a quadratic field: the generalized values differ from it
    do node = 1, node_count
      x = real(node - 1, wp)
      target(:, node) = [x*x, 3.0_wp - 0.1_wp*x*x, 0.5_wp*x*(21.0_wp - x)]
    end do
    field = target
    call solve_particle_rows(rows, target, 1.0e-12_wp, 500, field, converged, residual, iterations)
    largest = 0.0_wp
    do j = 1, rows%count
      largest = max(largest, maxval(abs(row_value(rows, j, field) - target(:, rows%particle(j)))))
    end do
    call check(suite, "a quadratic field converges", converged .and. iterations > 0)
    call check_close(suite, "A x = target at every particle", largest/maxval(abs(target)), 0.0_wp, thr=1.0e-12_wp)
    call check(suite, "nodes that are no particles keep their values", &
               all(field(:, 1) == target(:, 1)) .and. all(field(:, 22) == target(:, 22)))
    call check(suite, "the generalized values differ from the field", &
               maxval(abs(field(:, 2:21) - target(:, 2:21))) > 0.1_wp)
  end subroutine test_chain

  !> Two particles with the same row and different targets: no solution.
  subroutine test_singular_rows()
    type(particle_rows_t) :: rows
    real(wp) :: target(3, 2), field(3, 2), residual
    integer :: iterations
    logical :: converged
    call start_particle_rows(rows, 2)
    call append_particle_rows(rows, [1, 2], [1, 3, 5], [1, 2, 1, 2], [0.5_wp, 0.5_wp, 0.5_wp, 0.5_wp])
    target(:, 1) = 1.0_wp
    target(:, 2) = -1.0_wp
    field = target
    call solve_particle_rows(rows, target, 1.0e-12_wp, 50, field, converged, residual, iterations)
    call check(suite, "a singular system is not converged", .not. converged .and. residual > 1.0e-3_wp)
  end subroutine test_singular_rows
end program test_particle_rows
