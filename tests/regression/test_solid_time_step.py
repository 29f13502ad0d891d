"""The stable time step of hexahedra against the eigenvalues of a single element.

1. For one free element (a cube, bricks, a parallelepiped, distorted shapes; ELFORM 1 with the
   viscous IHQ 1 and the stiffness IHQ 5, ELFORM 2; nu = 0, 0.3, 0.49), numpy builds the
   element's stiffness (and for the viscous hourglass form its damping) against its lumped
   masses as the solver does, and finds the largest step at which the central difference
   scheme stays stable for it: 2 / omega_max without damping, else by bisection on the
   spectral radius of the scheme's two-step matrix (the viscous forces use the velocity of the
   last half step). The solver's first step with TSSFAC 1 must be at or below it, and not far
   below (the bound is tight: 0.85 of it allowed).
2. One and two hexahedra with a node kicked at 1 mm/ms run 3,000 cycles at the default
   TSSFAC 0.9 and keep their energy. With LS-DYNA's rule L / c alone (L = V / largest face) a
   single element at nu = 0.3 went to a negative volume at cycle 10: its volumetric mode
   (every node out along its diagonal) has omega^2 = 4 (3 lambda + 2 mu) / (rho L^2), critical
   at 0.73 L / c.
3. Free meshes (cubes of 2^3, 4^3 and 8^3 elements, a distorted 4^3 with every node moved;
   nu = 0, 0.3, 0.49): numpy assembles the whole mesh's stiffness and lumped masses and takes
   2 / omega_max of it (dense eigvalsh); the solver's first step with TSSFAC 1 must be at or
   below it. Only the elements at the mesh's corners and edges get the eigenvalue bound, the
   others LS-DYNA's rule, which alone is up to 1.23 times the critical step of these meshes
   (their fastest modes sit at the corners). Kicked meshes (random nodal velocities) run
   3,000 cycles at TSSFAC 0.9 with the energy balanced (with the rule alone, those at
   nu = 0.49 invert an element within 27-33 cycles), and a mesh whose smallest step is inside
   keeps LS-DYNA's rule there (the bound on every element made it 0.99 of that for ELFORM 1,
   0.92 for ELFORM 2)."""
import numpy as np
import pytest

from deck_writer import block_mesh, fields, nodes_card, solids_card, write_deck

YOUNGS, DENSITY = 210.0, 7.85e-6           # steel, GPa kg/mm^3 (mm, ms)
HOURGLASS_COEFFICIENT = 0.1

# natural coordinates of LS-DYNA's node order and the hourglass base vectors
XI = np.array([-1, 1, 1, -1, -1, 1, 1, -1.0])
ETA = np.array([-1, -1, 1, 1, -1, -1, 1, 1.0])
ZETA = np.array([-1, -1, -1, -1, 1, 1, 1, 1.0])
HOURGLASS_BASE = np.stack([ETA * ZETA, ZETA * XI, XI * ETA, XI * ETA * ZETA], axis=1)
GAUSS = 1.0 / np.sqrt(3.0)


def lame(poisson):
    return YOUNGS * poisson / ((1 + poisson) * (1 - 2 * poisson)), YOUNGS / (2 * (1 + poisson))


def elasticity(lam, mu):
    """Voigt matrix with engineering shear strains."""
    matrix = np.zeros((6, 6))
    matrix[:3, :3] = lam
    matrix[range(3), range(3)] += 2 * mu
    matrix[range(3, 6), range(3, 6)] = mu
    return matrix


def strain_matrix(gradients):
    """6 x 24 matrix of the strain (engineering shear) from nodal displacements."""
    matrix = np.zeros((6, 24))
    for node, (gx, gy, gz) in enumerate(gradients):
        x, y, z = 3 * node, 3 * node + 1, 3 * node + 2
        matrix[0, x], matrix[1, y], matrix[2, z] = gx, gy, gz
        matrix[3, x], matrix[3, y] = gy, gx
        matrix[4, y], matrix[4, z] = gz, gy
        matrix[5, x], matrix[5, z] = gz, gx
    return matrix


def point_gradients(x, xi, eta, zeta):
    natural = np.stack([XI * (1 + ETA * eta) * (1 + ZETA * zeta), ETA * (1 + XI * xi) * (1 + ZETA * zeta),
                        ZETA * (1 + XI * xi) * (1 + ETA * eta)], axis=1) / 8
    jacobian = x.T @ natural
    return natural @ np.linalg.inv(jacobian), np.linalg.det(jacobian)


def gauss_points():
    return [(a, b, c) for a in (-GAUSS, GAUSS) for b in (-GAUSS, GAUSS) for c in (-GAUSS, GAUSS)]


def volume_derivatives(x):
    """Exact dV/dx_I (the 2x2x2 rule integrates the trilinear Jacobian exactly) and V."""
    derivatives, volume = np.zeros((8, 3)), 0.0
    for point in gauss_points():
        gradients, determinant = point_gradients(x, *point)
        derivatives += gradients * determinant
        volume += determinant
    return derivatives, volume


def per_direction(matrix8):
    """The 24 x 24 matrix acting alike on each direction."""
    full = np.zeros((24, 24))
    for direction in range(3):
        index = np.arange(8) * 3 + direction
        full[np.ix_(index, index)] = matrix8
    return full


def element_matrices(x, poisson, formulation, hourglass):
    """Stiffness, damping and lumped masses of one element as the solver builds them:
    ELFORM 1 (uniform strain with the exact volume derivatives) with IHQ 1 (viscous,
    a_h = QM rho c V^(2/3) / 4 on the base vectors) or IHQ 5 (stiffness QM (lambda + 2 mu)
    b.b / (3 V) on the Flanagan-Belytschko shape vectors); ELFORM 2 (deviatoric at the 2x2x2
    points, volumetric from the element mean)."""
    lam, mu = lame(poisson)
    derivatives, volume = volume_derivatives(x)
    damping = np.zeros((24, 24))
    if formulation == 1:
        strain = strain_matrix(derivatives / volume)
        stiffness = volume * strain.T @ elasticity(lam, mu) @ strain
        if hourglass == 5:
            gamma = HOURGLASS_BASE - derivatives @ (x.T @ HOURGLASS_BASE) / volume
            k = HOURGLASS_COEFFICIENT * (lam + 2 * mu) * np.sum(derivatives**2) / (3 * volume)
            stiffness += per_direction(k * gamma @ gamma.T)
        else:
            speed = np.sqrt((lam + 2 * mu) / DENSITY)
            viscosity = 0.25 * HOURGLASS_COEFFICIENT * DENSITY * speed * volume**(2 / 3)
            damping = per_direction(viscosity * HOURGLASS_BASE @ HOURGLASS_BASE.T)
    else:
        deviatoric = elasticity(-2 * mu / 3, mu)
        stiffness, mean = np.zeros((24, 24)), np.zeros(24)
        for point in gauss_points():
            gradients, determinant = point_gradients(x, *point)
            strain = strain_matrix(gradients)
            stiffness += determinant * strain.T @ deviatoric @ strain
            mean += determinant * strain[:3].sum(axis=0)
        stiffness += (lam + 2 * mu / 3) * np.outer(mean, mean) / volume
    return stiffness, damping, np.full(24, DENSITY * volume / 8)


def critical_step(stiffness, damping, masses):
    """Largest dt for which u(n+1) = (2 - dt^2 M^-1 K - dt M^-1 C) u(n) - (1 - dt M^-1 C) u(n-1)
    (damping on the velocity of the last half step) has no growing solution."""
    inverse = 1.0 / masses
    scaled = np.sqrt(inverse)[:, None] * stiffness * np.sqrt(inverse)[None, :]
    undamped = 2.0 / np.sqrt(np.linalg.eigvalsh(scaled).max())
    if not np.any(damping):
        return undamped
    a, c, n = inverse[:, None] * stiffness, inverse[:, None] * damping, len(masses)

    def growth(step):
        two_step = np.block([[2 * np.eye(n) - step**2 * a - step * c, -(np.eye(n) - step * c)],
                             [np.eye(n), np.zeros((n, n))]])
        return np.abs(np.linalg.eigvals(two_step)).max()

    low, high = 0.0, undamped
    for _ in range(50):
        middle = 0.5 * (low + high)
        # rigid and hourglass motions sit at |z| = 1 (double roots): round-off puts them at 1 +- 1e-8
        low, high = (middle, high) if growth(middle) <= 1 + 1e-6 else (low, middle)
    return low


CUBE = np.stack([XI, ETA, ZETA], axis=1) * 0.5


def shapes():
    rng = np.random.default_rng(7)
    yield "cube", CUBE
    yield "brick 1 x 1 x 4", CUBE * [1.0, 1.0, 4.0]
    yield "plate 1 x 1 x 0.25", CUBE * [1.0, 1.0, 0.25]
    yield "sheared", CUBE @ np.array([[1.0, 0.4, 0.0], [0.0, 1.0, 0.3], [0.0, 0.0, 1.0]])
    yield "distorted a", CUBE + rng.uniform(-0.15, 0.15, CUBE.shape)
    yield "distorted b", CUBE * [2.0, 1.0, 1.0] + rng.uniform(-0.2, 0.2, CUBE.shape)


def single_element_deck(path, x, poisson, formulation, hourglass, tssfac=1.0, cycles=1, kick=None):
    blocks = ["*CONTROL_TERMINATION\n" + fields(1.0e3, cycles),
              "*CONTROL_TIMESTEP\n" + fields(0.0, tssfac),
              "*DATABASE_GLSTAT\n" + fields(1.0e-9),
              "*PART\nelement\n" + fields(1, 1, 1, 0, 1),
              "*SECTION_SOLID\n" + fields(1, formulation),
              "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, poisson),
              "*HOURGLASS\n" + fields(1, hourglass, HOURGLASS_COEFFICIENT),
              "*NODE\n" + "\n".join(f"{k + 1},{float(p[0])!r},{float(p[1])!r},{float(p[2])!r}" for k, p in enumerate(x)),
              solids_card([list(range(8))])]
    if kick is not None:
        blocks.append("*INITIAL_VELOCITY_NODE\n" + fields(kick[0], *kick[1]))
    return write_deck(path, *blocks)


CASES = [(name, poisson, formulation, hourglass)
         for name, _ in shapes() for poisson in (0.0, 0.3, 0.49) for formulation, hourglass in ((1, 1), (1, 5), (2, 1))]


@pytest.mark.parametrize("name, poisson, formulation, hourglass", CASES)
def test_single_element_step_is_below_its_critical_step(tmp_path, run_deck, name, poisson, formulation, hourglass):
    x = dict(shapes())[name]
    critical = critical_step(*element_matrices(x, poisson, formulation, hourglass))
    run = run_deck(single_element_deck(tmp_path / "element.k", x, poisson, formulation, hourglass))
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        step = results["history/glstat/time_step"][0]
    assert step <= critical * (1 + 1e-9), f"step {step:.6e} above the critical {critical:.6e}"
    assert step >= 0.85 * critical, f"step {step:.6e} far below the critical {critical:.6e}"


@pytest.mark.parametrize("elements", [1, 2])
@pytest.mark.parametrize("formulation", [1, 2])
@pytest.mark.parametrize("poisson", [0.0, 0.3, 0.49])
def test_kicked_hexahedra_run_stably_at_the_default_tssfac(tmp_path, run_deck, elements, formulation, poisson):
    """One or two unit cubes (default IHQ 1, bulk viscosity on), the far corner node kicked at
    1 mm/ms, no *CONTROL_TIMESTEP (TSSFAC 0.9), 3,000 cycles: kinetic + internal + hourglass
    energy (bulk viscosity and hourglass work included) stays equal to the initial kinetic
    energy, and the elements really deform."""
    nodes, solids = block_mesh((elements, 1, 1), (float(elements), 1.0, 1.0))
    kicked = int(np.argmax(nodes.sum(axis=1))) + 1
    deck = write_deck(
        tmp_path / "kicked.k",
        "*CONTROL_TERMINATION\n" + fields(1.0e3, 3000),
        "*DATABASE_GLSTAT\n" + fields(1.0e-5),
        "*PART\nblock\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, formulation),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, poisson),
        nodes_card(nodes),
        solids_card(solids),
        "*INITIAL_VELOCITY_NODE\n" + fields(kicked, 1.0, 0.0, 0.0),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        assert results["run"].attrs["cycles"] == 3000
        glstat = {name: results["history/glstat"][name][...] for name in results["history/glstat"]}
    total = glstat["total_energy"]
    assert np.isfinite(total).all()
    assert np.abs(total - total[0]).max() < 1e-9 * total[0]
    assert glstat["internal_energy"].max() > 0.05 * total[0]


def mesh_matrices(nodes, elements, poisson, formulation, hourglass):
    """Assembled stiffness and lumped masses of a mesh (no damping: the stiffness forms only)."""
    stiffness, masses = np.zeros((3 * len(nodes), 3 * len(nodes))), np.zeros(3 * len(nodes))
    for corners in elements:
        element_stiffness, _, element_masses = element_matrices(nodes[corners], poisson, formulation, hourglass)
        index = (3 * corners[:, None] + np.arange(3)).ravel()
        stiffness[np.ix_(index, index)] += element_stiffness
        masses[index] += element_masses
    return stiffness, masses


def mesh_critical_step(nodes, elements, poisson, formulation, hourglass):
    """2 / omega_max of the free mesh's lumped-mass eigenproblem."""
    stiffness, masses = mesh_matrices(nodes, elements, poisson, formulation, hourglass)
    scale = 1.0 / np.sqrt(masses)
    return 2.0 / np.sqrt(np.linalg.eigvalsh(scale[:, None] * stiffness * scale[None, :])[-1])


def lsdyna_rule_steps(nodes, elements, poisson):
    """L / c of every element: L = V / largest face area (half the cross product of the face's
    diagonals), c = sqrt((lambda + 2 mu) / rho)."""
    lam, mu = lame(poisson)
    speed = np.sqrt((lam + 2 * mu) / DENSITY)
    faces = [[0, 1, 2, 3], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
    steps = []
    for corners in elements:
        x = nodes[corners]
        area = max(0.5 * np.linalg.norm(np.cross(x[f[2]] - x[f[0]], x[f[3]] - x[f[1]])) for f in faces)
        steps.append(volume_derivatives(x)[1] / area / speed)
    return np.array(steps)


def free_mesh(name):
    count = {"cube 2^3": 2, "cube 4^3": 4, "cube 8^3": 8, "distorted 4^3": 4}[name]
    nodes, elements = block_mesh((count,) * 3, (float(count),) * 3)
    if name.startswith("distorted"):
        nodes = nodes + np.random.default_rng(5).uniform(-0.15, 0.15, nodes.shape)
    return nodes, elements


def mesh_deck(path, nodes, elements, poisson, formulation, hourglass, tssfac, cycles, velocities=None):
    blocks = ["*CONTROL_TERMINATION\n" + fields(1.0e3, cycles),
              "*DATABASE_GLSTAT\n" + fields(1.0e-5),
              "*PART\nmesh\n" + fields(1, 1, 1, 0, 1),
              "*SECTION_SOLID\n" + fields(1, formulation),
              "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, poisson),
              "*HOURGLASS\n" + fields(1, hourglass, HOURGLASS_COEFFICIENT),
              "*NODE\n" + "\n".join(f"{k + 1},{float(p[0])!r},{float(p[1])!r},{float(p[2])!r}"
                                    for k, p in enumerate(nodes)),
              solids_card(elements)]
    if tssfac is not None:
        blocks.append("*CONTROL_TIMESTEP\n" + fields(0.0, tssfac))
    if velocities is not None:
        blocks.append("*INITIAL_VELOCITY_NODE\n" + "\n".join(
            f"{k + 1},{float(v[0])!r},{float(v[1])!r},{float(v[2])!r}" for k, v in enumerate(velocities)))
    return write_deck(path, *blocks)


MESH_CASES = [(name, poisson, formulation, hourglass)
              for name in ("cube 2^3", "cube 4^3", "cube 8^3", "distorted 4^3") for poisson in (0.0, 0.3, 0.49)
              for formulation, hourglass in ((1, 5), (2, 1)) if not (name == "cube 8^3" and formulation == 2)]


@pytest.mark.parametrize("name, poisson, formulation, hourglass", MESH_CASES)
def test_free_mesh_step_is_below_its_critical_step(tmp_path, run_deck, name, poisson, formulation, hourglass):
    """ELFORM 1 with the stiffness IHQ 5 (no damping: 2 / omega_max is the critical step) and
    ELFORM 2. LS-DYNA's rule alone gives 1.07-1.24 times the critical step of the cubes at
    nu = 0.3 and 0.49."""
    nodes, elements = free_mesh(name)
    critical = mesh_critical_step(nodes, elements, poisson, formulation, hourglass)
    run = run_deck(mesh_deck(tmp_path / "mesh.k", nodes, elements, poisson, formulation, hourglass, 1.0, 1))
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        step = results["history/glstat/time_step"][0]
    assert step <= critical * (1 + 1e-9), f"step {step:.6e} above the mesh's critical {critical:.6e}"
    assert step >= 0.6 * critical, f"step {step:.6e} far below the mesh's critical {critical:.6e}"


@pytest.mark.parametrize("formulation, hourglass", [(1, 1), (1, 5), (2, 1)])
@pytest.mark.parametrize("poisson", [0.0, 0.3, 0.49])
def test_kicked_mesh_runs_stably_at_the_default_tssfac(tmp_path, run_deck, poisson, formulation, hourglass):
    """A free 4^3 mesh with random nodal velocities (up to 1 mm/ms), bulk viscosity on, TSSFAC
    0.9: 3,000 cycles with kinetic + internal + hourglass energy equal to the initial kinetic
    energy (with LS-DYNA's rule alone, 1.10 times the critical step at nu = 0.49, an element
    inverts within 27-33 cycles)."""
    nodes, elements = block_mesh((4, 4, 4), (4.0, 4.0, 4.0))
    velocities = np.random.default_rng(3).uniform(-1.0, 1.0, nodes.shape)
    run = run_deck(mesh_deck(tmp_path / "kicked.k", nodes, elements, poisson, formulation, hourglass, None, 3000,
                             velocities))
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        assert results["run"].attrs["cycles"] == 3000
        total = results["history/glstat/total_energy"][...]
        internal = results["history/glstat/internal_energy"][...]
    assert np.isfinite(total).all()
    assert np.abs(total - total[0]).max() < 1e-9 * total[0]
    assert internal.max() > 0.05 * total[0]


@pytest.mark.parametrize("formulation, hourglass", [(1, 1), (2, 1)])
def test_mesh_interior_keeps_the_lsdyna_rule(tmp_path, run_deck, formulation, hourglass):
    """A 6^3 mesh whose interior nodes are moved by up to 0.2 of the cell (nu = 0.3): its
    smallest LS-DYNA step is inside, where the elements are held by their neighbours, and the
    solver's first step (TSSFAC 1) is that step, not the element bound below it."""
    nodes, elements = block_mesh((6, 6, 6), (6.0, 6.0, 6.0), perturbation=0.2, seed=4)
    rule = lsdyna_rule_steps(nodes, elements, 0.3)
    run = run_deck(mesh_deck(tmp_path / "interior.k", nodes, elements, 0.3, formulation, hourglass, 1.0, 1))
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        step = results["history/glstat/time_step"][0]
    assert step == pytest.approx(rule.min(), rel=1e-9)
