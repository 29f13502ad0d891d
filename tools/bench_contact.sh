#!/usr/bin/env bash
# make bench, contact part: the vehicle-like shell structure of tools/make_vehicle_deck.py
# (edges 5-100 mm at 52,000 shells; single-surface contact over all parts; driven into a rigid
# wall) at three sizes, about 13,000, 52,000 and 209,000 shells (--scale 2, 1, 0.5), CYCLES
# cycles each (default 500), three runs per size alternating between the sizes, ncpu=1.
# tools/bench_contact_report.py prints the medians: shell and contact ns per shell per cycle,
# their ratio, and contact ns per shell per cycle across the sizes (flat when the search is linear).
#   tools/bench_contact.sh [DIRECTORY] [BINARY]
#   tools/bench_contact.sh compare OLD_BINARY NEW_BINARY   (old against new, alternating, on
#                                                           the two smaller sizes, 200 cycles)
set -euo pipefail
python=${PYTHON:-python3}
cycles=${CYCLES:-500}
if [ "${1:-}" = compare ]; then
  old=$2
  new=$3
  directory=build/bench/contact_compare
  mkdir -p "$directory"
  for scale in 2 1; do
    [ -f "$directory/vehicle_$scale.k" ] || "$python" tools/make_vehicle_deck.py "$directory/vehicle_$scale.k" \
      --scale "$scale" --cycles 200 > /dev/null
  done
  for repetition in 1 2 3; do
    for build in old new; do
      binary=$old
      [ "$build" = new ] && binary=$new
      for scale in 2 1; do
        "$binary" i="$directory/vehicle_$scale.k" outdir="$directory" jobid="${build}_${scale}_run$repetition" ncpu=1 \
          > "$directory/${build}_${scale}_run$repetition.log" 2>&1
      done
    done
  done
  "$python" tools/bench_contact_report.py "$directory" compare
  exit 0
fi
directory=${1:-build/bench/contact}
binary=${2:-bin/crashfree}
mkdir -p "$directory"
for scale in 2 1 0.5; do
  [ -f "$directory/vehicle_$scale.k" ] || "$python" tools/make_vehicle_deck.py "$directory/vehicle_$scale.k" \
    --scale "$scale" --cycles "$cycles" > /dev/null
done
for repetition in 1 2 3; do
  for scale in 2 1 0.5; do
    "$binary" i="$directory/vehicle_$scale.k" outdir="$directory" jobid="new_${scale}_run$repetition" ncpu=1 \
      > "$directory/new_${scale}_run$repetition.log" 2>&1
  done
done
"$python" tools/bench_contact_report.py "$directory"
