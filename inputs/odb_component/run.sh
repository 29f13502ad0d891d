#!/usr/bin/env bash
# ODB component test (docs/examples/odb_component.md): write the decks, run the FE deck and the
# coupled deck, and post-process. Run from the repository root after `make`:
#
#   inputs/odb_component/run.sh            # SIZE=40 mm elements, NCPU=1, into results/odb_component
#   SIZE=50 inputs/odb_component/run.sh    # the coarse variant (about a minute in all)
#
# crashfree rejects *MAT_MODIFIED_HONEYCOMB in a meshfree part today, so coupled.k (honeycomb in
# the meshfree corner) stops with a deck error; the script then runs the stand-in pair
# (fe_standin.k, coupled_standin.k: the corner part of an elastic-plastic stand-in) and compares
# FE honeycomb, FE stand-in and coupled stand-in.
set -uo pipefail
size=${SIZE:-40}
ncpu=${NCPU:-1}
output=${OUTPUT:-results/odb_component}
python=${PYTHON:-python3}
decks="$output/decks_${size}mm"
mkdir -p "$output"
"$python" inputs/odb_component/generate_mesh.py --size "$size" -o "$decks" || exit 1
run() {   # run DECK NAME
  bin/crashfree i="$decks/$1.k" outdir="$output/$1" ncpu="$ncpu"
}
run fe || exit 1
if run coupled; then
  "$python" postproc/odb_component.py "$output/fe/results.h5" "$output/coupled/results.h5" \
    --labels "FE" "coupled" -o "$output" || exit 1
else
  echo
  echo "coupled.k was rejected (honeycomb in a meshfree part): running the stand-in decks"
  run fe_standin || exit 1
  run coupled_standin || exit 1
  "$python" postproc/odb_component.py "$output/fe/results.h5" "$output/fe_standin/results.h5" \
    "$output/coupled_standin/results.h5" --labels "FE honeycomb" "FE stand-in" "coupled stand-in" \
    -o "$output" || exit 1
fi
echo "results: $output/*/results.h5 (open results.xdmf in ParaView)"
