!> Fully integrated selective-reduced hexahedron, ELFORM 2: the deviatoric part of the rate of
!> deformation at the 2x2x2 Gauss points, its volumetric part from the element mean (mean
!> dilatation / B-bar; Hughes, IJNME 15 (1980) 1413-1418; LS-DYNA Theory Manual, "Fully
!> integrated brick elements"). The stress is updated at each point and the corner forces are
!> the virtual work of the B-bar strain rate,
!>   f_iI = sum_p detJ_p s_ij(p) dN_I/dx_j(p) + (mean(sigma_kk/3) - q) b_iI,
!> with s the deviatoric stress, the mean taken over the element volume and
!> b_iI = sum_p detJ_p dN_I/dx_i(p) (the exact volume derivatives: the 2x2x2 rule integrates
!> them exactly). No hourglass control is needed. These kernels work point by point on a block;
!> the block driver (solid_block) loops over the points.
module hex8_full
  use kinds, only: wp, block_size
  implicit none
  private

  public :: point_velocity_gradient, add_deviatoric_point_forces, add_mean_stress_forces
  public :: add_point_stress_power, corner_force_power, add_point_gram, deviatoric_mode_bound
  public :: add_point_gradient_norm, deviatoric_mode_trace_bound

contains

  !> Velocity gradient at one point, L_ij = sum_I v_iI dN_I/dx_j, stored row by row. Summed
  !> over the velocities relative to node 1's (the same value, as sum_I dN_I/dx_j = 0), so that a
  !> translating element gets exactly L = 0 in every build (hex8_geometry's
  !> hex8_velocity_gradient says why that matters).
  subroutine point_velocity_gradient(nel, dndx, dndy, dndz, vx, vy, vz, gradient)
    integer, intent(in) :: nel
    real(wp), intent(in) :: dndx(block_size, 8), dndy(block_size, 8), dndz(block_size, 8)
    real(wp), intent(in) :: vx(block_size, 8), vy(block_size, 8), vz(block_size, 8)
    real(wp), intent(out) :: gradient(block_size, 9)
    real(wp) :: l11, l12, l13, l21, l22, l23, l31, l32, l33, rx, ry, rz
    integer :: node, i
    do i = 1, nel
      l11 = 0.0_wp; l12 = 0.0_wp; l13 = 0.0_wp
      l21 = 0.0_wp; l22 = 0.0_wp; l23 = 0.0_wp
      l31 = 0.0_wp; l32 = 0.0_wp; l33 = 0.0_wp
      do node = 1, 8
        rx = vx(i, node) - vx(i, 1)
        ry = vy(i, node) - vy(i, 1)
        rz = vz(i, node) - vz(i, 1)
        l11 = l11 + rx*dndx(i, node)
        l12 = l12 + rx*dndy(i, node)
        l13 = l13 + rx*dndz(i, node)
        l21 = l21 + ry*dndx(i, node)
        l22 = l22 + ry*dndy(i, node)
        l23 = l23 + ry*dndz(i, node)
        l31 = l31 + rz*dndx(i, node)
        l32 = l32 + rz*dndy(i, node)
        l33 = l33 + rz*dndz(i, node)
      end do
      gradient(i, 1) = l11
      gradient(i, 2) = l12
      gradient(i, 3) = l13
      gradient(i, 4) = l21
      gradient(i, 5) = l22
      gradient(i, 6) = l23
      gradient(i, 7) = l31
      gradient(i, 8) = l32
      gradient(i, 9) = l33
    end do
  end subroutine point_velocity_gradient

  !> Adds the deviatoric stress forces of one point, detJ s_ij dN_I/dx_j, to the corner forces
  !> and accumulates what the mean-stress term needs: the integral of sigma_kk/3 and the
  !> volume derivatives b_iI = sum_p detJ dN_I/dx_i (both start from zero at the first point).
  subroutine add_deviatoric_point_forces(nel, determinant, dndx, dndy, dndz, stress, corner_force, &
                                         mean_stress_integral, bx, by, bz)
    integer, intent(in) :: nel
    real(wp), intent(in) :: determinant(block_size)
    real(wp), intent(in) :: dndx(block_size, 8), dndy(block_size, 8), dndz(block_size, 8)
    real(wp), intent(in) :: stress(block_size, 6)
    real(wp), intent(inout) :: corner_force(block_size, 8, 3)
    real(wp), intent(inout) :: mean_stress_integral(block_size)
    real(wp), intent(inout) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8)
    real(wp) :: mean, w, s11, s22, s33, s12, s23, s31
    integer :: node, i
    do i = 1, nel
      w = determinant(i)
      mean = (stress(i, 1) + stress(i, 2) + stress(i, 3))/3.0_wp
      mean_stress_integral(i) = mean_stress_integral(i) + w*mean
      s11 = w*(stress(i, 1) - mean)
      s22 = w*(stress(i, 2) - mean)
      s33 = w*(stress(i, 3) - mean)
      s12 = w*stress(i, 4)
      s23 = w*stress(i, 5)
      s31 = w*stress(i, 6)
      do node = 1, 8
        corner_force(i, node, 1) = corner_force(i, node, 1) + s11*dndx(i, node) + s12*dndy(i, node) &
                                   + s31*dndz(i, node)
        corner_force(i, node, 2) = corner_force(i, node, 2) + s12*dndx(i, node) + s22*dndy(i, node) &
                                   + s23*dndz(i, node)
        corner_force(i, node, 3) = corner_force(i, node, 3) + s31*dndx(i, node) + s23*dndy(i, node) &
                                   + s33*dndz(i, node)
      end do
    end do
    ! (a separate lane loop: one loop with both would be too large to vectorize)
    do i = 1, nel
      do node = 1, 8
        bx(i, node) = bx(i, node) + determinant(i)*dndx(i, node)
        by(i, node) = by(i, node) + determinant(i)*dndy(i, node)
        bz(i, node) = bz(i, node) + determinant(i)*dndz(i, node)
      end do
    end do
  end subroutine add_deviatoric_point_forces

  !> Adds the forces of a uniform mean stress (volume-averaged sigma_kk/3 minus the bulk
  !> viscosity), mean_stress b_iI.
  subroutine add_mean_stress_forces(nel, bx, by, bz, mean_stress, corner_force)
    integer, intent(in) :: nel
    real(wp), intent(in) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8)
    real(wp), intent(in) :: mean_stress(block_size)
    real(wp), intent(inout) :: corner_force(block_size, 8, 3)
    integer :: node, i
    do i = 1, nel
      do node = 1, 8
        corner_force(i, node, 1) = corner_force(i, node, 1) + mean_stress(i)*bx(i, node)
        corner_force(i, node, 2) = corner_force(i, node, 2) + mean_stress(i)*by(i, node)
        corner_force(i, node, 3) = corner_force(i, node, 3) + mean_stress(i)*bz(i, node)
      end do
    end do
  end subroutine add_mean_stress_forces

  !> Accumulates what the power of the B-bar forces of one point needs, for a velocity field
  !> whose gradient at the point is `gradient` (row by row): detJ s : L into `deviatoric_power`,
  !> detJ sigma_kk/3 into `mean_stress_integral` and detJ tr L into `trace_integral`. The
  !> power of the element's forces is then deviatoric_power + (mean_stress_integral / V - q)
  !> trace_integral (see the module comment).
  subroutine add_point_stress_power(nel, determinant, gradient, stress, deviatoric_power, &
                                    mean_stress_integral, trace_integral)
    integer, intent(in) :: nel
    real(wp), intent(in) :: determinant(block_size), gradient(block_size, 9), stress(block_size, 6)
    real(wp), intent(inout) :: deviatoric_power(block_size), mean_stress_integral(block_size)
    real(wp), intent(inout) :: trace_integral(block_size)
    real(wp) :: mean, trace
    integer :: i
    do i = 1, nel
      mean = (stress(i, 1) + stress(i, 2) + stress(i, 3))/3.0_wp
      trace = gradient(i, 1) + gradient(i, 5) + gradient(i, 9)
      deviatoric_power(i) = deviatoric_power(i) + determinant(i)*(stress(i, 1)*gradient(i, 1) &
                            + stress(i, 2)*gradient(i, 5) + stress(i, 3)*gradient(i, 9) &
                            + stress(i, 4)*(gradient(i, 2) + gradient(i, 4)) &
                            + stress(i, 5)*(gradient(i, 6) + gradient(i, 8)) &
                            + stress(i, 6)*(gradient(i, 7) + gradient(i, 3)) - mean*trace)
      mean_stress_integral(i) = mean_stress_integral(i) + determinant(i)*mean
      trace_integral(i) = trace_integral(i) + determinant(i)*trace
    end do
  end subroutine add_point_stress_power

  !> Power of the corner forces against the corner velocities, sum_I f_I . v_I.
  subroutine corner_force_power(nel, corner_force, vx, vy, vz, power)
    integer, intent(in) :: nel
    real(wp), intent(in) :: corner_force(block_size, 8, 3)
    real(wp), intent(in) :: vx(block_size, 8), vy(block_size, 8), vz(block_size, 8)
    real(wp), intent(out) :: power(block_size)
    real(wp) :: sum_of_products
    integer :: node, i
    do i = 1, nel
      sum_of_products = 0.0_wp
      do node = 1, 8
        sum_of_products = sum_of_products + corner_force(i, node, 1)*vx(i, node) &
                          + corner_force(i, node, 2)*vy(i, node) + corner_force(i, node, 3)*vz(i, node)
      end do
      power(i) = sum_of_products
    end do
  end subroutine corner_force_power

  !> Accumulates the 8 x 8 Gram matrix sum_p detJ_p sum_k dN_I/dx_k(p) dN_J/dx_k(p) of the
  !> points (upper triangle packed row by row, 36 entries; start from zero), for
  !> deviatoric_mode_bound.
  subroutine add_point_gram(nel, determinant, dndx, dndy, dndz, gram)
    integer, intent(in) :: nel
    real(wp), intent(in) :: determinant(block_size)
    real(wp), intent(in) :: dndx(block_size, 8), dndy(block_size, 8), dndz(block_size, 8)
    real(wp), intent(inout) :: gram(block_size, 36)
    integer :: first, second, k, i
    k = 0
    do first = 1, 8
      do second = first, 8
        k = k + 1
        do i = 1, nel
          gram(i, k) = gram(i, k) + determinant(i)*(dndx(i, first)*dndx(i, second) + dndy(i, first)*dndy(i, second) &
                                                    + dndz(i, first)*dndz(i, second))
        end do
      end do
    end do
  end subroutine add_point_gram

  !> For the stable step (element_time_step): a bound on lambda_max of the element's extra
  !> deviatoric stiffness over the one-point element. With B_p the point gradients and
  !> b = sum_p detJ_p B_p, the deviatoric energy splits exactly into that of the mean strain and
  !> 2 mu sum_p detJ_p |dev sym(sum_I u_I (x) (B_pI - b_I / V))|^2, at most 2 mu u_k^T L u_k
  !> summed over the directions k, L = gram - b b^T / V (the cross terms vanish since
  !> sum_p detJ_p (B_p - b / V) = 0). Returns the largest absolute row sum of L (>= lambda_max).
  subroutine deviatoric_mode_bound(nel, gram, bx, by, bz, volume, bound)
    integer, intent(in) :: nel
    real(wp), intent(in) :: gram(block_size, 36)
    real(wp), intent(in) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8), volume(block_size)
    real(wp), intent(out) :: bound(block_size)
    real(wp) :: row(8), entry, inverse_volume
    integer :: first, second, k, i
    do i = 1, nel
      inverse_volume = 1.0_wp/sign(max(abs(volume(i)), tiny(1.0_wp)), volume(i))
      row = 0.0_wp
      k = 0
      do first = 1, 8
        do second = first, 8
          k = k + 1
          entry = abs(gram(i, k) - (bx(i, first)*bx(i, second) + by(i, first)*by(i, second) &
                                    + bz(i, first)*bz(i, second))*inverse_volume)
          row(first) = row(first) + entry
          if (second /= first) row(second) = row(second) + entry
        end do
      end do
      bound(i) = maxval(row)
    end do
  end subroutine deviatoric_mode_bound

  !> Accumulates sum_p detJ_p sum_I |dN_I/dx(p)|^2 (start from zero), the trace of the Gram
  !> matrix of add_point_gram, for deviatoric_mode_trace_bound.
  subroutine add_point_gradient_norm(nel, determinant, dndx, dndy, dndz, total)
    integer, intent(in) :: nel
    real(wp), intent(in) :: determinant(block_size)
    real(wp), intent(in) :: dndx(block_size, 8), dndy(block_size, 8), dndz(block_size, 8)
    real(wp), intent(inout) :: total(block_size)
    integer :: node, i
    do node = 1, 8
      do i = 1, nel
        total(i) = total(i) + determinant(i)*(dndx(i, node)**2 + dndy(i, node)**2 + dndz(i, node)**2)
      end do
    end do
  end subroutine add_point_gradient_norm

  !> The cheaper bound of deviatoric_mode_bound: lambda_max(L) <= tr L = sum_p detJ_p |B_p|^2 -
  !> |b|^2 / V (L is positive semi-definite; for a cube tr L is 3.5 times lambda_max).
  subroutine deviatoric_mode_trace_bound(nel, total, bx, by, bz, volume, bound)
    integer, intent(in) :: nel
    real(wp), intent(in) :: total(block_size)
    real(wp), intent(in) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8), volume(block_size)
    real(wp), intent(out) :: bound(block_size)
    real(wp) :: norm
    integer :: node, i
    do i = 1, nel
      norm = 0.0_wp
      do node = 1, 8
        norm = norm + bx(i, node)**2 + by(i, node)**2 + bz(i, node)**2
      end do
      bound(i) = max(total(i) - norm/sign(max(abs(volume(i)), tiny(1.0_wp)), volume(i)), 0.0_wp)
    end do
  end subroutine deviatoric_mode_trace_bound
end module hex8_full
