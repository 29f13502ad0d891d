"""Meshfree (EFG) and coupled FE + EFG parts in explicit dynamics.

- stability: an elastic EFG block and a coupled bar in free vibration keep their total energy
  within 1% over 10,000 cycles at the default TSSFAC;
- waves: a stress wave crosses the FE/EFG interface of a bar without a reflection beyond 2% of
  the incident amplitude;
- large deformation: a soft elastic-plastic cube squeezed to 30% of its height between sticking
  rigid walls runs to the end as EFG with its energy balanced within 2%, while the same cube of
  one-point hexahedra inverts or needs hourglass energy above 10% of its internal energy;
- threads: a coupled model gives identical results with 1 and 2 threads.
"""
import h5py
import numpy as np
import pytest

from deck_writer import block_mesh, efg_section, fields, nodes_card, node_list_set, solids_card, write_deck

DENSITY, MODULUS = 7.85e-6, 210.0


def split_cards(nodes, elements, meshfree_cells):
    """Element cards: part 1 (meshfree) for meshfree_cells, part 2 (FE) for the others."""
    cards = solids_card(elements[meshfree_cells], part_id=1)
    if (~meshfree_cells).any():
        fe = solids_card(elements[~meshfree_cells], part_id=2, first_id=100001)
        cards += "\n" + fe.split("\n", 1)[1]
    return cards


def parts_and_sections(fe_formulation=1):
    return ["*PART\nmeshfree\n" + fields(1, 1, 1, 0, 1),
            "*PART\nfinite elements\n" + fields(2, 2, 1, 0, 1),
            efg_section(1, 1.5),
            "*SECTION_SOLID\n" + fields(2, fe_formulation),
            "*HOURGLASS\n" + fields(1, 4, 0.1)]


@pytest.mark.parametrize("coupled", [False, True], ids=["efg-block", "coupled-bar"])
def test_free_vibration_keeps_energy(tmp_path, run_deck, coupled):
    # an EFG block, or a bar of 40 x 10 x 10 mm whose left half is EFG and right half FE
    cells, lengths = ((8, 3, 3), (40.0, 10.0, 10.0)) if coupled else ((4, 4, 4), (10.0, 10.0, 10.0))
    nodes, elements = block_mesh(cells, lengths, perturbation=0.15, seed=3)
    centres = nodes[elements].mean(axis=1)
    meshfree = centres[:, 0] < 20.0 if coupled else np.ones(len(elements), bool)
    initial = ["*INITIAL_VELOCITY_NODE"]
    for k, position in enumerate(nodes):
        shape = np.cos(np.pi * position / np.array(lengths))
        initial.append(fields(k + 1, *[float(v) for v in shape]))
    deck = write_deck(
        tmp_path / "vibration.k",
        "*CONTROL_TERMINATION\n" + fields(100.0, 10000),
        "*DATABASE_GLSTAT\n" + fields(1.0e-4),
        *parts_and_sections(),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, MODULUS, 0.3),
        nodes_card(nodes),
        split_cards(nodes, elements, meshfree),
        "\n".join(initial),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        assert results["run"].attrs["cycles"] == 10000
        glstat = results["history/glstat"]
        total, internal = glstat["total_energy"][...], glstat["internal_energy"][...]
    assert internal.max() > 0.3 * total[0], "the block must really vibrate"
    drift = np.abs(total - total[0]).max() / total[0]
    assert drift < 0.01, f"total energy drift {100 * drift:.3f}%"


def test_wave_crosses_the_interface_without_reflection(tmp_path, run_deck):
    # a bar along x, FE for x < 50, EFG for x > 50; nu = 0 makes it one-dimensional
    nodes, elements = block_mesh((100, 2, 2), (100.0, 2.0, 2.0))
    centres = nodes[elements].mean(axis=1)
    meshfree = centres[:, 0] > 50.0
    loaded = list(np.flatnonzero(np.abs(nodes[:, 0]) < 1e-9) + 1)
    probe = int(np.flatnonzero((np.abs(nodes[:, 0] - 25.0) < 1e-9) & (np.abs(nodes[:, 1]) < 1e-9)
                               & (np.abs(nodes[:, 2]) < 1e-9))[0]) + 1
    # a smooth velocity pulse (0.004 ms) enters at x = 0, reaches the interface, and whatever is
    # reflected comes back to the probe at x = 25 after the incident pulse has passed it
    pulse = "\n".join(f"{t:20.6e}{np.sin(np.pi * t / 0.004) ** 2 if t < 0.004 else 0.0:20.6e}"
                      for t in np.linspace(0.0, 0.004, 21)) + f"\n{1.0:20.6e}{0.0:20.6e}"
    deck = write_deck(
        tmp_path / "bar.k",
        "*CONTROL_TERMINATION\n" + fields(0.0175),
        "*DATABASE_NODOUT\n" + fields(2.0e-5),
        "*DATABASE_HISTORY_NODE\n" + fields(probe),
        *parts_and_sections(fe_formulation=2),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, MODULUS, 0.0),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + pulse,
        node_list_set(1, loaded),
        "*BOUNDARY_PRESCRIBED_MOTION_SET\n" + fields(1, 1, 0, 1, 1.0),
        nodes_card(nodes),
        split_cards(nodes, elements, meshfree),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        history = results[f"history/nodout/{probe}"]
        time, velocity = history["time"][...], history["velocity"][:, 0]
    speed = np.sqrt(MODULUS / DENSITY)
    incident = np.abs(velocity[time < 25.0 / speed + 0.006]).max()
    # a reflection from x = 50 would pass the probe between (75 / c) and (75 / c + 0.004 + margin)
    window = (time > 75.0 / speed - 0.001) & (time < 75.0 / speed + 0.006)
    reflected = np.abs(velocity[window]).max()
    assert incident > 0.9
    assert reflected < 0.02 * incident, f"reflection {100 * reflected / incident:.2f}% of the incident pulse"


def squeeze_deck(path, meshfree):
    nodes, elements = block_mesh((8, 8, 8), (10.0, 10.0, 10.0))
    section = efg_section(1, 1.2) if meshfree else "*SECTION_SOLID\n" + fields(1, 1)
    # the top wall moves down at 50 mm/ms with a large mass: 7 mm (70% of the height) by 0.14 ms
    return write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(0.14),
        "*DATABASE_GLSTAT\n" + fields(0.001),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.02),
        "*PART\ncube\n" + fields(1, 1, 1, 0, 1),
        section,
        "*HOURGLASS\n" + fields(1, 1, 0.1),
        # soft, perfectly plastic: E 1 GPa, yield 5 MPa
        "*MAT_PLASTIC_KINEMATIC\n" + fields(1, 1.0e-6, 1.0, 0.3, 0.005, 0.0, 1.0) + "\n" + fields(0.0, 0.0),
        "*RIGIDWALL_PLANAR_ID\n" + fields(1) + "anvil\n" + fields(0) + "\n" + fields(0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0),
        "*RIGIDWALL_PLANAR_MOVING_ID\n" + fields(2) + "press\n" + fields(0) + "\n" +
        fields(0.0, 0.0, 10.0, 0.0, 0.0, 9.0, 1.0) + "\n" + fields(1.0e3, 50.0),
        nodes_card(nodes),
        solids_card(elements),
    )


def test_large_deformation_runs_as_efg(tmp_path, run_deck):
    efg = run_deck(squeeze_deck(tmp_path / "efg.k", True), jobid="efg")
    assert efg.status == 0, efg.stdout + efg.stderr
    with efg.open() as results:
        glstat = results["history/glstat"]
        ratio = glstat["energy_ratio"][...]
        nodes = results["mesh/nodes/coordinates"][...]
        states = sorted(results["states"])
        final = results["states"][states[-1]]
        height = (nodes[:, 2] + final["displacement"][:, 2]).max() - (nodes[:, 2] + final["displacement"][:, 2]).min()
    assert height < 3.3, f"the cube was squeezed to {height:.2f} mm only"
    assert np.abs(ratio - 1.0).max() < 0.02, f"energy ratio between {ratio.min():.4f} and {ratio.max():.4f}"

    fe = run_deck(squeeze_deck(tmp_path / "fe.k", False), jobid="fe")
    with fe.open() as results:
        glstat = results["history/glstat"]
        hourglass, internal = glstat["hourglass_energy"][-1], glstat["internal_energy"][-1]
    inverted = fe.status == 1 and "negative volume" in fe.stderr
    assert inverted or hourglass > 0.1 * internal, \
        f"one-point hexahedra survived with hourglass energy {100 * hourglass / internal:.1f}% of internal"


def test_coupled_model_is_identical_for_one_and_two_threads(tmp_path, run_deck):
    nodes, elements = block_mesh((6, 4, 4), (12.0, 8.0, 8.0), origin=(0.0, 0.0, 0.3), perturbation=0.1)
    centres = nodes[elements].mean(axis=1)
    deck = write_deck(
        tmp_path / "coupled.k",
        "*CONTROL_TERMINATION\n" + fields(0.03),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.01),
        *parts_and_sections(),
        "*MAT_PLASTIC_KINEMATIC\n" + fields(1, DENSITY, 200.0, 0.3, 0.4, 1.0, 1.0) + "\n" + fields(0.0, 0.0),
        "*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields(0.0, 0.0, -100.0),
        "*RIGIDWALL_PLANAR\n" + fields(0) + "\n" + fields(0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
        nodes_card(nodes),
        split_cards(nodes, elements, centres[:, 0] < 6.0),
    )
    one, two = run_deck(deck, ncpu=1), run_deck(deck, ncpu=2)
    assert one.status == 0 and two.status == 0, one.stderr + two.stderr

    def datasets(results):
        found = {}
        results.visititems(lambda name, item: found.__setitem__(name, item[...])
                           if isinstance(item, h5py.Dataset) and not name.startswith("timing") else None)
        return found

    with one.open() as first, two.open() as second:
        a, b = datasets(first), datasets(second)
    assert a.keys() == b.keys()
    for name in a:
        assert np.array_equal(a[name], b[name]), f"{name} differs between 1 and 2 threads"
