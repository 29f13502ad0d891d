"""Beam elements (*SECTION_BEAM ELFORM 1 Hughes-Liu, 9 spot weld beam) and *MAT_SPOTWELD, each
against an analytical value (units mm, ms, kg, kN, GPa; steel):

a. a cantilever under a slowly applied tip load: tip deflection against Timoshenko's beam and
   the exact answer of the one-point element, root shear force and moment against statics;
b. a rod under a suddenly applied end force: the mean end displacement F L / (E A) and the
   period 4 L / c of its motion (the axial wave speed);
c. a tube twisted by a torque: twist angle T L / (G J);
d. a free beam spinning in its plane: angular momentum and energy conserved;
e. a spot weld beam between two masses pulled apart by a force ramp: it fails within one time
   step of the moment the force reaches NRR (*MAT_SPOTWELD's resultant criterion), and by TFAIL
   and EFAIL;
f. 1 and 2 threads bit-identical; a restart bit-identical to the uninterrupted run;
g. decks with beam features crashfree does not have are refused with a clear message.
"""
import h5py
import re

import numpy as np
import pytest

from deck_writer import fields, nodes_card, write_deck
from test_restart import assert_same, contents, copy_run, restart, run_fresh
from test_threads import assert_identical_results, run_on_threads

DENSITY, YOUNGS, POISSON = 7.85e-6, 210.0, 0.3
SHEAR = YOUNGS / (2.0 * (1.0 + POISSON))
SOUND_SPEED = np.sqrt(YOUNGS / DENSITY)


def beams_card(pairs, part_id=1, first_id=1, orientation=0):
    """*ELEMENT_BEAM: EID PID N1 N2 N3, node ids as given."""
    lines = ["*ELEMENT_BEAM"]
    for k, (first, second) in enumerate(pairs):
        lines.append(f"{k + first_id:8d}{part_id:8d}{first:8d}{second:8d}{orientation:8d}")
    return "\n".join(lines)


def curve_card(curve_id, points):
    return "\n".join(["*DEFINE_CURVE", fields(curve_id)] + [fields(float(a), float(b), width=20) for a, b in points])


def smooth_ramp(rise_time, end_time, points=81):
    """0 -> 1 as a half cosine over `rise_time`, then 1."""
    return [(t, 0.5 * (1.0 - np.cos(np.pi * t / rise_time))) for t in np.linspace(0.0, rise_time, points)] + \
           [(end_time, 1.0)]


def history(results, node_id, name="displacement"):
    group = results[f"history/nodout/{node_id}"]
    return group["time"][...], group[name][...]


def last_state(results):
    return results["states"][sorted(results["states"].keys())[-1]]


# ---------------------------------------------------------------------------------------------
# a. cantilever

CANTILEVER_ELEMENTS, CANTILEVER_LENGTH, CANTILEVER_SIDE, TIP_LOAD = 10, 100.0, 10.0, 0.1
SHEAR_FACTOR = 5.0 / 6.0


def cantilever_deck(path, end_time=26.0, rise_time=18.0, formulation=1):
    """A 100 mm steel beam of 10 x 10 mm section (2 x 2 Gauss points, SHRF 5/6), ten elements
    along x, clamped at x = 0 (all six dofs); the tip load along z rises as a half cosine over
    18 ms, fifteen periods of the first bending mode (1.2 ms), and is then held. With
    `formulation` 2 the same section as a resultant beam: A, ISS = ITT = s^4/12, J blank."""
    n = CANTILEVER_ELEMENTS
    nodes = np.zeros((n + 2, 3))
    nodes[:n + 1, 0] = np.linspace(0.0, CANTILEVER_LENGTH, n + 1)
    nodes[n + 1] = [0.0, 10.0, 0.0]               # orientation node: s along y, t along z
    side = CANTILEVER_SIDE
    section_card = fields(*[side] * 4) if formulation == 1 else fields(side ** 2, side ** 4 / 12, side ** 4 / 12)
    return write_deck(
        path, "*TITLE\ncantilever",
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_GLSTAT\n" + fields(0.1),
        "*DATABASE_BINARY_D3PLOT\n" + fields(end_time / 4),
        "*DATABASE_NODOUT\n" + fields(0.01),
        "*DATABASE_HISTORY_NODE\n" + fields(n + 1),
        "*PART\ncantilever\n" + fields(1, 1, 1),
        "*SECTION_BEAM\n" + fields(1, formulation, SHEAR_FACTOR, 2, 0) + "\n" + section_card,
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
        nodes_card(nodes),
        beams_card([(k + 1, k + 2) for k in range(n)], orientation=n + 2),
        "*BOUNDARY_SPC_NODE\n" + fields(1, 0, 1, 1, 1, 1, 1, 1) + "\n" + fields(n + 2, 0, 1, 1, 1),
        curve_card(1, smooth_ramp(rise_time, 100.0)),
        "*LOAD_NODE_POINT\n" + fields(n + 1, 3, 1, TIP_LOAD))


@pytest.mark.parametrize("formulation", [1, 2])
def test_cantilever_tip_deflection_matches_timoshenko(tmp_path, run_deck, formulation):
    """Static tip deflection of a cantilever: Timoshenko's P L^3 / (3 E I) + P L / (k G A).

    The element has one point along its length (no shear locking); on n elements it is exact
    for the shear term and gives P L^3 / (3 E I) (1 - 1 / (4 n^2)) for bending (the element's
    linear stiffness, assembled and solved, gives the same), 0.25% below the continuum for
    n = 10. The load is held after a ramp of fifteen bending periods: the mean over the last
    8 ms (6.7 periods) is the static deflection within 1e-4 (the ringing left by the smooth ramp
    is a few 1e-5 of it). Tolerances: 2e-4 against the element's exact answer (the tip rotation,
    2.9e-3 rad, adds geometric effects of order 1e-5), 0.4% against the continuum. The root
    element's resultants: shear P, moment P (L - l/2) at its mid-length point, within 0.5%.
    The resultant beam (ELFORM 2) has the same kinematics and the same answer."""
    run = run_deck(cantilever_deck(tmp_path / "cantilever.k", formulation=formulation))
    assert run.status == 0, run.stdout + run.stderr
    n, length, side = CANTILEVER_ELEMENTS, CANTILEVER_LENGTH, CANTILEVER_SIDE
    inertia, area = side ** 4 / 12.0, side ** 2
    bending = TIP_LOAD * length ** 3 / (3.0 * YOUNGS * inertia)
    shear = TIP_LOAD * length / (SHEAR_FACTOR * SHEAR * area)
    element_exact = bending * (1.0 - 1.0 / (4.0 * n ** 2)) + shear
    with run.open() as results:
        time, displacement = history(results, n + 1)
        held = time > 18.0
        deflection = displacement[held, 2].mean()
        resultant = last_state(results)["beam_resultant"][...]
    assert abs(deflection / element_exact - 1.0) < 2e-4, (deflection, element_exact)
    assert abs(deflection / (bending + shear) - 1.0) < 4e-3, (deflection, bending + shear)
    # root element: N, Q_s, Q_t, T, M_s, M_t in its local axes (s = y, t = z)
    root = resultant[:, 0] if resultant.shape[0] == 6 else resultant[0, :]
    assert abs(abs(root[2]) / TIP_LOAD - 1.0) < 5e-3, root
    assert abs(abs(root[4]) / (TIP_LOAD * (length - length / n / 2.0)) - 1.0) < 5e-3, root
    assert abs(root[0]) < 1e-3 * TIP_LOAD and abs(root[1]) < 1e-3 * TIP_LOAD and abs(root[3]) < 1e-3 * TIP_LOAD


# ---------------------------------------------------------------------------------------------
# b. axial wave

ROD_ELEMENTS, ROD_LENGTH, ROD_SIDE, END_FORCE = 20, 100.0, 4.0, 1.0


def rod_deck(path, end_time):
    n = ROD_ELEMENTS
    nodes = np.zeros((n + 1, 3))
    nodes[:, 0] = np.linspace(0.0, ROD_LENGTH, n + 1)
    return write_deck(
        path, "*TITLE\nrod under a step load",
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_NODOUT\n" + fields(1e-4),
        "*DATABASE_HISTORY_NODE\n" + fields(n + 1),
        "*PART\nrod\n" + fields(1, 1, 1),
        "*SECTION_BEAM\n" + fields(1, 0, 0.0, 0, 0) + "\n" + fields(ROD_SIDE, ROD_SIDE, ROD_SIDE, ROD_SIDE),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
        nodes_card(nodes),
        beams_card([(k + 1, k + 2) for k in range(n)]),
        "*BOUNDARY_SPC_NODE\n" + fields(1, 0, 1, 1, 1, 1, 1, 1),
        curve_card(1, [(0.0, 1.0), (100.0, 1.0)]),
        "*LOAD_NODE_POINT\n" + fields(n + 1, 1, 1, END_FORCE))


def test_axial_step_load_gives_stiffness_and_wave_speed(tmp_path, run_deck):
    """A rod fixed at one end, a force applied at once at the other (ELFORM and SHRF blank:
    LS-DYNA's defaults 1 and 1.0). The end moves as a triangle wave between 0 and
    2 F L / (E A) with period 4 L / c: its mean over whole periods is F L / (E A) and it crosses
    that mean every 2 L / c. On 20 lumped-mass elements the first period is 4 L / c within
    3e-4 (the chain's frequency (2 c / l) sin(pi / 4n)); the corners of the triangle are
    rounded by the mesh's dispersion but the crossings of the mean stay put. Tolerances: 1%
    for the mean (sampling of the triangle at 1e-4 ms, 1/770 of a period), 1% for the period."""
    period = 4.0 * ROD_LENGTH / SOUND_SPEED
    run = run_deck(rod_deck(tmp_path / "rod.k", 3.2 * period))
    assert run.status == 0, run.stdout + run.stderr
    static = END_FORCE * ROD_LENGTH / (YOUNGS * ROD_SIDE ** 2)
    with run.open() as results:
        time, displacement = history(results, ROD_ELEMENTS + 1)
    motion = displacement[:, 0]
    whole = time <= 3.0 * period
    mean = np.trapezoid(motion[whole], time[whole]) / time[whole][-1]
    assert abs(mean / static - 1.0) < 1e-2, (mean, static)
    above = motion - static > 0.0
    crossings = time[1:][above[1:] != above[:-1]]
    assert len(crossings) >= 5, crossings
    measured = crossings[4] - crossings[2]
    assert abs(measured / period - 1.0) < 1e-2, (measured, period)
    assert abs(motion.max() / (2.0 * static) - 1.0) < 0.1


# ---------------------------------------------------------------------------------------------
# c. torsion of a tube

TUBE_ELEMENTS, TUBE_LENGTH, TUBE_DIAMETER, TUBE_WALL = 10, 100.0, 20.0, 2.0
ARM, ARM_FORCE, ARM_SIDE = 20.0, 0.5, 20.0


def tube_deck(path, end_time=4.5, rise_time=3.0, formulation=1):
    """A tube (CST 1, QR 2: 8 angles x 2 radii) along x, clamped at x = 0; at the free end two
    arms (part 2: one beam each, 20 x 20 mm, same steel) reach to y = +-20 and are pushed along
    +-z with forces F: a torque 2 a F about x, raised as a half cosine over 3 ms (25 torsion
    periods), then held. With `formulation` 2 the tube is a resultant beam with its A, I and J."""
    n = TUBE_ELEMENTS
    outer, inner = TUBE_DIAMETER / 2.0, TUBE_DIAMETER / 2.0 - TUBE_WALL
    polar = np.pi / 2.0 * (outer ** 4 - inner ** 4)
    if formulation == 1:
        tube_section = fields(1, 1, 1.0, 2, 1) + "\n" + fields(TUBE_DIAMETER, TUBE_DIAMETER, TUBE_WALL, TUBE_WALL)
    else:
        tube_section = fields(1, 2, 1.0) + "\n" + fields(np.pi * (outer ** 2 - inner ** 2), polar / 2, polar / 2, polar)
    nodes = np.zeros((n + 3, 3))
    nodes[:n + 1, 0] = np.linspace(0.0, TUBE_LENGTH, n + 1)
    nodes[n + 1] = [TUBE_LENGTH, ARM, 0.0]
    nodes[n + 2] = [TUBE_LENGTH, -ARM, 0.0]
    first_arm, second_arm = n + 2, n + 3
    return write_deck(
        path, "*TITLE\ntube in torsion",
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_NODOUT\n" + fields(0.01),
        "*DATABASE_HISTORY_NODE\n" + fields(first_arm, second_arm),
        "*PART\ntube\n" + fields(1, 1, 1),
        "*SECTION_BEAM\n" + tube_section,
        "*PART\narms\n" + fields(2, 2, 1),
        "*SECTION_BEAM\n" + fields(2, 1, SHEAR_FACTOR, 2, 0) + "\n" + fields(*[ARM_SIDE] * 4),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
        nodes_card(nodes),
        beams_card([(k + 1, k + 2) for k in range(n)]),
        beams_card([(n + 1, first_arm), (n + 1, second_arm)], part_id=2, first_id=n + 1),
        "*BOUNDARY_SPC_NODE\n" + fields(1, 0, 1, 1, 1, 1, 1, 1),
        curve_card(1, smooth_ramp(rise_time, 100.0)),
        "*LOAD_NODE_POINT\n" + fields(first_arm, 3, 1, ARM_FORCE) + "\n" + fields(second_arm, 3, 1, -ARM_FORCE))


@pytest.mark.parametrize("formulation", [1, 2])
def test_tube_twist_matches_saint_venant(tmp_path, run_deck, formulation):
    """Twist of a thick tube: T L / (G J), J = pi/2 (r_o^4 - r_i^4) (the section's points,
    Gauss in the radius, integrate J exactly). The twist is read from the arms' ends: their
    difference along z over 2 a, less each arm's own bending, F a^3 / (4 E I) + F a / (k G A)
    for one element (1.4% of the end's motion). Mean over the last 1.5 ms (12 periods) after
    the ramp; tolerance 0.5%. The resultant beam (ELFORM 2) given that J: the same."""
    run = run_deck(tube_deck(tmp_path / "tube.k", formulation=formulation))
    assert run.status == 0, run.stdout + run.stderr
    outer, inner = TUBE_DIAMETER / 2.0, TUBE_DIAMETER / 2.0 - TUBE_WALL
    polar = np.pi / 2.0 * (outer ** 4 - inner ** 4)
    expected = 2.0 * ARM * ARM_FORCE * TUBE_LENGTH / (SHEAR * polar)
    arm_bending = ARM_FORCE * ARM ** 3 / (4.0 * YOUNGS * ARM_SIDE ** 4 / 12.0) + \
        ARM_FORCE * ARM / (SHEAR_FACTOR * SHEAR * ARM_SIDE ** 2)
    with run.open() as results:
        time, first = history(results, TUBE_ELEMENTS + 2)
        _, second = history(results, TUBE_ELEMENTS + 3)
    held = time > 3.0
    twist = np.arcsin((0.5 * (first[held, 2] - second[held, 2]) - arm_bending) / ARM).mean()
    assert abs(twist / expected - 1.0) < 5e-3, (twist, expected)


# ---------------------------------------------------------------------------------------------
# d. spinning free beam

SPIN_ELEMENTS, SPIN_LENGTH, SPIN_RATE, SPIN_SIDE = 40, 100.0, 1.0, 2.0


def spinning_deck(path, end_time=1.5, dump_cycles=0, parts=1):
    """A free beam along x through the origin, 40 elements of 5 x 5 mm (3 x 3 Gauss points,
    *MAT_PLASTIC_KINEMATIC, elastic at these strains), spinning about z at 1 rad/ms
    (*INITIAL_VELOCITY_GENERATION over a part set; the nodes' rotations start at rest, so the
    beam starts to bend and stretch: the motion is not a rigid one). With `parts` 2 the second
    half is another part (two blocks sharing the middle node)."""
    n = SPIN_ELEMENTS
    nodes = np.zeros((n + 1, 3))
    nodes[:, 0] = np.linspace(-SPIN_LENGTH / 2, SPIN_LENGTH / 2, n + 1)
    half = n // 2 if parts == 2 else n
    history_nodes = "\n".join(fields(*range(k + 1, min(k + 9, n + 2))) for k in range(0, n + 1, 8))
    blocks = [
        "*TITLE\nspinning beam", "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_GLSTAT\n" + fields(0.01),
        "*DATABASE_MATSUM\n" + fields(0.05),
        "*DATABASE_NODOUT\n" + fields(0.05),
        "*DATABASE_HISTORY_NODE\n" + history_nodes,
        "*DATABASE_BINARY_D3PLOT\n" + fields(end_time / 5),
        "*SECTION_BEAM\n" + fields(1, 1, 0.0, 3, 0) + "\n" + fields(*[SPIN_SIDE] * 4),
        "*MAT_PLASTIC_KINEMATIC\n" + fields(1, DENSITY, YOUNGS, POISSON, 0.5, 1.0, 1.0) + "\n" + fields(0.0, 0.0),
        nodes_card(nodes),
        "*INITIAL_VELOCITY_GENERATION\n" + fields(1, 1, SPIN_RATE, 0.0, 0.0, 0.0) + "\n" +
        fields(0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
        "*PART\nbeam\n" + fields(1, 1, 1),
        beams_card([(k + 1, k + 2) for k in range(half)]),
    ]
    if parts == 2:
        blocks.append("*PART\nbeam end\n" + fields(2, 1, 1))
        blocks.append(beams_card([(k + 1, k + 2) for k in range(half, n)], part_id=2, first_id=half + 1))
        blocks.append("*SET_PART_LIST\n" + fields(1) + "\n" + fields(1, 2))
    else:
        blocks.append("*SET_PART_LIST\n" + fields(1) + "\n" + fields(1))
    if dump_cycles:
        blocks.append("*DATABASE_BINARY_D3DUMP\n" + fields(dump_cycles))
    return write_deck(path, *blocks)


def test_spinning_beam_conserves_angular_momentum_and_energy(tmp_path, run_deck):
    """The total energy (glstat, with the rotary inertias' kinetic energy) stays within 1e-3 of
    the initial kinetic energy (the element's internal energy is the exact work of its nodal
    forces, so the balance closes to rounding: 2e-15 measured). The angular momentum about z of the nodal masses,
    sum m (x v_y - y v_x), stays within 2e-3 of the initial one: the part the nodes' rotary
    inertias take (they start at rest and spin up to the beam's rate, about which they swing
    with its bending vibration) is not in the nodal output; sum J Omega is 8e-4 of the total
    here, and the swing about doubles it (measured: 1.5e-3)."""
    run = run_deck(spinning_deck(tmp_path / "spin.k"))
    assert run.status == 0, run.stdout + run.stderr
    n = SPIN_ELEMENTS
    element = SPIN_LENGTH / n
    area = SPIN_SIDE ** 2
    mass = np.full(n + 1, DENSITY * area * element)
    mass[[0, -1]] /= 2.0
    with run.open() as results:
        glstat = {name: results["history/glstat"][name][...] for name in results["history/glstat"]}
        momentum = None
        for k in range(n + 1):
            time, position = history(results, k + 1)
            _, velocity = history(results, k + 1, "velocity")
            x = np.linspace(-SPIN_LENGTH / 2, SPIN_LENGTH / 2, n + 1)[k] + position[:, 0]
            y = position[:, 1]
            term = mass[k] * (x * velocity[:, 1] - y * velocity[:, 0])
            momentum = term if momentum is None else momentum + term
    initial_energy = glstat["kinetic_energy"][0]
    assert initial_energy > 0.0
    drift = np.abs(glstat["total_energy"] - glstat["total_energy"][0]).max()
    assert drift < 1e-3 * initial_energy, (drift, initial_energy)
    assert glstat["internal_energy"].max() > 1e-4 * initial_energy     # the beam did deform
    assert np.abs(momentum / momentum[0] - 1.0).max() < 2e-3, momentum


# ---------------------------------------------------------------------------------------------
# e. spot weld failure

WELD_LENGTH, WELD_DIAMETER, WELD_MASS = 2.0, 5.0, 1e-3
FAILURE_FORCE, FORCE_RATE, FORCE_START = 5.0, 20.0, 0.2


def weld_deck(path, failure_card, end_time=0.6, material_extra=None):
    """A spot weld beam (ELFORM 9, solid circular section of 5 mm, CST 1 with TT 0) along z
    between two nodes of 1 g each (*ELEMENT_MASS), free in space; equal and opposite forces
    along the axis pull them apart: smooth start over 0.2 ms (about 60 periods of the
    mass-weld-mass oscillator), then F(t) = 20 (t - 0.1) kN, the straight line it joins."""
    nodes = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, WELD_LENGTH]])
    # F' rises as a half cosine to FORCE_RATE over FORCE_START: F = k (t - T/pi sin(pi t/T)) / 2
    rise = [(t, FORCE_RATE * 0.5 * (t - FORCE_START / np.pi * np.sin(np.pi * t / FORCE_START)))
            for t in np.linspace(0.0, FORCE_START, 161)]
    rise.append((10.0, FORCE_RATE * (10.0 - FORCE_START / 2.0)))
    material = material_extra or ("*MAT_SPOTWELD\n" + fields(1, DENSITY, YOUNGS, POISSON, 2.0, 0.0, 0.0, 0.0) +
                                  "\n" + failure_card)
    return write_deck(
        path, "*TITLE\nspot weld pulled apart",
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_NODOUT\n" + fields(1e-5),
        "*DATABASE_HISTORY_NODE\n" + fields(2),
        "*DATABASE_BINARY_D3PLOT\n" + fields(end_time / 4),
        "*PART\nweld\n" + fields(1, 1, 1),
        "*SECTION_BEAM\n" + fields(1, 9, 0.0, 2, 1) + "\n" + fields(WELD_DIAMETER, WELD_DIAMETER, 0.0, 0.0),
        material,
        nodes_card(nodes),
        beams_card([(1, 2)]),
        "*ELEMENT_MASS\n" + f"{1:8d}{1:8d}{WELD_MASS:16.6e}\n" + f"{2:8d}{2:8d}{WELD_MASS:16.6e}",
        curve_card(1, rise),
        "*LOAD_NODE_POINT\n" + fields(2, 3, 1, 1.0) + "\n" + fields(1, 3, 1, -1.0))


def failure_time_of(results):
    """The first nodout sample of node 2 whose acceleration is more than half the free one
    F/m: the weld no longer holds it. Returns (time, time step)."""
    time, acceleration = history(results, 2, "acceleration")
    force = FORCE_RATE * (time - FORCE_START / 2.0)
    free = np.flatnonzero((acceleration[:, 2] > 0.5 * force / (WELD_MASS + DENSITY * np.pi * 6.25 * WELD_LENGTH / 2))
                          & (time > FORCE_START))
    step = results["history/glstat/time_step"][...].max() if "history/glstat" in results else np.diff(time).max()
    return (time[free[0]] if len(free) else None), step


@pytest.mark.parametrize("criterion", ["resultant", "time"])
def test_spot_weld_fails_when_the_force_reaches_nrr(tmp_path, run_deck, criterion):
    """Resultant criterion with NRR only: (N/NRR)^2 >= 1, i.e. N = NRR = 5 kN, reached when
    F(t) = 5, t = 0.35 ms (the weld's axial force follows F exactly for a linear ramp once the
    smooth start's ringing has died: a few 1e-5 ms here). TFAIL = 0.3 ms fails it at 0.3 ms.
    The acceleration of the pulled mass jumps from ~0 to F/m in the cycle of failure: found
    within one time step (0.3 us) of the analytical time. The results mark the beam failed."""
    if criterion == "resultant":
        card = fields(0.0, FAILURE_FORCE, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        expected = FAILURE_FORCE / FORCE_RATE + FORCE_START / 2.0
    else:
        card = fields(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        expected = 0.3
    deck = weld_deck(tmp_path / "weld.k", card)
    if criterion == "time":
        deck.write_text(deck.read_text().replace(fields(1, DENSITY, YOUNGS, POISSON, 2.0, 0.0, 0.0, 0.0),
                                                 fields(1, DENSITY, YOUNGS, POISSON, 2.0, 0.0, 0.0, 0.3)))
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        time, acceleration = history(results, 2, "acceleration")
        steps = np.diff(time)
        failed_at, _ = failure_time_of(results)
        failed = last_state(results)["beam_failed"][...]
        assert results["timing"].attrs["failed_beams"] == 1
    step = 0.9 * WELD_LENGTH / SOUND_SPEED
    assert failed_at is not None
    assert abs(failed_at - expected) <= step, (failed_at, expected, step)
    assert failed.ravel()[0] == 1.0
    # a failed weld is an eroded element: one message line, glstat counts it, and its stored
    # energy moves to the eroded internal energy with the balance kept
    assert re.search(r"beam element \d+ \(part \d+\) failed at time", run.stdout), run.stdout
    with run.open() as results:
        glstat = results["history/glstat"]
        assert glstat["eroded_elements"][-1] == 1 and glstat["eroded_elements"][0] == 0
        assert glstat["eroded_internal_energy"][-1] > 0.0
        total, work = glstat["total_energy"][...], glstat["external_work"][...]
        assert np.abs(total - total[0] - work).max() < 1e-3 * np.abs(work).max()


def test_spot_weld_fails_by_plastic_strain(tmp_path, run_deck):
    """SIGY 0.2 GPa, ET 0: the weld yields at N = 0.2 A = 3.93 kN and then carries that force
    while it stretches; EFAIL 0.01: it fails once every section point has 1% plastic strain.
    Before the failure the axial force stays at the yield force (within 1%), and the weld
    fails (no force from then on) before the end of the pull."""
    deck = weld_deck(tmp_path / "weld.k", fields(0.01, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0), end_time=0.6)
    deck.write_text(deck.read_text().replace(fields(1, DENSITY, YOUNGS, POISSON, 2.0, 0.0, 0.0, 0.0),
                                             fields(1, DENSITY, YOUNGS, POISSON, 0.2, 0.0, 0.0, 0.0)))
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        failed_at, _ = failure_time_of(results)
        final = last_state(results)
        assert final["beam_failed"][...].ravel()[0] == 1.0
        assert final["beam_plastic_strain"][...].ravel()[0] >= 0.01
    yield_force = 0.2 * np.pi * WELD_DIAMETER ** 2 / 4.0
    assert failed_at is not None and failed_at > yield_force / FORCE_RATE + FORCE_START / 2.0


# ---------------------------------------------------------------------------------------------
# f. threads and restart

def test_beams_are_identical_for_one_and_two_threads(tmp_path, run_deck):
    """Two parts (two blocks, coloured apart where they share a node), plasticity off: every
    dataset of results.h5 the same on 1 and 2 threads."""
    deck = spinning_deck(tmp_path / "spin2.k", end_time=0.5, parts=2)
    runs = run_on_threads(run_deck, deck, counts=(1, 2))
    assert_identical_results(runs, counts=(1, 2))


def test_restart_of_beams_reproduces_the_uninterrupted_run(tmp_path):
    """A dump in the middle of the spinning beam, continued on 2 threads: every dataset the same
    as the uninterrupted run's."""
    deck = spinning_deck(tmp_path / "spin.k", end_time=0.5, dump_cycles=400, parts=2)
    run_fresh(deck, tmp_path / "one", ncpu=1)
    reference = contents(tmp_path / "one" / "results.h5")
    dumps = sorted(p.name for p in (tmp_path / "one").glob("d3dump*"))
    assert len(dumps) >= 2, dumps
    middle = dumps[len(dumps) // 2]
    target = copy_run(tmp_path / "one", tmp_path / "restarted")
    process = restart(target / middle, 2)
    assert process.returncode == 0, process.stdout + process.stderr
    assert_same(reference, contents(target / "results.h5"), f"continued from {middle}")


# ---------------------------------------------------------------------------------------------
# g. refused input

@pytest.mark.parametrize("old, new, fragments", [
    (fields(1, 1, SHEAR_FACTOR, 2, 0), fields(1, 3, SHEAR_FACTOR, 2, 0),
     ["*SECTION_BEAM: field ELFORM", "beam formulation 3 is not available"]),
    (fields(1, 1, SHEAR_FACTOR, 2, 0), fields(1, 1, SHEAR_FACTOR, -3, 0),
     ["field QR/IRID", "user integration rules"]),
    (fields(1, 1, SHEAR_FACTOR, 2, 0), fields(1, 1, SHEAR_FACTOR, 2, 2),
     ["field CST", "arbitrary sections"]),
    (f"{1:8d}{1:8d}{1:8d}{2:8d}{12:8d}", f"{1:8d}{1:8d}{1:8d}{2:8d}{12:8d}{1:8d}",
     ["*ELEMENT_BEAM: field RT1", "end releases are not available"]),
    (f"{1:8d}{1:8d}{1:8d}{2:8d}{12:8d}", f"{1:8d}{1:8d}{1:8d}{2:8d}{3:8d}",
     ["field N3", "lies on the beam's axis"]),
    (f"{1:8d}{1:8d}{1:8d}{2:8d}{12:8d}", f"{1:8d}{1:8d}{1:8d}{99:8d}{12:8d}",
     ["field N2", "node 99 of beam 1 is not defined"]),
    ("*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
     "*MAT_LOW_DENSITY_FOAM\n" + fields(1, DENSITY, YOUNGS, 1) + "\n" + fields(0.0) +
     "\n*DEFINE_CURVE\n" + fields(1) + "\n" + fields(0.0, 0.0, width=20) + "\n" + fields(1.0, 1.0, width=20),
     ["field MID", "not available on beams"]),
])
def test_unavailable_beam_input_is_refused(tmp_path, run_deck, old, new, fragments):
    deck = cantilever_deck(tmp_path / "good.k", end_time=0.01)
    text = deck.read_text()
    assert old in text
    deck.write_text(text.replace(old, new, 1))
    run = run_deck(deck)
    assert run.status == 2, run.stdout + run.stderr
    for fragment in fragments:
        assert fragment in run.stderr, f"'{fragment}' not in:\n{run.stderr}"
    assert "At line" not in run.stderr


def test_beam_thickness_card_that_sets_nothing_is_read(tmp_path, run_deck):
    """*ELEMENT_BEAM_THICKNESS with a blank second card runs as *ELEMENT_BEAM; one that sets a
    size is refused."""
    deck = cantilever_deck(tmp_path / "thick.k", end_time=0.01)
    text = deck.read_text()
    lines = text.split("\n")
    start = lines.index("*ELEMENT_BEAM")
    beam_lines = [k for k in range(start + 1, start + 1 + CANTILEVER_ELEMENTS)]
    blank = list(lines)
    blank[start] = "*ELEMENT_BEAM_THICKNESS"
    for offset, k in enumerate(beam_lines):
        blank.insert(k + offset + 1, fields(0.0, 0.0, 0.0, 0.0, 0.0))
    deck.write_text("\n".join(blank))
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    sized = "\n".join(blank).replace(fields(0.0, 0.0, 0.0, 0.0, 0.0), fields(3.0, 3.0, 0.0, 0.0, 0.0), 1)
    deck.write_text(sized)
    run = run_deck(deck)
    assert run.status == 2 and "per-element section sizes" in run.stderr, run.stderr


# ---------------------------------------------------------------------------------------------
# h. a weld on shell nodes

PLATE_SIDE, PLATE_CELLS, PLATE_THICKNESS, PLATE_GAP, WELD_NRR = 20.0, 8, 1.0, 2.0, 0.5


def welded_plates_deck(path, end_time=2.5):
    """Two square plates of 8 x 8 Belytschko-Tsay shells (20 mm, 1 mm thick, MAT_ELASTIC), at
    z = 0 and z = 2, joined at their centre nodes by one spot weld beam (ELFORM 9, 5 mm solid
    circle, *MAT_SPOTWELD with NRR = 0.5 kN) whose nodes are the shells' nodes. The lower
    plate's edges are clamped (all six dofs), the upper plate's edges pulled along +z at a speed
    that rises as a half cosine over 0.5 ms (11 periods of the plates' first mode) to 0.1 mm/ms."""
    from deck_writer import plate_mesh, shells_card
    nodes, shells = plate_mesh((PLATE_CELLS, PLATE_CELLS), (PLATE_SIDE, PLATE_SIDE))
    count = len(nodes)
    upper = nodes + [0.0, 0.0, PLATE_GAP]
    all_nodes = np.vstack([nodes, upper])
    centre = int(np.flatnonzero(np.isclose(nodes[:, 0], PLATE_SIDE / 2) & np.isclose(nodes[:, 1], PLATE_SIDE / 2))[0])
    edge = np.flatnonzero(np.isclose(nodes[:, 0], 0.0) | np.isclose(nodes[:, 0], PLATE_SIDE) |
                          np.isclose(nodes[:, 1], 0.0) | np.isclose(nodes[:, 1], PLATE_SIDE))
    speed = 0.1
    ramp = [(t, speed * 0.5 * (1.0 - np.cos(np.pi * t / 0.5))) for t in np.linspace(0.0, 0.5, 41)] + [(100.0, speed)]
    spc = ["*BOUNDARY_SPC_NODE"] + [fields(k + 1, 0, 1, 1, 1, 1, 1, 1) for k in edge]
    spc += [fields(count + k + 1, 0, 1, 1, 0, 1, 1, 1) for k in edge]
    motion = ["*BOUNDARY_PRESCRIBED_MOTION_NODE"] + [fields(count + k + 1, 3, 0, 1, 1.0) for k in edge]
    deck = write_deck(
        path, "*TITLE\nwelded plates",
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_GLSTAT\n" + fields(0.01),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.02),
        "*PART\nlower\n" + fields(1, 1, 1), "*PART\nupper\n" + fields(2, 1, 1), "*PART\nweld\n" + fields(3, 2, 2),
        "*SECTION_SHELL\n" + fields(1, 2, 5.0 / 6.0, 3) + "\n" + fields(*[PLATE_THICKNESS] * 4),
        "*SECTION_BEAM\n" + fields(2, 9, 0.0, 2, 1) + "\n" + fields(WELD_DIAMETER, WELD_DIAMETER, 0.0, 0.0),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
        "*MAT_SPOTWELD\n" + fields(2, DENSITY, YOUNGS, POISSON, 2.0, 0.0, 0.0, 0.0) + "\n" +
        fields(0.0, WELD_NRR, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        nodes_card(all_nodes),
        shells_card(shells, part_id=1),
        shells_card(shells, part_id=2, first_id=len(shells) + 1, first_node_id=count + 1),
        beams_card([(centre + 1, count + centre + 1)], part_id=3),
        curve_card(1, ramp), "\n".join(spc), "\n".join(motion))
    return deck, centre


def test_weld_on_shell_nodes_carries_the_plates_and_fails_at_nrr(tmp_path, run_deck):
    """Before it fails the weld carries the force that bends the lower plate: its axial force N
    over the lower plate's centre deflection w is the clamped square plate's stiffness under a
    centre load, D / (0.0056 a^2) (Timoshenko & Woinowsky-Krieger's thin-plate value, 8.6
    kN/mm). On 8 x 8 one-point shells with transverse shear (t/a = 1/20), under a load on one
    node, the computed stiffness is 9.5% below it (thin-plate theory leaves out the shear
    deflection, which grows without bound under a point load); 12% is asked. The weld fails
    once N reaches NRR: the largest N of the states before is at most NRR and within 10% of it (states every
    0.02 ms, N grows by ~8% of NRR between them), and from then on it carries nothing (the
    lower plate swings back about its rest position)."""
    deck, centre = welded_plates_deck(tmp_path / "plates.k")
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    rigidity = YOUNGS * PLATE_THICKNESS ** 3 / (12.0 * (1.0 - POISSON ** 2))
    plate_stiffness = rigidity / (0.0056 * PLATE_SIDE ** 2)
    with run.open() as results:
        keys = sorted(results["states"].keys())
        force = np.array([results["states"][k]["beam_resultant"][...].ravel()[0] for k in keys])
        failed = np.array([results["states"][k]["beam_failed"][...].ravel()[0] for k in keys])
        deflection = np.array([results["states"][k]["displacement"][centre, 2] for k in keys])
    assert failed[-1] == 1.0 and failed[0] == 0.0
    before = failed == 0.0
    loaded = before & (force > 0.3 * WELD_NRR)
    stiffness = force[loaded] / deflection[loaded]
    assert np.all(np.abs(stiffness / plate_stiffness - 1.0) < 0.12), (stiffness, plate_stiffness)
    assert force[before].max() <= WELD_NRR and force[before].max() > 0.9 * WELD_NRR, force[before].max()
    assert np.all(force[~before] == 0.0)
    assert np.abs(deflection[~before]).max() < 1.5 * deflection[before].max()


def test_resultant_beam_refuses_plasticity_and_unsymmetric_sections(tmp_path, run_deck):
    """ELFORM 2 is elastic: *MAT_PLASTIC_KINEMATIC on it is an error at the part; a product of
    inertia IST is an error at the section card."""
    deck = cantilever_deck(tmp_path / "resultant.k", end_time=0.01, formulation=2)
    text = deck.read_text()
    elastic = "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON)
    deck.write_text(text.replace(elastic, "*MAT_PLASTIC_KINEMATIC\n" + fields(1, DENSITY, YOUNGS, POISSON, 0.3) +
                                 "\n" + fields(0.0, 0.0)))
    run = run_deck(deck)
    assert run.status == 2 and "*PART: field MID" in run.stderr and "takes *MAT_ELASTIC only" in run.stderr, \
        run.stderr
    side = CANTILEVER_SIDE
    section = fields(side ** 2, side ** 4 / 12, side ** 4 / 12)
    assert section in text
    deck.write_text(text.replace(section, fields(side ** 2, side ** 4 / 12, side ** 4 / 12, 0.0, 0.0, 5.0)))
    run = run_deck(deck)
    assert run.status == 2 and "field IST" in run.stderr and "product of inertia" in run.stderr, run.stderr


def test_plastic_cantilever_root_moment_saturates_at_the_section_points_capacity(tmp_path, run_deck):
    """*MAT_PLASTIC_KINEMATIC, SIGY 0.3 GPa, ETAN 0 (perfectly plastic), 3 x 3 Gauss points on a
    10 x 10 mm section; the tip of the cantilever is pushed along z (a velocity that rises as a
    half cosine over 4 ms to 0.25 mm/ms, 4.5 mm in 20 ms; first yield at 0.95 mm). The root
    element's moment saturates at the capacity of its section points, sigma_y sum w |t| =
    sigma_y b h^2 (5/18) sqrt(3/5) = 64.5 kN mm (a fully plastic section, b h^2 / 4, carries
    75: three points through the depth under-integrate the stress block), within 1%; its
    points reach plastic strains > 0; the moment never exceeds the capacity by more than 1%."""
    deck = cantilever_deck(tmp_path / "plastic.k", end_time=20.0)
    text = deck.read_text()
    elastic = "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON)
    plastic = "*MAT_PLASTIC_KINEMATIC\n" + fields(1, DENSITY, YOUNGS, POISSON, 0.3, 0.0, 1.0) + "\n" + fields(0.0, 0.0)
    text = text.replace(elastic, plastic).replace(fields(1, 1, SHEAR_FACTOR, 2, 0), fields(1, 1, SHEAR_FACTOR, 3, 0))
    load = "*LOAD_NODE_POINT\n" + fields(CANTILEVER_ELEMENTS + 1, 3, 1, TIP_LOAD)
    push = "*BOUNDARY_PRESCRIBED_MOTION_NODE\n" + fields(CANTILEVER_ELEMENTS + 1, 3, 0, 2, 0.25)
    ramp = curve_card(2, smooth_ramp(4.0, 100.0))
    assert load in text
    text = text.replace(load, push + "\n" + ramp).replace("*DATABASE_BINARY_D3PLOT\n" + fields(20.0 / 4),
                                                          "*DATABASE_BINARY_D3PLOT\n" + fields(0.5))
    deck.write_text(text)
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    side = CANTILEVER_SIDE
    capacity = 0.3 * side ** 3 * 5.0 / 18.0 * np.sqrt(0.6)
    with run.open() as results:
        keys = sorted(results["states"].keys())
        moment = np.array([abs(results["states"][k]["beam_resultant"][...].reshape(-1, 6)[0, 4]) for k in keys])
        strain = results["states"][keys[-1]]["beam_plastic_strain"][...]
    assert abs(moment[-1] / capacity - 1.0) < 1e-2, (moment[-1], capacity)
    assert moment.max() < 1.01 * capacity, (moment.max(), capacity)
    assert strain[0] > 0.0


def test_weld_tied_by_contact_spotweld_acts_as_on_shared_nodes(tmp_path, run_deck):
    """The vehicle decks' way of writing a beam weld: its two nodes are its own, on the sheets'
    mid-surfaces, and *CONTACT_SPOTWELD ties them (translations and rotations) to the shells
    of both plates. With the weld's nodes where the plates' centre nodes are, the tie carries
    the weld's mass, force and moment to those nodes: the weld's axial force, the plate's
    deflection and the failure at NRR follow the shared-node weld (within 1% of NRR before it
    fails, the same state of failure)."""
    shared_deck, centre = welded_plates_deck(tmp_path / "shared.k")
    text = shared_deck.read_text()
    count = (PLATE_CELLS + 1) ** 2
    weld_nodes = nodes_card([(PLATE_SIDE / 2, PLATE_SIDE / 2, 0.0), (PLATE_SIDE / 2, PLATE_SIDE / 2, PLATE_GAP)],
                            first_id=2 * count + 1)
    shared_beam = beams_card([(centre + 1, count + centre + 1)], part_id=3)
    tied_beam = beams_card([(2 * count + 1, 2 * count + 2)], part_id=3)
    assert shared_beam in text
    tied_text = text.replace(shared_beam, weld_nodes + "\n" + tied_beam + "\n" +
                             "*SET_PART_LIST\n" + fields(7) + "\n" + fields(1, 2) + "\n" +
                             "*CONTACT_SPOTWELD\n" + fields(3, 7, 3, 2) + "\n" + fields(0.0) + "\n" + fields(0.0))
    tied_deck = tmp_path / "tied" / "tied.k"
    tied_deck.parent.mkdir()
    tied_deck.write_text(tied_text)
    shared = run_deck(shared_deck, jobid="shared")
    tied = run_deck(tied_deck, jobid="tied")
    assert shared.status == 0 and tied.status == 0, tied.stdout + tied.stderr

    def series(run):
        with run.open() as results:
            keys = sorted(results["states"].keys())
            force = np.array([results["states"][k]["beam_resultant"][...].ravel()[0] for k in keys])
            failed = np.array([results["states"][k]["beam_failed"][...].ravel()[0] for k in keys])
            deflection = np.array([results["states"][k]["displacement"][centre, 2] for k in keys])
        return force, failed, deflection

    force_shared, failed_shared, deflection_shared = series(shared)
    force_tied, failed_tied, deflection_tied = series(tied)
    assert np.array_equal(failed_shared, failed_tied)
    assert failed_tied[-1] == 1.0
    before = failed_shared == 0.0
    assert np.abs(force_tied[before] - force_shared[before]).max() < 0.01 * WELD_NRR
    assert np.abs(deflection_tied[before] - deflection_shared[before]).max() < \
        0.01 * np.abs(deflection_shared[before]).max()
