!> Output of the linear static analysis: one state at the end time (physical displacements, zero
!> velocities, element stresses, zero plastic strain) and the glstat and matsum histories with two
!> rows, the unloaded state at t = 0 and the solution at the end time (the loads are taken as
!> applied in proportion between them, so the energy ratio of the post-processing scripts, total
!> energy over initial total plus external work, reads 1 for a balanced solution). The glstat
!> columns are those of explicit runs; kinetic, hourglass, contact and wall energies are zero.
module static_output
  use kinds, only: wp
  use error_handling, only: error_t
  use model, only: model_t
  use history_buffer, only: history_set_t, add_history_series, append_history_row
  use results_file, only: results_file_t, write_state, write_histories
  use static_solution, only: static_solution_t
  implicit none
  private

  public :: write_static_results, report_static_solution

  character(len=32), parameter :: glstat_columns(12) = [character(len=32) :: "time", "time_step", &
    "kinetic_energy", "internal_energy", "hourglass_energy", "contact_energy", "external_work", &
    "total_energy", "rigid_wall_energy", "energy_ratio", "added_mass", "momentum"]
  integer, parameter :: glstat_widths(12) = [1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 3]
  character(len=32), parameter :: matsum_columns(4) = [character(len=32) :: "time", "kinetic_energy", &
    "internal_energy", "hourglass_energy"]

contains

  !> `/states/000000` at the end time, `/history/glstat` and `/history/matsum/<part id>`.
  subroutine write_static_results(model, solution, results, error)
    type(model_t), intent(in) :: model
    type(static_solution_t), intent(in) :: solution
    type(results_file_t), intent(inout) :: results
    type(error_t), allocatable, intent(out) :: error
    type(history_set_t) :: histories
    real(wp), allocatable :: velocity(:, :), plastic_strain(:)
    real(wp) :: ratio
    integer :: glstat, part, series
    character(len=16) :: label

    allocate (velocity(3, size(model%node_ids)), plastic_strain(size(model%solid_ids)))
    velocity = 0.0_wp
    plastic_strain = 0.0_wp
    call write_state(results, solution%time, solution%displacement, velocity, solution%solid_stress, &
                     plastic_strain, error, reference_coordinates=model%coordinates)
    if (allocated(error)) return

    ratio = 1.0_wp
    if (abs(solution%external_work) > tiny(1.0_wp)) ratio = solution%internal_energy/solution%external_work
    call add_history_series(histories, "glstat", glstat_columns, glstat_widths, 2, glstat)
    ! time, time_step, kinetic, internal, hourglass, contact, external work, total, wall, ratio,
    ! added mass, momentum (3)
    call append_history_row(histories%series(glstat), [0.0_wp, solution%time, 0.0_wp, 0.0_wp, 0.0_wp, &
                            0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp])
    call append_history_row(histories%series(glstat), [solution%time, solution%time, 0.0_wp, &
                            solution%internal_energy, 0.0_wp, 0.0_wp, solution%external_work, &
                            solution%internal_energy, 0.0_wp, ratio, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp])
    do part = 1, size(model%parts)
      write (label, '(i0)') model%parts(part)%id
      call add_history_series(histories, "matsum/"//trim(label), matsum_columns, [1, 1, 1, 1], 2, series)
      call append_history_row(histories%series(series), [0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp])
      call append_history_row(histories%series(series), [solution%time, 0.0_wp, solution%part_energy(part), 0.0_wp])
    end do
    call write_histories(results, histories, error)
  end subroutine write_static_results

  !> The figures of the solve on standard output.
  subroutine report_static_solution(model, solution)
    type(model_t), intent(in) :: model
    type(static_solution_t), intent(in) :: solution
    character(len=240) :: line

    write (line, '(a,i0,a,i0,a,i0,a,es12.5)') "model: ", size(model%node_ids), " nodes, ", size(model%solid_ids), &
      " solids in ", size(model%parts), " parts; linear static analysis at time ", solution%time
    write (*, '(a)') trim(line)
    write (line, '(a,i0,a,i0,a,i0,a)') "static: ", solution%unknowns + solution%multipliers, " equations (", &
      solution%unknowns, " displacement unknowns, ", solution%multipliers, " multipliers)"
    write (*, '(a)') trim(line)
    if (solution%efg_parts > 0) then
      write (line, '(a,i0,a,i0,a,f0.3,a)') "  meshfree: ", solution%efg_parts, " EFG part(s), ", &
        solution%efg_particles, " particles; set-up ", solution%efg_setup_s, " s"
      write (*, '(a)') trim(line)
    end if
    write (line, '(a,i0,a,i0,a,i0,a,i0,a,f0.3,a)') "  ordering: "//solution%ordering//", half bandwidth ", &
      solution%half_bandwidth, " (reverse Cuthill-McKee ", solution%rcm_half_bandwidth, ", coordinate order ", &
      solution%coordinate_half_bandwidth, ", deck order ", solution%natural_half_bandwidth, "); ", &
      solution%ordering_s, " s"
    write (*, '(a)') trim(line)
    write (line, '(a,a,a,f0.1,a,es9.2)') "  ", trim(merge("banded Cholesky (dpbtrf)", "banded LU (dgbtrf)      ", &
                                                             solution%cholesky)), ", ", solution%band_megabytes, &
      " MB, smallest pivot ratio ", solution%pivot_ratio
    write (*, '(a)') trim(line)
    write (line, '(a,4(f0.3,a))') "  seconds: assembly ", solution%fe_assembly_s + solution%efg_assembly_s, &
      "  factorization ", solution%factor_s, "  solution ", solution%solve_s, "  stresses ", solution%recovery_s, ""
    write (*, '(a)') trim(line)
    write (line, '(a,es12.5,a,es12.5,a,es9.2)') "  strain energy ", solution%internal_energy, ", external work ", &
      solution%external_work, ", equilibrium residual ", solution%residual
    write (*, '(a)') trim(line)
  end subroutine report_static_solution
end module static_output
