"""Write the vehicle front-structure deck: two longitudinal rails (hat sections with closing
plates), two crush cans, a bumper beam (hat section with closing plate), two rockers (hat
sections with closing plates) and a floor panel, with a lumped mass at the rear for the rest of
the car, driven at 15 m/s into a rigid planar wall (or a rigid pole).

Usage: python3 generate_vehicle.py [--size default|coarse] [--welds merged|spotweld|generalized]
                                   [--barrier wall|pole] [--end-time MS] [--output vehicle.k]

Units: mm, ms, kg, kN, GPa (LS-DYNA's consistent set: stress in GPa = kN/mm^2, energy in J).

Geometry (x points rearward; the car moves in -x towards the barrier at x = 0; y to the left;
z up; the floor lies at z = 0):
  bumper beam  hat section 60 x 100 with 20 mm flanges, x = 5 .. 65, y = -600 .. 600, opening
               rearward, closing plate at the rear
  crush cans   square tubes 70 x 70, x = 65 .. 215, at y = +-450
  rails        hat sections 80 x 100 with 20 mm flanges, x = 215 .. 915, at y = +-450,
               opening inboard, closing plate on the inboard side
  floor panel  z = 0, x = 915 .. 2115, between the rockers
  rail extensions  closed boxes 80 x 80 just under the floor, x = 915 .. 2115, at y = +-450:
               they carry the rails' load to the rear mass, as the rails of a real car run on
               under the floor (without them the whole load would pass through the 1 mm floor)
  rockers      hat sections 100 x 120, x = 915 .. 2115, at y = +-700, opening inboard
Joints: the hat flanges and their closing plates are joined by spot welds every --pitch mm at
mid-flange, the closing plate lying (t_hat + t_plate) / 2 off the flange (--welds spotweld, the
default: *CONSTRAINED_SPOTWELD pairs failing at SN = SS = --weld-strength kN; --welds generalized:
*CONSTRAINED_GENERALIZED_WELD_SPOT on two-node sets, the same failure), or by shared nodes along
the whole flange (--welds merged: a continuous seam). The bolted joints (bumper to cans, cans to
rails, rails to the floor) are *CONSTRAINED_NODAL_RIGID_BODY ties of the end rings. The floor
and the rockers share nodes along the rockers' closing plates. The rest of the car is a lumped
mass (*ELEMENT_MASS) spread over the nodes of the rear ends of the floor, the rockers and the rail
extensions, which form one nodal rigid body (id 200: /history/rbdout/200 is the rear mass's motion).

Materials: *MAT_PIECEWISE_LINEAR_PLASTICITY (024) mild steel with its hardening curve (*DEFINE_CURVE,
true stress against effective plastic strain), Belytschko-Tsay shells with 3 points through
the thickness. One single-surface contact over all parts.
"""
from __future__ import annotations

import argparse
import math

SIZES = {
    # element sizes (mm) of: cans, rails, bumper, rockers, floor
    "default": {"can": 8.0, "rail": 12.0, "bumper": 15.0, "rocker": 30.0, "floor": 60.0},
    "coarse": {"can": 17.5, "rail": 20.0, "bumper": 30.0, "rocker": 50.0, "floor": 100.0},
}
# part id: (name, thickness mm)
PARTS = {
    1: ("bumper beam", 2.0), 2: ("bumper closing plate", 1.5),
    3: ("crush can left", 1.5), 4: ("crush can right", 1.5),
    5: ("rail left", 2.0), 6: ("rail right", 2.0), 7: ("rail closing plates", 1.5),
    8: ("rocker left", 1.5), 9: ("rocker right", 1.5), 10: ("rocker closing plates", 1.2),
    11: ("floor panel", 1.0), 12: ("rail extensions", 2.0),
}
REAR_BODY = 200


class Mesh:
    """Nodes (merged by position within a scope) and four-node shells."""

    def __init__(self):
        self.coordinates: list[tuple[float, float, float]] = []
        self.index: dict[tuple, int] = {}
        self.shells: list[tuple[int, int, int, int, int]] = []

    def node(self, point, scope: str) -> int:
        key = (scope,) + tuple(round(value, 3) for value in point)
        if key not in self.index:
            self.coordinates.append(tuple(point))
            self.index[key] = len(self.coordinates)
        return self.index[key]

    def strip(self, part, scope, origin, along, across, count_along, count_across):
        """Quads over the parallelogram origin + s along + r across; returns the node grid."""
        grid = [[self.node([origin[k] + i / count_along * along[k] + j / count_across * across[k]
                            for k in range(3)], scope)
                 for j in range(count_across + 1)] for i in range(count_along + 1)]
        for i in range(count_along):
            for j in range(count_across):
                self.shells.append((part, grid[i][j], grid[i + 1][j], grid[i + 1][j + 1], grid[i][j + 1]))
        return grid


def divisions(length: float, size: float, even: bool = False) -> int:
    count = max(1, round(length / size))
    if even and count % 2:
        count += 1
    return count


def member(mesh, part, scope, start, axis, length, size, section, u_axis, v_axis):
    """A prismatic member along axis from start: section is a list of (u0, v0, u1, v1, count)
    wall segments in the (u_axis, v_axis) plane. Returns a dict: segment index -> node grid."""
    count_along = divisions(length, size)
    grids = {}
    for number, (u0, v0, u1, v1, count) in enumerate(section):
        origin = [start[k] + u0 * u_axis[k] + v0 * v_axis[k] for k in range(3)]
        across = [(u1 - u0) * u_axis[k] + (v1 - v0) * v_axis[k] for k in range(3)]
        along = [length * axis[k] for k in range(3)]
        grids[number] = mesh.strip(part, scope, origin, along, across, count_along, count)
    return grids


def hat_section(width, height, flange, size, gap, open_sign):
    """Hat walls and closing plate in (u, v): the web at u = -open_sign * width / 2, the flanges
    in the plane u = +open_sign * width / 2, v from 0 (bottom) to height; the closing plate
    `gap` further out. Returns (hat segments, plate segments); segment 0 and 4 are the flanges,
    the plate's 0 and 2 lie on them."""
    inner, outer = open_sign * width / 2, -open_sign * width / 2
    wall, web, lip = divisions(width, size), divisions(height, size), divisions(flange, size, even=True)
    hat = [(inner, height + flange, inner, height, lip),      # top flange
           (inner, height, outer, height, wall),              # top wall
           (outer, height, outer, 0.0, web),                  # web
           (outer, 0.0, inner, 0.0, wall),                    # bottom wall
           (inner, 0.0, inner, -flange, lip)]                 # bottom flange
    plate_u = inner + open_sign * gap
    plate = [(plate_u, height + flange, plate_u, height, lip),
             (plate_u, height, plate_u, 0.0, web),
             (plate_u, 0.0, plate_u, -flange, lip)]
    return hat, plate


def weld_pairs(hat_grids, plate_grids, pitch, size):
    """Node pairs at mid-flange every `pitch` mm: (hat node, plate node)."""
    pairs = []
    step = max(1, round(pitch / size))
    for hat_segment, plate_segment in ((0, 0), (4, 2)):
        hat, plate = hat_grids[hat_segment], plate_grids[plate_segment]
        middle = len(hat[0]) // 2
        for i in range(step // 2, len(hat), step):
            pairs.append((hat[i][middle], plate[i][middle]))
    return pairs


def ring(mesh, scope_nodes, axis_value, axis_index):
    """Nodes of a list whose coordinate along axis_index equals axis_value."""
    return [n for n in scope_nodes if abs(mesh.coordinates[n - 1][axis_index] - axis_value) < 1e-6]


def nodes_of(grids):
    return sorted({n for grid in grids.values() for row in grid for n in row})


def build(args):
    size = SIZES[args.size]
    mesh = Mesh()
    thickness = {part: t for part, (_, t) in PARTS.items()}
    merged = args.welds == "merged"
    welds = []
    rail_y, rail_width, rail_height, rail_flange = 450.0, 80.0, 100.0, 20.0
    x_bumper, bumper_depth = 5.0, 60.0
    can_length, rail_length, body_length = 150.0, 700.0, 1200.0
    # the body starts where the rails end; with welds the cans and rails start a plate gap later
    x_body = x_bumper + bumper_depth + can_length + rail_length
    x_rear = x_body + body_length
    rocker_y, rocker_width, rocker_height, rocker_flange = 700.0, 100.0, 120.0, 20.0
    centre_z = rail_height / 2
    ties = []   # (id, node list)
    extension_rear = []

    # bumper beam along y: u along x (the hat opens rearward, +x), v along z
    gap = 0.0 if merged else 0.5 * (thickness[1] + thickness[2])
    hat, plate = hat_section(bumper_depth, 100.0, 20.0, size["bumper"], gap, +1)
    start = (x_bumper + bumper_depth / 2, -600.0, centre_z - 50.0)
    bumper_hat = member(mesh, 1, "bumper", start, (0, 1, 0), 1200.0, size["bumper"], hat, (1, 0, 0), (0, 0, 1))
    bumper_plate = member(mesh, 2, "bumper", start, (0, 1, 0), 1200.0, size["bumper"], plate, (1, 0, 0), (0, 0, 1))
    welds += weld_pairs(bumper_hat, bumper_plate, args.pitch, size["bumper"])
    x_can = x_bumper + bumper_depth + gap
    x_rail = x_can + can_length
    plate_nodes = nodes_of(bumper_plate)

    for side, sign in ((0, +1), (1, -1)):
        y = sign * rail_y
        # crush can: a square tube 70 x 70 along x
        can_part = 3 + side
        half = 35.0
        count = divisions(2 * half, size["can"])
        square = [(-half, -half, half, -half, count), (half, -half, half, half, count),
                  (half, half, -half, half, count), (-half, half, -half, -half, count)]
        can = member(mesh, can_part, f"can{side}", (x_can, y, centre_z), (1, 0, 0), can_length, size["can"],
                     square, (0, 1, 0), (0, 0, 1))
        can_nodes = nodes_of(can)
        # bumper to can: the can's front ring and the closing-plate nodes inside its outline
        front = ring(mesh, can_nodes, x_can, 0)
        footprint = [n for n in plate_nodes
                     if abs(mesh.coordinates[n - 1][1] - y) <= half + 1e-6
                     and abs(mesh.coordinates[n - 1][2] - centre_z) <= half + 1e-6]
        ties.append((101 + side, front + footprint))
        # rail: hat opening inboard (towards y = 0), u along y
        gap = 0.0 if merged else 0.5 * (thickness[5] + thickness[7])
        hat, plate = hat_section(rail_width, rail_height, rail_flange, size["rail"], gap, -sign)
        rail_hat = member(mesh, 5 + side, f"rail{side}", (x_rail, y, 0.0), (1, 0, 0), rail_length, size["rail"],
                          hat, (0, 1, 0), (0, 0, 1))
        rail_plate = member(mesh, 7, f"rail{side}", (x_rail, y, 0.0), (1, 0, 0), rail_length, size["rail"],
                            plate, (0, 1, 0), (0, 0, 1))
        welds += weld_pairs(rail_hat, rail_plate, args.pitch, size["rail"])
        rail_nodes = nodes_of(rail_hat) + nodes_of(rail_plate)
        ties.append((103 + side, ring(mesh, can_nodes, x_rail, 0) + ring(mesh, rail_nodes, x_rail, 0)))
        # rail extension under the floor, its top wall (t_floor + t_extension) / 2 below it
        below = 0.5 * (thickness[11] + thickness[12])
        count = divisions(80.0, size["rocker"])
        box = [(-40.0, -80.0, 40.0, -80.0, count), (40.0, -80.0, 40.0, 0.0, count),
               (40.0, 0.0, -40.0, 0.0, count), (-40.0, 0.0, -40.0, -80.0, count)]
        extension = member(mesh, 12, f"extension{side}", (x_body, y, -below), (1, 0, 0), body_length,
                           size["rocker"], box, (0, 1, 0), (0, 0, 1))
        extension_nodes = nodes_of(extension)
        ties.append((105 + side, ring(mesh, rail_nodes, x_rail + rail_length, 0)
                     + ring(mesh, extension_nodes, x_body, 0)))   # floor nodes added below
        extension_rear.extend(ring(mesh, extension_nodes, x_rear, 0))

        # rocker: hat opening inboard, closing plate inboard; bottom at z = 0
        gap = 0.0 if merged else 0.5 * (thickness[8] + thickness[10])
        hat, plate = hat_section(rocker_width, rocker_height, rocker_flange, size["rocker"], gap, -sign)
        rocker_hat = member(mesh, 8 + side, "body", (x_body, sign * rocker_y, 0.0), (1, 0, 0), body_length,
                            size["rocker"], hat, (0, 1, 0), (0, 0, 1))
        rocker_plate = member(mesh, 10, "body", (x_body, sign * rocker_y, 0.0), (1, 0, 0), body_length,
                              size["rocker"], plate, (0, 1, 0), (0, 0, 1))
        welds += weld_pairs(rocker_hat, rocker_plate, args.pitch, size["rocker"])
    # floor panel between the rockers' closing plates, at z = 0, sharing their nodes
    inner_y = rocker_y - rocker_width / 2 - (0.0 if merged else 0.5 * (thickness[8] + thickness[10]))
    floor = mesh.strip(11, "body", (x_body, -inner_y, 0.0), (body_length, 0, 0), (0, 2 * inner_y, 0),
                       divisions(body_length, size["floor"]), divisions(2 * inner_y, size["floor"]))
    floor_front = list(floor[0])
    for number, (tie_id, tie_nodes) in enumerate(ties):
        if tie_id in (105, 106):
            y = rail_y if tie_id == 105 else -rail_y
            near = [n for n in floor_front
                    if abs(mesh.coordinates[n - 1][1] - y) <= rail_width / 2 + size["floor"] / 2]
            ties[number] = (tie_id, tie_nodes + near)
    body_nodes = sorted({n for key, n in mesh.index.items() if key[0] == "body"})
    rear = ring(mesh, body_nodes, x_rear, 0) + extension_rear
    ties.append((REAR_BODY, rear))
    # a weld at a member's end would join a rigid tie (LS-DYNA and crashfree refuse that): the tie
    # holds those two nodes together already
    tied = {n for _, tie_nodes in ties for n in tie_nodes}
    welds = [(a, b) for a, b in welds if a not in tied and b not in tied]
    return mesh, welds, ties, rear


def field(value, width=10):
    text = f"{value:{width}.4g}" if isinstance(value, float) else f"{value:{width}d}"
    if len(text) > width:
        text = f"{value:{width}.3e}"
    return text


def write_deck(args, mesh, welds, ties, rear):
    structure_mass = 0.0
    density = 7.85e-6
    lines = ["*KEYWORD", "*TITLE",
             f"vehicle front structure, {args.size} mesh, {args.welds} flanges, {args.barrier}, {args.speed:g} m/s",
             "$ units: mm, ms, kg, kN, GPa, J", "*CONTROL_TERMINATION", field(args.end_time),
             "*CONTROL_TIMESTEP", f"{0.0:10.1f}{0.9:10.2f}",
             "*CONTROL_HOURGLASS", f"{4:10d}{0.05:10.3f}",
             "*CONTROL_CONTACT", f"{0.1:10.2f}",
             "*DATABASE_GLSTAT", field(args.end_time / 400),
             "*DATABASE_MATSUM", field(args.end_time / 400),
             "*DATABASE_RWFORC", field(args.end_time / 800),
             "*DATABASE_RCFORC", field(args.end_time / 400),
             "*DATABASE_BINARY_D3PLOT", field(args.end_time / 20)]
    lines += ["*NODE"]
    for number, (x, y, z) in enumerate(mesh.coordinates, start=1):
        lines.append(f"{number:8d}{x:16.6f}{y:16.6f}{z:16.6f}{0:8d}{0:8d}")
    lines += ["*ELEMENT_SHELL"]
    for number, (part, a, b, c, d) in enumerate(mesh.shells, start=1):
        lines.append(f"{number:8d}{part:8d}{a:8d}{b:8d}{c:8d}{d:8d}")
    for part, (name, thickness) in PARTS.items():
        lines += ["*PART", name, f"{part:10d}{part:10d}{1:10d}",
                  "*SECTION_SHELL", f"{part:10d}{2:10d}{5 / 6:10.6f}{3:10d}",
                  f"{thickness:10.3f}{thickness:10.3f}{thickness:10.3f}{thickness:10.3f}"]
    # mild steel (DC04-like), yield 0.21 GPa, saturating hardening; no strain-rate effect
    lines += ["*MAT_PIECEWISE_LINEAR_PLASTICITY_TITLE", "mild steel",
              f"{1:10d}{density:10.3e}{210.0:10.1f}{0.3:10.2f}{0.0:10.1f}{0.0:10.1f}",
              f"{0.0:10.1f}{0.0:10.1f}{1:10d}{0:10d}", "", "",
              "*DEFINE_CURVE_TITLE", "mild steel: true stress (GPa) against effective plastic strain", f"{1:10d}"]
    for strain in [0.0, 0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5, 1.0]:
        lines.append(f"{strain:20.6f}{0.21 + 0.17 * (1 - math.exp(-strain / 0.1)):20.6f}")
    # mass of the structure, for the lumped mass of the rest of the car
    for part, a, b, c, d in mesh.shells:
        p = [mesh.coordinates[n - 1] for n in (a, b, c, d)]
        diagonal1 = [p[2][k] - p[0][k] for k in range(3)]
        diagonal2 = [p[3][k] - p[1][k] for k in range(3)]
        cross = [diagonal1[1] * diagonal2[2] - diagonal1[2] * diagonal2[1],
                 diagonal1[2] * diagonal2[0] - diagonal1[0] * diagonal2[2],
                 diagonal1[0] * diagonal2[1] - diagonal1[1] * diagonal2[0]]
        structure_mass += 0.5 * math.sqrt(sum(v * v for v in cross)) * PARTS[part][1] * density
    rest = max(0.0, args.vehicle_mass - structure_mass)
    lines += ["$ the rest of the car: a lumped mass spread over the rear body's nodes",
              "*ELEMENT_MASS"]
    for number, node in enumerate(rear, start=1):
        lines.append(f"{number:8d}{node:8d}{rest / len(rear):16.6f}")
    for tie_id, tie_nodes in ties:
        unique = sorted(set(tie_nodes))
        lines += ["*SET_NODE_LIST", f"{tie_id:10d}"]
        for k in range(0, len(unique), 8):
            lines.append("".join(f"{n:10d}" for n in unique[k:k + 8]))
        lines += ["*CONSTRAINED_NODAL_RIGID_BODY", f"{tie_id:10d}{0:10d}{tie_id:10d}"]
    strength = args.weld_strength
    if args.welds == "spotweld":
        lines += [f"$ spot welds at mid-flange: they fail at (fn/SN)^2 + (fs/SS)^2 = 1, SN = SS = {strength:g} kN",
                  "*CONSTRAINED_SPOTWELD",
                  "$#     n1        n2        sn        ss         n         m        tf        ep"]
        for a, b in welds:
            lines.append(f"{a:10d}{b:10d}{strength:10.3f}{strength:10.3f}{2.0:10.1f}{2.0:10.1f}")
    elif args.welds == "generalized":
        for number, (a, b) in enumerate(welds, start=1):
            set_id = 1000 + number
            lines += ["*CONSTRAINED_GENERALIZED_WELD_SPOT", f"{set_id:10d}",
                      f"{1e20:10.2e}{0.0:10.1f}{strength:10.3f}{strength:10.3f}{2.0:10.1f}{2.0:10.1f}",
                      "*SET_NODE_LIST", f"{set_id:10d}", f"{a:10d}{b:10d}"]
    lines += ["*CONTACT_AUTOMATIC_SINGLE_SURFACE_ID", f"{1:10d}{'':70s}structure",
              f"{0:10d}{0:10d}{5:10d}{0:10d}", f"{0.2:10.2f}{0.2:10.2f}", ""]
    lines += ["*INITIAL_VELOCITY", f"{0:10d}", field(-args.speed)]
    if args.barrier == "wall":
        lines += ["*RIGIDWALL_PLANAR_ID", f"{1:10d}{'':70s}barrier", f"{0:10d}",
                  f"{0.0:10.1f}{0.0:10.1f}{0.0:10.1f}{1.0:10.1f}{0.0:10.1f}{0.0:10.1f}{0.0:10.1f}"]
    else:
        radius = 127.0
        lines += ["*RIGIDWALL_GEOMETRIC_CYLINDER_ID", f"{1:10d}{'':70s}pole", f"{0:10d}",
                  f"{-radius:10.1f}{args.pole_offset:10.1f}{-500.0:10.1f}{-radius:10.1f}{args.pole_offset:10.1f}"
                  f"{500.0:10.1f}{0.0:10.1f}",
                  f"{radius:10.1f}{0.0:10.1f}{0:10d}"]
    lines += ["*END"]
    with open(args.output, "w") as deck:
        deck.write("\n".join(lines) + "\n")
    return structure_mass, rest


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", choices=sorted(SIZES), default="default",
                        help="element sizes: default (8-60 mm, about 11,300 shells) or coarse (17-100 mm, about 4,100)")
    parser.add_argument("--welds", choices=("merged", "spotweld", "generalized"), default="spotweld",
                        help="flange joints: *CONSTRAINED_SPOTWELD pairs (default), "
                             "*CONSTRAINED_GENERALIZED_WELD_SPOT, or shared nodes along the whole flange")
    parser.add_argument("--weld-strength", type=float, default=8.0,
                        help="normal and shear force at which a spot weld fails, kN (default 8)")
    parser.add_argument("--pitch", type=float, default=40.0, help="spot weld pitch along the flanges, mm")
    parser.add_argument("--barrier", choices=("wall", "pole"), default="wall")
    parser.add_argument("--pole-offset", type=float, default=0.0, help="y of the pole's axis, mm (default 0: centre)")
    parser.add_argument("--speed", type=float, default=15.0, help="impact speed, mm/ms = m/s (default 15)")
    parser.add_argument("--vehicle-mass", type=float, default=800.0,
                        help="total mass in kg; the rear lumped mass is this less the structure (default 800)")
    parser.add_argument("--end-time", type=float, default=40.0, help="ms (default 40)")
    parser.add_argument("--output", default="vehicle.k")
    args = parser.parse_args()
    mesh, welds, ties, rear = build(args)
    structure_mass, rest = write_deck(args, mesh, welds, ties, rear)
    print(f"{args.output}: {len(mesh.shells)} shells, {len(mesh.coordinates)} nodes, {len(welds)} spot welds"
          f"{' (written as shared nodes)' if args.welds == 'merged' else ''}, structure {structure_mass:.1f} kg, "
          f"rear mass {rest:.1f} kg, end time {args.end_time:g} ms")


if __name__ == "__main__":
    main()
