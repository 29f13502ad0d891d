!> Explicit update of the meshfree (EFG) shells (*SECTION_SHELL ELFORM 41): a corotational
!> Mindlin-Reissner shell whose integration points see N (node, gradient) pairs instead of four
!> corners (Wu, Guo, Wang & Botkin 2004, "A mesh-free analysis of shell structures", 8th Int.
!> LS-DYNA Users Conference: Lagrangian MLS functions on the undeformed surface, co-rotational
!> update as in the Belytschko-Tsay shell, stabilized conforming (sub-cell) integration of the
!> membrane and bending strains) with an assumed-strain transverse shear on the cells' physical
!> corner and edge-midpoint values (below). The geometry (pairs, smoothed gradients, masses, transformation) comes
!> from the set-up (efg_shell_part); this module is the per-cycle work on it.
!>
!> Per background cell c: the current frame E = shell_cell_frame of its current corners, the
!> same function that gave the reference frame of the set-up, so the undeformed state has no
!> strain; rates on the mid-step frame (corners x - dt/2 v), forces on the end-of-step frame, as
!> shell_block. Per membrane/bending point g of the cell, from its pairs (I, b_I) (b_I the
!> smoothed gradient along the reference e1, e2 of the cell):
!>   Xb = sum x_I (x) b_I, Vb = sum v_I (x) b_I, Wb = sum w_I (x) b_I      (3 x 2 each)
!>   F = E2 Xb (the in-plane deformation gradient, E2 = rows e1, e2), G = F^-T,
!>   current gradients g_I = G b_I, so L = (E2 Vb) G^T = Fdot F^-1 at mid-step (as the solids),
!>   membrane rates d = sym L, in-plane spin (L21 - L12)/2,
!>   curvature rates from K = (E2 Wb) G^T: k_x = K21, k_y = -K12, 2 k_xy = K22 - K11
!> (the Belytschko-Tsay rates with the corner gradients replaced by g_I: docs/shells.md). The
!> through-thickness points and plane_stress_dispatch are the FE shells' (NIP Gauss points,
!> every plane-stress law); the stress is kept in the cell's corotational frame and turned with
!> the material spin (half into the mid-step frame, half into the end frame, as
!> shell_block's rotate_with_material). Resultants N, M per unit current length; the point's
!> forces and moments are the transposes, W J N g_I and W J (M-moments), J = det F.
!> Transverse shear (docs/efg_shells.md says why not from the meshfree functions): on the
!> physical values of the cell's stations, its corners (a particle corner through its
!> transformation row) and its edge midpoints (the functions there), MITC4 on a quadrilateral
!> (Bathe & Dvorkin 1985: covariant shear of each edge, interpolated to the four sub-cell
!> points), the FE triangle's edge-based constant shear on a triangle (shell_triangle), each
!> edge's mean rotation by Simpson's rule on its corners and midpoint (exact for a rotation
!> quadratic along the edge, where the corners' mean leaves the FE shell's -1/(4 n^2) in a
!> cantilever); a Kirchhoff mode has no shear on any mesh. Elastic with SHRF G, uniform through
!> the thickness as in shell_block; forces and moments onto the stations are handed to the
!> nodes through the rows (A^T).
!>
!> Energies are the exact work of the nodal forces and moments (element_work's add_force_work,
!> as efg_forces and shell_block). Their power needs no pair loop: a point's forces and moments
!> are f_I = P b_I and m_I = Q b_I (P, Q: 3 x 2 per point), so their power is P : Vb + Q : Wb
!> (= W J (N : L + M : k)); the forces of the last call (kept per point) against this step's
!> velocities complete the last step's work.
!>
!> Blocks are runs of whole cells, at most block_size membrane/bending points each (a lane per
!> point for the materials; the block's cells go with it). Blocks are coloured by the nodes of
!> their pairs, corners and station rows, so the blocks of one colour share no node:
!> colours one after another, the blocks of a colour in parallel, each node receives its
!> contributions in the same order for any thread count.
module efg_shell_forces
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use kinds, only: wp, block_size
  use gather_list, only: gather_list_t
  use block_colouring, only: colour_blocks_by_node_lists
  use model, only: model_t, material_t, law_null
  use efg_shell_part, only: efg_shell_part_t, shell_cell_frame
  use plane_stress_dispatch, only: plane_stress_history_count, initialize_plane_stress_history, &
                                   update_plane_stress_block, plane_stress_plastic_strain, rotate_plane_stress_history
  use element_work, only: add_force_work
  use gauss_legendre, only: gauss_legendre_rule
  use shell_block, only: max_shell_points
  use shell_triangle, only: triangle_edge_fit
  implicit none
  private

  public :: efg_shell_block_t, efg_shell_solver_t, set_up_efg_shell_solver, compute_efg_shell_forces
  public :: efg_shell_cell_results, efg_shell_nodal_masses, transform_shell_to_physical, transpose_shell_to_generalized
  public :: efg_shell_rotary_factor, raise_corner_plastic_strain, stations_per_cell
  public :: efg_shell_cell_time_steps

  !> Transverse shear stations of a cell: corners 1-4, midpoints 5-8 of the edges 1-2, 2-3, 3-4, 4-1.
  integer, parameter :: stations_per_cell = 8

  !> Whole cells whose membrane/bending points fill at most block_size lanes, and their state.
  type :: efg_shell_block_t
    integer :: first_cell = 0                     !< cells first_cell .. first_cell + cell_count - 1
    integer :: cell_count = 0
    integer :: first_point = 0                    !< points first_point .. first_point + point_count - 1
    integer :: point_count = 0
    !> Local stress xx, yy, xy (block_size, 3, NIP) of each point lane, in its cell's frame.
    real(wp), allocatable :: stress(:, :, :)
    !> Plane-stress history (block_size, count, NIP).
    real(wp), allocatable :: history(:, :, :)
    !> Transverse shear stress zx, yz of each point lane (elastic, the same at every thickness point).
    real(wp) :: shear_stress(block_size, 2) = 0.0_wp
    real(wp) :: internal_energy(block_size) = 0.0_wp   !< per point lane: membrane and bending work
    real(wp) :: force_power(block_size) = 0.0_wp
    real(wp) :: shear_energy(block_size) = 0.0_wp      !< per cell lane: transverse shear work (its points')
    real(wp) :: shear_power(block_size) = 0.0_wp
    real(wp) :: previous_time_step = 0.0_wp
  end type efg_shell_block_t

  !> The run-time data of one meshfree shell part.
  type :: efg_shell_solver_t
    type(efg_shell_part_t) :: geometry
    real(wp) :: density = 0.0_wp
    real(wp) :: shear_factor = 1.0_wp             !< SHRF
    integer :: thickness_points = 2               !< NIP
    real(wp) :: point_height(max_shell_points) = 0.0_wp !< in [-1/2, 1/2]
    real(wp) :: point_weight(max_shell_points) = 0.0_wp !< summing to 1
    integer, allocatable :: cell_nodes(:, :)      !< (4, cells) corner nodes (a triangle repeats node 3)
    type(efg_shell_block_t), allocatable :: blocks(:)
    !> Per cell, from the last call: frame(:, a, c) = e_a at the end of the step, current area.
    real(wp), allocatable :: cell_frame(:, :, :)
    real(wp), allocatable :: cell_area(:)
    !> Per point, the resultants of the last call times the point's current area, W J N and
    !> W J M (local xx, yy, xy), and its forces and moments on a pair (I, b_I): global
    !> f_I = P b_I, m_I = Q b_I with P, Q (3, 2) (forces_of_point).
    real(wp), allocatable :: point_membrane(:, :)
    real(wp), allocatable :: point_moment(:, :)
    real(wp), allocatable :: point_force(:, :, :)
    real(wp), allocatable :: point_couple(:, :, :)
    !> The physical values at each cell's stations (transverse shear): its corners 1-4 and the
    !> midpoints 5-8 of its edges 1-2, 2-3, 3-4, 4-1. Station L of cell c, k = 8 (c - 1) + L, is
    !> the sum over station_offsets(k) : station_offsets(k+1)-1 of station_weight times the
    !> solver's value at station_node (a corner: a particle's transformation row, a Gamma node
    !> itself; a midpoint: the functions there; empty for a triangle's midpoints).
    integer, allocatable :: station_offsets(:), station_node(:)
    real(wp), allocatable :: station_weight(:)
    !> Per cell, the transverse shear forces (1-3) and moments (4-6) of the last call on its
    !> stations' physical values (global; (6, stations_per_cell, cells)).
    real(wp), allocatable :: station_force(:, :, :)
    type(gather_list_t) :: block_colours          !< colour -> blocks; blocks of one colour share no node
    real(wp), allocatable :: block_time_step(:)
    integer, allocatable :: block_critical_cell(:), block_failed_cell(:)
  end type efg_shell_solver_t

contains

  !> Blocks, material state and colours of one part whose geometry is built.
  subroutine set_up_efg_shell_solver(model, geometry, solver)
    type(model_t), intent(in) :: model
    type(efg_shell_part_t), intent(in) :: geometry
    type(efg_shell_solver_t), intent(out) :: solver
    real(wp) :: points(max_shell_points), weights(max_shell_points)
    integer :: cell_count, point_count, c, n, b, history_count, point, first_cell, points_in_block
    integer :: block_count

    solver%geometry = geometry
    cell_count = size(geometry%cells)
    point_count = size(geometry%point_cell)
    associate (part => model%parts(geometry%part), material => model%materials(geometry%material))
      solver%density = material%density
      associate (section => model%sections(part%section))
        n = max(1, min(max_shell_points, section%integration_points))
        solver%shear_factor = section%shear_factor
      end associate
      solver%thickness_points = n
      call gauss_legendre_rule(n, points(1:n), weights(1:n))
      solver%point_height(1:n) = 0.5_wp*points(1:n)
      solver%point_weight(1:n) = 0.5_wp*weights(1:n)
      allocate (solver%cell_nodes(4, cell_count))
      do c = 1, cell_count
        solver%cell_nodes(:, c) = model%shell_nodes(:, geometry%cells(c))
      end do
      ! blocks: runs of whole cells (the points of a cell are consecutive, cells ascending)
      block_count = 0
      first_cell = 1
      do while (first_cell <= cell_count)
        call next_block_cells(geometry, first_cell, c, points_in_block)
        block_count = block_count + 1
        first_cell = c + 1
      end do
      allocate (solver%blocks(block_count))
      history_count = max(0, plane_stress_history_count(material))
      first_cell = 1
      do b = 1, block_count
        call next_block_cells(geometry, first_cell, c, points_in_block)
        associate (block => solver%blocks(b))
          block%first_cell = first_cell
          block%cell_count = c - first_cell + 1
          block%first_point = first_point_of(geometry, first_cell)
          block%point_count = points_in_block
          allocate (block%stress(block_size, 3, n), source=0.0_wp)
          allocate (block%history(block_size, history_count, n), source=0.0_wp)
          do point = 1, n
            call initialize_plane_stress_history(material, block%point_count, block%history(:, :, point))
          end do
        end associate
        first_cell = c + 1
      end do
    end associate
    allocate (solver%cell_frame(3, 3, cell_count), solver%cell_area(cell_count))
    solver%cell_frame = geometry%cell_frame
    solver%cell_area = geometry%cell_area
    allocate (solver%point_membrane(3, point_count), solver%point_moment(3, point_count), &
              solver%point_force(3, 2, point_count), solver%point_couple(3, 2, point_count), &
              solver%station_force(6, stations_per_cell, cell_count))
    solver%point_membrane = 0.0_wp
    solver%point_moment = 0.0_wp
    solver%point_force = 0.0_wp
    solver%point_couple = 0.0_wp
    solver%station_force = 0.0_wp
    call set_up_station_rows(geometry, solver%cell_nodes, size(model%coordinates, 2), solver)
    allocate (solver%block_time_step(block_count), solver%block_critical_cell(block_count), &
              solver%block_failed_cell(block_count))
    solver%block_time_step = huge(1.0_wp)
    solver%block_critical_cell = 0
    solver%block_failed_cell = 0
    call colour_shell_blocks(size(model%coordinates, 2), solver)
  end subroutine set_up_efg_shell_solver

  !> The last cell of the block that starts at first_cell (as many whole cells as fit in
  !> block_size points, at least one) and its point count.
  subroutine next_block_cells(geometry, first_cell, last_cell, point_count)
    type(efg_shell_part_t), intent(in) :: geometry
    integer, intent(in) :: first_cell
    integer, intent(out) :: last_cell, point_count
    integer :: cell_points
    last_cell = first_cell
    point_count = points_of_cell(geometry, first_cell)
    do while (last_cell < size(geometry%cells))
      cell_points = points_of_cell(geometry, last_cell + 1)
      if (point_count + cell_points > block_size) exit
      last_cell = last_cell + 1
      point_count = point_count + cell_points
    end do
  end subroutine next_block_cells

  !> The first point of a cell (points come in cell order).
  integer function first_point_of(geometry, cell)
    type(efg_shell_part_t), intent(in) :: geometry
    integer, intent(in) :: cell
    integer :: low, high, middle
    ! point_cell is ascending: the first point whose cell is `cell`
    low = 1
    high = size(geometry%point_cell)
    do while (low < high)
      middle = (low + high)/2
      if (geometry%point_cell(middle) < cell) then
        low = middle + 1
      else
        high = middle
      end if
    end do
    first_point_of = low
  end function first_point_of

  integer function points_of_cell(geometry, cell)
    type(efg_shell_part_t), intent(in) :: geometry
    integer, intent(in) :: cell
    integer :: g
    points_of_cell = 0
    do g = first_point_of(geometry, cell), size(geometry%point_cell)
      if (geometry%point_cell(g) /= cell) exit
      points_of_cell = points_of_cell + 1
    end do
  end function points_of_cell

  !> The station rows (physical values for the transverse shear): a particle corner takes its
  !> transformation row, a Gamma corner itself with weight 1, an edge midpoint the functions
  !> there (the geometry's midpoint rows).
  subroutine set_up_station_rows(geometry, cell_nodes, node_count, solver)
    type(efg_shell_part_t), intent(in) :: geometry
    integer, intent(in) :: cell_nodes(:, :), node_count
    type(efg_shell_solver_t), intent(inout) :: solver
    integer, allocatable :: particle_of(:)
    integer :: c, corner, edge, j, k, count, node, station_count
    allocate (particle_of(node_count))
    particle_of = 0
    do j = 1, size(geometry%particles)
      particle_of(geometry%particles(j)) = j
    end do
    station_count = stations_per_cell*size(geometry%cells)
    count = size(geometry%midpoint_node)
    do c = 1, size(geometry%cells)
      do corner = 1, 4
        j = particle_of(cell_nodes(corner, c))
        if (j == 0) then
          count = count + 1
        else
          count = count + geometry%transform_offsets(j + 1) - geometry%transform_offsets(j)
        end if
      end do
    end do
    allocate (solver%station_offsets(station_count + 1), solver%station_node(count), solver%station_weight(count))
    count = 0
    do c = 1, size(geometry%cells)
      do corner = 1, 4
        solver%station_offsets(stations_per_cell*(c - 1) + corner) = count + 1
        node = cell_nodes(corner, c)
        j = particle_of(node)
        if (j == 0) then
          count = count + 1
          solver%station_node(count) = node
          solver%station_weight(count) = 1.0_wp
        else
          do k = geometry%transform_offsets(j), geometry%transform_offsets(j + 1) - 1
            count = count + 1
            solver%station_node(count) = geometry%transform_node(k)
            solver%station_weight(count) = geometry%transform_value(k)
          end do
        end if
      end do
      do edge = 1, 4
        solver%station_offsets(stations_per_cell*(c - 1) + 4 + edge) = count + 1
        do k = geometry%midpoint_offsets(4*(c - 1) + edge), geometry%midpoint_offsets(4*(c - 1) + edge + 1) - 1
          count = count + 1
          solver%station_node(count) = geometry%midpoint_node(k)
          solver%station_weight(count) = geometry%midpoint_value(k)
        end do
      end do
    end do
    solver%station_offsets(station_count + 1) = count + 1
  end subroutine set_up_station_rows

  !> Colours the blocks by the nodes of their points' pairs, their cells' station rows and their
  !> cells' corners (each node listed once per block).
  subroutine colour_shell_blocks(node_count, solver)
    integer, intent(in) :: node_count
    type(efg_shell_solver_t), intent(inout) :: solver
    integer, allocatable :: offsets(:), block_nodes(:), listed_by(:)
    integer :: b, k, c, count
    associate (geometry => solver%geometry)
      allocate (offsets(size(solver%blocks) + 1), listed_by(node_count), &
                block_nodes(size(geometry%pair_node) + size(solver%station_node) + 4*size(geometry%cells)))
      listed_by = 0
      count = 0
      do b = 1, size(solver%blocks)
        offsets(b) = count + 1
        associate (block => solver%blocks(b))
          do k = geometry%point_offsets(block%first_point), geometry%point_offsets(block%first_point + block%point_count) - 1
            call list_node(geometry%pair_node(k))
          end do
          do c = block%first_cell, block%first_cell + block%cell_count - 1
            do k = solver%station_offsets(stations_per_cell*(c - 1) + 1), &
                   solver%station_offsets(stations_per_cell*c + 1) - 1
              call list_node(solver%station_node(k))
            end do
            do k = 1, 4
              call list_node(solver%cell_nodes(k, c))
            end do
          end do
        end associate
      end do
      offsets(size(solver%blocks) + 1) = count + 1
    end associate
    call colour_blocks_by_node_lists(node_count, offsets, block_nodes(1:count), solver%block_colours)
  contains
    subroutine list_node(node)
      integer, intent(in) :: node
      if (listed_by(node) == b) return
      listed_by(node) = b
      count = count + 1
      block_nodes(count) = node
    end subroutine list_node
  end subroutine colour_shell_blocks

  !> Rotary inertia of a shell node per unit of its mass, (t^2 + A) / 4 with A the area of the
  !> cells around it: the FE shells' scaling (shell_block's rotary_inertia_factor says why: with
  !> the physical t^2 / 12 the transverse shear of a thin shell would set a step L / t times
  !> smaller than the membrane's).
  pure real(wp) function efg_shell_rotary_factor(thickness, area)
    real(wp), intent(in) :: thickness, area
    efg_shell_rotary_factor = (thickness**2 + area)/4.0_wp
  end function efg_shell_rotary_factor

  !> Row-sum masses (density x mass_volume) and rotary inertias of the part's nodes, in the
  !> order of mass_node; the inertia factor takes the mean area of the cells whose shear point
  !> the node reaches (a particle's support spans several cells).
  subroutine efg_shell_nodal_masses(solver, node_count, mass, inertia)
    type(efg_shell_solver_t), intent(in) :: solver
    integer, intent(in) :: node_count
    real(wp), allocatable, intent(out) :: mass(:), inertia(:)
    real(wp), allocatable :: area_sum(:), thickness_sum(:), weight(:)
    integer :: c, k, node, j
    associate (geometry => solver%geometry)
      allocate (area_sum(node_count), thickness_sum(node_count), weight(node_count))
      area_sum = 0.0_wp
      thickness_sum = 0.0_wp
      weight = 0.0_wp
      do c = 1, size(geometry%cells)
        do k = geometry%shear_offsets(c), geometry%shear_offsets(c + 1) - 1
          node = geometry%shear_node(k)
          area_sum(node) = area_sum(node) + geometry%cell_area(c)
          thickness_sum(node) = thickness_sum(node) + geometry%cell_thickness(c)
          weight(node) = weight(node) + 1.0_wp
        end do
      end do
      allocate (mass(size(geometry%mass_node)), inertia(size(geometry%mass_node)))
      do j = 1, size(geometry%mass_node)
        node = geometry%mass_node(j)
        mass(j) = solver%density*geometry%mass_volume(j)
        if (weight(node) > 0.0_wp) then
          inertia(j) = abs(mass(j))*efg_shell_rotary_factor(thickness_sum(node)/weight(node), area_sum(node)/weight(node))
        else
          inertia(j) = abs(mass(j))*efg_shell_rotary_factor(maxval(geometry%cell_thickness), maxval(geometry%cell_area))
        end if
      end do
    end associate
  end subroutine efg_shell_nodal_masses

  !> Stresses, forces and moments, energies and stable steps of every cell of one part; forces
  !> into internal_force, moments into internal_moment, and area x normal and area of each cell
  !> into its corners' sums (the drilling-rate removal of the time loop). `dt` is the step just
  !> taken (0 at the start); coordinates, velocity and angular_velocity are the solver's
  !> (generalized at interior particles).
  subroutine compute_efg_shell_forces(material, solver, coordinates, velocity, angular_velocity, dt, &
                                      internal_force, internal_moment, normal_sum, area_sum, computed)
    type(material_t), intent(in) :: material
    type(efg_shell_solver_t), intent(inout) :: solver
    real(wp), intent(in), contiguous :: coordinates(:, :), velocity(:, :), angular_velocity(:, :)
    real(wp), intent(in) :: dt
    real(wp), intent(inout), contiguous :: internal_force(:, :), internal_moment(:, :), normal_sum(:, :), area_sum(:)
    !> A distributed run (docs/parallel.md): the part's blocks this rank computes; the others are
    !> left alone (their state stays as it was). Absent: all.
    logical, intent(in), optional :: computed(:)
    integer :: colour, k, b
    associate (colours => solver%block_colours)
      do colour = 1, size(colours%offsets) - 1
        !$omp parallel do schedule(dynamic, 1) default(shared) private(k, b)
        do k = colours%offsets(colour), colours%offsets(colour + 1) - 1
          b = colours%corners(k)
          if (present(computed)) then
            if (.not. computed(b)) cycle
          end if
          call compute_shell_block(material, solver%geometry, solver%cell_nodes, solver%density, &
                                   solver%shear_factor, solver%thickness_points, solver%point_height, &
                                   solver%point_weight, solver%blocks(b), coordinates, velocity, angular_velocity, &
                                   dt, solver%cell_frame, solver%cell_area, solver%point_membrane, &
                                   solver%point_moment, solver%point_force, solver%point_couple, solver%station_offsets, &
                                   solver%station_node, solver%station_weight, solver%station_force, &
                                   solver%block_time_step(b), solver%block_critical_cell(b), &
                                   solver%block_failed_cell(b))
          call add_block_forces(solver%geometry, solver%cell_nodes, solver%blocks(b), solver%cell_frame, &
                                solver%cell_area, solver%point_force, solver%point_couple, solver%station_offsets, &
                                solver%station_node, solver%station_weight, solver%station_force, internal_force, &
                                internal_moment, normal_sum, area_sum)
        end do
        !$omp end parallel do
      end do
    end associate
  end subroutine compute_efg_shell_forces

  !> One block: kinematics, stress update, resultants, the forces' data per point and cell,
  !> energies, stable step (per cell) and the first failed cell (0: none; else its cell number).
  !> Allocates nothing.
  subroutine compute_shell_block(material, geometry, cell_nodes, density, shear_factor, thickness_points, &
                                 point_height, point_weight, block, coordinates, velocity, angular_velocity, dt, &
                                 cell_frame, cell_area, point_membrane, point_moment, point_force, point_couple, &
                                 station_offsets, station_node, station_weight, station_force, critical_time_step, &
                                 critical_cell, failed_cell)
    type(material_t), intent(in) :: material
    type(efg_shell_part_t), intent(in) :: geometry
    integer, intent(in) :: cell_nodes(:, :), thickness_points
    real(wp), intent(in) :: density, shear_factor, point_height(:), point_weight(:)
    type(efg_shell_block_t), intent(inout) :: block
    real(wp), intent(in), contiguous :: coordinates(:, :), velocity(:, :), angular_velocity(:, :)
    real(wp), intent(in) :: dt
    real(wp), intent(inout) :: cell_frame(:, :, :), cell_area(:), point_membrane(:, :), point_moment(:, :)
    real(wp), intent(inout) :: point_force(:, :, :), point_couple(:, :, :)
    integer, intent(in) :: station_offsets(:), station_node(:)
    real(wp), intent(in) :: station_weight(:)
    real(wp), intent(inout) :: station_force(:, :, :)
    real(wp), intent(out) :: critical_time_step
    integer, intent(out) :: critical_cell, failed_cell
    real(wp) :: mid_frame(3, 3, block_size), end_frame(3, 3, block_size), first_turn(block_size)
    real(wp) :: second_turn(block_size), spin(block_size), jacobian(block_size), thickness(block_size)
    real(wp) :: membrane(block_size, 3), curvature(block_size, 3), increment(block_size, 3)
    real(wp) :: thickness_increment(block_size), old_power(block_size), new_power(block_size)
    real(wp) :: velocity_sum(3, 2, block_size), rotation_sum(3, 2, block_size), end_inverse(2, 2, block_size)
    real(wp) :: corners(3, 4), corner_velocity(3, 4), node_velocity(3, 4)
    real(wp) :: physical_velocity(3, stations_per_cell), physical_rotation(3, stations_per_cell)
    real(wp) :: shear_weights(2, stations_per_cell, 3, 4), station_values(stations_per_cell, 3)
    real(wp) :: station_local(stations_per_cell, 3)
    real(wp) :: area_scale
    real(wp) :: position_sum(3, 2), inverse(2, 2), rate(2, 2), bend(2, 2), determinant
    real(wp) :: shear_modulus, height, gamma(2), transverse(2), resultant(6), weight, arm
    real(wp) :: area, wave_speed, cell_step
    integer :: nel, i, g, cell, lane, point, corner, k, first_point, station
    logical :: triangle

    nel = block%point_count
    failed_cell = 0
    shear_modulus = 0.0_wp
    if (material%law /= law_null) shear_modulus = material%youngs_modulus/(2.0_wp*(1.0_wp + material%poissons_ratio))
    wave_speed = shell_wave_speed(material, density)
    critical_time_step = huge(1.0_wp)
    critical_cell = 0

    ! per cell: mid-step and end frames, their turns from the last frame, the stable step
    do lane = 1, block%cell_count
      cell = block%first_cell + lane - 1
      do corner = 1, 4
        corners(:, corner) = coordinates(:, cell_nodes(corner, cell))
        corner_velocity(:, corner) = velocity(:, cell_nodes(corner, cell))
      end do
      end_frame(:, :, lane) = shell_cell_frame(corners)
      mid_frame(:, :, lane) = shell_cell_frame(corners - 0.5_wp*dt*corner_velocity)
      first_turn(lane) = atan2(dot_product(cell_frame(:, 1, cell), mid_frame(:, 2, lane)), &
                               dot_product(cell_frame(:, 1, cell), mid_frame(:, 1, lane)))
      second_turn(lane) = atan2(dot_product(mid_frame(:, 1, lane), end_frame(:, 2, lane)), &
                                dot_product(mid_frame(:, 1, lane), end_frame(:, 1, lane)))
      call cell_stable_step(corners, cell_nodes(3, cell) == cell_nodes(4, cell), wave_speed, area, cell_step)
      cell_area(cell) = area
      if (cell_step < critical_time_step) then
        critical_time_step = cell_step
        critical_cell = cell
      end if
      ! (a NaN area gives a NaN step: the group reports it as not finite)
      if (area /= area) then
        critical_time_step = area
        critical_cell = cell
      end if
    end do

    ! per point: rates at mid-step, F at the end, the power of the last call's forces
    do i = 1, nel
      g = block%first_point + i - 1
      cell = geometry%point_cell(g)
      lane = cell - block%first_cell + 1
      thickness(i) = geometry%cell_thickness(cell)
      call pair_sums(geometry%point_offsets(g), geometry%point_offsets(g + 1) - 1, geometry%pair_node, &
                     geometry%pair_gradient, coordinates, velocity, angular_velocity, position_sum, &
                     velocity_sum(:, :, i), rotation_sum(:, :, i))
      call in_plane_inverse(mid_frame(:, :, lane), position_sum - 0.5_wp*dt*velocity_sum(:, :, i), inverse, determinant)
      rate = local_gradient(mid_frame(:, :, lane), velocity_sum(:, :, i), inverse)
      bend = local_gradient(mid_frame(:, :, lane), rotation_sum(:, :, i), inverse)
      membrane(i, :) = [rate(1, 1), rate(2, 2), rate(1, 2) + rate(2, 1)]
      curvature(i, :) = [bend(2, 1), -bend(1, 2), bend(2, 2) - bend(1, 1)]
      ! half the material's spin over the step (the stress turns with it: module comment)
      spin(i) = 0.25_wp*dt*(rate(2, 1) - rate(1, 2))
      ! the power of the last call's forces f_I = P b_I, m_I = Q b_I: P : Vb + Q : Wb
      old_power(i) = sum(point_force(:, :, g)*velocity_sum(:, :, i)) + sum(point_couple(:, :, g)*rotation_sum(:, :, i))
      call in_plane_inverse(end_frame(:, :, lane), position_sum, end_inverse(:, :, i), jacobian(i))
      if (.not. jacobian(i) > 0.0_wp .and. failed_cell == 0) failed_cell = cell
    end do

    ! stresses into the mid-step frame, plane-stress update at every thickness point, into the
    ! end frame
    do i = 1, nel
      lane = geometry%point_cell(block%first_point + i - 1) - block%first_cell + 1
      call rotate_point_stress(block, material%law, i, thickness_points, spin(i) + first_turn(lane))
    end do
    do point = 1, thickness_points
      do i = 1, nel
        height = point_height(point)*thickness(i)
        increment(i, :) = dt*(membrane(i, :) + height*curvature(i, :))
      end do
      call update_plane_stress_block(material, nel, dt, increment, block%stress(:, :, point), &
                                     block%history(:, :, point), thickness_increment)
    end do
    do i = 1, nel
      g = block%first_point + i - 1
      lane = geometry%point_cell(g) - block%first_cell + 1
      call rotate_point_stress(block, material%law, i, thickness_points, spin(i) + second_turn(lane))
      ! resultants per unit current length, times the point's current area W J
      resultant = 0.0_wp
      do point = 1, thickness_points
        weight = point_weight(point)*thickness(i)
        arm = point_height(point)*thickness(i)
        resultant(1:3) = resultant(1:3) + weight*block%stress(i, :, point)
        resultant(4:6) = resultant(4:6) + weight*arm*block%stress(i, :, point)
      end do
      resultant = geometry%point_area(g)*jacobian(i)*resultant
      point_membrane(:, g) = resultant(1:3)
      point_moment(:, g) = resultant(4:6)
      call forces_of_point(end_frame(:, :, lane), end_inverse(:, :, i), resultant, point_force(:, :, g), &
                           point_couple(:, :, g))
      new_power(i) = sum(point_force(:, :, g)*velocity_sum(:, :, i)) + sum(point_couple(:, :, g)*rotation_sum(:, :, i))
    end do
    call add_force_work(nel, dt, block%previous_time_step, old_power, new_power, block%force_power, &
                        block%internal_energy)

    ! transverse shear: assumed strain on the cells' physical station values (module comment)
    do lane = 1, block%cell_count
      cell = block%first_cell + lane - 1
      triangle = cell_nodes(3, cell) == cell_nodes(4, cell)
      do corner = 1, 4
        corners(:, corner) = coordinates(:, cell_nodes(corner, cell))
        node_velocity(:, corner) = velocity(:, cell_nodes(corner, cell))
      end do
      do station = 1, stations_per_cell
        physical_velocity(:, station) = 0.0_wp
        physical_rotation(:, station) = 0.0_wp
        do k = station_offsets(stations_per_cell*(cell - 1) + station), &
               station_offsets(stations_per_cell*(cell - 1) + station + 1) - 1
          physical_velocity(:, station) = physical_velocity(:, station) + station_weight(k)*velocity(:, station_node(k))
          physical_rotation(:, station) = physical_rotation(:, station) + &
                                          station_weight(k)*angular_velocity(:, station_node(k))
        end do
      end do
      old_power(lane) = sum(station_force(1:3, :, cell)*physical_velocity) + sum(station_force(4:6, :, cell)*physical_rotation)
      ! rates on the mid-step corners and frame
      call shear_operator(mid_frame(:, :, lane), corners - 0.5_wp*dt*node_velocity, triangle, shear_weights)
      call local_station_values(mid_frame(:, :, lane), physical_velocity, physical_rotation, station_values)
      first_point = first_point_in_block(geometry, block, cell)
      do point = 1, merge(3, 4, triangle)
        i = first_point + point - 1
        gamma = shear_rate(shear_weights(:, :, :, point), station_values)
        call rotate_shear_stress(block, i, spin(i) + first_turn(lane))
        block%shear_stress(i, :) = block%shear_stress(i, :) + shear_factor*shear_modulus*dt*gamma
        call rotate_shear_stress(block, i, spin(i) + second_turn(lane))
      end do
      ! forces on the end-of-step corners: the transposes, times each point's current area
      call shear_operator(end_frame(:, :, lane), corners, triangle, shear_weights)
      area_scale = cell_area(cell)/geometry%cell_area(cell)
      station_local = 0.0_wp
      do point = 1, merge(3, 4, triangle)
        i = first_point + point - 1
        transverse = geometry%point_area(block%first_point + i - 1)*area_scale*geometry%cell_thickness(cell) &
                     *block%shear_stress(i, :)
        station_local = station_local + transverse(1)*shear_weights(1, :, :, point) &
                        + transverse(2)*shear_weights(2, :, :, point)
      end do
      do station = 1, stations_per_cell
        station_force(1:3, station, cell) = station_local(station, 1)*end_frame(:, 3, lane)
        station_force(4:6, station, cell) = station_local(station, 2)*end_frame(:, 1, lane) &
                                            + station_local(station, 3)*end_frame(:, 2, lane)
      end do
      new_power(lane) = sum(station_force(1:3, :, cell)*physical_velocity) + sum(station_force(4:6, :, cell)*physical_rotation)
      cell_frame(:, :, cell) = end_frame(:, :, lane)
    end do
    call add_force_work(block%cell_count, dt, block%previous_time_step, old_power, new_power, block%shear_power, &
                        block%shear_energy)
    block%previous_time_step = dt
  end subroutine compute_shell_block

  !> Xb, Vb, Wb = sums of x, v, w (x) b over the pairs first..last.
  pure subroutine pair_sums(first, last, pair_node, pair_gradient, coordinates, velocity, angular_velocity, &
                            position_sum, velocity_sum, rotation_sum)
    integer, intent(in) :: first, last, pair_node(:)
    real(wp), intent(in) :: pair_gradient(:, :)
    real(wp), intent(in) :: coordinates(:, :), velocity(:, :), angular_velocity(:, :)
    real(wp), intent(out) :: position_sum(3, 2), velocity_sum(3, 2), rotation_sum(3, 2)
    real(wp) :: b1, b2
    integer :: k, node
    position_sum = 0.0_wp
    velocity_sum = 0.0_wp
    rotation_sum = 0.0_wp
    do k = first, last
      node = pair_node(k)
      b1 = pair_gradient(1, k)
      b2 = pair_gradient(2, k)
      position_sum(:, 1) = position_sum(:, 1) + coordinates(:, node)*b1
      position_sum(:, 2) = position_sum(:, 2) + coordinates(:, node)*b2
      velocity_sum(:, 1) = velocity_sum(:, 1) + velocity(:, node)*b1
      velocity_sum(:, 2) = velocity_sum(:, 2) + velocity(:, node)*b2
      rotation_sum(:, 1) = rotation_sum(:, 1) + angular_velocity(:, node)*b1
      rotation_sum(:, 2) = rotation_sum(:, 2) + angular_velocity(:, node)*b2
    end do
  end subroutine pair_sums

  !> G = F^-T of the in-plane deformation gradient F = E2 Xb (rows e1, e2 of the frame) and
  !> det F (a singular F gives G = 0: the caller reports the cell).
  pure subroutine in_plane_inverse(frame, position_sum, inverse, determinant)
    real(wp), intent(in) :: frame(3, 3), position_sum(3, 2)
    real(wp), intent(out) :: inverse(2, 2), determinant
    real(wp) :: f(2, 2), scale
    f(1, 1) = dot_product(frame(:, 1), position_sum(:, 1))
    f(1, 2) = dot_product(frame(:, 1), position_sum(:, 2))
    f(2, 1) = dot_product(frame(:, 2), position_sum(:, 1))
    f(2, 2) = dot_product(frame(:, 2), position_sum(:, 2))
    determinant = f(1, 1)*f(2, 2) - f(1, 2)*f(2, 1)
    scale = 0.0_wp
    if (determinant /= 0.0_wp .and. determinant == determinant) scale = 1.0_wp/determinant
    ! F^-T = [f22 -f21; -f12 f11] / det
    inverse(1, 1) = f(2, 2)*scale
    inverse(1, 2) = -f(2, 1)*scale
    inverse(2, 1) = -f(1, 2)*scale
    inverse(2, 2) = f(1, 1)*scale
  end subroutine in_plane_inverse

  !> (E2 S) G^T: the local gradient L(a, b) = sum_I (e_a . s_I) g_Ib of a nodal field s whose
  !> pair sum is S = sum s_I (x) b_I, with g_I = G b_I.
  pure function local_gradient(frame, field_sum, inverse) result(gradient)
    real(wp), intent(in) :: frame(3, 3), field_sum(3, 2), inverse(2, 2)
    real(wp) :: gradient(2, 2), projected(2, 2)
    integer :: a, b
    do b = 1, 2
      do a = 1, 2
        projected(a, b) = dot_product(frame(:, a), field_sum(:, b))
      end do
    end do
    do b = 1, 2
      do a = 1, 2
        gradient(a, b) = projected(a, 1)*inverse(b, 1) + projected(a, 2)*inverse(b, 2)
      end do
    end do
  end function local_gradient

  !> The first lane of a cell's points in its block.
  pure integer function first_point_in_block(geometry, block, cell) result(lane)
    type(efg_shell_part_t), intent(in) :: geometry
    type(efg_shell_block_t), intent(in) :: block
    integer, intent(in) :: cell
    do lane = 1, block%point_count
      if (geometry%point_cell(block%first_point + lane - 1) == cell) return
    end do
    lane = 0
  end function first_point_in_block

  !> Local station values (v_z, w_x, w_y) of the physical velocities and angular velocities.
  pure subroutine local_station_values(frame, velocity, rotation, values)
    real(wp), intent(in) :: frame(3, 3), velocity(3, stations_per_cell), rotation(3, stations_per_cell)
    real(wp), intent(out) :: values(stations_per_cell, 3)
    integer :: station
    do station = 1, stations_per_cell
      values(station, 1) = dot_product(frame(:, 3), velocity(:, station))
      values(station, 2) = dot_product(frame(:, 1), rotation(:, station))
      values(station, 3) = dot_product(frame(:, 2), rotation(:, station))
    end do
  end subroutine local_station_values

  !> (2 d_xz, 2 d_yz) of one point from its shear_weights and the local station values.
  pure function shear_rate(shear_weights, values) result(gamma)
    real(wp), intent(in) :: shear_weights(2, stations_per_cell, 3), values(stations_per_cell, 3)
    real(wp) :: gamma(2)
    gamma(1) = sum(shear_weights(1, :, :)*values)
    gamma(2) = sum(shear_weights(2, :, :)*values)
  end function shear_rate

  !> The transverse shear operator of a cell at its membrane/bending points:
  !> (2 d_xz, 2 d_yz) at point p = sum over corners L and local dofs (v_z, w_x, w_y) of
  !> shear_weights(:, L, dof, p) times the corner's value. A quadrilateral takes MITC4 (Bathe &
  !> Dvorkin 1985): the covariant shear at the midpoint of each edge (i, j),
  !> gamma_e = (w_j - w_i)/2 + g_x (th_y,i + th_y,j)/2 - g_y (th_x,i + th_x,j)/2 with
  !> g = (x_j - x_i)/2, interpolated linearly across the cell (gamma_xi between edges 1-2 and 4-3,
  !> gamma_eta between edges 1-4 and 2-3) to the sub-cell points (+-1/2, +-1/2) and turned into
  !> Cartesian components with the point's Jacobian. A Kirchhoff mode (w quadratic, theta its
  !> gradient) gives zero at every edge midpoint of any quadrilateral. A triangle (corner 4 =
  !> corner 3) takes the edge-based constant shear of the FE triangle (shell_triangle) at its
  !> three points.
  pure subroutine shear_operator(frame, corners, triangle, shear_weights)
    real(wp), intent(in) :: frame(3, 3), corners(3, 4)
    logical, intent(in) :: triangle
    real(wp), intent(out) :: shear_weights(2, stations_per_cell, 3, 4)
    real(wp), parameter :: point_xi(4) = [-0.5_wp, 0.5_wp, 0.5_wp, -0.5_wp]
    real(wp), parameter :: point_eta(4) = [-0.5_wp, -0.5_wp, 0.5_wp, 0.5_wp]
    real(wp) :: xl(4), yl(4)
    real(wp) :: edge_a(stations_per_cell, 3), edge_b(stations_per_cell, 3), edge_c(stations_per_cell, 3)
    real(wp) :: edge_d(stations_per_cell, 3), along_xi(stations_per_cell, 3), along_eta(stations_per_cell, 3)
    real(wp) :: x_xi, y_xi, x_eta, y_eta, determinant, xi, eta
    integer :: corner, point
    do corner = 1, 4
      xl(corner) = dot_product(frame(:, 1), corners(:, corner) - corners(:, 1))
      yl(corner) = dot_product(frame(:, 2), corners(:, corner) - corners(:, 1))
    end do
    shear_weights = 0.0_wp
    if (triangle) then
      call triangle_shear_weights(xl(1:3), yl(1:3), shear_weights(:, :, :, 1))
      do point = 2, 3
        shear_weights(:, :, :, point) = shear_weights(:, :, :, 1)
      end do
      return
    end if
    ! tying points A (edge 1-2), B (2-3), C (4-3), D (1-4), along xi for A, C and eta for B, D
    edge_a = edge_operator(1, 2, 5)
    edge_b = edge_operator(2, 3, 6)
    edge_c = edge_operator(4, 3, 7)
    edge_d = edge_operator(1, 4, 8)
    do point = 1, 4
      xi = point_xi(point)
      eta = point_eta(point)
      along_xi = 0.5_wp*(1.0_wp - eta)*edge_a + 0.5_wp*(1.0_wp + eta)*edge_c
      along_eta = 0.5_wp*(1.0_wp - xi)*edge_d + 0.5_wp*(1.0_wp + xi)*edge_b
      x_xi = 0.25_wp*((1.0_wp - eta)*(xl(2) - xl(1)) + (1.0_wp + eta)*(xl(3) - xl(4)))
      y_xi = 0.25_wp*((1.0_wp - eta)*(yl(2) - yl(1)) + (1.0_wp + eta)*(yl(3) - yl(4)))
      x_eta = 0.25_wp*((1.0_wp - xi)*(xl(4) - xl(1)) + (1.0_wp + xi)*(xl(3) - xl(2)))
      y_eta = 0.25_wp*((1.0_wp - xi)*(yl(4) - yl(1)) + (1.0_wp + xi)*(yl(3) - yl(2)))
      determinant = x_xi*y_eta - y_xi*x_eta
      if (determinant == 0.0_wp) cycle
      ! [gamma_xi, gamma_eta] = J [gamma_x, gamma_y], J = [[x_xi, y_xi], [x_eta, y_eta]]
      shear_weights(1, :, :, point) = (y_eta*along_xi - y_xi*along_eta)/determinant
      shear_weights(2, :, :, point) = (-x_eta*along_xi + x_xi*along_eta)/determinant
    end do
  contains
    !> Weights of the covariant shear of edge (i, j), averaged along the edge, on the station
    !> values: (w_j - w_i)/2 - the edge average of theta . (e3 x g), the rotations' average by
    !> Simpson's rule on the corners i, j and the edge's midpoint station m.
    pure function edge_operator(i, j, m) result(weights)
      integer, intent(in) :: i, j, m
      real(wp) :: weights(stations_per_cell, 3), gx, gy
      gx = 0.5_wp*(xl(j) - xl(i))
      gy = 0.5_wp*(yl(j) - yl(i))
      weights = 0.0_wp
      weights(i, 1) = -0.5_wp
      weights(j, 1) = 0.5_wp
      weights([i, j], 2) = -gy/6.0_wp
      weights(m, 2) = -4.0_wp*gy/6.0_wp
      weights([i, j], 3) = gx/6.0_wp
      weights(m, 3) = 4.0_wp*gx/6.0_wp
    end function edge_operator
  end subroutine shear_operator

  !> The constant transverse shear of a triangle cell (corners 1-3, midpoint stations 5, 6, 7 of
  !> its edges 1-2, 2-3, 3-1): the FE triangle's edge-based operator (shell_triangle: the shear
  !> along each edge at its middle, least-squares fitted), with each edge's mean rotation taken
  !> by Simpson's rule on its corners and its midpoint station instead of its corners' mean.
  pure subroutine triangle_shear_weights(xl, yl, weights)
    real(wp), intent(in) :: xl(3), yl(3)
    real(wp), intent(out) :: weights(2, stations_per_cell, 3)
    real(wp) :: tangent(2, 3), length(3), fit(2, 3)
    integer :: edge, first, second, middle
    call triangle_edge_fit(xl, yl, tangent, length, fit)
    weights = 0.0_wp
    do edge = 1, 3
      first = edge
      second = modulo(edge, 3) + 1
      middle = 4 + edge
      weights(:, first, 1) = weights(:, first, 1) - fit(:, edge)/length(edge)
      weights(:, second, 1) = weights(:, second, 1) + fit(:, edge)/length(edge)
      weights(:, first, 3) = weights(:, first, 3) + tangent(1, edge)*fit(:, edge)/6.0_wp
      weights(:, second, 3) = weights(:, second, 3) + tangent(1, edge)*fit(:, edge)/6.0_wp
      weights(:, middle, 3) = weights(:, middle, 3) + 4.0_wp*tangent(1, edge)*fit(:, edge)/6.0_wp
      weights(:, first, 2) = weights(:, first, 2) - tangent(2, edge)*fit(:, edge)/6.0_wp
      weights(:, second, 2) = weights(:, second, 2) - tangent(2, edge)*fit(:, edge)/6.0_wp
      weights(:, middle, 2) = weights(:, middle, 2) - 4.0_wp*tangent(2, edge)*fit(:, edge)/6.0_wp
    end do
  end subroutine triangle_shear_weights

  !> Turn lane i's transverse shear stress (zx, yz) as an in-plane vector by `angle`.
  pure subroutine rotate_shear_stress(block, i, angle)
    type(efg_shell_block_t), intent(inout) :: block
    integer, intent(in) :: i
    real(wp), intent(in) :: angle
    real(wp) :: c, s, first, second
    c = cos(angle)
    s = sin(angle)
    first = block%shear_stress(i, 1)
    second = block%shear_stress(i, 2)
    block%shear_stress(i, 1) = c*first - s*second
    block%shear_stress(i, 2) = s*first + c*second
  end subroutine rotate_shear_stress

  !> A point's forces and moments on its pairs as global f_I = P b_I and m_I = Q b_I, from the
  !> end frame, G = F^-T and the resultants times W J (N: xx, yy, xy; M: xx, yy, xy): with
  !> g_I = G b_I the local force is (N g_I) and the local moment about e1, e2 is
  !> (-M_xy g_1 - M_yy g_2, M_xx g_1 + M_xy g_2), the transposes of the rates (module comment).
  pure subroutine forces_of_point(frame, inverse, resultant, force, couple)
    real(wp), intent(in) :: frame(3, 3), inverse(2, 2), resultant(6)
    real(wp), intent(out) :: force(3, 2), couple(3, 2)
    real(wp) :: local_force(2, 2), local_couple(2, 2)
    integer :: c
    do c = 1, 2
      local_force(1, c) = resultant(1)*inverse(1, c) + resultant(3)*inverse(2, c)
      local_force(2, c) = resultant(3)*inverse(1, c) + resultant(2)*inverse(2, c)
      local_couple(1, c) = -resultant(6)*inverse(1, c) - resultant(5)*inverse(2, c)
      local_couple(2, c) = resultant(4)*inverse(1, c) + resultant(6)*inverse(2, c)
      force(:, c) = local_force(1, c)*frame(:, 1) + local_force(2, c)*frame(:, 2)
      couple(:, c) = local_couple(1, c)*frame(:, 1) + local_couple(2, c)*frame(:, 2)
    end do
  end subroutine forces_of_point

  !> Turn lane i's stresses (every thickness point) by `angle` (components kept in a frame that
  !> turned by phi while the material turned by psi turn by psi - phi: shell_block's
  !> rotate_with_material). Tensor history (the rubbers' b, the viscoelastic branch) turns with
  !> the stress.
  pure subroutine rotate_point_stress(block, law, i, thickness_points, angle)
    type(efg_shell_block_t), intent(inout) :: block
    integer, intent(in) :: law, i, thickness_points
    real(wp), intent(in) :: angle
    real(wp) :: c, s, sxx, syy, sxy
    integer :: point
    c = cos(angle)
    s = sin(angle)
    do point = 1, thickness_points
      sxx = block%stress(i, 1, point)
      syy = block%stress(i, 2, point)
      sxy = block%stress(i, 3, point)
      block%stress(i, 1, point) = c*c*sxx - 2.0_wp*c*s*sxy + s*s*syy
      block%stress(i, 2, point) = s*s*sxx + 2.0_wp*c*s*sxy + c*c*syy
      block%stress(i, 3, point) = c*s*(sxx - syy) + (c*c - s*s)*sxy
      if (size(block%history, 2) > 0) call rotate_plane_stress_history(law, c, s, block%history(i, :, point))
    end do
  end subroutine rotate_point_stress

  !> The block's forces and moments into the nodes: point by point, pair by pair (a node
  !> appears once among a point's pairs), then cell by cell its shear pairs and its corners'
  !> normal and area sums.
  subroutine add_block_forces(geometry, cell_nodes, block, cell_frame, cell_area, point_force, point_couple, &
                              station_offsets, station_node, station_weight, station_force, internal_force, &
                              internal_moment, normal_sum, area_sum)
    type(efg_shell_part_t), intent(in) :: geometry
    integer, intent(in) :: cell_nodes(:, :)
    type(efg_shell_block_t), intent(in) :: block
    real(wp), intent(in) :: cell_frame(:, :, :), cell_area(:), point_force(:, :, :), point_couple(:, :, :)
    integer, intent(in) :: station_offsets(:), station_node(:)
    real(wp), intent(in) :: station_weight(:), station_force(:, :, :)
    real(wp), intent(inout) :: internal_force(:, :), internal_moment(:, :), normal_sum(:, :), area_sum(:)
    real(wp) :: p(3, 2), q(3, 2), b1, b2, weight
    integer :: gp, k, node, cell, corner, station
    do gp = block%first_point, block%first_point + block%point_count - 1
      p = point_force(:, :, gp)
      q = point_couple(:, :, gp)
      do k = geometry%point_offsets(gp), geometry%point_offsets(gp + 1) - 1
        node = geometry%pair_node(k)
        b1 = geometry%pair_gradient(1, k)
        b2 = geometry%pair_gradient(2, k)
        internal_force(:, node) = internal_force(:, node) + (p(:, 1)*b1 + p(:, 2)*b2)
        internal_moment(:, node) = internal_moment(:, node) + (q(:, 1)*b1 + q(:, 2)*b2)
      end do
    end do
    do cell = block%first_cell, block%first_cell + block%cell_count - 1
      ! the shear forces on the stations' physical values, through each station's row (A^T)
      do station = 1, stations_per_cell
        if (station == 4 .and. cell_nodes(4, cell) == cell_nodes(3, cell)) cycle
        do k = station_offsets(stations_per_cell*(cell - 1) + station), &
               station_offsets(stations_per_cell*(cell - 1) + station + 1) - 1
          node = station_node(k)
          weight = station_weight(k)
          internal_force(:, node) = internal_force(:, node) + weight*station_force(1:3, station, cell)
          internal_moment(:, node) = internal_moment(:, node) + weight*station_force(4:6, station, cell)
        end do
      end do
      do corner = 1, 4
        if (corner == 4 .and. cell_nodes(4, cell) == cell_nodes(3, cell)) cycle
        node = cell_nodes(corner, cell)
        normal_sum(:, node) = normal_sum(:, node) + cell_area(cell)*cell_frame(:, 3, cell)
        area_sum(node) = area_sum(node) + cell_area(cell)
      end do
    end do
  end subroutine add_block_forces

  pure function cross_product(a, b) result(c)
    real(wp), intent(in) :: a(3), b(3)
    real(wp) :: c(3)
    c = [a(2)*b(3) - a(3)*b(2), a(3)*b(1) - a(1)*b(3), a(1)*b(2) - a(2)*b(1)]
  end function cross_product

  !> Physical values at the interior particles (uhat = sum Psi_I(X_J) d_I): physical(:, J) for
  !> every particle J; other nodes are left as they are (Gamma nodes carry physical values).
  subroutine transform_shell_to_physical(solver, field, physical)
    type(efg_shell_solver_t), intent(in) :: solver
    real(wp), intent(in) :: field(:, :)
    real(wp), intent(inout) :: physical(:, :)
    integer :: j, k
    real(wp) :: value(3)
    associate (geometry => solver%geometry)
      do j = 1, size(geometry%particles)
        value = 0.0_wp
        do k = geometry%transform_offsets(j), geometry%transform_offsets(j + 1) - 1
          value = value + geometry%transform_value(k)*field(:, geometry%transform_node(k))
        end do
        physical(:, geometry%particles(j)) = value
      end do
    end associate
  end subroutine transform_shell_to_physical

  !> The transpose: forces `physical` acting on the physical values (uhat = A d) become the
  !> generalized forces A^T f in `generalized`, which holds the same forces on entry. A
  !> particle's own entry is replaced by what the rows give it; its physical force goes to the
  !> nodes of its row with the row's weights (rows sum to one: the total force, hence momentum,
  !> is kept). Particle by particle, in order: the same sum for any thread count.
  subroutine transpose_shell_to_generalized(solver, physical, generalized)
    type(efg_shell_solver_t), intent(in) :: solver
    real(wp), intent(in) :: physical(:, :)
    real(wp), intent(inout) :: generalized(:, :)
    integer :: j, k, node
    associate (geometry => solver%geometry)
      do j = 1, size(geometry%particles)
        generalized(:, geometry%particles(j)) = 0.0_wp
      end do
      do j = 1, size(geometry%particles)
        do k = geometry%transform_offsets(j), geometry%transform_offsets(j + 1) - 1
          node = geometry%transform_node(k)
          generalized(:, node) = generalized(:, node) + geometry%transform_value(k)*physical(:, geometry%particles(j))
        end do
      end do
    end associate
  end subroutine transpose_shell_to_generalized

  !> Per cell (column cells(c) of the outputs): the mean over its points and thickness points
  !> of the local stresses, in global axes; the point of largest von Mises stress; the mean and
  !> largest effective plastic strain.
  subroutine efg_shell_cell_results(material, solver, mid_stress, peak_stress, mean_plastic_strain, &
                                    peak_plastic_strain, point_stress, point_plastic_strain, point_count, &
                                    resultant, thickness, energy_density)
    type(material_t), intent(in) :: material
    type(efg_shell_solver_t), intent(in) :: solver
    real(wp), intent(inout) :: mid_stress(:, :), peak_stress(:, :), mean_plastic_strain(:), peak_plastic_strain(:)
    !> For the d3plot, as the FE shells' (shell_block_element_results): per cell, each thickness
    !> point's stress (global) and plastic strain, bottom to top, as the area-weighted mean of its
    !> sub-cell points; the resultants per unit width in the cell's frame (M_xx M_yy M_xy Q_x Q_y
    !> N_xx N_yy N_xy); the thickness; the internal energy (membrane, bending and transverse
    !> shear work) per unit current volume.
    real(wp), intent(inout), optional :: point_stress(:, :, :), point_plastic_strain(:, :)
    integer, intent(inout), optional :: point_count(:)
    real(wp), intent(inout), optional :: resultant(:, :), thickness(:), energy_density(:)
    real(wp) :: point_strain(block_size, max_shell_points), local(5), mean(5), peak(5), effective, largest
    real(wp) :: weight_sum, area, mean_strain, peak_strain, layer(5, max_shell_points), layer_strain(max_shell_points)
    real(wp) :: through(5), moment(3), height, energy, volume
    integer :: b, c, i, point, shell, lane, written
    do b = 1, size(solver%blocks)
      associate (block => solver%blocks(b), geometry => solver%geometry)
        point_strain = 0.0_wp
        if (size(block%history, 2) > 0) then
          do point = 1, solver%thickness_points
            call plane_stress_plastic_strain(material, block%point_count, block%history(:, :, point), &
                                             point_strain(:, point))
          end do
        end if
        do c = block%first_cell, block%first_cell + block%cell_count - 1
          lane = c - block%first_cell + 1
          mean = 0.0_wp
          peak = 0.0_wp
          largest = -1.0_wp
          weight_sum = 0.0_wp
          mean_strain = 0.0_wp
          peak_strain = 0.0_wp
          layer = 0.0_wp
          layer_strain = 0.0_wp
          energy = block%shear_energy(lane)
          do i = 1, block%point_count
            if (geometry%point_cell(block%first_point + i - 1) /= c) cycle
            area = geometry%point_area(block%first_point + i - 1)
            do point = 1, solver%thickness_points
              local = [block%stress(i, :, point), block%shear_stress(i, 2), block%shear_stress(i, 1)]
              mean = mean + solver%point_weight(point)*area*local
              layer(:, point) = layer(:, point) + area*local
              layer_strain(point) = layer_strain(point) + area*point_strain(i, point)
              mean_strain = mean_strain + solver%point_weight(point)*area*point_strain(i, point)
              peak_strain = max(peak_strain, point_strain(i, point))
              effective = local(1)**2 - local(1)*local(2) + local(2)**2 + 3.0_wp*(local(3)**2 + local(4)**2 + local(5)**2)
              if (effective > largest) then
                largest = effective
                peak = local
              end if
            end do
            weight_sum = weight_sum + area
            energy = energy + block%internal_energy(i)
          end do
          if (weight_sum > 0.0_wp) then
            mean = mean/weight_sum
            mean_strain = mean_strain/weight_sum
            layer = layer/weight_sum
            layer_strain = layer_strain/weight_sum
          end if
          shell = geometry%cells(c)
          mid_stress(:, shell) = global_stress(solver%cell_frame(:, :, c), mean)
          peak_stress(:, shell) = global_stress(solver%cell_frame(:, :, c), peak)
          mean_plastic_strain(shell) = mean_strain
          peak_plastic_strain(shell) = peak_strain
          if (.not. present(point_stress)) cycle
          ! the d3plot's layers, resultants, thickness and energy density (as the FE shells')
          written = min(solver%thickness_points, size(point_stress, 2))
          point_count(shell) = written
          do point = 1, written
            point_stress(:, point, shell) = global_stress(solver%cell_frame(:, :, c), layer(:, point))
            point_plastic_strain(point, shell) = layer_strain(point)
          end do
          through = 0.0_wp
          moment = 0.0_wp
          do point = 1, solver%thickness_points
            height = solver%point_height(point)
            through = through + solver%point_weight(point)*layer(:, point)
            moment = moment + solver%point_weight(point)*height*layer(1:3, point)
          end do
          resultant(1:3, shell) = geometry%cell_thickness(c)**2*moment
          resultant(4, shell) = geometry%cell_thickness(c)*through(5)
          resultant(5, shell) = geometry%cell_thickness(c)*through(4)
          resultant(6:8, shell) = geometry%cell_thickness(c)*through(1:3)
          thickness(shell) = geometry%cell_thickness(c)
          ! (0 for a volume so small or values so large that the quotient would overflow)
          volume = solver%cell_area(c)*geometry%cell_thickness(c)
          energy_density(shell) = 0.0_wp
          if (ieee_is_finite(volume) .and. ieee_is_finite(energy)) then
            if (volume >= 1.0_wp) then
              energy_density(shell) = energy/volume
            else if (abs(energy) < huge(1.0_wp)*volume) then
              energy_density(shell) = energy/volume
            end if
          end if
        end do
      end associate
    end do
  end subroutine efg_shell_cell_results

  !> The largest effective plastic strain over the points of each cell, raised into its corner
  !> nodes that `wanted` flags (the nodes of spot welds that fail by EP / EPSF), as the FE shells.
  subroutine raise_corner_plastic_strain(material, solver, wanted, strain, computed)
    type(material_t), intent(in) :: material
    type(efg_shell_solver_t), intent(in) :: solver
    logical, intent(in) :: wanted(:)
    real(wp), intent(inout) :: strain(:)
    !> A distributed run: the part's blocks this rank computes (the others' state is old here;
    !> the solver takes the largest over the ranks). Absent: all.
    logical, intent(in), optional :: computed(:)
    real(wp) :: point_strain(block_size), largest(block_size)
    integer :: b, point, i, c, corner, node
    do b = 1, size(solver%blocks)
      if (present(computed)) then
        if (.not. computed(b)) cycle
      end if
      associate (block => solver%blocks(b))
        if (size(block%history, 2) == 0) cycle
        largest = 0.0_wp
        do point = 1, solver%thickness_points
          call plane_stress_plastic_strain(material, block%point_count, block%history(:, :, point), point_strain)
          do i = 1, block%point_count
            c = solver%geometry%point_cell(block%first_point + i - 1) - block%first_cell + 1
            largest(c) = max(largest(c), point_strain(i))
          end do
        end do
        do c = 1, block%cell_count
          do corner = 1, 4
            node = solver%cell_nodes(corner, block%first_cell + c - 1)
            if (wanted(node)) strain(node) = max(strain(node), largest(c))
          end do
        end do
      end associate
    end do
  end subroutine raise_corner_plastic_strain

  !> Global components (xx, yy, zz, xy, yz, zx) of a local shell stress (xx, yy, xy, yz, zx):
  !> sigma = E s E^T with the columns of E the frame vectors.
  pure function global_stress(frame, local) result(stress)
    real(wp), intent(in) :: frame(3, 3), local(5)
    real(wp) :: stress(6), s(3, 3), g(3, 3)
    s = reshape([local(1), local(3), local(5), local(3), local(2), local(4), local(5), local(4), 0.0_wp], [3, 3])
    g = matmul(frame, matmul(s, transpose(frame)))
    stress = [g(1, 1), g(2, 2), g(3, 3), g(1, 2), g(2, 3), g(3, 1)]
  end function global_stress

  !> The plane-stress wave speed sqrt(E / (rho (1 - nu^2))) of a part's cells (0: a material
  !> without Young's modulus sets no step).
  pure real(wp) function shell_wave_speed(material, density) result(wave_speed)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: density
    wave_speed = 0.0_wp
    if (material%youngs_modulus > 0.0_wp .and. density > 0.0_wp) &
      wave_speed = sqrt(material%youngs_modulus/(density*(1.0_wp - material%poissons_ratio**2)))
  end function shell_wave_speed

  !> A cell's area and stable step on its corners: LS-DYNA's characteristic length of a shell,
  !> (1 + beta) A / longest side (beta = 1 on a triangle), over the wave speed (huge without one).
  pure subroutine cell_stable_step(corners, triangle, wave_speed, area, step)
    real(wp), intent(in) :: corners(3, 4), wave_speed
    logical, intent(in) :: triangle
    real(wp), intent(out) :: area, step
    real(wp) :: longest
    integer :: corner
    area = 0.5_wp*norm2(cross_product(corners(:, 3) - corners(:, 1), corners(:, 4) - corners(:, 2)))
    longest = 0.0_wp
    do corner = 1, 4
      longest = max(longest, norm2(corners(:, modulo(corner, 4) + 1) - corners(:, corner)))
    end do
    step = huge(1.0_wp)
    if (wave_speed > 0.0_wp) step = merge(2.0_wp, 1.0_wp, triangle)*area/max(longest, tiny(1.0_wp))/wave_speed
  end subroutine cell_stable_step

  !> Stable step (no TSSFAC) of every cell of one part on the current coordinates: the force
  !> call's rule (compute_shell_block), for d3hsp's table of the smallest steps.
  subroutine efg_shell_cell_time_steps(material, solver, coordinates, cell_time_step)
    type(material_t), intent(in) :: material
    type(efg_shell_solver_t), intent(in) :: solver
    real(wp), intent(in), contiguous :: coordinates(:, :)
    real(wp), intent(out) :: cell_time_step(:)        !< (cells)
    real(wp) :: corners(3, 4), area, wave_speed
    integer :: cell, corner
    wave_speed = shell_wave_speed(material, solver%density)
    do cell = 1, size(solver%cell_nodes, 2)
      do corner = 1, 4
        corners(:, corner) = coordinates(:, solver%cell_nodes(corner, cell))
      end do
      call cell_stable_step(corners, solver%cell_nodes(3, cell) == solver%cell_nodes(4, cell), wave_speed, area, &
                            cell_time_step(cell))
    end do
  end subroutine efg_shell_cell_time_steps
end module efg_shell_forces
