#!/usr/bin/env python3
"""Print the tables of tools/bench_contact.sh from the results files in its directory: per
deck size the medians over the runs of shell and contact nanoseconds per shell per cycle (the
solver's /timing: fe_shell_s and contact_s over fe_shells x cycles) and their ratio.

    bench_contact_report.py DIRECTORY            (runs new_<scale>_run<k>.h5)
    bench_contact_report.py DIRECTORY compare    (runs old_* and new_*: both builds)
"""
import statistics
import sys
from pathlib import Path

import h5py


def timing(path):
    with h5py.File(path, "r") as results:
        return dict(results["timing"].attrs)


def figures(directory, build, scale):
    runs = [timing(path) for path in sorted(directory.glob(f"{build}_{scale}_run*.h5"))]
    if not runs:
        return None
    per = [1e9 / (t["fe_shells"] * t["cycles"]) for t in runs]
    shell = [t["fe_shell_s"] * p for t, p in zip(runs, per)]
    contact = [t["contact_s"] * p for t, p in zip(runs, per)]
    return {"shells": int(runs[0]["fe_shells"]), "cycles": int(runs[0]["cycles"]), "runs": len(runs),
            "shell": statistics.median(shell), "contact": statistics.median(contact),
            "contact_runs": contact}


def main():
    directory = Path(sys.argv[1])
    compare = len(sys.argv) > 2 and sys.argv[2] == "compare"
    builds = ["old", "new"] if compare else ["new"]
    scales = ["2", "1"] if compare else ["2", "1", "0.5"]
    print("Contact at vehicle scale: tools/make_vehicle_deck.py (single-surface contact over all parts, "
          "rigid wall), ncpu=1, medians of alternating runs")
    print()
    print("| build | shells | cycles | runs | shell ns/shell/cycle | contact ns/shell/cycle (runs) | contact / shell |")
    print("|---|---|---|---|---|---|---|")
    for scale in scales:
        for build in builds:
            f = figures(directory, build, scale)
            if f is None:
                continue
            runs = ", ".join(f"{value:.0f}" for value in f["contact_runs"])
            print(f"| {build} | {f['shells']} | {f['cycles']} | {f['runs']} | {f['shell']:.0f} | {f['contact']:.1f} "
                  f"({runs}) | {f['contact'] / f['shell']:.3f} |")


if __name__ == "__main__":
    main()
