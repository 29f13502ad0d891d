!> Linear static analysis (*CONTROL_IMPLICIT_GENERAL IMFLAG = 1): small-strain linear elasticity
!> with the element and meshfree kernels of the explicit solver, solved once for the loads and
!> essential conditions at the end time. It exists to reproduce accuracy results (patch tests,
!> cantilever convergence) without dynamics. See docs/static.md.
!>
!> Steps, each one procedure:
!>   EFG set-up of each meshfree part (efg_setup, as for explicit runs)
!>   -> essential conditions and node classes (static_conditions, static_dofs)
!>   -> reverse Cuthill-McKee order and equation numbers (static_ordering, static_dofs)
!>   -> loads on the unknowns (static_loads, static_dofs)
!>   -> K and right-hand side in band storage, multiplier rows for particle conditions
!>      (static_assembly)
!>   -> banded Cholesky, or banded LU when there are multipliers (static_band_matrix)
!>   -> displacements, stresses, internal forces, energies, residual (static_recovery)
!>   -> one state and the histories (static_output).
module static_analysis
  use kinds, only: wp
  use error_handling, only: error_t, make_error
  use wall_clock, only: seconds_now
  use model, only: model_t, formulation_fe, formulation_efg
  use efg_part, only: efg_part_t
  use efg_setup, only: build_efg_part
  use results_file, only: results_file_t
  use run_summary, only: run_summary_t
  use static_solution, only: static_solution_t
  use static_conditions, only: static_end_time, essential_conditions
  use static_loads, only: static_nodal_forces
  use static_dofs, only: static_dofs_t, classify_nodes, coupling_groups, number_equations, &
                         equation_half_bandwidth, generalize_forces, physical_displacements, &
                         node_inactive, node_nodal, node_particle
  use static_ordering, only: node_groups_t, reverse_cuthill_mckee, coordinate_order
  use static_band_matrix, only: band_matrix_t, create_band_matrix, factor_band_matrix, solve_band_matrix
  use static_assembly, only: assemble_stiffness, add_constraint_rows
  use static_recovery, only: recover_static_fields
  use static_output, only: write_static_results, report_static_solution
  use text_format, only: integer_text, scientific_text
  implicit none
  private

  public :: run_static, solve_static

contains

  !> The static analysis of a job: solve, print the figures, write the state and histories into
  !> the open `results` file, and fill `summary` (end time, one cycle, counts, seconds). On an
  !> error nothing is written and `error` names the cause; the job then closes the file with an
  !> error status.
  subroutine run_static(model, results, summary, error)
    type(model_t), intent(in) :: model
    type(results_file_t), intent(inout) :: results
    type(run_summary_t), intent(inout) :: summary
    type(error_t), allocatable, intent(out) :: error
    type(static_solution_t) :: solution
    real(wp) :: started

    call solve_static(model, solution, error)
    summary%efg_setup_s = solution%efg_setup_s
    summary%setup_s = summary%setup_s + solution%efg_setup_s + solution%ordering_s
    summary%fe_elements = solution%fe_elements
    summary%efg_particles = solution%efg_particles
    summary%dofs_total = 3*size(model%node_ids)
    summary%dofs_efg = 3*solution%efg_nodes
    if (allocated(error)) return
    call report_static_solution(model, solution)

    started = seconds_now()
    call write_static_results(model, solution, results, error)
    summary%output_s = seconds_now() - started
    summary%fe_solid_s = solution%fe_assembly_s
    summary%efg_s = solution%efg_assembly_s
    summary%end_time = solution%time
    summary%cycles = 1
  end subroutine run_static

  !> Solve the linear static problem of `model` at its end time.
  subroutine solve_static(model, solution, error)
    type(model_t), intent(in) :: model
    type(static_solution_t), intent(out) :: solution
    type(error_t), allocatable, intent(out) :: error
    type(efg_part_t), allocatable :: efg_parts(:)
    type(static_dofs_t) :: dofs
    type(node_groups_t) :: groups
    type(band_matrix_t) :: matrix
    logical, allocatable :: prescribed(:, :)
    real(wp), allocatable :: prescribed_value(:, :), physical_force(:, :), force(:, :), right_hand_side(:)
    real(wp), allocatable :: internal_force(:, :), constraint_force(:, :)
    real(wp) :: started, scale, pivot_ratio
    integer :: weakest
    logical :: singular, failed

    solution%time = static_end_time(model)
    call check_model(model, error)
    if (allocated(error)) return
    call set_up_meshfree_parts(model, efg_parts, solution, error)
    if (allocated(error)) return

    ! unknowns, their order and numbers
    started = seconds_now()
    call essential_conditions(model, solution%time, prescribed, prescribed_value, error)
    if (allocated(error)) return
    call classify_nodes(model, efg_parts, prescribed, prescribed_value, dofs, error)
    if (allocated(error)) return
    call coupling_groups(model, efg_parts, dofs, groups)
    call choose_ordering(model, groups, dofs, solution)
    solution%multipliers = dofs%multiplier_count
    solution%unknowns = dofs%equation_count - dofs%multiplier_count
    solution%cholesky = dofs%multiplier_count == 0
    solution%ordering_s = seconds_now() - started
    if (dofs%equation_count == 0) then
      call make_error(error, "static analysis: every dof is prescribed; there is nothing to solve")
      return
    end if

    ! loads on the unknowns
    call static_nodal_forces(model, solution%time, physical_force)
    call generalize_forces(model, efg_parts, dofs, physical_force, force, error)
    if (allocated(error)) return
    allocate (right_hand_side(dofs%equation_count))
    right_hand_side = 0.0_wp
    call gather_unknowns(dofs, force, right_hand_side)

    ! the system
    call create_band_matrix(matrix, dofs%equation_count, solution%half_bandwidth, solution%cholesky, &
                            solution%band_megabytes, failed)
    if (failed) then
      call make_error(error, "static analysis: cannot allocate the band matrix ("// &
                      scientific_text(solution%band_megabytes, 3)//" MB for "//integer_text(dofs%equation_count)// &
                      " equations, half bandwidth "//integer_text(solution%half_bandwidth)//")")
      return
    end if
    call assemble_stiffness(model, efg_parts, dofs, matrix, right_hand_side, solution%fe_assembly_s, &
                            solution%efg_assembly_s, error)
    if (allocated(error)) return
    scale = 0.0_wp
    if (dofs%multiplier_count > 0) call add_constraint_rows(efg_parts, dofs, matrix, right_hand_side, scale)

    started = seconds_now()
    call factor_band_matrix(matrix, singular, weakest, pivot_ratio)
    solution%factor_s = seconds_now() - started
    solution%pivot_ratio = pivot_ratio
    if (singular) then
      call singular_error(model, dofs, weakest, pivot_ratio, error)
      return
    end if
    started = seconds_now()
    call solve_band_matrix(matrix, right_hand_side)
    solution%solve_s = seconds_now() - started

    ! results
    started = seconds_now()
    call scatter_unknowns(dofs, right_hand_side, solution%generalized)
    allocate (solution%displacement(3, size(model%node_ids)))
    call physical_displacements(efg_parts, dofs, solution%generalized, solution%displacement)
    allocate (solution%solid_stress(6, size(model%solid_ids)), internal_force(3, size(model%node_ids)), &
              solution%part_energy(size(model%parts)))
    call recover_static_fields(model, efg_parts, solution%generalized, solution%solid_stress, internal_force, &
                               solution%part_energy)
    call constraint_forces(efg_parts, dofs, scale, right_hand_side, constraint_force)
    call balance_energies(dofs, force, internal_force, constraint_force, solution, scale, right_hand_side)
    solution%recovery_s = seconds_now() - started
  end subroutine solve_static

  !> Number the equations in the node order with the narrowest band among reverse Cuthill-McKee,
  !> the coordinate order along the longest extent and the deck's own node order (see
  !> static_ordering for why one algorithm does not win everywhere).
  subroutine choose_ordering(model, groups, dofs, solution)
    type(model_t), intent(in) :: model
    type(node_groups_t), intent(in) :: groups
    type(static_dofs_t), intent(inout) :: dofs
    type(static_solution_t), intent(inout) :: solution
    integer, allocatable :: natural(:), rcm(:), coordinate(:)
    logical, allocatable :: listed(:)
    integer :: node

    natural = pack([(node, node=1, size(model%node_ids))], dofs%node_class /= node_inactive)
    call number_equations(natural, dofs)
    solution%natural_half_bandwidth = equation_half_bandwidth(dofs, groups)
    call coordinate_order(model%coordinates, natural, coordinate)
    call number_equations(coordinate, dofs)
    solution%coordinate_half_bandwidth = equation_half_bandwidth(dofs, groups)
    call reverse_cuthill_mckee(size(model%node_ids), groups, rcm)
    ! a node with unknowns but no coupling (it would make K singular) still gets its numbers
    allocate (listed(size(model%node_ids)))
    listed = .false.
    listed(rcm) = .true.
    rcm = [rcm, pack(natural, .not. listed(natural))]
    call number_equations(rcm, dofs)
    solution%rcm_half_bandwidth = equation_half_bandwidth(dofs, groups)
    solution%ordering = "reverse Cuthill-McKee"
    solution%half_bandwidth = solution%rcm_half_bandwidth
    if (solution%coordinate_half_bandwidth < solution%half_bandwidth) then
      call number_equations(coordinate, dofs)
      solution%ordering = "coordinate order"
      solution%half_bandwidth = solution%coordinate_half_bandwidth
    end if
    if (solution%natural_half_bandwidth < solution%half_bandwidth) then
      call number_equations(natural, dofs)
      solution%ordering = "node order of the deck"
      solution%half_bandwidth = solution%natural_half_bandwidth
    end if
  end subroutine choose_ordering

  !> What a static analysis cannot take: rigid parts, rigid walls, materials without a proper
  !> elastic stiffness, a model without solids.
  subroutine check_model(model, error)
    type(model_t), intent(in) :: model
    type(error_t), allocatable, intent(out) :: error
    integer :: part

    if (.not. allocated(model%solid_ids)) then
      call make_error(error, "static analysis: the model has no solid elements")
      return
    else if (size(model%solid_ids) == 0) then
      call make_error(error, "static analysis: the model has no solid elements")
      return
    end if
    if (allocated(model%walls)) then
      if (size(model%walls) > 0) then
        call make_error(error, "static analysis: rigid wall "//integer_text(model%walls(1)%id)//" (and any "// &
                        "other *RIGIDWALL) is contact, which a linear static analysis does not model; remove "// &
                        "the *RIGIDWALL cards or prescribe the displacements they would impose")
        return
      end if
    end if
    do part = 1, size(model%parts)
      if (.not. any(model%solid_part == part)) cycle
      if (model%parts(part)%formulation /= formulation_fe .and. model%parts(part)%formulation /= formulation_efg) then
        call make_error(error, "static analysis: part "//integer_text(model%parts(part)%id)// &
                        " is rigid; the static analysis takes deformable FE and EFG parts only")
        return
      end if
      associate (material => model%materials(model%parts(part)%material))
        if (material%youngs_modulus <= 0.0_wp .or. material%poissons_ratio <= -1.0_wp .or. &
            material%poissons_ratio >= 0.5_wp) then
          call make_error(error, "static analysis: material "//integer_text(material%id)//" of part "// &
                          integer_text(model%parts(part)%id)//" needs E > 0 and PR in (-1, 0.5) for a "// &
                          "stiffness (E = "//scientific_text(material%youngs_modulus, 3)//", PR = "// &
                          scientific_text(material%poissons_ratio, 3)//")")
          return
        end if
      end associate
    end do
  end subroutine check_model

  !> Build the EFG data of every meshfree part (the same set-up as explicit runs).
  subroutine set_up_meshfree_parts(model, efg_parts, solution, error)
    type(model_t), intent(in) :: model
    type(efg_part_t), allocatable, intent(out) :: efg_parts(:)
    type(static_solution_t), intent(inout) :: solution
    type(error_t), allocatable, intent(out) :: error
    integer :: part, k

    solution%fe_elements = 0
    do part = 1, size(model%parts)
      if (model%parts(part)%formulation == formulation_fe) &
        solution%fe_elements = solution%fe_elements + count(model%solid_part == part)
    end do
    ! parts without solids (defined in the deck but not used) have nothing to set up
    allocate (efg_parts(count([(model%parts(part)%formulation == formulation_efg .and. &
                                any(model%solid_part == part), part=1, size(model%parts))])))
    k = 0
    do part = 1, size(model%parts)
      if (model%parts(part)%formulation /= formulation_efg .or. .not. any(model%solid_part == part)) cycle
      k = k + 1
      call build_efg_part(model, part, efg_parts(k), error)
      if (allocated(error)) return
      solution%efg_setup_s = solution%efg_setup_s + efg_parts(k)%setup_seconds
      solution%efg_particles = solution%efg_particles + size(efg_parts(k)%particles)
      solution%efg_nodes = solution%efg_nodes + size(efg_parts(k)%mass_node)
    end do
    solution%efg_parts = size(efg_parts)
  end subroutine set_up_meshfree_parts

  !> right_hand_side(equation) += force on that unknown.
  subroutine gather_unknowns(dofs, force, right_hand_side)
    type(static_dofs_t), intent(in) :: dofs
    real(wp), intent(in) :: force(:, :)
    real(wp), intent(inout) :: right_hand_side(:)
    integer :: node, direction
    do node = 1, size(force, 2)
      do direction = 1, 3
        if (dofs%equation(direction, node) > 0) right_hand_side(dofs%equation(direction, node)) = &
          right_hand_side(dofs%equation(direction, node)) + force(direction, node)
      end do
    end do
  end subroutine gather_unknowns

  !> The complete field of unknowns: solved values, prescribed values of eliminated dofs, zero on
  !> inactive nodes.
  subroutine scatter_unknowns(dofs, solved, generalized)
    type(static_dofs_t), intent(in) :: dofs
    real(wp), intent(in) :: solved(:)
    real(wp), allocatable, intent(out) :: generalized(:, :)
    integer :: node, direction
    allocate (generalized(3, size(dofs%node_class)))
    do node = 1, size(dofs%node_class)
      do direction = 1, 3
        if (dofs%equation(direction, node) > 0) then
          generalized(direction, node) = solved(dofs%equation(direction, node))
        else if (dofs%node_class(node) == node_nodal .and. dofs%prescribed(direction, node)) then
          generalized(direction, node) = dofs%prescribed_value(direction, node)
        else
          generalized(direction, node) = 0.0_wp
        end if
      end do
    end do
  end subroutine scatter_unknowns

  !> Forces of the multipliers on the unknowns, scale * C^T mu (C the transformation rows of the
  !> constrained particles): the supports' reactions are their negatives.
  subroutine constraint_forces(efg_parts, dofs, scale, solved, force)
    type(efg_part_t), intent(in) :: efg_parts(:)
    type(static_dofs_t), intent(in) :: dofs
    real(wp), intent(in) :: scale, solved(:)
    real(wp), allocatable, intent(out) :: force(:, :)
    integer :: node, direction, k
    allocate (force(3, size(dofs%node_class)))
    force = 0.0_wp
    do node = 1, size(dofs%node_class)
      if (dofs%node_class(node) /= node_particle) cycle
      associate (efg => efg_parts(dofs%particle_part(node)), j => dofs%particle_number(node))
        do direction = 1, 3
          if (dofs%multiplier(direction, node) == 0) cycle
          do k = efg%transform_offsets(j), efg%transform_offsets(j + 1) - 1
            force(direction, efg%transform_node(k)) = force(direction, efg%transform_node(k)) + &
              scale*efg%transform_value(k)*solved(dofs%multiplier(direction, node))
          end do
        end do
      end associate
    end do
  end subroutine constraint_forces

  !> Energies of the loads applied in proportion from zero (Clapeyron): the strain energy d.K.d/2
  !> from the points, the work f.u/2 of the loads, and the work of the supports: reactions K d - f
  !> on eliminated dofs times their prescribed values, and the multipliers' reactions
  !> -scale C^T mu, whose work on d is -scale mu.g. Their sum equals the strain energy up to the
  !> equilibrium residual, which is measured on the unknowns: K d - f + scale C^T mu.
  subroutine balance_energies(dofs, force, internal_force, constraint_force, solution, scale, solved)
    type(static_dofs_t), intent(in) :: dofs
    real(wp), intent(in) :: force(:, :), internal_force(:, :), constraint_force(:, :)
    type(static_solution_t), intent(inout) :: solution
    real(wp), intent(in) :: scale, solved(:)
    real(wp) :: largest_residual, largest_force
    integer :: node, direction

    solution%internal_energy = sum(solution%part_energy)
    solution%load_work = 0.5_wp*sum(force*solution%generalized)
    solution%support_work = 0.0_wp
    largest_residual = 0.0_wp
    largest_force = 0.0_wp
    do node = 1, size(dofs%node_class)
      do direction = 1, 3
        largest_force = max(largest_force, abs(internal_force(direction, node)))
        if (dofs%equation(direction, node) > 0) then
          largest_residual = max(largest_residual, abs(internal_force(direction, node) - force(direction, node) + &
                                                       constraint_force(direction, node)))
        else if (dofs%node_class(node) == node_nodal .and. dofs%prescribed(direction, node)) then
          solution%support_work = solution%support_work + 0.5_wp*(internal_force(direction, node) - &
                                  force(direction, node))*dofs%prescribed_value(direction, node)
        end if
        if (dofs%multiplier(direction, node) > 0) solution%support_work = solution%support_work - &
          0.5_wp*scale*solved(dofs%multiplier(direction, node))*dofs%prescribed_value(direction, node)
      end do
    end do
    solution%external_work = solution%load_work + solution%support_work
    solution%residual = 0.0_wp
    if (largest_force > 0.0_wp) solution%residual = largest_residual/largest_force
  end subroutine balance_energies

  !> A singular system: name the dof where the factorization found it and the likely causes.
  subroutine singular_error(model, dofs, column, pivot_ratio, error)
    type(model_t), intent(in) :: model
    type(static_dofs_t), intent(in) :: dofs
    integer, intent(in) :: column
    real(wp), intent(in) :: pivot_ratio
    type(error_t), allocatable, intent(out) :: error
    character(len=*), parameter :: axes = "xyz"
    character(len=:), allocatable :: where
    integer :: node, direction

    where = "equation "//integer_text(column)
    do node = 1, size(dofs%node_class)
      do direction = 1, 3
        if (dofs%equation(direction, node) == column) then
          where = "node "//integer_text(model%node_ids(node))//" "//axes(direction:direction)
        else if (dofs%multiplier(direction, node) == column) then
          where = "the condition on particle "//integer_text(model%node_ids(node))//" "//axes(direction:direction)
        end if
      end do
    end do
    call make_error(error, "static analysis: the stiffness matrix is singular (pivot ratio "// &
                    scientific_text(pivot_ratio, 3)//" at "//where//"): the model can move without straining. Likely "// &
                    "cause: the supports do not prevent every rigid-body motion (three translations and three "// &
                    "rotations of each separate part; check *BOUNDARY_SPC and the prescribed displacements), or a "// &
                    "part is not connected to a supported one")
  end subroutine singular_error
end module static_analysis
