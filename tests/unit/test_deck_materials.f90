!> Unit tests of the deck reader for *MAT_PIECEWISE_LINEAR_PLASTICITY (*MAT_024) and *MAT_NULL
!> (*MAT_009): values read with LS-DYNA's precedence (LCSS over EPS/ES over SIGY/ETAN, LCSR
!> over C/P), the EPS/ES table turned into a curve, curves copied by the cross-check, the
!> warnings of fields read but not used, and the exact `file:line: *KEYWORD: field NAME` of
!> every rejected value.
!>
!> Decks are one-hexahedron cubes in free format written under /tmp; the line numbers in the
!> expected messages are those of `cube_deck` (materials and curves start at line 20).
program test_deck_materials
  use kinds, only: wp
  use testing, only: test_suite_t, check, check_close, finish_suite
  use fixtures, only: make_scratch_directory
  use error_handling, only: error_t, error_list_t
  use model, only: model_t, piecewise_hardening_curve, piecewise_rate_curve
  use material_laws, only: law_piecewise_linear, law_null
  use deck_reader, only: read_deck
  implicit none

  integer, parameter :: line_length = 120
  type(test_suite_t) :: suite
  character(len=:), allocatable :: directory

  suite%name = "deck materials"
  directory = make_scratch_directory("crashfree_test_deck_materials")
  call test_values()
  call test_reader_errors()
  call test_cross_check_errors()
  call test_missing_card()
  call test_shell_parts()
  call execute_command_line("rm -rf "//directory)
  call finish_suite(suite)

contains

  !> Lines 1-19: a unit cube of one hexahedron whose part uses material `material_id`; then
  !> `extra` from line 20, then *END.
  function cube_deck(material_id, extra) result(lines)
    character(len=*), intent(in) :: material_id
    character(len=*), intent(in) :: extra(:)
    character(len=line_length), allocatable :: lines(:)
    character(len=line_length) :: base(19)
    base = [character(len=line_length) :: "*KEYWORD", "*CONTROL_TERMINATION", "1.0", "*NODE", &
      "1,0.0,0.0,0.0", "2,1.0,0.0,0.0", "3,1.0,1.0,0.0", "4,0.0,1.0,0.0", &
      "5,0.0,0.0,1.0", "6,1.0,0.0,1.0", "7,1.0,1.0,1.0", "8,0.0,1.0,1.0", &
      "*ELEMENT_SOLID", "1,1,1,2,3,4,5,6,7,8", "*PART", "cube", "1,1,"//material_id, "*SECTION_SOLID", "1,1"]
    lines = [base, extra, [character(len=line_length) :: "*END"]]
  end function cube_deck

  !> Write `lines` as deck `name` and read it.
  subroutine read_lines(name, lines, model, warnings, error)
    character(len=*), intent(in) :: name
    character(len=*), intent(in) :: lines(:)
    type(model_t), intent(out) :: model
    type(error_list_t), intent(out) :: warnings
    type(error_t), allocatable, intent(out) :: error
    integer :: unit, k
    open (newunit=unit, file=directory//"/"//name, status="replace", action="write")
    do k = 1, size(lines)
      write (unit, '(a)') trim(lines(k))
    end do
    close (unit)
    call read_deck(directory//"/"//name, model, warnings, error, .false.)
  end subroutine read_lines

  !> `text` holds every `expected` line (`@` stands for the deck's path); `count` lines in all.
  subroutine check_messages(name, text, expected, count)
    character(len=*), intent(in) :: name, text
    character(len=*), intent(in) :: expected(:)
    integer, intent(in), optional :: count
    character(len=:), allocatable :: wanted
    integer :: k, at, lines
    do k = 1, size(expected)
      wanted = trim(expected(k))
      at = index(wanted, "@")
      if (at > 0) wanted = wanted(:at - 1)//directory//"/"//name//wanted(at + 1:)
      call check(suite, name//": "//wanted, index(text, wanted) > 0, "messages were:"//new_line("a")//text)
    end do
    if (present(count)) then
      lines = 1
      do k = 1, len(text)
        if (text(k:k) == new_line("a")) lines = lines + 1
      end do
      call check(suite, name//": number of messages", lines == count, "messages were:"//new_line("a")//text)
    end if
  end subroutine check_messages

  !> *MAT_024 with LCSS and LCSR (_TITLE, the cube's material), with the EPS / ES table, and
  !> bilinear without cards 3-4; *MAT_NULL (_TITLE) and *MAT_009.
  subroutine test_values()
    type(model_t) :: model
    type(error_list_t) :: warnings
    type(error_t), allocatable :: error
    call read_lines("good.k", cube_deck("24", [character(len=line_length) :: &
      "*MAT_PIECEWISE_LINEAR_PLASTICITY_TITLE", "steel with curves", &   ! 20, 21
      "24,7.85e-9,210000.0,0.3,250.0,1000.0,0.0,1.0e-9", &              ! 22
      "40.0,5.0,7,8,1.0", &                                              ! 23
      "*MAT_024", "25,7.85e-9,210000.0,0.3,100.0,,0.5", "0.0,0.0,0,0,0.0", & ! 24-26
      "0.0,0.02,0.05,0.1", "250.0,300.0,340.0,400.0", &                  ! 27, 28
      "*MAT_024", "26,7.85e-9,210000.0,0.3,250.0,2100.0", "0.0", &       ! 29-31
      "*MAT_NULL_TITLE", "null shell", "9,1.0e-9,,,,,70000.0,0.3", &      ! 32-34
      "*MAT_009", "10,1.0e-9,-1.0,0.1", &                                ! 35, 36
      "*DEFINE_CURVE", "7", "0.0,250.0", "0.02,300.0", "0.05,340.0", "0.1,400.0", & ! 37-42
      "*DEFINE_CURVE", "8", "0.0,1.0", "1000.0,1.5"]), model, warnings, error)
    if (allocated(error)) then
      call check(suite, "good.k is accepted", .false., error%message)
      return
    end if
    call check(suite, "good.k: five materials", size(model%materials) == 5)
    if (size(model%materials) /= 5) return
    associate (m => model%materials(1))
      call check(suite, "024 LCSS: law, title, part", m%law == law_piecewise_linear .and. m%title == &
                 "steel with curves" .and. model%parts(1)%material == 1)
      call check(suite, "024 LCSS: curve ids LCSS, LCSR", all(m%curve_ids == [7, 8]))
      call check(suite, "024 LCSS: curves copied", m%curves(piecewise_hardening_curve)%id == 7 .and. &
                 size(m%curves(piecewise_hardening_curve)%abscissa) == 4 .and. m%curves(piecewise_rate_curve)%id == 8)
      call check_close(suite, "024 LCSS: RO E PR SIGY ETAN FAIL(0 -> 1e21) TDEL C P VP", [m%density, &
        m%youngs_modulus, m%poissons_ratio, m%yield_stress, m%tangent_modulus, m%failure_strain, &
        m%failure_time_step, m%rate_c, m%rate_p, m%rate_formulation], [7.85e-9_wp, 210000.0_wp, 0.3_wp, 250.0_wp, &
        1000.0_wp, 1.0e21_wp, 1.0e-9_wp, 40.0_wp, 5.0_wp, 1.0_wp], rel=1e-15_wp)
    end associate
    associate (m => model%materials(2))
      call check(suite, "024 table: no curve ids", all(m%curve_ids == [0, 0]))
      call check(suite, "024 table: a curve of 4 points in the hardening slot, none for rates", &
                 size(m%curves(piecewise_hardening_curve)%abscissa) == 4 .and. &
                 .not. allocated(m%curves(piecewise_rate_curve)%abscissa))
      if (allocated(m%curves(piecewise_hardening_curve)%abscissa)) then
        call check_close(suite, "024 table: EPS1-4", m%curves(piecewise_hardening_curve)%abscissa, &
                         [0.0_wp, 0.02_wp, 0.05_wp, 0.1_wp], rel=1e-15_wp)
        call check_close(suite, "024 table: ES1-4", m%curves(piecewise_hardening_curve)%ordinate, &
                         [250.0_wp, 300.0_wp, 340.0_wp, 400.0_wp], rel=1e-15_wp)
      end if
      call check_close(suite, "024 table: FAIL", m%failure_strain, 0.5_wp, rel=1e-15_wp)
    end associate
    associate (m => model%materials(3))
      call check(suite, "024 bilinear: two empty curve slots", size(m%curves) == 2 .and. &
                 .not. allocated(m%curves(1)%abscissa) .and. .not. allocated(m%curves(2)%abscissa))
      call check_close(suite, "024 bilinear: SIGY ETAN", [m%yield_stress, m%tangent_modulus], [250.0_wp, 2100.0_wp], &
                       rel=1e-15_wp)
    end associate
    associate (m => model%materials(4))
      call check(suite, "009: law, title", m%law == law_null .and. m%title == "null shell")
      call check_close(suite, "009: RO YM PR", [m%density, m%youngs_modulus, m%poissons_ratio], &
                       [1.0e-9_wp, 70000.0_wp, 0.3_wp], rel=1e-15_wp)
    end associate
    associate (m => model%materials(5))
      call check_close(suite, "009: PC MU", [m%pressure_cutoff, m%viscosity], [-1.0_wp, 0.1_wp], rel=1e-15_wp)
    end associate
    if (warnings%count == 0) then
      call check(suite, "good.k: warnings", .false., "no warnings")
      return
    end if
    ! (FAIL and TDEL erode elements: no warning)
    call check_messages("good.k", warnings%text, [character(len=line_length) :: &
      "@:23: *MAT_PIECEWISE_LINEAR_PLASTICITY_TITLE: field C: ignored (LCSR overrides C and P)", &
      "@:23: *MAT_PIECEWISE_LINEAR_PLASTICITY_TITLE: field P: ignored (LCSR overrides C and P)", &
      "@:36: *MAT_009: field PC: ignored (no equation of state", &
      "@:36: *MAT_009: field MU: ignored (no equation of state"], count=4)
  end subroutine test_values

  !> Values the readers reject, each at its card and field.
  subroutine test_reader_errors()
    type(model_t) :: model
    type(error_list_t) :: warnings
    type(error_t), allocatable :: error
    call read_lines("bad.k", cube_deck("31", [character(len=line_length) :: &
      "*MAT_024", "30,0.0,-5.0,0.5,0.0,,-1.0", "40.0,0.0,-1,-2,2.0", &       ! 20-22
      "*MAT_024", "31,7.8e-9,210000.0,0.3", "0.0,0.0,0,0,-1.0", &           ! 23-25
      "0.0,0.02,0.02,0.1", "250.0,300.0,0.0,400.0", &                        ! 26, 27
      "*MAT_024", "32,7.8e-9,210000.0,0.3,250.0,210000.0", "0.0", &         ! 28-30
      "*MAT_024", "33,7.8e-9,210000.0,-1.0,250.0", "0.0", "0.0,0.1", "0.0,300.0", & ! 31-35
      "*MAT_NULL", "34,0.0,1.0,-0.1,,,-1.0,0.5"]), model, warnings, error)    ! 36, 37
    if (.not. allocated(error)) then
      call check(suite, "bad.k is rejected", .false., "the deck was accepted")
      return
    end if
    call check_messages("bad.k", error%message, [character(len=200) :: &
      "@:21: *MAT_024: field RO: density must be > 0, found 0.0", &
      "@:21: *MAT_024: field E: Young's modulus must be > 0, found -5.0", &
      "@:21: *MAT_024: field PR: Poisson's ratio must lie in (-1, 0.5), found 0.5", &
      "@:21: *MAT_024: field FAIL: FAIL < 0 (a user failure subroutine) is not available", &
      "@:21: *MAT_024: field SIGY: yield stress must be > 0 when neither LCSS nor the EPS1-8 / ES1-8 table is given", &
      "@:22: *MAT_024: field P: Cowper-Symonds rate effects need both C and P > 0 (or both 0 for none)", &
      "@:22: *MAT_024: field LCSS: curve id must be >= 0", &
      "@:22: *MAT_024: field LCSR: curve id must be >= 0", &
      "@:22: *MAT_024: field VP: must be 0 (scale the yield stress) or 1 (viscoplastic), found 2.0", &
      "@:25: *MAT_024: field VP: must be 0 (scale the yield stress) or 1 (viscoplastic), found -1.0; VP = -1 "// &
      "(deviatoric rate), 3 and 4 (filtered rates) are not available", &
      "@:26: *MAT_024: field EPS3: effective plastic strains must increase: EPS3 = 0.02 is not above EPS2 = 0.02", &
      "@:27: *MAT_024: field ES3: yield stress must be > 0, found 0.0", &
      "@:29: *MAT_024: field ETAN: tangent modulus must be smaller than E = 210000.0", &
      "@:32: *MAT_024: field PR: Poisson's ratio must lie in (-1, 0.5), found -1.0", &
      "@:35: *MAT_024: field ES1: the EPS / ES table needs ES1 > 0", &
      "@:37: *MAT_NULL: field RO: density must be > 0, found 0.0", &
      "@:37: *MAT_NULL: field PC: pressure cut-off must be <= 0, found 1.0", &
      "@:37: *MAT_NULL: field MU: viscosity coefficient must be >= 0, found -0.1", &
      "@:37: *MAT_NULL: field YM: Young's modulus must be >= 0, found -1.0", &
      "@:37: *MAT_NULL: field PR: Poisson's ratio must lie in (-1, 0.5), found 0.5"], count=20)
  end subroutine test_reader_errors

  !> Problems found once the whole deck is read: undefined LCSS (a table id) and LCSR, curves
  !> that do not stay positive, *MAT_NULL on a solid part.
  subroutine test_cross_check_errors()
    type(model_t) :: model
    type(error_list_t) :: warnings
    type(error_t), allocatable :: error
    call read_lines("cross.k", cube_deck("34", [character(len=line_length) :: &
      "*MAT_024", "33,7.8e-9,210000.0,0.3,250.0", "0.0,0.0,99,98", &          ! 20-22
      "*MAT_NULL", "34,1.0e-9,,,,,70000.0,0.3", &                            ! 23, 24
      "*MAT_024", "35,7.8e-9,210000.0,0.3,250.0", "0.0,0.0,7,8", &            ! 25-27
      "*DEFINE_CURVE", "7", "0.0,0.0", "0.1,300.0", &                         ! 28-31
      "*DEFINE_CURVE", "8", "0.0,1.0", "100.0,0.0"]), model, warnings, error) ! 32-35
    if (.not. allocated(error)) then
      call check(suite, "cross.k is rejected", .false., "the deck was accepted")
      return
    end if
    call check_messages("cross.k", error%message, [character(len=200) :: &
      "@:22: *MAT_024: field LCSS: curve 99 of material 33 is not defined (no *DEFINE_CURVE with this LCID; "// &
      "a table of curves per strain rate, *DEFINE_TABLE, is not available for LCSS)", &
      "@:22: *MAT_024: field LCSR: curve 98 of material 33 is not defined (no *DEFINE_CURVE with this LCID)", &
      "@:27: *MAT_024: field LCSS: curve 7 of material 35 must stay > 0 (a yield stress), found 0.0 at 0.0", &
      "@:27: *MAT_024: field LCSR: curve 8 of material 35 must stay > 0 (a scale factor), found 0.0 at 100.0", &
      "@:17: *PART: field MID: part 1: material 34 (*MAT_NULL) needs an equation of state on solid elements"], &
      count=5)
  end subroutine test_cross_check_errors

  subroutine test_missing_card()
    type(model_t) :: model
    type(error_list_t) :: warnings
    type(error_t), allocatable :: error
    call read_lines("missing.k", cube_deck("24", [character(len=line_length) :: &
      "*MAT_024", "24,7.8e-9,210000.0,0.3,250.0", "*MAT_024", "25,7.8e-9,210000.0,0.3", "0.0", "0.1,0.2", &
      "*MAT_NULL"]), model, warnings, error)
    if (.not. allocated(error)) then
      call check(suite, "missing.k is rejected", .false., "the deck was accepted")
      return
    end if
    call check_messages("missing.k", error%message, [character(len=160) :: &
      "@:21: *MAT_024: field C: card 2 (C P LCSS LCSR VP) is missing: the keyword ends after this line", &
      "@:25: *MAT_024: field ES1: card 4 (ES1 ... ES8) is missing: the keyword ends after this line", &
      "@:26: *MAT_NULL: field MID: card 1 (MID RO PC MU TEROD CEROD YM PR) is missing: the keyword has no cards"], &
      count=3)
  end subroutine test_missing_card

  !> Shell parts: *MAT_024 is accepted, *MAT_NULL needs YM > 0 (the shells' time step), a law
  !> without a plane-stress kernel (the foam) is an error at the *PART card.
  subroutine test_shell_parts()
    type(model_t) :: model
    type(error_list_t) :: warnings
    type(error_t), allocatable :: error
    character(len=line_length), parameter :: shells(*) = [character(len=line_length) :: &
      "*ELEMENT_SHELL", "2,2,1,2,3,4", "3,3,5,6,7,8", "4,4,1,2,6,5", &                     ! 20-23
      "*PART", "null shells", "2,2,40", "*PART", "foam shells", "3,2,41", &                ! 24-29
      "*PART", "steel shells", "4,2,24", "*SECTION_SHELL", "2,2", "1.0", &                  ! 30-35
      "*MAT_024", "24,7.8e-9,210000.0,0.3,250.0", "0.0", "*MAT_NULL", "40,1.0e-9", &         ! 36-40
      "*MAT_LOW_DENSITY_FOAM", "41,1.0e-10,1.0,7", "*DEFINE_CURVE", "7", "0.0,0.0", "1.0,1.0"] ! 41-46
    character(len=line_length) :: lines(size(shells))
    lines = shells
    call read_lines("shells.k", cube_deck("24", lines), model, warnings, error)
    if (.not. allocated(error)) then
      call check(suite, "shells.k is rejected", .false., "the deck was accepted")
      return
    end if
    call check_messages("shells.k", error%message, [character(len=200) :: &
      "@:40: *MAT_NULL: field YM: material 40 (*MAT_NULL) on the shells of part 2 needs YM > 0 (it sets "// &
      "their time step and contact stiffness), found 0.0", &
      "@:29: *PART: field MID: part 3: material 41 has no shell (plane-stress) formulation"], count=2)
    lines(21) = "40,1.0e-9,,,,,70000.0,0.3"     ! deck line 40
    lines(10) = "3,2,24"                        ! deck line 29
    call read_lines("shells_good.k", cube_deck("24", lines), model, warnings, error)
    if (allocated(error)) then
      call check(suite, "shells_good.k (MAT_024 and MAT_NULL shells) is accepted", .false., error%message)
    else
      call check(suite, "shells_good.k (MAT_024 and MAT_NULL shells) is accepted", size(model%shell_ids) == 3)
    end if
  end subroutine test_shell_parts
end program test_deck_materials
