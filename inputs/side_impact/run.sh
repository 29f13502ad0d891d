#!/usr/bin/env bash
# Side-impact dummy component test (docs/examples/side_impact.md): run fe.k, ribs_efg.k and
# coupled.k, alternately, REPEAT times each (default 1), then post-process the last three. Run
# from the repository root after `make` (`make side-impact` does both):
#
#   inputs/side_impact/run.sh                  # the shipped decks, NCPU=1, into results/side_impact
#   REPEAT=3 inputs/side_impact/run.sh         # the timing study: medians of 3 runs each
#   DECKS="fe coupled" inputs/side_impact/run.sh   # only some of the decks
#   DECK_DIR=DIR inputs/side_impact/run.sh     # decks written elsewhere by the generator (e.g. --end-time 10)
#
# The user CPU seconds of each run go to cpu_seconds.txt beside its results (the machine may be
# shared: CPU time, not wall time, is what the ratio compares); all of them, with the simulated
# time each run reached, to cpu_times.txt. A deck that stops with an error termination (exit 1:
# results kept) is part of the test, not a failure of this script.
set -euo pipefail
ncpu=${NCPU:-1}
repeat=${REPEAT:-1}
output=${OUTPUT:-results/side_impact}
python=${PYTHON:-python3}
decks=${DECK_DIR:-inputs/side_impact}
names=${DECKS:-fe ribs_efg coupled}
mkdir -p "$output"
run() {   # run NAME
  local directory="$output/$1"
  mkdir -p "$directory"
  local TIMEFORMAT='%3U'
  local status=0
  { time bin/crashfree i="$decks/$1.k" outdir="$directory" ncpu="$ncpu" >"$directory/log.txt" 2>&3; } \
    3>&2 2>"$directory/cpu_seconds.txt" || status=$?
  if [ "$status" -gt 1 ]; then
    echo "$1: the deck was rejected (exit $status); see $directory/log.txt" >&2
    return "$status"
  fi
  local reached
  reached=$("$python" -c "import h5py, sys; print(h5py.File(sys.argv[1], 'r')['history/glstat/time'][-1])" \
    "$directory/results.h5")
  echo "$1 $(cat "$directory/cpu_seconds.txt") $reached exit=$status $(tail -n 8 "$directory/log.txt" | grep -m1 -i 'termination')" \
    | tee -a "$output/cpu_times.txt"
}
: > "$output/cpu_times.txt"
for k in $(seq "$repeat"); do
  for name in $names; do
    run "$name"
  done
done
"$python" - "$output/cpu_times.txt" <<'PY'
import statistics, sys
per_ms = {}
for line in open(sys.argv[1]):
    words = line.split()
    per_ms.setdefault(words[0], []).append(float(words[1]) / float(words[2]))
medians = {name: statistics.median(values) for name, values in per_ms.items()}
for name, value in medians.items():
    print(f"{name}: median user CPU per simulated ms {value:.3f} s ({len(per_ms[name])} runs)")
if "fe" in medians:
    for name in medians:
        if name != "fe":
            print(f"CPU per simulated ms, {name} / fe: {medians[name] / medians['fe']:.2f}")
PY
results=()
labels=()
for name in $names; do
  results+=("$output/$name/results.h5")
  labels+=("$name")
done
"$python" postproc/side_impact.py "${results[@]}" --labels "${labels[@]}" -o "$output"
echo "results: $output/{$(echo "$names" | tr ' ' ',')}/results.h5 (open results.xdmf in ParaView)"
