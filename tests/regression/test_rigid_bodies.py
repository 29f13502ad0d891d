"""Rigid bodies (*MAT_RIGID, *BOUNDARY_PRESCRIBED_MOTION_RIGID, rbdout).

1. A rigid 20 x 30 x 50 block spinning freely about a non-principal axis (and translating):
   mass and inertia as the analytical ones (1e-12), angular momentum and kinetic energy
   conserved to 1e-6 over 10,000 cycles, the body stays rigid and really tumbles.
2. A rigid block driven by a prescribed velocity ramp pushes an elastic block through shared
   nodes: the impulse of the rbdout force equals the momentum change of the elastic block
   within 1%.
3. Deck errors: local constraint systems, constraint points, a part constrained twice, a
   prescribed motion on a part that is not rigid.
"""
import numpy as np
import pytest

from conftest import last_state
from deck_writer import block_mesh, fields, nodes_card, solids_card, write_deck

RO, E, PR = 7.85e-6, 210.0, 0.3   # kg/mm^3, GPa (kN/mm^2): ms, mm, kg units


def spinning_block_deck(path):
    nodes, elements = block_mesh((2, 2, 2), (20.0, 30.0, 50.0))
    deck = write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(100.0, 10000),
        "*DATABASE_GLSTAT\n" + fields(0.15),
        "*PART\nblock\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_RIGID\n" + fields(1, RO, E, PR) + "\n" + fields(0.0, 0.0, 0.0) + "\n" + fields(0.0),
        nodes_card(nodes),
        solids_card(elements),
        # omega = 1 rad/ms about (1, 0.5, 0.3) through the centre, plus 1 mm/ms along x
        "*INITIAL_VELOCITY_GENERATION\n" + fields(1, 2, 1.0, 1.0, 0.0, 0.0) + "\n" +
        fields(10.0, 15.0, 25.0, 1.0, 0.5, 0.3),
    )
    return deck, nodes


def test_free_spin_conserves_angular_momentum_and_energy(tmp_path, run_deck):
    deck, nodes = spinning_block_deck(tmp_path / "spin.k")
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    with run.open() as results:
        assert results["run"].attrs["cycles"] == 10000
        assert results["mesh/parts/formulation"][0] == b"rigid"
        kinetic = results["history/glstat/kinetic_energy"][...]
        rbdout = results["history/rbdout/1"]
        momentum = rbdout["angular_momentum"][...]
        velocity = rbdout["velocity"][...]
        displacement = last_state(results)["displacement"][...]
    mass = RO * 20.0 * 30.0 * 50.0
    inertia = mass / 12.0 * np.diag([30.0**2 + 50.0**2, 20.0**2 + 50.0**2, 20.0**2 + 30.0**2])
    axis = np.array([1.0, 0.5, 0.3]) / np.linalg.norm([1.0, 0.5, 0.3])
    assert momentum[0] == pytest.approx(inertia @ axis, rel=1e-12)
    assert kinetic[0] == pytest.approx(0.5 * axis @ inertia @ axis + 0.5 * mass, rel=1e-12)
    drift_l = np.linalg.norm(momentum - momentum[0], axis=1).max() / np.linalg.norm(momentum[0])
    drift_k = np.abs(kinetic / kinetic[0] - 1.0).max()
    print(f"angular momentum drift {drift_l:.2e}, kinetic energy drift {drift_k:.2e}")
    assert drift_l < 1e-6 and drift_k < 1e-6
    assert np.abs(velocity - [1.0, 0.0, 0.0]).max() < 1e-12
    # rigid: every distance between nodes kept; tumbling: the nodes are far from where a
    # steady rotation about the initial axis would put them (several radians turned)
    final = nodes + displacement
    initial_distances = np.linalg.norm(nodes[:, None] - nodes[None], axis=2)
    final_distances = np.linalg.norm(final[:, None] - final[None], axis=2)
    assert np.abs(final_distances - initial_distances).max() < 1e-9 * initial_distances.max()
    assert np.abs(displacement).max() > 10.0


def pusher_deck(path):
    nodes, elements = block_mesh((6, 2, 2), (60.0, 20.0, 20.0))
    rigid = nodes[elements].mean(axis=1)[:, 0] < 10.0
    lines = ["*ELEMENT_SOLID"]
    for k, corners in enumerate(elements):
        lines.append(f"{k + 1:8d}{2 if rigid[k] else 1:8d}" + "".join(f"{c + 1:8d}" for c in corners))
    return write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(1.0),
        "*DATABASE_GLSTAT\n" + fields(0.01),
        "*PART\nblock\n" + fields(1, 1, 1),
        "*PART\npusher\n" + fields(2, 1, 2),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, RO, E, PR),
        # CMO = 1: no rotation (CON2 = 7); x is prescribed, y and z are free
        "*MAT_RIGID\n" + fields(2, RO, E, PR) + "\n" + fields(1.0, 0.0, 7.0),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + fields(0.0, 0.0, width=20) + "\n" +
        fields(0.5, 1.0, width=20) + "\n" + fields(10.0, 1.0, width=20),
        "*BOUNDARY_PRESCRIBED_MOTION_RIGID\n" + fields(2, 1, 0, 1, 5.0),
        nodes_card(nodes),
        "\n".join(lines),
    )


def test_pusher_force_equals_momentum_rate(tmp_path, run_deck):
    run = run_deck(pusher_deck(tmp_path / "push.k"))
    assert run.status == 0, run.stderr
    with run.open() as results:
        glstat = results["history/glstat"]
        rbdout = results["history/rbdout/2"]
        time = rbdout["time"][...]
        force = rbdout["force"][...]
        velocity = rbdout["velocity"][...]
        displacement = rbdout["displacement"][...]
        momentum = glstat["momentum"][...]
    assert velocity[-1] == pytest.approx([5.0, 0.0, 0.0], abs=1e-9)
    # the run ends with the first step past ENDTIM = 1: compare at the time it reached (a step
    # of 1e-3 ms moves the pusher 5e-3 mm, more than the tolerance)
    assert displacement[-1, 0] == pytest.approx(5.0 * (time[-1] - 0.25), rel=1e-3)
    # body mass: its elements plus the corner masses of the elastic layer on its nodes
    body_mass = RO * 20.0 * 20.0 * (10.0 + 10.0 / 2)
    block_momentum = momentum[:, 0] - body_mass * velocity[:, 0]
    change = block_momentum - block_momentum[0]
    impulse = np.concatenate([[0.0], np.cumsum(force[1:, 0] * np.diff(time))])
    error = np.abs(impulse + change).max() / np.abs(change).max()
    print(f"impulse vs momentum change: {error:.2e} of {np.abs(change).max():.4f}")
    assert error < 0.01
    assert change[-1] == pytest.approx(RO * 20.0 * 20.0 * 45.0 * 5.0, rel=0.02)


BASE = [
    "*CONTROL_TERMINATION\n" + fields(1.0),
    "*PART\nblock\n" + fields(1, 1, 1),
    "*PART\npusher\n" + fields(2, 1, 2),
    "*SECTION_SOLID\n" + fields(1, 1),
    "*MAT_ELASTIC\n" + fields(1, RO, E, PR),
    "*DEFINE_CURVE\n" + fields(1) + "\n" + fields(0.0, 1.0, width=20) + "\n" + fields(1.0, 1.0, width=20),
]


def mesh_blocks():
    nodes, elements = block_mesh((2, 1, 1), (20.0, 10.0, 10.0))
    lines = ["*ELEMENT_SOLID"]
    for k, corners in enumerate(elements):
        lines.append(f"{k + 1:8d}{k + 1:8d}" + "".join(f"{c + 1:8d}" for c in corners))
    return [nodes_card(nodes), "\n".join(lines)]


@pytest.mark.parametrize("cards, field, message", [
    (["*MAT_RIGID\n" + fields(2, RO, E, PR) + "\n" + fields(-1.0, 1.0, 101111.0)], "CMO", "local coordinate"),
    (["*MAT_RIGID\n" + fields(2, RO, E, PR) + "\n" + fields(2.0, 1.0, 0.0, 5)], "SPCNID", "not available"),
    (["*MAT_RIGID\n" + fields(2, RO, E, PR) + "\n" + fields(1.0, 9.0, 0.0)], "CON1", "code 0-7"),
    (["*MAT_RIGID\n" + fields(2, RO, E, PR) + "\n" + fields(1.0, 1.0, 0.0),
      "*BOUNDARY_PRESCRIBED_MOTION_RIGID\n" + fields(2, 1, 0, 1)], "DOF", "constrained twice"),
    (["*MAT_RIGID\n" + fields(2, RO, E, PR),
      "*BOUNDARY_PRESCRIBED_MOTION_RIGID\n" + fields(2, 6, 0, 1) + "\n" + fields(2, 6, 2, 1)],
     "DOF", "constrained twice"),
    (["*MAT_RIGID\n" + fields(2, RO, E, PR),
      "*BOUNDARY_PRESCRIBED_MOTION_RIGID\n" + fields(1, 1, 0, 1)], "PID", "is not rigid"),
    (["*MAT_RIGID\n" + fields(2, RO, E, PR),
      "*BOUNDARY_PRESCRIBED_MOTION_RIGID\n" + fields(2, 4, 0, 1)], "DOF", "not available"),
    (["*MAT_RIGID\n" + fields(2, RO, E, PR),
      "*CONSTRAINED_NODAL_RIGID_BODY\n" + fields(7, 0, 99)], "NSID", "node set 99 is not defined"),
])
def test_deck_errors(tmp_path, run_deck, cards, field, message):
    deck = write_deck(tmp_path / "bad.k", *BASE, *cards, *mesh_blocks())
    run = run_deck(deck)
    assert run.status == 2, run.stdout + run.stderr
    lines = [line for line in run.stderr.splitlines() if f"field {field}:" in line]
    assert lines and message in lines[0], run.stderr
    assert "bad.k:" in lines[0]


def test_nodal_rigid_body_and_element_mass(tmp_path, run_deck):
    """A node set made rigid (the end layer of an elastic bar) with a lumped mass on one of its
    nodes: it moves as one body whose mass is the nodes' masses (rbdout velocity = momentum /
    mass, no deformation of the layer)."""
    nodes, elements = block_mesh((4, 2, 2), (40.0, 20.0, 20.0))
    end = [k + 1 for k in range(len(nodes)) if nodes[k, 0] < 1e-9]
    deck = write_deck(
        tmp_path / "nodal.k",
        "*CONTROL_TERMINATION\n" + fields(0.2),
        "*PART\nbar\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, RO, E, PR),
        "*SET_NODE_LIST\n" + fields(5) + "\n" + fields(*end[:8]) + "\n" + fields(*end[8:]),
        "*CONSTRAINED_NODAL_RIGID_BODY\n" + fields(100, 0, 5),
        "*ELEMENT_MASS\n" + f"{1:8d}{end[0]:8d}{0.01:16.6e}",
        "*INITIAL_VELOCITY_GENERATION\n" + fields(1, 2, 0.0, -2.0, 0.0, 0.0) + "\n" + fields(0.0, 0.0, 0.0, 1.0, 0.0, 0.0),
        nodes_card(nodes), solids_card(elements),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    with run.open() as results:
        rbdout = results["history/rbdout/100"]
        assert rbdout["velocity"][0] == pytest.approx([-2.0, 0.0, 0.0], abs=1e-12)
        displacement = last_state(results)["displacement"][...]
        momentum = results["history/glstat/momentum"][...]
    layer = np.array(end) - 1
    assert np.ptp(displacement[layer], axis=0).max() < 1e-9
    mass = RO * 40.0 * 400.0 + 0.01
    assert momentum[0] == pytest.approx([-2.0 * mass, 0.0, 0.0], rel=1e-12, abs=1e-15)
    assert np.abs(momentum - momentum[0]).max() < 1e-9 * mass
