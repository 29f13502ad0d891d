#!/usr/bin/env python3
"""Write the decks of the linear patch tests (paper section 4.1, Table 1; formulation section 7,
property 5) and their manifest.

Two geometries, both irregular background meshes, all parts meshfree (EFG):

* ``slab``: the paper's domain (0,9) x (0,9), 9 x 9 cells in x-y, made 3D with 4 cells over a
  thickness t = 4 (with one cell every node would be a boundary node). Interior nodes move
  randomly by up to 25% of the cell in each direction, boundary nodes by up to 20% within their
  face (reproducible seed). The nodes at the four points of Table 1, (4,4), (6,2), (2,6) and
  (5,5), keep their x and y so that their exact [u1 u2] is Table 1's; the mid-plane one
  (z near t/2) is reported.
* ``cube``: the unit cube, 6 x 6 x 6 cells, every node moved randomly (25% of the cell inside,
  25% within the faces), a general affine field.

Fields: ``unit`` is the paper's u = X; ``affine`` is u = A X + c with a full (non-symmetric) A.
The field is prescribed on every node of the bounding box (*BOUNDARY_PRESCRIBED_MOTION_NODE,
VAD 2, constant curve), nothing else loads the body, and the analysis is linear static
(*CONTROL_IMPLICIT_GENERAL IMFLAG 1). The exact solution is the field itself at every node.

Methods (the columns of Table 1, plus a finite element reference):

=================  ==========================================================  ======  =====
key                meaning                                                     IEBT    IDIM
=================  ==========================================================  ======  =====
``conventional``   conventional EFG, 4x4x4 Gauss points, direct MLS gradients  1       4
``lbi``            local boundary integration without the boundary            1       1
                   correction (every node MLS, full transformation)
``full``           the full method (coupled shape functions, modified SCNI)    3       1
``fe``             fully integrated hexahedra (ELFORM 2), reference            --      --
=================  ==========================================================  ======  =====

Usage::

    python3 verification/patch_test.py --out results/verification/patch
    python3 verification/patch_test.py --out DIR --quick     # one support size, for tests
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import decks  # noqa: E402
from analytic import affine_field  # noqa: E402

#: The four points of Table 1 of the paper (exact [u1 u2] of u = X there).
TABLE1_POINTS = ((4.0, 4.0), (6.0, 2.0), (2.0, 6.0), (5.0, 5.0))

#: The general affine field of the 3D tests: u = A X + c (A neither symmetric nor diagonal).
AFFINE_GRADIENT = ((0.12, 0.04, -0.03),
                   (0.02, -0.05, 0.06),
                   (-0.07, 0.03, 0.08))
AFFINE_OFFSET = (0.011, -0.02, 0.03)

#: Method key -> (label, IEBT, IDIM); None marks the finite element reference.
METHODS = {
    "conventional": ("conventional EFG, 4x4x4 Gauss", 1, 4),
    "lbi": ("local boundary integration, no boundary correction", 1, 1),
    "full": ("full method (IEBT 3, IDIM 1)", 3, 1),
    "fe": ("finite elements (ELFORM 2)", None, None),
}

#: Kernel name -> ISPLINE.
KERNELS = {"box": 0, "sphere": 2}

#: (kernel, DX) of the full study; --quick keeps the first.
SUPPORTS = (("box", 1.5), ("box", 2.0), ("box", 2.5), ("sphere", 1.5))

#: Material of the patch tests (mm, ms, kg, kN, GPa). Any elastic constants pass the test.
DENSITY, YOUNG, POISSON = 7.85e-6, 1.0, 0.25


def slab_geometry(cells_xy=9, cells_z=4, thickness=4.0, seed=2008):
    """The Table 1 domain (0,9) x (0,9) x (0,t): nodes, hexahedra, and the node index of each
    Table 1 point at the mid-plane layer (``{"(4,4)": index, ...}``)."""
    counts = (cells_xy, cells_xy, cells_z)
    lengths = (9.0, 9.0, thickness)
    nodes, elements, ijk = decks.block_mesh(counts, lengths)
    cell = 9.0 / cells_xy
    index = decks.grid_index(counts)
    mid = cells_z // 2
    table_nodes, keep = {}, {}
    for x, y in TABLE1_POINTS:
        i, j = int(round(x / cell)), int(round(y / cell))
        for k in range(cells_z + 1):
            keep[index(i, j, k)] = (0, 1)
        table_nodes[f"({x:g},{y:g})"] = index(i, j, mid)
    nodes = decks.perturb_nodes(nodes, ijk, counts, lengths, 0.25, 0.2, seed, keep=keep)
    nodes = decks.round_to_card(nodes)
    jacobian = decks.check_mesh(nodes, elements, np.prod(np.array(lengths) / counts))
    return nodes, elements, table_nodes, jacobian


def cube_geometry(cells=6, seed=86):
    """The unit cube with every node moved randomly: nodes, hexahedra, smallest Jacobian."""
    counts = (cells, cells, cells)
    lengths = (1.0, 1.0, 1.0)
    nodes, elements, ijk = decks.block_mesh(counts, lengths)
    nodes = decks.perturb_nodes(nodes, ijk, counts, lengths, 0.25, 0.25, seed)
    nodes = decks.round_to_card(nodes)
    jacobian = decks.check_mesh(nodes, elements, np.prod(np.array(lengths) / counts))
    return nodes, elements, jacobian


def field_parameters(field: str):
    """(A, c) of a field name: ``unit`` is u = X, ``affine`` the general affine field."""
    if field == "unit":
        return np.eye(3), np.zeros(3)
    if field == "affine":
        return np.array(AFFINE_GRADIENT), np.array(AFFINE_OFFSET)
    raise ValueError(f"unknown field {field!r}")


def section_cards(method: str, kernel: str, support: float) -> str:
    """The section of part 1 for a method (section id 1)."""
    _, boundary_treatment, integration = METHODS[method]
    if boundary_treatment is None:
        return decks.fe_section(1, elform=2)
    return decks.efg_section(1, support, KERNELS[kernel], boundary_treatment, integration)


def write_case(root: Path, geometry: str, field: str, method: str, kernel: str, support: float,
               mesh) -> dict:
    """Write one deck and return its manifest entry."""
    nodes, elements = mesh["nodes"], mesh["elements"]
    gradient, offset = field_parameters(field)
    boundary = np.flatnonzero(decks.bounding_box_nodes(nodes))
    values = affine_field(nodes[boundary], gradient, offset)
    support_name = "" if method == "fe" else f"-{kernel}{support:g}"
    name = f"{geometry}-{field}-{method}{support_name}"
    deck = root / name / "deck.k"
    decks.write_deck(
        deck, f"patch test {name}",
        decks.static_controls(),
        decks.part_card(1, 1, 1, f"{geometry} ({METHODS[method][0]})"),
        section_cards(method, kernel, support),
        decks.elastic_material(1, DENSITY, YOUNG, POISSON),
        decks.constant_curves(),
        decks.nodes_card(nodes),
        decks.solids_card(elements, 1),
        decks.prescribed_displacements(boundary, values),
    )
    return {
        "study": "patch", "name": name, "deck": str(deck.relative_to(root)),
        "outdir": str(deck.parent.relative_to(root)), "geometry": geometry, "field": field,
        "gradient": gradient.tolist(), "offset": offset.tolist(), "method": method,
        "method_label": METHODS[method][0], "kernel": None if method == "fe" else kernel,
        "support": None if method == "fe" else support,
        "cells": [int(c) for c in mesh["counts"]], "nodes": int(len(nodes)),
        "prescribed_node_ids": (boundary + 1).tolist(),
        "table_node_ids": {key: int(index) + 1 for key, index in mesh.get("table_nodes", {}).items()},
        "smallest_jacobian": mesh["jacobian"],
    }


def case_list(quick: bool):
    """(geometry, field, method, kernel, support) of every case: the slab with u = X and the
    cube with the affine field at every support size, the slab with the affine field at box
    DX 1.5; the FE reference once per geometry. ``quick``: the slab with u = X at box DX 1.5."""
    supports = SUPPORTS[:1] if quick else SUPPORTS
    studies = [("slab", "unit", supports, True)]
    if not quick:
        studies += [("slab", "affine", SUPPORTS[:1], False), ("cube", "affine", supports, True)]
    cases = []
    for geometry, field, sizes, with_fe in studies:
        for kernel, support in sizes:
            for method in ("conventional", "lbi", "full"):
                cases.append((geometry, field, method, kernel, support))
        if with_fe:
            cases.append((geometry, field, "fe", None, None))
    return cases


def build_meshes(slab_cells_xy: int, slab_cells_z: int, cube_cells: int):
    """The two irregular meshes, keyed by geometry name."""
    nodes, elements, table_nodes, jacobian = slab_geometry(slab_cells_xy, slab_cells_z,
                                                           thickness=float(slab_cells_z) * 9.0 / slab_cells_xy)
    slab = {"nodes": nodes, "elements": elements, "table_nodes": table_nodes, "jacobian": jacobian,
            "counts": (slab_cells_xy, slab_cells_xy, slab_cells_z)}
    nodes, elements, jacobian = cube_geometry(cube_cells)
    cube = {"nodes": nodes, "elements": elements, "jacobian": jacobian,
            "counts": (cube_cells,) * 3}
    return {"slab": slab, "cube": cube}


def main(argv=None) -> int:
    """Write every patch-test deck and the manifest."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path, default=Path("results/verification/patch"),
                        help="directory for the decks and manifest.json")
    parser.add_argument("--quick", action="store_true",
                        help="only the slab with u = X and box DX 1.5 (regression tests)")
    parser.add_argument("--slab-cells", type=int, default=9,
                        help="cells along x and y of the slab (9: the paper's 1 x 1 cells)")
    parser.add_argument("--slab-layers", type=int, default=4, help="cells through the slab")
    parser.add_argument("--cube-cells", type=int, default=6, help="cells along each edge of the cube")
    parser.add_argument("--methods", nargs="+", choices=sorted(METHODS), default=sorted(METHODS),
                        help="methods to write (default: all)")
    args = parser.parse_args(argv)
    if args.slab_layers < 2:
        parser.error("--slab-layers must be at least 2 (with one cell every node is a boundary node)")
    if args.slab_cells % 9 != 0:
        parser.error("--slab-cells must be a multiple of 9 (the Table 1 points must be grid nodes)")
    meshes = build_meshes(args.slab_cells, args.slab_layers, args.cube_cells)
    args.out.mkdir(parents=True, exist_ok=True)
    entries = [write_case(args.out, geometry, field, method, kernel, support, meshes[geometry])
               for geometry, field, method, kernel, support in case_list(args.quick)
               if method in args.methods]
    manifest = {"study": "patch", "material": {"density": DENSITY, "young": YOUNG, "poisson": POISSON},
                "table1_points": TABLE1_POINTS, "cases": entries}
    (args.out / "manifest.json").write_text(json.dumps(manifest, indent=1))
    print(f"patch test: {len(entries)} decks in {args.out} (slab smallest corner Jacobian "
          f"{meshes['slab']['jacobian']:.2f}, cube {meshes['cube']['jacobian']:.2f} of the cell volume)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
