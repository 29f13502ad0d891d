"""Decks of flat plates and strips of shells for the verification of the meshfree (EFG) shells
against FE shells and analytical values (test_efg_shell_verification.py and
tools/efg_shell_convergence.py).

Every deck is written for one shell formulation: 2 (Belytschko-Tsay FE shells) or 41 (EFG
shells: *SECTION_SHELL ELFORM 41 followed by its EFG card DX DY ISPLINE IDILA). Units mm, ms,
kg, kN, GPa; elastic steel unless said otherwise.
"""
from __future__ import annotations

import numpy as np

from deck_writer import fields, node_list_set, nodes_card, plate_mesh, round_to_node_card, shells_card, write_deck

DENSITY, YOUNGS = 7.85e-6, 210.0
SHEAR_FACTOR = 5.0 / 6.0
FE, EFG = 2, 41


def shell_section(section_id, formulation, thickness, points=3, support=1.5, kernel=0):
    """*SECTION_SHELL of one formulation; an EFG section (41) gets its EFG card DX = DY =
    support (None: blank, the default 1.1), ISPLINE = kernel, IDILA 0 (IEBT, IDIM blank)."""
    text = ("*SECTION_SHELL\n" + fields(section_id, formulation, f"{SHEAR_FACTOR:10.7f}", points) + "\n" +
            fields(*[float(thickness)] * 4))
    if formulation == EFG:
        size = None if support is None else float(support)
        text += "\n" + fields(size, size, kernel, 0)
    return text


def curve_card(curve_id, points):
    lines = ["*DEFINE_CURVE", fields(curve_id)]
    lines += [fields(float(a), float(b), width=20) for a, b in points]
    return "\n".join(lines)


def history_nodes_card(node_ids):
    lines = ["*DATABASE_HISTORY_NODE"]
    for start in range(0, len(node_ids), 8):
        lines.append(fields(*[int(n) for n in node_ids[start:start + 8]]))
    return "\n".join(lines)


def split_into_triangles(shells, cells):
    """The quadrilaterals with the given indices each split along their 1-3 diagonal into two
    triangles (N4 = N3)."""
    result = []
    for k, (a, b, c, d) in enumerate(shells):
        if k in cells:
            result += [[a, b, c, c], [a, c, d, d]]
        else:
            result.append([a, b, c, d])
    return np.array(result, dtype=int)


def irregular_plate(cells, lengths, perturbation=0.25, seed=14, triangles=()):
    """Nodes and shells of a rectangle whose interior nodes are moved off the grid by up to
    `perturbation` of a cell, with the quadrilaterals `triangles` split in two; the coordinates
    exactly as the solver reads them."""
    nodes, shells = plate_mesh(cells, lengths, perturbation=perturbation, seed=seed)
    return round_to_node_card(nodes), split_into_triangles(shells, set(triangles))


def velocity_lines(node_ids, velocities):
    return "\n".join(f"{n},{float(v[0])!r},{float(v[1])!r},{float(v[2])!r}" for n, v in zip(node_ids, velocities))


def common_cards(title, end_time, state_interval, formulation, thickness, poisson, points=3, support=1.5,
                 glstat_interval=None, kernel=0):
    cards = [f"*TITLE\n{title}",
             "*CONTROL_TERMINATION\n" + fields(float(end_time)),
             "*CONTROL_TIMESTEP\n" + fields(0.0, 0.9),
             "*DATABASE_BINARY_D3PLOT\n" + fields(float(state_interval)),
             "*PART\nplate\n" + fields(1, 1, 1, 0, 1),
             shell_section(1, formulation, thickness, points, support, kernel),
             "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, float(poisson)),
             "*HOURGLASS\n" + fields(1, 4, 0.1)]
    if glstat_interval is not None:
        cards.append("*DATABASE_GLSTAT\n" + fields(float(glstat_interval)))
    return cards


def membrane_patch_deck(path, formulation, nodes, shells, gradient, offset, end_time, thickness=1.0, poisson=0.3,
                        support=1.5, kernel=0):
    """Every node starts with the velocity v = gradient X + offset (in-plane, constant in time);
    the boundary nodes keep it (prescribed velocity, DOF 1 and 2), the interior nodes are free.
    The exact solution is the homogeneous motion u = t v(X) with uniform stress."""
    velocity = np.zeros_like(nodes)
    velocity[:, :2] = nodes[:, :2] @ np.asarray(gradient).T + np.asarray(offset)
    low, high = nodes[:, :2].min(axis=0), nodes[:, :2].max(axis=0)
    boundary = np.flatnonzero(np.any(np.isclose(nodes[:, :2], low) | np.isclose(nodes[:, :2], high), axis=1))
    motions = ["*BOUNDARY_PRESCRIBED_MOTION_NODE"]
    for k in boundary:
        for direction in (0, 1):
            if velocity[k, direction] != 0.0:
                motions.append(f"{k + 1},{direction + 1},0,1,{float(velocity[k, direction])!r}")
            else:
                motions.append(f"{k + 1},{direction + 1},0,2,1.0")
    write_deck(path,
               *common_cards("membrane patch test", end_time, end_time, formulation, thickness, poisson,
                             support=support, kernel=kernel),
               curve_card(1, [(0.0, 1.0), (1.0e3, 1.0)]),
               curve_card(2, [(0.0, 0.0), (1.0e3, 0.0)]),
               nodes_card(nodes), shells_card(shells),
               "\n".join(motions),
               "*INITIAL_VELOCITY_NODE\n" + velocity_lines(np.arange(1, len(nodes) + 1), velocity))
    return boundary


def smooth_ramp(duration, hold, samples=64):
    """Points of a curve rising from 0 to 1 as 3 s^2 - 2 s^3 over `duration`, then 1 for `hold`."""
    s = np.linspace(0.0, 1.0, samples)
    points = [(duration * a, 3 * a**2 - 2 * a**3) for a in s]
    return points + [(duration + hold, 1.0), (1.0e3, 1.0)]


def rotate_in_plane(nodes, degrees):
    """Nodes turned about z by `degrees` (as the solver will read them)."""
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    turned = nodes.copy()
    turned[:, 0], turned[:, 1] = c * nodes[:, 0] - s * nodes[:, 1], s * nodes[:, 0] + c * nodes[:, 1]
    return round_to_node_card(turned)


def pure_bending_deck(path, formulation, strip_nodes, shells, curvature, ramp, hold, state_interval, degrees=0.0,
                      thickness=1.0, support=1.5):
    """A strip along s (the x of `strip_nodes`, turned by `degrees` about z in the deck), Poisson's
    ratio 0, whose end edges (s = 0 and s = L) are two nodal rigid bodies (parts 11 and 12) held
    in translation (body 12 free in the plane, so that no axial force arises from the shortening
    of the chord) and turned through their centres about the in-plane normal of the strip by
    +/- curvature L / 2 (rotation components about x and y on the same smooth ramp): pure
    bending, w = curvature (s^2 - L s) / 2 and a uniform moment (the long edges are free).
    Returns the nodes as written."""
    length = strip_nodes[:, 0].max()
    left = np.flatnonzero(np.isclose(strip_nodes[:, 0], 0.0)) + 1
    right = np.flatnonzero(np.isclose(strip_nodes[:, 0], length)) + 1
    nodes = rotate_in_plane(strip_nodes, degrees)
    angle = curvature * length / 2.0
    normal = (-np.sin(np.radians(degrees)), np.cos(np.radians(degrees)))   # the strip's in-plane normal
    motions = ["*BOUNDARY_PRESCRIBED_MOTION_RIGID"]
    for body, sign in ((11, 1.0), (12, -1.0)):
        for dof in (1, 2, 3, 7) if body == 11 else (3, 7):
            motions.append(fields(body, dof, 2, 2, 1.0))
        for dof, component in ((5, normal[0]), (6, normal[1])):
            if abs(component) > 1e-12:
                motions.append(fields(body, dof, 2, 1, float(f"{sign * angle * component:.3e}")))
            else:
                motions.append(fields(body, dof, 2, 2, 1.0))
    write_deck(path,
               *common_cards("pure bending of a strip", ramp + hold, state_interval, formulation, thickness, 0.0,
                             support=support, glstat_interval=state_interval),
               curve_card(1, smooth_ramp(ramp, hold)),
               curve_card(2, [(0.0, 0.0), (1.0e3, 0.0)]),
               nodes_card(nodes), shells_card(shells),
               node_list_set(11, left), node_list_set(12, right),
               "*CONSTRAINED_NODAL_RIGID_BODY\n" + fields(11, 0, 11) + "\n" + fields(12, 0, 12),
               "\n".join(motions))
    return nodes


def clamped_strip(cells, length, width):
    nodes, shells = plate_mesh(cells, (length, width))
    nodes = round_to_node_card(nodes)
    root = np.flatnonzero(np.isclose(nodes[:, 0], 0.0))
    tip = np.flatnonzero(np.isclose(nodes[:, 0], length))
    return nodes, shells, root, tip


def middle_node(nodes, candidates, width):
    return candidates[np.argmin(np.abs(nodes[candidates, 1] - width / 2))]


def cantilever_deck(path, formulation, cells, length, width, thickness, load, ramp, hold, poisson=0.0, support=1.5,
                    triangles=False):
    """A strip clamped at x = 0 with a total transverse force `load` (z) spread over its tip edge
    as consistent nodal forces, raised linearly over `ramp` (whole periods of the first mode:
    that leaves no first-mode vibration) and then held. History of the tip nodes. `triangles`:
    every cell split into two triangles."""
    nodes, shells, root, tip = clamped_strip(cells, length, width)
    if triangles:
        shells = split_into_triangles(shells, set(range(len(shells))))
    share = np.full(len(tip), load / cells[1])
    share[np.isclose(nodes[tip, 1], 0.0) | np.isclose(nodes[tip, 1], width)] *= 0.5
    sample = (ramp + hold) / 2000.0
    write_deck(path,
               *common_cards("cantilever plate, tip load", ramp + hold, ramp + hold, formulation, thickness, poisson,
                             support=support, glstat_interval=sample),
               "*DATABASE_NODOUT\n" + fields(sample),
               history_nodes_card(tip + 1),
               curve_card(1, [(0.0, 0.0), (ramp, 1.0), (1.0e3, 1.0)]),
               nodes_card(nodes), shells_card(shells),
               "*BOUNDARY_SPC_NODE\n" + "\n".join(fields(k + 1, 0, 1, 1, 1, 1, 1, 1) for k in root),
               "*LOAD_NODE_POINT\n" + "\n".join(fields(k + 1, 3, 1, float(f)) for k, f in zip(tip, share)))
    return nodes, tip


BETA_L = 1.8751040687                      # first root of cos x cosh x = -1


def first_mode_shape(x, length):
    """First mode of a clamped-free Euler-Bernoulli beam, 0 at x = 0."""
    b = BETA_L * x / length
    s = (np.cosh(BETA_L) + np.cos(BETA_L)) / (np.sinh(BETA_L) + np.sin(BETA_L))
    return np.cosh(b) - np.cos(b) - s * (np.sinh(b) - np.sin(b))


def vibrating_strip_deck(path, formulation, cells, length, width, thickness, poisson, end_time, speed=0.1,
                         support=1.5):
    """A strip clamped at x = 0 started with the velocity of its first beam mode (tip speed
    `speed`); GLSTAT and the tip node's history."""
    nodes, shells, root, tip = clamped_strip(cells, length, width)
    probe = middle_node(nodes, tip, width)
    velocity = np.zeros_like(nodes)
    velocity[:, 2] = speed * first_mode_shape(nodes[:, 0], length) / first_mode_shape(length, length)
    sample = end_time / 2000.0
    write_deck(path,
               *common_cards("clamped strip in free vibration", end_time, end_time, formulation, thickness, poisson,
                             support=support, glstat_interval=sample),
               "*DATABASE_NODOUT\n" + fields(sample),
               history_nodes_card([probe + 1]),
               nodes_card(nodes), shells_card(shells),
               "*BOUNDARY_SPC_NODE\n" + "\n".join(fields(k + 1, 0, 1, 1, 1, 1, 1, 1) for k in root),
               "*INITIAL_VELOCITY_NODE\n" + velocity_lines(np.arange(1, len(nodes) + 1), velocity))
    return probe


def spinning_plate_deck(path, formulation, cells, side, thickness, omega, end_time, support=1.5):
    """A free square plate (centre at the origin) spun about its normal z at `omega` rad/ms
    (*INITIAL_VELOCITY_GENERATION); GLSTAT and the corner nodes' histories."""
    nodes, shells = plate_mesh(cells, (side, side))
    nodes[:, :2] -= side / 2.0
    nodes = round_to_node_card(nodes)
    corners = np.flatnonzero(np.all(np.isclose(np.abs(nodes[:, :2]), side / 2.0), axis=1))
    write_deck(path,
               *common_cards("spinning free plate", end_time, end_time / 4.0, formulation, thickness, 0.3,
                             support=support, glstat_interval=end_time / 400.0),
               "*DATABASE_NODOUT\n" + fields(end_time / 400.0),
               history_nodes_card(corners + 1),
               nodes_card(nodes), shells_card(shells),
               "*INITIAL_VELOCITY_GENERATION\n" + fields(0, 2, float(omega), 0.0, 0.0, 0.0) + "\n" +
               fields(0.0, 0.0, 0.0, 0.0, 0.0, 1.0))
    return nodes, corners


def interface_strip_deck(path, efg_half, cells, length, width, thickness, poisson, speed, pulse, end_time,
                         probes, direction=1, interface=None, support=1.5):
    """A strip along x, part 1 on x < interface (default length / 2) FE shells, part 2 beyond it FE shells
    (efg_half False) or EFG shells (True), both the same material and mesh. The nodes at x = 0
    get a velocity pulse speed sin^2(pi t / pulse) for 0 < t < pulse (smooth) along `direction`
    (1 axial, 3 transverse), then are held in that direction; the histories of the nodes nearest
    the middle line at the x of `probes`."""
    nodes, shells = plate_mesh(cells, (length, width))
    nodes = round_to_node_card(nodes)
    centre = nodes[shells].mean(axis=1)[:, 0]
    parts = np.where(centre > (length / 2.0 if interface is None else interface), 2, 1)
    left = np.flatnonzero(np.isclose(nodes[:, 0], 0.0))
    probe_nodes = []
    for x in probes:
        near = np.flatnonzero(np.isclose(nodes[:, 0], nodes[np.argmin(np.abs(nodes[:, 0] - x)), 0]))
        probe_nodes.append(middle_node(nodes, near, width))
    second = EFG if efg_half else FE
    element_lines = ["*ELEMENT_SHELL"] + [
        f"{k + 1:8d}{p:8d}" + "".join(f"{c + 1:8d}" for c in corners)
        for k, (p, corners) in enumerate(zip(parts, shells))]
    sample = end_time / 1000.0
    pulse_curve = [(a * pulse, round(np.sin(np.pi * a)**2, 12)) for a in np.linspace(0.0, 1.0, 81)] + [(1.0e3, 0.0)]
    write_deck(path,
               "*TITLE\naxial pulse through a shell strip",
               "*CONTROL_TERMINATION\n" + fields(float(end_time)),
               "*CONTROL_TIMESTEP\n" + fields(0.0, 0.9),
               "*DATABASE_GLSTAT\n" + fields(sample),
               "*DATABASE_NODOUT\n" + fields(sample),
               history_nodes_card([n + 1 for n in probe_nodes]),
               "*PART\nfe half\n" + fields(1, 1, 1, 0, 1),
               "*PART\nsecond half\n" + fields(2, 2, 1, 0, 1),
               shell_section(1, FE, thickness),
               shell_section(2, second, thickness, support=support),
               "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, float(poisson)),
               "*HOURGLASS\n" + fields(1, 4, 0.1),
               curve_card(1, pulse_curve),
               nodes_card(nodes), "\n".join(element_lines),
               "*BOUNDARY_PRESCRIBED_MOTION_NODE\n" +
               "\n".join(fields(k + 1, direction, 0, 1, float(speed)) for k in left))
    return nodes, probe_nodes


# analytical values and readings shared by the tests and tools/efg_shell_convergence.py ----------

def timoshenko_tip_deflection(length, width, thickness, load):
    """Tip deflection of a cantilever, nu = 0 (G = E / 2), shear factor SHRF 5/6:
    P L^3 / (3 E I) + P L / (k G A). At nu = 0 it is also the exact Mindlin plate solution of
    the free-edged plate (no anticlastic curvature)."""
    second_moment = width * thickness**3 / 12.0
    return (load * length**3 / (3.0 * YOUNGS * second_moment) +
            load * length / (SHEAR_FACTOR * YOUNGS / 2.0 * width * thickness))


def beam_period(length, width, thickness):
    """First period of a clamped-free Euler-Bernoulli beam with E (a narrow strip)."""
    second_moment = width * thickness**3 / 12.0
    omega = BETA_L**2 * np.sqrt(YOUNGS * second_moment / (DENSITY * width * thickness * length**4))
    return 2.0 * np.pi / omega


def held_tip_deflection(results, ramp):
    """Mean over the history nodes of w averaged (trapezoidal rule in time) from `ramp` on."""
    means = []
    for node in results["history/nodout"].values():
        time, w = node["time"][...], node["displacement"][:, 2]
        held = time >= ramp
        means.append(np.trapezoid(w[held], time[held]) / (time[held][-1] - time[held][0]))
    return float(np.mean(means))


def vibration_period(results):
    """Twice the mean interval between the zero crossings of the first history node's w (linear
    interpolation), and their number."""
    node = next(iter(results["history/nodout"].values()))
    time, w = node["time"][...], node["displacement"][:, 2]
    index = np.flatnonzero(np.sign(w[:-1]) * np.sign(w[1:]) < 0)
    crossings = time[index] - w[index] * (time[index + 1] - time[index]) / (w[index + 1] - w[index])
    return 2.0 * float(np.diff(crossings).mean()), len(crossings)


def quarter_ring_deck(path, formulation, cells, radius, width, thickness, load, ramp, hold, support=1.5):
    """A quarter of a circular ring (mid-surface radius `radius` about the y axis, width along y)
    of flat shells, nu = 0: x = R cos(phi), z = R sin(phi), phi from 0 (clamped edge) to pi/2
    (free edge), `cells` = (along the arc, across the width). A total force `load` along z (radial
    at the free edge), consistent nodal forces raised linearly over `ramp`, then held; history of
    the free edge's nodes."""
    along, across = cells
    phi = np.linspace(0.0, np.pi / 2.0, along + 1)
    y = np.linspace(0.0, width, across + 1)
    nodes = np.array([[radius * np.cos(a), b, radius * np.sin(a)] for a in phi for b in y])
    nodes = round_to_node_card(nodes)
    index = lambda i, j: i * (across + 1) + j
    shells = np.array([[index(i, j), index(i + 1, j), index(i + 1, j + 1), index(i, j + 1)]
                       for i in range(along) for j in range(across)], dtype=int)
    root = np.arange(across + 1)
    tip = along * (across + 1) + np.arange(across + 1)
    share = np.full(len(tip), load / across)
    share[[0, -1]] *= 0.5
    sample = (ramp + hold) / 2000.0
    write_deck(path,
               *common_cards("quarter ring, end load", ramp + hold, ramp + hold, formulation, thickness, 0.0,
                             support=support, glstat_interval=sample),
               "*DATABASE_NODOUT\n" + fields(sample),
               history_nodes_card(tip + 1),
               curve_card(1, [(0.0, 0.0), (ramp, 1.0), (1.0e3, 1.0)]),
               nodes_card(nodes), shells_card(shells),
               "*BOUNDARY_SPC_NODE\n" + "\n".join(fields(k + 1, 0, 1, 1, 1, 1, 1, 1) for k in root),
               "*LOAD_NODE_POINT\n" + "\n".join(fields(k + 1, 3, 1, float(f)) for k, f in zip(tip, share)))
    return nodes, tip


def turning_ring_deck(path, formulation, cells, radius, width, thickness, omega, end_time, support=1.5):
    """The quarter ring of quarter_ring_deck, free, started turning about its own axis (y, an
    in-plane axis of every cell) at `omega` rad/ms (*INITIAL_VELOCITY_GENERATION); GLSTAT."""
    along, across = cells
    phi = np.linspace(0.0, np.pi / 2.0, along + 1)
    y = np.linspace(0.0, width, across + 1)
    nodes = round_to_node_card(np.array([[radius * np.cos(a), b, radius * np.sin(a)] for a in phi for b in y]))
    index = lambda i, j: i * (across + 1) + j
    shells = np.array([[index(i, j), index(i + 1, j), index(i + 1, j + 1), index(i, j + 1)]
                       for i in range(along) for j in range(across)], dtype=int)
    write_deck(path,
               *common_cards("turning quarter ring", end_time, end_time, formulation, thickness, 0.0,
                             support=support, glstat_interval=end_time / 200.0),
               nodes_card(nodes), shells_card(shells),
               "*INITIAL_VELOCITY_GENERATION\n" + fields(0, 2, float(omega), 0.0, 0.0, 0.0) + "\n" +
               fields(0.0, 0.0, 0.0, 0.0, 1.0, 0.0))
    return nodes
