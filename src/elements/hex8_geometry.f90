!> Geometry of the 8-node hexahedron on a block of elements: exact volume derivatives (the
!> uniform-strain B matrix), mean velocity gradient, face areas, centre Jacobian and the
!> natural derivatives at the 2x2x2 Gauss points.
!>
!> Node numbering is LS-DYNA's: nodes 1-4 the bottom face counterclockwise seen from the top,
!> nodes 5-8 the top face above them; natural coordinates (xi, eta, zeta) of the nodes are
!> `node_xi`, `node_eta`, `node_zeta`. All arrays have the element (lane) index first and every
!> loop over it runs `do i = 1, nel`, so the compiler vectorizes across elements.
!>
!> Reference: D.P. Flanagan and T. Belytschko, "A uniform strain hexahedron and quadrilateral
!> with orthogonal hourglass control", IJNME 17 (1981) 679-706: the mean gradient
!> b_iI = integral of dN_I/dx_i over the element equals dV/dx_iI and has a closed form.
module hex8_geometry
  use kinds, only: wp, block_size
  implicit none
  private

  public :: hex8_volume_derivatives, hex8_volume, hex8_velocity_gradient, hex8_largest_face_area
  public :: hex8_gauss_natural_derivatives, hex8_point_derivatives, deformation_increments
  public :: hex8_gradient_invariants, largest_eigenvalue_bounds
  public :: distinct_corner_count, tetrahedron_corner_order, hex8_corner_volumes

  !> Natural coordinates of the eight nodes.
  real(wp), parameter, public :: node_xi(8) = [-1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp]
  real(wp), parameter, public :: node_eta(8) = [-1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp]
  real(wp), parameter, public :: node_zeta(8) = [-1.0_wp, -1.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, 1.0_wp, 1.0_wp]

  !> The six faces, each as four corner nodes in order around the face.
  integer, parameter, public :: hex8_faces(4, 6) = reshape([1, 2, 3, 4, 5, 6, 7, 8, 1, 2, 6, 5, &
                                                            2, 3, 7, 6, 3, 4, 8, 7, 4, 1, 5, 8], [4, 6])

  ! The volume derivative of node 1 is a fixed bilinear form in the coordinates of nodes 2, 3,
  ! 4, 5, 6 and 8 (Flanagan & Belytschko 1981 give it); every other node uses the same form
  ! on its own neighbours. For node I the element nodes playing the roles of nodes 1..8 of the
  ! node-1 formula are (derived from the rotations of the cube and checked symbolically against
  ! dV/dx_I for every node and component):
  !   node 1: 1 2 3 4 5 6 7 8    node 2: 2 1 5 6 3 4 8 7    node 3: 3 4 1 2 7 8 5 6
  !   node 4: 4 3 7 8 1 2 6 5    node 5: 5 6 2 1 8 7 3 4    node 6: 6 5 8 7 2 1 4 3
  !   node 7: 7 8 4 3 6 5 1 2    node 8: 8 7 6 5 4 3 2 1
  ! The y and z components follow from the x component by the cyclic permutations (y,z) ->
  ! (z,x) -> (x,y).

contains

  !> Exact volume derivatives b_iI = dV/dx_iI of each element and its exact volume
  !> V = sum_I x_I b_xI (the volume is linear in the x coordinates alone, so this is exact;
  !> it equals the 2x2x2 Gauss volume). Node I uses the node-1 form on the nodes of its role
  !> list (see above), written out so that the lane loop vectorizes with every coordinate in a
  !> register.
  subroutine hex8_volume_derivatives(nel, x, y, z, bx, by, bz, volume)
    integer, intent(in) :: nel
    real(wp), intent(in) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp), intent(out) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8)
    real(wp), intent(out) :: volume(block_size)
    real(wp), parameter :: twelfth = 1.0_wp/12.0_wp
    real(wp) :: x1, x2, x3, x4, x5, x6, x7, x8, y1, y2, y3, y4, y5, y6, y7, y8
    real(wp) :: z1, z2, z3, z4, z5, z6, z7, z8
    integer :: i

    do i = 1, nel
      x1 = x(i, 1); x2 = x(i, 2); x3 = x(i, 3); x4 = x(i, 4); x5 = x(i, 5); x6 = x(i, 6); x7 = x(i, 7); x8 = x(i, 8)
      y1 = y(i, 1); y2 = y(i, 2); y3 = y(i, 3); y4 = y(i, 4); y5 = y(i, 5); y6 = y(i, 6); y7 = y(i, 7); y8 = y(i, 8)
      z1 = z(i, 1); z2 = z(i, 2); z3 = z(i, 3); z4 = z(i, 4); z5 = z(i, 5); z6 = z(i, 6); z7 = z(i, 7); z8 = z(i, 8)
      bx(i, 1) = twelfth*volume_form(y2, y3, y4, y5, y6, y8, z2, z3, z4, z5, z6, z8)
      bx(i, 2) = twelfth*volume_form(y1, y5, y6, y3, y4, y7, z1, z5, z6, z3, z4, z7)
      bx(i, 3) = twelfth*volume_form(y4, y1, y2, y7, y8, y6, z4, z1, z2, z7, z8, z6)
      bx(i, 4) = twelfth*volume_form(y3, y7, y8, y1, y2, y5, z3, z7, z8, z1, z2, z5)
      bx(i, 5) = twelfth*volume_form(y6, y2, y1, y8, y7, y4, z6, z2, z1, z8, z7, z4)
      bx(i, 6) = twelfth*volume_form(y5, y8, y7, y2, y1, y3, z5, z8, z7, z2, z1, z3)
      bx(i, 7) = twelfth*volume_form(y8, y4, y3, y6, y5, y2, z8, z4, z3, z6, z5, z2)
      bx(i, 8) = twelfth*volume_form(y7, y6, y5, y4, y3, y1, z7, z6, z5, z4, z3, z1)
      by(i, 1) = twelfth*volume_form(z2, z3, z4, z5, z6, z8, x2, x3, x4, x5, x6, x8)
      by(i, 2) = twelfth*volume_form(z1, z5, z6, z3, z4, z7, x1, x5, x6, x3, x4, x7)
      by(i, 3) = twelfth*volume_form(z4, z1, z2, z7, z8, z6, x4, x1, x2, x7, x8, x6)
      by(i, 4) = twelfth*volume_form(z3, z7, z8, z1, z2, z5, x3, x7, x8, x1, x2, x5)
      by(i, 5) = twelfth*volume_form(z6, z2, z1, z8, z7, z4, x6, x2, x1, x8, x7, x4)
      by(i, 6) = twelfth*volume_form(z5, z8, z7, z2, z1, z3, x5, x8, x7, x2, x1, x3)
      by(i, 7) = twelfth*volume_form(z8, z4, z3, z6, z5, z2, x8, x4, x3, x6, x5, x2)
      by(i, 8) = twelfth*volume_form(z7, z6, z5, z4, z3, z1, x7, x6, x5, x4, x3, x1)
      bz(i, 1) = twelfth*volume_form(x2, x3, x4, x5, x6, x8, y2, y3, y4, y5, y6, y8)
      bz(i, 2) = twelfth*volume_form(x1, x5, x6, x3, x4, x7, y1, y5, y6, y3, y4, y7)
      bz(i, 3) = twelfth*volume_form(x4, x1, x2, x7, x8, x6, y4, y1, y2, y7, y8, y6)
      bz(i, 4) = twelfth*volume_form(x3, x7, x8, x1, x2, x5, y3, y7, y8, y1, y2, y5)
      bz(i, 5) = twelfth*volume_form(x6, x2, x1, x8, x7, x4, y6, y2, y1, y8, y7, y4)
      bz(i, 6) = twelfth*volume_form(x5, x8, x7, x2, x1, x3, y5, y8, y7, y2, y1, y3)
      bz(i, 7) = twelfth*volume_form(x8, x4, x3, x6, x5, x2, y8, y4, y3, y6, y5, y2)
      bz(i, 8) = twelfth*volume_form(x7, x6, x5, x4, x3, x1, y7, y6, y5, y4, y3, y1)
      volume(i) = x1*bx(i, 1) + x2*bx(i, 2) + x3*bx(i, 3) + x4*bx(i, 4) + x5*bx(i, 5) + x6*bx(i, 6) &
                  + x7*bx(i, 7) + x8*bx(i, 8)
    end do
  end subroutine hex8_volume_derivatives

  !> The trilinear "volume" V = sum_I x_I b_xI of eight points given as x, y, z (for the
  !> element's nodes its volume; for the nodal velocities the cubic coefficient of the volume
  !> along the step, see solid_block).
  subroutine hex8_volume(nel, x, y, z, volume)
    integer, intent(in) :: nel
    real(wp), intent(in) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp), intent(out) :: volume(block_size)
    real(wp), parameter :: twelfth = 1.0_wp/12.0_wp
    real(wp) :: x1, x2, x3, x4, x5, x6, x7, x8, y1, y2, y3, y4, y5, y6, y7, y8
    real(wp) :: z1, z2, z3, z4, z5, z6, z7, z8
    integer :: i

    do i = 1, nel
      x1 = x(i, 1); x2 = x(i, 2); x3 = x(i, 3); x4 = x(i, 4); x5 = x(i, 5); x6 = x(i, 6); x7 = x(i, 7); x8 = x(i, 8)
      y1 = y(i, 1); y2 = y(i, 2); y3 = y(i, 3); y4 = y(i, 4); y5 = y(i, 5); y6 = y(i, 6); y7 = y(i, 7); y8 = y(i, 8)
      z1 = z(i, 1); z2 = z(i, 2); z3 = z(i, 3); z4 = z(i, 4); z5 = z(i, 5); z6 = z(i, 6); z7 = z(i, 7); z8 = z(i, 8)
      volume(i) = twelfth*(x1*volume_form(y2, y3, y4, y5, y6, y8, z2, z3, z4, z5, z6, z8) &
                           + x2*volume_form(y1, y5, y6, y3, y4, y7, z1, z5, z6, z3, z4, z7) &
                           + x3*volume_form(y4, y1, y2, y7, y8, y6, z4, z1, z2, z7, z8, z6) &
                           + x4*volume_form(y3, y7, y8, y1, y2, y5, z3, z7, z8, z1, z2, z5) &
                           + x5*volume_form(y6, y2, y1, y8, y7, y4, z6, z2, z1, z8, z7, z4) &
                           + x6*volume_form(y5, y8, y7, y2, y1, y3, z5, z8, z7, z2, z1, z3) &
                           + x7*volume_form(y8, y4, y3, y6, y5, y2, z8, z4, z3, z6, z5, z2) &
                           + x8*volume_form(y7, y6, y5, y4, y3, y1, z7, z6, z5, z4, z3, z1))
    end do
  end subroutine hex8_volume

  !> Twelve times dV/dx_1 written with the roles of nodes 2..8 (node 7 does not appear):
  !> the cyclic permutations (y,z), (z,x), (x,y) give the x, y and z components.
  elemental function volume_form(a2, a3, a4, a5, a6, a8, c2, c3, c4, c5, c6, c8) result(value)
    real(wp), intent(in) :: a2, a3, a4, a5, a6, a8, c2, c3, c4, c5, c6, c8
    real(wp) :: value
    value = a2*((c6 - c3) - (c4 - c5)) + a3*(c2 - c4) + a4*((c3 - c8) - (c5 - c2)) &
            + a5*((c8 - c6) - (c2 - c4)) + a6*(c5 - c2) + a8*(c4 - c5)
  end function volume_form

  !> Mean velocity gradient over the element, L_ij = (1/V) sum_I v_iI b_jI, stored row by row:
  !> gradient(:, 3*(i-1)+j) = dv_i/dx_j, with b and V taken on the configuration x + shift v
  !> (shift = -dt/2 gives the mid-step configuration from x(n+1) and v(n+1/2)). For a velocity
  !> field linear in the coordinates of that configuration it is exact
  !> (sum_I x_jI b_kI = V delta_jk). Also returns the exact volume of that configuration.
  !> The sum runs over the velocities relative to node 1's (the same value, as sum_I b_I = 0):
  !> a translating element then gets exactly L = 0. With the absolute velocities it got the
  !> round-off v . sum_I b_I instead, of either sign and different with and without FMA
  !> contraction, and a negative tr D switches on the linear bulk viscosity's term of the
  !> stable step (element_time_step), 6% smaller at Q2 = 0.06: the release and the debug build
  !> then took different steps in free flight (docs/solver.md, "Why two builds differ").
  subroutine hex8_velocity_gradient(nel, shift, x, y, z, vx, vy, vz, gradient, volume)
    integer, intent(in) :: nel
    real(wp), intent(in) :: shift
    real(wp), intent(in) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp), intent(in) :: vx(block_size, 8), vy(block_size, 8), vz(block_size, 8)
    real(wp), intent(out) :: gradient(block_size, 9)
    real(wp), intent(out) :: volume(block_size)
    real(wp) :: shifted_x(block_size, 8), shifted_y(block_size, 8), shifted_z(block_size, 8)
    real(wp) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8)
    real(wp) :: l11, l12, l13, l21, l22, l23, l31, l32, l33, inverse_volume, rx, ry, rz
    integer :: node, i

    do i = 1, nel
      do node = 1, 8
        shifted_x(i, node) = x(i, node) + shift*vx(i, node)
        shifted_y(i, node) = y(i, node) + shift*vy(i, node)
        shifted_z(i, node) = z(i, node) + shift*vz(i, node)
      end do
    end do
    call hex8_volume_derivatives(nel, shifted_x, shifted_y, shifted_z, bx, by, bz, volume)
    do i = 1, nel
      l11 = 0.0_wp; l12 = 0.0_wp; l13 = 0.0_wp
      l21 = 0.0_wp; l22 = 0.0_wp; l23 = 0.0_wp
      l31 = 0.0_wp; l32 = 0.0_wp; l33 = 0.0_wp
      do node = 1, 8
        rx = vx(i, node) - vx(i, 1)
        ry = vy(i, node) - vy(i, 1)
        rz = vz(i, node) - vz(i, 1)
        l11 = l11 + rx*bx(i, node)
        l12 = l12 + rx*by(i, node)
        l13 = l13 + rx*bz(i, node)
        l21 = l21 + ry*bx(i, node)
        l22 = l22 + ry*by(i, node)
        l23 = l23 + ry*bz(i, node)
        l31 = l31 + rz*bx(i, node)
        l32 = l32 + rz*by(i, node)
        l33 = l33 + rz*bz(i, node)
      end do
      ! An inverted element (V <= 0) is reported by the caller; only keep the division finite.
      inverse_volume = 1.0_wp/sign(max(abs(volume(i)), tiny(1.0_wp)), volume(i))
      gradient(i, 1) = l11*inverse_volume
      gradient(i, 2) = l12*inverse_volume
      gradient(i, 3) = l13*inverse_volume
      gradient(i, 4) = l21*inverse_volume
      gradient(i, 5) = l22*inverse_volume
      gradient(i, 6) = l23*inverse_volume
      gradient(i, 7) = l31*inverse_volume
      gradient(i, 8) = l32*inverse_volume
      gradient(i, 9) = l33*inverse_volume
    end do
  end subroutine hex8_velocity_gradient

  !> Area of the largest face of each element. A face's area is the magnitude of its vector
  !> area, (1/2) |(x_3 - x_1) x (x_4 - x_2)|, which is exact for a plane face and the projected
  !> area for a warped one. LS-DYNA's characteristic length of a hexahedron is V / this area.
  subroutine hex8_largest_face_area(nel, x, y, z, area)
    integer, intent(in) :: nel
    real(wp), intent(in) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp), intent(out) :: area(block_size)
    real(wp) :: largest_squared, ax, ay, az, cx, cy, cz
    integer :: face, i, n1, n2, n3, n4

    do i = 1, nel
      largest_squared = 0.0_wp
      do face = 1, 6
        n1 = hex8_faces(1, face)
        n2 = hex8_faces(2, face)
        n3 = hex8_faces(3, face)
        n4 = hex8_faces(4, face)
        ax = x(i, n3) - x(i, n1)
        ay = y(i, n3) - y(i, n1)
        az = z(i, n3) - z(i, n1)
        cx = x(i, n4) - x(i, n2)
        cy = y(i, n4) - y(i, n2)
        cz = z(i, n4) - z(i, n2)
        largest_squared = max(largest_squared, (ay*cz - az*cy)**2 + (az*cx - ax*cz)**2 + (ax*cy - ay*cx)**2)
      end do
      area(i) = 0.5_wp*sqrt(largest_squared)
    end do
  end subroutine hex8_largest_face_area

  !> What the stable step of a hexahedron needs from its geometry (element_time_step): with the
  !> mean gradients B_I = b_I / V (b the exact volume derivatives) and G = sum_I B_I B_I^T,
  !> - g = G (packed 11 22 33 12 23 13), trace_g = tr G and largest_g >= lambda_max(G)
  !>   (largest_eigenvalue_bounds);
  !> - overlap = an upper bound on cos^2 of the largest principal angle between span{b_x, b_y,
  !>   b_z} (the one-point element's strain modes, as vectors over the 8 nodes) and the space of
  !>   nodal fields orthogonal to 1, x, y, z (where the hourglass modes of IHQ 2-5 and the
  !>   extra deviatoric modes of ELFORM 2 lie): with S = sum_I x~_I x~_I^T (x~ about the
  !>   centroid), sum_I x~_kI b_jI = V delta_jk gives cos^2 = 1 - 1 / lambda_max(S G), and
  !>   since every eigenvalue of S G is >= 1, lambda_max(S G) <= tr(S G) - 2. It is 0 for a
  !>   parallelepiped (G = S^-1), where the two kinds of modes are orthogonal. Only computed
  !>   `with_overlap` (IHQ 1 has its own, standard_hourglass_overlap).
  subroutine hex8_gradient_invariants(nel, x, y, z, bx, by, bz, volume, g, trace_g, largest_g, overlap, with_overlap, &
                                      corner_weight)
    integer, intent(in) :: nel
    logical, intent(in) :: with_overlap
    !> corner masses in units of rho V0 / 8 (degenerate elements, solid_block): G then sums
    !> B_I B_I^T / w_I, the lumped-mass form the eigenvalue bound needs; 1 when absent
    real(wp), intent(in), optional :: corner_weight(block_size, 8)
    real(wp), intent(in) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp), intent(in) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8), volume(block_size)
    real(wp), intent(out) :: g(block_size, 6), trace_g(block_size), largest_g(block_size), overlap(block_size)
    real(wp) :: g11, g22, g33, g12, g23, g13, s11, s22, s33, s12, s23, s13
    real(wp) :: xc, yc, zc, dx, dy, dz, scale, product_trace
    integer :: node, i
    do i = 1, nel
      g11 = 0.0_wp; g22 = 0.0_wp; g33 = 0.0_wp; g12 = 0.0_wp; g23 = 0.0_wp; g13 = 0.0_wp
      if (present(corner_weight)) then
        do node = 1, 8
          g11 = g11 + bx(i, node)**2/corner_weight(i, node)
          g22 = g22 + by(i, node)**2/corner_weight(i, node)
          g33 = g33 + bz(i, node)**2/corner_weight(i, node)
          g12 = g12 + bx(i, node)*by(i, node)/corner_weight(i, node)
          g23 = g23 + by(i, node)*bz(i, node)/corner_weight(i, node)
          g13 = g13 + bx(i, node)*bz(i, node)/corner_weight(i, node)
        end do
      else
        do node = 1, 8
          g11 = g11 + bx(i, node)**2
          g22 = g22 + by(i, node)**2
          g33 = g33 + bz(i, node)**2
          g12 = g12 + bx(i, node)*by(i, node)
          g23 = g23 + by(i, node)*bz(i, node)
          g13 = g13 + bx(i, node)*bz(i, node)
        end do
      end if
      ! b / V, kept finite for a flattened or inverted element (reported by the caller): V^2 is
      ! of the order of |b|^3 for any element of reasonable shape
      scale = 1.0_wp/max(volume(i)**2, 1.0e-12_wp*(g11 + g22 + g33)*sqrt(g11 + g22 + g33), tiny(1.0_wp))
      g(i, 1) = g11*scale
      g(i, 2) = g22*scale
      g(i, 3) = g33*scale
      g(i, 4) = g12*scale
      g(i, 5) = g23*scale
      g(i, 6) = g13*scale
      trace_g(i) = g(i, 1) + g(i, 2) + g(i, 3)
    end do
    call largest_eigenvalue_bounds(nel, g, largest_g)
    if (.not. with_overlap) return
    do i = 1, nel
      xc = 0.0_wp; yc = 0.0_wp; zc = 0.0_wp
      do node = 1, 8
        xc = xc + x(i, node)
        yc = yc + y(i, node)
        zc = zc + z(i, node)
      end do
      xc = 0.125_wp*xc
      yc = 0.125_wp*yc
      zc = 0.125_wp*zc
      s11 = 0.0_wp; s22 = 0.0_wp; s33 = 0.0_wp; s12 = 0.0_wp; s23 = 0.0_wp; s13 = 0.0_wp
      do node = 1, 8
        dx = x(i, node) - xc
        dy = y(i, node) - yc
        dz = z(i, node) - zc
        s11 = s11 + dx*dx
        s22 = s22 + dy*dy
        s33 = s33 + dz*dz
        s12 = s12 + dx*dy
        s23 = s23 + dy*dz
        s13 = s13 + dx*dz
      end do
      product_trace = s11*g(i, 1) + s22*g(i, 2) + s33*g(i, 3) + 2.0_wp*(s12*g(i, 4) + s23*g(i, 5) + s13*g(i, 6))
      overlap(i) = 1.0_wp - 1.0_wp/max(1.0_wp, product_trace - 2.0_wp)
    end do
  end subroutine hex8_gradient_invariants

  !> Upper bounds on the largest eigenvalue of symmetric 3 x 3 matrices (a(i, :) = 11, 22, 33,
  !> 12, 23, 13), at most 0.4% above it for positive semi-definite ones. The eigenvalues are
  !> q + 2 p cos(theta_k) (q = tr / 3, p^2 = |A - q I|^2 / 6), the largest q + 2 p f(r) with
  !> f(r) = cos(acos(r) / 3) and r = det(A - q I) / (2 p^3) in [-1, 1] (Smith, CACM 4 (1961)
  !> 168). f is concave, so each of its tangents lies above it: the smallest of eight tangents
  !> (and of f <= 1) bounds it within 0.006. Arithmetic only, in one loop over the lanes, so that
  !> it vectorizes (acos and cos of the closed form, per lane, doubled the cost of a one-point
  !> element; Newton steps on the characteristic polynomial cost four divisions).
  subroutine largest_eigenvalue_bounds(nel, a, bound)
    integer, intent(in) :: nel
    real(wp), intent(in) :: a(block_size, 6)
    real(wp), intent(out) :: bound(block_size)
    ! tangent points r_k of f and f(r_k), f'(r_k) = sin(acos(r_k) / 3) / (3 sin(acos(r_k)))
    real(wp), parameter :: point(8) = [0.6_wp, 0.0_wp, -0.5_wp, -0.8_wp, -0.93_wp, -0.98_wp, -0.995_wp, &
                                       -0.9995_wp]
    real(wp), parameter :: value(8) = [0.9526082218220564_wp, 0.8660254037844387_wp, 0.766044443118978_wp, &
                                       0.6728829727813683_wp, 0.60443776901398_wp, 0.5566742948343846_wp, &
                                       0.5285962191048232_wp, 0.5091011407914117_wp]
    real(wp), parameter :: slope(8) = [0.12674995597537844_wp, 0.16666666666666666_wp, 0.2474090663228531_wp, &
                                       0.41097163735488723_wp, 0.7224701663069244_wp, 1.3915265151213427_wp, &
                                       2.8331215944236416_wp, 9.073779555306288_wp]
    real(wp) :: q, p, d11, d22, d33, r, envelope
    integer :: i, k
    do i = 1, nel
      q = (a(i, 1) + a(i, 2) + a(i, 3))/3.0_wp
      d11 = a(i, 1) - q
      d22 = a(i, 2) - q
      d33 = a(i, 3) - q
      p = sqrt((d11**2 + d22**2 + d33**2 + 2.0_wp*(a(i, 4)**2 + a(i, 5)**2 + a(i, 6)**2))/6.0_wp)
      ! (p = 0, all eigenvalues equal: r = 0 and the bound q)
      r = (d11*(d22*d33 - a(i, 5)**2) - a(i, 4)*(a(i, 4)*d33 - a(i, 5)*a(i, 6)) &
           + a(i, 6)*(a(i, 4)*a(i, 5) - d22*a(i, 6)))/max(2.0_wp*p**3, tiny(1.0_wp))
      r = min(1.0_wp, max(-1.0_wp, r))
      envelope = 1.0_wp
      do k = 1, 8
        envelope = min(envelope, value(k) + slope(k)*(r - point(k)))
      end do
      ! round-off in r (of order epsilon q / p) moves the envelope by at most its steepest slope
      bound(i) = q + 2.0_wp*p*envelope + 256.0_wp*epsilon(1.0_wp)*(abs(q) + 2.0_wp*p)
    end do
  end subroutine largest_eigenvalue_bounds

  !> Derivatives of the shape functions with respect to (xi, eta, zeta) at the eight Gauss
  !> points of the 2x2x2 rule (+-1/sqrt(3), weights 1; point p sits in the octant of node p):
  !> natural_derivatives(I, a, p) = dN_I/dxi_a at point p.
  pure subroutine hex8_gauss_natural_derivatives(natural_derivatives)
    real(wp), intent(out) :: natural_derivatives(8, 3, 8)
    real(wp) :: g, xi, eta, zeta
    integer :: point, node
    g = 1.0_wp/sqrt(3.0_wp)
    do point = 1, 8
      xi = g*node_xi(point)
      eta = g*node_eta(point)
      zeta = g*node_zeta(point)
      do node = 1, 8
        natural_derivatives(node, 1, point) = 0.125_wp*node_xi(node)*(1.0_wp + node_eta(node)*eta) &
                                              *(1.0_wp + node_zeta(node)*zeta)
        natural_derivatives(node, 2, point) = 0.125_wp*node_eta(node)*(1.0_wp + node_xi(node)*xi) &
                                              *(1.0_wp + node_zeta(node)*zeta)
        natural_derivatives(node, 3, point) = 0.125_wp*node_zeta(node)*(1.0_wp + node_xi(node)*xi) &
                                              *(1.0_wp + node_eta(node)*eta)
      end do
    end do
  end subroutine hex8_gauss_natural_derivatives

  !> Shape function derivatives dN_I/dx at one integration point of each element, from the
  !> natural derivatives at that point (natural(I, a) = dN_I/dxi_a), and det J. Elements with
  !> det J <= 0 get finite (meaningless) derivatives; the caller reports them.
  subroutine hex8_point_derivatives(nel, natural, x, y, z, dndx, dndy, dndz, determinant)
    integer, intent(in) :: nel
    real(wp), intent(in) :: natural(8, 3)
    real(wp), intent(in) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp), intent(out) :: dndx(block_size, 8), dndy(block_size, 8), dndz(block_size, 8)
    real(wp), intent(out) :: determinant(block_size)
    real(wp) :: j11, j12, j13, j21, j22, j23, j31, j32, j33
    real(wp) :: i11, i12, i13, i21, i22, i23, i31, i32, i33, inverse_determinant, largest_entry
    integer :: node, i

    do i = 1, nel
      ! J_ka = dx_k/dxi_a
      j11 = 0.0_wp; j12 = 0.0_wp; j13 = 0.0_wp
      j21 = 0.0_wp; j22 = 0.0_wp; j23 = 0.0_wp
      j31 = 0.0_wp; j32 = 0.0_wp; j33 = 0.0_wp
      do node = 1, 8
        j11 = j11 + x(i, node)*natural(node, 1)
        j12 = j12 + x(i, node)*natural(node, 2)
        j13 = j13 + x(i, node)*natural(node, 3)
        j21 = j21 + y(i, node)*natural(node, 1)
        j22 = j22 + y(i, node)*natural(node, 2)
        j23 = j23 + y(i, node)*natural(node, 3)
        j31 = j31 + z(i, node)*natural(node, 1)
        j32 = j32 + z(i, node)*natural(node, 2)
        j33 = j33 + z(i, node)*natural(node, 3)
      end do
      ! i_ak = (J^-1)_ak from the cofactors
      i11 = j22*j33 - j23*j32
      i12 = j13*j32 - j12*j33
      i13 = j12*j23 - j13*j22
      i21 = j23*j31 - j21*j33
      i22 = j11*j33 - j13*j31
      i23 = j13*j21 - j11*j23
      i31 = j21*j32 - j22*j31
      i32 = j12*j31 - j11*j32
      i33 = j11*j22 - j12*j21
      determinant(i) = j11*i11 + j12*i21 + j13*i31
      ! a flattened point keeps finite derivatives: det J ~ (largest |J_ka|)^3, floored at 1e-15 of it
      largest_entry = max(abs(j11), abs(j12), abs(j13), abs(j21), abs(j22), abs(j23), abs(j31), abs(j32), abs(j33))
      inverse_determinant = 1.0_wp/sign(max(abs(determinant(i)), 1.0e-15_wp*largest_entry**3, tiny(1.0_wp)), determinant(i))
      ! dN_I/dx_k = sum_a dN_I/dxi_a (J^-1)_ak
      do node = 1, 8
        dndx(i, node) = (natural(node, 1)*i11 + natural(node, 2)*i21 + natural(node, 3)*i31)*inverse_determinant
        dndy(i, node) = (natural(node, 1)*i12 + natural(node, 2)*i22 + natural(node, 3)*i32)*inverse_determinant
        dndz(i, node) = (natural(node, 1)*i13 + natural(node, 2)*i23 + natural(node, 3)*i33)*inverse_determinant
      end do
    end do
  end subroutine hex8_point_derivatives

  !> Strain and spin increments of a step from a velocity gradient (row by row, see
  !> hex8_velocity_gradient): strain_increment = sym(L) dt in TENSOR components (xx, yy, zz, xy,
  !> yz, zx), with its volumetric part replaced by volumetric_rate dt / 3 (the element mean, for
  !> the selective-reduced element; pass tr L itself to keep it); spin_increment = axial vector
  !> of skw(L) dt, w = (W32, W13, W21) dt.
  subroutine deformation_increments(nel, time_step, gradient, volumetric_rate, strain_increment, spin_increment)
    integer, intent(in) :: nel
    real(wp), intent(in) :: time_step
    real(wp), intent(in) :: gradient(block_size, 9), volumetric_rate(block_size)
    real(wp), intent(out) :: strain_increment(block_size, 6), spin_increment(block_size, 3)
    real(wp) :: half_step, volumetric_correction
    integer :: i
    half_step = 0.5_wp*time_step
    do i = 1, nel
      volumetric_correction = (volumetric_rate(i) - (gradient(i, 1) + gradient(i, 5) + gradient(i, 9))) &
                              *time_step/3.0_wp
      strain_increment(i, 1) = gradient(i, 1)*time_step + volumetric_correction
      strain_increment(i, 2) = gradient(i, 5)*time_step + volumetric_correction
      strain_increment(i, 3) = gradient(i, 9)*time_step + volumetric_correction
      strain_increment(i, 4) = (gradient(i, 2) + gradient(i, 4))*half_step
      strain_increment(i, 5) = (gradient(i, 6) + gradient(i, 8))*half_step
      strain_increment(i, 6) = (gradient(i, 7) + gradient(i, 3))*half_step
      spin_increment(i, 1) = (gradient(i, 8) - gradient(i, 6))*half_step
      spin_increment(i, 2) = (gradient(i, 3) - gradient(i, 7))*half_step
      spin_increment(i, 3) = (gradient(i, 4) - gradient(i, 2))*half_step
    end do
  end subroutine deformation_increments

  !> Number of distinct nodes among an element's eight: 8 a hexahedron, 6 a wedge
  !> (pentahedron), 5 a pyramid, 4 a tetrahedron written as a degenerate hexahedron.
  pure integer function distinct_corner_count(nodes)
    integer, intent(in) :: nodes(8)
    integer :: corner
    distinct_corner_count = 0
    do corner = 1, 8
      if (.not. any(nodes(1:corner - 1) == nodes(corner))) distinct_corner_count = distinct_corner_count + 1
    end do
  end function distinct_corner_count

  !> A tetrahedron (4 distinct nodes among the 8) may be written N1 N2 N3 N3 N4 N4 N4 N4 or
  !> N1 N2 N3 N4 N4 N4 N4 N4 (both are in use). Only the first makes the trilinear map the
  !> tetrahedron itself (the second spans a ruled surface through the four nodes: a
  !> different volume). `order` lists the corners that give the first form, a b c c d d d d
  !> with a, b, c, d the corners where the four nodes first appear, b and c swapped if that
  !> makes the volume positive (a tetrahedron has no other node order to get wrong), from the
  !> corner coordinates `x(3, 8)`. Any other element gets 1..8.
  pure subroutine tetrahedron_corner_order(nodes, x, order)
    integer, intent(in) :: nodes(8)
    real(wp), intent(in) :: x(3, 8)
    integer, intent(out) :: order(8)
    integer :: first(4), found, corner
    real(wp) :: a(3), b(3), c(3), triple
    order = [1, 2, 3, 4, 5, 6, 7, 8]
    if (distinct_corner_count(nodes) /= 4) return
    found = 0
    do corner = 1, 8
      if (any(nodes(1:corner - 1) == nodes(corner))) cycle
      found = found + 1
      first(found) = corner
    end do
    a = x(:, first(2)) - x(:, first(1))
    b = x(:, first(3)) - x(:, first(1))
    c = x(:, first(4)) - x(:, first(1))
    triple = c(1)*(a(2)*b(3) - a(3)*b(2)) + c(2)*(a(3)*b(1) - a(1)*b(3)) + c(3)*(a(1)*b(2) - a(2)*b(1))
    if (triple < 0.0_wp) first(2:3) = [first(3), first(2)]
    order = [first(1), first(2), first(3), first(3), first(4), first(4), first(4), first(4)]
  end subroutine tetrahedron_corner_order

  !> integral of N_I over each element (corner I of lane i), by the 2x2x2 Gauss rule, exact
  !> for the trilinear hexahedron (N_I det J is cubic in each natural coordinate). They sum to
  !> the volume. For a degenerate element the corners of one node together give the row sum of
  !> its consistent mass over rho: V / 4 at each node of a tetrahedron.
  subroutine hex8_corner_volumes(nel, x, y, z, corner_volume)
    integer, intent(in) :: nel
    real(wp), intent(in) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp), intent(out) :: corner_volume(block_size, 8)
    real(wp) :: natural(8, 3, 8), dndx(block_size, 8), dndy(block_size, 8), dndz(block_size, 8)
    real(wp) :: determinant(block_size), shape, g
    integer :: point, node, i
    g = 1.0_wp/sqrt(3.0_wp)
    call hex8_gauss_natural_derivatives(natural)
    corner_volume(1:nel, :) = 0.0_wp
    do point = 1, 8
      call hex8_point_derivatives(nel, natural(:, :, point), x, y, z, dndx, dndy, dndz, determinant)
      do node = 1, 8
        shape = 0.125_wp*(1.0_wp + node_xi(node)*g*node_xi(point))*(1.0_wp + node_eta(node)*g*node_eta(point)) &
                *(1.0_wp + node_zeta(node)*g*node_zeta(point))
        do i = 1, nel
          corner_volume(i, node) = corner_volume(i, node) + shape*determinant(i)
        end do
      end do
    end do
  end subroutine hex8_corner_volumes
end module hex8_geometry
