#!/usr/bin/env python3
"""The tables of tools/bench_mpi.sh from its directory: the timed runs (ranks_N/results.h5) and
the partitions (partition_N/results.h5, /run/partition).

    python3 tools/bench_mpi_report.py DIRECTORY
"""
import sys
from pathlib import Path

import h5py
import numpy as np

# what a stage-2 neighbour exchange would send per interface node: its force and moment (6 reals)
DOUBLES_PER_NODE = 6
# what stage 1's allgatherv sends per owned node (domain_exchange): 3 acceleration components, 10
# at the nodes of shells and beams (angular accelerations, the normal and area sums)
FORCE_REALS, MOMENT_REALS = 3, 10


def cycle_seconds(path):
    """Seconds of the cycle's phases (output excluded), cycles, elements. With several ranks, the
    slowest rank's phases and its nodal exchange with the wait before it (outside the phases)."""
    with h5py.File(path, "r") as results:
        timing = results["timing"].attrs
        phases = sum(float(timing[name]) for name in timing if name.startswith("phase_") and name != "phase_output_s")
        if "rank_seconds" in results["timing"]:
            names = [name.decode() for name in results["timing/rank_column_names"][...]]
            rows = results["timing/rank_seconds"][...]
            inside_phases = ("output", "contact_pair_exchange", "contact_pair_wait")
            phases = max(sum(value for name, value in zip(names, row) if name not in inside_phases) for row in rows)
        return phases, int(timing["cycles"]), int(timing["fe_elements"])


def print_phase_shares(path, cycles):
    """Milliseconds per cycle of the force, contact and other phases; with several ranks, each
    rank's (/timing/rank_seconds: what the first rank's clocks alone do not show)."""
    with h5py.File(path, "r") as results:
        timing = results["timing"]
        if "rank_seconds" in timing:
            names = [name.decode() for name in timing["rank_column_names"][...]]
            rows = timing["rank_seconds"][...]
        else:
            names = [name[len("phase_"):-len("_s")] for name in timing.attrs if name.startswith("phase_")]
            rows = np.array([[float(timing.attrs[f"phase_{name}_s"]) for name in names]])
    column = {name: k for k, name in enumerate(names)}
    exchange = [column[name] for name in ("nodal_exchange", "nodal_exchange_wait") if name in column]
    pairs = [column[name] for name in ("contact_pair_exchange", "contact_pair_wait") if name in column]
    others = [k for name, k in column.items() if name not in ("internal_forces", "contact", "output")
              and k not in exchange and k not in pairs]
    print(f"{'':>8}{'rank':>6} {'internal forces':>16} {'contact':>9} {'(pair exchange + wait)':>23} "
          f"{'nodal exchange + wait':>22} {'other phases':>13}   (ms per cycle)")
    for rank, row in enumerate(rows):
        scale = 1e3 / max(cycles, 1)
        print(f"{'':>8}{rank:>6} {scale * row[column['internal_forces']]:>16.1f} {scale * row[column['contact']]:>9.1f} "
              f"{scale * sum(row[k] for k in pairs):>23.1f} {scale * sum(row[k] for k in exchange):>22.1f} "
              f"{scale * sum(row[k] for k in others):>13.1f}")


def peak_memory(log):
    """Each process's peak resident memory in kB (bench_mpi.sh runs them under GNU time: one
    `peak_resident_kB=` line per rank, in the order they ended); [] without it."""
    if not log.exists():
        return []
    return sorted((int(line.split("=")[1]) for line in log.read_text().splitlines()
                   if line.startswith("peak_resident_kB=")), reverse=True)


def print_timed_runs(directory):
    """One pair of runs (ranks_1, ranks_2 in `directory`); returns {ranks: seconds per cycle}."""
    print(f"{'ranks':>6} {'cycles':>7} {'s per cycle':>12} {'ns per element per cycle':>25} {'efficiency':>11}")
    single = None
    found = {}
    for ranks in (1, 2):
        path = directory / f"ranks_{ranks}" / "results.h5"
        if not path.exists():
            print(f"{ranks:>6}   (not run)")
            continue
        seconds, cycles, elements = cycle_seconds(path)
        per_cycle = seconds / max(cycles, 1)
        found[ranks] = (per_cycle, elements)
        if ranks == 1:
            single = per_cycle
        efficiency = f"{single / (ranks * per_cycle):.2f}" if single else "-"
        print(f"{ranks:>6} {cycles:>7} {per_cycle:>12.4f} {1e9 * per_cycle / elements:>25.1f} {efficiency:>11}")
        print_phase_shares(path, cycles)
        log = directory / f"ranks_{ranks}.log"
        peaks = peak_memory(log)
        if peaks:
            print(f"        peak resident memory per rank, largest first: "
                  f"{', '.join(f'{peak / 2**20:.2f} GB' for peak in peaks)} ({peaks[0] / elements:.2f} kB per element)")
        if ranks > 1 and log.exists():
            for line in log.read_text().splitlines():
                if line.strip().startswith("MPI:") and "seconds per rank" not in line:
                    print("        " + line.strip())
    return found


def main():
    directory = Path(sys.argv[1])
    print("Timed runs (ncpu=1 per rank):")
    pairs = sorted(directory.glob("pair_*"), key=lambda path: int(path.name.split("_")[1]))
    if not pairs:
        pairs = [directory]
    timed = []
    for pair in pairs:
        if len(pairs) > 1:
            print(f"  {pair.name}:")
        timed.append(print_timed_runs(pair))
    if len(timed) > 1 and all(1 in runs and 2 in runs for runs in timed):
        one = np.median([runs[1][0] for runs in timed])
        two = np.median([runs[2][0] for runs in timed])
        elements = timed[0][1][1]
        print(f"  medians of {len(timed)} alternating pairs: N = 1 {one:.4f} s per cycle "
              f"({1e9 * one / elements:.1f} ns per element), N = 2 {two:.4f} s ({1e9 * two / elements:.1f} ns), "
              f"speed-up {one / two:.2f}, efficiency {one / (2 * two):.2f}")

    print()
    print("Partitions (partition=N; costs estimated from the per-kind lane costs):")
    header = (f"{'ranks':>6} {'imbalance':>9} {'with ghosts':>11} {'blocks/rank':>11} {'ghost mean':>10} "
              f"{'ghost max':>9} {'owned nodes':>11} {'interface mean':>14} {'interface max':>13} "
              f"{'interface/owned':>15} {'stage-2 kB/cycle':>16} {'stage-1 kB/cycle':>16}")
    print(header)
    for path in sorted(directory.glob("partition_*/results.h5"), key=lambda p: int(p.parent.name.split("_")[1])):
        with h5py.File(path, "r") as results:
            partition = results["run/partition"]
            ranks = int(partition.attrs["rank_count"])
            blocks = partition["rank_blocks"][()]
            ghosts = partition["rank_ghost_blocks"][()]
            owned = partition["rank_owned_nodes"][()]
            interface = partition["rank_interface_nodes"][()]
            nodes = owned.sum()
            owner = partition["node_rank"][()]
            moment_nodes = np.zeros(len(owner), dtype=bool)
            if "mesh/shells" in results:
                ids = results["mesh/nodes/ids"][()]
                order = np.argsort(ids)
                shell_nodes = results["mesh/shells/connectivity"][()].ravel()
                moment_nodes[order[np.searchsorted(ids[order], shell_nodes)]] = True
            reals = np.where(moment_nodes, MOMENT_REALS, FORCE_REALS)
            # stage 1: each rank receives every other rank's owned nodes (allgatherv); the rank
            # owning the fewest values receives the most
            owned_reals = np.bincount(owner, weights=reals, minlength=ranks)
            stage_1 = (reals.sum() - owned_reals.min()) * 8 / 1024
            stage_2 = interface.max() * DOUBLES_PER_NODE * 8 / 1024
            print(f"{ranks:>6} {partition.attrs['imbalance']:>9.3f} {partition.attrs['computed_imbalance']:>11.3f} "
                  f"{blocks.mean():>11.1f} {ghosts.mean():>10.1f} {ghosts.max():>9d} {owned.mean():>11.0f} "
                  f"{interface.mean():>14.0f} {interface.max():>13d} {interface.mean() / owned.mean():>15.3f} "
                  f"{stage_2:>16.1f} {stage_1:>16.1f}")


if __name__ == "__main__":
    main()
