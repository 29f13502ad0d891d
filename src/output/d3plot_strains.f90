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

  public :: solid_hencky_strains, shell_hencky_strains

  !> LS-DYNA's node order in natural coordinates (xi, eta, zeta = -1 or 1).
  real(wp), parameter :: hex_xi(8) = [-1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp]
  real(wp), parameter :: hex_eta(8) = [-1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp]
  real(wp), parameter :: hex_zeta(8) = [-1.0_wp, -1.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, 1.0_wp, 1.0_wp]
  real(wp), parameter :: quad_xi(4) = [-1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp]
  real(wp), parameter :: quad_eta(4) = [-1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp]

contains

  !> strain(:, e) of each solid e: F = (dx/dxi)(dX/dxi)^-1 at the centre (xi = 0) of the
  !> trilinear hexahedron on nodes `solid_nodes(:, e)` (a degenerate one repeats nodes), h of
  !> F. An element whose reference map is singular gets zero.
  pure subroutine solid_hencky_strains(reference, current, solid_nodes, strain)
    real(wp), intent(in) :: reference(:, :), current(:, :)     !< (3, nodes)
    integer, intent(in) :: solid_nodes(:, :)                   !< (8, solids) node indices
    real(wp), intent(out) :: strain(:, :)                      !< (6, solids)
    real(wp) :: reference_map(3, 3), current_map(3, 3), gradient(3, 3)
    integer :: element, corner
    do element = 1, size(solid_nodes, 2)
      reference_map = 0.0_wp
      current_map = 0.0_wp
      do corner = 1, 8
        associate (node => solid_nodes(corner, element))
          reference_map(:, 1) = reference_map(:, 1) + hex_xi(corner)*reference(:, node)
          reference_map(:, 2) = reference_map(:, 2) + hex_eta(corner)*reference(:, node)
          reference_map(:, 3) = reference_map(:, 3) + hex_zeta(corner)*reference(:, node)
          current_map(:, 1) = current_map(:, 1) + hex_xi(corner)*current(:, node)
          current_map(:, 2) = current_map(:, 2) + hex_eta(corner)*current(:, node)
          current_map(:, 3) = current_map(:, 3) + hex_zeta(corner)*current(:, node)
        end associate
      end do
      if (.not. abs(determinant3(reference_map)) > 0.0_wp) then
        strain(:, element) = 0.0_wp
        cycle
      end if
      ! (the factors 1/8 of the shape functions' derivatives cancel)
      gradient = matmul(current_map, inverse3(reference_map))
      strain(:, element) = hencky_strain(matmul(gradient, transpose(gradient)))
    end do
  end subroutine solid_hencky_strains

  !> strain(:, surface, e) of each shell e, surface 1 the inner, 2 the outer one (the same
  !> mid-surface tensor): B = A (a^T a)^-1 A^T + (t / t0)^2 n n^T, a and A the reference and
  !> current tangents at the centre of the bilinear quadrilateral on `shell_nodes(:, e)` (a
  !> triangle repeats its third node), n the current unit normal, t and t0 the thickness of the
  !> state and of the deck (a stretch of 1 when one is not positive); h of B. A shell that has
  !> lost its area gets zero.
  pure subroutine shell_hencky_strains(reference, current, shell_nodes, thickness, reference_thickness, strain)
    real(wp), intent(in) :: reference(:, :), current(:, :)     !< (3, nodes)
    integer, intent(in) :: shell_nodes(:, :)                   !< (4, shells) node indices
    real(wp), intent(in) :: thickness(:), reference_thickness(:)   !< (shells)
    real(wp), intent(out) :: strain(:, :, :)                   !< (6, 2, shells)
    real(wp) :: tangents(3, 2), current_tangents(3, 2), metric(2, 2), inverse_metric(2, 2), normal(3)
    real(wp) :: stretched(3, 3), determinant, stretch
    integer :: element, corner
    do element = 1, size(shell_nodes, 2)
      tangents = 0.0_wp
      current_tangents = 0.0_wp
      do corner = 1, 4
        associate (node => shell_nodes(corner, element))
          tangents(:, 1) = tangents(:, 1) + quad_xi(corner)*reference(:, node)
          tangents(:, 2) = tangents(:, 2) + quad_eta(corner)*reference(:, node)
          current_tangents(:, 1) = current_tangents(:, 1) + quad_xi(corner)*current(:, node)
          current_tangents(:, 2) = current_tangents(:, 2) + quad_eta(corner)*current(:, node)
        end associate
      end do
      metric = matmul(transpose(tangents), tangents)
      determinant = metric(1, 1)*metric(2, 2) - metric(1, 2)*metric(2, 1)
      normal = cross(current_tangents(:, 1), current_tangents(:, 2))
      if (.not. (determinant > 0.0_wp .and. norm2(normal) > 0.0_wp)) then
        strain(:, :, element) = 0.0_wp
        cycle
      end if
      normal = normal/norm2(normal)
      inverse_metric = reshape([metric(2, 2), -metric(2, 1), -metric(1, 2), metric(1, 1)], [2, 2])/determinant
      stretch = 1.0_wp
      if (thickness(element) > 0.0_wp .and. reference_thickness(element) > 0.0_wp) &
        stretch = thickness(element)/reference_thickness(element)
      stretched = matmul(current_tangents, matmul(inverse_metric, transpose(current_tangents)))
      stretched = stretched + stretch**2*spread(normal, 2, 3)*spread(normal, 1, 3)
      strain(:, 1, element) = hencky_strain(stretched)
      strain(:, 2, element) = strain(:, 1, element)
    end do
  end subroutine shell_hencky_strains

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
