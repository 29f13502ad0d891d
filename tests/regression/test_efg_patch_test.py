"""Explicit patch tests of meshfree (EFG) parts and of a coupled FE + EFG model on irregular
meshes (formulation section 7, property 5 in explicit form).

Initial velocity v = A X on every node and the same velocity prescribed on the boundary nodes:
the exact solution keeps v = A X. With the coupled shape functions and the modified SCNI
(IDIM = 1), every node (physical values, through the transformation of eq. 16) still moves with
A X after 100 cycles, to 1e-10 relative, for box and spherical kernels and supports DX from 1.01
to 2. Gauss integration with direct gradients (IDIM = 2) breaks the integration constraint, and
the error it leaves is what Table 1 of the paper attributes to it.
"""
import numpy as np
import pytest

from conftest import last_state
from deck_writer import (block_mesh, boundary_node_mask, efg_section, fields, nodes_card,
                         round_to_node_card, solids_card, write_deck)

VELOCITY_GRADIENT = np.array([[0.010, 0.004, -0.002],
                              [0.003, -0.006, 0.005],
                              [-0.001, 0.002, 0.008]])


def patch_deck(path, section_cards, coupled, cells=(6, 5, 5)):
    """An irregular block of 1.2 x 1 x 1; part 1 (meshfree) everywhere, or, when coupled, part 2
    (fully integrated hexahedra) for the cells with x > 0.6."""
    nodes, elements = block_mesh(cells, (1.2, 1.0, 1.0), perturbation=0.25, seed=11)
    nodes = round_to_node_card(nodes)
    centres = nodes[elements].mean(axis=1)
    fe_cells = centres[:, 0] > 0.6 if coupled else np.zeros(len(elements), bool)
    velocity = nodes @ VELOCITY_GRADIENT.T
    boundary = np.flatnonzero(boundary_node_mask(nodes))
    initial = ["*INITIAL_VELOCITY_NODE+"]
    for k, v in enumerate(velocity):
        initial.append(f"{k + 1:20d}{v[0]:20.13e}{v[1]:20.13e}{v[2]:20.13e}")
    motion = ["*BOUNDARY_PRESCRIBED_MOTION_NODE+"]
    for k in boundary:
        for direction in range(3):
            value = velocity[k, direction]
            curve, scale = (1, value) if value != 0.0 else (2, 1.0)
            motion.append(f"{k + 1:20d}{direction + 1:20d}{0:20d}{curve:20d}{scale:20.13e}")
    element_cards = solids_card(elements[~fe_cells], part_id=1)
    if coupled:
        fe = solids_card(elements[fe_cells], part_id=2, first_id=1001)
        element_cards += "\n" + fe.split("\n", 1)[1]
    write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(1.0, 100),
        "*DATABASE_BINARY_D3PLOT\n" + fields(1.0),
        "*PART\nmeshfree\n" + fields(1, 1, 1),
        "*PART\nfinite elements\n" + fields(2, 2, 1),
        section_cards,
        "*SECTION_SOLID\n" + fields(2, 2),
        "*MAT_ELASTIC\n" + fields(1, 7.8e-6, 210.0, 0.3),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + f"{0.0:20.6e}{1.0:20.6e}\n{10.0:20.6e}{1.0:20.6e}",
        "*DEFINE_CURVE\n" + fields(2) + "\n" + f"{0.0:20.6e}{0.0:20.6e}\n{10.0:20.6e}{0.0:20.6e}",
        nodes_card(nodes),
        element_cards,
        "\n".join(initial),
        "\n".join(motion),
    )
    return path, nodes


def velocity_error(run, nodes):
    with run.open() as results:
        assert results["run"].attrs["cycles"] == 100
        assert int(results["timing"].attrs["efg_particles"]) > 0
        velocity = last_state(results)["velocity"][...]
    expected = nodes @ VELOCITY_GRADIENT.T
    return np.abs(velocity - expected).max() / np.abs(expected).max()


CASES = [(kernel, support, coupled) for kernel in (0, 2) for support in (1.01, 1.5, 2.0)
         for coupled in (False, True)]


@pytest.mark.parametrize("kernel, support, coupled", CASES,
                         ids=[f"{'sphere' if k else 'box'}-{s}-{'coupled' if c else 'efg'}" for k, s, c in CASES])
def test_linear_field_is_exact(tmp_path, run_deck, kernel, support, coupled):
    # a spherical support of DX 2 reaches across a part 5 cells thick and gives negative row-sum
    # masses there (formulation section 2): that case runs on a thicker block
    cells = (10, 9, 9) if kernel == 2 and support >= 2.0 else (6, 5, 5)
    deck, nodes = patch_deck(tmp_path / "patch.k", efg_section(1, support, kernel), coupled, cells)
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    error = velocity_error(run, nodes)
    assert error < 1e-10, f"velocity error {error:.3e}"


def test_gauss_integration_is_not_exact(tmp_path, run_deck):
    deck, nodes = patch_deck(tmp_path / "patch.k", efg_section(1, 1.5, 0, integration=2), False)
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    error = velocity_error(run, nodes)
    # measured 1.3e-2 (percents, as Table 1 of the paper reports for Gauss integration), against
    # 1e-14 for the local boundary integration above
    assert error > 1e-6, f"Gauss integration unexpectedly exact ({error:.3e})"


@pytest.mark.parametrize("boundary_treatment, integration, field", [(1, 1, "IEBT = 1"), (3, 4, "IDIM = 4")])
def test_verification_variants_are_rejected_in_explicit_runs(tmp_path, run_deck, boundary_treatment,
                                                             integration, field):
    # IEBT 1 and IDIM 4 are the other columns of Table 1: linear static analysis only
    deck, _ = patch_deck(tmp_path / "patch.k", efg_section(1, 1.5, 0, boundary_treatment, integration), False)
    run = run_deck(deck)
    assert run.status == 2
    assert "patch.k:8: *PART: field SECID" in run.stderr and field in run.stderr, run.stderr
