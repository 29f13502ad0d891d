!> Work of element forces integrated the way central differences integrate the kinetic energy
!> (see the comment at the top of solid_block), and the block's smallest stable step: shared by
!> the solid and shell blocks.
module element_work
  use kinds, only: wp, block_size
  implicit none
  private

  public :: add_force_work, smallest_time_step

contains

  !> Work of the forces of the previous call (power `last_power` against v(n-1/2) from that
  !> call, `old_power` against v(n+1/2) now) completed with the mean step of those two steps,
  !> minus the part of it booked by the previous call, plus the first half of the work of the
  !> new forces with the current step. `last_power` becomes `new_power` for the next call.
  subroutine add_force_work(nel, time_step, previous_time_step, old_power, new_power, last_power, energy)
    integer, intent(in) :: nel
    real(wp), intent(in) :: time_step, previous_time_step
    real(wp), intent(in) :: old_power(block_size), new_power(block_size)
    real(wp), intent(inout) :: last_power(block_size), energy(block_size)
    real(wp) :: mean_step
    integer :: i
    mean_step = 0.5_wp*(previous_time_step + time_step)
    do i = 1, nel
      energy(i) = energy(i) + 0.5_wp*mean_step*(last_power(i) + old_power(i)) &
                  - 0.5_wp*previous_time_step*last_power(i) + 0.5_wp*time_step*new_power(i)
      last_power(i) = new_power(i)
    end do
  end subroutine add_force_work

  !> The smallest of the lanes' stable steps (huge if none) and the element of that lane
  !> (`elements(lane)`; 0 if none).
  pure subroutine smallest_time_step(nel, element_time_step, elements, critical_time_step, critical_element)
    integer, intent(in) :: nel
    real(wp), intent(in) :: element_time_step(block_size)
    integer, intent(in) :: elements(block_size)
    real(wp), intent(out) :: critical_time_step
    integer, intent(out) :: critical_element
    integer :: i, lane
    critical_time_step = huge(1.0_wp)
    lane = 0
    do i = 1, nel
      if (element_time_step(i) < critical_time_step) then
        critical_time_step = element_time_step(i)
        lane = i
      end if
    end do
    critical_element = 0
    if (lane > 0) critical_element = elements(lane)
  end subroutine smallest_time_step
end module element_work
