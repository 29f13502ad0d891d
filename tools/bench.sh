#!/usr/bin/env bash
# make bench: nanoseconds per element per cycle of the one-point hexahedron with plasticity, on
# a block of 100,000 elements thrown at a rigid wall. ncpu=1 is the figure to compare (three
# runs; the median is the figure, the spread shows the machine's noise); ncpu=2 is for
# information only (this machine's two cores share their caches and load).
set -euo pipefail
python=${PYTHON:-python3}
directory=build/bench
mkdir -p "$directory"
deck=$directory/block_100k.k
[ -f "$deck" ] || "$python" tools/make_bench_deck.py "$deck" --cells 50 50 40 --cycles 200
runs=()
for repetition in 1 2 3; do
  bin/crashfree i="$deck" outdir="$directory" jobid="block_ncpu1_run$repetition" ncpu=1 > "$directory/block_ncpu1_run$repetition.log"
  runs+=("$directory/block_ncpu1_run$repetition.h5")
done
bin/crashfree i="$deck" outdir="$directory" jobid="block_ncpu2" ncpu=2 > "$directory/block_ncpu2.log"
"$python" - "$directory/block_ncpu2.h5" "${runs[@]}" <<'PYTHON'
import statistics
import sys

import h5py


def figures(path):
    with h5py.File(path, "r") as results:
        timing = results["timing"].attrs
        element_cycles = int(timing["fe_elements"]) * int(timing["cycles"])
        solid = 1e9 * timing["fe_solid_s"] / element_cycles
        loop = 1e9 * (timing["wall_s"] - timing["setup_s"] - timing["output_s"]) / element_cycles
        return int(timing["fe_elements"]), int(timing["cycles"]), solid, loop, float(timing["setup_s"])


two_threads, single = sys.argv[1], sys.argv[2:]
rows = [figures(path) for path in single]
elements, cycles = rows[0][0], rows[0][1]
solid = [row[2] for row in rows]
loop = [row[3] for row in rows]
print("| case | threads | elements | cycles | solid ns/element/cycle | whole cycle ns/element | setup s |")
print("|---|---|---|---|---|---|---|")
print(f"| hex8 ELFORM 1, MAT_003 | 1 (median of {len(rows)}) | {elements} | {cycles} | "
      f"{statistics.median(solid):.1f} (runs {', '.join(f'{v:.0f}' for v in solid)}) | "
      f"{statistics.median(loop):.1f} | {statistics.median(row[4] for row in rows):.2f} |")
_, _, solid2, loop2, setup2 = figures(two_threads)
print(f"| hex8 ELFORM 1, MAT_003 | 2 | {elements} | {cycles} | {solid2:.1f} | {loop2:.1f} | {setup2:.2f} |")
PYTHON
