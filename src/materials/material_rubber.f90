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
    third = max(determinant(b), tiny(1.0_wp))
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
      update = midpoint_update(unpacked(lane))
      lane = history(i, 1:6)
      b = unpacked(lane)
      b(1, 1) = b(1, 1) + 1.0_wp
      b(2, 2) = b(2, 2) + 1.0_wp
      b(3, 3) = b(3, 3) + 1.0_wp
      b = matmul(update, matmul(b, transpose(update)))
      stress(i, :) = packed(rubber_cauchy_stress(form, constants, b))
      b(1, 1) = b(1, 1) - 1.0_wp
      b(2, 2) = b(2, 2) - 1.0_wp
      b(3, 3) = b(3, 3) - 1.0_wp
      history(i, 1:6) = packed(b)
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
    real(wp) :: rate(2, 2), half(2, 2), update(2, 2), b(2, 2), squared(2, 2), previous, thickness, trace
    real(wp) :: det, third, volume, first, derivative, scale, lane_stress(2, 2)
    integer :: i, used, most
    most = 0
    do i = 1, nel
      rate(1, 1) = strain_increment(i, 1)
      rate(2, 2) = strain_increment(i, 2)
      rate(1, 2) = 0.5_wp*strain_increment(i, 3)
      rate(2, 1) = rate(1, 2)
      half = -0.5_wp*rate
      half(1, 1) = half(1, 1) + 1.0_wp
      half(2, 2) = half(2, 2) + 1.0_wp
      update = 0.5_wp*rate
      update(1, 1) = update(1, 1) + 1.0_wp
      update(2, 2) = update(2, 2) + 1.0_wp
      update = matmul(inverse2(half), update)
      b(1, 1) = history(i, 1) + 1.0_wp
      b(2, 2) = history(i, 2) + 1.0_wp
      b(1, 2) = history(i, 3)
      b(2, 1) = history(i, 3)
      b = matmul(update, matmul(b, transpose(update)))
      previous = history(i, 4) + 1.0_wp
      trace = b(1, 1) + b(2, 2)
      det = max(b(1, 1)*b(2, 2) - b(1, 2)*b(2, 1), tiny(1.0_wp))
      call rubber_plane_stress_thickness(form, constants, trace, det, previous, thickness, used)
      most = max(most, used)
      third = det*thickness
      volume = sqrt(third)
      squared = matmul(b, b)
      if (form == rubber_mooney_rivlin) then
        first = trace + thickness
        derivative = -2.0_wp*constants(3)/third**3 + 2.0_wp*constants(4)*(third - 1.0_wp)
        lane_stress = (2.0_wp/volume)*((constants(1) + first*constants(2))*b - constants(2)*squared)
        scale = 2.0_wp*volume*derivative
        lane_stress(1, 1) = lane_stress(1, 1) + scale
        lane_stress(2, 2) = lane_stress(2, 2) + scale
      else
        lane_stress = (constants(1)/volume)*(squared/volume - volume**(-constants(2))*b)
      end if
      stress(i, 1) = lane_stress(1, 1)
      stress(i, 2) = lane_stress(2, 2)
      stress(i, 3) = 0.5_wp*(lane_stress(1, 2) + lane_stress(2, 1))
      thickness_strain_increment(i) = 0.5_wp*log(thickness/previous)
      history(i, 1) = b(1, 1) - 1.0_wp
      history(i, 2) = b(2, 2) - 1.0_wp
      history(i, 3) = 0.5_wp*(b(1, 2) + b(2, 1))
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

  !> M = (I - L/2)^-1 (I + L/2) for a 3x3 increment L.
  pure function midpoint_update(increment) result(update)
    real(wp), intent(in) :: increment(3, 3)
    real(wp) :: update(3, 3)
    real(wp) :: minus(3, 3), plus(3, 3)
    integer :: k
    minus = -0.5_wp*increment
    plus = 0.5_wp*increment
    do k = 1, 3
      minus(k, k) = minus(k, k) + 1.0_wp
      plus(k, k) = plus(k, k) + 1.0_wp
    end do
    update = matmul(inverse3(minus), plus)
  end function midpoint_update

  pure real(wp) function determinant(m)
    real(wp), intent(in) :: m(3, 3)
    determinant = m(1, 1)*(m(2, 2)*m(3, 3) - m(2, 3)*m(3, 2)) - m(1, 2)*(m(2, 1)*m(3, 3) - m(2, 3)*m(3, 1)) &
                  + m(1, 3)*(m(2, 1)*m(3, 2) - m(2, 2)*m(3, 1))
  end function determinant

  pure function inverse3(m) result(inverse)
    real(wp), intent(in) :: m(3, 3)
    real(wp) :: inverse(3, 3)
    inverse(1, 1) = m(2, 2)*m(3, 3) - m(2, 3)*m(3, 2)
    inverse(1, 2) = m(1, 3)*m(3, 2) - m(1, 2)*m(3, 3)
    inverse(1, 3) = m(1, 2)*m(2, 3) - m(1, 3)*m(2, 2)
    inverse(2, 1) = m(2, 3)*m(3, 1) - m(2, 1)*m(3, 3)
    inverse(2, 2) = m(1, 1)*m(3, 3) - m(1, 3)*m(3, 1)
    inverse(2, 3) = m(1, 3)*m(2, 1) - m(1, 1)*m(2, 3)
    inverse(3, 1) = m(2, 1)*m(3, 2) - m(2, 2)*m(3, 1)
    inverse(3, 2) = m(1, 2)*m(3, 1) - m(1, 1)*m(3, 2)
    inverse(3, 3) = m(1, 1)*m(2, 2) - m(1, 2)*m(2, 1)
    inverse = inverse/determinant(m)
  end function inverse3

  pure function inverse2(m) result(inverse)
    real(wp), intent(in) :: m(2, 2)
    real(wp) :: inverse(2, 2)
    inverse = reshape([m(2, 2), -m(2, 1), -m(1, 2), m(1, 1)], [2, 2])/(m(1, 1)*m(2, 2) - m(1, 2)*m(2, 1))
  end function inverse2

  pure function unpacked(tensor) result(matrix)
    real(wp), intent(in) :: tensor(6)
    real(wp) :: matrix(3, 3)
    matrix = reshape([tensor(1), tensor(4), tensor(6), tensor(4), tensor(2), tensor(5), &
                      tensor(6), tensor(5), tensor(3)], [3, 3])
  end function unpacked

  pure function packed(matrix) result(tensor)
    real(wp), intent(in) :: matrix(3, 3)
    real(wp) :: tensor(6)
    tensor = [matrix(1, 1), matrix(2, 2), matrix(3, 3), 0.5_wp*(matrix(1, 2) + matrix(2, 1)), &
              0.5_wp*(matrix(2, 3) + matrix(3, 2)), 0.5_wp*(matrix(3, 1) + matrix(1, 3))]
  end function packed
end module material_rubber
