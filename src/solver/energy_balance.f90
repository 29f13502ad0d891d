!> Energies of the whole model and of each part (glstat, matsum), summed in a fixed order.
module energy_balance
  use kinds, only: wp
  use fixed_order_sum, only: sum_chunk_size
  use model, only: model_t
  use explicit_state, only: explicit_state_t, energy_totals_t
  use element_work, only: add_kinetic_energy
  use rigid_bodies, only: rigid_body_energy
  implicit none
  private

  public :: measured_energies, part_energies, part_momenta, total_energy, energy_ratio, energy_ratio_without_eroded

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
  subroutine measured_energies(model, state, partial, energy)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    real(wp), intent(inout) :: partial(:, :)      !< scratch (5, chunks of nodes)
    type(energy_totals_t), intent(inout) :: energy !< the ledger: the measured energies are replaced
    real(wp) :: body_kinetic, body_momentum(3), body_angular_momentum(3), body_velocity(3)
    integer :: chunk, first, last, node, b, k
    real(wp) :: velocity(3)
    real(wp) :: half_step, average_step, step_correction

    half_step = 0.5_wp*state%time_step
    average_step = 0.5_wp*(state%time_step + state%next_time_step)
    ! the elements book the newest forces' work with the step just taken; the kinetic energy
    ! above uses the mean of that step and the next (see solid_block)
    step_correction = 0.25_wp*(state%next_time_step - state%time_step)
    !$omp parallel do schedule(static) default(shared) private(chunk, first, last, node, velocity)
    do chunk = 1, size(partial, 2)
      first = (chunk - 1)*sum_chunk_size + 1
        last = min(chunk*sum_chunk_size, state%nodes%count)
        partial(:, chunk) = 0.0_wp
        do node = first, last
          if (state%nodes%is_rigid_node(node)) cycle   ! moves with its body (below)
          call add_kinetic_energy(state%nodes%mass(node), state%nodes%velocity(:, node), state%nodes%acceleration(:, node), &
                                  average_step, partial(1, chunk), partial(5, chunk))
          if (state%nodes%rotary_inertia(node) > 0.0_wp) &
            call add_kinetic_energy(state%nodes%rotary_inertia(node), state%nodes%angular_velocity(:, node), &
                                    state%nodes%angular_acceleration(:, node), average_step, partial(1, chunk), partial(5, chunk))
          velocity = state%nodes%velocity(:, node) + half_step*state%nodes%acceleration(:, node)
          partial(2:4, chunk) = partial(2:4, chunk) + state%nodes%mass(node)*velocity
        end do
      end do
    !$omp end parallel do
    energy%kinetic = 0.0_wp
    energy%momentum = 0.0_wp
    energy%internal = 0.0_wp
    do chunk = 1, size(partial, 2)
      energy%kinetic = energy%kinetic + partial(1, chunk)
      energy%momentum = energy%momentum + partial(2:4, chunk)
      energy%internal = energy%internal + partial(5, chunk)
    end do
    ! rigid bodies: translation and rotation of each body
    do b = 1, size(state%rigid)
      call rigid_body_energy(model, b, state%rigid(b), state%nodes%acceleration, state%nodes%mass, half_step, average_step, &
                             body_kinetic, body_momentum, body_angular_momentum, body_velocity)
      energy%kinetic = energy%kinetic + body_kinetic
      energy%momentum = energy%momentum + body_momentum
    end do
    ! moving rigid walls are bodies of the model
    do b = 1, size(state%walls)
      associate (wall => state%walls(b))
        energy%kinetic = energy%kinetic + 0.5_wp*wall%mass*wall%speed**2
        energy%momentum = energy%momentum + wall%mass*wall%speed*wall%normal
      end associate
    end do
    energy%hourglass = 0.0_wp
    do k = 1, size(state%groups)
      call state%groups(k)%group%add_energies(step_correction, energy%internal, energy%hourglass)
    end do
    energy%eroded_internal = 0.0_wp
    energy%eroded_hourglass = 0.0_wp
    energy%eroded_kinetic = 0.0_wp
    do k = 1, size(state%groups)
      call state%groups(k)%group%add_eroded_energies(energy%eroded_internal, energy%eroded_hourglass)
    end do
  end subroutine measured_energies


  !> Kinetic, internal and hourglass energy of each part (indexed like model%parts), measured
  !> as the totals are. A node's kinetic energy is shared among parts in proportion to the
  !> mass each element gives it.
  subroutine part_energies(model, state, part_count, kinetic, internal, hourglass)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    real(wp) :: body_kinetic, body_momentum(3), body_angular_momentum(3), body_velocity(3)
    integer, intent(in) :: part_count
    real(wp), intent(out) :: kinetic(part_count), internal(part_count), hourglass(part_count)
    integer :: b, k
    real(wp) :: average_step, step_correction
    kinetic = 0.0_wp
    internal = 0.0_wp
    hourglass = 0.0_wp
    average_step = 0.5_wp*(state%time_step + state%next_time_step)
    step_correction = 0.25_wp*(state%next_time_step - state%time_step)
    do k = 1, size(state%groups)
      call state%groups(k)%group%add_part_energies(state%nodes, average_step, step_correction, kinetic, internal, &
                                                   hourglass)
    end do
    ! a rigid part's kinetic energy is its body's (the corner masses of deformable elements at
    ! the body's nodes move with the body and count in both parts)
    do b = 1, size(state%rigid)
      if (model%rigid_bodies(b)%part == 0) cycle
      call rigid_body_energy(model, b, state%rigid(b), state%nodes%acceleration, state%nodes%mass, 0.5_wp*state%time_step, &
                             average_step, body_kinetic, body_momentum, body_angular_momentum, body_velocity)
      kinetic(model%rigid_bodies(b)%part) = kinetic(model%rigid_bodies(b)%part) + body_kinetic
    end do
  end subroutine part_energies

  !> Momentum, mass and rigid-body velocity of each part (matsum; indexed like model%parts), at
  !> the integer step as the glstat momentum. A node's momentum is shared among parts in
  !> proportion to the mass each element gives it (as the kinetic energy). A rigid part has
  !> its body's momentum, mass and velocity (a body of merged parts is reported under its
  !> first part); the other parts' rigid-body velocity is 0, as LS-DYNA writes it.
  subroutine part_momenta(model, state, part_count, momentum, mass, rigid_velocity)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    integer, intent(in) :: part_count
    real(wp), intent(out) :: momentum(3, part_count), mass(part_count), rigid_velocity(3, part_count)
    real(wp) :: body_kinetic, body_momentum(3), body_angular_momentum(3), body_velocity(3), half_step, average_step
    integer :: b, k, part
    momentum = 0.0_wp
    mass = 0.0_wp
    rigid_velocity = 0.0_wp
    half_step = 0.5_wp*state%time_step
    average_step = 0.5_wp*(state%time_step + state%next_time_step)
    do k = 1, size(state%groups)
      call state%groups(k)%group%add_part_momenta(state%nodes, half_step, momentum, mass)
    end do
    do b = 1, size(state%rigid)
      part = model%rigid_bodies(b)%part
      if (part == 0) cycle
      call rigid_body_energy(model, b, state%rigid(b), state%nodes%acceleration, state%nodes%mass, half_step, &
                             average_step, body_kinetic, body_momentum, body_angular_momentum, body_velocity)
      momentum(:, part) = momentum(:, part) + body_momentum
      mass(part) = mass(part) + state%rigid(b)%mass
      rigid_velocity(:, part) = body_velocity
    end do
  end subroutine part_momenta

  !> Total energy: kinetic + internal + hourglass + contact + rigid-wall (energy the walls took)
  !> + the energy eroded elements took along.
  pure real(wp) function total_energy(energy)
    type(energy_totals_t), intent(in) :: energy
    total_energy = energy%kinetic + energy%internal + energy%hourglass + energy%contact + energy%rigid_wall &
                   + energy%eroded_internal + energy%eroded_hourglass + energy%eroded_kinetic
  end function total_energy

  !> Energy ratio as in glstat: total / (initial total + external work); 1 is a perfect balance.
  pure real(wp) function energy_ratio(energy)
    type(energy_totals_t), intent(in) :: energy
    real(wp) :: reference
    reference = energy%initial_total + energy%external_work
    if (abs(reference) > tiny(1.0_wp)) then
      energy_ratio = total_energy(energy)/reference
    else
      energy_ratio = 1.0_wp
    end if
  end function energy_ratio

  !> glstat's "energy ratio w/o eroded energy": the total without the energy eroded elements
  !> took along, over (initial total + external work); below 1 once elements eroded.
  pure real(wp) function energy_ratio_without_eroded(energy)
    type(energy_totals_t), intent(in) :: energy
    real(wp) :: reference
    reference = energy%initial_total + energy%external_work
    if (abs(reference) > tiny(1.0_wp)) then
      energy_ratio_without_eroded = (total_energy(energy) - energy%eroded_internal - energy%eroded_hourglass &
                                     - energy%eroded_kinetic)/reference
    else
      energy_ratio_without_eroded = 1.0_wp
    end if
  end function energy_ratio_without_eroded
end module energy_balance
