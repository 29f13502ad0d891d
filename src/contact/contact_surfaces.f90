!> Contact surfaces made of solid element faces and shells: the exterior faces of a part (faces
!> of its elements that no other element of the part shares), the shells of a part (each shell
!> is a two-sided segment), the element that owns a given segment (for its stiffness and
!> orientation; owners are solid indices, or minus the shell index), and the geometry contact
!> needs of one segment (area, owner volume).
module contact_surfaces
  use kinds, only: wp
  use integer_lists, only: reserve_integers, reserve_integer_columns
  implicit none
  private

  public :: append_exterior_faces, append_part_shells, find_segment_owners, find_shell_owners, surface_node_list
  public :: hexahedron_volume, segment_area

  !> The six faces of a hexahedron, numbered so that the right-hand rule over 1-2-3-4 points
  !> out of an element of positive volume (LS-DYNA's node order).
  integer, parameter :: hex_faces(4, 6) = reshape([1, 4, 3, 2, 5, 6, 7, 8, 1, 2, 6, 5, &
                                                   2, 3, 7, 6, 3, 4, 8, 7, 1, 5, 8, 4], [4, 6])

contains

  !> Append to `segments` / `owners` (`count` used entries; both grow) the exterior faces of the
  !> solids of part `part`. Faces of degenerate elements with three distinct corners become
  !> triangles (N4 = N3); faces with fewer are left out. Faces are matched by their sorted
  !> corners, grouped by the smallest corner, so the cost is linear in the part size.
  subroutine append_exterior_faces(solid_nodes, solid_part, part, node_count, segments, owners, count)
    integer, intent(in) :: solid_nodes(:, :), solid_part(:), part, node_count
    integer, allocatable, intent(inout) :: segments(:, :), owners(:)
    integer, intent(inout) :: count
    integer, allocatable :: faces(:, :), keys(:, :), face_owner(:), first(:), members(:)
    logical, allocatable :: shared(:)
    integer :: element, f, k, face_count, n, a, b, corner(4), distinct
    face_count = 0
    allocate (faces(4, 6*count_part(solid_part, part)), keys(4, 6*count_part(solid_part, part)), &
              face_owner(6*count_part(solid_part, part)))
    do element = 1, size(solid_part)
      if (solid_part(element) /= part) cycle
      do f = 1, 6
        corner = solid_nodes(hex_faces(:, f), element)
        ! collapse repeated corners, keeping the cyclic order
        distinct = 0
        do k = 1, 4
          if (distinct > 0) then
            if (any(corner(1:distinct) == corner(k))) cycle
          end if
          distinct = distinct + 1
          corner(distinct) = corner(k)
        end do
        if (distinct < 3) cycle
        if (distinct == 3) corner(4) = corner(3)
        face_count = face_count + 1
        faces(:, face_count) = corner
        keys(:, face_count) = sorted4(corner)
        face_owner(face_count) = element
      end do
    end do
    ! group the faces by their smallest corner (counting sort), compare within each group
    allocate (first(node_count + 1), members(face_count), shared(face_count))
    first = 0
    do f = 1, face_count
      first(keys(1, f) + 1) = first(keys(1, f) + 1) + 1
    end do
    first(1) = 1
    do n = 1, node_count
      first(n + 1) = first(n + 1) + first(n)
    end do
    do f = 1, face_count
      n = keys(1, f)
      members(first(n)) = f
      first(n) = first(n) + 1
    end do
    do n = node_count, 1, -1
      first(n + 1) = first(n)
    end do
    first(1) = 1
    shared = .false.
    do n = 1, node_count
      do a = first(n), first(n + 1) - 1
        do b = a + 1, first(n + 1) - 1
          if (all(keys(:, members(a)) == keys(:, members(b)))) then
            shared(members(a)) = .true.
            shared(members(b)) = .true.
          end if
        end do
      end do
    end do
    call reserve_integer_columns(segments, 4, count, count + count_false(shared))
    call reserve_integers(owners, count, count + count_false(shared))
    do f = 1, face_count
      if (shared(f)) cycle
      count = count + 1
      segments(:, count) = faces(:, f)
      owners(count) = face_owner(f)
    end do
  end subroutine append_exterior_faces

  !> Append the shells of part `part` as segments, owners minus the shell index.
  subroutine append_part_shells(shell_nodes, shell_part, part, segments, owners, count)
    integer, intent(in) :: shell_nodes(:, :), shell_part(:), part
    integer, allocatable, intent(inout) :: segments(:, :), owners(:)
    integer, intent(inout) :: count
    integer :: shell, needed
    needed = count + count_part(shell_part, part)
    call reserve_integer_columns(segments, 4, count, needed)
    call reserve_integers(owners, count, needed)
    do shell = 1, size(shell_part)
      if (shell_part(shell) /= part) cycle
      count = count + 1
      segments(:, count) = shell_nodes(:, shell)
      owners(count) = -shell
    end do
  end subroutine append_part_shells

  !> Segments of a segment set that no solid owns (owner 0): the shell with the same corners,
  !> as minus its index (0 stays when there is none). Shells are grouped by their smallest
  !> node, so the cost is linear.
  subroutine find_shell_owners(shell_nodes, node_count, segments, owners)
    integer, intent(in) :: shell_nodes(:, :), node_count, segments(:, :)
    integer, intent(inout) :: owners(:)
    integer, allocatable :: first(:), members(:)
    integer :: shell, n, s, k, key(4)
    allocate (first(node_count + 1), members(size(shell_nodes, 2)))
    first = 0
    do shell = 1, size(shell_nodes, 2)
      n = minval(shell_nodes(:, shell))
      first(n + 1) = first(n + 1) + 1
    end do
    first(1) = 1
    do n = 1, node_count
      first(n + 1) = first(n + 1) + first(n)
    end do
    do shell = 1, size(shell_nodes, 2)
      n = minval(shell_nodes(:, shell))
      members(first(n)) = shell
      first(n) = first(n) + 1
    end do
    do n = node_count, 1, -1
      first(n + 1) = first(n)
    end do
    first(1) = 1
    do s = 1, size(segments, 2)
      if (owners(s) /= 0) cycle
      key = sorted4(segments(:, s))
      n = key(1)
      do k = first(n), first(n + 1) - 1
        if (all(sorted4(shell_nodes(:, members(k))) == key)) then
          owners(s) = -members(k)
          exit
        end if
      end do
    end do
  end subroutine find_shell_owners

  pure integer function count_part(solid_part, part)
    integer, intent(in) :: solid_part(:), part
    count_part = count(solid_part == part)
  end function count_part

  pure integer function count_false(flags)
    logical, intent(in) :: flags(:)
    count_false = count(.not. flags)
  end function count_false

  pure function sorted4(values) result(sorted)
    integer, intent(in) :: values(4)
    integer :: sorted(4), i, j, swap
    sorted = values
    do i = 2, 4
      j = i
      do while (j > 1)
        if (sorted(j - 1) <= sorted(j)) exit
        swap = sorted(j)
        sorted(j) = sorted(j - 1)
        sorted(j - 1) = swap
        j = j - 1
      end do
    end do
  end function sorted4

  !> For each segment of a segment set: the solid whose face it is (0 when none), and the
  !> segment turned to face out of that solid (LS-DYNA reorients segments of solids).
  subroutine find_segment_owners(solid_nodes, node_count, coordinates, segments, owners)
    integer, intent(in) :: solid_nodes(:, :), node_count
    real(wp), intent(in) :: coordinates(:, :)
    integer, intent(inout) :: segments(:, :)
    integer, intent(out) :: owners(:)
    integer, allocatable :: first(:), elements(:)
    integer :: element, k, n, s, j, candidate
    real(wp) :: centre(3), face_centre(3), normal(3)
    allocate (first(node_count + 1), elements(8*size(solid_nodes, 2)))
    first = 0
    do element = 1, size(solid_nodes, 2)
      do k = 1, 8
        if (k > 1) then
          if (any(solid_nodes(1:k - 1, element) == solid_nodes(k, element))) cycle
        end if
        first(solid_nodes(k, element) + 1) = first(solid_nodes(k, element) + 1) + 1
      end do
    end do
    first(1) = 1
    do n = 1, node_count
      first(n + 1) = first(n + 1) + first(n)
    end do
    do element = 1, size(solid_nodes, 2)
      do k = 1, 8
        if (k > 1) then
          if (any(solid_nodes(1:k - 1, element) == solid_nodes(k, element))) cycle
        end if
        n = solid_nodes(k, element)
        elements(first(n)) = element
        first(n) = first(n) + 1
      end do
    end do
    do n = node_count, 1, -1
      first(n + 1) = first(n)
    end do
    first(1) = 1
    do s = 1, size(segments, 2)
      owners(s) = 0
      n = segments(1, s)
      do j = first(n), first(n + 1) - 1
        candidate = elements(j)
        if (all([(any(solid_nodes(:, candidate) == segments(k, s)), k=2, 4)])) then
          owners(s) = candidate
          exit
        end if
      end do
      if (owners(s) == 0) cycle
      centre = sum(coordinates(:, solid_nodes(:, owners(s))), dim=2)/8.0_wp
      face_centre = sum(coordinates(:, segments(:, s)), dim=2)/4.0_wp
      normal = cross(coordinates(:, segments(3, s)) - coordinates(:, segments(1, s)), &
                     coordinates(:, segments(4, s)) - coordinates(:, segments(2, s)))
      if (dot_product(normal, face_centre - centre) < 0.0_wp) then
        if (segments(3, s) == segments(4, s)) then
          segments(:, s) = [segments(1, s), segments(3, s), segments(2, s), segments(2, s)]
        else
          segments(:, s) = [segments(1, s), segments(4, s), segments(3, s), segments(2, s)]
        end if
      end if
    end do
  end subroutine find_segment_owners

  !> The distinct nodes of `segments`, ascending (nodes flagged in `exclude` are
  !> left out: interior meshfree particles).
  subroutine surface_node_list(segments, exclude, nodes)
    integer, intent(in) :: segments(:, :)
    logical, intent(in) :: exclude(:)
    integer, allocatable, intent(out) :: nodes(:)
    logical, allocatable :: used(:)
    integer :: n
    allocate (used(size(exclude)))
    used = .false.
    do n = 1, size(segments, 2)
      used(segments(:, n)) = .true.
    end do
    used = used .and. .not. exclude
    nodes = pack([(n, n=1, size(exclude))], used)
  end subroutine surface_node_list

  !> Volume of a hexahedron (divergence theorem over its six faces, each face's area vector
  !> from its diagonals: exact for flat faces).
  pure real(wp) function hexahedron_volume(x)
    real(wp), intent(in) :: x(3, 8)
    integer :: f
    real(wp) :: area(3), centre(3)
    hexahedron_volume = 0.0_wp
    do f = 1, 6
      area = 0.5_wp*cross(x(:, hex_faces(3, f)) - x(:, hex_faces(1, f)), x(:, hex_faces(4, f)) - x(:, hex_faces(2, f)))
      centre = 0.25_wp*sum(x(:, hex_faces(:, f)), dim=2)
      hexahedron_volume = hexahedron_volume + dot_product(area, centre)/3.0_wp
    end do
  end function hexahedron_volume

  !> Area of a segment (half the cross product of its diagonals; exact for a triangle and a
  !> flat quadrilateral).
  pure real(wp) function segment_area(x)
    real(wp), intent(in) :: x(3, 4)
    segment_area = 0.5_wp*norm2(cross(x(:, 3) - x(:, 1), x(:, 4) - x(:, 2)))
  end function segment_area

  pure function cross(a, b) result(c)
    real(wp), intent(in) :: a(3), b(3)
    real(wp) :: c(3)
    c = [a(2)*b(3) - a(3)*b(2), a(3)*b(1) - a(1)*b(3), a(1)*b(2) - a(2)*b(1)]
  end function cross
end module contact_surfaces
