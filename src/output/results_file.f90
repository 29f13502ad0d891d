!> The results file `DIR/JOBID.h5` (layout: docs/contract.md; user reference: docs/output.md)
!> and its XDMF companion `DIR/JOBID.xdmf`.
!>
!> The solver calls `open_results` before the first cycle (mesh, and `/run` with status
!> "running"), `write_state` at each state time (with the history rows recorded since the
!> previous state), and `close_results` with the run summary, also after an error, so that the
!> file says how the run ended. `write_histories` writes the histories alone.
!>
!> What the output costs and what survives a failure:
!> - Each state is one commit: its group (created anonymous) with its datasets and the new
!>   history rows, flushed; then its link in /states, flushed. The histories are extendible,
!>   chunked datasets to which only the new rows are written, and /states keeps its links in
!>   HDF5's dense form, so the cost of a state does not grow with the number of states before
!>   it. A kill can only break the link being written (see write_state).
!> - The XDMF file is rewritten whole (and atomically, see xdmf_writer) at the states 1, 2, 4,
!>   8, ... and, for a reader watching a long run, whenever its last rewrite is 2 s old and
!>   took less than a twentieth of that time: linear in total, and complete at `close_results`.
!> - Before a commit the disk blocks it needs are reserved (file_system's reserve_file_space),
!>   so on a full disk the reservation fails before anything of the state is written: the
!>   file keeps every complete state and is closed cleanly.
!> - When a write fails anyway (a file system without reservations, an I/O error), the HDF5
!>   handle is abandoned rather than flushed or closed: the metadata HDF5 holds in memory would
!>   only partly reach the disk and could break the states already there, while the file on
!>   disk is complete as of the previous commit. HDF5's exit handler is switched off for the
!>   same reason (it would flush the abandoned file at exit; on a full disk it crashed).
!> - The output directory is locked for the job (file_lock on `DIR/JOBID.lock`), so a second
!>   run into the same files is refused before it truncates them.
!>
!> Conventions of the file:
!> - Fortran arrays `(3, n)` are stored with HDF5 dimensions `(n, 3)`, which is how h5py and
!>   every C-ordered reader see them: one row per node, columns x, y, z.
!> - Reals are IEEE 64-bit. Ids and connectivities are 32-bit integers; the counts in
!>   attributes (`cycles`, `threads`, `fe_elements`, ...) are 64-bit, so that products such
!>   as elements x cycles do not overflow in a reader's integer arithmetic.
!> - Strings (attributes and `/mesh/parts/formulation`) are variable-length ASCII: h5py
!>   returns attributes as `str` (and the dataset as `str` through `.asstr()`).
!> - Extensions of the contract layout: `/mesh/solids/connectivity_index` (m,8), the 0-based
!>   node indices of each solid, which the XDMF topology needs; the `/run` attribute `title`;
!>   the `/timing` attributes `output_bytes` (values handed to HDF5 for states and histories)
!>   and `xdmf_writes` (times the XDMF file was written), which show what the output cost.
!>
!> HDF5's automatic error printing is switched off: every failure becomes an `error_t` naming
!> the file and the operation. The file is opened without HDF5's file lock, so ParaView or a
!> script can read the states written so far while the run goes on.
module results_file
  use, intrinsic :: iso_c_binding, only: c_ptr, c_loc, c_null_ptr, c_char, c_null_char, c_bool, &
                                         c_int, c_int64_t
  use hdf5, only: hid_t, hsize_t, h5open_f, h5eset_auto_f, h5dont_atexit_f, &
                  h5fcreate_f, h5fopen_f, h5fclose_f, h5fflush_f, H5F_ACC_TRUNC_F, H5F_ACC_RDWR_F, &
                  H5F_SCOPE_GLOBAL_F, h5gget_info_f, h5aopen_f, h5aread_f, h5sget_simple_extent_dims_f, &
                  h5sget_simple_extent_ndims_f, &
                  h5pcreate_f, h5pclose_f, h5pset_file_locking_f, h5pset_chunk_f, &
                  H5P_FILE_ACCESS_F, H5P_DATASET_CREATE_F, H5P_GROUP_CREATE_F, &
                  h5pset_link_phase_change_f, h5pset_link_creation_order_f, H5P_CRT_ORDER_TRACKED_F, &
                  h5gcreate_f, h5gcreate_anon_f, h5gopen_f, h5gclose_f, h5lexists_f, h5ldelete_f, &
                  h5olink_f, &
                  h5screate_f, h5screate_simple_f, h5sclose_f, h5sselect_hyperslab_f, &
                  H5S_SCALAR_F, H5S_UNLIMITED_F, H5S_SELECT_SET_F, &
                  h5dcreate_f, h5dopen_f, h5dclose_f, h5dwrite_f, h5dset_extent_f, &
                  h5dget_space_f, h5acreate_f, h5aclose_f, h5awrite_f, h5aexists_f, &
                  h5adelete_f, h5tcopy_f, h5tclose_f, H5T_STRING, H5T_NATIVE_INTEGER, &
                  H5T_STD_I32LE, H5T_STD_I64LE, H5T_IEEE_F64LE, h5kind_to_type, H5_REAL_KIND, &
                  H5_INTEGER_KIND, h5oclose_f, h5oopen_f
  use kinds, only: wp, long_int
  use error_handling, only: error_t, make_error
  use version, only: crashfree_version
  use model, only: model_t, formulation_fe, formulation_efg, formulation_rigid
  use run_summary, only: run_summary_t, status_error
  use history_buffer, only: history_set_t
  use xdmf_writer, only: write_xdmf, state_group_name
  use wall_clock, only: seconds_now
  use file_system, only: reserve_file_space, release_file_space, remove_file, file_size, &
                         clear_system_error, system_error_number, system_error_text, &
                         error_no_space, error_quota_exceeded
  use file_lock, only: file_lock_t, acquire_file_lock, release_file_lock
  use d3plot_file, only: d3plot_file_t, open_d3plot, continue_d3plot, write_d3plot_state, close_d3plot, &
                         d3plot_base_name, default_file_scale
  implicit none
  private

  public :: results_file_t, open_results, write_state, write_histories, close_results, continue_results

  !> An open results file: the HDF5 handle, the paths, the lock, and what the incremental
  !> writing of the histories and the XDMF file needs.
  type :: results_file_t
    integer(hid_t) :: file_id = -1                !< HDF5 file handle while open
    logical :: is_open = .false.
    !> A write failed: the HDF5 handle is abandoned (see the module comment) and the file on
    !> disk holds what the last commit left, `state_count` states.
    logical :: broken = .false.
    !> A write failed (the .h5, or the XDMF file): `close_results` then says what the files hold.
    logical :: failed = .false.
    character(len=:), allocatable :: h5_path      !< DIR/JOBID.h5
    character(len=:), allocatable :: xdmf_path    !< DIR/JOBID.xdmf
    character(len=:), allocatable :: h5_name      !< JOBID.h5, as the XDMF refers to it
    type(file_lock_t) :: lock                     !< held on DIR/JOBID.lock while open
    type(d3plot_file_t) :: d3plot                 !< LS-DYNA's d3plot beside it, with the same states
    !> A random number written to /run as `run_id` when the file is created; a restart dump
    !> records it, and a restart continues only the file of the run that wrote the dump.
    integer(long_int) :: run_id = 0
    integer :: node_count = 0                     !< n, rows of the nodal datasets
    integer :: solid_count = 0                    !< m, rows of the solid datasets
    integer :: shell_count = 0                    !< k, rows of the shell datasets
    integer :: state_count = 0                    !< complete states in the file
    real(wp), allocatable :: state_times(:)       !< time of each state written (with spare room)
    integer, allocatable :: history_rows(:)       !< rows of each history series in the file
    integer :: xdmf_state_count = 0               !< states listed by the XDMF file on disk
    integer :: xdmf_writes = 0                    !< times the XDMF file was written
    real(wp) :: xdmf_written_at = 0.0_wp          !< wall clock (s) of its last writing
    real(wp) :: xdmf_seconds = 0.0_wp             !< how long that took
    integer(long_int) :: xdmf_bytes = 0           !< size of the last XDMF file built
    integer(long_int) :: output_bytes = 0         !< bytes of state and history values written
    integer(long_int) :: reserved_bytes = 0       !< largest reservation asked for beyond the end
    integer(long_int) :: reserved_end = 0         !< end of the disk space reserved (0: none)
  end type results_file_t

  interface
    !> H5Pset_evict_on_close (HDF5 1.10.1), which the Fortran API of HDF5 1.10 does not wrap.
    function c_h5pset_evict_on_close(access_list, evict) bind(c, name="H5Pset_evict_on_close") &
      result(status)
      import :: c_int64_t, c_bool, c_int
      integer(c_int64_t), value :: access_list
      logical(c_bool), value :: evict
      integer(c_int) :: status
    end function c_h5pset_evict_on_close
  end interface

  !> The groups and datasets of one commit, kept open until it is flushed: HDF5 evicts an
  !> object's metadata from its cache when the object is closed (see open_results), writing
  !> it if it is dirty, so closing before the flush would put half a state on disk.
  type :: open_objects_t
    integer(hid_t), allocatable :: ids(:)
    integer :: count = 0
  end type open_objects_t

  !> Rows per chunk of the extendible history datasets: small enough for many short nodout
  !> series, large enough that a long glstat is not cut into thousands of pieces.
  integer(hsize_t), parameter :: history_chunk_rows = 64

  !> Space kept free for HDF5's own bookkeeping of one commit (object headers, B-tree nodes,
  !> heaps), on top of twice the values written; and for the run status at the end.
  integer(long_int), parameter :: metadata_reserve = 65536_long_int

  !> The XDMF file is rewritten, besides at the states 1, 2, 4, 8, ..., when its last
  !> rewrite is this old (s) and took less than 1/xdmf_cost_fraction of that.
  real(wp), parameter :: xdmf_refresh_seconds = 2.0_wp
  real(wp), parameter :: xdmf_cost_fraction = 20.0_wp

contains

  !> Lock `directory/job_id.lock`, create `directory/job_id.h5` (replacing an earlier file)
  !> and write `/mesh` and `/run` (status "running"). The directory must exist. On a failure
  !> nothing stays open or locked, and a half-written file is removed.
  subroutine open_results(results, directory, job_id, model, threads, error, d3plot_scale)
    type(results_file_t), intent(inout) :: results
    character(len=*), intent(in) :: directory   !< output directory ("" for the current one)
    character(len=*), intent(in) :: job_id      !< base name of the files, e.g. "results"
    type(model_t), intent(in) :: model
    integer, intent(in) :: threads              !< OpenMP threads of the run
    type(error_t), allocatable, intent(out) :: error
    !> d3plot family file size in multiples of 512^2 words (x=; default LS-DYNA's 7)
    integer, intent(in), optional :: d3plot_scale
    type(error_t), allocatable :: space_error
    integer(hid_t) :: access_list
    integer :: status, ignored

    if (results%is_open) then
      call make_error(error, "results file "//results%h5_path//": already open")
      return
    end if
    results%h5_name = job_id//".h5"
    results%h5_path = join_path(directory, results%h5_name)
    results%xdmf_path = join_path(directory, job_id//".xdmf")
    results%node_count = 0
    if (allocated(model%node_ids)) results%node_count = size(model%node_ids)
    results%solid_count = 0
    if (allocated(model%solid_ids)) results%solid_count = size(model%solid_ids)
    results%shell_count = 0
    if (allocated(model%shell_ids)) results%shell_count = size(model%shell_ids)
    results%state_count = 0
    results%broken = .false.
    results%failed = .false.
    results%run_id = new_run_id()
    if (allocated(results%state_times)) deallocate (results%state_times)
    allocate (results%state_times(16))
    if (allocated(results%history_rows)) deallocate (results%history_rows)
    allocate (results%history_rows(0))
    results%xdmf_state_count = 0
    results%xdmf_writes = 0
    results%xdmf_seconds = 0.0_wp
    results%xdmf_bytes = 0
    results%output_bytes = 0
    results%reserved_bytes = 0
    results%reserved_end = 0

    ! The lock before anything else: a second run must not truncate the first one's file.
    call lock_job(results, directory, job_id, error)
    if (allocated(error)) return

    ! Before the library starts (a later call in the same process changes nothing): no exit
    ! handler, see the module comment.
    call h5dont_atexit_f(ignored)
    ! Initialising again is harmless. Without automatic printing HDF5 keeps its error stack
    ! to itself: failures reach the user once, through `error`.
    call h5open_f(status)
    if (status /= 0) then
      call make_error(error, "results file "//results%h5_path//": cannot initialise HDF5")
      call release_file_lock(results%lock)
      return
    end if
    call h5eset_auto_f(0, status)

    ! No file lock, so that readers may open the file between two writes.
    call clear_system_error()
    call h5pcreate_f(H5P_FILE_ACCESS_F, access_list, status)
    if (status == 0) call h5pset_file_locking_f(access_list, .false., .true., status)
    ! A state's groups and datasets are not opened again: evicting their metadata when they are
    ! closed keeps HDF5's cache small, and with it the cost of each flush, which otherwise
    ! grows with the number of objects in the cache (the states written so far).
    if (status == 0) status = int(c_h5pset_evict_on_close(int(access_list, c_int64_t), .true._c_bool))
    if (status == 0) call h5fcreate_f(results%h5_path, H5F_ACC_TRUNC_F, results%file_id, status, &
                                      access_prp=access_list)
    call h5pclose_f(access_list, ignored)
    if (status /= 0) then
      if (disk_full()) then
        call make_error(error, lower_reason()//" while creating "//results%h5_path)
      else
        call make_error(error, "results file "//results%h5_path//": cannot create the file"// &
                        system_reason())
      end if
      ! An empty file left by the attempt (created, then its first write failed) is no result.
      if (file_size(results%h5_path) == 0) call remove_file(results%h5_path)
      results%file_id = -1
      call release_file_lock(results%lock)
      return
    end if
    results%is_open = .true.

    call reserve_space(results, mesh_bytes(results) + metadata_reserve, space_error)
    if (allocated(space_error)) then
      call make_error(error, space_error%message//" while creating "//results%h5_path)
    else
      call write_mesh(results%file_id, model, error)
      call write_run_start(results%file_id, model, threads, results%run_id, error)
      call create_states_group(results%file_id, error)
      call create_group_path(results%file_id, "/history", error)
      call flush_file(results%file_id, error)
      if (allocated(error)) then
        if (disk_full()) then
          error%message = lower_reason()//" while creating "//results%h5_path
        else
          error%message = "results file "//results%h5_path//": "//error%message//system_reason()
        end if
      end if
    end if
    ! LS-DYNA's d3plot beside it, with every state written here
    if (.not. allocated(error)) then
      if (present(d3plot_scale)) then
        call open_d3plot(results%d3plot, join_path(directory, d3plot_base_name(job_id)), model, d3plot_scale, error)
      else
        call open_d3plot(results%d3plot, join_path(directory, d3plot_base_name(job_id)), model, default_file_scale, &
                         error)
      end if
    end if
    if (allocated(error)) then
      ! Abandoned, not closed (a close would flush into a file that cannot take it), and
      ! removed: it holds no result.
      results%broken = .true.
      results%is_open = .false.
      results%file_id = -1
      call remove_file(results%h5_path)
      call release_file_lock(results%lock)
    end if
  end subroutine open_results

  !> Write the next state `/states/NNNNNN` and, when `histories` is given, the history rows
  !> recorded since the previous call, as one commit; then rewrite the XDMF file when its
  !> schedule says so.
  !> Beam results, when the model has beams: `beam_resultant` (6, beams) N, Q_s, Q_t, T, M_s,
  !> M_t in each beam's local axes, `beam_plastic_strain` the largest of its section points,
  !> `beam_failed` 1 for a failed weld.
  !> Shell results (global axes): `shell_stress` the mid-surface stress (mean over the
  !> through-thickness points), `shell_plastic_strain` its mean plastic strain, and, as crashfree
  !> extensions, `shell_stress_peak` / `shell_plastic_strain_peak` at the point with the largest
  !> von Mises stress / plastic strain. Without shell arguments the shell datasets are empty
  !> (a model without shells).
  !> On a failure the message says which state and time could not be written and why ("no
  !> space left on device while writing state 12 at time ... to DIR/results.h5"); the file
  !> keeps the states before it.
  subroutine write_state(results, time, displacement, velocity, solid_stress, &
                         solid_plastic_strain, error, shell_stress, shell_plastic_strain, shell_stress_peak, &
                         shell_plastic_strain_peak, histories, beam_resultant, beam_plastic_strain, beam_failed, &
                         solid_eroded, shell_eroded, eroded_count, acceleration, globals, shell_point_stress, &
                         shell_point_plastic_strain, shell_point_count, shell_resultant, shell_thickness, &
                         shell_energy_density, reference_coordinates)
    type(results_file_t), intent(inout) :: results
    real(wp), intent(in) :: time
    ! Contiguous: the solver's whole arrays go to HDF5 without a copy.
    real(wp), intent(in), contiguous :: displacement(:, :)       !< (3, nodes)
    real(wp), intent(in), contiguous :: velocity(:, :)           !< (3, nodes)
    real(wp), intent(in), contiguous :: solid_stress(:, :)       !< (6, solids) xx yy zz xy yz zx
    real(wp), intent(in), contiguous :: solid_plastic_strain(:)  !< (solids)
    type(error_t), allocatable, intent(out) :: error
    real(wp), intent(in), contiguous, optional :: shell_stress(:, :), shell_stress_peak(:, :) !< (6, shells)
    real(wp), intent(in), contiguous, optional :: shell_plastic_strain(:), shell_plastic_strain_peak(:) !< (shells)
    type(history_set_t), intent(in), target, optional :: histories !< rows not yet in the file are added
    real(wp), intent(in), contiguous, optional :: beam_resultant(:, :)   !< (6, beams)
    real(wp), intent(in), contiguous, optional :: beam_plastic_strain(:), beam_failed(:) !< (beams)
    !> deleted-element flags (1: eroded) and the count of eroded elements (explicit runs)
    integer, intent(in), contiguous, optional :: solid_eroded(:), shell_eroded(:)
    integer, intent(in), optional :: eroded_count
    !> for the d3plot only: (3, nodes) accelerations (absent: 0), and its global values
    !> (kinetic, internal, total energy, velocity (3), per part internal then kinetic energy)
    real(wp), intent(in), contiguous, optional :: acceleration(:, :), globals(:)
    !> for the d3plot only: the shells' points through the thickness (element_results_t)
    real(wp), intent(in), contiguous, optional :: shell_point_stress(:, :, :), shell_point_plastic_strain(:, :)
    integer, intent(in), contiguous, optional :: shell_point_count(:)
    real(wp), intent(in), contiguous, optional :: shell_resultant(:, :), shell_thickness(:), shell_energy_density(:)
    !> for the d3plot, which writes reference + displacement and keeps no copy of the model's
    !> coordinates: (3, nodes) the reference coordinates (model%coordinates); needed while a
    !> d3plot is written
    real(wp), intent(in), contiguous, optional :: reference_coordinates(:, :)
    real(wp) :: no_shell_stress(6, 0), no_shell_strain(0)
    real(wp), allocatable :: grown(:)
    type(error_t), allocatable :: space_error
    character(len=:), allocatable :: path, what
    type(open_objects_t) :: objects
    integer(hid_t) :: group_id, states_id
    integer(long_int) :: state_bytes, history_bytes, history_space
    integer :: status

    if (.not. results%is_open .or. results%broken) then
      call make_error(error, "results file: write_state on a file that is not open")
      return
    end if
    if (any(shape(displacement) /= [3, results%node_count]) .or. &
        any(shape(velocity) /= [3, results%node_count]) .or. &
        any(shape(solid_stress) /= [6, results%solid_count]) .or. &
        size(solid_plastic_strain) /= results%solid_count .or. &
        (present(shell_stress) .neqv. results%shell_count > 0)) then
      call make_error(error, "results file "//results%h5_path//": state at time "// &
                      real_text(time)//": array sizes do not match the mesh ("// &
                      integer_text(results%node_count)//" nodes, "// &
                      integer_text(results%solid_count)//" solids)")
      return
    end if

    if (results%d3plot%is_open) then
      if (.not. present(reference_coordinates)) then
        call make_error(error, "results file "//results%h5_path//": state at time "//real_text(time)// &
                        ": no reference coordinates for the d3plot")
        return
      else if (any(shape(reference_coordinates) /= [3, results%node_count])) then
        call make_error(error, "results file "//results%h5_path//": state at time "//real_text(time)// &
                        ": the reference coordinates do not match the mesh ("//integer_text(results%node_count)// &
                        " nodes)")
        return
      end if
    end if

    what = "state "//integer_text(results%state_count)//" at time "//real_text(time)
    state_bytes = 8_long_int*(6_long_int*results%node_count + 7_long_int*results%solid_count + &
                              14_long_int*results%shell_count)
    ! the deleted-element flags, 32-bit
    if (present(solid_eroded)) state_bytes = state_bytes + 4_long_int*size(solid_eroded)
    if (present(shell_eroded)) state_bytes = state_bytes + 4_long_int*size(shell_eroded)
    history_bytes = 0
    history_space = 0
    if (present(histories)) call new_history_bytes(results, histories, history_bytes, history_space)
    ! Twice the values (HDF5 allocates in blocks), its bookkeeping, and the room the next XDMF
    ! file takes (given back just before it is written, see write_xdmf_now).
    call reserve_space(results, 2_long_int*(state_bytes + history_space) + metadata_reserve + &
                       xdmf_estimate(results, results%state_count + 1), space_error)
    if (allocated(space_error)) then
      ! Nothing of this state was written: the file is complete and can still be closed.
      call make_error(error, space_error%message//" while writing "//what//" to "// &
                      results%h5_path//kept_states(results))
      results%failed = .true.
      return
    end if

    call clear_system_error()
    path = "/states/"//state_group_name(results%state_count + 1)
    ! Two steps. First the state as an anonymous group (not yet in /states) and the new history
    ! rows, flushed: this writes new objects and extends the histories, and a run killed here
    ! leaves /states as it was. Then the link /states/NNNNNN, flushed: the only change to
    ! /states, a few small blocks, so the window in which a kill can leave it half-updated is
    ! as short as it can be with HDF5 (SWMR, which orders these writes, cannot add groups).
    call h5gcreate_anon_f(results%file_id, group_id, status)
    if (status /= 0) then
      call make_error(error, "cannot create group "//path)
    else
      call keep_open(objects, group_id)
      call write_real_attribute(group_id, path, "time", time, error)
      call write_real_dataset_2d(group_id, path, "displacement", displacement, error, objects)
      call write_real_dataset_2d(group_id, path, "velocity", velocity, error, objects)
      call write_real_dataset_2d(group_id, path, "solid_stress", solid_stress, error, objects)
      call write_real_dataset_1d(group_id, path, "solid_plastic_strain", solid_plastic_strain, error, &
                                 objects)
      if (present(shell_stress)) then
        call write_real_dataset_2d(group_id, path, "shell_stress", shell_stress, error, objects)
        call write_real_dataset_1d(group_id, path, "shell_plastic_strain", shell_plastic_strain, error, &
                                   objects)
        call write_real_dataset_2d(group_id, path, "shell_stress_peak", shell_stress_peak, error, objects)
        call write_real_dataset_1d(group_id, path, "shell_plastic_strain_peak", &
                                   shell_plastic_strain_peak, error, objects)
      else
        call write_real_dataset_2d(group_id, path, "shell_stress", no_shell_stress, error, objects)
        call write_real_dataset_1d(group_id, path, "shell_plastic_strain", no_shell_strain, error, objects)
      end if
      if (present(beam_resultant)) then
        if (size(beam_resultant, 2) > 0) then
          call write_real_dataset_2d(group_id, path, "beam_resultant", beam_resultant, error, objects)
          call write_real_dataset_1d(group_id, path, "beam_plastic_strain", beam_plastic_strain, error, objects)
          call write_real_dataset_1d(group_id, path, "beam_failed", beam_failed, error, objects)
        end if
      end if
      if (present(solid_eroded)) call write_integer_dataset_1d(group_id, path, "solid_eroded", solid_eroded, error)
      if (present(shell_eroded)) call write_integer_dataset_1d(group_id, path, "shell_eroded", shell_eroded, error)
      if (present(eroded_count)) call write_integer_attribute(group_id, path, "eroded_elements", eroded_count, error)
    end if
    if (present(histories)) call append_histories(results, histories, objects, error)
    call flush_file(results%file_id, error)
    ! /states through an explicit open and close, so that its B-tree and name heap leave the
    ! cache with it instead of staying there for every later flush to visit.
    if (.not. allocated(error)) then
      call h5gopen_f(results%file_id, "/states", states_id, status)
      if (status == 0) then
        call keep_open(objects, states_id)
        call h5olink_f(group_id, states_id, state_group_name(results%state_count + 1), status)
      end if
      if (status /= 0) call make_error(error, "cannot link group "//path)
    end if
    call flush_file(results%file_id, error)
    if (allocated(error)) then
      ! The objects stay open: closing them could write into the file (see open_objects_t).
      call abandon(results, error, what)
      return
    end if
    call close_objects(objects)
    results%output_bytes = results%output_bytes + state_bytes + history_bytes

    if (results%state_count == size(results%state_times)) then
      allocate (grown(2*size(results%state_times)))
      grown(1:results%state_count) = results%state_times(1:results%state_count)
      call move_alloc(grown, results%state_times)
    end if
    results%state_count = results%state_count + 1
    results%state_times(results%state_count) = time

    if (results%d3plot%is_open) then
      ! the state just written to results.h5; what results.h5 does not have is written as 0
      ! (the accelerations and global values of a static state)
      call write_d3plot_state(results%d3plot, time, reference_coordinates, displacement, velocity, solid_stress, &
                              solid_plastic_strain, error, shell_stress, shell_plastic_strain, beam_resultant, &
                              beam_failed, solid_eroded, shell_eroded, acceleration, globals, shell_point_stress, &
                              shell_point_plastic_strain, shell_point_count, shell_resultant, shell_thickness, &
                              shell_energy_density)
      if (allocated(error)) return
    end if
    if (xdmf_due(results)) call write_xdmf_now(results, error)
  end subroutine write_state

  !> Add the history rows recorded since the previous call (each series as
  !> `/history/<group>/<column>`), and flush. Rows already in the file are not written again;
  !> a series holding fewer rows than the file cuts the file's rows to its count.
  subroutine write_histories(results, histories, error)
    type(results_file_t), intent(inout) :: results
    type(history_set_t), intent(in), target :: histories
    type(error_t), allocatable, intent(out) :: error
    type(error_t), allocatable :: space_error
    type(open_objects_t) :: objects
    integer(long_int) :: history_bytes, history_space

    if (.not. results%is_open .or. results%broken) then
      call make_error(error, "results file: write_histories on a file that is not open")
      return
    end if
    call new_history_bytes(results, histories, history_bytes, history_space)
    call reserve_space(results, 2_long_int*history_space + metadata_reserve, space_error)
    if (allocated(space_error)) then
      call make_error(error, space_error%message//" while writing the histories to "// &
                      results%h5_path//kept_states(results))
      results%failed = .true.
      return
    end if
    call clear_system_error()
    call append_histories(results, histories, objects, error)
    call flush_file(results%file_id, error)
    if (allocated(error)) then
      call abandon(results, error, "the histories")
      return
    end if
    call close_objects(objects)
    results%output_bytes = results%output_bytes + history_bytes
  end subroutine write_histories

  !> Write the complete XDMF file, how the run ended (`/run`) and its timing (`/timing`), close
  !> the file and release the lock. Does nothing when the file is not open (e.g. after
  !> `open_results` failed, or twice). After a failed write (or on a disk too full for the
  !> status) `error` says what the two files hold; `/run` keeps the status "running" when it
  !> could not be written.
  subroutine close_results(results, summary, error)
    type(results_file_t), intent(inout) :: results
    type(run_summary_t), intent(in) :: summary
    type(error_t), allocatable, intent(out) :: error
    type(error_t), allocatable :: problem
    character(len=:), allocatable :: final_status
    integer :: status
    logical :: failed_before

    call close_d3plot(results%d3plot)
    if (.not. results%is_open) return
    ! a failure that happens first here has no run error to report it: keep its reason
    failed_before = results%failed
    ! The XDMF first, so that /timing counts it; it lists the complete states only.
    if (results%xdmf_state_count /= results%state_count .or. results%xdmf_writes == 0) &
      call write_xdmf_now(results, problem)
    final_status = "running"
    if (.not. results%broken) then
      ! A full disk: the file keeps its states, and closing a flushed file writes nothing.
      call reserve_space(results, metadata_reserve + 2_long_int*len(text_or_empty(summary%message)) + &
                         2_long_int*len(text_or_empty(summary%warnings)), error)
      if (allocated(error)) then
        error%message = error%message//" while writing the run status to "//results%h5_path
      else
        call clear_system_error()
        call write_run_end(results%file_id, summary, error)
        call write_timing(results, summary, error)
        call flush_file(results%file_id, error)
        if (allocated(error)) then
          call abandon(results, error, "the run status")
        else
          final_status = status_error
          if (allocated(summary%status)) final_status = summary%status
        end if
      end if
      if (allocated(error) .and. .not. allocated(problem)) call move_alloc(error, problem)
    end if
    if (.not. results%broken) then
      call h5fclose_f(results%file_id, status)
      if (status /= 0 .and. .not. allocated(problem)) &
        call make_error(problem, "cannot close "//results%h5_path//system_reason())
    end if
    call release_file_space(results%h5_path, results%reserved_bytes)
    results%reserved_end = 0
    call release_file_lock(results%lock)
    results%is_open = .false.
    results%file_id = -1

    ! After any failure, what the user has; the reason too unless the run's own error said what
    ! went wrong first (a failure during the run).
    if (allocated(problem) .or. results%failed) then
      call make_error(error, "")
      if (allocated(problem) .and. .not. failed_before) error%message = problem%message//"; "
      error%message = error%message//results%h5_path//" keeps "//state_range(results%state_count)// &
                      " with /run status """//final_status//""", "//results%xdmf_path//" lists "// &
                      state_range(results%xdmf_state_count)
    end if
  end subroutine close_results


  !> Continue the results file `directory/job_id.h5` of an interrupted run from a restart dump.
  !> `results` comes with the dump's bookkeeping (run_state_dump's exchange_results_progress:
  !> `run_id`, `state_count`, `state_times`, `history_rows`, `output_bytes`) and `histories`
  !> with the dump's history series (their groups and columns). The job is locked as by
  !> `open_results`; the file must be the one of the run that wrote the dump (its `run_id`) and
  !> hold the states the dump counts, at their times. The states and history rows written after
  !> the dump are removed, `/run` says "running" again and the XDMF file lists the states kept;
  !> the continued run then writes on as `open_results` had left it. `dump_path` names the dump
  !> in messages.
  subroutine continue_results(results, directory, job_id, model, threads, histories, dump_path, error, d3plot_scale)
    type(results_file_t), intent(inout) :: results
    character(len=*), intent(in) :: directory, job_id
    type(model_t), intent(in) :: model
    integer, intent(in) :: threads
    type(history_set_t), intent(in) :: histories
    character(len=*), intent(in) :: dump_path
    type(error_t), allocatable, intent(out) :: error
    integer, intent(in), optional :: d3plot_scale   !< d3plot family file size (x=), see open_results
    integer(hid_t) :: access_list
    integer(long_int) :: file_run_id
    integer, allocatable :: grown(:)
    integer :: status, ignored
    logical :: exists, continued

    if (results%is_open) then
      call make_error(error, "results file "//results%h5_path//": already open")
      return
    end if
    results%h5_name = job_id//".h5"
    results%h5_path = join_path(directory, results%h5_name)
    results%xdmf_path = join_path(directory, job_id//".xdmf")
    results%node_count = size(model%node_ids)
    results%solid_count = size(model%solid_ids)
    results%shell_count = 0
    if (allocated(model%shell_ids)) results%shell_count = size(model%shell_ids)
    results%broken = .false.
    results%failed = .false.
    results%xdmf_state_count = 0
    results%xdmf_writes = 0
    results%xdmf_seconds = 0.0_wp
    results%xdmf_bytes = 0
    results%reserved_bytes = 0
    results%reserved_end = 0
    if (.not. allocated(results%history_rows)) allocate (results%history_rows(0))
    if (size(results%history_rows) < histories%count) then
      allocate (grown(histories%count))
      grown = 0
      grown(1:size(results%history_rows)) = results%history_rows
      call move_alloc(grown, results%history_rows)
    end if

    call lock_job(results, directory, job_id, error)
    if (allocated(error)) return
    call h5dont_atexit_f(ignored)
    call h5open_f(status)
    call h5eset_auto_f(0, status)
    inquire (file=results%h5_path, exist=exists)
    if (.not. exists) then
      call make_error(error, "the results file "//results%h5_path//" of the interrupted run is missing: "// &
                      "a restart continues it (the dump "//dump_path//" holds the state of the run, not the "// &
                      "results written before it); put the file back, or give the outdir= and jobid= of "// &
                      "the interrupted run")
      call release_file_lock(results%lock)
      return
    end if
    call clear_system_error()
    call h5pcreate_f(H5P_FILE_ACCESS_F, access_list, status)
    if (status == 0) call h5pset_file_locking_f(access_list, .false., .true., status)
    if (status == 0) status = int(c_h5pset_evict_on_close(int(access_list, c_int64_t), .true._c_bool))
    if (status == 0) call h5fopen_f(results%h5_path, H5F_ACC_RDWR_F, results%file_id, status, &
                                    access_prp=access_list)
    call h5pclose_f(access_list, ignored)
    if (status /= 0) then
      call make_error(error, "results file "//results%h5_path//": cannot open it for writing"// &
                      system_reason()//" (not an HDF5 file, or damaged)")
      results%file_id = -1
      call release_file_lock(results%lock)
      return
    end if

    file_run_id = 0
    call read_long_attribute(results%file_id, "/run", "run_id", file_run_id, error)
    if (.not. allocated(error) .and. file_run_id /= results%run_id) &
      call make_error(error, "")
    if (allocated(error)) then
      error%message = "the results file "//results%h5_path//" is not the one of the run that wrote "// &
                      dump_path//" (its /run run_id is "//long_text(file_run_id)//", the dump's "// &
                      long_text(results%run_id)//"): a restart continues the results file of the "// &
                      "interrupted run; put that file back, or give the outdir= and jobid= of that run"
    else
      call check_kept_states(results, dump_path, error)
      if (.not. allocated(error)) call cut_states(results, error)
      if (.not. allocated(error)) call cut_histories(results, histories, dump_path, error)
      if (.not. allocated(error)) call write_run_restart(results%file_id, threads, error)
      call flush_file(results%file_id, error)
      if (allocated(error)) error%message = "results file "//results%h5_path//": "//error%message
    end if
    if (allocated(error)) then
      call h5fclose_f(results%file_id, ignored)
      results%file_id = -1
      call release_file_lock(results%lock)
      return
    end if
    results%is_open = .true.
    ! the XDMF file of the interrupted run may list states removed here
    call write_xdmf_now(results, error)
    ! its d3plot too, when it holds the states kept (else the continued run writes none)
    if (present(d3plot_scale)) then
      call continue_d3plot(results%d3plot, join_path(directory, d3plot_base_name(job_id)), model, &
                           results%state_count, d3plot_scale, continued)
    else
      call continue_d3plot(results%d3plot, join_path(directory, d3plot_base_name(job_id)), model, &
                           results%state_count, default_file_scale, continued)
    end if
  end subroutine continue_results

  !> The states the dump counts are in the file, at the dump's times.
  subroutine check_kept_states(results, dump_path, error)
    type(results_file_t), intent(in) :: results
    character(len=*), intent(in) :: dump_path
    type(error_t), allocatable, intent(inout) :: error
    character(len=:), allocatable :: path
    real(wp) :: time
    integer :: k
    logical :: exists
    integer :: status
    do k = 1, results%state_count
      path = "/states/"//state_group_name(k)
      call h5lexists_f(results%file_id, path, exists, status)
      if (status /= 0 .or. .not. exists) then
        call make_error(error, "state "//state_group_name(k)//" is missing, and the dump "//dump_path// &
                        " was written after "//integer_text(results%state_count)//" states: not the file of that "// &
                        "run, or one cut short")
        return
      end if
      time = -huge(1.0_wp)
      call read_real_attribute(results%file_id, path, "time", time, error)
      if (allocated(error)) return
      if (time /= results%state_times(k)) then
        call make_error(error, "state "//state_group_name(k)//" is at time "//real_text(time)//", the dump "// &
                        dump_path//" has it at "//real_text(results%state_times(k))//": not the file of that run")
        return
      end if
    end do
  end subroutine check_kept_states

  !> Remove the links of the states after the first `state_count` (written after the dump).
  subroutine cut_states(results, error)
    type(results_file_t), intent(in) :: results
    type(error_t), allocatable, intent(inout) :: error
    integer(hid_t) :: group_id
    integer :: storage, links, order, status, ignored, k
    logical :: exists
    call h5gopen_f(results%file_id, "/states", group_id, status)
    if (status == 0) call h5gget_info_f(group_id, storage, links, order, status)
    if (status /= 0) then
      call make_error(error, "cannot read the group /states")
      return
    end if
    do k = results%state_count + 1, results%state_count + links
      call h5lexists_f(group_id, state_group_name(k), exists, status)
      if (status == 0 .and. exists) call h5ldelete_f(group_id, state_group_name(k), status)
      if (status /= 0) then
        call make_error(error, "cannot remove the state "//state_group_name(k)//" written after the dump")
        exit
      end if
    end do
    call h5gclose_f(group_id, ignored)
  end subroutine cut_states

  !> Cut every history column to the rows the dump counts (a series with none loses its
  !> columns: the continued run creates them again).
  subroutine cut_histories(results, histories, dump_path, error)
    type(results_file_t), intent(in) :: results
    type(history_set_t), intent(in) :: histories
    character(len=*), intent(in) :: dump_path
    type(error_t), allocatable, intent(inout) :: error
    integer(hsize_t) :: dims(2), maximum(2)
    integer(hid_t) :: dataset_id, space_id
    character(len=:), allocatable :: path
    integer :: series_index, column, rank, status, ignored, rows
    logical :: exists
    do series_index = 1, histories%count
      associate (series => histories%series(series_index))
        rows = results%history_rows(series_index)
        do column = 1, size(series%widths)
          path = "/history/"//series%group//"/"//trim(series%names(column))
          call h5lexists_f(results%file_id, "/history/"//series%group, exists, status)
          if (status == 0 .and. exists) call h5lexists_f(results%file_id, path, exists, status)
          if (status == 0 .and. exists .and. rows == 0) then
            call h5ldelete_f(results%file_id, path, status)
            if (status /= 0) call make_error(error, "cannot remove "//path)
          else if (status == 0 .and. exists) then
            call h5dopen_f(results%file_id, path, dataset_id, status)
            if (status == 0) call h5dget_space_f(dataset_id, space_id, status)
            if (status == 0) call h5sget_simple_extent_ndims_f(space_id, rank, status)
            if (status == 0 .and. rank >= 1 .and. rank <= 2) then
              call h5sget_simple_extent_dims_f(space_id, dims(1:rank), maximum(1:rank), status)
              if (status >= 0) status = 0
              call h5sclose_f(space_id, ignored)
              if (status == 0 .and. dims(rank) < int(rows, hsize_t)) then
                call make_error(error, path//" holds "//integer_text(int(dims(rank)))//" rows, the dump "// &
                                dump_path//" was written after "//integer_text(rows))
              else if (status == 0) then
                dims(rank) = int(rows, hsize_t)
                call h5dset_extent_f(dataset_id, dims(1:rank), status)
              end if
            else if (status == 0) then
              status = 1
            end if
            call h5dclose_f(dataset_id, ignored)
            if (status /= 0 .and. .not. allocated(error)) call make_error(error, "cannot cut "//path)
          else if (rows > 0) then
            call make_error(error, path//" is missing, the dump "//dump_path//" was written after "// &
                            integer_text(rows)//" rows of it")
          end if
          if (allocated(error)) return
        end do
      end associate
    end do
  end subroutine cut_histories

  !> `/run` of a continued run: running again, on these threads.
  subroutine write_run_restart(file_id, threads, error)
    integer(hid_t), intent(in) :: file_id
    integer, intent(in) :: threads
    type(error_t), allocatable, intent(inout) :: error
    integer(hid_t) :: group_id
    integer :: status
    if (allocated(error)) return
    call h5gopen_f(file_id, "/run", group_id, status)
    if (status /= 0) then
      call make_error(error, "cannot open group /run")
      return
    end if
    call write_string_attribute(group_id, "/run", "status", "running", error)
    call write_string_attribute(group_id, "/run", "message", "", error)
    call write_integer_attribute(group_id, "/run", "threads", threads, error)
    call h5gclose_f(group_id, status)
  end subroutine write_run_restart

  !> A scalar attribute `name` of the object at `path`, read as a 64-bit integer.
  subroutine read_long_attribute(file_id, path, name, value, error)
    integer(hid_t), intent(in) :: file_id
    character(len=*), intent(in) :: path, name
    integer(long_int), intent(inout) :: value
    type(error_t), allocatable, intent(inout) :: error
    integer(long_int), target :: stored
    call read_attribute(file_id, path, name, h5kind_to_type(long_int, H5_INTEGER_KIND), c_loc(stored), error)
    if (.not. allocated(error)) value = stored
  end subroutine read_long_attribute

  !> A scalar attribute `name` of the object at `path`, read as a real.
  subroutine read_real_attribute(file_id, path, name, value, error)
    integer(hid_t), intent(in) :: file_id
    character(len=*), intent(in) :: path, name
    real(wp), intent(inout) :: value
    type(error_t), allocatable, intent(inout) :: error
    real(wp), target :: stored
    call read_attribute(file_id, path, name, h5kind_to_type(wp, H5_REAL_KIND), c_loc(stored), error)
    if (.not. allocated(error)) value = stored
  end subroutine read_real_attribute

  subroutine read_attribute(file_id, path, name, memory_type, buffer, error)
    integer(hid_t), intent(in) :: file_id
    character(len=*), intent(in) :: path, name
    integer(hid_t), intent(in) :: memory_type
    type(c_ptr), intent(in) :: buffer
    type(error_t), allocatable, intent(inout) :: error
    integer(hid_t) :: object_id, attribute_id
    type(c_ptr) :: pointer
    integer :: status, ignored
    logical :: exists
    if (allocated(error)) return
    call h5oopen_f(file_id, path, object_id, status)
    if (status /= 0) then
      call make_error(error, "cannot open "//path)
      return
    end if
    call h5aexists_f(object_id, name, exists, status)
    if (status == 0 .and. exists) then
      call h5aopen_f(object_id, name, attribute_id, status)
      pointer = buffer
      if (status == 0) then
        call h5aread_f(attribute_id, memory_type, pointer, status)
        call h5aclose_f(attribute_id, ignored)
      end if
    else
      status = 1
    end if
    call h5oclose_f(object_id, ignored)
    if (status /= 0) call make_error(error, "cannot read the attribute "//name//" of "//path)
  end subroutine read_attribute

  !> A random number that identifies a run (OS entropy through random_seed).
  function new_run_id() result(id)
    integer(long_int) :: id
    real(wp) :: noise(2)
    call random_seed()
    call random_number(noise)
    id = int(noise(1)*2.0_wp**30, long_int)*2_long_int**31 + int(noise(2)*2.0_wp**31, long_int)
  end function new_run_id

  pure function long_text(value) result(text)
    integer(long_int), intent(in) :: value
    character(len=:), allocatable :: text
    character(len=24) :: buffer
    write (buffer, '(i0)') value
    text = trim(buffer)
  end function long_text

  ! ---------------------------------------------------------------------------------------------
  ! Commits, failures and the XDMF schedule.

  !> Reserve `bytes` beyond the end of the file (see file_system); `error` only on a full disk.
  subroutine reserve_space(results, bytes, error)
    type(results_file_t), intent(inout) :: results
    integer(long_int), intent(in) :: bytes
    type(error_t), allocatable, intent(out) :: error
    call reserve_file_space(results%h5_path, bytes, results%reserved_end, error)
    if (.not. allocated(error)) results%reserved_bytes = max(results%reserved_bytes, bytes)
  end subroutine reserve_space

  !> After a failed HDF5 call while writing `what`: give up the handle (see the module comment)
  !> and turn `error` into the user's message, the reason first when the disk is full.
  subroutine abandon(results, error, what)
    type(results_file_t), intent(inout) :: results
    type(error_t), intent(inout) :: error
    character(len=*), intent(in) :: what
    results%broken = .true.
    results%failed = .true.
    if (disk_full()) then
      error%message = lower_reason()//" while writing "//what//" to "//results%h5_path// &
                      kept_states(results)
    else
      error%message = "results file "//results%h5_path//": "//error%message//system_reason()// &
                      " while writing "//what//kept_states(results)
    end if
  end subroutine abandon

  !> Whether the last failed system call found the disk full (or the quota used up).
  logical function disk_full()
    disk_full = system_error_number() == error_no_space .or. &
                system_error_number() == error_quota_exceeded
  end function disk_full

  !> The system's reason of the last failure, in lower case ("no space left on device").
  function lower_reason() result(text)
    character(len=:), allocatable :: text
    text = system_error_text(system_error_number())
    if (len(text) > 0) then
      if (text(1:1) >= "A" .and. text(1:1) <= "Z") text(1:1) = achar(iachar(text(1:1)) + 32)
    end if
  end function lower_reason

  !> " (No such file or directory)" after a failure that set errno, else "".
  function system_reason() result(text)
    character(len=:), allocatable :: text
    text = ""
    if (system_error_number() /= 0) text = " ("//system_error_text(system_error_number())//")"
  end function system_reason

  !> What the file holds, for messages after a failure: "; the file keeps states 0 to 11 (up to
  !> time ...)".
  function kept_states(results) result(text)
    type(results_file_t), intent(in) :: results
    character(len=:), allocatable :: text
    text = "; the file keeps "//state_range(results%state_count, results)
  end function kept_states

  !> Whether the XDMF file is to be rewritten now: at the states 1, 2, 4, 8, ... (so the
  !> rewrites cost at most twice the final file in total), or when the last rewrite is older
  !> than `xdmf_refresh_seconds` and took less than 1/xdmf_cost_fraction of the time since (so
  !> that a reader watching a long run sees new states, at a bounded share of the run time).
  logical function xdmf_due(results)
    type(results_file_t), intent(in) :: results
    real(wp) :: since
    xdmf_due = results%state_count >= 2*results%xdmf_state_count
    if (xdmf_due) return
    since = seconds_now() - results%xdmf_written_at
    xdmf_due = since >= xdmf_refresh_seconds .and. since >= xdmf_cost_fraction*results%xdmf_seconds
  end function xdmf_due

  !> Write the XDMF file listing the complete states, and note when and how long it took.
  !> The space reserved beyond the end of the .h5 is given back first: it includes room for
  !> this file, so that on a disk that fills up the XDMF file can still list every complete
  !> state (the next commit reserves again).
  subroutine write_xdmf_now(results, error)
    type(results_file_t), intent(inout) :: results
    type(error_t), allocatable, intent(inout) :: error
    type(error_t), allocatable :: xdmf_error
    real(wp) :: started
    started = seconds_now()
    call release_file_space(results%h5_path, results%reserved_bytes)
    results%reserved_end = 0
    call clear_system_error()
    call write_xdmf(results%xdmf_path, results%h5_name, results%node_count, results%solid_count, &
                    results%shell_count, results%state_times(1:results%state_count), xdmf_error, &
                    results%xdmf_bytes)
    results%xdmf_written_at = seconds_now()
    results%xdmf_seconds = results%xdmf_written_at - started
    results%xdmf_writes = results%xdmf_writes + 1
    if (allocated(xdmf_error)) then
      ! The previous XDMF file is still there, complete; the .h5 is not affected.
      results%failed = .true.
      if (disk_full() .and. results%state_count > 0) then
        xdmf_error%message = lower_reason()//" while writing "//results%xdmf_path//" after state "// &
          integer_text(results%state_count - 1)//" at time "//real_text(results%state_times(results%state_count))
      else if (disk_full()) then
        xdmf_error%message = lower_reason()//" while writing "//results%xdmf_path//" before any state"
      end if
      if (.not. allocated(error)) call move_alloc(xdmf_error, error)
      return
    end if
    results%xdmf_state_count = results%state_count
  end subroutine write_xdmf_now

  !> Bytes the XDMF file listing `count` states will take: measured on the last one written
  !> (with a margin), about 4 kB per state before.
  function xdmf_estimate(results, count) result(bytes)
    type(results_file_t), intent(in) :: results
    integer, intent(in) :: count
    integer(long_int) :: bytes
    if (results%xdmf_state_count > 0) then
      bytes = 4096_long_int + (5_long_int*results%xdmf_bytes*count)/(4_long_int*results%xdmf_state_count)
    else
      bytes = 4096_long_int*(count + 1)
    end if
  end function xdmf_estimate

  !> "states 0 to 11 (up to time 1.1E-02)", "state 0 (time 0)", or "no state".
  function state_range(count, results) result(text)
    integer, intent(in) :: count
    type(results_file_t), intent(in), optional :: results
    character(len=:), allocatable :: text
    if (count == 0) then
      text = "no state"
    else if (count == 1) then
      text = "state 0"
    else
      text = "states 0 to "//integer_text(count - 1)
    end if
    if (present(results) .and. count > 0) text = text//" (up to time "//real_text(results%state_times(count))//")"
  end function state_range

  !> Bytes of the mesh datasets, for the reservation before they are written.
  function mesh_bytes(results) result(bytes)
    type(results_file_t), intent(in) :: results
    integer(long_int) :: bytes
    bytes = 2_long_int*(28_long_int*results%node_count + 72_long_int*results%solid_count + &
                        40_long_int*results%shell_count)
  end function mesh_bytes

  !> Bytes of the history rows not yet in the file (`values`), and what writing them may add to
  !> the file (`allocated`: the values and one new chunk per column of each series that gets
  !> rows, as HDF5 allocates whole chunks).
  subroutine new_history_bytes(results, histories, values, allocated)
    type(results_file_t), intent(in) :: results
    type(history_set_t), intent(in) :: histories
    integer(long_int), intent(out) :: values, allocated
    integer :: series_index, in_file
    values = 0
    allocated = 0
    do series_index = 1, histories%count
      in_file = 0
      if (series_index <= size(results%history_rows)) in_file = results%history_rows(series_index)
      associate (series => histories%series(series_index))
        if (series%count > in_file) then
          values = values + 8_long_int*series%row_width*(series%count - in_file)
          allocated = allocated + 8_long_int*series%row_width*(series%count - in_file + history_chunk_rows)
        end if
      end associate
    end do
  end subroutine new_history_bytes

  !> Append to every history series the rows not yet in the file (see write_histories).
  !> The groups and datasets it opens are added to `objects`, for closing after the flush.
  subroutine append_histories(results, histories, objects, error)
    type(results_file_t), intent(inout) :: results
    type(history_set_t), intent(in), target :: histories
    type(open_objects_t), intent(inout) :: objects
    type(error_t), allocatable, intent(inout) :: error
    integer, allocatable :: grown(:)
    character(len=:), allocatable :: path
    integer(hid_t) :: group_id
    integer :: series_index, column, first_row, in_file, status

    if (allocated(error)) return
    if (size(results%history_rows) < histories%count) then
      allocate (grown(histories%count))
      grown = 0
      grown(1:size(results%history_rows)) = results%history_rows
      call move_alloc(grown, results%history_rows)
    end if
    do series_index = 1, histories%count
      associate (series => histories%series(series_index))
        in_file = results%history_rows(series_index)
        if (series%count == in_file) cycle
        path = "/history/"//series%group
        if (in_file == 0) call create_group_path(results%file_id, path, error)
        if (allocated(error)) return
        call h5gopen_f(results%file_id, path, group_id, status)
        if (status /= 0) then
          call make_error(error, "cannot open group "//path)
          return
        end if
        call keep_open(objects, group_id)
        first_row = 1
        do column = 1, size(series%widths)
          call append_history_column(group_id, path, trim(series%names(column)), series%rows, &
                                     first_row, series%widths(column), in_file, series%count, &
                                     objects, error)
          first_row = first_row + series%widths(column)
        end do
        if (allocated(error)) return
        results%history_rows(series_index) = series%count
      end associate
    end do
  end subroutine append_histories

  !> One history column, the rows `first_row : first_row + width - 1` of `rows(:, 1:count)`,
  !> stored as (count) for width 1 and (count, width) otherwise, in a chunked dataset
  !> extendible in rows. Only the rows after `in_file` (those already in the file) are written,
  !> straight from `rows` through a strided memory selection (no copy). A count below
  !> `in_file` cuts the dataset.
  subroutine append_history_column(group_id, group_path, name, rows, first_row, width, in_file, &
                                   count, objects, error)
    integer(hid_t), intent(in) :: group_id
    character(len=*), intent(in) :: group_path, name
    real(wp), intent(in), target, contiguous :: rows(:, :)   !< (row width, capacity)
    integer, intent(in) :: first_row, width, in_file, count
    type(open_objects_t), intent(inout) :: objects          !< the dataset is added to it
    type(error_t), allocatable, intent(inout) :: error
    integer(hsize_t), allocatable :: dims(:), maximum_dims(:), chunk(:), start(:), block(:)
    integer(hid_t) :: dataset_id, file_space, memory_space, create_list
    integer :: status, rank, ignored
    logical :: exists

    if (allocated(error)) return
    if (width == 1) then
      dims = [int(count, hsize_t)]
      maximum_dims = [H5S_UNLIMITED_F]
      chunk = [history_chunk_rows]
      start = [int(in_file, hsize_t)]
      block = [int(count - in_file, hsize_t)]
    else
      dims = [int(width, hsize_t), int(count, hsize_t)]
      maximum_dims = [int(width, hsize_t), H5S_UNLIMITED_F]
      chunk = [int(width, hsize_t), history_chunk_rows]
      start = [0_hsize_t, int(in_file, hsize_t)]
      block = [int(width, hsize_t), int(count - in_file, hsize_t)]
    end if
    rank = size(dims)

    exists = .false.
    if (in_file > 0) then
      exists = .true.
    else
      ! A dataset left by an earlier writer of the same file (not the solver): start afresh.
      call h5lexists_f(group_id, name, exists, status)
      if (status /= 0) then
        call make_error(error, "cannot look up dataset "//group_path//"/"//name)
        return
      end if
      if (exists) call h5ldelete_f(group_id, name, status)
      exists = .false.
    end if

    if (exists) then
      call h5dopen_f(group_id, name, dataset_id, status)
      if (status /= 0) then
        call make_error(error, "cannot open dataset "//group_path//"/"//name)
        return
      end if
      call keep_open(objects, dataset_id)
      call h5dset_extent_f(dataset_id, dims, status)
      if (status /= 0) then
        call make_error(error, "cannot extend dataset "//group_path//"/"//name)
        return
      end if
    else
      call h5screate_simple_f(rank, dims, file_space, status, maximum_dims)
      if (status /= 0) then
        call make_error(error, "cannot create the dataspace of "//group_path//"/"//name)
        return
      end if
      call h5pcreate_f(H5P_DATASET_CREATE_F, create_list, status)
      if (status == 0) call h5pset_chunk_f(create_list, rank, chunk, status)
      if (status == 0) call h5dcreate_f(group_id, name, H5T_IEEE_F64LE, file_space, dataset_id, &
                                        status, dcpl_id=create_list)
      call h5pclose_f(create_list, ignored)
      call h5sclose_f(file_space, ignored)
      if (status /= 0) then
        call make_error(error, "cannot create dataset "//group_path//"/"//name)
        return
      end if
      call keep_open(objects, dataset_id)
    end if

    if (count > in_file) then
      call h5dget_space_f(dataset_id, file_space, status)
      if (status == 0) call h5sselect_hyperslab_f(file_space, H5S_SELECT_SET_F, start, block, status)
      if (status == 0) then
        call h5screate_simple_f(2, int(shape(rows), hsize_t), memory_space, status)
        if (status == 0) then
          call h5sselect_hyperslab_f(memory_space, H5S_SELECT_SET_F, &
                                     [int(first_row - 1, hsize_t), int(in_file, hsize_t)], &
                                     [int(width, hsize_t), int(count - in_file, hsize_t)], status)
          if (status == 0) call h5dwrite_f(dataset_id, h5kind_to_type(wp, H5_REAL_KIND), c_loc(rows), &
                                           status, mem_space_id=memory_space, file_space_id=file_space)
          call h5sclose_f(memory_space, ignored)
        end if
        call h5sclose_f(file_space, ignored)
      end if
      if (status /= 0) call make_error(error, "cannot write dataset "//group_path//"/"//name)
    end if
  end subroutine append_history_column

  !> Add an open group or dataset to the objects of a commit.
  subroutine keep_open(objects, object_id)
    type(open_objects_t), intent(inout) :: objects
    integer(hid_t), intent(in) :: object_id
    integer(hid_t), allocatable :: grown(:)
    if (.not. allocated(objects%ids)) allocate (objects%ids(16))
    if (objects%count == size(objects%ids)) then
      allocate (grown(2*size(objects%ids)))
      grown(1:objects%count) = objects%ids(1:objects%count)
      call move_alloc(grown, objects%ids)
    end if
    objects%count = objects%count + 1
    objects%ids(objects%count) = object_id
  end subroutine keep_open

  !> Close the objects of a commit after its flush, the last opened first.
  subroutine close_objects(objects)
    type(open_objects_t), intent(inout) :: objects
    integer :: entry, ignored
    do entry = objects%count, 1, -1
      call h5oclose_f(objects%ids(entry), ignored)
    end do
    objects%count = 0
  end subroutine close_objects

  ! ---------------------------------------------------------------------------------------------
  ! The groups of the layout. Like every private writer below, each does nothing once `error`
  ! is set, so a sequence of writes reads as a list and stops at the first failure.

  !> `/mesh`: nodes, solids, the (empty) shells, parts, and the beams of a model that has some.
  !> The model's arrays are written as they are; a dataset that needs its values converted (ids
  !> for indices, 0-based rows) is built, written and freed before the next one, so that the
  !> mesh costs memory of one dataset at a time.
  subroutine write_mesh(file_id, model, error)
    integer(hid_t), intent(in) :: file_id
    type(model_t), intent(in) :: model
    type(error_t), allocatable, intent(inout) :: error
    integer, allocatable :: part_ids(:), material_ids(:)
    character(len=8), allocatable :: formulations(:)
    integer :: part, solid_count, part_count, shell_count

    if (allocated(error)) return
    part_count = 0
    if (allocated(model%parts)) part_count = size(model%parts)
    allocate (part_ids(part_count), material_ids(part_count), formulations(part_count))
    do part = 1, part_count
      part_ids(part) = model%parts(part)%id
      material_ids(part) = model%parts(part)%material_id
      select case (model%parts(part)%formulation)
      case (formulation_fe)
        formulations(part) = "fe"
      case (formulation_efg)
        formulations(part) = "efg"
      case (formulation_rigid)
        formulations(part) = "rigid"
      case default
        call make_error(error, "part "//integer_text(part_ids(part))//": unknown formulation "// &
                        integer_text(model%parts(part)%formulation))
        return
      end select
    end do
    solid_count = 0
    if (allocated(model%solid_ids)) solid_count = size(model%solid_ids)
    shell_count = 0
    if (allocated(model%shell_ids)) shell_count = size(model%shell_ids)

    call create_group_path(file_id, "/mesh/nodes", error)
    call create_group_path(file_id, "/mesh/solids", error)
    call create_group_path(file_id, "/mesh/shells", error)
    call create_group_path(file_id, "/mesh/parts", error)
    ! (empty datasets for a model without nodes, solids or shells: the layout is always whole)
    if (allocated(model%node_ids)) then
      call write_integer_dataset_1d(file_id, "", "/mesh/nodes/ids", model%node_ids, error)
      call write_real_dataset_2d(file_id, "", "/mesh/nodes/coordinates", model%coordinates, error)
    else
      call write_integer_dataset_1d(file_id, "", "/mesh/nodes/ids", [integer ::], error)
      call write_real_dataset_2d(file_id, "", "/mesh/nodes/coordinates", reshape([real(wp) ::], [3, 0]), error)
    end if
    if (solid_count > 0) then
      call write_element_mesh("/mesh/solids", model%solid_ids, model%solid_part, model%solid_nodes)
    else
      call write_element_mesh("/mesh/solids", [integer ::], [integer ::], reshape([integer ::], [8, 0]))
    end if
    if (shell_count > 0) then
      call write_element_mesh("/mesh/shells", model%shell_ids, model%shell_part, model%shell_nodes)
    else
      call write_element_mesh("/mesh/shells", [integer ::], [integer ::], reshape([integer ::], [4, 0]))
    end if
    call write_integer_dataset_1d(file_id, "", "/mesh/parts/ids", part_ids, error)
    call write_string_dataset(file_id, "/mesh/parts/formulation", formulations, error)
    call write_integer_dataset_1d(file_id, "", "/mesh/parts/material_ids", material_ids, error)
    if (allocated(model%beam_ids)) then
      if (size(model%beam_ids) > 0) call write_beam_mesh()
    end if
  contains
    !> `group` (/mesh/solids, /mesh/shells): the elements' ids, part ids, node ids
    !> (`connectivity`) and 0-based node rows (`connectivity_index`, for the XDMF file), one
    !> converted dataset at a time.
    subroutine write_element_mesh(group, ids, element_part, element_nodes)
      character(len=*), intent(in) :: group
      integer, intent(in) :: ids(:), element_part(:), element_nodes(:, :)
      integer, allocatable :: values(:), rows(:, :)
      integer :: element
      call write_integer_dataset_1d(file_id, "", group//"/ids", ids, error)
      allocate (values(size(ids)))
      do element = 1, size(ids)
        values(element) = model%parts(element_part(element))%id
      end do
      call write_integer_dataset_1d(file_id, "", group//"/part_ids", values, error)
      deallocate (values)
      allocate (rows(size(element_nodes, 1), size(ids)))
      do element = 1, size(ids)
        rows(:, element) = model%node_ids(element_nodes(:, element))
      end do
      call write_integer_dataset_2d(file_id, "", group//"/connectivity", rows, error)
      do element = 1, size(ids)
        rows(:, element) = element_nodes(:, element) - 1
      end do
      call write_integer_dataset_2d(file_id, "", group//"/connectivity_index", rows, error)
    end subroutine write_element_mesh

    !> `/mesh/beams` (a model with beams): ids, part ids, the node ids N1 N2 (`connectivity`),
    !> their 0-based rows (`connectivity_index`) and the orientation node N3 (0: none).
    subroutine write_beam_mesh()
      integer, allocatable :: beam_part_ids(:), beam_connectivity(:, :), orientation(:)
      integer :: beam
      allocate (beam_part_ids(size(model%beam_ids)), beam_connectivity(2, size(model%beam_ids)), &
                orientation(size(model%beam_ids)))
      do beam = 1, size(model%beam_ids)
        beam_part_ids(beam) = model%parts(model%beam_part(beam))%id
        beam_connectivity(:, beam) = model%node_ids(model%beam_nodes(1:2, beam))
        orientation(beam) = 0
        if (model%beam_nodes(3, beam) > 0) orientation(beam) = model%node_ids(model%beam_nodes(3, beam))
      end do
      call create_group_path(file_id, "/mesh/beams", error)
      call write_integer_dataset_1d(file_id, "", "/mesh/beams/ids", model%beam_ids, error)
      call write_integer_dataset_1d(file_id, "", "/mesh/beams/part_ids", beam_part_ids, error)
      call write_integer_dataset_2d(file_id, "", "/mesh/beams/connectivity", beam_connectivity, error)
      call write_integer_dataset_2d(file_id, "", "/mesh/beams/connectivity_index", model%beam_nodes(1:2, :) - 1, &
                                    error)
      call write_integer_dataset_1d(file_id, "", "/mesh/beams/orientation_node", orientation, error)
    end subroutine write_beam_mesh
  end subroutine write_mesh

  !> `/states`, as a group whose links are kept in HDF5's "dense" form (a fractal heap and a
  !> B-tree of names, HDF5 1.8 and later): adding the n-th state then changes a few small blocks
  !> of it, where the classic form rewrites its whole name heap (of size n) at every flush,
  !> and moves it whenever it grows.
  subroutine create_states_group(file_id, error)
    integer(hid_t), intent(in) :: file_id
    type(error_t), allocatable, intent(inout) :: error
    integer(hid_t) :: create_list, group_id
    integer :: status, ignored

    if (allocated(error)) return
    call h5pcreate_f(H5P_GROUP_CREATE_F, create_list, status)
    ! Tracking the creation order is what makes HDF5 use the new form (no index is kept on it);
    ! no "compact" phase: dense from the first state.
    if (status == 0) call h5pset_link_creation_order_f(create_list, H5P_CRT_ORDER_TRACKED_F, status)
    if (status == 0) call h5pset_link_phase_change_f(create_list, 0, 0, status)
    if (status == 0) call h5gcreate_f(file_id, "/states", group_id, status, gcpl_id=create_list)
    call h5pclose_f(create_list, ignored)
    if (status /= 0) then
      call make_error(error, "cannot create group /states")
      return
    end if
    call h5gclose_f(group_id, ignored)
  end subroutine create_states_group

  !> `/run` at the start. Every attribute of the contract is there from the start; the status
  !> is "running" until `close_results`, so a file left by a killed process says so. The
  !> extension `run_id` identifies the run for its restarts.
  subroutine write_run_start(file_id, model, threads, run_id, error)
    integer(hid_t), intent(in) :: file_id
    type(model_t), intent(in) :: model
    integer, intent(in) :: threads
    integer(long_int), intent(in) :: run_id
    type(error_t), allocatable, intent(inout) :: error
    integer(hid_t) :: group_id
    integer :: status

    if (allocated(error)) return
    call h5gcreate_f(file_id, "/run", group_id, status)
    if (status /= 0) then
      call make_error(error, "cannot create group /run")
      return
    end if
    call write_string_attribute(group_id, "/run", "version", crashfree_version, error)
    call write_string_attribute(group_id, "/run", "deck", text_or_empty(model%deck_path), error)
    call write_string_attribute(group_id, "/run", "title", text_or_empty(model%title), error)
    call write_string_attribute(group_id, "/run", "status", "running", error)
    call write_string_attribute(group_id, "/run", "message", "", error)
    call write_real_attribute(group_id, "/run", "end_time", 0.0_wp, error)
    call write_integer_attribute(group_id, "/run", "cycles", 0, error)
    call write_integer_attribute(group_id, "/run", "threads", threads, error)
    call write_long_attribute(group_id, "/run", "run_id", run_id, error)
    call h5gclose_f(group_id, status)
  end subroutine write_run_start

  !> `/run` at the end: outcome, end time, cycles, threads (version, deck and title stay).
  subroutine write_run_end(file_id, summary, error)
    integer(hid_t), intent(in) :: file_id
    type(run_summary_t), intent(in) :: summary
    type(error_t), allocatable, intent(inout) :: error
    integer(hid_t) :: group_id
    integer :: status

    if (allocated(error)) return
    call h5gopen_f(file_id, "/run", group_id, status)
    if (status /= 0) then
      call make_error(error, "cannot open group /run")
      return
    end if
    ! A summary without a status did not come from a normal end: never claim one for it.
    if (allocated(summary%status)) then
      call write_string_attribute(group_id, "/run", "status", summary%status, error)
    else
      call write_string_attribute(group_id, "/run", "status", status_error, error)
    end if
    call write_string_attribute(group_id, "/run", "message", text_or_empty(summary%message), error)
    call write_real_attribute(group_id, "/run", "end_time", summary%end_time, error)
    call write_integer_attribute(group_id, "/run", "cycles", summary%cycles, error)
    call write_integer_attribute(group_id, "/run", "threads", summary%threads, error)
    call write_integer_attribute(group_id, "/run", "tangled_solids", summary%tangled_solids, error)
    call write_real_attribute(group_id, "/run", "worst_corner_jacobian_ratio", summary%worst_corner_jacobian_ratio, error)
    call write_integer_attribute(group_id, "/run", "worst_corner_jacobian_element", &
                                 summary%worst_corner_jacobian_element, error)
    call h5gclose_f(group_id, status)
    call write_warnings(file_id, summary, error)
    call write_partition(file_id, summary, error)
  end subroutine write_run_end

  !> `/run/partition` (MPI runs and partition=N; nothing for one rank): per rank (rows, rank 0
  !> first) its elements by kind (`rank_elements`, columns in `kind_names`' order), blocks,
  !> ghost blocks, blocks computed by kind (`rank_computed_blocks`; `kind_blocks`: all ranks'
  !> blocks of each kind), owned and interface nodes, estimated cost (ns per cycle, owned blocks and with
  !> the ghost blocks); per solid, shell and beam (the mesh's order) the rank computing it, -1
  !> for none (rigid parts: every rank); per node the rank owning it. Attributes: rank_count, method, imbalance (max / mean
  !> cost), computed_imbalance. A continued run replaces the earlier run's.
  subroutine write_partition(file_id, summary, error)
    integer(hid_t), intent(in) :: file_id
    type(run_summary_t), intent(in) :: summary
    type(error_t), allocatable, intent(inout) :: error
    character(len=*), parameter :: path = "/run/partition"
    integer(hid_t) :: group_id
    integer :: status
    logical :: exists
    if (allocated(error)) return
    associate (partition => summary%partition)
      if (partition%rank_count <= 1 .or. .not. allocated(partition%rank_blocks)) return
      call h5lexists_f(file_id, path, exists, status)
      if (status == 0 .and. exists) call h5ldelete_f(file_id, path, status)
      call create_group_path(file_id, path, error)
      if (allocated(error)) return
      call h5gopen_f(file_id, path, group_id, status)
      if (status /= 0) then
        call make_error(error, "cannot open group "//path)
        return
      end if
      call write_integer_attribute(group_id, path, "rank_count", partition%rank_count, error)
      call write_string_attribute(group_id, path, "method", trim(partition%method), &
                                  error)
      call write_real_attribute(group_id, path, "imbalance", partition%imbalance, error)
      call write_real_attribute(group_id, path, "computed_imbalance", partition%computed_imbalance, error)
      call write_string_dataset(group_id, "kind_names", partition%kind_names, error)
      call write_integer_dataset_2d(group_id, path, "rank_elements", partition%rank_elements, error)
      call write_integer_dataset_1d(group_id, path, "rank_blocks", partition%rank_blocks, error)
      call write_integer_dataset_1d(group_id, path, "rank_ghost_blocks", partition%rank_ghost_blocks, error)
      call write_integer_dataset_2d(group_id, path, "rank_computed_blocks", partition%rank_computed_blocks, error)
      call write_integer_dataset_1d(group_id, path, "kind_blocks", partition%kind_blocks, error)
      call write_integer_dataset_1d(group_id, path, "rank_owned_nodes", partition%rank_owned_nodes, error)
      call write_integer_dataset_1d(group_id, path, "rank_interface_nodes", partition%rank_interface_nodes, error)
      call write_real_dataset_1d(group_id, path, "rank_cost", partition%rank_cost, error)
      call write_real_dataset_1d(group_id, path, "rank_computed_cost", partition%rank_computed_cost, error)
      call write_integer_dataset_1d(group_id, path, "solid_rank", partition%solid_rank, error)
      call write_integer_dataset_1d(group_id, path, "shell_rank", partition%shell_rank, error)
      call write_integer_dataset_1d(group_id, path, "beam_rank", partition%beam_rank, error)
      call write_integer_dataset_1d(group_id, path, "node_rank", partition%node_rank, error)
      call h5gclose_f(group_id, status)
    end associate
  end subroutine write_partition

  !> `/run/warnings`: one string per warning line the run printed (an empty dataset when there
  !> were none); a continued run replaces the earlier run's.
  subroutine write_warnings(file_id, summary, error)
    integer(hid_t), intent(in) :: file_id
    type(run_summary_t), intent(in) :: summary
    type(error_t), allocatable, intent(inout) :: error
    integer :: count, longest, status
    logical :: exists
    if (allocated(error)) return
    call h5lexists_f(file_id, "/run/warnings", exists, status)
    if (status == 0 .and. exists) call h5ldelete_f(file_id, "/run/warnings", status)
    if (.not. allocated(summary%warnings)) then
      call write_warning_lines(file_id, "", 0, 1, error)
      return
    end if
    call split_lines(summary%warnings, count=count, longest=longest)
    call write_warning_lines(file_id, summary%warnings, count, longest, error)
  end subroutine write_warnings

  subroutine write_warning_lines(file_id, text, count, longest, error)
    integer(hid_t), intent(in) :: file_id
    character(len=*), intent(in) :: text
    integer, intent(in) :: count, longest
    type(error_t), allocatable, intent(inout) :: error
    character(len=longest) :: lines(count)
    integer :: ignored_count, ignored_longest
    call split_lines(text, lines, ignored_count, ignored_longest)
    call write_string_dataset(file_id, "/run/warnings", lines, error)
  end subroutine write_warning_lines

  !> The non-empty lines of `text` (split at new lines): how many, the longest, and (when
  !> `lines` is given) the lines themselves.
  subroutine split_lines(text, lines, count, longest)
    character(len=*), intent(in) :: text
    character(len=*), intent(out), optional :: lines(:)
    integer, intent(out) :: count, longest
    integer :: start, finish
    count = 0
    longest = 1
    start = 1
    do while (start <= len(text))
      finish = index(text(start:), new_line("a"))
      if (finish == 0) finish = len(text) - start + 2
      if (finish > 1) then
        count = count + 1
        longest = max(longest, finish - 1)
        if (present(lines)) lines(count) = text(start:start + finish - 2)
      end if
      start = start + finish
    end do
  end subroutine split_lines

  !> `/timing`: seconds per phase, the sizes that normalise them, and what the output wrote
  !> (`output_bytes`, `xdmf_writes`: see the module comment).
  subroutine write_timing(results, summary, error)
    type(results_file_t), intent(in) :: results
    type(run_summary_t), intent(in) :: summary
    type(error_t), allocatable, intent(inout) :: error
    character(len=*), parameter :: second_names(11) = [character(len=17) :: "wall_s", &
      "fe_solid_s", "fe_shell_s", "efg_s", "contact_s", "output_s", "setup_s", "efg_setup_s", "fe_beam_s", &
      "efg_shell_s", "efg_shell_setup_s"]
    character(len=*), parameter :: count_names(13) = [character(len=19) :: "cycles", "threads", &
      "fe_elements", "efg_particles", "dofs_total", "dofs_efg", "fe_solids", "fe_shells", "fe_beams", "failed_beams", &
      "efg_shell_cells", "efg_shell_particles", "dofs_efg_shell"]
    character(len=*), parameter :: rank_datasets(2) = [character(len=17) :: "rank_seconds", "rank_column_names"]
    real(wp) :: seconds(11)
    integer :: counts(13), entry, status
    integer(hid_t) :: group_id
    logical :: exists

    call create_group_path(results%file_id, "/timing", error)
    if (allocated(error)) return
    call h5gopen_f(results%file_id, "/timing", group_id, status)
    if (status /= 0) then
      call make_error(error, "cannot open group /timing")
      return
    end if
    seconds = [summary%wall_s, summary%fe_solid_s, summary%fe_shell_s, summary%efg_s, &
               summary%contact_s, summary%output_s, summary%setup_s, summary%efg_setup_s, summary%fe_beam_s, &
               summary%efg_shell_s, summary%efg_shell_setup_s]
    counts = [summary%cycles, summary%threads, summary%fe_elements, summary%efg_particles, &
              summary%dofs_total, summary%dofs_efg, summary%fe_solids, summary%fe_shells, &
              summary%fe_beams, summary%failed_beams, summary%efg_shell_cells, summary%efg_shell_particles, &
              summary%dofs_efg_shell]
    do entry = 1, size(seconds)
      call write_real_attribute(group_id, "/timing", trim(second_names(entry)), seconds(entry), &
                                error)
    end do
    do entry = 1, size(counts)
      call write_integer_attribute(group_id, "/timing", trim(count_names(entry)), counts(entry), &
                                   error)
    end do
    ! the explicit cycle's phases (explicit_solver): where "other" time goes
    if (allocated(summary%phase_seconds)) then
      do entry = 1, size(summary%phase_seconds)
        call write_real_attribute(group_id, "/timing", "phase_"//trim(summary%phase_names(entry))//"_s", &
                                  summary%phase_seconds(entry), error)
      end do
    end if
    ! a distributed run: each rank's (row = rank), to see the balance; a run continued from a
    ! dump replaces those of the run before (on any number of ranks)
    do entry = 1, size(rank_datasets)
      call h5lexists_f(group_id, trim(rank_datasets(entry)), exists, status)
      if (status == 0 .and. exists) call h5ldelete_f(group_id, trim(rank_datasets(entry)), status)
    end do
    if (allocated(summary%rank_seconds)) then
      call write_real_dataset_2d(group_id, "/timing", "rank_seconds", summary%rank_seconds, error)
      call write_string_dataset(group_id, "rank_column_names", summary%rank_column_names, error)
    end if
    call write_long_attribute(group_id, "/timing", "output_bytes", results%output_bytes, error)
    call write_integer_attribute(group_id, "/timing", "xdmf_writes", results%xdmf_writes, error)
    call h5gclose_f(group_id, status)
  end subroutine write_timing

  ! ---------------------------------------------------------------------------------------------
  ! Small writers. Each closes the handles it opens, so a failure leaves nothing open.
  ! `parent_path` and `name` make the message ("" as `parent_path` when `name` is a full path).

  !> Create a contiguous dataset of `dims` and write `buffer` into it (nothing for size 0).
  !> With `objects` the dataset is left open and added to it (see open_objects_t).
  subroutine write_dataset(parent_id, parent_path, name, file_type, memory_type, dims, buffer, &
                           error, objects)
    integer(hid_t), intent(in) :: parent_id
    character(len=*), intent(in) :: parent_path, name
    integer(hid_t), intent(in) :: file_type, memory_type
    integer(hsize_t), intent(in) :: dims(:)
    type(c_ptr), intent(in) :: buffer
    type(error_t), allocatable, intent(inout) :: error
    type(open_objects_t), intent(inout), optional :: objects
    integer(hid_t) :: space_id, dataset_id
    integer :: status, ignored

    if (allocated(error)) return
    call h5screate_simple_f(size(dims), dims, space_id, status)
    if (status /= 0) then
      call make_error(error, "cannot create the dataspace of "//object_path(parent_path, name))
      return
    end if
    call h5dcreate_f(parent_id, name, file_type, space_id, dataset_id, status)
    call h5sclose_f(space_id, ignored)
    if (status /= 0) then
      call make_error(error, "cannot create dataset "//object_path(parent_path, name))
      return
    end if
    if (product(dims) > 0) then
      call h5dwrite_f(dataset_id, memory_type, buffer, status)
      if (status /= 0) call make_error(error, "cannot write dataset "// &
                                       object_path(parent_path, name))
    end if
    if (present(objects)) then
      call keep_open(objects, dataset_id)
    else
      call h5dclose_f(dataset_id, ignored)
    end if
  end subroutine write_dataset

  !> Reals `(rows)`.
  subroutine write_real_dataset_1d(parent_id, parent_path, name, values, error, objects)
    integer(hid_t), intent(in) :: parent_id
    character(len=*), intent(in) :: parent_path, name
    real(wp), intent(in), target, contiguous :: values(:)
    type(error_t), allocatable, intent(inout) :: error
    type(open_objects_t), intent(inout), optional :: objects
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call write_dataset(parent_id, parent_path, name, H5T_IEEE_F64LE, &
                       h5kind_to_type(wp, H5_REAL_KIND), [int(size(values), hsize_t)], buffer, &
                       error, objects)
  end subroutine write_real_dataset_1d

  !> Reals `(columns, rows)` in Fortran, stored as (rows, columns).
  subroutine write_real_dataset_2d(parent_id, parent_path, name, values, error, objects)
    integer(hid_t), intent(in) :: parent_id
    character(len=*), intent(in) :: parent_path, name
    real(wp), intent(in), target, contiguous :: values(:, :)
    type(error_t), allocatable, intent(inout) :: error
    type(open_objects_t), intent(inout), optional :: objects
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call write_dataset(parent_id, parent_path, name, H5T_IEEE_F64LE, &
                       h5kind_to_type(wp, H5_REAL_KIND), int(shape(values), hsize_t), buffer, error, &
                       objects)
  end subroutine write_real_dataset_2d

  !> Integers `(rows)`, stored as 32-bit.
  subroutine write_integer_dataset_1d(parent_id, parent_path, name, values, error)
    integer(hid_t), intent(in) :: parent_id
    character(len=*), intent(in) :: parent_path, name
    integer, intent(in), target, contiguous :: values(:)
    type(error_t), allocatable, intent(inout) :: error
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call write_dataset(parent_id, parent_path, name, H5T_STD_I32LE, H5T_NATIVE_INTEGER, &
                       [int(size(values), hsize_t)], buffer, error)
  end subroutine write_integer_dataset_1d

  !> Integers `(columns, rows)` in Fortran, stored as 32-bit (rows, columns).
  subroutine write_integer_dataset_2d(parent_id, parent_path, name, values, error)
    integer(hid_t), intent(in) :: parent_id
    character(len=*), intent(in) :: parent_path, name
    integer, intent(in), target, contiguous :: values(:, :)
    type(error_t), allocatable, intent(inout) :: error
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call write_dataset(parent_id, parent_path, name, H5T_STD_I32LE, H5T_NATIVE_INTEGER, &
                       int(shape(values), hsize_t), buffer, error)
  end subroutine write_integer_dataset_2d

  !> Strings `(rows)`, variable-length ASCII, each without its trailing blanks.
  subroutine write_string_dataset(parent_id, path, values, error)
    integer(hid_t), intent(in) :: parent_id
    character(len=*), intent(in) :: path
    character(len=*), intent(in) :: values(:)
    type(error_t), allocatable, intent(inout) :: error
    character(kind=c_char, len=1), allocatable, target :: characters(:)
    type(c_ptr), allocatable, target :: pointers(:)
    integer(hid_t) :: string_type
    integer :: row, start, length, status
    type(c_ptr) :: buffer

    if (allocated(error)) return
    ! The memory form of variable-length strings: one C pointer per string, here into one
    ! buffer holding every string followed by NUL.
    allocate (characters(sum(len_trim(values)) + size(values)), pointers(size(values)))
    start = 1
    do row = 1, size(values)
      length = len_trim(values(row))
      call copy_c_string(values(row)(1:length), characters(start:start + length))
      pointers(row) = c_loc(characters(start))
      start = start + length + 1
    end do
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(pointers)
    call h5tcopy_f(H5T_STRING, string_type, status)
    if (status /= 0) then
      call make_error(error, "cannot create the string type of "//path)
      return
    end if
    call write_dataset(parent_id, "", path, string_type, string_type, &
                       [int(size(values), hsize_t)], buffer, error)
    call h5tclose_f(string_type, status)
  end subroutine write_string_dataset

  !> Create (or replace) a scalar attribute of `object_id` and write `buffer` into it.
  subroutine write_attribute(object_id, object_path, name, file_type, memory_type, buffer, error)
    integer(hid_t), intent(in) :: object_id
    character(len=*), intent(in) :: object_path, name
    integer(hid_t), intent(in) :: file_type, memory_type
    type(c_ptr), intent(in) :: buffer
    type(error_t), allocatable, intent(inout) :: error
    integer(hid_t) :: space_id, attribute_id
    integer :: status, ignored
    logical :: exists

    if (allocated(error)) return
    ! Delete and recreate rather than overwrite: a string's length may change.
    call h5aexists_f(object_id, name, exists, status)
    if (status == 0 .and. exists) call h5adelete_f(object_id, name, status)
    if (status /= 0) then
      call make_error(error, "cannot replace attribute "//name//" of "//object_path)
      return
    end if
    call h5screate_f(H5S_SCALAR_F, space_id, status)
    if (status /= 0) then
      call make_error(error, "cannot create the dataspace of attribute "//name//" of "// &
                      object_path)
      return
    end if
    call h5acreate_f(object_id, name, file_type, space_id, attribute_id, status)
    call h5sclose_f(space_id, ignored)
    if (status /= 0) then
      call make_error(error, "cannot create attribute "//name//" of "//object_path)
      return
    end if
    call h5awrite_f(attribute_id, memory_type, buffer, status)
    if (status /= 0) call make_error(error, "cannot write attribute "//name//" of "//object_path)
    call h5aclose_f(attribute_id, ignored)
  end subroutine write_attribute

  !> A real scalar attribute, 64-bit.
  subroutine write_real_attribute(object_id, object_path, name, value, error)
    integer(hid_t), intent(in) :: object_id
    character(len=*), intent(in) :: object_path, name
    real(wp), intent(in) :: value
    type(error_t), allocatable, intent(inout) :: error
    real(wp), target :: stored
    stored = value
    call write_attribute(object_id, object_path, name, H5T_IEEE_F64LE, &
                         h5kind_to_type(wp, H5_REAL_KIND), c_loc(stored), error)
  end subroutine write_real_attribute

  !> An integer scalar attribute, stored as 64-bit (see the module comment).
  subroutine write_integer_attribute(object_id, object_path, name, value, error)
    integer(hid_t), intent(in) :: object_id
    character(len=*), intent(in) :: object_path, name
    integer, intent(in) :: value
    type(error_t), allocatable, intent(inout) :: error
    integer, target :: stored
    stored = value
    call write_attribute(object_id, object_path, name, H5T_STD_I64LE, H5T_NATIVE_INTEGER, &
                         c_loc(stored), error)
  end subroutine write_integer_attribute

  !> A 64-bit integer scalar attribute (byte counts).
  subroutine write_long_attribute(object_id, object_path, name, value, error)
    integer(hid_t), intent(in) :: object_id
    character(len=*), intent(in) :: object_path, name
    integer(long_int), intent(in) :: value
    type(error_t), allocatable, intent(inout) :: error
    integer(long_int), target :: stored
    stored = value
    call write_attribute(object_id, object_path, name, H5T_STD_I64LE, &
                         h5kind_to_type(long_int, H5_INTEGER_KIND), c_loc(stored), error)
  end subroutine write_long_attribute

  !> A string scalar attribute, variable-length ASCII.
  subroutine write_string_attribute(object_id, object_path, name, value, error)
    integer(hid_t), intent(in) :: object_id
    character(len=*), intent(in) :: object_path, name, value
    type(error_t), allocatable, intent(inout) :: error
    character(kind=c_char, len=1), allocatable, target :: characters(:)
    type(c_ptr), target :: pointer
    integer(hid_t) :: string_type
    integer :: status

    if (allocated(error)) return
    allocate (characters(len(value) + 1))
    call copy_c_string(value, characters)
    pointer = c_loc(characters)
    call h5tcopy_f(H5T_STRING, string_type, status)
    if (status /= 0) then
      call make_error(error, "cannot create the string type of attribute "//name)
      return
    end if
    call write_attribute(object_id, object_path, name, string_type, string_type, c_loc(pointer), &
                         error)
    call h5tclose_f(string_type, status)
  end subroutine write_string_attribute

  !> Create the groups of the absolute `path` that do not exist yet ("/history/matsum/3").
  subroutine create_group_path(file_id, path, error)
    integer(hid_t), intent(in) :: file_id
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(inout) :: error
    integer(hid_t) :: group_id
    integer :: position, status, ignored
    logical :: exists

    if (allocated(error)) return
    ! Prefix by prefix: asking HDF5 about "/a/b/c" when "/a/b" is missing is an error.
    do position = 2, len(path) + 1
      if (position <= len(path)) then
        if (path(position:position) /= "/") cycle
      end if
      call h5lexists_f(file_id, path(1:position - 1), exists, status)
      if (status /= 0) then
        call make_error(error, "cannot look up group "//path(1:position - 1))
        return
      end if
      if (exists) cycle
      call h5gcreate_f(file_id, path(1:position - 1), group_id, status)
      if (status /= 0) then
        call make_error(error, "cannot create group "//path(1:position - 1))
        return
      end if
      call h5gclose_f(group_id, ignored)
    end do
  end subroutine create_group_path

  !> Push everything written so far to the disk, so that readers find a consistent file.
  subroutine flush_file(file_id, error)
    integer(hid_t), intent(in) :: file_id
    type(error_t), allocatable, intent(inout) :: error
    integer :: status
    if (allocated(error)) return
    call h5fflush_f(file_id, H5F_SCOPE_GLOBAL_F, status)
    if (status /= 0) call make_error(error, "cannot flush the file")
  end subroutine flush_file

  !> `text` followed by NUL, into `characters` (of length len(text) + 1).
  pure subroutine copy_c_string(text, characters)
    character(len=*), intent(in) :: text
    character(kind=c_char, len=1), intent(out) :: characters(:)
    integer :: position
    do position = 1, len(text)
      characters(position) = text(position:position)
    end do
    characters(len(text) + 1) = c_null_char
  end subroutine copy_c_string

  !> The text, or "" when it was never set.
  pure function text_or_empty(text) result(copy)
    character(len=:), allocatable, intent(in) :: text
    character(len=:), allocatable :: copy
    copy = ""
    if (allocated(text)) copy = text
  end function text_or_empty

  !> "directory/name", or "name" alone for an empty directory.
  pure function join_path(directory, name) result(path)
    character(len=*), intent(in) :: directory, name
    character(len=:), allocatable :: path
    integer :: length
    length = len_trim(directory)
    if (length == 0) then
      path = name
    else if (directory(length:length) == "/") then
      path = directory(1:length)//name
    else
      path = directory(1:length)//"/"//name
    end if
  end function join_path

  !> The directory as the user gave it, "." for the current one, for messages.
  pure function directory_text(directory) result(text)
    character(len=*), intent(in) :: directory
    character(len=:), allocatable :: text
    text = trim(directory)
    if (len(text) == 0) text = "."
  end function directory_text

  !> Full path of an object, for messages.
  pure function object_path(parent_path, name) result(path)
    character(len=*), intent(in) :: parent_path, name
    character(len=:), allocatable :: path
    if (len(parent_path) == 0) then
      path = name
    else
      path = parent_path//"/"//name
    end if
  end function object_path

  pure function integer_text(value) result(text)
    integer, intent(in) :: value
    character(len=:), allocatable :: text
    character(len=24) :: buffer
    write (buffer, '(i0)') value
    text = trim(buffer)
  end function integer_text

  pure function real_text(value) result(text)
    real(wp), intent(in) :: value
    character(len=:), allocatable :: text
    character(len=32) :: buffer
    if (abs(value) < 1.0e100_wp .and. (abs(value) >= 1.0e-99_wp .or. value == 0.0_wp)) then
      write (buffer, '(es14.6)') value
    else
      write (buffer, '(es15.6e3)') value
    end if
    text = trim(adjustl(buffer))
  end function real_text

  !> The job's lock file DIR/JOBID.lock, or an error naming the run that holds it.
  subroutine lock_job(results, directory, job_id, error)
    type(results_file_t), intent(inout) :: results
    character(len=*), intent(in) :: directory, job_id
    type(error_t), allocatable, intent(out) :: error
    character(len=:), allocatable :: holder
    call acquire_file_lock(results%lock, join_path(directory, job_id//".lock"), error, holder)
    if (.not. allocated(error)) return
    if (len(holder) > 0) then
      error%message = "another run (process "//holder//") is writing job '"//job_id// &
                      "' in the output directory '"//directory_text(directory)// &
                      "' (lock file "//join_path(directory, job_id//".lock")// &
                      "); wait for it to end, or give this run another outdir= or jobid="
    else
      error%message = "results file "//results%h5_path//": "//error%message
    end if
  end subroutine lock_job
end module results_file
