!> *MAT_SPOTWELD (LS-DYNA material 100) failure of a beam weld: the plasticity of its points is
!> beam_point_plasticity's (SIGY, ET); this module decides when the weld breaks.
!>
!> A weld fails, and carries no force from that cycle on, when any of these is met:
!> - TFAIL > 0 and the time has reached TFAIL;
!> - EFAIL > 0 and the plastic strain at every integration point of its section has reached EFAIL;
!> - the resultant criterion, when some of NRR NRS NRT MRR MSS MTT are > 0 (LS-DYNA's Keyword
!>   Manual, *MAT_SPOTWELD, beam welds):
!>     (max(N_rr, 0)/NRR)^2 + (N_rs/NRS)^2 + (N_rt/NRT)^2 + (M_rr/MRR)^2 + (M_ss/MSS)^2
!>       + (M_tt/MTT)^2 >= 1,
!>   terms whose failure value is 0 left out; r is the beam's axis (N_rr the axial force, only
!>   tension counts), s and t its section axes, M_rr the torsion.
module material_spotweld
  use kinds, only: wp
  use model, only: material_t
  use material_laws, only: law_spotweld
  implicit none
  private

  public :: spotweld_fails, spotweld_failure_measure

contains

  !> The left-hand side of the resultant criterion (0 when no resultant is given).
  !> `resultants` = N_rr, N_rs, N_rt, M_rr, M_ss, M_tt.
  pure real(wp) function spotweld_failure_measure(material, resultants)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: resultants(6)
    real(wp) :: value
    integer :: k
    spotweld_failure_measure = 0.0_wp
    do k = 1, 6
      if (.not. material%failure_resultants(k) > 0.0_wp) cycle
      value = resultants(k)
      if (k == 1) value = max(value, 0.0_wp)
      spotweld_failure_measure = spotweld_failure_measure + (value/material%failure_resultants(k))**2
    end do
  end function spotweld_failure_measure

  !> Whether a weld of `material` fails now (false for any other law).
  pure logical function spotweld_fails(material, time, resultants, plastic_strain)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: time, resultants(6), plastic_strain(:)
    spotweld_fails = .false.
    if (material%law /= law_spotweld) return
    if (material%failure_time > 0.0_wp .and. time >= material%failure_time) spotweld_fails = .true.
    if (material%failure_plastic_strain > 0.0_wp .and. size(plastic_strain) > 0) then
      if (all(plastic_strain >= material%failure_plastic_strain)) spotweld_fails = .true.
    end if
    if (any(material%failure_resultants > 0.0_wp)) then
      if (spotweld_failure_measure(material, resultants) >= 1.0_wp) spotweld_fails = .true.
    end if
  end function spotweld_fails
end module material_spotweld
