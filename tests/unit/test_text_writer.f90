!> Unit tests of the bounded writer of LS-DYNA's ASCII files (ascii_databases' text_writer_t):
!> a file of several buffers' worth of lines of every length (pieces ending anywhere in a
!> line), with a text longer than the buffer in the middle, is byte for byte the text added;
!> a file that existed is replaced, not appended to; a writer given nothing leaves an empty
!> file; a file that cannot be created gives the path and the system's reason, and nothing
!> else is written.
program test_text_writer
  use error_handling, only: error_t
  use ascii_databases, only: text_writer_t, begin_text, add_line, add_text, finish_database
  use testing, only: test_suite_t, check, finish_suite
  implicit none

  !> the writer's buffer is 1 MiB: the texts below are several times that
  integer, parameter :: mebibyte = 1048576
  type(test_suite_t) :: suite
  character(len=:), allocatable :: directory

  suite%name = "text_writer"
  call make_directory(directory)
  call test_many_buffers(directory//"/many")
  call test_replaces_a_file(directory//"/replaced")
  call test_empty_file(directory//"/empty")
  call test_cannot_create(directory//"/no_such_directory/d3hsp")
  call execute_command_line("rm -rf '"//directory//"'")
  call finish_suite(suite)

contains

  !> Lines of 0 to 400 characters (about 3.5 MiB), a text of 2.5 MiB without new line in the
  !> middle, then more lines: the file holds exactly what was added, in order.
  subroutine test_many_buffers(path)
    character(len=*), intent(in) :: path
    type(text_writer_t) :: out
    type(error_t), allocatable :: error
    character(len=:), allocatable :: expected, line, long_text, written
    integer :: k, length, position

    allocate (character(len=8*mebibyte) :: expected)
    position = 0
    call begin_text(out, path)
    do k = 1, 17000
      length = mod(k*37, 401)
      line = repeat(achar(iachar("a") + mod(k, 26)), length)
      if (length > 0) line(1:1) = "$"
      call add_line(out, line)
      expected(position + 1:position + length + 1) = line//new_line("a")
      position = position + length + 1
      if (k == 9000) then
        long_text = repeat("0123456789", mebibyte/4)
        call add_text(out, long_text)
        expected(position + 1:position + len(long_text)) = long_text
        position = position + len(long_text)
      end if
    end do
    call finish_database(out, error)
    call check(suite, "many buffers: written without error", .not. allocated(error))
    call check(suite, "many buffers: more than three buffers' worth", position > 3*mebibyte)
    call read_file(path, written)
    call check(suite, "many buffers: the file's size", len(written) == position)
    if (len(written) == position) &
      call check(suite, "many buffers: the file's bytes", written == expected(1:position))
  end subroutine test_many_buffers

  !> A file longer than the new text is replaced (created again), not written over or appended to.
  subroutine test_replaces_a_file(path)
    character(len=*), intent(in) :: path
    type(text_writer_t) :: out
    type(error_t), allocatable :: error
    character(len=:), allocatable :: written
    integer :: unit
    open (newunit=unit, file=path, access="stream", form="unformatted", status="replace", action="write")
    write (unit) repeat("old text ", 300000)
    close (unit)
    call begin_text(out, path)
    call add_line(out, " first")
    call add_line(out, " second")
    call finish_database(out, error)
    call check(suite, "replaced: written without error", .not. allocated(error))
    call read_file(path, written)
    call check(suite, "replaced: only the new text", &
               written == " first"//new_line("a")//" second"//new_line("a"), written(1:min(len(written), 40)))
  end subroutine test_replaces_a_file

  subroutine test_empty_file(path)
    character(len=*), intent(in) :: path
    type(text_writer_t) :: out
    type(error_t), allocatable :: error
    logical :: exists
    integer :: bytes
    call begin_text(out, path)
    call finish_database(out, error)
    call check(suite, "empty: written without error", .not. allocated(error))
    inquire (file=path, exist=exists, size=bytes)
    call check(suite, "empty: the file exists and is empty", exists .and. bytes == 0)
  end subroutine test_empty_file

  !> More than a buffer added to a file that cannot be created: the first failure is reported
  !> once, at the end, with the path and the reason in lower case.
  subroutine test_cannot_create(path)
    character(len=*), intent(in) :: path
    type(text_writer_t) :: out
    type(error_t), allocatable :: error
    integer :: k
    call begin_text(out, path)
    do k = 1, 30000
      call add_line(out, repeat("x", 80))
    end do
    call finish_database(out, error)
    call check(suite, "cannot create: an error", allocated(error))
    if (allocated(error)) call check(suite, "cannot create: path and reason", &
                                     error%message == "cannot write "//path//": no such file or directory", &
                                     error%message)
  end subroutine test_cannot_create

  subroutine read_file(path, text)
    character(len=*), intent(in) :: path
    character(len=:), allocatable, intent(out) :: text
    integer :: unit, bytes, status
    open (newunit=unit, file=path, access="stream", form="unformatted", status="old", action="read", iostat=status)
    if (status /= 0) then
      text = ""
      return
    end if
    inquire (unit=unit, size=bytes)
    allocate (character(len=bytes) :: text)
    if (bytes > 0) read (unit) text
    close (unit)
  end subroutine read_file

  subroutine make_directory(directory)
    character(len=:), allocatable, intent(out) :: directory
    character(len=1024) :: value
    integer :: length, status, clock(8)
    real :: random
    call get_environment_variable("TMPDIR", value, length, status)
    if (status /= 0 .or. length == 0) value = "/tmp"
    call date_and_time(values=clock)
    call random_seed()
    call random_number(random)
    write (value, '(a,"/crashfree_test_text_writer_",i2.2,i2.2,i2.2,i3.3,"_",i6.6)') trim(value), clock(5:8), &
      int(random*1.0e6)
    directory = trim(value)
    call execute_command_line("mkdir -p '"//directory//"'", exitstat=status)
    call check(suite, "temporary directory created", status == 0, directory)
  end subroutine make_directory
end program test_text_writer
