#!/usr/bin/env python3
"""Energy balance of a crashfree run: the glstat energies against time (kinetic, internal,
hourglass, contact, external work, total) and, below, the energy ratio
total / (initial total + external work). Prints the energy ratio at the end.

    python3 postproc/plot_energy.py results.h5 -o energy.png
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

import crashfree_results as cr

#: glstat columns plotted when present, with their legend labels. ``rigid_wall_energy`` (the
#: energy the walls took, part of the total) is a column the solver adds to the contract's.
LABELS = {
    "kinetic_energy": "kinetic",
    "internal_energy": "internal",
    "hourglass_energy": "hourglass",
    "contact_energy": "contact",
    "rigid_wall_energy": "rigid walls",
    "external_work": "external work",
    "total_energy": "total",
}


def energy_summary(glstat: dict) -> dict:
    """End time, final energies, energy ratio and hourglass ratio of a glstat history."""
    summary = {"end_time": float(glstat["time"][-1]), "energy_ratio": cr.energy_ratio(glstat)}
    for name in cr.GLSTAT_ENERGIES:
        if name in glstat:
            summary[name] = float(glstat[name][-1])
    if "hourglass_energy" in glstat and "internal_energy" in glstat:
        summary["hourglass_ratio"] = cr.hourglass_ratio(glstat)
    return summary


def plot_energy(results_path, output_path, title: str | None = None) -> dict:
    """Plot the energies of ``results_path`` into the PNG ``output_path``; return
    :func:`energy_summary`."""
    with cr.open_results(results_path) as results:
        glstat = cr.read_history(results, "glstat")
        run = cr.read_run(results)
    if len(glstat.get("time", [])) == 0:
        raise cr.ResultsError(f"{results_path}: the glstat history is empty")
    missing = [name for name in ("total_energy", "external_work") if name not in glstat]
    if missing:
        raise cr.ResultsError(f"{results_path}: glstat lacks {', '.join(missing)}")

    time = glstat["time"]
    figure = Figure(figsize=(8.0, 6.5), constrained_layout=True)
    FigureCanvasAgg(figure)
    energies, ratio = figure.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [3, 1]})
    for name, label in LABELS.items():
        if name in glstat:
            style = {"linewidth": 2.0, "color": "black"} if name == "total_energy" else {}
            energies.plot(time, glstat[name], label=label, **style)
    energies.set_ylabel("energy")
    energies.grid(True, alpha=0.3)
    energies.legend(loc="best")
    energies.set_title(title or run.get("title") or Path(results_path).name)

    ratio_history = cr.energy_ratio_history(glstat)
    ratio.plot(time, ratio_history, color="black")
    ratio.axhline(1.0, color="gray", linestyle="--", linewidth=0.8)
    # at least +-2 % around 1, so that a perfect balance does not zoom into round-off
    low = min(0.98, float(min(ratio_history.min(), 1.0)) - 0.005)
    high = max(1.02, float(max(ratio_history.max(), 1.0)) + 0.005)
    ratio.set_ylim(low, high)
    ratio.ticklabel_format(axis="y", useOffset=False)
    ratio.set_xlabel("time")
    ratio.set_ylabel("energy ratio")
    ratio.grid(True, alpha=0.3)
    figure.savefig(output_path, dpi=120)
    return energy_summary(glstat)


def build_parser() -> argparse.ArgumentParser:
    """The command line of the script."""
    parser = argparse.ArgumentParser(
        description="Plot the glstat energies of a crashfree results file and print the energy "
                    "ratio total / (initial total + external work) at the end.")
    parser.add_argument("results", help="results file (results.h5)")
    parser.add_argument("-o", "--output", default="energy.png",
                        help="PNG to write (default: energy.png)")
    parser.add_argument("--title", help="plot title (default: the deck's title)")
    return parser


def main(argv=None) -> int:
    """Run the script on ``argv`` (default: the command line); return the exit status."""
    arguments = build_parser().parse_args(argv)
    try:
        summary = plot_energy(arguments.results, arguments.output, arguments.title)
    except (cr.ResultsError, KeyError, OSError) as error:
        print(f"plot_energy: {error}", file=sys.stderr)
        return 1
    ratio = summary["energy_ratio"]
    if np.isfinite(ratio):
        print(f"energy ratio (total / (initial total + external work)) at t = "
              f"{summary['end_time']:.6g}: {ratio:.4f}")
    else:
        print(f"energy ratio at t = {summary['end_time']:.6g}: undefined (no energy)")
    if np.isfinite(summary.get("hourglass_ratio", np.nan)):
        print(f"hourglass / internal energy at the end: {summary['hourglass_ratio']:.4f}")
    print(f"plot: {arguments.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
