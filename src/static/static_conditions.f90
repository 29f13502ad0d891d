!> Essential (kinematic) conditions of the linear static analysis at its end time:
!> *BOUNDARY_SPC dofs are zero, *BOUNDARY_PRESCRIBED_MOTION with VAD 2 (displacement) gives the
!> curve value at the end time. A static analysis has no velocity or acceleration, so VAD 0 and
!> VAD 1 are rejected rather than silently ignored.
!>
!> As in the explicit solver a prescribed motion overrides an SPC of the same dof, and of two
!> motions of one dof the later one counts. A motion whose birth-death window does not contain
!> the end time leaves its dof free (the explicit solver frees it after its death too).
module static_conditions
  use kinds, only: wp
  use error_handling, only: error_t, make_error
  use curves, only: curve_value
  use model, only: model_t, motion_displacement, motion_velocity
  use text_format, only: integer_text
  implicit none
  private

  public :: static_end_time, essential_conditions, static_curve_value

contains

  !> The time at which a static analysis evaluates its loads and conditions: ENDTIM, or 1.0 when
  !> the deck gives none (ENDTIM = 0), so that curves running from 0 to 1 give their full value.
  pure function static_end_time(model) result(time)
    type(model_t), intent(in) :: model
    real(wp) :: time
    time = model%end_time
    if (time <= 0.0_wp) time = 1.0_wp
  end function static_end_time

  !> Which dofs have an essential condition at `time` (`prescribed(direction, node)`) and its value
  !> (`values`, zero for SPCs).
  subroutine essential_conditions(model, time, prescribed, values, error)
    type(model_t), intent(in) :: model
    real(wp), intent(in) :: time
    logical, allocatable, intent(out) :: prescribed(:, :)
    real(wp), allocatable, intent(out) :: values(:, :)
    type(error_t), allocatable, intent(out) :: error
    character(len=:), allocatable :: listed
    integer :: k, rejected

    allocate (prescribed(3, size(model%node_ids)), values(3, size(model%node_ids)))
    prescribed = .false.
    values = 0.0_wp
    if (allocated(model%spcs)) then
      do k = 1, size(model%spcs)
        associate (node => model%spcs(k)%node)
          where (model%spcs(k)%fixed)
            prescribed(:, node) = .true.
            values(:, node) = 0.0_wp
          end where
        end associate
      end do
    end if
    if (.not. allocated(model%motions)) return

    rejected = 0
    listed = ""
    do k = 1, size(model%motions)
      associate (motion => model%motions(k))
        if (motion%kind /= motion_displacement) then
          rejected = rejected + 1
          if (rejected <= 5) listed = listed//" "//integer_text(model%node_ids(motion%node))// &
                                      trim(merge(" (VAD 0)", " (VAD 1)", motion%kind == motion_velocity))
          cycle
        end if
        if (time < motion%birth .or. time > motion%death) cycle
        prescribed(motion%direction, motion%node) = .true.
        values(motion%direction, motion%node) = motion%scale* &
                                                static_curve_value(model, motion%curve, time - motion%birth)
      end associate
    end do
    if (rejected > 0) then
      call make_error(error, "static analysis: "//integer_text(rejected)//" prescribed motion(s) are velocities "// &
                      "or accelerations, which a static analysis does not have; node id (VAD):"//listed// &
                      ". Prescribe displacements (*BOUNDARY_PRESCRIBED_MOTION VAD 2)")
    end if
  end subroutine essential_conditions

  !> Value of curve `curve` (an index; 0 means the constant 1) at `x`.
  pure function static_curve_value(model, curve, x) result(value)
    type(model_t), intent(in) :: model
    integer, intent(in) :: curve
    real(wp), intent(in) :: x
    real(wp) :: value
    value = 1.0_wp
    if (curve > 0) value = curve_value(model%curves(curve), x)
  end function static_curve_value
end module static_conditions
