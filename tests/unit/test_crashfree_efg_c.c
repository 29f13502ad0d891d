/*
 * Unit test of the C interface of crashfree_efg (include/crashfree_efg.h), as a C host calls it:
 * a block of 3 x 3 x 3 hexahedra in the unit cube (interior nodes moved).
 * - NULL handles and NULL arrays give a status and a message naming the argument, never a
 *   crash; a node out of range and an inside-out hexahedron are refused at creation;
 * - exact mass: the lumped masses add up to density x volume (1e-12);
 * - the linear patch test: a uniform stretch gives no force at the interior particles and the
 *   traction resultant on the face x = 1;
 * - a host law given as a C function pointer gives the forces of the built-in elastic law;
 * - cf_efg_destroy sets the handle to NULL.
 * Prints "N passed, M failed" and exits with 1 when a check failed (tools/run_unit_tests.sh).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "crashfree_efg.h"

#define CELLS 3
#define SIDE (CELLS + 1)
#define NODES (SIDE * SIDE * SIDE)
#define HEXAHEDRA (CELLS * CELLS * CELLS)

static int passed = 0, failed = 0;

static void check(const char *name, int condition, const cf_efg_part *part)
{
    char message[512];
    if (condition) {
        passed++;
        return;
    }
    failed++;
    cf_efg_last_error(part, message, (int)sizeof message);
    printf("FAIL crashfree_efg_c: %s (last error: %s)\n", name, message);
}

/* The status is `expected` and the message contains `words`. */
static void expect(const char *name, const cf_efg_part *part, int status, int expected, const char *words)
{
    char message[512];
    cf_efg_last_error(part, message, (int)sizeof message);
    if (status == expected && strstr(message, words) != NULL) {
        passed++;
        return;
    }
    failed++;
    printf("FAIL crashfree_efg_c: %s: status %d (expected %d), message \"%s\" (expected to contain \"%s\")\n", name,
           status, expected, message, words);
}

static int node_index(int i, int j, int k) { return 1 + i + SIDE * (j + SIDE * k); }

static void block_mesh(double *coordinates, int *hexahedra)
{
    const double h = 1.0 / CELLS;
    for (int k = 0; k <= CELLS; k++)
        for (int j = 0; j <= CELLS; j++)
            for (int i = 0; i <= CELLS; i++) {
                int node = node_index(i, j, k);
                double *x = &coordinates[3 * (node - 1)];
                x[0] = h * i;
                x[1] = h * j;
                x[2] = h * k;
                if (i > 0 && i < CELLS && j > 0 && j < CELLS && k > 0 && k < CELLS) {
                    x[0] += 0.15 * h * sin(1.7 * node);
                    x[1] += 0.15 * h * cos(2.3 * node);
                    x[2] += 0.15 * h * sin(0.9 * node + 1.0);
                }
            }
    int cell = 0;
    for (int k = 0; k < CELLS; k++)
        for (int j = 0; j < CELLS; j++)
            for (int i = 0; i < CELLS; i++) {
                int corners[8] = {node_index(i, j, k),         node_index(i + 1, j, k),
                                  node_index(i + 1, j + 1, k), node_index(i, j + 1, k),
                                  node_index(i, j, k + 1),     node_index(i + 1, j, k + 1),
                                  node_index(i + 1, j + 1, k + 1), node_index(i, j + 1, k + 1)};
                memcpy(&hexahedra[8 * cell], corners, sizeof corners);
                cell++;
            }
}

struct elastic_constants {
    double young, poisson;
};

/* sigma += lambda tr(de) I + 2 mu de on a block of n points, column-major (n, 6). */
static void host_elastic_law(int n, const double *strain_increment, const double *spin, double *stress,
                             double *history, void *context)
{
    const struct elastic_constants *constants = context;
    double nu = constants->poisson;
    double lame = constants->young * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    double shear = 0.5 * constants->young / (1.0 + nu);
    (void)spin;
    for (int i = 0; i < n; i++) {
        double trace = strain_increment[i] + strain_increment[i + n] + strain_increment[i + 2 * n];
        for (int c = 0; c < 3; c++) stress[i + c * n] += lame * trace + 2.0 * shear * strain_increment[i + c * n];
        for (int c = 3; c < 6; c++) stress[i + c * n] += 2.0 * shear * strain_increment[i + c * n];
        history[i] += 1.0;
    }
}

static cf_efg_part *set_up_part(const double *coordinates, const int *hexahedra)
{
    const double support[3] = {1.4, 1.4, 1.4};
    cf_efg_part *part = NULL;
    int status = cf_efg_create(&part, NODES, coordinates, HEXAHEDRA, hexahedra, support, CF_EFG_KERNEL_BOX,
                               CF_EFG_INTEGRATION_STABILIZED_NODAL);
    check("create", status == CF_EFG_OK, part);
    status = cf_efg_set_up(part);
    check("set up", status == CF_EFG_OK, part);
    return part;
}

int main(void)
{
    static double coordinates[3 * NODES], displacement[3 * NODES], velocity[3 * NODES], force[2][3 * NODES];
    static double mass[NODES];
    static int hexahedra[8 * HEXAHEDRA], bad[8 * HEXAHEDRA];
    const double support[3] = {1.4, 1.4, 1.4};
    const double young = 210.0, poisson = 0.3, density = 7.85e-3, dt = 1.0e-4, strain = 1.0e-3;
    double stable_dt, energy;
    int status;
    block_mesh(coordinates, hexahedra);

    /* NULL handles and arrays */
    cf_efg_part *part = NULL;
    expect("set up of a NULL handle", part, cf_efg_set_up(part), CF_EFG_ERROR_HANDLE, "null");
    expect("destroy of a NULL handle", part, cf_efg_destroy(&part), CF_EFG_ERROR_HANDLE, "null");
    status = cf_efg_create(&part, NODES, NULL, HEXAHEDRA, hexahedra, support, 0, 1);
    expect("create with NULL coordinates", part, status, CF_EFG_ERROR_ARGUMENT, "coordinates has shape (3, 0)");
    cf_efg_destroy(&part);
    memcpy(bad, hexahedra, sizeof bad);
    bad[8 * 4 + 2] = NODES + 1; /* hexahedra(3, 5) */
    status = cf_efg_create(&part, NODES, coordinates, HEXAHEDRA, bad, support, 0, 1);
    expect("create with a node out of range", part, status, CF_EFG_ERROR_ARGUMENT,
           "hexahedra(3, 5) = 65 names no node (coordinates has 64 nodes)");
    cf_efg_destroy(&part);
    memcpy(bad, hexahedra, sizeof bad);
    for (int a = 0; a < 4; a++) { /* hexahedron 2 inside out */
        bad[8 + a] = hexahedra[8 + a + 4];
        bad[8 + a + 4] = hexahedra[8 + a];
    }
    status = cf_efg_create(&part, NODES, coordinates, HEXAHEDRA, bad, support, 0, 1);
    expect("create with an inside-out hexahedron", part, status, CF_EFG_ERROR_GEOMETRY,
           "hexahedra(:, 2) is inside out");
    cf_efg_destroy(&part);
    check("destroy sets the handle to NULL", part == NULL, part);

    /* mass and the patch test through the built-in law */
    part = set_up_part(coordinates, hexahedra);
    int nodes, particles, boundary_nodes, points;
    status = cf_efg_counts(part, &nodes, &particles, &boundary_nodes, &points);
    check("counts", status == CF_EFG_OK && nodes == NODES && particles == (CELLS - 1) * (CELLS - 1) * (CELLS - 1) &&
                        boundary_nodes + particles == NODES && points == 8 * HEXAHEDRA, part);
    status = cf_efg_lumped_mass(part, density, NULL);
    expect("lumped mass into NULL", part, status, CF_EFG_ERROR_ARGUMENT, "mass has 0 values");
    status = cf_efg_lumped_mass(part, density, mass);
    double total = 0.0;
    for (int j = 0; j < NODES; j++) total += mass[j];
    check("mass: sum = density x volume", status == CF_EFG_OK && fabs(total - density) <= 1e-12 * density, part);
    status = cf_efg_internal_force(part, displacement, velocity, dt, force[0], &stable_dt);
    expect("internal force without a law", part, status, CF_EFG_ERROR_ORDER, "no material law");
    check("set elastic", cf_efg_set_elastic(part, young, poisson) == CF_EFG_OK, part);
    double increment[3] = {strain, -poisson * strain, -poisson * strain}, stretch[3];
    for (int c = 0; c < 3; c++) stretch[c] = increment[c] / (1.0 - 0.5 * increment[c]);
    for (int j = 0; j < NODES; j++)
        for (int c = 0; c < 3; c++) {
            displacement[3 * j + c] = stretch[c] * coordinates[3 * j + c];
            velocity[3 * j + c] = displacement[3 * j + c] / dt;
        }
    memset(force, 0, sizeof force);
    status = cf_efg_internal_force(part, displacement, velocity, dt, force[0], &stable_dt);
    check("patch: internal force", status == CF_EFG_OK && stable_dt > 0.0, part);
    double right = 0.0, interior = 0.0, largest = 0.0;
    for (int j = 0; j < NODES; j++) {
        const double *x = &coordinates[3 * j];
        int boundary = 0;
        for (int c = 0; c < 3; c++) boundary |= fabs(x[c]) < 1e-12 || fabs(x[c] - 1.0) < 1e-12;
        for (int c = 0; c < 3; c++) {
            largest = fmax(largest, fabs(force[0][3 * j + c]));
            if (!boundary) interior = fmax(interior, fabs(force[0][3 * j + c]));
        }
        if (fabs(x[0] - 1.0) < 1e-12) right += force[0][3 * j];
    }
    double expected = (1.0 + stretch[1]) * (1.0 + stretch[2]) * young * strain;
    check("patch: no force at interior particles", interior <= 1e-10 * largest, part);
    check("patch: traction resultant on x = 1", fabs(right - expected) <= 1e-10 * expected, part);
    check("energy", cf_efg_internal_energy(part, &energy) == CF_EFG_OK && energy > 0.0, part);
    expect("law changed while running", part, cf_efg_set_elastic(part, young, poisson), CF_EFG_ERROR_ORDER,
           "are fixed once");
    expect("bulk viscosity changed while running", part, cf_efg_set_bulk_viscosity(part, 1.5, 0.06), CF_EFG_ERROR_ORDER,
           "are fixed once");

    /* the host's law as a C function pointer */
    struct elastic_constants constants = {young, poisson};
    cf_efg_part *hosted = set_up_part(coordinates, hexahedra);
    cf_efg_lumped_mass(hosted, density, mass);
    expect("NULL callback", hosted, cf_efg_set_material_callback(hosted, NULL, &constants, 1, 1.0),
           CF_EFG_ERROR_ARGUMENT, "callback is NULL");
    double wave_modulus = young * (1.0 - poisson) / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
    check("set callback",
          cf_efg_set_material_callback(hosted, host_elastic_law, &constants, 1, wave_modulus) == CF_EFG_OK, hosted);
    double hosted_dt;
    status = cf_efg_internal_force(hosted, displacement, velocity, dt, force[1], &hosted_dt);
    check("callback: internal force", status == CF_EFG_OK, hosted);
    double worst = 0.0;
    for (int j = 0; j < 3 * NODES; j++) worst = fmax(worst, fabs(force[1][j] - force[0][j]));
    check("callback: forces of the built-in elastic law", worst <= 1e-12 * largest, hosted);
    check("callback: same stable step", fabs(hosted_dt - stable_dt) <= 1e-12 * stable_dt, hosted);

    double physical[3 * NODES];
    check("to physical", cf_efg_to_physical(hosted, displacement, physical) == CF_EFG_OK, hosted);
    worst = 0.0;
    for (int j = 0; j < 3 * NODES; j++) worst = fmax(worst, fabs(physical[j] - displacement[j]));
    check("to physical reproduces a linear field", worst <= 1e-14, hosted);

    check("destroy", cf_efg_destroy(&part) == CF_EFG_OK && part == NULL, part);
    check("destroy the hosted part", cf_efg_destroy(&hosted) == CF_EFG_OK && hosted == NULL, hosted);
    expect("destroy twice", hosted, cf_efg_destroy(&hosted), CF_EFG_ERROR_HANDLE, "null");

    printf("%d passed, %d failed\n", passed, failed);
    return failed > 0;
}
