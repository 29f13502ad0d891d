!> The little the solver needs from the file system: create an output directory.
module file_system
  use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char
  use error_handling, only: error_t, make_error
  implicit none
  private

  public :: make_directory

  interface
    !> POSIX mkdir(2); mode_t is an unsigned int on the platforms crashfree builds on.
    function c_mkdir(path, mode) bind(c, name="mkdir") result(status)
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: path(*)
      integer(c_int), value :: mode
      integer(c_int) :: status
    end function c_mkdir
  end interface

contains

  !> Create `path` and its missing parents (like `mkdir -p`); an existing directory is fine.
  subroutine make_directory(path, error)
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: error
    integer :: k, status
    logical :: exists
    do k = 2, len_trim(path) + 1
      if (k <= len_trim(path)) then
        if (path(k:k) /= "/") cycle
      end if
      status = c_mkdir(path(1:k - 1)//c_null_char, int(o'755', c_int))
    end do
    inquire (file=trim(path)//"/.", exist=exists)
    if (.not. exists) call make_error(error, "cannot create the output directory '"//trim(path)//"'")
  end subroutine make_directory
end module file_system
