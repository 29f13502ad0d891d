!> What the tied-contact keywords collect before the cross-check: each *CONTACT_TIED_... and
!> *CONTACT_SPOTWELD definition as written (set and part ids, not indices) with its deck line.
!> The readers and the set-up search are in deck_tied_contact; this module only holds the list
!> so that deck_input can keep it.
module deck_tied_input
  use kinds, only: wp
  implicit none
  private

  !> One tied contact as written.
  type, public :: tied_entry_t
    integer :: id = 0                !< CID (0: numbered in deck order)
    integer :: kind = 0              !< model's tied_...
    logical :: offset = .false.
    integer :: side_ids(2) = 0       !< SURFA SURFB
    integer :: side_types(2) = 0     !< SURFATYP SURFBTYP
    real(wp) :: thickness(2) = 0.0_wp !< SAST SBST (0: the shells' own)
    integer :: line = 0              !< card 1
  end type tied_entry_t

  !> All tied-contact input; `entries` holds `count` definitions.
  type, public :: tied_input_t
    integer :: count = 0
    type(tied_entry_t), allocatable :: entries(:)
  end type tied_input_t
end module deck_tied_input
