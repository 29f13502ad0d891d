"""Crushable materials in a full run: a honeycomb cube (*MAT_MODIFIED_HONEYCOMB and *MAT_HONEYCOMB,
flat crush curve, AOPT 0 element axes) on a stationary rigid wall, crushed by a heavy moving
rigid wall. On the plateau the wall force per unit area equals the crush strength (analytical:
the curve's 1 MPa plus the shock term rho v^2, here 1e-3 of it) within 3%."""
import numpy as np
import pytest

from deck_writer import block_mesh, fields, nodes_card, solids_card, write_deck

DENSITY = 5.0e-8          # kg/mm^3 (50 kg/m^3)
CRUSH_STRENGTH = 0.001    # GPa (1 MPa)
SPEED = 5.0               # mm/ms
SIDE = 10.0               # mm


def crush_deck(path, keyword):
    nodes, elements = block_mesh((2, 2, 4), (SIDE, SIDE, SIDE))
    return write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(1.0),
        "*DATABASE_RWFORC\n" + fields(0.01),
        "*DATABASE_GLSTAT\n" + fields(0.01),
        "*PART\nhoneycomb\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        # MID RO E PR SIGY VF MU BULK / LCA / EAAU..GCAU AOPT / XP..A3 / D1..
        f"*{keyword}\n" + fields(1, DENSITY, 1.0, 0.3, 1.0, 0.2, 0.0, 0.0) + "\n" + fields(10) + "\n" +
        fields(0.1, 0.1, 0.1, 0.05, 0.05, 0.05, 0.0) + "\n" + fields(0.0) + "\n" + fields(0.0),
        "*DEFINE_CURVE\n" + fields(10) + f"\n0.0,{CRUSH_STRENGTH}\n1.0,{CRUSH_STRENGTH}",
        "*RIGIDWALL_PLANAR_ID\n" + fields(2) + "floor\n" + fields(0) + "\n" + fields(0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
        "*RIGIDWALL_PLANAR_MOVING_ID\n" + fields(3) + "ram\n" + fields(0) + "\n" +
        fields(0.0, 0.0, SIDE + 0.2, 0.0, 0.0, -1.0) + "\n" + fields(1.0, SPEED),
        nodes_card(nodes),
        solids_card(elements),
    )


@pytest.mark.parametrize("keyword", ["MAT_MODIFIED_HONEYCOMB", "MAT_HONEYCOMB"])
def test_honeycomb_plateau_force(tmp_path, run_deck, keyword):
    run = run_deck(crush_deck(tmp_path / "crush.k", keyword))
    assert run.status == 0, run.stderr
    with run.open() as results:
        ram = results["history/rwforc/3"]
        time, force = ram["time"][...], ram["force"][...]
        floor = results["history/rwforc/2/force"][...]
    crush = SPEED * time - 0.2                       # wall travel into the block (mm)
    plateau = (crush > 1.0) & (crush < 4.5)          # past the elastic rise, before compaction (V > VF)
    expected = (CRUSH_STRENGTH + DENSITY * SPEED ** 2) * SIDE * SIDE
    pressure_ram = np.abs(force[plateau, 2])
    pressure_floor = np.abs(floor[plateau, 2])
    assert abs(pressure_ram.mean() / expected - 1.0) < 0.03
    assert np.abs(pressure_ram / expected - 1.0).max() < 0.10
    assert abs(pressure_floor.mean() / expected - 1.0) < 0.03
