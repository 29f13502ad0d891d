!> Energies of the whole model and of each part (glstat, matsum), summed in a fixed order.
module energy_balance
  use kinds, only: wp, block_size
  use fixed_order_sum, only: sum_chunk_size
  use model, only: model_t
  use explicit_state, only: explicit_state_t
  use rigid_bodies, only: rigid_body_energy
  implicit none
  private

  public :: update_energy_totals, part_energies, total_energy, energy_ratio

contains

  !> Kinetic energy and momentum at the integer step and the sums of the element energies.
  !>
  !> Central differences conserve 1/2 m v^{n-1/2} . v^{n+1/2} plus the strain energy exactly for
  !> a linear system (Belytschko, Liu & Moran, Nonlinear Finite Elements, section 6.2.3). That
  !> product is 1/2 m (v^n)^2 - 1/8 m (dt a^n)^2, with v^n the mean of the two half-step
  !> velocities and dt the mean of the two steps. The first term, never negative, is reported as
  !> the kinetic energy; the second, the central-difference part of the strain energy (for a
  !> linear system 1/2 x.(K - dt^2/4 K M^-1 K) x is what the scheme conserves, positive while the
  !> step is stable), is booked with the internal energy. The total is the conserved one, and
  !> the kinetic energy no longer dips below zero when energy sits in modes near the stability
  !> limit (velocities that change sign between half steps made the product negative).
  subroutine update_energy_totals(model, state)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    real(wp) :: body_kinetic, body_momentum(3), body_angular_momentum(3), body_velocity(3)
    integer :: chunk, first, last, node, b, k
    real(wp) :: velocity(3)
    real(wp) :: half_step, average_step, step_correction

    half_step = 0.5_wp*state%time_step
    average_step = 0.5_wp*(state%time_step + state%next_time_step)
    ! the elements book the newest forces' work with the step just taken; the kinetic energy
    ! above uses the mean of that step and the next (see solid_block)
    step_correction = 0.25_wp*(state%next_time_step - state%time_step)
    associate (partial => state%chunk_sums)
      !$omp parallel do schedule(static) default(shared) private(chunk, first, last, node, velocity)
      do chunk = 1, size(partial, 2)
        first = (chunk - 1)*sum_chunk_size + 1
        last = min(chunk*sum_chunk_size, state%node_count)
        partial(:, chunk) = 0.0_wp
        do node = first, last
          if (state%is_rigid_node(node)) cycle   ! moves with its body (below)
          call add_kinetic_energy(state%mass(node), state%velocity(:, node), state%acceleration(:, node), &
                                  average_step, partial(1, chunk), partial(5, chunk))
          if (state%rotary_inertia(node) > 0.0_wp) &
            call add_kinetic_energy(state%rotary_inertia(node), state%angular_velocity(:, node), &
                                    state%angular_acceleration(:, node), average_step, partial(1, chunk), partial(5, chunk))
          velocity = state%velocity(:, node) + half_step*state%acceleration(:, node)
          partial(2:4, chunk) = partial(2:4, chunk) + state%mass(node)*velocity
        end do
      end do
      !$omp end parallel do
      state%energy%kinetic = 0.0_wp
      state%energy%momentum = 0.0_wp
      state%energy%internal = 0.0_wp
      do chunk = 1, size(partial, 2)
        state%energy%kinetic = state%energy%kinetic + partial(1, chunk)
        state%energy%momentum = state%energy%momentum + partial(2:4, chunk)
        state%energy%internal = state%energy%internal + partial(5, chunk)
      end do
    end associate
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
    real(wp) :: average_step, step_correction
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
            call add_kinetic_energy(state%corner_mass(lane, corner, b), state%velocity(:, node), &
                                    state%acceleration(:, node), average_step, kinetic(block%part), internal(block%part))
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
            call add_kinetic_energy(state%shell_corner_mass(lane, corner, b), state%velocity(:, node), &
                                    state%acceleration(:, node), average_step, kinetic(shell%part), internal(shell%part))
            call add_kinetic_energy(state%shell_corner_inertia(lane, corner, b), state%angular_velocity(:, node), &
                                    state%angular_acceleration(:, node), average_step, kinetic(shell%part), &
                                    internal(shell%part))
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
          call add_kinetic_energy(efg%density*efg%geometry%mass_volume(lane), state%velocity(:, node), &
                                  state%acceleration(:, node), average_step, kinetic(part), internal(part))
        end do
      end associate
    end do
  end subroutine part_energies

  !> Add a mass's share of the conserved kinetic energy 1/2 m v^{n-1/2} . v^{n+1/2}, split as
  !> explained at update_energy_totals: 1/2 m (v^n)^2 to `kinetic`, -1/8 m (dt a)^2 to `internal`.
  !> `velocity` is v^{n-1/2}, `average_step` the mean of the steps around t^n.
  pure subroutine add_kinetic_energy(mass, velocity, acceleration, average_step, kinetic, internal)
    real(wp), intent(in) :: mass, velocity(3), acceleration(3), average_step
    real(wp), intent(inout) :: kinetic, internal
    real(wp) :: half_change(3), midpoint(3)
    half_change = 0.5_wp*average_step*acceleration
    midpoint = velocity + half_change
    kinetic = kinetic + 0.5_wp*mass*dot_product(midpoint, midpoint)
    internal = internal - 0.5_wp*mass*dot_product(half_change, half_change)
  end subroutine add_kinetic_energy

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
