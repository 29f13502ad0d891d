!> *MAT_HONEYCOMB (LS-DYNA material 26) and *MAT_MODIFIED_HONEYCOMB (material 126, LCA > 0)
!> for solids: orthotropic, uncoupled crushable behaviour up to full compaction, then isotropic
!> elastic-perfectly plastic (LS-DYNA Keyword User's Manual Vol. II, *MAT_026 and *MAT_126;
!> LS-DYNA Theory Manual, "Material Model 26: Crushable Foam / Honeycomb"; Hallquist).
!>
!> Uncompacted (V/V0 > VF), in the material axes a, b, c:
!>
!>   beta     = max(min((1 - V/V0) / (1 - VF), 1), 0)
!>   E_ii(V)  = E_iiu + beta (E - E_iiu)             (EAAU, EBBU, ECCU)
!>   G_ij(V)  = G_iju + beta (G - G_iju),  G = E / (2 (1 + PR))   (GABU, GBCU, GCAU)
!>   sigma_ii^trial = sigma_ii^n + E_ii de_ii,   sigma_ij^trial = sigma_ij^n + 2 G_ij de_ij
!>   |sigma_ij| <= k(rate) |f_ij(x)|  (f: LCA, LCB, LCC, LCAB, LCBC, LCCA)
!>
!> each component independently (no Poisson coupling). The abscissa x of the yield curves is
!> the volumetric strain 1 - V/V0 for *MAT_026 (LS-DYNA's Figure M26-1: "the time value is
!> the volumetric strain") and, for *MAT_126 with LCA > 0, the magnitude of the component's own
!> logarithmic strain (normal: |eps_ii|, shear: engineering |2 eps_ij|), accumulated in the
!> material axes from the strain increments (the Keyword Manual: logarithmic strain for solid
!> formulations other than 0 and 9).
!>
!> Fully compacted (V/V0 <= VF once reached; the state is kept): the stress is updated with
!> the moduli E, PR, then returned radially to the von Mises surface of radius SIGY.
!>
!> Strain rate (LCSR > 0): the yield curves are scaled by k = LCSR(rate), the rate being the
!> effective total strain rate sqrt(2/3 D:D) (an assumption: the manuals do not define it).
!>
!> Viscous damping MU: LS-DYNA's honeycomb viscosity is a stress q = MU rho c L D added to
!> each component; with rho c^2 = C (the component's current modulus: E_ii(V), 2 G_ij, or
!> K + 4G/3 and 2G once compacted) and L / c replaced by the time step, q_ij = MU C_ij D_ij dt.
!> It is kept apart from the elastic-plastic stress: the previous step's q is subtracted before
!> the update and the new one added after it (history), so it never accumulates.
!>
!> Material axes are stored per integration point as the global components of a, b, c and are
!> rotated with the element by the objective (Jaumann) rotation, like the stress.
module material_honeycomb
  use kinds, only: wp, block_size
  use curves, only: curve_t, curve_value, smallest_magnitude_from
  implicit none
  private

  public :: honeycomb_update, honeycomb_initialize_axes

  ! History variables per integration point: 23 in all (law_table in material_laws), laid out
  ! as follows.
  !> ln(V/V0), accumulated from the trace of the strain increments.
  integer, parameter, public :: honeycomb_log_volume_slot = 1
  !> 1 once fully compacted, else 0.
  integer, parameter, public :: honeycomb_compacted_slot = 2
  !> First of nine slots: global components of the axes a (3), b (3), c (3).
  integer, parameter, public :: honeycomb_axes_first_slot = 3
  !> First of six slots: viscous stress of the last step, in the material axes.
  integer, parameter, public :: honeycomb_viscous_first_slot = 12
  !> First of six slots: logarithmic strain in the material axes (tensor shear), used by 126.
  integer, parameter, public :: honeycomb_strain_first_slot = 18

contains

  !> Initial axes of lanes 1..nel from two vectors per lane: a along `first`, c = a x d with d
  !> = `second`, b = c x a (LS-DYNA's AOPT 2 construction, also used for AOPT 0 with the
  !> element edges 1-2 and 1-4). Degenerate input gives the global axes.
  subroutine honeycomb_initialize_axes(nel, first, second, axes)
    integer, intent(in) :: nel
    real(wp), intent(in) :: first(block_size, 3), second(block_size, 3)
    real(wp), intent(out) :: axes(block_size, 9)
    real(wp) :: a(3), b(3), c(3), d(3), length
    integer :: i
    do i = 1, nel
      a = first(i, :)
      d = second(i, :)
      length = norm2(a)
      c = cross(a, d)
      if (length <= 0.0_wp .or. norm2(c) <= 1.0e-12_wp*length*norm2(d)) then
        axes(i, :) = [1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 1.0_wp]
        cycle
      end if
      a = a/length
      c = c/norm2(c)
      b = cross(c, a)
      axes(i, 1:3) = a
      axes(i, 4:6) = b
      axes(i, 7:9) = c
    end do
  end subroutine honeycomb_initialize_axes

  !> Update of lanes 1..nel. `strain_increment`: D dt with tensor shear, global axes, order xx,
  !> yy, zz, xy, yz, zx; `stress` enters rotated to the end of the step. `yield_curves` are
  !> aa, bb, cc, ab, bc, ca; `rate_curve` is used when `has_rate_curve`. `modified` selects the
  !> *MAT_126 abscissa (component strain) instead of the volumetric strain of *MAT_026.
  subroutine honeycomb_update(nel, modified, youngs_modulus, poissons_ratio, yield_stress, compaction_volume, &
                              viscosity, uncompacted_moduli, yield_curves, has_rate_curve, rate_curve, time_step, &
                              strain_increment, stress, history)
    integer, intent(in) :: nel
    logical, intent(in) :: modified
    real(wp), intent(in) :: youngs_modulus, poissons_ratio, yield_stress, compaction_volume, viscosity
    real(wp), intent(in) :: uncompacted_moduli(6)
    type(curve_t), intent(in) :: yield_curves(6)
    logical, intent(in) :: has_rate_curve
    type(curve_t), intent(in) :: rate_curve
    real(wp), intent(in) :: time_step
    real(wp), intent(in) :: strain_increment(block_size, 6)
    real(wp), intent(inout) :: stress(block_size, 6)
    real(wp), intent(inout), contiguous :: history(:, :)

    real(wp) :: axes(3, 3), local_stress(6), local_increment(6), modulus(6), trial(6), viscous(6)
    real(wp) :: bulk, shear, compacted_moduli(6), relative_volume, beta, abscissa, limit
    real(wp) :: rate_factor, rate, mean, deviator(6), effective, scale, volumetric_increment
    real(wp) :: least_yield(6)
    integer :: i, k
    integer, parameter :: axes_first = honeycomb_axes_first_slot, viscous_first = honeycomb_viscous_first_slot
    integer, parameter :: strain_first = honeycomb_strain_first_slot

    shear = youngs_modulus/(2.0_wp*(1.0_wp + poissons_ratio))
    bulk = youngs_modulus/(3.0_wp*(1.0_wp - 2.0_wp*poissons_ratio))
    compacted_moduli = [youngs_modulus, youngs_modulus, youngs_modulus, shear, shear, shear]
    ! a trial stress below the least the yield curve reaches is inside the yield surface
    ! whatever the strain: most points of a barrier, away from the crush zone, then need no
    ! curve evaluation. *MAT_126's abscissae (strain magnitudes) are >= 0; *MAT_026's volumetric
    ! strain is negative in expansion, where the curve is extrapolated: no bound there.
    least_yield = 0.0_wp
    if (modified) then
      do k = 1, 6
        least_yield(k) = smallest_magnitude_from(yield_curves(k), 0.0_wp)
      end do
    end if

    do i = 1, nel
      ! rows of `axes` are a, b, c (element by element: the history row is strided)
      do k = 1, 3
        axes(1, k) = history(i, axes_first + k - 1)
        axes(2, k) = history(i, axes_first + 2 + k)
        axes(3, k) = history(i, axes_first + 5 + k)
      end do
      call to_axes(axes, stress(i, 1), stress(i, 2), stress(i, 3), stress(i, 4), stress(i, 5), stress(i, 6), &
                   local_stress)
      do k = 1, 6
        local_stress(k) = local_stress(k) - history(i, viscous_first + k - 1)
      end do
      call to_axes(axes, strain_increment(i, 1), strain_increment(i, 2), strain_increment(i, 3), &
                   strain_increment(i, 4), strain_increment(i, 5), strain_increment(i, 6), local_increment)
      volumetric_increment = strain_increment(i, 1) + strain_increment(i, 2) + strain_increment(i, 3)
      history(i, honeycomb_log_volume_slot) = history(i, honeycomb_log_volume_slot) + volumetric_increment
      do k = 1, 6
        history(i, strain_first + k - 1) = history(i, strain_first + k - 1) + local_increment(k)
      end do
      ! (an element folding through itself can pile up logarithmic strain beyond exp's range;
      ! a relative volume of e^50 means the same to the law as any larger one)
      relative_volume = exp(min(history(i, honeycomb_log_volume_slot), 50.0_wp))
      if (relative_volume <= compaction_volume) history(i, honeycomb_compacted_slot) = 1.0_wp

      if (history(i, honeycomb_compacted_slot) > 0.5_wp) then
        ! Isotropic elastic-perfectly plastic (von Mises, SIGY); isotropy makes the axes irrelevant.
        mean = (local_stress(1) + local_stress(2) + local_stress(3))/3.0_wp + bulk*volumetric_increment
        do k = 1, 3
          deviator(k) = local_stress(k) - (local_stress(1) + local_stress(2) + local_stress(3))/3.0_wp &
                        + 2.0_wp*shear*(local_increment(k) - volumetric_increment/3.0_wp)
          deviator(k + 3) = local_stress(k + 3) + 2.0_wp*shear*local_increment(k + 3)
        end do
        effective = sqrt(1.5_wp*(deviator(1)**2 + deviator(2)**2 + deviator(3)**2) &
                         + 3.0_wp*(deviator(4)**2 + deviator(5)**2 + deviator(6)**2))
        scale = 1.0_wp
        if (effective > yield_stress) scale = yield_stress/effective
        do k = 1, 3
          trial(k) = scale*deviator(k) + mean
          trial(k + 3) = scale*deviator(k + 3)
          modulus(k) = bulk + 4.0_wp*shear/3.0_wp
          modulus(k + 3) = 2.0_wp*shear
        end do
      else
        beta = max(min((1.0_wp - relative_volume)/(1.0_wp - compaction_volume), 1.0_wp), 0.0_wp)
        do k = 1, 6
          modulus(k) = uncompacted_moduli(k) + beta*(compacted_moduli(k) - uncompacted_moduli(k))
        end do
        modulus(4:6) = 2.0_wp*modulus(4:6)          ! tensor shear increments
        rate_factor = 1.0_wp
        if (has_rate_curve .and. time_step > 0.0_wp) then
          rate = sqrt(2.0_wp/3.0_wp*(strain_increment(i, 1)**2 + strain_increment(i, 2)**2 + strain_increment(i, 3)**2 &
                                     + 2.0_wp*(strain_increment(i, 4)**2 + strain_increment(i, 5)**2 &
                                               + strain_increment(i, 6)**2)))/time_step
          rate_factor = curve_value(rate_curve, rate)
        end if
        do k = 1, 6
          trial(k) = local_stress(k) + modulus(k)*local_increment(k)
          if (abs(trial(k)) <= rate_factor*least_yield(k)) cycle
          if (modified) then
            abscissa = abs(history(i, strain_first + k - 1))
            if (k > 3) abscissa = 2.0_wp*abscissa
          else
            abscissa = 1.0_wp - relative_volume
          end if
          limit = rate_factor*abs(curve_value(yield_curves(k), abscissa))
          if (abs(trial(k)) > limit) trial(k) = sign(limit, trial(k))
        end do
      end if

      do k = 1, 6
        viscous(k) = viscosity*modulus(k)*local_increment(k)
        history(i, viscous_first + k - 1) = viscous(k)
        trial(k) = trial(k) + viscous(k)
      end do
      call from_axes(axes, trial, stress(i, 1), stress(i, 2), stress(i, 3), stress(i, 4), stress(i, 5), stress(i, 6))
    end do
  end subroutine honeycomb_update

  !> Components in the axes whose rows q1, q2, q3 are a, b, c: S'_kl = q_k . S q_l (6-vector,
  !> tensor shear; written out so that the kernel makes no array temporaries).
  pure subroutine to_axes(axes, sxx, syy, szz, sxy, syz, szx, local)
    real(wp), intent(in) :: axes(3, 3), sxx, syy, szz, sxy, syz, szx
    real(wp), intent(out) :: local(6)
    real(wp) :: product(3, 3)
    integer :: k
    ! product(:, k) = S q_k
    do k = 1, 3
      product(1, k) = sxx*axes(k, 1) + sxy*axes(k, 2) + szx*axes(k, 3)
      product(2, k) = sxy*axes(k, 1) + syy*axes(k, 2) + syz*axes(k, 3)
      product(3, k) = szx*axes(k, 1) + syz*axes(k, 2) + szz*axes(k, 3)
    end do
    local(1) = axes(1, 1)*product(1, 1) + axes(1, 2)*product(2, 1) + axes(1, 3)*product(3, 1)
    local(2) = axes(2, 1)*product(1, 2) + axes(2, 2)*product(2, 2) + axes(2, 3)*product(3, 2)
    local(3) = axes(3, 1)*product(1, 3) + axes(3, 2)*product(2, 3) + axes(3, 3)*product(3, 3)
    local(4) = axes(1, 1)*product(1, 2) + axes(1, 2)*product(2, 2) + axes(1, 3)*product(3, 2)
    local(5) = axes(2, 1)*product(1, 3) + axes(2, 2)*product(2, 3) + axes(2, 3)*product(3, 3)
    local(6) = axes(3, 1)*product(1, 1) + axes(3, 2)*product(2, 1) + axes(3, 3)*product(3, 1)
  end subroutine to_axes

  !> Global components from the material ones: S = sum_kl S'_kl q_k (x) q_l.
  pure subroutine from_axes(axes, local, sxx, syy, szz, sxy, syz, szx)
    real(wp), intent(in) :: axes(3, 3), local(6)
    real(wp), intent(out) :: sxx, syy, szz, sxy, syz, szx
    real(wp) :: weighted(3, 3)
    integer :: j
    ! weighted(k, :) = sum_l S'_kl q_l
    do j = 1, 3
      weighted(1, j) = local(1)*axes(1, j) + local(4)*axes(2, j) + local(6)*axes(3, j)
      weighted(2, j) = local(4)*axes(1, j) + local(2)*axes(2, j) + local(5)*axes(3, j)
      weighted(3, j) = local(6)*axes(1, j) + local(5)*axes(2, j) + local(3)*axes(3, j)
    end do
    sxx = axes(1, 1)*weighted(1, 1) + axes(2, 1)*weighted(2, 1) + axes(3, 1)*weighted(3, 1)
    syy = axes(1, 2)*weighted(1, 2) + axes(2, 2)*weighted(2, 2) + axes(3, 2)*weighted(3, 2)
    szz = axes(1, 3)*weighted(1, 3) + axes(2, 3)*weighted(2, 3) + axes(3, 3)*weighted(3, 3)
    sxy = axes(1, 1)*weighted(1, 2) + axes(2, 1)*weighted(2, 2) + axes(3, 1)*weighted(3, 2)
    syz = axes(1, 2)*weighted(1, 3) + axes(2, 2)*weighted(2, 3) + axes(3, 2)*weighted(3, 3)
    szx = axes(1, 3)*weighted(1, 1) + axes(2, 3)*weighted(2, 1) + axes(3, 3)*weighted(3, 1)
  end subroutine from_axes

  pure function cross(u, v) result(w)
    real(wp), intent(in) :: u(3), v(3)
    real(wp) :: w(3)
    w = [u(2)*v(3) - u(3)*v(2), u(3)*v(1) - u(1)*v(3), u(1)*v(2) - u(2)*v(1)]
  end function cross
end module material_honeycomb
