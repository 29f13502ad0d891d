!> The results file `DIR/JOBID.h5` (layout: docs/contract.md; user reference: docs/output.md)
!> and its XDMF companion `DIR/JOBID.xdmf`.
!>
!> The solver calls `open_results` before the first cycle (mesh, and `/run` with status
!> "running"), `write_state` at each state time, `write_histories` at each state and at the
!> end, and `close_results` with the run summary, also after an error, so that the file always
!> says how the run ended. Every call ends with a flush: a run that dies leaves a readable file
!> holding everything written so far.
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
!>   node indices of each solid, which the XDMF topology needs; the `/run` attribute `title`.
!>
!> HDF5's automatic error printing is switched off: every failure becomes an `error_t` naming
!> the file and the operation. The file is opened without HDF5's file lock, so ParaView or a
!> script can read the states written so far while the run goes on.
module results_file
  use, intrinsic :: iso_c_binding, only: c_ptr, c_loc, c_null_ptr, c_char, c_null_char
  use hdf5, only: hid_t, hsize_t, h5open_f, h5eset_auto_f, &
                  h5fcreate_f, h5fclose_f, h5fflush_f, H5F_ACC_TRUNC_F, H5F_SCOPE_GLOBAL_F, &
                  h5pcreate_f, h5pclose_f, h5pset_file_locking_f, h5pset_chunk_f, &
                  H5P_FILE_ACCESS_F, H5P_DATASET_CREATE_F, &
                  h5gcreate_f, h5gopen_f, h5gclose_f, h5lexists_f, h5ldelete_f, &
                  h5screate_f, h5screate_simple_f, h5sclose_f, h5sget_simple_extent_ndims_f, &
                  h5sget_simple_extent_dims_f, H5S_SCALAR_F, H5S_UNLIMITED_F, &
                  h5dcreate_f, h5dopen_f, h5dclose_f, h5dwrite_f, h5dset_extent_f, &
                  h5dget_space_f, h5acreate_f, h5aclose_f, h5awrite_f, h5aexists_f, &
                  h5adelete_f, h5tcopy_f, h5tclose_f, H5T_STRING, H5T_NATIVE_INTEGER, &
                  H5T_STD_I32LE, H5T_STD_I64LE, H5T_IEEE_F64LE, h5kind_to_type, H5_REAL_KIND
  use kinds, only: wp
  use error_handling, only: error_t, make_error
  use version, only: crashfree_version
  use model, only: model_t, formulation_fe, formulation_efg, formulation_rigid
  use run_summary, only: run_summary_t, status_error
  use history_buffer, only: history_set_t
  use xdmf_writer, only: write_xdmf, state_group_name
  implicit none
  private

  public :: results_file_t, open_results, write_state, write_histories, close_results

  !> An open results file: the HDF5 handle, the paths, and what rewriting the XDMF needs.
  type :: results_file_t
    integer(hid_t) :: file_id = -1                !< HDF5 file handle while open
    logical :: is_open = .false.
    character(len=:), allocatable :: h5_path      !< DIR/JOBID.h5
    character(len=:), allocatable :: xdmf_path    !< DIR/JOBID.xdmf
    character(len=:), allocatable :: h5_name      !< JOBID.h5, as the XDMF refers to it
    integer :: node_count = 0                     !< n, rows of the nodal datasets
    integer :: solid_count = 0                    !< m, rows of the solid datasets
    integer :: shell_count = 0                    !< k, rows of the shell datasets
    integer :: state_count = 0                    !< states written so far
    real(wp), allocatable :: state_times(:)       !< time of each state written (with spare room)
  end type results_file_t

  !> Rows per chunk of the extendible history datasets: small enough for many short nodout
  !> series, large enough that a long glstat is not cut into thousands of pieces.
  integer(hsize_t), parameter :: history_chunk_rows = 256

contains

  !> Create `directory/job_id.h5` (replacing an earlier file) and write `/mesh` and `/run`
  !> (status "running"). The directory must exist.
  subroutine open_results(results, directory, job_id, model, threads, error)
    type(results_file_t), intent(inout) :: results
    character(len=*), intent(in) :: directory   !< output directory ("" for the current one)
    character(len=*), intent(in) :: job_id      !< base name of the files, e.g. "results"
    type(model_t), intent(in) :: model
    integer, intent(in) :: threads              !< OpenMP threads of the run
    type(error_t), allocatable, intent(out) :: error
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
    if (allocated(results%state_times)) deallocate (results%state_times)
    allocate (results%state_times(16))

    ! Initialising again is harmless. Without automatic printing HDF5 keeps its error stack
    ! to itself: failures reach the user once, through `error`.
    call h5open_f(status)
    if (status /= 0) then
      call make_error(error, "results file "//results%h5_path//": cannot initialise HDF5")
      return
    end if
    call h5eset_auto_f(0, status)

    ! No file lock, so that readers may open the file between two writes.
    call h5pcreate_f(H5P_FILE_ACCESS_F, access_list, status)
    if (status == 0) call h5pset_file_locking_f(access_list, .false., .true., status)
    if (status == 0) call h5fcreate_f(results%h5_path, H5F_ACC_TRUNC_F, results%file_id, status, &
                                      access_prp=access_list)
    call h5pclose_f(access_list, ignored)
    if (status /= 0) then
      call make_error(error, "results file "//results%h5_path// &
                      ": cannot create the file (does the directory exist and is it writable?)")
      results%file_id = -1
      return
    end if
    results%is_open = .true.

    call write_mesh(results%file_id, model, error)
    call write_run_start(results%file_id, model, threads, error)
    call create_group_path(results%file_id, "/states", error)
    call create_group_path(results%file_id, "/history", error)
    call flush_file(results%file_id, error)
    if (allocated(error)) then
      error%message = "results file "//results%h5_path//": "//error%message
      call h5fclose_f(results%file_id, ignored)
      results%is_open = .false.
      results%file_id = -1
    end if
  end subroutine open_results

  !> Write the next state `/states/NNNNNN`, flush, and rewrite the XDMF file.
  !> Shell results (global axes): `shell_stress` the mid-surface stress (mean over the
  !> through-thickness points), `shell_plastic_strain` its mean plastic strain, and, as crashfree
  !> extensions, `shell_stress_peak` / `shell_plastic_strain_peak` at the point with the largest
  !> von Mises stress / plastic strain. Without shell arguments the shell datasets are empty
  !> (a model without shells).
  subroutine write_state(results, time, displacement, velocity, solid_stress, &
                         solid_plastic_strain, error, shell_stress, shell_plastic_strain, shell_stress_peak, &
                         shell_plastic_strain_peak)
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
    real(wp) :: no_shell_stress(6, 0), no_shell_strain(0)
    real(wp), allocatable :: grown(:)
    character(len=:), allocatable :: path
    integer(hid_t) :: group_id
    integer :: status

    if (.not. results%is_open) then
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

    path = "/states/"//state_group_name(results%state_count + 1)
    call h5gcreate_f(results%file_id, path, group_id, status)
    if (status /= 0) then
      call make_error(error, "results file "//results%h5_path//": cannot create group "//path)
      return
    end if
    call write_real_attribute(group_id, path, "time", time, error)
    call write_real_dataset_2d(group_id, path, "displacement", displacement, error)
    call write_real_dataset_2d(group_id, path, "velocity", velocity, error)
    call write_real_dataset_2d(group_id, path, "solid_stress", solid_stress, error)
    call write_real_dataset_1d(group_id, path, "solid_plastic_strain", solid_plastic_strain, error)
    if (present(shell_stress)) then
      call write_real_dataset_2d(group_id, path, "shell_stress", shell_stress, error)
      call write_real_dataset_1d(group_id, path, "shell_plastic_strain", shell_plastic_strain, error)
      call write_real_dataset_2d(group_id, path, "shell_stress_peak", shell_stress_peak, error)
      call write_real_dataset_1d(group_id, path, "shell_plastic_strain_peak", shell_plastic_strain_peak, error)
    else
      call write_real_dataset_2d(group_id, path, "shell_stress", no_shell_stress, error)
      call write_real_dataset_1d(group_id, path, "shell_plastic_strain", no_shell_strain, error)
    end if
    call h5gclose_f(group_id, status)
    call flush_file(results%file_id, error)
    if (allocated(error)) then
      error%message = "results file "//results%h5_path//": "//error%message
      return
    end if

    if (results%state_count == size(results%state_times)) then
      allocate (grown(2*size(results%state_times)))
      grown(1:results%state_count) = results%state_times(1:results%state_count)
      call move_alloc(grown, results%state_times)
    end if
    results%state_count = results%state_count + 1
    results%state_times(results%state_count) = time

    call write_xdmf(results%xdmf_path, results%h5_name, results%node_count, results%solid_count, &
                    results%shell_count, results%state_times(1:results%state_count), error)
  end subroutine write_state

  !> Write every history series as `/history/<group>/<column>`, replacing what an earlier call
  !> wrote, and flush. The datasets are extendible and rewritten in place, so calling this at
  !> every state does not make the file grow beyond the histories' own size.
  subroutine write_histories(results, histories, error)
    type(results_file_t), intent(inout) :: results
    type(history_set_t), intent(in) :: histories
    type(error_t), allocatable, intent(out) :: error
    real(wp), allocatable :: column_values(:, :)
    character(len=:), allocatable :: path
    integer(hid_t) :: group_id
    integer :: series_index, column, first_row, last_row, status

    if (.not. results%is_open) then
      call make_error(error, "results file: write_histories on a file that is not open")
      return
    end if
    do series_index = 1, histories%count
      associate (series => histories%series(series_index))
        path = "/history/"//series%group
        call create_group_path(results%file_id, path, error)
        if (allocated(error)) exit
        call h5gopen_f(results%file_id, path, group_id, status)
        if (status /= 0) then
          call make_error(error, "cannot open group "//path)
          exit
        end if
        first_row = 1
        do column = 1, size(series%widths)
          ! A column is a strided slice of the rows: copy it to the contiguous form HDF5 takes.
          last_row = first_row + series%widths(column) - 1
          column_values = series%rows(first_row:last_row, 1:series%count)
          call write_history_column(group_id, path, trim(series%names(column)), column_values, &
                                    error)
          first_row = last_row + 1
        end do
        call h5gclose_f(group_id, status)
        if (allocated(error)) exit
      end associate
    end do
    call flush_file(results%file_id, error)
    if (allocated(error)) error%message = "results file "//results%h5_path//": "//error%message
  end subroutine write_histories

  !> Write how the run ended (`/run`) and its timing (`/timing`), and close the file.
  !> Does nothing when the file is not open (e.g. after `open_results` failed, or twice).
  subroutine close_results(results, summary, error)
    type(results_file_t), intent(inout) :: results
    type(run_summary_t), intent(in) :: summary
    type(error_t), allocatable, intent(out) :: error
    integer :: status

    if (.not. results%is_open) return
    call write_run_end(results%file_id, summary, error)
    call write_timing(results%file_id, summary, error)
    call flush_file(results%file_id, error)
    ! Close even after a failure: what is in the file stays readable.
    call h5fclose_f(results%file_id, status)
    if (status /= 0 .and. .not. allocated(error)) call make_error(error, "cannot close the file")
    results%is_open = .false.
    results%file_id = -1
    if (allocated(error)) error%message = "results file "//results%h5_path//": "//error%message
  end subroutine close_results

  ! ---------------------------------------------------------------------------------------------
  ! The groups of the layout. Like every private writer below, each does nothing once `error`
  ! is set, so a sequence of writes reads as a list and stops at the first failure.

  !> `/mesh`: nodes, solids, the (empty) shells, and parts.
  subroutine write_mesh(file_id, model, error)
    integer(hid_t), intent(in) :: file_id
    type(model_t), intent(in) :: model
    type(error_t), allocatable, intent(inout) :: error
    integer, allocatable :: node_ids(:), solid_ids(:), solid_part_ids(:), connectivity(:, :)
    integer, allocatable :: connectivity_index(:, :), part_ids(:), material_ids(:)
    real(wp), allocatable :: coordinates(:, :)
    character(len=8), allocatable :: formulations(:)
    integer, allocatable :: shell_ids(:), shell_part_ids(:), shell_connectivity(:, :)
    integer :: solid, part, solid_count, part_count, shell, shell_count

    if (allocated(error)) return
    ! Local copies, so that a model without nodes, solids or parts still gives the full layout.
    if (allocated(model%node_ids)) then
      node_ids = model%node_ids
      coordinates = model%coordinates
    else
      allocate (node_ids(0), coordinates(3, 0))
    end if
    solid_count = 0
    if (allocated(model%solid_ids)) solid_count = size(model%solid_ids)
    allocate (solid_ids(solid_count), solid_part_ids(solid_count), connectivity(8, solid_count), &
              connectivity_index(8, solid_count))
    do solid = 1, solid_count
      solid_ids(solid) = model%solid_ids(solid)
      solid_part_ids(solid) = model%parts(model%solid_part(solid))%id
      connectivity(:, solid) = model%node_ids(model%solid_nodes(:, solid))
      connectivity_index(:, solid) = model%solid_nodes(:, solid) - 1
    end do
    shell_count = 0
    if (allocated(model%shell_ids)) shell_count = size(model%shell_ids)
    allocate (shell_ids(shell_count), shell_part_ids(shell_count), shell_connectivity(4, shell_count))
    do shell = 1, shell_count
      shell_ids(shell) = model%shell_ids(shell)
      shell_part_ids(shell) = model%parts(model%shell_part(shell))%id
      shell_connectivity(:, shell) = model%node_ids(model%shell_nodes(:, shell))
    end do
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

    call create_group_path(file_id, "/mesh/nodes", error)
    call create_group_path(file_id, "/mesh/solids", error)
    call create_group_path(file_id, "/mesh/shells", error)
    call create_group_path(file_id, "/mesh/parts", error)
    call write_integer_dataset_1d(file_id, "", "/mesh/nodes/ids", node_ids, error)
    call write_real_dataset_2d(file_id, "", "/mesh/nodes/coordinates", coordinates, error)
    call write_integer_dataset_1d(file_id, "", "/mesh/solids/ids", solid_ids, error)
    call write_integer_dataset_1d(file_id, "", "/mesh/solids/part_ids", solid_part_ids, error)
    call write_integer_dataset_2d(file_id, "", "/mesh/solids/connectivity", connectivity, error)
    call write_integer_dataset_2d(file_id, "", "/mesh/solids/connectivity_index", &
                                  connectivity_index, error)
    call write_integer_dataset_1d(file_id, "", "/mesh/shells/ids", shell_ids, error)
    call write_integer_dataset_1d(file_id, "", "/mesh/shells/part_ids", shell_part_ids, error)
    call write_integer_dataset_2d(file_id, "", "/mesh/shells/connectivity", shell_connectivity, error)
    call write_integer_dataset_2d(file_id, "", "/mesh/shells/connectivity_index", shell_connectivity_index(), error)
    call write_integer_dataset_1d(file_id, "", "/mesh/parts/ids", part_ids, error)
    call write_string_dataset(file_id, "/mesh/parts/formulation", formulations, error)
    call write_integer_dataset_1d(file_id, "", "/mesh/parts/material_ids", material_ids, error)
  contains
    !> 0-based node rows of the shells (as connectivity_index of the solids, for the XDMF file).
    function shell_connectivity_index() result(rows)
      integer, allocatable :: rows(:, :)
      allocate (rows(4, shell_count))
      do shell = 1, shell_count
        rows(:, shell) = model%shell_nodes(:, shell) - 1
      end do
    end function shell_connectivity_index
  end subroutine write_mesh

  !> `/run` at the start. Every attribute of the contract is there from the start; the status
  !> is "running" until `close_results`, so a file left by a killed process says so.
  subroutine write_run_start(file_id, model, threads, error)
    integer(hid_t), intent(in) :: file_id
    type(model_t), intent(in) :: model
    integer, intent(in) :: threads
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
  end subroutine write_run_end

  !> `/timing`: seconds per phase, and the sizes that normalise them.
  subroutine write_timing(file_id, summary, error)
    integer(hid_t), intent(in) :: file_id
    type(run_summary_t), intent(in) :: summary
    type(error_t), allocatable, intent(inout) :: error
    character(len=*), parameter :: second_names(8) = [character(len=11) :: "wall_s", &
      "fe_solid_s", "fe_shell_s", "efg_s", "contact_s", "output_s", "setup_s", "efg_setup_s"]
    character(len=*), parameter :: count_names(8) = [character(len=13) :: "cycles", "threads", &
      "fe_elements", "efg_particles", "dofs_total", "dofs_efg", "fe_solids", "fe_shells"]
    real(wp) :: seconds(8)
    integer :: counts(8), entry, status
    integer(hid_t) :: group_id

    call create_group_path(file_id, "/timing", error)
    if (allocated(error)) return
    call h5gopen_f(file_id, "/timing", group_id, status)
    if (status /= 0) then
      call make_error(error, "cannot open group /timing")
      return
    end if
    seconds = [summary%wall_s, summary%fe_solid_s, summary%fe_shell_s, summary%efg_s, &
               summary%contact_s, summary%output_s, summary%setup_s, summary%efg_setup_s]
    counts = [summary%cycles, summary%threads, summary%fe_elements, summary%efg_particles, &
              summary%dofs_total, summary%dofs_efg, summary%fe_solids, summary%fe_shells]
    do entry = 1, size(seconds)
      call write_real_attribute(group_id, "/timing", trim(second_names(entry)), seconds(entry), &
                                error)
    end do
    do entry = 1, size(counts)
      call write_integer_attribute(group_id, "/timing", trim(count_names(entry)), counts(entry), &
                                   error)
    end do
    call h5gclose_f(group_id, status)
  end subroutine write_timing

  !> One history column `values(width, rows)`, stored as (rows) for width 1 and (rows, width)
  !> otherwise, in a chunked dataset extendible in rows. An existing dataset of the same width
  !> is resized and overwritten in place; one of another width is replaced.
  subroutine write_history_column(group_id, group_path, name, values, error)
    integer(hid_t), intent(in) :: group_id
    character(len=*), intent(in) :: group_path, name
    real(wp), intent(in), target, contiguous :: values(:, :)
    type(error_t), allocatable, intent(inout) :: error
    integer(hsize_t), allocatable :: dims(:), maximum_dims(:), chunk(:)
    integer(hsize_t) :: old_dims(2), old_maximum(2)
    integer(hid_t) :: dataset_id, space_id, create_list
    integer :: status, rank, old_rank, ignored
    logical :: exists, reusable
    type(c_ptr) :: buffer

    if (allocated(error)) return
    if (size(values, 1) == 1) then
      dims = [int(size(values, 2), hsize_t)]
      maximum_dims = [H5S_UNLIMITED_F]
      chunk = [history_chunk_rows]
    else
      dims = int(shape(values), hsize_t)
      maximum_dims = [dims(1), H5S_UNLIMITED_F]
      chunk = [dims(1), history_chunk_rows]
    end if
    rank = size(dims)

    call h5lexists_f(group_id, name, exists, status)
    if (status /= 0) then
      call make_error(error, "cannot look up dataset "//group_path//"/"//name)
      return
    end if
    reusable = .false.
    if (exists) then
      call h5dopen_f(group_id, name, dataset_id, status)
      if (status /= 0) then
        call make_error(error, "cannot open dataset "//group_path//"/"//name)
        return
      end if
      call h5dget_space_f(dataset_id, space_id, status)
      if (status == 0) call h5sget_simple_extent_ndims_f(space_id, old_rank, status)
      if (status == 0 .and. old_rank == rank) then
        ! On success this returns the rank in `status`.
        call h5sget_simple_extent_dims_f(space_id, old_dims, old_maximum, status)
        reusable = status == rank .and. old_maximum(rank) == H5S_UNLIMITED_F
        if (rank == 2) reusable = reusable .and. old_dims(1) == dims(1)
      end if
      call h5sclose_f(space_id, ignored)
      if (reusable) then
        call h5dset_extent_f(dataset_id, dims, status)
        if (status /= 0) then
          call h5dclose_f(dataset_id, ignored)
          call make_error(error, "cannot resize dataset "//group_path//"/"//name)
          return
        end if
      else
        call h5dclose_f(dataset_id, ignored)
        call h5ldelete_f(group_id, name, status)
        if (status /= 0) then
          call make_error(error, "cannot replace dataset "//group_path//"/"//name)
          return
        end if
      end if
    end if

    if (.not. reusable) then
      call h5screate_simple_f(rank, dims, space_id, status, maximum_dims)
      if (status /= 0) then
        call make_error(error, "cannot create the dataspace of "//group_path//"/"//name)
        return
      end if
      call h5pcreate_f(H5P_DATASET_CREATE_F, create_list, status)
      if (status == 0) call h5pset_chunk_f(create_list, rank, chunk, status)
      if (status == 0) call h5dcreate_f(group_id, name, H5T_IEEE_F64LE, space_id, dataset_id, &
                                        status, dcpl_id=create_list)
      call h5pclose_f(create_list, ignored)
      call h5sclose_f(space_id, ignored)
      if (status /= 0) then
        call make_error(error, "cannot create dataset "//group_path//"/"//name)
        return
      end if
    end if

    if (size(values) > 0) then
      buffer = c_loc(values)
      call h5dwrite_f(dataset_id, h5kind_to_type(wp, H5_REAL_KIND), buffer, status)
      if (status /= 0) call make_error(error, "cannot write dataset "//group_path//"/"//name)
    end if
    call h5dclose_f(dataset_id, ignored)
  end subroutine write_history_column

  ! ---------------------------------------------------------------------------------------------
  ! Small writers. Each closes the handles it opens, so a failure leaves nothing open.
  ! `parent_path` and `name` make the message ("" as `parent_path` when `name` is a full path).

  !> Create a contiguous dataset of `dims` and write `buffer` into it (nothing for size 0).
  subroutine write_dataset(parent_id, parent_path, name, file_type, memory_type, dims, buffer, &
                           error)
    integer(hid_t), intent(in) :: parent_id
    character(len=*), intent(in) :: parent_path, name
    integer(hid_t), intent(in) :: file_type, memory_type
    integer(hsize_t), intent(in) :: dims(:)
    type(c_ptr), intent(in) :: buffer
    type(error_t), allocatable, intent(inout) :: error
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
    call h5dclose_f(dataset_id, ignored)
  end subroutine write_dataset

  !> Reals `(rows)`.
  subroutine write_real_dataset_1d(parent_id, parent_path, name, values, error)
    integer(hid_t), intent(in) :: parent_id
    character(len=*), intent(in) :: parent_path, name
    real(wp), intent(in), target, contiguous :: values(:)
    type(error_t), allocatable, intent(inout) :: error
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call write_dataset(parent_id, parent_path, name, H5T_IEEE_F64LE, &
                       h5kind_to_type(wp, H5_REAL_KIND), [int(size(values), hsize_t)], buffer, &
                       error)
  end subroutine write_real_dataset_1d

  !> Reals `(columns, rows)` in Fortran, stored as (rows, columns).
  subroutine write_real_dataset_2d(parent_id, parent_path, name, values, error)
    integer(hid_t), intent(in) :: parent_id
    character(len=*), intent(in) :: parent_path, name
    real(wp), intent(in), target, contiguous :: values(:, :)
    type(error_t), allocatable, intent(inout) :: error
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call write_dataset(parent_id, parent_path, name, H5T_IEEE_F64LE, &
                       h5kind_to_type(wp, H5_REAL_KIND), int(shape(values), hsize_t), buffer, error)
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
    write (buffer, '(es15.7e3)') value
    text = trim(adjustl(buffer))
  end function real_text
end module results_file
