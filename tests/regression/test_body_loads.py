"""*LOAD_BODY_X / _Y / _Z: a base acceleration a(t) = SF curve(t) along an axis; every node takes
the inertial force -m a (LS-DYNA's sign: gravity in -z is a positive *LOAD_BODY_Z, 9.81 m/s^2 =
9.81e-3 mm/ms^2 in mm, ms, kg, kN).

- Free fall: an elastic block and a rigid block (*MAT_RIGID) fall together, every node at
  v = -g t and u = -g t^2 / 2 (to 1e-9 of the fall), and the load's work is the kinetic energy
  they gained (energy ratio 1 to 1e-5: the leapfrog's O(dt^2) at the first sample).
- At rest on the ground: a block on a rigid wall z = 0 under gravity pushes on the wall with its
  weight: the wall's mean force over the last half of the run is m g within 1 %.
- Refusals: a body load in a local system (CID) and one in the linear static analysis.
"""
import numpy as np

from deck_writer import block_mesh, fields, nodes_card, solids_card, write_deck

DENSITY = 7.85e-6      # kg/mm^3
GRAVITY = 9.81e-3      # mm/ms^2


def gravity_cards(scale=1.0, system=0):
    return ["*DEFINE_CURVE\n" + fields(5) + "\n" + fields(0.0, GRAVITY, width=20) + "\n" +
            fields(1000.0, GRAVITY, width=20),
            "*LOAD_BODY_Z\n" + fields(5, scale, 0, 0.0, 0.0, 0.0, system)]


def falling_blocks_deck(path, end_time=10.0, cards=None):
    elastic_nodes, elastic = block_mesh((2, 2, 2), (10.0, 10.0, 10.0))
    rigid_nodes, rigid = block_mesh((1, 1, 1), (10.0, 10.0, 10.0), origin=(20.0, 0.0, 0.0))
    return write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_GLSTAT\n" + fields(end_time / 50),
        "*DATABASE_BINARY_D3PLOT\n" + fields(end_time / 5),
        "*PART\nelastic\n" + fields(1, 1, 1),
        "*PART\nrigid\n" + fields(2, 1, 2),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, 210.0, 0.3),
        "*MAT_RIGID\n" + fields(2, DENSITY, 210.0, 0.3),
        *(cards if cards is not None else gravity_cards()),
        nodes_card(np.vstack([elastic_nodes, rigid_nodes])),
        solids_card(elastic, part_id=1),
        solids_card(rigid, part_id=2, first_id=len(elastic) + 1, first_node_id=len(elastic_nodes) + 1),
    )


def test_free_fall_of_an_elastic_and_a_rigid_block(tmp_path, run_deck):
    end_time = 10.0
    run = run_deck(falling_blocks_deck(tmp_path / "fall.k", end_time))
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        last = results["states"][sorted(results["states"].keys())[-1]]
        time = float(last.attrs["time"])
        velocity, displacement = last["velocity"][...], last["displacement"][...]
        glstat = results["history/glstat"]
        ratio, kinetic = glstat["energy_ratio"][...], glstat["kinetic_energy"][...]
    assert time == end_time
    fall = 0.5 * GRAVITY * time ** 2
    assert np.abs(velocity[:, 2] + GRAVITY * time).max() < 1e-9 * GRAVITY * time
    assert np.abs(displacement[:, 2] + fall).max() < 1e-9 * fall
    assert np.abs(velocity[:, :2]).max() < 1e-12 and np.abs(displacement[:, :2]).max() < 1e-12
    mass = DENSITY * (1000.0 + 1000.0)
    assert abs(kinetic[-1] - 0.5 * mass * (GRAVITY * time) ** 2) < 1e-9 * kinetic[-1]
    # (the energy measure of the leapfrog differs from the load's work by O(m (g dt)^2), which
    # is 2e-6 of the energy at the first sample and shrinks as the energy grows)
    assert np.abs(ratio[1:] - 1.0).max() < 1e-5


def test_block_at_rest_on_the_ground_pushes_with_its_weight(tmp_path, run_deck):
    end_time = 40.0
    nodes, elements = block_mesh((2, 2, 2), (10.0, 10.0, 10.0))
    deck = write_deck(
        tmp_path / "rest.k",
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_GLSTAT\n" + fields(0.1),
        "*DATABASE_RWFORC\n" + fields(0.01),
        "*PART\nblock\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, 0.21, 0.3),
        *gravity_cards(),
        "*RIGIDWALL_PLANAR_ID\n" + fields(7) + "ground\n" + fields(0) + "\n" + fields(0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
        nodes_card(nodes),
        solids_card(elements),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        time = results["history/rwforc/7/time"][...]
        force = results["history/rwforc/7/force"][...]
    weight = DENSITY * 1000.0 * GRAVITY
    later = time > end_time / 2
    mean = np.abs(force[later, 2]).mean()
    assert abs(mean - weight) < 0.01 * weight, (mean, weight)


def test_body_load_refusals(tmp_path, run_deck):
    local = run_deck(falling_blocks_deck(tmp_path / "local.k", cards=gravity_cards(system=3)))
    assert local.status == 2 and "field CID: a body load in a local system" in local.stdout + local.stderr
    static = falling_blocks_deck(tmp_path / "static.k")
    static.write_text(static.read_text().replace("*CONTROL_TERMINATION", "*CONTROL_IMPLICIT_GENERAL\n         1"
                                                 "       1.0\n*CONTROL_TERMINATION"))
    shown = run_deck(static)
    assert shown.status == 2 and "body loads are not available in the linear static analysis" in \
        shown.stdout + shown.stderr
