#!/usr/bin/env bash
# ODB component test (docs/examples/odb_component.md): run the FE deck and the coupled deck,
# alternately, REPEAT times each (default 1), and post-process the last pair. Run from the
# repository root after `make`:
#
#   inputs/odb_component/run.sh                    # the shipped decks, NCPU=1, into results/odb_component_pair
#   REPEAT=3 inputs/odb_component/run.sh           # the timing study: median CPU time of 3 runs each
#   EXPORT=1 inputs/odb_component/run.sh           # also rewrite the shipped FE reference
#                                                  # (inputs/odb_component/fe_reference.npz)
#   SIZE=50 inputs/odb_component/run.sh            # regenerate the decks at another element size first
#
# The user CPU seconds of each run go to cpu_seconds.txt beside its results (the machine may be
# shared: CPU time, not wall time, is what the ratio compares); all of them to cpu_times.txt.
set -euo pipefail
ncpu=${NCPU:-1}
repeat=${REPEAT:-1}
output=${OUTPUT:-results/odb_component_pair}
python=${PYTHON:-python3}
decks=inputs/odb_component
mkdir -p "$output"
if [ -n "${SIZE:-}" ]; then
  decks="$output/decks_${SIZE}mm"
  "$python" inputs/odb_component/generate_mesh.py --size "$SIZE" -o "$decks"
fi
run() {   # run NAME
  local directory="$output/$1"
  mkdir -p "$directory"
  local TIMEFORMAT='%3U'
  { time bin/crashfree i="$decks/$1.k" outdir="$directory" ncpu="$ncpu" 2>&3; } 3>&2 2>"$directory/cpu_seconds.txt"
  echo "$1 $(cat "$directory/cpu_seconds.txt") $(uptime | sed 's/.*load average: //')" | tee -a "$output/cpu_times.txt"
}
: > "$output/cpu_times.txt"
for k in $(seq "$repeat"); do
  run fe
  run coupled
done
"$python" - "$output/cpu_times.txt" <<'PY'
import statistics, sys
times = {}
for line in open(sys.argv[1]):
    name, seconds = line.split()[:2]
    times.setdefault(name, []).append(float(seconds))
fe, coupled = statistics.median(times["fe"]), statistics.median(times["coupled"])
print(f"median user CPU of {len(times['fe'])} runs: FE {fe:.1f} s, coupled {coupled:.1f} s, ratio {coupled / fe:.3f}")
PY
"$python" postproc/odb_component.py "$output/fe/results.h5" "$output/coupled/results.h5" -o "$output"
if [ "${EXPORT:-0}" = 1 ]; then
  "$python" postproc/odb_component.py "$output/fe/results.h5" --export-reference inputs/odb_component/fe_reference.npz
fi
echo "results: $output/{fe,coupled}/results.h5 (open results.xdmf in ParaView)"
