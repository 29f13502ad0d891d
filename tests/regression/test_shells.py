"""Belytschko-Tsay shells (*SECTION_SHELL ELFORM 2): the static deflection and first bending
frequency of a clamped strip against beam theory, the energy balance, a membrane patch test on
an irregular mesh in a tilted plane, a free spin (the corotational frame keeps rigid rotations
strain-free), and identical results for one and two threads."""
import numpy as np
import pytest

from conftest import last_state
from deck_writer import fields, nodes_card, plate_mesh, round_to_node_card, shells_card, write_deck

# steel strip, mm ms kg kN GPa
LENGTH, WIDTH, THICKNESS = 100.0, 10.0, 1.0
YOUNGS, POISSON, DENSITY = 210.0, 0.3, 7.85e-6
TIP_LOAD = 1.0e-4
SECOND_MOMENT = WIDTH * THICKNESS**3 / 12.0


def cantilever_deck(path, end_time=40.0, cells=(20, 2), hourglass=1):
    """The strip clamped at x = 0 (all six dofs) with a constant tip load P along z from t = 0,
    shared by the tip nodes as a consistent edge load."""
    nodes, shells = plate_mesh(cells, (LENGTH, WIDTH))
    nodes = round_to_node_card(nodes)
    root = np.flatnonzero(np.isclose(nodes[:, 0], 0.0))
    tip = np.flatnonzero(np.isclose(nodes[:, 0], LENGTH))
    tip_middle = tip[np.argmin(np.abs(nodes[tip, 1] - WIDTH / 2))]
    spc = ["*BOUNDARY_SPC_NODE"] + [fields(k + 1, 0, 1, 1, 1, 1, 1, 1) for k in root]
    loads = ["*LOAD_NODE_POINT"]
    for k in tip:
        share = 0.5 if np.isclose(nodes[k, 1], 0.0) or np.isclose(nodes[k, 1], WIDTH) else 1.0
        loads.append(fields(k + 1, 3, 1, f"{TIP_LOAD * share / cells[1]:10.4e}"))
    write_deck(
        path,
        "*TITLE\nshell cantilever",
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*CONTROL_TIMESTEP\n" + fields(0.0, 0.9),
        "*DATABASE_GLSTAT\n" + fields(0.05),
        "*DATABASE_NODOUT\n" + fields(0.05),
        "*DATABASE_HISTORY_NODE\n" + fields(tip_middle + 1),
        "*DATABASE_BINARY_D3PLOT\n" + fields(end_time / 4),
        "*PART\nstrip\n" + fields(1, 1, 1, 0, 1),
        "*SECTION_SHELL\n" + fields(1, 2, f"{5 / 6:10.7f}", 3) + "\n" + fields(THICKNESS, THICKNESS, THICKNESS,
                                                                           THICKNESS),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
        "*HOURGLASS\n" + fields(1, hourglass, 0.1),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + f"{0.0:20.6e}{1.0:20.6e}\n{1000.0:20.6e}{1.0:20.6e}",
        nodes_card(nodes),
        shells_card(shells),
        "\n".join(spc),
        "\n".join(loads),
    )
    return path


@pytest.fixture(scope="module")
def cantilever(tmp_path_factory):
    """One run shared by the cantilever checks: a step load, so the tip swings about its static
    deflection at the first bending frequency."""
    import subprocess, os
    from conftest import BINARY, Run
    directory = tmp_path_factory.mktemp("cantilever")
    deck = cantilever_deck(directory / "cantilever.k")
    process = subprocess.run([str(BINARY), f"i={deck}", f"outdir={directory}", "ncpu=1"],
                             capture_output=True, text=True, timeout=600,
                             env=dict(os.environ, OMP_NUM_THREADS="1"))
    run = Run(process, directory / "results.h5")
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        node = next(iter(results["history/nodout"]))
        history = {"time": results["history/nodout"][node]["time"][...],
                   "tip": results["history/nodout"][node]["displacement"][:, 2]}
        history["glstat"] = {name: results["history/glstat"][name][...] for name in results["history/glstat"]}
    return history


def whole_periods(time, signal):
    """Upward crossings of the signal's mean: the times that bound whole periods."""
    mean = signal.mean()
    above = signal > mean
    return time[1:][~above[:-1] & above[1:]]


def test_cantilever_static_deflection_within_3_percent_of_beam_theory(cantilever):
    crossings = whole_periods(cantilever["time"], cantilever["tip"])
    assert len(crossings) >= 3
    window = (cantilever["time"] >= crossings[0]) & (cantilever["time"] < crossings[-1])
    mean_deflection = cantilever["tip"][window].mean()
    beam = TIP_LOAD * LENGTH**3 / (3.0 * YOUNGS * SECOND_MOMENT)
    # a step load swings the tip about the static deflection: the mean over whole periods
    assert abs(mean_deflection / beam - 1.0) < 0.03, f"mean tip deflection {mean_deflection:.5f}, beam {beam:.5f}"


def test_cantilever_first_bending_frequency_within_3_percent(cantilever):
    crossings = whole_periods(cantilever["time"], cantilever["tip"])
    frequency = 1.0 / np.diff(crossings).mean()
    mass_per_length = DENSITY * WIDTH * THICKNESS
    euler_bernoulli = 1.875104**2 / (2.0 * np.pi) * np.sqrt(YOUNGS * SECOND_MOMENT / (mass_per_length * LENGTH**4))
    assert abs(frequency / euler_bernoulli - 1.0) < 0.03, f"{frequency:.5f} kHz against {euler_bernoulli:.5f}"


def test_cantilever_energy_balance(cantilever):
    glstat = cantilever["glstat"]
    imbalance = glstat["total_energy"] - glstat["total_energy"][0] - glstat["external_work"]
    assert np.abs(imbalance).max() < 1e-5 * glstat["external_work"].max()
    assert glstat["kinetic_energy"].min() >= 0.0 and glstat["internal_energy"][-1] > 0.0


# in-plane velocity gradient of the membrane patch test, in plane coordinates
MEMBRANE_GRADIENT = np.array([[0.010, 0.004], [-0.003, -0.006]])
PLANE_AXES = np.linalg.qr(np.array([[1.0, 0.3, 0.4], [-0.2, 1.0, 0.5], [0.1, -0.3, 1.0]]).T)[0]


def test_membrane_patch_test_on_a_tilted_irregular_mesh(tmp_path, run_deck):
    """v = A X in the plane of an irregular mesh that lies in a tilted plane, prescribed on the
    boundary: every interior node keeps it to 1e-10 relative, with no hourglass energy."""
    flat, shells = plate_mesh((4, 4), (1.0, 1.0), perturbation=0.25, seed=3)
    # full precision in comma format: rounding to the 16-column card would warp the elements
    # out of the tilted plane by 1e-10 and the one-point element is exact only for flat ones
    nodes = flat @ PLANE_AXES.T
    plane = nodes @ PLANE_AXES                      # coordinates in the plane's axes (z = 0)
    velocity = (plane[:, :2] @ MEMBRANE_GRADIENT.T) @ PLANE_AXES[:, :2].T
    boundary = np.flatnonzero(np.isclose(flat[:, 0], 0) | np.isclose(flat[:, 0], 1) |
                              np.isclose(flat[:, 1], 0) | np.isclose(flat[:, 1], 1))
    initial = ["*INITIAL_VELOCITY_NODE+"] + [f"{k + 1:20d}{v[0]:20.13e}{v[1]:20.13e}{v[2]:20.13e}"
                                               for k, v in enumerate(velocity)]
    motion = ["*BOUNDARY_PRESCRIBED_MOTION_NODE+"]
    for k in boundary:
        for direction in range(3):
            value = velocity[k, direction]
            curve, scale = (1, value) if value != 0.0 else (2, 1.0)
            motion.append(f"{k + 1:20d}{direction + 1:20d}{0:20d}{curve:20d}{scale:20.13e}")
    deck = write_deck(
        tmp_path / "membrane_patch.k",
        "*TITLE\nmembrane patch test",
        "*CONTROL_TERMINATION\n" + fields(1.0, 100),
        "*CONTROL_TIMESTEP\n" + fields(0.0, 0.9),
        "*DATABASE_GLSTAT\n" + fields(1.0e-4),
        "*DATABASE_BINARY_D3PLOT\n" + fields(1.0),
        "*PART\nsheet\n" + fields(1, 1, 1, 0, 1),
        "*SECTION_SHELL\n" + fields(1, 2, 1.0, 3) + "\n" + fields(0.05, 0.05, 0.05, 0.05),
        "*MAT_ELASTIC\n" + fields(1, 7.8e-6, 210.0, 0.3),
        "*HOURGLASS\n" + fields(1, 4, 0.1),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + f"{0.0:20.6e}{1.0:20.6e}\n{10.0:20.6e}{1.0:20.6e}",
        "*DEFINE_CURVE\n" + fields(2) + "\n" + f"{0.0:20.6e}{0.0:20.6e}\n{10.0:20.6e}{0.0:20.6e}",
        "*NODE\n" + "\n".join(f"{k + 1},{float(x)!r},{float(y)!r},{float(z)!r}" for k, (x, y, z) in enumerate(nodes)),
        shells_card(shells),
        "\n".join(initial),
        "\n".join(motion),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        assert results["run"].attrs["cycles"] == 100
        final = last_state(results)["velocity"][...]
        glstat = {name: results["history/glstat"][name][...] for name in results["history/glstat"]}
        stress = last_state(results)["shell_stress"][...]
    interior = np.setdiff1d(np.arange(len(nodes)), boundary)
    assert len(interior) == 9
    error = np.abs(final[interior] - velocity[interior]).max() / np.abs(velocity).max()
    assert error < 1e-10, f"interior velocity error {error:.3e}"
    assert abs(glstat["hourglass_energy"][-1]) <= 1e-10 * glstat["internal_energy"][-1]
    # a uniform membrane state: every element carries the same stress
    assert np.abs(stress - stress.mean(axis=0)).max() < 1e-8 * np.abs(stress).max()


def test_free_spin_stays_strain_free(tmp_path, run_deck):
    """A square plate spinning about its normal at 50 rad/ms for 2000 cycles: its kinetic energy
    stays constant and its strain energy at round-off relative to it."""
    nodes, shells = plate_mesh((6, 6), (1.0, 1.0), perturbation=0.2, seed=5)
    nodes = round_to_node_card(nodes - [0.5, 0.5, 0.0])
    spin = 50.0
    velocity = spin * np.stack([-nodes[:, 1], nodes[:, 0], np.zeros(len(nodes))], axis=1)
    initial = ["*INITIAL_VELOCITY_NODE+"] + [f"{k + 1:20d}{v[0]:20.13e}{v[1]:20.13e}{v[2]:20.13e}"
                                               for k, v in enumerate(velocity)]
    deck = write_deck(
        tmp_path / "spin.k",
        "*TITLE\nfree spin",
        "*CONTROL_TERMINATION\n" + fields(1.0, 2000),
        "*CONTROL_TIMESTEP\n" + fields(0.0, 0.9),
        "*DATABASE_GLSTAT\n" + fields(1.0e-4),
        "*PART\nsheet\n" + fields(1, 1, 1),
        "*SECTION_SHELL\n" + fields(1, 2, 1.0, 2) + "\n" + fields(0.02, 0.02, 0.02, 0.02),
        "*MAT_ELASTIC\n" + fields(1, 7.8e-6, 210.0, 0.3),
        nodes_card(nodes),
        shells_card(shells),
        "\n".join(initial),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        glstat = {name: results["history/glstat"][name][...] for name in results["history/glstat"]}
    kinetic = glstat["kinetic_energy"]
    # central differences turn the nodes along chords: the radius grows by O((w dt)^2) per
    # step, which the membrane resists; the energy it takes stays tiny
    assert np.abs(kinetic / kinetic[0] - 1.0).max() < 1e-4
    assert np.abs(glstat["internal_energy"]).max() < 1e-4 * kinetic[0]
    assert np.abs(glstat["total_energy"] / glstat["total_energy"][0] - 1.0).max() < 1e-10


def test_one_and_two_threads_give_identical_shell_results(tmp_path, run_deck):
    from test_threads import datasets
    deck = cantilever_deck(tmp_path / "cantilever.k", end_time=2.0)
    one = run_deck(deck, ncpu=1)
    two = run_deck(deck, ncpu=2)
    assert one.status == 0 and two.status == 0, one.stderr + two.stderr
    with one.open() as first, two.open() as second:
        a, b = datasets(first), datasets(second)
        assert first["mesh/shells/ids"].shape == (40,)
    for name in a:
        assert np.array_equal(a[name], b[name]), f"{name} differs between 1 and 2 threads"
