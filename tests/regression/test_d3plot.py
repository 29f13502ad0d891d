"""LS-DYNA's d3plot database beside results.h5, read by lasso-python (docs/output.md, d3plot).

Every test opens the d3plot of a run with lasso-python's D3plot and compares it with the run's
results.h5: node count and ids, element ids, connectivity, part ids and titles, the time of
every state, the current coordinates (reference + displacement), velocities, stresses and
plastic strains at every state. d3plot stores 32-bit floats, so values agree to single
precision: 1e-6 of the largest value of the field (coordinates: of the model's size). The
global energies agree with glstat at the same times; eroded elements carry LS-DYNA's deleted
flag; family files (d3plot01, ...) past the size limit (x=) read as one database.
"""
from __future__ import annotations

import os
import subprocess
from pathlib import Path

import h5py
import numpy as np
import pytest

lasso_dyna = pytest.importorskip("lasso.dyna")
D3plot, ArrayType = lasso_dyna.D3plot, lasso_dyna.ArrayType

from conftest import BINARY, REPOSITORY  # noqa: E402
from deck_writer import (block_mesh, fields, node_list_set, nodes_card, plate_mesh, round_to_node_card,  # noqa: E402
                         shells_card, solids_card, write_deck)

E, NU, SIGY, ETAN, DENSITY = 200.0, 0.3, 0.25, 2.0, 7.85e-6   # GPa, kg/mm^3 (mm, ms)
SPEED, RAMP = 0.2, 0.05                                        # mm/ms, ms
SINGLE = 1e-6                                                  # single precision, relative


def ramp_curve():
    return "*DEFINE_CURVE\n" + fields(1) + "\n" + fields(0.0, 0.0, width=20) + "\n" + \
        fields(RAMP, 1.0, width=20) + "\n" + fields(100.0, 1.0, width=20)


def pulled_deck(path, kind, cells, length, end_time, state_interval, points=5, failure=0.0, title="pulled"):
    """A bar of solids (1 x 1 mm) or a strip of shells (1 mm wide, 0.1 mm thick, NIP `points`)
    of *MAT_PIECEWISE_LINEAR_PLASTICITY in uniaxial stress, its end x = `length` pulled at SPEED
    after a ramp: it yields (SIGY / E = 0.125 %) within the run. Node ids start at 101, element
    ids at 1001 and the part id is 7, so that ids and indices differ."""
    if kind == "solid":
        nodes, elements = block_mesh((cells, 1, 1), (length, 1.0, 1.0))
        element_cards = solids_card(elements, part_id=7, first_id=1001, first_node_id=101)
        section = "*SECTION_SOLID\n" + fields(3, 1)
    else:
        nodes, elements = plate_mesh((cells, 1), (length, 1.0))
        element_cards = shells_card(elements, part_id=7, first_id=1001, first_node_id=101)
        section = "*SECTION_SHELL\n" + fields(3, 2, 1.0, points) + "\n" + fields(*[0.1] * 4)
    nodes = round_to_node_card(nodes)
    spc = ["*BOUNDARY_SPC_NODE"]
    for k, node in enumerate(nodes):
        dofs = [int(abs(node[axis]) < 1e-9) for axis in range(3)]
        if kind == "shell":
            dofs[2] = 1
        if any(dofs):
            spc.append(fields(k + 101, 0, *dofs, *([1, 1, 1] if kind == "shell" else [0, 0, 0])))
    pulled = list(np.flatnonzero(np.abs(nodes[:, 0] - length) < 1e-9) + 101)
    return write_deck(
        path,
        f"*TITLE\n{title}",
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_GLSTAT\n" + fields(state_interval / 2),
        "*DATABASE_BINARY_D3PLOT\n" + fields(state_interval),
        f"*PART\n{kind} of part seven\n" + fields(7, 3, 5),
        section,
        "*MAT_PIECEWISE_LINEAR_PLASTICITY\n" + fields(5, DENSITY, E, NU, SIGY, ETAN, failure) + "\n" + fields(0.0),
        ramp_curve(),
        node_list_set(1, pulled),
        "*BOUNDARY_PRESCRIBED_MOTION_SET\n" + fields(1, 1, 0, 1, SPEED),
        "\n".join(spc),
        nodes_card(nodes, first_id=101),
        element_cards,
    )


def run_solver(deck, output, *extra):
    output.mkdir(exist_ok=True)
    environment = dict(os.environ, OMP_NUM_THREADS="1")
    process = subprocess.run([str(BINARY), f"i={deck}", f"outdir={output}", "ncpu=1", *extra],
                             capture_output=True, text=True, timeout=300, env=environment)
    assert process.returncode == 0, process.stderr
    return process


def states(results, name):
    """(states, ...) array of `name` over every state of results.h5."""
    return np.stack([results["states"][key][name][()] for key in sorted(results["states"])])


def assert_close(actual, expected, what, scale=None):
    """Equal to single precision: within SINGLE of `scale`, by default the field's largest
    magnitude (a mean over layers: the layers' largest magnitude, whose rounding it carries)."""
    actual, expected = np.asarray(actual, float), np.asarray(expected, float)
    assert actual.shape == expected.shape, f"{what}: shape {actual.shape} != {expected.shape}"
    if scale is None:
        scale = max(np.abs(expected).max(initial=0.0), 1e-30)
    error = np.abs(actual - expected).max(initial=0.0)
    print(f"  {what}: largest difference {error:.3e} of {scale:.3e}")
    assert error <= SINGLE * scale, f"{what}: differs by {error} (scale {scale})"


def von_mises(s):
    """Von Mises stress of (..., 6) global stresses xx yy zz xy yz zx."""
    return np.sqrt(0.5 * ((s[..., 0] - s[..., 1]) ** 2 + (s[..., 1] - s[..., 2]) ** 2 + (s[..., 2] - s[..., 0]) ** 2)
                   + 3 * (s[..., 3] ** 2 + s[..., 4] ** 2 + s[..., 5] ** 2))


def check_common(plot, results):
    """Mesh, ids, parts, times, coordinates and velocities: d3plot against results.h5."""
    mesh = results["mesh"]
    node_ids = mesh["nodes/ids"][()]
    coordinates = mesh["nodes/coordinates"][()]
    assert plot.header.n_nodes == len(node_ids)
    assert np.array_equal(plot.arrays[ArrayType.node_ids], node_ids)
    assert_close(plot.arrays[ArrayType.node_coordinates], coordinates, "reference coordinates")
    part_ids = mesh["parts/ids"][()]
    assert np.array_equal(plot.arrays[ArrayType.part_ids], part_ids)
    assert np.array_equal(plot.arrays[ArrayType.part_titles_ids], part_ids)
    times = np.array([results["states"][key].attrs["time"] for key in sorted(results["states"])])
    assert len(times) >= 3
    assert_close(plot.arrays[ArrayType.global_timesteps], times, "times")
    scale = np.abs(coordinates).max()
    current = plot.arrays[ArrayType.node_displacement]  # LS-DYNA writes the current coordinates
    displacement = states(results, "displacement")
    error = np.abs(current - (coordinates + displacement)).max()
    print(f"  coordinates: largest difference {error:.3e} of the model size {scale:.3e}")
    assert error <= SINGLE * scale
    assert np.abs(displacement).max() > 1e-3 * scale          # the model moved
    assert_close(plot.arrays[ArrayType.node_velocity], states(results, "velocity"), "velocities")
    return times


def check_solids(plot, results):
    mesh = results["mesh"]
    assert np.array_equal(plot.arrays[ArrayType.element_solid_ids], mesh["solids/ids"][()])
    node_ids = plot.arrays[ArrayType.node_ids]
    connectivity = node_ids[plot.arrays[ArrayType.element_solid_node_indexes]]
    assert np.array_equal(connectivity, mesh["solids/connectivity"][()])
    part_ids = plot.arrays[ArrayType.part_ids][plot.arrays[ArrayType.element_solid_part_indexes]]
    assert np.array_equal(part_ids, mesh["solids/part_ids"][()])
    assert_close(plot.arrays[ArrayType.element_solid_stress][:, :, 0, :], states(results, "solid_stress"),
                 "solid stresses")
    assert_close(plot.arrays[ArrayType.element_solid_effective_plastic_strain][:, :, 0],
                 states(results, "solid_plastic_strain"), "solid plastic strains")


def check_energies(plot, results, times):
    """Kinetic and internal energy of the states against glstat at the same times."""
    glstat = results["history/glstat"]
    rows = [int(np.argmin(np.abs(glstat["time"][()] - t))) for t in times]
    assert np.allclose(glstat["time"][()][rows], times, rtol=0, atol=1e-9)
    assert_close(plot.arrays[ArrayType.global_kinetic_energy], glstat["kinetic_energy"][()][rows], "kinetic energy")
    assert_close(plot.arrays[ArrayType.global_internal_energy], glstat["internal_energy"][()][rows],
                 "internal energy")
    assert_close(plot.arrays[ArrayType.part_internal_energy][:, 0], glstat["internal_energy"][()][rows],
                 "internal energy of the one part")


def test_solid_bar_d3plot_equals_results(tmp_path, run_deck):
    """A pulled bar of 6 plastic solids: mesh, ids, part title, every state; energies as glstat."""
    deck = pulled_deck(tmp_path / "bar.k", "solid", 6, 6.0, 0.2, 0.02)
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    plot = D3plot(str(run.results.parent / "d3plot"))
    assert plot.header.title == "pulled"
    assert plot.arrays[ArrayType.part_titles][0].decode().strip() == "solid of part seven"
    assert plot.header.n_solids == 6 and plot.header.n_shells == 0
    with run.open() as results:
        times = check_common(plot, results)
        check_solids(plot, results)
        assert states(results, "solid_plastic_strain").max() > 1e-3     # it yielded
        check_energies(plot, results, times)
    # LS-DYNA's deletion flag: the element's part number (1-based) while it is in the model
    assert np.all(plot.arrays[ArrayType.element_solid_is_alive] == 1.0)


def test_plastic_shell_strip_nip5_d3plot_equals_results(tmp_path, run_deck):
    """A pulled strip of 8 plastic Belytschko-Tsay shells with 5 points through the thickness:
    shell connectivity, ids, part, stresses and plastic strains at every state."""
    deck = pulled_deck(tmp_path / "strip.k", "shell", 8, 8.0, 0.2, 0.02, points=5)
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    plot = D3plot(str(run.results.parent / "d3plot"))
    assert plot.header.n_shells == 8 and plot.header.n_solids == 0
    with run.open() as results:
        check_common(plot, results)
        mesh = results["mesh"]
        assert np.array_equal(plot.arrays[ArrayType.element_shell_ids], mesh["shells/ids"][()])
        node_ids = plot.arrays[ArrayType.node_ids]
        connectivity = node_ids[plot.arrays[ArrayType.element_shell_node_indexes]]
        assert np.array_equal(connectivity, mesh["shells/connectivity"][()])
        part_ids = plot.arrays[ArrayType.part_ids][plot.arrays[ArrayType.element_shell_part_indexes]]
        assert np.array_equal(part_ids, mesh["shells/part_ids"][()])
        stress = plot.arrays[ArrayType.element_shell_stress]            # (states, shells, layers, 6)
        strain = plot.arrays[ArrayType.element_shell_effective_plastic_strain]
        assert plot.header.n_shell_tshell_layers == 5 and stress.shape[2] == 5
        expected_strain = states(results, "shell_plastic_strain")
        assert expected_strain.max() > 1e-3                              # it yielded
        # results.h5's mid-surface values are the Gauss-weighted means over the 5 points, its
        # peak values those of the point of largest von Mises stress / plastic strain
        weights = np.polynomial.legendre.leggauss(5)[1] / 2.0
        assert_close(np.einsum("l,selk->sek", weights, stress), states(results, "shell_stress"), "shell stresses")
        assert_close(strain @ weights, expected_strain, "shell plastic strains")
        assert_close(strain.max(axis=2), states(results, "shell_plastic_strain_peak"), "peak plastic strains")
        s = stress
        mises = s[..., 0] ** 2 - s[..., 0] * s[..., 1] + s[..., 1] ** 2 + 3 * (s[..., 3] ** 2 + s[..., 4] ** 2 +
                                                                               s[..., 5] ** 2)
        peak = np.take_along_axis(stress, mises.argmax(axis=2)[..., None, None], axis=2)[:, :, 0, :]
        assert_close(peak, states(results, "shell_stress_peak"), "peak stresses")


def test_meshfree_cube_d3plot_has_the_physical_values(tmp_path, run_deck):
    """The squeezed meshfree (EFG) cube: its background cells as solids, the particles'
    physical (transformed) displacements and velocities, as in results.h5."""
    run = run_deck(REPOSITORY / "inputs" / "squeeze_cube" / "efg.k")
    assert run.status == 0, run.stderr
    plot = D3plot(str(run.results.parent / "d3plot"))
    with run.open() as results:
        assert list(results["mesh/parts/formulation"].asstr()[()]) == ["efg"]
        check_common(plot, results)
        check_solids(plot, results)


def test_eroded_shells_carry_the_deleted_flag(tmp_path, run_deck):
    """FAIL = 0.03: the 4 shells of the strip erode; the d3plot flags them deleted (0.0) from
    the state where results.h5 says they are eroded, and with their part number (1) before."""
    deck = pulled_deck(tmp_path / "erode.k", "shell", 4, 4.0, 0.8, 0.05, points=3, failure=0.03)
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    plot = D3plot(str(run.results.parent / "d3plot"))
    with run.open() as results:
        eroded = states(results, "shell_eroded")
    alive = plot.arrays[ArrayType.element_shell_is_alive]
    assert eroded[0].sum() == 0 and eroded[-1].sum() == 4
    assert np.array_equal(alive, 1.0 - eroded)


def test_family_files_past_the_size_limit_read_as_one(tmp_path):
    """A block of 1000 solids, 41 states, x=1 (files of 512^2 words, about 13 states each):
    the states go on in NAME.d3plot01, 02, ...; lasso-python reads them as one database whose
    states equal results.h5's."""
    nodes, elements = block_mesh((10, 10, 10), (10.0, 10.0, 10.0))
    nodes = round_to_node_card(nodes)
    deck = write_deck(
        tmp_path / "block.k",
        "*CONTROL_TERMINATION\n" + fields(0.4),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.01),
        "*PART\nblock\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, E, NU),
        "*INITIAL_VELOCITY_GENERATION\n" + fields(1, 2, 0.0, 1.0, 0.0, 0.0) + "\n" + fields(0.0, 0.0, 0.0, 0.0, 0.0,
                                                                                           1.0),
        nodes_card(nodes),
        solids_card(elements),
    )
    output = tmp_path / "out"
    run_solver(deck, output, "jobid=crash", "x=1")
    words = 512 ** 2
    family = sorted(output.glob("crash.d3plot*"))
    print(f"  files: {[(f.name, f.stat().st_size) for f in family]}")
    assert len(family) >= 3
    assert all(f.stat().st_size <= 4 * words for f in family)
    plot = D3plot(str(output / "crash.d3plot"))
    with h5py.File(output / "crash.h5", "r") as results:
        assert len(results["states"]) == 41
        check_common(plot, results)
        check_solids(plot, results)


def test_bent_shell_layers_hold_the_plastic_hinge(tmp_path, run_deck):
    """The plastic collapse of a cantilever strip (test_shell_physics, NIP 5, elastic-perfectly
    plastic): at the last state the root element is a hinge, so its bottom and top points are on
    the yield surface (von Mises = SIGY to 0.1 %) with axial stresses of opposite sign, the
    middle point carries less; its bending moment is the Gauss rule's plastic moment; the
    energy densities add up to glstat's internal energy; the Gauss-weighted mean over the layers
    is results.h5's mid-surface stress and the largest von Mises stress of the layers its
    peak's."""
    from test_shell_physics import YIELD, cantilever_deck
    deck, _ = cantilever_deck(tmp_path / "cantilever.k", 5)
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    plot = D3plot(str(run.results.parent / "d3plot"))
    stress = plot.arrays[ArrayType.element_shell_stress].astype(float)   # (states, shells, layers, 6)
    mises = von_mises(stress)
    root = int(np.argmin(plot.arrays[ArrayType.node_coordinates][
        plot.arrays[ArrayType.element_shell_node_indexes]][:, :, 0].mean(axis=1)))
    last = mises[-1, root]
    print(f"  root element, last state: von Mises / SIGY by layer {np.round(last / YIELD, 4)}, "
          f"sigma_xx {np.round(stress[-1, root, :, 0], 4)}")
    assert np.allclose(last[[0, 4]], YIELD, rtol=1e-3)
    assert stress[-1, root, 0, 0] * stress[-1, root, 4, 0] < 0
    assert last[2] < 0.9 * YIELD
    # the resultants per unit width (local frame): the hinge's moment is the Gauss rule's plastic
    # moment k SIGY t^2 / 4 (measured 1.01-1.02 of it: some plate action, see test_shell_physics)
    points, weights = np.polynomial.legendre.leggauss(5)
    weights = weights / 2.0
    thickness = plot.arrays[ArrayType.element_shell_thickness]
    assert np.all(thickness == 2.0)
    moment = plot.arrays[ArrayType.element_shell_bending_moment][-1, root, 0]
    plastic = np.sum(weights * np.abs(points)) * YIELD * 2.0 ** 2 / 2.0      # per unit width
    from_layers = 2.0 ** 2 * np.sum(weights * points / 2.0 * stress[-1, root, :, 0])
    normal = plot.arrays[ArrayType.element_shell_normal_force][-1, root, 0]
    print(f"  root M_xx {moment:.5f}, from the layers {from_layers:.5f}, Gauss plastic moment {plastic:.5f}; "
          f"N_xx {normal:.2e}")
    assert abs(abs(moment) / plastic - 1.0) < 0.03
    assert abs(abs(moment) - abs(from_layers)) < 2e-3 * plastic
    assert abs(normal) < 0.02 * YIELD * 2.0
    # the internal energy densities times the elements' volumes add up to glstat's internal energy
    corners = plot.arrays[ArrayType.node_displacement][:, plot.arrays[ArrayType.element_shell_node_indexes]]
    area = 0.5 * np.linalg.norm(np.cross(corners[:, :, 2] - corners[:, :, 0], corners[:, :, 3] - corners[:, :, 1]),
                                axis=-1)
    energy = np.sum(plot.arrays[ArrayType.element_shell_internal_energy] * area * thickness, axis=1)
    with run.open() as results:
        internal = results["history/glstat/internal_energy"][()]
        rows = [int(np.argmin(np.abs(results["history/glstat/time"][()] - t)))
                for t in plot.arrays[ArrayType.global_timesteps]]
        print(f"  internal energy from the densities / glstat at the end {energy[-1] / internal[rows][-1]:.6f}")
        assert np.allclose(energy, internal[rows], rtol=2e-3, atol=1e-6 * internal.max())
        assert_close(np.einsum("l,selk->sek", weights, stress), states(results, "shell_stress"), "shell stresses",
                     scale=np.abs(stress).max())
        # top and bottom points tie in a hinge: compare the peak's von Mises stress
        assert_close(mises.max(axis=2), von_mises(states(results, "shell_stress_peak")), "peak von Mises stresses")
        strain = plot.arrays[ArrayType.element_shell_effective_plastic_strain]
        assert_close(strain @ weights, states(results, "shell_plastic_strain"), "shell plastic strains")
        assert_close(strain.max(axis=2), states(results, "shell_plastic_strain_peak"), "peak plastic strains")


def test_coupled_meshfree_shell_strip_d3plot_has_the_physical_values(tmp_path, run_deck):
    """A strip of FE shells (x < 30 mm) coupled to meshfree EFG shells (ELFORM 41) beyond, its
    end x = 0 pushed transversely by a short pulse: the flexural wave crosses the interface.
    The EFG cells are written as shells with the particles' physical (transformed)
    displacements and velocities of results.h5, both parts with their titles; their layers and
    bending moments as the FE shells'."""
    import plate_decks
    deck = tmp_path / "coupled.k"
    end_time = 0.04
    plate_decks.interface_strip_deck(deck, True, (40, 2), 100.0, 5.0, 1.0, 0.0, 100.0, 0.01, end_time,
                                     probes=(10.0, 50.0), direction=3, interface=30.0)
    text = deck.read_text().replace("*END", "*DATABASE_BINARY_D3PLOT\n" + fields(end_time / 8) + "\n*END")
    deck.write_text(text)
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    plot = D3plot(str(run.results.parent / "d3plot"))
    titles = [title.decode().strip() for title in plot.arrays[ArrayType.part_titles]]
    assert titles == ["fe half", "second half"]
    with run.open() as results:
        assert list(results["mesh/parts/formulation"].asstr()[()]) == ["fe", "efg"]
        check_common(plot, results)
        efg = results["mesh/shells/part_ids"][()] == 2
        efg_nodes = np.unique(plot.arrays[ArrayType.element_shell_node_indexes][efg])
        moved = np.abs(states(results, "displacement")[:, efg_nodes, 2]).max()
        print(f"  largest transverse displacement of the meshfree particles {moved:.3e} mm")
        assert moved > 1e-4
        stress = plot.arrays[ArrayType.element_shell_stress]             # (states, shells, 3 layers, 6)
        mid = states(results, "shell_stress")
        # both kinds, NIP 3 (LS-DYNA's MAXINT 3): the layers are the mid, inner (bottom) and outer
        # (top) points, so the Gauss mean weighs them 8/9, 5/9, 5/9 (over 2); a meshfree cell's
        # layer is the area-weighted mean of its sub-cell points at that height
        weights = np.array([8.0, 5.0, 5.0]) / 18.0
        for kind, cells in (("FE", ~efg), ("meshfree", efg)):
            assert_close(np.einsum("l,selk->sek", weights, stress[:, cells]), mid[:, cells], f"{kind} shell stresses",
                         scale=np.abs(stress).max())
            bending = np.abs(stress[:, cells, 1, 0] - stress[:, cells, 2, 0]).max()
            print(f"  largest difference of the {kind} shells' inner and outer axial stress {bending:.3e}")
            assert bending > 0.1 * np.abs(stress).max()           # the layers are the bent shell's
        # resultants per unit width from the layers (t = 1, points at z = 0, -/+ sqrt(3/5) t / 2):
        # M_xx = t^2 sum w h s_xx in the shell's frame; along the strip (x) frame and global agree
        height = np.array([0.0, -np.sqrt(0.6) / 2.0, np.sqrt(0.6) / 2.0])
        moment = plot.arrays[ArrayType.element_shell_bending_moment][:, efg, 0]
        from_layers = np.einsum("l,sel->se", weights * height, stress[..., 0][:, efg])
        print(f"  meshfree M_xx: largest {np.abs(moment).max():.3e}, from the layers {np.abs(from_layers).max():.3e}")
        assert np.abs(moment).max() > 0.0
        assert np.allclose(np.abs(moment), np.abs(from_layers), rtol=0, atol=2e-3 * np.abs(moment).max())
        thickness = plot.arrays[ArrayType.element_shell_thickness]
        assert np.all(thickness == 1.0)
    # no erosion: every shell's deletion flag is its part number, 1 (FE) or 2 (meshfree)
    part_numbers = plot.arrays[ArrayType.element_shell_part_indexes] + 1
    assert set(part_numbers) == {1, 2}
    assert np.all(plot.arrays[ArrayType.element_shell_is_alive] == part_numbers)


def test_beam_cantilever_d3plot_has_the_beams_and_their_resultants(tmp_path, run_deck):
    """The beam cantilever of test_beams (10 Hughes-Liu beams, tip load along z): beam ids,
    nodes N1 N2 and the orientation node, part, and at every state the resultants of results.h5
    in LS-DYNA's order (axial, shear s, shear t, moment s, moment t, torsion). The root
    element, whose moment is largest, carries a shear of the order of the tip load."""
    from test_beams import TIP_LOAD, cantilever_deck
    run = run_deck(cantilever_deck(tmp_path / "cantilever.k", end_time=8.0, rise_time=6.0))
    assert run.status == 0, run.stderr
    plot = D3plot(str(run.results.parent / "d3plot"))
    assert plot.header.n_beams == 10
    with run.open() as results:
        check_common(plot, results)
        mesh = results["mesh/beams"]
        assert np.array_equal(plot.arrays[ArrayType.element_beam_ids], mesh["ids"][()])
        node_ids = plot.arrays[ArrayType.node_ids]
        nodes = plot.arrays[ArrayType.element_beam_node_indexes]
        assert np.array_equal(node_ids[nodes[:, :2]], mesh["connectivity"][()])
        assert np.array_equal(node_ids[nodes[:, 2]], mesh["orientation_node"][()])
        part_ids = plot.arrays[ArrayType.part_ids][plot.arrays[ArrayType.element_beam_part_indexes]]
        assert np.array_equal(part_ids, mesh["part_ids"][()])
        resultant = states(results, "beam_resultant")        # N, Q_s, Q_t, T, M_s, M_t
    assert_close(plot.arrays[ArrayType.element_beam_axial_force], resultant[..., 0], "axial forces",
                 scale=np.abs(resultant).max())
    assert_close(plot.arrays[ArrayType.element_beam_shear_force], resultant[..., 1:3], "shear forces")
    assert_close(plot.arrays[ArrayType.element_beam_bending_moment], resultant[..., 4:6], "bending moments")
    assert_close(plot.arrays[ArrayType.element_beam_torsion_moment], resultant[..., 3], "torsion",
                 scale=np.abs(resultant).max())
    shear = np.abs(plot.arrays[ArrayType.element_beam_shear_force][-1, 0]).max()
    print(f"  root shear at the end {shear:.4f} for a tip load {TIP_LOAD}")
    assert 0.5 * TIP_LOAD < shear < 1.5 * TIP_LOAD
    assert np.all(plot.arrays[ArrayType.element_beam_is_alive] == 1.0)


def garble_states_after(directory, plot, time):
    """Overwrite with 7.0 every word of the d3plot states of `directory` later than `time`
    (`plot`: the same database read, for its sizes and times); the count of states garbled."""
    state_bytes = plot._compute_n_bytes_per_state()
    times = plot.arrays[ArrayType.global_timesteps]
    files = sorted(directory.glob("d3plot*"), key=lambda path: (len(path.name), path.name))
    index, garbled = 0, 0
    for number, path in enumerate(files):
        start = plot.geometry_section_size if number == 0 else 0
        count = max(0, (path.stat().st_size - 4 - start) // state_bytes)
        with open(path, "r+b") as stream:
            for k in range(count):
                if times[index + k] > time:
                    stream.seek(start + k * state_bytes)
                    stream.write(np.full(state_bytes // 4, 7.0, np.float32).tobytes())
                    garbled += 1
        index += count
    assert index == len(times)
    return garbled


@pytest.mark.parametrize("scale", [None, 1])
def test_restart_continues_the_d3plot(tmp_path, scale):
    """A run continued from a restart dump (test_restart's plastic block thrown at a wall) keeps
    the d3plot states before the dump, overwrites the ones after it (garbled here, as an
    interrupted run may have left them) and writes on: its d3plot equals the uninterrupted
    run's. With x=1 and a finer state interval the states fill
    family files, and the continued run cuts and goes on in the family file of the dump."""
    from test_restart import copy_run, restart, run_fresh, solids_deck
    deck = solids_deck(tmp_path / "block.k", cells=8 if scale else 5)
    if scale:
        deck.write_text(deck.read_text().replace("*DATABASE_BINARY_D3PLOT\n", "*DATABASE_BINARY_D3PLOT\n" +
                                                 fields(0.001) + "\n$ (the finer interval)\n$", 1))
    extra = [f"x={scale}"] if scale else []
    reference_dir = tmp_path / "one"
    process = run_fresh(deck, reference_dir) if not extra else run_solver(deck, reference_dir, *extra)
    reference = D3plot(str(reference_dir / "d3plot"))
    family = sorted(p.name for p in reference_dir.glob("d3plot*"))
    print(f"  {len(reference.arrays[ArrayType.global_timesteps])} states in {family}")
    if scale:
        assert len(family) >= 3
    dumps = sorted(p.name for p in reference_dir.glob("d3dump*"))
    for dump in (dumps[len(dumps) // 2], dumps[-2]):
        target = copy_run(reference_dir, tmp_path / f"restart_{dump}")
        with h5py.File(target / dump, "r") as store:
            dump_time = store["clock/time"][()]
        # what the interrupted run wrote after its dump: the continued run must replace it
        garbled = garble_states_after(target, reference, dump_time)
        assert garbled > 0
        process = restart(target / dump, 1, *extra)
        assert process.returncode == 0, process.stdout + process.stderr
        assert sorted(p.name for p in target.glob("d3plot*")) == family
        continued = D3plot(str(target / "d3plot"))
        for array in (ArrayType.global_timesteps, ArrayType.node_displacement, ArrayType.node_velocity,
                      ArrayType.element_solid_stress, ArrayType.element_solid_effective_plastic_strain):
            assert np.array_equal(continued.arrays[array], reference.arrays[array]), f"{dump}: {array}"


@pytest.mark.parametrize("value", ["0", "-3", "big", "1.5"])
def test_a_bad_file_size_scale_is_refused(tmp_path, value):
    """x= must be a positive whole number: anything else is refused before the run (exit 2)."""
    deck = pulled_deck(tmp_path / "bar.k", "solid", 2, 2.0, 0.01, 0.005)
    process = subprocess.run([str(BINARY), f"i={deck}", f"outdir={tmp_path / 'out'}", f"x={value}"],
                             capture_output=True, text=True, timeout=60)
    assert process.returncode == 2, process.stderr
    assert f"command line: x='{value}' is not a positive whole number" in process.stderr
    assert not (tmp_path / "out" / "d3plot").exists()


def test_paraview_lsdyna_reader_reads_the_states(tmp_path, run_deck):
    """VTK's LS-DYNA reader (ParaView's) finds every state of the d3plot, which start in
    d3plot01, and reads the last one's deflected coordinates and solid stresses as results.h5
    has them (the reader orders a part's points its own way: they are matched by their
    coordinates at the first state; one part, the elements keep the file's order)."""
    vtk = pytest.importorskip("vtk")
    from vtk.util.numpy_support import vtk_to_numpy
    run = run_deck(REPOSITORY / "inputs" / "squeeze_cube" / "fe.k")
    assert run.status == 0, run.stderr
    reader = vtk.vtkLSDynaReader()
    reader.SetFileName(str(run.results.parent / "d3plot"))
    reader.UpdateInformation()
    with run.open() as results:
        names = sorted(results["states"])
        assert reader.GetNumberOfTimeSteps() == len(names)
        last = results["states"][names[-1]]
        reference = results["mesh/nodes/coordinates"][()]
        reader.UpdateTimeStep(reader.GetTimeValue(0))
        first = vtk_to_numpy(reader.GetOutput().GetBlock(0).GetPoints().GetData()).astype(float)
        rows = np.lexsort(np.round(first, 4).T)
        expected_rows = np.lexsort(np.round(reference, 4).T)
        order = np.empty(len(first), int)
        order[rows] = expected_rows                      # reader's point k is node order[k]
        assert_close(first, reference[order], "ParaView: coordinates at the first state")
        reader.UpdateTimeStep(reader.GetTimeValue(len(names) - 1))
        block = reader.GetOutput().GetBlock(0)
        coordinates = vtk_to_numpy(block.GetPointData().GetArray("Deflected Coordinates"))
        assert_close(coordinates, (reference + last["displacement"][()])[order], "ParaView: deflected coordinates")
        assert_close(vtk_to_numpy(block.GetCellData().GetArray("Stress")), last["solid_stress"][()],
                     "ParaView: solid stresses")
        assert abs(reader.GetTimeValue(len(names) - 1) - last.attrs["time"]) < 1e-6 * last.attrs["time"]


STRETCH_RATE = 0.4          # 1/(mm ms): node velocity along x = STRETCH_RATE * x^2


def stretched_deck(path):
    """A 3 x 2 x 2 block of solids and, beside it, a 3 x 2 plate of shells, every node moved
    along x at the prescribed velocity STRETCH_RATE x^2 and held in y and z (shells also in
    rotation): element k between x = a and b has the centre derivative dx/dX = 1 + R t (a + b),
    so its strain tensor is the analytical xx = ln(1 + R t (a + b)), yy = 0 and no shear; a
    shell's zz is ln(t / t0) of its thickness."""
    solid_nodes, solids = block_mesh((3, 2, 2), (3.0, 2.0, 2.0), origin=(1.0, 0.0, 0.0))
    plate_nodes, shells = plate_mesh((3, 2), (3.0, 2.0))
    plate_nodes = plate_nodes + [1.0, 0.0, 10.0]
    nodes = np.vstack([solid_nodes, plate_nodes])
    count = len(solid_nodes)
    motions, spc = ["*BOUNDARY_PRESCRIBED_MOTION_NODE"], ["*BOUNDARY_SPC_NODE"]
    for k, (x, _, _) in enumerate(nodes):
        motions.append(fields(k + 1, 1, 0, 1, float(STRETCH_RATE * x * x)))
        spc.append(fields(k + 1, 0, 0, 1, 1, *([1, 1, 1] if k >= count else [0, 0, 0])))
    return write_deck(
        path,
        "*TITLE\nstretched",
        "*CONTROL_TERMINATION\n" + fields(0.2),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.05),
        "*DATABASE_EXTENT_BINARY\n" + fields(0, 0, 3, 1),
        "*PART\nblock\n" + fields(1, 1, 1),
        "*PART\nplate\n" + fields(2, 2, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*SECTION_SHELL\n" + fields(2, 2, 1.0, 3) + "\n" + fields(*[0.1] * 4),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, 1.0, 0.3),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + fields(0.0, 1.0, width=20) + "\n" + fields(10.0, 1.0, width=20),
        "\n".join(motions),
        "\n".join(spc),
        nodes_card(nodes),
        solids_card(solids),
        shells_card(shells, part_id=2, first_id=len(solids) + 1, first_node_id=count + 1),
    ), nodes[solids], nodes[count:][shells]


def test_element_strains_with_strflg(tmp_path, run_deck):
    """*DATABASE_EXTENT_BINARY STRFLG = 1: lasso-python reads element_solid_strain and
    element_shell_strain (inner and outer surface), equal to the analytical strain of every
    element at every state (to single precision)."""
    deck, solid_corners, shell_corners = stretched_deck(tmp_path / "stretched.k")
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    plot = D3plot(str(run.results.parent / "d3plot"))
    times = plot.arrays[ArrayType.global_timesteps]
    assert len(times) >= 4 and times[-1] >= 0.2
    solid_strain = plot.arrays[ArrayType.element_solid_strain][:, :, 0, :]     # (states, solids, 6)
    shell_strain = plot.arrays[ArrayType.element_shell_strain]                 # (states, shells, 2, 6)
    assert solid_strain.shape == (len(times), 12, 6) and shell_strain.shape == (len(times), 6, 2, 6)
    # the other fields keep their place: stresses, plastic strains, thickness
    assert plot.arrays[ArrayType.element_solid_stress].shape == (len(times), 12, 1, 6)
    thickness = plot.arrays[ArrayType.element_shell_thickness]
    for corners, strain in ((solid_corners, solid_strain), (shell_corners[:, None], shell_strain)):
        ends = corners[..., 0].min(axis=-1) + corners[..., 0].max(axis=-1)         # a + b per element
        expected_xx = np.log1p(STRETCH_RATE * times[:, None] * ends.reshape(1, -1))
        if strain.ndim == 4:
            expected_xx = np.repeat(expected_xx[:, :, None], 2, axis=2)
        assert_close(strain[..., 0], expected_xx, "strain xx", scale=expected_xx.max())
        assert expected_xx.max() > 0.1
        assert np.abs(strain[..., 1]).max() <= 2 * SINGLE * expected_xx.max()          # held in y
        assert np.abs(strain[..., 3:]).max() <= 2 * SINGLE * expected_xx.max()         # no shear
    # a solid held in y and z keeps zz = 0; a shell's zz is its thickness strain
    assert np.abs(solid_strain[..., 2]).max() <= 2 * SINGLE * solid_strain[..., 0].max()
    # (without *CONTROL_SHELL ISTUPD the shells keep their thickness, as LS-DYNA's do)
    expected_zz = np.log(thickness / 0.1)
    assert np.abs(shell_strain[:, :, :, 2] - expected_zz[:, :, None]).max() <= 2 * SINGLE * expected_xx.max()


@pytest.mark.parametrize("value, message", [
    (2, "field STRFLG: must be 0 or 1"),
    (-1, "field STRFLG: must be 0 or 1"),
    (11, "field STRFLG: ignored (its digits for the plastic and thermal strain tensors"),
])
def test_strain_flag_checked(tmp_path, run_deck, value, message):
    """STRFLG: a last digit other than 0 or 1 is refused with its file:line; LS-DYNA's digits
    for the plastic and thermal strain tensors get a warning and the strains are written."""
    deck, _, _ = stretched_deck(tmp_path / "stretched.k")
    deck.write_text(deck.read_text().replace("*DATABASE_EXTENT_BINARY\n" + fields(0, 0, 3, 1),
                                             "*DATABASE_EXTENT_BINARY\n" + fields(0, 0, 3, value)))
    line = deck.read_text().splitlines().index(fields(0, 0, 3, value)) + 1
    run = run_deck(deck)
    assert f"stretched.k:{line}: *DATABASE_EXTENT_BINARY: {message}" in run.stderr, run.stderr
    if value == 11:
        assert run.status == 0
        plot = D3plot(str(run.results.parent / "d3plot"))
        assert plot.arrays[ArrayType.element_solid_strain].shape[-1] == 6
    else:
        assert run.status == 2
