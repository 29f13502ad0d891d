#!/usr/bin/env bash
# The embedding API's internal force against the solver's meshfree kernel on the same part
# (tools/bench_api.py; docs/embedding.md, "Cost"): builds and installs the examples (make
# examples), then alternates solver and host runs, one thread each.
set -euo pipefail
python=${PYTHON:-python3}
make --no-print-directory -s examples
"$python" tools/bench_api.py --host build/release/examples/host_fortran --solver bin/crashfree \
  --directory build/bench/api "$@"
