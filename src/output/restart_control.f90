!> Restart dumps as LS-DYNA users know them: when they are written, under which names, and how
!> `r=` continues a run from one.
!>
!> Dumps (HDF5, restart_file; content: run_state_dump):
!> - `DIR/d3dump01`, `d3dump02`, ... every CYCL cycles of *DATABASE_BINARY_D3DUMP (a family
!>   that grows), and `DIR/runrsf` every CYCL cycles of *DATABASE_BINARY_RUNRSF (overwritten;
!>   with NR > 1 `runrsf01` .. `runrsfNR` written in turn). With `jobid=NAME` the names are
!>   `NAME.d3dump01`, `NAME.runrsf`.
!> - The sense switches: SIGINT / SIGTERM end the run after the cycle with a dump (LS-DYNA's
!>   sw1), SIGUSR1 writes a dump and the run goes on (sw3); both dumps join the d3dump family.
!> - A dump is taken at the end of a cycle, before that cycle's output, and never at the last
!>   cycle of a run that reached its end. It holds the run's state, its header (version, deck
!>   signature, time, cycle, why it was written) and the list of the deck's files with their
!>   signatures. A dump that cannot be written (full disk, a deck file changed since the run
!>   read it) is reported and the run goes on.
!>
!> Restart (`r=FILE`): the deck is read again from its recorded path (or `i=`), and every file
!> it reads must hold the bytes it held when the dump was written; the dump must come from this
!> crashfree version. The model is set up from the deck, the state read from the dump, the
!> results file of the interrupted run continued (results_file's continue_results) and the time
!> loop resumes at the dump's cycle. Defaults: `outdir=` the dump's directory, `jobid=` the
!> dump's job.
module restart_control
  use, intrinsic :: iso_c_binding, only: c_char, c_null_char, c_size_t, c_ptr, c_associated
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
  use kinds, only: wp
  use text_format, only: integer_text
  use error_handling, only: error_t, make_error
  use version, only: crashfree_version
  use model, only: model_t
  use run_state, only: run_state_t
  use history_buffer, only: history_set_t
  use results_file, only: results_file_t, continue_results
  use run_summary, only: run_summary_t
  use deck_signature, only: deck_source_t, sign_deck_files
  use restart_file, only: restart_store_t, create_restart_store, commit_restart_store, discard_restart_store, &
                          open_restart_store, close_restart_store, write_restart, read_restart, &
                          write_restart_attribute, read_restart_attribute
  use run_state_dump, only: exchange_run_state, exchange_results_progress, exchange_history_set
  use stop_signals, only: dump_requested, received_stop_signal, signal_name
  use domain_exchange, only: gather_block_state
  use rank_communication, only: any_rank
  use wall_clock, only: seconds_now
  implicit none
  private

  public :: restart_control_t, set_up_restart_control, write_due_dumps, prepare_restart, check_restart_deck, &
            continue_restart_results, resume_run, count_earlier_run

  !> Written into every dump and checked first: the file is a crashfree dump of this layout.
  character(len=*), parameter :: dump_format = "crashfree restart dump"
  integer, parameter :: dump_format_version = 1

  !> The dumps of a run and, for a restart, the dump it continues from.
  type :: restart_control_t
    ! schedule (*DATABASE_BINARY_D3DUMP, *DATABASE_BINARY_RUNRSF)
    integer :: dump_cycles = 0               !< CYCL of D3DUMP (0: only the sense switches' dumps)
    integer :: running_cycles = 0            !< CYCL of RUNRSF (0: none)
    integer :: running_files = 1             !< NR
    integer :: dump_number = 0               !< d3dump files written so far in the run (the family's last)
    integer :: running_number = 0            !< running restart files written so far
    character(len=:), allocatable :: directory, job_id
    ! the deck, for the dump's header
    character(len=:), allocatable :: deck_path        !< as given
    character(len=:), allocatable :: deck_absolute    !< from the directory the run started in
    type(deck_source_t), allocatable :: sources(:)
    character(len=:), allocatable :: deck_files       !< "hash size path" per file (signed at the first dump)
    character(len=:), allocatable :: deck_signature
    ! time spent: this run's start (seconds_now), and the earlier runs' up to the dump resumed
    real(wp) :: started = 0.0_wp
    real(wp) :: earlier_wall_s = 0.0_wp
    real(wp) :: earlier_setup_s = 0.0_wp
    ! restart
    logical :: resuming = .false.
    type(restart_store_t) :: source          !< the dump being resumed (open until resume_run)
    real(wp) :: source_time = 0.0_wp
    integer :: source_cycle = 0
  end type restart_control_t

  interface
    function c_getcwd(buffer, size) bind(c, name="getcwd") result(pointer)
      import :: c_char, c_size_t, c_ptr
      character(kind=c_char), intent(inout) :: buffer(*)
      integer(c_size_t), value :: size
      type(c_ptr) :: pointer
    end function c_getcwd
  end interface

contains

  !> The dump schedule of a run and what its dumps record: the output directory and job,
  !> the deck (as given, its files as the reader found them) and when the job started. For a
  !> restart (`control%resuming`) the counters and the deck come from the dump already.
  subroutine set_up_restart_control(control, model, directory, job_id, deck_path, sources, started)
    type(restart_control_t), intent(inout) :: control
    type(model_t), intent(in) :: model
    character(len=*), intent(in) :: directory, job_id, deck_path
    type(deck_source_t), intent(in) :: sources(:)
    real(wp), intent(in) :: started
    control%dump_cycles = model%output%dump_cycles
    control%running_cycles = model%output%running_restart_cycles
    control%running_files = max(1, model%output%running_restart_files)
    control%directory = directory
    control%job_id = job_id
    control%sources = sources
    control%started = started
    if (.not. control%resuming) then
      control%deck_path = deck_path
      control%deck_absolute = absolute_path(deck_path)
    end if
  end subroutine set_up_restart_control

  !> At the end of a cycle, before its output: the dumps due. `stopped`: the run ends on a
  !> SIGINT / SIGTERM (sw1; `error` holds its message, to which where the dump is gets
  !> added); `finished`: the run reached its end (no dump then). The periodic dumps go by the
  !> cycle number, so a restarted run writes them at the cycles the uninterrupted one did.
  subroutine write_due_dumps(control, model, run, setup_s, results, stopped, finished, error)
    type(restart_control_t), intent(inout) :: control
    type(model_t), intent(in) :: model
    type(run_state_t), intent(inout) :: run
    real(wp), intent(in) :: setup_s
    type(results_file_t), intent(inout) :: results
    logical, intent(in) :: stopped, finished
    type(error_t), allocatable, intent(inout) :: error
    character(len=:), allocatable :: path
    logical :: requested

    ! (a SIGUSR1 that reached one rank: all write, or rather bring their blocks to the first)
    requested = any_rank(dump_requested())
    if (stopped) then
      path = write_dump(dump_name(control, control%dump_number + 1), signal_name(received_stop_signal()), .false.)
      if (len(path) > 0) error%message = error%message//"; restart dump "//path//" written (bin/crashfree r="// &
                                         path//" continues the run)"
      return
    end if
    if (finished) return
    if (requested .or. (control%dump_cycles > 0 .and. mod(run%state%cycle, max(1, control%dump_cycles)) == 0)) &
      path = write_dump(dump_name(control, control%dump_number + 1), trim(merge("SIGUSR1", "d3dump ", requested)), &
                        .false.)
    if (control%running_cycles > 0 .and. mod(run%state%cycle, max(1, control%running_cycles)) == 0) &
      path = write_dump(running_name(control, mod(control%running_number, control%running_files) + 1), "runrsf", &
                        .true.)

  contains

    !> Write one dump (a d3dump, or with `running` a running restart file) and count it; its
    !> path, or "" after reporting why it could not be written.
    function write_dump(name, reason, running) result(written)
      character(len=*), intent(in) :: name, reason
      logical, intent(in) :: running
      character(len=:), allocatable :: written
      type(restart_store_t) :: store
      type(error_t), allocatable :: failure
      character(len=40) :: text
      written = ""
      ! a distributed run: the blocks from their owners, then the first rank writes the dump (the
      ! same file for any number of ranks; a run may continue from it on another number)
      call gather_block_state(run%state%groups, run%partition, run%exchange, run%state%cycle)
      if (run%exchange%rank /= 0) then
        written = name
        if (running) then
          control%running_number = control%running_number + 1
        else
          control%dump_number = control%dump_number + 1
        end if
        return
      end if
      call sign_deck(control, failure)
      if (.not. allocated(failure)) call create_restart_store(store, name, failure)
      if (.not. allocated(failure)) then
        call write_restart_attribute(store, "format", dump_format, failure)
        call write_restart_attribute(store, "format_version", dump_format_version, failure)
        call write_restart_attribute(store, "version", crashfree_version, failure)
        call write_restart_attribute(store, "reason", reason, failure)
        call write_restart_attribute(store, "time", run%state%time, failure)
        call write_restart_attribute(store, "cycle", run%state%cycle, failure)
        call write_restart_attribute(store, "deck", control%deck_path, failure)
        call write_restart_attribute(store, "deck_absolute", control%deck_absolute, failure)
        call write_restart_attribute(store, "deck_signature", control%deck_signature, failure)
        call write_restart_attribute(store, "job_id", control%job_id, failure)
        call write_restart_attribute(store, "dump_number", control%dump_number + merge(0, 1, running), failure)
        call write_restart_attribute(store, "running_number", control%running_number + merge(1, 0, running), failure)
        call write_restart_attribute(store, "wall_seconds", control%earlier_wall_s + seconds_now() - control%started, &
                                     failure)
        call write_restart_attribute(store, "setup_seconds", control%earlier_setup_s + setup_s, failure)
        call write_restart(store, "deck/files", control%deck_files, failure)
        call exchange_run_state(store, model, run, failure)
        call exchange_results_progress(store, "results", results, failure)
        if (allocated(failure)) then
          call discard_restart_store(store)
        else
          call commit_restart_store(store, failure)
        end if
      end if
      if (allocated(failure)) then
        flush (output_unit)   ! (after the progress lines printed so far, in a log of both)
        write (error_unit, '(a)') "crashfree: warning: no restart dump written at cycle "// &
          trim(integer_text(run%state%cycle))//": "//failure%message
        return
      end if
      written = name
      if (running) then
        control%running_number = control%running_number + 1
      else
        control%dump_number = control%dump_number + 1
      end if
      write (text, '(es12.5,a,i0)') run%state%time, ", cycle ", run%state%cycle
      write (output_unit, '(a)') "restart dump "//name//" at time "//trim(adjustl(text))//" ("//reason//")"
    end function write_dump
  end subroutine write_due_dumps

  !> Sign the deck's files once, at the first dump (a run without dumps never reads its deck
  !> twice): every file must still be the one the run read.
  subroutine sign_deck(control, error)
    type(restart_control_t), intent(inout) :: control
    type(error_t), allocatable, intent(out) :: error
    character(len=16), allocatable :: hashes(:)
    if (allocated(control%deck_signature)) return
    call sign_deck_files(control%sources, hashes, error)
    if (allocated(error)) then
      error%message = error%message//" (a restart reads the deck again, and this dump could not be checked "// &
                      "against it)"
      return
    end if
    control%deck_files = files_text(control%sources, hashes)
    control%deck_signature = combined_signature(hashes)
  end subroutine sign_deck

  ! ---------------------------------------------------------------------------------------------
  ! Restart

  !> Open the dump `path` and read its header: it must be a crashfree dump of this version.
  !> `deck`, `directory`, `job_id` not given (unallocated) are taken from it: the deck from its
  !> recorded path, the output directory the dump's own, the job the dump's.
  subroutine prepare_restart(control, path, deck, directory, job_id, error)
    type(restart_control_t), intent(inout) :: control
    character(len=*), intent(in) :: path
    character(len=:), allocatable, intent(inout) :: deck, directory, job_id
    type(error_t), allocatable, intent(out) :: error
    character(len=:), allocatable :: format, written_by, recorded_job
    integer :: format_version
    logical :: exists

    call open_restart_store(control%source, path, error)
    if (allocated(error)) return
    call read_restart_attribute(control%source, "format", format, error)
    if (allocated(error)) then
      error%message = "restart file "//path//" is not a crashfree restart dump (no format attribute)"
      call close_restart_store(control%source)
      return
    end if
    if (format /= dump_format) then
      call make_error(error, "restart file "//path//" is not a crashfree restart dump (format '"//format//"')")
      call close_restart_store(control%source)
      return
    end if
    format_version = 0
    call read_restart_attribute(control%source, "format_version", format_version, error)
    call read_restart_attribute(control%source, "version", written_by, error)
    if (.not. allocated(error) .and. (written_by /= crashfree_version .or. format_version /= dump_format_version)) &
      call make_error(error, "restart dump "//path//" was written by crashfree "//written_by//"; this is crashfree "// &
                      crashfree_version//", which reads only its own dumps (their content follows the solver's "// &
                      "state): continue the run with crashfree "//written_by)
    call read_restart_attribute(control%source, "time", control%source_time, error)
    call read_restart_attribute(control%source, "cycle", control%source_cycle, error)
    call read_restart_attribute(control%source, "deck", control%deck_path, error)
    call read_restart_attribute(control%source, "deck_absolute", control%deck_absolute, error)
    call read_restart_attribute(control%source, "deck_signature", control%deck_signature, error)
    call read_restart_attribute(control%source, "job_id", recorded_job, error)
    call read_restart_attribute(control%source, "dump_number", control%dump_number, error)
    call read_restart_attribute(control%source, "running_number", control%running_number, error)
    call read_restart_attribute(control%source, "wall_seconds", control%earlier_wall_s, error)
    call read_restart_attribute(control%source, "setup_seconds", control%earlier_setup_s, error)
    call read_restart(control%source, "deck/files", control%deck_files, error)
    if (allocated(error)) then
      call close_restart_store(control%source)
      return
    end if
    control%resuming = .true.
    if (.not. allocated(deck)) then
      deck = control%deck_absolute
      inquire (file=deck, exist=exists)
      if (.not. exists) deck = control%deck_path
    end if
    if (.not. allocated(directory)) directory = directory_of(path)
    if (.not. allocated(job_id)) job_id = recorded_job
  end subroutine prepare_restart

  !> The deck read for a restart must be the dump's: the same files with the same bytes.
  subroutine check_restart_deck(control, deck, sources, error)
    type(restart_control_t), intent(inout) :: control
    character(len=*), intent(in) :: deck
    type(deck_source_t), intent(in) :: sources(:)
    type(error_t), allocatable, intent(out) :: error
    character(len=16), allocatable :: hashes(:)
    character(len=:), allocatable :: now, recorded_line, current_line
    integer :: k, recorded_count

    ! the hashes only: the paths may differ (the deck given relative to another directory)
    call sign_deck_files(sources, hashes, error)
    if (allocated(error)) return
    if (combined_signature(hashes) == control%deck_signature) return
    now = files_text(sources, hashes)
    recorded_count = line_count(control%deck_files)
    do k = 1, min(size(sources), recorded_count)
      recorded_line = line_of(control%deck_files, k)
      current_line = line_of(now, k)
      if (recorded_line(1:min(16, len(recorded_line))) /= current_line(1:min(16, len(current_line)))) exit
    end do
    if (k > min(size(sources), recorded_count)) then
      call make_error(error, "the deck "//deck//" is not the one restart dump "//control%source%path// &
                      " was written with: it reads "//integer_text(size(sources))//" file(s), the dump's run read "// &
                      integer_text(recorded_count)//" (a restart continues the same model: restore the deck)")
    else
      call make_error(error, "the deck "//deck//" is not the one restart dump "//control%source%path// &
                      " was written with: "//file_of(current_line)//" has changed since (signature "// &
                      current_line(1:16)//", the dump's "//recorded_line(1:16)//"; a restart continues the same "// &
                      "model: restore the deck, or start the run again)")
    end if
  end subroutine check_restart_deck

  !> Continue the results file of the interrupted run (see results_file's continue_results).
  subroutine continue_restart_results(control, results, directory, job_id, model, threads, error, d3plot_scale)
    type(restart_control_t), intent(inout) :: control
    type(results_file_t), intent(inout) :: results
    character(len=*), intent(in) :: directory, job_id
    type(model_t), intent(in) :: model
    integer, intent(in) :: threads
    type(error_t), allocatable, intent(out) :: error
    integer, intent(in), optional :: d3plot_scale   !< d3plot family file size (x=), see open_results
    type(history_set_t) :: histories
    call exchange_results_progress(control%source, "results", results, error)
    call exchange_history_set(control%source, "histories", histories, error)
    if (allocated(error)) return
    call continue_results(results, directory, job_id, model, threads, histories, control%source%path, error, &
                          d3plot_scale)
  end subroutine continue_restart_results

  !> Read the run state from the dump into the run state that the deck built, and close the dump.
  subroutine resume_run(control, model, run, error)
    type(restart_control_t), intent(inout) :: control
    type(model_t), intent(in) :: model
    type(run_state_t), intent(inout) :: run
    type(error_t), allocatable, intent(out) :: error
    character(len=60) :: text
    call exchange_run_state(control%source, model, run, error)
    call close_restart_store(control%source)
    if (allocated(error)) return
    write (text, '(es12.5,a,i0)') run%state%time, ", cycle ", run%state%cycle
    if (run%exchange%rank == 0) &
      write (output_unit, '(a)') "continuing from restart dump "//control%source%path//" at time "//trim(adjustl(text))
  end subroutine resume_run

  !> A restarted run's wall and set-up time include the earlier runs' up to the dump.
  subroutine count_earlier_run(control, summary)
    type(restart_control_t), intent(in) :: control
    type(run_summary_t), intent(inout) :: summary
    summary%wall_s = summary%wall_s + control%earlier_wall_s
    summary%setup_s = summary%setup_s + control%earlier_setup_s
  end subroutine count_earlier_run

  ! ---------------------------------------------------------------------------------------------
  ! Names

  !> DIR/d3dumpNN, or DIR/NAME.d3dumpNN for a job other than the default "results".
  function dump_name(control, number) result(name)
    type(restart_control_t), intent(in) :: control
    integer, intent(in) :: number
    character(len=:), allocatable :: name
    name = join_path(control%directory, job_prefix(control%job_id)//"d3dump"//two_digits(number))
  end function dump_name

  !> DIR/runrsf (NR = 1) or DIR/runrsfNN (NR > 1), with NAME. before it as for the dumps.
  function running_name(control, number) result(name)
    type(restart_control_t), intent(in) :: control
    integer, intent(in) :: number
    character(len=:), allocatable :: name
    if (control%running_files > 1) then
      name = join_path(control%directory, job_prefix(control%job_id)//"runrsf"//two_digits(number))
    else
      name = join_path(control%directory, job_prefix(control%job_id)//"runrsf")
    end if
  end function running_name

  pure function job_prefix(job_id) result(prefix)
    character(len=*), intent(in) :: job_id
    character(len=:), allocatable :: prefix
    prefix = ""
    if (job_id /= "results") prefix = job_id//"."
  end function job_prefix

  pure function two_digits(number) result(text)
    integer, intent(in) :: number
    character(len=:), allocatable :: text
    character(len=16) :: buffer
    write (buffer, '(i2.2)') number
    if (number > 99) write (buffer, '(i0)') number
    text = trim(buffer)
  end function two_digits

  pure function join_path(directory, name) result(path)
    character(len=*), intent(in) :: directory, name
    character(len=:), allocatable :: path
    integer :: length
    length = len_trim(directory)
    if (length == 0) then
      path = name
    else if (directory(length:length) == "/") then
      path = directory(1:length)//name
    else
      path = directory(1:length)//"/"//name
    end if
  end function join_path

  !> The directory part of a path ("." for a bare name).
  pure function directory_of(path) result(directory)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: directory
    integer :: slash
    slash = index(path, "/", back=.true.)
    if (slash == 0) then
      directory = "."
    else if (slash == 1) then
      directory = "/"
    else
      directory = path(1:slash - 1)
    end if
  end function directory_of

  !> `path` from the root: relative paths are taken from the current directory.
  function absolute_path(path) result(absolute)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: absolute
    character(kind=c_char, len=1) :: buffer(4096)
    character(len=:), allocatable :: directory
    integer :: length
    absolute = path
    if (len(path) == 0) return
    if (path(1:1) == "/") return
    if (.not. c_associated(c_getcwd(buffer, int(size(buffer), c_size_t)))) return
    length = 0
    do while (length < size(buffer))
      if (buffer(length + 1) == c_null_char) exit
      length = length + 1
    end do
    allocate (character(len=length) :: directory)
    do length = 1, len(directory)
      directory(length:length) = buffer(length)
    end do
    absolute = join_path(directory, path)
  end function absolute_path

  ! ---------------------------------------------------------------------------------------------
  ! The deck's files

  !> One line per file: "hash size path".
  function files_text(sources, hashes) result(text)
    type(deck_source_t), intent(in) :: sources(:)
    character(len=16), intent(in) :: hashes(:)
    character(len=:), allocatable :: text
    character(len=24) :: size_text
    integer :: k
    text = ""
    do k = 1, size(sources)
      write (size_text, '(i0)') sources(k)%size
      if (k > 1) text = text//new_line("a")
      text = text//hashes(k)//" "//trim(size_text)//" "//sources(k)%path
    end do
  end function files_text

  !> The deck's signature: the hashes of its files in reading order.
  function combined_signature(hashes) result(signature)
    character(len=16), intent(in) :: hashes(:)
    character(len=:), allocatable :: signature
    integer :: k
    signature = "fnv1a64"
    do k = 1, size(hashes)
      signature = signature//":"//hashes(k)
    end do
  end function combined_signature

  pure integer function line_count(text)
    character(len=*), intent(in) :: text
    integer :: k
    line_count = 0
    if (len(text) == 0) return
    line_count = 1
    do k = 1, len(text)
      if (text(k:k) == new_line("a")) line_count = line_count + 1
    end do
  end function line_count

  !> Line `number` of `text` ("" beyond its end).
  function line_of(text, number) result(line)
    character(len=*), intent(in) :: text
    integer, intent(in) :: number
    character(len=:), allocatable :: line
    integer :: start, finish, k
    line = ""
    start = 1
    do k = 1, number
      if (start > len(text)) return
      finish = index(text(start:), new_line("a"))
      if (finish == 0) then
        finish = len(text) + 1
      else
        finish = start + finish - 1
      end if
      if (k == number) line = text(start:finish - 1)
      start = finish + 1
    end do
  end function line_of

  !> The path of a "hash size path" line ("(none)" for an empty one).
  function file_of(line) result(path)
    character(len=*), intent(in) :: line
    character(len=:), allocatable :: path
    integer :: blank
    path = "(none)"
    if (len(line) < 18) return
    blank = index(line(18:), " ")
    if (blank == 0) return
    path = line(18 + blank:)
  end function file_of
end module restart_control
