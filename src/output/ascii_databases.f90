!> LS-DYNA's ASCII history files (glstat, matsum, nodout, rwforc, rcforc, rbdout) written beside
!> results.h5 from the run's histories, in LS-DYNA's layout (labels, column positions and
!> number formats as LS-DYNA and its binout-to-ASCII translator write them), so that the
!> parsers crash engineers already use read them. A file is written when the deck has its
!> *DATABASE_<name> keyword with BINARY 1 or 3 (blank or 0: 1); results.h5 holds every history
!> whatever BINARY says. The layouts are documented in docs/output.md.
!>
!> The files are written at the end of the run (normal or error termination) from the
!> in-memory histories, so that a restart, which continues those histories, writes complete
!> files too. Their text goes to the file as it is produced, through a buffer of bounded size
!> (text_writer_t): a file is never held whole in memory (d3hsp echoes the whole deck, which
!> is gigabytes for a full vehicle).
module ascii_databases
  use kinds, only: wp
  use error_handling, only: error_t, make_error
  use model, only: model_t
  use history_buffer, only: history_set_t, history_series_t
  use version, only: crashfree_version
  use file_system, only: write_text_file
  implicit none
  private

  public :: write_ascii_databases, lsdyna_file_path, c_exponential, text_writer_t, begin_text, add_line, add_text, &
            start_database, finish_database

  !> Bytes a text_writer_t holds before it hands them to its file.
  integer, parameter :: writer_capacity = 1048576

  !> A text file being written: `begin_text` names it, `add_line` and `add_text` append to
  !> `buffer(1:length)`, which goes to the file (created by the first write, appended to by the
  !> next) whenever the next piece would not fit, and `finish_database` writes the rest and
  !> reports the first failure. The memory it takes is at most writer_capacity whatever the size
  !> of the file.
  type :: text_writer_t
    character(len=:), allocatable :: path
    character(len=:), allocatable :: buffer
    integer :: length = 0
    logical :: created = .false.                  !< the file has been created (next writes append)
    type(error_t), allocatable :: error           !< the first write that failed (later ones skipped)
  end type text_writer_t

contains

  !> Every ASCII file the deck asks for, in `directory`, named as LS-DYNA names them
  !> (`glstat`; with jobid=NAME `NAME.glstat`).
  subroutine write_ascii_databases(model, histories, directory, job_id, error)
    type(model_t), intent(in) :: model
    type(history_set_t), intent(in) :: histories
    character(len=*), intent(in) :: directory, job_id
    type(error_t), allocatable, intent(out) :: error
    if (wanted(model%output%glstat_interval, model%output%glstat_binary)) then
      call write_glstat(model, histories, lsdyna_file_path(directory, job_id, "glstat"), error)
      if (allocated(error)) return
    end if
    if (wanted(model%output%matsum_interval, model%output%matsum_binary)) then
      call write_matsum(model, histories, lsdyna_file_path(directory, job_id, "matsum"), error)
      if (allocated(error)) return
    end if
    if (wanted(model%output%nodout_interval, model%output%nodout_binary)) then
      call write_nodout(model, histories, lsdyna_file_path(directory, job_id, "nodout"), error)
      if (allocated(error)) return
    end if
    if (wanted(model%output%rwforc_interval, model%output%rwforc_binary) .and. size(model%walls) > 0) then
      call write_rwforc(model, histories, lsdyna_file_path(directory, job_id, "rwforc"), error)
      if (allocated(error)) return
    end if
    if (allocated(model%rigid_bodies)) then
      if (wanted(model%output%rbdout_interval, model%output%rbdout_binary) .and. size(model%rigid_bodies) > 0) then
        call write_rbdout(model, histories, lsdyna_file_path(directory, job_id, "rbdout"), error)
        if (allocated(error)) return
      end if
    end if
    if (allocated(model%contacts)) then
      if (wanted(model%output%rcforc_interval, model%output%rcforc_binary) .and. size(model%contacts) > 0) then
        call write_rcforc(model, histories, lsdyna_file_path(directory, job_id, "rcforc"), error)
        if (allocated(error)) return
      end if
    end if
  end subroutine write_ascii_databases

  !> `directory/name`, or `directory/JOB.name` when a job id other than the default was given
  !> (LS-DYNA prefixes its files with jobid=).
  function lsdyna_file_path(directory, job_id, name) result(path)
    character(len=*), intent(in) :: directory, job_id, name
    character(len=:), allocatable :: path
    if (job_id == "results" .or. len_trim(job_id) == 0) then
      path = directory//"/"//name
    else
      path = directory//"/"//trim(job_id)//"."//name
    end if
  end function lsdyna_file_path

  !> A history database is in the deck (its interval > 0) and asks for the ASCII file.
  logical function wanted(interval, binary)
    real(wp), intent(in) :: interval
    integer, intent(in) :: binary
    wanted = interval > 0.0_wp .and. (binary == 1 .or. binary == 3)
  end function wanted

  !> A real as C's printf %<width>.<digits>E writes it (LS-DYNA's files are written so): a
  !> two-digit exponent below 100, three above; right-justified in `width`.
  function c_exponential(value, width, digits) result(text)
    real(wp), intent(in) :: value
    integer, intent(in) :: width, digits
    character(len=width) :: text
    character(len=64) :: buffer, format_text
    integer :: mark
    if (value /= value) then
      text = adjustr("nan")
      return
    end if
    if (abs(value) > huge(1.0_wp)) then
      text = adjustr(merge("-inf", " inf", value < 0.0_wp))
      return
    end if
    write (format_text, '(a,i0,a,i0,a)') "(es", digits + 8, ".", digits, "e3)"
    write (buffer, format_text) value
    buffer = adjustl(buffer)
    mark = index(buffer, "E")
    ! E+012 -> E+12 (C keeps at least two exponent digits)
    if (mark > 0) then
      if (buffer(mark + 2:mark + 2) == "0") buffer = buffer(1:mark + 1)//buffer(mark + 3:)
    end if
    if (len_trim(buffer) > width) then
      text = trim(buffer)       ! (C widens the field; Fortran truncates: keep the leading part)
    else
      text = adjustr(buffer(1:width))
    end if
  end function c_exponential

  !> The series of a history group, 0 when it was not recorded.
  integer function series_index(histories, group)
    type(history_set_t), intent(in) :: histories
    character(len=*), intent(in) :: group
    integer :: k
    series_index = 0
    do k = 1, histories%count
      if (histories%series(k)%group == group) then
        series_index = k
        return
      end if
    end do
  end function series_index

  !> Position of a column's first component in a row (0: no such column).
  integer function column(series, name)
    type(history_series_t), intent(in) :: series
    character(len=*), intent(in) :: name
    integer :: k
    column = 0
    do k = 1, size(series%names)
      if (series%names(k) == name) then
        column = sum(series%widths(1:k - 1)) + 1
        return
      end if
    end do
  end function column

  !> A column's value in row `row` (0 when the column does not exist).
  real(wp) function value_of(series, name, row, component)
    type(history_series_t), intent(in) :: series
    character(len=*), intent(in) :: name
    integer, intent(in) :: row
    integer, intent(in), optional :: component
    integer :: position
    value_of = 0.0_wp
    position = column(series, name)
    if (position == 0) return
    if (present(component)) position = position + component - 1
    value_of = series%rows(position, row)
  end function value_of

  !> The file `path` begun (begin_text) with LS-DYNA's first two lines: the title, then the
  !> program, its version and the date.
  subroutine start_database(model, out, path)
    type(model_t), intent(in) :: model
    type(text_writer_t), intent(out) :: out
    character(len=*), intent(in) :: path
    character(len=8) :: date
    call begin_text(out, path)
    call date_and_time(date=date)
    if (allocated(model%title)) then
      call add_line(out, " "//model%title(1:min(len(model%title), 72)))
    else
      call add_line(out, " ")
    end if
    call add_line(out, "                         crashfree (version "//crashfree_version//")     date "// &
      date(5:6)//"/"//date(7:8)//"/"//date(1:4))
  end subroutine start_database

  !> The history series "<database>/<id>" of each id, and the rows all of them hold; false when
  !> one of them was not recorded.
  logical function series_of(histories, database, ids, series, rows) result(found)
    type(history_set_t), intent(in) :: histories
    character(len=*), intent(in) :: database
    integer, intent(in) :: ids(:)
    integer, allocatable, intent(out) :: series(:)
    integer, intent(out) :: rows
    character(len=16) :: id_text
    integer :: k
    allocate (series(size(ids)))
    rows = huge(1)
    found = .false.
    do k = 1, size(ids)
      write (id_text, '(i0)') ids(k)
      series(k) = series_index(histories, database//"/"//trim(id_text))
      if (series(k) == 0) return
      rows = min(rows, histories%series(series(k))%count)
    end do
    found = .true.
  end function series_of

  !> A writer for the file `path` (nothing is written before the first buffer is full or
  !> finish_database is called).
  subroutine begin_text(out, path)
    type(text_writer_t), intent(out) :: out
    character(len=*), intent(in) :: path
    out%path = path
  end subroutine begin_text

  !> Append one line and its new line to the file of `out`.
  subroutine add_line(out, line)
    type(text_writer_t), intent(inout) :: out
    character(len=*), intent(in) :: line
    call add_text(out, line)
    call add_text(out, new_line("a"))
  end subroutine add_line

  !> Append `text` as it is (no new line added) to the file of `out`: into the buffer, which is
  !> written out first when `text` does not fit; a text longer than the buffer goes straight to
  !> the file.
  subroutine add_text(out, text)
    type(text_writer_t), intent(inout) :: out
    character(len=*), intent(in) :: text
    if (.not. allocated(out%buffer)) allocate (character(len=writer_capacity) :: out%buffer)
    if (out%length + len(text) > len(out%buffer)) then
      call write_buffer(out)
      if (len(text) > len(out%buffer)) then
        call write_piece(out, text)
        return
      end if
    end if
    out%buffer(out%length + 1:out%length + len(text)) = text
    out%length = out%length + len(text)
  end subroutine add_text

  !> The buffer to the file, emptied.
  subroutine write_buffer(out)
    type(text_writer_t), intent(inout) :: out
    if (out%length > 0) call write_piece(out, out%buffer(1:out%length))
    out%length = 0
  end subroutine write_buffer

  !> `text` to the file: the first piece creates (or replaces) it, the next ones are appended;
  !> after a failure nothing more is written.
  subroutine write_piece(out, text)
    type(text_writer_t), intent(inout) :: out
    character(len=*), intent(in) :: text
    if (allocated(out%error)) return
    call write_text_file(out%path, text, out%error, append=out%created)
    out%created = .true.
  end subroutine write_piece

  !> The rest of the text to the file (an empty file when nothing was added), the buffer
  !> released, and the first failure of the file's writes reported. Writes go through C's stdio
  !> (file_system's write_text_file), which reports a full disk; gfortran's formatted writes
  !> would cut the file short without a word.
  subroutine finish_database(out, error)
    type(text_writer_t), intent(inout) :: out
    type(error_t), allocatable, intent(out) :: error
    integer :: mark
    if (allocated(out%buffer)) call write_buffer(out)
    if (.not. out%created) call write_piece(out, "")
    if (allocated(out%buffer)) deallocate (out%buffer)
    if (.not. allocated(out%error)) return
    call move_alloc(out%error, error)
    ! "...: no space left on device", as the results file's messages say it
    mark = index(error%message, ": ", back=.true.) + 2
    if (mark > 2 .and. mark <= len(error%message)) then
      if (error%message(mark:mark) >= "A" .and. error%message(mark:mark) <= "Z") &
        error%message(mark:mark) = achar(iachar(error%message(mark:mark)) + 32)
    end if
  end subroutine finish_database

  !> A glstat line: the label padded with dots to 31 characters after a blank, then %14.5E.
  subroutine glstat_line(out, label, value)
    type(text_writer_t), intent(inout) :: out
    character(len=*), intent(in) :: label
    real(wp), intent(in) :: value
    character(len=32) :: padded
    padded = " "//label//repeat(".", 31)
    call add_line(out, padded//c_exponential(value, 14, 5))
  end subroutine glstat_line

  !> glstat: per sample " dt of cycle" with the cycle number, then LS-DYNA's lines.
  subroutine write_glstat(model, histories, path, error)
    type(model_t), intent(in) :: model
    type(history_set_t), intent(in) :: histories
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: error
    type(text_writer_t) :: out
    integer :: s, row
    character(len=32) :: cycle_text
    s = series_index(histories, "glstat")
    if (s == 0) return
    call start_database(model, out, path)
    associate (series => histories%series(s))
      do row = 1, series%count
        write (cycle_text, '(i8)') nint(value_of(series, "cycle", row))
        call add_line(out, "")
        call add_line(out, "")
        call add_line(out, " dt of cycle"//trim(cycle_text)//controller_text(series, row))
        call add_line(out, "")
        call glstat_line(out, "time", value_of(series, "time", row))
        call glstat_line(out, "time step", value_of(series, "time_step", row))
        call glstat_line(out, "kinetic energy", value_of(series, "kinetic_energy", row))
        call glstat_line(out, "internal energy", value_of(series, "internal_energy", row))
        if (size(model%walls) > 0) call glstat_line(out, "stonewall energy", value_of(series, "rigid_wall_energy", row))
        call glstat_line(out, "spring and damper energy", value_of(series, "spring_damper_energy", row))
        call glstat_line(out, "hourglass energy ", value_of(series, "hourglass_energy", row))
        call glstat_line(out, "system damping energy", value_of(series, "system_damping_energy", row))
        call glstat_line(out, "sliding interface energy", value_of(series, "contact_energy", row))
        call glstat_line(out, "external work", value_of(series, "external_work", row))
        call glstat_line(out, "eroded kinetic energy", value_of(series, "eroded_kinetic_energy", row))
        call glstat_line(out, "eroded internal energy", value_of(series, "eroded_internal_energy", row))
        call glstat_line(out, "eroded hourglass energy", value_of(series, "eroded_hourglass_energy", row))
        call glstat_line(out, "total energy", value_of(series, "total_energy", row))
        call glstat_line(out, "total energy / initial energy", value_of(series, "energy_ratio", row))
        call glstat_line(out, "energy ratio w/o eroded energy", value_of(series, "energy_ratio_without_eroded", row))
        call glstat_line(out, "global x velocity", value_of(series, "global_velocity", row, 1))
        call glstat_line(out, "global y velocity", value_of(series, "global_velocity", row, 2))
        call glstat_line(out, "global z velocity", value_of(series, "global_velocity", row, 3))
        call add_line(out, "")
        call add_line(out, "")
        call glstat_line(out, "added mass", value_of(series, "added_mass", row))
        call glstat_line(out, "percentage increase", value_of(series, "percent_mass_increase", row))
      end do
    end associate
    call finish_database(out, error)
  end subroutine write_glstat

  !> The end of glstat's "dt of cycle" line: " is controlled by solid   <id> of part   <id>", as
  !> LS-DYNA writes it; nothing when no element set the step (a rigid body's step).
  function controller_text(series, row) result(text)
    type(history_series_t), intent(in) :: series
    integer, intent(in) :: row
    character(len=:), allocatable :: text
    character(len=10), parameter :: families(3) = [character(len=10) :: "solid", "shell", "beam"]
    character(len=64) :: buffer
    integer :: family
    text = ""
    family = nint(value_of(series, "controlling_element_family", row))
    if (family < 1 .or. family > size(families)) return
    write (buffer, '(a,a10,i10,a,i10)') " is controlled by ", families(family), &
      nint(value_of(series, "controlling_element", row)), " of part", nint(value_of(series, "controlling_part", row))
    text = trim(buffer)
  end function controller_text

  !> The legend of part, wall or contact titles LS-DYNA writes after the header.
  subroutine write_legend(out, ids, titles)
    type(text_writer_t), intent(inout) :: out
    integer, intent(in) :: ids(:)
    character(len=*), intent(in) :: titles(:)
    integer :: k
    character(len=9) :: id_text
    if (all(len_trim(titles) == 0)) return
    call add_line(out, "")
    call add_line(out, "{BEGIN LEGEND")
    call add_line(out, " Entity #        Title")
    do k = 1, size(ids)
      write (id_text, '(i9)') ids(k)
      call add_line(out, id_text//"     "//trim(titles(k)))
    end do
    call add_line(out, "{END LEGEND}")
    call add_line(out, "")
  end subroutine write_legend

  !> matsum: per sample "time =", then per part its energies, momentum, rigid-body velocity,
  !> hourglass energy and mass.
  subroutine write_matsum(model, histories, path, error)
    type(model_t), intent(in) :: model
    type(history_set_t), intent(in) :: histories
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: error
    integer, allocatable :: part_series(:)
    character(len=70), allocatable :: titles(:)
    character(len=16) :: id_text
    type(text_writer_t) :: out
    integer :: k, row, rows
    allocate (titles(size(model%parts)))
    if (.not. series_of(histories, "matsum", model%parts%id, part_series, rows)) return
    do k = 1, size(model%parts)
      titles(k) = ""
      if (allocated(model%parts(k)%title)) titles(k) = model%parts(k)%title
    end do
    if (size(model%parts) == 0) return
    call start_database(model, out, path)
    call write_legend(out, model%parts%id, titles)
    do row = 1, rows
      call add_line(out, "")
      call add_line(out, "")
      call add_line(out, " time ="//c_exponential(histories%series(part_series(1))%rows(1, row), 13, 4))
      do k = 1, size(model%parts)
        associate (series => histories%series(part_series(k)))
          if (model%parts(k)%id < 100000) then
            write (id_text, '(i5,3x)') model%parts(k)%id
          else
            write (id_text, '(i8)') model%parts(k)%id
          end if
          call add_line(out, " mat.#="//id_text(1:8)//"          inten="// &
            c_exponential(value_of(series, "internal_energy", row), 13, 4)//"     kinen="// &
            c_exponential(value_of(series, "kinetic_energy", row), 13, 4))
          call add_line(out, " x-mom="//c_exponential(value_of(series, "momentum", row, 1), 13, 4)// &
            "     y-mom="//c_exponential(value_of(series, "momentum", row, 2), 13, 4)// &
            "     z-mom="//c_exponential(value_of(series, "momentum", row, 3), 13, 4))
          call add_line(out, " x-rbv="//c_exponential(value_of(series, "rigid_body_velocity", row, 1), 13, 4)// &
            "     y-rbv="//c_exponential(value_of(series, "rigid_body_velocity", row, 2), 13, 4)// &
            "     z-rbv="//c_exponential(value_of(series, "rigid_body_velocity", row, 3), 13, 4))
          call add_line(out, "                         hgeng="// &
            c_exponential(value_of(series, "hourglass_energy", row), 13, 4)//"     +mass="// &
            c_exponential(value_of(series, "mass", row), 13, 4))
        end associate
      end do
    end do
    call finish_database(out, error)
  end subroutine write_matsum

  !> nodout: per sample the "n o d a l   p r i n t   o u t" block, one line per history node.
  subroutine write_nodout(model, histories, path, error)
    type(model_t), intent(in) :: model
    type(history_set_t), intent(in) :: histories
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: error
    integer, allocatable :: node_series(:)
    character(len=9) :: node_text
    character(len=8) :: cycle_text
    type(text_writer_t) :: out
    integer :: k, j, row, rows, node
    character(len=:), allocatable :: line
    if (.not. allocated(model%output%history_nodes)) return
    if (size(model%output%history_nodes) == 0) return
    if (.not. series_of(histories, "nodout", model%node_ids(model%output%history_nodes), node_series, rows)) return
    call start_database(model, out, path)
    do row = 1, rows
      associate (first => histories%series(node_series(1)))
        write (cycle_text, '(i8)') nint(value_of(first, "cycle", row))
        call add_line(out, "")
        call add_line(out, "")
        call add_line(out, "")
        call add_line(out, " n o d a l   p r i n t   o u t   f o r   t i m e  s t e p"//cycle_text// &
          "                              ( at time"//c_exponential(first%rows(1, row), 12, 5)//" )")
      end associate
      call add_line(out, "")
      call add_line(out, " nodal point  x-disp     y-disp      z-disp      x-vel       y-vel       z-vel      "// &
        "x-accl      y-accl      z-accl      x-coor      y-coor      z-coor")
      do k = 1, size(node_series)
        node = model%output%history_nodes(k)
        associate (series => histories%series(node_series(k)))
          write (node_text, '(i9)') model%node_ids(node)
          line = node_text//c_exponential(value_of(series, "displacement", row, 1), 13, 4)
          do j = 2, 3
            line = line//c_exponential(value_of(series, "displacement", row, j), 12, 4)
          end do
          do j = 1, 3
            line = line//c_exponential(value_of(series, "velocity", row, j), 12, 4)
          end do
          do j = 1, 3
            line = line//c_exponential(value_of(series, "acceleration", row, j), 12, 4)
          end do
          do j = 1, 3
            line = line//c_exponential(model%coordinates(j, node) + value_of(series, "displacement", row, j), 12, 4)
          end do
          call add_line(out, line)
        end associate
      end do
    end do
    call finish_database(out, error)
  end subroutine write_nodout

  !> rwforc: one line per sample and wall: time, wall id, normal force, x, y, z force (the
  !> force the wall exerts on the structure).
  subroutine write_rwforc(model, histories, path, error)
    type(model_t), intent(in) :: model
    type(history_set_t), intent(in) :: histories
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: error
    integer, allocatable :: wall_series(:)
    character(len=70), allocatable :: titles(:)
    character(len=8) :: wall_text
    type(text_writer_t) :: out
    integer :: k, j, row, rows
    character(len=:), allocatable :: line
    allocate (titles(size(model%walls)))
    if (.not. series_of(histories, "rwforc", model%walls%id, wall_series, rows)) return
    do k = 1, size(model%walls)
      titles(k) = ""
      if (allocated(model%walls(k)%title)) titles(k) = model%walls(k)%title
    end do
    call start_database(model, out, path)
    call write_legend(out, model%walls%id, titles)
    call add_line(out, "")
    call add_line(out, "")
    call add_line(out, "    time       wall#   normal-force    x-force        y-force        z-force")
    do row = 1, rows
      do k = 1, size(model%walls)
        associate (series => histories%series(wall_series(k)))
          write (wall_text, '(i8)') model%walls(k)%id
          line = c_exponential(series%rows(1, row), 12, 5)//wall_text// &
            c_exponential(value_of(series, "normal_force", row), 15, 6)
          do j = 1, 3
            line = line//c_exponential(value_of(series, "force", row, j), 15, 6)
          end do
          call add_line(out, line)
        end associate
      end do
    end do
    call finish_database(out, error)
  end subroutine write_rwforc

  !> rcforc: per sample and contact a "slave" line (the force on SURFA) and a "master" line
  !> (on SURFB): time, x, y, z force and the side's nodal mass in contact.
  subroutine write_rcforc(model, histories, path, error)
    type(model_t), intent(in) :: model
    type(history_set_t), intent(in) :: histories
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: error
    integer, allocatable :: contact_series(:)
    character(len=70), allocatable :: titles(:)
    character(len=11) :: contact_text
    type(text_writer_t) :: out
    integer :: k, row, rows
    allocate (titles(size(model%contacts)))
    if (.not. series_of(histories, "rcforc", model%contacts%id, contact_series, rows)) return
    do k = 1, size(model%contacts)
      titles(k) = ""
      if (allocated(model%contacts(k)%title)) titles(k) = model%contacts(k)%title
    end do
    call start_database(model, out, path)
    call write_legend(out, model%contacts%id, titles)
    do row = 1, rows
      do k = 1, size(model%contacts)
        associate (series => histories%series(contact_series(k)))
          write (contact_text, '(i11)') model%contacts(k)%id
          call add_line(out, "  slave "//contact_text//" time"//c_exponential(series%rows(1, row), 12, 5)// &
            "  x "//c_exponential(value_of(series, "force", row, 1), 12, 5)// &
            "  y "//c_exponential(value_of(series, "force", row, 2), 12, 5)// &
            "  z "//c_exponential(value_of(series, "force", row, 3), 12, 5)// &
            " mass "//c_exponential(value_of(series, "mass", row), 12, 5))
          call add_line(out, "  master"//contact_text//" time"//c_exponential(series%rows(1, row), 12, 5)// &
            "  x "//c_exponential(value_of(series, "surfb_force", row, 1), 12, 5)// &
            "  y "//c_exponential(value_of(series, "surfb_force", row, 2), 12, 5)// &
            "  z "//c_exponential(value_of(series, "surfb_force", row, 3), 12, 5)// &
            " mass "//c_exponential(value_of(series, "surfb_mass", row), 12, 5))
        end associate
      end do
    end do
    call finish_database(out, error)
  end subroutine write_rcforc

  !> One rbdout line: a label right-aligned in 15 columns, then the values, %12.4E each.
  subroutine rbdout_line(out, label, values)
    type(text_writer_t), intent(inout) :: out
    character(len=*), intent(in) :: label
    real(wp), intent(in) :: values(:)
    character(len=15) :: padded
    character(len=:), allocatable :: line
    integer :: k
    padded = label
    line = adjustr(padded)
    do k = 1, size(values)
      line = line//c_exponential(values(k), 12, 4)
    end do
    call add_line(out, line)
  end subroutine rbdout_line

  !> rbdout: per sample the " r i g i d   b o d y   m o t i o n" line with the cycle and time,
  !> then per rigid body (LS-DYNA's block): the centre of mass's coordinates, displacements,
  !> velocities and accelerations with the rotations, angular velocities and accelerations
  !> (global axes), the body's axes in global axes (rows a, b, c), and the same motion in the
  !> body's axes.
  subroutine write_rbdout(model, histories, path, error)
    type(model_t), intent(in) :: model
    type(history_set_t), intent(in) :: histories
    character(len=*), intent(in) :: path
    type(error_t), allocatable, intent(out) :: error
    integer, allocatable :: body_series(:)
    character(len=8) :: id_text, cycle_text
    character(len=12), parameter :: titles(6) = [character(len=12) :: "x", "y", "z", "x-rot", "y-rot", "z-rot"]
    character(len=12), parameter :: local_titles(6) = [character(len=12) :: "a", "b", "c", "a-rot", "b-rot", "c-rot"]
    character(len=:), allocatable :: header, local_header
    real(wp) :: axes(3, 3), displacement(6), velocity(6), acceleration(6)
    type(text_writer_t) :: out
    integer :: k, j, i, row, rows
    ! (the ids as an array expression: a component of an array of types is not contiguous)
    if (.not. series_of(histories, "rbdout", [(model%rigid_bodies(k)%id, k = 1, size(model%rigid_bodies))], &
                        body_series, rows)) return
    ! the column titles end one column after their numbers (the header is 88 characters, where
    ! readers that count characters from the body's line expect the coordinates)
    header = "          global"
    local_header = "                "
    do j = 1, 6
      header = header//adjustr(titles(j))
      local_header = local_header//adjustr(local_titles(j))
    end do
    call start_database(model, out, path)
    do row = 1, rows
      associate (first => histories%series(body_series(1)))
        write (cycle_text, '(i8)') nint(value_of(first, "cycle", row))
        call add_line(out, "")
        call add_line(out, "  r i g i d   b o d y   m o t i o n   a t  cycle="//cycle_text//"     time="// &
          c_exponential(first%rows(1, row), 15, 7))
      end associate
      do k = 1, size(model%rigid_bodies)
        associate (series => histories%series(body_series(k)))
          write (id_text, '(i8)') model%rigid_bodies(k)%id
          call add_line(out, "")
          if (model%rigid_bodies(k)%part == 0) then
            call add_line(out, " nodal rigid body"//id_text)
          else
            call add_line(out, " rigid body"//id_text)
          end if
          call add_line(out, header)
          do j = 1, 3
            displacement(j) = value_of(series, "displacement", row, j)
            displacement(3 + j) = value_of(series, "rotation", row, j)
            velocity(j) = value_of(series, "velocity", row, j)
            velocity(3 + j) = value_of(series, "angular_velocity", row, j)
            acceleration(j) = value_of(series, "acceleration", row, j)
            acceleration(3 + j) = value_of(series, "angular_acceleration", row, j)
          end do
          ! axes(:, a): body axis a in global axes
          do j = 1, 3
            do i = 1, 3
              axes(i, j) = value_of(series, "direction_cosines", row, 3*(j - 1) + i)
            end do
          end do
          call rbdout_line(out, "coordinates:", [(value_of(series, "coordinates", row, j), j = 1, 3)])
          call rbdout_line(out, "displacements:", displacement)
          call rbdout_line(out, "velocities:", velocity)
          call rbdout_line(out, "accelerations:", acceleration)
          call add_line(out, " principal or user defined local coordinate direction vectors")
          call add_line(out, local_header(1:52))
          do j = 1, 3
            call rbdout_line(out, "row "//achar(iachar("0") + j), axes(:, j))
          end do
          call add_line(out, " output in principal or user defined local coordinate directions")
          call add_line(out, local_header)
          call rbdout_line(out, "displacements:", [matmul(transpose(axes), displacement(1:3)), &
                                                   matmul(transpose(axes), displacement(4:6))])
          call rbdout_line(out, "velocities:", [matmul(transpose(axes), velocity(1:3)), &
                                                matmul(transpose(axes), velocity(4:6))])
          call rbdout_line(out, "accelerations:", [matmul(transpose(axes), acceleration(1:3)), &
                                                   matmul(transpose(axes), acceleration(4:6))])
        end associate
      end do
    end do
    call finish_database(out, error)
  end subroutine write_rbdout
end module ascii_databases
