/* An explicit host code in C of its own (hexahedra, central differences, a support and a
 * prescribed velocity) that makes one region of its mesh meshfree through crashfree's C
 * interface (crashfree_efg.h, docs/embedding.md). The same model as examples/host_fortran, mode
 * for mode, with the same output lines. Units: mm, ms, kg, kN (GPa for stresses).
 *   host_c patch [support kernel [host-law]]
 *                                   explicit patch test (v = A X), velocity error after 100 cycles
 *   host_c bar [host-law]           a pulse along a bar, host elements for x < 50, meshfree beyond
 *   (host-law: the part uses the host's elastic law through the material callback)
 *   host_c forces DT                one internal force call of an all-meshfree block
 *   host_c bench CELLS CALLS        ns per integration point per call of cf_efg_internal_force
 *   host_c misuse                   calls in error (null, destroyed handles, wrong order, bad
 *                                   arrays): each status and message, one line each */
/* clock_gettime */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <crashfree_efg.h>

static const double density = 7.85e-6, young = 210.0;

/* ---------- the mesh: a block of hexahedra, LS-DYNA node order (as host_mesh.f90) ---------- */

typedef struct {
    int cells[3];
    double cell_size;
    int node_count, element_count;
    double *coordinates; /* [3 * node_count] */
    int *hexahedra;      /* [8 * element_count], 1-based node numbers */
} host_mesh;

/* 1-based node number at 0-based grid position (i, j, k), x fastest */
static int node_index(const host_mesh *mesh, int i, int j, int k)
{
    return 1 + i + (mesh->cells[0] + 1) * (j + (mesh->cells[1] + 1) * k);
}

static int on_block_boundary(const host_mesh *mesh, int i, int j, int k)
{
    return i == 0 || j == 0 || k == 0 || i == mesh->cells[0] || j == mesh->cells[1] || k == mesh->cells[2];
}

/* interior nodes moved by up to perturbation * cell_size in steps of 1/256 of the range, from
 * state = (1103515245 state + 12345) mod 2^31: the Fortran host's numbers exactly */
static void block_mesh(const int cells[3], double cell_size, double perturbation, int seed, host_mesh *mesh)
{
    int64_t state = seed;
    mesh->cells[0] = cells[0];
    mesh->cells[1] = cells[1];
    mesh->cells[2] = cells[2];
    mesh->cell_size = cell_size;
    mesh->node_count = (cells[0] + 1) * (cells[1] + 1) * (cells[2] + 1);
    mesh->element_count = cells[0] * cells[1] * cells[2];
    mesh->coordinates = malloc(sizeof(double) * 3 * mesh->node_count);
    mesh->hexahedra = malloc(sizeof(int) * 8 * mesh->element_count);
    for (int k = 0; k <= cells[2]; k++)
        for (int j = 0; j <= cells[1]; j++)
            for (int i = 0; i <= cells[0]; i++) {
                double *x = mesh->coordinates + 3 * (node_index(mesh, i, j, k) - 1);
                x[0] = cell_size * i;
                x[1] = cell_size * j;
                x[2] = cell_size * k;
                if (on_block_boundary(mesh, i, j, k)) continue;
                for (int direction = 0; direction < 3; direction++) {
                    state = (1103515245 * state + 12345) % 2147483648;
                    double fraction = (double)(state / 8388608) / 256.0;
                    x[direction] = x[direction] + perturbation * cell_size * (2.0 * fraction - 1.0);
                }
            }
    for (int k = 0; k < cells[2]; k++)
        for (int j = 0; j < cells[1]; j++)
            for (int i = 0; i < cells[0]; i++) {
                int *h = mesh->hexahedra + 8 * (i + cells[0] * (j + cells[1] * k));
                h[0] = node_index(mesh, i, j, k);
                h[1] = node_index(mesh, i + 1, j, k);
                h[2] = node_index(mesh, i + 1, j + 1, k);
                h[3] = node_index(mesh, i, j + 1, k);
                h[4] = node_index(mesh, i, j, k + 1);
                h[5] = node_index(mesh, i + 1, j, k + 1);
                h[6] = node_index(mesh, i + 1, j + 1, k + 1);
                h[7] = node_index(mesh, i, j + 1, k + 1);
            }
}

/* ---------- the host's own elements (as host_hexahedra.f90): 2x2x2 points, elastic, rate form ---------- */

typedef struct {
    int count;
    int *nodes;         /* [8 * count], 1-based */
    double *gradient;   /* [count][8 points][8 nodes][3] dN/dX */
    double *weight;     /* [count][8 points] */
    double *reference;  /* [count][8 nodes][3] */
    double *stress;     /* [count][8 points][6]: xx yy zz xy yz zx */
    double shape[8][8]; /* [point][node] */
    double density, young, poisson, bulk_quadratic, bulk_linear;
} host_solids;

static const double corner[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                    {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};

/* inverse (row-major a[i][j]) and determinant */
static double invert(double a[3][3], double inverse[3][3])
{
    double determinant = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                         a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                         a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    inverse[0][0] = (a[1][1] * a[2][2] - a[1][2] * a[2][1]) / determinant;
    inverse[0][1] = (a[0][2] * a[2][1] - a[0][1] * a[2][2]) / determinant;
    inverse[0][2] = (a[0][1] * a[1][2] - a[0][2] * a[1][1]) / determinant;
    inverse[1][0] = (a[1][2] * a[2][0] - a[1][0] * a[2][2]) / determinant;
    inverse[1][1] = (a[0][0] * a[2][2] - a[0][2] * a[2][0]) / determinant;
    inverse[1][2] = (a[0][2] * a[1][0] - a[0][0] * a[1][2]) / determinant;
    inverse[2][0] = (a[1][0] * a[2][1] - a[1][1] * a[2][0]) / determinant;
    inverse[2][1] = (a[0][1] * a[2][0] - a[0][0] * a[2][1]) / determinant;
    inverse[2][2] = (a[0][0] * a[1][1] - a[0][1] * a[1][0]) / determinant;
    return determinant;
}

static void set_up_solids(const double *coordinates, int count, const int *nodes, host_solids *solids)
{
    double root = 1.0 / sqrt(3.0);
    solids->count = count;
    solids->nodes = malloc(sizeof(int) * 8 * (count > 0 ? count : 1));
    memcpy(solids->nodes, nodes, sizeof(int) * 8 * count);
    solids->gradient = malloc(sizeof(double) * 192 * (count > 0 ? count : 1));
    solids->weight = malloc(sizeof(double) * 8 * (count > 0 ? count : 1));
    solids->reference = malloc(sizeof(double) * 24 * (count > 0 ? count : 1));
    solids->stress = calloc(48 * (count > 0 ? count : 1), sizeof(double));
    solids->density = density;
    solids->bulk_quadratic = 1.5;
    solids->bulk_linear = 0.06;
    for (int g = 0; g < 8; g++)
        for (int a = 0; a < 8; a++)
            solids->shape[g][a] = (1 + corner[a][0] * corner[g][0] * root) * (1 + corner[a][1] * corner[g][1] * root) *
                                  (1 + corner[a][2] * corner[g][2] * root) / 8.0;
    for (int e = 0; e < count; e++) {
        for (int a = 0; a < 8; a++)
            for (int i = 0; i < 3; i++)
                solids->reference[24 * e + 3 * a + i] = coordinates[3 * (nodes[8 * e + a] - 1) + i];
        for (int g = 0; g < 8; g++) {
            double local[3] = {corner[g][0] * root, corner[g][1] * root, corner[g][2] * root};
            double derivative[8][3], jacobian[3][3] = {{0}}, inverse[3][3];
            for (int a = 0; a < 8; a++) {
                derivative[a][0] = corner[a][0] * (1 + corner[a][1] * local[1]) * (1 + corner[a][2] * local[2]) / 8;
                derivative[a][1] = corner[a][1] * (1 + corner[a][0] * local[0]) * (1 + corner[a][2] * local[2]) / 8;
                derivative[a][2] = corner[a][2] * (1 + corner[a][0] * local[0]) * (1 + corner[a][1] * local[1]) / 8;
                for (int i = 0; i < 3; i++)
                    for (int j = 0; j < 3; j++) jacobian[i][j] += solids->reference[24 * e + 3 * a + i] * derivative[a][j];
            }
            solids->weight[8 * e + g] = invert(jacobian, inverse);
            for (int a = 0; a < 8; a++)
                for (int i = 0; i < 3; i++) {
                    /* dN/dX_i = sum_j (J^-1)_ji dN/dxi_j */
                    double value = 0;
                    for (int j = 0; j < 3; j++) value += inverse[j][i] * derivative[a][j];
                    solids->gradient[192 * e + 24 * g + 3 * a + i] = value;
                }
        }
    }
}

static void add_solid_masses(const host_solids *solids, double *mass)
{
    for (int e = 0; e < solids->count; e++)
        for (int g = 0; g < 8; g++)
            for (int a = 0; a < 8; a++)
                mass[solids->nodes[8 * e + a] - 1] += solids->density * solids->shape[g][a] * solids->weight[8 * e + g];
}

static double largest_face_area(double corners[8][3])
{
    static const int faces[6][4] = {{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
    double largest = 0;
    for (int f = 0; f < 6; f++) {
        double a[3], b[3], c[3];
        for (int i = 0; i < 3; i++) {
            a[i] = corners[faces[f][2]][i] - corners[faces[f][0]][i];
            b[i] = corners[faces[f][3]][i] - corners[faces[f][1]][i];
        }
        c[0] = a[1] * b[2] - a[2] * b[1];
        c[1] = a[2] * b[0] - a[0] * b[2];
        c[2] = a[0] * b[1] - a[1] * b[0];
        double area = 0.5 * sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        if (area > largest) largest = area;
    }
    return largest;
}

/* the same update as host_hexahedra.f90's add_solid_forces: mid-step velocity gradient,
 * Hughes-Winget rotation, elastic increment, bulk viscosity, f += W P grad N */
static double add_solid_forces(host_solids *solids, const double *displacement, const double *velocity, double dt,
                               double *force)
{
    double shear = solids->young / (2 * (1 + solids->poisson));
    double lame = solids->young * solids->poisson / ((1 + solids->poisson) * (1 - 2 * solids->poisson));
    double sound_speed = sqrt((lame + 2 * shear) / solids->density);
    double stable_dt = HUGE_VAL;
    for (int e = 0; e < solids->count; e++) {
        const int *nodes = solids->nodes + 8 * e;
        double element_volume = 0, current_volume = 0, compression = 0;
        for (int g = 0; g < 8; g++) element_volume += solids->weight[8 * e + g];
        for (int g = 0; g < 8; g++) {
            const double *gradient = solids->gradient + 192 * e + 24 * g;
            double deformation[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, rate[3][3] = {{0}};
            for (int a = 0; a < 8; a++)
                for (int i = 0; i < 3; i++)
                    for (int j = 0; j < 3; j++) {
                        deformation[i][j] += displacement[3 * (nodes[a] - 1) + i] * gradient[3 * a + j];
                        rate[i][j] += velocity[3 * (nodes[a] - 1) + i] * gradient[3 * a + j];
                    }
            double middle[3][3], inverse[3][3], l[3][3] = {{0}}, strain[3][3], spin[3][3];
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++) middle[i][j] = deformation[i][j] - 0.5 * dt * rate[i][j];
            invert(middle, inverse);
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++)
                    for (int k = 0; k < 3; k++) l[i][j] += rate[i][k] * inverse[k][j];
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++) {
                    strain[i][j] = 0.5 * dt * (l[i][j] + l[j][i]);
                    spin[i][j] = 0.5 * dt * (l[i][j] - l[j][i]);
                }
            /* Hughes-Winget: R = (I - spin/2)^-1 (I + spin/2) */
            double left[3][3], right[3][3], rotation[3][3] = {{0}};
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++) {
                    left[i][j] = (i == j) - 0.5 * spin[i][j];
                    right[i][j] = (i == j) + 0.5 * spin[i][j];
                }
            invert(left, inverse);
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++)
                    for (int k = 0; k < 3; k++) rotation[i][j] += inverse[i][k] * right[k][j];
            double *voigt = solids->stress + 48 * e + 6 * g;
            double sigma[3][3] = {{voigt[0], voigt[3], voigt[5]}, {voigt[3], voigt[1], voigt[4]}, {voigt[5], voigt[4], voigt[2]}};
            double turned[3][3] = {{0}}, temporary[3][3] = {{0}};
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++)
                    for (int k = 0; k < 3; k++) temporary[i][j] += rotation[i][k] * sigma[k][j];
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++)
                    for (int k = 0; k < 3; k++) turned[i][j] += temporary[i][k] * rotation[j][k];
            double trace = strain[0][0] + strain[1][1] + strain[2][2];
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++) sigma[i][j] = turned[i][j] + lame * trace * (i == j) + 2 * shear * strain[i][j];
            voigt[0] = sigma[0][0];
            voigt[1] = sigma[1][1];
            voigt[2] = sigma[2][2];
            voigt[3] = sigma[0][1];
            voigt[4] = sigma[1][2];
            voigt[5] = sigma[2][0];
            double jacobian = invert(deformation, inverse);
            current_volume += jacobian * solids->weight[8 * e + g];
            double volumetric_rate = l[0][0] + l[1][1] + l[2][2], viscosity = 0;
            if (volumetric_rate < 0 && dt > 0) {
                double length = cbrt(element_volume * jacobian);
                viscosity = solids->density / jacobian * length *
                            (solids->bulk_quadratic * solids->bulk_quadratic * length * volumetric_rate * volumetric_rate -
                             solids->bulk_linear * sound_speed * volumetric_rate);
            }
            /* the element's mean rate of compression, for its stable step */
            if (volumetric_rate < 0) compression += volumetric_rate / 8;
            /* P = J (sigma - q I) F^-T: P_ij = J sum_k (sigma - q I)_ik (F^-1)_jk */
            double first_piola[3][3];
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++) {
                    double value = 0;
                    for (int k = 0; k < 3; k++) value += (sigma[i][k] - viscosity * (i == k)) * inverse[j][k];
                    first_piola[i][j] = jacobian * value;
                }
            for (int a = 0; a < 8; a++)
                for (int i = 0; i < 3; i++) {
                    double value = 0;
                    for (int j = 0; j < 3; j++) value += first_piola[i][j] * gradient[3 * a + j];
                    force[3 * (nodes[a] - 1) + i] += solids->weight[8 * e + g] * value;
                }
        }
        double corners[8][3];
        for (int a = 0; a < 8; a++)
            for (int i = 0; i < 3; i++) corners[a][i] = solids->reference[24 * e + 3 * a + i] + displacement[3 * (nodes[a] - 1) + i];
        double length = current_volume / largest_face_area(corners);
        double viscous = compression < 0 ? solids->bulk_linear * sound_speed - solids->bulk_quadratic * length * compression : 0;
        double step = length / (viscous + sqrt(viscous * viscous + sound_speed * sound_speed));
        if (step < stable_dt) stable_dt = step;
    }
    return stable_dt;
}

/* the host's elastic law as the part's material callback (cf_efg_material_law): on a block of n
 * points, column-major (n, 6), the stress (already rotated by the library) plus the elastic
 * increment; context points to the law's constants. The same law as the host's elements. */
typedef struct {
    double lame, shear;
} host_elastic;

static void host_elastic_law(int n, const double *strain_increment, const double *spin, double *stress, double *history,
                             void *context)
{
    const host_elastic *law = context;
    (void)spin;    /* the library has rotated the stress */
    (void)history; /* an elastic law keeps none */
    for (int i = 0; i < n; i++) {
        double trace = strain_increment[i] + strain_increment[i + n] + strain_increment[i + 2 * n];
        for (int j = 0; j < 3; j++) stress[i + n * j] += law->lame * trace + 2 * law->shear * strain_increment[i + n * j];
        for (int j = 3; j < 6; j++) stress[i + n * j] += 2 * law->shear * strain_increment[i + n * j];
    }
}

/* ---------- the coupling (as host_coupling.f90) ---------- */

typedef struct {
    host_mesh mesh;
    host_solids solids;
    cf_efg_part *part;
    int part_node_count;
    int *part_node;  /* part's local node (0-based) -> host node (0-based) */
    double *mass, *part_mass;
    double *displacement, *velocity, *force;
    double *part_displacement, *part_velocity, *part_force;
    int counts[4];
    host_elastic law; /* the callback's context when the part uses the host's law */
} host_model;

/* stops the host with the library's message when status is not 0 */
static void check(const host_model *model, int status, const char *call)
{
    char message[512];
    if (status == 0) return;
    cf_efg_last_error(model->part, message, sizeof message);
    printf("host_c: %s failed (status %d): %s\n", call, status, message);
    exit(1);
}

/* the part's law: the library's elastic law, or with host_law the host's own through the callback
   (model must then stay where it is while the part lives: the context points into it) */
static void set_up_model(const host_mesh *mesh, const int *meshfree, const int *marked, double poisson, double support,
                         int kernel, int host_law, host_model *model)
{
    int node_count = mesh->node_count;
    int *in_part = calloc(node_count, sizeof(int)), *in_host = calloc(node_count, sizeof(int));
    int *local_node = calloc(node_count, sizeof(int));
    int part_elements = 0, host_elements = 0;
    model->mesh = *mesh;
    for (int e = 0; e < mesh->element_count; e++) {
        for (int a = 0; a < 8; a++) (meshfree[e] ? in_part : in_host)[mesh->hexahedra[8 * e + a] - 1] = 1;
        if (meshfree[e]) part_elements++; else host_elements++;
    }
    /* the part's own numbering: its nodes in the host's order */
    model->part_node = malloc(sizeof(int) * node_count);
    model->part_node_count = 0;
    for (int node = 0; node < node_count; node++)
        if (in_part[node]) {
            local_node[node] = model->part_node_count + 1;
            model->part_node[model->part_node_count++] = node;
        }
    int n = model->part_node_count;
    double *part_coordinates = malloc(sizeof(double) * 3 * n);
    for (int p = 0; p < n; p++)
        for (int i = 0; i < 3; i++) part_coordinates[3 * p + i] = mesh->coordinates[3 * model->part_node[p] + i];
    int *part_hexahedra = malloc(sizeof(int) * 8 * part_elements), *solid_nodes = malloc(sizeof(int) * 8 * (host_elements + 1));
    int next_part = 0, next_host = 0;
    for (int e = 0; e < mesh->element_count; e++)
        for (int a = 0; a < 8; a++) {
            int node = mesh->hexahedra[8 * e + a];
            if (meshfree[e]) part_hexahedra[next_part++] = local_node[node - 1];
            else solid_nodes[next_host++] = node;
        }
    double supports[3] = {support, support, support};
    int status = cf_efg_create(&model->part, n, part_coordinates, part_elements, part_hexahedra, supports, kernel, 1);
    check(model, status, "cf_efg_create");
    /* interface nodes (shared with host elements) and the host's supports and driven nodes */
    int *boundary = malloc(sizeof(int) * n), count = 0;
    for (int p = 0; p < n; p++)
        if (in_host[model->part_node[p]] || marked[model->part_node[p]]) boundary[count++] = p + 1;
    check(model, cf_efg_mark_boundary(model->part, count, boundary), "cf_efg_mark_boundary");
    check(model, cf_efg_set_up(model->part), "cf_efg_set_up");
    if (host_law) {
        model->law.shear = young / (2 * (1 + poisson));
        model->law.lame = young * poisson / ((1 + poisson) * (1 - 2 * poisson));
        check(model, cf_efg_set_material_callback(model->part, host_elastic_law, &model->law, 0,
                                                  model->law.lame + 2 * model->law.shear),
              "cf_efg_set_material_callback");
    } else {
        check(model, cf_efg_set_elastic(model->part, young, poisson), "cf_efg_set_elastic");
    }
    check(model, cf_efg_counts(model->part, &model->counts[0], &model->counts[1], &model->counts[2], &model->counts[3]),
          "cf_efg_counts");
    /* lumped masses: the host's elements, then the part's row sums */
    model->mass = calloc(node_count, sizeof(double));
    model->part_mass = calloc(n, sizeof(double));
    set_up_solids(mesh->coordinates, host_elements, solid_nodes, &model->solids);
    model->solids.young = young;
    model->solids.poisson = poisson;
    add_solid_masses(&model->solids, model->mass);
    check(model, cf_efg_lumped_mass(model->part, density, model->part_mass), "cf_efg_lumped_mass");
    for (int p = 0; p < n; p++) model->mass[model->part_node[p]] += model->part_mass[p];
    model->displacement = calloc(3 * node_count, sizeof(double));
    model->velocity = calloc(3 * node_count, sizeof(double));
    model->force = calloc(3 * node_count, sizeof(double));
    model->part_displacement = calloc(3 * n, sizeof(double));
    model->part_velocity = calloc(3 * n, sizeof(double));
    model->part_force = calloc(3 * n, sizeof(double));
    free(in_part);
    free(in_host);
    free(local_node);
    free(part_coordinates);
    free(part_hexahedra);
    free(solid_nodes);
    free(boundary);
}

/* internal forces of the host's elements and of the part; the smaller stable step */
static double compute_forces(host_model *model, double dt)
{
    double part_dt;
    memset(model->force, 0, sizeof(double) * 3 * model->mesh.node_count);
    double stable_dt = add_solid_forces(&model->solids, model->displacement, model->velocity, dt, model->force);
    for (int p = 0; p < model->part_node_count; p++)
        for (int i = 0; i < 3; i++) {
            model->part_displacement[3 * p + i] = model->displacement[3 * model->part_node[p] + i];
            model->part_velocity[3 * p + i] = model->velocity[3 * model->part_node[p] + i];
            model->part_force[3 * p + i] = 0;
        }
    check(model, cf_efg_internal_force(model->part, model->part_displacement, model->part_velocity, dt, model->part_force,
                                       &part_dt),
          "cf_efg_internal_force");
    for (int p = 0; p < model->part_node_count; p++)
        for (int i = 0; i < 3; i++) model->force[3 * model->part_node[p] + i] += model->part_force[3 * p + i];
    return stable_dt < part_dt ? stable_dt : part_dt;
}

/* a nodal field with physical values at the part's interior particles (output, probes, contact) */
static void physical_field(host_model *model, const double *field, double *physical)
{
    memcpy(physical, field, sizeof(double) * 3 * model->mesh.node_count);
    for (int p = 0; p < model->part_node_count; p++)
        for (int i = 0; i < 3; i++) model->part_displacement[3 * p + i] = field[3 * model->part_node[p] + i];
    check(model, cf_efg_to_physical(model->part, model->part_displacement, model->part_force), "cf_efg_to_physical");
    for (int p = 0; p < model->part_node_count; p++)
        for (int i = 0; i < 3; i++) physical[3 * model->part_node[p] + i] = model->part_force[3 * p + i];
}

/* v += step a, a = -f / m */
static void advance(host_model *model, double step)
{
    for (int node = 0; node < model->mesh.node_count; node++)
        for (int i = 0; i < 3; i++) model->velocity[3 * node + i] -= step * model->force[3 * node + i] / model->mass[node];
}

/* ---------- the modes ---------- */

static void patch_test(double support, int kernel, int host_law)
{
    static const double gradient[3][3] = {{0.010, 0.004, -0.002}, {0.003, -0.006, 0.005}, {-0.001, 0.002, 0.008}};
    host_mesh mesh;
    host_model model;
    int cells[3] = {6, 5, 5};
    block_mesh(cells, 0.25, 0.25, 11, &mesh);
    int *meshfree = malloc(sizeof(int) * mesh.element_count), *driven = calloc(mesh.node_count, sizeof(int));
    int part_elements = 0;
    for (int e = 0; e < mesh.element_count; e++) part_elements += meshfree[e] = e % mesh.cells[0] < 3;
    for (int k = 0; k <= cells[2]; k++)
        for (int j = 0; j <= cells[1]; j++)
            for (int i = 0; i <= cells[0]; i++) driven[node_index(&mesh, i, j, k) - 1] = on_block_boundary(&mesh, i, j, k);
    set_up_model(&mesh, meshfree, driven, 0.3, support, kernel, host_law, &model);
    /* the part's mass against density times its cells' volume (the host integrates them) */
    host_solids cells_of_part;
    int *part_nodes = malloc(sizeof(int) * 8 * part_elements), next = 0;
    for (int e = 0; e < mesh.element_count; e++)
        if (meshfree[e]) for (int a = 0; a < 8; a++) part_nodes[next++] = mesh.hexahedra[8 * e + a];
    set_up_solids(mesh.coordinates, part_elements, part_nodes, &cells_of_part);
    double volume = 0, part_mass = 0;
    for (int g = 0; g < 8 * part_elements; g++) volume += cells_of_part.weight[g];
    for (int p = 0; p < model.part_node_count; p++) part_mass += model.part_mass[p];
    printf("counts %d %d %d %d\n", model.counts[0], model.counts[1], model.counts[2], model.counts[3]);
    printf("mass_error %.16e\n", fabs(part_mass - density * volume) / (density * volume));

    /* linear fields are reproduced: the generalized values of A X are A X */
    double *exact = malloc(sizeof(double) * 3 * mesh.node_count), *physical = malloc(sizeof(double) * 3 * mesh.node_count);
    for (int node = 0; node < mesh.node_count; node++)
        for (int i = 0; i < 3; i++) {
            exact[3 * node + i] = 0;
            for (int j = 0; j < 3; j++) exact[3 * node + i] += gradient[i][j] * mesh.coordinates[3 * node + j];
        }
    memcpy(model.velocity, exact, sizeof(double) * 3 * mesh.node_count);
    double stable_dt = compute_forces(&model, 0.0), previous_dt = 0;
    for (int cycle = 1; cycle <= 100; cycle++) {
        double dt = 0.9 * stable_dt;
        advance(&model, 0.5 * (previous_dt + dt));
        for (int node = 0; node < mesh.node_count; node++)
            for (int i = 0; i < 3; i++) {
                if (driven[node]) model.velocity[3 * node + i] = exact[3 * node + i];
                model.displacement[3 * node + i] += dt * model.velocity[3 * node + i];
            }
        stable_dt = compute_forces(&model, dt);
        previous_dt = dt;
    }
    physical_field(&model, model.velocity, physical);
    double error = 0, largest = 0;
    for (int k = 0; k < 3 * mesh.node_count; k++) {
        if (fabs(physical[k] - exact[k]) > error) error = fabs(physical[k] - exact[k]);
        if (fabs(exact[k]) > largest) largest = fabs(exact[k]);
    }
    printf("velocity_error %.16e\n", error / largest);
    check(&model, cf_efg_destroy(&model.part), "cf_efg_destroy");
}

static void coupled_bar(int host_law)
{
    const double duration = 0.004, end_time = 0.023, pi = 3.14159265358979323846;
    host_mesh mesh;
    host_model model;
    int cells[3] = {100, 2, 2};
    block_mesh(cells, 1.0, 0.0, 1, &mesh);
    int *meshfree = malloc(sizeof(int) * mesh.element_count);
    int *supported = calloc(mesh.node_count, sizeof(int)), *driven = calloc(mesh.node_count, sizeof(int));
    double *physical = malloc(sizeof(double) * 3 * mesh.node_count);
    for (int e = 0; e < mesh.element_count; e++) meshfree[e] = e % mesh.cells[0] >= 50;
    for (int k = 0; k <= 2; k++)
        for (int j = 0; j <= 2; j++) {
            supported[node_index(&mesh, 100, j, k) - 1] = 1;
            driven[node_index(&mesh, 0, j, k) - 1] = 1;
        }
    /* the supported nodes are the part's: marked as boundary nodes (nodal values) */
    set_up_model(&mesh, meshfree, supported, 0.0, 1.5, 0, host_law, &model);
    int incident_probe = node_index(&mesh, 20, 0, 0) - 1, transmitted_probe = node_index(&mesh, 75, 1, 1) - 1;
    printf("counts %d %d %d %d\n", model.counts[0], model.counts[1], model.counts[2], model.counts[3]);
    printf("wave_speed %.16e\n", sqrt(young / density));
    printf("probes_interface_pulse %.16e %.16e %.16e %.16e\n", 20.0, 75.0, 50.0, duration);
    double stable_dt = compute_forces(&model, 0.0), previous_dt = 0, time = 0;
    while (time < end_time) {
        double dt = 0.9 * stable_dt, pulse = 0;
        advance(&model, 0.5 * (previous_dt + dt));
        /* the velocity of the step from time to time + dt, at its middle */
        if (time + 0.5 * dt < duration) pulse = pow(sin(pi * (time + 0.5 * dt) / duration), 2);
        for (int node = 0; node < mesh.node_count; node++) {
            for (int i = 0; i < 3; i++) {
                if (supported[node]) model.velocity[3 * node + i] = 0;
                if (driven[node]) model.velocity[3 * node + i] = i == 0 ? pulse : 0;
                model.displacement[3 * node + i] += dt * model.velocity[3 * node + i];
            }
        }
        time += dt;
        stable_dt = compute_forces(&model, dt);
        previous_dt = dt;
        physical_field(&model, model.velocity, physical);
        printf("sample %.16e %.16e %.16e\n", time - 0.5 * dt, physical[3 * incident_probe], physical[3 * transmitted_probe]);
    }
    check(&model, cf_efg_destroy(&model.part), "cf_efg_destroy");
}

static void one_force_call(double step)
{
    host_mesh mesh;
    host_model model;
    int cells[3] = {5, 4, 4};
    block_mesh(cells, 1.0, 0.25, 7, &mesh);
    int *meshfree = malloc(sizeof(int) * mesh.element_count), *marked = calloc(mesh.node_count, sizeof(int));
    for (int e = 0; e < mesh.element_count; e++) meshfree[e] = 1;
    set_up_model(&mesh, meshfree, marked, 0.3, 1.5, 0, 0, &model);
    for (int k = 0; k <= cells[2]; k++)
        for (int j = 0; j <= cells[1]; j++)
            for (int i = 0; i <= cells[0]; i++) {
                if (!on_block_boundary(&mesh, i, j, k)) continue;
                int node = node_index(&mesh, i, j, k) - 1;
                double x = mesh.coordinates[3 * node], y = mesh.coordinates[3 * node + 1], z = mesh.coordinates[3 * node + 2];
                /* multiples of 1/1024 mm/ms: a keyword deck writes them exactly */
                model.velocity[3 * node] = round(1024.0 * (0.5 * (x * x - y * z))) / 1024.0;
                model.velocity[3 * node + 1] = round(1024.0 * (0.8 * x * z - 0.3 * y * y)) / 1024.0;
                model.velocity[3 * node + 2] = round(1024.0 * (0.6 * x * y + z)) / 1024.0;
            }
    double stable_dt = compute_forces(&model, 0.0);
    printf("counts %d %d %d %d\n", model.counts[0], model.counts[1], model.counts[2], model.counts[3]);
    printf("stable_dt %.16e\n", stable_dt);
    /* step 0: the mesh and the velocities only (to write the same part as a keyword deck) */
    if (step > 0) {
        for (int k = 0; k < 3 * mesh.node_count; k++) model.displacement[k] = step * model.velocity[k];
        compute_forces(&model, step);
    }
    double *acceleration = malloc(sizeof(double) * 3 * mesh.node_count), *physical = malloc(sizeof(double) * 3 * mesh.node_count);
    for (int k = 0; k < 3 * mesh.node_count; k++) acceleration[k] = -model.force[k] / model.mass[k / 3];
    physical_field(&model, acceleration, physical);
    for (int e = 0; e < mesh.element_count; e++) {
        printf("hexahedron %d", e + 1);
        for (int a = 0; a < 8; a++) printf(" %d", mesh.hexahedra[8 * e + a]);
        printf("\n");
    }
    for (int node = 0; node < mesh.node_count; node++) {
        const double *x = mesh.coordinates + 3 * node, *v = model.velocity + 3 * node, *f = model.force + 3 * node;
        const double *a = physical + 3 * node;
        printf("node %d %.16e %.16e %.16e %.16e %.16e %.16e %.16e %.16e %.16e %.16e %.16e %.16e %.16e\n", node + 1, x[0], x[1],
               x[2], v[0], v[1], v[2], model.mass[node], f[0], f[1], f[2], a[0], a[1], a[2]);
    }
    check(&model, cf_efg_destroy(&model.part), "cf_efg_destroy");
}

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void bench(int cells_per_side, int calls)
{
    host_mesh mesh;
    host_model model;
    int cells[3] = {cells_per_side, cells_per_side, cells_per_side};
    block_mesh(cells, 1.0, 0.1, 11, &mesh);
    int *meshfree = malloc(sizeof(int) * mesh.element_count), *marked = calloc(mesh.node_count, sizeof(int));
    double *seconds = malloc(sizeof(double) * calls), part_dt;
    for (int e = 0; e < mesh.element_count; e++) meshfree[e] = 1;
    set_up_model(&mesh, meshfree, marked, 0.3, 1.2, 0, 0, &model);
    for (int k = 0; k < 3 * mesh.node_count; k++) {
        model.part_displacement[k] = 1.0e-3 * sin(mesh.coordinates[k]);
        model.part_velocity[k] = 1.0e-1 * cos(mesh.coordinates[k]);
    }
    /* the first call builds the part's run-time state (blocks, their colours, stresses): untimed,
       as the solver builds it before its first cycle */
    check(&model, cf_efg_internal_force(model.part, model.part_displacement, model.part_velocity, 0.0, model.part_force,
                                        &part_dt),
          "cf_efg_internal_force");
    for (int c = 0; c < calls; c++) {
        struct timespec start, finish;
        memset(model.part_force, 0, sizeof(double) * 3 * mesh.node_count);
        clock_gettime(CLOCK_MONOTONIC, &start);
        int status = cf_efg_internal_force(model.part, model.part_displacement, model.part_velocity, 1.0e-5, model.part_force,
                                           &part_dt);
        clock_gettime(CLOCK_MONOTONIC, &finish);
        check(&model, status, "cf_efg_internal_force");
        seconds[c] = (double)(finish.tv_sec - start.tv_sec) + 1.0e-9 * (double)(finish.tv_nsec - start.tv_nsec);
    }
    double total = 0;
    for (int c = 0; c < calls; c++) total += seconds[c];
    qsort(seconds, calls, sizeof(double), compare_doubles);
    printf("integration_points %d\n", model.counts[3]);
    printf("ns_per_point_call %12.3f\n", 1.0e9 * seconds[(calls + 1) / 2 - 1] / model.counts[3]);
    printf("ns_per_point_call_mean %12.3f\n", 1.0e9 * total / calls / model.counts[3]);
    check(&model, cf_efg_destroy(&model.part), "cf_efg_destroy");
}

/* one misuse: its status and the library's message on one line */
static void report(const char *name, const cf_efg_part *part, int status)
{
    char message[512];
    cf_efg_last_error(part, message, sizeof message);
    printf("misuse %s %d %s\n", name, status, message);
}

/* calls a host code should not make, each answered with a status and a message (never a crash) */
static void misuse(void)
{
    host_mesh mesh;
    int cells[3] = {3, 3, 3};
    double support[3] = {1.5, 1.5, 1.5}, small[3] = {1.5, 1.0, 1.5}, force[3 * 64] = {0}, step;
    block_mesh(cells, 1.0, 0.0, 1, &mesh);
    int n = mesh.node_count, m = mesh.element_count;
    cf_efg_part *part = NULL;

    report("null_handle", NULL, cf_efg_set_up(NULL));
    report("null_coordinates", part, cf_efg_create(&part, n, NULL, m, mesh.hexahedra, support, 0, 1));
    cf_efg_destroy(&part);
    report("wrong_size", part, cf_efg_create(&part, -1, mesh.coordinates, m, mesh.hexahedra, support, 0, 1));
    cf_efg_destroy(&part);
    int *wrong = malloc(sizeof(int) * 8 * m);
    memcpy(wrong, mesh.hexahedra, sizeof(int) * 8 * m);
    wrong[8 * 16 + 2] = n + 7; /* hexahedra(3, 17) */
    report("node_out_of_range", part, cf_efg_create(&part, n, mesh.coordinates, m, wrong, support, 0, 1));
    cf_efg_destroy(&part);
    memcpy(wrong, mesh.hexahedra, sizeof(int) * 8 * m);
    for (int a = 0; a < 4; a++) { /* hexahedron 5 inside out: its two faces swapped */
        wrong[8 * 4 + a] = mesh.hexahedra[8 * 4 + a + 4];
        wrong[8 * 4 + a + 4] = mesh.hexahedra[8 * 4 + a];
    }
    report("inside_out", part, cf_efg_create(&part, n, mesh.coordinates, m, wrong, support, 0, 1));
    cf_efg_destroy(&part);
    report("support_not_above_one", part, cf_efg_create(&part, n, mesh.coordinates, m, mesh.hexahedra, small, 0, 1));
    cf_efg_destroy(&part);
    report("kernel", part, cf_efg_create(&part, n, mesh.coordinates, m, mesh.hexahedra, support, 1, 1));
    cf_efg_destroy(&part);
    cf_efg_create(&part, n, mesh.coordinates, m, mesh.hexahedra, support, 0, 1);
    report("create_on_live_handle", part, cf_efg_create(&part, n, mesh.coordinates, m, mesh.hexahedra, support, 0, 1));
    int outside = n + 1;
    report("mark_out_of_range", part, cf_efg_mark_boundary(part, 1, &outside));
    report("force_before_set_up", part, cf_efg_internal_force(part, force, force, 0.0, force, &step));
    cf_efg_set_up(part);
    report("set_up_twice", part, cf_efg_set_up(part));
    report("force_without_law", part, cf_efg_internal_force(part, force, force, 0.0, force, &step));
    report("elastic_poisson", part, cf_efg_set_elastic(part, 210.0, 0.5));
    report("null_force", part, cf_efg_internal_force(part, force, force, 0.0, NULL, &step));
    cf_efg_destroy(&part);
    report("destroyed_handle", part, cf_efg_set_up(part));
    report("destroy_twice", part, cf_efg_destroy(&part));
    free(wrong);
}

int main(int argc, char **argv)
{
    const char *mode = argc > 1 ? argv[1] : "";
    if (strcmp(mode, "patch") == 0)
        patch_test(argc > 2 ? atof(argv[2]) : 1.5, argc > 3 ? atoi(argv[3]) : 0, argc > 4 && strcmp(argv[4], "host-law") == 0);
    else if (strcmp(mode, "bar") == 0) coupled_bar(argc > 2 && strcmp(argv[2], "host-law") == 0);
    else if (strcmp(mode, "forces") == 0) one_force_call(argc > 2 ? strtod(argv[2], NULL) : 0.0);
    else if (strcmp(mode, "misuse") == 0) misuse();
    else if (strcmp(mode, "bench") == 0) bench(argc > 2 ? atoi(argv[2]) : 20, argc > 3 ? atoi(argv[3]) : 50);
    else {
        printf("usage: host_c patch [support kernel [host-law]] | bar [host-law] | forces DT | bench CELLS CALLS | misuse\n");
        return 2;
    }
    return 0;
}
