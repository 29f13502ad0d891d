!> The C interface of crashfree_efg (include/crashfree_efg.h): the same procedures with
!> bind(C) under the same names, a part as an opaque `cf_efg_part *`.
!>
!> Every function returns its status (CF_EFG_OK = 0, else CF_EFG_ERROR_*). A handle is the C
!> address of a crashfree_efg handle made by cf_efg_create(&part, ...) and set to NULL by
!> cf_efg_destroy(&part); a NULL handle gives CF_EFG_ERROR_HANDLE, never a crash. Arrays are
!> the Fortran ones, column-major: coordinates[3*n] (x, y, z of node 1, then node 2 ...),
!> hexahedra[8*m] 1-based node indices. A NULL array is reported like an empty one, by the
!> argument's name.
module crashfree_efg_c
  use, intrinsic :: iso_c_binding, only: c_int, c_double, c_ptr, c_funptr, c_char, c_null_ptr, c_null_char, &
                                         c_associated, c_f_pointer, c_f_procpointer, c_loc
  use crashfree_efg, only: cf_efg_part, cf_efg_material_law, cf_efg_create, cf_efg_mark_boundary, cf_efg_set_up, &
                           cf_efg_counts, cf_efg_lumped_mass, cf_efg_set_elastic, cf_efg_set_plastic_kinematic, &
                           cf_efg_set_material_callback, cf_efg_set_bulk_viscosity, cf_efg_internal_force, &
                           cf_efg_to_physical, &
                           cf_efg_internal_energy, cf_efg_destroy, cf_efg_last_error, cf_efg_node_count, &
                           cf_efg_set_error, cf_efg_error_argument, cf_efg_error_handle, cf_efg_ok
  implicit none
  private

  public :: cf_efg_create_c, cf_efg_mark_boundary_c, cf_efg_set_up_c, cf_efg_counts_c, cf_efg_lumped_mass_c
  public :: cf_efg_set_elastic_c, cf_efg_set_plastic_kinematic_c, cf_efg_set_material_callback_c
  public :: cf_efg_set_bulk_viscosity_c
  public :: cf_efg_internal_force_c, cf_efg_to_physical_c, cf_efg_internal_energy_c, cf_efg_destroy_c
  public :: cf_efg_last_error_c

contains

  !> int cf_efg_create(cf_efg_part **part, int node_count, const double *coordinates,
  !>                   int hexahedron_count, const int *hexahedra, const double *support,
  !>                   int kernel, int integration)
  integer(c_int) function cf_efg_create_c(part, node_count, coordinates, hexahedron_count, hexahedra, support, &
                                          kernel, integration) bind(c, name="cf_efg_create")
    type(c_ptr), intent(inout) :: part
    integer(c_int), value, intent(in) :: node_count, hexahedron_count, kernel, integration
    type(c_ptr), value, intent(in) :: coordinates, hexahedra, support
    type(cf_efg_part), pointer :: handle
    real(c_double), pointer, contiguous :: coordinate_values(:, :), support_values(:)
    integer(c_int), pointer, contiguous :: hexahedron_values(:, :)
    real(c_double), target :: no_reals(3, 0), no_support(0)
    integer(c_int), target :: no_integers(8, 0)

    if (c_associated(part)) then
      ! a live handle: the Fortran procedure reports the order error into it
      call c_f_pointer(part, handle)
    else
      allocate (handle)
      part = c_loc(handle)
    end if
    coordinate_values => no_reals
    hexahedron_values => no_integers
    support_values => no_support
    if (c_associated(coordinates) .and. node_count > 0) &
      call c_f_pointer(coordinates, coordinate_values, [3, node_count])
    if (c_associated(hexahedra) .and. hexahedron_count > 0) &
      call c_f_pointer(hexahedra, hexahedron_values, [8, hexahedron_count])
    if (c_associated(support)) call c_f_pointer(support, support_values, [3])
    call cf_efg_create(handle, coordinate_values, hexahedron_values, support_values, kernel, integration, &
                       cf_efg_create_c)
  end function cf_efg_create_c

  !> int cf_efg_mark_boundary(cf_efg_part *part, int count, const int *nodes)
  integer(c_int) function cf_efg_mark_boundary_c(part, count, nodes) bind(c, name="cf_efg_mark_boundary")
    type(c_ptr), value, intent(in) :: part, nodes
    integer(c_int), value, intent(in) :: count
    type(cf_efg_part), pointer :: handle
    integer(c_int), pointer, contiguous :: node_values(:)
    integer(c_int), target :: no_nodes(0)
    if (.not. handle_of(part, handle, cf_efg_mark_boundary_c)) return
    if (count < 0 .or. (count > 0 .and. .not. c_associated(nodes))) then
      call cf_efg_set_error(handle, cf_efg_error_argument, "cf_efg_mark_boundary: count < 0 or nodes is NULL", &
                            cf_efg_mark_boundary_c)
      return
    end if
    node_values => no_nodes
    if (count > 0) call c_f_pointer(nodes, node_values, [count])
    call cf_efg_mark_boundary(handle, node_values, cf_efg_mark_boundary_c)
  end function cf_efg_mark_boundary_c

  !> int cf_efg_set_up(cf_efg_part *part)
  integer(c_int) function cf_efg_set_up_c(part) bind(c, name="cf_efg_set_up")
    type(c_ptr), value, intent(in) :: part
    type(cf_efg_part), pointer :: handle
    if (.not. handle_of(part, handle, cf_efg_set_up_c)) return
    call cf_efg_set_up(handle, cf_efg_set_up_c)
  end function cf_efg_set_up_c

  !> int cf_efg_counts(cf_efg_part *part, int *nodes, int *particles, int *boundary_nodes,
  !>                   int *integration_points)
  integer(c_int) function cf_efg_counts_c(part, nodes, particles, boundary_nodes, integration_points) &
    bind(c, name="cf_efg_counts")
    type(c_ptr), value, intent(in) :: part
    integer(c_int), intent(out) :: nodes, particles, boundary_nodes, integration_points
    type(cf_efg_part), pointer :: handle
    nodes = 0
    particles = 0
    boundary_nodes = 0
    integration_points = 0
    if (.not. handle_of(part, handle, cf_efg_counts_c)) return
    call cf_efg_counts(handle, nodes, particles, boundary_nodes, integration_points, cf_efg_counts_c)
  end function cf_efg_counts_c

  !> int cf_efg_lumped_mass(cf_efg_part *part, double density, double *mass)
  integer(c_int) function cf_efg_lumped_mass_c(part, density, mass) bind(c, name="cf_efg_lumped_mass")
    type(c_ptr), value, intent(in) :: part, mass
    real(c_double), value, intent(in) :: density
    type(cf_efg_part), pointer :: handle
    real(c_double), pointer, contiguous :: mass_values(:)
    real(c_double), target :: no_values(0)
    if (.not. handle_of(part, handle, cf_efg_lumped_mass_c)) return
    mass_values => no_values
    if (c_associated(mass)) call c_f_pointer(mass, mass_values, [cf_efg_node_count(handle)])
    call cf_efg_lumped_mass(handle, density, mass_values, cf_efg_lumped_mass_c)
  end function cf_efg_lumped_mass_c

  !> int cf_efg_set_elastic(cf_efg_part *part, double young, double poisson)
  integer(c_int) function cf_efg_set_elastic_c(part, young, poisson) bind(c, name="cf_efg_set_elastic")
    type(c_ptr), value, intent(in) :: part
    real(c_double), value, intent(in) :: young, poisson
    type(cf_efg_part), pointer :: handle
    if (.not. handle_of(part, handle, cf_efg_set_elastic_c)) return
    call cf_efg_set_elastic(handle, young, poisson, cf_efg_set_elastic_c)
  end function cf_efg_set_elastic_c

  !> int cf_efg_set_plastic_kinematic(cf_efg_part *part, double young, double poisson,
  !>                                  double yield, double tangent, double beta)
  integer(c_int) function cf_efg_set_plastic_kinematic_c(part, young, poisson, yield, tangent, beta) &
    bind(c, name="cf_efg_set_plastic_kinematic")
    type(c_ptr), value, intent(in) :: part
    real(c_double), value, intent(in) :: young, poisson, yield, tangent, beta
    type(cf_efg_part), pointer :: handle
    if (.not. handle_of(part, handle, cf_efg_set_plastic_kinematic_c)) return
    call cf_efg_set_plastic_kinematic(handle, young, poisson, yield, tangent, beta, cf_efg_set_plastic_kinematic_c)
  end function cf_efg_set_plastic_kinematic_c

  !> int cf_efg_set_material_callback(cf_efg_part *part, cf_efg_material_law callback,
  !>                                  void *context, int history_count, double wave_modulus)
  integer(c_int) function cf_efg_set_material_callback_c(part, callback, context, history_count, wave_modulus) &
    bind(c, name="cf_efg_set_material_callback")
    type(c_ptr), value, intent(in) :: part, context
    type(c_funptr), value, intent(in) :: callback
    integer(c_int), value, intent(in) :: history_count
    real(c_double), value, intent(in) :: wave_modulus
    type(cf_efg_part), pointer :: handle
    procedure(cf_efg_material_law), pointer :: law
    if (.not. handle_of(part, handle, cf_efg_set_material_callback_c)) return
    if (.not. c_associated(callback)) then
      call cf_efg_set_error(handle, cf_efg_error_argument, "cf_efg_set_material_callback: callback is NULL", &
                            cf_efg_set_material_callback_c)
      return
    end if
    call c_f_procpointer(callback, law)
    call cf_efg_set_material_callback(handle, law, context, history_count, wave_modulus, &
                                      cf_efg_set_material_callback_c)
  end function cf_efg_set_material_callback_c

  !> int cf_efg_set_bulk_viscosity(cf_efg_part *part, double quadratic, double linear)
  integer(c_int) function cf_efg_set_bulk_viscosity_c(part, quadratic, linear) bind(c, name="cf_efg_set_bulk_viscosity")
    type(c_ptr), value, intent(in) :: part
    real(c_double), value, intent(in) :: quadratic, linear
    type(cf_efg_part), pointer :: handle
    if (.not. handle_of(part, handle, cf_efg_set_bulk_viscosity_c)) return
    call cf_efg_set_bulk_viscosity(handle, quadratic, linear, cf_efg_set_bulk_viscosity_c)
  end function cf_efg_set_bulk_viscosity_c

  !> int cf_efg_internal_force(cf_efg_part *part, const double *displacement,
  !>                           const double *velocity, double dt, double *force, double *stable_dt)
  integer(c_int) function cf_efg_internal_force_c(part, displacement, velocity, dt, force, stable_dt) &
    bind(c, name="cf_efg_internal_force")
    type(c_ptr), value, intent(in) :: part, displacement, velocity, force
    real(c_double), value, intent(in) :: dt
    real(c_double), intent(out) :: stable_dt
    type(cf_efg_part), pointer :: handle
    real(c_double), pointer, contiguous :: displacement_values(:, :), velocity_values(:, :), force_values(:, :)
    real(c_double), target :: no_displacement(3, 0), no_velocity(3, 0), no_force(3, 0)
    stable_dt = huge(1.0_c_double)
    if (.not. handle_of(part, handle, cf_efg_internal_force_c)) return
    displacement_values => no_displacement
    velocity_values => no_velocity
    force_values => no_force
    call nodal_field(handle, displacement, displacement_values)
    call nodal_field(handle, velocity, velocity_values)
    call nodal_field(handle, force, force_values)
    call cf_efg_internal_force(handle, displacement_values, velocity_values, dt, force_values, stable_dt, &
                               cf_efg_internal_force_c)
  end function cf_efg_internal_force_c

  !> int cf_efg_to_physical(cf_efg_part *part, const double *generalized, double *physical)
  integer(c_int) function cf_efg_to_physical_c(part, generalized, physical) bind(c, name="cf_efg_to_physical")
    type(c_ptr), value, intent(in) :: part, generalized, physical
    type(cf_efg_part), pointer :: handle
    real(c_double), pointer, contiguous :: generalized_values(:, :), physical_values(:, :)
    real(c_double), target :: no_generalized(3, 0), no_physical(3, 0)
    if (.not. handle_of(part, handle, cf_efg_to_physical_c)) return
    generalized_values => no_generalized
    physical_values => no_physical
    call nodal_field(handle, generalized, generalized_values)
    call nodal_field(handle, physical, physical_values)
    call cf_efg_to_physical(handle, generalized_values, physical_values, cf_efg_to_physical_c)
  end function cf_efg_to_physical_c

  !> int cf_efg_internal_energy(cf_efg_part *part, double *energy)
  integer(c_int) function cf_efg_internal_energy_c(part, energy) bind(c, name="cf_efg_internal_energy")
    type(c_ptr), value, intent(in) :: part
    real(c_double), intent(out) :: energy
    type(cf_efg_part), pointer :: handle
    energy = 0.0_c_double
    if (.not. handle_of(part, handle, cf_efg_internal_energy_c)) return
    call cf_efg_internal_energy(handle, energy, cf_efg_internal_energy_c)
  end function cf_efg_internal_energy_c

  !> int cf_efg_destroy(cf_efg_part **part): *part is NULL afterwards.
  integer(c_int) function cf_efg_destroy_c(part) bind(c, name="cf_efg_destroy")
    type(c_ptr), intent(inout) :: part
    type(cf_efg_part), pointer :: handle
    if (.not. handle_of(part, handle, cf_efg_destroy_c)) return
    call cf_efg_destroy(handle, cf_efg_destroy_c)
    if (cf_efg_destroy_c /= cf_efg_ok) return
    deallocate (handle)
    part = c_null_ptr
  end function cf_efg_destroy_c

  !> int cf_efg_last_error(const cf_efg_part *part, char *message, int length): the message,
  !> cut to length - 1 characters and ended by NUL.
  integer(c_int) function cf_efg_last_error_c(part, message, length) bind(c, name="cf_efg_last_error")
    type(c_ptr), value, intent(in) :: part
    character(kind=c_char), intent(out) :: message(*)
    integer(c_int), value, intent(in) :: length
    type(cf_efg_part), pointer :: handle
    type(cf_efg_part) :: null_handle
    character(len=:), allocatable :: text
    integer :: k, kept
    cf_efg_last_error_c = cf_efg_error_argument
    if (length < 1) return
    if (c_associated(part)) then
      call c_f_pointer(part, handle)
      call cf_efg_last_error(handle, text)
    else
      call cf_efg_last_error(null_handle, text)
    end if
    kept = min(len(text), length - 1)
    do k = 1, kept
      message(k) = text(k:k)
    end do
    message(kept + 1) = c_null_char
    cf_efg_last_error_c = cf_efg_ok
  end function cf_efg_last_error_c

  !> The Fortran handle behind a C handle; false (status cf_efg_error_handle) for NULL.
  logical function handle_of(part, handle, status)
    type(c_ptr), intent(in) :: part
    type(cf_efg_part), pointer, intent(out) :: handle
    integer(c_int), intent(out) :: status
    handle_of = c_associated(part)
    handle => null()
    status = cf_efg_error_handle
    if (.not. handle_of) return
    call c_f_pointer(part, handle)
    status = cf_efg_ok
  end function handle_of

  !> A nodal array (3, n) of the part from a C pointer (left as it is, empty, when NULL).
  subroutine nodal_field(handle, address, field)
    type(cf_efg_part), intent(in) :: handle
    type(c_ptr), intent(in) :: address
    real(c_double), pointer, contiguous, intent(inout) :: field(:, :)
    if (.not. c_associated(address)) return
    call c_f_pointer(address, field, [3, cf_efg_node_count(handle)])
  end subroutine nodal_field
end module crashfree_efg_c
