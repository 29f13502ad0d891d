#!/usr/bin/env bash
# Run each unit-test program given as an argument and print the summed counts last.
passed=0
failed=0
for program in "$@"; do
  output=$("$program" 2>&1)
  status=$?
  echo "$output" | grep -v -E '^[0-9]+ passed, [0-9]+ failed$'
  counts=$(echo "$output" | grep -E '^[0-9]+ passed, [0-9]+ failed$' | tail -n 1)
  if [ -z "$counts" ]; then
    echo "FAIL $(basename "$program"): ended without a summary (exit status $status)"
    failed=$((failed + 1))
    continue
  fi
  p=${counts%% passed*}
  f=${counts#*, }
  f=${f%% failed*}
  echo "$(basename "$program"): $counts"
  passed=$((passed + p))
  failed=$((failed + f))
  if [ "$status" -ne 0 ] && [ "$f" -eq 0 ]; then failed=$((failed + 1)); fi
done
echo "unit: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
