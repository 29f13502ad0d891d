!> External loads of the linear static analysis at its end time, as physical nodal forces:
!> concentrated nodal loads (*LOAD_NODE_POINT/_SET: curve value at the end time times SF) and the
!> consistent nodal forces of distributed segment loads (*LOAD_SEGMENT, *LOAD_SEGMENT_SET,
!> *LOAD_SEGMENT_NONUNIFORM; see segment_load_t in model).
!>
!> Consistent forces of a segment: F_a = integral over the segment of N_a q dA, with the
!> bilinear functions N_a of the quadrilateral, the load per unit area q interpolated bilinearly
!> from the corner values, and a 2x2 Gauss rule in the segment's parameters. On a bilinear
!> (possibly warped) quadrilateral the area vector n dA = (dX/dxi x dX/deta) dxi deta is linear
!> in (xi, eta), so for a pressure the integrand is at most cubic in each parameter and the rule
!> is exact; for a traction along a fixed direction it is exact on plane segments (there
!> |n dA| is linear as well). A triangle (node 4 repeating node 3, or 0) is the quadrilateral
!> collapsed at corner 3: its functions N_1, N_2 and N_3 + N_4 are then exactly the linear
!> triangle functions, corner 4 takes the value of corner 3, and the same rule stays exact.
module static_loads
  use kinds, only: wp
  use model, only: model_t
  use static_conditions, only: static_curve_value
  implicit none
  private

  public :: static_nodal_forces, segment_consistent_forces

  !> Parameters of the quadrilateral's corners.
  real(wp), parameter :: corner_xi(4) = [-1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp]
  real(wp), parameter :: corner_eta(4) = [-1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp]

contains

  !> Physical nodal forces `force(:, node)` of every nodal and segment load at `time`.
  subroutine static_nodal_forces(model, time, force)
    type(model_t), intent(in) :: model
    real(wp), intent(in) :: time
    real(wp), allocatable, intent(out) :: force(:, :)
    real(wp) :: corners(3, 4), values(4), forces(3, 4), magnitude
    integer :: k, corner, nodes(4)

    allocate (force(3, size(model%node_ids)))
    force = 0.0_wp
    if (allocated(model%loads)) then
      do k = 1, size(model%loads)
        associate (load => model%loads(k))
          force(load%direction, load%node) = force(load%direction, load%node) + &
                                             load%scale*static_curve_value(model, load%curve, time)
        end associate
      end do
    end if
    if (.not. allocated(model%segment_loads)) return
    do k = 1, size(model%segment_loads)
      associate (load => model%segment_loads(k))
        ! LS-DYNA's arrival and death times: the load acts from AT (the curve's time shifted by
        ! AT) until DT
        if (time < load%arrival_time .or. time > load%death) cycle
        magnitude = load%scale*static_curve_value(model, load%curve, time - load%arrival_time)
        nodes = load%nodes
        values = load%nodal_values
        if (nodes(4) == 0 .or. nodes(4) == nodes(3)) then
          nodes(4) = nodes(3)
          values(4) = values(3)
        end if
        corners = model%coordinates(:, nodes)
        call segment_consistent_forces(corners, magnitude*values, load%along_normal, load%direction, forces)
        do corner = 1, 4
          force(:, nodes(corner)) = force(:, nodes(corner)) + forces(:, corner)
        end do
      end associate
    end do
  end subroutine static_nodal_forces

  !> Consistent nodal forces `forces(:, a)` of a load per unit area with corner values
  !> `corner_values` on the quadrilateral `corners` (a triangle repeats corner 3 in corner 4):
  !> a pressure pushing against the unit normal by the right-hand rule over corners 1-2-3-4
  !> (`along_normal`), or a traction along the unit vector `direction`.
  pure subroutine segment_consistent_forces(corners, corner_values, along_normal, direction, forces)
    real(wp), intent(in) :: corners(3, 4), corner_values(4)
    logical, intent(in) :: along_normal
    real(wp), intent(in) :: direction(3)
    real(wp), intent(out) :: forces(3, 4)
    real(wp) :: points(2), xi, eta, functions(4), d_xi(4), d_eta(4), tangent_xi(3), tangent_eta(3)
    real(wp) :: area_vector(3), load(3), value
    integer :: i, j, a

    points = [-1.0_wp, 1.0_wp]/sqrt(3.0_wp)
    forces = 0.0_wp
    do j = 1, 2
      do i = 1, 2
        xi = points(i)
        eta = points(j)
        functions = 0.25_wp*(1.0_wp + corner_xi*xi)*(1.0_wp + corner_eta*eta)
        d_xi = 0.25_wp*corner_xi*(1.0_wp + corner_eta*eta)
        d_eta = 0.25_wp*corner_eta*(1.0_wp + corner_xi*xi)
        tangent_xi = matmul(corners, d_xi)
        tangent_eta = matmul(corners, d_eta)
        area_vector = [tangent_xi(2)*tangent_eta(3) - tangent_xi(3)*tangent_eta(2), &
                       tangent_xi(3)*tangent_eta(1) - tangent_xi(1)*tangent_eta(3), &
                       tangent_xi(1)*tangent_eta(2) - tangent_xi(2)*tangent_eta(1)]
        value = dot_product(functions, corner_values)
        if (along_normal) then
          load = -value*area_vector
        else
          load = value*norm2(area_vector)*direction
        end if
        do a = 1, 4
          forces(:, a) = forces(:, a) + functions(a)*load
        end do
      end do
    end do
  end subroutine segment_consistent_forces
end module static_loads
