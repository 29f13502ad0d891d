!> Growable integer lists: an allocatable array whose first `used` entries (or columns) are in
!> use, grown geometrically (at least doubled) when more room is needed, so that appending n
!> values costs O(n) in all.
module integer_lists
  implicit none
  private

  public :: reserve_integers, reserve_integer_columns, append_integer, sorted_position, sort_short_list, &
            sort_integers

contains

  !> Room for `needed` entries in `list`, keeping the first `used`; `list` may be unallocated
  !> (it then gets max(`minimum`, needed) entries, by default 16).
  pure subroutine reserve_integers(list, used, needed, minimum)
    integer, allocatable, intent(inout) :: list(:)
    integer, intent(in) :: used, needed
    integer, intent(in), optional :: minimum
    integer, allocatable :: grown(:)
    if (.not. allocated(list)) then
      allocate (list(max(first_capacity(minimum), needed)))
      return
    end if
    if (size(list) >= needed) return
    allocate (grown(max(needed, 2*size(list))))
    grown(1:used) = list(1:used)
    call move_alloc(grown, list)
  end subroutine reserve_integers

  !> Room for `needed` columns of `rows` entries in `list`, keeping the first `used` columns;
  !> `list` may be unallocated (it then gets max(`minimum`, needed) columns, by default 16).
  pure subroutine reserve_integer_columns(list, rows, used, needed, minimum)
    integer, allocatable, intent(inout) :: list(:, :)
    integer, intent(in) :: rows, used, needed
    integer, intent(in), optional :: minimum
    integer, allocatable :: grown(:, :)
    if (.not. allocated(list)) then
      allocate (list(rows, max(first_capacity(minimum), needed)))
      return
    end if
    if (size(list, 2) >= needed) return
    allocate (grown(rows, max(needed, 2*size(list, 2))))
    grown(:, 1:used) = list(:, 1:used)
    call move_alloc(grown, list)
  end subroutine reserve_integer_columns

  !> Append `value` to list(1:count) (count + 1 entries afterwards; the list grows as needed).
  pure subroutine append_integer(list, count, value)
    integer, allocatable, intent(inout) :: list(:)
    integer, intent(inout) :: count
    integer, intent(in) :: value
    call reserve_integers(list, count, count + 1)
    count = count + 1
    list(count) = value
  end subroutine append_integer

  pure integer function first_capacity(minimum)
    integer, intent(in), optional :: minimum
    first_capacity = 16
    if (present(minimum)) first_capacity = minimum
  end function first_capacity

  !> Position of `value` in the ascending list (0 if absent), by bisection.
  pure integer function sorted_position(list, value)
    integer, intent(in) :: list(:), value
    integer :: low, high, middle

    sorted_position = 0
    low = 1
    high = size(list)
    do while (low <= high)
      middle = (low + high)/2
      if (list(middle) == value) then
        sorted_position = middle
        return
      else if (list(middle) < value) then
        low = middle + 1
      else
        high = middle - 1
      end if
    end do
  end function sorted_position

  !> Sort a short list ascending in place (insertion sort: the lists here hold a few dozen
  !> entries, mostly in order already).
  pure subroutine sort_short_list(values)
    integer, intent(inout) :: values(:)
    integer :: i, j, held

    do i = 2, size(values)
      held = values(i)
      j = i - 1
      do while (j >= 1)
        if (values(j) <= held) exit
        values(j + 1) = values(j)
        j = j - 1
      end do
      values(j + 1) = held
    end do
  end subroutine sort_short_list

  !> Ascending heap sort in place: n log n whatever the input (a particle's neighbours, a meshfree
  !> block's thousands of pair nodes).
  pure subroutine sort_integers(values)
    integer, intent(inout) :: values(:)
    integer :: n, last, held

    n = size(values)
    do last = n/2, 1, -1
      call sift_down(values, last, n)
    end do
    do last = n, 2, -1
      held = values(1)
      values(1) = values(last)
      values(last) = held
      call sift_down(values, 1, last - 1)
    end do
  end subroutine sort_integers

  pure subroutine sift_down(values, start, last)
    integer, intent(inout) :: values(:)
    integer, intent(in) :: start, last
    integer :: root, child, held

    root = start
    held = values(root)
    do
      child = 2*root
      if (child > last) exit
      if (child < last) then
        if (values(child + 1) > values(child)) child = child + 1
      end if
      if (values(child) <= held) exit
      values(root) = values(child)
      root = child
    end do
    values(root) = held
  end subroutine sift_down
end module integer_lists
