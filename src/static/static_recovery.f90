!> Results of the linear static analysis from the solved unknowns, point by point with the same
!> B matrices as the assembly: strain eps = B d, Cauchy stress sigma = D eps (small strain), the
!> internal forces K d = sum W B^T sigma on the unknowns, and the strain energy
!> sum W eps.sigma / 2 per part (= d.K.d / 2).
!>
!> Element stresses are volume averages over each solid's points: the 2x2x2 Gauss points of an FE
!> solid (weights det J), the integration points of an EFG background cell (weights W_g).
module static_recovery
  use kinds, only: wp, block_size
  use model, only: model_t, formulation_fe
  use efg_part, only: efg_part_t
  use static_stiffness, only: strain_displacement_matrix, solid_gauss_gradients
  use static_assembly, only: part_elasticity_matrix, fe_part_solids
  implicit none
  private

  public :: recover_static_fields

contains

  !> From the complete field of unknowns `generalized(:, node)` (solved values, prescribed values of
  !> eliminated dofs): element stresses `solid_stress(:, solid)`, internal forces
  !> `internal_force(:, node)` = K d on the unknowns, and the strain energy `part_energy(part)`.
  subroutine recover_static_fields(model, efg_parts, generalized, solid_stress, internal_force, part_energy)
    type(model_t), intent(in) :: model
    type(efg_part_t), intent(in) :: efg_parts(:)
    real(wp), intent(in) :: generalized(:, :)
    real(wp), intent(out) :: solid_stress(:, :), internal_force(:, :), part_energy(:)
    real(wp) :: d(6, 6), gradients(3, 8, 8, block_size), weights(8, block_size), b(6, 24), stress(6), strain(6)
    real(wp) :: element_displacement(24), element_force(24), volume
    real(wp), allocatable :: b_point(:, :), point_displacement(:), cell_volume(:), point_force(:)
    integer, allocatable :: solids(:)
    integer :: part, first, last, lane, point, inverted, k, g, pair_first, pair_last, n, a, solid

    solid_stress = 0.0_wp
    internal_force = 0.0_wp
    part_energy = 0.0_wp
    do part = 1, size(model%parts)
      if (model%parts(part)%formulation /= formulation_fe) cycle
      d = part_elasticity_matrix(model, part)
      solids = fe_part_solids(model, part)
      do first = 1, size(solids), block_size
        last = min(first + block_size - 1, size(solids))
        ! inverted solids were reported by the assembly; nothing reaches here for them
        call solid_gauss_gradients(model%coordinates, model%solid_nodes(:, solids(first:last)), gradients, weights, &
                                   inverted)
        do lane = 1, last - first + 1
          solid = solids(first + lane - 1)
          element_displacement = reshape(generalized(:, model%solid_nodes(:, solid)), [24])
          volume = 0.0_wp
          do point = 1, 8
            call strain_displacement_matrix(gradients(:, :, point, lane), b)
            strain = matmul(b, element_displacement)
            stress = matmul(d, strain)
            solid_stress(:, solid) = solid_stress(:, solid) + weights(point, lane)*stress
            volume = volume + weights(point, lane)
            part_energy(part) = part_energy(part) + 0.5_wp*weights(point, lane)*dot_product(strain, stress)
            element_force = weights(point, lane)*matmul(stress, b)
            ! node by node: a degenerate solid may repeat a node
            do a = 1, 8
              internal_force(:, model%solid_nodes(a, solid)) = internal_force(:, model%solid_nodes(a, solid)) + &
                                                               element_force(3*a - 2:3*a)
            end do
          end do
          solid_stress(:, solid) = solid_stress(:, solid)/volume
        end do
      end do
    end do

    allocate (cell_volume(size(model%solid_ids)))
    cell_volume = 0.0_wp
    do k = 1, size(efg_parts)
      associate (efg => efg_parts(k))
        d = part_elasticity_matrix(model, efg%part)
        ! work arrays for the point with the most pairs
        n = max(0, maxval(efg%point_offsets(2:) - efg%point_offsets(:size(efg%point_offsets) - 1)))
        if (allocated(b_point)) deallocate (b_point, point_displacement, point_force)
        allocate (b_point(6, 3*n), point_displacement(3*n), point_force(3*n))
        do g = 1, size(efg%point_volume)
          pair_first = efg%point_offsets(g)
          pair_last = efg%point_offsets(g + 1) - 1
          n = pair_last - pair_first + 1
          call strain_displacement_matrix(efg%pair_gradient(:, pair_first:pair_last), b_point(:, 1:3*n))
          point_displacement(1:3*n) = reshape(generalized(:, efg%pair_node(pair_first:pair_last)), [3*n])
          strain = matmul(b_point(:, 1:3*n), point_displacement(1:3*n))
          stress = matmul(d, strain)
          solid = efg%point_cell(g)
          solid_stress(:, solid) = solid_stress(:, solid) + efg%point_volume(g)*stress
          cell_volume(solid) = cell_volume(solid) + efg%point_volume(g)
          part_energy(efg%part) = part_energy(efg%part) + 0.5_wp*efg%point_volume(g)*dot_product(strain, stress)
          point_force(1:3*n) = efg%point_volume(g)*matmul(stress, b_point(:, 1:3*n))
          do a = 1, n
            associate (node => efg%pair_node(pair_first + a - 1))
              internal_force(:, node) = internal_force(:, node) + point_force(3*a - 2:3*a)
            end associate
          end do
        end do
      end associate
    end do
    do solid = 1, size(model%solid_ids)
      if (cell_volume(solid) > 0.0_wp) solid_stress(:, solid) = solid_stress(:, solid)/cell_volume(solid)
    end do
  end subroutine recover_static_fields
end module static_recovery
