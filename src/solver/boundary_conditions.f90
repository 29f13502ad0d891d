!> Nodal loads, single-point constraints and prescribed motions.
!>
!> Kinematic conditions act on the half-step velocities: a constrained or prescribed dof gets
!> the velocity its condition demands for the coming step. The support exerts the impulse J
!> that turns the velocity the forces would have given, v^{n-1/2} + a_free dt, into that one; its
!> work in the central-difference sense, J (v^{n-1/2} + v^{n+1/2})/2, is booked as external work
!> so that the energy balance closes.
module boundary_conditions
  use kinds, only: wp
  use curves, only: curve_value
  use model, only: model_t, motion_velocity, motion_acceleration, motion_displacement, &
                   motion_along_vector, motion_only_along_vector
  implicit none
  private

  public :: assemble_nodal_loads, load_work, impose_kinematic_conditions, fixed_dof_mask, &
            hold_prescribed_accelerations, fixed_rotation_mask

contains

  !> Which dofs are fixed by *BOUNDARY_SPC (x, y, z per node).
  subroutine fixed_dof_mask(model, fixed)
    type(model_t), intent(in) :: model
    logical, intent(out) :: fixed(:, :)
    integer :: k
    fixed = .false.
    do k = 1, size(model%spcs)
      fixed(:, model%spcs(k)%node) = fixed(:, model%spcs(k)%node) .or. model%spcs(k)%fixed
    end do
  end subroutine fixed_dof_mask

  !> Which rotations are fixed by *BOUNDARY_SPC (about x, y, z per node; only shell nodes
  !> carry rotations).
  subroutine fixed_rotation_mask(model, fixed)
    type(model_t), intent(in) :: model
    logical, intent(out) :: fixed(:, :)
    integer :: k
    fixed = .false.
    do k = 1, size(model%spcs)
      fixed(:, model%spcs(k)%node) = fixed(:, model%spcs(k)%node) .or. model%spcs(k)%fixed_rotation
    end do
  end subroutine fixed_rotation_mask

  !> Prescribed dofs follow their motion, not the forces: their acceleration is the prescribed
  !> one (VAD = 1) or zero (velocity and displacement are imposed on the half-step velocities),
  !> so that integer-step velocities, kinetic energy and output show the prescribed motion. The
  !> acceleration the forces would have given each prescribed dof is kept in
  !> `free_acceleration`: the support's reaction does the work between the two. Nodes held in
  !> local directions (SPCs with a CID) lose their acceleration along those directions first.
  subroutine hold_prescribed_accelerations(model, time, acceleration, free_acceleration)
    type(model_t), intent(in) :: model
    real(wp), intent(in) :: time
    real(wp), intent(inout) :: acceleration(:, :)
    real(wp), intent(out) :: free_acceleration(:)
    integer :: k
    real(wp) :: along, value
    call remove_local_components(model, acceleration)
    do k = 1, size(model%motions)
      associate (motion => model%motions(k))
        if (motion%direction == motion_along_vector .or. &
            motion%direction == motion_only_along_vector) then
          ! along a vector: the component along it is the prescribed dof
          along = dot_product(acceleration(:, motion%node), motion%vector)
          free_acceleration(k) = along
          if (time < motion%birth .or. time > motion%death) cycle
          value = 0.0_wp
          if (motion%kind == motion_acceleration) value = &
            motion%scale*curve_value(model%curves(motion%curve), time - motion%birth)
          if (motion%direction == motion_only_along_vector) then
            acceleration(:, motion%node) = value*motion%vector
          else
            acceleration(:, motion%node) = acceleration(:, motion%node) + (value - along)*motion%vector
          end if
          cycle
        end if
        free_acceleration(k) = acceleration(motion%direction, motion%node)
        if (time < motion%birth .or. time > motion%death) cycle
        if (motion%kind == motion_acceleration) then
          acceleration(motion%direction, motion%node) = &
            motion%scale*curve_value(model%curves(motion%curve), time - motion%birth)
        else
          acceleration(motion%direction, motion%node) = 0.0_wp
        end if
      end associate
    end do
  end subroutine hold_prescribed_accelerations

  !> Remove from `vectors` (velocities or accelerations, per node) the components along the
  !> local SPC directions of each node (orthonormal, so one projection each).
  pure subroutine remove_local_components(model, vectors)
    type(model_t), intent(in) :: model
    real(wp), intent(inout) :: vectors(:, :)
    integer :: k, j
    if (.not. allocated(model%local_spcs)) return
    do k = 1, size(model%local_spcs)
      associate (spc => model%local_spcs(k))
        do j = 1, spc%count
          vectors(:, spc%node) = vectors(:, spc%node) - &
            dot_product(vectors(:, spc%node), spc%directions(:, j))*spc%directions(:, j)
        end do
      end associate
    end do
  end subroutine remove_local_components

  !> The number of body loads (none in a model built without them).
  pure integer function body_load_count(model)
    type(model_t), intent(in) :: model
    body_load_count = 0
    if (allocated(model%body_loads)) body_load_count = size(model%body_loads)
  end function body_load_count

  !> External nodal forces at `time` (overwrites `external_force`).
  subroutine assemble_nodal_loads(model, time, mass, external_force)
    type(model_t), intent(in) :: model
    real(wp), intent(in) :: time
    real(wp), intent(in) :: mass(:)                 !< nodal masses (body loads)
    real(wp), intent(inout) :: external_force(:, :)
    real(wp) :: acceleration(3)
    integer :: k, node
    if (size(model%loads) == 0 .and. body_load_count(model) == 0) return
    if (body_load_count(model) > 0) then
      ! base accelerations: every node takes -m a (gravity in -z is a positive *LOAD_BODY_Z)
      acceleration = 0.0_wp
      do k = 1, size(model%body_loads)
        associate (load => model%body_loads(k))
          acceleration(load%direction) = acceleration(load%direction) + &
                                         load%scale*curve_value(model%curves(load%curve), time)
        end associate
      end do
      !$omp parallel do schedule(static) default(shared) private(node)
      do node = 1, size(mass)
        external_force(:, node) = -mass(node)*acceleration
      end do
      !$omp end parallel do
    else
      do k = 1, size(model%loads)
        associate (load => model%loads(k))
          external_force(load%direction, load%node) = 0.0_wp
        end associate
      end do
    end if
    do k = 1, size(model%loads)
      associate (load => model%loads(k))
        external_force(load%direction, load%node) = external_force(load%direction, load%node) &
                                                    + load%scale*curve_value(model%curves(load%curve), time)
      end associate
    end do
  end subroutine assemble_nodal_loads

  !> Work of the nodal and body loads over the step, f . (v dt) summed over every dof (call with
  !> f at the start and at the end of the step, each weighted 1/2).
  function load_work(model, external_force, velocity, step) result(work)
    type(model_t), intent(in) :: model
    real(wp), intent(in) :: external_force(:, :), velocity(:, :), step
    real(wp) :: work
    work = 0.0_wp
    if (size(model%loads) == 0 .and. body_load_count(model) == 0) return
    work = step*sum(external_force*velocity)
  end function load_work

  !> Set the half-step velocities demanded by SPCs and prescribed motions for the step from
  !> `time` to `time + dt` (`average_dt` is the step of the velocity update). Returns the
  !> kinetic energy the supports added (external work).
  subroutine impose_kinematic_conditions(model, fixed, time, dt, average_dt, displacement, acceleration, &
                                         free_acceleration, mass, velocity, support_work)
    type(model_t), intent(in) :: model
    logical, intent(in) :: fixed(:, :)
    real(wp), intent(in) :: time, dt, average_dt
    real(wp), intent(in) :: displacement(:, :)
    real(wp), intent(in) :: acceleration(:, :)
    real(wp), intent(in) :: free_acceleration(:)
    real(wp), intent(in) :: mass(:)
    real(wp), intent(inout) :: velocity(:, :)
    real(wp), intent(out) :: support_work
    integer :: k, node, direction
    real(wp) :: target, local_time, value, previous, free

    support_work = 0.0_wp
    do k = 1, size(model%spcs)
      node = model%spcs(k)%node
      where (fixed(:, node)) velocity(:, node) = 0.0_wp
    end do
    call remove_local_components(model, velocity)
    do k = 1, size(model%motions)
      associate (motion => model%motions(k))
        node = motion%node
        direction = motion%direction
        if (direction == motion_along_vector .or. direction == motion_only_along_vector) then
          call impose_along_vector(model, k, time, dt, average_dt, displacement, acceleration, &
                                   free_acceleration, mass, velocity, support_work)
          cycle
        end if
        select case (motion%kind)
        case (motion_velocity)
          local_time = time + 0.5_wp*dt
        case (motion_acceleration)
          local_time = time
        case default
          local_time = time + dt
        end select
        if (local_time < motion%birth .or. local_time > motion%death) cycle
        value = motion%scale*curve_value(model%curves(motion%curve), local_time - motion%birth)
        select case (motion%kind)
        case (motion_velocity)
          target = value
        case (motion_acceleration)
          ! the acceleration of this dof is already the prescribed one
          target = velocity(direction, node)
        case (motion_displacement)
          target = (value - displacement(direction, node))/dt
        case default
          cycle
        end select
        ! impulse m (target - v) times the mean of v^{n-1/2} = v - a dt and v^{n+1/2} = target
        ! v^{n-1/2}, and the velocity the forces alone would have given
        previous = velocity(direction, node) - average_dt*acceleration(direction, node)
        free = previous + average_dt*free_acceleration(k)
        support_work = support_work + 0.5_wp*mass(node)*(target - free)*(target + previous)
        velocity(direction, node) = target
      end associate
    end do
  end subroutine impose_kinematic_conditions

  !> impose_kinematic_conditions for motion `k`, which acts along its unit vector d: the
  !> velocity component v.d becomes the prescribed one (and, for motion_only_along_vector, the
  !> components across d vanish). The support's work is booked as for an axis direction.
  subroutine impose_along_vector(model, k, time, dt, average_dt, displacement, acceleration, &
                                 free_acceleration, mass, velocity, support_work)
    type(model_t), intent(in) :: model
    integer, intent(in) :: k
    real(wp), intent(in) :: time, dt, average_dt
    real(wp), intent(in) :: displacement(:, :), acceleration(:, :), free_acceleration(:), mass(:)
    real(wp), intent(inout) :: velocity(:, :)
    real(wp), intent(inout) :: support_work
    real(wp) :: local_time, value, target, current, previous(3), free(3)
    associate (motion => model%motions(k), node => model%motions(k)%node)
      select case (motion%kind)
      case (motion_velocity)
        local_time = time + 0.5_wp*dt
      case (motion_acceleration)
        local_time = time
      case default
        local_time = time + dt
      end select
      if (local_time < motion%birth .or. local_time > motion%death) return
      value = motion%scale*curve_value(model%curves(motion%curve), local_time - motion%birth)
      current = dot_product(velocity(:, node), motion%vector)
      select case (motion%kind)
      case (motion_velocity)
        target = value
      case (motion_acceleration)
        target = current
      case default
        target = (value - dot_product(displacement(:, node), motion%vector))/dt
      end select
      previous = velocity(:, node) - average_dt*acceleration(:, node)
      ! the velocity the forces alone would have given (across d a held node has no velocity
      ! before or after, so whatever the forces did there does no work)
      free = velocity(:, node) + average_dt*(free_acceleration(k) - &
             dot_product(acceleration(:, node), motion%vector))*motion%vector
      if (motion%direction == motion_only_along_vector) then
        velocity(:, node) = target*motion%vector
      else
        velocity(:, node) = velocity(:, node) + (target - current)*motion%vector
      end if
      ! impulse m (v^{n+1/2} - v_free) times the mean of v^{n-1/2} and v^{n+1/2}
      support_work = support_work + 0.5_wp*mass(node)*dot_product(velocity(:, node) - free, &
                                                                   velocity(:, node) + previous)
    end associate
  end subroutine impose_along_vector
end module boundary_conditions
