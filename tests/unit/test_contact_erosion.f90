!> Eroded elements leave the penalty contacts (contact_erosion): elements are marked eroded by
!> hand between contact evaluations.
!>  - A node pressed 0.01 mm into the top of a 2 x 2 x 2 block of 1 mm hexahedra: force
!>    SLSFAC K A^2 / V x 0.01. Pressed 0.01 mm into the second layer it gets nothing (deeper than
!>    the contact depth V / 2A); once the top layer has eroded, the faces it covered are the
!>    surface and the same node gets the same force as on the intact top. The block's single
!>    surface contact takes the newly exposed faces and nodes.
!>  - A node 0.03 mm into the contact surface of a 2 x 2 plate of 1 mm shells (t = 0.2 mm):
!>    force SLSFAC K A / diagonal x 0.03; it keeps its pair and its force when a shell elsewhere
!>    erodes, and falls through (no force) once the shell under it has eroded. Plate nodes that
!>    lost all their shells are no longer checked. A node just beside the plate's edge gets the
!>    same force whatever the masses of the segment's corners it lies away from.
program test_contact_erosion
  use kinds, only: wp
  use testing, only: test_suite_t, check, check_close, finish_suite
  use fixtures, only: make_scratch_directory, node_card, element_card, read_deck_lines
  use error_handling, only: error_t
  use model, only: model_t
  use penalty_contact, only: contact_state_t, set_up_contacts, compute_contact_forces
  use contact_erosion, only: remove_eroded_elements
  implicit none

  !> SLSFAC (default 0.1) x bulk modulus of E = 1, nu = 0.3
  real(wp), parameter :: stiffness_scale = 0.1_wp/(3.0_wp*(1.0_wp - 0.6_wp))
  real(wp), parameter :: step = 0.02_wp
  type(test_suite_t) :: suite
  character(len=:), allocatable :: directory

  suite%name = "contact_erosion"
  directory = make_scratch_directory("crashfree_test_contact_erosion")
  call test_block_layer_erodes()
  call test_plate_shells_erode()
  call finish_suite(suite)

contains

  subroutine test_block_layer_erodes()
    type(model_t) :: model
    type(contact_state_t), allocatable :: contacts(:)
    real(wp), allocatable :: x(:, :), v(:, :), mass(:), force(:, :)
    logical, allocatable :: solid_eroded(:), shell_eroded(:)
    character(len=80), allocatable :: lines(:)
    integer :: i, j, k, e, probe
    real(wp) :: on_top, expected

    allocate (lines(0))
    lines = [character(len=80) :: "*KEYWORD", "*CONTROL_TERMINATION", "1.0", &
                                  "*PART", "block", "1,1,1", "*PART", "probe", "2,1,1", "*SECTION_SOLID", "1,1", &
                                  "*MAT_ELASTIC", "1,1.0e-6,1.0,0.3", "*SET_NODE_LIST", "1", "28", &
                                  "*CONTACT_AUTOMATIC_NODES_TO_SURFACE", "1,1,4,3", &
                                  "*CONTACT_AUTOMATIC_SINGLE_SURFACE", "1,0,3", "*NODE"]
    do k = 0, 2
      do j = 0, 2
        do i = 0, 2
          lines = [character(len=80) :: lines, node_card(1 + i + 3*j + 9*k, real([i, j, k], wp))]
        end do
      end do
    end do
    ! the probe: a unit cube above the block, its first node at (1.3, 1.2, 2.5)
    do k = 0, 1
      do j = 0, 1
        do i = 0, 1
          lines = [character(len=80) :: lines, node_card(28 + i + 2*j + 4*k, [1.3_wp, 1.2_wp, 2.5_wp] + &
                                                         real([i, j, k], wp))]
        end do
      end do
    end do
    lines = [character(len=80) :: lines, "*ELEMENT_SOLID"]
    e = 0
    do k = 0, 1
      do j = 0, 1
        do i = 0, 1
          e = e + 1
          associate (n => 1 + i + 3*j + 9*k)
            lines = [character(len=80) :: lines, element_card(e, 1, [n, n + 1, n + 4, n + 3, n + 9, n + 10, n + 13, &
                                                                      n + 12])]
          end associate
        end do
      end do
    end do
    lines = [character(len=80) :: lines, element_card(9, 2, [28, 29, 31, 30, 32, 33, 35, 34]), "*END"]
    if (.not. read_model("block.k", lines, model)) return
    call set_up(model, contacts, x, v, mass, force)
    probe = 28
    call check(suite, "block: single surface has the 24 faces and 26 surface nodes of the intact block", &
               contacts(2)%passes(1)%segment_count == 24 .and. contacts(2)%passes(1)%node_count == 26)
    call evaluate(model, contacts, x, v, mass, force)          ! the first check: nothing touches
    v(3, probe) = -1.0_wp
    x(:, probe) = [1.3_wp, 1.2_wp, 1.99_wp]
    call evaluate(model, contacts, x, v, mass, force)
    on_top = force(3, probe)
    expected = stiffness_scale*1.0_wp*0.01_wp
    call check_close(suite, "block: a node 0.01 into the top face gets SLSFAC K A^2/V x 0.01", on_top, expected, &
                     rel=1.0e-9_wp)
    x(:, probe) = [1.3_wp, 1.2_wp, 0.99_wp]
    call evaluate(model, contacts, x, v, mass, force)
    call check(suite, "block: 0.01 into the second layer is beyond the contact depth of the intact block", &
               all(force(:, probe) == 0.0_wp))
    allocate (solid_eroded(size(model%solid_part)), shell_eroded(size(model%shell_part)))
    solid_eroded = .false.
    shell_eroded = .false.
    solid_eroded(5:8) = .true.                                  ! the top layer
    call remove_eroded_elements(model, contacts, solid_eroded, shell_eroded)
    call evaluate(model, contacts, x, v, mass, force)
    call check_close(suite, "block: once the top layer eroded, the same force on the second layer", &
                     force(3, probe), on_top, rel=1.0e-12_wp)
    call check(suite, "block: force along +z only", abs(force(1, probe)) + abs(force(2, probe)) < 1.0e-14_wp)
    associate (pass => contacts(2)%passes(1))
      call check(suite, "block: single surface now has the 16 faces and 18 nodes of one layer, the centre node "// &
                 "among them", pass%segment_count == 16 .and. pass%node_count == 18 .and. any(pass%nodes == 14))
    end associate
    associate (pass => contacts(1)%passes(1))
      call check(suite, "block: the probe contact's surface is the remaining layer (16 faces)", &
                 pass%segment_count == 16)
    end associate
  end subroutine test_block_layer_erodes

  subroutine test_plate_shells_erode()
    type(model_t) :: model
    type(contact_state_t), allocatable :: contacts(:)
    real(wp), allocatable :: x(:, :), v(:, :), mass(:), force(:, :)
    logical, allocatable :: solid_eroded(:), shell_eroded(:)
    character(len=80), allocatable :: lines(:)
    integer :: i, j, k, probe, pair
    integer :: corners(4)
    real(wp) :: on_plate, expected, beside

    allocate (lines(0))
    lines = [character(len=80) :: "*KEYWORD", "*CONTROL_TERMINATION", "1.0", &
                                  "*PART", "plate", "1,1,1", "*PART", "probe", "2,2,1", "*SECTION_SHELL", "1,2,1.0,2", &
                                  "0.2,0.2,0.2,0.2", "*SECTION_SOLID", "2,1", "*MAT_ELASTIC", "1,1.0e-6,1.0,0.3", &
                                  "*SET_NODE_LIST", "1", "10", "*SET_NODE_LIST", "2", "1,2,3,4,5,6,7,8", "9", &
                                  "*CONTACT_AUTOMATIC_NODES_TO_SURFACE", "1,1,4,3", &
                                  "*CONTACT_AUTOMATIC_NODES_TO_SURFACE", "2,2,4,3", "*NODE"]
    do j = 0, 2
      do i = 0, 2
        lines = [character(len=80) :: lines, node_card(1 + i + 3*j, real([i, j, 0], wp))]
      end do
    end do
    do k = 0, 1
      do j = 0, 1
        do i = 0, 1
          lines = [character(len=80) :: lines, node_card(10 + i + 2*j + 4*k, [0.5_wp, 0.4_wp, 0.5_wp] + &
                                                         real([i, j, k], wp))]
        end do
      end do
    end do
    lines = [character(len=80) :: lines, "*ELEMENT_SHELL"]
    k = 0
    do j = 0, 1
      do i = 0, 1
        k = k + 1
        associate (n => 1 + i + 3*j)
          lines = [character(len=80) :: lines, element_card(k, 1, [n, n + 1, n + 4, n + 3])]
        end associate
      end do
    end do
    lines = [character(len=80) :: lines, "*ELEMENT_SOLID", element_card(5, 2, [10, 11, 13, 12, 14, 15, 17, 16]), &
             "*END"]
    if (.not. read_model("plate.k", lines, model)) return
    call set_up(model, contacts, x, v, mass, force)
    probe = 10
    call evaluate(model, contacts, x, v, mass, force)
    v(3, probe) = -1.0_wp
    x(:, probe) = [0.5_wp, 0.4_wp, 0.07_wp]
    call evaluate(model, contacts, x, v, mass, force)
    on_plate = force(3, probe)
    expected = stiffness_scale*1.0_wp/sqrt(2.0_wp)*0.03_wp
    call check_close(suite, "plate: a node 0.03 into the shell's contact surface gets SLSFAC K A / diagonal x 0.03", &
                     on_plate, expected, rel=1.0e-9_wp)
    ! just outside the plate's edge x = 0 (within the parametric tolerance) the far corners of
    ! the segment have negative weights; made heavy (a lumped mass), they once turned the pair's
    ! mass negative and its spring infinite: the force must not depend on them
    x(:, probe) = [-0.01_wp, 0.5_wp, 0.07_wp]
    call evaluate(model, contacts, x, v, mass, force)
    beside = force(3, probe)
    mass([2, 5]) = 1.0e4_wp
    call evaluate(model, contacts, x, v, mass, force)
    call check(suite, "plate: a node just beside the edge is in contact", beside > 0.0_wp)
    call check_close(suite, "plate: ... with the same force when the corners it lies away from are heavy", &
                     force(3, probe), beside, rel=1.0e-12_wp)
    mass = 1.0_wp
    x(:, probe) = [0.5_wp, 0.4_wp, 0.07_wp]
    call evaluate(model, contacts, x, v, mass, force)
    pair = contacts(1)%passes(1)%pair_segment(1)
    corners = contacts(1)%passes(1)%segments(:, max(1, pair))
    allocate (solid_eroded(size(model%solid_part)), shell_eroded(size(model%shell_part)))
    solid_eroded = .false.
    shell_eroded = .false.
    shell_eroded(4) = .true.                                    ! the far corner
    call remove_eroded_elements(model, contacts, solid_eroded, shell_eroded)
    associate (pass => contacts(1)%passes(1))
      pair = pass%pair_segment(1)
      call check(suite, "plate: the pair survives another shell's erosion (same corners)", &
                 pair > 0 .and. pass%segment_count == 3)
      if (pair > 0) call check(suite, "plate: ... its segment found again by its corners", &
                               all(pass%segments(:, pair) == corners))
    end associate
    call evaluate(model, contacts, x, v, mass, force)
    call check_close(suite, "plate: same force after another shell eroded", force(3, probe), on_plate, rel=1.0e-12_wp)
    call check(suite, "plate: the corner node that lost its only shell is no longer checked", &
               contacts(2)%passes(1)%node_count == 8 .and. .not. any(contacts(2)%passes(1)%nodes == 9))
    shell_eroded(1) = .true.                                    ! the shell under the node
    call remove_eroded_elements(model, contacts, solid_eroded, shell_eroded)
    x(:, probe) = [0.5_wp, 0.4_wp, 0.05_wp]
    call evaluate(model, contacts, x, v, mass, force)
    call check(suite, "plate: the node falls through where the shell eroded", all(force(:, probe) == 0.0_wp))
    call check(suite, "plate: two shells left, nodes 1 and 9 no longer checked", &
               contacts(1)%passes(1)%segment_count == 2 .and. contacts(2)%passes(1)%node_count == 7)
  end subroutine test_plate_shells_erode

  logical function read_model(name, lines, model)
    character(len=*), intent(in) :: name, lines(:)
    type(model_t), intent(out) :: model
    type(error_t), allocatable :: error
    call read_deck_lines(directory//"/"//name, lines, model, error)
    read_model = .not. allocated(error)
    if (allocated(error)) call check(suite, name//" is accepted", .false., error%message)
  end function read_model

  subroutine set_up(model, contacts, x, v, mass, force)
    type(model_t), intent(in) :: model
    type(contact_state_t), allocatable, intent(out) :: contacts(:)
    real(wp), allocatable, intent(out) :: x(:, :), v(:, :), mass(:), force(:, :)
    type(error_t), allocatable :: error
    logical, allocatable :: is_particle(:)
    allocate (is_particle(size(model%node_ids)))
    is_particle = .false.
    call set_up_contacts(model, is_particle, contacts, error)
    call check(suite, "contacts set up", .not. allocated(error))
    x = model%coordinates
    allocate (v(3, size(x, 2)), mass(size(x, 2)), force(3, size(x, 2)))
    v = 0.0_wp
    mass = 1.0_wp
    force = 0.0_wp
  end subroutine set_up

  subroutine evaluate(model, contacts, x, v, mass, force)
    type(model_t), intent(in) :: model
    type(contact_state_t), intent(inout) :: contacts(:)
    real(wp), intent(in) :: x(:, :), v(:, :), mass(:)
    real(wp), intent(inout) :: force(:, :)
    real(wp) :: energy
    call compute_contact_forces(model, contacts, 0.0_wp, step, x, v, mass, force, energy)
  end subroutine evaluate
end program test_contact_erosion
