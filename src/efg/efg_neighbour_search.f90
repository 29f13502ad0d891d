!> Neighbour search over the particles of a meshfree part: which particles' supports cover a
!> point or touch a box (a background cell).
!>
!> A uniform grid of bins (cell lists) over the particles' support boxes [X_I - a_I, X_I + a_I].
!> Each particle is listed in every bin its support box overlaps; the bin size is the mean
!> support diameter, so a particle sits in about 8 bins and a bin holds the particles whose
!> supports reach it. Building and querying are then linear in the number of particles (no
!> O(n^2) search), with the bin count capped at a few times the particle count.
!> A particle met in several bins of one query is reported once: only from the first bin of the
!> intersection of its bin range with the query's. Results are in ascending particle order, so
!> everything built from them is deterministic.
module efg_neighbour_search
  use kinds, only: wp
  use integer_lists, only: append_integer, sort_integers
  use efg_kernel, only: kernel_weight
  implicit none
  private

  public :: particle_grid_t, build_particle_grid, find_support_candidates, find_covering_particles

  !> Bins over the particles' support boxes.
  type :: particle_grid_t
    real(wp) :: origin(3) = 0.0_wp
    real(wp) :: spacing(3) = 1.0_wp
    integer :: bins(3) = 0                       !< bins per direction (0: no particles)
    integer, allocatable :: offsets(:)           !< members of bin b: offsets(b) : offsets(b+1)-1
    integer, allocatable :: members(:)           !< particle numbers
    integer, allocatable :: first_bin(:, :)      !< (3, particles): bin range of each support box
    integer, allocatable :: last_bin(:, :)
  end type particle_grid_t

  !> At most this many bins per particle (keeps memory linear for very uneven supports).
  integer, parameter :: bins_per_particle = 4

contains

  !> Bin the supports of particles at `centres` (3, n) with radii `radius` (3, n).
  subroutine build_particle_grid(centres, radius, grid)
    real(wp), intent(in) :: centres(:, :), radius(:, :)
    type(particle_grid_t), intent(out) :: grid
    real(wp) :: upper(3), extent(3), bin_count
    integer, allocatable :: fill(:)
    integer :: particle_count, particle, k, i, j, l, bin, total

    particle_count = size(centres, 2)
    allocate (grid%first_bin(3, particle_count), grid%last_bin(3, particle_count))
    if (particle_count == 0) then
      allocate (grid%offsets(1), grid%members(0))
      grid%offsets = 1
      return
    end if
    do k = 1, 3
      grid%origin(k) = minval(centres(k, :) - radius(k, :))
      upper(k) = maxval(centres(k, :) + radius(k, :))
      extent(k) = max(upper(k) - grid%origin(k), tiny(1.0_wp))
      grid%spacing(k) = max(2.0_wp*sum(radius(k, :))/particle_count, extent(k)*1.0e-9_wp)
    end do
    ! enlarge the bins uniformly if there would be too many of them
    bin_count = product(max(extent/grid%spacing, 1.0_wp))
    if (bin_count > real(bins_per_particle*particle_count + 8, wp)) &
      grid%spacing = grid%spacing*(bin_count/real(bins_per_particle*particle_count + 8, wp))**(1.0_wp/3.0_wp)
    grid%bins = max(1, min(ceiling(extent/grid%spacing), bins_per_particle*particle_count + 8))

    do particle = 1, particle_count
      grid%first_bin(:, particle) = bin_of(grid, centres(:, particle) - radius(:, particle))
      grid%last_bin(:, particle) = bin_of(grid, centres(:, particle) + radius(:, particle))
    end do

    allocate (grid%offsets(product(grid%bins) + 1))
    grid%offsets = 0
    do particle = 1, particle_count
      do l = grid%first_bin(3, particle), grid%last_bin(3, particle)
        do j = grid%first_bin(2, particle), grid%last_bin(2, particle)
          do i = grid%first_bin(1, particle), grid%last_bin(1, particle)
            bin = bin_number(grid, [i, j, l])
            grid%offsets(bin + 1) = grid%offsets(bin + 1) + 1
          end do
        end do
      end do
    end do
    grid%offsets(1) = 1
    do bin = 1, product(grid%bins)
      grid%offsets(bin + 1) = grid%offsets(bin + 1) + grid%offsets(bin)
    end do
    total = grid%offsets(product(grid%bins) + 1) - 1
    allocate (grid%members(total), fill(product(grid%bins)))
    fill = grid%offsets(1:product(grid%bins))
    do particle = 1, particle_count
      do l = grid%first_bin(3, particle), grid%last_bin(3, particle)
        do j = grid%first_bin(2, particle), grid%last_bin(2, particle)
          do i = grid%first_bin(1, particle), grid%last_bin(1, particle)
            bin = bin_number(grid, [i, j, l])
            grid%members(fill(bin)) = particle
            fill(bin) = fill(bin) + 1
          end do
        end do
      end do
    end do
  end subroutine build_particle_grid

  !> Particles whose support box intersects the box [low, high] (closed intervals), in
  !> ascending order: found(1:count). A superset of the particles covering any point of the box.
  subroutine find_support_candidates(grid, centres, radius, low, high, found, count)
    type(particle_grid_t), intent(in) :: grid
    real(wp), intent(in) :: centres(:, :), radius(:, :), low(3), high(3)
    integer, allocatable, intent(inout) :: found(:)
    integer, intent(out) :: count
    integer :: first(3), last(3), i, j, l, member, particle

    count = 0
    if (.not. allocated(found)) allocate (found(64))
    if (any(grid%bins == 0)) return
    first = bin_of(grid, low)
    last = bin_of(grid, high)
    do l = first(3), last(3)
      do j = first(2), last(2)
        do i = first(1), last(1)
          do member = grid%offsets(bin_number(grid, [i, j, l])), &
            grid%offsets(bin_number(grid, [i, j, l]) + 1) - 1
            particle = grid%members(member)
            ! report each particle from one bin only
            if (any([i, j, l] /= max(first, grid%first_bin(:, particle)))) cycle
            if (any(centres(:, particle) - radius(:, particle) > high)) cycle
            if (any(centres(:, particle) + radius(:, particle) < low)) cycle
            call append_integer(found, count, particle)
          end do
        end do
      end do
    end do
    call sort_integers(found(1:count))
  end subroutine find_support_candidates

  !> Particles whose support covers `point` (kernel weight > 0), in ascending order.
  subroutine find_covering_particles(grid, centres, radius, kernel, point, found, count)
    type(particle_grid_t), intent(in) :: grid
    real(wp), intent(in) :: centres(:, :), radius(:, :), point(3)
    integer, intent(in) :: kernel
    integer, allocatable, intent(inout) :: found(:)
    integer, intent(out) :: count
    integer :: candidate_count, k

    call find_support_candidates(grid, centres, radius, point, point, found, candidate_count)
    count = 0
    do k = 1, candidate_count
      if (kernel_weight(kernel, centres(:, found(k)), radius(:, found(k)), point) > 0.0_wp) then
        count = count + 1
        found(count) = found(k)
      end if
    end do
  end subroutine find_covering_particles

  !> Bin indices (clamped to the grid) of a point.
  pure function bin_of(grid, point) result(bin)
    type(particle_grid_t), intent(in) :: grid
    real(wp), intent(in) :: point(3)
    integer :: bin(3)
    real(wp) :: position(3)

    position = (point - grid%origin)/grid%spacing
    position = min(max(position, 0.0_wp), real(grid%bins, wp))
    bin = min(max(int(position) + 1, 1), grid%bins)
  end function bin_of

  pure integer function bin_number(grid, bin)
    type(particle_grid_t), intent(in) :: grid
    integer, intent(in) :: bin(3)
    bin_number = bin(1) + grid%bins(1)*((bin(2) - 1) + grid%bins(2)*(bin(3) - 1))
  end function bin_number
end module efg_neighbour_search
