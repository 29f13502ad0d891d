#!/usr/bin/env python3
"""Write the MPI scaling deck (tools/bench_mpi.sh, docs/parallel_scaling.md): a block of one-point
hexahedra (elastic-plastic, MAT_003) dropped onto a plate of Belytschko-Tsay shells (MAT_003,
NIP 3) held at its edges, one single-surface contact over all parts. Default sizes: 80 x 80 x 60
hexahedra of 1 mm (384,000) over 360 x 360 shells of 1 mm (129,600): 513,600 elements, the
segments of the contact all of one size (a plate of 0.5 mm shells under 2 mm hexahedra made the
contact search 20 times dearer per element than the elements: 2,900 ns per element per cycle,
machine loaded). The
block starts 0.1 mm above the plate's contact surface (its half thickness, 0.5 mm) at 20 m/s, so
the contact takes load within the first hundred cycles.

    python3 tools/make_scaling_deck.py OUT.k [--solids 80 80 60] [--shells 360] [--cycles 300]
"""
import argparse

import numpy as np


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("output")
    parser.add_argument("--solids", type=int, nargs=3, default=[80, 80, 60], help="hexahedra along x, y, z")
    parser.add_argument("--shells", type=int, default=360, help="shells along each side of the plate")
    parser.add_argument("--cycles", type=int, default=300, help="ENDCYC")
    options = parser.parse_args()
    nx, ny, nz = options.solids
    cell = 1.0                        # edge of the hexahedra and of the shells, mm
    side = options.shells * cell      # plate side, mm, around the block
    gap = 0.6                         # above the shells' half thickness (contact surface)
    m = options.shells
    rng = np.random.default_rng(17)

    # the block: centred over the plate, bottom face at z = gap
    x, y, z = np.meshgrid(np.arange(nx + 1) * cell, np.arange(ny + 1) * cell, np.arange(nz + 1) * cell, indexing="ij")
    block = np.stack([x + (side - nx * cell) / 2, y + (side - ny * cell) / 2, z + gap], axis=-1)
    block[1:-1, 1:-1, 1:-1] += rng.uniform(-0.1 * cell, 0.1 * cell, (nx - 1, ny - 1, nz - 1, 3))
    block = block.reshape(-1, 3)
    index = np.arange((nx + 1) * (ny + 1) * (nz + 1)).reshape(nx + 1, ny + 1, nz + 1) + 1
    corners = [index[:-1, :-1, :-1], index[1:, :-1, :-1], index[1:, 1:, :-1], index[:-1, 1:, :-1],
               index[:-1, :-1, 1:], index[1:, :-1, 1:], index[1:, 1:, 1:], index[:-1, 1:, 1:]]
    solids = np.stack([c.reshape(-1) for c in corners], axis=1)

    # the plate in z = 0, nodes numbered after the block's
    h = cell
    px, py = np.meshgrid(np.arange(m + 1) * h, np.arange(m + 1) * h, indexing="ij")
    plate = np.stack([px, py, np.zeros_like(px)], axis=-1).reshape(-1, 3)
    first = len(block) + 1
    pindex = np.arange((m + 1) * (m + 1)).reshape(m + 1, m + 1) + first
    shells = np.stack([pindex[:-1, :-1].reshape(-1), pindex[1:, :-1].reshape(-1), pindex[1:, 1:].reshape(-1),
                       pindex[:-1, 1:].reshape(-1)], axis=1)
    edge = np.zeros((m + 1, m + 1), bool)
    edge[0, :] = edge[-1, :] = edge[:, 0] = edge[:, -1] = True
    edge_nodes = pindex[edge]

    nodes = np.vstack([block, plate])
    with open(options.output, "w") as deck:
        deck.write("*KEYWORD\n*TITLE\nscaling deck: %d hexahedra on %d shells, single-surface contact\n"
                   % (len(solids), len(shells)))
        deck.write("*CONTROL_TERMINATION\n%10.3f%10d\n" % (10.0, options.cycles))
        deck.write("*DATABASE_BINARY_D3PLOT\n%10.3f\n*DATABASE_GLSTAT\n%10.3f\n" % (100.0, 100.0))
        deck.write("*PART\nblock\n%10d%10d%10d%10d%10d\n" % (1, 1, 1, 0, 1))
        deck.write("*SECTION_SOLID\n%10d%10d\n" % (1, 1))
        deck.write("*PART\nplate\n%10d%10d%10d%10d%10d\n" % (2, 2, 2, 0, 1))
        deck.write("*SECTION_SHELL\n%10d%10d%10s%10d\n" % (2, 2, "1.0", 3) + ("%10.3f" % 1.0) * 4 + "\n")
        for material, yield_stress in ((1, "0.2"), (2, "0.3")):
            deck.write("*MAT_PLASTIC_KINEMATIC\n%10d%10s%10s%10s%10s%10s%10s\n%10s%10s\n"
                       % (material, "7.85e-6", "210.0", "0.3", yield_stress, "1.0", "1.0", "0.0", "0.0"))
        deck.write("*HOURGLASS\n%10d%10d%10s\n" % (1, 1, "0.1"))
        deck.write("*CONTACT_AUTOMATIC_SINGLE_SURFACE_ID\n%10d%s\n%10d%10d%10d\n%10s%10s\n"
                   % (1, "block on plate", 0, 0, 5, "0.1", "0.1"))
        deck.write("*INITIAL_VELOCITY_GENERATION\n%10d%10d%10s%10s%10s%10s\n%10s%10s%10s\n"
                   % (1, 2, "0.0", "0.0", "0.0", "-20.0", "0.0", "0.0", "0.0"))
        deck.write("*SET_NODE_LIST\n%10d\n" % 1)
        for start in range(0, len(edge_nodes), 8):
            deck.write("".join("%10d" % n for n in edge_nodes[start:start + 8]) + "\n")
        deck.write("*BOUNDARY_SPC_SET\n%10d%10d%10d%10d%10d%10d%10d%10d\n" % (1, 0, 1, 1, 1, 1, 1, 1))
        deck.write("*NODE\n")
        np.savetxt(deck, np.column_stack([np.arange(1, len(nodes) + 1), nodes, np.zeros((len(nodes), 2))]),
                   fmt="%8d%16.9e%16.9e%16.9e%8d%8d")
        deck.write("*ELEMENT_SOLID\n")
        np.savetxt(deck, np.column_stack([np.arange(1, len(solids) + 1), np.ones(len(solids), int), solids]),
                   fmt="%8d" * 10)
        deck.write("*ELEMENT_SHELL\n")
        np.savetxt(deck, np.column_stack([np.arange(len(solids) + 1, len(solids) + len(shells) + 1),
                                          np.full(len(shells), 2), shells]), fmt="%8d" * 6)
        deck.write("*END\n")


if __name__ == "__main__":
    main()
