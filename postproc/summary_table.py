#!/usr/bin/env python3
"""Markdown tables of crashfree runs: status, cycles, end time, wall time and time per phase,
the cost per element and cycle, and the energy checks (energy ratio, hourglass / internal).

    python3 postproc/summary_table.py results.h5                  # one table per run
    python3 postproc/summary_table.py fe/results.h5 efg/results.h5 --combined -o cpu.md

``ns/element/cycle`` is fe_solid_s / (fe_elements x cycles) x 1e9, the figure crash codes are
compared by; ``ns/particle/cycle`` does the same for efg_s and EFG particles.
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import crashfree_results as cr

#: (key, heading, format) of the rows, in order. A value of None is shown as "n/a".
ROWS = (
    ("title", "title", "{}"),
    ("status", "status", "{}"),
    ("message", "message", "{}"),
    ("threads", "threads", "{:d}"),
    ("cycles", "cycles", "{:d}"),
    ("end_time", "end time", "{:.6g}"),
    ("wall_s", "wall time (s)", "{:.3f}"),
    ("setup_s", "setup (s)", "{:.3f}"),
    ("fe_solid_s", "FE solids (s)", "{:.3f}"),
    ("fe_shell_s", "FE shells (s)", "{:.3f}"),
    ("efg_s", "EFG (s)", "{:.3f}"),
    ("contact_s", "contact (s)", "{:.3f}"),
    ("output_s", "output (s)", "{:.3f}"),
    ("other_s", "other (s)", "{:.3f}"),
    ("fe_elements", "FE elements", "{:d}"),
    ("efg_particles", "EFG particles", "{:d}"),
    ("dofs_total", "degrees of freedom", "{:d}"),
    ("ns_per_element_cycle", "FE solid ns/element/cycle", "{:.1f}"),
    ("ns_per_particle_cycle", "EFG ns/particle/cycle", "{:.1f}"),
    ("energy_ratio", "energy ratio", "{:.4f}"),
    ("hourglass_ratio", "hourglass / internal energy", "{:.4f}"),
)


def per_unit_ns(seconds, count, cycles):
    """seconds / (count x cycles) in nanoseconds; None when a factor is missing or zero."""
    if seconds is None or not count or not cycles:
        return None
    return seconds / (count * cycles) * 1e9


def run_summary(results_path) -> dict:
    """The numbers of one run, keyed as in ROWS (None where the file does not have them:
    a run that did not end has no /timing, a run without glstat no energy ratio)."""
    with cr.open_results(results_path) as results:
        run = cr.read_run(results)
        timing = cr.read_timing(results)
        has_glstat = "glstat" in cr.list_history_groups(results)
        glstat = cr.read_history(results, "glstat") if has_glstat else {}

    summary = {key: None for key, _, _ in ROWS}
    summary["title"] = run.get("title") or None
    summary["status"] = run.get("status", "unknown")
    summary["message"] = run.get("message") or None
    summary["end_time"] = run.get("end_time")
    for key in ("threads", "cycles"):
        value = timing.get(key, run.get(key))
        summary[key] = int(value) if value is not None else None
    for key in ("wall_s",) + cr.TIMING_PHASES:
        summary[key] = float(timing[key]) if key in timing else None
    for key in ("fe_elements", "efg_particles", "dofs_total"):
        summary[key] = int(timing[key]) if key in timing else None
    if summary["wall_s"] is not None:
        phases = [summary[key] for key in cr.TIMING_PHASES if summary[key] is not None]
        summary["other_s"] = summary["wall_s"] - sum(phases)
    summary["ns_per_element_cycle"] = per_unit_ns(summary["fe_solid_s"], summary["fe_elements"],
                                                  summary["cycles"])
    summary["ns_per_particle_cycle"] = per_unit_ns(summary["efg_s"], summary["efg_particles"],
                                                   summary["cycles"])
    if len(glstat.get("time", [])) > 0:
        if "total_energy" in glstat and "external_work" in glstat:
            summary["energy_ratio"] = cr.energy_ratio(glstat)
        if "hourglass_energy" in glstat and "internal_energy" in glstat:
            summary["hourglass_ratio"] = cr.hourglass_ratio(glstat)
    return summary


def format_value(value, template: str) -> str:
    """A cell: the value formatted, "n/a" for None or NaN; '|' escaped for Markdown."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "n/a"
    return template.format(value).replace("|", "\\|").replace("\n", " ")


def markdown_table(headers, rows) -> str:
    """A Markdown table from a header row and rows of cells."""
    lines = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def summary_markdown(paths, combined: bool = False, labels=None) -> str:
    """Markdown for several runs: one table per run under a heading, or one table with a
    column per run (``combined``). Rows that are n/a for every run are left out."""
    labels = list(labels) if labels else cr.run_labels(paths)
    summaries = [run_summary(path) for path in paths]
    shown = [(key, heading, template) for key, heading, template in ROWS
             if any(summary[key] is not None for summary in summaries)]
    if combined:
        rows = [[heading] + [format_value(summary[key], template) for summary in summaries]
                for key, heading, template in shown]
        return markdown_table(["quantity"] + labels, rows) + "\n"
    parts = []
    for label, path, summary in zip(labels, paths, summaries):
        rows = [[heading, format_value(summary[key], template)] for key, heading, template in shown
                if summary[key] is not None]
        table = markdown_table(["quantity", "value"], rows)
        parts.append(f"## {label} ({path})\n\n{table}\n")
    return "\n".join(parts)


def build_parser() -> argparse.ArgumentParser:
    """The command line of the script."""
    parser = argparse.ArgumentParser(
        description="Print Markdown tables of crashfree runs: status, cycles, end time, wall "
                    "and phase times, ns per element per cycle, energy ratio, hourglass ratio.")
    parser.add_argument("results", nargs="+", help="results files (results.h5)")
    parser.add_argument("--combined", action="store_true",
                        help="one table with a column per run instead of a table per run")
    parser.add_argument("--label", action="append",
                        help="name of each run, in order (repeat; default: file or directory "
                             "names)")
    parser.add_argument("-o", "--output", help="also write the Markdown to this file")
    return parser


def main(argv=None) -> int:
    """Run the script on ``argv`` (default: the command line); return the exit status."""
    arguments = build_parser().parse_args(argv)
    if arguments.label and len(arguments.label) != len(arguments.results):
        print("summary_table: give one --label per results file", file=sys.stderr)
        return 2
    try:
        text = summary_markdown(arguments.results, arguments.combined, arguments.label)
    except (cr.ResultsError, KeyError, OSError) as error:
        print(f"summary_table: {error}", file=sys.stderr)
        return 1
    print(text, end="")
    if arguments.output:
        Path(arguments.output).write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
