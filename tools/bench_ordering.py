#!/usr/bin/env python3
"""Does the deck's numbering still matter? Times the solid phase of one block of 100 x 100 x 10
one-point hexahedra (tools/make_bench_deck.py) numbered naturally, numbered at random
(--renumber: random node and element ids, elements in random order) and numbered at random with
the nodes in random order too (--shuffle-nodes), with 1 and 2 threads. Every
combination runs --repetitions times, the combinations alternating within each repetition so
that a change in the machine's load hits all of them alike; the table gives medians.

    python3 tools/bench_ordering.py [--binary NAME=PATH ...] [--directory build/bench_ordering]
                                    [--repetitions 3] [--cycles 200]

Without --binary it times bin/crashfree. With several binaries (before and after a change) they
alternate too. Every run reports how busy the other processes kept the machine meanwhile (from
/proc/stat, less the run's own CPU time); on a shared machine, --busy-limit F waits until the
others use less than F of the processors and repeats a run they disturbed more than that
(up to --attempts times). Element ordering: docs/solver.md, "Element order and blocks".
"""
import argparse
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

import h5py

REPOSITORY = Path(__file__).resolve().parents[1]


def timing(path):
    with h5py.File(path, "r") as results:
        return dict(results["timing"].attrs)


def processor_seconds():
    """Busy and total processor seconds of the whole machine so far (Linux /proc/stat)."""
    with open("/proc/stat") as stat:
        values = [int(value) for value in stat.readline().split()[1:]]
    ticks = os.sysconf("SC_CLK_TCK")
    idle = values[3] + values[4]
    return (sum(values) - idle) / ticks, sum(values) / ticks


def others_load(seconds=1.0):
    """Fraction of the processors that other processes kept busy over the next `seconds`."""
    busy, total = processor_seconds()
    time.sleep(seconds)
    busy_after, total_after = processor_seconds()
    return (busy_after - busy) / max(total_after - total, 1e-9)


def timed_run(command, log_path):
    """Run the solver; return the fraction of the processors the other processes used meanwhile."""
    busy, total = processor_seconds()
    own = resource.getrusage(resource.RUSAGE_CHILDREN)
    with open(log_path, "w") as log:
        subprocess.run(command, stdout=log, stderr=subprocess.STDOUT, check=True)
    busy_after, total_after = processor_seconds()
    own_after = resource.getrusage(resource.RUSAGE_CHILDREN)
    own_seconds = (own_after.ru_utime - own.ru_utime) + (own_after.ru_stime - own.ru_stime)
    return max(0.0, (busy_after - busy) - own_seconds) / max(total_after - total, 1e-9)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--binary", action="append", default=[], metavar="NAME=PATH")
    parser.add_argument("--directory", default=str(REPOSITORY / "build" / "bench_ordering"))
    parser.add_argument("--repetitions", type=int, default=3)
    parser.add_argument("--cycles", type=int, default=200)
    parser.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--busy-limit", type=float, help="wait for and repeat runs below this load of others")
    parser.add_argument("--attempts", type=int, default=5)
    options = parser.parse_args()
    binaries = dict(entry.split("=", 1) for entry in options.binary) or {"crashfree": str(REPOSITORY / "bin" / "crashfree")}
    directory = Path(options.directory)
    directory.mkdir(parents=True, exist_ok=True)
    decks = {}
    for numbering, extra in (("natural", []), ("renumbered", ["--renumber", "7"]),
                             ("renumbered_nodes_shuffled", ["--renumber", "7", "--shuffle-nodes"])):
        deck = directory / f"block_{numbering}_{options.cycles}.k"
        if not deck.exists():
            subprocess.run([sys.executable, str(REPOSITORY / "tools" / "make_bench_deck.py"), str(deck),
                            "--cells", "100", "100", "10", "--cycles", str(options.cycles)] + extra, check=True)
        decks[numbering] = deck

    solid = {}
    setup = {}
    per_element = {}
    for repetition in range(1, options.repetitions + 1):
        for name, binary in binaries.items():
            for numbering, deck in decks.items():
                for threads in options.threads:
                    jobid = f"{name}_{numbering}_ncpu{threads}_run{repetition}"
                    command = [binary, f"i={deck}", f"outdir={directory}", f"jobid={jobid}", f"ncpu={threads}"]
                    for attempt in range(1, options.attempts + 1):
                        if options.busy_limit is not None:
                            waited = time.monotonic()
                            while others_load() > options.busy_limit and time.monotonic() - waited < 900:
                                time.sleep(5)
                        others = timed_run(command, directory / f"{jobid}.log")
                        if options.busy_limit is None or others <= options.busy_limit:
                            break
                        print(f"{jobid}: others used {100 * others:.0f}% of the processors, again", flush=True)
                    attributes = timing(directory / f"{jobid}.h5")
                    key = (name, numbering, threads)
                    solid.setdefault(key, []).append(attributes["fe_solid_s"])
                    setup.setdefault(key, []).append(attributes["setup_s"])
                    per_element.setdefault(key, []).append(
                        1e9 * attributes["fe_solid_s"] / (attributes["fe_elements"] * attributes["cycles"]))
                    print(f"{jobid}: solids {attributes['fe_solid_s']:.3f} s, set-up {attributes['setup_s']:.3f} s, "
                          f"others' load {100 * others:.0f}%", flush=True)

    print()
    print(f"Solid phase of 100,000 hexahedra, {options.cycles} cycles: median of {options.repetitions} "
          "alternating runs (every run in the last column)")
    print()
    print("| binary | numbering | ncpu | solids s | ns per element per cycle | set-up s | runs (solids s) |")
    print("|---|---|---|---|---|---|---|")
    for key, seconds in solid.items():
        name, numbering, threads = key
        median = statistics.median(seconds)
        print(f"| {name} | {numbering} | {threads} | {median:.2f} | {statistics.median(per_element[key]):.0f} "
              f"| {statistics.median(setup[key]):.2f} "
              f"| {', '.join(f'{value:.2f}' for value in seconds)} |")


if __name__ == "__main__":
    main()
