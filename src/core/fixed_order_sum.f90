!> Floating-point sums whose result does not depend on the thread count.
!>
!> A parallel loop adds its terms into partial sums over fixed chunks of `sum_chunk_size`
!> items (one chunk per iteration of the parallel loop, each summed in item order); the
!> partial sums are then added in chunk order by `sum_in_order`. An OpenMP sum reduction
!> instead adds in an order that follows the threads, so its last bits change with `ncpu`.
module fixed_order_sum
  use kinds, only: wp
  implicit none
  private

  public :: sum_chunk_size, chunk_count, sum_in_order

  !> Items per partial sum.
  integer, parameter :: sum_chunk_size = 4096

contains

  !> Number of chunks (at least one) that cover `item_count` items.
  pure integer function chunk_count(item_count)
    integer, intent(in) :: item_count
    chunk_count = max(1, (item_count + sum_chunk_size - 1)/sum_chunk_size)
  end function chunk_count

  !> The partial sums added one after the other, first to last.
  pure real(wp) function sum_in_order(partial)
    real(wp), intent(in) :: partial(:)
    integer :: k
    sum_in_order = 0.0_wp
    do k = 1, size(partial)
      sum_in_order = sum_in_order + partial(k)
    end do
  end function sum_in_order
end module fixed_order_sum
