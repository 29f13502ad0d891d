!> Segments, the 3- and 4-node faces that *SET_SEGMENT, *LOAD_SEGMENT and
!> *LOAD_SEGMENT_NONUNIFORM list: their corner nodes as one card writes them, and the area test
!> of the cross-check.
module deck_segments
  use kinds, only: wp
  use deck_problems, only: problem_log_t
  use deck_numbers, only: digit
  use text_format, only: integer_text
  use deck_lexer, only: deck_t
  use deck_fields, only: card_t, get_integer, card_problem
  implicit none
  private

  public :: read_segment_nodes, segment_has_no_area

contains

  !> N1-N4 from fields `first` to `first + 3` of `card`. N4 blank or 0 is a triangle and becomes
  !> N3, LS-DYNA's way of writing one. `usable` is false once a problem was reported: a field
  !> that is not an integer, an id <= 0, or a node repeated other than N4 = N3.
  subroutine read_segment_nodes(deck, card, first, nodes, usable, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    integer, intent(in) :: first
    integer, intent(out) :: nodes(4)
    logical, intent(out) :: usable
    type(problem_log_t), intent(inout) :: log
    integer :: k, earlier
    logical :: failed_before

    failed_before = card%failed
    card%failed = .false.
    do k = 1, 4
      call get_integer(deck, card, first + k - 1, "N"//digit(k), nodes(k), log)
    end do
    usable = .not. card%failed
    card%failed = card%failed .or. failed_before
    if (.not. usable) return
    do k = 1, 3
      if (nodes(k) > 0) cycle
      call card_problem(deck, log, card, "N"//digit(k), "node id must be > 0, found "// &
                        integer_text(nodes(k)))
      usable = .false.
    end do
    if (nodes(4) < 0) then
      call card_problem(deck, log, card, "N4", "node id must be > 0 (blank or 0: a triangle, "// &
                        "N4 = N3), found "//integer_text(nodes(4)))
      usable = .false.
    end if
    if (.not. usable) return
    if (nodes(4) == 0) nodes(4) = nodes(3)
    do k = 2, 4
      do earlier = 1, k - 1
        if (nodes(earlier) /= nodes(k) .or. (earlier == 3 .and. k == 4)) cycle
        call card_problem(deck, log, card, "N"//digit(k), "the segment repeats node "// &
          integer_text(nodes(k))//" (N"//digit(earlier)//" and N"//digit(k)//"); only N4 "// &
          "may repeat N3 (a triangle)")
        usable = .false.
        return
      end do
    end do
  end subroutine read_segment_nodes

  !> True when the segment with corners `x(3, 4)` (a triangle repeats corner 3) has no area:
  !> half the cross product of its diagonals, which is its area vector for a triangle and for
  !> a flat quadrilateral, is below 1e-10 of the square of its longest edge. Corners that
  !> coincide or lie on one line, and a quadrilateral folded onto itself, have none.
  pure logical function segment_has_no_area(x)
    real(wp), intent(in) :: x(3, 4)
    real(wp) :: longest, first(3), second(3), area(3)
    longest = max(norm2(x(:, 2) - x(:, 1)), norm2(x(:, 3) - x(:, 2)), &
                  norm2(x(:, 4) - x(:, 3)), norm2(x(:, 1) - x(:, 4)))
    first = x(:, 3) - x(:, 1)
    second = x(:, 4) - x(:, 2)
    area = 0.5_wp*[first(2)*second(3) - first(3)*second(2), &
                   first(3)*second(1) - first(1)*second(3), &
                   first(1)*second(2) - first(2)*second(1)]
    segment_has_no_area = norm2(area) <= 1.0e-10_wp*longest**2
  end function segment_has_no_area
end module deck_segments
