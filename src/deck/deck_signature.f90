!> The files a deck was read from and a signature of their bytes, which a restart checks: a
!> restart re-reads the deck from its recorded path and continues only when every file (the
!> main deck and its includes, in reading order) holds the same bytes as when the dump was
!> written.
!>
!> The signature of a file is its FNV-1a hash (64 bit, Fowler-Noll-Vo) over all its bytes,
!> written as 16 hexadecimal digits. It finds any accidental change (an edited value, a
!> re-generated mesh); it is not meant to resist someone forging a deck.
module deck_signature
  use, intrinsic :: iso_fortran_env, only: int64
  use error_handling, only: error_t, make_error
  use deck_file_io, only: inspect_file, open_file, read_bytes, close_file, file_handle_t, file_regular
  implicit none
  private

  public :: deck_source_t, sign_deck_files, fnv1a_hash, hash_text

  !> One file of a deck, as the deck reader found it.
  type :: deck_source_t
    character(len=:), allocatable :: path        !< as opened (include paths resolved)
    integer(int64) :: size = 0                   !< bytes
    integer(int64) :: modified = 0               !< modification time when read (ns since 1970)
  end type deck_source_t

  !> FNV-1a's offset basis and prime, the 64-bit state kept as two 32-bit halves in 64-bit
  !> integers, so that no product overflows (0xcbf29ce484222325; 0x100000001b3 = 2^40 + 435).
  integer(int64), parameter :: basis_high = 3421674724_int64, basis_low = 2216829733_int64
  integer(int64), parameter :: prime_low = 435_int64, low_mask = 4294967295_int64, &
                               low_24_bits = 16777215_int64
  !> Bytes read per step.
  integer, parameter :: chunk = 1048576

contains

  !> The signature of each file (16 hexadecimal digits), after checking that it is still the
  !> file the deck reader read (same size and modification time): a file changed since then
  !> cannot be signed for the run that read it.
  subroutine sign_deck_files(sources, hashes, error)
    type(deck_source_t), intent(in) :: sources(:)
    character(len=16), allocatable, intent(out) :: hashes(:)
    type(error_t), allocatable, intent(out) :: error
    character(len=:), allocatable :: buffer
    type(file_handle_t) :: handle
    integer(int64) :: bytes, modified, offset, high, low
    integer :: k, kind, count
    logical :: opened, failed

    allocate (hashes(size(sources)))
    allocate (character(len=chunk) :: buffer)
    do k = 1, size(sources)
      call inspect_file(sources(k)%path, kind, bytes, modified)
      if (kind /= file_regular .or. bytes /= sources(k)%size .or. modified /= sources(k)%modified) then
        call make_error(error, "deck file "//sources(k)%path//" changed since the run read it")
        return
      end if
      call open_file(sources(k)%path, handle, opened)
      if (.not. opened) then
        call make_error(error, "deck file "//sources(k)%path//" cannot be opened again")
        return
      end if
      high = basis_high
      low = basis_low
      offset = 0
      failed = .false.
      do while (offset < bytes .and. .not. failed)
        call read_bytes(handle, offset, buffer, count, failed)
        if (count == 0) exit
        call fnv1a_hash(buffer(1:count), high, low)
        offset = offset + count
      end do
      call close_file(handle)
      if (failed .or. offset /= bytes) then
        call make_error(error, "deck file "//sources(k)%path//" could not be read again")
        return
      end if
      hashes(k) = hash_text(high, low)
    end do
  end subroutine sign_deck_files

  !> Continue an FNV-1a hash (64 bit, as two 32-bit halves `high`, `low`) over `bytes`; start
  !> from `high = 3421674724`, `low = 2216829733` (the offset basis) for a new hash.
  pure subroutine fnv1a_hash(bytes, high, low)
    character(len=*), intent(in) :: bytes
    integer(int64), intent(inout) :: high, low
    integer(int64) :: product_low
    integer :: k
    do k = 1, len(bytes)
      low = ieor(low, int(ichar(bytes(k:k)), int64))
      ! (high, low) * (2^40 + 435) mod 2^64: low's lowest 24 bits move to the top of high
      product_low = low*prime_low
      high = iand(high*prime_low + shiftr(product_low, 32) + iand(low, low_24_bits)*256_int64, low_mask)
      low = iand(product_low, low_mask)
    end do
  end subroutine fnv1a_hash

  !> The 64-bit hash (`high`, `low`) as 16 hexadecimal digits.
  pure function hash_text(high, low) result(text)
    integer(int64), intent(in) :: high, low
    character(len=16) :: text
    character(len=*), parameter :: digits = "0123456789abcdef"
    integer :: k, digit
    do k = 1, 8
      digit = int(iand(shiftr(high, 4*(8 - k)), 15_int64))
      text(k:k) = digits(digit + 1:digit + 1)
      digit = int(iand(shiftr(low, 4*(8 - k)), 15_int64))
      text(k + 8:k + 8) = digits(digit + 1:digit + 1)
    end do
  end function hash_text
end module deck_signature
