!> One crashfree job: read and check the deck, set up, run, write results, summarise. A deck with
!> *CONTROL_IMPLICIT_GENERAL IMFLAG 1 runs the linear static analysis instead of the explicit
!> set-up and time loop (same results file, one state at the end time).
!>
!> Exit status: 0 normal termination; 1 error termination during the run (results up to that
!> point are written); 2 the deck or the command line was rejected (nothing is run).
module job
  use kinds, only: wp
  use command_line, only: run_options_t
  use error_handling, only: error_t, error_list_t
  use model, only: model_t, formulation_efg
  use deck_reader, only: read_deck
  use explicit_state, only: explicit_state_t
  use run_state, only: run_state_t, phase_internal_forces, phase_contact
  use explicit_setup, only: set_up_run_state, set_up_warnings
  use explicit_run, only: run_explicit
  use domain_partition, only: domain_partition_t, partition_domains, partition_text
  use static_analysis, only: run_static
  use results_file, only: results_file_t, open_results, close_results
  use run_summary, only: run_summary_t, status_normal, status_error
  use wall_clock, only: seconds_now
  use file_system, only: make_directory
  use progress_report, only: format_duration
  use version, only: crashfree_version
  use stop_signals, only: catch_stop_signals
  use deck_signature, only: deck_source_t
  use ascii_databases, only: write_ascii_databases
  use ascii_run_summary, only: write_d3hsp, write_messag
  use restart_control, only: restart_control_t, prepare_restart, check_restart_deck, set_up_restart_control, &
                             continue_restart_results, count_earlier_run
  use rank_communication, only: rank_index, rank_total, any_rank
  use text_format, only: integer_text
  use, intrinsic :: iso_fortran_env, only: error_unit, output_unit, int64
  !$ use omp_lib, only: omp_set_num_threads, omp_get_max_threads
  implicit none
  private

  public :: run_job

contains

  subroutine run_job(options, exit_status)
    type(run_options_t), intent(in) :: options
    integer, intent(out) :: exit_status
    type(run_options_t) :: settings
    type(restart_control_t) :: restart
    type(deck_source_t), allocatable :: sources(:)
    type(model_t) :: model
    type(run_state_t) :: run
    type(results_file_t) :: results
    type(run_summary_t) :: summary
    type(domain_partition_t) :: partition
    type(error_list_t) :: warnings
    type(error_t), allocatable :: error, close_error, ascii_error
    character(len=:), allocatable :: warning_text
    character(len=:), allocatable :: messages    !< every warning and error printed (messag)
    character(len=:), allocatable :: warning_lines   !< the warnings among them (/run/warnings)
    logical :: output_ready
    logical :: first_rank    !< a distributed run: only the first rank prints and writes files
    real(wp) :: started

    started = seconds_now()
    exit_status = 2
    messages = ""
    warning_lines = ""
    output_ready = .false.
    first_rank = rank_index() == 0
    ! r=: the deck, output directory and job of the dump unless given
    settings = options
    if (allocated(settings%restart_file)) &
      call prepare_restart(restart, settings%restart_file, settings%deck, settings%output_dir, settings%job_id, error)
    if (allocated(error)) then
      call report("crashfree: "//error%message, messages)
      return
    end if
    summary%threads = select_threads(settings%threads)
    if (first_rank .and. rank_total() > 1) then
      write (*, '(a)') "crashfree "//crashfree_version//": "//settings%deck//" on "//trim(count_text(rank_total()))// &
        " MPI ranks of "//trim(count_text(summary%threads))//" thread(s)"
    else if (first_rank) then
      write (*, '(a)') "crashfree "//crashfree_version//": "//settings%deck//" on "//trim(count_text(summary%threads))// &
        " thread(s)"
    end if
    flush (output_unit)

    call read_deck(settings%deck, model, warnings, error, settings%ignore_unknown, sources)
    if (warnings%count > 0) then
      call report(warnings%text, messages)
      warning_lines = warning_lines//warnings%text//new_line("a")
    end if
    if (allocated(error)) then
      call report(error%message, messages)
      call report("crashfree: the deck was rejected; nothing was run", messages)
      return
    end if
    if (restart%resuming) call check_restart_deck(restart, settings%deck, sources, error)
    if (model%implicit_static .and. rank_total() > 1 .and. .not. allocated(error)) then
      call report("crashfree: the deck asks for the linear static analysis (*CONTROL_IMPLICIT_GENERAL), which "// &
                  "runs on one rank: run it without mpirun", messages)
      return
    end if
    if (.not. (model%implicit_static .or. allocated(error))) call set_up_run_state(model, run, error)
    if (allocated(error)) then
      call report("crashfree: "//error%message, messages)
      return
    end if
    ! partition=N: the domain partition for N ranks, then stop after the set-up
    if (settings%partition_ranks > 0) then
      if (model%implicit_static) then
        call report("crashfree: partition="//trim(count_text(settings%partition_ranks))//": the deck asks for "// &
                    "the linear static analysis (*CONTROL_IMPLICIT_GENERAL), which runs on one rank", messages)
        return
      end if
      call partition_domains(model, run%state%groups, settings%partition_ranks, 0, partition, error)
      if (allocated(error)) then
        call report("crashfree: "//error%message, messages)
        return
      end if
      summary%partition = partition%report
    else if (rank_total() > 1 .and. .not. model%implicit_static) then
      ! a distributed run: the partition its set-up made
      summary%partition = run%partition%report
    end if
    ! (the first rank writes every file; the others wait for it to say whether it could)
    if (first_rank) call make_directory(settings%output_dir, error)
    if (allocated(error)) then
      call report("crashfree: "//error%message, messages)
    else if (first_rank .and. restart%resuming) then
      call continue_restart_results(restart, results, settings%output_dir, settings%job_id, model, summary%threads, &
                                    error, d3plot_scale=settings%binary_file_scale)
      if (allocated(error)) call report("crashfree: "//error%message, messages)
    else if (first_rank) then
      call open_results(results, settings%output_dir, settings%job_id, model, summary%threads, error, &
                        d3plot_scale=settings%binary_file_scale)
      if (allocated(error)) call report("crashfree: "//error%message, messages)
    end if
    if (any_rank(allocated(error))) return
    output_ready = first_rank
    if (first_rank .and. .not. model%implicit_static) then
      call describe_model(model, run%state, summary)
      flush (output_unit)
      if (summary%partition%rank_count > 1) write (*, '(a)', advance="no") partition_text(summary%partition)
    end if
    if (.not. model%implicit_static) then
      warning_text = set_up_warnings(model, run%state)
      if (len(warning_text) > 0) then
        call report(warning_text, messages)
        warning_lines = warning_lines//warning_text//new_line("a")
      end if
    end if
    summary%setup_s = seconds_now() - started

    if (model%implicit_static) then
      call run_static(model, results, summary, error)
    else if (settings%partition_ranks > 0) then
      write (*, '(a)') "partition="//trim(count_text(settings%partition_ranks))// &
        ": the partition only (results.h5 /run/partition, d3hsp); nothing was run"
    else
      ! from here on SIGINT / SIGTERM end the run after a cycle, with the results written (before,
      ! while the deck is read and the model set up, they end the process at once: nothing has
      ! been written yet, and a previous results file of the job is still whole)
      call catch_stop_signals()
      call set_up_restart_control(restart, model, settings%output_dir, settings%job_id, settings%deck, sources, &
                                  started)
      call run_explicit(model, run, results, summary, error, restart)
      ! what the run printed while it went (already on the terminal): all of it into messag, its
      ! warnings into /run/warnings as well
      if (allocated(run%state%messages%text)) then
        messages = messages//run%state%messages%text
        warning_lines = warning_lines//warnings_among(run%state%messages%text)
      end if
    end if

    summary%wall_s = seconds_now() - started
    if (restart%resuming) call count_earlier_run(restart, summary)
    if (allocated(error)) then
      summary%status = status_error
      summary%message = error%message
      exit_status = 1
    else
      summary%status = status_normal
      summary%message = ""
      exit_status = 0
    end if
    summary%warnings = warning_lines
    ! the other ranks of a distributed run are done: the first writes and prints what follows
    if (.not. first_rank) return
    ! LS-DYNA's ASCII files the deck asks for, from the histories of the whole run, and d3hsp
    if (.not. model%implicit_static) then
      call write_ascii_databases(model, run%histories, settings%output_dir, settings%job_id, ascii_error)
      if (.not. allocated(ascii_error)) &
        call write_d3hsp(model, run%state, run%histories, initial_time_steps(run), summary, settings%output_dir, &
                         settings%job_id, ascii_error, sources)
    end if
    if (allocated(ascii_error)) exit_status = 1
    call close_results(results, summary, close_error)
    if (allocated(close_error)) exit_status = 1
    call print_summary(summary, settings, model%implicit_static)
    if (run%exchange%rank_count > 1) call print_exchange_summary(run, summary)
    flush (output_unit)
    if (allocated(error)) call report("crashfree: error termination: "//error%message, messages)
    ! last: what the results file holds after a failed write
    if (allocated(close_error)) call report("crashfree: "//close_error%message, messages)
    if (allocated(ascii_error)) call report("crashfree: "//ascii_error%message, messages)
    if (output_ready) then
      call write_messag(settings%output_dir, settings%job_id, messages, summary, ascii_error)
      if (allocated(ascii_error)) then
        exit_status = max(exit_status, 1)
        call report("crashfree: "//ascii_error%message, messages)
      end if
    end if
  end subroutine run_job

  !> The d3hsp time step table the output recorded at cycle 0 ("" when it was not: a restart).
  function initial_time_steps(run) result(text)
    type(run_state_t), intent(in) :: run
    character(len=:), allocatable :: text
    text = ""
    if (allocated(run%plan%initial_time_steps)) text = run%plan%initial_time_steps
  end function initial_time_steps

  !> Print a warning or error on the terminal (standard error) after what standard output
  !> holds so far, so that a log of both reads in the order things happened, and keep it for
  !> messag.
  !> The lines of `text` (each ended by a new line) that are warnings.
  function warnings_among(text) result(lines)
    character(len=*), intent(in) :: text
    character(len=:), allocatable :: lines
    integer :: start, finish
    lines = ""
    start = 1
    do while (start <= len(text))
      finish = index(text(start:), new_line("a")) + start - 1
      if (finish < start) finish = len(text) + 1
      if (index(text(start:finish - 1), "warning") == 1) lines = lines//text(start:finish - 1)//new_line("a")
      start = finish + 1
    end do
  end function warnings_among

  subroutine report(text, messages)
    character(len=*), intent(in) :: text
    character(len=:), allocatable, intent(inout) :: messages
    ! (every rank of a distributed run reads the same deck and meets the same errors: the first
    ! says so)
    if (rank_index() == 0) then
      flush (output_unit)
      write (error_unit, '(a)') text
      flush (error_unit)
    end if
    messages = messages//text//new_line("a")
  end subroutine report

  !> ncpu=, else OMP_NUM_THREADS (the OpenMP runtime reads it), else all cores; at most the
  !> processors this process may run on (a typing slip such as ncpu=1000 would otherwise run
  !> many times slower), with a warning naming both numbers. CRASHFREE_OVERSUBSCRIBE=1 lifts
  !> the limit, for tests that compare results on more threads than the machine has.
  integer function select_threads(requested)
    !$ use omp_lib, only: omp_get_num_procs
    integer, intent(in) :: requested
    character(len=32) :: setting
    integer :: wanted, processors, length, status
    select_threads = 1
    wanted = 1
    processors = 1
    !$ wanted = requested
    !$ if (wanted <= 0) wanted = omp_get_max_threads()
    !$ processors = omp_get_num_procs()
    if (wanted > processors) then
      call get_environment_variable("CRASHFREE_OVERSUBSCRIBE", setting, length, status)
      if (status /= 0 .or. trim(setting) /= "1") then
        if (requested > 0) then
          write (error_unit, '(a)') "crashfree: warning: ncpu="//trim(count_text(requested))// &
            " is more than the "//trim(count_text(processors))//" processors available; "// &
            "running on "//trim(count_text(processors))//" threads"
        else
          call get_environment_variable("OMP_NUM_THREADS", setting, length, status)
          write (error_unit, '(a)') "crashfree: warning: OMP_NUM_THREADS="//trim(setting)// &
            " is more than the "//trim(count_text(processors))//" processors available; "// &
            "running on "//trim(count_text(processors))//" threads"
        end if
        wanted = processors
      end if
    end if
    !$ call omp_set_num_threads(wanted)
    !$ select_threads = omp_get_max_threads()
  end function select_threads

  subroutine describe_model(model, state, summary)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    type(run_summary_t), intent(inout) :: summary
    character(len=200) :: line
    integer :: k
    do k = 1, size(state%groups)
      call state%groups(k)%group%add_to_summary(summary)
    end do
    summary%fe_elements = summary%fe_solids + summary%fe_shells + summary%fe_beams
    summary%dofs_total = 3*size(model%node_ids) + 3*count(state%nodes%rotary_inertia > 0.0_wp)
    write (line, '(a,i0,a,i0,a,i0,a,i0,a)') "model: ", size(model%node_ids), " nodes, ", size(model%solid_ids), &
      " solids, ", size(model%shell_ids), " shells in ", size(model%parts), " parts"
    write (*, '(a)') trim(line)
    if (summary%fe_beams > 0) then
      write (line, '(a,i0,a)') "beams: ", summary%fe_beams, " (Hughes-Liu and spot weld beams)"
      write (*, '(a)') trim(line)
    end if
    write (line, '(a,es12.5)') "mass: ", state%physical_mass
    write (*, '(a)') trim(line)
    if (summary%dofs_efg > 0) then
      write (line, '(a,i0,a,i0,a,f0.1,a,f0.3,a)') "meshfree: ", count(model%parts%formulation == formulation_efg), &
        " EFG part(s), ", &
        summary%efg_particles, " interior particles, ", 100.0_wp*real(summary%dofs_efg, wp)/real(summary%dofs_total, wp), &
        "% of the dofs; set-up ", summary%efg_setup_s, " s"
      write (*, '(a)') trim(line)
    end if
    if (summary%efg_shell_cells > 0) then
      write (line, '(a,i0,a,i0,a,f0.1,a,f0.3,a)') "meshfree shells: ", summary%efg_shell_cells, " cells, ", &
        summary%efg_shell_particles, " interior particles, ", &
        100.0_wp*real(summary%dofs_efg_shell, wp)/real(summary%dofs_total, wp), "% of the dofs; set-up ", &
        summary%efg_shell_setup_s, " s"
      write (*, '(a)') trim(line)
    end if
    if (state%added_mass > 0.0_wp) then
      ! (es: the percentage of a huge DT2MS does not fit a fixed format)
      write (line, '(a,es12.5,a,es10.3,a)') "mass scaling: added mass ", state%added_mass, " (", &
        100.0_wp*state%added_mass/state%physical_mass, " % of the physical mass)"
      write (*, '(a)') trim(line)
    end if
  end subroutine describe_model

  !> The end-of-run summary; the cost per element and cycle only for explicit runs (a static
  !> analysis reports its own phases).
  subroutine print_summary(summary, options, static)
    type(run_summary_t), intent(in) :: summary
    type(run_options_t), intent(in) :: options
    logical, intent(in) :: static
    character(len=200) :: line
    real(wp) :: per_element
    write (*, '(a)') ""
    write (*, '(a)') summary%status
    write (line, '(a,i0,a,es12.5,a)') "  ", summary%cycles, " cycles to time ", summary%end_time, &
      ", wall time "//format_duration(summary%wall_s)
    write (*, '(a)') trim(line)
    write (line, '(a,f9.3,a,f9.3,a,f9.3,a,f9.3,a,f9.3,a,f9.3,a,f9.3)') "  seconds: setup", summary%setup_s, &
      "  solids", summary%fe_solid_s, "  shells", summary%fe_shell_s, "  meshfree", summary%efg_s + summary%efg_shell_s, &
      "  contact", &
      summary%contact_s, "  output", summary%output_s, "  other", &
      max(0.0_wp, summary%wall_s - summary%setup_s - summary%fe_solid_s - summary%fe_shell_s - summary%efg_s &
          - summary%efg_shell_s - summary%contact_s - summary%output_s - summary%fe_beam_s)
    write (*, '(a)') trim(line)
    if (.not. static .and. summary%cycles > 0 .and. summary%fe_solids > 0) then
      per_element = 1.0e9_wp*summary%fe_solid_s/(real(summary%cycles, wp)*real(summary%fe_solids, wp))
      write (line, '(a,f0.1,a)') "  solid elements: ", per_element, " ns per element per cycle"
      write (*, '(a)') trim(line)
    end if
    if (.not. static .and. summary%cycles > 0 .and. summary%fe_shells > 0) then
      per_element = 1.0e9_wp*summary%fe_shell_s/(real(summary%cycles, wp)*real(summary%fe_shells, wp))
      write (line, '(a,f0.1,a)') "  shell elements: ", per_element, " ns per element per cycle"
      write (*, '(a)') trim(line)
    end if
    if (.not. static .and. summary%cycles > 0 .and. summary%fe_beams > 0) then
      per_element = 1.0e9_wp*summary%fe_beam_s/(real(summary%cycles, wp)*real(summary%fe_beams, wp))
      write (line, '(a,f0.1,a,i0,a)') "  beam elements: ", per_element, " ns per element per cycle; ", &
        summary%failed_beams, " failed"
      write (*, '(a)') trim(line)
    end if
    if (.not. static .and. summary%cycles > 0 .and. summary%efg_particles > 0) then
      per_element = 1.0e9_wp*summary%efg_s/(real(summary%cycles, wp)*real(summary%efg_particles, wp))
      write (line, '(a,f0.1,a)') "  meshfree: ", per_element, " ns per interior particle per cycle"
      write (*, '(a)') trim(line)
    end if
    if (.not. static .and. summary%cycles > 0 .and. summary%efg_shell_cells > 0) then
      per_element = 1.0e9_wp*summary%efg_shell_s/(real(summary%cycles, wp)*real(summary%efg_shell_cells, wp))
      write (line, '(a,f0.1,a)') "  meshfree shells: ", per_element, " ns per cell per cycle"
      write (*, '(a)') trim(line)
    end if
    write (*, '(a)') "  results: "//options%output_dir//"/"//options%job_id//".h5 (and .xdmf for ParaView)"
  end subroutine print_summary

  !> A distributed run: the seconds of the exchanges among the ranks (the first rank's), per
  !> cycle, and the forces' volume.
  subroutine print_exchange_summary(run, summary)
    type(run_state_t), intent(in) :: run
    type(run_summary_t), intent(in) :: summary
    character(len=240) :: line
    character(len=:), allocatable :: counts
    real(wp) :: per_cycle
    integer :: r, cycles
    cycles = summary%cycles
    per_cycle = 1.0e3_wp/real(max(1, cycles), wp)
    write (line, '(a,i0,a,f0.3,a,f0.1,a,f0.3,a)') "  MPI: ", run%exchange%rank_count, &
      " ranks; nodal exchange (accelerations) ", per_cycle*run%exchange%timer%seconds, " ms per cycle (", &
      8.0e-3_wp*real(size(run%exchange%receive), wp), " kB to each rank), waiting for the slowest rank ", &
      per_cycle*run%exchange%wait_timer%seconds, " ms per cycle"
    write (*, '(a)') trim(line)
    write (line, '(a,i0,a,i0,a,i0,a,f0.3,a,f0.1,a)') "  MPI: block state gathered to the first rank ", &
      run%exchange%block_gathers, " times (states, dumps, the end), to every rank ", run%exchange%block_shares, &
      " times (erosion); the blocks' energy sums shared ", run%exchange%energy_shares, " times: ", &
      run%exchange%gather_timer%seconds, " s, ", 8.0e-6_wp*run%exchange%gathered_values, " MB received by the first rank"
    write (*, '(a)') trim(line)
    ! every rank's seconds: where the balance is lost
    if (allocated(summary%rank_seconds)) then
      write (*, '(a)') "  MPI: seconds per rank   internal forces    contact   nodal exchange    waiting   all phases"
      associate (seconds => summary%rank_seconds)
        do r = 1, size(seconds, 2)
          ! (the last two columns, the pair exchange and its wait, lie inside the contact phase)
          write (line, '(i22,5f11.3)') r - 1, seconds(phase_internal_forces, r), seconds(phase_contact, r), &
            seconds(size(seconds, 1) - 3, r), seconds(size(seconds, 1) - 2, r), sum(seconds(1:size(seconds, 1) - 2, r))
          write (*, '(a)') trim(line)
        end do
      end associate
    end if
    if (size(run%state%contacts) == 0) return
    write (line, '(a,f0.3,a,f0.1,a,f0.3,a)') "  MPI: contact pair exchange ", &
      per_cycle*run%exchange%contact_timer%seconds, " ms per cycle (", &
      8.0e-3_wp*run%exchange%pair_values/real(max(1, cycles), wp), " kB to each rank per cycle), waiting for the "// &
      "rank with the most pairs ", per_cycle*run%exchange%contact_wait_timer%seconds, " ms per cycle"
    write (*, '(a)') trim(line)
    ! how evenly the ranks shared the pairs (a record: a node with a pair, a depth or an
    ! ignored initial penetration, in one cycle)
    counts = "  MPI: contact pair records sent per rank over the run:"
    do r = 1, size(run%exchange%rank_pair_records)
      counts = counts//" "//integer_text(nint(run%exchange%rank_pair_records(r), int64))
    end do
    write (*, '(a)') counts
  end subroutine print_exchange_summary

  function count_text(value) result(text)
    integer, intent(in) :: value
    character(len=16) :: text
    write (text, '(i0)') value
  end function count_text
end module job
