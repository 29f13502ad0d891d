"""Degenerate elements: tetrahedra, wedges and pyramids written as hexahedra with repeated nodes
(*ELEMENT_SOLID), and triangles written as shells with N4 = N3 or N4 blank (*ELEMENT_SHELL).

1. Mass: meshes of tetrahedra, wedges or pyramids carry rho V to 1e-12; each node of a lone
   tetrahedron a quarter of it (the row sum of the consistent mass), whichever of the two
   tetrahedron forms the deck uses; a pyramid's apex 1/4 and its base nodes 3/16.
2. Patch test: a linear velocity field on irregular meshes of tetrahedra, wedges, pyramids and
   wedges under tetrahedra is kept to 1e-10 at the interior nodes, with no hourglass energy
   (ELFORM 1 with IHQ 1 (tetrahedra only), 3, 4, 5; ELFORM 2), and no distortion warning.
3. Time step: a lone tetrahedron's first step at TSSFAC 1 against its exact critical step
   (numpy: the linear tetrahedron with lumped masses V / 4); a tetrahedral mesh's step at or
   below the critical step of the whole mesh and above half of it; a lone triangle's step
   against its exact membrane critical step.
4. Waves and energy: the elastic bar meshed with tetrahedra or wedges carries the wave front at
   sqrt(E / rho) within 2% (the hexahedron test's tolerance); kicked meshes of each shape
   (ELFORM 1 and 2) keep their energy; tetrahedra book no hourglass energy.
5. Shells: the membrane patch test on a mixed quadrilateral / triangle mesh (1e-10); the
   static deflection of a clamped strip of triangles against beam theory and the quadrilateral
   strip within 3%.
"""
import numpy as np
import pytest

from conftest import last_state
from deck_writer import (block_mesh, boundary_node_mask, fields, nodes_card, node_list_set, plate_mesh,
                         round_to_node_card, shells_card, solids_card, write_deck)

YOUNGS, POISSON, DENSITY = 210.0, 0.3, 7.85e-6   # steel, mm ms kg GPa

# the six tetrahedra of a hexahedron (its corners 0-7, split along the diagonal 0-6) and its
# two wedges (triangles 0-1-2 / 4-5-6 and 0-2-3 / 4-6-7)
KUHN = [(0, 1, 2, 6), (0, 2, 3, 6), (0, 3, 7, 6), (0, 7, 4, 6), (0, 4, 5, 6), (0, 5, 1, 6)]
WEDGES = [(0, 1, 2, 4, 5, 6), (0, 2, 3, 4, 6, 7)]


def signed_volume(x, tet):
    a, b, c, d = (x[i] for i in tet)
    return np.dot(b - a, np.cross(c - a, d - a)) / 6.0


def tetrahedra(nodes, hexes, form="N3"):
    """Each hexahedron as six tetrahedra, written N1 N2 N3 N3 N4 N4 N4 N4 (form "N3") or
    N1 N2 N3 N4 N4 N4 N4 N4 (form "N4")."""
    out = []
    for h in hexes:
        for t in KUHN:
            t = [h[i] for i in t]
            if signed_volume(nodes, t) < 0:
                t = [t[0], t[2], t[1], t[3]]
            out.append([t[0], t[1], t[2], t[2], t[3], t[3], t[3], t[3]] if form == "N3"
                       else [t[0], t[1], t[2], t[3], t[3], t[3], t[3], t[3]])
    return np.array(out, dtype=int)


def wedges(hexes):
    """Each hexahedron as two wedges N1 N2 N3 N3 N4 N5 N6 N6."""
    return np.array([[h[w[0]], h[w[1]], h[w[2]], h[w[2]], h[w[3]], h[w[4]], h[w[5]], h[w[5]]]
                     for h in hexes for w in WEDGES], dtype=int)


def pyramids(nodes, hexes):
    """Each hexahedron as six pyramids on its faces with a new apex node at its centre: the
    nodes with the centres appended, and the pyramids N1 N2 N3 N4 N5 N5 N5 N5 (the base
    counterclockwise seen from the apex)."""
    faces = [(0, 1, 2, 3), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    centres = np.array([nodes[h].mean(axis=0) for h in hexes])
    out = []
    for k, h in enumerate(hexes):
        apex = len(nodes) + k
        for face in faces:
            base = [h[i] for i in face]
            a, b, d = nodes[base[0]], nodes[base[1]], nodes[base[3]]
            if np.dot(np.cross(b - a, d - a), centres[k] - a) < 0:
                base = base[::-1]
            out.append(base + [apex] * 4)
    return np.vstack([nodes, centres]), np.array(out, dtype=int)


def degenerate_mesh(kind, counts, lengths, seed):
    """Nodes, degenerate elements and boundary nodes of a box with moved interior nodes:
    "tetrahedra", "wedges", or "mixed": wedges in the bottom layer of cells and tetrahedra
    above, which meet on the wedges' triangles (both split the cells' top and bottom faces along
    the same diagonal, so the mesh is conforming)."""
    nodes, hexes = block_mesh(counts, lengths, perturbation=0.2, seed=seed)
    nodes = round_to_node_card(nodes)
    if kind == "pyramids":
        boundary = np.flatnonzero(boundary_node_mask(nodes))
        nodes, elements = pyramids(nodes, hexes)
        return round_to_node_card(nodes), elements, boundary
    if kind == "tetrahedra":
        elements = tetrahedra(nodes, hexes)
    elif kind == "wedges":
        elements = wedges(hexes)
    else:
        bottom = np.arange(len(hexes)) % counts[2] == 0       # block_mesh runs k innermost
        elements = np.vstack([wedges(hexes[bottom]), tetrahedra(nodes, hexes[~bottom])])
    return nodes, elements, np.flatnonzero(boundary_node_mask(nodes))


def solid_part(element_formulation=1, hourglass_type=1):
    return ["*PART\nsolid\n" + fields(1, 1, 1, 0, 1),
            "*SECTION_SOLID\n" + fields(1, element_formulation),
            "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
            "*HOURGLASS\n" + fields(1, hourglass_type, 0.1)]


def initial_velocities(velocity):
    return "\n".join(["*INITIAL_VELOCITY_NODE+"] + [f"{k + 1:20d}{v[0]:20.13e}{v[1]:20.13e}{v[2]:20.13e}"
                                                      for k, v in enumerate(velocity)])


def glstat(results):
    return {name: results["history/glstat"][name][...] for name in results["history/glstat"]}


def lumped_tetrahedron_critical_step(x, poisson):
    """2 / omega_max of the linear tetrahedron with lumped masses rho V / 4 (free element)."""
    matrix = np.hstack([np.ones((4, 1)), x])
    gradients = np.linalg.inv(matrix)[1:].T
    volume = abs(np.linalg.det(matrix)) / 6.0
    lam = YOUNGS * poisson / ((1 + poisson) * (1 - 2 * poisson))
    mu = YOUNGS / (2 * (1 + poisson))
    elasticity = np.zeros((6, 6))
    elasticity[:3, :3] = lam
    elasticity[range(3), range(3)] += 2 * mu
    elasticity[range(3, 6), range(3, 6)] = mu
    strain = np.zeros((6, 12))
    for a, (gx, gy, gz) in enumerate(gradients):
        strain[0, 3 * a], strain[1, 3 * a + 1], strain[2, 3 * a + 2] = gx, gy, gz
        strain[3, 3 * a], strain[3, 3 * a + 1] = gy, gx
        strain[4, 3 * a + 1], strain[4, 3 * a + 2] = gz, gy
        strain[5, 3 * a], strain[5, 3 * a + 2] = gz, gx
    stiffness = volume * strain.T @ elasticity @ strain
    mass = DENSITY * volume / 4.0
    return 2.0 / np.sqrt(np.linalg.eigvalsh(stiffness / mass).max()), stiffness, volume


# ---------------------------------------------------------------------------------------------
# 1. mass

@pytest.mark.parametrize("form", ["N3", "N4"])
def test_lone_tetrahedron_lumps_a_quarter_of_its_mass_at_each_node(tmp_path, run_deck, form):
    x = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.3, 1.5, 0.0], [0.4, 0.5, 1.2]])
    element = [[0, 1, 2, 2, 3, 3, 3, 3]] if form == "N3" else [[0, 1, 2, 3, 3, 3, 3, 3]]
    volume = signed_volume(x, [0, 1, 2, 3])
    for node in range(4):
        velocity = np.zeros((4, 3))
        velocity[node, 0] = 1.0
        deck = write_deck(tmp_path / f"tet_{form}_{node}.k",
                          "*CONTROL_TERMINATION\n" + fields(0.0, 1),
                          "*DATABASE_GLSTAT\n" + fields(1.0e-9),
                          *solid_part(), nodes_card(x), solids_card(element), initial_velocities(velocity))
        run = run_deck(deck, jobid=f"n{node}")
        assert run.status == 0, run.stdout + run.stderr
        with run.open() as results:
            kinetic = glstat(results)["kinetic_energy"][0]
            connectivity = results["mesh/solids/connectivity"][0]
        assert abs(2.0 * kinetic / (DENSITY * volume / 4.0) - 1.0) < 1e-12, f"node {node + 1}"
        # the output shows the tetrahedron itself: N1 N2 N3 N3 N4 N4 N4 N4
        assert list(connectivity) == [1, 2, 3, 3, 4, 4, 4, 4]


def test_lone_pyramid_lumps_the_row_sums_of_its_mass(tmp_path, run_deck):
    """A square pyramid: rho V / 4 at the apex, 3 rho V / 16 at each base node."""
    x = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 2.0, 0.0], [0.0, 2.0, 0.0], [0.7, 1.2, 1.5]])
    volume = 4.0 * 1.5 / 3.0
    for node, share in [(0, 3 / 16), (2, 3 / 16), (4, 1 / 4)]:
        velocity = np.zeros((5, 3))
        velocity[node, 2] = 1.0
        deck = write_deck(tmp_path / f"pyramid_{node}.k",
                          "*CONTROL_TERMINATION\n" + fields(0.0, 1),
                          "*DATABASE_GLSTAT\n" + fields(1.0e-9),
                          *solid_part(), nodes_card(x), solids_card([[0, 1, 2, 3, 4, 4, 4, 4]]),
                          initial_velocities(velocity))
        run = run_deck(deck, jobid=f"n{node}")
        assert run.status == 0, run.stdout + run.stderr
        with run.open() as results:
            kinetic = glstat(results)["kinetic_energy"][0]
        assert abs(2.0 * kinetic / (DENSITY * volume * share) - 1.0) < 1e-12, f"node {node + 1}"


@pytest.mark.parametrize("kind", ["tetrahedra", "wedges", "pyramids"])
def test_mesh_of_tetrahedra_or_wedges_carries_rho_v(tmp_path, run_deck, kind):
    nodes, elements, _ = degenerate_mesh(kind, (3, 3, 3), (1.0, 2.0, 1.5), seed=5)
    velocity = np.tile([1.0, 0.0, 0.0], (len(nodes), 1))
    deck = write_deck(tmp_path / "mass.k",
                      "*CONTROL_TERMINATION\n" + fields(0.0, 1),
                      "*DATABASE_GLSTAT\n" + fields(1.0e-9),
                      *solid_part(), nodes_card(nodes), solids_card(elements), initial_velocities(velocity))
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        kinetic = glstat(results)["kinetic_energy"][0]
    assert abs(2.0 * kinetic / (DENSITY * 1.0 * 2.0 * 1.5) - 1.0) < 1e-12


# ---------------------------------------------------------------------------------------------
# 2. patch test

VELOCITY_GRADIENT = np.array([[0.010, 0.004, -0.002], [0.003, -0.006, 0.005], [-0.001, 0.002, 0.008]])


# IHQ 1's hourglass vectors are not orthogonal to linear fields on irregular shapes (as on
# hexahedra): it is tested on tetrahedra only, which have no hourglass modes
@pytest.mark.parametrize("kind, element_formulation, hourglass_type",
                         [("tetrahedra", 1, 1), ("tetrahedra", 1, 4), ("tetrahedra", 2, 1), ("wedges", 1, 3),
                          ("wedges", 1, 4), ("wedges", 2, 1), ("mixed", 1, 3), ("mixed", 1, 5), ("mixed", 2, 1),
                          ("pyramids", 1, 3), ("pyramids", 1, 4), ("pyramids", 2, 1)])
def test_patch_test_on_tetrahedra_and_wedges(tmp_path, run_deck, kind, element_formulation, hourglass_type):
    nodes, elements, boundary = degenerate_mesh(kind, (3, 3, 3), (1.0, 1.0, 1.0), seed=7)
    velocity = nodes @ VELOCITY_GRADIENT.T
    motion = ["*BOUNDARY_PRESCRIBED_MOTION_NODE+"]
    for k in boundary:
        for direction in range(3):
            value = velocity[k, direction]
            curve, scale = (1, value) if value != 0.0 else (2, 1.0)
            motion.append(f"{k + 1:20d}{direction + 1:20d}{0:20d}{curve:20d}{scale:20.13e}")
    deck = write_deck(tmp_path / "patch.k",
                      "*CONTROL_TERMINATION\n" + fields(1.0, 100),
                      "*CONTROL_TIMESTEP\n" + fields(0.0, 0.9),
                      "*DATABASE_GLSTAT\n" + fields(1.0e-6),
                      "*DATABASE_BINARY_D3PLOT\n" + fields(1.0),
                      *solid_part(element_formulation, hourglass_type),
                      "*DEFINE_CURVE\n" + fields(1) + "\n" + f"{0.0:20.6e}{1.0:20.6e}\n{10.0:20.6e}{1.0:20.6e}",
                      "*DEFINE_CURVE\n" + fields(2) + "\n" + f"{0.0:20.6e}{0.0:20.6e}\n{10.0:20.6e}{0.0:20.6e}",
                      nodes_card(nodes), solids_card(elements), initial_velocities(velocity), "\n".join(motion))
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    # the repeated nodes' collapsed corners are not folded corners (distortion check)
    assert "folded" not in run.stdout
    with run.open() as results:
        assert results["run"].attrs["cycles"] == 100
        final = last_state(results)["velocity"][...]
        energies = glstat(results)
        assert results["run"].attrs["worst_corner_jacobian_ratio"] > 0.0
    interior = np.setdiff1d(np.arange(len(nodes)), boundary)
    assert len(interior) == (8 + 27 if kind == "pyramids" else 8)
    error = np.abs(final[interior] - velocity[interior]).max() / np.abs(velocity).max()
    print(f"interior velocity error {error:.2e}, hourglass / internal "
          f"{abs(energies['hourglass_energy'][-1]) / energies['internal_energy'][-1]:.1e}")
    assert error < 1e-10, f"interior velocity error {error:.3e}"
    assert abs(energies["hourglass_energy"][-1]) <= 1e-10 * energies["internal_energy"][-1]
    assert energies["internal_energy"][-1] > 0.0


# ---------------------------------------------------------------------------------------------
# 3. time step

@pytest.mark.parametrize("element_formulation", [1, 2])
@pytest.mark.parametrize("poisson", [0.0, 0.3, 0.49])
def test_lone_tetrahedron_step_against_its_critical_step(tmp_path, run_deck, poisson, element_formulation):
    x = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.2, 0.9, 0.0], [0.3, 0.2, 0.8]])
    critical, _, _ = lumped_tetrahedron_critical_step(x, poisson)
    deck = write_deck(tmp_path / "tet.k",
                      "*CONTROL_TERMINATION\n" + fields(0.0, 1),
                      "*CONTROL_TIMESTEP\n" + fields(0.0, 1.0),
                      "*DATABASE_GLSTAT\n" + fields(1.0e-9),
                      "*PART\nsolid\n" + fields(1, 1, 1),
                      "*SECTION_SOLID\n" + fields(1, element_formulation),
                      "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, poisson),
                      nodes_card(x), solids_card([[0, 1, 2, 2, 3, 3, 3, 3]]))
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        step = glstat(results)["time_step"][0]
    # at or below the critical step, and the bound is tight (LS-DYNA's rule alone, the
    # smallest altitude over c, is 1.15-1.40 times the critical step of a lone tetrahedron)
    print(f"step / critical {step / critical:.4f}")
    assert 0.85 * critical <= step <= critical, f"step {step:.5g}, critical {critical:.5g}"


def test_tetrahedral_mesh_step_against_the_mesh_critical_step(tmp_path, run_deck):
    """Free 3 x 3 x 3 cube of 162 tetrahedra (irregular): numpy assembles the mesh's stiffness
    and lumped masses; the first step at TSSFAC 1 is at or below 2 / omega_max and above 0.45 of
    it (0.52 measured: the smallest altitude of the flattest tetrahedron sets it, as in LS-DYNA;
    the old V / largest face rule, a third of the altitude, gave 0.24)."""
    nodes, hexes = block_mesh((3, 3, 3), (1.0, 1.0, 1.0), perturbation=0.2, seed=7)
    nodes = round_to_node_card(nodes)
    elements = tetrahedra(nodes, hexes)
    stiffness = np.zeros((3 * len(nodes), 3 * len(nodes)))
    mass = np.zeros(len(nodes))
    for element in elements:
        tet = element[[0, 1, 2, 4]]
        _, k, volume = lumped_tetrahedron_critical_step(nodes[tet], POISSON)
        dofs = (3 * tet[:, None] + np.arange(3)).ravel()
        stiffness[np.ix_(dofs, dofs)] += k
        mass[tet] += DENSITY * volume / 4.0
    scale = 1.0 / np.sqrt(np.repeat(mass, 3))
    critical = 2.0 / np.sqrt(np.linalg.eigvalsh(stiffness * np.outer(scale, scale)).max())
    deck = write_deck(tmp_path / "tets.k",
                      "*CONTROL_TERMINATION\n" + fields(0.0, 1),
                      "*CONTROL_TIMESTEP\n" + fields(0.0, 1.0),
                      "*DATABASE_GLSTAT\n" + fields(1.0e-9),
                      *solid_part(), nodes_card(nodes), solids_card(elements))
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        step = glstat(results)["time_step"][0]
    print(f"step / mesh critical {step / critical:.4f}")
    assert 0.45 * critical < step <= critical, f"step {step:.5g}, mesh critical {critical:.5g}"


@pytest.mark.parametrize("kind, element_formulation, hourglass_type",
                         [("tetrahedra", 1, 1), ("tetrahedra", 2, 1), ("wedges", 1, 1), ("wedges", 1, 5),
                          ("wedges", 2, 1), ("mixed", 1, 4), ("pyramids", 1, 4), ("pyramids", 2, 1)])
def test_kicked_degenerate_mesh_keeps_its_energy(tmp_path, run_deck, kind, element_formulation, hourglass_type):
    """Random nodal velocities on a free irregular mesh, 3,000 cycles at TSSFAC 0.9: stable,
    the energy balanced; tetrahedra book no hourglass energy."""
    nodes, elements, _ = degenerate_mesh(kind, (3, 3, 3), (1.0, 1.0, 1.0), seed=7)
    velocity = np.random.default_rng(3).uniform(-1.0, 1.0, nodes.shape)
    deck = write_deck(tmp_path / "kick.k",
                      "*CONTROL_TERMINATION\n" + fields(0.0, 3000),
                      "*CONTROL_TIMESTEP\n" + fields(0.0, 0.9),
                      "*DATABASE_GLSTAT\n" + fields(1.0e-4),
                      *solid_part(element_formulation, hourglass_type), nodes_card(nodes), solids_card(elements),
                      initial_velocities(velocity))
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        assert results["run"].attrs["cycles"] == 3000
        energies = glstat(results)
    total = energies["total_energy"]
    print(f"energy drift {np.abs(total - total[0]).max() / total[0]:.1e}, "
          f"hourglass / initial {energies['hourglass_energy'].max() / total[0]:.2e}")
    assert np.abs(total - total[0]).max() < 1e-6 * total[0]
    if kind == "tetrahedra":
        assert energies["hourglass_energy"].max() == 0.0
    assert energies["internal_energy"].max() > 0.1 * total[0]


@pytest.mark.parametrize("kind", ["tetrahedra", "wedges"])
def test_wave_front_in_a_bar_of_tetrahedra_or_wedges(tmp_path, run_deck, kind):
    length, speed = 100.0, 1.0
    nodes, hexes = block_mesh((200, 1, 1), (length, 1.0, 1.0))
    elements = tetrahedra(nodes, hexes) if kind == "tetrahedra" else wedges(hexes)
    loaded = np.flatnonzero(np.abs(nodes[:, 0]) < 1e-9) + 1
    far_end = int(np.flatnonzero(np.abs(nodes[:, 0] - length) < 1e-9)[0]) + 1
    deck = write_deck(tmp_path / "bar.k",
                      "*CONTROL_TERMINATION\n" + fields(0.03),
                      "*DATABASE_NODOUT\n" + fields(1.0e-6),
                      "*DATABASE_HISTORY_NODE\n" + fields(far_end),
                      "*PART\nbar\n" + fields(1, 1, 1),
                      "*SECTION_SOLID\n" + fields(1, 1),
                      "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, 0.0),
                      "*DEFINE_CURVE\n" + fields(1) + "\n" + f"{0.0:20.6e}{1.0:20.6e}\n{1.0:20.6e}{1.0:20.6e}",
                      node_list_set(1, list(loaded)),
                      "*BOUNDARY_PRESCRIBED_MOTION_SET\n" + fields(1, 1, 0, 1, speed),
                      nodes_card(nodes), solids_card(elements))
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        history = results[f"history/nodout/{far_end}"]
        time = history["time"][...]
        velocity = history["velocity"][:, 0]
    crossing = np.flatnonzero(velocity >= speed)[0]
    t0, t1 = time[crossing - 1], time[crossing]
    v0, v1 = velocity[crossing - 1], velocity[crossing]
    arrival = t0 + (speed - v0) * (t1 - t0) / (v1 - v0)
    expected = length / np.sqrt(YOUNGS / DENSITY)
    print(f"arrival / (L / c) {arrival / expected:.4f}")
    assert abs(arrival - expected) / expected < 0.02, f"arrival {arrival:.6g} ms, L/c {expected:.6g} ms"


# ---------------------------------------------------------------------------------------------
# shells

def shell_part(thickness, shear_factor=1.0, points=3, hourglass=4):
    return ["*PART\nsheet\n" + fields(1, 1, 1, 0, 1),
            "*SECTION_SHELL\n" + fields(1, 2, shear_factor, points) + "\n" + fields(*[thickness] * 4),
            "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
            "*HOURGLASS\n" + fields(1, hourglass, 0.1)]


def split_quads(shells, every=1, blank_n4=True):
    """Quadrilaterals of even index (every = 2) or all (every = 1) split into two triangles
    along their 1-3 diagonal; N4 is left blank (written 0) or repeats N3."""
    out = []
    for k, (a, b, c, d) in enumerate(shells):
        if k % every:
            out.append([a, b, c, d])
        else:
            out.append([a, b, c, -1 if blank_n4 else c])
            out.append([a, c, d, d])
    return out


def shell_card(shells):
    lines = ["*ELEMENT_SHELL"]
    for k, corners in enumerate(shells):
        lines.append(f"{k + 1:8d}{1:8d}" + "".join(f"{c + 1 if c >= 0 else 0:8d}" for c in corners))
    return "\n".join(lines)


def test_lone_triangle_step_against_its_critical_step(tmp_path, run_deck):
    """The in-plane critical step of a lone constant-strain triangle with masses rho t A / 3
    (numpy): the first step at TSSFAC 1 is at or below it and above 0.85 of it."""
    x = np.array([[0.0, 0.0], [10.0, 0.0], [3.0, 8.0]])
    thickness = 1.0
    (ax, ay), (bx, by) = x[1] - x[0], x[2] - x[0]
    area = 0.5 * (ax * by - ay * bx)
    b = np.array([x[1, 1] - x[2, 1], x[2, 1] - x[0, 1], x[0, 1] - x[1, 1]]) / (2 * area)
    c = np.array([x[2, 0] - x[1, 0], x[0, 0] - x[2, 0], x[1, 0] - x[0, 0]]) / (2 * area)
    strain = np.zeros((3, 6))
    strain[0, 0::2], strain[1, 1::2], strain[2, 0::2], strain[2, 1::2] = b, c, c, b
    plane = YOUNGS / (1 - POISSON**2) * np.array([[1, POISSON, 0], [POISSON, 1, 0], [0, 0, (1 - POISSON) / 2]])
    stiffness = thickness * area * strain.T @ plane @ strain
    critical = 2.0 / np.sqrt(np.linalg.eigvalsh(stiffness / (DENSITY * thickness * area / 3)).max())
    nodes = np.hstack([x, np.zeros((3, 1))])
    deck = write_deck(tmp_path / "triangle.k",
                      "*CONTROL_TERMINATION\n" + fields(0.0, 1),
                      "*CONTROL_TIMESTEP\n" + fields(0.0, 1.0),
                      "*DATABASE_GLSTAT\n" + fields(1.0e-9),
                      *shell_part(thickness, 5 / 6), nodes_card(nodes), shell_card([[0, 1, 2, -1]]))
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        step = glstat(results)["time_step"][0]
    print(f"step / critical {step / critical:.4f}")
    assert 0.85 * critical <= step <= critical, f"step {step:.5g}, critical {critical:.5g}"


MEMBRANE_GRADIENT = np.array([[0.010, 0.004], [-0.003, -0.006]])


def test_membrane_patch_test_on_a_mixed_quadrilateral_triangle_mesh(tmp_path, run_deck):
    flat, quads = plate_mesh((4, 4), (1.0, 1.0), perturbation=0.25, seed=3)
    shells = split_quads(quads, every=2, blank_n4=True)
    velocity = np.hstack([flat[:, :2] @ MEMBRANE_GRADIENT.T, np.zeros((len(flat), 1))])
    boundary = np.flatnonzero(np.isclose(flat[:, 0], 0) | np.isclose(flat[:, 0], 1) |
                              np.isclose(flat[:, 1], 0) | np.isclose(flat[:, 1], 1))
    motion = ["*BOUNDARY_PRESCRIBED_MOTION_NODE+"]
    for k in boundary:
        for direction in range(3):
            value = velocity[k, direction]
            curve, scale = (1, value) if value != 0.0 else (2, 1.0)
            motion.append(f"{k + 1:20d}{direction + 1:20d}{0:20d}{curve:20d}{scale:20.13e}")
    deck = write_deck(tmp_path / "membrane.k",
                      "*CONTROL_TERMINATION\n" + fields(1.0, 100),
                      "*CONTROL_TIMESTEP\n" + fields(0.0, 0.9),
                      "*DATABASE_GLSTAT\n" + fields(1.0e-4),
                      "*DATABASE_BINARY_D3PLOT\n" + fields(1.0),
                      *shell_part(0.05),
                      "*DEFINE_CURVE\n" + fields(1) + "\n" + f"{0.0:20.6e}{1.0:20.6e}\n{10.0:20.6e}{1.0:20.6e}",
                      "*DEFINE_CURVE\n" + fields(2) + "\n" + f"{0.0:20.6e}{0.0:20.6e}\n{10.0:20.6e}{0.0:20.6e}",
                      "*NODE\n" + "\n".join(f"{k + 1},{float(p[0])!r},{float(p[1])!r},0.0" for k, p in enumerate(flat)),
                      shell_card(shells), initial_velocities(velocity), "\n".join(motion))
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        assert results["run"].attrs["cycles"] == 100
        state = last_state(results)
        final = state["velocity"][...]
        stress = state["shell_stress"][...]
        energies = glstat(results)
    interior = np.setdiff1d(np.arange(len(flat)), boundary)
    error = np.abs(final[interior] - velocity[interior]).max() / np.abs(velocity).max()
    print(f"membrane interior velocity error {error:.2e}")
    assert error < 1e-10, f"interior velocity error {error:.3e}"
    assert abs(energies["hourglass_energy"][-1]) <= 1e-10 * energies["internal_energy"][-1]
    # every element, quadrilateral or triangle, carries the same stress
    assert np.abs(stress - stress.mean(axis=0)).max() < 1e-8 * np.abs(stress).max()


LENGTH, WIDTH, THICKNESS, TIP_LOAD = 100.0, 10.0, 1.0, 1.0e-4


def strip_tip_deflection(tmp_path, run_deck, triangles):
    """Clamped strip (20 x 2 cells) under a constant tip load from t = 0: the mean tip deflection
    over whole periods of its swing is the static deflection."""
    nodes, quads = plate_mesh((20, 2), (LENGTH, WIDTH))
    nodes = round_to_node_card(nodes)
    shells = split_quads(quads, blank_n4=False) if triangles else [list(q) for q in quads]
    root = np.flatnonzero(np.isclose(nodes[:, 0], 0.0))
    tip = np.flatnonzero(np.isclose(nodes[:, 0], LENGTH))
    middle = tip[np.argmin(np.abs(nodes[tip, 1] - WIDTH / 2))]
    loads = ["*LOAD_NODE_POINT"]
    for k in tip:
        share = 0.5 if np.isclose(nodes[k, 1], 0.0) or np.isclose(nodes[k, 1], WIDTH) else 1.0
        loads.append(fields(k + 1, 3, 1, f"{TIP_LOAD * share / 2:10.4e}"))
    deck = write_deck(tmp_path / f"strip_{triangles}.k",
                      "*CONTROL_TERMINATION\n" + fields(40.0),
                      "*CONTROL_TIMESTEP\n" + fields(0.0, 0.9),
                      "*DATABASE_GLSTAT\n" + fields(0.05),
                      "*DATABASE_NODOUT\n" + fields(0.05),
                      "*DATABASE_HISTORY_NODE\n" + fields(middle + 1),
                      *shell_part(THICKNESS, f"{5 / 6:10.7f}", 3, 1),
                      "*DEFINE_CURVE\n" + fields(1) + "\n" + f"{0.0:20.6e}{1.0:20.6e}\n{1000.0:20.6e}{1.0:20.6e}",
                      nodes_card(nodes), shell_card(shells),
                      "\n".join(["*BOUNDARY_SPC_NODE"] + [fields(k + 1, 0, 1, 1, 1, 1, 1, 1) for k in root]),
                      "\n".join(loads))
    run = run_deck(deck, jobid=f"strip{int(triangles)}")
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        node = next(iter(results["history/nodout"]))
        time = results["history/nodout"][node]["time"][...]
        deflection = results["history/nodout"][node]["displacement"][:, 2]
        energies = glstat(results)
    above = deflection > deflection.mean()
    crossings = time[1:][~above[:-1] & above[1:]]
    assert len(crossings) >= 3
    window = (time >= crossings[0]) & (time < crossings[-1])
    imbalance = energies["total_energy"] - energies["total_energy"][0] - energies["external_work"]
    return deflection[window].mean(), np.abs(imbalance).max() / energies["external_work"].max()


def test_triangle_strip_deflection_against_beam_theory_and_quadrilaterals(tmp_path, run_deck):
    beam = TIP_LOAD * LENGTH**3 / (3.0 * YOUNGS * WIDTH * THICKNESS**3 / 12.0)
    triangles, triangle_imbalance = strip_tip_deflection(tmp_path, run_deck, True)
    quads, _ = strip_tip_deflection(tmp_path, run_deck, False)
    print(f"tip deflection: triangles {triangles:.6f}, quadrilaterals {quads:.6f}, beam {beam:.6f}; "
          f"energy imbalance {triangle_imbalance:.2e}")
    assert abs(triangles / beam - 1.0) < 0.03, f"triangles {triangles:.5f}, beam {beam:.5f}"
    assert abs(triangles / quads - 1.0) < 0.03, f"triangles {triangles:.5f}, quadrilaterals {quads:.5f}"
    assert triangle_imbalance < 1e-5
