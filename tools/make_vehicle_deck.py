#!/usr/bin/env python3
"""Write the contact benchmark deck: a vehicle-like shell structure with mixed element sizes,
single-surface contact over all parts, driven into a rigid wall.

The structure (x to the rear, the wall at x = 0 facing +x; every node starts at -15 mm/ms):
a bumper beam (10 mm elements), two front rails (5 mm around the section, graded 5 -> 15 mm
along), two upper rails (8 mm), an engine block (a 500 x 400 mm tube, 25 mm), a corrugated dash panel
(10 mm), a hood (100 mm), a floor (graded 20 -> 100 mm along x), two sills (10 mm), three
crossmembers (20 mm), two side panels and a roof (100 mm). The parts are separate (no shared
nodes), a few millimetres apart: large flat panels next to small folded sections, the mix that
makes a search sized by the largest segment quadratic. With the default --scale 1 it has about
57,000 shells with edges from 5 to 100 mm; --scale s multiplies every element size by s (the
number of shells goes as 1 / s^2), so --scale 2 and --scale 0.5 give about 14,000 and 230,000.

    python3 tools/make_vehicle_deck.py OUT.k [--scale 1.0] [--cycles 600]
"""
import argparse

import numpy as np

SPEED = 15.0            # mm/ms
THICKNESS = 1.5         # mm, every part


def graded(length, first, last):
    """Positions 0..length with element sizes going linearly from `first` to `last`."""
    mean = 0.5 * (first + last)
    count = max(1, int(round(length / mean)))
    sizes = np.linspace(first, last, count)
    positions = np.concatenate([[0.0], np.cumsum(sizes)])
    return positions * (length / positions[-1])


def uniform(length, size):
    return np.linspace(0.0, length, max(1, int(round(length / size))) + 1)


class Mesh:
    def __init__(self):
        self.nodes = []
        self.shells = []
        self.count = 0
        self.parts = []

    def add(self, name, points, quads):
        """A part from its node coordinates (n, 3) and quadrilaterals (m, 4, 0-based)."""
        part = len(self.parts) + 1
        self.parts.append(name)
        self.nodes.append(points)
        self.shells.append(np.column_stack([np.full(len(quads), part), quads + self.count + 1]))
        self.count += len(points)

    def surface(self, name, origin, u_axis, v_axis, u, v, bump=None):
        """A flat patch origin + u u_axis + v v_axis over the grid u x v; `bump(u, v)` displaces
        it along u_axis x v_axis (corrugations)."""
        origin, u_axis, v_axis = (np.asarray(a, float) for a in (origin, u_axis, v_axis))
        uu, vv = np.meshgrid(u, v, indexing="ij")
        points = origin + uu[..., None] * u_axis + vv[..., None] * v_axis
        if bump is not None:
            points = points + bump(uu, vv)[..., None] * np.cross(u_axis, v_axis)
        index = np.arange(len(u) * len(v)).reshape(len(u), len(v))
        quads = np.stack([index[:-1, :-1], index[1:, :-1], index[1:, 1:], index[:-1, 1:]], axis=-1).reshape(-1, 4)
        self.add(name, points.reshape(-1, 3), quads)

    def tube(self, name, axis, start, along, centre, width, height, around):
        """A closed rectangular tube along coordinate `axis` (0, 1, 2), from `start` with the
        stations `along`; its section is width x height about `centre` (the two other
        coordinates, in increasing axis order), `around` the element size round the section."""
        others = [k for k in range(3) if k != axis]
        perimeter = []
        corners = [(-width / 2, -height / 2), (width / 2, -height / 2), (width / 2, height / 2), (-width / 2, height / 2)]
        for k in range(4):
            a, b = np.array(corners[k]), np.array(corners[(k + 1) % 4])
            count = max(1, int(round(np.linalg.norm(b - a) / around)))
            for t in np.arange(count) / count:
                perimeter.append(a + t * (b - a))
        perimeter = np.array(perimeter) + np.asarray(centre, float)
        ring = len(perimeter)
        points = np.zeros((len(along), ring, 3))
        points[..., axis] = start + np.asarray(along)[:, None]
        points[..., others[0]] = perimeter[None, :, 0]
        points[..., others[1]] = perimeter[None, :, 1]
        index = np.arange(len(along) * ring).reshape(len(along), ring)
        following = np.roll(index, -1, axis=1)
        quads = np.stack([index[:-1], index[1:], following[1:], following[:-1]], axis=-1).reshape(-1, 4)
        self.add(name, points.reshape(-1, 3), quads)


def vehicle(scale):
    s = scale
    mesh = Mesh()
    # bumper beam: a 100 x 120 box section across the front, 2 mm from the wall
    mesh.tube("bumper", 1, -700.0, uniform(1400.0, 10 * s), (52.0, 300.0), 100.0, 120.0, 10 * s)
    for y in (-400.0, 400.0):
        mesh.tube("front rail", 0, 112.0, graded(650.0, 5 * s, 15 * s), (y, 300.0), 60.0, 80.0, 5 * s)
        mesh.tube("upper rail", 0, 150.0, uniform(600.0, 8 * s), (1.6 * y, 700.0), 40.0, 40.0, 8 * s)
    mesh.tube("engine", 0, 200.0, uniform(500.0, 25 * s), (0.0, 580.0), 500.0, 400.0, 25 * s)
    mesh.surface("dash", (790.0, -700.0, 200.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), uniform(1400.0, 10 * s),
                 uniform(800.0, 10 * s), bump=lambda u, v: 5.0 * np.sin(2 * np.pi * u / 100.0))
    mesh.surface("hood", (50.0, -700.0, 1000.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), uniform(720.0, 100 * s),
                 uniform(1400.0, 100 * s))
    mesh.surface("floor", (810.0, -700.0, 150.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), graded(2190.0, 20 * s, 100 * s),
                 uniform(1400.0, 100 * s))
    for y in (-760.0, 760.0):
        mesh.tube("sill", 0, 810.0, uniform(2190.0, 10 * s), (y, 220.0), 80.0, 120.0, 10 * s)
        mesh.surface("side panel", (810.0, 1.08 * y, 150.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0), uniform(2190.0, 100 * s),
                     uniform(1150.0, 100 * s))
    for x in (1000.0, 1700.0, 2400.0):
        mesh.tube("crossmember", 1, -690.0, uniform(1380.0, 20 * s), (x, 210.0), 100.0, 100.0, 20 * s)
    mesh.surface("roof", (810.0, -810.0, 1310.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), uniform(2190.0, 100 * s),
                 uniform(1620.0, 100 * s))
    return mesh


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("output")
    parser.add_argument("--scale", type=float, default=1.0, help="multiplies every element size")
    parser.add_argument("--cycles", type=int, default=600, help="ENDCYC")
    options = parser.parse_args()
    mesh = vehicle(options.scale)
    nodes = np.vstack(mesh.nodes)
    shells = np.vstack(mesh.shells)
    edges = np.linalg.norm(nodes[shells[:, [1, 2, 3, 4]] - 1] - nodes[shells[:, [2, 3, 4, 1]] - 1], axis=2)
    with open(options.output, "w") as deck:
        deck.write("*KEYWORD\n*TITLE\ncontact benchmark: vehicle-like structure, %d shells, edges %.1f to %.1f mm\n"
                   % (len(shells), edges.min(), edges.max()))
        deck.write("*CONTROL_TERMINATION\n%10.3f%10d\n" % (100.0, options.cycles))
        deck.write("*DATABASE_GLSTAT\n%10.3f\n*DATABASE_BINARY_D3PLOT\n%10.3f\n" % (1.0, 100.0))
        deck.write("*SECTION_SHELL\n%10d%10d%10s%10d\n" % (1, 2, "1.0", 3) + ("%10.3f" % THICKNESS) * 4 + "\n")
        deck.write("*MAT_PLASTIC_KINEMATIC\n%10d%10s%10s%10s%10s%10s%10s\n%10s%10s\n"
                   % (1, "7.85e-6", "210.0", "0.3", "0.3", "1.0", "1.0", "0.0", "0.0"))
        for part, name in enumerate(mesh.parts, start=1):
            deck.write("*PART\n%s\n%10d%10d%10d\n" % (name, part, 1, 1))
        deck.write("*CONTACT_AUTOMATIC_SINGLE_SURFACE_ID\n%10d%s\n%10d%10d%10d\n%10s%10s\n"
                   % (1, "vehicle", 0, 0, 5, "0.1", "0.1"))
        deck.write("*RIGIDWALL_PLANAR\n%10d\n%10s%10s%10s%10s%10s%10s\n" % (0, "0.0", "0.0", "0.0", "1.0", "0.0", "0.0"))
        deck.write("*INITIAL_VELOCITY\n%10d\n%10s%10s%10s\n" % (0, "%.1f" % -SPEED, "0.0", "0.0"))
        deck.write("*NODE\n")
        np.savetxt(deck, np.column_stack([np.arange(1, len(nodes) + 1), nodes, np.zeros((len(nodes), 2))]),
                   fmt="%8d%16.9e%16.9e%16.9e%8d%8d")
        deck.write("*ELEMENT_SHELL\n")
        np.savetxt(deck, np.column_stack([np.arange(1, len(shells) + 1), shells]), fmt="%8d" * 6)
        deck.write("*END\n")
    print(f"{options.output}: {len(shells)} shells, {len(nodes)} nodes, edges {edges.min():.1f} to "
          f"{edges.max():.1f} mm (median {np.median(edges.max(axis=1)):.1f})")


if __name__ == "__main__":
    main()
