"""Keyword cards and meshes for the verification decks (numpy only).

Every real number that enters the solution (coordinates, prescribed displacements, tractions)
is written in LS-DYNA's long format (``*KEYWORD+``: 20-column fields) with 14 significant
digits, and the coordinates are rounded to exactly what the card holds before any prescribed
value is computed from them: the patch tests then compare against the field the solver really
sees, to round-off.

Meshes are structured blocks of hexahedra (LS-DYNA node order: N1-N4 counterclockwise seen from
the N5-N8 face) with reproducibly seeded random node moves; every corner Jacobian is checked.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

#: Digits after the point in the long-format reals (14 significant digits).
LONG_DIGITS = 13

#: Curve ids used by every deck: a constant 1 and a constant 0 (a prescribed motion of value 0
#: cannot be written as SF = 0, which LS-DYNA reads as 1).
CURVE_ONE = 1
CURVE_ZERO = 2


# ------------------------------------------------------------------------------------------------
# Fields and cards


def fields(*values, width=10):
    """One fixed-format card from values (None = blank field). Reals are written exactly when
    their shortest form fits the field, else rounded to the digits the field holds."""
    text = ""
    for value in values:
        if value is None:
            text += " " * width
        elif isinstance(value, (float, np.floating)):
            shortest = repr(float(value))
            if len(shortest) > width:
                shortest = f"{float(value):.{width - 7}e}"
            text += f"{shortest:>{width}}"
        else:
            text += f"{value:>{width}}"
    return text


def long_real(value: float) -> str:
    """A real in a 20-column long-format field, 14 significant digits."""
    return f"{float(value):20.{LONG_DIGITS}e}"


def long_fields(*values) -> str:
    """One long-format card (20 columns per field): ints as they are, reals with 14 digits."""
    text = ""
    for value in values:
        if value is None:
            text += " " * 20
        elif isinstance(value, (float, np.floating)):
            text += long_real(value)
        else:
            text += f"{value:>20}"
    return text


def round_to_card(values: np.ndarray) -> np.ndarray:
    """Values exactly as the reader sees them in a long-format field (14 significant digits)."""
    values = np.asarray(values, dtype=float)
    return np.vectorize(lambda v: float(f"{v:.{LONG_DIGITS}e}"))(values) if values.size else values


def nodes_card(nodes: np.ndarray, first_id: int = 1) -> str:
    """*NODE+ (long format): NID X Y Z, one node per line."""
    lines = ["*NODE+"]
    for k, (x, y, z) in enumerate(nodes):
        lines.append(f"{k + first_id:20d}{long_real(x)}{long_real(y)}{long_real(z)}{0:20d}{0:20d}")
    return "\n".join(lines)


def solids_card(elements: np.ndarray, part_ids, first_id: int = 1, first_node_id: int = 1) -> str:
    """*ELEMENT_SOLID, one-line form: EID PID N1-N8 (8 columns each). ``part_ids`` is one id for
    all elements or one per element."""
    part_ids = np.broadcast_to(np.asarray(part_ids, dtype=int), (len(elements),))
    lines = ["*ELEMENT_SOLID"]
    for k, (corners, part) in enumerate(zip(elements, part_ids)):
        ids = "".join(f"{c + first_node_id:8d}" for c in corners)
        lines.append(f"{k + first_id:8d}{part:8d}{ids}")
    return "\n".join(lines)


def part_card(part_id: int, section_id: int, material_id: int, heading: str) -> str:
    """*PART with a heading line."""
    return "*PART\n" + heading + "\n" + fields(part_id, section_id, material_id)


def fe_section(section_id: int, elform: int = 2) -> str:
    """*SECTION_SOLID: ELFORM 2 = fully integrated (selective-reduced) hexahedron."""
    return "*SECTION_SOLID\n" + fields(section_id, elform)


def efg_section(section_id: int, support: float, kernel: int = 0, boundary_treatment: int = 3,
                integration: int = 1) -> str:
    """*SECTION_SOLID_EFG: card 1 SECID ELFORM 41; EFG card DX = DY = DZ = support,
    ISPLINE = kernel (0 box cubic spline, 2 sphere), IDILA 0, IEBT (3 coupled, 1 full
    transformation), IDIM (1 local boundary integration, 2 Gauss 2x2x2, 4 conventional 4x4x4
    Gauss), TOLDEF 0."""
    return ("*SECTION_SOLID_EFG\n" + fields(section_id, 41) + "\n" +
            fields(float(support), float(support), float(support), kernel, 0, boundary_treatment,
                   integration, 0.0))


def elastic_material(material_id: int, density: float, young: float, poisson: float) -> str:
    """*MAT_ELASTIC: MID RO E PR."""
    return "*MAT_ELASTIC\n" + fields(material_id, float(density), float(young), float(poisson))


def constant_curves(end_time: float = 1.0) -> str:
    """The two constant curves every deck uses: CURVE_ONE (1) and CURVE_ZERO (0), defined well
    past the end time so that the static solve may evaluate them at any time of the run."""
    far = 1000.0 * end_time
    blocks = []
    for curve, value in ((CURVE_ONE, 1.0), (CURVE_ZERO, 0.0)):
        blocks.append("*DEFINE_CURVE\n" + fields(curve) + "\n" +
                      f"{0.0:20.6e}{value:20.6e}\n{far:20.6e}{value:20.6e}")
    return "\n".join(blocks)


def static_controls(end_time: float = 1.0) -> str:
    """Linear static analysis: *CONTROL_IMPLICIT_GENERAL IMFLAG 1 (DT0 = the end time) and the
    *CONTROL_TERMINATION every deck needs."""
    return ("*CONTROL_IMPLICIT_GENERAL\n" + fields(1, float(end_time)) + "\n" +
            "*CONTROL_TERMINATION\n" + fields(float(end_time)))


def prescribed_displacements(node_indices, values: np.ndarray, first_node_id: int = 1) -> str:
    """*BOUNDARY_PRESCRIBED_MOTION_NODE+ (long format), VAD 2 (displacement): one card per node
    and direction, value = SF x constant curve 1 (curve 0 for an exact zero)."""
    lines = ["*BOUNDARY_PRESCRIBED_MOTION_NODE+"]
    for node, value in zip(node_indices, np.asarray(values, dtype=float)):
        for direction in range(3):
            component = float(value[direction])
            curve, scale = (CURVE_ONE, component) if component != 0.0 else (CURVE_ZERO, 1.0)
            lines.append(long_fields(int(node) + first_node_id, direction + 1, 2, curve, scale))
    return "\n".join(lines)


def nonuniform_segment_loads(segments: np.ndarray, corner_values: np.ndarray, direction,
                             first_node_id: int = 1) -> str:
    """One *LOAD_SEGMENT_NONUNIFORM+ per segment (long format): card 1 LCID SF AT DT CID V1 V2 V3
    (traction along V), card 2 N1-N4, card 3 P1-P4 (traction per unit area at each corner)."""
    direction = [float(v) for v in direction]
    blocks = []
    for nodes, values in zip(np.asarray(segments, dtype=int), np.asarray(corner_values, dtype=float)):
        blocks.append("\n".join([
            "*LOAD_SEGMENT_NONUNIFORM+",
            long_fields(CURVE_ONE, 1.0, 0.0, 1.0e20, 0, *direction),
            long_fields(*[int(n) + first_node_id for n in nodes]),
            long_fields(*[float(v) for v in values]),
        ]))
    return "\n".join(blocks)


def write_deck(path: Path, title: str, *blocks: str) -> Path:
    """Join keyword blocks into a deck that starts with *KEYWORD and *TITLE and ends with *END."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    text = "*KEYWORD\n*TITLE\n" + title + "\n" + "\n".join(blocks) + "\n*END\n"
    path.write_text(text)
    return path


# ------------------------------------------------------------------------------------------------
# Meshes


def grid_index(counts):
    """Index function (i, j, k) -> node number of a structured block, k fastest."""
    _, ny, nz = counts

    def index(i, j, k):
        """Node number of grid point (i, j, k)."""
        return (i * (ny + 1) + j) * (nz + 1) + k

    return index


def block_mesh(counts, lengths, origin=(0.0, 0.0, 0.0)):
    """Nodes (n, 3), hexahedra (m, 8, 0-based) and grid indices (n, 3) of a box split into
    counts = (nx, ny, nz) equal cells."""
    counts = tuple(int(c) for c in counts)
    axes = [np.linspace(o, o + length, n + 1) for o, length, n in zip(origin, lengths, counts)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)
    ijk = np.stack(np.meshgrid(*[np.arange(n + 1) for n in counts], indexing="ij"), axis=-1)
    index = grid_index(counts)
    nx, ny, nz = counts
    elements = []
    for i in range(nx):
        for j in range(ny):
            for k in range(nz):
                elements.append([index(i, j, k), index(i + 1, j, k), index(i + 1, j + 1, k),
                                 index(i, j + 1, k), index(i, j, k + 1), index(i + 1, j, k + 1),
                                 index(i + 1, j + 1, k + 1), index(i, j + 1, k + 1)])
    return grid.reshape(-1, 3), np.array(elements, dtype=int), ijk.reshape(-1, 3)


def perturb_nodes(nodes, ijk, counts, lengths, interior_fraction, boundary_fraction, seed,
                  keep=None):
    """Move nodes randomly (uniform, reproducible with ``seed``) by up to a fraction of the cell
    size per direction: ``interior_fraction`` for nodes inside the box, ``boundary_fraction``
    for nodes on its surface, which move only within their face (edge nodes along their edge,
    corners stay). ``keep`` maps node indices to the directions that must not move (e.g. the
    Table 1 nodes keep x and y)."""
    counts = np.asarray(counts)
    cell = np.asarray(lengths, dtype=float) / counts
    on_plane = (ijk == 0) | (ijk == counts)            # (n, 3): on a boundary plane normal to d
    interior = ~on_plane.any(axis=1)
    rng = np.random.default_rng(seed)
    shift = rng.uniform(-1.0, 1.0, nodes.shape) * cell
    amplitude = np.where(interior, interior_fraction, boundary_fraction)[:, None]
    shift *= amplitude * ~on_plane
    if keep:
        for node, directions in keep.items():
            shift[node, list(directions)] = 0.0
    return nodes + shift


def corner_jacobians(nodes, elements):
    """Determinant of the trilinear map's Jacobian at the 8 corners of every hexahedron,
    (m, 8)."""
    corner_edges = {0: (1, 3, 4), 1: (2, 0, 5), 2: (3, 1, 6), 3: (0, 2, 7),
                    4: (7, 5, 0), 5: (4, 6, 1), 6: (5, 7, 2), 7: (6, 4, 3)}
    x = nodes[elements]                                 # (m, 8, 3)
    dets = np.empty(elements.shape, dtype=float)
    for corner, (a, b, c) in corner_edges.items():
        e1 = x[:, a] - x[:, corner]
        e2 = x[:, b] - x[:, corner]
        e3 = x[:, c] - x[:, corner]
        dets[:, corner] = np.einsum("ij,ij->i", np.cross(e1, e2), e3)
    return dets


def check_mesh(nodes, elements, cell_volume):
    """Smallest corner Jacobian over the nominal cell volume; raise if a cell is inverted or
    nearly flat (below 0.05)."""
    smallest = float(corner_jacobians(nodes, elements).min() / cell_volume)
    if smallest < 0.05:
        raise ValueError(f"mesh too distorted: smallest corner Jacobian {smallest:.3f} of the "
                         "nominal cell volume (reduce the node moves or change the seed)")
    return smallest


def bounding_box_nodes(nodes, tolerance=1e-9):
    """Boolean mask of the nodes on the faces of the mesh's bounding box."""
    low, high = nodes.min(axis=0), nodes.max(axis=0)
    span = np.max(high - low)
    return np.any((np.abs(nodes - low) < tolerance * span) | (np.abs(nodes - high) < tolerance * span),
                  axis=1)
