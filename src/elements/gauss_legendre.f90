!> Gauss-Legendre points and weights on [-1, 1], computed (not tabulated) by Newton's method
!> on the Legendre polynomial P_n with the three-term recurrence; exact for polynomials of
!> degree 2n - 1. Used through the shell thickness (NIP 1-10).
module gauss_legendre
  use kinds, only: wp
  implicit none
  private

  public :: gauss_legendre_rule

contains

  !> The n-point rule: points ascending, weights summing to 2.
  pure subroutine gauss_legendre_rule(n, points, weights)
    integer, intent(in) :: n
    real(wp), intent(out) :: points(n), weights(n)
    real(wp), parameter :: pi = acos(-1.0_wp)
    real(wp) :: x, value, derivative, change
    integer :: i, iteration
    do i = 1, (n + 1)/2
      ! Chebyshev-like first guess of the i-th largest root, then Newton
      x = cos(pi*(i - 0.25_wp)/(n + 0.5_wp))
      do iteration = 1, 100
        call legendre(n, x, value, derivative)
        change = value/derivative
        x = x - change
        if (abs(change) <= 4.0_wp*epsilon(1.0_wp)) exit
      end do
      call legendre(n, x, value, derivative)
      points(n + 1 - i) = x
      points(i) = -x
      weights(i) = 2.0_wp/((1.0_wp - x*x)*derivative*derivative)
      weights(n + 1 - i) = weights(i)
    end do
    if (mod(n, 2) == 1) points((n + 1)/2) = 0.0_wp
  contains
    pure subroutine legendre(order, at, p, dp)
      integer, intent(in) :: order
      real(wp), intent(in) :: at
      real(wp), intent(out) :: p, dp
      real(wp) :: previous, older
      integer :: k
      older = 0.0_wp
      previous = 1.0_wp
      p = 1.0_wp
      do k = 1, order
        p = ((2*k - 1)*at*previous - (k - 1)*older)/k
        older = previous
        previous = p
      end do
      ! P_n' = n (x P_n - P_{n-1}) / (x^2 - 1)
      dp = order*(at*p - older)/(at*at - 1.0_wp)
    end subroutine legendre
  end subroutine gauss_legendre_rule
end module gauss_legendre
