!> The transformation from generalized to physical displacements of the interior particles
!> (formulation section 5; Wang et al. 2009, eq. 16): uhat_J = sum_I Psi_I(X_J) d_I.
!>
!> The coupled functions are continuous, so Psi_I(X_J) may be evaluated in any cell that has J as
!> a vertex; the set-up uses the first cell of the part that does (`owner_cell`). At the vertex
!> the FE functions are exact Kronecker deltas, so Gamma nodes get exactly zero coefficients and
!> only particles remain.
module efg_transformation
  use kinds, only: wp
  use efg_cell_geometry, only: vertex_parametric
  use efg_shape_functions, only: cell_shape_context_t, evaluate_shape_functions
  implicit none
  private

  public :: particle_transformation_row

contains

  !> Row J of the transformation for the particle at vertex `vertex` of the context's cell:
  !> the local nodes k with Psi_k(X_J) /= 0, `nodes(1:count)` (model node indices, ascending) and
  !> `values(1:count)`.
  subroutine particle_transformation_row(context, vertex, nodes, values, count, singular_points, worst_residual)
    type(cell_shape_context_t), intent(in) :: context
    integer, intent(in) :: vertex
    integer, intent(out) :: nodes(:)
    real(wp), intent(out) :: values(:)
    integer, intent(out) :: count
    integer, intent(inout) :: singular_points
    real(wp), intent(inout) :: worst_residual
    real(wp) :: all_values(context%node_count), point(3), residual
    integer :: k, rank

    call evaluate_shape_functions(context, vertex_parametric(:, vertex), point, all_values, rank, residual)
    if (rank > 0 .and. rank < 4) singular_points = singular_points + 1
    worst_residual = max(worst_residual, residual)
    count = 0
    do k = 1, context%node_count
      if (all_values(k) == 0.0_wp) cycle
      count = count + 1
      nodes(count) = context%nodes(k)
      values(count) = all_values(k)
    end do
  end subroutine particle_transformation_row
end module efg_transformation
