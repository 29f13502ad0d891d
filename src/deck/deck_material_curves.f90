!> Cross-check of the materials against the laws' rows in law_table (material_laws):
!> - the laws with curve slots (*MAT_HONEYCOMB, *MAT_MODIFIED_HONEYCOMB, *MAT_LOW_DENSITY_FOAM,
!>   *MAT_PIECEWISE_LINEAR_PLASTICITY): their curve ids resolved to copies of the curves kept in
!>   the material (so that the law kernels get them through the material dispatch);
!> - *MAT_MOONEY-RIVLIN_RUBBER with LCID1: A and B fitted to the test curve;
!> - each part's section against the element families its law takes: shells, solids, meshfree
!>   (*MAT_NULL: shells only), and the hexahedron formulations ELFORM 1, 2 and 41 for the laws
!>   that need them (the crushable honeycombs and foam).
module deck_material_curves
  use kinds, only: wp
  use model, only: model_t, material_t, section_shell, section_beam, piecewise_hardening_curve
  use material_laws, only: law_table, find_law, law_keyword_name, law_curve_field, law_piecewise_linear, &
                           law_null, law_mooney_rivlin
  use material_rubber, only: mooney_rivlin_fit
  use deck_materials, only: mooney_rivlin_check
  use deck_problems, only: problem_log_t
  use text_format, only: integer_text, real_text
  use deck_lexer, only: deck_t
  use deck_fields, only: located_problem
  use deck_id_index, only: id_index_t, build_id_index, find_id
  use deck_efg_cards, only: elform_efg
  implicit none
  private

  public :: resolve_material_curves, apply_material_bulk_viscosity

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
    integer :: m, k, curve, line, law
    character(len=:), allocatable :: missing

    if (.not. allocated(model%curves)) allocate (model%curves(0))
    call build_id_index([(model%curves(k)%id, k=1, size(model%curves))], curve_index)
    do m = 1, size(model%materials)
      law = find_law(model%materials(m)%law)
      if (law == 0) cycle
      if (len_trim(law_table(law)%curve_fields) == 0) cycle
      associate (material => model%materials(m))
        line = material_lines(m) + law_table(law)%curve_card - 1
        ! *MAT_024 arrives with its slots allocated (and the EPS / ES table in slot 1).
        if (.not. allocated(material%curves)) allocate (material%curves(size(material%curve_ids)))
        do k = 1, size(material%curve_ids)
          if (material%curve_ids(k) <= 0) cycle      ! none given, or reported by the reader
          curve = find_id(curve_index, material%curve_ids(k))
          if (curve > 0) then
            material%curves(k) = model%curves(curve)
            if (material%law == law_piecewise_linear) call check_positive_curve(deck, material, law, k, line, log)
            cycle
          end if
          if (any(material%curve_ids(1:k - 1) == material%curve_ids(k))) cycle   ! reported once
          missing = " (no *DEFINE_CURVE with this LCID)"
          if (material%law == law_piecewise_linear .and. k == piecewise_hardening_curve) missing = &
            " (no *DEFINE_CURVE with this LCID; a table of curves per strain rate, *DEFINE_TABLE, is not "// &
            "available for LCSS)"
          call located_problem(deck, log, line, law_curve_field(law, k), "curve "// &
            integer_text(material%curve_ids(k))//" of material "//integer_text(material%id)// &
            " is not defined"//missing)
        end do
        if (material%law == law_mooney_rivlin .and. material%curve_ids(1) > 0) then
          if (allocated(material%curves(1)%abscissa)) call fit_mooney_rivlin(deck, material, line, log)
        end if
      end associate
    end do
    call check_part_laws(deck, model, material_lines, part_lines, log)
  end subroutine resolve_material_curves

  !> *MAT_MOONEY-RIVLIN_RUBBER with LCID1: A and B by least squares on its uniaxial test curve
  !> (force against change of gauge length; stretch 1 + dL / SGL, nominal stress F / (SW ST));
  !> material_rubber's mooney_rivlin_fit), then the checks of the reader on them.
  subroutine fit_mooney_rivlin(deck, material, line, log)
    type(deck_t), intent(in) :: deck
    type(material_t), intent(inout) :: material
    integer, intent(in) :: line
    type(problem_log_t), intent(inout) :: log
    logical :: fitted
    character(len=:), allocatable :: field, problem
    associate (curve => material%curves(1), dimensions => material%specimen_dimensions)
      if (.not. all(dimensions > 0.0_wp)) return         ! reported by the reader
      call mooney_rivlin_fit(1.0_wp + curve%abscissa/dimensions(1), curve%ordinate/(dimensions(2)*dimensions(3)), &
                             material%mooney_rivlin_a, material%mooney_rivlin_b, fitted)
      if (.not. fitted) then
        call located_problem(deck, log, line, "LCID1", "curve "//integer_text(curve%id)//" of material "// &
          integer_text(material%id)//" needs points at two or more different changes of gauge length "// &
          "(besides 0) to fit A and B")
        return
      end if
      call mooney_rivlin_check(material, field, problem)
      if (len(problem) > 0) call located_problem(deck, log, line, "LCID1", "A and B fitted to curve "// &
        integer_text(curve%id)//" of material "//integer_text(material%id)//": "//problem)
    end associate
  end subroutine fit_mooney_rivlin

  !> The LCSS yield curve and the LCSR scale factors of *MAT_024 must stay positive.
  subroutine check_positive_curve(deck, material, law, slot, line, log)
    type(deck_t), intent(in) :: deck
    type(material_t), intent(in) :: material
    integer, intent(in) :: law, slot, line
    type(problem_log_t), intent(inout) :: log
    integer :: point
    associate (curve => material%curves(slot))
      if (size(curve%ordinate) == 0) return
      point = minloc(curve%ordinate, dim=1)
      if (curve%ordinate(point) > 0.0_wp) return
      call located_problem(deck, log, line, law_curve_field(law, slot), "curve "//integer_text(curve%id)// &
        " of material "//integer_text(material%id)//" must stay > 0 (a "// &
        trim(merge("yield stress", "scale factor", slot == piecewise_hardening_curve))//"), found "// &
        real_text(curve%ordinate(point))//" at "//real_text(curve%abscissa(point)))
    end associate
  end subroutine check_positive_curve

  !> Parts against their sections, by the law's row in law_table: a shell section needs a law
  !> that takes shells (with YM > 0 for *MAT_NULL: the shells' time step and contact
  !> stiffness), a solid section one that takes solids (meshfree for ELFORM 41), and the laws
  !> that need hexahedra ELFORM 1, 2 or 41.
  subroutine check_part_laws(deck, model, material_lines, part_lines, log)
    type(deck_t), intent(in) :: deck
    type(model_t), intent(in) :: model
    integer, intent(in) :: material_lines(:), part_lines(:)
    type(problem_log_t), intent(inout) :: log
    integer :: part, formulation, law
    logical :: family_taken
    character(len=:), allocatable :: part_name

    do part = 1, size(model%parts)
      if (model%parts(part)%material <= 0 .or. model%parts(part)%section <= 0) cycle
      part_name = "part "//integer_text(model%parts(part)%id)//": material "// &
                  integer_text(model%parts(part)%material_id)
      associate (material => model%materials(model%parts(part)%material), &
                 section => model%sections(model%parts(part)%section))
        law = find_law(material%law)
        if (law == 0) cycle
        formulation = section%element_formulation
        if (section%kind == section_beam) then
          if (.not. law_table(law)%beams) call located_problem(deck, log, part_lines(part), "MID", part_name// &
            " (*"//law_keyword_name(law)//") is not available on beams; beam sections take *MAT_ELASTIC, "// &
            "*MAT_PLASTIC_KINEMATIC or *MAT_SPOTWELD")
          cycle
        end if
        if (section%kind == section_shell) then
          if (.not. law_table(law)%shells) then
            call located_problem(deck, log, part_lines(part), "MID", part_name//" has no shell (plane-stress) "// &
              "formulation; shell sections take "//shell_laws()//" (section "// &
              integer_text(model%parts(part)%section_id)//" is a shell section)")
          else if (material%law == law_null .and. .not. material%youngs_modulus > 0.0_wp) then
            call located_problem(deck, log, material_lines(model%parts(part)%material), "YM", "material "// &
              integer_text(material%id)//" (*MAT_NULL) on the shells of part "// &
              integer_text(model%parts(part)%id)//" needs YM > 0 (it sets their time step and contact "// &
              "stiffness), found "//real_text(material%youngs_modulus))
          end if
          cycle
        end if
        if (formulation == elform_efg) then
          family_taken = law_table(law)%meshfree
        else
          family_taken = law_table(law)%solids
        end if
        if (.not. family_taken) then
          if (material%law == law_null) then
            call located_problem(deck, log, part_lines(part), "MID", part_name//" (*MAT_NULL) needs an "// &
              "equation of state on solid elements (*EOS is not read); crashfree takes *MAT_NULL on shell "// &
              "parts only")
          else
            call located_problem(deck, log, part_lines(part), "MID", part_name//" (*"//law_keyword_name(law)// &
              ") is not available on "//trim(merge("meshfree (ELFORM 41)", "solid               ", &
              formulation == elform_efg))//" parts")
          end if
        else if (law_table(law)%hexahedra_only) then
          ! meshfree (ELFORM 41) points take the material axes of their background hexahedron
          if (formulation /= 1 .and. formulation /= 2 .and. formulation /= elform_efg) &
            call located_problem(deck, log, part_lines(part), "SECID", &
            part_name//" (honeycomb or low-density foam) needs a hexahedron section, ELFORM 1, 2 or 41; "// &
            "section "//integer_text(model%parts(part)%section_id)//" has ELFORM "//integer_text(formulation))
        end if
      end associate
    end do
  end subroutine check_part_laws

  !> "*MAT_ELASTIC, ... or *MAT_RIGID": the laws that take shells, in law_table's order.
  function shell_laws() result(text)
    character(len=:), allocatable :: text
    integer :: k, listed, total
    total = count(law_table%shells)
    text = ""
    listed = 0
    do k = 1, size(law_table)
      if (.not. law_table(k)%shells) cycle
      listed = listed + 1
      if (listed == total .and. listed > 1) then
        text = text//" or "
      else if (listed > 1) then
        text = text//", "
      end if
      text = text//"*"//law_keyword_name(k)
    end do
  end function shell_laws

  !> Parts whose law switches the element bulk viscosity off (BULK / BVFLAG = 0 of the
  !> honeycombs and the foam, LS-DYNA's default; every other law keeps bulk_viscosity true) get
  !> none (run after the effective hourglass and bulk-viscosity values are set).
  subroutine apply_material_bulk_viscosity(model)
    type(model_t), intent(inout) :: model
    integer :: part
    do part = 1, size(model%parts)
      if (model%parts(part)%material <= 0) cycle
      if (model%materials(model%parts(part)%material)%bulk_viscosity) cycle
      model%parts(part)%bulk_quadratic = 0.0_wp
      model%parts(part)%bulk_linear = 0.0_wp
    end do
  end subroutine apply_material_bulk_viscosity
end module deck_material_curves
