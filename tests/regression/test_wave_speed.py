"""Elastic bar: a velocity step at one end sends a stress wave that reaches the free end at
L / c with c = sqrt(E / rho) (Poisson's ratio 0 makes the bar one-dimensional). At the free end
the velocity doubles when the front arrives; the arrival is the time it passes half its jump."""
import numpy as np

from deck_writer import block_mesh, fields, nodes_card, node_list_set, solids_card, write_deck

YOUNGS_MODULUS = 210.0      # GPa
DENSITY = 7.85e-6           # kg/mm^3
LENGTH = 100.0              # mm
IMPACT_SPEED = 1.0          # mm/ms


def test_wave_front_arrives_at_length_over_bar_speed(tmp_path, run_deck):
    nodes, elements = block_mesh((200, 1, 1), (LENGTH, 1.0, 1.0))
    loaded = np.flatnonzero(np.abs(nodes[:, 0]) < 1e-9) + 1
    far_end = int(np.flatnonzero(np.abs(nodes[:, 0] - LENGTH) < 1e-9)[0]) + 1
    deck = write_deck(
        tmp_path / "bar.k",
        "*CONTROL_TERMINATION\n" + fields(0.03),
        "*DATABASE_NODOUT\n" + fields(1.0e-6),
        "*DATABASE_HISTORY_NODE\n" + fields(far_end),
        "*PART\nbar\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS_MODULUS, 0.0),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + f"{0.0:20.6e}{1.0:20.6e}\n{1.0:20.6e}{1.0:20.6e}",
        node_list_set(1, list(loaded)),
        "*BOUNDARY_PRESCRIBED_MOTION_SET\n" + fields(1, 1, 0, 1, IMPACT_SPEED),
        nodes_card(nodes),
        solids_card(elements),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    with run.open() as results:
        history = results[f"history/nodout/{far_end}"]
        time = history["time"][...]
        velocity = history["velocity"][:, 0]
    # the free end's velocity jumps from 0 to 2 v0; the front is where it passes v0
    crossing = np.flatnonzero(velocity >= IMPACT_SPEED)[0]
    t0, t1 = time[crossing - 1], time[crossing]
    v0, v1 = velocity[crossing - 1], velocity[crossing]
    arrival = t0 + (IMPACT_SPEED - v0) * (t1 - t0) / (v1 - v0)
    expected = LENGTH / np.sqrt(YOUNGS_MODULUS / DENSITY)
    assert abs(arrival - expected) / expected < 0.02, f"arrival {arrival:.6g} ms, L/c {expected:.6g} ms"
    assert velocity[-1] > 1.8 * IMPACT_SPEED
