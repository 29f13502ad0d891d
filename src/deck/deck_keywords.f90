!> The keywords crashfree reads: names, options (`_TITLE`, `_ID`, rigid-wall options) and a
!> spelling suggestion for a name that is not one of them.
module deck_keywords
  implicit none
  private

  public :: keyword_t, identify_keyword, closest_keyword

  !> Keyword codes (one per reader entry; aliases such as *MAT_001 share a code).
  integer, parameter, public :: keyword_unknown = 0, keyword_title = 1, keyword_node = 2, &
    keyword_element_solid = 3, keyword_part = 4, keyword_section_solid = 5, &
    keyword_section_solid_efg = 6, keyword_mat_elastic = 7, keyword_mat_plastic_kinematic = 8, &
    keyword_hourglass = 9, keyword_control_hourglass = 10, keyword_control_bulk_viscosity = 11, &
    keyword_control_termination = 12, keyword_control_timestep = 13, keyword_control_energy = 14, &
    keyword_set_node_list = 15, keyword_set_node_list_generate = 16, keyword_set_part_list = 17, &
    keyword_spc_node = 18, keyword_spc_set = 19, keyword_initial_velocity = 20, &
    keyword_initial_velocity_node = 21, keyword_initial_velocity_generation = 22, &
    keyword_define_curve = 23, keyword_motion_node = 24, keyword_motion_set = 25, &
    keyword_load_node_point = 26, keyword_load_node_set = 27, keyword_rigidwall_planar = 28, &
    keyword_d3plot = 29, keyword_glstat = 30, keyword_matsum = 31, keyword_nodout = 32, &
    keyword_rwforc = 33, keyword_history_node = 34, keyword_history_node_set = 35, &
    keyword_control_implicit_general = 36, keyword_control_implicit_solution = 37, &
    keyword_load_segment = 38, keyword_load_segment_set = 39, &
    keyword_load_segment_nonuniform = 40, keyword_set_segment = 41, keyword_mat_honeycomb = 42, &
    keyword_mat_modified_honeycomb = 43, keyword_mat_low_density_foam = 44, &
    keyword_rigidwall_cylinder = 45
  !> Shell elements and sections.
  integer, parameter, public :: keyword_element_shell = 46, keyword_element_shell_thickness = 47, &
    keyword_section_shell = 48
  !> Number of keyword codes.
  integer, parameter, public :: keyword_count = 48

  !> A keyword name taken apart: its code and the options given with it.
  type :: keyword_t
    integer :: code = keyword_unknown
    logical :: title = .false.     !< _TITLE: a title line before the first card
    logical :: id = .false.        !< _ID: an id/heading line before the first card
    logical :: finite = .false.    !< *RIGIDWALL_PLANAR_FINITE
    logical :: moving = .false.    !< *RIGIDWALL_PLANAR_MOVING
    logical :: forces = .false.    !< *RIGIDWALL_PLANAR_FORCES
    logical :: motion = .false.    !< *RIGIDWALL_GEOMETRIC_CYLINDER_MOTION
  end type keyword_t

  integer, parameter :: entry_count = 58
  character(len=*), parameter :: base_names(entry_count) = [character(len=36) :: &
    "TITLE", "NODE", "ELEMENT_SOLID", "PART", "SECTION_SOLID", "SECTION_SOLID_EFG", &
    "MAT_ELASTIC", "MAT_001", "MAT_PLASTIC_KINEMATIC", "MAT_003", "HOURGLASS", &
    "CONTROL_HOURGLASS", "CONTROL_BULK_VISCOSITY", "CONTROL_TERMINATION", "CONTROL_TIMESTEP", &
    "CONTROL_ENERGY", "SET_NODE_LIST", "SET_NODE_LIST_GENERATE", "SET_PART_LIST", &
    "BOUNDARY_SPC_NODE", "BOUNDARY_SPC_SET", "INITIAL_VELOCITY", "INITIAL_VELOCITY_NODE", &
    "INITIAL_VELOCITY_GENERATION", "DEFINE_CURVE", "BOUNDARY_PRESCRIBED_MOTION_NODE", &
    "BOUNDARY_PRESCRIBED_MOTION_SET", "LOAD_NODE_POINT", "LOAD_NODE_SET", "RIGIDWALL_PLANAR", &
    "DATABASE_BINARY_D3PLOT", "DATABASE_GLSTAT", "DATABASE_MATSUM", "DATABASE_NODOUT", &
    "DATABASE_RWFORC", "DATABASE_HISTORY_NODE", "DATABASE_HISTORY_NODE_SET", &
    "CONTROL_IMPLICIT_GENERAL", "CONTROL_IMPLICIT_SOLUTION", "LOAD_SEGMENT", &
    "LOAD_SEGMENT_SET", "LOAD_SEGMENT_NONUNIFORM", "SET_SEGMENT", &
    "MAT_HONEYCOMB", "MAT_026", "MAT_MODIFIED_HONEYCOMB", "MAT_126", "MAT_LOW_DENSITY_FOAM", "MAT_057", &
    "RIGIDWALL_GEOMETRIC_CYLINDER", "ELEMENT_SHELL", "ELEMENT_SHELL_THICKNESS", "SECTION_SHELL", &
    "KEYWORD", "INCLUDE", "PARAMETER", "COMMENT", "END"]
  integer, parameter :: base_codes(entry_count) = [keyword_title, keyword_node, &
    keyword_element_solid, keyword_part, keyword_section_solid, keyword_section_solid_efg, &
    keyword_mat_elastic, keyword_mat_elastic, keyword_mat_plastic_kinematic, &
    keyword_mat_plastic_kinematic, keyword_hourglass, keyword_control_hourglass, &
    keyword_control_bulk_viscosity, keyword_control_termination, keyword_control_timestep, &
    keyword_control_energy, keyword_set_node_list, keyword_set_node_list_generate, &
    keyword_set_part_list, keyword_spc_node, keyword_spc_set, keyword_initial_velocity, &
    keyword_initial_velocity_node, keyword_initial_velocity_generation, keyword_define_curve, &
    keyword_motion_node, keyword_motion_set, keyword_load_node_point, keyword_load_node_set, &
    keyword_rigidwall_planar, keyword_d3plot, keyword_glstat, keyword_matsum, keyword_nodout, &
    keyword_rwforc, keyword_history_node, keyword_history_node_set, &
    keyword_control_implicit_general, keyword_control_implicit_solution, keyword_load_segment, &
    keyword_load_segment_set, keyword_load_segment_nonuniform, keyword_set_segment, &
    keyword_mat_honeycomb, keyword_mat_honeycomb, keyword_mat_modified_honeycomb, &
    keyword_mat_modified_honeycomb, keyword_mat_low_density_foam, keyword_mat_low_density_foam, &
    keyword_rigidwall_cylinder, keyword_element_shell, keyword_element_shell_thickness, &
    keyword_section_shell, keyword_unknown, keyword_unknown, keyword_unknown, keyword_unknown, keyword_unknown]
  !> Options each entry accepts (blank-separated).
  character(len=*), parameter :: base_options(entry_count) = [character(len=28) :: &
    "", "", "", "", "TITLE", "TITLE", &
    "TITLE", "TITLE", "TITLE", "TITLE", "TITLE", &
    "", "", "", "", &
    "", "TITLE", "TITLE", "TITLE", &
    "ID", "ID", "", "", &
    "", "TITLE", "ID", &
    "ID", "", "", "FINITE MOVING FORCES ID", &
    "", "", "", "", &
    "", "ID", "", &
    "", "", "ID", &
    "ID", "ID", "TITLE", &
    "TITLE", "TITLE", "TITLE", "TITLE", "TITLE", "TITLE", &
    "MOTION ID", "", "", "TITLE", "", "", "", "", ""]

contains

  !> Take keyword `name` (upper case, no `*`) apart; `code` stays `keyword_unknown` when it is
  !> not a keyword crashfree reads. The longest base name whose options all fit wins, so
  !> *SET_NODE_LIST_GENERATE is not read as *SET_NODE_LIST with an option GENERATE.
  pure function identify_keyword(name) result(keyword)
    character(len=*), intent(in) :: name
    type(keyword_t) :: keyword
    type(keyword_t) :: candidate
    integer :: k, base_length, best_length
    logical :: fits

    best_length = 0
    do k = 1, entry_count
      if (base_codes(k) == keyword_unknown) cycle
      base_length = len_trim(base_names(k))
      if (name == base_names(k)(:base_length)) then
        candidate = keyword_t(code=base_codes(k))
        fits = .true.
      else if (len(name) > base_length + 1) then
        if (name(:base_length + 1) /= base_names(k)(:base_length)//"_") cycle
        call read_options(name(base_length + 2:), trim(base_options(k)), candidate, fits)
        candidate%code = base_codes(k)
      else
        cycle
      end if
      if (fits .and. base_length > best_length) then
        keyword = candidate
        best_length = base_length
      end if
    end do
  end function identify_keyword

  !> Options `text` ("MOVING_FORCES") against the allowed list; each at most once.
  pure subroutine read_options(text, allowed, keyword, fits)
    character(len=*), intent(in) :: text, allowed
    type(keyword_t), intent(out) :: keyword
    logical, intent(out) :: fits
    integer :: start, finish
    character(len=:), allocatable :: option

    fits = .false.
    start = 1
    do while (start <= len(text))
      finish = index(text(start:), "_")
      if (finish == 0) then
        finish = len(text)
      else
        finish = start + finish - 2
      end if
      option = text(start:finish)
      start = finish + 2
      if (len(option) == 0) return
      if (index(" "//allowed//" ", " "//option//" ") == 0) return
      select case (option)
      case ("TITLE")
        if (keyword%title) return
        keyword%title = .true.
      case ("ID")
        if (keyword%id) return
        keyword%id = .true.
      case ("FINITE")
        if (keyword%finite) return
        keyword%finite = .true.
      case ("MOVING")
        if (keyword%moving) return
        keyword%moving = .true.
      case ("FORCES")
        if (keyword%forces) return
        keyword%forces = .true.
      case ("MOTION")
        if (keyword%motion) return
        keyword%motion = .true.
      end select
    end do
    fits = text(len(text):) /= "_"
  end subroutine read_options

  !> The known keyword nearest to `name` in spelling ("" when none is close), for
  !> "did you mean" hints: edit distance at most 2, or a fifth of the name for long names.
  pure function closest_keyword(name) result(closest)
    character(len=*), intent(in) :: name
    character(len=:), allocatable :: closest
    integer :: k, distance, best
    best = max(2, len(name)/5) + 1
    closest = ""
    do k = 1, entry_count
      distance = edit_distance(name, trim(base_names(k)))
      if (distance < best) then
        best = distance
        closest = trim(base_names(k))
      end if
    end do
  end function closest_keyword

  !> Levenshtein distance (insertions, deletions, substitutions).
  pure integer function edit_distance(first, second)
    character(len=*), intent(in) :: first, second
    integer :: previous(0:len(second)), current(0:len(second))
    integer :: i, j, cost
    do j = 0, len(second)
      previous(j) = j
    end do
    do i = 1, len(first)
      current(0) = i
      do j = 1, len(second)
        cost = merge(0, 1, first(i:i) == second(j:j))
        current(j) = min(previous(j) + 1, current(j - 1) + 1, previous(j - 1) + cost)
      end do
      previous = current
    end do
    edit_distance = previous(len(second))
  end function edit_distance
end module deck_keywords
