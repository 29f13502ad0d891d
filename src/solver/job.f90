!> One crashfree job: read the deck, run, write results; returns the exit status.
module job
  use command_line, only: run_options_t
  implicit none
  private
  public :: run_job
contains
  subroutine run_job(options, exit_status)
    type(run_options_t), intent(in) :: options
    integer, intent(out) :: exit_status
    exit_status = 1
    if (allocated(options%deck)) exit_status = 1
  end subroutine run_job
end module job
