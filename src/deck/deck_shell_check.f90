!> The part of the cross-check that shells brought, run once part ids and section ids are
!> resolved: every element's part has a section of the element's kind (a solid a solid
!> section, a shell a shell section), every shell gets its four corner thicknesses, and the
!> linear static analysis gets no shells. (Which materials a shell part takes, and *MAT_NULL
!> on shells only, is checked with the material laws in deck_material_curves.)
!>
!> A wrong section usually concerns every element of a part, so these problems are
!> reported once per part, at its first element, with the number of further elements alike: a
!> mesh of a million shells on a solid section gives one line, not a million.
module deck_shell_check
  use kinds, only: wp
  use model, only: section_solid, section_shell, section_beam
  use deck_problems, only: problem_log_t
  use deck_numbers, only: digit
  use text_format, only: integer_text, real_text
  use deck_lexer, only: deck_t
  use deck_fields, only: located_problem
  use deck_input, only: deck_input_t
  implicit none
  private

  public :: check_element_sections, build_shell_thickness
  public :: check_static_shells

contains

  !> A solid element needs a part with a solid section (*SECTION_SOLID, _EFG), a shell a part
  !> with a shell section (*SECTION_SHELL). Elements whose part or section is undefined were
  !> reported before and are skipped.
  subroutine check_element_sections(deck, input, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(in) :: input
    type(problem_log_t), intent(inout) :: log
    associate (model => input%model)
      call check_section_kind(deck, input, model%solid_part(1:input%solid_count), &
        model%solid_ids(1:input%solid_count), input%solid_lines(1:input%solid_count), &
        section_solid, log)
      call check_section_kind(deck, input, model%shell_part(1:input%shell_count), &
        model%shell_ids(1:input%shell_count), input%shell_lines(1:input%shell_count), &
        section_shell, log)
    end associate
  end subroutine check_element_sections

  !> Elements (part indices `parts`, ids `ids`, cards `lines`) whose part's section is not of
  !> kind `wanted`: one message per part.
  subroutine check_section_kind(deck, input, parts, ids, lines, wanted, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(in) :: input
    integer, intent(in) :: parts(:), ids(:), lines(:)
    integer, intent(in) :: wanted
    type(problem_log_t), intent(inout) :: log
    integer, allocatable :: first(:), others(:)
    integer :: element, part, section
    character(len=:), allocatable :: message

    allocate (first(input%part_count), others(input%part_count))
    first = 0
    others = 0
    do element = 1, size(parts)
      part = parts(element)
      if (part <= 0) cycle
      section = input%model%parts(part)%section
      if (section <= 0) cycle
      if (input%model%sections(section)%kind == wanted) cycle
      if (first(part) == 0) then
        first(part) = element
      else
        others(part) = others(part) + 1
      end if
    end do
    do part = 1, input%part_count
      if (first(part) == 0) cycle
      associate (section => input%model%sections(input%model%parts(part)%section))
        if (section%kind == section_beam) then
          message = "part "//integer_text(input%model%parts(part)%id)//" of "// &
            trim(merge("solid element", "shell        ", wanted == section_solid))//" "// &
            integer_text(ids(first(part)))//" has beam section "//integer_text(section%id)// &
            " (*SECTION_BEAM); beam sections are for *ELEMENT_BEAM"
        else if (wanted == section_solid) then
          message = "part "//integer_text(input%model%parts(part)%id)//" of solid element "// &
            integer_text(ids(first(part)))//" has shell section "//integer_text(section%id)// &
            " (*SECTION_SHELL); solid elements need a *SECTION_SOLID or *SECTION_SOLID_EFG "// &
            "section"
        else
          message = "part "//integer_text(input%model%parts(part)%id)//" of shell "// &
            integer_text(ids(first(part)))//" has solid section "//integer_text(section%id)// &
            " (*SECTION_SOLID); shells need a *SECTION_SHELL section"
        end if
      end associate
      call located_problem(deck, log, lines(first(part)), "PID", message// &
                           more_elements(others(part)))
    end do
  end subroutine check_section_kind

  !> Each shell's corner thicknesses: THICk of *ELEMENT_SHELL_THICKNESS where it is > 0, else
  !> Tk of the section (whose T2-T4 already default to T1). A triangle's corner 4 is its node 3
  !> and takes corner 3's thickness. A corner left without thickness is an error, once per part
  !> (at the first such shell). Shells whose part or section is undefined or of the wrong kind
  !> were reported before and are skipped.
  subroutine build_shell_thickness(deck, input, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    integer, allocatable :: first(:), others(:), corner_of(:)
    real(wp) :: given(4), thickness(4)
    integer :: shell, part, section, corner

    allocate (first(input%part_count), others(input%part_count), corner_of(input%part_count))
    first = 0
    others = 0
    corner_of = 0
    associate (model => input%model)
      do shell = 1, input%shell_count
        part = model%shell_part(shell)
        if (part <= 0) cycle
        section = model%parts(part)%section
        if (section <= 0) cycle
        if (model%sections(section)%kind /= section_shell) cycle
        given = model%shell_thickness(:, shell)
        thickness = merge(given, model%sections(section)%thickness, given > 0.0_wp)
        if (model%shell_nodes(3, shell) == model%shell_nodes(4, shell)) thickness(4) = thickness(3)
        model%shell_thickness(:, shell) = thickness
        if (all(thickness > 0.0_wp)) cycle
        if (first(part) == 0) then
          first(part) = shell
          do corner = 1, 4
            if (thickness(corner) <= 0.0_wp) exit
          end do
          corner_of(part) = corner
        else
          others(part) = others(part) + 1
        end if
      end do
      do part = 1, input%part_count
        if (first(part) == 0) cycle
        call report_no_thickness(first(part), corner_of(part), others(part))
      end do
    end associate
  contains
    !> "shell EID has no thickness", at the THIC card of a *ELEMENT_SHELL_THICKNESS shell,
    !> else at the element card.
    subroutine report_no_thickness(shell, corner, more)
      integer, intent(in) :: shell, corner, more
      character(len=:), allocatable :: reason
      associate (model => input%model, section => &
                 input%model%sections(input%model%parts(input%model%shell_part(shell))%section))
        if (input%shell_thickness_lines(shell) /= input%shell_lines(shell)) then
          reason = "THIC"//digit(corner)//" is blank or 0 and T"//digit(corner)// &
            " of section "//integer_text(section%id)//" is "// &
            real_text(section%thickness(corner))
          call located_problem(deck, log, input%shell_thickness_lines(shell), "THIC"// &
            digit(corner), "shell "//integer_text(model%shell_ids(shell))//" has no "// &
            "thickness at N"//digit(corner)//": "//reason//more_shells(more))
        else
          reason = "T1 of its section "//integer_text(section%id)//" is "// &
            real_text(section%thickness(1))//" and *ELEMENT_SHELL gives none (set T1 on "// &
            "card 2 of *SECTION_SHELL, or use *ELEMENT_SHELL_THICKNESS)"
          if (corner > 1) reason = "T"//digit(corner)//" of its section "// &
            integer_text(section%id)//" is "//real_text(section%thickness(corner))
          call located_problem(deck, log, input%shell_lines(shell), "PID", "shell "// &
            integer_text(model%shell_ids(shell))//" has no thickness: "//reason// &
            more_shells(more))
        end if
      end associate
    end subroutine report_no_thickness

    function more_shells(more) result(text)
      integer, intent(in) :: more
      character(len=:), allocatable :: text
      text = ""
      if (more == 1) text = "; 1 more shell of this part has none"
      if (more > 1) text = "; "//integer_text(more)//" more shells of this part have none"
    end function more_shells
  end subroutine build_shell_thickness

  !> The linear static analysis (*CONTROL_IMPLICIT_GENERAL IMFLAG = 1) assembles solids only.
  subroutine check_static_shells(deck, input, log)
    type(deck_t), intent(in) :: deck
    type(deck_input_t), intent(in) :: input
    type(problem_log_t), intent(inout) :: log
    if (.not. input%model%implicit_static .or. input%shell_count == 0) return
    call located_problem(deck, log, input%shell_lines(1), "EID", "the linear static "// &
      "analysis (*CONTROL_IMPLICIT_GENERAL IMFLAG = 1) takes solid elements only; this deck "// &
      "has "//integer_text(input%shell_count)//" shell"//trim(merge("s", " ", &
      input%shell_count > 1))//", which run in explicit analyses only")
  end subroutine check_static_shells

  function more_elements(more) result(text)
    integer, intent(in) :: more
    character(len=:), allocatable :: text
    text = ""
    if (more == 1) text = "; 1 more element of this part is alike"
    if (more > 1) text = "; "//integer_text(more)//" more elements of this part are alike"
  end function more_elements
end module deck_shell_check
