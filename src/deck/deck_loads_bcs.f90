!> Boundary conditions, loads, initial velocities and rigid walls: *BOUNDARY_SPC_NODE/_SET,
!> *BOUNDARY_PRESCRIBED_MOTION_NODE/_SET, *LOAD_NODE_POINT/_SET, *LOAD_SEGMENT(_SET,
!> _NONUNIFORM), *INITIAL_VELOCITY(_NODE, _GENERATION), *RIGIDWALL_PLANAR and
!> *RIGIDWALL_GEOMETRIC_CYLINDER. They are kept as
!> written (by node, segment or set id); the cross-check expands them per node or segment.
module deck_loads_bcs
  use kinds, only: wp
  use error_handling, only: error_list_t
  use model, only: rigid_wall_t, wall_cylinder, motion_velocity, motion_acceleration, motion_displacement
  use deck_problems, only: problem_log_t
  use text_format, only: integer_text, real_text
  use deck_lexer, only: deck_t
  use deck_keywords, only: keyword_t
  use deck_fields, only: card_t, open_card, next_line, require_card, has_data, get_integer, &
                         get_real, card_problem, warn_if_set, id_heading, line_problem, &
                         card_is_empty, field_is_blank, located_warning, keyword_label
  use deck_input, only: deck_input_t, velocity_input_t, velocity_by_set, velocity_by_node, &
                        velocity_generation, segment_load_input_t, wall_input_t
  use deck_segments, only: read_segment_nodes
  implicit none
  private

  public :: read_node_spcs, read_set_spcs, read_node_motions, read_set_motions, read_node_loads
  public :: read_set_loads, read_initial_velocities
  public :: read_initial_velocity_nodes, read_velocity_generations, read_planar_walls
  public :: read_cylinder_walls
  public :: read_segment_loads, read_segment_set_loads, read_nonuniform_segment_loads
  public :: read_body_loads

  integer, parameter :: standard_widths(8) = 10
  character(len=*), parameter :: no_rotations = "solid nodes have no rotations"
  character(len=*), parameter :: no_local_systems = "loads in local coordinate systems are "// &
                                                    "not available; leave it blank or 0"

contains

  !> *BOUNDARY_SPC_NODE: see read_spc_cards.
  subroutine read_node_spcs(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_spc_cards(deck, block, keyword, .false., input, log)
  end subroutine read_node_spcs

  !> *BOUNDARY_SPC_SET: see read_spc_cards.
  subroutine read_set_spcs(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_spc_cards(deck, block, keyword, .true., input, log)
  end subroutine read_set_spcs

  !> *BOUNDARY_SPC_NODE / _SET: NID|NSID CID DOFX DOFY DOFZ DOFRX DOFRY DOFRZ per line. With a
  !> CID the translations are held along the axes of that coordinate system. The rotations act
  !> on shell nodes (global axes only); the cross-check warns when they name no shell node.
  subroutine read_spc_cards(deck, block, keyword, by_set, input, log)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    logical, intent(in) :: by_set
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(card_t) :: card
    integer :: line, n, k, system, flag
    logical :: fixed(6)
    character(len=5), parameter :: names(6) = ["DOFX ", "DOFY ", "DOFZ ", "DOFRX", "DOFRY", "DOFRZ"]

    line = 0
    if (.not. skip_id_card(deck, block, keyword, line, log)) return
    do while (next_line(deck, block, line, .true.))
      call open_card(deck, block, line, standard_widths, card, log)
      n = input%spc_count + 1
      input%spc_count = n
      associate (spc => input%spcs(n))
        spc%is_set = by_set
        spc%line = line
        call read_target(deck, card, by_set, spc%target, log)
        call get_integer(deck, card, 2, "CID", system, log)
        if (system < 0) then
          call card_problem(deck, log, card, "CID", "must be >= 0, found "//integer_text(system))
        else
          spc%frame_id = system
        end if
        do k = 1, 6
          call get_integer(deck, card, k + 2, trim(names(k)), flag, log)
          if (flag /= 0 .and. flag /= 1) then
            call card_problem(deck, log, card, trim(names(k)), "must be 0 (free) or 1 "// &
                              "(fixed), found "//integer_text(flag))
            flag = 0
          end if
          fixed(k) = flag == 1
        end do
        spc%fixed = fixed(1:3)
        spc%fixed_rotation = fixed(4:6)
        if (system > 0 .and. any(fixed(4:6))) call card_problem(deck, log, card, "DOFRX", &
          "rotations held about local axes (CID > 0) are not available; hold rotations with "// &
          "CID 0 on a separate line")
      end associate
    end do
  end subroutine read_spc_cards

  !> *BOUNDARY_PRESCRIBED_MOTION_NODE: see read_motion_cards.
  subroutine read_node_motions(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_motion_cards(deck, block, keyword, .false., input, log, warnings)
  end subroutine read_node_motions

  !> *BOUNDARY_PRESCRIBED_MOTION_SET: see read_motion_cards.
  subroutine read_set_motions(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_motion_cards(deck, block, keyword, .true., input, log, warnings)
  end subroutine read_set_motions

  !> *BOUNDARY_PRESCRIBED_MOTION_NODE / _SET: NID|NSID DOF VAD LCID SF VID DEATH BIRTH. DOF 4
  !> moves the nodes along the vector VID (free across it), DOF -4 along VID only.
  subroutine read_motion_cards(deck, block, keyword, by_set, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    logical, intent(in) :: by_set
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, n, vector

    line = 0
    if (.not. skip_id_card(deck, block, keyword, line, log)) return
    do while (next_line(deck, block, line, .true.))
      call open_card(deck, block, line, standard_widths, card, log)
      n = input%motion_count + 1
      input%motion_count = n
      associate (motion => input%motions(n))
        motion%is_set = by_set
        motion%line = line
        call read_target(deck, card, by_set, motion%target, log)
        call get_integer(deck, card, 2, "DOF", motion%direction, log)
        call get_integer(deck, card, 3, "VAD", motion%kind, log)
        call get_integer(deck, card, 4, "LCID", motion%curve_id, log)
        call get_real(deck, card, 5, "SF", motion%scale, log)
        call get_integer(deck, card, 6, "VID", vector, log)
        call get_real(deck, card, 7, "DEATH", motion%death, log)
        call get_real(deck, card, 8, "BIRTH", motion%birth, log)
        if (motion%scale == 0.0_wp) motion%scale = 1.0_wp
        if (motion%death == 0.0_wp) motion%death = 1.0e28_wp
        if (card%failed) cycle
        call check_motion_direction(deck, card, motion%direction, log)
        motion%vector_id = vector
        select case (motion%kind)
        case (motion_velocity, motion_acceleration, motion_displacement)
        case (3, 4)
          call card_problem(deck, log, card, "VAD", integer_text(motion%kind)//" applies to "// &
            "rigid bodies only; use 0 (velocity), 1 (acceleration) or 2 (displacement)")
        case default
          call card_problem(deck, log, card, "VAD", "must be 0 (velocity), 1 (acceleration) "// &
                            "or 2 (displacement), found "//integer_text(motion%kind))
        end select
        call check_curve_given(deck, card, 4, motion%curve_id, log)
        if (abs(motion%direction) == 4) then
          if (vector <= 0) call card_problem(deck, log, card, "VID", "DOF "// &
            integer_text(motion%direction)//" moves along a vector: VID must name a "// &
            "*DEFINE_VECTOR, found "//integer_text(vector))
        else
          call warn_if_set(deck, card, 6, "VID", "used with DOF 4 or -4 only", warnings)
        end if
        if (motion%death <= motion%birth) call card_problem(deck, log, card, "DEATH", &
          "death time "//real_text(motion%death)//" must be later than the birth time "// &
          real_text(motion%birth))
      end associate
    end do
  end subroutine read_motion_cards

  !> DOF of a prescribed motion: 1-3, or 4 and -4 along a vector; no rotations, since solid
  !> nodes carry none.
  subroutine check_motion_direction(deck, card, direction, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(in) :: card
    integer, intent(in) :: direction
    type(problem_log_t), intent(inout) :: log
    select case (direction)
    case (1:4, -4)
    case (8, -8)
      call card_problem(deck, log, card, "DOF", integer_text(direction)//" (rotation about "// &
        "a vector VID) is not available, since "//no_rotations//"; use DOF 1-4 or -4")
    case (5:7, 9:11, -11:-9)
      call card_problem(deck, log, card, "DOF", integer_text(direction)//" is a rotation, "// &
        "but "//no_rotations//"; use DOF 1, 2 or 3 (x, y, z)")
    case (12)
      call card_problem(deck, log, card, "DOF", "12 (along segment normals) applies to "// &
        "*BOUNDARY_PRESCRIBED_MOTION_SET_SEGMENT only; use DOF 1, 2 or 3")
    case default
      call card_problem(deck, log, card, "DOF", "must be 1, 2 or 3 (x, y, z translation) or "// &
                        "4, -4 (along the vector VID), found "//integer_text(direction))
    end select
  end subroutine check_motion_direction

  !> *LOAD_NODE_POINT: see read_load_cards.
  subroutine read_node_loads(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_load_cards(deck, block, .false., input, log)
  end subroutine read_node_loads

  !> *LOAD_NODE_SET: see read_load_cards.
  subroutine read_set_loads(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_load_cards(deck, block, .true., input, log)
  end subroutine read_set_loads

  !> *LOAD_NODE_POINT / _SET: NID|NSID DOF LCID SF CID M1 M2 M3.
  subroutine read_load_cards(deck, block, by_set, input, log)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    logical, intent(in) :: by_set
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(card_t) :: card
    integer :: line, n, system

    line = 0
    do while (next_line(deck, block, line, .true.))
      call open_card(deck, block, line, standard_widths, card, log)
      n = input%load_count + 1
      input%load_count = n
      associate (load => input%loads(n))
        load%is_set = by_set
        load%line = line
        call read_target(deck, card, by_set, load%target, log)
        call get_integer(deck, card, 2, "DOF", load%direction, log)
        call get_integer(deck, card, 3, "LCID", load%curve_id, log)
        call get_real(deck, card, 4, "SF", load%scale, log)
        call get_integer(deck, card, 5, "CID", system, log)
        if (load%scale == 0.0_wp) load%scale = 1.0_wp
        if (card%failed) cycle
        select case (load%direction)
        case (1:3)
        case (4, 8)
          call card_problem(deck, log, card, "DOF", integer_text(load%direction)//" (follower "// &
            "force or moment) is not available; use DOF 1, 2 or 3 (x, y, z)")
        case (5:7)
          call card_problem(deck, log, card, "DOF", integer_text(load%direction)//" is a "// &
            "moment, but "//no_rotations//"; use DOF 1, 2 or 3 (x, y, z)")
        case default
          call card_problem(deck, log, card, "DOF", "must be 1, 2 or 3 (force in x, y, z), "// &
                            "found "//integer_text(load%direction))
        end select
        call check_curve_given(deck, card, 3, load%curve_id, log)
        if (system /= 0) call card_problem(deck, log, card, "CID", no_local_systems)
      end associate
    end do
  end subroutine read_load_cards

  !> *LOAD_BODY_X / _Y / _Z: LCID SF LCIDDR XC YC ZC CID, a base acceleration SF*curve(t) along
  !> the axis; every node takes the inertial force -m SF curve(t) (LS-DYNA: gravity in -z is
  !> *LOAD_BODY_Z with a positive curve, 9.81 m/s^2 in the deck's units).
  subroutine read_body_loads(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    character(len=:), allocatable :: name
    integer :: line, system, n
    line = 0
    if (.not. require_card(deck, block, line, standard_widths, card, log, &
                           "card 1 (LCID SF LCIDDR XC YC ZC CID)", "LCID")) return
    n = input%body_load_count + 1
    input%body_load_count = n
    name = keyword_label(deck, block)
    associate (load => input%body_loads(n))
      load%line = line
      load%direction = index("XYZ", name(len(name):len(name)))
      call get_integer(deck, card, 1, "LCID", load%curve_id, log)
      call get_real(deck, card, 2, "SF", load%scale, log)
      if (load%scale == 0.0_wp) load%scale = 1.0_wp
      call warn_if_set(deck, card, 3, "LCIDDR", "no dynamic relaxation: the run starts from the deck's state", &
                       warnings)
      call warn_if_set(deck, card, 4, "XC", "the centre is only used by angular body loads", warnings)
      call warn_if_set(deck, card, 5, "YC", "the centre is only used by angular body loads", warnings)
      call warn_if_set(deck, card, 6, "ZC", "the centre is only used by angular body loads", warnings)
      call get_integer(deck, card, 7, "CID", system, log)
      if (card%failed) return
      call check_curve_given(deck, card, 1, load%curve_id, log)
      if (system /= 0) call card_problem(deck, log, card, "CID", "a body load in a local system is "// &
        "not available; give the load along a global axis (CID 0)")
    end associate
  end subroutine read_body_loads

  !> *LOAD_SEGMENT(_ID): one segment per line, LCID SF AT N1 N2 N3 N4 N5: a pressure, uniform
  !> over the segment, SF*curve(t - AT). A line that sets nothing is skipped: pydyna writes a card
  !> of mid-side nodes N6 N7 N8 after every segment, which would otherwise be read as a segment.
  subroutine read_segment_loads(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    type(segment_load_input_t) :: given
    integer :: line, k, mid_side, nodes(4)

    line = 0
    if (.not. skip_id_card(deck, block, keyword, line, log)) return
    do while (next_line(deck, block, line, .true.))
      call open_card(deck, block, line, standard_widths, card, log)
      if (card_is_empty(card)) cycle
      do k = 1, 4
        call get_integer(deck, card, k + 3, "N"//achar(iachar("0") + k), nodes(k), log)
      end do
      call get_integer(deck, card, 8, "N5", mid_side, log)
      if (card%failed) cycle
      if (all(nodes == 0) .and. mid_side == 0) then
        call card_problem(deck, log, card, "N1", "the line has no segment nodes (N1-N4 are "// &
          "blank): each line of *LOAD_SEGMENT is one segment, LCID SF AT N1 N2 N3 N4 N5; a "// &
          "card of mid-side nodes N6 N7 N8 (quadratic segments) is not read")
        cycle
      end if
      given = segment_load_input_t(line=line, node_line=line)
      call read_load_curve(deck, card, given%curve_id, given%load%scale, &
                           given%load%arrival_time, log)
      call read_segment_nodes(deck, card, 4, given%load%nodes, given%usable, log)
      if (mid_side /= 0) call card_problem(deck, log, card, "N5", "quadratic segments "// &
        "(mid-side nodes) are not available; leave N5 blank, found "//integer_text(mid_side))
      call add_segment_load(input, given)
    end do
  end subroutine read_segment_loads

  !> *LOAD_SEGMENT_SET(_ID): SSID LCID SF AT per line, a uniform pressure on every segment of
  !> the *SET_SEGMENT SSID.
  subroutine read_segment_set_loads(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    type(segment_load_input_t) :: given
    integer :: line, set

    line = 0
    if (.not. skip_id_card(deck, block, keyword, line, log)) return
    do while (next_line(deck, block, line, .true.))
      call open_card(deck, block, line, standard_widths, card, log)
      given = segment_load_input_t(line=line, node_line=line)
      call get_integer(deck, card, 1, "SSID", set, log)
      call read_load_curve(deck, card, given%curve_id, given%load%scale, &
                           given%load%arrival_time, log, first=2)
      if (card%failed) cycle
      if (set <= 0) then
        call card_problem(deck, log, card, "SSID", "segment set id must be > 0, found "// &
                          integer_text(set))
        cycle
      end if
      given%segment_set = set
      call add_segment_load(input, given)
    end do
  end subroutine read_segment_set_loads

  !> *LOAD_SEGMENT_NONUNIFORM(_ID): card 1 LCID SF AT DT CID V1 V2 V3, then for each segment a
  !> card of nodes N1-N8 and a card of nodal values P1-P8. The load per unit area is
  !> SF*curve(t - AT) times the value interpolated from the corners, from AT to DT: a pressure
  !> along the normal when V1 = V2 = V3 = 0, else a traction along the unit vector of V.
  subroutine read_nonuniform_segment_loads(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    type(segment_load_input_t) :: common, given
    integer :: line, first_line, system, segments
    real(wp) :: vector(3), length

    line = 0
    if (.not. has_data(deck, block, log, "card 1 (LCID SF AT DT CID V1 V2 V3)", "LCID")) return
    if (.not. skip_id_card(deck, block, keyword, line, log)) return
    if (.not. require_card(deck, block, line, standard_widths, card, log, &
                           "card 1 (LCID SF AT DT CID V1 V2 V3)", "LCID")) return
    first_line = line
    common = segment_load_input_t(line=line)
    call read_load_curve(deck, card, common%curve_id, common%load%scale, &
                         common%load%arrival_time, log)
    call get_real(deck, card, 4, "DT", common%load%death, log)
    call get_integer(deck, card, 5, "CID", system, log)
    call read_vector(deck, card, 6, ["V1", "V2", "V3"], vector, log)
    if (.not. card%failed) then
      if (common%load%death == 0.0_wp) then
        common%load%death = huge(1.0_wp)
      else if (common%load%death <= common%load%arrival_time) then
        call card_problem(deck, log, card, "DT", "death time "//real_text(common%load%death)// &
          " must be later than the arrival time AT = "//real_text(common%load%arrival_time))
      end if
      if (system /= 0) call card_problem(deck, log, card, "CID", no_local_systems)
      length = norm2(vector)
      common%load%along_normal = length == 0.0_wp
      if (length > 0.0_wp) common%load%direction = vector/length
    end if

    segments = 0
    do while (next_line(deck, block, line, .true.))
      call open_card(deck, block, line, standard_widths, card, log)
      given = common
      given%node_line = line
      call read_segment_nodes(deck, card, 1, given%load%nodes, given%usable, log)
      call reject_mid_side_nodes(deck, card, log)
      segments = segments + 1
      if (.not. require_card(deck, block, line, standard_widths, card, log, "the card of "// &
          "nodal values (P1-P8) after the node card of the segment", "P1")) exit
      call read_nodal_values(deck, card, given, log, warnings)
      call add_segment_load(input, given)
    end do
    if (segments == 0) call line_problem(deck, log, first_line, block, "N1", "the keyword has "// &
      "no segment: a card of nodes N1-N8 and a card of nodal values P1-P8 must follow card 1", &
      unreadable=.true.)
  end subroutine read_nonuniform_segment_loads

  !> Mid-side nodes N5-N8 of a *LOAD_SEGMENT_NONUNIFORM node card: quadratic segments are not
  !> available, so each must be blank or 0.
  subroutine reject_mid_side_nodes(deck, card, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    type(problem_log_t), intent(inout) :: log
    integer :: k, node
    character(len=2) :: name
    do k = 5, 8
      name = "N"//achar(iachar("0") + k)
      call get_integer(deck, card, k, name, node, log)
      if (node == 0) cycle
      call card_problem(deck, log, card, name, "quadratic segments (mid-side nodes N5-N8) "// &
                        "are not available; leave N5-N8 blank, found "//integer_text(node))
      return
    end do
  end subroutine reject_mid_side_nodes

  !> P1-P4 of a *LOAD_SEGMENT_NONUNIFORM values card (blank: 0). A triangle (N4 = N3) has one
  !> value at N3: P4 must be blank or equal P3.
  subroutine read_nodal_values(deck, card, given, log, warnings)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    type(segment_load_input_t), intent(inout) :: given
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    integer :: k
    character(len=2) :: name
    do k = 1, 4
      name = "P"//achar(iachar("0") + k)
      call get_real(deck, card, k, name, given%load%nodal_values(k), log)
    end do
    do k = 5, 8
      name = "P"//achar(iachar("0") + k)
      call warn_if_set(deck, card, k, name, "no mid-side nodes", warnings)
    end do
    if (card%failed .or. .not. given%usable) return
    associate (values => given%load%nodal_values)
      if (given%load%nodes(4) == given%load%nodes(3)) then
        if (field_is_blank(card, 4)) then
          values(4) = values(3)
        else if (values(4) /= values(3)) then
          call card_problem(deck, log, card, "P4", "the segment is a triangle (N4 = N3), "// &
            "which has one value at N3: leave P4 blank or equal to P3 = "//real_text(values(3))// &
            ", found "//real_text(values(4)))
        end if
      end if
      if (all(values == 0.0_wp)) call located_warning(deck, warnings, card%line, "P1-P4", &
        "the nodal values are all zero, so the segment carries no load")
    end associate
  end subroutine read_nodal_values

  !> LCID SF AT from field `first` on (default 1): the curve is required, SF blank or 0 means 1.
  subroutine read_load_curve(deck, card, curve_id, scale, arrival_time, log, first)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    integer, intent(out) :: curve_id
    real(wp), intent(out) :: scale, arrival_time
    type(problem_log_t), intent(inout) :: log
    integer, intent(in), optional :: first
    integer :: k
    k = 1
    if (present(first)) k = first
    call get_integer(deck, card, k, "LCID", curve_id, log)
    call get_real(deck, card, k + 1, "SF", scale, log)
    call get_real(deck, card, k + 2, "AT", arrival_time, log)
    if (scale == 0.0_wp) scale = 1.0_wp
    if (.not. card%failed) call check_curve_given(deck, card, k, curve_id, log)
  end subroutine read_load_curve

  subroutine add_segment_load(input, given)
    type(deck_input_t), intent(inout) :: input
    type(segment_load_input_t), intent(in) :: given
    input%segment_load_count = input%segment_load_count + 1
    input%segment_loads(input%segment_load_count) = given
  end subroutine add_segment_load

  !> *INITIAL_VELOCITY: card 1 NSID NSIDEX BOXID IRIGID ICID, card 2 VX VY VZ VXR VYR VZR,
  !> card 3 (when NSIDEX > 0) the velocities of the exempted nodes.
  subroutine read_initial_velocities(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    type(velocity_input_t) :: velocity
    integer :: line, box, system

    line = 0
    if (.not. has_data(deck, block, log, "card 1 (NSID NSIDEX BOXID IRIGID ICID)", "NSID")) return
    do while (next_line(deck, block, line, .true.))
      velocity = velocity_input_t(kind=velocity_by_set, line=line)
      call open_card(deck, block, line, standard_widths, card, log)
      call get_integer(deck, card, 1, "NSID", velocity%target, log)
      call get_integer(deck, card, 2, "NSIDEX", velocity%exempt_set, log)
      call get_integer(deck, card, 3, "BOXID", box, log)
      call get_integer(deck, card, 5, "ICID", system, log)
      call check_set_id(deck, card, 1, "NSID", velocity%target, log)
      call check_set_id(deck, card, 2, "NSIDEX", velocity%exempt_set, log)
      call check_set_id(deck, card, 3, "BOXID", box, log)
      call check_set_id(deck, card, 5, "ICID", system, log)
      velocity%box_id = max(box, 0)
      velocity%frame_id = max(system, 0)
      call warn_if_set(deck, card, 4, "IRIGID", "no rigid bodies", warnings)
      if (.not. require_card(deck, block, line, standard_widths, card, log, &
                             "card 2 (VX VY VZ VXR VYR VZR)", "VX")) exit
      call read_vector(deck, card, 1, ["VX", "VY", "VZ"], velocity%velocity, log)
      call warn_rotations(deck, card, 4, ["VXR", "VYR", "VZR"], warnings)
      if (velocity%exempt_set > 0) then
        if (.not. require_card(deck, block, line, standard_widths, card, log, "card 3 (VXE "// &
                               "VYE VZE VXRE VYRE VZRE, read because NSIDEX > 0)", "VXE")) exit
        call read_vector(deck, card, 1, ["VXE", "VYE", "VZE"], velocity%exempt_velocity, log)
        call warn_rotations(deck, card, 4, ["VXRE", "VYRE", "VZRE"], warnings)
      end if
      call add_velocity(input, velocity)
    end do
  end subroutine read_initial_velocities

  !> *INITIAL_VELOCITY_NODE: NID VX VY VZ VXR VYR VZR ICID per line.
  subroutine read_initial_velocity_nodes(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    type(velocity_input_t) :: velocity
    integer :: line, system

    line = 0
    do while (next_line(deck, block, line, .true.))
      velocity = velocity_input_t(kind=velocity_by_node, line=line)
      call open_card(deck, block, line, standard_widths, card, log)
      call read_target(deck, card, .false., velocity%target, log)
      call read_vector(deck, card, 2, ["VX", "VY", "VZ"], velocity%velocity, log)
      call warn_rotations(deck, card, 5, ["VXR", "VYR", "VZR"], warnings)
      call get_integer(deck, card, 8, "ICID", system, log)
      call check_set_id(deck, card, 8, "ICID", system, log)
      velocity%frame_id = max(system, 0)
      call add_velocity(input, velocity)
    end do
  end subroutine read_initial_velocity_nodes

  !> *INITIAL_VELOCITY_GENERATION: card 1 ID STYP OMEGA VX VY VZ IVATN ICID, card 2 XC YC ZC
  !> NX NY NZ PHASE IRIGID. The velocity is V + OMEGA n x (x - c): a rotation about the axis
  !> through c along n plus a translation. NX = -999 makes NY and NZ two nodes on the axis.
  subroutine read_velocity_generations(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    type(velocity_input_t) :: velocity
    integer :: line, system

    line = 0
    if (.not. has_data(deck, block, log, "card 1 (ID STYP OMEGA VX VY VZ IVATN ICID)", "ID")) return
    do while (next_line(deck, block, line, .true.))
      velocity = velocity_input_t(kind=velocity_generation, line=line)
      call open_card(deck, block, line, standard_widths, card, log)
      call get_integer(deck, card, 1, "ID", velocity%target, log)
      call get_integer(deck, card, 2, "STYP", velocity%target_type, log, default=1)
      call get_real(deck, card, 3, "OMEGA", velocity%omega, log)
      call read_vector(deck, card, 4, ["VX", "VY", "VZ"], velocity%velocity, log)
      call get_integer(deck, card, 8, "ICID", system, log)
      if (velocity%target_type == 0) velocity%target_type = 1
      if (velocity%target_type < 1 .or. velocity%target_type > 3) call card_problem(deck, log, &
        card, "STYP", "must be 1 (part set), 2 (part) or 3 (node set), found "// &
        integer_text(velocity%target_type))
      call check_set_id(deck, card, 1, "ID", velocity%target, log)
      call check_set_id(deck, card, 8, "ICID", system, log)
      velocity%frame_id = max(system, 0)
      call warn_if_set(deck, card, 7, "IVATN", "no rigid bodies or constrained nodes", warnings)
      if (.not. require_card(deck, block, line, standard_widths, card, log, &
                             "card 2 (XC YC ZC NX NY NZ PHASE IRIGID)", "XC")) exit
      velocity%axis_line = line
      call read_vector(deck, card, 1, ["XC", "YC", "ZC"], velocity%centre, log)
      call read_vector(deck, card, 4, ["NX", "NY", "NZ"], velocity%axis, log)
      call warn_if_set(deck, card, 8, "IRIGID", "no rigid bodies", warnings)
      if (.not. card%failed) call prepare_axis(deck, card, velocity, log)
      call add_velocity(input, velocity)
    end do
  end subroutine read_velocity_generations

  !> Normalise the rotation axis, or take its two nodes when NX = -999.
  subroutine prepare_axis(deck, card, velocity, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(in) :: card
    type(velocity_input_t), intent(inout) :: velocity
    type(problem_log_t), intent(inout) :: log
    real(wp) :: length
    integer :: k
    character(len=2), parameter :: names(2) = ["NY", "NZ"]
    if (velocity%axis(1) == -999.0_wp) then
      do k = 1, 2
        if (velocity%axis(k + 1) <= 0.0_wp .or. velocity%axis(k + 1) /= aint(velocity%axis(k + 1)) &
            .or. velocity%axis(k + 1) > 2.0e9_wp) then
          call card_problem(deck, log, card, names(k), "with NX = -999, NY and NZ are node "// &
                            "ids, found "//real_text(velocity%axis(k + 1)))
          return
        end if
        velocity%axis_nodes(k) = nint(velocity%axis(k + 1))
      end do
      return
    end if
    length = norm2(velocity%axis)
    if (length > 0.0_wp) then
      velocity%axis = velocity%axis/length
    else if (velocity%omega /= 0.0_wp) then
      call card_problem(deck, log, card, "NX", "the rotation axis (NX NY NZ) has zero length "// &
                        "but OMEGA is "//real_text(velocity%omega))
    end if
  end subroutine prepare_axis

  !> The start of one rigid wall, shared by every kind: the RWID heading line (`_ID`), then card 1
  !> with NSID NSIDEX BOXID and BIRTH DEATH at fields `birth_field` and `birth_field + 1`, checked
  !> (DEATH 0 means never). False when card 1 is missing (reported).
  logical function read_wall_card_one(deck, block, keyword, line, card, entry, birth_field, card_name, log) &
    result(found)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    integer, intent(inout) :: line
    type(card_t), intent(inout) :: card
    type(wall_input_t), intent(inout) :: entry
    integer, intent(in) :: birth_field
    character(len=*), intent(in) :: card_name
    type(problem_log_t), intent(inout) :: log
    integer :: box

    found = .true.
    entry%id_given = keyword%id
    entry%wall%title = ""
    if (keyword%id) then
      call id_heading(deck, block, line, "RWID", entry%wall%id, entry%wall%title, log)
      if (entry%wall%id <= 0) call line_problem(deck, log, line, block, "RWID", "wall id must "// &
                                                "be > 0, found "//integer_text(entry%wall%id))
      found = require_card(deck, block, line, standard_widths, card, log, card_name, "NSID")
      if (.not. found) return
    else
      call open_card(deck, block, line, standard_widths, card, log)
    end if
    entry%line = line
    call get_integer(deck, card, 1, "NSID", entry%node_set, log)
    call get_integer(deck, card, 2, "NSIDEX", entry%exempt_set, log)
    call get_integer(deck, card, 3, "BOXID", box, log)
    call get_real(deck, card, birth_field, "BIRTH", entry%wall%birth, log)
    call get_real(deck, card, birth_field + 1, "DEATH", entry%wall%death, log)
    if (entry%wall%death == 0.0_wp) entry%wall%death = 1.0e20_wp
    call check_set_id(deck, card, 1, "NSID", entry%node_set, log)
    call check_set_id(deck, card, 2, "NSIDEX", entry%exempt_set, log)
    call check_set_id(deck, card, 3, "BOXID", box, log)
    entry%box_id = max(box, 0)
    if (entry%wall%death <= entry%wall%birth) call card_problem(deck, log, card, "DEATH", "death "// &
      "time "//real_text(entry%wall%death)//" must be later than the birth time "// &
      real_text(entry%wall%birth))
  end function read_wall_card_one

  !> *RIGIDWALL_PLANAR(_FINITE)(_MOVING)(_FORCES)(_DISPLAY)(_ID): [RWID heading], card 1 NSID
  !> NSIDEX BOXID OFFSET BIRTH DEATH RWKSF, card 2 XT YT ZT XH YH ZH FRIC WVEL, then the option
  !> cards in the order FINITE, MOVING, FORCES, DISPLAY.
  subroutine read_planar_walls(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, n

    line = 0
    if (.not. has_data(deck, block, log, "card 1 (NSID NSIDEX BOXID OFFSET BIRTH DEATH RWKSF)", &
                       "NSID")) return
    do while (next_line(deck, block, line, .false.))
      n = input%wall_count + 1
      input%wall_count = n
      associate (entry => input%walls(n), wall => input%walls(n)%wall)
        if (.not. read_wall_card_one(deck, block, keyword, line, card, entry, 5, "card 1 (NSID "// &
                                     "NSIDEX BOXID OFFSET BIRTH DEATH RWKSF)", log)) exit
        call get_real(deck, card, 4, "OFFSET", wall%offset, log)
        if (wall%offset < 0.0_wp) call card_problem(deck, log, card, "OFFSET", "must be >= 0, "// &
                                                    "found "//real_text(wall%offset))
        if (.not. require_card(deck, block, line, standard_widths, card, log, &
                               "card 2 (XT YT ZT XH YH ZH FRIC WVEL)", "XT")) exit
        call read_wall_plane(deck, card, entry%wall, log)
        if (keyword%finite) then
          if (.not. require_card(deck, block, line, standard_widths, card, log, "the FINITE "// &
                                 "card (XHEV YHEV ZHEV LENL LENM)", "XHEV")) exit
          call read_wall_edges(deck, card, entry%wall, log)
        end if
        if (keyword%moving) then
          if (.not. require_card(deck, block, line, standard_widths, card, log, &
                                 "the MOVING card (MASS V0)", "MASS")) exit
          call read_wall_motion(deck, card, entry%wall, log)
        end if
        wall%forces_requested = keyword%forces
        if (keyword%forces) then
          if (.not. require_card(deck, block, line, standard_widths, card, log, &
                                 "the FORCES card (SOFT SSID N1 N2 N3 N4)", "SOFT")) exit
          call warn_if_set(deck, card, 1, "SOFT", "the wall force is not softened", warnings)
        end if
        ! the DISPLAY card may be left out at the end of the keyword (LS-DYNA reads it as
        ! defaults; public decks do so): it only shows the wall in a post-processor
        if (keyword%display) then
          if (next_line(deck, block, line, .false.)) call note_display_card(deck, line, warnings)
        end if
      end associate
    end do
  end subroutine read_planar_walls

  !> *RIGIDWALL_GEOMETRIC_CYLINDER(_MOTION)(_DISPLAY)(_ID): [RWID heading], card 1 NSID NSIDEX
  !> BOXID BIRTH DEATH, card 2 XT YT ZT XH YH ZH FRIC (tail and head of the axis), card 3
  !> RADCYL LENCYL NSEGS, then the MOTION card LCID OPT VX VY VZ and the DISPLAY card PID RO E
  !> PR (read, and noted as not used: it only shows the wall in a post-processor).
  !> Subsections (NSEGS > 0, whose VL HEIGHT cards are skipped) are reported as not available.
  subroutine read_cylinder_walls(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, n, segments, k

    line = 0
    if (.not. has_data(deck, block, log, "card 1 (NSID NSIDEX BOXID BIRTH DEATH)", "NSID")) return
    do while (next_line(deck, block, line, .false.))
      n = input%wall_count + 1
      input%wall_count = n
      associate (entry => input%walls(n), wall => input%walls(n)%wall)
        wall%kind = wall_cylinder
        if (.not. read_wall_card_one(deck, block, keyword, line, card, entry, 4, "card 1 (NSID "// &
                                     "NSIDEX BOXID BIRTH DEATH)", log)) exit
        if (.not. require_card(deck, block, line, standard_widths, card, log, &
                               "card 2 (XT YT ZT XH YH ZH FRIC)", "XT")) exit
        call read_wall_plane(deck, card, entry%wall, log)
        if (.not. require_card(deck, block, line, standard_widths, card, log, &
                               "card 3 (RADCYL LENCYL NSEGS)", "RADCYL")) exit
        call get_real(deck, card, 1, "RADCYL", wall%radius, log)
        call get_real(deck, card, 2, "LENCYL", wall%length, log)
        call get_integer(deck, card, 3, "NSEGS", segments, log)
        if (.not. card%failed .and. wall%radius <= 0.0_wp) call card_problem(deck, log, card, &
          "RADCYL", "the cylinder radius must be > 0, found "//real_text(wall%radius))
        if (wall%length < 0.0_wp) wall%length = 0.0_wp
        if (segments > 0) then
          call card_problem(deck, log, card, "NSEGS", "cylinder subsections (NSEGS > 0) are "// &
                            "not available; use NSEGS = 0, found "//integer_text(segments))
          ! skip the VL HEIGHT cards so that the next wall is read from its own card 1
          do k = 1, segments
            if (.not. require_card(deck, block, line, standard_widths, card, log, &
                                   "the subsection card (VL HEIGHT)", "VL")) exit
          end do
        end if
        if (keyword%motion) then
          if (.not. require_card(deck, block, line, standard_widths, card, log, &
                                 "the MOTION card (LCID OPT VX VY VZ)", "LCID")) exit
          entry%motion_line = line
          call get_integer(deck, card, 1, "LCID", wall%motion_curve_id, log)
          call get_integer(deck, card, 2, "OPT", wall%motion_option, log)
          call read_vector(deck, card, 3, ["VX", "VY", "VZ"], wall%motion_direction, log)
          if (.not. card%failed) call check_cylinder_motion(deck, card, wall, log)
        end if
        ! the DISPLAY card may be left out at the end of the keyword (LS-DYNA reads it as
        ! defaults; public decks do so): it only shows the wall in a post-processor
        if (keyword%display) then
          if (next_line(deck, block, line, .false.)) call note_display_card(deck, line, warnings)
        end if
      end associate
    end do
  end subroutine read_cylinder_walls

  !> The DISPLAY card of a wall (PID RO E PR) only shows the wall in a post-processor.
  subroutine note_display_card(deck, line, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: line
    type(error_list_t), intent(inout) :: warnings
    call located_warning(deck, warnings, line, "PID RO E PR", "the DISPLAY card is read but "// &
                         "not used: it only shows the wall in a post-processor")
  end subroutine note_display_card

  !> The MOTION card of a cylinder, read: a curve, OPT 0 or 1, a direction (normalised here).
  subroutine check_cylinder_motion(deck, card, wall, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(in) :: card
    type(rigid_wall_t), intent(inout) :: wall
    type(problem_log_t), intent(inout) :: log
    real(wp) :: length
    if (wall%motion_curve_id <= 0) call card_problem(deck, log, card, "LCID", "the "// &
      "motion needs a curve (LCID > 0), found "//integer_text(wall%motion_curve_id))
    if (wall%motion_option /= 0 .and. wall%motion_option /= 1) call card_problem(deck, log, &
      card, "OPT", "must be 0 (velocity) or 1 (displacement), found "// &
      integer_text(wall%motion_option))
    length = norm2(wall%motion_direction)
    if (length == 0.0_wp) then
      call card_problem(deck, log, card, "VX", "the motion direction (VX VY VZ) has zero length")
    else
      wall%motion_direction = wall%motion_direction/length
    end if
  end subroutine check_cylinder_motion

  !> Card 2: tail (a point of the wall) and head of the normal, friction.
  subroutine read_wall_plane(deck, card, wall, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    type(rigid_wall_t), intent(inout) :: wall
    type(problem_log_t), intent(inout) :: log
    real(wp) :: head(3), length
    call read_vector(deck, card, 1, ["XT", "YT", "ZT"], wall%point, log)
    call read_vector(deck, card, 4, ["XH", "YH", "ZH"], head, log)
    call get_real(deck, card, 7, "FRIC", wall%friction, log)
    if (card%failed) return
    length = norm2(head - wall%point)
    if (length == 0.0_wp) then
      call card_problem(deck, log, card, "XH", "the normal from the tail (XT YT ZT) to the "// &
                        "head (XH YH ZH) has zero length")
    else
      wall%normal = (head - wall%point)/length
    end if
    if (wall%friction < 0.0_wp .or. wall%friction > 1.0_wp) then
      if (wall%friction == 2.0_wp .or. wall%friction == 3.0_wp) then
        call card_problem(deck, log, card, "FRIC", "welding walls (FRIC 2 or 3) are not "// &
                          "available; use a Coulomb coefficient 0-1")
      else
        call card_problem(deck, log, card, "FRIC", "must be a Coulomb coefficient 0-1, found "// &
                          real_text(wall%friction))
      end if
    end if
  end subroutine read_wall_plane

  !> FINITE card: head of the edge vector l (its tail is XT YT ZT), lengths along l and m.
  subroutine read_wall_edges(deck, card, wall, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    type(rigid_wall_t), intent(inout) :: wall
    type(problem_log_t), intent(inout) :: log
    real(wp) :: head(3), edge(3), length
    wall%finite = .true.
    call read_vector(deck, card, 1, ["XHEV", "YHEV", "ZHEV"], head, log)
    call get_real(deck, card, 4, "LENL", wall%length_l, log)
    call get_real(deck, card, 5, "LENM", wall%length_m, log)
    if (card%failed) return
    ! only the part of l in the wall's plane matters
    edge = head - wall%point
    edge = edge - dot_product(edge, wall%normal)*wall%normal
    length = norm2(edge)
    if (length <= 1.0e-12_wp*max(norm2(head - wall%point), tiny(1.0_wp))) then
      call card_problem(deck, log, card, "XHEV", "the edge vector l from (XT YT ZT) to "// &
                        "(XHEV YHEV ZHEV) is zero or along the normal")
    else
      wall%edge_direction = edge/length
    end if
    if (wall%length_l < 0.0_wp) call card_problem(deck, log, card, "LENL", "must be >= 0, "// &
                                                  "found "//real_text(wall%length_l))
    if (wall%length_m < 0.0_wp) call card_problem(deck, log, card, "LENM", "must be >= 0, "// &
                                                  "found "//real_text(wall%length_m))
  end subroutine read_wall_edges

  !> MOVING card: the wall's mass and initial speed along the normal.
  subroutine read_wall_motion(deck, card, wall, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    type(rigid_wall_t), intent(inout) :: wall
    type(problem_log_t), intent(inout) :: log
    wall%moving = .true.
    call get_real(deck, card, 1, "MASS", wall%mass, log)
    call get_real(deck, card, 2, "V0", wall%initial_speed, log)
    if (.not. card%failed .and. wall%mass <= 0.0_wp) call card_problem(deck, log, card, &
      "MASS", "a moving wall needs a mass > 0, found "//real_text(wall%mass))
  end subroutine read_wall_motion

  !> Skip the _ID card (ID, heading) when the keyword has it: spcs and motions have no id in
  !> the model. False when the block is empty.
  logical function skip_id_card(deck, block, keyword, line, log)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    integer, intent(inout) :: line
    type(problem_log_t), intent(inout) :: log
    integer :: id
    character(len=:), allocatable :: heading
    skip_id_card = .true.
    if (.not. keyword%id) return
    skip_id_card = next_line(deck, block, line, .false.)
    if (skip_id_card) call id_heading(deck, block, line, "ID", id, heading, log)
  end function skip_id_card

  !> Field 1: a node id (> 0) or, for `by_set`, a node set id (> 0).
  subroutine read_target(deck, card, by_set, target, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    logical, intent(in) :: by_set
    integer, intent(out) :: target
    type(problem_log_t), intent(inout) :: log
    if (by_set) then
      call get_integer(deck, card, 1, "NSID", target, log)
      if (target <= 0 .and. .not. card%failed) call card_problem(deck, log, card, "NSID", &
        "node set id must be > 0, found "//integer_text(target))
    else
      call get_integer(deck, card, 1, "NID", target, log)
      if (target <= 0 .and. .not. card%failed) call card_problem(deck, log, card, "NID", &
        "node id must be > 0, found "//integer_text(target))
    end if
  end subroutine read_target

  !> A set id field where 0 keeps LS-DYNA's meaning (all nodes, or none exempted).
  subroutine check_set_id(deck, card, k, name, id, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(in) :: card
    integer, intent(in) :: k
    character(len=*), intent(in) :: name
    integer, intent(in) :: id
    type(problem_log_t), intent(inout) :: log
    if (id < 0 .and. .not. card%failed) call card_problem(deck, log, card, name, "must be "// &
      ">= 0, found "//integer_text(id)//" (field "//integer_text(k)//")")
  end subroutine check_set_id

  !> A load curve id is required (LS-DYNA has no default curve).
  subroutine check_curve_given(deck, card, k, curve_id, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(in) :: card
    integer, intent(in) :: k, curve_id
    type(problem_log_t), intent(inout) :: log
    if (curve_id <= 0) call card_problem(deck, log, card, "LCID", "a load curve id > 0 is "// &
      "required (field "//integer_text(k)//"), found "//integer_text(curve_id))
  end subroutine check_curve_given

  !> Three consecutive real fields from field `first`.
  subroutine read_vector(deck, card, first, names, vector, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    integer, intent(in) :: first
    character(len=*), intent(in) :: names(3)
    real(wp), intent(out) :: vector(3)
    type(problem_log_t), intent(inout) :: log
    integer :: k
    do k = 1, 3
      call get_real(deck, card, first + k - 1, trim(names(k)), vector(k), log)
    end do
  end subroutine read_vector

  subroutine warn_rotations(deck, card, first, names, warnings)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(in) :: card
    integer, intent(in) :: first
    character(len=*), intent(in) :: names(3)
    type(error_list_t), intent(inout) :: warnings
    integer :: k
    do k = 1, 3
      call warn_if_set(deck, card, first + k - 1, trim(names(k)), no_rotations, warnings)
    end do
  end subroutine warn_rotations

  subroutine add_velocity(input, velocity)
    type(deck_input_t), intent(inout) :: input
    type(velocity_input_t), intent(in) :: velocity
    input%velocity_count = input%velocity_count + 1
    input%velocities(input%velocity_count) = velocity
  end subroutine add_velocity
end module deck_loads_bcs
