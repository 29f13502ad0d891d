!> The contract every element kind of the explicit engine fulfils (solid hexahedra, Belytschko-
!> Tsay shells, meshfree parts; beams and welds next), in the spirit of OpenRadioss's element
!> groups and MFEM's integrators.
!>
!> An element group holds all elements of one kind in the model: a payload of blocks of at
!> most `block_size` lanes (each block one part, one material, its node list lane-first and its
!> state), coloured so that blocks of one colour share no node. The header below is what the
!> engine reads without knowing the kind: the smallest stable step of the last force call and
!> the element that set it, an element that failed (inverted, lost its area), the kind's name
!> for timers and messages. The deferred procedures are the only calls the engine makes; the
!> engine calls them for every group in a fixed order (element_groups), so each node receives
!> its contributions in the same order for any thread count.
!>
!> Element references: `element` arguments and the header's element fields are the group's own
!> element numbers (a solid's index in the model's solid list for the solids, a shell's for the
!> shells, the background cell for meshfree points); `describe` turns one into the words of a
!> message.
module element_group
  use kinds, only: wp
  use integer_lists, only: sort_integers
  use model, only: model_t
  use nodal_state, only: nodal_state_t
  use wall_clock, only: phase_timer_t
  use run_summary, only: run_summary_t
  use error_handling, only: error_t
  use restart_file, only: restart_store_t
  use particle_rows, only: particle_rows_t
  use element_work, only: booked_energy
  implicit none
  private

  public :: element_group_t, group_holder_t, element_results_t, distortion_t, shell_output_points
  public :: distinct_nodes

  !> Which list of the model a group's element numbers index (its header's `element_family`):
  !> the solids (FE solids, and the meshfree parts' background cells), the shells (FE shells,
  !> the meshfree shells' background cells) or the beams. The domain partition counts and
  !> assigns elements by these lists.
  integer, parameter, public :: family_solid = 1, family_shell = 2, family_beam = 3
  !> Values per block in block_energy (every kind uses at most these).
  integer, parameter, public :: block_energy_values = 6

  !> Elements folded inside out at a corner while their volume stays positive (distortion_check),
  !> checked at every output state.
  type :: distortion_t
    integer :: tangled = 0                  !< elements with an inverted corner at the last check
    integer :: reported = 0                 !< the count of the last warning
    real(wp) :: worst_ratio = 1.0_wp        !< smallest corner Jacobian ratio of any check
    integer :: worst_element = 0            !< its element (0: none)
    !> the warning of the last check that found more folded elements than before ("" none);
    !> the solver prints and keeps it
    character(len=:), allocatable :: message
  end type distortion_t

  !> The element fields of one output state, filled by the groups (each writes its elements'
  !> rows; meshfree cells write the solid rows of their background cells).
  type :: element_results_t
    real(wp), allocatable :: solid_stress(:, :)          !< (6, solids) xx yy zz xy yz zx
    real(wp), allocatable :: solid_plastic_strain(:)
    real(wp), allocatable :: shell_stress(:, :)          !< (6, shells) mid-surface
    real(wp), allocatable :: shell_stress_peak(:, :)     !< (6, shells) the point of largest von Mises
    real(wp), allocatable :: shell_plastic_strain(:), shell_plastic_strain_peak(:)
    !> (6, beams) N, Q_s, Q_t, T, M_s, M_t in the beam's local axes r, s, t (beam_group)
    real(wp), allocatable :: beam_resultant(:, :)
    real(wp), allocatable :: beam_plastic_strain(:)      !< (beams) largest over the section points
    real(wp), allocatable :: beam_failed(:)              !< (beams) 1 failed (*MAT_SPOTWELD), 0 not
    !> deleted-element flags: 1 for an eroded element, 0 otherwise (solids, shells)
    integer, allocatable :: solid_eroded(:), shell_eroded(:)
    !> For the d3plot (optional, allocated by the output plan): (6, shell_output_points, shells)
    !> global stress and (points, shells) plastic strain at each point through the thickness,
    !> bottom to top, and (shells) how many points a group wrote (0: none, e.g. meshfree shells)
    real(wp), allocatable :: shell_point_stress(:, :, :), shell_point_plastic_strain(:, :)
    integer, allocatable :: shell_point_count(:)
    !> For the d3plot, with the points: (8, shells) resultants per unit width in the shell's
    !> local frame, M_xx M_yy M_xy Q_x Q_y N_xx N_yy N_xy, its thickness and its internal energy
    !> per unit volume (shells)
    real(wp), allocatable :: shell_resultant(:, :), shell_thickness(:), shell_energy_density(:)
  end type element_results_t

  type, abstract :: element_group_t
    character(len=16) :: name = ""                 !< "solid", "shell", "meshfree": timers, summary
    real(wp) :: stable_time_step = huge(1.0_wp)    !< smallest over the blocks, from the last force call
    integer :: critical_element = 0                !< the element that sets it (0: none)
    logical :: step_not_finite = .false.           !< a block's step was NaN (comparisons skip it)
    integer :: failed_element = 0                  !< an element that inverted or degenerated (0: none)
    type(phase_timer_t) :: timer                   !< wall-clock time of its force calls
    integer :: element_family = 0                  !< family_solid, family_shell or family_beam
    !> Erosion: an element that meets its material's failure criterion (erosion_criteria) or,
    !> with ERODE, whose step falls below `erosion_time_step`, leaves the force loops for good
    !> in the force call where it fails (no stress, forces, hourglass forces or step from then
    !> on; its nodes keep their mass). The group keeps a per-element eroded mask, reports the
    !> count of its last call here and lists them (newly_eroded_elements), sets the model-indexed
    !> masks the contacts read (mark_eroded) and reports the energy its eroded elements took
    !> along (add_eroded_energies; add_energies no longer counts them).
    integer :: newly_eroded = 0                    !< elements eroded by the last force call
    integer :: eroded_count = 0                    !< elements eroded so far
    real(wp) :: erosion_time_step = 0.0_wp         !< ERODE: DTMIN x the first step (0: off), set by the solver
    !> Distributed runs (docs/parallel.md), for kinds whose blocks are shared out among the ranks
    !> (distributes_blocks): the blocks this rank computes (its own and those on a node it owns)
    !> and those it owns. Not allocated (one rank, or a kind computed whole on every rank): all.
    !> The header then covers the computed blocks only, and newly_eroded the owned ones; the
    !> solver makes both global.
    logical, allocatable :: computed(:), owned(:)
    integer :: critical_block = 0                  !< the block of critical_element (0: none, or not by block)
    integer :: failed_block = 0                    !< the block of failed_element (0: none, or not by block)
    !> (block_energy_values, blocks): per block the sums over its lanes that the energy
    !> procedures read (add_energies, add_part_energies, add_eroded_energies): (1) the live
    !> lanes' internal energy, (2) its power, (3) their hourglass energy, (4) its power, (5) the
    !> eroded lanes' internal energy, (6) their hourglass energy (0 where a kind has none; a kind
    !> with energies of its own kind overrides add_energies). sum_block_energies fills the
    !> columns of the blocks this rank computes; a distributed run then hands the owners'
    !> columns to every rank (domain_exchange's share_block_energies), so that the energies need
    !> no block state from another rank.
    real(wp), allocatable :: block_energy(:, :)
  contains
    !> Once before the first cycle: its element count (0: the group is dropped).
    procedure(count_interface), deferred :: element_count
    !> Once: mass scaling to `target_step` (> 0; DT2MS), adding to the physical and added mass.
    procedure(scale_interface), deferred :: scale_masses
    !> Once: colour the blocks, add the lumped masses (and rotary inertias) into `nodes`.
    procedure(lump_interface), deferred :: lump_masses
    !> Every cycle: add the internal forces (and moments) at the current configuration into
    !> `nodes`, which the engine has cleared; set the header's step, critical and failed element.
    procedure(forces_interface), deferred :: add_internal_forces
    !> Before the energies are read (energy checks, glstat, matsum, states): the block_energy
    !> columns of the blocks this rank computes, from their lanes.
    procedure(block_energy_interface), deferred :: sum_block_energies
    !> Internal and hourglass energies, summed block by block from block_energy (energy_balance).
    procedure :: add_energies
    !> Per part: internal, hourglass, and the kinetic energy of the nodal masses the group gave.
    procedure(part_energy_interface), deferred :: add_part_energies
    !> Per part: the momentum and the mass of the nodal masses the group gave (matsum).
    procedure(part_momentum_interface), deferred :: add_part_momenta
    !> Stresses and plastic strains of its elements for an output state.
    procedure(results_interface), deferred :: element_results
    !> "solid element 12 (part 3)"
    procedure(describe_interface), deferred :: describe
    !> Its counts and seconds in the run summary (after the run: the time of its force calls).
    procedure(summary_interface), deferred :: add_to_summary
    !> Restart dumps: write what its blocks carry from cycle to cycle under `path`, or read it
    !> back into a group built from the same deck (restart_file's exchange_restart); what the
    !> set-up derives from the deck is not stored.
    procedure(exchange_interface), deferred :: exchange_state
    !> Set-up (domain partition): its blocks, the units of work a rank computes or not, in the
    !> order its force call visits them (over all its parts, part after part).
    procedure(block_count_interface), deferred :: block_count
    !> Set-up (domain partition): the distinct nodes block `block` reads or adds forces (and
    !> moments) into, ascending: its elements' corners; for a meshfree
    !> block the pair nodes of all its points (the supports reach beyond one element layer) and
    !> what else its force call adds into (the meshfree shells' cell corners and station rows).
    procedure(block_nodes_interface), deferred :: block_nodes
    !> Set-up (domain partition): the group's element numbers (element_family's list) of each
    !> lane of block `block`: an element per lane, for meshfree blocks the background cell of
    !> each integration point (a cell with several points is listed once per point).
    procedure(block_elements_interface), deferred :: block_elements
    !> Optional: the failure message of `failed_element` (default: "<describe> inverted").
    procedure :: failure_text
    !> Optional: transform a nodal field from solver values to physical ones (meshfree parts).
    procedure :: to_physical
    !> Optional (meshfree parts): the transpose of to_physical for forces. `physical` holds forces
    !> on the physical values; `generalized` holds the same on entry and gets A^T f at the
    !> group's interior particles (the contact phase: contact on physical positions).
    procedure :: forces_to_generalized
    !> Optional (meshfree parts): append the transformation rows of its interior particles
    !> (particle_rows), the rows of to_physical: the walls and the initial velocities use them.
    procedure :: add_particle_rows
    !> Optional: the element whose density mass scaling raised most, and the factor.
    procedure :: most_scaled
    !> For kinds whose blocks report a step, critical element and failed element each: the
    !> header from those arrays, in block order.
    procedure, non_overridable :: header_from_blocks
    !> Optional: the thinnest element (shells; bounds the angular velocities of the run checks).
    procedure :: thinnest
    !> Optional: count the elements folded at a corner, warn when more are (solids).
    procedure :: check_distortion
    !> Optional (kinds that erode): its elements eroded by the last force call, in its order.
    procedure :: newly_eroded_elements
    !> Optional (kinds that erode): set the entries of its eroded elements in the model-indexed
    !> masks (solids in `solid_eroded`, shells in `shell_eroded`); others are left alone.
    procedure :: mark_eroded
    !> Internal and hourglass energy of its eroded elements, from block_energy.
    procedure :: add_eroded_energies
    !> Optional (shells): raise `strain(node)`, at the nodes `wanted` flags, to the largest
    !> effective plastic strain of its elements on the node (spot welds failing by EP).
    procedure :: raise_nodal_plastic_strain
    !> Optional (d3hsp's table of the smallest steps): every element's stable step (no TSSFAC)
    !> at the current configuration, with its deck id and part id, from the routines that give
    !> the engine its step (default: none).
    procedure :: list_time_steps
    !> Optional (kinds whose blocks the ranks share out): true; the kind then skips the blocks
    !> `computed` leaves out in its force call and implements exchange_block_state.
    procedure :: distributes_blocks
    !> Optional, with distributes_blocks: write or read the state of one block (as exchange_state
    !> does for all, into a store in memory), so that the ranks can bring their blocks together.
    procedure :: exchange_block_state
    !> Optional: whether its force call adds moments, shell normals or areas at the nodes of its
    !> blocks (shells, beams, meshfree shells; default: no). A distributed run exchanges those
    !> only at such nodes (forces alone elsewhere).
    procedure :: adds_moments
    !> Whether this rank computes, or owns, block `block` (always, when not distributed).
    procedure, non_overridable :: computes, owns
  end type element_group_t

  !> An array element holding one group of any kind.
  type :: group_holder_t
    class(element_group_t), allocatable :: group
  end type group_holder_t

  abstract interface
    integer function count_interface(self)
      import :: element_group_t
      class(element_group_t), intent(in) :: self
    end function count_interface

    subroutine scale_interface(self, model, nodes, target_step, physical_mass, added_mass)
      import :: element_group_t, model_t, nodal_state_t, wp
      class(element_group_t), intent(inout) :: self
      type(model_t), intent(in) :: model
      type(nodal_state_t), intent(in) :: nodes
      real(wp), intent(in) :: target_step
      real(wp), intent(inout) :: physical_mass, added_mass
    end subroutine scale_interface

    subroutine lump_interface(self, model, nodes)
      import :: element_group_t, model_t, nodal_state_t
      class(element_group_t), intent(inout) :: self
      type(model_t), intent(in) :: model
      type(nodal_state_t), intent(inout) :: nodes
    end subroutine lump_interface

    subroutine forces_interface(self, model, nodes, step)
      import :: element_group_t, model_t, nodal_state_t, wp
      class(element_group_t), intent(inout) :: self
      type(model_t), intent(in) :: model
      type(nodal_state_t), intent(inout) :: nodes
      real(wp), intent(in) :: step          !< the step just taken (0 at the start)
    end subroutine forces_interface

    subroutine block_energy_interface(self)
      import :: element_group_t
      class(element_group_t), intent(inout) :: self
    end subroutine block_energy_interface

    subroutine part_energy_interface(self, nodes, average_step, step_correction, kinetic, internal, hourglass)
      import :: element_group_t, nodal_state_t, wp
      class(element_group_t), intent(in) :: self
      type(nodal_state_t), intent(in) :: nodes
      real(wp), intent(in) :: average_step, step_correction
      real(wp), intent(inout) :: kinetic(:), internal(:), hourglass(:)
    end subroutine part_energy_interface

    subroutine part_momentum_interface(self, nodes, half_step, momentum, mass)
      import :: element_group_t, nodal_state_t, wp
      class(element_group_t), intent(in) :: self
      type(nodal_state_t), intent(in) :: nodes
      real(wp), intent(in) :: half_step               !< half the step just taken: v^n = v^{n-1/2} + half_step a^n
      real(wp), intent(inout) :: momentum(:, :)       !< (3, parts)
      real(wp), intent(inout) :: mass(:)              !< (parts)
    end subroutine part_momentum_interface

    subroutine results_interface(self, model, results)
      import :: element_group_t, model_t, element_results_t
      class(element_group_t), intent(in) :: self
      type(model_t), intent(in) :: model
      type(element_results_t), intent(inout) :: results
    end subroutine results_interface

    function describe_interface(self, model, element) result(text)
      import :: element_group_t, model_t
      class(element_group_t), intent(in) :: self
      type(model_t), intent(in) :: model
      integer, intent(in) :: element
      character(len=:), allocatable :: text
    end function describe_interface

    subroutine exchange_interface(self, store, path, error)
      import :: element_group_t, restart_store_t, error_t
      class(element_group_t), intent(inout) :: self
      type(restart_store_t), intent(inout) :: store
      character(len=*), intent(in) :: path
      type(error_t), allocatable, intent(inout) :: error
    end subroutine exchange_interface

    integer function block_count_interface(self)
      import :: element_group_t
      class(element_group_t), intent(in) :: self
    end function block_count_interface

    subroutine block_nodes_interface(self, block, nodes)
      import :: element_group_t
      class(element_group_t), intent(in) :: self
      integer, intent(in) :: block
      integer, allocatable, intent(out) :: nodes(:)
    end subroutine block_nodes_interface

    subroutine block_elements_interface(self, block, elements)
      import :: element_group_t
      class(element_group_t), intent(in) :: self
      integer, intent(in) :: block
      integer, allocatable, intent(out) :: elements(:)
    end subroutine block_elements_interface

    subroutine summary_interface(self, summary)
      import :: element_group_t, run_summary_t
      class(element_group_t), intent(in) :: self
      type(run_summary_t), intent(inout) :: summary
    end subroutine summary_interface
  end interface

contains

  function failure_text(self, model) result(text)
    class(element_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    character(len=:), allocatable :: text
    text = self%describe(model, self%failed_element)//" inverted"
  end function failure_text

  !> The smallest block step and the element that sets it (the first block on a tie: the same
  !> for any thread count), the first failed element, and whether a step was NaN (the ordered
  !> comparisons skip it).
  subroutine header_from_blocks(self, block_time_step, block_critical_element, block_failed_element)
    class(element_group_t), intent(inout) :: self
    real(wp), intent(in) :: block_time_step(:)
    integer, intent(in) :: block_critical_element(:), block_failed_element(:)
    integer :: b
    self%stable_time_step = huge(1.0_wp)
    self%critical_element = 0
    self%critical_block = 0
    self%failed_element = 0
    self%failed_block = 0
    self%step_not_finite = .false.
    do b = 1, size(block_time_step)
      ! (a block another rank computes holds an old step)
      if (.not. self%computes(b)) cycle
      if (block_time_step(b) < self%stable_time_step) then
        self%stable_time_step = block_time_step(b)
        self%critical_element = block_critical_element(b)
        self%critical_block = b
      end if
      if (self%failed_element == 0 .and. block_failed_element(b) /= 0) then
        self%failed_element = block_failed_element(b)
        self%failed_block = b
      end if
      if (block_time_step(b) /= block_time_step(b)) self%step_not_finite = .true.
    end do
  end subroutine header_from_blocks

  logical function distributes_blocks(self)
    class(element_group_t), intent(in) :: self
    distributes_blocks = .false.
  end function distributes_blocks

  logical function adds_moments(self)
    class(element_group_t), intent(in) :: self
    adds_moments = .false.
  end function adds_moments

  subroutine exchange_block_state(self, store, block, error)
    class(element_group_t), intent(inout) :: self
    type(restart_store_t), intent(inout) :: store
    integer, intent(in) :: block
    type(error_t), allocatable, intent(inout) :: error
  end subroutine exchange_block_state

  pure logical function computes(self, block)
    class(element_group_t), intent(in) :: self
    integer, intent(in) :: block
    computes = .true.
    if (allocated(self%computed)) computes = self%computed(block)
  end function computes

  pure logical function owns(self, block)
    class(element_group_t), intent(in) :: self
    integer, intent(in) :: block
    owns = .true.
    if (allocated(self%owned)) owns = self%owned(block)
  end function owns

  subroutine to_physical(self, field, physical)
    class(element_group_t), intent(in) :: self
    real(wp), intent(in) :: field(:, :)
    real(wp), intent(inout) :: physical(:, :)
  end subroutine to_physical

  subroutine forces_to_generalized(self, physical, generalized)
    class(element_group_t), intent(in) :: self
    real(wp), intent(in) :: physical(:, :)
    real(wp), intent(inout) :: generalized(:, :)
  end subroutine forces_to_generalized

  subroutine add_particle_rows(self, rows)
    class(element_group_t), intent(in) :: self
    type(particle_rows_t), intent(inout) :: rows
  end subroutine add_particle_rows

  subroutine most_scaled(self, model, largest, element)
    class(element_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    real(wp), intent(inout) :: largest    !< the largest factor so far (raised when this group has one)
    integer, intent(inout) :: element     !< its element, set when raised
  end subroutine most_scaled

  subroutine check_distortion(self, model, nodes, time, distortion)
    class(element_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(in) :: nodes
    real(wp), intent(in) :: time
    type(distortion_t), intent(inout) :: distortion
  end subroutine check_distortion

  function newly_eroded_elements(self) result(elements)
    class(element_group_t), intent(in) :: self
    integer, allocatable :: elements(:)
    allocate (elements(0))
  end function newly_eroded_elements

  subroutine mark_eroded(self, solid_eroded, shell_eroded)
    class(element_group_t), intent(in) :: self
    logical, intent(inout) :: solid_eroded(:), shell_eroded(:)
  end subroutine mark_eroded

  !> The blocks' booked internal and hourglass energies (block_energy's rows 1 to 4), block by
  !> block: the work booked by the elements plus the step correction of their newest forces'
  !> power (solid_block).
  subroutine add_energies(self, step_correction, internal, hourglass)
    class(element_group_t), intent(in) :: self
    real(wp), intent(in) :: step_correction
    real(wp), intent(inout) :: internal, hourglass
    integer :: b
    do b = 1, size(self%block_energy, 2)
      internal = internal + booked_energy(self%block_energy(1, b), self%block_energy(2, b), step_correction)
      hourglass = hourglass + booked_energy(self%block_energy(3, b), self%block_energy(4, b), step_correction)
    end do
  end subroutine add_energies

  !> The energy its eroded elements took along (block_energy's rows 5 and 6), block by block.
  subroutine add_eroded_energies(self, internal, hourglass)
    class(element_group_t), intent(in) :: self
    real(wp), intent(inout) :: internal, hourglass
    integer :: b
    do b = 1, size(self%block_energy, 2)
      internal = internal + self%block_energy(5, b)
      hourglass = hourglass + self%block_energy(6, b)
    end do
  end subroutine add_eroded_energies

  real(wp) function thinnest(self)
    class(element_group_t), intent(in) :: self
    thinnest = huge(1.0_wp)
  end function thinnest

  subroutine raise_nodal_plastic_strain(self, model, wanted, strain)
    class(element_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    logical, intent(in) :: wanted(:)
    real(wp), intent(inout) :: strain(:)
  end subroutine raise_nodal_plastic_strain

  !> Lists nothing: `kind` "" and empty lists (kinds without a per-element step).
  subroutine list_time_steps(self, model, nodes, kind, element_ids, part_ids, steps)
    class(element_group_t), intent(in) :: self
    type(model_t), intent(in) :: model
    type(nodal_state_t), intent(in) :: nodes
    !> LS-DYNA's word for the element type in d3hsp: "solid", "shell", "beam"
    character(len=:), allocatable, intent(out) :: kind
    integer, allocatable, intent(out) :: element_ids(:), part_ids(:)   !< deck ids
    real(wp), allocatable, intent(out) :: steps(:)
    kind = ""
    allocate (element_ids(0), part_ids(0), steps(0))
  end subroutine list_time_steps

  !> The distinct entries of `list`, ascending (block_nodes of every kind; set-up only).
  pure function distinct_nodes(list) result(nodes)
    integer, intent(in) :: list(:)
    integer, allocatable :: nodes(:)
    integer, allocatable :: sorted(:)
    integer :: k, count
    allocate (sorted(size(list)))
    sorted(:) = list
    call sort_integers(sorted)
    allocate (nodes(size(sorted)))
    count = 0
    do k = 1, size(sorted)
      if (count > 0) then
        if (nodes(count) == sorted(k)) cycle
      end if
      count = count + 1
      nodes(count) = sorted(k)
    end do
    nodes = nodes(1:count)
  end function distinct_nodes

  !> Layers written per shell to the d3plot (its MAXINT): LS-DYNA's default 3 (mid, inner and
  !> outer surface) when no shell section has more than 3 points (NIP), else the largest NIP
  !> (at most 10: every point, as LS-DYNA writes them with MAXINT = NIP).
  pure integer function shell_output_points(model)
    type(model_t), intent(in) :: model
    integer :: shell, section
    shell_output_points = 3
    if (.not. (allocated(model%shell_ids) .and. allocated(model%sections))) return
    do shell = 1, size(model%shell_ids)
      section = model%parts(model%shell_part(shell))%section
      if (section < 1 .or. section > size(model%sections)) cycle
      shell_output_points = max(shell_output_points, min(10, model%sections(section)%integration_points))
    end do
  end function shell_output_points
end module element_group
