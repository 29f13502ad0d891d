/*
 * crashfree_efg: the coupled meshfree (EFG) method of crashfree as a library for host crash
 * codes. C99 interface of the Fortran module crashfree_efg (same procedures, same names).
 *
 * A part is made from plain arrays: the reference coordinates of its nodes and its hexahedra
 * (background cells). The library finds the part's free surface itself (faces of one hexahedron
 * only); those nodes, and the nodes marked with cf_efg_mark_boundary, keep FE functions and
 * physical values (boundary or Gamma nodes). Every other node is an interior particle: its
 * displacement and velocity are generalized values (cf_efg_to_physical gives the physical ones).
 *
 * Order of calls:
 *   cf_efg_create -> cf_efg_mark_boundary (any number of times) -> cf_efg_set_up
 *   -> cf_efg_counts, cf_efg_lumped_mass (declares the density), one law (cf_efg_set_elastic,
 *      cf_efg_set_plastic_kinematic or cf_efg_set_material_callback)
 *   -> cf_efg_internal_force every cycle -> cf_efg_destroy.
 * The law, the density and the bulk viscosity (cf_efg_set_bulk_viscosity, optional) may be given
 * any time before the first cf_efg_internal_force and are fixed after it.
 *
 * Arrays of one call must not overlap (the library reads its inputs while it writes its outputs).
 *
 * Arrays are column-major as in Fortran, node by node: coordinates[3*n] holds x, y, z of node 1,
 * then of node 2, ...; hexahedra[8*m] holds the 8 node indices of hexahedron 1, then of
 * hexahedron 2, ...: 1-BASED indices into the nodes, LS-DYNA's node order (nodes 1-4 one face,
 * 5-8 the opposite one, volume positive). Nodal arrays (displacement, velocity, force, mass,
 * physical values) have the part's n nodes in the order of coordinates. Messages name array
 * entries the Fortran way: hexahedra(3, 17) is hexahedra[8*16 + 2].
 *
 * Errors: every function returns a status, CF_EFG_OK (0) or one of CF_EFG_ERROR_*;
 * cf_efg_last_error gives the message (naming the argument and what is wrong). The library
 * never prints, never stops the process, never writes files. A handle is NULL until created and
 * NULL again after cf_efg_destroy; a NULL handle gives CF_EFG_ERROR_HANDLE. After a failed
 * cf_efg_create the handle exists only to give the message and to be destroyed.
 *
 * Threads: different parts may be used from different threads at the same time; one part from
 * one thread at a time. Inside a call the library uses OpenMP with the caller's settings (it
 * never sets the thread count); results are bit-identical for any thread count.
 *
 * Link: the Fortran library and its run-time, e.g. through pkg-config crashfree-efg; by hand
 * libcrashfree_efg.a -lgfortran -lgomp -llapack -lblas -lm (or link with gfortran -fopenmp).
 */
#ifndef CRASHFREE_EFG_H
#define CRASHFREE_EFG_H

#ifdef __cplusplus
extern "C" {
#endif

/* Status codes (the same values as the Fortran module's cf_efg_ok, cf_efg_error_*). */
#define CF_EFG_OK 0
/* An argument is wrong: a size, a value out of range, a node index naming no node, NULL. */
#define CF_EFG_ERROR_ARGUMENT 1
/* A call in the wrong order: internal force before set-up, set-up twice, create on a live
   handle, a law changed after the first internal force, ... */
#define CF_EFG_ERROR_ORDER 2
/* The handle is NULL: never created, or destroyed. */
#define CF_EFG_ERROR_HANDLE 3
/* The geometry is unusable: an inside-out or degenerate hexahedron; during the run, an
   integration point inverted by the displacement. */
#define CF_EFG_ERROR_GEOMETRY 4
/* The shape functions cannot be built (singular moment matrix, non-positive row-sum masses):
   the supports do not suit the part. */
#define CF_EFG_ERROR_SINGULAR 5
/* The material gave a non-finite or non-positive stable time step, or the host's law a stress
   that is not a finite number. */
#define CF_EFG_ERROR_MATERIAL 6

/* kernel of cf_efg_create (LS-DYNA's ISPLINE) */
#define CF_EFG_KERNEL_BOX 0
#define CF_EFG_KERNEL_SPHERE 2
/* integration of cf_efg_create (LS-DYNA's IDIM) */
#define CF_EFG_INTEGRATION_STABILIZED_NODAL 1
#define CF_EFG_INTEGRATION_GAUSS 2

/* A meshfree part (opaque). */
typedef struct cf_efg_part cf_efg_part;

/*
 * A host's constitutive law, called on blocks of n <= 64 integration points:
 *   strain_increment[6*n]  D dt (rate of deformation at mid-step times the step), column-major
 *                          (n, 6): component j of point i at [i + n*j], Voigt order
 *                          xx yy zz xy yz zx (LS-DYNA's), tensor shear components (not doubled);
 *   spin[3*n]              (n, 3): the axial vector of W dt, x = (dvz/dy - dvy/dz) dt/2, ...;
 *   stress[6*n]            (n, 6) Cauchy stress, same order, IN: already rotated objectively by
 *                          the library with that spin; OUT: the updated stress;
 *   history[k*n]           (n, k) the law's variables (k given to cf_efg_set_material_callback),
 *                          zero at the start, not rotated by the library;
 *   context                the pointer given to cf_efg_set_material_callback, untouched.
 * It may run on several threads at once for different blocks: it must only write its
 * arguments (and may read context).
 */
typedef void (*cf_efg_material_law)(int n, const double *strain_increment, const double *spin, double *stress,
                                    double *history, void *context);

/* Create *part from node_count nodes coordinates[3*node_count] (reference configuration) and
   hexahedron_count hexahedra[8*hexahedron_count] (1-based node indices, LS-DYNA order), with
   the normalized support support[3] (DX DY DZ, each > 1), kernel (CF_EFG_KERNEL_*) and
   integration (CF_EFG_INTEGRATION_*). Every node must belong to a hexahedron. *part must be
   NULL on entry (initialise handles to NULL). On failure *part is still set: read the message,
   then destroy it. */
int cf_efg_create(cf_efg_part **part, int node_count, const double *coordinates, int hexahedron_count,
                  const int *hexahedra, const double *support, int kernel, int integration);

/* Mark count nodes (1-based indices) as boundary (Gamma) nodes besides the free surface: nodes
   the host ties to its own elements, supports or contact inside the part. Before
   cf_efg_set_up; the marks of several calls add up. */
int cf_efg_mark_boundary(cf_efg_part *part, int count, const int *nodes);

/* Supports, shape functions, smoothed gradients, masses, transformation (once). */
int cf_efg_set_up(cf_efg_part *part);

/* The part's nodes, interior particles, boundary nodes and integration points (nodes =
   particles + boundary_nodes). After set-up. */
int cf_efg_counts(cf_efg_part *part, int *nodes, int *particles, int *boundary_nodes, int *integration_points);

/* mass[n] = the row-sum lumped mass of each node (eq. 29), density times its volume share; the
   masses add up to density times the part's volume. Overwrites mass (the host adds it into
   its own nodal masses). Declares the part's density (fixed after the first internal force).
   After set-up. */
int cf_efg_lumped_mass(cf_efg_part *part, double density, double *mass);

/* Isotropic linear elasticity (*MAT_ELASTIC, Jaumann rate): young > 0, -1 < poisson < 0.5. */
int cf_efg_set_elastic(cf_efg_part *part, double young, double poisson);

/* Bilinear elastic-plastic law (*MAT_PLASTIC_KINEMATIC without rate effects): yield > 0,
   0 <= tangent < young, beta in [0, 1] (0 kinematic, 1 isotropic hardening). */
int cf_efg_set_plastic_kinematic(cf_efg_part *part, double young, double poisson, double yield, double tangent,
                                 double beta);

/* The host's own law (see cf_efg_material_law) with history_count >= 0 variables per point and
   wave_modulus > 0, the law's largest constrained modulus K + 4/3 G (for the stable step). */
int cf_efg_set_material_callback(cf_efg_part *part, cf_efg_material_law callback, void *context,
                                 int history_count, double wave_modulus);

/* The bulk viscosity of the part, as *CONTROL_BULK_VISCOSITY: quadratic Q1 and linear Q2, both
   >= 0 (LS-DYNA's defaults 1.5 and 0.06 hold until this is called); it acts in compression only.
   Before the first internal force. */
int cf_efg_set_bulk_viscosity(cf_efg_part *part, double quadratic, double linear);

/* ADD the part's internal forces into force[3*n] (the host's sign: a = (f_ext - force) / m) for
   displacement[3*n] at the end of the step and velocity[3*n] at its middle (d^{n+1},
   v^{n+1/2}): generalized values at particles, nodal values at boundary nodes. dt is the step
   just taken (0 on the first call). *stable_dt: the part's stable time step, without a safety
   factor (scale it, e.g. by 0.9). Stresses and history stay in the part. On a failure during the
   computation (CF_EFG_ERROR_GEOMETRY: an inverted point; CF_EFG_ERROR_MATERIAL) force holds
   partial sums: end the run. */
int cf_efg_internal_force(cf_efg_part *part, const double *displacement, const double *velocity, double dt,
                          double *force, double *stable_dt);

/* physical[3*n]: the physical values of the nodal field generalized[3*n] (eq. 16; boundary
   nodes unchanged), for output, contact and the host's use of positions. After set-up. */
int cf_efg_to_physical(cf_efg_part *part, const double *generalized, double *physical);

/* *energy: the work of the part's internal forces up to the last internal force call. */
int cf_efg_internal_energy(cf_efg_part *part, double *energy);

/* Free the part; *part is NULL afterwards. */
int cf_efg_destroy(cf_efg_part **part);

/* The message of the part's last failure ("" after a success; for a NULL part, a sentence
   saying so) into message[length], cut to length - 1 characters and ended by NUL. */
int cf_efg_last_error(const cf_efg_part *part, char *message, int length);

#ifdef __cplusplus
}
#endif

#endif /* CRASHFREE_EFG_H */
