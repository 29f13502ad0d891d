!> Strict conversion of field text to numbers, and the small text helpers the deck reader shares
!> (numbers as text: text_format).
!>
!> List-directed reads accept "1 2" as 1 and "1,2" as 1, so every field is checked character by
!> character here instead. Reals take Fortran's forms, as LS-DYNA reads them: `1.5`, `-.5`,
!> `2e3`, `2.0D+3`, and `1.0-3` (exponent without its letter). Most values are converted
!> directly (exact and fast); long mantissas fall back to an internal read. Non-zero magnitudes
!> outside [1e-30, 1e30] are out of range.
module deck_numbers
  use kinds, only: wp
  use, intrinsic :: iso_fortran_env, only: int64
  implicit none
  private

  public :: parse_integer, parse_real, to_upper, digit

  !> Status codes of `parse_integer` and `parse_real`.
  integer, parameter, public :: number_ok = 0, number_invalid = 1, number_not_integral = 2, &
                                number_out_of_range = 3

  !> Exact powers of ten 10**0 ... 10**22 (every one is a double without rounding).
  real(wp), parameter :: exact_powers(0:22) = [1.0e0_wp, 1.0e1_wp, 1.0e2_wp, 1.0e3_wp, 1.0e4_wp, &
    1.0e5_wp, 1.0e6_wp, 1.0e7_wp, 1.0e8_wp, 1.0e9_wp, 1.0e10_wp, 1.0e11_wp, 1.0e12_wp, 1.0e13_wp, &
    1.0e14_wp, 1.0e15_wp, 1.0e16_wp, 1.0e17_wp, 1.0e18_wp, 1.0e19_wp, 1.0e20_wp, 1.0e21_wp, &
    1.0e22_wp]

contains

  !> Integer value of `text` (trimmed, not blank). An integral real such as `3.0` is accepted,
  !> as LS-DYNA's formatted reads accept it.
  subroutine parse_integer(text, value, status)
    character(len=*), intent(in) :: text
    integer, intent(out) :: value
    integer, intent(out) :: status
    integer(int64) :: accumulated
    real(wp) :: real_value
    integer :: position, first_digit
    logical :: negative

    value = 0
    status = number_invalid
    if (len(text) == 0) return
    negative = text(1:1) == "-"
    first_digit = 1
    if (text(1:1) == "-" .or. text(1:1) == "+") first_digit = 2
    if (first_digit > len(text)) return
    accumulated = 0
    do position = first_digit, len(text)
      if (.not. is_digit(text(position:position))) then
        call parse_real(text, real_value, status)
        if (status /= number_ok) return
        if (abs(real_value) > real(huge(value), wp)) then
          status = number_out_of_range
        else if (real_value /= aint(real_value)) then
          status = number_not_integral
        else
          value = nint(real_value)
        end if
        return
      end if
      accumulated = 10*accumulated + (iachar(text(position:position)) - iachar("0"))
      if (accumulated > huge(value)) then
        status = number_out_of_range
        return
      end if
    end do
    value = int(accumulated)
    if (negative) value = -value
    status = number_ok
  end subroutine parse_integer

  !> Real value of `text` (trimmed, not blank).
  subroutine parse_real(text, value, status)
    character(len=*), intent(in) :: text
    real(wp), intent(out) :: value
    integer, intent(out) :: status
    integer(int64) :: mantissa
    integer :: position, digits, fraction_digits, exponent, exponent_sign, dropped_digits
    integer :: significant, magnitude
    logical :: negative, after_point
    character :: c

    value = 0.0_wp
    status = number_invalid
    position = 1
    negative = .false.
    if (text(1:1) == "-" .or. text(1:1) == "+") then
      negative = text(1:1) == "-"
      position = 2
    end if
    mantissa = 0
    digits = 0
    significant = 0
    fraction_digits = 0
    dropped_digits = 0
    after_point = .false.
    do while (position <= len(text))
      c = text(position:position)
      if (is_digit(c)) then
        digits = digits + 1
        if (mantissa == 0 .and. c == "0") then
          ! leading zeros are not significant digits
          if (after_point) fraction_digits = fraction_digits + 1
        else if (significant < 18) then
          mantissa = 10*mantissa + (iachar(c) - iachar("0"))
          significant = significant + 1
          if (after_point) fraction_digits = fraction_digits + 1
        else if (.not. after_point) then
          ! a digit beyond the 18th before the point still scales the value by ten
          dropped_digits = dropped_digits + 1
        end if
      else if (c == "." .and. .not. after_point) then
        after_point = .true.
      else
        exit
      end if
      position = position + 1
    end do
    if (digits == 0) return
    exponent = 0
    if (position <= len(text)) then
      c = text(position:position)
      if (index("eEdD", c) > 0) then
        position = position + 1
      else if (c /= "+" .and. c /= "-") then
        return
      end if
      exponent_sign = 1
      if (position <= len(text)) then
        if (text(position:position) == "+" .or. text(position:position) == "-") then
          if (text(position:position) == "-") exponent_sign = -1
          position = position + 1
        end if
      end if
      if (position > len(text)) return
      do while (position <= len(text))
        c = text(position:position)
        if (.not. is_digit(c)) return
        if (exponent < 100000) exponent = 10*exponent + (iachar(c) - iachar("0"))
        position = position + 1
      end do
      exponent = exponent_sign*exponent
    end if
    exponent = exponent + dropped_digits - fraction_digits
    if (mantissa == 0) then
      status = number_ok
      return
    end if
    ! Decimal magnitude of the value: 10**(magnitude-1) <= |value| < 10**magnitude. Non-zero
    ! values outside [1e-30, 1e30] are refused: no input quantity in any consistent unit system
    ! is near them (LS-DYNA's "never" is 1e20 or 1e28; densities in t/mm^3 are 1e-9), and the
    ! products and quotients of the ten or so inputs that meet in one formula (stiffness over
    ! density over a length, a wall's mass times its speed squared) then stay far from overflow
    ! and underflow, so a deck of extreme values gets a message here instead of a blow-up later.
    magnitude = exponent + significant
    if (magnitude > 31 .or. magnitude < -29) then
      status = number_out_of_range
      return
    end if
    if (mantissa <= 2_int64**53 .and. abs(exponent) <= 22) then
      ! Clinger's fast path: both factors are exact doubles, so one rounding gives the
      ! correctly rounded result
      if (exponent >= 0) then
        value = real(mantissa, wp)*exact_powers(exponent)
      else
        value = real(mantissa, wp)/exact_powers(-exponent)
      end if
    else
      call read_real_slowly(text, value, status)
      if (status /= number_ok) return
      value = abs(value)
    end if
    if (value > 1.0e30_wp) then      ! 1e30 < value < 1e31 passed the magnitude test above
      value = 0.0_wp
      status = number_out_of_range
      return
    end if
    if (negative) value = -value
    status = number_ok
  end subroutine parse_real

  !> Formatted read for the rare values outside the fast path (already checked for syntax).
  subroutine read_real_slowly(text, value, status)
    character(len=*), intent(in) :: text
    real(wp), intent(out) :: value
    integer, intent(out) :: status
    character(len=32) :: edit
    integer :: io_status
    write (edit, '(a,i0,a)') "(f", len(text), ".0)"
    read (text, edit, iostat=io_status) value
    status = number_ok
    if (io_status /= 0) status = number_invalid
  end subroutine read_real_slowly

  pure logical function is_digit(c)
    character, intent(in) :: c
    is_digit = c >= "0" .and. c <= "9"
  end function is_digit

  !> Upper-case copy of `text` (ASCII letters only).
  pure function to_upper(text) result(upper)
    character(len=*), intent(in) :: text
    character(len=len(text)) :: upper
    integer :: k, code
    upper = text
    do k = 1, len(text)
      code = iachar(text(k:k))
      if (code >= iachar("a") .and. code <= iachar("z")) upper(k:k) = achar(code - 32)
    end do
  end function to_upper

  !> The digit of 0 <= `value` <= 9, for field names such as NID3 (cheaper than a write).
  pure character function digit(value)
    integer, intent(in) :: value
    digit = achar(iachar("0") + modulo(value, 10))
  end function digit
end module deck_numbers
