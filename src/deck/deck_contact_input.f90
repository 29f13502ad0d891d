!> What the contact keywords collect before the cross-check: each *CONTACT_AUTOMATIC_...
!> definition as written (set and part ids, not indices) with its deck lines. The readers are
!> in deck_contact; this module only holds the list so that deck_input can keep it.
module deck_contact_input
  use model, only: contact_t
  implicit none
  private

  public :: contact_input_t, contact_entry_t

  !> One contact definition: the model entry (sides not yet resolved) and where it came from.
  type :: contact_entry_t
    type(contact_t) :: contact
    logical :: numbered = .false.    !< CID given on an _ID / _TITLE card
    integer :: id_line = 0           !< the ID card (0: none)
    integer :: surface_line = 0      !< card C1 (SURFA SURFB SURFATYP SURFBTYP)
  end type contact_entry_t

  !> All contact input; `entries` holds `count` definitions and grows by doubling.
  type :: contact_input_t
    integer :: count = 0
    type(contact_entry_t), allocatable :: entries(:)
  end type contact_input_t
end module deck_contact_input
