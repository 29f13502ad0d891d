!> LS-DYNA's run files beside results.h5: `d3hsp` (the model summary: controls, parts with
!> their material, section, element counts and mass, the total mass, the time step
!> information with LS-DYNA's 100 smallest element steps at the start and the smallest step
!> of each element kind, the deck as read and the termination line) and
!> `messag` (every warning and error the job printed, with file:line as the terminal showed
!> them, and the termination line). Both are written at the end of the run (normal or error
!> termination); the layout is in docs/output.md.
module ascii_run_summary
  use domain_partition, only: partition_text
  use kinds, only: wp
  use error_handling, only: error_t
  use model, only: model_t
  use material_laws, only: find_law, law_keyword_name
  use explicit_state, only: explicit_state_t
  use energy_balance, only: part_momenta
  use run_summary, only: run_summary_t, status_normal
  use history_buffer, only: history_set_t
  use ascii_databases, only: lsdyna_file_path, c_exponential, text_writer_t, begin_text, add_line, add_text, &
                             finish_database
  use version, only: crashfree_version
  use deck_signature, only: deck_source_t
  implicit none
  private

  public :: write_d3hsp, write_messag, termination_line, initial_time_step_tables

  !> Rows of d3hsp's table of the smallest element steps (LS-DYNA's "100 smallest timesteps").
  integer, parameter :: smallest_rows = 100

contains

  !> LS-DYNA's termination line, letters spaced as LS-DYNA writes it (scripts search for it).
  function termination_line(summary) result(line)
    type(run_summary_t), intent(in) :: summary
    character(len=:), allocatable :: line
    line = " E r r o r   t e r m i n a t i o n"
    if (allocated(summary%status)) then
      if (summary%status == status_normal) line = " N o r m a l    t e r m i n a t i o n"
    end if
  end function termination_line

  !> `messag` (`JOB.messag` with jobid=): `messages` (one message per line, as printed), then
  !> the termination line.
  subroutine write_messag(directory, job_id, messages, summary, error)
    character(len=*), intent(in) :: directory, job_id, messages
    type(run_summary_t), intent(in) :: summary
    type(error_t), allocatable, intent(out) :: error
    type(text_writer_t) :: out
    call begin_text(out, lsdyna_file_path(directory, job_id, "messag"))
    call add_line(out, " crashfree (version "//crashfree_version//") messages")
    call add_line(out, "")
    if (len(messages) > 0) call add_line(out, messages)
    call add_line(out, "")
    call add_line(out, termination_line(summary))
    if (allocated(summary%message)) then
      if (len(summary%message) > 0) call add_line(out, " "//summary%message)
    end if
    call finish_database(out, error)
  end subroutine write_messag

  !> `d3hsp` (`JOB.d3hsp` with jobid=).
  subroutine write_d3hsp(model, state, histories, initial_time_steps, summary, directory, job_id, error, sources)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    type(history_set_t), intent(in) :: histories
    character(len=*), intent(in) :: initial_time_steps   !< the table at cycle 0 ("" if not recorded)
    type(run_summary_t), intent(in) :: summary
    character(len=*), intent(in) :: directory, job_id
    type(error_t), allocatable, intent(out) :: error
    !> the deck's files as read (the main deck, then its includes, paths resolved): echoed
    type(deck_source_t), intent(in), optional :: sources(:)
    type(text_writer_t) :: out
    character(len=8) :: date
    character(len=16) :: cycles
    call begin_text(out, lsdyna_file_path(directory, job_id, "d3hsp"))
    call date_and_time(date=date)
    call add_line(out, " crashfree (version "//crashfree_version//")     date "//date(5:6)//"/"//date(7:8)//"/"// &
      date(1:4))
    call add_line(out, "")
    if (allocated(model%title)) call add_line(out, " "//model%title)
    if (allocated(model%deck_path)) call add_line(out, " input deck: "//model%deck_path)
    call write_controls(out, model)
    call write_parts(out, model, state)
    call write_time_steps(out, model, state, histories, initial_time_steps)
    if (summary%partition%rank_count > 1) call write_partition(out, summary)
    if (present(sources)) call echo_deck(out, sources)
    call add_line(out, "")
    write (cycles, '(i0)') summary%cycles
    call add_line(out, " cycles: "//trim(cycles)//", problem time "// &
                  trim(adjustl(c_exponential(summary%end_time, 12, 5))))
    call add_line(out, "")
    call add_line(out, termination_line(summary))
    if (allocated(summary%message)) then
      if (len(summary%message) > 0) call add_line(out, " "//summary%message)
    end if
    call finish_database(out, error)
  end subroutine write_d3hsp

  !> The domain partition of an MPI run (or partition=N), as printed at set-up.
  subroutine write_partition(out, summary)
    type(text_writer_t), intent(inout) :: out
    type(run_summary_t), intent(in) :: summary
    character(len=:), allocatable :: text
    integer :: start, finish
    call add_line(out, "")
    call add_line(out, " d o m a i n   p a r t i t i o n")
    call add_line(out, "")
    text = partition_text(summary%partition)
    start = 1
    do while (start <= len(text))
      finish = index(text(start:), new_line("a")) + start - 1
      if (finish < start) finish = len(text) + 1
      call add_line(out, " "//text(start:finish - 1))
      start = finish + 1
    end do
  end subroutine write_partition

  !> The input as read, file by file (LS-DYNA's d3hsp echoes its input too): each file's text
  !> under a line naming it, copied in pieces of at most echo_piece bytes (a vehicle's deck is
  !> gigabytes), with a new line after a last line that has none. A file that cannot be read
  !> any more is named as such (after the part that was read, if it fails midway).
  subroutine echo_deck(out, sources)
    type(text_writer_t), intent(inout) :: out
    type(deck_source_t), intent(in) :: sources(:)
    integer, parameter :: echo_piece = 1048576
    character(len=:), allocatable :: piece
    character(len=1) :: last
    integer :: k, unit, status, bytes, done, size_read
    call add_line(out, "")
    call add_line(out, " i n p u t   d e c k   a s   r e a d   (file by file, include paths resolved)")
    do k = 1, size(sources)
      call add_line(out, "")
      call add_line(out, " ---- "//sources(k)%path)
      open (newunit=unit, file=sources(k)%path, access="stream", form="unformatted", action="read", &
            status="old", iostat=status)
      if (status /= 0) then
        call add_line(out, " (cannot be read now)")
        cycle
      end if
      bytes = 0
      inquire (unit=unit, size=bytes, iostat=status)
      done = 0
      last = new_line("a")
      if (status == 0 .and. bytes > 0) allocate (character(len=min(bytes, echo_piece)) :: piece)
      do while (status == 0 .and. done < bytes)
        size_read = min(bytes - done, len(piece))
        read (unit, iostat=status) piece(1:size_read)
        if (status /= 0) exit
        call add_text(out, piece(1:size_read))
        last = piece(size_read:size_read)
        done = done + size_read
      end do
      close (unit)
      if (allocated(piece)) deallocate (piece)
      if (last /= new_line("a")) call add_text(out, new_line("a"))
      if (status /= 0) call add_line(out, " (cannot be read now)")
    end do
  end subroutine echo_deck

  !> One "label ..... value" line of the control section.
  subroutine control_line(out, label, value)
    type(text_writer_t), intent(inout) :: out
    character(len=*), intent(in) :: label, value
    character(len=48) :: padded
    padded = "   "//label//" "//repeat(".", 48)
    call add_line(out, padded//" "//value)
  end subroutine control_line

  function real_field(value) result(text)
    real(wp), intent(in) :: value
    character(len=:), allocatable :: text
    text = trim(adjustl(c_exponential(value, 12, 5)))
  end function real_field

  function integer_field(value) result(text)
    integer, intent(in) :: value
    character(len=:), allocatable :: text
    character(len=16) :: buffer
    write (buffer, '(i0)') value
    text = trim(buffer)
  end function integer_field

  subroutine write_controls(out, model)
    type(text_writer_t), intent(inout) :: out
    type(model_t), intent(in) :: model
    call add_line(out, "")
    call add_line(out, " c o n t r o l   i n f o r m a t i o n")
    call add_line(out, "")
    call control_line(out, "termination time (ENDTIM)", real_field(model%end_time))
    call control_line(out, "termination cycle (ENDCYC)", integer_field(model%end_cycle))
    call control_line(out, "time step scale factor (TSSFAC)", real_field(model%time_step_scale))
    call control_line(out, "initial time step (DTINIT)", real_field(model%initial_time_step))
    call control_line(out, "mass-scaled time step (DT2MS)", real_field(model%mass_scaled_time_step))
    call control_line(out, "state interval (d3plot DT)", real_field(model%output%state_interval))
    call control_line(out, "glstat interval, BINARY", real_field(model%output%glstat_interval)//", "// &
                      integer_field(model%output%glstat_binary))
    call control_line(out, "matsum interval, BINARY", real_field(model%output%matsum_interval)//", "// &
                      integer_field(model%output%matsum_binary))
    call control_line(out, "nodout interval, BINARY", real_field(model%output%nodout_interval)//", "// &
                      integer_field(model%output%nodout_binary))
    call control_line(out, "rwforc interval, BINARY", real_field(model%output%rwforc_interval)//", "// &
                      integer_field(model%output%rwforc_binary))
    call control_line(out, "rcforc interval, BINARY", real_field(model%output%rcforc_interval)//", "// &
                      integer_field(model%output%rcforc_binary))
    call control_line(out, "number of nodes", integer_field(size(model%node_ids)))
    call control_line(out, "number of solid elements", integer_field(size(model%solid_ids)))
    call control_line(out, "number of shell elements", integer_field(size(model%shell_ids)))
    if (allocated(model%beam_ids)) &
      call control_line(out, "number of beam elements", integer_field(size(model%beam_ids)))
    call control_line(out, "number of parts", integer_field(size(model%parts)))
    call control_line(out, "number of rigid walls", integer_field(size(model%walls)))
    if (allocated(model%contacts)) call control_line(out, "number of contacts", integer_field(size(model%contacts)))
  end subroutine write_controls

  !> One line per part: id, material id and keyword, section id and ELFORM, its solids, shells
  !> and beams, its mass (the nodal masses its elements give, a rigid part its body's), title;
  !> then the totals.
  subroutine write_parts(out, model, state)
    type(text_writer_t), intent(inout) :: out
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    real(wp), allocatable :: momentum(:, :), mass(:), rigid_velocity(:, :)
    character(len=24) :: material_name
    character(len=160) :: line
    integer :: k, solids, shells, beams, row, section_id, formulation
    allocate (momentum(3, size(model%parts)), mass(size(model%parts)), rigid_velocity(3, size(model%parts)))
    call part_momenta(model, state, size(model%parts), momentum, mass, rigid_velocity)
    call add_line(out, "")
    call add_line(out, " p a r t   d e f i n i t i o n s")
    call add_line(out, "")
    call add_line(out, "     part id  material id  material                 section id  elform     solids" // &
      "     shells      beams          mass  title")
    do k = 1, size(model%parts)
      associate (part => model%parts(k))
        solids = count(model%solid_part == k)
        shells = count(model%shell_part == k)
        beams = 0
        if (allocated(model%beam_part)) beams = count(model%beam_part == k)
        material_name = ""
        if (part%material > 0) then
          row = find_law(model%materials(part%material)%law)
          if (row > 0) material_name = law_keyword_name(row)
        end if
        section_id = 0
        formulation = 0
        if (part%section > 0) then
          section_id = model%sections(part%section)%id
          formulation = model%sections(part%section)%element_formulation
        end if
        write (line, '(i12,i13,2x,a24,i11,i8,3i11,a14)') part%id, part%material_id, material_name, section_id, &
          formulation, solids, shells, beams, c_exponential(mass(k), 14, 5)
        if (allocated(part%title)) then
          call add_line(out, trim(line)//"  "//trim(part%title))
        else
          call add_line(out, trim(line))
        end if
      end associate
    end do
    call add_line(out, "")
    call control_line(out, "total mass of the parts", real_field(sum(mass)))
    call control_line(out, "physical mass of the model", real_field(state%physical_mass))
    call control_line(out, "added mass (mass scaling)", real_field(state%added_mass))
    call control_line(out, "percentage increase", real_field(100.0_wp*state%added_mass/ &
                      max(state%physical_mass, tiny(1.0_wp))))
  end subroutine write_parts

  !> The first time step (glstat's first row), the tables of the start (initial_time_step_tables,
  !> recorded at cycle 0) and the smallest stable step of each element kind with its element
  !> at the last cycle.
  subroutine write_time_steps(out, model, state, histories, initial_time_steps)
    type(text_writer_t), intent(inout) :: out
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    type(history_set_t), intent(in) :: histories
    character(len=*), intent(in) :: initial_time_steps
    integer :: k, j
    character(len=200) :: line
    call add_line(out, "")
    call add_line(out, " t i m e   s t e p   i n f o r m a t i o n")
    call add_line(out, "")
    do k = 1, histories%count
      if (histories%series(k)%group /= "glstat") cycle
      if (histories%series(k)%count == 0) cycle
      do j = 1, size(histories%series(k)%names)
        if (histories%series(k)%names(j) == "time_step") then
          call control_line(out, "first time step", &
                            real_field(histories%series(k)%rows(sum(histories%series(k)%widths(1:j - 1)) + 1, 1)))
        end if
      end do
    end do
    call control_line(out, "last stable time step (before TSSFAC)", real_field(state%stable_time_step))
    call add_line(out, "")
    if (len(initial_time_steps) > 0) then
      call add_line(out, initial_time_steps(1:len(initial_time_steps) - 1))
      call add_line(out, "")
    end if
    call add_line(out, " s m a l l e s t   t i m e   s t e p s   (by element kind, last cycle)")
    call add_line(out, " ----------------------------------------------------------------------")
    call add_line(out, "      stable step  element")
    do k = 1, size(state%groups)
      associate (group => state%groups(k)%group)
        if (group%critical_element <= 0) cycle
        write (line, '(a)') c_exponential(group%stable_time_step, 17, 5)//"  "// &
          group%describe(model, group%critical_element)
        call add_line(out, trim(line))
      end associate
    end do
    if (size(state%rigid) > 0 .and. state%rigid_time_step < huge(1.0_wp)) then
      write (line, '(a)') c_exponential(state%rigid_time_step, 17, 5)//"  rigid bodies"
      call add_line(out, trim(line))
    end if
  end subroutine write_time_steps

  !> d3hsp's time step tables at the start (cycle 0), as text (lines ending in a new line):
  !> LS-DYNA's "100 smallest timesteps" (element type, deck id, part id, stable step without
  !> TSSFAC, smallest first; every group's list_time_steps, at the current configuration), then
  !> the step of each element kind as the force call set it, with its element, and the rigid
  !> bodies'.
  function initial_time_step_tables(model, state) result(text)
    type(model_t), intent(in) :: model
    type(explicit_state_t), intent(in) :: state
    character(len=:), allocatable :: text
    character(len=8) :: row_kind(smallest_rows)
    integer :: row_id(smallest_rows), row_part(smallest_rows)
    real(wp) :: row_step(smallest_rows)
    character(len=:), allocatable :: kind
    integer, allocatable :: element_ids(:), part_ids(:)
    real(wp), allocatable :: steps(:)
    character(len=80) :: line
    integer :: k, j, rows, place
    character(len=1), parameter :: eol = new_line("a")
    ! the smallest first; among equal steps the earlier group and element first (an element
    ! goes in after the rows with its step)
    rows = 0
    do k = 1, size(state%groups)
      call state%groups(k)%group%list_time_steps(model, state%nodes, kind, element_ids, part_ids, steps)
      do j = 1, size(steps)
        if (.not. steps(j) < huge(1.0_wp)) cycle
        if (rows == smallest_rows) then
          if (.not. steps(j) < row_step(rows)) cycle
        else
          rows = rows + 1
        end if
        place = rows
        do while (place > 1)
          if (.not. steps(j) < row_step(place - 1)) exit
          row_kind(place) = row_kind(place - 1)
          row_id(place) = row_id(place - 1)
          row_part(place) = row_part(place - 1)
          row_step(place) = row_step(place - 1)
          place = place - 1
        end do
        row_kind(place) = kind
        row_id(place) = element_ids(j)
        row_part(place) = part_ids(j)
        row_step(place) = steps(j)
      end do
    end do
    text = ""
    if (rows > 0) then
      text = text//"     100 smallest timesteps"//eol//"     ----------------------"//eol// &
             "   element       number        part      timestep"//eol
      do j = 1, rows
        write (line, '(a10,i13,i12,a)') adjustr(row_kind(j)), row_id(j), row_part(j), c_exponential(row_step(j), 15, 7)
        text = text//trim(line)//eol
      end do
      text = text//eol
    end if
    text = text//" s m a l l e s t   t i m e   s t e p s   (by element kind, cycle 0)"//eol// &
           " ----------------------------------------------------------------------"//eol// &
           "      stable step  element"//eol
    do k = 1, size(state%groups)
      associate (group => state%groups(k)%group)
        if (group%critical_element <= 0) cycle
        text = text//c_exponential(group%stable_time_step, 17, 5)//"  "//group%describe(model, group%critical_element)//eol
      end associate
    end do
    if (size(state%rigid) > 0 .and. state%rigid_time_step < huge(1.0_wp)) &
      text = text//c_exponential(state%rigid_time_step, 17, 5)//"  rigid bodies"//eol
  end function initial_time_step_tables
end module ascii_run_summary
