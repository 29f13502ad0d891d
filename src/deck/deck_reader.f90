!> The LS-DYNA keyword deck reader: `read_deck` turns a deck file (with its includes) into a
!> checked `model_t`, or into one error listing every problem found.
!>
!> Three passes, none of which aborts at the first problem:
!> 1. the lexer reads the files, follows *INCLUDE, collects *PARAMETER and cuts the text into
!>    keyword blocks (deck_lexer);
!> 2. one reader per keyword family turns cards into values, checking each field
!>    (deck_nodes_elements, deck_parts_sections, deck_materials, deck_sets_curves,
!>    deck_loads_bcs, deck_controls, deck_database);
!> 3. the cross-check resolves every id, expands sets and checks the mesh (deck_cross_check).
!> Pass 3 is skipped when a card could not be read at all, since its messages would only
!> repeat the first ones.
module deck_reader
  use error_handling, only: error_t, error_list_t, add_error
  use model, only: model_t
  use deck_problems, only: problem_log_t, report_problem, has_problems, problems_to_error, &
                           printable
  use deck_numbers, only: integer_text
  use deck_lexer, only: deck_t, load_deck, release_deck, line_location, check_files_unchanged
  use deck_keywords, only: keyword_t, identify_keyword, suggest_keyword, keyword_count, &
    keyword_unknown, keyword_title, keyword_node, keyword_element_solid, keyword_part, &
    keyword_section_solid, keyword_section_solid_efg, keyword_mat_elastic, &
    keyword_mat_plastic_kinematic, keyword_hourglass, keyword_control_hourglass, &
    keyword_control_bulk_viscosity, keyword_control_termination, keyword_control_timestep, &
    keyword_control_energy, keyword_set_node_list, keyword_set_node_list_generate, &
    keyword_set_part_list, keyword_spc_node, keyword_spc_set, keyword_initial_velocity, &
    keyword_initial_velocity_node, keyword_initial_velocity_generation, keyword_define_curve, &
    keyword_motion_node, keyword_motion_set, keyword_load_node_point, keyword_load_node_set, &
    keyword_rigidwall_planar, keyword_rigidwall_cylinder, keyword_d3plot, keyword_glstat, &
    keyword_matsum, keyword_nodout, &
    keyword_rwforc, keyword_history_node, keyword_history_node_set, &
    keyword_control_implicit_general, keyword_control_implicit_solution, keyword_load_segment, &
    keyword_load_segment_set, keyword_load_segment_nonuniform, keyword_set_segment, &
    keyword_mat_honeycomb, keyword_mat_modified_honeycomb, keyword_mat_low_density_foam
  use deck_keywords, only: keyword_element_shell, keyword_element_shell_thickness, &
    keyword_section_shell, keyword_d3dump, keyword_runrsf
  use deck_input, only: deck_input_t, prepare_input
  use deck_nodes_elements, only: read_nodes, read_solid_elements, read_shell_elements
  use deck_parts_sections, only: read_parts, read_solid_sections, read_hourglasses, &
    read_shell_sections
  use deck_materials, only: read_elastic_materials, read_plastic_kinematic_materials, &
    read_honeycomb_materials, read_low_density_foam_materials, identify_material_keyword, &
    read_material_block, material_keyword_first, material_keyword_last
  use deck_sets_curves, only: read_node_set, read_part_set, read_segment_set, read_curve
  use deck_loads_bcs, only: read_spcs, read_motions, read_loads, read_initial_velocities, &
    read_initial_velocity_nodes, read_velocity_generations, read_planar_walls, &
    read_cylinder_walls, &
    read_segment_loads, read_segment_set_loads, read_nonuniform_segment_loads
  use deck_controls, only: read_title, read_termination, read_time_step, &
    read_hourglass_control, read_bulk_viscosity, read_energy_control, read_implicit_general, &
    read_implicit_solution
  use deck_database, only: read_plot_output, read_history_output, read_history_nodes, read_dump_output
  use deck_cross_check, only: check_and_build
  use deck_rigid_bodies, only: identify_rigid_keyword, read_rigid_block, rigid_keyword_first, &
    rigid_keyword_last
  use deck_contact, only: identify_contact_keyword, read_contact_block, contact_keyword_first, &
    contact_keyword_last
  use deck_signature, only: deck_source_t
  implicit none
  private

  public :: read_deck, identify_any_keyword

contains

  !> Read the deck `path` into `model`. On any problem `error` is allocated and its message
  !> lists every problem found, one per line, as `file:line: *KEYWORD: field NAME: what is
  !> wrong`; `model` is then not usable. Unknown keywords are errors, or with
  !> `ignore_unknown` warnings in `warnings` (which also lists fields read but not used).
  !> `sources`: the files read (main deck and includes, in reading order), for a restart's check.
  subroutine read_deck(path, model, warnings, error, ignore_unknown, sources)
    character(len=*), intent(in) :: path
    type(model_t), intent(out) :: model
    type(error_list_t), intent(out) :: warnings
    type(error_t), allocatable, intent(out) :: error
    logical, intent(in) :: ignore_unknown
    type(deck_source_t), allocatable, intent(out), optional :: sources(:)
    type(deck_t) :: deck
    type(deck_input_t) :: input
    type(problem_log_t) :: log
    type(keyword_t), allocatable :: keywords(:)
    integer :: block, file

    call load_deck(path, deck, log, warnings)
    allocate (keywords(deck%block_count))
    do block = 1, deck%block_count
      keywords(block) = identify_any_keyword(deck%blocks(block)%name)
      if (keywords(block)%code == keyword_unknown) call report_unknown(deck, block, &
        ignore_unknown, log, warnings)
    end do
    call prepare_input_for(deck, keywords, input)
    do block = 1, deck%block_count
      call read_block(deck, block, keywords(block), input, log, warnings)
    end do
    call check_files_unchanged(deck, log)
    if (.not. log%unreadable) call check_and_build(deck, input, model, log, warnings)
    if (present(sources)) then
      allocate (sources(deck%file_count))
      do file = 1, deck%file_count
        sources(file)%path = deck%files(file)%path
        sources(file)%size = deck%files(file)%size
        sources(file)%modified = deck%files(file)%modified
      end do
    end if
    call release_deck(deck)
    if (has_problems(log)) then
      call problems_to_error(log, error)
      return
    end if
    model%deck_path = path
  end subroutine read_deck

  !> The keyword `name` (upper case, no `*`) with its options, whichever module reads it
  !> (code `keyword_unknown` when none does).
  pure function identify_any_keyword(name) result(keyword)
    character(len=*), intent(in) :: name
    type(keyword_t) :: keyword
    keyword = identify_keyword(name)
    if (keyword%code == keyword_unknown) keyword = identify_rigid_keyword(name)
    if (keyword%code == keyword_unknown) keyword = identify_contact_keyword(name)
    if (keyword%code == keyword_unknown) keyword = identify_material_keyword(name)
  end function identify_any_keyword

  !> An unknown keyword: an error (with a spelling hint), or a warning with `ignore_unknown`.
  subroutine report_unknown(deck, block, ignore_unknown, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    logical, intent(in) :: ignore_unknown
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    character(len=:), allocatable :: where, hint, suggestion, base, name
    type(keyword_t) :: suggested
    integer :: data_lines
    where = line_location(deck, deck%blocks(block)%keyword_line)//": *"//deck%blocks(block)%name
    data_lines = deck%blocks(block)%last_line - deck%blocks(block)%first_line + 1
    if (ignore_unknown) then
      call add_error(warnings, printable(where)//": unknown keyword skipped ("// &
                     integer_text(data_lines)//" data lines not read)")
      return
    end if
    name = deck%blocks(block)%name
    call suggest_keyword(name, suggestion, base)
    ! the options may not all go together (*CONTACT_..._ID_TITLE): then the name alone
    if (len(suggestion) > 0) then
      suggested = identify_any_keyword(suggestion)
      if (suggested%code == keyword_unknown .and. .not. handled_by_lexer(suggestion)) &
        suggestion = base
    end if
    hint = ""
    if (len(base) > 0 .and. len(name) > len(base) + 1) then
      if (name(:len(base) + 1) == base//"_" .and. suggestion == base) hint = &
        " (crashfree reads *"//base//", but not with "//name(len(base) + 1:)//")"
    end if
    if (len(hint) == 0 .and. len(suggestion) > 0) hint = " (did you mean *"//suggestion//"?)"
    call report_problem(log, where//": unknown keyword"//hint//"; crashfree reads the "// &
      "keywords listed in docs/keywords.md (--ignore-unknown skips the others)", unreadable=.true.)
  end subroutine report_unknown

  !> The keywords the lexer handles itself.
  pure logical function handled_by_lexer(name)
    character(len=*), intent(in) :: name
    select case (name)
    case ("KEYWORD", "INCLUDE", "PARAMETER", "COMMENT", "END")
      handled_by_lexer = .true.
    case default
      handled_by_lexer = .false.
    end select
  end function handled_by_lexer

  !> Size the input lists from the number of data lines of each keyword.
  subroutine prepare_input_for(deck, keywords, input)
    type(deck_t), intent(in) :: deck
    type(keyword_t), intent(in) :: keywords(:)
    type(deck_input_t), intent(out) :: input
    integer :: lines(keyword_count), blocks(keyword_count), block, code
    lines = 0
    blocks = 0
    do block = 1, deck%block_count
      code = keywords(block)%code
      if (code == keyword_unknown .or. code > keyword_count) cycle
      blocks(code) = blocks(code) + 1
      lines(code) = lines(code) + max(0, deck%blocks(block)%last_line - &
                                      deck%blocks(block)%first_line + 1)
    end do
    call prepare_input(lines, blocks, input)
  end subroutine prepare_input_for

  !> Hand one keyword block to its reader.
  subroutine read_block(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    select case (keyword%code)
    case (keyword_title)
      call read_title(deck, block, input)
    case (keyword_node)
      call read_nodes(deck, block, input, log)
    case (keyword_element_solid)
      call read_solid_elements(deck, block, input, log)
    case (keyword_element_shell, keyword_element_shell_thickness)
      call read_shell_elements(deck, block, keyword%code == keyword_element_shell_thickness, &
                               input, log)
    case (keyword_section_shell)
      call read_shell_sections(deck, block, keyword, input, log, warnings)
    case (keyword_part)
      call read_parts(deck, block, input, log, warnings)
    case (keyword_section_solid, keyword_section_solid_efg)
      call read_solid_sections(deck, block, keyword, keyword%code == keyword_section_solid_efg, &
                               input, log, warnings)
    case (keyword_mat_elastic)
      call read_elastic_materials(deck, block, keyword, input, log)
    case (keyword_mat_plastic_kinematic)
      call read_plastic_kinematic_materials(deck, block, keyword, input, log, warnings)
    case (keyword_mat_honeycomb, keyword_mat_modified_honeycomb)
      call read_honeycomb_materials(deck, block, keyword, keyword%code == keyword_mat_modified_honeycomb, &
                                    input, log)
    case (keyword_mat_low_density_foam)
      call read_low_density_foam_materials(deck, block, keyword, input, log, warnings)
    case (keyword_hourglass)
      call read_hourglasses(deck, block, keyword, input, log)
    case (keyword_control_hourglass)
      call read_hourglass_control(deck, block, input, log)
    case (keyword_control_bulk_viscosity)
      call read_bulk_viscosity(deck, block, input, log)
    case (keyword_control_termination)
      call read_termination(deck, block, input, log, warnings)
    case (keyword_control_timestep)
      call read_time_step(deck, block, input, log, warnings)
    case (keyword_control_energy)
      call read_energy_control(deck, block, input, log)
    case (keyword_control_implicit_general)
      call read_implicit_general(deck, block, input, log, warnings)
    case (keyword_control_implicit_solution)
      call read_implicit_solution(deck, block, input, log)
    case (keyword_set_node_list, keyword_set_node_list_generate)
      call read_node_set(deck, block, keyword, keyword%code == keyword_set_node_list_generate, &
                         input, log, warnings)
    case (keyword_set_part_list)
      call read_part_set(deck, block, keyword, input, log, warnings)
    case (keyword_set_segment)
      call read_segment_set(deck, block, keyword, input, log, warnings)
    case (keyword_define_curve)
      call read_curve(deck, block, keyword, input, log)
    case (keyword_spc_node, keyword_spc_set)
      call read_spcs(deck, block, keyword, keyword%code == keyword_spc_set, input, log)
    case (keyword_motion_node, keyword_motion_set)
      call read_motions(deck, block, keyword, keyword%code == keyword_motion_set, input, log)
    case (keyword_load_node_point, keyword_load_node_set)
      call read_loads(deck, block, keyword%code == keyword_load_node_set, input, log)
    case (keyword_load_segment)
      call read_segment_loads(deck, block, keyword, input, log)
    case (keyword_load_segment_set)
      call read_segment_set_loads(deck, block, keyword, input, log)
    case (keyword_load_segment_nonuniform)
      call read_nonuniform_segment_loads(deck, block, keyword, input, log, warnings)
    case (keyword_initial_velocity)
      call read_initial_velocities(deck, block, input, log, warnings)
    case (keyword_initial_velocity_node)
      call read_initial_velocity_nodes(deck, block, input, log, warnings)
    case (keyword_initial_velocity_generation)
      call read_velocity_generations(deck, block, input, log, warnings)
    case (keyword_rigidwall_planar)
      call read_planar_walls(deck, block, keyword, input, log, warnings)
    case (keyword_rigidwall_cylinder)
      call read_cylinder_walls(deck, block, keyword, input, log)
    case (keyword_d3plot)
      call read_plot_output(deck, block, input, log, warnings)
    case (keyword_glstat, keyword_matsum, keyword_nodout, keyword_rwforc)
      call read_history_output(deck, block, keyword%code, input, log, warnings)
    case (keyword_d3dump, keyword_runrsf)
      call read_dump_output(deck, block, keyword%code == keyword_runrsf, input, log, warnings)
    case (keyword_history_node, keyword_history_node_set)
      call read_history_nodes(deck, block, keyword, keyword%code == keyword_history_node_set, &
                              input, log)
    case (rigid_keyword_first:rigid_keyword_last)
      call read_rigid_block(deck, block, keyword, input, log, warnings)
    case (contact_keyword_first:contact_keyword_last)
      call read_contact_block(deck, block, keyword, input, log, warnings)
    case (material_keyword_first:material_keyword_last)
      call read_material_block(deck, block, keyword, input, log, warnings)
    end select
  end subroutine read_block
end module deck_reader
