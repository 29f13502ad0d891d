#!/usr/bin/env python3
"""Side-impact dummy component test of Wang, Wu, Guo & Botkin 2009, section 4.4: a door panel
driven into the thorax of a EuroSID-2 (ES-2) kind of side-impact dummy.

Writes, into the output directory (default: this script's directory):

  mesh.k       nodes, elements and node sets shared by the three decks;
  fe.k         everything finite elements: rib foams one-point hexahedra (ELFORM 1), jacket
               Belytschko-Tsay shells (ELFORM 2);
  ribs_efg.k   the three rib foams meshfree solids (*SECTION_SOLID_EFG, ELFORM 41), the jacket
               FE shells;
  coupled.k    the rib foams meshfree solids and the jacket meshfree shells (*SECTION_SHELL
               ELFORM 41 and its EFG card DX DY ISPLINE IDILA).

The three decks include mesh.k and differ only in the sections of the foam parts and of the
jacket (and in their titles).

Units: mm, ms, kg, kN, GPa (stress in GPa = kN/mm^2, density in kg/mm^3; 1 mm/ms = 1 m/s),
as the other examples (inputs/odb_component, inputs/vehicle_front).

Geometry (x forward, y lateral toward the door, z up; the spine axis is the z axis):
  spine box     rigid hexahedron, x -60..60, y -60..20, z -20..220; it carries the thorax mass
                (THORAX_MASS) and is otherwise free
  rib bands     three steel bands (upper, middle, lower), each an arc of radius RIB_RADIUS about
                the z axis from -RIB_ANGLE to +RIB_ANGLE (measured from +y toward +x), RIB_WIDTH
                high, centred at z = 20, 100, 180 (pitch RIB_PITCH); both ends join the spine box
  rib foams     the damping foam on the outside of each band: FOAM_THICKNESS thick, the band's
                height and arc, sharing the band's nodes on its inner face
  jacket        rubber shells on the arc of radius RIB_RADIUS + FOAM_THICKNESS from z = -20 to
                220, sharing the foams' outer face nodes where the ribs are; its front and rear
                edges join the spine box
  door          a flat rigid plate (shells), x -200..200, z -60..260, at y = jacket + GAP, with
                DOOR_MASS, moving at SPEED in -y; it touches the thorax only by contact

What is taken from public sources and what is chosen is listed in docs/examples/side_impact.md.
Run `python3 generate_side_impact.py --help` for the options.
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

# ----------------------------------------------------------------------------------------------
# Model data (every value is explained in docs/examples/side_impact.md)
SPEED = 8.0                     # mm/ms = m/s, door speed (7-9 m/s for ES-2 door/thorax tests)
DOOR_MASS = 40.0                # kg, door panel with its carrier (chosen)
THORAX_MASS = 20.0              # kg, spine box with what it carries (chosen, ~28% of the 72 kg ES-2)
RIB_RADIUS = 130.0              # mm, rib band arc radius (half chest breadth ~ 165 mm less foam + jacket)
RIB_ANGLE = 75.0                # degrees either side of the lateral (+y) axis
RIB_WIDTH = 40.0                # mm, height of a rib band and its foam
RIB_PITCH = 80.0                # mm, vertical distance of the rib modules
RIB_CENTRES = (20.0, 100.0, 180.0)   # lower, middle, upper rib (z)
RIB_THICKNESS = 2.0             # mm, spring steel band
FOAM_THICKNESS = 25.0           # mm
JACKET_THICKNESS = 5.0          # mm
JACKET_LOW, JACKET_HIGH = -20.0, 220.0
GAP = 2.0                       # mm, initial gap door - jacket
DOOR_X = (-200.0, 200.0)
DOOR_Z = (-60.0, 260.0)
DOOR_THICKNESS = 3.0            # mm (contact thickness; the mass is DOOR_MASS)
SPINE_BOX = ((-60.0, 60.0), (-60.0, 20.0), (-20.0, 220.0))

# materials
STEEL = dict(ro=7.85e-6, e=210.0, pr=0.3)
SPRING_STEEL_YIELD, SPRING_STEEL_TANGENT = 1.0, 2.0          # GPa (chosen: a hardened band)
FOAM_DENSITY = 6.0e-8           # kg/mm^3 (60 kg/m^3)
FOAM_TENSION_MODULUS = 1.0e-3   # GPa (1 MPa)
FOAM_HU, FOAM_SHAPE, FOAM_DAMP = 0.2, 5.0, 0.1
# nominal compressive stress (GPa) against nominal strain: a polyurethane damping foam with a
# 0.1 MPa plateau and densification from 70% strain (chosen)
FOAM_CURVE = [(0.0, 0.0), (0.05, 0.08e-3), (0.5, 0.12e-3), (0.7, 0.3e-3), (0.8, 0.8e-3),
              (0.9, 3.0e-3), (0.95, 10.0e-3)]
RUBBER_DENSITY = 1.23e-6        # kg/mm^3, neoprene
RUBBER_A, RUBBER_B = 0.4e-3, 0.1e-3     # GPa, Mooney-Rivlin constants (E = 6(A+B) = 3 MPa)
RUBBER_PR = 0.495

PART_SPINE, PART_DOOR, PART_JACKET = 1, 2, 3
PART_RIBS = (11, 12, 13)        # steel bands: lower, middle, upper
PART_FOAMS = (21, 22, 23)       # foams: lower, middle, upper
RIB_NAMES = ("lower", "middle", "upper")
MID_RIGID_SPINE, MID_RIGID_DOOR, MID_STEEL, MID_FOAM, MID_JACKET = 1, 2, 3, 4, 5
LC_FOAM = 1
SET_SPINE_EXTRA = 1             # rib ends and jacket edges: join the spine box
SET_THORAX_PARTS, SET_DEFORMABLE_PARTS = 1, 2
CONTACT_DOOR, CONTACT_SELF = 1, 2

DECKS = ("fe", "ribs_efg", "coupled")


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


def id_lines(ids) -> list:
    ids = list(ids)
    return ["".join(f"{n:10d}" for n in ids[k:k + 8]) for k in range(0, len(ids), 8)]


# ----------------------------------------------------------------------------------------------
class Mesh:
    def __init__(self, size: float):
        self.size = size
        self.node_id = {}
        self.nodes = []
        self.solids = []      # (eid, pid, 8 node ids)
        self.shells = []      # (eid, pid, 4 node ids)
        self.spine_extra = set()
        jacket_radius = RIB_RADIUS + FOAM_THICKNESS
        arc = math.radians(2.0 * RIB_ANGLE) * jacket_radius
        self.n_arc = max(4, int(round(arc / size)))
        self.angles = np.linspace(-math.radians(RIB_ANGLE), math.radians(RIB_ANGLE), self.n_arc + 1)
        self.n_radial = max(2, int(round(FOAM_THICKNESS / size)))
        self.radii = np.linspace(RIB_RADIUS, jacket_radius, self.n_radial + 1)
        # z lines: rib bands and gaps each cut into cells close to `size`
        breaks = [JACKET_LOW]
        for centre in RIB_CENTRES:
            breaks += [centre - RIB_WIDTH / 2, centre + RIB_WIDTH / 2]
        breaks.append(JACKET_HIGH)
        zs = [breaks[0]]
        for low, high in zip(breaks[:-1], breaks[1:]):
            n = max(1, int(round((high - low) / size)))
            zs += list(np.linspace(low, high, n + 1)[1:])
        self.zs = np.array(zs)

    def node(self, x, y, z) -> int:
        key = (round(float(x), 6), round(float(y), 6), round(float(z), 6))
        nid = self.node_id.get(key)
        if nid is None:
            nid = len(self.nodes) + 1
            self.node_id[key] = nid
            self.nodes.append(key)
        return nid

    def arc_node(self, radius, angle, z) -> int:
        return self.node(radius * math.sin(angle), radius * math.cos(angle), z)

    def in_rib(self, z0, z1):
        for k, centre in enumerate(RIB_CENTRES):
            if z0 >= centre - RIB_WIDTH / 2 - 1e-6 and z1 <= centre + RIB_WIDTH / 2 + 1e-6:
                return k
        return None

    def build(self):
        eid = 0
        a, r, zs = self.angles, self.radii, self.zs
        # spine box: one rigid hexahedron (N1-N4 counterclockwise seen from the N5-N8 face)
        (x0, x1), (y0, y1), (z0, z1) = SPINE_BOX
        eid += 1
        self.solids.append((eid, PART_SPINE, [self.node(x0, y0, z0), self.node(x1, y0, z0), self.node(x1, y1, z0),
                                              self.node(x0, y1, z0), self.node(x0, y0, z1), self.node(x1, y0, z1),
                                              self.node(x1, y1, z1), self.node(x0, y1, z1)]))
        # rib foams: hexahedra in (angle, radius, z); the corner order gives a positive volume
        for i in range(len(a) - 1):
            for j in range(len(r) - 1):
                for k in range(len(zs) - 1):
                    rib = self.in_rib(zs[k], zs[k + 1])
                    if rib is None:
                        continue
                    eid += 1
                    c = [self.arc_node(r[j], a[i], zs[k]), self.arc_node(r[j], a[i + 1], zs[k]),
                         self.arc_node(r[j + 1], a[i + 1], zs[k]), self.arc_node(r[j + 1], a[i], zs[k]),
                         self.arc_node(r[j], a[i], zs[k + 1]), self.arc_node(r[j], a[i + 1], zs[k + 1]),
                         self.arc_node(r[j + 1], a[i + 1], zs[k + 1]), self.arc_node(r[j + 1], a[i], zs[k + 1])]
                    self.solids.append((eid, PART_FOAMS[rib], c))
        self.solid_count = eid
        # shells: rib bands on the inner foam face, jacket on the outer; normals outward (+radius)
        sid = 0
        for i in range(len(a) - 1):
            for k in range(len(zs) - 1):
                rib = self.in_rib(zs[k], zs[k + 1])
                outer = [self.arc_node(r[-1], a[i], zs[k]), self.arc_node(r[-1], a[i], zs[k + 1]),
                         self.arc_node(r[-1], a[i + 1], zs[k + 1]), self.arc_node(r[-1], a[i + 1], zs[k])]
                sid += 1
                self.shells.append((sid, PART_JACKET, outer))
                if rib is not None:
                    inner = [self.arc_node(r[0], a[i], zs[k]), self.arc_node(r[0], a[i], zs[k + 1]),
                             self.arc_node(r[0], a[i + 1], zs[k + 1]), self.arc_node(r[0], a[i + 1], zs[k])]
                    sid += 1
                    self.shells.append((sid, PART_RIBS[rib], inner))
        # the ends of the rib bands and the front and rear edges of the jacket join the spine
        for angle in (a[0], a[-1]):
            for z in zs:
                self.spine_extra.add(self.arc_node(r[-1], angle, z))
                if self.in_rib(z, z) is not None:
                    self.spine_extra.add(self.arc_node(r[0], angle, z))
        # door: rigid plate in the x-z plane, normal -y (toward the thorax)
        y_door = r[-1] + GAP + 0.5 * (JACKET_THICKNESS + DOOR_THICKNESS)
        nx = max(2, int(round((DOOR_X[1] - DOOR_X[0]) / (4 * self.size))))
        nz = max(2, int(round((DOOR_Z[1] - DOOR_Z[0]) / (4 * self.size))))
        xd = np.linspace(*DOOR_X, nx + 1)
        zd = np.linspace(*DOOR_Z, nz + 1)
        self.door_y = y_door
        for i in range(nx):
            for k in range(nz):
                sid += 1
                self.shells.append((sid, PART_DOOR, [self.node(xd[i], y_door, zd[k]), self.node(xd[i + 1], y_door, zd[k]),
                                                     self.node(xd[i + 1], y_door, zd[k + 1]),
                                                     self.node(xd[i], y_door, zd[k + 1])]))
        self.door_area = (DOOR_X[1] - DOOR_X[0]) * (DOOR_Z[1] - DOOR_Z[0])

    def part_nodes(self, parts) -> set:
        nodes = set()
        for _, pid, corners in self.solids + self.shells:
            if pid in parts:
                nodes.update(corners)
        return nodes

    def dof_counts(self, efg_parts) -> dict:
        """Degrees of freedom as the solver counts them in /timing: 3 translations per node and 3
        rotations more per deformable shell node (dofs_total); 3 per node of a meshfree solid part and 6 per
        node of a meshfree shell part (a node in both counts its 6 once). The nodes of the rigid
        door count their translations only, as the solver's count does."""
        shell_nodes = set()
        for _, pid, corners in self.shells:
            if pid != PART_DOOR:          # the rigid door's nodes have no rotational dofs
                shell_nodes.update(corners)
        efg_solid = self.part_nodes([p for p in efg_parts if p in PART_FOAMS])
        efg_shell = self.part_nodes([p for p in efg_parts if p == PART_JACKET])
        efg = 3 * len(efg_solid | efg_shell) + 3 * len(efg_shell)
        return dict(total=3 * len(self.nodes) + 3 * len(shell_nodes), efg=efg)


# ----------------------------------------------------------------------------------------------
def write_mesh(mesh: Mesh, path: Path, args):
    lines = ["*KEYWORD", "$ Side-impact dummy component test: shared mesh (generate_side_impact.py; do not edit)",
             f"$ element size {args.size:g} mm, {len(mesh.nodes)} nodes, {mesh.solid_count} solids, "
             f"{len(mesh.shells)} shells",
             "*NODE"]
    for k, (x, y, z) in enumerate(mesh.nodes, start=1):
        lines.append(f"{k:8d}{x:16.6f}{y:16.6f}{z:16.6f}{0:8d}{0:8d}")
    lines.append("*ELEMENT_SOLID")
    for eid, pid, corners in mesh.solids:
        lines.append(f"{eid:8d}{pid:8d}" + "".join(f"{c:8d}" for c in corners))
    lines.append("*ELEMENT_SHELL")
    for eid, pid, corners in mesh.shells:
        lines.append(f"{eid:8d}{pid:8d}" + "".join(f"{c:8d}" for c in corners))
    lines += ["*SET_NODE_LIST_TITLE", "rib band ends and jacket edges (join the spine box)", card(SET_SPINE_EXTRA)]
    lines += id_lines(sorted(mesh.spine_extra))
    lines += ["*SET_PART_LIST_TITLE", "thorax parts hit by the door", card(SET_THORAX_PARTS)]
    lines += id_lines((PART_JACKET,) + PART_FOAMS + PART_RIBS)
    lines += ["*SET_PART_LIST_TITLE", "thorax parts in self-contact", card(SET_DEFORMABLE_PARTS)]
    lines += id_lines((PART_JACKET,) + PART_FOAMS + PART_RIBS + (PART_SPINE,))
    lines.append("*END")
    path.write_text("\n".join(lines) + "\n")


def section_lines(deck: str, args) -> list:
    efg_foam = deck in ("ribs_efg", "coupled")
    efg_jacket = deck == "coupled"
    out = ["*SECTION_SOLID_TITLE", "rigid spine box", "$    SECID    ELFORM", card(1, 1),
           "*SECTION_SHELL_TITLE", "rigid door plate",
           "$    SECID    ELFORM      SHRF       NIP", card(2, 2, 1.0, 2),
           "$       T1", card(DOOR_THICKNESS, DOOR_THICKNESS, DOOR_THICKNESS, DOOR_THICKNESS),
           "*SECTION_SHELL_TITLE", "steel rib bands",
           "$    SECID    ELFORM      SHRF       NIP", card(3, 2, 0.8333, 3),
           "$       T1", card(RIB_THICKNESS, RIB_THICKNESS, RIB_THICKNESS, RIB_THICKNESS)]
    if efg_foam:
        out += ["*SECTION_SOLID_EFG_TITLE", "meshfree rib foams",
                "$    SECID    ELFORM", card(4, 41),
                "$       DX        DY        DZ   ISPLINE     IDILA      IEBT      IDIM    TOLDEF",
                card(args.dx, args.dx, args.dx, 0, 0, 3, 1, 0.0)]
    else:
        out += ["*SECTION_SOLID_TITLE", "rib foams", "$    SECID    ELFORM", card(4, 1)]
    out += ["*SECTION_SHELL_TITLE", "meshfree jacket" if efg_jacket else "jacket",
            "$    SECID    ELFORM      SHRF       NIP", card(5, 41 if efg_jacket else 2, 0.8333, 3),
            "$       T1", card(JACKET_THICKNESS, JACKET_THICKNESS, JACKET_THICKNESS, JACKET_THICKNESS)]
    if efg_jacket:
        out += ["$       DX        DY   ISPLINE     IDILA", card(args.shell_dx, args.shell_dx, 0, 0)]
    return out


def jacket_material(args) -> list:
    if args.jacket == "elastic":
        e = 6.0 * (RUBBER_A + RUBBER_B)
        return ["*MAT_ELASTIC_TITLE", "jacket (linear elastic stand-in for the rubber)",
                "$      MID        RO         E        PR", card(MID_JACKET, RUBBER_DENSITY, e, 0.45)]
    return ["*MAT_MOONEY-RIVLIN_RUBBER_TITLE", "jacket: neoprene",
            "$      MID        RO        PR         A         B       REF",
            card(MID_JACKET, RUBBER_DENSITY, RUBBER_PR, RUBBER_A, RUBBER_B, 0.0),
            "$      SGL        SW        ST     LCID1      DATA     LCID2", card(0.0, 0.0, 0.0, 0)]


def write_deck(mesh: Mesh, path: Path, args, deck: str):
    titles = {"fe": "all finite elements",
              "ribs_efg": "rib foams meshfree solids, jacket FE shells",
              "coupled": "rib foams meshfree solids, jacket meshfree shells"}
    spine_volume = np.prod([b - a for a, b in SPINE_BOX])
    spine_density = args.thorax_mass / spine_volume
    door_density = args.door_mass / (mesh.door_area * DOOR_THICKNESS)
    counts = mesh.dof_counts({"fe": (), "ribs_efg": PART_FOAMS, "coupled": PART_FOAMS + (PART_JACKET,)}[deck])
    share = counts["efg"] / counts["total"]
    end = args.end_time
    out = ["*KEYWORD", "*TITLE", f"side-impact dummy component test, {titles[deck]}",
           "$ European side-impact dummy component test (Wang, Wu, Guo & Botkin 2009, section 4.4),",
           "$ written by inputs/side_impact/generate_side_impact.py. Units mm, ms, kg, kN, GPa.",
           f"$ element size {args.size:g} mm; door {args.door_mass:g} kg at {SPEED:g} m/s into a {args.thorax_mass:g} kg thorax;",
           f"$ meshfree dofs {counts['efg']} of {counts['total']} ({100 * share:.1f}%, 3 per node, 3 more per shell node).",
           "*CONTROL_TERMINATION", card(end),
           "*CONTROL_TIMESTEP", "$   DTINIT    TSSFAC", card(0.0, args.tssfac),
           "*CONTROL_HOURGLASS", "$      IHQ        QH", card(args.ihq, args.qh),
           "*CONTROL_ENERGY", "$     HGEN      RWEN", card(2, 2),
           "*DATABASE_GLSTAT", card(end / 600),
           "*DATABASE_MATSUM", card(end / 600),
           "*DATABASE_RCFORC", card(end / 600),
           "*DATABASE_BINARY_D3PLOT", card(end / args.states),
           "*PART", "spine box (rigid, carries the thorax mass)", card(PART_SPINE, 1, MID_RIGID_SPINE),
           "*PART", "door panel (rigid)", card(PART_DOOR, 2, MID_RIGID_DOOR),
           "*PART", "jacket" + (" (meshfree shells)" if deck == "coupled" else ""), card(PART_JACKET, 5, MID_JACKET)]
    for pid, name in zip(PART_RIBS, RIB_NAMES):
        out += ["*PART", f"{name} rib band", card(pid, 3, MID_STEEL)]
    for pid, name in zip(PART_FOAMS, RIB_NAMES):
        out += ["*PART", f"{name} rib foam" + (" (meshfree)" if deck != "fe" else ""), card(pid, 4, MID_FOAM)]
    out += section_lines(deck, args)
    out += ["*MAT_RIGID_TITLE", "spine box", "$      MID        RO         E        PR",
            card(MID_RIGID_SPINE, spine_density, STEEL["e"], STEEL["pr"]),
            "*MAT_RIGID_TITLE", "door panel", "$      MID        RO         E        PR",
            card(MID_RIGID_DOOR, door_density, STEEL["e"], STEEL["pr"]),
            "$      CMO      CON1      CON2", card(1.0, 6, 7),
            "*MAT_PIECEWISE_LINEAR_PLASTICITY_TITLE", "spring steel rib bands",
            "$      MID        RO         E        PR      SIGY      ETAN",
            card(MID_STEEL, STEEL["ro"], STEEL["e"], STEEL["pr"], SPRING_STEEL_YIELD, SPRING_STEEL_TANGENT),
            "$        C         P      LCSS      LCSR        VP", card(0.0, 0.0, 0, 0, 0.0), "", "",
            "*MAT_LOW_DENSITY_FOAM_TITLE", "rib damping foam",
            "$      MID        RO         E      LCID        TC        HU      BETA      DAMP",
            card(MID_FOAM, FOAM_DENSITY, FOAM_TENSION_MODULUS, LC_FOAM, 0.0, FOAM_HU, 0.0, FOAM_DAMP),
            "$    SHAPE      FAIL    BVFLAG", card(FOAM_SHAPE, 0.0, 0.0),
            "*DEFINE_CURVE_TITLE", "rib foam: nominal compressive stress (GPa) against nominal strain",
            card(LC_FOAM)]
    out += [f"{a:20.6e}{o:20.6e}" for a, o in FOAM_CURVE]
    out += jacket_material(args)
    out += ["*CONSTRAINED_EXTRA_NODES_SET", "$      PID      NSID", card(PART_SPINE, SET_SPINE_EXTRA),
            "*INITIAL_VELOCITY_GENERATION", "$       ID      STYP     OMEGA        VX        VY        VZ",
            card(PART_DOOR, 2, 0.0, 0.0, -SPEED, 0.0),
            "$       XC        YC        ZC        NX        NY        NZ", card(0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
            "*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE_ID", card(CONTACT_DOOR) + "door on the thorax",
            "$    SURFA     SURFB  SURFATYP  SURFBTYP", card(SET_THORAX_PARTS, PART_DOOR, 2, 3),
            "$       FS        FD        DC        VC       VDC", card(0.3, 0.3, 0.0, 0.0, 10.0),
            "$     SFSA      SFSB", card(1.0, 1.0)]
    if args.self_contact:
        out += ["*CONTACT_AUTOMATIC_SINGLE_SURFACE_ID", card(CONTACT_SELF) + "thorax self-contact",
                "$    SURFA     SURFB  SURFATYP  SURFBTYP", card(SET_DEFORMABLE_PARTS, 0, 2, 0),
                "$       FS        FD        DC        VC       VDC", card(0.3, 0.3, 0.0, 0.0, 10.0),
                "$     SFSA      SFSB", card(1.0, 1.0)]
    out += ["*INCLUDE", "mesh.k", "*END"]
    path.write_text("\n".join(out) + "\n")
    return share


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                     formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    parser.add_argument("--size", type=float, default=10.0, help="element size (mm)")
    parser.add_argument("--end-time", type=float, default=60.0, help="termination time (ms)")
    parser.add_argument("--states", type=int, default=30, help="number of state intervals")
    parser.add_argument("--dx", type=float, default=1.2, help="EFG solids: normalized support DX = DY = DZ")
    parser.add_argument("--shell-dx", type=float, default=1.1,
                        help="EFG shells: normalized support DX = DY (LS-DYNA's default 1.1)")
    parser.add_argument("--ihq", type=int, default=1, help="hourglass type of the FE solids")
    parser.add_argument("--qh", type=float, default=0.1, help="hourglass coefficient")
    parser.add_argument("--tssfac", type=float, default=0.9, help="time step scale factor")
    parser.add_argument("--door-mass", type=float, default=DOOR_MASS, help="door mass (kg)")
    parser.add_argument("--thorax-mass", type=float, default=THORAX_MASS,
                        help="mass of the spine box (kg): the thorax and what it carries")
    parser.add_argument("--jacket", choices=("rubber", "elastic"), default="rubber",
                        help="jacket material: *MAT_MOONEY-RIVLIN_RUBBER, or *MAT_ELASTIC of the same "
                             "small-strain modulus")
    parser.add_argument("--self-contact", action=argparse.BooleanOptionalAction, default=True,
                        help="single-surface contact over the thorax parts")
    parser.add_argument("-o", "--output", type=Path, default=Path(__file__).resolve().parent,
                        help="directory for mesh.k and the decks")
    args = parser.parse_args(argv)

    mesh = Mesh(args.size)
    mesh.build()
    args.output.mkdir(parents=True, exist_ok=True)
    write_mesh(mesh, args.output / "mesh.k", args)
    shares = {deck: write_deck(mesh, args.output / f"{deck}.k", args, deck) for deck in DECKS}
    print(f"{args.output}: mesh.k ({len(mesh.nodes)} nodes, {mesh.solid_count} solids, {len(mesh.shells)} shells), "
          + ", ".join(f"{deck}.k ({100 * share:.1f}% meshfree dofs)" for deck, share in shares.items()))


if __name__ == "__main__":
    main()
