!> One-point (uniform strain) hexahedron, ELFORM 1: corner forces from the element stress and
!> the hourglass control forces, on a block of elements (Flanagan & Belytschko, IJNME 17 (1981)
!> 679-706; LS-DYNA Theory Manual, "Solid elements" and "Hourglass control").
!>
!> Stress divergence: f_iI = (sigma_ij - q delta_ij) b_jI with b the exact volume derivatives at
!> the end-of-step configuration and q the bulk viscosity. The sum over I vanishes
!> (sum_I b_jI = 0) and so does the moment (sum_I x_kI b_jI = V delta_jk, sigma symmetric).
!>
!> Hourglass control. With the base vectors h_alpha (alpha = 1..4: eta zeta, zeta xi, xi eta,
!> xi eta zeta at the nodes) the shape vectors are
!>   IHQ 1      gamma_alpha = h_alpha                               (LS-DYNA standard form)
!>   IHQ 2, 4   gamma_alphaI = h_alphaI - (h_alpha . x_i) dN_I/dx_i(0)  (one-point Jacobian at
!>              the element centre; "volume" V0 = 8 det J(0))
!>   IHQ 3, 5   gamma_alphaI = h_alphaI - (h_alpha . x_i) b_iI / V      (exact volume)
!> For IHQ 2-5, sum_I gamma_alphaI x_jI = 0 and sum_I gamma_alphaI = 0 (Flanagan & Belytschko's
!> orthogonality), so a velocity field linear in the coordinates has zero hourglass velocity
!> q_ialpha = sum_I v_iI gamma_alphaI, and the hourglass forces f_iI = sum_alpha Q_ialpha
!> gamma_alphaI carry neither resultant nor moment. IHQ 1 has no resultant, but it is orthogonal
!> to linear fields only on parallelepipeds, so on distorted elements it resists uniform strain
!> and its forces have a moment.
!>   viscous (IHQ 1, 2, 3):   Q_ialpha = a_h q_ialpha,  a_h = QM rho c V^(2/3) / 4
!>                            (the scaling of the LS-DYNA Theory Manual's viscous form)
!>   stiffness (IHQ 4, 5):    Q_ialpha(n+1) = R Q_ialpha(n) + k dt q_ialpha,
!>                            k = QM (lambda + 2 mu) (b_iI b_iI) / (3 V)
!> For the stiffness we use QM times (rho V / 8) omega^2 with the uniform-strain estimate of the
!> highest frequency omega^2 = 8 (lambda + 2 mu) b_iI b_iI / (3 rho V^2) (Flanagan & Belytschko's
!> bound has this form; for a cube of side h it gives omega = 2c/h, the critical step h/c), so
!> that k = QM (lambda + 2 mu) h / 2 for a cube; the Theory Manual gives the (lambda + 2 mu)
!> scaling but we have not checked LS-DYNA's constant against it. The accumulated Q rotate with
!> the element (R the incremental rotation of the spin). Hourglass energy is the work of the
!> hourglass forces (solid_block integrates it in the central-difference sense).
!> rho is the current density (mass / current volume), c = sqrt((lambda + 2 mu) / rho_block).
module hex8_one_point
  use kinds, only: wp, block_size
  use hex8_geometry, only: node_xi, node_eta, node_zeta
  use objective_rotation, only: rotate_vectors
  implicit none
  private

  public :: one_point_corner_forces, hourglass_shape_vectors, hourglass_viscous_forces
  public :: hourglass_stiffness_forces, one_point_force_powers, previous_hourglass_velocities, hourglass_power
  public :: hourglass_mode_bounds, standard_hourglass_overlap

  !> Hourglass base vectors h_alpha(I) (rows: eta zeta, zeta xi, xi eta, xi eta zeta).
  real(wp), parameter, public :: hourglass_base(8, 4) = reshape([ &
                                 node_eta*node_zeta, node_zeta*node_xi, node_xi*node_eta, &
                                 node_xi*node_eta*node_zeta], [8, 4])

contains

  !> Corner forces of each element, overwriting lanes 1..nel:
  !>   corner_force(:, I, i) = sum_j (sigma_ij - q delta_ij) b_jI + sum_alpha Q_ialpha gamma_alphaI
  !> (stress divergence with bulk viscosity, plus the generalized hourglass forces Q stored as
  !> generalized(:, i + 3 (alpha - 1))). Written in one pass, as the corner forces go to memory.
  subroutine one_point_corner_forces(nel, bx, by, bz, stress, bulk_viscosity, gamma, generalized, corner_force)
    integer, intent(in) :: nel
    real(wp), intent(in) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8)
    real(wp), intent(in) :: stress(block_size, 6), bulk_viscosity(block_size)
    real(wp), intent(in) :: gamma(block_size, 8, 4), generalized(block_size, 12)
    real(wp), intent(inout) :: corner_force(block_size, 8, 3)
    ! Voigt position of stress row `component`, columns x, y, z
    integer, parameter :: row(3, 3) = reshape([1, 4, 6, 4, 2, 5, 6, 5, 3], [3, 3])
    real(wp) :: sx, sy, sz, g1, g2, g3, g4
    integer :: node, i, component
    ! one component at a time keeps the lane loop small enough to vectorize
    do component = 1, 3
      do i = 1, nel
        sx = stress(i, row(1, component))
        sy = stress(i, row(2, component))
        sz = stress(i, row(3, component))
        if (component == 1) sx = sx - bulk_viscosity(i)
        if (component == 2) sy = sy - bulk_viscosity(i)
        if (component == 3) sz = sz - bulk_viscosity(i)
        g1 = generalized(i, component)
        g2 = generalized(i, component + 3)
        g3 = generalized(i, component + 6)
        g4 = generalized(i, component + 9)
        do node = 1, 8
          corner_force(i, node, component) = sx*bx(i, node) + sy*by(i, node) + sz*bz(i, node) &
                                             + g1*gamma(i, node, 1) + g2*gamma(i, node, 2) &
                                             + g3*gamma(i, node, 3) + g4*gamma(i, node, 4)
        end do
      end do
    end do
  end subroutine one_point_corner_forces

  !> Power against v(n+1/2) of the stress-divergence forces (sigma - q I) b of this call
  !> (new_power, b at x(n+1)) and of the previous call (old_power, with the previous stress and
  !> q and b at x(n) = x(n+1) - dt v). The sums G = sum_I v_I (x) b_I at x(n) need no second
  !> geometry: along x(s) = x(n+1) - s dt v the volume derivatives are quadratic in s, and the
  !> identity sum_I v_jI b_kI(v) = V(v) delta_jk (b and V of the "velocity hexahedron") gives
  !>   G(n) = 2 G(n+1/2) - G(n+1) + dt^2 V(v) I / 2,   V(n) = V(n+1) - dt tr G(n+1/2) - dt^3 V(v) / 4
  !> with G(n+1/2) = V(n+1/2) L(n+1/2) from the mid-step kinematics. G(n) (row by row) and V(n)
  !> are returned for the hourglass power of the previous call.
  subroutine one_point_force_powers(nel, time_step, bx, by, bz, volume, vx, vy, vz, mid_gradient, mid_volume, &
                                    velocity_volume, old_stress, old_bulk_viscosity, new_stress, &
                                    new_bulk_viscosity, old_gradient_sum, old_volume, old_power, new_power)
    integer, intent(in) :: nel
    real(wp), intent(in) :: time_step
    real(wp), intent(in) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8), volume(block_size)
    real(wp), intent(in) :: vx(block_size, 8), vy(block_size, 8), vz(block_size, 8)
    real(wp), intent(in) :: mid_gradient(block_size, 9), mid_volume(block_size), velocity_volume(block_size)
    real(wp), intent(in) :: old_stress(block_size, 6), old_bulk_viscosity(block_size)
    real(wp), intent(in) :: new_stress(block_size, 6), new_bulk_viscosity(block_size)
    real(wp), intent(out) :: old_gradient_sum(block_size, 9), old_volume(block_size)
    real(wp), intent(out) :: old_power(block_size), new_power(block_size)
    real(wp) :: g11, g12, g13, g21, g22, g23, g31, g32, g33, diagonal
    real(wp) :: o11, o12, o13, o21, o22, o23, o31, o32, o33
    integer :: node, i
    do i = 1, nel
      g11 = 0.0_wp; g12 = 0.0_wp; g13 = 0.0_wp
      g21 = 0.0_wp; g22 = 0.0_wp; g23 = 0.0_wp
      g31 = 0.0_wp; g32 = 0.0_wp; g33 = 0.0_wp
      do node = 1, 8
        g11 = g11 + vx(i, node)*bx(i, node)
        g12 = g12 + vx(i, node)*by(i, node)
        g13 = g13 + vx(i, node)*bz(i, node)
        g21 = g21 + vy(i, node)*bx(i, node)
        g22 = g22 + vy(i, node)*by(i, node)
        g23 = g23 + vy(i, node)*bz(i, node)
        g31 = g31 + vz(i, node)*bx(i, node)
        g32 = g32 + vz(i, node)*by(i, node)
        g33 = g33 + vz(i, node)*bz(i, node)
      end do
      new_power(i) = (new_stress(i, 1) - new_bulk_viscosity(i))*g11 + (new_stress(i, 2) - new_bulk_viscosity(i))*g22 &
                     + (new_stress(i, 3) - new_bulk_viscosity(i))*g33 + new_stress(i, 4)*(g12 + g21) &
                     + new_stress(i, 5)*(g23 + g32) + new_stress(i, 6)*(g31 + g13)
      diagonal = 0.5_wp*time_step**2*velocity_volume(i)
      o11 = 2.0_wp*mid_volume(i)*mid_gradient(i, 1) - g11 + diagonal
      o12 = 2.0_wp*mid_volume(i)*mid_gradient(i, 2) - g12
      o13 = 2.0_wp*mid_volume(i)*mid_gradient(i, 3) - g13
      o21 = 2.0_wp*mid_volume(i)*mid_gradient(i, 4) - g21
      o22 = 2.0_wp*mid_volume(i)*mid_gradient(i, 5) - g22 + diagonal
      o23 = 2.0_wp*mid_volume(i)*mid_gradient(i, 6) - g23
      o31 = 2.0_wp*mid_volume(i)*mid_gradient(i, 7) - g31
      o32 = 2.0_wp*mid_volume(i)*mid_gradient(i, 8) - g32
      o33 = 2.0_wp*mid_volume(i)*mid_gradient(i, 9) - g33 + diagonal
      old_power(i) = (old_stress(i, 1) - old_bulk_viscosity(i))*o11 + (old_stress(i, 2) - old_bulk_viscosity(i))*o22 &
                     + (old_stress(i, 3) - old_bulk_viscosity(i))*o33 + old_stress(i, 4)*(o12 + o21) &
                     + old_stress(i, 5)*(o23 + o32) + old_stress(i, 6)*(o31 + o13)
      old_gradient_sum(i, 1) = o11
      old_gradient_sum(i, 2) = o12
      old_gradient_sum(i, 3) = o13
      old_gradient_sum(i, 4) = o21
      old_gradient_sum(i, 5) = o22
      old_gradient_sum(i, 6) = o23
      old_gradient_sum(i, 7) = o31
      old_gradient_sum(i, 8) = o32
      old_gradient_sum(i, 9) = o33
      old_volume(i) = volume(i) - time_step*mid_volume(i)*(mid_gradient(i, 1) + mid_gradient(i, 5) + mid_gradient(i, 9)) &
                      - 0.25_wp*time_step**3*velocity_volume(i)
    end do
  end subroutine one_point_force_powers

  !> Hourglass velocities q_ialpha = sum_I v_iI gamma_alphaI(n) with the shape vectors of the
  !> previous configuration x(n) = x(n+1) - dt v, for the power of the previous call's hourglass
  !> forces, without forming gamma(n): with p = h_alpha . x(n) and h_alpha . v,
  !>   IHQ 1      q = h_alpha . v
  !>   IHQ 3, 5   q = h_alpha . v - G(n) p / V(n)          (G(n), V(n) from one_point_force_powers)
  !>   IHQ 2, 4   q = h_alpha . v - Jv (8 J(n))^-1 p,  Jv_ia = sum_I v_iI xi_aI, 8 J(n)_ka = sum_I x_kI(n) xi_aI
  subroutine previous_hourglass_velocities(nel, hourglass_type, time_step, x, y, z, vx, vy, vz, &
                                           old_gradient_sum, old_volume, velocity)
    integer, intent(in) :: nel, hourglass_type
    real(wp), intent(in) :: time_step
    real(wp), intent(in) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp), intent(in) :: vx(block_size, 8), vy(block_size, 8), vz(block_size, 8)
    real(wp), intent(in) :: old_gradient_sum(block_size, 9), old_volume(block_size)
    real(wp), intent(out) :: velocity(block_size, 12)
    real(wp) :: mapping(block_size, 9)
    real(wp) :: hvx, hvy, hvz, px, py, pz
    real(wp) :: j11, j12, j13, j21, j22, j23, j31, j32, j33, i11, i12, i13, i21, i22, i23, i31, i32, i33
    real(wp) :: v11, v12, v13, v21, v22, v23, v31, v32, v33, scale, xn, yn, zn
    integer :: node, mode, i

    ! the 3 x 3 map from p to the correction of q, row by row
    select case (hourglass_type)
    case (2, 4)
      do i = 1, nel
        j11 = 0.0_wp; j12 = 0.0_wp; j13 = 0.0_wp; j21 = 0.0_wp; j22 = 0.0_wp; j23 = 0.0_wp
        j31 = 0.0_wp; j32 = 0.0_wp; j33 = 0.0_wp
        v11 = 0.0_wp; v12 = 0.0_wp; v13 = 0.0_wp; v21 = 0.0_wp; v22 = 0.0_wp; v23 = 0.0_wp
        v31 = 0.0_wp; v32 = 0.0_wp; v33 = 0.0_wp
        do node = 1, 8
          xn = x(i, node) - time_step*vx(i, node)
          yn = y(i, node) - time_step*vy(i, node)
          zn = z(i, node) - time_step*vz(i, node)
          j11 = j11 + xn*node_xi(node)
          j12 = j12 + xn*node_eta(node)
          j13 = j13 + xn*node_zeta(node)
          j21 = j21 + yn*node_xi(node)
          j22 = j22 + yn*node_eta(node)
          j23 = j23 + yn*node_zeta(node)
          j31 = j31 + zn*node_xi(node)
          j32 = j32 + zn*node_eta(node)
          j33 = j33 + zn*node_zeta(node)
          v11 = v11 + vx(i, node)*node_xi(node)
          v12 = v12 + vx(i, node)*node_eta(node)
          v13 = v13 + vx(i, node)*node_zeta(node)
          v21 = v21 + vy(i, node)*node_xi(node)
          v22 = v22 + vy(i, node)*node_eta(node)
          v23 = v23 + vy(i, node)*node_zeta(node)
          v31 = v31 + vz(i, node)*node_xi(node)
          v32 = v32 + vz(i, node)*node_eta(node)
          v33 = v33 + vz(i, node)*node_zeta(node)
        end do
        i11 = j22*j33 - j23*j32
        i12 = j13*j32 - j12*j33
        i13 = j12*j23 - j13*j22
        i21 = j23*j31 - j21*j33
        i22 = j11*j33 - j13*j31
        i23 = j13*j21 - j11*j23
        i31 = j21*j32 - j22*j31
        i32 = j12*j31 - j11*j32
        i33 = j11*j22 - j12*j21
        scale = j11*i11 + j12*i21 + j13*i31
        scale = 1.0_wp/sign(max(abs(scale), tiny(1.0_wp)), scale)
        mapping(i, 1) = (v11*i11 + v12*i21 + v13*i31)*scale
        mapping(i, 2) = (v11*i12 + v12*i22 + v13*i32)*scale
        mapping(i, 3) = (v11*i13 + v12*i23 + v13*i33)*scale
        mapping(i, 4) = (v21*i11 + v22*i21 + v23*i31)*scale
        mapping(i, 5) = (v21*i12 + v22*i22 + v23*i32)*scale
        mapping(i, 6) = (v21*i13 + v22*i23 + v23*i33)*scale
        mapping(i, 7) = (v31*i11 + v32*i21 + v33*i31)*scale
        mapping(i, 8) = (v31*i12 + v32*i22 + v33*i32)*scale
        mapping(i, 9) = (v31*i13 + v32*i23 + v33*i33)*scale
      end do
    case (3, 5)
      do i = 1, nel
        scale = 1.0_wp/sign(max(abs(old_volume(i)), tiny(1.0_wp)), old_volume(i))
        mapping(i, 1) = old_gradient_sum(i, 1)*scale
        mapping(i, 2) = old_gradient_sum(i, 2)*scale
        mapping(i, 3) = old_gradient_sum(i, 3)*scale
        mapping(i, 4) = old_gradient_sum(i, 4)*scale
        mapping(i, 5) = old_gradient_sum(i, 5)*scale
        mapping(i, 6) = old_gradient_sum(i, 6)*scale
        mapping(i, 7) = old_gradient_sum(i, 7)*scale
        mapping(i, 8) = old_gradient_sum(i, 8)*scale
        mapping(i, 9) = old_gradient_sum(i, 9)*scale
      end do
    case default
      mapping(1:nel, :) = 0.0_wp
    end select

    do mode = 1, 4
      do i = 1, nel
        hvx = 0.0_wp
        hvy = 0.0_wp
        hvz = 0.0_wp
        px = 0.0_wp
        py = 0.0_wp
        pz = 0.0_wp
        do node = 1, 8
          hvx = hvx + hourglass_base(node, mode)*vx(i, node)
          hvy = hvy + hourglass_base(node, mode)*vy(i, node)
          hvz = hvz + hourglass_base(node, mode)*vz(i, node)
          px = px + hourglass_base(node, mode)*x(i, node)
          py = py + hourglass_base(node, mode)*y(i, node)
          pz = pz + hourglass_base(node, mode)*z(i, node)
        end do
        ! p = h . x(n) = h . x(n+1) - dt h . v
        px = px - time_step*hvx
        py = py - time_step*hvy
        pz = pz - time_step*hvz
        velocity(i, 3*mode - 2) = hvx - (mapping(i, 1)*px + mapping(i, 2)*py + mapping(i, 3)*pz)
        velocity(i, 3*mode - 1) = hvy - (mapping(i, 4)*px + mapping(i, 5)*py + mapping(i, 6)*pz)
        velocity(i, 3*mode) = hvz - (mapping(i, 7)*px + mapping(i, 8)*py + mapping(i, 9)*pz)
      end do
    end do
  end subroutine previous_hourglass_velocities

  !> sum_k generalized(:, k) velocity(:, k): the power of hourglass forces.
  subroutine hourglass_power(nel, generalized, velocity, power)
    integer, intent(in) :: nel
    real(wp), intent(in) :: generalized(block_size, 12), velocity(block_size, 12)
    real(wp), intent(out) :: power(block_size)
    real(wp) :: total
    integer :: k, i
    do i = 1, nel
      total = 0.0_wp
      do k = 1, 12
        total = total + generalized(i, k)*velocity(i, k)
      end do
      power(i) = total
    end do
  end subroutine hourglass_power

  !> Hourglass shape vectors gamma(:, I, alpha) of the chosen type at the configuration x, y, z
  !> (see the module comment), the volume that scales the hourglass coefficient and the sum
  !> b_iI b_iI of the volume derivatives of that integration (exact or centre).
  !> (The loops run mode by mode outside the lane loop, with a single node loop inside, which
  !> is the shape the compiler vectorizes across lanes.)
  subroutine hourglass_shape_vectors(nel, hourglass_type, x, y, z, bx, by, bz, volume, gamma, &
                                     hourglass_volume, gradient_norm_squared)
    integer, intent(in) :: nel, hourglass_type
    real(wp), intent(in) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp), intent(in) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8)
    real(wp), intent(in) :: volume(block_size)
    real(wp), intent(out) :: gamma(block_size, 8, 4)
    real(wp), intent(out) :: hourglass_volume(block_size), gradient_norm_squared(block_size)
    real(wp) :: inverse_volume(block_size)
    real(wp) :: px, py, pz, norm
    integer :: node, mode, i

    select case (hourglass_type)
    case (2, 4)
      call centre_shape_vectors(nel, x, y, z, gamma, hourglass_volume, gradient_norm_squared)
      return
    case (3, 5)
      do i = 1, nel
        ! kept finite for inverted elements (reported by the caller); a flattened one gets at
        ! most 1e12 times its size (V ~ |b|^(3/2)), so that the time step's Gram matrix of the
        ! shape vectors stays finite too
        norm = 0.0_wp
        do node = 1, 8
          norm = norm + bx(i, node)**2 + by(i, node)**2 + bz(i, node)**2
        end do
        inverse_volume(i) = 1.0_wp/sign(max(abs(volume(i)), 1.0e-12_wp*sqrt(norm*sqrt(norm)), tiny(1.0_wp)), volume(i))
      end do
      do mode = 1, 4
        do i = 1, nel
          ! (h_alpha . x_j) / V
          px = 0.0_wp
          py = 0.0_wp
          pz = 0.0_wp
          do node = 1, 8
            px = px + hourglass_base(node, mode)*x(i, node)
            py = py + hourglass_base(node, mode)*y(i, node)
            pz = pz + hourglass_base(node, mode)*z(i, node)
          end do
          px = px*inverse_volume(i)
          py = py*inverse_volume(i)
          pz = pz*inverse_volume(i)
          do node = 1, 8
            gamma(i, node, mode) = hourglass_base(node, mode) - (px*bx(i, node) + py*by(i, node) + pz*bz(i, node))
          end do
        end do
      end do
    case default
      do mode = 1, 4
        do node = 1, 8
          do i = 1, nel
            gamma(i, node, mode) = hourglass_base(node, mode)
          end do
        end do
      end do
    end select
    do i = 1, nel
      hourglass_volume(i) = volume(i)
      norm = 0.0_wp
      do node = 1, 8
        norm = norm + bx(i, node)**2 + by(i, node)**2 + bz(i, node)**2
      end do
      gradient_norm_squared(i) = norm
    end do
  end subroutine hourglass_shape_vectors

  !> Shape vectors from the Jacobian at the element centre (IHQ 2 and 4):
  !> dN_I/dx_i(0) = sum_a Jinv_ai xi_aI / 8 with J_ia = sum_I x_iI xi_aI / 8, so
  !> gamma_alphaI = h_alphaI - (1/8) sum_a xi_aI c_alphaa, c_alphaa = sum_i Jinv_ai (h_alpha . x_i).
  !> V0 = 8 det J(0); sum_I b0_iI b0_iI = V0^2 |Jinv|^2 / 8 since sum_I xi_aI xi_bI = 8 delta_ab.
  subroutine centre_shape_vectors(nel, x, y, z, gamma, centre_volume, gradient_norm_squared)
    integer, intent(in) :: nel
    real(wp), intent(in) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp), intent(out) :: gamma(block_size, 8, 4)
    real(wp), intent(out) :: centre_volume(block_size), gradient_norm_squared(block_size)
    real(wp) :: inverse(block_size, 9)
    real(wp) :: j11, j12, j13, j21, j22, j23, j31, j32, j33
    real(wp) :: i11, i12, i13, i21, i22, i23, i31, i32, i33
    real(wp) :: determinant, scale, px, py, pz, c1, c2, c3, largest_entry
    integer :: node, mode, i

    do i = 1, nel
      j11 = 0.0_wp; j12 = 0.0_wp; j13 = 0.0_wp
      j21 = 0.0_wp; j22 = 0.0_wp; j23 = 0.0_wp
      j31 = 0.0_wp; j32 = 0.0_wp; j33 = 0.0_wp
      do node = 1, 8
        j11 = j11 + x(i, node)*node_xi(node)
        j12 = j12 + x(i, node)*node_eta(node)
        j13 = j13 + x(i, node)*node_zeta(node)
        j21 = j21 + y(i, node)*node_xi(node)
        j22 = j22 + y(i, node)*node_eta(node)
        j23 = j23 + y(i, node)*node_zeta(node)
        j31 = j31 + z(i, node)*node_xi(node)
        j32 = j32 + z(i, node)*node_eta(node)
        j33 = j33 + z(i, node)*node_zeta(node)
      end do
      ! 8 J(0) = (j_ka); cofactors i_ak of 8 J
      i11 = j22*j33 - j23*j32
      i12 = j13*j32 - j12*j33
      i13 = j12*j23 - j13*j22
      i21 = j23*j31 - j21*j33
      i22 = j11*j33 - j13*j31
      i23 = j13*j21 - j11*j23
      i31 = j21*j32 - j22*j31
      i32 = j12*j31 - j11*j32
      i33 = j11*j22 - j12*j21
      ! det(8 J) = 512 det J, so V0 = 8 det J = det(8 J) / 64
      determinant = j11*i11 + j12*i21 + j13*i31
      centre_volume(i) = determinant/64.0_wp
      ! sum b0.b0 = 8 det(J)^2 |J^-1|^2 = 8 |cof(J)|^2 = 8 |cof(8J)|^2 / 64^2
      gradient_norm_squared(i) = (i11**2 + i12**2 + i13**2 + i21**2 + i22**2 + i23**2 + i31**2 + i32**2 &
                                  + i33**2)/512.0_wp
      ! J^-1 / 8 = (8 J)^-1, kept finite for inverted elements (reported by the caller)
      ! (a flattened element keeps finite shape vectors: det(8 J) ~ (largest |8 J_ka|)^3, floored
      ! at 1e-12 of it)
      largest_entry = max(abs(j11), abs(j12), abs(j13), abs(j21), abs(j22), abs(j23), abs(j31), abs(j32), abs(j33))
      scale = 1.0_wp/sign(max(abs(determinant), 1.0e-12_wp*largest_entry**3, tiny(1.0_wp)), determinant)
      inverse(i, 1) = i11*scale
      inverse(i, 2) = i12*scale
      inverse(i, 3) = i13*scale
      inverse(i, 4) = i21*scale
      inverse(i, 5) = i22*scale
      inverse(i, 6) = i23*scale
      inverse(i, 7) = i31*scale
      inverse(i, 8) = i32*scale
      inverse(i, 9) = i33*scale
    end do
    do mode = 1, 4
      do i = 1, nel
        px = 0.0_wp
        py = 0.0_wp
        pz = 0.0_wp
        do node = 1, 8
          px = px + hourglass_base(node, mode)*x(i, node)
          py = py + hourglass_base(node, mode)*y(i, node)
          pz = pz + hourglass_base(node, mode)*z(i, node)
        end do
        c1 = inverse(i, 1)*px + inverse(i, 2)*py + inverse(i, 3)*pz
        c2 = inverse(i, 4)*px + inverse(i, 5)*py + inverse(i, 6)*pz
        c3 = inverse(i, 7)*px + inverse(i, 8)*py + inverse(i, 9)*pz
        do node = 1, 8
          gamma(i, node, mode) = hourglass_base(node, mode) - (node_xi(node)*c1 + node_eta(node)*c2 &
                                                               + node_zeta(node)*c3)
        end do
      end do
    end do
  end subroutine centre_shape_vectors

  !> Hourglass velocities q_ialpha = sum_I v_iI gamma_alphaI, as velocity(:, i + 3 (alpha - 1)).
  subroutine hourglass_velocities(nel, gamma, vx, vy, vz, velocity)
    integer, intent(in) :: nel
    real(wp), intent(in) :: gamma(block_size, 8, 4)
    real(wp), intent(in) :: vx(block_size, 8), vy(block_size, 8), vz(block_size, 8)
    real(wp), intent(out) :: velocity(block_size, 12)
    real(wp) :: qx, qy, qz
    integer :: node, mode, i
    do mode = 1, 4
      do i = 1, nel
        qx = 0.0_wp
        qy = 0.0_wp
        qz = 0.0_wp
        do node = 1, 8
          qx = qx + vx(i, node)*gamma(i, node, mode)
          qy = qy + vy(i, node)*gamma(i, node, mode)
          qz = qz + vz(i, node)*gamma(i, node, mode)
        end do
        velocity(i, 3*mode - 2) = qx
        velocity(i, 3*mode - 1) = qy
        velocity(i, 3*mode) = qz
      end do
    end do
  end subroutine hourglass_velocities

  !> Viscous forms (IHQ 1-3): generalized hourglass forces Q_ialpha = a_h q_ialpha with
  !> a_h = QM rho c V^(2/3) / 4, and their power a_h |q|^2 against the velocities;
  !> viscosity_scale = rho c V^(2/3) / 4 (a_h per unit QM, for the time step).
  subroutine hourglass_viscous_forces(nel, coefficient, density, sound_speed, hourglass_volume, &
                                      gamma, vx, vy, vz, generalized, power, viscosity_scale)
    integer, intent(in) :: nel
    real(wp), intent(in) :: coefficient
    real(wp), intent(in) :: density(block_size), sound_speed(block_size), hourglass_volume(block_size)
    real(wp), intent(in) :: gamma(block_size, 8, 4)
    real(wp), intent(in) :: vx(block_size, 8), vy(block_size, 8), vz(block_size, 8)
    real(wp), intent(out) :: generalized(block_size, 12)
    real(wp), intent(out) :: power(block_size), viscosity_scale(block_size)
    real(wp) :: viscosity, squared
    integer :: k, i

    call hourglass_velocities(nel, gamma, vx, vy, vz, generalized)
    do i = 1, nel
      viscosity_scale(i) = 0.25_wp*density(i)*sound_speed(i)*abs(hourglass_volume(i))**(2.0_wp/3.0_wp)
      viscosity = coefficient*viscosity_scale(i)
      squared = 0.0_wp
      do k = 1, 12
        squared = squared + generalized(i, k)**2
        generalized(i, k) = viscosity*generalized(i, k)
      end do
      power(i) = viscosity*squared
    end do
  end subroutine hourglass_viscous_forces

  !> Stiffness forms (IHQ 4, 5): rotates the accumulated generalized forces Q with the element
  !> and adds k dt q; returns the power Q . q of the new forces. `hourglass_force` (the block
  !> state, (block_size, 3, 4) seen as (block_size, 12)) then holds the generalized forces of the
  !> corner-force kernel.
  subroutine hourglass_stiffness_forces(nel, coefficient, time_step, wave_modulus, hourglass_volume, &
                                        gradient_norm_squared, rotation, gamma, vx, vy, vz, hourglass_force, power)
    integer, intent(in) :: nel
    real(wp), intent(in) :: coefficient, time_step
    real(wp), intent(in) :: wave_modulus(block_size), hourglass_volume(block_size)
    real(wp), intent(in) :: gradient_norm_squared(block_size), rotation(block_size, 9)
    real(wp), intent(in) :: gamma(block_size, 8, 4)
    real(wp), intent(in) :: vx(block_size, 8), vy(block_size, 8), vz(block_size, 8)
    real(wp), intent(inout) :: hourglass_force(block_size, 12)
    real(wp), intent(out) :: power(block_size)
    real(wp) :: velocity(block_size, 12)
    real(wp) :: stiffness_step, total
    integer :: k, i

    call hourglass_velocities(nel, gamma, vx, vy, vz, velocity)
    call rotate_vectors(nel, 4, rotation, hourglass_force)
    do i = 1, nel
      stiffness_step = coefficient*wave_modulus(i)*gradient_norm_squared(i)*time_step &
                       /(3.0_wp*sign(max(abs(hourglass_volume(i)), tiny(1.0_wp)), hourglass_volume(i)))
      total = 0.0_wp
      do k = 1, 12
        hourglass_force(i, k) = hourglass_force(i, k) + stiffness_step*velocity(i, k)
        total = total + hourglass_force(i, k)*velocity(i, k)
      end do
      power(i) = total
    end do
  end subroutine hourglass_stiffness_forces

  !> For the stable step (element_time_step): bounds on what the hourglass forces add to the
  !> element's lumped-mass eigenproblem (corner mass `corner_mass` = rho V0 / 8). The forces
  !> are f_iI = sum_alpha gamma_alphaI Q_ialpha with Q = k dt q (IHQ 4, 5: a stiffness k per
  !> unit hourglass displacement) or Q = a_h q (IHQ 1-3: a viscosity), q_ialpha = sum_I v_iI
  !> gamma_alphaI, so per direction the matrix is k (or a_h) times Gamma = sum_alpha gamma_alpha
  !> gamma_alpha^T, whose largest eigenvalue is that of the 4 x 4 Gram matrix gamma_alpha .
  !> gamma_beta, bounded by its largest absolute row sum (exact for a parallelepiped, where
  !> the gamma_alpha are orthogonal with |gamma|^2 = 8):
  !>   IHQ 4, 5: frequency_squared = k lambda / m, k = QM (lambda + 2 mu) b.b / (3 V);
  !>   IHQ 1-3:  damping = a_h lambda / m (a rate, 1/time), a_h = QM viscosity_scale
  !>             (hourglass_viscous_forces).
  subroutine hourglass_mode_bounds(nel, hourglass_type, coefficient, wave_modulus, viscosity_scale, &
                                   hourglass_volume, gradient_norm_squared, gamma, corner_mass, frequency_squared, &
                                   damping)
    integer, intent(in) :: nel, hourglass_type
    real(wp), intent(in) :: coefficient
    real(wp), intent(in) :: wave_modulus(block_size), viscosity_scale(block_size)
    real(wp), intent(in) :: hourglass_volume(block_size), gradient_norm_squared(block_size)
    real(wp), intent(in) :: gamma(block_size, 8, 4), corner_mass(block_size)
    real(wp), intent(out) :: frequency_squared(block_size), damping(block_size)
    ! the 10 entries of the symmetric 4 x 4 Gram matrix: (mode, other) pairs
    integer, parameter :: pair_mode(10) = [1, 1, 1, 1, 2, 2, 2, 3, 3, 4]
    integer, parameter :: pair_other(10) = [1, 2, 3, 4, 2, 3, 4, 3, 4, 4]
    real(wp) :: gram(block_size, 10), stiffness
    integer :: i, node, pair
    if (hourglass_type == 1) then
      ! the base vectors themselves: orthogonal, |h|^2 = 8
      gram(1:nel, :) = 0.0_wp
      gram(1:nel, [1, 5, 8, 10]) = 8.0_wp
    else
      do pair = 1, 10
        gram(1:nel, pair) = 0.0_wp
        do node = 1, 8
          do i = 1, nel
            gram(i, pair) = gram(i, pair) + gamma(i, node, pair_mode(pair))*gamma(i, node, pair_other(pair))
          end do
        end do
      end do
    end if
    do i = 1, nel
      ! largest absolute row sum of [g1 g2 g3 g4; g2 g5 g6 g7; g3 g6 g8 g9; g4 g7 g9 g10]
      gram(i, 1) = max(abs(gram(i, 1)) + abs(gram(i, 2)) + abs(gram(i, 3)) + abs(gram(i, 4)), &
                       abs(gram(i, 2)) + abs(gram(i, 5)) + abs(gram(i, 6)) + abs(gram(i, 7)), &
                       abs(gram(i, 3)) + abs(gram(i, 6)) + abs(gram(i, 8)) + abs(gram(i, 9)), &
                       abs(gram(i, 4)) + abs(gram(i, 7)) + abs(gram(i, 9)) + abs(gram(i, 10))) &
                   /max(corner_mass(i), tiny(1.0_wp))
    end do
    if (hourglass_type >= 4) then
      do i = 1, nel
        ! (a flattened element keeps a finite, huge stiffness: |V| is of order |b|^(3/2))
        stiffness = coefficient*wave_modulus(i)*gradient_norm_squared(i) &
                    /(3.0_wp*max(abs(hourglass_volume(i)), &
                                 1.0e-12_wp*sqrt(gradient_norm_squared(i)*sqrt(gradient_norm_squared(i))), tiny(1.0_wp)))
        ! (capped so that an inverted element, which stops the run, cannot overflow)
        frequency_squared(i) = min(stiffness, 1.0e150_wp)*min(gram(i, 1), 1.0e150_wp)
        damping(i) = 0.0_wp
      end do
    else
      do i = 1, nel
        frequency_squared(i) = 0.0_wp
        damping(i) = coefficient*min(viscosity_scale(i), 1.0e150_wp)*min(gram(i, 1), 1.0e150_wp)
      end do
    end if
  end subroutine hourglass_mode_bounds

  !> IHQ 1 takes gamma_alpha = h_alpha, which is orthogonal to the strain modes b only on
  !> parallelepipeds. An upper bound on cos^2 of the largest principal angle between span{b_x,
  !> b_y, b_z} and span{h_alpha} (orthogonal, |h|^2 = 8): with G = b^T b / V^2 (3 x 3, packed
  !> 11 22 33 12 23 13 as hex8_gradient_invariants returns it) and F = (h^T b)^T (h^T b) / (8 V^2),
  !> cos^2 = lambda_max(G^-1 F) <= tr(G^-1 F), capped at 1.
  subroutine standard_hourglass_overlap(nel, bx, by, bz, volume, g, overlap)
    integer, intent(in) :: nel
    real(wp), intent(in) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8), volume(block_size)
    real(wp), intent(in) :: g(block_size, 6)
    real(wp), intent(out) :: overlap(block_size)
    real(wp) :: f11, f22, f33, f12, f23, f13, hx, hy, hz
    real(wp) :: c11, c22, c33, c12, c23, c13, determinant, numerator, scale
    integer :: i, node, mode
    do i = 1, nel
      f11 = 0.0_wp; f22 = 0.0_wp; f33 = 0.0_wp; f12 = 0.0_wp; f23 = 0.0_wp; f13 = 0.0_wp
      do mode = 1, 4
        hx = 0.0_wp
        hy = 0.0_wp
        hz = 0.0_wp
        do node = 1, 8
          hx = hx + hourglass_base(node, mode)*bx(i, node)
          hy = hy + hourglass_base(node, mode)*by(i, node)
          hz = hz + hourglass_base(node, mode)*bz(i, node)
        end do
        f11 = f11 + hx*hx
        f22 = f22 + hy*hy
        f33 = f33 + hz*hz
        f12 = f12 + hx*hy
        f23 = f23 + hy*hz
        f13 = f13 + hx*hz
      end do
      ! tr(G^-1 F) = tr(cof(G) F) / det G; the cofactor matrix of a symmetric G is symmetric
      c11 = g(i, 2)*g(i, 3) - g(i, 5)**2
      c22 = g(i, 1)*g(i, 3) - g(i, 6)**2
      c33 = g(i, 1)*g(i, 2) - g(i, 4)**2
      c12 = g(i, 6)*g(i, 5) - g(i, 4)*g(i, 3)
      c23 = g(i, 4)*g(i, 6) - g(i, 1)*g(i, 5)
      c13 = g(i, 4)*g(i, 5) - g(i, 6)*g(i, 2)
      determinant = g(i, 1)*c11 + g(i, 4)*c12 + g(i, 6)*c13
      scale = 0.125_wp/max(volume(i)**2, tiny(1.0_wp))
      numerator = max(scale*(c11*f11 + c22*f22 + c33*f33 + 2.0_wp*(c12*f12 + c23*f23 + c13*f13)), 0.0_wp)
      ! a degenerate element (det G ~ 0) gets 1, without dividing by zero
      overlap(i) = min(1.0_wp, numerator/max(determinant, numerator, tiny(1.0_wp)))
    end do
  end subroutine standard_hourglass_overlap
end module hex8_one_point
