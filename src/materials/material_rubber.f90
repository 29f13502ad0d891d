!> The rubbers *MAT_MOONEY-RIVLIN_RUBBER (LS-DYNA material 27) and *MAT_BLATZ-KO_RUBBER
!> (material 7), for solids and for plane stress (shells), as functions of the left
!> Cauchy-Green tensor b = F F^T (LS-DYNA Theory Manual, "Material Model 27: Mooney-Rivlin
!> Rubber" and "Material Model 7: Continuum Rubber"; see docs/materials.md):
!>
!> - Mooney-Rivlin: W = A (I1 - 3) + B (I2 - 3) + C (I3^-2 - 1) + D (I3 - 1)^2 with
!>   C = A/2 + B and D = (A (5 nu - 2) + B (11 nu - 5)) / (2 (1 - 2 nu)), so that the
!>   undeformed state is stress-free and the small-strain moduli are G = 2 (A + B) and the
!>   Poisson's ratio nu. Cauchy stress, from W(I1, I2, I3) of b:
!>   sigma = (2 / J) [(W1 + I1 W2) b - W2 b^2 + I3 W3 I], J = sqrt(I3), with W1 = A, W2 = B,
!>   W3 = -2 C I3^-3 + 2 D (I3 - 1).
!> - Blatz-Ko: the Theory Manual's second Piola-Kirchhoff stress
!>   S = G (C / V - V^(-1 / (1 - 2 nu)) I), V = J the relative volume, C = F^T F, nu = 0.463;
!>   pushed forward, sigma = F S F^T / J = (G / J) (b^2 / J - J^-beta b), beta = 1 / (1 - 2 nu).
!>   Its small-strain limit is linear elasticity with shear modulus G and Poisson's ratio nu;
!>   its uniaxial stress state has the lateral stretch lambda^-nu exactly.
!>
!> How the deformation gets here: the elements pass strain increments D dt and rotate the
!> history with the stress (the Jaumann rate of b is D b + b D plus the spin terms). b is kept
!> as history and updated by b <- M b M^T with M = (I - D dt / 2)^-1 (I + D dt / 2), which is
!> exact for a stretch along fixed axes when D is taken at the mid-step configuration (as the
!> elements do): (1 + d/2) / (1 - d/2) = lambda(n+1) / lambda(n) for d = 2 (lambda(n+1) -
!> lambda(n)) / (lambda(n+1) + lambda(n)). The history holds b - I, so that zero history is the
!> undeformed state.
!>
!> Plane stress: b = diag-block(b2, x) with b2 the in-plane 2x2 block (in the shell's local
!> frame) and x = lambda_3^2 the thickness stretch squared, found at every point so that
!> sigma_33 = 0: Blatz-Ko in closed form (x = det(b2)^((1 - beta) / (1 + beta))), Mooney-Rivlin
!> by Newton's method on f(x) = (A + B tr b2) x - 2 C (d x)^-2 + 2 D d x (d x - 1) = J sigma_33 / 2
!> (d = det b2), from the last step's x, safeguarded by bisection, to a relative change of x
!> below rubber_thickness_tolerance (2 to 3 iterations per step at explicit steps).
module material_rubber
  use kinds, only: wp, block_size
  use small_tensors, only: determinant3, symmetric_matrix, symmetric_components, midpoint_update
  implicit none
  private

  public :: rubber_update, rubber_plane_stress_update, rubber_cauchy_stress
  public :: rubber_plane_stress_thickness, mooney_rivlin_constants, mooney_rivlin_fit

  !> The two rubbers (the `form` argument).
  integer, parameter, public :: rubber_mooney_rivlin = 1, rubber_blatz_ko = 2
  !> Relative change of the thickness stretch squared at which the plane-stress Newton
  !> iteration of Mooney-Rivlin stops, and its iteration limit (bisection steps included).
  real(wp), parameter, public :: rubber_thickness_tolerance = 1.0e-13_wp
  integer, parameter, public :: rubber_thickness_iterations = 60

contains

  !> Mooney-Rivlin's [A, B, C, D] from A, B and Poisson's ratio nu (module notes).
  pure function mooney_rivlin_constants(a, b, poissons_ratio) result(constants)
    real(wp), intent(in) :: a, b, poissons_ratio
    real(wp) :: constants(4)
    constants(1) = a
    constants(2) = b
    constants(3) = 0.5_wp*a + b
    constants(4) = (a*(5.0_wp*poissons_ratio - 2.0_wp) + b*(11.0_wp*poissons_ratio - 5.0_wp))/ &
                   (2.0_wp*(1.0_wp - 2.0_wp*poissons_ratio))
  end function mooney_rivlin_constants

  !> Least-squares A and B of Mooney-Rivlin from a uniaxial test: `stretch` lambda_i and nominal
  !> stress `nominal` P_i (force over the undeformed section), fitted to the incompressible
  !> uniaxial curve P = 2 (lambda - lambda^-2) (A + B / lambda), which is linear in A and B: the
  !> 2x2 normal equations. Points at lambda = 1 carry no information and are skipped. `fitted`
  !> is false when fewer than two distinct stretches remain (singular normal equations).
  pure subroutine mooney_rivlin_fit(stretch, nominal, a, b, fitted)
    real(wp), intent(in) :: stretch(:), nominal(:)
    real(wp), intent(out) :: a, b
    logical, intent(out) :: fitted
    real(wp) :: normal(2, 2), right(2), first, second, determinant_of_normal
    integer :: k
    normal = 0.0_wp
    right = 0.0_wp
    do k = 1, size(stretch)
      if (.not. stretch(k) > 0.0_wp) cycle
      first = 2.0_wp*(stretch(k) - 1.0_wp/stretch(k)**2)
      second = first/stretch(k)
      normal(1, 1) = normal(1, 1) + first*first
      normal(1, 2) = normal(1, 2) + first*second
      normal(2, 2) = normal(2, 2) + second*second
      right(1) = right(1) + first*nominal(k)
      right(2) = right(2) + second*nominal(k)
    end do
    determinant_of_normal = normal(1, 1)*normal(2, 2) - normal(1, 2)**2
    fitted = determinant_of_normal > 1.0e-12_wp*max(normal(1, 1)*normal(2, 2), tiny(1.0_wp))
    a = 0.0_wp
    b = 0.0_wp
    if (.not. fitted) return
    a = (normal(2, 2)*right(1) - normal(1, 2)*right(2))/determinant_of_normal
    b = (normal(1, 1)*right(2) - normal(1, 2)*right(1))/determinant_of_normal
  end subroutine mooney_rivlin_fit

  !> Cauchy stress of left Cauchy-Green tensor `b` (3x3). `constants`: Mooney-Rivlin A, B, C, D;
  !> Blatz-Ko G, beta = 1 / (1 - 2 nu) (the rest unused).
  pure function rubber_cauchy_stress(form, constants, b) result(stress)
    integer, intent(in) :: form
    real(wp), intent(in) :: constants(4), b(3, 3)
    real(wp) :: stress(3, 3)
    real(wp) :: squared(3, 3), first, third, volume, derivative
    integer :: k
    squared = matmul(b, b)
    third = max(determinant3(b), tiny(1.0_wp))
    volume = sqrt(third)
    if (form == rubber_mooney_rivlin) then
      first = b(1, 1) + b(2, 2) + b(3, 3)
      derivative = -2.0_wp*constants(3)/third**3 + 2.0_wp*constants(4)*(third - 1.0_wp)
      stress = (2.0_wp/volume)*((constants(1) + first*constants(2))*b - constants(2)*squared)
      do k = 1, 3
        stress(k, k) = stress(k, k) + 2.0_wp*volume*derivative
      end do
    else
      stress = (constants(1)/volume)*(squared/volume - volume**(-constants(2))*b)
    end if
  end function rubber_cauchy_stress

  !> Solid update of lanes 1..nel: b from the strain increments (TENSOR shear components, xx yy
  !> zz xy yz zx), then the stress in total from b. history(:, 1:6): b - I.
  subroutine rubber_update(nel, form, constants, strain_increment, stress, history)
    integer, intent(in) :: nel, form
    real(wp), intent(in) :: constants(4)
    real(wp), intent(in) :: strain_increment(block_size, 6)
    real(wp), intent(inout) :: stress(block_size, 6)
    real(wp), intent(inout), contiguous :: history(:, :)
    real(wp) :: b(3, 3), update(3, 3), lane(6)
    integer :: i
    do i = 1, nel
      lane = strain_increment(i, :)
      update = midpoint_update(symmetric_matrix(lane))
      lane = history(i, 1:6)
      b = symmetric_matrix(lane)
      b(1, 1) = b(1, 1) + 1.0_wp
      b(2, 2) = b(2, 2) + 1.0_wp
      b(3, 3) = b(3, 3) + 1.0_wp
      b = matmul(update, matmul(b, transpose(update)))
      stress(i, :) = symmetric_components(rubber_cauchy_stress(form, constants, b))
      b(1, 1) = b(1, 1) - 1.0_wp
      b(2, 2) = b(2, 2) - 1.0_wp
      b(3, 3) = b(3, 3) - 1.0_wp
      history(i, 1:6) = symmetric_components(b)
    end do
  end subroutine rubber_update

  !> Plane-stress update of lanes 1..nel in the shell's local frame: strain increments d eps_xx,
  !> d eps_yy, d gamma_xy (ENGINEERING shear); history(:, 1:4) = b_xx - 1, b_yy - 1, b_xy,
  !> x - 1 (x = b_zz). Returns sigma_xx, sigma_yy, sigma_xy with sigma_zz = 0, the thickness
  !> strain increment ln(lambda_3(n+1) / lambda_3(n)) and, if asked, the largest number of
  !> iterations any lane needed.
  subroutine rubber_plane_stress_update(nel, form, constants, strain_increment, stress, history, &
                                        thickness_strain_increment, iterations)
    integer, intent(in) :: nel, form
    real(wp), intent(in) :: constants(4)
    real(wp), intent(in) :: strain_increment(block_size, 3)
    real(wp), intent(inout) :: stress(block_size, 3)
    real(wp), intent(inout), contiguous :: history(:, :)
    real(wp), intent(out) :: thickness_strain_increment(block_size)
    integer, intent(out), optional :: iterations
    real(wp) :: d11, d22, d12, m11, m22, m12, p11, p22, p12, inverse_det, u11, u12, u21, u22
    real(wp) :: t11, t12, t21, t22, b11, b22, b12, s11, s22, s12, previous, thickness, trace
    real(wp) :: det, third, volume, first, derivative, scale, factor, power
    integer :: i, used, most
    ! explicit 2x2 algebra (no matmul temporaries): M = (I - L/2)^-1 (I + L/2), b2 <- M b2 M^T
    most = 0
    do i = 1, nel
      d11 = 0.5_wp*strain_increment(i, 1)
      d22 = 0.5_wp*strain_increment(i, 2)
      d12 = 0.25_wp*strain_increment(i, 3)
      m11 = 1.0_wp - d11
      m22 = 1.0_wp - d22
      m12 = -d12
      p11 = 1.0_wp + d11
      p22 = 1.0_wp + d22
      p12 = d12
      inverse_det = 1.0_wp/(m11*m22 - m12*m12)
      ! (I - L/2)^-1 = [m22, -m12; -m12, m11] / det, times (I + L/2)
      u11 = (m22*p11 - m12*p12)*inverse_det
      u12 = (m22*p12 - m12*p22)*inverse_det
      u21 = (-m12*p11 + m11*p12)*inverse_det
      u22 = (-m12*p12 + m11*p22)*inverse_det
      b11 = history(i, 1) + 1.0_wp
      b22 = history(i, 2) + 1.0_wp
      b12 = history(i, 3)
      t11 = u11*b11 + u12*b12
      t12 = u11*b12 + u12*b22
      t21 = u21*b11 + u22*b12
      t22 = u21*b12 + u22*b22
      b11 = t11*u11 + t12*u12
      b12 = 0.5_wp*((t11*u21 + t12*u22) + (t21*u11 + t22*u12))
      b22 = t21*u21 + t22*u22
      previous = history(i, 4) + 1.0_wp
      trace = b11 + b22
      det = max(b11*b22 - b12*b12, tiny(1.0_wp))
      call rubber_plane_stress_thickness(form, constants, trace, det, previous, thickness, used)
      most = max(most, used)
      third = det*thickness
      volume = sqrt(third)
      ! b2^2 of the symmetric 2x2 block
      s11 = b11*b11 + b12*b12
      s22 = b22*b22 + b12*b12
      s12 = b12*trace
      if (form == rubber_mooney_rivlin) then
        first = trace + thickness
        derivative = -2.0_wp*constants(3)/third**3 + 2.0_wp*constants(4)*(third - 1.0_wp)
        factor = 2.0_wp/volume
        power = constants(1) + first*constants(2)
        scale = 2.0_wp*volume*derivative
        stress(i, 1) = factor*(power*b11 - constants(2)*s11) + scale
        stress(i, 2) = factor*(power*b22 - constants(2)*s22) + scale
        stress(i, 3) = factor*(power*b12 - constants(2)*s12)
      else
        factor = constants(1)/volume
        power = volume**(-constants(2))
        stress(i, 1) = factor*(s11/volume - power*b11)
        stress(i, 2) = factor*(s22/volume - power*b22)
        stress(i, 3) = factor*(s12/volume - power*b12)
      end if
      thickness_strain_increment(i) = 0.5_wp*log(thickness/previous)
      history(i, 1) = b11 - 1.0_wp
      history(i, 2) = b22 - 1.0_wp
      history(i, 3) = b12
      history(i, 4) = thickness - 1.0_wp
    end do
    if (present(iterations)) iterations = most
  end subroutine rubber_plane_stress_update

  !> The thickness stretch squared x = b_zz that makes sigma_zz = 0 for in-plane invariants
  !> tr b2 = `trace`, det b2 = `det`, starting from `guess` (module notes); `used`: iterations.
  pure subroutine rubber_plane_stress_thickness(form, constants, trace, det, guess, thickness, used)
    integer, intent(in) :: form
    real(wp), intent(in) :: constants(4), trace, det, guess
    real(wp), intent(out) :: thickness
    integer, intent(out) :: used
    real(wp) :: x, residual, slope, step, low, high, trial
    used = 0
    if (form == rubber_blatz_ko) then
      thickness = det**((1.0_wp - constants(2))/(1.0_wp + constants(2)))
      return
    end if
    ! Newton on f(x), kept inside a bracket [low, high] with f(low) < 0 < f(high): f -> -inf as
    ! x -> 0 (C > 0), and f > 0 for large x when D >= 0 (nu >= (2A + 5B) / (5A + 11B), rubbers).
    low = 0.0_wp
    high = huge(1.0_wp)
    x = max(guess, tiny(1.0_wp))
    do used = 1, rubber_thickness_iterations
      residual = (constants(1) + constants(2)*trace)*x - 2.0_wp*constants(3)/(det*x)**2 + &
                 2.0_wp*constants(4)*det*x*(det*x - 1.0_wp)
      if (residual < 0.0_wp) then
        low = max(low, x)
      else
        high = min(high, x)
      end if
      slope = constants(1) + constants(2)*trace + 4.0_wp*constants(3)/(det*det*x**3) + &
              2.0_wp*constants(4)*det*(2.0_wp*det*x - 1.0_wp)
      if (slope > 0.0_wp) then
        step = -residual/slope
      else
        step = merge(x, -0.5_wp*x, residual < 0.0_wp)
      end if
      if (abs(step) <= rubber_thickness_tolerance*x) then
        x = x + step
        exit
      end if
      trial = x + step
      if (trial <= low .or. trial >= high) then
        ! outside the bracket: bisect it (or grow / shrink while one side is still open)
        if (high >= huge(1.0_wp)) then
          trial = 2.0_wp*x
        else
          trial = 0.5_wp*(low + high)
        end if
      end if
      if (abs(trial - x) <= rubber_thickness_tolerance*x) then
        x = trial
        exit
      end if
      x = trial
    end do
    used = min(used, rubber_thickness_iterations)
    thickness = x
  end subroutine rubber_plane_stress_thickness

end module material_rubber
