!> Cross-check of the crushable materials (*MAT_HONEYCOMB, *MAT_MODIFIED_HONEYCOMB,
!> *MAT_LOW_DENSITY_FOAM): their curve ids resolved to copies of the curves kept in the
!> material (so that the law kernels get them through the material dispatch), and the parts
!> using them restricted to the hexahedron formulations ELFORM 1 and 2.
module deck_material_curves
  use kinds, only: wp
  use model, only: model_t, material_t, law_honeycomb, law_modified_honeycomb, law_low_density_foam
  use curves, only: curve_t
  use deck_problems, only: problem_log_t
  use deck_numbers, only: integer_text
  use deck_lexer, only: deck_t
  use deck_fields, only: located_problem
  use deck_id_index, only: id_index_t, build_id_index, find_id
  implicit none
  private

  public :: resolve_material_curves, apply_material_bulk_viscosity

  character(len=4), parameter :: honeycomb_fields(7) = ["LCA ", "LCB ", "LCC ", "LCAB", "LCBC", "LCCA", "LCSR"]

contains

  !> Copy each referenced curve into its material, reporting undefined ids at the card holding
  !> them (`material_lines`: card 1 of each material; the honeycomb curves are on card 2, the
  !> next line), and reject parts of these laws whose section is not ELFORM 1 or 2.
  subroutine resolve_material_curves(deck, model, material_lines, part_lines, log)
    type(deck_t), intent(in) :: deck
    type(model_t), intent(inout) :: model
    integer, intent(in) :: material_lines(:), part_lines(:)
    type(problem_log_t), intent(inout) :: log
    type(id_index_t) :: curve_index
    integer :: m, k, curve, line, part, formulation
    character(len=:), allocatable :: field

    if (.not. allocated(model%curves)) allocate (model%curves(0))
    call build_id_index([(model%curves(k)%id, k=1, size(model%curves))], curve_index)
    do m = 1, size(model%materials)
      associate (material => model%materials(m))
        if (.not. crushable(material)) cycle
        allocate (material%curves(size(material%curve_ids)))
        do k = 1, size(material%curve_ids)
          if (material%curve_ids(k) <= 0) cycle      ! none given, or reported by the reader
          curve = find_id(curve_index, material%curve_ids(k))
          if (curve > 0) then
            material%curves(k) = model%curves(curve)
            cycle
          end if
          if (any(material%curve_ids(1:k - 1) == material%curve_ids(k))) cycle   ! reported once
          if (material%law == law_low_density_foam) then
            field = "LCID"
            line = material_lines(m)
          else
            field = trim(honeycomb_fields(k))
            line = material_lines(m) + 1
          end if
          call located_problem(deck, log, line, field, "curve "//integer_text(material%curve_ids(k))// &
            " of material "//integer_text(material%id)//" is not defined (no *DEFINE_CURVE with this LCID)")
        end do
      end associate
    end do

    do part = 1, size(model%parts)
      if (model%parts(part)%material <= 0 .or. model%parts(part)%section <= 0) cycle
      if (.not. crushable(model%materials(model%parts(part)%material))) cycle
      formulation = model%sections(model%parts(part)%section)%element_formulation
      if (formulation /= 1 .and. formulation /= 2) call located_problem(deck, log, part_lines(part), "SECID", &
        "part "//integer_text(model%parts(part)%id)//": material "// &
        integer_text(model%parts(part)%material_id)//" (honeycomb or low-density foam) needs a hexahedron "// &
        "section, ELFORM 1 or 2; section "//integer_text(model%parts(part)%section_id)//" has ELFORM "// &
        integer_text(formulation))
    end do
  end subroutine resolve_material_curves

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
