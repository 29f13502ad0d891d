!> Stable time step and artificial bulk viscosity of solid elements, on a block of elements
!> (LS-DYNA Theory Manual, "Time step control" and "Artificial bulk viscosity"; Hallquist,
!> DYNA3D; von Neumann & Richtmyer 1950, Landshoff 1955 for the linear term).
!>
!>   bulk viscosity   q = rho l (Q1^2 l (tr D)^2 - Q2 c tr D)  if tr D < 0, else 0,  l = V^(1/3)
!>   time step        dt = L / (Q + sqrt(Q^2 + c^2)),  L = V / (largest face area),
!>                    Q = Q2 c + Q1 L |tr D| if tr D < 0, else 0
!> with c = sqrt((K + 4G/3) / rho_block) the dilatational wave speed at the block's (possibly
!> mass-scaled) density and rho in q the current density. q is added to the pressure in the
!> force computation and its work to the internal energy (by the element drivers).
module element_time_step
  use kinds, only: wp, block_size
  implicit none
  private

  public :: bulk_viscosity_pressure, solid_element_time_steps

contains

  !> Bulk viscosity q of each element from its current density, wave speed, current volume and
  !> volumetric strain rate tr D (branch-free: tr D >= 0 gives q = 0).
  subroutine bulk_viscosity_pressure(nel, bulk_quadratic, bulk_linear, density, sound_speed, volume, &
                                     volumetric_rate, bulk_viscosity)
    integer, intent(in) :: nel
    real(wp), intent(in) :: bulk_quadratic, bulk_linear
    real(wp), intent(in) :: density(block_size), sound_speed(block_size), volume(block_size)
    real(wp), intent(in) :: volumetric_rate(block_size)
    real(wp), intent(out) :: bulk_viscosity(block_size)
    real(wp) :: compression, length
    integer :: i
    do i = 1, nel
      compression = min(volumetric_rate(i), 0.0_wp)
      length = abs(volume(i))**(1.0_wp/3.0_wp)
      bulk_viscosity(i) = density(i)*length*(bulk_quadratic**2*length*compression**2 &
                                             - bulk_linear*sound_speed(i)*compression)
    end do
  end subroutine bulk_viscosity_pressure

  !> Stable step of each element (no TSSFAC) from its volume, largest face area, wave modulus
  !> rho c^2, density and volumetric strain rate (pass zero rates for the step at rest).
  subroutine solid_element_time_steps(nel, bulk_quadratic, bulk_linear, volume, largest_face_area, &
                                      wave_modulus, density, volumetric_rate, time_step)
    integer, intent(in) :: nel
    real(wp), intent(in) :: bulk_quadratic, bulk_linear
    real(wp), intent(in) :: volume(block_size), largest_face_area(block_size)
    real(wp), intent(in) :: wave_modulus(block_size), density(block_size), volumetric_rate(block_size)
    real(wp), intent(out) :: time_step(block_size)
    real(wp) :: length, sound_speed, viscous, compressing
    integer :: i
    do i = 1, nel
      length = volume(i)/max(largest_face_area(i), tiny(1.0_wp))
      sound_speed = sqrt(max(wave_modulus(i), 0.0_wp)/max(density(i), tiny(1.0_wp)))
      ! 1 in compression, 0 otherwise (a select of constants keeps the loop branch-free)
      compressing = merge(1.0_wp, 0.0_wp, volumetric_rate(i) < 0.0_wp)
      viscous = compressing*(bulk_linear*sound_speed - bulk_quadratic*length*volumetric_rate(i))
      time_step(i) = length/max(viscous + sqrt(viscous**2 + sound_speed**2), tiny(1.0_wp))
    end do
  end subroutine solid_element_time_steps
end module element_time_step
