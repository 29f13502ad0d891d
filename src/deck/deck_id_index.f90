!> Sorted id -> position lookup (binary search), so resolving a million references costs
!> n log n, not n squared.
module deck_id_index
  implicit none
  private

  public :: id_index_t, build_id_index, find_id, lower_bound

  !> `ids` sorted ascending; `positions(k)` is where `ids(k)` stood in the original list.
  !> Equal ids keep their original order (the sort is stable), so the first definition of a
  !> duplicated id comes first.
  type :: id_index_t
    integer, allocatable :: ids(:)
    integer, allocatable :: positions(:)
    !> True when the original ids were first, first + 1, ... (the usual mesh numbering):
    !> then a lookup is a subtraction.
    logical :: consecutive = .false.
  end type id_index_t

contains

  !> Index the ids `ids` (positions 1..size(ids)).
  subroutine build_id_index(ids, index)
    integer, intent(in) :: ids(:)
    type(id_index_t), intent(out) :: index
    integer :: k
    index%ids = ids
    allocate (index%positions(size(ids)))
    do k = 1, size(ids)
      index%positions(k) = k
    end do
    if (size(ids) == 0) return
    index%consecutive = ids(size(ids)) - ids(1) == size(ids) - 1
    if (index%consecutive) index%consecutive = all(ids(2:) - ids(:size(ids) - 1) == 1)
    if (index%consecutive) return
    if (all(ids(2:) >= ids(:size(ids) - 1))) return   ! already sorted
    call merge_sort(index%ids, index%positions)
  end subroutine build_id_index

  !> Original position of `id` (its first definition), 0 when absent.
  pure integer function find_id(index, id)
    type(id_index_t), intent(in) :: index
    integer, intent(in) :: id
    integer :: k
    find_id = 0
    if (index%consecutive) then
      if (id >= index%ids(1) .and. id <= index%ids(size(index%ids))) find_id = id - index%ids(1) + 1
      return
    end if
    k = lower_bound(index, id)
    if (k <= size(index%ids)) then
      if (index%ids(k) == id) find_id = index%positions(k)
    end if
  end function find_id

  !> First k with ids(k) >= id (size + 1 when none).
  pure integer function lower_bound(index, id)
    type(id_index_t), intent(in) :: index
    integer, intent(in) :: id
    integer :: low, high, middle
    low = 1
    high = size(index%ids) + 1
    do while (low < high)
      middle = (low + high)/2
      if (index%ids(middle) < id) then
        low = middle + 1
      else
        high = middle
      end if
    end do
    lower_bound = low
  end function lower_bound

  !> Stable bottom-up merge sort of `keys`, carrying `values` along.
  subroutine merge_sort(keys, values)
    integer, intent(inout) :: keys(:), values(:)
    integer, allocatable :: key_buffer(:), value_buffer(:)
    integer :: n, width, start, middle, finish, left, right, k
    logical :: from_left
    n = size(keys)
    allocate (key_buffer(n), value_buffer(n))
    width = 1
    do while (width < n)
      do start = 1, n, 2*width
        middle = min(start + width, n + 1)
        finish = min(start + 2*width, n + 1)
        left = start
        right = middle
        do k = start, finish - 1
          ! Fortran does not short-circuit .and./.or., so the cases are spelled out
          if (left >= middle) then
            from_left = .false.
          else if (right >= finish) then
            from_left = .true.
          else
            from_left = keys(left) <= keys(right)
          end if
          if (from_left) then
            key_buffer(k) = keys(left)
            value_buffer(k) = values(left)
            left = left + 1
          else
            key_buffer(k) = keys(right)
            value_buffer(k) = values(right)
            right = right + 1
          end if
        end do
      end do
      keys = key_buffer
      values = value_buffer
      width = 2*width
    end do
  end subroutine merge_sort
end module deck_id_index
