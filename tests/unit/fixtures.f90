!> Helpers shared by the unit tests: a reproducible random sequence, scratch directories, the
!> test steel and curves of *MAT_024, the cross product, the text of an error, keyword decks
!> written from lines (comma-separated node and element cards) and read.
module fixtures
  use kinds, only: wp, long_int
  use model, only: material_t
  use material_laws, only: law_piecewise_linear
  use curves, only: curve_t
  use error_handling, only: error_t, error_list_t
  use model, only: model_t
  use deck_reader, only: read_deck
  implicit none
  private

  public :: random_uniform, make_scratch_directory, piecewise_steel, make_curve, cross, error_message
  public :: node_card, element_card, read_deck_lines

  !> The test steel: E, nu, yield stress (N, mm, s, t).
  real(wp), parameter, public :: steel_youngs = 210000.0_wp, steel_poisson = 0.3_wp, steel_yield = 250.0_wp

contains

  !> Next number of the Park-Miller minimal standard sequence in `state`, as a uniform number
  !> in (-1, 1): the same sequence on every compiler and machine.
  function random_uniform(state) result(value)
    integer, intent(inout) :: state
    real(wp) :: value
    state = int(mod(16807_long_int*int(state, long_int), 2147483647_long_int))
    value = 2.0_wp*real(state, wp)/2147483647.0_wp - 1.0_wp
  end function random_uniform

  !> A new directory /tmp/<prefix>_<clock>_<random> (with the folders `inside`, e.g.
  !> "sub/nested", if given).
  function make_scratch_directory(prefix, inside) result(path)
    character(len=*), intent(in) :: prefix
    character(len=*), intent(in), optional :: inside
    character(len=:), allocatable :: path
    real :: random
    integer :: clock
    character(len=24) :: suffix
    call random_seed()
    call random_number(random)
    call system_clock(clock)
    write (suffix, '(i0,"_",i0)') clock, int(random*1.0e6)
    path = "/tmp/"//prefix//"_"//trim(suffix)
    if (present(inside)) then
      call execute_command_line("mkdir -p "//path//"/"//inside)
    else
      call execute_command_line("mkdir -p "//path)
    end if
  end function make_scratch_directory

  !> *MAT_PIECEWISE_LINEAR_PLASTICITY of the test steel with tangent modulus `etan`, bilinear
  !> (no curves: both slots empty).
  function piecewise_steel(etan) result(material)
    real(wp), intent(in) :: etan
    type(material_t) :: material
    material%law = law_piecewise_linear
    material%density = 7.85e-9_wp
    material%youngs_modulus = steel_youngs
    material%poissons_ratio = steel_poisson
    material%yield_stress = steel_yield
    material%tangent_modulus = etan
    allocate (material%curve_ids(2), material%curves(2))
    material%curve_ids(:) = 0
  end function piecewise_steel

  !> A curve with id `id` through the points (abscissa, ordinate).
  function make_curve(id, abscissa, ordinate) result(curve)
    integer, intent(in) :: id
    real(wp), intent(in) :: abscissa(:), ordinate(:)
    type(curve_t) :: curve
    curve%id = id
    allocate (curve%abscissa, source=abscissa)
    allocate (curve%ordinate, source=ordinate)
  end function make_curve

  pure function cross(a, b) result(c)
    real(wp), intent(in) :: a(3), b(3)
    real(wp) :: c(3)
    c = [a(2)*b(3) - a(3)*b(2), a(3)*b(1) - a(1)*b(3), a(1)*b(2) - a(2)*b(1)]
  end function cross

  !> The message of `error`, or `none` (default "") when there is no error.
  function error_message(error, none) result(text)
    type(error_t), allocatable, intent(in) :: error
    character(len=*), intent(in), optional :: none
    character(len=:), allocatable :: text
    text = ""
    if (present(none)) text = none
    if (allocated(error)) text = error%message
  end function error_message

  !> A *NODE card, comma separated: id, x, y, z.
  function node_card(id, position) result(line)
    integer, intent(in) :: id
    real(wp), intent(in) :: position(3)
    character(len=80) :: line
    write (line, '(i0,3(",",es16.8))') id, position
  end function node_card

  !> An element card, comma separated: id, part, nodes.
  function element_card(id, part, nodes) result(line)
    integer, intent(in) :: id, part, nodes(:)
    character(len=80) :: line
    integer :: k
    write (line, '(i0,",",i0)') id, part
    do k = 1, size(nodes)
      write (line, '(a,",",i0)') trim(line), nodes(k)
    end do
  end function element_card

  !> Write `lines` to the keyword file `path` and read it into `model` (`error` when rejected).
  subroutine read_deck_lines(path, lines, model, error)
    character(len=*), intent(in) :: path, lines(:)
    type(model_t), intent(out) :: model
    type(error_t), allocatable, intent(out) :: error
    type(error_list_t) :: warnings
    integer :: unit, k
    open (newunit=unit, file=path, status="replace", action="write")
    do k = 1, size(lines)
      write (unit, '(a)') trim(lines(k))
    end do
    close (unit)
    call read_deck(path, model, warnings, error, .false.)
  end subroutine read_deck_lines
end module fixtures
