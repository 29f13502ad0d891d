"""A run-time failure keeps what was computed: one corner of a hexahedron is pushed into it
until its volume is negative, the element inverts, and the run stops with exit status 1, a message naming the
element, the part and the time, and a readable results file whose last state is that time."""
import re

from conftest import last_state
from deck_writer import block_mesh, fields, nodes_card, solids_card, write_deck


def test_inverted_element_stops_the_run_and_keeps_results(tmp_path, run_deck):
    nodes, elements = block_mesh((1, 1, 1), (1.0, 1.0, 1.0))
    corner = 8     # node at (1, 1, 1) in block_mesh's numbering
    spc = ["*BOUNDARY_SPC_NODE"] + [fields(n, 0, 1, 1, 1, 0, 0, 0) for n in range(1, 9) if n != corner]
    # displacement (VAD = 2) jumping by 1.5 mm along (-1,-1,-1) at t = 0.01 ms: past 4/3 mm the
    # trilinear volume of the unit cube is negative
    motion = ["*BOUNDARY_PRESCRIBED_MOTION_NODE"] + [fields(corner, d, 2, 1, -1.5) for d in (1, 2, 3)]
    deck = write_deck(
        tmp_path / "crush.k",
        "*CONTROL_TERMINATION\n" + fields(1.0),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.5),
        "*PART\ncorner\n" + fields(42, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, 7.85e-6, 1.0, 0.3),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + "\n".join(
            f"{t:20.6e}{u:20.6e}" for t, u in ((0.0, 0.0), (0.01, 0.0), (0.0101, 1.0), (10.0, 1.0))),
        nodes_card(nodes),
        solids_card(elements, part_id=42, first_id=17),
        "\n".join(spc),
        "\n".join(motion),
    )
    run = run_deck(deck)
    assert run.status == 1, run.stdout + run.stderr
    found = re.search(r"negative volume in solid element 17 \(part 42\) at time\s+([0-9.Ee+-]+)", run.stderr)
    assert found, run.stderr
    failure_time = float(found.group(1))
    # the first step that ends after the jump (steps are about 2.5e-3 ms)
    assert 0.01 < failure_time < 0.02
    with run.open() as results:
        assert results["run"].attrs["status"] == "error termination"
        assert "element 17" in results["run"].attrs["message"]
        state = last_state(results)
        assert abs(state.attrs["time"] - failure_time) <= 1e-5 * failure_time   # printed with 6 digits
        assert len(results["history/glstat/time"]) >= 2
