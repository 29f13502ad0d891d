"""Solids in free flight take the step at rest, in every build.

A block of solids flies through space without touching anything; every node has the same
velocity, so nothing strains or compresses:
- every cycle's step is TSSFAC times the smallest step at rest, the first line of d3hsp's table
  of the 100 smallest element steps;
- the kinetic energy stays 1/2 m v^2, and no internal or hourglass energy arises.
The blocks: that of test_threads' contact model (6 x 6 x 4 one-point hexahedra of 2 mm, at its
position, 5 mm/ms along x and 20 mm/ms down), an irregular block of selective-reduced
hexahedra, and a block of EFG cells, each flying its own way.

The velocity gradients of the solids and of the meshfree points used to sum the absolute nodal
velocities: a translating element then had tr D = v . sum_I b_I / V, round-off of either sign,
different with and without FMA contraction. A negative one switched on the linear bulk
viscosity's term of the stable step, Q2 c: 6% smaller at Q2 = 0.06. The release build (FMA)
took 2.073e-4 ms instead of 2.201e-4 ms for the contact model's first step, the debug build only
from its second cycle on, and the two builds' kinetic energies after the impact differed by up
to 3% at the same cycle (13% at the same output time: docs/solver.md, "Why two builds differ").
The meshfree block took the smaller step in every build."""
import numpy as np
import pytest

from deck_writer import block_mesh, efg_section, fields, nodes_card, solids_card, write_deck
from test_ascii_databases import read_smallest_time_steps

CYCLES = 40
TSSFAC = 0.9

# kind: (section card, cells, size in mm, origin, perturbation of the inner nodes, velocity in mm/ms)
BLOCKS = {
    "one-point": ("*SECTION_SOLID\n" + fields(1, 1), (6, 6, 4), (12.0, 12.0, 8.0), (55.1, 10.3, 8.1), 0.0,
                  (5.0, 0.0, -20.0)),
    "selective-reduced": ("*SECTION_SOLID\n" + fields(1, 2), (4, 4, 4), (6.0, 6.0, 6.0), (-20.3, 40.7, 3.3), 0.2,
                          (-3.3, 7.1, 12.9)),
    "meshfree": (efg_section(1, 1.5), (6, 6, 4), (6.0, 6.0, 4.0), (55.1, 10.3, 8.1), 0.0, (5.0, 0.0, -20.0)),
}


def free_flight_deck(path, kind):
    """One block of `kind` (BLOCKS), elastic-plastic steel (kg, mm, ms, GPa), flying at its
    velocity; glstat and matsum every cycle."""
    section, cells, size, origin, perturbation, velocity = BLOCKS[kind]
    nodes, elements = block_mesh(cells, size, origin=origin, perturbation=perturbation, seed=7)
    return write_deck(
        path,
        f"*TITLE\n{kind} block in free flight",
        "*CONTROL_TERMINATION\n" + fields(1.0, CYCLES),
        "*CONTROL_TIMESTEP\n" + fields(0.0, TSSFAC),
        "*DATABASE_GLSTAT\n" + fields(1.0e-6),
        "*DATABASE_MATSUM\n" + fields(1.0e-6),
        f"*PART\n{kind} block\n" + fields(1, 1, 1),
        section,
        "*MAT_PLASTIC_KINEMATIC\n" + fields(1, 7.85e-6, 210.0, 0.3, 0.3, 1.0, 1.0) + "\n" + fields(0.0, 0.0),
        "*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields(*velocity),
        nodes_card(nodes),
        solids_card(elements, part_id=1),
    )


@pytest.mark.parametrize("kind", sorted(BLOCKS))
def test_free_flight_keeps_the_step_at_rest(tmp_path, run_deck, kind):
    run = run_deck(free_flight_deck(tmp_path / "free_flight.k", kind))
    assert run.status == 0, run.stdout + run.stderr
    table = read_smallest_time_steps(run.results.parent / "d3hsp")
    at_rest = table[0][3]
    with run.open() as results:
        glstat = results["history/glstat"]
        cycles, steps = glstat["cycle"][...], glstat["time_step"][...]
        kinetic, internal, hourglass = (glstat[name][...] for name in
                                        ("kinetic_energy", "internal_energy", "hourglass_energy"))
        mass = results["history/matsum/1/mass"][0]
    print(f"{kind} block in free flight: step at rest {at_rest:.7e} ms (element {table[0][1]}), steps taken "
          f"{steps.min():.7e} to {steps.max():.7e} ms over cycles {cycles[0]:.0f}-{cycles[-1]:.0f}")
    assert cycles[-1] == CYCLES and len(steps) == CYCLES + 1
    # d3hsp's table has 8 digits; the steps of all cycles are the same up to the round-off of
    # the moving configuration
    assert np.allclose(steps, TSSFAC * at_rest, rtol=2e-7, atol=0.0), steps / (TSSFAC * at_rest)
    assert np.all(np.abs(steps / steps[0] - 1.0) < 1e-12), steps / steps[0] - 1.0
    # nothing strains: the energy stays kinetic, 1/2 m v^2
    velocity = BLOCKS[kind][-1]
    expected = 0.5 * mass * float(np.dot(velocity, velocity))
    assert np.allclose(kinetic, expected, rtol=1e-12, atol=0.0), kinetic / expected
    assert np.all(np.abs(internal) <= 1e-12 * expected) and np.all(np.abs(hourglass) <= 1e-12 * expected), \
        (np.abs(internal).max(), np.abs(hourglass).max())
