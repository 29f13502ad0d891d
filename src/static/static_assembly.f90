!> Assembly of the linear static system: the stiffness K = sum over integration points of
!> W B^T D B (static_stiffness) into the banded matrix, the eliminated essential conditions into
!> the right-hand side, and the rows and columns of the Lagrange multipliers of the particle
!> conditions.
!>
!> Integration points:
!> - FE solids: the 2x2x2 Gauss points, for ELFORM 1 as well as ELFORM 2. The explicit one-point
!>   element owes its stability to its hourglass forces; without them its stiffness has twelve
!>   zero-energy (hourglass) modes besides the rigid-body modes and a static system built on it is
!>   singular, so a static analysis integrates every solid fully.
!> - EFG parts: the points of efg_part_t with their volumes W_g and (node, gradient) pairs.
!> Every point of a part uses the elastic moduli of its material (the static analysis is linear
!> whatever the law).
module static_assembly
  use kinds, only: wp, block_size
  use error_handling, only: error_t, make_error
  use wall_clock, only: seconds_now
  use model, only: model_t, formulation_fe
  use material_dispatch, only: elastic_moduli
  use efg_part, only: efg_part_t
  use static_dofs, only: static_dofs_t, node_particle
  use static_stiffness, only: elasticity_matrix, add_point_stiffness, solid_gauss_gradients
  use static_band_matrix, only: band_matrix_t, add_band_entry, add_band_block, band_diagonal
  use text_format, only: integer_text
  implicit none
  private

  public :: assemble_stiffness, add_constraint_rows, part_elasticity_matrix, fe_part_solids

contains

  !> K into `matrix` (created empty with the system's size and bandwidth) and the eliminated
  !> conditions into `right_hand_side` (which holds the forces on the unknowns). Seconds spent on
  !> the FE solids and on the EFG points are returned for /timing.
  subroutine assemble_stiffness(model, efg_parts, dofs, matrix, right_hand_side, fe_seconds, efg_seconds, error)
    type(model_t), intent(in) :: model
    type(efg_part_t), intent(in) :: efg_parts(:)
    type(static_dofs_t), intent(in) :: dofs
    type(band_matrix_t), intent(inout) :: matrix
    real(wp), intent(inout) :: right_hand_side(:)
    real(wp), intent(out) :: fe_seconds, efg_seconds
    type(error_t), allocatable, intent(out) :: error
    real(wp) :: gradients(3, 8, 8, block_size), weights(8, block_size), element(24, 24), lambda, mu
    integer, allocatable :: solids(:)
    integer, parameter :: corners(8) = [1, 2, 3, 4, 5, 6, 7, 8]
    integer :: part, first, last, lane, point, inverted, k
    real(wp) :: started

    started = seconds_now()
    do part = 1, size(model%parts)
      if (model%parts(part)%formulation /= formulation_fe) cycle
      call part_lame_constants(model, part, lambda, mu)
      solids = fe_part_solids(model, part)
      do first = 1, size(solids), block_size
        last = min(first + block_size - 1, size(solids))
        call solid_gauss_gradients(model%coordinates, model%solid_nodes(:, solids(first:last)), gradients, weights, &
                                   inverted)
        if (inverted > 0) then
          call make_error(error, "static analysis: solid "// &
                          integer_text(model%solid_ids(solids(first + inverted - 1)))//" of part "// &
                          integer_text(model%parts(part)%id)//" has a non-positive Jacobian determinant at a "// &
                          "Gauss point: it is inverted or degenerate")
          return
        end if
        do lane = 1, last - first + 1
          element = 0.0_wp
          do point = 1, 8
            call add_point_stiffness(weights(point, lane), gradients(:, :, point, lane), corners, lambda, mu, element)
          end do
          call add_group_matrix(dofs, model%solid_nodes(:, solids(first + lane - 1)), element, matrix, right_hand_side)
        end do
      end do
    end do
    fe_seconds = seconds_now() - started

    started = seconds_now()
    do k = 1, size(efg_parts)
      call assemble_efg_part(model, efg_parts(k), dofs, matrix, right_hand_side)
    end do
    efg_seconds = seconds_now() - started
  end subroutine assemble_stiffness

  !> The points of one EFG part, cell by cell: the points of a cell (consecutive in efg_part_t)
  !> add into one matrix over the union of their nodes, which is scattered into the band once
  !> (a cell's 8 or 64 points share most of their nodes). Serial: it takes a small fraction of the
  !> EFG set-up for the usual supports (an OpenMP version with the scatter in cell order was
  !> slower: the ordered scatter serialises it and the cell matrices stream through memory).
  subroutine assemble_efg_part(model, efg, dofs, matrix, right_hand_side)
    type(model_t), intent(in) :: model
    type(efg_part_t), intent(in) :: efg
    type(static_dofs_t), intent(in) :: dofs
    type(band_matrix_t), intent(inout) :: matrix
    real(wp), intent(inout) :: right_hand_side(:)
    real(wp), allocatable :: cell_matrix(:, :)
    integer, allocatable :: position(:), cell_nodes(:), cell_first(:)
    real(wp) :: lambda, mu
    integer :: g, cell, cell_count, node_count

    call part_lame_constants(model, efg%part, lambda, mu)
    ! runs of points with the same cell
    allocate (cell_first(size(efg%point_volume) + 1))
    cell_count = 0
    do g = 1, size(efg%point_volume)
      if (g > 1) then
        if (efg%point_cell(g) == efg%point_cell(g - 1)) cycle
      end if
      cell_count = cell_count + 1
      cell_first(cell_count) = g
    end do
    cell_first(cell_count + 1) = size(efg%point_volume) + 1

    allocate (position(size(model%node_ids)))
    position = 0
    do cell = 1, cell_count
      call cell_stiffness(efg, cell_first(cell), cell_first(cell + 1) - 1, lambda, mu, position, cell_nodes, &
                          node_count, cell_matrix)
      call add_group_matrix(dofs, cell_nodes(1:node_count), cell_matrix(1:3*node_count, 1:3*node_count), matrix, &
                            right_hand_side)
    end do
  end subroutine assemble_efg_part

  !> The stiffness of points first..last (one cell) over the union of their nodes,
  !> `cell_nodes(1:node_count)` in order of appearance: `cell_matrix(1:3 node_count, 1:3 node_count)`.
  !> `position` (one entry per model node) is zero on entry and on return; the work arrays grow as
  !> needed.
  subroutine cell_stiffness(efg, first, last, lambda, mu, position, cell_nodes, node_count, cell_matrix)
    type(efg_part_t), intent(in) :: efg
    integer, intent(in) :: first, last
    real(wp), intent(in) :: lambda, mu
    integer, intent(inout) :: position(:)
    integer, allocatable, intent(inout) :: cell_nodes(:)
    integer, intent(out) :: node_count
    real(wp), allocatable, intent(inout) :: cell_matrix(:, :)
    integer :: g, k, pair_first, pair_last

    node_count = 0
    do k = efg%point_offsets(first), efg%point_offsets(last + 1) - 1
      if (position(efg%pair_node(k)) /= 0) cycle
      node_count = node_count + 1
      position(efg%pair_node(k)) = node_count
    end do
    if (allocated(cell_nodes)) then
      if (size(cell_nodes) < node_count) deallocate (cell_nodes, cell_matrix)
    end if
    if (.not. allocated(cell_nodes)) allocate (cell_nodes(2*node_count), cell_matrix(6*node_count, 6*node_count))
    do k = efg%point_offsets(first), efg%point_offsets(last + 1) - 1
      cell_nodes(position(efg%pair_node(k))) = efg%pair_node(k)
    end do
    cell_matrix(1:3*node_count, 1:3*node_count) = 0.0_wp
    do g = first, last
      pair_first = efg%point_offsets(g)
      pair_last = efg%point_offsets(g + 1) - 1
      call add_point_stiffness(efg%point_volume(g), efg%pair_gradient(:, pair_first:pair_last), &
                               position(efg%pair_node(pair_first:pair_last)), lambda, mu, &
                               cell_matrix(1:3*node_count, 1:3*node_count))
    end do
    position(cell_nodes(1:node_count)) = 0
  end subroutine cell_stiffness

  !> Rows and columns of the multipliers: for each prescribed direction c of a particle J,
  !> scale * sum_k Psi_k(X_J) d_kc = scale * g_Jc, with the multiplier's column the transposed
  !> row (the system stays symmetric). `scale` (the mean stiffness diagonal) puts the constraint
  !> entries on the stiffness's scale, so partial pivoting treats both alike; the solved
  !> multiplier unknowns are mu = lambda / scale.
  subroutine add_constraint_rows(efg_parts, dofs, matrix, right_hand_side, scale)
    type(efg_part_t), intent(in) :: efg_parts(:)
    type(static_dofs_t), intent(in) :: dofs
    type(band_matrix_t), intent(inout) :: matrix
    real(wp), intent(inout) :: right_hand_side(:)
    real(wp), intent(out) :: scale
    real(wp) :: value
    integer :: node, direction, row, column, k, count, other

    scale = 0.0_wp
    count = 0
    do node = 1, size(dofs%node_class)
      do direction = 1, 3
        if (dofs%equation(direction, node) == 0) cycle
        scale = scale + abs(band_diagonal(matrix, dofs%equation(direction, node)))
        count = count + 1
      end do
    end do
    scale = scale/real(max(count, 1), wp)
    if (scale <= 0.0_wp) scale = 1.0_wp

    do node = 1, size(dofs%node_class)
      if (dofs%node_class(node) /= node_particle) cycle
      do direction = 1, 3
        row = dofs%multiplier(direction, node)
        if (row == 0) cycle
        right_hand_side(row) = scale*dofs%prescribed_value(direction, node)
        associate (efg => efg_parts(dofs%particle_part(node)), j => dofs%particle_number(node))
          do k = efg%transform_offsets(j), efg%transform_offsets(j + 1) - 1
            other = efg%transform_node(k)
            value = scale*efg%transform_value(k)
            column = dofs%equation(direction, other)
            if (column > 0) then
              call add_band_entry(matrix, row, column, value)
              call add_band_entry(matrix, column, row, value)
            else if (dofs%prescribed(direction, other)) then
              right_hand_side(row) = right_hand_side(row) - value*dofs%prescribed_value(direction, other)
            end if
          end do
        end associate
      end do
    end do
  end subroutine add_constraint_rows

  !> Add an element's or a cell's matrix over `nodes` (3 dofs each, node-major): entries between
  !> unknowns go to the band, entries against eliminated dofs move their known values to the
  !> right-hand side.
  subroutine add_group_matrix(dofs, nodes, local, matrix, right_hand_side)
    type(static_dofs_t), intent(in) :: dofs
    integer, intent(in) :: nodes(:)
    real(wp), intent(in) :: local(:, :)
    type(band_matrix_t), intent(inout) :: matrix
    real(wp), intent(inout) :: right_hand_side(:)
    integer :: equations(3*size(nodes)), a, c
    real(wp) :: known(3*size(nodes))

    do a = 1, size(nodes)
      do c = 1, 3
        equations(3*(a - 1) + c) = dofs%equation(c, nodes(a))
        known(3*(a - 1) + c) = 0.0_wp
        if (dofs%equation(c, nodes(a)) == 0 .and. dofs%prescribed(c, nodes(a))) &
          known(3*(a - 1) + c) = dofs%prescribed_value(c, nodes(a))
      end do
    end do
    call add_band_block(matrix, equations, local)
    if (all(known == 0.0_wp)) return
    do a = 1, size(equations)
      if (equations(a) == 0) cycle
      right_hand_side(equations(a)) = right_hand_side(equations(a)) - dot_product(local(a, :), known)
    end do
  end subroutine add_group_matrix

  !> Lame constants lambda = K - 2G/3 and mu = G of the material of part `part` (its elastic
  !> moduli, whatever its law).
  pure subroutine part_lame_constants(model, part, lambda, mu)
    type(model_t), intent(in) :: model
    integer, intent(in) :: part
    real(wp), intent(out) :: lambda, mu
    real(wp) :: bulk_modulus
    call elastic_moduli(model%materials(model%parts(part)%material), bulk_modulus, mu)
    lambda = bulk_modulus - 2.0_wp*mu/3.0_wp
  end subroutine part_lame_constants

  !> D of the material of part `part` (its elastic moduli, whatever its law).
  pure function part_elasticity_matrix(model, part) result(d)
    type(model_t), intent(in) :: model
    integer, intent(in) :: part
    real(wp) :: d(6, 6)
    real(wp) :: bulk_modulus, shear_modulus
    call elastic_moduli(model%materials(model%parts(part)%material), bulk_modulus, shear_modulus)
    d = elasticity_matrix(bulk_modulus, shear_modulus)
  end function part_elasticity_matrix

  !> The solids of part `part`, ascending.
  pure function fe_part_solids(model, part) result(solids)
    type(model_t), intent(in) :: model
    integer, intent(in) :: part
    integer, allocatable :: solids(:)
    integer :: solid
    solids = pack([(solid, solid=1, size(model%solid_part))], model%solid_part == part)
  end function fe_part_solids
end module static_assembly
