!> The little the solver needs from the file system: create an output directory, replace a file
!> atomically, remove one, reserve disk space ahead of writing, and say why a system call failed.
!>
!> These are thin bindings to POSIX (and Linux's fallocate); the values of errno used below
!> (ENOSPC, EDQUOT, EOPNOTSUPP, ...) are Linux's, the platform crashfree builds on. Only
!> functions with fixed argument lists are bound (fopen rather than the variadic open).
module file_system
  use, intrinsic :: iso_c_binding, only: c_int, c_long, c_char, c_null_char, c_ptr, c_null_ptr, &
                                         c_associated, c_f_pointer, c_size_t
  use kinds, only: long_int
  use error_handling, only: error_t, make_error
  use text_format, only: integer_text
  implicit none
  private

  public :: make_directory, write_text_file, rename_file, remove_file, reserve_file_space, &
            release_file_space, file_size, system_error_number, clear_system_error, system_error_text, &
            error_no_space, error_quota_exceeded

  !> errno values (Linux) that mean "the disk is full" for the user.
  integer, parameter :: error_no_space = 28        !< ENOSPC
  integer, parameter :: error_quota_exceeded = 122 !< EDQUOT
  integer, parameter :: error_exists = 17          !< EEXIST

  !> fallocate(2) modes: keep the file size (reserve blocks beyond the end), punch a hole.
  integer(c_int), parameter :: fallocate_keep_size = 1, fallocate_punch_hole = 2
  integer(c_int), parameter :: seek_end = 2

  interface
    !> POSIX mkdir(2); mode_t is an unsigned int on the platforms crashfree builds on.
    function c_mkdir(path, mode) bind(c, name="mkdir") result(status)
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: path(*)
      integer(c_int), value :: mode
      integer(c_int) :: status
    end function c_mkdir

    !> POSIX rename(2): atomic replacement of `new_path` within one file system.
    function c_rename(old_path, new_path) bind(c, name="rename") result(status)
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: old_path(*), new_path(*)
      integer(c_int) :: status
    end function c_rename

    !> POSIX unlink(2).
    function c_unlink(path) bind(c, name="unlink") result(status)
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: path(*)
      integer(c_int) :: status
    end function c_unlink

    !> C fopen(3), used for an existing file ("r+": neither created nor truncated).
    function c_fopen(path, mode) bind(c, name="fopen") result(stream)
      import :: c_ptr, c_char
      character(kind=c_char), intent(in) :: path(*), mode(*)
      type(c_ptr) :: stream
    end function c_fopen

    function c_fwrite(buffer, item_size, count, stream) bind(c, name="fwrite") result(written)
      import :: c_char, c_size_t, c_ptr
      character(kind=c_char), intent(in) :: buffer(*)
      integer(c_size_t), value :: item_size, count
      type(c_ptr), value :: stream
      integer(c_size_t) :: written
    end function c_fwrite

    function c_fflush(stream) bind(c, name="fflush") result(status)
      import :: c_int, c_ptr
      type(c_ptr), value :: stream
      integer(c_int) :: status
    end function c_fflush

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

    !> lseek(2); off_t is a long on the 64-bit platforms crashfree builds on.
    function c_lseek(descriptor, offset, whence) bind(c, name="lseek") result(position)
      import :: c_int, c_long
      integer(c_int), value :: descriptor
      integer(c_long), value :: offset
      integer(c_int), value :: whence
      integer(c_long) :: position
    end function c_lseek

    !> ftruncate(2): with the file's own size it frees the blocks reserved beyond its end.
    function c_ftruncate(descriptor, length) bind(c, name="ftruncate") result(status)
      import :: c_int, c_long
      integer(c_int), value :: descriptor
      integer(c_long), value :: length
      integer(c_int) :: status
    end function c_ftruncate

    !> Linux fallocate(2).
    function c_fallocate(descriptor, mode, offset, length) bind(c, name="fallocate") result(status)
      import :: c_int, c_long
      integer(c_int), value :: descriptor, mode
      integer(c_long), value :: offset, length
      integer(c_int) :: status
    end function c_fallocate

    !> glibc's location of errno (errno is a per-thread variable, not a plain global).
    function c_errno_location() bind(c, name="__errno_location") result(location)
      import :: c_ptr
      type(c_ptr) :: location
    end function c_errno_location

    function c_strerror(number) bind(c, name="strerror") result(text)
      import :: c_int, c_ptr
      integer(c_int), value :: number
      type(c_ptr) :: text
    end function c_strerror

    function c_strlen(text) bind(c, name="strlen") result(length)
      import :: c_ptr, c_size_t
      type(c_ptr), value :: text
      integer(c_size_t) :: length
    end function c_strlen
  end interface

contains

  !> Create `path` and its missing parents (like `mkdir -p`); an existing directory is fine.
  !> The message says why not, e.g. "cannot create the output directory 'a/b': Not a directory".
  subroutine make_directory(path, error)
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: error
    integer :: k, status, number
    logical :: exists

    number = 0
    do k = 2, len_trim(path) + 1
      if (k <= len_trim(path)) then
        if (path(k:k) /= "/") cycle
      end if
      call clear_system_error()
      status = c_mkdir(path(1:k - 1)//c_null_char, int(o'755', c_int))
      ! Keep the first real failure: it names the cause ("Permission denied" on a parent, or
      ! "Not a directory" when a parent is a file); "exists" is the normal case.
      if (status /= 0 .and. number == 0) then
        number = system_error_number()
        if (number == error_exists) number = 0
      end if
    end do
    inquire (file=trim(path)//"/.", exist=exists)
    if (.not. exists) then
      if (number /= 0) then
        call make_error(error, "cannot create the output directory '"//trim(path)//"': "// &
                        system_error_text(number))
      else
        call make_error(error, "cannot create the output directory '"//trim(path)//"'")
      end if
    end if
  end subroutine make_directory

  !> Write `text` as the whole content of the file `path` (created or replaced), and say when
  !> any of it could not be written ("... /results.xdmf.tmp: No space left on device").
  !> Through C's stdio rather than a Fortran unit: gfortran's formatted writes and CLOSE report
  !> no error when the disk is full, and the file is silently cut short. With `append` true,
  !> `text` goes after the file's content instead (a file written piece by piece).
  subroutine write_text_file(path, text, error, append)
    character(len=*), intent(in) :: path, text
    type(error_t), allocatable, intent(out) :: error
    logical, intent(in), optional :: append
    type(c_ptr) :: stream
    integer(c_size_t) :: written
    integer(c_int) :: flushed, closed
    integer :: number
    character(len=1) :: mode

    mode = "w"
    if (present(append)) then
      if (append) mode = "a"
    end if
    call clear_system_error()
    stream = c_fopen(path//c_null_char, mode//c_null_char)
    if (.not. c_associated(stream)) then
      call make_error(error, "cannot write "//path//": "//system_error_text(system_error_number()))
      return
    end if
    written = 0
    if (len(text) > 0) written = c_fwrite(text, 1_c_size_t, int(len(text), c_size_t), stream)
    number = system_error_number()
    flushed = c_fflush(stream)
    if (number == 0) number = system_error_number()
    closed = c_fclose(stream)
    if (number == 0) number = system_error_number()
    if (written /= int(len(text), c_size_t) .or. flushed /= 0 .or. closed /= 0) then
      if (number /= 0) then
        call make_error(error, "cannot write "//path//": "//system_error_text(number))
      else
        call make_error(error, "cannot write "//path)
      end if
    end if
  end subroutine write_text_file

  !> Replace `new_path` by `old_path` in one step (rename(2)): a reader, or a process killed at
  !> any moment, sees either the old or the new file, never a mixture. Both paths must be in
  !> the same directory (one file system).
  subroutine rename_file(old_path, new_path, error)
    character(len=*), intent(in) :: old_path, new_path
    type(error_t), allocatable, intent(out) :: error
    call clear_system_error()
    if (c_rename(old_path//c_null_char, new_path//c_null_char) /= 0) &
      call make_error(error, "cannot rename "//old_path//" to "//new_path//": "// &
                      system_error_text(system_error_number()))
  end subroutine rename_file

  !> Remove a file; a missing file is not an error (nothing to report to the user either way).
  subroutine remove_file(path)
    character(len=*), intent(in) :: path
    integer(c_int) :: status
    status = c_unlink(path//c_null_char)
  end subroutine remove_file

  !> Size in bytes of an existing file, -1 when it cannot be opened.
  function file_size(path) result(bytes)
    character(len=*), intent(in) :: path
    integer(long_int) :: bytes
    type(c_ptr) :: stream
    integer(c_int) :: status
    bytes = -1
    stream = c_fopen(path//c_null_char, "r"//c_null_char)
    if (.not. c_associated(stream)) return
    bytes = int(c_lseek(c_fileno(stream), 0_c_long, seek_end), long_int)
    status = c_fclose(stream)
  end function file_size

  !> Reserve `bytes` of disk blocks just beyond the current end of the existing file `path`,
  !> without changing its size (fallocate with FALLOC_FL_KEEP_SIZE). Later writes that extend
  !> the file into the reserved range cannot fail for lack of space; when the disk is already
  !> too full, this fails first, before anything of the next piece is written.
  !> `reserved_end` is the end of what earlier calls reserved (0 for none): only the part
  !> beyond it is asked for, so that reserving again before each piece costs what is new.
  !> `error` is set only when the disk is full or the quota is exceeded (its message is the
  !> system's reason in lower case, e.g. "no space left on device"); a file system without
  !> fallocate (some network file systems) just gets no reservation.
  subroutine reserve_file_space(path, bytes, reserved_end, error)
    character(len=*), intent(in) :: path
    integer(long_int), intent(in) :: bytes
    integer(long_int), intent(inout) :: reserved_end
    type(error_t), allocatable, intent(out) :: error
    type(c_ptr) :: stream
    integer(c_long) :: end_of_file, start
    integer(c_int) :: status, ignored
    integer :: number

    if (bytes <= 0) return
    call clear_system_error()
    stream = c_fopen(path//c_null_char, "r+"//c_null_char)
    if (.not. c_associated(stream)) return
    end_of_file = c_lseek(c_fileno(stream), 0_c_long, seek_end)
    start = max(end_of_file, int(reserved_end, c_long))
    if (end_of_file >= 0 .and. start < end_of_file + int(bytes, c_long)) then
      status = c_fallocate(c_fileno(stream), fallocate_keep_size, start, &
                           end_of_file + int(bytes, c_long) - start)
      if (status == 0) then
        reserved_end = int(end_of_file, long_int) + bytes
      else
        number = system_error_number()
        if (number == error_no_space .or. number == error_quota_exceeded) &
          call make_error(error, lower_first(system_error_text(number)))
      end if
    end if
    ignored = c_fclose(stream)
  end subroutine reserve_file_space

  !> Give back what `reserve_file_space` reserved beyond the end of `path` and was not used, so
  !> a finished run occupies its size only: a hole punched from the end of the file on, and a
  !> truncation to the file's own size, which frees blocks beyond the end on file systems whose
  !> punch ignores them (ext4). The file's content and size do not change.
  subroutine release_file_space(path, bytes)
    character(len=*), intent(in) :: path
    integer(long_int), intent(in) :: bytes
    type(c_ptr) :: stream
    integer(c_long) :: end_of_file
    integer(c_int) :: status

    if (bytes <= 0) return
    stream = c_fopen(path//c_null_char, "r+"//c_null_char)
    if (.not. c_associated(stream)) return
    end_of_file = c_lseek(c_fileno(stream), 0_c_long, seek_end)
    if (end_of_file >= 0) then
      status = c_fallocate(c_fileno(stream), ior(fallocate_keep_size, fallocate_punch_hole), end_of_file, &
                           int(bytes, c_long))
      status = c_ftruncate(c_fileno(stream), end_of_file)
    end if
    status = c_fclose(stream)
  end subroutine release_file_space

  !> errno of the calling thread.
  function system_error_number() result(number)
    integer :: number
    integer(c_int), pointer :: errno
    call c_f_pointer(c_errno_location(), errno)
    number = int(errno)
  end function system_error_number

  !> Set errno to 0, so that a failure seen afterwards can be told from an older one.
  subroutine clear_system_error()
    integer(c_int), pointer :: errno
    call c_f_pointer(c_errno_location(), errno)
    errno = 0
  end subroutine clear_system_error

  !> The system's text for an errno value, e.g. "No space left on device".
  function system_error_text(number) result(text)
    integer, intent(in) :: number
    character(len=:), allocatable :: text
    character(kind=c_char, len=1), pointer :: characters(:)
    type(c_ptr) :: pointer
    integer :: length, position
    pointer = c_strerror(int(number, c_int))
    if (c_associated(pointer)) then
      length = int(c_strlen(pointer))
      call c_f_pointer(pointer, characters, [length])
      allocate (character(len=length) :: text)
      do position = 1, length
        text(position:position) = characters(position)
      end do
    else
      text = "error "//integer_text(number)
    end if
  end function system_error_text

  pure function lower_first(text) result(lowered)
    character(len=*), intent(in) :: text
    character(len=len(text)) :: lowered
    lowered = text
    if (len(text) > 0) then
      if (text(1:1) >= "A" .and. text(1:1) <= "Z") lowered(1:1) = achar(iachar(text(1:1)) + 32)
    end if
  end function lower_first
end module file_system
