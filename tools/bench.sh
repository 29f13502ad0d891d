#!/usr/bin/env bash
# make bench: the solver's cost, measured in one session on this machine.
#  1. one-point hexahedra with plasticity: nanoseconds per element per cycle on a block of
#     100,000 elements thrown at a rigid wall (ncpu=1: median of three runs; ncpu=2 for
#     information, the two cores of this machine share their caches and load);
#  2. the same block with 0%, about 7.6% and about 19% of its dofs meshfree (the paper's ODB and
#     dummy ratios): CPU time per cycle relative to the all-FE block;
#  3. an all-EFG block: nanoseconds per interior particle per cycle and set-up per particle;
#  4. Belytschko-Tsay shells: the square tube of inputs/tube_crush (6,400 shells, NIP 5, MAT_024,
#     single-surface contact), its first 5 mm of crush: nanoseconds per shell per cycle;
#  5. element order: a block of 100 x 100 x 10 hexahedra numbered naturally and at random, ncpu=1
#     and 2 (tools/bench_ordering.py: solid phase, medians of 3 alternating runs);
#  6. the vehicle front structure of inputs/vehicle_front (about 11,300 shells of 8-60 mm, one
#     single-surface contact over all parts), its first 3 ms into the wall, ncpu=1: nanoseconds per
#     shell per cycle for the shells, the contact and the rest (tools/bench_vehicle.py).
set -euo pipefail
python=${PYTHON:-python3}
directory=build/bench
mkdir -p "$directory"
make_deck() { [ -f "$1" ] || "$python" tools/make_bench_deck.py "$@"; }
run() { bin/crashfree i="$1" outdir="$directory" jobid="$2" ncpu="$3" > "$directory/$2.log"; }

make_deck "$directory/block_100k.k" --cells 50 50 40 --cycles 200
make_deck "$directory/coupled_7.k" --cells 50 50 40 --cycles 200 --efg-cells 3
make_deck "$directory/coupled_19.k" --cells 50 50 40 --cycles 200 --efg-cells 9
make_deck "$directory/efg_block.k" --cells 20 20 20 --cycles 100 --efg-cells 20
[ -f "$directory/tube.k" ] || "$python" inputs/tube_crush/generate_tube.py --element 2.5 --crush 5 \
  --output "$directory/tube.k" > /dev/null
for repetition in 1 2 3; do run "$directory/block_100k.k" "fe_ncpu1_run$repetition" 1; done
run "$directory/block_100k.k" fe_ncpu2 2
run "$directory/coupled_7.k" coupled_7 1
run "$directory/coupled_19.k" coupled_19 1
run "$directory/efg_block.k" efg_block 1
run "$directory/tube.k" tube_shells 1
[ -f "$directory/vehicle_front.k" ] || "$python" inputs/vehicle_front/generate_vehicle.py --end-time 3 \
  --output "$directory/vehicle_front.k" > /dev/null
run "$directory/vehicle_front.k" vehicle_front 1
"$python" tools/bench_report.py "$directory"
echo
"$python" tools/bench_ordering.py --directory "$directory/ordering" | sed -n '/^Solid phase/,$p'
echo
"$python" tools/bench_vehicle.py "$directory/vehicle_front.h5"
