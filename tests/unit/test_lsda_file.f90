!> Unit tests of the LSDA container (lsda_file), the format of binout: arrays of every type
!> (I1..I8, U1..U8 tagged, R4, R8, text) written in nested and relative directories over two
!> flushes (two chained symbol tables) and read back bit for bit; a variable written again
!> reads as its last values; the record layout at the start of the file; the checks on reading
!> (missing variable, wrong type, not an LSDA file) and on writing (names) with their messages.
program test_lsda_file
  use, intrinsic :: iso_fortran_env, only: int8, int16, int32, int64, real32, real64
  use kinds, only: wp
  use error_handling, only: error_t
  use lsda_file, only: lsda_file_t, create_lsda, change_lsda_directory, write_lsda, flush_lsda, close_lsda, &
                       open_lsda, find_lsda_entry, read_lsda, lsda_i1, lsda_u2, lsda_i4, lsda_u8, lsda_r4, lsda_r8
  use testing, only: test_suite_t, check, finish_suite
  implicit none

  type(test_suite_t) :: suite
  character(len=:), allocatable :: directory

  suite%name = "lsda_file"
  call make_directory(directory)
  call test_round_trip(directory//"/binout")
  call test_layout(directory//"/binout")
  call test_read_checks(directory//"/binout", directory//"/not_lsda")
  call test_many_variables(directory//"/many")
  call execute_command_line("rm -rf '"//directory//"'")
  call finish_suite(suite)

contains

  subroutine test_round_trip(path)
    character(len=*), intent(in) :: path
    type(lsda_file_t) :: file
    type(error_t), allocatable :: error
    integer(int8) :: octets(4)
    integer(int16) :: halves(3)
    integer(int32) :: ints(5)
    integer(int64) :: longs(2)
    real(real32) :: singles(3)
    real(real64) :: doubles(6), time
    integer(int8), allocatable :: octets_in(:)
    integer(int16), allocatable :: halves_in(:)
    integer(int32), allocatable :: ints_in(:)
    integer(int64), allocatable :: longs_in(:)
    real(real32), allocatable :: singles_in(:)
    real(real64), allocatable :: doubles_in(:), time_in(:)
    character(len=:), allocatable :: text_in
    character(len=255) :: long_name

    octets = [-127_int8 - 1_int8, -1_int8, 0_int8, 127_int8]
    halves = [-32767_int16 - 1_int16, 7_int16, 32767_int16]
    ints = [-huge(1_int32) - 1_int32, -1_int32, 0_int32, 1_int32, huge(1_int32)]
    longs = [-huge(1_int64), huge(1_int64)]
    singles = [tiny(1.0_real32), -huge(1.0_real32), 0.1_real32]
    call random_number(doubles)
    doubles(2) = -0.0_real64
    doubles(3) = huge(1.0_real64)
    time = 1.25e-3_real64
    long_name = repeat("n", 255)

    call create_lsda(file, path, error)
    call check(suite, "create", .not. allocated(error))
    call change_lsda_directory(file, "/nodout/metadata")
    call write_lsda(file, "title", "a title with spaces ", error)
    call write_lsda(file, "ids", ints, error)
    call write_lsda(file, "octets", octets, error)
    call write_lsda(file, "halves", halves, error, unsigned=.true.)
    call change_lsda_directory(file, "../d000001")
    call write_lsda(file, "time", [time], error)
    call write_lsda(file, "x_displacement", doubles, error)
    call write_lsda(file, "singles", singles, error)
    call write_lsda(file, long_name, longs, error, unsigned=.true.)
    call check(suite, "writes before the first flush", .not. allocated(error))
    call flush_lsda(file, error)
    call check(suite, "first flush", .not. allocated(error))
    ! a second symbol table, chained from the first: a new directory, and a variable again
    call change_lsda_directory(file, "/glstat/d000001")
    call write_lsda(file, "kinetic_energy", [2.5_real64], error)
    call change_lsda_directory(file, "/nodout/d000001")
    call write_lsda(file, "time", [2.0_real64*time], error)
    call close_lsda(file, error)
    call check(suite, "close", .not. allocated(error))

    call open_lsda(file, path, error)
    call check(suite, "open", .not. allocated(error))
    if (allocated(error)) return
    call check(suite, "every variable listed once", file%entry_count == 9)
    call read_lsda(file, "/nodout/metadata/title", text_in, error)
    call check(suite, "text", .not. allocated(error) .and. text_in == "a title with spaces ")
    call check(suite, "text as I1", file%entries(find_lsda_entry(file, "/nodout/metadata/title"))%type_code == lsda_i1)
    call read_lsda(file, "/nodout/metadata/ids", ints_in, error)
    call check(suite, "I4", .not. allocated(error) .and. same_ints(int(ints, int64), int(ints_in, int64)))
    call check(suite, "I4 type id", file%entries(find_lsda_entry(file, "/nodout/metadata/ids"))%type_code == lsda_i4)
    call read_lsda(file, "/nodout/metadata/octets", octets_in, error)
    call check(suite, "I1", .not. allocated(error) .and. same_ints(int(octets, int64), int(octets_in, int64)))
    call read_lsda(file, "/nodout/metadata/halves", halves_in, error)
    call check(suite, "U2", .not. allocated(error) .and. same_ints(int(halves, int64), int(halves_in, int64)))
    call check(suite, "U2 type id", file%entries(find_lsda_entry(file, "/nodout/metadata/halves"))%type_code == lsda_u2)
    call read_lsda(file, "/nodout/d000001/x_displacement", doubles_in, error)
    call check(suite, "R8 bit for bit", .not. allocated(error) .and. same_doubles(doubles, doubles_in))
    call check(suite, "R8 type id", &
               file%entries(find_lsda_entry(file, "/nodout/d000001/x_displacement"))%type_code == lsda_r8)
    call read_lsda(file, "/nodout/d000001/singles", singles_in, error)
    call check(suite, "R4 bit for bit", .not. allocated(error) .and. size(singles_in) == 3 .and. &
               all(transfer(singles_in, 1_int32, 3) == transfer(singles, 1_int32, 3)))
    call check(suite, "R4 type id", file%entries(find_lsda_entry(file, "/nodout/d000001/singles"))%type_code == lsda_r4)
    call read_lsda(file, "/nodout/d000001/"//long_name, longs_in, error)
    call check(suite, "U8 with a 255-character name", .not. allocated(error) .and. same_ints(longs, longs_in))
    call check(suite, "U8 type id", &
               file%entries(find_lsda_entry(file, "/nodout/d000001/"//long_name))%type_code == lsda_u8)
    call read_lsda(file, "/glstat/d000001/kinetic_energy", doubles_in, error)
    call check(suite, "second symbol table", .not. allocated(error) .and. same_doubles([2.5_real64], doubles_in))
    call read_lsda(file, "/nodout/d000001/time", time_in, error)
    call check(suite, "a variable written again reads as its last values", &
               .not. allocated(error) .and. same_doubles([2.0_real64*time], time_in))
    call close_lsda(file, error)
  end subroutine test_round_trip

  !> The first records as the format defines them: the header, SYMBOLTABLEOFFSET (17 octets,
  !> command 7, the offset of the first table), then a CD to the first directory.
  subroutine test_layout(path)
    character(len=*), intent(in) :: path
    integer(int8) :: header(8), command, cd_command
    integer(int64) :: length, table_offset, cd_length, table_length
    integer :: unit, status
    character(len=16) :: directory
    integer(int64) :: file_bytes
    open (newunit=unit, file=path, access="stream", form="unformatted", status="old", action="read", iostat=status)
    call check(suite, "layout: the file opens", status == 0)
    if (status /= 0) return
    inquire (unit=unit, size=file_bytes)
    read (unit, iostat=status) header, length, command, table_offset, cd_length, cd_command, directory
    call check(suite, "layout: header", status == 0 .and. all(header(1:5) == [8_int8, 8_int8, 8_int8, 1_int8, 1_int8]))
    call check(suite, "layout: SYMBOLTABLEOFFSET record", length == 17 .and. command == 7)
    call check(suite, "layout: the first table inside the file", table_offset > 25 .and. table_offset < file_bytes)
    call check(suite, "layout: CD to the first directory", cd_length == 9 + 16 .and. cd_command == 2 .and. &
               directory == "/nodout/metadata")
    read (unit, pos=table_offset + 1, iostat=status) table_length, command
    call check(suite, "layout: BEGINSYMBOLTABLE", status == 0 .and. command == 5 .and. &
               table_offset + table_length <= file_bytes)
    close (unit)
  end subroutine test_layout

  subroutine test_read_checks(path, other_path)
    character(len=*), intent(in) :: path, other_path
    type(lsda_file_t) :: file
    type(error_t), allocatable :: error
    real(real64), allocatable :: doubles_in(:)
    integer(int32), allocatable :: ints_in(:)
    integer :: unit

    call open_lsda(file, path, error)
    if (allocated(error)) return
    call read_lsda(file, "/nodout/d000002/time", doubles_in, error)
    call check(suite, "missing variable: message", allocated(error), "no error")
    if (allocated(error)) call check(suite, "missing variable: names it", &
                                     index(error%message, "no variable /nodout/d000002/time") > 0, error%message)
    call read_lsda(file, "/nodout/d000001/time", ints_in, error)
    call check(suite, "wrong type: message", allocated(error), "no error")
    if (allocated(error)) call check(suite, "wrong type: says so", index(error%message, "LSDA type 10") > 0, &
                                     error%message)
    call close_lsda(file, error)

    open (newunit=unit, file=other_path, access="stream", form="unformatted", status="replace")
    write (unit) "not an LSDA file at all, only text"
    close (unit)
    call open_lsda(file, other_path, error)
    call check(suite, "not LSDA: refused", allocated(error), "no error")
    if (allocated(error)) call check(suite, "not LSDA: says so", index(error%message, "not an LSDA file") > 0, &
                                     error%message)

    call create_lsda(file, other_path, error)
    call write_lsda(file, "a/b", [1.0_real64], error)
    call check(suite, "a name with / refused", allocated(error), "no error")
    call write_lsda(file, repeat("n", 256), [1.0_real64], error)
    call check(suite, "a name of 256 characters refused", allocated(error), "no error")
    call close_lsda(file, error)
  end subroutine test_read_checks

  !> More variables than one symbol table holds: the writer flushes on its own (a chain of
  !> tables) and every variable reads back.
  subroutine test_many_variables(path)
    character(len=*), intent(in) :: path
    type(lsda_file_t) :: file
    type(error_t), allocatable :: error
    real(real64), allocatable :: values_in(:)
    character(len=16) :: sample
    integer :: k, wrong
    integer, parameter :: samples = 5000

    call create_lsda(file, path, error)
    do k = 1, samples
      write (sample, '("d", i6.6)') k
      call change_lsda_directory(file, "/glstat/"//trim(sample))
      call write_lsda(file, "time", [real(k, real64)], error)
      if (allocated(error)) exit
      call write_lsda(file, "kinetic_energy", [1.0_real64/k], error)
      if (allocated(error)) exit
    end do
    call check(suite, "many: written", .not. allocated(error))
    call check(suite, "many: the writer keeps only the variables of the table to come", &
               size(file%entries) <= 2*4096 .and. file%entry_count < 4096)
    call close_lsda(file, error)
    call open_lsda(file, path, error)
    call check(suite, "many: open", .not. allocated(error))
    if (allocated(error)) return
    call check(suite, "many: every variable listed", file%entry_count == 2*samples)
    wrong = 0
    do k = 1, samples, 97
      write (sample, '("d", i6.6)') k
      call read_lsda(file, "/glstat/"//trim(sample)//"/kinetic_energy", values_in, error)
      if (allocated(error)) then
        wrong = wrong + 1
      else if (.not. same_doubles([1.0_real64/k], values_in)) then
        wrong = wrong + 1
      end if
    end do
    call check(suite, "many: values read back", wrong == 0)
    call close_lsda(file, error)
  end subroutine test_many_variables

  logical function same_ints(expected, actual)
    integer(int64), intent(in) :: expected(:), actual(:)
    same_ints = size(expected) == size(actual)
    if (same_ints) same_ints = all(expected == actual)
  end function same_ints

  logical function same_doubles(expected, actual)
    real(real64), intent(in) :: expected(:), actual(:)
    same_doubles = size(expected) == size(actual)
    if (same_doubles) same_doubles = all(transfer(expected, 1_int64, size(expected)) == &
                                         transfer(actual, 1_int64, size(actual)))
  end function same_doubles

  subroutine make_directory(directory)
    character(len=:), allocatable, intent(out) :: directory
    character(len=1024) :: value
    integer :: length, status, clock(8)
    real(wp) :: random
    call get_environment_variable("TMPDIR", value, length, status)
    if (status /= 0 .or. length == 0) value = "/tmp"
    call date_and_time(values=clock)
    call random_seed()
    call random_number(random)
    write (value, '(a,"/crashfree_test_lsda_",i2.2,i2.2,i2.2,i3.3,"_",i6.6)') trim(value), clock(5:8), &
      int(random*1.0e6_wp)
    directory = trim(value)
    call execute_command_line("mkdir -p '"//directory//"'", exitstat=status)
    call check(suite, "temporary directory created", status == 0, directory)
  end subroutine make_directory
end program test_lsda_file
