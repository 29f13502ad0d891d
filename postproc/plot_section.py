#!/usr/bin/env python3
"""Draw the deformed mesh in a plane of nodes: the element faces whose four nodes lie (in the
reference configuration) on the plane `axis = value`, at a given state, projected on the two
other axes. Several results files give side-by-side panels (e.g. an FE and an EFG run).

    python3 postproc/plot_section.py fe.h5 efg.h5 --axis y --value 5 [--state -1] -o section.png
"""
import argparse
import sys
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure

sys.path.insert(0, str(Path(__file__).resolve().parent))
import crashfree_results as cr  # noqa: E402

AXES = {"x": 0, "y": 1, "z": 2}
# the six faces of a hexahedron in LS-DYNA's node order (0-based)
FACES = [(0, 1, 2, 3), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]


def section_polygons(path, axis, value, state_index):
    """Deformed quadrilaterals (k, 4, 2) of the faces on the plane, the state time, and the
    plastic strain of each face's element."""
    with cr.open_results(path) as results:
        mesh = cr.read_mesh(results)
        coordinates = mesh["coordinates"]
        # node ids -> rows of the node arrays (the contract's connectivity holds ids)
        order = np.argsort(mesh["node_ids"])
        connectivity = order[np.searchsorted(mesh["node_ids"], mesh["connectivity"], sorter=order)]
        names = sorted(results["states"])
        state = results["states"][names[state_index]]
        current = coordinates + state["displacement"][...]
        plastic = state["solid_plastic_strain"][...]
        time = float(state.attrs["time"])
    tolerance = 1e-6 * (np.ptp(coordinates[:, axis]) + 1.0)
    on_plane = np.abs(coordinates[:, axis] - value) < tolerance
    others = [k for k in range(3) if k != axis]
    polygons, values, seen = [], [], set()
    for element, corners in enumerate(connectivity):
        for face in FACES:
            nodes = corners[list(face)]
            key = tuple(sorted(nodes))
            if on_plane[nodes].all() and key not in seen:
                seen.add(key)
                polygons.append(current[nodes][:, others])
                values.append(plastic[element])
    return np.array(polygons), np.array(values), time, others


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("results", nargs="+", type=Path)
    parser.add_argument("--axis", choices=AXES, default="y", help="normal of the plane")
    parser.add_argument("--value", type=float, required=True, help="coordinate of the plane (reference)")
    parser.add_argument("--state", type=int, default=-1, help="state index (default: the last)")
    parser.add_argument("--labels", nargs="*", help="one title per file")
    parser.add_argument("-o", "--output", type=Path, default=Path("section.png"))
    options = parser.parse_args()

    figure = Figure(figsize=(5 * len(options.results), 5))
    FigureCanvasAgg(figure)
    for k, path in enumerate(options.results):
        polygons, values, time, others = section_polygons(path, AXES[options.axis], options.value, options.state)
        if len(polygons) == 0:
            sys.exit(f"plot_section: no element face of {path} lies on {options.axis} = {options.value}")
        axes = figure.add_subplot(1, len(options.results), k + 1)
        collection = PolyCollection(polygons, array=values, cmap="viridis", edgecolors="black", linewidths=0.5)
        axes.add_collection(collection)
        axes.autoscale()
        axes.set_aspect("equal")
        axes.set_xlabel("xyz"[others[0]])
        axes.set_ylabel("xyz"[others[1]])
        label = options.labels[k] if options.labels and k < len(options.labels) else path.stem
        axes.set_title(f"{label}, t = {time:.4g}")
        figure.colorbar(collection, ax=axes, shrink=0.8, label="effective plastic strain")
    figure.tight_layout()
    figure.savefig(options.output, dpi=120)
    print(f"plot: {options.output}")


if __name__ == "__main__":
    main()
