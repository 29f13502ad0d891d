!> One-point (uniform strain) hexahedron, ELFORM 1: corner forces from the element stress and
!> the hourglass control forces, on a block of elements.
!>
!> Stress divergence (Flanagan & Belytschko 1981, eq. 20): f_iI = (sigma_ij - q delta_ij) b_jI
!> with b the exact volume derivatives at the end-of-step configuration and q the bulk
!> viscosity. Sum over I vanishes (sum_I b_jI = 0) and so does the moment
!> (sum_I x_kI b_jI = V delta_jk with sigma symmetric).
!>
!> Hourglass control (LS-DYNA Theory Manual, section "Hourglass control" of the solid elements;
!> Flanagan & Belytschko 1981, section 4). With the base vectors h_alpha (alpha = 1..4; eta zeta,
!> zeta xi, xi eta, xi eta zeta at the nodes) the shape vectors are
!>   IHQ 1      gamma_alpha = h_alpha                          (LS-DYNA standard, Kosloff-Frazier)
!>   IHQ 2, 4   gamma_alphaI = h_alphaI - (h_alpha . x_i) dN_I/dx_i(0)  (one-point Jacobian at
!>              the element centre; "volume" V0 = 8 det J(0))
!>   IHQ 3, 5   gamma_alphaI = h_alphaI - (h_alpha . x_i) b_iI / V      (exact volume)
!> For IHQ 2-5, sum_I gamma_alphaI x_jI = 0 and sum_I gamma_alphaI = 0, so a velocity field
!> linear in the coordinates has zero hourglass velocity q_ialpha = sum_I v_iI gamma_alphaI,
!> and the hourglass forces f_iI = sum_alpha Q_ialpha gamma_alphaI carry neither resultant nor
!> moment. IHQ 1 passes neither test on a distorted element (it is only orthogonal to linear
!> fields on parallelepipeds).
!>   viscous (IHQ 1, 2, 3):   Q_ialpha = a_h q_ialpha,  a_h = QM rho c V^(2/3) / 4
!>                            (the LS-DYNA Theory Manual's scaling of the viscous form)
!>   stiffness (IHQ 4, 5):    Q_ialpha(n+1) = R Q_ialpha(n) + k dt q_ialpha,
!>                            k = QM (lambda + 2 mu) (b_iI b_iI) / (3 V)
!> The stiffness k is QM times the one-eighth share of the element's highest-mode stiffness in
!> the eigenvalue bound of Flanagan & Belytschko (1981): omega_max^2 = 8 (lambda + 2 mu)
!> b_iI b_iI / (3 rho V^2), i.e. (rho V / 8) omega_max^2 = (lambda + 2 mu) b_iI b_iI / (3 V).
!> For a cube of side h, k = QM (lambda + 2 mu) h / 2. The accumulated Q rotate with the
!> element (R the incremental rotation of the spin). Hourglass energy is the work
!> sum Q_ialpha q_ialpha dt (mid-step force for the stiffness form).
!> rho is the current density (mass / current volume), c = sqrt((lambda + 2 mu) / rho_block).
module hex8_one_point
  use kinds, only: wp, block_size
  use hex8_geometry, only: node_xi, node_eta, node_zeta
  use objective_rotation, only: rotate_vectors
  implicit none
  private

  public :: one_point_stress_forces, hourglass_shape_vectors, hourglass_viscous_forces
  public :: hourglass_stiffness_forces

  !> Hourglass base vectors h_alpha(I) (rows: eta zeta, zeta xi, xi eta, xi eta zeta).
  real(wp), parameter, public :: hourglass_base(8, 4) = reshape([ &
                                 node_eta*node_zeta, node_zeta*node_xi, node_xi*node_eta, &
                                 node_xi*node_eta*node_zeta], [8, 4])

contains

  !> Corner forces of the uniform stress (sigma - q I) of each element, overwriting
  !> corner_force(:, I, i) = sum_j (sigma_ij - q delta_ij) b_jI.
  subroutine one_point_stress_forces(nel, bx, by, bz, stress, bulk_viscosity, corner_force)
    integer, intent(in) :: nel
    real(wp), intent(in) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8)
    real(wp), intent(in) :: stress(block_size, 6), bulk_viscosity(block_size)
    real(wp), intent(inout) :: corner_force(block_size, 8, 3)
    real(wp) :: s11, s22, s33, s12, s23, s31
    integer :: node, i
    do i = 1, nel
      s11 = stress(i, 1) - bulk_viscosity(i)
      s22 = stress(i, 2) - bulk_viscosity(i)
      s33 = stress(i, 3) - bulk_viscosity(i)
      s12 = stress(i, 4)
      s23 = stress(i, 5)
      s31 = stress(i, 6)
      do node = 1, 8
        corner_force(i, node, 1) = s11*bx(i, node) + s12*by(i, node) + s31*bz(i, node)
        corner_force(i, node, 2) = s12*bx(i, node) + s22*by(i, node) + s23*bz(i, node)
        corner_force(i, node, 3) = s31*bx(i, node) + s23*by(i, node) + s33*bz(i, node)
      end do
    end do
  end subroutine one_point_stress_forces

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
        ! kept finite for inverted elements (reported by the caller)
        inverse_volume(i) = 1.0_wp/sign(max(abs(volume(i)), tiny(1.0_wp)), volume(i))
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
    real(wp) :: determinant, scale, px, py, pz, c1, c2, c3
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
      scale = 1.0_wp/sign(max(abs(determinant), tiny(1.0_wp)), determinant)
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

  !> corner_force(:, I, i) += sum_alpha generalized(:, i + 3 (alpha - 1)) gamma(:, I, alpha)
  subroutine add_generalized_forces(nel, gamma, generalized, corner_force)
    integer, intent(in) :: nel
    real(wp), intent(in) :: gamma(block_size, 8, 4), generalized(block_size, 12)
    real(wp), intent(inout) :: corner_force(block_size, 8, 3)
    integer :: node, component, i
    do component = 1, 3
      do i = 1, nel
        do node = 1, 8
          corner_force(i, node, component) = corner_force(i, node, component) &
                                             + generalized(i, component)*gamma(i, node, 1) &
                                             + generalized(i, component + 3)*gamma(i, node, 2) &
                                             + generalized(i, component + 6)*gamma(i, node, 3) &
                                             + generalized(i, component + 9)*gamma(i, node, 4)
        end do
      end do
    end do
  end subroutine add_generalized_forces

  !> Viscous forms (IHQ 1-3): adds a_h sum_alpha q_ialpha gamma_alphaI to the corner forces with
  !> a_h = QM rho c V^(2/3) / 4 and returns the hourglass work a_h |q|^2 dt of the step.
  subroutine hourglass_viscous_forces(nel, coefficient, time_step, density, sound_speed, hourglass_volume, &
                                      gamma, vx, vy, vz, corner_force, energy_increment)
    integer, intent(in) :: nel
    real(wp), intent(in) :: coefficient, time_step
    real(wp), intent(in) :: density(block_size), sound_speed(block_size), hourglass_volume(block_size)
    real(wp), intent(in) :: gamma(block_size, 8, 4)
    real(wp), intent(in) :: vx(block_size, 8), vy(block_size, 8), vz(block_size, 8)
    real(wp), intent(inout) :: corner_force(block_size, 8, 3)
    real(wp), intent(out) :: energy_increment(block_size)
    real(wp) :: velocity(block_size, 12)
    real(wp) :: viscosity, squared
    integer :: k, i

    call hourglass_velocities(nel, gamma, vx, vy, vz, velocity)
    do i = 1, nel
      viscosity = 0.25_wp*coefficient*density(i)*sound_speed(i)*abs(hourglass_volume(i))**(2.0_wp/3.0_wp)
      squared = 0.0_wp
      do k = 1, 12
        squared = squared + velocity(i, k)**2
        velocity(i, k) = viscosity*velocity(i, k)
      end do
      energy_increment(i) = viscosity*squared*time_step
    end do
    call add_generalized_forces(nel, gamma, velocity, corner_force)
  end subroutine hourglass_viscous_forces

  !> Stiffness forms (IHQ 4, 5): rotates the accumulated generalized forces Q with the element,
  !> adds k dt q, adds sum_alpha Q_ialpha gamma_alphaI to the corner forces and returns the work
  !> of the mid-step force, (Q_rotated + Q_new)/2 . q dt.
  subroutine hourglass_stiffness_forces(nel, coefficient, time_step, wave_modulus, hourglass_volume, &
                                        gradient_norm_squared, rotation, gamma, vx, vy, vz, &
                                        hourglass_force, corner_force, energy_increment)
    integer, intent(in) :: nel
    real(wp), intent(in) :: coefficient, time_step
    real(wp), intent(in) :: wave_modulus(block_size), hourglass_volume(block_size)
    real(wp), intent(in) :: gradient_norm_squared(block_size), rotation(block_size, 9)
    real(wp), intent(in) :: gamma(block_size, 8, 4)
    real(wp), intent(in) :: vx(block_size, 8), vy(block_size, 8), vz(block_size, 8)
    real(wp), intent(inout) :: hourglass_force(block_size, 12)
    real(wp), intent(inout) :: corner_force(block_size, 8, 3)
    real(wp), intent(out) :: energy_increment(block_size)
    real(wp) :: velocity(block_size, 12)
    real(wp) :: stiffness_step, work
    integer :: k, i

    call hourglass_velocities(nel, gamma, vx, vy, vz, velocity)
    call rotate_vectors(nel, 4, rotation, hourglass_force)
    do i = 1, nel
      stiffness_step = coefficient*wave_modulus(i)*gradient_norm_squared(i)*time_step &
                       /(3.0_wp*sign(max(abs(hourglass_volume(i)), tiny(1.0_wp)), hourglass_volume(i)))
      work = 0.0_wp
      do k = 1, 12
        ! work of (Q_rotated + Q_new) / 2 = Q_rotated + k dt q / 2
        work = work + (hourglass_force(i, k) + 0.5_wp*stiffness_step*velocity(i, k))*velocity(i, k)
        hourglass_force(i, k) = hourglass_force(i, k) + stiffness_step*velocity(i, k)
      end do
      energy_increment(i) = work*time_step
    end do
    call add_generalized_forces(nel, gamma, hourglass_force, corner_force)
  end subroutine hourglass_stiffness_forces
end module hex8_one_point
