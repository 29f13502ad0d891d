#!/usr/bin/env python3
"""Write the hexahedral mesh of a quarter cylinder (Taylor bar) as *NODE and *ELEMENT_SOLID cards.

Cross-section: a "butterfly" mesh of a quarter disc, a square core of core x core cells and two
outer blocks of core x ring cells mapped onto the arc, so no element is degenerate. The bar
runs along z from 0 to the length. Node sets for the symmetry planes are written too:
set 1 = nodes on x = 0, set 2 = nodes on y = 0.

    python3 make_mesh.py [--radius 3.2] [--length 32.4] [--core 6] [--ring 5] [--layers 80] > mesh.k
"""
import argparse
import math

import numpy as np


def quarter_disc(radius, core, ring):
    """Points (p,2) and quadrilaterals (q,4, counter-clockwise) of a quarter disc."""
    side = 0.55 * radius            # half-width of the core square, as a fraction of the radius
    points = {}

    def point(x, y):
        key = (round(x, 10), round(y, 10))
        if key not in points:
            points[key] = len(points)
        return points[key]

    quads = []
    # core square
    grid = [[point(side * i / core, side * j / core) for j in range(core + 1)] for i in range(core + 1)]
    for i in range(core):
        for j in range(core):
            quads.append([grid[i][j], grid[i + 1][j], grid[i + 1][j + 1], grid[i][j + 1]])
    # the two outer blocks: from the core edge x = side (angles 0..45 deg) and y = side (45..90 deg)
    for block in range(2):
        rows = []
        for s in range(core + 1):
            t = s / core
            if block == 0:
                inner = np.array([side, side * t])
                angle = 0.25 * math.pi * t
            else:
                inner = np.array([side * (1.0 - t), side])
                angle = 0.25 * math.pi * (1.0 + t)
            outer = radius * np.array([math.cos(angle), math.sin(angle)])
            rows.append([point(*(inner + (outer - inner) * r / ring)) for r in range(ring + 1)])
        for s in range(core):
            for r in range(ring):
                quad = [rows[s][r], rows[s][r + 1], rows[s + 1][r + 1], rows[s + 1][r]]
                quads.append(quad)
    coordinates = np.zeros((len(points), 2))
    for (x, y), index in points.items():
        coordinates[index] = (x, y)
    # make every quadrilateral counter-clockwise
    for quad in quads:
        a, b, c = coordinates[quad[0]], coordinates[quad[1]], coordinates[quad[2]]
        if (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) < 0.0:
            quad.reverse()
    return coordinates, np.array(quads)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--radius", type=float, default=3.2)
    parser.add_argument("--length", type=float, default=32.4)
    parser.add_argument("--core", type=int, default=6)
    parser.add_argument("--ring", type=int, default=5)
    parser.add_argument("--layers", type=int, default=80)
    parser.add_argument("--part", type=int, default=1)
    options = parser.parse_args()

    section, quads = quarter_disc(options.radius, options.core, options.ring)
    per_layer = len(section)
    lines = [f"$ Taylor bar quarter model: radius {options.radius} mm, length {options.length} mm,",
             f"$ {len(quads)} cells per layer x {options.layers} layers (written by make_mesh.py)", "*NODE"]
    for layer in range(options.layers + 1):
        z = options.length * layer / options.layers
        for k, (x, y) in enumerate(section):
            lines.append(f"{layer * per_layer + k + 1:8d}{x:16.9e}{y:16.9e}{z:16.9e}{0:8d}{0:8d}")
    lines.append("*ELEMENT_SOLID")
    element = 0
    for layer in range(options.layers):
        for quad in quads:
            element += 1
            bottom = [layer * per_layer + q + 1 for q in quad]
            top = [(layer + 1) * per_layer + q + 1 for q in quad]
            lines.append(f"{element:8d}{options.part:8d}" + "".join(f"{n:8d}" for n in bottom + top))
    for set_id, axis in ((1, 0), (2, 1)):
        members = [layer * per_layer + k + 1 for layer in range(options.layers + 1)
                   for k in range(per_layer) if abs(section[k, axis]) < 1e-9]
        lines.append("*SET_NODE_LIST")
        lines.append(f"{set_id:10d}")
        for start in range(0, len(members), 8):
            lines.append("".join(f"{n:10d}" for n in members[start:start + 8]))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
