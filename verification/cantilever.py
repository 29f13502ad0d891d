#!/usr/bin/env python3
"""Write the decks of the cantilever convergence study (paper section 4.2, Figs. 7-8;
formulation section 7, property 7) and their manifest.

Beam: E = 1 GPa, nu = 0.3, L = 50 mm, depth D = h = 10 mm (y from -5 to 5), width b = 1 mm
(z from -0.5 to 0.5); units mm, ms, kg, kN, GPa (E = 1.0 kN/mm^2). Load P = 1e-3 kN (1 N) as
the parabolic shear traction t_y(y) = P / (2 I) (D^2/4 - y^2) on the free end x = L, direction
+y (*LOAD_SEGMENT_NONUNIFORM, V = (0, 1, 0)); the Timoshenko-Goodier displacements (all three
components, see verification/analytic.py) prescribed on every node of the supported end x = 0.
Linear static analysis. Exact tip deflection v(L, 0) = 0.51375 mm.

Corner values of the traction (``--traction``):

* ``projected`` (default): on each end-face segment the linear traction that is the L2
  projection of the parabola over that segment (segments may carry different values at a
  shared node). The consistent nodal forces are then exactly those of the parabolic traction
  and the resultant is exactly P at every refinement.
* ``interpolated``: the corner values tau(y_k) of the parabola itself. The bilinear
  interpolant underestimates the resultant by a factor 1 - 1/n_y^2 (25% for 2 cells over
  the depth), a load error that adds to the discretization error of the solid.

Models, the same structured mesh of n_x x n_y x n_z cells (n_x = 5 n_y, square cells in x-y,
n_z = 2 cells through b, so that EFG parts have interior particles; ``--width-series`` adds the
same series with more cells through b):

* ``fe``: all fully integrated hexahedra (ELFORM 2);
* ``efg``: all EFG (normalized support DX 1.5, box cubic spline, IEBT 3, IDIM 1);
* ``coupled``: EFG for x < L/2 (the supported half, which bends most), ELFORM 2 for x > L/2,
  sharing the nodes of the plane x = L/2 (Fig. 7b).

Usage::

    python3 verification/cantilever.py --out results/verification/cantilever
    python3 verification/cantilever.py --out DIR --levels 2 4 --models fe
    python3 verification/cantilever.py --out DIR --width-series 4
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import decks  # noqa: E402
from analytic import (projected_corner_values, shear_traction, timoshenko_goodier,  # noqa: E402
                      tip_deflection)

#: Problem data (mm, ms, kg, kN, GPa).
LENGTH, DEPTH, WIDTH = 50.0, 10.0, 1.0
YOUNG, POISSON, DENSITY = 1.0, 0.3, 7.85e-6
LOAD = 1.0e-3

#: Normalized support of the EFG parts (the paper's 1.5), box cubic spline kernel.
EFG_SUPPORT = 1.5

#: Model key -> label.
MODELS = {"fe": "FE (ELFORM 2)", "efg": "EFG (DX 1.5)", "coupled": "coupled EFG/FE"}

#: Cells over the depth of each refinement (n_x = 5 n_y), and cells through the width b.
DEFAULT_LEVELS = (2, 4, 8, 16, 32)
DEFAULT_WIDTH_CELLS = 2

#: Part and section ids.
EFG_PART, FE_PART = 1, 2


def beam_mesh(cells_depth: int, cells_width: int):
    """Nodes (n, 3), hexahedra and grid indices of the beam: n_x = 5 n_y cells along the length,
    origin at the centre of the supported end."""
    counts = (5 * cells_depth, cells_depth, cells_width)
    nodes, elements, ijk = decks.block_mesh(counts, (LENGTH, DEPTH, WIDTH),
                                            origin=(0.0, -DEPTH / 2.0, -WIDTH / 2.0))
    return decks.round_to_card(nodes), elements, ijk, counts


def element_parts(model: str, nodes, elements):
    """Part id of every element: EFG everywhere, FE everywhere, or EFG for x < L/2."""
    if model == "fe":
        return np.full(len(elements), FE_PART)
    if model == "efg":
        return np.full(len(elements), EFG_PART)
    centres = nodes[elements].mean(axis=1)
    return np.where(centres[:, 0] < LENGTH / 2.0, EFG_PART, FE_PART)


def end_segments(counts, index):
    """End-face quadrilaterals (node indices) at x = L, counterclockwise seen from +x (outward
    normal +x)."""
    nx, ny, nz = counts
    segments = []
    for j in range(ny):
        for k in range(nz):
            segments.append([index(nx, j, k), index(nx, j + 1, k), index(nx, j + 1, k + 1),
                             index(nx, j, k + 1)])
    return np.array(segments)


def corner_values(nodes, segments, traction: str):
    """Traction value at each corner of each end segment (see the module docstring)."""
    values = np.empty(segments.shape)
    for s, corners in enumerate(segments):
        y = nodes[corners, 1]
        if traction == "interpolated":
            values[s] = shear_traction(y, LOAD, DEPTH, WIDTH)
            continue
        low, high = y.min(), y.max()
        value_low, value_high = projected_corner_values(low, high, LOAD, DEPTH, WIDTH)
        values[s] = np.where(np.isclose(y, low), value_low, value_high)
    return values


def interior_particles(model: str, counts) -> int:
    """Interior particles the EFG part must have: nodes of the EFG part not on its surface."""
    nx, ny, nz = counts
    if model == "fe":
        return 0
    cells_x = nx if model == "efg" else nx // 2
    return (cells_x - 1) * (ny - 1) * (nz - 1)


def write_case(root: Path, model: str, cells_depth: int, cells_width: int, traction: str) -> dict:
    """Write one deck and return its manifest entry."""
    nodes, elements, ijk, counts = beam_mesh(cells_depth, cells_width)
    index = decks.grid_index(counts)
    nx, ny, nz = counts
    parts = element_parts(model, nodes, elements)
    support = np.flatnonzero(ijk[:, 0] == 0)
    prescribed = timoshenko_goodier(nodes[support], LOAD, LENGTH, DEPTH, WIDTH, YOUNG, POISSON)
    segments = end_segments(counts, index)
    values = corner_values(nodes, segments, traction)
    suffix = "" if traction == "projected" else "-interpolated"
    if cells_width != DEFAULT_WIDTH_CELLS:
        suffix += f"-nz{cells_width}"
    name = f"{model}-ny{cells_depth:02d}{suffix}"
    deck = root / name / "deck.k"
    blocks = [decks.static_controls()]
    if np.any(parts == EFG_PART):
        blocks += [decks.part_card(EFG_PART, EFG_PART, 1, "meshfree (EFG)"),
                   decks.efg_section(EFG_PART, EFG_SUPPORT, kernel=0, boundary_treatment=3,
                                     integration=1)]
    if np.any(parts == FE_PART):
        blocks += [decks.part_card(FE_PART, FE_PART, 1, "fully integrated hexahedra"),
                   decks.fe_section(FE_PART, elform=2)]
    blocks += [
        decks.elastic_material(1, DENSITY, YOUNG, POISSON),
        decks.constant_curves(),
        decks.nodes_card(nodes),
        decks.solids_card(elements, parts),
        decks.prescribed_displacements(support, prescribed),
        decks.nonuniform_segment_loads(segments, values, (0.0, 1.0, 0.0)),
    ]
    decks.write_deck(deck, f"cantilever {name}: {MODELS[model]}, {nx} x {ny} x {nz} cells", *blocks)
    tip = [index(nx, ny // 2, k) for k in range(nz + 1)]
    end_face = np.flatnonzero(ijk[:, 0] == nx)
    resultant = sum(0.25 * np.sum(v) * (nodes[s[2], 1] - nodes[s[0], 1]) * (nodes[s[2], 2] - nodes[s[0], 2])
                    for s, v in zip(segments, values))
    return {
        "study": "cantilever", "name": name, "deck": str(deck.relative_to(root)),
        "outdir": str(deck.parent.relative_to(root)), "model": model, "model_label": MODELS[model],
        "traction": traction, "width_cells": int(nz), "cells": [int(c) for c in counts],
        "element_size": LENGTH / nx,
        "nodes": int(len(nodes)), "elements": int(len(elements)),
        "efg_elements": int(np.sum(parts == EFG_PART)),
        "expected_interior_particles": interior_particles(model, counts),
        "tip_node_ids": [int(n) + 1 for n in tip], "end_face_node_ids": (end_face + 1).tolist(),
        "support_node_ids": (support + 1).tolist(), "load_resultant": float(resultant),
    }


def main(argv=None) -> int:
    """Write every cantilever deck and the manifest."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path, default=Path("results/verification/cantilever"),
                        help="directory for the decks and manifest.json")
    parser.add_argument("--levels", type=int, nargs="+", default=list(DEFAULT_LEVELS),
                        help="cells over the depth of each refinement, even (n_x = 5 n_y)")
    parser.add_argument("--width-cells", type=int, default=DEFAULT_WIDTH_CELLS,
                        help="cells through the width b (at least 2)")
    parser.add_argument("--width-series", type=int, nargs="*", default=[], metavar="CELLS",
                        help="also write the whole series (every model and level, exact load) "
                        "with CELLS cells through the width, to measure the effect of the width "
                        "discretization")
    parser.add_argument("--models", nargs="+", choices=sorted(MODELS), default=list(MODELS))
    parser.add_argument("--traction", choices=("projected", "interpolated", "both"),
                        default="projected", help="corner values of the end traction")
    parser.add_argument("--interpolated-levels", type=int, nargs="*", default=None,
                        help="with --traction both: levels of the interpolated series "
                             "(default: all)")
    args = parser.parse_args(argv)
    if any(level < 2 or level % 2 for level in args.levels):
        parser.error("--levels must be even and at least 2 (a node row on the neutral axis)")
    if args.width_cells < 2:
        parser.error("--width-cells must be at least 2 (EFG parts need interior particles)")
    args.out.mkdir(parents=True, exist_ok=True)
    tractions = ("projected", "interpolated") if args.traction == "both" else (args.traction,)
    entries = []
    for traction in tractions:
        levels = args.levels
        if traction == "interpolated" and args.traction == "both" and args.interpolated_levels is not None:
            levels = args.interpolated_levels
        for model in args.models:
            for level in levels:
                entries.append(write_case(args.out, model, level, args.width_cells, traction))
    for cells in args.width_series:
        if cells < 2:
            parser.error("--width-series needs at least 2 cells")
        if cells == args.width_cells:
            continue
        for model in args.models:
            for level in args.levels:
                entries.append(write_case(args.out, model, level, cells, "projected"))
    exact = tip_deflection(LOAD, LENGTH, DEPTH, WIDTH, YOUNG, POISSON)
    manifest = {
        "study": "cantilever",
        "width_cells": args.width_cells,
        "width_series": sorted({args.width_cells, *args.width_series}),
        "problem": {"length": LENGTH, "depth": DEPTH, "width": WIDTH, "young": YOUNG,
                    "poisson": POISSON, "load": LOAD, "efg_support": EFG_SUPPORT,
                    "tip_deflection": exact},
        "cases": entries,
    }
    (args.out / "manifest.json").write_text(json.dumps(manifest, indent=1))
    print(f"cantilever: {len(entries)} decks in {args.out} (exact tip deflection {exact:.6g} mm)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
