!> Where every kept line of a deck is: its file, its line number there and the byte offset at
!> which it starts, for files of any size.
!>
!> A deck of 30 million node cards has 30 million lines, so the table is kept small: lines
!> that follow each other in one file (no comment or skipped line between them) form a run,
!> which stores the file, the first line number and a 64-bit base offset once; each line then
!> costs one 32-bit offset from its run's base. A run ends where the file changes, a line is
!> skipped, or the next offset would not fit in 32 bits, so offsets beyond 2 GiB are exact.
module deck_line_table
  use, intrinsic :: iso_fortran_env, only: int32, int64
  implicit none
  private

  public :: line_table_t, append_line, line_file, line_number, line_start, start_table
  public :: line_place

  !> The table: `count` lines, `run_count` runs.
  type :: line_table_t
    integer :: count = 0
    integer(int32), allocatable :: offset(:)        !< from the base of the line's run
    integer :: run_count = 0
    integer, allocatable :: run_first(:)            !< first line (table index) of each run
    integer, allocatable :: run_file(:)
    integer, allocatable :: run_number(:)           !< line number of the run's first line
    integer(int64), allocatable :: run_base(:)      !< file offset of the run's first line
  end type line_table_t

  !> Largest offset a line may have from its run's base.
  integer(int64), parameter :: largest_offset = huge(1_int32)

contains

  !> An empty table with room for `capacity` lines.
  subroutine start_table(table, capacity)
    type(line_table_t), intent(out) :: table
    integer, intent(in) :: capacity
    allocate (table%offset(max(capacity, 16)))
    allocate (table%run_first(16), table%run_file(16), table%run_number(16), table%run_base(16))
  end subroutine start_table

  !> Add line `number` of file `file`, which starts at byte `start` (0 = the file's first
  !> byte). `added` is false when the table is full (2**31 - 1 lines).
  subroutine append_line(table, file, number, start, added)
    type(line_table_t), intent(inout) :: table
    integer, intent(in) :: file, number
    integer(int64), intent(in) :: start
    logical, intent(out) :: added
    integer :: run
    logical :: continues

    added = table%count < huge(table%count)
    if (.not. added) return
    if (.not. allocated(table%offset)) call start_table(table, 1024)
    continues = .false.
    run = table%run_count
    if (run > 0) then
      continues = table%run_file(run) == file .and. &
                  number - table%run_number(run) == table%count + 1 - table%run_first(run) .and. &
                  start >= table%run_base(run) .and. start - table%run_base(run) <= largest_offset
    end if
    if (.not. continues) then
      if (run == size(table%run_first)) call grow_runs(table)
      run = run + 1
      table%run_count = run
      table%run_first(run) = table%count + 1
      table%run_file(run) = file
      table%run_number(run) = number
      table%run_base(run) = start
    end if
    if (table%count == size(table%offset)) call grow_offsets(table)
    table%count = table%count + 1
    table%offset(table%count) = int(start - table%run_base(run), int32)
  end subroutine append_line

  !> The file of line `line`.
  pure integer function line_file(table, line)
    type(line_table_t), intent(in) :: table
    integer, intent(in) :: line
    line_file = table%run_file(run_of_line(table, line))
  end function line_file

  !> The line number (in its file) of line `line`.
  pure integer function line_number(table, line)
    type(line_table_t), intent(in) :: table
    integer, intent(in) :: line
    integer :: run
    run = run_of_line(table, line)
    line_number = table%run_number(run) + (line - table%run_first(run))
  end function line_number

  !> The byte offset in its file at which line `line` starts.
  pure integer(int64) function line_start(table, line)
    type(line_table_t), intent(in) :: table
    integer, intent(in) :: line
    line_start = table%run_base(run_of_line(table, line)) + int(table%offset(line), int64)
  end function line_start

  !> The file of line `line` and the byte offset at which it starts (one search for both).
  pure subroutine line_place(table, line, file, start)
    type(line_table_t), intent(in) :: table
    integer, intent(in) :: line
    integer, intent(out) :: file
    integer(int64), intent(out) :: start
    integer :: run
    run = run_of_line(table, line)
    file = table%run_file(run)
    start = table%run_base(run) + int(table%offset(line), int64)
  end subroutine line_place

  !> The run holding line `line` (runs are stored in line order).
  pure integer function run_of_line(table, line)
    type(line_table_t), intent(in) :: table
    integer, intent(in) :: line
    integer :: low, high, middle
    low = 1
    high = table%run_count
    run_of_line = 1
    do while (low <= high)
      middle = low + (high - low)/2
      if (table%run_first(middle) <= line) then
        run_of_line = middle
        low = middle + 1
      else
        high = middle - 1
      end if
    end do
  end function run_of_line

  subroutine grow_offsets(table)
    type(line_table_t), intent(inout) :: table
    integer(int32), allocatable :: larger(:)
    allocate (larger(larger_size(size(table%offset))))
    larger(1:table%count) = table%offset(1:table%count)
    call move_alloc(larger, table%offset)
  end subroutine grow_offsets

  subroutine grow_runs(table)
    type(line_table_t), intent(inout) :: table
    integer :: n, new_size
    integer, allocatable :: larger(:)
    integer(int64), allocatable :: larger_base(:)
    n = table%run_count
    new_size = larger_size(size(table%run_first))
    allocate (larger(new_size))
    larger(1:n) = table%run_first(1:n)
    call move_alloc(larger, table%run_first)
    allocate (larger(new_size))
    larger(1:n) = table%run_file(1:n)
    call move_alloc(larger, table%run_file)
    allocate (larger(new_size))
    larger(1:n) = table%run_number(1:n)
    call move_alloc(larger, table%run_number)
    allocate (larger_base(new_size))
    larger_base(1:n) = table%run_base(1:n)
    call move_alloc(larger_base, table%run_base)
  end subroutine grow_runs

  !> Twice `current`, or as far as a default integer reaches.
  pure integer function larger_size(current)
    integer, intent(in) :: current
    larger_size = int(min(2_int64*current, int(huge(current), int64)))
  end function larger_size
end module deck_line_table
