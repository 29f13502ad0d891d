#!/usr/bin/env bash
# Compare two builds on the bench decks, alternating their runs in one session (so that the
# machine's load falls on both alike): three runs each of the 100,000-hexahedron block, the
# coupled block with 19% of its dofs meshfree and the shell tube, on one thread. Prints each
# run's ns per element (particle) per cycle and wall time; compare medians.
#   tools/bench_compare.sh OLD_BINARY NEW_BINARY     (make bench writes the decks first)
set -u
old=$1
new=$2
decks=build/bench
out=$(mktemp -d)
for deck in block_100k coupled_19 tube; do
  [ -f "$decks/$deck.k" ] || { echo "missing $decks/$deck.k: run make bench once"; exit 1; }
done
for repetition in 1 2 3; do
  for build in old new; do
    binary=$old
    [ "$build" = new ] && binary=$new
    for deck in block_100k coupled_19 tube; do
      "$binary" i="$decks/$deck.k" outdir="$out" jobid="$deck" ncpu=1 > "$out/$deck.$build.$repetition.log" 2>&1
    done
  done
done
for deck in block_100k coupled_19 tube; do
  for build in old new; do
    printf '%-11s %-4s' "$deck" "$build"
    for repetition in 1 2 3; do
      log="$out/$deck.$build.$repetition.log"
      printf ' | %s %s' "$(grep -ohE '[0-9.]+ ns per (element|interior particle)' "$log" | cut -d' ' -f1 | tr '\n' ' ')" \
        "$(grep -oE 'wall time [0-9.]+s' "$log" | cut -d' ' -f3)"
    done
    echo
  done
done
rm -rf "$out"
