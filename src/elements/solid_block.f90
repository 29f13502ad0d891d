!> Blocks of hexahedral solid elements of one part and the per-cycle element work on them:
!> kinematics, objective stress update through the material dispatch, bulk viscosity, corner
!> forces (stress divergence + hourglass control + bulk viscosity), energies and time step.
!>
!> A block holds at most `block_size` elements of one part (hence one material, section and
!> hourglass setting) with all per-element arrays lane-first, so every kernel below runs its
!> innermost loop over the elements of the block. The solver calls, per cycle and per block,
!> `compute_solid_block` (blocks are independent, so they can be spread over threads) and
!> gathers the corner forces to the nodes itself.
!>
!> Time centring: coordinates are x(n+1), velocities v(n+1/2). The velocity gradient is taken
!> at the mid-step configuration x(n+1/2) = x(n+1) - dt/2 v(n+1/2) (second-order strain
!> increments; a rigid rotation then gives D = 0 exactly and, with the orthogonal incremental
!> rotation, the exact rotation of the stress); forces, volume and time step use x(n+1).
!>
!> Energies are the work of the element's corner forces (internal energy: stress divergence and
!> bulk viscosity; hourglass energy: hourglass forces), integrated exactly as central
!> differences integrate the kinetic energy 1/2 m v(n-1/2) . v(n+1/2): the force f(m) of call m
!> works over (dt(m-1/2) + dt(m+1/2))/2 against (v(m-1/2) + v(m+1/2))/2. Call m+1 recomputes
!> f(m) . v(m+1/2) from the stored state on x(m) = x(m+1) - dt v(m+1/2), completes the work of
!> f(m) with the stored f(m) . v(m-1/2), and books the first half of the work of f(m+1) with the
!> current step (corrected by the next call if the step changes: until then the balance is off
!> by 1/4 (dt(m+1/2) - dt(m-1/2)) (force_power + hourglass_power), which a solver that knows its
!> next step can add when it reports). Kinetic plus internal plus hourglass energy then balances
!> to round-off (exactly for a constant step), which the stress-power
!> integral V (sigma(n) + sigma(n+1))/2 : D dt does only to O(dt^2) (it drifts by percents over
!> 10^4 cycles of a vibrating block at TSSFAC 0.9). The viscous forces (bulk viscosity, viscous
!> hourglass control) damp the motion over a step; the solver's first call, with dt = 0, has no
!> step, so they are zero there (otherwise their work over the first half step, whose length
!> this call cannot know, would be missing from the energy at t = 0).
module solid_block
  use kinds, only: wp, block_size
  use model, only: model_t, material_t, formulation_fe
  use material_dispatch, only: material_history_count, initialize_material_history, update_material_block, &
                               rotate_material_history, material_wave_modulus, material_plastic_strain, &
                               material_stiffness_bounds
  use objective_rotation, only: incremental_rotation, rotate_symmetric_tensors
  use hex8_geometry, only: hex8_volume_derivatives, hex8_volume, hex8_velocity_gradient, hex8_largest_face_area, &
                           hex8_gauss_natural_derivatives, hex8_point_derivatives, deformation_increments, &
                           hex8_gradient_invariants, distinct_corner_count, tetrahedron_corner_order, &
                           hex8_corner_volumes
  use hex8_one_point, only: one_point_corner_forces, hourglass_shape_vectors, hourglass_viscous_forces, &
                            hourglass_stiffness_forces, one_point_force_powers, previous_hourglass_velocities, &
                            hourglass_power, hourglass_mode_bounds, standard_hourglass_overlap
  use hex8_full, only: point_velocity_gradient, add_deviatoric_point_forces, add_mean_stress_forces, &
                       add_point_stress_power, corner_force_power, add_point_gram, deviatoric_mode_bound, &
                       add_point_gradient_norm, deviatoric_mode_trace_bound
  use element_work, only: add_force_work, smallest_time_step
  use solid_exposure, only: exposed_elements
  use element_ordering, only: spatial_element_order
  use element_time_step, only: bulk_viscosity_pressure, solid_element_time_steps, eigenvalue_time_steps
  use erosion_criteria, only: plastic_failure_limit, principal_strains_active, failed_points_needed, principal_strains_fail, &
                              principal_log_strains_3d
  implicit none
  private

  public :: build_solid_blocks, solid_block_corner_masses, solid_block_time_steps, compute_solid_block
  public :: solid_block_element_results

  !> ELFORM values this module implements.
  integer, parameter, public :: formulation_one_point = 1, formulation_selective_reduced = 2

  !> Up to `block_size` hexahedra of one part and their state. Lane i describes model solid
  !> `elements(i)`; lanes beyond `element_count` are unused.
  type, public :: solid_block_t
    integer :: element_count = 0                 !< 1..block_size
    integer :: part = 0                          !< index into model%parts
    integer :: material = 0                      !< index into model%materials
    integer :: formulation = 1                   !< ELFORM 1 (one point) or 2 (selective-reduced)
    integer :: hourglass_type = 1                !< effective IHQ (1-5)
    real(wp) :: hourglass_coefficient = 0.1_wp   !< QM
    real(wp) :: bulk_quadratic = 1.5_wp          !< Q1
    real(wp) :: bulk_linear = 0.06_wp            !< Q2
    integer :: elements(block_size) = 0          !< model solid index of each lane
    !> Lanes whose element sits at a corner or edge of the mesh (solid_exposure): only they get
    !> the eigenvalue bound on their step; a block without them skips it.
    logical :: exposed(block_size) = .false.
    integer :: exposed_count = 0                 !< number of exposed lanes
    integer :: nodes(block_size, 8) = 0          !< node indices of each corner
    !> Degenerate elements (repeated nodes: wedges, pyramids, tetrahedra; degenerate_lanes).
    logical :: degenerate(block_size) = .false.
    !> Tetrahedra among them: no hourglass modes and the characteristic length of a tetrahedron.
    logical :: tetrahedron(block_size) = .false.
    !> Corner masses in units of rho V0 / 8: 1 on a hexahedron; on a degenerate element each
    !> node's row sum of the consistent mass shared equally by its corners (degenerate_lanes).
    real(wp) :: corner_weight(block_size, 8) = 1.0_wp
    real(wp) :: density(block_size) = 0.0_wp     !< effective density (raised by mass scaling)
    real(wp) :: reference_volume(block_size) = 0.0_wp   !< exact initial volume
    real(wp) :: internal_energy(block_size) = 0.0_wp    !< cumulative, bulk viscosity work included
    real(wp) :: hourglass_energy(block_size) = 0.0_wp   !< cumulative work of the hourglass forces
    real(wp) :: volume(block_size) = 0.0_wp             !< current volume (end of the last step)
    real(wp) :: bulk_viscosity(block_size) = 0.0_wp     !< q of the last step
    real(wp) :: force_power(block_size) = 0.0_wp        !< f . v of the last call's stress and q forces
    real(wp) :: hourglass_power(block_size) = 0.0_wp    !< f . v of the last call's hourglass forces
    real(wp) :: previous_time_step = 0.0_wp             !< dt of the last call
    !> Smallest element step of the two calls before the last and its element (see
    !> compute_solid_block: the block reports the smallest of the last three).
    real(wp) :: recent_time_step(2) = huge(1.0_wp)
    integer :: recent_critical_element(2) = 0
    integer :: point_count = 1                   !< integration points: 1 (ELFORM 1) or 8 (ELFORM 2)
    integer :: material_law = 0                  !< law of the material (material_t%law)
    !> Cauchy stress (block_size, 6, point_count), order xx, yy, zz, xy, yz, zx.
    real(wp), allocatable :: stress(:, :, :)
    !> Material history (block_size, material_history_count, point_count), the law's layout.
    real(wp), allocatable :: history(:, :, :)
    !> Volume of each integration point (block_size, point_count), for averaging.
    real(wp), allocatable :: point_volume(:, :)
    !> Generalized hourglass forces Q (block_size, 3, 4) of the last call (ELFORM 1): the
    !> accumulated state of the stiffness forms (IHQ 4, 5), kept by the viscous forms for the
    !> work of the forces; (block_size, 3, 0) for ELFORM 2.
    real(wp), allocatable :: hourglass_force(:, :, :)
    !> Erosion (erode_failed_lanes): lanes that failed are out of the force loops for good; the
    !> kernels run them on their reference geometry at rest, and their forces, powers and step
    !> are discarded.
    logical :: eroded(block_size) = .false.
    logical :: newly_eroded(block_size) = .false.        !< eroded by the last call
    real(wp) :: erosion_time_step = 0.0_wp               !< ERODE: a lane whose step falls below erodes (0: off)
    real(wp) :: reference_coordinates(block_size, 8, 3) = 0.0_wp
  end type solid_block_t

contains

  !> Group the model's solids into blocks: parts in model order; in each part first the solids
  !> at a corner or edge of the mesh (solid_exposure), then the others, at most block_size per
  !> block (so that the other blocks skip the eigenvalue bound). Each group follows the part's
  !> spatially coherent order (element_ordering), so that a block is a compact patch of the
  !> mesh whatever the deck's numbering.
  !> Only parts discretised with finite elements (formulation_fe) get blocks; EFG and rigid
  !> parts are handled elsewhere. Sets every field, density = material density, exact reference
  !> volumes, zero stress, energies and history.
  subroutine build_solid_blocks(model, blocks)
    type(model_t), intent(in) :: model
    type(solid_block_t), allocatable, intent(out) :: blocks(:)
    integer, allocatable :: part_solid_count(:), first_of_part(:), ordered_solids(:), next_slot(:)
    integer, allocatable :: spatial_order(:)
    logical, allocatable :: exposed(:)
    integer :: part, solid, block_count, solid_count, part_count, lane, current, slot, k, order(8)

    solid_count = 0
    if (allocated(model%solid_part)) solid_count = size(model%solid_part)
    part_count = 0
    if (allocated(model%parts)) part_count = size(model%parts)

    ! Solids per part, and where each part's list starts.
    allocate (part_solid_count(part_count), first_of_part(part_count + 1), next_slot(part_count))
    part_solid_count = 0
    do solid = 1, solid_count
      part = model%solid_part(solid)
      if (model%parts(part)%formulation == formulation_fe) part_solid_count(part) = part_solid_count(part) + 1
    end do
    first_of_part(1) = 1
    do part = 1, part_count
      first_of_part(part + 1) = first_of_part(part) + part_solid_count(part)
    end do
    allocate (ordered_solids(first_of_part(part_count + 1) - 1))
    allocate (exposed(solid_count))
    if (solid_count > 0) exposed = exposed_elements(model%coordinates, model%solid_nodes)
    ! three shared nodes make a face: a quadrilateral, or the triangle of a degenerate hexahedron
    if (solid_count > 0) spatial_order = spatial_element_order(model%solid_nodes, model%solid_part, &
                                                              model%parts%formulation == formulation_fe, &
                                                              face_nodes=3, leading=exposed)
    next_slot = first_of_part(1:part_count)
    do k = 1, solid_count
      solid = spatial_order(k)
      part = model%solid_part(solid)
      if (model%parts(part)%formulation /= formulation_fe) cycle
      ordered_solids(next_slot(part)) = solid
      next_slot(part) = next_slot(part) + 1
    end do

    block_count = sum((part_solid_count + block_size - 1)/block_size)
    allocate (blocks(block_count))
    current = 0
    do part = 1, part_count
      lane = block_size
      do slot = first_of_part(part), first_of_part(part + 1) - 1
        if (lane == block_size) then
          current = current + 1
          call start_block(model, part, blocks(current))
          lane = 0
        end if
        lane = lane + 1
        solid = ordered_solids(slot)
        blocks(current)%element_count = lane
        blocks(current)%elements(lane) = solid
        call tetrahedron_corner_order(model%solid_nodes(:, solid), model%coordinates(:, model%solid_nodes(:, solid)), &
                                      order)
        blocks(current)%nodes(lane, :) = model%solid_nodes(order, solid)
        blocks(current)%exposed(lane) = exposed(solid)
        if (exposed(solid)) blocks(current)%exposed_count = blocks(current)%exposed_count + 1
      end do
    end do
    do current = 1, block_count
      call finish_block(model, blocks(current))
    end do
  end subroutine build_solid_blocks

  !> Part-level settings of a new block.
  subroutine start_block(model, part, block)
    type(model_t), intent(in) :: model
    integer, intent(in) :: part
    type(solid_block_t), intent(inout) :: block
    block%part = part
    block%material = model%parts(part)%material
    block%material_law = model%materials(block%material)%law
    block%formulation = formulation_one_point
    if (model%parts(part)%section > 0 .and. allocated(model%sections)) then
      if (model%sections(model%parts(part)%section)%element_formulation == formulation_selective_reduced) &
        block%formulation = formulation_selective_reduced
    end if
    ! IHQ 1-5 are implemented; anything else falls back to LS-DYNA's type 1.
    block%hourglass_type = model%parts(part)%hourglass_type
    if (block%hourglass_type < 1 .or. block%hourglass_type > 5) block%hourglass_type = 1
    block%hourglass_coefficient = model%parts(part)%hourglass_coefficient
    block%bulk_quadratic = model%parts(part)%bulk_quadratic
    block%bulk_linear = model%parts(part)%bulk_linear
  end subroutine start_block

  !> Allocate the state of a filled block and set its reference geometry.
  subroutine finish_block(model, block)
    type(model_t), intent(in) :: model
    type(solid_block_t), intent(inout) :: block
    real(wp) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8)
    real(wp) :: dndx(block_size, 8), dndy(block_size, 8), dndz(block_size, 8)
    real(wp) :: natural(8, 3, 8), element_edges(block_size, 6)
    integer :: nel, point, history_count

    nel = block%element_count
    block%point_count = merge(8, 1, block%formulation == formulation_selective_reduced)
    history_count = material_history_count(model%materials(block%material))
    allocate (block%stress(block_size, 6, block%point_count), source=0.0_wp)
    allocate (block%history(block_size, history_count, block%point_count), source=0.0_wp)
    allocate (block%point_volume(block_size, block%point_count), source=0.0_wp)
    if (block%formulation == formulation_one_point) then
      allocate (block%hourglass_force(block_size, 3, 4), source=0.0_wp)
    else
      allocate (block%hourglass_force(block_size, 3, 0))
    end if
    block%density(1:nel) = model%materials(block%material)%density
    call gather_coordinates(nel, block%nodes, model%coordinates, x, y, z)
    block%reference_coordinates(:, :, 1) = x
    block%reference_coordinates(:, :, 2) = y
    block%reference_coordinates(:, :, 3) = z
    ! Element edges 1-2 and 1-4: the material axes of AOPT 0 (honeycombs).
    element_edges(1:nel, :) = reshape([x(1:nel, 2) - x(1:nel, 1), y(1:nel, 2) - y(1:nel, 1), &
                                       z(1:nel, 2) - z(1:nel, 1), x(1:nel, 4) - x(1:nel, 1), &
                                       y(1:nel, 4) - y(1:nel, 1), z(1:nel, 4) - z(1:nel, 1)], [nel, 6])
    do point = 1, block%point_count
      call initialize_material_history(model%materials(block%material), nel, block%history(:, :, point), &
                                       element_edges)
    end do
    call hex8_volume_derivatives(nel, x, y, z, bx, by, bz, block%reference_volume)
    block%volume(1:nel) = block%reference_volume(1:nel)
    call degenerate_lanes(block, x, y, z)
    if (block%point_count == 1) then
      block%point_volume(1:nel, 1) = block%reference_volume(1:nel)
    else
      call hex8_gauss_natural_derivatives(natural)
      do point = 1, 8
        call hex8_point_derivatives(nel, natural(:, :, point), x, y, z, dndx, dndy, dndz, &
                                    block%point_volume(:, point))
      end do
    end if
  end subroutine finish_block

  !> Degenerate elements of a filled block (x, y, z its reference coordinates). A hexahedron
  !> lumps rho V0 / 8 at each corner. With repeated nodes that would give a tetrahedron's
  !> repeated node 5/8 of its mass: instead each node gets its row sum of the consistent mass,
  !> rho times the integral of its shape function (hex8_corner_volumes): V / 4 at each node of a
  !> tetrahedron, V / 6 at each node of a right wedge, V / 4 at a pyramid's apex. The repeated
  !> corners of a node share its mass equally; the eigenvalue bound on the step (which treats
  !> the corners as free points) stays a bound, since tying corners together lowers the
  !> frequencies.
  subroutine degenerate_lanes(block, x, y, z)
    type(solid_block_t), intent(inout) :: block
    real(wp), intent(in) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp) :: corner_volume(block_size, 8), node_volume
    integer :: i, corner, distinct, lane_nodes(8)
    call hex8_corner_volumes(block%element_count, x, y, z, corner_volume)
    do i = 1, block%element_count
      lane_nodes = block%nodes(i, :)
      distinct = distinct_corner_count(lane_nodes)
      block%degenerate(i) = distinct < 8
      block%tetrahedron(i) = distinct == 4
      if (.not. block%degenerate(i)) cycle
      do corner = 1, 8
        node_volume = sum(corner_volume(i, :), mask=block%nodes(i, :) == block%nodes(i, corner))
        block%corner_weight(i, corner) = 8.0_wp*node_volume &
                                         /(count(block%nodes(i, :) == block%nodes(i, corner))*block%reference_volume(i))
      end do
    end do
  end subroutine degenerate_lanes

  !> Corner masses density * reference volume / 8 (a degenerate element: times its corner
  !> weights, degenerate_lanes); lanes beyond element_count zero.
  subroutine solid_block_corner_masses(block, corner_mass)
    type(solid_block_t), intent(in) :: block
    real(wp), intent(out) :: corner_mass(block_size, 8)
    integer :: node, nel
    nel = block%element_count
    corner_mass = 0.0_wp
    do node = 1, 8
      corner_mass(1:nel, node) = 0.125_wp*block%density(1:nel)*block%reference_volume(1:nel) &
                                 *block%corner_weight(1:nel, node)
    end do
  end subroutine solid_block_corner_masses

  !> Stable time step of each element at the given configuration, at rest (no bulk viscosity:
  !> no rates are known here) and without TSSFAC; lanes beyond element_count get huge.
  subroutine solid_block_time_steps(block, material, coordinates, element_time_step)
    type(solid_block_t), intent(in) :: block
    type(material_t), intent(in) :: material
    real(wp), intent(in), contiguous :: coordinates(:, :)
    real(wp), intent(out) :: element_time_step(block_size)
    real(wp) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8)
    real(wp) :: dndx(block_size, 8), dndy(block_size, 8), dndz(block_size, 8), natural(8, 3, 8)
    real(wp) :: gamma(block_size, 8, 4), gram(block_size, 36), determinant(block_size)
    real(wp) :: volume(block_size), wave_modulus(block_size), rest(block_size)
    real(wp) :: density(block_size), sound_speed(block_size), hourglass_volume(block_size)
    real(wp) :: gradient_norm_squared(block_size), mode_frequency_squared(block_size), mode_damping(block_size)
    real(wp) :: viscosity_scale(block_size)
    integer :: nel, point
    nel = block%element_count
    element_time_step = huge(1.0_wp)
    call gather_coordinates(nel, block%nodes, coordinates, x, y, z)
    call hex8_volume_derivatives(nel, x, y, z, bx, by, bz, volume)
    call material_wave_modulus(material, nel, wave_modulus)
    call current_density_and_speed(nel, block%density, block%reference_volume, volume, wave_modulus, &
                                   density, sound_speed)
    rest(1:nel) = 0.0_wp
    if (block%exposed_count == 0) then
      ! no exposed lane: LS-DYNA's rule alone (stable_time_steps reads no mode bounds)
    else if (block%formulation == formulation_selective_reduced) then
      call hex8_gauss_natural_derivatives(natural)
      gram(1:nel, :) = 0.0_wp
      do point = 1, 8
        call hex8_point_derivatives(nel, natural(:, :, point), x, y, z, dndx, dndy, dndz, determinant)
        if (use_gram(material)) then
          call add_point_gram(nel, determinant, dndx, dndy, dndz, gram)
        else
          call add_point_gradient_norm(nel, determinant, dndx, dndy, dndz, gram(:, 1))
        end if
      end do
      call deviatoric_modes(block, material, nel, gram, bx, by, bz, volume, mode_frequency_squared, mode_damping)
      call clear_tetrahedron_modes(block, nel, mode_frequency_squared, mode_damping)
    else
      call hourglass_shape_vectors(nel, block%hourglass_type, x, y, z, bx, by, bz, volume, gamma, &
                                   hourglass_volume, gradient_norm_squared)
      call clear_tetrahedron_hourglass(block, nel, gamma)
      ! a_h / QM of hourglass_viscous_forces
      viscosity_scale(1:nel) = 0.25_wp*density(1:nel)*sound_speed(1:nel) &
                               *abs(hourglass_volume(1:nel))**(2.0_wp/3.0_wp)
      call hourglass_mode_bounds(nel, block%hourglass_type, block%hourglass_coefficient, wave_modulus, &
                                 viscosity_scale, hourglass_volume, gradient_norm_squared, gamma, &
                                 corner_mass_of(block, nel), mode_frequency_squared, mode_damping)
      call clear_tetrahedron_modes(block, nel, mode_frequency_squared, mode_damping)
    end if
    call stable_time_steps(block, material, nel, x, y, z, bx, by, bz, volume, wave_modulus, rest, &
                           mode_frequency_squared, mode_damping, element_time_step)
  end subroutine solid_block_time_steps

  !> Stable step of each lane (no TSSFAC) on the configuration x: LS-DYNA's rule, and on the
  !> exposed lanes the smaller of it and the element's eigenvalue bound (element_time_step),
  !> given the frequency and damping bounds of the formulation's other modes (hourglass modes
  !> of ELFORM 1, extra deviatoric modes of ELFORM 2; not read in a block without exposed
  !> lanes). Lanes 1..nel of element_time_step are overwritten.
  subroutine stable_time_steps(block, material, nel, x, y, z, bx, by, bz, volume, wave_modulus, volumetric_rate, &
                               mode_frequency_squared, mode_damping, element_time_step)
    type(solid_block_t), intent(in) :: block
    type(material_t), intent(in) :: material
    integer, intent(in) :: nel
    real(wp), intent(in) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp), intent(in) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8), volume(block_size)
    real(wp), intent(in) :: wave_modulus(block_size), volumetric_rate(block_size)
    real(wp), intent(in) :: mode_frequency_squared(block_size), mode_damping(block_size)
    real(wp), intent(inout) :: element_time_step(block_size)
    real(wp) :: area(block_size), g(block_size, 6), trace_g(block_size), largest_g(block_size)
    real(wp) :: overlap(block_size), lame_bound, shear_bound, bound_time_step(block_size)
    real(wp) :: node_bx(block_size, 8), node_by(block_size, 8), node_bz(block_size, 8), node_weight(block_size, 8)
    logical :: standard
    integer :: i
    call hex8_largest_face_area(nel, x, y, z, area)
    ! a tetrahedron's characteristic length is its smallest altitude, 3 V / largest face (LS-DYNA's
    ! tetrahedra); the other shapes keep V / largest face
    do i = 1, nel
      if (block%tetrahedron(i)) area(i) = area(i)/3.0_wp
    end do
    call solid_element_time_steps(nel, block%bulk_quadratic, block%bulk_linear, volume, area, wave_modulus, &
                                  block%density, volumetric_rate, element_time_step)
    if (block%exposed_count == 0) return
    standard = block%formulation == formulation_one_point .and. block%hourglass_type == 1
    call merged_gradients(block, nel, bx, by, bz, node_bx, node_by, node_bz, node_weight)
    call hex8_gradient_invariants(nel, x, y, z, node_bx, node_by, node_bz, volume, g, trace_g, largest_g, overlap, &
                                  with_overlap=.not. standard, corner_weight=node_weight)
    ! IHQ 1's hourglass vectors are the plain base vectors, orthogonal to the strain modes only
    ! on parallelepipeds
    if (standard) call standard_hourglass_overlap(nel, bx, by, bz, volume, g, overlap)
    ! a degenerate element: no overlap bound (its corners carry unequal masses), the safe 1
    do i = 1, nel
      if (block%degenerate(i)) overlap(i) = 1.0_wp
    end do
    call material_stiffness_bounds(material, lame_bound, shear_bound)
    bound_time_step(1:nel) = element_time_step(1:nel)
    call eigenvalue_time_steps(nel, block%bulk_quadratic, block%bulk_linear, lame_bound, shear_bound, &
                               block%reference_volume, volume, block%density, volumetric_rate, trace_g, largest_g, &
                               overlap, mode_frequency_squared, mode_damping, bound_time_step)
    do i = 1, nel
      element_time_step(i) = merge(bound_time_step(i), element_time_step(i), block%exposed(i))
    end do
  end subroutine stable_time_steps

  !> ELFORM 2: frequency bound of the deviatoric modes beyond the one-point element's,
  !> 2 mu lambda_max(L) / m (hex8_full); they have no damping. `gram` holds the points' Gram
  !> matrix (use_gram, deviatoric_mode_bound) or, in its first column, its trace
  !> (deviatoric_mode_trace_bound).
  subroutine deviatoric_modes(block, material, nel, gram, bx, by, bz, volume, mode_frequency_squared, mode_damping)
    type(solid_block_t), intent(in) :: block
    type(material_t), intent(in) :: material
    integer, intent(in) :: nel
    real(wp), intent(in) :: gram(block_size, 36)
    real(wp), intent(in) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8), volume(block_size)
    real(wp), intent(out) :: mode_frequency_squared(block_size), mode_damping(block_size)
    real(wp) :: bound(block_size), corner_mass(block_size)
    if (use_gram(material)) then
      call deviatoric_mode_bound(nel, gram, bx, by, bz, volume, bound)
    else
      call deviatoric_mode_trace_bound(nel, gram(:, 1), bx, by, bz, volume, bound)
    end if
    corner_mass = corner_mass_of(block, nel)
    mode_frequency_squared(1:nel) = 2.0_wp*shear_bound_of(material)*bound(1:nel) &
                                    /max(corner_mass(1:nel), tiny(1.0_wp))
    mode_damping(1:nel) = 0.0_wp
  end subroutine deviatoric_modes

  !> ELFORM 2 computes the Gram matrix of its points' gradients (36 entries, a quarter of the
  !> element's cost) only where its extra deviatoric modes can set the step: when lambda < mu
  !> (nu < 1/4 for an elastic material). Above, the volumetric modes outrun them (a cube:
  !> omega^2 = 4 (3 lambda + 2 mu) / (rho L^2) against 8 mu / (rho L^2) exactly and 18.7 mu /
  !> (rho L^2) by the trace), and the trace bound, cheap and safe, does.
  logical function use_gram(material)
    type(material_t), intent(in) :: material
    real(wp) :: lame_bound, shear_bound
    call material_stiffness_bounds(material, lame_bound, shear_bound)
    use_gram = lame_bound < shear_bound
  end function use_gram

  !> mu of material_stiffness_bounds.
  real(wp) function shear_bound_of(material)
    type(material_t), intent(in) :: material
    real(wp) :: lame_bound
    call material_stiffness_bounds(material, lame_bound, shear_bound_of)
  end function shear_bound_of

  !> The volume derivatives and corner weights that the eigenvalue bound of the uniform-strain
  !> modes takes: a hexahedron's own; on a degenerate element those of its nodes, each node's
  !> summed over its corners and put at its first corner with the node's whole weight (the
  !> other corners get zero derivatives and weight 1). Corners of one node move together, so
  !> this bound is the element's, not that of eight free corners (several times larger on a
  !> tetrahedron, whose repeated corners have large derivatives of opposite sign).
  pure subroutine merged_gradients(block, nel, bx, by, bz, node_bx, node_by, node_bz, node_weight)
    type(solid_block_t), intent(in) :: block
    integer, intent(in) :: nel
    real(wp), intent(in) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8)
    real(wp), intent(out) :: node_bx(block_size, 8), node_by(block_size, 8), node_bz(block_size, 8)
    real(wp), intent(out) :: node_weight(block_size, 8)
    integer :: i, corner, other
    node_bx(1:nel, :) = bx(1:nel, :)
    node_by(1:nel, :) = by(1:nel, :)
    node_bz(1:nel, :) = bz(1:nel, :)
    node_weight(1:nel, :) = block%corner_weight(1:nel, :)
    do i = 1, nel
      if (.not. block%degenerate(i)) cycle
      do corner = 8, 1, -1
        other = findloc(block%nodes(i, 1:corner), block%nodes(i, corner), dim=1)
        if (other == corner) cycle
        node_bx(i, other) = node_bx(i, other) + node_bx(i, corner)
        node_by(i, other) = node_by(i, other) + node_by(i, corner)
        node_bz(i, other) = node_bz(i, other) + node_bz(i, corner)
        node_weight(i, other) = node_weight(i, other) + node_weight(i, corner)
        node_bx(i, corner) = 0.0_wp
        node_by(i, corner) = 0.0_wp
        node_bz(i, corner) = 0.0_wp
        node_weight(i, corner) = 1.0_wp
      end do
    end do
  end subroutine merged_gradients

  !> Lumped corner mass rho V0 / 8 of lanes 1..nel (the rest zero); for a degenerate element
  !> its smallest corner mass (the mode bounds that read it take one mass for all corners, and
  !> a smaller mass only raises them).
  pure function corner_mass_of(block, nel) result(corner_mass)
    type(solid_block_t), intent(in) :: block
    integer, intent(in) :: nel
    real(wp) :: corner_mass(block_size)
    integer :: i
    corner_mass = 0.0_wp
    corner_mass(1:nel) = 0.125_wp*block%density(1:nel)*block%reference_volume(1:nel)
    do i = 1, nel
      if (block%degenerate(i)) corner_mass(i) = corner_mass(i)*minval(block%corner_weight(i, :))
    end do
  end function corner_mass_of

  !> A tetrahedron's (absent) hourglass modes do not bound its step, nor, under ELFORM 2, its
  !> (absent) extra deviatoric modes: its gradients are the same at every Gauss point.
  pure subroutine clear_tetrahedron_modes(block, nel, mode_frequency_squared, mode_damping)
    type(solid_block_t), intent(in) :: block
    integer, intent(in) :: nel
    real(wp), intent(inout) :: mode_frequency_squared(block_size), mode_damping(block_size)
    integer :: i
    do i = 1, nel
      if (block%tetrahedron(i)) then
        mode_frequency_squared(i) = 0.0_wp
        mode_damping(i) = 0.0_wp
      end if
    end do
  end subroutine clear_tetrahedron_modes

  !> A tetrahedron has no hourglass modes: every motion of its four nodes is linear. The base
  !> vectors of IHQ 1-3 (not orthogonal to linear fields on a degenerate shape) would still
  !> damp its uniform straining and book that work as hourglass energy; its lanes get none.
  pure subroutine clear_tetrahedron_hourglass(block, nel, gamma)
    type(solid_block_t), intent(in) :: block
    integer, intent(in) :: nel
    real(wp), intent(inout) :: gamma(block_size, 8, 4)
    integer :: i
    do i = 1, nel
      if (block%tetrahedron(i)) gamma(i, :, :) = 0.0_wp
    end do
  end subroutine clear_tetrahedron_hourglass

  !> One cycle of element work on a block: strain increments from x(n+1) and v(n+1/2), stress
  !> and material state update, energies, corner forces on x(n+1), stable time step.
  !> corner_force(i, I, k) is the internal force on corner I of lane i in direction k (the solver
  !> uses a = (f_ext - sum of corner forces) / m); lanes beyond element_count are zero.
  !> critical_time_step / critical_element: smallest stable element step (no TSSFAC) of this
  !> call and the two before, and the model solid index of its element (a step that follows the
  !> bulk viscosity of the element's oscillation, on in compression and off in expansion, would
  !> alternate from cycle to cycle, and a step that alternates at the rate of the highest mode
  !> pumps energy into it: a single hexahedron at nu = 0 went unstable that way at TSSFAC 0.9
  !> when the bound counted the element's full bulk damping, a 17% alternation; over three
  !> cycles the smallest step holds still while the element rings). inverted_element: 0, or the
  !> model solid index of the first element whose volume (ELFORM 2: any Gauss point Jacobian)
  !> is <= 0; the state of the block is then not meaningful and the solver should stop.
  !> Allocates nothing.
  subroutine compute_solid_block(block, material, coordinates, velocities, dt, corner_force, &
                                 critical_time_step, critical_element, inverted_element)
    type(solid_block_t), intent(inout) :: block
    type(material_t), intent(in) :: material
    real(wp), intent(in), contiguous :: coordinates(:, :)
    real(wp), intent(in), contiguous :: velocities(:, :)
    real(wp), intent(in) :: dt
    real(wp), intent(out) :: corner_force(block_size, 8, 3)
    real(wp), intent(out) :: critical_time_step
    integer, intent(out) :: critical_element
    integer, intent(out) :: inverted_element
    real(wp) :: element_time_step(block_size), step
    real(wp) :: held_internal(block_size), held_hourglass(block_size)
    integer :: nel, i, point, element, k

    nel = block%element_count
    ! The kernels write lanes 1..nel only; the rest stay zero (huge for the time step).
    corner_force(nel + 1:, :, :) = 0.0_wp
    element_time_step(nel + 1:) = huge(1.0_wp)
    block%newly_eroded = .false.
    held_internal = block%internal_energy
    held_hourglass = block%hourglass_energy
    if (block%formulation == formulation_selective_reduced) then
      call compute_selective_reduced(block, material, coordinates, velocities, dt, corner_force, &
                                     element_time_step)
    else
      call compute_one_point(block, material, coordinates, velocities, dt, corner_force, &
                             element_time_step)
    end if
    block%previous_time_step = dt
    call erode_failed_lanes(block, material, nel, dt, coordinates, held_internal, held_hourglass, &
                            element_time_step, corner_force)

    call smallest_time_step(nel, element_time_step, block%elements, step, element)
    critical_time_step = step
    critical_element = element
    do k = 1, 2
      if (block%recent_time_step(k) < critical_time_step) then
        critical_time_step = block%recent_time_step(k)
        critical_element = block%recent_critical_element(k)
      end if
    end do
    block%recent_time_step = [step, block%recent_time_step(1)]
    block%recent_critical_element = [element, block%recent_critical_element(1)]
    inverted_element = 0
    ! Inverted: element volume (ELFORM 1) or a Gauss point volume (ELFORM 2) <= 0.
    lanes: do i = 1, nel
      if (block%eroded(i)) cycle
      do point = 1, block%point_count
        if (block%point_volume(i, point) <= 0.0_wp) then
          inverted_element = block%elements(i)
          exit lanes
        end if
      end do
    end do lanes
  end subroutine compute_solid_block

  !> ELFORM 1: Flanagan-Belytschko uniform strain hexahedron with hourglass control.
  subroutine compute_one_point(block, material, coordinates, velocities, dt, corner_force, &
                               element_time_step)
    type(solid_block_t), intent(inout) :: block
    type(material_t), intent(in) :: material
    real(wp), intent(in), contiguous :: coordinates(:, :), velocities(:, :)
    real(wp), intent(in) :: dt
    real(wp), intent(inout) :: corner_force(block_size, 8, 3)
    real(wp), intent(inout) :: element_time_step(block_size)
    real(wp) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp) :: vx(block_size, 8), vy(block_size, 8), vz(block_size, 8)
    real(wp) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8)
    real(wp) :: gamma(block_size, 8, 4)
    real(wp) :: gradient(block_size, 9), rotation(block_size, 9)
    real(wp) :: strain_increment(block_size, 6), spin_increment(block_size, 3)
    real(wp) :: old_stress(block_size, 6), old_bulk_viscosity(block_size), velocity_volume(block_size)
    real(wp) :: old_gradient_sum(block_size, 9), old_volume(block_size), old_hourglass_velocity(block_size, 12)
    real(wp) :: volume_mid(block_size), volume(block_size), volumetric_rate(block_size)
    real(wp) :: wave_modulus(block_size), density(block_size), sound_speed(block_size)
    real(wp) :: bulk_viscosity(block_size)
    real(wp) :: hourglass_volume(block_size), gradient_norm_squared(block_size)
    real(wp) :: old_power(block_size), new_power(block_size)
    real(wp) :: old_hourglass_power(block_size), new_hourglass_power(block_size)
    real(wp) :: mode_frequency_squared(block_size), mode_damping(block_size)
    real(wp) :: viscosity_scale(block_size)
    integer :: nel, i

    nel = block%element_count
    call gather_coordinates(nel, block%nodes, coordinates, x, y, z)
    call gather_coordinates(nel, block%nodes, velocities, vx, vy, vz)
    call hold_eroded_lanes(block, nel, x, y, z, vx, vy, vz)
    ! the state that made the previous call's forces, for their work over this step
    old_stress(1:nel, :) = block%stress(1:nel, :, 1)
    old_bulk_viscosity(1:nel) = block%bulk_viscosity(1:nel)

    ! Kinematics at the mid-step configuration x(n+1/2) = x(n+1) - dt/2 v(n+1/2).
    call hex8_velocity_gradient(nel, -0.5_wp*dt, x, y, z, vx, vy, vz, gradient, volume_mid)
    do i = 1, nel
      volumetric_rate(i) = gradient(i, 1) + gradient(i, 5) + gradient(i, 9)
    end do
    call deformation_increments(nel, dt, gradient, volumetric_rate, strain_increment, spin_increment)

    ! Objective rotation of the state, then the constitutive update.
    call incremental_rotation(nel, spin_increment, rotation)
    call rotate_symmetric_tensors(nel, rotation, block%stress(:, :, 1))
    call rotate_material_history(material, nel, rotation, block%history(:, :, 1))
    call update_material_block(material, nel, dt, strain_increment, block%stress(:, :, 1), &
                               block%history(:, :, 1), wave_modulus)

    ! End-of-step geometry and bulk viscosity.
    call hex8_volume_derivatives(nel, x, y, z, bx, by, bz, volume)
    call current_density_and_speed(nel, block%density, block%reference_volume, volume, wave_modulus, &
                                   density, sound_speed)
    call bulk_viscosity_pressure(nel, block%bulk_quadratic, block%bulk_linear, density, sound_speed, volume, &
                                 volumetric_rate, bulk_viscosity)
    if (dt <= 0.0_wp) bulk_viscosity(1:nel) = 0.0_wp ! no step: no viscous forces (module comment)

    ! Power of the stress forces of the previous call and of this one (module comment).
    call hex8_volume(nel, vx, vy, vz, velocity_volume)
    call one_point_force_powers(nel, dt, bx, by, bz, volume, vx, vy, vz, gradient, volume_mid, velocity_volume, &
                                old_stress, old_bulk_viscosity, block%stress(:, :, 1), bulk_viscosity, &
                                old_gradient_sum, old_volume, old_power, new_power)

    ! Hourglass control: power of the previous forces, new forces and their power.
    call previous_hourglass_velocities(nel, block%hourglass_type, dt, x, y, z, vx, vy, vz, old_gradient_sum, &
                                       old_volume, old_hourglass_velocity)
    call hourglass_power(nel, block%hourglass_force, old_hourglass_velocity, old_hourglass_power)
    call hourglass_shape_vectors(nel, block%hourglass_type, x, y, z, bx, by, bz, volume, gamma, &
                                 hourglass_volume, gradient_norm_squared)
    call clear_tetrahedron_hourglass(block, nel, gamma)
    if (block%hourglass_type >= 4) then
      call hourglass_stiffness_forces(nel, block%hourglass_coefficient, dt, wave_modulus, hourglass_volume, &
                                      gradient_norm_squared, rotation, gamma, vx, vy, vz, block%hourglass_force, &
                                      new_hourglass_power)
    else
      call hourglass_viscous_forces(nel, merge(block%hourglass_coefficient, 0.0_wp, dt > 0.0_wp), density, &
                                    sound_speed, hourglass_volume, gamma, vx, vy, vz, block%hourglass_force, &
                                    new_hourglass_power, viscosity_scale)
    end if

    ! All corner forces in one pass, then the work of the forces.
    call one_point_corner_forces(nel, bx, by, bz, block%stress(:, :, 1), bulk_viscosity, gamma, &
                                 block%hourglass_force, corner_force)
    call add_force_work(nel, dt, block%previous_time_step, old_power, new_power, block%force_power, &
                        block%internal_energy)
    call add_force_work(nel, dt, block%previous_time_step, old_hourglass_power, new_hourglass_power, &
                        block%hourglass_power, block%hourglass_energy)

    if (block%exposed_count > 0) then
      if (block%hourglass_type >= 4) viscosity_scale(1:nel) = 0.0_wp
      call hourglass_mode_bounds(nel, block%hourglass_type, block%hourglass_coefficient, wave_modulus, &
                                 viscosity_scale, hourglass_volume, gradient_norm_squared, gamma, &
                                 corner_mass_of(block, nel), mode_frequency_squared, mode_damping)
      call clear_tetrahedron_modes(block, nel, mode_frequency_squared, mode_damping)
    end if
    call stable_time_steps(block, material, nel, x, y, z, bx, by, bz, volume, wave_modulus, volumetric_rate, &
                           mode_frequency_squared, mode_damping, element_time_step)
    block%volume(1:nel) = volume(1:nel)
    block%point_volume(1:nel, 1) = volume(1:nel)
    block%bulk_viscosity(1:nel) = bulk_viscosity(1:nel)
  end subroutine compute_one_point

  !> ELFORM 2: selective-reduced 2x2x2 hexahedron (deviatoric at the points, volumetric from
  !> the element mean).
  subroutine compute_selective_reduced(block, material, coordinates, velocities, dt, corner_force, &
                                       element_time_step)
    type(solid_block_t), intent(inout) :: block
    type(material_t), intent(in) :: material
    real(wp), intent(in), contiguous :: coordinates(:, :), velocities(:, :)
    real(wp), intent(in) :: dt
    real(wp), intent(inout) :: corner_force(block_size, 8, 3)
    real(wp), intent(inout) :: element_time_step(block_size)
    real(wp) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp) :: xm(block_size, 8), ym(block_size, 8), zm(block_size, 8)
    real(wp) :: vx(block_size, 8), vy(block_size, 8), vz(block_size, 8)
    real(wp) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8)
    real(wp) :: dndx(block_size, 8), dndy(block_size, 8), dndz(block_size, 8)
    real(wp) :: natural(8, 3, 8)
    real(wp) :: gradient(block_size, 9, 8), point_gradient(block_size, 9), determinant(block_size)
    real(wp) :: rotation(block_size, 9), strain_increment(block_size, 6), spin_increment(block_size, 3)
    real(wp) :: volume_mid(block_size), volume(block_size), volumetric_rate(block_size)
    real(wp) :: wave_modulus(block_size), density(block_size), sound_speed(block_size)
    real(wp) :: bulk_viscosity(block_size), mean_stress(block_size)
    real(wp) :: old_power(block_size), new_power(block_size), trace_integral(block_size)
    real(wp) :: gram(block_size, 36), mode_frequency_squared(block_size), mode_damping(block_size)
    logical :: gram_wanted, bound_wanted
    integer :: nel, i, point

    nel = block%element_count
    call hex8_gauss_natural_derivatives(natural)
    call gather_coordinates(nel, block%nodes, coordinates, x, y, z)
    call gather_coordinates(nel, block%nodes, velocities, vx, vy, vz)
    call hold_eroded_lanes(block, nel, x, y, z, vx, vy, vz)

    ! Power of the forces f(n) of the previous call over this step, from the point stresses and
    ! q they were made of on the configuration x(n) = x(n+1) - dt v(n+1/2).
    call shifted_configuration(nel, -dt, vx, vy, vz, x, y, z, xm, ym, zm)
    old_power(1:nel) = 0.0_wp
    mean_stress(1:nel) = 0.0_wp
    trace_integral(1:nel) = 0.0_wp
    volume(1:nel) = 0.0_wp
    do point = 1, 8
      call hex8_point_derivatives(nel, natural(:, :, point), xm, ym, zm, dndx, dndy, dndz, determinant)
      call point_velocity_gradient(nel, dndx, dndy, dndz, vx, vy, vz, point_gradient)
      call add_point_stress_power(nel, determinant, point_gradient, block%stress(:, :, point), old_power, &
                                  mean_stress, trace_integral)
      volume(1:nel) = volume(1:nel) + determinant(1:nel)
    end do
    do i = 1, nel
      old_power(i) = old_power(i) + (mean_stress(i)/sign(max(abs(volume(i)), tiny(1.0_wp)), volume(i)) &
                                     - block%bulk_viscosity(i))*trace_integral(i)
    end do

    ! Point velocity gradients at the mid-step configuration and the element mean dilatation.
    call shifted_configuration(nel, -0.5_wp*dt, vx, vy, vz, x, y, z, xm, ym, zm)
    volume_mid(1:nel) = 0.0_wp
    volumetric_rate(1:nel) = 0.0_wp
    do point = 1, 8
      call hex8_point_derivatives(nel, natural(:, :, point), xm, ym, zm, dndx, dndy, dndz, determinant)
      call point_velocity_gradient(nel, dndx, dndy, dndz, vx, vy, vz, gradient(:, :, point))
      do i = 1, nel
        volume_mid(i) = volume_mid(i) + determinant(i)
        volumetric_rate(i) = volumetric_rate(i) + determinant(i) &
                             *(gradient(i, 1, point) + gradient(i, 5, point) + gradient(i, 9, point))
      end do
    end do
    do i = 1, nel
      volumetric_rate(i) = volumetric_rate(i)/sign(max(abs(volume_mid(i)), tiny(1.0_wp)), volume_mid(i))
    end do

    ! Stress update and deviatoric forces point by point at x(n+1).
    corner_force(1:nel, :, :) = 0.0_wp
    bx(1:nel, :) = 0.0_wp
    by(1:nel, :) = 0.0_wp
    bz(1:nel, :) = 0.0_wp
    mean_stress(1:nel) = 0.0_wp
    ! the extra modes' bound, for the exposed lanes only
    bound_wanted = block%exposed_count > 0
    gram_wanted = bound_wanted .and. use_gram(material)
    if (gram_wanted) then
      gram(1:nel, :) = 0.0_wp
    else if (bound_wanted) then
      gram(1:nel, 1) = 0.0_wp
    end if
    do point = 1, 8
      call deformation_increments(nel, dt, gradient(:, :, point), volumetric_rate, strain_increment, &
                                  spin_increment)
      call incremental_rotation(nel, spin_increment, rotation)
      call rotate_symmetric_tensors(nel, rotation, block%stress(:, :, point))
      call rotate_material_history(material, nel, rotation, block%history(:, :, point))
      call update_material_block(material, nel, dt, strain_increment, block%stress(:, :, point), &
                                 block%history(:, :, point), wave_modulus)
      call hex8_point_derivatives(nel, natural(:, :, point), x, y, z, dndx, dndy, dndz, &
                                  block%point_volume(:, point))
      call add_deviatoric_point_forces(nel, block%point_volume(:, point), dndx, dndy, dndz, &
                                       block%stress(:, :, point), corner_force, mean_stress, bx, by, bz)
      if (gram_wanted) then
        call add_point_gram(nel, block%point_volume(:, point), dndx, dndy, dndz, gram)
      else if (bound_wanted) then
        call add_point_gradient_norm(nel, block%point_volume(:, point), dndx, dndy, dndz, gram(:, 1))
      end if
    end do

    volume(1:nel) = 0.0_wp
    do point = 1, 8
      do i = 1, nel
        volume(i) = volume(i) + block%point_volume(i, point)
      end do
    end do
    call current_density_and_speed(nel, block%density, block%reference_volume, volume, wave_modulus, &
                                   density, sound_speed)
    call bulk_viscosity_pressure(nel, block%bulk_quadratic, block%bulk_linear, density, sound_speed, volume, &
                                 volumetric_rate, bulk_viscosity)
    if (dt <= 0.0_wp) bulk_viscosity(1:nel) = 0.0_wp ! no step: no viscous forces (module comment)
    do i = 1, nel
      mean_stress(i) = mean_stress(i)/sign(max(abs(volume(i)), tiny(1.0_wp)), volume(i)) - bulk_viscosity(i)
    end do
    call add_mean_stress_forces(nel, bx, by, bz, mean_stress, corner_force)

    ! Work of the forces (see the module comment).
    call corner_force_power(nel, corner_force, vx, vy, vz, new_power)
    call add_force_work(nel, dt, block%previous_time_step, old_power, new_power, block%force_power, &
                        block%internal_energy)

    if (bound_wanted) then
      call deviatoric_modes(block, material, nel, gram, bx, by, bz, volume, mode_frequency_squared, mode_damping)
      call clear_tetrahedron_modes(block, nel, mode_frequency_squared, mode_damping)
    end if
    call stable_time_steps(block, material, nel, x, y, z, bx, by, bz, volume, wave_modulus, volumetric_rate, &
                           mode_frequency_squared, mode_damping, element_time_step)
    block%volume(1:nel) = volume(1:nel)
    block%bulk_viscosity(1:nel) = bulk_viscosity(1:nel)
  end subroutine compute_selective_reduced

  !> Eroded lanes run on their reference geometry at rest: no strain, finite geometry however
  !> far their nodes have flown, so nothing in the kernels can overflow or trap.
  pure subroutine hold_eroded_lanes(block, nel, x, y, z, vx, vy, vz)
    type(solid_block_t), intent(in) :: block
    integer, intent(in) :: nel
    real(wp), intent(inout) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp), intent(inout) :: vx(block_size, 8), vy(block_size, 8), vz(block_size, 8)
    integer :: i
    if (.not. any(block%eroded(1:nel))) return
    do i = 1, nel
      if (.not. block%eroded(i)) cycle
      x(i, :) = block%reference_coordinates(i, :, 1)
      y(i, :) = block%reference_coordinates(i, :, 2)
      z(i, :) = block%reference_coordinates(i, :, 3)
      vx(i, :) = 0.0_wp
      vy(i, :) = 0.0_wp
      vz(i, :) = 0.0_wp
    end do
  end subroutine hold_eroded_lanes

  !> After the kernel: lanes eroded before give no force and no step and keep the energy they
  !> had (`held_*`, before the call); lanes that fail now (effective plastic strain of enough
  !> points, principal strains of the centre, ERODE's smallest step) erode at once: their forces
  !> of this call are dropped and so is the half step of work add_force_work booked for them, so
  !> that their energy is exactly the work their applied forces did. Their stress, hourglass
  !> forces and bulk viscosity go to zero.
  subroutine erode_failed_lanes(block, material, nel, dt, coordinates, held_internal, held_hourglass, &
                                element_time_step, corner_force)
    type(solid_block_t), intent(inout) :: block
    type(material_t), intent(in) :: material
    integer, intent(in) :: nel
    real(wp), intent(in) :: dt
    real(wp), intent(in), contiguous :: coordinates(:, :)
    real(wp), intent(in) :: held_internal(block_size), held_hourglass(block_size)
    real(wp), intent(inout) :: element_time_step(block_size)
    real(wp), intent(inout) :: corner_force(block_size, 8, 3)
    real(wp) :: limit, point_strain(block_size), x(block_size, 8, 3)
    real(wp) :: bx(block_size, 8), by(block_size, 8), bz(block_size, 8), volume(block_size)
    real(wp) :: gradient(3, 3), largest, smallest
    integer :: failed_points(block_size), needed, i, point, k
    logical :: failed(block_size)

    failed(1:nel) = .false.
    limit = plastic_failure_limit(material)
    if (limit < huge(1.0_wp) .and. size(block%history, 2) > 0) then
      failed_points(1:nel) = 0
      do point = 1, block%point_count
        call material_plastic_strain(block%material_law, nel, block%history(:, :, point), point_strain)
        do i = 1, nel
          if (point_strain(i) >= limit) failed_points(i) = failed_points(i) + 1
        end do
      end do
      needed = failed_points_needed(material, block%point_count, .false.)
      failed(1:nel) = failed_points(1:nel) >= needed
    end if
    if (principal_strains_active(material)) then
      ! F of the centre: sum over the corners of x_I (x) dV0/dX_I / V0 (the mean F of the element)
      call gather_coordinates(nel, block%nodes, coordinates, x(:, :, 1), x(:, :, 2), x(:, :, 3))
      call hex8_volume_derivatives(nel, block%reference_coordinates(:, :, 1), block%reference_coordinates(:, :, 2), &
                                   block%reference_coordinates(:, :, 3), bx, by, bz, volume)
      do i = 1, nel
        if (block%eroded(i) .or. failed(i)) cycle
        do k = 1, 3
          gradient(k, 1) = sum(x(i, :, k)*bx(i, :))/volume(i)
          gradient(k, 2) = sum(x(i, :, k)*by(i, :))/volume(i)
          gradient(k, 3) = sum(x(i, :, k)*bz(i, :))/volume(i)
        end do
        call principal_log_strains_3d(gradient, largest, smallest)
        if (principal_strains_fail(material, largest, smallest)) failed(i) = .true.
      end do
    end if
    if (block%erosion_time_step > 0.0_wp) then
      do i = 1, nel
        if (element_time_step(i) < block%erosion_time_step) failed(i) = .true.
      end do
    end if
    do i = 1, nel
      if (block%eroded(i)) then
        block%internal_energy(i) = held_internal(i)
        block%hourglass_energy(i) = held_hourglass(i)
      else if (failed(i)) then
        block%internal_energy(i) = block%internal_energy(i) - 0.5_wp*dt*block%force_power(i)
        block%hourglass_energy(i) = block%hourglass_energy(i) - 0.5_wp*dt*block%hourglass_power(i)
        block%eroded(i) = .true.
        block%newly_eroded(i) = .true.
      else
        cycle
      end if
      block%force_power(i) = 0.0_wp
      block%hourglass_power(i) = 0.0_wp
      block%stress(i, :, :) = 0.0_wp
      block%hourglass_force(i, :, :) = 0.0_wp
      block%bulk_viscosity(i) = 0.0_wp
      corner_force(i, :, :) = 0.0_wp
      element_time_step(i) = huge(1.0_wp)
    end do
    ! an eroded element no longer sets the step through the last calls' memory (compute_solid_block)
    if (any(block%newly_eroded(1:nel))) then
      do k = 1, 2
        do i = 1, nel
          if (block%newly_eroded(i) .and. block%recent_critical_element(k) == block%elements(i)) then
            block%recent_time_step(k) = huge(1.0_wp)
            block%recent_critical_element(k) = 0
          end if
        end do
      end do
    end if
  end subroutine erode_failed_lanes

  !> x(i, I) = coordinates(1, nodes(i, I)) etc. for lanes 1..nel (also used for velocities).
  !> A plain scalar loop: on the machines measured it beats the vector gather instructions.
  subroutine gather_coordinates(nel, nodes, coordinates, x, y, z)
    integer, intent(in) :: nel
    integer, intent(in) :: nodes(block_size, 8)
    real(wp), intent(in) :: coordinates(3, *)
    real(wp), intent(out) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    integer :: node, i, global
    !GCC$ novector
    do i = 1, nel
      do node = 1, 8
        global = nodes(i, node)
        x(i, node) = coordinates(1, global)
        y(i, node) = coordinates(2, global)
        z(i, node) = coordinates(3, global)
      end do
    end do
  end subroutine gather_coordinates

  !> shifted = x + factor v on every corner (the mid-step configuration for factor = -dt/2).
  subroutine shifted_configuration(nel, factor, vx, vy, vz, x, y, z, shifted_x, shifted_y, shifted_z)
    integer, intent(in) :: nel
    real(wp), intent(in) :: factor
    real(wp), intent(in) :: vx(block_size, 8), vy(block_size, 8), vz(block_size, 8)
    real(wp), intent(in) :: x(block_size, 8), y(block_size, 8), z(block_size, 8)
    real(wp), intent(out) :: shifted_x(block_size, 8), shifted_y(block_size, 8), shifted_z(block_size, 8)
    integer :: node, i
    do i = 1, nel
      do node = 1, 8
        shifted_x(i, node) = x(i, node) + factor*vx(i, node)
        shifted_y(i, node) = y(i, node) + factor*vy(i, node)
        shifted_z(i, node) = z(i, node) + factor*vz(i, node)
      end do
    end do
  end subroutine shifted_configuration

  !> Current density rho_block V0 / V (kept finite and positive for an inverted element) and
  !> wave speed sqrt(rho c^2 / rho_block).
  subroutine current_density_and_speed(nel, block_density, reference_volume, volume, wave_modulus, &
                                       density, sound_speed)
    integer, intent(in) :: nel
    real(wp), intent(in) :: block_density(block_size), reference_volume(block_size), volume(block_size)
    real(wp), intent(in) :: wave_modulus(block_size)
    real(wp), intent(out) :: density(block_size), sound_speed(block_size)
    integer :: i
    do i = 1, nel
      ! an inverted or flattened element (the solver stops) gets at most 1e12 times its density:
      ! with tiny(1.0) here the bulk viscosity of the last cycle overflowed in the checked build
      density(i) = block_density(i)*reference_volume(i)/max(volume(i), 1.0e-12_wp*reference_volume(i), tiny(1.0_wp))
      sound_speed(i) = sqrt(max(wave_modulus(i), 0.0_wp)/max(block_density(i), tiny(1.0_wp)))
    end do
  end subroutine current_density_and_speed

  !> Element stress (volume average over the integration points) into column elements(i) of
  !> stress(6, solids), and the effective plastic strain (mean over the points, 0 for elastic
  !> laws) into plastic_strain(elements(i)).
  subroutine solid_block_element_results(block, stress, plastic_strain)
    type(solid_block_t), intent(in) :: block
    real(wp), intent(inout) :: stress(:, :)
    real(wp), intent(inout) :: plastic_strain(:)
    real(wp) :: point_plastic_strain(block_size), mean_plastic_strain(block_size)
    real(wp) :: average(block_size, 6), total_volume(block_size)
    integer :: nel, i, point, component

    nel = block%element_count
    average(1:nel, :) = 0.0_wp
    total_volume(1:nel) = 0.0_wp
    mean_plastic_strain(1:nel) = 0.0_wp
    do point = 1, block%point_count
      do component = 1, 6
        average(1:nel, component) = average(1:nel, component) &
                                    + block%point_volume(1:nel, point)*block%stress(1:nel, component, point)
      end do
      total_volume(1:nel) = total_volume(1:nel) + block%point_volume(1:nel, point)
    end do
    if (size(block%history, 2) > 0) then
      do point = 1, block%point_count
        call material_plastic_strain(block%material_law, nel, block%history(:, :, point), point_plastic_strain)
        mean_plastic_strain(1:nel) = mean_plastic_strain(1:nel) + point_plastic_strain(1:nel)/block%point_count
      end do
    end if
    do i = 1, nel
      stress(:, block%elements(i)) = average(i, :)/sign(max(abs(total_volume(i)), tiny(1.0_wp)), total_volume(i))
      plastic_strain(block%elements(i)) = mean_plastic_strain(i)
    end do
  end subroutine solid_block_element_results
end module solid_block
