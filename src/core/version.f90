!> The program's version, written to results files and shown by --version.
module version
  implicit none
  private
  character(len=*), parameter, public :: crashfree_version = "0.1.0"
end module version
