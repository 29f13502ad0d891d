!> Numeric kinds and the block size shared by every element kernel.
module kinds
  use, intrinsic :: iso_fortran_env, only: real64, int64
  implicit none
  private

  !> Working precision for every real quantity of the solver.
  integer, parameter, public :: wp = real64
  !> Integer kind for counters that may exceed 2**31 (cycles x elements).
  integer, parameter, public :: long_int = int64
  !> Maximum number of elements in one block. Blocks of one type and material are the unit of
  !> work of every element kernel; 64 keeps a block's arrays in L1/L2 cache and gives the
  !> compiler a long inner loop to vectorize (OpenRadioss MVSIZ, WARP3D mxvl).
  integer, parameter, public :: block_size = 64
end module kinds
