!> The checks that make "normal termination" trustworthy: a run whose state is no longer finite
!> or physical, whose energy explodes, whose time step collapses or jumps, stops with an error
!> that names the node or element, its part, the time and the cycle.
!>
!> - Runaway motion, every cycle and before anything moves: the velocities the coming update
!>   would give (v + dt a) must be finite and below `velocity_limit`, 100 times the fastest
!>   dilatational wave speed of the model's materials (a node faster than that crosses a hundred
!>   elements per step: no impact does that, an instability does within a few cycles). Checking
!>   before the update leaves the last finite state for the results, and keeps every later
!>   computation of the cycle (walls, elements, contact, energies) on bounded values, which is
!>   what lets the checked debug build end as cleanly as the release build.
!> - Elements: inverted solids, shells without area, meshfree points with negative volume, a
!>   rigid body whose motion is not finite, a stable step that is not finite or that grows more
!>   than a hundredfold in one cycle, a step below DTMIN times the first one.
!> - Energy, every `energy_check_interval` cycles: the energy the model holds may not exceed the
!>   energy put in (initial energy and external work) by more than `energy_excess_limit` times the
!>   largest energy put in so far, and ENDENG (*CONTROL_TERMINATION) bounds the change of the
!>   energy ratio when given.
!> - A falling time step is reported at every tenth of its first value it passes, naming the
!>   element that sets it.
module run_checks
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use kinds, only: wp
  use message_log, only: log_message
  use text_format, only: integer_text
  use error_handling, only: error_t, make_error
  use model, only: model_t, law_null
  use explicit_state, only: explicit_state_t, energy_totals_t
  use element_groups, only: group_failure
  use energy_balance, only: measured_energies, total_energy, energy_ratio, part_energies
  implicit none
  private

  public :: set_up_run_checks, check_runaway_motion, check_elements, check_time_step, check_energy
  public :: describe_node, describe_element, energy_check_interval

  !> Nodes faster than this many times the fastest wave speed stop the run.
  real(wp), parameter :: wave_speed_multiple = 100.0_wp
  !> Values beyond this are never physical in any unit system, and their squares still fit in a
  !> double: the bound when the model's materials give no wave speed.
  real(wp), parameter :: largest_meaningful_value = 1.0e100_wp
  !> A step below this fraction of the first one stops the run even without DTMIN: the run could
  !> not reach its end time (a collapsing element drove one to 1e-13 of its first step, and the
  !> run stalled for good).
  real(wp), parameter :: smallest_step_fraction = 1.0e-8_wp
  !> A stable step larger than this many times the last one is not physical.
  real(wp), parameter :: step_growth_limit = 100.0_wp
  !> Energy created by the run, in units of the largest energy put in so far, that stops it.
  real(wp), parameter :: energy_excess_limit = 10.0_wp
  !> Cycles between two energy checks (a pass over the nodes; the motion check runs every cycle).
  integer, parameter :: energy_check_interval = 16

contains

  !> The bounds of the checks, from the materials and sections of the model; the mass that
  !> mass scaling added against ENDMAS.
  subroutine set_up_run_checks(model, state, error)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    type(error_t), allocatable, intent(out) :: error
    real(wp) :: speed, thinnest
    integer :: k
    speed = 0.0_wp
    do k = 1, size(model%parts)
      speed = max(speed, dilatational_wave_speed(model, model%parts(k)%material))
    end do
    state%watch%largest_wave_speed = speed
    state%watch%velocity_limit = largest_meaningful_value
    if (speed > 0.0_wp) state%watch%velocity_limit = min(wave_speed_multiple*speed, largest_meaningful_value)
    ! a shell node turning at w moves its faces at w t/2
    thinnest = huge(1.0_wp)
    do k = 1, size(state%groups)
      thinnest = min(thinnest, state%groups(k)%group%thinnest())
    end do
    state%watch%angular_velocity_limit = largest_meaningful_value
    if (thinnest < huge(1.0_wp) .and. thinnest > 0.0_wp) &
      state%watch%angular_velocity_limit = min(state%watch%velocity_limit/thinnest, largest_meaningful_value)
    if (state%physical_mass > 0.0_wp .and. 100.0_wp*state%added_mass > model%mass_change_limit*state%physical_mass) then
      call make_error(error, "mass scaling (DT2MS) adds "//real_text(state%added_mass)//" to the physical mass "// &
                      real_text(state%physical_mass)//", more than ENDMAS = "//real_text(model%mass_change_limit)// &
                      " percent; the most scaled is "//most_scaled_element(model, state)//time_text(state))
    end if
  end subroutine set_up_run_checks

  !> "solid element 12 (part 3), its density raised 1.2E+03 times": the element whose density
  !> mass scaling raised most.
  function most_scaled_element(model, state) result(text)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    character(len=:), allocatable :: text
    real(wp) :: largest, before
    integer :: k, element, group
    largest = 0.0_wp
    element = 0
    group = 0
    do k = 1, size(state%groups)
      before = largest
      call state%groups(k)%group%most_scaled(model, largest, element)
      if (largest > before) group = k
    end do
    text = describe_element(model, state, group, element)//", its density raised "//real_text(largest)//" times"
  end function most_scaled_element

  !> sqrt((K + 4G/3) / rho) of a material from its E, PR and RO (0 when it has none: *MAT_NULL
  !> shells, or constants that give no real speed).
  real(wp) function dilatational_wave_speed(model, material) result(speed)
    type(model_t), intent(in) :: model
    integer, intent(in) :: material
    real(wp) :: poisson, modulus
    speed = 0.0_wp
    if (material < 1 .or. material > size(model%materials)) return
    associate (m => model%materials(material))
      if (m%law == law_null .or. .not. (m%youngs_modulus > 0.0_wp .and. m%density > 0.0_wp)) return
      if (m%youngs_modulus >= largest_meaningful_value .or. m%density <= 1.0_wp/largest_meaningful_value) return
      poisson = min(max(m%poissons_ratio, -0.99_wp), 0.499_wp)
      modulus = m%youngs_modulus*(1.0_wp - poisson)/((1.0_wp + poisson)*(1.0_wp - 2.0_wp*poisson))
      speed = sqrt(modulus/m%density)
    end associate
  end function dilatational_wave_speed

  !> Before the velocity update with `average_step`: the first node (lowest index, so the same for
  !> any thread count) whose velocity v + average_step a, or angular velocity, would be
  !> non-finite or beyond the limits. Nothing is changed, so the state stays the last good one.
  !> At cycle 0 call it with average_step = 0: it checks the initial velocities.
  subroutine check_runaway_motion(model, state, average_step, error)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    real(wp), intent(in) :: average_step
    type(error_t), allocatable, intent(out) :: error
    integer :: node, first, first_turning
    real(wp) :: limit, angular_limit, speed(3)
    character(len=:), allocatable :: what, bound

    limit = state%watch%velocity_limit
    angular_limit = state%watch%angular_velocity_limit
    first = huge(1)
    first_turning = huge(1)
    !$omp parallel do schedule(static) default(shared) private(node, speed) &
    !$omp& reduction(min:first, first_turning)
    do node = 1, state%nodes%count
      if (state%nodes%is_rigid_node(node)) cycle   ! moves with its body (check_rigid_body_rotation)
      speed = abs(state%nodes%velocity(:, node) + average_step*state%nodes%acceleration(:, node))
      if (beyond(speed, limit)) first = min(first, node)
      speed = abs(state%nodes%angular_velocity(:, node) + average_step*state%nodes%angular_acceleration(:, node))
      if (beyond(speed, angular_limit)) first_turning = min(first_turning, node)
    end do
    !$omp end parallel do
    if (first == huge(1) .and. first_turning == huge(1)) then
      call check_rigid_body_rotation(model, state, error)
      return
    end if

    if (first <= first_turning) then
      node = first
      speed = state%nodes%velocity(:, node) + average_step*state%nodes%acceleration(:, node)
      what = "velocity"
      bound = " (the limit is 100 times the fastest wave speed of the model's materials, "// &
              real_text(state%watch%largest_wave_speed)//")"
    else
      node = first_turning
      speed = state%nodes%angular_velocity(:, node) + average_step*state%nodes%angular_acceleration(:, node)
      what = "angular velocity"
      limit = angular_limit
      bound = " (the limit is 100 times the fastest wave speed of the model's materials over the thinnest shell)"
    end if
    if (.not. (state%watch%largest_wave_speed > 0.0_wp .and. limit < largest_meaningful_value)) bound = ""
    what = describe_node(model, node)//merge(" starts with the ", " would reach the ", state%cycle == 0)// &
           what//" ("//real_text(speed(1))//", "//real_text(speed(2))//", "//real_text(speed(3))// &
           ") beyond "//real_text(limit)//bound
    if (state%cycle == 0) then
      what = what//": check the initial velocities of the deck"
    else
      what = trim(what)//" in the next step: the run has become unstable"
    end if
    call make_error(error, what//time_text(state))
  end subroutine check_runaway_motion

  !> A rigid body may turn at most one radian per step: its rotation update (a Cayley transform
  !> of the step's rotation vector) cannot follow more, and no spinning part of a crash model comes
  !> near it (a wheel at 1000 rpm turns 1e-4 rad in a 1e-3 ms step).
  subroutine check_rigid_body_rotation(model, state, error)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    type(error_t), allocatable, intent(out) :: error
    integer :: b
    if (.not. (state%next_time_step > 0.0_wp)) return
    do b = 1, size(state%rigid)
      associate (spin => state%rigid(b)%angular_velocity)
        if (.not. beyond(abs(spin), 1.0_wp/state%next_time_step)) cycle
        call make_error(error, "rigid body "//integer_text(model%rigid_bodies(b)%id)//" turns at ("// &
                        real_text(spin(1))//", "//real_text(spin(2))//", "//real_text(spin(3))// &
                        "), more than one radian in the next step of "//real_text(state%next_time_step)// &
                        ": the run has become unstable, or the initial spin is beyond what a step can follow"// &
                        time_text(state))
        return
      end associate
    end do
  end subroutine check_rigid_body_rotation

  !> Whether x is finite and above zero, without an ordered comparison on NaN (which raises the
  !> invalid-operation flag that the checked build traps).
  elemental logical function positive_finite(x)
    real(wp), intent(in) :: x
    positive_finite = .false.
    if (ieee_is_finite(x)) positive_finite = x > 0.0_wp .and. x < huge(1.0_wp)
  end function positive_finite

  !> Whether a speed is NaN or above the limit. NaN is tested first, with the quiet comparison
  !> (/=): an ordered comparison with NaN raises the invalid-operation flag, which the checked
  !> build traps.
  pure logical function beyond(speed, limit)
    real(wp), intent(in) :: speed(3), limit
    if (any(speed /= speed)) then
      beyond = .true.
    else
      beyond = any(speed > limit)
    end if
  end function beyond

  !> After the element forces: an inverted element, a shell without area, a meshfree point
  !> with negative volume, a rigid body whose motion is not finite, or internal forces that are
  !> not finite.
  subroutine check_elements(model, state, error)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    type(error_t), allocatable, intent(out) :: error
    integer :: b, k
    k = group_failure(state%groups)
    if (k > 0) then
      call make_error(error, state%groups(k)%group%failure_text(model)//time_text(state))
      return
    end if
    ! rigid bodies set no element step: their motion must be finite too
    do b = 1, size(state%rigid)
      if (all(ieee_is_finite(state%rigid(b)%velocity)) .and. all(ieee_is_finite(state%rigid(b)%angular_velocity))) &
        cycle
      call make_error(error, "the motion of rigid body "//integer_text(model%rigid_bodies(b)%id)// &
                      " is no longer finite"//time_text(state))
      return
    end do
  end subroutine check_elements

  !> The stable step just selected (`stable_step`, before TSSFAC, set by
  !> state%controlling_element): it must be finite, the step to be taken not beyond twice it,
  !> it may not grow more than a hundredfold in one cycle,
  !> and TSSFAC times it not below DTMIN times the first such step; every tenth of the first step
  !> it falls below is reported on standard output. (The step actually taken may be shorter: the
  !> last one ends at ENDTIM, the first is capped by DTINIT.)
  subroutine check_time_step(model, state, stable_step, error)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    real(wp), intent(in) :: stable_step
    type(error_t), allocatable, intent(out) :: error
    real(wp) :: step, fraction

    associate (watch => state%watch)
      step = model%time_step_scale*stable_step
      if (.not. (positive_finite(stable_step) .and. positive_finite(step) .and. &
                 (positive_finite(state%next_time_step) .or. state%next_time_step == 0.0_wp))) then
        call make_error(error, "no finite stable time step ("//step_setter(model, state)//")"//time_text(state))
        return
      end if
      ! central differences are unstable beyond twice the stable step of the element that
      ! sets it (a TSSFAC far above 1; the last step may be cut shorter at ENDTIM)
      if (state%next_time_step > 2.0_wp*stable_step) then
        call make_error(error, "the next time step "//real_text(state%next_time_step)//" is "// &
                        real_text(state%next_time_step/stable_step)//" times the stable step ("// &
                        step_setter(model, state)//"; TSSFAC "//real_text(model%time_step_scale)// &
                        "): central differences are unstable beyond twice the stable step"//time_text(state))
        return
      end if
      if (state%cycle == 0) then
        watch%first_time_step = step
        watch%last_stable_step = stable_step
        return
      end if
      ! (erosion may take the element that set the step out at once)
      if (stable_step > step_growth_limit*watch%last_stable_step .and. .not. state%eroded_this_cycle) then
        call make_error(error, "the stable time step grew from "//real_text(watch%last_stable_step)//" to "// &
                        real_text(stable_step)//" in one cycle ("//step_setter(model, state)// &
                        "): element sizes or wave speeds cannot change so much in one step, the state is no "// &
                        "longer physical"//time_text(state))
        return
      end if
      watch%last_stable_step = stable_step
      if (step < max(model%minimum_time_step_factor, smallest_step_fraction)*watch%first_time_step) then
        if (model%minimum_time_step_factor > smallest_step_fraction) then
          call make_error(error, "the time step "//real_text(step)//" fell below DTMIN ("// &
                          real_text(model%minimum_time_step_factor)//") times the first step "// &
                          real_text(watch%first_time_step)//" ("//step_setter(model, state)//")"//time_text(state))
        else
          call make_error(error, "the time step "//real_text(step)//" fell below "// &
                          real_text(smallest_step_fraction)//" times the first step "// &
                          real_text(watch%first_time_step)//" ("//step_setter(model, state)//"): the run "// &
                          "would need a hundred million times as many cycles as its first steps took"//time_text(state))
        end if
        return
      end if
      fraction = step/watch%first_time_step
      if (fraction < 0.1_wp**(watch%step_decades_reported + 1)) then
        call log_message(state%messages, "warning: t = "//real_text(state%time)//": the time step "// &
          real_text(step)//" has fallen to "//real_text(fraction)//" times the first step "// &
          real_text(watch%first_time_step)//" ("//step_setter(model, state)//"); *CONTROL_TERMINATION DTMIN "// &
          "stops a run whose step falls below a fraction of the first one")
        watch%step_decades_reported = min(int(-log10(fraction)), 300)
      end if
    end associate
  end subroutine check_time_step

  !> Every energy_check_interval cycles and at the end: the energies must be finite, the energy
  !> created by the run (total minus initial energy and external work) below energy_excess_limit
  !> times the largest energy put in so far, and |energy ratio - 1| below ENDENG percent when
  !> the deck gives one.
  subroutine check_energy(model, state, scratch, error)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(inout) :: state
    real(wp), intent(inout) :: scratch(:, :)     !< (5, chunks of nodes) for the sums
    type(error_t), allocatable, intent(out) :: error
    real(wp) :: total, supplied, ratio
    type(energy_totals_t) :: energy

    energy = state%energy
    call measured_energies(model, state, scratch, energy)
    state%energy = energy
    total = total_energy(state%energy)
    supplied = state%energy%initial_total + state%energy%external_work
    associate (watch => state%watch)
      watch%largest_energy_supplied = max(watch%largest_energy_supplied, abs(state%energy%initial_total), &
                                          abs(state%energy%external_work), abs(supplied))
      if (.not. (ieee_is_finite(total) .and. ieee_is_finite(supplied))) then
        call make_error(error, "the energies are no longer finite ("//energy_text(state)//")"//time_text(state))
        return
      end if
      if (watch%largest_energy_supplied > 0.0_wp .and. &
          abs(total - supplied) > energy_excess_limit*watch%largest_energy_supplied) then
        call make_error(error, "the energy has exploded: the model holds "//real_text(total)//" but was given "// &
                        real_text(supplied)//" ("//energy_text(state)//"; most of it in "// &
                        part_with_most_energy(model, state)//"): the run has become unstable"//time_text(state))
        return
      end if
      if (model%energy_ratio_change_limit > 0.0_wp) then
        ratio = energy_ratio(state%energy)
        if (100.0_wp*abs(ratio - 1.0_wp) > model%energy_ratio_change_limit) then
          call make_error(error, "the energy ratio "//real_text(ratio)//" differs from 1 by more than ENDENG = "// &
                          real_text(model%energy_ratio_change_limit)//" percent"//time_text(state))
        end if
      end if
    end associate
  end subroutine check_energy

  !> "part 3 (kinetic ..., internal ...)": the part whose energies are largest in magnitude.
  function part_with_most_energy(model, state) result(text)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    character(len=:), allocatable :: text
    real(wp) :: kinetic(size(model%parts)), internal(size(model%parts)), hourglass(size(model%parts))
    integer :: k
    text = "no part"
    if (size(model%parts) == 0) return
    call part_energies(model, state, size(model%parts), kinetic, internal, hourglass)
    k = maxloc(abs(kinetic) + abs(internal) + abs(hourglass), dim=1)
    text = "part "//integer_text(model%parts(k)%id)//" (kinetic "//real_text(kinetic(k))//", internal "// &
           real_text(internal(k))//", hourglass "//real_text(hourglass(k))//")"
  end function part_with_most_energy

  !> "kinetic ..., internal ..., ..." for messages.
  function energy_text(state) result(text)
    type(explicit_state_t), intent(in) :: state
    character(len=:), allocatable :: text
    text = "kinetic "//real_text(state%energy%kinetic)//", internal "//real_text(state%energy%internal)// &
           ", hourglass "//real_text(state%energy%hourglass)//", contact "//real_text(state%energy%contact)
  end function energy_text

  !> What sets the stable step: "set by solid 12, part 3", or the meshfree cell, or the rigid
  !> elements; when it is not finite and no element set it, the first element whose step is not
  !> finite.
  function step_setter(model, state) result(text)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    character(len=:), allocatable :: text
    integer :: k
    if (state%controlling_group /= 0) then
      text = "set by "//describe_element(model, state, state%controlling_group, state%controlling_element)
      return
    end if
    if (positive_finite(state%stable_time_step)) then
      text = "set by the elements of the rigid bodies"
      return
    end if
    do k = 1, size(state%groups)
      associate (group => state%groups(k)%group)
        if (.not. group%step_not_finite) cycle
        text = "the step of a block of "//trim(group%name)//" elements is not finite"
        if (group%critical_element /= 0) text = text//" (smallest finite step: "// &
                                                group%describe(model, group%critical_element)//")"
        return
      end associate
    end do
    text = "no element sets a step"
  end function step_setter

  !> "solid element 12 (part 3)": element `element` of group `group` (0: "no element").
  function describe_element(model, state, group, element) result(text)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    integer, intent(in) :: group, element
    character(len=:), allocatable :: text
    if (group > 0 .and. element /= 0) then
      text = state%groups(group)%group%describe(model, element)
    else
      text = "no element"
    end if
  end function describe_element

  !> "node 17 (part 2)": the part of the first solid or shell on the node, else its rigid body,
  !> else "(on no element)". Only for messages: a scan of the connectivity.
  function describe_node(model, node) result(text)
    type(model_t), intent(in) :: model
    integer, intent(in) :: node
    character(len=:), allocatable :: text
    integer :: k
    text = "node "//integer_text(model%node_ids(node))
    do k = 1, size(model%solid_ids)
      if (any(model%solid_nodes(:, k) == node)) then
        text = text//" (part "//integer_text(model%parts(model%solid_part(k))%id)//")"
        return
      end if
    end do
    do k = 1, size(model%shell_ids)
      if (any(model%shell_nodes(:, k) == node)) then
        text = text//" (part "//integer_text(model%parts(model%shell_part(k))%id)//")"
        return
      end if
    end do
    if (allocated(model%rigid_bodies)) then
      do k = 1, size(model%rigid_bodies)
        if (any(model%rigid_bodies(k)%nodes == node)) then
          text = text//" (rigid body "//integer_text(model%rigid_bodies(k)%id)//")"
          return
        end if
      end do
    end if
    text = text//" (on no element)"
  end function describe_node

  !> " at time 1.23450E-03, cycle 17"
  function time_text(state) result(text)
    type(explicit_state_t), intent(in) :: state
    character(len=:), allocatable :: text
    character(len=24) :: buffer
    write (buffer, '(es12.5)') state%time
    text = " at time "//trim(adjustl(buffer))//", cycle "//integer_text(state%cycle)
  end function time_text

  !> "1.2345E-03" (three exponent digits when needed, no blanks; "NaN", "Infinity" as the
  !> compiler writes them).
  function real_text(value) result(text)
    real(wp), intent(in) :: value
    character(len=:), allocatable :: text
    character(len=24) :: buffer
    if (value /= value) then
      buffer = "NaN"      ! (an ordered comparison with NaN would trap in the checked build)
    else if (abs(value) < 1.0e100_wp .and. (abs(value) >= 1.0e-99_wp .or. value == 0.0_wp)) then
      write (buffer, '(es11.4)') value
    else
      write (buffer, '(es12.4e3)') value
    end if
    text = trim(adjustl(buffer))
  end function real_text
end module run_checks
