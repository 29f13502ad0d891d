"""Element erosion: failure strains (FS of *MAT_PLASTIC_KINEMATIC, FAIL of
*MAT_PIECEWISE_LINEAR_PLASTICITY), *MAT_ADD_EROSION strain criteria and ERODE with DTMIN.

A bar (solids) or a strip (shells) in uniaxial stress is pulled at a constant speed after a
short linear ramp: symmetry planes at x = 0, y = 0 (and z = 0), the end x = L prescribed. Its
end moves u(t) = v (t - ramp / 2) after the ramp, the strain is uniform, so the logarithmic
strain is ln(1 + u / L) and, with the bilinear law, the effective plastic strain
eps_p = ln(1 + u / L) - sigma(eps_p) / E with sigma = SIGY + E ETAN / (E - ETAN) eps_p.
Each element must erode in the cycle where its criterion is met: the time is checked against
that prediction to 0.5 % (the wave crossing the bar and the slow ringing of the pulled end
make the strain non-uniform by less). After erosion the elements carry no stress and the
energy balance (total = kinetic + internal + hourglass + eroded energies) stays closed.
"""
import re

import h5py
import numpy as np
import pytest

from test_restart import assert_same, contents, copy_run, restart, run_fresh
from deck_writer import (block_mesh, efg_section, fields, node_list_set, nodes_card, plate_mesh, round_to_node_card,
                         shells_card, solids_card, write_deck)

E, NU, SIGY, ETAN, DENSITY = 200.0, 0.3, 0.25, 2.0, 7.85e-6   # GPa, kg/mm^3 (mm, ms)
SPEED, RAMP = 0.2, 0.05                                        # mm/ms, ms
LENGTH, CELLS = 4.0, 4
HARDENING = E * ETAN / (E - ETAN)                              # plastic modulus of the bilinear law

FAILURE_LINE = re.compile(r"^(solid|shell) element (\d+) \(part \d+\) failed at time (\S+), cycle (\d+)$",
                          re.MULTILINE)


def ramp_curve():
    return "*DEFINE_CURVE\n" + fields(1) + "\n" + fields(0.0, 0.0, width=20) + "\n" + \
        fields(RAMP, 1.0, width=20) + "\n" + fields(100.0, 1.0, width=20)


def bar_deck(path, material_cards, kind="solid", formulation=1, end_time=0.6, extra=()):
    """A bar of CELLS elements (solids 1 x 1 mm, or shells 1 mm wide and 0.1 mm thick) of length
    LENGTH in uniaxial stress, its end pulled at SPEED."""
    if kind == "solid":
        nodes, elements = block_mesh((CELLS, 1, 1), (LENGTH, 1.0, 1.0))
        element_cards = solids_card(elements)
        section = "*SECTION_SOLID\n" + fields(1, formulation)
    else:
        nodes, elements = plate_mesh((CELLS, 1), (LENGTH, 1.0))
        element_cards = shells_card(elements)
        section = "*SECTION_SHELL\n" + fields(1, 2, 1.0, 3) + "\n" + fields(*[0.1] * 4)
    nodes = round_to_node_card(nodes)
    spc = ["*BOUNDARY_SPC_NODE"]
    for k, node in enumerate(nodes):
        dofs = [int(abs(node[axis]) < 1e-9) for axis in range(3)]
        if kind == "shell":
            dofs[2] = 1
        if any(dofs):
            spc.append(fields(k + 1, 0, *dofs, *([1, 1, 1] if kind == "shell" else [0, 0, 0])))
    pulled = list(np.flatnonzero(np.abs(nodes[:, 0] - LENGTH) < 1e-9) + 1)
    return write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_GLSTAT\n" + fields(0.002),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.05),
        "*PART\nbar\n" + fields(1, 1, 1),
        section,
        material_cards,
        ramp_curve(),
        node_list_set(1, pulled),
        "*BOUNDARY_PRESCRIBED_MOTION_SET\n" + fields(1, 1, 0, 1, SPEED),
        "\n".join(spc),
        nodes_card(nodes),
        element_cards,
        *extra,
    )


def time_of_stretch(log_strain):
    """When the bar's logarithmic strain reaches `log_strain`."""
    return LENGTH * (np.exp(log_strain) - 1.0) / SPEED + RAMP / 2


def plastic_failure_time(failure_strain):
    return time_of_stretch(failure_strain + (SIGY + HARDENING * failure_strain) / E)


def failures(run):
    """[(kind, element id, time, cycle)] from the message lines of the run."""
    return [(kind, int(element), float(time), int(cycle))
            for kind, element, time, cycle in FAILURE_LINE.findall(run.stdout)]


def check_energy_balance(results, tolerance=1e-3):
    glstat = results["history/glstat"]
    total, work = glstat["total_energy"][...], glstat["external_work"][...]
    imbalance = total - total[0] - work
    print(f"  energy imbalance {np.abs(imbalance).max():.3e} of external work {np.abs(work).max():.3e}")
    assert np.abs(imbalance).max() < tolerance * np.abs(work).max()
    return glstat


@pytest.mark.parametrize("formulation", [1, 2])
def test_solid_bar_erodes_at_the_failure_strain_of_mat_003(tmp_path, run_deck, formulation):
    """FS = 0.02 of *MAT_PLASTIC_KINEMATIC (isotropic hardening): all four solids erode at the
    predicted time; then no stress, the flags and counts in the states and glstat, and the
    internal energy they had moved to the eroded internal energy."""
    failure_strain = 0.02
    deck = bar_deck(tmp_path / "bar.k", "*MAT_PLASTIC_KINEMATIC\n" + fields(1, DENSITY, E, NU, SIGY, ETAN, 1.0) +
                    "\n" + fields(0.0, 0.0, failure_strain), formulation=formulation)
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    eroded = failures(run)
    expected = plastic_failure_time(failure_strain)
    print(f"  failures {[(e, t) for _, e, t, _ in eroded]}, predicted {expected:.5f} ms")
    assert sorted(e for _, e, _, _ in eroded) == [1, 2, 3, 4]
    for kind, _, time, _ in eroded:
        assert kind == "solid"
        assert abs(time - expected) < 5e-3 * expected
    # messag, beside the results, lists the same failures in the same order as the terminal
    messag = (run.results.parent / "messag").read_text()
    assert FAILURE_LINE.findall(messag) == FAILURE_LINE.findall(run.stdout)
    with run.open() as results:
        glstat = check_energy_balance(results)
        count = glstat["eroded_elements"][...]
        times = glstat["time"][...]
        assert count[0] == 0 and count[-1] == 4
        assert times[np.argmax(count > 0)] >= min(t for _, _, t, _ in eroded)
        internal, eroded_internal = glstat["internal_energy"][...], glstat["eroded_internal_energy"][...]
        # the plastic work of the bar, about volume x sigma x eps_p, went with the elements
        assert eroded_internal[-1] == pytest.approx(LENGTH * (SIGY + 0.5 * HARDENING * failure_strain)
                                                    * failure_strain, rel=0.05)
        assert abs(internal[-1]) < 1e-9 * eroded_internal[-1]
        assert eroded_internal[0] == 0.0
        last = results["states"][sorted(results["states"])[-1]]
        assert np.all(last["solid_eroded"][...] == 1)
        assert last.attrs["eroded_elements"] == 4
        assert np.all(last["solid_stress"][...] == 0.0)
        first = results["states"][sorted(results["states"])[0]]
        assert np.all(first["solid_eroded"][...] == 0)


def test_shell_strip_erodes_at_fail_of_mat_024(tmp_path, run_deck):
    """FAIL = 0.03 of *MAT_PIECEWISE_LINEAR_PLASTICITY on Belytschko-Tsay shells (3 points): a
    shell erodes when all its points failed (LS-DYNA without *MAT_ADD_EROSION); in membrane
    tension they fail together, at the predicted time."""
    failure_strain = 0.03
    deck = bar_deck(tmp_path / "strip.k", "*MAT_PIECEWISE_LINEAR_PLASTICITY\n" +
                    fields(1, DENSITY, E, NU, SIGY, ETAN, failure_strain) + "\n" + fields(0.0), kind="shell",
                    end_time=0.8)
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    eroded = failures(run)
    # plane stress, uniaxial: the same law in the pulled direction (ETAN is the tangent modulus)
    expected = plastic_failure_time(failure_strain)
    print(f"  failures {[(e, t) for _, e, t, _ in eroded]}, predicted {expected:.5f} ms")
    assert sorted(e for _, e, _, _ in eroded) == [1, 2, 3, 4]
    for kind, _, time, _ in eroded:
        assert kind == "shell"
        assert abs(time - expected) < 5e-3 * expected
    with run.open() as results:
        glstat = check_energy_balance(results)
        assert glstat["eroded_elements"][-1] == 4
        last = results["states"][sorted(results["states"])[-1]]
        assert np.all(last["shell_eroded"][...] == 1)
        assert np.all(last["shell_stress"][...] == 0.0)


@pytest.mark.parametrize("criterion, value, log_strain", [("MXEPS", 0.01, 0.01), ("MNEPS", -0.003, 0.01)])
@pytest.mark.parametrize("kind", ["solid", "shell"])
def test_add_erosion_principal_strain(tmp_path, run_deck, criterion, value, log_strain, kind):
    """*MAT_ADD_EROSION on an elastic bar: MXEPS erodes when the axial logarithmic strain
    reaches it; MNEPS when the lateral one, -nu times the axial, reaches it (solids; shells see
    the in-plane strains only, the lateral one here)."""
    card1 = fields(1, 0.0, 0.0, value if criterion == "MNEPS" else 0.0, 0.0, 0.0, 0.0, 0.0)
    card2 = fields(0.0, 0.0, 0.0, value if criterion == "MXEPS" else 0.0)
    if criterion == "MNEPS":
        log_strain = -value / NU
    deck = bar_deck(tmp_path / "bar.k", "*MAT_ELASTIC\n" + fields(1, DENSITY, E, NU) + "\n*MAT_ADD_EROSION\n" +
                    card1 + "\n" + card2, kind=kind, end_time=1.2)
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    eroded = failures(run)
    expected = time_of_stretch(log_strain)
    print(f"  failures {[(e, t) for _, e, t, _ in eroded]}, predicted {expected:.5f} ms")
    assert sorted(e for _, e, _, _ in eroded) == [1, 2, 3, 4]
    for _, _, time, _ in eroded:
        assert abs(time - expected) < 5e-3 * expected
    with run.open() as results:
        check_energy_balance(results)


def test_add_erosion_effective_plastic_strain_and_numfip(tmp_path, run_deck):
    """EFFEPS of *MAT_ADD_EROSION below FS wins; NUMFIP = 1 erodes a shell at its first failed
    point (all points together here, so the time is the same as with all points)."""
    deck = bar_deck(tmp_path / "strip.k", "*MAT_PLASTIC_KINEMATIC\n" + fields(1, DENSITY, E, NU, SIGY, ETAN, 1.0) +
                    "\n" + fields(0.0, 0.0, 0.05) + "\n*MAT_ADD_EROSION\n" +
                    fields(1, 0.0, 0.0, 0.0, 0.015, 0.0, 1.0, 1.0) + "\n" + fields(0.0), kind="shell")
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    eroded = failures(run)
    expected = plastic_failure_time(0.015)
    assert len(eroded) == 4
    for _, _, time, _ in eroded:
        assert abs(time - expected) < 5e-3 * expected


def bent_strip_deck(path, failed_points):
    """A cantilever strip of ten shells (NIP 5, MAT_024 FAIL 0.05) clamped at x = 0, its tip
    pushed sideways at 5 mm/ms: bending, the outer points fail first; *MAT_ADD_EROSION NUMFIP
    `failed_points` (None: no *MAT_ADD_EROSION, all five points)."""
    nodes, shells = plate_mesh((10, 1), (10.0, 1.0))
    nodes = round_to_node_card(nodes)
    root = [k + 1 for k, node in enumerate(nodes) if abs(node[0]) < 1e-9]
    tip = [k + 1 for k, node in enumerate(nodes) if abs(node[0] - 10.0) < 1e-9]
    erosion = []
    if failed_points is not None:
        erosion = ["*MAT_ADD_EROSION\n" + fields(1, 0.0, 0.0, 0.0, 0.0, 0.0, float(failed_points)) + "\n" + fields(0.0)]
    return write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(1.5),
        "*DATABASE_GLSTAT\n" + fields(0.01),
        "*PART\nstrip\n" + fields(1, 1, 1),
        "*SECTION_SHELL\n" + fields(1, 2, 0.8333, 5) + "\n" + fields(*[0.5] * 4),
        "*MAT_PIECEWISE_LINEAR_PLASTICITY\n" + fields(1, DENSITY, E, NU, SIGY, ETAN, 0.05) + "\n" + fields(0.0),
        *erosion,
        ramp_curve(),
        node_list_set(1, root),
        "*BOUNDARY_SPC_SET\n" + fields(1, 0, 1, 1, 1, 1, 1, 1),
        node_list_set(2, tip),
        "*BOUNDARY_PRESCRIBED_MOTION_SET\n" + fields(2, 3, 0, 1, 5.0),
        nodes_card(nodes),
        shells_card(shells),
    )


def test_numfip_counts_the_failed_points_of_a_bent_shell(tmp_path, run_deck):
    """In bending the outer points of the root shell fail first (top and bottom within a few
    cycles: the large deflection adds some tension), the next pair later, the mid-surface point
    never: NUMFIP 1 erodes it first, 2 a little later, 3 and -60 (60 % of 5 points) much later
    and at the same cycle; without *MAT_ADD_EROSION (all five points) it does not erode. Failed
    points carry no stress, and the energy balance holds."""
    first = {}
    for failed_points in (1, 2, 3, -60, None):
        run = run_deck(bent_strip_deck(tmp_path / f"strip_{failed_points}.k", failed_points), jobid=str(failed_points))
        assert run.status == 0, run.stderr
        eroded = failures(run)
        first[failed_points] = min((cycle for *_, cycle in eroded), default=None)
        with run.open() as results:
            check_energy_balance(results, tolerance=1e-2)
    print(f"  first erosion cycle by NUMFIP: {first}")
    assert first[1] is not None and first[1] <= first[2] < first[1] + 100
    assert first[3] is not None and first[3] == first[-60] and first[3] > first[2] + 1000
    assert first[None] is None


def crushed_block_deck(path, erode, material=None, minimum_step_factor=0.5):
    """One hexahedron crushed at 10 m/s (10 mm/ms) against its held face: its step shrinks with
    its length; DTMIN = 0.5 x the first step."""
    nodes, elements = block_mesh((1, 1, 1), (1.0, 1.0, 1.0))
    nodes = round_to_node_card(nodes)
    spc = ["*BOUNDARY_SPC_NODE"]
    for k, node in enumerate(nodes):
        dofs = [int(abs(node[axis]) < 1e-9) for axis in range(3)]
        if any(dofs):
            spc.append(fields(k + 1, 0, *dofs, 0, 0, 0))
    pushed = list(np.flatnonzero(np.abs(nodes[:, 0] - 1.0) < 1e-9) + 1)
    return write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(0.09, 0, minimum_step_factor),
        "*CONTROL_TIMESTEP\n" + fields(0.0, 0.9, 0, 0.0, 0.0, 0, erode),
        "*DATABASE_GLSTAT\n" + fields(0.001),
        "*PART\nblock\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        material or "*MAT_ELASTIC\n" + fields(1, DENSITY, E, NU),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + fields(0.0, 1.0, width=20) + "\n" + fields(1.0, 1.0, width=20),
        node_list_set(1, pushed),
        "*BOUNDARY_PRESCRIBED_MOTION_SET\n" + fields(1, 1, 0, 1, -10.0),
        "\n".join(spc),
        nodes_card(nodes),
        solids_card(elements),
    )


def test_erode_with_dtmin_deletes_the_element_instead_of_stopping(tmp_path, run_deck):
    """ERODE = 1: the crushed solid erodes when its step falls below DTMIN x the first step
    (its length, which sets its step, about halved) and the run goes on to ENDTIM; ERODE = 0
    stops the run there (error termination)."""
    stopped = run_deck(crushed_block_deck(tmp_path / "stop.k", 0), jobid="stop")
    assert stopped.status == 1
    assert "DTMIN" in stopped.stderr + stopped.stdout
    run = run_deck(crushed_block_deck(tmp_path / "erode.k", 1), jobid="erode")
    assert run.status == 0, run.stderr
    eroded = failures(run)
    assert [(kind, element) for kind, element, _, _ in eroded] == [("solid", 1)]
    length = 1.0 - 10.0 * eroded[0][2]
    print(f"  eroded at length {length:.4f} mm")
    assert 0.35 < length < 0.55
    with run.open() as results:
        check_energy_balance(results, tolerance=1e-2)


def test_tdel_of_mat_024_deletes_the_element_at_its_smallest_step(tmp_path, run_deck):
    """TDEL = half the first stable step: the crushed solid of MAT_024 erodes as with ERODE and
    DTMIN = 0.5 (at the same time to 0.2 %: TDEL is written with 5 digits), without any
    *CONTROL_TIMESTEP flag."""
    reference = run_deck(crushed_block_deck(tmp_path / "erode.k", 1), jobid="erode")
    assert reference.status == 0, reference.stderr
    with reference.open() as results:
        first_stable_step = results["history/glstat/time_step"][0] / 0.9
    material = ("*MAT_PIECEWISE_LINEAR_PLASTICITY\n" + fields(1, DENSITY, E, NU, 100.0, 0.0, 0.0,
                                                              float(f"{0.5 * first_stable_step:.4e}")) +
                "\n" + fields(0.0))
    run = run_deck(crushed_block_deck(tmp_path / "tdel.k", 0, material, 0.0), jobid="tdel")
    assert run.status == 0, run.stderr
    eroded, expected = failures(run), failures(reference)
    print(f"  TDEL: {eroded}, ERODE: {expected}")
    assert len(eroded) == 1 and abs(eroded[0][2] - expected[0][2]) < 2e-3 * expected[0][2]


def test_bad_erode_is_refused(tmp_path, run_deck):
    run = run_deck(crushed_block_deck(tmp_path / "bad.k", 2))
    assert run.status == 2
    assert "field ERODE:" in run.stderr


def plate_deck(path):
    """An irregular plate of 191 shells (three blocks, two of them of one colour) with a hole of
    one element in its middle, pulled until it tears from the hole: the elements erode at
    different cycles."""
    nodes, shells = plate_mesh((24, 8), (24.0, 8.0), perturbation=0.2, seed=3)
    shells = np.delete(shells, 12 * 8 + 4, axis=0)
    nodes = round_to_node_card(nodes)
    spc = ["*BOUNDARY_SPC_NODE"]
    for k, node in enumerate(nodes):
        spc.append(fields(k + 1, 0, int(abs(node[0]) < 1e-9), int(abs(node[0]) < 1e-9), 1, 1, 1, 1))
    pulled = list(np.flatnonzero(np.abs(nodes[:, 0] - 24.0) < 1e-9) + 1)
    return write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(0.32),
        "*DATABASE_GLSTAT\n" + fields(0.005),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.02),
        "*PART\nstrip\n" + fields(1, 1, 1),
        "*SECTION_SHELL\n" + fields(1, 2, 1.0, 3) + "\n" + fields(*[0.2] * 4),
        "*MAT_PIECEWISE_LINEAR_PLASTICITY\n" + fields(1, DENSITY, E, NU, SIGY, ETAN, 0.08) + "\n" + fields(0.0),
        ramp_curve(),
        node_list_set(1, pulled),
        "*BOUNDARY_PRESCRIBED_MOTION_SET\n" + fields(1, 1, 0, 1, 8.0),
        "\n".join(spc),
        nodes_card(nodes),
        shells_card(shells),
    )


def test_erosion_is_bit_identical_on_one_and_two_threads(tmp_path):
    """Every dataset of the results file is the same on 1 and 2 threads while elements erode at
    different cycles, and the energy balance holds."""
    deck = plate_deck(tmp_path / "plate.k")
    one = run_fresh(deck, tmp_path / "one", ncpu=1)
    two = run_fresh(deck, tmp_path / "two", ncpu=2)
    failed = FAILURE_LINE.findall(one.stdout)
    assert failed == FAILURE_LINE.findall(two.stdout)
    cycles = {int(cycle) for *_, cycle in failed}
    print(f"  {len(failed)} shells eroded at {len(cycles)} different cycles")
    assert len(failed) > 1 and len(cycles) > 1
    assert_same(contents(tmp_path / "one" / "results.h5"), contents(tmp_path / "two" / "results.h5"), "ncpu=2")
    with h5py.File(tmp_path / "one" / "results.h5", "r") as results:
        check_energy_balance(results)


@pytest.mark.parametrize("model", ["solid bar", "bent shells"])
def test_restart_with_eroded_elements_reproduces_the_uninterrupted_run(tmp_path, model):
    """Dumps before and after elements eroded (the eroded masks, the shells' failed points, the
    energy eroded elements took and the counts are in the dump): each continued run gives the
    uninterrupted file bit for bit. The solids erode at cycle 4124 (dumps at 2200 and 4400); the
    root shell's outer points fail near cycle 5400 and it erodes at 7233 (dumps every 3000
    cycles: the one at 6000 between the two)."""
    if model == "solid bar":
        interval = 2200
        deck = bar_deck(tmp_path / "bar.k", "*MAT_PLASTIC_KINEMATIC\n" + fields(1, DENSITY, E, NU, SIGY, ETAN, 1.0) +
                        "\n" + fields(0.0, 0.0, 0.02), extra=["*DATABASE_BINARY_D3DUMP\n" + fields(interval)])
    else:
        interval = 3000
        deck = bent_strip_deck(tmp_path / "strip.k", 3)
        deck.write_text(deck.read_text().replace("*END", "*DATABASE_BINARY_D3DUMP\n" + fields(interval) + "\n*END"))
    uninterrupted = run_fresh(deck, tmp_path / "one")
    eroded_cycles = [int(cycle) for *_, cycle in FAILURE_LINE.findall(uninterrupted.stdout)]
    assert eroded_cycles
    reference = contents(tmp_path / "one" / "results.h5")
    dumps = sorted(p.name for p in (tmp_path / "one").glob("d3dump*"))
    assert len(dumps) >= 2 and any(interval * (k + 1) > max(eroded_cycles) for k in range(len(dumps))), dumps
    for k, dump in enumerate(dumps):
        target = copy_run(tmp_path / "one", tmp_path / f"restart_{dump}")
        process = restart(target / dump, 2)
        assert process.returncode == 0, process.stdout + process.stderr
        assert_same(reference, contents(target / "results.h5"), f"continued from {dump}")
        # the failure lines come from the part of the run that was continued
        later = [cycle for cycle in eroded_cycles if cycle > interval * (k + 1)]
        assert len(FAILURE_LINE.findall(process.stdout)) == len(later)


@pytest.mark.parametrize("cards, field", [
    ("*MAT_PIECEWISE_LINEAR_PLASTICITY\n" + fields(1, DENSITY, E, NU, SIGY, ETAN, -1.0) + "\n" + fields(0.0), "FAIL"),
    ("*MAT_PLASTIC_KINEMATIC\n" + fields(1, DENSITY, E, NU, SIGY, ETAN, 1.0) + "\n" + fields(0.0, 0.0, -0.1), "FS"),
    ("*MAT_ELASTIC\n" + fields(1, DENSITY, E, NU) + "\n*MAT_ADD_EROSION\n" + fields(1, 0.0, 1.0) + "\n" +
     fields(0.0), "MXPRES"),
    ("*MAT_ELASTIC\n" + fields(1, DENSITY, E, NU) + "\n*MAT_ADD_EROSION\n" + fields(1) + "\n" +
     fields(0.0, 0.0, 0.5), "SIGVM"),
    ("*MAT_ELASTIC\n" + fields(1, DENSITY, E, NU) + "\n*MAT_ADD_EROSION\n" + fields(7, 0.0, 0.0, 0.0, 0.1) + "\n" +
     fields(0.0), "MID"),
    ("*MAT_ELASTIC\n" + fields(1, DENSITY, E, NU) + "\n*MAT_ADD_EROSION\n" + fields(1, 0.0, 0.0, 0.0, 0.1, 0.0, 0.0,
                                                                                     2.0) + "\n" + fields(0.0), "NCS"),
])
def test_bad_erosion_input_is_refused(tmp_path, run_deck, cards, field):
    run = run_deck(bar_deck(tmp_path / "bad.k", cards))
    assert run.status == 2
    assert f"field {field}:" in run.stderr


def test_meshfree_parts_warn_that_they_do_not_erode(tmp_path, run_deck):
    deck = bar_deck(tmp_path / "efg.k", "*MAT_PLASTIC_KINEMATIC\n" + fields(1, DENSITY, E, NU, SIGY, ETAN, 1.0) +
                    "\n" + fields(0.0, 0.0, 0.02), end_time=0.01)
    deck.write_text(deck.read_text().replace("*SECTION_SOLID\n" + fields(1, 1), efg_section(1)))
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    assert "field MID: the failure criteria of material 1 are ignored for part 1: meshfree (EFG) parts do not " \
           "erode" in run.stdout + run.stderr


def test_excl_switches_a_criterion_off(tmp_path, run_deck):
    """A field equal to EXCL is off: MXEPS = EXCL = 0.01 erodes nothing."""
    deck = bar_deck(tmp_path / "bar.k", "*MAT_ELASTIC\n" + fields(1, DENSITY, E, NU) + "\n*MAT_ADD_EROSION\n" +
                    fields(1, 0.01) + "\n" + fields(0.0, 0.0, 0.0, 0.01), end_time=1.0)
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    assert failures(run) == []


def ball_deck(path, extra=()):
    """An elastic block (the ball) at 200 m/s over a free shell plate of MAT_024 with FAIL
    0.05, in surface-to-surface contact; returns the deck and the ball's node count."""
    ball_nodes, ball_elements = block_mesh((3, 3, 3), (3.0, 3.0, 3.0), origin=(3.5, 3.5, 0.6))
    plate_nodes, shells = plate_mesh((10, 10), (10.0, 10.0))
    offset = len(ball_nodes)
    deck = write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(0.05),
        "*DATABASE_GLSTAT\n" + fields(0.001),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.01),
        "*PART\nball\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, E, NU),
        "*PART\nplate\n" + fields(2, 2, 2),
        "*SECTION_SHELL\n" + fields(2, 2, 1.0, 3) + "\n" + fields(*[0.1] * 4),
        "*MAT_PIECEWISE_LINEAR_PLASTICITY\n" + fields(2, DENSITY, E, NU, SIGY, ETAN, 0.05) + "\n" + fields(0.0),
        "*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE\n" + fields(1, 2, 3, 3) + "\n" + fields(0.0) + "\n" + fields(0.0),
        node_list_set(10, list(range(1, offset + 1))),
        "*INITIAL_VELOCITY\n" + fields(10) + "\n" + fields(0.0, 0.0, -200.0),
        nodes_card(np.vstack([ball_nodes, round_to_node_card(plate_nodes)])),
        solids_card(ball_elements),
        shells_card(shells, part_id=2, first_id=1000, first_node_id=offset + 1),
        *extra,
    )
    return deck, offset


def test_ball_through_eroding_plate(tmp_path, run_deck):
    """An elastic block (the ball) shot at 200 m/s through a free, eroding shell plate: the
    shells under it erode, leave the contact, and the ball passes through; with no support, the
    momentum of the model is kept to round-off, and the energy balance holds with the eroded
    energies."""
    deck, offset = ball_deck(tmp_path / "ball.k")
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    eroded = failures(run)
    assert len(eroded) > 0 and all(kind == "shell" for kind, *_ in eroded)
    with run.open() as results:
        glstat = results["history/glstat"]
        momentum, total = glstat["momentum"][...], glstat["total_energy"][...]
        initial = momentum[0]
        assert np.abs(momentum - initial).max() < 1e-9 * np.abs(initial).max()
        assert np.abs(total - total[0] - glstat["external_work"][...]).max() < 1e-3 * total[0]
        assert glstat["eroded_internal_energy"][-1] > 0.0
        last = results["states"][sorted(results["states"])[-1]]
        ball_z = (results["mesh/nodes/coordinates"][:offset, 2] + last["displacement"][:offset, 2]).max()
        live = results["mesh/shells/connectivity_index"][...][last["shell_eroded"][...] == 0].ravel()
        plate_z = (results["mesh/nodes/coordinates"][...][live, 2] + last["displacement"][...][live, 2]).min()
        assert ball_z < plate_z        # the whole ball is below the plate that is left: it went through


def test_restart_after_erosion_with_contact(tmp_path):
    """A dump written after shells eroded in a contact: the restarted run builds its contacts
    from the deck, drops the eroded shells' segments again before reading the dump's search
    lists and pairs, and continues to the uninterrupted file bit for bit."""
    deck, _ = ball_deck(tmp_path / "probe.k")
    probe = run_fresh(deck, tmp_path / "probe")
    first = min(int(cycle) for *_, cycle in FAILURE_LINE.findall(probe.stdout))
    interval = first + 7
    deck, _ = ball_deck(tmp_path / "ball.k", extra=["*DATABASE_BINARY_D3DUMP\n" + fields(interval)])
    uninterrupted = run_fresh(deck, tmp_path / "one")
    assert uninterrupted.returncode == 0, uninterrupted.stderr
    reference = contents(tmp_path / "one" / "results.h5")
    dump = sorted((tmp_path / "one").glob("d3dump*"))[0]
    target = copy_run(tmp_path / "one", tmp_path / "continued")
    process = restart(target / dump.name, 1)
    assert process.returncode == 0, process.stdout + process.stderr
    assert_same(reference, contents(target / "results.h5"), f"continued from {dump.name}")


def test_eroding_contact_keyword_acts_as_the_automatic_one(tmp_path):
    """*CONTACT_ERODING_SURFACE_TO_SURFACE with its card ISYM EROSOP IADJ (the form of LS-DYNA's
    penetration examples) is the automatic contact, which already drops eroded segments: the
    ball through the plate gives the same results file bit for bit."""
    deck, _ = ball_deck(tmp_path / "automatic.k")
    automatic = run_fresh(deck, tmp_path / "automatic")
    eroding_deck = tmp_path / "eroding.k"
    text = deck.read_text()
    card_3 = fields(0.0)
    old = "*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE\n" + fields(1, 2, 3, 3) + "\n" + fields(0.0) + "\n" + card_3
    assert old in text
    eroding_deck.write_text(text.replace(old, "*CONTACT_ERODING_SURFACE_TO_SURFACE\n" + fields(1, 2, 3, 3) + "\n" +
                                         fields(0.0) + "\n" + card_3 + "\n" + fields(0, 1, 1)))
    eroding = run_fresh(eroding_deck, tmp_path / "eroding")
    assert automatic.returncode == 0 and eroding.returncode == 0, eroding.stdout + eroding.stderr
    assert FAILURE_LINE.findall(automatic.stdout)
    first, second = (contents(tmp_path / name / "results.h5") for name in ("automatic", "eroding"))
    for run_attribute in ("run@deck", "run@deck_absolute", "run/warnings"):   # the deck's own name and warnings
        first.pop(run_attribute, None)
        second.pop(run_attribute, None)
    assert_same(first, second, "eroding contact keyword")
