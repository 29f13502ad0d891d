!> Work of element forces integrated the way central differences integrate the kinetic energy
!> (see the comment at the top of solid_block), and the block's smallest stable step: shared by
!> the solid and shell blocks; and the shares of energy every element kind reports the same way.
module element_work
  use kinds, only: wp, block_size
  implicit none
  private

  public :: append_marked_lanes, mark_lanes
  public :: add_force_work, smallest_time_step, booked_energy, lane_energy_sums, block_energy_column, add_kinetic_energy, &
            scale_block_density, raise_largest_scaling

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

  !> A block's energy as the solver reports it, from its lanes' sums (lane_energy_sums): the
  !> work booked by the elements plus the step correction of their newest forces' power (see
  !> solid_block).
  pure real(wp) function booked_energy(energy_sum, power_sum, step_correction)
    real(wp), intent(in) :: energy_sum, power_sum, step_correction
    booked_energy = energy_sum + step_correction*power_sum
  end function booked_energy

  !> The sums over the first `count` lanes of a block that its energies need (element_group's
  !> block_energy): the energy and the power of the live lanes (booked_energy adds them), and
  !> the energy the eroded lanes (`eroded`) took along, reported apart (their powers are zero).
  pure function lane_energy_sums(energy, power, count, eroded) result(sums)
    real(wp), intent(in) :: energy(:), power(:)
    integer, intent(in) :: count
    logical, intent(in), optional :: eroded(:)
    real(wp) :: sums(3)
    logical :: some_eroded
    some_eroded = .false.
    if (present(eroded)) some_eroded = any(eroded(1:count))
    if (some_eroded) then
      sums(1) = sum(energy(1:count), mask=.not. eroded(1:count))
      sums(2) = sum(power(1:count), mask=.not. eroded(1:count))
      sums(3) = sum(energy(1:count), mask=eroded(1:count))
    else
      sums(1) = sum(energy(1:count))
      sums(2) = sum(power(1:count))
      sums(3) = 0.0_wp
    end if
  end function lane_energy_sums

  !> A block's column of element_group's block_energy from its lanes' internal and hourglass
  !> energies and powers: live internal energy and power, live hourglass energy and power,
  !> eroded internal and hourglass energy.
  pure function block_energy_column(internal, internal_power, hourglass, hourglass_power, count, eroded) &
    result(column)
    real(wp), intent(in) :: internal(:), internal_power(:), hourglass(:), hourglass_power(:)
    integer, intent(in) :: count
    logical, intent(in) :: eroded(:)
    real(wp) :: column(6)
    real(wp) :: internal_sums(3), hourglass_sums(3)
    internal_sums = lane_energy_sums(internal, internal_power, count, eroded)
    hourglass_sums = lane_energy_sums(hourglass, hourglass_power, count, eroded)
    column = [internal_sums(1:2), hourglass_sums(1:2), internal_sums(3), hourglass_sums(3)]
  end function block_energy_column

  !> Append to `elements` (`n` used) the elements (`lane_elements`) of the first `count` lanes
  !> of a block that `marked` flags, as long as there is room: the elements an element group
  !> eroded in its last force call, block after block.
  pure subroutine append_marked_lanes(count, marked, lane_elements, elements, n)
    integer, intent(in) :: count, lane_elements(:)
    logical, intent(in) :: marked(:)
    integer, intent(inout) :: elements(:), n
    integer :: lane
    do lane = 1, count
      if (.not. marked(lane) .or. n >= size(elements)) cycle
      n = n + 1
      elements(n) = lane_elements(lane)
    end do
  end subroutine append_marked_lanes

  !> Set `mask(lane_elements(lane))` for the first `count` lanes of a block that `marked` flags
  !> (a group's eroded elements in the model-indexed masks the contacts read).
  pure subroutine mark_lanes(count, marked, lane_elements, mask)
    integer, intent(in) :: count, lane_elements(:)
    logical, intent(in) :: marked(:)
    logical, intent(inout) :: mask(:)
    integer :: lane
    do lane = 1, count
      if (marked(lane)) mask(lane_elements(lane)) = .true.
    end do
  end subroutine mark_lanes

  !> Add a mass's share of the conserved kinetic energy 1/2 m v^{n-1/2} . v^{n+1/2}, split as
  !> explained at energy_balance: 1/2 m (v^n)^2 to `kinetic`, -1/8 m (dt a)^2 to `internal`.
  !> `velocity` is v^{n-1/2}, `average_step` the mean of the steps around t^n.
  pure subroutine add_kinetic_energy(mass, velocity, acceleration, average_step, kinetic, internal)
    real(wp), intent(in) :: mass, velocity(3), acceleration(3), average_step
    real(wp), intent(inout) :: kinetic, internal
    real(wp) :: half_change(3), midpoint(3)
    half_change = 0.5_wp*average_step*acceleration
    midpoint = velocity + half_change
    kinetic = kinetic + 0.5_wp*mass*dot_product(midpoint, midpoint)
    internal = internal - 0.5_wp*mass*dot_product(half_change, half_change)
  end subroutine add_kinetic_energy

  !> One block of mass scaling: its physical mass, then each lane whose step is below
  !> `target_step` (> 0) gets the density that brings its step to it (the step scales with
  !> 1/sqrt(rho)), and the mass added.
  subroutine scale_block_density(nel, volume, target_step, element_time_step, density, physical_mass, added_mass)
    integer, intent(in) :: nel
    real(wp), intent(in) :: volume(block_size), target_step, element_time_step(block_size)
    real(wp), intent(inout) :: density(block_size), physical_mass, added_mass
    real(wp) :: factor
    integer :: i
    physical_mass = physical_mass + sum(density(1:nel)*volume(1:nel))
    if (target_step <= 0.0_wp) return
    do i = 1, nel
      if (element_time_step(i) >= target_step) cycle
      factor = (target_step/element_time_step(i))**2
      added_mass = added_mass + (factor - 1.0_wp)*density(i)*volume(i)
      density(i) = density(i)*factor
    end do
  end subroutine scale_block_density

  !> The lane whose density mass scaling raised most over the material's, when above `largest`:
  !> `largest` and `element` (its entry of `elements`) are raised (the mass-scaling report).
  pure subroutine raise_largest_scaling(nel, density, material_density, elements, largest, element)
    integer, intent(in) :: nel
    real(wp), intent(in) :: density(block_size), material_density
    integer, intent(in) :: elements(block_size)
    real(wp), intent(inout) :: largest
    integer, intent(inout) :: element
    integer :: i
    if (.not. material_density > 0.0_wp) return
    do i = 1, nel
      if (density(i)/material_density > largest) then
        largest = density(i)/material_density
        element = elements(i)
      end if
    end do
  end subroutine raise_largest_scaling
end module element_work
