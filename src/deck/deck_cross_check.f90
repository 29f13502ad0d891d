!> The consistency pass: every id resolved to an index, every list expanded per node, the
!> mesh checked, and every problem listed at once, each at the card holding the reference
!> (CalculiX's way: one run shows all mistakes, not one per run).
module deck_cross_check
  use kinds, only: wp
  use error_handling, only: error_list_t, add_error
  use model, only: model_t, spc_t, prescribed_motion_t, nodal_load_t, segment_load_t, &
                   rigid_wall_t, formulation_fe, formulation_efg, boundary_full_transformation, &
                   integration_gauss_conventional, local_spc_t, motion_along_vector, &
                   motion_only_along_vector
  use deck_problems, only: problem_log_t, report_problem, has_problems
  use deck_numbers, only: digit
  use text_format, only: integer_text, real_text
  use deck_lexer, only: deck_t, line_location
  use deck_fields, only: located_problem, located_warning
  use deck_add_erosion, only: apply_add_erosions, warn_parts_that_do_not_erode
  use deck_input, only: deck_input_t, set_input_t, velocity_input_t, velocity_by_set, &
                        velocity_by_node, velocity_generation, set_general, set_added, &
                        general_all, general_node, general_part, general_box, &
                        general_remove_node, general_remove_part, general_remove_box
  use deck_boxes_frames, only: resolve_frames, frame_axes, vector_direction, mark_nodes_in_box
  use deck_segments, only: segment_has_no_area
  use deck_id_index, only: id_index_t, build_id_index, find_id, lower_bound
  use deck_element_check, only: check_hexahedron, shape_inside_out, shape_flat, order_tetrahedra
  use deck_efg_cards, only: elform_efg
  use deck_material_curves, only: resolve_material_curves, apply_material_bulk_viscosity
  use deck_rigid_bodies, only: build_rigid_bodies
  use deck_contact, only: build_contacts
  use deck_tied_contact, only: build_tied_contacts
  use deck_beams, only: resolve_beams
  use deck_shell_check, only: check_element_sections, build_shell_thickness, &
                              check_static_shells
  implicit none
  private

  public :: check_and_build

  !> Sorted ids of everything that can be referenced.
  type :: deck_indices_t
    type(id_index_t) :: nodes, solids, shells, parts, sections, materials, hourglasses, curves
    type(id_index_t) :: node_sets, part_sets, segment_sets
  end type deck_indices_t

  character(len=1), parameter :: axis_names(3) = ["x", "y", "z"]

  !> The members (node or part indices) of one set while sets of sets are resolved.
  type :: member_list_t
    integer, allocatable :: items(:)
  end type member_list_t

contains

  !> Resolve and check everything in `input` and build the final `model`.
  subroutine check_and_build(deck, input, model, log, warnings)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(model_t), intent(out) :: model
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(deck_indices_t) :: indices
    logical :: mesh_resolved, shells_resolved

    call trim_to_counts(input)
    call index_definitions(deck, input, indices, log)
    call resolve_solids(deck, input, indices, mesh_resolved, log)
    call resolve_shells(deck, input, indices, shells_resolved, log)
    mesh_resolved = mesh_resolved .and. shells_resolved
    call resolve_parts(deck, input, indices, log)
    call resolve_beams(deck, input, indices%nodes, indices%parts, log, warnings)
    call check_element_sections(deck, input, log)
    call build_shell_thickness(deck, input, log)
    if (mesh_resolved) call order_tetrahedra(input)
    call check_static_shells(deck, input, log)
    call resolve_material_curves(deck, input%model, input%material_lines, input%part_lines, log)
    call resolve_frames(deck, input, indices%nodes, log)
    call apply_add_erosions(deck, input, indices%materials, log)
    call warn_parts_that_do_not_erode(deck, input, warnings)
    call resolve_node_sets(deck, input, indices, log)
    call resolve_part_sets(deck, input, indices, log)
    call resolve_segment_sets(deck, input, indices, log)
    call build_constraints(deck, input, indices, log, warnings)
    call build_motions(deck, input, indices, log)
    call build_loads(deck, input, indices, log)
    call build_segment_loads(deck, input, indices, log)
    call build_initial_velocities(deck, input, indices, log)
    call hold_local_initial_velocities(input)
    call check_static_conditions(deck, input, log)
    call build_walls(deck, input, indices, log)
    call build_rigid_bodies(deck, input, log)
    call build_contacts(deck, input, log)
    call build_tied_contacts(deck, input, log, warnings)
    call build_history_nodes(deck, input, indices, log, warnings)
    call check_mesh(deck, input, mesh_resolved, log)
    call check_controls(deck, input, log)
    call check_implicit_solution(deck, input, log, warnings)
    call set_effective_hourglass(input)
    call apply_material_bulk_viscosity(input%model)
    if (has_problems(log)) return
    model = input%model
  end subroutine check_and_build

  !> Cut every list to what was read (the readers sized them from line counts).
  subroutine trim_to_counts(input)
    type(deck_input_t), intent(inout) :: input
    associate (model => input%model)
      model%node_ids = model%node_ids(1:input%node_count)
      model%coordinates = model%coordinates(:, 1:input%node_count)
      model%solid_ids = model%solid_ids(1:input%solid_count)
      model%solid_part = model%solid_part(1:input%solid_count)
      model%solid_nodes = model%solid_nodes(:, 1:input%solid_count)
      model%shell_ids = model%shell_ids(1:input%shell_count)
      model%shell_part = model%shell_part(1:input%shell_count)
      model%shell_nodes = model%shell_nodes(:, 1:input%shell_count)
      model%shell_thickness = model%shell_thickness(:, 1:input%shell_count)
      model%parts = model%parts(1:input%part_count)
      model%sections = model%sections(1:input%section_count)
      model%materials = model%materials(1:input%material_count)
      model%hourglasses = model%hourglasses(1:input%hourglass_count)
      model%curves = model%curves(1:input%curve_count)
      if (.not. allocated(model%title)) model%title = ""
    end associate
  end subroutine trim_to_counts

  !> Sorted indices of all definitions; a duplicated id is reported at its second definition.
  subroutine index_definitions(deck, input, indices, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(in) :: input
    type(deck_indices_t), intent(out) :: indices
    type(problem_log_t), intent(inout) :: log
    integer :: k
    associate (model => input%model)
      call index_ids(deck, model%node_ids, input%node_lines, "NID", "node", indices%nodes, log)
      call index_ids(deck, model%solid_ids, input%solid_lines, "EID", "element", indices%solids, &
                     log)
      call index_ids(deck, model%shell_ids, input%shell_lines, "EID", "shell", indices%shells, &
                     log)
      call index_ids(deck, [(model%parts(k)%id, k=1, input%part_count)], input%part_lines, &
                     "PID", "part", indices%parts, log)
      call index_ids(deck, [(model%sections(k)%id, k=1, input%section_count)], &
                     input%section_lines, "SECID", "section", indices%sections, log)
      call index_ids(deck, [(model%materials(k)%id, k=1, input%material_count)], &
                     input%material_lines, "MID", "material", indices%materials, log)
      call index_ids(deck, [(model%hourglasses(k)%id, k=1, input%hourglass_count)], &
                     input%hourglass_lines, "HGID", "hourglass", indices%hourglasses, log)
      call index_ids(deck, [(model%curves(k)%id, k=1, input%curve_count)], input%curve_lines, &
                     "LCID", "curve", indices%curves, log)
    end associate
    call index_ids(deck, [(input%node_sets(k)%id, k=1, input%node_set_count)], &
                   [(input%node_sets(k)%line, k=1, input%node_set_count)], "SID", "node set", &
                   indices%node_sets, log)
    call index_ids(deck, [(input%part_sets(k)%id, k=1, input%part_set_count)], &
                   [(input%part_sets(k)%line, k=1, input%part_set_count)], "SID", "part set", &
                   indices%part_sets, log)
    call index_ids(deck, [(input%segment_sets(k)%id, k=1, input%segment_set_count)], &
                   [(input%segment_sets(k)%line, k=1, input%segment_set_count)], "SID", &
                   "segment set", indices%segment_sets, log)
  end subroutine index_definitions

  subroutine index_ids(deck, ids, lines, field, noun, index, log)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: ids(:), lines(:)
    character(len=*), intent(in) :: field, noun
    type(id_index_t), intent(out) :: index
    type(problem_log_t), intent(inout) :: log
    integer :: k, first
    call build_id_index(ids, index)
    first = 1
    do k = 2, size(index%ids)
      if (index%ids(k) /= index%ids(k - 1)) then
        first = k
      else if (index%ids(k) > 0) then
        call located_problem(deck, log, lines(index%positions(k)), field, noun//" id "// &
          integer_text(index%ids(k))//" is defined twice (first at "// &
          line_location(deck, lines(index%positions(first)))//")")
      end if
    end do
  end subroutine index_ids

  !> Element part ids and node ids to indices.
  subroutine resolve_solids(deck, input, indices, resolved, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(deck_indices_t), intent(in) :: indices
    logical, intent(out) :: resolved
    type(problem_log_t), intent(inout) :: log
    integer, allocatable :: unknown_part(:)
    integer :: element, corner, index, missing
    resolved = .true.
    allocate (unknown_part(input%solid_count))
    missing = 0
    associate (model => input%model)
      do element = 1, input%solid_count
        index = find_id(indices%parts, model%solid_part(element))
        if (index == 0) then
          missing = missing + 1
          unknown_part(missing) = element
        end if
        if (index > 0) model%solid_part(element) = index
        do corner = 1, 8
          index = find_id(indices%nodes, model%solid_nodes(corner, element))
          if (index == 0) then
            call located_problem(deck, log, input%solid_node_lines(element), &
              "N"//achar(iachar("0") + corner), "node "// &
              integer_text(model%solid_nodes(corner, element))//" of element "// &
              integer_text(model%solid_ids(element))//" is not defined")
            resolved = .false.
          end if
          model%solid_nodes(corner, element) = index
        end do
      end do
      call report_unknown_parts(deck, model%solid_part, model%solid_ids, input%solid_lines, &
                                unknown_part(1:missing), "element", log)
      model%solid_part(unknown_part(1:missing)) = 0
    end associate
  end subroutine resolve_solids

  !> Shell part ids and node ids to indices. Node ids <= 0 were reported by the reader.
  subroutine resolve_shells(deck, input, indices, resolved, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(deck_indices_t), intent(in) :: indices
    logical, intent(out) :: resolved
    type(problem_log_t), intent(inout) :: log
    integer, allocatable :: unknown_part(:)
    integer :: element, corner, index, missing
    logical :: triangle
    resolved = .true.
    allocate (unknown_part(input%shell_count))
    missing = 0
    associate (model => input%model)
      do element = 1, input%shell_count
        index = find_id(indices%parts, model%shell_part(element))
        if (index == 0) then
          missing = missing + 1
          unknown_part(missing) = element
        end if
        if (index > 0) model%shell_part(element) = index
        ! (a triangle's N4 repeats N3, whose id is reported once)
        triangle = model%shell_nodes(4, element) == model%shell_nodes(3, element)
        do corner = 1, 4
          index = 0
          if (model%shell_nodes(corner, element) > 0) &
            index = find_id(indices%nodes, model%shell_nodes(corner, element))
          if (index == 0) then
            resolved = .false.
            if (model%shell_nodes(corner, element) > 0 .and. .not. (corner == 4 .and. triangle)) &
              call located_problem(deck, log, input%shell_lines(element), "N"//digit(corner), &
                "node "//integer_text(model%shell_nodes(corner, element))//" of shell "// &
                integer_text(model%shell_ids(element))//" is not defined")
          end if
          model%shell_nodes(corner, element) = index
        end do
      end do
      call report_unknown_parts(deck, model%shell_part, model%shell_ids, input%shell_lines, &
                                unknown_part(1:missing), "shell", log)
      model%shell_part(unknown_part(1:missing)) = 0
    end associate
  end subroutine resolve_shells

  !> One message per undefined part id, at its first element, with the number of elements
  !> naming it (a mesh include without its *PART would otherwise fill the report). `parts`,
  !> `ids` and `lines` are the part ids, element ids and cards of all elements of one kind
  !> (`noun`: "element", "shell"), `elements` those whose part is undefined.
  subroutine report_unknown_parts(deck, parts, ids, lines, elements, noun, log)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: parts(:), ids(:), lines(:), elements(:)
    character(len=*), intent(in) :: noun
    type(problem_log_t), intent(inout) :: log
    type(id_index_t) :: by_part
    integer :: k, first, element
    character(len=:), allocatable :: others
    call build_id_index(parts(elements), by_part)
    first = 1
    do k = 1, size(elements)
      if (k < size(elements)) then
        if (by_part%ids(k + 1) == by_part%ids(k)) cycle
      end if
      element = elements(by_part%positions(first))
      others = ""
      if (k - first == 1) others = "; 1 more element names it"
      if (k - first > 1) others = "; "//integer_text(k - first)//" more elements name it"
      call located_problem(deck, log, lines(element), "PID", "part "// &
        integer_text(parts(element))//" of "//noun//" "//integer_text(ids(element))// &
        " is not defined (no *PART with this PID)"//others)
      first = k + 1
    end do
  end subroutine report_unknown_parts

  !> Part -> section, material and hourglass indices, and the part's formulation from its
  !> section (ELFORM 41: EFG, otherwise finite elements).
  subroutine resolve_parts(deck, input, indices, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(deck_indices_t), intent(in) :: indices
    type(problem_log_t), intent(inout) :: log
    integer :: k, line
    character(len=:), allocatable :: part_name
    do k = 1, input%part_count
      associate (part => input%model%parts(k))
        line = input%part_lines(k)
        part_name = "part "//integer_text(part%id)
        if (part%section_id == 0) then
          call located_problem(deck, log, line, "SECID", part_name//" has no section (SECID "// &
                               "is blank or 0)")
        else
          part%section = find_id(indices%sections, part%section_id)
          if (part%section == 0) call located_problem(deck, log, line, "SECID", "section "// &
            integer_text(part%section_id)//" of "//part_name//" is not defined")
        end if
        part%formulation = formulation_fe
        if (part%section > 0) then
          if (input%model%sections(part%section)%element_formulation == elform_efg) &
            part%formulation = formulation_efg
          ! the verification variants of Table 1 exist in the linear static analysis only
          if (part%formulation == formulation_efg .and. .not. input%model%implicit_static) then
            associate (section => input%model%sections(part%section))
              if (section%boundary_treatment == boundary_full_transformation) &
                call located_problem(deck, log, line, "SECID", "section "//integer_text(section%id)// &
                  " of "//part_name//" has IEBT = 1 (full transformation), a verification variant of the "// &
                  "linear static analysis (*CONTROL_IMPLICIT_GENERAL IMFLAG 1); explicit runs need IEBT = 3")
              if (section%domain_integration == integration_gauss_conventional) &
                call located_problem(deck, log, line, "SECID", "section "//integer_text(section%id)// &
                  " of "//part_name//" has IDIM = 4 (conventional EFG), a verification variant of the "// &
                  "linear static analysis (*CONTROL_IMPLICIT_GENERAL IMFLAG 1); explicit runs use IDIM 1 or 2")
            end associate
          end if
        end if
        if (part%material_id == 0) then
          call located_problem(deck, log, line, "MID", part_name//" has no material (MID is "// &
                               "blank or 0)")
        else
          part%material = find_id(indices%materials, part%material_id)
          if (part%material == 0) call located_problem(deck, log, line, "MID", "material "// &
            integer_text(part%material_id)//" of "//part_name//" is not defined")
        end if
        if (part%hourglass_id > 0) then
          part%hourglass = find_id(indices%hourglasses, part%hourglass_id)
          if (part%hourglass == 0) call located_problem(deck, log, line, "HGID", "hourglass "// &
            integer_text(part%hourglass_id)//" of "//part_name//" is not defined (no "// &
            "*HOURGLASS with this HGID)")
        end if
      end associate
    end do
  end subroutine resolve_parts

  !> Node set members (ids, ranges or *SET_NODE_GENERAL operations) to node indices, each node
  !> once; then the sets of sets (*SET_NODE_ADD), whatever their order in the deck.
  subroutine resolve_node_sets(deck, input, indices, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(deck_indices_t), intent(in) :: indices
    type(problem_log_t), intent(inout) :: log
    integer, allocatable :: seen(:), members(:)
    type(member_list_t), allocatable :: lists(:)
    integer :: set, count
    allocate (seen(input%node_count), input%model%node_sets(input%node_set_count), &
              lists(input%node_set_count))
    seen = 0
    do set = 1, input%node_set_count
      associate (given => input%node_sets(set))
        input%model%node_sets(set)%id = given%id
        input%model%node_sets(set)%title = given%title
        if (given%kind == set_added) cycle
        if (given%kind == set_general) then
          call general_members(deck, input, indices, given, members, count, log)
        else if (given%generated) then
          call generate_members(deck, given, indices%nodes, "node", set, seen, members, count, log)
        else
          call list_members(deck, given, indices%nodes, "node", set, seen, members, count, log)
        end if
        lists(set)%items = members(1:count)
      end associate
    end do
    call resolve_added_sets(deck, input%node_sets(1:input%node_set_count), indices%node_sets, &
                            input%node_count, "node", lists, log)
    do set = 1, input%node_set_count
      input%model%node_sets(set)%nodes = lists(set)%items
    end do
  end subroutine resolve_node_sets

  !> Part set members (ids or ranges) to part indices, each part once; then the sets of sets
  !> (*SET_PART_ADD).
  subroutine resolve_part_sets(deck, input, indices, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(deck_indices_t), intent(in) :: indices
    type(problem_log_t), intent(inout) :: log
    integer, allocatable :: seen(:), members(:)
    type(member_list_t), allocatable :: lists(:)
    integer :: set, count
    allocate (seen(input%part_count), input%model%part_sets(input%part_set_count), &
              lists(input%part_set_count))
    seen = 0
    do set = 1, input%part_set_count
      associate (given => input%part_sets(set))
        input%model%part_sets(set)%id = given%id
        input%model%part_sets(set)%title = given%title
        if (given%kind == set_added) cycle
        if (given%generated) then
          call generate_members(deck, given, indices%parts, "part", set, seen, members, count, log)
        else
          call list_members(deck, given, indices%parts, "part", set, seen, members, count, log)
        end if
        lists(set)%items = members(1:count)
      end associate
    end do
    call resolve_added_sets(deck, input%part_sets(1:input%part_set_count), indices%part_sets, &
                            input%part_count, "part", lists, log)
    do set = 1, input%part_set_count
      input%model%part_sets(set)%parts = lists(set)%items
    end do
  end subroutine resolve_part_sets

  !> Sets of sets (kind set_added): the union of their sets' members in the order listed, each
  !> item once. A set is resolved once all its sets are, so the deck order does not matter;
  !> sets left over form a loop (a set that contains itself) and are reported.
  subroutine resolve_added_sets(deck, sets, set_index, item_count, noun, lists, log)
    type(deck_t), intent(in) :: deck
    type(set_input_t), intent(in) :: sets(:)
    type(id_index_t), intent(in) :: set_index
    integer, intent(in) :: item_count
    character(len=*), intent(in) :: noun
    type(member_list_t), intent(inout) :: lists(:)
    type(problem_log_t), intent(inout) :: log
    logical, allocatable :: done(:)
    integer, allocatable :: seen(:), members(:)
    integer :: k, j, position, count, item
    logical :: progress, ready

    allocate (done(size(sets)), seen(item_count), members(item_count))
    done = sets%kind /= set_added
    seen = 0
    ! undefined sets, reported once
    do k = 1, size(sets)
      if (done(k)) cycle
      do j = 1, sets(k)%members%count
        if (find_id(set_index, sets(k)%members%ids(j)) == 0) call located_problem(deck, log, &
          sets(k)%members%lines(j), "DSID"//integer_text(sets(k)%members%fields(j)), noun// &
          " set "//integer_text(sets(k)%members%ids(j))//" of set "//integer_text(sets(k)%id)// &
          " is not defined")
      end do
    end do
    progress = .true.
    do while (progress)
      progress = .false.
      do k = 1, size(sets)
        if (done(k)) cycle
        ready = .true.
        do j = 1, sets(k)%members%count
          position = find_id(set_index, sets(k)%members%ids(j))
          if (position > 0) ready = ready .and. done(position)
        end do
        if (.not. ready) cycle
        count = 0
        do j = 1, sets(k)%members%count
          position = find_id(set_index, sets(k)%members%ids(j))
          if (position == 0) cycle
          do item = 1, size(lists(position)%items)
            if (seen(lists(position)%items(item)) == k) cycle
            seen(lists(position)%items(item)) = k
            count = count + 1
            members(count) = lists(position)%items(item)
          end do
        end do
        lists(k)%items = members(1:count)
        done(k) = .true.
        progress = .true.
      end do
    end do
    do k = 1, size(sets)
      if (done(k)) cycle
      call located_problem(deck, log, sets(k)%line, "SID", noun//" set "// &
        integer_text(sets(k)%id)//" contains itself through its sets (a loop of *SET_"// &
        trim(merge("NODE", "PART", noun == "node"))//"_ADD)")
      allocate (lists(k)%items(0))
    end do
  end subroutine resolve_added_sets

  !> *SET_NODE_GENERAL: the operations in deck order on a mask of the nodes; members in node
  !> order.
  subroutine general_members(deck, input, indices, given, members, count, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(in) :: input
    type(deck_indices_t), intent(in) :: indices
    type(set_input_t), intent(in) :: given
    integer, allocatable, intent(out) :: members(:)
    integer, intent(out) :: count
    type(problem_log_t), intent(inout) :: log
    logical, allocatable :: chosen(:)
    integer :: operation, first, j, position, k
    logical :: add
    character(len=:), allocatable :: field

    allocate (chosen(input%node_count))
    chosen = .false.
    first = 0
    do operation = 1, given%operations%count
      add = given%operations%ids(operation) <= general_box
      if (given%operations%ids(operation) == general_all) chosen = .true.
      do j = first + 1, first + given%operations%fields(operation)
        field = "E"//integer_text(given%members%fields(j) - 1)
        select case (given%operations%ids(operation))
        case (general_node, general_remove_node)
          position = find_id(indices%nodes, given%members%ids(j))
          if (position == 0) then
            call located_problem(deck, log, given%members%lines(j), field, "node "// &
              integer_text(given%members%ids(j))//" of set "//integer_text(given%id)// &
              " is not defined")
          else
            chosen(position) = add
          end if
        case (general_part, general_remove_part)
          position = find_id(indices%parts, given%members%ids(j))
          if (position == 0) then
            call located_problem(deck, log, given%members%lines(j), field, "part "// &
              integer_text(given%members%ids(j))//" of set "//integer_text(given%id)// &
              " is not defined")
          else
            call mark_part_nodes(input, position, add, chosen)
          end if
        case (general_box, general_remove_box)
          if (.not. mark_nodes_in_box(deck, input, given%members%ids(j), &
                                      given%members%lines(j), field, add, chosen, log)) cycle
        end select
      end do
      first = first + given%operations%fields(operation)
    end do
    members = pack([(k, k=1, input%node_count)], chosen)
    count = size(members)
  end subroutine general_members

  !> Set `chosen` to `value` on the nodes of the solids, shells and beams of part `part` (an index).
  subroutine mark_part_nodes(input, part, value, chosen)
    type(deck_input_t), intent(in) :: input
    integer, intent(in) :: part
    logical, intent(in) :: value
    logical, intent(inout) :: chosen(:)
    integer :: element, k
    do element = 1, input%solid_count
      if (input%model%solid_part(element) /= part) cycle
      do k = 1, 8
        if (input%model%solid_nodes(k, element) > 0) chosen(input%model%solid_nodes(k, element)) = value
      end do
    end do
    do element = 1, input%shell_count
      if (input%model%shell_part(element) /= part) cycle
      do k = 1, 4
        if (input%model%shell_nodes(k, element) > 0) chosen(input%model%shell_nodes(k, element)) = value
      end do
    end do
    do element = 1, input%beam_count
      if (input%model%beam_part(element) /= part) cycle
      do k = 1, 2
        if (input%model%beam_nodes(k, element) > 0) chosen(input%model%beam_nodes(k, element)) = value
      end do
    end do
  end subroutine mark_part_nodes

  !> Segment set node ids to node indices. A segment with an undefined node or without area
  !> is reported at its line and marked unusable, so that loads on the set skip it.
  subroutine resolve_segment_sets(deck, input, indices, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(deck_indices_t), intent(in) :: indices
    type(problem_log_t), intent(inout) :: log
    integer :: set, segment
    do set = 1, input%segment_set_count
      associate (given => input%segment_sets(set))
        do segment = 1, given%count
          if (.not. given%usable(segment)) cycle
          given%usable(segment) = resolve_segment(deck, input%model%coordinates, indices, &
            given%lines(segment), given%nodes(:, segment), " of segment set "// &
            integer_text(given%id), log)
        end do
      end associate
    end do
  end subroutine resolve_segment_sets

  !> Node ids of one segment to indices (in place); a node not defined, or a segment without
  !> area, is reported at `line` and gives false. `owner` completes the message ("of segment
  !> set 3").
  logical function resolve_segment(deck, coordinates, indices, line, nodes, owner, log)
    type(deck_t), intent(in) :: deck
    real(wp), intent(in) :: coordinates(:, :)
    type(deck_indices_t), intent(in) :: indices
    integer, intent(in) :: line
    integer, intent(inout) :: nodes(4)
    character(len=*), intent(in) :: owner
    type(problem_log_t), intent(inout) :: log
    integer :: k, position(4)
    resolve_segment = .true.
    do k = 1, 4
      position(k) = find_id(indices%nodes, nodes(k))
      if (position(k) > 0 .or. (k == 4 .and. nodes(4) == nodes(3))) cycle
      call located_problem(deck, log, line, "N"//integer_text(k), "node "// &
        integer_text(nodes(k))//owner//" is not defined")
      resolve_segment = .false.
    end do
    if (.not. resolve_segment) return
    if (segment_has_no_area(coordinates(:, position))) then
      call located_problem(deck, log, line, "N1-N4", "the segment (nodes "// &
        integer_text(nodes(1))//" "//integer_text(nodes(2))//" "//integer_text(nodes(3))// &
        " "//integer_text(nodes(4))//")"//owner//" has no area: its corners coincide or lie "// &
        "on one line")
      resolve_segment = .false.
      return
    end if
    nodes = position
  end function resolve_segment

  !> Listed ids of a set to indices; `seen(i) == stamp` marks indices already taken.
  subroutine list_members(deck, given, index, noun, stamp, seen, members, count, log)
    type(deck_t), intent(in) :: deck
    type(set_input_t), intent(in) :: given
    type(id_index_t), intent(in) :: index
    character(len=*), intent(in) :: noun
    integer, intent(in) :: stamp
    integer, intent(inout) :: seen(:)
    integer, allocatable, intent(out) :: members(:)
    integer, intent(out) :: count
    type(problem_log_t), intent(inout) :: log
    integer :: k, position
    character(len=:), allocatable :: prefix
    allocate (members(given%members%count))
    count = 0
    prefix = merge("NID", "PID", noun == "node")
    do k = 1, given%members%count
      position = find_id(index, given%members%ids(k))
      if (position == 0) then
        call located_problem(deck, log, given%members%lines(k), prefix// &
          integer_text(given%members%fields(k)), noun//" "//integer_text(given%members%ids(k))// &
          " of set "//integer_text(given%id)//" is not defined")
      else if (seen(position) /= stamp) then
        seen(position) = stamp
        count = count + 1
        members(count) = position
      end if
    end do
  end subroutine list_members

  !> Ranges of a generated node (`noun` "node") or part set: every defined node (part) with an
  !> id in a range (LS-DYNA numbering may have gaps); a range that holds none is an error.
  subroutine generate_members(deck, given, index, noun, stamp, seen, members, count, log)
    type(deck_t), intent(in) :: deck
    type(set_input_t), intent(in) :: given
    type(id_index_t), intent(in) :: index
    character(len=*), intent(in) :: noun
    integer, intent(in) :: stamp
    integer, intent(inout) :: seen(:)
    integer, allocatable, intent(out) :: members(:)
    integer, intent(out) :: count
    type(problem_log_t), intent(inout) :: log
    integer :: range, k, first, last, found
    allocate (members(size(seen)))
    count = 0
    do range = 1, given%members%count/2
      first = given%members%ids(2*range - 1)
      last = given%members%ids(2*range)
      found = 0
      do k = lower_bound(index, first), size(index%ids)
        if (index%ids(k) > last) exit
        found = found + 1
        if (seen(index%positions(k)) == stamp) cycle
        seen(index%positions(k)) = stamp
        count = count + 1
        members(count) = index%positions(k)
      end do
      if (found == 0) call located_problem(deck, log, given%members%lines(2*range - 1), &
        trim(merge("B", "P", noun == "node"))//integer_text((given%members%fields(2*range - 1) + 1)/2)// &
        "BEG", "no "//noun//" has an "// &
        "id in "//integer_text(first)//"-"//integer_text(last)//" (set "// &
        integer_text(given%id)//")")
    end do
  end subroutine generate_members

  !> Node indices a condition applies to: one node, or a node set's members. False after
  !> reporting an undefined id.
  logical function target_nodes(deck, input, indices, target, is_set, line, nodes, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(in) :: input
    type(deck_indices_t), intent(in) :: indices
    integer, intent(in) :: target, line
    logical, intent(in) :: is_set
    integer, allocatable, intent(out) :: nodes(:)
    type(problem_log_t), intent(inout) :: log
    integer :: position
    target_nodes = .false.
    if (is_set) then
      position = find_id(indices%node_sets, target)
      if (position == 0) then
        call located_problem(deck, log, line, "NSID", "node set "//integer_text(target)// &
                             " is not defined (no *SET_NODE with this SID)")
        return
      end if
      nodes = input%model%node_sets(position)%nodes
    else
      position = find_id(indices%nodes, target)
      if (position == 0) then
        call located_problem(deck, log, line, "NID", "node "//integer_text(target)// &
                             " is not defined")
        return
      end if
      nodes = [position]
    end if
    target_nodes = .true.
  end function target_nodes

  !> Node set `id` as node indices, where 0 means every node (LS-DYNA's NSID = 0).
  logical function set_or_all(deck, input, indices, id, line, field, nodes, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(in) :: input
    type(deck_indices_t), intent(in) :: indices
    integer, intent(in) :: id, line
    character(len=*), intent(in) :: field
    integer, allocatable, intent(out) :: nodes(:)
    type(problem_log_t), intent(inout) :: log
    integer :: k, position
    set_or_all = .true.
    if (id == 0) then
      nodes = [(k, k=1, input%node_count)]
      return
    end if
    position = find_id(indices%node_sets, id)
    if (position == 0) then
      call located_problem(deck, log, line, field, "node set "//integer_text(id)// &
                           " is not defined (no *SET_NODE with this SID)")
      set_or_all = .false.
      allocate (nodes(0))
      return
    end if
    nodes = input%model%node_sets(position)%nodes
  end function set_or_all

  !> *BOUNDARY_SPC_* and *NODE TC / RC codes merged into one spc_t per constrained node.
  !> Rotations act on shell nodes only: a rotation fixed on a node of no shell is dropped with
  !> one warning per card (per *NODE block for RC codes, at the first such node).
  subroutine build_constraints(deck, input, indices, log, warnings)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(deck_indices_t), intent(in) :: indices
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    logical, allocatable :: fixed(:, :), on_shell(:)
    integer, allocatable :: nodes(:), local_count(:)
    real(wp), allocatable :: local_directions(:, :, :)
    real(wp) :: axes(3, 3)
    integer :: k, node, constrained, first, others, j
    character(len=:), allocatable :: more
    ! TC and RC codes: 1 x, 2 y, 3 z, 4 xy, 5 yz, 6 zx, 7 xyz
    logical, parameter :: by_code(3, 0:7) = reshape([.false., .false., .false., &
      .true., .false., .false., .false., .true., .false., .false., .false., .true., &
      .true., .true., .false., .false., .true., .true., .true., .false., .true., &
      .true., .true., .true.], [3, 8])
    character(len=5), parameter :: rotation_names(3) = ["DOFRX", "DOFRY", "DOFRZ"]
    character(len=*), parameter :: no_rotations = "solid nodes have no rotations"

    allocate (fixed(6, input%node_count), on_shell(input%node_count))
    on_shell = .false.
    do k = 1, input%shell_count
      do node = 1, 4
        if (input%model%shell_nodes(node, k) > 0) &
          on_shell(input%model%shell_nodes(node, k)) = .true.
      end do
    end do
    ! (beam nodes have rotations as shell nodes do)
    do k = 1, input%beam_count
      do node = 1, 2
        if (input%model%beam_nodes(node, k) > 0) on_shell(input%model%beam_nodes(node, k)) = .true.
      end do
    end do
    first = 0
    others = 0
    do node = 1, input%node_count
      fixed(1:3, node) = by_code(:, input%node_constraints(node))
      fixed(4:6, node) = by_code(:, input%node_rotation_constraints(node))
      if (.not. any(fixed(4:6, node)) .or. on_shell(node)) cycle
      if (first == 0) then
        first = node
      else
        others = others + 1
      end if
    end do
    if (first > 0) then
      more = ""
      if (others == 1) more = "; 1 more node alike"
      if (others > 1) more = "; "//integer_text(others)//" more nodes alike"
      call located_warning(deck, warnings, input%node_lines(first), "RC", "ignored on node "// &
        integer_text(input%model%node_ids(first))//", which belongs to no shell ("// &
        no_rotations//")"//more)
    end if
    ! directions held in local systems (CID), per node: allocated only when a CID is given
    if (any(input%spcs(1:input%spc_count)%frame_id /= 0)) then
      allocate (local_count(input%node_count), local_directions(3, 3, input%node_count))
    else
      allocate (local_count(0), local_directions(3, 3, 0))
    end if
    local_count = 0
    do k = 1, input%spc_count
      associate (spc => input%spcs(k))
        if (.not. target_nodes(deck, input, indices, spc%target, spc%is_set, spc%line, nodes, &
                               log)) cycle
        if (spc%frame_id /= 0) then
          ! the reader has refused rotations with a CID
          if (.not. frame_axes(deck, input, spc%frame_id, spc%line, "CID", axes, log)) cycle
          do node = 1, size(nodes)
            do j = 1, 3
              if (spc%fixed(j)) call add_direction(axes(:, j), local_count(nodes(node)), &
                                                   local_directions(:, :, nodes(node)))
            end do
          end do
          cycle
        end if
        do node = 1, size(nodes)
          fixed(1:3, nodes(node)) = fixed(1:3, nodes(node)) .or. spc%fixed
          fixed(4:6, nodes(node)) = fixed(4:6, nodes(node)) .or. spc%fixed_rotation
        end do
        if (.not. any(spc%fixed_rotation) .or. size(nodes) == 0) cycle
        if (any(on_shell(nodes))) cycle
        do first = 1, 3
          if (spc%fixed_rotation(first)) exit
        end do
        if (spc%is_set) then
          call located_warning(deck, warnings, spc%line, trim(rotation_names(first)), &
            "ignored: no node of set "//integer_text(spc%target)//" belongs to a shell ("// &
            no_rotations//")")
        else
          call located_warning(deck, warnings, spc%line, trim(rotation_names(first)), &
            "ignored: node "//integer_text(spc%target)//" belongs to no shell ("// &
            no_rotations//")")
        end if
      end associate
    end do
    do node = 1, input%node_count
      if (.not. on_shell(node)) fixed(4:6, node) = .false.
    end do
    call build_local_spcs(fixed, local_count, local_directions, input)
    allocate (input%model%spcs(count(any(fixed, dim=1))))
    constrained = 0
    do node = 1, input%node_count
      if (.not. any(fixed(:, node))) cycle
      constrained = constrained + 1
      input%model%spcs(constrained) = spc_t(node=node, fixed=fixed(1:3, node), &
                                            fixed_rotation=fixed(4:6, node))
    end do
  end subroutine build_constraints

  !> Add unit vector `direction` to the `count` orthonormal `directions` (Gram-Schmidt), unless
  !> it lies in their span already (relative tolerance 1e-9).
  pure subroutine add_direction(direction, count, directions)
    real(wp), intent(in) :: direction(3)
    integer, intent(inout) :: count
    real(wp), intent(inout) :: directions(3, 3)
    real(wp) :: rest(3)
    integer :: k
    rest = direction
    do k = 1, count
      rest = rest - dot_product(rest, directions(:, k))*directions(:, k)
    end do
    if (norm2(rest) <= 1.0e-9_wp .or. count == 3) return
    count = count + 1
    directions(:, count) = rest/norm2(rest)
  end subroutine add_direction

  !> model%local_spcs from the local directions of each node, with the node's global SPC axes
  !> put first; a node held in three independent directions is simply fixed in x, y and z.
  subroutine build_local_spcs(fixed, local_count, local_directions, input)
    logical, intent(inout) :: fixed(:, :)
    integer, intent(in) :: local_count(:)
    real(wp), intent(in) :: local_directions(:, :, :)
    type(deck_input_t), intent(inout) :: input
    type(local_spc_t), allocatable :: spcs(:)
    real(wp) :: unit(3, 3)
    integer :: node, j, held
    unit = 0.0_wp
    do j = 1, 3
      unit(j, j) = 1.0_wp
    end do
    allocate (spcs(count(local_count > 0)))
    held = 0
    do node = 1, size(local_count)
      if (local_count(node) == 0) cycle
      held = held + 1
      spcs(held) = local_spc_t(node=node)
      do j = 1, 3
        if (fixed(j, node)) call add_direction(unit(:, j), spcs(held)%count, spcs(held)%directions)
      end do
      do j = 1, local_count(node)
        call add_direction(local_directions(:, j, node), spcs(held)%count, spcs(held)%directions)
      end do
      if (spcs(held)%count == 3) then
        fixed(1:3, node) = .true.
        held = held - 1
      end if
    end do
    input%model%local_spcs = spcs(1:held)
  end subroutine build_local_spcs

  !> Initial velocities have no component along a direction an SPC holds in a local system
  !> (the global ones are removed when the run is set up).
  subroutine hold_local_initial_velocities(input)
    type(deck_input_t), intent(inout) :: input
    integer :: k, j
    if (.not. allocated(input%model%local_spcs)) return
    do k = 1, size(input%model%local_spcs)
      associate (spc => input%model%local_spcs(k), velocity => input%model%initial_velocity)
        do j = 1, spc%count
          velocity(:, spc%node) = velocity(:, spc%node) - &
            dot_product(velocity(:, spc%node), spc%directions(:, j))*spc%directions(:, j)
        end do
      end associate
    end do
  end subroutine hold_local_initial_velocities

  !> The linear static analysis takes SPCs and motions along the global axes only.
  subroutine check_static_conditions(deck, input, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(in) :: input
    type(problem_log_t), intent(inout) :: log
    integer :: k
    if (.not. input%model%implicit_static) return
    do k = 1, input%spc_count
      if (input%spcs(k)%frame_id /= 0) call located_problem(deck, log, input%spcs(k)%line, "CID", &
        "a static analysis (*CONTROL_IMPLICIT_GENERAL) takes SPCs along the global axes only; "// &
        "use CID 0")
    end do
    do k = 1, input%motion_count
      if (input%motions(k)%direction == 4 .or. input%motions(k)%direction == -4) &
        call located_problem(deck, log, input%motions(k)%line, "DOF", "a static analysis "// &
        "(*CONTROL_IMPLICIT_GENERAL) takes motions along x, y, z only (DOF 1, 2, 3)")
    end do
  end subroutine check_static_conditions

  !> One prescribed_motion_t per node and direction; two motions on one node and direction
  !> contradict each other. DOF 4 and -4 act along the vector VID.
  subroutine build_motions(deck, input, indices, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(deck_indices_t), intent(in) :: indices
    type(problem_log_t), intent(inout) :: log
    type(prescribed_motion_t), allocatable :: motions(:)
    integer, allocatable :: nodes(:), owner(:, :)
    integer :: k, node, count, curve
    real(wp) :: direction(3)

    allocate (owner(3, input%node_count), motions(0))
    owner = 0
    count = 0
    do k = 1, input%motion_count
      associate (given => input%motions(k))
        curve = find_curve(deck, indices, given%curve_id, given%line, log)
        if (.not. target_nodes(deck, input, indices, given%target, given%is_set, given%line, &
                               nodes, log)) cycle
        if (given%direction == 4 .or. given%direction == -4) then
          if (.not. vector_direction(deck, input, given%vector_id, given%line, "VID", direction, &
                                     log)) cycle
          call reserve_motions(motions, count + size(nodes))
          do node = 1, size(nodes)
            count = count + 1
            motions(count) = prescribed_motion_t(node=nodes(node), direction=merge( &
              motion_along_vector, motion_only_along_vector, given%direction == 4), &
              vector=direction, kind=given%kind, curve=curve, scale=given%scale, &
              birth=given%birth, death=given%death)
          end do
          cycle
        end if
        if (given%direction < 1 .or. given%direction > 3) cycle
        call reserve_motions(motions, count + size(nodes))
        do node = 1, size(nodes)
          if (owner(given%direction, nodes(node)) /= 0) then
            call located_problem(deck, log, given%line, merge("NSID", "NID ", given%is_set), &
              "node "//integer_text(input%model%node_ids(nodes(node)))//" already has a "// &
              "prescribed motion in "//axis_names(given%direction)//" (at "// &
              line_location(deck, input%motions(owner(given%direction, nodes(node)))%line)//")")
            cycle
          end if
          owner(given%direction, nodes(node)) = k
          count = count + 1
          motions(count) = prescribed_motion_t(node=nodes(node), direction=given%direction, &
            kind=given%kind, curve=curve, scale=given%scale, birth=given%birth, &
            death=given%death)
        end do
      end associate
    end do
    input%model%motions = motions(1:count)
  end subroutine build_motions

  subroutine reserve_motions(motions, needed)
    type(prescribed_motion_t), allocatable, intent(inout) :: motions(:)
    integer, intent(in) :: needed
    type(prescribed_motion_t), allocatable :: larger(:)
    if (needed <= size(motions)) return
    allocate (larger(max(needed, 2*size(motions))))
    larger(1:size(motions)) = motions
    call move_alloc(larger, motions)
  end subroutine reserve_motions

  !> One nodal_load_t per node (loads on the same node add up, as in LS-DYNA).
  subroutine build_loads(deck, input, indices, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(deck_indices_t), intent(in) :: indices
    type(problem_log_t), intent(inout) :: log
    type(nodal_load_t), allocatable :: loads(:), larger(:)
    integer, allocatable :: nodes(:)
    integer :: k, node, count, curve

    allocate (loads(input%load_count))
    count = 0
    do k = 1, input%load_count
      associate (given => input%loads(k))
        curve = find_curve(deck, indices, given%curve_id, given%line, log)
        if (.not. target_nodes(deck, input, indices, given%target, given%is_set, given%line, &
                               nodes, log)) cycle
        if (count + size(nodes) > size(loads)) then
          allocate (larger(max(count + size(nodes), 2*size(loads))))
          larger(1:count) = loads(1:count)
          call move_alloc(larger, loads)
        end if
        do node = 1, size(nodes)
          count = count + 1
          loads(count) = nodal_load_t(node=nodes(node), direction=given%direction, &
                                      curve=curve, scale=given%scale)
        end do
      end associate
    end do
    input%model%loads = loads(1:count)
    ! body loads (*LOAD_BODY_...): every node, its mass times the base acceleration
    allocate (input%model%body_loads(input%body_load_count))
    do k = 1, input%body_load_count
      associate (given => input%body_loads(k))
        input%model%body_loads(k) = nodal_load_t(node=0, direction=given%direction, &
          curve=find_curve(deck, indices, given%curve_id, given%line, log), scale=given%scale)
        if (input%model%implicit_static) call located_problem(deck, log, given%line, "LCID", &
          "body loads are not available in the linear static analysis (*CONTROL_IMPLICIT_GENERAL IMFLAG = 1)")
      end associate
    end do
  end subroutine build_loads

  !> One segment_load_t per segment: a *LOAD_SEGMENT(_NONUNIFORM) segment as given, a
  !> *LOAD_SEGMENT_SET line once for every segment of its set. Always allocated.
  subroutine build_segment_loads(deck, input, indices, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(deck_indices_t), intent(in) :: indices
    type(problem_log_t), intent(inout) :: log
    type(segment_load_t), allocatable :: loads(:)
    type(segment_load_t) :: load
    integer :: k, count, total, set, segment

    total = 0
    do k = 1, input%segment_load_count
      set = find_id(indices%segment_sets, input%segment_loads(k)%segment_set)
      if (input%segment_loads(k)%segment_set == 0) then
        total = total + 1
      else if (set > 0) then
        total = total + input%segment_sets(set)%count
      end if
    end do
    allocate (loads(total))
    count = 0
    do k = 1, input%segment_load_count
      associate (given => input%segment_loads(k))
        load = given%load
        load%curve = find_curve(deck, indices, given%curve_id, given%line, log)
        if (given%segment_set == 0) then
          if (.not. given%usable) cycle
          if (.not. resolve_segment(deck, input%model%coordinates, indices, given%node_line, &
                                    load%nodes, "", log)) cycle
          count = count + 1
          loads(count) = load
          cycle
        end if
        set = find_id(indices%segment_sets, given%segment_set)
        if (set == 0) then
          call located_problem(deck, log, given%line, "SSID", "segment set "// &
            integer_text(given%segment_set)//" is not defined (no *SET_SEGMENT with this SID)")
          cycle
        end if
        associate (segments => input%segment_sets(set))
          do segment = 1, segments%count
            if (.not. segments%usable(segment)) cycle
            load%nodes = segments%nodes(:, segment)
            count = count + 1
            loads(count) = load
          end do
        end associate
      end associate
    end do
    input%model%segment_loads = loads(1:count)
  end subroutine build_segment_loads

  integer function find_curve(deck, indices, id, line, log)
    type(deck_t), intent(in) :: deck
    type(deck_indices_t), intent(in) :: indices
    integer, intent(in) :: id, line
    type(problem_log_t), intent(inout) :: log
    find_curve = 0
    if (id <= 0) return      ! already reported by the reader
    find_curve = find_id(indices%curves, id)
    if (find_curve == 0) call located_problem(deck, log, line, "LCID", "curve "// &
      integer_text(id)//" is not defined (no *DEFINE_CURVE with this LCID)")
  end function find_curve

  !> Initial velocities: *INITIAL_VELOCITY (by set) first, then _GENERATION, then _NODE, each
  !> in deck order; a later, more specific definition overrides an earlier one.
  subroutine build_initial_velocities(deck, input, indices, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(deck_indices_t), intent(in) :: indices
    type(problem_log_t), intent(inout) :: log
    integer :: pass, k
    integer, parameter :: order(3) = [velocity_by_set, velocity_generation, velocity_by_node]

    allocate (input%model%initial_velocity(3, input%node_count))
    input%model%initial_velocity = 0.0_wp
    do pass = 1, 3
      do k = 1, input%velocity_count
        if (input%velocities(k)%kind /= order(pass)) cycle
        select case (order(pass))
        case (velocity_by_set)
          call apply_set_velocity(deck, input, indices, input%velocities(k), log)
        case (velocity_generation)
          call apply_generated_velocity(deck, input, indices, input%velocities(k), log)
        case (velocity_by_node)
          call apply_node_velocity(deck, input, indices, input%velocities(k), log)
        end select
      end do
    end do
  end subroutine build_initial_velocities

  subroutine apply_set_velocity(deck, input, indices, given, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(deck_indices_t), intent(in) :: indices
    type(velocity_input_t), intent(in) :: given
    type(problem_log_t), intent(inout) :: log
    integer, allocatable :: nodes(:), exempt(:)
    logical, allocatable :: is_exempt(:), in_box(:)
    real(wp) :: axes(3, 3), velocity(3), exempt_velocity(3)
    integer :: k
    if (.not. set_or_all(deck, input, indices, given%target, given%line, "NSID", nodes, log)) &
      return
    velocity = given%velocity
    exempt_velocity = given%exempt_velocity
    if (given%frame_id > 0) then
      ! ICID: the velocities are components along the system's axes
      if (.not. frame_axes(deck, input, given%frame_id, given%line, "ICID", axes, log)) return
      velocity = matmul(axes, velocity)
      exempt_velocity = matmul(axes, exempt_velocity)
    end if
    allocate (in_box(input%node_count))
    in_box = given%box_id == 0
    if (given%box_id > 0) then
      if (.not. mark_nodes_in_box(deck, input, given%box_id, given%line, "BOXID", .true., &
                                  in_box, log)) return
    end if
    allocate (is_exempt(input%node_count))
    is_exempt = .false.
    if (given%exempt_set > 0) then
      if (.not. set_or_all(deck, input, indices, given%exempt_set, given%line, "NSIDEX", &
                           exempt, log)) return
      is_exempt(exempt) = .true.
      do k = 1, size(exempt)
        input%model%initial_velocity(:, exempt(k)) = exempt_velocity
      end do
    end if
    do k = 1, size(nodes)
      if (.not. is_exempt(nodes(k)) .and. in_box(nodes(k))) &
        input%model%initial_velocity(:, nodes(k)) = velocity
    end do
  end subroutine apply_set_velocity

  subroutine apply_node_velocity(deck, input, indices, given, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(deck_indices_t), intent(in) :: indices
    type(velocity_input_t), intent(in) :: given
    type(problem_log_t), intent(inout) :: log
    integer, allocatable :: nodes(:)
    real(wp) :: axes(3, 3)
    if (.not. target_nodes(deck, input, indices, given%target, .false., given%line, nodes, &
                           log)) return
    if (given%frame_id > 0) then
      if (.not. frame_axes(deck, input, given%frame_id, given%line, "ICID", axes, log)) return
      input%model%initial_velocity(:, nodes(1)) = matmul(axes, given%velocity)
    else
      input%model%initial_velocity(:, nodes(1)) = given%velocity
    end if
  end subroutine apply_node_velocity

  !> V + OMEGA n x (x - c) on the nodes of a part set (STYP 1), a part (2) or a node set (3).
  subroutine apply_generated_velocity(deck, input, indices, given, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(deck_indices_t), intent(in) :: indices
    type(velocity_input_t), intent(in) :: given
    type(problem_log_t), intent(inout) :: log
    integer, allocatable :: nodes(:)
    real(wp) :: centre(3), axis(3), length, velocity(3), axes(3, 3)
    integer :: k, first, second

    centre = given%centre
    axis = given%axis
    velocity = given%velocity
    if (given%frame_id > 0) then
      ! ICID: VX VY VZ and NX NY NZ are along the system's axes; XC YC ZC stay global
      if (.not. frame_axes(deck, input, given%frame_id, given%line, "ICID", axes, log)) return
      velocity = matmul(axes, velocity)
      axis = matmul(axes, axis)
    end if
    if (given%axis_nodes(1) > 0) then
      first = find_id(indices%nodes, given%axis_nodes(1))
      second = find_id(indices%nodes, given%axis_nodes(2))
      if (first == 0 .or. second == 0) then
        call located_problem(deck, log, given%axis_line, trim(merge("NY", "NZ", first == 0)), &
          "axis node "//integer_text(given%axis_nodes(merge(1, 2, first == 0)))//" is not "// &
          "defined (NX = -999 makes NY and NZ node ids)")
        return
      end if
      centre = input%model%coordinates(:, first)
      axis = input%model%coordinates(:, second) - centre
      length = norm2(axis)
      if (length == 0.0_wp) then
        call located_problem(deck, log, given%axis_line, "NZ", "axis nodes "// &
          integer_text(given%axis_nodes(1))//" and "//integer_text(given%axis_nodes(2))// &
          " are at the same place")
        return
      end if
      axis = axis/length
    end if
    if (.not. generation_nodes(deck, input, indices, given, nodes, log)) return
    do k = 1, size(nodes)
      input%model%initial_velocity(:, nodes(k)) = velocity + given%omega* &
        cross_product(axis, input%model%coordinates(:, nodes(k)) - centre)
    end do
  end subroutine apply_generated_velocity

  !> Nodes of *INITIAL_VELOCITY_GENERATION's ID by STYP (ID 0: every node).
  logical function generation_nodes(deck, input, indices, given, nodes, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(in) :: input
    type(deck_indices_t), intent(in) :: indices
    type(velocity_input_t), intent(in) :: given
    integer, allocatable, intent(out) :: nodes(:)
    type(problem_log_t), intent(inout) :: log
    logical, allocatable :: chosen_part(:), chosen_node(:)
    integer :: position, element, k
    generation_nodes = .false.
    if (given%target == 0 .or. given%target_type == 3) then
      generation_nodes = set_or_all(deck, input, indices, given%target, given%line, "ID", &
                                    nodes, log)
      return
    end if
    allocate (chosen_part(input%part_count), chosen_node(input%node_count))
    chosen_part = .false.
    if (given%target_type == 2) then
      position = find_id(indices%parts, given%target)
      if (position == 0) then
        call located_problem(deck, log, given%line, "ID", "part "//integer_text(given%target)// &
                             " is not defined (STYP 2: ID is a part)")
        return
      end if
      chosen_part(position) = .true.
    else
      position = find_id(indices%part_sets, given%target)
      if (position == 0) then
        call located_problem(deck, log, given%line, "ID", "part set "// &
          integer_text(given%target)//" is not defined (STYP 1: ID is a part set)")
        return
      end if
      chosen_part(input%model%part_sets(position)%parts) = .true.
    end if
    chosen_node = .false.
    do element = 1, input%solid_count
      k = input%model%solid_part(element)
      if (k == 0) cycle
      if (chosen_part(k)) chosen_node(pack(input%model%solid_nodes(:, element), &
                                           input%model%solid_nodes(:, element) > 0)) = .true.
    end do
    do element = 1, input%shell_count
      k = input%model%shell_part(element)
      if (k == 0) cycle
      if (chosen_part(k)) chosen_node(pack(input%model%shell_nodes(:, element), &
                                           input%model%shell_nodes(:, element) > 0)) = .true.
    end do
    do element = 1, input%beam_count
      k = input%model%beam_part(element)
      if (k == 0) cycle
      if (chosen_part(k)) chosen_node(pack(input%model%beam_nodes(1:2, element), &
                                           input%model%beam_nodes(1:2, element) > 0)) = .true.
    end do
    nodes = pack([(k, k=1, input%node_count)], chosen_node)
    generation_nodes = .true.
  end function generation_nodes

  !> Rigid walls (planar and cylinders): tracked nodes (NSID 0: all) without the exempted set,
  !> the motion curve of a moving cylinder, ids (walls without
  !> _ID are numbered by their place among the walls, as LS-DYNA numbers them).
  subroutine build_walls(deck, input, indices, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(deck_indices_t), intent(in) :: indices
    type(problem_log_t), intent(inout) :: log
    integer, allocatable :: nodes(:), exempt(:)
    logical, allocatable :: keep(:), in_box(:)
    type(id_index_t) :: wall_index
    integer :: k

    allocate (input%model%walls(input%wall_count), keep(input%node_count))
    do k = 1, input%wall_count
      associate (given => input%walls(k))
        if (.not. given%id_given) given%wall%id = k
        if (.not. set_or_all(deck, input, indices, given%node_set, given%line, "NSID", nodes, &
                             log)) cycle
        if (given%exempt_set > 0) then
          if (.not. set_or_all(deck, input, indices, given%exempt_set, given%line, "NSIDEX", &
                               exempt, log)) cycle
          keep = .false.
          keep(nodes) = .true.
          keep(exempt) = .false.
          nodes = pack(nodes, keep(nodes))
        end if
        if (given%box_id > 0) then
          ! BOXID: only the tracked nodes inside the box (at the start)
          if (.not. allocated(in_box)) allocate (in_box(input%node_count))
          in_box = .false.
          if (.not. mark_nodes_in_box(deck, input, given%box_id, given%line, "BOXID", .true., &
                                      in_box, log)) cycle
          nodes = pack(nodes, in_box(nodes))
        end if
        given%wall%nodes = nodes
        ! a moving cylinder's curve (the reader has reported LCID <= 0)
        if (given%wall%motion_curve_id > 0) given%wall%motion_curve = find_curve(deck, indices, &
          given%wall%motion_curve_id, given%motion_line, log)
        input%model%walls(k) = given%wall
      end associate
    end do
    call index_ids(deck, [(input%walls(k)%wall%id, k=1, input%wall_count)], &
                   [(input%walls(k)%line, k=1, input%wall_count)], "RWID", &
                   "rigid wall (walls without _ID are numbered 1, 2, ... in deck order)", &
                   wall_index, log)
    do k = 1, input%wall_count
      if (.not. allocated(input%model%walls(k)%nodes)) allocate (input%model%walls(k)%nodes(0))
    end do
  end subroutine build_walls

  !> *DATABASE_HISTORY_NODE(_SET): node indices in deck order, each node once.
  subroutine build_history_nodes(deck, input, indices, log, warnings)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(deck_indices_t), intent(in) :: indices
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    integer, allocatable :: nodes(:), members(:)
    logical, allocatable :: taken(:)
    integer :: k, position, count, member

    allocate (taken(input%node_count), nodes(input%node_count))
    taken = .false.
    count = 0
    do k = 1, input%history_requests%count
      associate (request => input%history_requests)
        if (request%fields(k) > 0) then
          position = find_id(indices%nodes, request%ids(k))
          if (position == 0) then
            call located_problem(deck, log, request%lines(k), "ID"// &
              integer_text(request%fields(k)), "node "//integer_text(request%ids(k))// &
              " is not defined")
          else if (.not. taken(position)) then
            taken(position) = .true.
            count = count + 1
            nodes(count) = position
          end if
          cycle
        end if
        position = find_id(indices%node_sets, request%ids(k))
        if (position == 0) then
          call located_problem(deck, log, request%lines(k), "ID"// &
            integer_text(-request%fields(k)), "node set "//integer_text(request%ids(k))// &
            " is not defined")
          cycle
        end if
      end associate
      members = input%model%node_sets(position)%nodes
      do member = 1, size(members)
        if (taken(members(member))) cycle
        taken(members(member)) = .true.
        count = count + 1
        nodes(count) = members(member)
      end do
    end do
    input%model%output%history_nodes = nodes(1:count)
    if (count > 0 .and. input%model%output%nodout_interval == 0.0_wp) call add_error(warnings, &
      deck%files(1)%path//": *DATABASE_HISTORY_NODE: "//integer_text(count)//" history "// &
      "nodes are given but *DATABASE_NODOUT has no interval (DT), so no nodout is written")
  end subroutine build_history_nodes

  !> At least one node and one element (solid or shell), every element with a valid shape (a
  !> shell with an area), and the elements of EFG parts proper hexahedra.
  subroutine check_mesh(deck, input, resolved, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(in) :: input
    logical, intent(in) :: resolved
    type(problem_log_t), intent(inout) :: log
    integer :: element, status, corner, part
    real(wp) :: corners(3, 8)
    character(len=:), allocatable :: name

    if (input%node_count == 0) call report_problem(log, deck%files(1)%path// &
      ": *NODE: field NID: the deck defines no nodes")
    if (input%solid_count == 0 .and. input%shell_count == 0 .and. input%beam_count == 0) call report_problem(log, &
      deck%files(1)%path//": *ELEMENT_SOLID: field EID: the deck defines no elements (no "// &
      "*ELEMENT_SOLID or *ELEMENT_SHELL)")
    if (.not. resolved) return
    associate (model => input%model)
      do element = 1, input%shell_count
        if (.not. segment_has_no_area(model%coordinates(:, model%shell_nodes(:, element)))) cycle
        part = model%shell_part(element)
        name = "shell "//integer_text(model%shell_ids(element))
        if (part > 0) name = name//" of part "//integer_text(model%parts(part)%id)
        call located_problem(deck, log, input%shell_lines(element), "N1-N4", name// &
          " has no area: its corners coincide or lie on one line")
      end do
      ! a meshfree shell cell is split into sub-cells at its centre: a concave quadrilateral has
      ! one of no or negative area
      do element = 1, input%shell_count
        part = model%shell_part(element)
        if (part <= 0) cycle
        if (model%parts(part)%formulation /= formulation_efg) cycle
        corner = concave_corner(model%coordinates(:, model%shell_nodes(:, element)))
        if (corner == 0) cycle
        call located_problem(deck, log, input%shell_lines(element), "N1-N4", "shell "// &
          integer_text(model%shell_ids(element))//" of meshfree part "//integer_text(model%parts(part)%id)// &
          " is not convex at its corner N"//integer_text(corner)//" (node "// &
          integer_text(model%node_ids(model%shell_nodes(corner, element)))//"): a meshfree shell cell "// &
          "(ELFORM 41) must be a convex quadrilateral or a triangle")
      end do
      do element = 1, input%solid_count
        do corner = 1, 8
          corners(:, corner) = model%coordinates(:, model%solid_nodes(corner, element))
        end do
        part = model%solid_part(element)
        name = "element "//integer_text(model%solid_ids(element))
        if (part > 0) name = name//" of part "//integer_text(model%parts(part)%id)
        if (part > 0) then
          if (model%parts(part)%formulation == formulation_efg) call check_efg_cell(deck, &
            model%solid_nodes(:, element), model%node_ids, input%solid_node_lines(element), &
            name, log)
        end if
        call check_hexahedron(corners, status, corner)
        if (status == 0) cycle
        if (status == shape_inside_out) then
          call located_problem(deck, log, input%solid_node_lines(element), "N1-N8", name// &
            " is inside out: negative Jacobian at corner N"//integer_text(corner)//" (node "// &
            integer_text(model%node_ids(model%solid_nodes(corner, element)))//"); number "// &
            "N1-N4 counterclockwise as seen from the N5-N8 face")
        else if (status == shape_flat) then
          call located_problem(deck, log, input%solid_node_lines(element), "N1-N8", name// &
            " has no volume: its nodes are collapsed or lie in one plane")
        end if
      end do
    end associate
  end subroutine check_mesh

  !> A background cell of an EFG part needs 8 distinct nodes: the support sizes, the sub-cell
  !> split and the face integration all assume a proper hexahedron, so a wedge or tetrahedron
  !> written with repeated nodes is an error naming the element and the corners that repeat.
  subroutine check_efg_cell(deck, nodes, node_ids, line, name, log)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: nodes(8), node_ids(:), line
    character(len=*), intent(in) :: name
    type(problem_log_t), intent(inout) :: log
    integer :: first, second
    do second = 2, 8
      do first = 1, second - 1
        if (nodes(first) /= nodes(second)) cycle
        call located_problem(deck, log, line, "N1-N8", name//" repeats node "// &
          integer_text(node_ids(nodes(first)))//" (N"//integer_text(first)//" and N"// &
          integer_text(second)//"): the background cells of an EFG part (ELFORM 41) must be "// &
          "proper hexahedra with 8 distinct nodes")
        return
      end do
    end do
  end subroutine check_efg_cell

  !> ENDTIM (or ENDCYC) and the output intervals that depend on it.
  subroutine check_controls(deck, input, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    associate (model => input%model)
      if (input%termination_line == 0) then
        call report_problem(log, deck%files(1)%path//": *CONTROL_TERMINATION: field ENDTIM: "// &
          "the deck has no *CONTROL_TERMINATION, so the run has no end time")
      else if (model%end_time < 0.0_wp .or. (model%end_time == 0.0_wp .and. &
                                              model%end_cycle == 0)) then
        call located_problem(deck, log, input%termination_line, "ENDTIM", "end time must be "// &
          "> 0 (or give ENDCYC > 0), found "//real_text(model%end_time))
      else if (model%end_time == 0.0_wp) then
        model%end_time = huge(1.0_wp)    ! ENDCYC alone ends the run
      end if
      if (input%plot_count > 0) then
        if (model%end_time > 0.0_wp .and. model%end_time < huge(1.0_wp)) then
          model%output%state_interval = model%end_time/input%plot_count
        else if (input%termination_line > 0) then
          call located_problem(deck, log, input%plot_line, "NPLTC", "NPLTC sets the interval "// &
            "to ENDTIM/NPLTC, which needs ENDTIM > 0")
        end if
      end if
    end associate
  end subroutine check_controls

  !> *CONTROL_IMPLICIT_SOLUTION NSOLVR, which matters only for an implicit analysis
  !> (*CONTROL_IMPLICIT_GENERAL IMFLAG 1, in any place of the deck): 1 (linear) is accepted;
  !> blank, 0 and LS-DYNA's default 12 (nonlinear) are solved as linear with a warning; any other
  !> value is an error. In an explicit analysis the keyword is ignored with a warning.
  subroutine check_implicit_solution(deck, input, log, warnings)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(in) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    integer :: line
    line = input%implicit_solution_line
    if (line == 0) return
    if (.not. input%model%implicit_static) then
      call located_warning(deck, warnings, line, "NSOLVR", "ignored (the analysis is explicit: "// &
                           "*CONTROL_IMPLICIT_GENERAL IMFLAG 1 is not given)")
      return
    end if
    select case (input%implicit_solver)
    case (1)
    case (0)
      call located_warning(deck, warnings, line, "NSOLVR", "blank means LS-DYNA's default 12 "// &
        "(nonlinear, BFGS updates); crashfree's implicit analysis is linear static, as NSOLVR 1")
    case (12)
      call located_warning(deck, warnings, line, "NSOLVR", "12 (nonlinear, BFGS updates) is "// &
        "solved as linear: crashfree's implicit analysis is linear static, as NSOLVR 1")
    case default
      call located_problem(deck, log, line, "NSOLVR", "crashfree's implicit analysis is linear "// &
        "static: NSOLVR 1 (linear), or blank, found "//integer_text(input%implicit_solver))
    end select
  end subroutine check_implicit_solution

  !> Each part's effective hourglass and bulk-viscosity values (LS-DYNA's rules): the part's
  !> *HOURGLASS where it gives a value, else *CONTROL_HOURGLASS IHQ/QH and
  !> *CONTROL_BULK_VISCOSITY Q1/Q2, else LS-DYNA's defaults (IHQ 1, QM 0.1, Q1 1.5, Q2 0.06).
  subroutine set_effective_hourglass(input)
    type(deck_input_t), intent(inout) :: input
    integer :: k
    associate (model => input%model)
      do k = 1, input%hourglass_count
        associate (hourglass => model%hourglasses(k))
          if (hourglass%coefficient == 0.0_wp) hourglass%coefficient = &
            model%default_hourglass_coefficient
          if (hourglass%bulk_quadratic == 0.0_wp) hourglass%bulk_quadratic = input%bulk_quadratic
          if (hourglass%bulk_linear == 0.0_wp) hourglass%bulk_linear = input%bulk_linear
        end associate
      end do
      do k = 1, input%part_count
        associate (part => model%parts(k))
          part%hourglass_type = model%default_hourglass_type
          part%hourglass_coefficient = model%default_hourglass_coefficient
          part%bulk_quadratic = input%bulk_quadratic
          part%bulk_linear = input%bulk_linear
          if (part%hourglass > 0) then
            if (model%hourglasses(part%hourglass)%hourglass_type > 0) &
              part%hourglass_type = model%hourglasses(part%hourglass)%hourglass_type
            part%hourglass_coefficient = model%hourglasses(part%hourglass)%coefficient
            part%bulk_quadratic = model%hourglasses(part%hourglass)%bulk_quadratic
            part%bulk_linear = model%hourglasses(part%hourglass)%bulk_linear
          end if
        end associate
      end do
    end associate
  end subroutine set_effective_hourglass

  pure function cross_product(a, b) result(c)
    real(wp), intent(in) :: a(3), b(3)
    real(wp) :: c(3)
    c = [a(2)*b(3) - a(3)*b(2), a(3)*b(1) - a(1)*b(3), a(1)*b(2) - a(2)*b(1)]
  end function cross_product

  !> The first corner (1-4) at which a quadrilateral with corners x(3, 4) turns against its
  !> normal (the cross product of the diagonals), or 0 for a convex one; triangles (corner 4
  !> repeating corner 3) and cells with no area are left to the other checks.
  pure integer function concave_corner(x)
    real(wp), intent(in) :: x(3, 4)
    real(wp) :: normal(3), incoming(3), outgoing(3), turn(3)
    integer :: corner
    concave_corner = 0
    if (all(x(:, 4) == x(:, 3))) return
    normal = cross_product(x(:, 3) - x(:, 1), x(:, 4) - x(:, 2))
    if (norm2(normal) <= 0.0_wp) return
    do corner = 1, 4
      incoming = x(:, corner) - x(:, modulo(corner - 2, 4) + 1)
      outgoing = x(:, modulo(corner, 4) + 1) - x(:, corner)
      turn = cross_product(incoming, outgoing)
      if (dot_product(turn, normal) <= 0.0_wp) then
        concave_corner = corner
        return
      end if
    end do
  end function concave_corner
end module deck_cross_check
