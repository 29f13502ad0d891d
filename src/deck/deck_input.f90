!> What the keyword readers collect before the cross-check: the model with ids where indices
!> will go, the deck lines every definition came from, and the loads and conditions as written
!> (by node or by set) before they are expanded per node.
module deck_input
  use kinds, only: wp
  use integer_lists, only: reserve_integers
  use model, only: model_t, rigid_wall_t, segment_load_t
  use deck_rigid_input, only: rigid_input_t
  use deck_tied_input, only: tied_input_t
  use deck_contact_input, only: contact_input_t
  implicit none
  private

  public :: id_list_t, set_input_t, spc_input_t, motion_input_t, load_input_t
  public :: velocity_input_t, wall_input_t, segment_set_input_t, segment_load_input_t
  public :: deck_input_t, prepare_input, append_id, add_erosion_input_t
  public :: box_input_t, frame_input_t, vector_input_t

  !> The lists of definitions the keyword readers fill, one entry per definition. Each keyword
  !> table row names the lists its definitions go to (deck_keyword_table), and prepare_input
  !> sizes every list from the data lines (or blocks) of the keywords that fill it, so that no
  !> reader needs to grow one. Lists of ids (set members, history nodes) grow (append_id).
  integer, parameter, public :: list_none = 0, list_nodes = 1, list_solids = 2, list_shells = 3, &
    list_parts = 4, list_sections = 5, list_materials = 6, list_hourglasses = 7, list_curves = 8, &
    list_node_sets = 9, list_part_sets = 10, list_spcs = 11, list_motions = 12, list_loads = 13, &
    list_velocities = 14, list_walls = 15, list_segment_sets = 16, list_segment_loads = 17, &
    list_rigid_materials = 18, list_rigid_motions = 19, list_nodal_rigid_bodies = 20, &
    list_element_masses = 21, list_contacts = 22, list_boxes = 23, list_frames = 24, list_vectors = 25, &
    list_spot_welds = 26, list_rigid_links = 27, list_tied_contacts = 28, list_beams = 29, &
    list_body_loads = 30
  !> Number of lists.
  integer, parameter, public :: list_count = 30

  !> How a set's members are given (set_input_t%kind): listed ids (or ranges when `generated`),
  !> *SET_NODE_GENERAL operations, or *SET_..._ADD set ids.
  integer, parameter, public :: set_listed = 0, set_general = 1, set_added = 2
  !> *SET_NODE_GENERAL operations (the ids of set_input_t%operations), applied in deck order.
  integer, parameter, public :: general_all = 1, general_node = 2, general_part = 3, &
    general_box = 4, general_remove_node = 5, general_remove_part = 6, general_remove_box = 7
  !> How a coordinate system is given (frame_input_t%kind).
  integer, parameter, public :: frame_by_points = 1, frame_by_nodes = 2, frame_by_vectors = 3

  !> How an initial velocity was given.
  integer, parameter, public :: velocity_by_set = 1, velocity_by_node = 2, &
                                velocity_generation = 3

  !> Ids as written, with the line and field (1-8) each came from.
  type :: id_list_t
    integer :: count = 0
    integer, allocatable :: ids(:), lines(:), fields(:)
  end type id_list_t

  !> One *SET_NODE(_LIST)(_GENERATE), *SET_NODE_GENERAL, *SET_NODE_ADD, *SET_PART(_LIST)
  !> (_GENERATE) or *SET_PART_ADD. For a generated set `members` holds pairs (first id, last id)
  !> of the ranges; for an added set the ids of its sets; for a general set the entity ids of
  !> every operation, one after another.
  type :: set_input_t
    integer :: id = 0
    character(len=:), allocatable :: title
    integer :: line = 0
    logical :: generated = .false.
    integer :: kind = set_listed
    type(id_list_t) :: members
    !> *SET_NODE_GENERAL: one entry per operation line: the operation (general_...) as id, its
    !> line, and as field the number of entity ids it put into `members`.
    type(id_list_t) :: operations
  end type set_input_t

  !> *DEFINE_BOX(_LOCAL): the box [minimum, maximum] in its own axes. A local box's axes are the
  !> columns of `axes` (global components) with origin `origin`; a plain box has the global ones.
  type :: box_input_t
    integer :: id = 0
    character(len=:), allocatable :: title
    real(wp) :: minimum(3) = 0.0_wp, maximum(3) = 0.0_wp
    real(wp) :: axes(3, 3) = reshape([1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, &
                                      0.0_wp, 0.0_wp, 1.0_wp], [3, 3])
    real(wp) :: origin(3) = 0.0_wp
    integer :: line = 0
  end type box_input_t

  !> *DEFINE_COORDINATE_SYSTEM (three points: origin, a point on local x, a point in the local
  !> x-y plane), _NODES (the same by three node ids, resolved in the cross-check) or _VECTOR
  !> (local x and a vector in the local x-y plane). The cross-check fills `axes` (columns: unit
  !> local x, y, z in global components) and `origin`, and sets `usable`.
  type :: frame_input_t
    integer :: id = 0
    character(len=:), allocatable :: title
    integer :: kind = frame_by_points
    real(wp) :: points(3, 3) = 0.0_wp      !< origin, x point, plane point (or x and plane vectors)
    integer :: nodes(3) = 0                !< N1 N2 N3 of _NODES (ids)
    integer :: origin_node = 0             !< NID of _VECTOR (0: the global origin)
    logical :: follows_nodes = .false.     !< FLAG = 1 of _NODES (taken at its initial position)
    real(wp) :: axes(3, 3) = 0.0_wp
    real(wp) :: origin(3) = 0.0_wp
    logical :: usable = .false.
    integer :: line = 0
  end type frame_input_t

  !> *DEFINE_VECTOR: from tail to head, in the coordinate system `frame_id` (0: global). The
  !> cross-check fills `direction` (unit, global components) and sets `usable`.
  type :: vector_input_t
    integer :: id = 0
    character(len=:), allocatable :: title
    real(wp) :: tail(3) = 0.0_wp, head(3) = 0.0_wp
    integer :: frame_id = 0
    real(wp) :: direction(3) = 0.0_wp
    logical :: usable = .false.
    integer :: line = 0
  end type vector_input_t

  !> *SET_SEGMENT(_TITLE): card 1 as for the other sets (`members` is not used), then the
  !> segments as written: node ids, N4 = N3 for a triangle. The cross-check turns the ids into
  !> node indices.
  type, extends(set_input_t) :: segment_set_input_t
    integer :: count = 0
    integer, allocatable :: nodes(:, :)     !< (4, count)
    integer, allocatable :: lines(:)        !< the line of each segment
    !> False once a problem of the segment was reported (a bad id, a repeated node; in the
    !> cross-check an undefined node or no area), so that loads skip it without repeating it.
    logical, allocatable :: usable(:)
  end type segment_set_input_t

  !> One *LOAD_SEGMENT(_ID) or *LOAD_SEGMENT_NONUNIFORM(_ID) segment (node ids in
  !> `load%nodes`), or one *LOAD_SEGMENT_SET(_ID) line (`segment_set` > 0), before ids are
  !> resolved.
  type :: segment_load_input_t
    type(segment_load_t) :: load
    integer :: curve_id = 0
    integer :: segment_set = 0          !< SSID (0: the one segment in load%nodes)
    logical :: usable = .true.          !< false once a problem of its nodes was reported
    integer :: line = 0                 !< the card with LCID
    integer :: node_line = 0            !< the card with N1-N4
  end type segment_load_input_t

  !> *BOUNDARY_SPC_NODE/_SET line (or a *NODE TC code): `target` is a node or set id.
  type :: spc_input_t
    integer :: target = 0
    logical :: is_set = .false.
    logical :: fixed(3) = .false.
    logical :: fixed_rotation(3) = .false.  !< DOFRX DOFRY DOFRZ
    integer :: frame_id = 0                 !< CID: the DOFs are along its axes (0: global)
    integer :: line = 0
  end type spc_input_t

  !> *BOUNDARY_PRESCRIBED_MOTION_NODE/_SET line.
  type :: motion_input_t
    integer :: target = 0
    logical :: is_set = .false.
    integer :: direction = 0, kind = 0, curve_id = 0
    real(wp) :: scale = 1.0_wp, birth = 0.0_wp, death = 1.0e28_wp
    integer :: vector_id = 0                !< VID: the direction of DOF 4 and -4
    integer :: line = 0
  end type motion_input_t

  !> *LOAD_NODE_POINT/_SET line.
  type :: load_input_t
    integer :: target = 0
    logical :: is_set = .false.
    integer :: direction = 0, curve_id = 0
    real(wp) :: scale = 1.0_wp
    integer :: line = 0
  end type load_input_t

  !> *INITIAL_VELOCITY (by node set), _NODE or _GENERATION definition.
  type :: velocity_input_t
    integer :: kind = velocity_by_set
    integer :: target = 0             !< NSID, NID or ID (0: all nodes)
    integer :: target_type = 1        !< STYP of _GENERATION: 1 part set, 2 part, 3 node set
    integer :: exempt_set = 0         !< NSIDEX
    integer :: box_id = 0             !< BOXID: only nodes inside the box (0: no box)
    integer :: frame_id = 0           !< ICID: velocities (and axis) in this system (0: global)
    real(wp) :: velocity(3) = 0.0_wp
    real(wp) :: exempt_velocity(3) = 0.0_wp
    real(wp) :: omega = 0.0_wp        !< angular velocity about the axis
    real(wp) :: centre(3) = 0.0_wp    !< point on the axis
    real(wp) :: axis(3) = 0.0_wp      !< unit axis direction
    integer :: axis_nodes(2) = 0      !< NX = -999: NY, NZ are nodes on the axis
    integer :: line = 0               !< first card
    integer :: axis_line = 0          !< card with the axis
  end type velocity_input_t

  !> *RIGIDWALL_PLANAR or *RIGIDWALL_GEOMETRIC_CYLINDER definition; its node sets (and curve) are resolved later.
  type :: wall_input_t
    type(rigid_wall_t) :: wall
    integer :: node_set = 0, exempt_set = 0
    integer :: box_id = 0             !< BOXID: only tracked nodes inside the box (0: no box)
    logical :: id_given = .false.
    integer :: line = 0               !< card 1 (NSID)
    integer :: motion_line = 0        !< the MOTION card of a cylinder (LCID)
  end type wall_input_t

  !> Everything read, before ids are resolved. Arrays are sized by prepare_input and hold
  !> `*_count` entries.
  !> One *MAT_ADD_EROSION as read (deck_add_erosion), applied to its material once the
  !> materials are indexed.
  type :: add_erosion_input_t
    integer :: material_id = 0             !< MID
    integer :: line = 0                    !< card 1
    real(wp) :: plastic_strain = 0.0_wp    !< EFFEPS
    real(wp) :: max_principal = 0.0_wp     !< MXEPS
    real(wp) :: min_principal = 0.0_wp     !< MNEPS
    real(wp) :: failed_points = 0.0_wp     !< NUMFIP (0: blank)
  end type add_erosion_input_t

  type :: deck_input_t
    type(model_t) :: model
    integer :: node_count = 0, solid_count = 0, part_count = 0, section_count = 0
    integer :: material_count = 0, hourglass_count = 0, curve_count = 0
    integer :: node_set_count = 0, part_set_count = 0, spc_count = 0, motion_count = 0
    integer :: load_count = 0, velocity_count = 0, wall_count = 0, body_load_count = 0
    integer :: segment_set_count = 0, segment_load_count = 0
    integer :: box_count = 0, frame_count = 0, vector_count = 0
    type(box_input_t), allocatable :: boxes(:)
    type(frame_input_t), allocatable :: frames(:)
    type(vector_input_t), allocatable :: vectors(:)
    integer, allocatable :: node_lines(:), node_constraints(:)     !< TC code of each node
    integer, allocatable :: node_rotation_constraints(:)           !< RC code of each node
    integer, allocatable :: solid_lines(:), solid_node_lines(:)   !< PID card, node card
    !> *ELEMENT_SHELL(_THICKNESS): the element card and the THIC card (the element card for
    !> *ELEMENT_SHELL). model%shell_thickness holds THIC1-4 as read (0: the section's).
    integer :: shell_count = 0
    integer, allocatable :: shell_lines(:), shell_thickness_lines(:)
    !> *ELEMENT_BEAM: the element card of each beam (deck_beams).
    integer :: beam_count = 0
    integer, allocatable :: beam_lines(:)
    integer, allocatable :: part_lines(:), section_lines(:), material_lines(:)
    integer, allocatable :: hourglass_lines(:), curve_lines(:)
    type(set_input_t), allocatable :: node_sets(:), part_sets(:)
    type(spc_input_t), allocatable :: spcs(:)
    type(motion_input_t), allocatable :: motions(:)
    type(load_input_t), allocatable :: loads(:)
    !> *LOAD_BODY_X/_Y/_Z: direction, curve, scale (target unused: every node)
    type(load_input_t), allocatable :: body_loads(:)
    type(velocity_input_t), allocatable :: velocities(:)
    type(wall_input_t), allocatable :: walls(:)
    type(segment_set_input_t), allocatable :: segment_sets(:)
    type(segment_load_input_t), allocatable :: segment_loads(:)
    type(rigid_input_t) :: rigid           !< *MAT_RIGID, rigid motions, nodal rigid bodies, masses
    type(contact_input_t) :: contact       !< *CONTACT_AUTOMATIC_... definitions
    type(tied_input_t) :: tied             !< *CONTACT_TIED_..., *CONTACT_SPOTWELD definitions
    type(add_erosion_input_t), allocatable :: add_erosions(:)  !< *MAT_ADD_EROSION, in deck order
    !> *DATABASE_HISTORY_NODE(_SET) requests in deck order; a node set id is stored with a
    !> negative field number (-k for field IDk) so that nodes and sets keep their order.
    type(id_list_t) :: history_requests
    ! controls whose meaning depends on other keywords
    integer :: termination_line = 0        !< *CONTROL_TERMINATION card (0: not given)
    integer :: plot_count = 0              !< *DATABASE_BINARY_D3PLOT NPLTC
    integer :: plot_line = 0
    integer :: nodout_line = 0
    integer :: implicit_solution_line = 0  !< *CONTROL_IMPLICIT_SOLUTION card (0: not given)
    integer :: implicit_solver = 0         !< its NSOLVR (0: blank)
    real(wp) :: bulk_quadratic = 1.5_wp    !< *CONTROL_BULK_VISCOSITY Q1
    real(wp) :: bulk_linear = 0.06_wp      !< *CONTROL_BULK_VISCOSITY Q2
  end type deck_input_t

contains

  !> Allocate every list for `capacity(list)` definitions (an upper bound: deck_reader counts
  !> them from the data lines or blocks of the keywords that fill each list).
  subroutine prepare_input(capacity, input)
    integer, intent(in) :: capacity(list_count)
    type(deck_input_t), intent(out) :: input
    integer :: n

    n = capacity(list_nodes)
    allocate (input%model%node_ids(n), input%model%coordinates(3, n), input%node_lines(n), &
              input%node_constraints(n), input%node_rotation_constraints(n))
    n = capacity(list_solids)
    allocate (input%model%solid_ids(n), input%model%solid_part(n), input%model%solid_nodes(8, n), &
              input%solid_lines(n), input%solid_node_lines(n))
    n = capacity(list_shells)
    allocate (input%model%shell_ids(n), input%model%shell_part(n), input%model%shell_nodes(4, n), &
              input%model%shell_thickness(4, n), input%shell_lines(n), input%shell_thickness_lines(n))
    n = capacity(list_beams)
    allocate (input%model%beam_ids(n), input%model%beam_part(n), input%model%beam_nodes(3, n), input%beam_lines(n))
    n = capacity(list_parts)
    allocate (input%model%parts(n), input%part_lines(n))
    n = capacity(list_sections)
    allocate (input%model%sections(n), input%section_lines(n))
    n = capacity(list_materials)
    allocate (input%model%materials(n), input%material_lines(n))
    n = capacity(list_hourglasses)
    allocate (input%model%hourglasses(n), input%hourglass_lines(n))
    n = capacity(list_curves)
    allocate (input%model%curves(n), input%curve_lines(n))
    allocate (input%node_sets(capacity(list_node_sets)))
    allocate (input%part_sets(capacity(list_part_sets)))
    allocate (input%spcs(capacity(list_spcs)))
    allocate (input%motions(capacity(list_motions)))
    allocate (input%loads(capacity(list_loads)))
    allocate (input%body_loads(capacity(list_body_loads)))
    allocate (input%velocities(capacity(list_velocities)))
    allocate (input%walls(capacity(list_walls)))
    allocate (input%segment_sets(capacity(list_segment_sets)))
    allocate (input%segment_loads(capacity(list_segment_loads)))
    allocate (input%rigid%materials(capacity(list_rigid_materials)))
    allocate (input%rigid%motions(capacity(list_rigid_motions)))
    allocate (input%rigid%nodal(capacity(list_nodal_rigid_bodies)))
    allocate (input%rigid%masses(capacity(list_element_masses)))
    allocate (input%rigid%welds(capacity(list_spot_welds)))
    allocate (input%rigid%links(capacity(list_rigid_links)))
    allocate (input%tied%entries(capacity(list_tied_contacts)))
    allocate (input%contact%entries(capacity(list_contacts)))
    allocate (input%boxes(capacity(list_boxes)))
    allocate (input%frames(capacity(list_frames)))
    allocate (input%vectors(capacity(list_vectors)))
  end subroutine prepare_input

  !> Append one id with its origin (the list grows as needed).
  pure subroutine append_id(list, id, line, field)
    type(id_list_t), intent(inout) :: list
    integer, intent(in) :: id, line, field
    call reserve_integers(list%ids, list%count, list%count + 1)
    call reserve_integers(list%lines, list%count, list%count + 1)
    call reserve_integers(list%fields, list%count, list%count + 1)
    list%count = list%count + 1
    list%ids(list%count) = id
    list%lines(list%count) = line
    list%fields(list%count) = field
  end subroutine append_id
end module deck_input
