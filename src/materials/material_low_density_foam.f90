!> *MAT_LOW_DENSITY_FOAM (LS-DYNA material 57) for solids: a hyperelastic-like foam whose
!> principal stresses are uncoupled functions of the principal nominal strains (Poisson's
!> ratio zero), with hysteretic unloading (LS-DYNA Keyword User's Manual Vol. II,
!> *MAT_LOW_DENSITY_FOAM; LS-DYNA Theory Manual, "Material Model 57: Low Density Urethane
!> Foam", after Storakers 1986 and Chang et al. 1995).
!>
!> What is computed (crashfree's reading of the manuals; see docs/materials.md):
!> - the left Cauchy-Green tensor B = F F^T is tracked in the history: its Jaumann rate is
!>   exactly D B + B D, so the element's objective rotation (rotate_material_history) and
!>   B <- A B A^T with A = (I - D dt / 2)^-1 (I + D dt / 2) update it from the strain
!>   increments alone;
!> - principal stretches lambda_i = sqrt(eig(B)) with directions n_i, nominal strains
!>   e_i = lambda_i - 1 (negative in compression);
!> - nominal stresses: compression t_i = -h_i LCID(-e_i), tension t_i = min(E e_i, TC);
!> - hysteretic unloading (HU < 1): h_i = 1 - (1 - HU) (1 - (-e_i / e_max)^SHAPE) when
!>   -e_i < e_max, e_max the largest compressive principal nominal strain reached; h_i = 1 on
!>   the loading curve (HU = 1: no dissipation);
!> - Cauchy stress sigma = sum_i t_i / (lambda_j lambda_k) n_i n_i^T (t_i per unit reference
!>   area; 1 for the lateral stretches of a uniaxial test with Poisson's ratio zero);
!> - viscous damping DAMP: sigma += DAMP M D dt with M the stiffness bound of the wave speed
!>   (LS-DYNA's q = DAMP rho c L D with L / c replaced by the time step). Being recomputed from
!>   B every step, the stress carries no memory of it.
module material_low_density_foam
  use kinds, only: wp, block_size
  use curves, only: curve_t, curve_value
  use small_tensors, only: symmetric_matrix, symmetric_components, midpoint_update, symmetric_eigen
  implicit none
  private

  public :: low_density_foam_update, low_density_foam_initialize

  ! History variables per integration point (7 in all: law_table in material_laws): B (6, xx yy
  ! zz xy yz zx), then e_max.
  integer, parameter, public :: foam_left_cauchy_green_first_slot = 1
  integer, parameter, public :: foam_largest_compression_slot = 7

contains

  !> Undeformed state: B = I, no compression reached.
  subroutine low_density_foam_initialize(nel, history)
    integer, intent(in) :: nel
    real(wp), intent(inout), contiguous :: history(:, :)
    history(1:nel, :) = 0.0_wp
    history(1:nel, 1:3) = 1.0_wp
  end subroutine low_density_foam_initialize

  !> Update of lanes 1..nel (stress is recomputed in total from B; see the module notes).
  subroutine low_density_foam_update(nel, youngs_modulus, loading_curve, tension_cutoff, hysteretic_unloading, &
                                     unloading_shape, damping, damping_modulus, strain_increment, stress, history)
    integer, intent(in) :: nel
    real(wp), intent(in) :: youngs_modulus
    type(curve_t), intent(in) :: loading_curve
    real(wp), intent(in) :: tension_cutoff, hysteretic_unloading, unloading_shape, damping, damping_modulus
    real(wp), intent(in) :: strain_increment(block_size, 6)
    real(wp), intent(inout) :: stress(block_size, 6)
    real(wp), intent(inout), contiguous :: history(:, :)
    real(wp) :: update(3, 3), b(3, 3), vectors(3, 3), values(3)
    real(wp) :: stretch(3), nominal_strain(3), nominal_stress(3), cauchy(3), largest, compression, factor
    real(wp) :: lane(6)
    integer :: i, k

    do i = 1, nel
      ! (the rows are copied to contiguous lanes once)
      lane = strain_increment(i, :)
      update = midpoint_update(symmetric_matrix(lane))
      lane = history(i, 1:6)
      b = matmul(matmul(update, symmetric_matrix(lane)), transpose(update))
      history(i, 1:6) = symmetric_components(b)
      call symmetric_eigen(b, values, vectors)
      stretch = sqrt(max(values, tiny(1.0_wp)))
      nominal_strain = stretch - 1.0_wp
      largest = max(history(i, foam_largest_compression_slot), maxval(-nominal_strain))
      history(i, foam_largest_compression_slot) = largest
      do k = 1, 3
        if (nominal_strain(k) < 0.0_wp) then
          compression = -nominal_strain(k)
          factor = 1.0_wp
          if (hysteretic_unloading < 1.0_wp .and. compression < largest) &
            factor = 1.0_wp - (1.0_wp - hysteretic_unloading)*(1.0_wp - (compression/largest)**unloading_shape)
          nominal_stress(k) = -factor*curve_value(loading_curve, compression)
        else
          nominal_stress(k) = min(youngs_modulus*nominal_strain(k), tension_cutoff)
        end if
      end do
      cauchy(1) = nominal_stress(1)/(stretch(2)*stretch(3))
      cauchy(2) = nominal_stress(2)/(stretch(3)*stretch(1))
      cauchy(3) = nominal_stress(3)/(stretch(1)*stretch(2))
      ! sum_k cauchy_k n_k n_k^T, packed (xx yy zz xy yz zx)
      lane = 0.0_wp
      do k = 1, 3
        lane(1) = lane(1) + cauchy(k)*vectors(1, k)*vectors(1, k)
        lane(2) = lane(2) + cauchy(k)*vectors(2, k)*vectors(2, k)
        lane(3) = lane(3) + cauchy(k)*vectors(3, k)*vectors(3, k)
        lane(4) = lane(4) + cauchy(k)*vectors(1, k)*vectors(2, k)
        lane(5) = lane(5) + cauchy(k)*vectors(2, k)*vectors(3, k)
        lane(6) = lane(6) + cauchy(k)*vectors(3, k)*vectors(1, k)
      end do
      stress(i, :) = lane + damping*damping_modulus*strain_increment(i, :)
    end do
  end subroutine low_density_foam_update
end module material_low_density_foam
