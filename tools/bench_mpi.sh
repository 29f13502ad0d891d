#!/usr/bin/env bash
# MPI scaling benchmark (not a test; docs/parallel_scaling.md): the 513,600-element deck of
# tools/make_scaling_deck.py (hexahedra dropped on a shell plate, single-surface contact), CYCLES
# cycles (default 300), ncpu=1 per rank:
#  1. N = 1 (no mpirun) and N = 2 (mpirun -np 2), REPEATS pairs alternating (default 1):
#     nanoseconds per element per cycle of the slowest rank's cycle (output excluded), parallel
#     efficiency T1 / (N TN), each rank's phases and peak resident memory; with several pairs the
#     medians;
#  2. the partition for N = 2 ... 1,024 ranks (partition=N: set-up only): imbalance, ghost blocks,
#     owned and interface nodes per rank, the communication volume per cycle per rank (stage 1's
#     allgatherv of the owned nodes' forces; a stage-2 neighbour exchange of the interface nodes:
#     6 doubles per node).
# A build without MPI refuses to run under mpirun (exit status 2): step 1 then reports N = 1 only.
#   [REPEATS=3] tools/bench_mpi.sh [DIRECTORY] [BINARY]
set -euo pipefail
python=${PYTHON:-python3}
cycles=${CYCLES:-300}
directory=${1:-build/bench/mpi}
binary=${2:-bin/crashfree}
mkdir -p "$directory"
deck=$directory/scaling.k
[ -f "$deck" ] || "$python" tools/make_scaling_deck.py "$deck" --cycles "$cycles"
# Open MPI refuses to start as root unless told (containers, this machine)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMP_NUM_THREADS=1

measure=""
[ -x /usr/bin/time ] && measure="/usr/bin/time -f peak_resident_kB=%M"

# REPEATS pairs of runs, N = 1 then N = 2, alternating (the machine's load drifts: medians of
# alternating runs compare the two under the same conditions)
repeats=${REPEATS:-1}
for pair in $(seq 1 "$repeats"); do
  run=$directory/pair_$pair
  mkdir -p "$run"
  # each process's own peak resident memory (GNU time's %M), one line per rank in the log
  $measure "$binary" i="$deck" outdir="$run/ranks_1" ncpu=1 > "$run/ranks_1.log" 2>&1
  status=0
  mpirun -np 2 --oversubscribe $measure "$binary" i="$deck" outdir="$run/ranks_2" ncpu=1 \
    > "$run/ranks_2.log" 2>&1 || status=$?
  if [ "$status" -ne 0 ]; then
    echo "N = 2 did not run (exit status $status; see $run/ranks_2.log):"
    grep -m1 "crashfree:" "$run/ranks_2.log" || true
    rm -rf "$run/ranks_2"
  fi
done
for ranks in 2 4 8 16 32 64 128 256 512 1024; do
  "$binary" i="$deck" outdir="$directory/partition_$ranks" partition="$ranks" ncpu=1 \
    > "$directory/partition_$ranks.log" 2>&1
done
"$python" tools/bench_mpi_report.py "$directory"
