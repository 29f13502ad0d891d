!> The host's own finite elements: 8-node hexahedra with 2x2x2 Gauss points, elastic, in the
!> rate form an explicit crash code uses: at each point the velocity gradient at mid-step
!> L = dF/dt Fmid^-1, the stress rotated with the Hughes-Winget increment of the spin, the
!> elastic increment of the rate of deformation added, bulk viscosity in compression, and the
!> nodal forces W P grad N from the first Piola-Kirchhoff stress P = J (sigma - q I) F^-T.
!> This is the same update the meshfree part applies at its points, so a uniform deformation
!> gives the same stress on both sides of the interface (the explicit patch test).
module host_hexahedra
  use, intrinsic :: iso_c_binding, only: c_double, c_int, c_ptr, c_f_pointer
  implicit none
  private

  public :: host_solids_t, set_up_solids, add_solid_masses, add_solid_forces
  public :: host_elastic_t, host_elastic_law

  !> The constants of the host's elastic law, handed to the meshfree part as the context of its
  !> material callback (bind(C): the C host passes the same layout).
  type, bind(c) :: host_elastic_t
    real(c_double) :: lame = 0.0_c_double, shear = 0.0_c_double
  end type host_elastic_t

  integer, parameter :: points = 8

  !> The host's finite elements and their state.
  type :: host_solids_t
    integer, allocatable :: nodes(:, :)                !< (8, elements) node indices
    real(c_double), allocatable :: gradient(:, :, :, :) !< (3, 8 nodes, 8 points, elements) dN/dX
    real(c_double), allocatable :: shape_value(:, :)   !< (8 nodes, 8 points) N at the points
    real(c_double), allocatable :: weight(:, :)        !< (8 points, elements) reference volume of a point
    real(c_double), allocatable :: reference(:, :, :)  !< (3, 8 nodes, elements) reference corner positions
    real(c_double), allocatable :: stress(:, :, :)     !< (6, 8 points, elements): xx yy zz xy yz zx
    real(c_double) :: density = 0.0_c_double, young = 0.0_c_double, poisson = 0.0_c_double
    real(c_double) :: bulk_quadratic = 1.5_c_double, bulk_linear = 0.06_c_double
  end type host_solids_t

contains

  !> Reference gradients and volumes of the elements `nodes` (8, m) over `coordinates`.
  subroutine set_up_solids(coordinates, nodes, density, young, poisson, solids)
    real(c_double), intent(in) :: coordinates(:, :)
    integer, intent(in) :: nodes(:, :)
    real(c_double), intent(in) :: density, young, poisson
    type(host_solids_t), intent(out) :: solids
    real(c_double), parameter :: corner(3, 8) = reshape([-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, &
                                                         -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1], [3, 8])
    real(c_double) :: local(3), derivative(3, 8), jacobian(3, 3), inverse(3, 3), determinant
    integer :: e, g, a

    solids%nodes = nodes
    solids%density = density
    solids%young = young
    solids%poisson = poisson
    allocate (solids%gradient(3, 8, points, size(nodes, 2)), solids%weight(points, size(nodes, 2)), &
              solids%shape_value(8, points), solids%stress(6, points, size(nodes, 2)))
    solids%stress = 0.0_c_double
    solids%reference = reshape(coordinates(:, reshape(nodes, [size(nodes)])), [3, 8, size(nodes, 2)])
    do g = 1, points
      local = corner(:, g)/sqrt(3.0_c_double)
      do a = 1, 8
        solids%shape_value(a, g) = product(1.0_c_double + corner(:, a)*local)/8.0_c_double
      end do
    end do
    do e = 1, size(nodes, 2)
      do g = 1, points
        local = corner(:, g)/sqrt(3.0_c_double)
        do a = 1, 8
          derivative(1, a) = corner(1, a)*(1.0_c_double + corner(2, a)*local(2))*(1.0_c_double + corner(3, a)*local(3))/8
          derivative(2, a) = corner(2, a)*(1.0_c_double + corner(1, a)*local(1))*(1.0_c_double + corner(3, a)*local(3))/8
          derivative(3, a) = corner(3, a)*(1.0_c_double + corner(1, a)*local(1))*(1.0_c_double + corner(2, a)*local(2))/8
        end do
        ! jacobian(i, j) = dX_i / dxi_j
        jacobian = matmul(coordinates(:, nodes(:, e)), transpose(derivative))
        call invert(jacobian, inverse, determinant)
        solids%weight(g, e) = determinant
        ! dN/dX = J^-T dN/dxi
        solids%gradient(:, :, g, e) = matmul(transpose(inverse), derivative)
      end do
    end do
  end subroutine set_up_solids

  !> Row-sum lumped masses, m_a += density * sum over points of N_a W.
  subroutine add_solid_masses(solids, mass)
    type(host_solids_t), intent(in) :: solids
    real(c_double), intent(inout) :: mass(:)
    integer :: e, g
    do e = 1, size(solids%nodes, 2)
      do g = 1, points
        mass(solids%nodes(:, e)) = mass(solids%nodes(:, e)) + solids%density*solids%shape_value(:, g)*solids%weight(g, e)
      end do
    end do
  end subroutine add_solid_masses

  !> Adds the internal forces of every element into `force` for the displacement at the end of
  !> the step `dt` and the velocity of that step; `stable_dt` is the smallest element step.
  subroutine add_solid_forces(solids, displacement, velocity, dt, force, stable_dt)
    type(host_solids_t), intent(inout) :: solids
    real(c_double), intent(in) :: displacement(:, :), velocity(:, :), dt
    real(c_double), intent(inout) :: force(:, :)
    real(c_double), intent(out) :: stable_dt
    real(c_double) :: deformation(3, 3), rate(3, 3), middle(3, 3), inverse(3, 3), velocity_gradient(3, 3)
    real(c_double) :: strain(3, 3), spin(3, 3), rotation(3, 3), sigma(3, 3), first_piola(3, 3), identity(3, 3)
    real(c_double) :: jacobian, mid_jacobian, lame, shear, wave_modulus, sound_speed, length, element_volume
    real(c_double) :: volumetric_rate, compression, viscosity, trace, current_volume, viscous
    integer :: e, g, i

    identity = 0.0_c_double
    do i = 1, 3
      identity(i, i) = 1.0_c_double
    end do
    shear = solids%young/(2.0_c_double*(1.0_c_double + solids%poisson))
    lame = solids%young*solids%poisson/((1.0_c_double + solids%poisson)*(1.0_c_double - 2.0_c_double*solids%poisson))
    wave_modulus = lame + 2.0_c_double*shear
    sound_speed = sqrt(wave_modulus/solids%density)
    stable_dt = huge(1.0_c_double)
    do e = 1, size(solids%nodes, 2)
      element_volume = sum(solids%weight(:, e))
      compression = 0.0_c_double
      current_volume = 0.0_c_double
      do g = 1, points
        deformation = identity + matmul(displacement(:, solids%nodes(:, e)), transpose(solids%gradient(:, :, g, e)))
        rate = matmul(velocity(:, solids%nodes(:, e)), transpose(solids%gradient(:, :, g, e)))
        middle = deformation - 0.5_c_double*dt*rate
        call invert(middle, inverse, mid_jacobian)
        velocity_gradient = matmul(rate, inverse)
        strain = 0.5_c_double*dt*(velocity_gradient + transpose(velocity_gradient))
        spin = 0.5_c_double*dt*(velocity_gradient - transpose(velocity_gradient))
        ! Hughes-Winget: R = (I - spin/2)^-1 (I + spin/2), an exact rotation
        call invert(identity - 0.5_c_double*spin, inverse, jacobian)
        rotation = matmul(inverse, identity + 0.5_c_double*spin)
        sigma = tensor_of(solids%stress(:, g, e))
        sigma = matmul(rotation, matmul(sigma, transpose(rotation)))
        trace = strain(1, 1) + strain(2, 2) + strain(3, 3)
        sigma = sigma + lame*trace*identity + 2.0_c_double*shear*strain
        solids%stress(:, g, e) = [sigma(1, 1), sigma(2, 2), sigma(3, 3), sigma(1, 2), sigma(2, 3), sigma(3, 1)]
        call invert(deformation, inverse, jacobian)
        current_volume = current_volume + jacobian*solids%weight(g, e)
        volumetric_rate = velocity_gradient(1, 1) + velocity_gradient(2, 2) + velocity_gradient(3, 3)
        viscosity = 0.0_c_double
        if (volumetric_rate < 0.0_c_double .and. dt > 0.0_c_double) then
          length = (element_volume*jacobian)**(1.0_c_double/3.0_c_double)
          viscosity = solids%density/jacobian*length*(solids%bulk_quadratic**2*length*volumetric_rate**2 &
                                                       - solids%bulk_linear*sound_speed*volumetric_rate)
        end if
        ! the element's mean rate of compression, for its stable step
        compression = compression + min(volumetric_rate, 0.0_c_double)/points
        first_piola = jacobian*matmul(sigma - viscosity*identity, transpose(inverse))
        force(:, solids%nodes(:, e)) = force(:, solids%nodes(:, e)) &
                                       + solids%weight(g, e)*matmul(first_piola, solids%gradient(:, :, g, e))
      end do
      ! L = V / A_max of the current element, the step of a wave (and the viscosity) across it
      length = current_volume/largest_face_area(solids%reference(:, :, e) + displacement(:, solids%nodes(:, e)))
      viscous = solids%bulk_linear*sound_speed - solids%bulk_quadratic*length*compression
      if (compression >= 0.0_c_double) viscous = 0.0_c_double
      stable_dt = min(stable_dt, length/(viscous + sqrt(viscous**2 + sound_speed**2)))
    end do
  end subroutine add_solid_forces

  !> The host's own elastic law as the meshfree part's material callback (cf_efg_material_law):
  !> on a block of n points, the stress (already rotated by the library) plus the elastic
  !> increment of the strain increment, Voigt order xx yy zz xy yz zx with tensor shear
  !> components; `context` points to a host_elastic_t. The same law as the host's elements. An
  !> elastic law keeps no history and needs no spin (the library has rotated the stress).
  subroutine host_elastic_law(n, strain_increment, spin, stress, history, context) bind(c)
    integer(c_int), value, intent(in) :: n
    real(c_double), intent(in) :: strain_increment(n, 6), spin(n, 3)
    real(c_double), intent(inout) :: stress(n, 6), history(n, *)
    type(c_ptr), value, intent(in) :: context
    type(host_elastic_t), pointer :: law
    real(c_double) :: trace
    integer :: i
    call c_f_pointer(context, law)
    do i = 1, n
      trace = strain_increment(i, 1) + strain_increment(i, 2) + strain_increment(i, 3)
      stress(i, 1:3) = stress(i, 1:3) + law%lame*trace + 2.0_c_double*law%shear*strain_increment(i, 1:3)
      stress(i, 4:6) = stress(i, 4:6) + 2.0_c_double*law%shear*strain_increment(i, 4:6)
    end do
  end subroutine host_elastic_law

  !> Largest face area of an element with current corner positions `corners` (each face as
  !> half the cross product of its diagonals).
  pure real(c_double) function largest_face_area(corners)
    real(c_double), intent(in) :: corners(3, 8)
    integer, parameter :: faces(4, 6) = reshape([1, 2, 3, 4, 5, 6, 7, 8, 1, 2, 6, 5, 2, 3, 7, 6, 3, 4, 8, 7, &
                                                 4, 1, 5, 8], [4, 6])
    integer :: face
    largest_face_area = 0.0_c_double
    do face = 1, 6
      largest_face_area = max(largest_face_area, 0.5_c_double*norm2(cross( &
        corners(:, faces(3, face)) - corners(:, faces(1, face)), corners(:, faces(4, face)) - corners(:, faces(2, face)))))
    end do
  end function largest_face_area

  pure function cross(a, b) result(c)
    real(c_double), intent(in) :: a(3), b(3)
    real(c_double) :: c(3)
    c = [a(2)*b(3) - a(3)*b(2), a(3)*b(1) - a(1)*b(3), a(1)*b(2) - a(2)*b(1)]
  end function cross

  pure function tensor_of(voigt) result(tensor)
    real(c_double), intent(in) :: voigt(6)
    real(c_double) :: tensor(3, 3)
    tensor = reshape([voigt(1), voigt(4), voigt(6), voigt(4), voigt(2), voigt(5), voigt(6), voigt(5), voigt(3)], &
                     [3, 3])
  end function tensor_of

  !> Inverse and determinant of a 3x3 matrix.
  pure subroutine invert(a, inverse, determinant)
    real(c_double), intent(in) :: a(3, 3)
    real(c_double), intent(out) :: inverse(3, 3), determinant
    determinant = a(1, 1)*(a(2, 2)*a(3, 3) - a(2, 3)*a(3, 2)) - a(1, 2)*(a(2, 1)*a(3, 3) - a(2, 3)*a(3, 1)) &
                  + a(1, 3)*(a(2, 1)*a(3, 2) - a(2, 2)*a(3, 1))
    inverse(1, 1) = a(2, 2)*a(3, 3) - a(2, 3)*a(3, 2)
    inverse(1, 2) = a(1, 3)*a(3, 2) - a(1, 2)*a(3, 3)
    inverse(1, 3) = a(1, 2)*a(2, 3) - a(1, 3)*a(2, 2)
    inverse(2, 1) = a(2, 3)*a(3, 1) - a(2, 1)*a(3, 3)
    inverse(2, 2) = a(1, 1)*a(3, 3) - a(1, 3)*a(3, 1)
    inverse(2, 3) = a(1, 3)*a(2, 1) - a(1, 1)*a(2, 3)
    inverse(3, 1) = a(2, 1)*a(3, 2) - a(2, 2)*a(3, 1)
    inverse(3, 2) = a(1, 2)*a(3, 1) - a(1, 1)*a(3, 2)
    inverse(3, 3) = a(1, 1)*a(2, 2) - a(1, 2)*a(2, 1)
    inverse = inverse/determinant
  end subroutine invert
end module host_hexahedra
