#!/usr/bin/env python3
"""The vehicle front-structure example's cost per phase, from /timing of its results file:
nanoseconds per shell per cycle for the shells, the contact, the rest of the cycle and the whole
cycle. Usage: bench_vehicle.py RESULTS.h5 [RESULTS.h5 ...] (one row each)."""
import sys

import h5py


def row(path):
    with h5py.File(path, "r") as results:
        timing = dict(results["timing"].attrs)
        title = results["run"].attrs.get("title", "")
    shells, cycles = int(timing["fe_shells"]), int(timing["cycles"])
    loop = timing["wall_s"] - timing["setup_s"] - timing["output_s"]
    rest = loop - timing["fe_shell_s"] - timing["contact_s"] - timing["fe_solid_s"] - timing["efg_s"]
    per = 1e9 / (shells * cycles)
    return (f"| {path} | {shells} | {cycles} | {timing['threads']} | {timing['fe_shell_s'] * per:.0f} "
            f"| {timing['contact_s'] * per:.0f} | {rest * per:.0f} | {loop * per:.0f} | {timing['setup_s']:.2f} |"), title


def main():
    print("Vehicle front structure (inputs/vehicle_front): shells, single-surface contact over all parts,"
          " planar wall")
    print()
    print("| results | shells | cycles | threads | shells ns/shell/cycle | contact ns/shell/cycle "
          "| rest of the cycle ns/shell | whole cycle ns/shell | setup s |")
    print("|---|---|---|---|---|---|---|---|---|")
    for path in sys.argv[1:]:
        print(row(path)[0])


if __name__ == "__main__":
    main()
