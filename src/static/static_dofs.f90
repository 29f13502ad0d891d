!> Unknowns of the linear static analysis: what each node's three dofs mean, which are eliminated,
!> which get a Lagrange multiplier, and their equation numbers in the banded system.
!>
!> Node classes:
!> - *nodal* (nodes of finite elements and Gamma nodes of meshfree parts): the unknowns are the
!>   nodal displacements and the shape functions have the Kronecker-delta property, so an
!>   essential condition fixes the dof itself: it is eliminated (its known value moves to the
!>   right-hand side).
!> - *particle* (interior particles of meshfree parts; with IEBT 1 every node of the part): the
!>   unknowns d are generalized displacements and the physical displacement is the
!>   transformation uhat_J = sum_I Psi_I(X_J) d_I (eq. 16). An essential condition uhat_J = g_J is
!>   one linear constraint on the d of the transformation row, imposed exactly with a Lagrange
!>   multiplier; a load at the particle acts through the same row (f_I += Psi_I(X_J) F_J).
!> - *inactive*: nodes of no element; they have no stiffness and no unknown (their output
!>   displacement is their prescribed value, or zero).
!>
!> Numbering: nodes in the bandwidth-reducing order, each node's unknowns (x, y, z) and then its
!> multipliers, so that a multiplier sits beside the particle it constrains.
module static_dofs
  use kinds, only: wp
  use error_handling, only: error_t, make_error
  use model, only: model_t, formulation_fe
  use efg_part, only: efg_part_t
  use static_ordering, only: node_groups_t, add_node_group
  use text_format, only: integer_text
  implicit none
  private

  public :: static_dofs_t, classify_nodes, coupling_groups, number_equations, equation_half_bandwidth
  public :: generalize_forces, physical_displacements

  !> Node classes.
  integer, parameter, public :: node_inactive = 0, node_nodal = 1, node_particle = 2

  !> The unknowns of a static analysis.
  type :: static_dofs_t
    integer, allocatable :: node_class(:)          !< node_inactive, node_nodal or node_particle
    integer, allocatable :: particle_part(:)       !< particles: index into the EFG part list
    integer, allocatable :: particle_number(:)     !< particles: position in that part's particle list
    logical, allocatable :: prescribed(:, :)       !< (3, nodes): an essential condition holds
    real(wp), allocatable :: prescribed_value(:, :) !< (3, nodes): its value
    integer, allocatable :: equation(:, :)         !< (3, nodes): equation of the unknown, 0 if eliminated
    integer, allocatable :: multiplier(:, :)       !< (3, nodes): equation of the multiplier, 0 if none
    integer :: equation_count = 0                  !< unknowns + multipliers
    integer :: multiplier_count = 0
  end type static_dofs_t

contains

  !> Classify every node (see the module comment) and keep the essential conditions. A node that
  !> is a particle of a meshfree part and also belongs to another part (an FE element, or any node
  !> of another meshfree part) is an error: without the Kronecker property there is no nodal
  !> displacement to share (IEBT 1 parts must stand alone; IEBT 3 parts share Gamma nodes).
  subroutine classify_nodes(model, efg_parts, prescribed, prescribed_value, dofs, error)
    type(model_t), intent(in) :: model
    type(efg_part_t), intent(in) :: efg_parts(:)
    logical, intent(in) :: prescribed(:, :)
    real(wp), intent(in) :: prescribed_value(:, :)
    type(static_dofs_t), intent(out) :: dofs
    type(error_t), allocatable, intent(out) :: error
    integer, allocatable :: first_part(:)
    integer :: node_count, solid, k, j, node, corner

    node_count = size(model%node_ids)
    allocate (dofs%node_class(node_count), dofs%particle_part(node_count), dofs%particle_number(node_count), &
              first_part(node_count))
    dofs%node_class = node_inactive
    dofs%particle_part = 0
    dofs%particle_number = 0
    dofs%prescribed = prescribed
    dofs%prescribed_value = prescribed_value
    first_part = 0
    do solid = 1, size(model%solid_ids)
      if (model%parts(model%solid_part(solid))%formulation /= formulation_fe) cycle
      ! corner by corner: a degenerate solid may repeat a node
      do corner = 1, 8
        node = model%solid_nodes(corner, solid)
        dofs%node_class(node) = node_nodal
        if (first_part(node) == 0) first_part(node) = model%solid_part(solid)
      end do
    end do
    do k = 1, size(efg_parts)
      do j = 1, size(efg_parts(k)%gamma_nodes)
        node = efg_parts(k)%gamma_nodes(j)
        if (dofs%node_class(node) == node_particle) then
          call shared_particle_error(model, node, efg_parts(dofs%particle_part(node))%part, efg_parts(k)%part, error)
          return
        end if
        dofs%node_class(node) = node_nodal
        if (first_part(node) == 0) first_part(node) = efg_parts(k)%part
      end do
    end do
    do k = 1, size(efg_parts)
      do j = 1, size(efg_parts(k)%particles)
        node = efg_parts(k)%particles(j)
        if (dofs%node_class(node) /= node_inactive) then
          call shared_particle_error(model, node, efg_parts(k)%part, first_part(node), error)
          return
        end if
        dofs%node_class(node) = node_particle
        dofs%particle_part(node) = k
        dofs%particle_number(node) = j
        first_part(node) = efg_parts(k)%part
      end do
    end do
  end subroutine classify_nodes

  subroutine shared_particle_error(model, node, particle_part, other_part, error)
    type(model_t), intent(in) :: model
    integer, intent(in) :: node, particle_part, other_part
    type(error_t), allocatable, intent(out) :: error
    call make_error(error, "static analysis: node "//integer_text(model%node_ids(node))// &
                    " is an interior particle of meshfree part "//integer_text(model%parts(particle_part)%id)// &
                    " and also a node of part "//integer_text(model%parts(other_part)%id)// &
                    ": a node shared by two parts needs the Kronecker-delta property (with IEBT 1 every node "// &
                    "of a meshfree part is a particle; use IEBT 3 for meshfree parts connected to other parts)")
  end subroutine shared_particle_error

  !> The couplings of the system as groups of nodes: the nodes of each FE solid, the (node,
  !> gradient) pairs of each EFG integration point, and each constrained particle with the nodes
  !> of its transformation row.
  subroutine coupling_groups(model, efg_parts, dofs, groups)
    type(model_t), intent(in) :: model
    type(efg_part_t), intent(in) :: efg_parts(:)
    type(static_dofs_t), intent(in) :: dofs
    type(node_groups_t), intent(out) :: groups
    integer :: solid, k, g, node

    do solid = 1, size(model%solid_ids)
      if (model%parts(model%solid_part(solid))%formulation /= formulation_fe) cycle
      call add_node_group(groups, model%solid_nodes(:, solid))
    end do
    do k = 1, size(efg_parts)
      associate (efg => efg_parts(k))
        do g = 1, size(efg%point_volume)
          call add_node_group(groups, efg%pair_node(efg%point_offsets(g):efg%point_offsets(g + 1) - 1))
        end do
      end associate
    end do
    do node = 1, size(dofs%node_class)
      if (dofs%node_class(node) /= node_particle .or. .not. any(dofs%prescribed(:, node))) cycle
      associate (efg => efg_parts(dofs%particle_part(node)), j => dofs%particle_number(node))
        call add_node_group(groups, [node, &
                                     efg%transform_node(efg%transform_offsets(j):efg%transform_offsets(j + 1) - 1)])
      end associate
    end do
  end subroutine coupling_groups

  !> Equation numbers for the nodes in `order` (every node with unknowns, in the order wanted):
  !> each node's unknowns, then its multipliers. Prescribed dofs of nodal nodes are eliminated.
  subroutine number_equations(order, dofs)
    integer, intent(in) :: order(:)
    type(static_dofs_t), intent(inout) :: dofs
    integer :: k, node, direction, next

    if (.not. allocated(dofs%equation)) allocate (dofs%equation(3, size(dofs%node_class)), &
                                                  dofs%multiplier(3, size(dofs%node_class)))
    dofs%equation = 0
    dofs%multiplier = 0
    next = 0
    dofs%multiplier_count = 0
    do k = 1, size(order)
      node = order(k)
      if (dofs%node_class(node) == node_inactive) cycle
      do direction = 1, 3
        if (dofs%node_class(node) == node_nodal .and. dofs%prescribed(direction, node)) cycle
        next = next + 1
        dofs%equation(direction, node) = next
      end do
      if (dofs%node_class(node) /= node_particle) cycle
      do direction = 1, 3
        if (.not. dofs%prescribed(direction, node)) cycle
        next = next + 1
        dofs%multiplier(direction, node) = next
        dofs%multiplier_count = dofs%multiplier_count + 1
      end do
    end do
    dofs%equation_count = next
  end subroutine number_equations

  !> Half bandwidth of the numbered system: the largest distance between two equations that
  !> share a group.
  pure function equation_half_bandwidth(dofs, groups) result(half_bandwidth)
    type(static_dofs_t), intent(in) :: dofs
    type(node_groups_t), intent(in) :: groups
    integer :: half_bandwidth
    integer :: g, k, node, lowest, highest, direction

    half_bandwidth = 0
    do g = 1, groups%count
      lowest = huge(1)
      highest = 0
      do k = groups%offsets(g), groups%offsets(g + 1) - 1
        node = groups%nodes(k)
        do direction = 1, 3
          if (dofs%equation(direction, node) > 0) then
            lowest = min(lowest, dofs%equation(direction, node))
            highest = max(highest, dofs%equation(direction, node))
          end if
          if (dofs%multiplier(direction, node) > 0) then
            lowest = min(lowest, dofs%multiplier(direction, node))
            highest = max(highest, dofs%multiplier(direction, node))
          end if
        end do
      end do
      if (highest > 0) half_bandwidth = max(half_bandwidth, highest - lowest)
    end do
  end function equation_half_bandwidth

  !> Forces on the unknowns from physical nodal forces: nodal nodes take theirs, a particle J
  !> spreads its force over its transformation row, f_I += Psi_I(X_J) F_J (the virtual work of F_J
  !> on uhat_J). A force on an inactive node is an error (nothing resists it).
  subroutine generalize_forces(model, efg_parts, dofs, physical, generalized, error)
    type(model_t), intent(in) :: model
    type(efg_part_t), intent(in) :: efg_parts(:)
    type(static_dofs_t), intent(in) :: dofs
    real(wp), intent(in) :: physical(:, :)
    real(wp), allocatable, intent(out) :: generalized(:, :)
    type(error_t), allocatable, intent(out) :: error
    integer :: node, k

    allocate (generalized(3, size(physical, 2)))
    generalized = 0.0_wp
    do node = 1, size(physical, 2)
      if (all(physical(:, node) == 0.0_wp)) cycle
      select case (dofs%node_class(node))
      case (node_nodal)
        generalized(:, node) = generalized(:, node) + physical(:, node)
      case (node_particle)
        associate (efg => efg_parts(dofs%particle_part(node)), j => dofs%particle_number(node))
          do k = efg%transform_offsets(j), efg%transform_offsets(j + 1) - 1
            generalized(:, efg%transform_node(k)) = generalized(:, efg%transform_node(k)) + &
                                                    efg%transform_value(k)*physical(:, node)
          end do
        end associate
      case default
        call make_error(error, "static analysis: node "//integer_text(model%node_ids(node))// &
                        " carries a load but belongs to no element, so nothing resists it")
        return
      end select
    end do
  end subroutine generalize_forces

  !> Physical displacements from the unknowns: the transformation for particles, the unknowns
  !> themselves for nodal nodes, the prescribed value (or zero) for inactive nodes.
  subroutine physical_displacements(efg_parts, dofs, generalized, physical)
    type(efg_part_t), intent(in) :: efg_parts(:)
    type(static_dofs_t), intent(in) :: dofs
    real(wp), intent(in) :: generalized(:, :)
    real(wp), intent(out) :: physical(:, :)
    integer :: node, k

    do node = 1, size(generalized, 2)
      select case (dofs%node_class(node))
      case (node_particle)
        physical(:, node) = 0.0_wp
        associate (efg => efg_parts(dofs%particle_part(node)), j => dofs%particle_number(node))
          do k = efg%transform_offsets(j), efg%transform_offsets(j + 1) - 1
            physical(:, node) = physical(:, node) + efg%transform_value(k)*generalized(:, efg%transform_node(k))
          end do
        end associate
      case (node_nodal)
        physical(:, node) = generalized(:, node)
      case default
        physical(:, node) = merge(dofs%prescribed_value(:, node), 0.0_wp, dofs%prescribed(:, node))
      end select
    end do
  end subroutine physical_displacements
end module static_dofs
