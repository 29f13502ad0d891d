!> The transformation rows of the interior particles of every meshfree part of a model, in one
!> sparse row structure: the physical value at particle I is sum_J A_IJ d_J over the nodes J of
!> its row (eq. 16 of the meshfree solids, the same rows for the meshfree shells). Only particles
!> appear in the rows (the Gamma nodes' functions vanish at the particles), and each row sums to
!> one. The solver's walls use single rows (physical positions and velocities, the mass-norm
!> weight of a row); the initial velocities solve A v = v_deck over all rows (BiCGSTAB).
module particle_rows
  use kinds, only: wp
  implicit none
  private

  public :: particle_rows_t, start_particle_rows, append_particle_rows, row_value, row_mass_weight, &
            solve_particle_rows

  !> Rows in compressed form; row r belongs to node `particle(r)`.
  type :: particle_rows_t
    integer :: count = 0                        !< number of rows (particles)
    integer, allocatable :: particle(:)         !< (rows) the node of each row
    integer, allocatable :: offsets(:)          !< (rows + 1) row r: offsets(r) : offsets(r + 1) - 1
    integer, allocatable :: node(:)             !< node of each coefficient
    real(wp), allocatable :: value(:)           !< the coefficient A_IJ
    integer, allocatable :: row_of_node(:)      !< (nodes) its row, 0 for a node that is no particle
  end type particle_rows_t

contains

  !> No rows yet, for a model of `node_count` nodes.
  subroutine start_particle_rows(rows, node_count)
    type(particle_rows_t), intent(out) :: rows
    integer, intent(in) :: node_count
    allocate (rows%particle(0), rows%offsets(1), rows%node(0), rows%value(0), rows%row_of_node(node_count))
    rows%offsets(1) = 1
    rows%row_of_node = 0
  end subroutine start_particle_rows

  !> Append the rows of one meshfree part (set-up only: the arrays grow): row j of the part
  !> belongs to `particles(j)` and holds `values(k)` for `nodes(k)`, k in offsets(j) : offsets(j+1)-1.
  subroutine append_particle_rows(rows, particles, offsets, nodes, values)
    type(particle_rows_t), intent(inout) :: rows
    integer, intent(in) :: particles(:), offsets(:), nodes(:)
    real(wp), intent(in) :: values(:)
    integer :: j, first
    if (size(particles) == 0) return
    first = size(rows%node)
    rows%particle = [rows%particle, particles]
    rows%node = [rows%node, nodes(offsets(1):offsets(size(particles) + 1) - 1)]
    rows%value = [rows%value, values(offsets(1):offsets(size(particles) + 1) - 1)]
    rows%offsets = [rows%offsets, [(first + offsets(j + 1) - offsets(1) + 1, j=1, size(particles))]]
    do j = 1, size(particles)
      rows%row_of_node(particles(j)) = rows%count + j
    end do
    rows%count = rows%count + size(particles)
  end subroutine append_particle_rows

  !> sum_J A_IJ field(:, J) over row `row`: the physical value of a generalized field.
  pure function row_value(rows, row, field) result(value)
    type(particle_rows_t), intent(in) :: rows
    integer, intent(in) :: row
    real(wp), intent(in) :: field(:, :)
    real(wp) :: value(3)
    integer :: k
    value = 0.0_wp
    do k = rows%offsets(row), rows%offsets(row + 1) - 1
      value = value + rows%value(k)*field(:, rows%node(k))
    end do
  end function row_value

  !> sum_J A_IJ^2 / m_J over row `row` (nodes without mass left out): a physical velocity change
  !> dv at the particle made with the smallest change of the generalized velocities in the mass
  !> norm is dv_J = A_IJ dv / (m_J S), S this weight; 1 / S is the particle's effective mass.
  pure function row_mass_weight(rows, row, mass) result(weight)
    type(particle_rows_t), intent(in) :: rows
    integer, intent(in) :: row
    real(wp), intent(in) :: mass(:)
    real(wp) :: weight
    integer :: k
    weight = 0.0_wp
    do k = rows%offsets(row), rows%offsets(row + 1) - 1
      if (mass(rows%node(k)) > 0.0_wp) weight = weight + rows%value(k)**2/mass(rows%node(k))
    end do
  end function row_mass_weight

  !> Generalized values whose physical values are `target` at every particle: solve A x = target
  !> (one system over all rows, each of the three components) by BiCGSTAB with the rows'
  !> diagonals as preconditioner, from x = target, to a residual of `tolerance` times the largest
  !> |target| of the particles. `field` holds the nodal field; its particle entries are replaced.
  !> A node in a row that is no particle keeps its value (moved to the right-hand side).
  !> `converged` false: the residual stayed above the tolerance after `iteration_limit` iterations
  !> (`residual` is the largest row residual reached, relative to the largest |target|).
  subroutine solve_particle_rows(rows, target, tolerance, iteration_limit, field, converged, residual, iterations)
    type(particle_rows_t), intent(in) :: rows
    real(wp), intent(in) :: target(:, :)       !< (3, nodes) wanted physical values at the particles
    real(wp), intent(in) :: tolerance
    integer, intent(in) :: iteration_limit
    real(wp), intent(inout) :: field(:, :)     !< (3, nodes)
    logical, intent(out) :: converged
    real(wp), intent(out) :: residual
    integer, intent(out) :: iterations
    real(wp), allocatable :: diagonal(:), b(:), x(:), r(:), r_hat(:), p(:), v(:), s(:), t(:), p_hat(:), s_hat(:)
    real(wp) :: scale, rho, rho_new, alpha, omega, beta, limit, check(3), denominator
    integer :: n, row, k, component, iteration, column
    converged = .true.
    residual = 0.0_wp
    iterations = 0
    n = rows%count
    if (n == 0) return
    scale = 0.0_wp
    do row = 1, n
      scale = max(scale, maxval(abs(target(:, rows%particle(row)))))
    end do
    if (scale <= 0.0_wp) then
      do row = 1, n
        field(:, rows%particle(row)) = 0.0_wp
      end do
      call known_part_check()
      return
    end if
    allocate (diagonal(n), b(n), x(n), r(n), r_hat(n), p(n), v(n), s(n), t(n), p_hat(n), s_hat(n))
    diagonal = 1.0_wp
    do row = 1, n
      do k = rows%offsets(row), rows%offsets(row + 1) - 1
        if (rows%node(k) == rows%particle(row) .and. rows%value(k) /= 0.0_wp) diagonal(row) = rows%value(k)
      end do
    end do
    limit = 0.1_wp*tolerance*scale
    do component = 1, 3
      ! right-hand side: the target less what nodes that are no particles give
      do row = 1, n
        b(row) = target(component, rows%particle(row))
        do k = rows%offsets(row), rows%offsets(row + 1) - 1
          if (rows%row_of_node(rows%node(k)) == 0) b(row) = b(row) - rows%value(k)*field(component, rows%node(k))
        end do
      end do
      do row = 1, n
        x(row) = target(component, rows%particle(row))
      end do
      call multiply(x, r)
      r = b - r
      if (maxval(abs(r)) <= limit) then
        call store()
        cycle
      end if
      r_hat = r
      rho = 1.0_wp
      alpha = 1.0_wp
      omega = 1.0_wp
      v = 0.0_wp
      p = 0.0_wp
      do iteration = 1, iteration_limit
        iterations = max(iterations, iteration)
        rho_new = dot_product(r_hat, r)
        if (rho_new == 0.0_wp) exit
        beta = (rho_new/rho)*(alpha/omega)
        p = r + beta*(p - omega*v)
        p_hat = p/diagonal
        call multiply(p_hat, v)
        denominator = dot_product(r_hat, v)
        if (denominator == 0.0_wp) exit   ! breakdown: the final check reports the residual
        alpha = rho_new/denominator
        s = r - alpha*v
        if (maxval(abs(s)) <= limit) then
          x = x + alpha*p_hat
          exit
        end if
        s_hat = s/diagonal
        call multiply(s_hat, t)
        if (dot_product(t, t) == 0.0_wp) exit
        omega = dot_product(t, s)/dot_product(t, t)
        x = x + alpha*p_hat + omega*s_hat
        r = s - omega*t
        if (maxval(abs(r)) <= limit .or. omega == 0.0_wp) exit
        rho = rho_new
      end do
      call store()
    end do
    call known_part_check()
  contains
    !> y = A x over the particle columns
    subroutine multiply(vector, product)
      real(wp), intent(in) :: vector(:)
      real(wp), intent(out) :: product(:)
      integer :: i, m
      do i = 1, n
        product(i) = 0.0_wp
        do m = rows%offsets(i), rows%offsets(i + 1) - 1
          column = rows%row_of_node(rows%node(m))
          if (column > 0) product(i) = product(i) + rows%value(m)*vector(column)
        end do
      end do
    end subroutine multiply

    subroutine store()
      integer :: i
      do i = 1, n
        field(component, rows%particle(i)) = x(i)
      end do
    end subroutine store

    !> the residual of the values stored, row by row
    subroutine known_part_check()
      integer :: i
      residual = 0.0_wp
      do i = 1, n
        check = row_value(rows, i, field) - target(:, rows%particle(i))
        if (any(check /= check)) then
          residual = huge(1.0_wp)
        else
          residual = max(residual, maxval(abs(check)))
        end if
      end do
      if (scale > 0.0_wp) residual = residual/scale
      ! (a NaN residual, from a breakdown, is no convergence)
      converged = residual <= tolerance .and. residual == residual
    end subroutine known_part_check
  end subroutine solve_particle_rows
end module particle_rows
