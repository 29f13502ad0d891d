"""Tied contacts (*CONTACT_TIED_SURFACE_TO_SURFACE, _SHELL_EDGE_TO_SURFACE, _OFFSET forms).

1. A shell cantilever cut in two with a finer mesh on the outer half, its cut edge tied to the
   inner half by *CONTACT_TIED_SHELL_EDGE_TO_SURFACE: the mean tip deflection under a step
   load is beam theory's within 3%, as for a continuous strip (the tie carries the moment).
2. Two solid blocks with non-matching meshes tied face to face, the upper one thrown
   sideways and up: linear momentum conserved to round-off, the tied nodes stay on the lower
   block's face, and the lower block is carried along.
3. *CONTACT_SPOTWELD carries a lone heavy node (a weld beam's end) with its point of a plate.
4. Deck errors.
"""
import numpy as np
import pytest

from conftest import last_state
from deck_writer import block_mesh, fields, nodes_card, plate_mesh, round_to_node_card, shells_card, solids_card, \
    write_deck

LENGTH, WIDTH, THICKNESS = 100.0, 10.0, 1.0
YOUNGS, POISSON, DENSITY = 210.0, 0.3, 7.85e-6
TIP_LOAD = 1.0e-4
SECOND_MOMENT = WIDTH * THICKNESS**3 / 12.0


def whole_periods(time, signal):
    mean = signal.mean()
    above = signal > mean
    return time[1:][~above[:-1] & above[1:]]


def tied_cantilever_deck(path, keyword="CONTACT_TIED_SHELL_EDGE_TO_SURFACE"):
    """Inner half 10 x 2 shells (part 1), outer half 10 x 3 shells (part 2) with its own nodes;
    part 2 (secondary) tied to part 1 (primary)."""
    inner, inner_shells = plate_mesh((10, 2), (LENGTH / 2, WIDTH))
    outer, outer_shells = plate_mesh((10, 3), (LENGTH / 2, WIDTH))
    outer = outer + [LENGTH / 2, 0.0, 0.0]
    nodes = round_to_node_card(np.vstack([inner, outer]))
    n = len(inner)
    root = np.flatnonzero(np.isclose(nodes[:, 0], 0.0))
    tip = np.flatnonzero(np.isclose(nodes[:, 0], LENGTH))
    tip_middle = tip[np.argmin(np.abs(nodes[tip, 1] - WIDTH / 2))]
    spc = ["*BOUNDARY_SPC_NODE"] + [fields(k + 1, 0, 1, 1, 1, 1, 1, 1) for k in root]
    loads = ["*LOAD_NODE_POINT"]
    for k in tip:
        share = 0.5 if np.isclose(nodes[k, 1], 0.0) or np.isclose(nodes[k, 1], WIDTH) else 1.0
        loads.append(fields(k + 1, 3, 1, f"{TIP_LOAD * share / 3:10.4e}"))
    return write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(40.0),
        "*DATABASE_GLSTAT\n" + fields(0.05),
        "*DATABASE_NODOUT\n" + fields(0.05),
        "*DATABASE_HISTORY_NODE\n" + fields(tip_middle + 1),
        "*PART\ninner\n" + fields(1, 1, 1, 0, 1),
        "*PART\nouter\n" + fields(2, 1, 1, 0, 1),
        "*SECTION_SHELL\n" + fields(1, 2, f"{5 / 6:10.7f}", 3) + "\n" + fields(THICKNESS, THICKNESS, THICKNESS,
                                                                           THICKNESS),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
        "*HOURGLASS\n" + fields(1, 1, 0.1),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + f"{0.0:20.6e}{1.0:20.6e}\n{1000.0:20.6e}{1.0:20.6e}",
        nodes_card(nodes),
        shells_card(inner_shells) + "\n" +
        "\n".join(shells_card(outer_shells, part_id=2, first_id=101, first_node_id=n + 1).splitlines()[1:]),
        "\n".join(spc),
        "\n".join(loads),
        f"*{keyword}\n" + fields(2, 1, 3, 3),
    )


def test_tied_shell_edge_carries_the_bending_moment(tmp_path, run_deck):
    run = run_deck(tied_cantilever_deck(tmp_path / "edge.k"))
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        node = next(iter(results["history/nodout"]))
        time = results["history/nodout"][node]["time"][...]
        tip = results["history/nodout"][node]["displacement"][:, 2]
        glstat = {name: results["history/glstat"][name][...] for name in results["history/glstat"]}
    crossings = whole_periods(time, tip)
    assert len(crossings) >= 3
    window = (time >= crossings[0]) & (time < crossings[-1])
    beam = TIP_LOAD * LENGTH**3 / (3.0 * YOUNGS * SECOND_MOMENT)
    ratio = tip[window].mean() / beam
    print(f"mean tip deflection / beam theory {ratio:.4f}")
    assert abs(ratio - 1.0) < 0.03
    imbalance = glstat["total_energy"] - glstat["total_energy"][0] - glstat["external_work"]
    assert np.abs(imbalance).max() < 1e-2 * glstat["external_work"].max()


def tied_blocks_deck(path, keyword="CONTACT_TIED_SURFACE_TO_SURFACE", gap=0.0):
    """A 20 x 20 x 10 block (2 x 2 x 1 hexahedra, part 1) under a 20 x 20 x 10 block of 3 x 3 x 1
    (part 2, its own nodes, `gap` above); part 2 tied to part 1 and thrown at (1, 0.5, 0.2)."""
    lower, lower_hexes = block_mesh((2, 2, 1), (20.0, 20.0, 10.0))
    upper, upper_hexes = block_mesh((3, 3, 1), (20.0, 20.0, 10.0), origin=(0.0, 0.0, 10.0 + gap))
    nodes = np.vstack([lower, upper])
    n = len(lower)
    lines = ["*ELEMENT_SOLID"]
    for k, corners in enumerate(lower_hexes):
        lines.append(f"{k + 1:8d}{1:8d}" + "".join(f"{c + 1:8d}" for c in corners))
    for k, corners in enumerate(upper_hexes):
        lines.append(f"{k + 101:8d}{2:8d}" + "".join(f"{c + n + 1:8d}" for c in corners))
    velocity = ["*INITIAL_VELOCITY_NODE"] + [fields(n + k + 1, 1.0, 0.5, 0.2) for k in range(len(upper))]
    return write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(1.0),
        "*DATABASE_GLSTAT\n" + fields(0.01),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.5),
        "*PART\nlower\n" + fields(1, 1, 1),
        "*PART\nupper\n" + fields(2, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
        nodes_card(nodes),
        "\n".join(lines),
        "\n".join(velocity),
        f"*{keyword}\n" + fields(2, 1, 3, 3) + "\n" + fields(0.0) + "\n" + fields(0.0, 0.0, 0.0, 2.0 * gap),
    ), nodes, n


@pytest.mark.parametrize("keyword, gap", [("CONTACT_TIED_SURFACE_TO_SURFACE", 0.0),
                                          ("CONTACT_TIED_SURFACE_TO_SURFACE_OFFSET", 0.5)])
def test_tied_blocks_move_as_one(tmp_path, run_deck, keyword, gap):
    deck, nodes, n = tied_blocks_deck(tmp_path / "blocks.k", keyword, gap)
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        momentum = results["history/glstat/momentum"][...]
        ratio = results["history/glstat/energy_ratio"][...]
        state = last_state(results)
        displacement = state["displacement"][...]
        velocity = state["velocity"][...]
    mass = DENSITY * 20.0 * 20.0 * 10.0
    expected = mass * np.array([1.0, 0.5, 0.2])
    print(f"momentum error {np.abs(momentum - expected).max() / np.linalg.norm(expected):.2e}, "
          f"energy ratio {ratio.min():.4f} .. {ratio.max():.4f}")
    assert np.abs(momentum - expected).max() < 1e-9 * np.linalg.norm(expected)
    # the upper block's bottom nodes stay on the lower block's top face (at their offset)
    final = nodes + displacement
    bottom = n + np.flatnonzero(np.isclose(nodes[n:, 2], 10.0 + gap))
    top = np.flatnonzero(np.isclose(nodes[:n, 2], 10.0))
    # the lower top face stays flat to the bilinear interpolation: compare with its plane fit
    plane = np.linalg.lstsq(np.c_[final[top, :2], np.ones(len(top))], final[top, 2], rcond=None)[0]
    height = final[bottom, 2] - (np.c_[final[bottom, :2], np.ones(len(bottom))] @ plane)
    assert np.abs(height - gap).max() < 0.05
    # carried along: the lower block moves with about half the momentum
    lower_velocity = velocity[:n].mean(axis=0)
    assert lower_velocity[0] > 0.3


@pytest.mark.parametrize("card, field, message", [
    (fields(2, 7, 3, 3), "SURFB", "part 7 is not defined"),
    (fields(9, 1, 4, 3), "SURFA", "node set 9 is not defined"),
    (fields(2, 1, 3, 4), "SURFBTYP", "is not available for the primary side"),
    (fields(2, 1, 3, 3, 1), "SABOXID", "contact boxes are not available"),
])
def test_tied_contact_deck_errors(tmp_path, run_deck, card, field, message):
    deck, _, _ = tied_blocks_deck(tmp_path / "bad.k")
    text = deck.read_text().replace(fields(2, 1, 3, 3) + "\n", card + "\n", 1)
    deck.write_text(text)
    run = run_deck(deck)
    assert run.status == 2, run.stdout + run.stderr
    output = run.stdout + run.stderr
    assert f"field {field}" in output and message in output, output


def test_tied_contact_that_ties_nothing_is_reported(tmp_path, run_deck):
    deck, _, _ = tied_blocks_deck(tmp_path / "far.k", gap=5.0)
    text = deck.read_text().replace(fields(0.0, 0.0, 0.0, 10.0), fields(0.0))
    deck.write_text(text)
    run = run_deck(deck)
    assert run.status == 2
    assert "ties no node" in run.stdout + run.stderr


def test_spotweld_contact_carries_a_free_node_with_its_offset(tmp_path, run_deck):
    """*CONTACT_SPOTWELD ties a lone node with a 5 g mass (as a spot-weld beam's end), 0.5 mm
    above a 2 x 2 shell plate, to the plate; the plate is thrown along x and z: momentum is
    conserved and the node moves with its point of the plate (its offset kept)."""
    plate, shells = plate_mesh((2, 2), (10.0, 10.0))
    nodes = np.vstack([plate, [[3.0, 4.0, 0.5]]])
    n = len(plate)
    velocity = ["*INITIAL_VELOCITY_NODE"] + [fields(k + 1, 1.0, 0.0, 0.5) for k in range(n)]
    deck = write_deck(
        tmp_path / "spotweld.k",
        "*CONTROL_TERMINATION\n" + fields(2.0),
        "*DATABASE_GLSTAT\n" + fields(0.01),
        "*DATABASE_BINARY_D3PLOT\n" + fields(1.0),
        "*PART\nplate\n" + fields(1, 1, 1),
        "*SECTION_SHELL\n" + fields(1, 2, 1.0, 3) + "\n" + fields(1.0, 1.0, 1.0, 1.0),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
        nodes_card(nodes),
        shells_card(shells),
        "*ELEMENT_MASS\n" + f"{1:8d}{n + 1:8d}{0.005:16.6e}",
        "\n".join(velocity),
        "*SET_NODE_LIST\n" + fields(7) + "\n" + fields(n + 1),
        "*CONTACT_SPOTWELD_ID\n" + fields(3, "weld") + "\n" + fields(7, 1, 4, 3),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        momentum = results["history/glstat/momentum"][...]
        displacement = last_state(results)["displacement"][...]
    plate_mass = DENSITY * 100.0 * 1.0
    # the node starts at rest: the tie shares the plate's momentum with it at the start
    expected = plate_mass * np.array([1.0, 0.0, 0.5])
    assert np.abs(momentum - expected).max() < 1e-9 * np.linalg.norm(expected)
    # it moves with its point of the first shell (corners 1, 4, 5, 2 at x, y = 0 and 5):
    # xi = 0.2, eta = 0.6, while the heavy node makes the plate bend
    xi, eta = 0.2, 0.6
    weights = np.array([(1 - xi) * (1 - eta), (1 + xi) * (1 - eta), (1 + xi) * (1 + eta), (1 - xi) * (1 + eta)]) / 4
    interpolated = weights @ displacement[[0, 3, 4, 1]]
    print(f"node {displacement[n]}, its point of the plate {interpolated}")
    assert np.abs(displacement[n] - interpolated).max() < 1e-9 * np.linalg.norm(interpolated)
    assert interpolated[0] > 0.05
