!> Unit tests of results_file: write a tiny model (2 hexahedra, 12 nodes, 1 part), two states,
!> histories (twice, to see that the second call adds the new rows) and the run summary into a
!> temporary directory, then read everything back with the HDF5 library and compare: shapes as
!> the contract gives them (h5py's row-major view) and values bit for bit. Then the commits of
!> states with their history rows, the XDMF schedule and the lock on the job's files.
!>
!> Set CRASHFREE_KEEP_TEST_OUTPUT=DIR to write into DIR (which must exist) and keep the files:
!> tests/regression/test_postproc.py uses that to read a Fortran-written file with h5py.
program test_results_file
  use, intrinsic :: iso_c_binding, only: c_ptr, c_loc, c_f_pointer, c_char, c_size_t, c_null_ptr, c_int
  use hdf5, only: hid_t, hsize_t, size_t, h5fopen_f, h5fclose_f, H5F_ACC_RDONLY_F, &
                  h5dopen_f, h5dclose_f, h5dread_f, h5dget_space_f, h5dget_type_f, &
                  h5sget_simple_extent_ndims_f, h5sget_simple_extent_dims_f, h5sclose_f, &
                  h5screate_f, H5S_SCALAR_F, h5aopen_by_name_f, h5aclose_f, h5aread_f, &
                  h5aget_type_f, h5tcopy_f, h5tclose_f, h5tget_size_f, h5tis_variable_str_f, &
                  h5dvlen_reclaim_f, h5lexists_f, H5T_STRING, H5T_NATIVE_INTEGER, H5P_DEFAULT_F, &
                  h5kind_to_type, H5_REAL_KIND
  use kinds, only: wp
  use error_handling, only: error_t
  use version, only: crashfree_version
  use model, only: model_t, part_t, formulation_efg, formulation_fe
  use run_summary, only: run_summary_t, status_normal
  use history_buffer, only: history_set_t, add_history_series, append_history_row
  use results_file, only: results_file_t, open_results, write_state, write_histories, close_results
  use testing, only: test_suite_t, check, check_close, finish_suite
  use fixtures, only: error_message
  implicit none

  interface
    !> C's strlen, to find the end of a string HDF5 allocated.
    function c_string_length(string) bind(c, name="strlen") result(length)
      import :: c_ptr, c_size_t
      type(c_ptr), value :: string
      integer(c_size_t) :: length
    end function c_string_length

    !> POSIX getpid, for the lock's message.
    function c_getpid() bind(c, name="getpid") result(pid)
      import :: c_int
      integer(c_int) :: pid
    end function c_getpid
  end interface

  type(test_suite_t) :: suite
  type(model_t) :: model
  character(len=:), allocatable :: directory
  logical :: keep_output

  suite%name = "results_file"
  call make_model(model)
  call make_directory(suite, directory, keep_output)

  call test_write_and_read_back(suite, model, directory)
  call test_errors(suite, model, directory)
  call test_open_again(suite, model, directory)
  call test_shells_in_xdmf(suite, model, directory)
  call test_commits_schedule_and_lock(suite, model, directory)

  if (.not. keep_output) call remove_outputs(directory)
  call finish_suite(suite)

contains

  ! ---------------------------------------------------------------------------------------------
  ! Fixtures

  !> Two hexahedra side by side: nodes on a 3 x 2 x 2 grid, ids 101, 111, ... so that ids and
  !> indices differ; one EFG part (id 5, material 3).
  subroutine make_model(model)
    type(model_t), intent(out) :: model
    integer :: i, j, k, node

    model%title = "two bricks"
    model%deck_path = "inputs/two_bricks.k"
    allocate (model%node_ids(12), model%coordinates(3, 12))
    node = 0
    do k = 0, 1
      do j = 0, 1
        do i = 0, 2
          node = node + 1
          model%node_ids(node) = 101 + 10*(node - 1)
          model%coordinates(:, node) = [real(i, wp)*0.5_wp, real(j, wp)*0.25_wp, real(k, wp)/3.0_wp]
        end do
      end do
    end do
    ! Node index of grid point (i, j, k) is 1 + i + 3 j + 6 k; LS-DYNA order: bottom face
    ! counter-clockwise, then the top face.
    allocate (model%solid_ids(2), model%solid_part(2), model%solid_nodes(8, 2))
    model%solid_ids = [7, 9]
    model%solid_part = [1, 1]
    model%solid_nodes(:, 1) = [1, 2, 5, 4, 7, 8, 11, 10]
    model%solid_nodes(:, 2) = [2, 3, 6, 5, 8, 9, 12, 11]
    allocate (model%parts(1))
    model%parts(1)%id = 5
    model%parts(1)%material_id = 3
    model%parts(1)%material = 1
    model%parts(1)%formulation = formulation_efg
  end subroutine make_model

  !> A fresh directory under $TMPDIR (or /tmp), or $CRASHFREE_KEEP_TEST_OUTPUT when set.
  subroutine make_directory(suite, directory, keep_output)
    type(test_suite_t), intent(inout) :: suite
    character(len=:), allocatable, intent(out) :: directory
    logical, intent(out) :: keep_output
    character(len=1024) :: value, name
    integer :: length, status, clock(8)
    real(wp) :: random

    call get_environment_variable("CRASHFREE_KEEP_TEST_OUTPUT", value, length, status)
    keep_output = status == 0 .and. length > 0
    if (keep_output) then
      directory = trim(value)
      return
    end if
    call get_environment_variable("TMPDIR", value, length, status)
    if (status /= 0 .or. length == 0) value = "/tmp"
    ! Time and a random number: two test programs running at once get different directories.
    call date_and_time(values=clock)
    call random_seed()
    call random_number(random)
    write (name, '("/crashfree_test_results_",i2.2,i2.2,i2.2,i3.3,"_",i6.6)') clock(5:8), &
      int(random*1.0e6_wp)
    directory = trim(value)//trim(name)
    call execute_command_line("mkdir -p '"//directory//"'", exitstat=status)
    call check(suite, "temporary directory created", status == 0, directory)
  end subroutine make_directory

  !> Delete what the tests wrote, then the directory.
  subroutine remove_outputs(directory)
    character(len=*), intent(in) :: directory
    character(len=*), parameter :: jobs(5) = [character(len=7) :: "job", "again", "mixed", "plates", "commits"]
    character(len=*), parameter :: endings(5) = [character(len=9) :: ".h5", ".xdmf", ".lock", ".d3plot", ".d3plot01"]
    integer :: j, e
    do j = 1, size(jobs)
      do e = 1, size(endings)
        call delete_file(directory//"/"//trim(jobs(j))//trim(endings(e)))
      end do
    end do
    call execute_command_line("rmdir '"//directory//"'")
  end subroutine remove_outputs

  subroutine delete_file(path)
    character(len=*), intent(in) :: path
    integer :: unit, status
    logical :: exists
    inquire (file=path, exist=exists)
    if (.not. exists) return
    open (newunit=unit, file=path, status="old", iostat=status)
    if (status == 0) close (unit, status="delete")
  end subroutine delete_file

  !> Nodal field (3, 12) with distinct, exactly representable values.
  pure function nodal_field(offset) result(field)
    real(wp), intent(in) :: offset
    real(wp) :: field(3, 12)
    integer :: node, component
    do node = 1, 12
      do component = 1, 3
        field(component, node) = offset + real(component, wp) + 0.125_wp*real(node, wp)
      end do
    end do
  end function nodal_field

  !> Stress (6, 2) with distinct values.
  pure function stress_field(offset) result(field)
    real(wp), intent(in) :: offset
    real(wp) :: field(6, 2)
    integer :: solid, component
    do solid = 1, 2
      do component = 1, 6
        field(component, solid) = offset - 100.0_wp*real(component, wp) + 0.5_wp*real(solid, wp)
      end do
    end do
  end function stress_field

  !> A glstat series and a nodout series with `rows` rows each.
  subroutine make_histories(histories, rows)
    type(history_set_t), intent(out) :: histories
    integer, intent(in) :: rows
    integer :: glstat, nodout, row
    real(wp) :: time
    character(len=32) :: glstat_names(8), nodout_names(4)

    glstat_names = [character(len=32) :: "time", "time_step", "kinetic_energy", "internal_energy", &
                    "hourglass_energy", "contact_energy", "external_work", "total_energy"]
    nodout_names = [character(len=32) :: "time", "displacement", "velocity", "acceleration"]
    call add_history_series(histories, "glstat", glstat_names, [1, 1, 1, 1, 1, 1, 1, 1], 4, glstat)
    call add_history_series(histories, "nodout/101", nodout_names, [1, 3, 3, 3], 4, nodout)
    do row = 1, rows
      time = 0.25_wp*real(row - 1, wp)
      call append_history_row(histories%series(glstat), [time, 1.0e-3_wp, 10.0_wp - time, &
                              time, 0.0625_wp*time, 0.0_wp, 0.5_wp*time, 10.0_wp + 0.5_wp*time])
      call append_history_row(histories%series(nodout), [time, 1.0_wp*row, 2.0_wp*row, 3.0_wp*row, &
                              -1.0_wp*row, -2.0_wp*row, -3.0_wp*row, 0.5_wp, 0.25_wp, 0.125_wp])
    end do
  end subroutine make_histories

  ! ---------------------------------------------------------------------------------------------
  ! Tests

  subroutine test_write_and_read_back(suite, model, directory)
    type(test_suite_t), intent(inout) :: suite
    type(model_t), intent(in) :: model
    character(len=*), intent(in) :: directory
    type(results_file_t) :: results
    type(error_t), allocatable :: error
    type(history_set_t) :: histories
    type(run_summary_t) :: summary
    real(wp) :: plastic(2)
    integer(hid_t) :: file_id
    integer :: status
    character(len=:), allocatable :: xdmf_text

    call open_results(results, directory, "job", model, 4, error)
    call check(suite, "open_results succeeds", .not. allocated(error), error_message(error))
    if (allocated(error)) return

    call write_state(results, 0.0_wp, nodal_field(0.0_wp)*0.0_wp, nodal_field(0.0_wp)*0.0_wp, &
                     stress_field(0.0_wp)*0.0_wp, [0.0_wp, 0.0_wp], error, reference_coordinates=model%coordinates)
    call check(suite, "write_state 0 succeeds", .not. allocated(error), error_message(error))
    call make_histories(histories, 3)
    call write_histories(results, histories, error)
    call check(suite, "write_histories (first) succeeds", .not. allocated(error), error_message(error))

    plastic = [0.03125_wp, 0.0625_wp]
    call write_state(results, 1.5e-3_wp, nodal_field(1.0_wp), nodal_field(-20.0_wp), &
                     stress_field(1000.0_wp), plastic, error, reference_coordinates=model%coordinates)
    call check(suite, "write_state 1 succeeds", .not. allocated(error), error_message(error))
    call check(suite, "two states counted", results%state_count == 2)
    ! The second call holds more rows: the datasets must show exactly these.
    call make_histories(histories, 5)
    call write_histories(results, histories, error)
    call check(suite, "write_histories (second) succeeds", .not. allocated(error), &
               error_message(error))

    summary%status = status_normal
    summary%message = ""
    summary%end_time = 1.5e-3_wp
    summary%cycles = 1234
    summary%threads = 4
    summary%wall_s = 2.5_wp
    summary%setup_s = 0.25_wp
    summary%fe_solid_s = 1.0_wp
    summary%efg_s = 0.75_wp
    summary%output_s = 0.125_wp
    summary%fe_elements = 2
    summary%efg_particles = 12
    summary%dofs_total = 36
    summary%dofs_efg = 36
    call close_results(results, summary, error)
    call check(suite, "close_results succeeds", .not. allocated(error), error_message(error))
    call check(suite, "file marked closed", .not. results%is_open)

    call h5fopen_f(directory//"/job.h5", H5F_ACC_RDONLY_F, file_id, status)
    call check(suite, "results file opens for reading", status == 0)
    if (status /= 0) return
    call check_mesh(suite, file_id, model)
    call check_run_and_timing(suite, file_id, summary)
    call check_states(suite, file_id, plastic)
    call check_histories(suite, file_id, 5)
    call h5fclose_f(file_id, status)

    call read_text_file(directory//"/job.xdmf", xdmf_text)
    call check(suite, "xdmf refers to the h5 by name", &
               index(xdmf_text, ">job.h5:/states/000001/displacement<") > 0)
    call check(suite, "xdmf has no directory in references", index(xdmf_text, directory) == 0)
    call check(suite, "xdmf has both time steps", index(xdmf_text, '<Time Value="0.') > 0 .and. &
               index(xdmf_text, '<Time Value="1.5000000000000000E-003"/>') > 0)
    call check(suite, "xdmf hexahedron topology", &
               index(xdmf_text, 'TopologyType="Hexahedron" NumberOfElements="2"') > 0 .and. &
               index(xdmf_text, "job.h5:/mesh/solids/connectivity_index") > 0)
    call check(suite, "xdmf stress as Tensor6 on cells", &
               index(xdmf_text, 'Name="solid_stress" AttributeType="Tensor6" Center="Cell"') > 0)
  end subroutine test_write_and_read_back

  subroutine check_mesh(suite, file_id, model)
    type(test_suite_t), intent(inout) :: suite
    integer(hid_t), intent(in) :: file_id
    type(model_t), intent(in) :: model
    integer :: expected_connectivity(8, 2)

    ! HDF5 dimensions are listed here in Fortran order: (3, 12) is h5py's (12, 3).
    call check(suite, "nodes/ids shape (12)", same_dims(dims_of(file_id, "/mesh/nodes/ids"), [12]))
    call check(suite, "nodes/ids values", all(integers_of(file_id, "/mesh/nodes/ids") == &
                                              model%node_ids))
    call check(suite, "nodes/coordinates shape (12,3)", &
               same_dims(dims_of(file_id, "/mesh/nodes/coordinates"), [3, 12]))
    call check(suite, "nodes/coordinates exact", &
               all(reals_of(file_id, "/mesh/nodes/coordinates") == &
                   reshape(model%coordinates, [36])))
    call check(suite, "solids/ids", all(integers_of(file_id, "/mesh/solids/ids") == [7, 9]))
    call check(suite, "solids/part_ids are part ids", &
               all(integers_of(file_id, "/mesh/solids/part_ids") == [5, 5]))
    call check(suite, "solids/connectivity shape (2,8)", &
               same_dims(dims_of(file_id, "/mesh/solids/connectivity"), [8, 2]))
    expected_connectivity(:, 1) = model%node_ids(model%solid_nodes(:, 1))
    expected_connectivity(:, 2) = model%node_ids(model%solid_nodes(:, 2))
    call check(suite, "solids/connectivity holds node ids", &
               all(integers_of(file_id, "/mesh/solids/connectivity") == &
                   reshape(expected_connectivity, [16])))
    call check(suite, "solids/connectivity_index 0-based", &
               all(integers_of(file_id, "/mesh/solids/connectivity_index") == &
                   reshape(model%solid_nodes - 1, [16])))
    call check(suite, "shells/ids empty (0)", same_dims(dims_of(file_id, "/mesh/shells/ids"), [0]))
    call check(suite, "shells/part_ids empty (0)", &
               same_dims(dims_of(file_id, "/mesh/shells/part_ids"), [0]))
    call check(suite, "shells/connectivity empty (0,4)", &
               same_dims(dims_of(file_id, "/mesh/shells/connectivity"), [4, 0]))
    call check(suite, "parts/ids", all(integers_of(file_id, "/mesh/parts/ids") == [5]))
    call check(suite, "parts/material_ids", &
               all(integers_of(file_id, "/mesh/parts/material_ids") == [3]))
    call check(suite, "parts/formulation efg", first_string_of(file_id, "/mesh/parts/formulation") &
               == "efg")
  end subroutine check_mesh

  subroutine check_run_and_timing(suite, file_id, summary)
    type(test_suite_t), intent(inout) :: suite
    integer(hid_t), intent(in) :: file_id
    type(run_summary_t), intent(in) :: summary
    character(len=10), parameter :: second_names(7) = [character(len=10) :: "wall_s", &
      "fe_solid_s", "fe_shell_s", "efg_s", "contact_s", "output_s", "setup_s"]
    character(len=13), parameter :: count_names(6) = [character(len=13) :: "cycles", "threads", &
      "fe_elements", "efg_particles", "dofs_total", "dofs_efg"]
    real(wp) :: seconds(7)
    integer :: counts(6), entry

    call check(suite, "run version", &
               string_attribute(file_id, "/run", "version") == crashfree_version)
    call check(suite, "run deck", &
               string_attribute(file_id, "/run", "deck") == "inputs/two_bricks.k")
    call check(suite, "run status", string_attribute(file_id, "/run", "status") == status_normal)
    call check(suite, "run message empty", string_attribute(file_id, "/run", "message") == "")
    call check(suite, "run end_time", &
               real_attribute(file_id, "/run", "end_time") == summary%end_time)
    call check(suite, "run cycles", integer_attribute(file_id, "/run", "cycles") == 1234)
    call check(suite, "run threads", integer_attribute(file_id, "/run", "threads") == 4)
    call check(suite, "counts stored as 64-bit", attribute_size(file_id, "/run", "cycles") == 8)

    seconds = [summary%wall_s, summary%fe_solid_s, summary%fe_shell_s, summary%efg_s, &
               summary%contact_s, summary%output_s, summary%setup_s]
    do entry = 1, size(second_names)
      call check(suite, "timing "//trim(second_names(entry)), &
                 real_attribute(file_id, "/timing", trim(second_names(entry))) == seconds(entry))
    end do
    counts = [summary%cycles, summary%threads, summary%fe_elements, summary%efg_particles, &
              summary%dofs_total, summary%dofs_efg]
    do entry = 1, size(count_names)
      call check(suite, "timing "//trim(count_names(entry)), &
                 integer_attribute(file_id, "/timing", trim(count_names(entry))) == counts(entry))
    end do
  end subroutine check_run_and_timing

  subroutine check_states(suite, file_id, plastic)
    type(test_suite_t), intent(inout) :: suite
    integer(hid_t), intent(in) :: file_id
    real(wp), intent(in) :: plastic(2)
    real(wp) :: expected(36)

    call check(suite, "state 0 time", real_attribute(file_id, "/states/000000", "time") == 0.0_wp)
    call check(suite, "state 1 time", &
               real_attribute(file_id, "/states/000001", "time") == 1.5e-3_wp)
    call check(suite, "no third state", .not. link_exists(file_id, "/states/000002"))
    call check(suite, "displacement shape (12,3)", &
               same_dims(dims_of(file_id, "/states/000001/displacement"), [3, 12]))
    expected = reshape(nodal_field(1.0_wp), [36])
    call check(suite, "displacement exact", &
               all(reals_of(file_id, "/states/000001/displacement") == expected))
    expected = reshape(nodal_field(-20.0_wp), [36])
    call check(suite, "velocity exact", &
               all(reals_of(file_id, "/states/000001/velocity") == expected))
    call check(suite, "solid_stress shape (2,6)", &
               same_dims(dims_of(file_id, "/states/000001/solid_stress"), [6, 2]))
    call check(suite, "solid_stress exact", &
               all(reals_of(file_id, "/states/000001/solid_stress") == &
                   reshape(stress_field(1000.0_wp), [12])))
    call check(suite, "solid_plastic_strain exact", &
               all(reals_of(file_id, "/states/000001/solid_plastic_strain") == plastic))
    call check(suite, "shell_stress empty (0,6)", &
               same_dims(dims_of(file_id, "/states/000001/shell_stress"), [6, 0]))
    call check(suite, "shell_plastic_strain empty (0)", &
               same_dims(dims_of(file_id, "/states/000000/shell_plastic_strain"), [0]))
  end subroutine check_states

  subroutine check_histories(suite, file_id, rows)
    type(test_suite_t), intent(inout) :: suite
    integer(hid_t), intent(in) :: file_id
    integer, intent(in) :: rows
    type(history_set_t) :: expected_set
    real(wp), allocatable :: expected(:)

    call make_histories(expected_set, rows)
    associate (glstat => expected_set%series(1), nodout => expected_set%series(2))
      call check(suite, "glstat/time has the rows last written", &
                 same_dims(dims_of(file_id, "/history/glstat/time"), [rows]))
      call check(suite, "glstat/time values", all(reals_of(file_id, "/history/glstat/time") == &
                                                  glstat%rows(1, 1:rows)))
      call check(suite, "glstat/total_energy values", &
                 all(reals_of(file_id, "/history/glstat/total_energy") == glstat%rows(8, 1:rows)))
      call check(suite, "nodout/101 intermediate groups", &
                 link_exists(file_id, "/history/nodout/101"))
      call check(suite, "nodout displacement shape (rows,3)", &
                 same_dims(dims_of(file_id, "/history/nodout/101/displacement"), [3, rows]))
      expected = reshape(nodout%rows(2:4, 1:rows), [3*rows])
      call check(suite, "nodout displacement values", &
                 all(reals_of(file_id, "/history/nodout/101/displacement") == expected))
      expected = reshape(nodout%rows(8:10, 1:rows), [3*rows])
      call check_close(suite, "nodout acceleration values", &
                       reals_of(file_id, "/history/nodout/101/acceleration"), expected, thr=0.0_wp)
    end associate
  end subroutine check_histories

  subroutine test_errors(suite, model, directory)
    type(test_suite_t), intent(inout) :: suite
    type(model_t), intent(in) :: model
    character(len=*), intent(in) :: directory
    type(results_file_t) :: results
    type(error_t), allocatable :: error
    type(history_set_t) :: histories
    type(run_summary_t) :: summary
    real(wp) :: wrong(3, 5)

    ! A missing directory: an error naming the file, and no HDF5 error stack on the output.
    call open_results(results, directory//"/no/such/directory", "job", model, 1, error)
    call check(suite, "missing directory is an error", allocated(error))
    if (allocated(error)) then
      call check(suite, "error names the file", &
                 index(error%message, directory//"/no/such/directory/job.h5") > 0, error%message)
      call check(suite, "error says what failed", index(error%message, "cannot create") > 0, &
                 error%message)
    end if
    call check(suite, "failed open leaves it closed", .not. results%is_open)

    wrong = 0.0_wp
    call write_state(results, 0.0_wp, wrong, wrong, stress_field(0.0_wp), [0.0_wp, 0.0_wp], error)
    call check(suite, "write_state on a closed file is an error", allocated(error))
    call make_histories(histories, 1)
    call write_histories(results, histories, error)
    call check(suite, "write_histories on a closed file is an error", allocated(error))

    call open_results(results, directory, "again", model, 1, error)
    call check(suite, "second file opens", .not. allocated(error), error_message(error))
    call write_state(results, 0.0_wp, wrong, wrong, stress_field(0.0_wp), [0.0_wp, 0.0_wp], error)
    call check(suite, "wrong node count is an error", allocated(error))
    if (allocated(error)) call check(suite, "size error names the mesh", &
                                     index(error%message, "12 nodes") > 0, error%message)
    call check(suite, "nothing written after a size error", results%state_count == 0)
    ! the d3plot writes reference + displacement from the caller's coordinates: without them
    ! (or with ones of another mesh) the state is refused before anything is written
    call write_state(results, 0.0_wp, nodal_field(0.0_wp), nodal_field(0.0_wp), stress_field(0.0_wp), &
                     [0.0_wp, 0.0_wp], error)
    call check(suite, "state without reference coordinates is an error", allocated(error))
    if (allocated(error)) call check(suite, "error names the reference coordinates", &
                                     index(error%message, "no reference coordinates") > 0, error%message)
    call write_state(results, 0.0_wp, nodal_field(0.0_wp), nodal_field(0.0_wp), stress_field(0.0_wp), &
                     [0.0_wp, 0.0_wp], error, reference_coordinates=model%coordinates(:, 1:3))
    call check(suite, "reference coordinates of another mesh are an error", allocated(error))
    call check(suite, "nothing written without the reference coordinates", results%state_count == 0)
    call open_results(results, directory, "again", model, 1, error)
    call check(suite, "opening an open file is an error", allocated(error))
    call close_results(results, summary, error)
    call check(suite, "close after errors", .not. allocated(error) .and. .not. results%is_open)
  end subroutine test_errors

  !> Open, write and close a second time in the same process: the library stays usable.
  subroutine test_open_again(suite, model, directory)
    type(test_suite_t), intent(inout) :: suite
    type(model_t), intent(in) :: model
    character(len=*), intent(in) :: directory
    type(results_file_t) :: results
    type(error_t), allocatable :: error
    type(run_summary_t) :: summary
    type(history_set_t) :: histories
    integer(hid_t) :: file_id
    integer :: status

    call open_results(results, directory//"/", "again", model, 2, error)
    call check(suite, "reopen after close succeeds", .not. allocated(error), error_message(error))
    if (allocated(error)) return
    call write_state(results, 0.0_wp, nodal_field(2.0_wp), nodal_field(3.0_wp), &
                     stress_field(4.0_wp), [0.0_wp, 0.0_wp], error, reference_coordinates=model%coordinates)
    call check(suite, "state in reopened file", .not. allocated(error), error_message(error))
    ! Histories written again with fewer rows shrink: the file holds the last call only.
    call make_histories(histories, 5)
    call write_histories(results, histories, error)
    call make_histories(histories, 2)
    call write_histories(results, histories, error)
    call check(suite, "histories rewritten with fewer rows", .not. allocated(error), &
               error_message(error))
    ! No status given: the file must not claim a normal termination.
    call close_results(results, summary, error)
    call check(suite, "close reopened file", .not. allocated(error), error_message(error))
    call close_results(results, summary, error)
    call check(suite, "closing twice is harmless", .not. allocated(error))

    call h5fopen_f(directory//"/again.h5", H5F_ACC_RDONLY_F, file_id, status)
    call check(suite, "reopened file readable", status == 0)
    if (status /= 0) return
    call check(suite, "missing status written as error termination", &
               string_attribute(file_id, "/run", "status") == "error termination")
    call check(suite, "threads from the summary", &
               integer_attribute(file_id, "/run", "threads") == 1)
    call check(suite, "histories shrank to 2 rows", &
               same_dims(dims_of(file_id, "/history/nodout/101/velocity"), [3, 2]))
    call check_histories(suite, file_id, 2)
    call h5fclose_f(file_id, status)
  end subroutine test_open_again

  !> Shells in the XDMF file: the two bricks with two shells on their top face (solids and
  !> shells: a spatial collection of a hexahedron and a quadrilateral grid per state), and the
  !> same shells alone (one quadrilateral grid per state, no hexahedra).
  subroutine test_shells_in_xdmf(suite, bricks, directory)
    type(test_suite_t), intent(inout) :: suite
    type(model_t), intent(in) :: bricks
    character(len=*), intent(in) :: directory
    type(model_t) :: mixed, plates
    type(results_file_t) :: results
    type(error_t), allocatable :: error
    type(run_summary_t) :: summary
    character(len=:), allocatable :: xdmf_text
    real(wp) :: shell_stress(6, 2), no_solid_stress(6, 0), no_solid_strain(0), plate_field(3, 6)
    integer(hid_t) :: file_id
    integer :: status

    mixed = bricks
    ! Top face (k = 1) of the 3 x 2 grid: node index 7 + i + 3 j.
    allocate (mixed%shell_ids(2), mixed%shell_part(2), mixed%shell_nodes(4, 2))
    mixed%shell_ids = [31, 32]
    mixed%shell_part = [2, 2]
    mixed%shell_nodes(:, 1) = [7, 8, 11, 10]
    mixed%shell_nodes(:, 2) = [8, 9, 12, 11]
    deallocate (mixed%parts)
    allocate (mixed%parts(2))
    mixed%parts(1) = bricks%parts(1)
    mixed%parts(2)%id = 6
    mixed%parts(2)%material_id = 3
    mixed%parts(2)%material = 1
    mixed%parts(2)%formulation = formulation_fe
    shell_stress = stress_field(7.0_wp)

    call open_results(results, directory, "mixed", mixed, 1, error)
    call check(suite, "solids and shells: file opens", .not. allocated(error), error_message(error))
    if (allocated(error)) return
    call write_state(results, 0.0_wp, nodal_field(0.0_wp), nodal_field(1.0_wp), stress_field(0.0_wp), &
                     [0.0_wp, 0.0_wp], error, shell_stress, [0.5_wp, 0.25_wp], shell_stress, &
                     [0.5_wp, 0.25_wp], reference_coordinates=mixed%coordinates)
    call check(suite, "solids and shells: state written", .not. allocated(error), error_message(error))
    summary%status = status_normal
    summary%message = ""
    call close_results(results, summary, error)
    call h5fopen_f(directory//"/mixed.h5", H5F_ACC_RDONLY_F, file_id, status)
    call check(suite, "solids and shells: file readable", status == 0)
    if (status == 0) then
      call check(suite, "shells/connectivity_index shape (2,4)", &
                 same_dims(dims_of(file_id, "/mesh/shells/connectivity_index"), [4, 2]))
      call check(suite, "shells/connectivity_index 0-based", &
                 all(integers_of(file_id, "/mesh/shells/connectivity_index") == &
                     reshape(mixed%shell_nodes - 1, [8])))
      call check(suite, "shell_stress shape (2,6)", &
                 same_dims(dims_of(file_id, "/states/000000/shell_stress"), [6, 2]))
      call h5fclose_f(file_id, status)
    end if
    call read_text_file(directory//"/mixed.xdmf", xdmf_text)
    call check(suite, "xdmf solids and shells: a spatial collection per state", &
               index(xdmf_text, '<Grid Name="state_000000" GridType="Collection" '// &
                     'CollectionType="Spatial">') > 0)
    call check(suite, "xdmf solids and shells: hexahedron grid", &
               index(xdmf_text, '<Grid Name="solids" GridType="Uniform">') > 0 .and. &
               index(xdmf_text, 'TopologyType="Hexahedron" NumberOfElements="2"') > 0)
    call check(suite, "xdmf solids and shells: quadrilateral grid", &
               index(xdmf_text, '<Grid Name="shells" GridType="Uniform">') > 0 .and. &
               index(xdmf_text, 'TopologyType="Quadrilateral" NumberOfElements="2" '// &
                     'NodesPerElement="4"') > 0 .and. &
               index(xdmf_text, '>mixed.h5:/mesh/shells/connectivity_index<') > 0)
    call check(suite, "xdmf shell stress as Tensor6 on cells", &
               index(xdmf_text, 'Name="shell_stress" AttributeType="Tensor6" Center="Cell"') > 0 &
               .and. index(xdmf_text, '>mixed.h5:/states/000000/shell_stress<') > 0 .and. &
               index(xdmf_text, '>mixed.h5:/states/000000/shell_plastic_strain<') > 0)
    call check(suite, "xdmf shell ids and part ids", &
               index(xdmf_text, '>mixed.h5:/mesh/shells/ids<') > 0 .and. &
               index(xdmf_text, '>mixed.h5:/mesh/shells/part_ids<') > 0)

    ! The shells alone: nodes 7-12 of the bricks, renumbered 1-6.
    allocate (plates%node_ids(6), plates%coordinates(3, 6))
    plates%node_ids = bricks%node_ids(7:12)
    plates%coordinates = bricks%coordinates(:, 7:12)
    allocate (plates%shell_ids(2), plates%shell_part(2), plates%shell_nodes(4, 2))
    plates%shell_ids = [31, 32]
    plates%shell_part = [1, 1]
    plates%shell_nodes = mixed%shell_nodes - 6
    allocate (plates%parts(1))
    plates%parts(1) = mixed%parts(2)
    call open_results(results, directory, "plates", plates, 1, error)
    call check(suite, "shells only: file opens", .not. allocated(error), error_message(error))
    if (allocated(error)) return
    plate_field = 0.0_wp
    call write_state(results, 0.0_wp, plate_field, plate_field, &
                     no_solid_stress, no_solid_strain, error, shell_stress, [0.5_wp, 0.25_wp], &
                     shell_stress, [0.5_wp, 0.25_wp], reference_coordinates=plates%coordinates)
    call check(suite, "shells only: state written", .not. allocated(error), error_message(error))
    call close_results(results, summary, error)
    call read_text_file(directory//"/plates.xdmf", xdmf_text)
    call check(suite, "xdmf shells only: one quadrilateral grid per state", &
               index(xdmf_text, '<Grid Name="state_000000" GridType="Uniform">') > 0 .and. &
               index(xdmf_text, 'TopologyType="Quadrilateral" NumberOfElements="2"') > 0)
    call check(suite, "xdmf shells only: no hexahedra, no spatial collection", &
               index(xdmf_text, "Hexahedron") == 0 .and. index(xdmf_text, "Spatial") == 0 .and. &
               index(xdmf_text, "solid_stress") == 0)
  end subroutine test_shells_in_xdmf

  !> Ten states, each with the history rows recorded since the previous one (one commit each):
  !> the histories grow row by row and hold every row once; the XDMF file is written at the
  !> states 1, 2, 4, 8 and at the close, lists every state and leaves no temporary file; /timing
  !> counts the values written and the XDMF writes. A second open of the same job while the
  !> first is open is refused, naming this process; after the close it succeeds.
  subroutine test_commits_schedule_and_lock(suite, model, directory)
    type(test_suite_t), intent(inout) :: suite
    type(model_t), intent(in) :: model
    character(len=*), intent(in) :: directory
    type(results_file_t) :: results, second
    type(error_t), allocatable :: error
    type(history_set_t) :: histories
    type(run_summary_t) :: summary
    character(len=:), allocatable :: xdmf_text
    character(len=16) :: pid_text
    integer(hid_t) :: file_id
    integer :: state, status, writes
    logical :: exists, all_written

    call open_results(results, directory, "commits", model, 1, error)
    call check(suite, "commits: file opens", .not. allocated(error), error_message(error))
    if (allocated(error)) return

    write (pid_text, '(i0)') c_getpid()
    call open_results(second, directory, "commits", model, 1, error)
    call check(suite, "lock: a second open of the job is refused", allocated(error))
    if (allocated(error)) call check(suite, "lock: the message names the job, directory and process", &
                                     index(error%message, "another run (process "//trim(pid_text)// &
                                           ") is writing job 'commits' in the output directory '"// &
                                           directory//"'") > 0, error%message)
    call check(suite, "lock: the refused file is not open", .not. second%is_open)

    all_written = .true.
    do state = 1, 10
      call make_histories(histories, 2*state)
      call write_state(results, 0.25_wp*real(state, wp), nodal_field(real(state, wp)), nodal_field(0.0_wp), &
                       stress_field(0.0_wp), [0.0_wp, 0.0_wp], error, histories=histories, &
                       reference_coordinates=model%coordinates)
      all_written = all_written .and. .not. allocated(error)
      if (state == 3) call check(suite, "commits: XDMF written at states 1, 2 (not 3)", results%xdmf_writes == 2)
    end do
    call check(suite, "commits: ten states written", all_written .and. results%state_count == 10)
    writes = results%xdmf_writes
    call check(suite, "commits: XDMF written at states 1, 2, 4, 8", writes == 4)
    summary%status = status_normal
    summary%message = ""
    call close_results(results, summary, error)
    call check(suite, "commits: close", .not. allocated(error), error_message(error))

    call h5fopen_f(directory//"/commits.h5", H5F_ACC_RDONLY_F, file_id, status)
    call check(suite, "commits: file readable", status == 0)
    if (status /= 0) return
    call check_histories(suite, file_id, 20)
    call check(suite, "commits: state 9 is the last", link_exists(file_id, "/states/000009") .and. &
               .not. link_exists(file_id, "/states/000010"))
    call check(suite, "commits: output_bytes counts states and rows", &
               integer_attribute(file_id, "/timing", "output_bytes") == &
               10*8*(2*3*12 + 7*2) + 20*8*(8 + 10))
    call check(suite, "commits: xdmf_writes counts the close", &
               integer_attribute(file_id, "/timing", "xdmf_writes") == writes + 1)
    call h5fclose_f(file_id, status)
    call read_text_file(directory//"/commits.xdmf", xdmf_text)
    call check(suite, "commits: XDMF lists all ten states", &
               index(xdmf_text, ">commits.h5:/states/000009/displacement<") > 0 .and. &
               index(xdmf_text, "</Xdmf>") > 0)
    inquire (file=directory//"/commits.xdmf.tmp", exist=exists)
    call check(suite, "commits: no temporary XDMF file left", .not. exists)

    call open_results(second, directory, "commits", model, 1, error)
    call check(suite, "lock: released by the close", .not. allocated(error), error_message(error))
    call close_results(second, summary, error)
  end subroutine test_commits_schedule_and_lock

  ! ---------------------------------------------------------------------------------------------
  ! Readers

  logical function same_dims(actual, expected)
    integer(hsize_t), intent(in) :: actual(:)
    integer, intent(in) :: expected(:)
    same_dims = size(actual) == size(expected)
    if (same_dims) same_dims = all(actual == int(expected, hsize_t))
  end function same_dims

  logical function link_exists(file_id, path)
    integer(hid_t), intent(in) :: file_id
    character(len=*), intent(in) :: path
    logical :: exists
    integer :: status
    call h5lexists_f(file_id, path, exists, status)
    link_exists = status == 0 .and. exists
  end function link_exists

  !> Dimensions in HDF5's Fortran order (the reverse of h5py's); empty when missing.
  function dims_of(file_id, path) result(dims)
    integer(hid_t), intent(in) :: file_id
    character(len=*), intent(in) :: path
    integer(hsize_t), allocatable :: dims(:)
    integer(hsize_t) :: maximum(7), buffer(7)
    integer(hid_t) :: dataset_id, space_id
    integer :: rank, status
    allocate (dims(0))
    call h5dopen_f(file_id, path, dataset_id, status)
    if (status /= 0) return
    call h5dget_space_f(dataset_id, space_id, status)
    call h5sget_simple_extent_ndims_f(space_id, rank, status)
    call h5sget_simple_extent_dims_f(space_id, buffer, maximum, status)
    dims = buffer(1:rank)
    call h5sclose_f(space_id, status)
    call h5dclose_f(dataset_id, status)
  end function dims_of

  !> All values of a real dataset, in storage order.
  function reals_of(file_id, path) result(values)
    integer(hid_t), intent(in) :: file_id
    character(len=*), intent(in) :: path
    real(wp), allocatable, target :: values(:)
    integer(hid_t) :: dataset_id
    integer :: status
    type(c_ptr) :: buffer
    allocate (values(product(dims_of(file_id, path))))
    if (size(values) == 0) return
    call h5dopen_f(file_id, path, dataset_id, status)
    buffer = c_loc(values)
    call h5dread_f(dataset_id, h5kind_to_type(wp, H5_REAL_KIND), buffer, status)
    call h5dclose_f(dataset_id, status)
  end function reals_of

  !> All values of an integer dataset, in storage order.
  function integers_of(file_id, path) result(values)
    integer(hid_t), intent(in) :: file_id
    character(len=*), intent(in) :: path
    integer, allocatable, target :: values(:)
    integer(hid_t) :: dataset_id
    integer :: status
    type(c_ptr) :: buffer
    allocate (values(product(dims_of(file_id, path))))
    if (size(values) == 0) return
    call h5dopen_f(file_id, path, dataset_id, status)
    buffer = c_loc(values)
    call h5dread_f(dataset_id, H5T_NATIVE_INTEGER, buffer, status)
    call h5dclose_f(dataset_id, status)
  end function integers_of

  !> The first element of a variable-length string dataset ("" if it is not one).
  function first_string_of(file_id, path) result(text)
    integer(hid_t), intent(in) :: file_id
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: text
    type(c_ptr), allocatable, target :: pointers(:)
    integer(hid_t) :: dataset_id, file_type, memory_type, space_id
    integer :: status
    logical :: variable
    type(c_ptr) :: buffer

    text = ""
    allocate (pointers(product(dims_of(file_id, path))))
    if (size(pointers) == 0) return
    call h5dopen_f(file_id, path, dataset_id, status)
    call h5dget_type_f(dataset_id, file_type, status)
    call h5tis_variable_str_f(file_type, variable, status)
    call h5tclose_f(file_type, status)
    if (variable) then
      call h5tcopy_f(H5T_STRING, memory_type, status)
      buffer = c_loc(pointers)
      call h5dread_f(dataset_id, memory_type, buffer, status)
      text = c_string(pointers(1))
      call h5dget_space_f(dataset_id, space_id, status)
      call h5dvlen_reclaim_f(memory_type, space_id, H5P_DEFAULT_F, buffer, status)
      call h5sclose_f(space_id, status)
      call h5tclose_f(memory_type, status)
    end if
    call h5dclose_f(dataset_id, status)
  end function first_string_of

  !> A variable-length string attribute ("<missing>" or "<not variable-length>" otherwise).
  function string_attribute(file_id, object, name) result(text)
    integer(hid_t), intent(in) :: file_id
    character(len=*), intent(in) :: object, name
    character(len=:), allocatable :: text
    type(c_ptr), target :: pointer
    integer(hid_t) :: attribute_id, file_type, memory_type, space_id
    integer :: status
    logical :: variable
    type(c_ptr) :: buffer

    text = "<missing>"
    call h5aopen_by_name_f(file_id, object, name, attribute_id, status)
    if (status /= 0) return
    call h5aget_type_f(attribute_id, file_type, status)
    call h5tis_variable_str_f(file_type, variable, status)
    call h5tclose_f(file_type, status)
    text = "<not variable-length>"
    if (variable) then
      call h5tcopy_f(H5T_STRING, memory_type, status)
      pointer = c_null_ptr
      buffer = c_loc(pointer)
      call h5aread_f(attribute_id, memory_type, buffer, status)
      text = c_string(pointer)
      call h5screate_f(H5S_SCALAR_F, space_id, status)
      call h5dvlen_reclaim_f(memory_type, space_id, H5P_DEFAULT_F, buffer, status)
      call h5sclose_f(space_id, status)
      call h5tclose_f(memory_type, status)
    end if
    call h5aclose_f(attribute_id, status)
  end function string_attribute

  !> Copy a NUL-terminated C string.
  function c_string(pointer) result(text)
    type(c_ptr), intent(in) :: pointer
    character(len=:), allocatable :: text
    character(kind=c_char, len=1), pointer :: characters(:)
    integer :: length, position
    length = int(c_string_length(pointer))
    call c_f_pointer(pointer, characters, [length])
    allocate (character(len=length) :: text)
    do position = 1, length
      text(position:position) = characters(position)
    end do
  end function c_string

  real(wp) function real_attribute(file_id, object, name) result(value)
    integer(hid_t), intent(in) :: file_id
    character(len=*), intent(in) :: object, name
    real(wp), target :: buffer
    integer(hid_t) :: attribute_id
    integer :: status
    type(c_ptr) :: pointer
    buffer = -huge(1.0_wp)
    call h5aopen_by_name_f(file_id, object, name, attribute_id, status)
    if (status == 0) then
      pointer = c_loc(buffer)
      call h5aread_f(attribute_id, h5kind_to_type(wp, H5_REAL_KIND), pointer, status)
      call h5aclose_f(attribute_id, status)
    end if
    value = buffer
  end function real_attribute

  integer function integer_attribute(file_id, object, name) result(value)
    integer(hid_t), intent(in) :: file_id
    character(len=*), intent(in) :: object, name
    integer, target :: buffer
    integer(hid_t) :: attribute_id
    integer :: status
    type(c_ptr) :: pointer
    buffer = -huge(1)
    call h5aopen_by_name_f(file_id, object, name, attribute_id, status)
    if (status == 0) then
      pointer = c_loc(buffer)
      call h5aread_f(attribute_id, H5T_NATIVE_INTEGER, pointer, status)
      call h5aclose_f(attribute_id, status)
    end if
    value = buffer
  end function integer_attribute

  !> Size in bytes of an attribute's stored type (0 when missing).
  integer function attribute_size(file_id, object, name) result(bytes)
    integer(hid_t), intent(in) :: file_id
    character(len=*), intent(in) :: object, name
    integer(hid_t) :: attribute_id, file_type
    integer(size_t) :: type_size
    integer :: status
    bytes = 0
    call h5aopen_by_name_f(file_id, object, name, attribute_id, status)
    if (status /= 0) return
    call h5aget_type_f(attribute_id, file_type, status)
    call h5tget_size_f(file_type, type_size, status)
    bytes = int(type_size)
    call h5tclose_f(file_type, status)
    call h5aclose_f(attribute_id, status)
  end function attribute_size

  !> A whole text file as one string (lines joined by new lines).
  subroutine read_text_file(path, text)
    character(len=*), intent(in) :: path
    character(len=:), allocatable, intent(out) :: text
    character(len=4096) :: line
    integer :: unit, status
    text = ""
    open (newunit=unit, file=path, status="old", action="read", iostat=status)
    if (status /= 0) return
    do
      read (unit, '(a)', iostat=status) line
      if (status /= 0) exit
      text = text//trim(line)//new_line("a")
    end do
    close (unit)
  end subroutine read_text_file
end program test_results_file
