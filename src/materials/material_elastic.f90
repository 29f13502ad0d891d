!> *MAT_ELASTIC (LS-DYNA material 1) for solids: isotropic hypoelastic law on the objective
!> (Jaumann) stress rate, sigma_jaumann = lambda tr(D) I + 2 mu D (LS-DYNA Theory Manual,
!> "Material model 1: Elastic"). The element has already rotated the stress to the end of the
!> step; this routine adds the elastic response to the strain increment D dt.
module material_elastic
  use kinds, only: wp, block_size
  implicit none
  private

  public :: elastic_update

  ! No history variables (law_table in material_laws: history_count 0).

contains

  !> stress <- stress + lambda tr(de) I + 2 mu de for lanes 1..nel. `strain_increment` holds
  !> TENSOR components (de_xy, not the engineering shear 2 de_xy), order xx, yy, zz, xy, yz, zx.
  subroutine elastic_update(nel, bulk_modulus, shear_modulus, strain_increment, stress)
    integer, intent(in) :: nel
    real(wp), intent(in) :: bulk_modulus, shear_modulus
    real(wp), intent(in) :: strain_increment(block_size, 6)
    real(wp), intent(inout) :: stress(block_size, 6)
    real(wp) :: lame_lambda, twice_shear, volumetric_stress
    integer :: i
    lame_lambda = bulk_modulus - 2.0_wp*shear_modulus/3.0_wp
    twice_shear = 2.0_wp*shear_modulus
    do i = 1, nel
      volumetric_stress = lame_lambda*(strain_increment(i, 1) + strain_increment(i, 2) + strain_increment(i, 3))
      stress(i, 1) = stress(i, 1) + volumetric_stress + twice_shear*strain_increment(i, 1)
      stress(i, 2) = stress(i, 2) + volumetric_stress + twice_shear*strain_increment(i, 2)
      stress(i, 3) = stress(i, 3) + volumetric_stress + twice_shear*strain_increment(i, 3)
      stress(i, 4) = stress(i, 4) + twice_shear*strain_increment(i, 4)
      stress(i, 5) = stress(i, 5) + twice_shear*strain_increment(i, 5)
      stress(i, 6) = stress(i, 6) + twice_shear*strain_increment(i, 6)
    end do
  end subroutine elastic_update
end module material_elastic
