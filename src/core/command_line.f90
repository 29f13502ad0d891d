!> The command line in the style LS-DYNA users know: `crashfree i=deck.k ncpu=2 ...`.
!>
!> LS-DYNA's own arguments that have no meaning here (memory=, d=nodump, s=, o=, ...) are
!> accepted and listed as notes, so that a command line copied from an LS-DYNA job runs; a bare
!> deck name as the first argument (`crashfree deck.k`) is the deck, as LS-DYNA takes it (also
!> with a note, so that a mistyped key is not silently taken for a deck).
module command_line
  use error_handling, only: error_t, error_list_t, make_error, add_error
  implicit none
  private

  public :: run_options_t, command_argument_t, parse_command_line, usage_text
  public :: get_command_arguments, launched_rank_count, launched_rank_index, check_launch

  !> One argument as the shell passed it, whatever its length.
  type :: command_argument_t
    character(len=:), allocatable :: text
  end type command_argument_t

  !> What the user asked for.
  type :: run_options_t
    character(len=:), allocatable :: deck          !< i=
    character(len=:), allocatable :: output_dir    !< outdir= (default "."; with r= unset: the dump's)
    character(len=:), allocatable :: job_id        !< jobid= (default "results"; with r= unset: the dump's)
    character(len=:), allocatable :: restart_file  !< r= (the deck, when i= is not given, is the dump's)
    integer :: threads = 0                         !< ncpu= (0: OMP_NUM_THREADS, else all cores)
    !> x=: d3plot family file size in multiples of 512^2 words (LS-DYNA's default 7)
    integer :: binary_file_scale = 7
    !> partition=N: compute and report the domain partition for N MPI ranks after the set-up,
    !> then stop without running (as LS-DYNA MPP's decomposition-only runs); 0: run
    integer :: partition_ranks = 0
    logical :: ignore_unknown = .false.            !< --ignore-unknown
    logical :: show_help = .false.
    logical :: show_version = .false.
    !> LS-DYNA arguments accepted but not used, one note each (for standard error).
    type(error_list_t) :: notes
  end type run_options_t

contains

  !> The arguments the program was started with, each at its full length.
  subroutine get_command_arguments(arguments)
    type(command_argument_t), allocatable, intent(out) :: arguments(:)
    integer :: k, length
    allocate (arguments(command_argument_count()))
    do k = 1, size(arguments)
      call get_command_argument(k, length=length)
      allocate (character(len=length) :: arguments(k)%text)
      if (length > 0) call get_command_argument(k, arguments(k)%text)
    end do
  end subroutine get_command_arguments

  !> Parse `arguments` (already split as the shell split them).
  subroutine parse_command_line(arguments, options, error)
    type(command_argument_t), intent(in) :: arguments(:)
    type(run_options_t), intent(out) :: options
    type(error_t), allocatable, intent(out) :: error
    integer :: k, equals
    character(len=:), allocatable :: argument, key, value, note
    logical :: bare_deck

    bare_deck = .false.
    do k = 1, size(arguments)
      argument = arguments(k)%text
      select case (argument)
      case ("--help", "-h", "help")
        options%show_help = .true.
        cycle
      case ("--version", "-v")
        options%show_version = .true.
        cycle
      case ("--ignore-unknown")
        options%ignore_unknown = .true.
        cycle
      end select
      equals = index(argument, "=")
      if (k == 1 .and. equals == 0 .and. len(argument) > 0) then
        ! LS-DYNA takes a first argument without "=" as the input deck
        if (argument(1:1) /= "-") then
          options%deck = argument
          bare_deck = .true.
          call add_error(options%notes, argument//": read as the input deck (i="//argument// &
                         "), as LS-DYNA takes a first argument without '='")
          cycle
        end if
      end if
      if (equals <= 1 .or. equals == len(argument)) then
        call make_error(error, "command line: '"//argument//"' is not of the form key=value (see --help)")
        return
      end if
      key = to_lower(argument(:equals - 1))
      value = argument(equals + 1:)
      select case (key)
      case ("i")
        if (bare_deck) then
          call make_error(error, "command line: two decks given: '"//options%deck//"' and i="// &
                          value)
          return
        end if
        options%deck = value
      case ("outdir")
        options%output_dir = value
      case ("jobid")
        options%job_id = value
      case ("r")
        options%restart_file = value
      case ("ncpu")
        call read_thread_count(value, options, error)
        if (allocated(error)) return
      case ("x")
        call read_file_scale(value, options, error)
        if (allocated(error)) return
      case ("partition")
        call read_partition_ranks(value, options, error)
        if (allocated(error)) return
      case default
        note = ignored_argument_note(key)
        if (len(note) == 0) then
          call make_error(error, "command line: unknown option '"//key//"=' (see --help)")
          return
        end if
        call add_error(options%notes, argument//": ignored ("//note//")")
      end select
    end do
    if (.not. (options%show_help .or. options%show_version) .and. .not. allocated(options%deck) .and. &
        .not. allocated(options%restart_file)) then
      call make_error(error, "command line: no input deck given: use i=DECK.k, or r=DUMP to continue a run "// &
                      "(see --help)")
    end if
    ! a restart takes the output directory and job of its dump unless they are given
    if (.not. allocated(options%restart_file)) then
      if (.not. allocated(options%output_dir)) options%output_dir = "."
      if (.not. allocated(options%job_id)) options%job_id = "results"
    end if
  end subroutine parse_command_line

  !> ncpu=N: N threads. LS-DYNA's ncpu=-N (N threads, results independent of N) is read as N,
  !> with a note: crashfree's results are the same for any N anyway.
  subroutine read_thread_count(value, options, error)
    character(len=*), intent(in) :: value
    type(run_options_t), intent(inout) :: options
    type(error_t), allocatable, intent(out) :: error
    character(len=:), allocatable :: digits
    integer :: status
    digits = value
    if (len(value) > 1) then
      if (value(1:1) == "-") digits = value(2:)
    end if
    status = 1
    if (verify(digits, "0123456789") == 0 .and. len(digits) <= 9) &
      read (digits, *, iostat=status) options%threads
    if (status /= 0 .or. options%threads < 1) then
      call make_error(error, "command line: ncpu='"//value//"' is not a positive whole number")
      return
    end if
    if (len(digits) < len(value)) call add_error(options%notes, "ncpu="//value//": read as "// &
      "ncpu="//digits//" (results are the same for any number of threads, as LS-DYNA's "// &
      "negative ncpu asks for)")
  end subroutine read_thread_count

  !> x=N: the d3plot family files hold up to N x 512^2 words (a positive whole number).
  subroutine read_file_scale(value, options, error)
    character(len=*), intent(in) :: value
    type(run_options_t), intent(inout) :: options
    type(error_t), allocatable, intent(out) :: error
    call read_positive_whole_number("x", value, "the d3plot file size in multiples of 512^2 words", &
                                    options%binary_file_scale, error)
  end subroutine read_file_scale

  !> partition=N: a positive whole number of ranks.
  subroutine read_partition_ranks(value, options, error)
    character(len=*), intent(in) :: value
    type(run_options_t), intent(inout) :: options
    type(error_t), allocatable, intent(out) :: error
    call read_positive_whole_number("partition", value, "the number of MPI ranks to partition the model for", &
                                    options%partition_ranks, error)
  end subroutine read_partition_ranks

  !> name=value as a positive whole number of at most 6 digits into `number` (left as it was, and
  !> an error naming the argument and its `meaning`, otherwise).
  subroutine read_positive_whole_number(name, value, meaning, number, error)
    character(len=*), intent(in) :: name, value, meaning
    integer, intent(inout) :: number
    type(error_t), allocatable, intent(out) :: error
    integer :: status, read_number
    status = 1
    if (verify(value, "0123456789") == 0 .and. len(value) >= 1 .and. len(value) <= 6) &
      read (value, *, iostat=status) read_number
    if (status == 0) then
      if (read_number >= 1) then
        number = read_number
        return
      end if
    end if
    call make_error(error, "command line: "//name//"='"//value//"' is not a positive whole number ("// &
                    meaning//")")
  end subroutine read_positive_whole_number

  !> The number of processes an MPI launcher (mpirun, mpiexec, srun) started this one among,
  !> read from the environment it sets: Open MPI's OMPI_COMM_WORLD_SIZE, else PMI_SIZE (MPICH,
  !> Intel MPI, Slurm); 1 when started without a launcher.
  integer function launched_rank_count()
    launched_rank_count = max(1, launcher_setting("OMPI_COMM_WORLD_SIZE", "PMI_SIZE", 1))
  end function launched_rank_count

  !> This process's place (0, 1, ...) among those an MPI launcher started, from the environment
  !> it sets: OMPI_COMM_WORLD_RANK, else PMI_RANK; 0 when started without a launcher. (A build
  !> without MPI has no other way to tell the processes apart: the first one alone says why
  !> they all stop.)
  integer function launched_rank_index()
    launched_rank_index = max(0, launcher_setting("OMPI_COMM_WORLD_RANK", "PMI_RANK", 0))
  end function launched_rank_index

  !> The whole number in the environment variable `open_mpi_name`, else in `pmi_name`; `absent`
  !> when neither is set to a number.
  integer function launcher_setting(open_mpi_name, pmi_name, absent)
    character(len=*), intent(in) :: open_mpi_name, pmi_name
    integer, intent(in) :: absent
    character(len=32) :: setting
    integer :: length, status, value
    launcher_setting = absent
    call get_environment_variable(open_mpi_name, setting, length, status)
    if (status /= 0) call get_environment_variable(pmi_name, setting, length, status)
    if (status /= 0) return
    read (setting, *, iostat=status) value
    if (status == 0) launcher_setting = value
  end function launcher_setting

  !> A program built without MPI (`mpi_built` false) that an MPI launcher started as one of
  !> several processes would run the whole job once per process, all writing the same files:
  !> an error naming the process count and what to do. `mpi_built` true: no error (the MPI
  !> runtime itself then tells the ranks apart).
  subroutine check_launch(mpi_built, error)
    logical, intent(in) :: mpi_built
    type(error_t), allocatable, intent(out) :: error
    integer :: count
    if (mpi_built) return
    count = launched_rank_count()
    if (count <= 1) return
    call make_error(error, "this crashfree was built without MPI, and an MPI launcher started it as "// &
                    trim(count_text(count))//" processes (OMPI_COMM_WORLD_SIZE / PMI_SIZE), which would each "// &
                    "run the whole job and write the same files: run it without mpirun (ncpu= sets the threads), "// &
                    "or rebuild with MPI (tools/install_dependencies.sh installs Open MPI, then make)")
  contains
    pure function count_text(value) result(text)
      integer, intent(in) :: value
      character(len=12) :: text
      write (text, '(i0)') value
    end function count_text
  end subroutine check_launch

  !> Why LS-DYNA's argument `key`= is not used here ("" for a key LS-DYNA does not have
  !> either, which is an error).
  pure function ignored_argument_note(key) result(note)
    character(len=*), intent(in) :: key
    character(len=:), allocatable :: note
    select case (key)
    case ("memory", "memory2")
      ! LS-DYNA: memory= words of memory for the run (MPP: for the first rank, which decomposes
      ! the model), memory2= words for each of the other ranks
      note = "LS-DYNA's memory in words (memory2=: per MPP rank after the first); crashfree sizes its "// &
             "memory from the model"
    case ("s")
      note = "LS-DYNA's interface segment save file; crashfree writes none"
    case ("d")
      note = "crashfree writes no dump at the end of a run; restart dumps come from *DATABASE_BINARY_D3DUMP, "// &
             "_RUNRSF and the sense switches (SIGTERM, SIGUSR1)"
    case ("o")
      note = "crashfree prints its run output on standard output"
    case ("g")
      note = "results go to DIR/results.h5, see outdir= and jobid="
    case ("pfile")
      ! LS-DYNA MPP: a file of decomposition settings (method, region weights, ...)
      note = "LS-DYNA MPP's decomposition control file; crashfree partitions the model itself "// &
             "(METIS, weighted by element cost; partition=N shows the partition for N ranks)"
    case ("ncycle")
      note = "an LS-DYNA option crashfree does not use"
    case default
      note = ""
    end select
  end function ignored_argument_note

  !> The text of --help.
  function usage_text() result(text)
    character(len=:), allocatable :: text
    character(len=*), parameter :: nl = new_line('a')
    text = "usage: crashfree i=DECK.k [outdir=DIR] [ncpu=N] [jobid=NAME]"//nl// &
           "                 [--ignore-unknown] [--help] [--version]"//nl// &
           "       crashfree DECK.k [...]"//nl// &
           "       crashfree r=DUMP [outdir=DIR] [ncpu=N] [jobid=NAME]"//nl//nl// &
           "  i=DECK.k        LS-DYNA style keyword deck to run (or the deck name alone, first)"//nl// &
           "  outdir=DIR      directory for the results (default: the current directory)"//nl// &
           "  ncpu=N          OpenMP threads (default: OMP_NUM_THREADS, else all cores; at most"//nl// &
           "                  the processors available); results are bit-identical for any N"//nl// &
           "  jobid=NAME      name the results NAME.h5 and NAME.xdmf (default: results)"//nl// &
           "  x=N             d3plot family files of up to N x 512^2 words (default: 7)"//nl// &
           "  r=DUMP          continue the run from a restart dump (DIR/d3dump01, DIR/runrsf, ...): the"//nl// &
           "                  deck is read again from its recorded path (or i=) and must be unchanged;"//nl// &
           "                  results go on in the run's DIR/JOBID.h5 (default: the dump's directory"//nl// &
           "                  and job)"//nl// &
           "  --ignore-unknown  warn about unknown keywords and skip them instead of stopping (a"//nl// &
           "                  keyword crashfree reads, with an option it lacks, still stops)"//nl// &
           "  partition=N     compute and print the domain partition for N MPI ranks (also in"//nl// &
           "                  results.h5 /run/partition and d3hsp), then stop without running"//nl// &
           "  memory= memory2= d=nodump s= o= g= ncycle= pfile=   LS-DYNA's: accepted, not used"//nl//nl// &
           "Results: DIR/results.h5 (HDF5, see README) and DIR/results.xdmf for ParaView."//nl// &
           "Signals: SIGINT/SIGTERM stop after the cycle with a restart dump, SIGUSR1 writes a dump"//nl// &
           "and goes on, SIGUSR2 prints the progress line."//nl// &
           "Exit status: 0 normal termination, 1 error termination, 2 bad command line or deck."
  end function usage_text

  pure function to_lower(text) result(lower)
    character(len=*), intent(in) :: text
    character(len=len(text)) :: lower
    integer :: k
    lower = text
    do k = 1, len(text)
      if (text(k:k) >= "A" .and. text(k:k) <= "Z") lower(k:k) = achar(iachar(text(k:k)) + 32)
    end do
  end function to_lower
end module command_line
