!> Unit tests of degenerate solids (tetrahedra, wedges, pyramids written as hexahedra with
!> repeated nodes): the order that puts a tetrahedron in its linear form, the corners' masses,
!> and which elements of a mesh are exposed (solid_exposure: only those at its corners and
!> edges, as for hexahedra).
program test_degenerate_solids
  use kinds, only: wp, block_size
  use model, only: model_t, formulation_fe
  use material_laws, only: law_elastic
  use hex8_geometry, only: tetrahedron_corner_order, distinct_corner_count
  use solid_exposure, only: exposed_elements
  use solid_block, only: solid_block_t, build_solid_blocks, solid_block_corner_masses
  use testing, only: test_suite_t, check, finish_suite
  implicit none

  type(test_suite_t) :: suite
  ! the six tetrahedra of a cube (corners 1-8, LS-DYNA's order) around its diagonal 1-7
  integer, parameter :: kuhn(4, 6) = reshape([1, 2, 3, 7, 1, 3, 4, 7, 1, 4, 8, 7, 1, 8, 5, 7, 1, 5, 6, 7, &
                                              1, 6, 2, 7], [4, 6])

  suite%name = "degenerate_solids"
  call test_tetrahedron_order()
  call test_masses()
  call test_exposure_of_a_tetrahedral_mesh()
  call test_exposure_of_a_pyramid_mesh()
  call finish_suite(suite)

contains

  !> Both forms of a tetrahedron, and a mirrored one, give a b c c d d d d with a positive
  !> volume; a wedge keeps its order.
  subroutine test_tetrahedron_order()
    real(wp) :: x(3, 8), a(3), b(3), c(3)
    integer :: order(8), nodes(8)
    x = 0.0_wp
    x(:, 2) = [1.0_wp, 0.0_wp, 0.0_wp]
    x(:, 3) = [0.0_wp, 1.0_wp, 0.0_wp]
    x(:, 4:8) = spread([0.2_wp, 0.3_wp, 1.0_wp], 2, 5)
    nodes = [11, 12, 13, 14, 14, 14, 14, 14]
    call tetrahedron_corner_order(nodes, x, order)
    call check(suite, "order: N1 N2 N3 N4 N4 N4 N4 N4 becomes N1 N2 N3 N3 N4 N4 N4 N4", &
               all(nodes(order) == [11, 12, 13, 13, 14, 14, 14, 14]))
    ! mirrored: N2 and N3 swapped in the deck
    x(:, [2, 3]) = x(:, [3, 2])
    call tetrahedron_corner_order(nodes, x, order)
    a = x(:, order(2)) - x(:, order(1))
    b = x(:, order(3)) - x(:, order(1))
    c = x(:, order(5)) - x(:, order(1))
    call check(suite, "order: a mirrored tetrahedron is turned to a positive volume", &
               dot_product(c, [a(2)*b(3) - a(3)*b(2), a(3)*b(1) - a(1)*b(3), a(1)*b(2) - a(2)*b(1)]) > 0.0_wp &
               .and. all(nodes(order) == [11, 13, 12, 12, 14, 14, 14, 14]))
    nodes = [1, 2, 3, 3, 4, 5, 6, 6]
    call tetrahedron_corner_order(nodes, x, order)
    call check(suite, "order: a wedge keeps its order", all(order == [1, 2, 3, 4, 5, 6, 7, 8]) .and. &
               distinct_corner_count(nodes) == 6)
  end subroutine test_tetrahedron_order

  !> Unit cube split into six tetrahedra (each rho / 24 at each node) and into two wedges (each
  !> rho / 12 at each node).
  subroutine test_masses()
    type(model_t) :: model
    type(solid_block_t), allocatable :: blocks(:)
    real(wp) :: corner_mass(block_size, 8), node_mass(8)
    integer :: tet, lane, corner
    call cube_model(model, 6)
    do tet = 1, 6
      model%solid_nodes(:, tet) = kuhn([1, 2, 3, 3, 4, 4, 4, 4], tet)
    end do
    call build_solid_blocks(model, blocks)
    call solid_block_corner_masses(blocks(1), corner_mass)
    node_mass = 0.0_wp
    do lane = 1, blocks(1)%element_count
      do corner = 1, 8
        node_mass(blocks(1)%nodes(lane, corner)) = node_mass(blocks(1)%nodes(lane, corner)) + corner_mass(lane, corner)
      end do
    end do
    call check(suite, "masses: rho V / 4 at each node of six tetrahedra", &
               abs(node_mass(1)/(6.0_wp*model%materials(1)%density/24.0_wp) - 1.0_wp) < 1.0e-13_wp .and. &
               abs(node_mass(2)/(2.0_wp*model%materials(1)%density/24.0_wp) - 1.0_wp) < 1.0e-13_wp .and. &
               abs(sum(node_mass)/model%materials(1)%density - 1.0_wp) < 1.0e-13_wp)
    call cube_model(model, 2)
    model%solid_nodes(:, 1) = [1, 2, 3, 3, 5, 6, 7, 7]
    model%solid_nodes(:, 2) = [1, 3, 4, 4, 5, 7, 8, 8]
    call build_solid_blocks(model, blocks)
    call solid_block_corner_masses(blocks(1), corner_mass)
    node_mass = 0.0_wp
    do lane = 1, 2
      do corner = 1, 8
        node_mass(blocks(1)%nodes(lane, corner)) = node_mass(blocks(1)%nodes(lane, corner)) + corner_mass(lane, corner)
      end do
    end do
    call check(suite, "masses: rho V / 6 at each node of two right wedges", &
               all(abs(node_mass([2, 4, 6, 8])/(model%materials(1)%density/12.0_wp) - 1.0_wp) < 1.0e-13_wp) .and. &
               all(abs(node_mass([1, 3, 5, 7])/(model%materials(1)%density/6.0_wp) - 1.0_wp) < 1.0e-13_wp))
  end subroutine test_masses

  !> 3 x 3 x 3 unit cubes, each split into six tetrahedra: the tetrahedra fill the space
  !> around every node (4 pi inside, 2 pi on a flat face of the box, pi on an edge, pi / 2 at a
  !> corner), so exactly those with a node on an edge or at a corner of the box are exposed (as
  !> for hexahedra; before, every degenerate element was).
  subroutine test_exposure_of_a_tetrahedral_mesh()
    real(wp) :: coordinates(3, 64)
    integer :: connectivity(8, 162), cube(8), i, j, k, tet, solid, outer_faces(162), corner
    logical, allocatable :: exposed(:)
    do k = 0, 3
      do j = 0, 3
        do i = 0, 3
          coordinates(:, 1 + i + 4*j + 16*k) = [real(i, wp), real(j, wp), real(k, wp)]
        end do
      end do
    end do
    solid = 0
    do k = 0, 2
      do j = 0, 2
        do i = 0, 2
          cube = 1 + [i + 4*j + 16*k, i + 1 + 4*j + 16*k, i + 1 + 4*(j + 1) + 16*k, i + 4*(j + 1) + 16*k, &
                      i + 4*j + 16*(k + 1), i + 1 + 4*j + 16*(k + 1), i + 1 + 4*(j + 1) + 16*(k + 1), &
                      i + 4*(j + 1) + 16*(k + 1)]
          do tet = 1, 6
            solid = solid + 1
            connectivity(:, solid) = cube(kuhn([1, 2, 3, 3, 4, 4, 4, 4], tet))
            ! exposed: a node with two or three coordinates on the box's faces (0 or 3)
            outer_faces(solid) = maxval([(count(coordinates(:, connectivity(corner, solid)) == 0.0_wp .or. &
                                                coordinates(:, connectivity(corner, solid)) == 3.0_wp), corner=1, 8)])
          end do
        end do
      end do
    end do
    exposed = exposed_elements(coordinates, connectivity)
    call check(suite, "exposure: tetrahedra inside and on the box's faces are not exposed", &
               .not. any(exposed .and. outer_faces < 2) .and. count(outer_faces < 2) == 60)
    call check(suite, "exposure: those with a node on an edge or at a corner are", all(exposed .or. outer_faces < 2))
  end subroutine test_exposure_of_a_tetrahedral_mesh

  !> 3 x 3 x 3 unit cubes, each split into six pyramids on its faces with its centre as their
  !> apex: the apex of six pyramids is filled (4 pi, two trihedra each), so the pyramids of
  !> the centre cube are not exposed (all their nodes are inside), while every pyramid with a
  !> node on an edge or at a corner of the box is.
  subroutine test_exposure_of_a_pyramid_mesh()
    integer, parameter :: faces(4, 6) = reshape([1, 4, 3, 2, 5, 6, 7, 8, 1, 2, 6, 5, 2, 3, 7, 6, 3, 4, 8, 7, &
                                                 4, 1, 5, 8], [4, 6])
    real(wp) :: coordinates(3, 64 + 27)
    integer :: connectivity(8, 162), cube(8), i, j, k, face, solid, corner, on_box(162), inside(162)
    logical, allocatable :: exposed(:)
    do k = 0, 3
      do j = 0, 3
        do i = 0, 3
          coordinates(:, 1 + i + 4*j + 16*k) = [real(i, wp), real(j, wp), real(k, wp)]
        end do
      end do
    end do
    solid = 0
    do k = 0, 2
      do j = 0, 2
        do i = 0, 2
          cube = 1 + [i + 4*j + 16*k, i + 1 + 4*j + 16*k, i + 1 + 4*(j + 1) + 16*k, i + 4*(j + 1) + 16*k, &
                      i + 4*j + 16*(k + 1), i + 1 + 4*j + 16*(k + 1), i + 1 + 4*(j + 1) + 16*(k + 1), &
                      i + 4*(j + 1) + 16*(k + 1)]
          coordinates(:, 65 + i + 3*j + 9*k) = [i + 0.5_wp, j + 0.5_wp, k + 0.5_wp]
          do face = 1, 6
            solid = solid + 1
            ! the base in order around the face (the solid angles do not depend on its sense)
            connectivity(:, solid) = [cube(faces(:, face)), (65 + i + 3*j + 9*k, corner=1, 4)]
            on_box(solid) = maxval([(count(coordinates(:, connectivity(corner, solid)) == 0.0_wp .or. &
                                           coordinates(:, connectivity(corner, solid)) == 3.0_wp), corner=1, 4)])
            inside(solid) = merge(1, 0, i == 1 .and. j == 1 .and. k == 1)
          end do
        end do
      end do
    end do
    exposed = exposed_elements(coordinates, connectivity)
    call check(suite, "exposure: the pyramids of the centre cube are not exposed", &
               .not. any(exposed .and. inside == 1))
    call check(suite, "exposure: pyramids with a node on an edge or at a corner of the box are", &
               all(exposed .or. on_box < 2))
    call check(suite, "exposure: pyramids whose nodes are inside or on the box's faces are not", &
               .not. any(exposed .and. on_box < 2))
  end subroutine test_exposure_of_a_pyramid_mesh

  !> A unit cube's 8 nodes, `count` solids of one elastic part (connectivity left to the caller).
  subroutine cube_model(model, count)
    type(model_t), intent(out) :: model
    integer, intent(in) :: count
    integer :: k
    model%coordinates = reshape([0.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 1.0_wp, 0.0_wp, &
                                 0.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 1.0_wp, 0.0_wp, 1.0_wp, &
                                 1.0_wp, 1.0_wp, 1.0_wp, 0.0_wp, 1.0_wp, 1.0_wp], [3, 8])
    allocate (model%solid_nodes(8, count), model%solid_part(count), model%solid_ids(count))
    model%solid_part = 1
    model%solid_ids = [(k, k=1, count)]
    allocate (model%parts(1), model%sections(1), model%materials(1))
    model%materials(1)%law = law_elastic
    model%materials(1)%density = 7.85e-9_wp
    model%materials(1)%youngs_modulus = 210000.0_wp
    model%materials(1)%poissons_ratio = 0.3_wp
    model%sections(1)%element_formulation = 1
    model%parts(1)%section = 1
    model%parts(1)%material = 1
    model%parts(1)%formulation = formulation_fe
  end subroutine cube_model
end program test_degenerate_solids
