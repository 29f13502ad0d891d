!> LS-DYNA's `binout`: the history databases glstat, matsum, nodout, rwforc, rcforc and rbdout
!> in an LSDA file (lsda_file), in LS-DYNA's directories and variable names, so that
!> lasso-python's Binout, dynareadout and users' scripts read them as they read LS-DYNA's.
!>
!> Layout (as LS-DYNA writes it): `/<database>/metadata` holds title, version, revision, date
!> (text), `ids` (I4) and, for matsum, `legend` (the part titles, 80 characters each) and
!> `legend_ids`; for rcforc `ids` lists every contact twice, secondary side then primary side,
!> and `side` says which (0, 1). Each sample is a directory `/<database>/d000001`, `d000002`,
!> ...: `time`, then every variable as an array over the ids (glstat: one value). rwforc's
!> directories are under `/rwforc/forces`. Values are R8, the values results.h5 holds.
!>
!> What goes in comes from one table, `binout_table`: database, LS-DYNA's variable name, the
!> column of the history series (history_buffer) it is taken from, the component of a vector
!> column, a factor and how it is derived. A variable whose column the run does not record is
!> left out, so a quantity the histories gain later is one more row of the table.
!>
!> The file is written whole from the histories, under a hidden temporary name and then
!> renamed, so a reader never sees it half written; the output step calls `write_binout` at the last
!> output and at the states 1, 2, 4, 8, ... (the cost over the run is then at most about twice
!> that of the final file, and a run that is killed still leaves most of its histories).
module binout_file
  use, intrinsic :: iso_fortran_env, only: int32
  use kinds, only: wp
  use error_handling, only: error_t
  use model, only: model_t
  use history_buffer, only: history_set_t
  use lsda_file, only: lsda_file_t, create_lsda, change_lsda_directory, write_lsda, close_lsda
  use file_system, only: rename_file, remove_file
  use version, only: crashfree_version
  implicit none
  private

  public :: binout_requested, binout_name, write_binout

  !> How a variable is derived from its column.
  integer, parameter :: derived_none = 0
  integer, parameter :: derived_coordinate = 1   !< + the node's reference coordinate (nodout)

  !> One binout variable: where it goes and where its values come from.
  type :: binout_variable_t
    character(len=8) :: database = ""      !< glstat, matsum, nodout, rwforc, rcforc, rbdout
    character(len=32) :: name = ""         !< LS-DYNA's variable name
    character(len=32) :: column = ""       !< the history series' column
    integer :: component = 0               !< 0 a scalar column; 1-3 of a vector column
    real(wp) :: factor = 1.0_wp
    integer :: derived = derived_none
  end type binout_variable_t

  !> The databases in the order they are written, and their directories.
  character(len=8), parameter :: databases(6) = [character(len=8) :: "glstat", "matsum", "nodout", "rwforc", &
                                                 "rcforc", "rbdout"]

  !> Every variable written, by database. (LS-DYNA's names; see docs/output.md for those not
  !> filled yet.)
  type(binout_variable_t), parameter :: binout_table(*) = [ &
    binout_variable_t("glstat", "time_step", "time_step", 0, 1.0_wp, derived_none), &
    binout_variable_t("glstat", "kinetic_energy", "kinetic_energy", 0, 1.0_wp, derived_none), &
    binout_variable_t("glstat", "internal_energy", "internal_energy", 0, 1.0_wp, derived_none), &
    binout_variable_t("glstat", "hourglass_energy", "hourglass_energy", 0, 1.0_wp, derived_none), &
    binout_variable_t("glstat", "sliding_interface_energy", "contact_energy", 0, 1.0_wp, derived_none), &
    binout_variable_t("glstat", "external_work", "external_work", 0, 1.0_wp, derived_none), &
    binout_variable_t("glstat", "total_energy", "total_energy", 0, 1.0_wp, derived_none), &
    binout_variable_t("glstat", "stonewall_energy", "rigid_wall_energy", 0, 1.0_wp, derived_none), &
    binout_variable_t("glstat", "energy_ratio", "energy_ratio", 0, 1.0_wp, derived_none), &
    binout_variable_t("glstat", "added_mass", "added_mass", 0, 1.0_wp, derived_none), &
    binout_variable_t("glstat", "eroded_internal_energy", "eroded_internal_energy", 0, 1.0_wp, derived_none), &
    binout_variable_t("glstat", "eroded_hourglass_energy", "eroded_hourglass_energy", 0, 1.0_wp, derived_none), &
    binout_variable_t("glstat", "eroded_kinetic_energy", "eroded_kinetic_energy", 0, 1.0_wp, derived_none), &
    binout_variable_t("glstat", "cycle", "cycle", 0, 1.0_wp, derived_none), &
    binout_variable_t("glstat", "spring_and_damper_energy", "spring_damper_energy", 0, 1.0_wp, derived_none), &
    binout_variable_t("glstat", "system_damping_energy", "system_damping_energy", 0, 1.0_wp, derived_none), &
    binout_variable_t("glstat", "energy_ratio_wo_eroded", "energy_ratio_without_eroded", 0, 1.0_wp, derived_none), &
    binout_variable_t("glstat", "percent_increase", "percent_mass_increase", 0, 1.0_wp, derived_none), &
    binout_variable_t("glstat", "global_x_velocity", "global_velocity", 1, 1.0_wp, derived_none), &
    binout_variable_t("glstat", "global_y_velocity", "global_velocity", 2, 1.0_wp, derived_none), &
    binout_variable_t("glstat", "global_z_velocity", "global_velocity", 3, 1.0_wp, derived_none), &
    binout_variable_t("matsum", "kinetic_energy", "kinetic_energy", 0, 1.0_wp, derived_none), &
    binout_variable_t("matsum", "internal_energy", "internal_energy", 0, 1.0_wp, derived_none), &
    binout_variable_t("matsum", "hourglass_energy", "hourglass_energy", 0, 1.0_wp, derived_none), &
    binout_variable_t("matsum", "x_momentum", "momentum", 1, 1.0_wp, derived_none), &
    binout_variable_t("matsum", "y_momentum", "momentum", 2, 1.0_wp, derived_none), &
    binout_variable_t("matsum", "z_momentum", "momentum", 3, 1.0_wp, derived_none), &
    binout_variable_t("matsum", "x_rbvelocity", "rigid_body_velocity", 1, 1.0_wp, derived_none), &
    binout_variable_t("matsum", "y_rbvelocity", "rigid_body_velocity", 2, 1.0_wp, derived_none), &
    binout_variable_t("matsum", "z_rbvelocity", "rigid_body_velocity", 3, 1.0_wp, derived_none), &
    binout_variable_t("matsum", "mass", "mass", 0, 1.0_wp, derived_none), &
    binout_variable_t("nodout", "x_displacement", "displacement", 1, 1.0_wp, derived_none), &
    binout_variable_t("nodout", "y_displacement", "displacement", 2, 1.0_wp, derived_none), &
    binout_variable_t("nodout", "z_displacement", "displacement", 3, 1.0_wp, derived_none), &
    binout_variable_t("nodout", "x_velocity", "velocity", 1, 1.0_wp, derived_none), &
    binout_variable_t("nodout", "y_velocity", "velocity", 2, 1.0_wp, derived_none), &
    binout_variable_t("nodout", "z_velocity", "velocity", 3, 1.0_wp, derived_none), &
    binout_variable_t("nodout", "x_acceleration", "acceleration", 1, 1.0_wp, derived_none), &
    binout_variable_t("nodout", "y_acceleration", "acceleration", 2, 1.0_wp, derived_none), &
    binout_variable_t("nodout", "z_acceleration", "acceleration", 3, 1.0_wp, derived_none), &
    binout_variable_t("nodout", "cycle", "cycle", 0, 1.0_wp, derived_none), &
    binout_variable_t("nodout", "x_coordinate", "displacement", 1, 1.0_wp, derived_coordinate), &
    binout_variable_t("nodout", "y_coordinate", "displacement", 2, 1.0_wp, derived_coordinate), &
    binout_variable_t("nodout", "z_coordinate", "displacement", 3, 1.0_wp, derived_coordinate), &
    binout_variable_t("rwforc", "normal_force", "normal_force", 0, 1.0_wp, derived_none), &
    binout_variable_t("rwforc", "x_force", "force", 1, 1.0_wp, derived_none), &
    binout_variable_t("rwforc", "y_force", "force", 2, 1.0_wp, derived_none), &
    binout_variable_t("rwforc", "z_force", "force", 3, 1.0_wp, derived_none), &
    binout_variable_t("rcforc", "x_force", "force", 1, 1.0_wp, derived_none), &
    binout_variable_t("rcforc", "y_force", "force", 2, 1.0_wp, derived_none), &
    binout_variable_t("rcforc", "z_force", "force", 3, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "global_dx", "displacement", 1, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "global_dy", "displacement", 2, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "global_dz", "displacement", 3, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "global_vx", "velocity", 1, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "global_vy", "velocity", 2, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "global_vz", "velocity", 3, 1.0_wp, derived_none), &
    ! (LS-DYNA's dircos_ij: component j of body axis i, the rows of rbdout's direction vectors)
    binout_variable_t("rbdout", "global_x", "coordinates", 1, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "global_y", "coordinates", 2, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "global_z", "coordinates", 3, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "global_ax", "acceleration", 1, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "global_ay", "acceleration", 2, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "global_az", "acceleration", 3, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "global_rdx", "rotation", 1, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "global_rdy", "rotation", 2, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "global_rdz", "rotation", 3, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "global_rvx", "angular_velocity", 1, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "global_rvy", "angular_velocity", 2, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "global_rvz", "angular_velocity", 3, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "global_rax", "angular_acceleration", 1, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "global_ray", "angular_acceleration", 2, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "global_raz", "angular_acceleration", 3, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "dircos_11", "direction_cosines", 1, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "dircos_12", "direction_cosines", 2, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "dircos_13", "direction_cosines", 3, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "dircos_21", "direction_cosines", 4, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "dircos_22", "direction_cosines", 5, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "dircos_23", "direction_cosines", 6, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "dircos_31", "direction_cosines", 7, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "dircos_32", "direction_cosines", 8, 1.0_wp, derived_none), &
    binout_variable_t("rbdout", "dircos_33", "direction_cosines", 9, 1.0_wp, derived_none)]

contains

  !> Whether any history database asks for binout (BINARY 2 or 3).
  logical function binout_requested(model)
    type(model_t), intent(in) :: model
    binout_requested = any([model%output%glstat_binary, model%output%matsum_binary, model%output%nodout_binary, &
                            model%output%rwforc_binary, model%output%rcforc_binary, model%output%rbdout_binary] >= 2)
  end function binout_requested

  !> The file name LS-DYNA gives it: `binout`, or `JOBID.binout` for a job named on the command
  !> line (crashfree's default job id, "results", is taken as none).
  pure function binout_name(job_id) result(name)
    character(len=*), intent(in) :: job_id
    character(len=:), allocatable :: name
    if (len_trim(job_id) == 0 .or. job_id == "results") then
      name = "binout"
    else
      name = trim(job_id)//".binout"
    end if
  end function binout_name

  !> Write `path` whole from the histories recorded so far (the databases whose BINARY is 2 or
  !> 3): as the hidden `.NAME.partial` beside it (which a reader's glob `binout*` does not
  !> pick up, should a killed run leave it), then renamed to `path`.
  subroutine write_binout(model, histories, path, error)
    type(model_t), intent(in) :: model
    type(history_set_t), intent(in) :: histories
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: error
    type(lsda_file_t) :: file
    type(error_t), allocatable :: close_error
    character(len=:), allocatable :: partial
    integer :: k, slash

    if (.not. binout_requested(model)) return
    slash = index(path, "/", back=.true.)
    partial = path(1:slash)//"."//path(slash + 1:)//".partial"
    call create_lsda(file, partial, error)
    do k = 1, size(databases)
      if (allocated(error)) exit
      if (database_binary(model, databases(k)) >= 2) call write_database(model, histories, databases(k), file, error)
    end do
    call close_lsda(file, close_error)
    if (.not. allocated(error) .and. allocated(close_error)) call move_alloc(close_error, error)
    if (allocated(error)) then
      call remove_file(partial)
      error%message = "binout: "//error%message
      return
    end if
    call rename_file(partial, path, error)
    if (allocated(error)) error%message = "binout: "//error%message
  end subroutine write_binout

  integer function database_binary(model, database)
    type(model_t), intent(in) :: model
    character(len=*), intent(in) :: database
    select case (database)
    case ("glstat")
      database_binary = model%output%glstat_binary
    case ("matsum")
      database_binary = model%output%matsum_binary
    case ("nodout")
      database_binary = model%output%nodout_binary
    case ("rwforc")
      database_binary = model%output%rwforc_binary
    case ("rcforc")
      database_binary = model%output%rcforc_binary
    case default
      database_binary = model%output%rbdout_binary
    end select
  end function database_binary

  !> One database: its metadata and a directory per sample. Its series are "glstat" or
  !> "<database>/<id>" (one per part, node, wall, contact, rigid body, in the model's order);
  !> a database the run did not record is left out.
  subroutine write_database(model, histories, database, file, error)
    type(model_t), intent(in) :: model
    type(history_set_t), intent(in) :: histories
    character(len=*), intent(in) :: database
    type(lsda_file_t), intent(inout) :: file
    type(error_t), allocatable, intent(out) :: error
    integer, allocatable :: series(:), ids(:), columns(:), offsets(:)
    real(wp), allocatable :: values(:)
    character(len=:), allocatable :: base
    character(len=16) :: sample
    integer :: k, row, entity, sides, count, rows

    call find_series(histories, database, series, ids)
    count = size(series)
    if (count == 0) return
    rows = histories%series(series(1))%count
    ! all series of a database share one clock; a shorter one (none expected) limits the rows
    do k = 2, count
      rows = min(rows, histories%series(series(k))%count)
    end do
    sides = merge(2, 1, database == "rcforc")
    base = "/"//trim(database)
    if (database == "rwforc") base = base//"/forces"
    call write_metadata(model, database, base, ids, sides, file, error)
    if (allocated(error)) return

    ! the columns of this database's variables in its series (0: not recorded), and their
    ! first value in a row
    allocate (columns(size(binout_table)), offsets(size(binout_table)))
    do k = 1, size(binout_table)
      columns(k) = 0
      offsets(k) = 0
      if (binout_table(k)%database /= database) cycle
      call find_column(histories, series(1), binout_table(k)%column, binout_table(k)%component, columns(k), &
                       offsets(k))
    end do
    allocate (values(sides*count))
    do row = 1, rows
      write (sample, '("d", i0.6)') row
      call change_lsda_directory(file, base//"/"//trim(sample))
      call write_lsda(file, "time", [histories%series(series(1))%rows(1, row)], error)
      if (allocated(error)) return
      do k = 1, size(binout_table)
        if (columns(k) == 0) cycle
        do entity = 1, count
          values(sides*entity) = sample_value(model, histories%series(series(entity))%rows(:, row), &
                                              binout_table(k), offsets(k), entity)
          ! rcforc: the secondary side's force, then the primary side's (its opposite)
          if (sides == 2) values(sides*entity - 1:sides*entity) = [values(sides*entity), -values(sides*entity)]
        end do
        call write_lsda(file, trim(binout_table(k)%name), values, error)
        if (allocated(error)) return
      end do
    end do
  end subroutine write_database

  !> The value of one variable for one entity from its history row.
  real(wp) function sample_value(model, row, variable, offset, entity) result(value)
    type(model_t), intent(in) :: model
    real(wp), intent(in) :: row(:)
    type(binout_variable_t), intent(in) :: variable
    integer, intent(in) :: offset, entity
    select case (variable%derived)
    case (derived_coordinate)
      value = row(offset) + model%coordinates(variable%component, model%output%history_nodes(entity))
    case default
      value = variable%factor*row(offset)
    end select
  end function sample_value

  !> title, version, revision, date, ids (and matsum's legend, rcforc's sides).
  subroutine write_metadata(model, database, base, ids, sides, file, error)
    type(model_t), intent(in) :: model
    character(len=*), intent(in) :: database, base
    integer, intent(in) :: ids(:), sides
    type(lsda_file_t), intent(inout) :: file
    type(error_t), allocatable, intent(out) :: error
    character(len=8) :: today
    character(len=80) :: title
    character(len=:), allocatable :: legend
    integer :: k

    call date_and_time(date=today)
    title = ""
    if (allocated(model%title)) title = model%title
    call change_lsda_directory(file, base//"/metadata")
    call write_lsda(file, "title", title, error)
    if (.not. allocated(error)) call write_lsda(file, "version", "crashfree "//crashfree_version, error)
    if (.not. allocated(error)) call write_lsda(file, "revision", crashfree_version, error)
    if (.not. allocated(error)) call write_lsda(file, "date", today(5:6)//"/"//today(7:8)//"/"//today(1:4), error)
    if (allocated(error)) return
    if (database == "glstat") return
    if (sides == 2) then
      call write_lsda(file, "ids", int([(ids((k + 1)/2), k=1, 2*size(ids))], int32), error)
      if (.not. allocated(error)) call write_lsda(file, "side", int([(mod(k + 1, 2), k=1, 2*size(ids))], int32), &
                                                  error)
    else
      call write_lsda(file, "ids", int(ids, int32), error)
    end if
    if (allocated(error) .or. database /= "matsum") return
    legend = ""
    do k = 1, size(ids)
      title = ""
      if (allocated(model%parts(k)%title)) title = model%parts(k)%title
      legend = legend//title
    end do
    call write_lsda(file, "legend", legend, error)
    if (.not. allocated(error)) call write_lsda(file, "legend_ids", int(ids, int32), error)
  end subroutine write_metadata

  !> The series of a database ("glstat", or "<database>/<id>" in the order recorded) and the
  !> ids their names carry (glstat: none).
  subroutine find_series(histories, database, series, ids)
    type(history_set_t), intent(in) :: histories
    character(len=*), intent(in) :: database
    integer, allocatable, intent(out) :: series(:), ids(:)
    integer :: k, id, status
    character(len=:), allocatable :: prefix
    allocate (series(0), ids(0))
    prefix = trim(database)//"/"
    do k = 1, histories%count
      associate (group => histories%series(k)%group)
        if (group == trim(database)) then
          series = [series, k]
          ids = [ids, 0]
        else if (len(group) > len(prefix)) then
          if (group(1:len(prefix)) /= prefix) cycle
          read (group(len(prefix) + 1:), *, iostat=status) id
          if (status /= 0) cycle
          series = [series, k]
          ids = [ids, id]
        end if
      end associate
    end do
  end subroutine find_series

  !> The position in a row of a column's value (its component of a vector column); 0 in
  !> `column` when the series has no such column.
  subroutine find_column(histories, series, name, component, column, offset)
    type(history_set_t), intent(in) :: histories
    integer, intent(in) :: series
    character(len=*), intent(in) :: name
    integer, intent(in) :: component
    integer, intent(out) :: column, offset
    integer :: k, first
    column = 0
    offset = 0
    first = 1
    associate (found => histories%series(series))
      do k = 1, size(found%names)
        if (found%names(k) == name) then
          ! a scalar column has no component; a vector column needs one, except where the
          ! value is derived from the whole vector (wall normal force)
          if (found%widths(k) == 1 .and. component > 1) return
          column = k
          offset = first + max(component, 1) - 1
          return
        end if
        first = first + found%widths(k)
      end do
    end associate
  end subroutine find_column
end module binout_file
