!> *TITLE and the *CONTROL_ keywords: termination, time step, hourglass and bulk-viscosity
!> defaults, energy bookkeeping, and the choice of an implicit (linear static) analysis.
module deck_controls
  use kinds, only: wp
  use error_handling, only: error_list_t
  use deck_problems, only: problem_log_t
  use text_format, only: integer_text, real_text
  use deck_lexer, only: deck_t
  use deck_fields, only: card_t, next_line, require_card, get_integer, get_real, &
                         card_problem, warn_if_set, line_title, located_warning, &
                         note_not_acted_upon, keyword_label
  use deck_input, only: deck_input_t
  use deck_keywords, only: keyword_t
  implicit none
  private

  public :: read_title, read_termination, read_time_step, read_hourglass_control
  public :: read_bulk_viscosity, read_energy_control, read_implicit_general
  public :: read_implicit_solution, read_unused_control, read_sensor_definition

  integer, parameter :: standard_widths(8) = 10

contains

  !> *TITLE: the next line is the title.
  subroutine read_title(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    integer :: line
    line = 0
    if (next_line(deck, block, line, .false.)) input%model%title = line_title(deck, line)
  end subroutine read_title

  !> *CONTROL_TERMINATION: ENDTIM ENDCYC DTMIN ENDENG ENDMAS NOSOL. Whether ENDTIM is usable
  !> is checked once the whole deck is read (ENDCYC may stand in for it).
  subroutine read_termination(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line
    line = 0
    if (.not. require_card(deck, block, line, standard_widths, card, log, &
                           "card 1 (ENDTIM ENDCYC DTMIN ENDENG ENDMAS NOSOL)", "ENDTIM")) return
    input%termination_line = line
    call get_real(deck, card, 1, "ENDTIM", input%model%end_time, log)
    call get_integer(deck, card, 2, "ENDCYC", input%model%end_cycle, log)
    if (input%model%end_cycle < 0) call card_problem(deck, log, card, "ENDCYC", "must be "// &
      ">= 0 (0: no cycle limit), found "//integer_text(input%model%end_cycle))
    call get_real(deck, card, 3, "DTMIN", input%model%minimum_time_step_factor, log)
    call get_real(deck, card, 4, "ENDENG", input%model%energy_ratio_change_limit, log)
    call get_real(deck, card, 5, "ENDMAS", input%model%mass_change_limit, log)
    if (card%failed) return
    if (input%model%minimum_time_step_factor < 0.0_wp) call card_problem(deck, log, card, "DTMIN", &
      "must be >= 0 (a factor on the first time step; 0: off), found "//real_text(input%model%minimum_time_step_factor))
    if (input%model%minimum_time_step_factor >= 1.0_wp) call card_problem(deck, log, card, "DTMIN", &
      "must be below 1 (a factor on the first time step), found "//real_text(input%model%minimum_time_step_factor))
    if (input%model%energy_ratio_change_limit < 0.0_wp) call card_problem(deck, log, card, "ENDENG", &
      "must be >= 0 (percent; 0: off), found "//real_text(input%model%energy_ratio_change_limit))
    ! LS-DYNA's ENDMAS default 1e8 percent: blank or 0 keeps it; a curve (ENDMAS < 0) is not read
    if (input%model%mass_change_limit == 0.0_wp) input%model%mass_change_limit = 1.0e8_wp
    if (input%model%mass_change_limit < 0.0_wp) call card_problem(deck, log, card, "ENDMAS", &
      "a curve of the mass change (ENDMAS < 0) is not available; give a percentage")
    call warn_if_set(deck, card, 6, "NOSOL", "the solution always runs", warnings)
  end subroutine read_termination

  !> *CONTROL_TIMESTEP card 1: DTINIT TSSFAC ISDO TSLIMT DT2MS LCTM ERODE MS1ST (the optional
  !> cards 2 and 3 are not read). TSSFAC 0 or blank means 0.9.
  subroutine read_time_step(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, limit_curve, erode
    line = 0
    if (.not. require_card(deck, block, line, standard_widths, card, log, "card 1 (DTINIT "// &
                           "TSSFAC ISDO TSLIMT DT2MS LCTM ERODE MS1ST)", "DTINIT")) return
    associate (model => input%model)
      call get_real(deck, card, 1, "DTINIT", model%initial_time_step, log)
      call get_real(deck, card, 2, "TSSFAC", model%time_step_scale, log)
      call get_real(deck, card, 5, "DT2MS", model%mass_scaled_time_step, log)
      call get_integer(deck, card, 6, "LCTM", limit_curve, log)
      call get_integer(deck, card, 7, "ERODE", erode, log)
      if (card%failed) return
      ! ERODE's digits: 1 solids, 10 shells, 100 beams (none in crashfree)
      if (erode < 0 .or. erode > 111 .or. mod(erode, 10) > 1 .or. mod(erode/10, 10) > 1) then
        call card_problem(deck, log, card, "ERODE", "must be 0 or a sum of 1 (erode solids), 10 (shells) and "// &
          "100 (beams) when the step falls below DTMIN times the first, found "//integer_text(erode))
      else
        model%erode_solids_on_step = mod(erode, 10) == 1
        model%erode_shells_on_step = mod(erode/10, 10) == 1
        if (erode >= 100) call located_warning(deck, warnings, card%line, "ERODE", &
          "100 (erode beams): there are no beam elements")
      end if
      if (model%time_step_scale == 0.0_wp) model%time_step_scale = 0.9_wp
      if (model%initial_time_step < 0.0_wp) call card_problem(deck, log, card, "DTINIT", &
        "must be >= 0 (0: computed), found "//real_text(model%initial_time_step))
      if (model%time_step_scale < 0.0_wp) call card_problem(deck, log, card, "TSSFAC", &
        "a time-step scale curve (TSSFAC < 0) is not available; give a factor > 0")
      if (limit_curve /= 0) call card_problem(deck, log, card, "LCTM", "a curve limiting "// &
        "the time step is not available; leave LCTM blank")
      if (model%time_step_scale > 1.0_wp) call located_warning(deck, warnings, card%line, "TSSFAC", &
        "a factor of "//real_text(model%time_step_scale)//" takes steps beyond the stable step of the elements: "// &
        "the run is unstable unless their highest modes stay quiet (0.9, LS-DYNA's default, is safe)")
    end associate
    call warn_if_set(deck, card, 3, "ISDO", "shells only", warnings)
    call warn_if_set(deck, card, 4, "TSLIMT", "shells only", warnings)
    call warn_if_set(deck, card, 8, "MS1ST", "mass scaling is applied every cycle", warnings)
  end subroutine read_time_step

  !> *CONTROL_HOURGLASS: IHQ QH, the defaults of parts without their own *HOURGLASS type
  !> (IHQ 0 or blank: 1; QH 0 or blank: 0.1).
  subroutine read_hourglass_control(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line
    line = 0
    if (.not. require_card(deck, block, line, standard_widths, card, log, "card 1 (IHQ QH)", &
                           "IHQ")) return
    associate (model => input%model)
      call get_integer(deck, card, 1, "IHQ", model%default_hourglass_type, log, default=1)
      call get_real(deck, card, 2, "QH", model%default_hourglass_coefficient, log, default=0.1_wp)
      if (model%default_hourglass_type == 0) model%default_hourglass_type = 1
      if (model%default_hourglass_coefficient == 0.0_wp) &
        model%default_hourglass_coefficient = 0.1_wp
      if (card%failed) return
      if (model%default_hourglass_type < 1 .or. model%default_hourglass_type > 10) &
        call card_problem(deck, log, card, "IHQ", "hourglass type must be 1-10, found "// &
                          integer_text(model%default_hourglass_type))
      if (model%default_hourglass_coefficient < 0.0_wp) call card_problem(deck, log, card, &
        "QH", "must be >= 0, found "//real_text(model%default_hourglass_coefficient))
    end associate
  end subroutine read_hourglass_control

  !> *CONTROL_BULK_VISCOSITY: Q1 Q2 TYPE, the bulk-viscosity defaults (0 or blank: 1.5 and
  !> 0.06). TYPE is not used: bulk viscosity acts on solids, which is LS-DYNA's default.
  subroutine read_bulk_viscosity(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line
    line = 0
    if (.not. require_card(deck, block, line, standard_widths, card, log, "card 1 (Q1 Q2 TYPE)", &
                           "Q1")) return
    call get_real(deck, card, 1, "Q1", input%bulk_quadratic, log)
    call get_real(deck, card, 2, "Q2", input%bulk_linear, log)
    if (input%bulk_quadratic == 0.0_wp) input%bulk_quadratic = 1.5_wp
    if (input%bulk_linear == 0.0_wp) input%bulk_linear = 0.06_wp
    if (card%failed) return
    if (input%bulk_quadratic < 0.0_wp) call card_problem(deck, log, card, "Q1", &
      "must be >= 0, found "//real_text(input%bulk_quadratic))
    if (input%bulk_linear < 0.0_wp) call card_problem(deck, log, card, "Q2", "must be >= 0, "// &
                                                      "found "//real_text(input%bulk_linear))
  end subroutine read_bulk_viscosity

  !> *CONTROL_ENERGY: HGEN RWEN SLNTEN RYLEN ...; 1 = not in the energy balance, 2 = in it.
  !> HGEN and RWEN are used; the others concern features crashfree does not have, or what it
  !> always does (a warning names each one set).
  subroutine read_energy_control(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, hourglass, wall
    line = 0
    if (.not. require_card(deck, block, line, standard_widths, card, log, "card 1 (HGEN RWEN "// &
                           "SLNTEN RYLEN IRGEN MATEN DRLEN DISEN)", "HGEN")) return
    call get_integer(deck, card, 1, "HGEN", hourglass, log, default=1)
    call get_integer(deck, card, 2, "RWEN", wall, log, default=2)
    if (card%failed) return
    if (hourglass < 0 .or. hourglass > 2) call card_problem(deck, log, card, "HGEN", "must be "// &
      "1 (not computed) or 2 (in the energy balance), found "//integer_text(hourglass))
    if (wall < 0 .or. wall > 2) call card_problem(deck, log, card, "RWEN", "must be 1 (not "// &
      "computed) or 2 (in the energy balance), found "//integer_text(wall))
    input%model%hourglass_energy_in_balance = hourglass == 2
    input%model%wall_energy_in_balance = wall /= 1
    call warn_if_set(deck, card, 3, "SLNTEN", "contact energy is always computed and in the "// &
                     "energy balance", warnings)
    call warn_if_set(deck, card, 4, "RYLEN", "no Rayleigh damping, so no damping energy", warnings)
    call warn_if_set(deck, card, 5, "IRGEN", "no initial reference geometry", warnings)
    call warn_if_set(deck, card, 6, "MATEN", "matsum always holds each part's internal, "// &
                     "hourglass and kinetic energy", warnings)
    call warn_if_set(deck, card, 7, "DRLEN", "no dynamic relaxation", warnings)
    call warn_if_set(deck, card, 8, "DISEN", "no damping, so no dissipated damping energy", &
                     warnings)
  end subroutine read_energy_control

  !> *CONTROL_IMPLICIT_GENERAL: IMFLAG DT0 IMFORM NSBS IGS CNSTN FORM ZERO_V. IMFLAG 0 (blank)
  !> is the explicit analysis and 1 crashfree's implicit one, a linear static analysis; any
  !> other value is an error. With IMFLAG 0 the other fields are not used. With IMFLAG 1,
  !> geometric stiffness (IGS 1 or < 0) is an error, since it belongs to a nonlinear analysis;
  !> DT0 and CNSTN are ignored with a warning. IMFORM, NSBS, FORM and ZERO_V concern springback
  !> and the switching between explicit and implicit (IMFLAG 2, 4, 5) and are not used.
  subroutine read_implicit_general(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, analysis, formulation, springback_steps, geometric, tangent, form, &
               zero_velocity
    real(wp) :: first_step
    line = 0
    if (.not. require_card(deck, block, line, standard_widths, card, log, "card 1 (IMFLAG DT0 "// &
                           "IMFORM NSBS IGS CNSTN FORM ZERO_V)", "IMFLAG")) return
    call get_integer(deck, card, 1, "IMFLAG", analysis, log)
    call get_real(deck, card, 2, "DT0", first_step, log)
    call get_integer(deck, card, 3, "IMFORM", formulation, log, default=2)
    call get_integer(deck, card, 4, "NSBS", springback_steps, log, default=1)
    call get_integer(deck, card, 5, "IGS", geometric, log, default=2)
    call get_integer(deck, card, 6, "CNSTN", tangent, log)
    call get_integer(deck, card, 7, "FORM", form, log)
    call get_integer(deck, card, 8, "ZERO_V", zero_velocity, log)
    if (card%failed) return
    select case (analysis)
    case (0)
      input%model%implicit_static = .false.
      return
    case (1)
      input%model%implicit_static = .true.
    case default
      call card_problem(deck, log, card, "IMFLAG", "crashfree's implicit analysis is linear "// &
        "static: IMFLAG 0 or 1 (0 explicit, 1 implicit linear static), found "// &
        integer_text(analysis)//analysis_note(analysis))
      return
    end select
    if (geometric == 1 .or. geometric < 0) call card_problem(deck, log, card, "IGS", &
      "geometric stiffness is not available: crashfree's implicit analysis is linear static; "// &
      "leave IGS blank or 2, found "//integer_text(geometric))
    call warn_if_set(deck, card, 2, "DT0", "crashfree's linear static analysis takes no "// &
                     "implicit time step", warnings)
    call warn_if_set(deck, card, 6, "CNSTN", "a linear analysis uses the elastic stiffness", &
                     warnings)
  end subroutine read_implicit_general

  !> What an IMFLAG value crashfree does not have would select, for the message.
  pure function analysis_note(analysis) result(note)
    integer, intent(in) :: analysis
    character(len=:), allocatable :: note
    select case (analysis)
    case (2)
      note = " (an implicit springback step after the explicit analysis)"
    case (4, 5)
      note = " (automatic switching between implicit and explicit)"
    case (6)
      note = " (eigenvalue extraction)"
    case (:-1)
      note = " (a curve switching between explicit and implicit)"
    case default
      note = ""
    end select
  end function analysis_note

  !> *CONTROL_IMPLICIT_SOLUTION card 1: NSOLVR ILIMIT MAXREF DCTOL ECTOL RCTOL LSTOL ABSTOL.
  !> NSOLVR is judged once the whole deck is read, since it matters only when
  !> *CONTROL_IMPLICIT_GENERAL asks for the implicit analysis. The other fields and the further
  !> cards steer nonlinear iterations, which a linear analysis does not do: they are read
  !> (card 1) or skipped (cards 2-4) and not used.
  subroutine read_implicit_solution(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, k, iterations, reformations
    real(wp) :: tolerance
    character(len=6), parameter :: tolerance_names(5) = ["DCTOL ", "ECTOL ", "RCTOL ", "LSTOL ", &
                                                         "ABSTOL"]
    line = 0
    if (.not. require_card(deck, block, line, standard_widths, card, log, "card 1 (NSOLVR "// &
                           "ILIMIT MAXREF DCTOL ECTOL RCTOL LSTOL ABSTOL)", "NSOLVR")) return
    call get_integer(deck, card, 1, "NSOLVR", input%implicit_solver, log)
    call get_integer(deck, card, 2, "ILIMIT", iterations, log)
    call get_integer(deck, card, 3, "MAXREF", reformations, log)
    do k = 1, 5
      call get_real(deck, card, k + 3, trim(tolerance_names(k)), tolerance, log)
    end do
    input%implicit_solution_line = line
  end subroutine read_implicit_solution
  !> *CONTROL_ keywords a vehicle deck commonly has that only set LS-DYNA's own bookkeeping,
  !> or options of formulations crashfree does not have: read (every card), not acted upon;
  !> the warning names the fields the deck sets.
  subroutine read_unused_control(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    character(len=:), allocatable :: name
    name = keyword_label(deck, block)
    if (index(name, "CONTROL_PARALLEL") == 1) then
      call note_not_acted_upon(deck, block, [character(len=40) :: "NCPU NUMRHS CONST PARA"], &
        "threads are set with ncpu= on the command line; results are the same for any "// &
        "thread count, which is what CONST asks for", warnings)
    else if (index(name, "CONTROL_OUTPUT") == 1) then
      call note_not_acted_upon(deck, block, [character(len=60) :: &
        "NPOPT NEECHO NREFUP IACCOP OPIFS IPNINT IKEDIT IFLUSH", &
        "IPRTF IERODE TET10S8 MSGMAX IPCURV GMDT IP1DBLT EOCS", &
        "TOLEV NEWLEG FRFREQ MINFO SOLSIG MSGFLG CDETOL"], &
        "it chooses what LS-DYNA's d3hsp and messag hold; crashfree writes its own d3hsp summary "// &
        "and messag (docs/output.md)", warnings)
    else if (index(name, "CONTROL_CPU") == 1) then
      call note_not_acted_upon(deck, block, [character(len=40) :: "CPUTIM IGLST"], &
        "no CPU-time limit; stop a run with SIGTERM, which writes a restart dump", warnings)
    else if (index(name, "CONTROL_SHELL") == 1) then
      call note_not_acted_upon(deck, block, [character(len=60) :: &
        "WRPANG ESORT IRNXX ISTUPD THEORY BWC MITER PROJ", &
        "ROTASCL INTGRD LAMSHT CSTYP6 THSHEL", &
        "PSSTUPD SIDT4TU CNTCO ITSFLG IRQUAD W-MODE STRETCH ICRQ", &
        "NFAIL1 NFAIL4 PSNFAIL KEEPCS DELFR DRCPSID DRCPRM INTPERR"], &
        "crashfree's shell is the Belytschko-Tsay shell of *SECTION_SHELL ELFORM 2, with "// &
        "constant thickness and Gauss points through it; the global shell options do not "// &
        "change it, and triangles (N3 = N4) always run as C0 triangles, as with ESORT = 1", warnings)
    else if (index(name, "CONTROL_SOLID") == 1) then
      call note_not_acted_upon(deck, block, [character(len=60) :: &
        "ESORT FMATRX NIPTETS SWLOCL PSFAIL T10JTOL ICOH TET13K"], &
        "solids take their formulation from *SECTION_SOLID ELFORM; degenerate tetrahedra "// &
        "always run as one-point tetrahedra (as with ESORT = 1), wedges and pyramids as "// &
        "degenerate hexahedra", warnings)
    else if (index(name, "CONTROL_ACCURACY") == 1) then
      call note_not_acted_upon(deck, block, [character(len=40) :: "OSU INN PIDOSU IACC EXACC"], &
        "stresses are rotated objectively in every cycle and results do not depend on the "// &
        "node numbering", warnings)
    else if (index(name, "CONTROL_MPP_") == 1) then
      call note_not_acted_upon(deck, block, [character(len=1) :: ], "it sets up LS-DYNA's MPP "// &
        "domain decomposition and files; crashfree partitions the model itself for mpirun (METIS, "// &
        "weighted by element cost; partition=N shows it) and writes one set of files", warnings)
    else
      call note_not_acted_upon(deck, block, [character(len=1) :: ], "crashfree has no use "// &
        "for it", warnings)
    end if
  end subroutine read_unused_control

  !> *SENSOR_DEFINE_...: read (all of its cards), not acted upon: crashfree reads nothing that
  !> a sensor could switch (*SENSOR_CONTROL and *SENSOR_SWITCH are not read, and a deck
  !> holding them is refused as unknown keywords).
  subroutine read_sensor_definition(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call note_not_acted_upon(deck, block, [character(len=1) :: ], "nothing in the deck uses "// &
      "the sensor: crashfree reads no keyword that a sensor switches", warnings)
  end subroutine read_sensor_definition
end module deck_controls
