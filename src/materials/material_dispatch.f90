!> One entry point per material operation for a block of lanes (elements or integration
!> points of one material); each selects the law by `material%law` and calls the law's kernel
!> with plain arrays and scalar constants. A new law is a new module plus one case in each
!> procedure here.
!>
!> Conventions shared by every law:
!> - stress: Cauchy stress (block_size, 6), order xx, yy, zz, xy, yz, zx, already rotated by the
!>   element to the end of the step (objective Jaumann rotation, see objective_rotation);
!> - strain_increment: D dt (block_size, 6), TENSOR shear components (de_xy = 1/2 gamma_xy);
!> - history: (block_size, material_history_count(material)) per integration point, with the
!>   law's own layout; tensor-valued history is rotated by rotate_material_history;
!> - wave_modulus: rho c^2 of the dilatational wave, K + 4G/3 for these laws (per lane, so that
!>   laws with a state-dependent stiffness fit the same interface); the elements use it for the
!>   time step, the linear bulk viscosity and the hourglass stiffness (lambda + 2 mu).
module material_dispatch
  use kinds, only: wp, block_size
  use model, only: material_t, law_elastic, law_plastic_kinematic
  use material_elastic, only: elastic_update
  use material_plastic_kinematic, only: plastic_kinematic_update, plastic_kinematic_history_count, &
                                        plastic_strain_slot, back_stress_first_slot
  use objective_rotation, only: rotate_symmetric_tensors
  implicit none
  private

  public :: material_history_count, initialize_material_history, update_material_block
  public :: rotate_material_history, material_wave_modulus, material_plastic_strain
  public :: elastic_moduli, plastic_hardening_modulus

contains

  !> Number of history variables per integration point of the material's law.
  pure function material_history_count(material) result(count)
    type(material_t), intent(in) :: material
    integer :: count
    select case (material%law)
    case (law_plastic_kinematic)
      count = plastic_kinematic_history_count
    case default
      count = 0
    end select
  end function material_history_count

  !> Initial history of lanes 1..nel (virgin material: no plastic strain, no back stress).
  subroutine initialize_material_history(material, nel, history)
    type(material_t), intent(in) :: material
    integer, intent(in) :: nel
    real(wp), intent(inout), contiguous :: history(:, :)
    select case (material%law)
    case default
      ! Every law so far starts from zero history.
      if (size(history, 2) > 0) history(1:nel, :) = 0.0_wp
    end select
  end subroutine initialize_material_history

  !> Bulk modulus K = E / (3 (1 - 2 nu)) and shear modulus G = E / (2 (1 + nu)).
  pure subroutine elastic_moduli(material, bulk_modulus, shear_modulus)
    type(material_t), intent(in) :: material
    real(wp), intent(out) :: bulk_modulus, shear_modulus
    bulk_modulus = material%youngs_modulus/(3.0_wp*(1.0_wp - 2.0_wp*material%poissons_ratio))
    shear_modulus = material%youngs_modulus/(2.0_wp*(1.0_wp + material%poissons_ratio))
  end subroutine elastic_moduli

  !> Plastic hardening modulus of *MAT_PLASTIC_KINEMATIC, E_p = E Etan / (E - Etan)
  !> (0 for Etan = 0, perfect plasticity; also 0 if Etan >= E, which the deck check rejects).
  pure function plastic_hardening_modulus(material) result(modulus)
    type(material_t), intent(in) :: material
    real(wp) :: modulus
    if (material%tangent_modulus < material%youngs_modulus) then
      modulus = material%youngs_modulus*material%tangent_modulus/(material%youngs_modulus - material%tangent_modulus)
    else
      modulus = 0.0_wp
    end if
  end function plastic_hardening_modulus

  !> Constitutive update of lanes 1..nel over a step of length `time_step` (used for rates).
  !> Returns the dilatational wave modulus rho c^2 of each lane.
  subroutine update_material_block(material, nel, time_step, strain_increment, stress, history, wave_modulus)
    type(material_t), intent(in) :: material
    integer, intent(in) :: nel
    real(wp), intent(in) :: time_step
    real(wp), intent(in) :: strain_increment(block_size, 6)
    real(wp), intent(inout) :: stress(block_size, 6)
    real(wp), intent(inout), contiguous :: history(:, :)
    real(wp), intent(out) :: wave_modulus(block_size)
    real(wp) :: bulk_modulus, shear_modulus

    call elastic_moduli(material, bulk_modulus, shear_modulus)
    select case (material%law)
    case (law_elastic)
      call elastic_update(nel, bulk_modulus, shear_modulus, strain_increment, stress)
    case (law_plastic_kinematic)
      call plastic_kinematic_update(nel, bulk_modulus, shear_modulus, material%yield_stress, &
                                    plastic_hardening_modulus(material), material%hardening_beta, &
                                    material%rate_c, material%rate_p, material%rate_formulation > 0.5_wp, &
                                    time_step, strain_increment, stress, history(:, plastic_strain_slot), &
                                    history(:, back_stress_first_slot:back_stress_first_slot + 5))
    case default
      ! Unknown laws are rejected by the deck check; keep the stress as it is.
      continue
    end select
    call material_wave_modulus(material, nel, wave_modulus)
  end subroutine update_material_block

  !> Rotate the tensor-valued history with the element (objectivity), like the stress.
  subroutine rotate_material_history(material, nel, rotation, history)
    type(material_t), intent(in) :: material
    integer, intent(in) :: nel
    real(wp), intent(in) :: rotation(block_size, 9)
    real(wp), intent(inout), contiguous :: history(:, :)
    select case (material%law)
    case (law_plastic_kinematic)
      call rotate_symmetric_tensors(nel, rotation, history(:, back_stress_first_slot:back_stress_first_slot + 5))
    case default
      continue
    end select
  end subroutine rotate_material_history

  !> Dilatational wave modulus rho c^2 = K + 4G/3 = lambda + 2 mu of lanes 1..nel (both laws
  !> use their elastic moduli, as LS-DYNA does for the time step). A law whose stiffness
  !> depends on its state would add its history here.
  subroutine material_wave_modulus(material, nel, wave_modulus)
    type(material_t), intent(in) :: material
    integer, intent(in) :: nel
    real(wp), intent(out) :: wave_modulus(block_size)
    real(wp) :: bulk_modulus, shear_modulus
    call elastic_moduli(material, bulk_modulus, shear_modulus)
    wave_modulus(1:nel) = bulk_modulus + 4.0_wp*shear_modulus/3.0_wp
  end subroutine material_wave_modulus

  !> Effective plastic strain of lanes 1..nel (0 for laws without plasticity), from the history
  !> of a material of law `law` (material_t%law; the law alone fixes the history layout).
  subroutine material_plastic_strain(law, nel, history, plastic_strain)
    integer, intent(in) :: law
    integer, intent(in) :: nel
    real(wp), intent(in), contiguous :: history(:, :)
    real(wp), intent(out) :: plastic_strain(block_size)
    select case (law)
    case (law_plastic_kinematic)
      plastic_strain(1:nel) = history(1:nel, plastic_strain_slot)
    case default
      plastic_strain(1:nel) = 0.0_wp
    end select
  end subroutine material_plastic_strain
end module material_dispatch
