!> One entry point per material operation for a block of lanes (elements or integration
!> points of one material); each selects the law by `material%law` and calls the law's kernel
!> with plain arrays and scalar constants. The law codes and what each law has (its history
!> size, the element families it takes) are rows of material_laws' law_table; a new law is a
!> new module, one row there and its case in update_material_block (and in the procedures here
!> that treat its history or stiffness specially).
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
  use model, only: material_t, honeycomb_rate_curve, foam_loading_curve, piecewise_hardening_curve, &
                   piecewise_rate_curve
  use material_laws, only: law_table, find_law, law_elastic, law_plastic_kinematic, law_honeycomb, &
                           law_modified_honeycomb, law_low_density_foam, law_piecewise_linear, law_null, &
                           law_viscoelastic, law_blatz_ko, law_mooney_rivlin
  use material_elastic, only: elastic_update
  use material_plastic_kinematic, only: plastic_kinematic_update, plastic_strain_slot, back_stress_first_slot
  use material_honeycomb, only: honeycomb_update, honeycomb_initialize_axes, honeycomb_axes_first_slot
  use material_piecewise_linear, only: piecewise_linear_update, piecewise_plastic_strain_slot
  use material_low_density_foam, only: low_density_foam_update, low_density_foam_initialize, &
                                       foam_left_cauchy_green_first_slot
  use material_rubber, only: rubber_update, mooney_rivlin_constants, rubber_mooney_rivlin, rubber_blatz_ko
  use material_viscoelastic, only: viscoelastic_update
  use objective_rotation, only: rotate_symmetric_tensors, rotate_vectors
  implicit none
  private

  public :: material_history_count, initialize_material_history, update_material_block
  public :: rotate_material_history, material_wave_modulus, material_plastic_strain
  public :: elastic_moduli, plastic_hardening_modulus, material_stiffness_bounds, rubber_constants

contains

  !> Number of history variables per integration point of the material's law (law_table; 0
  !> for a code that is not a law).
  pure function material_history_count(material) result(count)
    type(material_t), intent(in) :: material
    integer :: count
    integer :: law
    law = find_law(material%law)
    count = 0
    if (law > 0) count = law_table(law)%history_count
  end function material_history_count

  !> Initial history of lanes 1..nel (virgin material: no plastic strain, no back stress).
  !> `element_edges` (x2 - x1, x4 - x1 of each hexahedron, block_size x 6) gives the material
  !> axes of AOPT 0 (LS-DYNA: a along nodes 1-2, d along 1-4); without it AOPT 0 takes the
  !> global axes (the deck check admits the honeycombs on hexahedron parts only).
  subroutine initialize_material_history(material, nel, history, element_edges)
    type(material_t), intent(in) :: material
    integer, intent(in) :: nel
    real(wp), intent(inout), contiguous :: history(:, :)
    real(wp), intent(in), optional :: element_edges(block_size, 6)
    real(wp) :: first(block_size, 3), second(block_size, 3)
    integer :: k
    select case (material%law)
    case (law_honeycomb, law_modified_honeycomb)
      history(1:nel, :) = 0.0_wp
      if (material%axes_option == 2) then
        do k = 1, 3
          first(1:nel, k) = material%axis_a(k)
          second(1:nel, k) = material%axis_d(k)
        end do
      else if (present(element_edges)) then
        first(1:nel, :) = element_edges(1:nel, 1:3)
        second(1:nel, :) = element_edges(1:nel, 4:6)
      else
        first(1:nel, :) = 0.0_wp
        second(1:nel, :) = 0.0_wp
      end if
      call honeycomb_initialize_axes(nel, first, second, &
                                     history(:, honeycomb_axes_first_slot:honeycomb_axes_first_slot + 8))
    case (law_low_density_foam)
      call low_density_foam_initialize(nel, history)
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

  !> Plastic hardening modulus of *MAT_PLASTIC_KINEMATIC (and of the bilinear
  !> *MAT_PIECEWISE_LINEAR_PLASTICITY), E_p = E Etan / (E - Etan)
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
  !> Returns the dilatational wave modulus rho c^2 of each lane. *MAT_PIECEWISE_LINEAR_PLASTICITY
  !> reads material%curves(piecewise_hardening_curve) and (piecewise_rate_curve), which the
  !> deck's cross-check allocates (a curve without points: bilinear SIGY/ETAN, no LCSR).
  !> *MAT_NULL carries no stress (the deck admits it on shell parts only).
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
    ! A select case on the integer law code: the fastest dispatch here (a jump table, with the
    ! kernels free to take their own constants and be inlined). A procedure pointer per law
    ! would need one kernel interface taking material_t. The codes and what each law has come
    ! from law_table (material_laws).
    select case (material%law)
    case (law_elastic)
      call elastic_update(nel, bulk_modulus, shear_modulus, strain_increment, stress)
    case (law_plastic_kinematic)
      call plastic_kinematic_update(nel, bulk_modulus, shear_modulus, material%yield_stress, &
                                    plastic_hardening_modulus(material), material%hardening_beta, &
                                    material%rate_c, material%rate_p, material%rate_formulation > 0.5_wp, &
                                    time_step, strain_increment, stress, history(:, plastic_strain_slot), &
                                    history(:, back_stress_first_slot:back_stress_first_slot + 5))
    case (law_honeycomb, law_modified_honeycomb)
      call honeycomb_update(nel, material%law == law_modified_honeycomb, material%youngs_modulus, &
                            material%poissons_ratio, material%yield_stress, material%compaction_volume, &
                            material%viscosity, material%uncompacted_moduli, material%curves(1:6), &
                            material%curve_ids(honeycomb_rate_curve) > 0, material%curves(honeycomb_rate_curve), &
                            time_step, strain_increment, stress, history)
    case (law_low_density_foam)
      call low_density_foam_update(nel, material%youngs_modulus, material%curves(foam_loading_curve), &
                                   material%tension_cutoff, material%hysteretic_unloading, &
                                   material%unloading_shape, material%viscosity, foam_stiffness_bound(material), &
                                   strain_increment, stress, history)
    case (law_piecewise_linear)
      call piecewise_linear_update(nel, bulk_modulus, shear_modulus, material%curves(piecewise_hardening_curve), &
                                   material%yield_stress, plastic_hardening_modulus(material), &
                                   material%curves(piecewise_rate_curve), material%rate_c, material%rate_p, &
                                   material%rate_formulation > 0.5_wp, time_step, strain_increment, stress, &
                                   history(:, piecewise_plastic_strain_slot))
    case (law_mooney_rivlin)
      call rubber_update(nel, rubber_mooney_rivlin, rubber_constants(material), strain_increment, stress, history)
    case (law_blatz_ko)
      call rubber_update(nel, rubber_blatz_ko, rubber_constants(material), strain_increment, stress, history)
    case (law_viscoelastic)
      call viscoelastic_update(nel, bulk_modulus, shear_modulus, material%long_term_shear_modulus, &
                               material%decay_constant, time_step, strain_increment, stress, history)
    case (law_null)
      stress(1:nel, :) = 0.0_wp
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
    case (law_honeycomb, law_modified_honeycomb)
      ! The material axes a, b, c turn with the material.
      call rotate_vectors(nel, 3, rotation, history(:, honeycomb_axes_first_slot:honeycomb_axes_first_slot + 8))
    case (law_low_density_foam)
      ! B's Jaumann rate is D B + B D: the spin part is this rotation.
      call rotate_symmetric_tensors(nel, rotation, &
                                    history(:, foam_left_cauchy_green_first_slot:foam_left_cauchy_green_first_slot + 5))
    case (law_mooney_rivlin, law_blatz_ko, law_viscoelastic)
      ! the rubbers' b - I (b's Jaumann rate is D b + b D), the viscoelastic branch stress
      call rotate_symmetric_tensors(nel, rotation, history(:, 1:6))
    case default
      continue
    end select
  end subroutine rotate_material_history

  !> Dilatational wave modulus rho c^2 = K + 4G/3 = lambda + 2 mu of lanes 1..nel (the elastic
  !> and plastic laws use their elastic moduli, as LS-DYNA does for the time step). The
  !> honeycombs use the largest modulus they can reach, that of the compacted material (or an
  !> uncompacted normal modulus if larger), so that the time step needs no history; the foam
  !> uses max(E, steepest slope of its loading curve).
  subroutine material_wave_modulus(material, nel, wave_modulus)
    type(material_t), intent(in) :: material
    integer, intent(in) :: nel
    real(wp), intent(out) :: wave_modulus(block_size)
    real(wp) :: bulk_modulus, shear_modulus
    select case (material%law)
    case (law_low_density_foam)
      wave_modulus(1:nel) = foam_stiffness_bound(material)
    case default
      call elastic_moduli(material, bulk_modulus, shear_modulus)
      wave_modulus(1:nel) = bulk_modulus + 4.0_wp*shear_modulus/3.0_wp
      if (material%law == law_honeycomb .or. material%law == law_modified_honeycomb) &
        wave_modulus(1:nel) = max(wave_modulus(1:nel), maxval(material%uncompacted_moduli(1:3)))
    end select
  end subroutine material_wave_modulus

  !> Isotropic moduli (lambda, mu) that bound the material's incremental stiffness from above,
  !> d sigma : d epsilon <= lambda (tr d epsilon)^2 + 2 mu |d epsilon|^2, for the element
  !> eigenvalue bounds of the time step (element_time_step). The elastic and plastic laws:
  !> their elastic Lame constants (a plastic return only lowers the stiffness). The honeycombs:
  !> the compacted material's lambda, and a mu that also covers the uncoupled moduli of the
  !> partly compacted material (normal moduli up to K + 4G/3 of the compacted one, or the
  !> uncompacted E_ii: 2 mu >= each; shear moduli G_ij <= mu). The foam: lambda = 0 (its
  !> principal stresses are uncoupled) and 2 mu = its stiffness bound. The viscosity of these
  !> three (MU, DAMP: a stress VISC M D dt, a damping proportional to the stiffness with the
  !> current step) turns the stability condition dt^2 omega^2 <= 4 into
  !> dt^2 omega^2 (1 + 2 VISC) <= 4: both moduli are raised by that factor.
  pure subroutine material_stiffness_bounds(material, lame_bound, shear_bound)
    type(material_t), intent(in) :: material
    real(wp), intent(out) :: lame_bound, shear_bound
    real(wp) :: bulk_modulus, shear_modulus
    select case (material%law)
    case (law_low_density_foam)
      lame_bound = 0.0_wp
      shear_bound = 0.5_wp*foam_stiffness_bound(material)*(1.0_wp + 2.0_wp*max(material%viscosity, 0.0_wp))
    case default
      call elastic_moduli(material, bulk_modulus, shear_modulus)
      lame_bound = bulk_modulus - 2.0_wp*shear_modulus/3.0_wp
      shear_bound = shear_modulus
      if (material%law == law_honeycomb .or. material%law == law_modified_honeycomb) then
        shear_bound = max(0.5_wp*(bulk_modulus + 4.0_wp*shear_modulus/3.0_wp), &
                          0.5_wp*maxval(material%uncompacted_moduli(1:3)), maxval(material%uncompacted_moduli(4:6)))
        lame_bound = lame_bound*(1.0_wp + 2.0_wp*max(material%viscosity, 0.0_wp))
        shear_bound = shear_bound*(1.0_wp + 2.0_wp*max(material%viscosity, 0.0_wp))
      end if
    end select
  end subroutine material_stiffness_bounds

  !> The rubbers' constants for material_rubber: *MAT_MOONEY-RIVLIN_RUBBER A, B, C, D (from A, B,
  !> PR); *MAT_BLATZ-KO_RUBBER G (E / (2 (1 + nu)), the deck stores E = 2 G (1 + nu)) and
  !> beta = 1 / (1 - 2 nu), nu = 0.463.
  pure function rubber_constants(material) result(constants)
    type(material_t), intent(in) :: material
    real(wp) :: constants(4)
    if (material%law == law_mooney_rivlin) then
      constants = mooney_rivlin_constants(material%mooney_rivlin_a, material%mooney_rivlin_b, &
                                          material%poissons_ratio)
    else
      constants = [material%youngs_modulus/(2.0_wp*(1.0_wp + material%poissons_ratio)), &
                   1.0_wp/(1.0_wp - 2.0_wp*material%poissons_ratio), 0.0_wp, 0.0_wp]
    end if
  end function rubber_constants

  !> Stiffness bound of *MAT_LOW_DENSITY_FOAM: max(E, largest slope of the loading curve).
  pure function foam_stiffness_bound(material) result(modulus)
    type(material_t), intent(in) :: material
    real(wp) :: modulus
    integer :: k
    modulus = material%youngs_modulus
    associate (curve => material%curves(foam_loading_curve))
      do k = 1, size(curve%abscissa) - 1
        if (curve%abscissa(k + 1) > curve%abscissa(k)) modulus = max(modulus, &
          (curve%ordinate(k + 1) - curve%ordinate(k))/(curve%abscissa(k + 1) - curve%abscissa(k)))
      end do
    end associate
  end function foam_stiffness_bound

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
    case (law_piecewise_linear)
      plastic_strain(1:nel) = history(1:nel, piecewise_plastic_strain_slot)
    case default
      plastic_strain(1:nel) = 0.0_wp
    end select
  end subroutine material_plastic_strain
end module material_dispatch
