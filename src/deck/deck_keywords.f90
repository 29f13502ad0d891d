!> A keyword name taken apart (`keyword_t`: its row in the keyword table and the options given
!> with it) and the spelling tools for keyword names: options read against the ones a keyword
!> accepts, and the "did you mean" suggestion for a name that is not known. The names
!> themselves, with their options and readers, are rows of the keyword table
!> (deck_keyword_table).
module deck_keywords
  implicit none
  private

  public :: keyword_t, read_options, suggest_keyword

  !> `keyword_t%entry` of a name that is not a keyword crashfree reads.
  integer, parameter, public :: keyword_unknown = 0

  !> A keyword name taken apart: its row in the keyword table and the options given with it.
  type :: keyword_t
    integer :: entry = keyword_unknown  !< row of the keyword table (keyword_unknown: none)
    logical :: title = .false.     !< _TITLE: a title line before the first card
    logical :: id = .false.        !< _ID: an id/heading line before the first card
    logical :: finite = .false.    !< *RIGIDWALL_PLANAR_FINITE
    logical :: moving = .false.    !< *RIGIDWALL_PLANAR_MOVING
    logical :: forces = .false.    !< *RIGIDWALL_PLANAR_FORCES
    logical :: motion = .false.    !< *RIGIDWALL_GEOMETRIC_CYLINDER_MOTION
    logical :: contact = .false.   !< *PART_CONTACT: a card of contact values after each part
    logical :: display = .false.   !< *RIGIDWALL_GEOMETRIC_..._DISPLAY: a display card at the end
  end type keyword_t

  !> Longest keyword name a suggestion is looked for (longer ones are no typing slip).
  integer, parameter :: longest_suggested = 80

contains

  !> Options `text` ("MOVING_FORCES") against the `allowed` ones (blank-separated): each at
  !> most once, in any order, and with `one_option` at most one of them. `fits` is false when
  !> an option is not allowed or repeated; `keyword` then holds no options.
  pure subroutine read_options(text, allowed, one_option, keyword, fits)
    character(len=*), intent(in) :: text, allowed
    logical, intent(in) :: one_option
    type(keyword_t), intent(out) :: keyword
    logical, intent(out) :: fits
    integer :: start, finish, given
    character(len=:), allocatable :: option

    fits = .false.
    given = 0
    start = 1
    do while (start <= len(text))
      finish = index(text(start:), "_")
      if (finish == 0) then
        finish = len(text)
      else
        finish = start + finish - 2
      end if
      option = text(start:finish)
      start = finish + 2
      if (len(option) == 0) return
      if (index(" "//allowed//" ", " "//option//" ") == 0) return
      given = given + 1
      if (one_option .and. given > 1) return
      select case (option)
      case ("TITLE")
        if (keyword%title) return
        keyword%title = .true.
      case ("ID")
        if (keyword%id) return
        keyword%id = .true.
      case ("FINITE")
        if (keyword%finite) return
        keyword%finite = .true.
      case ("MOVING")
        if (keyword%moving) return
        keyword%moving = .true.
      case ("FORCES")
        if (keyword%forces) return
        keyword%forces = .true.
      case ("MOTION")
        if (keyword%motion) return
        keyword%motion = .true.
      case ("CONTACT")
        if (keyword%contact) return
        keyword%contact = .true.
      case ("DISPLAY")
        if (keyword%display) return
        keyword%display = .true.
      end select
    end do
    fits = text(len(text):) /= "_"
  end subroutine read_options

  !> A "did you mean" hint for the unknown keyword `name` (upper case, no `*`): the known
  !> keyword nearest in spelling, with the options of `name` spelt right (`suggestion`), and
  !> the same without options (`base`); both "" when no known keyword is close. Spelling
  !> distance counts insertions, deletions, substitutions and swaps of neighbours; the
  !> nearest name wins, a name of the same family (*MAT_..., *DATABASE_...) on a tie. A
  !> keyword crashfree reads, but not with the options given, gets `base` alone.
  !> The known names and their options are `names(k)` and `options_of(k)` (blank-separated, both
  !> trimmed here), in the keyword table's order: on equal distance the first one wins.
  pure subroutine suggest_keyword(name, names, options_of, suggestion, base)
    character(len=*), intent(in) :: name
    character(len=*), intent(in) :: names(:), options_of(:)
    character(len=:), allocatable, intent(out) :: suggestion, base
    character(len=:), allocatable :: candidate, options, corrected
    integer :: k, split, distance, best_score, option_distance
    logical :: fits

    suggestion = ""
    base = ""
    if (len(name) == 0 .or. len(name) > longest_suggested) return
    best_score = huge(best_score)
    do k = 1, size(names)
      candidate = trim(names(k))
      options = trim(options_of(k))
      ! the whole name as the base name
      distance = spelling_distance(name, candidate)
      if (distance > 0 .and. close_enough(name, candidate, distance)) &
        call consider(2*distance + family_penalty(name, candidate), candidate, candidate, &
                      best_score, suggestion, base)
      ! the name as a base name and options: NAME = HEAD_OPTION[_OPTION...]
      do split = len(name) - 1, 2, -1
        if (name(split:split) /= "_") cycle
        call match_options(name(split + 1:), options, corrected, option_distance, fits)
        if (.not. fits) cycle
        distance = spelling_distance(name(:split - 1), candidate)
        if (distance == 0 .and. option_distance == 0) cycle
        if (.not. close_enough(name(:split - 1), candidate, max(distance, 1))) cycle
        call consider(2*(distance + option_distance) + family_penalty(name, candidate), &
                      candidate//"_"//corrected, candidate, best_score, suggestion, base)
      end do
    end do
    if (len(suggestion) > 0) return
    ! a keyword read without these options: name it alone
    do split = len(name) - 1, 2, -1
      if (name(split:split) /= "_") cycle
      do k = 1, size(names)
        candidate = trim(names(k))
        if (name(:split - 1) /= candidate) cycle
        suggestion = candidate
        base = candidate
        return
      end do
    end do
  end subroutine suggest_keyword

  !> Keep `full` (and `new_base`) when `new_score` beats `best_score`.
  pure subroutine consider(new_score, full, new_base, best_score, suggestion, base)
    integer, intent(in) :: new_score
    character(len=*), intent(in) :: full, new_base
    integer, intent(inout) :: best_score
    character(len=:), allocatable, intent(inout) :: suggestion, base
    if (new_score >= best_score) return
    best_score = new_score
    suggestion = full
    base = new_base
  end subroutine consider

  !> Options `text` ("TITEL", "MOVING_FORCES") each matched to the nearest of `allowed`
  !> (blank-separated), within one slip per three letters; `corrected` joins the matches.
  pure subroutine match_options(text, allowed, corrected, distance, fits)
    character(len=*), intent(in) :: text, allowed
    character(len=:), allocatable, intent(out) :: corrected
    integer, intent(out) :: distance
    logical, intent(out) :: fits
    character(len=:), allocatable :: token, option, best_option
    integer :: start, finish, option_start, option_end, best, slip

    corrected = ""
    distance = 0
    fits = .false.
    if (len(allowed) == 0 .or. len(text) == 0) return
    start = 1
    do while (start <= len(text))
      finish = index(text(start:), "_")
      if (finish == 0) then
        finish = len(text)
      else
        finish = start + finish - 2
      end if
      token = text(start:finish)
      start = finish + 2
      if (len(token) == 0) return
      best = huge(best)
      option_start = 1
      do while (option_start <= len(allowed))
        option_end = index(allowed(option_start:), " ")
        if (option_end == 0) then
          option_end = len(allowed)
        else
          option_end = option_start + option_end - 2
        end if
        option = allowed(option_start:option_end)
        option_start = option_end + 2
        slip = spelling_distance(token, option)
        if (slip < best) then
          best = slip
          best_option = option
        end if
      end do
      if (best > max(1, len(best_option)/3)) return
      distance = distance + best
      if (len(corrected) > 0) corrected = corrected//"_"
      corrected = corrected//best_option
    end do
    fits = text(len(text):) /= "_"
  end subroutine match_options

  !> A distance small enough for a typing slip: at most one slip per five letters (one for
  !> short names, three at most), and, when both names have the same number of `_`-separated
  !> words, at most one slip per three letters in each word, so that *DATABASE_BINARY_D3THDT
  !> is not taken for *DATABASE_BINARY_D3PLOT.
  pure logical function close_enough(name, candidate, distance)
    character(len=*), intent(in) :: name, candidate
    integer, intent(in) :: distance
    integer :: name_start, candidate_start, name_end, candidate_end
    close_enough = distance <= min(3, max(1, len(name)/5))
    if (.not. close_enough) return
    if (count_words(name) /= count_words(candidate)) return
    name_start = 1
    candidate_start = 1
    do while (name_start <= len(name) .and. candidate_start <= len(candidate))
      name_end = word_end(name, name_start)
      candidate_end = word_end(candidate, candidate_start)
      if (spelling_distance(name(name_start:name_end), candidate(candidate_start:candidate_end)) &
          > max(1, (candidate_end - candidate_start + 1)/3)) then
        close_enough = .false.
        return
      end if
      name_start = name_end + 2
      candidate_start = candidate_end + 2
    end do
  end function close_enough

  pure integer function count_words(text)
    character(len=*), intent(in) :: text
    integer :: k
    count_words = 1
    do k = 1, len(text)
      if (text(k:k) == "_") count_words = count_words + 1
    end do
  end function count_words

  !> Last position of the `_`-separated word that starts at `start`.
  pure integer function word_end(text, start)
    character(len=*), intent(in) :: text
    integer, intent(in) :: start
    word_end = index(text(start:), "_")
    if (word_end == 0) then
      word_end = len(text)
    else
      word_end = start + word_end - 2
    end if
  end function word_end

  !> 1 when `name` and `candidate` are of different families (the word before the first
  !> `_`: MAT, DATABASE, CONTROL ...), else 0.
  pure integer function family_penalty(name, candidate)
    character(len=*), intent(in) :: name, candidate
    family_penalty = merge(0, 1, name(:word_end(name, 1)) == candidate(:word_end(candidate, 1)))
  end function family_penalty

  !> Edit distance with swaps of neighbouring letters (optimal string alignment): the number
  !> of insertions, deletions, substitutions and swaps that turn `first` into `second`.
  pure integer function spelling_distance(first, second)
    character(len=*), intent(in) :: first, second
    integer :: before(0:len(second)), previous(0:len(second)), current(0:len(second))
    integer :: i, j, cost
    do j = 0, len(second)
      previous(j) = j
    end do
    before = 0
    do i = 1, len(first)
      current(0) = i
      do j = 1, len(second)
        cost = merge(0, 1, first(i:i) == second(j:j))
        current(j) = min(previous(j) + 1, current(j - 1) + 1, previous(j - 1) + cost)
        if (i > 1 .and. j > 1) then
          if (first(i:i) == second(j - 1:j - 1) .and. first(i - 1:i - 1) == second(j:j)) &
            current(j) = min(current(j), before(j - 2) + 1)
        end if
      end do
      before = previous
      previous = current
    end do
    spelling_distance = previous(len(second))
  end function spelling_distance
end module deck_keywords
