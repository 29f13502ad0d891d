#!/usr/bin/env python3
"""Every model of tests/regression/test_mpi.py on rank and thread counts beyond those the test
suite runs (docs/parallel.md, "Why the results do not depend on N"): each deck is run alone on
1 and 2 threads and under `mpirun --oversubscribe -np N ... ncpu=T` for each case N x T, and
every results file is compared with the runs alone, bit for bit (test_mpi's comparison:
/timing, /run/partition and the /run attributes threads and run_id left out). With --restart,
restart dumps written on some N are continued on others (and alone) and compared with the
uninterrupted run. Prints one line per run; exit status 1 when some file differs or a run failed.

    python3 tools/mpi_sweep.py                       # N x T = 4x1, 2x2, 3x2 into mpi_sweep/
    python3 tools/mpi_sweep.py --cases 4x2 --models contact rigid --output /tmp/sweep
    python3 tools/mpi_sweep.py --restart             # the dump and continuation cases below

Run from the repository root after `make` (bin/crashfree built with MPI, mpirun installed; as
root, Open MPI's OMPI_ALLOW_RUN_AS_ROOT variables are set here as in the tests).
"""
from __future__ import annotations

import argparse
import shutil
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "regression"))

import h5py  # noqa: E402

import test_mpi  # noqa: E402
from deck_writer import fields  # noqa: E402
from test_threads import contact_deck, meshfree_deck, rigid_deck  # noqa: E402

MODELS = {
    "contact": lambda directory: test_mpi.shortened(contact_deck(directory / "contact.k")),
    "meshfree": lambda directory: test_mpi.shortened(meshfree_deck(directory / "meshfree.k"), 60),
    "side_impact": lambda directory: test_mpi.side_impact_deck(directory, 250),
    "eroding": lambda directory: test_mpi.shortened(test_mpi.brittle(contact_deck(directory / "erode.k"), 0.005)),
    "rigid": lambda directory: test_mpi.shortened(rigid_deck(directory / "rigid.k")),
    "welds_fe": lambda directory: test_mpi.welded_strips_deck(directory / "welded.k", False),
    "welds_meshfree": lambda directory: test_mpi.welded_strips_deck(directory / "welded.k", True),
}
# model: (dump every so many cycles, ranks that write the dumps, [(dump, ranks (None: alone), threads)])
RESTARTS = {
    "contact": (30, 4, [("d3dump01", 2, 2), ("d3dump02", 3, 2), ("d3dump03", None, 2)]),
    "side_impact": (100, 4, [("d3dump01", 3, 2), ("d3dump02", 2, 2)]),
    "welds_fe": (200, 3, [("d3dump01", 4, 1), ("d3dump02", 2, 2), ("d3dump03", None, 2)]),
    "welds_meshfree": (200, 4, [("d3dump01", 3, 2), ("d3dump02", 2, 2)]),
}


def computed_blocks(results_path):
    """'kind: blocks computed per rank' of a run's partition report."""
    with h5py.File(results_path, "r") as results:
        partition = results[test_mpi.RANK_REPORT]
        kinds = [name.decode() for name in partition["kind_names"][...]]
        computed = partition["rank_computed_blocks"][...]
        total = partition["kind_blocks"][...]
    return "; ".join(f"{kind} {computed[:, k].tolist()} of {total[k]}" for k, kind in enumerate(kinds))


def sweep(models, cases, output):
    """Each model alone (1 and 2 threads) and on each (ranks, threads) case; True when all agree."""
    agreed = True
    for name in models:
        directory = output / name
        directory.mkdir(parents=True, exist_ok=True)
        deck = MODELS[name](directory)
        files = {}
        for ranks, threads in [(None, 1), (None, 2), *cases]:
            label = f"alone_ncpu{threads}" if ranks is None else f"np{ranks}_ncpu{threads}"
            start = time.monotonic()
            process = test_mpi.solver(ranks, [f"i={deck}", f"outdir={directory / label}"], threads, timeout=1800)
            seconds = time.monotonic() - start
            if process.returncode != 0:
                agreed = False
                print(f"{name} {label}: exit status {process.returncode}\n{process.stderr[-2000:]}", flush=True)
                continue
            files[label] = directory / label / "results.h5"
            comparisons = []
            for reference in ("alone_ncpu1", "alone_ncpu2"):
                if reference in files and reference != label:
                    difference = test_mpi.results_difference(files[reference], files[label])
                    agreed = agreed and not difference
                    comparisons.append(f"vs {reference} {difference or 'identical'}")
            blocks = f"; computed blocks per rank: {computed_blocks(files[label])}" if ranks else ""
            print(f"{name} {label}: {seconds:.1f} s; {', '.join(comparisons) or 'reference'}{blocks}", flush=True)
    return agreed


def restarts(models, output):
    """Dumps written on some ranks continued on others; True when every continuation gives the
    uninterrupted run's file."""
    agreed = True
    for name in models:
        if name not in RESTARTS:
            continue
        every, dump_ranks, continuations = RESTARTS[name]
        directory = output / f"{name}_restart"
        directory.mkdir(parents=True, exist_ok=True)
        deck = MODELS[name](directory)
        deck.write_text(deck.read_text().replace("*PART\n", "*DATABASE_BINARY_D3DUMP\n" + fields(every) + "\n*PART\n", 1))
        reference = test_mpi.run(deck, directory / "alone", None)
        dumped = test_mpi.run(deck, directory / f"np{dump_ranks}", dump_ranks)
        difference = test_mpi.results_difference(reference, dumped)
        agreed = agreed and not difference
        print(f"{name}: dumps every {every} cycles on {dump_ranks} ranks: {difference or 'identical to the run alone'}",
              flush=True)
        for dump, ranks, threads in continuations:
            target = directory / f"{dump}_on_{ranks or 1}x{threads}"
            shutil.rmtree(target, ignore_errors=True)
            shutil.copytree(directory / f"np{dump_ranks}", target)
            process = test_mpi.solver(ranks, [f"r={target / dump}"], threads, timeout=1800)
            if process.returncode != 0:
                agreed = False
                print(f"  {dump} on {ranks or 1} x {threads}: exit status {process.returncode}\n{process.stderr[-2000:]}")
                continue
            difference = test_mpi.results_difference(reference, target / "results.h5")
            agreed = agreed and not difference
            print(f"  {dump} continued on {ranks or 1} rank(s) x {threads} thread(s): "
                  f"{difference or 'identical to the uninterrupted run'}", flush=True)
    return agreed


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", default="4x1,2x2,3x2", help="ranks x threads, comma-separated")
    parser.add_argument("--models", nargs="*", default=list(MODELS), choices=list(MODELS))
    parser.add_argument("--restart", action="store_true", help="the dump and continuation cases instead")
    parser.add_argument("--output", type=Path, default=Path("mpi_sweep"))
    arguments = parser.parse_args()
    reason = test_mpi.mpi_missing_reason()
    if reason:
        sys.exit(f"mpi_sweep: {reason}")
    if arguments.restart:
        agreed = restarts(arguments.models, arguments.output)
    else:
        cases = [tuple(int(number) for number in case.split("x")) for case in arguments.cases.split(",")]
        agreed = sweep(arguments.models, cases, arguments.output)
    sys.exit(0 if agreed else 1)


if __name__ == "__main__":
    main()
