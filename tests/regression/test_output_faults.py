"""What the output costs, and what it leaves after a kill, a full disk, a read-only or impossible
output directory, and a second run into the same files (docs/output.md, "When things go wrong").

The cost tests count, they do not time: the bytes the solver hands to HDF5 (/timing/output_bytes),
the bytes HDF5 writes into the file (counted by a small C shim loaded with LD_PRELOAD) and the
times the XDMF file is written (/timing/xdmf_writes). Rewriting the histories or the XDMF file
whole at every state makes the bytes per state grow with the number of states."""
from __future__ import annotations

import fcntl
import math
import os
import random
import re
import signal
import subprocess
import time

import h5py
import pytest

from conftest import BINARY
from output_faults import (can_mount, compile_disk_shim, cube_deck, readable_states, run_solver,
                           tmpfs, xdmf_state_count)

NO_SPACE = re.compile(r"no space left on device while writing state (\d+) at time ([0-9.Ee+-]+) to (\S+)"
                      r"; the file keeps states 0 to (\d+)")


@pytest.fixture(scope="module")
def disk_shim(tmp_path_factory):
    return compile_disk_shim(tmp_path_factory.mktemp("shim"))


def test_output_cost_per_state_does_not_grow_with_the_number_of_states(tmp_path, disk_shim):
    per_state = {}
    for states in (100, 800):
        deck = cube_deck(tmp_path / f"cube_{states}.k", states)
        output = tmp_path / f"out_{states}"
        output.mkdir()
        log = tmp_path / f"written_{states}.txt"
        run = run_solver(BINARY, deck, output, {"LD_PRELOAD": str(disk_shim),
                                                "CRASHFREE_TEST_DISK_DIR": str(output),
                                                "CRASHFREE_TEST_WRITE_LOG": str(log)})
        assert run.returncode == 0, run.stderr
        with h5py.File(output / "results.h5", "r") as results:
            count = len(results["states"])
            assert count == states + 1
            assert results["history/glstat/time"].shape == (count,)
            assert results["history/glstat/momentum"].shape == (count, 3)
            timing = dict(results["timing"].attrs)
        assert xdmf_state_count(output / "results.xdmf") == count
        per_state[states] = (int(log.read_text()) / count, timing)
    # What HDF5 writes per state (data, metadata, history chunks): the same for 8 times as many
    # states, within what chunk and B-tree growth vary. Rewriting whole histories gives 5x.
    assert per_state[800][0] < 1.3 * per_state[100][0], per_state
    for states, (_, timing) in per_state.items():
        # Values: one state (27 nodes x 6 + 8 solids x 7, and the solids' 32-bit eroded flags),
        # one glstat row (30 values, the eroded energies and count, LS-DYNA's remaining glstat
        # lines and the element that set the step included) and one matsum row (11 values:
        # energies, momentum, rigid-body velocity, mass).
        assert timing["output_bytes"] == (states + 1) * (8 * (27 * 6 + 8 * 7 + 30 + 11) + 4 * 8)
        # The XDMF file at states 1, 2, 4, ... and the end; else at most every 2 s of the run.
        assert timing["xdmf_writes"] <= math.ceil(math.log2(states + 1)) + 2 + timing["wall_s"] / 2.0


def test_killed_run_leaves_a_valid_xdmf_file(tmp_path):
    """SIGKILL at random moments while states are written densely: the XDMF file is always
    well-formed (it is replaced by a rename) and lists no state the .h5 does not have."""
    deck = cube_deck(tmp_path / "dense.k", 4000)
    rng = random.Random(7)
    for attempt in range(5):
        output = tmp_path / f"out_{attempt}"
        output.mkdir()
        process = subprocess.Popen([str(BINARY), f"i={deck}", f"outdir={output}", "ncpu=1"],
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                   env=dict(os.environ, OMP_NUM_THREADS="1"))
        time.sleep(rng.uniform(0.3, 1.0))
        process.send_signal(signal.SIGKILL)
        process.wait()
        listed = xdmf_state_count(output / "results.xdmf")
        assert listed >= 1
        with h5py.File(output / "results.h5", "r") as results:
            assert results["run"].attrs["status"] == "running"
            assert f"states/{listed - 1:06d}/displacement" in results


def test_full_disk_at_start_is_refused_before_any_cycle(tmp_path, disk_shim):
    deck = cube_deck(tmp_path / "cube.k", 100)
    output = tmp_path / "full"
    output.mkdir()
    run = run_solver(BINARY, deck, output, {"LD_PRELOAD": str(disk_shim), "CRASHFREE_TEST_DISK_DIR": str(output),
                                            "CRASHFREE_TEST_DISK_BYTES": "0"})
    assert run.returncode == 2, run.stderr
    assert f"no space left on device while creating {output}/results.h5" in run.stderr
    assert "normal termination" not in run.stdout
    assert not (output / "results.h5").exists()      # nothing half-written is left


def test_full_disk_during_the_run_without_disk_reservation(tmp_path, disk_shim):
    """A file system without fallocate: the write that fails stops the run; the file keeps the
    states written before."""
    deck = cube_deck(tmp_path / "cube.k", 2000)
    output = tmp_path / "full"
    output.mkdir()
    run = run_solver(BINARY, deck, output, {"LD_PRELOAD": str(disk_shim), "CRASHFREE_TEST_DISK_DIR": str(output),
                                            "CRASHFREE_TEST_DISK_BYTES": "250000",
                                            "CRASHFREE_TEST_NO_FALLOCATE": "1"})
    assert run.returncode == 1, run.stderr
    found = NO_SPACE.search(run.stderr)
    assert found, run.stderr
    state, kept = int(found.group(1)), int(found.group(4))
    assert found.group(3) == f"{output}/results.h5" and kept == state - 1 and state > 5
    listed, readable, status = readable_states(output / "results.h5")
    assert listed == readable == state
    assert status == "running"            # the file was left as the last complete state left it
    assert xdmf_state_count(output / "results.xdmf") <= state


@pytest.mark.skipif(not can_mount(), reason="mounting a small tmpfs needs root")
def test_full_tmpfs_during_the_run_and_at_start(tmp_path):
    """A real full disk (a 1 MB tmpfs): the space of each state is reserved before it is
    written, so the run stops cleanly: exit 1, the message, every state readable, the run
    status written, the XDMF file listing them all. A disk full from the start: exit 2."""
    deck = cube_deck(tmp_path / "cube.k", 2000)
    with tmpfs(tmp_path / "disk", "size=1m") as disk:
        run = run_solver(BINARY, deck, disk)
        assert run.returncode == 1, run.stderr
        found = NO_SPACE.search(run.stderr)
        assert found, run.stderr
        state = int(found.group(1))
        assert state > 20
        listed, readable, status = readable_states(disk / "results.h5")
        assert listed == readable == state and status == "error termination"
        with h5py.File(disk / "results.h5", "r") as results:
            assert "no space left on device" in results["run"].attrs["message"]
            assert len(results["history/glstat/time"]) >= state
        assert xdmf_state_count(disk / "results.xdmf") == state
        assert not (disk / "results.xdmf.tmp").exists()
    with tmpfs(tmp_path / "small", "size=64k") as disk:
        (disk / "filler").write_bytes(b"\0" * 65536)
        run = run_solver(BINARY, deck, disk)
        assert run.returncode == 2, run.stderr
        assert f"no space left on device while creating {disk}/results.h5" in run.stderr
        assert not (disk / "results.h5").exists()


def test_read_only_output_directory_is_refused_before_any_cycle(tmp_path):
    deck = cube_deck(tmp_path / "cube.k", 10)
    if can_mount():
        with tmpfs(tmp_path / "read_only", "size=64k,ro") as directory:
            run = run_solver(BINARY, deck, directory)
        reason = "Read-only file system"
    elif os.geteuid() != 0:
        directory = tmp_path / "read_only"
        directory.mkdir(mode=0o555)
        run = run_solver(BINARY, deck, directory)
        reason = "Permission denied"
    else:
        pytest.skip("root without mount: nothing is read-only")
    assert run.returncode == 2, run.stderr
    assert f"cannot create the lock file {directory}/results.lock: {reason}" in run.stderr
    assert "cycles to time" not in run.stdout


def test_output_directory_that_cannot_be_created_is_refused(tmp_path):
    deck = cube_deck(tmp_path / "cube.k", 10)
    (tmp_path / "a_file").write_text("not a directory\n")
    run = run_solver(BINARY, deck, tmp_path / "a_file" / "results")
    assert run.returncode == 2, run.stderr
    assert f"cannot create the output directory '{tmp_path}/a_file/results': Not a directory" in run.stderr
    assert "cycles to time" not in run.stdout


def test_second_run_into_the_same_directory_is_refused(tmp_path):
    """Another process holds the job's lock: the run is refused before it truncates anything,
    naming the directory, the job id and that process."""
    deck = cube_deck(tmp_path / "cube.k", 10)
    output = tmp_path / "shared"
    output.mkdir()
    (output / "job7.h5").write_bytes(b"earlier results")
    with open(output / "job7.lock", "a+") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        lock.write(f"{os.getpid()}\n")
        lock.flush()
        run = subprocess.run([str(BINARY), f"i={deck}", f"outdir={output}", "jobid=job7"],
                             capture_output=True, text=True, timeout=60)
    assert run.returncode == 2, run.stderr
    assert (f"another run (process {os.getpid()}) is writing job 'job7' in the output directory "
            f"'{output}'") in run.stderr
    assert (output / "job7.h5").read_bytes() == b"earlier results"
    # The lock is gone with its holder: the same command now runs.
    run = subprocess.run([str(BINARY), f"i={deck}", f"outdir={output}", "jobid=job7"],
                         capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr


def start_and_wait_for_lock(deck, output):
    """A solver started on `deck`, once it holds the lock of `output`/results."""
    process = subprocess.Popen([str(BINARY), f"i={deck}", f"outdir={output}", "ncpu=1"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               env=dict(os.environ, OMP_NUM_THREADS="1"))
    lock = output / "results.lock"
    deadline = time.time() + 30.0
    while not (lock.exists() and lock.read_text().strip() == str(process.pid)) and time.time() < deadline:
        time.sleep(0.01)
    return process


def test_two_solver_runs_and_a_killed_one(tmp_path):
    """Two solvers on one output directory: the second is refused while the first runs, and the
    first ends normally with an intact file. A killed run leaves no stale lock."""
    long_deck = cube_deck(tmp_path / "long.k", 200, end_time=4.0)
    short_deck = cube_deck(tmp_path / "short.k", 10)
    output = tmp_path / "shared"
    output.mkdir()
    first = start_and_wait_for_lock(long_deck, output)
    second = run_solver(BINARY, short_deck, output)
    assert first.poll() is None, "the first run ended too early for this test"
    assert second.returncode == 2, second.stderr
    assert f"another run (process {first.pid}) is writing job 'results'" in second.stderr
    assert "cycles to time" not in second.stdout
    stdout, stderr = first.communicate(timeout=120)
    assert first.returncode == 0, stderr
    listed, readable, status = readable_states(output / "results.h5")
    assert listed == readable == 201 and status == "normal termination"

    killed = start_and_wait_for_lock(long_deck, output)
    killed.send_signal(signal.SIGKILL)
    killed.wait()
    third = run_solver(BINARY, short_deck, output)
    assert third.returncode == 0, third.stderr
    listed, readable, status = readable_states(output / "results.h5")
    assert listed == readable == 11 and status == "normal termination"


def test_every_full_disk_failure_says_so(tmp_path, disk_shim):
    """Disks of 40 to 330 kB without fallocate under a run of 20 states: wherever the disk fills
    (a state, the histories, the XDMF file, the run status or LS-DYNA's ASCII files at the end),
    a run that does not end normally says "no space left on device" (a failure that first
    happened while the file was closed was reported only as what the file keeps)."""
    deck = cube_deck(tmp_path / "cube.k", 20)
    endings = set()
    for size in range(40000, 330000, 7000):     # (up to where the run, its ASCII files included, fits)
        output = tmp_path / f"disk_{size}"
        output.mkdir()
        run = run_solver(BINARY, deck, output, {"LD_PRELOAD": str(disk_shim), "CRASHFREE_TEST_DISK_DIR": str(output),
                                                "CRASHFREE_TEST_DISK_BYTES": str(size),
                                                "CRASHFREE_TEST_NO_FALLOCATE": "1"})
        assert run.returncode in (0, 1, 2), (size, run.stderr)
        if run.returncode != 0:
            assert "no space left on device" in run.stderr, (size, run.stderr)
        endings.add(run.returncode)
    assert endings == {0, 1}        # (a disk too small to start is refused: its own test)
