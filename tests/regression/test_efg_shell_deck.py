"""The keyword of the meshfree (EFG) shell: *SECTION_SHELL ELFORM 41 and its EFG card DX DY
ISPLINE IDILA IEBT IDIM. A deck with it is accepted and its part is written as meshfree
(`/mesh/parts/formulation` "efg"); values crashfree does not build are refused before the run
(exit 2) with file:line, field and reason."""
import numpy as np

from deck_writer import fields, nodes_card, plate_mesh, round_to_node_card, shells_card, write_deck

THICKNESS, YOUNGS, POISSON, DENSITY = 1.0, 210.0, 0.3, 7.85e-6


def plate_deck(path, efg_card, elform=41, end_time=0.01):
    """A free 4 x 4 plate of part 1 on a shell section with ELFORM `elform` followed by
    `efg_card` (None: no EFG card), and beside it a 1 x 1 Belytschko-Tsay plate, part 2, which
    gives the model mass whichever groups compute the meshfree part. The EFG card is on line 7
    of the deck."""
    nodes, shells = plate_mesh((4, 4), (40.0, 40.0), perturbation=0.2)
    nodes = round_to_node_card(nodes)
    fe_nodes, fe_shells = plate_mesh((1, 1), (10.0, 10.0))
    fe_nodes[:, 0] += 60.0
    section = ["*SECTION_SHELL", fields(1, elform, f"{5 / 6:10.7f}", 3), fields(THICKNESS)]
    if efg_card is not None:
        section.append(efg_card)
    return write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(end_time),         # lines 2-3
        "\n".join(section),                                  # lines 4-7
        "*PART\nmeshfree plate\n" + fields(1, 1, 1),
        "*SECTION_SHELL\n" + fields(2, 2) + "\n" + fields(THICKNESS),
        "*PART\nFE plate\n" + fields(2, 2, 1),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, YOUNGS, POISSON),
        "*DATABASE_BINARY_D3PLOT\n" + fields(end_time),
        nodes_card(nodes),
        nodes_card(round_to_node_card(fe_nodes), first_id=len(nodes) + 1).replace("*NODE\n", ""),
        shells_card(shells),
        shells_card(fe_shells, part_id=2, first_id=len(shells) + 1, first_node_id=len(nodes) + 1)
        .replace("*ELEMENT_SHELL\n", ""),
    )


def test_meshfree_shell_section_is_read_and_its_part_is_meshfree(tmp_path, run_deck):
    deck = plate_deck(tmp_path / "plate.k", fields(1.5, 1.5, 0, 0, 3, 1))
    assert deck.read_text().splitlines()[6].startswith("       1.5")
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    with run.open() as results:
        formulations = [f.decode() if isinstance(f, bytes) else f for f in results["/mesh/parts/formulation"][()]]
        assert formulations == ["efg", "fe"]
        assert np.asarray(results["/mesh/parts/ids"][()]).tolist() == [1, 2]


def test_every_efg_card_value_not_built_is_refused_with_its_line_and_field(tmp_path, run_deck):
    cases = [
        (fields(0.9), "field DX: DX must be greater than 1"),
        (fields(1.5, 1e29), "field DY: DY must be at most 4.0 (the support in element neighbour distances; 1.0 to "
                            "2.0 is usual, and wider supports cover most of the part); found 1.0e29"),
        (fields(None, None, 3), "field ISPLINE: must be 0 (cubic spline, box support), 1 (quadratic spline, box "
                                "support) or 2 (cubic spline, circular support), found 3"),
        (fields(None, None, None, 1), "field IDILA: IDILA 1 (support size from the surrounding nodes) is not "
                                      "available"),
        (fields(None, None, None, None, 1), "field IEBT: essential boundary treatment 1 is not available for "
                                            "meshfree shells"),
        (fields(None, None, None, None, None, 2), "field IDIM: domain integration 2 is not available for meshfree "
                                                  "shells"),
    ]
    for number, (card, reason) in enumerate(cases):
        deck = plate_deck(tmp_path / f"bad{number}.k", card)
        run = run_deck(deck, jobid=f"bad{number}")
        assert run.status == 2, (card, run.stdout, run.stderr)
        assert f"bad{number}.k:7: *SECTION_SHELL: {reason}" in run.stderr, run.stderr


def test_global_meshfree_shell_and_a_missing_efg_card_are_refused(tmp_path, run_deck):
    run = run_deck(plate_deck(tmp_path / "global.k", fields(1.5, 1.5), elform=42), jobid="global")
    assert run.status == 2
    assert ("global.k:5: *SECTION_SHELL: field ELFORM: the global meshfree shell (ELFORM 42, LS-DYNA's EFG "
            "shell for metal forming) is not available; use ELFORM 41") in run.stderr, run.stderr
    run = run_deck(plate_deck(tmp_path / "missing.k", None), jobid="missing")
    assert run.status == 2
    assert ("missing.k:6: *SECTION_SHELL: field DX: the EFG card (DX DY ISPLINE IDILA IEBT IDIM) of section 1 "
            "is missing") in run.stderr, run.stderr


def test_a_concave_meshfree_shell_cell_is_refused_with_its_line(tmp_path, run_deck):
    """A meshfree cell is split into sub-cells at its centre, so a concave quadrilateral would have
    a sub-cell of negative area: the deck check refuses it with the element's line, its corner
    and node (an FE shell part with the same cell is accepted: the Belytschko-Tsay shell takes
    it). The centre node of the 4 x 4 plate (node 13, at about (20, 20)) is pulled to (14, 14),
    past the diagonal of shell 6, whose corner N3 it is."""
    for elform, expected in [(41, 2), (2, 0)]:
        deck = plate_deck(tmp_path / f"concave{elform}.k", fields(1.5, 1.5) if elform == 41 else None, elform=elform)
        lines = deck.read_text().splitlines()
        node_line = next(k for k, line in enumerate(lines) if line.startswith(f"{13:8d}"))
        lines[node_line] = f"{13:8d}{14.0:16.6f}{14.0:16.6f}{0.0:16.6f}"
        deck.write_text("\n".join(lines) + "\n")
        run = run_deck(deck, jobid=f"concave{elform}")
        assert run.status == expected, run.stdout + run.stderr
        if elform == 41:
            assert "*ELEMENT_SHELL: field N1-N4: shell 6 of meshfree part 1 is not convex at its corner N3 (node 13): " \
                   "a meshfree shell cell (ELFORM 41) must be a convex quadrilateral or a triangle" in run.stderr, \
                run.stderr
