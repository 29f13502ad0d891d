"""ODB component test (inputs/odb_component, docs/examples/odb_component.md), reduced: 50 mm
elements, the cylinder pushed 60 mm into the barrier's upper-left corner (4 ms at 15 mm/ms), the
real model otherwise: honeycomb (*MAT_MODIFIED_HONEYCOMB) in the FE parts and in the meshfree
corner, aluminium cladding shells sharing the blocks' nodes, honeycomb self-contact. Two runs,
ncpu=1 and ncpu=2, about 6 s each.

Force band. The cylinder's end cap (radius R = 100 mm, axis at x = 70, y = 555) covers
A = 28,231 mm^2 of the barrier face (it overhangs the left edge by 30 mm and the top edge by
5 mm) and its rim runs r = 406 mm inside the face; the crush strength is
sigma_c = 0.342 MPa, so sigma_c A = 9.7 kN. The cap clears the bumper (y > 455 > 410), and it
meets the top cladding sheet (t = 0.81 mm, yield sigma_y = 180 MPa) edge-on along the chord
y = 650, L = 2 sqrt(R^2 - 95^2) = 62 mm long.

* Lower bound, after the first contact (t > 0.4 ms): the honeycomb under the cap crushes at
  sigma_c, so F > 0.5 sigma_c A = 4.8 kN. Half, because the cap's rim cuts through elements
  whose nodes it catches only partly, and the first layers load elastically.
* Upper bound: what can resist the cap at once. The honeycomb under the cap and within one
  element (h = 50 mm) outside the rim (the nodes the rim drags along), at the plateau:
  sigma_c (A + r h) = 16.6 kN (60 mm is 13% of the depth, far from densification), plus its
  inertia rho v^2 (A + r h) = 0.3 kN; the honeycomb sheared around the rim at the larger (L)
  transverse shear strength 1.5 sigma_c over r h: 10.4 kN; the cladding sheet squashed edge-on
  over its chord and, like the honeycomb, up to one element beyond it on either side (the cap
  holds the sheet at its nodes, which carry the sheet to the next node), sigma_y t (L + 2 h)
  = 23.7 kN (its elastic impact stress rho c v = 206 MPa exceeds the yield, so the sheet
  carries at most its squash load until it buckles). Together F < 51.0 kN.
The first contact itself (one sample at t = 0.07 ms, when the constraint wall brings the sheet's
edge nodes to 15 mm/ms in one cycle) is outside the band.
"""
import math
import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

REPOSITORY = Path(__file__).resolve().parents[2]
DECKS = REPOSITORY / "inputs" / "odb_component"
GENERATOR = DECKS / "generate_mesh.py"
BINARY = Path(os.environ.get("CRASHFREE", REPOSITORY / "bin" / "crashfree"))
sys.path.insert(0, str(REPOSITORY / "postproc"))

CRUSH_STRENGTH = 0.342e-3          # GPa
DENSITY = 28.6e-9                  # kg/mm^3
SPEED = 15.0                       # mm/ms
FOOTPRINT = 28231.0                # mm^2, printed by the generator for the default cylinder
RIM = 406.0                        # mm of the cap's rim inside the barrier face
ELEMENT = 50.0                     # mm, the reduced model's element size
SHEET = 0.18 * 0.81 * (2.0 * math.sqrt(100.0 ** 2 - 95.0 ** 2) + 2.0 * ELEMENT)   # kN, top sheet squashed
LOWER = 0.5 * CRUSH_STRENGTH * FOOTPRINT
UPPER = (CRUSH_STRENGTH + DENSITY * SPEED ** 2) * (FOOTPRINT + RIM * ELEMENT) \
    + 1.5 * CRUSH_STRENGTH * RIM * ELEMENT + SHEET
ENERGY_TOLERANCE = 0.05


def run_solver(deck: Path, output: Path, ncpu: int) -> subprocess.CompletedProcess:
    output.mkdir(parents=True, exist_ok=True)
    # passive waiting: on a shared 2-core machine, spinning threads of the ncpu=2 run would
    # otherwise wait on each other for minutes (results do not depend on it)
    environment = dict(os.environ, OMP_NUM_THREADS=str(ncpu), OMP_WAIT_POLICY="PASSIVE")
    return subprocess.run([str(BINARY), f"i={deck}", f"outdir={output}", f"ncpu={ncpu}"],
                          capture_output=True, text=True, timeout=600, env=environment)


@pytest.fixture(scope="module")
def decks(tmp_path_factory):
    directory = tmp_path_factory.mktemp("odb")
    subprocess.run([sys.executable, str(GENERATOR), "--size", "50", "--crush", "60", "-o", str(directory)],
                   check=True, capture_output=True, text=True)
    return directory


@pytest.fixture(scope="module")
def coupled_runs(decks):
    """The reduced coupled deck run with ncpu=1 and ncpu=2: {ncpu: results.h5 path}."""
    if not BINARY.exists():
        pytest.fail(f"{BINARY} is missing: build it with make")
    paths = {}
    for ncpu in (1, 2):
        output = decks / f"coupled_{ncpu}"
        process = run_solver(decks / "coupled.k", output, ncpu)
        assert process.returncode == 0, process.stdout + process.stderr
        paths[ncpu] = output / "results.h5"
    return paths


def test_shipped_decks_are_the_generator_output(tmp_path):
    """inputs/odb_component/*.k are what generate_mesh.py writes with its defaults (no drift)."""
    subprocess.run([sys.executable, str(GENERATOR), "-o", str(tmp_path)], check=True, capture_output=True, text=True)
    for name in ("mesh.k", "fe.k", "coupled.k"):
        assert (tmp_path / name).read_text() == (DECKS / name).read_text(), name


def test_decks_carry_honeycomb_cladding_and_efg(decks):
    text = (decks / "coupled.k").read_text()
    assert "*SECTION_SOLID_EFG" in text and "*INCLUDE\nmesh.k" in text
    assert text.count("*MAT_MODIFIED_HONEYCOMB") == 2 and "*SECTION_SHELL" in text
    assert "*SECTION_SOLID_EFG" not in (decks / "fe.k").read_text()
    mesh = (decks / "mesh.k").read_text().splitlines()
    start = mesh.index("*ELEMENT_SHELL")
    fields = [int(mesh[start + 1][k:k + 8]) for k in range(0, 48, 8)]
    assert fields[0] == 1 and fields[1] == 11 and len(mesh[start + 1].rstrip()) == 48


def test_shipped_fe_reference_matches_the_decks():
    import odb_component
    reference = odb_component.load_reference(DECKS / "fe_reference.npz")
    node_count = sum(1 for line in (DECKS / "mesh.k").read_text().split("*ELEMENT_SOLID")[0].splitlines()
                     if line[:8].strip().isdigit())
    assert len(reference["node_ids"]) == node_count
    assert reference["dofs_efg"] == 0 and "normal termination" in str(reference["status"])


def test_coupled_run_energy_and_force(coupled_runs):
    with h5py.File(coupled_runs[1], "r") as results:
        assert "normal termination" in str(results["run"].attrs["status"])
        timing = results["timing"].attrs
        assert 0.05 < timing["dofs_efg"] / timing["dofs_total"] < 0.10
        glstat = results["history/glstat"]
        total, work = glstat["total_energy"][...], glstat["external_work"][...]
        reference = total[0] + work
        loaded = reference > 1e-6 * reference[-1]        # before contact nothing moves: 0 / 0
        ratio = total[loaded] / reference[loaded]
        assert np.all(np.abs(ratio - 1.0) < ENERGY_TOLERANCE), (ratio.min(), ratio.max())
        hourglass, internal = glstat["hourglass_energy"][-1], glstat["internal_energy"][-1]
        assert hourglass < 0.15 * internal
        history = results["history/rwforc/1"]
        # the cylinder pushes the component down: LS-DYNA's rwforc (the wall's force on the
        # structure) is negative in z; the crush force is its opposite
        time, force = history["time"][...], -history["force"][...][:, 2]
    loaded = time > 0.1 * time[-1]
    assert force[loaded].min() > LOWER, (force[loaded].min(), LOWER)
    assert force[loaded].max() < UPPER, (force[loaded].max(), UPPER)


def test_coupled_run_identical_for_one_and_two_threads(coupled_runs):
    with h5py.File(coupled_runs[1], "r") as a, h5py.File(coupled_runs[2], "r") as b:
        assert sorted(a["states"].keys()) == sorted(b["states"].keys())
        for name in a["states"]:
            for key in a["states"][name]:
                assert np.array_equal(a["states"][name][key][...], b["states"][name][key][...]), (name, key)
        for group in ("glstat", "rwforc/1"):
            for key in a["history"][group]:
                assert np.array_equal(a["history"][group][key][...], b["history"][group][key][...]), (group, key)
