"""Deterministic assembly: the same deck on 1, 2 and 3 threads gives the same results file bit
for bit: every dataset of /mesh, /states and /history, every attribute, the attributes of /run
but `threads`; /timing is left out. `results_difference` names the first dataset (and index)
that differs.

Models, each but the first larger than two chunks of the fixed-order sums
(src/core/fixed_order_sum.f90), so that every parallel loop over nodes really splits:
- a small block thrown at a planar rigid wall;
- the shell tube of inputs/tube_crush, whose drilling-rate removal books external work every
  cycle;
- penalty contact: a shell plate and a solid block hitting a solid slab (single surface of
  shells on solids; surface to surface of solids on solids with friction, soft constraint and
  frequent bucket sorts);
- a coupled meshfree / finite element bar hitting a rigid wall with its EFG end;
- rigid bodies: a turning rigid block (*MAT_RIGID) hitting a free slab (nodes-to-surface
  contact), the slab's one edge a rigid part on shared nodes, its other edge a
  *CONSTRAINED_NODAL_RIGID_BODY with a lumped mass.
Each also checks something physical of its run, so that the comparison is not one of empty
results.

The runs wait passively (OMP_WAIT_POLICY=PASSIVE unless set): on a shared 2-core machine the
spinning threads of a 2-thread run otherwise wait on each other for long (the tube's 2-thread
run took 32 s instead of 5 s). Every parallel loop of src/ names its schedule, so OMP_SCHEDULE
does not change them; the dynamic ones still hand blocks to threads in a different order each
run.
"""
import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from deck_writer import block_mesh, efg_section, fields, node_list_set, nodes_card, plate_mesh, shells_card, \
    solids_card, write_deck
from test_rigid_wall import impact_deck

REPOSITORY = Path(__file__).resolve().parents[2]
THREAD_COUNTS = (1, 2, 3)
SUM_CHUNK_SIZE = 4096          # sum_chunk_size of src/core/fixed_order_sum.f90
# attributes of /run that may differ between thread counts
RUN_ATTRIBUTES_ALLOWED_TO_DIFFER = {"threads", "run_id"}   # run_id: a random identity of each run

DENSITY, MODULUS, POISSON = 7.85e-6, 210.0, 0.3     # kg/mm^3, GPa: mm, ms, kg, kN units
YIELD, TANGENT = 0.3, 1.0                           # GPa


@pytest.fixture(autouse=True)
def passive_waiting(monkeypatch):
    """OMP_WAIT_POLICY=PASSIVE for the runs of this module, unless the environment sets it."""
    monkeypatch.setenv("OMP_WAIT_POLICY", os.environ.get("OMP_WAIT_POLICY", "PASSIVE"))


# ---------------------------------------------------------------------------------------------
# comparing results files

def datasets(results):
    """Every dataset of an open results file but /timing: {name: values}."""
    found = {}

    def visit(name, item):
        if isinstance(item, h5py.Dataset) and not name.startswith("timing"):
            found[name] = item[...]

    results.visititems(visit)
    return found


def _objects(results):
    """{name: object} of every group and dataset but /timing, and the root as "/"."""
    found = {"/": results}

    def visit(name, item):
        if name != "timing" and not name.startswith("timing/"):
            found[name] = item

    results.visititems(visit)
    return found


def _first_difference(a, b):
    """None when the arrays are the same bit for bit, else (index, value a, value b) of the
    first element that is not (index None for a different shape or type)."""
    a, b = np.atleast_1d(np.asarray(a)), np.atleast_1d(np.asarray(b))
    if a.shape != b.shape or a.dtype != b.dtype:
        return None, f"{a.dtype}{a.shape}", f"{b.dtype}{b.shape}"
    if a.dtype.kind in "biufc":
        # the bits of each element: NaN equals itself, 0.0 differs from -0.0
        bits = lambda x: np.ascontiguousarray(x).view(np.uint8).reshape(x.shape + (x.dtype.itemsize,))
        differ = (bits(a) != bits(b)).any(axis=-1)
    else:
        differ = np.array([x != y for x, y in zip(a.ravel(), b.ravel())], bool).reshape(a.shape)
    if not differ.any():
        return None
    index = np.unravel_index(int(np.flatnonzero(differ)[0]), a.shape)
    return tuple(int(k) for k in index), a[index], b[index]


def _text(value):
    """A value of a results file as Python writes it (17 digits for a float)."""
    value = value.item() if isinstance(value, np.generic) else value
    return repr(value.decode() if isinstance(value, bytes) else value)


def _position(index, shape):
    return "" if index is None or len(shape) == 0 else f"[{', '.join(map(str, index))}]"


def results_difference(reference_path, other_path, leave_out_rows=None):
    """How two results files differ: '' when every dataset and attribute (but /timing and the
    /run attributes in RUN_ATTRIBUTES_ALLOWED_TO_DIFFER) is the same bit for bit, else a
    message naming the first differing dataset (in name order) and index, its two values, and
    which others differ. `leave_out_rows` {dataset base name: row indices} leaves rows of
    those datasets out of the comparison (a known defect that is checked on its own)."""
    leave_out_rows = leave_out_rows or {}
    problems = []
    with h5py.File(reference_path, "r") as first, h5py.File(other_path, "r") as second:
        a, b = _objects(first), _objects(second)
        if a.keys() != b.keys():
            only_a, only_b = sorted(a.keys() - b.keys()), sorted(b.keys() - a.keys())
            problems.append(f"objects only in the first: {only_a[:5]}, only in the second: {only_b[:5]}")
        for name in sorted(a.keys() & b.keys()):
            x, y = a[name], b[name]
            if isinstance(x, h5py.Dataset) != isinstance(y, h5py.Dataset):
                problems.append(f"{name}: a dataset in one file, a group in the other")
                continue
            if isinstance(x, h5py.Dataset):
                values_a, values_b = x[...], y[...]
                rows = leave_out_rows.get(name.rsplit("/", 1)[-1])
                if rows is not None and values_a.shape == values_b.shape:
                    values_b = values_b.copy()
                    values_b[rows] = values_a[rows]
                found = _first_difference(values_a, values_b)
                if found is not None:
                    index, value_a, value_b = found
                    problems.append(f"{name}{_position(index, x.shape)}: {_text(value_a)} != {_text(value_b)}")
            skip = RUN_ATTRIBUTES_ALLOWED_TO_DIFFER if name == "run" else set()
            keys_a, keys_b = set(x.attrs.keys()) - skip, set(y.attrs.keys()) - skip
            if keys_a != keys_b:
                problems.append(f"{name}: attributes {sorted(keys_a ^ keys_b)} in one file only")
            for key in sorted(keys_a & keys_b):
                found = _first_difference(x.attrs[key], y.attrs[key])
                if found is not None:
                    index, value_a, value_b = found
                    problems.append(f"{name} attribute {key}{_position(index, np.shape(x.attrs[key]))}: "
                                    f"{_text(value_a)} != {_text(value_b)}")
    if not problems:
        return ""
    others = [problem.split(":")[0] for problem in problems[1:]]
    more = f" (and {len(others)} more: {'; '.join(others[:5])}{', ...' if len(others) > 5 else ''})" if others else ""
    return problems[0] + more


def run_on_threads(run_deck, deck, counts=THREAD_COUNTS, cycles=None):
    """The deck run once per thread count; every run ends normally, on the threads asked for
    (and after `cycles` cycles). Returns the runs."""
    runs = [run_deck(deck, ncpu=n) for n in counts]
    for threads, run in zip(counts, runs):
        assert run.status == 0, f"ncpu={threads}:\n" + run.stdout + run.stderr
        with run.open() as results:
            assert results["run"].attrs["threads"] == threads
            if cycles is not None:
                assert results["run"].attrs["cycles"] == cycles
    return runs


def assert_identical_results(runs, counts=THREAD_COUNTS, leave_out_rows=None):
    """The results of runs[1:] the same as those of runs[0] (see results_difference)."""
    for threads, run in zip(counts[1:], runs[1:]):
        difference = results_difference(runs[0].results, run.results, leave_out_rows)
        assert not difference, f"{counts[0]} and {threads} threads differ: {difference}"


def node_count(run):
    with run.open() as results:
        return len(results["mesh/nodes/ids"])


def test_comparison_names_the_first_differing_dataset_and_index(tmp_path):
    """The helper itself: bit differences (also -0.0 against 0.0), attributes, missing datasets."""
    def write(path, velocity, time, threads, extra=False):
        with h5py.File(path, "w") as results:
            results.create_dataset("history/glstat/kinetic_energy", data=[1.0, 2.0, 3.0])
            results.create_dataset("states/000001/velocity", data=velocity)
            results["states/000001"].attrs["time"] = time
            results.create_group("run").attrs["threads"] = threads
            results["run"].attrs["status"] = "normal termination"
            results.create_group("timing").attrs["wall_s"] = float(threads)
            if extra:
                results.create_dataset("history/rcforc/1/force", data=[0.0])
        return path

    velocity = np.arange(12.0).reshape(4, 3)
    reference = write(tmp_path / "a.h5", velocity, 0.5, 1)
    assert results_difference(reference, write(tmp_path / "b.h5", velocity, 0.5, 2)) == ""
    changed = velocity.copy()
    changed[2, 1] = np.nextafter(changed[2, 1], 10.0)
    message = results_difference(reference, write(tmp_path / "c.h5", changed, 0.5, 3))
    assert message.startswith("states/000001/velocity[2, 1]: "), message
    signed = velocity.copy()
    signed[0, 0] = -0.0
    assert results_difference(reference, write(tmp_path / "d.h5", signed, 0.5, 1)).startswith(
        "states/000001/velocity[0, 0]")
    assert results_difference(reference, write(tmp_path / "e.h5", velocity, 0.25, 1)).startswith(
        "states/000001 attribute time: 0.5 != 0.25")
    assert "only in the second: ['history/rcforc', 'history/rcforc/1'" in results_difference(
        reference, write(tmp_path / "f.h5", velocity, 0.5, 1, extra=True))
    # rows left out: the same file but for them
    assert results_difference(reference, tmp_path / "c.h5", leave_out_rows={"velocity": [2]}) == ""
    assert results_difference(reference, tmp_path / "c.h5", leave_out_rows={"velocity": [1, 3]}) != ""


# ---------------------------------------------------------------------------------------------
# the models

def test_wall_impact_is_identical_for_one_two_and_three_threads(tmp_path, run_deck):
    """A small block (216 nodes, 125 hexahedra: one sum chunk) thrown at a planar rigid wall."""
    runs = run_on_threads(run_deck, impact_deck(tmp_path / "impact.k"))
    with runs[0].open() as results:
        assert any(name.startswith("states/") for name in datasets(results))
        assert np.abs(results["history/rwforc/7/force"][...]).max() > 0.0
    assert_identical_results(runs)


def test_shell_drilling_work_is_identical_for_one_two_and_three_threads(tmp_path, run_deck):
    """The tube of inputs/tube_crush with 2 mm shells (10,100 nodes: three chunks of the fixed-order
    sum) for 300 cycles: the drilling-rate removal books external work at every cycle, and the
    whole results file must be the same bit for bit on 1, 2 and 3 threads."""
    deck = tmp_path / "tube.k"
    subprocess.run([sys.executable, str(REPOSITORY / "inputs" / "tube_crush" / "generate_tube.py"),
                    "--element", "2", "--crush", "15", "--output", str(deck)], check=True, capture_output=True)
    text = deck.read_text()
    termination = "*CONTROL_TERMINATION\n"
    start = text.index(termination) + len(termination)
    end_time = text[start:].split("\n", 1)[0]
    deck.write_text(text.replace(termination + end_time, termination + f"{end_time.strip():>10}{300:>10}", 1))
    runs = run_on_threads(run_deck, deck, cycles=300)
    with runs[0].open() as results:
        assert results["history/glstat/external_work"][-1] != 0.0
    assert_identical_results(runs)


CONTACT_CYCLES = 500
# the plate's centre node and the block's bottom corner at x = 67.1 mm, y = 10.3 mm
CONTACT_HISTORY_NODES = (41 * 41 * 5 + 221, 41 * 41 * 5 + 21 * 21 + 7 * 7 * 5 - 34)


def contact_deck(path):
    """A 80 x 80 x 8 mm slab of hexahedra (40 x 40 x 4, part 1, bottom held) hit at 20 mm/ms by
    a 40 x 40 mm plate of 2 mm shells (20 x 20, part 2) and by a 12 x 12 x 8 mm block of
    hexahedra (6 x 6 x 4, part 3) that also slides along x at 5 mm/ms; both start 0.1 mm above
    the slab and their meshes do not line up with it. Contact 11: single surface of the plate
    and the slab (shells on solids); contact 12: block on the slab, surface to surface with
    Coulomb friction 0.2, soft constraint and a bucket sort every 10 cycles. Elastic-plastic
    steel. 9,091 nodes (three sum chunks), 6,544 solids and 400 shells."""
    slab_nodes, slab_elements = block_mesh((40, 40, 4), (80.0, 80.0, 8.0))
    plate_nodes, plate_shells = plate_mesh((20, 20), (40.0, 40.0))
    plate_nodes = plate_nodes + [5.3, 30.7, 8.0 + 1.0 + 0.1]     # contact surface t/2 below the mid-surface
    block_nodes, block_elements = block_mesh((6, 6, 4), (12.0, 12.0, 8.0), origin=(55.1, 10.3, 8.1))
    slab, plate = len(slab_nodes), len(plate_nodes)
    bottom = [k + 1 for k in np.flatnonzero(np.isclose(slab_nodes[:, 2], 0.0))]
    return write_deck(
        path,
        "*TITLE\nplate and block hitting a slab",
        "*CONTROL_TERMINATION\n" + fields(1.0, CONTACT_CYCLES),
        "*DATABASE_GLSTAT\n" + fields(0.001),
        "*DATABASE_MATSUM\n" + fields(0.001),
        "*DATABASE_RCFORC\n" + fields(0.001),
        "*DATABASE_NODOUT\n" + fields(0.001),
        "*DATABASE_HISTORY_NODE\n" + fields(*CONTACT_HISTORY_NODES),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.02),
        "*PART\nslab\n" + fields(1, 1, 1),
        "*PART\nplate\n" + fields(2, 2, 1),
        "*PART\nblock\n" + fields(3, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*SECTION_SHELL\n" + fields(2, 2, 1.0, 3) + "\n" + fields(2.0, 2.0, 2.0, 2.0),
        "*MAT_PLASTIC_KINEMATIC\n" + fields(1, DENSITY, MODULUS, POISSON, YIELD, TANGENT, 1.0) + "\n" +
        fields(0.0, 0.0),
        node_list_set(1, bottom),
        "*BOUNDARY_SPC_SET\n" + fields(1, 0, 1, 1, 1),
        "*INITIAL_VELOCITY_GENERATION\n" + fields(2, 2, 0.0, 0.0, 0.0, -20.0) + "\n" + fields(*[0.0] * 5, 1.0) + "\n" +
        fields(3, 2, 0.0, 5.0, 0.0, -20.0) + "\n" + fields(*[0.0] * 5, 1.0),
        "*SET_PART_LIST\n" + fields(1) + "\n" + fields(1, 2),
        "*CONTACT_AUTOMATIC_SINGLE_SURFACE_ID\n" + fields(11) + "plate\n" + fields(1, 0, 2) + "\n" + fields(0.0) +
        "\n" + fields(1.0),
        # soft constraint, candidate lists rebuilt at least every 10 cycles
        "*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE_ID\n" + fields(12) + "block\n" + fields(3, 1, 3, 3) + "\n" +
        fields(0.2, 0.2) + "\n" + fields(1.0) + "\n" + fields(1, 0.1, 0, 0.0, 0, 0, 10),
        nodes_card(np.vstack([slab_nodes, plate_nodes, block_nodes])),
        solids_card(slab_elements, part_id=1) + "\n" +
        "\n".join(solids_card(block_elements, part_id=3, first_id=len(slab_elements) + 1,
                              first_node_id=slab + plate + 1).splitlines()[1:]),
        shells_card(plate_shells, part_id=2, first_id=len(slab_elements) + len(block_elements) + 1,
                    first_node_id=slab + 1),
    )


def test_contact_is_identical_for_one_two_and_three_threads(tmp_path, run_deck):
    runs = run_on_threads(run_deck, contact_deck(tmp_path / "contact.k"), cycles=CONTACT_CYCLES)
    assert node_count(runs[0]) > 2 * SUM_CHUNK_SIZE
    with runs[0].open() as results:
        single = results["history/rcforc/11/force"][...]
        block = results["history/rcforc/12/force"][...]
        contact_energy = results["history/glstat/contact_energy"][...]
        slab_energy = results["history/matsum/1/internal_energy"][-1]
        plate_centre, block_corner = (results[f"history/nodout/{node}/velocity"][...]
                                      for node in CONTACT_HISTORY_NODES)
    print(f"contact: largest force single surface {np.abs(single).max():.3g} kN, block "
          f"{np.abs(block[:, 2]).max():.3g} kN (friction {np.abs(block[:, 0]).max():.3g} kN), contact energy up to "
          f"{contact_energy.max():.3g}, slab internal energy {slab_energy:.3g}; plate centre and block corner "
          f"velocities at the end {plate_centre[-1]}, {block_corner[-1]} mm/ms")
    # both came down at 20 mm/ms and bounced off the slab; friction slowed the block's sliding
    assert plate_centre[0, 2] == -20.0 and plate_centre[-1, 2] > 5.0
    assert block_corner[0, 2] == -20.0 and block_corner[-1, 2] > 5.0
    assert block[:, 2].max() > 0.0 and block[:, 0].min() < 0.0 and block_corner[-1, 0] < 0.5 * 5.0
    assert np.abs(single[:, 2]).max() > 0.0
    assert contact_energy.max() > 0.0 and slab_energy > 0.0
    assert_identical_results(runs)


EFG_CYCLES = 400


def meshfree_deck(path):
    """A 48 x 14 x 12 mm bar (1 mm cells) flying at 50 mm/ms along -x into a planar rigid wall
    at x = 0 (0.05 mm away); its first 6 mm are an EFG part (part 1, 1,008 cells), the rest
    one-point hexahedra with hourglass control (part 2), sharing the interface nodes.
    Elastic-plastic steel. 9,555 nodes (three sum chunks)."""
    nodes, elements = block_mesh((48, 14, 12), (48.0, 14.0, 12.0), origin=(0.05, 0.0, 0.0))
    meshfree = nodes[elements].mean(axis=1)[:, 0] < 6.05
    return write_deck(
        path,
        "*TITLE\ncoupled EFG / FE bar against a wall",
        "*CONTROL_TERMINATION\n" + fields(1.0, EFG_CYCLES),
        "*DATABASE_GLSTAT\n" + fields(0.0005),
        "*DATABASE_MATSUM\n" + fields(0.0005),
        "*DATABASE_RWFORC\n" + fields(0.0005),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.01),
        "*PART\nmeshfree\n" + fields(1, 1, 1, 0, 1),
        "*PART\nfinite elements\n" + fields(2, 2, 1, 0, 1),
        efg_section(1, 1.5),
        "*SECTION_SOLID\n" + fields(2, 1),
        "*HOURGLASS\n" + fields(1, 4, 0.1),
        "*MAT_PLASTIC_KINEMATIC\n" + fields(1, DENSITY, MODULUS, POISSON, YIELD, TANGENT, 1.0) + "\n" +
        fields(0.0, 0.0),
        "*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields(-50.0, 0.0, 0.0),
        "*RIGIDWALL_PLANAR_ID\n" + fields(5) + "wall\n" + fields(0) + "\n" + fields(0.0, 0.0, 0.0, 1.0, 0.0, 0.0),
        nodes_card(nodes),
        solids_card(elements[meshfree], part_id=1) + "\n" +
        "\n".join(solids_card(elements[~meshfree], part_id=2, first_id=100001).splitlines()[1:]),
    )


def test_meshfree_model_is_identical_for_one_two_and_three_threads(tmp_path, run_deck):
    """With 8 points per cell the EFG part has 126 blocks of 64 points in 24 colours of 3 to 8
    blocks: with 2 threads the colours of 3 blocks, with 3 threads those of 3 and 4 compute
    their stresses ahead of the colour loop (efg_forces' runs_fused), the others in it."""
    runs = run_on_threads(run_deck, meshfree_deck(tmp_path / "meshfree.k"), cycles=EFG_CYCLES)
    assert node_count(runs[0]) > 2 * SUM_CHUNK_SIZE
    with runs[0].open() as results:
        assert list(results["mesh/parts/formulation"][...]) == [b"efg", b"fe"]
        particles = results["timing"].attrs["efg_particles"]
        meshfree_energy = results["history/matsum/1/internal_energy"][...]
        meshfree_cells = results["mesh/solids/part_ids"][...] == 1
        plastic = results["states"][sorted(results["states"])[-1]]["solid_plastic_strain"][...][meshfree_cells]
        wall = results["history/rwforc/5/force"][...]
    print(f"meshfree: {particles} particles, EFG internal energy {meshfree_energy[-1]:.3g}, largest plastic strain "
          f"of its cells {plastic.max():.3g}, largest wall force {np.abs(wall[:, 0]).max():.3g} kN")
    assert particles == 5 * 13 * 11         # the interior nodes of the 6 x 14 x 12 cells
    assert meshfree_energy[-1] > 0.0 and plastic.max() > 0.0
    assert np.abs(wall[:, 0]).max() > 0.0
    assert_identical_results(runs)


RIGID_CYCLES = 500


def rigid_deck(path):
    """A free 72 x 72 x 10 mm slab (36 x 36 x 5 hexahedra of elastic-plastic steel, part 1) hit
    by a rigid block (*MAT_RIGID, 12 x 12 x 6 mm, 6 x 6 x 3 hexahedra, part 2) at 30 mm/ms,
    turning at 2 rad/ms about y so that an edge lands first (contact 21, the block's nodes on
    the slab's faces, friction 0.1). The slab's first column of elements (x < 2 mm) is a rigid
    part on shared nodes (part 3); its nodes at x = 72 mm are a *CONSTRAINED_NODAL_RIGID_BODY
    (100) with a 0.01 kg *ELEMENT_MASS. 8,410 nodes (three sum chunks), 6,588 solids."""
    slab_nodes, slab_elements = block_mesh((36, 36, 5), (72.0, 72.0, 10.0))
    block_nodes, block_elements = block_mesh((6, 6, 3), (12.0, 12.0, 6.0), origin=(40.3, 30.7, 10.1))
    slab = len(slab_nodes)
    edge = slab_nodes[slab_elements].mean(axis=1)[:, 0] < 2.0
    far_edge = [k + 1 for k in np.flatnonzero(np.isclose(slab_nodes[:, 0], 72.0))]
    lines = ["*ELEMENT_SOLID"]
    for k, corners in enumerate(slab_elements):
        lines.append(f"{k + 1:8d}{3 if edge[k] else 1:8d}" + "".join(f"{c + 1:8d}" for c in corners))
    for k, corners in enumerate(block_elements):
        lines.append(f"{len(slab_elements) + k + 1:8d}{2:8d}" + "".join(f"{c + slab + 1:8d}" for c in corners))
    return write_deck(
        path,
        "*TITLE\nrigid block hitting a slab with rigid edges",
        "*CONTROL_TERMINATION\n" + fields(1.0, RIGID_CYCLES),
        "*DATABASE_GLSTAT\n" + fields(0.001),
        "*DATABASE_MATSUM\n" + fields(0.001),
        "*DATABASE_RCFORC\n" + fields(0.001),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.02),
        "*PART\nslab\n" + fields(1, 1, 1),
        "*PART\nrigid block\n" + fields(2, 1, 2),
        "*PART\nrigid edge\n" + fields(3, 1, 2),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_PLASTIC_KINEMATIC\n" + fields(1, DENSITY, MODULUS, POISSON, YIELD, TANGENT, 1.0) + "\n" +
        fields(0.0, 0.0),
        "*MAT_RIGID\n" + fields(2, DENSITY, MODULUS, POISSON),
        node_list_set(100, far_edge),
        "*CONSTRAINED_NODAL_RIGID_BODY\n" + fields(100, 0, 100),
        "*ELEMENT_MASS\n" + f"{1:8d}{far_edge[len(far_edge) // 3]:8d}{0.01:16.6e}",
        # -30 mm/ms along z and 2 rad/ms about y through the block's centre
        "*INITIAL_VELOCITY_GENERATION\n" + fields(2, 2, 2.0, 0.0, 0.0, -30.0) + "\n" +
        fields(46.3, 36.7, 13.1, 0.0, 1.0, 0.0),
        node_list_set(200, list(range(slab + 1, slab + len(block_nodes) + 1))),
        "*CONTACT_AUTOMATIC_NODES_TO_SURFACE_ID\n" + fields(21) + "block\n" + fields(200, 1, 4, 3) + "\n" +
        fields(0.1, 0.1) + "\n" + fields(1.0),
        nodes_card(np.vstack([slab_nodes, block_nodes])),
        "\n".join(lines),
    )


def test_rigid_bodies_are_identical_for_one_two_and_three_threads(tmp_path, run_deck):
    runs = run_on_threads(run_deck, rigid_deck(tmp_path / "rigid.k"), cycles=RIGID_CYCLES)
    assert node_count(runs[0]) > 2 * SUM_CHUNK_SIZE
    with runs[0].open() as results:
        assert list(results["mesh/parts/formulation"][...]) == [b"fe", b"rigid", b"rigid"]
        rigid_elements = results["mesh/solids/part_ids"][...] != 1
        bodies = {int(name): {key: results[f"history/rbdout/{name}/{key}"][...]
                              for key in ("displacement", "velocity", "angular_momentum")}
                  for name in results["history/rbdout"]}
        contact = results["history/rcforc/21/force"][...]
        slab_energy = results["history/matsum/1/internal_energy"][-1]
    block = bodies[2]
    print(f"rigid: block velocity {block['velocity'][0]} -> {block['velocity'][-1]} mm/ms, angular momentum "
          f"{block['angular_momentum'][0]} -> {block['angular_momentum'][-1]}, edge bodies moved "
          f"{np.linalg.norm(bodies[3]['displacement'][-1]):.3g} and "
          f"{np.linalg.norm(bodies[100]['displacement'][-1]):.3g} mm, largest contact force "
          f"{np.abs(contact[:, 2]).max():.3g} kN, slab internal energy {slab_energy:.3g}")
    assert sorted(bodies) == [2, 3, 100]
    # the block was stopped and thrown back, its spin changed; the slab's edge bodies, at rest
    # at first, moved with the slab
    assert block["velocity"][0, 2] == pytest.approx(-30.0) and block["velocity"][-1, 2] > 0.0
    assert np.abs(block["angular_momentum"][-1] - block["angular_momentum"][0]).max() > \
        0.1 * np.abs(block["angular_momentum"][0]).max()
    for body in (3, 100):
        assert np.abs(bodies[body]["velocity"][0]).max() == 0.0
        assert np.abs(bodies[body]["displacement"][-1]).max() > 1e-3
    assert contact[:, 2].max() > 0.0 and slab_energy > 0.0
    assert_identical_results(runs)
    # the elements of rigid parts have no stress: their rows are zero (they were uninitialised
    # memory, different on every run)
    rows = np.flatnonzero(rigid_elements)
    with runs[0].open() as results:
        for name in results["states"]:
            assert not np.any(results[f"states/{name}/solid_stress"][...][rows])
            assert not np.any(results[f"states/{name}/solid_plastic_strain"][...][rows])
