!> The domain partition of an MPI run: which rank owns each element block and each node, and
!> which blocks a rank computes (stage 1 of the distributed cycle, see docs/parallel_scaling.md).
!>
!> The unit of work is the element group's block (block_size lanes of one part; the same blocks
!> for any number of ranks). Every rank reads the deck and sets up the whole model; a rank
!> computes the blocks it owns and every block touching a node it owns (ghost blocks, computed
!> again there), so each owned node receives all its contributions in the one-rank order and
!> its force is the same sum as on one rank. The owned nodes' forces are then exchanged; rigid
!> bodies, walls, tied contacts and contact are done by every rank on the whole model.
!>
!> The partition, computed alike on every rank from the model alone (serial METIS with a fixed
!> seed is deterministic for a given input):
!> - two candidates, both METIS k-way (METIS_PartGraphKway; Karypis & Kumar, SIAM J. Sci.
!>   Comput. 20 (1998) 359) weighted by the estimated cost per cycle (`lane_cost`):
!>   (a) on the element graph (FE solids, shells, beams, meshfree background cells; adjacent
!>   when they share a node), each block then to the rank owning most of its lanes (ties: the
!>   lowest rank); (b) on the graph of the blocks (adjacent when they share a node, edges
!>   weighted by the nodes shared);
!> - in each, blocks move between neighbouring ranks until no move evens out a pair of ranks
!>   (balance_owners), as blocks are coarse;
!> - kept: the candidate whose largest computed cost (owned and ghost blocks) is smaller, (a) on
!>   a tie (choose_owners). A graph without edges, or one METIS refuses, is split contiguously in
!>   block order by cost instead;
!> - a node belongs to one of the ranks owning a block touching it (nodes no block touches:
!>   rank 0): the interface nodes are dealt out so that the ranks' computed costs stay even
!>   (own_nodes);
!> - a rank computes the blocks it owns and the blocks touching a node it owns.
!> One rank owns everything and calls no METIS. More ranks than blocks is refused.
!>
!> Elements in no block (rigid parts: the rigid bodies are replicated) get rank -1 in the report.
module domain_partition
  use, intrinsic :: iso_c_binding, only: c_int, c_ptr, c_null_ptr, c_associated, c_f_pointer, c_loc
  use metis_library, only: idx_t, metis_ok, metis_option_count, metis_option_seed, metis_option_numbering, &
                           metis_set_default_options, metis_mesh_to_dual, metis_part_graph_kway, metis_free
  use kinds, only: wp
  use model, only: model_t
  use error_handling, only: error_t, make_error
  use text_format, only: integer_text, fixed_text
  use element_group, only: group_holder_t, family_solid, family_shell, family_beam
  use run_summary, only: partition_summary_t
  use signal_hold, only: signal_mask_t, hold_termination_signal, release_held_signals
  use rank_communication, only: rank_index, integers_from_first
  implicit none
  private

  public :: group_blocks_t, domain_partition_t, partition_domains, partition_text, lane_cost

  !> One element group's blocks (in element_groups' order, run%state%groups).
  type :: group_blocks_t
    integer, allocatable :: owner(:)     !< 0-based rank owning each block of the group
    logical, allocatable :: computed(:)  !< this rank computes the block (owned, or touches an owned node)
  end type group_blocks_t

  !> The partition as seen from one rank, and the figures of all ranks (`report`).
  type :: domain_partition_t
    integer :: rank_count = 1, rank = 0
    type(group_blocks_t), allocatable :: groups(:)  !< in element_groups' order (run%state%groups)
    integer, allocatable :: node_owner(:)           !< 0-based rank owning each node
    !> per rank: elements by kind, blocks, ghost blocks, owned and interface nodes, cost and
    !> imbalance; per element its rank (results.h5 /run/partition, d3hsp, the set-up print)
    type(partition_summary_t) :: report
  end type domain_partition_t

  !> Any fixed seed makes METIS's randomized matching repeatable; this one is arbitrary.
  integer(idx_t), parameter :: metis_seed = 20261126_idx_t

  !> The blocks of all groups in one list (set-up work arrays): block k is block
  !> block_local(k) of group block_group(k); its lanes' elements (element_family's list) are
  !> lane_element(lane_offsets(k) : lane_offsets(k+1)-1), its nodes likewise.
  type :: block_list_t
    integer, allocatable :: block_group(:), block_local(:)
    integer, allocatable :: lane_offsets(:), lane_element(:)
    integer, allocatable :: node_offsets(:), node_list(:)
    real(wp), allocatable :: block_cost(:)
  end type block_list_t

contains

  !> Estimated wall-clock cost of one lane of a block of the group named `name` for one cycle,
  !> in nanoseconds (one thread): the partition's weights. A meshfree lane is an integration
  !> point, so a background cell weighs its points together (8 per solid cell, 4 per shell cell).
  !>
  !> Measured on this project's machine (release build, ncpu=1), each group's force-call seconds
  !> from the run summary over its lanes and cycles. The machine is shared and its speed drifts,
  !> so the ratios come from kinds timed in one run where possible:
  !>
  !> | kind           | ns per lane per cycle | run                                                   |
  !> |----------------|-----------------------|-------------------------------------------------------|
  !> | solid          | 150  | tools/make_bench_deck.py --cells 30 30 20 --cycles 200: 148.9 ns per hexahedron (README's make bench: 150) |
  !> | shell          | 360  | tools/make_scaling_deck.py (MAT_003, NIP 3), one run: 1,124.5 ns per shell against 466.5 per hexahedron (load average 6), 2.4 times; inputs/side_impact/coupled.k alone: 538 ns; the tube of make bench (NIP 5, MAT_024): 1,062 |
  !> | meshfree       | 450  | make_bench_deck.py --cells 12 12 12 --efg-cells 12 (elastic-plastic, DX 1.2): 174 ns per point; side_impact's foam ribs: 1,150; the geometric mean |
  !> | meshfree shell | 760  | inputs/side_impact/coupled.k: 3,034 ns per cell, 4 points per cell |
  !> | beam           | 150  | not measured (few beams in a model): taken as a solid |
  !>
  !> The cost of a lane also depends on the material and the number of integration points; these
  !> figures only set the ratios between kinds, which is what the partition needs. A kind not in
  !> the table weighs as a solid. (With the shells at 540, the scaling deck's two ranks at N = 2
  !> waited 74 ms per cycle of 340 for each other.)
  pure real(wp) function lane_cost(name)
    character(len=*), intent(in) :: name
    select case (trim(name))
    case ("solid")
      lane_cost = 150.0_wp
    case ("shell")
      lane_cost = 360.0_wp
    case ("meshfree")
      lane_cost = 450.0_wp
    case ("meshfree shell")
      lane_cost = 760.0_wp
    case ("beam")
      lane_cost = 150.0_wp
    case default
      lane_cost = 150.0_wp
    end select
  end function lane_cost

  !> The partition of the model's element groups (`groups`, in element_groups' order, set up)
  !> over `rank_count` ranks as seen from rank `rank` (module comment). Error: a rank count
  !> below 1, or several ranks and more of them than blocks.
  subroutine partition_domains(model, groups, rank_count, rank, partition, error)
    type(model_t), intent(in) :: model
    type(group_holder_t), intent(in) :: groups(:)
    integer, intent(in) :: rank_count, rank
    type(domain_partition_t), intent(out) :: partition
    type(error_t), allocatable, intent(out) :: error
    type(block_list_t) :: blocks
    integer, allocatable :: block_owner(:)
    integer :: block_total, element_total, g, k

    if (rank_count < 1 .or. rank < 0 .or. rank >= max(rank_count, 1)) then
      call make_error(error, "domain partition: rank "//integer_text(rank)//" of "//integer_text(rank_count)// &
                      " ranks is not a valid rank")
      return
    end if
    call list_blocks(groups, blocks)
    block_total = size(blocks%block_group)
    element_total = 0
    do g = 1, size(groups)
      element_total = element_total + groups(g)%group%element_count()
    end do
    ! (one rank takes any model, also one whose elements are all rigid: no block)
    if (rank_count > 1 .and. block_total == 0) then
      ! rigid bodies, masses and welds are advanced by every rank alike: nothing to share out
      call make_error(error, "domain partition: "//integer_text(rank_count)//" ranks, but the model has no "// &
                      "deformable element to share out among them (its elements are all rigid: no element block); "// &
                      "run it on one rank (without mpirun)")
      return
    end if
    if (rank_count > 1 .and. rank_count > block_total .and. block_total == 1) then
      call make_error(error, "domain partition: "//integer_text(rank_count)//" ranks are more than the model's "// &
                      "1 element block (elements: "//integer_text(element_total)//"; at most 64 of one part per "// &
                      "block); run it on one rank (without mpirun)")
      return
    end if
    if (rank_count > 1 .and. rank_count > block_total) then
      call make_error(error, "domain partition: "//integer_text(rank_count)//" ranks are more than the model's "// &
                      integer_text(block_total)//" element blocks ("//integer_text(element_total)// &
                      " elements, at most 64 of one part per block); use at most "//integer_text(block_total)// &
                      " ranks")
      return
    end if
    partition%rank_count = rank_count
    partition%rank = rank

    allocate (block_owner(block_total))
    block_owner = 0
    partition%report%by_metis = .false.
    partition%report%method = "one rank"
    if (rank_count > 1) then
      ! the first process of a distributed run chooses the owners and hands them to the others
      ! (METIS's graphs are the largest memory of a rank's set-up: about 200 MB on the
      ! 513,600-element scaling deck); alone, or partition=N, this process chooses
      if (rank_index() == 0) call choose_owners(model, groups, blocks, rank_count, block_owner, partition%report)
      call share_choice(block_owner, partition%report)
    end if

    allocate (partition%groups(size(groups)))
    do g = 1, size(groups)
      allocate (partition%groups(g)%owner(groups(g)%group%block_count()), &
                partition%groups(g)%computed(groups(g)%group%block_count()))
    end do
    do k = 1, block_total
      partition%groups(blocks%block_group(k))%owner(blocks%block_local(k)) = block_owner(k)
    end do
    call own_nodes(size(model%node_ids), blocks, block_owner, rank_count, partition%node_owner)
    do k = 1, block_total
      associate (nodes => blocks%node_list(blocks%node_offsets(k):blocks%node_offsets(k + 1) - 1))
        partition%groups(blocks%block_group(k))%computed(blocks%block_local(k)) = &
          block_owner(k) == rank .or. any(partition%node_owner(nodes) == rank)
      end associate
    end do
    call report_partition(model, groups, blocks, block_owner, partition%node_owner, rank_count, partition%report)
  end subroutine partition_domains

  !> The first process's block owners and method to every process of a distributed run (one
  !> process: nothing to do).
  subroutine share_choice(block_owner, report)
    integer, intent(inout) :: block_owner(:)
    type(partition_summary_t), intent(inout) :: report
    character(len=*), parameter :: methods(3) = [character(len=19) :: "contiguous", "metis_kway_elements", &
                                                  "metis_kway_blocks"]
    integer, allocatable :: values(:)
    integer :: method
    method = max(1, findloc(methods, report%method, dim=1))
    values = [block_owner, method]
    call integers_from_first(values)
    block_owner = values(1:size(block_owner))
    report%method = trim(methods(values(size(values))))
    report%by_metis = values(size(values)) > 1
  end subroutine share_choice

  !> The block owners of the better of two partitions, both METIS k-way with the same costs and
  !> both evened out by balance_owners: (a) the element graph, each block to the rank owning most
  !> of its lanes; (b) the graph of the blocks themselves (adjacent when they share nodes, edges
  !> weighted by the nodes shared). (a) follows the mesh finely, but where a part's blocks are
  !> strips or pencils of a structured mesh (element_ordering keeps a deck's order when its
  !> blocks colour better) METIS's boundaries cut through many blocks and the majority rule makes
  !> them ragged: on the 513,600-element scaling deck at 16 ranks a domain's interface was 3.6
  !> times that of a clean cut. (b) cuts between whole blocks. Kept: the one whose largest
  !> computed cost (owned and ghost blocks: what a rank does in stage 1) is smaller, (a) on a tie.
  !> Without METIS (no edge, refused): a contiguous split of the elements in block order.
  subroutine choose_owners(model, groups, blocks, rank_count, block_owner, report)
    type(model_t), intent(in) :: model
    type(group_holder_t), intent(in) :: groups(:)
    type(block_list_t), intent(in) :: blocks
    integer, intent(in) :: rank_count
    integer, intent(inout) :: block_owner(:)
    type(partition_summary_t), intent(inout) :: report
    type(partition_summary_t) :: by_elements, by_blocks
    integer, allocatable :: lane_rank(:), block_graph_owner(:), node_owner(:), node_offsets(:), node_blocks(:)
    logical :: element_metis, block_metis

    call node_block_lists(blocks, size(model%node_ids), node_offsets, node_blocks)
    call rank_elements(model, groups, blocks, rank_count, lane_rank, element_metis)
    call owners_by_majority(blocks, lane_rank, rank_count, block_owner)
    call balance_owners(blocks, node_offsets, node_blocks, rank_count, block_owner)
    report%by_metis = element_metis
    report%method = merge("metis_kway_elements", "contiguous         ", element_metis)

    allocate (block_graph_owner(size(block_owner)))
    call metis_block_ranks(blocks, node_offsets, node_blocks, rank_count, block_graph_owner, block_metis)
    if (.not. block_metis) return
    call balance_owners(blocks, node_offsets, node_blocks, rank_count, block_graph_owner)
    call own_nodes(size(model%node_ids), blocks, block_owner, rank_count, node_owner)
    call report_partition(model, groups, blocks, block_owner, node_owner, rank_count, by_elements)
    call own_nodes(size(model%node_ids), blocks, block_graph_owner, rank_count, node_owner)
    call report_partition(model, groups, blocks, block_graph_owner, node_owner, rank_count, by_blocks)
    if (maxval(by_blocks%rank_computed_cost) < maxval(by_elements%rank_computed_cost) .or. .not. element_metis) then
      block_owner = block_graph_owner
      report%by_metis = .true.
      report%method = "metis_kway_blocks"
    end if
  end subroutine choose_owners

  !> METIS k-way on the graph of the blocks (adjacent when they share a node; edge weight: the
  !> nodes they share; vertex weight: the block's cost). `ok` false when it has no edge or METIS
  !> refuses.
  subroutine metis_block_ranks(blocks, node_offsets, node_blocks, rank_count, block_owner, ok)
    type(block_list_t), intent(in) :: blocks
    integer, intent(in) :: node_offsets(:), node_blocks(:), rank_count
    integer, intent(out) :: block_owner(:)
    logical, intent(out) :: ok
    integer(idx_t), allocatable, target :: offsets(:), neighbours(:), edge_weight(:)
    integer(idx_t), allocatable :: vertex_weight(:), options(:), piece(:)
    integer, allocatable :: shared(:), met(:)
    integer :: k, slot, other, neighbour, met_count, edge_count, m
    integer(idx_t) :: edge_cut
    integer(c_int) :: status
    type(signal_mask_t) :: signal_mask

    ok = .false.
    associate (block_count => size(blocks%block_group))
      allocate (offsets(block_count + 1), shared(block_count), met(block_count), vertex_weight(block_count), &
                neighbours(0), edge_weight(0))
      shared = 0
      offsets(1) = 0
      edge_count = 0
      do k = 1, block_count
        met_count = 0
        do slot = blocks%node_offsets(k), blocks%node_offsets(k + 1) - 1
          associate (node => blocks%node_list(slot))
            do other = node_offsets(node), node_offsets(node + 1) - 1
              neighbour = node_blocks(other)
              if (neighbour == k) cycle
              if (shared(neighbour) == 0) then
                met_count = met_count + 1
                met(met_count) = neighbour
              end if
              shared(neighbour) = shared(neighbour) + 1
            end do
          end associate
        end do
        if (edge_count + met_count > size(neighbours)) then
          neighbours = [neighbours, (0_idx_t, m=1, max(edge_count + met_count, 2*size(neighbours)) - size(neighbours))]
          edge_weight = [edge_weight, (0_idx_t, m=1, size(neighbours) - size(edge_weight))]
        end if
        do m = 1, met_count
          neighbours(edge_count + m) = int(met(m) - 1, idx_t)
          edge_weight(edge_count + m) = int(shared(met(m)), idx_t)
          shared(met(m)) = 0
        end do
        edge_count = edge_count + met_count
        offsets(k + 1) = int(edge_count, idx_t)
        vertex_weight(k) = int(max(1.0_wp, 10.0_wp*blocks%block_cost(k)), idx_t)
      end do
      if (edge_count == 0) return
      allocate (options(metis_option_count), piece(block_count))
      call hold_termination_signal(signal_mask)
      status = metis_set_default_options(options)
      options(metis_option_seed + 1) = metis_seed
      options(metis_option_numbering + 1) = 0
      status = metis_part_graph_kway(int(block_count, idx_t), 1_idx_t, c_loc(offsets), c_loc(neighbours), &
                                     vertex_weight, c_null_ptr, c_loc(edge_weight), int(rank_count, idx_t), &
                                     c_null_ptr, c_null_ptr, options, edge_cut, piece)
      call release_held_signals(signal_mask)
      ok = status == metis_ok
      if (ok) block_owner = int(piece)
    end associate
  end subroutine metis_block_ranks

  !> node -> the blocks touching it: node_blocks(node_offsets(n) : node_offsets(n+1)-1).
  subroutine node_block_lists(blocks, node_count, node_offsets, node_blocks)
    type(block_list_t), intent(in) :: blocks
    integer, intent(in) :: node_count
    integer, allocatable, intent(out) :: node_offsets(:), node_blocks(:)
    integer, allocatable :: next_slot(:)
    integer :: k, slot, node
    allocate (node_offsets(node_count + 1), next_slot(node_count))
    node_offsets = 0
    do slot = 1, size(blocks%node_list)
      node = blocks%node_list(slot)
      node_offsets(node + 1) = node_offsets(node + 1) + 1
    end do
    node_offsets(1) = 1
    do node = 1, node_count
      node_offsets(node + 1) = node_offsets(node + 1) + node_offsets(node)
    end do
    allocate (node_blocks(node_offsets(node_count + 1) - 1))
    next_slot = node_offsets(1:node_count)
    do k = 1, size(blocks%block_group)
      do slot = blocks%node_offsets(k), blocks%node_offsets(k + 1) - 1
        node = blocks%node_list(slot)
        node_blocks(next_slot(node)) = k
        next_slot(node) = next_slot(node) + 1
      end do
    end do
  end subroutine node_block_lists

  !> Every block of every group in one list, with its lanes' elements, its nodes and its cost.
  subroutine list_blocks(groups, blocks)
    type(group_holder_t), intent(in) :: groups(:)
    type(block_list_t), intent(out) :: blocks
    integer, allocatable :: elements(:), nodes(:), lane_element(:), node_list(:)
    integer :: block_total, g, b, k, lane_count, node_count

    block_total = 0
    do g = 1, size(groups)
      block_total = block_total + groups(g)%group%block_count()
    end do
    allocate (blocks%block_group(block_total), blocks%block_local(block_total), blocks%lane_offsets(block_total + 1), &
              blocks%node_offsets(block_total + 1), blocks%block_cost(block_total))
    allocate (lane_element(1024), node_list(4096))
    lane_count = 0
    node_count = 0
    k = 0
    do g = 1, size(groups)
      do b = 1, groups(g)%group%block_count()
        k = k + 1
        blocks%block_group(k) = g
        blocks%block_local(k) = b
        call groups(g)%group%block_elements(b, elements)
        call groups(g)%group%block_nodes(b, nodes)
        call append(lane_element, lane_count, elements)
        call append(node_list, node_count, nodes)
        blocks%lane_offsets(k + 1) = lane_count + 1
        blocks%node_offsets(k + 1) = node_count + 1
        blocks%block_cost(k) = size(elements)*lane_cost(groups(g)%group%name)
      end do
    end do
    blocks%lane_offsets(1) = 1
    blocks%node_offsets(1) = 1
    blocks%lane_element = lane_element(1:lane_count)
    blocks%node_list = node_list(1:node_count)
  contains
    subroutine append(list, count, items)
      integer, allocatable, intent(inout) :: list(:)
      integer, intent(inout) :: count
      integer, intent(in) :: items(:)
      integer, allocatable :: grown(:)
      if (count + size(items) > size(list)) then
        allocate (grown(max(2*size(list), count + size(items))))
        grown(1:count) = list(1:count)
        call move_alloc(grown, list)
      end if
      list(count + 1:count + size(items)) = items
      count = count + size(items)
    end subroutine append
  end subroutine list_blocks

  !> The rank (0-based) of each lane of `blocks` (lane_element's order): METIS k-way on the
  !> element graph weighted by cost, or, when METIS cannot (no edges, refused), a contiguous
  !> split of the elements in block order by cost. The lanes of one element share its rank.
  subroutine rank_elements(model, groups, blocks, rank_count, lane_rank, by_metis)
    type(model_t), intent(in) :: model
    type(group_holder_t), intent(in) :: groups(:)
    type(block_list_t), intent(in) :: blocks
    integer, intent(in) :: rank_count
    integer, allocatable, intent(out) :: lane_rank(:)
    logical, intent(out) :: by_metis
    integer, allocatable :: vertex_of(:, :), lane_vertex(:), vertex_family(:), vertex_element(:), vertex_rank(:)
    integer(idx_t), allocatable :: vertex_weight(:)
    real(wp), allocatable :: weight(:)
    integer :: k, lane, family, element, vertex_count, largest

    ! the elements in blocks are the vertices, numbered in order of first appearance
    largest = max(size(model%solid_ids), size(model%shell_ids), size(model%beam_ids), 1)
    allocate (vertex_of(largest, 3), lane_vertex(size(blocks%lane_element)), &
              vertex_family(size(blocks%lane_element)), vertex_element(size(blocks%lane_element)), &
              weight(size(blocks%lane_element)))
    vertex_of = 0
    vertex_count = 0
    weight = 0.0_wp
    do k = 1, size(blocks%block_group)
      family = groups(blocks%block_group(k))%group%element_family
      do lane = blocks%lane_offsets(k), blocks%lane_offsets(k + 1) - 1
        element = blocks%lane_element(lane)
        if (vertex_of(element, family) == 0) then
          vertex_count = vertex_count + 1
          vertex_of(element, family) = vertex_count
          vertex_family(vertex_count) = family
          vertex_element(vertex_count) = element
        end if
        lane_vertex(lane) = vertex_of(element, family)
        weight(lane_vertex(lane)) = weight(lane_vertex(lane)) + lane_cost(groups(blocks%block_group(k))%group%name)
      end do
    end do
    ! integer weights for METIS: tenths of a nanosecond keep the ratios (at least 1)
    allocate (vertex_weight(vertex_count))
    vertex_weight = int(max(1.0_wp, 10.0_wp*weight(1:vertex_count)), idx_t)

    call metis_ranks(model, vertex_family(1:vertex_count), vertex_element(1:vertex_count), vertex_weight, &
                     rank_count, vertex_rank, by_metis)
    if (.not. by_metis) call contiguous_ranks(weight(1:vertex_count), rank_count, vertex_rank)
    lane_rank = vertex_rank(lane_vertex)
  end subroutine rank_elements

  !> METIS k-way on the graph of elements sharing a node; `by_metis` false (and `vertex_rank`
  !> unset) when the graph has no edge or METIS refuses.
  subroutine metis_ranks(model, vertex_family, vertex_element, vertex_weight, rank_count, vertex_rank, by_metis)
    type(model_t), intent(in) :: model
    integer, intent(in) :: vertex_family(:), vertex_element(:)
    integer(idx_t), intent(in) :: vertex_weight(:)
    integer, intent(in) :: rank_count
    integer, allocatable, intent(out) :: vertex_rank(:)
    logical, intent(out) :: by_metis
    integer(idx_t), allocatable, target :: element_offsets(:), element_nodes(:)
    integer(idx_t), allocatable :: options(:), piece(:)
    integer(idx_t) :: vertex_count, node_count, edge_cut
    integer(idx_t), pointer :: offsets(:)
    type(c_ptr) :: metis_offsets, metis_neighbours
    type(signal_mask_t) :: signal_mask
    integer(c_int) :: status, free_status
    integer :: v, corner, slot, node, corners, k

    by_metis = .false.
    vertex_count = int(size(vertex_family), idx_t)
    node_count = int(size(model%node_ids), idx_t)
    ! the elements as a METIS mesh: each element's distinct nodes, numbered from 0
    allocate (element_offsets(vertex_count + 1), element_nodes(8*vertex_count))
    element_offsets(1) = 0
    slot = 0
    do v = 1, int(vertex_count)
      corners = merge(8, merge(4, 2, vertex_family(v) == family_shell), vertex_family(v) == family_solid)
      do corner = 1, corners
        node = element_node(v, corner)
        if (any([(element_node(v, k) == node, k=1, corner - 1)])) cycle
        slot = slot + 1
        element_nodes(slot) = int(node - 1, idx_t)
      end do
      element_offsets(v + 1) = int(slot, idx_t)
    end do

    allocate (options(metis_option_count), piece(vertex_count))
    ! METIS would catch a SIGTERM and carry on (signal_hold)
    call hold_termination_signal(signal_mask)
    status = metis_mesh_to_dual(vertex_count, node_count, element_offsets, element_nodes, 1_idx_t, 0_idx_t, &
                                metis_offsets, metis_neighbours)
    if (status == metis_ok) then
      call c_f_pointer(metis_offsets, offsets, [vertex_count + 1])
      if (offsets(vertex_count + 1) > 0) then
        status = metis_set_default_options(options)
        options(metis_option_seed + 1) = metis_seed
        options(metis_option_numbering + 1) = 0
        status = metis_part_graph_kway(vertex_count, 1_idx_t, metis_offsets, metis_neighbours, vertex_weight, &
                                       c_null_ptr, c_null_ptr, int(rank_count, idx_t), c_null_ptr, c_null_ptr, &
                                       options, edge_cut, piece)
        by_metis = status == metis_ok
      end if
      if (c_associated(metis_offsets)) free_status = metis_free(metis_offsets)
      if (c_associated(metis_neighbours)) free_status = metis_free(metis_neighbours)
    end if
    call release_held_signals(signal_mask)
    if (by_metis) vertex_rank = int(piece)
  contains
    integer function element_node(vertex, corner)
      integer, intent(in) :: vertex, corner
      select case (vertex_family(vertex))
      case (family_solid)
        element_node = model%solid_nodes(corner, vertex_element(vertex))
      case (family_shell)
        element_node = model%shell_nodes(corner, vertex_element(vertex))
      case default
        element_node = model%beam_nodes(corner, vertex_element(vertex))
      end select
    end function element_node
  end subroutine metis_ranks

  !> Ranks in order: rank r takes the elements whose cumulative cost (before them) lies in
  !> [r, r+1) times the mean share.
  pure subroutine contiguous_ranks(weight, rank_count, vertex_rank)
    real(wp), intent(in) :: weight(:)
    integer, intent(in) :: rank_count
    integer, allocatable, intent(out) :: vertex_rank(:)
    real(wp) :: total, before
    integer :: v
    allocate (vertex_rank(size(weight)))
    total = sum(weight)
    before = 0.0_wp
    do v = 1, size(weight)
      vertex_rank(v) = min(rank_count - 1, int(before/total*rank_count))
      before = before + weight(v)
    end do
  end subroutine contiguous_ranks

  !> Each block to the rank owning most of its lanes (ties: the lowest rank).
  subroutine owners_by_majority(blocks, lane_rank, rank_count, block_owner)
    type(block_list_t), intent(in) :: blocks
    integer, intent(in) :: lane_rank(:), rank_count
    integer, intent(inout) :: block_owner(:)
    integer, allocatable :: votes(:)
    integer :: k, lane
    allocate (votes(0:rank_count - 1))
    do k = 1, size(blocks%block_group)
      votes = 0
      do lane = blocks%lane_offsets(k), blocks%lane_offsets(k + 1) - 1
        votes(lane_rank(lane)) = votes(lane_rank(lane)) + 1
      end do
      ! maxloc returns the first of equal maxima: the lowest rank
      block_owner(k) = maxloc(votes, dim=1) - 1
    end do
  end subroutine owners_by_majority

  !> Blocks are coarse (64 lanes; a meshfree block costs as much as 200 hexahedra), and where a
  !> part's blocks are strips of a structured mesh (element_ordering keeps them when they are
  !> better for the colouring) METIS's regions cross many blocks and the majority rule can leave
  !> a rank far from its share. Diffusion by single moves evens it out: in sweeps over the
  !> blocks in order, a block goes from its owner to the cheapest rank (the lowest on a tie)
  !> owning a block that shares a node with it (so domains stay compact) when the owner's cost
  !> exceeds that rank's by more than the block's: each move lowers the sum of squared rank
  !> costs, so the sweeps end; at the end every two neighbouring ranks differ by at most one
  !> block's cost. A rank METIS left without blocks neighbours none, so it also counts as a
  !> neighbour of every block while it has none (with 4 blocks on 3 ranks METIS gave two ranks
  !> two blocks each and the first rank none). Serial and in a fixed order: the same on every
  !> rank.
  subroutine balance_owners(blocks, node_offsets, node_blocks, rank_count, block_owner)
    type(block_list_t), intent(in) :: blocks
    integer, intent(in) :: node_offsets(:), node_blocks(:), rank_count
    integer, intent(inout) :: block_owner(:)
    integer, allocatable :: seen_by(:), owned_blocks(:)
    real(wp), allocatable :: cost(:)
    integer :: k, slot, node, other, target, source, best_target, sweep, empty_ranks
    logical :: moved

    allocate (cost(0:rank_count - 1), seen_by(0:rank_count - 1), owned_blocks(0:rank_count - 1))
    cost = 0.0_wp
    owned_blocks = 0
    do k = 1, size(blocks%block_group)
      cost(block_owner(k)) = cost(block_owner(k)) + blocks%block_cost(k)
      owned_blocks(block_owner(k)) = owned_blocks(block_owner(k)) + 1
    end do
    empty_ranks = count(owned_blocks == 0)
    seen_by = 0
    ! (a bound on the sweeps for safety; they end long before on any mesh tried)
    do sweep = 1, 1000
      moved = .false.
      do k = 1, size(blocks%block_group)
        source = block_owner(k)
        best_target = -1
        do slot = blocks%node_offsets(k), blocks%node_offsets(k + 1) - 1
          node = blocks%node_list(slot)
          do other = node_offsets(node), node_offsets(node + 1) - 1
            target = block_owner(node_blocks(other))
            if (target == source .or. seen_by(target) == k) cycle
            seen_by(target) = k
            if (best_target < 0) then
              best_target = target
            else if (cost(target) < cost(best_target) .or. &
                     (cost(target) == cost(best_target) .and. target < best_target)) then
              best_target = target
            end if
          end do
        end do
        ! seen_by holds block numbers: clear it for the next sweep's same block
        do slot = blocks%node_offsets(k), blocks%node_offsets(k + 1) - 1
          node = blocks%node_list(slot)
          do other = node_offsets(node), node_offsets(node + 1) - 1
            seen_by(block_owner(node_blocks(other))) = 0
          end do
        end do
        ! (the first rank without blocks, if any: no cost, so it beats every neighbour)
        if (empty_ranks > 0) best_target = findloc(owned_blocks, 0, dim=1) - 1
        if (best_target < 0) cycle
        if (cost(source) - cost(best_target) <= blocks%block_cost(k)) cycle
        cost(source) = cost(source) - blocks%block_cost(k)
        cost(best_target) = cost(best_target) + blocks%block_cost(k)
        if (owned_blocks(best_target) == 0) empty_ranks = empty_ranks - 1
        owned_blocks(source) = owned_blocks(source) - 1
        owned_blocks(best_target) = owned_blocks(best_target) + 1
        block_owner(k) = best_target
        moved = .true.
      end do
      if (.not. moved) exit
    end do
  end subroutine balance_owners

  !> Each node to one of the ranks owning a block touching it (rank 0 when none). A node touched
  !> by one rank's blocks goes to that rank. An interface node (touched by several ranks) makes
  !> its owner compute every block on it (ghost blocks): giving each to the lowest touching rank
  !> leaves the low ranks with most ghost blocks (computed imbalance 3.0 at 1,024 ranks on the
  !> scaling deck, 1.35 with this rule). So the interface nodes are dealt out greedily, in node
  !> order: each to the touching rank whose computed cost (owned blocks plus the ghost blocks
  !> taken so far, each counted once per rank) would be smallest after taking it, the lowest rank
  !> on a tie. A rank that already computes the node's blocks gains nothing, so the nodes along
  !> one interface mostly follow one another and a block is rarely computed by more ranks than
  !> needed. Serial and in a fixed order: the same on every rank. Any touching rank is correct
  !> (its owner computes every block on it); only the cost depends on the choice.
  subroutine own_nodes(node_count, blocks, block_owner, rank_count, node_owner)
    integer, intent(in) :: node_count
    type(block_list_t), intent(in) :: blocks
    integer, intent(in) :: block_owner(:), rank_count
    integer, allocatable, intent(out) :: node_owner(:)
    integer, allocatable :: node_offsets(:), node_blocks(:), rank_offsets(:), block_ranks(:), seen_by(:), counted_at(:)
    logical, allocatable :: computes(:)
    real(wp), allocatable :: cost(:)
    real(wp) :: added, best_cost
    integer :: k, slot, node, other, r, best, block_total, pass, total

    block_total = size(blocks%block_group)
    call node_block_lists(blocks, node_count, node_offsets, node_blocks)
    allocate (node_owner(node_count), cost(0:rank_count - 1), seen_by(0:rank_count - 1), counted_at(block_total))
    cost = 0.0_wp
    do k = 1, block_total
      cost(block_owner(k)) = cost(block_owner(k)) + blocks%block_cost(k)
    end do

    ! per block, the other ranks owning a block that shares a node with it (the ranks that may
    ! compute it as a ghost block) and whether each does: block_ranks(rank_offsets(k) :
    ! rank_offsets(k+1)-1); the first pass counts, the second fills
    allocate (rank_offsets(block_total + 1), block_ranks(0))
    do pass = 1, 2
      seen_by = 0
      total = 0
      rank_offsets(1) = 1
      do k = 1, block_total
        seen_by(block_owner(k)) = k
        do slot = blocks%node_offsets(k), blocks%node_offsets(k + 1) - 1
          node = blocks%node_list(slot)
          do other = node_offsets(node), node_offsets(node + 1) - 1
            r = block_owner(node_blocks(other))
            if (seen_by(r) == k) cycle
            seen_by(r) = k
            total = total + 1
            if (pass == 2) block_ranks(total) = r
          end do
        end do
        rank_offsets(k + 1) = total + 1
      end do
      if (pass == 1) deallocate (block_ranks)
      if (pass == 1) allocate (block_ranks(total))
    end do
    allocate (computes(total))
    computes = .false.

    seen_by = 0
    counted_at = 0
    do node = 1, node_count
      node_owner(node) = 0
      if (node_offsets(node + 1) == node_offsets(node)) cycle
      best = block_owner(node_blocks(node_offsets(node)))
      if (all(block_owner(node_blocks(node_offsets(node):node_offsets(node + 1) - 1)) == best)) then
        node_owner(node) = best
        cycle
      end if
      best = -1
      best_cost = 0.0_wp
      do slot = node_offsets(node), node_offsets(node + 1) - 1
        r = block_owner(node_blocks(slot))
        if (seen_by(r) == node) cycle
        seen_by(r) = node
        added = 0.0_wp
        do other = node_offsets(node), node_offsets(node + 1) - 1
          k = node_blocks(other)
          if (block_owner(k) == r .or. counted_at(k) == node) cycle
          ! (counted_at: a block listed twice at a node counts once)
          counted_at(k) = node
          if (.not. computes(rank_slot(k, r))) added = added + blocks%block_cost(k)
        end do
        do other = node_offsets(node), node_offsets(node + 1) - 1
          counted_at(node_blocks(other)) = 0
        end do
        if (best < 0 .or. cost(r) + added < best_cost .or. (cost(r) + added == best_cost .and. r < best)) then
          best = r
          best_cost = cost(r) + added
        end if
      end do
      node_owner(node) = best
      do other = node_offsets(node), node_offsets(node + 1) - 1
        k = node_blocks(other)
        if (block_owner(k) == best) cycle
        if (computes(rank_slot(k, best))) cycle
        computes(rank_slot(k, best)) = .true.
        cost(best) = cost(best) + blocks%block_cost(k)
      end do
    end do
  contains
    !> The slot of rank `rank` in block `block`'s list (it is there: the rank owns a block
    !> sharing a node with it).
    pure integer function rank_slot(block, rank)
      integer, intent(in) :: block, rank
      integer :: slot
      rank_slot = rank_offsets(block)
      do slot = rank_offsets(block), rank_offsets(block + 1) - 1
        if (block_ranks(slot) == rank) then
          rank_slot = slot
          return
        end if
      end do
    end function rank_slot
  end subroutine own_nodes

  !> The figures of every rank and the rank of every element (partition_summary_t).
  subroutine report_partition(model, groups, blocks, block_owner, node_owner, rank_count, report)
    type(model_t), intent(in) :: model
    type(group_holder_t), intent(in) :: groups(:)
    type(block_list_t), intent(in) :: blocks
    integer, intent(in) :: block_owner(:), node_owner(:), rank_count
    type(partition_summary_t), intent(inout) :: report
    integer, allocatable :: seen_by(:), touched_by(:), rank_touches(:)
    integer :: k, g, r, lane, slot, node, element, family

    report%rank_count = rank_count
    allocate (report%kind_names(size(groups)), report%rank_elements(size(groups), rank_count), &
              report%rank_blocks(rank_count), report%rank_ghost_blocks(rank_count), report%rank_owned_nodes(rank_count), &
              report%rank_interface_nodes(rank_count), report%rank_cost(rank_count), report%rank_computed_cost(rank_count), &
              report%rank_computed_blocks(size(groups), rank_count), report%kind_blocks(size(groups)))
    allocate (report%solid_rank(size(model%solid_ids)), report%shell_rank(size(model%shell_ids)), &
              report%beam_rank(size(model%beam_ids)))
    report%solid_rank = -1
    report%shell_rank = -1
    report%beam_rank = -1
    report%rank_elements = 0
    report%rank_blocks = 0
    report%rank_ghost_blocks = 0
    report%rank_computed_blocks = 0
    report%kind_blocks = 0
    report%rank_cost = 0.0_wp
    report%rank_computed_cost = 0.0_wp
    do g = 1, size(groups)
      report%kind_names(g) = groups(g)%group%name
    end do

    ! elements: the rank of the block holding their first lane
    do k = 1, size(blocks%block_group)
      g = blocks%block_group(k)
      family = groups(g)%group%element_family
      r = block_owner(k) + 1
      report%rank_blocks(r) = report%rank_blocks(r) + 1
      report%kind_blocks(g) = report%kind_blocks(g) + 1
      if (groups(g)%group%distributes_blocks()) then
        report%rank_computed_blocks(g, r) = report%rank_computed_blocks(g, r) + 1
      else
        report%rank_computed_blocks(g, :) = report%rank_computed_blocks(g, :) + 1
      end if
      report%rank_cost(r) = report%rank_cost(r) + blocks%block_cost(k)
      report%rank_computed_cost(r) = report%rank_computed_cost(r) + blocks%block_cost(k)
      do lane = blocks%lane_offsets(k), blocks%lane_offsets(k + 1) - 1
        element = blocks%lane_element(lane)
        select case (family)
        case (family_solid)
          if (report%solid_rank(element) >= 0) cycle
          report%solid_rank(element) = r - 1
        case (family_shell)
          if (report%shell_rank(element) >= 0) cycle
          report%shell_rank(element) = r - 1
        case default
          if (report%beam_rank(element) >= 0) cycle
          report%beam_rank(element) = r - 1
        end select
        report%rank_elements(g, r) = report%rank_elements(g, r) + 1
      end do
    end do

    ! ghost blocks: another rank owns one of its nodes (each such rank counted once per block)
    allocate (seen_by(rank_count))
    seen_by = 0
    do k = 1, size(blocks%block_group)
      do slot = blocks%node_offsets(k), blocks%node_offsets(k + 1) - 1
        r = node_owner(blocks%node_list(slot)) + 1
        if (r == block_owner(k) + 1 .or. seen_by(r) == k) cycle
        seen_by(r) = k
        report%rank_ghost_blocks(r) = report%rank_ghost_blocks(r) + 1
        if (groups(blocks%block_group(k))%group%distributes_blocks()) &
          report%rank_computed_blocks(blocks%block_group(k), r) = report%rank_computed_blocks(blocks%block_group(k), r) + 1
        report%rank_computed_cost(r) = report%rank_computed_cost(r) + blocks%block_cost(k)
      end do
    end do

    report%rank_owned_nodes = 0
    do node = 1, size(node_owner)
      report%rank_owned_nodes(node_owner(node) + 1) = report%rank_owned_nodes(node_owner(node) + 1) + 1
    end do

    ! interface nodes: touched by the blocks of two or more ranks; first count the ranks at each
    ! node (touched_by: the last rank that counted it, ranks taken one after another)
    allocate (touched_by(size(node_owner)), rank_touches(size(node_owner)))
    touched_by = -1
    rank_touches = 0
    do r = 0, rank_count - 1
      do k = 1, size(blocks%block_group)
        if (block_owner(k) /= r) cycle
        do slot = blocks%node_offsets(k), blocks%node_offsets(k + 1) - 1
          node = blocks%node_list(slot)
          if (touched_by(node) == r) cycle
          touched_by(node) = r
          rank_touches(node) = rank_touches(node) + 1
        end do
      end do
    end do
    report%rank_interface_nodes = 0
    touched_by = -1
    do r = 0, rank_count - 1
      do k = 1, size(blocks%block_group)
        if (block_owner(k) /= r) cycle
        do slot = blocks%node_offsets(k), blocks%node_offsets(k + 1) - 1
          node = blocks%node_list(slot)
          if (touched_by(node) == r) cycle
          touched_by(node) = r
          if (rank_touches(node) > 1) report%rank_interface_nodes(r + 1) = report%rank_interface_nodes(r + 1) + 1
        end do
      end do
    end do

    report%node_rank = node_owner
    report%imbalance = balance(report%rank_cost)
    report%computed_imbalance = balance(report%rank_computed_cost)
  contains
    pure real(wp) function balance(cost)
      real(wp), intent(in) :: cost(:)
      balance = 1.0_wp
      if (sum(cost) > 0.0_wp) balance = maxval(cost)/(sum(cost)/size(cost))
    end function balance
  end subroutine report_partition

  !> The partition as printed at set-up and written to d3hsp: one line per rank, the imbalance.
  function partition_text(report) result(text)
    type(partition_summary_t), intent(in) :: report
    character(len=:), allocatable :: text
    character(len=*), parameter :: nl = new_line("a")
    character(len=:), allocatable :: line
    real(wp) :: total
    integer :: r, g

    if (report%rank_count <= 1 .or. .not. allocated(report%rank_blocks)) then
      text = "domain partition: one rank (everything computed here)"//nl
      return
    end if
    if (report%method == "metis_kway_elements") then
      line = "METIS k-way on the element graph, weighted by cost"
    else if (report%method == "metis_kway_blocks") then
      line = "METIS k-way on the graph of the element blocks, weighted by cost"
    else
      line = "contiguous split by cost (METIS could not partition the element graph)"
    end if
    text = "domain partition: "//integer_text(report%rank_count)//" ranks, "//line//nl
    line = "  rank"
    do g = 1, size(report%kind_names)
      line = line//pad(trim(report%kind_names(g)), 16)
    end do
    text = text//line//"   blocks    ghost   cost %  owned nodes  interface nodes"//nl// &
           "  (elements per kind; meshfree: background cells)"//nl
    total = max(sum(report%rank_cost), tiny(1.0_wp))
    do r = 1, report%rank_count
      line = pad(integer_text(r - 1), 6)
      do g = 1, size(report%kind_names)
        line = line//pad(integer_text(report%rank_elements(g, r)), 16)
      end do
      line = line//pad(integer_text(report%rank_blocks(r)), 9)//pad(integer_text(report%rank_ghost_blocks(r)), 9)// &
             pad(fixed_text(100.0_wp*report%rank_cost(r)/total, 1), 9)//pad(integer_text(report%rank_owned_nodes(r)), 13)// &
             pad(integer_text(report%rank_interface_nodes(r)), 17)
      text = text//line//nl
    end do
    text = text//"  imbalance (largest / mean estimated cost): "//fixed_text(report%imbalance, 3)// &
           " over the owned blocks, "//fixed_text(report%computed_imbalance, 3)//" with the ghost blocks"//nl
  contains
    pure function pad(item, width) result(padded)
      character(len=*), intent(in) :: item
      integer, intent(in) :: width
      character(len=:), allocatable :: padded
      padded = repeat(" ", max(1, width - len(item)))//item
    end function pad
  end function partition_text
end module domain_partition
