"""*RIGIDWALL_GEOMETRIC_CYLINDER(_MOTION): a cylinder driven along x by a velocity curve pushes
into an elastic-plastic block, and a block is thrown at a stationary infinite cylinder. No node
ends a state inside the cylinder, the impulse integrated from the wall force history (rwforc)
equals the block's change of momentum (glstat) within 1%, and the energy balance closes.
Unavailable options (NSEGS > 0) and an undefined motion curve are deck errors."""
import numpy as np
import pytest

from deck_writer import block_mesh, fields, nodes_card, solids_card, write_deck

DENSITY = 7.85e-6
RADIUS = 3.0
SPEED = 50.0      # mm/ms


def block_cards(end_time, initial_velocity=None, origin=(0.0, 0.0, 0.0)):
    nodes, elements = block_mesh((6, 6, 6), (10.0, 10.0, 10.0), origin=origin, perturbation=0.1)
    cards = [
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_GLSTAT\n" + fields(end_time / 200),
        "*DATABASE_RWFORC\n" + fields(end_time / 200),
        "*DATABASE_BINARY_D3PLOT\n" + fields(end_time / 40),
        "*PART\nblock\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_PLASTIC_KINEMATIC\n" + fields(1, DENSITY, 200.0, 0.3, 0.4, 1.0, 1.0) + "\n" + fields(0.0, 0.0),
        nodes_card(nodes),
        solids_card(elements),
    ]
    if initial_velocity is not None:
        cards.append("*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields(*initial_velocity))
    return cards


def moving_cylinder_cards(lcid=1, segments=0):
    # axis along z through (-4, 5), 30 mm long from z = -10: the side strikes the block's x = 0 face
    return ("*RIGIDWALL_GEOMETRIC_CYLINDER_MOTION_ID\n" + fields(4) + "pusher\n" + fields(0) + "\n" +
            fields(-4.0, 5.0, -10.0, -4.0, 5.0, 20.0) + "\n" + fields(RADIUS, 30.0, segments) + "\n" +
            ("" if segments == 0 else fields(1.0, 2.0) + "\n") +
            fields(lcid, 0, 1.0, 0.0, 0.0))


def nodes_outside(results, tail_at):
    """Smallest distance from the axis over all states and nodes, relative to the radius, for
    the nodes that lie along the cylinder's length."""
    coordinates = results["mesh/nodes/coordinates"][...]
    smallest = np.inf
    for name in sorted(results["states"].keys()):
        state = results["states"][name]
        x = coordinates + state["displacement"][...]
        tail = tail_at(float(state.attrs["time"]))
        relative = x - tail
        radial = relative[:, :2]
        smallest = min(smallest, np.linalg.norm(radial, axis=1).min() / RADIUS)
    return smallest


def impulse_and_momentum(results, wall_id):
    wall = results[f"history/rwforc/{wall_id}"]
    time, force = wall["time"][...], wall["force"][...]
    momentum = results["history/glstat/momentum"][...]
    ratio = results["history/glstat/energy_ratio"][...]
    # (LS-DYNA's sign: the force of the wall on the structure)
    impulse_on_structure = (force[1:] * np.diff(time)[:, None]).sum(axis=0)
    return impulse_on_structure, momentum[-1] - momentum[0], ratio


def test_moving_cylinder_pushes_a_block(tmp_path, run_deck):
    end_time = 0.1
    deck = write_deck(
        tmp_path / "pusher.k",
        "*TITLE\ncylinder pushes a block",
        *block_cards(end_time),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + fields(0.0, SPEED, width=20) + "\n" + fields(1.0, SPEED, width=20),
        moving_cylinder_cards(),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    with run.open() as results:
        closest = nodes_outside(results, lambda t: np.array([-4.0 + SPEED * t, 5.0, -10.0]))
        impulse, momentum_change, ratio = impulse_and_momentum(results, 4)
    print(f"moving: closest/R = {closest:.9f}, impulse {impulse[0]:.6e}, dp {momentum_change[0]:.6e}, "
          f"energy ratio {ratio.min():.5f}..{ratio.max():.5f}")
    assert closest > 1.0 - 1e-6
    assert momentum_change[0] > 0.5 * DENSITY * 1000.0 * SPEED * 0.5, "the block must be pushed"
    assert abs(impulse[0] - momentum_change[0]) / abs(momentum_change[0]) < 0.01
    assert np.abs(impulse[1:]).max() < 0.05 * abs(impulse[0])
    assert np.abs(ratio - 1.0).max() < 0.01


def test_block_thrown_at_a_stationary_cylinder(tmp_path, run_deck):
    end_time = 0.08
    deck = write_deck(
        tmp_path / "post.k",
        "*TITLE\nblock thrown at a post",
        *block_cards(end_time, initial_velocity=(-2.0 * SPEED, 0.0, 0.0)),
        # infinite cylinder (LENCYL 0) along z, 0.5 mm left of the block, off-centre in y
        "*RIGIDWALL_GEOMETRIC_CYLINDER\n" + fields(0) + "\n" + fields(-3.5, 4.0, 0.0, -3.5, 4.0, 1.0) + "\n" +
        fields(RADIUS, 0.0, 0),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    with run.open() as results:
        closest = nodes_outside(results, lambda t: np.array([-3.5, 4.0, 0.0]))
        impulse, momentum_change, ratio = impulse_and_momentum(results, 1)
    print(f"stationary: closest/R = {closest:.9f}, impulse {impulse[0]:.6e}, dp {momentum_change[0]:.6e}, "
          f"energy ratio {ratio.min():.5f}..{ratio.max():.5f}")
    assert closest > 1.0 - 1e-6
    assert momentum_change[0] > 0.5 * DENSITY * 1000.0 * 2.0 * SPEED, "the block must be stopped"
    assert abs(impulse[0] - momentum_change[0]) / abs(momentum_change[0]) < 0.01
    assert abs(impulse[1] - momentum_change[1]) <= 0.01 * abs(momentum_change[0])
    assert np.abs(ratio - 1.0).max() < 0.01


def test_block_dropped_on_an_end_cap(tmp_path, run_deck):
    """A finite cylinder along z with its top cap at z = 0: the block's middle lands on the cap."""
    end_time = 0.08
    deck = write_deck(
        tmp_path / "cap.k",
        "*TITLE\nblock dropped on an end cap",
        *block_cards(end_time, initial_velocity=(0.0, 0.0, -2.0 * SPEED), origin=(0.0, 0.0, 0.5)),
        "*RIGIDWALL_GEOMETRIC_CYLINDER_ID\n" + fields(6) + "stool\n" + fields(0) + "\n" +
        fields(5.0, 5.0, -20.0, 5.0, 5.0, -10.0) + "\n" + fields(RADIUS, 20.0, 0),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    with run.open() as results:
        coordinates = results["mesh/nodes/coordinates"][...]
        deepest = 0.0
        for name in sorted(results["states"].keys()):
            x = coordinates + results["states"][name]["displacement"][...]
            over_cap = np.linalg.norm(x[:, :2] - 5.0, axis=1) < RADIUS
            deepest = max(deepest, -x[over_cap, 2].min())
        impulse, momentum_change, ratio = impulse_and_momentum(results, 6)
    print(f"cap: deepest below the cap/R = {deepest / RADIUS:.3e}, impulse {impulse[2]:.6e}, "
          f"dp {momentum_change[2]:.6e}, energy ratio {ratio.min():.5f}..{ratio.max():.5f}")
    assert deepest < 1e-6 * RADIUS
    assert momentum_change[2] > 0.0, "the cap must slow the block down"
    assert abs(impulse[2] - momentum_change[2]) / abs(momentum_change[2]) < 0.01
    assert np.abs(ratio - 1.0).max() < 0.01


@pytest.mark.parametrize("description, cylinder, fragments", [
    ("subsections", moving_cylinder_cards(segments=1), ["RIGIDWALL_GEOMETRIC_CYLINDER", "NSEGS"]),
    ("undefined motion curve", moving_cylinder_cards(lcid=9), ["RIGIDWALL_GEOMETRIC_CYLINDER", "LCID", "9"]),
])
def test_cylinder_deck_errors(tmp_path, run_deck, description, cylinder, fragments):
    deck = write_deck(
        tmp_path / "bad.k",
        *block_cards(0.01),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + fields(0.0, SPEED, width=20) + "\n" + fields(1.0, SPEED, width=20),
        cylinder,
    )
    run = run_deck(deck)
    assert run.status == 2, f"{description}: exit status {run.status}\n{run.stderr}"
    for fragment in fragments:
        assert fragment in run.stderr, f"{description}: '{fragment}' not in:\n{run.stderr}"
    assert "At line" not in run.stderr
    assert not run.results.exists()
