!> The element step of the time loop. Blocks are coloured so that the blocks of one colour
!> share no node: the blocks of a colour compute their corner forces in parallel and add them
!> straight into the nodal forces; colours follow one another. Each node receives its
!> contributions in a fixed order (colour, then lane and corner), so the sum is bit-identical
!> for any `ncpu`, with no atomics and no per-corner force array in memory.
module element_forces
  use kinds, only: wp, block_size
  use model, only: model_t
  use solid_block, only: compute_solid_block
  use shell_block, only: shell_block_t, compute_shell_block
  use explicit_state, only: explicit_state_t
  use efg_forces, only: compute_efg_forces
  implicit none
  private

  public :: compute_element_forces, compute_shell_forces, compute_meshfree_forces

contains

  !> Internal forces at the current configuration with the half-step velocities; `dt` is the
  !> step just taken (0 at the start). Leaves the blocks' stable steps in the state.
  subroutine compute_element_forces(model, state, dt)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    real(wp), intent(in) :: dt
    real(wp) :: block_force(block_size, 8, 3)
    integer :: colour, k, b, node

    !$omp parallel do schedule(static) default(shared) private(node)
    do node = 1, state%node_count
      state%internal_force(:, node) = 0.0_wp
    end do
    !$omp end parallel do
    do colour = 1, size(state%block_colors%offsets) - 1
      !$omp parallel do schedule(dynamic, 2) default(shared) private(k, b, block_force)
      do k = state%block_colors%offsets(colour), state%block_colors%offsets(colour + 1) - 1
        b = state%block_colors%corners(k)
        call compute_solid_block(state%blocks(b), model%materials(state%blocks(b)%material), &
                                 state%coordinates, state%velocity, dt, block_force, &
                                 state%block_time_step(b), state%block_critical_element(b), &
                                 state%block_inverted_element(b))
        call add_block_forces(state%blocks(b)%element_count, state%blocks(b)%nodes, block_force, &
                              state%internal_force)
      end do
      !$omp end parallel do
    end do
  end subroutine compute_element_forces

  !> Forces and moments of the shells, added after the solids' (same colouring scheme); called
  !> after compute_element_forces, which cleared the nodal forces.
  subroutine compute_shell_forces(model, state, dt)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    real(wp), intent(in) :: dt
    real(wp) :: shell_force(block_size, 4, 6)
    integer :: colour, k, b, node

    if (size(state%shells) == 0) return
    !$omp parallel do schedule(static) default(shared) private(node)
    do node = 1, state%node_count
      state%internal_moment(:, node) = 0.0_wp
      state%shell_normal_sum(:, node) = 0.0_wp
      state%shell_area_sum(node) = 0.0_wp
    end do
    !$omp end parallel do
    do colour = 1, size(state%shell_colors%offsets) - 1
      !$omp parallel do schedule(dynamic, 2) default(shared) private(k, b, shell_force)
      do k = state%shell_colors%offsets(colour), state%shell_colors%offsets(colour + 1) - 1
        b = state%shell_colors%corners(k)
        call compute_shell_block(state%shells(b), model%materials(state%shells(b)%material), state%coordinates, &
                                 state%velocity, state%angular_velocity, dt, shell_force, state%shell_time_step(b), &
                                 state%shell_critical_element(b), state%shell_degenerate_element(b))
        call add_shell_forces(state%shells(b), shell_force, state%internal_force, state%internal_moment, &
                              state%shell_normal_sum, state%shell_area_sum)
      end do
      !$omp end parallel do
    end do
  end subroutine compute_shell_forces

  !> internal_force and internal_moment of the block's nodes += the shells' nodal forces and
  !> moments, corner by corner, lane by lane; and each node's sums of area x normal and area of
  !> its shells (for the drilling projection, see explicit_solver).
  subroutine add_shell_forces(block, shell_force, internal_force, internal_moment, normal_sum, area_sum)
    type(shell_block_t), intent(in) :: block
    real(wp), intent(in) :: shell_force(block_size, 4, 6)
    real(wp), intent(inout) :: internal_force(:, :), internal_moment(:, :), normal_sum(:, :), area_sum(:)
    integer :: corner, lane, node
    do corner = 1, 4
      do lane = 1, block%element_count
        if (corner == 4 .and. block%nodes(lane, 4) == block%nodes(lane, 3)) then
          node = 0
        else
          node = block%nodes(lane, corner)
          normal_sum(:, node) = normal_sum(:, node) + block%area(lane)*block%frame(lane, 3, :)
          area_sum(node) = area_sum(node) + block%area(lane)
        end if
        node = block%nodes(lane, corner)
        internal_force(:, node) = internal_force(:, node) + shell_force(lane, corner, 1:3)
        internal_moment(:, node) = internal_moment(:, node) + shell_force(lane, corner, 4:6)
      end do
    end do
  end subroutine add_shell_forces

  !> Forces of the meshfree parts, added after the finite elements' (a Gamma node shared with
  !> an FE part receives both, always in this order).
  subroutine compute_meshfree_forces(model, state, dt)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    real(wp), intent(in) :: dt
    integer :: k
    do k = 1, size(state%efg)
      call compute_efg_forces(model%materials(state%efg(k)%geometry%material), state%efg(k), &
                              state%displacement, state%velocity, dt, state%internal_force)
    end do
  end subroutine compute_meshfree_forces

  !> internal_force(:, node) += the block's corner forces, corner by corner, lane by lane.
  subroutine add_block_forces(element_count, nodes, block_force, internal_force)
    integer, intent(in) :: element_count
    integer, intent(in) :: nodes(block_size, 8)
    real(wp), intent(in) :: block_force(block_size, 8, 3)
    real(wp), intent(inout) :: internal_force(:, :)
    integer :: corner, lane, node
    do corner = 1, 8
      do lane = 1, element_count
        node = nodes(lane, corner)
        internal_force(1, node) = internal_force(1, node) + block_force(lane, corner, 1)
        internal_force(2, node) = internal_force(2, node) + block_force(lane, corner, 2)
        internal_force(3, node) = internal_force(3, node) + block_force(lane, corner, 3)
      end do
    end do
  end subroutine add_block_forces
end module element_forces
