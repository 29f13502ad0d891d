!> Numbers as text for the messages of the static analysis (ids, counts, magnitudes).
module static_messages
  use kinds, only: wp
  implicit none
  private

  public :: integer_text, real_text

contains

  !> An integer without blanks ("104").
  pure function integer_text(value) result(text)
    integer, intent(in) :: value
    character(len=:), allocatable :: text
    character(len=16) :: buffer
    write (buffer, '(i0)') value
    text = trim(buffer)
  end function integer_text

  !> A real in scientific notation with four significant digits ("1.002E-15").
  pure function real_text(value) result(text)
    real(wp), intent(in) :: value
    character(len=:), allocatable :: text
    character(len=24) :: buffer
    write (buffer, '(es10.3)') value
    text = trim(adjustl(buffer))
  end function real_text
end module static_messages
