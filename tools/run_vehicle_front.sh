#!/usr/bin/env bash
# make vehicle: the vehicle front structure (inputs/vehicle_front, docs/examples/vehicle_front.md)
# at 15 m/s into the rigid wall, then its plots and table. NCPU=n threads (default 1).
set -euo pipefail
output=results/vehicle_front
mkdir -p "$output"
bin/crashfree i=inputs/vehicle_front/vehicle.k outdir="$output" ncpu="${NCPU:-1}"
python=${PYTHON:-python3}
"$python" postproc/vehicle_front.py "$output/results.h5" -o "$output"
echo
echo "results: $output/results.h5 (open $output/results.xdmf in ParaView)"
