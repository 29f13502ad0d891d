!> crashfree: explicit crash solver with coupled meshfree (EFG) / finite element parts.
!> The program only reads the command line; everything else lives in libcrashfree.
program crashfree
  use command_line, only: run_options_t, parse_command_line, usage_text
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
  character(len=4096), allocatable :: arguments(:)
  integer :: k, exit_status

  allocate (arguments(command_argument_count()))
  do k = 1, size(arguments)
    call get_command_argument(k, arguments(k))
  end do
  call parse_command_line(arguments, options, error)
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
end program crashfree
