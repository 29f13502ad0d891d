"""The verification studies of docs/verification.md in small (make verify runs them in full):
linear static patch tests of the three Table 1 variants on an irregular cube, and the cantilever
tip deflection of the FE, EFG and coupled models at the coarsest refinement that is within 1%
of the Timoshenko-Goodier value.

The decks come from the generators of verification/ and the errors from the functions of
postproc/verification_report.py, so the tests check exactly what the report shows.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

REPOSITORY = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPOSITORY / "verification"))
sys.path.insert(0, str(REPOSITORY / "postproc"))

import analytic  # noqa: E402
import cantilever  # noqa: E402
import patch_test  # noqa: E402
import verification_report as report  # noqa: E402

#: Cells along each edge of the irregular cube of the patch tests (27 interior particles).
CUBE_CELLS = 4


@pytest.fixture(scope="module")
def cube_mesh():
    """The irregular cube of the patch tests, 4 x 4 x 4 cells, every node moved."""
    nodes, elements, jacobian = patch_test.cube_geometry(CUBE_CELLS)
    return {"nodes": nodes, "elements": elements, "jacobian": jacobian, "counts": (CUBE_CELLS,) * 3}


def run_case(run_deck, root: Path, case: dict) -> dict:
    """Run a generated case; return the report's reading of its results."""
    run = run_deck(root / case["deck"], jobid=case["name"])
    assert run.status == 0, run.stdout[-2000:] + run.stderr
    data = report.read_results(run.results)
    assert data["ok"], data["message"]
    assert data["states"] == 1, "a static run writes one state"
    return data


def patch_error(tmp_path, run_deck, mesh, method, kernel="box", support=1.5) -> float:
    """Largest interior error, relative to the largest exact component, of u = A X + c."""
    case = patch_test.write_case(tmp_path, "cube", "affine", method, kernel, support, mesh)
    data = run_case(run_deck, tmp_path, case)
    metrics = report.patch_metrics(case, data)
    # the boundary condition itself is applied exactly
    assert metrics["boundary_max"] < 1e-12
    return metrics["interior_relative"]


def test_timoshenko_goodier_formulas():
    # plane-stress Hooke's law from central differences of the displacements (truncation-sized)
    # and equilibrium; the tip value of formulation section 7
    hooke, equilibrium = analytic.check_timoshenko_goodier()
    assert hooke < 1e-6 and equilibrium < 1e-14
    assert analytic.tip_deflection(1e-3, 50.0, 10.0, 1.0, 1.0, 0.3) == pytest.approx(0.51375, rel=1e-14)


def test_projected_end_load_has_the_exact_resultant():
    for cells in (2, 4, 8):
        edges = np.linspace(-5.0, 5.0, cells + 1)
        total = sum(0.5 * (b - a) * np.sum(analytic.projected_corner_values(a, b, 1e-3, 10.0, 1.0))
                    for a, b in zip(edges[:-1], edges[1:]))
        assert total == pytest.approx(1e-3, rel=1e-13)


@pytest.mark.parametrize("kernel, support", [("box", 1.5), ("box", 2.5), ("sphere", 1.5)])
def test_full_method_passes_the_patch_test(tmp_path, run_deck, cube_mesh, kernel, support):
    error = patch_error(tmp_path, run_deck, cube_mesh, "full", kernel, support)
    # measured 1.3e-14 to 1.7e-14 (round-off)
    assert error < 1e-10, f"full method (IEBT 3, IDIM 1): relative interior error {error:.2e}"


def test_table1_slab_full_method_is_exact(tmp_path, run_deck):
    # the Table 1 case of docs/verification.md: slab (0,9) x (0,9) x (0,4), u = X, box DX 1.5
    meshes = patch_test.build_meshes(9, 4, 2)
    case = patch_test.write_case(tmp_path, "slab", "unit", "full", "box", 1.5, meshes["slab"])
    data = run_case(run_deck, tmp_path, case)
    metrics = report.patch_metrics(case, data)
    assert set(metrics["table"]) == {f"({x:g},{y:g})" for x, y in patch_test.TABLE1_POINTS}
    for key, entry in metrics["table"].items():
        # the reported nodes sit at the Table 1 points, so the exact [u1 u2] is Table 1's
        assert entry["exact"][:2] == pytest.approx([float(v) for v in key.strip("()").split(",")],
                                                   abs=1e-12)
        assert entry["computed"][:2] == pytest.approx(entry["exact"][:2], rel=1e-10)
    # measured 2.0e-15
    assert metrics["interior_relative"] < 1e-10


@pytest.mark.parametrize("method", ["conventional", "lbi"])
def test_other_table1_variants_are_not_exact(tmp_path, run_deck, cube_mesh, method):
    error = patch_error(tmp_path, run_deck, cube_mesh, method)
    # measured (box DX 1.5, this cube): 4.4e-3 conventional (IEBT 1, IDIM 4), 5.3e-3 local
    # boundary integration without the boundary correction (IEBT 1, IDIM 1)
    assert error > 1e-5, f"{method}: unexpectedly exact ({error:.2e})"


#: model -> (cells over the depth of the coarsest refinement within 1% (n_x = 5 n_y, n_z = 2),
#: v_tip / v_exact measured there by make verify).
CANTILEVER_LEVELS = {
    "fe": (8, 0.99223),        # 40 x 8 x 2 fully integrated hexahedra: -0.78%
    "coupled": (4, 0.99326),   # 20 x 4 x 2, EFG for x < L/2: -0.67%
    "efg": (4, 0.99729),       # 20 x 4 x 2 all EFG, DX 1.5: -0.27%
}


@pytest.mark.parametrize("model", sorted(CANTILEVER_LEVELS))
def test_cantilever_tip_deflection_within_one_percent(tmp_path, run_deck, model):
    level, measured = CANTILEVER_LEVELS[model]
    case = cantilever.write_case(tmp_path, model, level, 2, "projected")
    data = run_case(run_deck, tmp_path, case)
    problem = {"length": cantilever.LENGTH, "depth": cantilever.DEPTH, "width": cantilever.WIDTH,
               "young": cantilever.YOUNG, "poisson": cantilever.POISSON, "load": cantilever.LOAD,
               "tip_deflection": analytic.tip_deflection(cantilever.LOAD, cantilever.LENGTH,
                                                         cantilever.DEPTH, cantilever.WIDTH,
                                                         cantilever.YOUNG, cantilever.POISSON)}
    metrics = report.cantilever_metrics(case, data, problem)
    if model != "fe":
        assert metrics["particles"] == case["expected_interior_particles"]
    assert abs(metrics["tip"] - 1.0) < 0.01, f"{model}: v_tip / v_exact = {metrics['tip']:.5f}"
    # a regression guard on the measured value (a change of the elements or of EFG shows here)
    assert metrics["tip"] == pytest.approx(measured, abs=2e-5)
