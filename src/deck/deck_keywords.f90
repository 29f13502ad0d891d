!> The keywords crashfree reads: names, options (`_TITLE`, `_ID`, rigid-wall options) and a
!> spelling suggestion for a name that is not one of them.
module deck_keywords
  implicit none
  private

  public :: keyword_t, identify_keyword, suggest_keyword, known_keyword_count, known_keyword

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
  !> Restart dumps.
  integer, parameter, public :: keyword_d3dump = 49, keyword_runrsf = 50
  !> Number of keyword codes.
  integer, parameter, public :: keyword_count = 50

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

  integer, parameter :: entry_count = 60
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
    "DATABASE_BINARY_D3DUMP", "DATABASE_BINARY_RUNRSF", "KEYWORD", "INCLUDE", "PARAMETER", "COMMENT", "END"]
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
    keyword_section_shell, keyword_d3dump, keyword_runrsf, &
    keyword_unknown, keyword_unknown, keyword_unknown, keyword_unknown, keyword_unknown]
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
    "MOTION ID", "", "", "TITLE", "", "", "", "", "", "", ""]

  !> The keywords read by other modules (deck_rigid_bodies, deck_contact, deck_materials), with
  !> their options: spelling suggestions are taken from these and the entries above, and the
  !> unit tests check that every name listed here is read.
  integer, parameter :: other_count = 14
  character(len=*), parameter :: other_names(other_count) = [character(len=36) :: &
    "MAT_RIGID", "MAT_020", "BOUNDARY_PRESCRIBED_MOTION_RIGID", "CONSTRAINED_NODAL_RIGID_BODY", &
    "ELEMENT_MASS", "CONTACT_AUTOMATIC_NODES_TO_SURFACE", "CONTACT_AUTOMATIC_SURFACE_TO_SURFACE", &
    "CONTACT_AUTOMATIC_SINGLE_SURFACE", "CONTROL_CONTACT", "DATABASE_RCFORC", &
    "MAT_PIECEWISE_LINEAR_PLASTICITY", "MAT_024", "MAT_NULL", "MAT_009"]
  character(len=*), parameter :: other_options(other_count) = [character(len=28) :: &
    "TITLE", "TITLE", "ID", "TITLE", "", "ID TITLE", "ID TITLE", "ID TITLE", "", "", "TITLE", &
    "TITLE", "TITLE", "TITLE"]
  !> Number of names suggestions are taken from.
  integer, parameter :: known_count = entry_count + other_count
  !> Longest keyword name a suggestion is looked for (longer ones are no typing slip).
  integer, parameter :: longest_suggested = 80

contains

  !> Number of keyword names crashfree knows (those it reads and those the lexer handles).
  pure integer function known_keyword_count()
    known_keyword_count = known_count
  end function known_keyword_count

  !> Known keyword name `k` (1 .. known_keyword_count()) and the options it accepts
  !> (blank-separated).
  pure subroutine known_keyword(k, name, options)
    integer, intent(in) :: k
    character(len=:), allocatable, intent(out) :: name, options
    if (k <= entry_count) then
      name = trim(base_names(k))
      options = trim(base_options(k))
    else
      name = trim(other_names(k - entry_count))
      options = trim(other_options(k - entry_count))
    end if
  end subroutine known_keyword

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

  !> A "did you mean" hint for the unknown keyword `name` (upper case, no `*`): the known
  !> keyword nearest in spelling, with the options of `name` spelt right (`suggestion`), and
  !> the same without options (`base`); both "" when no known keyword is close. Spelling
  !> distance counts insertions, deletions, substitutions and swaps of neighbours; the
  !> nearest name wins, a name of the same family (*MAT_..., *DATABASE_...) on a tie. A
  !> keyword crashfree reads, but not with the options given, gets `base` alone.
  pure subroutine suggest_keyword(name, suggestion, base)
    character(len=*), intent(in) :: name
    character(len=:), allocatable, intent(out) :: suggestion, base
    character(len=:), allocatable :: candidate, options, corrected
    integer :: k, split, distance, best_score, option_distance
    logical :: fits

    suggestion = ""
    base = ""
    if (len(name) == 0 .or. len(name) > longest_suggested) return
    best_score = huge(best_score)
    do k = 1, known_count
      call known_keyword(k, candidate, options)
      ! the whole name as the base name
      distance = spelling_distance(name, candidate)
      if (distance > 0 .and. close_enough(name, candidate, distance)) &
        call consider(2*distance + family_penalty(name, candidate), candidate, candidate, &
                      best_score, suggestion, base)
      ! the name as a base name and options: NAME = HEAD_OPTION[_OPTION...]
      do split = len(name) - 1, 2, -1
        if (name(split:split) /= "_") cycle
        call match_options(name(split + 1:), options, corrected, option_distance, fits)
        if (.not. fits) cycle
        distance = spelling_distance(name(:split - 1), candidate)
        if (distance == 0 .and. option_distance == 0) cycle
        if (.not. close_enough(name(:split - 1), candidate, max(distance, 1))) cycle
        call consider(2*(distance + option_distance) + family_penalty(name, candidate), &
                      candidate//"_"//corrected, candidate, best_score, suggestion, base)
      end do
    end do
    if (len(suggestion) > 0) return
    ! a keyword read without these options: name it alone
    do split = len(name) - 1, 2, -1
      if (name(split:split) /= "_") cycle
      do k = 1, known_count
        call known_keyword(k, candidate, options)
        if (name(:split - 1) /= candidate) cycle
        suggestion = candidate
        base = candidate
        return
      end do
    end do
  end subroutine suggest_keyword

  !> Keep `full` (and `new_base`) when `new_score` beats `best_score`.
  pure subroutine consider(new_score, full, new_base, best_score, suggestion, base)
    integer, intent(in) :: new_score
    character(len=*), intent(in) :: full, new_base
    integer, intent(inout) :: best_score
    character(len=:), allocatable, intent(inout) :: suggestion, base
    if (new_score >= best_score) return
    best_score = new_score
    suggestion = full
    base = new_base
  end subroutine consider

  !> Options `text` ("TITEL", "MOVING_FORCES") each matched to the nearest of `allowed`
  !> (blank-separated), within one slip per three letters; `corrected` joins the matches.
  pure subroutine match_options(text, allowed, corrected, distance, fits)
    character(len=*), intent(in) :: text, allowed
    character(len=:), allocatable, intent(out) :: corrected
    integer, intent(out) :: distance
    logical, intent(out) :: fits
    character(len=:), allocatable :: token, option, best_option
    integer :: start, finish, option_start, option_end, best, slip

    corrected = ""
    distance = 0
    fits = .false.
    if (len(allowed) == 0 .or. len(text) == 0) return
    start = 1
    do while (start <= len(text))
      finish = index(text(start:), "_")
      if (finish == 0) then
        finish = len(text)
      else
        finish = start + finish - 2
      end if
      token = text(start:finish)
      start = finish + 2
      if (len(token) == 0) return
      best = huge(best)
      option_start = 1
      do while (option_start <= len(allowed))
        option_end = index(allowed(option_start:), " ")
        if (option_end == 0) then
          option_end = len(allowed)
        else
          option_end = option_start + option_end - 2
        end if
        option = allowed(option_start:option_end)
        option_start = option_end + 2
        slip = spelling_distance(token, option)
        if (slip < best) then
          best = slip
          best_option = option
        end if
      end do
      if (best > max(1, len(best_option)/3)) return
      distance = distance + best
      if (len(corrected) > 0) corrected = corrected//"_"
      corrected = corrected//best_option
    end do
    fits = text(len(text):) /= "_"
  end subroutine match_options

  !> A distance small enough for a typing slip: at most one slip per five letters (one for
  !> short names, three at most), and, when both names have the same number of `_`-separated
  !> words, at most one slip per three letters in each word, so that *DATABASE_BINARY_D3THDT
  !> is not taken for *DATABASE_BINARY_D3PLOT.
  pure logical function close_enough(name, candidate, distance)
    character(len=*), intent(in) :: name, candidate
    integer, intent(in) :: distance
    integer :: name_start, candidate_start, name_end, candidate_end
    close_enough = distance <= min(3, max(1, len(name)/5))
    if (.not. close_enough) return
    if (count_words(name) /= count_words(candidate)) return
    name_start = 1
    candidate_start = 1
    do while (name_start <= len(name) .and. candidate_start <= len(candidate))
      name_end = word_end(name, name_start)
      candidate_end = word_end(candidate, candidate_start)
      if (spelling_distance(name(name_start:name_end), candidate(candidate_start:candidate_end)) &
          > max(1, (candidate_end - candidate_start + 1)/3)) then
        close_enough = .false.
        return
      end if
      name_start = name_end + 2
      candidate_start = candidate_end + 2
    end do
  end function close_enough

  pure integer function count_words(text)
    character(len=*), intent(in) :: text
    integer :: k
    count_words = 1
    do k = 1, len(text)
      if (text(k:k) == "_") count_words = count_words + 1
    end do
  end function count_words

  !> Last position of the `_`-separated word that starts at `start`.
  pure integer function word_end(text, start)
    character(len=*), intent(in) :: text
    integer, intent(in) :: start
    word_end = index(text(start:), "_")
    if (word_end == 0) then
      word_end = len(text)
    else
      word_end = start + word_end - 2
    end if
  end function word_end

  !> 1 when `name` and `candidate` are of different families (the word before the first
  !> `_`: MAT, DATABASE, CONTROL ...), else 0.
  pure integer function family_penalty(name, candidate)
    character(len=*), intent(in) :: name, candidate
    family_penalty = merge(0, 1, name(:word_end(name, 1)) == candidate(:word_end(candidate, 1)))
  end function family_penalty

  !> Edit distance with swaps of neighbouring letters (optimal string alignment): the number
  !> of insertions, deletions, substitutions and swaps that turn `first` into `second`.
  pure integer function spelling_distance(first, second)
    character(len=*), intent(in) :: first, second
    integer :: before(0:len(second)), previous(0:len(second)), current(0:len(second))
    integer :: i, j, cost
    do j = 0, len(second)
      previous(j) = j
    end do
    before = 0
    do i = 1, len(first)
      current(0) = i
      do j = 1, len(second)
        cost = merge(0, 1, first(i:i) == second(j:j))
        current(j) = min(previous(j) + 1, current(j - 1) + 1, previous(j - 1) + cost)
        if (i > 1 .and. j > 1) then
          if (first(i:i) == second(j - 1:j - 1) .and. first(i - 1:i - 1) == second(j:j)) &
            current(j) = min(current(j), before(j - 2) + 1)
        end if
      end do
      before = previous
      previous = current
    end do
    spelling_distance = previous(len(second))
  end function spelling_distance
end module deck_keywords
