#!/usr/bin/env python3
"""Time history of one column of one history group, one curve per results file, to compare
runs (FE against EFG, two meshes, two thread counts ...).

    python3 postproc/plot_history.py a/results.h5 b/results.h5 --group rwforc/1 --column force \\
        --component z -o force.png
    python3 postproc/plot_history.py results.h5 --group nodout/5 --column displacement
    python3 postproc/plot_history.py results.h5 --list      # the groups and columns there are

Vector columns (force, displacement, velocity, acceleration) are shown as one component or
as their magnitude (the default). ``--csv`` also writes the curves as a table.
"""
from __future__ import annotations

import argparse
import csv
import sys

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

import crashfree_results as cr


def history_curve(results_path, group: str, column: str, component: str = "magnitude"):
    """``(time, values, is_vector)`` of one column of a history group of one results file;
    ``values`` is the chosen component (or magnitude) when the column is a vector."""
    with cr.open_results(results_path) as results:
        history = cr.read_history(results, group)
    if column not in history:
        columns = ", ".join(sorted(name for name in history if name != "time"))
        raise cr.ResultsError(f"{results_path}: history {group!r} has no column {column!r} "
                              f"(columns: {columns})")
    values = history[column]
    return history["time"], cr.select_component(values, component), values.ndim == 2


def default_output(group: str, column: str, component: str) -> str:
    """A file name that says what is plotted: ``rwforc_1_force_z.png`` for a component,
    ``rwforc_1_force.png`` for the magnitude or a scalar column."""
    suffix = "" if component == "magnitude" else f"_{component}"
    return f"{group.strip('/').replace('/', '_')}_{column}{suffix}.png"


def plot_histories(paths, group: str, column: str, component: str, output_path,
                   labels=None, title: str | None = None, csv_path=None) -> list:
    """Plot the column of every file into the PNG ``output_path`` (and the CSV ``csv_path``
    when given). Returns ``[(label, time, values), ...]``."""
    labels = list(labels) if labels else cr.run_labels(paths)
    if len(labels) != len(paths):
        raise cr.ResultsError(f"{len(labels)} labels for {len(paths)} files")
    curves = []
    vector = False
    for path, label in zip(paths, labels):
        time, values, is_vector = history_curve(path, group, column, component)
        curves.append((label, time, values))
        vector = vector or is_vector
    quantity = f"{column} ({component})" if vector else column
    figure = Figure(figsize=(8.0, 5.0), constrained_layout=True)
    FigureCanvasAgg(figure)
    axes = figure.subplots()
    for label, time, values in curves:
        axes.plot(time, values, label=label)
    axes.set_xlabel("time")
    axes.set_ylabel(quantity)
    axes.set_title(title or f"{group}: {quantity}")
    axes.grid(True, alpha=0.3)
    if len(curves) > 1:
        axes.legend(loc="best")
    figure.savefig(output_path, dpi=120)

    if csv_path:
        write_curves_csv(csv_path, curves, quantity)
    return curves


def write_curves_csv(path, curves, quantity: str) -> None:
    """One pair of columns (time, value) per curve; shorter curves leave blank cells."""
    rows = max(len(time) for _, time, _ in curves)
    with open(path, "w", newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow([heading for label, _, _ in curves
                         for heading in (f"{label}: time", f"{label}: {quantity}")])
        for row in range(rows):
            cells = []
            for _, time, values in curves:
                if row < len(time):
                    cells += [repr(float(time[row])), repr(float(values[row]))]
                else:
                    cells += ["", ""]
            writer.writerow(cells)


def describe_histories(results_path) -> str:
    """The history groups of a file with their columns and lengths, one group a line."""
    lines = []
    with cr.open_results(results_path) as results:
        for group in cr.list_history_groups(results):
            history = cr.read_history(results, group)
            columns = ", ".join(f"{name}{'(3)' if values.ndim == 2 else ''}"
                                for name, values in history.items() if name != "time")
            lines.append(f"{group}: {len(history.get('time', []))} samples; {columns}")
    return "\n".join(lines)


def build_parser() -> argparse.ArgumentParser:
    """The command line of the script."""
    parser = argparse.ArgumentParser(
        description="Plot one column of a history group (rwforc/<id>, nodout/<id>, glstat, "
                    "matsum/<id>, rcforc/<id>) of one or more crashfree results files, one "
                    "curve per file.")
    parser.add_argument("results", nargs="+", help="results files (results.h5)")
    parser.add_argument("--group", help="history group, e.g. rwforc/1, nodout/5, glstat")
    parser.add_argument("--column", help="column, e.g. force, displacement, kinetic_energy")
    parser.add_argument("--component", choices=cr.COMPONENTS, default="magnitude",
                        help="component of a vector column (default: magnitude)")
    parser.add_argument("-o", "--output",
                        help="PNG to write (default: <group>_<column>[_<component>].png)")
    parser.add_argument("--label", action="append",
                        help="legend label of each file, in order (repeat; default: file or "
                             "directory names)")
    parser.add_argument("--title", help="plot title")
    parser.add_argument("--csv", help="also write the curves to this CSV file")
    parser.add_argument("--list", action="store_true",
                        help="list the history groups and columns of each file and stop")
    return parser


def main(argv=None) -> int:
    """Run the script on ``argv`` (default: the command line); return the exit status."""
    parser = build_parser()
    arguments = parser.parse_args(argv)
    try:
        if arguments.list:
            for path in arguments.results:
                print(f"{path}:\n{describe_histories(path)}")
            return 0
        if not arguments.group or not arguments.column:
            parser.error("--group and --column are required (use --list to see them)")
        output = arguments.output or default_output(arguments.group, arguments.column,
                                                    arguments.component)
        curves = plot_histories(arguments.results, arguments.group, arguments.column,
                                arguments.component, output, arguments.label, arguments.title,
                                arguments.csv)
    except (cr.ResultsError, KeyError, OSError) as error:
        print(f"plot_history: {error}", file=sys.stderr)
        return 1
    for label, time, values in curves:
        if len(time) == 0:
            print(f"{label}: no samples")
            continue
        extreme = values[abs(values).argmax()]
        print(f"{label}: {len(time)} samples to t = {time[-1]:.6g}; peak {extreme:.6g}, "
              f"final {values[-1]:.6g}")
    print(f"plot: {output}" + (f", table: {arguments.csv}" if arguments.csv else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
