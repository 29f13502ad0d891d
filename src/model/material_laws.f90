!> The material laws crashfree has, one row each: the law's code (LS-DYNA's law number, kept in
!> material_t%law), its keyword name, the element families it may be used on, the size of its
!> history and its curve slots. Everything that asks "which laws ..." reads this table: the
!> deck (keyword names, the checks of parts against their sections, the curve references), the
!> material dispatch (history per integration point) and the plane-stress dispatch (history per
!> shell point).
!>
!> Adding a law: its module in src/materials, one row here, its case in update_material_block
!> (material_dispatch; plane_stress_dispatch too when it has shells), and its reader with one
!> row in the deck's keyword table (deck_keyword_table: `law_keyword(law_..., read_...)`).
!>
!> The table sits in src/model, below src/materials and src/deck, because both read it; the
!> deck readers themselves are attached to the law in the keyword table, since a procedure
!> pointer to a deck reader here would make the model depend on the deck.
module material_laws
  implicit none
  private

  public :: material_law_t, law_table, find_law, law_keyword_name, law_number_name, law_curve_field

  !> Law codes: LS-DYNA's law numbers.
  integer, parameter, public :: law_elastic = 1               !< *MAT_ELASTIC
  integer, parameter, public :: law_plastic_kinematic = 3     !< *MAT_PLASTIC_KINEMATIC
  integer, parameter, public :: law_piecewise_linear = 24     !< *MAT_PIECEWISE_LINEAR_PLASTICITY
  integer, parameter, public :: law_null = 9                  !< *MAT_NULL (shells: contact surface only)
  integer, parameter, public :: law_rigid = 20                !< *MAT_RIGID (parts become rigid bodies)
  integer, parameter, public :: law_honeycomb = 26            !< *MAT_HONEYCOMB
  integer, parameter, public :: law_modified_honeycomb = 126  !< *MAT_MODIFIED_HONEYCOMB
  integer, parameter, public :: law_low_density_foam = 57     !< *MAT_LOW_DENSITY_FOAM
  integer, parameter, public :: law_spotweld = 100            !< *MAT_SPOTWELD (beams)
  integer, parameter, public :: law_viscoelastic = 6          !< *MAT_VISCOELASTIC
  integer, parameter, public :: law_blatz_ko = 7              !< *MAT_BLATZ-KO_RUBBER
  integer, parameter, public :: law_mooney_rivlin = 27        !< *MAT_MOONEY-RIVLIN_RUBBER

  !> History count of a law without a plane-stress kernel (it cannot be used on shell blocks).
  integer, parameter, public :: no_plane_stress_kernel = -1

  !> One material law.
  type :: material_law_t
    integer :: code = 0                   !< LS-DYNA's law number (material_t%law)
    !> Keyword name after MAT_: the law is read from *MAT_<name> and *MAT_<nnn> (its number in
    !> three digits, law_number_name).
    character(len=32) :: name = ""
    logical :: solids = .false.           !< may be used on hexahedra (ELFORM 1, 2)
    logical :: shells = .false.           !< may be used on shells (ELFORM 2)
    logical :: meshfree = .false.         !< may be used on EFG parts (ELFORM 41)
    logical :: beams = .false.            !< may be used on beams (*SECTION_BEAM ELFORM 1, 9)
    !> Needs a hexahedron section (ELFORM 1, 2 or 41): the law takes its material axes or its
    !> volume from the hexahedron (EFG points from their background cell).
    logical :: hexahedra_only = .false.
    integer :: history_count = 0          !< history variables per solid / EFG integration point
    !> History variables per shell integration point (no_plane_stress_kernel: none; a rigid
    !> part's shells become a rigid body and need none).
    integer :: shell_history_count = no_plane_stress_kernel
    !> The deck fields of its curve slots in material_t%curves, blank-separated, in slot order
    !> ("" for a law without curves), and the card of the keyword that holds them.
    character(len=40) :: curve_fields = ""
    integer :: curve_card = 0
  end type material_law_t

  !> The laws, in the order messages list them.
  type(material_law_t), parameter :: law_table(12) = [ &
    material_law_t(code=law_elastic, name="ELASTIC", solids=.true., shells=.true., meshfree=.true., &
                   beams=.true., history_count=0, shell_history_count=0), &
    material_law_t(code=law_plastic_kinematic, name="PLASTIC_KINEMATIC", solids=.true., shells=.true., &
                   meshfree=.true., beams=.true., history_count=7, shell_history_count=4), &
    material_law_t(code=law_piecewise_linear, name="PIECEWISE_LINEAR_PLASTICITY", solids=.true., &
                   shells=.true., meshfree=.true., history_count=1, shell_history_count=1, &
                   curve_fields="LCSS LCSR", curve_card=2), &
    material_law_t(code=law_null, name="NULL", solids=.false., shells=.true., meshfree=.false., &
                   history_count=0, shell_history_count=0), &
    material_law_t(code=law_rigid, name="RIGID", solids=.true., shells=.true., meshfree=.true., &
                   history_count=0), &
    material_law_t(code=law_honeycomb, name="HONEYCOMB", solids=.true., meshfree=.true., &
                   hexahedra_only=.true., history_count=23, curve_fields="LCA LCB LCC LCAB LCBC LCCA LCSR", &
                   curve_card=2), &
    material_law_t(code=law_modified_honeycomb, name="MODIFIED_HONEYCOMB", solids=.true., meshfree=.true., &
                   hexahedra_only=.true., history_count=23, curve_fields="LCA LCB LCC LCAB LCBC LCCA LCSR", &
                   curve_card=2), &
    material_law_t(code=law_low_density_foam, name="LOW_DENSITY_FOAM", solids=.true., meshfree=.true., &
                   hexahedra_only=.true., history_count=7, curve_fields="LCID", curve_card=1), &
    material_law_t(code=law_spotweld, name="SPOTWELD", beams=.true.), &
    material_law_t(code=law_viscoelastic, name="VISCOELASTIC", solids=.true., shells=.true., meshfree=.true., &
                   history_count=6, shell_history_count=4), &
    material_law_t(code=law_blatz_ko, name="BLATZ-KO_RUBBER", solids=.true., shells=.true., meshfree=.true., &
                   history_count=6, shell_history_count=4), &
    material_law_t(code=law_mooney_rivlin, name="MOONEY-RIVLIN_RUBBER", solids=.true., shells=.true., &
                   meshfree=.true., history_count=6, shell_history_count=4, curve_fields="LCID1", curve_card=2)]

contains

  !> Row of law `code` in law_table (0 when crashfree has no such law).
  pure integer function find_law(code)
    integer, intent(in) :: code
    integer :: k
    find_law = 0
    do k = 1, size(law_table)
      if (law_table(k)%code == code) then
        find_law = k
        return
      end if
    end do
  end function find_law

  !> "MAT_ELASTIC": the keyword of law row `k`.
  pure function law_keyword_name(k) result(name)
    integer, intent(in) :: k
    character(len=:), allocatable :: name
    name = "MAT_"//trim(law_table(k)%name)
  end function law_keyword_name

  !> "MAT_001": the keyword of law row `k` by number.
  pure function law_number_name(k) result(name)
    integer, intent(in) :: k
    character(len=:), allocatable :: name
    character(len=3) :: digits
    write (digits, '(i3.3)') law_table(k)%code
    name = "MAT_"//digits
  end function law_number_name

  !> The deck field of curve slot `slot` of law row `k` ("LCSR").
  pure function law_curve_field(k, slot) result(field)
    integer, intent(in) :: k, slot
    character(len=:), allocatable :: field
    character(len=:), allocatable :: rest
    integer :: word
    rest = trim(adjustl(law_table(k)%curve_fields))//" "
    do word = 1, slot - 1
      rest = adjustl(rest(index(rest, " ") + 1:))
    end do
    field = rest(1:index(rest, " ") - 1)
  end function law_curve_field
end module material_laws
