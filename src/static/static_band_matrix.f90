!> Banded matrices of the linear static analysis and their direct solution with LAPACK.
!>
!> Two storages, both LAPACK's:
!> - symmetric positive definite (the stiffness matrix when every essential condition is
!>   eliminated): the upper triangle in `dpbtrf` form, A(i, j) at values(kd + 1 + i - j, j) for
!>   max(1, j - kd) <= i <= j; factored by banded Cholesky (`dpbtrf`, solved with `dpbtrs`; the two
!>   steps of `dpbsv`, kept apart so that the pivots can be inspected before solving);
!> - general (the symmetric indefinite system augmented by Lagrange multipliers): `dgbtrf` form
!>   with kl = ku = kd, A(i, j) at values(2 kd + 1 + i - j, j) and kd extra rows on top for the
!>   fill-in of partial pivoting; factored by banded LU (`dgbtrf`, solved with `dgbtrs`).
!>
!> A singular matrix does not stop LAPACK when round-off keeps its pivots off zero, so the factor
!> is inspected: the pivot of each column is compared with that column's size before the
!> factorization (Cholesky: U_jj^2 / A_jj, the part of the diagonal stiffness left after the
!> earlier columns are eliminated; LU: |U_jj| / max_i |A_ij|). A rigid-body mode leaves a ratio of
!> round-off size (1e-16 to 1e-13); a slender but supported structure keeps ratios of about
!> (thickness / length)^3, far above `singular_pivot_ratio` for any realistic model.
module static_band_matrix
  use kinds, only: wp
  implicit none
  private

  public :: band_matrix_t, create_band_matrix, add_band_entry, add_band_block, band_diagonal, factor_band_matrix
  public :: solve_band_matrix

  !> Pivot ratios below this mark the matrix as numerically singular.
  real(wp), parameter, public :: singular_pivot_ratio = 1.0e-12_wp

  !> A square banded matrix of order n and half bandwidth kd, then its factor.
  type :: band_matrix_t
    integer :: order = 0                      !< n
    integer :: half_bandwidth = 0             !< kd: A(i, j) = 0 for |i - j| > kd
    logical :: symmetric = .true.             !< Cholesky storage (else general LU storage)
    logical :: factored = .false.
    real(wp), allocatable :: values(:, :)     !< LAPACK band storage (see the module comment)
    integer, allocatable :: pivots(:)         !< row interchanges of the LU factorization
    real(wp), allocatable :: column_size(:)   !< A_jj (Cholesky) or max_i |A_ij| (LU), before factoring
  end type band_matrix_t

  interface
    !> LAPACK: Cholesky factorization of a symmetric positive definite band matrix.
    subroutine dpbtrf(uplo, n, kd, ab, ldab, info)
      import :: wp
      character(len=1), intent(in) :: uplo
      integer, intent(in) :: n, kd, ldab
      real(wp), intent(inout) :: ab(ldab, *)
      integer, intent(out) :: info
    end subroutine dpbtrf

    !> LAPACK: solve with the band Cholesky factor of dpbtrf.
    subroutine dpbtrs(uplo, n, kd, nrhs, ab, ldab, b, ldb, info)
      import :: wp
      character(len=1), intent(in) :: uplo
      integer, intent(in) :: n, kd, nrhs, ldab, ldb
      real(wp), intent(in) :: ab(ldab, *)
      real(wp), intent(inout) :: b(ldb, *)
      integer, intent(out) :: info
    end subroutine dpbtrs

    !> LAPACK: LU factorization with partial pivoting of a general band matrix.
    subroutine dgbtrf(m, n, kl, ku, ab, ldab, ipiv, info)
      import :: wp
      integer, intent(in) :: m, n, kl, ku, ldab
      real(wp), intent(inout) :: ab(ldab, *)
      integer, intent(out) :: ipiv(*)
      integer, intent(out) :: info
    end subroutine dgbtrf

    !> LAPACK: solve with the band LU factors of dgbtrf.
    subroutine dgbtrs(trans, n, kl, ku, nrhs, ab, ldab, ipiv, b, ldb, info)
      import :: wp
      character(len=1), intent(in) :: trans
      integer, intent(in) :: n, kl, ku, nrhs, ldab, ldb
      real(wp), intent(in) :: ab(ldab, *)
      integer, intent(in) :: ipiv(*)
      real(wp), intent(inout) :: b(ldb, *)
      integer, intent(out) :: info
    end subroutine dgbtrs
  end interface

contains

  !> A zero matrix of order `order` and half bandwidth `half_bandwidth`, in Cholesky storage
  !> (`symmetric`) or LU storage. `failed` is set when the storage cannot be allocated; `megabytes`
  !> is its size either way (for the message).
  subroutine create_band_matrix(matrix, order, half_bandwidth, symmetric, megabytes, failed)
    type(band_matrix_t), intent(out) :: matrix
    integer, intent(in) :: order, half_bandwidth
    logical, intent(in) :: symmetric
    real(wp), intent(out) :: megabytes
    logical, intent(out) :: failed
    integer :: rows, status

    matrix%order = order
    matrix%half_bandwidth = half_bandwidth
    matrix%symmetric = symmetric
    if (symmetric) then
      rows = half_bandwidth + 1
    else
      rows = 3*half_bandwidth + 1
    end if
    megabytes = 8.0_wp*real(rows, wp)*real(order, wp)/1.0e6_wp
    allocate (matrix%values(rows, order), stat=status)
    failed = status /= 0
    if (failed) return
    matrix%values = 0.0_wp
    allocate (matrix%column_size(order), matrix%pivots(order))
  end subroutine create_band_matrix

  !> A(row, column) += value. For the Cholesky storage only the upper triangle (row <= column) is
  !> kept, so a symmetric contribution is added whole and its lower half is dropped here. The
  !> caller guarantees |row - column| <= kd (the bandwidth is computed from the same couplings).
  pure subroutine add_band_entry(matrix, row, column, value)
    type(band_matrix_t), intent(inout) :: matrix
    integer, intent(in) :: row, column
    real(wp), intent(in) :: value
    if (matrix%symmetric) then
      if (row > column) return
      matrix%values(matrix%half_bandwidth + 1 + row - column, column) = &
        matrix%values(matrix%half_bandwidth + 1 + row - column, column) + value
    else
      matrix%values(2*matrix%half_bandwidth + 1 + row - column, column) = &
        matrix%values(2*matrix%half_bandwidth + 1 + row - column, column) + value
    end if
  end subroutine add_band_entry

  !> A(equations(a), equations(b)) += local(a, b) for every pair whose equations are both > 0 (a
  !> dense symmetric block scattered at once; in Cholesky storage only its upper triangle is kept).
  !> Exact zeros are skipped: a block gathered over the union of several points' nodes holds
  !> exact zeros between nodes that share no point, and those may lie outside the band.
  pure subroutine add_band_block(matrix, equations, local)
    type(band_matrix_t), intent(inout) :: matrix
    integer, intent(in) :: equations(:)
    real(wp), intent(in) :: local(:, :)
    integer :: a, b, row, column, offset

    if (matrix%symmetric) then
      offset = matrix%half_bandwidth + 1
    else
      offset = 2*matrix%half_bandwidth + 1
    end if
    do b = 1, size(equations)
      column = equations(b)
      if (column == 0) cycle
      do a = 1, size(equations)
        row = equations(a)
        if (row == 0) cycle
        if (matrix%symmetric .and. row > column) cycle
        if (local(a, b) == 0.0_wp) cycle
        matrix%values(offset + row - column, column) = matrix%values(offset + row - column, column) + local(a, b)
      end do
    end do
  end subroutine add_band_block

  !> A(j, j) of a matrix not yet factored.
  pure function band_diagonal(matrix, j) result(value)
    type(band_matrix_t), intent(in) :: matrix
    integer, intent(in) :: j
    real(wp) :: value
    if (matrix%symmetric) then
      value = matrix%values(matrix%half_bandwidth + 1, j)
    else
      value = matrix%values(2*matrix%half_bandwidth + 1, j)
    end if
  end function band_diagonal

  !> Factor the matrix in place. `weakest_column` is the column with the smallest pivot ratio (see
  !> the module comment) and `pivot_ratio` that ratio; `singular` is set when LAPACK met a zero or
  !> negative pivot (then `weakest_column` is the column where it stopped and the ratio is 0) or
  !> the smallest ratio is below `singular_pivot_ratio`.
  subroutine factor_band_matrix(matrix, singular, weakest_column, pivot_ratio)
    type(band_matrix_t), intent(inout) :: matrix
    logical, intent(out) :: singular
    integer, intent(out) :: weakest_column
    real(wp), intent(out) :: pivot_ratio
    integer :: n, kd, info, j, diagonal_row
    real(wp) :: ratio

    n = matrix%order
    kd = matrix%half_bandwidth
    weakest_column = 0
    pivot_ratio = huge(1.0_wp)
    singular = .false.
    if (n == 0) return
    if (matrix%symmetric) then
      matrix%column_size = matrix%values(kd + 1, :)
      call dpbtrf("U", n, kd, matrix%values, size(matrix%values, 1), info)
      diagonal_row = kd + 1
    else
      do j = 1, n
        matrix%column_size(j) = maxval(abs(matrix%values(kd + 1:3*kd + 1, j)))
      end do
      call dgbtrf(n, n, kd, kd, matrix%values, size(matrix%values, 1), matrix%pivots, info)
      diagonal_row = 2*kd + 1
    end if
    if (info > 0) then
      singular = .true.
      weakest_column = info
      pivot_ratio = 0.0_wp
      return
    end if
    do j = 1, n
      if (matrix%column_size(j) > 0.0_wp) then
        if (matrix%symmetric) then
          ratio = matrix%values(diagonal_row, j)**2/matrix%column_size(j)
        else
          ratio = abs(matrix%values(diagonal_row, j))/matrix%column_size(j)
        end if
      else
        ratio = 0.0_wp
      end if
      if (ratio < pivot_ratio) then
        pivot_ratio = ratio
        weakest_column = j
      end if
    end do
    singular = pivot_ratio < singular_pivot_ratio
    matrix%factored = .not. singular
  end subroutine factor_band_matrix

  !> Overwrite `right_hand_side` with the solution of A x = b, A factored by factor_band_matrix.
  subroutine solve_band_matrix(matrix, right_hand_side)
    type(band_matrix_t), intent(in) :: matrix
    real(wp), intent(inout) :: right_hand_side(:)
    integer :: info
    if (matrix%order == 0 .or. .not. matrix%factored) return
    if (matrix%symmetric) then
      call dpbtrs("U", matrix%order, matrix%half_bandwidth, 1, matrix%values, size(matrix%values, 1), &
                  right_hand_side, matrix%order, info)
    else
      call dgbtrs("N", matrix%order, matrix%half_bandwidth, matrix%half_bandwidth, 1, matrix%values, &
                  size(matrix%values, 1), matrix%pivots, right_hand_side, matrix%order, info)
    end if
  end subroutine solve_band_matrix
end module static_band_matrix
