#!/usr/bin/env python3
"""Write a benchmark deck: a block of one-point hexahedra (elastic-plastic) thrown at a rigid
wall, so that the elements deform plastically while the cycles are timed. With --efg-cells N the
first N layers of cells along x form a second part with the meshfree (EFG) section, sharing
nodes with the FE part (a coupled model). With --renumber SEED the same mesh is written as a
mesher that numbers at random would: node and element ids are random permutations of 1..n and
the *ELEMENT_SOLID lines come in a random order (so the solver's element indices are random);
with --shuffle-nodes the *NODE lines too (so are its node indices). The physics is the same.

    python3 tools/make_bench_deck.py OUT.k [--cells 50 50 40] [--cycles 200] [--efg-cells N]
                                           [--renumber SEED [--shuffle-nodes]]
"""
import argparse

import numpy as np


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("output")
    parser.add_argument("--cells", type=int, nargs=3, default=[50, 50, 40])
    parser.add_argument("--cycles", type=int, default=200)
    parser.add_argument("--size", type=float, default=1.0, help="cell edge in mm")
    parser.add_argument("--efg-cells", type=int, default=0, help="layers of cells along x that are EFG")
    parser.add_argument("--support", type=float, default=1.2, help="normalized EFG support DX = DY = DZ")
    parser.add_argument("--renumber", type=int, metavar="SEED",
                        help="random node and element ids and element line order (seed of the permutations)")
    parser.add_argument("--shuffle-nodes", action="store_true", help="with --renumber: *NODE lines in random order")
    options = parser.parse_args()
    nx, ny, nz = options.cells
    h = options.size
    rng = np.random.default_rng(11)
    x, y, z = np.meshgrid(np.arange(nx + 1) * h, np.arange(ny + 1) * h, np.arange(nz + 1) * h, indexing="ij")
    nodes = np.stack([x, y, z], axis=-1)
    nodes[1:-1, 1:-1, 1:-1] += rng.uniform(-0.1 * h, 0.1 * h, (nx - 1, ny - 1, nz - 1, 3))
    nodes = nodes.reshape(-1, 3)
    index = np.arange((nx + 1) * (ny + 1) * (nz + 1)).reshape(nx + 1, ny + 1, nz + 1) + 1
    corners = [index[:-1, :-1, :-1], index[1:, :-1, :-1], index[1:, 1:, :-1], index[:-1, 1:, :-1],
               index[:-1, :-1, 1:], index[1:, :-1, 1:], index[1:, 1:, 1:], index[:-1, 1:, 1:]]
    elements = np.stack([c.reshape(-1) for c in corners], axis=1)
    layer = np.broadcast_to(np.arange(nx)[:, None, None], (nx, ny, nz)).reshape(-1)
    parts = np.where(layer < options.efg_cells, 2, 1)
    node_ids = np.arange(1, len(nodes) + 1)
    element_ids = np.arange(1, len(elements) + 1)
    node_lines = np.arange(len(nodes))
    element_lines = np.arange(len(elements))
    if options.renumber is not None:
        shuffle = np.random.default_rng(options.renumber)
        node_ids = shuffle.permutation(len(nodes)) + 1
        element_ids = shuffle.permutation(len(elements)) + 1
        element_lines = shuffle.permutation(len(elements))
        if options.shuffle_nodes:
            node_lines = shuffle.permutation(len(nodes))
        elements = node_ids[elements - 1]

    with open(options.output, "w") as deck:
        deck.write("*KEYWORD\n*TITLE\nbenchmark block: %d one-point hexahedra\n" % len(elements))
        deck.write("*CONTROL_TERMINATION\n%10.3f%10d\n" % (1.0, options.cycles))
        deck.write("*DATABASE_BINARY_D3PLOT\n%10.3f\n*DATABASE_GLSTAT\n%10.3f\n" % (10.0, 10.0))
        deck.write("*PART\nblock\n%10d%10d%10d%10d%10d\n" % (1, 1, 1, 0, 1))
        deck.write("*SECTION_SOLID\n%10d%10d\n" % (1, 1))
        if options.efg_cells > 0:
            deck.write("*PART\nmeshfree layers\n%10d%10d%10d%10d%10d\n" % (2, 2, 1, 0, 1))
            support = "%10.3f" % options.support
            deck.write("*SECTION_SOLID_EFG\n%10d%10d\n%s%s%s%10d%10d%10d%10d%10s\n"
                       % (2, 41, support, support, support, 0, 0, 3, 1, "0.0"))
        deck.write("*MAT_PLASTIC_KINEMATIC\n%10d%10s%10s%10s%10s%10s%10s\n%10s%10s\n"
                   % (1, "7.85e-6", "210.0", "0.3", "0.2", "1.0", "1.0", "0.0", "0.0"))
        deck.write("*HOURGLASS\n%10d%10d%10s\n" % (1, 1, "0.1"))
        deck.write("*INITIAL_VELOCITY\n%10d\n%10s%10s%10s\n" % (0, "0.0", "0.0", "-200.0"))
        deck.write("*RIGIDWALL_PLANAR\n%10d\n%10s%10s%10s%10s%10s%10s\n" % (0, "0.0", "0.0", "0.0", "0.0", "0.0", "1.0"))
        deck.write("*NODE\n")
        np.savetxt(deck, np.column_stack([node_ids, nodes, np.zeros((len(nodes), 2))])[node_lines],
                   fmt="%8d%16.9e%16.9e%16.9e%8d%8d")
        deck.write("*ELEMENT_SOLID\n")
        np.savetxt(deck, np.column_stack([element_ids, parts, elements])[element_lines], fmt="%8d" * 10)
        deck.write("*END\n")


if __name__ == "__main__":
    main()
