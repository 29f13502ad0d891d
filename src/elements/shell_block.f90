!> Blocks of Belytschko-Tsay shell elements (*SECTION_SHELL ELFORM 2; triangles, N4 = N3, as C0
!> triangles with their own transverse shear, shell_triangle) and the per-cycle
!> element work on them.
!>
!> The element (Belytschko, Lin & Tsay 1984; Hallquist, LS-DYNA Theory Manual, "Belytschko-Tsay
!> shell") is a flat four-node quadrilateral with one in-plane integration point and a
!> corotational frame: e3 is normal to the diagonals, e1 follows side 1-2 projected on the
!> element plane, e2 = e3 x e1. Mindlin kinematics in that frame give, from the nodal
!> velocities v and angular velocities w (local components),
!>   membrane rates  d_x = B1 v_x,  d_y = B2 v_y,  2 d_xy = B2 v_x + B1 v_y
!>   curvature rates k_x = B1 w_y,  k_y = -B2 w_x, 2 k_xy = B2 w_y - B1 w_x
!>   shear rates     2 d_xz = B1 v_z + N w_y,  2 d_yz = B2 v_z - N w_x
!> (B1, B2: the one-point gradients of the bilinear functions; N: their centre values). The
!> rate at height z is d + z k; each integration point through the thickness (Gauss, NIP 1-10)
!> gets a plane-stress update through plane_stress_dispatch, in the local frame (stresses move
!> with the element; a small correction turns them with the material spin rather than with side
!> 1-2, see rotate_with_material). Transverse shear is elastic with the
!> shear factor SHRF. Resultants N = t sum w_k s_k, M = t sum w_k z_k s_k, Q = t sum w_k s_zk
!> give the nodal forces and moments as the transposes of the rates above, times the area.
!> The thickness stays constant, as in LS-DYNA's default (*CONTROL_SHELL ISTUPD = 0).
!>
!> A triangle (N4 = N3) is this element collapsed at corner 3, whose membrane and bending rates
!> are exactly the constant-strain triangle's; its transverse shear comes from its edges
!> (shell_triangle, against shear locking), it has no hourglass modes and its characteristic
!> length is 2 A / longest side (docs/shells.md, "Triangles").
!>
!> Hourglass control acts on the five modes a single point cannot see: in-plane (x, y),
!> out-of-plane (z) and the two bending modes, through the vector
!> gamma = h - (h . x) B1 - (h . y) B2 with h = (1, -1, 1, -1), orthogonal to every linear field
!> (so the patch test is unaffected). Its stiffnesses follow the forms of Belytschko & Tsay
!> (1983), scaled by the element's gradient norm so that they do not depend on the mesh size:
!> membrane E t A |B|^2 / 8, out-of-plane SHRF G t^3 |B|^2 / 6, bending E t^3 A |B|^2 / 192
!> (for a square A |B|^2 = 2; the out-of-plane form grows only with |B|^2 as an element is
!> crushed flat). IHQ 4 and 5 accumulate QM times these stiffnesses times the mode rates, on
!> Belytschko & Tsay's mode amplitudes (gamma / 4: a factor 1/16); IHQ 1-3 use viscous forces
!> QM sqrt(k m) times the rates, m the node's mass or rotary inertia.
!>
!> Time centring and energies as in solid_block: strain rates on the mid-step configuration,
!> forces on x(n+1); the internal and hourglass energies are the exact work of the element's
!> nodal forces and moments (element_work). Lumped masses rho t A / 4 per node; the rotary
!> inertia is scaled to m (t^2 + A) / 4 so that the rotations do not control the time step
!> (with the physical m t^2 / 12 the transverse-shear frequency of a thin shell would be L/t
!> times the membrane one; rotary_inertia_factor says why 1/4). Time step: L / c with
!> L = A / longest side (LS-DYNA's default) and c = sqrt(E / (rho (1 - nu^2))), unless a bound
!> on the out-of-plane frequencies asks for less (stable_steps).
module shell_block
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use kinds, only: wp, block_size
  use model, only: model_t, material_t, formulation_fe, law_null
  use plane_stress_dispatch, only: plane_stress_history_count, initialize_plane_stress_history, &
                                   update_plane_stress_block, plane_stress_plastic_strain, &
                                   rotate_plane_stress_history
  use element_work, only: add_force_work, smallest_time_step
  use gauss_legendre, only: gauss_legendre_rule
  use erosion_criteria, only: plastic_failure_limit, principal_strains_active, failed_points_needed, principal_strains_fail, &
                              principal_log_strains_2d
  use element_ordering, only: spatial_element_order
  use shell_triangle, only: triangle_shear_operator
  implicit none
  private

  public :: shell_block_t, build_shell_blocks, shell_block_masses, shell_block_time_steps, compute_shell_block
  public :: shell_block_element_results

  !> The most through-thickness points a section may ask for (NIP).
  integer, parameter, public :: max_shell_points = 10

  !> Up to `block_size` shells of one part and their state. Lane i describes model shell
  !> `elements(i)`; lanes beyond `element_count` are unused.
  type :: shell_block_t
    integer :: element_count = 0
    integer :: part = 0                          !< index into model%parts
    integer :: material = 0                      !< index into model%materials
    integer :: point_count = 2                   !< NIP
    integer :: hourglass_type = 1                !< effective IHQ (1-5)
    real(wp) :: hourglass_coefficient = 0.1_wp   !< QM
    real(wp) :: shear_factor = 1.0_wp            !< SHRF
    real(wp) :: point_height(max_shell_points) = 0.0_wp !< Gauss points through the thickness, in [-1/2, 1/2]
    real(wp) :: point_weight(max_shell_points) = 0.0_wp !< their weights, summing to 1
    integer :: elements(block_size) = 0          !< model shell index of each lane
    integer :: nodes(block_size, 4) = 0          !< node indices (a triangle repeats node 3)
    !> Lanes whose shell has two or more corners that no other shell shares (a lone shell, a
    !> pair, the ends of a single row): only they get the membrane eigenvalue bound on their
    !> step (stable_steps).
    logical :: exposed(block_size) = .false.
    real(wp) :: centre_weight(block_size, 4) = 0.25_wp !< shape functions at the centre (1/3 on a triangle)
    real(wp) :: thickness(block_size) = 0.0_wp   !< mean of the corner thicknesses
    real(wp) :: density(block_size) = 0.0_wp     !< raised by mass scaling
    real(wp) :: reference_area(block_size) = 0.0_wp
    real(wp) :: area(block_size) = 0.0_wp        !< at the end of the last step
    real(wp) :: internal_energy(block_size) = 0.0_wp
    real(wp) :: hourglass_energy(block_size) = 0.0_wp
    real(wp) :: force_power(block_size) = 0.0_wp
    real(wp) :: hourglass_power(block_size) = 0.0_wp
    real(wp) :: previous_time_step = 0.0_wp
    !> Generalized hourglass forces of the modes membrane x, y, out-of-plane, bending x, y.
    real(wp) :: hourglass_force(block_size, 5) = 0.0_wp
    !> Global nodal forces (1-3) and moments (4-6) of the last call: stress and hourglass parts,
    !> kept for the work they do over the next step.
    real(wp) :: previous_force(block_size, 4, 6) = 0.0_wp
    real(wp) :: previous_hourglass_force(block_size, 4, 6) = 0.0_wp
    !> Corotational frame of the last call: frame(i, a, k) = component k of e_a.
    real(wp) :: frame(block_size, 3, 3) = 0.0_wp
    !> Local stress (block_size, 5, point_count): xx, yy, xy, yz, zx.
    real(wp), allocatable :: stress(:, :, :)
    !> Plane-stress material history (block_size, count, point_count).
    real(wp), allocatable :: history(:, :, :)
    !> Erosion (erode_failed_lanes): as the solids' (solid_block), on the reference geometry
    !> at rest; an eroded lane adds no area to its nodes' normals.
    logical :: eroded(block_size) = .false.
    logical :: newly_eroded(block_size) = .false.        !< eroded by the last call
    real(wp) :: erosion_time_step = 0.0_wp               !< ERODE: a lane whose step falls below erodes (0: off)
    real(wp) :: reference_coordinates(block_size, 4, 3) = 0.0_wp
    !> Points whose plastic strain reached the failure strain: they carry no stress from then on
    !> (as in LS-DYNA) until enough of them have failed for the shell to erode.
    logical :: point_failed(block_size, max_shell_points) = .false.
  end type shell_block_t

contains

  !> Group the model's shells into blocks: parts in model order, shells of a part in its
  !> spatially coherent order (element_ordering: a block is a compact patch of the mesh whatever
  !> the deck's numbering), at most block_size per block; only finite element (not rigid) parts.
  subroutine build_shell_blocks(model, blocks)
    type(model_t), intent(in) :: model
    type(shell_block_t), allocatable, intent(out) :: blocks(:)
    integer, allocatable :: per_part(:), shells_around(:), spatial_order(:)
    integer :: part, shell, block_count, lane, current, part_count, shell_count, corner, k

    shell_count = 0
    if (allocated(model%shell_part)) shell_count = size(model%shell_part)
    ! shells around each node (a triangle's repeated node counted once), for `exposed`
    allocate (shells_around(size(model%coordinates, 2)))
    shells_around = 0
    do shell = 1, shell_count
      do corner = 1, 4
        if (any(model%shell_nodes(1:corner - 1, shell) == model%shell_nodes(corner, shell))) cycle
        shells_around(model%shell_nodes(corner, shell)) = shells_around(model%shell_nodes(corner, shell)) + 1
      end do
    end do
    part_count = size(model%parts)
    allocate (per_part(part_count))
    per_part = 0
    do shell = 1, shell_count
      part = model%shell_part(shell)
      if (model%parts(part)%formulation == formulation_fe) per_part(part) = per_part(part) + 1
    end do
    block_count = sum((per_part + block_size - 1)/block_size)
    allocate (blocks(block_count))
    ! two shared nodes make a common edge
    if (shell_count > 0) spatial_order = spatial_element_order(model%shell_nodes, model%shell_part, &
                                                              model%parts%formulation == formulation_fe, face_nodes=2)
    current = 0
    do part = 1, part_count
      if (per_part(part) == 0) cycle
      lane = block_size
      do k = 1, shell_count
        shell = spatial_order(k)
        if (model%shell_part(shell) /= part) cycle
        if (lane == block_size) then
          if (current > 0) call finish_block(model, blocks(current))
          current = current + 1
          call start_block(model, part, blocks(current))
          lane = 0
        end if
        lane = lane + 1
        blocks(current)%element_count = lane
        blocks(current)%elements(lane) = shell
        blocks(current)%nodes(lane, :) = model%shell_nodes(:, shell)
        blocks(current)%exposed(lane) = count([(shells_around(model%shell_nodes(corner, shell)) == 1 .and. &
                                                .not. any(model%shell_nodes(1:corner - 1, shell) == &
                                                          model%shell_nodes(corner, shell)), corner=1, 4)]) >= 2
        blocks(current)%thickness(lane) = 0.25_wp*sum(model%shell_thickness(:, shell))
        if (model%shell_nodes(3, shell) == model%shell_nodes(4, shell)) then
          blocks(current)%thickness(lane) = sum(model%shell_thickness(1:3, shell))/3.0_wp
          blocks(current)%centre_weight(lane, :) = [1.0_wp, 1.0_wp, 0.5_wp, 0.5_wp]/3.0_wp
        end if
      end do
    end do
    if (current > 0) call finish_block(model, blocks(current))
  end subroutine build_shell_blocks

  !> Part-level settings of a new block.
  subroutine start_block(model, part, block)
    type(model_t), intent(in) :: model
    integer, intent(in) :: part
    type(shell_block_t), intent(inout) :: block
    real(wp) :: points(max_shell_points), weights(max_shell_points)
    integer :: n
    block%part = part
    block%material = model%parts(part)%material
    associate (section => model%sections(model%parts(part)%section))
      n = max(1, min(max_shell_points, section%integration_points))
      block%shear_factor = section%shear_factor
    end associate
    block%point_count = n
    call gauss_legendre_rule(n, points(1:n), weights(1:n))
    block%point_height(1:n) = 0.5_wp*points(1:n)
    block%point_weight(1:n) = 0.5_wp*weights(1:n)
    block%hourglass_type = model%parts(part)%hourglass_type
    if (block%hourglass_type < 1 .or. block%hourglass_type > 5) block%hourglass_type = 1
    block%hourglass_coefficient = model%parts(part)%hourglass_coefficient
  end subroutine start_block

  !> Allocate the state of a filled block; reference areas and frames.
  subroutine finish_block(model, block)
    type(model_t), intent(in) :: model
    type(shell_block_t), intent(inout) :: block
    real(wp) :: x(block_size, 4, 3), xl(block_size, 4), yl(block_size, 4), b1(block_size, 4), b2(block_size, 4)
    integer :: nel, point, count
    nel = block%element_count
    count = max(0, plane_stress_history_count(model%materials(block%material)))
    allocate (block%stress(block_size, 5, block%point_count), source=0.0_wp)
    allocate (block%history(block_size, count, block%point_count), source=0.0_wp)
    do point = 1, block%point_count
      call initialize_plane_stress_history(model%materials(block%material), nel, block%history(:, :, point))
    end do
    block%density(1:nel) = model%materials(block%material)%density
    call gather_nodal(nel, block%nodes, model%coordinates, x)
    block%reference_coordinates = x
    call shell_geometry(nel, x, block%frame, xl, yl, b1, b2, block%reference_area)
    block%area(1:nel) = block%reference_area(1:nel)
  end subroutine finish_block

  !> Lumped corner masses rho t A / 4 (a triangle: A / 3 at its three nodes) and rotary
  !> inertias m (t^2 + A) / 4 (rotary_inertia_factor); lanes beyond element_count zero.
  subroutine shell_block_masses(block, corner_mass, corner_inertia)
    type(shell_block_t), intent(in) :: block
    real(wp), intent(out) :: corner_mass(block_size, 4), corner_inertia(block_size, 4)
    integer :: i, corner
    corner_mass = 0.0_wp
    corner_inertia = 0.0_wp
    do i = 1, block%element_count
      do corner = 1, 4
        corner_mass(i, corner) = block%density(i)*block%thickness(i)*block%reference_area(i)* &
                                 mass_share(block, i, corner)
        corner_inertia(i, corner) = corner_mass(i, corner)*rotary_inertia_factor(block%thickness(i), &
                                                                             block%reference_area(i))
      end do
    end do
  end subroutine shell_block_masses

  !> Share of the element's mass at a corner: 1/4, or 1/3 for the three nodes of a triangle.
  pure real(wp) function mass_share(block, lane, corner)
    type(shell_block_t), intent(in) :: block
    integer, intent(in) :: lane, corner
    if (block%nodes(lane, 3) /= block%nodes(lane, 4)) then
      mass_share = 0.25_wp
    else
      mass_share = merge(0.0_wp, 1.0_wp/3.0_wp, corner == 4)
    end if
  end function mass_share

  !> Stable step of each element at the given configuration (no TSSFAC); lanes beyond
  !> element_count get huge.
  subroutine shell_block_time_steps(block, material, coordinates, element_time_step)
    type(shell_block_t), intent(in) :: block
    type(material_t), intent(in) :: material
    real(wp), intent(in), contiguous :: coordinates(:, :)
    real(wp), intent(out) :: element_time_step(block_size)
    real(wp) :: x(block_size, 4, 3), frame(block_size, 3, 3), area(block_size)
    real(wp) :: xl(block_size, 4), yl(block_size, 4), b1(block_size, 4), b2(block_size, 4)
    element_time_step = huge(1.0_wp)
    call gather_nodal(block%element_count, block%nodes, coordinates, x)
    call shell_geometry(block%element_count, x, frame, xl, yl, b1, b2, area)
    call stable_steps(block, material, x, area, xl, yl, b1, b2, element_time_step)
  end subroutine shell_block_time_steps

  !> One cycle of element work on a block: rates on the mid-step configuration from
  !> x(n+1), v(n+1/2) and w(n+1/2), stress update at every point, resultants, nodal forces
  !> and moments on x(n+1), energies and time step. nodal_force(i, I, 1:3) is the internal
  !> force and nodal_force(i, I, 4:6) the internal moment on corner I of lane i (global axes);
  !> degenerate_element is 0 or the model shell index of the first element whose area is no
  !> longer positive. Allocates nothing.
  subroutine compute_shell_block(block, material, coordinates, velocities, angular_velocities, dt, nodal_force, &
                                 critical_time_step, critical_element, degenerate_element)
    type(shell_block_t), intent(inout) :: block
    type(material_t), intent(in) :: material
    real(wp), intent(in), contiguous :: coordinates(:, :), velocities(:, :), angular_velocities(:, :)
    real(wp), intent(in) :: dt
    real(wp), intent(out) :: nodal_force(block_size, 4, 6)
    real(wp), intent(out) :: critical_time_step
    integer, intent(out) :: critical_element, degenerate_element
    real(wp) :: x(block_size, 4, 3), v(block_size, 4, 3), w(block_size, 4, 3), mid(block_size, 4, 3)
    real(wp) :: frame(block_size, 3, 3), area(block_size)
    real(wp) :: xl(block_size, 4), yl(block_size, 4), b1(block_size, 4), b2(block_size, 4)
    real(wp) :: vl(block_size, 4, 3), wl(block_size, 4, 3)
    real(wp) :: membrane(block_size, 3), curvature(block_size, 3), shear(block_size, 2)
    real(wp) :: increment(block_size, 3), thickness_increment(block_size)
    real(wp) :: resultant(block_size, 8), local_force(block_size, 4, 6), hourglass_local(block_size, 4, 6)
    real(wp) :: hourglass_global(block_size, 4, 6), element_time_step(block_size)
    real(wp) :: old_power(block_size), new_power(block_size), old_hourglass(block_size), new_hourglass(block_size)
    real(wp) :: shear_modulus, height, spin_angle(block_size)
    real(wp) :: held_internal(block_size), held_hourglass(block_size)
    integer :: nel, i, point

    nel = block%element_count
    nodal_force = 0.0_wp
    call gather_nodal(nel, block%nodes, coordinates, x)
    call gather_nodal(nel, block%nodes, velocities, v)
    call gather_nodal(nel, block%nodes, angular_velocities, w)
    block%newly_eroded = .false.
    held_internal = block%internal_energy
    held_hourglass = block%hourglass_energy
    if (any(block%eroded(1:nel))) then
      ! eroded lanes run on their reference geometry at rest (solid_block's hold_eroded_lanes)
      do i = 1, nel
        if (.not. block%eroded(i)) cycle
        x(i, :, :) = block%reference_coordinates(i, :, :)
        v(i, :, :) = 0.0_wp
        w(i, :, :) = 0.0_wp
      end do
    end if
    shear_modulus = 0.0_wp
    if (material%law /= law_null) shear_modulus = material%youngs_modulus/(2.0_wp*(1.0_wp + material%poissons_ratio))

    ! rates on the mid-step configuration x(n+1/2) = x(n+1) - dt/2 v(n+1/2)
    mid(1:nel, :, :) = x(1:nel, :, :) - 0.5_wp*dt*v(1:nel, :, :)
    call shell_geometry(nel, mid, frame, xl, yl, b1, b2, area)
    call to_local(nel, frame, v, vl)
    call to_local(nel, frame, w, wl)
    call shell_rates(nel, b1, b2, block%centre_weight, vl, wl, membrane, curvature, shear)
    call triangle_shear_rates(block, nel, xl, yl, vl, wl, shear)
    ! the frame follows side 1-2; the stress must turn with the material (module comment):
    ! half the material spin from the last frame to the mid-step one, where the increments are
    ! added, the other half from there to the end-of-step frame
    do i = 1, nel
      spin_angle(i) = 0.25_wp*dt*sum(b1(i, :)*vl(i, :, 2) - b2(i, :)*vl(i, :, 1))
    end do
    call rotate_with_material(block, material%law, nel, frame, spin_angle)
    block%frame(1:nel, :, :) = frame(1:nel, :, :)

    ! plane-stress update at every point through the thickness; elastic transverse shear
    do point = 1, block%point_count
      do i = 1, nel
        height = block%point_height(point)*block%thickness(i)
        increment(i, 1) = dt*(membrane(i, 1) + height*curvature(i, 1))
        increment(i, 2) = dt*(membrane(i, 2) + height*curvature(i, 2))
        increment(i, 3) = dt*(membrane(i, 3) + height*curvature(i, 3))
      end do
      call update_plane_stress_block(material, nel, dt, increment, block%stress(:, 1:3, point), &
                                     block%history(:, :, point), thickness_increment)
      do i = 1, nel
        block%stress(i, 4, point) = block%stress(i, 4, point) + block%shear_factor*shear_modulus*dt*shear(i, 2)
        block%stress(i, 5, point) = block%stress(i, 5, point) + block%shear_factor*shear_modulus*dt*shear(i, 1)
      end do
    end do
    ! failed points carry no stress (erode_failed_lanes)
    if (any(block%point_failed(1:nel, 1:block%point_count))) then
      do point = 1, block%point_count
        do i = 1, nel
          if (block%point_failed(i, point)) block%stress(i, :, point) = 0.0_wp
        end do
      end do
    end if

    ! forces and moments on the end-of-step configuration
    call shell_geometry(nel, x, frame, xl, yl, b1, b2, area)
    call rotate_with_material(block, material%law, nel, frame, spin_angle)
    call to_local(nel, frame, v, vl)
    call to_local(nel, frame, w, wl)
    call stress_resultants(block, nel, resultant)
    call resultant_forces(nel, area, b1, b2, block%centre_weight, resultant, local_force)
    call triangle_shear_forces(block, nel, area, xl, yl, b1, b2, resultant, local_force)
    call hourglass_forces(block, material, nel, dt, area, xl, yl, b1, b2, vl, wl, hourglass_local)

    ! global forces, and the work of the last call's and this call's forces
    call to_global(nel, frame, local_force, nodal_force)
    call to_global(nel, frame, hourglass_local, hourglass_global)
    call nodal_power(nel, block%previous_force, v, w, old_power)
    call nodal_power(nel, nodal_force, v, w, new_power)
    call nodal_power(nel, block%previous_hourglass_force, v, w, old_hourglass)
    call nodal_power(nel, hourglass_global, v, w, new_hourglass)
    call add_force_work(nel, dt, block%previous_time_step, old_power, new_power, block%force_power, &
                        block%internal_energy)
    call add_force_work(nel, dt, block%previous_time_step, old_hourglass, new_hourglass, block%hourglass_power, &
                        block%hourglass_energy)
    block%previous_force(1:nel, :, :) = nodal_force(1:nel, :, :)
    block%previous_hourglass_force(1:nel, :, :) = hourglass_global(1:nel, :, :)
    nodal_force(1:nel, :, :) = nodal_force(1:nel, :, :) + hourglass_global(1:nel, :, :)
    block%previous_time_step = dt
    block%frame(1:nel, :, :) = frame(1:nel, :, :)
    block%area(1:nel) = area(1:nel)

    element_time_step = huge(1.0_wp)
    call stable_steps(block, material, x, area, xl, yl, b1, b2, element_time_step)
    call erode_failed_lanes(block, material, nel, dt, xl, yl, held_internal, held_hourglass, element_time_step, &
                            nodal_force)
    call smallest_time_step(nel, element_time_step, block%elements, critical_time_step, critical_element)
    degenerate_element = 0
    do i = 1, nel
      if (block%eroded(i)) cycle
      if (.not. area(i) > 0.0_wp) then
        degenerate_element = block%elements(i)
        exit
      end if
    end do
  end subroutine compute_shell_block

  !> Turn the stored local stresses and generalized hourglass forces from the block's frame
  !> (`block%frame`) to `frame` so that they rotate with the material spin, not with side 1-2;
  !> `spin_angle` is the material's rotation between the two.
  !> Components kept in a frame that turned by phi about the normal have turned with it (the
  !> old e1 lies at -phi in the new frame); the material turned by psi = W_z dt
  !> (W_z = (dv_y/dx - dv_x/dy) / 2, from the mid-step rates), so the components turn by
  !> psi - phi in the new frame. The solver turns by half the step's spin into the mid-step
  !> frame, where the strain increments are added, and by the other half into the end frame
  !> (the mid-point rule, as the Hughes-Winget rotation of the solids). Without this (the classical element)
  !> a uniform membrane state becomes non-uniform wherever the sides of neighbouring elements
  !> rotate at different rates, and the membrane patch test fails at O(strain rate x dt).
  pure subroutine rotate_with_material(block, law, nel, frame, spin_angle)
    type(shell_block_t), intent(inout) :: block
    integer, intent(in) :: law
    integer, intent(in) :: nel
    real(wp), intent(in) :: frame(block_size, 3, 3), spin_angle(block_size)
    real(wp) :: angle, c, s, sxx, syy, sxy, first, second
    integer :: i, point
    do i = 1, nel
      angle = spin_angle(i) + atan2(dot_product(block%frame(i, 1, :), frame(i, 2, :)), &
                                    dot_product(block%frame(i, 1, :), frame(i, 1, :)))
      c = cos(angle)
      s = sin(angle)
      do point = 1, block%point_count
        sxx = block%stress(i, 1, point)
        syy = block%stress(i, 2, point)
        sxy = block%stress(i, 3, point)
        block%stress(i, 1, point) = c*c*sxx - 2.0_wp*c*s*sxy + s*s*syy
        block%stress(i, 2, point) = s*s*sxx + 2.0_wp*c*s*sxy + c*c*syy
        block%stress(i, 3, point) = c*s*(sxx - syy) + (c*c - s*s)*sxy
        ! transverse shear (s_zx, s_yz) turns as a vector
        first = block%stress(i, 5, point)
        second = block%stress(i, 4, point)
        block%stress(i, 5, point) = c*first - s*second
        block%stress(i, 4, point) = s*first + c*second
        ! tensor history (the rubbers' b, the viscoelastic branch) turns with the stress
        if (size(block%history, 2) > 0) call rotate_plane_stress_history(law, c, s, block%history(i, :, point))
      end do
      first = block%hourglass_force(i, 1)
      second = block%hourglass_force(i, 2)
      block%hourglass_force(i, 1) = c*first - s*second
      block%hourglass_force(i, 2) = s*first + c*second
      first = block%hourglass_force(i, 4)
      second = block%hourglass_force(i, 5)
      block%hourglass_force(i, 4) = c*first - s*second
      block%hourglass_force(i, 5) = s*first + c*second
    end do
  end subroutine rotate_with_material

  !> After the kernel, as solid_block's erode_failed_lanes: lanes eroded before give no force,
  !> moment or step and keep their energy; lanes that fail now (enough points at the effective
  !> plastic strain limit, in-plane principal strains of the mid-surface from the current local
  !> corners `xl`, `yl`, ERODE's smallest step) erode at once, without the forces of this call
  !> and the half step of their work.
  subroutine erode_failed_lanes(block, material, nel, dt, xl, yl, held_internal, held_hourglass, &
                                element_time_step, nodal_force)
    type(shell_block_t), intent(inout) :: block
    type(material_t), intent(in) :: material
    integer, intent(in) :: nel
    real(wp), intent(in) :: dt, xl(block_size, 4), yl(block_size, 4)
    real(wp), intent(in) :: held_internal(block_size), held_hourglass(block_size)
    real(wp), intent(inout) :: element_time_step(block_size), nodal_force(block_size, 4, 6)
    real(wp) :: limit, point_strain(block_size), gradient(2, 2), largest, smallest
    real(wp) :: frame(block_size, 3, 3), xl0(block_size, 4), yl0(block_size, 4)
    real(wp) :: b1(block_size, 4), b2(block_size, 4), area(block_size)
    integer :: failed_points(block_size), needed, i, point
    logical :: failed(block_size)

    failed(1:nel) = .false.
    limit = plastic_failure_limit(material)
    if (limit < huge(1.0_wp) .and. size(block%history, 2) > 0) then
      failed_points(1:nel) = 0
      do point = 1, block%point_count
        call plane_stress_plastic_strain(material, nel, block%history(:, :, point), point_strain)
        do i = 1, nel
          if (point_strain(i) >= limit .and. .not. block%eroded(i)) then
            block%point_failed(i, point) = .true.
            block%stress(i, :, point) = 0.0_wp
          end if
          if (block%point_failed(i, point)) failed_points(i) = failed_points(i) + 1
        end do
      end do
      needed = failed_points_needed(material, block%point_count, .true.)
      failed(1:nel) = failed_points(1:nel) >= needed
    end if
    if (principal_strains_active(material)) then
      ! in-plane F of the mid-surface: current local corners against the reference gradients
      call shell_geometry(nel, block%reference_coordinates, frame, xl0, yl0, b1, b2, area)
      do i = 1, nel
        if (block%eroded(i) .or. failed(i)) cycle
        gradient(1, 1) = sum(xl(i, :)*b1(i, :))
        gradient(1, 2) = sum(xl(i, :)*b2(i, :))
        gradient(2, 1) = sum(yl(i, :)*b1(i, :))
        gradient(2, 2) = sum(yl(i, :)*b2(i, :))
        call principal_log_strains_2d(gradient, largest, smallest)
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
      block%hourglass_force(i, :) = 0.0_wp
      block%previous_force(i, :, :) = 0.0_wp
      block%previous_hourglass_force(i, :, :) = 0.0_wp
      block%area(i) = 0.0_wp
      nodal_force(i, :, :) = 0.0_wp
      element_time_step(i) = huge(1.0_wp)
    end do
  end subroutine erode_failed_lanes

  !> Corotational frame, local corner coordinates (origin at node 1), one-point gradients and
  !> area of each lane: e3 along r31 x r42, e1 along r21 projected on the plane.
  pure subroutine shell_geometry(nel, x, frame, xl, yl, b1, b2, area)
    integer, intent(in) :: nel
    real(wp), intent(in) :: x(block_size, 4, 3)
    real(wp), intent(out) :: frame(block_size, 3, 3), xl(block_size, 4), yl(block_size, 4)
    real(wp), intent(out) :: b1(block_size, 4), b2(block_size, 4), area(block_size)
    real(wp) :: r31(3), r42(3), r21(3), normal(3), first(3), length, twice_area
    integer :: i, corner
    do i = 1, nel
      r31 = x(i, 3, :) - x(i, 1, :)
      r42 = x(i, 4, :) - x(i, 2, :)
      r21 = x(i, 2, :) - x(i, 1, :)
      normal = [r31(2)*r42(3) - r31(3)*r42(2), r31(3)*r42(1) - r31(1)*r42(3), r31(1)*r42(2) - r31(2)*r42(1)]
      length = norm2(normal)
      normal = normal/max(length, tiny(1.0_wp))
      first = r21 - dot_product(r21, normal)*normal
      first = first/max(norm2(first), tiny(1.0_wp))
      frame(i, 3, :) = normal
      frame(i, 1, :) = first
      frame(i, 2, :) = [normal(2)*first(3) - normal(3)*first(2), normal(3)*first(1) - normal(1)*first(3), &
                        normal(1)*first(2) - normal(2)*first(1)]
      do corner = 1, 4
        xl(i, corner) = dot_product(frame(i, 1, :), x(i, corner, :) - x(i, 1, :))
        yl(i, corner) = dot_product(frame(i, 2, :), x(i, corner, :) - x(i, 1, :))
      end do
      twice_area = (xl(i, 3) - xl(i, 1))*(yl(i, 4) - yl(i, 2)) - (xl(i, 4) - xl(i, 2))*(yl(i, 3) - yl(i, 1))
      area(i) = 0.5_wp*twice_area
      twice_area = sign(max(abs(twice_area), tiny(1.0_wp)), twice_area)
      b1(i, :) = [yl(i, 2) - yl(i, 4), yl(i, 3) - yl(i, 1), yl(i, 4) - yl(i, 2), yl(i, 1) - yl(i, 3)]/twice_area
      b2(i, :) = [xl(i, 4) - xl(i, 2), xl(i, 1) - xl(i, 3), xl(i, 2) - xl(i, 4), xl(i, 3) - xl(i, 1)]/twice_area
    end do
  end subroutine shell_geometry

  !> Membrane (d_x, d_y, 2 d_xy), curvature (k_x, k_y, 2 k_xy) and transverse shear
  !> (2 d_xz, 2 d_yz) rates from the local velocities and angular velocities.
  pure subroutine shell_rates(nel, b1, b2, centre_weight, vl, wl, membrane, curvature, shear)
    integer, intent(in) :: nel
    real(wp), intent(in) :: b1(block_size, 4), b2(block_size, 4), centre_weight(block_size, 4)
    real(wp), intent(in) :: vl(block_size, 4, 3), wl(block_size, 4, 3)
    real(wp), intent(out) :: membrane(block_size, 3), curvature(block_size, 3), shear(block_size, 2)
    integer :: i, corner
    membrane(1:nel, :) = 0.0_wp
    curvature(1:nel, :) = 0.0_wp
    shear(1:nel, :) = 0.0_wp
    do corner = 1, 4
      do i = 1, nel
        membrane(i, 1) = membrane(i, 1) + b1(i, corner)*vl(i, corner, 1)
        membrane(i, 2) = membrane(i, 2) + b2(i, corner)*vl(i, corner, 2)
        membrane(i, 3) = membrane(i, 3) + b2(i, corner)*vl(i, corner, 1) + b1(i, corner)*vl(i, corner, 2)
        curvature(i, 1) = curvature(i, 1) + b1(i, corner)*wl(i, corner, 2)
        curvature(i, 2) = curvature(i, 2) - b2(i, corner)*wl(i, corner, 1)
        curvature(i, 3) = curvature(i, 3) + b2(i, corner)*wl(i, corner, 2) - b1(i, corner)*wl(i, corner, 1)
        shear(i, 1) = shear(i, 1) + b1(i, corner)*vl(i, corner, 3) + centre_weight(i, corner)*wl(i, corner, 2)
        shear(i, 2) = shear(i, 2) + b2(i, corner)*vl(i, corner, 3) - centre_weight(i, corner)*wl(i, corner, 1)
      end do
    end do
  end subroutine shell_rates

  !> The transverse shear rates of the triangle lanes (N4 = N3), from their edges
  !> (shell_triangle); the quadrilaterals keep those of shell_rates.
  pure subroutine triangle_shear_rates(block, nel, xl, yl, vl, wl, shear)
    type(shell_block_t), intent(in) :: block
    integer, intent(in) :: nel
    real(wp), intent(in) :: xl(block_size, 4), yl(block_size, 4), vl(block_size, 4, 3), wl(block_size, 4, 3)
    real(wp), intent(inout) :: shear(block_size, 2)
    real(wp) :: vz_weight(3, 2), wx_weight(3, 2), wy_weight(3, 2)
    integer :: i, corner
    do i = 1, nel
      if (block%nodes(i, 3) /= block%nodes(i, 4)) cycle
      call triangle_shear_operator(xl(i, 1:3), yl(i, 1:3), vz_weight, wx_weight, wy_weight)
      shear(i, :) = 0.0_wp
      do corner = 1, 3
        shear(i, :) = shear(i, :) + vz_weight(corner, :)*vl(i, corner, 3) + wx_weight(corner, :)*wl(i, corner, 1) &
                      + wy_weight(corner, :)*wl(i, corner, 2)
      end do
    end do
  end subroutine triangle_shear_rates

  !> The local forces and moments of the triangle lanes with their edge-based shear: the
  !> transposes of triangle_shear_rates for the transverse force and of the curvature rates and
  !> the shear for the moments (what resultant_forces gives the quadrilaterals).
  pure subroutine triangle_shear_forces(block, nel, area, xl, yl, b1, b2, resultant, local_force)
    type(shell_block_t), intent(in) :: block
    integer, intent(in) :: nel
    real(wp), intent(in) :: area(block_size), xl(block_size, 4), yl(block_size, 4)
    real(wp), intent(in) :: b1(block_size, 4), b2(block_size, 4), resultant(block_size, 8)
    real(wp), intent(inout) :: local_force(block_size, 4, 6)
    real(wp) :: vz_weight(3, 2), wx_weight(3, 2), wy_weight(3, 2)
    integer :: i, corner
    do i = 1, nel
      if (block%nodes(i, 3) /= block%nodes(i, 4)) cycle
      call triangle_shear_operator(xl(i, 1:3), yl(i, 1:3), vz_weight, wx_weight, wy_weight)
      do corner = 1, 3
        local_force(i, corner, 3) = area(i)*(vz_weight(corner, 1)*resultant(i, 7) + vz_weight(corner, 2)*resultant(i, 8))
        local_force(i, corner, 4) = area(i)*(-b2(i, corner)*resultant(i, 5) - b1(i, corner)*resultant(i, 6) &
                                             + wx_weight(corner, 1)*resultant(i, 7) + wx_weight(corner, 2)*resultant(i, 8))
        local_force(i, corner, 5) = area(i)*(b1(i, corner)*resultant(i, 4) + b2(i, corner)*resultant(i, 6) &
                                             + wy_weight(corner, 1)*resultant(i, 7) + wy_weight(corner, 2)*resultant(i, 8))
      end do
      ! corner 4 is node 3 again: its bending moments stay (its gradients complete the
      ! triangle's), the shear went to corners 1-3
      local_force(i, 4, 3) = 0.0_wp
      local_force(i, 4, 4) = area(i)*(-b2(i, 4)*resultant(i, 5) - b1(i, 4)*resultant(i, 6))
      local_force(i, 4, 5) = area(i)*(b1(i, 4)*resultant(i, 4) + b2(i, 4)*resultant(i, 6))
    end do
  end subroutine triangle_shear_forces

  !> Resultants per unit length: N_x, N_y, N_xy, M_x, M_y, M_xy, Q_x (zx), Q_y (yz).
  pure subroutine stress_resultants(block, nel, resultant)
    type(shell_block_t), intent(in) :: block
    integer, intent(in) :: nel
    real(wp), intent(out) :: resultant(block_size, 8)
    real(wp) :: weight, moment_arm
    integer :: i, point
    resultant(1:nel, :) = 0.0_wp
    do point = 1, block%point_count
      do i = 1, nel
        weight = block%point_weight(point)*block%thickness(i)
        moment_arm = block%point_height(point)*block%thickness(i)
        resultant(i, 1:3) = resultant(i, 1:3) + weight*block%stress(i, 1:3, point)
        resultant(i, 4:6) = resultant(i, 4:6) + weight*moment_arm*block%stress(i, 1:3, point)
        resultant(i, 7) = resultant(i, 7) + weight*block%stress(i, 5, point)
        resultant(i, 8) = resultant(i, 8) + weight*block%stress(i, 4, point)
      end do
    end do
  end subroutine stress_resultants

  !> Local nodal forces and moments whose power equals A (N . d + M . k + Q . shear rates).
  pure subroutine resultant_forces(nel, area, b1, b2, centre_weight, resultant, local_force)
    integer, intent(in) :: nel
    real(wp), intent(in) :: area(block_size), b1(block_size, 4), b2(block_size, 4), centre_weight(block_size, 4)
    real(wp), intent(in) :: resultant(block_size, 8)
    real(wp), intent(out) :: local_force(block_size, 4, 6)
    integer :: i, corner
    do corner = 1, 4
      do i = 1, nel
        local_force(i, corner, 1) = area(i)*(b1(i, corner)*resultant(i, 1) + b2(i, corner)*resultant(i, 3))
        local_force(i, corner, 2) = area(i)*(b2(i, corner)*resultant(i, 2) + b1(i, corner)*resultant(i, 3))
        local_force(i, corner, 3) = area(i)*(b1(i, corner)*resultant(i, 7) + b2(i, corner)*resultant(i, 8))
        local_force(i, corner, 4) = area(i)*(-b2(i, corner)*resultant(i, 5) - b1(i, corner)*resultant(i, 6) &
                                             - centre_weight(i, corner)*resultant(i, 8))
        local_force(i, corner, 5) = area(i)*(b1(i, corner)*resultant(i, 4) + b2(i, corner)*resultant(i, 6) &
                                             + centre_weight(i, corner)*resultant(i, 7))
        local_force(i, corner, 6) = 0.0_wp
      end do
    end do
  end subroutine resultant_forces

  !> Hourglass forces of the five modes (module comment), local axes; updates the block's
  !> generalized hourglass forces.
  pure subroutine hourglass_forces(block, material, nel, dt, area, xl, yl, b1, b2, vl, wl, hourglass_local)
    type(shell_block_t), intent(inout) :: block
    type(material_t), intent(in) :: material
    integer, intent(in) :: nel
    real(wp), intent(in) :: dt, area(block_size), xl(block_size, 4), yl(block_size, 4)
    real(wp), intent(in) :: b1(block_size, 4), b2(block_size, 4), vl(block_size, 4, 3), wl(block_size, 4, 3)
    real(wp), intent(out) :: hourglass_local(block_size, 4, 6)
    real(wp), parameter :: h(4) = [1.0_wp, -1.0_wp, 1.0_wp, -1.0_wp]
    real(wp) :: gamma(4), rate(5), stiffness(5), mass(5), hx, hy, norm_squared, t, youngs, shear_modulus
    integer :: i, corner
    youngs = material%youngs_modulus
    shear_modulus = youngs/(2.0_wp*(1.0_wp + material%poissons_ratio))
    hourglass_local(1:nel, :, :) = 0.0_wp
    do i = 1, nel
      hx = dot_product(h, xl(i, :))
      hy = dot_product(h, yl(i, :))
      gamma = h - hx*b1(i, :) - hy*b2(i, :)
      ! a triangle has no hourglass modes (its three nodes' motions are all linear); gamma is
      ! zero there up to round-off, which must not give forces or energy
      if (block%nodes(i, 3) == block%nodes(i, 4)) gamma = 0.0_wp
      rate(1) = dot_product(gamma, vl(i, :, 1))
      rate(2) = dot_product(gamma, vl(i, :, 2))
      rate(3) = dot_product(gamma, vl(i, :, 3))
      rate(4) = dot_product(gamma, wl(i, :, 1))
      rate(5) = dot_product(gamma, wl(i, :, 2))
      t = block%thickness(i)
      norm_squared = sum(b1(i, :)**2 + b2(i, :)**2)
      stiffness(1:2) = youngs*t*area(i)*norm_squared/8.0_wp
      stiffness(3) = block%shear_factor*shear_modulus*t**3*norm_squared/6.0_wp
      stiffness(4:5) = youngs*t**3*area(i)*norm_squared/192.0_wp
      if (block%hourglass_type >= 4) then
        ! the stiffness forms act on the mode amplitudes of Belytschko & Tsay's normalisation
        ! gamma / 4 (so forces are gamma/4 times QM k (gamma/4 . v) dt: k / 16 here)
        block%hourglass_force(i, :) = block%hourglass_force(i, :) &
                                      + block%hourglass_coefficient*dt*stiffness*rate/16.0_wp
      else if (dt > 0.0_wp) then
        mass(1:3) = 0.25_wp*block%density(i)*t*block%reference_area(i)
        mass(4:5) = mass(1)*rotary_inertia_factor(t, block%reference_area(i))
        block%hourglass_force(i, :) = block%hourglass_coefficient*sqrt(stiffness*mass)*rate
      else
        block%hourglass_force(i, :) = 0.0_wp ! no step: no viscous forces (as in solid_block)
      end if
      do corner = 1, 4
        hourglass_local(i, corner, 1) = gamma(corner)*block%hourglass_force(i, 1)
        hourglass_local(i, corner, 2) = gamma(corner)*block%hourglass_force(i, 2)
        hourglass_local(i, corner, 3) = gamma(corner)*block%hourglass_force(i, 3)
        hourglass_local(i, corner, 4) = gamma(corner)*block%hourglass_force(i, 4)
        hourglass_local(i, corner, 5) = gamma(corner)*block%hourglass_force(i, 5)
      end do
    end do
  end subroutine hourglass_forces

  !> Stable step per lane: the smaller of the membrane step L / c (L = area / longest side,
  !> c^2 = E / (rho (1 - nu^2)), LS-DYNA's default) and 2 / omega_r with omega_r^2 a bound on
  !> the highest frequency of the element's out-of-plane motion (transverse shear, bending and
  !> out-of-plane hourglass stiffness against the lumped masses and rotary inertias; see
  !> out_of_plane_frequency_squared). With the rotary inertia of shell_block_masses the second
  !> stays above the first for SHRF <= 1 and any Poisson ratio; it guards larger SHRF and thick
  !> or distorted elements. The exposed lanes (a lone shell, a pair, a single row's ends) also
  !> take membrane_time_step. A null material without YM sets no step.
  pure subroutine stable_steps(block, material, x, area, xl, yl, b1, b2, element_time_step)
    type(shell_block_t), intent(in) :: block
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: x(block_size, 4, 3), area(block_size), xl(block_size, 4), yl(block_size, 4)
    real(wp), intent(in) :: b1(block_size, 4), b2(block_size, 4)
    real(wp), intent(inout) :: element_time_step(block_size)
    real(wp) :: longest, wave_speed, out_of_plane
    integer :: i, corner
    if (material%youngs_modulus <= 0.0_wp) return
    do i = 1, block%element_count
      longest = 0.0_wp
      do corner = 1, 4
        longest = max(longest, norm2(x(i, modulo(corner, 4) + 1, :) - x(i, corner, :)))
      end do
      wave_speed = sqrt(material%youngs_modulus/(block%density(i)*(1.0_wp - material%poissons_ratio**2)))
      element_time_step(i) = characteristic_factor(block, i)*max(area(i), 0.0_wp)/max(longest, tiny(1.0_wp))/wave_speed
      out_of_plane = out_of_plane_frequency_squared(block, material, i, area(i), xl(i, :), yl(i, :), b1(i, :), &
                                                    b2(i, :))
      if (out_of_plane > 0.0_wp) element_time_step(i) = min(element_time_step(i), 2.0_wp/sqrt(out_of_plane))
      if (block%exposed(i)) element_time_step(i) = min(element_time_step(i), &
                                                       membrane_time_step(block, material, i, area(i), xl(i, :), &
                                                                          yl(i, :), b1(i, :), b2(i, :)))
    end do
  end subroutine stable_steps

  !> LS-DYNA's characteristic length of a shell is (1 + beta) A / longest side, beta = 0 for a
  !> quadrilateral and 1 for a triangle (its smallest altitude, 2 A / longest side).
  pure real(wp) function characteristic_factor(block, i)
    type(shell_block_t), intent(in) :: block
    integer, intent(in) :: i
    characteristic_factor = merge(2.0_wp, 1.0_wp, block%nodes(i, 3) == block%nodes(i, 4))
  end function characteristic_factor

  !> Stable step of lane i's in-plane motion alone (for the exposed lanes): the membrane rule
  !> L / c is the critical step of a mesh, but a free shell's areal mode (u = x, v = y) has
  !> omega^2 = (1 + nu) (2 c / L)^2 on a square, so a lone shell needs TSSFAC below
  !> 1 / sqrt(1 + nu) (docs/shells.md). As for the solids and the bending part of
  !> out_of_plane_frequency_squared, the one-point membrane stiffness t A B^T C B has against
  !> the lumped masses omega^2 <= t A (lambda' tr S + 2 G lambda_max(S)), S_ab = sum B_a B_b / m
  !> (exact for a square: the areal mode); the membrane hourglass modes add (QM k / 16) |gamma|^2
  !> / m for IHQ 4, 5 (the largest eigenvalue of a sum is at most the sum of the largest), or a
  !> damping QM sqrt(k m) |gamma|^2 / m for IHQ 1-3 (the viscous forces of hourglass_forces),
  !> k = E t A sum B^2 / 8. Stable while dt^2 omega^2 + 2 dt beta <= 4:
  !> dt = 4 / (beta + sqrt(beta^2 + 4 omega^2)).
  pure real(wp) function membrane_time_step(block, material, i, area, xl, yl, b1, b2) result(step)
    type(shell_block_t), intent(in) :: block
    type(material_t), intent(in) :: material
    integer, intent(in) :: i
    real(wp), intent(in) :: area
    ! (assumed shape: the callers pass a lane's row of the block arrays without copying it)
    real(wp), intent(in) :: xl(:), yl(:), b1(:), b2(:)
    real(wp), parameter :: h(4) = [1.0_wp, -1.0_wp, 1.0_wp, -1.0_wp]
    real(wp) :: g1(4), g2(4), gamma(4), mass(4), s11, s22, s12, t, youngs, nu, shear_modulus, plane_lambda
    real(wp) :: stiffness, omega2, damping, gamma_mass
    integer :: corners
    t = block%thickness(i)
    youngs = material%youngs_modulus
    nu = material%poissons_ratio
    shear_modulus = youngs/(2.0_wp*(1.0_wp + nu))
    plane_lambda = youngs*nu/(1.0_wp - nu*nu)
    gamma = h - dot_product(h, xl)*b1 - dot_product(h, yl)*b2
    g1 = b1
    g2 = b2
    corners = 4
    if (block%nodes(i, 3) == block%nodes(i, 4)) then
      corners = 3
      g1(3) = g1(3) + g1(4)
      g2(3) = g2(3) + g2(4)
      gamma(3) = gamma(3) + gamma(4)
    end if
    mass(1:corners) = block%density(i)*t*block%reference_area(i)/real(corners, wp)
    s11 = sum(g1(1:corners)**2/mass(1:corners))
    s22 = sum(g2(1:corners)**2/mass(1:corners))
    s12 = sum(g1(1:corners)*g2(1:corners)/mass(1:corners))
    omega2 = t*max(area, 0.0_wp)*(plane_lambda*(s11 + s22) &
                                  + 2.0_wp*shear_modulus*(0.5_wp*(s11 + s22) + sqrt(0.25_wp*(s11 - s22)**2 + s12**2)))
    ! the membrane hourglass stiffness of hourglass_forces
    stiffness = youngs*t*max(area, 0.0_wp)*sum(b1**2 + b2**2)/8.0_wp
    gamma_mass = sum(gamma(1:corners)**2/mass(1:corners))
    damping = 0.0_wp
    if (block%hourglass_type >= 4) then
      omega2 = omega2 + block%hourglass_coefficient*stiffness/16.0_wp*gamma_mass
    else
      damping = block%hourglass_coefficient*sqrt(stiffness*0.25_wp*block%density(i)*t*block%reference_area(i)) &
                *gamma_mass
    end if
    ! (a shell without stiffness gets huge, not an overflow)
    step = 4.0_wp/max(damping + sqrt(damping**2 + 4.0_wp*omega2), 4.0_wp/huge(1.0_wp))
  end function membrane_time_step

  !> Upper bound on omega^2 of lane i's out-of-plane motion (w, theta_x, theta_y) against its
  !> lumped masses m_I and rotary inertias I_I (element eigenvalues bound the mesh's). Three
  !> parts are added (the largest eigenvalue of a sum is at most the sum of the largest):
  !> - transverse shear SHRF G t A (g_x g_x^T + g_y g_y^T), g_x = (B1 on w, N on theta_y),
  !>   g_y = (B2 on w, -N on theta_x): the largest eigenvalue of its 2 x 2 form against the masses,
  !>   SHRF G t A [(s11 + s22)/2 + sqrt((s11 - s22)^2/4 + s12^2)] + SHRF G t A sum N^2/I,
  !>   s_ab = sum B_a B_b / m;
  !> - bending, the membrane operator with t^3/12 acting on the rotations: as for any one-point
  !>   element with lumped masses, omega^2 <= (t^3 A / 12) (lambda' tr H + 2 G lambda_max(H)),
  !>   H_ab = sum B_a B_b / I, lambda' = E nu / (1 - nu^2) (plane stress);
  !> - the out-of-plane and bending hourglass stiffnesses of IHQ 4, 5 (QM k / 16) |gamma|^2 / m.
  !> A triangle (nodes 3 and 4 the same) has its corners 3 and 4 taken as one node.
  pure real(wp) function out_of_plane_frequency_squared(block, material, i, area, xl, yl, b1, b2) result(omega2)
    type(shell_block_t), intent(in) :: block
    type(material_t), intent(in) :: material
    integer, intent(in) :: i
    real(wp), intent(in) :: area
    ! (assumed shape: the callers pass a lane's row of the block arrays without copying it)
    real(wp), intent(in) :: xl(:), yl(:), b1(:), b2(:)
    real(wp), parameter :: h(4) = [1.0_wp, -1.0_wp, 1.0_wp, -1.0_wp]
    real(wp) :: g1(4), g2(4), n(4), gamma(4), mass(4), inertia(4)
    real(wp) :: t, youngs, nu, shear_modulus, plane_lambda, norm_squared
    real(wp) :: s11, s22, s12, rotation, h11, h22, h12, gamma_mass, gamma_inertia, hourglass
    real(wp) :: vz_weight(3, 2), wx_weight(3, 2), wy_weight(3, 2)
    integer :: corners
    t = block%thickness(i)
    youngs = material%youngs_modulus
    nu = material%poissons_ratio
    shear_modulus = youngs/(2.0_wp*(1.0_wp + nu))
    plane_lambda = youngs*nu/(1.0_wp - nu*nu)
    gamma = h - dot_product(h, xl)*b1 - dot_product(h, yl)*b2
    norm_squared = sum(b1**2 + b2**2)
    g1 = b1
    g2 = b2
    n = block%centre_weight(i, :)
    corners = 4
    if (block%nodes(i, 3) == block%nodes(i, 4)) then
      corners = 3
      g1(3) = g1(3) + g1(4)
      g2(3) = g2(3) + g2(4)
      n(3) = n(3) + n(4)
      gamma(3) = gamma(3) + gamma(4)
    end if
    mass(1:corners) = block%density(i)*t*block%reference_area(i)/real(corners, wp)
    inertia(1:corners) = mass(1:corners)*rotary_inertia_factor(t, block%reference_area(i))
    s11 = sum(g1(1:corners)**2/mass(1:corners))
    s22 = sum(g2(1:corners)**2/mass(1:corners))
    s12 = sum(g1(1:corners)*g2(1:corners)/mass(1:corners))
    rotation = sum(n(1:corners)**2/inertia(1:corners))
    if (corners == 3) then
      ! the triangle's edge-based shear (shell_triangle): the 2 x 2 form S M^-1 S^T
      call triangle_shear_operator(xl(1:3), yl(1:3), vz_weight, wx_weight, wy_weight)
      s11 = sum(vz_weight(:, 1)**2/mass(1:3) + (wx_weight(:, 1)**2 + wy_weight(:, 1)**2)/inertia(1:3))
      s22 = sum(vz_weight(:, 2)**2/mass(1:3) + (wx_weight(:, 2)**2 + wy_weight(:, 2)**2)/inertia(1:3))
      s12 = sum(vz_weight(:, 1)*vz_weight(:, 2)/mass(1:3) &
                + (wx_weight(:, 1)*wx_weight(:, 2) + wy_weight(:, 1)*wy_weight(:, 2))/inertia(1:3))
      rotation = 0.0_wp
    end if
    omega2 = block%shear_factor*shear_modulus*t*max(area, 0.0_wp) &
             *(0.5_wp*(s11 + s22) + sqrt(0.25_wp*(s11 - s22)**2 + s12**2) + rotation)
    h11 = sum(g1(1:corners)**2/inertia(1:corners))
    h22 = sum(g2(1:corners)**2/inertia(1:corners))
    h12 = sum(g1(1:corners)*g2(1:corners)/inertia(1:corners))
    omega2 = omega2 + t**3*max(area, 0.0_wp)/12.0_wp*(plane_lambda*(h11 + h22) &
             + 2.0_wp*shear_modulus*(0.5_wp*(h11 + h22) + sqrt(0.25_wp*(h11 - h22)**2 + h12**2)))
    if (block%hourglass_type >= 4) then
      gamma_mass = sum(gamma(1:corners)**2/mass(1:corners))
      gamma_inertia = sum(gamma(1:corners)**2/inertia(1:corners))
      ! the stiffnesses of hourglass_forces, times QM / 16
      hourglass = block%shear_factor*shear_modulus*t**3*norm_squared/6.0_wp*gamma_mass &
                  + youngs*t**3*max(area, 0.0_wp)*norm_squared/192.0_wp*gamma_inertia
      omega2 = omega2 + block%hourglass_coefficient*hourglass/16.0_wp
    end if
  end function out_of_plane_frequency_squared

  !> Rotary inertia of a shell node per unit of its mass: (t^2 + A) / 4. The physical value
  !> t^2 / 12 would let the transverse shear of a thin shell (the node's rotation against the
  !> element's deflection) vibrate (L / t) times faster than the membrane sets the step. The
  !> shear mode of one element has omega^2 <= SHRF G / rho (4 / L^2 + 1 / factor) (rectangle,
  !> L the shorter side); factor >= L^2 / 4 keeps it at or below the membrane's (2 c / L)^2 =
  !> 4 E / (rho (1 - nu^2) L^2) for SHRF <= 1 and every 0 <= nu < 0.5 (equal at SHRF 1, nu 0).
  !> (A / 12, used before, let a strip with SHRF 5/6 explode at nu <= 0.1: docs/shells.md.)
  pure real(wp) function rotary_inertia_factor(thickness, area)
    real(wp), intent(in) :: thickness, area
    rotary_inertia_factor = (thickness**2 + area)/4.0_wp
  end function rotary_inertia_factor

  !> values(i, I, k) = nodal(k, nodes(i, I)).
  pure subroutine gather_nodal(nel, nodes, nodal, values)
    integer, intent(in) :: nel, nodes(block_size, 4)
    real(wp), intent(in) :: nodal(:, :)
    real(wp), intent(out) :: values(block_size, 4, 3)
    integer :: i, corner, k
    do k = 1, 3
      do corner = 1, 4
        do i = 1, nel
          values(i, corner, k) = nodal(k, nodes(i, corner))
        end do
      end do
    end do
  end subroutine gather_nodal

  !> Local components of nodal vectors.
  pure subroutine to_local(nel, frame, global, local)
    integer, intent(in) :: nel
    real(wp), intent(in) :: frame(block_size, 3, 3), global(block_size, 4, 3)
    real(wp), intent(out) :: local(block_size, 4, 3)
    integer :: i, corner, axis
    do axis = 1, 3
      do corner = 1, 4
        do i = 1, nel
          local(i, corner, axis) = frame(i, axis, 1)*global(i, corner, 1) + frame(i, axis, 2)*global(i, corner, 2) &
                                   + frame(i, axis, 3)*global(i, corner, 3)
        end do
      end do
    end do
  end subroutine to_local

  !> Global components of local nodal forces (1-3) and moments (4-6).
  pure subroutine to_global(nel, frame, local, global)
    integer, intent(in) :: nel
    real(wp), intent(in) :: frame(block_size, 3, 3), local(block_size, 4, 6)
    real(wp), intent(out) :: global(block_size, 4, 6)
    integer :: i, corner, k
    do k = 1, 3
      do corner = 1, 4
        do i = 1, nel
          global(i, corner, k) = frame(i, 1, k)*local(i, corner, 1) + frame(i, 2, k)*local(i, corner, 2) &
                                 + frame(i, 3, k)*local(i, corner, 3)
          global(i, corner, k + 3) = frame(i, 1, k)*local(i, corner, 4) + frame(i, 2, k)*local(i, corner, 5) &
                                     + frame(i, 3, k)*local(i, corner, 6)
        end do
      end do
    end do
  end subroutine to_global

  !> Power of nodal forces and moments against the velocities and angular velocities.
  pure subroutine nodal_power(nel, force, v, w, power)
    integer, intent(in) :: nel
    real(wp), intent(in) :: force(block_size, 4, 6), v(block_size, 4, 3), w(block_size, 4, 3)
    real(wp), intent(out) :: power(block_size)
    integer :: i, corner, k
    power = 0.0_wp
    do k = 1, 3
      do corner = 1, 4
        do i = 1, nel
          power(i) = power(i) + force(i, corner, k)*v(i, corner, k) + force(i, corner, k + 3)*w(i, corner, k)
        end do
      end do
    end do
  end subroutine nodal_power

  !> Per element (columns elements(i) of the outputs): the mid-surface stress (weighted mean
  !> over the points) and the stress of the point with the largest von Mises stress, both in
  !> global axes (xx, yy, zz, xy, yz, zx), and the mean and largest effective plastic strain.
  subroutine shell_block_element_results(block, material, mid_stress, peak_stress, mean_plastic_strain, &
                                         peak_plastic_strain, point_stress, point_plastic_strain, point_count, &
                                         resultant, thickness, energy_density)
    type(shell_block_t), intent(in) :: block
    type(material_t), intent(in) :: material
    real(wp), intent(inout) :: mid_stress(:, :), peak_stress(:, :), mean_plastic_strain(:), peak_plastic_strain(:)
    !> (the d3plot's) global stress (6, points, shells) and plastic strain (points, shells) at
    !> each point, bottom to top, and the points written (shells)
    real(wp), intent(inout), optional :: point_stress(:, :, :), point_plastic_strain(:, :)
    integer, intent(inout), optional :: point_count(:)
    !> (with the points) (8, shells) resultants per unit width in the local frame: M_xx M_yy
    !> M_xy Q_x Q_y N_xx N_yy N_xy; the thickness; the internal energy per unit volume
    real(wp), intent(inout), optional :: resultant(:, :), thickness(:), energy_density(:)
    real(wp) :: point_strain(block_size), mean_local(5), effective, largest, through(5), moment(3)
    integer :: nel, i, point, peak, written
    nel = block%element_count
    ! Gauss points are numbered from the bottom (height -1/2) to the top, as LS-DYNA's layers
    written = 0
    if (present(point_stress)) written = min(block%point_count, size(point_stress, 2))
    do i = 1, nel
      if (written == 0) exit
      point_count(block%elements(i)) = written
      do point = 1, written
        point_stress(:, point, block%elements(i)) = global_stress(block%frame(i, :, :), block%stress(i, :, point))
      end do
      point_plastic_strain(:, block%elements(i)) = 0.0_wp
      ! resultants per unit width: N = t sum w s, M = t^2 sum w h s (h = z / t), Q = t sum w s_xz
      through = 0.0_wp
      moment = 0.0_wp
      do point = 1, block%point_count
        through = through + block%point_weight(point)*block%stress(i, :, point)
        moment = moment + block%point_weight(point)*block%point_height(point)*block%stress(i, 1:3, point)
      end do
      resultant(1:3, block%elements(i)) = block%thickness(i)**2*moment
      resultant(4, block%elements(i)) = block%thickness(i)*through(5)
      resultant(5, block%elements(i)) = block%thickness(i)*through(4)
      resultant(6:8, block%elements(i)) = block%thickness(i)*through(1:3)
      thickness(block%elements(i)) = block%thickness(i)
      ! (0 for a volume so small that the quotient would overflow: a collapsed element)
      ! (and 0 when either is not finite: a run that blew up, whose comparisons must not trap)
      energy_density(block%elements(i)) = 0.0_wp
      associate (volume => block%area(i)*block%thickness(i))
        if (ieee_is_finite(volume) .and. ieee_is_finite(block%internal_energy(i))) then
          ! (two tests, not one .or.: huge x volume would overflow for a volume above 1)
          if (volume >= 1.0_wp) then
            energy_density(block%elements(i)) = block%internal_energy(i)/volume
          else if (abs(block%internal_energy(i)) < huge(1.0_wp)*volume) then
            energy_density(block%elements(i)) = block%internal_energy(i)/volume
          end if
        end if
      end associate
    end do
    do i = 1, nel
      mean_local = 0.0_wp
      largest = -1.0_wp
      peak = 1
      do point = 1, block%point_count
        mean_local = mean_local + block%point_weight(point)*block%stress(i, :, point)
        associate (s => block%stress(i, :, point))
          effective = s(1)**2 - s(1)*s(2) + s(2)**2 + 3.0_wp*(s(3)**2 + s(4)**2 + s(5)**2)
        end associate
        if (effective > largest) then
          largest = effective
          peak = point
        end if
      end do
      mid_stress(:, block%elements(i)) = global_stress(block%frame(i, :, :), mean_local)
      peak_stress(:, block%elements(i)) = global_stress(block%frame(i, :, :), block%stress(i, :, peak))
    end do
    do i = 1, nel
      mean_plastic_strain(block%elements(i)) = 0.0_wp
      peak_plastic_strain(block%elements(i)) = 0.0_wp
    end do
    if (size(block%history, 2) == 0) return
    do point = 1, block%point_count
      call plane_stress_plastic_strain(material, nel, block%history(:, :, point), point_strain)
      do i = 1, nel
        mean_plastic_strain(block%elements(i)) = mean_plastic_strain(block%elements(i)) &
                                                 + block%point_weight(point)*point_strain(i)
        peak_plastic_strain(block%elements(i)) = max(peak_plastic_strain(block%elements(i)), point_strain(i))
      end do
      if (point > written) cycle
      do i = 1, nel
        point_plastic_strain(point, block%elements(i)) = point_strain(i)
      end do
    end do
  end subroutine shell_block_element_results

  !> Global components (xx, yy, zz, xy, yz, zx) of a local shell stress (xx, yy, xy, yz, zx;
  !> zz = 0): sigma = E^T s E with the rows of E the frame vectors.
  pure function global_stress(frame, local) result(stress)
    real(wp), intent(in) :: frame(:, :), local(:)   ! (3, 3), (5): assumed shape, passed without a copy
    real(wp) :: stress(6), s(3, 3), g(3, 3)
    s = reshape([local(1), local(3), local(5), local(3), local(2), local(4), local(5), local(4), 0.0_wp], [3, 3])
    g = matmul(transpose(frame), matmul(s, frame))
    stress = [g(1, 1), g(2, 2), g(3, 3), g(1, 2), g(2, 3), g(3, 1)]
  end function global_stress
end module shell_block
