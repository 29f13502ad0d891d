"""A heavy moving rigid wall (*RIGIDWALL_PLANAR_MOVING) strikes a block at rest: the momentum of
block and wall together is conserved and the energy balance closes. Mass scaling (DT2MS) adds
exactly the mass that brings every element's stable step up to |DT2MS|."""
import numpy as np

from deck_writer import block_mesh, fields, nodes_card, solids_card, write_deck

DENSITY = 7.85e-6


def test_moving_wall_conserves_momentum(tmp_path, run_deck):
    nodes, elements = block_mesh((4, 4, 4), (10.0, 10.0, 10.0), origin=(0.0, 0.0, 0.0))
    block_mass = DENSITY * 1000.0
    wall_mass, wall_speed = 5.0 * block_mass, 50.0
    deck = write_deck(
        tmp_path / "moving_wall.k",
        "*CONTROL_TERMINATION\n" + fields(0.05),
        "*DATABASE_GLSTAT\n" + fields(0.0005),
        "*DATABASE_RWFORC\n" + fields(0.0005),
        "*PART\nblock\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_PLASTIC_KINEMATIC\n" + fields(1, DENSITY, 200.0, 0.3, 0.3, 2.0, 1.0) + "\n" + fields(0.0, 0.0),
        # a wall 0.2 mm below the block, normal +z, moving up at 50 mm/ms
        "*RIGIDWALL_PLANAR_MOVING_ID\n" + fields(3) + "anvil\n" + fields(0) + "\n" +
        fields(0.0, 0.0, -0.2, 0.0, 0.0, 1.0) + "\n" + fields(wall_mass, wall_speed),
        nodes_card(nodes),
        solids_card(elements),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    with run.open() as results:
        glstat = results["history/glstat"]
        momentum = glstat["momentum"][...]
        ratio = glstat["energy_ratio"][...]
        kinetic = glstat["kinetic_energy"][...]
    initial = wall_mass * wall_speed
    assert abs(momentum[0][2] - initial) < 1e-12 * initial
    assert np.abs(momentum[:, 2] - initial).max() < 1e-8 * initial
    assert np.abs(momentum[:, :2]).max() < 1e-8 * initial
    assert abs(kinetic[0] - 0.5 * wall_mass * wall_speed ** 2) < 1e-9 * kinetic[0]
    # the block has been hit: it moves up with at least the wall's speed share
    assert np.abs(ratio - 1.0).max() < 0.01


def test_mass_scaling_adds_the_mass_for_the_target_step(tmp_path, run_deck):
    nodes, elements = block_mesh((4, 4, 4), (10.0, 10.0, 10.0))
    lame, shear = 210.0 * 0.3 / (1.3 * 0.4), 210.0 / 2.6   # E = 210, nu = 0.3
    # the stable step of a 2.5 mm cube at the block's corners and edges (32 of the 64): 2 / omega
    # of its volumetric mode, omega^2 = 4 (3 lambda + 2 mu) / (rho L^2) (0.73 of L / c); the 32
    # others (face centres and inside) keep L / c (docs/solver.md, "Time step")
    natural_steps = np.array([2.5 * np.sqrt(DENSITY / (3.0 * lame + 2.0 * shear))] * 32
                             + [2.5 * np.sqrt(DENSITY / (lame + 2.0 * shear))] * 32)
    target = 0.0016                                   # about 5 natural steps, exact in a 10-column field
    deck = write_deck(
        tmp_path / "mass_scaling.k",
        "*CONTROL_TERMINATION\n" + fields(1.0, 20),
        "*CONTROL_TIMESTEP\n" + fields(0.0, 0.9, None, None, -target),
        "*DATABASE_GLSTAT\n" + fields(1e-9),
        "*PART\nblock\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, 210.0, 0.3),
        nodes_card(nodes),
        solids_card(elements),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    assert "mass scaling: added mass" in run.stdout
    with run.open() as results:
        glstat = results["history/glstat"]
        added, steps = glstat["added_mass"][...], glstat["time_step"][...]
    # every element's step goes from its natural step to the target: its density rises by
    # (target / step)^2
    expected = np.sum((target / natural_steps) ** 2 - 1.0) * DENSITY * 2.5**3
    assert abs(added[-1] - expected) < 1e-9 * expected
    assert np.abs(steps - 0.9 * target).max() < 1e-9 * target
