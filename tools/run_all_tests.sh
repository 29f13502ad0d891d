#!/usr/bin/env bash
# make test: release build, the layer check of src/ (tools/check_layers.py: one test), Fortran
# unit tests in the checked (debug) build, then the pytest regression tests on the release
# binary, then a short deck fuzzing run with both builds (each mutant deck and each stored
# reproducer of tests/fuzz/findings is one test). The last line adds them up: "N passed, N failed".
set -u
jobs=$(nproc 2>/dev/null || echo 2)
make --no-print-directory -s -j"$jobs" all || { echo "0 passed, 1 failed"; exit 1; }

echo "== layers (tools/check_layers.py: a folder of src/ uses only the folders below it) =="
layers_passed=0
layers_failed=1
if ${PYTHON:-python3} tools/check_layers.py; then
  layers_passed=1
  layers_failed=0
fi

echo "== unit tests (MODE=debug: -std=f2008 -fcheck=all -ffpe-trap=invalid,zero,overflow) =="
unit_log=$(mktemp)
make --no-print-directory -s -j"$jobs" MODE=debug unit 2>&1 | tee "$unit_log"
unit_line=$(grep -E '^unit: [0-9]+ passed, [0-9]+ failed' "$unit_log" | tail -n 1)
unit_passed=0
unit_failed=1
if [ -n "$unit_line" ]; then
  unit_passed=$(echo "$unit_line" | sed -E 's/^unit: ([0-9]+) passed.*/\1/')
  unit_failed=$(echo "$unit_line" | sed -E 's/.* ([0-9]+) failed.*/\1/')
fi
rm -f "$unit_log"

echo "== regression tests (pytest on results.h5) =="
regression_log=$(mktemp)
${PYTHON:-python3} -m pytest -q -p no:cacheprovider tests/regression 2>&1 | tee "$regression_log"
summary=$(grep -E ' in [0-9.]+s' "$regression_log" | tail -n 1)
count() { echo "$summary" | grep -oE "[0-9]+ $1" | grep -oE '^[0-9]+' | awk '{s += $1} END {print s + 0}'; }
regression_passed=$(count passed)
regression_failed=$(( $(count failed) + $(count errors?) ))
if [ "$regression_passed" -eq 0 ]; then regression_failed=$((regression_failed + 1)); fi
rm -f "$regression_log"

echo "== deck fuzzing, short run (release and debug builds, fixed seed; docs/fuzzing.md) =="
fuzz_log=$(mktemp)
fuzz_passed=0
fuzz_failed=1
if make --no-print-directory -s -j"$jobs" MODE=debug all; then
  ${PYTHON:-python3} tests/fuzz/fuzz.py run --decks "${FUZZ_SHORT_DECKS:-400}" --seed "${FUZZ_SHORT_SEED:-1}" \
    --jobs "$jobs" --replay --quiet --findings "${TMPDIR:-/tmp}/crashfree-fuzz-findings/make-test" 2>&1 | tee "$fuzz_log"
  fuzz_line=$(grep -E '^fuzz: [0-9]+ passed, [0-9]+ failed' "$fuzz_log" | tail -n 1)
  if [ -n "$fuzz_line" ]; then
    fuzz_passed=$(echo "$fuzz_line" | sed -E 's/^fuzz: ([0-9]+) passed.*/\1/')
    fuzz_failed=$(echo "$fuzz_line" | sed -E 's/.* ([0-9]+) failed.*/\1/')
  fi
fi
rm -f "$fuzz_log"

passed=$((layers_passed + unit_passed + regression_passed + fuzz_passed))
failed=$((layers_failed + unit_failed + regression_failed + fuzz_failed))
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
