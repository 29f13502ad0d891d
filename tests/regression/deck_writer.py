"""Write small LS-DYNA style keyword decks for the regression tests.

Meshes are structured blocks of hexahedra, optionally with randomly perturbed interior nodes
(irregular meshes for patch tests). Cards are written in LS-DYNA's fixed format, so the tests
also exercise the reader's column handling.
"""
from __future__ import annotations

import numpy as np


def block_mesh(counts, lengths, origin=(0.0, 0.0, 0.0), perturbation=0.0, seed=1):
    """Nodes (n,3) and hexahedra (m,8, 0-based) of a box split into counts = (nx, ny, nz) cells.

    `perturbation` moves every node that is not on the box's boundary by up to that fraction
    of the local cell size in each direction (a reproducible irregular mesh)."""
    nx, ny, nz = counts
    axes = [np.linspace(o, o + length, n + 1) for o, length, n in zip(origin, lengths, counts)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)  # (nx+1, ny+1, nz+1, 3)
    if perturbation > 0.0:
        rng = np.random.default_rng(seed)
        cell = np.array(lengths) / np.array(counts)
        shift = rng.uniform(-perturbation, perturbation, grid.shape) * cell
        interior = np.zeros(grid.shape[:3], bool)
        interior[1:-1, 1:-1, 1:-1] = True
        grid[interior] += shift[interior]
    nodes = grid.reshape(-1, 3)

    def index(i, j, k):
        return (i * (ny + 1) + j) * (nz + 1) + k

    elements = []
    for i in range(nx):
        for j in range(ny):
            for k in range(nz):
                elements.append([index(i, j, k), index(i + 1, j, k), index(i + 1, j + 1, k), index(i, j + 1, k),
                                 index(i, j, k + 1), index(i + 1, j, k + 1), index(i + 1, j + 1, k + 1),
                                 index(i, j + 1, k + 1)])
    return nodes, np.array(elements, dtype=int)


def boundary_node_mask(nodes, tolerance=1e-9):
    """Nodes on the bounding box of the mesh."""
    low, high = nodes.min(axis=0), nodes.max(axis=0)
    return np.any((np.abs(nodes - low) < tolerance) | (np.abs(nodes - high) < tolerance), axis=1)


def nodes_card(nodes, first_id=1):
    lines = ["*NODE"]
    for k, (x, y, z) in enumerate(nodes):
        lines.append(f"{k + first_id:8d}{x:16.9e}{y:16.9e}{z:16.9e}{0:8d}{0:8d}")
    return "\n".join(lines)


def plate_mesh(counts, lengths, perturbation=0.0, seed=1):
    """Nodes (n,3) in the z = 0 plane and quadrilaterals (m,4, 0-based, counter-clockwise seen
    from +z) of a rectangle split into counts = (nx, ny) cells; `perturbation` moves interior
    nodes by up to that fraction of the cell size (an irregular mesh)."""
    nx, ny = counts
    x, y = np.meshgrid(np.linspace(0.0, lengths[0], nx + 1), np.linspace(0.0, lengths[1], ny + 1), indexing="ij")
    nodes = np.stack([x, y, np.zeros_like(x)], axis=-1)
    if perturbation > 0.0:
        rng = np.random.default_rng(seed)
        cell = np.array([lengths[0] / nx, lengths[1] / ny])
        shift = rng.uniform(-perturbation, perturbation, (nx + 1, ny + 1, 2)) * cell
        nodes[1:-1, 1:-1, :2] += shift[1:-1, 1:-1]
    nodes = nodes.reshape(-1, 3)
    index = lambda i, j: i * (ny + 1) + j
    shells = [[index(i, j), index(i + 1, j), index(i + 1, j + 1), index(i, j + 1)]
              for i in range(nx) for j in range(ny)]
    return nodes, np.array(shells, dtype=int)


def shells_card(shells, part_id=1, first_id=1, first_node_id=1):
    lines = ["*ELEMENT_SHELL"]
    for k, corners in enumerate(shells):
        ids = "".join(f"{c + first_node_id:8d}" for c in corners)
        lines.append(f"{k + first_id:8d}{part_id:8d}{ids}")
    return "\n".join(lines)


def solids_card(elements, part_id=1, first_id=1, first_node_id=1):
    lines = ["*ELEMENT_SOLID"]
    for k, corners in enumerate(elements):
        ids = "".join(f"{c + first_node_id:8d}" for c in corners)
        lines.append(f"{k + first_id:8d}{part_id:8d}{ids}")
    return "\n".join(lines)


def fields(*values, width=10):
    """One fixed-format card from values (None = blank field). Reals are written exactly when
    their shortest form fits the field, else rounded to the digits the field holds."""
    text = ""
    for value in values:
        if value is None:
            text += " " * width
        elif isinstance(value, float):
            shortest = repr(value)
            if len(shortest) > width:
                shortest = f"{value:.{width - 7}e}"
            text += f"{shortest:>{width}}"
        else:
            text += f"{value:>{width}}"
    return text


def round_to_node_card(nodes):
    """Coordinates exactly as the reader will see them in a *NODE card (16-column fields)."""
    return np.array([[float(f"{x:16.9e}") for x in row] for row in nodes])


def node_list_set(set_id, node_ids):
    lines = ["*SET_NODE_LIST", fields(set_id)]
    for start in range(0, len(node_ids), 8):
        lines.append("".join(f"{n:10d}" for n in node_ids[start:start + 8]))
    return "\n".join(lines)


def write_deck(path, *blocks):
    """Join keyword blocks into a deck that starts with *KEYWORD and ends with *END."""
    text = "*KEYWORD\n" + "\n".join(blocks) + "\n*END\n"
    path.write_text(text)
    return path


def efg_section(section_id, support=1.01, kernel=0, boundary_treatment=3, integration=1):
    """*SECTION_SOLID_EFG (ELFORM 41) with its EFG card: DX = DY = DZ = support, ISPLINE = kernel
    (0 cubic spline box support, 2 spherical), IDILA 0, IEBT, IDIM, TOLDEF 0."""
    return ("*SECTION_SOLID_EFG\n" + fields(section_id, 41) + "\n" +
            fields(float(support), float(support), float(support), kernel, 0, boundary_treatment, integration, 0.0))
