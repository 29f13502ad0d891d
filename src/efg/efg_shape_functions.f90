!> Coupled meshfree/FE shape functions Psi at a point of a background cell (formulation
!> section 3; Wang et al. 2009, eqs. 7-9 and 24-25).
!>
!> For a point X of a cell of a meshfree part:
!>   Gamma vertex L of the cell:  Psi_L(X) = Phi_L(X), its trilinear FE function;
!>   interior particle I:         Psi_I(X) = w_I(X) p(xi_I)^T alpha(X),  M(X) alpha(X) = b(X),
!>     M = sum_I w_I p(xi_I) p(xi_I)^T over the particles covering X,
!>     b = sum_V Phi_V(X) p(xi_V) over the interior vertices V of the cell
!>         (= p(0) - sum_L Phi_L(X) p(xi_L); with the full transformation, IEBT 1, b = p(0)),
!>   with the linear basis p(xi) = [1, xi_1, xi_2, xi_3] in the shifted, scaled coordinates
!>   xi = (X_I - X) / h, h the cell's mean edge length (conditioning only).
!> Then sum_J Psi_J p(xi_J) = p(0) (linear consistency) and, where b = 0 (boundary faces, cells
!> without interior vertices), every Psi_I vanishes exactly: the interface constraint (eq. 8).
!>
!> M is 4x4, symmetric, positive semi-definite and genuinely singular at many points near edges
!> and corners of a part (one or few covering particles, coplanar particles). b always lies in
!> its range because every interior vertex of the cell covers the whole cell (support rule of
!> section 2), and Psi does not depend on which solution is taken. So the solve is rank-revealing:
!> column-pivoted QR (LAPACK dgeqp3) of the rows A = [sqrt(w_I) p(xi_I)^T], A P = Q R, keeping
!> the leading columns whose |R_kk| exceed 1e-10 |R_11|. Then Psi_I = sqrt(w_I) (A alpha)_I with
!> A alpha = Q [y; 0] and R11^T y = (P^T b)(1:rank): one triangular solve and one product with Q
!> (dormqr), never alpha itself, whose computation would square the condition number. A plain
!> Cholesky of M would fail on the singular points and a threshold on the eigenvalues of M (the
!> squared singular values) costs accuracy. The residual |M alpha - b| = |sum_I Psi_I p(xi_I) - b|
!> is returned for the caller's round-off assertion.
!>
!> Direct gradients (for the Gauss variant, IDIM 2): dPsi_I = dw_I p^T alpha + w_I dp^T alpha
!> + w_I p^T dalpha with M dalpha = db - dM alpha, solved with the same factorization (and the
!> same product with Q for w_I p^T dalpha); Gamma vertices take the exact gradients of their
!> trilinear functions.
module efg_shape_functions
  use kinds, only: wp
  use integer_lists, only: sorted_position, sort_short_list
  use efg_kernel, only: kernel_weights, kernel_weight_gradient
  use efg_cell_geometry, only: trilinear_functions, trilinear_natural_derivatives, cell_jacobian, inverse_3, &
                               mean_edge_length
  use efg_supports, only: part_supports_t
  use efg_neighbour_search, only: particle_grid_t, find_support_candidates
  implicit none
  private

  public :: cell_shape_context_t, prepare_cell_context, evaluate_shape_functions

  !> Columns of R whose diagonal falls below this fraction of |R_11| are taken as dependent.
  real(wp), parameter, public :: rank_tolerance = 1.0e-10_wp

  !> Everything the shape functions of one background cell need: its vertices and their classes,
  !> and the particles whose supports touch the cell. Local nodes `nodes(1:node_count)` are the
  !> cell's Gamma vertices and those particles, in ascending model node order; evaluations return
  !> one value per local node.
  type :: cell_shape_context_t
    integer :: cell = 0                               !< model solid index
    real(wp) :: vertices(3, 8) = 0.0_wp
    logical :: vertex_is_particle(8) = .false.
    integer :: vertex_local(8) = 0                    !< local node of each vertex
    integer :: vertex_particle(8) = 0                 !< position among the candidate particles
    real(wp) :: scale_length = 1.0_wp                 !< h
    integer :: kernel = 0
    logical :: full_transformation = .false.
    integer :: node_count = 0
    integer, allocatable :: nodes(:)                  !< model node indices, ascending
    integer :: particle_count = 0
    integer, allocatable :: particle_local(:)         !< local node of each candidate particle
    real(wp), allocatable :: particle_coordinates(:, :)
    real(wp), allocatable :: particle_radius(:, :)
    real(wp), allocatable :: particle_inverse_radius(:, :) !< 1 / particle_radius
    integer, allocatable :: candidates(:)             !< particle numbers (search scratch)
  end type cell_shape_context_t

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

  !> Gather the vertices, vertex classes and candidate particles of model solid `cell`.
  subroutine prepare_cell_context(supports, grid, coordinates, cell_nodes, cell, context)
    type(part_supports_t), intent(in) :: supports
    type(particle_grid_t), intent(in) :: grid
    real(wp), intent(in) :: coordinates(:, :)
    integer, intent(in) :: cell_nodes(8), cell
    type(cell_shape_context_t), intent(inout) :: context
    integer :: gamma_vertices(8), gamma_count, a, k, candidate_count, next_gamma, next_particle, node

    context%cell = cell
    context%kernel = supports%kernel
    context%full_transformation = supports%full_transformation
    context%vertices = coordinates(:, cell_nodes)
    context%scale_length = mean_edge_length(context%vertices)
    do a = 1, 8
      context%vertex_is_particle(a) = supports%particle_of_node(cell_nodes(a)) > 0
    end do

    call find_support_candidates(grid, supports%particle_coordinates, supports%particle_radius, &
                                 minval(context%vertices, dim=2), maxval(context%vertices, dim=2), &
                                 context%candidates, candidate_count)
    context%particle_count = candidate_count
    call ensure_size(context, candidate_count)
    do k = 1, candidate_count
      context%particle_coordinates(:, k) = supports%particle_coordinates(:, context%candidates(k))
      context%particle_radius(:, k) = supports%particle_radius(:, context%candidates(k))
      context%particle_inverse_radius(:, k) = 1.0_wp/context%particle_radius(:, k)
    end do

    ! Gamma vertices, ascending and without repeats (degenerate cells repeat nodes)
    gamma_count = 0
    do a = 1, 8
      if (context%vertex_is_particle(a)) cycle
      if (any(gamma_vertices(1:gamma_count) == cell_nodes(a))) cycle
      gamma_count = gamma_count + 1
      gamma_vertices(gamma_count) = cell_nodes(a)
    end do
    call sort_short_list(gamma_vertices(1:gamma_count))

    ! merge the two ascending lists (particle numbers ascend with their node indices)
    context%node_count = gamma_count + candidate_count
    next_gamma = 1
    next_particle = 1
    do k = 1, context%node_count
      if (next_particle > candidate_count) then
        context%nodes(k) = gamma_vertices(next_gamma)
        next_gamma = next_gamma + 1
      else if (next_gamma > gamma_count) then
        context%nodes(k) = supports%particles(context%candidates(next_particle))
        context%particle_local(next_particle) = k
        next_particle = next_particle + 1
      else if (gamma_vertices(next_gamma) < supports%particles(context%candidates(next_particle))) then
        context%nodes(k) = gamma_vertices(next_gamma)
        next_gamma = next_gamma + 1
      else
        context%nodes(k) = supports%particles(context%candidates(next_particle))
        context%particle_local(next_particle) = k
        next_particle = next_particle + 1
      end if
    end do

    do a = 1, 8
      node = cell_nodes(a)
      context%vertex_local(a) = sorted_position(context%nodes(1:context%node_count), node)
      context%vertex_particle(a) = 0
      if (context%vertex_is_particle(a)) then
        ! an interior vertex always covers its cell, so it is among the candidates
        context%vertex_particle(a) = sorted_position(context%candidates(1:candidate_count), &
                                                    supports%particle_of_node(node))
      end if
    end do
  end subroutine prepare_cell_context

  !> Coupled shape functions at the parametric point `parametric` of the context's cell:
  !> `values(k)` = Psi of local node k at `point` = X(parametric); optionally their gradients
  !> (3, node_count). `rank` is the rank of M found (0 when b = 0: no MLS part at this point) and
  !> `residual` the largest component of |M alpha - b| (and of h |M dalpha - (db - dM alpha)| when
  !> gradients are asked for): round-off when the support rule holds.
  subroutine evaluate_shape_functions(context, parametric, point, values, rank, residual, gradients)
    type(cell_shape_context_t), intent(in) :: context
    real(wp), intent(in) :: parametric(3)
    real(wp), intent(out) :: point(3)
    real(wp), intent(out) :: values(:)
    integer, intent(out) :: rank
    real(wp), intent(out) :: residual
    real(wp), intent(out), optional :: gradients(:, :)
    real(wp) :: phi(8), natural(3, 8), phi_gradient(3, 8), jacobian(3, 3)
    real(wp) :: moment(4), moment_gradient(4, 3), basis(4), alpha(4)
    real(wp) :: right_side(4, 3), reproduced(4), weight_gradient(3, context%particle_count)
    real(wp) :: weight(context%particle_count), shifted(4, context%particle_count)
    real(wp) :: rows(max(context%particle_count, 1), 4), tau(4), work(256)
    real(wp) :: projected(max(context%particle_count, 4)), projected_gradient(max(context%particle_count, 4), 3)
    real(wp) :: inverse_h, basis_alpha
    integer :: covering(context%particle_count), covering_count, pivot(4), info, a, i, k, n, local
    logical :: with_gradients

    with_gradients = present(gradients)
    inverse_h = 1.0_wp/context%scale_length
    call trilinear_functions(parametric, phi)
    point = matmul(context%vertices, phi)
    n = context%node_count
    values(1:n) = 0.0_wp
    rank = 0
    residual = 0.0_wp
    if (with_gradients) then
      call trilinear_natural_derivatives(parametric, natural)
      jacobian = cell_jacobian(context%vertices, parametric)
      ! dPhi/dX_i = sum_a dPhi/ds_a ds_a/dX_i
      phi_gradient = matmul(transpose(inverse_3(jacobian)), natural)
      gradients(:, 1:n) = 0.0_wp
    end if

    ! Gamma vertices keep their FE functions (eq. 24)
    do a = 1, 8
      if (context%vertex_is_particle(a)) cycle
      values(context%vertex_local(a)) = values(context%vertex_local(a)) + phi(a)
      if (with_gradients) gradients(:, context%vertex_local(a)) = gradients(:, context%vertex_local(a)) &
                                                                  + phi_gradient(:, a)
    end do

    ! b(X) and its gradient; dp(xi)/dX_k = -e_(k+1) / h for every node
    moment = 0.0_wp
    moment_gradient = 0.0_wp
    if (context%full_transformation) then
      moment(1) = 1.0_wp
    else
      do a = 1, 8
        if (.not. context%vertex_is_particle(a)) cycle
        basis = [1.0_wp, (context%vertices(:, a) - point)*inverse_h]
        moment = moment + phi(a)*basis
        if (with_gradients) then
          do k = 1, 3
            moment_gradient(:, k) = moment_gradient(:, k) + phi_gradient(k, a)*basis
            moment_gradient(k + 1, k) = moment_gradient(k + 1, k) - phi(a)*inverse_h
          end do
        end if
      end do
    end if
    ! no MLS part here: b = 0 (a face of the part's boundary, or a cell without interior
    ! vertices) makes alpha = 0 and every particle function exactly zero (eq. 8)
    if (all(moment == 0.0_wp) .and. all(moment_gradient == 0.0_wp)) return

    ! weighted basis rows of the covering particles
    if (with_gradients) then
      do i = 1, context%particle_count
        call kernel_weight_gradient(context%kernel, context%particle_coordinates(:, i), &
                                    context%particle_radius(:, i), point, weight(i), weight_gradient(:, i))
      end do
    else
      call kernel_weights(context%kernel, context%particle_coordinates(:, 1:context%particle_count), &
                          context%particle_inverse_radius(:, 1:context%particle_count), point, weight)
    end if
    covering_count = 0
    do i = 1, context%particle_count
      if (weight(i) <= 0.0_wp) cycle
      covering_count = covering_count + 1
      covering(covering_count) = i
      shifted(:, i) = [1.0_wp, (context%particle_coordinates(:, i) - point)*inverse_h]
      rows(covering_count, :) = sqrt(weight(i))*shifted(:, i)
    end do
    if (covering_count == 0) then
      ! only possible when the support rule is broken: report b as the residual
      residual = maxval(abs(moment))
      return
    end if

    ! rank-revealing factorization A P = Q R (so P^T M P = R^T R)
    pivot = 0
    call dgeqp3(covering_count, 4, rows, size(rows, 1), pivot, tau, work, size(work), info)
    rank = 0
    do k = 1, min(covering_count, 4)
      if (abs(rows(k, k)) <= rank_tolerance*abs(rows(1, 1))) exit
      rank = k
    end do

    ! Psi_I = w_I p_I^T alpha = sqrt(w_I) (A alpha)_I with A = Q R P^T and R^T R P^T alpha =
    ! P^T b, so A alpha = Q y with R11^T y = (P^T b)(1:rank): one triangular solve and one
    ! product with Q. Forming alpha first would square the condition number of the rows.
    projected = 0.0_wp
    projected(1:rank) = forward_solve(rows, rank, moment(pivot))
    call dormqr("L", "N", covering_count, 1, min(covering_count, 4), rows, size(rows, 1), tau, projected, &
                size(projected), work, size(work), info)
    do i = 1, covering_count
      values(context%particle_local(covering(i))) = sqrt(weight(covering(i)))*projected(i)
    end do
    ! M alpha - b = sum_I Psi_I p(xi_I) - b: the reproduction error of the MLS part
    reproduced = 0.0_wp
    do i = 1, covering_count
      reproduced = reproduced + values(context%particle_local(covering(i)))*shifted(:, covering(i))
    end do
    residual = maxval(abs(reproduced - moment))

    if (.not. with_gradients) return
    ! Direct derivatives. p_I.alpha = Psi_I / w_I and w_I p_I.dalpha_k = sqrt(w_I) (Q y_k)_I with
    ! R11^T y_k = (P^T (db_k - dM_k alpha))(1:rank) come through Q as above; only the terms
    ! dp_k.alpha = -alpha_(k+1) / h need alpha itself (alpha(pivot) = R11^-1 y).
    alpha = solve_factored(rows, pivot, rank, moment)
    ! dM_k alpha = sum_I [dw_Ik (p_I.alpha) p_I + w_I ((p_I.alpha) dp_k + (dp_k.alpha) p_I)]
    right_side = moment_gradient
    do i = 1, covering_count
      associate (particle => covering(i))
        basis_alpha = projected(i)/sqrt(weight(particle))
        do k = 1, 3
          right_side(:, k) = right_side(:, k) - weight_gradient(k, particle)*basis_alpha*shifted(:, particle) &
                             + weight(particle)*alpha(k + 1)*inverse_h*shifted(:, particle)
          right_side(k + 1, k) = right_side(k + 1, k) + weight(particle)*basis_alpha*inverse_h
        end do
      end associate
    end do
    projected_gradient = 0.0_wp
    do k = 1, 3
      projected_gradient(1:rank, k) = forward_solve(rows, rank, right_side(pivot, k))
    end do
    call dormqr("L", "N", covering_count, 3, min(covering_count, 4), rows, size(rows, 1), tau, projected_gradient, &
                size(projected_gradient, 1), work, size(work), info)
    do i = 1, covering_count
      associate (particle => covering(i))
        local = context%particle_local(particle)
        basis_alpha = projected(i)/sqrt(weight(particle))
        do k = 1, 3
          gradients(k, local) = weight_gradient(k, particle)*basis_alpha - weight(particle)*alpha(k + 1)*inverse_h &
                                + sqrt(weight(particle))*projected_gradient(i, k)
        end do
      end associate
    end do
    ! residuals of the derivative equations, M dalpha_k - (db_k - dM_k alpha), scaled by h
    do k = 1, 3
      reproduced = 0.0_wp
      do i = 1, covering_count
        reproduced = reproduced + sqrt(weight(covering(i)))*projected_gradient(i, k)*shifted(:, covering(i))
      end do
      residual = max(residual, context%scale_length*maxval(abs(reproduced - right_side(:, k))))
    end do
  end subroutine evaluate_shape_functions

  !> Basic solution of M alpha = b from the pivoted QR factor R (upper triangle of `factor`):
  !> M = P R^T R P^T, so R11^T R11 z = (P^T b)(1:rank), alpha(pivot(k)) = z(k), the remaining
  !> components zero. Valid whenever b lies in the range of M.
  pure function solve_factored(factor, pivot, rank, right_side) result(alpha)
    real(wp), intent(in) :: factor(:, :), right_side(4)
    integer, intent(in) :: pivot(4), rank
    real(wp) :: alpha(4)
    real(wp) :: permuted(4), z(4)
    integer :: i

    permuted = right_side(pivot)
    z = 0.0_wp
    z(1:rank) = forward_solve(factor, rank, permuted)
    ! R11 z = y
    do i = rank, 1, -1
      z(i) = (z(i) - dot_product(factor(i, i + 1:rank), z(i + 1:rank)))/factor(i, i)
    end do
    alpha = 0.0_wp
    alpha(pivot(1:rank)) = z(1:rank)
  end function solve_factored

  !> y with R11^T y = c (R11 the leading rank x rank block of the upper triangle of `factor`).
  pure function forward_solve(factor, rank, right_side) result(y)
    real(wp), intent(in) :: factor(:, :), right_side(:)
    integer, intent(in) :: rank
    real(wp) :: y(rank)
    integer :: i

    do i = 1, rank
      y(i) = (right_side(i) - dot_product(factor(1:i - 1, i), y(1:i - 1)))/factor(i, i)
    end do
  end function forward_solve



  !> Room for `count` candidate particles (and count + 8 local nodes); arrays only grow, so one
  !> context can be reused for every cell of a thread.
  subroutine ensure_size(context, count)
    type(cell_shape_context_t), intent(inout) :: context
    integer, intent(in) :: count
    integer :: capacity

    if (allocated(context%particle_local)) then
      if (size(context%particle_local) >= count) return
      deallocate (context%particle_local, context%particle_coordinates, context%particle_radius, &
                  context%particle_inverse_radius, context%nodes)
    end if
    capacity = max(count, 64)
    allocate (context%particle_local(capacity), context%particle_coordinates(3, capacity), &
              context%particle_radius(3, capacity), context%particle_inverse_radius(3, capacity), &
              context%nodes(capacity + 8))
  end subroutine ensure_size
end module efg_shape_functions
