!> The command line in the style LS-DYNA users know: `crashfree i=deck.k ncpu=2 ...`.
module command_line
  use error_handling, only: error_t, make_error
  implicit none
  private

  public :: run_options_t, parse_command_line, usage_text

  !> What the user asked for.
  type :: run_options_t
    character(len=:), allocatable :: deck          !< i=
    character(len=:), allocatable :: output_dir    !< outdir= (default ".")
    character(len=:), allocatable :: job_id        !< jobid= (default "results")
    character(len=:), allocatable :: restart_file  !< r=
    integer :: threads = 0                         !< ncpu= (0: OMP_NUM_THREADS, else all cores)
    logical :: ignore_unknown = .false.            !< --ignore-unknown
    logical :: show_help = .false.
    logical :: show_version = .false.
  end type run_options_t

contains

  !> Parse `arguments` (already split as the shell split them).
  subroutine parse_command_line(arguments, options, error)
    character(len=*), intent(in) :: arguments(:)
    type(run_options_t), intent(out) :: options
    type(error_t), allocatable, intent(out) :: error
    integer :: k, equals, status
    character(len=:), allocatable :: argument, key, value

    options%output_dir = "."
    options%job_id = "results"
    do k = 1, size(arguments)
      argument = trim(arguments(k))
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
      if (equals <= 1 .or. equals == len(argument)) then
        call make_error(error, "command line: '"//argument//"' is not of the form key=value (see --help)")
        return
      end if
      key = to_lower(argument(:equals - 1))
      value = argument(equals + 1:)
      select case (key)
      case ("i")
        options%deck = value
      case ("outdir")
        options%output_dir = value
      case ("jobid")
        options%job_id = value
      case ("r")
        options%restart_file = value
      case ("ncpu")
        read (value, *, iostat=status) options%threads
        if (status /= 0 .or. options%threads < 1 .or. verify(value, "0123456789") /= 0) then
          call make_error(error, "command line: ncpu='"//value//"' is not a positive whole number")
          return
        end if
      case default
        call make_error(error, "command line: unknown option '"//key//"=' (see --help)")
        return
      end select
    end do
    if (.not. (options%show_help .or. options%show_version) .and. .not. allocated(options%deck)) then
      call make_error(error, "command line: no input deck given: use i=DECK.k (see --help)")
    end if
  end subroutine parse_command_line

  !> The text of --help.
  function usage_text() result(text)
    character(len=:), allocatable :: text
    character(len=*), parameter :: nl = new_line('a')
    text = "usage: crashfree i=DECK.k [outdir=DIR] [ncpu=N] [jobid=NAME] [r=RESTARTFILE]"//nl// &
           "                 [--ignore-unknown] [--help] [--version]"//nl//nl// &
           "  i=DECK.k        LS-DYNA style keyword deck to run"//nl// &
           "  outdir=DIR      directory for the results (default: the current directory)"//nl// &
           "  ncpu=N          OpenMP threads (default: OMP_NUM_THREADS, else all cores);"//nl// &
           "                  results are bit-identical for any N"//nl// &
           "  jobid=NAME      name the results NAME.h5 and NAME.xdmf (default: results)"//nl// &
           "  r=FILE          restart file (not supported yet: rejected)"//nl// &
           "  --ignore-unknown  warn about unknown keywords instead of stopping"//nl//nl// &
           "Results: DIR/results.h5 (HDF5, see README) and DIR/results.xdmf for ParaView."//nl// &
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
