"""Deterministic assembly: ncpu=1 and ncpu=2 give identical results files (every dataset of
/mesh, /states and /history equal bit for bit)."""
import h5py
import numpy as np

from test_rigid_wall import impact_deck


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
