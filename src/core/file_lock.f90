!> An exclusive advisory lock on a file (flock(2)), held by a running job on `DIR/JOBID.lock`,
!> so that a second run writing the same results into the same directory is refused instead of
!> both runs corrupting one file.
!>
!> The kernel releases a flock lock when the process ends in any way (also SIGKILL), so a killed
!> run never leaves a stale lock behind: the lock file stays, but it is only a lock while a live
!> process holds it. The lock file holds the pid of the holder as text, for the message of the
!> process that is refused. The lock is taken on a separate file rather than on the results
!> file itself because HDF5 readers (h5py, ParaView) take their own flock on the file they
!> read: a lock on `results.h5` would keep them from opening the results of a running job.
module file_lock
  use, intrinsic :: iso_c_binding, only: c_int, c_long, c_char, c_null_char, c_ptr, c_null_ptr, &
                                         c_associated, c_size_t, c_loc
  use error_handling, only: error_t, make_error
  use file_system, only: clear_system_error, system_error_number, system_error_text
  use text_format, only: integer_text
  implicit none
  private

  public :: file_lock_t, acquire_file_lock, release_file_lock

  !> A lock held on a file (or none).
  type :: file_lock_t
    type(c_ptr) :: stream = c_null_ptr              !< the open lock file (C FILE*)
    character(len=:), allocatable :: path           !< the lock file
  end type file_lock_t

  integer(c_int), parameter :: lock_exclusive = 2, lock_no_wait = 4, lock_release = 8
  !> errno of flock on a lock held by someone else (EWOULDBLOCK = EAGAIN on Linux).
  integer, parameter :: error_would_block = 11

  interface
    !> C fopen(3) with "a+": creates the file when missing, never truncates it.
    function c_fopen(path, mode) bind(c, name="fopen") result(stream)
      import :: c_ptr, c_char
      character(kind=c_char), intent(in) :: path(*), mode(*)
      type(c_ptr) :: stream
    end function c_fopen

    function c_fclose(stream) bind(c, name="fclose") result(status)
      import :: c_int, c_ptr
      type(c_ptr), value :: stream
      integer(c_int) :: status
    end function c_fclose

    function c_fileno(stream) bind(c, name="fileno") result(descriptor)
      import :: c_int, c_ptr
      type(c_ptr), value :: stream
      integer(c_int) :: descriptor
    end function c_fileno

    function c_flock(descriptor, operation) bind(c, name="flock") result(status)
      import :: c_int
      integer(c_int), value :: descriptor, operation
      integer(c_int) :: status
    end function c_flock

    function c_ftruncate(descriptor, length) bind(c, name="ftruncate") result(status)
      import :: c_int, c_long
      integer(c_int), value :: descriptor
      integer(c_long), value :: length
      integer(c_int) :: status
    end function c_ftruncate

    function c_write(descriptor, buffer, count) bind(c, name="write") result(written)
      import :: c_int, c_ptr, c_size_t, c_long
      integer(c_int), value :: descriptor
      type(c_ptr), value :: buffer
      integer(c_size_t), value :: count
      integer(c_long) :: written
    end function c_write

    function c_getpid() bind(c, name="getpid") result(pid)
      import :: c_int
      integer(c_int) :: pid
    end function c_getpid
  end interface

contains

  !> Take the lock on `path` (created when missing) without waiting. When another process holds
  !> it, `error` is set and `holder` is that process's pid as text (read from the lock file;
  !> "unknown" until it has written it); on any other failure `holder` is "" and `error` says
  !> why (e.g. "cannot create the lock file out/results.lock: Read-only file system").
  subroutine acquire_file_lock(lock, path, error, holder)
    type(file_lock_t), intent(inout) :: lock
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: error
    character(len=:), allocatable, intent(out) :: holder
    character(kind=c_char, len=1), allocatable, target :: pid_text(:)
    character(len=:), allocatable :: digits
    integer(c_int) :: status
    integer(c_long) :: written
    integer :: number, k

    holder = ""
    call release_file_lock(lock)
    call clear_system_error()
    lock%stream = c_fopen(path//c_null_char, "a+"//c_null_char)
    if (.not. c_associated(lock%stream)) then
      call make_error(error, "cannot create the lock file "//path//": "// &
                      system_error_text(system_error_number()))
      return
    end if
    status = c_flock(c_fileno(lock%stream), ior(lock_exclusive, lock_no_wait))
    if (status /= 0) then
      number = system_error_number()
      status = c_fclose(lock%stream)
      lock%stream = c_null_ptr
      if (number == error_would_block) then
        holder = holder_pid(path)
        call make_error(error, path//" is locked by process "//holder)
      else
        call make_error(error, "cannot lock "//path//": "//system_error_text(number))
      end if
      return
    end if
    lock%path = path
    ! Our pid for the next one refused. Not writing it (a full disk) does not weaken the lock.
    digits = integer_text(int(c_getpid()))
    allocate (pid_text(len(digits) + 1))
    do k = 1, len(digits)
      pid_text(k) = digits(k:k)
    end do
    pid_text(size(pid_text)) = achar(10)
    status = c_ftruncate(c_fileno(lock%stream), 0_c_long)
    written = c_write(c_fileno(lock%stream), c_loc(pid_text), int(size(pid_text), c_size_t))
  end subroutine acquire_file_lock

  !> Release the lock (nothing when none is held). The lock file stays: removing it could let a
  !> third process lock a new file while a second one still waits on the old one.
  subroutine release_file_lock(lock)
    type(file_lock_t), intent(inout) :: lock
    integer(c_int) :: status
    if (.not. c_associated(lock%stream)) return
    status = c_flock(c_fileno(lock%stream), lock_release)
    status = c_fclose(lock%stream)
    lock%stream = c_null_ptr
  end subroutine release_file_lock

  !> The pid written in the lock file by its holder, or "unknown" while it has not written it.
  function holder_pid(path) result(text)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: text
    integer :: unit, status, pid
    text = "unknown"
    open (newunit=unit, file=path, status="old", action="read", iostat=status)
    if (status /= 0) return
    read (unit, *, iostat=status) pid
    close (unit)
    if (status /= 0) return
    text = integer_text(pid)
  end function holder_pid
end module file_lock
