!> Stable time step and artificial bulk viscosity of solid elements, on a block of elements
!> (LS-DYNA Theory Manual, "Time step control" and "Artificial bulk viscosity"; Hallquist,
!> DYNA3D; von Neumann & Richtmyer 1950, Landshoff 1955 for the linear term).
!>
!>   bulk viscosity   q = rho l (Q1^2 l (tr D)^2 - Q2 c tr D)  if tr D < 0, else 0,  l = V^(1/3)
!>   time step        the smaller of
!>   - LS-DYNA's rule dt = L / (Q + sqrt(Q^2 + c^2)),  L = V / (largest face area),
!>                    Q = Q2 c + Q1 L |tr D| if tr D < 0, else 0
!>     (solid_element_time_steps; the meshfree integration points use it alone), and
!>   - the element's eigenvalue bound (eigenvalue_time_steps): the step at which the central
!>     difference scheme becomes unstable for the element alone, from bounds on the largest
!>     frequency and damping rate of its lumped-mass eigenproblem (docs/solver.md, "Time step").
!> The first is not safe for a free element: the volumetric mode of a cube of one-point or
!> selective-reduced hexahedra has omega^2 = 4 (3 lambda + 2 mu) / (rho L^2) (every node
!> moving out along its diagonal), so it needs dt <= L / c sqrt((lambda + 2 mu) /
!> (3 lambda + 2 mu)) = 0.73 L / c at nu = 0.3, 0.59 at nu = 0.49; a mesh's largest frequency is
!> at most its elements' (the element eigenvalue theorem), so the bound is safe in any mesh.
!> c = sqrt((K + 4G/3) / rho_block) is the dilatational wave speed at the block's (possibly
!> mass-scaled) density and rho in q the current density. q is added to the pressure in the
!> force computation and its work to the internal energy (by the element drivers).
module element_time_step
  use kinds, only: wp, block_size
  implicit none
  private

  public :: bulk_viscosity_pressure, solid_element_time_steps, eigenvalue_time_steps

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

  !> Lowers each lane's step to the element's eigenvalue bound. The central difference scheme
  !> with the viscous forces of the last half step is stable while dt^2 M^-1 K + 2 dt M^-1 C <= 4
  !> (scalar case: z^2 - (2 - dt^2 omega^2 - dt beta) z + 1 - dt beta has its roots in the unit
  !> circle iff dt^2 omega^2 + 2 dt beta <= 4). The element's stiffness K and damping C split
  !> into parts acting on two subspaces of nodal motions:
  !> - U, the uniform-strain modes (span of the volume derivatives b in each direction): the
  !>   one-point stiffness, with omega_U^2 = 8 (V / V0) / rho_block (lambda tr G + 2 mu
  !>   lambda_max(G)) (exact for it: its 9 nonzero eigenvalues are those of lambda s s^T +
  !>   2 mu diag(g), g the eigenvalues of G = sum_I b_I b_I^T / V^2, s_i = sqrt(g_i), and
  !>   mu (g_i + g_j); lambda s s^T <= lambda tr G). The bulk viscosity enters in compression
  !>   as LS-DYNA's rule counts it, with the damping ratio Q2 + Q1 L |tr D| / c that
  !>   L / (Q + sqrt(Q^2 + c^2)) gives a row of elements: beta_U = 2 Q2 omega_U + 4 Q1 |tr D|.
  !>   (The pressure q = rho l (Q1^2 l (tr D)^2 - Q2 c tr D), l = V^(1/3), damps the volumetric
  !>   mode of a lone element harder: 8 tr G l (Q2 c + ...), a ratio 3 Q2 on a cube and near
  !>   0.4 on the flattened elements of the Taylor bar's impact face. Counted in full, the
  !>   Taylor bar needed 12,191 cycles instead of 9,184; counted as here, the kicked one- and
  !>   two-element decks stay stable at TSSFAC 0.9, and the 0.1 margin covers the rest, as it
  !>   does for LS-DYNA's rule.)
  !> - W, the other modes (hourglass modes of ELFORM 1, extra deviatoric modes of ELFORM 2):
  !>   omega_W^2 and beta_W from the caller.
  !> With cos^2 theta <= `overlap` (r = sqrt(overlap)) between U and W, the largest eigenvalue of
  !> dt^2 M^-1 K + 2 dt M^-1 C is at most (u + w)/2 + sqrt((u - w)^2/4 + r^2 u w) <=
  !> max(u, w) + r min(u, w), u and w those of the two parts, so it stays below 4 if
  !> u + r w <= 4 and w + r u <= 4: two conditions a dt^2 + 2 b dt <= 4, each met up to
  !> dt = 4 / (b + sqrt(b^2 + 4 a)). `lame_bound`, `shear_bound` bound the material's stiffness
  !> (material_stiffness_bounds).
  subroutine eigenvalue_time_steps(nel, bulk_quadratic, bulk_linear, lame_bound, shear_bound, reference_volume, &
                                   volume, density, volumetric_rate, trace_g, largest_g, overlap, &
                                   mode_frequency_squared, mode_damping, time_step)
    integer, intent(in) :: nel
    real(wp), intent(in) :: bulk_quadratic, bulk_linear, lame_bound, shear_bound
    real(wp), intent(in) :: reference_volume(block_size), volume(block_size), density(block_size)
    real(wp), intent(in) :: volumetric_rate(block_size)
    real(wp), intent(in) :: trace_g(block_size), largest_g(block_size), overlap(block_size)
    real(wp), intent(in) :: mode_frequency_squared(block_size), mode_damping(block_size)
    real(wp), intent(inout) :: time_step(block_size)
    real(wp) :: frequency_squared, damping, cosine, compressing, stiffness, viscous, first, second
    integer :: i
    do i = 1, nel
      frequency_squared = 8.0_wp*abs(volume(i))/max(density(i)*reference_volume(i), tiny(1.0_wp)) &
                          *(lame_bound*trace_g(i) + 2.0_wp*shear_bound*largest_g(i))
      ! no element that can run has rates near these caps; an inverted one (the solver stops)
      ! must not overflow
      frequency_squared = min(frequency_squared, 1.0e300_wp)
      ! 1 in compression, 0 otherwise (a select of constants keeps the loop branch-free)
      compressing = merge(1.0_wp, 0.0_wp, volumetric_rate(i) < 0.0_wp)
      damping = min(compressing*(2.0_wp*bulk_linear*sqrt(frequency_squared) &
                                 + 4.0_wp*bulk_quadratic*abs(volumetric_rate(i))), 1.0e150_wp)
      cosine = sqrt(min(max(overlap(i), 0.0_wp), 1.0_wp))
      stiffness = frequency_squared + cosine*min(mode_frequency_squared(i), 1.0e300_wp)
      viscous = damping + cosine*min(mode_damping(i), 1.0e150_wp)
      ! (a lane without stiffness or damping gets huge, not an overflow)
      first = 4.0_wp/max(viscous + sqrt(viscous**2 + 4.0_wp*stiffness), 4.0_wp/huge(1.0_wp))
      stiffness = min(mode_frequency_squared(i), 1.0e300_wp) + cosine*frequency_squared
      viscous = min(mode_damping(i), 1.0e150_wp) + cosine*damping
      second = 4.0_wp/max(viscous + sqrt(viscous**2 + 4.0_wp*stiffness), 4.0_wp/huge(1.0_wp))
      time_step(i) = min(time_step(i), first, second)
    end do
  end subroutine eigenvalue_time_steps
end module element_time_step
