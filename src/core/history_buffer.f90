!> In-memory time histories (glstat, matsum, nodout, rwforc, ...) recorded during the run.
!>
!> Every history is a group `/history/<group>` of named columns sharing one row per sample;
!> a column is a scalar (width 1) or a vector (width 3). The results writer stores each column
!> as one dataset. Rows are kept in memory so that an error termination still writes them all;
!> capacity is reserved from the end time and the interval, so growth in the loop is rare.
module history_buffer
  use kinds, only: wp
  implicit none
  private

  public :: history_series_t, history_set_t, add_history_series, append_history_row

  !> One history group: column names and widths, and the rows recorded so far.
  type :: history_series_t
    character(len=:), allocatable :: group          !< e.g. "glstat", "matsum/3", "nodout/17"
    character(len=32), allocatable :: names(:)      !< column names, the first is "time"
    integer, allocatable :: widths(:)               !< 1 (scalar) or 3 (vector) per column
    integer :: row_width = 0                        !< sum of widths
    integer :: count = 0                            !< rows recorded
    real(wp), allocatable :: rows(:, :)             !< (row_width, capacity)
  end type history_series_t

  !> All histories of a run.
  type :: history_set_t
    integer :: count = 0
    type(history_series_t), allocatable :: series(:)
  end type history_set_t

contains

  !> Add a history group; `index` is its position in `set%series`.
  subroutine add_history_series(set, group, names, widths, capacity, index)
    type(history_set_t), intent(inout) :: set
    character(len=*), intent(in) :: group
    character(len=*), intent(in) :: names(:)
    integer, intent(in) :: widths(:)
    integer, intent(in) :: capacity
    integer, intent(out) :: index
    type(history_series_t), allocatable :: grown(:)
    integer :: k

    if (.not. allocated(set%series)) allocate (set%series(8))
    if (set%count == size(set%series)) then
      allocate (grown(2*size(set%series)))
      ! each series' arrays are moved, not copied (a copy held every reserved row twice: a
      ! thousand nodout nodes reserve hundreds of MB)
      do k = 1, set%count
        call move_series(set%series(k), grown(k))
      end do
      call move_alloc(grown, set%series)
    end if
    set%count = set%count + 1
    index = set%count
    associate (series => set%series(index))
      series%group = group
      allocate (series%names(size(names)))
      series%names = names
      series%widths = widths
      series%row_width = sum(widths)
      series%count = 0
      allocate (series%rows(series%row_width, max(capacity, 16)))
    end associate
  end subroutine add_history_series

  !> `from` into `to`, its arrays moved (from is left empty).
  subroutine move_series(from, to)
    type(history_series_t), intent(inout) :: from, to
    to%count = from%count
    to%row_width = from%row_width
    call move_alloc(from%group, to%group)
    call move_alloc(from%names, to%names)
    call move_alloc(from%widths, to%widths)
    call move_alloc(from%rows, to%rows)
  end subroutine move_series

  !> Record one row (all columns concatenated, time first).
  subroutine append_history_row(series, row)
    type(history_series_t), intent(inout) :: series
    real(wp), intent(in) :: row(:)
    real(wp), allocatable :: grown(:, :)
    if (series%count == size(series%rows, 2)) then
      allocate (grown(series%row_width, 2*size(series%rows, 2)))
      grown(:, 1:series%count) = series%rows(:, 1:series%count)
      call move_alloc(grown, series%rows)
    end if
    series%count = series%count + 1
    series%rows(:, series%count) = row
  end subroutine append_history_row
end module history_buffer
