!> Spot welds (*CONSTRAINED_SPOTWELD, *CONSTRAINED_GENERALIZED_WELD_SPOT) in the explicit time
!> loop. LS-DYNA treats a spot weld as a massless rigid beam between its nodes: here each weld
!> is a small rigid body of its nodes (rigid_bodies: set_up_body, advance_body), with the
!> masses and rotary inertias the elements gave them, until it fails.
!>
!> The force a weld transmits is measured from what the rigid link does to its nodes: each
!> node's constraint impulse m (v_rigid - v_free) over the velocity update, divided by the
!> step. The weld's force is the sum over the nodes on one side of its mid-plane (the plane
!> halfway between the two nodes farthest apart, normal to the line joining them, turning with
!> the weld): for two nodes the force on the second node. Its component along that line is
!> the normal force fn, the rest the shear force fs. The weld fails when
!> (|fn|/SN)^N + (|fs|/SS)^M >= 1 (a strength of 0 leaves its term out), or at TF (TFAIL);
!> the step in which it fails still holds it, from the next its nodes move independently.
!>
!> A node is in at most one weld and no rigid body (deck_rigid_bodies), so the welds are
!> independent: they are advanced in parallel, each on its own nodes, and the results do not
!> depend on the thread count. Failures are printed after the loop in weld order.
module spot_weld_constraints
  use kinds, only: wp
  use message_log, only: message_log_t, log_message
  use model, only: model_t
  use rigid_body_state, only: rigid_body_state_t
  use rigid_bodies, only: set_up_body, advance_body
  use text_format, only: integer_text
  implicit none
  private

  public :: set_up_spot_welds, advance_spot_welds, failed_weld_count

  !> The motion and state of one weld (indexed like model%spot_welds).
  type, public :: spot_weld_state_t
    type(rigid_body_state_t) :: body               !< the weld as a rigid body of its nodes
    logical :: failed = .false.
    real(wp) :: failure_time = 0.0_wp              !< when it failed
    real(wp) :: normal_force = 0.0_wp              !< fn in the last step it held (signed: > 0 tension)
    real(wp) :: shear_force = 0.0_wp               !< |fs| in the last step it held
    real(wp) :: axis(3) = 0.0_wp                   !< unit axis in body axes (the farthest pair)
    real(wp) :: failure_value = 0.0_wp             !< the criterion's value in the last step it held
    logical, allocatable :: far_side(:)            !< nodes whose force is the weld's force
    real(wp), allocatable :: constraint_impulse(:, :) !< (3, nodes) scratch of each step
  end type spot_weld_state_t

contains

  !> Every weld as a rigid body of its nodes (after the elements lumped their masses); its axis
  !> and the side of each node.
  subroutine set_up_spot_welds(model, reference, mass, rotary_inertia, velocity, welds)
    type(model_t), intent(in) :: model
    real(wp), intent(in) :: reference(:, :)
    real(wp), intent(inout) :: mass(:)
    real(wp), intent(in) :: rotary_inertia(:)
    real(wp), intent(inout) :: velocity(:, :)
    type(spot_weld_state_t), allocatable, intent(out) :: welds(:)
    real(wp), allocatable :: corner_mass(:)
    real(wp) :: distance, farthest, middle(3)
    integer :: w, i, j, first, last, count
    count = 0
    if (allocated(model%spot_welds)) count = size(model%spot_welds)
    allocate (welds(count), corner_mass(size(mass)))
    corner_mass = 0.0_wp
    do w = 1, count
      associate (weld => welds(w), nodes => model%spot_welds(w)%nodes)
        call set_up_body(model, 0, nodes, reference, mass, rotary_inertia, velocity, corner_mass, weld%body)
        allocate (weld%far_side(size(nodes)), weld%constraint_impulse(3, size(nodes)))
        farthest = -1.0_wp
        first = 1
        last = size(nodes)
        do i = 1, size(nodes)
          do j = i + 1, size(nodes)
            distance = norm2(reference(:, nodes(j)) - reference(:, nodes(i)))
            if (distance > farthest) then
              farthest = distance
              first = i
              last = j
            end if
          end do
        end do
        weld%axis = 0.0_wp
        if (farthest > 0.0_wp) weld%axis = (reference(:, nodes(last)) - reference(:, nodes(first)))/farthest
        middle = 0.5_wp*(reference(:, nodes(first)) + reference(:, nodes(last)))
        do i = 1, size(nodes)
          weld%far_side(i) = dot_product(reference(:, nodes(i)) - middle, weld%axis) > 0.0_wp
        end do
        ! coincident nodes: no axis; the whole force counts as shear and the second node's
        ! force is the weld's
        if (farthest <= 0.0_wp) weld%far_side = [(i == last, i=1, size(nodes))]
      end associate
    end do
  end subroutine set_up_spot_welds

  !> One step of every weld that holds (after the rigid bodies), its forces and its failure.
  !> `velocity` holds v^{n+1/2} after the ordinary update; `angular_velocity` of weld nodes with
  !> rotary inertia follows the weld. Failures are printed.
  subroutine advance_spot_welds(model, welds, time, dt, average_dt, coordinates, angular_acceleration, &
                                rotary_inertia, velocity, angular_velocity, node_plastic_strain, log)
    type(model_t), intent(in) :: model
    type(spot_weld_state_t), intent(inout) :: welds(:)
    real(wp), intent(in) :: time, dt, average_dt
    real(wp), intent(in) :: coordinates(:, :), angular_acceleration(:, :), rotary_inertia(:)
    !> (nodes) the largest effective plastic strain of the shells on each node of a weld that
    !> fails by plastic strain (EP / EPSF)
    real(wp), intent(in) :: node_plastic_strain(:)
    real(wp), intent(inout) :: velocity(:, :), angular_velocity(:, :)
    type(message_log_t), intent(inout) :: log     !< a weld's failure is printed and kept
    real(wp) :: work, force(3), axis(3), value
    logical :: was_failed
    integer :: w, k
    character(len=400) :: text

    !$omp parallel do schedule(dynamic, 16) default(shared) private(w, k, work, force, axis, value, was_failed) &
    !$omp& if (size(welds) > 64)
    do w = 1, size(welds)
      associate (weld => welds(w), given => model%spot_welds(w))
        if (weld%failed) cycle
        if (time >= given%failure_time) then
          weld%failed = .true.
          weld%failure_time = time
          cycle
        end if
        call advance_body(model, 0, given%nodes, weld%body, time, dt, average_dt, coordinates, angular_acceleration, &
                          rotary_inertia, velocity, work, weld%constraint_impulse)
        do k = 1, size(given%nodes)
          if (rotary_inertia(given%nodes(k)) > 0.0_wp) angular_velocity(:, given%nodes(k)) = weld%body%angular_velocity
        end do
        force = 0.0_wp
        do k = 1, size(given%nodes)
          if (weld%far_side(k)) force = force + weld%constraint_impulse(:, k)
        end do
        force = force/average_dt
        axis = matmul(weld%body%rotation, weld%axis)
        ! the link pulls the far side back when the weld is stretched: tension is positive
        weld%normal_force = -dot_product(force, axis)
        weld%shear_force = norm2(force + weld%normal_force*axis)
        value = 0.0_wp
        if (given%normal_strength > 0.0_wp) &
          value = (abs(weld%normal_force)/given%normal_strength)**given%normal_exponent
        if (given%shear_strength > 0.0_wp) &
          value = value + (weld%shear_force/given%shear_strength)**given%shear_exponent
        weld%failure_value = value
        was_failed = value >= 1.0_wp
        ! EP / EPSF: a shell on one of its nodes has reached the plastic strain at failure
        if (given%failure_plastic_strain > 0.0_wp) then
          if (maxval(node_plastic_strain(given%nodes)) >= given%failure_plastic_strain) was_failed = .true.
        end if
        if (was_failed) then
          weld%failed = .true.
          weld%failure_time = time
        end if
      end associate
    end do
    !$omp end parallel do

    ! the welds that failed in this step, in weld order
    do w = 1, size(welds)
      if (.not. welds(w)%failed .or. welds(w)%failure_time /= time) cycle
      associate (weld => welds(w), given => model%spot_welds(w))
        if (time >= given%failure_time) then
          write (text, '(a,i0,a,es12.5,a)') "spot weld ", given%id, " fails at its failure time (t = ", time, ")"
        else if (weld%failure_value < 1.0_wp) then
          write (text, '(a,i0,a,a,a,es12.5,a,es12.5,a)') "spot weld ", given%id, " (nodes ", &
            node_list(model, given%nodes), ") fails at t = ", time, ": a shell on its nodes reached the "// &
            "plastic strain ", given%failure_plastic_strain, " (EP)"
        else
          write (text, '(a,i0,a,a,a,es12.5,a,es12.5,a,es12.5,a)') "spot weld ", given%id, " (nodes ", &
            node_list(model, given%nodes), ") fails at t = ", time, ": normal force ", weld%normal_force, &
            ", shear force ", weld%shear_force, " (its strengths SN, SS reached)"
        end if
        call log_message(log, trim(text))
      end associate
    end do
  end subroutine advance_spot_welds

  !> "12, 13, 14" (the first eight node ids, then "...").
  function node_list(model, nodes) result(text)
    type(model_t), intent(in) :: model
    integer, intent(in) :: nodes(:)
    character(len=:), allocatable :: text
    integer :: k
    text = integer_text(model%node_ids(nodes(1)))
    do k = 2, min(size(nodes), 8)
      text = text//", "//integer_text(model%node_ids(nodes(k)))
    end do
    if (size(nodes) > 8) text = text//", ..."
  end function node_list

  !> How many welds have failed.
  pure integer function failed_weld_count(welds)
    type(spot_weld_state_t), intent(in) :: welds(:)
    failed_weld_count = count(welds%failed)
  end function failed_weld_count
end module spot_weld_constraints
