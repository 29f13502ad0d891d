"""Write the seed decks of the deck fuzzer into tests/fuzz/seeds/.

One small deck per keyword family, built with the regression tests' deck_writer (fixed 10-column
cards, 16-column node cards). Every seed is a correct deck that runs to its end time in a few
hundred cycles at most, so that the checked debug build (-O0, every check on) finishes it in
well under a second and the fuzzer spends its time on mutants, not on physics.

The seeds are stored in the repository, so a fuzzing run depends only on these files and its
seed number; this script is how they were made (run it again after changing it, then check that
every seed still ends with normal termination: `python3 tests/fuzz/fuzz.py seeds`).

    python3 tests/fuzz/make_seeds.py [--out tests/fuzz/seeds]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[0] / "regression"))

from deck_writer import (block_mesh, efg_section, fields, node_list_set, nodes_card,  # noqa: E402
                         plate_mesh, shells_card, solids_card)

STEEL = (7.85e-6, 210.0, 0.3)       # kg/mm^3, GPa, -
# The seeds of one to four solid elements run at TSSFAC 0.6: at the default 0.9 such small
# models of one-point hexahedra are not stable (the step of a single free hexahedron is above its
# volumetric mode's limit), and a seed must end normally. The mutations set TSSFAC back to 0.9
# and far beyond.
SMALL_MODEL_STEP = "*CONTROL_TIMESTEP\n" + fields(0.0, 0.6)


def curve(curve_id, points, options=()):
    """*DEFINE_CURVE: card 1 LCID (and SIDR SFA SFO OFFA OFFO when given), points in 20 columns."""
    lines = ["*DEFINE_CURVE", fields(curve_id, *options)]
    lines += [fields(float(a), float(b), width=20) for a, b in points]
    return "\n".join(lines)


def deck_text(*blocks, title=None):
    head = ["*KEYWORD"] + ([f"*TITLE\n{title}"] if title else [])
    return "\n".join(head + [b for b in blocks if b]) + "\n*END\n"


def merge_solids(*groups):
    """Element cards of several (elements, part, first id, first node id) groups in one keyword."""
    lines = ["*ELEMENT_SOLID"]
    for elements, part, first_id, first_node in groups:
        lines += solids_card(elements, part_id=part, first_id=first_id, first_node_id=first_node).splitlines()[1:]
    return "\n".join(lines)


def merge_shells(*groups):
    lines = ["*ELEMENT_SHELL"]
    for shells, part, first_id, first_node in groups:
        lines += shells_card(shells, part_id=part, first_id=first_id, first_node_id=first_node).splitlines()[1:]
    return "\n".join(lines)


def ids_where(nodes, mask):
    return [int(k) + 1 for k in np.flatnonzero(mask)]


def database(end_time, states=4, histories=20, nodes=None):
    cards = ["*DATABASE_GLSTAT\n" + fields(end_time / histories),
             "*DATABASE_MATSUM\n" + fields(end_time / histories),
             "*DATABASE_BINARY_D3PLOT\n" + fields(end_time / states)]
    if nodes:
        cards += ["*DATABASE_NODOUT\n" + fields(end_time / histories),
                  "*DATABASE_HISTORY_NODE\n" + fields(*nodes)]
    return "\n".join(cards)


# ---------------------------------------------------------------------------------------------
# The seeds. Units mm, ms, kg, kN, GPa. A 5 mm steel hexahedron has a stable step of about
# 8e-4 ms, so an end time of 0.08 ms is about 100 cycles.

def solid_elform1():
    nodes, elements = block_mesh((2, 1, 1), (10.0, 5.0, 5.0))
    fixed = ids_where(nodes, np.isclose(nodes[:, 0], 0.0))
    moving = ids_where(nodes, np.isclose(nodes[:, 0], 10.0))
    end = 0.08
    return deck_text(
        "*CONTROL_TERMINATION\n" + fields(end),
        SMALL_MODEL_STEP,
        "*CONTROL_HOURGLASS\n" + fields(1, 0.1),
        "*CONTROL_BULK_VISCOSITY\n" + fields(1.5, 0.06),
        "*CONTROL_ENERGY\n" + fields(2, 2),
        database(end, nodes=moving[:2]),
        "*PART\nbar\n" + fields(1, 1, 1, 0, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, *STEEL),
        "*HOURGLASS\n" + fields(1, 4, 0.1),
        node_list_set(1, fixed),
        node_list_set(2, moving),
        "*BOUNDARY_SPC_SET\n" + fields(1, 0, 1, 1, 1),
        "*INITIAL_VELOCITY\n" + fields(2) + "\n" + fields(2.0, 0.5, 0.0),
        nodes_card(nodes),
        solids_card(elements),
        title="one-point hexahedra: a bar clamped at one end, its other end kicked")


def solid_elform2_plastic():
    nodes, elements = block_mesh((2, 1, 1), (10.0, 5.0, 5.0))
    left = ids_where(nodes, np.isclose(nodes[:, 0], 0.0))
    right = ids_where(nodes, np.isclose(nodes[:, 0], 10.0))
    end = 0.1
    return deck_text(
        "*CONTROL_TERMINATION\n" + fields(end),
        database(end, nodes=right[:1]),
        "*PART\nbar\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 2),
        "*MAT_PLASTIC_KINEMATIC\n" + fields(1, 7.85e-6, 210.0, 0.3, 0.3, 2.0, 0.5) + "\n" + fields(40.0, 5.0, 0.0, 0.0),
        curve(1, [(0.0, 0.0), (0.02, 20.0), (1.0, 20.0)]),
        "*BOUNDARY_SPC_NODE\n" + "\n".join(fields(n, 0, 1, 1, 1) for n in left),
        "*BOUNDARY_PRESCRIBED_MOTION_NODE\n" + "\n".join(fields(n, 1, 0, 1, 1.0) for n in right),
        nodes_card(nodes),
        solids_card(elements),
        title="fully integrated hexahedra pulled into plasticity (Cowper-Symonds)")


def shell_cantilever():
    nodes, shells = plate_mesh((3, 1), (30.0, 10.0))
    root = ids_where(nodes, np.isclose(nodes[:, 0], 0.0))
    tip = ids_where(nodes, np.isclose(nodes[:, 0], 30.0))
    end = 0.3
    return deck_text(
        "*CONTROL_TERMINATION\n" + fields(end),
        "*CONTROL_TIMESTEP\n" + fields(0.0, 0.9),
        database(end, nodes=tip),
        "*PART\nstrip\n" + fields(1, 1, 1, 0, 1),
        "*SECTION_SHELL\n" + fields(1, 2, 0.8333, 3) + "\n" + fields(1.0, 1.0, 1.0, 1.0),
        "*MAT_ELASTIC\n" + fields(1, *STEEL),
        "*HOURGLASS\n" + fields(1, 4, 0.1),
        curve(1, [(0.0, 0.0), (0.1, 1.0), (10.0, 1.0)]),
        "*BOUNDARY_SPC_NODE\n" + "\n".join(fields(n, 0, 1, 1, 1, 1, 1, 1) for n in root),
        "*LOAD_NODE_POINT\n" + "\n".join(fields(n, 3, 1, 0.001) for n in tip),
        nodes_card(nodes),
        shells_card(shells[:2]),
        "*ELEMENT_SHELL_THICKNESS\n" + f"{3:8d}{1:8d}" + "".join(f"{c + 1:8d}" for c in shells[2]) + "\n" +
        "".join(f"{t:16.6e}" for t in (1.0, 1.1, 1.1, 1.0)),
        title="shell cantilever with a tip load")


def shell_plastic_tension():
    nodes, shells = plate_mesh((2, 1), (10.0, 5.0))
    left = ids_where(nodes, np.isclose(nodes[:, 0], 0.0))
    right = ids_where(nodes, np.isclose(nodes[:, 0], 10.0))
    # one more node and a triangle beside the strip
    nodes = np.vstack([nodes, [[15.0, 0.0, 0.0]]])
    extra = len(nodes)
    end = 0.2
    spc = ["*BOUNDARY_SPC_NODE"] + [fields(n, 0, 1, 1, 1, 1, 1, 1) for n in left]
    return deck_text(
        "*CONTROL_TERMINATION\n" + fields(end),
        database(end),
        "*PART\nstrip\n" + fields(1, 1, 1),
        "*SECTION_SHELL\n" + fields(1, 2, 1.0, 5) + "\n" + fields(1.0),
        "*MAT_PIECEWISE_LINEAR_PLASTICITY\n" + fields(1, 7.85e-6, 210.0, 0.3, 0.3, 0.0) + "\n" +
        fields(0.0, 0.0, 2) + "\n" + fields(0.0) + "\n" + fields(0.0),
        curve(1, [(0.0, 0.0), (0.05, 20.0), (1.0, 20.0)]),
        curve(2, [(0.0, 0.3), (0.1, 0.4), (1.0, 0.6)]),
        "\n".join(spc),
        "*BOUNDARY_PRESCRIBED_MOTION_NODE\n" + "\n".join(fields(n, 1, 0, 1, 1.0) for n in right),
        nodes_card(nodes),
        shells_card(shells) + "\n" + f"{3:8d}{1:8d}{right[0]:8d}{extra:8d}{right[1]:8d}",
        title="shell strip pulled into plasticity (LCSS curve), and a triangle")


def four_shells_kick():
    nodes, shells = plate_mesh((2, 2), (10.0, 10.0))
    end = 0.05
    return deck_text(
        "*CONTROL_TERMINATION\n" + fields(end),
        database(end, nodes=[5]),
        "*PART\nplate\n" + fields(1, 1, 1),
        "*SECTION_SHELL\n" + fields(1, 2, 0.8333, 3) + "\n" + fields(1.0),
        "*MAT_ELASTIC\n" + fields(1, *STEEL),
        nodes_card(nodes),
        shells_card(shells),
        "*INITIAL_VELOCITY_NODE\n" + fields(5, 0.0, 0.0, 1.0),
        title="four free shells, the middle node kicked")


def efg_block():
    nodes, elements = block_mesh((2, 2, 2), (6.0, 6.0, 6.0), perturbation=0.1, seed=3)
    velocity = ["*INITIAL_VELOCITY_NODE"] + [fields(k + 1, float(0.1 * x), float(-0.05 * z), 0.0)
                                             for k, (x, y, z) in enumerate(nodes)]
    end = 0.05
    return deck_text(
        "*CONTROL_TERMINATION\n" + fields(end),
        database(end),
        "*PART\nmeshfree\n" + fields(1, 1, 1),
        efg_section(1, 1.5),
        "*MAT_ELASTIC\n" + fields(1, *STEEL),
        nodes_card(nodes),
        solids_card(elements),
        "\n".join(velocity),
        title="meshfree (EFG) block in free vibration")


def efg_coupled_wall():
    nodes, elements = block_mesh((3, 2, 2), (9.0, 6.0, 6.0), origin=(0.0, 0.0, 0.2))
    centres = nodes[elements].mean(axis=1)
    meshfree = centres[:, 0] < 6.0
    end = 0.02
    return deck_text(
        "*CONTROL_TERMINATION\n" + fields(end),
        database(end),
        "*PART\nmeshfree\n" + fields(1, 1, 1, 0, 1),
        "*PART\nfinite elements\n" + fields(2, 2, 1, 0, 1),
        "*SECTION_SOLID\n" + fields(1, 41) + "\n" + fields(1.2, 1.2, 1.2, 0, 0, 3, 1, 0.0) + "\n" + fields(2, 1),
        "*HOURGLASS\n" + fields(1, 4, 0.1),
        "*MAT_PLASTIC_KINEMATIC\n" + fields(1, 7.85e-6, 200.0, 0.3, 0.4, 1.0, 1.0) + "\n" + fields(0.0, 0.0),
        "*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields(0.0, 0.0, -50.0),
        "*RIGIDWALL_PLANAR\n" + fields(0) + "\n" + fields(0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
        "*DATABASE_RWFORC\n" + fields(end / 20),
        nodes_card(nodes),
        merge_solids((elements[meshfree], 1, 1, 1), (elements[~meshfree], 2, 101, 1)),
        title="coupled EFG and FE block thrown on a rigid wall")


def rigid_pusher():
    nodes, elements = block_mesh((3, 1, 1), (15.0, 5.0, 5.0))
    rigid = nodes[elements].mean(axis=1)[:, 0] < 5.0
    end = 0.06
    return deck_text(
        "*CONTROL_TERMINATION\n" + fields(end),
        SMALL_MODEL_STEP,
        database(end),
        "*PART\nblock\n" + fields(1, 1, 1),
        "*PART\npusher\n" + fields(2, 1, 2),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, *STEEL),
        "*MAT_RIGID\n" + fields(2, *STEEL) + "\n" + fields(1.0, 0.0, 7.0),
        curve(1, [(0.0, 0.0), (0.02, 1.0), (10.0, 1.0)]),
        "*BOUNDARY_PRESCRIBED_MOTION_RIGID\n" + fields(2, 1, 0, 1, 5.0),
        nodes_card(nodes),
        merge_solids((elements[~rigid], 1, 1, 1), (elements[rigid], 2, 11, 1)),
        title="rigid part driven by a velocity curve pushes an elastic block")


def nodal_rigid_body():
    nodes, elements = block_mesh((2, 1, 1), (10.0, 5.0, 5.0))
    end_layer = ids_where(nodes, np.isclose(nodes[:, 0], 0.0))
    end = 0.08
    return deck_text(
        "*CONTROL_TERMINATION\n" + fields(end),
        SMALL_MODEL_STEP,
        database(end),
        "*PART\nbar\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, *STEEL),
        node_list_set(5, end_layer),
        "*CONSTRAINED_NODAL_RIGID_BODY\n" + fields(100, 0, 5),
        "*ELEMENT_MASS\n" + f"{1:8d}{end_layer[0]:8d}{0.001:16.6e}",
        "*INITIAL_VELOCITY_GENERATION\n" + fields(1, 2, 0.2, -2.0, 0.0, 0.0) + "\n" +
        fields(5.0, 2.5, 2.5, 0.0, 0.0, 1.0),
        nodes_card(nodes),
        solids_card(elements),
        title="end layer of a bar made a nodal rigid body with a lumped mass")


def rigid_spin():
    nodes, elements = block_mesh((1, 1, 1), (20.0, 30.0, 50.0))
    end = 0.5
    return deck_text(
        "*CONTROL_TERMINATION\n" + fields(end, 300),
        "*DATABASE_GLSTAT\n" + fields(0.01),
        "*PART\nblock\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_RIGID\n" + fields(1, *STEEL) + "\n" + fields(0.0, 0.0, 0.0) + "\n" + fields(0.0),
        nodes_card(nodes),
        solids_card(elements),
        "*INITIAL_VELOCITY_GENERATION\n" + fields(1, 2, 1.0, 1.0, 0.0, 0.0) + "\n" +
        fields(10.0, 15.0, 25.0, 1.0, 0.5, 0.3),
        title="a rigid block spinning about a non-principal axis")


def planar_walls():
    nodes, elements = block_mesh((2, 1, 1), (10.0, 5.0, 5.0), origin=(0.0, 0.0, 0.5))
    end = 0.05
    return deck_text(
        "*CONTROL_TERMINATION\n" + fields(end),
        SMALL_MODEL_STEP,
        database(end),
        "*DATABASE_RWFORC\n" + fields(end / 20),
        "*PART\nblock\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_PLASTIC_KINEMATIC\n" + fields(1, 7.85e-6, 200.0, 0.3, 0.3, 2.0, 1.0) + "\n" + fields(0.0, 0.0),
        "*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields(0.0, 0.0, -40.0),
        "*RIGIDWALL_PLANAR_FINITE_FORCES_ID\n" + fields(1) + "floor\n" + fields(0, 0, 0, 0.0) + "\n" +
        fields(-5.0, -5.0, 0.0, -5.0, -5.0, 1.0, 0.2) + "\n" + fields(20.0, -5.0, 0.0, 25.0, 15.0) + "\n" +
        fields(0, 0, 0, 0, 0, 0),
        "*RIGIDWALL_PLANAR_MOVING_ID\n" + fields(2) + "ram\n" + fields(0) + "\n" +
        fields(0.0, 0.0, 6.0, 0.0, 0.0, -1.0) + "\n" + fields(0.01, 20.0),
        nodes_card(nodes),
        solids_card(elements),
        title="block between a finite floor with friction and a moving ram")


def cylinder_wall():
    nodes, elements = block_mesh((2, 2, 1), (10.0, 10.0, 5.0))
    end = 0.05
    return deck_text(
        "*CONTROL_TERMINATION\n" + fields(end),
        SMALL_MODEL_STEP,
        database(end),
        "*DATABASE_RWFORC\n" + fields(end / 20),
        "*PART\nblock\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_PLASTIC_KINEMATIC\n" + fields(1, 7.85e-6, 200.0, 0.3, 0.4, 1.0, 1.0) + "\n" + fields(0.0, 0.0),
        curve(1, [(0.0, 50.0), (1.0, 50.0)]),
        "*RIGIDWALL_GEOMETRIC_CYLINDER_MOTION_ID\n" + fields(4) + "pusher\n" + fields(0) + "\n" +
        fields(-3.2, 5.0, -10.0, -3.2, 5.0, 20.0) + "\n" + fields(3.0, 30.0, 0) + "\n" + fields(1, 0, 1.0, 0.0, 0.0),
        "*RIGIDWALL_GEOMETRIC_CYLINDER\n" + fields(0) + "\n" + fields(14.0, 5.0, 0.0, 14.0, 5.0, 1.0) + "\n" +
        fields(2.0, 0.0, 0),
        nodes_card(nodes),
        solids_card(elements),
        title="a moving cylinder pushes a block towards a fixed post")


def contact_surface_to_surface():
    a_nodes, a_elements = block_mesh((1, 1, 1), (5.0, 5.0, 5.0))
    b_nodes, b_elements = block_mesh((1, 1, 1), (5.0, 5.0, 5.0), origin=(5.05, 0.0, 0.0))
    end = 0.03
    return deck_text(
        "*CONTROL_TERMINATION\n" + fields(end),
        SMALL_MODEL_STEP,
        database(end),
        "*DATABASE_RCFORC\n" + fields(end / 20),
        "*CONTROL_CONTACT\n" + fields(0.1),
        "*PART\nleft\n" + fields(1, 1, 1),
        "*PART\nright\n" + fields(2, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, 7.85e-6, 200.0, 0.3),
        node_list_set(1, list(range(1, 9))),
        node_list_set(2, list(range(9, 17))),
        "*INITIAL_VELOCITY\n" + fields(1) + "\n" + fields(10.0, 0.0, 0.0),
        "*INITIAL_VELOCITY\n" + fields(2) + "\n" + fields(-10.0, 0.0, 0.0),
        "*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE_ID\n" + fields(5) + "blocks\n" + fields(1, 2, 3, 3) + "\n" +
        fields(0.2, 0.1, 0.0, 0.0, 20.0, 0, 0.0, 0.0) + "\n" + fields(1.0, 1.0) + "\n" + fields(1, 0.1),
        nodes_card(np.vstack([a_nodes, b_nodes])),
        merge_solids((a_elements, 1, 1, 1), (b_elements, 2, 2, 9)),
        title="two blocks head on (surface to surface, soft constraint)")


def contact_nodes_to_surface():
    base_nodes, base_elements = block_mesh((2, 1, 1), (20.0, 10.0, 5.0), origin=(-5.0, 0.0, -5.0))
    slider_nodes, slider_elements = block_mesh((1, 1, 1), (5.0, 5.0, 5.0), origin=(0.0, 2.5, 0.05))
    count = len(base_nodes)
    # the two top faces of the base, counterclockwise seen from above
    def index(i, j):
        return (i * 2 + j) * 2 + 1 + 1
    segments = [fields(index(i, 0), index(i + 1, 0), index(i + 1, 1), index(i, 1)) for i in range(2)]
    end = 0.05
    return deck_text(
        "*CONTROL_TERMINATION\n" + fields(end),
        SMALL_MODEL_STEP,
        database(end),
        "*PART\nbase\n" + fields(1, 1, 1),
        "*PART\nslider\n" + fields(2, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, 7.85e-6, 200.0, 0.3),
        node_list_set(1, list(range(1, count + 1))),
        node_list_set(2, list(range(count + 1, count + 9))),
        "*BOUNDARY_SPC_SET\n" + fields(1, 0, 1, 1, 1),
        "*INITIAL_VELOCITY\n" + fields(2) + "\n" + fields(20.0, 0.0, -1.0),
        curve(1, [(0.0, 1.0), (10.0, 1.0)]),
        "*LOAD_NODE_SET\n" + fields(2, 3, 1, -1e-5),
        "*SET_SEGMENT\n" + fields(7) + "\n" + "\n".join(segments),
        "*CONTACT_AUTOMATIC_NODES_TO_SURFACE\n" + fields(2, 7, 4, 0) + "\n" + fields(0.3, 0.3, 0.0, 0.0, 20.0),
        "*CONTACT_AUTOMATIC_SINGLE_SURFACE\n" + fields(0, 0, 5),
        nodes_card(np.vstack([base_nodes, slider_nodes])),
        merge_solids((base_elements, 1, 1, 1), (slider_elements, 2, 3, count + 1)),
        title="a block sliding on a segment set (nodes to surface, single surface)")


def shell_contact():
    base_nodes, base_shells = plate_mesh((2, 2), (20.0, 20.0))
    drop_nodes, drop_shells = plate_mesh((1, 1), (8.0, 8.0))
    drop_nodes = drop_nodes + [6.3, 5.7, 2.3]
    count = len(base_nodes)
    end = 0.05
    return deck_text(
        "*CONTROL_TERMINATION\n" + fields(end),
        database(end),
        "*DATABASE_RCFORC\n" + fields(end / 20),
        "*PART\nbase\n" + fields(1, 1, 2),
        "*PART\ndrop\n" + fields(2, 1, 1),
        "*SECTION_SHELL\n" + fields(1, 2, 1.0, 3) + "\n" + fields(2.0, 2.0, 2.0, 2.0),
        "*MAT_ELASTIC\n" + fields(1, *STEEL),
        "*MAT_NULL\n" + fields(2, 7.85e-6, 0.0, 0.0, 0.0, 0.0, 210.0, 0.3),
        "*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE_ID\n" + fields(7) + "drop\n" + fields(2, 1, 3, 3) + "\n" +
        fields(0.0) + "\n" + fields(0.1, 0.1),
        "*BOUNDARY_SPC_NODE\n" + "\n".join(fields(k + 1, 0, 1, 1, 1, 1, 1, 1) for k in range(count)),
        nodes_card(np.vstack([base_nodes, drop_nodes])),
        merge_shells((base_shells, 1, 1, 1), (drop_shells, 2, 5, count + 1)),
        "*SET_NODE_LIST_GENERATE\n" + fields(2) + "\n" + fields(count + 1, count + len(drop_nodes)),
        "*INITIAL_VELOCITY\n" + fields(2) + "\n" + fields(0.0, 0.0, -10.0),
        title="a shell dropped on a null-shell plate")


def honeycomb(keyword):
    nodes, elements = block_mesh((1, 1, 2), (5.0, 5.0, 5.0))
    end = 0.05
    axes = (fields(0.1, 0.1, 0.1, 0.05, 0.05, 0.05, 2.0) + "\n" + fields(0.0, 0.0, 0.0, 0.0, 0.0, 1.0) + "\n" +
            fields(0.0, 1.0, 0.0))
    return deck_text(
        "*CONTROL_TERMINATION\n" + fields(end),
        database(end),
        "*DATABASE_RWFORC\n" + fields(end / 20),
        "*PART\nhoneycomb\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        f"*{keyword}\n" + fields(1, 5.0e-8, 1.0, 0.3, 1.0, 0.2, 0.0, 0.0) + "\n" + fields(10, 0, 0, 11) + "\n" + axes,
        curve(10, [(0.0, 0.001), (1.0, 0.001)]),
        curve(11, [(0.0, 0.0005), (1.0, 0.0007)]),
        "*RIGIDWALL_PLANAR_ID\n" + fields(2) + "floor\n" + fields(0) + "\n" + fields(0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
        "*RIGIDWALL_PLANAR_MOVING_ID\n" + fields(3) + "ram\n" + fields(0) + "\n" +
        fields(0.0, 0.0, 5.1, 0.0, 0.0, -1.0) + "\n" + fields(1.0, 20.0),
        nodes_card(nodes),
        solids_card(elements),
        title=f"{keyword.lower()} crushed by a heavy moving wall (AOPT 2 axes)")


def foam():
    nodes, elements = block_mesh((1, 1, 2), (5.0, 5.0, 5.0))
    end = 0.05
    return deck_text(
        "*CONTROL_TERMINATION\n" + fields(end),
        database(end),
        "*PART\nfoam\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_LOW_DENSITY_FOAM\n" + fields(1, 5.0e-8, 0.01, 10, 0.001, 0.2, 0.0, 0.1) + "\n" +
        fields(2.0, 0.0, 1),
        curve(10, [(0.0, 0.0), (0.5, 0.0005), (0.9, 0.01)]),
        "*RIGIDWALL_PLANAR\n" + fields(0) + "\n" + fields(0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
        "*RIGIDWALL_PLANAR_MOVING\n" + fields(0) + "\n" + fields(0.0, 0.0, 5.1, 0.0, 0.0, -1.0) + "\n" +
        fields(1.0, 20.0),
        nodes_card(nodes),
        solids_card(elements),
        title="low density foam crushed by a heavy moving wall")


def piecewise_solid():
    nodes, elements = block_mesh((2, 1, 1), (10.0, 5.0, 5.0))
    left = ids_where(nodes, np.isclose(nodes[:, 0], 0.0))
    right = ids_where(nodes, np.isclose(nodes[:, 0], 10.0))
    end = 0.1
    return deck_text(
        "*CONTROL_TERMINATION\n" + fields(end),
        SMALL_MODEL_STEP,
        database(end),
        "*PART\nbar\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_PIECEWISE_LINEAR_PLASTICITY\n" + fields(1, 7.85e-6, 210.0, 0.3, 0.25, 0.0) + "\n" +
        fields(0.0, 0.0, 2) + "\n" + fields(0.0) + "\n" + fields(0.0),
        curve(1, [(0.0, 0.0), (0.05, 1.0), (1.0, 1.0)], options=(0, 1.0, 20.0, 0.0, 0.0)),
        curve(2, [(0.0, 0.25), (0.1, 0.3), (1.0, 0.5)]),
        node_list_set(1, left),
        node_list_set(2, right),
        "*BOUNDARY_SPC_SET\n" + fields(1, 0, 1, 1, 1),
        "*BOUNDARY_PRESCRIBED_MOTION_SET\n" + fields(2, 1, 0, 1, 1.0),
        nodes_card(nodes),
        solids_card(elements),
        title="piecewise linear plasticity solids pulled by a node set")


def loads_explicit():
    nodes, elements = block_mesh((2, 1, 1), (10.0, 5.0, 5.0))
    left = ids_where(nodes, np.isclose(nodes[:, 0], 0.0))
    right = ids_where(nodes, np.isclose(nodes[:, 0], 10.0))
    # block_mesh numbering: index(i, j, k) = (i * 2 + j) * 2 + k, 1-based ids
    def node(i, j, k):
        return (i * 2 + j) * 2 + k + 1
    end_face = [node(2, 0, 0), node(2, 1, 0), node(2, 1, 1), node(2, 0, 1)]
    top_face = [node(0, 0, 1), node(1, 0, 1), node(1, 1, 1), node(0, 1, 1)]
    end = 0.08
    return deck_text(
        "*CONTROL_TERMINATION\n" + fields(end),
        SMALL_MODEL_STEP,
        database(end),
        "*PART\nbar\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, *STEEL),
        curve(1, [(0.0, 0.0), (0.02, 1.0), (10.0, 1.0)]),
        curve(2, [(0.0, 0.0), (1.0, 0.01)]),
        node_list_set(3, right),
        "*BOUNDARY_SPC_NODE\n" + "\n".join(fields(n, 0, 1, 1, 1) for n in left[:3]),
        "*BOUNDARY_PRESCRIBED_MOTION_NODE\n" + fields(left[3], 1, 2, 2, 1.0, 0, 0.06, 0.01) + "\n" +
        fields(left[3], 2, 1, 1, 0.1),
        "*LOAD_SEGMENT\n" + fields(1, 0.01, 0.0, *end_face),
        "*SET_SEGMENT\n" + fields(4) + "\n" + fields(*top_face),
        "*LOAD_SEGMENT_SET\n" + fields(4, 1, 0.005, 0.01),
        "*LOAD_SEGMENT_NONUNIFORM_ID\n" + fields(9) + "side\n" + fields(1, 0.01, 0.0, 0.0, 0, 0.0, 1.0, 1.0) + "\n" +
        fields(*end_face) + "\n" + fields(1.0, 2.0, 2.0, 1.0),
        "*LOAD_NODE_SET\n" + fields(3, 3, 1, 0.001),
        "*LOAD_NODE_POINT\n" + fields(right[0], 2, 2, 1.0),
        nodes_card(nodes),
        solids_card(elements),
        title="segment, set and node loads with curves; prescribed displacement and acceleration")


def parameter_include():
    nodes, elements = block_mesh((2, 1, 1), (10.0, 5.0, 5.0))
    main = deck_text(
        "*PARAMETER\n" + "R tend    " + f"{0.08:>10}" + "I one     " + f"{1:>10}" + "R young   " + f"{210.0:>10}" +
        "R speed   " + f"{-3.0:>10}" + "\nCmesh,include/parameter_include_mesh.k",
        "*CONTROL_TERMINATION\n" + fields("&tend"),
        SMALL_MODEL_STEP,
        "*DATABASE_GLSTAT\n" + fields(0.004),
        "*PART\nbar\n" + fields("&one", "&one", "&one"),
        "*SECTION_SOLID\n" + fields("&one", 2),
        "*MAT_ELASTIC\n" + fields("&one", 7.85e-6, "&young", 0.3),
        "*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields("-&speed", 0.0, "&speed"),
        "*INCLUDE\n&mesh",
        title="parameters and an include file")
    mesh = "*KEYWORD\n" + nodes_card(nodes) + "\n" + solids_card(elements) + "\n*END\n"
    return main, {"include/parameter_include_mesh.k": mesh}


def static_linear():
    nodes, elements = block_mesh((2, 1, 1), (10.0, 5.0, 5.0))
    left = ids_where(nodes, np.isclose(nodes[:, 0], 0.0))
    def node(i, j, k):
        return (i * 2 + j) * 2 + k + 1
    end_face = [node(2, 0, 0), node(2, 1, 0), node(2, 1, 1), node(2, 0, 1)]
    return deck_text(
        "*CONTROL_IMPLICIT_GENERAL\n" + fields(1, 1.0),
        "*CONTROL_IMPLICIT_SOLUTION\n" + fields(1),
        "*CONTROL_TERMINATION\n" + fields(1.0),
        "*PART\nbar\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 2),
        "*MAT_ELASTIC\n" + fields(1, *STEEL),
        curve(1, [(0.0, 1.0), (10.0, 1.0)]),
        "*BOUNDARY_SPC_NODE\n" + "\n".join(fields(n, 0, 1, 1, 1) for n in left),
        "*SET_SEGMENT\n" + fields(3) + "\n" + fields(*end_face),
        "*LOAD_SEGMENT_SET\n" + fields(3, 1, 0.1),
        "*LOAD_NODE_POINT\n" + fields(end_face[0], 3, 1, 0.5),
        nodes_card(nodes),
        solids_card(elements),
        title="linear static analysis of a clamped bar under an end pressure")


def static_efg():
    nodes, elements = block_mesh((2, 2, 2), (4.0, 4.0, 4.0))
    left = ids_where(nodes, np.isclose(nodes[:, 0], 0.0))
    right_face = []
    def node(i, j, k):
        return (i * 3 + j) * 3 + k + 1
    for j in range(2):
        for k in range(2):
            right_face.append([node(2, j, k), node(2, j + 1, k), node(2, j + 1, k + 1), node(2, j, k + 1)])
    loads = []
    for segment in right_face:
        loads += ["*LOAD_SEGMENT_NONUNIFORM", fields(1, 1.0, 0.0, 0.0, 0, 0.0, 1.0, 0.0), fields(*segment),
                  fields(0.01, 0.01, 0.02, 0.02)]
    return deck_text(
        "*CONTROL_IMPLICIT_GENERAL\n" + fields(1),
        "*CONTROL_TERMINATION\n" + fields(1.0),
        "*PART\nmeshfree\n" + fields(1, 1, 1),
        efg_section(1, 1.5),
        "*MAT_ELASTIC\n" + fields(1, *STEEL),
        curve(1, [(0.0, 1.0), (10.0, 1.0)]),
        "*BOUNDARY_SPC_NODE\n" + "\n".join(fields(n, 0, 1, 1, 1) for n in left),
        "\n".join(loads),
        nodes_card(nodes),
        solids_card(elements),
        title="linear static analysis of a meshfree block under a shear traction")


def free_format_generation():
    nodes, elements = block_mesh((2, 1, 1), (10.0, 5.0, 5.0))
    node_lines = ["*NODE+"] + [f"{k + 1:20d}{x:20.12e}{y:20.12e}{z:20.12e}" for k, (x, y, z) in enumerate(nodes)]
    element_lines = ["*ELEMENT_SOLID"] + [",".join(str(v) for v in [k + 1, 1 + (k % 2)] + [c + 1 for c in row])
                                          for k, row in enumerate(elements)]
    end = 0.08
    return deck_text(
        "*CONTROL_TERMINATION\n0.08,0",
        "*CONTROL_TIMESTEP\n0.0,0.6",
        "*DATABASE_GLSTAT\n" + f"{end / 20}",
        "*DATABASE_BINARY_D3PLOT\n" + f"{end / 4},0,0,0",
        "*PART\nleft half\n1,1,1\n*PART\nright half\n2,1,2",
        "*SECTION_SOLID\n1,1,0",
        "*MAT_ELASTIC\n1,7.85e-6,210.0,0.3\n2,2.7e-6,70.0,0.33",
        "*SET_PART_LIST\n1\n1,2",
        "*SET_NODE_LIST_GENERATE\n2\n1,4,9,12",
        "*BOUNDARY_SPC_SET\n2,0,0,1,1",
        "*INITIAL_VELOCITY_GENERATION\n1,1,0.5,1.0,0.0,0.0\n5.0,2.5,2.5,0.0,0.0,1.0",
        "\n".join(node_lines),
        "\n".join(element_lines),
        title="free format cards, a long format *NODE+, sets made by generation")


def mass_scaling_endcyc():
    nodes, elements = block_mesh((2, 1, 1), (10.0, 5.0, 5.0))
    return deck_text(
        "*CONTROL_TERMINATION\n" + fields(0.0, 150),
        "*CONTROL_TIMESTEP\n" + fields(0.0, 0.6, None, None, -0.0015),
        "*DATABASE_GLSTAT\n" + fields(0.005),
        "*PART\nbar\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, *STEEL),
        "*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields(0.0, 1.0, 0.0),
        "*INITIAL_VELOCITY_NODE\n" + fields(1, -1.0, 0.0, 0.0),
        nodes_card(nodes),
        solids_card(elements),
        title="mass scaling (DT2MS < 0) and a run ended by ENDCYC")


SEEDS = {
    "solid_elform1": solid_elform1,
    "solid_elform2_plastic": solid_elform2_plastic,
    "shell_cantilever": shell_cantilever,
    "shell_plastic_tension": shell_plastic_tension,
    "four_shells_kick": four_shells_kick,
    "efg_block": efg_block,
    "efg_coupled_wall": efg_coupled_wall,
    "rigid_pusher": rigid_pusher,
    "nodal_rigid_body": nodal_rigid_body,
    "rigid_spin": rigid_spin,
    "planar_walls": planar_walls,
    "cylinder_wall": cylinder_wall,
    "contact_surface_to_surface": contact_surface_to_surface,
    "contact_nodes_to_surface": contact_nodes_to_surface,
    "shell_contact": shell_contact,
    "honeycomb": lambda: honeycomb("MAT_HONEYCOMB"),
    "modified_honeycomb": lambda: honeycomb("MAT_MODIFIED_HONEYCOMB"),
    "low_density_foam": foam,
    "piecewise_solid": piecewise_solid,
    "loads_explicit": loads_explicit,
    "parameter_include": parameter_include,
    "static_linear": static_linear,
    "static_efg": static_efg,
    "free_format_generation": free_format_generation,
    "mass_scaling_endcyc": mass_scaling_endcyc,
}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=HERE / "seeds")
    arguments = parser.parse_args()
    arguments.out.mkdir(parents=True, exist_ok=True)
    for name, make in SEEDS.items():
        made = make()
        main_text, includes = (made if isinstance(made, tuple) else (made, {}))
        (arguments.out / f"{name}.k").write_text(main_text)
        for relative, text in includes.items():
            path = arguments.out / relative
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text)
    print(f"{len(SEEDS)} seeds in {arguments.out}")


if __name__ == "__main__":
    main()
