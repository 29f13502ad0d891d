"""Free vibration of a clamped strip of Belytschko-Tsay shells for Poisson ratios from 0 to
0.45: the first bending period against Euler-Bernoulli beam theory, the time step against the
membrane rule, and the total energy.

The strip is the one of test_shells.py (100 x 10 x 1 mm, 20 x 2 shells, NIP 3, SHRF 5/6,
elastic steel) clamped at x = 0 and started with the velocity of its first beam mode. With the
rotary inertia of the element before docs/shells.md "Mass and time step" (m (t^2 + A) / 12) it
stopped with "shell element ... has lost its area" within 50 cycles at nu = 0 and 0.01 and
within 170 at nu = 0.1: the transverse shear mode (the nodes' rotation about the strip's axis
against the deflection across its width) had omega^2 = SHRF G / rho (4 / L^2 + 12 / (t^2 + A))
per element, above the membrane's (2 c / L)^2 once G / (E / (1 - nu^2)) is large, i.e. at small
nu; the lumped-mass eigenvalues of the strip put its critical step at 0.84 L/c (nu = 0),
0.89 L/c (0.1) and 0.94 L/c (0.2), below or at TSSFAC 0.9.

Free shells in their plane: a lone shell's areal mode (u = x, v = y) has omega^2 = (1 + nu)
(2 c / L)^2, so the membrane rule L / c alone let it grow at TSSFAC 0.9 for nu = 0.3; the shells
with two or more corners that no other shell shares (a lone shell, a pair, the ends of a single
row) take the membrane eigenvalue bound too. numpy builds the in-plane stiffness (one-point
membrane and the IHQ 4 hourglass stiffness) and lumped masses of small free meshes; the
solver's step with TSSFAC 1 must be at or below 2 / omega_max of them."""
import numpy as np
import pytest

from deck_writer import fields, nodes_card, plate_mesh, round_to_node_card, shells_card, write_deck

LENGTH, WIDTH, THICKNESS = 100.0, 10.0, 1.0
YOUNGS, DENSITY = 210.0, 7.85e-6
CELLS = (20, 2)
BETA_L = 1.8751040687                      # first root of cos x cosh x = -1
SPEED = 0.1                                # tip speed at t = 0, mm/ms
PERIODS = 3
# measured: period / Euler-Bernoulli 1.0005-1.0023 over the six ratios (20 elements, rotary
# inertia and the plate action of a strip ten thicknesses wide), energy drift 1e-13
PERIOD_TOLERANCE = 0.005


def mode_shape(x):
    """First mode of a clamped-free Euler-Bernoulli beam."""
    b = BETA_L * x / LENGTH
    s = (np.cosh(BETA_L) + np.cos(BETA_L)) / (np.sinh(BETA_L) + np.sin(BETA_L))
    return np.cosh(b) - np.cos(b) - s * (np.sinh(b) - np.sin(b))


def beam_period():
    """2 pi / omega_1, omega_1 = (beta L)^2 sqrt(E I / (rho A L^4)) (E, not E / (1 - nu^2): the
    strip is narrow, its cross-section curves freely)."""
    second_moment = WIDTH * THICKNESS**3 / 12.0
    omega = BETA_L**2 * np.sqrt(YOUNGS * second_moment / (DENSITY * WIDTH * THICKNESS * LENGTH**4))
    return 2.0 * np.pi / omega


def strip_deck(path, poisson):
    nodes, shells = plate_mesh(CELLS, (LENGTH, WIDTH))
    nodes = round_to_node_card(nodes)
    root = np.flatnonzero(np.isclose(nodes[:, 0], 0.0))
    tip = np.flatnonzero(np.isclose(nodes[:, 0], LENGTH))
    tip_middle = tip[np.argmin(np.abs(nodes[tip, 1] - WIDTH / 2))]
    velocity = SPEED * mode_shape(nodes[:, 0]) / mode_shape(LENGTH)
    period = beam_period()
    write_deck(
        path,
        "*TITLE\nclamped strip in free vibration",
        "*CONTROL_TERMINATION\n" + fields(PERIODS * period),
        "*CONTROL_TIMESTEP\n" + fields(0.0, 0.9),
        "*DATABASE_GLSTAT\n" + fields(period / 200),
        "*DATABASE_NODOUT\n" + fields(period / 400),
        "*DATABASE_HISTORY_NODE\n" + fields(tip_middle + 1),
        "*PART\nstrip\n" + fields(1, 1, 1, 0, 1),
        "*SECTION_SHELL\n" + fields(1, 2, f"{5 / 6:10.7f}", 3) + "\n" + fields(*[THICKNESS] * 4),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, poisson),
        "*HOURGLASS\n" + fields(1, 1, 0.1),
        nodes_card(nodes),
        shells_card(shells),
        "*BOUNDARY_SPC_NODE\n" + "\n".join(fields(k + 1, 0, 1, 1, 1, 1, 1, 1) for k in root),
        "*INITIAL_VELOCITY_NODE\n" + "\n".join(fields(k + 1, 0.0, 0.0, f"{v:10.4e}") for k, v in enumerate(velocity)),
    )
    return path


def zero_crossings(time, signal):
    """Times where the signal changes sign, interpolated linearly."""
    index = np.flatnonzero(np.sign(signal[:-1]) * np.sign(signal[1:]) < 0)
    return time[index] - signal[index] * (time[index + 1] - time[index]) / (signal[index + 1] - signal[index])


@pytest.mark.parametrize("poisson", [0.0, 0.01, 0.1, 0.2, 0.3, 0.45])
def test_clamped_strip_vibrates_at_the_beam_period_for_any_poisson_ratio(tmp_path, run_deck, poisson):
    run = run_deck(strip_deck(tmp_path / "strip.k", poisson))
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        history = results["history/nodout"]
        node = next(iter(history))
        time = history[node]["time"][...]
        tip = history[node]["displacement"][:, 2]
        glstat = {name: results["history/glstat"][name][...] for name in results["history/glstat"]}
    crossings = zero_crossings(time, tip)
    assert len(crossings) >= 2 * PERIODS - 1
    period = 2.0 * np.diff(crossings).mean()
    ratio = period / beam_period()
    total = glstat["total_energy"]
    drift = np.abs(total - total[0]).max() / total[0]
    print(f"nu {poisson}: period / beam theory {ratio:.5f}, energy drift {drift:.1e}")
    assert abs(ratio - 1.0) < PERIOD_TOLERANCE, f"period {period:.5f} ms, beam theory {beam_period():.5f} ms"
    # the rotations do not set the step: TSSFAC times the membrane rule L / c, L = 5 mm
    membrane_step = 0.9 * (LENGTH / CELLS[0]) / np.sqrt(YOUNGS / (DENSITY * (1.0 - poisson**2)))
    # (the last step is cut so that the run ends at ENDTIM)
    assert glstat["time_step"][1:-1] == pytest.approx(membrane_step, rel=1e-6)
    assert 0.0 < glstat["time_step"][-1] <= membrane_step * (1.0 + 1e-6)
    # nothing external works on the strip (clamped nodes do not move): the total is constant,
    # and the motion really turns into strain energy and back
    assert drift < 1e-9
    assert glstat["internal_energy"].max() + glstat["hourglass_energy"].max() > 0.9 * total[0]
    assert np.abs(glstat["external_work"]).max() < 1e-9 * total[0]


HOURGLASS_BASE = np.array([1.0, -1.0, 1.0, -1.0])


def membrane_matrices(nodes, shells, poisson, coefficient=0.1):
    """In-plane stiffness (x, y per node) and lumped masses of flat shells (z = 0) as the
    solver builds them: t A B^T C B at the centre (plane stress) and the IHQ 4, 5 stiffness
    QM k / 16 gamma gamma^T per direction, k = E t A sum B^2 / 8, masses rho t A / 4."""
    lam, mu = YOUNGS * poisson / (1.0 - poisson**2), YOUNGS / (2.0 * (1.0 + poisson))
    elasticity = np.array([[lam + 2 * mu, lam, 0.0], [lam, lam + 2 * mu, 0.0], [0.0, 0.0, mu]])
    stiffness, masses = np.zeros((2 * len(nodes), 2 * len(nodes))), np.zeros(2 * len(nodes))
    for corners in shells:
        (x1, x2, x3, x4), (y1, y2, y3, y4) = nodes[corners, 0], nodes[corners, 1]
        area = 0.5 * ((x3 - x1) * (y4 - y2) - (x4 - x2) * (y3 - y1))
        b1 = np.array([y2 - y4, y3 - y1, y4 - y2, y1 - y3]) / (2 * area)
        b2 = np.array([x4 - x2, x1 - x3, x2 - x4, x3 - x1]) / (2 * area)
        strain = np.zeros((3, 8))
        strain[0, 0::2], strain[1, 1::2], strain[2, 0::2], strain[2, 1::2] = b1, b2, b2, b1
        element = THICKNESS * area * strain.T @ elasticity @ strain
        gamma = HOURGLASS_BASE - (HOURGLASS_BASE @ nodes[corners, 0]) * b1 - (HOURGLASS_BASE @ nodes[corners, 1]) * b2
        k = YOUNGS * THICKNESS * area * np.sum(b1**2 + b2**2) / 8.0
        for direction in range(2):
            element[direction::2, direction::2] += coefficient * k / 16.0 * np.outer(gamma, gamma)
        index = (2 * corners[:, None] + np.arange(2)).ravel()
        stiffness[np.ix_(index, index)] += element
        masses[index] += DENSITY * THICKNESS * area / 4.0
    return stiffness, masses


def free_shells_deck(path, nodes, shells, poisson, tssfac, cycles, velocities=None):
    blocks = ["*CONTROL_TERMINATION\n" + fields(1.0e3, cycles),
              "*CONTROL_TIMESTEP\n" + fields(0.0, tssfac),
              "*DATABASE_GLSTAT\n" + fields(1.0e-5),
              "*PART\nshells\n" + fields(1, 1, 1, 0, 1),
              "*SECTION_SHELL\n" + fields(1, 2, f"{5 / 6:10.7f}", 3) + "\n" + fields(*[THICKNESS] * 4),
              "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, poisson),
              "*HOURGLASS\n" + fields(1, 4, 0.1),
              nodes_card(nodes),
              shells_card(shells)]
    if velocities is not None:
        blocks.append("*INITIAL_VELOCITY_NODE\n" + "\n".join(
            f"{k + 1},{float(v[0])!r},{float(v[1])!r},0.0" for k, v in enumerate(velocities)))
    return write_deck(path, *blocks)


FREE_SHELLS = {"lone square": ((1, 1), (10.0, 10.0)), "lone 2:1": ((1, 1), (20.0, 10.0)),
               "pair": ((2, 1), (20.0, 10.0)), "row of 6": ((6, 1), (60.0, 10.0)),
               "4 x 4 plate": ((4, 4), (40.0, 40.0))}


@pytest.mark.parametrize("poisson", [0.0, 0.3, 0.49])
@pytest.mark.parametrize("name", list(FREE_SHELLS))
def test_free_shells_step_is_below_their_in_plane_critical_step(tmp_path, run_deck, name, poisson):
    """A lone shell, a pair and a row take the bound (their exposed shells); a 4 x 4 plate keeps
    the membrane rule L / c, 0.99 of its critical step at nu = 0.3 and 0.98 at 0.49 (its
    corners, each with one free corner node, are not exposed)."""
    nodes, shells = plate_mesh(*FREE_SHELLS[name])
    stiffness, masses = membrane_matrices(nodes, shells, poisson)
    scale = 1.0 / np.sqrt(masses)
    critical = 2.0 / np.sqrt(np.linalg.eigvalsh(scale[:, None] * stiffness * scale[None, :])[-1])
    rule = 10.0 / np.sqrt(YOUNGS / (DENSITY * (1.0 - poisson**2)))
    run = run_deck(free_shells_deck(tmp_path / "shells.k", nodes, shells, poisson, 1.0, 1))
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        step = results["history/glstat/time_step"][0]
    if name == "4 x 4 plate":
        assert step == pytest.approx(rule, rel=1e-9)
        assert step <= critical * (1.0 + 1e-9) / 0.97
    else:
        assert step <= critical * (1.0 + 1e-9), f"step {step:.6e} above the critical {critical:.6e}"
        assert step >= 0.8 * critical


@pytest.mark.parametrize("poisson", [0.3, 0.49])
def test_kicked_lone_shell_runs_stably_at_the_default_tssfac(tmp_path, run_deck, poisson):
    """One free square shell with random in-plane nodal velocities, TSSFAC 0.9, 3,000 cycles:
    the energy stays constant (with the membrane rule alone, 0.9 L / c is above its critical
    step 0.88 L / c at nu = 0.3 and 0.82 at 0.49, and the areal mode grew)."""
    nodes, shells = plate_mesh((1, 1), (10.0, 10.0))
    velocities = np.random.default_rng(2).uniform(-1.0, 1.0, (4, 2))
    run = run_deck(free_shells_deck(tmp_path / "kicked.k", nodes, shells, poisson, 0.9, 3000, velocities))
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        assert results["run"].attrs["cycles"] == 3000
        total = results["history/glstat/total_energy"][...]
        internal = results["history/glstat/internal_energy"][...]
    assert np.isfinite(total).all()
    assert np.abs(total - total[0]).max() < 1e-9 * total[0]
    assert internal.max() > 0.05 * total[0]
