!> Small dense tensor algebra shared by the material laws: 3x3 determinant and inverse,
!> symmetric tensors between their 6-component storage (xx yy zz xy yz zx, the order of the
!> stress arrays) and 3x3 matrices, the midpoint (Hughes-Winget) update of a tensor increment,
!> and the eigen-decomposition of a symmetric 3x3 matrix. Pure, allocation-free, for the
!> materials' point loops.
module small_tensors
  use kinds, only: wp
  implicit none
  private

  public :: determinant3, inverse3, symmetric_matrix, symmetric_components, midpoint_update, symmetric_eigen

  !> Sweeps of the cyclic Jacobi method at most (it converges quadratically: 4-5 are typical).
  integer, parameter :: jacobi_sweeps = 12

contains

  pure real(wp) function determinant3(m)
    real(wp), intent(in) :: m(3, 3)
    determinant3 = m(1, 1)*(m(2, 2)*m(3, 3) - m(2, 3)*m(3, 2)) - m(1, 2)*(m(2, 1)*m(3, 3) - m(2, 3)*m(3, 1)) &
                   + m(1, 3)*(m(2, 1)*m(3, 2) - m(2, 2)*m(3, 1))
  end function determinant3

  !> The inverse by cofactors (the caller knows m is regular).
  pure function inverse3(m) result(inverse)
    real(wp), intent(in) :: m(3, 3)
    real(wp) :: inverse(3, 3), determinant
    inverse(1, 1) = m(2, 2)*m(3, 3) - m(2, 3)*m(3, 2)
    inverse(1, 2) = m(1, 3)*m(3, 2) - m(1, 2)*m(3, 3)
    inverse(1, 3) = m(1, 2)*m(2, 3) - m(1, 3)*m(2, 2)
    inverse(2, 1) = m(2, 3)*m(3, 1) - m(2, 1)*m(3, 3)
    inverse(2, 2) = m(1, 1)*m(3, 3) - m(1, 3)*m(3, 1)
    inverse(2, 3) = m(1, 3)*m(2, 1) - m(1, 1)*m(2, 3)
    inverse(3, 1) = m(2, 1)*m(3, 2) - m(2, 2)*m(3, 1)
    inverse(3, 2) = m(1, 2)*m(3, 1) - m(1, 1)*m(3, 2)
    inverse(3, 3) = m(1, 1)*m(2, 2) - m(1, 2)*m(2, 1)
    determinant = m(1, 1)*inverse(1, 1) + m(1, 2)*inverse(2, 1) + m(1, 3)*inverse(3, 1)
    inverse = inverse/determinant
  end function inverse3

  !> The 3x3 matrix of a symmetric tensor stored as (xx yy zz xy yz zx).
  pure function symmetric_matrix(tensor) result(matrix)
    real(wp), intent(in) :: tensor(6)
    real(wp) :: matrix(3, 3)
    matrix(1, 1) = tensor(1)
    matrix(2, 2) = tensor(2)
    matrix(3, 3) = tensor(3)
    matrix(1, 2) = tensor(4)
    matrix(2, 1) = tensor(4)
    matrix(2, 3) = tensor(5)
    matrix(3, 2) = tensor(5)
    matrix(3, 1) = tensor(6)
    matrix(1, 3) = tensor(6)
  end function symmetric_matrix

  !> The (xx yy zz xy yz zx) components of the symmetric part of a 3x3 matrix.
  pure function symmetric_components(matrix) result(tensor)
    real(wp), intent(in) :: matrix(3, 3)
    real(wp) :: tensor(6)
    tensor = [matrix(1, 1), matrix(2, 2), matrix(3, 3), 0.5_wp*(matrix(1, 2) + matrix(2, 1)), &
              0.5_wp*(matrix(2, 3) + matrix(3, 2)), 0.5_wp*(matrix(3, 1) + matrix(1, 3))]
  end function symmetric_components

  !> M = (I - L/2)^-1 (I + L/2) for an increment L (3x3): the midpoint rule's update of a
  !> tensor whose rate is L X + X L^T (Hughes & Winget 1980), orthogonal when L is skew.
  pure function midpoint_update(increment) result(update)
    real(wp), intent(in) :: increment(3, 3)
    real(wp) :: update(3, 3)
    real(wp) :: minus(3, 3), plus(3, 3), inverse(3, 3)
    integer :: i, j, k
    minus = -0.5_wp*increment
    plus = 0.5_wp*increment
    do k = 1, 3
      minus(k, k) = minus(k, k) + 1.0_wp
      plus(k, k) = plus(k, k) + 1.0_wp
    end do
    inverse = inverse3(minus)
    ! the 3x3 product written out (an inlined matmul of a function result draws false warnings)
    do j = 1, 3
      do i = 1, 3
        update(i, j) = inverse(i, 1)*plus(1, j) + inverse(i, 2)*plus(2, j) + inverse(i, 3)*plus(3, j)
      end do
    end do
  end function midpoint_update

  !> Eigenvalues and eigenvectors (columns) of a symmetric 3x3 matrix by cyclic Jacobi
  !> rotations (converges quadratically; accurate also for close eigenvalues, where closed
  !> forms lose the vectors). Each rotation in the plane (p, q) changes only rows and columns
  !> p and q, updated in place (Golub & Van Loan, "Matrix Computations", 8.5).
  pure subroutine symmetric_eigen(matrix, values, vectors)
    real(wp), intent(in) :: matrix(3, 3)
    real(wp), intent(out) :: values(3), vectors(3, 3)
    real(wp) :: a(3, 3), theta, t, c, s, scale, apr, aqr, vp, vq, app, aqq, apq
    integer :: sweep, p, q, r, k
    a = matrix
    vectors = 0.0_wp
    vectors(1, 1) = 1.0_wp
    vectors(2, 2) = 1.0_wp
    vectors(3, 3) = 1.0_wp
    scale = max(maxval(abs(matrix)), tiny(1.0_wp))
    do sweep = 1, jacobi_sweeps
      if (abs(a(1, 2)) + abs(a(2, 3)) + abs(a(1, 3)) <= 1.0e-15_wp*scale) exit
      do p = 1, 2
        do q = p + 1, 3
          apq = a(p, q)
          if (abs(apq) <= 1.0e-300_wp) cycle
          app = a(p, p)
          aqq = a(q, q)
          ! the rotation that zeroes a(p, q): tan = t, the smaller root (Numerical Recipes 11.1)
          theta = (aqq - app)/(2.0_wp*apq)
          t = sign(1.0_wp, theta)/(abs(theta) + sqrt(theta*theta + 1.0_wp))
          c = 1.0_wp/sqrt(t*t + 1.0_wp)
          s = t*c
          ! A <- R^T A R, R the identity but R(p,p) = R(q,q) = c, R(p,q) = s, R(q,p) = -s
          r = 6 - p - q
          apr = a(p, r)
          aqr = a(q, r)
          a(p, r) = c*apr - s*aqr
          a(r, p) = a(p, r)
          a(q, r) = s*apr + c*aqr
          a(r, q) = a(q, r)
          a(p, p) = c*c*app - 2.0_wp*s*c*apq + s*s*aqq
          a(q, q) = s*s*app + 2.0_wp*s*c*apq + c*c*aqq
          a(p, q) = 0.0_wp
          a(q, p) = 0.0_wp
          ! V <- V R
          do k = 1, 3
            vp = vectors(k, p)
            vq = vectors(k, q)
            vectors(k, p) = c*vp - s*vq
            vectors(k, q) = s*vp + c*vq
          end do
        end do
      end do
    end do
    values = [a(1, 1), a(2, 2), a(3, 3)]
  end subroutine symmetric_eigen
end module small_tensors
