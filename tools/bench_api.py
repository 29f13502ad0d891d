#!/usr/bin/env python3
"""The cost of the embedding API's internal force (cf_efg_internal_force, docs/embedding.md)
against the solver's meshfree kernel on the same part: a block of CELLS^3 meshfree cells (box
kernel, DX 1.2, modified SCNI, elastic), its interior nodes moved by up to 10% of a cell by the
example hosts' own generator (reproduced here), so that the keyword deck and the host hold the
same nodes. One thread each (OMP_NUM_THREADS=1, ncpu=1). Runs alternate, solver then host,
REPEAT times; the figures are nanoseconds per integration point per call:
  - solver: the meshfree group's timer of the run summary (/timing efg_s) over CALLS force calls
    (cycle 0 and CALLS - 1 cycles), the mean over its calls;
  - host: the mean (and the median) of CALLS timed calls of cf_efg_internal_force, after a first
    untimed call that builds the part's run-time state (the solver builds it during its set-up).
    bench_api.py --host build/release/examples/host_fortran --solver bin/crashfree
                 --directory build/bench/api [--cells 16] [--calls 200] [--repeat 5]
"""
import argparse
import os
import statistics
import subprocess
from pathlib import Path

import h5py


def host_block(cells, perturbation=0.1, seed=11):
    """The example hosts' block_mesh: nodes x fastest, interior nodes moved by the integer
    generator state = (1103515245 state + 12345) mod 2^31."""
    n = cells + 1
    state = seed
    nodes = []
    for k in range(n):
        for j in range(n):
            for i in range(n):
                position = [float(i), float(j), float(k)]
                if 0 < i < cells and 0 < j < cells and 0 < k < cells:
                    for direction in range(3):
                        state = (1103515245 * state + 12345) % 2147483648
                        fraction = (state // 8388608) / 256.0
                        position[direction] += perturbation * (2.0 * fraction - 1.0)
                nodes.append(position)

    def index(i, j, k):
        return 1 + i + n * (j + n * k)

    hexahedra = [[index(i, j, k), index(i + 1, j, k), index(i + 1, j + 1, k), index(i, j + 1, k),
                  index(i, j, k + 1), index(i + 1, j, k + 1), index(i + 1, j + 1, k + 1), index(i, j + 1, k + 1)]
                 for k in range(cells) for j in range(cells) for i in range(cells)]
    return nodes, hexahedra


def write_deck(path, cells, calls):
    nodes, hexahedra = host_block(cells)
    with open(path, "w") as deck:
        deck.write("*KEYWORD\n*TITLE\nembedding benchmark: the example hosts' meshfree block\n")
        deck.write("*CONTROL_TERMINATION\n%10.3f%10d\n" % (1.0, calls - 1))
        deck.write("*DATABASE_BINARY_D3PLOT\n%10.3f\n" % 10.0)
        deck.write("*PART\nmeshfree block\n%10d%10d%10d\n" % (1, 1, 1))
        deck.write("*SECTION_SOLID_EFG\n%10d%10d\n%10.3f%10.3f%10.3f%10d%10d%10d%10d%10s\n"
                   % (1, 41, 1.2, 1.2, 1.2, 0, 0, 3, 1, "0.0"))
        deck.write("*MAT_ELASTIC\n%10d%10s%10s%10s\n" % (1, "7.85e-6", "210.0", "0.3"))
        deck.write("*INITIAL_VELOCITY\n%10d\n%10s%10s%10s\n" % (0, "0.0", "0.0", "-10.0"))
        deck.write("*NODE\n")
        for k, (x, y, z) in enumerate(nodes):
            deck.write(f"{k + 1:8d}{x:16.9e}{y:16.9e}{z:16.9e}{0:8d}{0:8d}\n")
        deck.write("*ELEMENT_SOLID\n")
        for k, corners in enumerate(hexahedra):
            deck.write(f"{k + 1:8d}{1:8d}" + "".join(f"{c:8d}" for c in corners) + "\n")
        deck.write("*END\n")
    return 8 * len(hexahedra)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--host", required=True)
    parser.add_argument("--solver", default="bin/crashfree")
    parser.add_argument("--directory", default="build/bench/api")
    parser.add_argument("--cells", type=int, default=16)
    parser.add_argument("--calls", type=int, default=200)
    parser.add_argument("--repeat", type=int, default=5)
    options = parser.parse_args()
    directory = Path(options.directory)
    directory.mkdir(parents=True, exist_ok=True)
    deck = directory / f"block_{options.cells}.k"
    points = write_deck(deck, options.cells, options.calls)
    environment = dict(os.environ, OMP_NUM_THREADS="1")
    solver, host, host_median = [], [], []
    for repetition in range(options.repeat):
        subprocess.run([options.solver, f"i={deck}", f"outdir={directory}", "jobid=solver", "ncpu=1"], check=True,
                       capture_output=True, env=environment)
        with h5py.File(directory / "solver.h5", "r") as results:
            timing = dict(results["timing"].attrs)
        calls = int(timing["cycles"]) + 1
        solver.append(1e9 * timing["efg_s"] / (points * calls))
        output = subprocess.run([options.host, "bench", str(options.cells), str(options.calls)], check=True,
                                capture_output=True, text=True, env=environment).stdout
        figures = dict(line.split()[:2] for line in output.splitlines())
        assert int(figures["integration_points"]) == points, output
        host.append(float(figures["ns_per_point_call_mean"]))
        host_median.append(float(figures["ns_per_point_call"]))
    print(f"Meshfree internal force, {options.cells}^3 cells, {points} integration points, {options.calls} calls, "
          f"one thread (ns per integration point per call; runs alternate)")
    print()
    print("| | median of the runs | fastest run | runs |")
    print("|---|---|---|---|")
    for name, values in (("solver (efg_s timer, mean per call)", solver),
                         ("API cf_efg_internal_force (mean per call)", host),
                         ("API cf_efg_internal_force (median call)", host_median)):
        print(f"| {name} | {statistics.median(values):.1f} | {min(values):.1f} | "
              f"{', '.join(f'{v:.1f}' for v in values)} |")
    print()
    print(f"API / solver: {statistics.median(host) / statistics.median(solver):.3f} (medians), "
          f"{min(host) / min(solver):.3f} (fastest runs)")


if __name__ == "__main__":
    main()
