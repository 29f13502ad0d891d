"""The post-processing scripts (postproc/) on small synthetic results files written with h5py
in the contract's layout (docs/contract.md), whose answers are known exactly: energy ratio,
ns per element per cycle, history curves, Taylor bar length and radius; and that each script
writes its PNG and runs from the command line. One test reads a file written by the Fortran
writer (the unit-test program), when that program has been built."""
from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

REPOSITORY = Path(__file__).resolve().parents[2]
POSTPROC = REPOSITORY / "postproc"
sys.path.insert(0, str(POSTPROC))

import crashfree_results as cr  # noqa: E402
import plot_energy  # noqa: E402
import plot_history  # noqa: E402
import summary_table  # noqa: E402
import taylor_bar  # noqa: E402

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"

# glstat of the synthetic run: kinetic 100 (1 - t), internal 90 t, hourglass 5 t, external
# work 2 t, so total = 100 - 5 t and at t = 1 the energy ratio is 95 / (100 + 2).
EXPECTED_ENERGY_RATIO = 95.0 / 102.0
EXPECTED_HOURGLASS_RATIO = 5.0 / 90.0
# /timing: fe_solid_s = 6 s over 16 elements x 1000 cycles.
EXPECTED_NS_PER_ELEMENT_CYCLE = 6.0 / (16 * 1000) * 1e9


# ------------------------------------------------------------------------------------------------
# Synthetic results files


def bar_mesh(lateral=(-1.0, 0.0, 1.0), layers=5, axis=2):
    """Nodes on a grid lateral x lateral x layers (unit spacing along the axis) and the
    hexahedra between them, LS-DYNA node order; returns ids, coordinates (n, 3), connectivity
    (m, 8) of node ids."""
    count = len(lateral)
    points = []
    for k in range(layers):
        for j in range(count):
            for i in range(count):
                point = [lateral[i], lateral[j]]
                point.insert(axis, float(k))
                points.append(point)
    ids = np.arange(1, len(points) + 1) * 10
    index = lambda i, j, k: i + count * j + count * count * k  # noqa: E731
    connectivity = []
    for k in range(layers - 1):
        for j in range(count - 1):
            for i in range(count - 1):
                corners = [index(i, j, k), index(i + 1, j, k), index(i + 1, j + 1, k),
                           index(i, j + 1, k)]
                corners += [corner + count * count for corner in corners]
                connectivity.append(ids[corners])
    return ids, np.array(points), np.array(connectivity)


def mushroom(coordinates, axis=2, center=(0.0, 0.0), impact_end="low", shortening=0.75):
    """Displacement that shortens the bar to `shortening` of its length (towards the impact
    end) and widens each layer by 1 + 0.5 (1 - s), s = 0 at the impact end, 1 at the other."""
    lateral = [d for d in range(3) if d != axis]
    axial = coordinates[:, axis]
    low, high = axial.min(), axial.max()
    distance = (axial - low if impact_end == "low" else high - axial) / (high - low)
    deformed = coordinates.copy()
    deformed[:, axis] = (low + shortening * (axial - low) if impact_end == "low"
                         else high - shortening * (high - axial))
    scale = 1.0 + 0.5 * (1.0 - distance)
    for column, middle in zip(lateral, center):
        deformed[:, column] = middle + scale * (coordinates[:, column] - middle)
    return deformed - coordinates


def write_results(path, coordinates=None, ids=None, connectivity=None, final_displacement=None,
                  force_amplitude=10.0, finished=True):
    """A results file in the contract's layout: two states, glstat, matsum/1, rwforc/1,
    nodout/50, /run and (if `finished`) /timing."""
    if coordinates is None:
        ids, coordinates, connectivity = bar_mesh()
    if final_displacement is None:
        final_displacement = mushroom(coordinates)
    nodes, solids = len(ids), len(connectivity)
    time = np.linspace(0.0, 1.0, 11)
    with h5py.File(path, "w") as results:
        run = results.create_group("run")
        run.attrs["version"] = "0.1.0"
        run.attrs["deck"] = "synthetic.k"
        run.attrs["title"] = "synthetic bar"
        run.attrs["status"] = "normal termination" if finished else "running"
        run.attrs["message"] = ""
        run.attrs["end_time"] = 1.0 if finished else 0.0
        run.attrs["cycles"] = np.int64(1000 if finished else 0)
        run.attrs["threads"] = np.int64(2)
        mesh = results.create_group("mesh")
        mesh["nodes/ids"] = ids.astype(np.int32)
        mesh["nodes/coordinates"] = coordinates
        mesh["solids/ids"] = np.arange(1, solids + 1, dtype=np.int32)
        mesh["solids/part_ids"] = np.ones(solids, dtype=np.int32)
        mesh["solids/connectivity"] = connectivity.astype(np.int32)
        mesh["shells/ids"] = np.zeros(0, dtype=np.int32)
        mesh["shells/part_ids"] = np.zeros(0, dtype=np.int32)
        mesh["shells/connectivity"] = np.zeros((0, 4), dtype=np.int32)
        mesh["parts/ids"] = np.array([1], dtype=np.int32)
        mesh.create_dataset("parts/formulation", data=["fe"], dtype=h5py.string_dtype())
        mesh["parts/material_ids"] = np.array([1], dtype=np.int32)
        for number, (state_time, displacement) in enumerate(
                [(0.0, np.zeros_like(coordinates)), (1.0, final_displacement)]):
            state = results.create_group(f"states/{number:06d}")
            state.attrs["time"] = state_time
            state["displacement"] = displacement
            state["velocity"] = np.zeros((nodes, 3))
            state["solid_stress"] = np.zeros((solids, 6))
            state["solid_plastic_strain"] = np.zeros(solids)
            state["shell_stress"] = np.zeros((0, 6))
            state["shell_plastic_strain"] = np.zeros(0)
        glstat = results.create_group("history/glstat")
        glstat["time"] = time
        glstat["time_step"] = np.full_like(time, 1e-3)
        glstat["kinetic_energy"] = 100.0 * (1.0 - time)
        glstat["internal_energy"] = 90.0 * time
        glstat["hourglass_energy"] = 5.0 * time
        glstat["contact_energy"] = np.zeros_like(time)
        glstat["external_work"] = 2.0 * time
        glstat["total_energy"] = 100.0 - 5.0 * time
        matsum = results.create_group("history/matsum/1")
        matsum["time"] = time
        matsum["kinetic_energy"] = 100.0 * (1.0 - time)
        matsum["internal_energy"] = 90.0 * time
        wall = results.create_group("history/rwforc/1")
        wall["time"] = time
        wall["force"] = np.stack([3.0 * time, -4.0 * time, force_amplitude * np.sin(np.pi * time)],
                                 axis=1)
        node = results.create_group("history/nodout/50")
        node["time"] = time
        node["displacement"] = np.stack([time, 2.0 * time, -2.0 * time], axis=1)
        node["velocity"] = np.ones((len(time), 3))
        node["acceleration"] = np.zeros((len(time), 3))
        if finished:
            timing = results.create_group("timing")
            for name, value in (("wall_s", 10.0), ("fe_solid_s", 6.0), ("fe_shell_s", 0.0),
                                ("efg_s", 0.0), ("contact_s", 0.5), ("output_s", 0.5),
                                ("setup_s", 1.0)):
                timing.attrs[name] = value
            for name, value in (("cycles", 1000), ("threads", 2), ("fe_elements", solids),
                                ("efg_particles", 0), ("dofs_total", 3 * nodes), ("dofs_efg", 0)):
                timing.attrs[name] = np.int64(value)
    return Path(path)


@pytest.fixture
def results_file(tmp_path):
    return write_results(tmp_path / "results.h5")


def run_script(name, *arguments, cwd=None):
    """Run a postproc script as a user would; returns the completed process."""
    return subprocess.run([sys.executable, str(POSTPROC / name), *map(str, arguments)],
                          capture_output=True, text=True, cwd=cwd, timeout=120)


def is_png(path) -> bool:
    path = Path(path)
    return path.is_file() and path.read_bytes()[:8] == PNG_SIGNATURE


# ------------------------------------------------------------------------------------------------
# Reader module


def test_reader_gives_states_histories_and_run_information(results_file):
    with cr.open_results(results_file) as results:
        assert cr.list_states(results) == [("000000", 0.0), ("000001", 1.0)]
        last = cr.read_state(results, -1)
        assert last["name"] == "000001" and last["displacement"].shape == (45, 3)
        assert cr.read_state(results, "000000")["time"] == 0.0
        run = cr.read_run(results)
        assert run["status"] == "normal termination" and isinstance(run["status"], str)
        assert run["cycles"] == 1000 and isinstance(run["cycles"], int)
        assert cr.read_timing(results)["fe_solid_s"] == 6.0
        assert cr.list_history_groups(results) == ["glstat", "matsum/1", "nodout/50", "rwforc/1"]
        wall = cr.read_history(results, "rwforc/1")
        assert wall["force"].shape == (11, 3) and wall["time"].shape == (11,)
        mesh = cr.read_mesh(results)
        assert mesh["formulations"] == ["fe"] and mesh["connectivity"].shape == (16, 8)
        with pytest.raises(cr.ResultsError, match="available: glstat"):
            cr.read_history(results, "rcforc/1")
        with pytest.raises(cr.ResultsError, match="2 states"):
            cr.read_state(results, 5)


def test_energy_ratio_definition():
    glstat = {"total_energy": np.array([10.0, 9.0, 12.0]), "external_work": np.array([0, 1, 2.0])}
    assert cr.energy_ratio(glstat) == pytest.approx(1.0)
    assert cr.energy_ratio(glstat, 1) == pytest.approx(9.0 / 11.0)
    assert np.allclose(cr.energy_ratio_history(glstat), [1.0, 9.0 / 11.0, 1.0])
    assert math.isnan(cr.energy_ratio({"total_energy": np.zeros(2), "external_work": np.zeros(2)}))


def test_component_selection():
    values = np.array([[3.0, -4.0, 0.0], [0.0, 0.0, 2.0]])
    assert np.allclose(cr.select_component(values, "magnitude"), [5.0, 2.0])
    assert np.allclose(cr.select_component(values, "y"), [-4.0, 0.0])
    assert np.allclose(cr.select_component(np.array([1.0, 2.0]), "x"), [1.0, 2.0])


def test_run_labels_prefer_what_differs():
    assert cr.run_labels(["a/fe.h5", "a/efg.h5"]) == ["fe", "efg"]
    assert cr.run_labels(["fe/results.h5", "efg/results.h5"]) == ["fe", "efg"]


# ------------------------------------------------------------------------------------------------
# plot_energy.py


def test_plot_energy_prints_energy_ratio_and_writes_png(results_file, tmp_path):
    output = tmp_path / "energy.png"
    process = run_script("plot_energy.py", results_file, "-o", output)
    assert process.returncode == 0, process.stderr
    assert f"{EXPECTED_ENERGY_RATIO:.4f}" in process.stdout
    assert is_png(output)


def test_plot_energy_summary_values(results_file, tmp_path):
    summary = plot_energy.plot_energy(results_file, tmp_path / "e.png")
    assert summary["energy_ratio"] == pytest.approx(EXPECTED_ENERGY_RATIO, rel=1e-12)
    assert summary["hourglass_ratio"] == pytest.approx(EXPECTED_HOURGLASS_RATIO, rel=1e-12)
    assert summary["total_energy"] == pytest.approx(95.0)


def test_plot_energy_reports_a_missing_file(tmp_path):
    process = run_script("plot_energy.py", tmp_path / "missing.h5", "-o", tmp_path / "e.png")
    assert process.returncode == 1
    assert "no such file" in process.stderr and "Traceback" not in process.stderr


# ------------------------------------------------------------------------------------------------
# plot_history.py


def test_plot_history_compares_runs(tmp_path):
    first = write_results(tmp_path / "fe.h5", force_amplitude=10.0)
    second = write_results(tmp_path / "efg.h5", force_amplitude=20.0)
    output, table = tmp_path / "force.png", tmp_path / "force.csv"
    process = run_script("plot_history.py", first, second, "--group", "rwforc/1", "--column",
                         "force", "--component", "z", "-o", output, "--csv", table)
    assert process.returncode == 0, process.stderr
    assert is_png(output)
    rows = np.genfromtxt(table, delimiter=",", skip_header=1)
    time = np.linspace(0.0, 1.0, 11)
    assert np.allclose(rows[:, 0], time)
    assert np.allclose(rows[:, 1], 10.0 * np.sin(np.pi * time))
    assert np.allclose(rows[:, 3], 20.0 * np.sin(np.pi * time))
    assert table.read_text().splitlines()[0] == "fe: time,fe: force (z),efg: time,efg: force (z)"


def test_plot_history_magnitude_and_nodout(results_file, tmp_path):
    curves = plot_history.plot_histories([results_file], "rwforc/1", "force", "magnitude",
                                         tmp_path / "f.png")
    label, time, values = curves[0]
    assert np.allclose(values[:3], np.hypot(5.0 * time[:3], 10.0 * np.sin(np.pi * time[:3])))
    curves = plot_history.plot_histories([results_file], "nodout/50", "displacement", "z",
                                         tmp_path / "d.png")
    assert np.allclose(curves[0][2], -2.0 * time)
    assert is_png(tmp_path / "d.png")


def test_plot_history_default_name_list_and_errors(results_file, tmp_path):
    process = run_script("plot_history.py", results_file, "--group", "glstat", "--column",
                         "kinetic_energy", cwd=tmp_path)
    assert process.returncode == 0, process.stderr
    assert is_png(tmp_path / "glstat_kinetic_energy.png")
    process = run_script("plot_history.py", results_file, "--list")
    assert "rwforc/1: 11 samples; force(3)" in process.stdout
    process = run_script("plot_history.py", results_file, "--group", "rwforc/1", "--column",
                         "moment", "-o", tmp_path / "x.png")
    assert process.returncode == 1 and "columns: force" in process.stderr


# ------------------------------------------------------------------------------------------------
# summary_table.py


def test_summary_table_numbers(results_file):
    summary = summary_table.run_summary(results_file)
    assert summary["status"] == "normal termination"
    assert summary["cycles"] == 1000
    assert summary["ns_per_element_cycle"] == pytest.approx(EXPECTED_NS_PER_ELEMENT_CYCLE)
    assert summary["ns_per_particle_cycle"] is None
    assert summary["other_s"] == pytest.approx(10.0 - 8.0)
    assert summary["energy_ratio"] == pytest.approx(EXPECTED_ENERGY_RATIO)
    assert summary["hourglass_ratio"] == pytest.approx(EXPECTED_HOURGLASS_RATIO)


def test_summary_table_markdown(tmp_path):
    finished = write_results(tmp_path / "finished.h5")
    killed = write_results(tmp_path / "killed.h5", finished=False)
    output = tmp_path / "summary.md"
    process = run_script("summary_table.py", finished, killed, "-o", output)
    assert process.returncode == 0, process.stderr
    text = output.read_text()
    assert text == process.stdout
    assert "## finished" in text and "## killed" in text
    assert f"| FE solid ns/element/cycle | {EXPECTED_NS_PER_ELEMENT_CYCLE:.1f} |" in text
    assert f"| energy ratio | {EXPECTED_ENERGY_RATIO:.4f} |" in text
    assert f"| hourglass / internal energy | {EXPECTED_HOURGLASS_RATIO:.4f} |" in text
    assert "| status | running |" in text
    process = run_script("summary_table.py", finished, killed, "--combined")
    assert "| quantity | finished | killed |" in process.stdout
    assert "| wall time (s) | 10.000 | n/a |" in process.stdout


# ------------------------------------------------------------------------------------------------
# taylor_bar.py


def test_taylor_bar_full_section(results_file, tmp_path):
    measures = taylor_bar.taylor_bar_measures(results_file)
    assert measures["wall"] == "low"
    assert measures["initial_length"] == pytest.approx(4.0)
    assert measures["final_length"] == pytest.approx(3.0)
    assert measures["length_ratio"] == pytest.approx(0.75)
    assert measures["initial_radius"] == pytest.approx(math.sqrt(2.0))
    assert measures["impact_radius"] == pytest.approx(1.5 * math.sqrt(2.0))
    assert np.allclose(measures["center"], [0.0, 0.0])


def test_taylor_bar_quarter_model_and_offset_bar(tmp_path):
    ids, coordinates, connectivity = bar_mesh(lateral=(0.0, 0.5, 1.0))
    quarter = write_results(tmp_path / "quarter.h5", coordinates, ids, connectivity,
                            mushroom(coordinates))
    measures = taylor_bar.taylor_bar_measures(quarter)
    assert np.allclose(measures["center"], [0.0, 0.0])
    assert measures["impact_radius"] == pytest.approx(1.5 * math.sqrt(2.0))

    ids, coordinates, connectivity = bar_mesh(lateral=(10.0, 11.0, 12.0), axis=0)
    displacement = mushroom(coordinates, axis=0, center=(11.0, 11.0), impact_end="high",
                            shortening=0.5)
    offset = write_results(tmp_path / "offset.h5", coordinates, ids, connectivity, displacement)
    measures = taylor_bar.taylor_bar_measures(offset, axis="x")
    assert measures["wall"] == "high"
    assert np.allclose(measures["center"], [11.0, 11.0])
    assert measures["final_length"] == pytest.approx(2.0)
    assert measures["impact_radius"] == pytest.approx(1.5 * math.sqrt(2.0))
    # the other end did not grow
    measures = taylor_bar.taylor_bar_measures(offset, axis="x", wall="low")
    assert measures["impact_radius"] == pytest.approx(math.sqrt(2.0))


def test_taylor_bar_command_line(results_file, tmp_path):
    table, profile = tmp_path / "taylor_bar.md", tmp_path / "profile.png"
    process = run_script("taylor_bar.py", results_file, "--markdown", table, "--plot", profile,
                         "--reference-length", 3.0)
    assert process.returncode == 0, process.stderr
    assert is_png(profile)
    text = table.read_text()
    assert "| final length L | 3 |" in text
    assert f"| impact-face radius R | {1.5 * math.sqrt(2.0):.6g} |" in text
    assert "| L / L0 | 0.7500 |" in text
    assert "(+0.00%)" in text
    assert "final length L" in process.stdout


# ------------------------------------------------------------------------------------------------
# Every script: --help, and importable without side effects


def test_plot_section_draws_the_faces_of_a_plane(results_file, tmp_path):
    sys.path.insert(0, str(POSTPROC))
    import plot_section
    # the synthetic bar: a 3 x 3 x 5 grid along z with unit spacing; the plane x = 0 holds
    # 2 x 4 faces (one column of cells on each side shares it)
    polygons, values, time, others = plot_section.section_polygons(results_file, 0, 0.0, -1)
    assert polygons.shape == (8, 4, 2) and others == [1, 2] and time == 1.0
    output = tmp_path / "section.png"
    completed = run_script("plot_section.py", results_file, "--axis", "x", "--value", "0", "-o", output)
    assert completed.returncode == 0, completed.stderr
    assert is_png(output)


@pytest.mark.parametrize("script", ["plot_energy.py", "plot_history.py", "summary_table.py",
                                    "taylor_bar.py", "crashfree_results.py"])
def test_scripts_run_and_explain_themselves(script, tmp_path):
    if script == "crashfree_results.py":
        process = subprocess.run([sys.executable, "-c", "import crashfree_results"],
                                 cwd=POSTPROC, capture_output=True, text=True)
        assert process.returncode == 0, process.stderr
        return
    process = run_script(script, "--help", cwd=tmp_path)
    assert process.returncode == 0 and "usage:" in process.stdout
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------------------------------------
# A file written by the Fortran writer


def fortran_writer_test_program():
    """The newest built unit-test program of results_file, if any."""
    programs = sorted(REPOSITORY.glob("build/*/tests/test_results_file"),
                      key=lambda path: path.stat().st_mtime)
    return programs[-1] if programs else None


def test_fortran_written_file_reads_as_the_contract_says(tmp_path):
    program = fortran_writer_test_program()
    if program is None:
        pytest.skip("build the unit tests first (make MODE=debug unit)")
    process = subprocess.run([str(program)], capture_output=True, text=True, timeout=120,
                             env=dict(os.environ, CRASHFREE_KEEP_TEST_OUTPUT=str(tmp_path)))
    assert process.returncode == 0, process.stdout + process.stderr
    with cr.open_results(tmp_path / "job.h5") as results:
        run = dict(results["run"].attrs)
        assert run["status"] == "normal termination" and isinstance(run["status"], str)
        assert isinstance(run["version"], str) and run["deck"] == "inputs/two_bricks.k"
        assert results["mesh/nodes/coordinates"].shape == (12, 3)
        assert results["mesh/solids/connectivity"].shape == (2, 8)
        assert results["mesh/shells/connectivity"].shape == (0, 4)
        assert results["mesh/parts/formulation"].asstr()[()].tolist() == ["efg"]
        assert [name for name, _ in cr.list_states(results)] == ["000000", "000001"]
        state = cr.read_state(results, -1)
        assert state["displacement"].shape == (12, 3) and state["solid_stress"].shape == (2, 6)
        # row = node, columns x y z: the Fortran test's field is offset + component + node / 8
        assert state["displacement"][1].tolist() == [2.25, 3.25, 4.25]
        assert cr.read_history(results, "nodout/101")["displacement"].shape == (5, 3)
        connectivity = results["mesh/solids/connectivity"][()]
        index = results["mesh/solids/connectivity_index"][()]
        assert (results["mesh/nodes/ids"][()][index] == connectivity).all()
        timing = cr.read_timing(results)
        assert timing["fe_elements"] == 2 and isinstance(timing["fe_elements"], int)
    xdmf = (tmp_path / "job.xdmf").read_text()
    assert "job.h5:/states/000001/solid_stress" in xdmf and str(tmp_path) not in xdmf
