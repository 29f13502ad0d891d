!> LS-DYNA's d3plot database, written beside results.h5 for the tools crash engineers already
!> use (LS-PrePost, lasso-python, ParaView's LS-DYNA reader): 32-bit words (single precision,
!> LS-DYNA's default), little-endian as the machine writes them, through Fortran stream access.
!>
!> The first file (`d3plot`, or `NAME.d3plot` with jobid=NAME) holds, in the order of LS-DYNA's
!> "d3plot database manual": the 64 control words; the geometry (node coordinates, solids as
!> 8 nodes + part, beams as N1 N2 N3 + two unused words + part, shells as 4 nodes + part, all
!> 1-based); the arbitrary-numbering section (the deck's node, element and part ids); an
!> end-of-file marker (-999999.0), the part titles (type 90001) and another marker. The states
!> (d3plot_states) follow in the family files `d3plot01`, `d3plot02`, ...: a new one when the
!> next state would take the file past its size limit. (lasso-python also reads states after
!> the titles in the first file; ParaView's reader looks for them in the next file.)
!> Every file ends with the end-of-file marker: a state is written over the marker of the
!> previous one and followed by a new marker, so that a run that stops anywhere leaves files
!> a reader takes whole (readers count a file's states from its last non-zero byte).
module d3plot_file
  use, intrinsic :: iso_fortran_env, only: int32, int64, real32
  use kinds, only: wp
  use error_handling, only: error_t, make_error
  use text_format, only: integer_text, real_text
  use file_system, only: remove_file, file_size
  use model, only: model_t
  use element_group, only: shell_output_points
  use d3plot_states, only: d3plot_layout_t, state_word_count, shell_extra_values, word_stream_t, &
                           open_word_stream, put_values, put_zeros, write_buffer, put_node_vectors, put_solids, &
                           put_beams, put_shells, put_deletion_flags
  implicit none
  private

  public :: d3plot_file_t, open_d3plot, continue_d3plot, write_d3plot_state, close_d3plot, d3plot_base_name
  public :: default_file_scale, words_per_scale

  !> LS-DYNA's default family file size: 7 x 512^2 words; x= on the command line gives the
  !> multiple of 512^2 words.
  integer, parameter :: default_file_scale = 7
  integer(int64), parameter :: words_per_scale = 512_int64**2
  real(real32), parameter :: end_marker = -999999.0_real32
  !> LS-DYNA's part-title section: type 90001, then per part its id and 18 words of title.
  integer(int32), parameter :: part_titles_type = 90001
  integer, parameter :: title_characters = 72
  !> Words a state is written in at a time (1 MiB).
  integer, parameter :: stream_buffer_words = 2**18
  !> Elements of the geometry written at a time.
  integer, parameter :: geometry_chunk = 4096

  !> An open d3plot family.
  type :: d3plot_file_t
    logical :: is_open = .false.
    logical :: failed = .false.                   !< a write failed: no more states are written
    integer :: unit = -1
    character(len=:), allocatable :: base_path    !< DIR/d3plot or DIR/NAME.d3plot
    character(len=:), allocatable :: path         !< the file being written
    integer :: member = 0                         !< 0: the first file, k: base_path//"0k"
    integer(int64) :: file_words = 0              !< words in the file, its end marker not counted
    integer(int64) :: limit_words = 0             !< family file size limit
    integer :: state_count = 0                    !< states written (all files)
    type(d3plot_layout_t) :: layout
    integer, allocatable :: solid_part(:), shell_part(:), beam_part(:)  !< part numbers of the elements
    real(wp), allocatable :: shell_thickness(:)   !< the deck's (mean of the corners), for shells without points
    !> with strains (layout%strains): the elements' nodes, (8, solids) and (4, shells); without
    !> them none, (8, 0) and (4, 0)
    integer, allocatable :: solid_nodes(:, :), shell_nodes(:, :)
  end type d3plot_file_t

contains

  !> LS-DYNA's name of the database: `d3plot`, or `NAME.d3plot` for a job named NAME
  !> (jobid=NAME; the default job "results" writes `d3plot`).
  pure function d3plot_base_name(job_id) result(name)
    character(len=*), intent(in) :: job_id
    character(len=:), allocatable :: name
    if (job_id == "results" .or. len_trim(job_id) == 0) then
      name = "d3plot"
    else
      name = trim(job_id)//".d3plot"
    end if
  end function d3plot_base_name

  !> Create `base_path` with the control words, geometry, ids and part titles of `model`.
  !> Family files of an earlier run of the job (base_path01, ...) are removed first, so that a
  !> reader does not take their states for this run's. `file_scale`: the family file size in
  !> multiples of 512^2 words (LS-DYNA's x=).
  subroutine open_d3plot(plot, base_path, model, file_scale, error)
    type(d3plot_file_t), intent(inout) :: plot
    character(len=*), intent(in) :: base_path
    type(model_t), intent(in) :: model
    integer, intent(in) :: file_scale
    type(error_t), allocatable, intent(out) :: error
    integer :: member, status
    character(len=256) :: message

    plot%base_path = base_path
    plot%member = 0
    plot%path = base_path
    plot%state_count = 0
    plot%failed = .false.
    plot%limit_words = max(1, file_scale)*words_per_scale
    member = 1
    do while (file_size(base_path//member_suffix(member)) >= 0)
      call remove_file(base_path//member_suffix(member))
      member = member + 1
    end do
    call set_layout(plot, model)
    open (newunit=plot%unit, file=plot%path, access="stream", form="unformatted", status="replace", &
          action="readwrite", iostat=status, iomsg=message)
    if (status /= 0) then
      call make_error(error, "d3plot "//plot%path//": cannot create the file: "//trim(message))
      plot%failed = .true.
      return
    end if
    plot%is_open = .true.
    call write_header(plot, model, status, message)
    if (status == 0) call write_geometry(plot, model, status, message)
    if (status == 0) call write_numbering(plot, model, status, message)
    if (status == 0) call write_part_titles(plot, model, status, message)
    if (status == 0) call write_end_marker(plot, status, message)
    ! the states go into the family files: a reader that meets the end marker after the
    ! geometry (ParaView's) looks for them in the next file
    if (status == 0) call next_member(plot, status, message)
    if (status == 0) flush (plot%unit, iostat=status, iomsg=message)
    if (status /= 0) then
      call make_error(error, "d3plot "//plot%path//": cannot write the geometry: "//trim(message))
      call fail(plot)
    end if
  end subroutine open_d3plot

  !> Continue the d3plot of an interrupted run (restart): keep its first `kept_states` states,
  !> the ones results.h5 keeps, and write on after them. The states after them are overwritten
  !> with zeros (readers count a file's states from its last non-zero word) and later family
  !> files are deleted. A d3plot that does not hold those states (missing, written by another
  !> model, or cut short) is not continued: `continued` is false and it is left as it is.
  subroutine continue_d3plot(plot, base_path, model, kept_states, file_scale, continued)
    type(d3plot_file_t), intent(inout) :: plot
    character(len=*), intent(in) :: base_path
    type(model_t), intent(in) :: model
    integer, intent(in) :: kept_states, file_scale
    logical, intent(out) :: continued
    integer(int64) :: state_words, base_words, file_words, bytes, keep_words
    integer :: member, remaining, in_file, status
    integer(int32) :: control(64)
    integer(int32), allocatable :: zeros(:)
    character(len=:), allocatable :: path
    character(len=256) :: message

    continued = .false.
    plot%base_path = base_path
    plot%failed = .false.
    plot%limit_words = max(1, file_scale)*words_per_scale
    call set_layout(plot, model)
    state_words = state_word_count(plot%layout)
    base_words = first_file_words(plot%layout)
    ! the first file must be this model's geometry (its control words), with no states
    bytes = file_size(base_path)
    if (bytes /= 4*(base_words + 1)) return
    open (newunit=plot%unit, file=base_path, access="stream", form="unformatted", status="old", action="read", &
          iostat=status)
    if (status /= 0) return
    read (plot%unit, iostat=status) control
    close (plot%unit)
    if (status /= 0) return
    if (control(17) /= plot%layout%node_count .or. control(24) /= plot%layout%solid_count .or. &
        control(32) /= plot%layout%shell_count .or. control(29) /= plot%layout%beam_count .or. &
        control(34) /= plot%layout%shell_values .or. control(19) /= plot%layout%global_count) return
    ! the file holding the last state kept
    remaining = kept_states
    member = 1
    do
      path = base_path//member_suffix(member)
      bytes = file_size(path)
      if (bytes < 4) return
      file_words = bytes/4 - 1
      in_file = int(max(0_int64, file_words)/state_words)
      if (in_file >= remaining) exit
      remaining = remaining - in_file
      member = member + 1
    end do
    keep_words = int(remaining, int64)*state_words
    open (newunit=plot%unit, file=path, access="stream", form="unformatted", status="old", action="readwrite", &
          iostat=status)
    if (status /= 0) return
    plot%is_open = .true.
    plot%path = path
    plot%member = member
    plot%file_words = keep_words
    ! zeros over what follows, then the end marker
    allocate (zeros(max(0_int64, bytes/4 - keep_words)), source=0_int32)
    write (plot%unit, pos=4*keep_words + 1, iostat=status) zeros
    if (status == 0) call write_end_marker(plot, status, message)
    if (status /= 0) then
      call fail(plot)
      return
    end if
    member = member + 1
    do while (file_size(base_path//member_suffix(member)) >= 0)
      call remove_file(base_path//member_suffix(member))
      member = member + 1
    end do
    plot%state_count = kept_states
    continued = .true.
  end subroutine continue_d3plot

  !> Append one state: the time; the global values `globals` (kinetic, internal, total energy,
  !> velocity (3), per part internal then kinetic energy; absent: 0); the current coordinates,
  !> `reference` + `displacement` (the caller's reference coordinates: the database keeps no
  !> copy), as LS-DYNA writes them, the velocities and the accelerations
  !> (absent: 0), all (3, nodes); the solids' stress (6, solids) and plastic strain; the beams'
  !> resultants (6, beams) in crashfree's order N, Q_s, Q_t, T, M_s, M_t (absent: 0); the shells'
  !> layers, resultants, thickness and energy density (see d3plot_states' put_shells); the
  !> deletion flags from `solid_eroded`, `shell_eroded` (1: eroded) and `beam_failed` (1:
  !> failed; one not of the beams' size is not used). The words go to the file section by
  !> section through a buffer of bounded size, with no copy of the arrays. After a failed write
  !> the database is closed with the states before it, and later calls do nothing.
  subroutine write_d3plot_state(plot, time, reference, displacement, velocity, solid_stress, solid_plastic_strain, &
                                error, shell_stress, shell_plastic_strain, beam_resultant, beam_failed, solid_eroded, &
                                shell_eroded, acceleration, globals, shell_point_stress, shell_point_plastic_strain, &
                                shell_point_count, shell_resultant, shell_thickness, shell_energy_density)
    type(d3plot_file_t), intent(inout) :: plot
    real(wp), intent(in) :: time
    real(wp), intent(in) :: reference(:, :), displacement(:, :), velocity(:, :)
    real(wp), intent(in) :: solid_stress(:, :), solid_plastic_strain(:)
    type(error_t), allocatable, intent(out) :: error
    real(wp), intent(in), optional :: shell_stress(:, :), shell_plastic_strain(:)
    real(wp), intent(in), optional :: beam_resultant(:, :), beam_failed(:)
    integer, intent(in), optional :: solid_eroded(:), shell_eroded(:)
    real(wp), intent(in), optional :: acceleration(:, :), globals(:)
    real(wp), intent(in), optional :: shell_point_stress(:, :, :), shell_point_plastic_strain(:, :)
    integer, intent(in), optional :: shell_point_count(:)
    real(wp), intent(in), optional :: shell_resultant(:, :), shell_thickness(:), shell_energy_density(:)
    type(word_stream_t) :: stream
    integer(int64) :: state_words
    integer :: status
    character(len=256) :: message

    if (.not. plot%is_open .or. plot%failed) return
    state_words = state_word_count(plot%layout)
    status = 0
    ! a new family file when this state would pass the limit (a file holds at least one state)
    if (plot%file_words > 0 .and. plot%file_words + state_words + 1 > plot%limit_words) &
      call next_member(plot, status, message)
    if (status == 0) then
      call open_word_stream(stream, plot%unit, plot%file_words, stream_buffer_words)
      associate (layout => plot%layout)
        call put_values(stream, [time])
        if (present(globals)) then
          call put_values(stream, globals(1:layout%global_count))
        else
          call put_zeros(stream, layout%global_count)
        end if
        call put_node_vectors(stream, layout%node_count, reference, displacement)
        call put_node_vectors(stream, layout%node_count, velocity)
        call put_node_vectors(stream, layout%node_count, acceleration)
        call put_solids(stream, layout, solid_stress, solid_plastic_strain, reference, displacement, &
                        plot%solid_nodes)
        call put_beams(stream, layout, beam_resultant)
        call put_shells(stream, layout, plot%shell_thickness, reference, displacement, plot%shell_nodes, &
                        shell_stress, shell_plastic_strain, shell_point_stress, shell_point_plastic_strain, &
                        shell_point_count, shell_resultant, shell_thickness, shell_energy_density)
        ! deletion flags: solids, (thick shells: none), shells, beams
        call put_deletion_flags(stream, plot%solid_part, solid_eroded)
        call put_deletion_flags(stream, plot%shell_part, shell_eroded)
        if (present(beam_failed)) then
          if (size(beam_failed) == layout%beam_count) then
            call put_deletion_flags(stream, plot%beam_part, failed=beam_failed)
          else
            call put_deletion_flags(stream, plot%beam_part)
          end if
        else
          call put_deletion_flags(stream, plot%beam_part)
        end if
      end associate
      call write_buffer(stream)
      status = stream%status
      message = stream%message
      if (status == 0 .and. stream%written /= state_words) then
        status = -1
        message = "the state has "//integer_text(stream%written)//" words instead of "//integer_text(state_words)
      end if
    end if
    if (status == 0) then
      plot%file_words = plot%file_words + state_words
      call write_end_marker(plot, status, message)
    end if
    if (status == 0) flush (plot%unit, iostat=status, iomsg=message)
    if (status /= 0) then
      call make_error(error, "d3plot "//plot%path//": cannot write state "//integer_text(plot%state_count + 1)// &
                      " at time "//real_text(time)//": "//trim(message)//"; the d3plot files keep "// &
                      integer_text(plot%state_count)//" state(s)")
      call fail(plot)
      return
    end if
    plot%state_count = plot%state_count + 1
  end subroutine write_d3plot_state

  !> Close the file being written (nothing to do for a database that is not open).
  subroutine close_d3plot(plot)
    type(d3plot_file_t), intent(inout) :: plot
    integer :: status
    if (plot%is_open) close (plot%unit, iostat=status)
    plot%is_open = .false.
    plot%unit = -1
  end subroutine close_d3plot

  ! --- the layout ---------------------------------------------------------------------------

  subroutine set_layout(plot, model)
    type(d3plot_file_t), intent(inout) :: plot
    type(model_t), intent(in) :: model
    integer :: element
    associate (layout => plot%layout)
      layout%node_count = 0
      if (allocated(model%node_ids)) layout%node_count = size(model%node_ids)
      layout%solid_count = 0
      if (allocated(model%solid_ids)) layout%solid_count = size(model%solid_ids)
      layout%shell_count = 0
      if (allocated(model%shell_ids)) layout%shell_count = size(model%shell_ids)
      layout%beam_count = 0
      if (allocated(model%beam_ids)) layout%beam_count = size(model%beam_ids)
      layout%part_count = 0
      if (allocated(model%parts)) layout%part_count = size(model%parts)
      layout%shell_layers = shell_output_points(model)
      layout%global_count = 6 + 2*layout%part_count
      layout%strains = model%output%element_strains
      layout%solid_values = merge(13, 7, layout%strains)
      layout%beam_values = 6
      layout%shell_values = 7*layout%shell_layers + shell_extra_values + merge(12, 0, layout%strains)
    end associate
    plot%solid_nodes = reshape([integer ::], [8, 0])
    plot%shell_nodes = reshape([integer ::], [4, 0])
    if (plot%layout%strains) then
      if (plot%layout%solid_count > 0) plot%solid_nodes = model%solid_nodes
      if (plot%layout%shell_count > 0) plot%shell_nodes = model%shell_nodes
    end if
    if (allocated(plot%shell_thickness)) deallocate (plot%shell_thickness)
    plot%solid_part = [integer ::]
    if (plot%layout%solid_count > 0) plot%solid_part = model%solid_part
    plot%shell_part = [integer ::]
    if (plot%layout%shell_count > 0) plot%shell_part = model%shell_part
    ! the deck's thickness (mean of the corners, of the three of a triangle)
    allocate (plot%shell_thickness(plot%layout%shell_count), source=0.0_wp)
    if (allocated(model%shell_thickness)) then
      do element = 1, plot%layout%shell_count
        if (model%shell_nodes(3, element) == model%shell_nodes(4, element)) then
          plot%shell_thickness(element) = sum(model%shell_thickness(1:3, element))/3.0_wp
        else
          plot%shell_thickness(element) = 0.25_wp*sum(model%shell_thickness(:, element))
        end if
      end do
    end if
    plot%beam_part = [integer ::]
    if (plot%layout%beam_count > 0) plot%beam_part = model%beam_part
  end subroutine set_layout

  ! --- the first file -------------------------------------------------------------------------

  !> The 64 control words (no extra words).
  subroutine write_header(plot, model, status, message)
    type(d3plot_file_t), intent(inout) :: plot
    type(model_t), intent(in) :: model
    integer, intent(out) :: status
    character(len=*), intent(inout) :: message
    integer(int32) :: control(64)
    character(len=40) :: title
    integer :: solid_materials, shell_materials, beam_materials

    title = ""
    if (allocated(model%title)) title = model%title
    solid_materials = 0
    if (plot%layout%solid_count > 0) solid_materials = distinct_count(model%solid_part, plot%layout%part_count)
    shell_materials = 0
    if (plot%layout%shell_count > 0) shell_materials = distinct_count(model%shell_part, plot%layout%part_count)
    beam_materials = 0
    if (plot%layout%beam_count > 0) beam_materials = distinct_count(model%beam_part, plot%layout%part_count)
    control = 0
    control(1:10) = transfer(title, control(1:10))
    control(11) = seconds_since_1970()                          ! RUNTIME
    control(12) = 1                                             ! FILETYPE: d3plot
    control(13) = 0                                             ! SOURCE
    control(14) = transfer("CRFR", control(14))                  ! RELEASE
    control(15) = transfer(971.0_real32, control(15))           ! VERSION
    control(16) = 4                                             ! NDIM: 3-D, connectivity unpacked
    control(17) = plot%layout%node_count                        ! NUMNP
    control(18) = 6                                             ! ICODE
    control(19) = plot%layout%global_count                      ! NGLBV
    control(20) = 0                                             ! IT: no temperatures
    control(21:23) = 1                                          ! IU IV IA
    control(24) = plot%layout%solid_count                       ! NEL8
    control(25) = solid_materials                               ! NUMMAT8
    control(28) = plot%layout%solid_values                      ! NV3D
    control(29) = plot%layout%beam_count                        ! NEL2
    control(30) = beam_materials                                ! NUMMAT2
    control(31) = plot%layout%beam_values                       ! NV1D
    control(32) = plot%layout%shell_count                       ! NEL4
    control(33) = shell_materials                               ! NUMMAT4
    control(34) = plot%layout%shell_values                      ! NV2D
    control(35) = merge(6, 0, plot%layout%strains)              ! NEIPH: the solids' strains
    control(36) = 0                                             ! NEIPS
    control(37) = -(plot%layout%shell_layers + 10000)           ! MAXINT, with element deletion flags
    control(40) = numbering_word_count(plot%layout)             ! NARBS
    control(44) = 1000                                          ! IOSHL(1): stresses
    control(45) = 1000                                          ! IOSHL(2): plastic strains
    control(46) = 1000                                          ! IOSHL(3): shell resultants
    control(47) = 1000                                          ! IOSHL(4): thickness, energy
    control(52) = plot%layout%part_count                        ! NMMAT
    if (plot%layout%strains) control(57) = 10000                ! IDTDT: ISTRN, the strain tensors
    write (plot%unit, iostat=status, iomsg=message) control
    plot%file_words = 64
  end subroutine write_header

  !> Nodes, solids, beams and shells (1-based node and part indices), written in chunks (of
  !> `geometry_chunk` elements, of stream_buffer_words): no copy of the whole mesh.
  subroutine write_geometry(plot, model, status, message)
    type(d3plot_file_t), intent(inout) :: plot
    type(model_t), intent(in) :: model
    integer, intent(out) :: status
    character(len=*), intent(inout) :: message
    integer(int32) :: solids(9, geometry_chunk), beams(6, geometry_chunk), shells(5, geometry_chunk)
    type(word_stream_t) :: stream
    integer :: first, last, element

    associate (layout => plot%layout)
      ! the coordinates after the control words; the elements follow where they end
      call open_word_stream(stream, plot%unit, plot%file_words, stream_buffer_words)
      call put_node_vectors(stream, layout%node_count, model%coordinates)
      call write_buffer(stream)
      status = stream%status
      if (status /= 0) message = stream%message
      do first = 1, layout%solid_count, geometry_chunk
        last = min(first + geometry_chunk - 1, layout%solid_count)
        do element = first, last
          solids(1:8, element - first + 1) = model%solid_nodes(:, element)
          solids(9, element - first + 1) = model%solid_part(element)
        end do
        if (status == 0) write (plot%unit, iostat=status, iomsg=message) solids(:, 1:last - first + 1)
      end do
      do first = 1, layout%beam_count, geometry_chunk
        last = min(first + geometry_chunk - 1, layout%beam_count)
        do element = first, last
          beams(1:3, element - first + 1) = model%beam_nodes(1:3, element)
          beams(4:5, element - first + 1) = 0
          beams(6, element - first + 1) = model%beam_part(element)
        end do
        if (status == 0) write (plot%unit, iostat=status, iomsg=message) beams(:, 1:last - first + 1)
      end do
      do first = 1, layout%shell_count, geometry_chunk
        last = min(first + geometry_chunk - 1, layout%shell_count)
        do element = first, last
          shells(1:4, element - first + 1) = model%shell_nodes(:, element)
          shells(5, element - first + 1) = model%shell_part(element)
        end do
        if (status == 0) write (plot%unit, iostat=status, iomsg=message) shells(:, 1:last - first + 1)
      end do
      plot%file_words = plot%file_words + 3_int64*layout%node_count + 9_int64*layout%solid_count + &
                        6_int64*layout%beam_count + 5_int64*layout%shell_count
    end associate
  end subroutine write_geometry

  !> Words of the first file before its final end marker: control words, geometry, numbering,
  !> the end marker and the part titles.
  pure function first_file_words(layout) result(words)
    type(d3plot_layout_t), intent(in) :: layout
    integer(int64) :: words
    words = 64_int64 + 3_int64*layout%node_count + 9_int64*layout%solid_count + 6_int64*layout%beam_count + &
            5_int64*layout%shell_count + numbering_word_count(layout) + 1 + 2 + &
            (1 + title_characters/4)*int(layout%part_count, int64)
  end function first_file_words

  !> NARBS: 16 words of pointers and counts, the node, solid, beam, shell (and thick shell: none)
  !> ids, and the part ids three times (sorted, as defined, and the cross-reference).
  pure integer function numbering_word_count(layout)
    type(d3plot_layout_t), intent(in) :: layout
    numbering_word_count = 16 + layout%node_count + layout%solid_count + layout%beam_count + &
                           layout%shell_count + 3*layout%part_count
  end function numbering_word_count

  subroutine write_numbering(plot, model, status, message)
    type(d3plot_file_t), intent(inout) :: plot
    type(model_t), intent(in) :: model
    integer, intent(out) :: status
    character(len=*), intent(inout) :: message
    integer(int32) :: pointers(16)
    integer(int32), allocatable :: part_ids(:), part_order(:)
    integer :: part, first

    associate (layout => plot%layout)
      ! pointers to the first word of each list, counted from 1 at this section's start; the
      ! negative node pointer says that the part lists follow
      first = 17
      pointers(1) = -first                                                    ! NSORT
      pointers(2) = first + layout%node_count                                 ! NSRH
      pointers(3) = pointers(2) + layout%solid_count                          ! NSRB
      pointers(4) = pointers(3) + layout%beam_count                           ! NSRS
      pointers(5) = pointers(4) + layout%shell_count                          ! NSRT
      pointers(6) = layout%node_count                                         ! NSORTD
      pointers(7) = layout%solid_count                                        ! NSRHD
      pointers(8) = layout%beam_count                                         ! NSRBD
      pointers(9) = layout%shell_count                                        ! NSRSD
      pointers(10) = 0                                                        ! NSRTD
      pointers(12) = pointers(5)                                              ! NSRMU
      pointers(11) = pointers(12) + layout%part_count                         ! NSRMA
      pointers(13) = pointers(11) + layout%part_count                         ! NSRMP
      pointers(14) = layout%part_count                                        ! NSRTM
      pointers(15) = 0                                                        ! NUMRBS
      pointers(16) = layout%part_count                                        ! NMMAT
      allocate (part_ids(layout%part_count), part_order(layout%part_count))
      do part = 1, layout%part_count
        part_ids(part) = model%parts(part)%id
        part_order(part) = part
      end do
      write (plot%unit, iostat=status, iomsg=message) pointers
      if (status == 0 .and. layout%node_count > 0) write (plot%unit, iostat=status, iomsg=message) &
        int(model%node_ids, int32)
      if (status == 0 .and. layout%solid_count > 0) write (plot%unit, iostat=status, iomsg=message) &
        int(model%solid_ids, int32)
      if (status == 0 .and. layout%beam_count > 0) write (plot%unit, iostat=status, iomsg=message) &
        int(model%beam_ids, int32)
      if (status == 0 .and. layout%shell_count > 0) write (plot%unit, iostat=status, iomsg=message) &
        int(model%shell_ids, int32)
      if (status == 0) write (plot%unit, iostat=status, iomsg=message) part_ids, part_ids, part_order
      plot%file_words = plot%file_words + numbering_word_count(layout)
    end associate
  end subroutine write_numbering

  !> The end-of-file marker, then type 90001: the part count and per part its id and 72
  !> characters of title (*PART's heading line).
  subroutine write_part_titles(plot, model, status, message)
    type(d3plot_file_t), intent(inout) :: plot
    type(model_t), intent(in) :: model
    integer, intent(out) :: status
    character(len=*), intent(inout) :: message
    character(len=title_characters) :: title
    integer :: part

    call write_end_marker(plot, status, message)
    if (status /= 0) return
    plot%file_words = plot%file_words + 1
    write (plot%unit, pos=4_int64*plot%file_words + 1, iostat=status, iomsg=message) part_titles_type, &
      int(plot%layout%part_count, int32)
    do part = 1, plot%layout%part_count
      if (status /= 0) exit
      title = ""
      if (allocated(model%parts(part)%title)) title = model%parts(part)%title
      write (plot%unit, iostat=status, iomsg=message) int(model%parts(part)%id, int32), title
    end do
    plot%file_words = plot%file_words + 2 + (1 + title_characters/4)*int(plot%layout%part_count, int64)
  end subroutine write_part_titles

  !> The end-of-file marker just after the file's words (not counted in them: the next state
  !> is written over it).
  subroutine write_end_marker(plot, status, message)
    type(d3plot_file_t), intent(inout) :: plot
    integer, intent(out) :: status
    character(len=*), intent(inout) :: message
    write (plot%unit, pos=4_int64*plot%file_words + 1, iostat=status, iomsg=message) end_marker
  end subroutine write_end_marker

  !> Close the file being written and start the next family file (states only).
  subroutine next_member(plot, status, message)
    type(d3plot_file_t), intent(inout) :: plot
    integer, intent(out) :: status
    character(len=*), intent(inout) :: message
    close (plot%unit, iostat=status, iomsg=message)
    plot%is_open = .false.
    if (status /= 0) return
    plot%member = plot%member + 1
    plot%path = plot%base_path//member_suffix(plot%member)
    open (newunit=plot%unit, file=plot%path, access="stream", form="unformatted", status="replace", &
          action="readwrite", iostat=status, iomsg=message)
    if (status /= 0) return
    plot%is_open = .true.
    plot%file_words = 0
    call write_end_marker(plot, status, message)
  end subroutine next_member

  !> A write failed: close what is open, write no more.
  subroutine fail(plot)
    type(d3plot_file_t), intent(inout) :: plot
    call close_d3plot(plot)
    plot%failed = .true.
  end subroutine fail

  !> LS-DYNA's family suffix: 01 ... 99, then 100, 101, ...
  pure function member_suffix(member) result(suffix)
    integer, intent(in) :: member
    character(len=:), allocatable :: suffix
    character(len=12) :: digits
    write (digits, '(i2.2)') member
    if (member > 99) write (digits, '(i0)') member
    suffix = trim(digits)
  end function member_suffix

  !> How many of the parts 1..part_count appear in `element_part`.
  pure integer function distinct_count(element_part, part_count)
    integer, intent(in) :: element_part(:)
    integer, intent(in) :: part_count
    logical :: used(part_count)
    integer :: element
    used = .false.
    do element = 1, size(element_part)
      if (element_part(element) >= 1 .and. element_part(element) <= part_count) used(element_part(element)) = .true.
    end do
    distinct_count = count(used)
  end function distinct_count

  !> RUNTIME: the wall-clock time of writing, in seconds since 1970-01-01 UTC.
  integer(int32) function seconds_since_1970()
    integer :: values(8), year, month, days
    integer(int64) :: seconds
    call date_and_time(values=values)
    ! days from the civil date (proleptic Gregorian), then local time minus its UTC offset
    year = values(1)
    month = values(2)
    if (month <= 2) year = year - 1
    days = 365*year + year/4 - year/100 + year/400 + (153*(month + merge(-3, 9, month > 2)) + 2)/5 + &
           values(3) - 1 - 719468
    seconds = 86400_int64*days + 3600_int64*values(5) + 60_int64*values(6) + values(7) - 60_int64*values(4)
    seconds_since_1970 = int(min(seconds, int(huge(1_int32), int64)), int32)
  end function seconds_since_1970
end module d3plot_file
