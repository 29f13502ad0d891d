!> Numbers as text for messages, file names and XML: one definition of each form, so that a
!> number reads the same wherever it is printed.
!>
!> - `integer_text(value)`: decimal digits without blanks ("104", "-3"), default or 64-bit;
!> - `real_text(value)`: short text for messages: plain decimals for ordinary magnitudes,
!>   otherwise scientific notation, trailing zeros removed ("0.3", "210.0", "7.8e-6");
!> - `scientific_text(value, decimals[, exponent_digits])`: Fortran's ES form with `decimals`
!>   digits after the point, without blanks ("1.002E-15"; three exponent digits always with
!>   `exponent_digits` = 3);
!> - `fixed_text(value, decimals)`: Fortran's F0.d form ("12.50").
module text_format
  use kinds, only: wp
  use, intrinsic :: iso_fortran_env, only: int64
  implicit none
  private

  public :: integer_text, real_text, scientific_text, fixed_text

  !> Decimal text of an integer, without blanks.
  interface integer_text
    module procedure default_integer_text, long_integer_text
  end interface integer_text

contains

  pure function default_integer_text(value) result(text)
    integer, intent(in) :: value
    character(len=:), allocatable :: text
    character(len=24) :: buffer
    write (buffer, '(i0)') value
    text = trim(buffer)
  end function default_integer_text

  pure function long_integer_text(value) result(text)
    integer(int64), intent(in) :: value
    character(len=:), allocatable :: text
    character(len=24) :: buffer
    write (buffer, '(i0)') value
    text = trim(buffer)
  end function long_integer_text

  !> `value` as short text for messages: plain decimals for ordinary magnitudes, otherwise
  !> scientific notation, trailing zeros removed (0.3, 210.0, 7.8e-6).
  pure function real_text(value) result(text)
    real(wp), intent(in) :: value
    character(len=:), allocatable :: text
    character(len=40) :: buffer
    integer :: mark
    if (value == 0.0_wp .or. (abs(value) >= 1.0e-3_wp .and. abs(value) < 1.0e7_wp)) then
      write (buffer, '(f0.10)') value
      text = without_trailing_zeros(trim(adjustl(buffer)))
      if (text(1:1) == ".") text = "0"//text
      if (text(1:2) == "-.") text = "-0"//text(2:)
    else
      write (buffer, '(es24.14e3)') value
      buffer = adjustl(buffer)
      mark = index(buffer, "E")
      text = without_trailing_zeros(buffer(1:mark - 1))//"e"// &
             integer_text(exponent_value(buffer(mark + 1:)))
    end if
  end function real_text

  !> `value` written with ES(w).(decimals) (or ES(w).(decimals)E(exponent_digits)), leading
  !> blanks removed: "1.002E-15" for decimals = 3. The width is the smallest that always
  !> fits, so the text is what any wider ES field holds.
  pure function scientific_text(value, decimals, exponent_digits) result(text)
    real(wp), intent(in) :: value
    integer, intent(in) :: decimals
    integer, intent(in), optional :: exponent_digits
    character(len=:), allocatable :: text
    character(len=32) :: form
    character(len=64) :: buffer
    if (present(exponent_digits)) then
      write (form, '("(es", i0, ".", i0, "e", i0, ")")') decimals + 6 + exponent_digits, decimals, &
        exponent_digits
    else
      write (form, '("(es", i0, ".", i0, ")")') decimals + 7, decimals
    end if
    write (buffer, form) value
    text = trim(adjustl(buffer))
  end function scientific_text

  !> `value` written with F0.(decimals): no leading blanks, as many digits before the point
  !> as needed.
  pure function fixed_text(value, decimals) result(text)
    real(wp), intent(in) :: value
    integer, intent(in) :: decimals
    character(len=:), allocatable :: text
    character(len=16) :: form
    character(len=64) :: buffer
    write (form, '("(f0.", i0, ")")') decimals
    write (buffer, form) value
    text = trim(adjustl(buffer))
  end function fixed_text

  !> "2.500" -> "2.5", "3.000" -> "3.0".
  pure function without_trailing_zeros(text) result(short)
    character(len=*), intent(in) :: text
    character(len=:), allocatable :: short
    integer :: last
    last = len(text)
    do while (last > 1 .and. text(last:last) == "0")
      last = last - 1
    end do
    if (text(last:last) == ".") last = min(last + 1, len(text))
    short = text(1:last)
  end function without_trailing_zeros

  pure integer function exponent_value(text)
    character(len=*), intent(in) :: text
    integer :: status
    read (text, *, iostat=status) exponent_value
    if (status /= 0) exponent_value = 0
  end function exponent_value
end module text_format
