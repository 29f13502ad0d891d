"""A block thrown at a stationary planar rigid wall: the impulse integrated from the wall
force history (rwforc) equals the block's change of momentum (glstat) within 1%."""
import numpy as np

from deck_writer import block_mesh, fields, nodes_card, solids_card, write_deck

SPEED = 100.0     # mm/ms


def impact_deck(path, gap=0.2):
    nodes, elements = block_mesh((5, 5, 5), (10.0, 10.0, 10.0), origin=(0.0, 0.0, gap), perturbation=0.1)
    return write_deck(
        path,
        "*TITLE\nblock against a rigid wall",
        "*CONTROL_TERMINATION\n" + fields(0.06),
        "*DATABASE_GLSTAT\n" + fields(0.0005),
        "*DATABASE_RWFORC\n" + fields(0.0005),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.01),
        "*PART\nblock\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_PLASTIC_KINEMATIC\n" + fields(1, 7.85e-6, 200.0, 0.3, 0.4, 1.0, 1.0) + "\n" + fields(0.0, 0.0),
        "*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields(0.0, 0.0, -SPEED),
        "*RIGIDWALL_PLANAR_ID\n" + fields(7) + "wall\n" + fields(0) + "\n" + fields(0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
        nodes_card(nodes),
        solids_card(elements),
    )


def test_wall_impulse_equals_momentum_change(tmp_path, run_deck):
    run = run_deck(impact_deck(tmp_path / "impact.k"))
    assert run.status == 0, run.stderr
    with run.open() as results:
        wall = results["history/rwforc/7"]
        time, force = wall["time"][...], wall["force"][...]
        momentum = results["history/glstat/momentum"][...]
    # forces are averages over each sampling interval: the impulse is their exact integral
    # (LS-DYNA's sign: the force of the wall on the block)
    impulse_on_block = (force[1:] * np.diff(time)[:, None]).sum(axis=0)
    momentum_change = momentum[-1] - momentum[0]
    assert momentum_change[2] > 0.5 * abs(momentum[0][2]), "the block must be stopped or thrown back"
    assert abs(impulse_on_block[2] - momentum_change[2]) / abs(momentum_change[2]) < 0.01
    assert np.abs(impulse_on_block[:2]).max() < 1e-6 * abs(impulse_on_block[2])
