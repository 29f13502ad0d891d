"""Nodal rigid bodies of two nodes and spot welds (*CONSTRAINED_NODAL_RIGID_BODY,
*CONSTRAINED_SPOTWELD, *CONSTRAINED_GENERALIZED_WELD_SPOT).

1. A shell cantilever cut in two, its halves joined at the cut by two-node nodal rigid bodies
   on coincident nodes (a body with no inertia of its own but the shells' rotary inertias):
   the mean tip deflection under a step load is beam theory's within 3%, as for the
   continuous strip (the joints carry the bending moment).
2. Two free shell sheets joined by one two-node rigid body, one sheet thrown at the other:
   linear momentum and energy conserved, the joined nodes keep their distance.
3. A spot weld pulled apart by a load ramp F = c t fails when F reaches SN (within one step);
   at TF; a generalized weld on three nodes likewise; after failure the nodes separate; the
   count of failed welds is in swforc. A lap joint of two strips fails in shear when the
   weld's shear force reaches SS, the weld's force being the pull (within 5%). 121 welds
   peeled apart give the same results on 1 and 3 threads.
4. Two rigid parts merged (*CONSTRAINED_RIGID_BODIES) with extra nodes (*CONSTRAINED_EXTRA_NODES
   _NODE, _SET) spin as one body: its angular momentum is the analytical one.
5. Deck errors.
"""
import numpy as np
import pytest

from conftest import last_state
from deck_writer import fields, node_list_set, nodes_card, plate_mesh, round_to_node_card, shells_card, write_deck

LENGTH, WIDTH, THICKNESS = 100.0, 10.0, 1.0
YOUNGS, POISSON, DENSITY = 210.0, 0.3, 7.85e-6
TIP_LOAD = 1.0e-4
SECOND_MOMENT = WIDTH * THICKNESS**3 / 12.0


def whole_periods(time, signal):
    mean = signal.mean()
    above = signal > mean
    return time[1:][~above[:-1] & above[1:]]


def split_cantilever_deck(path, cells=(20, 2)):
    """The strip of test_shells clamped at x = 0, cut at x = L/2: the second half has its own
    nodes at the cut, each joined to the first half's node there by a two-node
    *CONSTRAINED_NODAL_RIGID_BODY."""
    nodes, shells = plate_mesh(cells, (LENGTH, WIDTH))
    nodes = round_to_node_card(nodes)
    cut = np.flatnonzero(np.isclose(nodes[:, 0], LENGTH / 2))
    copies = {node: len(nodes) + k for k, node in enumerate(cut)}
    all_nodes = np.vstack([nodes, nodes[cut]])
    centres = nodes[shells].mean(axis=1)[:, 0]
    shells = np.array([[copies.get(c, c) if centre > LENGTH / 2 else c for c in corners]
                       for corners, centre in zip(shells, centres)])
    root = np.flatnonzero(np.isclose(all_nodes[:, 0], 0.0))
    tip = np.flatnonzero(np.isclose(all_nodes[:, 0], LENGTH))
    tip_middle = tip[np.argmin(np.abs(all_nodes[tip, 1] - WIDTH / 2))]
    spc = ["*BOUNDARY_SPC_NODE"] + [fields(k + 1, 0, 1, 1, 1, 1, 1, 1) for k in root]
    loads = ["*LOAD_NODE_POINT"]
    for k in tip:
        share = 0.5 if np.isclose(all_nodes[k, 1], 0.0) or np.isclose(all_nodes[k, 1], WIDTH) else 1.0
        loads.append(fields(k + 1, 3, 1, f"{TIP_LOAD * share / cells[1]:10.4e}"))
    joints = []
    for k, node in enumerate(cut):
        joints.append(node_list_set(100 + k, [node + 1, copies[node] + 1]))
        joints.append("*CONSTRAINED_NODAL_RIGID_BODY\n" + fields(100 + k, 0, 100 + k))
    return write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(40.0),
        "*DATABASE_GLSTAT\n" + fields(0.05),
        "*DATABASE_NODOUT\n" + fields(0.05),
        "*DATABASE_HISTORY_NODE\n" + fields(tip_middle + 1),
        "*PART\nstrip\n" + fields(1, 1, 1, 0, 1),
        "*SECTION_SHELL\n" + fields(1, 2, f"{5 / 6:10.7f}", 3) + "\n" + fields(THICKNESS, THICKNESS, THICKNESS,
                                                                           THICKNESS),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
        "*HOURGLASS\n" + fields(1, 1, 0.1),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + f"{0.0:20.6e}{1.0:20.6e}\n{1000.0:20.6e}{1.0:20.6e}",
        nodes_card(all_nodes),
        shells_card(shells),
        "\n".join(spc),
        "\n".join(loads),
        *joints,
    )


def test_two_node_rigid_bodies_carry_the_bending_moment_of_a_cut_cantilever(tmp_path, run_deck):
    run = run_deck(split_cantilever_deck(tmp_path / "split.k"))
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
    assert np.abs(imbalance).max() < 1e-3 * glstat["external_work"].max()


def two_sheets_deck(path):
    """Two 10 x 10 mm sheets, 2 x 2 shells each, the upper one 1 mm above and shifted by (0.3,
    0.2) mm; node 5 (the centre of the lower sheet) and node 14 (the upper sheet's centre) form
    a two-node rigid body along a slanted line. The upper sheet starts at 1 mm/ms along x and
    0.5 along z. (Before the degenerate inertia was treated, this run stopped at cycle 2 with
    a shell that "lost its area".)"""
    lower, shells = plate_mesh((2, 2), (10.0, 10.0))
    upper = lower + [0.3, 0.2, 1.0]
    nodes = np.vstack([lower, upper])
    n = len(lower)
    velocity = ["*INITIAL_VELOCITY_NODE"] + [fields(n + k + 1, 1.0, 0.0, 0.5) for k in range(n)]
    return write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(2.0),
        "*DATABASE_GLSTAT\n" + fields(0.01),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.5),
        "*PART\nsheets\n" + fields(1, 1, 1),
        "*SECTION_SHELL\n" + fields(1, 2, 1.0, 3) + "\n" + fields(0.5, 0.5, 0.5, 0.5),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
        nodes_card(nodes),
        shells_card(shells) + "\n" + "\n".join(shells_card(shells + n, first_id=5).splitlines()[1:]),
        "\n".join(velocity),
        node_list_set(9, [5, n + 5]),
        "*CONSTRAINED_NODAL_RIGID_BODY\n" + fields(9, 0, 9),
    ), nodes


def test_two_node_rigid_body_between_sheets_conserves_momentum_and_energy(tmp_path, run_deck):
    deck, nodes = two_sheets_deck(tmp_path / "sheets.k")
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        momentum = results["history/glstat/momentum"][...]
        ratio = results["history/glstat/energy_ratio"][...]
        kinetic = results["history/glstat/kinetic_energy"][...]
        internal = results["history/glstat/internal_energy"][...]
        displacement = last_state(results)["displacement"][...]
    mass = 2 * DENSITY * 10.0 * 10.0 * 0.5
    expected = 0.5 * mass * np.array([1.0, 0.0, 0.5])
    print(f"momentum drift {np.abs(momentum - expected).max():.2e}, energy ratio {ratio.min():.6f} .. {ratio.max():.6f}")
    assert np.abs(momentum - expected).max() < 1e-9 * np.linalg.norm(expected)
    assert np.abs(ratio - 1.0).max() < 5e-3
    # the sheets really deform (energy went into the shells) and the joint holds its length
    assert internal.max() > 0.05 * kinetic[0]
    final = nodes + displacement
    assert abs(np.linalg.norm(final[4] - final[9 + 4]) - np.linalg.norm([0.3, 0.2, 1.0])) < 1e-9


RATE = 10.0   # kN/ms load ramp


def weld_deck(path, weld, direction=(0.0, 0.0, 1.0), nodes=((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)), end_time=1.0,
              loaded=(1, 2)):
    """Point masses (1 g) on the weld's nodes, pulled apart along `direction` by F = RATE t on
    the last node and -F on the first; one soft hexahedron away from them sets the step."""
    block = np.array([[100, 0, 0], [101, 0, 0], [101, 1, 0], [100, 1, 0],
                      [100, 0, 1], [101, 0, 1], [101, 1, 1], [100, 1, 1]], float)
    count = len(nodes)
    all_nodes = np.vstack([np.array(nodes, float), block])
    loads = ["*LOAD_NODE_POINT"]
    for axis, value in enumerate(direction):
        if value != 0.0:
            loads.append(fields(loaded[0], axis + 1, 1, -float(value)))
            loads.append(fields(loaded[1], axis + 1, 1, float(value)))
    masses = ["*ELEMENT_MASS"] + [f"{k + 1:8d}{k + 1:8d}{0.001:16.6e}" for k in range(count)]
    return write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_GLSTAT\n" + fields(0.01),
        "*DATABASE_NODOUT\n" + fields(0.01),
        "*DATABASE_HISTORY_NODE\n" + fields(*range(1, count + 1)),
        "*PART\nblock\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, 0.21, POISSON),
        nodes_card(all_nodes),
        "*ELEMENT_SOLID\n" + f"{1:8d}{1:8d}" + "".join(f"{count + k + 1:8d}" for k in range(8)),
        "\n".join(masses),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + f"{0.0:20.6e}{0.0:20.6e}\n{10.0:20.6e}{10.0 * RATE:20.6e}",
        "\n".join(loads),
        weld,
    )


def failure_time(stdout):
    line = next(line for line in stdout.splitlines() if "spot weld" in line and "fails" in line)
    return float(line.split("t =")[1].split(":")[0].split(")")[0])


def test_spot_weld_fails_when_the_normal_force_reaches_sn(tmp_path, run_deck):
    run = run_deck(weld_deck(tmp_path / "normal.k", "*CONSTRAINED_SPOTWELD_ID\n" + fields(77) + "\n" +
                             fields(1, 2, 4.0, 0.0)))
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        step = results["history/glstat/time_step"][...].max()
        failed = results["history/swforc/failed_welds"][...]
        times = results["history/swforc/time"][...]
        momentum = results["history/glstat/momentum"][...]
        node_ids = list(results["history/nodout"])
        gap = (results["history/nodout"][node_ids[1]]["displacement"][-1, 2] -
               results["history/nodout"][node_ids[0]]["displacement"][-1, 2])
    time = failure_time(run.stdout)
    print(f"weld 77 fails at {time:.5f} ms, F = SN at 0.4 ms, step {step:.2e} ms")
    assert "spot weld 77 (nodes 1, 2)" in run.stdout
    assert 0.4 <= time < 0.4 + step
    assert failed[times < 0.4].max() == 0 and failed[-1] == 1
    # equal and opposite loads: no momentum; afterwards the nodes fly apart: x = F t^2 ... > 0
    assert np.abs(momentum).max() < 1e-12
    assert gap > 1.0


def test_spot_weld_fails_on_the_combined_criterion_along_its_axis(tmp_path, run_deck):
    # (F/SN)^N + 0 = 1 with N = 3 and a shear strength that the axial load does not touch
    run = run_deck(weld_deck(tmp_path / "combined.k", "*CONSTRAINED_SPOTWELD\n" + fields(1, 2, 3.0, 5.0, 3.0, 2.0)))
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        step = results["history/glstat/time_step"][...].max()
    time = failure_time(run.stdout)
    assert 0.3 <= time < 0.3 + step


def test_spot_weld_fails_at_its_failure_time(tmp_path, run_deck):
    run = run_deck(weld_deck(tmp_path / "time.k", "*CONSTRAINED_SPOTWELD\n" + fields(1, 2, 0.0, 0.0, 0.0, 0.0, 0.25)))
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        step = results["history/glstat/time_step"][...].max()
    assert "fails at its failure time" in run.stdout
    assert 0.25 <= failure_time(run.stdout) < 0.25 + step


def test_generalized_weld_on_three_nodes_fails_at_its_force(tmp_path, run_deck):
    # three stacked nodes held as one body; the outer ones pulled apart: the force across the
    # mid-plane is F
    weld = (node_list_set(5, [1, 2, 3]) + "\n*CONSTRAINED_GENERALIZED_WELD_SPOT_ID\n" + fields(12) + "\n" +
            fields(5) + "\n" + fields(0.0, 0.0, 6.0, 0.0))
    run = run_deck(weld_deck(tmp_path / "generalized.k", weld, nodes=((0, 0, 0), (0, 0, 1), (0, 0, 2)),
                             loaded=(1, 3)))
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        step = results["history/glstat/time_step"][...].max()
        momentum = results["history/glstat/momentum"][...]
    time = failure_time(run.stdout)
    print(f"generalized weld 12 fails at {time:.5f} ms, F = SN at 0.6 ms")
    assert "spot weld 12 (nodes 1, 2, 3)" in run.stdout
    assert 0.6 <= time < 0.6 + step
    assert np.abs(momentum).max() < 1e-12


@pytest.mark.parametrize("blocks, field, message", [
    (["*CONSTRAINED_SPOTWELD\n" + fields(1, 99)], "N2", "node 99 is not defined"),
    (["*CONSTRAINED_SPOTWELD\n" + fields(1, 2) + "\n" + fields(2, 1)], "N1", "a node may be in one weld only"),
    (["*CONSTRAINED_SPOTWELD\n" + fields(1, 2, -1.0)], "SN", "must not be negative"),
    (["*CONSTRAINED_GENERALIZED_WELD_SPOT\n" + fields(42) + "\n" + fields(0.0)], "NSID", "node set 42 is not defined"),
    ([node_list_set(5, [1, 2]), "*CONSTRAINED_GENERALIZED_WELD_SPOT\n" + fields(5, 3) + "\n" + fields(0.0)], "CID",
     "local coordinate systems are not available"),
    ([node_list_set(5, [1, 2]), "*CONSTRAINED_NODAL_RIGID_BODY\n" + fields(5, 0, 5),
      "*CONSTRAINED_SPOTWELD\n" + fields(1, 2)], "N1", "belongs to rigid body 5"),
    (["*CONSTRAINED_RIGID_BODIES\n" + fields(1, 7)], "PIDS", "part 7 is not defined"),
    (["*CONSTRAINED_RIGID_BODIES\n" + fields(1, 1)], "PIDM", "part 1 is not rigid"),
    (["*CONSTRAINED_EXTRA_NODES_NODE\n" + fields(4, 1)], "PID", "rigid body 4 is not defined"),
    ([node_list_set(5, [1, 2]), "*CONSTRAINED_NODAL_RIGID_BODY\n" + fields(5, 0, 5), node_list_set(6, [2, 3]),
      "*CONSTRAINED_NODAL_RIGID_BODY\n" + fields(6, 0, 6), "*CONSTRAINED_EXTRA_NODES_NODE\n" + fields(6, 1)], "NID",
     "node 1 belongs to rigid body 5 and to rigid body 6"),
])
def test_weld_deck_errors(tmp_path, run_deck, blocks, field, message):
    deck = weld_deck(tmp_path / "bad.k", "\n".join(blocks))
    run = run_deck(deck)
    assert run.status == 2, run.stdout + run.stderr
    text = run.stdout + run.stderr
    assert f"field {field}" in text and message in text, text


def merged_bodies_deck(path):
    """Rigid cubes (side 10) centred at x = -20 (part 1) and x = +20 (part 2), part 2 merged into
    part 1 (*CONSTRAINED_RIGID_BODIES); two nodes of 1 g at (0, +-30, 0) join the body as a node
    set (*CONSTRAINED_EXTRA_NODES_SET) and one at the origin as a node (_NODE). The whole spins
    at 1 rad/ms about z through the origin, its centre of mass (the extra nodes are given the
    velocities of that spin: the body starts with the rigid fit of all its nodes' velocities)."""
    from deck_writer import block_mesh, solids_card
    cube, hexes = block_mesh((1, 1, 1), (10.0, 10.0, 10.0), origin=(-25.0, -5.0, -5.0))
    nodes = np.vstack([cube, cube + [40.0, 0.0, 0.0], [[0.0, 30.0, 0.0], [0.0, -30.0, 0.0], [0.0, 0.0, 0.0]]])
    lines = ["*ELEMENT_SOLID"]
    for k, (part, offset) in enumerate([(1, 0), (2, 8)]):
        lines.append(f"{k + 1:8d}{part:8d}" + "".join(f"{c + offset + 1:8d}" for c in hexes[0]))
    return write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(20.0),
        "*DATABASE_GLSTAT\n" + fields(0.5),
        "*DATABASE_BINARY_D3PLOT\n" + fields(10.0),
        "*PART\nleft\n" + fields(1, 1, 1),
        "*PART\nright\n" + fields(2, 1, 2),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_RIGID\n" + fields(1, DENSITY, YOUNGS, POISSON),
        "*MAT_RIGID\n" + fields(2, DENSITY, YOUNGS, POISSON),
        nodes_card(nodes),
        "\n".join(lines),
        "*ELEMENT_MASS\n" + "\n".join(f"{k:8d}{k:8d}{0.001:16.6e}" for k in (17, 18, 19)),
        node_list_set(3, [17, 18]),
        "*CONSTRAINED_RIGID_BODIES\n" + fields(1, 2),
        "*CONSTRAINED_EXTRA_NODES_SET\n" + fields(1, 3),
        "*CONSTRAINED_EXTRA_NODES_NODE\n" + fields(1, 19),
        "*INITIAL_VELOCITY_GENERATION\n" + fields(1, 2, 1.0, 0.0, 0.0, 0.0) + "\n" + fields(0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
        "*INITIAL_VELOCITY_GENERATION\n" + fields(2, 2, 1.0, 0.0, 0.0, 0.0) + "\n" + fields(0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
        "*INITIAL_VELOCITY_NODE\n" + fields(17, -30.0, 0.0, 0.0) + "\n" + fields(18, 30.0, 0.0, 0.0),
    ), nodes


def test_merged_rigid_parts_and_extra_nodes_move_as_one_body(tmp_path, run_deck):
    deck, nodes = merged_bodies_deck(tmp_path / "merged.k")
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        assert list(results["history/rbdout"]) == ["1"]
        momentum = results["history/rbdout/1/angular_momentum"][...]
        kinetic = results["history/glstat/kinetic_energy"][...]
        displacement = last_state(results)["displacement"][...]
    cube = DENSITY * 1000.0
    inertia = 2.0 * (cube * 200.0 / 12.0 + cube * 20.0**2) + 2.0 * 0.001 * 30.0**2
    print(f"L_z {momentum[0, 2]:.6e}, analytical {inertia:.6e}")
    assert momentum[:, 2] == pytest.approx(inertia, rel=1e-9)
    assert np.abs(momentum[:, :2]).max() < 1e-9 * inertia
    assert kinetic == pytest.approx(0.5 * inertia, rel=1e-9)
    # rigid: all distances kept (the extra nodes included), and it turned (20 rad)
    final = nodes + displacement
    initial_distances = np.linalg.norm(nodes[:, None] - nodes[None], axis=2)
    final_distances = np.linalg.norm(final[:, None] - final[None], axis=2)
    assert np.abs(final_distances - initial_distances).max() < 1e-9 * initial_distances.max()
    assert np.abs(displacement).max() > 10.0


def welded_sheets_deck(path):
    """Two 10 x 10 shell sheets (11 x 11 nodes each) 1 mm apart, every node pair spot-welded
    (121 welds, advanced in parallel); the sheets are peeled apart at x = 0 by a load ramp on
    that edge (up on the upper sheet, down on the lower one): the welds there fail by force,
    then the peel runs across the sheets."""
    lower, shells = plate_mesh((10, 10), (50.0, 50.0))
    upper = lower + [0.0, 0.0, 1.0]
    nodes = np.vstack([lower, upper])
    n = len(lower)
    velocity = ["*INITIAL_VELOCITY_NODE"] + [fields(n + k + 1, 0.5, 0.0, 2.0 + 0.02 * lower[k, 0])
                                             for k in range(n)]
    welds = ["*CONSTRAINED_SPOTWELD"] + [fields(k + 1, n + k + 1, 0.05, 0.05) for k in range(n)]
    edge = np.flatnonzero(np.isclose(lower[:, 0], 0.0))
    loads = ["*LOAD_NODE_POINT"] + [fields(k + 1, 3, 1, -1.0) for k in edge] + \
        [fields(n + k + 1, 3, 1, 1.0) for k in edge]
    return write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(1.0),
        "*DATABASE_GLSTAT\n" + fields(0.01),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.25),
        "*PART\nsheets\n" + fields(1, 1, 1),
        "*SECTION_SHELL\n" + fields(1, 2, 1.0, 3) + "\n" + fields(0.8, 0.8, 0.8, 0.8),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
        nodes_card(nodes),
        shells_card(shells) + "\n" + "\n".join(shells_card(shells + n, first_id=101).splitlines()[1:]),
        "\n".join(velocity),
        "\n".join(welds),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + f"{0.0:20.6e}{0.0:20.6e}\n{1.0:20.6e}{0.2:20.6e}",
        "\n".join(loads),
    )


def test_many_welds_give_the_same_results_on_one_and_three_threads(tmp_path, run_deck):
    deck = welded_sheets_deck(tmp_path / "welded.k")
    runs = [run_deck(deck, ncpu=ncpu, jobid=f"threads{ncpu}") for ncpu in (1, 3)]
    arrays = []
    for run in runs:
        assert run.status == 0, run.stdout + run.stderr
        with run.open() as results:
            arrays.append({"displacement": last_state(results)["displacement"][...],
                           "failed": results["history/swforc/failed_welds"][...],
                           "kinetic": results["history/glstat/kinetic_energy"][...],
                           "momentum": results["history/glstat/momentum"][...]})
    failed = arrays[0]["failed"]
    print(f"{failed[-1]:.0f} of 121 welds failed")
    # the edge welds fail when the edge load reaches SN (0.2 t = 0.05 at t = 0.25), the others later
    assert "spot weld 1 (nodes 1, 122) fails at t =  2.5" in runs[0].stdout
    assert ((failed > 0) & (failed < 121)).any() and np.all(np.diff(failed) >= 0)
    for name in arrays[0]:
        assert np.array_equal(arrays[0][name], arrays[1][name]), name
    # the welds conserve momentum, failing or not
    mass = 2 * DENSITY * 50.0 * 50.0 * 0.8
    assert np.abs(arrays[0]["momentum"] - arrays[0]["momentum"][0]).max() < 1e-12 * mass


def lap_joint_deck(path, shear_strength, thickness=2.0):
    """Two steel strips 10 mm wide, `thickness` thick, overlapping over 10 mm (x = 10 .. 20
    mm), the upper one `thickness` above; one spot weld joins them at (15, 5), inside the
    overlap. The lower strip is clamped at x = 0, the upper one pulled along x at x = 30 by
    F = 10 t kN (a ramp slow next to the strips' axial periods): the weld carries F in shear."""
    lower, lower_shells = plate_mesh((4, 2), (20.0, 10.0))
    upper, upper_shells = plate_mesh((4, 2), (20.0, 10.0))
    upper = upper + [10.0, 0.0, thickness]
    nodes = np.vstack([lower, upper])
    n = len(lower)
    root = np.flatnonzero(np.isclose(lower[:, 0], 0.0))
    end = n + np.flatnonzero(np.isclose(upper[:, 0], 30.0))
    weld_lower = int(np.flatnonzero(np.isclose(lower[:, 0], 15.0) & np.isclose(lower[:, 1], 5.0))[0])
    weld_upper = n + int(np.flatnonzero(np.isclose(upper[:, 0], 15.0) & np.isclose(upper[:, 1], 5.0))[0])
    loads = ["*LOAD_NODE_POINT"] + [fields(k + 1, 1, 1, 0.5 if np.isclose(nodes[k, 1], 5.0) else 0.25) for k in end]
    return write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(1.0),
        "*DATABASE_GLSTAT\n" + fields(0.01),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.5),
        "*PART\nstrips\n" + fields(1, 1, 1),
        "*SECTION_SHELL\n" + fields(1, 2, 1.0, 3) + "\n" + fields(thickness, thickness, thickness, thickness),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
        nodes_card(nodes),
        shells_card(lower_shells) + "\n" + "\n".join(shells_card(upper_shells + n, first_id=101).splitlines()[1:]),
        "*BOUNDARY_SPC_NODE\n" + "\n".join(fields(k + 1, 0, 1, 1, 1, 1, 1, 1) for k in root),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + f"{0.0:20.6e}{0.0:20.6e}\n{10.0:20.6e}{100.0:20.6e}",
        "\n".join(loads),
        "*CONSTRAINED_SPOTWELD\n" + fields(weld_lower + 1, weld_upper + 1, 0.0, shear_strength),
    )


def test_spot_weld_of_a_lap_joint_fails_in_shear(tmp_path, run_deck):
    run = run_deck(lap_joint_deck(tmp_path / "lap.k", 2.0))
    assert run.status == 0, run.stdout + run.stderr
    line = next(line for line in run.stdout.splitlines() if "fails at" in line)
    normal = float(line.split("normal force")[1].split(",")[0])
    shear = float(line.split("shear force")[1].split("(")[0])
    time = failure_time(run.stdout)
    pull = 10.0 * time
    print(line, f"pull {pull:.4f}")
    # quasi-static: the weld transmits the pull F = 10 t (within 5%); the joint turns under the
    # eccentric load (the strips bend), so part of it is normal force, and the weld fails when
    # its shear component reaches SS: within 10% of t = SS / 10
    assert np.hypot(normal, shear) == pytest.approx(pull, rel=0.05)
    assert shear >= 2.0 and abs(normal) < 0.5 * shear
    assert time == pytest.approx(0.2, rel=0.1)


def test_restart_with_welds_reproduces_the_uninterrupted_run(tmp_path):
    """The peeled sheets with dumps every 100 cycles: continued from a dump written while the
    peel runs (some welds failed, some holding), the results file is the uninterrupted one."""
    from test_restart import assert_same, contents, copy_run, restart, run_fresh
    deck = welded_sheets_deck(tmp_path / "welded.k")
    deck.write_text(deck.read_text().replace("*PART\n", "*DATABASE_BINARY_D3DUMP\n" + fields(100) + "\n*PART\n", 1))
    run_fresh(deck, tmp_path / "one", ncpu=1)
    reference = contents(tmp_path / "one" / "results.h5")
    dumps = sorted(p.name for p in (tmp_path / "one").glob("d3dump*"))
    assert len(dumps) >= 6, dumps
    failed = reference["history/swforc/failed_welds"]
    assert failed[-1] > 0
    # dumps 3 to 6: about 0.27 to 0.55 ms, while the peel runs (first failure at 0.25 ms)
    for dump in dumps[2:6]:
        target = copy_run(tmp_path / "one", tmp_path / f"restart_{dump}")
        process = restart(target / dump, 2)
        assert process.returncode == 0, process.stdout + process.stderr
        assert_same(reference, contents(target / "results.h5"), f"welds continued from {dump}")


def test_spot_weld_fails_when_a_shell_on_its_nodes_reaches_ep(tmp_path, run_deck):
    """EP of *CONSTRAINED_SPOTWELD (and EPSF of the generalized weld): the weld fails once a shell
    on one of its nodes reaches that effective plastic strain. The lap joint of elastic-plastic
    strips (MAT_024, SIGY 0.2 GPa) with no force criterion (SN = SS = 0) never fails; with EP =
    0.002 it fails between the last state (every 0.01 ms) at which the shells on its nodes are
    below 0.002 and one step after the first at which one reaches it (the runs are the same
    until then)."""
    plastic = "*MAT_PIECEWISE_LINEAR_PLASTICITY\n" + fields(1, DENSITY, YOUNGS, POISSON, 0.2, 1.0) + "\n" + fields(0.0)
    decks = {}
    for name, weld_strain in (("reference", 0.0), ("ep", 0.002)):
        deck = lap_joint_deck(tmp_path / f"{name}.k", 0.0)
        text = deck.read_text().replace("*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON), plastic)
        text = text.replace("*DATABASE_BINARY_D3PLOT\n" + fields(0.5), "*DATABASE_BINARY_D3PLOT\n" + fields(0.01))
        lines = text.splitlines()
        weld = lines.index("*CONSTRAINED_SPOTWELD") + 1
        lines[weld] = lines[weld] + fields(0.0, 0.0, 0.0, weld_strain)[:40]
        deck.write_text("\n".join(lines) + "\n")
        decks[name] = deck
    reference = run_deck(decks["reference"], jobid="reference")
    assert reference.status == 0 and "spot weld" not in reference.stdout, reference.stdout + reference.stderr
    ep = run_deck(decks["ep"], jobid="ep")
    assert ep.status == 0, ep.stdout + ep.stderr
    assert "reached the plastic strain" in ep.stdout
    failed_at = failure_time(ep.stdout)
    weld_line = decks["ep"].read_text().splitlines()[decks["ep"].read_text().splitlines().index("*CONSTRAINED_SPOTWELD") + 1]
    weld_nodes = [int(weld_line[0:10]) - 1, int(weld_line[10:20]) - 1]
    with reference.open() as results:
        connectivity = results["mesh/shells/connectivity_index"][...]
        on_weld = np.flatnonzero(np.isin(connectivity, weld_nodes).any(axis=1))
        keys = sorted(results["states"].keys())
        times = np.array([results["states"][k].attrs["time"] for k in keys])
        strain = np.array([results["states"][k]["shell_plastic_strain_peak"][...][on_weld].max() for k in keys])
        steps = np.diff(results["history/glstat/time"][...])
    reached = np.flatnonzero(strain >= 0.002)
    assert len(reached) > 0 and reached[0] > 0, strain
    first = reached[0]
    print(f"EP 0.002 reached between states at {times[first - 1]:.4f} and {times[first]:.4f} ms; "
          f"weld failed at {failed_at:.5f} ms")
    assert times[first - 1] < failed_at <= times[first] + 2.0 * steps.max()
