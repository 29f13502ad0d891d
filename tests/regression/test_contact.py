"""Penalty contact between solid faces (*CONTACT_AUTOMATIC_...).

- Two identical elastic blocks in head-on contact (surface to surface): momentum conserved,
  velocities exchanged, little penetration, small contact energy (the spring work's integration
  error after separation, either sign, below 1e-4 of the impact energy).
- A block sliding on a fixed block with Coulomb friction under a weight-like nodal load:
  deceleration mu g.
- ncpu = 1 and 2 give identical results; deck errors name the field.
"""
import numpy as np
import pytest

from deck_writer import block_mesh, fields, node_list_set, nodes_card, solids_card, write_deck
from test_threads import datasets

DENSITY, MODULUS, POISSON = 7.85e-6, 200.0, 0.3      # kg/mm^3, GPa, -
SPEED = 1.0                                          # mm/ms
SIDE = 10.0                                          # slider edge, mm
LENGTH = 40.0                                        # head-on blocks: 40 x 5 x 5 mm (thickness 40 along x)
GAP = 0.01


def nodal_masses(nodes, elements, density=DENSITY):
    """Lumped masses: rho V / 8 of each element to each of its corners (box cells)."""
    masses = np.zeros(len(nodes))
    for corners in elements:
        extent = nodes[corners].max(axis=0) - nodes[corners].min(axis=0)
        masses[corners] += density * np.prod(extent) / 8.0
    return masses


def head_on_deck(path, end_time=0.03, extra="", counts=(16, 2, 2), lengths=(40.0, 5.0, 5.0)):
    a_nodes, a_elements = block_mesh(counts, lengths)
    b_nodes, b_elements = block_mesh(counts, lengths, origin=(lengths[0] + GAP, 0.0, 0.0))
    count = len(a_nodes)
    return write_deck(
        path,
        "*TITLE\ntwo blocks head on",
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_GLSTAT\n" + fields(end_time / 200),
        "*DATABASE_RCFORC\n" + fields(end_time / 200),
        "*DATABASE_BINARY_D3PLOT\n" + fields(end_time / 120),
        "*PART\nleft\n" + fields(1, 1, 1),
        "*PART\nright\n" + fields(2, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, MODULUS, POISSON),
        node_list_set(1, list(range(1, count + 1))),
        node_list_set(2, list(range(count + 1, 2 * count + 1))),
        "*INITIAL_VELOCITY\n" + fields(1) + "\n" + fields(SPEED, 0.0, 0.0),
        "*INITIAL_VELOCITY\n" + fields(2) + "\n" + fields(-SPEED, 0.0, 0.0),
        "*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE_ID\n" + fields(5) + "blocks\n" + fields(1, 2, 3, 3) + "\n" +
        fields(0.0) + "\n" + fields(1.0),
        extra,
        nodes_card(np.vstack([a_nodes, b_nodes])),
        solids_card(a_elements, part_id=1) + "\n" +
        "\n".join(solids_card(b_elements, part_id=2, first_id=len(a_elements) + 1,
                              first_node_id=count + 1).splitlines()[1:]),
    ), a_nodes, a_elements, b_nodes


def test_head_on_blocks_exchange_velocities(tmp_path, run_deck):
    deck, a_nodes, a_elements, b_nodes = head_on_deck(tmp_path / "head_on.k")
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    masses = nodal_masses(a_nodes, a_elements)
    block_mass = masses.sum()
    count = len(a_nodes)
    front_a = np.flatnonzero(np.isclose(a_nodes[:, 0], LENGTH))
    front_b = count + np.flatnonzero(np.isclose(b_nodes[:, 0], LENGTH + GAP))
    # the node of B facing each node of A (identical meshes, same y and z)
    order_a = np.lexsort((a_nodes[front_a - 0, 2], a_nodes[front_a, 1]))
    order_b = np.lexsort((b_nodes[front_b - count, 2], b_nodes[front_b - count, 1]))
    with run.open() as results:
        glstat = results["history/glstat"]
        momentum = glstat["momentum"][...]
        contact = glstat["contact_energy"][...]
        kinetic = glstat["kinetic_energy"][...]
        rcforc = results["history/rcforc/5"]
        force, force_time = rcforc["force"][...], rcforc["time"][...]
        penetration = 0.0
        coordinates = np.vstack([a_nodes, b_nodes])
        for name in sorted(results["states"].keys()):
            x = coordinates + results["states"][name]["displacement"][...]
            overlap = x[front_a[order_a], 0] - x[front_b[order_b], 0]
            penetration = max(penetration, overlap.max())
        last = results["states"][sorted(results["states"].keys())[-1]]
        velocity = last["velocity"][...]
    reference = block_mass * SPEED
    assert np.abs(momentum).max() < 1e-8 * reference
    mean_a = (masses * velocity[:count, 0]).sum() / block_mass
    mean_b = (masses * velocity[count:, 0]).sum() / block_mass
    print(f"head on: velocities after {mean_a:.5f} {mean_b:.5f} (expected -/+{SPEED}), "
          f"max penetration {penetration:.3e} mm, max contact energy {contact.max():.3e} "
          f"(initial kinetic {kinetic[0]:.3e}), min {contact.min():.3e}")
    assert abs(mean_a + SPEED) < 0.02 * SPEED
    assert abs(mean_b - SPEED) < 0.02 * SPEED
    assert penetration < 0.05 * LENGTH
    # after separation the springs have given back what they took up to the time discretisation
    # of their switching on and off: +0 (main) or -2.3e-5 of the impact energy (the smaller steps
    # of the element eigenvalue bound) are the same physics
    assert contact.min() >= -1e-4 * kinetic[0]
    # at full compression the penalty springs hold part of the impact energy (elastic, given
    # back); after separation only the integration error of the spring work remains
    assert contact.max() < 0.2 * kinetic[0]
    assert abs(contact[-1]) < 0.005 * kinetic[0]
    # the force on the left block points back (-x); its impulse is the left block's momentum change
    impulse = (force[1:, 0] * np.diff(force_time)).sum()
    assert abs(impulse + 2.0 * reference) < 0.03 * 2.0 * reference


def test_head_on_contact_is_thread_independent(tmp_path, run_deck):
    deck = head_on_deck(tmp_path / "head_on.k", end_time=0.015)[0]
    one = run_deck(deck, ncpu=1)
    two = run_deck(deck, ncpu=2)
    assert one.status == 0 and two.status == 0, one.stderr + two.stderr
    with one.open() as first, two.open() as second:
        a, b = datasets(first), datasets(second)
    assert a.keys() == b.keys()
    for name in a:
        assert np.array_equal(a[name], b[name]), f"{name} differs between 1 and 2 threads"


FRICTION = 0.3
GRAVITY = 10.0                                      # mm/ms^2


def base_top_segments(set_id):
    """*SET_SEGMENT of the base's top face, written clockwise seen from above (pointing into the
    base): the reader's owner search must turn them outward."""
    def index(i, j):
        return (i * 5 + j) * 2 + 1 + 1          # block_mesh numbering, k = 1 (top), 1-based
    lines = ["*SET_SEGMENT", fields(set_id)]
    for i in range(6):
        for j in range(4):
            lines.append(fields(index(i, j), index(i, j + 1), index(i + 1, j + 1), index(i + 1, j)))
    return "\n".join(lines)


def base_and_slider_deck(path, title, slider, end_time, glstat, d3plot, speed, cards):
    """The fixed 60 x 20 x 5 mm base (part 1, top face at z = 0) and a slider (part 2, the
    (nodes, elements) of `slider`) moving at `speed` along x; `cards` (loads, contact) go
    between the initial velocity and the mesh."""
    base_nodes, base_elements = block_mesh((6, 4, 1), (60.0, 20.0, 5.0), origin=(-10.0, -5.0, -5.0))
    slider_nodes, slider_elements = slider
    count = len(base_nodes)
    return write_deck(
        path,
        "*TITLE\n" + title,
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_GLSTAT\n" + fields(glstat),
        "*DATABASE_BINARY_D3PLOT\n" + fields(d3plot),
        "*PART\nbase\n" + fields(1, 1, 1),
        "*PART\nslider\n" + fields(2, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, MODULUS, POISSON),
        node_list_set(1, list(range(1, count + 1))),
        node_list_set(2, list(range(count + 1, count + len(slider_nodes) + 1))),
        "*BOUNDARY_SPC_SET\n" + fields(1, 0, 1, 1, 1),
        "*INITIAL_VELOCITY\n" + fields(2) + "\n" + fields(speed, 0.0, 0.0),
        *cards,
        nodes_card(np.vstack([base_nodes, slider_nodes])),
        solids_card(base_elements, part_id=1) + "\n" +
        "\n".join(solids_card(slider_elements, part_id=2, first_id=len(base_elements) + 1,
                              first_node_id=count + 1).splitlines()[1:]),
    ), count


def sliding_deck(path, kind="surface_to_surface"):
    slider_nodes, slider_elements = block_mesh((3, 3, 2), (SIDE, SIDE, 5.0))
    slider_mass = nodal_masses(slider_nodes, slider_elements).sum()
    per_node = slider_mass * GRAVITY / len(slider_nodes)
    deck, count = base_and_slider_deck(
        path, "block sliding with friction", (slider_nodes, slider_elements), 0.2, 0.002, 0.01, SPEED,
        ["*DEFINE_CURVE\n" + fields(1) + "\n" + fields(0.0, 1.0, width=20) + "\n" + fields(10.0, 1.0, width=20),
         "*LOAD_NODE_SET\n" + fields(2, 3, 1, -per_node),
         {"surface_to_surface": "*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE\n" + fields(2, 1, 3, 3),
          "nodes_to_surface": base_top_segments(7) + "\n*CONTACT_AUTOMATIC_NODES_TO_SURFACE\n" + fields(2, 7, 4, 0),
          "single_surface": "*CONTACT_AUTOMATIC_SINGLE_SURFACE\n" + fields(0, 0, 5)}[kind] + "\n" +
         fields(FRICTION, FRICTION, 0.0, 0.0, 20.0) + "\n" + fields(1.0)])
    return deck, count, nodal_masses(slider_nodes, slider_elements)


@pytest.mark.parametrize("kind", ["surface_to_surface", "nodes_to_surface", "single_surface"])
def test_block_sliding_with_friction_decelerates_at_mu_g(tmp_path, run_deck, kind):
    deck, count, masses = sliding_deck(tmp_path / "sliding.k", kind)
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    times, speeds, heights = [], [], []
    with run.open() as results:
        for name in sorted(results["states"].keys()):
            state = results["states"][name]
            velocity = state["velocity"][count:]
            times.append(state.attrs["time"])
            speeds.append((masses * velocity[:, 0]).sum() / masses.sum())
            heights.append(state["displacement"][count:, 2].min())
        contact = results["history/glstat/contact_energy"][...]
    times, speeds = np.array(times), np.array(speeds)
    window = (times >= 0.02) & (times <= 0.18)
    slope = np.polyfit(times[window], speeds[window], 1)[0]
    print(f"sliding ({kind}): deceleration {-slope:.4f} mm/ms^2 (mu g = {FRICTION * GRAVITY}), "
          f"lowest slider node {min(heights):.3e} mm, contact energy {contact.min():.3e}..{contact.max():.3e}")
    assert speeds[-1] > 0.0, "the slider must still slide at the end"
    assert abs(-slope - FRICTION * GRAVITY) < 0.03 * FRICTION * GRAVITY
    assert min(heights) > -0.05 * 5.0
    assert contact.min() >= -1e-9 * abs(contact).max()


def bad_deck(path, card_1):
    deck = head_on_deck(path)[0]
    text = deck.read_text().replace(fields(1, 2, 3, 3), card_1)
    path.write_text(text)
    return path


def test_contact_deck_errors(tmp_path, run_deck):
    cases = [
        (fields(1, 9, 3, 3), "field SURFB: part 9 is not defined"),
        (fields(4, 2, 2, 3), "field SURFA: part set 4 is not defined"),
        (fields(8, 2, 0, 3), "field SURFA: segment set 8 is not defined"),
        (fields(1, 2, 1, 3), "field SURFATYP: surface type 1 is not available"),
    ]
    for k, (card, message) in enumerate(cases):
        run = run_deck(bad_deck(tmp_path / f"bad{k}.k", card), jobid=f"bad{k}")
        assert run.status != 0
        text = run.stdout + run.stderr
        assert message in text, text
        assert "*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE_ID" in text


def test_node_arriving_under_a_segment_from_its_edge_is_not_pushed_out(tmp_path, run_deck):
    """A penetration only grows as fast as node and segment approach. The slider starts beside
    the base with its bottom 2 mm below the base's top face and slides in level: its nodes
    reach the underside of the top segments (the contact surface) from their edge, 2 mm deep
    with no approach along the normal. That is not a contact; pushing them out (a 2 mm spring at
    once) would throw the slider upward. Before the rule, the contact gave the 4.9 J slider
    848 J and the run stopped with a negative volume."""
    speed, end_time = 50.0, 0.4
    deck, count = base_and_slider_deck(
        tmp_path / "edge_entry.k", "slider entering under the contact surface from its edge",
        block_mesh((2, 2, 2), (SIDE, SIDE, 5.0), origin=(-25.0, 0.0, -2.0)), end_time, end_time / 100,
        end_time / 4, speed,
        [base_top_segments(7) + "\n*CONTACT_AUTOMATIC_NODES_TO_SURFACE\n" + fields(2, 7, 4, 0) + "\n" +
         fields(0.0) + "\n" + fields(1.0)])
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    with run.open() as results:
        final = results["states"][sorted(results["states"].keys())[-1]]
        displacement = final["displacement"][count:]
        velocity = final["velocity"][count:]
        contact = results["history/glstat/contact_energy"][...]
    travel = displacement[:, 0].mean()
    print(f"edge entry: slider travelled {travel:.2f} mm, largest |v_z| {np.abs(velocity[:, 2]).max():.3e} mm/ms, "
          f"contact energy {np.abs(contact).max():.3e}")
    assert travel > 15.0, "the slider must have passed under the top face (x > -10 mm by 5 mm)"
    assert np.abs(velocity[:, 2]).max() < 1e-9 * speed
    assert np.allclose(velocity[:, 0], speed, rtol=1e-9)
    assert np.abs(contact).max() == 0.0


def test_bucket_sort_interval_changes_when_the_search_runs_not_the_forces(tmp_path, run_deck):
    """NSBCS (*CONTROL_CONTACT card 2) and BSORT only make the search sort more often than the
    automatic rule (when a node has moved half the search margin), which misses no pair: the
    head-on impact gives the same histories and states, bit for bit, with a sort every cycle.
    A negative NSBCS is refused, naming the field."""
    automatic = run_deck(head_on_deck(tmp_path / "automatic.k", end_time=0.015)[0], jobid="automatic")
    every_cycle = run_deck(head_on_deck(tmp_path / "every.k", end_time=0.015,
                                        extra="*CONTROL_CONTACT\n" + fields(0.0) + "\n" + fields(0, 0, 1))[0],
                           jobid="every")
    assert automatic.status == 0 and every_cycle.status == 0, automatic.stdout + every_cycle.stdout
    with automatic.open() as first, every_cycle.open() as second:
        a, b = datasets(first), datasets(second)
    compared = [name for name in a if name.startswith(("history/", "states/"))]
    assert compared and all(name in b for name in compared)
    for name in compared:
        assert np.array_equal(a[name], b[name]), f"{name} differs with NSBCS = 1"
    bad = run_deck(head_on_deck(tmp_path / "bad_nsbcs.k", extra="*CONTROL_CONTACT\n" + fields(0.0) + "\n" +
                                fields(0, 0, -5))[0], jobid="bad_nsbcs")
    assert bad.status == 2
    assert "*CONTROL_CONTACT: field NSBCS: must be >= 0" in bad.stdout + bad.stderr, bad.stdout + bad.stderr
