"""Elastic block in free vibration: total energy (kinetic + internal + hourglass) stays within
0.5% of its initial value over 10,000 cycles. The initial velocity, v_i = V cos(pi X_i / L), has
neither momentum nor angular momentum: the block only deforms."""
import numpy as np
import pytest

from deck_writer import block_mesh, fields, nodes_card, solids_card, write_deck


@pytest.mark.parametrize("element_formulation", [1, 2])
def test_total_energy_is_conserved(tmp_path, run_deck, element_formulation):
    nodes, elements = block_mesh((4, 4, 4), (10.0, 10.0, 10.0), perturbation=0.15, seed=3)
    initial = ["*INITIAL_VELOCITY_NODE"]
    for k, position in enumerate(nodes):
        initial.append(fields(k + 1, *[float(v) for v in 20.0 * np.cos(np.pi * position / 10.0)]))
    deck = write_deck(
        tmp_path / "vibration.k",
        "*CONTROL_TERMINATION\n" + fields(100.0, 10000),
        "*DATABASE_GLSTAT\n" + fields(1.0e-4),
        "*PART\nblock\n" + fields(1, 1, 1, 0, 1),
        "*SECTION_SOLID\n" + fields(1, element_formulation),
        "*MAT_ELASTIC\n" + fields(1, 7.85e-6, 210.0, 0.3),
        "*HOURGLASS\n" + fields(1, 4, 0.1),
        nodes_card(nodes),
        solids_card(elements),
        "\n".join(initial),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    with run.open() as results:
        assert results["run"].attrs["cycles"] == 10000
        glstat = results["history/glstat"]
        total = glstat["total_energy"][...]
        internal = glstat["internal_energy"][...]
    assert internal.max() > 0.2 * total[0], "the block must really vibrate"
    drift = np.abs(total - total[0]).max() / total[0]
    assert drift < 0.005, f"total energy drift {100 * drift:.3f}%"
