"""Rigid walls and initial velocities act on the physical motion of meshfree particles
(docs/efg.md, docs/efg_shells.md, docs/solver.md "Rigid walls and meshfree particles" and
"Initial velocities").

The interior particles of meshfree parts carry generalized values; the physical position of
particle I is X_I + sum_J A_IJ u_J. Checked here:

- a meshfree solid block whose interior particles (the wall's node set) hit a stationary planar
  wall (also with Coulomb friction and without sliding), are struck by a moving wall with a mass,
  and fall on a cylinder: no physical position of a tracked node passes the wall by more than
  round-off, the impulse of the wall force history (rwforc) equals the change of momentum
  (1e-6), the energy balance closes within 1%; 1 and 2 threads give identical results;
- a meshfree shell plate thrown at a wall with a dome of speeds (its interior particles meet
  the wall first, and the motion is not a linear field): the same checks;
- a restart dump written while particles rest on the wall continues the run bit for bit;
- initial velocities with a quadratic profile across a meshfree solid block and a meshfree
  shell plate: the physical velocities at t = 0 equal the deck's to 1e-10.
"""
import shutil

import h5py
import numpy as np

from deck_writer import (block_mesh, boundary_node_mask, efg_section, fields, node_list_set, nodes_card, plate_mesh,
                         round_to_node_card, shells_card, solids_card, write_deck)

# mm, ms, kg, kN, GPa
DENSITY, YOUNGS, POISSON = 7.85e-6, 210.0, 0.3
BLOCK = 10.0
THICKNESS = 1.0


def velocity_card(velocities):
    lines = ["*INITIAL_VELOCITY_NODE"]
    for k, v in enumerate(velocities):
        lines.append(f"{k + 1:10d}{v[0]:10.4f}{v[1]:10.4f}{v[2]:10.4f}")
    return "\n".join(lines)


def shell_section():
    return "*SECTION_SHELL\n" + fields(1, 41, f"{5 / 6:10.7f}", 3) + "\n" + \
        fields(THICKNESS, THICKNESS, THICKNESS, THICKNESS) + "\n" + fields(1.5, 1.5, 0, 0)


def block_deck(path, wall, end_time=0.3, initial=None, interval=0.01):
    """A 10 mm meshfree block (4 x 4 x 4 irregular cells, DX 1.5): its 27 interior particles
    are the node set of the wall `wall` (the cards after the keyword line), so the surface
    nodes (Gamma nodes) pass the wall and the particles are stopped by it."""
    nodes, elements = block_mesh((4, 4, 4), (BLOCK, BLOCK, BLOCK), perturbation=0.15, seed=5)
    nodes = round_to_node_card(nodes)
    particles = np.flatnonzero(~boundary_node_mask(nodes)) + 1
    if initial is None:
        initial = np.tile([0.0, 0.0, -20.0], (len(nodes), 1))
    cards = [
        "*TITLE\nmeshfree block against a rigid wall",
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_GLSTAT\n" + fields(interval),
        "*DATABASE_RWFORC\n" + fields(1.0e-7),
        "*DATABASE_BINARY_D3PLOT\n" + fields(interval),
        "*PART\nmeshfree block\n" + fields(1, 1, 1),
        efg_section(1, 1.5),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
        nodes_card(nodes),
        solids_card(elements),
        velocity_card(initial),
    ]
    if wall:
        cards += [node_list_set(1, particles), wall]
    return write_deck(path, *cards), nodes, particles


def plate_deck(path, wall=True, end_time=0.3, initial=None, interval=0.005):
    """A 40 mm meshfree shell plate at z = 5 (8 x 8 irregular cells, DX 1.5) thrown at the wall
    z = 4.5 with a dome of speeds, 20 mm/ms down at the centre and 10 at the edges: the interior
    particles meet the wall first, in rings from the centre outward."""
    nodes, shells = plate_mesh((8, 8), (40.0, 40.0), perturbation=0.2, seed=4)
    nodes = round_to_node_card(nodes + [0.0, 0.0, 5.0])
    if initial is None:
        radius_squared = ((nodes[:, :2] - 20.0) ** 2).sum(axis=1) / 800.0
        initial = np.stack([np.zeros(len(nodes)), np.zeros(len(nodes)), -10.0 - 10.0 * (1.0 - radius_squared)],
                           axis=1)
    normal = np.array([0.0, 0.0, 1.0])
    cards = [
        "*TITLE\nmeshfree plate thrown at a rigid wall",
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_GLSTAT\n" + fields(interval),
        "*DATABASE_RWFORC\n" + fields(1.0e-7),
        "*DATABASE_BINARY_D3PLOT\n" + fields(interval),
        "*PART\nmeshfree plate\n" + fields(1, 1, 1),
        shell_section(),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
        nodes_card(nodes),
        shells_card(shells),
        velocity_card(initial),
    ]
    if wall:
        # every node tracked
        cards.append("*RIGIDWALL_PLANAR_ID\n" + fields(4) + "floor\n" + fields(0) + "\n" +
                     fields(0.0, 0.0, 4.5, 0.0, 0.0, 5.5))
    return write_deck(path, *cards), nodes, normal


def states_of(results):
    names = sorted(results["states"].keys(), key=lambda name: results["states"][name].attrs["time"])
    return [results["states"][name] for name in names]


def physical_positions(results):
    coordinates = results["mesh/nodes/coordinates"][...]
    return [(state.attrs["time"], coordinates + state["displacement"][...]) for state in states_of(results)]


def wall_history(results, wall_id):
    history = results[f"history/rwforc/{wall_id}"]
    return history["time"][...], history["force"][...]


def impulse_of(time, force):
    # each row is the mean force since the row before: the impulse is their exact sum
    return (force[1:] * np.diff(time)[:, None]).sum(axis=0)


def glstat_of(results):
    return {name: results["history/glstat"][name][...] for name in results["history/glstat"]}


def check_momentum_and_energy(results, wall_id, expected_sign):
    time, force = wall_history(results, wall_id)
    glstat = glstat_of(results)
    # rwforc holds LS-DYNA's sign, the force of the wall on the structure
    impulse_on_structure = impulse_of(time, force)
    momentum_change = glstat["momentum"][-1] - glstat["momentum"][0]
    mismatch = np.abs(impulse_on_structure - momentum_change).max() / np.abs(momentum_change).max()
    ratio = glstat["energy_ratio"]
    print(f"wall impulse on the structure {impulse_on_structure}, momentum change {momentum_change} (mismatch {mismatch:.2e}); energy "
          f"ratio {ratio.min():.8f} .. {ratio.max():.8f}; wall energy {glstat['rigid_wall_energy'][-1]:.4e}")
    assert expected_sign * momentum_change[2] > 0.0, "the wall must have stopped the particles"
    assert mismatch <= 1e-6
    assert np.abs(ratio - 1.0).max() < 0.01


def test_block_particles_stop_at_a_planar_wall(tmp_path, run_deck):
    """Interior particles of a meshfree block falling at 20 mm/ms on the wall z = 1.5 (the
    lowest particle starts above z = 2.1): after contact no particle's physical position is
    below the wall by more than 1e-9 mm (on the old generalized treatment: by about 1e-2 mm)."""
    wall_z = 1.5
    wall = ("*RIGIDWALL_PLANAR_ID\n" + fields(3) + "floor\n" + fields(1) + "\n" +
            fields(0.0, 0.0, wall_z, 0.0, 0.0, wall_z + 1.0))
    deck, nodes, particles = block_deck(tmp_path / "block.k", wall)
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        positions = physical_positions(results)
        check_momentum_and_energy(results, 3, +1.0)
    deepest = min(position[particles - 1, 2].min() - wall_z for _, position in positions)
    touching = sum(np.isclose(position[particles - 1, 2], wall_z, atol=1e-6).sum() for _, position in positions)
    print(f"deepest physical position relative to the wall {deepest:.3e} mm; {touching} particle states on it")
    assert deepest > -1e-9
    assert touching > 0, "some particles must rest on the wall"
    assert "generalized positions" not in run.stderr   # the warning of the generalized treatment


def test_block_particles_slide_on_a_wall_with_friction(tmp_path, run_deck):
    """The block thrown at the wall obliquely (10 mm/ms along x, 20 down) with FRIC 0.3: friction
    acts on the particles' physical tangential velocity, so the wall holds the block back along x
    (rwforc, the wall's force on the structure, is negative along x); its
    impulse equals the momentum change in every direction (1e-6), its tangential part is at most
    0.3 times its normal part;
    the energy balance closes within 1% and no particle passes the wall."""
    wall_z = 1.5
    wall = ("*RIGIDWALL_PLANAR_ID\n" + fields(3) + "rough floor\n" + fields(1) + "\n" +
            fields(0.0, 0.0, wall_z, 0.0, 0.0, wall_z + 1.0, 0.3))
    deck, nodes, particles = block_deck(tmp_path / "friction.k", wall, initial=np.tile([10.0, 0.0, -20.0], (125, 1)))
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        positions = physical_positions(results)
        check_momentum_and_energy(results, 3, +1.0)
        impulse = impulse_of(*wall_history(results, 3))
    ratio = np.linalg.norm(impulse[:2]) / abs(impulse[2])
    print(f"tangential / normal impulse {ratio:.4f} (x part {impulse[0]:.4e}, against the motion)")
    assert impulse[0] < 0.0 and 0.05 < ratio <= 0.3 * (1.0 + 1e-9)
    assert min(position[particles - 1, 2].min() - wall_z for _, position in positions) > -1e-9


def test_block_particles_stick_to_a_wall_without_sliding(tmp_path, run_deck):
    """The oblique throw with FRIC 1 (no sliding): a particle whose physical position is on the
    wall in two consecutive states (0.3 us apart, about one cycle) has not slid along it by more
    than 1e-10 mm."""
    wall_z = 1.5
    wall = ("*RIGIDWALL_PLANAR_ID\n" + fields(3) + "sticky floor\n" + fields(1) + "\n" +
            fields(0.0, 0.0, wall_z, 0.0, 0.0, wall_z + 1.0, 1.0))
    deck, nodes, particles = block_deck(tmp_path / "stick.k", wall, initial=np.tile([10.0, 0.0, -20.0], (125, 1)),
                                        interval=0.0003, end_time=0.15)
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        positions = [position[particles - 1] for _, position in physical_positions(results)]
    slides = []
    for before, after in zip(positions, positions[1:]):
        resting = (np.abs(before[:, 2] - wall_z) < 1e-9) & (np.abs(after[:, 2] - wall_z) < 1e-9)
        if resting.any():
            slides.append(np.abs(after[resting, :2] - before[resting, :2]).max())
    print(f"{len(slides)} pairs of states with particles resting on the wall; largest slide "
          f"{max(slides) if slides else float('nan'):.3e} mm")
    assert len(slides) > 5
    assert max(slides) < 1e-10


def test_block_particles_struck_by_a_moving_wall(tmp_path, run_deck):
    """A moving wall (mass 5 blocks, 30 mm/ms up) strikes the interior particles of a block at
    rest: the momentum of block and wall is kept to 1e-9, the energy balance closes within 1%,
    and no particle's physical position is behind the wall (its position rebuilt from its
    speed and the force history, cycle by cycle) by more than 1e-9 mm."""
    wall_mass, wall_speed, wall_z = 5.0 * DENSITY * BLOCK ** 3, 30.0, 1.9
    wall = ("*RIGIDWALL_PLANAR_MOVING_ID\n" + fields(5) + "anvil\n" + fields(1) + "\n" +
            fields(0.0, 0.0, wall_z, 0.0, 0.0, wall_z + 1.0) + "\n" + fields(wall_mass, wall_speed))
    deck, nodes, particles = block_deck(tmp_path / "moving.k", wall, initial=np.zeros((125, 3)), end_time=0.1,
                                        interval=0.002)
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        positions = physical_positions(results)
        time, force = wall_history(results, 5)
        glstat = glstat_of(results)
    initial = wall_mass * wall_speed
    assert np.abs(glstat["momentum"][:, 2] - initial).max() < 1e-9 * initial
    assert np.abs(glstat["energy_ratio"] - 1.0).max() < 0.01
    # the wall's speed and position after each cycle (rwforc every cycle: the wall's force on the
    # structure over that cycle, the opposite of the force on the wall); its position moves with
    # the speed of the cycle's start
    steps = np.diff(time)
    speed_after = wall_speed - np.cumsum(force[1:, 2] * steps) / wall_mass
    speed_before = np.concatenate([[wall_speed], speed_after[:-1]])
    position = wall_z + np.concatenate([[0.0], np.cumsum(speed_before * steps)])
    assert speed_after[-1] < wall_speed, "the wall must have struck the block"
    deepest = np.inf
    for state_time, state_position in positions:
        cycle = np.argmin(np.abs(time - state_time))
        assert abs(time[cycle] - state_time) < 1e-12
        deepest = min(deepest, (state_position[particles - 1, 2] - position[cycle]).min())
    print(f"deepest physical position behind the moving wall {deepest:.3e} mm; wall speed {speed_after[-1]:.4f}")
    assert deepest > -1e-9


def test_block_particles_on_a_cylinder(tmp_path, run_deck):
    """The block's interior particles fall on a stationary cylinder (*RIGIDWALL_GEOMETRIC_CYLINDER,
    radius 2.5 mm, axis along x at y = 5, z = -1: its top is 0.6 mm below the lowest particle):
    no particle's physical position ends a state inside it by more than 1e-9 mm, the wall's
    impulse is the momentum change, the energy balance closes within 1%."""
    radius, axis = 2.5, np.array([5.0, -1.0])
    wall = ("*RIGIDWALL_GEOMETRIC_CYLINDER_ID\n" + fields(6) + "roller\n" + fields(1) + "\n" +
            fields(-10.0, 5.0, -1.0, 20.0, 5.0, -1.0) + "\n" + fields(radius, 0.0, 0))
    deck, nodes, particles = block_deck(tmp_path / "cylinder.k", wall)
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        positions = physical_positions(results)
        check_momentum_and_energy(results, 6, +1.0)
    deepest = min((np.linalg.norm(position[particles - 1, 1:] - axis, axis=1) - radius).min()
                  for _, position in positions)
    print(f"deepest physical position inside the cylinder {deepest:.3e} mm")
    assert deepest > -1e-9


def test_block_wall_threads_identical(tmp_path, run_deck):
    wall = "*RIGIDWALL_PLANAR_ID\n" + fields(3) + "floor\n" + fields(1) + "\n" + fields(0.0, 0.0, 1.5, 0.0, 0.0, 2.5)
    deck, _, _ = block_deck(tmp_path / "threads.k", wall, end_time=0.15)
    runs = [run_deck(deck, ncpu=ncpu) for ncpu in (1, 2)]
    for run in runs:
        assert run.status == 0, run.stdout + run.stderr
    with runs[0].open() as one, runs[1].open() as two:
        first, second = states_of(one), states_of(two)
        assert len(first) == len(second)
        for a, b in zip(first, second):
            assert np.array_equal(a["displacement"][...], b["displacement"][...])
            assert np.array_equal(a["velocity"][...], b["velocity"][...])
        assert np.array_equal(one["history/rwforc/3/force"][...], two["history/rwforc/3/force"][...])


def test_shell_plate_thrown_at_a_wall(tmp_path, run_deck):
    """A meshfree shell plate thrown at a wall with a dome of speeds: its interior particles
    meet the wall first; no node's physical position passes the wall by more than
    1e-9 mm (interior particles among those on it), the wall's impulse is the momentum change,
    the energy balance closes within 1%, and 2 threads give the same results as 1."""
    deck, nodes, normal = plate_deck(tmp_path / "plate.k")
    runs = [run_deck(deck, ncpu=ncpu) for ncpu in (1, 2)]
    for run in runs:
        assert run.status == 0, run.stdout + run.stderr
    with runs[0].open() as results:
        positions = physical_positions(results)
        check_momentum_and_energy(results, 4, +1.0)
        particles = results["timing"].attrs["efg_shell_particles"]
    assert particles == 49
    point = np.array([0.0, 0.0, 4.5])
    distances = np.array([(position - point) @ normal for _, position in positions])
    interior = ~(np.isclose(nodes[:, 0], 0.0) | np.isclose(nodes[:, 0], 40.0) | np.isclose(nodes[:, 1], 0.0) |
                 np.isclose(nodes[:, 1], 40.0))
    deepest = distances.min()
    touching = (np.abs(distances[:, interior]) < 1e-6).sum()
    print(f"deepest physical position relative to the wall {deepest:.3e} mm; {touching} particle states on it")
    assert interior.sum() == particles and touching > 0
    assert deepest > -1e-9
    assert "generalized positions" not in runs[0].stderr
    with runs[0].open() as one, runs[1].open() as two:
        for a, b in zip(states_of(one), states_of(two)):
            assert np.array_equal(a["displacement"][...], b["displacement"][...])
            assert np.array_equal(a["velocity"][...], b["velocity"][...])


def quadratic_velocity(nodes, length):
    """v = (0.3 s t, -0.2 s^2, 5 (s^2 + t^2 - s t)) mm/ms with s, t = x / L, y / L: not a
    linear field, so the generalized velocities that give it differ from it."""
    s, t = nodes[:, 0] / length, nodes[:, 1] / length
    velocity = np.stack([0.3 * s * t, -0.2 * s ** 2, 5.0 * (s * s + t * t - s * t)], axis=1)
    return np.round(velocity, 4)   # as the 10-column card holds it


def test_quadratic_initial_velocity_is_physical(tmp_path, run_deck):
    """A quadratic initial velocity field on a meshfree block and a meshfree shell plate: the
    physical velocities of the first state (t = 0) equal the deck's at every node to 1e-10."""
    nodes, _ = block_mesh((4, 4, 4), (BLOCK, BLOCK, BLOCK), perturbation=0.15, seed=5)
    velocity = quadratic_velocity(round_to_node_card(nodes), BLOCK)
    deck, nodes, _ = block_deck(tmp_path / "block_velocity.k", None, end_time=0.001, initial=velocity,
                                interval=0.0005)
    plate_nodes, _ = plate_mesh((8, 8), (40.0, 40.0), perturbation=0.2, seed=4)
    plate_velocity = quadratic_velocity(round_to_node_card(plate_nodes), 40.0)
    plate, _, _ = plate_deck(tmp_path / "plate_velocity.k", wall=False, end_time=0.001, initial=plate_velocity,
                             interval=0.0005)
    for name, path, expected in (("block", deck, velocity), ("plate", plate, plate_velocity)):
        run = run_deck(path, jobid=name)
        assert run.status == 0, run.stdout + run.stderr
        with run.open() as results:
            first = states_of(results)[0]
            assert first.attrs["time"] == 0.0
            physical = first["velocity"][...]
        error = np.abs(physical - expected).max() / np.abs(expected).max()
        print(f"{name}: largest difference of the physical initial velocity {error:.3e} (relative)")
        assert error < 1e-10
        assert "initial velocities" not in run.stderr


def test_restart_while_particles_rest_on_the_wall(tmp_path):
    """The plate thrown at the wall (in contact from cycle 47 to 89), continued on 2 threads from
    the dumps of cycles 80 (particles on the wall) and 160: the results file of the uninterrupted
    run, bit for bit (the sweeps keep nothing from step to step)."""
    from test_restart import assert_same, contents, restart, run_fresh
    deck, _, _ = plate_deck(tmp_path / "plate.k", end_time=0.12)
    text = deck.read_text().replace("*DATABASE_GLSTAT", "*DATABASE_BINARY_D3DUMP\n" + fields(40) + "\n*DATABASE_GLSTAT")
    deck.write_text(text)
    run_fresh(deck, tmp_path / "one", ncpu=1)
    reference = contents(tmp_path / "one" / "results.h5")
    with h5py.File(tmp_path / "one" / "results.h5", "r") as results:
        touched = results["history/rwforc/4/force"][...]
    dumps = sorted(p.name for p in (tmp_path / "one").glob("d3dump*"))
    assert len(dumps) >= 4, dumps
    assert touched[80, 2] != 0.0, "the second dump (cycle 80) must be written during the contact"
    for dump in dumps[1:4:2]:
        target = tmp_path / f"restart_{dump}"
        shutil.copytree(tmp_path / "one", target)
        process = restart(target / dump, 2)
        assert process.returncode == 0, process.stdout + process.stderr
        assert_same(reference, contents(target / "results.h5"), f"continued from {dump}")
    print(f"dumps {dumps}; wall force in {np.count_nonzero(touched[:, 2])} of {len(touched)} cycles")
