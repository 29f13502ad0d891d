"""FE solids folded inside out at a corner are reported. One corner of a unit hexahedron is
pushed straight down through the opposite face (1.3 mm in 1 ms): the corner Jacobians there turn
negative when it crosses the face (t = 1/1.3 ms), while the element's volume stays positive
(0.675 at the end), so the run goes on. The solver must warn at the first state after the
crossing, name the element, and record the worst corner Jacobian ratio in /run; the ratio is
checked against an independent numpy computation of the corner determinants."""
import re
import sys
from pathlib import Path

import numpy as np

from deck_writer import block_mesh, fields, nodes_card, solids_card, write_deck

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "postproc"))
from odb_component import corner_determinants  # noqa: E402

CROSSING = 1.0 / 1.3        # ms: the corner passes the opposite face
STATE_INTERVAL = 0.05       # ms


def test_folded_solid_is_reported_with_its_corner_jacobian(tmp_path, run_deck):
    nodes, elements = block_mesh((1, 1, 1), (1.0, 1.0, 1.0))
    corner = int(np.flatnonzero(np.all(np.isclose(nodes, 1.0), axis=1))[0]) + 1     # the node at (1, 1, 1)
    spc = ["*BOUNDARY_SPC_NODE"] + [fields(n, 0, 1, 1, 1, 0, 0, 0) for n in range(1, 9) if n != corner]
    spc += [fields(corner, 0, 1, 1, 0, 0, 0, 0)]
    motion = ["*BOUNDARY_PRESCRIBED_MOTION_NODE", fields(corner, 3, 2, 1, -1.3)]
    deck = write_deck(
        tmp_path / "fold.k",
        "*CONTROL_TERMINATION\n" + fields(1.0),
        "*DATABASE_BINARY_D3PLOT\n" + fields(STATE_INTERVAL),
        "*PART\ncorner\n" + fields(42, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, 1.0e-6, 0.01, 0.3),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + f"{0.0:20.6e}{0.0:20.6e}\n{1.0:20.6e}{1.0:20.6e}",
        nodes_card(nodes),
        solids_card(elements, part_id=42, first_id=17),
        "\n".join(spc),
        "\n".join(motion),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    warnings = re.findall(r"warning: t = +([0-9.Ee+-]+): (\d+) FE solid\(s\) folded inside out at a corner.*"
                          r"element (\d+) \(part (\d+)\), has a corner Jacobian ratio of +([0-9.Ee+-]+)", run.stdout)
    assert len(warnings) == 1, run.stdout
    time, count, element, part, _ = warnings[0]
    assert (int(count), int(element), int(part)) == (1, 17, 42)
    assert CROSSING <= float(time) <= CROSSING + STATE_INTERVAL * 1.01
    with run.open() as results:
        attributes = dict(results["run"].attrs)
        connectivity = results["mesh/solids/connectivity_index"][...]
        reference = results["mesh/nodes/coordinates"][...]
        names = sorted(results["states"].keys())
        first, last = results["states"][names[0]], results["states"][names[-1]]
        ratios = []
        for state in (first, last):
            determinants = corner_determinants(reference + state["displacement"][...], connectivity)
            ratios.append(determinants.min() / np.abs(determinants).max())
    print(f"folded corner: warning at t = {float(time):.3f} ms (crossing {CROSSING:.3f}), "
          f"ratio {attributes['worst_corner_jacobian_ratio']:.6f} (numpy {ratios[1]:.6f})")
    assert abs(ratios[0] - 1.0) < 1e-12
    assert attributes["tangled_solids"] == 1 and attributes["worst_corner_jacobian_element"] == 17
    assert abs(attributes["worst_corner_jacobian_ratio"] - ratios[1]) < 1e-12
    assert attributes["worst_corner_jacobian_ratio"] < 0.0
