!> Explicit update of the meshfree (EFG) parts (formulation section 5; Wang et al. 2009,
!> eqs. 28-34).
!>
!> Every integration point g of a part carries a compressed list of (node, smoothed gradient)
!> pairs, precomputed on the undeformed mesh (Lagrangian kernel). Each cycle, per point:
!>   Fbar = I + sum_pairs d(node) (x) bbar,  dFbar/dt = sum_pairs v(node) (x) bbar,
!>   Lbar = dFbar/dt Fmid^-1 at the mid-step Fmid = Fbar - dt/2 dFbar/dt,
!> rate of deformation and spin from Lbar, the same objective stress update and material
!> routines as the finite elements, then the first Piola-Kirchhoff stress P = J sigma Fbar^-T
!> stored per point as W_g P. Points are processed in blocks of `block_size` (the material
!> kernels work on blocks). As soon as a block's stresses are known, its points add
!> (W P)_g bbar of each pair into the pair's node, point by point, while the block's pair data
!> is still in cache (a separate node-ordered gather streamed all pairs a second time). The
!> blocks are coloured so that the blocks of one colour share no node (as the finite element
!> blocks, see element_forces): the blocks of a colour run in parallel, colours one after
!> another, so each node receives its contributions in a fixed order (colour, point, pair) and
!> the sum is bit-identical for any number of threads. A small part has colours of one or two
!> blocks, which would leave threads idle: with several threads, the blocks of colours smaller
!> than twice the thread count are computed first, all in parallel, and only add their forces
!> in the colour loop (the order at each node is the same, so are the results). `d` is the
!> solver's nodal displacement: physical at Gamma nodes, generalized at interior particles.
!> A part may have a host code's law instead (efg_host_law, given through the library
!> crashfree_efg): it takes the place of the material routines, after the same rotation.
!>
!> Internal energy is the work of the point forces, integrated as central differences
!> integrate the kinetic energy 1/2 m v(n-1/2) . v(n+1/2) (the finite elements do the same, see
!> solid_block): the forces f(m) of call m work over (dt(m-1/2) + dt(m+1/2))/2 against
!> (v(m-1/2) + v(m+1/2))/2; call m+1 completes that with f(m) . v(m+1/2) and books half of the
!> new forces' work with the current step. The power of a point's forces needs no pair loop:
!> sum over pairs of (W P bbar) . v = W P : dFbar/dt. The stress-power integral would drift by
!> percents over 10^4 cycles at TSSFAC 0.9.
module efg_forces
  use kinds, only: wp, block_size
  use gather_list, only: gather_list_t
  use block_colouring, only: colour_blocks_by_node_lists
  use model, only: model_t, material_t
  use efg_part, only: efg_part_t
  use efg_host_law, only: host_law_t
  use material_dispatch, only: material_history_count, initialize_material_history, update_material_block, &
                               rotate_material_history, material_plastic_strain, &
                               material_wave_modulus
  use objective_rotation, only: incremental_rotation, rotate_symmetric_tensors
  use small_tensors, only: symmetric_matrix
  use hex8_geometry, only: deformation_increments
  use element_time_step, only: bulk_viscosity_pressure, solid_element_time_steps
  !$ use omp_lib, only: omp_get_max_threads
  implicit none
  private

  public :: efg_solver_t, set_up_efg_solver, set_up_efg_state, compute_efg_forces, efg_point_results
  public :: transform_to_physical
  public :: efg_point_time_steps

  !> Up to block_size consecutive integration points of one part and their state.
  type :: efg_block_t
    integer :: point_count = 0
    integer :: first_point = 0                    !< points first_point .. first_point + point_count - 1
    real(wp) :: stress(block_size, 6) = 0.0_wp    !< Cauchy stress
    real(wp), allocatable :: history(:, :)        !< (block_size, material history count)
    real(wp) :: internal_energy(block_size) = 0.0_wp
    real(wp) :: force_power(block_size) = 0.0_wp  !< f . v of the last call's pair forces (see below)
    real(wp) :: previous_time_step = 0.0_wp
  end type efg_block_t

  !> The run-time data of one EFG part.
  type :: efg_solver_t
    type(efg_part_t) :: geometry
    real(wp) :: density = 0.0_wp
    real(wp) :: bulk_quadratic = 1.5_wp, bulk_linear = 0.06_wp
    type(efg_block_t), allocatable :: blocks(:)
    real(wp), allocatable :: point_stress(:, :)   !< (9, points): W_g P_g, column-major 3x3
    real(wp), allocatable :: point_cell_volume(:) !< reference volume of each point's cell (bulk viscosity)
    type(gather_list_t) :: block_colours          !< colour -> blocks; blocks of one colour share no node
    real(wp), allocatable :: block_time_step(:)
    integer, allocatable :: block_critical_point(:), block_inverted_point(:)
    !> A host code's law (crashfree_efg): when associated it replaces the material dispatch;
    !> the blocks' history is then (points of the block, k)
    type(host_law_t) :: host_law
  end type efg_solver_t

contains

  !> Blocks, material state and the node -> pair list of one part of the model whose geometry
  !> is built (through set_up_efg_state, with the part's material and bulk viscosity).
  subroutine set_up_efg_solver(model, geometry, solver)
    type(model_t), intent(in) :: model
    type(efg_part_t), intent(in) :: geometry
    type(efg_solver_t), intent(out) :: solver
    type(host_law_t) :: no_host_law
    associate (part => model%parts(geometry%part), material => model%materials(geometry%material))
      call set_up_efg_state(geometry, model%coordinates, model%solid_nodes, material, material%density, &
                            part%bulk_quadratic, part%bulk_linear, no_host_law, size(model%node_ids), solver)
    end associate
  end subroutine set_up_efg_solver

  !> Blocks, material state and the node -> pair list of one part whose geometry is built:
  !> `point_cell` of the geometry indexes `hexahedra(8, :)` (indices into `coordinates`),
  !> `node_count` nodes take the forces. The law is `host_law` when it is associated, else
  !> `material` (its history initialized by the material dispatch).
  subroutine set_up_efg_state(geometry, coordinates, hexahedra, material, density, bulk_quadratic, bulk_linear, &
                              host_law, node_count, solver)
    type(efg_part_t), intent(in) :: geometry
    real(wp), intent(in) :: coordinates(:, :)
    integer, intent(in) :: hexahedra(:, :)
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: density, bulk_quadratic, bulk_linear
    type(host_law_t), intent(in) :: host_law
    integer, intent(in) :: node_count
    type(efg_solver_t), intent(out) :: solver
    integer :: point_count, block_count, b, history_count, k, g
    real(wp) :: element_edges(block_size, 6)
    logical :: hosted

    solver%geometry = geometry
    solver%host_law = host_law
    hosted = associated(host_law%update)
    solver%density = density
    solver%bulk_quadratic = bulk_quadratic
    solver%bulk_linear = bulk_linear
    if (hosted) then
      history_count = host_law%history_count
    else
      history_count = material_history_count(material)
    end if
    point_count = size(geometry%point_volume)
    block_count = (point_count + block_size - 1)/block_size
    allocate (solver%blocks(block_count))
    do b = 1, block_count
      solver%blocks(b)%first_point = (b - 1)*block_size + 1
      solver%blocks(b)%point_count = min(block_size, point_count - (b - 1)*block_size)
      if (hosted) then
        ! the host's law sees exactly the block's points: (n, k), contiguous
        allocate (solver%blocks(b)%history(solver%blocks(b)%point_count, max(history_count, 1)))
        solver%blocks(b)%history = 0.0_wp
        cycle
      end if
      allocate (solver%blocks(b)%history(block_size, max(history_count, 1)))
      solver%blocks(b)%history = 0.0_wp
      ! material axes of AOPT 0 (honeycombs) from the edges 1-2 and 1-4 of each point's cell
      do k = 1, solver%blocks(b)%point_count
        g = solver%blocks(b)%first_point + k - 1
        associate (corners => hexahedra(:, geometry%point_cell(g)))
          element_edges(k, 1:3) = coordinates(:, corners(2)) - coordinates(:, corners(1))
          element_edges(k, 4:6) = coordinates(:, corners(4)) - coordinates(:, corners(1))
        end associate
      end do
      call initialize_material_history(material, solver%blocks(b)%point_count, solver%blocks(b)%history, &
                                       element_edges)
    end do
    allocate (solver%point_stress(9, point_count))
    solver%point_stress = 0.0_wp
    call sum_cell_volumes(geometry, solver%point_cell_volume)
    allocate (solver%block_time_step(block_count), solver%block_critical_point(block_count), &
              solver%block_inverted_point(block_count))
    solver%block_time_step = huge(1.0_wp)
    solver%block_critical_point = 0
    solver%block_inverted_point = 0
    call colour_efg_blocks(node_count, solver)
  end subroutine set_up_efg_state

  !> Colours the blocks by the nodes of their points' pairs (each node listed once per block).
  subroutine colour_efg_blocks(node_count, solver)
    integer, intent(in) :: node_count
    type(efg_solver_t), intent(inout) :: solver
    integer, allocatable :: offsets(:), block_nodes(:), listed_by(:)
    integer :: b, k, node, count
    associate (geometry => solver%geometry)
      allocate (offsets(size(solver%blocks) + 1), block_nodes(size(geometry%pair_node)), listed_by(node_count))
      listed_by = 0
      count = 0
      do b = 1, size(solver%blocks)
        offsets(b) = count + 1
        associate (first_point => solver%blocks(b)%first_point, point_count => solver%blocks(b)%point_count)
          do k = geometry%point_offsets(first_point), geometry%point_offsets(first_point + point_count) - 1
            node = geometry%pair_node(k)
            if (listed_by(node) == b) cycle
            listed_by(node) = b
            count = count + 1
            block_nodes(count) = node
          end do
        end associate
      end do
      offsets(size(solver%blocks) + 1) = count + 1
    end associate
    call colour_blocks_by_node_lists(node_count, offsets, block_nodes(1:count), solver%block_colours)
  end subroutine colour_efg_blocks

  !> The reference volume of each point's background cell: the sum of the volumes of the
  !> points that share the cell (consecutive in the point lists). The sub-cells of a distorted
  !> cell differ in size, so 8 W_g is not the cell's volume.
  subroutine sum_cell_volumes(geometry, cell_volume)
    type(efg_part_t), intent(in) :: geometry
    real(wp), allocatable, intent(out) :: cell_volume(:)
    integer :: first, last, point_count
    point_count = size(geometry%point_volume)
    allocate (cell_volume(point_count))
    first = 1
    do while (first <= point_count)
      last = first
      do while (last < point_count)
        if (geometry%point_cell(last + 1) /= geometry%point_cell(first)) exit
        last = last + 1
      end do
      cell_volume(first:last) = sum(geometry%point_volume(first:last))
      first = last + 1
    end do
  end subroutine sum_cell_volumes

  !> Stresses (W P) and stable steps of every point of one part, and their forces added into
  !> internal_force. `dt` is the step just taken (0 at the start); displacement and velocity
  !> are the solver's d^{n+1} and v^{n+1/2}.
  subroutine compute_efg_forces(material, solver, displacement, velocity, dt, internal_force, computed)
    type(material_t), intent(in) :: material
    type(efg_solver_t), intent(inout) :: solver
    real(wp), intent(in), contiguous :: displacement(:, :), velocity(:, :)
    real(wp), intent(in) :: dt
    real(wp), intent(inout), contiguous :: internal_force(:, :)
    !> A distributed run (docs/parallel.md): the part's blocks this rank computes; the others are
    !> left alone (their state stays as it was). Absent: all.
    logical, intent(in), optional :: computed(:)
    integer :: colour, k, b, threads
    logical :: fused
    threads = 1
    !$ threads = omp_get_max_threads()
    associate (colours => solver%block_colours)
      if (threads > 1) then
        ! the blocks of the small colours, all together (a thread moves on to the next colour
        ! without waiting)
        !$omp parallel default(shared) private(colour, k, b)
        do colour = 1, size(colours%offsets) - 1
          if (runs_fused(colours%offsets, colour, threads)) cycle
          !$omp do schedule(dynamic, 1)
          do k = colours%offsets(colour), colours%offsets(colour + 1) - 1
            b = colours%corners(k)
            if (present(computed)) then
              if (.not. computed(b)) cycle
            end if
            call compute_efg_block(material, solver%host_law, solver%geometry, solver%point_cell_volume, &
                                   solver%density, solver%bulk_quadratic, solver%bulk_linear, solver%blocks(b), &
                                   displacement, velocity, dt, solver%point_stress, solver%block_time_step(b), &
                                   solver%block_critical_point(b), solver%block_inverted_point(b))
          end do
          !$omp end do nowait
        end do
        !$omp end parallel
      end if
      do colour = 1, size(colours%offsets) - 1
        fused = runs_fused(colours%offsets, colour, threads)
        !$omp parallel do schedule(dynamic, 1) default(shared) private(k, b)
        do k = colours%offsets(colour), colours%offsets(colour + 1) - 1
          b = colours%corners(k)
          if (present(computed)) then
            if (.not. computed(b)) cycle
          end if
          if (fused) then
            call compute_efg_block(material, solver%host_law, solver%geometry, solver%point_cell_volume, &
                                   solver%density, solver%bulk_quadratic, solver%bulk_linear, solver%blocks(b), &
                                   displacement, velocity, dt, solver%point_stress, solver%block_time_step(b), &
                                   solver%block_critical_point(b), solver%block_inverted_point(b))
          end if
          call add_block_forces(solver%geometry, solver%blocks(b), solver%point_stress, internal_force)
        end do
        !$omp end parallel do
      end do
    end associate
  end subroutine compute_efg_forces

  !> Whether the blocks of a colour compute their stresses in the colour loop, just before
  !> adding their forces: always with one thread, with more when the colour has at least two
  !> blocks per thread.
  pure logical function runs_fused(offsets, colour, threads)
    integer, intent(in) :: offsets(:), colour, threads
    runs_fused = threads == 1 .or. offsets(colour + 1) - offsets(colour) >= 2*threads
  end function runs_fused

  !> internal_force(:, node) += (W P)_g bbar for every pair of the block's points, point by
  !> point, pair by pair (a node appears once among a point's pairs).
  subroutine add_block_forces(geometry, block, point_stress, internal_force)
    type(efg_part_t), intent(in) :: geometry
    type(efg_block_t), intent(in) :: block
    real(wp), intent(in), contiguous :: point_stress(:, :)
    real(wp), intent(inout), contiguous :: internal_force(:, :)
    integer :: g, k, node
    real(wp) :: p1, p2, p3, p4, p5, p6, p7, p8, p9, bx, by, bz
    do g = block%first_point, block%first_point + block%point_count - 1
      p1 = point_stress(1, g); p2 = point_stress(2, g); p3 = point_stress(3, g)
      p4 = point_stress(4, g); p5 = point_stress(5, g); p6 = point_stress(6, g)
      p7 = point_stress(7, g); p8 = point_stress(8, g); p9 = point_stress(9, g)
      do k = geometry%point_offsets(g), geometry%point_offsets(g + 1) - 1
        node = geometry%pair_node(k)
        bx = geometry%pair_gradient(1, k)
        by = geometry%pair_gradient(2, k)
        bz = geometry%pair_gradient(3, k)
        internal_force(1, node) = internal_force(1, node) + (p1*bx + p4*by + p7*bz)
        internal_force(2, node) = internal_force(2, node) + (p2*bx + p5*by + p8*bz)
        internal_force(3, node) = internal_force(3, node) + (p3*bx + p6*by + p9*bz)
      end do
    end do
  end subroutine add_block_forces

  !> One block of integration points.
  subroutine compute_efg_block(material, host_law, geometry, point_cell_volume, density, bulk_quadratic, &
                               bulk_linear, block, displacement, velocity, dt, point_stress, critical_time_step, &
                               critical_point, inverted_point)
    type(material_t), intent(in) :: material
    type(host_law_t), intent(in) :: host_law
    type(efg_part_t), intent(in) :: geometry
    real(wp), intent(in) :: point_cell_volume(:)
    real(wp), intent(in) :: density, bulk_quadratic, bulk_linear
    type(efg_block_t), intent(inout) :: block
    real(wp), intent(in), contiguous :: displacement(:, :), velocity(:, :)
    real(wp), intent(in) :: dt
    real(wp), intent(inout), contiguous :: point_stress(:, :)
    real(wp), intent(out) :: critical_time_step
    integer, intent(out) :: critical_point, inverted_point
    real(wp) :: gradient(block_size, 9), volumetric_rate(block_size), strain_increment(block_size, 6)
    real(wp) :: spin_increment(block_size, 3), rotation(block_size, 9)
    real(wp) :: wave_modulus(block_size), jacobian(block_size), mid_jacobian(block_size)
    real(wp) :: current_density(block_size), sound_speed(block_size), cell_volume(block_size)
    real(wp) :: bulk_viscosity(block_size), length(block_size), unit_area(block_size)
    real(wp) :: point_time_step(block_size), deformation(3, 3, block_size), reference_density(block_size)
    real(wp) :: rate(3, 3, block_size), point_gradient(9), mean_step, old_power, new_power, lane_stress(6)
    integer :: nel, i, g

    nel = block%point_count
    do i = 1, nel
      g = block%first_point + i - 1
      call point_kinematics(geometry, g, displacement, velocity, dt, deformation(:, :, i), rate(:, :, i), &
                            jacobian(i), mid_jacobian(i), point_gradient)
      gradient(i, :) = point_gradient
      volumetric_rate(i) = point_gradient(1) + point_gradient(5) + point_gradient(9)
    end do
    call deformation_increments(nel, dt, gradient, volumetric_rate, strain_increment, spin_increment)

    ! the same objective update and material routines as the finite elements
    call incremental_rotation(nel, spin_increment, rotation)
    call rotate_symmetric_tensors(nel, rotation, block%stress)
    if (associated(host_law%update)) then
      call update_with_host_law(host_law, nel, strain_increment, spin_increment, block%stress, block%history, &
                                wave_modulus)
    else
      call rotate_material_history(material, nel, rotation, block%history)
      call update_material_block(material, nel, dt, strain_increment, block%stress, block%history, wave_modulus)
    end if

    ! bulk viscosity on the current cell around the point, energy, time step
    inverted_point = 0
    do i = 1, nel
      g = block%first_point + i - 1
      if (jacobian(i) <= 0.0_wp .and. inverted_point == 0) inverted_point = g
      current_density(i) = density/max(jacobian(i), tiny(1.0_wp))
      sound_speed(i) = sqrt(max(wave_modulus(i), 0.0_wp)/density)
      cell_volume(i) = point_cell_volume(g)*max(jacobian(i), 0.0_wp)
    end do
    ! the cell's length shrinks with the smallest principal stretch of Fbar (a cell squeezed
    ! flat keeps its volume but not its thickness)
    call smallest_stretches(nel, deformation, length)
    do i = 1, nel
      length(i) = geometry%point_length(block%first_point + i - 1)*length(i)
    end do
    call bulk_viscosity_pressure(nel, bulk_quadratic, bulk_linear, current_density, sound_speed, cell_volume, &
                                 volumetric_rate, bulk_viscosity)
    ! viscous forces damp motion over a step; the first call (dt = 0) has none (see solid_block)
    if (dt <= 0.0_wp) bulk_viscosity(1:nel) = 0.0_wp
    mean_step = 0.5_wp*(block%previous_time_step + dt)
    do i = 1, nel
      g = block%first_point + i - 1
      old_power = stress_power(point_stress(:, g), rate(:, :, i))
      ! a contiguous copy of the lane's stress: no array temporary in the hot loop
      lane_stress = block%stress(i, :)
      call store_point_stress(geometry%point_volume(g), deformation(:, :, i), jacobian(i), lane_stress, &
                              bulk_viscosity(i), point_stress(:, g))
      new_power = stress_power(point_stress(:, g), rate(:, :, i))
      block%internal_energy(i) = block%internal_energy(i) + 0.5_wp*mean_step*(block%force_power(i) + old_power) &
                                 - 0.5_wp*block%previous_time_step*block%force_power(i) + 0.5_wp*dt*new_power
      block%force_power(i) = new_power
    end do
    block%previous_time_step = dt
    ! the stable step of the cell, L = V / A_max scaled with the point's volume change (a length
    ! over a unit area is that length)
    unit_area(1:nel) = 1.0_wp
    reference_density(1:nel) = density
    call solid_element_time_steps(nel, bulk_quadratic, bulk_linear, length, unit_area, wave_modulus, &
                                  reference_density, volumetric_rate, point_time_step)
    critical_time_step = huge(1.0_wp)
    critical_point = 0
    do i = 1, nel
      if (point_time_step(i) < critical_time_step) then
        critical_time_step = point_time_step(i)
        critical_point = block%first_point + i - 1
      end if
    end do
  end subroutine compute_efg_block

  !> The host's law on the block's nel points (see efg_host_law): the lanes are copied to arrays
  !> of leading dimension nel (fixed-size buffers: nothing is allocated), the stress back.
  subroutine update_with_host_law(host_law, nel, strain_increment, spin_increment, stress, history, wave_modulus)
    type(host_law_t), intent(in) :: host_law
    integer, intent(in) :: nel
    real(wp), intent(in) :: strain_increment(block_size, 6), spin_increment(block_size, 3)
    real(wp), intent(inout) :: stress(block_size, 6)
    real(wp), intent(inout), contiguous :: history(:, :)
    real(wp), intent(out) :: wave_modulus(block_size)
    real(wp) :: lane_strain(block_size*6), lane_spin(block_size*3), lane_stress(block_size*6)
    integer :: i, j
    do j = 1, 6
      do i = 1, nel
        lane_strain(i + nel*(j - 1)) = strain_increment(i, j)
        lane_stress(i + nel*(j - 1)) = stress(i, j)
      end do
    end do
    do j = 1, 3
      do i = 1, nel
        lane_spin(i + nel*(j - 1)) = spin_increment(i, j)
      end do
    end do
    call host_law%update(nel, lane_strain, lane_spin, lane_stress, history, host_law%context)
    do j = 1, 6
      do i = 1, nel
        stress(i, j) = lane_stress(i + nel*(j - 1))
      end do
    end do
    wave_modulus(1:nel) = host_law%wave_modulus
  end subroutine update_with_host_law

  !> Fbar at the end of the step, its rate, J, J at mid-step and the velocity gradient at
  !> mid-step (row-major: gradient(3 (i - 1) + j) = dv_i / dx_j). The rate sums the velocities
  !> relative to the point's first node's (the same value, as the gradients of the shape
  !> functions sum to zero): a translating part then gets exactly L = 0. With the absolute
  !> velocities tr D was round-off of either sign, and a negative one lowered the point's stable
  !> step by the linear bulk viscosity's 6% (Q2 = 0.06; hex8_geometry's hex8_velocity_gradient
  !> says more). (Fbar keeps the absolute displacements: its round-off only moves J, by far less,
  !> and the pair loop is the meshfree update's hot spot.)
  subroutine point_kinematics(geometry, g, displacement, velocity, dt, deformation, rate, jacobian, &
                              mid_jacobian, gradient)
    type(efg_part_t), intent(in) :: geometry
    integer, intent(in) :: g
    real(wp), intent(in), contiguous :: displacement(:, :), velocity(:, :)
    real(wp), intent(in) :: dt
    real(wp), intent(out) :: deformation(3, 3), rate(3, 3), jacobian, mid_jacobian, gradient(9)
    real(wp) :: middle(3, 3), inverse(3, 3), velocity_gradient(3, 3)
    real(wp) :: f11, f21, f31, f12, f22, f32, f13, f23, f33
    real(wp) :: r11, r21, r31, r12, r22, r32, r13, r23, r33, bx, by, bz, dx, dy, dz, vx, vy, vz
    real(wp) :: base_vx, base_vy, base_vz
    integer :: k, node, i, j
    ! scalar accumulators: the pair loop is the hot spot of the meshfree update
    f11 = 0.0_wp; f21 = 0.0_wp; f31 = 0.0_wp; f12 = 0.0_wp; f22 = 0.0_wp; f32 = 0.0_wp
    f13 = 0.0_wp; f23 = 0.0_wp; f33 = 0.0_wp
    r11 = 0.0_wp; r21 = 0.0_wp; r31 = 0.0_wp; r12 = 0.0_wp; r22 = 0.0_wp; r32 = 0.0_wp
    r13 = 0.0_wp; r23 = 0.0_wp; r33 = 0.0_wp
    base_vx = 0.0_wp
    base_vy = 0.0_wp
    base_vz = 0.0_wp
    if (geometry%point_offsets(g + 1) > geometry%point_offsets(g)) then
      node = geometry%pair_node(geometry%point_offsets(g))
      base_vx = velocity(1, node)
      base_vy = velocity(2, node)
      base_vz = velocity(3, node)
    end if
    do k = geometry%point_offsets(g), geometry%point_offsets(g + 1) - 1
      node = geometry%pair_node(k)
      bx = geometry%pair_gradient(1, k)
      by = geometry%pair_gradient(2, k)
      bz = geometry%pair_gradient(3, k)
      dx = displacement(1, node)
      dy = displacement(2, node)
      dz = displacement(3, node)
      vx = velocity(1, node) - base_vx
      vy = velocity(2, node) - base_vy
      vz = velocity(3, node) - base_vz
      f11 = f11 + dx*bx; f21 = f21 + dy*bx; f31 = f31 + dz*bx
      f12 = f12 + dx*by; f22 = f22 + dy*by; f32 = f32 + dz*by
      f13 = f13 + dx*bz; f23 = f23 + dy*bz; f33 = f33 + dz*bz
      r11 = r11 + vx*bx; r21 = r21 + vy*bx; r31 = r31 + vz*bx
      r12 = r12 + vx*by; r22 = r22 + vy*by; r32 = r32 + vz*by
      r13 = r13 + vx*bz; r23 = r23 + vy*bz; r33 = r33 + vz*bz
    end do
    deformation(1, 1) = f11 + 1.0_wp
    deformation(2, 1) = f21
    deformation(3, 1) = f31
    deformation(1, 2) = f12
    deformation(2, 2) = f22 + 1.0_wp
    deformation(3, 2) = f32
    deformation(1, 3) = f13
    deformation(2, 3) = f23
    deformation(3, 3) = f33 + 1.0_wp
    rate(1, 1) = r11
    rate(2, 1) = r21
    rate(3, 1) = r31
    rate(1, 2) = r12
    rate(2, 2) = r22
    rate(3, 2) = r32
    rate(1, 3) = r13
    rate(2, 3) = r23
    rate(3, 3) = r33
    middle = deformation - 0.5_wp*dt*rate
    jacobian = determinant(deformation)
    mid_jacobian = determinant(middle)
    call invert(middle, mid_jacobian, inverse)
    velocity_gradient = matmul(rate, inverse)
    do i = 1, 3
      do j = 1, 3
        gradient(3*(i - 1) + j) = velocity_gradient(i, j)
      end do
    end do
  end subroutine point_kinematics

  !> W_g P with P = J (sigma - q I) Fbar^-T, the first Piola-Kirchhoff stress.
  pure subroutine store_point_stress(volume, deformation, jacobian, stress, bulk_viscosity, point_stress)
    real(wp), intent(in) :: volume, deformation(3, 3), jacobian, stress(6), bulk_viscosity
    real(wp), intent(out) :: point_stress(9)
    real(wp) :: cauchy(3, 3), inverse(3, 3), scale
    integer :: i, j
    cauchy = symmetric_matrix(stress)
    do i = 1, 3
      cauchy(i, i) = cauchy(i, i) - bulk_viscosity
    end do
    call invert(deformation, jacobian, inverse)
    scale = volume*jacobian
    ! (sigma F^-T)_ij = sum_k sigma_ik (F^-1)_jk; stored column-major
    do j = 1, 3
      do i = 1, 3
        point_stress(i + 3*(j - 1)) = scale*(cauchy(i, 1)*inverse(j, 1) + cauchy(i, 2)*inverse(j, 2) &
                                             + cauchy(i, 3)*inverse(j, 3))
      end do
    end do
  end subroutine store_point_stress

  !> (W P) : dFbar/dt, the power of a point's forces (W P column-major).
  pure real(wp) function stress_power(point_stress, rate)
    real(wp), intent(in) :: point_stress(9), rate(3, 3)
    stress_power = point_stress(1)*rate(1, 1) + point_stress(2)*rate(2, 1) + point_stress(3)*rate(3, 1) &
                   + point_stress(4)*rate(1, 2) + point_stress(5)*rate(2, 2) + point_stress(6)*rate(3, 2) &
                   + point_stress(7)*rate(1, 3) + point_stress(8)*rate(2, 3) + point_stress(9)*rate(3, 3)
  end function stress_power

  !> Smallest principal stretch of F of lanes 1..nel: the square root of the smallest
  !> eigenvalue of C = F^T F, from the trigonometric solution of the characteristic cubic of a
  !> symmetric 3x3 matrix (Smith, Comm. ACM 4 (1961) 168). The invariants are gathered first
  !> and the trigonometry runs in a loop of its own, which the compiler vectorizes (acos and
  !> cos cost more than the rest of the point's kinematics when called lane by lane).
  pure subroutine smallest_stretches(nel, deformation, stretch)
    integer, intent(in) :: nel
    real(wp), intent(in) :: deformation(3, 3, block_size)
    real(wp), intent(out) :: stretch(block_size)
    real(wp) :: mean(block_size), spread(block_size), half_det(block_size)
    real(wp) :: c11, c22, c33, c12, c13, c23, off_diagonal, spread_squared, angle, eigenvalue
    real(wp), parameter :: pi = 3.14159265358979323846_wp
    integer :: i
    do i = 1, nel
      associate (f => deformation(:, :, i))
        c11 = f(1, 1)**2 + f(2, 1)**2 + f(3, 1)**2
        c22 = f(1, 2)**2 + f(2, 2)**2 + f(3, 2)**2
        c33 = f(1, 3)**2 + f(2, 3)**2 + f(3, 3)**2
        c12 = f(1, 1)*f(1, 2) + f(2, 1)*f(2, 2) + f(3, 1)*f(3, 2)
        c13 = f(1, 1)*f(1, 3) + f(2, 1)*f(2, 3) + f(3, 1)*f(3, 3)
        c23 = f(1, 2)*f(1, 3) + f(2, 2)*f(2, 3) + f(3, 2)*f(3, 3)
      end associate
      mean(i) = (c11 + c22 + c33)/3.0_wp
      c11 = c11 - mean(i)
      c22 = c22 - mean(i)
      c33 = c33 - mean(i)
      off_diagonal = c12**2 + c13**2 + c23**2
      spread_squared = (c11**2 + c22**2 + c33**2 + 2.0_wp*off_diagonal)/6.0_wp
      if (spread_squared <= epsilon(1.0_wp)*mean(i)**2) then
        ! (nearly) isotropic: every eigenvalue is the mean
        spread(i) = 0.0_wp
        half_det(i) = 1.0_wp
      else
        spread(i) = sqrt(spread_squared)
        ! det((C - mean I) / spread) / 2
        half_det(i) = 0.5_wp*(c11*(c22*c33 - c23**2) - c12*(c12*c33 - c23*c13) + c13*(c12*c23 - c22*c13)) &
                      /spread_squared/spread(i)
      end if
    end do
    do i = 1, nel
      angle = acos(max(-1.0_wp, min(1.0_wp, half_det(i))))/3.0_wp
      ! the eigenvalues are mean + 2 spread cos(angle + 2 pi k / 3); k = 1 gives the smallest
      eigenvalue = mean(i) + 2.0_wp*spread(i)*cos(angle + 2.0_wp*pi/3.0_wp)
      stretch(i) = sqrt(max(eigenvalue, 0.0_wp))
    end do
  end subroutine smallest_stretches

  pure real(wp) function determinant(a)
    real(wp), intent(in) :: a(3, 3)
    determinant = a(1, 1)*(a(2, 2)*a(3, 3) - a(2, 3)*a(3, 2)) - a(1, 2)*(a(2, 1)*a(3, 3) - a(2, 3)*a(3, 1)) &
                  + a(1, 3)*(a(2, 1)*a(3, 2) - a(2, 2)*a(3, 1))
  end function determinant

  !> Inverse of a 3x3 matrix whose determinant is given (a zero determinant gives zeros: the
  !> point is reported as inverted by the caller).
  pure subroutine invert(a, det, inverse)
    real(wp), intent(in) :: a(3, 3), det
    real(wp), intent(out) :: inverse(3, 3)
    real(wp) :: scale
    scale = 0.0_wp
    if (det /= 0.0_wp) scale = 1.0_wp/det
    inverse(1, 1) = (a(2, 2)*a(3, 3) - a(2, 3)*a(3, 2))*scale
    inverse(1, 2) = (a(1, 3)*a(3, 2) - a(1, 2)*a(3, 3))*scale
    inverse(1, 3) = (a(1, 2)*a(2, 3) - a(1, 3)*a(2, 2))*scale
    inverse(2, 1) = (a(2, 3)*a(3, 1) - a(2, 1)*a(3, 3))*scale
    inverse(2, 2) = (a(1, 1)*a(3, 3) - a(1, 3)*a(3, 1))*scale
    inverse(2, 3) = (a(1, 3)*a(2, 1) - a(1, 1)*a(2, 3))*scale
    inverse(3, 1) = (a(2, 1)*a(3, 2) - a(2, 2)*a(3, 1))*scale
    inverse(3, 2) = (a(1, 2)*a(3, 1) - a(1, 1)*a(3, 2))*scale
    inverse(3, 3) = (a(1, 1)*a(2, 2) - a(1, 2)*a(2, 1))*scale
  end subroutine invert

  !> Physical values at the interior particles (eq. 16): physical(:, J) = sum_I Psi_I(X_J)
  !> field(:, I). Other nodes are left as they are (Gamma nodes carry physical values).
  subroutine transform_to_physical(geometry, field, physical)
    type(efg_part_t), intent(in) :: geometry
    real(wp), intent(in) :: field(:, :)
    real(wp), intent(inout) :: physical(:, :)
    integer :: j, k
    real(wp) :: value(3)
    do j = 1, size(geometry%particles)
      value = 0.0_wp
      do k = geometry%transform_offsets(j), geometry%transform_offsets(j + 1) - 1
        value = value + geometry%transform_value(k)*field(:, geometry%transform_node(k))
      end do
      physical(:, geometry%particles(j)) = value
    end do
  end subroutine transform_to_physical

  !> Cell stress (mean of its points) and effective plastic strain into the element arrays.
  subroutine efg_point_results(material, solver, stress, plastic_strain)
    type(material_t), intent(in) :: material
    type(efg_solver_t), intent(in) :: solver
    real(wp), intent(inout) :: stress(:, :), plastic_strain(:)
    real(wp) :: point_plastic(block_size)
    real(wp), allocatable :: weight(:)
    integer :: b, i, g, cell
    allocate (weight(size(stress, 2)))
    weight = 0.0_wp
    do b = 1, size(solver%blocks)
      associate (block => solver%blocks(b))
        call material_plastic_strain(material%law, block%point_count, block%history, point_plastic)
        do i = 1, block%point_count
          g = block%first_point + i - 1
          cell = solver%geometry%point_cell(g)
          if (weight(cell) == 0.0_wp) then
            stress(:, cell) = 0.0_wp
            plastic_strain(cell) = 0.0_wp
          end if
          stress(:, cell) = stress(:, cell) + block%stress(i, :)*solver%geometry%point_volume(g)
          plastic_strain(cell) = plastic_strain(cell) + point_plastic(i)*solver%geometry%point_volume(g)
          weight(cell) = weight(cell) + solver%geometry%point_volume(g)
        end do
      end associate
    end do
    do cell = 1, size(weight)
      if (weight(cell) > 0.0_wp) then
        stress(:, cell) = stress(:, cell)/weight(cell)
        plastic_strain(cell) = plastic_strain(cell)/weight(cell)
      end if
    end do
  end subroutine efg_point_results

  !> Stable step (no TSSFAC) of every integration point of one part at the displacement given,
  !> at rest (no bulk viscosity): the force call's rule (compute_efg_block, L = the point's
  !> length times the smallest stretch of Fbar) with the material's wave modulus at rest, as
  !> the finite elements' solid_block_time_steps (d3hsp's table of the smallest steps).
  subroutine efg_point_time_steps(material, solver, displacement, point_time_step)
    type(material_t), intent(in) :: material
    type(efg_solver_t), intent(in) :: solver
    real(wp), intent(in), contiguous :: displacement(:, :)
    real(wp), intent(out) :: point_time_step(:)       !< (points)
    real(wp) :: deformation(3, 3, block_size), rate(3, 3), jacobian, mid_jacobian, point_gradient(9)
    real(wp) :: length(block_size), unit_area(block_size), wave_modulus(block_size), density(block_size)
    real(wp) :: rest(block_size), lane_step(block_size)
    integer :: b, i, g, nel
    call material_wave_modulus(material, block_size, wave_modulus)
    unit_area = 1.0_wp
    density = solver%density
    rest = 0.0_wp
    deformation = 0.0_wp
    do b = 1, size(solver%blocks)
      nel = solver%blocks(b)%point_count
      do i = 1, nel
        g = solver%blocks(b)%first_point + i - 1
        ! (dt = 0: the displacement stands for the velocity too, whose rate is not used)
        call point_kinematics(solver%geometry, g, displacement, displacement, 0.0_wp, deformation(:, :, i), rate, &
                              jacobian, mid_jacobian, point_gradient)
      end do
      call smallest_stretches(nel, deformation, length)
      do i = 1, nel
        length(i) = solver%geometry%point_length(solver%blocks(b)%first_point + i - 1)*length(i)
      end do
      call solid_element_time_steps(nel, solver%bulk_quadratic, solver%bulk_linear, length, unit_area, wave_modulus, &
                                    density, rest, lane_step)
      do i = 1, nel
        point_time_step(solver%blocks(b)%first_point + i - 1) = lane_step(i)
      end do
    end do
  end subroutine efg_point_time_steps
end module efg_forces
