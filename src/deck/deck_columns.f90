!> Where the fields of one card are: fixed columns (standard, long or I10 widths) or
!> comma-separated entries.
!>
!> A card is either all fixed or all comma format (a deck may mix them from card to card), and
!> fixed fields are cut by column, never by whitespace: LS-DYNA decks may pack numbers with no
!> blank between them.
module deck_columns
  implicit none
  private

  public :: field_spans_t, split_fields, field_width

  !> Card formats: LS-DYNA's standard widths, long format (every field at least 20 wide,
  !> `LONG=Y` or a `+` suffix) and I10 (every field at least 10 wide, `I10=Y` or `%`).
  integer, parameter, public :: format_standard = 0, format_long = 1, format_i10 = 2

  !> Most fields a card may have (element cards have 10; extra comma entries are ignored).
  integer, parameter, public :: max_fields = 16

  !> Positions of the fields of one card, relative to the card's text (1 = its first column).
  !> An empty field has `last < first`. For fixed cards `column_first/last` are the columns of
  !> the field as laid out, whether or not the line reaches them.
  type :: field_spans_t
    logical :: free = .false.
    !> A tab comes before the card's last text, where it would move columns (`tab_column`:
    !> the first such tab). Tabs after the last text change no field and are not counted.
    logical :: has_tab = .false.
    integer :: tab_column = 0
    integer :: count = 0
    integer :: first(max_fields) = 1
    integer :: last(max_fields) = 0
    integer :: column_first(max_fields) = 0
    integer :: column_last(max_fields) = 0
  end type field_spans_t

contains

  !> Width of a field whose standard width is `standard_width` in `format`.
  pure integer function field_width(standard_width, format)
    integer, intent(in) :: standard_width, format
    select case (format)
    case (format_long)
      field_width = max(standard_width, 20)
    case (format_i10)
      field_width = max(standard_width, 10)
    case default
      field_width = standard_width
    end select
  end function field_width

  !> Split `line` into fields laid out with standard `widths` in `format`, or at commas when
  !> the line holds a comma.
  pure subroutine split_fields(line, widths, format, spans)
    character(len=*), intent(in) :: line
    integer, intent(in) :: widths(:)
    integer, intent(in) :: format
    type(field_spans_t), intent(out) :: spans
    integer :: k, column, comma, start, commas, tabs

    ! one counting loop for both (it vectorizes; two calls of `index` cost several times more)
    commas = 0
    tabs = 0
    do k = 1, len(line)
      if (line(k:k) == ",") commas = commas + 1
      if (line(k:k) == achar(9)) tabs = tabs + 1
    end do
    spans%free = commas > 0
    if (tabs > 0) then
      spans%tab_column = index(line, achar(9))
      spans%has_tab = spans%tab_column < verify(line, " "//achar(9), back=.true.)
    end if
    if (spans%free) then
      start = 1
      do k = 1, max_fields
        comma = index(line(start:), ",")
        spans%count = k
        spans%first(k) = start
        spans%column_first(k) = start
        if (comma == 0) then
          spans%last(k) = len(line)
          spans%column_last(k) = len(line)
          exit
        end if
        spans%last(k) = start + comma - 2
        spans%column_last(k) = spans%last(k)
        start = start + comma
      end do
      return
    end if
    spans%count = min(size(widths), max_fields)
    column = 1
    do k = 1, spans%count
      spans%column_first(k) = column
      spans%column_last(k) = column + field_width(widths(k), format) - 1
      spans%first(k) = column
      spans%last(k) = min(spans%column_last(k), len(line))
      column = spans%column_last(k) + 1
    end do
  end subroutine split_fields
end module deck_columns
