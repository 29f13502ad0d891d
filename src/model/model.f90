!> The checked model: everything the deck defines, with ids resolved to array indices.
!>
!> The deck reader builds a `model_t` and checks every cross reference before any cycle runs;
!> after that no code below the solver sees an id where it needs an index. Ids are kept beside
!> the indices for messages and output.
module model
  use kinds, only: wp
  use curves, only: curve_t
  use material_laws, only: law_null
  implicit none
  private

  public :: model_t, material_t, section_t, hourglass_t, part_t, node_set_t, part_set_t
  public :: spc_t, prescribed_motion_t, nodal_load_t, segment_load_t, rigid_wall_t, output_control_t
  public :: rigid_body_t, rigid_motion_t, spot_weld_t, tied_contact_t
  public :: local_spc_t
  public :: segment_set_t, contact_t, contact_surface_t

  !> The law codes and what each law can do are in material_laws' law_table. law_null is also
  !> reachable here for src/elements/shell_block.f90 and src/solver/run_checks.f90, which are
  !> being rewritten on another branch (they switch to material_laws after the merge).
  public :: law_null

  !> Curve slots of the crushable laws in material_t%curves (after the deck's defaults, such as
  !> LCB = 0 -> LCA, are applied): the six yield curves in stress order aa, bb, cc, ab, bc, ca,
  !> then the strain-rate scale curve LCSR (honeycombs); the loading curve LCID (foam).
  integer, parameter, public :: honeycomb_rate_curve = 7, foam_loading_curve = 1
  !> Curve slots of *MAT_PIECEWISE_LINEAR_PLASTICITY: the hardening curve (yield stress against
  !> effective plastic strain: LCSS, or the EPS1-8 / ES1-8 table turned into a curve; empty when
  !> SIGY and ETAN define bilinear hardening) and the strain-rate scale curve LCSR.
  integer, parameter, public :: piecewise_hardening_curve = 1, piecewise_rate_curve = 2

  !> How a part is discretised (`/mesh/parts/formulation`: "fe", "efg", "rigid").
  integer, parameter, public :: formulation_fe = 1, formulation_efg = 2, formulation_rigid = 3

  !> Prescribed-motion kinds (VAD).
  integer, parameter, public :: motion_velocity = 0, motion_acceleration = 1, motion_displacement = 2

  !> One material (*MAT_...). Fields not used by a law stay zero.
  type :: material_t
    integer :: id = 0
    integer :: law = 0                      !< law code (LS-DYNA's number): a row of law_table
    character(len=:), allocatable :: title
    real(wp) :: density = 0.0_wp            !< RO
    real(wp) :: youngs_modulus = 0.0_wp     !< E
    real(wp) :: poissons_ratio = 0.0_wp     !< PR
    ! *MAT_PLASTIC_KINEMATIC
    real(wp) :: yield_stress = 0.0_wp       !< SIGY
    real(wp) :: tangent_modulus = 0.0_wp    !< ETAN
    real(wp) :: hardening_beta = 0.0_wp     !< BETA: 0 kinematic ... 1 isotropic
    real(wp) :: rate_c = 0.0_wp             !< SRC, Cowper-Symonds C (0: no rate effect)
    real(wp) :: rate_p = 0.0_wp             !< SRP, Cowper-Symonds P (0: no rate effect)
    !> FS (MAT_003) / FAIL (MAT_024): effective plastic strain at which the element erodes
    !> (0 or >= 1e20: never)
    real(wp) :: failure_strain = 0.0_wp
    real(wp) :: rate_formulation = 0.0_wp   !< VP: 0 scale yield stress, 1 viscoplastic
    ! *MAT_PIECEWISE_LINEAR_PLASTICITY (SIGY, ETAN, FAIL, C, P, VP above; curves in the slots
    ! piecewise_hardening_curve and piecewise_rate_curve)
    real(wp) :: failure_time_step = 0.0_wp  !< TDEL: an element whose stable step falls below erodes (0: off)
    ! *MAT_SPOTWELD (E, PR, SIGY above; ET in tangent_modulus)
    real(wp) :: failure_time = 0.0_wp       !< TFAIL: the weld fails at this time (0: never)
    real(wp) :: failure_plastic_strain = 0.0_wp !< EFAIL: plastic strain at failure (0: none)
    !> NRR NRS NRT MRR MSS MTT: resultants at failure (0: that term is left out)
    real(wp) :: failure_resultants(6) = 0.0_wp
    ! *MAT_NULL
    real(wp) :: pressure_cutoff = 0.0_wp    !< PC (read and kept)
    ! *MAT_ADD_EROSION of this material (0: the criterion is off)
    logical :: has_add_erosion = .false.
    real(wp) :: erosion_plastic_strain = 0.0_wp       !< EFFEPS: effective plastic strain
    real(wp) :: erosion_max_principal_strain = 0.0_wp !< MXEPS: largest principal (logarithmic) strain
    real(wp) :: erosion_min_principal_strain = 0.0_wp !< MNEPS: smallest principal strain (< 0)
    !> NUMFIP: failed points before a shell erodes (> 0 a count, < 0 a percentage); without
    !> *MAT_ADD_EROSION a shell erodes when all its points failed (0 here)
    real(wp) :: erosion_failed_points = 0.0_wp
    ! *MAT_HONEYCOMB, *MAT_MODIFIED_HONEYCOMB (E, PR, SIGY above: the fully compacted material)
    real(wp) :: compaction_volume = 0.0_wp  !< VF: relative volume at full compaction, (0, 1]
    real(wp) :: viscosity = 0.0_wp          !< MU (honeycombs), DAMP (foam): viscous coefficient
    !> BULK (honeycombs) / BVFLAG (foam) = 1: the element bulk viscosity acts. LS-DYNA's default
    !> 0 switches it off for these laws (their own MU / DAMP replaces it).
    logical :: bulk_viscosity = .true.
    real(wp) :: uncompacted_moduli(6) = 0.0_wp !< EAAU EBBU ECCU GABU GBCU GCAU
    integer :: axes_option = 0              !< AOPT: 0 element nodes 1-2-4, 2 global vectors a, d
    real(wp) :: axis_a(3) = 0.0_wp          !< A1 A2 A3 (AOPT 2)
    real(wp) :: axis_d(3) = 0.0_wp          !< D1 D2 D3 (AOPT 2)
    ! *MAT_LOW_DENSITY_FOAM (E above: tension modulus)
    real(wp) :: tension_cutoff = 1.0e20_wp  !< TC: largest tensile (nominal) stress
    real(wp) :: hysteretic_unloading = 1.0_wp !< HU: 1 no dissipation ... 0 most
    real(wp) :: unloading_shape = 1.0_wp    !< SHAPE: exponent of the unloading factor
    ! *MAT_MOONEY-RIVLIN_RUBBER (PR above; E holds the small-strain 2 G (1 + nu), G = 2 (A + B))
    real(wp) :: mooney_rivlin_a = 0.0_wp    !< A
    real(wp) :: mooney_rivlin_b = 0.0_wp    !< B
    !> SGL SW ST: gauge length, width and thickness of the test specimen of LCID1 (whose curve
    !> gives the force against the change of gauge length; A and B are then fitted to it)
    real(wp) :: specimen_dimensions(3) = 0.0_wp
    ! *MAT_VISCOELASTIC (E, PR above hold the instantaneous moduli from BULK and G0)
    real(wp) :: long_term_shear_modulus = 0.0_wp !< GI
    real(wp) :: decay_constant = 0.0_wp     !< BETA: G(t) = GI + (G0 - GI) exp(-BETA t)
    !> Curve ids as given on the cards with LS-DYNA's defaults applied (0: none); the slots are
    !> honeycomb_rate_curve, foam_loading_curve, ... above.
    integer, allocatable :: curve_ids(:)
    !> Copies of those curves, resolved by the deck's cross-check (same slots; a slot whose id
    !> is 0 holds an empty curve). The law kernels read them through the material dispatch.
    type(curve_t), allocatable :: curves(:)
  end type material_t

  !> EFG kernels (ISPLINE) and boundary treatments (IEBT) and domain integrations (IDIM).
  !> The quadratic spline on a box support (ISPLINE 1) is read for meshfree shells only.
  integer, parameter, public :: kernel_cubic_box = 0, kernel_quadratic_box = 1, kernel_cubic_sphere = 2
  integer, parameter, public :: boundary_full_transformation = 1, boundary_coupled = 3
  integer, parameter, public :: integration_local_boundary = 1, integration_gauss = 2
  !> Conventional EFG: 4x4x4 Gauss points per cell with direct MLS gradients (IDIM = 4, a
  !> crashfree extension for the verification of Table 1 of the paper).
  integer, parameter, public :: integration_gauss_conventional = 4

  !> Section kinds (section_t%kind).
  integer, parameter, public :: section_solid = 1, section_shell = 2
  !> *SECTION_BEAM (section_t%kind).
  integer, parameter, public :: section_beam = 3
  !> Beam cross-section types (CST): rectangular, tubular (a solid circle when the wall is as
  !> thick as the radius).
  integer, parameter, public :: cross_section_rectangular = 0, cross_section_tubular = 1
  !> *SECTION_BEAM ELFORM of the resultant beam (section by A ISS ITT J SA).
  integer, parameter, public :: beam_resultant_formulation = 2

  !> One section: solid (*SECTION_SOLID, *SECTION_SOLID_EFG) or shell (*SECTION_SHELL).
  type :: section_t
    integer :: id = 0
    character(len=:), allocatable :: title
    integer :: kind = section_solid        !< section_solid or section_shell
    integer :: element_formulation = 1     !< ELFORM: 1 one-point, 2 fully integrated S/R, 41 EFG;
                                           !< shells: 2 Belytschko-Tsay, 41 meshfree (EFG) shell
    ! *SECTION_SHELL
    real(wp) :: shear_factor = 1.0_wp      !< SHRF: transverse shear correction (5/6 is usual)
    integer :: integration_points = 2      !< NIP through the thickness (1-10)
    real(wp) :: thickness(4) = 0.0_wp      !< T1-T4 at the element's nodes (T2-T4 default T1)
    real(wp) :: reference_surface = 0.0_wp !< NLOC: 0 mid surface, 1 top, -1 bottom
    ! EFG card (ELFORM 41), meaningful only for meshfree sections
    !> DX, DY, DZ: normalized support (> 1). Meshfree shells (*SECTION_SHELL ELFORM 41) use
    !> DX and DY, along the two tangent directions of each particle's frame; their DZ is DX.
    real(wp) :: support_scale(3) = 1.01_wp
    !> ISPLINE: 0 cubic spline, box; 1 quadratic spline, box (shells); 2 cubic spline, sphere
    !> (shells: a circle in the surface)
    integer :: kernel = kernel_cubic_box
    integer :: dilation_basis = 0          !< IDILA (0: from the nodes sharing an element)
    real(wp) :: kernel_tolerance = 0.0_wp  !< TOLDEF: 0 Lagrangian kernel (the only one built)
    integer :: boundary_treatment = boundary_coupled        !< IEBT: 3 coupled FE/EFG, 1 full transformation
    integer :: domain_integration = integration_local_boundary !< IDIM: 1 local boundary (SCNI), 2 Gauss 2x2x2
    ! *SECTION_BEAM (ELFORM 1 Hughes-Liu, 9 spot weld beam; SHRF above, default 1)
    integer :: cross_section = cross_section_rectangular !< CST: 0 rectangular, 1 tubular
    integer :: beam_rule = 2               !< QR/IRID: Gauss points per section direction (1-5)
    real(wp) :: beam_size(4) = 0.0_wp      !< TS1 TS2 TT1 TT2 (TS2, TT2 default TS1, TT1)
    !> ELFORM 2 (resultant beam): A ISS ITT J SA (J 0: ISS + ITT; SA 0: A)
    real(wp) :: beam_properties(5) = 0.0_wp
  end type section_t

  !> One hourglass / bulk-viscosity definition (*HOURGLASS).
  type :: hourglass_t
    integer :: id = 0
    character(len=:), allocatable :: title
    integer :: hourglass_type = 0           !< IHQ as given (0: the *CONTROL_HOURGLASS default)
    real(wp) :: coefficient = 0.1_wp        !< QM
    real(wp) :: bulk_quadratic = 1.5_wp     !< Q1
    real(wp) :: bulk_linear = 0.06_wp       !< Q2
  end type hourglass_t

  !> One part (*PART) with its references resolved. The hourglass and bulk-viscosity values
  !> are the effective ones (part's *HOURGLASS, else *CONTROL_HOURGLASS, else LS-DYNA's
  !> defaults), so element code never looks anything up.
  type :: part_t
    integer :: id = 0
    character(len=:), allocatable :: title
    integer :: section_id = 0, material_id = 0, hourglass_id = 0
    integer :: section = 0, material = 0, hourglass = 0   !< indices (hourglass: 0 = none given)
    integer :: formulation = formulation_fe
    integer :: hourglass_type = 1
    real(wp) :: hourglass_coefficient = 0.1_wp
    real(wp) :: bulk_quadratic = 1.5_wp
    real(wp) :: bulk_linear = 0.06_wp
  end type part_t

  !> *SET_NODE_LIST(_GENERATE), node indices.
  type :: node_set_t
    integer :: id = 0
    character(len=:), allocatable :: title
    integer, allocatable :: nodes(:)
  end type node_set_t

  !> *SET_PART_LIST, part indices.
  type :: part_set_t
    integer :: id = 0
    character(len=:), allocatable :: title
    integer, allocatable :: parts(:)
  end type part_set_t

  !> One constrained node (*BOUNDARY_SPC_NODE/_SET, expanded per node).
  type :: spc_t
    integer :: node = 0
    logical :: fixed(3) = .false.           !< x, y, z translations
    logical :: fixed_rotation(3) = .false.  !< rotations about x, y, z (act on shell nodes only)
  end type spc_t

  !> One node constrained along directions other than the global axes (*BOUNDARY_SPC with a
  !> CID): its velocity keeps no component along `directions(:, 1:count)` (orthonormal, global
  !> components; the node's global SPC directions are among them).
  type :: local_spc_t
    integer :: node = 0
    integer :: count = 0
    real(wp) :: directions(3, 3) = 0.0_wp
  end type local_spc_t

  !> Prescribed-motion directions beyond x, y, z (1, 2, 3): along `vector`, free across it
  !> (LS-DYNA's DOF 4), or along `vector` and held across it (DOF -4).
  integer, parameter, public :: motion_along_vector = 4, motion_only_along_vector = -4

  !> One prescribed motion of one node and one translational direction.
  type :: prescribed_motion_t
    integer :: node = 0
    integer :: direction = 0                 !< 1, 2, 3, motion_along_vector, motion_only_along_vector
    real(wp) :: vector(3) = 0.0_wp           !< unit direction of the last two (VID)
    integer :: kind = motion_velocity        !< VAD
    integer :: curve = 0                     !< index into model%curves
    real(wp) :: scale = 1.0_wp               !< SF
    real(wp) :: birth = 0.0_wp
    real(wp) :: death = 1.0e28_wp
  end type prescribed_motion_t

  !> One concentrated nodal load (*LOAD_NODE_POINT/_SET, expanded per node).
  type :: nodal_load_t
    integer :: node = 0
    integer :: direction = 0                 !< 1, 2, 3
    integer :: curve = 0                     !< index into model%curves
    real(wp) :: scale = 1.0_wp
  end type nodal_load_t

  !> A distributed load on one quadrilateral (or triangular) segment: *LOAD_SEGMENT (pressure),
  !> *LOAD_SEGMENT_SET, *LOAD_SEGMENT_NONUNIFORM (values per corner, optional direction).
  !> Load per unit area at time t and point s of the segment:
  !>   scale * curve(t - arrival_time) * sum_k N_k(s) nodal_values(k) * (direction or -normal)
  !> where `normal` is the unit normal by the right-hand rule over nodes 1-2-3-4: a positive
  !> pressure pushes against it (LS-DYNA's sign).
  type :: segment_load_t
    integer :: nodes(4) = 0                  !< node indices (a triangle repeats node 3)
    integer :: curve = 0                     !< index into model%curves (0: constant 1)
    real(wp) :: scale = 1.0_wp               !< SF
    real(wp) :: arrival_time = 0.0_wp        !< AT
    real(wp) :: death = huge(1.0_wp)         !< DT (NONUNIFORM): zero load after it; huge: never
    real(wp) :: nodal_values(4) = 1.0_wp     !< pressure or traction at each corner
    logical :: along_normal = .true.         !< pressure; false: traction along `direction`
    real(wp) :: direction(3) = 0.0_wp        !< unit direction of a traction
  end type segment_load_t

  !> Rigid-wall kinds (rigid_wall_t%kind).
  integer, parameter, public :: wall_planar = 1, wall_cylinder = 2

  !> A rigid wall: planar (*RIGIDWALL_PLANAR with its options) or a geometric cylinder
  !> (*RIGIDWALL_GEOMETRIC_CYLINDER(_MOTION)).
  type :: rigid_wall_t
    integer :: id = 0
    character(len=:), allocatable :: title
    integer, allocatable :: nodes(:)         !< tracked (slave) node indices, exempted removed
    real(wp) :: point(3) = 0.0_wp            !< tail of the normal: a point on the wall
    real(wp) :: normal(3) = 0.0_wp           !< unit normal, pointing into the allowed half space
    real(wp) :: offset = 0.0_wp              !< OFFSET
    real(wp) :: birth = 0.0_wp, death = 1.0e20_wp
    real(wp) :: friction = 0.0_wp            !< FRIC
    logical :: finite = .false.
    real(wp) :: edge_direction(3) = 0.0_wp   !< unit edge vector l (finite walls)
    real(wp) :: length_l = 0.0_wp, length_m = 0.0_wp
    logical :: moving = .false.
    real(wp) :: mass = 0.0_wp, initial_speed = 0.0_wp
    logical :: forces_requested = .false.     !< _FORCES option
    ! *RIGIDWALL_GEOMETRIC_CYLINDER(_MOTION): `point` is the axis tail, `normal` the unit axis
    integer :: kind = wall_planar             !< wall_planar or wall_cylinder
    real(wp) :: radius = 0.0_wp               !< RADCYL
    real(wp) :: length = 0.0_wp               !< LENCYL (<= 0: infinite)
    integer :: motion_curve = 0               !< curve index of _MOTION (0: the cylinder stands still)
    integer :: motion_curve_id = 0            !< its LCID as given
    integer :: motion_option = 0              !< OPT: 0 velocity, 1 displacement
    real(wp) :: motion_direction(3) = 0.0_wp  !< unit direction (VX VY VZ) of the motion
  end type rigid_wall_t

  !> One rigid body: a *MAT_RIGID part (its elements' nodes) or a *CONSTRAINED_NODAL_RIGID_BODY
  !> (its node set's nodes). A node belongs to at most one body.
  type :: rigid_body_t
    integer :: id = 0                        !< part id (PID of a nodal rigid body): rbdout/<id>
    integer :: part = 0                      !< part index; 0 for a nodal rigid body
    integer, allocatable :: merged_parts(:)  !< *CONSTRAINED_RIGID_BODIES: rigid parts merged into it
    integer, allocatable :: merged_ids(:)    !< their part ids (a prescribed motion may name them)
    integer, allocatable :: nodes(:)         !< node indices, ascending
    logical :: fixed(6) = .false.            !< CMO = 1: x, y, z (CON1), rx, ry, rz (CON2), global axes
  end type rigid_body_t

  !> One prescribed motion of a rigid body (*BOUNDARY_PRESCRIBED_MOTION_RIGID) at its centre
  !> of mass, in global axes.
  type :: rigid_motion_t
    integer :: body = 0                      !< index into model%rigid_bodies
    integer :: dof = 0                       !< 1-3 translation x, y, z; 4-6 rotation about x, y, z
    integer :: kind = motion_velocity        !< VAD
    integer :: curve = 0                     !< index into model%curves
    real(wp) :: scale = 1.0_wp               !< SF
    real(wp) :: birth = 0.0_wp
    real(wp) :: death = 1.0e28_wp
  end type rigid_motion_t

  !> A spot weld held as a small rigid body until it fails: *CONSTRAINED_SPOTWELD (two nodes)
  !> or *CONSTRAINED_GENERALIZED_WELD_SPOT (a node set). It fails when
  !> (|fn|/SN)^N + (|fs|/SS)^M >= 1 with the force it transmits (a strength of 0 leaves its
  !> term out), or at TFAIL; afterwards its nodes move independently.
  type :: spot_weld_t
    integer :: id = 0                        !< WID (welds without an id: 1, 2, ... in deck order)
    integer, allocatable :: nodes(:)         !< node indices
    real(wp) :: normal_strength = 0.0_wp     !< SN (0: no normal-force term)
    real(wp) :: shear_strength = 0.0_wp      !< SS (0: no shear-force term)
    real(wp) :: normal_exponent = 2.0_wp     !< N
    real(wp) :: shear_exponent = 2.0_wp      !< M
    real(wp) :: failure_time = 1.0e20_wp     !< TF / TFAIL
    !> EP / EPSF: the weld fails once the effective plastic strain of a shell at one of its nodes
    !> reaches this (0: never)
    real(wp) :: failure_plastic_strain = 0.0_wp
  end type spot_weld_t

  !> *SET_SEGMENT, node indices (a triangle repeats node 3); segments with a reported problem
  !> are left out.
  type :: segment_set_t
    integer :: id = 0
    character(len=:), allocatable :: title
    integer, allocatable :: nodes(:, :)      !< (4, segments)
  end type segment_set_t

  !> Contact kinds (*CONTACT_AUTOMATIC_...).
  integer, parameter, public :: contact_nodes_to_surface = 1, contact_surface_to_surface = 2, &
                                contact_single_surface = 3
  !> Surface types (SURFATYP / SURFBTYP) as LS-DYNA numbers them.
  integer, parameter, public :: surface_segment_set = 0, surface_part_set = 2, surface_part = 3, &
                                surface_node_set = 4, surface_all_parts = 5

  !> One side of a contact: what SURFA or SURFB names, resolved to indices.
  type :: contact_surface_t
    integer :: kind = surface_part           !< surface_segment_set ... surface_all_parts
    integer :: id = 0                        !< the set or part id as given
    integer, allocatable :: parts(:)         !< part indices (part, part set, all parts)
    integer, allocatable :: segments(:, :)   !< (4, n) node indices (segment set)
    integer, allocatable :: nodes(:)         !< node indices (node set)
  end type contact_surface_t

  !> One penalty contact (*CONTACT_AUTOMATIC_NODES_TO_SURFACE / _SURFACE_TO_SURFACE /
  !> _SINGLE_SURFACE).
  type :: contact_t
    integer :: id = 0                        !< CID (contacts without _ID: 1, 2, ... in deck order)
    character(len=:), allocatable :: title
    integer :: kind = contact_surface_to_surface
    type(contact_surface_t) :: side_a, side_b !< SURFA (secondary), SURFB (primary)
    real(wp) :: static_friction = 0.0_wp     !< FS
    real(wp) :: dynamic_friction = 0.0_wp    !< FD
    real(wp) :: decay = 0.0_wp               !< DC
    real(wp) :: viscous_friction = 0.0_wp    !< VC
    real(wp) :: viscous_damping = 0.0_wp     !< VDC, percent of critical
    real(wp) :: birth = 0.0_wp, death = 1.0e20_wp
    real(wp) :: scale_a = 1.0_wp, scale_b = 1.0_wp !< SFSA, SFSB
    real(wp) :: friction_scale = 1.0_wp      !< FSF
    real(wp) :: viscous_scale = 1.0_wp       !< VSF
    integer :: soft = 0                      !< SOFT: 0 penalty, 1 soft constraint
    real(wp) :: soft_scale = 0.1_wp          !< SOFSCL
    integer :: bucket_interval = 0           !< BSORT (0: automatic)
  end type contact_t

  !> Tied contact kinds (*CONTACT_TIED_..., *CONTACT_SPOTWELD).
  integer, parameter, public :: tied_nodes_to_surface = 1, tied_surface_to_surface = 2, &
                                tied_shell_edge_to_surface = 3, tied_spotweld = 4

  !> A tied contact after its set-up search: each tied secondary node, the primary segment it
  !> was projected on and the shape functions there. Its velocity and acceleration are those
  !> of the segment at that point; its mass and force go to the segment's nodes.
  type :: tied_contact_t
    integer :: id = 0                        !< CID (1, 2, ... in deck order without _ID)
    integer :: kind = tied_nodes_to_surface
    logical :: offset = .false.              !< _OFFSET: the node keeps its distance to the segment
    logical :: rotations = .false.           !< shell edges and spot weld beams: rotations tied too
    integer, allocatable :: nodes(:)         !< tied secondary nodes
    integer, allocatable :: segments(:, :)   !< (4, tied) the segment's nodes (a triangle repeats N3)
    real(wp), allocatable :: weights(:, :)   !< (4, tied) its shape functions at the projection
  end type tied_contact_t

  !> Output intervals and requests (*DATABASE_...). An interval of 0 means "not requested".
  type :: output_control_t
    real(wp) :: state_interval = 0.0_wp      !< *DATABASE_BINARY_D3PLOT DT (or ENDTIM/NPLTC)
    real(wp) :: glstat_interval = 0.0_wp
    real(wp) :: matsum_interval = 0.0_wp
    real(wp) :: nodout_interval = 0.0_wp
    real(wp) :: rwforc_interval = 0.0_wp
    real(wp) :: rcforc_interval = 0.0_wp     !< *DATABASE_RCFORC
    real(wp) :: rbdout_interval = 0.0_wp     !< *DATABASE_RBDOUT (0: the glstat interval)
    !> BINARY of *DATABASE_GLSTAT / _MATSUM / _NODOUT / _RWFORC / _RCFORC / _RBDOUT, as
    !> LS-DYNA: 1 the ASCII file, 2 binout, 3 both (0 or blank: 1). The ASCII file is written
    !> only when the keyword is in the deck (its interval > 0); results.h5 has every history.
    integer :: glstat_binary = 1
    integer :: matsum_binary = 1
    integer :: nodout_binary = 1
    integer :: rwforc_binary = 1
    integer :: rcforc_binary = 1
    integer :: rbdout_binary = 1
    integer :: dump_cycles = 0               !< *DATABASE_BINARY_D3DUMP CYCL (0: no periodic dumps)
    integer :: running_restart_cycles = 0    !< *DATABASE_BINARY_RUNRSF CYCL (0: none)
    integer :: running_restart_files = 1     !< *DATABASE_BINARY_RUNRSF NR, written in turn
    integer, allocatable :: history_nodes(:) !< node indices for nodout
    logical :: element_strains = .false.     !< *DATABASE_EXTENT_BINARY STRFLG = 1: strain tensors in the d3plot
  end type output_control_t

  !> The whole model.
  type :: model_t
    character(len=:), allocatable :: title
    character(len=:), allocatable :: deck_path
    ! nodes
    integer, allocatable :: node_ids(:)
    real(wp), allocatable :: coordinates(:, :)       !< (3, nodes), reference configuration
    real(wp), allocatable :: initial_velocity(:, :)  !< (3, nodes)
    ! solid elements
    integer, allocatable :: solid_ids(:)
    integer, allocatable :: solid_part(:)            !< part index of each solid
    integer, allocatable :: solid_nodes(:, :)        !< (8, solids) node indices
    ! shell elements (a triangle repeats its third node)
    integer, allocatable :: shell_ids(:)
    integer, allocatable :: shell_part(:)            !< part index of each shell
    integer, allocatable :: shell_nodes(:, :)        !< (4, shells) node indices
    real(wp), allocatable :: shell_thickness(:, :)   !< (4, shells): *ELEMENT_SHELL_THICKNESS, else the section's
    ! beam elements (*ELEMENT_BEAM)
    integer, allocatable :: beam_ids(:)
    integer, allocatable :: beam_part(:)             !< part index of each beam
    integer, allocatable :: beam_nodes(:, :)         !< (3, beams) node indices N1 N2 and the orientation
                                                     !< node N3 (0: none)
    ! properties
    type(part_t), allocatable :: parts(:)
    type(section_t), allocatable :: sections(:)
    type(material_t), allocatable :: materials(:)
    type(hourglass_t), allocatable :: hourglasses(:)
    type(curve_t), allocatable :: curves(:)
    type(node_set_t), allocatable :: node_sets(:)
    type(part_set_t), allocatable :: part_sets(:)
    ! boundary conditions and loads
    type(spc_t), allocatable :: spcs(:)
    type(local_spc_t), allocatable :: local_spcs(:)  !< SPCs in local systems (CID)
    type(prescribed_motion_t), allocatable :: motions(:)
    type(nodal_load_t), allocatable :: loads(:)
    !> *LOAD_BODY_X/_Y/_Z: base accelerations (node 0: they act on every node, -m a)
    type(nodal_load_t), allocatable :: body_loads(:)
    type(segment_load_t), allocatable :: segment_loads(:)
    type(rigid_wall_t), allocatable :: walls(:)
    ! rigid bodies and lumped masses (deck_rigid_bodies)
    type(rigid_body_t), allocatable :: rigid_bodies(:)
    type(rigid_motion_t), allocatable :: rigid_motions(:)
    real(wp), allocatable :: node_masses(:)          !< *ELEMENT_MASS per node (nodes)
    type(spot_weld_t), allocatable :: spot_welds(:)  !< *CONSTRAINED_SPOTWELD, _GENERALIZED_WELD_SPOT
    ! controls
    logical :: implicit_static = .false.             !< *CONTROL_IMPLICIT_GENERAL IMFLAG = 1: linear static
    real(wp) :: end_time = 0.0_wp                    !< ENDTIM
    integer :: end_cycle = 0                         !< ENDCYC (0 = no limit)
    real(wp) :: minimum_time_step_factor = 0.0_wp    !< DTMIN: stop below this times the first step (0: off)
    !> *CONTROL_TIMESTEP ERODE: solids / shells whose step falls below DTMIN x the first step
    !> erode instead of stopping the run
    logical :: erode_solids_on_step = .false., erode_shells_on_step = .false.
    real(wp) :: energy_ratio_change_limit = 0.0_wp   !< ENDENG: stop when |energy ratio - 1| exceeds this
                                                     !< many percent (0: off)
    real(wp) :: mass_change_limit = 1.0e8_wp         !< ENDMAS: percent of mass that mass scaling may add
    real(wp) :: time_step_scale = 0.9_wp             !< TSSFAC
    real(wp) :: initial_time_step = 0.0_wp           !< DTINIT (0 = computed)
    real(wp) :: mass_scaled_time_step = 0.0_wp       !< DT2MS (0 = no mass scaling)
    integer :: default_hourglass_type = 1            !< *CONTROL_HOURGLASS IHQ
    real(wp) :: default_hourglass_coefficient = 0.1_wp !< *CONTROL_HOURGLASS QH
    logical :: hourglass_energy_in_balance = .false. !< *CONTROL_ENERGY HGEN = 2
    logical :: wall_energy_in_balance = .true.       !< *CONTROL_ENERGY RWEN = 2
    ! contact
    type(segment_set_t), allocatable :: segment_sets(:)
    type(contact_t), allocatable :: contacts(:)
    type(tied_contact_t), allocatable :: tied_contacts(:) !< *CONTACT_TIED_..., *CONTACT_SPOTWELD
    real(wp) :: contact_penalty_scale = 0.1_wp       !< *CONTROL_CONTACT SLSFAC
    integer :: contact_sort_interval = 0             !< *CONTROL_CONTACT NSBCS (0: sort when nodes moved)
    type(output_control_t) :: output
  end type model_t
end module model
