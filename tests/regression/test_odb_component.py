"""ODB component test (inputs/odb_component, docs/examples/odb_component.md), reduced: 50 mm
elements, the cylinder pushed 60 mm into the barrier's upper-left corner (4 ms at 15 mm/ms).

The coupled model of the issue has the honeycomb (*MAT_MODIFIED_HONEYCOMB) in its meshfree
corner, and crashfree rejects honeycomb in a meshfree part today. The runs here therefore use
the stand-in decks the generator writes beside it (the corner part of an elastic-plastic
stand-in, MAT_003 with nu = 0 and the crush strength as yield stress, in both the FE and the
coupled deck); test_honeycomb_in_meshfree_corner records the missing feature as an expected
failure, and turns into a pass when the solver accepts it.

Force band. The cylinder's end cap (radius R = 125 mm, axis at x = 110, y = 560) covers
A = 43,678 mm^2 of the barrier face (it overhangs the left and top edges). Every material under
it yields in uniaxial compression at sigma_c = 0.342 MPa, and the inertia of the crushed
material adds rho v^2 = 0.0064 MPa (2%). After the first contact, the force must therefore
stay above a lower bound of 0.5 sigma_c A = 7.5 kN (half: the first element layers load
elastically and the cap's rim cuts through elements, whose nodes it catches only partly).
Upper bound: the densification curve reaches 3 sigma_c at full compaction, the confined
stand-in adds its pressure K eps_v (at most 1 MPa per unit log strain, under 0.3 MPa in 60 mm of
crush), and the honeycomb around the rim shears at up to tau_L = 1.5 sigma_c over the rim
inside the face (530 mm) times about one element length (50 mm): 13.6 kN = 0.9 sigma_c A. The
force must stay below (3 + 0.9 + 0.1) sigma_c A = 4 sigma_c A = 60 kN.
"""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

REPOSITORY = Path(__file__).resolve().parents[2]
GENERATOR = REPOSITORY / "inputs" / "odb_component" / "generate_mesh.py"
CRUSH_STRENGTH = 0.342e-3          # GPa
FOOTPRINT = 43678.0                # mm^2, printed by the generator for the default cylinder
SIGMA_A = CRUSH_STRENGTH * FOOTPRINT


@pytest.fixture(scope="module")
def decks(tmp_path_factory):
    directory = tmp_path_factory.mktemp("odb")
    subprocess.run([sys.executable, str(GENERATOR), "--size", "50", "--crush", "60", "-o", str(directory)],
                   check=True, capture_output=True, text=True)
    return directory


def cylinder_force(results):
    history = results["history/rwforc/1"]
    return history["time"][...], history["force"][...][:, 2]


def test_generator_writes_the_decks(decks):
    for name in ("mesh.k", "fe.k", "coupled.k", "fe_standin.k", "coupled_standin.k"):
        assert (decks / name).is_file(), name
    text = (decks / "coupled.k").read_text()
    assert "*SECTION_SOLID_EFG" in text and "*INCLUDE\nmesh.k" in text
    assert "*MAT_MODIFIED_HONEYCOMB" in text


def test_cladding_shell_cards(tmp_path):
    """The cladding (for when shells exist) is written in LS-DYNA's layouts: *ELEMENT_SHELL with
    8-column fields EID PID N1-N4, *SECTION_SHELL card 1 (ELFORM 2) and card 2 (T1-T4)."""
    subprocess.run([sys.executable, str(GENERATOR), "--size", "100", "--cladding", "-o", str(tmp_path)],
                   check=True, capture_output=True, text=True)
    mesh = (tmp_path / "mesh.k").read_text().splitlines()
    start = mesh.index("*ELEMENT_SHELL")
    first = mesh[start + 1]
    fields = [int(first[k:k + 8]) for k in range(0, 48, 8)]
    assert fields[0] == 1 and fields[1] == 11 and len(first.rstrip()) == 48
    deck = (tmp_path / "fe.k").read_text().splitlines()
    section = deck.index("*SECTION_SHELL")
    card1 = [line for line in deck[section + 1:] if not line.startswith("$")][0]
    assert int(card1[0:10]) == 11 and int(card1[10:20]) == 2
    card2 = [line for line in deck[section + 1:] if not line.startswith("$")][1]
    assert float(card2[0:10]) == pytest.approx(0.81)


def test_coupled_run_energy_and_force(decks, run_deck):
    run = run_deck(decks / "coupled_standin.k")
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        assert "normal termination" in str(results["run"].attrs["status"])
        timing = results["timing"].attrs
        assert 0.05 < timing["dofs_efg"] / timing["dofs_total"] < 0.12
        glstat = results["history/glstat"]
        total, work = glstat["total_energy"][...], glstat["external_work"][...]
        ratio = total[-1] / (total[0] + work[-1])
        assert abs(ratio - 1.0) < 0.05
        hourglass, internal = glstat["hourglass_energy"][-1], glstat["internal_energy"][-1]
        assert hourglass < internal
        time, force = cylinder_force(results)
    end = time[-1]
    loaded = time > 0.1 * end
    assert force[loaded].min() > 0.5 * SIGMA_A, force[loaded].min()
    assert force.max() < 4.0 * SIGMA_A, force.max()


def test_coupled_run_identical_for_one_and_two_threads(decks, run_deck):
    one = run_deck(decks / "coupled_standin.k", ncpu=1, jobid="one")
    two = run_deck(decks / "coupled_standin.k", ncpu=2, jobid="two")
    assert one.status == 0 and two.status == 0
    with one.open() as a, two.open() as b:
        assert sorted(a["states"].keys()) == sorted(b["states"].keys())
        for name in a["states"]:
            for key in ("displacement", "velocity", "solid_stress"):
                assert np.array_equal(a["states"][name][key][...], b["states"][name][key][...]), (name, key)
        for group in ("glstat", "rwforc/1"):
            for key in a["history"][group]:
                assert np.array_equal(a["history"][group][key][...], b["history"][group][key][...]), (group, key)


@pytest.mark.xfail(reason="crashfree rejects *MAT_MODIFIED_HONEYCOMB in a meshfree part (ELFORM 41): "
                          "src/deck/deck_material_curves.f90", strict=False)
def test_honeycomb_in_meshfree_corner(decks, run_deck):
    run = run_deck(decks / "coupled.k", jobid="honeycomb")
    assert run.status == 0, run.stdout + run.stderr
