#!/usr/bin/env python3
"""Offset deformable barrier (ODB) component test of Wang, Wu, Guo & Botkin 2009, section 4.3.

Writes, into the output directory (default: this script's directory):

  mesh.k     nodes, hexahedra (main block, its upper-left corner, bumper), the aluminium
             cladding shells and the node sets the decks use;
  fe.k       every solid part one-point hexahedra (ELFORM 1) with viscous hourglass control;
  coupled.k  the same, with the corner part of the main block meshfree (*SECTION_SOLID_EFG).

Both decks include mesh.k and differ only in the section of part 3 (the corner).

Cladding (on by default, --no-cladding leaves it out): Belytschko-Tsay shells of aluminium
(*MAT_PLASTIC_KINEMATIC) on the main block's top (y = 650), bottom (y = 0) and rear (z = 0)
faces (part 11) and a facing sheet on the bumper's rear face (z = 450, part 12). The shells are
bonded to the honeycomb by shared nodes: each shell's four nodes are the face nodes of the
hexahedron beneath it (no tied contact).

Units: mm, ms, kg, kN, GPa (stress in GPa = kN/mm^2, density in kg/mm^3).

Geometry (x across the barrier, y up, z along the honeycomb cell axis = impact direction):
  main block    x 0..1000, y 0..650, z 0..450 (rear face on the rigid backing at z = 0)
  bumper        x 0..1000, y 80..410, z 450..540 (in front of the main block, lower part; its
                lower edge 80 mm above the main block's, as in the EEVC / ECE R94 barrier)
  corner part   x 0..XE, y YE..650, all depths (XE, YE snapped to the mesh; --efg-x, --efg-y)
  cylinder      rigid, axis along z, radius R, centre (XC, YC), its flat end cap moving at
                15 mm/ms in -z into the upper-left corner (x = 0 is the left edge seen from the
                impactor, who looks in -z with y up).

Run `python3 generate_mesh.py --help` for the options (element size, crush depth, cladding,
backing, self-contact).
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

# ----------------------------------------------------------------------------------------------
# Model data (every value is explained in docs/examples/odb_component.md)
WIDTH, HEIGHT, DEPTH = 1000.0, 650.0, 450.0          # main block
BUMPER_LOW, BUMPER_HIGH, BUMPER_DEPTH = 80.0, 410.0, 90.0
SPEED = 15.0                                          # mm/ms
GPA_PER_MPA = 1.0e-3

# honeycomb: crush strength (MPa), density (kg/m^3), relative density of the foil stack,
# densification onset (engineering strain), VF, compacted E, PR, SIGY (GPa), moduli (GPa)
HONEYCOMBS = {
    "main": dict(mid=1, crush=0.342, density=28.6, onset=0.70, vf=0.20,
                 e=0.20, pr=0.20, sigy=0.00103,
                 eaau=0.50, ebbu=0.005, eccu=0.005, gabu=0.08, gbcu=0.002, gcau=0.14),
    "bumper": dict(mid=2, crush=1.711, density=82.6, onset=0.65, vf=0.25,
                   e=1.00, pr=0.20, sigy=0.00513,
                   eaau=1.50, ebbu=0.015, eccu=0.015, gabu=0.23, gbcu=0.006, gcau=0.40),
}
IN_PLANE_FRACTION = 0.05      # in-plane normal and in-plane shear yield / axial crush strength
W_SHEAR_FRACTION = 0.9        # transverse shear yield in the W (x-z) plane / crush strength
L_SHEAR_FRACTION = 1.5        # transverse shear yield in the L (y-z) plane / crush strength
SHEAR_RESIDUAL = 0.4          # shear yield after the cell walls tear, fraction of the peak
HONEYCOMB_MU = 0.05

# aluminium sheet (*MAT_PLASTIC_KINEMATIC): density, E, nu, yield, tangent modulus
SHEET = dict(mid=3, ro=2.68e-6, e=70.0, pr=0.33, sigy=0.18, etan=0.55)
CLADDING_THICKNESS = 0.81     # main block top, bottom, rear (ECE R94 Annex 9: 0.81 +- 0.07 mm)
FACING_THICKNESS = 0.81       # bumper rear facing sheet (same specification)

PART_MAIN, PART_BUMPER, PART_CORNER, PART_BACKING = 1, 2, 3, 5
PART_CLADDING, PART_FACING = 11, 12
SET_REAR, SET_HONEYCOMB, SET_HONEYCOMB_PARTS = 1, 2, 1
CYLINDER_WALL_ID = 1
SELF_CONTACT_ID = 1


def log_strain(engineering: float) -> float:
    """|ln(1 - e)| of a compressive engineering strain e."""
    return -math.log(1.0 - engineering)


def axial_curve(crush_gpa: float, onset: float, vf: float) -> list:
    """Yield stress against |logarithmic strain| along the cell axis (MAT_126 LCA):
    the plateau of pre-crushed honeycomb from zero strain (no initial peak), then
    densification from `onset` (engineering strain) to full compaction at 1 - VF."""
    full = 1.0 - vf
    mid = 0.5 * (onset + full)
    return [(0.0, crush_gpa),
            (log_strain(onset), crush_gpa),
            (log_strain(mid), 1.5 * crush_gpa),
            (log_strain(full), 3.0 * crush_gpa),
            (3.0, 10.0 * crush_gpa)]


def shear_curve(peak_gpa: float) -> list:
    """Transverse shear yield against engineering shear strain: the peak up to 0.15, the cell
    walls tear down to SHEAR_RESIDUAL of the peak at 0.5, then constant."""
    return [(0.0, peak_gpa), (0.15, peak_gpa), (0.5, SHEAR_RESIDUAL * peak_gpa), (10.0, SHEAR_RESIDUAL * peak_gpa)]


# ----------------------------------------------------------------------------------------------
# Formatting helpers (LS-DYNA fixed format: 10-column fields, 8-column element fields)
def fmt(value) -> str:
    if value is None or value == "":
        return " " * 10
    if isinstance(value, (int, np.integer)):
        return f"{int(value):10d}"
    text = f"{value:10.4g}"
    if len(text) > 10 or float(text) != float(f"{value:.4g}"):
        text = f"{value:10.3e}"
    return text.rjust(10)


def card(*values) -> str:
    return "".join(fmt(v) for v in values).rstrip()


def curve_card(lcid: int, points: list, title: str) -> str:
    lines = [f"*DEFINE_CURVE_TITLE", title, card(lcid)]
    lines += [f"{a:20.6e}{o:20.6e}" for a, o in points]
    return "\n".join(lines)


# ----------------------------------------------------------------------------------------------
def segment_lines(bounds: list, size: float) -> np.ndarray:
    """Grid coordinates through the given breakpoints, each interval cut into cells close to
    `size` (at least one)."""
    coords = [bounds[0]]
    for low, high in zip(bounds[:-1], bounds[1:]):
        n = max(1, int(round((high - low) / size)))
        coords += list(np.linspace(low, high, n + 1)[1:])
    return np.array(coords)


def nearest(values: np.ndarray, target: float) -> float:
    return float(values[np.argmin(np.abs(values - target))])


class Mesh:
    def __init__(self, size: float, efg_x: float, efg_y: float, bumper_cells: int):
        self.size = size
        self.xs = segment_lines([0.0, WIDTH], size)
        # the corner part's edges are grid lines
        self.efg_x = nearest(self.xs, efg_x)
        self.ys = segment_lines([0.0, BUMPER_LOW, BUMPER_HIGH, HEIGHT], size)
        self.efg_y = nearest(self.ys, efg_y)
        # refine the y lines so that efg_y is one (it already is: nearest line)
        self.zs = segment_lines([0.0, DEPTH], size)
        nbz = max(bumper_cells, int(round(BUMPER_DEPTH / size)))
        self.zb = np.linspace(DEPTH, DEPTH + BUMPER_DEPTH, nbz + 1)
        self.node_id = {}
        self.nodes = []
        self.solids = []      # (eid, pid, 8 node ids)
        self.shells = []      # (eid, pid, 4 node ids)

    def node(self, x, y, z) -> int:
        key = (round(x, 6), round(y, 6), round(z, 6))
        nid = self.node_id.get(key)
        if nid is None:
            nid = len(self.nodes) + 1
            self.node_id[key] = nid
            self.nodes.append(key)
        return nid

    def build(self, cladding: bool, backing: str, backing_thickness: float):
        xs, ys, zs, zb = self.xs, self.ys, self.zs, self.zb
        eid = 0
        # main block: the corner part (x < efg_x, y > efg_y) and the rest
        for i in range(len(xs) - 1):
            for j in range(len(ys) - 1):
                corner = xs[i + 1] <= self.efg_x + 1e-6 and ys[j] >= self.efg_y - 1e-6
                pid = PART_CORNER if corner else PART_MAIN
                for k in range(len(zs) - 1):
                    eid += 1
                    self.solids.append((eid, pid, self.hexa(xs[i:i + 2], ys[j:j + 2], zs[k:k + 2])))
        # bumper, in front of the main block's lower part
        yb = ys[(ys >= BUMPER_LOW - 1e-6) & (ys <= BUMPER_HIGH + 1e-6)]
        for i in range(len(xs) - 1):
            for j in range(len(yb) - 1):
                for k in range(len(zb) - 1):
                    eid += 1
                    self.solids.append((eid, PART_BUMPER, self.hexa(xs[i:i + 2], yb[j:j + 2], zb[k:k + 2])))
        if backing == "rigid":
            zr = [-backing_thickness, 0.0]
            for i in range(len(xs) - 1):
                for j in range(len(ys) - 1):
                    eid += 1
                    self.solids.append((eid, PART_BACKING, self.hexa(xs[i:i + 2], ys[j:j + 2], zr)))
        self.solid_count = eid
        if cladding:
            sid = 0
            # normals outward from the honeycomb: N1-N4 counterclockwise seen from outside
            for i in range(len(xs) - 1):
                for k in range(len(zs) - 1):
                    x0, x1, z0, z1 = xs[i], xs[i + 1], zs[k], zs[k + 1]
                    sid += 1   # top, y = HEIGHT, outward +y
                    self.shells.append((sid, PART_CLADDING, [self.node(x0, HEIGHT, z0), self.node(x0, HEIGHT, z1),
                                                             self.node(x1, HEIGHT, z1), self.node(x1, HEIGHT, z0)]))
                    sid += 1   # bottom, y = 0, outward -y
                    self.shells.append((sid, PART_CLADDING, [self.node(x0, 0.0, z0), self.node(x1, 0.0, z0),
                                                             self.node(x1, 0.0, z1), self.node(x0, 0.0, z1)]))
            for i in range(len(xs) - 1):
                for j in range(len(ys) - 1):
                    x0, x1, y0, y1 = xs[i], xs[i + 1], ys[j], ys[j + 1]
                    sid += 1   # rear, z = 0, outward -z
                    self.shells.append((sid, PART_CLADDING, [self.node(x0, y0, 0.0), self.node(x0, y1, 0.0),
                                                             self.node(x1, y1, 0.0), self.node(x1, y0, 0.0)]))
            for i in range(len(xs) - 1):
                for j in range(len(yb) - 1):
                    x0, x1, y0, y1 = xs[i], xs[i + 1], yb[j], yb[j + 1]
                    sid += 1   # bumper rear face, z = DEPTH, normal -z (toward the main block)
                    self.shells.append((sid, PART_FACING, [self.node(x0, y0, DEPTH), self.node(x0, y1, DEPTH),
                                                           self.node(x1, y1, DEPTH), self.node(x1, y0, DEPTH)]))

    def hexa(self, x, y, z) -> list:
        # N1-N4 counterclockwise seen from the N5-N8 face (+z side)
        return [self.node(x[0], y[0], z[0]), self.node(x[1], y[0], z[0]), self.node(x[1], y[1], z[0]),
                self.node(x[0], y[1], z[0]), self.node(x[0], y[0], z[1]), self.node(x[1], y[0], z[1]),
                self.node(x[1], y[1], z[1]), self.node(x[0], y[1], z[1])]

    def rear_nodes(self) -> list:
        return [nid for (x, y, z), nid in self.node_id.items() if abs(z) < 1e-6]

    def honeycomb_nodes(self) -> list:
        used = set()
        for _, pid, corners in self.solids:
            if pid in (PART_MAIN, PART_CORNER, PART_BUMPER):
                used.update(corners)
        return sorted(used)

    def dof_counts(self) -> dict:
        """Degrees of freedom as the solver counts them in /timing: 3 translations per node,
        3 rotations more per shell node (dofs_total), 3 per node of the corner part (dofs_efg,
        the meshfree particles and the interface nodes; their rotations, where the cladding
        covers the corner, belong to the shells)."""
        corner, shell_nodes = set(), set()
        for _, pid, corners in self.solids:
            if pid == PART_CORNER:
                corner.update(corners)
        for _, _, corners in self.shells:
            shell_nodes.update(corners)
        return dict(nodes=len(self.nodes), shell_nodes=len(shell_nodes), corner_nodes=len(corner),
                    total=3 * len(self.nodes) + 3 * len(shell_nodes), efg=3 * len(corner),
                    translational=3 * len(self.nodes))

    def corner_share(self) -> float:
        """dofs_efg / dofs_total as in the solver's /timing (rotations counted)."""
        counts = self.dof_counts()
        return counts["efg"] / counts["total"]

    def corner_share_translational(self) -> float:
        """dofs_efg over the translational dofs only (= corner nodes / all nodes)."""
        counts = self.dof_counts()
        return counts["efg"] / counts["translational"]


def footprint_area(xc: float, yc: float, radius: float, x_range, y_range, samples: int = 2000) -> float:
    """Area of the cylinder's circle inside the rectangle x_range x y_range (numerical)."""
    xs = np.linspace(xc - radius, xc + radius, samples)
    ys = np.linspace(yc - radius, yc + radius, samples)
    X, Y = np.meshgrid(xs, ys)
    inside = ((X - xc) ** 2 + (Y - yc) ** 2 <= radius ** 2) & (X >= x_range[0]) & (X <= x_range[1]) \
        & (Y >= y_range[0]) & (Y <= y_range[1])
    return float(inside.mean() * (2 * radius) ** 2)


def footprint_perimeter(xc, yc, radius, x_range, y_range, samples: int = 20000) -> float:
    """Length of the cylinder's rim inside the rectangle (where it shears the honeycomb)."""
    angle = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)
    x = xc + radius * np.cos(angle)
    y = yc + radius * np.sin(angle)
    inside = (x >= x_range[0]) & (x <= x_range[1]) & (y >= y_range[0]) & (y <= y_range[1])
    return float(inside.mean() * 2 * np.pi * radius)


# ----------------------------------------------------------------------------------------------
def write_mesh(mesh: Mesh, path: Path, args):
    lines = ["*KEYWORD", "$ ODB component: shared mesh (generated by generate_mesh.py; do not edit)",
             f"$ element size {args.size:g} mm, {len(mesh.nodes)} nodes, {mesh.solid_count} solids, "
             f"{len(mesh.shells)} shells; corner part x < {mesh.efg_x:g}, y > {mesh.efg_y:g}",
             "*NODE"]
    rear = set(mesh.rear_nodes()) if args.backing == "spc" else set()
    for k, (x, y, z) in enumerate(mesh.nodes, start=1):
        lines.append(f"{k:8d}{x:16.6f}{y:16.6f}{z:16.6f}{0:8d}{0:8d}")
    lines.append("*ELEMENT_SOLID")
    for eid, pid, corners in mesh.solids:
        lines.append(f"{eid:8d}{pid:8d}" + "".join(f"{c:8d}" for c in corners))
    if mesh.shells:
        lines.append("*ELEMENT_SHELL")
        for eid, pid, corners in mesh.shells:
            lines.append(f"{eid:8d}{pid:8d}" + "".join(f"{c:8d}" for c in corners))
    lines.append("*SET_NODE_LIST_TITLE\nrear face of the main block (on the rigid backing)")
    lines.append(card(SET_REAR))
    ids = sorted(mesh.rear_nodes())
    for k in range(0, len(ids), 8):
        lines.append("".join(f"{n:10d}" for n in ids[k:k + 8]))
    lines.append("*SET_NODE_LIST_TITLE\nhoneycomb nodes (tracked by the cylinder)")
    lines.append(card(SET_HONEYCOMB))
    ids = mesh.honeycomb_nodes()
    for k in range(0, len(ids), 8):
        lines.append("".join(f"{n:10d}" for n in ids[k:k + 8]))
    lines.append("*SET_PART_LIST_TITLE\nhoneycomb parts (self-contact)")
    lines.append(card(SET_HONEYCOMB_PARTS))
    lines.append(card(PART_MAIN, PART_CORNER, PART_BUMPER))
    lines.append("*END")
    path.write_text("\n".join(lines) + "\n")
    del rear


def honeycomb_cards(name: str) -> str:
    h = HONEYCOMBS[name]
    crush = h["crush"] * GPA_PER_MPA
    ro = h["density"] * 1.0e-9
    base = 100 * h["mid"]
    lca, lcb, lcab, lcbc, lcca = base + 1, base + 2, base + 3, base + 4, base + 5
    axial = axial_curve(crush, h["onset"], h["vf"])
    in_plane = [(a, IN_PLANE_FRACTION * o) for a, o in axial]
    cards = [
        f"*MAT_MODIFIED_HONEYCOMB_TITLE\n{name} honeycomb ({h['crush']} MPa, {h['density']} kg/m3)",
        "$      MID        RO         E        PR      SIGY        VF        MU      BULK",
        card(h["mid"], ro, h["e"], h["pr"], h["sigy"], h["vf"], HONEYCOMB_MU, 0),
        "$      LCA       LCB       LCC       LCS      LCAB      LCBC      LCCA      LCSR",
        card(lca, lcb, lcb, lcab, lcab, lcbc, lcca, 0),
        "$     EAAU      EBBU      ECCU      GABU      GBCU      GCAU      AOPT      MACF",
        card(h["eaau"], h["ebbu"], h["eccu"], h["gabu"], h["gbcu"], h["gcau"], 2, 1),
        "$       XP        YP        ZP        A1        A2        A3      RFAC       PRU",
        card(0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
        "$       D1        D2        D3      TSEF      SSEF      VREF      TREF    SHDFLG",
        card(1.0, 0.0, 0.0),
        curve_card(lca, axial, f"{name}: axial (a = z, cell axis) yield vs |log strain|"),
        curve_card(lcb, in_plane, f"{name}: in-plane normal yield (b = x, c = y)"),
        curve_card(lcab, shear_curve(W_SHEAR_FRACTION * crush), f"{name}: W shear (ab = z-x) vs shear strain"),
        curve_card(lcca, shear_curve(L_SHEAR_FRACTION * crush), f"{name}: L shear (ca = y-z) vs shear strain"),
        curve_card(lcbc, [(0.0, IN_PLANE_FRACTION * crush), (10.0, IN_PLANE_FRACTION * crush)],
                   f"{name}: in-plane shear (bc = x-y)"),
    ]
    return "\n".join(cards)


def write_deck(mesh: Mesh, path: Path, args, coupled: bool):
    end_time = args.crush / SPEED
    xc, yc, radius = args.cyl_x, args.cyl_y, args.radius
    # the cylinder starts args.gap in front of the foremost face under its footprint
    over_bumper = (yc - radius < BUMPER_HIGH) and (yc + radius > BUMPER_LOW)
    front = DEPTH + BUMPER_DEPTH if over_bumper else DEPTH
    tail_z = front + args.gap
    area = footprint_area(xc, yc, radius, (0.0, WIDTH), (0.0, HEIGHT))
    rim = footprint_perimeter(xc, yc, radius, (0.0, WIDTH), (0.0, HEIGHT))
    title = "ODB component test, " + ("coupled FE / EFG corner" if coupled else "all FE")
    out = ["*KEYWORD", "*TITLE", title,
           "$ Offset deformable barrier component test (Wang, Wu, Guo & Botkin 2009, section 4.3),",
           "$ written by inputs/odb_component/generate_mesh.py. Units mm, ms, kg, kN, GPa.",
           f"$ element size {args.size:g} mm; crush {args.crush:g} mm at {SPEED:g} mm/ms; cylinder radius {radius:g}",
           f"$ at x = {xc:g}, y = {yc:g}; its end cap covers {area:.0f} mm2 of the barrier face, its rim",
           f"$ runs {rim:.0f} mm inside the face. Corner part (3): x < {mesh.efg_x:g}, y > {mesh.efg_y:g},",
           f"$ {100 * mesh.corner_share():.1f}% of the dofs (3 per node, 3 more per shell node), "
           f"{100 * mesh.corner_share_translational():.1f}% of the translational dofs.",
           "*CONTROL_TERMINATION", card(end_time),
           "*CONTROL_TIMESTEP", "$   DTINIT    TSSFAC      ISDO    TSLIMT     DT2MS",
           card(0.0, args.tssfac, 0, 0.0, -args.dt2ms if args.dt2ms > 0 else 0.0),
           "*CONTROL_HOURGLASS", "$      IHQ        QH", card(args.ihq, args.qh),
           "*CONTROL_ENERGY", card(2, 2),
           "*DATABASE_GLSTAT", card(end_time / 400),
           "*DATABASE_MATSUM", card(end_time / 400),
           "*DATABASE_RWFORC", card(end_time / 400),
           "*DATABASE_BINARY_D3PLOT", card(end_time / args.states),
           ]
    if args.self_contact:
        out += ["*DATABASE_RCFORC", card(end_time / 400)]
    out += ["*PART", "main honeycomb block", card(PART_MAIN, 1, 1, 0, 1),
            "*PART", "main block, upper-left corner" + (" (meshfree)" if coupled else ""),
            card(PART_CORNER, 2 if coupled else 1, 1, 0, 1),
            "*PART", "bumper honeycomb", card(PART_BUMPER, 1, 2, 0, 1)]
    if args.backing == "rigid":
        out += ["*PART", "rigid backing", card(PART_BACKING, 1, 4)]
    out += ["*SECTION_SOLID", "$    SECID    ELFORM", card(1, 1)]
    if coupled:
        out += ["*SECTION_SOLID_EFG_TITLE", "meshfree corner",
                "$    SECID    ELFORM", card(2, 41),
                "$       DX        DY        DZ   ISPLINE     IDILA      IEBT      IDIM    TOLDEF",
                card(args.dx, args.dx, args.dx, 0, 0, 3, 1, 0.0)]
    out += ["*HOURGLASS", "$     HGID       IHQ        QM", card(1, args.ihq, args.qh)]
    out += [honeycomb_cards("main"), honeycomb_cards("bumper")]
    if args.cladding:
        out += ["*PART", "main block cladding (top, bottom, rear)", card(PART_CLADDING, 11, 3),
                "*PART", "bumper rear facing sheet", card(PART_FACING, 12, 3),
                "*SECTION_SHELL",
                "$    SECID    ELFORM      SHRF       NIP     PROPT   QR/IRID     ICOMP     SETYP",
                card(11, 2, 1.0, 2),
                "$       T1        T2        T3        T4      NLOC     MAREA      IDOF    EDGSET",
                card(CLADDING_THICKNESS, CLADDING_THICKNESS, CLADDING_THICKNESS, CLADDING_THICKNESS),
                card(12, 2, 1.0, 2),
                card(FACING_THICKNESS, FACING_THICKNESS, FACING_THICKNESS, FACING_THICKNESS),
                "*MAT_PLASTIC_KINEMATIC_TITLE", "aluminium sheet",
                "$      MID        RO         E        PR      SIGY      ETAN      BETA",
                card(SHEET["mid"], SHEET["ro"], SHEET["e"], SHEET["pr"], SHEET["sigy"], SHEET["etan"], 0.0),
                card(0.0, 0.0)]
    if args.backing == "rigid":
        out += ["*MAT_RIGID_TITLE", "rigid backing (fixed)",
                "$      MID        RO         E        PR", card(4, 7.85e-6, 210.0, 0.3),
                "$      CMO      CON1      CON2", card(1.0, 7, 7)]
    else:
        out += ["*BOUNDARY_SPC_SET", "$     NSID       CID      DOFX      DOFY      DOFZ",
                card(SET_REAR, 0, 1, 1, 1)]
    out += ["*DEFINE_CURVE_TITLE", "cylinder speed (mm/ms)", card(9),
            f"{0.0:20.6e}{SPEED:20.6e}", f"{1000.0:20.6e}{SPEED:20.6e}",
            "*RIGIDWALL_GEOMETRIC_CYLINDER_MOTION_ID", card(CYLINDER_WALL_ID) + "impactor",
            "$     NSID    NSIDEX     BOXID     BIRTH     DEATH", card(SET_HONEYCOMB),
            "$       XT        YT        ZT        XH        YH        ZH      FRIC",
            card(xc, yc, tail_z, xc, yc, tail_z + args.length, args.friction),
            "$   RADCYL    LENCYL     NSEGS", card(radius, args.length, 0),
            "$     LCID       OPT        VX        VY        VZ", card(9, 0, 0.0, 0.0, -1.0)]
    if args.self_contact:
        out += ["*CONTACT_AUTOMATIC_SINGLE_SURFACE_ID", card(SELF_CONTACT_ID) + "honeycomb self-contact",
                "$    SURFA     SURFB  SURFATYP  SURFBTYP", card(SET_HONEYCOMB_PARTS, 0, 2, 0),
                "$       FS        FD        DC        VC       VDC    PENCHK        BT        DT",
                card(0.2, 0.2, 0.0, 0.0, 10.0),
                "$     SFSA      SFSB", card(1.0, 1.0),
                "$     SOFT    SOFSCL", card(1, 0.1)]
    out += ["*INCLUDE", "mesh.k", "*END"]
    path.write_text("\n".join(out) + "\n")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                     formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    parser.add_argument("--size", type=float, default=42.0,
                        help="element size (mm): 42 for the shipped decks (41.7 x 41.25-40 x 40.9 mm cells), "
                             "50 for the test's reduced model")
    parser.add_argument("--crush", type=float, default=330.0, help="cylinder travel after contact (mm)")
    parser.add_argument("--radius", type=float, default=100.0, help="cylinder radius (mm)")
    parser.add_argument("--cyl-x", type=float, default=70.0, help="cylinder axis x (mm)")
    parser.add_argument("--cyl-y", type=float, default=555.0, help="cylinder axis y (mm)")
    parser.add_argument("--length", type=float, default=600.0, help="cylinder length (mm)")
    parser.add_argument("--gap", type=float, default=1.0, help="initial gap to the barrier face (mm)")
    parser.add_argument("--friction", type=float, default=0.0, help="cylinder wall FRIC")
    parser.add_argument("--efg-x", type=float, default=208.0, help="corner part: x < this (mm, snapped)")
    parser.add_argument("--efg-y", type=float, default=410.0, help="corner part: y > this (mm, snapped)")
    parser.add_argument("--dx", type=float, default=1.2, help="EFG normalized support DX = DY = DZ")
    parser.add_argument("--bumper-cells", type=int, default=2, help="least cells through the bumper depth")
    parser.add_argument("--ihq", type=int, default=1, help="hourglass type of the solid parts (4: see the docs)")
    parser.add_argument("--qh", type=float, default=0.1, help="hourglass coefficient")
    parser.add_argument("--tssfac", type=float, default=0.9, help="time step scale factor")
    parser.add_argument("--dt2ms", type=float, default=0.0,
                        help="mass scaling: the step held at this value (ms); 0 = none")
    parser.add_argument("--states", type=int, default=20, help="number of state intervals")
    parser.add_argument("--cladding", action=argparse.BooleanOptionalAction, default=True,
                        help="the aluminium cladding shells (main block top, bottom, rear; bumper rear)")
    parser.add_argument("--backing", choices=("spc", "rigid"), default="spc",
                        help="rigid backing: SPC on the rear face nodes, or a fixed *MAT_RIGID plate")
    parser.add_argument("--backing-thickness", type=float, default=20.0)
    parser.add_argument("--self-contact", action=argparse.BooleanOptionalAction, default=True,
                        help="single-surface contact on the honeycomb parts")
    parser.add_argument("-o", "--output", type=Path, default=Path(__file__).resolve().parent,
                        help="directory for mesh.k, fe.k, coupled.k")
    args = parser.parse_args(argv)

    mesh = Mesh(args.size, args.efg_x, args.efg_y, args.bumper_cells)
    mesh.build(args.cladding, args.backing, args.backing_thickness)
    args.output.mkdir(parents=True, exist_ok=True)
    write_mesh(mesh, args.output / "mesh.k", args)
    write_deck(mesh, args.output / "fe.k", args, coupled=False)
    write_deck(mesh, args.output / "coupled.k", args, coupled=True)
    area = footprint_area(args.cyl_x, args.cyl_y, args.radius, (0.0, WIDTH), (0.0, HEIGHT))
    print(f"{args.output}: mesh.k ({len(mesh.nodes)} nodes, {mesh.solid_count} solids, {len(mesh.shells)} shells), "
          f"fe.k, coupled.k; corner part x < {mesh.efg_x:g}, y > {mesh.efg_y:g}: "
          f"{100 * mesh.corner_share():.1f}% of the dofs ({100 * mesh.corner_share_translational():.1f}% of the "
          f"translational dofs); cylinder footprint {area:.0f} mm2")


if __name__ == "__main__":
    main()
