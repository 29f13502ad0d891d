""""Normal termination" can be trusted: runs that blow up, whose step collapses or jumps, that
would step past ENDTIM or that are stopped by a signal end with error termination (exit 1), a
message naming the node or element, its part, the time and the cycle, and a readable results
file whose values are finite; a sound run ends exactly at ENDTIM.

Units: mm, ms, kg, GPa. Steel: E = 210, nu = 0.3, rho = 7.85e-6, wave speed about 6000 mm/ms.
"""
import re
import signal
import subprocess
import time

import h5py
import numpy as np
import pytest

from conftest import BINARY, last_state
from test_contact import head_on_deck
from deck_writer import block_mesh, fields, nodes_card, plate_mesh, shells_card, solids_card, write_deck

STEEL = fields(1, 7.85e-6, 210.0, 0.3)


def one_hexahedron(path, end_time=1.0, kick=1.0, timestep=None, energy_change=None):
    """A free 10 mm steel cube whose node 8 starts at `kick` mm/ms along z."""
    nodes, elements = block_mesh((1, 1, 1), (10.0, 10.0, 10.0))
    blocks = ["*CONTROL_TERMINATION\n" + fields(end_time, None, None, energy_change)]
    if timestep is not None:
        blocks.append("*CONTROL_TIMESTEP\n" + timestep)
    return write_deck(path, *blocks, nodes_card(nodes), solids_card(elements),
                      "*PART\ncube\n" + fields(1, 1, 1), "*SECTION_SOLID\n" + fields(1, 1),
                      "*MAT_ELASTIC\n" + STEEL, "*INITIAL_VELOCITY_NODE\n" + fields(8, 0.0, 0.0, kick))


def all_finite(results):
    bad = []

    def visit(name, item):
        if isinstance(item, h5py.Dataset) and item.dtype.kind == "f" and not np.all(np.isfinite(item[...])):
            bad.append(name)

    results.visititems(visit)
    return bad


def assert_error_termination(run, pattern):
    assert run.status == 1, run.stdout + run.stderr
    assert "Fortran runtime error" not in run.stderr and "Backtrace" not in run.stderr, run.stderr
    found = re.search(pattern, run.stderr)
    assert found, run.stderr
    with run.open() as results:
        assert results["run"].attrs["status"] == "error termination"
        assert re.search(pattern, results["run"].attrs["message"])
        assert all_finite(results) == []
    return found


def test_initial_velocity_beyond_any_physical_run_stops_at_cycle_0(tmp_path, run_deck):
    """Two foam hexahedra, one node at 1e30 mm/ms (released builds gave NaN stresses and exit 0)."""
    nodes, elements = block_mesh((2, 1, 1), (20.0, 10.0, 10.0))
    curve = "\n".join(f"{s:20.6e}{t:20.6e}" for s, t in ((0.0, 0.0), (0.5, 0.001), (0.9, 0.1)))
    deck = write_deck(tmp_path / "foam.k", "*CONTROL_TERMINATION\n" + fields(0.01), nodes_card(nodes),
                      solids_card(elements, part_id=4), "*PART\nfoam\n" + fields(4, 1, 1), "*SECTION_SOLID\n" + fields(1, 1),
                      "*MAT_LOW_DENSITY_FOAM\n" + fields(1, 5.0e-8, 0.01, 1) + "\n" + fields(),
                      "*DEFINE_CURVE\n" + fields(1) + "\n" + curve,
                      "*INITIAL_VELOCITY_NODE\n" + fields(3, 0.0, 0.0, 1.0e30))
    run = run_deck(deck)
    assert_error_termination(run, r"node 3 \(part 4\) starts with the velocity .* at time 0\.00000E\+00, cycle 0")
    with run.open() as results:
        assert len(results["states"]) == 1


def test_unstable_shells_stop_with_the_node_part_and_time(tmp_path, run_deck):
    """Four shells with one node at 1e5 mm/ms: released builds stepped to t = 0.6 past ENDTIM
    and reported a negative kinetic energy of 1e44 with exit 0."""
    nodes, shells = plate_mesh((2, 2), (20.0, 20.0))
    deck = write_deck(tmp_path / "shells.k", "*CONTROL_TERMINATION\n" + fields(1.0), nodes_card(nodes),
                      shells_card(shells, part_id=2), "*PART\nplate\n" + fields(2, 1, 1),
                      "*SECTION_SHELL\n" + fields(1, 2, 0.8333, 3) + "\n" + fields(1.0, 1.0, 1.0, 1.0),
                      "*MAT_ELASTIC\n" + STEEL, "*INITIAL_VELOCITY_NODE\n" + fields(5, 0.0, 0.0, 1.0e5))
    run = run_deck(deck)
    found = assert_error_termination(run, r"node \d+ \(part 2\) would reach the (angular )?velocity .* the run has "
                                          r"become unstable at time ([0-9.E+-]+), cycle (\d+)")
    with run.open() as results:
        assert last_state(results).attrs["time"] == pytest.approx(float(found.group(2)), rel=1e-5)
        assert results["run"].attrs["end_time"] <= 1.0
        assert results["history/glstat/time"][-1] <= 1.0


def test_the_last_step_ends_at_endtim(tmp_path, run_deck):
    run = run_deck(one_hexahedron(tmp_path / "cube.k", end_time=0.0123))
    assert run.status == 0, run.stderr
    with run.open() as results:
        assert results["run"].attrs["end_time"] == 0.0123
        assert results["history/glstat/time"][-1] == 0.0123
        assert last_state(results).attrs["time"] == 0.0123
        steps = np.diff(results["history/glstat/time"][...])
        assert steps.min() > 0.0
        glstat = results["history/glstat"]
        total = glstat["total_energy"][...]
        assert abs(total[-1] / total[0] - 1.0) < 1e-3


def test_steps_beyond_twice_the_stable_step_are_refused(tmp_path, run_deck):
    """TSSFAC 9e99 was accepted and took one step to t = 1.5e96 (such a value is now refused by
    the reader, as any beyond 1e30); a TSSFAC of 1e6 would step to ENDTIM at once: a step beyond
    twice the stable one stops the run (TSSFAC above 1 is warned about)."""
    run = run_deck(one_hexahedron(tmp_path / "cube.k", timestep=fields(None, 1.0e6)))
    assert "field TSSFAC" in run.stderr
    assert_error_termination(run, r"the next time step 1\.0000E\+00 is .* times the stable step \(set by solid "
                                  r"element 1 \(part 1\); TSSFAC 1\.0000E\+06\)")


def test_tssfac_above_one_blows_up_and_is_stopped(tmp_path, run_deck):
    run = run_deck(one_hexahedron(tmp_path / "cube.k", timestep=fields(None, 1.5)))
    assert "field TSSFAC" in run.stderr
    assert_error_termination(run, r"(solid element 1 \(part 1\)|node \d+ \(part 1\))")


def test_mass_scaling_beyond_endmas_is_an_error(tmp_path, run_deck):
    run = run_deck(one_hexahedron(tmp_path / "cube.k", end_time=0.001, timestep=fields(None, None, None, None, 10.0)))
    assert_error_termination(run, r"mass scaling \(DT2MS\) adds .* more than ENDMAS = 1\.0000E\+08 percent")


def squeezed_cube(path, minimum_step_factor=None):
    """A soft unit cube whose top face is pushed down by its whole height in 1 ms: its stable step
    falls without bound as it flattens."""
    nodes, elements = block_mesh((1, 1, 1), (1.0, 1.0, 1.0))
    top = [n + 1 for n in range(8) if nodes[n, 2] > 0.5]
    bottom = [n + 1 for n in range(8) if nodes[n, 2] < 0.5]
    return write_deck(path, "*CONTROL_TERMINATION\n" + fields(1.0, None, minimum_step_factor),
                      "*PART\ncube\n" + fields(3, 1, 1), "*SECTION_SOLID\n" + fields(1, 1),
                      "*MAT_ELASTIC\n" + fields(1, 7.85e-6, 1.0, 0.3),
                      "*DEFINE_CURVE\n" + fields(1) + f"\n{0.0:20.6e}{0.0:20.6e}\n{1.0:20.6e}{1.0:20.6e}",
                      nodes_card(nodes), solids_card(elements, part_id=3, first_id=5),
                      "*BOUNDARY_SPC_NODE\n" + "\n".join(fields(n, 0, 1, 1, 1, 0, 0, 0) for n in bottom),
                      "*BOUNDARY_PRESCRIBED_MOTION_NODE\n" + "\n".join(fields(n, 3, 2, 1, -1.0) for n in top))


def test_a_collapsing_time_step_is_reported_and_dtmin_stops_it(tmp_path, run_deck):
    run = run_deck(squeezed_cube(tmp_path / "squeeze.k", 0.01))
    found = assert_error_termination(run, r"the time step ([0-9.E+-]+) fell below DTMIN \(1\.0000E-02\) times the "
                                          r"first step ([0-9.E+-]+) \(set by solid element 5 \(part 3\)\)")
    assert float(found.group(1)) < 0.01 * float(found.group(2))
    warnings = re.findall(r"warning: t = .*: the time step .* has fallen to ([0-9.E+-]+) times the first step .*"
                          r"solid element 5 \(part 3\)", run.stdout)
    assert len(warnings) == 1 and 0.01 < float(warnings[0]) < 0.1, run.stdout


def test_without_dtmin_every_decade_of_the_falling_step_is_reported(tmp_path, run_deck):
    run = run_deck(squeezed_cube(tmp_path / "squeeze.k"))
    fractions = [float(f) for f in re.findall(r"has fallen to ([0-9.E+-]+) times the first step", run.stdout)]
    assert len(fractions) >= 3, run.stdout
    for decade, fraction in enumerate(fractions, start=1):
        assert 10.0**-(decade + 1) < fraction < 1.0001 * 10.0**-decade   # printed with 5 digits
    # the flattened cube ends the run one way or the other, never with a lie
    assert run.status == 1
    with run.open() as results:
        assert all_finite(results) == []


def test_endeng_stops_a_run_whose_energy_ratio_drifts(tmp_path, run_deck):
    """Two blocks meeting head on through penalty contact: the springs' work is integrated with an
    error of about 1e-4 of the impact energy, so an ENDENG of 1e-6 percent stops the run once they
    touch, and one of 10 percent lets it end normally."""
    deck, *_ = head_on_deck(tmp_path / "head_on.k")
    text = deck.read_text()
    deck.write_text(text.replace("*CONTROL_TERMINATION\n" + fields(0.03),
                                 "*CONTROL_TERMINATION\n" + fields(0.03, None, None, 1e-6)))
    run = run_deck(deck)
    found = assert_error_termination(run, r"the energy ratio .* differs from 1 by more than ENDENG = 1\.0000E-06 "
                                          r"percent at time ([0-9.E+-]+)")
    assert 0.0 < float(found.group(1)) < 0.03
    deck.write_text(text.replace("*CONTROL_TERMINATION\n" + fields(0.03),
                                 "*CONTROL_TERMINATION\n" + fields(0.03, None, None, 10.0)))
    assert run_deck(deck, jobid="loose").status == 0


def long_run_deck(path):
    """A 12 x 12 x 12 steel block hitting a wall for long enough that a signal finds it running."""
    nodes, elements = block_mesh((12, 12, 12), (12.0, 12.0, 12.0), origin=(0.0, 0.0, 0.1))
    return write_deck(path, "*CONTROL_TERMINATION\n" + fields(100.0), "*DATABASE_BINARY_D3PLOT\n" + fields(1.0),
                      "*PART\nblock\n" + fields(1, 1, 1), "*SECTION_SOLID\n" + fields(1, 1),
                      "*MAT_ELASTIC\n" + STEEL, "*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields(0.0, 0.0, -1.0),
                      "*RIGIDWALL_PLANAR\n" + fields(0) + "\n" + fields(0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
                      nodes_card(nodes), solids_card(elements))


@pytest.mark.parametrize("signal_number,name", [(signal.SIGINT, "SIGINT"), (signal.SIGTERM, "SIGTERM")])
def test_a_stop_signal_ends_the_run_with_its_results(tmp_path, signal_number, name):
    deck = long_run_deck(tmp_path / "block.k")
    output = tmp_path / "out"
    # (a test run started in the background inherits SIGINT ignored, as shells do for
    # background jobs, and the solver keeps an ignored signal ignored: give it the default)
    process = subprocess.Popen([str(BINARY), f"i={deck}", f"outdir={output}", "ncpu=1"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    results_path = output / "results.h5"
    deadline = time.time() + 60.0
    while time.time() < deadline and not results_path.exists():
        time.sleep(0.05)
    time.sleep(0.5)
    process.send_signal(signal.SIGUSR2)
    time.sleep(0.3)
    process.send_signal(signal_number)
    stdout, stderr = process.communicate(timeout=60)
    assert process.returncode == 1, stdout + stderr
    found = re.search(rf"stopped by {name} at time ([0-9.E+-]+), cycle (\d+)", stderr)
    assert found, stderr
    assert "error termination" in stdout
    # SIGUSR2 printed a progress line before the end (besides the header and the last line)
    assert len(re.findall(r"^\s+\d+\s+[0-9.E+-]+\s+[0-9.E+-]+\s+[0-9.]+%", stdout, re.M)) >= 2, stdout
    with h5py.File(results_path, "r") as results:
        assert results["run"].attrs["status"] == "error termination"
        assert name in results["run"].attrs["message"]
        assert results["run"].attrs["cycles"] == int(found.group(2)) > 0
        assert last_state(results).attrs["time"] == pytest.approx(float(found.group(1)), rel=1e-5)
        assert results["timing"].attrs["wall_s"] > 0.0
        assert all_finite(results) == []
