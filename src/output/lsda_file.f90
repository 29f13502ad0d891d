!> LS-DYNA's LSDA container, the format of `binout`: writing and reading typed arrays in a tree
!> of directories.
!>
!> An LSDA file is an 8-byte header (header size 8; 8-byte LENGTH and OFFSET fields; 1-byte
!> COMMAND and TYPEID fields; the byte order; IEEE floats) followed by records, each
!> LENGTH (bytes of the whole record), COMMAND, then the command's own fields:
!>
!> | command | code | fields after LENGTH and COMMAND |
!> |---|---|---|
!> | CD | 2 | the new current directory (absolute or relative, no terminator) |
!> | DATA | 3 | TYPEID, name length (1 byte), name, the values |
!> | VARIABLE | 4 | name, TYPEID, OFFSET of its DATA record, number of values |
!> | BEGINSYMBOLTABLE | 5 | (LENGTH: of the whole symbol table) |
!> | ENDSYMBOLTABLE | 6 | OFFSET of the next symbol table, 0 for none |
!> | SYMBOLTABLEOFFSET | 7 | OFFSET of the first symbol table, 0 for none (the record after the header) |
!>
!> Readers such as lasso-python find the variables through the chain of symbol tables (CD and
!> VARIABLE records between BEGIN and END); others, such as dynareadout, walk the CD and DATA
!> records. This writer serves both: every DATA record follows a CD to its directory, and each
!> `flush_lsda` appends a symbol table of the variables written since the previous one and
!> links it from the previous one, so the file on disk is complete after every flush and the
!> run can add to it as it goes (a table is also flushed every `table_capacity` variables). Values are written in the machine's byte order, which the
!> header states.
module lsda_file
  use, intrinsic :: iso_fortran_env, only: int8, int16, int32, int64, real32, real64
  use error_handling, only: error_t, make_error
  implicit none
  private

  public :: lsda_file_t, lsda_entry_t, create_lsda, change_lsda_directory, write_lsda, flush_lsda, close_lsda
  public :: open_lsda, find_lsda_entry, read_lsda
  public :: lsda_i1, lsda_i2, lsda_i4, lsda_i8, lsda_u1, lsda_u2, lsda_u4, lsda_u8, lsda_r4, lsda_r8

  !> LSDA's type ids.
  integer, parameter :: lsda_i1 = 1, lsda_i2 = 2, lsda_i4 = 3, lsda_i8 = 4, lsda_u1 = 5, lsda_u2 = 6, &
                        lsda_u4 = 7, lsda_u8 = 8, lsda_r4 = 9, lsda_r8 = 10
  integer, parameter :: command_cd = 2, command_data = 3, command_variable = 4, command_begin_table = 5, &
                        command_end_table = 6, command_table_offset = 7
  !> Bytes of a record's LENGTH + COMMAND fields, and of a DATA record's fields before its name.
  integer(int64), parameter :: command_bytes = 9, data_head_bytes = 11
  !> Where the offset of the first symbol table is kept (after the header and the LENGTH and
  !> COMMAND of the SYMBOLTABLEOFFSET record).
  integer(int64), parameter :: first_link = 17
  !> Variables held for the next symbol table at most: more are flushed, so that a file of
  !> millions of variables (a long history at a short interval) does not keep them all in memory.
  integer, parameter :: table_capacity = 4096

  !> One variable: its directory, name, type, DATA record and number of values.
  type :: lsda_entry_t
    character(len=:), allocatable :: directory   !< absolute, e.g. "/glstat/d000001"
    character(len=:), allocatable :: name
    integer :: type_code = 0
    integer(int64) :: offset = 0                 !< byte offset of the DATA record in the file
    integer(int64) :: length = 0                 !< number of values
  end type lsda_entry_t

  !> An LSDA file open for writing (`create_lsda`) or reading (`open_lsda`).
  type :: lsda_file_t
    integer :: unit = 0                                 !< (newunit= gives negative numbers)
    logical :: is_open = .false.
    character(len=:), allocatable :: path
    character(len=:), allocatable :: directory          !< current directory of writes
    character(len=:), allocatable :: data_directory     !< directory of the last CD written
    type(lsda_entry_t), allocatable :: entries(:)
    integer :: entry_count = 0
    integer :: listed_count = 0                         !< entries in a symbol table on disk
    integer(int64) :: link_offset = first_link          !< where the next symbol table's offset goes
    integer(int64) :: end_offset = 0                    !< bytes in the file
  end type lsda_file_t

  !> Write one array as a DATA record in the current directory (integers: `unsigned` tags
  !> them U1..U8 instead of I1..I8; text: I1, one byte per character, as LS-DYNA writes titles).
  interface write_lsda
    module procedure write_int8, write_int16, write_int32, write_int64, write_real32, write_real64, write_text
  end interface write_lsda

  !> Read a variable by its absolute path ("/glstat/d000001/time") into an array of the kind
  !> its type has (a signed or unsigned integer of that size; R4; R8; I1 or U1 as text).
  interface read_lsda
    module procedure read_int8, read_int16, read_int32, read_int64, read_real32, read_real64, read_text
  end interface read_lsda

contains

  !> Create (or replace) the file with its header and an empty symbol-table link.
  subroutine create_lsda(file, path, error)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: error
    integer :: status
    character(len=256) :: message
    integer(int8) :: header(8)

    file%path = path
    file%directory = "/"
    file%data_directory = ""
    file%entry_count = 0
    file%listed_count = 0
    file%link_offset = first_link
    if (allocated(file%entries)) deallocate (file%entries)
    allocate (file%entries(64))
    open (newunit=file%unit, file=path, access="stream", form="unformatted", status="replace", &
          action="readwrite", iostat=status, iomsg=message)
    if (status /= 0) then
      call make_error(error, path//": cannot create the file: "//trim(message))
      return
    end if
    file%is_open = .true.
    header = [8_int8, 8_int8, 8_int8, 1_int8, 1_int8, merge(1_int8, 0_int8, little_endian()), 0_int8, 0_int8]
    write (file%unit, pos=1, iostat=status, iomsg=message) header, 17_int64, int(command_table_offset, int8), 0_int64
    file%end_offset = 25
    if (status /= 0) call write_failed(file, message, error)
  end subroutine create_lsda

  !> Make `directory` (absolute, or relative to the current one; ".." goes up) the directory of
  !> the next writes. Directories need no creating: a variable's path makes them.
  subroutine change_lsda_directory(file, directory)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: directory
    file%directory = resolved_directory(file%directory, directory)
  end subroutine change_lsda_directory

  subroutine write_int8(file, name, values, error, unsigned)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: name
    integer(int8), intent(in) :: values(:)
    type(error_t), allocatable, intent(out) :: error
    logical, intent(in), optional :: unsigned
    integer :: status
    character(len=256) :: message
    call begin_data(file, name, merge(lsda_u1, lsda_i1, is_set(unsigned)), 1, size(values), error)
    if (allocated(error)) return
    write (file%unit, iostat=status, iomsg=message) values
    if (status /= 0) call write_failed(file, message, error)
  end subroutine write_int8

  subroutine write_int16(file, name, values, error, unsigned)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: name
    integer(int16), intent(in) :: values(:)
    type(error_t), allocatable, intent(out) :: error
    logical, intent(in), optional :: unsigned
    integer :: status
    character(len=256) :: message
    call begin_data(file, name, merge(lsda_u2, lsda_i2, is_set(unsigned)), 2, size(values), error)
    if (allocated(error)) return
    write (file%unit, iostat=status, iomsg=message) values
    if (status /= 0) call write_failed(file, message, error)
  end subroutine write_int16

  subroutine write_int32(file, name, values, error, unsigned)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: name
    integer(int32), intent(in) :: values(:)
    type(error_t), allocatable, intent(out) :: error
    logical, intent(in), optional :: unsigned
    integer :: status
    character(len=256) :: message
    call begin_data(file, name, merge(lsda_u4, lsda_i4, is_set(unsigned)), 4, size(values), error)
    if (allocated(error)) return
    write (file%unit, iostat=status, iomsg=message) values
    if (status /= 0) call write_failed(file, message, error)
  end subroutine write_int32

  subroutine write_int64(file, name, values, error, unsigned)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: name
    integer(int64), intent(in) :: values(:)
    type(error_t), allocatable, intent(out) :: error
    logical, intent(in), optional :: unsigned
    integer :: status
    character(len=256) :: message
    call begin_data(file, name, merge(lsda_u8, lsda_i8, is_set(unsigned)), 8, size(values), error)
    if (allocated(error)) return
    write (file%unit, iostat=status, iomsg=message) values
    if (status /= 0) call write_failed(file, message, error)
  end subroutine write_int64

  subroutine write_real32(file, name, values, error)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: name
    real(real32), intent(in) :: values(:)
    type(error_t), allocatable, intent(out) :: error
    integer :: status
    character(len=256) :: message
    call begin_data(file, name, lsda_r4, 4, size(values), error)
    if (allocated(error)) return
    write (file%unit, iostat=status, iomsg=message) values
    if (status /= 0) call write_failed(file, message, error)
  end subroutine write_real32

  subroutine write_real64(file, name, values, error)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: name
    real(real64), intent(in) :: values(:)
    type(error_t), allocatable, intent(out) :: error
    integer :: status
    character(len=256) :: message
    call begin_data(file, name, lsda_r8, 8, size(values), error)
    if (allocated(error)) return
    write (file%unit, iostat=status, iomsg=message) values
    if (status /= 0) call write_failed(file, message, error)
  end subroutine write_real64

  subroutine write_text(file, name, text, error)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: name
    character(len=*), intent(in) :: text
    type(error_t), allocatable, intent(out) :: error
    integer :: status
    character(len=256) :: message
    call begin_data(file, name, lsda_i1, 1, len(text), error)
    if (allocated(error)) return
    write (file%unit, iostat=status, iomsg=message) text
    if (status /= 0) call write_failed(file, message, error)
  end subroutine write_text

  !> The CD record when the directory changed, the DATA record's fields before the values, and
  !> the variable's entry; the caller writes the values right after.
  subroutine begin_data(file, name, type_code, value_bytes, count, error)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: name
    integer, intent(in) :: type_code, value_bytes, count
    type(error_t), allocatable, intent(out) :: error
    integer :: status
    character(len=256) :: message
    integer(int64) :: record_bytes
    type(lsda_entry_t), allocatable :: grown(:)

    if (.not. file%is_open) then
      call make_error(error, "LSDA file: a write to a file that is not open")
      return
    end if
    if (file%entry_count - file%listed_count >= table_capacity) then
      call flush_lsda(file, error)
      if (allocated(error)) return
    end if
    if (len(name) < 1 .or. len(name) > 255 .or. index(name, "/") > 0) then
      call make_error(error, file%path//": variable name """//name//""" must have 1 to 255 characters and no /")
      return
    end if
    if (file%directory /= file%data_directory) then
      write (file%unit, pos=file%end_offset + 1, iostat=status, iomsg=message) &
        command_bytes + len(file%directory, int64), int(command_cd, int8), file%directory
      if (status /= 0) then
        call write_failed(file, message, error)
        return
      end if
      file%end_offset = file%end_offset + command_bytes + len(file%directory, int64)
      file%data_directory = file%directory
    end if
    record_bytes = data_head_bytes + len(name, int64) + int(value_bytes, int64)*int(count, int64)
    write (file%unit, pos=file%end_offset + 1, iostat=status, iomsg=message) record_bytes, &
      int(command_data, int8), int(type_code, int8), unsigned_byte(len(name)), name
    if (status /= 0) then
      call write_failed(file, message, error)
      return
    end if
    if (file%entry_count == size(file%entries)) then
      allocate (grown(2*size(file%entries)))
      grown(1:file%entry_count) = file%entries(1:file%entry_count)
      call move_alloc(grown, file%entries)
    end if
    file%entry_count = file%entry_count + 1
    associate (entry => file%entries(file%entry_count))
      entry%directory = file%directory
      entry%name = name
      entry%type_code = type_code
      entry%offset = file%end_offset
      entry%length = count
    end associate
    file%end_offset = file%end_offset + record_bytes
  end subroutine begin_data

  !> Append a symbol table of the variables written since the last one, link it from the
  !> previous one (or from the header) and flush: the file on disk is then complete.
  subroutine flush_lsda(file, error)
    type(lsda_file_t), intent(inout) :: file
    type(error_t), allocatable, intent(out) :: error
    integer :: status, k
    character(len=256) :: message
    character(len=:), allocatable :: directory
    integer(int64) :: start, record_bytes

    if (.not. file%is_open) then
      call make_error(error, "LSDA file: a flush of a file that is not open")
      return
    end if
    if (file%listed_count == file%entry_count) return
    start = file%end_offset
    ! the table's length is known at its end: 0 until then
    write (file%unit, pos=start + 1, iostat=status, iomsg=message) 0_int64, int(command_begin_table, int8)
    directory = ""
    do k = file%listed_count + 1, file%entry_count
      if (status /= 0) exit
      associate (entry => file%entries(k))
        if (entry%directory /= directory) then
          directory = entry%directory
          write (file%unit, iostat=status, iomsg=message) command_bytes + len(directory, int64), &
            int(command_cd, int8), directory
        end if
        if (status /= 0) exit
        record_bytes = command_bytes + len(entry%name, int64) + 17_int64
        write (file%unit, iostat=status, iomsg=message) record_bytes, int(command_variable, int8), entry%name, &
          int(entry%type_code, int8), entry%offset, entry%length
      end associate
    end do
    if (status == 0) write (file%unit, iostat=status, iomsg=message) 17_int64, int(command_end_table, int8), 0_int64
    if (status == 0) inquire (unit=file%unit, pos=file%end_offset)
    if (status == 0) then
      file%end_offset = file%end_offset - 1
      ! the table's length, then the link to it: a reader sees it only once it is whole
      write (file%unit, pos=start + 1, iostat=status, iomsg=message) file%end_offset - start
    end if
    if (status == 0) write (file%unit, pos=file%link_offset + 1, iostat=status, iomsg=message) start
    if (status == 0) flush (file%unit, iostat=status, iomsg=message)
    if (status /= 0) then
      call write_failed(file, message, error)
      return
    end if
    file%link_offset = file%end_offset - 8
    ! the entries are on disk: a writer needs them no more (a reader lists them from the file)
    file%entry_count = 0
    file%listed_count = 0
    ! the next DATA record says its directory again, for readers that walk the records
    file%data_directory = ""
  end subroutine flush_lsda

  !> Flush and close (a file open for reading: close).
  subroutine close_lsda(file, error)
    type(lsda_file_t), intent(inout) :: file
    type(error_t), allocatable, intent(out) :: error
    integer :: status
    if (.not. file%is_open) return
    if (file%entry_count > file%listed_count) call flush_lsda(file, error)
    if (.not. file%is_open) return
    close (file%unit, iostat=status)
    file%is_open = .false.
    if (status /= 0 .and. .not. allocated(error)) call make_error(error, file%path//": cannot close the file")
  end subroutine close_lsda

  !> Open an LSDA file for reading: its header is checked and the variables of every symbol
  !> table of the chain are listed in `file%entries` (a variable listed again later replaces
  !> the earlier entry, as in LS-DYNA's readers).
  subroutine open_lsda(file, path, error)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: error
    integer :: status, existing
    character(len=256) :: message
    integer(int8) :: header(8), command, type_code
    integer(int64) :: record_bytes, table_offset, value_offset, length, file_bytes
    character(len=:), allocatable :: directory, text

    file%path = path
    file%entry_count = 0
    file%listed_count = 0
    if (allocated(file%entries)) deallocate (file%entries)
    allocate (file%entries(64))
    open (newunit=file%unit, file=path, access="stream", form="unformatted", status="old", action="read", &
          iostat=status, iomsg=message)
    if (status /= 0) then
      call make_error(error, path//": cannot open the file: "//trim(message))
      return
    end if
    file%is_open = .true.
    inquire (unit=file%unit, size=file_bytes)
    read (file%unit, pos=1, iostat=status) header, record_bytes, command, table_offset
    if (status /= 0 .or. header(1) /= 8 .or. header(2) /= 8 .or. header(3) /= 8 .or. header(4) /= 1 .or. &
        header(5) /= 1 .or. command /= command_table_offset) then
      call read_failed(file, "not an LSDA file with 8-byte lengths and offsets", error)
      return
    end if
    if ((header(6) == 1) .neqv. little_endian()) then
      call read_failed(file, "written in the other byte order", error)
      return
    end if
    directory = "/"
    do while (table_offset /= 0)
      if (table_offset < 0 .or. table_offset + command_bytes > file_bytes) then
        call read_failed(file, "a symbol table offset outside the file", error)
        return
      end if
      read (file%unit, pos=table_offset + 1, iostat=status) record_bytes, command
      if (status /= 0 .or. command /= command_begin_table) then
        call read_failed(file, "no symbol table at offset "//long_text(table_offset), error)
        return
      end if
      table_offset = 0
      do
        read (file%unit, iostat=status) record_bytes, command
        if (status /= 0 .or. record_bytes < command_bytes .or. record_bytes > file_bytes) then
          call read_failed(file, "a broken symbol table record", error)
          return
        end if
        if (command == command_end_table) then
          read (file%unit, iostat=status) table_offset
          exit
        end if
        if (command == command_cd) then
          text = repeat(" ", int(record_bytes - command_bytes))
          read (file%unit, iostat=status) text
          directory = resolved_directory(directory, text)
        else if (command == command_variable .and. record_bytes > command_bytes + 17) then
          text = repeat(" ", int(record_bytes - command_bytes - 17))
          read (file%unit, iostat=status) text, type_code, value_offset, length
          existing = find_entry(file, directory, text)
          if (existing == 0) then
            call add_entry(file, directory, text, int(type_code), value_offset, length)
          else
            file%entries(existing)%type_code = type_code
            file%entries(existing)%offset = value_offset
            file%entries(existing)%length = length
          end if
        else
          call read_failed(file, "an unexpected record (command "//long_text(int(command, int64))// &
                           ") in a symbol table", error)
          return
        end if
        if (status /= 0) exit
      end do
      if (status /= 0) then
        call read_failed(file, "a symbol table cut short", error)
        return
      end if
    end do
    file%listed_count = file%entry_count
  end subroutine open_lsda

  !> The entry of the variable at an absolute path, 0 when there is none.
  integer function find_lsda_entry(file, path) result(index_found)
    type(lsda_file_t), intent(in) :: file
    character(len=*), intent(in) :: path
    integer :: slash
    slash = index(path, "/", back=.true.)
    index_found = 0
    if (slash == 0) return
    if (slash == 1) then
      index_found = find_entry(file, "/", path(2:))
    else
      index_found = find_entry(file, path(1:slash - 1), path(slash + 1:))
    end if
  end function find_lsda_entry

  subroutine read_int8(file, path, values, error)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: path
    integer(int8), allocatable, intent(out) :: values(:)
    type(error_t), allocatable, intent(out) :: error
    integer :: entry, status
    integer(int64) :: position
    call locate_values(file, path, [lsda_i1, lsda_u1], entry, position, error)
    if (allocated(error)) return
    allocate (values(file%entries(entry)%length))
    read (file%unit, pos=position, iostat=status) values
    if (status /= 0) call read_failed(file, path//" cut short", error)
  end subroutine read_int8

  subroutine read_int16(file, path, values, error)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: path
    integer(int16), allocatable, intent(out) :: values(:)
    type(error_t), allocatable, intent(out) :: error
    integer :: entry, status
    integer(int64) :: position
    call locate_values(file, path, [lsda_i2, lsda_u2], entry, position, error)
    if (allocated(error)) return
    allocate (values(file%entries(entry)%length))
    read (file%unit, pos=position, iostat=status) values
    if (status /= 0) call read_failed(file, path//" cut short", error)
  end subroutine read_int16

  subroutine read_int32(file, path, values, error)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: path
    integer(int32), allocatable, intent(out) :: values(:)
    type(error_t), allocatable, intent(out) :: error
    integer :: entry, status
    integer(int64) :: position
    call locate_values(file, path, [lsda_i4, lsda_u4], entry, position, error)
    if (allocated(error)) return
    allocate (values(file%entries(entry)%length))
    read (file%unit, pos=position, iostat=status) values
    if (status /= 0) call read_failed(file, path//" cut short", error)
  end subroutine read_int32

  subroutine read_int64(file, path, values, error)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: path
    integer(int64), allocatable, intent(out) :: values(:)
    type(error_t), allocatable, intent(out) :: error
    integer :: entry, status
    integer(int64) :: position
    call locate_values(file, path, [lsda_i8, lsda_u8], entry, position, error)
    if (allocated(error)) return
    allocate (values(file%entries(entry)%length))
    read (file%unit, pos=position, iostat=status) values
    if (status /= 0) call read_failed(file, path//" cut short", error)
  end subroutine read_int64

  subroutine read_real32(file, path, values, error)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: path
    real(real32), allocatable, intent(out) :: values(:)
    type(error_t), allocatable, intent(out) :: error
    integer :: entry, status
    integer(int64) :: position
    call locate_values(file, path, [lsda_r4], entry, position, error)
    if (allocated(error)) return
    allocate (values(file%entries(entry)%length))
    read (file%unit, pos=position, iostat=status) values
    if (status /= 0) call read_failed(file, path//" cut short", error)
  end subroutine read_real32

  subroutine read_real64(file, path, values, error)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: path
    real(real64), allocatable, intent(out) :: values(:)
    type(error_t), allocatable, intent(out) :: error
    integer :: entry, status
    integer(int64) :: position
    call locate_values(file, path, [lsda_r8], entry, position, error)
    if (allocated(error)) return
    allocate (values(file%entries(entry)%length))
    read (file%unit, pos=position, iostat=status) values
    if (status /= 0) call read_failed(file, path//" cut short", error)
  end subroutine read_real64

  subroutine read_text(file, path, text, error)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: path
    character(len=:), allocatable, intent(out) :: text
    type(error_t), allocatable, intent(out) :: error
    integer :: entry, status
    integer(int64) :: position
    call locate_values(file, path, [lsda_i1, lsda_u1], entry, position, error)
    if (allocated(error)) return
    text = repeat(" ", int(file%entries(entry)%length))
    read (file%unit, pos=position, iostat=status) text
    if (status /= 0) call read_failed(file, path//" cut short", error)
  end subroutine read_text

  !> Find the variable and check its type and its DATA record; `position` is where its values
  !> start (a file position, from 1).
  subroutine locate_values(file, path, type_codes, entry, position, error)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: path
    integer, intent(in) :: type_codes(:)
    integer, intent(out) :: entry
    integer(int64), intent(out) :: position
    type(error_t), allocatable, intent(out) :: error
    integer :: status
    integer(int64) :: record_bytes
    integer(int8) :: command, type_code, name_length

    position = 0
    entry = find_lsda_entry(file, path)
    if (entry == 0) then
      call make_error(error, file%path//": no variable "//path)
      return
    end if
    associate (found => file%entries(entry))
      if (all(type_codes /= found%type_code)) then
        call make_error(error, file%path//": "//path//" has LSDA type "//long_text(int(found%type_code, int64))// &
                        ", not the one asked for")
        return
      end if
      read (file%unit, pos=found%offset + 1, iostat=status) record_bytes, command, type_code, name_length
      if (status /= 0 .or. command /= command_data .or. type_code /= found%type_code .or. &
          byte_value(name_length) /= len(found%name)) then
        call read_failed(file, "the symbol table's offset of "//path//" is not its DATA record", error)
        return
      end if
      ! past the name: the values follow
      position = found%offset + data_head_bytes + len(found%name) + 1
    end associate
  end subroutine locate_values

  integer function find_entry(file, directory, name) result(index_found)
    type(lsda_file_t), intent(in) :: file
    character(len=*), intent(in) :: directory, name
    integer :: k
    index_found = 0
    do k = file%entry_count, 1, -1
      if (file%entries(k)%name == name .and. file%entries(k)%directory == directory) then
        index_found = k
        return
      end if
    end do
  end function find_entry

  subroutine add_entry(file, directory, name, type_code, offset, length)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: directory, name
    integer, intent(in) :: type_code
    integer(int64), intent(in) :: offset, length
    type(lsda_entry_t), allocatable :: grown(:)
    if (file%entry_count == size(file%entries)) then
      allocate (grown(2*size(file%entries)))
      grown(1:file%entry_count) = file%entries(1:file%entry_count)
      call move_alloc(grown, file%entries)
    end if
    file%entry_count = file%entry_count + 1
    file%entries(file%entry_count) = lsda_entry_t(directory, name, type_code, offset, length)
  end subroutine add_entry

  !> `path` from `current`: absolute, or relative with ".." going up; no trailing "/".
  pure function resolved_directory(current, path) result(directory)
    character(len=*), intent(in) :: current, path
    character(len=:), allocatable :: directory, part
    integer :: start, slash
    if (len(path) > 0) then
      if (path(1:1) == "/") then
        directory = "/"
      else
        directory = current
      end if
    else
      directory = current
    end if
    start = 1
    do while (start <= len(path))
      slash = index(path(start:), "/")
      if (slash == 0) then
        part = path(start:)
        start = len(path) + 1
      else
        part = path(start:start + slash - 2)
        start = start + slash
      end if
      if (len(part) == 0 .or. part == ".") cycle
      if (part == "..") then
        slash = index(directory, "/", back=.true.)
        directory = directory(1:max(1, slash - 1))
      else if (directory == "/") then
        directory = "/"//part
      else
        directory = directory//"/"//part
      end if
    end do
  end function resolved_directory

  subroutine write_failed(file, message, error)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: message
    type(error_t), allocatable, intent(inout) :: error
    integer :: status
    call make_error(error, file%path//": cannot write: "//trim(message))
    close (file%unit, iostat=status)
    file%is_open = .false.
  end subroutine write_failed

  subroutine read_failed(file, what, error)
    type(lsda_file_t), intent(inout) :: file
    character(len=*), intent(in) :: what
    type(error_t), allocatable, intent(inout) :: error
    integer :: status
    call make_error(error, file%path//": "//what)
    close (file%unit, iostat=status)
    file%is_open = .false.
  end subroutine read_failed

  logical function is_set(flag)
    logical, intent(in), optional :: flag
    is_set = .false.
    if (present(flag)) is_set = flag
  end function is_set

  !> 0..255 as the bit pattern of one byte.
  elemental integer(int8) function unsigned_byte(value)
    integer, intent(in) :: value
    unsigned_byte = int(iand(value, 255) - merge(256, 0, iand(value, 255) > 127), int8)
  end function unsigned_byte

  elemental integer function byte_value(byte)
    integer(int8), intent(in) :: byte
    byte_value = iand(int(byte), 255)
  end function byte_value

  logical function little_endian()
    integer(int8) :: bytes(4)
    bytes = transfer(1_int32, bytes)
    little_endian = bytes(1) == 1
  end function little_endian

  pure function long_text(value) result(text)
    integer(int64), intent(in) :: value
    character(len=:), allocatable :: text
    character(len=24) :: buffer
    write (buffer, '(i0)') value
    text = trim(buffer)
  end function long_text
end module lsda_file
