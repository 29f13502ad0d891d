"""Distributed runs (MPI, docs/parallel.md): `mpirun -np N bin/crashfree` gives the results file
of the one-rank run bit for bit, for N = 1, 2, 3 ranks and with 2 threads per rank, on a contact
model, a coupled meshfree / finite element model, the side-impact dummy (meshfree solids and
meshfree shells coupled to FE shells, contact, rigid bodies), a shell model with elements that
erode and a rigid-body model; the meshfree blocks are shared out among the ranks as the finite
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
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from conftest import BINARY
from deck_writer import fields
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
    """The first rank's count of the contact pairs each rank found over the run (its last print)."""
    marker = "contact pairs found per rank over the run:"
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
            assert {"internal_forces", "contact", "force_exchange", "force_exchange_wait"} <= set(names)
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
    assert "on 2 MPI ranks of 1 thread(s)" in process.stdout and "  MPI: 2 ranks; force exchange" in process.stdout
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
