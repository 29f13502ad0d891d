!> The one module that talks to MPI (mpi_f08): the ranks of a distributed run (docs/parallel.md).
!> Built with CRASHFREE_MPI (the Makefile defines it when Open MPI's mpifort is installed) it
!> calls MPI; without it, it is the one-rank version of the same interface, so that the rest of
!> the engine never asks whether MPI is there. A binary built with MPI and started without a
!> launcher (mpirun, srun) does not start MPI at all and runs as one rank: MPI's singleton start
!> would spawn a helper process and cost a fraction of a second for nothing. Every routine asks
!> MPI whether it was started (MPI_Initialized: allowed at any time) rather than keep a flag.
!>
!> Everything here is collective over all ranks unless said otherwise: every rank must make the
!> same calls in the same order. The exchanges only move values, they add nothing: the sums that
!> reach results happen on one rank in the one-rank order (the determinism argument of
!> docs/parallel.md), and the reductions offered are exact ones (logical or, max).
module rank_communication
  use kinds, only: wp
#ifdef CRASHFREE_MPI
  use mpi_f08, only: MPI_Init_thread, MPI_Initialized, MPI_Finalized, MPI_Finalize, MPI_Comm_rank, &
                     MPI_Comm_size, MPI_Barrier, MPI_Allgatherv, MPI_Gatherv, MPI_Allgather, MPI_Allreduce, MPI_Bcast, &
                     MPI_Abort, MPI_COMM_WORLD, MPI_THREAD_FUNNELED, MPI_DOUBLE_PRECISION, MPI_LOGICAL, MPI_INTEGER, &
                     MPI_MAX, MPI_LOR, MPI_IN_PLACE
#endif
  use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
  implicit none
  private

  public :: start_ranks, finish_ranks, rank_index, rank_total, mpi_built, barrier_ranks
  public :: gather_reals, gather_reals_to_first, gather_fixed_reals, integers_from_first, largest_over_ranks, any_rank
  public :: abort_ranks

  !> Whether this binary was built with MPI (mpirun -np N runs N ranks) or is one rank only.
#ifdef CRASHFREE_MPI
  logical, parameter :: mpi_built = .true.
#else
  logical, parameter :: mpi_built = .false.
#endif

contains

  !> Start MPI when a launcher started this process (once, before anything else: the program
  !> calls it). OpenMP threads run inside a rank; only the thread that started MPI calls it
  !> (FUNNELED).
  subroutine start_ranks()
#ifdef CRASHFREE_MPI
    integer :: provided
    if (mpi_running() .or. .not. launched()) return
    call MPI_Init_thread(MPI_THREAD_FUNNELED, provided)
#endif
  end subroutine start_ranks

#ifdef CRASHFREE_MPI
  !> Whether a launcher started this process: Open MPI's mpirun, or a PMI one (MPICH's Hydra,
  !> Slurm's srun), each set these.
  logical function launched()
    character(len=16) :: setting
    integer :: length, status, k
    character(len=20), parameter :: names(4) = [character(len=20) :: "OMPI_COMM_WORLD_SIZE", "PMI_SIZE", &
                                                 "PMIX_RANK", "PMI_RANK"]
    launched = .false.
    do k = 1, size(names)
      call get_environment_variable(trim(names(k)), setting, length, status)
      if (status == 0 .or. status == -1) launched = .true.
    end do
  end function launched
#endif

  !> Whether MPI is started and not yet finished (then the exchanges talk to the other ranks).
  logical function mpi_running()
#ifdef CRASHFREE_MPI
    logical :: started, finished
    call MPI_Initialized(started)
    call MPI_Finalized(finished)
    mpi_running = started .and. .not. finished
#else
    mpi_running = .false.
#endif
  end function mpi_running

  !> End MPI (the program calls it last, on every rank).
  subroutine finish_ranks()
#ifdef CRASHFREE_MPI
    if (mpi_running()) call MPI_Finalize()
#endif
  end subroutine finish_ranks

  !> This process's rank, 0 to rank_total() - 1 (0 without MPI).
  integer function rank_index()
    rank_index = 0
#ifdef CRASHFREE_MPI
    if (mpi_running()) call MPI_Comm_rank(MPI_COMM_WORLD, rank_index)
#endif
  end function rank_index

  !> The number of ranks of the run (1 without MPI, or without mpirun).
  integer function rank_total()
    rank_total = 1
#ifdef CRASHFREE_MPI
    if (mpi_running()) call MPI_Comm_size(MPI_COMM_WORLD, rank_total)
#endif
  end function rank_total

  !> Wait until every rank got here.
  subroutine barrier_ranks()
#ifdef CRASHFREE_MPI
    if (mpi_running()) call MPI_Barrier(MPI_COMM_WORLD)
#endif
  end subroutine barrier_ranks

  !> Every rank's `send` (counts(r + 1) values from rank r) into `receive` on every rank, rank
  !> after rank at `offsets(r + 1)` (0-based, as MPI counts). The buffers are the caller's,
  !> allocated once: the exchange itself allocates nothing.
  subroutine gather_reals(send, counts, offsets, receive)
    real(wp), intent(in), contiguous :: send(:)
    integer, intent(in), contiguous :: counts(:), offsets(:)
    real(wp), intent(inout), contiguous :: receive(:)
#ifdef CRASHFREE_MPI
    if (mpi_running()) then
      call MPI_Allgatherv(send, counts(rank_index() + 1), MPI_DOUBLE_PRECISION, receive, counts, offsets, &
                          MPI_DOUBLE_PRECISION, MPI_COMM_WORLD)
      return
    end if
#endif
    receive(offsets(1) + 1:offsets(1) + counts(1)) = send(1:counts(1))
  end subroutine gather_reals

  !> Every rank's `send` (`counts(rank + 1)` values) into `receive(offsets(rank + 1) + 1:)` on
  !> the first rank only (MPI_Gatherv; the others' `receive` is left as it is).
  subroutine gather_reals_to_first(send, counts, offsets, receive)
    real(wp), intent(in), contiguous :: send(:)
    integer, intent(in), contiguous :: counts(:), offsets(:)
    real(wp), intent(inout), contiguous :: receive(:)
#ifdef CRASHFREE_MPI
    if (mpi_running()) then
      call MPI_Gatherv(send, counts(rank_index() + 1), MPI_DOUBLE_PRECISION, receive, counts, offsets, &
                       MPI_DOUBLE_PRECISION, 0, MPI_COMM_WORLD)
      return
    end if
#endif
    receive(offsets(1) + 1:offsets(1) + counts(1)) = send(1:counts(1))
  end subroutine gather_reals_to_first

  !> Every rank's `send` (the same size on all) into `receive(:, rank + 1)` on every rank.
  subroutine gather_fixed_reals(send, receive)
    real(wp), intent(in), contiguous :: send(:)
    real(wp), intent(inout), contiguous :: receive(:, :)
#ifdef CRASHFREE_MPI
    if (mpi_running()) then
      call MPI_Allgather(send, size(send), MPI_DOUBLE_PRECISION, receive, size(send), MPI_DOUBLE_PRECISION, &
                         MPI_COMM_WORLD)
      return
    end if
#endif
    receive(:, 1) = send
  end subroutine gather_fixed_reals

  !> Every rank's `values` become the first rank's (MPI_Bcast; the same size on every rank).
  subroutine integers_from_first(values)
    integer, intent(inout), contiguous :: values(:)
#ifdef CRASHFREE_MPI
    if (mpi_running()) call MPI_Bcast(values, size(values), MPI_INTEGER, 0, MPI_COMM_WORLD)
#endif
  end subroutine integers_from_first

  !> values(k) becomes the largest values(k) of all ranks (exact: a maximum does not depend on
  !> the order in which it is taken).
  subroutine largest_over_ranks(values)
    real(wp), intent(inout), contiguous :: values(:)
#ifdef CRASHFREE_MPI
    if (mpi_running()) call MPI_Allreduce(MPI_IN_PLACE, values, size(values), MPI_DOUBLE_PRECISION, MPI_MAX, &
                                          MPI_COMM_WORLD)
#endif
  end subroutine largest_over_ranks

  !> Whether `flag` is true on some rank.
  logical function any_rank(flag)
    logical, intent(in) :: flag
    any_rank = flag
#ifdef CRASHFREE_MPI
    if (mpi_running()) call MPI_Allreduce(flag, any_rank, 1, MPI_LOGICAL, MPI_LOR, MPI_COMM_WORLD)
#endif
  end function any_rank

  !> Stop every rank at once: `message` on standard error (with the rank when there are several),
  !> then the exit status `status` (1 run-time error, 2 input rejected). For an error that only
  !> one rank sees; errors that all ranks see end the ordinary way.
  subroutine abort_ranks(message, status)
    character(len=*), intent(in) :: message
    integer, intent(in) :: status
    character(len=24) :: rank_text
    flush (output_unit)
    if (rank_total() > 1) then
      write (rank_text, '(a,i0,a)') " (rank ", rank_index(), ")"
      write (error_unit, '(a)') "crashfree"//trim(rank_text)//": "//message
    else
      write (error_unit, '(a)') "crashfree: "//message
    end if
    flush (error_unit)
#ifdef CRASHFREE_MPI
    if (mpi_running()) call MPI_Abort(MPI_COMM_WORLD, status)
#endif
    ! (Fortran 2008's error stop takes a constant)
    if (status == 2) error stop 2
    error stop 1
  end subroutine abort_ranks
end module rank_communication
