#!/usr/bin/env bash
# make bench: ns per element per cycle of the one-point hexahedron with plasticity, on a block
# of 100,000 elements, for ncpu=1 (the figure to compare) and ncpu=2 (for information: this
# machine's two cores share their caches and load).
set -euo pipefail
python=${PYTHON:-python3}
directory=build/bench
mkdir -p "$directory"
deck=$directory/block_100k.k
[ -f "$deck" ] || "$python" tools/make_bench_deck.py "$deck" --cells 50 50 40 --cycles 200
for threads in 1 2; do
  bin/crashfree i="$deck" outdir="$directory" jobid="block_ncpu$threads" ncpu=$threads > "$directory/block_ncpu$threads.log"
done
"$python" - "$directory" <<'PYTHON'
import sys
import h5py
directory = sys.argv[1]
print("| case | threads | elements | cycles | solid ns/element/cycle | whole cycle ns/element | setup s |")
print("|---|---|---|---|---|---|---|")
for threads in (1, 2):
    with h5py.File(f"{directory}/block_ncpu{threads}.h5", "r") as results:
        timing = results["timing"].attrs
        elements, cycles = int(timing["fe_elements"]), int(timing["cycles"])
        solid = 1e9 * timing["fe_solid_s"] / (elements * cycles)
        loop = 1e9 * (timing["wall_s"] - timing["setup_s"] - timing["output_s"]) / (elements * cycles)
        print(f"| hex8 ELFORM 1, MAT_003 | {threads} | {elements} | {cycles} | {solid:.1f} | {loop:.1f} | {timing['setup_s']:.2f} |")
PYTHON
