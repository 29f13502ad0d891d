!> The explicit run, cycle after cycle: the physics of a cycle (solver/explicit_solver) with,
!> between cycles, the stop signals, the restart dumps (output/restart_control), the output
!> that is due (output/run_output) and the progress line. It starts at cycle 0 for a new run,
!> at the dump's cycle for a restart.
module explicit_run
  use kinds, only: wp
  use error_handling, only: error_t, make_error
  use model, only: model_t
  use explicit_state, only: explicit_state_t
  use run_state, only: run_state_t, phase_output
  use explicit_solver, only: start_run, advance_and_check, reached_end, check_distortion, summarise
  use run_output, only: write_due_output
  use results_file, only: results_file_t
  use run_summary, only: run_summary_t
  use restart_control, only: restart_control_t, write_due_dumps, resume_run
  use stop_signals, only: received_stop_signal, progress_line_requested, signal_name, signal_terminate
  use progress_report, only: start_progress, report_progress
  use wall_clock, only: start_phase, stop_phase
  use output_plan, only: clock_is_due
  use domain_exchange, only: gather_block_state, share_block_energies
  use rank_communication, only: any_rank
  implicit none
  private

  public :: run_explicit

contains

  !> Run from the run state's time to the end time (or end cycle): from cycle 0 for a new run.
  !> On a run-time error (inverted element, runaway motion, exploding energy, collapsing time
  !> step, a stop signal) the last state is written and `error` says what, where and when.
  subroutine run_explicit(model, run, results, summary, error, restart)
    type(model_t), intent(in) :: model
    type(run_state_t), intent(inout) :: run
    type(results_file_t), intent(inout) :: results
    type(run_summary_t), intent(inout) :: summary
    type(error_t), allocatable, intent(out) :: error
    type(restart_control_t), intent(inout) :: restart   !< the run's dumps; resuming: the dump it continues
    type(error_t), allocatable :: output_error
    logical :: finished, clean

    if (restart%resuming) then
      ! the run state at the end of the dump's cycle, before its output
      call resume_run(restart, model, run, error)
      if (allocated(error)) return
      finished = reached_end(model, run%state)
    else
      ! cycle 0: forces and accelerations of the initial state (unless its motion is already
      ! beyond any physical run, or mass scaling added more than ENDMAS allows)
      call start_run(model, run, error)
      finished = allocated(error) .or. model%end_time <= 0.0_wp .and. model%end_cycle <= 0
    end if
    call check_distortion(model, run, finished)
    call output(model, run, results, finished, output_error)
    call share_output_failure(output_error)
    if (allocated(output_error)) then
      finished = .true.
      if (.not. allocated(error)) call move_alloc(output_error, error)
    end if
    if (run%exchange%rank == 0) call start_progress(run%progress, model%end_time, model%end_cycle)

    do while (.not. finished)
      call advance_and_check(model, run, finished, error)
      clean = .not. allocated(error)
      if (clean) call check_stop_signal(run%state, error)
      finished = finished .or. allocated(error)
      ! restart dumps: the run state of this cycle before its output (none after a run-time
      ! error; a stop signal writes one and says where)
      if (clean) call write_due_dumps(restart, model, run, summary%setup_s, results, allocated(error), finished, error)
      call check_distortion(model, run, finished)
      call output(model, run, results, finished, output_error)
      call share_output_failure(output_error)
      if (allocated(output_error)) exit
      if (run%exchange%rank == 0) &
        call report_progress(run%progress, run%state%cycle, run%state%time, run%state%time_step, &
                             finished .or. progress_line_requested())
    end do

    if (allocated(output_error) .and. .not. allocated(error)) call move_alloc(output_error, error)
    call summarise(model, run, summary)
  end subroutine run_explicit

  !> A SIGINT or SIGTERM ends the run after the cycle: the state is written and the run ends
  !> with error termination.
  subroutine check_stop_signal(state, error)
    type(explicit_state_t), intent(in) :: state
    type(error_t), allocatable, intent(out) :: error
    character(len=40) :: text
    integer :: number
    number = received_stop_signal()
    ! (every rank stops after the same cycle; mpirun passes a signal to all, not at one instant)
    if (.not. any_rank(number /= 0)) return
    if (number == 0) number = signal_terminate
    write (text, '(es12.5,a,i0)') state%time, ", cycle ", state%cycle
    call make_error(error, "stopped by "//signal_name(number)//" at time "//trim(adjustl(text))// &
                    ": the results hold the run up to this time")
  end subroutine check_stop_signal

  subroutine output(model, run, results, last, error)
    type(model_t), intent(in) :: model
    type(run_state_t), intent(inout) :: run
    type(results_file_t), intent(inout) :: results
    logical, intent(in) :: last
    type(error_t), allocatable, intent(out) :: error
    call start_phase(run%timers(phase_output))
    ! the blocks' energy sums for the histories and the states' globals; a distributed run: the
    ! blocks' state to the first rank, which writes the states (and all of it at the end: d3hsp,
    ! the summary)
    if (last .or. clock_is_due(run%plan%states, run%state%time, last) .or. &
        clock_is_due(run%plan%glstat, run%state%time, last) .or. clock_is_due(run%plan%matsum, run%state%time, last)) &
      call share_block_energies(run%state%groups, run%partition, run%exchange, run%state%cycle)
    if (last .or. clock_is_due(run%plan%states, run%state%time, last)) &
      call gather_block_state(run%state%groups, run%partition, run%exchange, run%state%cycle)
    call write_due_output(model, run%state, run%plan, run%histories, run%energy_scratch, results, last, error)
    call stop_phase(run%timers(phase_output))
  end subroutine output

  !> Only the first rank writes files: a failure there ends the run on every rank.
  subroutine share_output_failure(error)
    type(error_t), allocatable, intent(inout) :: error
    if (any_rank(allocated(error)) .and. .not. allocated(error)) &
      call make_error(error, "the first rank could not write the output")
  end subroutine share_output_failure
end module explicit_run
