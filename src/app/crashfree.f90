!> crashfree: explicit crash solver with coupled meshfree (EFG) / finite element parts.
!> The program only reads the command line; everything else lives in libcrashfree.
program crashfree
  use command_line, only: run_options_t, command_argument_t, get_command_arguments, &
                          parse_command_line, usage_text, check_launch, launched_rank_index
  use error_handling, only: error_t
  use job, only: run_job
  use version, only: crashfree_version
  use rank_communication, only: start_ranks, finish_ranks, rank_index, mpi_built
  use, intrinsic :: iso_c_binding, only: c_int
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
  implicit none
  interface
    !> The C library's exit: ends with a status and without the "STOP n" line of a Fortran stop.
    subroutine c_exit(status) bind(c, name="exit")
      import :: c_int
      integer(c_int), value :: status
    end subroutine c_exit
  end interface
  type(run_options_t) :: options
  type(error_t), allocatable :: error
  type(command_argument_t), allocatable :: arguments(:)
  integer :: exit_status

  ! (under mpirun every rank runs this program; started alone it is one rank; the first rank
  ! prints what all of them would)
  call start_ranks()
  call get_command_arguments(arguments)
  call parse_command_line(arguments, options, error)
  if (allocated(error)) then
    if (rank_index() == 0) write (error_unit, '(a)') "crashfree: "//error%message
    call finish(2)
  end if
  if (options%notes%count > 0 .and. rank_index() == 0) call write_notes(options%notes%text)
  ! a build without MPI that a launcher started several times would run the whole job in each
  call check_launch(mpi_built=mpi_built, error=error)
  if (allocated(error)) then
    ! (MPI is not running: the launcher's numbering picks the one process that says it)
    if (launched_rank_index() == 0) write (error_unit, '(a)') "crashfree: "//error%message
    call finish(2)
  end if
  if (options%show_help) then
    if (rank_index() == 0) write (*, '(a)') usage_text()
    call finish(0)
  end if
  if (options%show_version) then
    if (rank_index() == 0) write (*, '(a)') "crashfree "//crashfree_version
    call finish(0)
  end if
  call run_job(options, exit_status)
  call finish(exit_status)

contains

  !> End the process with `status` after MPI (and the output) is done.
  subroutine finish(status)
    integer, intent(in) :: status
    flush (output_unit)
    flush (error_unit)
    call finish_ranks()
    call c_exit(int(status, c_int))
  end subroutine finish

  !> Each line of `text` on standard error as `crashfree: line`.
  subroutine write_notes(text)
    character(len=*), intent(in) :: text
    integer :: start, finish
    start = 1
    do while (start <= len(text))
      finish = index(text(start:), new_line("a"))
      if (finish == 0) then
        finish = len(text) + 1
      else
        finish = start + finish - 1
      end if
      write (error_unit, '(a)') "crashfree: "//text(start:finish - 1)
      start = finish + 1
    end do
  end subroutine write_notes
end program crashfree
