!> Explicit update of the meshfree (EFG) parts (formulation section 5; Wang et al. 2009,
!> eqs. 28-34).
!>
!> Every integration point g of a part carries a compressed list of (node, smoothed gradient)
!> pairs, precomputed on the undeformed mesh (Lagrangian kernel). Each cycle, per point:
!>   Fbar = I + sum_pairs d(node) (x) bbar,  dFbar/dt = sum_pairs v(node) (x) bbar,
!>   Lbar = dFbar/dt Fmid^-1 at the mid-step Fmid = Fbar - dt/2 dFbar/dt,
!> rate of deformation and spin from Lbar, the same objective stress update and material
!> routines as the finite elements, then the first Piola-Kirchhoff stress P = J sigma Fbar^-T
!> and one force per pair, W_g P bbar. Points are processed in blocks of `block_size` (the
!> material kernels work on blocks); each block writes only its own pairs. Nodes then gather
!> their pairs in a fixed order (node -> pair list), so the sum does not depend on the number
!> of threads. `d` is the solver's nodal displacement: physical at Gamma nodes, generalized at
!> interior particles.
!>
!> Internal energy is the work of the pair forces, integrated as central differences
!> integrate the kinetic energy 1/2 m v(n-1/2) . v(n+1/2) (the finite elements do the same, see
!> solid_block): the forces f(m) of call m work over (dt(m-1/2) + dt(m+1/2))/2 against
!> (v(m-1/2) + v(m+1/2))/2; call m+1 completes that with f(m) . v(m+1/2), read from the pair
!> forces before they are overwritten, and books half of the new forces' work with the current
!> step. The stress-power integral would drift by percents over 10^4 cycles at TSSFAC 0.9.
module efg_forces
  use kinds, only: wp, block_size
  use gather_list, only: gather_list_t, build_gather_list
  use model, only: model_t, material_t
  use efg_part, only: efg_part_t
  use material_dispatch, only: material_history_count, initialize_material_history, update_material_block, &
                               rotate_material_history, material_plastic_strain
  use objective_rotation, only: incremental_rotation, rotate_symmetric_tensors
  use hex8_geometry, only: deformation_increments
  use element_time_step, only: bulk_viscosity_pressure, solid_element_time_steps
  implicit none
  private

  public :: efg_solver_t, set_up_efg_solver, compute_efg_forces, add_efg_forces, efg_point_results
  public :: transform_to_physical

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
    real(wp), allocatable :: pair_force(:, :)     !< (3, pairs), written by the blocks
    integer, allocatable :: nodes(:)              !< the part's nodes that receive forces
    type(gather_list_t) :: node_pairs             !< position in `nodes` -> pairs, in pair order
    real(wp), allocatable :: block_time_step(:)
    integer, allocatable :: block_critical_point(:), block_inverted_point(:)
  end type efg_solver_t

contains

  !> Blocks, material state and the node -> pair list of one part whose geometry is built.
  subroutine set_up_efg_solver(model, geometry, solver)
    type(model_t), intent(in) :: model
    type(efg_part_t), intent(in) :: geometry
    type(efg_solver_t), intent(out) :: solver
    integer :: point_count, block_count, b, history_count, k
    integer, allocatable :: local_index(:), pair_slot(:)

    solver%geometry = geometry
    associate (part => model%parts(geometry%part), material => model%materials(geometry%material))
      solver%density = material%density
      solver%bulk_quadratic = part%bulk_quadratic
      solver%bulk_linear = part%bulk_linear
      history_count = material_history_count(material)
      point_count = size(geometry%point_volume)
      block_count = (point_count + block_size - 1)/block_size
      allocate (solver%blocks(block_count))
      do b = 1, block_count
        solver%blocks(b)%first_point = (b - 1)*block_size + 1
        solver%blocks(b)%point_count = min(block_size, point_count - (b - 1)*block_size)
        allocate (solver%blocks(b)%history(block_size, max(history_count, 1)))
        solver%blocks(b)%history = 0.0_wp
        call initialize_material_history(material, solver%blocks(b)%point_count, solver%blocks(b)%history)
      end do
    end associate
    allocate (solver%pair_force(3, size(geometry%pair_node)))
    solver%pair_force = 0.0_wp
    allocate (solver%block_time_step(block_count), solver%block_critical_point(block_count), &
              solver%block_inverted_point(block_count))
    solver%block_time_step = huge(1.0_wp)
    solver%block_critical_point = 0
    solver%block_inverted_point = 0

    ! the part's nodes (mass nodes are every node of the part, once) and node -> pairs
    solver%nodes = geometry%mass_node
    allocate (local_index(size(model%node_ids)), pair_slot(size(geometry%pair_node)))
    local_index = 0
    do k = 1, size(solver%nodes)
      local_index(solver%nodes(k)) = k
    end do
    do k = 1, size(geometry%pair_node)
      pair_slot(k) = local_index(geometry%pair_node(k))
    end do
    call build_gather_list(size(solver%nodes), pair_slot, solver%node_pairs)
  end subroutine set_up_efg_solver

  !> Stresses, pair forces and stable steps of every point of one part. `dt` is the step just
  !> taken (0 at the start); displacement and velocity are the solver's d^{n+1} and v^{n+1/2}.
  subroutine compute_efg_forces(material, solver, displacement, velocity, dt)
    type(material_t), intent(in) :: material
    type(efg_solver_t), intent(inout) :: solver
    real(wp), intent(in) :: displacement(:, :), velocity(:, :)
    real(wp), intent(in) :: dt
    integer :: b
    !$omp parallel do schedule(dynamic, 2) default(shared) private(b)
    do b = 1, size(solver%blocks)
      call compute_efg_block(material, solver%geometry, solver%density, solver%bulk_quadratic, &
                             solver%bulk_linear, solver%blocks(b), displacement, velocity, dt, solver%pair_force, &
                             solver%block_time_step(b), solver%block_critical_point(b), &
                             solver%block_inverted_point(b))
    end do
    !$omp end parallel do
  end subroutine compute_efg_forces

  !> internal_force(:, node) += the node's pair forces, in pair order.
  subroutine add_efg_forces(solver, internal_force)
    type(efg_solver_t), intent(in) :: solver
    real(wp), intent(inout) :: internal_force(:, :)
    integer :: k, slot, node
    real(wp) :: force(3)
    !$omp parallel do schedule(static) default(shared) private(k, slot, node, force)
    do k = 1, size(solver%nodes)
      node = solver%nodes(k)
      force = 0.0_wp
      do slot = solver%node_pairs%offsets(k), solver%node_pairs%offsets(k + 1) - 1
        force = force + solver%pair_force(:, solver%node_pairs%corners(slot))
      end do
      internal_force(:, node) = internal_force(:, node) + force
    end do
    !$omp end parallel do
  end subroutine add_efg_forces

  !> One block of integration points.
  subroutine compute_efg_block(material, geometry, density, bulk_quadratic, bulk_linear, block, &
                               displacement, velocity, dt, pair_force, critical_time_step, critical_point, &
                               inverted_point)
    type(material_t), intent(in) :: material
    type(efg_part_t), intent(in) :: geometry
    real(wp), intent(in) :: density, bulk_quadratic, bulk_linear
    type(efg_block_t), intent(inout) :: block
    real(wp), intent(in) :: displacement(:, :), velocity(:, :)
    real(wp), intent(in) :: dt
    real(wp), intent(inout) :: pair_force(:, :)
    real(wp), intent(out) :: critical_time_step
    integer, intent(out) :: critical_point, inverted_point
    real(wp) :: gradient(block_size, 9), volumetric_rate(block_size), strain_increment(block_size, 6)
    real(wp) :: spin_increment(block_size, 3), rotation(block_size, 9)
    real(wp) :: wave_modulus(block_size), jacobian(block_size), mid_jacobian(block_size)
    real(wp) :: current_density(block_size), sound_speed(block_size), cell_volume(block_size)
    real(wp) :: bulk_viscosity(block_size), length(block_size), unit_area(block_size)
    real(wp) :: point_time_step(block_size), deformation(3, 3, block_size), reference_density(block_size)
    real(wp) :: mean_step, old_power, new_power
    integer :: nel, i, g

    nel = block%point_count
    do i = 1, nel
      g = block%first_point + i - 1
      call point_kinematics(geometry, g, displacement, velocity, dt, deformation(:, :, i), jacobian(i), &
                            mid_jacobian(i), gradient(i, :))
      volumetric_rate(i) = gradient(i, 1) + gradient(i, 5) + gradient(i, 9)
    end do
    call deformation_increments(nel, dt, gradient, volumetric_rate, strain_increment, spin_increment)

    ! the same objective update and material routines as the finite elements
    call incremental_rotation(nel, spin_increment, rotation)
    call rotate_symmetric_tensors(nel, rotation, block%stress)
    call rotate_material_history(material, nel, rotation, block%history)
    call update_material_block(material, nel, dt, strain_increment, block%stress, block%history, wave_modulus)

    ! bulk viscosity on the current cell around the point, energy, time step
    inverted_point = 0
    do i = 1, nel
      g = block%first_point + i - 1
      if (jacobian(i) <= 0.0_wp .and. inverted_point == 0) inverted_point = g
      current_density(i) = density/max(jacobian(i), tiny(1.0_wp))
      sound_speed(i) = sqrt(max(wave_modulus(i), 0.0_wp)/density)
      cell_volume(i) = 8.0_wp*geometry%point_volume(g)*max(jacobian(i), 0.0_wp)
      ! the cell's length shrinks with the smallest principal stretch of Fbar (a cell squeezed
      ! flat keeps its volume but not its thickness)
      length(i) = geometry%point_length(g)*smallest_stretch(deformation(:, :, i))
    end do
    call bulk_viscosity_pressure(nel, bulk_quadratic, bulk_linear, current_density, sound_speed, cell_volume, &
                                 volumetric_rate, bulk_viscosity)
    ! viscous forces damp motion over a step; the first call (dt = 0) has none (see solid_block)
    if (dt <= 0.0_wp) bulk_viscosity(1:nel) = 0.0_wp
    mean_step = 0.5_wp*(block%previous_time_step + dt)
    do i = 1, nel
      g = block%first_point + i - 1
      old_power = pair_power(geometry, g, pair_force, velocity)
      call write_pair_forces(geometry, g, deformation(:, :, i), jacobian(i), block%stress(i, :), &
                             bulk_viscosity(i), pair_force)
      new_power = pair_power(geometry, g, pair_force, velocity)
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

  !> Fbar at the end of the step, J, J at mid-step and the velocity gradient at mid-step
  !> (row-major: gradient(3 (i - 1) + j) = dv_i / dx_j).
  subroutine point_kinematics(geometry, g, displacement, velocity, dt, deformation, jacobian, mid_jacobian, &
                              gradient)
    type(efg_part_t), intent(in) :: geometry
    integer, intent(in) :: g
    real(wp), intent(in) :: displacement(:, :), velocity(:, :), dt
    real(wp), intent(out) :: deformation(3, 3), jacobian, mid_jacobian, gradient(9)
    real(wp) :: rate(3, 3), middle(3, 3), inverse(3, 3), velocity_gradient(3, 3)
    integer :: k, node, i, j
    deformation = 0.0_wp
    rate = 0.0_wp
    do k = geometry%point_offsets(g), geometry%point_offsets(g + 1) - 1
      node = geometry%pair_node(k)
      do j = 1, 3
        deformation(:, j) = deformation(:, j) + displacement(:, node)*geometry%pair_gradient(j, k)
        rate(:, j) = rate(:, j) + velocity(:, node)*geometry%pair_gradient(j, k)
      end do
    end do
    do i = 1, 3
      deformation(i, i) = deformation(i, i) + 1.0_wp
    end do
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

  !> pair_force(:, k) = W_g P bbar_k with P = J (sigma - q I) Fbar^-T.
  subroutine write_pair_forces(geometry, g, deformation, jacobian, stress, bulk_viscosity, pair_force)
    type(efg_part_t), intent(in) :: geometry
    integer, intent(in) :: g
    real(wp), intent(in) :: deformation(3, 3), jacobian, stress(6), bulk_viscosity
    real(wp), intent(inout) :: pair_force(:, :)
    real(wp) :: cauchy(3, 3), inverse(3, 3), first_piola(3, 3)
    integer :: k
    cauchy = reshape([stress(1), stress(4), stress(6), stress(4), stress(2), stress(5), &
                      stress(6), stress(5), stress(3)], [3, 3])
    cauchy(1, 1) = cauchy(1, 1) - bulk_viscosity
    cauchy(2, 2) = cauchy(2, 2) - bulk_viscosity
    cauchy(3, 3) = cauchy(3, 3) - bulk_viscosity
    call invert(deformation, jacobian, inverse)
    first_piola = geometry%point_volume(g)*jacobian*matmul(cauchy, transpose(inverse))
    do k = geometry%point_offsets(g), geometry%point_offsets(g + 1) - 1
      pair_force(:, k) = matmul(first_piola, geometry%pair_gradient(:, k))
    end do
  end subroutine write_pair_forces

  !> Power of point g's pair forces on the velocities: sum over its pairs of f . v(node).
  pure real(wp) function pair_power(geometry, g, pair_force, velocity)
    type(efg_part_t), intent(in) :: geometry
    integer, intent(in) :: g
    real(wp), intent(in) :: pair_force(:, :), velocity(:, :)
    integer :: k
    pair_power = 0.0_wp
    do k = geometry%point_offsets(g), geometry%point_offsets(g + 1) - 1
      pair_power = pair_power + dot_product(pair_force(:, k), velocity(:, geometry%pair_node(k)))
    end do
  end function pair_power

  !> Smallest principal stretch of F: the square root of the smallest eigenvalue of C = F^T F,
  !> from the trigonometric solution of the characteristic cubic of a symmetric 3x3 matrix
  !> (Smith, Comm. ACM 4 (1961) 168).
  pure real(wp) function smallest_stretch(deformation)
    real(wp), intent(in) :: deformation(3, 3)
    real(wp) :: c(3, 3), mean, off_diagonal, spread_squared, spread, half_det, angle, shifted(3, 3)
    real(wp), parameter :: pi = 3.14159265358979323846_wp
    integer :: i
    c = matmul(transpose(deformation), deformation)
    mean = (c(1, 1) + c(2, 2) + c(3, 3))/3.0_wp
    off_diagonal = c(1, 2)**2 + c(1, 3)**2 + c(2, 3)**2
    spread_squared = ((c(1, 1) - mean)**2 + (c(2, 2) - mean)**2 + (c(3, 3) - mean)**2 + 2.0_wp*off_diagonal)/6.0_wp
    if (spread_squared <= epsilon(1.0_wp)*mean**2) then
      smallest_stretch = sqrt(max(mean, 0.0_wp))
      return
    end if
    spread = sqrt(spread_squared)
    shifted = c
    do i = 1, 3
      shifted(i, i) = shifted(i, i) - mean
    end do
    half_det = 0.5_wp*determinant(shifted/spread)
    angle = acos(max(-1.0_wp, min(1.0_wp, half_det)))/3.0_wp
    ! the eigenvalues are mean + 2 spread cos(angle + 2 pi k / 3); k = 1 gives the smallest
    smallest_stretch = sqrt(max(mean + 2.0_wp*spread*cos(angle + 2.0_wp*pi/3.0_wp), 0.0_wp))
  end function smallest_stretch

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
  subroutine transform_to_physical(solver, field, physical)
    type(efg_solver_t), intent(in) :: solver
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
end module efg_forces
