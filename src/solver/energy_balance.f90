!> Energies of the whole model and of each part (glstat, matsum), summed in a fixed order.
module energy_balance
  use kinds, only: wp, block_size
  use fixed_order_sum, only: sum_chunk_size, chunk_count
  use model, only: model_t
  use explicit_state, only: explicit_state_t
  use rigid_bodies, only: rigid_body_energy
  implicit none
  private

  public :: update_energy_totals, part_energies, total_energy, energy_ratio

contains

  !> Kinetic energy and momentum at the integer step and the sums of the element energies.
  !>
  !> The kinetic energy is 1/2 m v^{n-1/2} . v^{n+1/2} (here with the half steps around the
  !> current time): with it, central differences conserve kinetic plus strain energy exactly for
  !> a linear system, whereas 1/2 m (v^n)^2 overstates the energy of high-frequency modes by up to
  !> (omega dt)^2 / 4 and looks like a drift (Belytschko, Liu & Moran, Nonlinear Finite Elements,
  !> section 6.2.3).
  subroutine update_energy_totals(model, state)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    real(wp) :: body_kinetic, body_momentum(3), body_angular_momentum(3), body_velocity(3)
    integer :: chunk, first, last, node, b, k
    real(wp) :: partial(4, chunk_count(state%node_count)), velocity(3), next_velocity(3)
    real(wp) :: half_step, average_step, step_correction

    half_step = 0.5_wp*state%time_step
    average_step = 0.5_wp*(state%time_step + state%next_time_step)
    ! the elements book the newest forces' work with the step just taken; the kinetic energy
    ! above uses the mean of that step and the next (see solid_block)
    step_correction = 0.25_wp*(state%next_time_step - state%time_step)
    !$omp parallel do schedule(static) default(shared) private(chunk, first, last, node, velocity, next_velocity)
    do chunk = 1, size(partial, 2)
      first = (chunk - 1)*sum_chunk_size + 1
      last = min(chunk*sum_chunk_size, state%node_count)
      partial(:, chunk) = 0.0_wp
      do node = first, last
        if (state%is_rigid_node(node)) cycle   ! moves with its body (below)
        next_velocity = state%velocity(:, node) + average_step*state%acceleration(:, node)
        partial(1, chunk) = partial(1, chunk) + state%mass(node)*dot_product(state%velocity(:, node), next_velocity)
        if (state%rotary_inertia(node) > 0.0_wp) then
          next_velocity = state%angular_velocity(:, node) + average_step*state%angular_acceleration(:, node)
          partial(1, chunk) = partial(1, chunk) + &
                              state%rotary_inertia(node)*dot_product(state%angular_velocity(:, node), next_velocity)
        end if
        velocity = state%velocity(:, node) + half_step*state%acceleration(:, node)
        partial(2:4, chunk) = partial(2:4, chunk) + state%mass(node)*velocity
      end do
    end do
    !$omp end parallel do
    state%energy%kinetic = 0.0_wp
    state%energy%momentum = 0.0_wp
    do chunk = 1, size(partial, 2)
      state%energy%kinetic = state%energy%kinetic + 0.5_wp*partial(1, chunk)
      state%energy%momentum = state%energy%momentum + partial(2:4, chunk)
    end do
    ! rigid bodies: translation and rotation of each body
    do b = 1, size(state%rigid)
      call rigid_body_energy(model, b, state%rigid(b), state%acceleration, state%mass, half_step, average_step, &
                             body_kinetic, body_momentum, body_angular_momentum, body_velocity)
      state%energy%kinetic = state%energy%kinetic + body_kinetic
      state%energy%momentum = state%energy%momentum + body_momentum
    end do
    ! moving rigid walls are bodies of the model
    do b = 1, size(state%walls)
      associate (wall => state%walls(b))
        state%energy%kinetic = state%energy%kinetic + 0.5_wp*wall%mass*wall%speed**2
        state%energy%momentum = state%energy%momentum + wall%mass*wall%speed*wall%normal
      end associate
    end do
    state%energy%internal = 0.0_wp
    state%energy%hourglass = 0.0_wp
    do b = 1, size(state%blocks)
      associate (block => state%blocks(b))
        state%energy%internal = state%energy%internal + booked_energy(block%internal_energy, block%force_power, &
          block%element_count, step_correction)
        state%energy%hourglass = state%energy%hourglass + booked_energy(block%hourglass_energy, block%hourglass_power, &
          block%element_count, step_correction)
      end associate
    end do
    do b = 1, size(state%shells)
      associate (shell => state%shells(b))
        state%energy%internal = state%energy%internal + booked_energy(shell%internal_energy, shell%force_power, &
          shell%element_count, step_correction)
        state%energy%hourglass = state%energy%hourglass + booked_energy(shell%hourglass_energy, shell%hourglass_power, &
          shell%element_count, step_correction)
      end associate
    end do
    do k = 1, size(state%efg)
      do b = 1, size(state%efg(k)%blocks)
        associate (block => state%efg(k)%blocks(b))
          state%energy%internal = state%energy%internal + booked_energy(block%internal_energy, block%force_power, &
            block%point_count, step_correction)
        end associate
      end do
    end do
  end subroutine update_energy_totals

  !> Kinetic, internal and hourglass energy of each part (indexed like model%parts), measured
  !> as the totals are. A node's kinetic energy is shared among parts in proportion to the
  !> mass each element gives it.
  subroutine part_energies(model, state, part_count, kinetic, internal, hourglass)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    real(wp) :: body_kinetic, body_momentum(3), body_angular_momentum(3), body_velocity(3)
    integer, intent(in) :: part_count
    real(wp), intent(out) :: kinetic(part_count), internal(part_count), hourglass(part_count)
    integer :: b, k, corner, lane, node
    real(wp) :: velocity(3), next_velocity(3), average_step, step_correction
    kinetic = 0.0_wp
    internal = 0.0_wp
    hourglass = 0.0_wp
    average_step = 0.5_wp*(state%time_step + state%next_time_step)
    step_correction = 0.25_wp*(state%next_time_step - state%time_step)
    do b = 1, size(state%blocks)
      associate (block => state%blocks(b))
        internal(block%part) = internal(block%part) + booked_energy(block%internal_energy, block%force_power, &
          block%element_count, step_correction)
        hourglass(block%part) = hourglass(block%part) + booked_energy(block%hourglass_energy, block%hourglass_power, &
          block%element_count, step_correction)
        do corner = 1, 8
          do lane = 1, block%element_count
            node = block%nodes(lane, corner)
            velocity = state%velocity(:, node)
            next_velocity = velocity + average_step*state%acceleration(:, node)
            kinetic(block%part) = kinetic(block%part) + &
                                  0.5_wp*state%corner_mass(lane, corner, b)*dot_product(velocity, next_velocity)
          end do
        end do
      end associate
    end do
    do b = 1, size(state%shells)
      associate (shell => state%shells(b))
        internal(shell%part) = internal(shell%part) + booked_energy(shell%internal_energy, shell%force_power, &
          shell%element_count, step_correction)
        hourglass(shell%part) = hourglass(shell%part) + booked_energy(shell%hourglass_energy, shell%hourglass_power, &
          shell%element_count, step_correction)
        do corner = 1, 4
          do lane = 1, shell%element_count
            node = shell%nodes(lane, corner)
            velocity = state%velocity(:, node)
            next_velocity = velocity + average_step*state%acceleration(:, node)
            kinetic(shell%part) = kinetic(shell%part) + &
                                  0.5_wp*state%shell_corner_mass(lane, corner, b)*dot_product(velocity, next_velocity)
            velocity = state%angular_velocity(:, node)
            next_velocity = velocity + average_step*state%angular_acceleration(:, node)
            kinetic(shell%part) = kinetic(shell%part) + 0.5_wp*state%shell_corner_inertia(lane, corner, b)* &
                                  dot_product(velocity, next_velocity)
          end do
        end do
      end associate
    end do
    ! a rigid part's kinetic energy is its body's (the corner masses of deformable elements at
    ! the body's nodes move with the body and count in both parts)
    do b = 1, size(state%rigid)
      if (model%rigid_bodies(b)%part == 0) cycle
      call rigid_body_energy(model, b, state%rigid(b), state%acceleration, state%mass, 0.5_wp*state%time_step, &
                             average_step, body_kinetic, body_momentum, body_angular_momentum, body_velocity)
      kinetic(model%rigid_bodies(b)%part) = kinetic(model%rigid_bodies(b)%part) + body_kinetic
    end do
    do k = 1, size(state%efg)
      associate (efg => state%efg(k), part => state%efg(k)%geometry%part)
        do b = 1, size(efg%blocks)
          internal(part) = internal(part) + booked_energy(efg%blocks(b)%internal_energy, efg%blocks(b)%force_power, &
            efg%blocks(b)%point_count, step_correction)
        end do
        do lane = 1, size(efg%geometry%mass_node)
          node = efg%geometry%mass_node(lane)
          velocity = state%velocity(:, node)
          next_velocity = velocity + average_step*state%acceleration(:, node)
          kinetic(part) = kinetic(part) + 0.5_wp*efg%density*efg%geometry%mass_volume(lane)* &
                          dot_product(velocity, next_velocity)
        end do
      end associate
    end do
  end subroutine part_energies

  !> Energy of the first `count` lanes of a block as the solver reports it: the work booked by
  !> the elements plus the step correction of their newest forces' power (see solid_block).
  pure real(wp) function booked_energy(energy, power, count, step_correction)
    real(wp), intent(in) :: energy(:), power(:), step_correction
    integer, intent(in) :: count
    booked_energy = sum(energy(1:count)) + step_correction*sum(power(1:count))
  end function booked_energy

  !> Total energy: kinetic + internal + hourglass + contact + rigid-wall (energy the walls took).
  pure real(wp) function total_energy(state)
    type(explicit_state_t), intent(in) :: state
    total_energy = state%energy%kinetic + state%energy%internal + state%energy%hourglass + &
                   state%energy%contact + state%energy%rigid_wall
  end function total_energy

  !> Energy ratio as in glstat: total / (initial total + external work); 1 is a perfect balance.
  pure real(wp) function energy_ratio(state)
    type(explicit_state_t), intent(in) :: state
    real(wp) :: reference
    reference = state%energy%initial_total + state%energy%external_work
    if (abs(reference) > tiny(1.0_wp)) then
      energy_ratio = total_energy(state)/reference
    else
      energy_ratio = 1.0_wp
    end if
  end function energy_ratio
end module energy_balance
