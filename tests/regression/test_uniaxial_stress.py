"""One hexahedron of *MAT_PLASTIC_KINEMATIC pulled along x.

Uniaxial stress (symmetry planes x = 0, y = 0, z = 0; the x = 1 face pulled slowly): the stress
follows the bilinear law in logarithmic strain (slope E, then ETAN after SIGY).
Cowper-Symonds is checked in uniaxial strain (every dof but the pulled one held), where the
strain rate is exactly known: the yield stress is scaled by 1 + (rate / C)^(1 / P) with the
effective rate sqrt(2/3 D':D') = 2/3 of the axial rate. (In uniaxial stress a single element's
free lateral dofs ring, and the ringing modulates a rate-dependent yield stress.)"""
import numpy as np
import pytest

from deck_writer import block_mesh, fields, nodes_card, node_list_set, solids_card, write_deck

E, NU, SIGY, ETAN = 200.0, 0.3, 0.25, 2.0     # GPa
PULL_SPEED = 0.05                             # mm/ms on a 1 mm element: strain rate 0.05 / ms
RAMP = 0.05                                   # ms to reach the pull speed smoothly


def uniaxial_deck(path, element_formulation, rate_c=0.0, rate_p=0.0, lateral_held=False):
    nodes, elements = block_mesh((1, 1, 1), (1.0, 1.0, 1.0))
    on = {axis: list(np.flatnonzero(np.abs(nodes[:, axis]) < 1e-9) + 1) for axis in range(3)}
    pulled = list(np.flatnonzero(np.abs(nodes[:, 0] - 1.0) < 1e-9) + 1)
    spc = ["*BOUNDARY_SPC_NODE"]
    for node in range(1, len(nodes) + 1):
        dofs = [int(node in on[axis] or (lateral_held and axis > 0)) for axis in range(3)]
        if any(dofs):
            spc.append(fields(node, 0, *dofs, 0, 0, 0))
    curve = "\n".join(f"{t:20.6e}{min(t / RAMP, 1.0):20.6e}" for t in np.linspace(0.0, RAMP, 11)) + \
        f"\n{10.0:20.6e}{1.0:20.6e}"
    return write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(0.8),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.01),
        "*PART\nelement\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, element_formulation),
        "*MAT_PLASTIC_KINEMATIC\n" + fields(1, 7.85e-6, E, NU, SIGY, ETAN, 1.0) + "\n" +
        fields(rate_c, rate_p),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + curve,
        node_list_set(1, pulled),
        "*BOUNDARY_PRESCRIBED_MOTION_SET\n" + fields(1, 1, 0, 1, PULL_SPEED),
        "\n".join(spc),
        nodes_card(nodes),
        solids_card(elements),
    )


def stress_strain(run):
    with run.open() as results:
        strains, stresses = [], []
        nodes = results["mesh/nodes/coordinates"][...]
        pulled = np.abs(nodes[:, 0] - 1.0) < 1e-9
        for name in sorted(results["states"]):
            state = results["states"][name]
            stretch = 1.0 + state["displacement"][pulled, 0].mean()
            strains.append(np.log(stretch))
            stresses.append(state["solid_stress"][0, 0])
    return np.array(strains), np.array(stresses)


def bilinear(strain, yield_stress):
    elastic = E * strain
    plastic = yield_stress + ETAN * (strain - yield_stress / E)
    return np.where(strain < yield_stress / E, elastic, plastic)


@pytest.mark.parametrize("element_formulation", [1, 2])
def test_stress_follows_bilinear_law(tmp_path, run_deck, element_formulation):
    run = run_deck(uniaxial_deck(tmp_path / "uniaxial.k", element_formulation))
    assert run.status == 0, run.stderr
    strain, stress = stress_strain(run)
    assert strain[-1] > 0.03
    away_from_knee = np.abs(strain - SIGY / E) > 2e-4
    expected = bilinear(strain, SIGY)
    error = np.abs(stress - expected)[away_from_knee].max()
    assert error < 0.01 * SIGY, f"largest deviation {error:.4g} GPa"
    # lateral stresses vanish (uniaxial stress)
    with run.open() as results:
        last = results["states"][sorted(results["states"])[-1]]["solid_stress"][0]
        ratio = results["history/glstat/energy_ratio"][-1]
    assert abs(last[1]) < 1e-3 * SIGY and abs(last[2]) < 1e-3 * SIGY
    # the work of the prescribed motion's reaction balances the internal energy
    assert abs(ratio - 1.0) < 0.01, f"energy ratio {ratio:.4f}"


def test_cowper_symonds_scales_the_yield_stress(tmp_path, run_deck):
    rate_c, rate_p = 0.5, 5.0      # 1/ms and exponent
    run = run_deck(uniaxial_deck(tmp_path / "rate.k", 1, rate_c, rate_p, lateral_held=True))
    assert run.status == 0, run.stderr
    with run.open() as results:
        last = results["states"][sorted(results["states"])[-1]]
        stress = last["solid_stress"][0]
        plastic_strain = last["solid_plastic_strain"][0]
        stretch = 1.0 + last["displacement"][...][:, 0].max()
    axial_rate = PULL_SPEED / stretch                 # true strain rate at the end
    effective_rate = 2.0 / 3.0 * axial_rate           # sqrt(2/3 D':D') for D = diag(r, 0, 0)
    factor = 1.0 + (effective_rate / rate_c) ** (1.0 / rate_p)
    hardening = E * ETAN / (E - ETAN)
    expected = factor * (SIGY + hardening * plastic_strain)
    equivalent = stress[0] - stress[1]                # von Mises stress in uniaxial strain
    assert plastic_strain > 0.02
    assert abs(stress[1] - stress[2]) < 1e-9 * abs(stress[0])
    assert abs(equivalent - expected) / expected < 0.01, f"{equivalent:.5g} vs {expected:.5g}"
