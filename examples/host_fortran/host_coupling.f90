!> A host model: one block mesh, its finite elements (host_hexahedra) and one meshfree region
!> handed to crashfree through its API. This is where a host code meets the library:
!>   - the region's nodes and hexahedra are copied into the part's own 1-based numbering;
!>   - the nodes the region shares with the host's elements, and the region's supported or
!>     driven nodes, are marked (they keep FE functions and nodal values);
!>   - the part's row-sum masses are added into the host's lumped masses;
!>   - each cycle the host gathers the part's displacements and velocities (generalized at its
!>     interior particles), the part adds its internal forces, the host scatters them;
!>   - the host's step is the smaller of its elements' and the part's stable steps.
module host_coupling
  use, intrinsic :: iso_c_binding, only: c_double, c_int, c_loc
  use crashfree_efg, only: cf_efg_part, cf_efg_create, cf_efg_mark_boundary, cf_efg_set_up, cf_efg_counts, &
                           cf_efg_lumped_mass, cf_efg_set_elastic, cf_efg_set_material_callback, &
                           cf_efg_internal_force, cf_efg_to_physical, cf_efg_last_error, cf_efg_destroy
  use host_mesh, only: host_mesh_t
  use host_hexahedra, only: host_solids_t, set_up_solids, add_solid_masses, add_solid_forces, host_elastic_t, &
                            host_elastic_law
  implicit none
  private

  public :: host_model_t, set_up_model, compute_forces, physical_field, check, destroy_model

  !> The host's model: mesh, its elements, the meshfree part and the nodal arrays.
  type :: host_model_t
    type(host_mesh_t) :: mesh
    type(host_solids_t) :: solids
    type(cf_efg_part) :: part
    integer, allocatable :: part_node(:)            !< part's local node -> host node
    integer, allocatable :: local_node(:)           !< host node -> part's local node (0: not in the part)
    real(c_double), allocatable :: mass(:)          !< lumped masses, host and part together
    real(c_double), allocatable :: part_mass(:)     !< the part's row-sum masses (its local nodes)
    real(c_double), allocatable :: displacement(:, :), velocity(:, :), force(:, :)
    real(c_double), allocatable :: part_displacement(:, :), part_velocity(:, :), part_force(:, :)
    integer(c_int) :: counts(4) = 0                 !< nodes, particles, boundary nodes, integration points
    !> the host's law constants when the part uses the host's law (the callback's context: a
    !> pointer, so that its address stays valid while the part lives)
    type(host_elastic_t), pointer :: law => null()
    real(c_double) :: density = 0.0_c_double
  end type host_model_t

contains

  !> Stops the host with the library's message when `status` is not 0.
  subroutine check(model, status, call_name)
    type(host_model_t), intent(inout) :: model
    integer(c_int), intent(in) :: status
    character(len=*), intent(in) :: call_name
    character(len=:), allocatable :: message
    if (status == 0) return
    call cf_efg_last_error(model%part, message)
    write (*, '(a)') "host_fortran: "//call_name//" failed (status "//trim(adjustl(text(status)))//"): "//message
    error stop 1
  end subroutine check

  !> Builds the model: cells with `meshfree(e)` form the meshfree part (kernel 0 box, 2 sphere;
  !> normalized support `support` in each direction; modified SCNI), the others are host
  !> elements; `marked(node)` lists host nodes the part must keep as boundary nodes besides those
  !> it shares with host elements. The part's law: crashfree's elastic law, or with `host_law`
  !> the host's own (host_elastic_law) through the material callback.
  subroutine set_up_model(mesh, meshfree, marked, density, young, poisson, support, kernel, host_law, model)
    type(host_mesh_t), intent(in) :: mesh
    logical, intent(in) :: meshfree(:), marked(:)
    real(c_double), intent(in) :: density, young, poisson, support
    integer(c_int), intent(in) :: kernel
    logical, intent(in) :: host_law
    type(host_model_t), intent(out) :: model
    integer :: node_count, e, marked_count, node
    logical, allocatable :: in_part(:), in_host(:)
    integer(c_int), allocatable :: part_hexahedra(:, :), boundary(:)
    integer(c_int) :: status
    integer, allocatable :: host_elements(:, :)

    model%mesh = mesh
    model%density = density
    node_count = size(mesh%coordinates, 2)
    allocate (in_part(node_count), in_host(node_count))
    in_part = .false.
    in_host = .false.
    do e = 1, size(mesh%hexahedra, 2)
      if (meshfree(e)) then
        in_part(mesh%hexahedra(:, e)) = .true.
      else
        in_host(mesh%hexahedra(:, e)) = .true.
      end if
    end do
    ! the part's own numbering: its nodes in the host's order
    allocate (model%local_node(node_count))
    model%local_node = 0
    model%part_node = pack([(node, node=1, node_count)], in_part)
    model%local_node(model%part_node) = [(node, node=1, size(model%part_node))]
    part_hexahedra = reshape(model%local_node(reshape(mesh%hexahedra(:, pack([(e, e=1, size(meshfree))], meshfree)), &
                                                      [8*count(meshfree)])), [8, count(meshfree)])
    call cf_efg_create(model%part, mesh%coordinates(:, model%part_node), part_hexahedra, &
                       [support, support, support], kernel, 1_c_int, status)
    call check(model, status, "cf_efg_create")
    ! interface nodes (shared with host elements) and the host's supports and driven nodes
    marked_count = 0
    allocate (boundary(size(model%part_node)))
    do node = 1, size(model%part_node)
      if (in_host(model%part_node(node)) .or. marked(model%part_node(node))) then
        marked_count = marked_count + 1
        boundary(marked_count) = node
      end if
    end do
    call cf_efg_mark_boundary(model%part, boundary(1:marked_count), status)
    call check(model, status, "cf_efg_mark_boundary")
    call cf_efg_set_up(model%part, status)
    call check(model, status, "cf_efg_set_up")
    if (host_law) then
      ! the host's own law through the callback (the same elastic law as its elements)
      allocate (model%law)
      model%law%shear = young/(2.0_c_double*(1.0_c_double + poisson))
      model%law%lame = young*poisson/((1.0_c_double + poisson)*(1.0_c_double - 2.0_c_double*poisson))
      call cf_efg_set_material_callback(model%part, host_elastic_law, c_loc(model%law), 0_c_int, &
                                        model%law%lame + 2.0_c_double*model%law%shear, status)
      call check(model, status, "cf_efg_set_material_callback")
    else
      call cf_efg_set_elastic(model%part, young, poisson, status)
      call check(model, status, "cf_efg_set_elastic")
    end if
    call cf_efg_counts(model%part, model%counts(1), model%counts(2), model%counts(3), model%counts(4), status)
    call check(model, status, "cf_efg_counts")

    ! lumped masses: the host's elements, then the part's row sums
    allocate (model%mass(node_count), model%part_mass(size(model%part_node)))
    model%mass = 0.0_c_double
    host_elements = mesh%hexahedra(:, pack([(e, e=1, size(meshfree))], .not. meshfree))
    call set_up_solids(mesh%coordinates, host_elements, density, young, poisson, model%solids)
    call add_solid_masses(model%solids, model%mass)
    model%part_mass = 0.0_c_double
    call cf_efg_lumped_mass(model%part, density, model%part_mass, status)
    call check(model, status, "cf_efg_lumped_mass")
    model%mass(model%part_node) = model%mass(model%part_node) + model%part_mass

    allocate (model%displacement(3, node_count), model%velocity(3, node_count), model%force(3, node_count))
    model%displacement = 0.0_c_double
    model%velocity = 0.0_c_double
    model%force = 0.0_c_double
    allocate (model%part_displacement(3, size(model%part_node)), model%part_velocity(3, size(model%part_node)), &
              model%part_force(3, size(model%part_node)))
  end subroutine set_up_model

  !> Internal forces of the host's elements and of the part for the current displacement and
  !> velocity after a step dt (dt = 0: the initial state); the stable step of both.
  subroutine compute_forces(model, dt, stable_dt)
    type(host_model_t), intent(inout) :: model
    real(c_double), intent(in) :: dt
    real(c_double), intent(out) :: stable_dt
    real(c_double) :: part_dt
    integer(c_int) :: status
    model%force = 0.0_c_double
    call add_solid_forces(model%solids, model%displacement, model%velocity, dt, model%force, stable_dt)
    model%part_displacement = model%displacement(:, model%part_node)
    model%part_velocity = model%velocity(:, model%part_node)
    model%part_force = 0.0_c_double
    call cf_efg_internal_force(model%part, model%part_displacement, model%part_velocity, dt, model%part_force, &
                               part_dt, status)
    call check(model, status, "cf_efg_internal_force")
    model%force(:, model%part_node) = model%force(:, model%part_node) + model%part_force
    stable_dt = min(stable_dt, part_dt)
  end subroutine compute_forces

  !> Frees the part, then the law constants its callback used.
  subroutine destroy_model(model)
    type(host_model_t), intent(inout) :: model
    integer(c_int) :: status
    call cf_efg_destroy(model%part, status)
    call check(model, status, "cf_efg_destroy")
    if (associated(model%law)) deallocate (model%law)
  end subroutine destroy_model

  !> A nodal field with physical values at the part's interior particles (eq. 16 of the
  !> formulation), for output, probes and contact.
  subroutine physical_field(model, field, physical)
    type(host_model_t), intent(inout) :: model
    real(c_double), intent(in) :: field(:, :)
    real(c_double), intent(out) :: physical(:, :)
    integer(c_int) :: status
    physical = field
    model%part_displacement = field(:, model%part_node)
    model%part_force = 0.0_c_double
    call cf_efg_to_physical(model%part, model%part_displacement, model%part_force, status)
    call check(model, status, "cf_efg_to_physical")
    physical(:, model%part_node) = model%part_force
  end subroutine physical_field

  function text(value) result(string)
    integer(c_int), intent(in) :: value
    character(len=16) :: string
    write (string, '(i0)') value
  end function text
end module host_coupling
