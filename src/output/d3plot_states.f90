!> What one state of LS-DYNA's d3plot database holds, and in which order: the layout of a
!> state (counts and the values per node and element, as the control words of the header say
!> them) and the assembly of one state's 32-bit words from crashfree's double-precision results,
!> section by section straight from the arrays the caller hands in, through a buffer of bounded
!> size (word_stream_t): writing a state takes no copy of a field nor a whole state of words.
!>
!> A state is, in LS-DYNA's order (d3plot database manual, "STATE DATA"): the time; NGLBV
!> global values; the nodes' current coordinates (IU), velocities (IV) and accelerations (IA);
!> per solid NV3D values (stress xx yy zz xy yz zx, effective plastic strain); per beam NV1D
!> values (axial force, shear s, shear t, bending moment s, bending moment t, torsion); per
!> shell NV2D values (per layer of MAXINT: stress xx yy zz xy yz zx, effective plastic
!> strain; then the resultants, thickness and energy density, shell_extra_values; with ISTRN the
!> strain tensors: solids 6 values after the plastic strain, shells 12, inner then outer
!> surface, before the energy density); and the deletion flags of the solids, shells and beams (the element's part number
!> while it is in the model, 0.0 once deleted), which LS-DYNA writes when MAXINT is given as
!> -(MAXINT + 10000).
module d3plot_states
  use, intrinsic :: iso_fortran_env, only: real32, int64
  use, intrinsic :: ieee_arithmetic, only: ieee_is_nan, ieee_value, ieee_quiet_nan, ieee_positive_inf, &
                                           ieee_negative_inf
  use kinds, only: wp
  use d3plot_strains, only: solid_hencky_strain, shell_hencky_strain
  implicit none
  private

  public :: d3plot_layout_t, state_word_count, shell_layer_values, single
  public :: word_stream_t, open_word_stream, put_values, put_words, put_zeros, write_buffer
  public :: put_node_vectors, put_solids, put_beams, put_shells, put_deletion_flags

  !> The sizes of a state, fixed when the database is opened.
  type :: d3plot_layout_t
    integer :: node_count = 0     !< NUMNP
    integer :: solid_count = 0    !< NEL8
    integer :: shell_count = 0    !< NEL4
    integer :: beam_count = 0     !< NEL2
    integer :: part_count = 0     !< NMMAT
    integer :: shell_layers = 1   !< MAXINT: through-thickness points written per shell
    integer :: global_count = 0   !< NGLBV: 6 + 2 per part (internal, kinetic energy)
    integer :: solid_values = 7   !< NV3D
    integer :: beam_values = 6    !< NV1D
    integer :: shell_values = 19  !< NV2D = MAXINT * 7 + 12 (+ 12 with strains)
    !> ISTRN (*DATABASE_EXTENT_BINARY STRFLG = 1): a strain tensor per solid after its plastic
    !> strain (NV3D = 13, as NEIPH = 6 extra values), two per shell (inner, outer surface) after
    !> its thickness and the two element-dependent values, before the energy density
    logical :: strains = .false.
  end type d3plot_layout_t

  !> After the layers, per shell (IOSHL(3) = IOSHL(4) = 1000): M_xx M_yy M_xy Q_x Q_y N_xx N_yy
  !> N_xy (local frame, per unit width), thickness, two element-dependent values, internal
  !> energy density.
  integer, parameter, public :: shell_extra_values = 12

  !> 32-bit words on their way to a file open for stream access: put into a buffer of bounded
  !> size, written at their place in the file whenever it is full (and by write_buffer).
  type :: word_stream_t
    integer :: unit = -1
    integer(int64) :: buffer_start = 0            !< word of the file (0-based) for buffer(1)
    integer :: filled = 0                         !< words in the buffer
    integer(int64) :: written = 0                 !< words passed to the file
    real(real32), allocatable :: buffer(:)
    integer :: status = 0                         !< of the first write that failed
    character(len=256) :: message = ""
  end type word_stream_t

contains

  !> Words of one state (the time word included).
  pure function state_word_count(layout) result(words)
    type(d3plot_layout_t), intent(in) :: layout
    integer(int64) :: words
    words = 1_int64 + layout%global_count + 9_int64*layout%node_count + &
            int(layout%solid_values, int64)*layout%solid_count + &
            int(layout%beam_values, int64)*layout%beam_count + &
            int(layout%shell_values, int64)*layout%shell_count + &
            int(layout%solid_count + layout%shell_count + layout%beam_count, int64)
  end function state_word_count

  !> Start a stream at word `first_word` (0-based) of the file open on `unit`, with a buffer of
  !> `capacity` words.
  subroutine open_word_stream(stream, unit, first_word, capacity)
    type(word_stream_t), intent(out) :: stream
    integer, intent(in) :: unit
    integer(int64), intent(in) :: first_word
    integer, intent(in) :: capacity
    stream%unit = unit
    stream%buffer_start = first_word
    allocate (stream%buffer(max(1, capacity)))
  end subroutine open_word_stream

  !> Append `values` (as 32-bit words, see `single`) to the stream.
  subroutine put_values(stream, values)
    type(word_stream_t), intent(inout) :: stream
    real(wp), intent(in) :: values(:)
    integer :: k
    do k = 1, size(values)
      if (stream%filled == size(stream%buffer)) call write_buffer(stream)
      stream%filled = stream%filled + 1
      stream%buffer(stream%filled) = single(values(k))
    end do
  end subroutine put_values

  !> Append 32-bit words to the stream.
  subroutine put_words(stream, words)
    type(word_stream_t), intent(inout) :: stream
    real(real32), intent(in) :: words(:)
    integer :: k
    do k = 1, size(words)
      if (stream%filled == size(stream%buffer)) call write_buffer(stream)
      stream%filled = stream%filled + 1
      stream%buffer(stream%filled) = words(k)
    end do
  end subroutine put_words

  !> Append `count` zero words to the stream.
  subroutine put_zeros(stream, count)
    type(word_stream_t), intent(inout) :: stream
    integer, intent(in) :: count
    integer :: k
    do k = 1, count
      call put_words(stream, [0.0_real32])
    end do
  end subroutine put_zeros

  !> Write what the buffer holds: after this the file has every word put. The words written
  !> are counted in `stream%written`; after a failed write (`stream%status` /= 0) nothing more is
  !> written.
  subroutine write_buffer(stream)
    type(word_stream_t), intent(inout) :: stream
    if (stream%status == 0 .and. stream%filled > 0) &
      write (stream%unit, pos=4_int64*stream%buffer_start + 1, iostat=stream%status, iomsg=stream%message) &
        stream%buffer(1:stream%filled)
    stream%buffer_start = stream%buffer_start + stream%filled
    stream%written = stream%written + stream%filled
    stream%filled = 0
  end subroutine write_buffer

  !> Put the nodal vectors `base + offset` (3, nodes) (`offset` absent: `base`; `base` absent:
  !> zeros) without forming the sum of the whole arrays.
  subroutine put_node_vectors(stream, node_count, base, offset)
    type(word_stream_t), intent(inout) :: stream
    integer, intent(in) :: node_count
    real(wp), intent(in), optional :: base(:, :), offset(:, :)
    real(wp) :: vector(3)
    integer :: node
    do node = 1, node_count
      if (.not. present(base)) then
        call put_zeros(stream, 3)
      else if (present(offset)) then
        ! (a named vector: an expression as the argument would be a temporary on the heap)
        vector = base(:, node) + offset(:, node)
        call put_values(stream, vector)
      else
        call put_values(stream, base(:, node))
      end if
    end do
  end subroutine put_node_vectors

  !> Per solid its NV3D values: stress, effective plastic strain, with layout%strains the
  !> strain tensor measured from `reference` and `displacement` on `solid_nodes` (8, solids).
  subroutine put_solids(stream, layout, solid_stress, solid_plastic_strain, reference, displacement, solid_nodes)
    type(word_stream_t), intent(inout) :: stream
    type(d3plot_layout_t), intent(in) :: layout
    real(wp), intent(in) :: solid_stress(:, :), solid_plastic_strain(:)
    real(wp), intent(in) :: reference(:, :), displacement(:, :)
    integer, intent(in) :: solid_nodes(:, :)
    integer :: element
    do element = 1, layout%solid_count
      call put_values(stream, solid_stress(:, element))
      call put_values(stream, [solid_plastic_strain(element)])
      if (layout%strains) &
        call put_values(stream, solid_hencky_strain(reference, displacement, solid_nodes(:, element)))
    end do
  end subroutine put_solids

  !> Per beam its NV1D values: LS-DYNA's resultant order from crashfree's (N, Q_s, Q_t, T, M_s,
  !> M_t); zeros without `beam_resultant`.
  subroutine put_beams(stream, layout, beam_resultant)
    type(word_stream_t), intent(inout) :: stream
    type(d3plot_layout_t), intent(in) :: layout
    real(wp), intent(in), optional :: beam_resultant(:, :)
    integer, parameter :: beam_order(6) = [1, 2, 3, 5, 6, 4]
    integer :: element
    do element = 1, layout%beam_count
      if (present(beam_resultant)) then
        call put_values(stream, beam_resultant(beam_order, element))
      else
        call put_zeros(stream, layout%beam_values)
      end if
    end do
  end subroutine put_beams

  !> Per shell its NV2D values: the MAXINT layers (stress, effective plastic strain), then the
  !> resultants, thickness, two element-dependent values, (with layout%strains the strain
  !> tensors of the inner and outer surface,) the internal energy density.
  !>
  !> The layers come from the shell's points through the thickness (`shell_point_stress` (6,
  !> points, shells), `shell_point_plastic_strain`, `shell_point_count`, see
  !> shell_layer_values); a shell without points (meshfree shells, rigid parts, a static state)
  !> has its mid-surface values `shell_stress` (6, shells), `shell_plastic_strain` in every
  !> layer. The resultants, thickness and energy density are the group's (`shell_resultant`
  !> (8, shells), `shell_thickness`, `shell_energy_density`) for a shell with points, else
  !> zeros with the deck's thickness `deck_thickness`; without `shell_stress` all are zero.
  subroutine put_shells(stream, layout, deck_thickness, reference, displacement, shell_nodes, shell_stress, &
                        shell_plastic_strain, shell_point_stress, shell_point_plastic_strain, shell_point_count, &
                        shell_resultant, shell_thickness, shell_energy_density)
    type(word_stream_t), intent(inout) :: stream
    type(d3plot_layout_t), intent(in) :: layout
    real(wp), intent(in) :: deck_thickness(:)
    real(wp), intent(in) :: reference(:, :), displacement(:, :)
    integer, intent(in) :: shell_nodes(:, :)
    real(wp), intent(in), optional :: shell_stress(:, :), shell_plastic_strain(:)
    real(wp), intent(in), optional :: shell_point_stress(:, :, :), shell_point_plastic_strain(:, :)
    integer, intent(in), optional :: shell_point_count(:)
    real(wp), intent(in), optional :: shell_resultant(:, :), shell_thickness(:), shell_energy_density(:)
    real(wp) :: layer_stress(6, layout%shell_layers), layer_strain(layout%shell_layers)
    real(wp) :: extra(shell_extra_values), strain(6)
    integer :: shell, layer, points

    do shell = 1, layout%shell_count
      layer_stress = 0.0_wp
      layer_strain = 0.0_wp
      extra = 0.0_wp
      if (present(shell_stress)) then
        points = 0
        if (present(shell_point_count)) points = min(shell_point_count(shell), size(shell_point_stress, 2))
        extra(9) = deck_thickness(shell)
        if (points > 0) then
          call shell_layer_values(points, shell_point_stress(:, 1:points, shell), &
                                  shell_point_plastic_strain(1:points, shell), layer_stress, layer_strain)
          if (present(shell_resultant)) then
            extra(1:8) = shell_resultant(:, shell)
            extra(9) = shell_thickness(shell)
            extra(12) = shell_energy_density(shell)
          end if
        else
          do layer = 1, layout%shell_layers
            layer_stress(:, layer) = shell_stress(:, shell)
            layer_strain(layer) = shell_plastic_strain(shell)
          end do
        end if
      end if
      do layer = 1, layout%shell_layers
        call put_values(stream, layer_stress(:, layer))
        call put_values(stream, [layer_strain(layer)])
      end do
      if (layout%strains) then
        ! measured with the thickness of the state, extra(9); inner then outer surface
        strain = shell_hencky_strain(reference, displacement, shell_nodes(:, shell), extra(9), deck_thickness(shell))
        call put_values(stream, extra(1:shell_extra_values - 1))
        call put_values(stream, strain)
        call put_values(stream, strain)
        call put_values(stream, extra(shell_extra_values:shell_extra_values))
      else
        call put_values(stream, extra)
      end if
    end do
  end subroutine put_shells

  !> Deletion flags of one family: LS-DYNA writes the element's material (part) number, 0 for
  !> a deleted element: one with `eroded` /= 0 or `failed` > 0.5 (absent: none is).
  subroutine put_deletion_flags(stream, element_part, eroded, failed)
    type(word_stream_t), intent(inout) :: stream
    integer, intent(in) :: element_part(:)
    integer, intent(in), optional :: eroded(:)
    real(wp), intent(in), optional :: failed(:)
    logical :: deleted
    integer :: element
    do element = 1, size(element_part)
      deleted = .false.
      if (present(eroded)) deleted = eroded(element) /= 0
      if (present(failed)) deleted = failed(element) > 0.5_wp
      if (deleted) then
        call put_words(stream, [0.0_real32])
      else
        call put_words(stream, [real(element_part(element), real32)])
      end if
    end do
  end subroutine put_deletion_flags

  !> One shell's layers from its `count` points through the thickness (bottom to top), as
  !> LS-DYNA writes them: with MAXINT = 3 the mid surface (the middle point, or the mean of the
  !> two nearest it for an even count), the inner (first) and the outer (last) point; with any
  !> other MAXINT the first MAXINT points in order (layers beyond `count` are 0).
  pure subroutine shell_layer_values(count, point_stress, point_strain, layer_stress, layer_strain)
    integer, intent(in) :: count
    real(wp), intent(in) :: point_stress(:, :), point_strain(:)     ! (6, points), (points)
    real(wp), intent(out) :: layer_stress(:, :), layer_strain(:)    ! (6, MAXINT), (MAXINT)
    integer :: layers, middle
    layers = size(layer_strain)
    layer_stress = 0.0_wp
    layer_strain = 0.0_wp
    if (count < 1) return
    if (layers == 3) then
      middle = (count + 1)/2
      if (mod(count, 2) == 1) then
        layer_stress(:, 1) = point_stress(:, middle)
        layer_strain(1) = point_strain(middle)
      else
        layer_stress(:, 1) = 0.5_wp*(point_stress(:, middle) + point_stress(:, middle + 1))
        layer_strain(1) = 0.5_wp*(point_strain(middle) + point_strain(middle + 1))
      end if
      layer_stress(:, 2) = point_stress(:, 1)
      layer_strain(2) = point_strain(1)
      layer_stress(:, 3) = point_stress(:, count)
      layer_strain(3) = point_strain(count)
    else
      layer_stress(:, 1:min(count, layers)) = point_stress(:, 1:min(count, layers))
      layer_strain(1:min(count, layers)) = point_strain(1:min(count, layers))
    end if
  end subroutine shell_layer_values

  !> A double-precision value as a 32-bit word: beyond single precision's range (a run that
  !> blew up) it is written as an infinity of its sign, NaN as NaN, without the overflow a plain
  !> conversion raises.
  elemental function single(value) result(word)
    real(wp), intent(in) :: value
    real(real32) :: word
    if (ieee_is_nan(value)) then
      word = ieee_value(word, ieee_quiet_nan)
    else if (value > huge(word)) then
      word = ieee_value(word, ieee_positive_inf)
    else if (value < -huge(word)) then
      word = ieee_value(word, ieee_negative_inf)
    else
      word = real(value, real32)
    end if
  end function single
end module d3plot_states
