!> The operating-system side of reading deck files: what kind of file a path names, and reads
!> of any number of bytes at any 64-bit offset.
!>
!> Fortran's own I/O cannot tell a regular file from a FIFO, a device or a directory (opening
!> a FIFO waits for a writer forever, and /dev/zero reads as an empty file), and gfortran will
!> not connect one file to two units, which the deck reader needs (it scans a file while it
!> reads *INCLUDE and *PARAMETER lines back from the same file). So the kind of a file comes
!> from Linux's statx(2), whose buffer layout is the same on every architecture, and bytes are
!> read with POSIX pread(2) at 64-bit offsets.
module deck_file_io
  use, intrinsic :: iso_c_binding, only: c_int, c_int16_t, c_int32_t, c_int64_t, c_long, &
                                         c_char, c_ptr, c_null_ptr, c_null_char, c_associated, &
                                         c_size_t
  use, intrinsic :: iso_fortran_env, only: int64
  use file_system, only: system_error_number
  implicit none
  private

  public :: inspect_file, open_file, read_bytes, close_file, file_handle_t

  !> What a path names.
  integer, parameter, public :: file_missing = 0, file_regular = 1, file_directory = 2, &
                                file_fifo = 3, file_device = 4, file_other = 5

  !> An open file (a C stream, and its descriptor for pread).
  type :: file_handle_t
    type(c_ptr) :: stream = c_null_ptr
    integer(c_int) :: descriptor = -1
  end type file_handle_t

  !> Linux's struct statx: 256 bytes, the fields used here at fixed offsets on every
  !> architecture (mode at byte 28, size at byte 40).
  type, bind(c) :: statx_t
    integer(c_int32_t) :: mask = 0, block_size = 0
    integer(c_int64_t) :: attributes = 0
    integer(c_int32_t) :: link_count = 0, user = 0, group = 0
    integer(c_int16_t) :: mode = 0, spare = 0
    integer(c_int64_t) :: inode = 0, size = 0, blocks = 0, attributes_mask = 0
    integer(c_int64_t) :: rest(24) = 0
  end type statx_t

  !> errno of an interrupted system call (EINTR, Linux).
  integer, parameter :: interrupted_call = 4

  !> statx arguments: paths relative to the working directory; the type, size and modification
  !> time wanted (STATX_TYPE | STATX_MODE | STATX_SIZE | STATX_MTIME).
  integer(c_int), parameter :: at_current_directory = -100, statx_type_and_size = 577
  !> struct statx's stx_mtime (seconds, then nanoseconds) is at byte 112: rest(7) and rest(8).
  integer, parameter :: modification_seconds = 7, modification_nanoseconds = 8
  !> File type bits of a mode (S_IFMT) and their values.
  integer, parameter :: type_bits = int(o'170000'), type_regular = int(o'100000'), &
                        type_directory = int(o'040000'), type_fifo = int(o'010000'), &
                        type_character_device = int(o'020000'), type_block_device = int(o'060000')

  interface
    function c_statx(directory, path, flags, mask, buffer) bind(c, name="statx") result(status)
      import :: c_int, c_char, statx_t
      integer(c_int), value :: directory
      character(kind=c_char), intent(in) :: path(*)
      integer(c_int), value :: flags
      integer(c_int), value :: mask
      type(statx_t), intent(inout) :: buffer
      integer(c_int) :: status
    end function c_statx

    function c_fopen(path, mode) bind(c, name="fopen") result(stream)
      import :: c_char, c_ptr
      character(kind=c_char), intent(in) :: path(*), mode(*)
      type(c_ptr) :: stream
    end function c_fopen

    function c_fileno(stream) bind(c, name="fileno") result(descriptor)
      import :: c_ptr, c_int
      type(c_ptr), value :: stream
      integer(c_int) :: descriptor
    end function c_fileno

    function c_fclose(stream) bind(c, name="fclose") result(status)
      import :: c_ptr, c_int
      type(c_ptr), value :: stream
      integer(c_int) :: status
    end function c_fclose

    !> ssize_t pread(int, void *, size_t, off_t): ssize_t and off_t are 64-bit longs on the
    !> 64-bit Linux platforms crashfree builds on.
    function c_pread(descriptor, buffer, count, offset) bind(c, name="pread") result(bytes)
      import :: c_int, c_char, c_size_t, c_long
      integer(c_int), value :: descriptor
      character(kind=c_char), intent(inout) :: buffer(*)
      integer(c_size_t), value :: count
      integer(c_long), value :: offset
      integer(c_long) :: bytes
    end function c_pread
  end interface

contains

  !> The kind of file `path` names (symbolic links followed) and, for a regular file, its
  !> size in bytes and its modification time (nanoseconds since 1970, to see whether the file
  !> changed while the deck was read).
  subroutine inspect_file(path, kind, size, modified)
    character(len=*), intent(in) :: path
    integer, intent(out) :: kind
    integer(int64), intent(out) :: size
    integer(int64), intent(out), optional :: modified
    type(statx_t) :: status_buffer
    integer :: file_type

    kind = file_missing
    size = 0
    if (present(modified)) modified = 0
    if (c_statx(at_current_directory, path//c_null_char, 0_c_int, statx_type_and_size, &
                status_buffer) /= 0) return
    if (present(modified)) modified = status_buffer%rest(modification_seconds)*1000000000_int64 + &
                                      iand(status_buffer%rest(modification_nanoseconds), 4294967295_int64)
    file_type = iand(iand(int(status_buffer%mode), 65535), type_bits)
    select case (file_type)
    case (type_regular)
      kind = file_regular
      size = status_buffer%size
    case (type_directory)
      kind = file_directory
    case (type_fifo)
      kind = file_fifo
    case (type_character_device, type_block_device)
      kind = file_device
    case default
      kind = file_other
    end select
  end subroutine inspect_file

  !> Open `path` for reading; `opened` is false when it cannot be opened.
  subroutine open_file(path, handle, opened)
    character(len=*), intent(in) :: path
    type(file_handle_t), intent(out) :: handle
    logical, intent(out) :: opened
    handle%stream = c_fopen(path//c_null_char, "r"//c_null_char)
    opened = c_associated(handle%stream)
    if (opened) handle%descriptor = c_fileno(handle%stream)
  end subroutine open_file

  !> Read up to len(buffer) bytes from byte `offset` (0 = the first byte) of the file into
  !> `buffer`; `count` is the number read (fewer at the end of the file). A read error other
  !> than an interruption sets `failed` (the bytes read before it are kept).
  subroutine read_bytes(handle, offset, buffer, count, failed)
    type(file_handle_t), intent(in) :: handle
    integer(int64), intent(in) :: offset
    character(len=*), intent(inout) :: buffer
    integer, intent(out) :: count
    logical, intent(out), optional :: failed
    integer(c_long) :: bytes
    integer :: filled, interruptions

    ! pread may return fewer bytes than asked (signals, some file systems): read on until the
    ! buffer is full or the file ends; an interrupted call (EINTR) is tried again.
    filled = 0
    interruptions = 0
    if (present(failed)) failed = .false.
    do while (filled < len(buffer))
      bytes = c_pread(handle%descriptor, buffer(filled + 1:), &
                      int(len(buffer) - filled, c_size_t), int(offset + filled, c_long))
      if (bytes == 0) exit
      if (bytes < 0) then
        interruptions = interruptions + 1
        if (system_error_number() == interrupted_call .and. interruptions < 100) cycle
        if (present(failed)) failed = .true.
        exit
      end if
      filled = filled + int(bytes)
    end do
    count = filled
  end subroutine read_bytes

  !> Close a file opened by `open_file` (nothing when it is not open).
  subroutine close_file(handle)
    type(file_handle_t), intent(inout) :: handle
    integer(c_int) :: status
    if (c_associated(handle%stream)) status = c_fclose(handle%stream)
    handle%stream = c_null_ptr
    handle%descriptor = -1
  end subroutine close_file
end module deck_file_io
