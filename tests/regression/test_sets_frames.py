"""Sets, boxes and coordinate systems as LS-DYNA reads them.

Sets are checked through the initial velocity they receive (state 0 shows exactly which nodes
move): a *SET_NODE_GENERAL BOX set holds exactly the nodes inside the box, a set of sets
(*SET_NODE_ADD, *SET_PART_ADD, nested, defined after its users and before its members) equals
the union of its sets. Coordinate systems (*DEFINE_COORDINATE_SYSTEM, _NODES, _VECTOR) and
vectors (*DEFINE_VECTOR) are checked through a free block: a velocity given in a rotated frame
moves it along the rotated direction, an SPC in a local frame leaves only the free local
direction, a motion along a vector moves it along the vector, each to 1e-12. The _DISPLAY card of
a cylinder wall is read and changes nothing.
"""
import numpy as np
import pytest

from deck_writer import block_mesh, fields, nodes_card, solids_card, write_deck

DENSITY = 7.85e-6
END_TIME = 0.01
# a rotated frame: origin, a point on local x, a point in the local x-y plane
ORIGIN = np.array([1.0, -2.0, 0.5])
X_POINT = ORIGIN + np.array([2.0, 1.0, 2.0])
PLANE_POINT = ORIGIN + np.array([-1.0, 2.0, 0.25])


def frame_axes():
    """Columns: the local x, y, z axes of the frame above (LS-DYNA's construction)."""
    x = (X_POINT - ORIGIN) / np.linalg.norm(X_POINT - ORIGIN)
    z = np.cross(x, PLANE_POINT - ORIGIN)
    z /= np.linalg.norm(z)
    return np.column_stack([x, np.cross(z, x), z])


def block_cards(counts=(3, 3, 3), two_parts=False, end_time=END_TIME):
    """An elastic block 0-3 mm on each side (node ids 1.., element ids 1..); with `two_parts`
    the elements with x < 1.5 are part 1 and the others part 2."""
    nodes, elements = block_mesh(counts, (3.0, 3.0, 3.0))
    cards = [
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_BINARY_D3PLOT\n" + fields(end_time),
        "*PART\nblock\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, 200.0, 0.3),
        nodes_card(nodes),
    ]
    if two_parts:
        centres = nodes[elements].mean(axis=1)
        first = centres[:, 0] < 1.5
        cards.append("*PART\nsecond\n" + fields(2, 1, 1))
        cards.append(solids_card(elements[first], part_id=1, first_id=1))
        cards.append(solids_card(elements[~first], part_id=2, first_id=1 + int(first.sum())))
    else:
        cards.append(solids_card(elements))
    return nodes, elements, cards


def id_lines(ids, per_line=8):
    return "\n".join(fields(*ids[k:k + per_line]) for k in range(0, len(ids), per_line))


def velocities(results, state=0):
    names = sorted(results["states"].keys())
    return results["states"][names[state]]["velocity"][...]


def moving_nodes(results):
    """Node ids (sorted) that have a velocity at state 0."""
    ids = results["mesh/nodes/ids"][...]
    return set(ids[np.linalg.norm(velocities(results), axis=1) > 0.0].tolist())


def test_node_set_from_a_box_holds_the_nodes_inside(tmp_path, run_deck):
    nodes, _, cards = block_cards()
    # the box [0.5, 3] x [-1, 1.5] x [0.9, 2.1]: the bounds are inclusive, and node 1 (the origin)
    # is removed again by DNODE if it were inside; DBOX takes away a corner box
    deck = write_deck(
        tmp_path / "box.k",
        *cards,
        # used before the set and the boxes are defined: LS-DYNA reads the whole deck first
        "*INITIAL_VELOCITY\n" + fields(10) + "\n" + fields(1.0, 2.0, 3.0),
        "*SET_NODE_GENERAL_TITLE\nnodes in the box\n" + fields(10) + "\n" + fields("BOX", 3) + "\n" +
        fields("DBOX", 4) + "\n" + fields("DNODE", 64),
        "*DEFINE_BOX\n" + fields(3, 0.5, 3.0, -1.0, 1.5, 0.9, 2.1) + "\n" + fields(4, 2.5, 3.5, 0.5, 1.5, 1.5, 2.5),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    inside = ((nodes[:, 0] >= 0.5) & (nodes[:, 0] <= 3.0) & (nodes[:, 1] >= -1.0) & (nodes[:, 1] <= 1.5) &
              (nodes[:, 2] >= 0.9) & (nodes[:, 2] <= 2.1))
    corner = ((nodes[:, 0] >= 2.5) & (nodes[:, 1] >= 0.5) & (nodes[:, 1] <= 1.5) & (nodes[:, 2] >= 1.5) &
              (nodes[:, 2] <= 2.5))
    expected = set((np.flatnonzero(inside & ~corner) + 1).tolist()) - {64}
    with run.open() as results:
        found = moving_nodes(results)
        v = velocities(results)
    print(f"box set: {len(found)} nodes, expected {len(expected)}")
    assert len(expected) > 4 and found == expected
    assert np.array_equal(v[sorted(i - 1 for i in found)], np.tile([1.0, 2.0, 3.0], (len(found), 1)))


def test_local_box_and_initial_velocity_box(tmp_path, run_deck):
    """*DEFINE_BOX_LOCAL in the rotated frame, and *INITIAL_VELOCITY with BOXID (all nodes,
    NSID 0, only those in the box)."""
    nodes, _, cards = block_cards()
    axes = frame_axes()
    low, high = np.array([0.0, -1.0, -1.0]), np.array([2.5, 3.0, 2.0])
    deck = write_deck(
        tmp_path / "local_box.k",
        *cards,
        "*INITIAL_VELOCITY\n" + fields(0, 0, 8) + "\n" + fields(0.0, 0.0, -5.0),
        "*DEFINE_BOX_LOCAL\n" + fields(8, low[0], high[0], low[1], high[1], low[2], high[2]) + "\n" +
        fields(*(X_POINT - ORIGIN), *(PLANE_POINT - ORIGIN)) + "\n" + fields(*ORIGIN),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    local = (nodes - ORIGIN) @ axes
    inside = np.all((local >= low) & (local <= high), axis=1)
    with run.open() as results:
        found = moving_nodes(results)
    print(f"local box: {len(found)} of {len(nodes)} nodes")
    assert 4 < inside.sum() < len(nodes) and found == set((np.flatnonzero(inside) + 1).tolist())


def test_sets_of_sets_equal_the_union(tmp_path, run_deck):
    nodes, elements, cards = block_cards(two_parts=True)
    node_count = len(nodes)
    deck = write_deck(
        tmp_path / "union.k",
        *cards,
        # a set of sets of sets, defined before the sets it names
        "*INITIAL_VELOCITY\n" + fields(100) + "\n" + fields(0.0, 4.0, 0.0),
        "*SET_NODE_ADD\n" + fields(100) + "\n" + fields(101, 3),
        "*SET_NODE_ADD_TITLE\nfirst two\n" + fields(101) + "\n" + fields(1, 2),
        "*SET_NODE\n" + fields(1) + "\n" + id_lines([1, 2, 3, 17]),
        "*SET_NODE_LIST_GENERATE\n" + fields(2) + "\n" + fields(3, 6, 20, 22),
        "*SET_NODE_TITLE\nthird\n" + fields(3) + "\n" + id_lines([64, 63, 1]),
        # part sets: parts 1 and 2 through a set of sets -> every node of both parts
        "*INITIAL_VELOCITY_GENERATION\n" + fields(200, 1, 0.0, 0.0, 0.0, 7.0) + "\n" + fields(0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
        "*SET_PART_ADD\n" + fields(200) + "\n" + fields(201, 202),
        "*SET_PART\n" + fields(201) + "\n" + fields(1),
        "*SET_PART_LIST_GENERATE\n" + fields(202) + "\n" + fields(2, 2),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    union = {1, 2, 3, 17} | {3, 4, 5, 6, 20, 21, 22} | {64, 63, 1}
    with run.open() as results:
        v = velocities(results)
    # _GENERATION is applied after *INITIAL_VELOCITY, over every node of parts 1 and 2
    assert np.array_equal(v, np.tile([0.0, 0.0, 7.0], (node_count, 1)))
    # the union alone, without the part sets
    deck = write_deck(tmp_path / "union_nodes.k", *cards,
                      "*INITIAL_VELOCITY\n" + fields(100) + "\n" + fields(0.0, 4.0, 0.0),
                      "*SET_NODE_ADD\n" + fields(100) + "\n" + fields(101, 3),
                      "*SET_NODE_ADD_TITLE\nfirst two\n" + fields(101) + "\n" + fields(1, 2),
                      "*SET_NODE\n" + fields(1) + "\n" + id_lines([1, 2, 3, 17]),
                      "*SET_NODE_LIST_GENERATE\n" + fields(2) + "\n" + fields(3, 6, 20, 22),
                      "*SET_NODE_TITLE\nthird\n" + fields(3) + "\n" + id_lines([64, 63, 1]),
                      "*INITIAL_VELOCITY_GENERATION\n" + fields(201, 1, 0.0, 0.0, 0.0, 7.0) + "\n" +
                      fields(0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
                      "*SET_PART\n" + fields(201) + "\n" + fields(2))
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    part_two = set((elements[nodes[elements].mean(axis=1)[:, 0] >= 1.5].ravel() + 1).tolist())
    with run.open() as results:
        v = velocities(results)
        ids = results["mesh/nodes/ids"][...]
    by_id = {int(i): v[k] for k, i in enumerate(ids)}
    for node_id, velocity in by_id.items():
        if node_id in part_two:
            expected = [0.0, 0.0, 7.0]
        elif node_id in union:
            expected = [0.0, 4.0, 0.0]
        else:
            expected = [0.0, 0.0, 0.0]
        assert np.array_equal(velocity, expected), node_id


def frame_cards():
    """The same rotated frame three ways (ids 5, 6, 7) and a vector along its local z (id 9,
    given in frame 5 as (0, 0, 2))."""
    return [
        "*DEFINE_COORDINATE_SYSTEM_TITLE\nrotated\n" + fields(5, *ORIGIN, *X_POINT) + "\n" + fields(*PLANE_POINT),
        "*DEFINE_COORDINATE_VECTOR\n" + fields(6, *(X_POINT - ORIGIN), *(PLANE_POINT - ORIGIN)),
        "*DEFINE_VECTOR\n" + fields(9, 1.0, 1.0, 1.0, 1.0, 1.0, 3.0, 5),
    ]


def node_frame_cards(first_id):
    """Frame 7 by three extra nodes (ids first_id..first_id+2, not attached to any element)."""
    points = [ORIGIN, X_POINT, PLANE_POINT]
    node_lines = "\n".join(f"{first_id + k:8d}{p[0]:16.9e}{p[1]:16.9e}{p[2]:16.9e}" for k, p in enumerate(points))
    return ["*NODE\n" + node_lines,
            "*DEFINE_COORDINATE_NODES\n" + fields(7, first_id, first_id + 1, first_id + 2)]


@pytest.mark.parametrize("keyword", ["set", "node", "generation"])
def test_velocity_in_a_rotated_frame(tmp_path, run_deck, keyword):
    nodes, _, cards = block_cards()
    axes = frame_axes()
    local = np.array([3.0, -1.0, 2.0])
    extra = len(nodes) + 1
    if keyword == "set":
        velocity_cards = ["*INITIAL_VELOCITY\n" + fields(0, 0, 0, 0, 5) + "\n" + fields(*local)]
    elif keyword == "node":
        velocity_cards = ["*INITIAL_VELOCITY_NODE\n" + "\n".join(fields(k + 1, *local, None, None, None, 6)
                                                                   for k in range(len(nodes)))]
    else:
        # a translation only (OMEGA 0) in frame 7, through node ids: the whole block
        velocity_cards = ["*INITIAL_VELOCITY_GENERATION\n" + fields(1, 2, 0.0, *local, 0, 7) + "\n" +
                          fields(0.0, 0.0, 0.0, 0.0, 0.0, 1.0)]
    deck = write_deck(tmp_path / f"frame_{keyword}.k", *cards, *frame_cards(), *node_frame_cards(extra),
                      *velocity_cards)
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    expected = axes @ local
    with run.open() as results:
        names = sorted(results["states"].keys())
        last = results["states"][names[-1]]
        time = float(last.attrs["time"])
        velocity = last["velocity"][:len(nodes)]
        displacement = last["displacement"][:len(nodes)]
    error = max(np.abs(velocity - expected).max(), np.abs(displacement - expected * time).max() / time)
    print(f"{keyword}: v = {expected}, error {error:.2e} (relative to |v| = {np.linalg.norm(local):.3f})")
    assert time == pytest.approx(END_TIME)
    assert error < 1e-12 * np.linalg.norm(local)


def test_spc_in_a_local_frame_holds_the_local_directions(tmp_path, run_deck):
    """Every node held along local x and y of frame 5 (CID): a block thrown along (1, 2, 3)
    moves along local z only, with the component of its velocity there."""
    nodes, _, cards = block_cards()
    axes = frame_axes()
    thrown = np.array([1.0, 2.0, 3.0])
    deck = write_deck(
        tmp_path / "local_spc.k", *cards, *frame_cards(),
        "*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields(*thrown),
        "*BOUNDARY_SPC_SET\n" + fields(1, 5, 1, 1, 0),
        "*SET_NODE_GENERAL\n" + fields(1) + "\n" + fields("ALL"),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    expected = (thrown @ axes[:, 2]) * axes[:, 2]
    with run.open() as results:
        names = sorted(results["states"].keys())
        first, last = results["states"][names[0]], results["states"][names[-1]]
        time = float(last.attrs["time"])
        error = max(np.abs(first["velocity"][...] - expected).max(), np.abs(last["velocity"][...] - expected).max(),
                    np.abs(last["displacement"][...] - expected * time).max() / time)
    print(f"local SPC: v = {expected}, error {error:.2e}")
    assert error < 1e-12 * np.linalg.norm(thrown)


@pytest.mark.parametrize("dof", [4, -4])
def test_motion_along_a_vector(tmp_path, run_deck, dof):
    """*BOUNDARY_PRESCRIBED_MOTION_SET DOF 4 / -4 along vector 9 (local z of frame 5, given in
    frame 5): displacement d(t) = 0.5 t along it. With DOF 4 the velocity across the vector
    stays; with DOF -4 it is held."""
    nodes, _, cards = block_cards()
    direction = frame_axes()[:, 2]
    thrown = np.array([1.0, 2.0, 3.0])
    deck = write_deck(
        tmp_path / "vector_motion.k", *cards, *frame_cards(),
        "*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields(*thrown),
        "*BOUNDARY_PRESCRIBED_MOTION_SET\n" + fields(1, dof, 2, 1, 1.0, 9),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + fields(0.0, 0.0, width=20) + "\n" + fields(1.0, 0.5, width=20),
        "*SET_NODE_LIST_GENERATE\n" + fields(1) + "\n" + fields(1, len(nodes)),
        "*DATABASE_GLSTAT\n" + fields(END_TIME / 10),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    with run.open() as results:
        names = sorted(results["states"].keys())
        last = results["states"][names[-1]]
        time = float(last.attrs["time"])
        displacement = last["displacement"][...]
        ratio = results["history/glstat/energy_ratio"][...]
    across = thrown - (thrown @ direction) * direction if dof == 4 else np.zeros(3)
    expected = 0.5 * time * direction + across * time
    error = np.abs(displacement - expected).max()
    print(f"DOF {dof}: u = {expected}, error {error:.2e}, energy ratio {ratio.min():.9f}..{ratio.max():.9f}")
    assert error < 1e-12 * np.linalg.norm(expected)
    # the support's work books the kinetic energy it takes away (the block is not deformed)
    assert np.abs(ratio - 1.0).max() < 1e-9


@pytest.mark.parametrize("kind", ["cylinder", "planar"])
def test_wall_display_card_is_read_and_changes_nothing(tmp_path, run_deck, kind):
    """A car's pole or barrier written with _DISPLAY: the display card is read (noted as not
    used) and the wall acts exactly as without it."""
    nodes, _, cards = block_cards(end_time=0.05)
    if kind == "cylinder":
        wall = ("*RIGIDWALL_GEOMETRIC_CYLINDER{}\n" + fields(0) + "\n" +
                fields(-1.0, 1.5, -5.0, -1.0, 1.5, 5.0) + "\n" + fields(0.9, 0.0, 0))
    else:
        wall = "*RIGIDWALL_PLANAR{}\n" + fields(0) + "\n" + fields(-0.5, 0.0, 0.0, 0.5, 0.0, 0.0)
    velocity = "*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields(-20.0, 0.0, 0.0)
    plain = run_deck(write_deck(tmp_path / "plain.k", *cards, velocity, wall.format("")), jobid="plain")
    shown = run_deck(write_deck(tmp_path / "display.k", *cards, velocity,
                                wall.format("_DISPLAY") + "\n" + fields(99, 7.8e-6, 210.0, 0.3)), jobid="shown")
    # a public car deck leaves the display card out at the end of the keyword: defaults
    left_out = run_deck(write_deck(tmp_path / "left_out.k", *cards, velocity, wall.format("_DISPLAY")),
                        jobid="left_out")
    assert plain.status == 0 and shown.status == 0 and left_out.status == 0, shown.stderr + left_out.stderr
    assert "DISPLAY card is read but not used" in shown.stdout + shown.stderr
    with plain.open() as a, shown.open() as b, left_out.open() as c:
        first = a["states"][sorted(a["states"].keys())[-1]]["displacement"][...]
        second = b["states"][sorted(b["states"].keys())[-1]]["displacement"][...]
        third = c["states"][sorted(c["states"].keys())[-1]]["displacement"][...]
    assert np.abs(first).max() > 0.1 and np.array_equal(first, second) and np.array_equal(first, third)
    # the wall stopped the block: no node went 0.5 mm past where it stands
    assert (nodes[:, 0] + first[:, 0]).min() > -0.5 - 1e-6


@pytest.mark.parametrize("cards, message", [
    (["*INITIAL_VELOCITY\n" + fields(1) + "\n" + fields(1.0),
      "*SET_NODE_GENERAL\n" + fields(1) + "\n" + fields("BOX", 12)], "box 12 is not defined"),
    (["*INITIAL_VELOCITY\n" + fields(1) + "\n" + fields(1.0),
      "*SET_NODE_ADD\n" + fields(1) + "\n" + fields(2), "*SET_NODE_ADD\n" + fields(2) + "\n" + fields(1)],
     "contains itself"),
    (["*INITIAL_VELOCITY\n" + fields(0, 0, 0, 0, 3) + "\n" + fields(1.0)], "coordinate system 3 is not defined"),
    (["*BOUNDARY_SPC_NODE\n" + fields(1, 5, 0, 0, 0, 1)], "rotations held about local axes"),
    (["*BOUNDARY_PRESCRIBED_MOTION_NODE\n" + fields(1, 4, 0, 1)], "VID must name"),
    (["*DEFINE_COORDINATE_SYSTEM\n" + fields(8, 0.0, 0.0, 0.0, 1.0) + "\n" + fields(2.0)], "is not defined"),
    (["*SET_NODE_GENERAL\n" + fields(1) + "\n" + fields("SEGMENT", 1)], "is not available"),
])
def test_bad_sets_and_frames_are_deck_errors(tmp_path, run_deck, cards, message):
    _, _, block = block_cards()
    run = run_deck(write_deck(tmp_path / "bad.k", *block, *frame_cards(), *cards))
    assert run.status == 2, run.stdout
    assert message in run.stdout + run.stderr


def test_wall_box_tracks_only_the_nodes_inside(tmp_path, run_deck):
    """*RIGIDWALL_PLANAR BOXID: the nodes in the box (x <= 1.5) never pass the wall z = -0.5; the
    others (held back only by the block) go through it."""
    nodes, _, cards = block_cards(end_time=0.05)
    deck = write_deck(
        tmp_path / "wall_box.k", *cards,
        "*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields(0.0, 0.0, -40.0),
        "*RIGIDWALL_PLANAR\n" + fields(0, 0, 2) + "\n" + fields(0.0, 0.0, -0.5, 0.0, 0.0, 0.5),
        "*DEFINE_BOX\n" + fields(2, -1.0, 1.5, -1.0, 4.0, -1.0, 4.0),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    with run.open() as results:
        z = nodes[:, 2] + results["states"][sorted(results["states"].keys())[-1]]["displacement"][:, 2]
    tracked = nodes[:, 0] <= 1.5
    print(f"wall box: lowest tracked z {z[tracked].min():.6f}, lowest other z {z[~tracked].min():.6f}")
    assert z[tracked].min() > -0.5 - 1e-9
    assert z[~tracked].min() < -0.5 - 0.1
