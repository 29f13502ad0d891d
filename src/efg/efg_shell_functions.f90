!> Coupled meshfree/FE shape functions Psi of a meshfree shell at a point of a background cell
!> (docs/efg_shells.md, "Shape functions"): the two-dimensional counterpart of
!> efg_shape_functions, in the cell's own plane.
!>
!> A point is given by its parametric coordinates in the cell (quadrilateral: [-1, 1]^2 with
!> bilinear functions; triangle, N4 = N3: area coordinates (s, t), Phi = 1 - s - t, s, t). Its
!> position is X = sum_a Phi_a X_a (3D, on the undeformed surface), its planar coordinates
!> y = F^T (X - X_0) (first two components; F = shell_cell_frame of the cell, X_0 its first
!> corner) and its height z = e3 . (X - X_0); particles get planar coordinates and heights the
!> same way. Then
!>   Gamma vertex L of the cell:   Psi_L = Phi_L (bilinear, or linear on a triangle);
!>   interior particle I:          Psi_I = w_I(X) p_I^T alpha,   M alpha = b,
!>     p_I = [1, xi_1, xi_2] on a flat cell, [1, xi_1, xi_2, zeta] on a curved one,
!>     xi_I = (y_I - y) / h, zeta_I = (z_I - z) / h (h the cell's mean edge length),
!>     M = sum_I w_I p_I p_I^T over the particles covering X,
!>     b = sum_V Phi_V p_V over the cell's interior vertices V,
!> so that sum_J Psi_J = 1, sum_J Psi_J y_J = y (linear reproduction) and, on a boundary edge
!> (where every Phi_V vanishes), every particle function is exactly zero. On a curved cell (a
!> particle or corner off its plane by more than shell_flat_tolerance h) also sum_J Psi_J z_J = z:
!> the functions reproduce every field linear in 3D position, sum_J Psi_J X_J = X, so a rigid
!> rotation about an in-plane axis gives no membrane strain (without the height term it did, in
!> proportion to the slope of the fitted surface off the cell's plane: membrane locking of curved
!> parts). Flat cells keep the three planar terms and their functions bit for bit.
!>
!> Kernel weights are measured in each particle's own frame from 3D positions (efg_shell_supports),
!> so they do not depend on the evaluation cell. The solve is the solids' rank-revealing one:
!> column-pivoted QR of the rows sqrt(w_I) p_I^T (LAPACK dgeqp3), a triangular solve with
!> R11^T and one product with Q (dormqr); the residual |sum_I Psi_I p_I - b| is returned.
module efg_shell_functions
  use kinds, only: wp
  use integer_lists, only: sorted_position, sort_short_list
  use efg_kernel, only: kernel_weight
  use efg_shell_part, only: shell_cell_frame
  use efg_shell_supports, only: shell_supports_t, corner_count
  use efg_neighbour_search, only: particle_grid_t, find_support_candidates
  implicit none
  private

  public :: shell_cell_context_t, prepare_shell_cell, evaluate_shell_functions, corner_functions

  !> Columns of R whose diagonal falls below this fraction of |R_11| are taken as dependent.
  real(wp), parameter, public :: shell_rank_tolerance = 1.0e-10_wp
  !> A cell whose candidate particles and corners all lie within this fraction of h of its plane
  !> is flat: its basis keeps the three planar terms (round-off of a flat part turned out of the
  !> global axes is far below it).
  real(wp), parameter, public :: shell_flat_tolerance = 1.0e-8_wp

  !> What the functions of one background cell need. Local nodes `nodes(1:node_count)` are the
  !> cell's Gamma vertices and the particles whose supports touch the cell, in ascending model
  !> node order; evaluations return one value per local node.
  type :: shell_cell_context_t
    integer :: corners = 4                            !< 4, or 3 for a triangle
    real(wp) :: frame(3, 3) = 0.0_wp                  !< shell_cell_frame of the undeformed corners
    real(wp) :: origin(3) = 0.0_wp                    !< X_0, the first corner
    real(wp) :: positions(3, 4) = 0.0_wp              !< corners (3D)
    real(wp) :: planar(2, 4) = 0.0_wp                 !< corners in the cell's plane
    logical :: corner_is_particle(4) = .false.
    integer :: corner_local(4) = 0                    !< local node of each corner
    real(wp) :: scale_length = 1.0_wp                 !< h
    integer :: kernel = 0
    integer :: node_count = 0
    integer, allocatable :: nodes(:)                  !< model node indices, ascending
    integer :: particle_count = 0
    integer, allocatable :: particle_local(:)         !< local node of each candidate particle
    real(wp), allocatable :: particle_position(:, :)  !< (3, candidates)
    real(wp), allocatable :: particle_planar(:, :)    !< (2, candidates)
    real(wp), allocatable :: particle_height(:)       !< (candidates) e3 . (X_I - X_0), off the cell's plane
    real(wp) :: corner_height(4) = 0.0_wp             !< e3 . (X_a - X_0) of the corners (a warped cell's)
    !> the basis has the fourth term zeta (height off the cell's plane): some particle or corner
    !> lies off the plane by more than shell_flat_tolerance h (a curved or warped part)
    logical :: curved = .false.
    real(wp), allocatable :: particle_frame(:, :, :)  !< (3, 3, candidates)
    real(wp), allocatable :: particle_radius(:, :)    !< (3, candidates)
    integer, allocatable :: candidates(:)             !< particle numbers (search scratch)
  end type shell_cell_context_t

  interface
    !> LAPACK: QR factorization with column pivoting, A P = Q R.
    subroutine dgeqp3(m, n, a, lda, jpvt, tau, work, lwork, info)
      import :: wp
      integer, intent(in) :: m, n, lda, lwork
      real(wp), intent(inout) :: a(lda, *)
      integer, intent(inout) :: jpvt(*)
      real(wp), intent(out) :: tau(*), work(*)
      integer, intent(out) :: info
    end subroutine dgeqp3

    !> LAPACK: multiply by the orthogonal factor Q of a QR factorization.
    subroutine dormqr(side, trans, m, n, k, a, lda, tau, c, ldc, work, lwork, info)
      import :: wp
      character(len=1), intent(in) :: side, trans
      integer, intent(in) :: m, n, k, lda, ldc, lwork
      real(wp), intent(in) :: a(lda, *), tau(*)
      real(wp), intent(inout) :: c(ldc, *)
      real(wp), intent(out) :: work(*)
      integer, intent(out) :: info
    end subroutine dormqr
  end interface

contains

  !> FE functions of the cell's corners at `parametric`: bilinear on a quadrilateral, linear
  !> (area coordinates) on a triangle, whose fourth value is 0.
  pure function corner_functions(corners, parametric) result(phi)
    integer, intent(in) :: corners
    real(wp), intent(in) :: parametric(2)
    real(wp) :: phi(4)
    associate (s => parametric(1), t => parametric(2))
      if (corners == 3) then
        phi = [1.0_wp - s - t, s, t, 0.0_wp]
        ! on the edge opposite corner 1, s + t = 1 holds only to round-off: snap, so that the
        ! functions of that edge's far vertex (and with it b) vanish exactly there
        if (abs(phi(1)) <= 4.0_wp*epsilon(1.0_wp)) phi(1) = 0.0_wp
      else
        phi = 0.25_wp*[(1.0_wp - s)*(1.0_wp - t), (1.0_wp + s)*(1.0_wp - t), &
                       (1.0_wp + s)*(1.0_wp + t), (1.0_wp - s)*(1.0_wp + t)]
      end if
    end associate
  end function corner_functions

  !> Gather the corners, their classes and the candidate particles of model shell `cell`.
  subroutine prepare_shell_cell(supports, grid, coordinates, cell_nodes, context)
    type(shell_supports_t), intent(in) :: supports
    type(particle_grid_t), intent(in) :: grid
    real(wp), intent(in) :: coordinates(:, :)
    integer, intent(in) :: cell_nodes(4)
    type(shell_cell_context_t), intent(inout) :: context
    integer :: gamma_corners(4), gamma_count, a, k, candidate_count, next_gamma, next_particle, particle
    real(wp) :: perimeter

    context%kernel = supports%kernel
    context%corners = corner_count(cell_nodes)
    context%positions = coordinates(:, cell_nodes)
    context%frame = shell_cell_frame(context%positions)
    context%origin = context%positions(:, 1)
    do a = 1, 4
      context%planar(:, a) = planar_coordinates(context, context%positions(:, a))
      context%corner_is_particle(a) = supports%particle_of_node(cell_nodes(a)) > 0
    end do
    perimeter = 0.0_wp
    do a = 1, context%corners
      perimeter = perimeter + norm2(context%planar(:, modulo(a, context%corners) + 1) - context%planar(:, a))
    end do
    context%scale_length = max(perimeter/context%corners, tiny(1.0_wp))

    call find_support_candidates(grid, supports%particle_coordinates, supports%search_radius, &
                                 minval(context%positions, dim=2), maxval(context%positions, dim=2), &
                                 context%candidates, candidate_count)
    context%particle_count = candidate_count
    call ensure_size(context, candidate_count)
    do a = 1, 4
      context%corner_height(a) = dot_product(context%positions(:, a) - context%origin, context%frame(:, 3))
    end do
    do k = 1, candidate_count
      particle = context%candidates(k)
      context%particle_position(:, k) = supports%particle_coordinates(:, particle)
      context%particle_planar(:, k) = planar_coordinates(context, supports%particle_coordinates(:, particle))
      context%particle_height(k) = dot_product(supports%particle_coordinates(:, particle) - context%origin, &
                                               context%frame(:, 3))
      context%particle_frame(:, :, k) = supports%particle_frame(:, :, particle)
      context%particle_radius(:, k) = supports%particle_radius(:, particle)
    end do

    gamma_count = 0
    do a = 1, context%corners
      if (context%corner_is_particle(a)) cycle
      if (any(gamma_corners(1:gamma_count) == cell_nodes(a))) cycle
      gamma_count = gamma_count + 1
      gamma_corners(gamma_count) = cell_nodes(a)
    end do
    call sort_short_list(gamma_corners(1:gamma_count))
    context%curved = any(abs(context%corner_height(1:context%corners)) > shell_flat_tolerance*context%scale_length) &
                     .or. any(abs(context%particle_height(1:candidate_count)) > shell_flat_tolerance*context%scale_length)

    ! merge the two ascending lists (particle numbers ascend with their node indices)
    context%node_count = gamma_count + candidate_count
    next_gamma = 1
    next_particle = 1
    do k = 1, context%node_count
      if (next_particle > candidate_count) then
        context%nodes(k) = gamma_corners(next_gamma)
        next_gamma = next_gamma + 1
      else if (next_gamma > gamma_count) then
        context%nodes(k) = supports%particles(context%candidates(next_particle))
        context%particle_local(next_particle) = k
        next_particle = next_particle + 1
      else if (gamma_corners(next_gamma) < supports%particles(context%candidates(next_particle))) then
        context%nodes(k) = gamma_corners(next_gamma)
        next_gamma = next_gamma + 1
      else
        context%nodes(k) = supports%particles(context%candidates(next_particle))
        context%particle_local(next_particle) = k
        next_particle = next_particle + 1
      end if
    end do
    do a = 1, 4
      context%corner_local(a) = sorted_position(context%nodes(1:context%node_count), cell_nodes(a))
    end do
  end subroutine prepare_shell_cell

  !> Coordinates of `position` in the cell's plane (projection on e1, e2 about X_0).
  pure function planar_coordinates(context, position) result(planar)
    type(shell_cell_context_t), intent(in) :: context
    real(wp), intent(in) :: position(3)
    real(wp) :: planar(2)
    planar = [dot_product(position - context%origin, context%frame(:, 1)), &
              dot_product(position - context%origin, context%frame(:, 2))]
  end function planar_coordinates

  !> Coupled functions at `parametric`: values(k) = Psi of local node k; `planar` the point's
  !> coordinates in the cell's plane. `rank` is the rank of M (0 where b = 0: no MLS part) and
  !> `residual` the largest component of |sum_I Psi_I p(xi_I) - b| (round-off when the support
  !> rule holds).
  subroutine evaluate_shell_functions(context, parametric, planar, values, rank, residual)
    type(shell_cell_context_t), intent(in) :: context
    real(wp), intent(in) :: parametric(2)
    real(wp), intent(out) :: planar(2)
    real(wp), intent(out) :: values(:)
    integer, intent(out) :: rank
    real(wp), intent(out) :: residual
    real(wp) :: phi(4), position(3), moment(4), reproduced(4), tau(4), work(256), local(3), inverse_h, height
    real(wp) :: weight(context%particle_count), shifted(4, context%particle_count)
    real(wp) :: rows(max(context%particle_count, 1), 4), projected(max(context%particle_count, 4))
    integer :: covering(context%particle_count), covering_count, pivot(4), info, a, i, k, n, terms
    real(wp), parameter :: origin(3) = 0.0_wp

    inverse_h = 1.0_wp/context%scale_length
    phi = corner_functions(context%corners, parametric)
    position = matmul(context%positions, phi)
    planar = matmul(context%planar, phi)
    height = dot_product(context%corner_height, phi)
    terms = merge(4, 3, context%curved)
    n = context%node_count
    values(1:n) = 0.0_wp
    rank = 0
    residual = 0.0_wp

    ! Gamma vertices keep their FE functions; b from the interior vertices
    moment = 0.0_wp
    do a = 1, context%corners
      if (context%corner_is_particle(a)) then
        moment = moment + phi(a)*[1.0_wp, (context%planar(:, a) - planar)*inverse_h, &
                                  (context%corner_height(a) - height)*inverse_h]
      else
        values(context%corner_local(a)) = values(context%corner_local(a)) + phi(a)
      end if
    end do
    ! b = 0 (a boundary edge, or a cell without interior vertices): every particle function is
    ! exactly zero here
    if (all(moment(1:terms) == 0.0_wp)) return

    covering_count = 0
    do i = 1, context%particle_count
      ! the distance in the particle's frame: (t1, t2, n) components
      local = matmul(position - context%particle_position(:, i), context%particle_frame(:, :, i))
      weight(i) = kernel_weight(context%kernel, origin, context%particle_radius(:, i), local)
      if (weight(i) <= 0.0_wp) cycle
      covering_count = covering_count + 1
      covering(covering_count) = i
      shifted(:, i) = [1.0_wp, (context%particle_planar(:, i) - planar)*inverse_h, &
                       (context%particle_height(i) - height)*inverse_h]
      rows(covering_count, 1:terms) = sqrt(weight(i))*shifted(1:terms, i)
    end do
    if (covering_count == 0) then
      ! only possible when the support rule is broken: report b as the residual
      residual = maxval(abs(moment(1:terms)))
      return
    end if

    pivot = 0
    call dgeqp3(covering_count, terms, rows, size(rows, 1), pivot, tau, work, size(work), info)
    do k = 1, min(covering_count, terms)
      if (abs(rows(k, k)) <= shell_rank_tolerance*abs(rows(1, 1))) exit
      rank = k
    end do
    ! Psi_I = sqrt(w_I) (A alpha)_I, A alpha = Q [y; 0], R11^T y = (P^T b)(1:rank)
    projected = 0.0_wp
    do i = 1, rank
      projected(i) = (moment(pivot(i)) - dot_product(rows(1:i - 1, i), projected(1:i - 1)))/rows(i, i)
    end do
    call dormqr("L", "N", covering_count, 1, min(covering_count, terms), rows, size(rows, 1), tau, projected, &
                size(projected), work, size(work), info)
    reproduced = 0.0_wp
    do i = 1, covering_count
      associate (particle => covering(i))
        values(context%particle_local(particle)) = sqrt(weight(particle))*projected(i)
        reproduced(1:terms) = reproduced(1:terms) + values(context%particle_local(particle))*shifted(1:terms, particle)
      end associate
    end do
    residual = maxval(abs(reproduced(1:terms) - moment(1:terms)))
  end subroutine evaluate_shell_functions



  !> Room for `count` candidate particles (and count + 4 local nodes); arrays only grow.
  subroutine ensure_size(context, count)
    type(shell_cell_context_t), intent(inout) :: context
    integer, intent(in) :: count
    integer :: capacity

    if (allocated(context%particle_local)) then
      if (size(context%particle_local) >= count) return
      deallocate (context%particle_local, context%particle_position, context%particle_planar, &
                  context%particle_height, context%particle_frame, context%particle_radius, context%nodes)
    end if
    capacity = max(count, 64)
    allocate (context%particle_local(capacity), context%particle_position(3, capacity), &
              context%particle_planar(2, capacity), context%particle_height(capacity), &
              context%particle_frame(3, 3, capacity), &
              context%particle_radius(3, capacity), context%nodes(capacity + 4))
  end subroutine ensure_size
end module efg_shell_functions
