!> *DATABASE_ keywords: output intervals, the nodes written to the nodout history, and the
!> restart dumps (*DATABASE_BINARY_D3DUMP, _RUNRSF).
module deck_database
  use kinds, only: wp
  use error_handling, only: error_list_t
  use deck_problems, only: problem_log_t
  use deck_numbers, only: digit
  use text_format, only: integer_text, real_text
  use deck_lexer, only: deck_t
  use deck_keywords, only: keyword_t
  use deck_fields, only: card_t, open_card, next_line, require_card, get_integer, get_real, &
                         card_problem, warn_if_set, id_heading, line_problem, &
                         note_not_acted_upon, keyword_label
  use deck_input, only: deck_input_t, append_id
  implicit none
  private

  public :: read_plot_output, read_glstat_output, read_matsum_output, read_nodout_output, read_rwforc_output
  public :: read_history_nodes, read_history_node_sets, read_d3dump_output, read_runrsf_output
  public :: read_unused_output, read_rbdout_output, read_binary_field

  integer, parameter :: standard_widths(8) = 10
  !> The history outputs read by read_history_output.
  integer, parameter :: history_glstat = 1, history_matsum = 2, history_nodout = 3, history_rwforc = 4, &
                        history_rbdout = 5

contains

  !> *DATABASE_BINARY_D3PLOT card 1: DT LCDT BEAM NPLTC PSETID (card 2, filtering, is not
  !> read). NPLTC > 0 gives DT = ENDTIM/NPLTC once ENDTIM is known.
  subroutine read_plot_output(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, interval_curve
    line = 0
    if (.not. require_card(deck, block, line, standard_widths, card, log, &
                           "card 1 (DT LCDT BEAM NPLTC PSETID)", "DT")) return
    call get_real(deck, card, 1, "DT", input%model%output%state_interval, log)
    call get_integer(deck, card, 2, "LCDT", interval_curve, log)
    call get_integer(deck, card, 4, "NPLTC", input%plot_count, log)
    input%plot_line = line
    if (card%failed) return
    call check_interval(deck, card, input%model%output%state_interval, interval_curve, log)
    if (input%plot_count < 0) call card_problem(deck, log, card, "NPLTC", "must be >= 0, "// &
                                                "found "//integer_text(input%plot_count))
    call warn_if_set(deck, card, 5, "PSETID", "every part is written", warnings)
  end subroutine read_plot_output

  !> *DATABASE_GLSTAT: see read_history_output_card.
  subroutine read_glstat_output(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_history_output_card(deck, block, history_glstat, input, log, warnings)
  end subroutine read_glstat_output

  !> *DATABASE_MATSUM: see read_history_output_card.
  subroutine read_matsum_output(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_history_output_card(deck, block, history_matsum, input, log, warnings)
  end subroutine read_matsum_output

  !> *DATABASE_NODOUT: see read_history_output_card.
  subroutine read_nodout_output(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_history_output_card(deck, block, history_nodout, input, log, warnings)
  end subroutine read_nodout_output

  !> *DATABASE_RWFORC: see read_history_output_card.
  subroutine read_rwforc_output(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_history_output_card(deck, block, history_rwforc, input, log, warnings)
  end subroutine read_rwforc_output

  !> *DATABASE_RBDOUT: see read_history_output_card.
  subroutine read_rbdout_output(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_history_output_card(deck, block, history_rbdout, input, log, warnings)
  end subroutine read_rbdout_output

  !> *DATABASE_GLSTAT / _MATSUM / _NODOUT / _RWFORC / _RBDOUT: DT BINARY LCUR IOOPT (NODOUT:
  !> OPTION1 OPTION2 for nodouthf). BINARY chooses the files as LS-DYNA does (1 the ASCII
  !> file, 2 binout, 3 both; 0 or blank 1); results.h5 holds every history whatever it says.
  subroutine read_history_output_card(deck, block, history, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block, history
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, interval_curve, binary
    real(wp) :: interval
    line = 0
    if (.not. require_card(deck, block, line, standard_widths, card, log, &
                           "card 1 (DT BINARY LCUR IOOPT)", "DT")) return
    call get_real(deck, card, 1, "DT", interval, log)
    call get_integer(deck, card, 3, "LCUR", interval_curve, log)
    call read_binary_field(deck, card, log, binary)
    if (card%failed) return
    call check_interval(deck, card, interval, interval_curve, log)
    select case (history)
    case (history_glstat)
      input%model%output%glstat_interval = interval
      input%model%output%glstat_binary = binary
    case (history_matsum)
      input%model%output%matsum_interval = interval
      input%model%output%matsum_binary = binary
    case (history_nodout)
      input%model%output%nodout_interval = interval
      input%model%output%nodout_binary = binary
      input%nodout_line = line
      call warn_if_set(deck, card, 5, "OPTION1", "no high-frequency nodouthf output", warnings)
    case (history_rwforc)
      input%model%output%rwforc_interval = interval
      input%model%output%rwforc_binary = binary
    case (history_rbdout)
      input%model%output%rbdout_interval = interval
      input%model%output%rbdout_binary = binary
    end select
  end subroutine read_history_output_card

  !> BINARY (field 2 of card 1 of a history database): 1 the ASCII file, 2 binout, 3 both;
  !> 0 or blank is 1 (LS-DYNA's SMP default). Anything else is refused with its line.
  subroutine read_binary_field(deck, card, log, binary)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(inout) :: card
    type(problem_log_t), intent(inout) :: log
    integer, intent(out) :: binary
    call get_integer(deck, card, 2, "BINARY", binary, log)
    if (card%failed) return
    if (binary == 0) binary = 1
    if (binary < 1 .or. binary > 3) call card_problem(deck, log, card, "BINARY", "must be 1 (ASCII file), "// &
      "2 (binout) or 3 (both); 0 or blank is 1; found "//integer_text(binary))
  end subroutine read_binary_field

  !> *DATABASE_BINARY_D3DUMP card 1: CYCL LCDT BEAM NPLTC PSETID (card 2: IOOPT);
  !> *DATABASE_BINARY_RUNRSF (`running`) card 1: CYCL NR BEAM NPLTC PSETID. CYCL is the number
  !> of cycles between dumps (0: none but those the sense switches ask for), NR the number of
  !> running restart files written in turn (0: 1). LCDT (dump times from a curve) must be 0.
  !> BEAM, NPLTC and PSETID are D3PLOT's and D3PART's fields, which LS-DYNA does not use for
  !> dumps either, and IOOPT only acts with LCDT: read, with a warning when set. The last
  !> keyword of each kind counts.
  subroutine read_d3dump_output(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_dump_output(deck, block, .false., input, log, warnings)
  end subroutine read_d3dump_output

  subroutine read_runrsf_output(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_dump_output(deck, block, .true., input, log, warnings)
  end subroutine read_runrsf_output

  subroutine read_dump_output(deck, block, running, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    logical, intent(in) :: running
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    character(len=*), parameter :: unused = "LS-DYNA uses it for D3PLOT and D3PART, not for restart dumps"
    type(card_t) :: card
    integer :: line, second
    real(wp) :: cycles
    line = 0
    if (.not. require_card(deck, block, line, standard_widths, card, log, "card 1 (CYCL "// &
                           trim(merge("NR  ", "LCDT", running))//" BEAM NPLTC PSETID)", "CYCL")) return
    call get_real(deck, card, 1, "CYCL", cycles, log)
    call get_integer(deck, card, 2, trim(merge("NR  ", "LCDT", running)), second, log)
    if (card%failed) return
    call warn_if_set(deck, card, 3, "BEAM", unused, warnings)
    call warn_if_set(deck, card, 4, "NPLTC", unused, warnings)
    call warn_if_set(deck, card, 5, "PSETID", unused, warnings)
    if (cycles < 0.0_wp .or. cycles /= aint(cycles) .or. cycles > 2.0e9_wp) then
      call card_problem(deck, log, card, "CYCL", "the number of cycles between dumps must be "// &
                        "a whole number >= 0 (0: no periodic dumps), found "//real_text(cycles))
      return
    end if
    if (running) then
      if (second < 0) then
        call card_problem(deck, log, card, "NR", "the number of running restart files must be "// &
                          ">= 0 (0: one), found "//integer_text(second))
        return
      end if
      input%model%output%running_restart_cycles = nint(cycles)
      input%model%output%running_restart_files = max(1, second)
    else
      if (second /= 0) then
        call card_problem(deck, log, card, "LCDT", "dump intervals from a curve are not "// &
                          "available; give CYCL")
        return
      end if
      input%model%output%dump_cycles = nint(cycles)
      if (next_line(deck, block, line, .true.)) then
        call open_card(deck, block, line, standard_widths, card, log)
        call warn_if_set(deck, card, 1, "IOOPT", "it only acts with LCDT", warnings)
      end if
    end if
  end subroutine read_dump_output

  subroutine check_interval(deck, card, interval, interval_curve, log)
    type(deck_t), intent(in) :: deck
    type(card_t), intent(in) :: card
    real(wp), intent(in) :: interval
    integer, intent(in) :: interval_curve
    type(problem_log_t), intent(inout) :: log
    if (interval < 0.0_wp) call card_problem(deck, log, card, "DT", "output interval must "// &
      "be >= 0 (0: no output), found "//real_text(interval))
    if (interval_curve /= 0) call card_problem(deck, log, card, trim(merge("LCDT", "LCUR", &
      deck%blocks(card%block)%name == "DATABASE_BINARY_D3PLOT")), "output intervals from a "// &
      "curve are not available; give DT")
  end subroutine check_interval

  !> *DATABASE_HISTORY_NODE: see read_history_node_cards.
  subroutine read_history_nodes(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_history_node_cards(deck, block, keyword, .false., input, log)
  end subroutine read_history_nodes

  !> *DATABASE_HISTORY_NODE_SET: see read_history_node_cards.
  subroutine read_history_node_sets(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    call read_history_node_cards(deck, block, keyword, .true., input, log)
  end subroutine read_history_node_sets

  !> *DATABASE_HISTORY_NODE (ids 8 per line), _NODE_ID (one id and a heading per line) and
  !> _NODE_SET (set ids 8 per line).
  subroutine read_history_node_cards(deck, block, keyword, by_set, input, log)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    logical, intent(in) :: by_set
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(card_t) :: card
    integer :: line, k, id
    character(len=:), allocatable :: heading

    line = 0
    do while (next_line(deck, block, line, .true.))
      if (keyword%id) then
        call id_heading(deck, block, line, "ID", id, heading, log)
        if (id <= 0) then
          call line_problem(deck, log, line, block, "ID", "node id must be > 0, found "// &
                            integer_text(id))
        else
          call append_id(input%history_requests, id, line, 1)
        end if
        cycle
      end if
      call open_card(deck, block, line, standard_widths, card, log)
      do k = 1, 8
        call get_integer(deck, card, k, "ID"//digit(k), id, log)
        if (id < 0) then
          call card_problem(deck, log, card, "ID"//digit(k), "id must be > 0 (blank or 0 "// &
                            "entries are skipped), found "//integer_text(id))
        else if (id > 0) then
          call append_id(input%history_requests, id, line, merge(-k, k, by_set))
        end if
      end do
    end do
  end subroutine read_history_node_cards
  !> *DATABASE_ keywords for LS-DYNA output files crashfree does not write (binary extents,
  !> ASCII files of forces it does not compute, element histories, the binary format): read
  !> (every card), not acted upon. results.h5 holds the states and the histories crashfree
  !> writes (docs/keywords.md lists them).
  subroutine read_unused_output(deck, block, keyword, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(keyword_t), intent(in) :: keyword
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    character(len=:), allocatable :: name
    name = keyword_label(deck, block)
    if (index(name, "DATABASE_EXTENT_BINARY") == 1) then
      if (name == "DATABASE_EXTENT_BINARY") call read_strain_flag(deck, block, input, log, warnings)
      call note_not_acted_upon(deck, block, [character(len=1) :: ], "apart from STRFLG, it chooses "// &
        "what LS-DYNA's d3plot holds; crashfree's d3plot and results.h5 hold their fixed set of nodal and "// &
        "element results (shell layers: every integration point)", warnings)
    else if (index(name, "DATABASE_FORMAT") == 1) then
      call note_not_acted_upon(deck, block, [character(len=1) :: ], "results are written to "// &
        "HDF5 (results.h5)", warnings)
    else if (index(name, "DATABASE_HISTORY_") == 1) then
      call note_not_acted_upon(deck, block, [character(len=1) :: ], "no element histories "// &
        "(elout); every state in results.h5 holds the stresses of all elements", warnings)
    else
      call note_not_acted_upon(deck, block, [character(len=1) :: ], "crashfree does not "// &
        "write this LS-DYNA output file; results.h5 holds the histories listed in "// &
        "docs/keywords.md", warnings)
    end if
  end subroutine read_unused_output

  !> *DATABASE_EXTENT_BINARY card 1, field 4: STRFLG (LS-DYNA's digits abc: c = 1 the strain
  !> tensors of the solids and of the shells' inner and outer surfaces in the d3plot; b, a the
  !> plastic and thermal strain tensors, which crashfree does not write).
  subroutine read_strain_flag(deck, block, input, log, warnings)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: block
    type(deck_input_t), intent(inout) :: input
    type(problem_log_t), intent(inout) :: log
    type(error_list_t), intent(inout) :: warnings
    type(card_t) :: card
    integer :: line, flag
    line = 0
    if (.not. next_line(deck, block, line, .false.)) return
    call open_card(deck, block, line, standard_widths, card, log)
    call get_integer(deck, card, 4, "STRFLG", flag, log)
    if (card%failed) return
    if (flag < 0 .or. mod(flag, 10) > 1) then
      call card_problem(deck, log, card, "STRFLG", "must be 0 or 1 (1: strain tensors in the d3plot; "// &
                        "LS-DYNA's digits abc with c = 0 or 1), found "//integer_text(flag))
      return
    end if
    if (flag >= 10) call warn_if_set(deck, card, 4, "STRFLG", "its digits for the plastic and thermal "// &
                                     "strain tensors: the d3plot holds the strain tensors only", warnings)
    input%model%output%element_strains = mod(flag, 10) == 1
  end subroutine read_strain_flag
end module deck_database
