!> Cross-check of the materials that use curves or need a particular kind of part:
!> - *MAT_HONEYCOMB, *MAT_MODIFIED_HONEYCOMB, *MAT_LOW_DENSITY_FOAM (the crushable laws) and
!>   *MAT_PIECEWISE_LINEAR_PLASTICITY: their curve ids resolved to copies of the curves kept in
!>   the material (so that the law kernels get them through the material dispatch);
!> - the crushable laws restricted to the hexahedron formulations ELFORM 1 and 2;
!> - shell parts restricted to the laws with a plane-stress kernel (plane_stress_dispatch), and
!>   *MAT_NULL to shell parts (on solids it needs an equation of state, which is not read).
module deck_material_curves
  use kinds, only: wp
  use model, only: model_t, material_t, law_honeycomb, law_modified_honeycomb, law_low_density_foam, &
                   law_piecewise_linear, law_null, law_rigid, section_shell, piecewise_hardening_curve
  use deck_problems, only: problem_log_t
  use text_format, only: integer_text, real_text
  use deck_lexer, only: deck_t
  use deck_fields, only: located_problem
  use deck_id_index, only: id_index_t, build_id_index, find_id
  use plane_stress_dispatch, only: plane_stress_history_count, plane_stress_unsupported
  implicit none
  private

  public :: resolve_material_curves, apply_material_bulk_viscosity

  character(len=4), parameter :: honeycomb_fields(7) = ["LCA ", "LCB ", "LCC ", "LCAB", "LCBC", "LCCA", "LCSR"]
  character(len=4), parameter :: piecewise_fields(2) = ["LCSS", "LCSR"]

contains

  !> Copy each referenced curve into its material, reporting undefined ids at the card holding
  !> them (`material_lines`: card 1 of each material; the honeycomb and *MAT_024 curves are on
  !> card 2, the next line), and check the parts of these laws against their sections.
  subroutine resolve_material_curves(deck, model, material_lines, part_lines, log)
    type(deck_t), intent(in) :: deck
    type(model_t), intent(inout) :: model
    integer, intent(in) :: material_lines(:), part_lines(:)
    type(problem_log_t), intent(inout) :: log
    type(id_index_t) :: curve_index
    integer :: m, k, curve, line
    character(len=:), allocatable :: field, missing

    if (.not. allocated(model%curves)) allocate (model%curves(0))
    call build_id_index([(model%curves(k)%id, k=1, size(model%curves))], curve_index)
    do m = 1, size(model%materials)
      associate (material => model%materials(m))
        if (.not. (crushable(material) .or. material%law == law_piecewise_linear)) cycle
        ! *MAT_024 arrives with its slots allocated (and the EPS / ES table in slot 1).
        if (.not. allocated(material%curves)) allocate (material%curves(size(material%curve_ids)))
        do k = 1, size(material%curve_ids)
          if (material%curve_ids(k) <= 0) cycle      ! none given, or reported by the reader
          curve = find_id(curve_index, material%curve_ids(k))
          if (curve > 0) then
            material%curves(k) = model%curves(curve)
            if (material%law == law_piecewise_linear) &
              call check_positive_curve(deck, material, k, material_lines(m) + 1, log)
            cycle
          end if
          if (any(material%curve_ids(1:k - 1) == material%curve_ids(k))) cycle   ! reported once
          missing = " (no *DEFINE_CURVE with this LCID)"
          if (material%law == law_low_density_foam) then
            field = "LCID"
            line = material_lines(m)
          else if (material%law == law_piecewise_linear) then
            field = trim(piecewise_fields(k))
            line = material_lines(m) + 1
            if (k == piecewise_hardening_curve) missing = " (no *DEFINE_CURVE with this LCID; a table of "// &
              "curves per strain rate, *DEFINE_TABLE, is not available for LCSS)"
          else
            field = trim(honeycomb_fields(k))
            line = material_lines(m) + 1
          end if
          call located_problem(deck, log, line, field, "curve "//integer_text(material%curve_ids(k))// &
            " of material "//integer_text(material%id)//" is not defined"//missing)
        end do
      end associate
    end do
    call check_part_laws(deck, model, material_lines, part_lines, log)
  end subroutine resolve_material_curves

  !> The LCSS yield curve and the LCSR scale factors of *MAT_024 must stay positive.
  subroutine check_positive_curve(deck, material, slot, line, log)
    type(deck_t), intent(in) :: deck
    type(material_t), intent(in) :: material
    integer, intent(in) :: slot, line
    type(problem_log_t), intent(inout) :: log
    integer :: point
    associate (curve => material%curves(slot))
      if (size(curve%ordinate) == 0) return
      point = minloc(curve%ordinate, dim=1)
      if (curve%ordinate(point) > 0.0_wp) return
      call located_problem(deck, log, line, trim(piecewise_fields(slot)), "curve "//integer_text(curve%id)// &
        " of material "//integer_text(material%id)//" must stay > 0 (a "// &
        trim(merge("yield stress", "scale factor", slot == piecewise_hardening_curve))//"), found "// &
        real_text(curve%ordinate(point))//" at "//real_text(curve%abscissa(point)))
    end associate
  end subroutine check_positive_curve

  !> Parts against their sections: the crushable laws need a hexahedron section (ELFORM 1 or
  !> 2), *MAT_NULL a shell section (with YM > 0: the shells' time step and contact stiffness),
  !> and a shell section a law with a plane-stress kernel (or *MAT_RIGID).
  subroutine check_part_laws(deck, model, material_lines, part_lines, log)
    type(deck_t), intent(in) :: deck
    type(model_t), intent(in) :: model
    integer, intent(in) :: material_lines(:), part_lines(:)
    type(problem_log_t), intent(inout) :: log
    integer :: part, formulation
    character(len=:), allocatable :: part_name

    do part = 1, size(model%parts)
      if (model%parts(part)%material <= 0 .or. model%parts(part)%section <= 0) cycle
      part_name = "part "//integer_text(model%parts(part)%id)//": material "// &
                  integer_text(model%parts(part)%material_id)
      associate (material => model%materials(model%parts(part)%material), &
                 section => model%sections(model%parts(part)%section))
        formulation = section%element_formulation
        if (section%kind == section_shell) then
          if (material%law == law_rigid) cycle
          if (plane_stress_history_count(material) == plane_stress_unsupported) then
            call located_problem(deck, log, part_lines(part), "MID", part_name//" has no shell (plane-stress) "// &
              "formulation; shell sections take *MAT_ELASTIC, *MAT_PLASTIC_KINEMATIC, "// &
              "*MAT_PIECEWISE_LINEAR_PLASTICITY, *MAT_NULL or *MAT_RIGID (section "// &
              integer_text(model%parts(part)%section_id)//" is a shell section)")
          else if (material%law == law_null .and. .not. material%youngs_modulus > 0.0_wp) then
            call located_problem(deck, log, material_lines(model%parts(part)%material), "YM", "material "// &
              integer_text(material%id)//" (*MAT_NULL) on the shells of part "// &
              integer_text(model%parts(part)%id)//" needs YM > 0 (it sets their time step and contact "// &
              "stiffness), found "//real_text(material%youngs_modulus))
          end if
        else if (crushable(material)) then
          ! meshfree (ELFORM 41) points take the material axes of their background hexahedron
          if (formulation /= 1 .and. formulation /= 2 .and. formulation /= 41) &
            call located_problem(deck, log, part_lines(part), "SECID", &
            part_name//" (honeycomb or low-density foam) needs a hexahedron section, ELFORM 1, 2 or 41; "// &
            "section "//integer_text(model%parts(part)%section_id)//" has ELFORM "//integer_text(formulation))
        else if (material%law == law_null) then
          call located_problem(deck, log, part_lines(part), "MID", part_name//" (*MAT_NULL) needs an equation "// &
            "of state on solid elements (*EOS is not read); crashfree takes *MAT_NULL on shell parts only")
        end if
      end associate
    end do
  end subroutine check_part_laws

  !> Parts of the crushable laws with BULK / BVFLAG = 0 (LS-DYNA's default) get no element bulk
  !> viscosity (run after the effective hourglass and bulk-viscosity values are set).
  subroutine apply_material_bulk_viscosity(model)
    type(model_t), intent(inout) :: model
    integer :: part
    do part = 1, size(model%parts)
      if (model%parts(part)%material <= 0) cycle
      associate (material => model%materials(model%parts(part)%material))
        if (crushable(material) .and. .not. material%bulk_viscosity) then
          model%parts(part)%bulk_quadratic = 0.0_wp
          model%parts(part)%bulk_linear = 0.0_wp
        end if
      end associate
    end do
  end subroutine apply_material_bulk_viscosity

  pure logical function crushable(material)
    type(material_t), intent(in) :: material
    crushable = material%law == law_honeycomb .or. material%law == law_modified_honeycomb .or. &
                material%law == law_low_density_foam
  end function crushable
end module deck_material_curves
