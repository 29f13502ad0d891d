!> Row-sum lumped masses of a meshfree part, as volume shares (formulation section 5; Wang et
!> al. 2009, eqs. 29-31): m_I = rho0 * integral of Psi_I = rho0 * sum_g Psi_I(X_g) W_g.
!>
!> Because the coupled functions are a partition of unity, the shares of one cell add up to its
!> volume and the total mass is exact. A share may be negative where a large support meets a thin
!> part (the MLS functions of such particles dip below zero near the boundary); the set-up checks
!> the sign after adding all cells.
module efg_mass
  use kinds, only: wp
  use efg_shape_functions, only: cell_shape_context_t, evaluate_shape_functions
  implicit none
  private

  public :: cell_mass_volumes

contains

  !> Volume shares of the local nodes of the context's cell, sum_g Psi(X_g) W_g over the points
  !> `parametric(:, g)` of the cell with weights `volume(g)`. The set-up passes the 8 sub-cell
  !> centres with the exact sub-cell volumes (IDIM 1) or the integration points themselves, the
  !> Gauss points with W = weight det J (IDIM 2: 8, IDIM 4: 64).
  subroutine cell_mass_volumes(context, parametric, volume, mass_volume, singular_points, worst_residual)
    type(cell_shape_context_t), intent(in) :: context
    real(wp), intent(in) :: parametric(:, :)
    real(wp), intent(in) :: volume(:)
    real(wp), intent(out) :: mass_volume(:)
    integer, intent(inout) :: singular_points
    real(wp), intent(inout) :: worst_residual
    real(wp) :: values(context%node_count), point(3), residual
    integer :: g, rank, n

    n = context%node_count
    mass_volume(1:n) = 0.0_wp
    do g = 1, size(volume)
      call evaluate_shape_functions(context, parametric(:, g), point, values, rank, residual)
      if (rank > 0 .and. rank < 4) singular_points = singular_points + 1
      worst_residual = max(worst_residual, residual)
      mass_volume(1:n) = mass_volume(1:n) + values*volume(g)
    end do
  end subroutine cell_mass_volumes
end module efg_mass
