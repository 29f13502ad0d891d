!> Element failure (erosion) criteria of a material, as LS-DYNA applies them: the failure
!> strain of the plasticity laws (FS of MAT_003, FAIL of MAT_024) and the strain criteria of
!> *MAT_ADD_EROSION (EFFEPS, MXEPS, MNEPS). The element kinds evaluate them on their points
!> after the stress update and erode an element that meets one (see docs/materials.md).
!>
!> Principal strains are logarithmic, from the deformation gradient F of the element centre
!> against its reference configuration: ln of the principal stretches, 1/2 ln of the
!> eigenvalues of C = F^T F. For the coaxial stretching of a bar or a plate this is the
!> integral of the rate of deformation, the strain LS-DYNA accumulates.
module erosion_criteria
  use kinds, only: wp
  use model, only: material_t
  use small_tensors, only: determinant3
  implicit none
  private

  public :: erodes_on_strain, plastic_failure_limit, principal_strains_active, failed_points_needed
  public :: principal_log_strains_3d, principal_log_strains_2d, principal_strains_fail

  !> A failure strain at or above this means "no failure" (LS-DYNA's default is 1e21).
  real(wp), parameter :: no_failure = 1.0e20_wp

contains

  !> The effective plastic strain at which a point fails: the smaller of FS / FAIL and EFFEPS
  !> (huge when neither is set).
  pure real(wp) function plastic_failure_limit(material) result(limit)
    type(material_t), intent(in) :: material
    limit = huge(1.0_wp)
    if (material%failure_strain > 0.0_wp .and. material%failure_strain < no_failure) &
      limit = material%failure_strain
    if (material%erosion_plastic_strain > 0.0_wp) limit = min(limit, material%erosion_plastic_strain)
  end function plastic_failure_limit

  !> Whether MXEPS or MNEPS is set (the kinds then compute the centre's principal strains).
  pure logical function principal_strains_active(material)
    type(material_t), intent(in) :: material
    principal_strains_active = material%erosion_max_principal_strain > 0.0_wp .or. &
                               material%erosion_min_principal_strain < 0.0_wp
  end function principal_strains_active

  !> Whether any strain criterion of the material can erode an element.
  pure logical function erodes_on_strain(material)
    type(material_t), intent(in) :: material
    erodes_on_strain = plastic_failure_limit(material) < huge(1.0_wp) .or. principal_strains_active(material)
  end function erodes_on_strain

  !> Whether the principal strains `largest` and `smallest` of an element centre meet MXEPS or
  !> MNEPS of `material` (a criterion left at 0 is off).
  pure logical function principal_strains_fail(material, largest, smallest) result(fails)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: largest, smallest
    fails = (material%erosion_max_principal_strain > 0.0_wp .and. largest >= material%erosion_max_principal_strain) &
            .or. (material%erosion_min_principal_strain < 0.0_wp .and. smallest <= material%erosion_min_principal_strain)
  end function principal_strains_fail

  !> Failed points after which an element of `point_count` points erodes. Without
  !> *MAT_ADD_EROSION: one for a solid, all of them for a shell (LS-DYNA deletes a shell whose
  !> points through the thickness have all failed). With it: NUMFIP (blank: 1; > 0 a count;
  !> < 0 a percentage of a shell's points), at least 1 and at most all.
  pure integer function failed_points_needed(material, point_count, shell) result(needed)
    type(material_t), intent(in) :: material
    integer, intent(in) :: point_count
    logical, intent(in) :: shell
    if (.not. material%has_add_erosion) then
      needed = merge(point_count, 1, shell)
    else if (material%erosion_failed_points > 0.0_wp) then
      needed = nint(material%erosion_failed_points)
    else if (material%erosion_failed_points < 0.0_wp .and. shell) then
      needed = ceiling(-0.01_wp*material%erosion_failed_points*point_count - 1.0e-9_wp)
    else
      needed = 1
    end if
    needed = max(1, min(point_count, needed))
  end function failed_points_needed

  !> Largest and smallest logarithmic principal strain of a 3D deformation gradient F(3, 3).
  pure subroutine principal_log_strains_3d(f, largest, smallest)
    real(wp), intent(in) :: f(3, 3)
    real(wp), intent(out) :: largest, smallest
    real(wp) :: c(3, 3), mean, shifted(3, 3), p1, p2, p, r, phi, e1, e3
    c = matmul(transpose(f), f)
    ! eigenvalues of a symmetric 3x3 matrix by the trigonometric form of the cubic
    p1 = c(1, 2)**2 + c(1, 3)**2 + c(2, 3)**2
    mean = (c(1, 1) + c(2, 2) + c(3, 3))/3.0_wp
    p2 = (c(1, 1) - mean)**2 + (c(2, 2) - mean)**2 + (c(3, 3) - mean)**2 + 2.0_wp*p1
    if (p2 <= epsilon(1.0_wp)**2*mean**2) then
      e1 = mean
      e3 = mean
    else
      p = sqrt(p2/6.0_wp)
      shifted = c
      shifted(1, 1) = shifted(1, 1) - mean
      shifted(2, 2) = shifted(2, 2) - mean
      shifted(3, 3) = shifted(3, 3) - mean
      shifted = shifted/p
      r = 0.5_wp*determinant3(shifted)
      r = max(-1.0_wp, min(1.0_wp, r))
      phi = acos(r)/3.0_wp
      e1 = mean + 2.0_wp*p*cos(phi)
      e3 = mean + 2.0_wp*p*cos(phi + 2.0_wp*acos(-1.0_wp)/3.0_wp)
    end if
    largest = 0.5_wp*log(max(e1, tiny(1.0_wp)))
    smallest = 0.5_wp*log(max(e3, tiny(1.0_wp)))
  end subroutine principal_log_strains_3d

  !> Largest and smallest logarithmic principal strain of an in-plane deformation gradient F(2, 2).
  pure subroutine principal_log_strains_2d(f, largest, smallest)
    real(wp), intent(in) :: f(2, 2)
    real(wp), intent(out) :: largest, smallest
    real(wp) :: c11, c22, c12, mean, radius
    c11 = f(1, 1)**2 + f(2, 1)**2
    c22 = f(1, 2)**2 + f(2, 2)**2
    c12 = f(1, 1)*f(1, 2) + f(2, 1)*f(2, 2)
    mean = 0.5_wp*(c11 + c22)
    radius = sqrt(0.25_wp*(c11 - c22)**2 + c12**2)
    largest = 0.5_wp*log(max(mean + radius, tiny(1.0_wp)))
    smallest = 0.5_wp*log(max(mean - radius, tiny(1.0_wp)))
  end subroutine principal_log_strains_2d

end module erosion_criteria
