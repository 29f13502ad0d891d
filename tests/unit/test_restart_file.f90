!> Unit tests of the restart dump store (restart_file) and the deck signature (deck_signature):
!> every kind and rank of value written and read back bit for bit, through `exchange_restart`
!> both ways; header attributes; the checks on reading (missing dataset, shape, kind) and their
!> messages; resized reads; the temporary name and the rename (a discarded dump leaves the
!> previous file of that name whole); FNV-1a against its published test values.
program test_restart_file
  use, intrinsic :: iso_fortran_env, only: int64
  use kinds, only: wp
  use error_handling, only: error_t
  use restart_file, only: restart_store_t, create_restart_store, commit_restart_store, discard_restart_store, &
                          open_restart_store, close_restart_store, write_restart, read_restart, &
                          read_restart_resized, exchange_restart, write_restart_attribute, read_restart_attribute, &
                          restart_entry_exists, start_memory_store
  use deck_signature, only: fnv1a_hash, hash_text
  use testing, only: test_suite_t, check, finish_suite
  implicit none

  type(test_suite_t) :: suite
  character(len=:), allocatable :: directory

  suite%name = "restart_file"
  call make_directory(directory)
  call test_values_round_trip(directory//"/values")
  call test_read_checks(directory//"/values")
  call test_discarded_dump_keeps_the_previous_file(directory//"/kept")
  call test_fnv1a()
  call test_memory_round_trip()
  call execute_command_line("rm -rf '"//directory//"'")
  call finish_suite(suite)

contains

  !> A store in memory (how the ranks of a distributed run move blocks): values of every kind
  !> and rank back bit for bit in the order written, past the first buffer's size.
  subroutine test_memory_round_trip()
    type(restart_store_t) :: store, reader
    type(error_t), allocatable :: error
    real(wp) :: scalar, large(3, 2000), scalar_in, large_in(3, 2000)
    integer :: count, table(2, 3), count_in, table_in(2, 3), k
    logical :: flags(3), flags_in(3)
    call random_number(large)
    large(1, 1) = -0.0_wp
    large(2, 1) = huge(1.0_wp)
    scalar = -tiny(1.0_wp)
    count = -huge(1)
    table = reshape([(k - 3, k=1, 6)], [2, 3])
    flags = [.true., .false., .true.]
    call start_memory_store(store, .true.)
    call exchange_restart(store, "scalar", scalar, error)
    call exchange_restart(store, "large", large, error)
    call exchange_restart(store, "count", count, error)
    call exchange_restart(store, "table", table, error)
    call exchange_restart(store, "flags", flags, error)
    call check(suite, "memory: written", .not. allocated(error) .and. store%position == 1 + 6000 + 1 + 6 + 3)
    reader%memory = store%memory(1:store%position)
    call start_memory_store(reader, .false.)
    scalar_in = 0.0_wp
    large_in = 1.0_wp
    count_in = 0
    table_in = 0
    flags_in = .false.
    call exchange_restart(reader, "scalar", scalar_in, error)
    call exchange_restart(reader, "large", large_in, error)
    call exchange_restart(reader, "count", count_in, error)
    call exchange_restart(reader, "table", table_in, error)
    call exchange_restart(reader, "flags", flags_in, error)
    call check(suite, "memory: read in order", .not. allocated(error) .and. reader%position == store%position)
    call check(suite, "memory: reals bit for bit", scalar_in == scalar .and. all(large_in == large) .and. &
               sign(1.0_wp, large_in(1, 1)) < 0.0_wp)
    call check(suite, "memory: integers and logicals", count_in == count .and. all(table_in == table) .and. &
               all(flags_in .eqv. flags))
  end subroutine test_memory_round_trip

  subroutine test_values_round_trip(path)
    character(len=*), intent(in) :: path
    type(restart_store_t) :: store
    type(error_t), allocatable :: error
    real(wp) :: scalar, vector(5), matrix(3, 4), cube(2, 3, 4), tesseract(2, 2, 3, 2), empty(3, 0)
    real(wp) :: scalar_in, vector_in(5), matrix_in(3, 4), cube_in(2, 3, 4), tesseract_in(2, 2, 3, 2), empty_in(3, 0)
    integer :: count, list(4), table(2, 3), block(2, 2, 2), count_in, list_in(4), table_in(2, 3), block_in(2, 2, 2)
    logical :: flag, flags(3), mask(2, 2), flag_in, flags_in(3), mask_in(2, 2)
    character(len=:), allocatable :: text, text_in, header
    real(wp), allocatable :: grown(:, :)
    integer :: k, header_count
    real(wp) :: header_time

    call random_number(vector)
    call random_number(matrix)
    call random_number(cube)
    call random_number(tesseract)
    scalar = -huge(1.0_wp)
    vector(2) = tiny(1.0_wp)
    matrix(1, 1) = -0.0_wp
    count = -7
    list = [1, -2, huge(1), -huge(1)]
    table = reshape([(k, k=1, 6)], [2, 3])
    block = reshape([(10*k, k=1, 8)], [2, 2, 2])
    flag = .true.
    flags = [.true., .false., .true.]
    mask = reshape([.false., .true., .true., .false.], [2, 2])
    text = "a text with "//achar(10)//"a line end, and bytes "//char(200)//achar(0)//"."

    call create_restart_store(store, path, error)
    call check(suite, "create", .not. allocated(error))
    call exchange_restart(store, "reals/scalar", scalar, error)
    call exchange_restart(store, "reals/vector", vector, error)
    call exchange_restart(store, "reals/matrix", matrix, error)
    call exchange_restart(store, "reals/cube", cube, error)
    call exchange_restart(store, "reals/tesseract", tesseract, error)
    call exchange_restart(store, "reals/empty", empty, error)
    call exchange_restart(store, "integers/scalar", count, error)
    call exchange_restart(store, "integers/list", list, error)
    call exchange_restart(store, "integers/table", table, error)
    call exchange_restart(store, "integers/block", block, error)
    call exchange_restart(store, "logicals/scalar", flag, error)
    call exchange_restart(store, "logicals/list", flags, error)
    call exchange_restart(store, "logicals/mask", mask, error)
    call write_restart(store, "text", text, error)
    call write_restart(store, "empty_text", "", error)
    call write_restart_attribute(store, "version", "9.8.7", error)
    call write_restart_attribute(store, "time", 0.125_wp, error)
    call write_restart_attribute(store, "cycle", 4711, error)
    call check(suite, "write everything", .not. allocated(error), message(error))
    call check(suite, "written under the temporary name", file_exists(path//".tmp") .and. .not. file_exists(path))
    call commit_restart_store(store, error)
    call check(suite, "commit renames", .not. allocated(error) .and. file_exists(path) .and. &
               .not. file_exists(path//".tmp"), message(error))

    call open_restart_store(store, path, error)
    call check(suite, "open", .not. allocated(error), message(error))
    call exchange_restart(store, "reals/scalar", scalar_in, error)
    call exchange_restart(store, "reals/vector", vector_in, error)
    call exchange_restart(store, "reals/matrix", matrix_in, error)
    call exchange_restart(store, "reals/cube", cube_in, error)
    call exchange_restart(store, "reals/tesseract", tesseract_in, error)
    call exchange_restart(store, "reals/empty", empty_in, error)
    call exchange_restart(store, "integers/scalar", count_in, error)
    call exchange_restart(store, "integers/list", list_in, error)
    call exchange_restart(store, "integers/table", table_in, error)
    call exchange_restart(store, "integers/block", block_in, error)
    call exchange_restart(store, "logicals/scalar", flag_in, error)
    call exchange_restart(store, "logicals/list", flags_in, error)
    call exchange_restart(store, "logicals/mask", mask_in, error)
    call read_restart(store, "text", text_in, error)
    call check(suite, "read everything", .not. allocated(error), message(error))
    call check(suite, "reals", scalar_in == scalar .and. all(vector_in == vector) .and. &
               all(matrix_in == matrix) .and. all(cube_in == cube) .and. all(tesseract_in == tesseract))
    call check(suite, "negative zero kept", sign(1.0_wp, matrix_in(1, 1)) < 0.0_wp)
    call check(suite, "integers", count_in == count .and. all(list_in == list) .and. all(table_in == table) .and. &
               all(block_in == block))
    call check(suite, "logicals", (flag_in .eqv. flag) .and. all(flags_in .eqv. flags) .and. all(mask_in .eqv. mask))
    call check(suite, "text bytes", text_in == text .and. len(text_in) == len(text))
    call read_restart(store, "empty_text", text_in, error)
    call check(suite, "empty text", .not. allocated(error) .and. len(text_in) == 0, message(error))
    call read_restart_attribute(store, "version", header, error)
    call read_restart_attribute(store, "time", header_time, error)
    call read_restart_attribute(store, "cycle", header_count, error)
    call check(suite, "header attributes", .not. allocated(error) .and. header == "9.8.7" .and. &
               header_time == 0.125_wp .and. header_count == 4711, message(error))
    allocate (grown(1, 1))
    call read_restart_resized(store, "reals/matrix", grown, error)
    call check(suite, "resized read", .not. allocated(error) .and. all(shape(grown) == [3, 4]) .and. &
               all(grown == matrix), message(error))
    call check(suite, "entry exists", restart_entry_exists(store, "reals/cube") .and. &
               .not. restart_entry_exists(store, "reals/nothing") .and. .not. restart_entry_exists(store, "no/such/path"))
    call close_restart_store(store)
  end subroutine test_values_round_trip

  subroutine test_read_checks(path)
    character(len=*), intent(in) :: path
    type(restart_store_t) :: store
    type(error_t), allocatable :: error
    real(wp) :: wrong(4, 3), vector(5)
    integer :: list(5)
    character(len=:), allocatable :: text
    call open_restart_store(store, path, error)
    call read_restart(store, "reals/matrix", wrong, error)
    call check(suite, "shape checked", has(error, "restart dump "//path//": reals/matrix: shape (3,4), this "// &
               "model needs (4,3)"), message(error))
    deallocate (error)
    call read_restart(store, "reals/missing", vector, error)
    call check(suite, "missing dataset named", has(error, "reals/missing: missing"), message(error))
    deallocate (error)
    call read_restart(store, "reals/vector", list, error)
    call check(suite, "kind checked", has(error, "reals/vector: holds reals, integers expected"), message(error))
    deallocate (error)
    call read_restart_attribute(store, "nothing", text, error)
    call check(suite, "missing attribute", has(error, "nothing: missing"), message(error))
    ! the chain stops at the first failure
    call read_restart(store, "reals/vector", vector, error)
    call check(suite, "nothing read after a failure", has(error, "nothing: missing"), message(error))
    call close_restart_store(store)
    deallocate (error)
    call open_restart_store(store, path//".none", error)
    call check(suite, "missing dump", has(error, "does not exist"), message(error))
  end subroutine test_read_checks

  subroutine test_discarded_dump_keeps_the_previous_file(path)
    character(len=*), intent(in) :: path
    type(restart_store_t) :: store
    type(error_t), allocatable :: error
    integer :: value
    call create_restart_store(store, path, error)
    call write_restart(store, "value", 1, error)
    call commit_restart_store(store, error)
    call create_restart_store(store, path, error)
    call write_restart(store, "value", 2, error)
    call discard_restart_store(store)
    call check(suite, "temporary file removed", .not. file_exists(path//".tmp"))
    value = 0
    call open_restart_store(store, path, error)
    call read_restart(store, "value", value, error)
    call close_restart_store(store)
    call check(suite, "previous dump kept", .not. allocated(error) .and. value == 1, message(error))
    call create_restart_store(store, path, error)
    call write_restart(store, "value", 3, error)
    call commit_restart_store(store, error)
    call open_restart_store(store, path, error)
    call read_restart(store, "value", value, error)
    call close_restart_store(store)
    call check(suite, "replaced by the next commit", .not. allocated(error) .and. value == 3, message(error))
  end subroutine test_discarded_dump_keeps_the_previous_file

  !> FNV-1a 64 of "", "a" and "foobar" (the reference values of the algorithm's authors).
  subroutine test_fnv1a()
    call check(suite, "fnv1a ''", hashed("") == "cbf29ce484222325", hashed(""))
    call check(suite, "fnv1a 'a'", hashed("a") == "af63dc4c8601ec8c", hashed("a"))
    call check(suite, "fnv1a 'foobar'", hashed("foobar") == "85944171f73967e8", hashed("foobar"))
    call check(suite, "fnv1a in pieces", hashed("foo", "bar") == hashed("foobar"))
    call check(suite, "fnv1a high bytes", hashed(char(255)//char(128)) /= hashed(achar(127)//achar(0)))
  end subroutine test_fnv1a

  function hashed(first, second) result(text)
    character(len=*), intent(in) :: first
    character(len=*), intent(in), optional :: second
    character(len=16) :: text
    integer(int64) :: high, low
    high = 3421674724_int64
    low = 2216829733_int64
    call fnv1a_hash(first, high, low)
    if (present(second)) call fnv1a_hash(second, high, low)
    text = hash_text(high, low)
  end function hashed

  logical function has(error, text)
    type(error_t), allocatable, intent(in) :: error
    character(len=*), intent(in) :: text
    has = .false.
    if (allocated(error)) has = index(error%message, text) > 0
  end function has

  function message(error) result(text)
    type(error_t), allocatable, intent(in) :: error
    character(len=:), allocatable :: text
    text = "(no error)"
    if (allocated(error)) text = error%message
  end function message

  logical function file_exists(path)
    character(len=*), intent(in) :: path
    inquire (file=path, exist=file_exists)
  end function file_exists

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
    write (value, '(a,"/crashfree_test_restart_",i2.2,i2.2,i2.2,i3.3,"_",i6.6)') trim(value), clock(5:8), &
      int(random*1.0e6_wp)
    directory = trim(value)
    call execute_command_line("mkdir -p '"//directory//"'", exitstat=status)
    call check(suite, "temporary directory created", status == 0, directory)
  end subroutine make_directory
end program test_restart_file
