!> The element strain tensors of LS-DYNA's d3plot (*DATABASE_EXTENT_BINARY STRFLG = 1): one per
!> solid, two per shell (its inner and outer surface), global axes, components xx yy zz xy yz zx
!> (tensor shear components, not engineering ones).
!>
!> crashfree's elements keep no strain, so the tensors are measured from the geometry of the
!> state: the logarithmic (Hencky) strain h = 1/2 ln(F F^T) of the element's deformation
!> gradient F from its reference to its current nodes, taken at the element's centre. Under a
!> deformation without rotation of the principal axes this is the integral of the rate of
!> deformation, the strain LS-DYNA writes; under large rotations of the principal axes the two
!> differ. A shell's F is that of its mid-surface at its centre, with the stretch t / t0 of
!> its thickness along the normal (its thickness of the state over the deck's); the bending
!> strain is not measured, so the inner and the outer surface carry the same mid-surface
!> tensor.
module d3plot_strains
  use kinds, only: wp
  use small_tensors, only: symmetric_eigen, inverse3, determinant3
  implicit none
  private

  public :: solid_hencky_strain, shell_hencky_strain

  !> LS-DYNA's node order in natural coordinates (xi, eta, zeta = -1 or 1).
  real(wp), parameter :: hex_xi(8) = [-1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp]
  real(wp), parameter :: hex_eta(8) = [-1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp]
  real(wp), parameter :: hex_zeta(8) = [-1.0_wp, -1.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, 1.0_wp, 1.0_wp]
  real(wp), parameter :: quad_xi(4) = [-1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp]
  real(wp), parameter :: quad_eta(4) = [-1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp]

contains

  !> The strain of one solid: F = (dx/dxi)(dX/dxi)^-1 at the centre (xi = 0) of the trilinear
  !> hexahedron on nodes `nodes` (a degenerate one repeats nodes), x = X + u, h of F. An
  !> element whose reference map is singular gets zero. (One element at a time: the d3plot
  !> writes a state element by element, without the current coordinates of all nodes.)
  pure function solid_hencky_strain(reference, displacement, nodes) result(strain)
    real(wp), intent(in) :: reference(:, :), displacement(:, :)   !< (3, nodes) X and u
    integer, intent(in) :: nodes(8)                               !< node indices
    real(wp) :: strain(6)                                         !< xx yy zz xy yz zx
    real(wp) :: reference_map(3, 3), current_map(3, 3), gradient(3, 3), current(3)
    integer :: corner
    reference_map = 0.0_wp
    current_map = 0.0_wp
    do corner = 1, 8
      associate (node => nodes(corner))
        current = reference(:, node) + displacement(:, node)
        reference_map(:, 1) = reference_map(:, 1) + hex_xi(corner)*reference(:, node)
        reference_map(:, 2) = reference_map(:, 2) + hex_eta(corner)*reference(:, node)
        reference_map(:, 3) = reference_map(:, 3) + hex_zeta(corner)*reference(:, node)
        current_map(:, 1) = current_map(:, 1) + hex_xi(corner)*current
        current_map(:, 2) = current_map(:, 2) + hex_eta(corner)*current
        current_map(:, 3) = current_map(:, 3) + hex_zeta(corner)*current
      end associate
    end do
    if (.not. abs(determinant3(reference_map)) > 0.0_wp) then
      strain = 0.0_wp
      return
    end if
    ! (the factors 1/8 of the shape functions' derivatives cancel)
    gradient = matmul(current_map, inverse3(reference_map))
    strain = hencky_strain(matmul(gradient, transpose(gradient)))
  end function solid_hencky_strain

  !> The strain of one shell's mid-surface, which its inner and its outer surface both carry:
  !> B = A (a^T a)^-1 A^T + (t / t0)^2 n n^T, a and A the reference and current tangents at
  !> the centre of the bilinear quadrilateral on `nodes` (a triangle repeats its third node),
  !> x = X + u, n the current unit normal, t and t0 the thickness of the state and of the deck
  !> (a stretch of 1 when one is not positive); h of B. A shell that has lost its area gets
  !> zero.
  pure function shell_hencky_strain(reference, displacement, nodes, thickness, reference_thickness) result(strain)
    real(wp), intent(in) :: reference(:, :), displacement(:, :)   !< (3, nodes) X and u
    integer, intent(in) :: nodes(4)                               !< node indices
    real(wp), intent(in) :: thickness, reference_thickness
    real(wp) :: strain(6)                                         !< xx yy zz xy yz zx
    real(wp) :: tangents(3, 2), current_tangents(3, 2), metric(2, 2), inverse_metric(2, 2), normal(3)
    real(wp) :: stretched(3, 3), current(3), determinant, stretch
    integer :: corner
    tangents = 0.0_wp
    current_tangents = 0.0_wp
    do corner = 1, 4
      associate (node => nodes(corner))
        current = reference(:, node) + displacement(:, node)
        tangents(:, 1) = tangents(:, 1) + quad_xi(corner)*reference(:, node)
        tangents(:, 2) = tangents(:, 2) + quad_eta(corner)*reference(:, node)
        current_tangents(:, 1) = current_tangents(:, 1) + quad_xi(corner)*current
        current_tangents(:, 2) = current_tangents(:, 2) + quad_eta(corner)*current
      end associate
    end do
    metric = matmul(transpose(tangents), tangents)
    determinant = metric(1, 1)*metric(2, 2) - metric(1, 2)*metric(2, 1)
    normal = cross(current_tangents(:, 1), current_tangents(:, 2))
    if (.not. (determinant > 0.0_wp .and. norm2(normal) > 0.0_wp)) then
      strain = 0.0_wp
      return
    end if
    normal = normal/norm2(normal)
    inverse_metric = reshape([metric(2, 2), -metric(2, 1), -metric(1, 2), metric(1, 1)], [2, 2])/determinant
    stretch = 1.0_wp
    if (thickness > 0.0_wp .and. reference_thickness > 0.0_wp) stretch = thickness/reference_thickness
    stretched = matmul(current_tangents, matmul(inverse_metric, transpose(current_tangents)))
    stretched = stretched + stretch**2*spread(normal, 2, 3)*spread(normal, 1, 3)
    strain = hencky_strain(stretched)
  end function shell_hencky_strain

  !> 1/2 ln(B) of a symmetric positive definite B, as xx yy zz xy yz zx.
  pure function hencky_strain(left_stretch_squared) result(components)
    real(wp), intent(in) :: left_stretch_squared(3, 3)
    real(wp) :: components(6)
    real(wp) :: values(3), vectors(3, 3), logarithm(3, 3)
    integer :: k
    call symmetric_eigen(left_stretch_squared, values, vectors)
    logarithm = 0.0_wp
    do k = 1, 3
      logarithm = logarithm + 0.5_wp*log(max(values(k), tiny(1.0_wp)))* &
                  spread(vectors(:, k), 2, 3)*spread(vectors(:, k), 1, 3)
    end do
    components = [logarithm(1, 1), logarithm(2, 2), logarithm(3, 3), logarithm(1, 2), logarithm(2, 3), &
                  logarithm(3, 1)]
  end function hencky_strain

  pure function cross(a, b) result(c)
    real(wp), intent(in) :: a(3), b(3)
    real(wp) :: c(3)
    c = [a(2)*b(3) - a(3)*b(2), a(3)*b(1) - a(1)*b(3), a(1)*b(2) - a(2)*b(1)]
  end function cross
end module d3plot_strains
