!> crashfree: explicit crash solver with coupled meshfree (EFG) / finite element parts.
!> The program only reads the command line; everything else lives in libcrashfree.
program crashfree
  use command_line, only: run_options_t, command_argument_t, get_command_arguments, &
                          parse_command_line, usage_text, check_launch
  use error_handling, only: error_t
  use job, only: run_job
  use version, only: crashfree_version
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

  call get_command_arguments(arguments)
  call parse_command_line(arguments, options, error)
  if (allocated(error)) then
    write (error_unit, '(a)') "crashfree: "//error%message
    call c_exit(2_c_int)
  end if
  if (options%notes%count > 0) call write_notes(options%notes%text)
  ! this program has no MPI: several processes started by mpirun would each run the whole job
  call check_launch(mpi_built=.false., error=error)
  if (allocated(error)) then
    write (error_unit, '(a)') "crashfree: "//error%message
    call c_exit(2_c_int)
  end if
  if (options%show_help) then
    write (*, '(a)') usage_text()
    stop
  end if
  if (options%show_version) then
    write (*, '(a)') "crashfree "//crashfree_version
    stop
  end if
  call run_job(options, exit_status)
  flush (output_unit)
  flush (error_unit)
  call c_exit(int(exit_status, c_int))

contains

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
