!> Blocks of beam elements (*SECTION_BEAM ELFORM 1 Hughes-Liu, 2 resultant beam, 9 spot weld beam) and
!> the per-cycle element work on them.
!>
!> The element (Hughes & Liu 1981, part I, specialised to a beam as in LS-DYNA's Theory Manual,
!> "Hughes-Liu beam") is a two-node beam with Timoshenko kinematics, one integration point at
!> mid-length and an integrated cross section, written in a corotational frame: a1 along node
!> 1 -> 2, a2 (the section's s axis) set at the start by the orientation node N3 and carried
!> with the mean spin of the two nodes about the axis, a3 = a1 x a2 (the t axis). From the
!> nodal velocities v and angular velocities w (length L, dv = v2 - v1, dw = w2 - w1,
!> wm = (w1 + w2) / 2):
!>   axial rate        e  = dv . a1 / L          twist rate   k1 = dw . a1 / L
!>   curvature rates   k2 = dw . a2 / L,          k3 = dw . a3 / L
!>   shear rates       g2 = dv . a2 / L - wm . a3, g3 = dv . a3 / L + wm . a2
!> and at a section point (s, t): d11 = e - s k3 + t k2, g12 = g2 - t k1, g13 = g3 + s k1.
!> Every point's (s11, s12, s13) is updated by beam_point_plasticity; the resultants
!> N = sum w s11, Q2 = sum w s12, Q3 = sum w s13, T = sum w (s s13 - t s12), M2 = sum w t s11,
!> M3 = -sum w s s11 give the nodal forces and moments as the transposes of the rates above
!> times L (the element's power is L (N e + Q2 g2 + Q3 g3 + T k1 + M2 k2 + M3 k3)). One point
!> along the length does not lock in shear and has no zero-energy mode on two nodes.
!>
!> Time centring and energies as in shell_block: rates on the mid-step configuration, forces
!> on x(n+1), the internal energy the exact work of the nodal forces (element_work).
!> Masses: rho A L / 2 per node; rotary inertia rho L / 2 max(I_polar, A L^2 / 12) per node,
!> so that the shear-rotation mode, whose frequency grows like 1 / depth with the physical
!> inertia, does not set the step. Stable step of a free element with these masses (docs/beams.md):
!>   dt = min(L / c, 2 / w_shear),  c = sqrt(E / rho),
!>   w_shear^2 = SHRF G A L (2 / (L^2 m) + 1 / (2 J)),  m, J the nodal mass and rotary inertia
!> (the bending and torsion modes are slower with this J).
!>
!> ELFORM 2 (LS-DYNA's Belytschko-Schwer resultant beam; Belytschko, Schwer & Klein 1977) is the
!> same corotational element with elastic resultants as its state instead of section points:
!> N += E A e dt, Q += SHRF G SA g dt, T += G J k1 dt, M_s += E ISS k2 dt, M_t += E ITT k3 dt
!> (*MAT_ELASTIC only; the deck refuses other laws on it).
!>
!> A failed beam (material_spotweld: *MAT_SPOTWELD's criteria) keeps zero stress and adds no
!> force or moment from the cycle in which it failed; `failed` is the mask.
module beam_block
  use kinds, only: wp, block_size
  use model, only: model_t, material_t, section_t, formulation_fe, cross_section_tubular, beam_resultant_formulation
  use gauss_legendre, only: gauss_legendre_rule
  use element_work, only: add_force_work, smallest_time_step
  use beam_point_plasticity, only: update_beam_point, beam_shear_modulus
  use material_spotweld, only: spotweld_fails
  implicit none
  private

  public :: beam_block_t, build_beam_blocks, beam_block_masses, beam_block_time_steps, compute_beam_block
  public :: beam_section_points

  !> The most section points: 5 x 5 on a rectangle, 8 angles x 5 radii on a tube.
  integer, parameter, public :: max_beam_points = 40
  !> Points around a tube's circumference.
  integer, parameter :: tube_angles = 8

  !> Up to `block_size` beams of one part and their state. Lane i is model beam `elements(i)`.
  type :: beam_block_t
    integer :: element_count = 0
    integer :: part = 0                          !< index into model%parts
    integer :: material = 0                      !< index into model%materials
    integer :: point_count = 0                   !< section points
    real(wp) :: shear_factor = 1.0_wp            !< SHRF (resultant beams: SHRF SA / A)
    !> ELFORM 2: the resultants are the state (no section points); stiffness per unit strain
    !> rate of N, Q_s, Q_t, T, M_s, M_t: E A, G SHRF SA, G SHRF SA, G J, E ISS, E ITT.
    logical :: resultant_beam = .false.
    real(wp) :: resultant_stiffness(6) = 0.0_wp
    real(wp) :: point_position(max_beam_points, 2) = 0.0_wp !< (s, t) of each section point
    real(wp) :: point_weight(max_beam_points) = 0.0_wp      !< its area
    real(wp) :: area = 0.0_wp                    !< sum of the weights
    real(wp) :: polar_inertia = 0.0_wp           !< sum w (s^2 + t^2)
    integer :: elements(block_size) = 0          !< model beam index of each lane
    integer :: nodes(block_size, 2) = 0          !< N1, N2
    real(wp) :: density(block_size) = 0.0_wp     !< raised by mass scaling
    real(wp) :: reference_length(block_size) = 0.0_wp
    !> Corotational frame of the last call: frame(i, a, k) = component k of a_a.
    real(wp) :: frame(block_size, 3, 3) = 0.0_wp
    real(wp) :: internal_energy(block_size) = 0.0_wp
    real(wp) :: force_power(block_size) = 0.0_wp
    real(wp) :: previous_time_step = 0.0_wp
    !> Global nodal forces (1-3) and moments (4-6) at N1, N2 of the last call.
    real(wp) :: previous_force(block_size, 2, 6) = 0.0_wp
    !> N, Q2, Q3, T, M2, M3 of the last call (local axes r, s, t).
    real(wp) :: resultant(block_size, 6) = 0.0_wp
    !> Failed beams: no stress, no force (material_spotweld).
    logical :: failed(block_size) = .false.
    logical :: newly_failed(block_size) = .false.    !< failed in the last call (erosion)
    real(wp) :: time = 0.0_wp                    !< the sum of the steps taken (TFAIL)
    real(wp), allocatable :: stress(:, :, :)     !< (block_size, 3, point_count): s11 s12 s13
    real(wp), allocatable :: plastic_strain(:, :) !< (block_size, point_count)
  end type beam_block_t

contains

  !> The section points of a *SECTION_BEAM: rectangle TS x TT (means of the two ends) with a
  !> QR x QR rule (QR 1-3, 5: Gauss with 1, 2, 3, 4 points; 4: 3-point Lobatto); tube of outer
  !> diameter TS and wall TT (TT 0 or >= TS/2: solid), 8 angles times QR radii (Gauss in r with
  !> the weight 2 pi r; QR 1: one ring at the radius that gives the exact bending inertia).
  subroutine beam_section_points(section, count, position, weight)
    type(section_t), intent(in) :: section
    integer, intent(out) :: count
    real(wp), intent(out) :: position(max_beam_points, 2), weight(max_beam_points)
    real(wp), parameter :: pi = acos(-1.0_wp)
    real(wp) :: points(5), weights(5), width, depth, outer, inner, radius, angle, ring_area
    integer :: n, i, j
    position = 0.0_wp
    weight = 0.0_wp
    count = 0
    if (section%cross_section == cross_section_tubular) then
      outer = 0.5_wp*0.5_wp*(section%beam_size(1) + section%beam_size(2))
      inner = outer - 0.5_wp*(section%beam_size(3) + section%beam_size(4))
      if (inner < 0.0_wp .or. section%beam_size(3) <= 0.0_wp) inner = 0.0_wp
      n = min(max(section%beam_rule, 1), 5)
      if (n == 4) n = 3
      if (section%beam_rule == 5) n = 4
      if (n == 1) then
        points(1) = sqrt(0.5_wp*(outer**2 + inner**2))
        weights(1) = pi*(outer**2 - inner**2)
      else
        call gauss_legendre_rule(n, points(1:n), weights(1:n))
        do i = 1, n
          points(i) = 0.5_wp*(outer + inner) + 0.5_wp*(outer - inner)*points(i)
          weights(i) = weights(i)*0.5_wp*(outer - inner)*2.0_wp*pi*points(i)
        end do
      end if
      do i = 1, n
        do j = 1, tube_angles
          angle = 2.0_wp*pi*real(j - 1, wp)/real(tube_angles, wp)
          radius = points(i)
          ring_area = weights(i)/real(tube_angles, wp)
          count = count + 1
          position(count, :) = [radius*cos(angle), radius*sin(angle)]
          weight(count) = ring_area
        end do
      end do
    else
      width = 0.5_wp*(section%beam_size(1) + section%beam_size(2))
      depth = 0.5_wp*(section%beam_size(3) + section%beam_size(4))
      select case (section%beam_rule)
      case (4)
        n = 3
        points(1:3) = [-1.0_wp, 0.0_wp, 1.0_wp]
        weights(1:3) = [1.0_wp, 4.0_wp, 1.0_wp]/3.0_wp
      case (5)
        n = 4
        call gauss_legendre_rule(n, points(1:n), weights(1:n))
      case default
        n = min(max(section%beam_rule, 1), 3)
        call gauss_legendre_rule(n, points(1:n), weights(1:n))
      end select
      do i = 1, n
        do j = 1, n
          count = count + 1
          position(count, :) = [0.5_wp*width*points(i), 0.5_wp*depth*points(j)]
          weight(count) = 0.25_wp*width*depth*weights(i)*weights(j)
        end do
      end do
    end if
  end subroutine beam_section_points

  !> Group the model's beams into blocks: parts in model order, beams of a part in deck order,
  !> at most block_size per block; finite element parts only. The frame at the start: a1 along
  !> N1 -> N2, a2 towards N3 (normal to a1), or without N3 normal to a1 in the plane of a1 and
  !> the global z axis (the global x axis for a beam within 30 degrees of z).
  subroutine build_beam_blocks(model, blocks)
    type(model_t), intent(in) :: model
    type(beam_block_t), allocatable, intent(out) :: blocks(:)
    integer, allocatable :: per_part(:)
    integer :: part, beam, block_count, lane, current, beam_count, axis
    real(wp) :: frame(3, 3)
    beam_count = 0
    if (allocated(model%beam_part)) beam_count = size(model%beam_part)
    allocate (per_part(size(model%parts)))
    per_part = 0
    do beam = 1, beam_count
      part = model%beam_part(beam)
      if (model%parts(part)%formulation == formulation_fe) per_part(part) = per_part(part) + 1
    end do
    block_count = sum((per_part + block_size - 1)/block_size)
    allocate (blocks(block_count))
    current = 0
    do part = 1, size(model%parts)
      if (per_part(part) == 0) cycle
      lane = block_size
      do beam = 1, beam_count
        if (model%beam_part(beam) /= part) cycle
        if (lane == block_size) then
          current = current + 1
          call start_block(model, part, blocks(current))
          lane = 0
        end if
        lane = lane + 1
        blocks(current)%element_count = lane
        blocks(current)%elements(lane) = beam
        blocks(current)%nodes(lane, :) = model%beam_nodes(1:2, beam)
        call initial_frame(model, beam, frame, blocks(current)%reference_length(lane))
        do axis = 1, 3
          blocks(current)%frame(lane, axis, :) = frame(:, axis)
        end do
      end do
    end do
  end subroutine build_beam_blocks

  subroutine start_block(model, part, block)
    type(model_t), intent(in) :: model
    integer, intent(in) :: part
    type(beam_block_t), intent(inout) :: block
    block%part = part
    block%material = model%parts(part)%material
    associate (section => model%sections(model%parts(part)%section), &
               material => model%materials(model%parts(part)%material))
      block%shear_factor = section%shear_factor
      if (section%element_formulation == beam_resultant_formulation) then
        ! A ISS ITT J SA
        block%resultant_beam = .true.
        block%point_count = 0
        block%area = section%beam_properties(1)
        block%polar_inertia = section%beam_properties(2) + section%beam_properties(3)
        block%shear_factor = section%shear_factor*section%beam_properties(5)/section%beam_properties(1)
        block%resultant_stiffness = [material%youngs_modulus*section%beam_properties(1), &
          beam_shear_modulus(material)*section%shear_factor*section%beam_properties(5), &
          beam_shear_modulus(material)*section%shear_factor*section%beam_properties(5), &
          beam_shear_modulus(material)*section%beam_properties(4), &
          material%youngs_modulus*section%beam_properties(2), material%youngs_modulus*section%beam_properties(3)]
      else
        call beam_section_points(section, block%point_count, block%point_position, block%point_weight)
        block%area = sum(block%point_weight(1:block%point_count))
        associate (points => block%point_position(1:block%point_count, :))
          block%polar_inertia = sum(block%point_weight(1:block%point_count)*(points(:, 1)**2 + points(:, 2)**2))
        end associate
      end if
    end associate
    block%density = model%materials(block%material)%density
    allocate (block%stress(block_size, 3, block%point_count), block%plastic_strain(block_size, block%point_count))
    block%stress = 0.0_wp
    block%plastic_strain = 0.0_wp
  end subroutine start_block

  !> The frame at the start, axes as columns (frame(:, a) = a_a).
  subroutine initial_frame(model, beam, frame, length)
    type(model_t), intent(in) :: model
    integer, intent(in) :: beam
    real(wp), intent(out) :: frame(3, 3), length
    real(wp) :: axis(3), toward(3)
    axis = model%coordinates(:, model%beam_nodes(2, beam)) - model%coordinates(:, model%beam_nodes(1, beam))
    length = norm2(axis)
    frame(:, 1) = axis/length
    if (model%beam_nodes(3, beam) > 0) then
      toward = model%coordinates(:, model%beam_nodes(3, beam)) - model%coordinates(:, model%beam_nodes(1, beam))
    else if (abs(frame(3, 1)) < 0.866_wp) then
      toward = [0.0_wp, 0.0_wp, 1.0_wp]
    else
      toward = [1.0_wp, 0.0_wp, 0.0_wp]
    end if
    frame(:, 2) = normal_part(toward, frame(:, 1))
    frame(:, 3) = cross(frame(:, 1), frame(:, 2))
  end subroutine initial_frame

  !> The unit vector along the part of `vector` normal to the unit vector `axis`.
  pure function normal_part(vector, axis) result(unit)
    real(wp), intent(in) :: vector(3), axis(3)
    real(wp) :: unit(3)
    unit = vector - dot_product(vector, axis)*axis
    unit = unit/norm2(unit)
  end function normal_part

  pure function cross(a, b) result(c)
    real(wp), intent(in) :: a(3), b(3)
    real(wp) :: c(3)
    c = [a(2)*b(3) - a(3)*b(2), a(3)*b(1) - a(1)*b(3), a(1)*b(2) - a(2)*b(1)]
  end function cross

  !> Lumped nodal masses and rotary inertias of each lane (the same at both nodes).
  pure subroutine beam_block_masses(block, nodal_mass, nodal_inertia)
    type(beam_block_t), intent(in) :: block
    real(wp), intent(out) :: nodal_mass(block_size), nodal_inertia(block_size)
    integer :: i
    real(wp) :: length
    nodal_mass = 0.0_wp
    nodal_inertia = 0.0_wp
    do i = 1, block%element_count
      length = block%reference_length(i)
      nodal_mass(i) = 0.5_wp*block%density(i)*block%area*length
      nodal_inertia(i) = 0.5_wp*block%density(i)*length*max(block%polar_inertia, block%area*length**2/12.0_wp)
    end do
  end subroutine beam_block_masses

  !> Stable step of each lane at length `length` (module comment); lanes beyond element_count huge.
  pure subroutine lane_time_steps(block, material, length, element_time_step)
    type(beam_block_t), intent(in) :: block
    type(material_t), intent(in) :: material
    real(wp), intent(in) :: length(block_size)
    real(wp), intent(out) :: element_time_step(block_size)
    real(wp) :: nodal_mass(block_size), nodal_inertia(block_size), shear_frequency_squared, axial_step, length_now
    integer :: i
    element_time_step = huge(1.0_wp)
    call beam_block_masses(block, nodal_mass, nodal_inertia)
    do i = 1, block%element_count
      ! (a failed beam keeps the step of its length at the start, or longer: a model whose
      ! welds have all failed goes on with the step they had)
      if (block%failed(i)) then
        length_now = max(length(i), block%reference_length(i))
      else
        length_now = length(i)
      end if
      axial_step = length_now/sqrt(material%youngs_modulus/block%density(i))
      shear_frequency_squared = block%shear_factor*beam_shear_modulus(material)*block%area*length_now* &
                                (2.0_wp/(length_now**2*nodal_mass(i)) + 0.5_wp/nodal_inertia(i))
      element_time_step(i) = min(axial_step, 2.0_wp/sqrt(shear_frequency_squared))
    end do
  end subroutine lane_time_steps

  !> Stable step of each element at the given configuration (no TSSFAC).
  subroutine beam_block_time_steps(block, material, coordinates, element_time_step)
    type(beam_block_t), intent(in) :: block
    type(material_t), intent(in) :: material
    real(wp), intent(in), contiguous :: coordinates(:, :)
    real(wp), intent(out) :: element_time_step(block_size)
    real(wp) :: length(block_size)
    integer :: i
    length = 1.0_wp
    do i = 1, block%element_count
      length(i) = norm2(coordinates(:, block%nodes(i, 2)) - coordinates(:, block%nodes(i, 1)))
    end do
    call lane_time_steps(block, material, length, element_time_step)
  end subroutine beam_block_time_steps

  !> One cycle of element work on a block (module comment): nodal_force(i, I, 1:3) is the
  !> internal force and nodal_force(i, I, 4:6) the internal moment at node I (1, 2) of lane i,
  !> global axes; `time` is the time at the end of the step (TFAIL). degenerate_element is 0 or
  !> the first model beam whose length is no longer positive. Allocates nothing.
  subroutine compute_beam_block(block, material, coordinates, velocities, angular_velocities, dt, nodal_force, &
                                critical_time_step, critical_element, degenerate_element)
    type(beam_block_t), intent(inout) :: block
    type(material_t), intent(in) :: material
    real(wp), intent(in), contiguous :: coordinates(:, :), velocities(:, :), angular_velocities(:, :)
    real(wp), intent(in) :: dt
    real(wp), intent(out) :: nodal_force(block_size, 2, 6)
    real(wp), intent(out) :: critical_time_step
    integer, intent(out) :: critical_element, degenerate_element
    real(wp) :: x(3, 2), v(3, 2), w(3, 2), mid_axis(3), end_axis(3), mid_frame(3, 3), end_frame(3, 3)
    real(wp) :: mid_length, end_length(block_size), spin, dv(3), dw(3), mean_w(3), previous(3), point_stress(3)
    real(wp) :: axial, twist, curvature(2), shear(2), increment(3), s, t, r(6)
    real(wp) :: old_power(block_size), new_power(block_size), element_time_step(block_size)
    integer :: nel, i, node, point

    nel = block%element_count
    nodal_force = 0.0_wp
    degenerate_element = 0
    end_length = 1.0_wp
    old_power = 0.0_wp
    new_power = 0.0_wp
    block%newly_failed = .false.
    block%time = block%time + dt
    do i = 1, nel
      do node = 1, 2
        x(:, node) = coordinates(:, block%nodes(i, node))
        v(:, node) = velocities(:, block%nodes(i, node))
        w(:, node) = angular_velocities(:, block%nodes(i, node))
      end do
      old_power(i) = sum(block%previous_force(i, 1, 1:3)*v(:, 1) + block%previous_force(i, 2, 1:3)*v(:, 2) + &
                         block%previous_force(i, 1, 4:6)*w(:, 1) + block%previous_force(i, 2, 4:6)*w(:, 2))
      end_axis = x(:, 2) - x(:, 1)
      end_length(i) = norm2(end_axis)
      mid_axis = end_axis - 0.5_wp*dt*(v(:, 2) - v(:, 1))
      mid_length = norm2(mid_axis)
      if (.not. (end_length(i) > 0.0_wp .and. mid_length > 0.0_wp)) then
        if (degenerate_element == 0 .and. .not. block%failed(i)) degenerate_element = block%elements(i)
        end_length(i) = 1.0_wp
        cycle
      end if
      ! the frame: a1 along the axis, a2 carried from the last frame and turned by the mean
      ! spin about the axis, half a step to the mid-step frame and half to the end
      mean_w = 0.5_wp*(w(:, 1) + w(:, 2))
      ! (local frames hold the axes as columns)
      mid_frame(:, 1) = mid_axis/mid_length
      spin = 0.5_wp*dt*dot_product(mean_w, mid_frame(:, 1))
      previous = block%frame(i, 2, :)
      call turned_frame(previous, spin, mid_frame)
      end_frame(:, 1) = end_axis/end_length(i)
      previous = mid_frame(:, 2)
      call turned_frame(previous, spin, end_frame)
      do node = 1, 3
        block%frame(i, node, :) = end_frame(:, node)
      end do
      if (block%failed(i)) cycle

      ! rates on the mid-step frame, point updates
      dv = v(:, 2) - v(:, 1)
      dw = w(:, 2) - w(:, 1)
      axial = dot_product(dv, mid_frame(:, 1))/mid_length
      twist = dot_product(dw, mid_frame(:, 1))/mid_length
      curvature(1) = dot_product(dw, mid_frame(:, 2))/mid_length
      curvature(2) = dot_product(dw, mid_frame(:, 3))/mid_length
      shear(1) = dot_product(dv, mid_frame(:, 2))/mid_length - dot_product(mean_w, mid_frame(:, 3))
      shear(2) = dot_product(dv, mid_frame(:, 3))/mid_length + dot_product(mean_w, mid_frame(:, 2))
      r = 0.0_wp
      if (block%resultant_beam) then
        ! elastic resultants, updated in the corotational frame
        r = block%resultant(i, :) + dt*block%resultant_stiffness*[axial, shear(1), shear(2), twist, curvature(1), &
                                                                  curvature(2)]
      end if
      do point = 1, block%point_count
        s = block%point_position(point, 1)
        t = block%point_position(point, 2)
        increment(1) = dt*(axial - s*curvature(2) + t*curvature(1))
        increment(2) = dt*(shear(1) - t*twist)
        increment(3) = dt*(shear(2) + s*twist)
        point_stress = block%stress(i, :, point)
        call update_beam_point(material, block%shear_factor, increment, point_stress, block%plastic_strain(i, point))
        block%stress(i, :, point) = point_stress
        associate (stress => point_stress, area => block%point_weight(point))
          r(1) = r(1) + area*stress(1)
          r(2) = r(2) + area*stress(2)
          r(3) = r(3) + area*stress(3)
          r(4) = r(4) + area*(s*stress(3) - t*stress(2))
          r(5) = r(5) + area*t*stress(1)
          r(6) = r(6) - area*s*stress(1)
        end associate
      end do
      block%resultant(i, :) = r
      if (spotweld_fails(material, block%time, r, block%plastic_strain(i, 1:block%point_count))) then
        block%failed(i) = .true.
        block%newly_failed(i) = .true.
        block%stress(i, :, :) = 0.0_wp
        block%resultant(i, :) = 0.0_wp
        cycle
      end if

      ! forces and moments on the end-of-step frame: the transposes of the rates times L
      associate (a1 => end_frame(:, 1), a2 => end_frame(:, 2), a3 => end_frame(:, 3), length => end_length(i))
        nodal_force(i, 2, 1:3) = r(1)*a1 + r(2)*a2 + r(3)*a3
        nodal_force(i, 1, 1:3) = -nodal_force(i, 2, 1:3)
        nodal_force(i, 2, 4:6) = r(4)*a1 + r(5)*a2 + r(6)*a3
        nodal_force(i, 1, 4:6) = -nodal_force(i, 2, 4:6)
        do node = 1, 2
          nodal_force(i, node, 4:6) = nodal_force(i, node, 4:6) + 0.5_wp*length*(r(3)*a2 - r(2)*a3)
        end do
      end associate
      new_power(i) = sum(nodal_force(i, 1, 1:3)*v(:, 1) + nodal_force(i, 2, 1:3)*v(:, 2) + &
                         nodal_force(i, 1, 4:6)*w(:, 1) + nodal_force(i, 2, 4:6)*w(:, 2))
    end do
    call add_force_work(nel, dt, block%previous_time_step, old_power, new_power, block%force_power, &
                        block%internal_energy)
    block%previous_force(1:nel, :, :) = nodal_force(1:nel, :, :)
    block%previous_time_step = dt

    call lane_time_steps(block, material, end_length, element_time_step)
    call smallest_time_step(nel, element_time_step, block%elements, critical_time_step, critical_element)
  end subroutine compute_beam_block

  !> frame(:, 2) = `previous` made normal to the unit axis frame(:, 1) (already set) and turned
  !> about it by `angle`; frame(:, 3) = a1 x a2.
  pure subroutine turned_frame(previous, angle, frame)
    real(wp), intent(in) :: previous(3), angle
    real(wp), intent(inout) :: frame(3, 3)
    real(wp) :: second(3)
    second = normal_part(previous, frame(:, 1))
    frame(:, 2) = cos(angle)*second + sin(angle)*cross(frame(:, 1), second)
    frame(:, 3) = cross(frame(:, 1), frame(:, 2))
  end subroutine turned_frame
end module beam_block
