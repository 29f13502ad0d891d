"""Shell contact beyond the drop test of test_shell_physics.py: a *MAT_NULL shell as a pure
contact surface; initial penetrations, which are reported once and ignored (as LS-DYNA's
IGNORE = 1) instead of throwing the parts apart; and a plate of small shells dropped on a
panel of shells 40 times larger (the search on mixed segment sizes), on 1, 2 and 3 threads."""
import numpy as np

import test_shell_physics as shells
from deck_writer import fields, nodes_card, plate_mesh, shells_card, write_deck
from test_threads import assert_identical_results, run_on_threads


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


# ---------------------------------------------------------------------------------------------
# mixed segment sizes: the bucket search is sized by the median segment, large segments are in
# every bucket their box covers (penalty_contact); a small-segment node must still find a huge one

PANEL_CELL = 200.0                          # mm, the held panel's shells
STRIP_CELL = 5.0                            # mm, the small plate's and the strip's shells


def mixed_size_deck(path):
    """The 20 x 20 mm plate of 5 mm shells of the drop test falls at 3 m/s onto a held panel of
    four 200 x 200 mm shells (40 times larger), off the panel's nodes and edges, with a held
    strip of 5 mm shells lying on the panel elsewhere: one single-surface contact over all
    three parts, most of its segments small."""
    panel_nodes, panel_shells = plate_mesh((2, 2), (2 * PANEL_CELL, 2 * PANEL_CELL))
    drop_nodes, drop_shells = plate_mesh((4, 4), (4 * STRIP_CELL, 4 * STRIP_CELL))
    drop_nodes = drop_nodes + [113.3, 141.7, shells.PLATE_THICKNESS + shells.DROP_GAP]
    strip_nodes, strip_shells = plate_mesh((20, 8), (20 * STRIP_CELL, 8 * STRIP_CELL))
    strip_nodes = strip_nodes + [250.0, 250.0, shells.PLATE_THICKNESS + 1.0]
    held = len(panel_nodes)
    count = held + len(drop_nodes)
    end_time = shells.DROP_TIME
    cards = [shells_card(panel_shells, part_id=1),
             shells_card(drop_shells, part_id=2, first_id=len(panel_shells) + 1, first_node_id=held + 1),
             shells_card(strip_shells, part_id=3, first_id=len(panel_shells) + len(drop_shells) + 1,
                         first_node_id=count + 1)]
    spc = [fields(k + 1, 0, 1, 1, 1, 1, 1, 1) for k in list(range(held)) + list(range(count, count + len(strip_nodes)))]
    return write_deck(
        path,
        "*TITLE\nsmall plate dropped on a large panel",
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_GLSTAT\n" + fields(end_time / 500),
        "*DATABASE_NODOUT\n" + fields(end_time / 1000),
        "*DATABASE_HISTORY_NODE_SET\n" + fields(2),
        "*PART\npanel\n" + fields(1, 1, 1),
        "*PART\ndrop\n" + fields(2, 1, 1),
        "*PART\nstrip\n" + fields(3, 1, 1),
        "*SECTION_SHELL\n" + fields(1, 2, 1.0, 3) + "\n" + fields(*[shells.PLATE_THICKNESS] * 4),
        "*MAT_ELASTIC\n" + fields(1, shells.DENSITY, shells.YOUNGS, shells.POISSON),
        "*CONTACT_AUTOMATIC_SINGLE_SURFACE_ID\n" + fields(9) + "mixed\n" + fields(0, 0, 5) + "\n" + fields(0.0) + "\n" +
        fields(shells.CONTACT_SCALE, shells.CONTACT_SCALE),
        "*BOUNDARY_SPC_NODE\n" + "\n".join(spc),
        nodes_card(np.vstack([panel_nodes, drop_nodes, strip_nodes])),
        cards[0] + "\n" + "\n".join("\n".join(card.splitlines()[1:]) for card in cards[1:]),
        "*SET_NODE_LIST_GENERATE\n" + fields(2) + "\n" + fields(held + 1, count),
        "*INITIAL_VELOCITY\n" + fields(2) + "\n" + fields(0.0, 0.0, -shells.DROP_SPEED),
    ), held, len(drop_nodes)


def test_small_segment_nodes_hit_a_large_panel(tmp_path, run_deck):
    """The plate of 5 mm shells lands on a 200 mm shell and bounces as off the fine base of
    the drop test: its nodes never come closer to the panel's mid-surface than 95% of the
    contact distance (t1 + t2)/2 = 2 mm, but do touch, most of the speed comes back, and the
    energy balance closes within 1%. (Before the search was sized by the median segment, the
    margin was half the largest segment, 100 mm: every node tested every segment within it
    each cycle. The forces are the same, bit for bit, on this deck.)"""
    deck, held, drop_count = mixed_size_deck(tmp_path / "mixed.k")
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        coordinates = results["mesh/nodes/coordinates"][...]
        node_ids = results["mesh/nodes/ids"][...]
        height = np.array([coordinates[k, 2] + results[f"history/nodout/{node_ids[k]}/displacement"][:, 2]
                           for k in range(held, held + drop_count)])
        energies = shells.glstat(results)
    mass = shells.DENSITY * 20.0 * 20.0 * shells.PLATE_THICKNESS
    kinetic = 0.5 * mass * shells.DROP_SPEED**2
    momentum = energies["momentum"][:, 2]
    rebound = momentum[-1] / mass
    imbalance = energies["total_energy"] - energies["total_energy"][0] - energies["external_work"]
    closest = height.min()
    print(f"mixed sizes: closest mid-surface distance {closest:.4f} mm, rebound speed {rebound:.4f} "
          f"(drop {shells.DROP_SPEED}), energy imbalance {np.abs(imbalance).max() / kinetic:.2e} of the kinetic energy")
    assert 0.95 * shells.PLATE_THICKNESS <= closest < shells.PLATE_THICKNESS
    assert 0.9 * shells.DROP_SPEED < rebound <= shells.DROP_SPEED
    assert energies["contact_energy"].max() > 0.5 * kinetic
    assert np.abs(imbalance).max() < 0.01 * kinetic


def test_mixed_size_contact_is_identical_for_one_two_and_three_threads(tmp_path, run_deck):
    """The mixed-size deck gives the same results, bit for bit, on 1, 2 and 3 threads."""
    deck, _, _ = mixed_size_deck(tmp_path / "mixed.k")
    assert_identical_results(run_on_threads(run_deck, deck))
