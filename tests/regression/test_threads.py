"""Deterministic assembly: ncpu=1, 2 (and 3) give identical results files (every dataset of
/mesh, /states and /history equal bit for bit)."""
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np

from test_rigid_wall import impact_deck

REPOSITORY = Path(__file__).resolve().parents[2]


def datasets(results):
    found = {}

    def visit(name, item):
        if isinstance(item, h5py.Dataset) and not name.startswith("timing"):
            found[name] = item[...]

    results.visititems(visit)
    return found


def test_one_and_two_threads_give_identical_results(tmp_path, run_deck):
    deck = impact_deck(tmp_path / "impact.k")
    one = run_deck(deck, ncpu=1)
    two = run_deck(deck, ncpu=2)
    assert one.status == 0 and two.status == 0, one.stderr + two.stderr
    with one.open() as first, two.open() as second:
        assert first["run"].attrs["threads"] == 1 and second["run"].attrs["threads"] == 2
        a, b = datasets(first), datasets(second)
    assert a.keys() == b.keys()
    assert any(name.startswith("states/") for name in a)
    for name in a:
        assert np.array_equal(a[name], b[name]), f"{name} differs between 1 and 2 threads"


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
    runs = [run_deck(deck, ncpu=n) for n in (1, 2, 3)]
    for run in runs:
        assert run.status == 0, run.stdout + run.stderr
    found = []
    for threads, run in zip((1, 2, 3), runs):
        with run.open() as results:
            assert results["run"].attrs["cycles"] == 300
            assert results["run"].attrs["threads"] == threads
            found.append(datasets(results))
    assert found[0]["history/glstat/external_work"][-1] != 0.0
    for threads, other in zip((2, 3), found[1:]):
        assert other.keys() == found[0].keys()
        for name in found[0]:
            assert np.array_equal(found[0][name], other[name]), f"{name} differs between 1 and {threads} threads"
