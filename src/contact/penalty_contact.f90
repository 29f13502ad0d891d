!> Penalty contact between solid faces: node-to-segment search and forces for
!> *CONTACT_AUTOMATIC_NODES_TO_SURFACE, _SURFACE_TO_SURFACE (both ways, symmetric) and
!> _SINGLE_SURFACE (LS-DYNA Theory Manual, "Contact-Impact Algorithm": penalty method,
!> sections on the standard penalty formulation and the soft constraint formulation).
!>
!> Each contact is done in one or two passes; a pass checks the secondary nodes against the
!> primary segments. The neighbour search is a bucket sort (LS-DYNA Theory Manual, "Contact
!> Searching", bucket sort): the segments, with their bounding boxes grown by a margin, are
!> sorted into a uniform grid, and every secondary node keeps the segments of its cell whose box
!> holds it. The lists stay valid until some node of the pass has moved half the margin since
!> they were built, apart from the motion common to the whole pass (or BSORT / NSBCS cycles have
!> passed), then they are rebuilt. Meshes mix
!> sizes (a 700 mm panel next to 30 mm rails): the margin and the cell are sized by the median
!> segment, not the largest, and a large segment is entered in every cell its box covers, so a
!> node's candidates are the segments that are really near it and a rebuild costs time linear in
!> the surface size whatever the spread of sizes. Arrays grow only at rebuilds.
!>
!> Penetration is measured from the closest point of the (bilinear) segment to the node along
!> the segment normal at that point. Normal force `k d` with LS-DYNA's stiffness for solid
!> segments `k = SLSFAC SFS K A^2 / V` (K bulk modulus of the segment's element, A the
!> segment area, V the element volume); SOFT = 1 takes the larger of that and the soft
!> constraint stiffness `0.5 SOFSCL m* / dt^2` (m* = m_node m_seg / (m_node + m_seg)). The
!> reaction goes to the segment's nodes with the shape-function weights of the contact point,
!> so every pair is in equilibrium and momentum is conserved to round-off. Coulomb friction
!> (FS, FD, DC; VC limit) uses an elastic tangential spring of stiffness k whose force is
!> capped at mu times the normal force (the theory manual's friction return mapping).
!>
!> Determinism: the secondary nodes are processed in parallel, each writing only its own pair
!> result (segment, weights, force); the forces are then added to the nodes in one serial loop
!> in pair order. Results are bit-identical for any thread count; no atomics.
!>
!> A distributed run (docs/parallel.md) shares the pairs out: `find_contact_pairs` computes the
!> pairs of this rank's share of the secondary nodes (`share_out_pairs`: contiguous ranges of
!> about equal work, chosen again at every bucket search; the costly part: the projections), the ranks
!> hand each other their pair records (`pack_pair_records`, `unpack_pair_records`; the exchange
!> itself is the solver's), and `apply_contact_pairs` adds every pair's forces on every rank in
!> the one-rank pair order. A pair depends only on its node, the candidate lists and the last
!> cycle's pair of that node, so it is the same whichever rank computes it.
module penalty_contact
  use, intrinsic :: iso_fortran_env, only: int64
  use kinds, only: wp
  use message_log, only: message_log_t, log_message
  use error_handling, only: error_t, make_error
  use model, only: model_t, contact_t, contact_surface_t, contact_nodes_to_surface, &
                   contact_surface_to_surface, contact_single_surface, surface_segment_set, &
                   surface_node_set
  use contact_surfaces, only: append_exterior_faces, append_part_shells, find_segment_owners, find_shell_owners, &
                              surface_node_list, hexahedron_volume, segment_area
  implicit none
  private

  public :: contact_state_t, contact_pass_t, set_up_contacts, set_up_contact, compute_contact_forces, &
            report_initial_penetrations, mass_in_contact
  public :: find_contact_pairs, apply_contact_pairs, pack_pair_records, unpack_pair_records
  public :: pair_record_size

  !> Values of one pair record of the exchange: contact, pass, secondary node (pass index),
  !> segment, side, depth, initial depth, weights (4), force (3), friction spring (3).
  integer, parameter :: pair_record_size = 17

  !> Parametric tolerance of the projection (LS-DYNA's MAXPAR default 1.025).
  real(wp), parameter :: parametric_limit = 1.025_wp
  !> Largest pair stiffness as a fraction of m* / dt^2 (a lone pair spring is stable up to 4).
  real(wp), parameter :: stable_fraction = 0.25_wp
  !> How much deeper than its last penetration plus this step's approach a pair may be found:
  !> a factor, not an offset, because the soft-constraint spring (m*/dt^2) throws a node out of
  !> any new depth d at about d/dt; a factor keeps that kick proportional to the approach.
  real(wp), parameter :: reach_factor = 2.0_wp

  !> Secondary nodes against primary segments.
  type :: contact_pass_t
    integer :: node_count = 0, segment_count = 0
    logical :: single = .false.                   !< single surface: skip a node's own neighbourhood
    integer, allocatable :: nodes(:)              !< secondary node indices
    real(wp), allocatable :: node_normal(:, :)    !< (3, nodes) outward normal on the secondary side (0: none)
    integer, allocatable :: segments(:, :)        !< (4, segments) primary segments, outward
    real(wp), allocatable :: stiffness(:)         !< SLSFAC SFS K A^2 / V per segment
    real(wp), allocatable :: depth(:)             !< deepest penetration still taken as contact: V / (2 A)
    real(wp), allocatable :: area(:)
    ! shells: contact surfaces at half the thickness on either side of the mid-surface
    real(wp), allocatable :: segment_offset(:)    !< t/2 of a shell segment, 0 for a solid face
    real(wp), allocatable :: node_offset(:)       !< t/2 of the thickest shell of the secondary side at the node
    real(wp) :: largest_node_offset = 0.0_wp
    ! initial penetrations (measured at the first evaluation) are ignored, as LS-DYNA's IGNORE = 1
    logical :: initial_checked = .false.
    real(wp), allocatable :: initial_depth(:)     !< per secondary node, shrinks as the node backs out
    integer :: initial_count = 0                  !< nodes found penetrating at the first evaluation
    real(wp) :: initial_deepest = 0.0_wp
    integer :: initial_node = 0                   !< node index of the deepest one
    logical :: initial_reported = .false.
    ! single surface: node -> its own segments (CSR over the pass nodes)
    integer, allocatable :: own_first(:), own_segments(:)
    ! bucket search
    integer, allocatable :: tracked(:)            !< every node of the pass
    real(wp), allocatable :: tracked_at_build(:, :)
    real(wp) :: margin = 0.0_wp                   !< half the median segment size: motion allowed between rebuilds
    real(wp) :: cell_size = 0.0_wp                !< median grown box of a segment: the bucket edge
    integer :: cycles_since_build = 0
    logical :: built = .false.
    integer, allocatable :: candidate_first(:), candidates(:)
    integer, allocatable :: cell_first(:), cell_segments(:)
    real(wp), allocatable :: box(:, :)            !< (6, segments) grown bounding boxes
    ! pair results, one per secondary node
    integer, allocatable :: pair_segment(:)
    real(wp), allocatable :: pair_side(:)          !< shells: +1 / -1, the side of the segment the node is on
    real(wp), allocatable :: pair_depth(:)         !< penetration of the node's pair in the last cycle (0: none)
    real(wp), allocatable :: pair_weights(:, :), pair_force(:, :), tangential(:, :)
    real(wp) :: side_sign = 1.0_wp                !< +1: secondary is SURFA; -1: the B -> A pass
    ! a distributed run: the secondary nodes whose pairs this rank computes (pass indices,
    ! ascending; listed at the first search after set-up, erosion or a restart), and those of
    ! other ranks whose records it took in the last exchange (cleared before the next one)
    integer, allocatable :: handled(:)
    logical, allocatable :: is_handled(:)
    integer, allocatable :: received(:)
    integer :: received_count = 0
  end type contact_pass_t

  !> One contact during the run.
  type :: contact_state_t
    integer :: pass_count = 0
    integer, allocatable :: excluded_nodes(:)     !< nodes never checked (interior meshfree particles)
    type(contact_pass_t) :: passes(2)
    real(wp) :: force(3) = 0.0_wp                 !< force on the SURFA side in the last cycle
    real(wp) :: impulse(3) = 0.0_wp               !< since the start of the run
  end type contact_state_t

contains

  !> Build the passes of every contact from the model (reference configuration).
  subroutine set_up_contacts(model, is_particle, contacts, error)
    type(model_t), intent(in) :: model
    logical, intent(in) :: is_particle(:)
    type(contact_state_t), allocatable, intent(out) :: contacts(:)
    type(error_t), allocatable, intent(out) :: error
    logical, allocatable :: solid_eroded(:), shell_eroded(:)
    integer :: k
    if (.not. allocated(model%contacts)) then
      allocate (contacts(0))
      return
    end if
    allocate (contacts(size(model%contacts)), solid_eroded(size(model%solid_part)), &
              shell_eroded(size(model%shell_part)))
    solid_eroded = .false.
    shell_eroded = .false.
    do k = 1, size(model%contacts)
      call set_up_contact(model, is_particle, k, solid_eroded, shell_eroded, contacts(k), error)
      if (allocated(error)) return
    end do
  end subroutine set_up_contacts

  !> Build the passes of contact `k` from the model (reference configuration) without the
  !> elements flagged eroded: their shells and faces leave the surfaces, the faces of the other
  !> solids of a part that become exterior join them (sides given by parts), and secondary
  !> nodes with no remaining element are not checked. Also used after erosion
  !> (contact_erosion), which then carries the pair state over.
  subroutine set_up_contact(model, is_particle, k, solid_eroded, shell_eroded, state, error)
    type(model_t), intent(in) :: model
    logical, intent(in) :: is_particle(:)
    integer, intent(in) :: k
    logical, intent(in) :: solid_eroded(:), shell_eroded(:)
    type(contact_state_t), intent(out) :: state
    type(error_t), allocatable, intent(out) :: error
    integer :: n
    integer, allocatable :: segments_a(:, :), owners_a(:), segments_b(:, :), owners_b(:), nodes(:)
    logical, allocatable :: node_lost(:)
    state%excluded_nodes = pack([(n, n=1, size(is_particle))], is_particle)
    ! nodes that had elements and have none left
    allocate (node_lost(size(model%node_ids)))
    node_lost = .false.
    if (any(solid_eroded) .or. any(shell_eroded)) call find_lost_nodes()
    associate (contact => model%contacts(k))
      call side_segments(contact%side_a, segments_a, owners_a)
      if (allocated(error)) return
      if (contact%kind /= contact_single_surface) then
        call side_segments(contact%side_b, segments_b, owners_b)
        if (allocated(error)) return
      end if
      select case (contact%kind)
      case (contact_nodes_to_surface, contact_surface_to_surface)
        if (contact%side_a%kind == surface_node_set) then
          nodes = pack(contact%side_a%nodes, .not. (is_particle(contact%side_a%nodes) .or. &
                                                    node_lost(contact%side_a%nodes)))
        else
          call surface_node_list(segments_a, is_particle, nodes)
        end if
        state%pass_count = 1
        call build_pass(state%passes(1), nodes, segments_a, owners_a, segments_b, owners_b, contact%scale_b, .false.)
        state%passes(1)%side_sign = 1.0_wp
        if (contact%kind == contact_surface_to_surface) then
          call surface_node_list(segments_b, is_particle, nodes)
          state%pass_count = 2
          call build_pass(state%passes(2), nodes, segments_b, owners_b, segments_a, owners_a, contact%scale_a, &
                          .false.)
          state%passes(2)%side_sign = -1.0_wp
        end if
      case (contact_single_surface)
        call surface_node_list(segments_a, is_particle, nodes)
        state%pass_count = 1
        call build_pass(state%passes(1), nodes, segments_a, owners_a, segments_a, owners_a, contact%scale_a, .true.)
      end select
    end associate
  contains
    subroutine find_lost_nodes()
      logical, allocatable :: had(:), kept(:)
      integer :: element
      allocate (had(size(model%node_ids)), kept(size(model%node_ids)))
      had = .false.
      kept = .false.
      do element = 1, size(model%solid_part)
        had(model%solid_nodes(:, element)) = .true.
        if (.not. solid_eroded(element)) kept(model%solid_nodes(:, element)) = .true.
      end do
      do element = 1, size(model%shell_part)
        had(model%shell_nodes(:, element)) = .true.
        if (.not. shell_eroded(element)) kept(model%shell_nodes(:, element)) = .true.
      end do
      node_lost = had .and. .not. kept
    end subroutine find_lost_nodes

    !> Segments (outward) and owning solids of one side.
    subroutine side_segments(side, segments, owners)
      type(contact_surface_t), intent(in) :: side
      integer, allocatable, intent(out) :: segments(:, :), owners(:)
      integer :: count, p, s
      integer, allocatable :: solid_part(:), shell_part(:)
      logical, allocatable :: keep(:)
      character(len=160) :: text
      count = 0
      select case (side%kind)
      case (surface_node_set)
        allocate (segments(4, 0), owners(0))
      case (surface_segment_set)
        segments = side%segments
        allocate (owners(size(segments, 2)))
        call find_segment_owners(model%solid_nodes, size(model%node_ids), model%coordinates, segments, owners)
        call find_shell_owners(model%shell_nodes, size(model%node_ids), segments, owners)
        do s = 1, size(owners)
          if (owners(s) /= 0) cycle
          write (text, '(a,i0,a,4(1x,i0),a)') "contact: segment set ", side%id, " has a segment (nodes", &
            model%node_ids(segments(:, s)), ") that is neither a face of a solid element nor a shell"
          call make_error(error, trim(text))
          return
        end do
        ! segments of eroded elements leave (a segment set is the user's list: nothing joins it)
        allocate (keep(size(owners)))
        do s = 1, size(owners)
          if (owners(s) > 0) then
            keep(s) = .not. solid_eroded(owners(s))
          else
            keep(s) = .not. shell_eroded(-owners(s))
          end if
        end do
        if (.not. all(keep)) then
          owners = pack(owners, keep)
          segments = reshape(pack(segments, spread(keep, 1, 4)), [4, size(owners)])
        end if
      case default
        ! eroded elements are left out of their part: the faces they covered become exterior
        solid_part = merge(0, model%solid_part, solid_eroded)
        shell_part = merge(0, model%shell_part, shell_eroded)
        do p = 1, size(side%parts)
          call append_exterior_faces(model%solid_nodes, solid_part, side%parts(p), size(model%node_ids), &
                                     segments, owners, count)
          call append_part_shells(model%shell_nodes, shell_part, side%parts(p), segments, owners, count)
        end do
        if (.not. allocated(segments)) allocate (segments(4, 0), owners(0))
        segments = segments(:, 1:count)
        owners = owners(1:count)
      end select
    end subroutine side_segments

    !> One pass: secondary nodes (with their normals and shell offsets from
    !> `secondary_segments`), primary segments with their stiffness and offsets, and the search
    !> and pair arrays. A solid face's stiffness is SLSFAC SFS K A^2 / V; a shell's is
    !> SLSFAC SFS K A / (longest diagonal), LS-DYNA's rule for shell segments.
    subroutine build_pass(pass, secondary_nodes, secondary_segments, secondary_owners, primary, owners, scale, single)
      type(contact_pass_t), intent(out) :: pass
      integer, intent(in) :: secondary_nodes(:), secondary_segments(:, :), secondary_owners(:), primary(:, :)
      integer, intent(in) :: owners(:)
      real(wp), intent(in) :: scale
      logical, intent(in) :: single
      integer :: s, j, n, position
      integer, allocatable :: slot(:), fill(:)
      real(wp) :: bulk, volume, normal(3)
      real(wp), allocatable :: segment_size(:)
      logical, allocatable :: used(:)
      pass%single = single
      pass%node_count = size(secondary_nodes)
      pass%segment_count = size(primary, 2)
      pass%nodes = secondary_nodes
      pass%segments = primary
      allocate (pass%stiffness(pass%segment_count), pass%depth(pass%segment_count), pass%area(pass%segment_count), &
                pass%segment_offset(pass%segment_count), segment_size(pass%segment_count))
      do s = 1, pass%segment_count
        associate (x => model%coordinates(:, primary(:, s)), owner => owners(s))
          associate (material => model%materials(model%parts(owner_part(owner))%material))
            bulk = material%youngs_modulus/(3.0_wp*max(1.0e-6_wp, 1.0_wp - 2.0_wp*material%poissons_ratio))
          end associate
          pass%area(s) = segment_area(x)
          if (owner > 0) then
            volume = abs(hexahedron_volume(model%coordinates(:, model%solid_nodes(:, owner))))
            pass%stiffness(s) = model%contact_penalty_scale*scale*bulk*pass%area(s)**2/max(volume, tiny(1.0_wp))
            pass%depth(s) = 0.5_wp*volume/max(pass%area(s), tiny(1.0_wp))
            pass%segment_offset(s) = 0.0_wp
          else
            pass%stiffness(s) = model%contact_penalty_scale*scale*bulk*pass%area(s)/ &
                                max(norm2(x(:, 3) - x(:, 1)), norm2(x(:, 4) - x(:, 2)), tiny(1.0_wp))
            pass%segment_offset(s) = 0.5_wp*shell_thickness(-owner)
            pass%depth(s) = pass%segment_offset(s)
          end if
          segment_size(s) = 0.0_wp
          do j = 1, 4
            segment_size(s) = max(segment_size(s), norm2(x(:, mod(j, 4) + 1) - x(:, j)))
          end do
        end associate
      end do
      ! the margin is the motion allowed between rebuilds: half the median segment, not the
      ! largest (half a 700 mm panel would give every node of a fine mesh nearby hundreds of
      ! candidates to test every cycle)
      pass%margin = 0.5_wp*median(segment_size)
      ! node normals: sum of the area vectors of the secondary solid faces at each node; a node
      ! of a (two-sided) shell has none, and its offset is half its thickest shell
      allocate (slot(size(model%node_ids)))
      slot = 0
      do n = 1, pass%node_count
        slot(secondary_nodes(n)) = n
      end do
      allocate (pass%node_normal(3, pass%node_count), pass%node_offset(pass%node_count), &
                pass%initial_depth(pass%node_count))
      pass%node_normal = 0.0_wp
      pass%node_offset = 0.0_wp
      pass%initial_depth = 0.0_wp
      allocate (used(pass%node_count))
      used = .false.
      do s = 1, size(secondary_segments, 2)
        associate (x => model%coordinates(:, secondary_segments(:, s)))
          normal = cross(x(:, 3) - x(:, 1), x(:, 4) - x(:, 2))
        end associate
        do j = 1, 4
          if (j == 4 .and. secondary_segments(4, s) == secondary_segments(3, s)) cycle
          position = slot(secondary_segments(j, s))
          if (position == 0) cycle
          if (secondary_owners(s) < 0) then
            used(position) = .true.
            pass%node_offset(position) = max(pass%node_offset(position), 0.5_wp*shell_thickness(-secondary_owners(s)))
          else
            pass%node_normal(:, position) = pass%node_normal(:, position) + normal
          end if
        end do
      end do
      do n = 1, pass%node_count
        if (used(n)) pass%node_normal(:, n) = 0.0_wp
        if (norm2(pass%node_normal(:, n)) > 0.0_wp) pass%node_normal(:, n) = pass%node_normal(:, n)/ &
                                                                            norm2(pass%node_normal(:, n))
      end do
      deallocate (used)
      if (pass%node_count > 0) pass%largest_node_offset = maxval(pass%node_offset)
      ! bucket edge: the median grown box, so that a typical box spans one or two cells
      do s = 1, pass%segment_count
        segment_size(s) = segment_size(s) + 2.0_wp*(pass%margin + pass%depth(s) + pass%largest_node_offset)
      end do
      pass%cell_size = median(segment_size)
      if (single) then
        ! node -> own segments (CSR)
        allocate (pass%own_first(pass%node_count + 1))
        pass%own_first = 0
        do s = 1, pass%segment_count
          do j = 1, 4
            if (j == 4 .and. primary(4, s) == primary(3, s)) cycle
            position = slot(primary(j, s))
            if (position > 0) pass%own_first(position + 1) = pass%own_first(position + 1) + 1
          end do
        end do
        pass%own_first(1) = 1
        do n = 1, pass%node_count
          pass%own_first(n + 1) = pass%own_first(n + 1) + pass%own_first(n)
        end do
        allocate (pass%own_segments(pass%own_first(pass%node_count + 1) - 1))
        fill = pass%own_first(1:pass%node_count)
        do s = 1, pass%segment_count
          do j = 1, 4
            if (j == 4 .and. primary(4, s) == primary(3, s)) cycle
            position = slot(primary(j, s))
            if (position == 0) cycle
            pass%own_segments(fill(position)) = s
            fill(position) = fill(position) + 1
          end do
        end do
      end if
      ! every node of the pass, for the rebuild test
      allocate (used(size(model%node_ids)))
      used = .false.
      used(secondary_nodes) = .true.
      do s = 1, pass%segment_count
        used(primary(:, s)) = .true.
      end do
      pass%tracked = pack([(n, n=1, size(used))], used)
      allocate (pass%tracked_at_build(3, size(pass%tracked)), pass%box(6, pass%segment_count), &
                pass%candidate_first(pass%node_count + 1), pass%candidates(max(16, 4*pass%node_count)), &
                pass%cell_first(1), pass%cell_segments(max(16, 8*pass%segment_count)))
      ! (all of it defined: a restart dump holds these arrays whole, also before the first search
      ! and beyond the lists in use, and must be the same file for any run of the deck)
      pass%tracked_at_build = 0.0_wp
      pass%box = 0.0_wp
      pass%candidate_first = 1
      pass%candidates = 0
      pass%cell_first = 0
      pass%cell_segments = 0
      allocate (pass%pair_segment(pass%node_count), pass%pair_weights(4, pass%node_count), &
                pass%pair_force(3, pass%node_count), pass%tangential(3, pass%node_count), &
                pass%pair_side(pass%node_count), pass%pair_depth(pass%node_count))
      call clear_pairs(pass)
    end subroutine build_pass

    !> Part of a segment owner (a solid index, or minus a shell index).
    integer function owner_part(owner)
      integer, intent(in) :: owner
      if (owner > 0) then
        owner_part = model%solid_part(owner)
      else
        owner_part = model%shell_part(-owner)
      end if
    end function owner_part

    !> Mean thickness of a shell (a triangle: of its three corners).
    real(wp) function shell_thickness(shell)
      integer, intent(in) :: shell
      if (model%shell_nodes(3, shell) == model%shell_nodes(4, shell)) then
        shell_thickness = sum(model%shell_thickness(1:3, shell))/3.0_wp
      else
        shell_thickness = 0.25_wp*sum(model%shell_thickness(:, shell))
      end if
    end function shell_thickness
  end subroutine set_up_contact

  !> Contact forces of every contact at the current configuration (added into
  !> `contact_force`, which is zeroed first) and the contact energy increment: minus the work
  !> of the contact forces over the step, by the trapezoidal rule
  !> `-dt/2 (f^n + f^{n+1}) . v^{n+1/2}`. For a linear spring this is exactly the change of
  !> its stored energy; friction adds its (positive) dissipation. One rank: every pair here.
  subroutine compute_contact_forces(model, contacts, time, step, coordinates, velocity, mass, &
                                    contact_force, energy_increment)
    type(model_t), intent(in) :: model
    type(contact_state_t), intent(inout) :: contacts(:)
    real(wp), intent(in) :: time, step
    real(wp), intent(in) :: coordinates(:, :), velocity(:, :), mass(:)
    real(wp), intent(inout) :: contact_force(:, :)
    real(wp), intent(out) :: energy_increment
    real(wp) :: work_before
    call find_contact_pairs(model, contacts, time, step, coordinates, velocity, mass, work_before)
    call apply_contact_pairs(contacts, step, velocity, contact_force, work_before, energy_increment)
  end subroutine compute_contact_forces

  !> The first half of the contact forces: the power of the last cycle's pairs (`work_before`,
  !> every pair: the pairs are complete on every rank after an exchange), the searches, and the
  !> pairs of this rank's share of the secondary nodes (`rank` of `rank_count`, share_out_pairs;
  !> absent: all). A contact outside its birth and death times has no pairs.
  subroutine find_contact_pairs(model, contacts, time, step, coordinates, velocity, mass, work_before, rank, &
                                rank_count)
    type(model_t), intent(in) :: model
    type(contact_state_t), intent(inout) :: contacts(:)
    real(wp), intent(in) :: time, step
    real(wp), intent(in) :: coordinates(:, :), velocity(:, :), mass(:)
    real(wp), intent(out) :: work_before
    integer, intent(in), optional :: rank, rank_count   !< this rank (0-based) of rank_count (absent: 0 of 1)
    integer :: k, p
    logical :: active, rebuilt
    work_before = 0.0_wp
    do k = 1, size(contacts)
      do p = 1, contacts(k)%pass_count
        work_before = work_before + pass_work(contacts(k)%passes(p), velocity)
      end do
    end do
    do k = 1, size(contacts)
      associate (contact => model%contacts(k), state => contacts(k))
        active = time >= contact%birth .and. time <= contact%death
        do p = 1, state%pass_count
          associate (pass => state%passes(p))
            if (.not. active) then
              call clear_pairs(pass)
              cycle
            end if
            ! BSORT of the contact, else NSBCS of *CONTROL_CONTACT, else only when nodes moved
            call update_search(pass, coordinates, merge(contact%bucket_interval, model%contact_sort_interval, &
                                                        contact%bucket_interval > 0), rebuilt)
            if (rebuilt .or. .not. allocated(pass%handled)) then
              if (present(rank)) then
                call share_out_pairs(pass, coordinates, rank, rank_count)
              else
                call share_out_pairs(pass, coordinates, 0, 1)
              end if
            end if
            call pair_forces(contact, pass, step, coordinates, velocity, mass)
          end associate
        end do
      end associate
    end do
  end subroutine find_contact_pairs

  !> The second half, once every rank holds every pair: the first evaluation's initial
  !> penetrations summed up, the pair forces added to the nodes (serial, in pair order: the same
  !> sums for any thread and rank count), the contacts' forces and impulses, and the energy
  !> increment with the power of the new pairs.
  subroutine apply_contact_pairs(contacts, step, velocity, contact_force, work_before, energy_increment)
    type(contact_state_t), intent(inout) :: contacts(:)
    real(wp), intent(in) :: step, velocity(:, :), work_before
    real(wp), intent(inout) :: contact_force(:, :)
    real(wp), intent(out) :: energy_increment
    integer :: k, p, i, j, node
    real(wp) :: work_after, total(3)
    !$omp parallel do schedule(static) default(shared) private(node)
    do node = 1, size(contact_force, 2)
      contact_force(:, node) = 0.0_wp
    end do
    !$omp end parallel do
    work_after = 0.0_wp
    do k = 1, size(contacts)
      associate (state => contacts(k))
        state%force = 0.0_wp
        do p = 1, state%pass_count
          associate (pass => state%passes(p))
            if (.not. pass%initial_checked .and. allocated(pass%handled)) call sum_up_initial_penetrations(pass)
            total = 0.0_wp
            do i = 1, pass%node_count
              if (pass%pair_segment(i) == 0) cycle
              node = pass%nodes(i)
              contact_force(:, node) = contact_force(:, node) + pass%pair_force(:, i)
              do j = 1, 4
                if (j == 4 .and. pass%segments(4, pass%pair_segment(i)) == pass%segments(3, pass%pair_segment(i))) &
                  cycle
                associate (other => pass%segments(j, pass%pair_segment(i)))
                  contact_force(:, other) = contact_force(:, other) - pass%pair_weights(j, i)*pass%pair_force(:, i)
                end associate
              end do
              total = total + pass%pair_force(:, i)
            end do
            state%force = state%force + pass%side_sign*total
            work_after = work_after + pass_work(pass, velocity)
          end associate
        end do
        state%impulse = state%impulse + step*state%force
      end associate
    end do
    energy_increment = -0.5_wp*step*(work_before + work_after)
  end subroutine apply_contact_pairs

  !> The secondary nodes of `pass` whose pairs this rank computes, chosen again at every search
  !> (the same on every rank: the candidate lists and positions are): contiguous ranges of the
  !> pass's nodes with about equal work. A node costs a little, each of its candidates a box
  !> test, each candidate within reach now a projection (the bulk: a shell plate's nodes all
  !> project onto their neighbouring segments every cycle, a solid's side faces hardly ever);
  !> the weights below are their measured ratios (about 10, 24 and 160 ns on the scaling deck of
  !> tools/make_scaling_deck.py). Any rank may compute any pair, all see the whole model; the
  !> ranges keep a rank's nodes together in memory. A node that leaves this rank with a pair is
  !> listed as received, so that the next exchange clears it unless its new rank sends it again.
  subroutine share_out_pairs(pass, coordinates, rank, rank_count)
    type(contact_pass_t), intent(inout) :: pass
    real(wp), intent(in) :: coordinates(:, :)
    integer, intent(in) :: rank, rank_count
    integer, parameter :: node_weight = 1, candidate_weight = 2, projection_weight = 16
    integer(int64) :: total, before, first_weight, last_weight
    integer :: i, c, j, first, last
    integer, allocatable :: weight(:)
    real(wp) :: corners(3, 4)
    logical, allocatable :: was_handled(:)
    if (allocated(pass%is_handled)) then
      call move_alloc(pass%is_handled, was_handled)
    else
      allocate (was_handled(pass%node_count))
      was_handled = .true.
    end if
    if (.not. allocated(pass%received)) allocate (pass%received(16))
    allocate (weight(pass%node_count))
    ! (one rank takes every node: no weights to measure)
    if (rank_count == 1) weight = node_weight
    !$omp parallel do schedule(static) default(shared) private(i, c, j, corners) if (rank_count > 1)
    do i = 1, pass%node_count
      if (rank_count == 1) cycle
      weight(i) = node_weight
      do c = pass%candidate_first(i), pass%candidate_first(i + 1) - 1
        weight(i) = weight(i) + candidate_weight
        do j = 1, 4
          corners(:, j) = coordinates(:, pass%segments(j, pass%candidates(c)))
        end do
        if (within_reach(pass%node_offset(i), pass%segment_offset(pass%candidates(c)), &
                         pass%depth(pass%candidates(c)), corners, coordinates(:, pass%nodes(i)))) &
          weight(i) = weight(i) + projection_weight
      end do
    end do
    !$omp end parallel do
    total = sum(int(weight, int64))
    first_weight = (total*rank)/rank_count
    last_weight = (total*(rank + 1))/rank_count
    ! this rank: the nodes whose weights end in (first_weight, last_weight]
    first = pass%node_count + 1
    last = 0
    before = 0
    do i = 1, pass%node_count
      before = before + weight(i)
      if (before > first_weight .and. before <= last_weight) then
        first = min(first, i)
        last = i
      end if
    end do
    allocate (pass%is_handled(pass%node_count))
    pass%is_handled = .false.
    if (last >= first) pass%is_handled(first:last) = .true.
    pass%handled = [(i, i=first, last)]
    do i = 1, pass%node_count
      if (was_handled(i) .and. .not. pass%is_handled(i) .and. carries_record(pass, i)) call note_received(pass, i)
    end do
  end subroutine share_out_pairs

  !> Secondary node `i` of `pass` is another rank's: its pair values are cleared at the next
  !> exchange, unless that rank sends them.
  subroutine note_received(pass, i)
    type(contact_pass_t), intent(inout) :: pass
    integer, intent(in) :: i
    integer, allocatable :: grown(:)
    if (pass%received_count == size(pass%received)) then
      allocate (grown(max(16, 2*size(pass%received))))
      grown(1:pass%received_count) = pass%received(1:pass%received_count)
      call move_alloc(grown, pass%received)
    end if
    pass%received_count = pass%received_count + 1
    pass%received(pass%received_count) = i
  end subroutine note_received

  !> After the first evaluation: how many nodes penetrated from the start, the deepest and where
  !> (report_initial_penetrations); from then on the pairs take the initial depths off.
  subroutine sum_up_initial_penetrations(pass)
    type(contact_pass_t), intent(inout) :: pass
    integer :: i
    pass%initial_checked = .true.
    pass%initial_count = count(pass%initial_depth > 0.0_wp)
    if (pass%initial_count > 0) then
      i = maxloc(pass%initial_depth, dim=1)
      pass%initial_deepest = pass%initial_depth(i)
      pass%initial_node = pass%nodes(i)
    end if
  end subroutine sum_up_initial_penetrations

  !> This rank's pair records into `buffer` (pair_record_size values each, contacts, passes and
  !> nodes in order; the buffer grows when they do not fit, and is kept), `records` of them: its
  !> handled secondary nodes with a pair, a depth, an initial depth or a friction spring
  !> (carries_record; the others hold no pair, which the receivers assume).
  subroutine pack_pair_records(contacts, buffer, records)
    type(contact_state_t), intent(in) :: contacts(:)
    real(wp), allocatable, intent(inout) :: buffer(:)
    integer, intent(out) :: records
    real(wp), allocatable :: grown(:)
    integer :: k, p, h, i, at
    if (.not. allocated(buffer)) allocate (buffer(16*pair_record_size))
    at = 0
    do k = 1, size(contacts)
      do p = 1, contacts(k)%pass_count
        associate (pass => contacts(k)%passes(p))
          if (.not. allocated(pass%handled)) cycle
          do h = 1, size(pass%handled)
            i = pass%handled(h)
            if (.not. carries_record(pass, i)) cycle
            if (at + pair_record_size > size(buffer)) then
              allocate (grown(2*size(buffer) + pair_record_size))
              grown(1:at) = buffer(1:at)
              call move_alloc(grown, buffer)
            end if
            buffer(at + 1:at + pair_record_size) = [real(k, wp), real(p, wp), real(i, wp), &
              real(pass%pair_segment(i), wp), pass%pair_side(i), pass%pair_depth(i), pass%initial_depth(i), &
              pass%pair_weights(:, i), pass%pair_force(:, i), pass%tangential(:, i)]
            at = at + pair_record_size
          end do
        end associate
      end do
    end do
    records = at/pair_record_size
  end subroutine pack_pair_records

  !> Every rank's records (`records` of them in `buffer`): the pairs of the nodes other ranks
  !> handle replace those of the last exchange, which are cleared first; this rank's own are
  !> already in place.
  subroutine unpack_pair_records(contacts, buffer, records)
    type(contact_state_t), intent(inout) :: contacts(:)
    real(wp), intent(in) :: buffer(:)
    integer, intent(in) :: records
    integer :: k, p, i, n, at
    do k = 1, size(contacts)
      do p = 1, contacts(k)%pass_count
        associate (pass => contacts(k)%passes(p))
          if (.not. allocated(pass%received)) cycle
          ! (a node that became this rank's at a search holds this cycle's own pair)
          do n = 1, pass%received_count
            if (.not. pass%is_handled(pass%received(n))) call clear_pair(pass, pass%received(n))
          end do
          pass%received_count = 0
        end associate
      end do
    end do
    do n = 1, records
      at = (n - 1)*pair_record_size
      k = nint(buffer(at + 1))
      p = nint(buffer(at + 2))
      i = nint(buffer(at + 3))
      associate (pass => contacts(k)%passes(p))
        if (pass%is_handled(i)) cycle
        call note_received(pass, i)
        pass%pair_segment(i) = nint(buffer(at + 4))
        pass%pair_side(i) = buffer(at + 5)
        pass%pair_depth(i) = buffer(at + 6)
        pass%initial_depth(i) = buffer(at + 7)
        pass%pair_weights(:, i) = buffer(at + 8:at + 11)
        pass%pair_force(:, i) = buffer(at + 12:at + 14)
        pass%tangential(:, i) = buffer(at + 15:at + 17)
      end associate
    end do
  end subroutine unpack_pair_records

  !> Whether secondary node `i` of `pass` has anything for the other ranks.
  logical function carries_record(pass, i)
    type(contact_pass_t), intent(in) :: pass
    integer, intent(in) :: i
    carries_record = pass%pair_segment(i) /= 0 .or. pass%pair_depth(i) /= 0.0_wp .or. &
                     pass%initial_depth(i) /= 0.0_wp .or. any(pass%tangential(:, i) /= 0.0_wp)
  end function carries_record

  !> Every secondary node of `pass` without a pair (the initial penetrations still ignored are
  !> kept): set-up, and a contact outside its birth and death times.
  subroutine clear_pairs(pass)
    type(contact_pass_t), intent(inout) :: pass
    pass%pair_segment = 0
    pass%pair_side = 1.0_wp
    pass%pair_depth = 0.0_wp
    pass%pair_weights = 0.0_wp
    pass%pair_force = 0.0_wp
    pass%tangential = 0.0_wp
  end subroutine clear_pairs

  !> Secondary node `i` of `pass` without a pair, nor an initial penetration: what a node holds
  !> when its rank sends no record for it.
  subroutine clear_pair(pass, i)
    type(contact_pass_t), intent(inout) :: pass
    integer, intent(in) :: i
    pass%pair_segment(i) = 0
    pass%pair_side(i) = 1.0_wp
    pass%pair_depth(i) = 0.0_wp
    pass%initial_depth(i) = 0.0_wp
    pass%pair_weights(:, i) = 0.0_wp
    pass%pair_force(:, i) = 0.0_wp
    pass%tangential(:, i) = 0.0_wp
  end subroutine clear_pair

  !> One warning line per contact whose first evaluation found penetrating nodes (then never
  !> again): how many (over its passes), the deepest and where. Their initial penetration is
  !> ignored.
  subroutine report_initial_penetrations(model, contacts, time, log)
    type(model_t), intent(in) :: model
    type(contact_state_t), intent(inout) :: contacts(:)
    real(wp), intent(in) :: time
    type(message_log_t), intent(inout) :: log
    character(len=300) :: text
    integer :: k, p, count, node
    real(wp) :: deepest
    do k = 1, size(contacts)
      if (contacts(k)%pass_count == 0) cycle
      if (.not. all(contacts(k)%passes(1:contacts(k)%pass_count)%initial_checked) .or. &
          all(contacts(k)%passes(1:contacts(k)%pass_count)%initial_reported)) cycle
      count = 0
      deepest = 0.0_wp
      node = 0
      do p = 1, contacts(k)%pass_count
        associate (pass => contacts(k)%passes(p))
          pass%initial_reported = .true.
          count = count + pass%initial_count
          if (pass%initial_count > 0 .and. pass%initial_deepest > deepest) then
            deepest = pass%initial_deepest
            node = pass%initial_node
          end if
        end associate
      end do
      if (count == 0) cycle
      write (text, '(a,i0,a,i0,a,es10.3,a,i0,a,es10.3,a)') "warning: contact ", model%contacts(k)%id, ": ", &
        count, " node(s) penetrate at the first contact check (t = ", time, "), the deepest node ", &
        model%node_ids(node), " by ", deepest, "; these initial penetrations are ignored (as LS-DYNA's IGNORE = 1)"
      call log_message(log, trim(text))
    end do
  end subroutine report_initial_penetrations

  !> Power of the pair forces of a pass with `velocity`: sum of f . (v_node - sum_j w_j v_j).
  real(wp) function pass_work(pass, velocity)
    type(contact_pass_t), intent(in) :: pass
    real(wp), intent(in) :: velocity(:, :)
    integer :: i, j
    real(wp) :: relative(3)
    pass_work = 0.0_wp
    do i = 1, pass%node_count
      if (pass%pair_segment(i) == 0) cycle
      relative = velocity(:, pass%nodes(i))
      do j = 1, 4
        relative = relative - pass%pair_weights(j, i)*velocity(:, pass%segments(j, pass%pair_segment(i)))
      end do
      pass_work = pass_work + dot_product(pass%pair_force(:, i), relative)
    end do
  end function pass_work

  !> Rebuild the candidate lists when a node of the pass has moved half the margin since the
  !> last build (two surfaces then approached by at most the margin), or after BSORT cycles.
  subroutine update_search(pass, coordinates, bucket_interval, rebuilt)
    type(contact_pass_t), intent(inout) :: pass
    real(wp), intent(in) :: coordinates(:, :)
    integer, intent(in) :: bucket_interval
    logical, intent(out) :: rebuilt
    real(wp) :: moved, low(3), high(3), common(3)
    integer :: n
    rebuilt = .false.
    pass%cycles_since_build = pass%cycles_since_build + 1
    moved = 0.0_wp
    if (pass%built .and. size(pass%tracked) > 0) then
      ! Pairs depend on relative motion only: a motion common to the whole pass (a car driving
      ! into a wall) is taken out, so that the lists live until the parts move relative to each
      ! other. Any common vector keeps the test safe; the midrange of the displacements (exact
      ! min/max, the same for any thread count) makes the largest remaining motion smallest.
      low = huge(1.0_wp)
      high = -huge(1.0_wp)
      !$omp parallel do schedule(static) default(shared) private(n) reduction(min:low) reduction(max:high)
      do n = 1, size(pass%tracked)
        low = min(low, coordinates(:, pass%tracked(n)) - pass%tracked_at_build(:, n))
        high = max(high, coordinates(:, pass%tracked(n)) - pass%tracked_at_build(:, n))
      end do
      !$omp end parallel do
      common = 0.5_wp*(low + high)
      !$omp parallel do schedule(static) default(shared) private(n) reduction(max:moved)
      do n = 1, size(pass%tracked)
        moved = max(moved, norm2(coordinates(:, pass%tracked(n)) - pass%tracked_at_build(:, n) - common))
      end do
      !$omp end parallel do
    end if
    if (pass%built .and. moved < 0.5_wp*pass%margin .and. &
        (bucket_interval <= 0 .or. pass%cycles_since_build < bucket_interval)) return
    call build_candidates(pass, coordinates)
    rebuilt = .true.
  end subroutine update_search

  !> Bucket sort: segment boxes (grown by the margin, the contact depth and the parametric
  !> tolerance) into a uniform grid with cells of the median box (at most about two cells per
  !> segment), each segment in every cell its box covers; then each node's candidates from its
  !> cell. A node within reach of a segment now (pair_forces' test) was within its grown box at
  !> the build, as long as no node has moved half the margin since.
  subroutine build_candidates(pass, coordinates)
    type(contact_pass_t), intent(inout) :: pass
    real(wp), intent(in) :: coordinates(:, :)
    real(wp) :: low(3), high(3), cell, extent(3), grow
    integer :: dims(3), s, i, c, j, total, lo(3), hi(3), ix, iy, iz, cell_count, own
    integer, allocatable :: counts(:)
    pass%built = .true.
    pass%cycles_since_build = 0
    do i = 1, size(pass%tracked)
      pass%tracked_at_build(:, i) = coordinates(:, pass%tracked(i))
    end do
    pass%candidate_first(1) = 1
    if (pass%segment_count == 0 .or. pass%node_count == 0) then
      pass%candidate_first = 1
      return
    end if
    do s = 1, pass%segment_count
      do j = 1, 3
        pass%box(j, s) = min(coordinates(j, pass%segments(1, s)), coordinates(j, pass%segments(2, s)), &
                             coordinates(j, pass%segments(3, s)), coordinates(j, pass%segments(4, s)))
        pass%box(j + 3, s) = max(coordinates(j, pass%segments(1, s)), coordinates(j, pass%segments(2, s)), &
                                 coordinates(j, pass%segments(3, s)), coordinates(j, pass%segments(4, s)))
      end do
      ! pair_forces reaches the node offset, the depth and the parametric tolerance of the
      ! segment's current extent (which may grow by the margin before the next build)
      grow = pass%margin + pass%depth(s) + pass%largest_node_offset + &
             (parametric_limit - 1.0_wp)*(maxval(pass%box(4:6, s) - pass%box(1:3, s)) + pass%margin)
      pass%box(1:3, s) = pass%box(1:3, s) - grow
      pass%box(4:6, s) = pass%box(4:6, s) + grow
    end do
    low = minval(pass%box(1:3, :), dim=2)
    high = maxval(pass%box(4:6, :), dim=2)
    extent = high - low
    cell = max(pass%cell_size, tiny(1.0_wp))
    do
      dims = max(1, ceiling(extent/cell))
      if (real(dims(1), wp)*dims(2)*dims(3) <= 2.0_wp*pass%segment_count + 8.0_wp) exit
      cell = 1.26_wp*cell
    end do
    cell_count = dims(1)*dims(2)*dims(3)
    ! segments into cells (a large segment into every cell its box covers)
    if (size(pass%cell_first) < cell_count + 1) then
      deallocate (pass%cell_first)
      allocate (pass%cell_first(cell_count + 1))
    end if
    pass%cell_first(1:cell_count + 1) = 0
    do s = 1, pass%segment_count
      call box_cells(pass%box(:, s), lo, hi)
      do iz = lo(3), hi(3)
        do iy = lo(2), hi(2)
          do ix = lo(1), hi(1)
            c = ix + dims(1)*(iy - 1 + dims(2)*(iz - 1))
            pass%cell_first(c + 1) = pass%cell_first(c + 1) + 1
          end do
        end do
      end do
    end do
    pass%cell_first(1) = 1
    do c = 1, cell_count
      pass%cell_first(c + 1) = pass%cell_first(c + 1) + pass%cell_first(c)
    end do
    total = pass%cell_first(cell_count + 1) - 1
    if (size(pass%cell_segments) < total) then
      deallocate (pass%cell_segments)
      allocate (pass%cell_segments(2*total), source=0)
    end if
    allocate (counts(cell_count))
    counts = pass%cell_first(1:cell_count)
    do s = 1, pass%segment_count
      call box_cells(pass%box(:, s), lo, hi)
      do iz = lo(3), hi(3)
        do iy = lo(2), hi(2)
          do ix = lo(1), hi(1)
            c = ix + dims(1)*(iy - 1 + dims(2)*(iz - 1))
            pass%cell_segments(counts(c)) = s
            counts(c) = counts(c) + 1
          end do
        end do
      end do
    end do
    ! candidates per node: count, offsets, fill (each node writes only its own range)
    !$omp parallel do schedule(static) default(shared) private(i)
    do i = 1, pass%node_count
      pass%candidate_first(i + 1) = candidate_count(i, .false.)
    end do
    !$omp end parallel do
    pass%candidate_first(1) = 1
    do i = 1, pass%node_count
      pass%candidate_first(i + 1) = pass%candidate_first(i + 1) + pass%candidate_first(i)
    end do
    total = pass%candidate_first(pass%node_count + 1) - 1
    if (size(pass%candidates) < total) then
      deallocate (pass%candidates)
      allocate (pass%candidates(2*total), source=0)
    end if
    !$omp parallel do schedule(static) default(shared) private(i, own)
    do i = 1, pass%node_count
      own = candidate_count(i, .true.)
    end do
    !$omp end parallel do
  contains
    subroutine box_cells(box, first, last)
      real(wp), intent(in) :: box(6)
      integer, intent(out) :: first(3), last(3)
      first = min(dims, max(1, int((box(1:3) - low)/cell) + 1))
      last = min(dims, max(1, int((box(4:6) - low)/cell) + 1))
    end subroutine box_cells

    !> Candidates of secondary node `i` (segments of its cell whose box holds it, less its own
    !> neighbourhood in single-surface contact); with `fill`, written to its list range.
    integer function candidate_count(i, fill)
      integer, intent(in) :: i
      logical, intent(in) :: fill
      integer :: cell_index(3), m, seg, slot, c
      real(wp) :: x(3)
      candidate_count = 0
      x = coordinates(:, pass%nodes(i))
      if (any(x < low) .or. any(x > high)) return
      cell_index = min(dims, max(1, int((x - low)/cell) + 1))
      m = cell_index(1) + dims(1)*(cell_index(2) - 1 + dims(2)*(cell_index(3) - 1))
      slot = pass%candidate_first(i)
      do c = pass%cell_first(m), pass%cell_first(m + 1) - 1
        seg = pass%cell_segments(c)
        if (any(x < pass%box(1:3, seg)) .or. any(x > pass%box(4:6, seg))) cycle
        if (pass%single) then
          if (excluded(i, seg)) cycle
        end if
        candidate_count = candidate_count + 1
        if (fill) then
          pass%candidates(slot) = seg
          slot = slot + 1
        end if
      end do
    end function candidate_count

    !> Single surface: a node does not contact its own segments nor segments sharing a node
    !> with them.
    logical function excluded(i, seg)
      integer, intent(in) :: i, seg
      integer :: q, r
      excluded = any(pass%segments(:, seg) == pass%nodes(i))
      if (excluded) return
      do q = pass%own_first(i), pass%own_first(i + 1) - 1
        do r = 1, 4
          if (any(pass%segments(:, seg) == pass%segments(r, pass%own_segments(q)))) then
            excluded = .true.
            return
          end if
        end do
      end do
    end function excluded
  end subroutine build_candidates

  !> The pair of each secondary node: the penetrated candidate with the least penetration,
  !> and its force (normal penalty, optional VDC damping, Coulomb friction).
  subroutine pair_forces(contact, pass, step, coordinates, velocity, mass)
    type(contact_t), intent(in) :: contact
    type(contact_pass_t), intent(inout) :: pass
    real(wp), intent(in) :: step, coordinates(:, :), velocity(:, :), mass(:)
    integer :: i, c, seg, best, j, h
    real(wp) :: x(3), corners(3, 4), weights(4), normal(3), gap, best_depth, best_weights(4), best_normal(3)
    real(wp) :: relative(3), stiffness, node_mass, segment_mass, reduced_mass, normal_force, damping
    real(wp) :: tangential(3), sliding(3), friction, limit, size_t, penetration, side, best_side
    real(wp) :: reach, low(3), high(3), reachable
    logical :: inside
    !$omp parallel do schedule(static) default(shared) private(i, c, seg, best, j, x, corners, weights, &
    !$omp& normal, gap, best_depth, best_weights, best_normal, relative, stiffness, node_mass, segment_mass, &
    !$omp& reduced_mass, normal_force, damping, tangential, sliding, friction, limit, size_t, inside, penetration, &
    !$omp& side, best_side, reach, low, high, reachable, h)
    do h = 1, size(pass%handled)
      i = pass%handled(h)
      x = coordinates(:, pass%nodes(i))
      best = 0
      best_depth = huge(1.0_wp)
      best_side = 1.0_wp
      do c = pass%candidate_first(i), pass%candidate_first(i + 1) - 1
        seg = pass%candidates(c)
        ! (corner by corner: a vector subscript would make a heap temporary per candidate)
        do j = 1, 4
          corners(:, j) = coordinates(:, pass%segments(j, seg))
        end do
        ! the candidate lists hold every segment within the search margin; most are out of
        ! reach this cycle, which the segment's current box (grown by the deepest contact and
        ! the parametric tolerance) shows without projecting (within_reach's test, written out
        ! here: the compiler does not inline the call into this, the hottest contact loop)
        reach = pass%node_offset(i) + max(pass%segment_offset(seg), pass%depth(seg))
        do j = 1, 3
          low(j) = min(corners(j, 1), corners(j, 2), corners(j, 3), corners(j, 4))
          high(j) = max(corners(j, 1), corners(j, 2), corners(j, 3), corners(j, 4))
        end do
        reach = reach + (parametric_limit - 1.0_wp)*max(high(1) - low(1), high(2) - low(2), high(3) - low(3))
        if (any(x < low - reach) .or. any(x > high + reach)) cycle
        call project_on_segment(x, corners, pass%segments(3, seg) == pass%segments(4, seg), weights, normal, &
                                gap, inside)
        if (.not. inside) cycle
        ! penetration of the node's contact surface (its shell offset) into the segment's: a
        ! solid face is one-sided; a shell is two-sided, with surfaces t/2 on either side, and
        ! pushes the node back to the side it is on
        if (pass%segment_offset(seg) > 0.0_wp) then
          ! the side is the one the node was on when the pair formed; a new pair deeper than
          ! half the contact thickness is a node arriving past the segment's edge or through
          ! it, not a contact (LS-DYNA likewise drops pairs beyond its largest penetration)
          if (seg == pass%pair_segment(i)) then
            side = pass%pair_side(i)
          else
            side = sign(1.0_wp, gap)
          end if
          penetration = pass%node_offset(i) + pass%segment_offset(seg) - side*gap
          if (seg /= pass%pair_segment(i) .and. &
              penetration > 0.5_wp*(pass%node_offset(i) + pass%segment_offset(seg))) cycle
          normal = side*normal
        else
          side = 1.0_wp
          penetration = pass%node_offset(i) - gap
          if (penetration > pass%depth(seg) + pass%node_offset(i)) cycle
        end if
        if (penetration <= 0.0_wp) cycle
        ! the node's own surface must face the segment (an edge or corner node touching a
        ! side face it is level with is not in contact with it)
        if (dot_product(pass%node_normal(:, i), normal) >= 0.0_wp .and. &
            any(pass%node_normal(:, i) /= 0.0_wp)) cycle
        ! a penetration grows only as fast as node and segment approach: one deeper than twice
        ! the node's last penetration plus this step's approach was not reached from outside
        ! (the node came round an edge, or a folding surface swept over it) and is not a contact;
        ! a spring that deep would throw the node out with more energy than the crush holds
        ! (LS-DYNA likewise releases nodes beyond its penetration limit). The first evaluation
        ! records the initial penetrations instead (IGNORE = 1).
        if (pass%initial_checked) then
          relative = velocity(:, pass%nodes(i))
          do j = 1, merge(3, 4, pass%segments(3, seg) == pass%segments(4, seg))
            relative = relative - weights(j)*velocity(:, pass%segments(j, seg))
          end do
          reachable = reach_factor*(pass%pair_depth(i) + step*max(0.0_wp, -dot_product(relative, normal)))
          if (penetration > reachable) cycle
        end if
        if (penetration < best_depth) then
          best = seg
          best_depth = penetration
          best_weights = weights
          best_normal = normal
          best_side = side
        end if
      end do
      ! initial penetrations are ignored (IGNORE = 1): the first evaluation records them, and
      ! a node that backs out keeps only what is left
      if (.not. pass%initial_checked) then
        if (best > 0) pass%initial_depth(i) = best_depth
      else if (best > 0) then
        pass%initial_depth(i) = min(pass%initial_depth(i), best_depth)
      else
        pass%initial_depth(i) = 0.0_wp
      end if
      pass%pair_depth(i) = 0.0_wp
      if (best > 0) pass%pair_depth(i) = best_depth
      if (best > 0) then
        best_depth = best_depth - pass%initial_depth(i)
        if (best_depth <= 0.0_wp) best = 0
      end if
      if (best == 0) then
        ! (side and weights too: a node without a pair holds the values of set-up, the same
        ! whichever rank computed it, so that restart dumps do not depend on the rank count)
        pass%pair_segment(i) = 0
        pass%pair_side(i) = 1.0_wp
        pass%pair_weights(:, i) = 0.0_wp
        pass%pair_force(:, i) = 0.0_wp
        pass%tangential(:, i) = 0.0_wp
        cycle
      end if
      relative = velocity(:, pass%nodes(i))
      segment_mass = 0.0_wp
      do j = 1, 4
        relative = relative - best_weights(j)*velocity(:, pass%segments(j, best))
        ! a point just outside the segment (the parametric tolerance) has a slightly negative
        ! weight: with a heavy corner (a lumped mass) the weighted mass would turn negative and
        ! the pair spring infinite, so only the corners it lies towards count
        segment_mass = segment_mass + max(best_weights(j), 0.0_wp)*mass(pass%segments(j, best))
      end do
      node_mass = mass(pass%nodes(i))
      reduced_mass = node_mass*segment_mass/max(node_mass + segment_mass, tiny(1.0_wp))
      stiffness = pass%stiffness(best)
      ! a pair spring must not set a shorter stable step than the elements: cap it at
      ! stable_fraction m* / dt^2 (coarse solids with SLSFAC 0.1 and both passes otherwise
      ! exceed the step TSSFAC leaves them)
      if (step > 0.0_wp) stiffness = min(stiffness, stable_fraction*reduced_mass/step**2)
      if (contact%soft == 1 .and. step > 0.0_wp) &
        stiffness = max(stiffness, 0.5_wp*contact%soft_scale*reduced_mass/step**2)
      normal_force = stiffness*best_depth
      if (contact%viscous_damping > 0.0_wp) then
        damping = 0.01_wp*contact%viscous_damping*2.0_wp*sqrt(stiffness*reduced_mass)
        normal_force = max(0.0_wp, normal_force - damping*dot_product(relative, best_normal))
      end if
      tangential = 0.0_wp
      if (contact%static_friction > 0.0_wp .or. contact%dynamic_friction > 0.0_wp) then
        ! elastic slip: the spring force of the last cycle, turned into the current tangent
        ! plane, plus k times the tangential slip increment; capped at mu |f_n|
        tangential = pass%tangential(:, i) - dot_product(pass%tangential(:, i), best_normal)*best_normal
        sliding = relative - dot_product(relative, best_normal)*best_normal
        tangential = tangential - stiffness*step*sliding
        friction = contact%friction_scale*(contact%dynamic_friction + (contact%static_friction - &
                   contact%dynamic_friction)*exp(-contact%decay*norm2(sliding)))
        limit = friction*normal_force
        if (contact%viscous_friction > 0.0_wp) &
          limit = min(limit, contact%viscous_scale*contact%viscous_friction*pass%area(best))
        size_t = norm2(tangential)
        if (size_t > limit) tangential = tangential*(limit/size_t)
      end if
      pass%tangential(:, i) = tangential
      pass%pair_segment(i) = best
      pass%pair_side(i) = best_side
      pass%pair_weights(:, i) = best_weights
      if (pass%segments(3, best) == pass%segments(4, best)) pass%pair_weights(4, i) = 0.0_wp
      pass%pair_force(:, i) = normal_force*best_normal + tangential
    end do
    !$omp end parallel do
  end subroutine pair_forces

  !> Whether a secondary node at `x` (shell offset `node_offset`) may touch a segment with the
  !> given corners (shell offset `segment_offset`, contact depth `depth`): the candidate lists
  !> hold every segment within the search margin, most out of reach this cycle, which the
  !> segment's current box (grown by the deepest contact, the node's shell offset and the
  !> parametric tolerance) shows without projecting. (pair_forces writes the same test out.)
  pure logical function within_reach(node_offset, segment_offset, depth, corners, x)
    real(wp), intent(in) :: node_offset, segment_offset, depth, corners(3, 4), x(3)
    real(wp) :: reach, low(3), high(3)
    integer :: j
    reach = node_offset + max(segment_offset, depth)
    do j = 1, 3
      low(j) = min(corners(j, 1), corners(j, 2), corners(j, 3), corners(j, 4))
      high(j) = max(corners(j, 1), corners(j, 2), corners(j, 3), corners(j, 4))
    end do
    reach = reach + (parametric_limit - 1.0_wp)*max(high(1) - low(1), high(2) - low(2), high(3) - low(3))
    within_reach = .true.
    do j = 1, 3
      if (x(j) < low(j) - reach .or. x(j) > high(j) + reach) within_reach = .false.
    end do
  end function within_reach

  !> Closest point of a segment to `x`: weights of the corners (bilinear shape functions at
  !> the point; barycentric for a triangle), the unit outward normal there and the signed gap
  !> along it. `inside`: the point lies on the segment within the parametric tolerance.
  pure subroutine project_on_segment(x, corners, triangle, weights, normal, gap, inside)
    real(wp), intent(in) :: x(3), corners(3, 4)
    logical, intent(in) :: triangle
    real(wp), intent(out) :: weights(4), normal(3), gap
    logical, intent(out) :: inside
    real(wp) :: xi, eta, point(3), d_xi(3), d_eta(3), residual(3), a11, a12, a22, b1, b2, det, area
    real(wp) :: edge1(3), edge2(3), tolerance
    integer :: iteration
    inside = .false.
    gap = 0.0_wp
    weights = 0.0_wp
    normal = 0.0_wp
    tolerance = parametric_limit - 1.0_wp
    if (triangle) then
      edge1 = corners(:, 2) - corners(:, 1)
      edge2 = corners(:, 3) - corners(:, 1)
      normal = cross(edge1, edge2)
      area = norm2(normal)
      if (area <= 0.0_wp) return
      normal = normal/area
      residual = x - corners(:, 1)
      a11 = dot_product(edge1, edge1)
      a12 = dot_product(edge1, edge2)
      a22 = dot_product(edge2, edge2)
      b1 = dot_product(edge1, residual)
      b2 = dot_product(edge2, residual)
      det = a11*a22 - a12*a12
      xi = (a22*b1 - a12*b2)/det
      eta = (a11*b2 - a12*b1)/det
      weights(1:3) = [1.0_wp - xi - eta, xi, eta]
      inside = all(weights(1:3) >= -0.5_wp*tolerance)
      gap = dot_product(residual, normal)
      return
    end if
    xi = 0.0_wp
    eta = 0.0_wp
    do iteration = 1, 6
      call bilinear(xi, eta, point, d_xi, d_eta)
      residual = x - point
      a11 = dot_product(d_xi, d_xi)
      a12 = dot_product(d_xi, d_eta)
      a22 = dot_product(d_eta, d_eta)
      b1 = dot_product(d_xi, residual)
      b2 = dot_product(d_eta, residual)
      det = a11*a22 - a12*a12
      if (det <= 0.0_wp) return
      xi = max(-2.0_wp, min(2.0_wp, xi + (a22*b1 - a12*b2)/det))
      eta = max(-2.0_wp, min(2.0_wp, eta + (a11*b2 - a12*b1)/det))
    end do
    call bilinear(xi, eta, point, d_xi, d_eta)
    normal = cross(d_xi, d_eta)
    area = norm2(normal)
    if (area <= 0.0_wp) return
    normal = normal/area
    weights = 0.25_wp*[(1.0_wp - xi)*(1.0_wp - eta), (1.0_wp + xi)*(1.0_wp - eta), &
                       (1.0_wp + xi)*(1.0_wp + eta), (1.0_wp - xi)*(1.0_wp + eta)]
    gap = dot_product(x - point, normal)
    inside = abs(xi) <= parametric_limit .and. abs(eta) <= parametric_limit
  contains
    pure subroutine bilinear(s, t, position, ds, dt)
      real(wp), intent(in) :: s, t
      real(wp), intent(out) :: position(3), ds(3), dt(3)
      position = 0.25_wp*((1.0_wp - s)*(1.0_wp - t)*corners(:, 1) + (1.0_wp + s)*(1.0_wp - t)*corners(:, 2) + &
                          (1.0_wp + s)*(1.0_wp + t)*corners(:, 3) + (1.0_wp - s)*(1.0_wp + t)*corners(:, 4))
      ds = 0.25_wp*(-(1.0_wp - t)*corners(:, 1) + (1.0_wp - t)*corners(:, 2) + (1.0_wp + t)*corners(:, 3) - &
                    (1.0_wp + t)*corners(:, 4))
      dt = 0.25_wp*(-(1.0_wp - s)*corners(:, 1) - (1.0_wp + s)*corners(:, 2) + (1.0_wp + s)*corners(:, 3) + &
                    (1.0_wp - s)*corners(:, 4))
    end subroutine bilinear
  end subroutine project_on_segment

  !> Median of `values` (the upper one of an even count; 0 for none), by quickselect on a
  !> copy: linear time on average, used at set-up only.
  pure real(wp) function median(values)
    real(wp), intent(in) :: values(:)
    real(wp), allocatable :: work(:)
    real(wp) :: pivot, swap
    integer :: left, right, i, j, target
    median = 0.0_wp
    if (size(values) == 0) return
    work = values
    target = size(work)/2 + 1
    left = 1
    right = size(work)
    do while (left < right)
      pivot = work((left + right)/2)
      i = left
      j = right
      do while (i <= j)
        do while (work(i) < pivot)
          i = i + 1
        end do
        do while (work(j) > pivot)
          j = j - 1
        end do
        if (i <= j) then
          swap = work(i)
          work(i) = work(j)
          work(j) = swap
          i = i + 1
          j = j - 1
        end if
      end do
      if (target <= j) then
        right = j
      else if (target >= i) then
        left = i
      else
        exit
      end if
    end do
    median = work(target)
  end function median

  pure function cross(a, b) result(c)
    real(wp), intent(in) :: a(3), b(3)
    real(wp) :: c(3)
    c = [a(2)*b(3) - a(3)*b(2), a(3)*b(1) - a(1)*b(3), a(1)*b(2) - a(2)*b(1)]
  end function cross

  !> rcforc's masses: the nodal mass in contact on each side, (SURFA, SURFB), after the last
  !> force call: the secondary nodes of a pass that penetrated and the nodes of the segments they
  !> met, each node once per side (summed in node order). A node the contact excludes (interior
  !> meshfree particle) is never in contact.
  function mass_in_contact(contact, node_mass) result(mass)
    type(contact_state_t), intent(in) :: contact
    real(wp), intent(in) :: node_mass(:)
    real(wp) :: mass(2)
    logical, allocatable :: touching(:, :)
    integer :: pass, k, corner, secondary_side, node
    allocate (touching(size(node_mass), 2))
    touching = .false.
    do pass = 1, contact%pass_count
      associate (this => contact%passes(pass))
        secondary_side = merge(1, 2, this%side_sign > 0.0_wp)
        if (.not. allocated(this%pair_depth)) cycle
        do k = 1, size(this%nodes)
          if (this%pair_depth(k) <= 0.0_wp .or. this%pair_segment(k) <= 0) cycle
          touching(this%nodes(k), secondary_side) = .true.
          do corner = 1, 4
            node = this%segments(corner, this%pair_segment(k))
            if (node > 0) touching(node, 3 - secondary_side) = .true.
          end do
        end do
      end associate
    end do
    mass = 0.0_wp
    do node = 1, size(node_mass)
      if (touching(node, 1)) mass(1) = mass(1) + node_mass(node)
      if (touching(node, 2)) mass(2) = mass(2) + node_mass(node)
    end do
  end function mass_in_contact

end module penalty_contact
