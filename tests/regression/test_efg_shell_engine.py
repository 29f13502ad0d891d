"""Meshfree (EFG) shells in the engine (*SECTION_SHELL ELFORM 41; efg_shell_forces,
efg_shell_group): a plate under uniform in-plane stretch carries the analytical stress; 1, 2 and
3 threads give identical results; a restart continues bit-identically; a plate thrown at a free
rigid plate through contact keeps the total momentum; a free vibration keeps its energy."""
import numpy as np

from conftest import last_state
from deck_writer import fields, nodes_card, plate_mesh, round_to_node_card, shells_card, write_deck

# mm, ms, kg, kN, GPa
THICKNESS, YOUNGS, POISSON, DENSITY = 1.0, 210.0, 0.3, 7.85e-6
SIDE = 40.0


def efg_section(section_id=1, support=1.5, points=3):
    return ("*SECTION_SHELL\n" + fields(section_id, 41, f"{5 / 6:10.7f}", points) + "\n" +
            fields(THICKNESS, THICKNESS, THICKNESS, THICKNESS) + "\n" + fields(float(support), float(support), 0, 0))


def initial_velocity_card(velocity, first_id=1):
    return "\n".join(["*INITIAL_VELOCITY_NODE+"] + [f"{k + first_id:20d}{v[0]:20.13e}{v[1]:20.13e}{v[2]:20.13e}"
                                                      for k, v in enumerate(velocity)])


def glstat_of(results):
    return {name: results["history/glstat"][name][...] for name in results["history/glstat"]}


def stretch_deck(path, cells=(8, 8), strain_rate=0.01, end_time=0.1, support=1.5):
    """A free irregular EFG plate in uniaxial stress: the ends x = 0 and x = L move at
    -/+ strain_rate L / 2 along x (prescribed), every node starts with the uniaxial velocity
    field (v_x = rate (x - L/2), v_y = -nu rate (y - L/2)), so the state stays uniform."""
    nodes, shells = plate_mesh(cells, (SIDE, SIDE), perturbation=0.2, seed=4)
    nodes = round_to_node_card(nodes)
    centred = nodes - [SIDE / 2, SIDE / 2, 0.0]
    velocity = np.stack([strain_rate * centred[:, 0], -POISSON * strain_rate * centred[:, 1],
                         np.zeros(len(nodes))], axis=1)
    ends = np.flatnonzero(np.isclose(nodes[:, 0], 0.0) | np.isclose(nodes[:, 0], SIDE))
    motion = ["*BOUNDARY_PRESCRIBED_MOTION_NODE+"]
    for k in ends:
        motion.append(f"{k + 1:20d}{1:20d}{0:20d}{1:20d}{velocity[k, 0]:20.13e}")
    return write_deck(
        path,
        "*TITLE\nmeshfree shell stretch",
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*CONTROL_TIMESTEP\n" + fields(0.0, 0.9),
        "*DATABASE_GLSTAT\n" + fields(end_time / 50),
        "*DATABASE_BINARY_D3PLOT\n" + fields(end_time / 2),
        "*PART\nmeshfree plate\n" + fields(1, 1, 1),
        efg_section(support=support),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + f"{0.0:20.6e}{1.0:20.6e}\n{1000.0:20.6e}{1.0:20.6e}",
        nodes_card(nodes),
        shells_card(shells),
        initial_velocity_card(velocity),
        "\n".join(motion),
    )


def test_uniform_stretch_gives_the_analytical_stress(tmp_path, run_deck):
    rate, end_time = 0.01, 0.1
    run = run_deck(stretch_deck(tmp_path / "stretch.k", strain_rate=rate, end_time=end_time))
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        stress = last_state(results)["shell_stress"][...]
        time = last_state(results).attrs["time"]
        assert results["timing"].attrs["efg_shell_cells"] == 64
        assert results["timing"].attrs["efg_shell_particles"] > 0
    # Cauchy stress of the stretch: the hypoelastic rate form integrates d = rate / (1 + rate t)
    strain = np.log(1.0 + rate * time)
    expected = YOUNGS * strain
    assert np.abs(stress[:, 0] / expected - 1.0).max() < 1e-3, stress[:, 0] / expected
    assert np.abs(stress[:, 1:]).max() < 1e-6 * expected


def vibration_deck(path, cells=(8, 8), end_time=2.0, support=1.5, scale=0.9, checker=0.0, points=3):
    """A free irregular EFG plate set vibrating: out-of-plane velocity of its first free-free
    shapes (and, with `checker`, a checkerboard of nodal velocities, the pattern one-point
    shear cannot see), some in-plane motion; no support."""
    nodes, shells = plate_mesh(cells, (SIDE, SIDE), perturbation=0.2, seed=7)
    nodes = round_to_node_card(nodes)
    x, y = nodes[:, 0] / SIDE - 0.5, nodes[:, 1] / SIDE - 0.5
    grid = np.round(nodes[:, :2] / (SIDE / np.array(cells))).astype(int)
    sign = np.where((grid[:, 0] + grid[:, 1]) % 2 == 0, 1.0, -1.0)
    velocity = np.stack([0.5 * np.sin(np.pi * y), 0.3 * x, 1.0 * (x * x - y * y) + checker * sign], axis=1)
    return write_deck(
        path,
        "*TITLE\nmeshfree shell free vibration",
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*CONTROL_TIMESTEP\n" + fields(0.0, scale),
        "*DATABASE_GLSTAT\n" + fields(end_time / 200),
        "*DATABASE_BINARY_D3PLOT\n" + fields(end_time / 4),
        "*PART\nmeshfree plate\n" + fields(1, 1, 1),
        efg_section(support=support, points=points),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
        nodes_card(nodes),
        shells_card(shells),
        initial_velocity_card(velocity),
    )


def test_free_vibration_keeps_its_energy_and_resists_the_checkerboard(tmp_path, run_deck):
    """2 ms of free vibration (some 3,500 cycles, several periods of the first free-free modes):
    total energy within 1% of the initial (measured 9e-9); the checkerboard of out-of-plane
    velocities, which a one-point shear alone would not resist, turns into strain energy."""
    run = run_deck(vibration_deck(tmp_path / "vibration.k", checker=0.3))
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        glstat = glstat_of(results)
        assert results["run"].attrs["cycles"] > 3000
    total, kinetic = glstat["total_energy"], glstat["kinetic_energy"]
    assert np.abs(total / total[0] - 1.0).max() < 0.01
    assert kinetic.min() < 0.5 * kinetic[0] and glstat["internal_energy"].max() > 0.4 * kinetic[0]
    assert np.abs(glstat["hourglass_energy"]).max() == 0.0


def test_one_two_and_three_threads_give_identical_results(tmp_path, run_deck):
    from test_threads import datasets
    deck = vibration_deck(tmp_path / "threads.k", cells=(12, 12), end_time=0.2, checker=0.3)
    runs = [run_deck(deck, ncpu=n) for n in (1, 2, 3)]
    assert all(run.status == 0 for run in runs), [run.stderr for run in runs]
    with runs[0].open() as first:
        reference = datasets(first)
    for run in runs[1:]:
        with run.open() as other:
            found = datasets(other)
        assert found.keys() == reference.keys()
        for name in reference:
            assert np.array_equal(reference[name], found[name]), f"{name} differs"


def test_restart_continues_bit_identically(tmp_path):
    from test_restart import contents, run_fresh, restart, copy_run
    deck = vibration_deck(tmp_path / "restart.k", end_time=0.3, checker=0.3)
    deck.write_text(deck.read_text().replace("*MAT_ELASTIC", "*DATABASE_BINARY_D3DUMP\n" + fields(400) +
                                             "\n*MAT_ELASTIC"))
    run_fresh(deck, tmp_path / "one")
    reference = contents(tmp_path / "one" / "results.h5")
    dumps = sorted((tmp_path / "one").glob("d3dump*"))
    assert dumps, "no restart dump written"
    target = copy_run(tmp_path / "one", tmp_path / "again")
    process = restart(target / dumps[0].name, 2)
    assert process.returncode == 0, process.stdout + process.stderr
    found = contents(target / "results.h5")
    assert found.keys() == reference.keys()
    for name in reference:
        assert np.array_equal(reference[name], found[name]), f"{name} differs after the restart"


def drop_deck(path, speed=3.0, end_time=0.4):
    """The EFG plate (40 x 40 mm, 8 x 8 cells, 2 mm) falls flat at `speed` onto a free rigid
    plate (60 x 60 mm, 6 x 6 FE shells, 2 mm, *MAT_RIGID, nothing held);
    *CONTACT_AUTOMATIC_NODES_TO_SURFACE with the EFG plate's nodes (a node set: most of them
    interior particles) as the secondary side, so the contact acts on physical positions. The
    nodes start 0.5 mm above the rigid plate's contact surface (its half thickness, 1 mm, above
    its mid-surface: a node set carries no thickness)."""
    thickness = 2.0
    nodes, shells = plate_mesh((8, 8), (SIDE, SIDE), perturbation=0.2, seed=9)
    nodes = round_to_node_card(nodes + [10.0, 10.0, 0.5 * thickness + 0.5])
    base_nodes, base_shells = plate_mesh((6, 6), (60.0, 60.0))
    count = len(nodes)
    return write_deck(
        path,
        "*TITLE\nmeshfree plate dropped on a free rigid plate",
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_GLSTAT\n" + fields(end_time / 200),
        "*DATABASE_RCFORC\n" + fields(end_time / 200),
        "*DATABASE_BINARY_D3PLOT\n" + fields(end_time / 4),
        "*PART\nmeshfree plate\n" + fields(1, 1, 1),
        "*SECTION_SHELL\n" + fields(1, 41, f"{5 / 6:10.7f}", 3) + "\n" + fields(thickness, thickness, thickness,
                                                                             thickness) + "\n" + fields(1.5, 1.5),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
        "*PART\nrigid plate\n" + fields(2, 2, 2),
        "*SECTION_SHELL\n" + fields(2, 2, 1.0, 2) + "\n" + fields(thickness, thickness, thickness, thickness),
        "*MAT_RIGID\n" + fields(2, DENSITY, YOUNGS, POISSON) + "\n" + fields(0.0, 0.0, 0.0) + "\n" + fields(0.0),
        "*CONTACT_AUTOMATIC_NODES_TO_SURFACE_ID\n" + fields(5) + "drop\n" + fields(1, 2, 4, 3) + "\n" +
        fields(0.0) + "\n" + fields(0.1, 0.1),
        "*SET_NODE_LIST_GENERATE\n" + fields(1) + "\n" + fields(1, count),
        nodes_card(np.vstack([nodes, base_nodes])),
        shells_card(shells, part_id=1) + "\n" +
        "\n".join(shells_card(base_shells, part_id=2, first_id=len(shells) + 1,
                              first_node_id=count + 1).splitlines()[1:]),
        "*INITIAL_VELOCITY\n" + fields(1) + "\n" + fields(0.0, 0.0, -speed),
    )


def test_drop_on_a_free_rigid_plate_keeps_the_momentum(tmp_path, run_deck):
    """Contact between the EFG plate's particles (physical positions, A^T f) and a free rigid
    plate: the total momentum stays at its initial value (1e-9 relative; measured 1e-15) and
    the total energy within 1e-5 (measured 1.5e-6), and the rigid plate moves off with more than
    half of the speed of a rigid-rigid elastic impact, 2 m1 / (m1 + m2) v (the rest rings in
    the EFG plate)."""
    run = run_deck(drop_deck(tmp_path / "drop.k"))
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        glstat = glstat_of(results)
        rigid = results["history/rbdout/2"]
        rigid_velocity = rigid["velocity"][...]
    momentum = glstat["momentum"]
    initial = momentum[0]
    assert np.abs(momentum - initial).max() <= 1e-9 * np.abs(initial).max()
    total = glstat["total_energy"]
    assert np.abs(total / total[0] - 1.0).max() < 1e-5
    plate_mass, rigid_mass = DENSITY * SIDE * SIDE * 2.0, DENSITY * 60.0 * 60.0 * 2.0
    elastic = 2.0 * plate_mass / (plate_mass + rigid_mass) * 3.0
    assert rigid_velocity[0, 2] == 0.0 and rigid_velocity[-1, 2] < -0.5 * elastic


def struck_surface_deck(path, speed=3.0, end_time=0.4):
    """The meshfree plate as the contact SURFACE: the EFG plate (40 x 40 mm, 8 x 8 irregular
    cells, 2 mm, moving up at `speed`) strikes a free rigid plate above it (20 x 20 mm, 4 x 4 FE
    shells, centred); *CONTACT_AUTOMATIC_NODES_TO_SURFACE with the rigid plate's nodes as the
    secondary side and the EFG part as the segments, so the segments' corners (mostly interior
    particles) are at their physical positions and the segment forces go back as A^T f. The
    rigid nodes start 0.5 mm above the EFG plate's upper contact surface (its half thickness above
    the mid-surface)."""
    thickness = 2.0
    nodes, shells = plate_mesh((8, 8), (SIDE, SIDE), perturbation=0.2, seed=9)
    nodes = round_to_node_card(nodes)
    rigid_nodes, rigid_shells = plate_mesh((4, 4), (20.0, 20.0))
    rigid_nodes = round_to_node_card(rigid_nodes + [10.0, 10.0, 0.5 * thickness + 0.5])
    count = len(nodes)
    return write_deck(
        path,
        "*TITLE\nrigid plate struck by a meshfree plate",
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_GLSTAT\n" + fields(end_time / 200),
        "*DATABASE_BINARY_D3PLOT\n" + fields(end_time / 4),
        "*PART\nmeshfree plate\n" + fields(1, 1, 1),
        "*SECTION_SHELL\n" + fields(1, 41, f"{5 / 6:10.7f}", 3) + "\n" + fields(thickness, thickness, thickness,
                                                                             thickness) + "\n" + fields(1.5, 1.5),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
        "*PART\nrigid plate\n" + fields(2, 2, 2),
        "*SECTION_SHELL\n" + fields(2, 2, 1.0, 2) + "\n" + fields(thickness, thickness, thickness, thickness),
        "*MAT_RIGID\n" + fields(2, DENSITY, YOUNGS, POISSON) + "\n" + fields(0.0, 0.0, 0.0) + "\n" + fields(0.0),
        "*CONTACT_AUTOMATIC_NODES_TO_SURFACE_ID\n" + fields(5) + "strike\n" + fields(2, 1, 4, 3) + "\n" +
        fields(0.0) + "\n" + fields(0.1, 0.1),
        "*SET_NODE_LIST_GENERATE\n" + fields(1) + "\n" + fields(1, count),
        "*SET_NODE_LIST_GENERATE\n" + fields(2) + "\n" + fields(count + 1, count + len(rigid_nodes)),
        nodes_card(np.vstack([nodes, rigid_nodes])),
        shells_card(shells, part_id=1) + "\n" +
        "\n".join(shells_card(rigid_shells, part_id=2, first_id=len(shells) + 1,
                              first_node_id=count + 1).splitlines()[1:]),
        "*INITIAL_VELOCITY\n" + fields(1) + "\n" + fields(0.0, 0.0, speed),
    )


def test_meshfree_plate_as_contact_surface_keeps_the_momentum(tmp_path, run_deck):
    """The other side of the contact: the EFG part gives the segments, a rigid plate's nodes
    strike them. Total momentum stays at its initial value (1e-9 relative), the total energy
    within 1e-5, the rigid plate is pushed up (faster than half the speed of an elastic impact of
    its mass on the EFG plate's, 2 m1 / (m1 + m2) v), and no rigid node passes the EFG plate's
    physical upper surface (its mid-surface at the rigid plate's nodes plus half the thickness)
    by more than a tenth of the thickness at any output state."""
    run = run_deck(struck_surface_deck(tmp_path / "struck.k"))
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        glstat = glstat_of(results)
        rigid_velocity = results["history/rbdout/2"]["velocity"][...]
        coordinates = results["mesh/nodes/coordinates"][...]
        gaps = []
        for name in sorted(results["states"]):
            current = coordinates + results["states"][name]["displacement"][...]
            meshfree, rigid = current[:81], current[81:]
            # the EFG plate's physical mid-surface height under the rigid plate: the mean of the
            # nodes within its footprint (the plate stays nearly flat; bending is small)
            under = (meshfree[:, 0] > 10.0) & (meshfree[:, 0] < 30.0) & (meshfree[:, 1] > 10.0) & \
                    (meshfree[:, 1] < 30.0)
            gaps.append(rigid[:, 2].min() - (meshfree[under, 2].max() + 1.0))
    momentum = glstat["momentum"]
    assert np.abs(momentum - momentum[0]).max() <= 1e-9 * np.abs(momentum[0]).max()
    total = glstat["total_energy"]
    assert np.abs(total / total[0] - 1.0).max() < 1e-5
    plate_mass, rigid_mass = DENSITY * SIDE * SIDE * 2.0, DENSITY * 20.0 * 20.0 * 2.0
    elastic = 2.0 * plate_mass / (plate_mass + rigid_mass) * 3.0
    print(f"rigid plate final speed {rigid_velocity[-1, 2]:.4f} (elastic {elastic:.4f}); smallest gap "
          f"{min(gaps):.4f} mm")
    assert rigid_velocity[0, 2] == 0.0 and rigid_velocity[-1, 2] > 0.5 * elastic
    assert min(gaps) > -0.2


def test_walls_and_failure_criteria_on_meshfree_shells_are_announced(tmp_path, run_deck):
    """What meshfree shells do not do is said before the run: their material's failure strain
    does not erode them (the deck check's warning for every meshfree part). A rigid wall
    tracking their interior particles acts on their physical positions (test_meshfree_walls):
    nothing to say about it."""
    deck = drop_deck(tmp_path / "announced.k", end_time=0.01)
    text = deck.read_text()
    text = text.replace("*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
                        "*MAT_PLASTIC_KINEMATIC\n" + fields(1, DENSITY, YOUNGS, POISSON, 0.25, 0.0, 0.0) + "\n" +
                        fields(0.0, 0.0, 0.3) + "\n*RIGIDWALL_PLANAR\n" + fields(0) + "\n" +
                        fields(0.0, 0.0, -10.0, 0.0, 0.0, 1.0))
    deck.write_text(text)
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    assert "rigid wall 1" not in run.stderr
    assert "the failure criteria of material 1 are ignored for part 1: meshfree (EFG) parts do not erode" in run.stderr


def test_initial_velocities_and_segment_loads_are_announced(tmp_path, run_deck):
    """Initial velocities are solved for the generalized values (test_meshfree_walls), so
    neither the stretch deck's linear field nor the same with one interior node (41, the plate's
    centre) given a different velocity brings a warning. A *LOAD_SEGMENT in an explicit run is
    said to be applied by the static analysis only."""
    deck = stretch_deck(tmp_path / "linear.k", end_time=0.001)
    run = run_deck(deck, jobid="linear")
    assert run.status == 0, run.stdout + run.stderr
    assert "initial velocities" not in run.stderr and "segment load" not in run.stderr
    text = deck.read_text().splitlines()
    centre = next(k for k, line in enumerate(text) if line.startswith(f"{41:20d}") and "e" in line[20:])
    text[centre] = f"{41:20d}{0.0:20.13e}{0.0:20.13e}{1.0:20.13e}"
    text.insert(text.index("*END") if "*END" in text else len(text),
                "*LOAD_SEGMENT\n" + fields(1, 1.0e-6, 0.0, 1, 2, 11, 10))
    changed = tmp_path / "changed.k"
    changed.write_text("\n".join(text) + "\n")
    run = run_deck(changed, jobid="changed")
    assert run.status == 0, run.stdout + run.stderr
    assert "initial velocities" not in run.stderr
    assert ("warning: the deck's 1 segment load(s) (*LOAD_SEGMENT, _SET, _NONUNIFORM) are applied by the linear "
            "static analysis (*CONTROL_IMPLICIT_GENERAL) only: this explicit run does not apply them") in run.stderr


def test_spot_weld_on_meshfree_shells_fails_by_their_plastic_strain(tmp_path, run_deck):
    """The lap joint of test_spot_welds with meshfree strips (ELFORM 41, DX 1.5; the weld's nodes
    stay Gamma nodes): with EP = 0.002 the weld fails by the plastic strain of the cells around
    its nodes, as on FE shells; with EP = 0 it holds."""
    from test_spot_welds import lap_joint_deck
    plastic = "*MAT_PIECEWISE_LINEAR_PLASTICITY\n" + fields(1, DENSITY, YOUNGS, POISSON, 0.2, 1.0) + "\n" + fields(0.0)
    runs = {}
    for name, weld_strain in (("holds", 0.0), ("fails", 0.002)):
        deck = lap_joint_deck(tmp_path / f"{name}.k", 0.0)
        text = deck.read_text().replace("*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON), plastic)
        text = text.replace("*SECTION_SHELL\n" + fields(1, 2, 1.0, 3) + "\n" + fields(2.0, 2.0, 2.0, 2.0),
                            "*SECTION_SHELL\n" + fields(1, 41, 1.0, 3) + "\n" + fields(2.0, 2.0, 2.0, 2.0) + "\n" +
                            fields(1.5, 1.5))
        lines = text.splitlines()
        weld = lines.index("*CONSTRAINED_SPOTWELD") + 1
        lines[weld] = lines[weld] + fields(0.0, 0.0, 0.0, weld_strain)[:40]
        deck.write_text("\n".join(lines) + "\n")
        runs[name] = run_deck(deck, jobid=name)
    for name, run in runs.items():
        assert run.status == 0, run.stdout + run.stderr
        assert "meshfree shells: 16 cells" in run.stdout
    assert "spot weld" not in runs["holds"].stdout
    assert "reached the plastic strain" in runs["fails"].stdout
