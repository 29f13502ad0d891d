#!/usr/bin/env python3
"""Taylor bar figures of a crashfree run: final length of the bar, radius of its impact face
(the mushroom), and an outline plot of the deformed profile against the initial one.

    python3 postproc/taylor_bar.py results.h5 --markdown taylor_bar.md --plot profile.png

Definitions (last state unless --state is given):
- length: extent of the deformed nodes along the bar axis (--axis, default z);
- impact face: the nodes of the end face of the undeformed bar nearest the wall, i.e. the
  end whose radius grew most (or --wall low|high: the end at the low or high axial coordinate);
- radius: largest distance of those nodes from the bar axis. The axis passes through the
  middle of the undeformed cross-section, or through 0 in a lateral direction where the mesh
  starts or ends at 0 (a half or quarter model on symmetry planes); --center overrides it.
"""
from __future__ import annotations

import argparse
import sys

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

import crashfree_results as cr

AXES = ("x", "y", "z")

#: Relative tolerance (of the bar length or cross-section size) for "on the same plane".
PLANE_TOLERANCE = 1e-6


def lateral_center(reference: np.ndarray, axis: int) -> np.ndarray:
    """Position of the bar axis in the two lateral directions (see the module comment)."""
    center = []
    for direction in (d for d in range(3) if d != axis):
        low, high = reference[:, direction].min(), reference[:, direction].max()
        tolerance = PLANE_TOLERANCE * max(high - low, np.finfo(float).tiny)
        if abs(low) <= tolerance or abs(high) <= tolerance:
            center.append(0.0)      # a symmetry plane at 0: the axis lies on it
        else:
            center.append(0.5 * (low + high))
    return np.array(center)


def radial_distance(points: np.ndarray, axis: int, center: np.ndarray) -> np.ndarray:
    """Distance of each point from the bar axis."""
    lateral = [d for d in range(3) if d != axis]
    return np.linalg.norm(points[:, lateral] - center, axis=1)


def axial_profile(reference: np.ndarray, points: np.ndarray, axis: int, center: np.ndarray):
    """Outline of the bar: for each layer of nodes (same undeformed axial coordinate), the mean
    axial coordinate and the largest radius of ``points``. Returns (axial, radius) sorted
    along the axis of the undeformed bar."""
    axial_reference = reference[:, axis]
    length = max(np.ptp(axial_reference), np.finfo(float).tiny)
    layers = np.round((axial_reference - axial_reference.min()) / (PLANE_TOLERANCE * length))
    keys, layer_of_node = np.unique(layers, return_inverse=True)
    radius = radial_distance(points, axis, center)
    axial = np.zeros(len(keys))
    outline = np.zeros(len(keys))
    for layer in range(len(keys)):
        in_layer = layer_of_node == layer
        axial[layer] = points[in_layer, axis].mean()
        outline[layer] = radius[in_layer].max()
    return axial, outline


def taylor_bar_measures(results_path, axis: str = "z", wall: str = "auto", center=None,
                        state=-1) -> dict:
    """Lengths and radii of the bar at a state (see the module comment for the definitions).
    Returns a dict with time, state, axis, wall, center, initial/final length and radius,
    their ratios, and the arrays needed for :func:`plot_profile`."""
    axis_index = AXES.index(axis)
    with cr.open_results(results_path) as results:
        reference = results["mesh/nodes/coordinates"][()]
        chosen = cr.read_state(results, state)
    if reference.shape[0] == 0:
        raise cr.ResultsError(f"{results_path}: the mesh has no nodes")
    deformed = reference + chosen["displacement"]
    center = lateral_center(reference, axis_index) if center is None else np.asarray(center, float)

    axial_reference = reference[:, axis_index]
    initial_length = float(np.ptp(axial_reference))
    tolerance = PLANE_TOLERANCE * max(initial_length, np.finfo(float).tiny)
    faces = {"low": axial_reference <= axial_reference.min() + tolerance,
             "high": axial_reference >= axial_reference.max() - tolerance}
    face_radius = {end: float(radial_distance(deformed[nodes], axis_index, center).max())
                   for end, nodes in faces.items()}
    if wall == "auto":
        wall = "low" if face_radius["low"] >= face_radius["high"] else "high"
    impact_face = faces[wall]
    initial_radius = float(radial_distance(reference[impact_face], axis_index, center).max())
    final_length = float(np.ptp(deformed[:, axis_index]))
    impact_radius = face_radius[wall]
    return {
        "time": chosen["time"],
        "state": chosen["name"],
        "axis": axis,
        "wall": wall,
        "center": center,
        "initial_length": initial_length,
        "final_length": final_length,
        "length_ratio": final_length / initial_length if initial_length > 0 else float("nan"),
        "initial_radius": initial_radius,
        "impact_radius": impact_radius,
        "radius_ratio": impact_radius / initial_radius if initial_radius > 0 else float("nan"),
        "reference": reference,
        "deformed": deformed,
    }


def plot_profile(measures: dict, output_path, title: str | None = None) -> None:
    """Outline of the deformed bar (solid) over the undeformed one (dashed), mirrored about
    the axis, radius across and axial coordinate up, to scale."""
    axis = AXES.index(measures["axis"])
    center = measures["center"]
    figure = Figure(figsize=(5.5, 7.0), constrained_layout=True)
    FigureCanvasAgg(figure)
    axes = figure.subplots()
    for points, style, label in ((measures["reference"], {"color": "gray", "linestyle": "--"},
                                  "initial"),
                                 (measures["deformed"], {"color": "tab:blue"},
                                  f"t = {measures['time']:.4g}")):
        axial, radius = axial_profile(measures["reference"], points, axis, center)
        # down the left side, up the right side, and back across the top: a closed outline
        axes.plot(np.concatenate([-radius[::-1], radius, [-radius[-1]]]),
                  np.concatenate([axial[::-1], axial, [axial[-1]]]), label=label, **style)
    axes.set_aspect("equal")
    axes.set_xlabel("radial distance from the axis")
    axes.set_ylabel(f"{measures['axis']}")
    axes.grid(True, alpha=0.3)
    axes.legend(loc="upper right")
    axes.set_title(title or f"state {measures['state']} (t = {measures['time']:.4g}): "
                            f"L/L0 = {measures['length_ratio']:.3f}, "
                            f"R/R0 = {measures['radius_ratio']:.3f}")
    figure.savefig(output_path, dpi=120)


def measures_rows(measures: dict, reference_length=None, reference_radius=None) -> list:
    """(quantity, value) rows for printing and Markdown."""
    end = "lowest" if measures["wall"] == "low" else "highest"
    rows = [
        ("state (time)", f"{measures['state']} ({measures['time']:.6g})"),
        ("bar axis", f"{measures['axis']} through ({measures['center'][0]:.6g}, "
                     f"{measures['center'][1]:.6g})"),
        ("impact face", f"{end} {measures['axis']} end"),
        ("initial length L0", f"{measures['initial_length']:.6g}"),
        ("final length L", f"{measures['final_length']:.6g}"),
        ("L / L0", f"{measures['length_ratio']:.4f}"),
        ("initial radius R0", f"{measures['initial_radius']:.6g}"),
        ("impact-face radius R", f"{measures['impact_radius']:.6g}"),
        ("R / R0", f"{measures['radius_ratio']:.4f}"),
    ]
    if reference_length:
        difference = measures["final_length"] / reference_length - 1.0
        rows.append(("final length vs reference", f"{reference_length:.6g} ({difference:+.2%})"))
    if reference_radius:
        difference = measures["impact_radius"] / reference_radius - 1.0
        rows.append(("impact radius vs reference", f"{reference_radius:.6g} ({difference:+.2%})"))
    return rows


def markdown(rows, heading: str) -> str:
    """The rows as a Markdown table under a heading."""
    lines = [f"## {heading}", "", "| quantity | value |", "|---|---|"]
    lines += [f"| {quantity} | {value} |" for quantity, value in rows]
    return "\n".join(lines) + "\n"


def build_parser() -> argparse.ArgumentParser:
    """The command line of the script."""
    parser = argparse.ArgumentParser(
        description="Final length and impact-face radius of a Taylor bar in a crashfree "
                    "results file, and a PNG outline of the deformed profile.")
    parser.add_argument("results", help="results file (results.h5)")
    parser.add_argument("--axis", choices=AXES, default="z", help="bar axis (default: z)")
    parser.add_argument("--wall", choices=("auto", "low", "high"), default="auto",
                        help="end of the bar at the wall: at the low or high axial coordinate "
                             "(default: auto, the end whose radius grew most)")
    parser.add_argument("--center", nargs=2, type=float, metavar=("A", "B"),
                        help="lateral coordinates of the bar axis, in x y z order without the "
                             "axis (default: the middle of the initial cross-section, or 0 "
                             "where the mesh starts or ends at 0, i.e. on a symmetry plane)")
    parser.add_argument("--state", type=int, default=-1,
                        help="state index, negative from the end (default: -1, the last)")
    parser.add_argument("--reference-length", type=float,
                        help="a measured or reference final length to compare with")
    parser.add_argument("--reference-radius", type=float,
                        help="a measured or reference impact-face radius to compare with")
    parser.add_argument("--markdown", help="also write the table to this Markdown file")
    parser.add_argument("-o", "--plot", default="taylor_bar_profile.png",
                        help="PNG of the profile (default: taylor_bar_profile.png)")
    return parser


def main(argv=None) -> int:
    """Run the script on ``argv`` (default: the command line); return the exit status."""
    arguments = build_parser().parse_args(argv)
    try:
        measures = taylor_bar_measures(arguments.results, arguments.axis, arguments.wall,
                                       arguments.center, arguments.state)
        plot_profile(measures, arguments.plot)
    except (cr.ResultsError, KeyError, OSError) as error:
        print(f"taylor_bar: {error}", file=sys.stderr)
        return 1
    rows = measures_rows(measures, arguments.reference_length, arguments.reference_radius)
    width = max(len(quantity) for quantity, _ in rows)
    for quantity, value in rows:
        print(f"{quantity:<{width}}  {value}")
    if arguments.markdown:
        with open(arguments.markdown, "w") as stream:
            stream.write(markdown(rows, f"Taylor bar: {arguments.results}"))
    print(f"plot: {arguments.plot}" + (f", table: {arguments.markdown}" if arguments.markdown
                                       else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
