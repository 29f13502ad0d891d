!> What one state of LS-DYNA's d3plot database holds, and in which order: the layout of a
!> state (counts and the values per node and element, as the control words of the header say
!> them) and the assembly of one state's 32-bit words from crashfree's double-precision results.
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
  implicit none
  private

  public :: d3plot_layout_t, state_word_count, fill_state_words, shell_layer_values, single

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

  !> The words of one state into `words` (size state_word_count). `globals` are the NGLBV
  !> global values; `coordinates`, `velocity`, `acceleration` (3, nodes) the physical nodal
  !> values; `shell_stress` (6, MAXINT, shells) and `shell_plastic_strain` (MAXINT, shells) the
  !> layers; `beam_resultant` (6, beams) in crashfree's order N, Q_s, Q_t, T, M_s, M_t; the
  !> part numbers of the elements; the eroded flags 1 for an element out of the model (absent:
  !> none is); with layout%strains the strain tensors, `solid_strain` (6, solids) and
  !> `shell_strain` (6, 2, shells: inner, outer surface), xx yy zz xy yz zx.
  subroutine fill_state_words(layout, time, globals, coordinates, velocity, acceleration, solid_stress, &
                              solid_plastic_strain, shell_stress, shell_plastic_strain, shell_extra, beam_resultant, &
                              solid_part, shell_part, beam_part, words, solid_eroded, shell_eroded, beam_failed, &
                              solid_strain, shell_strain)
    type(d3plot_layout_t), intent(in) :: layout
    real(wp), intent(in) :: time
    real(wp), intent(in) :: globals(:)
    real(wp), intent(in) :: coordinates(:, :), velocity(:, :), acceleration(:, :)
    real(wp), intent(in) :: solid_stress(:, :), solid_plastic_strain(:)
    real(wp), intent(in) :: shell_stress(:, :, :), shell_plastic_strain(:, :)
    real(wp), intent(in) :: shell_extra(:, :)        !< (shell_extra_values, shells)
    real(wp), intent(in) :: beam_resultant(:, :)
    integer, intent(in) :: solid_part(:), shell_part(:), beam_part(:)   !< part numbers (1-based)
    real(real32), intent(out) :: words(:)
    integer, intent(in), optional :: solid_eroded(:), shell_eroded(:)
    real(wp), intent(in), optional :: beam_failed(:)
    real(wp), intent(in), optional :: solid_strain(:, :), shell_strain(:, :, :)
    integer(int64) :: next
    integer :: node, element, layer
    ! LS-DYNA's beam resultant order from crashfree's (N, Q_s, Q_t, T, M_s, M_t)
    integer, parameter :: beam_order(6) = [1, 2, 3, 5, 6, 4]

    words = 0.0_real32
    words(1) = single(time)
    next = 2
    words(next:next + layout%global_count - 1) = single(globals(1:layout%global_count))
    next = next + layout%global_count
    do node = 1, layout%node_count
      words(next:next + 2) = single(coordinates(:, node))
      next = next + 3
    end do
    do node = 1, layout%node_count
      words(next:next + 2) = single(velocity(:, node))
      next = next + 3
    end do
    do node = 1, layout%node_count
      words(next:next + 2) = single(acceleration(:, node))
      next = next + 3
    end do
    do element = 1, layout%solid_count
      words(next:next + 5) = single(solid_stress(:, element))
      words(next + 6) = single(solid_plastic_strain(element))
      if (layout%strains .and. present(solid_strain)) words(next + 7:next + 12) = single(solid_strain(:, element))
      next = next + layout%solid_values
    end do
    do element = 1, layout%beam_count
      words(next:next + 5) = single(beam_resultant(beam_order, element))
      next = next + layout%beam_values
    end do
    do element = 1, layout%shell_count
      do layer = 1, layout%shell_layers
        words(next:next + 5) = single(shell_stress(:, layer, element))
        words(next + 6) = single(shell_plastic_strain(layer, element))
        next = next + 7
      end do
      if (layout%strains) then
        ! resultants, thickness, the two element-dependent values; the strains; the energy density
        words(next:next + shell_extra_values - 2) = single(shell_extra(1:shell_extra_values - 1, element))
        next = next + shell_extra_values - 1
        if (present(shell_strain)) then
          words(next:next + 5) = single(shell_strain(:, 1, element))
          words(next + 6:next + 11) = single(shell_strain(:, 2, element))
        end if
        next = next + 12
        words(next) = single(shell_extra(shell_extra_values, element))
        next = next + 1
      else
        words(next:next + shell_extra_values - 1) = single(shell_extra(:, element))
        next = next + shell_extra_values
      end if
    end do
    ! deletion flags: solids, (thick shells: none), shells, beams; LS-DYNA writes the element's
    ! material (part) number, 0 for a deleted element
    words(next:next + layout%solid_count - 1) = real(solid_part, real32)
    if (present(solid_eroded)) then
      do element = 1, layout%solid_count
        if (solid_eroded(element) /= 0) words(next + element - 1) = 0.0_real32
      end do
    end if
    next = next + layout%solid_count
    words(next:next + layout%shell_count - 1) = real(shell_part, real32)
    if (present(shell_eroded)) then
      do element = 1, layout%shell_count
        if (shell_eroded(element) /= 0) words(next + element - 1) = 0.0_real32
      end do
    end if
    next = next + layout%shell_count
    words(next:next + layout%beam_count - 1) = real(beam_part, real32)
    if (present(beam_failed)) then
      do element = 1, layout%beam_count
        if (beam_failed(element) > 0.5_wp) words(next + element - 1) = 0.0_real32
      end do
    end if
  end subroutine fill_state_words

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
