!> Unit tests of the tied contacts' work arrays (tied_contact): sized to the nodes of the
!> segments that carry a tied node, not to the model's nodes.
!>  - Without tied contacts: nothing (no slot, no share) for a model of 1,000 nodes.
!>  - Two ties in two contacts on segments sharing two nodes, in a model of 1,000 nodes: six
!>    slots, the segments' nodes in ascending order. Set-up: the momentum sum m v over all
!>    nodes is unchanged and each tied node moves with its segment's point. A cycle's
!>    distribution: the sum of m a is unchanged, a segment node that carries nothing keeps its
!>    acceleration, and a segment node a (w m_s a_s + m_j a_j) / (w m_s + m_j).
program test_tied_slots
  use kinds, only: wp
  use testing, only: test_suite_t, check, check_close, finish_suite
  use model, only: model_t
  use tied_contact, only: tied_state_t, set_up_tied_contacts, distribute_tied_nodes, follow_segments
  implicit none

  integer, parameter :: node_count = 1000
  type(test_suite_t) :: suite

  suite%name = "tied_slots"
  call test_without_ties()
  call test_two_ties()
  call finish_suite(suite)

contains

  subroutine test_without_ties()
    type(model_t) :: model
    type(tied_state_t) :: ties
    real(wp) :: mass(node_count), inertia(node_count), velocity(3, node_count), angular(3, node_count)
    mass = 1.0_wp
    inertia = 0.0_wp
    velocity = 1.0_wp
    angular = 0.0_wp
    call set_up_tied_contacts(model, mass, inertia, velocity, angular, ties)
    call check(suite, "no ties: no slot", size(ties%primary_nodes) == 0)
    call check(suite, "no ties: no share", size(ties%extra_mass) == 0 .and. size(ties%extra_force) == 0 .and. &
               size(ties%extra_inertia) == 0 .and. size(ties%extra_moment) == 0)
    call check(suite, "no ties: velocities unchanged", all(velocity == 1.0_wp))
  end subroutine test_without_ties

  subroutine test_two_ties()
    type(model_t) :: model
    type(tied_state_t) :: ties
    real(wp) :: mass(node_count), inertia(node_count), velocity(3, node_count), angular(3, node_count)
    real(wp) :: acceleration(3, node_count), angular_acceleration(3, node_count), before(3), after(3), expected(3)
    logical :: fixed(3, node_count), fixed_rotation(3, node_count)
    integer :: node, j

    ! node 900 tied to the segment 10 20 30 40 (shape functions 0.1 0.2 0.3 0.4), node 901 to
    ! 30 40 50 60 (0.25 each) in a second contact
    allocate (model%tied_contacts(2))
    model%tied_contacts(1)%nodes = [900]
    model%tied_contacts(1)%segments = reshape([10, 20, 30, 40], [4, 1])
    model%tied_contacts(1)%weights = reshape([0.1_wp, 0.2_wp, 0.3_wp, 0.4_wp], [4, 1])
    model%tied_contacts(2)%nodes = [901]
    model%tied_contacts(2)%segments = reshape([30, 40, 50, 60], [4, 1])
    model%tied_contacts(2)%weights = reshape([0.25_wp, 0.25_wp, 0.25_wp, 0.25_wp], [4, 1])
    do node = 1, node_count
      mass(node) = 1.0_wp + 0.01_wp*node
      velocity(:, node) = [sin(real(node, wp)), cos(real(node, wp)), 0.5_wp]
      acceleration(:, node) = [cos(3.0_wp*node), sin(2.0_wp*node), -1.0_wp]
    end do
    inertia = 0.0_wp
    angular = 0.0_wp
    angular_acceleration = 0.0_wp
    fixed = .false.
    fixed_rotation = .false.
    before = momentum(mass, velocity)
    call set_up_tied_contacts(model, mass, inertia, velocity, angular, ties)
    call check(suite, "two ties: six slots, ascending", size(ties%primary_nodes) == 6)
    if (size(ties%primary_nodes) == 6) &
      call check(suite, "two ties: the segments' nodes", all(ties%primary_nodes == [10, 20, 30, 40, 50, 60]))
    call check(suite, "two ties: shares sized to the slots", size(ties%extra_mass) == 6 .and. &
               size(ties%extra_force, 2) == 6 .and. size(ties%extra_moment, 2) == 6)
    call check_close(suite, "two ties: set-up keeps the momentum", momentum(mass, velocity), before, &
                     rel=1.0e-13_wp, thr=1.0e-12_wp)
    expected = 0.1_wp*velocity(:, 10) + 0.2_wp*velocity(:, 20) + 0.3_wp*velocity(:, 30) + 0.4_wp*velocity(:, 40)
    call check_close(suite, "two ties: the tied node moves with its segment's point", velocity(:, 900), expected, &
                     rel=1.0e-14_wp, thr=1.0e-15_wp)

    before = momentum(mass, acceleration)
    expected = (0.1_wp*mass(900)*acceleration(:, 900) + mass(10)*acceleration(:, 10))/(0.1_wp*mass(900) + mass(10))
    after = acceleration(:, 500)
    call distribute_tied_nodes(model, ties, mass, inertia, fixed, fixed_rotation, acceleration, angular_acceleration)
    call follow_segments(model, inertia, acceleration, angular_acceleration, velocity, angular)
    call check_close(suite, "two ties: a segment node's acceleration", acceleration(:, 10), expected, &
                     rel=1.0e-14_wp, thr=1.0e-15_wp)
    call check(suite, "two ties: a node of no segment keeps its acceleration", all(acceleration(:, 500) == after))
    ! the tied nodes' own m a now follows the segment: the sum of m a over the segments' nodes
    ! with the tied masses counted once, at the nodes that carry them
    after = 0.0_wp
    do node = 1, node_count
      if (node == 900 .or. node == 901) cycle
      after = after + mass(node)*acceleration(:, node)
    end do
    do j = 1, 4
      associate (first => model%tied_contacts(1), second => model%tied_contacts(2))
        after = after + first%weights(j, 1)*mass(900)*acceleration(:, first%segments(j, 1))
        after = after + second%weights(j, 1)*mass(901)*acceleration(:, second%segments(j, 1))
      end associate
    end do
    call check_close(suite, "two ties: the distribution keeps the sum of m a", after, before, &
                     rel=1.0e-12_wp, thr=1.0e-11_wp)
  end subroutine test_two_ties

  !> sum m v over the nodes, in index order
  function momentum(mass, velocity) result(total)
    real(wp), intent(in) :: mass(:), velocity(:, :)
    real(wp) :: total(3)
    integer :: node
    total = 0.0_wp
    do node = 1, size(mass)
      total = total + mass(node)*velocity(:, node)
    end do
  end function momentum
end program test_tied_slots
