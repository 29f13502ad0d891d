"""Hexahedra in free flight take the step at rest, in every build.

Two blocks of solids fly through space without touching anything: the block of test_threads'
contact model (6 x 6 x 4 one-point elements of 2 mm, at its position, 5 mm/ms along x and 20
mm/ms down) and an irregular 4 x 4 x 4 block of selective-reduced elements flying the other
way. Every node of a block has the same velocity, so its elements neither strain nor compress:
- every cycle's step is TSSFAC times the smallest step at rest, the first line of d3hsp's table
  of the 100 smallest element steps;
- the kinetic energy stays what it was, and no internal or hourglass energy arises.

The velocity gradients of the solids used to sum the absolute nodal velocities: a translating
element then had tr D = v . sum_I b_I / V, round-off of either sign, different with and
without FMA contraction. A negative one switched on the linear bulk viscosity's term of the
stable step, Q2 c: 6% smaller at Q2 = 0.06. The release build (FMA) took 2.073e-4 ms instead of
2.201e-4 ms for the contact model's first step, the debug build only from its second cycle on,
and the two builds' kinetic energies after the impact differed by up to 3% (docs/solver.md,
"Why two builds differ")."""
import numpy as np

from deck_writer import block_mesh, fields, nodes_card, solids_card, write_deck
from test_ascii_databases import read_smallest_time_steps

CYCLES = 40
TSSFAC = 0.9
FLIGHT_VELOCITIES = {1: (5.0, 0.0, -20.0), 2: (-3.3, 7.1, 12.9)}     # mm/ms, per part


def free_flight_deck(path):
    """Part 1: test_threads' contact block (ELFORM 1); part 2: an irregular block (ELFORM 2)
    1.5 mm cells, every inner node moved by up to 20% of a cell. Elastic-plastic steel
    (kg, mm, ms, GPa). Output every cycle."""
    first_nodes, first_elements = block_mesh((6, 6, 4), (12.0, 12.0, 8.0), origin=(55.1, 10.3, 8.1))
    second_nodes, second_elements = block_mesh((4, 4, 4), (6.0, 6.0, 6.0), origin=(-20.3, 40.7, 3.3),
                                               perturbation=0.2, seed=7)
    velocity_cards = "\n".join(fields(part, 2, 0.0, *velocity) + "\n" + fields(*[0.0] * 5, 1.0)
                               for part, velocity in FLIGHT_VELOCITIES.items())
    return write_deck(
        path,
        "*TITLE\ntwo blocks in free flight",
        "*CONTROL_TERMINATION\n" + fields(1.0, CYCLES),
        "*CONTROL_TIMESTEP\n" + fields(0.0, TSSFAC),
        "*DATABASE_GLSTAT\n" + fields(1.0e-6),
        "*DATABASE_MATSUM\n" + fields(1.0e-6),
        "*PART\none-point block\n" + fields(1, 1, 1),
        "*PART\nselective-reduced block\n" + fields(2, 2, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*SECTION_SOLID\n" + fields(2, 2),
        "*MAT_PLASTIC_KINEMATIC\n" + fields(1, 7.85e-6, 210.0, 0.3, 0.3, 1.0, 1.0) + "\n" + fields(0.0, 0.0),
        "*INITIAL_VELOCITY_GENERATION\n" + velocity_cards,
        nodes_card(np.vstack([first_nodes, second_nodes])),
        solids_card(first_elements, part_id=1) + "\n" +
        "\n".join(solids_card(second_elements, part_id=2, first_id=len(first_elements) + 1,
                              first_node_id=len(first_nodes) + 1).splitlines()[1:]),
    )


def test_free_flight_keeps_the_step_at_rest(tmp_path, run_deck):
    run = run_deck(free_flight_deck(tmp_path / "free_flight.k"))
    assert run.status == 0, run.stdout + run.stderr
    table = read_smallest_time_steps(run.results.parent / "d3hsp")
    at_rest = table[0][3]
    with run.open() as results:
        glstat = results["history/glstat"]
        cycles, steps = glstat["cycle"][...], glstat["time_step"][...]
        kinetic, internal, hourglass = (glstat[name][...] for name in
                                        ("kinetic_energy", "internal_energy", "hourglass_energy"))
        part_kinetic = {part: results[f"history/matsum/{part}/kinetic_energy"][...] for part in FLIGHT_VELOCITIES}
        part_mass = {part: results[f"history/matsum/{part}/mass"][0] for part in FLIGHT_VELOCITIES}
    print(f"free flight: step at rest {at_rest:.7e} ms (element {table[0][1]}, part {table[0][2]}), steps taken "
          f"{steps.min():.7e} to {steps.max():.7e} ms over cycles {cycles[0]:.0f}-{cycles[-1]:.0f}")
    assert cycles[-1] == CYCLES and len(steps) == CYCLES + 1
    # d3hsp's table has 8 digits; the steps of all cycles are the same up to the round-off of
    # the moving configuration
    assert np.allclose(steps, TSSFAC * at_rest, rtol=2e-7, atol=0.0), steps / (TSSFAC * at_rest)
    assert np.all(np.abs(steps / steps[0] - 1.0) < 1e-12), steps / steps[0] - 1.0
    # nothing strains: the energy stays kinetic, 1/2 m v^2 of each block
    for part, velocity in FLIGHT_VELOCITIES.items():
        expected = 0.5 * part_mass[part] * float(np.dot(velocity, velocity))
        assert np.allclose(part_kinetic[part], expected, rtol=1e-12, atol=0.0), (part, part_kinetic[part] / expected)
    assert np.all(np.abs(internal) <= 1e-12 * kinetic[0]) and np.all(np.abs(hourglass) <= 1e-12 * kinetic[0]), \
        (np.abs(internal).max(), np.abs(hourglass).max())
