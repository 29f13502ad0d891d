!> What the rigid-body keywords collect before the cross-check: *MAT_RIGID constraint cards,
!> *BOUNDARY_PRESCRIBED_MOTION_RIGID lines, *CONSTRAINED_NODAL_RIGID_BODY lines,
!> *ELEMENT_MASS lines and spot welds, as written (ids, not indices), with the deck line of each.
!> The readers are in deck_rigid_bodies; this module only holds the lists so that
!> deck_input can keep them beside the rest of the input.
module deck_rigid_input
  use kinds, only: wp
  implicit none
  private

  public :: rigid_input_t, rigid_material_input_t, rigid_motion_input_t, nodal_rigid_input_t
  public :: element_mass_input_t, spot_weld_input_t, rigid_link_input_t

  !> What a rigid_link_input_t adds: a node or a node set to a rigid body, or a rigid part to another.
  integer, parameter, public :: link_extra_node = 1, link_extra_set = 2, link_merge = 3

  !> Card 2 of one *MAT_RIGID: the constraint codes, and the position of the material in
  !> the input's material list.
  type :: rigid_material_input_t
    integer :: material = 0          !< position in input%model%materials
    integer :: constraint_mode = 0   !< CMO: 0 none, 1 global (the only mode built)
    integer :: translations = 0      !< CON1: 0-7 (0 none, 1 x, 2 y, 3 z, 4 xy, 5 yz, 6 zx, 7 xyz)
    integer :: rotations = 0         !< CON2: same codes for the rotations
    integer :: line = 0              !< card 2 (0: not given)
  end type rigid_material_input_t

  !> One *BOUNDARY_PRESCRIBED_MOTION_RIGID line.
  type :: rigid_motion_input_t
    integer :: part_id = 0
    integer :: dof = 0               !< 1-3 translations, 5-7 rotations (as written)
    integer :: kind = 0              !< VAD
    integer :: curve_id = 0
    real(wp) :: scale = 1.0_wp, birth = 0.0_wp, death = 1.0e28_wp
    integer :: line = 0
  end type rigid_motion_input_t

  !> One *CONSTRAINED_NODAL_RIGID_BODY line.
  type :: nodal_rigid_input_t
    integer :: id = 0                !< PID
    integer :: node_set = 0          !< NSID (PID when blank)
    integer :: line = 0
  end type nodal_rigid_input_t

  !> One *ELEMENT_MASS line.
  type :: element_mass_input_t
    integer :: id = 0, node_id = 0
    real(wp) :: mass = 0.0_wp
    integer :: line = 0
  end type element_mass_input_t

  !> One *CONSTRAINED_SPOTWELD (two nodes) or *CONSTRAINED_GENERALIZED_WELD_SPOT (a node set).
  type :: spot_weld_input_t
    integer :: id = 0                !< WID (0: numbered in deck order)
    integer :: node_ids(2) = 0       !< N1 N2 (a spot weld)
    integer :: node_set = 0          !< NSID (a generalized weld; 0 for a spot weld)
    real(wp) :: normal_strength = 0.0_wp, shear_strength = 0.0_wp
    real(wp) :: normal_exponent = 2.0_wp, shear_exponent = 2.0_wp
    real(wp) :: failure_plastic_strain = 0.0_wp  !< EP / EPSF (0: none)
    real(wp) :: failure_time = 1.0e20_wp
    integer :: line = 0              !< the card with the nodes (or the set)
  end type spot_weld_input_t

  !> One *CONSTRAINED_EXTRA_NODES_NODE / _SET line (PID NID / NSID) or *CONSTRAINED_RIGID_BODIES
  !> line (PIDM PIDS).
  type :: rigid_link_input_t
    integer :: kind = 0              !< link_extra_node, link_extra_set, link_merge
    integer :: body_id = 0           !< PID (PIDM)
    integer :: other_id = 0          !< NID, NSID or PIDS
    integer :: line = 0
  end type rigid_link_input_t

  !> All rigid-body input; each list holds `*_count` entries and grows by doubling.
  type :: rigid_input_t
    integer :: material_count = 0, motion_count = 0, nodal_count = 0, mass_count = 0, weld_count = 0, link_count = 0
    type(rigid_material_input_t), allocatable :: materials(:)
    type(rigid_motion_input_t), allocatable :: motions(:)
    type(nodal_rigid_input_t), allocatable :: nodal(:)
    type(element_mass_input_t), allocatable :: masses(:)
    type(spot_weld_input_t), allocatable :: welds(:)
    type(rigid_link_input_t), allocatable :: links(:)
  end type rigid_input_t
end module deck_rigid_input
