"""Explicit patch test on an irregular hexahedral mesh (ELFORM 1 and 2).

Initial velocity v = A X everywhere and the same velocity prescribed on the boundary nodes:
the exact solution keeps v = A X (uniform velocity gradient, uniform stress, no interior
acceleration). After 100 cycles every interior node must still move with A X to 1e-10
relative, and the hourglass energy must stay at round-off.
"""
import numpy as np
import pytest

from conftest import last_state
from deck_writer import (block_mesh, boundary_node_mask, fields, nodes_card, round_to_node_card,
                         solids_card, write_deck)

VELOCITY_GRADIENT = np.array([[0.010, 0.004, -0.002],
                              [0.003, -0.006, 0.005],
                              [-0.001, 0.002, 0.008]])


def patch_deck(path, element_formulation, hourglass_type):
    nodes, elements = block_mesh((4, 4, 4), (1.0, 1.0, 1.0), perturbation=0.25, seed=7)
    nodes = round_to_node_card(nodes)
    velocity = nodes @ VELOCITY_GRADIENT.T
    boundary = np.flatnonzero(boundary_node_mask(nodes))
    initial = ["*INITIAL_VELOCITY_NODE+"]
    for k, v in enumerate(velocity):
        initial.append(f"{k + 1:20d}{v[0]:20.13e}{v[1]:20.13e}{v[2]:20.13e}")
    motion = ["*BOUNDARY_PRESCRIBED_MOTION_NODE+"]
    for k in boundary:
        for direction in range(3):
            # curve 1 is 1.0 scaled by the velocity; SF = 0 would read as the default 1.0, so a
            # zero velocity uses curve 2, which is 0.0
            value = velocity[k, direction]
            curve, scale = (1, value) if value != 0.0 else (2, 1.0)
            motion.append(f"{k + 1:20d}{direction + 1:20d}{0:20d}{curve:20d}{scale:20.13e}")
    deck = write_deck(
        path,
        "*TITLE\npatch test",
        "*CONTROL_TERMINATION\n" + fields(1.0, 100),
        "*CONTROL_TIMESTEP\n" + fields(0.0, 0.9),
        "*DATABASE_BINARY_D3PLOT\n" + fields(1.0),
        "*PART\nblock\n" + fields(1, 1, 1, 0, 1),
        "*SECTION_SOLID\n" + fields(1, element_formulation),
        "*MAT_ELASTIC\n" + fields(1, 7.8e-6, 210.0, 0.3),
        "*HOURGLASS\n" + fields(1, hourglass_type, 0.1),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + f"{0.0:20.6e}{1.0:20.6e}\n{10.0:20.6e}{1.0:20.6e}",
        "*DEFINE_CURVE\n" + fields(2) + "\n" + f"{0.0:20.6e}{0.0:20.6e}\n{10.0:20.6e}{0.0:20.6e}",
        nodes_card(nodes),
        solids_card(elements),
        "\n".join(initial),
        "\n".join(motion),
    )
    return deck, nodes, boundary


@pytest.mark.parametrize("element_formulation, hourglass_type",
                         [(1, 2), (1, 3), (1, 4), (1, 5), (2, 1)])
def test_linear_velocity_field_is_kept(tmp_path, run_deck, element_formulation, hourglass_type):
    deck, nodes, boundary = patch_deck(tmp_path / "patch.k", element_formulation, hourglass_type)
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    with run.open() as results:
        assert results["run"].attrs["cycles"] == 100
        state = last_state(results)
        velocity = state["velocity"][...]
        glstat = {name: results["history/glstat"][name][...] for name in results["history/glstat"]}
    interior = np.setdiff1d(np.arange(len(nodes)), boundary)
    assert len(interior) == 27
    expected = nodes[interior] @ VELOCITY_GRADIENT.T
    error = np.abs(velocity[interior] - expected).max() / np.abs(expected).max()
    assert error < 1e-10, f"interior velocity error {error:.3e}"
    # the hourglass modes are orthogonal to linear fields: no hourglass work at all
    assert abs(glstat["hourglass_energy"][-1]) <= 1e-10 * max(glstat["internal_energy"][-1], 1e-30)
    assert glstat["internal_energy"][-1] > 0.0
