!> *PART, *SECTION_SOLID and *HOURGLASS: what each part is made of and how it is integrated.
module deck_parts_sections
  use kinds, only: wp
  use error_handling, only: error_list_t
  use model, only: formulation_fe
  use deck_problems, only: problem_log_t
  use deck_numbers, only: integer_text, real_text
  use deck_lexer, only: deck_t
  use deck_keywords, only: keyword_t
  use deck_fields, only: card_t, next_line, require_card, next_definition, has_data, &
                         get_integer, get_real, card_problem, warn_if_set, line_title
  use deck_input, only: deck_input_t
  implicit none
  private

  public :: read_parts, read_solid_sections, read_hourglasses

  integer, parameter :: standard_widths(8) = 10

contains

  !> *PART: a heading line, then PID SECID MID EOSID HGID GRAV ADPOPT TMID; repeated.
  subroutine read_parts(deck, block, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, n, equation_of_state, adaptivity
    character(len=:), allocatable :: title

    line = 0
    if (.not. has_data(deck, block, log, "the heading line and the data card", "PID")) return
    do while (next_line(deck, block, line, .false.))
      title = line_title(deck, line)
      if (.not. require_card(deck, block, line, standard_widths, card, log, "the data card "// &
          "(PID SECID MID EOSID HGID GRAV ADPOPT TMID) after the heading line", "PID")) exit
      n = input%part_count + 1
      input%part_count = n
      input%part_lines(n) = line
      associate (part => input%model%parts(n))
        part%title = title
        part%formulation = formulation_fe
        call get_integer(deck, card, 1, "PID", part%id, log)
        call get_integer(deck, card, 2, "SECID", part%section_id, log)
        call get_integer(deck, card, 3, "MID", part%material_id, log)
        call get_integer(deck, card, 4, "EOSID", equation_of_state, log)
        call get_integer(deck, card, 5, "HGID", part%hourglass_id, log)
        call get_integer(deck, card, 7, "ADPOPT", adaptivity, log)
        if (card%failed) cycle
        if (part%id <= 0) call card_problem(deck, log, card, "PID", "part id must be > 0, "// &
                                            "found "//integer_text(part%id))
        if (part%section_id < 0) call card_problem(deck, log, card, "SECID", &
          "section id must be > 0, found "//integer_text(part%section_id))
        if (part%material_id < 0) call card_problem(deck, log, card, "MID", &
          "material id must be > 0, found "//integer_text(part%material_id))
        if (part%hourglass_id < 0) call card_problem(deck, log, card, "HGID", "hourglass id "// &
          "must be >= 0 (0: the *CONTROL_HOURGLASS defaults), found "// &
          integer_text(part%hourglass_id))
        if (equation_of_state /= 0) call card_problem(deck, log, card, "EOSID", "equations "// &
          "of state (*EOS) are not available; leave EOSID blank")
        if (adaptivity /= 0) call card_problem(deck, log, card, "ADPOPT", "adaptive "// &
          "remeshing is not available; leave ADPOPT blank")
      end associate
      call warn_if_set(deck, card, 6, "GRAV", "*LOAD_DENSITY_DEPTH is not read", warnings)
      call warn_if_set(deck, card, 8, "TMID", "no thermal analysis", warnings)
    end do
  end subroutine read_parts

  !> *SECTION_SOLID (and *SECTION_SOLID_EFG): SECID ELFORM AET, one card per section
  !> (a title line before it with _TITLE). ELFORM 1 and 2 are available.
  subroutine read_solid_sections(deck, block, keyword, meshfree_keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    logical, intent(in) :: meshfree_keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, n, formulation
    character(len=:), allocatable :: title

    line = 0
    do while (next_definition(deck, block, keyword%title, line, standard_widths, card, title, &
                              log, "card 1 (SECID ELFORM AET)", "SECID"))
      n = input%section_count + 1
      input%section_count = n
      input%section_lines(n) = line
      associate (section => input%model%sections(n))
        section%title = title
        call get_integer(deck, card, 1, "SECID", section%id, log)
        call get_integer(deck, card, 2, "ELFORM", formulation, log, default=1)
        section%element_formulation = formulation
        if (card%failed) cycle
        if (section%id <= 0) call card_problem(deck, log, card, "SECID", "section id must "// &
                                               "be > 0, found "//integer_text(section%id))
        if (meshfree_keyword .or. formulation == 41 .or. formulation == 42) then
          call card_problem(deck, log, card, "ELFORM", "meshfree sections are not "// &
            "available yet (ELFORM "//integer_text(formulation)//"); use ELFORM 1 or 2")
          exit     ! the EFG cards that follow are not sections
        end if
        if (formulation /= 1 .and. formulation /= 2) call card_problem(deck, log, card, &
          "ELFORM", "element formulation "//integer_text(formulation)//" is not "// &
          "available; crashfree has ELFORM 1 (one-point, constant stress) and 2 (fully "// &
          "integrated, selective reduced)")
      end associate
      call warn_if_set(deck, card, 3, "AET", "ambient elements are not available", warnings)
    end do
  end subroutine read_solid_sections

  !> *HOURGLASS: HGID IHQ QM IBQ Q1 Q2 QB/VDC QW, one card per definition. Values are kept as
  !> written (blank = 0); the cross-check turns IHQ 0 and blank QM, Q1, Q2 into the global
  !> defaults.
  subroutine read_hourglasses(deck, block, keyword, input, log)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(card_t) :: card
    integer :: line, n
    character(len=:), allocatable :: title

    line = 0
    do while (next_definition(deck, block, keyword%title, line, standard_widths, card, title, &
                              log, "card 1 (HGID IHQ QM IBQ Q1 Q2 QB QW)", "HGID"))
      n = input%hourglass_count + 1
      input%hourglass_count = n
      input%hourglass_lines(n) = line
      associate (hourglass => input%model%hourglasses(n))
        hourglass%title = title
        call get_integer(deck, card, 1, "HGID", hourglass%id, log)
        call get_integer(deck, card, 2, "IHQ", hourglass%hourglass_type, log)
        call get_real(deck, card, 3, "QM", hourglass%coefficient, log)
        call get_real(deck, card, 5, "Q1", hourglass%bulk_quadratic, log)
        call get_real(deck, card, 6, "Q2", hourglass%bulk_linear, log)
        if (card%failed) cycle
        if (hourglass%id <= 0) call card_problem(deck, log, card, "HGID", "hourglass id "// &
                                                 "must be > 0, found "//integer_text(hourglass%id))
        if (hourglass%hourglass_type < 0 .or. hourglass%hourglass_type > 10) &
          call card_problem(deck, log, card, "IHQ", "hourglass type must be 0-10, found "// &
                            integer_text(hourglass%hourglass_type))
        call check_not_negative(deck, log, card, "QM", hourglass%coefficient)
        call check_not_negative(deck, log, card, "Q1", hourglass%bulk_quadratic)
        call check_not_negative(deck, log, card, "Q2", hourglass%bulk_linear)
      end associate
    end do
  end subroutine read_hourglasses

  subroutine check_not_negative(deck, log, card, name, value)
    type(deck_t), intent(in) :: deck
    type(problem_log_t), intent(inout) :: log
    type(card_t), intent(in) :: card
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: value
    if (value < 0.0_wp) call card_problem(deck, log, card, name, "must be >= 0, found "// &
                                          real_text(value))
  end subroutine check_not_negative
end module deck_parts_sections
