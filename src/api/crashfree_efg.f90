!> crashfree_efg: the coupled meshfree (EFG) method as a library for host crash codes, the only
!> module a Fortran host needs (C hosts: include/crashfree_efg.h, module crashfree_efg_c).
!>
!> A part is made from plain arrays: the reference coordinates of its nodes and its hexahedra
!> (the background cells). The library finds the part's free surface (the faces of one
!> hexahedron only): those nodes keep their FE functions (Gamma nodes), and so do the nodes a
!> host marks (interfaces inside the part, supports, contact); every other node is an interior
!> particle with MLS functions and a generalized displacement. The part's set-up (supports,
!> coupled shape functions, smoothed gradients, row-sum masses, the transformation of eq. 16) and
!> its internal force are those of the solver's meshfree parts: efg_setup's build_cell_efg_part
!> and efg_forces' compute_efg_forces, one code path.
!>
!> Order of calls: cf_efg_create -> cf_efg_mark_boundary (any number of times) -> cf_efg_set_up
!> -> cf_efg_counts, cf_efg_lumped_mass (declares the density), a law (cf_efg_set_elastic,
!> cf_efg_set_plastic_kinematic or cf_efg_set_material_callback) -> cf_efg_internal_force every
!> cycle -> cf_efg_destroy. The law, the density and the bulk viscosity (cf_efg_set_bulk_viscosity,
!> optional) can be given any time before the first internal force and are fixed after it.
!> cf_efg_to_physical and cf_efg_internal_energy can be called any time after set-up,
!> cf_efg_last_error always.
!>
!> Arrays are column-major, node by node: coordinates(3, n) holds x, y, z of node 1, then of
!> node 2 ...; hexahedra(8, m) 1-based node indices in LS-DYNA's order (nodes 1-4 one face,
!> 5-8 the opposite one, the volume positive). Units are the host's (consistent).
!>
!> The library never prints, never stops the process, never writes files: every procedure
!> returns a status (cf_efg_ok = 0, or one of cf_efg_error_*), and cf_efg_last_error gives the
!> message naming the argument and what is wrong. A handle is null until created, holds its own
!> state only (no global state) and is null again after cf_efg_destroy; a null or destroyed
!> handle gives cf_efg_error_handle. After a failed cf_efg_create the handle exists only to give
!> the message and to be destroyed.
!>
!> Threads: different handles may be used from different threads at the same time; one handle
!> from one thread at a time. Inside a call the library uses OpenMP with the caller's settings
!> (it never sets the thread count) and its results are bit-identical for any thread count.
module crashfree_efg
  use, intrinsic :: iso_c_binding, only: c_int, c_double, c_ptr
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use kinds, only: wp
  use error_handling, only: error_t
  use text_format, only: integer_text, scientific_text
  use model, only: material_t, kernel_cubic_box, kernel_cubic_sphere, integration_local_boundary, integration_gauss
  use material_laws, only: law_elastic, law_plastic_kinematic
  use efg_cell_geometry, only: subcell_volumes
  use efg_part, only: efg_part_t
  use efg_setup, only: build_cell_efg_part
  use efg_host_law, only: cf_efg_material_law => host_material_law, host_law_t
  use efg_forces, only: efg_solver_t, set_up_efg_state, compute_efg_forces, transform_to_physical
  implicit none
  private

  public :: cf_efg_part, cf_efg_material_law
  public :: cf_efg_create, cf_efg_mark_boundary, cf_efg_set_up, cf_efg_counts, cf_efg_lumped_mass
  public :: cf_efg_set_elastic, cf_efg_set_plastic_kinematic, cf_efg_set_material_callback
  public :: cf_efg_set_bulk_viscosity
  public :: cf_efg_internal_force, cf_efg_to_physical, cf_efg_internal_energy, cf_efg_destroy
  public :: cf_efg_last_error, cf_efg_is_null, cf_efg_node_count, cf_efg_set_error

  !> Success.
  integer(c_int), parameter, public :: cf_efg_ok = 0
  !> An argument is wrong: a size, a value out of range, a node index naming no node.
  integer(c_int), parameter, public :: cf_efg_error_argument = 1
  !> A call in the wrong order (internal force before set-up, set-up twice, create on a live
  !> handle, a law changed after the first internal force ...).
  integer(c_int), parameter, public :: cf_efg_error_order = 2
  !> The handle is null: never created, or destroyed.
  integer(c_int), parameter, public :: cf_efg_error_handle = 3
  !> The geometry is unusable: an inside-out or degenerate hexahedron, an inverted integration
  !> point during the run.
  integer(c_int), parameter, public :: cf_efg_error_geometry = 4
  !> The shape functions cannot be built: the moment matrix is singular or the row-sum masses are
  !> not positive (supports too small or too large for the part).
  integer(c_int), parameter, public :: cf_efg_error_singular = 5
  !> The material gave a non-finite stable time step, or a host's law a stress that is not a
  !> finite number.
  integer(c_int), parameter, public :: cf_efg_error_material = 6

  !> Kernel (ISPLINE) and integration (IDIM) choices of cf_efg_create.
  integer(c_int), parameter, public :: cf_efg_kernel_box = kernel_cubic_box
  integer(c_int), parameter, public :: cf_efg_kernel_sphere = kernel_cubic_sphere
  integer(c_int), parameter, public :: cf_efg_integration_stabilized_nodal = integration_local_boundary
  integer(c_int), parameter, public :: cf_efg_integration_gauss = integration_gauss

  !> Tells a live object from freed or foreign memory (checked on every call).
  integer, parameter :: live_magic = 1178879559
  integer, parameter :: stage_failed = -1, stage_created = 1, stage_set_up = 2, stage_running = 3
  integer, parameter :: law_none = 0, law_built_in = 1, law_host = 2

  !> Everything one part holds.
  type :: part_object_t
    integer :: magic = 0
    integer :: stage = stage_created
    character(len=:), allocatable :: message         !< the last failure ("" after none)
    real(wp), allocatable :: coordinates(:, :)       !< (3, n) reference configuration
    integer, allocatable :: hexahedra(:, :)          !< (8, m)
    real(wp) :: support(3) = 0.0_wp
    integer :: kernel = 0, integration = 0
    logical, allocatable :: marked(:)                !< (n) nodes marked as Gamma nodes
    type(efg_part_t) :: geometry
    type(efg_solver_t) :: state                      !< blocks, stresses, history (from the first call)
    integer :: law = law_none
    type(material_t) :: material                     !< the built-in law
    type(host_law_t) :: host_law                     !< the host's law
    real(wp) :: density = 0.0_wp                     !< from cf_efg_lumped_mass (0: not given)
    !> bulk viscosity coefficients Q1 (quadratic) and Q2 (linear): LS-DYNA's defaults
    real(wp) :: bulk_quadratic = 1.5_wp, bulk_linear = 0.06_wp
  end type part_object_t

  !> A meshfree part: an opaque handle, null until cf_efg_create, null again after
  !> cf_efg_destroy. (A copy of a handle refers to the same part; after destroy the copies
  !> dangle, as copies of any pointer.)
  type :: cf_efg_part
    private
    type(part_object_t), pointer :: object => null()
  end type cf_efg_part

contains

  !> Create part `part` from `coordinates(3, n)` (its nodes, reference configuration) and
  !> `hexahedra(8, m)` (1-based indices into coordinates, LS-DYNA node order), with the
  !> normalized support `support` (DX DY DZ, each > 1), `kernel` (0 cubic spline box, 2 cubic
  !> spline sphere: ISPLINE) and `integration` (1 modified stabilized nodal integration, 2 Gauss
  !> 2x2x2: IDIM). Every node must belong to a hexahedron. `part` must be null (new or
  !> destroyed). On failure the handle still holds the message: read it, then destroy the part.
  subroutine cf_efg_create(part, coordinates, hexahedra, support, kernel, integration, status)
    type(cf_efg_part), intent(inout) :: part
    real(c_double), intent(in) :: coordinates(:, :)
    integer(c_int), intent(in) :: hexahedra(:, :)
    real(c_double), intent(in) :: support(:)
    integer(c_int), intent(in) :: kernel, integration
    integer(c_int), intent(out) :: status
    character(len=*), parameter :: name = "cf_efg_create"
    logical, allocatable :: used(:)
    real(wp) :: volumes(8)
    integer :: n, m, k, a, direction

    if (associated(part%object)) then
      status = cf_efg_error_order
      if (part%object%magic == live_magic) part%object%message = name//": part is already created: destroy it "// &
                                                                 "first (or use a new handle)"
      return
    end if
    allocate (part%object)
    part%object%magic = live_magic
    part%object%stage = stage_failed
    part%object%message = ""
    associate (object => part%object)
      n = size(coordinates, 2)
      m = size(hexahedra, 2)
      if (size(coordinates, 1) /= 3 .or. n < 1) then
        call fail(object, cf_efg_error_argument, name//": coordinates has shape ("// &
                  integer_text(size(coordinates, 1))//", "//integer_text(n)//"); it must be (3, n) with n >= 1", status)
        return
      end if
      if (size(hexahedra, 1) /= 8 .or. m < 1) then
        call fail(object, cf_efg_error_argument, name//": hexahedra has shape ("// &
                  integer_text(size(hexahedra, 1))//", "//integer_text(m)//"); it must be (8, m) with m >= 1", status)
        return
      end if
      if (size(support) /= 3) then
        call fail(object, cf_efg_error_argument, name//": support has "//integer_text(size(support))// &
                  " values; it must have 3 (DX DY DZ)", status)
        return
      end if
      do k = 1, n
        do direction = 1, 3
          if (.not. ieee_is_finite(coordinates(direction, k))) then
            call fail(object, cf_efg_error_argument, name//": coordinates("//integer_text(direction)//", "// &
                      integer_text(k)//") is not a finite number", status)
            return
          end if
        end do
      end do
      do direction = 1, 3
        if (.not. (support(direction) > 1.0_wp .and. ieee_is_finite(support(direction)))) then
          call fail(object, cf_efg_error_argument, name//": support("//integer_text(direction)//") = "// &
                    scientific_text(support(direction), 3)//" must be a finite number greater than 1 (the "// &
                    "normalized support DX DY DZ; at 1 a vertex weight vanishes on the cell's far corner)", status)
          return
        end if
      end do
      if (kernel /= cf_efg_kernel_box .and. kernel /= cf_efg_kernel_sphere) then
        call fail(object, cf_efg_error_argument, name//": kernel = "//integer_text(kernel)// &
                  " must be 0 (cubic spline, box) or 2 (cubic spline, sphere)", status)
        return
      end if
      if (integration /= cf_efg_integration_stabilized_nodal .and. integration /= cf_efg_integration_gauss) then
        call fail(object, cf_efg_error_argument, name//": integration = "//integer_text(integration)// &
                  " must be 1 (modified stabilized nodal integration) or 2 (2x2x2 Gauss)", status)
        return
      end if
      allocate (used(n))
      used = .false.
      do k = 1, m
        do a = 1, 8
          if (hexahedra(a, k) < 1 .or. hexahedra(a, k) > n) then
            call fail(object, cf_efg_error_argument, name//": hexahedra("//integer_text(a)//", "// &
                      integer_text(k)//") = "//integer_text(hexahedra(a, k))//" names no node (coordinates has "// &
                      integer_text(n)//" nodes)", status)
            return
          end if
          used(hexahedra(a, k)) = .true.
        end do
      end do
      do k = 1, n
        if (.not. used(k)) then
          call fail(object, cf_efg_error_argument, name//": node "//integer_text(k)//" (coordinates(:, "// &
                    integer_text(k)//")) belongs to no hexahedron: every node of the part must", status)
          return
        end if
      end do
      do k = 1, m
        volumes = subcell_volumes(coordinates(:, hexahedra(:, k)))
        if (any(volumes <= 0.0_wp)) then
          call fail(object, cf_efg_error_geometry, name//": hexahedra(:, "//integer_text(k)// &
                    ") is inside out or degenerate (a non-positive volume near its node "// &
                    integer_text(hexahedra(minloc(volumes, dim=1), k))//"): nodes 1-4 are one face, 5-8 the "// &
                    "opposite one, numbered so that the volume is positive (LS-DYNA's order)", status)
          return
        end if
      end do
      object%coordinates = coordinates
      object%hexahedra = hexahedra
      object%support = support
      object%kernel = kernel
      object%integration = integration
      allocate (object%marked(n))
      object%marked = .false.
      object%stage = stage_created
    end associate
    status = cf_efg_ok
  end subroutine cf_efg_create

  !> Mark `nodes` (indices into the part's coordinates) as Gamma nodes: they keep their FE
  !> functions and physical values, besides the free surface the library finds itself. Mark
  !> the nodes a host code ties to its own elements, supports or contact inside the part.
  !> Before cf_efg_set_up; may be called several times (the marks add up).
  subroutine cf_efg_mark_boundary(part, nodes, status)
    type(cf_efg_part), intent(inout) :: part
    integer(c_int), intent(in) :: nodes(:)
    integer(c_int), intent(out) :: status
    character(len=*), parameter :: name = "cf_efg_mark_boundary"
    integer :: k
    if (.not. live(part, status)) return
    associate (object => part%object)
      if (.not. in_stage(object, stage_created, name, "before cf_efg_set_up", status)) return
      do k = 1, size(nodes)
        if (nodes(k) < 1 .or. nodes(k) > size(object%marked)) then
          call fail(object, cf_efg_error_argument, name//": nodes("//integer_text(k)//") = "// &
                    integer_text(nodes(k))//" names no node (the part has "//integer_text(size(object%marked))// &
                    " nodes)", status)
          return
        end if
      end do
      object%marked(nodes) = .true.
    end associate
    status = cf_efg_ok
  end subroutine cf_efg_mark_boundary

  !> Supports, coupled shape functions, smoothed gradients, row-sum mass shares and the
  !> transformation of the particles (once, on the reference configuration).
  subroutine cf_efg_set_up(part, status)
    type(cf_efg_part), intent(inout) :: part
    integer(c_int), intent(out) :: status
    character(len=*), parameter :: name = "cf_efg_set_up"
    type(error_t), allocatable :: error
    integer, allocatable :: marked(:), labels(:)
    integer :: k
    if (.not. live(part, status)) return
    associate (object => part%object)
      if (.not. in_stage(object, stage_created, name, "once, after cf_efg_create", status)) return
      marked = pack([(k, k=1, size(object%marked))], object%marked)
      labels = [(k, k=1, size(object%hexahedra, 2))]
      call build_cell_efg_part(object%coordinates, object%hexahedra, labels, object%support, object%kernel, &
                               object%integration, .false., marked, name, "hexahedron", labels, &
                               [(k, k=1, size(object%coordinates, 2))], object%geometry, error)
      if (allocated(error)) then
        call fail(object, cf_efg_error_singular, error%message, status)
        return
      end if
      object%stage = stage_set_up
    end associate
    status = cf_efg_ok
  end subroutine cf_efg_set_up

  !> The part's nodes, interior particles, boundary (Gamma) nodes and integration points
  !> (nodes = particles + boundary_nodes). After cf_efg_set_up.
  subroutine cf_efg_counts(part, nodes, particles, boundary_nodes, integration_points, status)
    type(cf_efg_part), intent(inout) :: part
    integer(c_int), intent(out) :: nodes, particles, boundary_nodes, integration_points
    integer(c_int), intent(out) :: status
    character(len=*), parameter :: name = "cf_efg_counts"
    nodes = 0
    particles = 0
    boundary_nodes = 0
    integration_points = 0
    if (.not. live(part, status)) return
    associate (object => part%object)
      if (.not. set_up_done(object, name, status)) return
      nodes = size(object%coordinates, 2)
      particles = size(object%geometry%particles)
      boundary_nodes = size(object%geometry%gamma_nodes)
      integration_points = size(object%geometry%point_volume)
    end associate
    status = cf_efg_ok
  end subroutine cf_efg_counts

  !> `mass(n)` = the row-sum lumped mass of each node (eq. 29), density times its volume share;
  !> the shares add up to the part's volume exactly. `mass` is overwritten (the host adds it into
  !> its own nodal masses). Also declares the density of the part for its stable time step: it
  !> cannot change after the first internal force. After cf_efg_set_up.
  subroutine cf_efg_lumped_mass(part, density, mass, status)
    type(cf_efg_part), intent(inout) :: part
    real(c_double), intent(in) :: density
    real(c_double), intent(out) :: mass(:)
    integer(c_int), intent(out) :: status
    character(len=*), parameter :: name = "cf_efg_lumped_mass"
    integer :: j
    if (.not. live(part, status)) return
    associate (object => part%object)
      if (.not. set_up_done(object, name, status)) return
      if (size(mass) /= size(object%coordinates, 2)) then
        call fail(object, cf_efg_error_argument, name//": mass has "//integer_text(size(mass))// &
                  " values; it must have one per node ("//integer_text(size(object%coordinates, 2))//")", status)
        return
      end if
      if (.not. (density > 0.0_wp .and. ieee_is_finite(density))) then
        call fail(object, cf_efg_error_argument, name//": density = "//scientific_text(density, 3)// &
                  " must be a finite number greater than 0", status)
        return
      end if
      if (object%stage == stage_running .and. density /= object%density) then
        call fail(object, cf_efg_error_order, name//": density = "//scientific_text(density, 3)//" differs from "// &
                  scientific_text(object%density, 3)//", in use since the first cf_efg_internal_force", status)
        return
      end if
      mass = 0.0_wp
      do j = 1, size(object%geometry%mass_node)
        mass(object%geometry%mass_node(j)) = density*object%geometry%mass_volume(j)
      end do
      object%density = density
    end associate
    status = cf_efg_ok
  end subroutine cf_efg_lumped_mass

  !> Isotropic linear elasticity (hypoelastic, Jaumann rate; *MAT_ELASTIC): Young's modulus
  !> `young` > 0, Poisson's ratio -1 < `poisson` < 0.5.
  subroutine cf_efg_set_elastic(part, young, poisson, status)
    type(cf_efg_part), intent(inout) :: part
    real(c_double), intent(in) :: young, poisson
    integer(c_int), intent(out) :: status
    character(len=*), parameter :: name = "cf_efg_set_elastic"
    if (.not. live(part, status)) return
    associate (object => part%object)
      if (.not. law_may_change(object, name, status)) return
      if (.not. elastic_constants_valid(object, name, young, poisson, status)) return
      object%material = material_t()
      object%material%law = law_elastic
      object%material%youngs_modulus = young
      object%material%poissons_ratio = poisson
      object%host_law = host_law_t()
      object%law = law_built_in
    end associate
    status = cf_efg_ok
  end subroutine cf_efg_set_elastic

  !> Bilinear elastic-plastic law with kinematic/isotropic hardening (*MAT_PLASTIC_KINEMATIC
  !> without rate effects): `young`, `poisson` as cf_efg_set_elastic, initial yield stress
  !> `yield` > 0, tangent modulus 0 <= `tangent` < young, `beta` in [0, 1] (0 kinematic, 1
  !> isotropic hardening).
  subroutine cf_efg_set_plastic_kinematic(part, young, poisson, yield, tangent, beta, status)
    type(cf_efg_part), intent(inout) :: part
    real(c_double), intent(in) :: young, poisson, yield, tangent, beta
    integer(c_int), intent(out) :: status
    character(len=*), parameter :: name = "cf_efg_set_plastic_kinematic"
    if (.not. live(part, status)) return
    associate (object => part%object)
      if (.not. law_may_change(object, name, status)) return
      if (.not. elastic_constants_valid(object, name, young, poisson, status)) return
      if (.not. (yield > 0.0_wp .and. ieee_is_finite(yield))) then
        call fail(object, cf_efg_error_argument, name//": yield = "//scientific_text(yield, 3)// &
                  " must be a finite number greater than 0", status)
        return
      end if
      if (.not. (tangent >= 0.0_wp .and. tangent < young)) then
        call fail(object, cf_efg_error_argument, name//": tangent = "//scientific_text(tangent, 3)// &
                  " must be at least 0 and less than young ("//scientific_text(young, 3)//")", status)
        return
      end if
      if (.not. (beta >= 0.0_wp .and. beta <= 1.0_wp)) then
        call fail(object, cf_efg_error_argument, name//": beta = "//scientific_text(beta, 3)// &
                  " must be in [0, 1] (0 kinematic, 1 isotropic hardening)", status)
        return
      end if
      object%material = material_t()
      object%material%law = law_plastic_kinematic
      object%material%youngs_modulus = young
      object%material%poissons_ratio = poisson
      object%material%yield_stress = yield
      object%material%tangent_modulus = tangent
      object%material%hardening_beta = beta
      object%host_law = host_law_t()
      object%law = law_built_in
    end associate
    status = cf_efg_ok
  end subroutine cf_efg_set_plastic_kinematic

  !> The host's own law `callback` (interface cf_efg_material_law, bind(C)), called on blocks of
  !> at most 64 integration points with `context` passed through: (n, strain_increment(n, 6),
  !> spin(n, 3), stress(n, 6), history(n, history_count), context). Voigt order xx yy zz xy yz
  !> zx (LS-DYNA's), tensor shear components; strain_increment = D dt at mid-step; the stress
  !> arrives already rotated objectively by the spin of the step (so the law integrates a plain
  !> rate, D dt), the history is not rotated (spin(n, 3), the axial vector of W dt, is there for
  !> tensor-valued history); the history starts at zero. `wave_modulus` > 0 is the law's largest
  !> constrained modulus K + 4/3 G (the stable step uses it). The callback may run on several
  !> threads at once for different blocks: it must only touch its arguments (and read context).
  !> It must be a module or external procedure with bind(C) (kept as a pointer: it must outlive
  !> this call).
  subroutine cf_efg_set_material_callback(part, callback, context, history_count, wave_modulus, status)
    type(cf_efg_part), intent(inout) :: part
    procedure(cf_efg_material_law) :: callback
    type(c_ptr), intent(in) :: context
    integer(c_int), intent(in) :: history_count
    real(c_double), intent(in) :: wave_modulus
    integer(c_int), intent(out) :: status
    character(len=*), parameter :: name = "cf_efg_set_material_callback"
    if (.not. live(part, status)) return
    associate (object => part%object)
      if (.not. law_may_change(object, name, status)) return
      if (history_count < 0) then
        call fail(object, cf_efg_error_argument, name//": history_count = "//integer_text(history_count)// &
                  " must be 0 or more", status)
        return
      end if
      if (.not. (wave_modulus > 0.0_wp .and. ieee_is_finite(wave_modulus))) then
        call fail(object, cf_efg_error_argument, name//": wave_modulus = "//scientific_text(wave_modulus, 3)// &
                  " must be a finite number greater than 0 (K + 4/3 G of the law)", status)
        return
      end if
      object%host_law = host_law_t()
      object%host_law%update => callback
      object%host_law%context = context
      object%host_law%history_count = history_count
      object%host_law%wave_modulus = wave_modulus
      object%material = material_t()
      object%law = law_host
    end associate
    status = cf_efg_ok
  end subroutine cf_efg_set_material_callback

  !> The bulk viscosity of the part's points, as *CONTROL_BULK_VISCOSITY: `quadratic` Q1 and
  !> `linear` Q2 (both >= 0; LS-DYNA's defaults 1.5 and 0.06 hold until this is called). It acts
  !> in compression only. Before the first internal force.
  subroutine cf_efg_set_bulk_viscosity(part, quadratic, linear, status)
    type(cf_efg_part), intent(inout) :: part
    real(c_double), intent(in) :: quadratic, linear
    integer(c_int), intent(out) :: status
    character(len=*), parameter :: name = "cf_efg_set_bulk_viscosity"
    if (.not. live(part, status)) return
    associate (object => part%object)
      if (.not. law_may_change(object, name, status)) return
      if (.not. (quadratic >= 0.0_wp .and. ieee_is_finite(quadratic))) then
        call fail(object, cf_efg_error_argument, name//": quadratic = "//scientific_text(quadratic, 3)// &
                  " must be a finite number, 0 or more (Q1)", status)
        return
      end if
      if (.not. (linear >= 0.0_wp .and. ieee_is_finite(linear))) then
        call fail(object, cf_efg_error_argument, name//": linear = "//scientific_text(linear, 3)// &
                  " must be a finite number, 0 or more (Q2)", status)
        return
      end if
      object%bulk_quadratic = quadratic
      object%bulk_linear = linear
    end associate
    status = cf_efg_ok
  end subroutine cf_efg_set_bulk_viscosity

  !> Add the part's internal forces into `force(3, n)` (the host's sign: a = (f_ext - force) / m,
  !> as LS-DYNA's internal force) for `displacement(3, n)` at the end of the step and
  !> `velocity(3, n)` at its middle (central differences: d^{n+1}, v^{n+1/2}), generalized values
  !> at the particles, nodal values at the boundary nodes. `dt` is the step just taken (0 on the
  !> first call). Returns the part's stable time step `stable_dt` (without a safety factor: the
  !> host scales it, e.g. by 0.9). The stresses and history stay in the part. On a failure during
  !> the computation (cf_efg_error_geometry: an inverted point; cf_efg_error_material) `force`
  !> holds partial sums: the host ends its run.
  subroutine cf_efg_internal_force(part, displacement, velocity, dt, force, stable_dt, status)
    type(cf_efg_part), intent(inout) :: part
    real(c_double), intent(in), contiguous :: displacement(:, :), velocity(:, :)
    real(c_double), intent(in) :: dt
    real(c_double), intent(inout), contiguous :: force(:, :)
    real(c_double), intent(out) :: stable_dt
    integer(c_int), intent(out) :: status
    character(len=*), parameter :: name = "cf_efg_internal_force"
    integer :: b, point
    stable_dt = huge(1.0_wp)
    if (.not. live(part, status)) return
    associate (object => part%object)
      if (.not. set_up_done(object, name, status)) return
      if (.not. field_shape_valid(object, name, "displacement", displacement, status)) return
      if (.not. field_shape_valid(object, name, "velocity", velocity, status)) return
      if (.not. field_shape_valid(object, name, "force", force, status)) return
      if (.not. (dt >= 0.0_wp .and. ieee_is_finite(dt))) then
        call fail(object, cf_efg_error_argument, name//": dt = "//scientific_text(dt, 3)// &
                  " must be a finite number, 0 or more", status)
        return
      end if
      if (object%stage == stage_set_up) then
        if (object%law == law_none) then
          call fail(object, cf_efg_error_order, name//": the part has no material law: call cf_efg_set_elastic, "// &
                    "cf_efg_set_plastic_kinematic or cf_efg_set_material_callback first", status)
          return
        end if
        if (object%density <= 0.0_wp) then
          call fail(object, cf_efg_error_order, name//": the part has no density: call cf_efg_lumped_mass first", &
                    status)
          return
        end if
        call set_up_efg_state(object%geometry, object%coordinates, object%hexahedra, object%material, &
                              object%density, object%bulk_quadratic, object%bulk_linear, object%host_law, &
                              size(object%coordinates, 2), object%state)
        object%stage = stage_running
      end if
      call compute_efg_forces(object%material, object%state, displacement, velocity, dt, force)
      ! a host's law is not known to the library: its stresses are checked (the built-in laws'
      ! are finite for finite input)
      if (object%law == law_host) then
        do point = 1, size(object%state%point_stress, 2)
          if (all(ieee_is_finite(object%state%point_stress(:, point)))) cycle
          call fail(object, cf_efg_error_material, name//": the host's material law returned a stress that is "// &
                    "not a finite number at integration point "//integer_text(point)//" of hexahedron "// &
                    integer_text(object%geometry%point_cell(point)), status)
          return
        end do
      end if
      do b = 1, size(object%state%blocks)
        if (object%state%block_inverted_point(b) /= 0) then
          point = object%state%block_inverted_point(b)
          call fail(object, cf_efg_error_geometry, name//": integration point "//integer_text(point)// &
                    " of hexahedron "//integer_text(object%geometry%point_cell(point))// &
                    " is inverted (negative volume): the displacement folds the part", status)
          return
        end if
        if (.not. (object%state%block_time_step(b) > 0.0_wp)) then
          call fail(object, cf_efg_error_material, name//": the stable time step of integration point "// &
                    integer_text(object%state%block_critical_point(b))//" is not a positive number: the "// &
                    "material returned a non-finite stress or modulus", status)
          return
        end if
        stable_dt = min(stable_dt, object%state%block_time_step(b))
      end do
    end associate
    status = cf_efg_ok
  end subroutine cf_efg_internal_force

  !> Physical values of a nodal field (eq. 16): `physical(:, J)` = sum_I Psi_I(X_J)
  !> `generalized(:, I)` at the particles, the values themselves at the boundary nodes. For
  !> output, contact and the host's own use of positions and velocities. After cf_efg_set_up.
  subroutine cf_efg_to_physical(part, generalized, physical, status)
    type(cf_efg_part), intent(inout) :: part
    real(c_double), intent(in) :: generalized(:, :)
    real(c_double), intent(out) :: physical(:, :)
    integer(c_int), intent(out) :: status
    character(len=*), parameter :: name = "cf_efg_to_physical"
    if (.not. live(part, status)) return
    associate (object => part%object)
      if (.not. set_up_done(object, name, status)) return
      if (.not. field_shape_valid(object, name, "generalized", generalized, status)) return
      if (.not. field_shape_valid(object, name, "physical", physical, status)) return
      physical = generalized
      call transform_to_physical(object%geometry, generalized, physical)
    end associate
    status = cf_efg_ok
  end subroutine cf_efg_to_physical

  !> The internal energy of the part: the work of its internal forces up to the last
  !> cf_efg_internal_force (0 before it), point by point in a fixed order.
  subroutine cf_efg_internal_energy(part, energy, status)
    type(cf_efg_part), intent(inout) :: part
    real(c_double), intent(out) :: energy
    integer(c_int), intent(out) :: status
    character(len=*), parameter :: name = "cf_efg_internal_energy"
    integer :: b, i
    energy = 0.0_wp
    if (.not. live(part, status)) return
    associate (object => part%object)
      if (.not. set_up_done(object, name, status)) return
      if (object%stage == stage_running) then
        do b = 1, size(object%state%blocks)
          do i = 1, object%state%blocks(b)%point_count
            energy = energy + object%state%blocks(b)%internal_energy(i)
          end do
        end do
      end if
    end associate
    status = cf_efg_ok
  end subroutine cf_efg_internal_energy

  !> Free everything the part holds; `part` is null afterwards. A null handle gives
  !> cf_efg_error_handle.
  subroutine cf_efg_destroy(part, status)
    type(cf_efg_part), intent(inout) :: part
    integer(c_int), intent(out) :: status
    if (.not. associated(part%object)) then
      status = cf_efg_error_handle
      return
    end if
    if (part%object%magic /= live_magic) then
      status = cf_efg_error_handle
      return
    end if
    part%object%magic = 0
    deallocate (part%object)
    nullify (part%object)
    status = cf_efg_ok
  end subroutine cf_efg_destroy

  !> The message of the part's last failure ("" when the last call succeeded); for a null
  !> handle, a sentence saying so.
  subroutine cf_efg_last_error(part, message)
    type(cf_efg_part), intent(in) :: part
    character(len=:), allocatable, intent(out) :: message
    if (.not. associated(part%object)) then
      message = "part: the handle is null (not created, or destroyed)"
    else if (part%object%magic /= live_magic) then
      message = "part: the handle does not refer to a live part"
    else
      message = part%object%message
    end if
  end subroutine cf_efg_last_error

  !> Whether `part` is null (never created, or destroyed).
  logical function cf_efg_is_null(part)
    type(cf_efg_part), intent(in) :: part
    cf_efg_is_null = .not. associated(part%object)
  end function cf_efg_is_null

  !> The part's node count n (the columns of its nodal arrays), known from creation; 0 for a
  !> null handle or a failed creation.
  integer(c_int) function cf_efg_node_count(part)
    type(cf_efg_part), intent(in) :: part
    cf_efg_node_count = 0
    if (.not. associated(part%object)) return
    if (part%object%magic /= live_magic) return
    if (.not. allocated(part%object%coordinates)) return
    cf_efg_node_count = size(part%object%coordinates, 2)
  end function cf_efg_node_count

  !> Record a failure found by a binding layer on top of this module (the C interface: a NULL
  !> array, a negative count) as the part's last error: `status` = `code`, the message kept for
  !> cf_efg_last_error. A null handle keeps nothing (status cf_efg_error_handle).
  subroutine cf_efg_set_error(part, code, message, status)
    type(cf_efg_part), intent(inout) :: part
    integer(c_int), intent(in) :: code
    character(len=*), intent(in) :: message
    integer(c_int), intent(out) :: status
    status = cf_efg_error_handle
    if (.not. associated(part%object)) return
    if (part%object%magic /= live_magic) return
    call fail(part%object, code, message, status)
  end subroutine cf_efg_set_error

  ! ---- checks shared by the procedures above --------------------------------------------------

  !> Whether the handle refers to a live part (not one whose creation failed: cf_efg_error_order,
  !> the creation's message kept); clears its message (a call starts afresh).
  logical function live(part, status)
    type(cf_efg_part), intent(in) :: part
    integer(c_int), intent(out) :: status
    live = .false.
    status = cf_efg_error_handle
    if (.not. associated(part%object)) return
    if (part%object%magic /= live_magic) return
    ! a failed creation keeps its message: giving it is all such a handle is for
    if (part%object%stage == stage_failed) then
      status = cf_efg_error_order
      return
    end if
    part%object%message = ""
    status = cf_efg_ok
    live = .true.
  end function live

  !> Whether the part is in `stage`; else an order failure saying `when`.
  logical function in_stage(object, stage, name, when, status)
    type(part_object_t), intent(inout) :: object
    integer, intent(in) :: stage
    character(len=*), intent(in) :: name, when
    integer(c_int), intent(out) :: status
    in_stage = object%stage == stage
    status = cf_efg_ok
    if (.not. in_stage) call fail(object, cf_efg_error_order, name//": wrong order of calls: call it "//when// &
                                  " (the part is "//stage_text(object%stage)//")", status)
  end function in_stage

  !> Whether cf_efg_set_up has been done.
  logical function set_up_done(object, name, status)
    type(part_object_t), intent(inout) :: object
    character(len=*), intent(in) :: name
    integer(c_int), intent(out) :: status
    set_up_done = object%stage == stage_set_up .or. object%stage == stage_running
    status = cf_efg_ok
    if (.not. set_up_done) call fail(object, cf_efg_error_order, name//": wrong order of calls: call "// &
                                     "cf_efg_set_up first (the part is "//stage_text(object%stage)//")", status)
  end function set_up_done

  !> A law (and the bulk viscosity) may be set after create and before the first internal force.
  logical function law_may_change(object, name, status)
    type(part_object_t), intent(inout) :: object
    character(len=*), intent(in) :: name
    integer(c_int), intent(out) :: status
    law_may_change = object%stage == stage_created .or. object%stage == stage_set_up
    status = cf_efg_ok
    if (.not. law_may_change) call fail(object, cf_efg_error_order, name//": wrong order of calls: the "// &
                                        "material law and the bulk viscosity are fixed once internal forces "// &
                                        "were computed", status)
  end function law_may_change

  logical function elastic_constants_valid(object, name, young, poisson, status)
    type(part_object_t), intent(inout) :: object
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: young, poisson
    integer(c_int), intent(out) :: status
    elastic_constants_valid = .false.
    status = cf_efg_ok
    if (.not. (young > 0.0_wp .and. ieee_is_finite(young))) then
      call fail(object, cf_efg_error_argument, name//": young = "//scientific_text(young, 3)// &
                " must be a finite number greater than 0", status)
    else if (.not. (poisson > -1.0_wp .and. poisson < 0.5_wp)) then
      call fail(object, cf_efg_error_argument, name//": poisson = "//scientific_text(poisson, 3)// &
                " must be greater than -1 and less than 0.5", status)
    else
      elastic_constants_valid = .true.
    end if
  end function elastic_constants_valid

  !> Whether a nodal field has the shape (3, n).
  logical function field_shape_valid(object, name, argument, field, status)
    type(part_object_t), intent(inout) :: object
    character(len=*), intent(in) :: name, argument
    real(wp), intent(in) :: field(:, :)
    integer(c_int), intent(out) :: status
    field_shape_valid = size(field, 1) == 3 .and. size(field, 2) == size(object%coordinates, 2)
    status = cf_efg_ok
    if (.not. field_shape_valid) call fail(object, cf_efg_error_argument, name//": "//argument//" has shape ("// &
                                           integer_text(size(field, 1))//", "//integer_text(size(field, 2))// &
                                           "); it must be (3, "//integer_text(size(object%coordinates, 2))// &
                                           "), one column per node of the part", status)
  end function field_shape_valid

  pure function stage_text(stage) result(text)
    integer, intent(in) :: stage
    character(len=:), allocatable :: text
    select case (stage)
    case (stage_created)
      text = "created, not set up"
    case (stage_set_up)
      text = "set up"
    case (stage_running)
      text = "running: internal forces were computed"
    case default
      text = "failed at creation"
    end select
  end function stage_text

  !> Record a failure: its status and message.
  subroutine fail(object, code, message, status)
    type(part_object_t), intent(inout) :: object
    integer(c_int), intent(in) :: code
    character(len=*), intent(in) :: message
    integer(c_int), intent(out) :: status
    object%message = message
    status = code
  end subroutine fail
end module crashfree_efg
