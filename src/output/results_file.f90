!> The results file `DIR/JOBID.h5` (layout: docs/contract.md, user reference: docs/output.md)
!> and its XDMF companion `DIR/JOBID.xdmf`.
!>
!> Usage by the solver: `open_results` before the first cycle (writes the mesh and `/run` with
!> status "running"), `write_state` at each state time, `write_histories` at each state and at
!> the end, `close_results` with the run summary (also after an error, so the file always says
!> how the run ended). Everything is flushed after each call, so a run that dies still leaves a
!> readable file holding what was written so far.
!>
!> Conventions of the file:
!> - Fortran arrays `(3, n)` are stored with HDF5 dimensions `(n, 3)`, which is how h5py and
!>   every C-ordered reader see them: one row per node, columns x, y, z.
!> - Reals are IEEE 64-bit little endian. Ids and connectivities are 32-bit integers; counts
!>   in attributes (`cycles`, `threads`, `fe_elements`, ...) are 64-bit, so products such as
!>   elements x cycles do not overflow in a reader's integer arithmetic.
!> - Strings (attributes and the `formulation` dataset) are variable-length ASCII, which h5py
!>   returns as `str` for attributes (`.asstr()` for datasets).
!> - Extension of the contract layout: `/mesh/solids/connectivity_index` (m,8), the 0-based
!>   node indices of each solid, which the XDMF topology needs; `/run` attribute `title`.
!>
!> HDF5's own error printing is switched off: every failure becomes an `error_t` naming the file
!> and the operation. The writer opens the file without HDF5's file lock, so that ParaView or a
!> script can read the states written so far while the run goes on.
module results_file
  use, intrinsic :: iso_c_binding, only: c_ptr, c_loc, c_null_ptr, c_char, c_null_char
  use hdf5, only: hid_t, hsize_t, h5open_f, h5eset_auto_f, &
                  h5fcreate_f, h5fclose_f, h5fflush_f, H5F_ACC_TRUNC_F, H5F_SCOPE_GLOBAL_F, &
                  h5pcreate_f, h5pclose_f, h5pset_file_locking_f, h5pset_chunk_f, &
                  H5P_FILE_ACCESS_F, H5P_DATASET_CREATE_F, H5P_DEFAULT_F, &
                  h5gcreate_f, h5gopen_f, h5gclose_f, h5lexists_f, h5ldelete_f, &
                  h5screate_f, h5screate_simple_f, h5sclose_f, h5sget_simple_extent_ndims_f, &
                  h5sget_simple_extent_dims_f, H5S_SCALAR_F, H5S_UNLIMITED_F, &
                  h5dcreate_f, h5dopen_f, h5dclose_f, h5dwrite_f, h5dset_extent_f, h5dget_space_f, &
                  h5acreate_f, h5aclose_f, h5awrite_f, h5aexists_f, h5adelete_f, &
                  h5tcopy_f, h5tclose_f, H5T_STRING, H5T_NATIVE_INTEGER, H5T_STD_I32LE, &
                  H5T_STD_I64LE, H5T_IEEE_F64LE, h5kind_to_type, H5_REAL_KIND
  use kinds, only: wp
  use error_handling, only: error_t, make_error
  use version, only: crashfree_version
  use model, only: model_t, formulation_fe, formulation_efg, formulation_rigid
  use run_summary, only: run_summary_t
  use history_buffer, only: history_set_t
  use xdmf_writer, only: write_xdmf, state_group_name
  implicit none
  private

  public :: results_file_t, open_results, write_state, write_histories, close_results

  !> An open results file: HDF5 handle, paths, and what the XDMF needs to be rewritten.
  type :: results_file_t
    integer(hid_t) :: file_id = -1                    !< HDF5 file handle while open
    logical :: is_open = .false.
    character(len=:), allocatable :: h5_path          !< DIR/JOBID.h5
    character(len=:), allocatable :: xdmf_path        !< DIR/JOBID.xdmf
    character(len=:), allocatable :: h5_name          !< JOBID.h5, as the XDMF refers to it
    integer :: node_count = 0                         !< n, rows of the nodal datasets
    integer :: solid_count = 0                        !< m, rows of the solid datasets
    integer :: state_count = 0                        !< states written so far
    real(wp), allocatable :: state_times(:)           !< (capacity) time of each state written
  end type results_file_t

  !> Rows per chunk of the extendible history datasets: small enough for many short nodout
  !> series, large enough that a long glstat is not split into thousands of pieces.
  integer(hsize_t), parameter :: history_chunk_rows = 256

contains

  !> Create `directory/job_id.h5` (replacing any earlier file) and write `/mesh` and `/run`
  !> (status "running"). The directory must exist.
  subroutine open_results(results, directory, job_id, model, threads, error)
    type(results_file_t), intent(inout) :: results
    character(len=*), intent(in) :: directory   !< output directory ("" or "." for the current one)
    character(len=*), intent(in) :: job_id      !< base name of the files, e.g. "results"
    type(model_t), intent(in) :: model
    integer, intent(in) :: threads              !< OpenMP threads of the run
    type(error_t), allocatable, intent(out) :: error
    integer(hid_t) :: access_list
    integer :: status

    if (results%is_open) then
      call make_error(error, "results file "//results%h5_path//": is already open")
      return
    end if
    results%h5_name = job_id//".h5"
    results%h5_path = join_path(directory, results%h5_name)
    results%xdmf_path = join_path(directory, job_id//".xdmf")
    results%node_count = 0
    if (allocated(model%node_ids)) results%node_count = size(model%node_ids)
    results%solid_count = 0
    if (allocated(model%solid_ids)) results%solid_count = size(model%solid_ids)
    results%state_count = 0
    if (allocated(results%state_times)) deallocate (results%state_times)
    allocate (results%state_times(16))

    ! Initialising twice is harmless; turning off the automatic error printing is what keeps
    ! HDF5 from printing its error stack: failures are reported through `error` instead.
    call h5open_f(status)
    if (status /= 0) then
      call make_error(error, "results file "//results%h5_path//": cannot initialise HDF5")
      return
    end if
    call h5eset_auto_f(0, status)

    ! No file lock: readers (ParaView, h5py) may open the file between two writes.
    call h5pcreate_f(H5P_FILE_ACCESS_F, access_list, status)
    if (status == 0) call h5pset_file_locking_f(access_list, .false., .true., status)
    if (status /= 0) then
      call make_error(error, "results file "//results%h5_path//": cannot set the file access")
      return
    end if
    call h5fcreate_f(results%h5_path, H5F_ACC_TRUNC_F, results%file_id, status, &
                     access_prp=access_list)
    call h5pclose_f(access_list, status)
    if (results%file_id < 0) then
      call make_error(error, "results file "//results%h5_path// &
                      ": cannot create the file (does the directory exist and is it writable?)")
      return
    end if
    results%is_open = .true.

    call write_mesh(results%file_id, model, error)
    if (.not. allocated(error)) call write_run_start(results%file_id, model, threads, error)
    if (.not. allocated(error)) call create_group_path(results%file_id, "/states", error)
    if (.not. allocated(error)) call create_group_path(results%file_id, "/history", error)
    if (.not. allocated(error)) call flush_file(results%file_id, error)
    if (allocated(error)) then
      error%message = "results file "//results%h5_path//": "//error%message
      call h5fclose_f(results%file_id, status)
      results%is_open = .false.
      results%file_id = -1
    end if
  end subroutine open_results

  !> Write one state `/states/NNNNNN`, flush, and rewrite the XDMF file.
  subroutine write_state(results, time, displacement, velocity, solid_stress, solid_plastic_strain, &
                         error)
    type(results_file_t), intent(inout) :: results
    real(wp), intent(in) :: time
    ! Contiguous: the solver's whole arrays go to HDF5 without a copy.
    real(wp), intent(in), contiguous :: displacement(:, :)       !< (3, nodes)
    real(wp), intent(in), contiguous :: velocity(:, :)           !< (3, nodes)
    real(wp), intent(in), contiguous :: solid_stress(:, :)       !< (6, solids): xx, yy, zz, xy, yz, zx
    real(wp), intent(in), contiguous :: solid_plastic_strain(:)  !< (solids)
    type(error_t), allocatable, intent(out) :: error
    real(wp) :: no_shell_stress(6, 0), no_shell_strain(0)
    real(wp), allocatable :: grown(:)
    character(len=:), allocatable :: state_path
    integer(hid_t) :: group_id
    integer :: status

    if (.not. results%is_open) then
      call make_error(error, "results file: write_state called on a file that is not open")
      return
    end if
    if (any(shape(displacement) /= [3, results%node_count]) .or. &
        any(shape(velocity) /= [3, results%node_count]) .or. &
        any(shape(solid_stress) /= [6, results%solid_count]) .or. &
        size(solid_plastic_strain) /= results%solid_count) then
      call make_error(error, "results file "//results%h5_path//": state at time "// &
                      real_text(time)//": array sizes do not match the mesh ("// &
                      integer_text(results%node_count)//" nodes, "// &
                      integer_text(results%solid_count)//" solids)")
      return
    end if

    state_path = "/states/"//state_group_name(results%state_count + 1)
    call h5gcreate_f(results%file_id, state_path, group_id, status)
    if (status /= 0) then
      call make_error(error, "results file "//results%h5_path//": cannot create group "//state_path)
      return
    end if
    call write_real_attribute(group_id, state_path, "time", time, error)
    if (.not. allocated(error)) call write_real_dataset_2d(group_id, state_path, "displacement", &
                                                           displacement, error)
    if (.not. allocated(error)) call write_real_dataset_2d(group_id, state_path, "velocity", &
                                                           velocity, error)
    if (.not. allocated(error)) call write_real_dataset_2d(group_id, state_path, "solid_stress", &
                                                           solid_stress, error)
    if (.not. allocated(error)) call write_real_dataset_1d(group_id, state_path, &
                                                           "solid_plastic_strain", &
                                                           solid_plastic_strain, error)
    ! Shells are not modelled yet; the empty datasets keep the layout of the contract.
    if (.not. allocated(error)) call write_real_dataset_2d(group_id, state_path, "shell_stress", &
                                                           no_shell_stress, error)
    if (.not. allocated(error)) call write_real_dataset_1d(group_id, state_path, &
                                                           "shell_plastic_strain", &
                                                           no_shell_strain, error)
    call h5gclose_f(group_id, status)
    if (.not. allocated(error)) call flush_file(results%file_id, error)
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
                    results%state_times(1:results%state_count), error)
  end subroutine write_state

  !> Write every history series as `/history/<group>/<column>`, replacing what an earlier call
  !> wrote (the datasets are extendible, so repeated calls reuse their space), and flush.
  subroutine write_histories(results, histories, error)
    type(results_file_t), intent(inout) :: results
    type(history_set_t), intent(in) :: histories
    type(error_t), allocatable, intent(out) :: error
    integer(hid_t) :: group_id
    integer :: series_index, column, first_row, last_row, status
    character(len=:), allocatable :: group_path
    real(wp), allocatable :: column_values(:, :)

    if (.not. results%is_open) then
      call make_error(error, "results file: write_histories called on a file that is not open")
      return
    end if
    do series_index = 1, histories%count
      associate (series => histories%series(series_index))
        group_path = "/history/"//series%group
        call create_group_path(results%file_id, group_path, error)
        if (allocated(error)) exit
        call h5gopen_f(results%file_id, group_path, group_id, status)
        if (status /= 0) then
          call make_error(error, "cannot open group "//group_path)
          exit
        end if
        first_row = 1
        do column = 1, size(series%widths)
          ! A column is a strided slice of the rows: copy it into the contiguous form HDF5 writes.
          last_row = first_row + series%widths(column) - 1
          column_values = series%rows(first_row:last_row, 1:series%count)
          call write_history_column(group_id, group_path, trim(series%names(column)), &
                                    column_values, error)
          if (allocated(error)) exit
          first_row = last_row + 1
        end do
        call h5gclose_f(group_id, status)
        if (allocated(error)) exit
      end associate
    end do
    if (.not. allocated(error)) call flush_file(results%file_id, error)
    if (allocated(error)) error%message = "results file "//results%h5_path//": "//error%message
  end subroutine write_histories

  !> Write the run's outcome (`/run`) and timing (`/timing`) and close the file.
  !> Does nothing when the file is not open (e.g. `open_results` failed).
  subroutine close_results(results, summary, error)
    type(results_file_t), intent(inout) :: results
    type(run_summary_t), intent(in) :: summary
    type(error_t), allocatable, intent(out) :: error
    integer :: status

    if (.not. results%is_open) return
    call write_run_end(results%file_id, summary, error)
    if (.not. allocated(error)) call write_timing(results%file_id, summary, error)
    if (.not. allocated(error)) call flush_file(results%file_id, error)
    ! Close even after a failure: what is in the file stays readable.
    call h5fclose_f(results%file_id, status)
    if (status /= 0 .and. .not. allocated(error)) call make_error(error, "cannot close the file")
    results%is_open = .false.
    results%file_id = -1
    if (allocated(error)) error%message = "results file "//results%h5_path//": "//error%message
  end subroutine close_results

  ! ---------------------------------------------------------------------------------------------
  ! Layout

  !> `/mesh`: nodes, solids, (empty) shells and parts.
  subroutine write_mesh(file_id, model, error)
    integer(hid_t), intent(in) :: file_id
    type(model_t), intent(in) :: model
    type(error_t), allocatable, intent(out) :: error
    integer, allocatable :: node_ids(:), solid_ids(:), solid_part_ids(:), connectivity(:, :)
    integer, allocatable :: connectivity_index(:, :), part_ids(:), material_ids(:)
    real(wp), allocatable :: coordinates(:, :)
    character(len=8), allocatable :: formulations(:)
    integer :: no_shell_ids(0), no_shell_connectivity(4, 0)
    integer :: solid, part, solid_count, part_count

    ! Local copies so that a model without solids (or nodes) still gives the full layout.
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
        call make_error(error, "part "//integer_text(part_ids(part))// &
                        ": unknown formulation code "// &
                        integer_text(model%parts(part)%formulation))
        return
      end select
    end do

    call create_group_path(file_id, "/mesh/nodes", error)
    if (.not. allocated(error)) call create_group_path(file_id, "/mesh/solids", error)
    if (.not. allocated(error)) call create_group_path(file_id, "/mesh/shells", error)
    if (.not. allocated(error)) call create_group_path(file_id, "/mesh/parts", error)
    if (.not. allocated(error)) call write_integer_dataset_1d(file_id, "", "/mesh/nodes/ids", &
                                                              node_ids, error)
    if (.not. allocated(error)) call write_real_dataset_2d(file_id, "", "/mesh/nodes/coordinates", &
                                                           coordinates, error)
    if (.not. allocated(error)) call write_integer_dataset_1d(file_id, "", "/mesh/solids/ids", &
                                                              solid_ids, error)
    if (.not. allocated(error)) call write_integer_dataset_1d(file_id, "", "/mesh/solids/part_ids", &
                                                              solid_part_ids, error)
    if (.not. allocated(error)) call write_integer_dataset_2d(file_id, "", &
                                                              "/mesh/solids/connectivity", &
                                                              connectivity, error)
    if (.not. allocated(error)) call write_integer_dataset_2d(file_id, "", &
                                                              "/mesh/solids/connectivity_index", &
                                                              connectivity_index, error)
    if (.not. allocated(error)) call write_integer_dataset_1d(file_id, "", "/mesh/shells/ids", &
                                                              no_shell_ids, error)
    if (.not. allocated(error)) call write_integer_dataset_1d(file_id, "", "/mesh/shells/part_ids", &
                                                              no_shell_ids, error)
    if (.not. allocated(error)) call write_integer_dataset_2d(file_id, "", &
                                                              "/mesh/shells/connectivity", &
                                                              no_shell_connectivity, error)
    if (.not. allocated(error)) call write_integer_dataset_1d(file_id, "", "/mesh/parts/ids", &
                                                              part_ids, error)
    if (.not. allocated(error)) call write_string_dataset(file_id, "/mesh/parts/formulation", &
                                                          formulations, error)
    if (.not. allocated(error)) call write_integer_dataset_1d(file_id, "", &
                                                              "/mesh/parts/material_ids", &
                                                              material_ids, error)
  end subroutine write_mesh

  !> `/run` at the start: the outcome is "running" until `close_results` writes it, so a
  !> file left by a killed process says so. All contract attributes are present from here on.
  subroutine write_run_start(file_id, model, threads, error)
    integer(hid_t), intent(in) :: file_id
    type(model_t), intent(in) :: model
    integer, intent(in) :: threads
    type(error_t), allocatable, intent(out) :: error
    integer(hid_t) :: group_id
    integer :: status

    call h5gcreate_f(file_id, "/run", group_id, status)
    if (status /= 0) then
      call make_error(error, "cannot create group /run")
      return
    end if
    call write_string_attribute(group_id, "/run", "version", crashfree_version, error)
    if (.not. allocated(error)) then
      if (allocated(model%deck_path)) then
        call write_string_attribute(group_id, "/run", "deck", model%deck_path, error)
      else
        call write_string_attribute(group_id, "/run", "deck", "", error)
      end if
    end if
    if (.not. allocated(error)) then
      if (allocated(model%title)) then
        call write_string_attribute(group_id, "/run", "title", model%title, error)
      else
        call write_string_attribute(group_id, "/run", "title", "", error)
      end if
    end if
    if (.not. allocated(error)) call write_string_attribute(group_id, "/run", "status", "running", &
                                                            error)
    if (.not. allocated(error)) call write_string_attribute(group_id, "/run", "message", "", error)
    if (.not. allocated(error)) call write_real_attribute(group_id, "/run", "end_time", 0.0_wp, &
                                                          error)
    if (.not. allocated(error)) call write_integer_attribute(group_id, "/run", "cycles", 0, error)
    if (.not. allocated(error)) call write_integer_attribute(group_id, "/run", "threads", threads, &
                                                             error)
    call h5gclose_f(group_id, status)
  end subroutine write_run_start

  !> `/run` at the end: outcome, end time, cycles, threads (version and deck stay).
  subroutine write_run_end(file_id, summary, error)
    integer(hid_t), intent(in) :: file_id
    type(run_summary_t), intent(in) :: summary
    type(error_t), allocatable, intent(out) :: error
    integer(hid_t) :: group_id
    integer :: status

    call h5gopen_f(file_id, "/run", group_id, status)
    if (status /= 0) then
      call make_error(error, "cannot open group /run")
      return
    end if
    ! A summary without a status did not reach a normal end: never claim one for it.
    if (allocated(summary%status)) then
      call write_string_attribute(group_id, "/run", "status", summary%status, error)
    else
      call write_string_attribute(group_id, "/run", "status", "error termination", error)
    end if
    if (.not. allocated(error)) then
      if (allocated(summary%message)) then
        call write_string_attribute(group_id, "/run", "message", summary%message, error)
      else
        call write_string_attribute(group_id, "/run", "message", "", error)
      end if
    end if
    if (.not. allocated(error)) call write_real_attribute(group_id, "/run", "end_time", &
                                                          summary%end_time, error)
    if (.not. allocated(error)) call write_integer_attribute(group_id, "/run", "cycles", &
                                                             summary%cycles, error)
    if (.not. allocated(error)) call write_integer_attribute(group_id, "/run", "threads", &
                                                             summary%threads, error)
    call h5gclose_f(group_id, status)
  end subroutine write_run_end

  !> `/timing`: seconds per phase and the sizes needed to normalise them.
  subroutine write_timing(file_id, summary, error)
    integer(hid_t), intent(in) :: file_id
    type(run_summary_t), intent(in) :: summary
    type(error_t), allocatable, intent(out) :: error
    integer(hid_t) :: group_id
    integer :: status

    call create_group_path(file_id, "/timing", error)
    if (allocated(error)) return
    call h5gopen_f(file_id, "/timing", group_id, status)
    if (status /= 0) then
      call make_error(error, "cannot open group /timing")
      return
    end if
    call write_real_attribute(group_id, "/timing", "wall_s", summary%wall_s, error)
    if (.not. allocated(error)) call write_integer_attribute(group_id, "/timing", "cycles", &
                                                             summary%cycles, error)
    if (.not. allocated(error)) call write_integer_attribute(group_id, "/timing", "threads", &
                                                             summary%threads, error)
    if (.not. allocated(error)) call write_real_attribute(group_id, "/timing", "fe_solid_s", &
                                                          summary%fe_solid_s, error)
    if (.not. allocated(error)) call write_real_attribute(group_id, "/timing", "fe_shell_s", &
                                                          summary%fe_shell_s, error)
    if (.not. allocated(error)) call write_real_attribute(group_id, "/timing", "efg_s", &
                                                          summary%efg_s, error)
    if (.not. allocated(error)) call write_real_attribute(group_id, "/timing", "contact_s", &
                                                          summary%contact_s, error)
    if (.not. allocated(error)) call write_real_attribute(group_id, "/timing", "output_s", &
                                                          summary%output_s, error)
    if (.not. allocated(error)) call write_real_attribute(group_id, "/timing", "setup_s", &
                                                          summary%setup_s, error)
    if (.not. allocated(error)) call write_integer_attribute(group_id, "/timing", "fe_elements", &
                                                             summary%fe_elements, error)
    if (.not. allocated(error)) call write_integer_attribute(group_id, "/timing", "efg_particles", &
                                                             summary%efg_particles, error)
    if (.not. allocated(error)) call write_integer_attribute(group_id, "/timing", "dofs_total", &
                                                             summary%dofs_total, error)
    if (.not. allocated(error)) call write_integer_attribute(group_id, "/timing", "dofs_efg", &
                                                             summary%dofs_efg, error)
    call h5gclose_f(group_id, status)
  end subroutine write_timing

  !> One history column: `values(width, rows)` stored as (rows) for width 1 and (rows, 3) for
  !> width 3. The dataset is chunked and extendible: an existing one of the same kind is resized
  !> and overwritten in place, so writing histories at every state does not grow the file.
  subroutine write_history_column(group_id, group_path, name, values, error)
    integer(hid_t), intent(in) :: group_id
    character(len=*), intent(in) :: group_path, name
    real(wp), intent(in), target, contiguous :: values(:, :)
    type(error_t), allocatable, intent(out) :: error
    integer(hsize_t), allocatable :: dims(:), maximum_dims(:), chunk(:)
    integer(hsize_t) :: old_dims(2), old_maximum(2)
    integer(hid_t) :: dataset_id, space_id, create_list
    integer :: status, rank, old_rank, ignored
    logical :: exists, reusable
    type(c_ptr) :: buffer

    if (size(values, 1) == 1) then
      dims = [int(size(values, 2), hsize_t)]
      maximum_dims = [H5S_UNLIMITED_F]
      chunk = [history_chunk_rows]
    else
      dims = [int(size(values, 1), hsize_t), int(size(values, 2), hsize_t)]
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
        call h5sget_simple_extent_dims_f(space_id, old_dims, old_maximum, status)
        ! h5sget_simple_extent_dims_f returns the rank on success.
        reusable = status == rank .and. old_maximum(rank) == H5S_UNLIMITED_F
        if (rank == 2) reusable = reusable .and. old_dims(1) == dims(1)
      end if
      call h5sclose_f(space_id, status)
      if (.not. reusable) then
        ! Another shape (the series changed its columns): start the dataset afresh.
        call h5dclose_f(dataset_id, status)
        call h5ldelete_f(group_id, name, status)
        if (status /= 0) then
          call make_error(error, "cannot replace dataset "//group_path//"/"//name)
          return
        end if
      else
        call h5dset_extent_f(dataset_id, dims, status)
        if (status /= 0) then
          call h5dclose_f(dataset_id, status)
          call make_error(error, "cannot resize dataset "//group_path//"/"//name)
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
      if (status == 0) call h5dcreate_f(group_id, name, H5T_IEEE_F64LE, space_id, dataset_id, status, &
                                        dcpl_id=create_list)
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
    call h5dclose_f(dataset_id, status)
  end subroutine write_history_column

  ! ---------------------------------------------------------------------------------------------
  ! Small writers. Each opens and closes its own handles, so a failure leaves nothing open;
  ! `parent_path` and `name` only make the message ("" when `name` is already a full path).

  !> Create a contiguous dataset of `dims` and write `buffer` into it (nothing for size 0).
  subroutine write_dataset(parent_id, parent_path, name, file_type, memory_type, dims, buffer, error)
    integer(hid_t), intent(in) :: parent_id
    character(len=*), intent(in) :: parent_path, name
    integer(hid_t), intent(in) :: file_type, memory_type
    integer(hsize_t), intent(in) :: dims(:)
    type(c_ptr), intent(in) :: buffer
    type(error_t), allocatable, intent(out) :: error
    integer(hid_t) :: space_id, dataset_id
    integer :: status, ignored

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
      if (status /= 0) call make_error(error, "cannot write dataset "//object_path(parent_path, name))
    end if
    call h5dclose_f(dataset_id, ignored)
  end subroutine write_dataset

  !> Reals `(rows)`.
  subroutine write_real_dataset_1d(parent_id, parent_path, name, values, error)
    integer(hid_t), intent(in) :: parent_id
    character(len=*), intent(in) :: parent_path, name
    real(wp), intent(in), target, contiguous :: values(:)
    type(error_t), allocatable, intent(out) :: error
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call write_dataset(parent_id, parent_path, name, H5T_IEEE_F64LE, h5kind_to_type(wp, H5_REAL_KIND), &
                       [int(size(values), hsize_t)], buffer, error)
  end subroutine write_real_dataset_1d

  !> Reals `(columns, rows)` in Fortran, stored as (rows, columns).
  subroutine write_real_dataset_2d(parent_id, parent_path, name, values, error)
    integer(hid_t), intent(in) :: parent_id
    character(len=*), intent(in) :: parent_path, name
    real(wp), intent(in), target, contiguous :: values(:, :)
    type(error_t), allocatable, intent(out) :: error
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call write_dataset(parent_id, parent_path, name, H5T_IEEE_F64LE, h5kind_to_type(wp, H5_REAL_KIND), &
                       int(shape(values), hsize_t), buffer, error)
  end subroutine write_real_dataset_2d

  !> Integers `(rows)`, stored as 32-bit.
  subroutine write_integer_dataset_1d(parent_id, parent_path, name, values, error)
    integer(hid_t), intent(in) :: parent_id
    character(len=*), intent(in) :: parent_path, name
    integer, intent(in), target, contiguous :: values(:)
    type(error_t), allocatable, intent(out) :: error
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
    type(error_t), allocatable, intent(out) :: error
    type(c_ptr) :: buffer
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(values)
    call write_dataset(parent_id, parent_path, name, H5T_STD_I32LE, H5T_NATIVE_INTEGER, &
                       int(shape(values), hsize_t), buffer, error)
  end subroutine write_integer_dataset_2d

  !> Strings `(rows)` as variable-length ASCII, each trimmed of trailing blanks.
  subroutine write_string_dataset(parent_id, path, values, error)
    integer(hid_t), intent(in) :: parent_id
    character(len=*), intent(in) :: path
    character(len=*), intent(in) :: values(:)
    type(error_t), allocatable, intent(out) :: error
    character(kind=c_char, len=1), allocatable, target :: characters(:)
    type(c_ptr), allocatable, target :: pointers(:)
    integer(hid_t) :: string_type
    integer :: row, start, status
    type(c_ptr) :: buffer

    ! All strings in one buffer, each ended by NUL, and one C pointer per string: the memory
    ! form HDF5 expects for variable-length strings.
    allocate (characters(sum(len_trim(values)) + size(values)), pointers(size(values)))
    start = 1
    do row = 1, size(values)
      call copy_c_string(trim(values(row)), characters(start:start + len_trim(values(row))))
      pointers(row) = c_loc(characters(start))
      start = start + len_trim(values(row)) + 1
    end do
    buffer = c_null_ptr
    if (size(values) > 0) buffer = c_loc(pointers)
    call h5tcopy_f(H5T_STRING, string_type, status)
    if (status /= 0) then
      call make_error(error, "cannot create the string type for "//path)
      return
    end if
    call write_dataset(parent_id, "", path, string_type, string_type, [int(size(values), hsize_t)], &
                       buffer, error)
    call h5tclose_f(string_type, status)
  end subroutine write_string_dataset

  !> Create (or replace) an attribute of `object_id` and write `buffer` into it.
  subroutine write_attribute(object_id, object_path, name, file_type, memory_type, buffer, error)
    integer(hid_t), intent(in) :: object_id
    character(len=*), intent(in) :: object_path, name
    integer(hid_t), intent(in) :: file_type, memory_type
    type(c_ptr), intent(in) :: buffer
    type(error_t), allocatable, intent(out) :: error
    integer(hid_t) :: space_id, attribute_id
    integer :: status, ignored
    logical :: exists

    ! Attributes are small: deleting and recreating lets the type (string length) change.
    call h5aexists_f(object_id, name, exists, status)
    if (status == 0 .and. exists) call h5adelete_f(object_id, name, status)
    if (status /= 0) then
      call make_error(error, "cannot replace attribute "//name//" of "//object_path)
      return
    end if
    call h5screate_f(H5S_SCALAR_F, space_id, status)
    if (status /= 0) then
      call make_error(error, "cannot create the dataspace of attribute "//name//" of "//object_path)
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

  !> A real scalar attribute (64-bit).
  subroutine write_real_attribute(object_id, object_path, name, value, error)
    integer(hid_t), intent(in) :: object_id
    character(len=*), intent(in) :: object_path, name
    real(wp), intent(in) :: value
    type(error_t), allocatable, intent(out) :: error
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
    type(error_t), allocatable, intent(out) :: error
    integer, target :: stored
    stored = value
    call write_attribute(object_id, object_path, name, H5T_STD_I64LE, H5T_NATIVE_INTEGER, &
                         c_loc(stored), error)
  end subroutine write_integer_attribute

  !> A string scalar attribute, variable-length ASCII.
  subroutine write_string_attribute(object_id, object_path, name, value, error)
    integer(hid_t), intent(in) :: object_id
    character(len=*), intent(in) :: object_path, name, value
    type(error_t), allocatable, intent(out) :: error
    character(kind=c_char, len=1), allocatable, target :: characters(:)
    type(c_ptr), target :: pointer
    integer(hid_t) :: string_type
    integer :: status

    allocate (characters(len(value) + 1))
    call copy_c_string(value, characters)
    pointer = c_loc(characters)
    call h5tcopy_f(H5T_STRING, string_type, status)
    if (status /= 0) then
      call make_error(error, "cannot create the string type for attribute "//name)
      return
    end if
    call write_attribute(object_id, object_path, name, string_type, string_type, c_loc(pointer), &
                         error)
    call h5tclose_f(string_type, status)
  end subroutine write_string_attribute

  !> Create the groups of an absolute `path` that do not exist yet ("/history/matsum/3").
  subroutine create_group_path(file_id, path, error)
    integer(hid_t), intent(in) :: file_id
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: error
    integer(hid_t) :: group_id
    integer :: position, status, ignored
    logical :: exists

    ! Walk the prefixes: asking HDF5 about "/a/b/c" when "/a/b" is missing is an error.
    do position = 2, len(path) + 1
      if (position <= len(path)) then
        if (path(position:position) /= "/") cycle
      end if
      call h5lexists_f(file_id, path(1:position - 1), exists, status)
      if (status /= 0) then
        call make_error(error, "cannot look up group "//path(1:position - 1))
        return
      end if
      if (.not. exists) then
        call h5gcreate_f(file_id, path(1:position - 1), group_id, status)
        if (status /= 0) then
          call make_error(error, "cannot create group "//path(1:position - 1))
          return
        end if
        call h5gclose_f(group_id, ignored)
      end if
    end do
  end subroutine create_group_path

  !> Push everything written so far to the disk, so that readers see a consistent file.
  subroutine flush_file(file_id, error)
    integer(hid_t), intent(in) :: file_id
    type(error_t), allocatable, intent(out) :: error
    integer :: status
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

  !> "directory/name", or "name" alone for an empty directory.
  pure function join_path(directory, name) result(path)
    character(len=*), intent(in) :: directory, name
    character(len=:), allocatable :: path
    if (len_trim(directory) == 0) then
      path = name
    else if (directory(len_trim(directory):len_trim(directory)) == "/") then
      path = trim(directory)//name
    else
      path = trim(directory)//"/"//name
    end if
  end function join_path

  !> Full path of an object for messages.
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
