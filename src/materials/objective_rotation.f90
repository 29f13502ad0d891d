!> Objective (Jaumann) rotation of stress-like state over one time step, on a block of lanes.
!>
!> The Jaumann rate sigma_dot = sigma_jaumann + W sigma - sigma W is integrated by rotating the
!> state with the incremental rotation of the spin, R = (I - Omega/2)^-1 (I + Omega/2),
!> Omega = W dt (Hughes & Winget, IJNME 15 (1980) 1862-1867). LS-DYNA writes the same Jaumann
!> update to first order, sigma + (Omega sigma - sigma Omega) (LS-DYNA Theory Manual, "Solid
!> elements", stress update); both agree to O(Omega^2), and R being exactly orthogonal keeps
!> the invariants of the stress exactly unchanged under a rigid rotation. With the velocity
!> gradient taken at the mid-step configuration (as the elements do) a rigid rotation of
!> angle theta per step gives |Omega| = 2 tan(theta/2), for which R is exactly the rotation
!> by theta.
!>
!> Symmetric tensors are stored as (block_size, 6) in the order xx, yy, zz, xy, yz, zx;
!> rotations as (block_size, 9) row by row: R11, R12, R13, R21, ..., R33.
module objective_rotation
  use kinds, only: wp, block_size
  implicit none
  private

  public :: incremental_rotation, rotate_symmetric_tensors, rotate_vectors

contains

  !> Incremental rotation of each lane from its spin increment, given as the axial vector w of
  !> Omega = W dt (Omega x = w cross x): R = I + f (Omega + Omega^2/2), f = 4/(4 + |w|^2),
  !> the closed form of the Cayley transform.
  subroutine incremental_rotation(nel, spin_increment, rotation)
    integer, intent(in) :: nel
    real(wp), intent(in) :: spin_increment(block_size, 3)
    real(wp), intent(out) :: rotation(block_size, 9)
    real(wp) :: w1, w2, w3, squared, factor, half_factor
    integer :: i
    do i = 1, nel
      w1 = spin_increment(i, 1)
      w2 = spin_increment(i, 2)
      w3 = spin_increment(i, 3)
      squared = w1*w1 + w2*w2 + w3*w3
      factor = 4.0_wp/(4.0_wp + squared)
      half_factor = 0.5_wp*factor
      ! Omega^2 = w w^T - |w|^2 I
      rotation(i, 1) = 1.0_wp + half_factor*(w1*w1 - squared)
      rotation(i, 2) = -factor*w3 + half_factor*w1*w2
      rotation(i, 3) = factor*w2 + half_factor*w1*w3
      rotation(i, 4) = factor*w3 + half_factor*w1*w2
      rotation(i, 5) = 1.0_wp + half_factor*(w2*w2 - squared)
      rotation(i, 6) = -factor*w1 + half_factor*w2*w3
      rotation(i, 7) = -factor*w2 + half_factor*w1*w3
      rotation(i, 8) = factor*w1 + half_factor*w2*w3
      rotation(i, 9) = 1.0_wp + half_factor*(w3*w3 - squared)
    end do
  end subroutine incremental_rotation

  !> tensor <- R tensor R^T for symmetric tensors (stress, back stress).
  subroutine rotate_symmetric_tensors(nel, rotation, tensor)
    integer, intent(in) :: nel
    real(wp), intent(in) :: rotation(block_size, 9)
    real(wp), intent(inout) :: tensor(block_size, 6)
    real(wp) :: s11, s22, s33, s12, s23, s31
    real(wp) :: t11, t12, t13, t21, t22, t23, t31, t32, t33
    integer :: i
    do i = 1, nel
      s11 = tensor(i, 1)
      s22 = tensor(i, 2)
      s33 = tensor(i, 3)
      s12 = tensor(i, 4)
      s23 = tensor(i, 5)
      s31 = tensor(i, 6)
      ! T = R S
      t11 = rotation(i, 1)*s11 + rotation(i, 2)*s12 + rotation(i, 3)*s31
      t12 = rotation(i, 1)*s12 + rotation(i, 2)*s22 + rotation(i, 3)*s23
      t13 = rotation(i, 1)*s31 + rotation(i, 2)*s23 + rotation(i, 3)*s33
      t21 = rotation(i, 4)*s11 + rotation(i, 5)*s12 + rotation(i, 6)*s31
      t22 = rotation(i, 4)*s12 + rotation(i, 5)*s22 + rotation(i, 6)*s23
      t23 = rotation(i, 4)*s31 + rotation(i, 5)*s23 + rotation(i, 6)*s33
      t31 = rotation(i, 7)*s11 + rotation(i, 8)*s12 + rotation(i, 9)*s31
      t32 = rotation(i, 7)*s12 + rotation(i, 8)*s22 + rotation(i, 9)*s23
      t33 = rotation(i, 7)*s31 + rotation(i, 8)*s23 + rotation(i, 9)*s33
      ! S' = T R^T
      tensor(i, 1) = t11*rotation(i, 1) + t12*rotation(i, 2) + t13*rotation(i, 3)
      tensor(i, 2) = t21*rotation(i, 4) + t22*rotation(i, 5) + t23*rotation(i, 6)
      tensor(i, 3) = t31*rotation(i, 7) + t32*rotation(i, 8) + t33*rotation(i, 9)
      tensor(i, 4) = t11*rotation(i, 4) + t12*rotation(i, 5) + t13*rotation(i, 6)
      tensor(i, 5) = t21*rotation(i, 7) + t22*rotation(i, 8) + t23*rotation(i, 9)
      tensor(i, 6) = t31*rotation(i, 1) + t32*rotation(i, 2) + t33*rotation(i, 3)
    end do
  end subroutine rotate_symmetric_tensors

  !> vector <- R vector for `count` vectors per lane stored as vectors(block_size, 3, count)
  !> (the accumulated hourglass forces of the stiffness forms rotate with the element).
  subroutine rotate_vectors(nel, count, rotation, vectors)
    integer, intent(in) :: nel, count
    real(wp), intent(in) :: rotation(block_size, 9)
    real(wp), intent(inout) :: vectors(block_size, 3, count)
    real(wp) :: a1, a2, a3
    integer :: i, k
    do k = 1, count
      do i = 1, nel
        a1 = vectors(i, 1, k)
        a2 = vectors(i, 2, k)
        a3 = vectors(i, 3, k)
        vectors(i, 1, k) = rotation(i, 1)*a1 + rotation(i, 2)*a2 + rotation(i, 3)*a3
        vectors(i, 2, k) = rotation(i, 4)*a1 + rotation(i, 5)*a2 + rotation(i, 6)*a3
        vectors(i, 3, k) = rotation(i, 7)*a1 + rotation(i, 8)*a2 + rotation(i, 9)*a3
      end do
    end do
  end subroutine rotate_vectors
end module objective_rotation
