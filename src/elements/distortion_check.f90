!> The FE solids folded inside out at a corner (a corner Jacobian <= 0, see hex8_quality),
!> checked at every state output. A one-point hexahedron can fold that far while its volume
!> stays positive: the run goes on, held by hourglass forces, and nothing would tell the user.
!> The check warns whenever the number of such elements has grown since its last warning, names
!> the worst element, and keeps the worst ratio of the run for `/run` in results.h5.
module distortion_check
  use kinds, only: wp
  use model, only: model_t
  use solid_block, only: solid_block_t
  use element_group, only: distortion_t
  use hex8_quality, only: corner_jacobian_ratio
  implicit none
  private

  public :: check_solid_distortion


contains

  !> Check the FE solid blocks at the current coordinates; warn on stdout when more elements
  !> are tangled than at the last warning.
  subroutine check_solid_distortion(model, blocks, coordinates, time, distortion)
    type(model_t), intent(in) :: model
    type(solid_block_t), intent(in) :: blocks(:)
    real(wp), intent(in) :: coordinates(:, :)
    real(wp), intent(in) :: time
    type(distortion_t), intent(inout) :: distortion
    integer :: block_tangled(size(blocks)), block_worst_element(size(blocks))
    real(wp) :: block_worst_ratio(size(blocks)), now_worst_ratio, ratio, corners(3, 8)
    integer :: b, lane, k, now_worst_element
    character(len=400) :: text

    !$omp parallel do schedule(static) default(shared) private(b, lane, k, ratio, corners)
    do b = 1, size(blocks)
      block_tangled(b) = 0
      block_worst_ratio(b) = huge(1.0_wp)
      block_worst_element(b) = 0
      do lane = 1, blocks(b)%element_count
        if (blocks(b)%eroded(lane)) cycle      ! out of the model: its nodes fly free
        do k = 1, 8
          corners(:, k) = coordinates(:, blocks(b)%nodes(lane, k))
        end do
        ratio = corner_jacobian_ratio(corners)
        if (ratio <= 0.0_wp) block_tangled(b) = block_tangled(b) + 1
        if (ratio < block_worst_ratio(b)) then
          block_worst_ratio(b) = ratio
          block_worst_element(b) = blocks(b)%elements(lane)
        end if
      end do
    end do
    !$omp end parallel do
    ! serial, in block order: the same worst element for any thread count
    distortion%tangled = sum(block_tangled)
    now_worst_ratio = huge(1.0_wp)
    now_worst_element = 0
    do b = 1, size(blocks)
      if (block_worst_ratio(b) < now_worst_ratio) then
        now_worst_ratio = block_worst_ratio(b)
        now_worst_element = block_worst_element(b)
      end if
    end do
    if (now_worst_element > 0 .and. now_worst_ratio < distortion%worst_ratio) then
      distortion%worst_ratio = now_worst_ratio
      distortion%worst_element = now_worst_element
    end if
    if (distortion%tangled > distortion%reported) then
      write (text, '(a,es11.4,a,i0,a,i0,a,i0,a,f6.3,a)') "warning: t = ", time, ": ", distortion%tangled, &
        " FE solid(s) folded inside out at a corner (corner Jacobian <= 0); the worst, element ", &
        model%solid_ids(now_worst_element), " (part ", model%parts(model%solid_part(now_worst_element))%id, &
        "), has a corner Jacobian ratio of ", now_worst_ratio, &
        ". Their one-point volumes stay positive and hourglass forces hold them: results there are not reliable"
      distortion%message = trim(text)
      distortion%reported = distortion%tangled
    end if
  end subroutine check_solid_distortion
end module distortion_check
