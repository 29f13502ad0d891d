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
