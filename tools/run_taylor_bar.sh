#!/usr/bin/env bash
# make taylor: the Taylor bar (inputs/taylor_bar, docs/examples/taylor_bar.md), then its plots.
set -euo pipefail
output=results/taylor_bar
mkdir -p "$output"
bin/crashfree i=inputs/taylor_bar/taylor_bar.k outdir="$output" ncpu="${NCPU:-1}"
python=${PYTHON:-python3}
"$python" postproc/plot_energy.py "$output/results.h5" -o "$output/energy.png"
"$python" postproc/taylor_bar.py "$output/results.h5" --markdown "$output/taylor_bar.md" --plot "$output/profile.png"
echo
echo "results: $output/results.h5 (open $output/results.xdmf in ParaView)"
echo "plots:   $output/energy.png $output/profile.png"
echo "figures: $output/taylor_bar.md"
