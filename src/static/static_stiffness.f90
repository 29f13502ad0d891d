!> Small-strain linear elasticity kernels of the static analysis: the isotropic elasticity
!> matrix D, the strain-displacement matrix B of one integration point from its (node, gradient)
!> pairs, the point stiffness W B^T D B (node pair by node pair), and the gradients of the fully
!> integrated hexahedron.
!>
!> One B serves both discretisations: for a hexahedron the gradients are dN_I/dx at a 2x2x2 Gauss
!> point (hex8_geometry, as in the explicit fully integrated element) with W = det J; for an EFG
!> point they are the pairs of efg_part_t (smoothed gradients for IDIM 1, direct MLS gradients
!> for the Gauss variants) with W = W_g, exactly what the explicit meshfree update uses.
!>
!> Voigt order xx, yy, zz, xy, yz, zx (the output order), engineering shear strains
!> (gamma_xy = du_x/dy + du_y/dx), so that sigma = D eps and the energy density is eps.D eps / 2.
module static_stiffness
  use kinds, only: wp, block_size
  use hex8_geometry, only: hex8_gauss_natural_derivatives, hex8_point_derivatives
  implicit none
  private

  public :: elasticity_matrix, strain_displacement_matrix, add_point_stiffness, solid_gauss_gradients

contains

  !> Isotropic elasticity matrix from the bulk and shear moduli: lambda = K - 2G/3, mu = G.
  pure function elasticity_matrix(bulk_modulus, shear_modulus) result(d)
    real(wp), intent(in) :: bulk_modulus, shear_modulus
    real(wp) :: d(6, 6)
    real(wp) :: lambda
    integer :: i
    lambda = bulk_modulus - 2.0_wp*shear_modulus/3.0_wp
    d = 0.0_wp
    d(1:3, 1:3) = lambda
    do i = 1, 3
      d(i, i) = lambda + 2.0_wp*shear_modulus
      d(i + 3, i + 3) = shear_modulus
    end do
  end function elasticity_matrix

  !> B (6, 3n) of a point whose n nodes have the shape-function gradients `gradients(:, a)`; the
  !> displacement of node a is column block 3(a-1)+1 : 3a, so that eps = B u.
  pure subroutine strain_displacement_matrix(gradients, b)
    real(wp), intent(in) :: gradients(:, :)
    real(wp), intent(out) :: b(:, :)
    integer :: a, column
    b = 0.0_wp
    do a = 1, size(gradients, 2)
      column = 3*(a - 1)
      b(1, column + 1) = gradients(1, a)
      b(2, column + 2) = gradients(2, a)
      b(3, column + 3) = gradients(3, a)
      b(4, column + 1) = gradients(2, a)
      b(4, column + 2) = gradients(1, a)
      b(5, column + 2) = gradients(3, a)
      b(5, column + 3) = gradients(2, a)
      b(6, column + 1) = gradients(3, a)
      b(6, column + 3) = gradients(1, a)
    end do
  end subroutine strain_displacement_matrix

  !> stiffness += weight B^T D B for an isotropic D (Lame constants lambda, mu), node pair by node
  !> pair: the 3x3 block of nodes a and b is
  !>   weight (lambda g_a g_b^T + mu g_b g_a^T + mu (g_a . g_b) I),
  !> which is B_a^T D B_b written out (B_a the three columns of node a in
  !> strain_displacement_matrix), at about a seventh of the operations of the dense product.
  !> Node a's block sits at rows and columns 3 (positions(a) - 1) + 1 : 3 positions(a), so that
  !> several points can add into one matrix over the union of their nodes.
  pure subroutine add_point_stiffness(weight, gradients, positions, lambda, mu, stiffness)
    real(wp), intent(in) :: weight
    real(wp), intent(in) :: gradients(:, :)
    integer, intent(in) :: positions(:)
    real(wp), intent(in) :: lambda, mu
    real(wp), intent(inout) :: stiffness(:, :)
    real(wp) :: ga(3), gb(3), block(3, 3), shear
    integer :: a, b, row, column, i

    do b = 1, size(gradients, 2)
      gb = weight*gradients(:, b)
      column = 3*(positions(b) - 1)
      do a = 1, size(gradients, 2)
        ga = gradients(:, a)
        row = 3*(positions(a) - 1)
        shear = mu*dot_product(ga, gb)
        do i = 1, 3
          block(:, i) = lambda*ga*gb(i) + mu*gb*ga(i)
          block(i, i) = block(i, i) + shear
        end do
        stiffness(row + 1:row + 3, column + 1:column + 3) = stiffness(row + 1:row + 3, column + 1:column + 3) + block
      end do
    end do
  end subroutine add_point_stiffness

  !> Gradients dN_I/dx of the eight nodes at the eight 2x2x2 Gauss points of up to block_size
  !> solids (`solid_nodes(:, lane)` their node indices into `coordinates`), computed by lanes as
  !> the element kernels do: gradients(:, node, point, lane), and weights(point, lane) = det J (the
  !> Gauss weights are 1). `inverted` is the first lane with det J <= 0 at some point (0: none).
  subroutine solid_gauss_gradients(coordinates, solid_nodes, gradients, weights, inverted)
    real(wp), intent(in) :: coordinates(:, :)
    integer, intent(in) :: solid_nodes(:, :)
    real(wp), intent(out) :: gradients(:, :, :, :), weights(:, :)
    integer, intent(out) :: inverted
    real(wp) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp) :: natural(8, 3, 8), dndx(block_size, 8), dndy(block_size, 8), dndz(block_size, 8)
    real(wp) :: determinant(block_size)
    integer :: nel, point, lane

    nel = size(solid_nodes, 2)
    x = 0.0_wp
    y = 0.0_wp
    z = 0.0_wp
    do lane = 1, nel
      x(lane, :) = coordinates(1, solid_nodes(:, lane))
      y(lane, :) = coordinates(2, solid_nodes(:, lane))
      z(lane, :) = coordinates(3, solid_nodes(:, lane))
    end do
    call hex8_gauss_natural_derivatives(natural)
    inverted = 0
    do point = 1, 8
      call hex8_point_derivatives(nel, natural(:, :, point), x, y, z, dndx, dndy, dndz, determinant)
      do lane = 1, nel
        gradients(1, :, point, lane) = dndx(lane, :)
        gradients(2, :, point, lane) = dndy(lane, :)
        gradients(3, :, point, lane) = dndz(lane, :)
        weights(point, lane) = determinant(lane)
        if (determinant(lane) <= 0.0_wp .and. (inverted == 0 .or. lane < inverted)) inverted = lane
      end do
    end do
  end subroutine solid_gauss_gradients
end module static_stiffness
