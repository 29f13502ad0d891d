"""Shared fixtures: the solver binary and a way to run a deck and open its results."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import h5py
import pytest

REPOSITORY = Path(__file__).resolve().parents[2]
BINARY = Path(os.environ.get("CRASHFREE", REPOSITORY / "bin" / "crashfree"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(REPOSITORY / "postproc"))


class Run:
    """One finished solver run: exit status, output text and the results file."""

    def __init__(self, process: subprocess.CompletedProcess, results: Path):
        self.status = process.returncode
        self.stdout = process.stdout
        self.stderr = process.stderr
        self.results = results

    def open(self):
        return h5py.File(self.results, "r")


@pytest.fixture
def run_deck(tmp_path):
    """run_deck(deck_path, ncpu=1, jobid="results") runs the solver in a fresh directory."""

    def run(deck: Path, ncpu: int = 1, jobid: str = "results", timeout: float = 600.0) -> Run:
        output = tmp_path / f"out_{jobid}_{ncpu}"
        output.mkdir(exist_ok=True)
        # the thread counts the tests ask for, also above the machine's processors (which
        # the solver would cap)
        environment = dict(os.environ, OMP_NUM_THREADS=str(ncpu), CRASHFREE_OVERSUBSCRIBE="1")
        process = subprocess.run(
            [str(BINARY), f"i={deck}", f"outdir={output}", f"ncpu={ncpu}", f"jobid={jobid}"],
            capture_output=True, text=True, timeout=timeout, env=environment)
        return Run(process, output / f"{jobid}.h5")

    if not BINARY.exists():
        pytest.fail(f"{BINARY} is missing: build it with make")
    return run


def last_state(results: h5py.File):
    """The group of the last state written."""
    names = sorted(results["states"].keys())
    return results["states"][names[-1]]
