!> A restart dump as a store of named arrays: one HDF5 file whose datasets are named by paths
!> such as "nodes/velocity" or "solids/3/stress", plus a few header attributes on its root
!> (format, version, deck signature, time, cycle). What goes into a dump is decided by
!> run_state_dump; this module only stores and checks.
!>
!> - Reals are IEEE 64-bit, integers 32-bit, logicals 8-bit integers (0 or 1), text 8-bit
!>   integers (its bytes). Fortran's shape is kept: a Fortran `(3, n)` array is stored with
!>   HDF5 dimensions `(n, 3)`, as h5py shows it, and reads back as `(3, n)`. Scalars are
!>   scalar datasets.
!> - A dump is written under a temporary name (`NAME.tmp` beside it), flushed and synced to
!>   the disk, and then renamed to its name in one step: a run killed at any moment leaves
!>   either the previous file of that name or the complete new one, never half a dump.
!> - Reading checks that a dataset exists and has the shape and the kind (real or integer) the
!>   caller expects; the message names the dump and the dataset ("restart dump out/d3dump02:
!>   solids/3/stress: shape (64,6,1), this model needs (64,6,8)"). `read_restart_resized`
!>   takes the stored shape instead, for arrays that grow during a run (contact search lists).
!> - Errors follow the chain style of results_file: every routine does nothing once `error`
!>   is allocated, so a sequence of writes or reads reads as a list and stops at the first
!>   failure.
module restart_file
  use, intrinsic :: iso_c_binding, only: c_ptr, c_loc, c_null_ptr, c_char, c_null_char, c_int, &
                                         c_associated
  use, intrinsic :: iso_fortran_env, only: int8
  use hdf5, only: hid_t, hsize_t, size_t, h5open_f, h5eset_auto_f, h5dont_atexit_f, &
                  h5fcreate_f, h5fopen_f, h5fclose_f, h5fflush_f, H5F_ACC_TRUNC_F, H5F_ACC_RDONLY_F, &
                  H5F_SCOPE_GLOBAL_F, h5pcreate_f, h5pclose_f, h5pset_file_locking_f, H5P_FILE_ACCESS_F, &
                  h5gcreate_f, h5gclose_f, h5lexists_f, h5screate_f, h5screate_simple_f, h5sclose_f, &
                  h5sget_simple_extent_ndims_f, h5sget_simple_extent_dims_f, H5S_SCALAR_F, &
                  h5dcreate_f, h5dopen_f, h5dclose_f, h5dwrite_f, h5dread_f, h5dget_space_f, h5dget_type_f, &
                  h5acreate_f, h5aopen_f, h5aclose_f, h5awrite_f, h5aread_f, h5aget_type_f, h5aexists_f, &
                  h5tcopy_f, h5tclose_f, h5tset_size_f, h5tget_size_f, h5tset_strpad_f, h5tget_class_f, &
                  H5T_FORTRAN_S1, H5T_STR_NULLTERM_F, H5T_STRING_F, H5T_FLOAT_F, H5T_INTEGER_F, &
                  H5T_NATIVE_INTEGER, H5T_STD_I32LE, H5T_STD_I8LE, H5T_IEEE_F64LE, h5kind_to_type, &
                  H5_REAL_KIND, H5_INTEGER_KIND
  use kinds, only: wp
  use error_handling, only: error_t, make_error
  use file_system, only: rename_file, remove_file, clear_system_error, system_error_number, &
                         system_error_text
  implicit none
  private

  public :: restart_store_t, create_restart_store, commit_restart_store, discard_restart_store
  public :: open_restart_store, close_restart_store, restart_entry_exists
  public :: write_restart, read_restart, read_restart_resized, exchange_restart, exchange_restart_resized
  public :: write_restart_attribute, read_restart_attribute, exchange_restart_count
  public :: start_memory_store

  !> An open dump, being written or read.
  type :: restart_store_t
    integer(hid_t) :: file_id = -1
    logical :: is_open = .false.
    logical :: writing = .false.
    character(len=:), allocatable :: path             !< the dump's name
    character(len=:), allocatable :: temporary_path   !< written here, then renamed to `path`
    !> In memory (start_memory_store): the values go into `memory` one after another instead of
    !> a file, and are read back in the same order (names are not kept). A distributed run
    !> moves element blocks between ranks this way with the groups' own exchange routines.
    logical :: in_memory = .false.
    !> In memory, writing nothing: the values are only counted (`position`), the room a store
    !> will need (start_memory_store's `room`), so that a large one is not grown by doubling
    logical :: counting = .false.
    real(wp), allocatable :: memory(:)                !< the values so far (integers and logicals as reals)
    integer :: position = 0                           !< values written, or read, so far
  end type restart_store_t

  !> Store a value under a path: real(wp) of rank 0-4, integer of rank 0-3, logical of rank
  !> 0-2, or a character scalar.
  interface write_restart
    module procedure write_real_0, write_real_1, write_real_2, write_real_3, write_real_4
    module procedure write_integer_0, write_integer_1, write_integer_2, write_integer_3
    module procedure write_logical_0, write_logical_1, write_logical_2, write_text
  end interface write_restart

  !> Read a value stored under a path into an existing variable of the same shape.
  interface read_restart
    module procedure read_real_0, read_real_1, read_real_2, read_real_3, read_real_4
    module procedure read_integer_0, read_integer_1, read_integer_2, read_integer_3
    module procedure read_logical_0, read_logical_1, read_logical_2, read_text
  end interface read_restart

  !> Read an array into an allocatable variable, (re)allocated to the stored shape.
  interface read_restart_resized
    module procedure read_real_resized_1, read_real_resized_2, read_integer_resized_1
  end interface read_restart_resized

  !> Write the value when the dump is being written, read it back (same shape) when it is being
  !> read: one traversal of the run state serves both (run_state_dump).
  interface exchange_restart
    module procedure exchange_real_0, exchange_real_1, exchange_real_2, exchange_real_3, exchange_real_4
    module procedure exchange_integer_0, exchange_integer_1, exchange_integer_2, exchange_integer_3
    module procedure exchange_logical_0, exchange_logical_1, exchange_logical_2
  end interface exchange_restart

  !> The same for allocatable arrays whose size may change during a run (read back at the
  !> stored size).
  interface exchange_restart_resized
    module procedure exchange_real_resized_1, exchange_real_resized_2, exchange_integer_resized_1
  end interface exchange_restart_resized

  !> Header attributes on the root of the dump: text, real or integer.
  interface write_restart_attribute
    module procedure write_text_attribute, write_real_attribute, write_integer_attribute
  end interface write_restart_attribute

  interface read_restart_attribute
    module procedure read_text_attribute, read_real_attribute, read_integer_attribute
  end interface read_restart_attribute

  interface
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

    function c_fsync(descriptor) bind(c, name="fsync") result(status)
      import :: c_int
      integer(c_int), value :: descriptor
      integer(c_int) :: status
    end function c_fsync

    function c_fclose(stream) bind(c, name="fclose") result(status)
      import :: c_ptr, c_int
      type(c_ptr), value :: stream
      integer(c_int) :: status
    end function c_fclose
  end interface

contains

  ! ---------------------------------------------------------------------------------------------
  ! Files

  !> Start writing the dump `path` (under its temporary name `path.tmp`, which an earlier
  !> attempt may have left and which is replaced).
  subroutine create_restart_store(store, path, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: error
    integer(hid_t) :: access_list
    integer :: status, ignored

    call start_library()
    store%path = path
    store%temporary_path = path//".tmp"
    store%writing = .true.
    call clear_system_error()
    call h5pcreate_f(H5P_FILE_ACCESS_F, access_list, status)
    if (status == 0) call h5pset_file_locking_f(access_list, .false., .true., status)
    if (status == 0) call h5fcreate_f(store%temporary_path, H5F_ACC_TRUNC_F, store%file_id, status, &
                                      access_prp=access_list)
    call h5pclose_f(access_list, ignored)
    if (status /= 0) then
      call make_error(error, "cannot create the restart dump "//store%temporary_path//system_reason())
      call remove_file(store%temporary_path)
      return
    end if
    store%is_open = .true.
  end subroutine create_restart_store

  !> Finish a dump being written: flush, close, sync to the disk and rename it to its name. On a
  !> failure the temporary file is removed and the previous file of that name (if any) stays.
  subroutine commit_restart_store(store, error)
    type(restart_store_t), intent(inout) :: store
    type(error_t), allocatable, intent(out) :: error
    type(c_ptr) :: stream
    integer :: status
    integer(c_int) :: synced, closed

    if (.not. (store%is_open .and. store%writing)) then
      call make_error(error, "restart dump: commit of a dump that is not being written")
      return
    end if
    call clear_system_error()
    call h5fflush_f(store%file_id, H5F_SCOPE_GLOBAL_F, status)
    if (status == 0) call h5fclose_f(store%file_id, status)
    store%is_open = .false.
    store%file_id = -1
    if (status == 0) then
      ! to the disk before the rename, so that after a crash of the machine the name never
      ! points to a file whose blocks were not yet written
      status = 1
      stream = c_fopen(store%temporary_path//c_null_char, "r"//c_null_char)
      if (c_associated(stream)) then
        synced = c_fsync(c_fileno(stream))
        closed = c_fclose(stream)
        if (synced == 0 .and. closed == 0) status = 0
      end if
    end if
    if (status /= 0) then
      call make_error(error, "cannot write the restart dump "//store%temporary_path//system_reason())
      call remove_file(store%temporary_path)
      return
    end if
    call rename_file(store%temporary_path, store%path, error)
    if (allocated(error)) call remove_file(store%temporary_path)
  end subroutine commit_restart_store

  !> Give up a dump being written (after a failed write): close it and remove the temporary
  !> file; the previous file of that name stays.
  subroutine discard_restart_store(store)
    type(restart_store_t), intent(inout) :: store
    integer :: status
    if (store%is_open) call h5fclose_f(store%file_id, status)
    store%is_open = .false.
    store%file_id = -1
    if (store%writing .and. allocated(store%temporary_path)) call remove_file(store%temporary_path)
  end subroutine discard_restart_store

  !> Open the dump `path` for reading.
  subroutine open_restart_store(store, path, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: error
    integer(hid_t) :: access_list
    integer :: status, ignored
    logical :: exists

    call start_library()
    store%path = path
    store%writing = .false.
    inquire (file=path, exist=exists)
    if (.not. exists) then
      call make_error(error, "restart dump "//path//" does not exist")
      return
    end if
    call h5pcreate_f(H5P_FILE_ACCESS_F, access_list, status)
    if (status == 0) call h5pset_file_locking_f(access_list, .false., .true., status)
    if (status == 0) call h5fopen_f(path, H5F_ACC_RDONLY_F, store%file_id, status, access_prp=access_list)
    call h5pclose_f(access_list, ignored)
    if (status /= 0) then
      call make_error(error, "restart dump "//path//" cannot be read: it is not an HDF5 file, or it is "// &
                      "damaged (a file cut short, or not a crashfree dump)")
      return
    end if
    store%is_open = .true.
  end subroutine open_restart_store

  !> Close a dump opened for reading (nothing when it is not open).
  subroutine close_restart_store(store)
    type(restart_store_t), intent(inout) :: store
    integer :: status
    if (store%is_open) call h5fclose_f(store%file_id, status)
    store%is_open = .false.
    store%file_id = -1
  end subroutine close_restart_store

  !> Whether `name` is stored.
  logical function restart_entry_exists(store, name)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    restart_entry_exists = path_exists(store%file_id, name)
  end function restart_entry_exists

  ! ---------------------------------------------------------------------------------------------
  ! Writing values

  subroutine write_real_0(store, name, value, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: value
    type(error_t), allocatable, intent(inout) :: error
    real(wp), target :: copy
    integer(hsize_t) :: dims(0)
    copy = value
    call put(store, name, H5T_IEEE_F64LE, real_type(), dims, c_loc(copy), error)
  end subroutine write_real_0

  subroutine write_real_1(store, name, values, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    real(wp), intent(in), target, contiguous :: values(:)
    type(error_t), allocatable, intent(inout) :: error
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call put(store, name, H5T_IEEE_F64LE, real_type(), int(shape(values), hsize_t), buffer, error)
  end subroutine write_real_1

  subroutine write_real_2(store, name, values, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    real(wp), intent(in), target, contiguous :: values(:, :)
    type(error_t), allocatable, intent(inout) :: error
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call put(store, name, H5T_IEEE_F64LE, real_type(), int(shape(values), hsize_t), buffer, error)
  end subroutine write_real_2

  subroutine write_real_3(store, name, values, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    real(wp), intent(in), target, contiguous :: values(:, :, :)
    type(error_t), allocatable, intent(inout) :: error
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call put(store, name, H5T_IEEE_F64LE, real_type(), int(shape(values), hsize_t), buffer, error)
  end subroutine write_real_3

  subroutine write_real_4(store, name, values, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    real(wp), intent(in), target, contiguous :: values(:, :, :, :)
    type(error_t), allocatable, intent(inout) :: error
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call put(store, name, H5T_IEEE_F64LE, real_type(), int(shape(values), hsize_t), buffer, error)
  end subroutine write_real_4

  subroutine write_integer_0(store, name, value, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    integer, intent(in) :: value
    type(error_t), allocatable, intent(inout) :: error
    integer, target :: copy
    integer(hsize_t) :: dims(0)
    copy = value
    call put(store, name, H5T_STD_I32LE, H5T_NATIVE_INTEGER, dims, c_loc(copy), error)
  end subroutine write_integer_0

  subroutine write_integer_1(store, name, values, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    integer, intent(in), target, contiguous :: values(:)
    type(error_t), allocatable, intent(inout) :: error
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call put(store, name, H5T_STD_I32LE, H5T_NATIVE_INTEGER, int(shape(values), hsize_t), buffer, error)
  end subroutine write_integer_1

  subroutine write_integer_2(store, name, values, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    integer, intent(in), target, contiguous :: values(:, :)
    type(error_t), allocatable, intent(inout) :: error
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call put(store, name, H5T_STD_I32LE, H5T_NATIVE_INTEGER, int(shape(values), hsize_t), buffer, error)
  end subroutine write_integer_2

  subroutine write_integer_3(store, name, values, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    integer, intent(in), target, contiguous :: values(:, :, :)
    type(error_t), allocatable, intent(inout) :: error
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call put(store, name, H5T_STD_I32LE, H5T_NATIVE_INTEGER, int(shape(values), hsize_t), buffer, error)
  end subroutine write_integer_3

  subroutine write_logical_0(store, name, value, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    logical, intent(in) :: value
    type(error_t), allocatable, intent(inout) :: error
    integer(int8), target :: copy
    integer(hsize_t) :: dims(0)
    copy = merge(1_int8, 0_int8, value)
    call put(store, name, H5T_STD_I8LE, byte_type(), dims, c_loc(copy), error)
  end subroutine write_logical_0

  subroutine write_logical_1(store, name, values, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    logical, intent(in) :: values(:)
    type(error_t), allocatable, intent(inout) :: error
    integer(int8), allocatable, target :: bytes(:)
    type(c_ptr) :: buffer
    allocate (bytes(size(values)))
    bytes = merge(1_int8, 0_int8, values)
    buffer = c_null_ptr
    if (size(bytes) > 0) buffer = c_loc(bytes)
    call put(store, name, H5T_STD_I8LE, byte_type(), int(shape(values), hsize_t), buffer, error)
  end subroutine write_logical_1

  subroutine write_logical_2(store, name, values, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    logical, intent(in) :: values(:, :)
    type(error_t), allocatable, intent(inout) :: error
    integer(int8), allocatable, target :: bytes(:, :)
    type(c_ptr) :: buffer
    allocate (bytes(size(values, 1), size(values, 2)))
    bytes = merge(1_int8, 0_int8, values)
    buffer = c_null_ptr
    if (size(bytes) > 0) buffer = c_loc(bytes)
    call put(store, name, H5T_STD_I8LE, byte_type(), int(shape(values), hsize_t), buffer, error)
  end subroutine write_logical_2

  !> Text, stored as its bytes.
  subroutine write_text(store, name, text, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    character(len=*), intent(in) :: text
    type(error_t), allocatable, intent(inout) :: error
    integer(int8), allocatable, target :: bytes(:)
    type(c_ptr) :: buffer
    allocate (bytes(len(text)))
    if (len(text) > 0) bytes = transfer(text, [0_int8], len(text))
    buffer = c_null_ptr
    if (size(bytes) > 0) buffer = c_loc(bytes)
    call put(store, name, H5T_STD_I8LE, byte_type(), [int(len(text), hsize_t)], buffer, error)
  end subroutine write_text

  ! ---------------------------------------------------------------------------------------------
  ! Reading values

  subroutine read_real_0(store, name, value, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    real(wp), intent(inout) :: value
    type(error_t), allocatable, intent(inout) :: error
    real(wp), target :: copy
    integer(hsize_t) :: dims(0)
    call get(store, name, H5T_FLOAT_F, real_type(), dims, c_loc(copy), error)
    if (.not. allocated(error)) value = copy
  end subroutine read_real_0

  subroutine read_real_1(store, name, values, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    real(wp), intent(inout), target, contiguous :: values(:)
    type(error_t), allocatable, intent(inout) :: error
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call get(store, name, H5T_FLOAT_F, real_type(), int(shape(values), hsize_t), buffer, error)
  end subroutine read_real_1

  subroutine read_real_2(store, name, values, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    real(wp), intent(inout), target, contiguous :: values(:, :)
    type(error_t), allocatable, intent(inout) :: error
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call get(store, name, H5T_FLOAT_F, real_type(), int(shape(values), hsize_t), buffer, error)
  end subroutine read_real_2

  subroutine read_real_3(store, name, values, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    real(wp), intent(inout), target, contiguous :: values(:, :, :)
    type(error_t), allocatable, intent(inout) :: error
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call get(store, name, H5T_FLOAT_F, real_type(), int(shape(values), hsize_t), buffer, error)
  end subroutine read_real_3

  subroutine read_real_4(store, name, values, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    real(wp), intent(inout), target, contiguous :: values(:, :, :, :)
    type(error_t), allocatable, intent(inout) :: error
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call get(store, name, H5T_FLOAT_F, real_type(), int(shape(values), hsize_t), buffer, error)
  end subroutine read_real_4

  subroutine read_integer_0(store, name, value, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    integer, intent(inout) :: value
    type(error_t), allocatable, intent(inout) :: error
    integer, target :: copy
    integer(hsize_t) :: dims(0)
    call get(store, name, H5T_INTEGER_F, H5T_NATIVE_INTEGER, dims, c_loc(copy), error)
    if (.not. allocated(error)) value = copy
  end subroutine read_integer_0

  subroutine read_integer_1(store, name, values, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    integer, intent(inout), target, contiguous :: values(:)
    type(error_t), allocatable, intent(inout) :: error
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call get(store, name, H5T_INTEGER_F, H5T_NATIVE_INTEGER, int(shape(values), hsize_t), buffer, error)
  end subroutine read_integer_1

  subroutine read_integer_2(store, name, values, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    integer, intent(inout), target, contiguous :: values(:, :)
    type(error_t), allocatable, intent(inout) :: error
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call get(store, name, H5T_INTEGER_F, H5T_NATIVE_INTEGER, int(shape(values), hsize_t), buffer, error)
  end subroutine read_integer_2

  subroutine read_integer_3(store, name, values, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    integer, intent(inout), target, contiguous :: values(:, :, :)
    type(error_t), allocatable, intent(inout) :: error
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call get(store, name, H5T_INTEGER_F, H5T_NATIVE_INTEGER, int(shape(values), hsize_t), buffer, error)
  end subroutine read_integer_3

  subroutine read_logical_0(store, name, value, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    logical, intent(inout) :: value
    type(error_t), allocatable, intent(inout) :: error
    integer(int8), target :: copy
    integer(hsize_t) :: dims(0)
    call get(store, name, H5T_INTEGER_F, byte_type(), dims, c_loc(copy), error)
    if (.not. allocated(error)) value = copy /= 0
  end subroutine read_logical_0

  subroutine read_logical_1(store, name, values, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    logical, intent(inout) :: values(:)
    type(error_t), allocatable, intent(inout) :: error
    integer(int8), allocatable, target :: bytes(:)
    type(c_ptr) :: buffer
    allocate (bytes(size(values)))
    buffer = c_null_ptr
    if (size(bytes) > 0) buffer = c_loc(bytes)
    call get(store, name, H5T_INTEGER_F, byte_type(), int(shape(values), hsize_t), buffer, error)
    if (.not. allocated(error)) values = bytes /= 0
  end subroutine read_logical_1

  subroutine read_logical_2(store, name, values, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    logical, intent(inout) :: values(:, :)
    type(error_t), allocatable, intent(inout) :: error
    integer(int8), allocatable, target :: bytes(:, :)
    type(c_ptr) :: buffer
    allocate (bytes(size(values, 1), size(values, 2)))
    buffer = c_null_ptr
    if (size(bytes) > 0) buffer = c_loc(bytes)
    call get(store, name, H5T_INTEGER_F, byte_type(), int(shape(values), hsize_t), buffer, error)
    if (.not. allocated(error)) values = bytes /= 0
  end subroutine read_logical_2

  !> Text of any length.
  subroutine read_text(store, name, text, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    character(len=:), allocatable, intent(inout) :: text
    type(error_t), allocatable, intent(inout) :: error
    integer(int8), allocatable, target :: bytes(:)
    integer(hsize_t), allocatable :: dims(:)
    type(c_ptr) :: buffer
    call stored_shape(store, name, 1, dims, error)
    if (allocated(error)) return
    allocate (bytes(dims(1)))
    buffer = c_null_ptr
    if (size(bytes) > 0) buffer = c_loc(bytes)
    call get(store, name, H5T_INTEGER_F, byte_type(), dims, buffer, error)
    if (allocated(error)) return
    text = transfer(bytes, repeat(" ", size(bytes)))
  end subroutine read_text

  subroutine read_real_resized_1(store, name, values, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    real(wp), allocatable, intent(inout) :: values(:)
    type(error_t), allocatable, intent(inout) :: error
    integer(hsize_t), allocatable :: dims(:)
    call stored_shape(store, name, 1, dims, error)
    if (allocated(error)) return
    if (allocated(values)) then
      if (any(shape(values) /= dims)) deallocate (values)
    end if
    if (.not. allocated(values)) allocate (values(dims(1)))
    call read_real_1(store, name, values, error)
  end subroutine read_real_resized_1

  subroutine read_real_resized_2(store, name, values, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    real(wp), allocatable, intent(inout) :: values(:, :)
    type(error_t), allocatable, intent(inout) :: error
    integer(hsize_t), allocatable :: dims(:)
    call stored_shape(store, name, 2, dims, error)
    if (allocated(error)) return
    if (allocated(values)) then
      if (any(shape(values) /= dims)) deallocate (values)
    end if
    if (.not. allocated(values)) allocate (values(dims(1), dims(2)))
    call read_real_2(store, name, values, error)
  end subroutine read_real_resized_2

  subroutine read_integer_resized_1(store, name, values, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    integer, allocatable, intent(inout) :: values(:)
    type(error_t), allocatable, intent(inout) :: error
    integer(hsize_t), allocatable :: dims(:)
    call stored_shape(store, name, 1, dims, error)
    if (allocated(error)) return
    if (allocated(values)) then
      if (any(shape(values) /= dims)) deallocate (values)
    end if
    if (.not. allocated(values)) allocate (values(dims(1)))
    call read_integer_1(store, name, values, error)
  end subroutine read_integer_resized_1

  ! ---------------------------------------------------------------------------------------------
  ! Writing or reading, as the store is open

  subroutine exchange_real_0(store, name, value, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    real(wp), intent(inout) :: value
    type(error_t), allocatable, intent(inout) :: error
    if (store%in_memory) then
      call memory_reals_scalar(store, value)
    else if (store%writing) then
      call write_restart(store, name, value, error)
    else
      call read_restart(store, name, value, error)
    end if
  end subroutine exchange_real_0

  subroutine exchange_real_1(store, name, value, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    real(wp), intent(inout), contiguous :: value(:)
    type(error_t), allocatable, intent(inout) :: error
    if (store%in_memory) then
      call memory_reals(store, value, size(value))
    else if (store%writing) then
      call write_restart(store, name, value, error)
    else
      call read_restart(store, name, value, error)
    end if
  end subroutine exchange_real_1

  subroutine exchange_real_2(store, name, value, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    real(wp), intent(inout), contiguous :: value(:, :)
    type(error_t), allocatable, intent(inout) :: error
    if (store%in_memory) then
      call memory_reals(store, value, size(value))
    else if (store%writing) then
      call write_restart(store, name, value, error)
    else
      call read_restart(store, name, value, error)
    end if
  end subroutine exchange_real_2

  subroutine exchange_real_3(store, name, value, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    real(wp), intent(inout), contiguous :: value(:, :, :)
    type(error_t), allocatable, intent(inout) :: error
    if (store%in_memory) then
      call memory_reals(store, value, size(value))
    else if (store%writing) then
      call write_restart(store, name, value, error)
    else
      call read_restart(store, name, value, error)
    end if
  end subroutine exchange_real_3

  subroutine exchange_real_4(store, name, value, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    real(wp), intent(inout), contiguous :: value(:, :, :, :)
    type(error_t), allocatable, intent(inout) :: error
    if (store%in_memory) then
      call memory_reals(store, value, size(value))
    else if (store%writing) then
      call write_restart(store, name, value, error)
    else
      call read_restart(store, name, value, error)
    end if
  end subroutine exchange_real_4

  subroutine exchange_integer_0(store, name, value, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    integer, intent(inout) :: value
    type(error_t), allocatable, intent(inout) :: error
    if (store%in_memory) then
      call memory_integers_scalar(store, value)
    else if (store%writing) then
      call write_restart(store, name, value, error)
    else
      call read_restart(store, name, value, error)
    end if
  end subroutine exchange_integer_0

  subroutine exchange_integer_1(store, name, value, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    integer, intent(inout), contiguous :: value(:)
    type(error_t), allocatable, intent(inout) :: error
    if (store%in_memory) then
      call memory_integers(store, value, size(value))
    else if (store%writing) then
      call write_restart(store, name, value, error)
    else
      call read_restart(store, name, value, error)
    end if
  end subroutine exchange_integer_1

  subroutine exchange_integer_2(store, name, value, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    integer, intent(inout), contiguous :: value(:, :)
    type(error_t), allocatable, intent(inout) :: error
    if (store%in_memory) then
      call memory_integers(store, value, size(value))
    else if (store%writing) then
      call write_restart(store, name, value, error)
    else
      call read_restart(store, name, value, error)
    end if
  end subroutine exchange_integer_2

  subroutine exchange_integer_3(store, name, value, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    integer, intent(inout), contiguous :: value(:, :, :)
    type(error_t), allocatable, intent(inout) :: error
    if (store%in_memory) then
      call memory_integers(store, value, size(value))
    else if (store%writing) then
      call write_restart(store, name, value, error)
    else
      call read_restart(store, name, value, error)
    end if
  end subroutine exchange_integer_3

  subroutine exchange_logical_0(store, name, value, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    logical, intent(inout) :: value
    type(error_t), allocatable, intent(inout) :: error
    if (store%in_memory) then
      call memory_logicals_scalar(store, value)
    else if (store%writing) then
      call write_restart(store, name, value, error)
    else
      call read_restart(store, name, value, error)
    end if
  end subroutine exchange_logical_0

  subroutine exchange_logical_1(store, name, value, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    logical, intent(inout) :: value(:)
    type(error_t), allocatable, intent(inout) :: error
    if (store%in_memory) then
      call memory_logicals(store, value, size(value))
    else if (store%writing) then
      call write_restart(store, name, value, error)
    else
      call read_restart(store, name, value, error)
    end if
  end subroutine exchange_logical_1

  subroutine exchange_logical_2(store, name, value, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    logical, intent(inout) :: value(:, :)
    type(error_t), allocatable, intent(inout) :: error
    if (store%in_memory) then
      call memory_logicals(store, value, size(value))
    else if (store%writing) then
      call write_restart(store, name, value, error)
    else
      call read_restart(store, name, value, error)
    end if
  end subroutine exchange_logical_2

  subroutine exchange_real_resized_1(store, name, value, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    real(wp), allocatable, intent(inout) :: value(:)
    type(error_t), allocatable, intent(inout) :: error
    if (store%writing) then
      call write_restart(store, name, value, error)
    else
      call read_restart_resized(store, name, value, error)
    end if
  end subroutine exchange_real_resized_1

  subroutine exchange_real_resized_2(store, name, value, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    real(wp), allocatable, intent(inout) :: value(:, :)
    type(error_t), allocatable, intent(inout) :: error
    if (store%writing) then
      call write_restart(store, name, value, error)
    else
      call read_restart_resized(store, name, value, error)
    end if
  end subroutine exchange_real_resized_2

  subroutine exchange_integer_resized_1(store, name, value, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    integer, allocatable, intent(inout) :: value(:)
    type(error_t), allocatable, intent(inout) :: error
    if (store%writing) then
      call write_restart(store, name, value, error)
    else
      call read_restart_resized(store, name, value, error)
    end if
  end subroutine exchange_integer_resized_1

  ! ---------------------------------------------------------------------------------------------
  ! In memory

  !> Start a store in memory: empty for writing, or (`writing` false) reading `memory` from its
  !> first value. `room`: the values it will hold when known (a counting pass): exactly that
  !> much memory, no doubling. `counting`: count the values written, store none.
  subroutine start_memory_store(store, writing, room, counting)
    type(restart_store_t), intent(inout) :: store
    logical, intent(in) :: writing
    integer, intent(in), optional :: room
    logical, intent(in), optional :: counting
    store%in_memory = .true.
    store%writing = writing
    store%is_open = .true.
    store%position = 0
    store%counting = .false.
    if (present(counting)) store%counting = counting .and. writing
    if (present(room)) then
      if (allocated(store%memory)) then
        if (size(store%memory) /= max(room, 1)) deallocate (store%memory)
      end if
      if (.not. allocated(store%memory)) allocate (store%memory(max(room, 1)))
    end if
    if (.not. allocated(store%memory)) allocate (store%memory(1024))
  end subroutine start_memory_store

  !> Room for `count` more values (doubling: a store is filled once per exchange).
  subroutine reserve_memory(store, count)
    type(restart_store_t), intent(inout) :: store
    integer, intent(in) :: count
    real(wp), allocatable :: grown(:)
    if (store%counting .or. store%position + count <= size(store%memory)) return
    allocate (grown(max(2*size(store%memory), store%position + count)))
    grown(1:store%position) = store%memory(1:store%position)
    call move_alloc(grown, store%memory)
  end subroutine reserve_memory

  !> Append `count` reals, or take them back in order.
  subroutine memory_reals(store, values, count)
    type(restart_store_t), intent(inout) :: store
    integer, intent(in) :: count
    real(wp), intent(inout) :: values(count)
    if (store%writing) then
      call reserve_memory(store, count)
      if (.not. store%counting) store%memory(store%position + 1:store%position + count) = values
    else
      values = store%memory(store%position + 1:store%position + count)
    end if
    store%position = store%position + count
  end subroutine memory_reals

  subroutine memory_reals_scalar(store, value)
    type(restart_store_t), intent(inout) :: store
    real(wp), intent(inout) :: value
    real(wp) :: values(1)
    values(1) = value
    call memory_reals(store, values, 1)
    value = values(1)
  end subroutine memory_reals_scalar

  !> Integers as reals (exact below 2**53).
  subroutine memory_integers(store, values, count)
    type(restart_store_t), intent(inout) :: store
    integer, intent(in) :: count
    integer, intent(inout) :: values(count)
    if (store%writing) then
      call reserve_memory(store, count)
      if (.not. store%counting) store%memory(store%position + 1:store%position + count) = real(values, wp)
    else
      values = nint(store%memory(store%position + 1:store%position + count))
    end if
    store%position = store%position + count
  end subroutine memory_integers

  subroutine memory_integers_scalar(store, value)
    type(restart_store_t), intent(inout) :: store
    integer, intent(inout) :: value
    integer :: values(1)
    values(1) = value
    call memory_integers(store, values, 1)
    value = values(1)
  end subroutine memory_integers_scalar

  !> Logicals as 1 and 0.
  subroutine memory_logicals(store, values, count)
    type(restart_store_t), intent(inout) :: store
    integer, intent(in) :: count
    logical, intent(inout) :: values(count)
    if (store%writing) then
      call reserve_memory(store, count)
      if (.not. store%counting) store%memory(store%position + 1:store%position + count) = merge(1.0_wp, 0.0_wp, values)
    else
      values = store%memory(store%position + 1:store%position + count) > 0.5_wp
    end if
    store%position = store%position + count
  end subroutine memory_logicals

  subroutine memory_logicals_scalar(store, value)
    type(restart_store_t), intent(inout) :: store
    logical, intent(inout) :: value
    logical :: values(1)
    values(1) = value
    call memory_logicals(store, values, 1)
    value = values(1)
  end subroutine memory_logicals_scalar

  ! ---------------------------------------------------------------------------------------------
  ! Header attributes (on the root group)

  !> A text attribute (a fixed-length, NUL-terminated string: h5py reads it as bytes).
  subroutine write_text_attribute(store, name, text, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name, text
    type(error_t), allocatable, intent(inout) :: error
    character(kind=c_char, len=1), allocatable, target :: characters(:)
    integer(hid_t) :: string_type
    integer :: status, position
    if (allocated(error)) return
    allocate (characters(len(text) + 1))
    do position = 1, len(text)
      characters(position) = text(position:position)
    end do
    characters(len(text) + 1) = c_null_char
    call h5tcopy_f(H5T_FORTRAN_S1, string_type, status)
    if (status == 0) call h5tset_size_f(string_type, int(len(text) + 1, size_t), status)
    if (status == 0) call h5tset_strpad_f(string_type, H5T_STR_NULLTERM_F, status)
    if (status /= 0) then
      call make_error(error, problem(store, name, "cannot create a string type"))
      return
    end if
    call put_attribute(store, name, string_type, string_type, c_loc(characters), error)
    call h5tclose_f(string_type, status)
  end subroutine write_text_attribute

  subroutine write_real_attribute(store, name, value, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: value
    type(error_t), allocatable, intent(inout) :: error
    real(wp), target :: copy
    copy = value
    call put_attribute(store, name, H5T_IEEE_F64LE, real_type(), c_loc(copy), error)
  end subroutine write_real_attribute

  subroutine write_integer_attribute(store, name, value, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    integer, intent(in) :: value
    type(error_t), allocatable, intent(inout) :: error
    integer, target :: copy
    copy = value
    call put_attribute(store, name, H5T_STD_I32LE, H5T_NATIVE_INTEGER, c_loc(copy), error)
  end subroutine write_integer_attribute

  subroutine read_text_attribute(store, name, text, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    character(len=:), allocatable, intent(inout) :: text
    type(error_t), allocatable, intent(inout) :: error
    character(kind=c_char, len=1), allocatable, target :: characters(:)
    type(c_ptr) :: pointer
    integer(hid_t) :: attribute_id, file_type, memory_type
    integer(size_t) :: size
    integer :: status, ignored, class, position
    if (allocated(error)) return
    call open_attribute(store, name, attribute_id, error)
    if (allocated(error)) return
    call h5aget_type_f(attribute_id, file_type, status)
    if (status == 0) call h5tget_class_f(file_type, class, status)
    if (status == 0 .and. class /= H5T_STRING_F) status = 1
    if (status == 0) call h5tget_size_f(file_type, size, status)
    if (status == 0) call h5tclose_f(file_type, ignored)
    if (status /= 0) then
      call h5aclose_f(attribute_id, ignored)
      call make_error(error, problem(store, name, "is not a text attribute"))
      return
    end if
    allocate (characters(size + 1))
    characters = c_null_char
    call h5tcopy_f(H5T_FORTRAN_S1, memory_type, status)
    if (status == 0) call h5tset_size_f(memory_type, size + 1, status)   ! room for the NUL
    if (status == 0) call h5tset_strpad_f(memory_type, H5T_STR_NULLTERM_F, status)
    pointer = c_loc(characters)
    if (status == 0) call h5aread_f(attribute_id, memory_type, pointer, status)
    call h5tclose_f(memory_type, ignored)
    call h5aclose_f(attribute_id, ignored)
    if (status /= 0) then
      call make_error(error, problem(store, name, "cannot be read"))
      return
    end if
    position = 0
    do while (position < size)
      if (characters(position + 1) == c_null_char) exit
      position = position + 1
    end do
    allocate (character(len=position) :: text)
    do position = 1, len(text)
      text(position:position) = characters(position)
    end do
  end subroutine read_text_attribute

  subroutine read_real_attribute(store, name, value, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    real(wp), intent(inout) :: value
    type(error_t), allocatable, intent(inout) :: error
    real(wp), target :: copy
    call get_attribute(store, name, H5T_FLOAT_F, real_type(), c_loc(copy), error)
    if (.not. allocated(error)) value = copy
  end subroutine read_real_attribute

  subroutine read_integer_attribute(store, name, value, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    integer, intent(inout) :: value
    type(error_t), allocatable, intent(inout) :: error
    integer, target :: copy
    call get_attribute(store, name, H5T_INTEGER_F, H5T_NATIVE_INTEGER, c_loc(copy), error)
    if (.not. allocated(error)) value = copy
  end subroutine read_integer_attribute

  ! ---------------------------------------------------------------------------------------------
  ! The HDF5 side

  !> Create dataset `name` (and the groups on its path) of `dims` (none: a scalar) and write
  !> `buffer` into it (nothing for size 0).
  subroutine put(store, name, file_type, memory_type, dims, buffer, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    integer(hid_t), intent(in) :: file_type, memory_type
    integer(hsize_t), intent(in) :: dims(:)
    type(c_ptr), intent(in) :: buffer
    type(error_t), allocatable, intent(inout) :: error
    integer(hid_t) :: space_id, dataset_id
    integer :: status, ignored

    if (allocated(error)) return
    if (.not. (store%is_open .and. store%writing)) then
      call make_error(error, problem(store, name, "the dump is not open for writing"))
      return
    end if
    call create_parent_groups(store, name, error)
    if (allocated(error)) return
    if (size(dims) == 0) then
      call h5screate_f(H5S_SCALAR_F, space_id, status)
    else
      call h5screate_simple_f(size(dims), dims, space_id, status)
    end if
    if (status /= 0) then
      call make_error(error, problem(store, name, "cannot create its dataspace"))
      return
    end if
    call h5dcreate_f(store%file_id, name, file_type, space_id, dataset_id, status)
    call h5sclose_f(space_id, ignored)
    if (status /= 0) then
      call make_error(error, problem(store, name, "cannot create the dataset (stored twice?)"))
      return
    end if
    if (product(dims) > 0) then
      call h5dwrite_f(dataset_id, memory_type, buffer, status)
      if (status /= 0) call make_error(error, problem(store, name, "cannot write it"//system_reason()))
    end if
    call h5dclose_f(dataset_id, ignored)
  end subroutine put

  !> Read dataset `name` into `buffer` after checking that it exists, is of type class `class`
  !> (H5T_FLOAT_F or H5T_INTEGER_F) and has the shape `dims` (none: a scalar).
  subroutine get(store, name, class, memory_type, dims, buffer, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    integer, intent(in) :: class
    integer(hid_t), intent(in) :: memory_type
    integer(hsize_t), intent(in) :: dims(:)
    type(c_ptr), intent(in) :: buffer
    type(error_t), allocatable, intent(inout) :: error
    integer(hsize_t), allocatable :: stored(:)
    integer(hid_t) :: dataset_id, type_id
    integer :: status, ignored, stored_class
    type(c_ptr) :: pointer

    if (allocated(error)) return
    call stored_shape(store, name, -1, stored, error)
    if (allocated(error)) return
    if (size(stored) /= size(dims)) then
      call make_error(error, problem(store, name, "shape "//shape_text(stored)//", this model needs "// &
                                     shape_text(dims)))
      return
    end if
    if (any(stored /= dims)) then
      call make_error(error, problem(store, name, "shape "//shape_text(stored)//", this model needs "// &
                                     shape_text(dims)))
      return
    end if
    call h5dopen_f(store%file_id, name, dataset_id, status)
    if (status /= 0) then
      call make_error(error, problem(store, name, "cannot be opened"))
      return
    end if
    call h5dget_type_f(dataset_id, type_id, status)
    if (status == 0) call h5tget_class_f(type_id, stored_class, status)
    if (status == 0) call h5tclose_f(type_id, ignored)
    if (status == 0 .and. stored_class /= class) then
      call h5dclose_f(dataset_id, ignored)
      call make_error(error, problem(store, name, "holds "//trim(merge("reals   ", "integers", &
                                     stored_class == H5T_FLOAT_F))//", "//trim(merge("reals   ", &
                                     "integers", class == H5T_FLOAT_F))//" expected"))
      return
    end if
    pointer = buffer
    if (status == 0 .and. product(dims) > 0) call h5dread_f(dataset_id, memory_type, pointer, status)
    call h5dclose_f(dataset_id, ignored)
    if (status /= 0) call make_error(error, problem(store, name, "cannot be read"))
  end subroutine get

  !> The shape of dataset `name` (empty for a scalar); with `rank` >= 0 it must have that rank.
  subroutine stored_shape(store, name, rank, dims, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    integer, intent(in) :: rank
    integer(hsize_t), allocatable, intent(out) :: dims(:)
    type(error_t), allocatable, intent(inout) :: error
    integer(hsize_t), allocatable :: maximum(:)
    integer(hid_t) :: dataset_id, space_id
    integer :: status, ignored, stored_rank

    allocate (dims(0))
    if (allocated(error)) return
    if (.not. store%is_open) then
      call make_error(error, problem(store, name, "the dump is not open"))
      return
    end if
    if (.not. path_exists(store%file_id, name)) then
      call make_error(error, problem(store, name, "missing (a dump of another model, or damaged)"))
      return
    end if
    call h5dopen_f(store%file_id, name, dataset_id, status)
    if (status /= 0) then
      call make_error(error, problem(store, name, "is not a dataset"))
      return
    end if
    call h5dget_space_f(dataset_id, space_id, status)
    if (status == 0) call h5sget_simple_extent_ndims_f(space_id, stored_rank, status)
    if (status == 0) then
      deallocate (dims)
      allocate (dims(stored_rank), maximum(stored_rank))
      if (stored_rank > 0) call h5sget_simple_extent_dims_f(space_id, dims, maximum, status)
      if (status > 0) status = 0    ! (it returns the rank)
      call h5sclose_f(space_id, ignored)
    end if
    call h5dclose_f(dataset_id, ignored)
    if (status /= 0) then
      call make_error(error, problem(store, name, "cannot read its shape"))
      return
    end if
    if (rank >= 0 .and. size(dims) /= rank) &
      call make_error(error, problem(store, name, "rank "//integer_text(size(dims))//", "// &
                                     integer_text(rank)//" expected"))
  end subroutine stored_shape

  !> Create a scalar attribute `name` of the root group and write `buffer` into it.
  subroutine put_attribute(store, name, file_type, memory_type, buffer, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    integer(hid_t), intent(in) :: file_type, memory_type
    type(c_ptr), intent(in) :: buffer
    type(error_t), allocatable, intent(inout) :: error
    integer(hid_t) :: space_id, attribute_id
    integer :: status, ignored
    if (allocated(error)) return
    if (.not. (store%is_open .and. store%writing)) then
      call make_error(error, problem(store, name, "the dump is not open for writing"))
      return
    end if
    call h5screate_f(H5S_SCALAR_F, space_id, status)
    if (status == 0) call h5acreate_f(store%file_id, name, file_type, space_id, attribute_id, status)
    call h5sclose_f(space_id, ignored)
    if (status == 0) then
      call h5awrite_f(attribute_id, memory_type, buffer, status)
      call h5aclose_f(attribute_id, ignored)
    end if
    if (status /= 0) call make_error(error, problem(store, name, "cannot write the attribute"))
  end subroutine put_attribute

  !> Open attribute `name` of the root group.
  subroutine open_attribute(store, name, attribute_id, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    integer(hid_t), intent(out) :: attribute_id
    type(error_t), allocatable, intent(inout) :: error
    integer :: status
    logical :: exists
    attribute_id = -1
    if (allocated(error)) return
    exists = .false.
    if (store%is_open) call h5aexists_f(store%file_id, name, exists, status)
    if (.not. exists) then
      call make_error(error, problem(store, name, "missing: not a crashfree restart dump"))
      return
    end if
    call h5aopen_f(store%file_id, name, attribute_id, status)
    if (status /= 0) call make_error(error, problem(store, name, "cannot be opened"))
  end subroutine open_attribute

  !> Read scalar attribute `name` of class `class` into `buffer`.
  subroutine get_attribute(store, name, class, memory_type, buffer, error)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name
    integer, intent(in) :: class
    integer(hid_t), intent(in) :: memory_type
    type(c_ptr), intent(in) :: buffer
    type(error_t), allocatable, intent(inout) :: error
    integer(hid_t) :: attribute_id, type_id
    integer :: status, ignored, stored_class
    type(c_ptr) :: pointer
    call open_attribute(store, name, attribute_id, error)
    if (allocated(error)) return
    call h5aget_type_f(attribute_id, type_id, status)
    if (status == 0) call h5tget_class_f(type_id, stored_class, status)
    if (status == 0) call h5tclose_f(type_id, ignored)
    if (status == 0 .and. stored_class /= class) status = 1
    pointer = buffer
    if (status == 0) call h5aread_f(attribute_id, memory_type, pointer, status)
    call h5aclose_f(attribute_id, ignored)
    if (status /= 0) call make_error(error, problem(store, name, "cannot be read (of another kind?)"))
  end subroutine get_attribute

  !> Create the groups on the path of `name` ("a/b/c": a and a/b) that do not exist yet.
  subroutine create_parent_groups(store, name, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: name
    type(error_t), allocatable, intent(inout) :: error
    integer(hid_t) :: group_id
    integer :: position, status, ignored
    do position = 2, len(name)
      if (name(position:position) /= "/") cycle
      if (path_exists(store%file_id, name(1:position - 1))) cycle
      call h5gcreate_f(store%file_id, name(1:position - 1), group_id, status)
      if (status /= 0) then
        call make_error(error, problem(store, name(1:position - 1), "cannot create the group"))
        return
      end if
      call h5gclose_f(group_id, ignored)
    end do
  end subroutine create_parent_groups

  !> Whether every prefix of `name` exists (HDF5 fails on "a/b/c" when "a/b" is missing).
  logical function path_exists(file_id, name)
    integer(hid_t), intent(in) :: file_id
    character(len=*), intent(in) :: name
    integer :: position, status
    logical :: exists
    path_exists = .false.
    do position = 2, len(name) + 1
      if (position <= len(name)) then
        if (name(position:position) /= "/") cycle
      end if
      call h5lexists_f(file_id, name(1:position - 1), exists, status)
      if (status /= 0 .or. .not. exists) return
    end do
    path_exists = .true.
  end function path_exists

  !> Initialise HDF5 once: no exit handler (see results_file) and no automatic error printing.
  subroutine start_library()
    integer :: status
    call h5dont_atexit_f(status)
    call h5open_f(status)
    call h5eset_auto_f(0, status)
  end subroutine start_library

  integer(hid_t) function real_type()
    real_type = h5kind_to_type(wp, H5_REAL_KIND)
  end function real_type

  integer(hid_t) function byte_type()
    byte_type = h5kind_to_type(int8, H5_INTEGER_KIND)
  end function byte_type

  !> "restart dump DIR/d3dump02: nodes/velocity: what".
  function problem(store, name, what) result(text)
    type(restart_store_t), intent(in) :: store
    character(len=*), intent(in) :: name, what
    character(len=:), allocatable :: text
    text = "restart dump "
    if (allocated(store%path)) text = text//store%path
    text = text//": "//name//": "//what
  end function problem

  !> " (No space left on device)" after a failure that set errno, else "".
  function system_reason() result(text)
    character(len=:), allocatable :: text
    text = ""
    if (system_error_number() /= 0) text = " ("//system_error_text(system_error_number())//")"
  end function system_reason

  !> "(3,120)": a shape as Fortran sees it.
  function shape_text(dims) result(text)
    integer(hsize_t), intent(in) :: dims(:)
    character(len=:), allocatable :: text
    integer :: k
    if (size(dims) == 0) then
      text = "scalar"
      return
    end if
    text = "("
    do k = 1, size(dims)
      text = text//integer_text(int(dims(k)))
      if (k < size(dims)) text = text//","
    end do
    text = text//")"
  end function shape_text

  pure function integer_text(value) result(text)
    integer, intent(in) :: value
    character(len=:), allocatable :: text
    character(len=24) :: buffer
    write (buffer, '(i0)') value
    text = trim(buffer)
  end function integer_text

  !> A count that the model fixes: written, or read and compared ("the dump has 12 solid
  !> blocks, this model 13": a dump of another model or of another crashfree version).
  subroutine exchange_restart_count(store, path, what, count, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path, what
    integer, intent(in) :: count
    type(error_t), allocatable, intent(inout) :: error
    integer :: stored
    character(len=24) :: stored_text, count_text
    if (allocated(error)) return
    if (store%in_memory) then
      ! (a store in memory is read by the same model that wrote it)
      stored = count
      call memory_integers_scalar(store, stored)
    else if (store%writing) then
      call write_restart(store, path, count, error)
    else
      stored = -1
      call read_restart(store, path, stored, error)
      write (stored_text, '(i0)') stored
      write (count_text, '(i0)') count
      if (.not. allocated(error) .and. stored /= count) &
        call make_error(error, "restart dump "//store%path//": it has "//trim(stored_text)//" "//what// &
                        ", this model "//trim(count_text))
    end if
  end subroutine exchange_restart_count
end module restart_file
