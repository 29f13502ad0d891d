"""Shell contact beyond the drop test of test_shell_physics.py: a *MAT_NULL shell as a pure
contact surface, and initial penetrations, which are reported once and ignored (as LS-DYNA's
IGNORE = 1) instead of throwing the parts apart."""
import numpy as np

import test_shell_physics as shells
from deck_writer import fields


def null_base_deck(path, **options):
    """The drop deck with the held base plate made of *MAT_NULL (YM and PR set: they give the
    contact stiffness), i.e. a surface that carries no stress of its own."""
    deck, count, drop_count = shells.drop_deck(path, "surface_to_surface", shells.CONTACT_SCALE, **options)
    text = deck.read_text()
    text = text.replace("*PART\nbase\n" + fields(1, 1, 1), "*PART\nbase\n" + fields(1, 1, 2))
    text = text.replace("*MAT_ELASTIC", "*MAT_NULL\n" + fields(2, shells.DENSITY, 0.0, 0.0, 0.0, 0.0, shells.YOUNGS,
                                                             shells.POISSON) + "\n*MAT_ELASTIC", 1)
    deck.write_text(text)
    return deck, count, drop_count


def test_null_shell_is_a_contact_surface(tmp_path, run_deck):
    """The falling elastic plate bounces off the held null-shell plate at the contact distance
    (t1 + t2)/2 like it does off an elastic one; the null shells take no internal energy."""
    deck, count, drop_count = null_base_deck(tmp_path / "null.k")
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        coordinates = results["mesh/nodes/coordinates"][...]
        node_ids = results["mesh/nodes/ids"][...]
        height = np.array([coordinates[k, 2] + results[f"history/nodout/{node_ids[k]}/displacement"][:, 2]
                           for k in range(count, count + drop_count)])
        energies = shells.glstat(results)
        base_internal = results["history/matsum/1/internal_energy"][...]
    mass = shells.DENSITY * 20.0 * 20.0 * shells.PLATE_THICKNESS
    kinetic = 0.5 * mass * shells.DROP_SPEED**2
    closest = height.min()
    assert 0.95 * shells.PLATE_THICKNESS <= closest < shells.PLATE_THICKNESS
    assert energies["momentum"][-1, 2] / mass > 0.9 * shells.DROP_SPEED      # it bounced
    assert np.abs(base_internal).max() == 0.0
    imbalance = energies["total_energy"] - energies["total_energy"][0] - energies["external_work"]
    assert np.abs(imbalance).max() < 0.01 * kinetic


def test_initial_penetration_is_reported_and_ignored(tmp_path, run_deck):
    """The small plate starts 0.5 mm inside the base's contact surface (mid-surfaces 1.5 mm
    apart for a contact distance of 2 mm) and at rest: the run says so once, with the count and
    the depth, and nothing moves (a penalty force on the initial overlap would throw the plate
    off with 0.5 k per node)."""
    deck, count, drop_count = shells.drop_deck(tmp_path / "overlap.k", "surface_to_surface", 1.0)
    text = deck.read_text()
    text = text.replace("*INITIAL_VELOCITY\n" + fields(2) + "\n" + fields(0.0, 0.0, -shells.DROP_SPEED) + "\n", "")
    # move the small plate down by the gap plus 0.5 mm: its nodes are the last ones of *NODE
    lines = text.splitlines()
    start = lines.index("*NODE")
    for k in range(start + 1 + count, start + 1 + count + drop_count):
        line = lines[k]
        z = float(line[40:56]) - shells.DROP_GAP - 0.5
        lines[k] = line[:40] + f"{z:16.9e}" + line[56:]
    deck.write_text("\n".join(lines) + "\n")
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    warnings = [line for line in run.stdout.splitlines() if "penetrate at the first contact check" in line]
    assert len(warnings) == 1, run.stdout
    # both passes of the surface-to-surface contact: the 25 nodes of the small plate and the 16
    # base nodes under it
    assert "41 node(s)" in warnings[0] and "5.000E-01" in warnings[0].upper()
    with run.open() as results:
        energies = shells.glstat(results)
        final = results["states"][sorted(results["states"])[-1]]["displacement"][...]
    assert energies["kinetic_energy"].max() == 0.0
    assert np.abs(final).max() == 0.0
