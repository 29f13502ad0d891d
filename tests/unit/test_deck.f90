!> Unit tests of the keyword deck reader: parsed values for every supported form, and the
!> exact `file:line: *KEYWORD: field NAME` of every kind of bad input.
!>
!> Decks are written to a fresh directory under /tmp; line numbers in the expected messages
!> are those of the lines written (the base deck below is numbered in its comments).
program test_deck
  use kinds, only: wp
  use testing, only: test_suite_t, check, check_close, finish_suite
  use fixtures, only: make_scratch_directory
  use error_handling, only: error_t, error_list_t
  use text_format, only: integer_text
  use model, only: model_t, formulation_fe, formulation_efg, motion_displacement, motion_velocity, &
                   kernel_cubic_box, kernel_cubic_sphere, kernel_quadratic_box, boundary_coupled, &
                   boundary_full_transformation, integration_local_boundary, integration_gauss, &
                   integration_gauss_conventional, formulation_rigid, section_shell, section_solid
  use material_laws, only: law_elastic, law_plastic_kinematic, law_honeycomb, &
                           law_modified_honeycomb, law_low_density_foam
  use deck_reader, only: read_deck
  use deck_lexer, only: deck_t, load_deck, check_files_unchanged, release_deck
  use deck_problems, only: problem_log_t, has_problems
  use deck_keywords, only: keyword_t, keyword_unknown
  use deck_keyword_table, only: keyword_entry_t, keyword_table, identify_keyword, handled_by_lexer, &
                                suggest_known_keyword, known_keyword_count, known_keyword
  use deck_line_table, only: line_table_t, start_table, append_line, line_file, line_number, &
                             line_start
  use, intrinsic :: iso_fortran_env, only: int64
  implicit none

  integer, parameter :: line_length = 200
  type(test_suite_t) :: suite
  character(len=:), allocatable :: directory

  suite%name = "deck"
  directory = make_scratch_directory("crashfree_test_deck", "sub/nested")
  call test_fixed_format()
  call test_free_format_parameters_include()
  call test_long_format()
  call test_two_line_elements_and_degenerate()
  call test_hourglass_rules()
  call test_curve_sets_and_conditions()
  call test_initial_velocity_generation()
  call test_rigid_walls_and_output()
  call test_unknown_keywords()
  call test_syntax_errors()
  call test_missing_cards()
  call test_reference_errors()
  call test_duplicates()
  call test_material_limits()
  call test_controls_and_mesh_errors()
  call test_field_meanings()
  call test_efg_section_keyword()
  call test_efg_in_solid_section_sets()
  call test_efg_card_errors()
  call test_efg_card_structure()
  call test_efg_cells()
  call test_efg_conventional_integration()
  call test_implicit_controls()
  call test_implicit_control_errors()
  call test_segment_loads()
  call test_segment_load_errors()
  call test_segment_load_structure()
  call test_crushable_materials()
  call test_crushable_material_errors()
  call test_shells()
  call test_shell_rotations_on_solids()
  call test_shell_errors()
  call test_shell_section_errors()
  call test_efg_shell_sections()
  call test_efg_shell_section_errors()
  call test_line_table_beyond_2_gib()
  call test_keyword_suggestions()
  call test_known_keywords_are_read()
  call test_file_changed_while_read()
  call execute_command_line("rm -rf "//directory)
  call finish_suite(suite)

contains

  ! ---------------------------------------------------------------- decks used by the tests

  !> A valid one-element deck in fixed format. Line numbers:
  !>  1 *KEYWORD  2 *TITLE  3 title  4 *CONTROL_TERMINATION  5 card  6 *NODE  7-14 nodes
  !>  15 *ELEMENT_SOLID  16 element  17 *PART  18 heading  19 card  20 *SECTION_SOLID  21 card
  !>  22 *MAT_ELASTIC  23 card ... then `extra` lines from 24, then *END.
  function cube_deck(extra) result(lines)
    character(len=*), intent(in), optional :: extra(:)
    character(len=line_length), allocatable :: lines(:)
    character(len=line_length) :: base(23)
    base(1) = "*KEYWORD"
    base(2) = "*TITLE"
    base(3) = "unit cube"
    base(4) = "*CONTROL_TERMINATION"
    base(5) = fixed(["1.0"], 10)
    base(6) = "*NODE"
    base(7) = node_line(1, 0.0_wp, 0.0_wp, 0.0_wp)
    base(8) = node_line(2, 1.0_wp, 0.0_wp, 0.0_wp)
    base(9) = node_line(3, 1.0_wp, 1.0_wp, 0.0_wp)
    base(10) = node_line(4, 0.0_wp, 1.0_wp, 0.0_wp)
    base(11) = node_line(5, 0.0_wp, 0.0_wp, 1.0_wp)
    base(12) = node_line(6, 1.0_wp, 0.0_wp, 1.0_wp)
    base(13) = node_line(7, 1.0_wp, 1.0_wp, 1.0_wp)
    base(14) = node_line(8, 0.0_wp, 1.0_wp, 1.0_wp)
    base(15) = "*ELEMENT_SOLID"
    base(16) = fixed(["1", "1", "1", "2", "3", "4", "5", "6", "7", "8"], 8)
    base(17) = "*PART"
    base(18) = "the cube"
    base(19) = fixed(["1", "1", "1"], 10)
    base(20) = "*SECTION_SOLID"
    base(21) = fixed(["1", "1"], 10)
    base(22) = "*MAT_ELASTIC"
    base(23) = fixed(["1     ", "7.8e-6", "210.0 ", "0.3   "], 10)
    if (present(extra)) then
      lines = [base, extra, text_line("*END")]
    else
      lines = [base, text_line("*END")]
    end if
  end function cube_deck

  !> The cube deck without its *SECTION_SOLID (lines 20 and 21 become comments), so that the
  !> sections given in `extra` start at line 24.
  function deck_with_sections(extra) result(lines)
    character(len=*), intent(in) :: extra(:)
    character(len=line_length), allocatable :: lines(:)
    lines = cube_deck(extra)
    lines(20) = "$ the sections follow *MAT_ELASTIC, from line 24"
    lines(21) = "$"
  end function deck_with_sections

  !> The cube deck with line `number` replaced.
  function replaced(number, text, extra) result(lines)
    integer, intent(in) :: number
    character(len=*), intent(in) :: text
    character(len=*), intent(in), optional :: extra(:)
    character(len=line_length), allocatable :: lines(:)
    lines = cube_deck(extra)
    lines(number) = text
  end function replaced

  function node_line(id, x, y, z) result(line)
    integer, intent(in) :: id
    real(wp), intent(in) :: x, y, z
    character(len=line_length) :: line
    write (line, '(i8,3f16.4)') id, x, y, z
  end function node_line

  !> Fields right-aligned in columns of `width`.
  function fixed(fields, width) result(line)
    character(len=*), intent(in) :: fields(:)
    integer, intent(in) :: width
    character(len=line_length) :: line
    integer :: k
    line = ""
    do k = 1, size(fields)
      line((k - 1)*width + 1:k*width) = adjustr(fields(k)(1:min(len(fields(k)), width)))
    end do
  end function fixed

  function text_line(text) result(line)
    character(len=*), intent(in) :: text
    character(len=line_length) :: line(1)
    line(1) = text
  end function text_line

  !> A deck edited after it was scanned: its cards are read again at their byte offsets, so the
  !> reader must notice the change instead of reading other text.
  subroutine test_file_changed_while_read()
    type(deck_t) :: deck
    type(problem_log_t) :: log
    type(error_list_t) :: warnings
    call write_file("changing.k", [character(len=20) :: "*KEYWORD", "*NODE", "1 0.0 0.0 0.0", "*END"])
    call load_deck(directory//"/changing.k", deck, log, warnings)
    call check_files_unchanged(deck, log)
    call check(suite, "an unchanged deck passes", .not. has_problems(log))
    call write_file("changing.k", [character(len=20) :: "*KEYWORD", "*NODE", "1 0.0 0.0 1.0", "2 0 0 0", "*END"])
    call check_files_unchanged(deck, log)
    call check(suite, "a deck changed after its scan is refused", has_problems(log))
    call release_deck(deck)
  end subroutine test_file_changed_while_read

  subroutine write_file(name, lines)
    character(len=*), intent(in) :: name
    character(len=*), intent(in) :: lines(:)
    integer :: unit, k
    open (newunit=unit, file=directory//"/"//name, status="replace", action="write")
    do k = 1, size(lines)
      write (unit, '(a)') trim(lines(k))
    end do
    close (unit)
  end subroutine write_file

  !> Read `lines` as deck `name`; a test fails when the deck is rejected.
  subroutine read_good(name, lines, model, warnings, ignore_unknown)
    character(len=*), intent(in) :: name
    character(len=*), intent(in) :: lines(:)
    type(model_t), intent(out) :: model
    type(error_list_t), intent(out) :: warnings
    logical, intent(in), optional :: ignore_unknown
    type(error_t), allocatable :: error
    logical :: ignore
    ignore = .false.
    if (present(ignore_unknown)) ignore = ignore_unknown
    call write_file(name, lines)
    call read_deck(directory//"/"//name, model, warnings, error, ignore)
    if (allocated(error)) then
      call check(suite, name//" is accepted", .false., error%message)
    else
      call check(suite, name//" is accepted", .true.)
    end if
  end subroutine read_good

  !> Read `lines` as deck `name`; it must be rejected with a message holding every `expected`
  !> text (in which `@` stands for the deck's path and `#` for the test directory).
  subroutine read_bad(name, lines, expected, message_lines, ignore_unknown)
    character(len=*), intent(in) :: name
    character(len=*), intent(in) :: lines(:)
    character(len=*), intent(in) :: expected(:)
    integer, intent(in), optional :: message_lines
    logical, intent(in), optional :: ignore_unknown
    type(model_t) :: model
    type(error_list_t) :: warnings
    type(error_t), allocatable :: error
    character(len=:), allocatable :: wanted
    integer :: k, at
    logical :: ignore
    ignore = .false.
    if (present(ignore_unknown)) ignore = ignore_unknown
    call write_file(name, lines)
    call read_deck(directory//"/"//name, model, warnings, error, ignore)
    if (.not. allocated(error)) then
      call check(suite, name//" is rejected", .false., "the deck was accepted")
      return
    end if
    do k = 1, size(expected)
      wanted = trim(expected(k))
      at = index(wanted, "@")
      if (at > 0) wanted = wanted(:at - 1)//directory//"/"//name//wanted(at + 1:)
      at = index(wanted, "@")
      if (at > 0) wanted = wanted(:at - 1)//directory//"/"//name//wanted(at + 1:)
      at = index(wanted, "#")
      if (at > 0) wanted = wanted(:at - 1)//directory//wanted(at + 1:)
      call check(suite, name//": "//wanted, index(error%message, wanted) > 0, &
                 "message was:"//new_line("a")//error%message)
    end do
    if (present(message_lines)) call check(suite, name//": "//integer_text(message_lines)// &
      " problems listed", count_lines(error%message) == message_lines, &
      "message was:"//new_line("a")//error%message)
  end subroutine read_bad

  integer function count_lines(text)
    character(len=*), intent(in) :: text
    integer :: k
    count_lines = 1
    do k = 1, len(text)
      if (text(k:k) == new_line("a")) count_lines = count_lines + 1
    end do
  end function count_lines

  ! ---------------------------------------------------------------- values read

  subroutine test_fixed_format()
    type(model_t) :: model
    type(error_list_t) :: warnings
    call read_good("fixed.k", cube_deck(), model, warnings)
    if (.not. allocated(model%node_ids)) return
    call check(suite, "fixed: 8 nodes", size(model%node_ids) == 8)
    call check_close(suite, "fixed: node 7 coordinates", model%coordinates(:, 7), &
                     [1.0_wp, 1.0_wp, 1.0_wp], thr=0.0_wp)
    call check(suite, "fixed: one solid", size(model%solid_ids) == 1)
    call check(suite, "fixed: solid node indices", all(model%solid_nodes(:, 1) == [1, 2, 3, 4, &
                                                                                  5, 6, 7, 8]))
    call check(suite, "fixed: part index", model%solid_part(1) == 1)
    call check(suite, "fixed: part references", model%parts(1)%section == 1 .and. &
               model%parts(1)%material == 1 .and. model%parts(1)%hourglass == 0)
    call check(suite, "fixed: part title", model%parts(1)%title == "the cube")
    call check(suite, "fixed: formulation", model%parts(1)%formulation == formulation_fe)
    call check(suite, "fixed: title", model%title == "unit cube")
    call check(suite, "fixed: deck path", model%deck_path == directory//"/fixed.k")
    call check_close(suite, "fixed: end time", model%end_time, 1.0_wp, thr=0.0_wp)
    call check_close(suite, "fixed: TSSFAC default", model%time_step_scale, 0.9_wp, thr=0.0_wp)
    call check(suite, "fixed: elastic law", model%materials(1)%law == law_elastic)
    call check_close(suite, "fixed: density", model%materials(1)%density, 7.8e-6_wp, rel=1e-15_wp)
    call check_close(suite, "fixed: E", model%materials(1)%youngs_modulus, 210.0_wp, thr=0.0_wp)
    call check(suite, "fixed: section ELFORM", model%sections(1)%element_formulation == 1)
    call check(suite, "fixed: default hourglass", model%parts(1)%hourglass_type == 1)
    call check_close(suite, "fixed: default QM", model%parts(1)%hourglass_coefficient, 0.1_wp, &
                     thr=0.0_wp)
    call check_close(suite, "fixed: default Q1", model%parts(1)%bulk_quadratic, 1.5_wp, thr=0.0_wp)
    call check_close(suite, "fixed: default Q2", model%parts(1)%bulk_linear, 0.06_wp, thr=0.0_wp)
    call check(suite, "fixed: empty lists allocated", size(model%spcs) == 0 .and. &
               size(model%motions) == 0 .and. size(model%loads) == 0 .and. &
               size(model%walls) == 0 .and. size(model%node_sets) == 0 .and. &
               size(model%part_sets) == 0 .and. size(model%curves) == 0 .and. &
               size(model%hourglasses) == 0 .and. size(model%output%history_nodes) == 0)
    call check(suite, "fixed: no segment loads, allocated", allocated(model%segment_loads))
    if (allocated(model%segment_loads)) call check(suite, "fixed: segment loads zero-size", &
                                                   size(model%segment_loads) == 0)
    call check(suite, "fixed: explicit analysis", .not. model%implicit_static)
    call check(suite, "fixed: initial velocity zero", all(shape(model%initial_velocity) == &
               [3, 8]) .and. all(model%initial_velocity == 0.0_wp))
    call check(suite, "fixed: no warnings", warnings%count == 0)
  end subroutine test_fixed_format

  !> Comma cards, lower-case keywords, parameters (R, I and C, `&`, `-&`), _TITLE options,
  !> blank fields with defaults, nested includes by relative path, *END ending an include.
  subroutine test_free_format_parameters_include()
    type(model_t) :: model
    type(error_list_t) :: warnings
    call write_file("sub/mesh.k", [character(len=line_length) :: &
      "$ nodes and elements, included from ../free.k", &
      "*node", &
      "1,0,0,0", "2,&len,0,0", "3,&len,&len,0", "4,0,&len,0", &
      "*include", &
      "nested/top.k", &
      "*element_solid", &
      "10,&part,1,2,3,4,5,6,7,8", &
      "*END", &
      "*NODE", &
      "99,5,5,5"])
    call write_file("sub/nested/top.k", [character(len=line_length) :: &
      "*NODE", "5,0,0,&len", "6,&len,0,&len", "7,&len,&len,&len", "8,0,&len,&len"])
    call read_good("free.k", [character(len=line_length) :: &
      "*keyword", &
      "$ comment before the parameters", &
      "*PARAMETER", &
      "R len      2.5       I part    3", &
      "*Control_Termination", &
      "&len,,,", &
      "*PARAMETER", &
      "C meshfile,sub/mesh.k", &
      "*include", &
      "&meshfile", &
      "*PART", &
      "", &
      "&part,4,2", &
      "*SECTION_SOLID_TITLE", &
      "fully integrated", &
      "4,2", &
      "*MAT_PLASTIC_KINEMATIC_TITLE", &
      "steel", &
      "2,7.8e-6,210.,0.3,0.25,2.1,-&beta", &
      "40.,5.,,", &
      "*PARAMETER", &
      "R beta     -1.0", &
      "*end"], model, warnings)
    if (.not. allocated(model%node_ids)) return
    call check(suite, "free: 8 nodes, *END ends the include only", size(model%node_ids) == 8)
    call check_close(suite, "free: parameter in a node", model%coordinates(:, 7), &
                     [2.5_wp, 2.5_wp, 2.5_wp], thr=0.0_wp)
    call check(suite, "free: element from include", model%solid_ids(1) == 10 .and. &
               model%parts(model%solid_part(1))%id == 3)
    call check(suite, "free: nested include nodes", model%node_ids(5) == 5)
    call check_close(suite, "free: ENDTIM from parameter", model%end_time, 2.5_wp, thr=0.0_wp)
    call check(suite, "free: blank part heading", model%parts(1)%title == "")
    call check(suite, "free: section title and ELFORM", model%sections(1)%title == &
               "fully integrated" .and. model%sections(1)%element_formulation == 2)
    call check(suite, "free: material title and law", model%materials(1)%title == "steel" .and. &
               model%materials(1)%law == law_plastic_kinematic)
    call check_close(suite, "free: SIGY", model%materials(1)%yield_stress, 0.25_wp, thr=0.0_wp)
    call check_close(suite, "free: -&beta", model%materials(1)%hardening_beta, 1.0_wp, thr=0.0_wp)
    call check_close(suite, "free: SRC SRP", [model%materials(1)%rate_c, &
                     model%materials(1)%rate_p], [40.0_wp, 5.0_wp], thr=0.0_wp)
    call check_close(suite, "free: blank FS", model%materials(1)%failure_strain, 0.0_wp, thr=0.0_wp)
    call check(suite, "free: title blank when no *TITLE", model%title == "")
  end subroutine test_free_format_parameters_include

  !> *KEYWORD LONG=Y (20-column fields everywhere), the per-keyword `+` suffix and the I10
  !> `%` suffix.
  subroutine test_long_format()
    type(model_t) :: model
    type(error_list_t) :: warnings
    character(len=line_length), allocatable :: lines(:)
    integer :: k
    allocate (lines(0))    ! (keeps gfortran 12 from a false "used uninitialized" warning)
    lines = cube_deck()
    lines(1) = "*KEYWORD LONG=Y"
    lines(5) = fixed(["0.5"], 20)
    do k = 7, 14
      lines(k) = long_node(lines(k))
    end do
    lines(16) = fixed(["1", "1", "1", "2", "3", "4", "5", "6", "7", "8"], 20)
    lines(19) = fixed(["1", "1", "1"], 20)
    lines(21) = fixed(["1", "1"], 20)
    lines(23) = fixed(["1     ", "7.8e-6", "210.0 ", "0.3   "], 20)
    call read_good("long.k", lines, model, warnings)
    if (allocated(model%node_ids)) then
      call check_close(suite, "long: ENDTIM", model%end_time, 0.5_wp, thr=0.0_wp)
      call check_close(suite, "long: node 7", model%coordinates(:, 7), [1.0_wp, 1.0_wp, 1.0_wp], &
                       thr=0.0_wp)
      call check_close(suite, "long: PR", model%materials(1)%poissons_ratio, 0.3_wp, thr=0.0_wp)
    end if
    lines = cube_deck()
    lines(6) = "*NODE +"     ! text after a blank is a comment; "+" must be attached
    lines(6) = "*NODE+"
    do k = 7, 14
      lines(k) = long_node(lines(k))
    end do
    call read_good("long_suffix.k", lines, model, warnings)
    if (allocated(model%node_ids)) call check_close(suite, "long suffix: node 2", &
      model%coordinates(:, 2), [1.0_wp, 0.0_wp, 0.0_wp], thr=0.0_wp)
    lines = cube_deck()
    lines(6) = "*node%"
    do k = 7, 14
      write (lines(k), '(i10,3f16.4,i10)') k - 6, model%coordinates(:, k - 6), merge(7, 0, k == 7)
    end do
    call read_good("i10_suffix.k", lines, model, warnings)
    if (allocated(model%node_ids)) then
      call check_close(suite, "I10: node 7", model%coordinates(:, 7), [1.0_wp, 1.0_wp, 1.0_wp], &
                       thr=0.0_wp)
      call check(suite, "I10: TC 7 of node 1", size(model%spcs) == 1 .and. all(model%spcs%node &
                 == [1]))
    end if
  end subroutine test_long_format

  function long_node(standard) result(line)
    character(len=*), intent(in) :: standard
    character(len=line_length) :: line
    character(len=16) :: fields(4)
    ! (assigned one by one: gfortran 12 mishandles typed constructors of unequal substrings)
    fields(1) = standard(1:8)
    fields(2) = standard(9:24)
    fields(3) = standard(25:40)
    fields(4) = standard(41:56)
    line = fixed(fields, 20)
  end function long_node

  !> The two-line (ten nodes) element layout, a wedge and a tetrahedron written with repeated
  !> nodes, and numbers packed without blanks between fixed fields.
  subroutine test_two_line_elements_and_degenerate()
    type(model_t) :: model
    type(error_list_t) :: warnings
    character(len=line_length), allocatable :: lines(:)
    allocate (lines(0))    ! (keeps gfortran 12 from a false "used uninitialized" warning)
    lines = cube_deck([character(len=line_length) :: &
      "*ELEMENT_SOLID", &
      fixed(["2", "1"], 8), &
      fixed(["1", "2", "3", "4", "5", "6", "7", "8", "0", " "], 8), &
      fixed(["3", "1"], 8), &
      fixed(["1", "2", "4", "4", "5", "6", "8", "8"], 8), &
      "*ELEMENT_SOLID", &
      fixed(["4", "1", "1", "2", "4", "5", "5", "5", "5", "5"], 8), &
      "*NODE", &
      "      20-1.5000000000000 2.0000000000000-3.000000000000"])
    call read_good("two_line.k", lines, model, warnings)
    if (.not. allocated(model%solid_ids)) return
    call check(suite, "two-line: 4 elements", size(model%solid_ids) == 4)
    call check(suite, "two-line: nodes", all(model%solid_nodes(:, 2) == [1, 2, 3, 4, 5, 6, 7, 8]))
    call check(suite, "wedge nodes", all(model%solid_nodes(:, 3) == [1, 2, 4, 4, 5, 6, 8, 8]))
    call check_close(suite, "packed node fields", model%coordinates(:, 9), &
                     [-1.5_wp, 2.0_wp, -3.0_wp], thr=0.0_wp)
  end subroutine test_two_line_elements_and_degenerate

  !> Effective hourglass values by LS-DYNA's rules.
  subroutine test_hourglass_rules()
    type(model_t) :: model
    type(error_list_t) :: warnings
    call read_good("hourglass.k", cube_deck([character(len=line_length) :: &
      "*CONTROL_HOURGLASS", &
      fixed(["4   ", "0.05"], 10), &
      "*CONTROL_BULK_VISCOSITY", &
      "1.2,0.05", &
      "*HOURGLASS", &
      fixed(["7  ", "0  ", "   ", "   ", "2.0"], 10), &
      fixed(["8   ", "5   ", "0.12"], 10), &
      "*PART", "with HGID 7", fixed(["2", "1", "1", "0", "7"], 10), &
      "*PART", "no HGID", fixed(["3", "1", "1"], 10), &
      "*PART", "with HGID 8", fixed(["4", "1", "1", "0", "8"], 10)]), model, warnings)
    if (.not. allocated(model%parts)) return
    call check(suite, "hourglass: part 1 control type", model%parts(1)%hourglass_type == 4)
    call check_close(suite, "hourglass: part 1 control values", [model%parts(1)% &
      hourglass_coefficient, model%parts(1)%bulk_quadratic, model%parts(1)%bulk_linear], &
      [0.05_wp, 1.2_wp, 0.05_wp], thr=0.0_wp)
    call check(suite, "hourglass: IHQ 0 takes the control type", model%parts(2)%hourglass_type == 4)
    call check_close(suite, "hourglass: HGID 7 values", [model%parts(2)%hourglass_coefficient, &
      model%parts(2)%bulk_quadratic, model%parts(2)%bulk_linear], [0.05_wp, 2.0_wp, 0.05_wp], &
      thr=0.0_wp)
    call check(suite, "hourglass: HGID 8 type", model%parts(4)%hourglass_type == 5 .and. &
               model%parts(4)%hourglass == 2)
    call check_close(suite, "hourglass: HGID 8 QM", model%parts(4)%hourglass_coefficient, &
                     0.12_wp, thr=0.0_wp)
    call check(suite, "hourglass: no HGID", model%parts(3)%hourglass_type == 4 .and. &
               model%parts(3)%hourglass == 0)
  end subroutine test_hourglass_rules

  !> Curve scale and offset, set generation, SPCs (with *NODE TC), motions, loads, history.
  subroutine test_curve_sets_and_conditions()
    type(model_t) :: model
    type(error_list_t) :: warnings
    call read_good("conditions.k", replaced(14, trim(node_line(8, 0.0_wp, 1.0_wp, 1.0_wp))// &
      "       3", [character(len=line_length) :: &
      "*DEFINE_CURVE_TITLE", "ramp", fixed(["5  ", "0  ", "2.0", "3.0", "1.0", "0.5"], 10), &
      fixed(["0.0", "1.0"], 20), fixed(["1.0", "2.0"], 20), &
      "*SET_NODE_LIST_GENERATE", fixed(["1"], 10), fixed(["1 ", "3 ", "7 ", "50"], 10), &
      "*SET_NODE_LIST", "2", "5,6,0,5", &
      "*SET_PART_LIST", "3", "1", &
      "*BOUNDARY_SPC_SET_ID", "         1base", "2,0,1,1,1", &
      "*BOUNDARY_SPC_NODE", "1,0,0,0,1", &
      "*BOUNDARY_PRESCRIBED_MOTION_SET", "1,3,2,5,-2.0", &
      "*BOUNDARY_PRESCRIBED_MOTION_NODE", "8,1,,5,,,0.0,0.0", &
      "*LOAD_NODE_SET", "2,2,5,", &
      "*DATABASE_HISTORY_NODE_SET", "1", &
      "*DATABASE_HISTORY_NODE", fixed(["8", "1"], 10), &
      "*DATABASE_NODOUT", "1.0e-3"]), model, warnings)
    if (.not. allocated(model%curves)) return
    call check(suite, "curve: id and title", model%curves(1)%id == 5 .and. &
               model%curves(1)%title == "ramp")
    call check_close(suite, "curve: SFA*(A+OFFA)", model%curves(1)%abscissa, [2.0_wp, 4.0_wp], &
                     thr=0.0_wp)
    call check_close(suite, "curve: SFO*(O+OFFO)", model%curves(1)%ordinate, [4.5_wp, 7.5_wp], &
                     thr=0.0_wp)
    call check(suite, "generate: ranges with gaps", size(model%node_sets(1)%nodes) == 5 .and. &
               all(model%node_sets(1)%nodes == [1, 2, 3, 7, 8]))
    call check(suite, "list: blank, 0 and repeated ids", all(model%node_sets(2)%nodes == [5, 6]))
    call check(suite, "part set", all(model%part_sets(1)%parts == [1]))
    call check(suite, "spc: merged per node", size(model%spcs) == 4)
    call check(suite, "spc: node 1 from SPC_NODE", model%spcs(1)%node == 1 .and. &
               all(model%spcs(1)%fixed .eqv. [.false., .false., .true.]))
    call check(suite, "spc: node 5 from set", model%spcs(2)%node == 5 .and. &
               all(model%spcs(2)%fixed))
    call check(suite, "spc: node 8 from TC 3", model%spcs(4)%node == 8 .and. &
               all(model%spcs(4)%fixed .eqv. [.false., .false., .true.]))
    call check(suite, "motions: set of 5 plus 1 node", size(model%motions) == 6)
    call check(suite, "motion: displacement in z", model%motions(1)%kind == motion_displacement &
               .and. model%motions(1)%direction == 3 .and. model%motions(1)%curve == 1)
    call check_close(suite, "motion: SF", model%motions(1)%scale, -2.0_wp, thr=0.0_wp)
    call check(suite, "motion: velocity default VAD", model%motions(6)%kind == motion_velocity &
               .and. model%motions(6)%node == 8)
    call check_close(suite, "motion: SF blank and DEATH 0", [model%motions(6)%scale, &
                     model%motions(6)%death], [1.0_wp, 1.0e28_wp], thr=0.0_wp)
    call check(suite, "loads: per node of set 2", size(model%loads) == 2 .and. &
               all(model%loads%node == [5, 6]) .and. all(model%loads%direction == 2))
    call check(suite, "history: set then nodes, once each", &
               all(model%output%history_nodes == [1, 2, 3, 7, 8]))
    call check_close(suite, "nodout interval", model%output%nodout_interval, 1.0e-3_wp, thr=0.0_wp)
  end subroutine test_curve_sets_and_conditions

  !> *INITIAL_VELOCITY (all nodes, exempted set), _GENERATION rotation and _NODE, in that
  !> order of precedence.
  subroutine test_initial_velocity_generation()
    type(model_t) :: model
    type(error_list_t) :: warnings
    call read_good("velocity.k", cube_deck([character(len=line_length) :: &
      "*SET_NODE_LIST", "1", "5,6,7,8", &
      "*SET_NODE_LIST", "2", "2", &
      "*SET_NODE_LIST", "4", "3,4", &
      "*INITIAL_VELOCITY", "0,2", "1.0,0.0,0.0", "0.0,-1.0,0.0", &
      "*INITIAL_VELOCITY_GENERATION", &
      "1,3,2.0,0.0,0.0,10.0", "0.0,0.0,0.0,0.0,0.0,1.0", &
      "4,3,1.0,0.0,0.0,5.0", "0.0,0.0,0.0,-999,2,3", &
      "*INITIAL_VELOCITY_NODE", "7,0,0,-3"]), model, warnings)
    if (.not. allocated(model%initial_velocity)) return
    call check_close(suite, "velocity: all nodes", model%initial_velocity(:, 1), &
                     [1.0_wp, 0.0_wp, 0.0_wp], thr=0.0_wp)
    call check_close(suite, "velocity: exempted node", model%initial_velocity(:, 2), &
                     [0.0_wp, -1.0_wp, 0.0_wp], thr=0.0_wp)
    ! node 6 at (1, 0, 1): 2 z x (1, 0, 1) = (0, 2, 0), plus (0, 0, 10)
    call check_close(suite, "generation: rotation plus translation", &
                     model%initial_velocity(:, 6), [0.0_wp, 2.0_wp, 10.0_wp], thr=1.0e-15_wp)
    ! node 8 at (0, 1, 1): 2 z x (0, 1, 1) = (-2, 0, 0), plus (0, 0, 10)
    call check_close(suite, "generation: second node", model%initial_velocity(:, 8), &
                     [-2.0_wp, 0.0_wp, 10.0_wp], thr=1.0e-15_wp)
    ! axis through nodes 2 (1, 0, 0) and 3 (1, 1, 0): node 3 is on it, node 4 at (0, 1, 0)
    ! moves with 1 y x (-1, 1, 0) = (0, 0, 1)
    call check_close(suite, "generation: axis nodes, node on the axis", &
                     model%initial_velocity(:, 3), [0.0_wp, 0.0_wp, 5.0_wp], thr=1.0e-15_wp)
    call check_close(suite, "generation: axis nodes, node off the axis", &
                     model%initial_velocity(:, 4), [0.0_wp, 0.0_wp, 6.0_wp], thr=1.0e-15_wp)
    call check_close(suite, "velocity: _NODE wins", model%initial_velocity(:, 7), &
                     [0.0_wp, 0.0_wp, -3.0_wp], thr=0.0_wp)
  end subroutine test_initial_velocity_generation

  !> Rigid walls with every option, and the output intervals.
  subroutine test_rigid_walls_and_output()
    type(model_t) :: model
    type(error_list_t) :: warnings
    call read_good("walls.k", cube_deck([character(len=line_length) :: &
      "*SET_NODE_LIST", "1", "1,2", &
      "*RIGIDWALL_PLANAR_MOVING_FORCES_FINITE_ID", "12,the floor", &
      "0,1,,,,", "0,0,-1,0,0,2,0.3", "5,0,-1,100,50", "20.0,-3.0", "0,0", &
      "*RIGIDWALL_PLANAR", "1", "0,0,0,1,0,0", &
      "*CONTROL_ENERGY", "2,1", &
      "*DATABASE_BINARY_D3PLOT", fixed(["   ", "   ", "   ", "10 "], 10), &
      "*DATABASE_GLSTAT", "1.0e-4", "*DATABASE_MATSUM", "2.0e-4", &
      "*DATABASE_RWFORC", "3.0e-4"]), model, warnings)
    if (.not. allocated(model%walls)) return
    call check(suite, "walls: two", size(model%walls) == 2)
    associate (wall => model%walls(1))
      call check(suite, "wall: id and title", wall%id == 12 .and. wall%title == "the floor")
      call check(suite, "wall: NSID 0 minus NSIDEX", size(wall%nodes) == 6 .and. &
                 all(wall%nodes == [3, 4, 5, 6, 7, 8]))
      call check_close(suite, "wall: unit normal", wall%normal, [0.0_wp, 0.0_wp, 1.0_wp], &
                       thr=0.0_wp)
      call check_close(suite, "wall: point", wall%point, [0.0_wp, 0.0_wp, -1.0_wp], thr=0.0_wp)
      call check_close(suite, "wall: friction", wall%friction, 0.3_wp, thr=0.0_wp)
      call check(suite, "wall: options", wall%finite .and. wall%moving .and. wall%forces_requested)
      call check_close(suite, "wall: edge", wall%edge_direction, [1.0_wp, 0.0_wp, 0.0_wp], &
                       thr=0.0_wp)
      call check_close(suite, "wall: edge lengths", [wall%length_l, wall%length_m], &
                       [100.0_wp, 50.0_wp], thr=0.0_wp)
      call check_close(suite, "wall: mass and V0", [wall%mass, wall%initial_speed], &
                       [20.0_wp, -3.0_wp], thr=0.0_wp)
      call check_close(suite, "wall: DEATH 0 means never", wall%death, 1.0e20_wp, thr=0.0_wp)
    end associate
    call check(suite, "wall 2: numbered, set 1", model%walls(2)%id == 2 .and. &
               all(model%walls(2)%nodes == [1, 2]) .and. .not. model%walls(2)%moving)
    call check_close(suite, "d3plot: ENDTIM/NPLTC", model%output%state_interval, 0.1_wp, &
                     rel=1.0e-15_wp)
    call check_close(suite, "history intervals", [model%output%glstat_interval, &
                     model%output%matsum_interval, model%output%rwforc_interval], &
                     [1.0e-4_wp, 2.0e-4_wp, 3.0e-4_wp], thr=0.0_wp)
    call check(suite, "energy: HGEN 2, RWEN 1", model%hourglass_energy_in_balance .and. &
               .not. model%wall_energy_in_balance)
  end subroutine test_rigid_walls_and_output

  !> An unknown keyword is an error; with ignore_unknown a warning.
  subroutine test_unknown_keywords()
    type(model_t) :: model
    type(error_list_t) :: warnings
    call read_bad("unknown.k", cube_deck([character(len=line_length) :: "*NODDE", "9,0,0,0"]), &
      [character(len=120) :: "@:24: *NODDE: unknown keyword (did you mean *NODE?)"])
    call read_good("ignored.k", cube_deck([character(len=line_length) :: "*CONTACT_AUTOMATIC", &
                   "1,2"]), model, warnings, ignore_unknown=.true.)
    call check(suite, "ignore_unknown: one warning", warnings%count == 1)
    if (warnings%count > 0) call check(suite, "ignore_unknown: warning text", &
      index(warnings%text, "fixed.k") == 0 .and. index(warnings%text, &
      "ignored.k:24: *CONTACT_AUTOMATIC: unknown keyword skipped") > 0, warnings%text)
  end subroutine test_unknown_keywords

  !> Letters in numbers, undefined parameters, tabs, a keyword not in column 1.
  subroutine test_syntax_errors()
    call read_bad("letter.k", replaced(9, "       3             1.0         1.0x0             0.0"), &
      [character(len=120) :: "@:9: *NODE: field Y: ""1.0x0"" is not a number (columns 25-40)"])
    call read_bad("letter_comma.k", replaced(21, "1,one"), &
      [character(len=120) :: "@:21: *SECTION_SOLID: field ELFORM: ""one"" is not an integer "// &
      "(entry 2 of the comma-separated card)"])
    call read_bad("not_integral.k", replaced(16, fixed(["1.5", "1  "], 8)), &
      [character(len=120) :: "@:16: *ELEMENT_SOLID: field EID: ""1.5"" is not an integer"])
    call read_bad("out_of_range.k", replaced(8, "2,1e200,0,0"), &
      [character(len=120) :: "@:8: *NODE: field X: ""1e200"" is out of range"])
    call read_bad("parameter.k", replaced(5, "&tend"), &
      [character(len=120) :: "@:5: *CONTROL_TERMINATION: field ENDTIM: parameter &tend is "// &
      "not defined"])
    call read_bad("tab.k", replaced(21, "         1"//achar(9)//"1"), &
      [character(len=120) :: "@:21: *SECTION_SOLID: the card holds a tab character"])
    call read_bad("column.k", replaced(20, " *SECTION_SOLID"), &
      [character(len=120) :: "@:20: a keyword must start in column 1"])
    call read_bad("bad_parameter.k", cube_deck([character(len=line_length) :: "*PARAMETER", &
      "X name    1.0"]), [character(len=120) :: "@:25: *PARAMETER: field PRMR1: ""X name"" "// &
      "must start with its type letter"])
  end subroutine test_syntax_errors

  !> Keywords that end before a required card.
  subroutine test_missing_cards()
    call read_bad("mat003_one_card.k", cube_deck([character(len=line_length) :: &
      "*MAT_PLASTIC_KINEMATIC", "2,7.8e-6,210.,0.3,0.25,2.1,0.0"]), &
      [character(len=120) :: "@:25: *MAT_PLASTIC_KINEMATIC: field SRC: card 2 (SRC SRP FS VP) "// &
      "is missing"])
    call read_bad("part_no_card.k", cube_deck([character(len=line_length) :: "*PART", &
      "a part without its data card"]), [character(len=120) :: "@:25: *PART: field PID: the "// &
      "data card (PID SECID MID EOSID HGID GRAV ADPOPT TMID) after the heading line is missing"])
    call read_bad("termination_no_card.k", replaced(5, "$ no card", [character(len=line_length) &
      :: "*DATABASE_GLSTAT", "1.0e-3"]), [character(len=120) :: "@:4: *CONTROL_TERMINATION: "// &
      "field ENDTIM: card 1 (ENDTIM ENDCYC DTMIN ENDENG ENDMAS NOSOL) is missing"])
    call read_bad("section_no_card.k", replaced(21, "$ the card is missing"), &
      [character(len=120) :: "@:20: *SECTION_SOLID: field SECID: card 1 (SECID ELFORM AET) is "// &
      "missing: the keyword has no cards"])
    call read_bad("two_line_missing.k", cube_deck([character(len=line_length) :: &
      "*ELEMENT_SOLID", fixed(["2", "1"], 8)]), [character(len=120) :: "@:25: *ELEMENT_SOLID: "// &
      "field N1: the node card (N1-N8) of element 2 is missing"])
    call read_bad("curve_no_points.k", cube_deck([character(len=line_length) :: &
      "*DEFINE_CURVE", "3"]), [character(len=120) :: "@:25: *DEFINE_CURVE: field A: the curve "// &
      "has no points"])
    call read_bad("include_missing.k", cube_deck([character(len=line_length) :: "*INCLUDE", &
      "sub/no_such_file.k"]), [character(len=120) :: "@:25: *INCLUDE: field FILENAME: cannot "// &
      "open ""#/sub/no_such_file.k"""])
    call test_blank_cards()
  end subroutine test_missing_cards

  !> A blank line is a card of defaults where a definition needs one, also as the keyword's
  !> last line; it is no definition of its own after the last one.
  subroutine test_blank_cards()
    type(model_t) :: model
    type(error_list_t) :: warnings
    call read_good("mat003_blank_card.k", cube_deck([character(len=line_length) :: &
      "*MAT_PLASTIC_KINEMATIC", "2,7.8e-6,210.,0.3,0.25,2.1,0.0", "", "   "]), model, warnings)
    call check(suite, "blank last card: two materials", size(model%materials) == 2)
    call read_good("section_blank_elform.k", cube_deck([character(len=line_length) :: &
      "*SECTION_SHELL", "2,0", "0.1", "", "*SECTION_SOLID", "3,0", ""]), model, warnings)
    call check(suite, "ELFORM 0: shell 2, solid 1, no section of blank lines", &
      size(model%sections) == 3 .and. model%sections(2)%element_formulation == 2 .and. &
      model%sections(3)%element_formulation == 1)
    call read_bad("option_not_skipped.k", cube_deck([character(len=line_length) :: &
      "*SECTION_SOLID_ALE", "3,1"]), [character(len=120) :: "@:24: *SECTION_SOLID_ALE: "// &
      "crashfree reads *SECTION_SOLID, but not with the option ALE"], ignore_unknown=.true.)
  end subroutine test_blank_cards

  !> Cross-reference errors: all listed at once, each at the card holding the reference.
  subroutine test_reference_errors()
    character(len=line_length), allocatable :: lines(:)
    allocate (lines(0))    ! (keeps gfortran 12 from a false "used uninitialized" warning)
    lines = replaced(16, fixed(["1 ", "1 ", "1 ", "2 ", "99", "4 ", "5 ", "6 ", "7 ", "8 "], 8), &
      [character(len=line_length) :: &
      "*PART", "no material", fixed(["2", "1"], 10), &
      "*PART", "bad references", fixed(["3 ", "9 ", "7 ", "0 ", "11"], 10), &
      "*BOUNDARY_PRESCRIBED_MOTION_NODE", "1,1,0,9", &
      "*BOUNDARY_SPC_SET", "5,0,1,1,1", &
      "*ELEMENT_SOLID", fixed(["2 ", "42", "1 ", "2 ", "3 ", "4 ", "5 ", "6 ", "7 ", "8 "], 8), &
      "*SET_NODE_LIST", "4", "1,77", &
      "*DATABASE_HISTORY_NODE", "1,0,88", &
      "*ELEMENT_SOLID", fixed(["3 ", "42", "1 ", "2 ", "3 ", "4 ", "5 ", "6 ", "7 ", "8 "], 8)])
    call read_bad("references.k", lines, [character(len=120) :: &
      "@:16: *ELEMENT_SOLID: field N3: node 99 of element 1 is not defined", &
      "@:26: *PART: field MID: part 2 has no material (MID is blank or 0)", &
      "@:29: *PART: field SECID: section 9 of part 3 is not defined", &
      "@:29: *PART: field MID: material 7 of part 3 is not defined", &
      "@:29: *PART: field HGID: hourglass 11 of part 3 is not defined", &
      "@:31: *BOUNDARY_PRESCRIBED_MOTION_NODE: field LCID: curve 9 is not defined", &
      "@:33: *BOUNDARY_SPC_SET: field NSID: node set 5 is not defined", &
      "@:35: *ELEMENT_SOLID: field PID: part 42 of element 2 is not defined (no *PART with "// &
      "this PID); 1 more element names it", &
      "@:38: *SET_NODE_LIST: field NID2: node 77 of set 4 is not defined", &
      "@:40: *DATABASE_HISTORY_NODE: field ID3: node 88 is not defined"], message_lines=10)
  end subroutine test_reference_errors

  subroutine test_duplicates()
    call read_bad("duplicates.k", replaced(10, node_line(3, 0.0_wp, 1.0_wp, 0.0_wp), &
      [character(len=line_length) :: &
      "*ELEMENT_SOLID", fixed(["1", "1", "1", "2", "3", "4", "5", "6", "7", "8"], 8), &
      "*PART", "again", fixed(["1", "1", "1"], 10), &
      "*SECTION_SOLID", "1,2", &
      "*MAT_ELASTIC", "1,1.0,1.0,0.2", &
      "*DEFINE_CURVE", "6", "0,0", "*DEFINE_CURVE", "6", "0,0", &
      "*SET_NODE_LIST", "3", "1", "*SET_NODE_LIST_GENERATE", "3", "1,2", &
      "*SET_PART_LIST", "3", "1"]), [character(len=120) :: &
      "@:10: *NODE: field NID: node id 3 is defined twice (first at @:9)", &
      "@:25: *ELEMENT_SOLID: field EID: element id 1 is defined twice (first at @:16)", &
      "@:28: *PART: field PID: part id 1 is defined twice (first at @:19)", &
      "@:30: *SECTION_SOLID: field SECID: section id 1 is defined twice", &
      "@:32: *MAT_ELASTIC: field MID: material id 1 is defined twice", &
      "@:37: *DEFINE_CURVE: field LCID: curve id 6 is defined twice (first at @:34)", &
      "@:43: *SET_NODE_LIST_GENERATE: field SID: node set id 3 is defined twice"])
  end subroutine test_duplicates

  !> Physically impossible material values.
  subroutine test_material_limits()
    call read_bad("materials.k", replaced(23, fixed(["1  ", "0.0", "0.0", "0.5"], 10), &
      [character(len=line_length) :: &
      "*MAT_PLASTIC_KINEMATIC", "2,1.0,-5.0,-1.0,-0.1,-1.0,1.5", "-1.0,,,2", &
      "*MAT_003", "3,1.0,100.0,0.3,1.0,100.0,0.5", "10.0,0.0", &
      "*MAT_ELASTIC", "4,1.0,,0.3"]), [character(len=120) :: &
      "@:23: *MAT_ELASTIC: field RO: density must be > 0, found 0.0", &
      "@:23: *MAT_ELASTIC: field E: Young's modulus must be > 0, found 0.0", &
      "@:23: *MAT_ELASTIC: field PR: Poisson's ratio must lie in (-1, 0.5), found 0.5", &
      "@:25: *MAT_PLASTIC_KINEMATIC: field E: Young's modulus must be > 0, found -5.0", &
      "@:25: *MAT_PLASTIC_KINEMATIC: field PR: Poisson's ratio must lie in (-1, 0.5), found -1.0", &
      "@:25: *MAT_PLASTIC_KINEMATIC: field SIGY: yield stress must be >= 0, found -0.1", &
      "@:25: *MAT_PLASTIC_KINEMATIC: field ETAN: tangent modulus must be >= 0, found -1.0", &
      "@:25: *MAT_PLASTIC_KINEMATIC: field BETA: hardening parameter must lie in [0, 1]", &
      "@:26: *MAT_PLASTIC_KINEMATIC: field SRC: Cowper-Symonds C must be >= 0", &
      "@:26: *MAT_PLASTIC_KINEMATIC: field VP: must be 0 (scale the yield stress) or 1", &
      "@:28: *MAT_003: field ETAN: tangent modulus must be smaller than E = 100.0", &
      "@:29: *MAT_003: field SRP: Cowper-Symonds rate effects need both SRC and SRP > 0", &
      "@:31: *MAT_ELASTIC: field E: Young's modulus must be > 0, found 0.0 (the field is blank)"])
  end subroutine test_material_limits

  !> ENDTIM, no nodes or elements, inside-out and flat elements.
  subroutine test_controls_and_mesh_errors()
    character(len=line_length), allocatable :: lines(:)
    allocate (lines(0))    ! (keeps gfortran 12 from a false "used uninitialized" warning)
    call read_bad("endtim.k", replaced(5, fixed(["0.0"], 10)), [character(len=120) :: &
      "@:5: *CONTROL_TERMINATION: field ENDTIM: end time must be > 0 (or give ENDCYC > 0), "// &
      "found 0.0"])
    lines = cube_deck()
    call read_bad("no_termination.k", [lines(1:3), lines(6:)], [character(len=120) :: &
      "@: *CONTROL_TERMINATION: field ENDTIM: the deck has no *CONTROL_TERMINATION"])
    call read_bad("no_mesh.k", [lines(1:5), lines(17:)], [character(len=120) :: &
      "@: *NODE: field NID: the deck defines no nodes", &
      "@: *ELEMENT_SOLID: field EID: the deck defines no elements (no *ELEMENT_SOLID or "// &
      "*ELEMENT_SHELL)"])
    call read_bad("inside_out.k", replaced(16, fixed(["1", "1", "1", "4", "3", "2", "5", "8", &
      "7", "6"], 8)), [character(len=120) :: "@:16: *ELEMENT_SOLID: field N1-N8: element 1 of "// &
      "part 1 is inside out: negative Jacobian at corner N"])
    call read_bad("flat.k", replaced(16, fixed(["1", "1", "1", "2", "3", "4", "1", "2", "3", &
      "4"], 8)), [character(len=120) :: "@:16: *ELEMENT_SOLID: field N1-N8: element 1 of part "// &
      "1 has no volume"])
  end subroutine test_controls_and_mesh_errors

  !> Values with no LS-DYNA meaning, and features crashfree does not have, name their field.
  subroutine test_field_meanings()
    call read_bad("fields.k", cube_deck([character(len=line_length) :: &
      "*DEFINE_CURVE", "1", "0,0", "1,1", "0.5,2", &
      "*BOUNDARY_PRESCRIBED_MOTION_NODE", "1,14,0,1", "2,5,0,1", "3,1,7,1", &
      "*LOAD_NODE_POINT", "4,8,1", &
      "*BOUNDARY_SPC_NODE", "5,0,2", &
      "*SECTION_SOLID", "7,43", &
      "*SECTION_SOLID", "8,7", &
      "*NODE", trim(node_line(9, 2.0_wp, 0.0_wp, 0.0_wp))//"      12", &
      "*RIGIDWALL_PLANAR_MOVING", "0", "0,0,0,0,0,0", "0.0"]), [character(len=120) :: &
      "@:28: *DEFINE_CURVE: field A: abscissa 0.5 is smaller than the previous one, 1.0", &
      "@:30: *BOUNDARY_PRESCRIBED_MOTION_NODE: field DOF: must be 1, 2 or 3 (x, y, z "// &
      "translation) or 4, -4 (along the vector VID), found 14", &
      "@:31: *BOUNDARY_PRESCRIBED_MOTION_NODE: field DOF: 5 is a rotation", &
      "@:32: *BOUNDARY_PRESCRIBED_MOTION_NODE: field VAD: must be 0 (velocity), 1 "// &
      "(acceleration) or 2 (displacement), found 7", &
      "@:34: *LOAD_NODE_POINT: field DOF: 8 (follower force or moment) is not available", &
      "@:36: *BOUNDARY_SPC_NODE: field DOFX: must be 0 (free) or 1 (fixed), found 2", &
      "@:38: *SECTION_SOLID: field ELFORM: element formulation 43 is not available", &
      "@:40: *SECTION_SOLID: field ELFORM: element formulation 7 is not available", &
      "@:42: *NODE: field TC: translational constraint code must be 0-7", &
      "@:45: *RIGIDWALL_PLANAR_MOVING: field XH: the normal from the tail (XT YT ZT) to the "// &
      "head (XH YH ZH) has zero length", &
      "@:46: *RIGIDWALL_PLANAR_MOVING: field MASS: a moving wall needs a mass > 0"])
  end subroutine test_field_meanings
  ! ---------------------------------------------------------------- meshfree (EFG) sections

  !> *SECTION_SOLID_EFG_TITLE with every field of the EFG card and card 3 given, then a
  !> *SECTION_SOLID_EFG of blank fields, without card 3 but with the empty user-element cards
  !> pydyna writes.
  subroutine test_efg_section_keyword()
    type(model_t) :: model
    type(error_list_t) :: warnings
    ! IEBT 1 and IDIM 4 are verification variants: read in a linear static deck
    call read_good("efg_keyword.k", deck_with_sections([character(len=line_length) :: &
      "*SECTION_SOLID_EFG_TITLE", &
      "meshfree block", &
      fixed(["1 ", "41"], 10), &
      fixed(["1.2", "1.3", "1.4", "2  ", "0  ", "1  ", "2  ", "0.0"], 10), &
      fixed(["0      ", "1.0E+20", "0      ", "0.0    ", "0      ", "1      ", "0.01   ", &
             "1.0e-2 "], 10), &
      "*CONTROL_IMPLICIT_GENERAL", fixed(["1"], 10)]), model, warnings)
    if (allocated(model%sections)) then
      associate (section => model%sections(1))
        call check(suite, "efg keyword: one section, title, ELFORM 41", size(model%sections) == &
                   1 .and. section%title == "meshfree block" .and. section%element_formulation &
                   == 41)
        call check_close(suite, "efg keyword: DX DY DZ", section%support_scale, [1.2_wp, &
                         1.3_wp, 1.4_wp], thr=0.0_wp)
        call check(suite, "efg keyword: ISPLINE 2, spherical", section%kernel == &
                   kernel_cubic_sphere)
        call check(suite, "efg keyword: IDILA 0", section%dilation_basis == 0)
        call check(suite, "efg keyword: IEBT 1", section%boundary_treatment == &
                   boundary_full_transformation)
        call check(suite, "efg keyword: IDIM 2", section%domain_integration == integration_gauss)
        call check_close(suite, "efg keyword: TOLDEF 0", section%kernel_tolerance, 0.0_wp, &
                         thr=0.0_wp)
      end associate
      call check(suite, "efg keyword: part is EFG", model%parts(1)%formulation == &
                 formulation_efg)
      call check(suite, "efg keyword: DY, DZ of a sphere warned", warnings%count == 2 .and. &
        index(warnings%text, "efg_keyword.k:27: *SECTION_SOLID_EFG_TITLE: field DZ: ignored "// &
        "(a spherical support (ISPLINE 2) has one radius, scaled by DX)") > 0, warnings%text)
    end if
    call read_good("efg_defaults.k", deck_with_sections([character(len=line_length) :: &
      "*SECTION_SOLID_EFG", &
      "1,41", &
      "", &
      "", &
      fixed(["  ", "  ", "0 ", "0 "], 10), &
      "", &
      fixed(["0.0"], 10)]), model, warnings)
    if (.not. allocated(model%sections)) return
    associate (section => model%sections(1))
      call check_close(suite, "efg defaults: DX DY DZ 1.01", section%support_scale, &
                       [1.01_wp, 1.01_wp, 1.01_wp], thr=0.0_wp)
      call check(suite, "efg defaults: ISPLINE 0, box", section%kernel == kernel_cubic_box)
      call check(suite, "efg defaults: IDILA 0", section%dilation_basis == 0)
      call check(suite, "efg defaults: IEBT 3", section%boundary_treatment == boundary_coupled)
      call check(suite, "efg defaults: IDIM 1", section%domain_integration == &
                 integration_local_boundary)
      call check_close(suite, "efg defaults: TOLDEF 0", section%kernel_tolerance, 0.0_wp, &
                       thr=0.0_wp)
    end associate
    call check(suite, "efg defaults: part is EFG", model%parts(1)%formulation == formulation_efg)
  end subroutine test_efg_section_keyword

  !> ELFORM 41 inside repeating *SECTION_SOLID sets: the EFG card follows card 1, and the next
  !> line is the next section (with _TITLE, its title). DX 0 means 1.01.
  subroutine test_efg_in_solid_section_sets()
    type(model_t) :: model
    type(error_list_t) :: warnings
    integer :: k
    call read_good("efg_sets.k", deck_with_sections([character(len=line_length) :: &
      "*SECTION_SOLID", &
      "1,41", &
      fixed(["0.0"], 10), &
      "2,2", &
      "3,41", &
      "1.5,0,1.2,0,,1,2,0", &
      "4,1", &
      "*SECTION_SOLID_TITLE", &
      "meshfree", &
      fixed(["5 ", "41"], 10), &
      fixed(["1.3", "   ", "   ", "2  "], 10), &
      "finite elements", &
      fixed(["6", "2"], 10), &
      "*PART", "fe", fixed(["2", "2", "1"], 10), &
      "*PART", "efg", fixed(["3", "3", "1"], 10), &
      "*PART", "efg titled", fixed(["4", "5", "1"], 10), &
      "*PART", "fe titled", fixed(["5", "6", "1"], 10), &
      "*CONTROL_IMPLICIT_GENERAL", fixed(["1"], 10)]), model, warnings)
    if (.not. allocated(model%sections)) return
    call check(suite, "efg sets: six sections", size(model%sections) == 6)
    if (size(model%sections) /= 6) return
    call check(suite, "efg sets: ids", all([(model%sections(k)%id, k=1, 6)] == [1, 2, 3, 4, 5, &
                                                                                6]))
    call check(suite, "efg sets: ELFORM", all([(model%sections(k)%element_formulation, k=1, &
                                                6)] == [41, 2, 41, 1, 41, 2]))
    call check_close(suite, "efg sets: DX 0 means 1.01", model%sections(1)%support_scale, &
                     [1.01_wp, 1.01_wp, 1.01_wp], thr=0.0_wp)
    call check(suite, "efg sets: blank IEBT IDIM", model%sections(1)%boundary_treatment == &
               boundary_coupled .and. model%sections(1)%domain_integration == &
               integration_local_boundary)
    call check_close(suite, "efg sets: DY 0 means 1.01", model%sections(3)%support_scale, &
                     [1.5_wp, 1.01_wp, 1.2_wp], thr=0.0_wp)
    call check(suite, "efg sets: IEBT 1, IDIM 2", model%sections(3)%boundary_treatment == &
               boundary_full_transformation .and. model%sections(3)%domain_integration == &
               integration_gauss)
    call check(suite, "efg sets: titles", model%sections(5)%title == "meshfree" .and. &
               model%sections(6)%title == "finite elements")
    call check(suite, "efg sets: titled section kernel", model%sections(5)%kernel == &
               kernel_cubic_sphere)
    call check(suite, "efg sets: blank DY DZ of a sphere, no warning", warnings%count == 0)
    call check(suite, "efg sets: part formulations", all([(model%parts(k)%formulation, k=1, &
               5)] == [formulation_efg, formulation_fe, formulation_efg, formulation_efg, &
               formulation_fe]))
  end subroutine test_efg_in_solid_section_sets

  !> Every value of the EFG card and card 3 that crashfree does not have names its field, and
  !> ELFORM must fit the keyword.
  subroutine test_efg_card_errors()
    call read_bad("efg_fields.k", deck_with_sections([character(len=line_length) :: &
      "*SECTION_SOLID_EFG", &
      "1,41", &
      "1.0,0.5,-2,1,1,2,3,0.01", &
      "1,5.0,1,0.1,7,2,0.02,0.5", &
      "*SECTION_SOLID_EFG", &
      "2,1", &
      "1.1", &
      "*SECTION_SOLID", &
      "3,42", &
      "1.1", &
      "4,41", &
      "1.1,,,3,2,0,0,-0.5", &
      "5,1", &
      "*SECTION_SOLID_EFG", &
      "6", &
      "1.1"]), [character(len=360) :: &
      "@:26: *SECTION_SOLID_EFG: field DX: DX must be greater than 1: at 1.0 a vertex weight "// &
      "vanishes on the cell's far corner; found 1.0 (blank or 0 means 1.01)", &
      "@:26: *SECTION_SOLID_EFG: field DY: DY must be greater than 1: at 1.0 a vertex weight "// &
      "vanishes on the cell's far corner; found 0.5", &
      "@:26: *SECTION_SOLID_EFG: field DZ: DZ must be greater than 1: at 1.0 a vertex weight "// &
      "vanishes on the cell's far corner; found -2.0", &
      "@:26: *SECTION_SOLID_EFG: field ISPLINE: the quadratic spline kernel (ISPLINE 1) is "// &
      "not available; use 0 (cubic spline, box support) or 2 (cubic spline, spherical support)", &
      "@:26: *SECTION_SOLID_EFG: field IDILA: IDILA 1 (support size from the surrounding "// &
      "nodes) is not available", &
      "@:26: *SECTION_SOLID_EFG: field IEBT: essential boundary treatment 2 is not available; "// &
      "crashfree has IEBT 3 (coupled FE/EFG, the default for a blank field) and 1 (full "// &
      "transformation)", &
      "@:26: *SECTION_SOLID_EFG: field IDIM: domain integration 3 is not available; crashfree "// &
      "has IDIM 1 (local boundary integration, the default for a blank field), 2 (2x2x2 Gauss "// &
      "points per cell, for comparison) and 4 (crashfree's extension: conventional EFG, 4x4x4 "// &
      "Gauss points per cell with direct MLS gradients)", &
      "@:26: *SECTION_SOLID_EFG: field TOLDEF: semi-Lagrangian and Eulerian kernels (TOLDEF "// &
      "/= 0) are not available; use 0 (found 0.01)", &
      "@:27: *SECTION_SOLID_EFG: field IPS: pressure smoothing is not available; leave IPS "// &
      "blank or 0, found 1", &
      "@:27: *SECTION_SOLID_EFG: field STIME: the switch from stabilized to standard EFG "// &
      "belongs to stabilized EFG integration (IDIM -1), which is not available; leave STIME "// &
      "blank (1e20), found 5.0", &
      "@:27: *SECTION_SOLID_EFG: field IKEN: the maximum-entropy approximation is not "// &
      "available: crashfree uses moving least squares (IKEN 0), found 1", &
      "@:27: *SECTION_SOLID_EFG: field SF: EFG fracture (crack initiation at the failure "// &
      "strain SF) is not available; leave SF blank or 0, found 0.1", &
      "@:27: *SECTION_SOLID_EFG: field CMID: EFG fracture (the cohesive material CMID) is not "// &
      "available; leave CMID blank, found 7", &
      "@:27: *SECTION_SOLID_EFG: field IBR: crack branching belongs to EFG fracture, which is "// &
      "not available; leave IBR blank or 1, found 2", &
      "@:27: *SECTION_SOLID_EFG: field DS: the support of the displacement jump belongs to EFG "// &
      "fracture, which is not available; leave DS blank (0.01), found 0.02", &
      "@:27: *SECTION_SOLID_EFG: field ECUT: the smallest crack-cut distance belongs to EFG "// &
      "fracture, which is not available; leave ECUT blank (0.01), found 0.5", &
      "@:29: *SECTION_SOLID_EFG: field ELFORM: *SECTION_SOLID_EFG needs ELFORM 41 (meshfree "// &
      "EFG solid), found 1 (a finite element formulation: use *SECTION_SOLID)", &
      "@:32: *SECTION_SOLID: field ELFORM: adaptive EFG (ELFORM 42, 4-node background cells) "// &
      "is not available; use ELFORM 41", &
      "@:35: *SECTION_SOLID: field ISPLINE: must be 0 (cubic spline, box support) or 2 (cubic "// &
      "spline, spherical support), found 3", &
      "@:35: *SECTION_SOLID: field IDILA: must be 0 (support size from the background "// &
      "elements), found 2", &
      "@:35: *SECTION_SOLID: field IEBT: essential boundary treatment 0 is not available; "// &
      "crashfree has IEBT 3 (coupled FE/EFG, the default for a blank field) and 1 (full "// &
      "transformation); 0 is not a default here: leave the field blank", &
      "@:35: *SECTION_SOLID: field IDIM: domain integration 0 is not available; crashfree has "// &
      "IDIM 1 (local boundary integration, the default for a blank field), 2 (2x2x2 Gauss "// &
      "points per cell, for comparison) and 4 (crashfree's extension: conventional EFG, 4x4x4 "// &
      "Gauss points per cell with direct MLS gradients); 0 is not a default here: leave the "// &
      "field blank", &
      "@:35: *SECTION_SOLID: field TOLDEF: semi-Lagrangian and Eulerian kernels (TOLDEF /= 0) "// &
      "are not available; use 0 (found -0.5)", &
      "@:38: *SECTION_SOLID_EFG: field ELFORM: *SECTION_SOLID_EFG needs ELFORM 41 (meshfree "// &
      "EFG solid), found 1 (the field is blank or 0, which means 1)"], message_lines=24)
  end subroutine test_efg_card_errors

  !> Where the cards of an EFG section end: a missing EFG card, card 3 inside a *SECTION_SOLID
  !> set, and a second section under one *SECTION_SOLID_EFG.
  subroutine test_efg_card_structure()
    call read_bad("efg_no_card.k", deck_with_sections([character(len=line_length) :: &
      "*SECTION_SOLID_EFG", "1,41"]), [character(len=200) :: "@:25: *SECTION_SOLID_EFG: field "// &
      "DX: the EFG card (DX DY DZ ISPLINE IDILA IEBT IDIM TOLDEF) of section 1 is missing: the "// &
      "keyword ends after this line"], message_lines=1)
    call read_bad("efg_no_card_in_set.k", deck_with_sections([character(len=line_length) :: &
      "*SECTION_SOLID", "1,2", "2,41"]), [character(len=200) :: "@:26: *SECTION_SOLID: field "// &
      "DX: the EFG card (DX DY DZ ISPLINE IDILA IEBT IDIM TOLDEF) of section 2 is missing"], &
      message_lines=1)
    call read_bad("efg_card3_in_set.k", deck_with_sections([character(len=line_length) :: &
      "*SECTION_SOLID", "1,41", "1.1", fixed(["0      ", "1.0E+20"], 10)]), &
      [character(len=200) :: "@:27: *SECTION_SOLID: field SECID: section id must be > 0, found "// &
      "0 (this card follows an EFG card; card 3, IPS STIME IKEN SF CMID IBR DS ECUT, is read "// &
      "only under *SECTION_SOLID_EFG)"], message_lines=1)
    call read_bad("efg_two_sections.k", deck_with_sections([character(len=line_length) :: &
      "*SECTION_SOLID_EFG_TITLE", "first", "1,41", "1.1", "0", "second", "2,41", "1.1"]), &
      [character(len=200) :: "@:29: *SECTION_SOLID_EFG_TITLE: field SECID: *SECTION_SOLID_EFG "// &
      "holds one section (card 1, the EFG card and the optional card 3); give the next section "// &
      "its own *SECTION_SOLID_EFG"], message_lines=1)
  end subroutine test_efg_card_structure

  !> The background cells of an EFG part must have 8 distinct nodes; FE parts may hold
  !> degenerate hexahedra.
  subroutine test_efg_cells()
    character(len=line_length), allocatable :: lines(:)
    allocate (lines(0))    ! (keeps gfortran 12 from a false "used uninitialized" warning)
    lines = deck_with_sections([character(len=line_length) :: &
      "*SECTION_SOLID", "1,41", "1.2", "2,1", &
      "*PART", "fe part", fixed(["2", "2", "1"], 10), &
      "*ELEMENT_SOLID", fixed(["2", "2", "1", "2", "3", "3", "5", "6", "7", "7"], 8)])
    lines(16) = fixed(["1", "1", "1", "2", "3", "3", "5", "6", "7", "7"], 8)
    call read_bad("efg_wedge.k", lines, &
      [character(len=200) :: "@:16: *ELEMENT_SOLID: field N1-N8: element 1 of part 1 repeats "// &
      "node 3 (N3 and N4): the background cells of an EFG part (ELFORM 41) must be proper "// &
      "hexahedra with 8 distinct nodes"], message_lines=1)
  end subroutine test_efg_cells

  !> IDIM 4, crashfree's conventional EFG (4x4x4 Gauss points, direct MLS gradients), in both
  !> section keywords.
  subroutine test_efg_conventional_integration()
    type(model_t) :: model
    type(error_list_t) :: warnings
    call read_good("efg_conventional.k", deck_with_sections([character(len=line_length) :: &
      "*SECTION_SOLID_EFG", "1,41", fixed(["1.2", "   ", "   ", "   ", "   ", "   ", "4  "], 10), &
      "*SECTION_SOLID", "2,41", "1.3,1.3,1.3,0,0,1,4", &
      "*PART", "second", fixed(["2", "2", "1"], 10), &
      "*CONTROL_IMPLICIT_GENERAL", fixed(["1"], 10)]), model, warnings)
    if (.not. allocated(model%sections)) return
    call check(suite, "IDIM 4: conventional Gauss integration", all([model%sections(1)% &
      domain_integration, model%sections(2)%domain_integration] == integration_gauss_conventional))
    call check(suite, "IDIM 4: IEBT blank 3, then 1", model%sections(1)%boundary_treatment == &
      boundary_coupled .and. model%sections(2)%boundary_treatment == boundary_full_transformation)
    call check(suite, "IDIM 4: parts are EFG", all(model%parts%formulation == formulation_efg))
    call check(suite, "IDIM 4: no warnings", warnings%count == 0, warnings%text)
  end subroutine test_efg_conventional_integration

  ! ---------------------------------------------------------------- implicit analysis

  !> IMFLAG 1 makes the analysis linear static; NSOLVR 1 is silent, a blank NSOLVR and DT0 /
  !> CNSTN warn; in an explicit deck *CONTROL_IMPLICIT_SOLUTION is ignored with a warning.
  subroutine test_implicit_controls()
    type(model_t) :: model
    type(error_list_t) :: warnings
    call read_good("implicit.k", cube_deck([character(len=line_length) :: &
      "*CONTROL_IMPLICIT_SOLUTION", "1,11,15,0.001,0.01,1e10,0.9,1e-10", &
      "*CONTROL_IMPLICIT_GENERAL", "1,,2,1,2"]), model, warnings)
    call check(suite, "implicit: IMFLAG 1 is linear static", model%implicit_static)
    call check(suite, "implicit: NSOLVR 1, no warnings", warnings%count == 0, warnings%text)
    call read_good("implicit_warnings.k", cube_deck([character(len=line_length) :: &
      "*CONTROL_IMPLICIT_GENERAL", fixed(["1  ", "0.1", "   ", "   ", "   ", "1  "], 10), &
      "*CONTROL_IMPLICIT_SOLUTION", fixed(["  ", "11"], 10)]), model, warnings)
    call check(suite, "implicit warnings: linear static", model%implicit_static)
    call check(suite, "implicit warnings: three", warnings%count == 3, warnings%text)
    if (warnings%count == 3) then
      call check(suite, "implicit warnings: DT0", index(warnings%text, "implicit_warnings.k:25: "// &
        "*CONTROL_IMPLICIT_GENERAL: field DT0: ignored (crashfree's linear static analysis "// &
        "takes no implicit time step)") > 0, warnings%text)
      call check(suite, "implicit warnings: CNSTN", index(warnings%text, "implicit_warnings.k:"// &
        "25: *CONTROL_IMPLICIT_GENERAL: field CNSTN: ignored (a linear analysis uses the "// &
        "elastic stiffness)") > 0, warnings%text)
      call check(suite, "implicit warnings: NSOLVR blank", index(warnings%text, &
        "implicit_warnings.k:27: *CONTROL_IMPLICIT_SOLUTION: field NSOLVR: blank means "// &
        "LS-DYNA's default 12 (nonlinear, BFGS updates); crashfree's implicit analysis is "// &
        "linear static, as NSOLVR 1") > 0, warnings%text)
    end if
    call read_good("implicit_off.k", cube_deck([character(len=line_length) :: &
      "*CONTROL_IMPLICIT_GENERAL", "0,0.1,,,1", &
      "*CONTROL_IMPLICIT_SOLUTION", "6"]), model, warnings)
    call check(suite, "implicit off: IMFLAG 0 is explicit", .not. model%implicit_static)
    call check(suite, "implicit off: solution card ignored", warnings%count == 1 .and. &
      index(warnings%text, "implicit_off.k:27: *CONTROL_IMPLICIT_SOLUTION: field NSOLVR: "// &
      "ignored (the analysis is explicit: *CONTROL_IMPLICIT_GENERAL IMFLAG 1 is not given)") > 0, &
      warnings%text)
  end subroutine test_implicit_controls

  !> IMFLAG other than 0 and 1, geometric stiffness, and a nonlinear solver in an implicit deck.
  subroutine test_implicit_control_errors()
    call read_bad("implicit_errors.k", cube_deck([character(len=line_length) :: &
      "*CONTROL_IMPLICIT_GENERAL", "2", &
      "*CONTROL_IMPLICIT_GENERAL", "-3", &
      "*CONTROL_IMPLICIT_GENERAL", "1,,,,1", &
      "*CONTROL_IMPLICIT_SOLUTION", "6"]), [character(len=240) :: &
      "@:25: *CONTROL_IMPLICIT_GENERAL: field IMFLAG: crashfree's implicit analysis is linear "// &
      "static: IMFLAG 0 or 1 (0 explicit, 1 implicit linear static), found 2 (an implicit "// &
      "springback step after the explicit analysis)", &
      "@:27: *CONTROL_IMPLICIT_GENERAL: field IMFLAG: crashfree's implicit analysis is linear "// &
      "static: IMFLAG 0 or 1 (0 explicit, 1 implicit linear static), found -3 (a curve "// &
      "switching between explicit and implicit)", &
      "@:29: *CONTROL_IMPLICIT_GENERAL: field IGS: geometric stiffness is not available: "// &
      "crashfree's implicit analysis is linear static; leave IGS blank or 2, found 1", &
      "@:31: *CONTROL_IMPLICIT_SOLUTION: field NSOLVR: crashfree's implicit analysis is linear "// &
      "static: NSOLVR 1 (linear), or blank, found 6"], message_lines=4)
  end subroutine test_implicit_control_errors

  ! ---------------------------------------------------------------- segment loads

  !> *LOAD_SEGMENT(_ID) quadrilaterals and triangles, *SET_SEGMENT_TITLE with
  !> *LOAD_SEGMENT_SET_ID, *LOAD_SEGMENT_NONUNIFORM(_ID) along the normal and along a vector.
  subroutine test_segment_loads()
    type(model_t) :: model
    type(error_list_t) :: warnings
    integer :: k
    real(wp), parameter :: never = huge(1.0_wp)
    call read_good("segments.k", cube_deck([character(len=line_length) :: &
      "*DEFINE_CURVE", "7", "0,0", "1,1", &
      "*LOAD_SEGMENT", &
      fixed(["7  ", "   ", "0.5", "5  ", "6  ", "7  ", "8  "], 10), &
      "7,-2.0,,1,2,6", &
      "0,0,0", &
      "*LOAD_SEGMENT_ID", "         3top", "7,0.0,,1,4,3,3", &
      "*SET_SEGMENT_TITLE", "bottom", "4", "1,4,3,2", "1,2,6,5,0.5", &
      "*LOAD_SEGMENT_SET_ID", "        10bottom pressure", "4,7,3.0,0.25", &
      "*LOAD_SEGMENT_NONUNIFORM", "7,2.0,0.1,0.9,0,0,0,0", "5,6,7,8", "1.0,2.0,3.0,4.0", &
      "2,3,7", "1.5,2.5,3.5", &
      "*LOAD_SEGMENT_NONUNIFORM_ID", "         5side", "7,,,,,0.0,3.0,4.0", "1,2,6,5", &
      "1,1,1,1"]), model, warnings)
    if (.not. allocated(model%segment_loads)) return
    call check(suite, "segments: eight loads", size(model%segment_loads) == 8)
    if (size(model%segment_loads) /= 8) return
    associate (loads => model%segment_loads)
      call check(suite, "segments: nodes", all(loads(1)%nodes == [5, 6, 7, 8]) .and. &
        all(loads(2)%nodes == [1, 2, 6, 6]) .and. all(loads(3)%nodes == [1, 4, 3, 3]) .and. &
        all(loads(4)%nodes == [1, 4, 3, 2]) .and. all(loads(5)%nodes == [1, 2, 6, 5]) .and. &
        all(loads(6)%nodes == [5, 6, 7, 8]) .and. all(loads(7)%nodes == [2, 3, 7, 7]) .and. &
        all(loads(8)%nodes == [1, 2, 6, 5]))
      call check(suite, "segments: curve index", all(loads%curve == 1))
      call check_close(suite, "segments: SF (blank and 0 mean 1)", [(loads(k)%scale, k=1, 8)], [1.0_wp, &
        -2.0_wp, 1.0_wp, 3.0_wp, 3.0_wp, 2.0_wp, 2.0_wp, 1.0_wp], thr=0.0_wp)
      call check_close(suite, "segments: AT", [(loads(k)%arrival_time, k=1, 8)], [0.5_wp, 0.0_wp, 0.0_wp, &
        0.25_wp, 0.25_wp, 0.1_wp, 0.1_wp, 0.0_wp], thr=0.0_wp)
      call check_close(suite, "segments: death (DT blank: never)", [(loads(k)%death, k=1, 8)], [never, never, &
        never, never, never, 0.9_wp, 0.9_wp, never], thr=0.0_wp)
      do k = 1, 5
        call check_close(suite, "segments: uniform values "//integer_text(k), &
                         loads(k)%nodal_values, [1.0_wp, 1.0_wp, 1.0_wp, 1.0_wp], thr=0.0_wp)
      end do
      call check_close(suite, "nonuniform: values", loads(6)%nodal_values, [1.0_wp, 2.0_wp, &
                       3.0_wp, 4.0_wp], thr=0.0_wp)
      call check_close(suite, "nonuniform: triangle P4 = P3", loads(7)%nodal_values, &
                       [1.5_wp, 2.5_wp, 3.5_wp, 3.5_wp], thr=0.0_wp)
      call check(suite, "segments: pressures along the normal", all(loads(1:7)%along_normal))
      call check(suite, "nonuniform: traction along V", .not. loads(8)%along_normal)
      call check_close(suite, "nonuniform: unit direction", loads(8)%direction, [0.0_wp, 0.6_wp, &
                       0.8_wp], rel=1.0e-15_wp)
      call check_close(suite, "nonuniform: values of the traction", loads(8)%nodal_values, &
                       [1.0_wp, 1.0_wp, 1.0_wp, 1.0_wp], thr=0.0_wp)
    end associate
    call check(suite, "segments: A1 warned", warnings%count == 1 .and. index(warnings%text, &
      "segments.k:39: *SET_SEGMENT_TITLE: field A1: ignored (segment attributes are not used)") &
      > 0, warnings%text)
  end subroutine test_segment_loads

  !> Every problem of a segment load or set names its field, all listed at once: undefined,
  !> repeated and non-positive nodes, no area, curves, sets, mid-side nodes, DT, CID, P4.
  subroutine test_segment_load_errors()
    call read_bad("segment_errors.k", cube_deck([character(len=line_length) :: &
      "*DEFINE_CURVE", "7", "0,0", &
      "*LOAD_SEGMENT", &
      "7,,,1,2,99,4", "7,,,1,2,1,4", "7,,,1,2,3,4,9", "0,,,1,2,3,4", "8,,,1,2,3,4", &
      "7,,,1,2,9,10", "7,1.0,,0,2,3", "7", &
      "*SET_SEGMENT", "3", "1,2,3,77", "1,1,2,3", &
      "*LOAD_SEGMENT_SET", "3,7", "5,7", "-1,7", &
      "*LOAD_SEGMENT_NONUNIFORM", "7,,1.0,0.5,2", "1,2,3,3,0,11", "1.0,2.0,3.0,4.0", &
      "5,6,7,8", "0,0,0,0", &
      "*SET_SEGMENT", "3", "5,6,7,8", &
      "*NODE", node_line(9, 2.0_wp, 0.0_wp, 0.0_wp), node_line(10, 3.0_wp, 0.0_wp, 0.0_wp)]), &
      [character(len=240) :: &
      "@:28: *LOAD_SEGMENT: field N3: node 99 is not defined", &
      "@:29: *LOAD_SEGMENT: field N3: the segment repeats node 1 (N1 and N3); only N4 may "// &
      "repeat N3 (a triangle)", &
      "@:30: *LOAD_SEGMENT: field N5: quadratic segments (mid-side nodes) are not available; "// &
      "leave N5 blank, found 9", &
      "@:31: *LOAD_SEGMENT: field LCID: a load curve id > 0 is required (field 1), found 0", &
      "@:32: *LOAD_SEGMENT: field LCID: curve 8 is not defined (no *DEFINE_CURVE with this LCID)", &
      "@:33: *LOAD_SEGMENT: field N1-N4: the segment (nodes 1 2 9 10) has no area: its corners "// &
      "coincide or lie on one line", &
      "@:34: *LOAD_SEGMENT: field N1: node id must be > 0, found 0", &
      "@:35: *LOAD_SEGMENT: field N1: the line has no segment nodes (N1-N4 are blank): each "// &
      "line of *LOAD_SEGMENT is one segment, LCID SF AT N1 N2 N3 N4 N5; a card of mid-side "// &
      "nodes N6 N7 N8 (quadratic segments) is not read", &
      "@:38: *SET_SEGMENT: field N4: node 77 of segment set 3 is not defined", &
      "@:39: *SET_SEGMENT: field N2: the segment repeats node 1 (N1 and N2); only N4 may "// &
      "repeat N3 (a triangle)", &
      "@:42: *LOAD_SEGMENT_SET: field SSID: segment set 5 is not defined (no *SET_SEGMENT with "// &
      "this SID)", &
      "@:43: *LOAD_SEGMENT_SET: field SSID: segment set id must be > 0, found -1", &
      "@:45: *LOAD_SEGMENT_NONUNIFORM: field DT: death time 0.5 must be later than the arrival "// &
      "time AT = 1.0", &
      "@:45: *LOAD_SEGMENT_NONUNIFORM: field CID: loads in local coordinate systems are not "// &
      "available; leave it blank or 0", &
      "@:46: *LOAD_SEGMENT_NONUNIFORM: field N6: quadratic segments (mid-side nodes N5-N8) are "// &
      "not available; leave N5-N8 blank, found 11", &
      "@:47: *LOAD_SEGMENT_NONUNIFORM: field P4: the segment is a triangle (N4 = N3), which has "// &
      "one value at N3: leave P4 blank or equal to P3 = 3.0, found 4.0", &
      "@:51: *SET_SEGMENT: field SID: segment set id 3 is defined twice (first at @:37)"], &
      message_lines=17)
  end subroutine test_segment_load_errors

  !> *LOAD_SEGMENT_NONUNIFORM without the values card of a segment, or without any segment.
  subroutine test_segment_load_structure()
    call read_bad("nonuniform_no_values.k", cube_deck([character(len=line_length) :: &
      "*DEFINE_CURVE", "7", "0,0", "*LOAD_SEGMENT_NONUNIFORM", "7", "5,6,7,8"]), &
      [character(len=200) :: "@:29: *LOAD_SEGMENT_NONUNIFORM: field P1: the card of nodal "// &
      "values (P1-P8) after the node card of the segment is missing: the keyword ends after "// &
      "this line"], message_lines=1)
    call read_bad("nonuniform_no_segment.k", cube_deck([character(len=line_length) :: &
      "*DEFINE_CURVE", "7", "0,0", "*LOAD_SEGMENT_NONUNIFORM", "7"]), &
      [character(len=200) :: "@:28: *LOAD_SEGMENT_NONUNIFORM: field N1: the keyword has no "// &
      "segment: a card of nodes N1-N8 and a card of nodal values P1-P8 must follow card 1"], &
      message_lines=1)
  end subroutine test_segment_load_structure
  ! ---------------------------------------------------------------- crushable materials

  !> *MAT_126 (with _TITLE) used by the cube's part, *MAT_026 and *MAT_057 beside it: values,
  !> LS-DYNA's curve defaults and the curves copied into the materials.
  subroutine test_crushable_materials()
    type(model_t) :: model
    type(error_list_t) :: warnings
    character(len=8), parameter :: c = ""
    call read_good("crushable.k", replaced(19, fixed([character(len=8) :: "1", "1", "2"], 10), [character(len=line_length) :: &
      "*MAT_MODIFIED_HONEYCOMB_TITLE", "aluminium honeycomb", &
      fixed([character(len=8) :: "2", "6.0e-11", "70000.", "0.3", "300.", "0.1"], 10), &
      fixed([character(len=8) :: "10", "11", c, c, c, c, "12", c], 10), &
      fixed([character(len=8) :: "1000.", "500.", "500.", "200.", "200.", "200.", "2", c], 10), &
      fixed([character(len=8) :: c, c, c, "0.0", "0.0", "1.0"], 10), &
      fixed([character(len=8) :: "0.0", "1.0", "0.0"], 10), &
      "*MAT_026", fixed([character(len=8) :: "3", "6.0e-11", "70000.", "0.3", "300.", "0.2", "0.0"], 10), &
      fixed([character(len=8) :: "11", c, c, "12", c, c, c, "10"], 10), &
      fixed([character(len=8) :: "1000.", "500.", "500.", "200.", "200.", "200."], 10), &
      fixed([character(len=8) :: "0.0"], 10), fixed([character(len=8) :: "0.0"], 10), &
      "*MAT_LOW_DENSITY_FOAM", fixed([character(len=8) :: "4", "3.0e-11", "5.0", "12", c, "0.1", c, "0.2"], 10), &
      fixed([character(len=8) :: "3.0"], 10), &
      "*DEFINE_CURVE", fixed([character(len=8) :: "10"], 10), "0.0,1.0", "1.0,2.0", &
      "*DEFINE_CURVE", fixed([character(len=8) :: "11"], 10), "0.0,0.5", "1.0,0.7", &
      "*DEFINE_CURVE", fixed([character(len=8) :: "12"], 10), "0.0,0.0", "0.5,0.2"]), model, warnings)
    if (.not. allocated(model%materials)) return
    if (size(model%materials) /= 4) then
      call check(suite, "crushable: four materials", .false.)
      return
    end if
    associate (m => model%materials(2))
      call check(suite, "126: law, title, part", m%law == law_modified_honeycomb .and. m%title == &
                 "aluminium honeycomb" .and. model%parts(1)%material == 2)
      call check_close(suite, "126: RO E PR SIGY VF MU(default)", [m%density, m%youngs_modulus, m%poissons_ratio, &
                       m%yield_stress, m%compaction_volume, m%viscosity], &
                       [6.0e-11_wp, 70000.0_wp, 0.3_wp, 300.0_wp, 0.1_wp, 0.05_wp], rel=1e-15_wp)
      call check(suite, "126: curve defaults LCC -> LCA, LCAB LCBC -> LCS -> LCA", &
                 all(m%curve_ids == [10, 11, 10, 10, 10, 12, 0]))
      call check(suite, "126: curves copied", m%curves(2)%id == 11 .and. m%curves(6)%id == 12 .and. &
                 size(m%curves(1)%abscissa) == 2)
      call check_close(suite, "126: moduli, axes", [m%uncompacted_moduli, m%axis_a, m%axis_d], &
        [1000.0_wp, 500.0_wp, 500.0_wp, 200.0_wp, 200.0_wp, 200.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, 1.0_wp, &
         0.0_wp], thr=0.0_wp)
      call check(suite, "126: AOPT 2", m%axes_option == 2)
      call check(suite, "126: BULK 0 switches the part's bulk viscosity off", .not. m%bulk_viscosity .and. &
                 model%parts(1)%bulk_linear == 0.0_wp .and. model%parts(1)%bulk_quadratic == 0.0_wp)
    end associate
    associate (m => model%materials(3))
      call check(suite, "026: law, MU 0 (the default 0.05), LCSR, AOPT 0", m%law == law_honeycomb .and. &
                 m%viscosity == 0.05_wp &
                 .and. all(m%curve_ids == [11, 11, 11, 12, 12, 12, 10]) .and. m%axes_option == 0)
    end associate
    associate (m => model%materials(4))
      call check(suite, "057: law and curve", m%law == law_low_density_foam .and. m%curves(1)%id == 12)
      call check_close(suite, "057: E TC(default) HU DAMP SHAPE", [m%youngs_modulus, m%tension_cutoff, &
        m%hysteretic_unloading, m%viscosity, m%unloading_shape], [5.0_wp, 1.0e20_wp, 0.1_wp, 0.2_wp, 3.0_wp], &
        rel=1e-15_wp)
    end associate
  end subroutine test_crushable_materials

  !> Impossible values, features not built and undefined curves, each naming its field.
  subroutine test_crushable_material_errors()
    character(len=8), parameter :: c = ""
    call read_bad("crushable_bad.k", cube_deck([character(len=line_length) :: &
      "*MAT_126", fixed([character(len=8) :: "5", "0.0", "70000.", "0.3", "300.", "1.5"], 10), &
      fixed([character(len=8) :: "99"], 10), &
      fixed([character(len=8) :: "1000.", "500.", "500.", "200.", "200.", "200.", "3"], 10), &
      fixed([character(len=8) :: c, c, c, "1.0", "0.0", "0.0", c, "1"], 10), &
      fixed([character(len=8) :: "0.0", "1.0", "0.0", "0.5"], 10), &
      "*MAT_LOW_DENSITY_FOAM", fixed([character(len=8) :: "6", "1.0e-10", "1.0", "0", c, "2.0", "1.0"], 10), &
      "*MAT_026", fixed([character(len=8) :: "7", "1.0e-10", "70000.", "0.3", "300.", "0.2"], 10), &
      fixed([character(len=8) :: "8", c, c, c, c, c, c, c], 10), &
      fixed([character(len=8) :: "1000.", "0.0", "500.", "200.", "200.", "200.", "2"], 10), &
      fixed([character(len=8) :: c, c, c, "1.0", "0.0", "0.0"], 10), &
      fixed([character(len=8) :: "2.0", "0.0", "0.0"], 10)]), [character(len=140) :: &
      "@:25: *MAT_126: field RO: density must be > 0, found 0.0", &
      "@:25: *MAT_126: field VF: relative volume at full compaction must lie in (0, 1], found 1.5", &
      "@:27: *MAT_126: field AOPT: material axes option 3.0 is not available", &
      "@:28: *MAT_126: field PRU: must be blank or 0, found 1.0", &
      "@:29: *MAT_126: field TSEF: must be blank or 0, found 0.5", &
      "@:26: *MAT_126: field LCA: curve 99 of material 5 is not defined", &
      "@:31: *MAT_LOW_DENSITY_FOAM: field LCID: a loading curve id > 0 is required", &
      "@:31: *MAT_LOW_DENSITY_FOAM: field HU: hysteretic unloading factor must lie in [0, 1], found 2.0", &
      "@:31: *MAT_LOW_DENSITY_FOAM: field BETA: must be blank or 0, found 1.0", &
      "@:35: *MAT_026: field EBBU: uncompacted modulus must be > 0, found 0.0", &
      "@:37: *MAT_026: field D1: AOPT 2 needs a vector d (D1 D2 D3) not parallel to a", &
      "@:34: *MAT_026: field LCA: curve 8 of material 7 is not defined"], message_lines=12)
  end subroutine test_crushable_material_errors

  ! ---------------------------------------------------------------- shells

  !> A valid shell-only deck in fixed format. Line numbers:
  !>  1 *KEYWORD  2 *CONTROL_TERMINATION  3 card  4 *NODE  5-10 nodes 1-6 (a 2 x 1 strip in
  !>  z = 0)  11 *ELEMENT_SHELL  12 quad 1 (N1-N4 1 2 3 4)  13 triangle 2 (2 5 6, N4 blank)
  !>  14 *PART  15 heading  16 card (PID 1 SECID 1 MID 1)  17 *SECTION_SHELL  18 card 1 (SECID 1)
  !>  19 card 2 (T1 1.5)  20 *MAT_ELASTIC  21 card ... then `extra` lines from 22, then *END.
  function plate_deck(extra) result(lines)
    character(len=*), intent(in), optional :: extra(:)
    character(len=line_length), allocatable :: lines(:)
    character(len=line_length) :: base(21)
    base(1) = "*KEYWORD"
    base(2) = "*CONTROL_TERMINATION"
    base(3) = fixed(["1.0"], 10)
    base(4) = "*NODE"
    base(5) = node_line(1, 0.0_wp, 0.0_wp, 0.0_wp)
    base(6) = node_line(2, 1.0_wp, 0.0_wp, 0.0_wp)
    base(7) = node_line(3, 1.0_wp, 1.0_wp, 0.0_wp)
    base(8) = node_line(4, 0.0_wp, 1.0_wp, 0.0_wp)
    base(9) = node_line(5, 2.0_wp, 0.0_wp, 0.0_wp)
    base(10) = node_line(6, 2.0_wp, 1.0_wp, 0.0_wp)
    base(11) = "*ELEMENT_SHELL"
    base(12) = fixed(["1", "1", "1", "2", "3", "4"], 8)
    base(13) = fixed(["2", "1", "2", "5", "6"], 8)
    base(14) = "*PART"
    base(15) = "the plate"
    base(16) = fixed(["1", "1", "1"], 10)
    base(17) = "*SECTION_SHELL"
    base(18) = fixed(["1"], 10)
    base(19) = fixed(["1.5"], 10)
    base(20) = "*MAT_ELASTIC"
    base(21) = fixed(["1     ", "7.8e-6", "210.0 ", "0.3   "], 10)
    if (present(extra)) then
      lines = [base, extra, text_line("*END")]
    else
      lines = [base, text_line("*END")]
    end if
  end function plate_deck

  !> The plate deck with line `number` replaced.
  function plate_replaced(number, text, extra) result(lines)
    integer, intent(in) :: number
    character(len=*), intent(in) :: text
    character(len=*), intent(in), optional :: extra(:)
    character(len=line_length), allocatable :: lines(:)
    lines = plate_deck(extra)
    lines(number) = text
  end function plate_replaced

  !> Shells of every form (fixed and comma cards, a triangle, *ELEMENT_SHELL_THICKNESS with a
  !> THIC left 0), sections with defaults and with every field, a *MAT_RIGID shell part, the
  !> rotations of *BOUNDARY_SPC_NODE/_SET and of *NODE RC, and a velocity generated on a
  !> shell part. No solid: a deck of shells alone is accepted.
  subroutine test_shells()
    type(model_t) :: model
    type(error_list_t) :: warnings
    integer :: k
    call read_good("shells.k", plate_replaced(9, trim(node_line(5, 2.0_wp, 0.0_wp, 0.0_wp))// &
      "       0       4", [character(len=line_length) :: &
      "*ELEMENT_SHELL_THICKNESS", &                                             ! 22
      fixed(["3", "2", "2", "5", "6", "3"], 8), &                               ! 23
      fixed(["0.5 ", "0.6 ", "0.0 ", "0.8 ", "30.0"], 16), &                    ! 24
      "*PART", "thick plate", "2,2,2", &                                        ! 25-27
      "*SECTION_SHELL_TITLE", "explicit", &                                     ! 28-29
      "2,2,0.8333,5,1,0,0,1", "1.0,1.1,1.2,1.3,0", &                           ! 30-31
      "*MAT_ELASTIC", "2,2.7e-6,70.0,0.33", &                                   ! 32-33
      "*MAT_RIGID", "3,7.8e-6,210.0,0.3", &                                     ! 34-35
      "*PART", "rigid", "3,1,3", &                                              ! 36-38
      "*NODE", trim(node_line(7, 3.0_wp, 0.0_wp, 0.0_wp)), &                   ! 39-40
      trim(node_line(8, 4.0_wp, 0.0_wp, 0.0_wp)), &
      trim(node_line(9, 4.0_wp, 1.0_wp, 0.0_wp)), &
      trim(node_line(10, 3.0_wp, 1.0_wp, 0.0_wp)), &                           ! 43
      "*ELEMENT_SHELL", "4,3,7,8,9,10", &                                       ! 44-45
      "*BOUNDARY_SPC_NODE", "1,0,1,1,1,1,1,1", "4,0,0,0,0,0,1,0", &            ! 46-48
      "*BOUNDARY_SPC_SET", "1,0,0,0,0,0,0,1", &                                 ! 49-50
      "*SET_NODE_LIST", "1", "6", &                                             ! 51-53
      "*INITIAL_VELOCITY_GENERATION", "2,2,0.0,0.0,0.0,3.0", "0,0,0,0,0,1"]), &
      model, warnings)
    if (.not. allocated(model%shell_ids)) return
    call check(suite, "shells: no solids", size(model%solid_ids) == 0 .and. &
               all(shape(model%solid_nodes) == [8, 0]))
    call check(suite, "shells: four shells", size(model%shell_ids) == 4 .and. &
               all(shape(model%shell_nodes) == [4, 4]) .and. &
               all(shape(model%shell_thickness) == [4, 4]))
    if (size(model%shell_ids) /= 4) return
    call check(suite, "shells: ids", all(model%shell_ids == [1, 2, 3, 4]))
    call check(suite, "shells: part indices", all(model%shell_part == [1, 1, 2, 3]))
    call check(suite, "shells: quad node indices", all(model%shell_nodes(:, 1) == [1, 2, 3, 4]))
    call check(suite, "shells: triangle repeats N3", all(model%shell_nodes(:, 2) == [2, 5, 6, 6]))
    call check(suite, "shells: _THICKNESS nodes", all(model%shell_nodes(:, 3) == [2, 5, 6, 3]))
    call check(suite, "shells: rigid part nodes", all(model%shell_nodes(:, 4) == [7, 8, 9, 10]))
    call check_close(suite, "shells: section T1 on all corners", model%shell_thickness(:, 1), &
                     [1.5_wp, 1.5_wp, 1.5_wp, 1.5_wp], thr=0.0_wp)
    call check_close(suite, "shells: triangle thickness", model%shell_thickness(:, 2), &
                     [1.5_wp, 1.5_wp, 1.5_wp, 1.5_wp], thr=0.0_wp)
    call check_close(suite, "shells: THIC, THIC3 0 takes the section's T3", &
                     model%shell_thickness(:, 3), [0.5_wp, 0.6_wp, 1.2_wp, 0.8_wp], thr=0.0_wp)
    call check(suite, "shells: two sections", size(model%sections) == 2)
    associate (section => model%sections(1))
      call check(suite, "section defaults: kind, ELFORM 2, NIP 2", section%kind == &
                 section_shell .and. section%element_formulation == 2 .and. &
                 section%integration_points == 2 .and. section%title == "")
      call check_close(suite, "section defaults: SHRF 1, T2-T4 = T1, NLOC 0", &
                       [section%shear_factor, section%thickness, section%reference_surface], &
                       [1.0_wp, 1.5_wp, 1.5_wp, 1.5_wp, 1.5_wp, 0.0_wp], thr=0.0_wp)
    end associate
    associate (section => model%sections(2))
      call check(suite, "section: title, kind, NIP 5", section%title == "explicit" .and. &
                 section%kind == section_shell .and. section%integration_points == 5 .and. &
                 section%id == 2)
      call check_close(suite, "section: SHRF, T1-T4", [section%shear_factor, section%thickness], &
                       [0.8333_wp, 1.0_wp, 1.1_wp, 1.2_wp, 1.3_wp], thr=0.0_wp)
    end associate
    call check(suite, "shells: parts", all([(model%parts(k)%section, k=1, 3)] == [1, 2, 1]) .and. &
               all([(model%parts(k)%material, k=1, 3)] == [1, 2, 3]))
    call check(suite, "shells: formulations", model%parts(1)%formulation == formulation_fe .and. &
               model%parts(3)%formulation == formulation_rigid)
    call check(suite, "shells: rigid shell part is a rigid body", size(model%rigid_bodies) == 1)
    if (size(model%rigid_bodies) == 1) call check(suite, "shells: rigid body nodes", &
      model%rigid_bodies(1)%part == 3 .and. all(model%rigid_bodies(1)%nodes == [7, 8, 9, 10]))
    call check(suite, "shells: four constrained nodes", size(model%spcs) == 4)
    if (size(model%spcs) == 4) then
      call check(suite, "spc: nodes", all(model%spcs%node == [1, 4, 5, 6]))
      call check(suite, "spc: node 1 all six", all(model%spcs(1)%fixed) .and. &
                 all(model%spcs(1)%fixed_rotation))
      call check(suite, "spc: node 4 DOFRY", .not. any(model%spcs(2)%fixed) .and. &
                 all(model%spcs(2)%fixed_rotation .eqv. [.false., .true., .false.]))
      call check(suite, "spc: node 5 RC 4 (x and y)", .not. any(model%spcs(3)%fixed) .and. &
                 all(model%spcs(3)%fixed_rotation .eqv. [.true., .true., .false.]))
      call check(suite, "spc: node set DOFRZ", .not. any(model%spcs(4)%fixed) .and. &
                 all(model%spcs(4)%fixed_rotation .eqv. [.false., .false., .true.]))
    end if
    call check_close(suite, "shells: velocity generated on a shell part", &
      reshape(model%initial_velocity(:, 1:6), [18]), [0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, &
      3.0_wp, 0.0_wp, 0.0_wp, 3.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 3.0_wp, 0.0_wp, &
      0.0_wp, 3.0_wp], thr=0.0_wp)
    call check(suite, "shells: no warnings", warnings%count == 0, warnings%text)
  end subroutine test_shells

  !> Rotations fixed on nodes of no shell (the cube's) are dropped with one warning per card
  !> (per *NODE block for RC), at the card that fixes them; shell nodes keep theirs. The solids
  !> and shells of one deck keep their own sections.
  subroutine test_shell_rotations_on_solids()
    type(model_t) :: model
    type(error_list_t) :: warnings
    call read_good("solid_rotations.k", cube_deck([character(len=line_length) :: &
      "*BOUNDARY_SPC_NODE", "1,0,1,0,0,0,1,0", &                                ! 24-25
      "*NODE", trim(node_line(9, 2.0_wp, 0.0_wp, 0.0_wp))//"       0       7", & ! 26-27
      trim(node_line(10, 2.0_wp, 1.0_wp, 0.0_wp))//"       0       1", &
      trim(node_line(11, 3.0_wp, 0.0_wp, 0.0_wp))//"       0       7", &       ! 29
      trim(node_line(12, 3.0_wp, 1.0_wp, 0.0_wp))//"       0       2", &
      "*BOUNDARY_SPC_SET", "1,0,0,0,0,1", &                                     ! 31-32
      "*SET_NODE_LIST", "1", "5,6", &
      "*ELEMENT_SHELL", "5,2,2,9,10,3", &
      "*PART", "plate", "2,2,1", &
      "*SECTION_SHELL", "2", "0.1", &
      "*BOUNDARY_SPC_NODE", "10,0,0,0,0,0,0,1"]), model, warnings)
    if (.not. allocated(model%spcs)) return
    call check(suite, "solid rotations: mixed mesh", size(model%solid_ids) == 1 .and. &
               size(model%shell_ids) == 1 .and. model%sections(model%parts(1)%section)%kind == &
               section_solid .and. model%sections(model%parts(2)%section)%kind == section_shell)
    call check(suite, "solid rotations: three constrained nodes", size(model%spcs) == 3)
    if (size(model%spcs) == 3) then
      call check(suite, "solid rotations: node 1 x only", model%spcs(1)%node == 1 .and. &
        all(model%spcs(1)%fixed .eqv. [.true., .false., .false.]) .and. &
        .not. any(model%spcs(1)%fixed_rotation))
      call check(suite, "solid rotations: shell node 9 keeps RC 7", &
        model%node_ids(model%spcs(2)%node) == 9 .and. .not. any(model%spcs(2)%fixed) .and. &
        all(model%spcs(2)%fixed_rotation))
      call check(suite, "solid rotations: shell node 10 keeps RC 1 and DOFRZ", &
        model%node_ids(model%spcs(3)%node) == 10 .and. &
        all(model%spcs(3)%fixed_rotation .eqv. [.true., .false., .true.]))
    end if
    call check(suite, "solid rotations: three warnings", warnings%count == 3, warnings%text)
    call check(suite, "solid rotations: DOFRY warned", index(warnings%text, &
      "solid_rotations.k:25: *BOUNDARY_SPC_NODE: field DOFRY: ignored: node 1 belongs to no "// &
      "shell (solid nodes have no rotations)") > 0, warnings%text)
    call check(suite, "solid rotations: RC warned once", index(warnings%text, &
      "solid_rotations.k:29: *NODE: field RC: ignored on node 11, which belongs to no shell "// &
      "(solid nodes have no rotations); 1 more node alike") > 0, warnings%text)
    call check(suite, "solid rotations: set warned", index(warnings%text, &
      "solid_rotations.k:32: *BOUNDARY_SPC_SET: field DOFRX: ignored: no node of set 1 "// &
      "belongs to a shell (solid nodes have no rotations)") > 0, warnings%text)
  end subroutine test_shell_rotations_on_solids

  !> Shell element cards and references: every problem at its card and field.
  subroutine test_shell_errors()
    character(len=8), parameter :: c = ""
    call read_bad("shell_part.k", plate_replaced(13, fixed(["2", "9", "2", "5", "6"], 8)), &
      [character(len=120) :: "@:13: *ELEMENT_SHELL: field PID: part 9 of shell 2 is not "// &
      "defined (no *PART with this PID)"], message_lines=1)
    call read_bad("shell_on_solid.k", plate_replaced(16, fixed(["1", "2", "1"], 10), &
      [character(len=line_length) :: "*SECTION_SOLID", "2,1"]), [character(len=300) :: &
      "@:12: *ELEMENT_SHELL: field PID: part 1 of shell 1 has solid section 2 "// &
      "(*SECTION_SOLID); shells need a *SECTION_SHELL section; 1 more element of this part "// &
      "is alike"], message_lines=1)
    call read_bad("solid_on_shell.k", replaced(19, fixed(["1", "5", "1"], 10), &
      [character(len=line_length) :: "*SECTION_SHELL", "5", "1.0"]), [character(len=300) :: &
      "@:16: *ELEMENT_SOLID: field PID: part 1 of solid element 1 has shell section 5 "// &
      "(*SECTION_SHELL); solid elements need a *SECTION_SOLID or *SECTION_SOLID_EFG section"], &
      message_lines=1)
    call read_bad("no_thickness.k", plate_replaced(19, fixed(["0.0"], 10)), &
      [character(len=300) :: "@:12: *ELEMENT_SHELL: field PID: shell 1 has no thickness: T1 "// &
      "of its section 1 is 0.0 and *ELEMENT_SHELL gives none (set T1 on card 2 of "// &
      "*SECTION_SHELL, or use *ELEMENT_SHELL_THICKNESS); 1 more shell of this part has none"], &
      message_lines=1)
    call read_bad("no_thic.k", plate_deck([character(len=line_length) :: &
      "*PART", "p2", "2,2,1", "*SECTION_SHELL", "2", "0.0", &                    ! 22-27
      "*ELEMENT_SHELL_THICKNESS", fixed(["3", "2", "2", "5", "6", "3"], 8), &  ! 28-29
      "0.5,0,0.5,0.5", &                                                        ! 30
      fixed(["4", "2", "2", "5", "6", "3"], 8), "-0.5"]), [character(len=300) :: &
      "@:30: *ELEMENT_SHELL_THICKNESS: field THIC2: shell 3 has no thickness at N2: THIC2 is "// &
      "blank or 0 and T2 of section 2 is 0.0; 1 more shell of this part has none", &
      "@:32: *ELEMENT_SHELL_THICKNESS: field THIC1: thickness must be >= 0 (0 or blank: the "// &
      "section's T1), found -0.5"], message_lines=2)
    call read_bad("thickness_card.k", plate_deck([character(len=line_length) :: &
      "*ELEMENT_SHELL_THICKNESS", fixed(["3", "1", "2", "5", "6", "3"], 8)]), &
      [character(len=300) :: "@:23: *ELEMENT_SHELL_THICKNESS: field THIC1: the thickness "// &
      "card (THIC1 THIC2 THIC3 THIC4 BETA) of shell 3 is missing"], message_lines=1)
    call read_bad("eight_nodes.k", plate_replaced(12, fixed(["1", "1", "1", "2", "3", "4", &
      "7"], 8), [character(len=line_length) :: "*ELEMENT_SHELL_THICKNESS", &
      fixed(["3", "1", "2", "5", "6", "3", "0", "0", "0", "8"], 8), "0.5", "0.5", &
      fixed(["4", "1", "2", "5", "6", "3"], 8), "0.5"]), [character(len=300) :: &
      "@:12: *ELEMENT_SHELL: field N5: 8-node shells are not available; 4-node shells and "// &
      "triangles leave N5-N8 blank, found 7", &
      "@:23: *ELEMENT_SHELL_THICKNESS: field N8: 8-node shells"], message_lines=2)
    call read_bad("shell_nodes.k", plate_replaced(12, fixed(["1", "1", "1", "2", "2", "4"], &
      8), [character(len=line_length) :: "*ELEMENT_SHELL", &
      fixed(["3", "1", "0", "2", "3"], 8), fixed([character(len=2) :: "4", "1", "1", "2", "3", "44"], 8), &
      fixed(["2", "1", "4", "3", "6"], 8)]), [character(len=300) :: &
      "@:12: *ELEMENT_SHELL: field N3: the shell repeats node 2 (N2 and N3); only N4 may "// &
      "repeat N3 (a triangle)", &
      "@:23: *ELEMENT_SHELL: field N1: node id must be > 0, found 0", &
      "@:24: *ELEMENT_SHELL: field N4: node 44 of shell 4 is not defined", &
      "@:25: *ELEMENT_SHELL: field EID: shell id 2 is defined twice (first at @:13)"], &
      message_lines=4)
    call read_bad("no_area.k", plate_replaced(13, fixed(["2", "1", "1", "2", "5"], 8)), &
      [character(len=300) :: "@:13: *ELEMENT_SHELL: field N1-N4: shell 2 of part 1 has no "// &
      "area: its corners coincide or lie on one line"], message_lines=1)
    call read_bad("shell_honeycomb.k", plate_replaced(16, fixed(["1", "1", "3"], 10), &
      [character(len=line_length) :: &
      "*MAT_026", fixed([character(len=8) :: "3", "6.0e-11", "70000.", "0.3", "300.", "0.2", &
      "0.0"], 10), &
      fixed([character(len=8) :: "11", c, c, "12", c, c, c, "10"], 10), &
      fixed([character(len=8) :: "1000.", "500.", "500.", "200.", "200.", "200."], 10), &
      fixed([character(len=8) :: "0.0"], 10), fixed([character(len=8) :: "0.0"], 10), &
      "*DEFINE_CURVE", fixed([character(len=8) :: "10"], 10), "0.0,1.0", "1.0,2.0", &
      "*DEFINE_CURVE", fixed([character(len=8) :: "11"], 10), "0.0,0.5", "1.0,0.7", &
      "*DEFINE_CURVE", fixed([character(len=8) :: "12"], 10), "0.0,0.0", "0.5,0.2"]), &
      [character(len=300) :: "@:16: *PART: field MID: part 1: material 3 has no shell "// &
      "(plane-stress) formulation; shell sections take *MAT_ELASTIC, *MAT_PLASTIC_KINEMATIC, "// &
      "*MAT_PIECEWISE_LINEAR_PLASTICITY, *MAT_NULL, *MAT_RIGID, *MAT_VISCOELASTIC, *MAT_BLATZ-KO_RUBBER or "// &
      "*MAT_MOONEY-RIVLIN_RUBBER"], message_lines=1)
    call read_bad("shell_static.k", plate_deck([character(len=line_length) :: &
      "*CONTROL_IMPLICIT_GENERAL", "1"]), [character(len=300) :: "@:12: *ELEMENT_SHELL: field "// &
      "EID: the linear static analysis (*CONTROL_IMPLICIT_GENERAL IMFLAG = 1) takes solid "// &
      "elements only; this deck has 2 shells, which run in explicit analyses only"], &
      message_lines=1)
    call read_bad("shell_spc_flag.k", plate_deck([character(len=line_length) :: &
      "*BOUNDARY_SPC_NODE", "1,0,0,0,0,1,2"]), [character(len=120) :: &
      "@:23: *BOUNDARY_SPC_NODE: field DOFRY: must be 0 (free) or 1 (fixed), found 2"], &
      message_lines=1)
  end subroutine test_shell_errors

  !> *SECTION_SHELL fields crashfree does not have, each named; cards after a rejected ICOMP 1
  !> (its angle cards) and after a rejected value are still read in their place.
  subroutine test_shell_section_errors()
    type(model_t) :: model
    type(error_list_t) :: warnings
    call read_bad("shell_elform.k", plate_replaced(18, "1,16"), [character(len=300) :: &
      "@:18: *SECTION_SHELL: field ELFORM: shell formulation 16 is not available; crashfree "// &
      "has ELFORM 2 (Belytschko-Tsay) and 41 (meshfree EFG shell)"], message_lines=1)
    call read_bad("shell_nip.k", plate_replaced(18, "1,2,0.8333,11"), [character(len=300) :: &
      "@:18: *SECTION_SHELL: field NIP: integration points through the thickness must be "// &
      "1-10 (0 or blank: 2), found 11"], message_lines=1)
    call read_bad("shell_nloc.k", plate_replaced(19, "1.5,,,,1.0"), [character(len=300) :: &
      "@:19: *SECTION_SHELL: field NLOC: reference surface offsets are not available: "// &
      "shells lie on their mid surface (NLOC 0 or blank), found 1.0"], message_lines=1)
    call read_bad("shell_marea.k", plate_replaced(19, "1.5,,,,,0.1"), [character(len=300) :: &
      "@:19: *SECTION_SHELL: field MAREA: non-structural mass per area is not available"], &
      message_lines=1)
    call read_bad("shell_rule.k", plate_replaced(18, "1,2,,,,1,,"), [character(len=300) :: &
      "@:18: *SECTION_SHELL: field QR/IRID: only Gauss integration through the thickness (0) "// &
      "is available; trapezoidal (1) and *INTEGRATION_SHELL rules (< 0) are not, found 1"], &
      message_lines=1)
    call read_bad("shell_icomp.k", plate_replaced(19, "1.5", [character(len=line_length) :: &
      "*SECTION_SHELL", "2,2,,3,,,1", "1.0", "0.0,45.0,90.0", "3,,,,", "2.0", &
      "*SECTION_SHELL", "4,2,,-1", "-1.0,,,,,,2"]), [character(len=300) :: &
      "@:23: *SECTION_SHELL: field ICOMP: composite layers with one material angle per "// &
      "integration point (ICOMP 1) are not available; leave ICOMP blank or 0", &
      "@:29: *SECTION_SHELL: field NIP: integration points through the thickness must be "// &
      "1-10 (0 or blank: 2), found -1", &
      "@:30: *SECTION_SHELL: field T1: thickness must be >= 0, found -1.0"], message_lines=3)
    call read_bad("shell_sections.k", plate_replaced(18, "1,2,-1.0,,,,2", &
      [character(len=line_length) :: "*SECTION_SHELL_TITLE", "last"]), [character(len=300) :: &
      "@:18: *SECTION_SHELL: field SHRF: shear factor must be > 0 (0 or blank: 1.0; 5/6 is "// &
      "usual), found -1.0", &
      "@:18: *SECTION_SHELL: field ICOMP: must be 0 (or 1, composite angles, which are not "// &
      "available), found 2", &
      "@:23: *SECTION_SHELL_TITLE: field SECID: card 1 (SECID ELFORM SHRF NIP PROPT QR/IRID "// &
      "ICOMP SETYP) is missing"], message_lines=3)
    call read_good("shell_warnings.k", plate_replaced(19, "1.5,,,,0,0,1,7"), model, warnings)
    call check(suite, "shell section: IDOF and EDGSET warned", warnings%count == 2 .and. &
      index(warnings%text, "shell_warnings.k:19: *SECTION_SHELL: field IDOF: ignored") > 0 .and. &
      index(warnings%text, "shell_warnings.k:19: *SECTION_SHELL: field EDGSET: ignored "// &
      "(seatbelt shells are not available)") > 0, warnings%text)
  end subroutine test_shell_section_errors

  !> The plate deck with its shell section given by `section` (lines 22 on: *SECTION_SHELL,
  !> card 1, card 2, the EFG card ...) instead of lines 17-19 (comments there).
  function plate_with_section(section) result(lines)
    character(len=*), intent(in) :: section(:)
    character(len=line_length), allocatable :: lines(:)
    lines = plate_deck(section)
    lines(17:19) = "$"
  end function plate_with_section

  !> *SECTION_SHELL ELFORM 41 and its EFG card DX DY ISPLINE IDILA IEBT IDIM: blank fields take
  !> DX = DY = 1.1 (LS-DYNA's default for the shell card), the cubic spline on a box, IDILA 0,
  !> IEBT 3, IDIM 1; the part becomes meshfree; the next section is read in place.
  subroutine test_efg_shell_sections()
    type(model_t) :: model
    type(error_list_t) :: warnings
    call read_good("efg_shell_defaults.k", plate_with_section([character(len=line_length) :: &
      "*SECTION_SHELL", "1,41,0.8333,3", "1.5", "", &                          ! 22-25
      "*SECTION_SHELL", "2,41", "1.0", "1.5,1.3,1,0,3,1", &                   ! 26-29
      "*SECTION_SHELL_TITLE", "disk", "3,41", "2.0", "1.4,0.0,2", &           ! 30-34
      "*SECTION_SHELL", "4", "1.0"]), model, warnings)                         ! 35-37
    if (.not. allocated(model%sections)) return
    if (size(model%sections) /= 4) then
      call check(suite, "efg shell: four sections", .false.)
      return
    end if
    associate (defaults => model%sections(1), given => model%sections(2), &
               disk => model%sections(3), fe => model%sections(4))
      call check(suite, "efg shell: ELFORM 41 kept", defaults%kind == section_shell .and. &
                 defaults%element_formulation == 41 .and. given%element_formulation == 41)
      call check_close(suite, "efg shell: blank DX DY are 1.1", defaults%support_scale(1:2), &
                       [1.1_wp, 1.1_wp], thr=0.0_wp)
      call check(suite, "efg shell: blank ISPLINE IDILA IEBT IDIM", &
                 defaults%kernel == kernel_cubic_box .and. defaults%dilation_basis == 0 .and. &
                 defaults%boundary_treatment == boundary_coupled .and. &
                 defaults%domain_integration == integration_local_boundary)
      call check_close(suite, "efg shell: the FE cards still read", &
                       [defaults%thickness(1), defaults%shear_factor], [1.5_wp, 0.8333_wp], &
                       thr=0.0_wp)
      call check(suite, "efg shell: NIP still read", defaults%integration_points == 3)
      call check_close(suite, "efg shell: DX DY given", given%support_scale(1:2), &
                       [1.5_wp, 1.3_wp], thr=0.0_wp)
      call check(suite, "efg shell: ISPLINE 1 is the quadratic spline", &
                 given%kernel == kernel_quadratic_box)
      call check(suite, "efg shell: ISPLINE 2 is the circle", disk%kernel == kernel_cubic_sphere &
                 .and. disk%title == "disk")
      call check_close(suite, "efg shell: circle DX, DY 0 is 1.1", disk%support_scale(1:2), &
                       [1.4_wp, 1.1_wp], thr=0.0_wp)
      call check(suite, "efg shell: the next section in place", fe%id == 4 .and. &
                 fe%element_formulation == 2)
    end associate
    call check(suite, "efg shell: no warning for blank fields", warnings%count == 0, warnings%text)
    call check(suite, "efg shell: the part is meshfree", model%parts(1)%section == 1 .and. &
               model%parts(1)%formulation == formulation_efg)

    call read_good("efg_shell_circle_dy.k", plate_with_section([character(len=line_length) :: &
      "*SECTION_SHELL", "1,41", "1.5", "1.4,1.2,2"]), model, warnings)
    call check(suite, "efg shell: DY of a circle warned", warnings%count == 1 .and. &
      index(warnings%text, "efg_shell_circle_dy.k:25: *SECTION_SHELL: field DY: ignored (a "// &
      "circular support (ISPLINE 2) has one radius, scaled by DX)") > 0, warnings%text)
  end subroutine test_efg_shell_sections

  !> Every value of the shell's EFG card that crashfree does not build is an error naming its
  !> field and line; ELFORM 42 is refused on card 1 and its EFG card read over.
  subroutine test_efg_shell_section_errors()
    call read_bad("efg_shell_values.k", plate_with_section([character(len=line_length) :: &
      "*SECTION_SHELL", "1,41", "1.5", "0.9,1.0,3,1,1,2", &                   ! 22-25
      "*SECTION_SHELL", "2,42", "1.5", "1.5,1.5", &                           ! 26-29
      "*SECTION_SHELL", "3,41", "1.5", ",,,2,0,0"]), [character(len=300) :: &    ! 30-33
      "@:25: *SECTION_SHELL: field DX: DX must be greater than 1: at 1.0 a vertex weight "// &
      "vanishes on the cell's far corner; found 0.9 (blank or 0 means 1.1)", &
      "@:25: *SECTION_SHELL: field DY: DY must be greater than 1", &
      "@:25: *SECTION_SHELL: field ISPLINE: must be 0 (cubic spline, box support), 1 "// &
      "(quadratic spline, box support) or 2 (cubic spline, circular support), found 3", &
      "@:25: *SECTION_SHELL: field IDILA: IDILA 1 (support size from the surrounding nodes) "// &
      "is not available", &
      "@:25: *SECTION_SHELL: field IEBT: essential boundary treatment 1 is not available for "// &
      "meshfree shells; crashfree has IEBT 3", &
      "@:25: *SECTION_SHELL: field IDIM: domain integration 2 is not available for meshfree "// &
      "shells; crashfree has IDIM 1", &
      "@:27: *SECTION_SHELL: field ELFORM: the global meshfree shell (ELFORM 42, LS-DYNA's "// &
      "EFG shell for metal forming) is not available; use ELFORM 41", &
      "@:33: *SECTION_SHELL: field IDILA: must be 0 (support size from the background "// &
      "elements), found 2", &
      "@:33: *SECTION_SHELL: field IEBT: essential boundary treatment 0 is not available for "// &
      "meshfree shells", "0 is not a default here: leave the field blank", &
      "@:33: *SECTION_SHELL: field IDIM: domain integration 0 is not available"], &
      message_lines=10)
    call read_bad("efg_shell_missing_card.k", [character(len=line_length) :: &
      plate_with_section([character(len=line_length) :: "*SECTION_SHELL", "1,41", "1.5"])], &
      [character(len=300) :: "@:24: *SECTION_SHELL: field DX: the EFG card (DX DY ISPLINE "// &
      "IDILA IEBT IDIM) of section 1 is missing"], message_lines=1)
  end subroutine test_efg_shell_section_errors

  ! ---------------------------------------------------------------- line table, keyword names

  !> Lines starting beyond byte 2**31 and 2**32 of a file keep their exact offsets, files and
  !> line numbers: a run of lines ends where the offset from its base would not fit in 32 bits,
  !> where a line is skipped (comments) and where the file changes.
  subroutine test_line_table_beyond_2_gib()
    type(line_table_t) :: table
    integer(int64), parameter :: gib = 2_int64**30
    integer(int64), parameter :: starts(9) = [0_int64, 81_int64, 2*gib - 10, 2*gib + 70, &
      4*gib + 3, 5*gib + 1, 100_int64, 181_int64, 9*gib]
    integer, parameter :: files(9) = [1, 1, 1, 1, 1, 1, 2, 2, 1]
    integer, parameter :: numbers(9) = [1, 2, 3, 4, 5, 9, 1, 2, 2000000000]
    logical :: added, exact
    integer :: k
    call start_table(table, 4)
    do k = 1, size(starts)
      call append_line(table, files(k), numbers(k), starts(k), added)
      if (.not. added) call check(suite, "line table: line added", .false.)
    end do
    exact = table%count == size(starts)
    do k = 1, size(starts)
      exact = exact .and. line_start(table, k) == starts(k) .and. line_file(table, k) == files(k) &
              .and. line_number(table, k) == numbers(k)
    end do
    call check(suite, "line table: offsets beyond 2 GiB, files and numbers exact", exact)
    ! runs: lines 1-3 | 4-5 (line 4 is more than 2**31 - 1 bytes after line 1, line 5 less
    ! after line 4) | 6 (line number 9 after 5) | 7-8 (file 2) | 9 (file 1 again)
    call check(suite, "line table: five runs", table%run_count == 5, &
               "found "//integer_text(table%run_count))
    call check(suite, "line table: 4 bytes per line", storage_size(table%offset)/8 == 4)
  end subroutine test_line_table_beyond_2_gib

  !> Typing slips get the keyword meant, options spelt right; real LS-DYNA keywords crashfree
  !> does not read get no far-fetched hint.
  subroutine test_keyword_suggestions()
    character(len=48), parameter :: typos(2, 24) = reshape([character(len=48) :: &
      "DATABASE_RCFORK", "DATABASE_RCFORC", &
      "MAT_RIGIDD", "MAT_RIGID", &
      "MAT_ELASTICK", "MAT_ELASTIC", &
      "ELEMNET_SOLID", "ELEMENT_SOLID", &
      "SECTION_SOILD", "SECTION_SOLID", &
      "CONTROL_TERMINATON", "CONTROL_TERMINATION", &
      "BOUNDARY_SPC_NODES", "BOUNDARY_SPC_NODE", &
      "SET_NODE_LIST_GENERAT", "SET_NODE_LIST_GENERATE", &
      "MAT_PIECEWISE_LINEAR_PLASTICTY", "MAT_PIECEWISE_LINEAR_PLASTICITY", &
      "SECTION_SOLID_TITEL", "SECTION_SOLID_TITLE", &
      "MAT_RIGIDD_TITLE", "MAT_RIGID_TITLE", &
      "CONTACT_AUTOMATIC_SURFACE_TO_SURFACE_IDD", "CONTACT_AUTOMATIC_SURFACE_TO_SURFACE_ID", &
      "RIGIDWALL_PLANAR_MOVNG_FORCES", "RIGIDWALL_PLANAR_MOVING_FORCES", &
      "DATABASE_GLSTATS", "DATABASE_GLSTAT", &
      "MAT_20", "MAT_020", &
      "NODES", "NODE", &
      "INCLDUE", "INCLUDE", &
      "PRAT", "PART", &
      "CONSTRAINED_NODAL_RIGID_BODDY", "CONSTRAINED_NODAL_RIGID_BODY", &
      "NODE_TITLE", "NODE", &
      "DATABASE_BINARY_D3THDT", "", &
      "CONTROL_OUTPUT", "", &
      "AIRBAG_SIMPLE_AIRBAG_MODEL", "", &
      "SECTION_BEAM", ""], [2, 24])
    character(len=:), allocatable :: suggestion, base
    integer :: k
    do k = 1, size(typos, 2)
      call suggest_known_keyword(trim(typos(1, k)), suggestion, base)
      call check(suite, "suggestion for *"//trim(typos(1, k)), suggestion == trim(typos(2, k)), &
                 "found '"//suggestion//"'")
    end do
  end subroutine test_keyword_suggestions

  !> Every name suggestions are taken from is read, with each of its options (the lexer's own
  !> keywords aside), so that the list cannot drift from the readers.
  subroutine test_known_keywords_are_read()
    character(len=:), allocatable :: name, options, option
    type(keyword_entry_t), allocatable :: table(:)
    type(keyword_t) :: keyword
    integer :: k, start, finish
    logical :: all_read
    character(len=:), allocatable :: missing
    all_read = .true.
    missing = ""
    table = keyword_table()
    do k = 1, known_keyword_count()
      call known_keyword(k, name, options)
      if (handled_by_lexer(name, table)) cycle
      keyword = identify_keyword(name, table)
      if (keyword%entry == keyword_unknown) missing = missing//" "//name
      start = 1
      do while (start <= len(options))
        finish = index(options(start:), " ")
        if (finish == 0) then
          finish = len(options)
        else
          finish = start + finish - 2
        end if
        option = options(start:finish)
        start = finish + 2
        keyword = identify_keyword(name//"_"//option, table)
        if (keyword%entry == keyword_unknown) missing = missing//" "//name//"_"//option
      end do
    end do
    all_read = len(missing) == 0
    call check(suite, "every known keyword name is read", all_read, "not read:"//missing)
  end subroutine test_known_keywords_are_read
end program test_deck
