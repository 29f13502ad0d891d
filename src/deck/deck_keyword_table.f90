!> The keyword table: one row per keyword crashfree knows, with its name (and another name for
!> it, *MAT_001 for *MAT_ELASTIC), the options it accepts, the input lists its definitions go
!> to, and its reader. Everything that asks "which keywords ..." reads it: identification of a
!> keyword block, the reader it is handed to, the sizes of the input lists, the "did you mean"
!> suggestions, --ignore-unknown, and the list of known keywords the unit tests check.
!>
!> Adding a keyword: write its reader (the interface `keyword_reader`) and add one row. A
!> material law's row comes from its row of the law table (material_laws):
!> `law_keyword(law_..., read_...)` takes the names *MAT_<name> and *MAT_<nnn> from there.
!>
!> The rows keep the order in which the names were added: on equal spelling distance the
!> earlier name is suggested. gfortran cannot hold procedure pointers in a named constant, so
!> `keyword_table()` builds the table on each call (about 100 rows; once per deck, and per unknown
!> keyword).
module deck_keyword_table
  use error_handling, only: error_list_t
  use material_laws, only: find_law, law_keyword_name, law_number_name, law_elastic, &
                           law_plastic_kinematic, law_honeycomb, law_modified_honeycomb, law_low_density_foam, &
                           law_rigid, law_piecewise_linear, law_null, law_spotweld, law_mooney_rivlin, &
                           law_blatz_ko, law_viscoelastic
  use deck_problems, only: problem_log_t
  use deck_lexer, only: deck_t
  use deck_keywords, only: keyword_t, keyword_unknown, read_options, suggest_keyword
  use deck_input, only: deck_input_t, list_none, list_nodes, list_solids, list_shells, list_parts, &
    list_sections, list_materials, list_hourglasses, list_curves, list_node_sets, list_part_sets, list_spcs, &
    list_motions, list_loads, list_velocities, list_walls, list_segment_sets, list_segment_loads, &
    list_rigid_materials, list_rigid_motions, list_nodal_rigid_bodies, list_element_masses, list_contacts, &
    list_count, list_boxes, list_frames, list_vectors, list_spot_welds, list_rigid_links, list_tied_contacts, list_beams, &
    list_body_loads
  use deck_nodes_elements, only: read_nodes, read_solid_elements, read_shell_elements, read_thick_shell_elements
  use deck_parts_sections, only: read_parts, read_solid_sections, read_efg_sections, read_shell_sections, &
    read_hourglasses
  use deck_materials, only: read_elastic_materials, read_plastic_kinematic_materials, read_honeycomb_materials, &
    read_modified_honeycomb_materials, read_low_density_foam_materials, read_piecewise_linear_materials, &
    read_mooney_rivlin_materials, read_blatz_ko_materials, read_viscoelastic_materials, &
    read_null_materials
  use deck_add_erosion, only: read_add_erosions
  use deck_sets_curves, only: read_node_set, read_generated_node_set, read_part_set, read_segment_set, read_curve, &
    read_generated_part_set, read_general_node_set, read_added_node_set, read_added_part_set
  use deck_boxes_frames, only: read_boxes, read_local_boxes, read_point_frames, read_node_frames, &
    read_vector_frames, read_vectors
  use deck_loads_bcs, only: read_node_spcs, read_set_spcs, read_node_motions, read_set_motions, read_node_loads, &
    read_set_loads, read_initial_velocities, read_initial_velocity_nodes, read_velocity_generations, &
    read_planar_walls, read_cylinder_walls, read_segment_loads, read_segment_set_loads, &
    read_nonuniform_segment_loads, read_body_loads
  use deck_controls, only: read_title, read_termination, read_time_step, read_hourglass_control, &
    read_bulk_viscosity, read_energy_control, read_implicit_general, read_implicit_solution, &
    read_unused_control, read_sensor_definition
  use deck_database, only: read_plot_output, read_glstat_output, read_matsum_output, read_nodout_output, &
    read_rwforc_output, read_rbdout_output, read_history_nodes, read_history_node_sets, read_d3dump_output, &
    read_runrsf_output, read_unused_output
  use deck_rigid_bodies, only: read_rigid_materials, read_rigid_motions, read_nodal_rigid_bodies, &
    read_element_masses, read_spot_welds, read_generalized_spot_welds, read_extra_nodes, read_extra_node_sets, &
    read_rigid_body_merges
  use deck_tied_contact, only: read_tied_nodes_to_surface, read_tied_nodes_to_surface_offset, &
    read_tied_surface_to_surface, read_tied_surface_to_surface_offset, read_tied_shell_edge_to_surface, &
    read_tied_shell_edge_to_surface_offset, read_spotweld_contacts
  use deck_beams, only: read_beam_elements, read_beam_elements_with_card, read_beam_sections, &
    read_spotweld_materials
  use deck_contact, only: read_nodes_to_surface_contacts, read_surface_to_surface_contacts, &
    read_single_surface_contacts, read_control_contact, read_rcforc
  implicit none
  private

  public :: keyword_entry_t, keyword_reader, keyword_table, identify_keyword, handled_by_lexer
  public :: suggest_known_keyword, known_keyword_count, known_keyword, list_capacity

  !> How the entries a keyword adds to its lists are bounded: one per data line (each
  !> definition takes at least one), one per block (keywords holding one definition), or one
  !> per two data lines of a block, rounded up (*ELEMENT_SHELL_THICKNESS).
  integer, parameter, public :: per_line = 1, per_block = 2, per_two_lines = 3

  !> What every keyword reader is: read block `block` of `deck`, a block of `keyword` (its row
  !> and options), into `input`; problems go to `log`, notes on fields read but not used to
  !> `warnings`. Not every reader needs every argument.
  abstract interface
    subroutine keyword_reader(deck, block, keyword, input, log, warnings)
      import :: deck_t, keyword_t, deck_input_t, problem_log_t, error_list_t
      type(deck_t), intent(in) :: deck
      integer, intent(in) :: block
      type(keyword_t), intent(in) :: keyword
      type(deck_input_t), intent(inout) :: input
      type(problem_log_t), intent(inout) :: log
      type(error_list_t), intent(inout) :: warnings
    end subroutine keyword_reader
  end interface

  !> One keyword.
  type :: keyword_entry_t
    character(len=48) :: name = ""       !< without the `*`
    character(len=48) :: alias = ""      !< another name of the same keyword ("" if none)
    character(len=36) :: options = ""    !< the options it accepts, blank-separated (any order)
    logical :: one_option = .false.      !< at most one of them (the contacts: _ID or _TITLE)
    !> The input lists its definitions go to (deck_input's list_...), and how many entries a
    !> block can add to them (per_line, per_block, per_two_lines).
    integer :: fills(2) = list_none
    integer :: entries = per_line
    !> Its reader; not associated for the keywords the lexer handles itself (*KEYWORD,
    !> *INCLUDE, *PARAMETER, *COMMENT, *END).
    procedure(keyword_reader), pointer, nopass :: reader => null()
  end type keyword_entry_t

contains

  !> The keyword table.
  function keyword_table() result(table)
    type(keyword_entry_t), allocatable :: table(:)
    table = [ &
      keyword_entry_t("TITLE", reader=read_title), &
      keyword_entry_t("NODE", fills=[list_nodes, list_none], reader=read_nodes), &
      keyword_entry_t("ELEMENT_SOLID", fills=[list_solids, list_none], reader=read_solid_elements), &
      keyword_entry_t("PART", options="CONTACT", fills=[list_parts, list_none], reader=read_parts), &
      keyword_entry_t("SECTION_SOLID", options="TITLE", fills=[list_sections, list_none], &
                      reader=read_solid_sections), &
      keyword_entry_t("SECTION_SOLID_EFG", options="TITLE", fills=[list_sections, list_none], &
                      reader=read_efg_sections), &
      law_keyword(law_elastic, read_elastic_materials), &
      law_keyword(law_plastic_kinematic, read_plastic_kinematic_materials), &
      keyword_entry_t("HOURGLASS", options="TITLE", fills=[list_hourglasses, list_none], reader=read_hourglasses), &
      keyword_entry_t("CONTROL_HOURGLASS", reader=read_hourglass_control), &
      keyword_entry_t("CONTROL_BULK_VISCOSITY", reader=read_bulk_viscosity), &
      keyword_entry_t("CONTROL_TERMINATION", reader=read_termination), &
      keyword_entry_t("CONTROL_TIMESTEP", reader=read_time_step), &
      keyword_entry_t("CONTROL_ENERGY", reader=read_energy_control), &
      ! read, not acted upon: LS-DYNA's bookkeeping, display and output files
      keyword_entry_t("CONTROL_PARALLEL", reader=read_unused_control), &
      keyword_entry_t("CONTROL_OUTPUT", reader=read_unused_control), &
      keyword_entry_t("CONTROL_CPU", reader=read_unused_control), &
      keyword_entry_t("CONTROL_SHELL", reader=read_unused_control), &
      keyword_entry_t("CONTROL_SOLID", reader=read_unused_control), &
      keyword_entry_t("CONTROL_ACCURACY", reader=read_unused_control), &
      keyword_entry_t("CONTROL_MPP_DECOMPOSITION_AUTOMATIC", reader=read_unused_control), &
      keyword_entry_t("CONTROL_MPP_DECOMPOSITION_METHOD", reader=read_unused_control), &
      keyword_entry_t("CONTROL_MPP_DECOMPOSITION_NUMPROC", reader=read_unused_control), &
      keyword_entry_t("CONTROL_MPP_DECOMPOSITION_SHOW", reader=read_unused_control), &
      keyword_entry_t("CONTROL_MPP_DECOMPOSITION_OUTDECOMP", reader=read_unused_control), &
      keyword_entry_t("CONTROL_MPP_IO_NOD3DUMP", reader=read_unused_control), &
      keyword_entry_t("CONTROL_MPP_IO_NODUMP", reader=read_unused_control), &
      keyword_entry_t("CONTROL_MPP_IO_NOFULL", reader=read_unused_control), &
      keyword_entry_t("DATABASE_EXTENT_BINARY", reader=read_unused_output), &
      keyword_entry_t("DATABASE_FORMAT", reader=read_unused_output), &
      keyword_entry_t("DATABASE_BINARY_INTFOR", reader=read_unused_output), &
      keyword_entry_t("DATABASE_BINARY_D3THDT", reader=read_unused_output), &
      keyword_entry_t("DATABASE_SPCFORC", reader=read_unused_output), &
      keyword_entry_t("DATABASE_SLEOUT", reader=read_unused_output), &
      keyword_entry_t("DATABASE_SECFORC", reader=read_unused_output), &
      keyword_entry_t("DATABASE_ELOUT", reader=read_unused_output), &
      keyword_entry_t("DATABASE_BNDOUT", reader=read_unused_output), &
      keyword_entry_t("DATABASE_NCFORC", reader=read_unused_output), &
      keyword_entry_t("DATABASE_SWFORC", reader=read_unused_output), &
      keyword_entry_t("DATABASE_JNTFORC", reader=read_unused_output), &
      keyword_entry_t("DATABASE_DEFORC", reader=read_unused_output), &
      keyword_entry_t("DATABASE_SBTOUT", reader=read_unused_output), &
      keyword_entry_t("DATABASE_NODFOR", reader=read_unused_output), &
      keyword_entry_t("DATABASE_ABSTAT", reader=read_unused_output), &
      keyword_entry_t("DATABASE_DEFGEO", reader=read_unused_output), &
      keyword_entry_t("DATABASE_BINARY_D3PROP", reader=read_unused_output), &
      keyword_entry_t("DATABASE_NODAL_FORCE_GROUP", reader=read_unused_output), &
      keyword_entry_t("DATABASE_CROSS_SECTION_PLANE", options="ID", reader=read_unused_output), &
      keyword_entry_t("DATABASE_CROSS_SECTION_SET", options="ID", reader=read_unused_output), &
      keyword_entry_t("DATABASE_HISTORY_SHELL", options="ID", reader=read_unused_output), &
      keyword_entry_t("DATABASE_HISTORY_SHELL_SET", reader=read_unused_output), &
      keyword_entry_t("DATABASE_HISTORY_SOLID", options="ID", reader=read_unused_output), &
      keyword_entry_t("DATABASE_HISTORY_SOLID_SET", reader=read_unused_output), &
      keyword_entry_t("SENSOR_DEFINE_NODE", options="SET", reader=read_sensor_definition), &
      keyword_entry_t("SENSOR_DEFINE_ELEMENT", options="SET", reader=read_sensor_definition), &
      keyword_entry_t("SENSOR_DEFINE_FORCE", reader=read_sensor_definition), &
      keyword_entry_t("SENSOR_DEFINE_FUNCTION", reader=read_sensor_definition), &
      keyword_entry_t("SENSOR_DEFINE_MISC", reader=read_sensor_definition), &
      keyword_entry_t("SENSOR_DEFINE_CALC-MATH", reader=read_sensor_definition), &
      keyword_entry_t("SENSOR_DEFINE_ANGLE", reader=read_sensor_definition), &
      keyword_entry_t("SET_NODE_LIST", options="TITLE", fills=[list_node_sets, list_none], entries=per_block, &
                      reader=read_node_set), &
      keyword_entry_t("SET_NODE_LIST_GENERATE", options="TITLE", fills=[list_node_sets, list_none], &
                      entries=per_block, reader=read_generated_node_set), &
      keyword_entry_t("SET_PART_LIST", options="TITLE", fills=[list_part_sets, list_none], entries=per_block, &
                      reader=read_part_set), &
      keyword_entry_t("BOUNDARY_SPC_NODE", options="ID", fills=[list_spcs, list_none], reader=read_node_spcs), &
      keyword_entry_t("BOUNDARY_SPC_SET", options="ID", fills=[list_spcs, list_none], reader=read_set_spcs), &
      keyword_entry_t("INITIAL_VELOCITY", fills=[list_velocities, list_none], reader=read_initial_velocities), &
      keyword_entry_t("INITIAL_VELOCITY_NODE", fills=[list_velocities, list_none], &
                      reader=read_initial_velocity_nodes), &
      keyword_entry_t("INITIAL_VELOCITY_GENERATION", fills=[list_velocities, list_none], &
                      reader=read_velocity_generations), &
      keyword_entry_t("DEFINE_CURVE", options="TITLE", fills=[list_curves, list_none], entries=per_block, &
                      reader=read_curve), &
      keyword_entry_t("BOUNDARY_PRESCRIBED_MOTION_NODE", options="ID", fills=[list_motions, list_none], &
                      reader=read_node_motions), &
      keyword_entry_t("BOUNDARY_PRESCRIBED_MOTION_SET", options="ID", fills=[list_motions, list_none], &
                      reader=read_set_motions), &
      keyword_entry_t("LOAD_NODE_POINT", fills=[list_loads, list_none], reader=read_node_loads), &
      keyword_entry_t("LOAD_NODE_SET", fills=[list_loads, list_none], reader=read_set_loads), &
      keyword_entry_t("LOAD_BODY_X", fills=[list_body_loads, list_none], entries=per_block, reader=read_body_loads), &
      keyword_entry_t("LOAD_BODY_Y", fills=[list_body_loads, list_none], entries=per_block, reader=read_body_loads), &
      keyword_entry_t("LOAD_BODY_Z", fills=[list_body_loads, list_none], entries=per_block, reader=read_body_loads), &
      keyword_entry_t("RIGIDWALL_PLANAR", options="FINITE MOVING FORCES DISPLAY ID", fills=[list_walls, list_none], &
                      reader=read_planar_walls), &
      keyword_entry_t("DATABASE_BINARY_D3PLOT", reader=read_plot_output), &
      keyword_entry_t("DATABASE_GLSTAT", reader=read_glstat_output), &
      keyword_entry_t("DATABASE_MATSUM", reader=read_matsum_output), &
      keyword_entry_t("DATABASE_NODOUT", reader=read_nodout_output), &
      keyword_entry_t("DATABASE_RWFORC", reader=read_rwforc_output), &
      keyword_entry_t("DATABASE_RBDOUT", reader=read_rbdout_output), &
      keyword_entry_t("DATABASE_HISTORY_NODE", options="ID", reader=read_history_nodes), &
      keyword_entry_t("DATABASE_HISTORY_NODE_SET", reader=read_history_node_sets), &
      keyword_entry_t("CONTROL_IMPLICIT_GENERAL", reader=read_implicit_general), &
      keyword_entry_t("CONTROL_IMPLICIT_SOLUTION", reader=read_implicit_solution), &
      keyword_entry_t("LOAD_SEGMENT", options="ID", fills=[list_segment_loads, list_none], &
                      reader=read_segment_loads), &
      keyword_entry_t("LOAD_SEGMENT_SET", options="ID", fills=[list_segment_loads, list_none], &
                      reader=read_segment_set_loads), &
      keyword_entry_t("LOAD_SEGMENT_NONUNIFORM", options="ID", fills=[list_segment_loads, list_none], &
                      reader=read_nonuniform_segment_loads), &
      keyword_entry_t("SET_SEGMENT", options="TITLE", fills=[list_segment_sets, list_none], entries=per_block, &
                      reader=read_segment_set), &
      law_keyword(law_honeycomb, read_honeycomb_materials), &
      law_keyword(law_modified_honeycomb, read_modified_honeycomb_materials), &
      law_keyword(law_low_density_foam, read_low_density_foam_materials), &
      law_keyword(law_mooney_rivlin, read_mooney_rivlin_materials), &
      law_keyword(law_blatz_ko, read_blatz_ko_materials), &
      law_keyword(law_viscoelastic, read_viscoelastic_materials), &
      keyword_entry_t("RIGIDWALL_GEOMETRIC_CYLINDER", options="MOTION DISPLAY ID", fills=[list_walls, list_none], &
                      reader=read_cylinder_walls), &
      keyword_entry_t("ELEMENT_SHELL", fills=[list_shells, list_none], reader=read_shell_elements), &
      keyword_entry_t("ELEMENT_SHELL_THICKNESS", fills=[list_shells, list_none], entries=per_two_lines, &
                      reader=read_thick_shell_elements), &
      keyword_entry_t("SECTION_SHELL", options="TITLE", fills=[list_sections, list_none], &
                      reader=read_shell_sections), &
      keyword_entry_t("ELEMENT_BEAM", fills=[list_beams, list_none], reader=read_beam_elements), &
      keyword_entry_t("ELEMENT_BEAM_THICKNESS", fills=[list_beams, list_none], entries=per_two_lines, &
                      reader=read_beam_elements_with_card), &
      keyword_entry_t("ELEMENT_BEAM_OFFSET", fills=[list_beams, list_none], entries=per_two_lines, &
                      reader=read_beam_elements_with_card), &
      keyword_entry_t("SECTION_BEAM", options="TITLE", fills=[list_sections, list_none], &
                      reader=read_beam_sections), &
      law_keyword(law_spotweld, read_spotweld_materials), &
      keyword_entry_t("DATABASE_BINARY_D3DUMP", reader=read_d3dump_output), &
      keyword_entry_t("DATABASE_BINARY_RUNRSF", reader=read_runrsf_output), &
      keyword_entry_t("KEYWORD"), keyword_entry_t("INCLUDE"), keyword_entry_t("PARAMETER"), &
      keyword_entry_t("COMMENT"), keyword_entry_t("END"), &
      law_keyword(law_rigid, read_rigid_materials, list_rigid_materials), &
      keyword_entry_t("BOUNDARY_PRESCRIBED_MOTION_RIGID", options="ID", fills=[list_rigid_motions, list_none], &
                      reader=read_rigid_motions), &
      keyword_entry_t("CONSTRAINED_NODAL_RIGID_BODY", options="TITLE", &
                      fills=[list_nodal_rigid_bodies, list_none], reader=read_nodal_rigid_bodies), &
      keyword_entry_t("CONSTRAINED_SPOTWELD", options="ID", fills=[list_spot_welds, list_none], &
                      reader=read_spot_welds), &
      keyword_entry_t("CONSTRAINED_GENERALIZED_WELD_SPOT", options="ID", fills=[list_spot_welds, list_none], &
                      reader=read_generalized_spot_welds), &
      keyword_entry_t("CONSTRAINED_EXTRA_NODES_NODE", fills=[list_rigid_links, list_none], reader=read_extra_nodes), &
      keyword_entry_t("CONSTRAINED_EXTRA_NODES_SET", fills=[list_rigid_links, list_none], &
                      reader=read_extra_node_sets), &
      keyword_entry_t("CONSTRAINED_RIGID_BODIES", fills=[list_rigid_links, list_none], reader=read_rigid_body_merges), &
      keyword_entry_t("CONTACT_TIED_NODES_TO_SURFACE", options="ID TITLE", one_option=.true., &
                      fills=[list_tied_contacts, list_none], reader=read_tied_nodes_to_surface), &
      keyword_entry_t("CONTACT_TIED_NODES_TO_SURFACE_OFFSET", options="ID TITLE", one_option=.true., &
                      fills=[list_tied_contacts, list_none], reader=read_tied_nodes_to_surface_offset), &
      keyword_entry_t("CONTACT_TIED_SURFACE_TO_SURFACE", options="ID TITLE", one_option=.true., &
                      fills=[list_tied_contacts, list_none], reader=read_tied_surface_to_surface), &
      keyword_entry_t("CONTACT_TIED_SURFACE_TO_SURFACE_OFFSET", options="ID TITLE", one_option=.true., &
                      fills=[list_tied_contacts, list_none], reader=read_tied_surface_to_surface_offset), &
      keyword_entry_t("CONTACT_TIED_SHELL_EDGE_TO_SURFACE", options="ID TITLE", one_option=.true., &
                      fills=[list_tied_contacts, list_none], reader=read_tied_shell_edge_to_surface), &
      keyword_entry_t("CONTACT_TIED_SHELL_EDGE_TO_SURFACE_OFFSET", options="ID TITLE", one_option=.true., &
                      fills=[list_tied_contacts, list_none], reader=read_tied_shell_edge_to_surface_offset), &
      keyword_entry_t("CONTACT_SPOTWELD", options="ID TITLE", one_option=.true., &
                      fills=[list_tied_contacts, list_none], reader=read_spotweld_contacts), &
      keyword_entry_t("ELEMENT_MASS", fills=[list_element_masses, list_none], reader=read_element_masses), &
      keyword_entry_t("CONTACT_AUTOMATIC_NODES_TO_SURFACE", options="ID TITLE", one_option=.true., &
                      fills=[list_contacts, list_none], entries=per_block, reader=read_nodes_to_surface_contacts), &
      keyword_entry_t("CONTACT_AUTOMATIC_SURFACE_TO_SURFACE", options="ID TITLE", one_option=.true., &
                      fills=[list_contacts, list_none], entries=per_block, reader=read_surface_to_surface_contacts), &
      keyword_entry_t("CONTACT_AUTOMATIC_SINGLE_SURFACE", options="ID TITLE", one_option=.true., &
                      fills=[list_contacts, list_none], entries=per_block, reader=read_single_surface_contacts), &
      ! the eroding contacts: the automatic ones already drop eroded elements' segments and
      ! expose the faces under them; their extra card (ISYM EROSOP IADJ) is read
      keyword_entry_t("CONTACT_ERODING_NODES_TO_SURFACE", options="ID TITLE", one_option=.true., &
                      fills=[list_contacts, list_none], entries=per_block, reader=read_nodes_to_surface_contacts), &
      keyword_entry_t("CONTACT_ERODING_SURFACE_TO_SURFACE", options="ID TITLE", one_option=.true., &
                      fills=[list_contacts, list_none], entries=per_block, reader=read_surface_to_surface_contacts), &
      keyword_entry_t("CONTACT_ERODING_SINGLE_SURFACE", options="ID TITLE", one_option=.true., &
                      fills=[list_contacts, list_none], entries=per_block, reader=read_single_surface_contacts), &
      keyword_entry_t("CONTROL_CONTACT", reader=read_control_contact), &
      keyword_entry_t("DATABASE_RCFORC", reader=read_rcforc), &
      law_keyword(law_piecewise_linear, read_piecewise_linear_materials), &
      law_keyword(law_null, read_null_materials), &
      keyword_entry_t("SET_NODE", options="TITLE", fills=[list_node_sets, list_none], entries=per_block, &
                      reader=read_node_set), &
      keyword_entry_t("SET_NODE_GENERAL", options="TITLE", fills=[list_node_sets, list_none], entries=per_block, &
                      reader=read_general_node_set), &
      keyword_entry_t("SET_NODE_ADD", options="TITLE", fills=[list_node_sets, list_none], entries=per_block, &
                      reader=read_added_node_set), &
      keyword_entry_t("SET_PART", options="TITLE", fills=[list_part_sets, list_none], entries=per_block, &
                      reader=read_part_set), &
      keyword_entry_t("SET_PART_LIST_GENERATE", options="TITLE", fills=[list_part_sets, list_none], &
                      entries=per_block, reader=read_generated_part_set), &
      keyword_entry_t("SET_PART_ADD", options="TITLE", fills=[list_part_sets, list_none], entries=per_block, &
                      reader=read_added_part_set), &
      keyword_entry_t("DEFINE_BOX", options="TITLE", fills=[list_boxes, list_none], reader=read_boxes), &
      keyword_entry_t("DEFINE_BOX_LOCAL", options="TITLE", fills=[list_boxes, list_none], reader=read_local_boxes), &
      keyword_entry_t("DEFINE_COORDINATE_SYSTEM", options="TITLE", fills=[list_frames, list_none], &
                      reader=read_point_frames), &
      keyword_entry_t("DEFINE_COORDINATE_NODES", options="TITLE", fills=[list_frames, list_none], &
                      reader=read_node_frames), &
      keyword_entry_t("DEFINE_COORDINATE_VECTOR", options="TITLE", fills=[list_frames, list_none], &
                      reader=read_vector_frames), &
      keyword_entry_t("DEFINE_VECTOR", options="TITLE", fills=[list_vectors, list_none], reader=read_vectors), &
      keyword_entry_t("MAT_ADD_EROSION", options="TITLE", reader=read_add_erosions)]
  end function keyword_table

  !> The row of material law `law` (a code of law_table): *MAT_<name>, also *MAT_<nnn>, with
  !> _TITLE; its materials go to the materials list (and to `also_fills`).
  function law_keyword(law, reader, also_fills) result(entry)
    integer, intent(in) :: law
    procedure(keyword_reader) :: reader
    integer, intent(in), optional :: also_fills
    type(keyword_entry_t) :: entry
    integer :: row
    row = find_law(law)
    entry%name = law_keyword_name(row)
    entry%alias = law_number_name(row)
    entry%options = "TITLE"
    entry%fills = list_none
    entry%fills(1) = list_materials
    if (present(also_fills)) entry%fills(2) = also_fills
    entry%reader => reader
  end function law_keyword

  !> Take keyword `name` (upper case, no `*`) apart against `table`; `entry` stays
  !> `keyword_unknown` when it is not a keyword crashfree reads (the lexer's own keywords
  !> included). The longest name whose options all fit wins, so *SET_NODE_LIST_GENERATE is not
  !> read as *SET_NODE_LIST with an option GENERATE.
  pure function identify_keyword(name, table) result(keyword)
    character(len=*), intent(in) :: name
    type(keyword_entry_t), intent(in) :: table(:)
    type(keyword_t) :: keyword
    type(keyword_t) :: candidate
    character(len=:), allocatable :: base
    integer :: k, which, best_length
    logical :: fits

    best_length = 0
    do k = 1, size(table)
      if (.not. associated(table(k)%reader)) cycle
      do which = 1, 2
        if (which == 1) then
          base = trim(table(k)%name)
        else
          base = trim(table(k)%alias)
          if (len(base) == 0) cycle
        end if
        if (name == base) then
          candidate = keyword_t(entry=k)
          fits = .true.
        else if (len(name) > len(base) + 1) then
          if (name(:len(base) + 1) /= base//"_") cycle
          call read_options(name(len(base) + 2:), trim(table(k)%options), table(k)%one_option, candidate, fits)
          candidate%entry = k
        else
          cycle
        end if
        if (fits .and. len(base) > best_length) then
          keyword = candidate
          best_length = len(base)
        end if
      end do
    end do
  end function identify_keyword

  !> True for the keywords the lexer handles itself (a row without reader).
  pure logical function handled_by_lexer(name, table)
    character(len=*), intent(in) :: name
    type(keyword_entry_t), intent(in) :: table(:)
    integer :: k
    handled_by_lexer = .false.
    do k = 1, size(table)
      if (associated(table(k)%reader)) cycle
      if (name == table(k)%name) handled_by_lexer = .true.
    end do
  end function handled_by_lexer

  !> A "did you mean" hint for the unknown keyword `name`: see suggest_keyword (deck_keywords),
  !> over every name and alias of the table.
  subroutine suggest_known_keyword(name, suggestion, base)
    character(len=*), intent(in) :: name
    character(len=:), allocatable, intent(out) :: suggestion, base
    character(len=48), allocatable :: names(:)
    character(len=36), allocatable :: options(:)
    call known_names(keyword_table(), names, options)
    call suggest_keyword(name, names, options, suggestion, base)
  end subroutine suggest_known_keyword

  !> Number of keyword names crashfree knows (those it reads and those the lexer handles),
  !> aliases included.
  integer function known_keyword_count()
    character(len=48), allocatable :: names(:)
    character(len=36), allocatable :: options(:)
    call known_names(keyword_table(), names, options)
    known_keyword_count = size(names)
  end function known_keyword_count

  !> Known keyword name `k` (1 .. known_keyword_count(), in table order, each name before its
  !> alias) and the options it accepts (blank-separated).
  subroutine known_keyword(k, name, options)
    integer, intent(in) :: k
    character(len=:), allocatable, intent(out) :: name, options
    character(len=48), allocatable :: names(:)
    character(len=36), allocatable :: all_options(:)
    call known_names(keyword_table(), names, all_options)
    name = trim(names(k))
    options = trim(all_options(k))
  end subroutine known_keyword

  !> Every name and alias of `table` in order, with its row's options.
  pure subroutine known_names(table, names, options)
    type(keyword_entry_t), intent(in) :: table(:)
    character(len=48), allocatable, intent(out) :: names(:)
    character(len=36), allocatable, intent(out) :: options(:)
    integer :: k, n
    allocate (names(size(table) + count(table%alias /= "")), options(size(table) + count(table%alias /= "")))
    n = 0
    do k = 1, size(table)
      n = n + 1
      names(n) = table(k)%name
      options(n) = table(k)%options
      if (len_trim(table(k)%alias) == 0) cycle
      n = n + 1
      names(n) = table(k)%alias
      options(n) = table(k)%options
    end do
  end subroutine known_names

  !> Upper bounds of the entries each input list gets from the blocks of `keywords` (rows of
  !> `table`), whose data lines are `lines`.
  pure function list_capacity(table, keywords, lines) result(capacity)
    type(keyword_entry_t), intent(in) :: table(:)
    type(keyword_t), intent(in) :: keywords(:)
    integer, intent(in) :: lines(:)
    integer :: capacity(list_count)
    integer :: block, k, added
    capacity = 0
    do block = 1, size(keywords)
      if (keywords(block)%entry == keyword_unknown) cycle
      associate (row => table(keywords(block)%entry))
        select case (row%entries)
        case (per_block)
          added = 1
        case (per_two_lines)
          added = (lines(block) + 1)/2
        case default
          added = lines(block)
        end select
        do k = 1, size(row%fills)
          if (row%fills(k) /= list_none) capacity(row%fills(k)) = capacity(row%fills(k)) + added
        end do
      end associate
    end do
  end function list_capacity
end module deck_keyword_table
