#!/usr/bin/env bash
# make run: the offset deformable barrier component test (inputs/odb_component,
# docs/examples/odb_component.md). Runs the coupled FE/EFG deck (progress line), then writes the
# force plot, the deformed barrier and the summary table against the FE run.
#
# The FE run is shipped (inputs/odb_component/fe_reference.npz: its force and energy histories,
# summary numbers and deformed mesh, from `inputs/odb_component/run.sh`), which keeps `make run`
# to one run of about 1.3 minutes. ODB_FE=1 runs fe.k too (about 1 minute more), and the CPU
# ratio in the table is then measured on this machine. NCPU=n sets the threads (default 1).
set -euo pipefail
decks=inputs/odb_component
output=results/odb_component
python=${PYTHON:-python3}
ncpu=${NCPU:-1}
mkdir -p "$output"

run() {   # run NAME: decks/NAME.k into output/NAME, user CPU seconds in cpu_seconds.txt
  local directory="$output/$1"
  mkdir -p "$directory"
  local TIMEFORMAT='%3U'
  { time bin/crashfree i="$decks/$1.k" outdir="$directory" ncpu="$ncpu" 2>&3; } 3>&2 2>"$directory/cpu_seconds.txt"
}

if [ "${ODB_FE:-0}" = 1 ]; then
  run fe
  run coupled
  "$python" postproc/odb_component.py "$output/fe/results.h5" "$output/coupled/results.h5" -o "$output"
else
  run coupled
  "$python" postproc/odb_component.py "$output/coupled/results.h5" --reference "$decks/fe_reference.npz" \
    -o "$output"
fi
echo
echo "results: $output/coupled/results.h5 (open $output/coupled/results.xdmf in ParaView)"
echo "the example explained: docs/examples/odb_component.md; the Taylor bar: make taylor"
