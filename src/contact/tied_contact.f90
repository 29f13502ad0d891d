!> Tied contacts in the explicit time loop (*CONTACT_TIED_..., *CONTACT_SPOTWELD), LS-DYNA's
!> constraint formulation: a tied secondary node moves with the point of its primary segment it
!> was projected on at set-up (deck_tied_contact).
!>
!> After the accelerations a = f / m of all nodes, each tied node's mass m_s and force
!> f_s = m_s a_s go to its segment's nodes with the shape functions w_j (m_j += w_j m_s,
!> f_j += w_j f_s); those nodes' accelerations are taken again from the sums, and the tied
!> node's acceleration is interpolated from them, a_s = sum w_j a_j (and its velocity, so that
!> it starts and stays with the segment). The sum of m a over all nodes is unchanged (the w_j
!> sum to 1): momentum is conserved exactly. Where the tie carries rotations (shell edges, spot
!> weld beams) and the tied node and all segment nodes have rotary inertia, their rotary
!> inertias and moments are treated the same way. Ties are visited in order on one thread:
!> a primary node gets its shares in the same order for any thread count; the cost is linear
!> in the number of tied nodes and nothing is allocated per cycle.
module tied_contact
  use kinds, only: wp
  use model, only: model_t
  implicit none
  private

  public :: set_up_tied_contacts, distribute_tied_nodes, follow_segments

  !> Work arrays of the ties, allocated once and sized to the nodes of the segments that carry a
  !> tied node (none without tied contacts): the list of those nodes, each one's slot in the
  !> shares, and the shares they receive.
  type, public :: tied_state_t
    integer, allocatable :: primary_nodes(:)        !< (slots) every node of a segment with a tied node
    integer, allocatable :: corner_slots(:)         !< (4 per tied node, ties in order) each corner's slot
    real(wp), allocatable :: extra_mass(:)          !< (slots) tied masses received
    real(wp), allocatable :: extra_force(:, :)      !< (3, slots) tied forces received
    real(wp), allocatable :: extra_inertia(:)       !< (slots) tied rotary inertias received
    real(wp), allocatable :: extra_moment(:, :)     !< (3, slots) tied moments received (I alpha)
  end type tied_state_t

contains

  !> The work arrays and the list of primary nodes; the initial motion of each tied node and its
  !> segment made one: the segment's nodes take the tied nodes' momentum (v_j = (m_j v_j +
  !> sum w_j m_s v_s) / (m_j + sum w_j m_s), the same for the rotations), the tied nodes the
  !> interpolated velocity. Momentum is conserved; a tied node thrown with its segment keeps
  !> its velocity.
  subroutine set_up_tied_contacts(model, mass, rotary_inertia, velocity, angular_velocity, ties)
    type(model_t), intent(in) :: model
    real(wp), intent(in) :: mass(:), rotary_inertia(:)
    real(wp), intent(inout) :: velocity(:, :), angular_velocity(:, :)
    type(tied_state_t), intent(out) :: ties
    integer :: c, i, j, k, node, slot, corner
    real(wp) :: total

    call number_slots(model, size(mass), ties)
    allocate (ties%extra_mass(size(ties%primary_nodes)), ties%extra_force(3, size(ties%primary_nodes)), &
              ties%extra_inertia(size(ties%primary_nodes)), ties%extra_moment(3, size(ties%primary_nodes)))
    ties%extra_mass = 0.0_wp
    ties%extra_force = 0.0_wp
    ties%extra_inertia = 0.0_wp
    ties%extra_moment = 0.0_wp
    if (size(ties%primary_nodes) == 0) return
    corner = 0
    do c = 1, size(model%tied_contacts)
      associate (tie => model%tied_contacts(c))
        do i = 1, size(tie%nodes)
          node = tie%nodes(i)
          do j = 1, 4
            slot = ties%corner_slots(corner + j)
            ! extra_force holds momenta and extra_moment angular momenta here
            ties%extra_mass(slot) = ties%extra_mass(slot) + tie%weights(j, i)*mass(node)
            ties%extra_force(:, slot) = ties%extra_force(:, slot) + tie%weights(j, i)*mass(node)*velocity(:, node)
            if (.not. tie%rotations .or. rotary_inertia(node) <= 0.0_wp) cycle
            if (.not. all(rotary_inertia(tie%segments(:, i)) > 0.0_wp)) cycle
            ties%extra_inertia(slot) = ties%extra_inertia(slot) + tie%weights(j, i)*rotary_inertia(node)
            ties%extra_moment(:, slot) = ties%extra_moment(:, slot) + &
                                         tie%weights(j, i)*rotary_inertia(node)*angular_velocity(:, node)
          end do
          corner = corner + 4
        end do
      end associate
    end do
    do k = 1, size(ties%primary_nodes)
      node = ties%primary_nodes(k)
      total = mass(node) + ties%extra_mass(k)
      if (total > 0.0_wp) velocity(:, node) = (mass(node)*velocity(:, node) + ties%extra_force(:, k))/total
      total = rotary_inertia(node) + ties%extra_inertia(k)
      if (ties%extra_inertia(k) > 0.0_wp) &
        angular_velocity(:, node) = (rotary_inertia(node)*angular_velocity(:, node) + ties%extra_moment(:, k))/total
    end do
    do c = 1, size(model%tied_contacts)
      associate (tie => model%tied_contacts(c))
        do i = 1, size(tie%nodes)
          velocity(:, tie%nodes(i)) = interpolated(velocity, tie%segments(:, i), tie%weights(:, i))
          if (tie%rotations .and. rotary_inertia(tie%nodes(i)) > 0.0_wp .and. &
              all(rotary_inertia(tie%segments(:, i)) > 0.0_wp)) &
            angular_velocity(:, tie%nodes(i)) = interpolated(angular_velocity, tie%segments(:, i), tie%weights(:, i))
        end do
      end associate
    end do
  end subroutine set_up_tied_contacts

  !> The slots: the distinct nodes of the segments that carry a tied node, in ascending node
  !> order (primary_nodes), and for every corner of every tie its node's slot (corner_slots).
  !> The map from nodes to slots is needed at set-up only.
  subroutine number_slots(model, node_count, ties)
    type(model_t), intent(in) :: model
    integer, intent(in) :: node_count
    type(tied_state_t), intent(inout) :: ties
    integer, allocatable :: slot_of_node(:)
    integer :: c, i, j, corners, node, slots
    corners = 0
    if (allocated(model%tied_contacts)) then
      do c = 1, size(model%tied_contacts)
        corners = corners + 4*size(model%tied_contacts(c)%nodes)
      end do
    end if
    allocate (ties%corner_slots(corners))
    if (corners == 0) then
      allocate (ties%primary_nodes(0))
      return
    end if
    allocate (slot_of_node(node_count))
    slot_of_node = 0
    do c = 1, size(model%tied_contacts)
      associate (tie => model%tied_contacts(c))
        do i = 1, size(tie%nodes)
          slot_of_node(tie%segments(:, i)) = 1
        end do
      end associate
    end do
    slots = 0
    do node = 1, node_count
      if (slot_of_node(node) == 0) cycle
      slots = slots + 1
      slot_of_node(node) = slots
    end do
    allocate (ties%primary_nodes(slots))
    do node = 1, node_count
      if (slot_of_node(node) > 0) ties%primary_nodes(slot_of_node(node)) = node
    end do
    corners = 0
    do c = 1, size(model%tied_contacts)
      associate (tie => model%tied_contacts(c))
        do i = 1, size(tie%nodes)
          do j = 1, 4
            ties%corner_slots(corners + j) = slot_of_node(tie%segments(j, i))
          end do
          corners = corners + 4
        end do
      end associate
    end do
  end subroutine number_slots

  !> The first half of the tie (see the module header): each tied node's mass and force go to
  !> its segment's nodes, whose accelerations are taken again from the sums (SPC'd dofs stay
  !> zero). `acceleration` and `angular_acceleration` hold a = f / m of every node on entry.
  subroutine distribute_tied_nodes(model, ties, mass, rotary_inertia, fixed, fixed_rotation, acceleration, &
                                   angular_acceleration)
    type(model_t), intent(in) :: model
    type(tied_state_t), intent(inout) :: ties
    real(wp), intent(in) :: mass(:), rotary_inertia(:)
    logical, intent(in) :: fixed(:, :), fixed_rotation(:, :)
    real(wp), intent(inout) :: acceleration(:, :), angular_acceleration(:, :)
    integer :: c, i, j, k, node, slot, corner
    real(wp) :: force(3), moment(3), total
    logical :: rotations

    if (.not. allocated(ties%primary_nodes)) return
    if (size(ties%primary_nodes) == 0) return
    ties%extra_mass = 0.0_wp
    ties%extra_force = 0.0_wp
    ties%extra_inertia = 0.0_wp
    ties%extra_moment = 0.0_wp
    ! the tied nodes' masses and forces to their segments' nodes
    corner = 0
    do c = 1, size(model%tied_contacts)
      associate (tie => model%tied_contacts(c))
        do i = 1, size(tie%nodes)
          node = tie%nodes(i)
          force = mass(node)*acceleration(:, node)
          rotations = ties_rotations(tie%rotations, node, tie%segments(:, i), rotary_inertia)
          if (rotations) moment = rotary_inertia(node)*angular_acceleration(:, node)
          do j = 1, 4
            slot = ties%corner_slots(corner + j)
            ties%extra_mass(slot) = ties%extra_mass(slot) + tie%weights(j, i)*mass(node)
            ties%extra_force(:, slot) = ties%extra_force(:, slot) + tie%weights(j, i)*force
            if (.not. rotations) cycle
            ties%extra_inertia(slot) = ties%extra_inertia(slot) + tie%weights(j, i)*rotary_inertia(node)
            ties%extra_moment(:, slot) = ties%extra_moment(:, slot) + tie%weights(j, i)*moment
          end do
          corner = corner + 4
        end do
      end associate
    end do
    ! the segments' nodes accelerate with what they carry
    do k = 1, size(ties%primary_nodes)
      node = ties%primary_nodes(k)
      total = mass(node) + ties%extra_mass(k)
      if (total > 0.0_wp) acceleration(:, node) = (mass(node)*acceleration(:, node) + ties%extra_force(:, k))/total
      where (fixed(:, node)) acceleration(:, node) = 0.0_wp
      total = rotary_inertia(node) + ties%extra_inertia(k)
      if (ties%extra_inertia(k) > 0.0_wp .and. total > 0.0_wp) &
        angular_acceleration(:, node) = (rotary_inertia(node)*angular_acceleration(:, node) + &
                                         ties%extra_moment(:, k))/total
      where (fixed_rotation(:, node)) angular_acceleration(:, node) = 0.0_wp
    end do
  end subroutine distribute_tied_nodes

  !> The second half: every tied node takes the acceleration and velocity of its point of the
  !> segment (after the segments' prescribed motions are held), and the rotations where tied.
  subroutine follow_segments(model, rotary_inertia, acceleration, angular_acceleration, velocity, angular_velocity)
    type(model_t), intent(in) :: model
    real(wp), intent(in) :: rotary_inertia(:)
    real(wp), intent(inout) :: acceleration(:, :), angular_acceleration(:, :), velocity(:, :), angular_velocity(:, :)
    integer :: c, i, node
    if (.not. allocated(model%tied_contacts)) return
    do c = 1, size(model%tied_contacts)
      associate (tie => model%tied_contacts(c))
        do i = 1, size(tie%nodes)
          node = tie%nodes(i)
          acceleration(:, node) = interpolated(acceleration, tie%segments(:, i), tie%weights(:, i))
          velocity(:, node) = interpolated(velocity, tie%segments(:, i), tie%weights(:, i))
          if (.not. ties_rotations(tie%rotations, node, tie%segments(:, i), rotary_inertia)) cycle
          angular_acceleration(:, node) = interpolated(angular_acceleration, tie%segments(:, i), tie%weights(:, i))
          angular_velocity(:, node) = interpolated(angular_velocity, tie%segments(:, i), tie%weights(:, i))
        end do
      end associate
    end do
  end subroutine follow_segments

  !> Rotations are tied where the tie carries them and the node and all the segment's nodes
  !> have rotational dofs (rotary inertia): a shell edge on a shell surface, not on solids.
  pure logical function ties_rotations(wanted, node, segment, rotary_inertia)
    logical, intent(in) :: wanted
    integer, intent(in) :: node, segment(4)
    real(wp), intent(in) :: rotary_inertia(:)
    ties_rotations = wanted
    if (.not. wanted) return
    ties_rotations = rotary_inertia(node) > 0.0_wp .and. all(rotary_inertia(segment) > 0.0_wp)
  end function ties_rotations
  !> The value at a tied node's point of its segment: the corners' values weighted by the
  !> shape functions, corner by corner (a vector subscript would make a heap temporary per
  !> node and cycle).
  pure function interpolated(values, corners, weights) result(value)
    real(wp), intent(in) :: values(:, :), weights(:)
    integer, intent(in) :: corners(:)
    real(wp) :: value(3)
    integer :: j
    value = 0.0_wp
    do j = 1, size(corners)
      value = value + weights(j)*values(:, corners(j))
    end do
  end function interpolated
end module tied_contact
