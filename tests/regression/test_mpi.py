"""Distributed runs (MPI, docs/parallel.md): `mpirun -np N bin/crashfree` gives the results file
of the one-rank run bit for bit, for N = 1, 2, 3 ranks and with 2 threads per rank, on a contact
model, a coupled meshfree / finite element model, the side-impact dummy (meshfree solids and
meshfree shells coupled to FE shells, contact, rigid bodies), a shell model with elements that
erode, a rigid-body model and spot welds that fail by plastic strain on FE and on meshfree
shells (the coupled model also on 4 ranks); the meshfree blocks are shared out among the ranks as the finite
elements' (the partition report's computed blocks); a run continued from a restart dump on another number of ranks gives the
uninterrupted run's file, also after SIGTERM to mpirun (every rank stops after the same cycle). Every dataset and attribute is compared (test_threads'
comparison) but /timing, the /run attributes that may differ between runs (threads, run_id)
and /run/partition, the partition report, which says how the ranks shared the model out.

The decks are those of test_threads, shortened; each test also checks something physical of
its run. The runs are oversubscribed on this small machine (--oversubscribe, one thread per
rank, passive waiting). Skipped, saying why, only when bin/crashfree was built without MPI or
mpirun is missing.
"""
from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from conftest import BINARY
from deck_writer import block_mesh, fields, nodes_card, plate_mesh, shells_card, solids_card, write_deck
from test_contact import head_on_deck as contact_head_on_deck
from test_rigid_wall import impact_deck
from test_threads import (DENSITY, MODULUS, POISSON, TANGENT, YIELD, _first_difference, _objects, _position, _text,
                          contact_deck, meshfree_deck, rigid_deck)

RANK_COUNTS = (1, 2, 3)
CYCLES = 100
# what may differ between runs on different numbers of ranks (besides /timing)
RUN_ATTRIBUTES_ALLOWED_TO_DIFFER = {"threads", "run_id"}
RANK_REPORT = "run/partition"
SIDE_IMPACT_GENERATOR = Path(__file__).resolve().parents[2] / "inputs" / "side_impact" / "generate_side_impact.py"


def mpi_missing_reason():
    """Why the MPI runs cannot be made here ("" when they can)."""
    if shutil.which("mpirun") is None:
        return "mpirun is not installed (tools/install_dependencies.sh installs Open MPI)"
    linked = subprocess.run(["ldd", str(BINARY)], capture_output=True, text=True).stdout
    if "libmpi" not in linked:
        return f"{BINARY} was built without MPI (make builds with it when mpifort is installed)"
    return ""


@pytest.fixture(autouse=True)
def require_mpi():
    if not BINARY.exists():
        pytest.fail(f"{BINARY} is missing: build it with make")
    reason = mpi_missing_reason()
    if reason:
        pytest.skip(reason)


def environment(threads):
    """Root may start mpirun (the CI runner is root); the threads asked for, passive waiting."""
    return dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
                OMP_NUM_THREADS=str(threads), CRASHFREE_OVERSUBSCRIBE="1",
                OMP_WAIT_POLICY=os.environ.get("OMP_WAIT_POLICY", "PASSIVE"))


def solver(ranks, arguments, threads=1, timeout=300.0):
    """bin/crashfree under `mpirun -np ranks` (ranks None: started alone, without mpirun)."""
    command = [str(BINARY), *map(str, arguments), f"ncpu={threads}"]
    if ranks is not None:
        command = ["mpirun", "--oversubscribe", "-np", str(ranks), *command]
    return subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=environment(threads))


def run(deck, output, ranks, threads=1):
    """The results file of the run; its standard output is kept beside it (stdout.txt)."""
    process = solver(ranks, [f"i={deck}", f"outdir={output}"], threads)
    assert process.returncode == 0, f"-np {ranks} ncpu={threads}:\n" + process.stdout + process.stderr
    (output / "stdout.txt").write_text(process.stdout)
    return output / "results.h5"


def contact_pairs_per_rank(output):
    """The first rank's count of the contact pair records each rank sent over the run (its last
    print)."""
    marker = "contact pair records sent per rank over the run:"
    lines = [line for line in (output / "stdout.txt").read_text().splitlines() if marker in line]
    assert lines, f"no '{marker}' in {output / 'stdout.txt'}"
    return [int(value) for value in lines[-1].split(marker)[1].split()]


def results_difference(reference_path, other_path):
    """'' when the two results files are the same bit for bit (see the module comment), else
    the first difference and how many more."""
    problems = []
    with h5py.File(reference_path, "r") as first, h5py.File(other_path, "r") as second:
        a, b = _objects(first), _objects(second)
        a = {name: item for name, item in a.items() if not name.startswith(RANK_REPORT)}
        b = {name: item for name, item in b.items() if not name.startswith(RANK_REPORT)}
        if a.keys() != b.keys():
            problems.append(f"objects in one file only: {sorted(a.keys() ^ b.keys())[:5]}")
        for name in sorted(a.keys() & b.keys()):
            x, y = a[name], b[name]
            if isinstance(x, h5py.Dataset) and isinstance(y, h5py.Dataset):
                found = _first_difference(x[...], y[...])
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
                    problems.append(f"{name} attribute {key}: {_text(found[1])} != {_text(found[2])}")
    if not problems:
        return ""
    return problems[0] + (f" (and {len(problems) - 1} more)" if len(problems) > 1 else "")


def assert_same_on_every_rank_count(deck, tmp_path, counts=RANK_COUNTS, threads=1):
    """The deck run alone (the reference) and under mpirun on each count: identical files.
    Returns the reference results file."""
    reference = run(deck, tmp_path / "alone", None, threads)
    for ranks in counts:
        other = run(deck, tmp_path / f"np{ranks}_ncpu{threads}", ranks, threads)
        difference = results_difference(reference, other)
        assert not difference, f"mpirun -np {ranks} ncpu={threads} differs from the run alone: {difference}"
    return reference


def shortened(path, cycles=CYCLES):
    """The deck's *CONTROL_TERMINATION with ENDCYC `cycles` (its ENDTIM kept)."""
    text = path.read_text()
    termination = "*CONTROL_TERMINATION\n"
    start = text.index(termination) + len(termination)
    end_time = text[start:].split("\n", 1)[0][:10]
    path.write_text(text.replace(termination + text[start:].split("\n", 1)[0],
                                 termination + end_time + f"{cycles:>10}", 1))
    return path


def brittle(path, failure_strain):
    """The steel of test_threads' decks with FS (*MAT_PLASTIC_KINEMATIC): elements erode."""
    steel = "*MAT_PLASTIC_KINEMATIC\n" + fields(1, DENSITY, MODULUS, POISSON, YIELD, TANGENT, 1.0) + "\n"
    text = path.read_text()
    assert steel + fields(0.0, 0.0) in text
    path.write_text(text.replace(steel + fields(0.0, 0.0), steel + fields(0.0, 0.0, failure_strain)))
    return path


def test_contact_model_is_identical_on_one_two_and_three_ranks(tmp_path):
    """test_threads' plate and block hitting a slab (penalty contacts, 6,544 solids, 400 shells):
    the contact forces of every rank count are those of the run alone; the plate and the block
    bounced."""
    deck = shortened(contact_deck(tmp_path / "contact.k"))
    reference = assert_same_on_every_rank_count(deck, tmp_path)
    # the ranks shared the contact pairs out (each computed some), yet the forces are the same
    for ranks in [count for count in RANK_COUNTS if count > 1]:
        pairs = contact_pairs_per_rank(tmp_path / f"np{ranks}_ncpu1")
        assert len(pairs) == ranks and min(pairs) > 0, pairs
        # every rank's phase seconds, a row per rank, for the balance
        with h5py.File(tmp_path / f"np{ranks}_ncpu1" / "results.h5", "r") as results:
            names = [name.decode() for name in results["timing/rank_column_names"][...]]
            assert results["timing/rank_seconds"].shape == (ranks, len(names))
            assert {"internal_forces", "contact", "nodal_exchange", "nodal_exchange_wait"} <= set(names)
    with h5py.File(reference, "r") as results:
        assert np.abs(results["history/rcforc/12/force"][...][:, 2]).max() > 0.0
        assert results["history/glstat/contact_energy"][...].max() > 0.0
        ratio = results["history/glstat/energy_ratio"][...]
    assert np.all(np.abs(ratio - 1.0) < 0.01), ratio


def test_contact_model_with_two_threads_per_rank(tmp_path):
    """Two ranks of two threads each: the same file as one rank of two threads."""
    deck = shortened(contact_deck(tmp_path / "contact.k"))
    assert_same_on_every_rank_count(deck, tmp_path, counts=(2,), threads=2)


def assert_shared_out(results_path, kinds):
    """The partition report of a run on several ranks: every rank computes some but not all of
    the blocks of each of `kinds`, and together they compute all (owned and ghost blocks).
    Returns {kind: computed blocks per rank}."""
    with h5py.File(results_path, "r") as results:
        partition = results[RANK_REPORT]
        names = [name.decode() for name in partition["kind_names"][...]]
        computed = partition["rank_computed_blocks"][...]      # (ranks, kinds)
        total = partition["kind_blocks"][...]
    shared = {}
    for kind in kinds:
        column = names.index(kind)
        blocks = computed[:, column]
        assert np.all(blocks > 0) and np.all(blocks < total[column]), (kind, blocks, total[column])
        assert blocks.sum() >= total[column], (kind, blocks, total[column])
        shared[kind] = blocks
    return shared


def test_meshfree_model_is_identical_on_one_two_and_three_ranks(tmp_path):
    """test_threads' coupled EFG / FE bar against a rigid wall: the meshfree part's point blocks
    are shared out among the ranks with the finite elements; the wall force and the meshfree
    part's energy of every rank count are those of the run alone."""
    deck = shortened(meshfree_deck(tmp_path / "meshfree.k"), 60)
    reference = assert_same_on_every_rank_count(deck, tmp_path)
    with h5py.File(reference, "r") as results:
        assert results["history/matsum/1/internal_energy"][-1] > 0.0
        assert np.abs(results["history/rwforc/5/force"][...][:, 0]).max() > 0.0
    for ranks in (2, 3):
        shared = assert_shared_out(tmp_path / f"np{ranks}_ncpu1" / "results.h5", ["meshfree"])
        print(f"{ranks} ranks: meshfree point blocks computed per rank {[int(count) for count in shared['meshfree']]}")


def side_impact_deck(directory, cycles):
    """inputs/side_impact's coupled model as its generator writes it (3 ms, 3 states) into
    `directory`, ending after `cycles` cycles."""
    subprocess.run([sys.executable, str(SIDE_IMPACT_GENERATOR), "--end-time", "3.0", "--states", "3",
                    "-o", str(directory)], check=True, capture_output=True, text=True)
    return shortened(directory / "coupled.k", cycles)


def test_side_impact_meshfree_solids_and_shells_are_identical_on_one_two_and_three_ranks(tmp_path):
    """inputs/side_impact's coupled model (three meshfree rib foams, the meshfree shell jacket,
    FE rib bands, a rigid door and spine, two contacts), 250 cycles: the door reaches the jacket
    (2 mm at 8 mm/ms, 0.25 ms). Every rank count gives the file of the run alone; each rank
    computes part of the blocks of both meshfree kinds; the energy stays balanced (ratio within
    1e-3 of 1) and the meshfree parts have taken up strain energy."""
    deck = side_impact_deck(tmp_path, 250)
    reference = assert_same_on_every_rank_count(deck, tmp_path)
    with h5py.File(reference, "r") as results:
        ratio = results["history/glstat/energy_ratio"][...]
        door_force = np.abs(results["history/rcforc/1/force"][...]).max()
        jacket, foams = (results["history/matsum/3/internal_energy"][-1],
                         [results[f"history/matsum/{part}/internal_energy"][-1] for part in (21, 22, 23)])
    print(f"door contact force up to {door_force:.3f} kN; strain energy: jacket {jacket:.4f} J, "
          f"foams {', '.join(f'{energy:.4f}' for energy in foams)} J")
    assert np.all(np.abs(ratio - 1.0) < 1e-3), ratio
    assert door_force > 0.0 and jacket > 0.0 and min(foams) > 0.0
    for ranks in (2, 3):
        shared = assert_shared_out(tmp_path / f"np{ranks}_ncpu1" / "results.h5", ["meshfree", "meshfree shell"])
        counts = {kind: [int(count) for count in blocks] for kind, blocks in shared.items()}
        print(f"{ranks} ranks: blocks computed per rank {counts}")


def test_side_impact_with_two_threads_per_rank(tmp_path):
    """The side-impact model on two ranks of two threads: the same file as one rank of two
    threads (the meshfree colours split between threads and ranks at once)."""
    deck = side_impact_deck(tmp_path, 120)
    assert_same_on_every_rank_count(deck, tmp_path, counts=(2,), threads=2)


def test_eroding_shells_are_identical_on_one_two_and_three_ranks(tmp_path):
    """The contact model with a brittle steel (FS 0.5 %): the plate's shells fail on impact; the
    failed elements, their order and their energy are the same on every rank count."""
    deck = shortened(brittle(contact_deck(tmp_path / "erode.k"), 0.005))
    reference = assert_same_on_every_rank_count(deck, tmp_path)
    with h5py.File(reference, "r") as results:
        eroded = results["history/glstat/eroded_elements"][...]
    print(f"eroded elements at the end: {eroded[-1]:.0f}")
    assert eroded[-1] > 0 and np.all(np.diff(eroded) >= 0)


def test_rigid_body_model_is_identical_on_one_two_and_three_ranks(tmp_path):
    """test_threads' turning rigid block hitting a slab with a rigid edge and a nodal rigid body."""
    deck = shortened(rigid_deck(tmp_path / "rigid.k"))
    reference = assert_same_on_every_rank_count(deck, tmp_path)
    with h5py.File(reference, "r") as results:
        assert np.abs(results["history/rcforc/21/force"][...]).max() > 0.0


def test_restart_on_another_number_of_ranks(tmp_path):
    """Dumps every 30 cycles of the contact model on 2 ranks; the second continued on 3 ranks
    and the third on 1 rank (alone) give the uninterrupted run's file."""
    deck = shortened(contact_deck(tmp_path / "contact.k"))
    text = deck.read_text()
    deck.write_text(text.replace("*PART\n", "*DATABASE_BINARY_D3DUMP\n" + fields(30) + "\n*PART\n", 1))
    reference = run(deck, tmp_path / "alone", None)
    dumped = run(deck, tmp_path / "two", 2)
    assert not results_difference(reference, dumped)
    dumps = sorted(path.name for path in (tmp_path / "two").glob("d3dump*"))
    assert dumps == ["d3dump01", "d3dump02", "d3dump03"], dumps
    for dump, ranks in (("d3dump02", 3), ("d3dump03", None)):
        target = tmp_path / f"continued_{dump}_{ranks}"
        shutil.copytree(tmp_path / "two", target)
        process = solver(ranks, [f"r={target / dump}"])
        assert process.returncode == 0, process.stdout + process.stderr
        assert process.stdout.count(f"continuing from restart dump {target / dump}") == 1, process.stdout
        difference = results_difference(reference, target / "results.h5")
        assert not difference, f"{dump} continued on {ranks or 1} rank(s): {difference}"


def test_side_impact_restart_on_another_number_of_ranks(tmp_path):
    """The side-impact model dumped every 100 cycles on 2 ranks: the meshfree blocks' state comes
    together in the dump; the first dump continued on 3 ranks and the second alone give the
    uninterrupted run's file."""
    deck = side_impact_deck(tmp_path, 250)
    deck.write_text(deck.read_text().replace("*PART\n", "*DATABASE_BINARY_D3DUMP\n" + fields(100) + "\n*PART\n", 1))
    reference = run(deck, tmp_path / "alone", None)
    dumped = run(deck, tmp_path / "two", 2)
    assert not results_difference(reference, dumped)
    for dump, ranks in (("d3dump01", 3), ("d3dump02", None)):
        target = tmp_path / f"continued_{dump}_{ranks}"
        shutil.copytree(tmp_path / "two", target)
        process = solver(ranks, [f"r={target / dump}"])
        assert process.returncode == 0, process.stdout + process.stderr
        difference = results_difference(reference, target / "results.h5")
        assert not difference, f"{dump} continued on {ranks or 1} rank(s): {difference}"


def test_first_rank_prints_and_too_many_ranks_are_refused(tmp_path):
    """The run's output once (the first rank), with the exchanges' summary; more ranks than
    element blocks: exit status 2 and a message saying how many at most."""
    deck = shortened(rigid_deck(tmp_path / "rigid.k"), 20)
    process = solver(2, [f"i={deck}", f"outdir={tmp_path / 'two'}"])
    assert process.returncode == 0, process.stdout + process.stderr
    assert process.stdout.count("normal termination") == 1, process.stdout
    assert "on 2 MPI ranks of 1 thread(s)" in process.stdout and "  MPI: 2 ranks; nodal exchange" in process.stdout
    tiny = impact_deck(tmp_path / "tiny.k")        # 125 hexahedra: 2 blocks
    process = solver(3, [f"i={tiny}", f"outdir={tmp_path / 'tiny'}"])
    assert process.returncode == 2, process.stdout + process.stderr
    assert "ranks are more than the model's" in process.stderr, process.stderr
    assert process.stderr.count("ranks are more than the model's") == 1, process.stderr


def test_sigterm_to_mpirun_stops_every_rank_after_the_same_cycle(tmp_path):
    """A batch system's time limit: SIGTERM to mpirun, which passes it to the ranks (not at one
    instant). Every rank stops after the same cycle, the first writes a restart dump and says so
    once (exit status 1); the dump continued on 3 ranks gives the uninterrupted run's file."""
    deck = shortened(contact_deck(tmp_path / "contact.k"), 600)
    reference = run(deck, tmp_path / "alone", None)
    output = tmp_path / "stopped"
    process = subprocess.Popen(["mpirun", "--oversubscribe", "-np", "2", str(BINARY), f"i={deck}", f"outdir={output}",
                                "ncpu=1"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               env=environment(1))
    for line in process.stdout:
        if line.split() and line.split()[0].isdigit():      # the first progress line: cycles are running
            break
    process.send_signal(signal.SIGTERM)
    stdout, stderr = process.communicate(timeout=300)
    assert process.returncode == 1, stdout + stderr
    assert stderr.count("stopped by SIGTERM") == 1, stderr
    assert (output / "d3dump01").exists(), stderr
    continued = solver(3, [f"r={output / 'd3dump01'}"])
    assert continued.returncode == 0, continued.stdout + continued.stderr
    difference = results_difference(reference, output / "results.h5")
    assert not difference, f"stopped on 2 ranks, continued on 3: {difference}"


WELD_STRAIN = 0.02     # EP of the welds of welded_strips_deck


def welded_strips_deck(path, meshfree, end_time=0.22, weld_strain=WELD_STRAIN, cell=2.0, length=64.0, width=16.0,
                       pitch=4.0, thickness=1.0, speed=5.0):
    """Two elastic-plastic steel strips (MAT_024, SIGY 0.2 GPa, ETAN 1 GPa) `length` x `width`,
    one `thickness` above the other, joined along their centre line by a spot weld every `pitch`
    (15 welds, *CONSTRAINED_SPOTWELD_ID 1 to 15 from x = 4 to x = 60) that fails by plastic
    strain only (SN = SS = 0, EP `weld_strain`). The lower strip is clamped at x = 0; the upper
    one's end x = `length` pulled along x at `speed` (ramped up over 0.1 ms): the welds carry the
    pull in shear, the shells round the end welds yield first, and the joint unzips from both
    ends towards the middle. FE shells (ELFORM 2) or meshfree shells (ELFORM 41, DX = DY =
    1.5; the welds' nodes are Gamma nodes). States every 0.005 ms."""
    counts = (round(length / cell), round(width / cell))
    lower, shells = plate_mesh(counts, (length, width))
    upper = lower + [0.0, 0.0, thickness]
    nodes = np.vstack([lower, upper])
    n = len(lower)
    root = np.flatnonzero(np.isclose(lower[:, 0], 0.0))
    end = n + np.flatnonzero(np.isclose(upper[:, 0], length))
    welds = ["*CONSTRAINED_SPOTWELD_ID"]
    for weld, x in enumerate(np.arange(pitch, length - pitch / 2, pitch)):
        node = int(np.flatnonzero(np.isclose(lower[:, 0], x) & np.isclose(lower[:, 1], width / 2))[0])
        welds += [fields(weld + 1), fields(node + 1, n + node + 1, 0.0, 0.0, 0.0, 0.0, 0.0, weld_strain)]
    section = ("*SECTION_SHELL\n" + fields(1, 41 if meshfree else 2, 1.0, 3) + "\n" + fields(*[thickness] * 4) +
               ("\n" + fields(1.5, 1.5) if meshfree else ""))
    upper_shells = shells_card(shells, part_id=2, first_id=len(shells) + 1, first_node_id=n + 1)
    return write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_GLSTAT\n" + fields(0.005),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.005),
        "*PART\nlower strip\n" + fields(1, 1, 1),
        "*PART\nupper strip\n" + fields(2, 1, 1),
        section,
        "*MAT_PIECEWISE_LINEAR_PLASTICITY\n" + fields(1, DENSITY, MODULUS, POISSON, 0.2, 1.0) + "\n" + fields(0.0),
        nodes_card(nodes),
        shells_card(shells) + "\n" + "\n".join(upper_shells.splitlines()[1:]),
        "*BOUNDARY_SPC_NODE\n" + "\n".join(fields(k + 1, 0, 1, 1, 1, 1, 1, 1) for k in root),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + f"{0.0:20.6e}{0.0:20.6e}\n{0.1:20.6e}{speed:20.6e}\n"
        f"{100.0:20.6e}{speed:20.6e}",
        "*BOUNDARY_PRESCRIBED_MOTION_NODE\n" + "\n".join(fields(k + 1, 1, 0, 1) for k in end),
        "\n".join(welds),
    )


def weld_failures(stdout):
    """{weld id: (its nodes' ids, failure time)} of the failure lines a run printed (EP only)."""
    failures = {}
    for line in stdout.splitlines():
        if line.startswith("spot weld ") and " fails at t = " in line:
            assert "reached the plastic strain" in line, line
            weld = int(line.split()[2])
            nodes = tuple(int(node) for node in line.split("(nodes ")[1].split(")")[0].split(","))
            failures[weld] = (nodes, float(line.split("t =")[1].split(":")[0]))
    return failures


def deck_welds(deck):
    """{weld id: (N1, N2)} of a *CONSTRAINED_SPOTWELD_ID written by welded_strips_deck."""
    lines = deck.read_text().splitlines()
    first = lines.index("*CONSTRAINED_SPOTWELD_ID") + 1
    welds = {}
    for k in range(first, len(lines) - 1, 2):
        if lines[k].startswith("*"):
            break
        welds[int(lines[k])] = (int(lines[k + 1][0:10]), int(lines[k + 1][10:20]))
    return welds


def welds_on_interfaces(results_path, welds):
    """The welds of a run on several ranks that a domain interface touches: {weld id: why} where
    the shells round one of its nodes are computed by more than one rank (the ranks' largest
    plastic strains there differ until they are brought together), or its two nodes have
    different owners."""
    with h5py.File(results_path, "r") as results:
        node_rank = results[f"{RANK_REPORT}/node_rank"][...]
        shell_rank = results[f"{RANK_REPORT}/shell_rank"][...]
        connectivity = results["mesh/shells/connectivity_index"][...]
        node_ids = results["mesh/nodes/ids"][...]
    index = {int(node_id): k for k, node_id in enumerate(node_ids)}
    found = {}
    for weld, nodes in welds.items():
        for node in nodes:
            ranks = sorted(set(shell_rank[(connectivity == index[node]).any(axis=1)].tolist()))
            if len(ranks) > 1:
                found[weld] = f"node {node}: shells on ranks {ranks}"
        owners = {int(node_rank[index[node]]) for node in nodes}
        if weld not in found and len(owners) > 1:
            found[weld] = f"nodes owned by ranks {sorted(owners)}"
    return found


@pytest.mark.parametrize("meshfree", [False, True], ids=["fe_shells", "meshfree_shells"])
def test_welds_failing_by_plastic_strain_are_identical_on_one_two_and_three_ranks(tmp_path, meshfree):
    """Spot welds that fail by EP (the shells' plastic strain at their nodes, raised by each rank
    with the blocks it computes and brought together by a maximum over the ranks each cycle), on
    FE shells and on meshfree shells: welded_strips_deck's joint unzips. Every rank count gives
    the file of the run alone and prints the same failures. The physics, from the run alone: a
    weld fails in the cycle after the force call in which a shell round one of its nodes first
    reached EP, so at every state (every 0.005 ms) the largest plastic strain of the shells on
    its nodes (`shell_plastic_strain_peak`) is below EP before the weld's failure time and at
    least EP from it on; the welds that hold stay below EP; swforc counts the failures. Some
    failing welds sit on a domain interface (the partition report)."""
    deck = welded_strips_deck(tmp_path / "welded.k", meshfree)
    reference = assert_same_on_every_rank_count(deck, tmp_path)
    failures = weld_failures((tmp_path / "alone" / "messag").read_text())
    for ranks in RANK_COUNTS:
        printed = weld_failures((tmp_path / f"np{ranks}_ncpu1" / "messag").read_text())
        assert printed == failures, f"-np {ranks}: {printed} != {failures}"
    welds = deck_welds(deck)
    print(f"{len(failures)} of {len(welds)} welds failed: " +
          ", ".join(f"{weld} at {time:.5f} ms" for weld, (_, time) in sorted(failures.items(), key=lambda w: w[1][1])))
    assert 3 <= len(failures) < len(welds), failures
    assert all(failures[weld][0] == welds[weld] for weld in failures)
    with h5py.File(reference, "r") as results:
        connectivity = results["mesh/shells/connectivity_index"][...]
        node_ids = results["mesh/nodes/ids"][...]
        keys = sorted(results["states"].keys())
        times = np.array([results["states"][key].attrs["time"] for key in keys])
        peak = np.array([results["states"][key]["shell_plastic_strain_peak"][...] for key in keys])
        count_time = results["history/swforc/time"][...]
        failed_count = results["history/swforc/failed_welds"][...]
    index = {int(node_id): k for k, node_id in enumerate(node_ids)}
    for weld, nodes in welds.items():
        around = (np.isin(connectivity, [index[node] for node in nodes])).any(axis=1)
        strain = peak[:, around].max(axis=1)
        # the printed time has 6 digits: a state within that rounding is the one at the failure
        failed_at = failures[weld][1] * (1.0 - 1e-5) if weld in failures else np.inf
        reached = strain >= WELD_STRAIN
        # (the last state's force call is checked in no later cycle: only "failed -> reached" there)
        assert np.array_equal(reached[:-1], (times >= failed_at)[:-1]), (weld, failed_at, times[reached][:1],
                                                                          strain.max())
        assert reached[-1] or times[-1] < failed_at, weld
    # a sample at t is written before the welds' check of the cycle that starts at t
    expected_count = [sum(time < sample * (1.0 - 1e-5) for _, time in failures.values()) for sample in count_time]
    assert np.array_equal(failed_count, expected_count), (failed_count, expected_count)
    on_interfaces = {}
    for ranks in (2, 3):
        found = welds_on_interfaces(tmp_path / f"np{ranks}_ncpu1" / "results.h5", welds)
        on_interfaces.update({(ranks, weld): why for weld, why in found.items() if weld in failures})
    print("failing welds on domain interfaces:", {key: why for key, why in on_interfaces.items() if "shells" in why})
    assert any("shells on ranks" in why for why in on_interfaces.values()), on_interfaces


def test_meshfree_model_is_identical_on_four_ranks(tmp_path):
    """test_threads' coupled EFG / FE bar on 4 ranks (the cheapest model of this file in which
    each of 4 ranks computes blocks of every kind it has: solids and meshfree points; the others
    were run on 4 ranks by hand, docs/parallel.md): the file of the run alone."""
    deck = shortened(meshfree_deck(tmp_path / "meshfree.k"), 60)
    assert_same_on_every_rank_count(deck, tmp_path, counts=(4,))
    shared = assert_shared_out(tmp_path / "np4_ncpu1" / "results.h5", ["solid", "meshfree"])
    print(f"4 ranks: blocks computed per rank {({kind: [int(count) for count in blocks] for kind, blocks in shared.items()})}")


def test_models_with_fewer_than_two_element_blocks_are_refused_with_one_rank_advised(tmp_path):
    """More ranks than element blocks is refused (exit status 2, test above); a model of one block
    (one hexahedron with point masses and a weld, test_spot_welds) or of none (two rigid cubes
    and point masses: rigid bodies are in no block) is told to run on one rank, not "at most 1
    ranks" or "at most 0 ranks". Checked with partition=2 (the same set-up without mpirun)."""
    from test_spot_welds import merged_bodies_deck, weld_deck
    one_block = weld_deck(tmp_path / "one_block.k", "*CONSTRAINED_SPOTWELD\n" + fields(1, 2, 4.0, 0.0))
    rigid_only, _ = merged_bodies_deck(tmp_path / "rigid_only.k")
    for deck, expected in ((one_block, "2 ranks are more than the model's 1 element block (elements: 1;"),
                           (rigid_only, "2 ranks, but the model has no deformable element to share out")):
        process = solver(None, [f"i={deck}", f"outdir={tmp_path / deck.stem}", "partition=2"])
        assert process.returncode == 2, process.stdout + process.stderr
        assert expected in process.stderr and "run it on one rank (without mpirun)" in process.stderr, process.stderr
        assert "use at most" not in process.stderr, process.stderr


def dying_contact_deck(path):
    """The contact model with a death time on its surface-to-surface contact (DT 0.009 s, while
    it is pressed) and a restart dump at cycle 90, after the death."""
    deck = shortened(contact_deck(path))
    text = deck.read_text()
    start = text.index("*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE_ID")
    card = fields(0.2, 0.2) + "\n"
    at = text.index(card, start)
    text = text[:at] + fields(0.2, 0.2, 0.0, 0.0, 0.0, 0, 0.0, 0.009) + "\n" + text[at + len(card):]
    deck.write_text(text.replace("*PART\n", "*DATABASE_BINARY_D3DUMP\n" + fields(90) + "\n*PART\n", 1))
    return deck


def dump_difference(first_path, second_path):
    """'' when two restart dumps hold the same datasets bit for bit (but the wall-clock seconds
    and the run id, which differ between any two runs), else the differing names."""
    with h5py.File(first_path, "r") as first, h5py.File(second_path, "r") as second:
        a, b = {}, {}
        first.visititems(lambda name, item: a.__setitem__(name, item) if isinstance(item, h5py.Dataset) else None)
        second.visititems(lambda name, item: b.__setitem__(name, item) if isinstance(item, h5py.Dataset) else None)
        if a.keys() != b.keys():
            return f"datasets in one dump only: {sorted(a.keys() ^ b.keys())[:5]}"
        different = [name for name in sorted(a) if not name.endswith("seconds") and name != "results/run_id"
                     and _first_difference(a[name][...], b[name][...]) is not None]
    return ", ".join(different[:8]) + (f" (and {len(different) - 8} more)" if len(different) > 8 else "")


def test_restart_dump_is_the_same_file_on_one_two_and_three_ranks(tmp_path):
    """A dump taken after a contact's death time (its pairs cleared, the other contact pressed):
    every dataset of d3dump01 from 2 and 3 ranks equals the one of the run alone (contact pair
    arrays, search lists and their buffers included; not the wall-clock seconds and the run id),
    so that a dump does not depend on N."""
    deck = dying_contact_deck(tmp_path / "dying.k")
    run(deck, tmp_path / "alone", None)
    for ranks in (2, 3):
        run(deck, tmp_path / f"np{ranks}", ranks)
        difference = dump_difference(tmp_path / "alone" / "d3dump01", tmp_path / f"np{ranks}" / "d3dump01")
        assert not difference, f"d3dump01 on {ranks} ranks differs from the run alone: {difference}"
    with h5py.File(tmp_path / "alone" / "results.h5", "r") as results:
        force = results["history/rcforc/12/force"][...]
        time = results["history/rcforc/12/time"][...]
    # the contact took load before its death time and none in the sampling intervals after it
    # (rcforc's force is the interval's impulse over its length)
    assert np.abs(force[time < 0.009]).max() > 0.0
    assert np.all(force[time > 0.0101] == 0.0)


def failing_run(deck, output, ranks):
    """A run that must end in error termination: its message (the first rank's standard error,
    one line) and results file."""
    process = solver(ranks, [f"i={deck}", f"outdir={output}"])
    assert process.returncode == 1, f"-np {ranks}:\n" + process.stdout + process.stderr
    assert "Backtrace" not in process.stderr and "runtime error" not in process.stderr, process.stderr
    messages = [line for line in process.stderr.splitlines() if "error termination" in line or "at time" in line]
    assert messages, process.stderr
    return messages, output / "results.h5"


def test_error_terminations_are_the_same_on_one_two_and_three_ranks(tmp_path):
    """Runs that must stop are stopped alike for any N, with the same message and the same file:
    (a) the eight corner nodes of a 12 x 12 x 6 block (its other nodes held) pushed 1.5 element
    sizes inwards in one step invert the eight corner hexahedra at once, on both ranks of 2; the
    message names the element one rank names (the first block with one: the tie rule across
    ranks); (b) two blocks meeting
    head on with ENDENG 1e-6 percent: the energy check, from the blocks' energy sums shared among
    the ranks, stops the run at the same cycle."""
    nodes, elements = block_mesh((12, 12, 6), (12.0, 12.0, 6.0))
    corners = [n + 1 for n, point in enumerate(nodes)
               if all(abs(point[d]) < 1e-9 or abs(point[d] - (12.0, 12.0, 6.0)[d]) < 1e-9 for d in range(3))]
    assert len(corners) == 8
    centre = np.array([6.0, 6.0, 3.0])
    motion = []
    for node in corners:
        inwards = centre - nodes[node - 1]
        inwards = 1.5 * inwards / np.abs(inwards)      # 1.5 mm along each axis, towards the centre
        motion += [fields(node, d + 1, 2, 1, inwards[d]) for d in range(3)]
    crush = write_deck(
        tmp_path / "crush.k",
        "*CONTROL_TERMINATION\n" + fields(1.0),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.5),
        "*DATABASE_GLSTAT\n" + fields(0.001),
        "*PART\nblock\n" + fields(42, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, 7.85e-6, 1.0, 0.3),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + "\n".join(
            f"{t:20.6e}{u:20.6e}" for t, u in ((0.0, 0.0), (0.01, 0.0), (0.0101, 1.0), (10.0, 1.0))),
        nodes_card(nodes),
        solids_card(elements, part_id=42, first_id=1),
        "*BOUNDARY_SPC_NODE\n" + "\n".join(fields(n, 0, 1, 1, 1, 0, 0, 0) for n in range(1, len(nodes) + 1)
                                           if n not in corners),
        "*BOUNDARY_PRESCRIBED_MOTION_NODE\n" + "\n".join(motion),
    )
    energy, *_ = contact_head_on_deck(tmp_path / "head_on.k", counts=(16, 4, 2))
    energy.write_text(energy.read_text().replace("*CONTROL_TERMINATION\n" + fields(0.03),
                                                 "*CONTROL_TERMINATION\n" + fields(0.03, None, None, 1e-6)))
    for deck, pattern in ((crush, "negative volume in solid element"), (energy, "differs from 1 by more than ENDENG")):
        reference_messages, reference = failing_run(deck, tmp_path / f"{deck.stem}_alone", None)
        assert any(pattern in line for line in reference_messages), reference_messages
        for ranks in (2, 3):
            messages, other = failing_run(deck, tmp_path / f"{deck.stem}_np{ranks}", ranks)
            assert messages == reference_messages, f"-np {ranks}"
            difference = results_difference(reference, other)
            assert not difference, f"{deck.stem}: mpirun -np {ranks} differs from the run alone: {difference}"
        if deck is crush:
            # the inverted corners lie on more than one rank (the test of the tie rule)
            with h5py.File(tmp_path / "crush_np2" / "results.h5", "r") as results:
                solid_rank = results["run/partition/solid_rank"][...]
            corner_elements = [k for k, element in enumerate(elements) if any(n + 1 in corners for n in element)]
            assert len(corner_elements) == 8
            assert len(set(solid_rank[corner_elements])) > 1, solid_rank[corner_elements]


HISTORY_NODES = 400


def peak_per_rank(deck, output):
    """Each rank's peak resident set (kB) of a 2-rank run, by rank."""
    output.mkdir()
    command = ["mpirun", "--oversubscribe", "--tag-output", "-np", "2", "/usr/bin/time", "-f", "maxrss_kB %M",
               str(BINARY), f"i={deck}", f"outdir={output}", "ncpu=1"]
    process = subprocess.run(command, capture_output=True, text=True, env=environment(1), timeout=600)
    assert process.returncode == 0, process.stdout + process.stderr
    # (--tag-output may split a line of one rank: join the rank's pieces first)
    text = process.stdout + process.stderr
    peaks = {}
    for rank in (0, 1):
        pieces = "".join(re.findall(rf"\[1,{rank}\]<stderr>:([^\[\n]*)", text))
        found = re.search(r"maxrss_kB (\d+)", pieces)
        assert found, text[-2000:]
        peaks[rank] = int(found.group(1))
    return peaks


def test_other_ranks_reserve_no_history_rows(tmp_path):
    """The other ranks of a distributed run keep only the output clocks: the contact model for 5
    cycles on 2 ranks, without and with 400 history nodes sampled every 1e-6 ms (ENDTIM 1 ms:
    4,112 rows of 11 values reserved per node on the first rank, 145 MB): the second rank, which
    records nothing, grows by less than 50 MB (it grew by the whole reservation when every rank
    created the history series)."""
    if not os.path.exists("/usr/bin/time"):
        pytest.skip("/usr/bin/time (GNU time) is missing")
    plain = shortened(contact_deck(tmp_path / "plain.k"), 5)
    many = tmp_path / "many.k"
    text = plain.read_text().replace("*DATABASE_NODOUT\n" + fields(0.001), "*DATABASE_NODOUT\n" + fields(1e-6))
    nodes = "\n".join(fields(*range(k, k + 8)) for k in range(1, HISTORY_NODES + 1, 8))
    many.write_text(text.replace("*PART\n", "*DATABASE_HISTORY_NODE\n" + nodes + "\n*PART\n", 1))
    without = peak_per_rank(plain, tmp_path / "plain")
    with_nodes = peak_per_rank(many, tmp_path / "many")
    growth_mb = (with_nodes[1] - without[1]) / 1024.0
    print(f"second rank's peak: {without[1] / 1024:.0f} MB without, {with_nodes[1] / 1024:.0f} MB with the history "
          f"nodes; first rank {without[0] / 1024:.0f} and {with_nodes[0] / 1024:.0f} MB")
    assert growth_mb < 50.0, f"the second rank grew by {growth_mb:.0f} MB for histories it never records"
