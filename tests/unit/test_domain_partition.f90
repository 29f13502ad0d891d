!> Unit tests of domain_partition's ownership rules on a small mixed model (8 x 4 x 4 hexahedra
!> of 1 mm: x < 6 finite elements, the rest a meshfree part sharing their nodes; shells under the
!> finite elements): 2 solid blocks, 4 meshfree blocks (256 points), 1 shell block.
!> - one rank: everything owned by rank 0 and computed there, no METIS;
!> - N = 2, 3, 4, seen from every rank: the same owners on every rank; each node belongs to one
!>   of the ranks owning a block touching it (rank 0 when none), to that rank when only one rank's
!>   blocks touch it; the busiest rank's computed cost (owned and ghost blocks, recounted here from
!>   the node owners and equal to the report's) is at most what giving every node to the lowest
!>   touching rank (the former rule) would make it; a rank computes
!>   exactly the blocks it owns and those touching a node it owns, so every block touching a
!>   node is computed on the node's owner (the meshfree blocks' nodes reach beyond their cells);
!>   every element is on one rank and the counts per rank add up;
!> - more ranks than blocks: an error naming both numbers;
!> - check_launch: a build without MPI that a launcher started as several processes
!>   (OMPI_COMM_WORLD_SIZE or PMI_SIZE above 1) is refused; one process, or an MPI build, is not;
!>   launched_rank_index reads which process this is (OMPI_COMM_WORLD_RANK, else PMI_RANK).
program test_domain_partition
  use kinds, only: wp
  use testing, only: test_suite_t, check, finish_suite
  use fixtures, only: make_scratch_directory
  use error_handling, only: error_t, error_list_t
  use text_format, only: integer_text
  use model, only: model_t
  use deck_reader, only: read_deck
  use run_state, only: run_state_t
  use explicit_setup, only: set_up_run_state
  use domain_partition, only: domain_partition_t, partition_domains, lane_cost
  use command_line, only: check_launch, launched_rank_index
  use rank_communication, only: start_ranks, finish_ranks
  use, intrinsic :: iso_c_binding, only: c_char, c_int, c_null_char
  implicit none

  interface
    function c_setenv(name, value, overwrite) bind(c, name="setenv") result(status)
      import :: c_char, c_int
      character(kind=c_char), intent(in) :: name(*), value(*)
      integer(c_int), value :: overwrite
      integer(c_int) :: status
    end function c_setenv

    function c_unsetenv(name) bind(c, name="unsetenv") result(status)
      import :: c_char, c_int
      character(kind=c_char), intent(in) :: name(*)
      integer(c_int) :: status
    end function c_unsetenv
  end interface

  type(test_suite_t) :: suite
  character(len=:), allocatable :: directory
  type(model_t) :: model
  type(run_state_t) :: run
  integer :: ranks

  ! (an MPI build's set-up asks MPI for the ranks: one rank here)
  call start_ranks()
  suite%name = "domain_partition"
  directory = make_scratch_directory("crashfree_test_domain_partition")
  if (set_up_mixed_model(model, run)) then
    call test_one_rank()
    do ranks = 2, 4
      call test_rules(ranks)
    end do
    call test_too_many_ranks()
  end if
  call test_no_rank_left_without_blocks()
  call test_launch()
  call finish_ranks()
  call finish_suite(suite)

contains

  subroutine test_one_rank()
    type(domain_partition_t) :: partition
    type(error_t), allocatable :: error
    integer :: g
    logical :: all_owned
    call partition_domains(model, run%state%groups, 1, 0, partition, error)
    call check(suite, "one rank: accepted", .not. allocated(error))
    if (allocated(error)) return
    all_owned = all(partition%node_owner == 0)
    do g = 1, size(partition%groups)
      all_owned = all_owned .and. all(partition%groups(g)%owner == 0) .and. all(partition%groups(g)%computed)
    end do
    call check(suite, "one rank: rank 0 owns and computes everything", all_owned)
    call check(suite, "one rank: no METIS call", .not. partition%report%by_metis)
    call check(suite, "one rank: 3 groups, 7 blocks", size(partition%groups) == 3 .and. block_total(partition) == 7)
  end subroutine test_one_rank

  subroutine test_rules(rank_count)
    integer, intent(in) :: rank_count
    type(domain_partition_t) :: first, partition
    type(error_t), allocatable :: error
    integer, allocatable :: nodes(:), elements(:), lowest(:), highest(:)
    real(wp), allocatable :: computed_cost(:), lowest_rule_cost(:)
    real(wp) :: block_cost
    logical :: same, lowest_rule, computed_rule, owner_computes, counted, touching, found
    character(len=:), allocatable :: label
    integer :: rank, g, b, node

    label = integer_text(rank_count)//" ranks: "
    call partition_domains(model, run%state%groups, rank_count, 0, first, error)
    call check(suite, label//"accepted", .not. allocated(error))
    if (allocated(error)) return
    call check(suite, label//"METIS", first%report%by_metis)

    ! node owner: one of the owners of the blocks touching it; the lowest and the highest of
    ! them bound it, and where they agree (one rank's blocks) it is that rank
    allocate (lowest(size(model%node_ids)), highest(size(model%node_ids)))
    lowest = huge(1)
    highest = -1
    touching = .true.
    do g = 1, size(first%groups)
      do b = 1, size(first%groups(g)%owner)
        call run%state%groups(g)%group%block_nodes(b, nodes)
        lowest(nodes) = min(lowest(nodes), first%groups(g)%owner(b))
        highest(nodes) = max(highest(nodes), first%groups(g)%owner(b))
      end do
    end do
    where (lowest == huge(1)) lowest = 0
    where (highest < 0) highest = 0
    ! the owner is a touching rank: some block on the node is owned by it
    do node = 1, size(model%node_ids)
      if (lowest(node) == highest(node)) cycle
      found = .false.
      do g = 1, size(first%groups)
        do b = 1, size(first%groups(g)%owner)
          if (first%groups(g)%owner(b) /= first%node_owner(node)) cycle
          call run%state%groups(g)%group%block_nodes(b, nodes)
          found = found .or. any(nodes == node)
        end do
      end do
      touching = touching .and. found
    end do
    call check(suite, label//"a node of one rank's blocks belongs to that rank (rank 0: no block)", &
               all(pack(first%node_owner, lowest == highest) == pack(lowest, lowest == highest)))
    call check(suite, label//"an interface node belongs to a rank owning a block on it", touching)

    ! computed cost per rank: owned blocks and blocks touching an owned node, with these owners
    ! and with every node to the lowest touching rank
    allocate (computed_cost(0:rank_count - 1), lowest_rule_cost(0:rank_count - 1))
    computed_cost = 0.0_wp
    lowest_rule_cost = 0.0_wp
    do g = 1, size(first%groups)
      do b = 1, size(first%groups(g)%owner)
        call run%state%groups(g)%group%block_nodes(b, nodes)
        call run%state%groups(g)%group%block_elements(b, elements)
        block_cost = size(elements)*lane_cost(run%state%groups(g)%group%name)
        do rank = 0, rank_count - 1
          if (first%groups(g)%owner(b) == rank .or. any(first%node_owner(nodes) == rank)) &
            computed_cost(rank) = computed_cost(rank) + block_cost
          if (first%groups(g)%owner(b) == rank .or. any(lowest(nodes) == rank)) &
            lowest_rule_cost(rank) = lowest_rule_cost(rank) + block_cost
        end do
      end do
    end do
    call check(suite, label//"computed cost per rank as reported", &
               all(abs(computed_cost - first%report%rank_computed_cost) <= 1.0e-9_wp*maxval(computed_cost)))
    call check(suite, label//"busiest rank no busier than with the lowest-rank rule (" // &
               integer_text(nint(maxval(computed_cost)))//" ns against "//integer_text(nint(maxval(lowest_rule_cost)))// &
               ")", maxval(computed_cost) <= maxval(lowest_rule_cost)*(1.0_wp + 1.0e-12_wp))

    same = .true.
    computed_rule = .true.
    owner_computes = .true.
    do rank = 0, rank_count - 1
      call partition_domains(model, run%state%groups, rank_count, rank, partition, error)
      if (allocated(error)) then
        same = .false.
        exit
      end if
      same = same .and. all(partition%node_owner == first%node_owner)
      do g = 1, size(first%groups)
        same = same .and. all(partition%groups(g)%owner == first%groups(g)%owner)
        do b = 1, size(first%groups(g)%owner)
          call run%state%groups(g)%group%block_nodes(b, nodes)
          computed_rule = computed_rule .and. (partition%groups(g)%computed(b) .eqv. &
                          (partition%groups(g)%owner(b) == rank .or. any(partition%node_owner(nodes) == rank)))
          ! every block on a node this rank owns is computed here
          if (any(partition%node_owner(nodes) == rank)) &
            owner_computes = owner_computes .and. partition%groups(g)%computed(b)
        end do
      end do
    end do
    call check(suite, label//"the same partition on every rank", same)
    call check(suite, label//"computed = owned or touching an owned node", computed_rule)
    call check(suite, label//"every block on a node is computed on the node's owner", owner_computes)

    lowest_rule = all(first%report%solid_rank >= 0 .and. first%report%solid_rank < rank_count) .and. &
                  all(first%report%shell_rank >= 0 .and. first%report%shell_rank < rank_count)
    call check(suite, label//"every element on one rank", lowest_rule)
    counted = sum(first%report%rank_elements) == size(model%solid_ids) + size(model%shell_ids) .and. &
              sum(first%report%rank_blocks) == 7 .and. sum(first%report%rank_owned_nodes) == size(model%node_ids)
    call check(suite, label//"elements, blocks and nodes per rank add up", counted)
  end subroutine test_rules

  subroutine test_too_many_ranks()
    type(domain_partition_t) :: partition
    type(error_t), allocatable :: error
    call partition_domains(model, run%state%groups, 8, 0, partition, error)
    call check(suite, "8 ranks for 7 blocks: refused", allocated(error))
    if (.not. allocated(error)) return
    call check(suite, "8 ranks for 7 blocks: the message names both", &
               index(error%message, "8 ranks") > 0 .and. index(error%message, "7 element blocks") > 0, error%message)
  end subroutine test_too_many_ranks

  !> An 8 x 8 x 4 block of hexahedra makes 4 blocks (2 of exposed elements, 2 inside); on 3
  !> ranks METIS gave two ranks two blocks each and the first none (an idle rank, imbalance 1.5
  !> whatever the moves between neighbours): every rank now owns a block.
  subroutine test_no_rank_left_without_blocks()
    type(model_t) :: block_model
    type(run_state_t) :: block_run
    type(domain_partition_t) :: partition
    type(error_list_t) :: warnings
    type(error_t), allocatable :: error
    integer, allocatable :: owned(:)
    integer :: unit, i, j, k, element, rank
    open (newunit=unit, file=directory//"/block.k", status="replace", action="write")
    write (unit, '(a)') "*KEYWORD", "*CONTROL_TERMINATION", "1.0", "*PART", "block", "1,1,1", "*SECTION_SOLID", "1,1", &
      "*MAT_ELASTIC", "1,7.85e-6,210.0,0.3", "*NODE"
    do k = 0, 4
      do j = 0, 8
        do i = 0, 8
          write (unit, '(i0,3(",",f0.1))') block_node(i, j, k), real(i, wp), real(j, wp), real(k, wp)
        end do
      end do
    end do
    write (unit, '(a)') "*ELEMENT_SOLID"
    element = 0
    do k = 0, 3
      do j = 0, 7
        do i = 0, 7
          element = element + 1
          write (unit, '(i0,",1",8(",",i0))') element, block_node(i, j, k), block_node(i + 1, j, k), &
            block_node(i + 1, j + 1, k), block_node(i, j + 1, k), block_node(i, j, k + 1), block_node(i + 1, j, k + 1), &
            block_node(i + 1, j + 1, k + 1), block_node(i, j + 1, k + 1)
        end do
      end do
    end do
    write (unit, '(a)') "*END"
    close (unit)
    call read_deck(directory//"/block.k", block_model, warnings, error, .false.)
    if (.not. allocated(error)) call set_up_run_state(block_model, block_run, error)
    if (.not. allocated(error)) call partition_domains(block_model, block_run%state%groups, 3, 0, partition, error)
    call check(suite, "8 x 8 x 4 hexahedra on 3 ranks: set up and partitioned", .not. allocated(error))
    if (allocated(error)) return
    call check(suite, "8 x 8 x 4 hexahedra: 4 blocks", size(partition%groups(1)%owner) == 4)
    allocate (owned(0:2))
    do rank = 0, 2
      owned(rank) = count(partition%groups(1)%owner == rank)
    end do
    call check(suite, "8 x 8 x 4 hexahedra on 3 ranks: every rank owns a block (2, 1, 1)", &
               all(owned >= 1) .and. sum(owned) == 4, integer_text(owned(0))//" "//integer_text(owned(1))//" "// &
               integer_text(owned(2)))
  end subroutine test_no_rank_left_without_blocks

  pure integer function block_node(i, j, k)
    integer, intent(in) :: i, j, k
    block_node = 1 + i + 9*j + 81*k
  end function block_node

  subroutine test_launch()
    type(error_t), allocatable :: error
    integer(c_int) :: status
    status = c_unsetenv("OMPI_COMM_WORLD_SIZE"//c_null_char)
    status = c_unsetenv("PMI_SIZE"//c_null_char)
    call check_launch(.false., error)
    call check(suite, "launch: started alone, no launcher variables: runs", .not. allocated(error))
    status = c_setenv("PMI_SIZE"//c_null_char, "1"//c_null_char, 1_c_int)
    call check_launch(.false., error)
    call check(suite, "launch: one process under a launcher: runs", .not. allocated(error))
    status = c_setenv("OMPI_COMM_WORLD_SIZE"//c_null_char, "3"//c_null_char, 1_c_int)
    call check_launch(.false., error)
    call check(suite, "launch: 3 processes of a build without MPI: refused", allocated(error))
    if (allocated(error)) call check(suite, "launch: the message names the count and what to do", &
                                     index(error%message, "3 processes") > 0 .and. index(error%message, "mpirun") > 0, &
                                     error%message)
    call check_launch(.true., error)
    call check(suite, "launch: 3 processes of an MPI build: runs", .not. allocated(error))
    status = c_unsetenv("OMPI_COMM_WORLD_SIZE"//c_null_char)
    status = c_setenv("PMI_SIZE"//c_null_char, "2"//c_null_char, 1_c_int)
    call check_launch(.false., error)
    call check(suite, "launch: PMI_SIZE 2 (MPICH, Slurm) without MPI: refused", allocated(error))
    status = c_unsetenv("PMI_SIZE"//c_null_char)
    ! which of the launched processes this is: the first alone prints the refusal
    status = c_unsetenv("OMPI_COMM_WORLD_RANK"//c_null_char)
    status = c_unsetenv("PMI_RANK"//c_null_char)
    call check(suite, "launch: started alone: process 0", launched_rank_index() == 0)
    status = c_setenv("PMI_RANK"//c_null_char, "2"//c_null_char, 1_c_int)
    call check(suite, "launch: PMI_RANK 2: process 2", launched_rank_index() == 2)
    status = c_setenv("OMPI_COMM_WORLD_RANK"//c_null_char, "1"//c_null_char, 1_c_int)
    call check(suite, "launch: OMPI_COMM_WORLD_RANK 1 (before PMI_RANK): process 1", launched_rank_index() == 1)
    status = c_unsetenv("OMPI_COMM_WORLD_RANK"//c_null_char)
    status = c_unsetenv("PMI_RANK"//c_null_char)
  end subroutine test_launch

  integer function block_total(partition)
    type(domain_partition_t), intent(in) :: partition
    integer :: g
    block_total = 0
    do g = 1, size(partition%groups)
      block_total = block_total + size(partition%groups(g)%owner)
    end do
  end function block_total

  !> The deck (module comment) read and set up.
  logical function set_up_mixed_model(model, run)
    type(model_t), intent(out) :: model
    type(run_state_t), intent(out) :: run
    type(error_list_t) :: warnings
    type(error_t), allocatable :: error
    character(len=*), parameter :: path_name = "mixed.k"
    integer :: unit, i, j, k, element, shell
    open (newunit=unit, file=directory//"/"//path_name, status="replace", action="write")
    write (unit, '(a)') "*KEYWORD", "*CONTROL_TERMINATION", "1.0", &
      "*PART", "meshfree", "1,1,1", "*PART", "finite elements", "2,2,1", "*PART", "shells", "3,3,1", &
      "*SECTION_SOLID_EFG", "1,41", "1.5,1.5,1.5,0,0,3,1,0.0", "*SECTION_SOLID", "2,1", &
      "*SECTION_SHELL", "3,2", "0.1,0.1,0.1,0.1", "*MAT_ELASTIC", "1,7.85e-6,210.0,0.3", "*NODE"
    do k = 0, 4
      do j = 0, 4
        do i = 0, 8
          write (unit, '(i0,3(",",f0.1))') node_id(i, j, k), real(i, wp), real(j, wp), real(k, wp)
        end do
      end do
    end do
    write (unit, '(a)') "*ELEMENT_SOLID"
    element = 0
    do k = 0, 3
      do j = 0, 3
        do i = 0, 7
          element = element + 1
          write (unit, '(i0,",",i0,8(",",i0))') element, merge(1, 2, i >= 6), node_id(i, j, k), node_id(i + 1, j, k), &
            node_id(i + 1, j + 1, k), node_id(i, j + 1, k), node_id(i, j, k + 1), node_id(i + 1, j, k + 1), &
            node_id(i + 1, j + 1, k + 1), node_id(i, j + 1, k + 1)
        end do
      end do
    end do
    write (unit, '(a)') "*ELEMENT_SHELL"
    shell = 1000
    do j = 0, 3
      do i = 0, 5
        shell = shell + 1
        write (unit, '(i0,",3",4(",",i0))') shell, node_id(i, j, 0), node_id(i + 1, j, 0), node_id(i + 1, j + 1, 0), &
          node_id(i, j + 1, 0)
      end do
    end do
    write (unit, '(a)') "*END"
    close (unit)
    call read_deck(directory//"/"//path_name, model, warnings, error, .false.)
    if (.not. allocated(error)) call set_up_run_state(model, run, error)
    set_up_mixed_model = .not. allocated(error)
    call check(suite, "the mixed model is read and set up", set_up_mixed_model)
    if (allocated(error)) write (*, '(a)') error%message
  end function set_up_mixed_model

  pure integer function node_id(i, j, k)
    integer, intent(in) :: i, j, k
    node_id = 1 + i + 9*j + 45*k
  end function node_id
end program test_domain_partition
