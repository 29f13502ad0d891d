#!/usr/bin/env python3
"""Print the tables of `make bench` from the results files in the bench directory."""
import statistics
import sys
from pathlib import Path

import h5py


def timing(path):
    with h5py.File(path, "r") as results:
        attributes = dict(results["timing"].attrs)
    attributes["loop_s"] = attributes["wall_s"] - attributes["setup_s"] - attributes["output_s"]
    return attributes


def main():
    directory = Path(sys.argv[1])
    runs = [timing(directory / f"fe_ncpu1_run{k}.h5") for k in (1, 2, 3)]
    per_element = [1e9 * t["fe_solid_s"] / (t["fe_elements"] * t["cycles"]) for t in runs]
    per_cycle = [1e9 * t["loop_s"] / (t["fe_elements"] * t["cycles"]) for t in runs]
    two = timing(directory / "fe_ncpu2.h5")
    print("One-point hexahedra (ELFORM 1, MAT_003), 100,000 elements")
    print()
    print("| threads | solid ns/element/cycle | whole cycle ns/element | setup s |")
    print("|---|---|---|---|")
    print(f"| 1 (median of 3; runs {', '.join(f'{v:.0f}' for v in per_element)}) | {statistics.median(per_element):.1f} "
          f"| {statistics.median(per_cycle):.1f} | {statistics.median(t['setup_s'] for t in runs):.2f} |")
    print(f"| 2 | {1e9 * two['fe_solid_s'] / (two['fe_elements'] * two['cycles']):.1f} "
          f"| {1e9 * two['loop_s'] / (two['fe_elements'] * two['cycles']):.1f} | {two['setup_s']:.2f} |")
    print()
    fe_cycle = statistics.median(t["loop_s"] / t["cycles"] for t in runs)
    print("Coupled FE + EFG block (same mesh, first layers EFG with DX 1.2), ncpu=1")
    print()
    print("| model | meshfree dofs | interior particles | ms per cycle | CPU ratio to all-FE | EFG set-up s |")
    print("|---|---|---|---|---|---|")
    print(f"| all FE | 0.0% | 0 | {1e3 * fe_cycle:.2f} | 1.00 | 0.00 |")
    for name in ("coupled_7", "coupled_19"):
        t = timing(directory / f"{name}.h5")
        cycle = t["loop_s"] / t["cycles"]
        print(f"| {name.replace('_', ' ')}% | {100 * t['dofs_efg'] / t['dofs_total']:.1f}% | {t['efg_particles']} "
              f"| {1e3 * cycle:.2f} | {cycle / fe_cycle:.2f} | {t['efg_setup_s']:.2f} |")
    print()
    t = timing(directory / "efg_block.h5")
    print("All-EFG block (20 x 20 x 20 cells, DX 1.2, box kernel), ncpu=1")
    print()
    print("| interior particles | ns per particle per cycle | set-up per particle (us) |")
    print("|---|---|---|")
    print(f"| {t['efg_particles']} | {1e9 * t['efg_s'] / (t['efg_particles'] * t['cycles']):.0f} "
          f"| {1e6 * t['efg_setup_s'] / t['efg_particles']:.0f} |")
    print()
    t = timing(directory / "tube_shells.h5")
    print("Belytschko-Tsay shells: square tube 50 x 1.5 mm, 2.5 mm elements, NIP 5, MAT_024, "
          "single-surface contact, first 5 mm of crush, ncpu=1")
    print()
    print("| shells | cycles | shell ns per element per cycle | contact ns per shell per cycle | "
          "whole cycle ns per shell |")
    print("|---|---|---|---|---|")
    per_shell = 1e9 / (t["fe_shells"] * t["cycles"])
    print(f"| {t['fe_shells']} | {t['cycles']} | {t['fe_shell_s'] * per_shell:.0f} | {t['contact_s'] * per_shell:.0f} "
          f"| {t['loop_s'] * per_shell:.0f} |")


if __name__ == "__main__":
    main()
