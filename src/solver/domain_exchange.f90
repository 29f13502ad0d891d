!> The exchanges of a distributed run (stage 1 of docs/parallel.md): every rank holds the whole
!> model and run state; the ranks share out the element blocks of the kinds that distribute them
!> (FE solids, shells, beams, meshfree solids and shells), each computing its own blocks and
!> those on a node it owns. Each rank computes the accelerations of the nodes it owns, and the
!> ranks hand them to each other (exchange_accelerations); the rest of the cycle runs on every
!> rank alike.
!>
!> Why the results do not depend on the number of ranks: a node receives its element forces
!> group by group, within a group colour by colour (element_groups), an order the global blocks
!> fix. The rank that owns a node computes every block on it, so it adds the node's force in
!> exactly that order, and its acceleration from it; the exchange only copies that. The headers (stable step, failed element,
!> eroded elements) are made global with the one-rank tie rules, and the block state that the
!> output, the checks and the dumps read is brought together from the owners first
!> (gather_block_state), only when it is read.
!>
!> Contact is shared out by secondary node: each rank computes the pairs of its share of every
!> contact's secondary nodes (penalty_contact's share_out_pairs), and the ranks hand each other the pair records (exchange_contact_pairs) before every
!> rank adds the pairs' forces in the one-rank pair order (penalty_contact).
module domain_exchange
  use kinds, only: wp
  use error_handling, only: error_t
  use model, only: model_t
  use nodal_state, only: nodal_state_t
  use element_group, only: group_holder_t, block_energy_values
  use restart_file, only: restart_store_t, start_memory_store
  use wall_clock, only: phase_timer_t, start_phase, stop_phase
  use domain_partition, only: domain_partition_t, partition_domains
  use penalty_contact, only: contact_state_t, pair_record_size, pack_pair_records, unpack_pair_records
  use rank_communication, only: rank_index, rank_total, gather_reals, gather_reals_to_first, gather_fixed_reals, &
                                barrier_ranks, abort_ranks
  use text_format, only: integer_text
  implicit none
  private

  public :: domain_exchange_t, set_up_domains, exchange_accelerations, combine_group_headers, gather_block_state
  public :: share_block_energies, exchange_contact_pairs

  !> Values per group in the header exchange: step, critical block, critical element, failed
  !> block, failed element, step not finite, newly eroded (owned blocks).
  integer, parameter :: header_values = 7

  !> What the exchanges need, set up once (the nodal exchange allocates nothing per cycle).
  type :: domain_exchange_t
    integer :: rank = 0                         !< this rank, 0-based
    integer :: rank_count = 1                   !< ranks of the run (1: no exchange at all)
    !> every rank's owned nodes, ascending, rank after rank: rank r's are
    !> rank_nodes(node_offsets(r + 1):node_offsets(r + 2) - 1)
    integer, allocatable :: rank_nodes(:), node_offsets(:)
    !> where rank_nodes(k)'s values start in the receive buffer (0-based), and whether they hold
    !> the angular acceleration, normal sum and area sum after the acceleration (10 values; 3 at
    !> nodes that no group adding moments touches: adds_moments)
    integer, allocatable :: value_start(:)
    logical, allocatable :: with_moments(:)
    integer, allocatable :: value_counts(:), value_offsets(:)   !< per rank, for the nodal exchange
    real(wp), allocatable :: send(:), receive(:)
    real(wp), allocatable :: header_send(:), header_receive(:, :)
    integer :: first_gathered_cycle = -1        !< the cycle whose block state the first rank last gathered
    integer :: shared_cycle = -1                !< the cycle whose block state every rank last received
    integer :: energies_cycle = -1              !< the cycle whose block energies were last summed and shared
    integer :: block_gathers = 0                !< how often the first rank gathered the blocks' state
    integer :: block_shares = 0                 !< how often every rank received it (elements eroded)
    integer :: energy_shares = 0                !< how often the blocks' energy sums were shared
    type(restart_store_t) :: store              !< this rank's blocks, packed for a gather
    !> wall-clock time of the nodal (accelerations) and header exchanges; of the wait for the slowest rank before
    !> them (a barrier: what the ranks' unequal work costs, kept apart from the communication);
    !> of bringing the blocks together
    type(phase_timer_t) :: timer, wait_timer, gather_timer
    real(wp) :: gathered_values = 0.0_wp        !< values this rank received of block state and energies, in all
    !> the contact pair exchange: counts of records per rank, buffers (grown, never shrunk)
    real(wp), allocatable :: pair_send(:), pair_receive(:), record_counts(:, :)
    integer, allocatable :: pair_value_counts(:), pair_value_offsets(:)
    type(phase_timer_t) :: contact_timer        !< wall-clock time of the pair exchange
    type(phase_timer_t) :: contact_wait_timer   !< of the wait for the slowest rank before it
    real(wp) :: pair_values = 0.0_wp            !< values received by the pair exchanges, in all
    real(wp), allocatable :: rank_pair_records(:)   !< per rank, the pair records it sent, in all
  end type domain_exchange_t

contains

  !> Partition the model (domain_partition) among the ranks of the run and set up the exchanges.
  !> One rank: nothing is shared out and nothing will be exchanged.
  subroutine set_up_domains(model, groups, nodes, partition, exchange, error)
    type(model_t), intent(in) :: model
    type(group_holder_t), intent(inout) :: groups(:)
    type(nodal_state_t), intent(in) :: nodes
    type(domain_partition_t), intent(out) :: partition
    type(domain_exchange_t), intent(out) :: exchange
    type(error_t), allocatable, intent(out) :: error
    integer :: k, r, b, node, filled
    logical, allocatable :: moment_node(:)
    integer, allocatable :: block_nodes(:)
    exchange%rank = rank_index()
    exchange%rank_count = rank_total()
    ! (one rank: no partition, every block computed as always)
    if (exchange%rank_count == 1) return
    call partition_domains(model, groups, exchange%rank_count, exchange%rank, partition, error)
    if (allocated(error)) return
    do k = 1, size(groups)
      if (.not. groups(k)%group%distributes_blocks()) cycle
      groups(k)%group%computed = partition%groups(k)%computed
      groups(k)%group%owned = partition%groups(k)%owner == exchange%rank
    end do
    ! (every node has an owner; a node without one would get no acceleration from the others)
    allocate (exchange%node_offsets(exchange%rank_count + 1), &
              exchange%rank_nodes(count(partition%node_owner >= 0 .and. partition%node_owner < exchange%rank_count)))
    exchange%node_offsets(1) = 1
    do r = 0, exchange%rank_count - 1
      exchange%node_offsets(r + 2) = exchange%node_offsets(r + 1) + count(partition%node_owner == r)
    end do
    do r = 0, exchange%rank_count - 1
      filled = exchange%node_offsets(r + 1)
      do node = 1, nodes%count
        if (partition%node_owner(node) /= r) cycle
        exchange%rank_nodes(filled) = node
        filled = filled + 1
      end do
    end do
    ! 10 values at the nodes of blocks that add moments, 3 (the acceleration) elsewhere: on a
    ! model of solids with a shell plate most nodes need only their acceleration
    allocate (moment_node(nodes%count))
    moment_node = .false.
    if (nodes%rotational) then
      do k = 1, size(groups)
        if (.not. groups(k)%group%adds_moments()) cycle
        do b = 1, groups(k)%group%block_count()
          call groups(k)%group%block_nodes(b, block_nodes)
          moment_node(block_nodes) = .true.
        end do
      end do
    end if
    allocate (exchange%value_counts(exchange%rank_count), exchange%value_offsets(exchange%rank_count), &
              exchange%value_start(size(exchange%rank_nodes)), exchange%with_moments(size(exchange%rank_nodes)))
    filled = 0
    do r = 1, exchange%rank_count
      exchange%value_offsets(r) = filled
      do k = exchange%node_offsets(r), exchange%node_offsets(r + 1) - 1
        exchange%value_start(k) = filled
        exchange%with_moments(k) = moment_node(exchange%rank_nodes(k))
        filled = filled + merge(10, 3, exchange%with_moments(k))
      end do
      exchange%value_counts(r) = filled - exchange%value_offsets(r)
    end do
    allocate (exchange%send(max(1, exchange%value_counts(exchange%rank + 1))), exchange%receive(max(1, filled)))
    allocate (exchange%header_send(header_values*size(groups)), &
              exchange%header_receive(header_values*size(groups), exchange%rank_count))
    allocate (exchange%pair_send(pair_record_size), exchange%pair_receive(pair_record_size), &
              exchange%record_counts(1, exchange%rank_count), exchange%pair_value_counts(exchange%rank_count), &
              exchange%pair_value_offsets(exchange%rank_count), exchange%rank_pair_records(exchange%rank_count))
    exchange%rank_pair_records = 0.0_wp
  end subroutine set_up_domains

  !> After each rank computed the contact pairs of its share of the secondary nodes: every rank's
  !> pair records (a secondary node with a pair, a depth or an initial depth) to every rank
  !> (MPI_Allgatherv; the buffers grow with the number of pairs and are kept), so that every
  !> rank holds every pair, as one rank computes them.
  subroutine exchange_contact_pairs(contacts, exchange)
    type(contact_state_t), intent(inout) :: contacts(:)
    type(domain_exchange_t), intent(inout) :: exchange
    real(wp) :: records(1)
    integer :: r, total, sent
    if (exchange%rank_count == 1 .or. size(contacts) == 0) return
    ! (the wait for the rank with the most pairs apart from the exchange, as for the accelerations)
    call start_phase(exchange%contact_wait_timer)
    call barrier_ranks()
    call stop_phase(exchange%contact_wait_timer)
    call start_phase(exchange%contact_timer)
    call pack_pair_records(contacts, exchange%pair_send, sent)
    records(1) = real(sent, wp)
    call gather_fixed_reals(records, exchange%record_counts)
    exchange%pair_value_counts = pair_record_size*nint(exchange%record_counts(1, :))
    exchange%rank_pair_records = exchange%rank_pair_records + exchange%record_counts(1, :)
    exchange%pair_value_offsets(1) = 0
    do r = 2, exchange%rank_count
      exchange%pair_value_offsets(r) = exchange%pair_value_offsets(r - 1) + exchange%pair_value_counts(r - 1)
    end do
    total = sum(exchange%pair_value_counts)
    if (size(exchange%pair_receive) < total) then
      deallocate (exchange%pair_receive)
      allocate (exchange%pair_receive(2*total))
    end if
    call gather_reals(exchange%pair_send, exchange%pair_value_counts, exchange%pair_value_offsets, &
                      exchange%pair_receive)
    call unpack_pair_records(contacts, exchange%pair_receive, total/pair_record_size)
    exchange%pair_values = exchange%pair_values + real(total, wp)
    call stop_phase(exchange%contact_timer)
  end subroutine exchange_contact_pairs

  !> After the accelerations of the nodes each rank owns (where its internal forces are
  !> complete: it computes every block on them): every rank sends those accelerations (at the
  !> nodes of groups that add moments also the angular accelerations and the shells' normal and
  !> area sums, which the drilling constraint of the next cycle reads; zero elsewhere on every
  !> rank) and takes the others'. Every rank then holds the one-rank arrays, bit for bit. (The
  !> internal forces themselves stay partial at the nodes a rank does not own: nothing after the
  !> accelerations reads them.)
  subroutine exchange_accelerations(nodes, exchange)
    type(nodal_state_t), intent(inout) :: nodes
    type(domain_exchange_t), intent(inout) :: exchange
    integer :: k, node, first, at
    if (exchange%rank_count == 1) return
    call start_phase(exchange%wait_timer)
    call barrier_ranks()
    call stop_phase(exchange%wait_timer)
    call start_phase(exchange%timer)
    first = exchange%value_offsets(exchange%rank + 1)
    !$omp parallel do schedule(static) default(shared) private(k, node, at)
    do k = exchange%node_offsets(exchange%rank + 1), exchange%node_offsets(exchange%rank + 2) - 1
      node = exchange%rank_nodes(k)
      at = exchange%value_start(k) - first
      exchange%send(at + 1:at + 3) = nodes%acceleration(:, node)
      if (exchange%with_moments(k)) then
        exchange%send(at + 4:at + 6) = nodes%angular_acceleration(:, node)
        exchange%send(at + 7:at + 9) = nodes%shell_normal_sum(:, node)
        exchange%send(at + 10) = nodes%shell_area_sum(node)
      end if
    end do
    !$omp end parallel do
    call gather_reals(exchange%send, exchange%value_counts, exchange%value_offsets, exchange%receive)
    ! (the receive buffer holds the ranks' nodes in rank_nodes' order)
    !$omp parallel do schedule(static) default(shared) private(k, node, at)
    do k = 1, size(exchange%rank_nodes)
      node = exchange%rank_nodes(k)
      at = exchange%value_start(k)
      nodes%acceleration(:, node) = exchange%receive(at + 1:at + 3)
      if (exchange%with_moments(k)) then
        nodes%angular_acceleration(:, node) = exchange%receive(at + 4:at + 6)
        nodes%shell_normal_sum(:, node) = exchange%receive(at + 7:at + 9)
        nodes%shell_area_sum(node) = exchange%receive(at + 10)
      end if
    end do
    !$omp end parallel do
    call stop_phase(exchange%timer)
  end subroutine exchange_accelerations

  !> The headers of the distributed groups from all ranks, made global with the one-rank rules:
  !> the smallest step, on a tie the first block (the group's own order: the same element as one
  !> rank picks); the failed element of the first block with one; a step that is not a number
  !> anywhere; the eroded elements of all ranks (then the blocks are brought together, so that
  !> every rank lists and marks the same elements). Groups computed whole on every rank already
  !> hold the global header. `cycle` is the state's cycle (for share_block_state).
  subroutine combine_group_headers(groups, partition, exchange, cycle)
    type(group_holder_t), intent(inout) :: groups(:)
    type(domain_partition_t), intent(in) :: partition
    type(domain_exchange_t), intent(inout) :: exchange
    integer, intent(in) :: cycle
    integer :: k, r, at, newly_eroded
    real(wp) :: step, block
    logical :: eroded
    if (exchange%rank_count == 1) return
    call start_phase(exchange%timer)
    do k = 1, size(groups)
      at = header_values*(k - 1)
      associate (group => groups(k)%group)
        exchange%header_send(at + 1:at + header_values) = [group%stable_time_step, real(group%critical_block, wp), &
          real(group%critical_element, wp), real(group%failed_block, wp), real(group%failed_element, wp), &
          merge(1.0_wp, 0.0_wp, group%step_not_finite), real(group%newly_eroded, wp)]
      end associate
    end do
    call gather_fixed_reals(exchange%header_send, exchange%header_receive)
    call stop_phase(exchange%timer)
    eroded = .false.
    do k = 1, size(groups)
      associate (group => groups(k)%group, values => exchange%header_receive(header_values*(k - 1) + 1:, :))
        if (.not. group%distributes_blocks()) cycle
        group%stable_time_step = huge(1.0_wp)
        group%critical_block = 0
        group%critical_element = 0
        group%failed_block = 0
        group%failed_element = 0
        group%step_not_finite = .false.
        newly_eroded = 0
        do r = 1, exchange%rank_count
          step = values(1, r)
          block = values(2, r)
          if (step < group%stable_time_step .or. &
              (step == group%stable_time_step .and. step < huge(1.0_wp) .and. block < group%critical_block)) then
            group%stable_time_step = step
            group%critical_block = nint(block)
            group%critical_element = nint(values(3, r))
          end if
          if (values(4, r) > 0.0_wp .and. (group%failed_block == 0 .or. values(4, r) < group%failed_block)) then
            group%failed_block = nint(values(4, r))
            group%failed_element = nint(values(5, r))
          end if
          if (values(6, r) > 0.0_wp) group%step_not_finite = .true.
          newly_eroded = newly_eroded + nint(values(7, r))
        end do
        ! the group counted its own blocks' eroded elements into eroded_count
        group%eroded_count = group%eroded_count - group%newly_eroded + newly_eroded
        group%newly_eroded = newly_eroded
        if (newly_eroded > 0) eroded = .true.
      end associate
    end do
    if (eroded) call share_block_state(groups, partition, exchange, cycle)
  end subroutine combine_group_headers

  !> Bring every block's state to the first rank from its owner (each rank's others are old):
  !> before the first rank writes what reads block state (output states, dumps, the end of the
  !> run). Once per cycle at most; nothing with one rank.
  subroutine gather_block_state(groups, partition, exchange, cycle)
    type(group_holder_t), intent(inout) :: groups(:)
    type(domain_partition_t), intent(in) :: partition
    type(domain_exchange_t), intent(inout) :: exchange
    integer, intent(in) :: cycle
    if (exchange%rank_count == 1 .or. exchange%first_gathered_cycle == cycle) return
    call start_phase(exchange%gather_timer)
    call bring_blocks_together(groups, partition, exchange, .false.)
    exchange%first_gathered_cycle = cycle
    exchange%block_gathers = exchange%block_gathers + 1
    call stop_phase(exchange%gather_timer)
  end subroutine gather_block_state

  !> The same to every rank: in a cycle in which elements eroded, so that every rank lists and
  !> marks the same elements (the contacts drop their segments everywhere alike).
  subroutine share_block_state(groups, partition, exchange, cycle)
    type(group_holder_t), intent(inout) :: groups(:)
    type(domain_partition_t), intent(in) :: partition
    type(domain_exchange_t), intent(inout) :: exchange
    integer, intent(in) :: cycle
    if (exchange%rank_count == 1 .or. exchange%shared_cycle == cycle) return
    call start_phase(exchange%gather_timer)
    call bring_blocks_together(groups, partition, exchange, .true.)
    exchange%shared_cycle = cycle
    exchange%first_gathered_cycle = cycle
    exchange%block_shares = exchange%block_shares + 1
    call stop_phase(exchange%gather_timer)
  end subroutine share_block_state

  !> Before the energies are read (the energy checks, glstat, matsum, output states): every
  !> group sums the energies of the blocks this rank computes into its block_energy columns,
  !> and a distributed run hands each owner's columns to every rank (one MPI_Allgatherv of
  !> block_energy_values reals per block). The energies are then the one-rank sums of the same
  !> block sums, in the same order, on every rank. Once per cycle at most.
  subroutine share_block_energies(groups, partition, exchange, cycle)
    type(group_holder_t), intent(inout) :: groups(:)
    type(domain_partition_t), intent(in) :: partition
    type(domain_exchange_t), intent(inout) :: exchange
    integer, intent(in) :: cycle
    real(wp), allocatable :: send(:), received(:)
    integer, allocatable :: counts(:), offsets(:)
    integer :: k, b, r, at
    if (exchange%energies_cycle == cycle) return
    exchange%energies_cycle = cycle
    do k = 1, size(groups)
      call groups(k)%group%sum_block_energies()
    end do
    if (exchange%rank_count == 1) return
    call start_phase(exchange%gather_timer)
    allocate (counts(exchange%rank_count), offsets(exchange%rank_count))
    counts = 0
    do k = 1, size(groups)
      if (.not. groups(k)%group%distributes_blocks()) cycle
      do b = 1, size(partition%groups(k)%owner)
        r = partition%groups(k)%owner(b)
        counts(r + 1) = counts(r + 1) + block_energy_values
      end do
    end do
    offsets(1) = 0
    do r = 2, exchange%rank_count
      offsets(r) = offsets(r - 1) + counts(r - 1)
    end do
    allocate (send(max(1, counts(exchange%rank + 1))), received(max(1, sum(counts))))
    at = 0
    call copy_energy_columns(exchange%rank, .true.)
    call gather_reals(send, counts, offsets, received)
    do r = 0, exchange%rank_count - 1
      if (r == exchange%rank) cycle
      at = offsets(r + 1)
      call copy_energy_columns(r, .false.)
    end do
    exchange%energy_shares = exchange%energy_shares + 1
    exchange%gathered_values = exchange%gathered_values + real(sum(counts) - counts(exchange%rank + 1), wp)
    call stop_phase(exchange%gather_timer)
  contains
    !> The columns of rank `owner`'s blocks, group by group in block order: into `send`
    !> (packing) or out of `received` from `at` on.
    subroutine copy_energy_columns(owner, packing)
      integer, intent(in) :: owner
      logical, intent(in) :: packing
      integer :: group_index, block
      do group_index = 1, size(groups)
        if (.not. groups(group_index)%group%distributes_blocks()) cycle
        do block = 1, size(partition%groups(group_index)%owner)
          if (partition%groups(group_index)%owner(block) /= owner) cycle
          if (packing) then
            send(at + 1:at + block_energy_values) = groups(group_index)%group%block_energy(:, block)
          else
            groups(group_index)%group%block_energy(:, block) = received(at + 1:at + block_energy_values)
          end if
          at = at + block_energy_values
        end do
      end do
    end subroutine copy_energy_columns
  end subroutine share_block_energies

  !> The owners pack their blocks into a store in memory; the first rank (`everyone`: every
  !> rank) receives all stores (MPI_Gatherv; MPI_Allgatherv) and unpacks the blocks of the
  !> others, rank by rank.
  subroutine bring_blocks_together(groups, partition, exchange, everyone)
    type(group_holder_t), intent(inout) :: groups(:)
    type(domain_partition_t), intent(in) :: partition
    type(domain_exchange_t), intent(inout) :: exchange
    logical, intent(in) :: everyone
    type(restart_store_t) :: reader
    type(error_t), allocatable :: error
    real(wp) :: length(1)
    real(wp), allocatable :: lengths(:, :), received(:)
    integer, allocatable :: counts(:), offsets(:)
    integer :: k, b, r, room
    ! the owned blocks counted, then packed into a store of exactly that size (grown by
    ! doubling, a store of a large model's blocks held up to three times their size); the first
    ! rank's own blocks are where a gather to it needs them: it sends none
    call start_memory_store(exchange%store, .true., counting=.true.)
    if (everyone .or. exchange%rank /= 0) call pack_owned_blocks()
    room = exchange%store%position
    call start_memory_store(exchange%store, .true., room=room)
    if (everyone .or. exchange%rank /= 0) call pack_owned_blocks()
    length(1) = real(exchange%store%position, wp)
    allocate (lengths(1, exchange%rank_count), counts(exchange%rank_count), offsets(exchange%rank_count))
    call gather_fixed_reals(length, lengths)
    counts = nint(lengths(1, :))
    offsets(1) = 0
    do r = 2, exchange%rank_count
      offsets(r) = offsets(r - 1) + counts(r - 1)
    end do
    if (everyone) then
      allocate (received(max(1, sum(counts))))
      call gather_reals(exchange%store%memory(1:max(1, exchange%store%position)), counts, offsets, received)
    else
      ! (only the first rank receives: the others need no room)
      allocate (received(merge(max(1, sum(counts)), 1, exchange%rank == 0)))
      call gather_reals_to_first(exchange%store%memory(1:max(1, exchange%store%position)), counts, offsets, received)
      if (exchange%rank /= 0) return
    end if
    ! (read where each rank's values start in what was received: no copy)
    call move_alloc(received, reader%memory)
    call start_memory_store(reader, .false.)
    do r = 0, exchange%rank_count - 1
      if (r == exchange%rank) cycle
      reader%position = offsets(r + 1)
      do k = 1, size(groups)
        if (.not. groups(k)%group%distributes_blocks()) cycle
        do b = 1, size(partition%groups(k)%owner)
          if (partition%groups(k)%owner(b) /= r) cycle
          call groups(k)%group%exchange_block_state(reader, b, error)
        end do
      end do
      ! (ranks that disagree on the blocks' shapes run different builds or decks: no result can
      ! be trusted, and the others may wait for ever)
      if (reader%position - offsets(r + 1) /= counts(r + 1)) &
        call abort_ranks("block state from rank "//integer_text(r)//": "//integer_text(counts(r + 1))// &
                         " values received, "//integer_text(reader%position - offsets(r + 1))//" expected", 1)
    end do
    exchange%gathered_values = exchange%gathered_values + real(sum(counts) - counts(exchange%rank + 1), wp)
  contains
    subroutine pack_owned_blocks()
      integer :: group_index, block
      do group_index = 1, size(groups)
        if (.not. groups(group_index)%group%distributes_blocks()) cycle
        do block = 1, size(partition%groups(group_index)%owner)
          if (partition%groups(group_index)%owner(block) /= exchange%rank) cycle
          call groups(group_index)%group%exchange_block_state(exchange%store, block, error)
        end do
      end do
    end subroutine pack_owned_blocks
  end subroutine bring_blocks_together
end module domain_exchange
