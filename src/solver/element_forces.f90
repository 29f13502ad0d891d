!> The element step of the time loop: every block computes its corner forces (in parallel,
!> each block writing only its own slice), then every node gathers its corners in a fixed
!> order. No atomics, no thread-dependent summation order: bit-identical for any `ncpu`.
module element_forces
  use kinds, only: wp, block_size
  use model, only: model_t
  use solid_block, only: compute_solid_block
  use explicit_state, only: explicit_state_t
  implicit none
  private

  public :: compute_element_forces

contains

  !> Internal forces at the current configuration with the half-step velocities; `dt` is the
  !> step just taken (0 at the start). Leaves the blocks' stable steps in the state.
  subroutine compute_element_forces(model, state, dt)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    real(wp), intent(in) :: dt
    integer :: b

    !$omp parallel do schedule(dynamic, 4) default(shared) private(b)
    do b = 1, size(state%blocks)
      call compute_solid_block(state%blocks(b), model%materials(state%blocks(b)%material), &
                               state%coordinates, state%velocity, dt, state%corner_force(:, :, :, b), &
                               state%block_time_step(b), state%block_critical_element(b), &
                               state%block_inverted_element(b))
    end do
    !$omp end parallel do
    call gather_corner_forces(state%node_count, state%node_corners%offsets, state%node_corners%corners, &
                              state%corner_force, state%internal_force)
  end subroutine compute_element_forces

  !> internal_force(:, node) = sum of the node's corner forces, in slot order.
  subroutine gather_corner_forces(node_count, offsets, slots, corner_force, internal_force)
    integer, intent(in) :: node_count
    integer, intent(in) :: offsets(:), slots(:)
    real(wp), intent(in) :: corner_force(*)
    real(wp), intent(out) :: internal_force(3, node_count)
    integer, parameter :: component_stride = 8*block_size
    integer :: node, k, slot
    real(wp) :: fx, fy, fz

    !$omp parallel do schedule(static) default(shared) private(node, k, slot, fx, fy, fz)
    do node = 1, node_count
      fx = 0.0_wp
      fy = 0.0_wp
      fz = 0.0_wp
      do k = offsets(node), offsets(node + 1) - 1
        slot = slots(k)
        fx = fx + corner_force(slot)
        fy = fy + corner_force(slot + component_stride)
        fz = fz + corner_force(slot + 2*component_stride)
      end do
      internal_force(1, node) = fx
      internal_force(2, node) = fy
      internal_force(3, node) = fz
    end do
    !$omp end parallel do
  end subroutine gather_corner_forces
end module element_forces
