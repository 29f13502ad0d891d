"""Side-impact dummy component test (inputs/side_impact, docs/examples/side_impact.md), reduced:
the shipped model (10 mm elements) run to END_TIME = 5 ms instead of 60 ms, the door's first
40 mm into the thorax (the force rises to about 12 kN of its 16.5 kN peak at 10.6 ms).

FE run (fe.k):
* Momentum: the door is a rigid body that touches nothing but the thorax, through contact 1, so
  its momentum change equals the contact impulse: M_door (v_end - v_0) = integral of the
  contact force (rcforc/1, y). 2%: the impulse is the trapezoidal rule on the rcforc samples
  (every END_TIME / 600), the velocity is exact.
* Force band: the reduced run is the full run stopped early, so its force follows the full
  run's measured curve (`make side-impact`, docs/examples/side_impact.md). The contact force
  chatters (the rigid door knocks the light jacket nodes ahead of it: single samples jump by a
  factor 2), so the band is on its mean over each millisecond, the window's contact impulse:
  within 5% plus 0.1 kN of the full run's mean force in that window, FULL_RUN_MEAN_FORCE below,
  M_door times the change of the door's velocity over the window (rbdout/2 of
  results/side_impact/fe/results.h5, exact where the sampled force is not).
  Physical bounds as well: a contact only pushes (force >= 0); the door first touches the jacket
  at 0.25 ms (the 2 mm gap at 8 mm/ms), knocks the light jacket nodes ahead of it, touches
  again, and pushes from 1.5 ms on (force > 0); and, a sanity ceiling, the mean force of each
  window stays below what would stop the 40 kg door within the 25 mm of foam plus the 2 mm
  gap: 0.5 M v^2 / 27 mm = 47 kN (single samples of the chattering force reach 50 kN).

Coupled run (coupled.k, rib foams meshfree solids and jacket meshfree shells), to
COUPLED_END_TIME = 3 ms (the force has risen to 5.6 kN, the internal energy to about 50 J of
the door's 1,280 J of kinetic energy): energy ratio
within 5% at every sample (nothing is pushed in from outside: the door's initial kinetic
energy is the whole budget), hourglass energy under 10% of the internal energy (only FE parts
have hourglass modes: the spine and door are rigid, the rib bands are FE shells), the meshfree
solids and shells both with interior particles, and ncpu 1 and 2 bit-identical.
"""
import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

REPOSITORY = Path(__file__).resolve().parents[2]
DECKS = REPOSITORY / "inputs" / "side_impact"
GENERATOR = DECKS / "generate_side_impact.py"
BINARY = Path(os.environ.get("CRASHFREE", REPOSITORY / "bin" / "crashfree"))

END_TIME = 5.0                      # ms, the FE run
COUPLED_END_TIME = 3.0              # ms, the coupled runs (each costs about 6 times the FE run per ms)
DOOR_MASS = 40.0                    # kg
SPEED = 8.0                         # mm/ms
GAP = 2.0                           # mm
FOAM = 25.0                         # mm
#: the full FE run's mean contact force (kN) over the 1 ms windows starting at 0, 1, 2, 3, 4 ms:
#: 40 kg x the door's velocity change in the window (`make side-impact`, results/side_impact/fe)
FULL_RUN_MEAN_FORCE = (1.545, 1.903, 3.685, 8.283, 11.778)
FORCE_TOLERANCE = 0.05
UPPER = 0.5 * DOOR_MASS * SPEED ** 2 / (FOAM + GAP)       # kN: J / mm (kg mm^2/ms^2 = J)


def run_solver(deck: Path, output: Path, ncpu: int) -> subprocess.CompletedProcess:
    output.mkdir(parents=True, exist_ok=True)
    environment = dict(os.environ, OMP_NUM_THREADS=str(ncpu), OMP_WAIT_POLICY="PASSIVE",
                       CRASHFREE_OVERSUBSCRIBE="1")
    return subprocess.run([str(BINARY), f"i={deck}", f"outdir={output}", f"ncpu={ncpu}"],
                          capture_output=True, text=True, timeout=600, env=environment)


@pytest.fixture(scope="module")
def decks(tmp_path_factory):
    directory = tmp_path_factory.mktemp("side_impact")
    subprocess.run([sys.executable, str(GENERATOR), "--end-time", str(END_TIME), "--states", "5",
                    "-o", str(directory)], check=True, capture_output=True, text=True)
    return directory


@pytest.fixture(scope="module")
def coupled_decks(tmp_path_factory):
    directory = tmp_path_factory.mktemp("side_impact_coupled")
    subprocess.run([sys.executable, str(GENERATOR), "--end-time", str(COUPLED_END_TIME), "--states", "3",
                    "-o", str(directory)], check=True, capture_output=True, text=True)
    return directory


@pytest.fixture(scope="module")
def fe_run(decks):
    if not BINARY.exists():
        pytest.fail(f"{BINARY} is missing: build it with make")
    process = run_solver(decks / "fe.k", decks / "fe", 1)
    assert process.returncode == 0, process.stdout + process.stderr
    return decks / "fe" / "results.h5"


@pytest.fixture(scope="module")
def coupled_runs(coupled_decks):
    if not BINARY.exists():
        pytest.fail(f"{BINARY} is missing: build it with make")
    paths = {}
    for ncpu in (1, 2):
        output = coupled_decks / f"coupled_{ncpu}"
        process = run_solver(coupled_decks / "coupled.k", output, ncpu)
        assert process.returncode == 0, process.stdout + process.stderr
        paths[ncpu] = output / "results.h5"
    return paths


def test_shipped_decks_are_the_generator_output(tmp_path):
    """inputs/side_impact/*.k are what the generator writes with its defaults (no drift)."""
    subprocess.run([sys.executable, str(GENERATOR), "-o", str(tmp_path)], check=True, capture_output=True, text=True)
    for name in ("mesh.k", "fe.k", "ribs_efg.k", "coupled.k"):
        assert (tmp_path / name).read_text() == (DECKS / name).read_text(), name


def test_decks_differ_only_in_the_foam_and_jacket_sections(decks):
    fe, ribs, coupled = ((decks / f"{name}.k").read_text() for name in ("fe", "ribs_efg", "coupled"))
    assert "*SECTION_SOLID_EFG" not in fe and "ELFORM 41" not in fe
    assert ribs.count("*SECTION_SOLID_EFG") == 1 and coupled.count("*SECTION_SOLID_EFG") == 1
    jacket = coupled.split("meshfree jacket\n")[1].splitlines()
    assert int(jacket[1][10:20]) == 41            # *SECTION_SHELL ELFORM 41 ...
    assert jacket[5].split()[:2] == ["1.1", "1.1"]  # ... and its EFG card DX DY
    for text in (fe, ribs, coupled):
        assert "*INCLUDE\nmesh.k" in text and text.count("*CONTACT_AUTOMATIC") == 2


def test_fe_door_momentum_equals_contact_impulse(fe_run):
    with h5py.File(fe_run, "r") as results:
        assert "normal termination" in str(results["run"].attrs["status"])
        contact = results["history/rcforc/1"]
        time, force = contact["time"][...], -contact["force"][...][:, 1]
        velocity = results["history/rbdout/2/velocity"][...][:, 1]
    impulse = np.trapezoid(force, time)
    momentum = DOOR_MASS * (velocity[-1] - velocity[0])
    assert impulse > 10.0, impulse                # the door did hit the thorax
    assert abs(impulse - momentum) < 0.02 * impulse, (impulse, momentum)
    assert velocity[0] == pytest.approx(-SPEED)


def test_fe_force_follows_the_full_run(fe_run):
    with h5py.File(fe_run, "r") as results:
        contact = results["history/rcforc/1"]
        time, force = contact["time"][...], -contact["force"][...][:, 1]
    assert force.min() >= 0.0
    assert force[time > 1.5].min() > 0.0
    for start, expected in enumerate(FULL_RUN_MEAN_FORCE):
        window = (time >= start - 1e-9) & (time <= start + 1.0 + 1e-9)
        mean = np.trapezoid(force[window], time[window]) / (time[window][-1] - time[window][0])
        assert abs(mean - expected) < FORCE_TOLERANCE * expected + 0.1, (start, mean, expected)
        assert mean < UPPER


def test_coupled_energy_balance_and_hourglass(coupled_runs):
    with h5py.File(coupled_runs[1], "r") as results:
        assert "normal termination" in str(results["run"].attrs["status"])
        timing = results["timing"].attrs
        assert timing["efg_particles"] > 0 and timing["efg_shell_particles"] > 0
        glstat = results["history/glstat"]
        total, work = glstat["total_energy"][...], glstat["external_work"][...]
        ratio = total / (total[0] + work)
        assert np.all(np.abs(ratio - 1.0) < 0.05), (ratio.min(), ratio.max())
        internal, hourglass = glstat["internal_energy"][-1], glstat["hourglass_energy"][-1]
        assert internal > 0.02 * glstat["kinetic_energy"][0]     # the thorax is being crushed
        assert hourglass < 0.10 * internal, (hourglass, internal)


def test_coupled_run_identical_for_one_and_two_threads(coupled_runs):
    with h5py.File(coupled_runs[1], "r") as a, h5py.File(coupled_runs[2], "r") as b:
        assert sorted(a["states"].keys()) == sorted(b["states"].keys())
        for name in a["states"]:
            for key in a["states"][name]:
                assert np.array_equal(a["states"][name][key][...], b["states"][name][key][...]), (name, key)
        for group in ("glstat", "rcforc/1", "rbdout/2"):
            for key in a["history"][group]:
                assert np.array_equal(a["history"][group][key][...], b["history"][group][key][...]), (group, key)
