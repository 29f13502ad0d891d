!> Contact pairs shared out over ranks (penalty_contact: find_contact_pairs, share_out_pairs,
!> pack_pair_records, unpack_pair_records, apply_contact_pairs), with the ranks played in one
!> process: copies of the contact state, each computing its share, their pair records
!> concatenated in rank order as MPI_Allgatherv would, every copy unpacking them and adding the
!> forces. A block of 3 x 3 hexahedra is pushed into a block of 4 x 4, slid across it with
!> friction and lifted off at once; the bucket search is redone every other cycle (NSBCS 2) and
!> as the blocks move, so that the ranks' shares move and pairs change hands (also in the cycle
!> that ends them). Played again with a death time, a later birth time, an element eroding
!> under the slider, and restarts (rank 0's pair arrays, as run_state_dump writes them, read
!> back on 2 ranks or 1, before a birth and after a death too). At every cycle each copy must
!> hold exactly the one-rank pair arrays (segment, side, depth, initial depth, weights, force,
!> friction spring: what rank 0 dumps must not depend on N), contact forces, contact force sums
!> and energy, bit for bit, and the shares must cover the secondary nodes once.
program test_contact_sharing
  use kinds, only: wp
  use testing, only: test_suite_t, check, finish_suite
  use fixtures, only: make_scratch_directory, node_card, element_card, read_deck_lines
  use error_handling, only: error_t
  use model, only: model_t
  use contact_erosion, only: remove_eroded_elements
  use penalty_contact, only: contact_state_t, set_up_contacts, find_contact_pairs, apply_contact_pairs, &
                             pack_pair_records, unpack_pair_records, pair_record_size
  implicit none

  integer, parameter :: rank_count = 3, cycles = 60
  real(wp), parameter :: step = 0.02_wp
  type(test_suite_t) :: suite
  character(len=:), allocatable :: directory

  suite%name = "contact_sharing"
  directory = make_scratch_directory("crashfree_test_contact_sharing")
  ! (birth, death, erosion cycle, restart cycle, ranks after the restart, what)
  call test_ranks_hold_the_one_rank_pairs(0.0_wp, 0.0_wp, 0, 0, 3, "three ranks")
  call test_ranks_hold_the_one_rank_pairs(0.0_wp, 0.9_wp, 0, 0, 3, "death time 0.9 (in contact)")
  call test_ranks_hold_the_one_rank_pairs(0.3_wp, 0.0_wp, 0, 0, 3, "birth time 0.3 (already penetrating)")
  call test_ranks_hold_the_one_rank_pairs(0.0_wp, 0.0_wp, 35, 0, 3, "an element under the slider erodes at cycle 35")
  call test_ranks_hold_the_one_rank_pairs(0.0_wp, 0.0_wp, 0, 33, 2, "restart at cycle 33 from rank 0 onto 2 ranks")
  call test_ranks_hold_the_one_rank_pairs(0.0_wp, 0.0_wp, 0, 33, 1, "restart at cycle 33 from rank 0 onto 1 rank")
  call test_ranks_hold_the_one_rank_pairs(0.3_wp, 0.0_wp, 0, 12, 2, "birth 0.3, restart at cycle 12 (before birth) onto 2")
  call test_ranks_hold_the_one_rank_pairs(0.0_wp, 0.9_wp, 0, 47, 2, "death 0.9, restart at cycle 47 (after death) onto 2")
  call finish_suite(suite)

contains

  subroutine test_ranks_hold_the_one_rank_pairs(birth, death, erode_at, restart_at, restart_ranks, what)
    real(wp), intent(in) :: birth, death
    integer, intent(in) :: erode_at, restart_at, restart_ranks
    character(len=*), intent(in) :: what
    type(model_t) :: model
    type(contact_state_t), allocatable :: restarted(:)
    logical, allocatable :: solid_eroded(:), shell_eroded(:)
    integer :: active_ranks, q, p
    real(wp) :: time
    type(contact_state_t), allocatable :: alone(:), ranks(:, :)
    real(wp), allocatable :: x(:, :), v(:, :), mass(:), force(:, :), rank_force(:, :, :), buffer(:), rank_buffer(:)
    real(wp) :: work_before, energy, rank_energy(rank_count), rank_work_before(rank_count), moved(3), velocity(3)
    integer :: cycle, r, records, sent, at, node, upper_first, handled_total, pairs_seen
    integer :: changed_hands, previous_first(rank_count)
    logical :: same, covered, all_same, all_covered, ranks_busy(rank_count)
    type(error_t), allocatable :: error
    logical, allocatable :: is_particle(:)

    if (.not. read_model("blocks.k", blocks_deck(upper_first, birth, death), model)) return
    active_ranks = rank_count
    allocate (is_particle(size(model%node_ids)))
    is_particle = .false.
    call set_up_contacts(model, is_particle, alone, error)
    call check(suite, "the single surface contact is set up", .not. allocated(error))
    if (allocated(error)) return
    allocate (ranks(size(alone), rank_count))
    do r = 1, rank_count
      ranks(:, r) = alone
    end do
    x = model%coordinates
    allocate (v(3, size(x, 2)), mass(size(x, 2)), force(3, size(x, 2)), rank_force(3, size(x, 2), rank_count))
    v = 0.0_wp
    mass = [(1.0_wp + 0.01_wp*mod(node, 7), node=1, size(x, 2))]
    allocate (buffer(0))
    all_same = .true.
    all_covered = .true.
    ranks_busy = .false.
    pairs_seen = 0
    changed_hands = 0
    previous_first = 0
    do cycle = 1, cycles
      ! the upper block comes down 0.005 a cycle from 0.05 above, then slides along x, each of
      ! its nodes a little differently (no symmetry to hide a wrong pair)
      velocity = [merge(2.0_wp, 0.0_wp, cycle > 20), 0.1_wp, merge(-0.25_wp, 0.0_wp, cycle <= 30)]
      do node = upper_first, size(x, 2)
        moved = step*velocity*(1.0_wp + 0.01_wp*sin(real(node, wp)))
        x(:, node) = x(:, node) + moved
        v(:, node) = moved/step
        ! at cycle 50 it is lifted off at once: every pair goes in the same cycle as the searches
        ! hand the nodes to other ranks (a rank must not keep a pair it no longer computes)
        if (cycle == 50) x(3, node) = x(3, node) + 3.0_wp
      end do
      time = cycle*step
      if (cycle == erode_at) then
        allocate (solid_eroded(size(model%solid_part)), shell_eroded(size(model%shell_part)))
        solid_eroded = .false.
        shell_eroded = .false.
        solid_eroded(6) = .true.   ! lower block, under the slider
        call remove_eroded_elements(model, alone, solid_eroded, shell_eroded)
        do r = 1, active_ranks
          call remove_eroded_elements(model, ranks(:, r), solid_eroded, shell_eroded)
        end do
      end if
      if (cycle == restart_at) then
        ! what run_state_dump writes (rank 0's arrays), read back on restart_ranks fresh ranks:
        ! the sharing lists are not in a dump
        restarted = ranks(:, 1)
        do q = 1, size(restarted)
          do p = 1, restarted(q)%pass_count
            if (allocated(restarted(q)%passes(p)%handled)) deallocate (restarted(q)%passes(p)%handled)
            if (allocated(restarted(q)%passes(p)%is_handled)) deallocate (restarted(q)%passes(p)%is_handled)
            if (allocated(restarted(q)%passes(p)%received)) deallocate (restarted(q)%passes(p)%received)
            restarted(q)%passes(p)%received_count = 0
          end do
        end do
        active_ranks = restart_ranks
        do r = 1, active_ranks
          ranks(:, r) = restarted
        end do
      end if
      call find_contact_pairs(model, alone, time, step, x, v, mass, work_before)
      call apply_contact_pairs(alone, step, v, force, work_before, energy)
      ! the ranks: their shares, the records gathered in rank order, every rank unpacking all
      do r = 1, active_ranks
        call find_contact_pairs(model, ranks(:, r), time, step, x, v, mass, rank_work_before(r), r - 1, active_ranks)
      end do
      records = 0
      at = 0
      do r = 1, active_ranks
        call pack_pair_records(ranks(:, r), rank_buffer, sent)
        if (sent > 0) ranks_busy(r) = .true.
        buffer = [buffer(1:at), rank_buffer(1:pair_record_size*sent)]
        at = at + pair_record_size*sent
        records = records + sent
      end do
      do r = 1, active_ranks
        call unpack_pair_records(ranks(:, r), buffer, records)
        call apply_contact_pairs(ranks(:, r), step, v, rank_force(:, :, r), rank_work_before(r), rank_energy(r))
      end do
      pairs_seen = max(pairs_seen, count(alone(1)%passes(1)%pair_segment > 0))
      associate (alone_pass => alone(1)%passes(1))
        handled_total = 0
        covered = .true.
        do r = 1, active_ranks
          associate (pass => ranks(1, r)%passes(1))
            same = all(pass%pair_segment == alone_pass%pair_segment) .and. &
                   all(pass%pair_side == alone_pass%pair_side) .and. &
                   all(pass%pair_depth == alone_pass%pair_depth) .and. &
                   all(pass%initial_depth == alone_pass%initial_depth) .and. &
                   all(pass%pair_weights == alone_pass%pair_weights) .and. &
                   all(pass%pair_force == alone_pass%pair_force) .and. &
                   all(pass%tangential == alone_pass%tangential) .and. &
                   all(rank_force(:, :, r) == force) .and. rank_energy(r) == energy .and. &
                   all(ranks(1, r)%force == alone(1)%force) .and. all(ranks(1, r)%impulse == alone(1)%impulse)
            all_same = all_same .and. same
            if (.not. same) call check(suite, what//": rank "//achar(47 + r)//" differs from one rank at cycle "// &
                                       cycle_text(cycle), .false., difference_text(pass, alone_pass))
            ! (a contact not yet born has no shares)
            if (allocated(pass%handled)) then
              handled_total = handled_total + size(pass%handled)
              if (size(pass%handled) > 0) then
                if (previous_first(r) /= 0 .and. pass%handled(1) /= previous_first(r)) changed_hands = changed_hands + 1
                previous_first(r) = pass%handled(1)
              end if
            end if
          end associate
        end do
        covered = handled_total == alone_pass%node_count .or. handled_total == 0
        all_covered = all_covered .and. covered
      end associate
      if (.not. all_same) exit
    end do
    call check(suite, what//": the ranks hold the one-rank pairs, contact forces and energy at every cycle, bit for bit", &
               all_same)
    call check(suite, what//": the ranks' shares cover the secondary nodes once at every cycle", all_covered)
    call check(suite, what//": the blocks were in contact (more than 9 pairs at once)", pairs_seen > 9)
    ! the whole story, uninterrupted: the pairs went with the lift-off, every rank had pairs to
    ! send, and the shares moved
    if (birth == 0.0_wp .and. death == 0.0_wp .and. erode_at == 0 .and. restart_at == 0) then
      call check(suite, what//": apart at the end", all(alone(1)%passes(1)%pair_segment == 0))
      call check(suite, what//": every rank found pairs", all(ranks_busy))
      call check(suite, what//": the shares moved between ranks as the searches were redone", changed_hands > 0)
    end if
  end subroutine test_ranks_hold_the_one_rank_pairs

  !> Two blocks of unit hexahedra (part 1: 4 x 4 x 1 from z = 0; part 2: 3 x 3 x 1 from
  !> z = 1.05, over the middle), one single surface contact with friction, NSBCS 2;
  !> `upper_first`: the first node of the upper block.
  function blocks_deck(upper_first, birth, death) result(lines)
    integer, intent(out) :: upper_first
    real(wp), intent(in) :: birth, death
    character(len=80) :: card2
    character(len=80), allocatable :: lines(:)
    integer :: i, j, k, e, n
    write (card2, '(a,es12.4,",",es12.4)') "0.3,0.2,0,0,0,0,", birth, death
    lines = [character(len=80) :: "*KEYWORD", "*CONTROL_TERMINATION", "1.0", "*CONTROL_CONTACT", "0.1", &
             "0,0,2", "*PART", "lower", "1,1,1", "*PART", "upper", "2,1,1", "*SECTION_SOLID", "1,1", &
             "*MAT_ELASTIC", "1,1.0e-6,1.0,0.3", "*CONTACT_AUTOMATIC_SINGLE_SURFACE", "0,0,5", card2, "", &
             "*NODE"]
    do k = 0, 1
      do j = 0, 4
        do i = 0, 4
          lines = [character(len=80) :: lines, node_card(1 + i + 5*j + 25*k, real([i, j, k], wp))]
        end do
      end do
    end do
    upper_first = 51
    do k = 0, 1
      do j = 0, 3
        do i = 0, 3
          lines = [character(len=80) :: lines, node_card(upper_first + i + 4*j + 16*k, &
                                                         [0.5_wp + i, 0.5_wp + j, 1.05_wp + k])]
        end do
      end do
    end do
    lines = [character(len=80) :: lines, "*ELEMENT_SOLID"]
    e = 0
    do j = 0, 3
      do i = 0, 3
        e = e + 1
        n = 1 + i + 5*j
        lines = [character(len=80) :: lines, element_card(e, 1, [n, n + 1, n + 6, n + 5, n + 25, n + 26, n + 31, &
                                                                 n + 30])]
      end do
    end do
    do j = 0, 2
      do i = 0, 2
        e = e + 1
        n = upper_first + i + 4*j
        lines = [character(len=80) :: lines, element_card(e, 2, [n, n + 1, n + 5, n + 4, n + 16, n + 17, n + 21, &
                                                                 n + 20])]
      end do
    end do
    lines = [character(len=80) :: lines, "*END"]
  end function blocks_deck

  logical function read_model(name, lines, model)
    character(len=*), intent(in) :: name, lines(:)
    type(model_t), intent(out) :: model
    type(error_t), allocatable :: error
    call read_deck_lines(directory//"/"//name, lines, model, error)
    read_model = .not. allocated(error)
    if (allocated(error)) call check(suite, name//" is accepted", .false., error%message)
  end function read_model

  function difference_text(pass, alone_pass) result(text)
    use penalty_contact, only: contact_pass_t
    type(contact_pass_t), intent(in) :: pass, alone_pass
    character(len=:), allocatable :: text
    integer :: i
    text = "differing:"
    if (any(pass%pair_segment /= alone_pass%pair_segment)) text = text//" pair_segment"
    if (any(pass%pair_side /= alone_pass%pair_side)) text = text//" pair_side"
    if (any(pass%pair_depth /= alone_pass%pair_depth)) text = text//" pair_depth"
    if (any(pass%initial_depth /= alone_pass%initial_depth)) text = text//" initial_depth"
    if (any(pass%pair_weights /= alone_pass%pair_weights)) text = text//" pair_weights"
    if (any(pass%pair_force /= alone_pass%pair_force)) text = text//" pair_force"
    if (any(pass%tangential /= alone_pass%tangential)) text = text//" tangential"
    text = text//" (or the forces/energy); nodes:"
    do i = 1, pass%node_count
      if (pass%pair_side(i) /= alone_pass%pair_side(i) .or. any(pass%pair_weights(:, i) /= alone_pass%pair_weights(:, i))) &
        text = text//" "//cycle_text(i)
      if (len(text) > 300) exit
    end do
  end function difference_text

  function cycle_text(value) result(text)
    integer, intent(in) :: value
    character(len=:), allocatable :: text
    character(len=12) :: buffer
    write (buffer, '(i0)') value
    text = trim(buffer)
  end function cycle_text
end program test_contact_sharing
