!> What a restart dump holds: the traversal of the run state, one routine per component.
!>
!> Each `exchange_<component>(store, path, ...)` writes the component's state under `path` when
!> the store is being written and reads it back when it is being read (restart_file's
!> `exchange_restart`), so writing and reading are one list and cannot drift apart. A dump holds
!> only what changes during a run: the model, and everything the set-up derives from it
!> (element blocks and their colours, masses, EFG shape functions and gradients, contact
!> segments, rigid-body inertias), is rebuilt from the deck, whose signature the restart checks.
!> What is stored is exactly what the next cycle reads, so that a restarted run repeats the
!> uninterrupted one bit for bit.
!>
!> A dump is taken at the end of a cycle, before that cycle's output (states, history rows):
!> the continued run starts by writing that output, as the uninterrupted run did.
!>
!> Layout (paths of the dump; k, b, p count from 1):
!> ```
!> clock/        time, cycle, time_step, next_time_step, stable_time_step, controlling_group,
!>               controlling_element
!> nodes/        coordinates, displacement, velocity, acceleration, external_force,
!>               contact_force, free_acceleration, angular_velocity, angular_acceleration,
!>               shell_normal_sum, shell_area_sum
!> groups/<name>/  each element group's own state (element_group's exchange_state: solid and
!>               shell blocks, meshfree parts)
!> rigid/k/      a rigid body's motion        walls/k/   a rigid wall's motion and forces
!> contacts/k/   forces; contacts/k/passes/p/: search lists, pairs, initial penetrations
!> energy/, watch/   energy totals, run-check memory
!> output/       clocks/<name>/{interval,next_time,active}, last sample times and impulses
!> distortion/   the folded-solids record
!> histories/    count; histories/k/{group,names,widths,count,rows}
!> results/      run_id, state_count, state_times, history_rows, output_bytes
!> timers/       seconds of each phase of the loop
!> ```
module run_state_dump
  use kinds, only: wp
  use text_format, only: integer_text
  use error_handling, only: error_t, make_error
  use explicit_state, only: explicit_state_t, energy_totals_t, run_watch_t
  use run_state, only: run_state_t
  use wall_state, only: wall_state_t
  use rigid_body_state, only: rigid_body_state_t
  use penalty_contact, only: contact_state_t, contact_pass_t
  use contact_erosion, only: remove_eroded_elements
  use element_groups, only: eroded_element_masks
  use model, only: model_t
  use output_plan, only: output_plan_t
  use history_buffer, only: history_set_t, add_history_series
  use element_group, only: distortion_t
  use results_file, only: results_file_t
  use restart_file, only: restart_store_t, exchange_restart, exchange_restart_resized, write_restart, &
                          read_restart, read_restart_resized, exchange_restart_count
  implicit none
  private

  public :: exchange_run_state, exchange_results_progress
  public :: exchange_clock, exchange_nodes, exchange_rigid_body, exchange_wall, exchange_contact, &
            exchange_energy, exchange_watch, exchange_output_plan, exchange_history_set

contains

  !> The whole run state at the end of a cycle. Reading needs a run state built from the same
  !> deck (explicit_setup's set_up_run_state).
  subroutine exchange_run_state(store, model, run, error)
    type(restart_store_t), intent(inout) :: store
    type(model_t), intent(in) :: model
    type(run_state_t), intent(inout) :: run
    type(error_t), allocatable, intent(inout) :: error
    integer :: k

    associate (state => run%state)
      call exchange_clock(store, "clock", state, error)
      call exchange_nodes(store, "nodes", state, error)
      call exchange_restart_count(store, "groups/count", "element groups", size(state%groups), error)
      do k = 1, size(state%groups)
        call state%groups(k)%group%exchange_state(store, "groups/"//trim(state%groups(k)%group%name), error)
      end do
      call exchange_restart_count(store, "rigid/count", "rigid bodies", size(state%rigid), error)
      do k = 1, size(state%rigid)
        call exchange_rigid_body(store, "rigid/"//integer_text(k), state%rigid(k), error)
      end do
      ! spot welds: each its rigid motion and whether (when, at what forces) it failed
      if (size(state%welds) > 0) then
        call exchange_restart_count(store, "welds/count", "spot welds", size(state%welds), error)
        do k = 1, size(state%welds)
          call exchange_rigid_body(store, "welds/"//integer_text(k), state%welds(k)%body, error)
          call exchange_restart(store, "welds/"//integer_text(k)//"/failed", state%welds(k)%failed, error)
          call exchange_restart(store, "welds/"//integer_text(k)//"/failure_time", state%welds(k)%failure_time, error)
          call exchange_restart(store, "welds/"//integer_text(k)//"/normal_force", state%welds(k)%normal_force, error)
          call exchange_restart(store, "welds/"//integer_text(k)//"/shear_force", state%welds(k)%shear_force, error)
        end do
      end if
      call exchange_restart_count(store, "walls/count", "rigid walls", size(state%walls), error)
      do k = 1, size(state%walls)
        call exchange_wall(store, "walls/"//integer_text(k), state%walls(k), error)
      end do
      ! contacts built from the deck still hold the segments of elements eroded before the dump:
      ! they drop them as the run did, so that the dump's search lists and pairs fit them
      if (.not. store%writing .and. .not. allocated(error)) then
        call eroded_element_masks(model, state%groups, state%solid_eroded, state%shell_eroded)
        if (any(state%solid_eroded) .or. any(state%shell_eroded)) &
          call remove_eroded_elements(model, state%contacts, state%solid_eroded, state%shell_eroded)
      end if
      call exchange_restart_count(store, "contacts/count", "contacts", size(state%contacts), error)
      do k = 1, size(state%contacts)
        call exchange_contact(store, "contacts/"//integer_text(k), state%contacts(k), error)
      end do
      call exchange_energy(store, "energy", state%energy, error)
      call exchange_watch(store, "watch", state%watch, error)
    end associate
    call exchange_output_plan(store, "output", run%plan, error)
    call exchange_distortion(store, "distortion", run%distortion, error)
    ! (the ranks that record no histories read none from a dump)
    if (store%writing .or. run%plan%records) call exchange_history_set(store, "histories", run%histories, error)
    call exchange_restart(store, "timers/seconds", run%timers%seconds, error)
  end subroutine exchange_run_state

  !> The clock: time, cycle, the step just taken, the coming one and where it comes from.
  subroutine exchange_clock(store, path, state, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(explicit_state_t), intent(inout) :: state
    type(error_t), allocatable, intent(inout) :: error
    call exchange_restart(store, path//"/time", state%time, error)
    call exchange_restart(store, path//"/cycle", state%cycle, error)
    call exchange_restart(store, path//"/time_step", state%time_step, error)
    call exchange_restart(store, path//"/next_time_step", state%next_time_step, error)
    call exchange_restart(store, path//"/stable_time_step", state%stable_time_step, error)
    call exchange_restart(store, path//"/controlling_group", state%controlling_group, error)
    call exchange_restart(store, path//"/controlling_element", state%controlling_element, error)
  end subroutine exchange_clock

  !> Nodal arrays that change during the run (the reference coordinates, masses and
  !> constraints come from the deck; the internal forces and moments are computed again before
  !> anything reads them, and a distributed run holds them whole only at each rank's own nodes).
  subroutine exchange_nodes(store, path, state, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(explicit_state_t), intent(inout) :: state
    type(error_t), allocatable, intent(inout) :: error
    associate (nodes => state%nodes)
      call exchange_restart(store, path//"/coordinates", nodes%coordinates, error)
      call exchange_restart(store, path//"/displacement", nodes%displacement, error)
      call exchange_restart(store, path//"/velocity", nodes%velocity, error)
      call exchange_restart(store, path//"/acceleration", nodes%acceleration, error)
      call exchange_restart(store, path//"/external_force", nodes%external_force, error)
      call exchange_restart(store, path//"/contact_force", nodes%contact_force, error)
      call exchange_restart(store, path//"/angular_velocity", nodes%angular_velocity, error)
      call exchange_restart(store, path//"/angular_acceleration", nodes%angular_acceleration, error)
      call exchange_restart(store, path//"/shell_normal_sum", nodes%shell_normal_sum, error)
      call exchange_restart(store, path//"/shell_area_sum", nodes%shell_area_sum, error)
    end associate
    call exchange_restart(store, path//"/free_acceleration", state%free_acceleration, error)
  end subroutine exchange_nodes

  !> One rigid body's motion (centre, rotation, velocities, angular momentum), the resultant
  !> of the last step, the impulse since the start of the run, the dofs held in the last step,
  !> and the velocities it gave its nodes (mass and inertia come from the deck).
  subroutine exchange_rigid_body(store, path, body, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(rigid_body_state_t), intent(inout) :: body
    type(error_t), allocatable, intent(inout) :: error
    call exchange_restart(store, path//"/centre", body%centre, error)
    call exchange_restart(store, path//"/velocity", body%velocity, error)
    call exchange_restart(store, path//"/angular_momentum", body%angular_momentum, error)
    call exchange_restart(store, path//"/angular_velocity", body%angular_velocity, error)
    call exchange_restart(store, path//"/rotation", body%rotation, error)
    call exchange_restart(store, path//"/rotation_angle", body%rotation_angle, error)
    call exchange_restart(store, path//"/force", body%force, error)
    call exchange_restart(store, path//"/moment", body%moment, error)
    call exchange_restart(store, path//"/impulse", body%impulse, error)
    call exchange_restart(store, path//"/held", body%held, error)
    call exchange_restart(store, path//"/held_acceleration", body%held_acceleration, error)
    call exchange_restart(store, path//"/node_velocity", body%node_velocity, error)
  end subroutine exchange_rigid_body

  !> One rigid wall (planar or cylinder): its motion and the forces on it.
  subroutine exchange_wall(store, path, wall, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(wall_state_t), intent(inout) :: wall
    type(error_t), allocatable, intent(inout) :: error
    call exchange_restart(store, path//"/displacement", wall%displacement, error)
    call exchange_restart(store, path//"/speed", wall%speed, error)
    call exchange_restart(store, path//"/mass", wall%mass, error)
    call exchange_restart(store, path//"/normal", wall%normal, error)
    call exchange_restart(store, path//"/force", wall%force, error)
    call exchange_restart(store, path//"/impulse", wall%impulse, error)
  end subroutine exchange_wall

  !> One contact: its force and impulse, and per pass the search lists as they are (a list
  !> rebuilt at another cycle would give other candidates, hence other pairs), the pairs of the
  !> last cycle (segment, side, depth, weights, forces, friction springs) and the initial
  !> penetrations being ignored.
  subroutine exchange_contact(store, path, contact, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(contact_state_t), intent(inout) :: contact
    type(error_t), allocatable, intent(inout) :: error
    integer :: p
    call exchange_restart_count(store, path//"/pass_count", "passes of "//path, contact%pass_count, error)
    call exchange_restart(store, path//"/force", contact%force, error)
    call exchange_restart(store, path//"/impulse", contact%impulse, error)
    do p = 1, contact%pass_count
      call exchange_contact_pass(store, path//"/passes/"//integer_text(p), contact%passes(p), error)
    end do
  end subroutine exchange_contact

  subroutine exchange_contact_pass(store, path, pass, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(contact_pass_t), intent(inout) :: pass
    type(error_t), allocatable, intent(inout) :: error
    call exchange_restart_count(store, path//"/node_count", "secondary nodes of "//path, pass%node_count, error)
    call exchange_restart_count(store, path//"/segment_count", "segments of "//path, pass%segment_count, error)
    call exchange_restart(store, path//"/initial_checked", pass%initial_checked, error)
    call exchange_restart(store, path//"/initial_depth", pass%initial_depth, error)
    call exchange_restart(store, path//"/initial_count", pass%initial_count, error)
    call exchange_restart(store, path//"/initial_deepest", pass%initial_deepest, error)
    call exchange_restart(store, path//"/initial_node", pass%initial_node, error)
    call exchange_restart(store, path//"/initial_reported", pass%initial_reported, error)
    call exchange_restart(store, path//"/tracked_at_build", pass%tracked_at_build, error)
    call exchange_restart(store, path//"/cycles_since_build", pass%cycles_since_build, error)
    call exchange_restart(store, path//"/built", pass%built, error)
    call exchange_restart(store, path//"/box", pass%box, error)
    call exchange_restart_resized(store, path//"/candidate_first", pass%candidate_first, error)
    call exchange_restart_resized(store, path//"/candidates", pass%candidates, error)
    call exchange_restart_resized(store, path//"/cell_first", pass%cell_first, error)
    call exchange_restart_resized(store, path//"/cell_segments", pass%cell_segments, error)
    call exchange_restart(store, path//"/pair_segment", pass%pair_segment, error)
    call exchange_restart(store, path//"/pair_side", pass%pair_side, error)
    call exchange_restart(store, path//"/pair_depth", pass%pair_depth, error)
    call exchange_restart(store, path//"/pair_weights", pass%pair_weights, error)
    call exchange_restart(store, path//"/pair_force", pass%pair_force, error)
    call exchange_restart(store, path//"/tangential", pass%tangential, error)
  end subroutine exchange_contact_pass

  !> The energy totals of the balance (glstat), the initial total included.
  subroutine exchange_energy(store, path, energy, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(energy_totals_t), intent(inout) :: energy
    type(error_t), allocatable, intent(inout) :: error
    call exchange_restart(store, path//"/kinetic", energy%kinetic, error)
    call exchange_restart(store, path//"/internal", energy%internal, error)
    call exchange_restart(store, path//"/hourglass", energy%hourglass, error)
    call exchange_restart(store, path//"/contact", energy%contact, error)
    call exchange_restart(store, path//"/rigid_wall", energy%rigid_wall, error)
    call exchange_restart(store, path//"/external_work", energy%external_work, error)
    call exchange_restart(store, path//"/initial_total", energy%initial_total, error)
    call exchange_restart(store, path//"/momentum", energy%momentum, error)
    call exchange_restart(store, path//"/eroded_internal", energy%eroded_internal, error)
    call exchange_restart(store, path//"/eroded_hourglass", energy%eroded_hourglass, error)
    call exchange_restart(store, path//"/eroded_kinetic", energy%eroded_kinetic, error)
  end subroutine exchange_energy

  !> What the run checks remember from cycle to cycle (and their bounds, set at cycle 0).
  subroutine exchange_watch(store, path, watch, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(run_watch_t), intent(inout) :: watch
    type(error_t), allocatable, intent(inout) :: error
    call exchange_restart(store, path//"/largest_wave_speed", watch%largest_wave_speed, error)
    call exchange_restart(store, path//"/velocity_limit", watch%velocity_limit, error)
    call exchange_restart(store, path//"/angular_velocity_limit", watch%angular_velocity_limit, error)
    call exchange_restart(store, path//"/first_time_step", watch%first_time_step, error)
    call exchange_restart(store, path//"/last_stable_step", watch%last_stable_step, error)
    call exchange_restart(store, path//"/step_decades_reported", watch%step_decades_reported, error)
    call exchange_restart(store, path//"/largest_energy_supplied", watch%largest_energy_supplied, error)
  end subroutine exchange_watch

  !> The output clocks (next sample times), the times and impulses of the last force samples
  !> (their averaging intervals); the series positions and work arrays are rebuilt by
  !> plan_output.
  subroutine exchange_output_plan(store, path, plan, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(output_plan_t), intent(inout) :: plan
    type(error_t), allocatable, intent(inout) :: error
    call exchange_clock_entry(path//"/clocks/states", plan%states%interval, plan%states%next_time, &
                              plan%states%active)
    call exchange_clock_entry(path//"/clocks/glstat", plan%glstat%interval, plan%glstat%next_time, &
                              plan%glstat%active)
    call exchange_clock_entry(path//"/clocks/matsum", plan%matsum%interval, plan%matsum%next_time, &
                              plan%matsum%active)
    call exchange_clock_entry(path//"/clocks/nodout", plan%nodout%interval, plan%nodout%next_time, &
                              plan%nodout%active)
    call exchange_clock_entry(path//"/clocks/rwforc", plan%rwforc%interval, plan%rwforc%next_time, &
                              plan%rwforc%active)
    call exchange_clock_entry(path//"/clocks/rbdout", plan%rbdout%interval, plan%rbdout%next_time, &
                              plan%rbdout%active)
    call exchange_clock_entry(path//"/clocks/rcforc", plan%rcforc%interval, plan%rcforc%next_time, &
                              plan%rcforc%active)
    call exchange_restart(store, path//"/last_rcforc_time", plan%last_rcforc_time, error)
    call exchange_restart(store, path//"/last_rbdout_time", plan%last_rbdout_time, error)
    call exchange_restart(store, path//"/last_rwforc_time", plan%last_rwforc_time, error)
    call exchange_restart(store, path//"/wall_impulse", plan%wall_impulse, error)
    call exchange_restart(store, path//"/contact_impulse", plan%contact_impulse, error)
    call exchange_restart(store, path//"/rigid_impulse", plan%rigid_impulse, error)
  contains
    subroutine exchange_clock_entry(clock_path, interval, next_time, active)
      character(len=*), intent(in) :: clock_path
      real(wp), intent(inout) :: interval, next_time
      logical, intent(inout) :: active
      call exchange_restart(store, clock_path//"/interval", interval, error)
      call exchange_restart(store, clock_path//"/next_time", next_time, error)
      call exchange_restart(store, clock_path//"/active", active, error)
    end subroutine exchange_clock_entry
  end subroutine exchange_output_plan

  !> The folded-solids record of the run (distortion_check).
  subroutine exchange_distortion(store, path, distortion, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(distortion_t), intent(inout) :: distortion
    type(error_t), allocatable, intent(inout) :: error
    call exchange_restart(store, path//"/tangled", distortion%tangled, error)
    call exchange_restart(store, path//"/reported", distortion%reported, error)
    call exchange_restart(store, path//"/worst_ratio", distortion%worst_ratio, error)
    call exchange_restart(store, path//"/worst_element", distortion%worst_element, error)
  end subroutine exchange_distortion

  !> Every history series with the rows recorded so far. Read into an empty set, the series are
  !> created from the dump (group, column names and widths); read into a set that plan_output
  !> built, its series must be the dump's, in the same order.
  subroutine exchange_history_set(store, path, histories, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(history_set_t), intent(inout) :: histories
    type(error_t), allocatable, intent(inout) :: error
    character(len=:), allocatable :: series_path, group, names
    character(len=32), allocatable :: columns(:)
    integer, allocatable :: widths(:)
    real(wp), allocatable :: grown(:, :)
    integer :: k, stored_count, index, row_count

    if (allocated(error)) return
    if (store%writing) then
      call write_restart(store, path//"/count", histories%count, error)
      do k = 1, histories%count
        associate (series => histories%series(k))
          series_path = path//"/"//integer_text(k)
          call write_restart(store, series_path//"/group", series%group, error)
          call write_restart(store, series_path//"/names", joined(series%names), error)
          call write_restart(store, series_path//"/widths", series%widths, error)
          call write_restart(store, series_path//"/count", series%count, error)
          call write_restart(store, series_path//"/rows", series%rows(:, 1:series%count), error)
        end associate
      end do
      return
    end if

    stored_count = 0
    call read_restart(store, path//"/count", stored_count, error)
    if (allocated(error)) return
    if (histories%count /= 0 .and. histories%count /= stored_count) then
      call make_error(error, "restart dump "//store%path//": it holds "//integer_text(stored_count)// &
                      " history series, this model has "//integer_text(histories%count))
      return
    end if
    do k = 1, stored_count
      series_path = path//"/"//integer_text(k)
      call read_restart(store, series_path//"/group", group, error)
      call read_restart(store, series_path//"/names", names, error)
      call read_restart(store, series_path//"/count", row_count, error)
      if (allocated(error)) return
      call split_names(names, columns)
      allocate (widths(size(columns)))
      call read_restart(store, series_path//"/widths", widths, error)
      if (allocated(error)) return
      if (k > histories%count) then
        call add_history_series(histories, group, columns, widths, row_count, index)
      else if (histories%series(k)%group /= group .or. size(histories%series(k)%widths) /= size(widths)) then
        call make_error(error, "restart dump "//store%path//": history series "//integer_text(k)//" is "//group// &
                        ", this model's is "//histories%series(k)%group)
        return
      else if (any(histories%series(k)%widths /= widths)) then
        call make_error(error, "restart dump "//store%path//": history "//group//" has other columns")
        return
      end if
      deallocate (widths)
      associate (series => histories%series(k))
        if (size(series%rows, 2) < row_count) then
          allocate (grown(series%row_width, row_count))
          call move_alloc(grown, series%rows)
        end if
        call read_restart(store, series_path//"/rows", series%rows(:, 1:row_count), error)
        series%count = row_count
      end associate
      if (allocated(error)) return
    end do
  end subroutine exchange_history_set

  !> The results file's bookkeeping at the dump: its identity (run_id), the states and history
  !> rows in it, their times, and the bytes written. A continued run cuts the file back to these
  !> (results_file's continue_results) and goes on from there.
  subroutine exchange_results_progress(store, path, results, error)
    type(restart_store_t), intent(inout) :: store
    character(len=*), intent(in) :: path
    type(results_file_t), intent(inout) :: results
    type(error_t), allocatable, intent(inout) :: error
    real(wp) :: bytes
    character(len=:), allocatable :: run_id
    character(len=24) :: buffer
    integer :: status
    if (allocated(error)) return
    if (store%writing) then
      write (buffer, '(i0)') results%run_id
      call write_restart(store, path//"/run_id", trim(buffer), error)
      call write_restart(store, path//"/state_count", results%state_count, error)
      call write_restart(store, path//"/state_times", results%state_times(1:results%state_count), error)
      call write_restart(store, path//"/history_rows", results%history_rows, error)
      call write_restart(store, path//"/output_bytes", real(results%output_bytes, wp), error)
      return
    end if
    call read_restart(store, path//"/run_id", run_id, error)
    if (allocated(error)) return
    read (run_id, *, iostat=status) results%run_id
    if (status /= 0) call make_error(error, "restart dump "//store%path//": "//path//"/run_id: not a number")
    call read_restart(store, path//"/state_count", results%state_count, error)
    if (allocated(error)) return
    if (allocated(results%state_times)) deallocate (results%state_times)
    allocate (results%state_times(max(16, 2*results%state_count)))
    call read_restart(store, path//"/state_times", results%state_times(1:results%state_count), error)
    call read_restart_resized(store, path//"/history_rows", results%history_rows, error)
    bytes = 0.0_wp
    call read_restart(store, path//"/output_bytes", bytes, error)
    results%output_bytes = int(bytes, kind(results%output_bytes))
  end subroutine exchange_results_progress

  ! ---------------------------------------------------------------------------------------------

  !> Column names joined by blanks (names have none).
  function joined(names) result(text)
    character(len=*), intent(in) :: names(:)
    character(len=:), allocatable :: text
    integer :: k
    text = ""
    do k = 1, size(names)
      text = text//trim(names(k))
      if (k < size(names)) text = text//" "
    end do
  end function joined

  subroutine split_names(text, names)
    character(len=*), intent(in) :: text
    character(len=32), allocatable, intent(out) :: names(:)
    integer :: start, finish, count
    count = 0
    if (len_trim(text) > 0) count = 1 + count_blanks(trim(text))
    allocate (names(count))
    start = 1
    do count = 1, size(names)
      finish = index(text(start:), " ")
      if (finish == 0) then
        finish = len_trim(text) + 1
      else
        finish = start + finish - 1
      end if
      names(count) = text(start:finish - 1)
      start = finish + 1
    end do
  end subroutine split_names

  pure integer function count_blanks(text)
    character(len=*), intent(in) :: text
    integer :: k
    count_blanks = 0
    do k = 1, len(text)
      if (text(k:k) == " ") count_blanks = count_blanks + 1
    end do
  end function count_blanks
end module run_state_dump
