!> Explicit update of the meshfree (EFG) shells (*SECTION_SHELL ELFORM 41): a corotational
!> Mindlin-Reissner shell whose integration points see N (node, gradient) pairs instead of four
!> corners (Wu, Guo, Wang & Botkin 2004, "A mesh-free analysis of shell structures", 8th Int.
!> LS-DYNA Users Conference: Lagrangian MLS functions on the undeformed surface, co-rotational
!> update as in the Belytschko-Tsay shell, stabilized conforming (sub-cell) integration of the
!> membrane and bending strains, one-point transverse shear per background cell against
!> locking). The geometry (pairs, smoothed gradients, shear point, masses, transformation) comes
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
!> Transverse shear at the cell's shear point (Psi_I, b^s_I at the centre): 2 d_xz = sum
!> g^s_1 vl_z + Psi wl_y, 2 d_yz = sum g^s_2 vl_z - Psi wl_x, elastic with SHRF G, uniform
!> through the thickness as in shell_block.
!>
!> Energies are the exact work of the nodal forces and moments (element_work's add_force_work,
!> as efg_forces and shell_block). Their power needs no pair loop: with the sums Vb, Wb of a
!> point, the power of any forces given by (E, G, W J N, W J M) is W J (N : L + M : k); the
!> forces of the last call (kept per point) against this step's velocities complete the last
!> step's work.
!>
!> Blocks are runs of whole cells, at most block_size membrane/bending points each (a lane per
!> point for the materials; the block's cells and their shear points go with it). Blocks are
!> coloured by the nodes of their pairs and corners, so the blocks of one colour share no node:
!> colours one after another, the blocks of a colour in parallel, each node receives its
!> contributions in the same order for any thread count.
module efg_shell_forces
  use kinds, only: wp, block_size
  use gather_list, only: gather_list_t
  use block_colouring, only: colour_blocks_by_node_lists
  use model, only: model_t, material_t, law_null
  use efg_shell_part, only: efg_shell_part_t, shell_cell_frame
  use plane_stress_dispatch, only: plane_stress_history_count, initialize_plane_stress_history, &
                                   update_plane_stress_block, plane_stress_plastic_strain
  use element_work, only: add_force_work
  use gauss_legendre, only: gauss_legendre_rule
  use shell_block, only: max_shell_points
  implicit none
  private

  public :: efg_shell_block_t, efg_shell_solver_t, set_up_efg_shell_solver, compute_efg_shell_forces
  public :: efg_shell_cell_results, efg_shell_nodal_masses, transform_shell_to_physical, transpose_shell_to_generalized
  public :: efg_shell_rotary_factor

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
    !> Transverse shear stress zx, yz of each cell lane (elastic, the same at every thickness point).
    real(wp) :: shear_stress(block_size, 2) = 0.0_wp
    real(wp) :: internal_energy(block_size) = 0.0_wp   !< per point lane: membrane and bending work
    real(wp) :: force_power(block_size) = 0.0_wp
    real(wp) :: shear_energy(block_size) = 0.0_wp      !< per cell lane: transverse shear work
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
    !> Per point, the forces of the last call: G = F^-T (2, 2), W J N and W J M (3 each).
    real(wp), allocatable :: point_inverse(:, :, :)
    real(wp), allocatable :: point_membrane(:, :)
    real(wp), allocatable :: point_moment(:, :)
    !> Per cell, the shear forces of the last call: G^s (2, 2) and A J_s Q (Q_zx, Q_yz).
    real(wp), allocatable :: shear_inverse(:, :, :)
    real(wp), allocatable :: shear_resultant(:, :)
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
    allocate (solver%point_inverse(2, 2, point_count), solver%point_membrane(3, point_count), &
              solver%point_moment(3, point_count), solver%shear_inverse(2, 2, cell_count), &
              solver%shear_resultant(2, cell_count))
    solver%point_inverse = 0.0_wp
    solver%point_membrane = 0.0_wp
    solver%point_moment = 0.0_wp
    solver%shear_inverse = 0.0_wp
    solver%shear_resultant = 0.0_wp
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

  !> Colours the blocks by the nodes of their points' pairs, their shear pairs and their cells'
  !> corners (each node listed once per block).
  subroutine colour_shell_blocks(node_count, solver)
    integer, intent(in) :: node_count
    type(efg_shell_solver_t), intent(inout) :: solver
    integer, allocatable :: offsets(:), block_nodes(:), listed_by(:)
    integer :: b, k, c, count
    associate (geometry => solver%geometry)
      allocate (offsets(size(solver%blocks) + 1), listed_by(node_count), &
                block_nodes(size(geometry%pair_node) + size(geometry%shear_node) + 4*size(geometry%cells)))
      listed_by = 0
      count = 0
      do b = 1, size(solver%blocks)
        offsets(b) = count + 1
        associate (block => solver%blocks(b))
          do k = geometry%point_offsets(block%first_point), geometry%point_offsets(block%first_point + block%point_count) - 1
            call list_node(geometry%pair_node(k))
          end do
          do c = block%first_cell, block%first_cell + block%cell_count - 1
            do k = geometry%shear_offsets(c), geometry%shear_offsets(c + 1) - 1
              call list_node(geometry%shear_node(k))
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
                                      internal_force, internal_moment, normal_sum, area_sum)
    type(material_t), intent(in) :: material
    type(efg_shell_solver_t), intent(inout) :: solver
    real(wp), intent(in), contiguous :: coordinates(:, :), velocity(:, :), angular_velocity(:, :)
    real(wp), intent(in) :: dt
    real(wp), intent(inout), contiguous :: internal_force(:, :), internal_moment(:, :), normal_sum(:, :), area_sum(:)
    integer :: colour, k, b
    associate (colours => solver%block_colours)
      do colour = 1, size(colours%offsets) - 1
        !$omp parallel do schedule(dynamic, 1) default(shared) private(k, b)
        do k = colours%offsets(colour), colours%offsets(colour + 1) - 1
          b = colours%corners(k)
          call compute_shell_block(material, solver%geometry, solver%cell_nodes, solver%density, &
                                   solver%shear_factor, solver%thickness_points, solver%point_height, &
                                   solver%point_weight, solver%blocks(b), coordinates, velocity, angular_velocity, &
                                   dt, solver%cell_frame, solver%cell_area, solver%point_inverse, &
                                   solver%point_membrane, solver%point_moment, solver%shear_inverse, &
                                   solver%shear_resultant, solver%block_time_step(b), solver%block_critical_cell(b), &
                                   solver%block_failed_cell(b))
          call add_block_forces(solver%geometry, solver%cell_nodes, solver%blocks(b), solver%cell_frame, &
                                solver%cell_area, solver%point_inverse, solver%point_membrane, solver%point_moment, &
                                solver%shear_inverse, solver%shear_resultant, internal_force, internal_moment, &
                                normal_sum, area_sum)
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
                                 cell_frame, cell_area, point_inverse, point_membrane, point_moment, shear_inverse, &
                                 shear_resultant, critical_time_step, critical_cell, failed_cell)
    type(material_t), intent(in) :: material
    type(efg_shell_part_t), intent(in) :: geometry
    integer, intent(in) :: cell_nodes(:, :), thickness_points
    real(wp), intent(in) :: density, shear_factor, point_height(:), point_weight(:)
    type(efg_shell_block_t), intent(inout) :: block
    real(wp), intent(in), contiguous :: coordinates(:, :), velocity(:, :), angular_velocity(:, :)
    real(wp), intent(in) :: dt
    real(wp), intent(inout) :: cell_frame(:, :, :), cell_area(:), point_inverse(:, :, :), point_membrane(:, :)
    real(wp), intent(inout) :: point_moment(:, :), shear_inverse(:, :, :), shear_resultant(:, :)
    real(wp), intent(out) :: critical_time_step
    integer, intent(out) :: critical_cell, failed_cell
    real(wp) :: mid_frame(3, 3, block_size), end_frame(3, 3, block_size), first_turn(block_size)
    real(wp) :: second_turn(block_size), spin(block_size), jacobian(block_size), thickness(block_size)
    real(wp) :: membrane(block_size, 3), curvature(block_size, 3), increment(block_size, 3)
    real(wp) :: thickness_increment(block_size), old_power(block_size), new_power(block_size)
    real(wp) :: velocity_sum(3, 2, block_size), rotation_sum(3, 2, block_size)
    real(wp) :: shear_velocity(3, 2), shear_rotation(3), corners(3, 4), corner_velocity(3, 4)
    real(wp) :: position_sum(3, 2), inverse(2, 2), rate(2, 2), bend(2, 2), determinant
    real(wp) :: shear_modulus, height, angle, c, s, first, second, gamma(2), resultant(6), weight, arm
    real(wp) :: area, longest, wave_speed, cell_step, shear_jacobian, local_z(2)
    integer :: nel, i, g, cell, lane, point, corner, k, node

    nel = block%point_count
    failed_cell = 0
    shear_modulus = 0.0_wp
    if (material%law /= law_null) shear_modulus = material%youngs_modulus/(2.0_wp*(1.0_wp + material%poissons_ratio))
    wave_speed = 0.0_wp
    if (material%youngs_modulus > 0.0_wp .and. density > 0.0_wp) &
      wave_speed = sqrt(material%youngs_modulus/(density*(1.0_wp - material%poissons_ratio**2)))
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
      ! LS-DYNA's characteristic length of a shell, (1 + beta) A / longest side (beta = 1 on a
      ! triangle), on the current corners
      area = 0.5_wp*norm2(cross_product(corners(:, 3) - corners(:, 1), corners(:, 4) - corners(:, 2)))
      longest = 0.0_wp
      do corner = 1, 4
        longest = max(longest, norm2(corners(:, modulo(corner, 4) + 1) - corners(:, corner)))
      end do
      cell_area(cell) = area
      if (wave_speed > 0.0_wp) then
        cell_step = merge(2.0_wp, 1.0_wp, cell_nodes(3, cell) == cell_nodes(4, cell))*area/max(longest, tiny(1.0_wp)) &
                    /wave_speed
        if (cell_step < critical_time_step) then
          critical_time_step = cell_step
          critical_cell = cell
        end if
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
      old_power(i) = point_power(cell_frame(:, :, cell), point_inverse(:, :, g), point_membrane(:, g), &
                                 point_moment(:, g), velocity_sum(:, :, i), rotation_sum(:, :, i))
      call in_plane_inverse(end_frame(:, :, lane), position_sum, point_inverse(:, :, g), jacobian(i))
      if (.not. jacobian(i) > 0.0_wp .and. failed_cell == 0) failed_cell = cell
    end do

    ! stresses into the mid-step frame, plane-stress update at every thickness point, into the
    ! end frame
    do i = 1, nel
      lane = geometry%point_cell(block%first_point + i - 1) - block%first_cell + 1
      call rotate_point_stress(block, i, thickness_points, spin(i) + first_turn(lane))
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
      call rotate_point_stress(block, i, thickness_points, spin(i) + second_turn(lane))
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
      new_power(i) = point_power(end_frame(:, :, lane), point_inverse(:, :, g), point_membrane(:, g), &
                                 point_moment(:, g), velocity_sum(:, :, i), rotation_sum(:, :, i))
    end do
    call add_force_work(nel, dt, block%previous_time_step, old_power, new_power, block%force_power, &
                        block%internal_energy)

    ! transverse shear at each cell's shear point
    do lane = 1, block%cell_count
      cell = block%first_cell + lane - 1
      position_sum = 0.0_wp
      shear_velocity = 0.0_wp
      shear_rotation = 0.0_wp
      do k = geometry%shear_offsets(cell), geometry%shear_offsets(cell + 1) - 1
        node = geometry%shear_node(k)
        position_sum(:, 1) = position_sum(:, 1) + coordinates(:, node)*geometry%shear_gradient(1, k)
        position_sum(:, 2) = position_sum(:, 2) + coordinates(:, node)*geometry%shear_gradient(2, k)
        shear_velocity(:, 1) = shear_velocity(:, 1) + velocity(:, node)*geometry%shear_gradient(1, k)
        shear_velocity(:, 2) = shear_velocity(:, 2) + velocity(:, node)*geometry%shear_gradient(2, k)
        shear_rotation = shear_rotation + angular_velocity(:, node)*geometry%shear_value(k)
      end do
      old_power(lane) = shear_power(cell_frame(:, :, cell), shear_inverse(:, :, cell), shear_resultant(:, cell), &
                                    shear_velocity, shear_rotation)
      call in_plane_inverse(mid_frame(:, :, lane), position_sum - 0.5_wp*dt*shear_velocity, inverse, determinant)
      rate = local_gradient(mid_frame(:, :, lane), shear_velocity, inverse)
      local_z = [dot_product(mid_frame(:, 3, lane), shear_velocity(:, 1)), &
                 dot_product(mid_frame(:, 3, lane), shear_velocity(:, 2))]
      gamma = matmul(inverse, local_z) + [dot_product(mid_frame(:, 2, lane), shear_rotation), &
                                          -dot_product(mid_frame(:, 1, lane), shear_rotation)]
      ! the shear stress (zx, yz) turns as an in-plane vector, with the spin at the shear point
      angle = 0.25_wp*dt*(rate(2, 1) - rate(1, 2))
      do k = 1, 2
        c = cos(angle + merge(first_turn(lane), second_turn(lane), k == 1))
        s = sin(angle + merge(first_turn(lane), second_turn(lane), k == 1))
        first = block%shear_stress(lane, 1)
        second = block%shear_stress(lane, 2)
        block%shear_stress(lane, 1) = c*first - s*second
        block%shear_stress(lane, 2) = s*first + c*second
        if (k == 1) block%shear_stress(lane, :) = block%shear_stress(lane, :) + shear_factor*shear_modulus*dt*gamma
      end do
      call in_plane_inverse(end_frame(:, :, lane), position_sum, shear_inverse(:, :, cell), shear_jacobian)
      shear_resultant(:, cell) = geometry%cell_area(cell)*shear_jacobian*geometry%cell_thickness(cell) &
                                 *block%shear_stress(lane, :)
      new_power(lane) = shear_power(end_frame(:, :, lane), shear_inverse(:, :, cell), shear_resultant(:, cell), &
                                    shear_velocity, shear_rotation)
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

  !> Power of a point's forces and moments given by (frame, G, W J N, W J M) against the
  !> velocities and angular velocities whose pair sums are Vb and Wb: W J (N : L + M : k).
  pure real(wp) function point_power(frame, inverse, membrane, moment, velocity_sum, rotation_sum)
    real(wp), intent(in) :: frame(3, 3), inverse(2, 2), membrane(3), moment(3), velocity_sum(3, 2), rotation_sum(3, 2)
    real(wp) :: rate(2, 2), bend(2, 2)
    rate = local_gradient(frame, velocity_sum, inverse)
    bend = local_gradient(frame, rotation_sum, inverse)
    point_power = membrane(1)*rate(1, 1) + membrane(2)*rate(2, 2) + membrane(3)*(rate(1, 2) + rate(2, 1)) &
                  + moment(1)*bend(2, 1) - moment(2)*bend(1, 2) + moment(3)*(bend(2, 2) - bend(1, 1))
  end function point_power

  !> Power of a cell's shear forces (frame, G^s, A J Q) against the velocities (pair sum over
  !> the shear gradients) and angular velocities (sum of Psi w).
  pure real(wp) function shear_power(frame, inverse, resultant, velocity_sum, rotation)
    real(wp), intent(in) :: frame(3, 3), inverse(2, 2), resultant(2), velocity_sum(3, 2), rotation(3)
    real(wp) :: local_z(2), gamma(2)
    local_z = [dot_product(frame(:, 3), velocity_sum(:, 1)), dot_product(frame(:, 3), velocity_sum(:, 2))]
    gamma = matmul(inverse, local_z) + [dot_product(frame(:, 2), rotation), -dot_product(frame(:, 1), rotation)]
    shear_power = resultant(1)*gamma(1) + resultant(2)*gamma(2)
  end function shear_power

  !> Turn lane i's stresses (every thickness point) by `angle` (components kept in a frame that
  !> turned by phi while the material turned by psi turn by psi - phi: shell_block's
  !> rotate_with_material).
  pure subroutine rotate_point_stress(block, i, thickness_points, angle)
    type(efg_shell_block_t), intent(inout) :: block
    integer, intent(in) :: i, thickness_points
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
    end do
  end subroutine rotate_point_stress

  !> The block's forces and moments into the nodes: point by point, pair by pair (a node
  !> appears once among a point's pairs), then cell by cell its shear pairs and its corners'
  !> normal and area sums.
  subroutine add_block_forces(geometry, cell_nodes, block, cell_frame, cell_area, point_inverse, point_membrane, &
                              point_moment, shear_inverse, shear_resultant, internal_force, internal_moment, &
                              normal_sum, area_sum)
    type(efg_shell_part_t), intent(in) :: geometry
    integer, intent(in) :: cell_nodes(:, :)
    type(efg_shell_block_t), intent(in) :: block
    real(wp), intent(in) :: cell_frame(:, :, :), cell_area(:), point_inverse(:, :, :), point_membrane(:, :)
    real(wp), intent(in) :: point_moment(:, :), shear_inverse(:, :, :), shear_resultant(:, :)
    real(wp), intent(inout) :: internal_force(:, :), internal_moment(:, :), normal_sum(:, :), area_sum(:)
    real(wp) :: e1(3), e2(3), e3(3), g1, g2, n1, n2, m1, m2, transverse
    integer :: gp, k, node, cell, corner
    do gp = block%first_point, block%first_point + block%point_count - 1
      cell = geometry%point_cell(gp)
      e1 = cell_frame(:, 1, cell)
      e2 = cell_frame(:, 2, cell)
      associate (inverse => point_inverse(:, :, gp), membrane => point_membrane(:, gp), moment => point_moment(:, gp))
        do k = geometry%point_offsets(gp), geometry%point_offsets(gp + 1) - 1
          node = geometry%pair_node(k)
          g1 = inverse(1, 1)*geometry%pair_gradient(1, k) + inverse(1, 2)*geometry%pair_gradient(2, k)
          g2 = inverse(2, 1)*geometry%pair_gradient(1, k) + inverse(2, 2)*geometry%pair_gradient(2, k)
          n1 = membrane(1)*g1 + membrane(3)*g2
          n2 = membrane(3)*g1 + membrane(2)*g2
          m1 = -moment(2)*g2 - moment(3)*g1
          m2 = moment(1)*g1 + moment(3)*g2
          internal_force(:, node) = internal_force(:, node) + (n1*e1 + n2*e2)
          internal_moment(:, node) = internal_moment(:, node) + (m1*e1 + m2*e2)
        end do
      end associate
    end do
    do cell = block%first_cell, block%first_cell + block%cell_count - 1
      e1 = cell_frame(:, 1, cell)
      e2 = cell_frame(:, 2, cell)
      e3 = cell_frame(:, 3, cell)
      associate (inverse => shear_inverse(:, :, cell), q => shear_resultant(:, cell))
        do k = geometry%shear_offsets(cell), geometry%shear_offsets(cell + 1) - 1
          node = geometry%shear_node(k)
          g1 = inverse(1, 1)*geometry%shear_gradient(1, k) + inverse(1, 2)*geometry%shear_gradient(2, k)
          g2 = inverse(2, 1)*geometry%shear_gradient(1, k) + inverse(2, 2)*geometry%shear_gradient(2, k)
          transverse = q(1)*g1 + q(2)*g2
          internal_force(:, node) = internal_force(:, node) + transverse*e3
          internal_moment(:, node) = internal_moment(:, node) + geometry%shear_value(k)*(q(1)*e2 - q(2)*e1)
        end do
      end associate
      do corner = 1, 4
        if (corner == 4 .and. cell_nodes(4, cell) == cell_nodes(3, cell)) cycle
        node = cell_nodes(corner, cell)
        normal_sum(:, node) = normal_sum(:, node) + cell_area(cell)*e3
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
                                    peak_plastic_strain)
    type(material_t), intent(in) :: material
    type(efg_shell_solver_t), intent(in) :: solver
    real(wp), intent(inout) :: mid_stress(:, :), peak_stress(:, :), mean_plastic_strain(:), peak_plastic_strain(:)
    real(wp) :: point_strain(block_size, max_shell_points), local(5), mean(5), peak(5), effective, largest
    real(wp) :: weight_sum, area, mean_strain, peak_strain
    integer :: b, c, i, point, shell, lane
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
          do i = 1, block%point_count
            if (geometry%point_cell(block%first_point + i - 1) /= c) cycle
            area = geometry%point_area(block%first_point + i - 1)
            do point = 1, solver%thickness_points
              local = [block%stress(i, :, point), block%shear_stress(lane, 2), block%shear_stress(lane, 1)]
              mean = mean + solver%point_weight(point)*area*local
              mean_strain = mean_strain + solver%point_weight(point)*area*point_strain(i, point)
              peak_strain = max(peak_strain, point_strain(i, point))
              effective = local(1)**2 - local(1)*local(2) + local(2)**2 + 3.0_wp*(local(3)**2 + local(4)**2 + local(5)**2)
              if (effective > largest) then
                largest = effective
                peak = local
              end if
            end do
            weight_sum = weight_sum + area
          end do
          if (weight_sum > 0.0_wp) then
            mean = mean/weight_sum
            mean_strain = mean_strain/weight_sum
          end if
          shell = geometry%cells(c)
          mid_stress(:, shell) = global_stress(solver%cell_frame(:, :, c), mean)
          peak_stress(:, shell) = global_stress(solver%cell_frame(:, :, c), peak)
          mean_plastic_strain(shell) = mean_strain
          peak_plastic_strain(shell) = peak_strain
        end do
      end associate
    end do
  end subroutine efg_shell_cell_results

  !> Global components (xx, yy, zz, xy, yz, zx) of a local shell stress (xx, yy, xy, yz, zx):
  !> sigma = E s E^T with the columns of E the frame vectors.
  pure function global_stress(frame, local) result(stress)
    real(wp), intent(in) :: frame(3, 3), local(5)
    real(wp) :: stress(6), s(3, 3), g(3, 3)
    s = reshape([local(1), local(3), local(5), local(3), local(2), local(4), local(5), local(4), 0.0_wp], [3, 3])
    g = matmul(frame, matmul(s, transpose(frame)))
    stress = [g(1, 1), g(2, 2), g(3, 3), g(1, 2), g(2, 3), g(3, 1)]
  end function global_stress
end module efg_shell_forces
