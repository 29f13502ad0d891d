"""ParaView opens the run's results headless: `results.xdmf` through ParaView's XDMF reader and
the `d3plot` through ParaView's LS-DYNA reader (vtkLSDynaReader), both from the `vtk` package of
PyPI (postproc/requirements.txt; the same reader classes ParaView runs), and
postproc/render_state.py (what `make run` ends with) draws the final state as a PNG.

The model: a cantilever block of 5 x 2 x 2 hexahedra (part 1) and a cantilever plate of 5 x 2
shells (part 2), both held at x = 0 and moving at 10 mm/ms in -z, elastic-plastic steel, 0.2 ms
with a state every 0.05 ms (5 states). Each reader must give the node and element counts, the
element types and connectivity, the states' times and the displacements of results.h5 at every
state: to the last bit through the XDMF (it points into results.h5) and to single precision
through the d3plot (32-bit floats).

The readers run in a child process (this file run as a script, printing JSON): a reader that
crashes on a file fails its test with the crash's message instead of ending the test session.
See docs/output.md, "ParaView".
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

REPOSITORY = Path(__file__).resolve().parents[2]
VTK_HEXAHEDRON, VTK_QUAD = 12, 9
END_TIME, STATE_INTERVAL = 0.2, 0.05


# ---------------------------------------------------------------------------------------------
# The child process: open a file with a VTK reader and report what it shows, as JSON.

def leaves(data):
    """(name, dataset) of every leaf of a multiblock dataset."""
    from vtkmodules.vtkCommonDataModel import vtkCompositeDataSet
    iterator = data.NewIterator()
    iterator.InitTraversal()
    while not iterator.IsDoneWithTraversal():
        yield (iterator.GetCurrentMetaData().Get(vtkCompositeDataSet.NAME()) or "",
               iterator.GetCurrentDataObject())
        iterator.GoToNextItem()


def describe_block(name, grid):
    """Points, cells (type and point indices) and the point and cell arrays of one block."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    points = grid.GetPoints()
    arrays = {}
    for attributes, kind in ((grid.GetPointData(), "point"), (grid.GetCellData(), "cell")):
        for k in range(attributes.GetNumberOfArrays()):
            array = attributes.GetArray(k)
            if array is not None:
                arrays[f"{kind}:{array.GetName()}"] = vtk_to_numpy(array).tolist()
    return {
        "name": name,
        "points": vtk_to_numpy(points.GetData()).tolist() if points is not None else [],
        "cell_types": [grid.GetCellType(c) for c in range(grid.GetNumberOfCells())],
        "cells": [[grid.GetCell(c).GetPointId(k) for k in range(grid.GetCell(c).GetNumberOfPoints())]
                  for c in range(grid.GetNumberOfCells())],
        "arrays": arrays,
    }


def probe_xdmf(path):
    """ParaView's "XDMF Reader" (vtkXdmfReader): the time steps and every block at each."""
    from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline
    from vtkmodules.vtkIOXdmf2 import vtkXdmfReader
    reader = vtkXdmfReader()
    reader.SetFileName(path)
    reader.UpdateInformation()
    times = list(reader.GetOutputInformation(0).Get(vtkStreamingDemandDrivenPipeline.TIME_STEPS()) or [])
    states = []
    for time in times:
        reader.UpdateTimeStep(time)
        states.append([describe_block(name, grid) for name, grid in leaves(reader.GetOutputDataObject(0))])
    return {"times": times, "states": states}


def probe_d3plot(path):
    """ParaView's LS-DYNA reader (vtkLSDynaReader): counts, parts, time steps and every part's
    block (deformed points) at each."""
    from vtkmodules.vtkIOLSDyna import vtkLSDynaReader
    reader = vtkLSDynaReader()
    if not reader.CanReadFile(path):
        return {"readable": False}
    reader.SetFileName(path)
    reader.UpdateInformation()
    steps = reader.GetNumberOfTimeSteps()
    report = {
        "readable": True,
        "nodes": reader.GetNumberOfNodes(),
        "solids": reader.GetNumberOfSolidCells(),
        "shells": reader.GetNumberOfShellCells(),
        "parts": [reader.GetPartArrayName(k) for k in range(reader.GetNumberOfPartArrays())],
        "times": [reader.GetTimeValue(k) for k in range(steps)],
        "states": [],
    }
    for step in range(steps):
        reader.SetTimeStep(step)
        reader.Update()
        report["states"].append([describe_block(name, grid) for name, grid in leaves(reader.GetOutput())])
    return report


def probe(kind, path):
    """Run this file as a child process on `path` and return its JSON report; the test fails
    with the child's own words when it crashed."""
    process = subprocess.run([sys.executable, __file__, kind, str(path)], capture_output=True, text=True,
                             timeout=300)
    assert process.returncode == 0, (f"the {kind} reader failed on {path} (exit status {process.returncode}):\n"
                                     f"{process.stderr[-3000:]}")
    return json.loads(process.stdout.splitlines()[-1])


# ---------------------------------------------------------------------------------------------
# The tests (pytest).

def cantilevers_deck(path):
    """The block and the plate of the module docstring; returns the deck's path."""
    from deck_writer import block_mesh, fields, node_list_set, nodes_card, plate_mesh, shells_card, \
        solids_card, write_deck
    block_nodes, block = block_mesh((5, 2, 2), (20.0, 4.0, 4.0))
    plate_nodes, plate = plate_mesh((5, 2), (20.0, 8.0))
    plate_nodes = plate_nodes + [0.0, 10.0, 2.0]
    held = ([k + 1 for k in np.flatnonzero(np.isclose(block_nodes[:, 0], 0.0))] +
            [len(block_nodes) + k + 1 for k in np.flatnonzero(np.isclose(plate_nodes[:, 0], 0.0))])
    return write_deck(
        path,
        "*TITLE\nsolid and shell cantilevers",
        "*CONTROL_TERMINATION\n" + fields(END_TIME),
        "*DATABASE_BINARY_D3PLOT\n" + fields(STATE_INTERVAL),
        "*PART\nblock\n" + fields(1, 1, 1),
        "*PART\nplate\n" + fields(2, 2, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*SECTION_SHELL\n" + fields(2, 2, 1.0, 3) + "\n" + fields(1.0, 1.0, 1.0, 1.0),
        "*MAT_PLASTIC_KINEMATIC\n" + fields(1, 7.85e-6, 210.0, 0.3, 0.25, 1.0, 1.0) + "\n" + fields(0.0, 0.0),
        node_list_set(1, held),
        "*BOUNDARY_SPC_SET\n" + fields(1, 0, 1, 1, 1, 1, 1, 1),
        "*SET_PART_LIST\n" + fields(1) + "\n" + fields(1, 2),
        "*INITIAL_VELOCITY_GENERATION\n" + fields(1, 2, 0.0, 0.0, 0.0, -10.0) + "\n" + fields(*[0.0] * 6),
        nodes_card(np.vstack([block_nodes, plate_nodes])),
        solids_card(block, part_id=1),
        shells_card(plate, part_id=2, first_id=len(block) + 1, first_node_id=len(block_nodes) + 1),
    )


@pytest.fixture(scope="module")
def cantilevers(tmp_path_factory):
    """The deck run once for the module, into a fresh directory, as a user runs it (no jobid=:
    LS-DYNA's file names)."""
    from conftest import BINARY
    directory = tmp_path_factory.mktemp("paraview")
    deck = cantilevers_deck(directory / "cantilevers.k")
    process = subprocess.run([str(BINARY), f"i={deck}", f"outdir={directory}", "ncpu=1"], capture_output=True,
                             text=True, timeout=300, env=dict(os.environ, OMP_NUM_THREADS="1"))
    assert process.returncode == 0, process.stdout + process.stderr
    return directory


def reference(directory):
    """What results.h5 holds: node ids and coordinates, connectivity (node rows) and part of
    each element kind, and per state its time, displacement and solid plastic strain."""
    import h5py
    with h5py.File(directory / "results.h5", "r") as results:
        mesh = results["mesh"]
        names = sorted(results["states"])
        return {
            "node_ids": mesh["nodes/ids"][...],
            "coordinates": mesh["nodes/coordinates"][...],
            "solids": mesh["solids/connectivity_index"][...], "solid_parts": mesh["solids/part_ids"][...],
            "solid_ids": mesh["solids/ids"][...],
            "shells": mesh["shells/connectivity_index"][...], "shell_parts": mesh["shells/part_ids"][...],
            "times": np.array([results["states"][n].attrs["time"] for n in names]),
            "displacement": np.array([results["states"][n]["displacement"][...] for n in names]),
            "solid_plastic_strain": np.array([results["states"][n]["solid_plastic_strain"][...] for n in names]),
        }


def test_the_xdmf_reader_gives_the_mesh_times_and_displacements_of_results_h5(cantilevers):
    directory = cantilevers
    expected = reference(directory)
    shown = probe("xdmf", directory / "results.xdmf")
    node_count = len(expected["node_ids"])

    assert np.allclose(shown["times"], expected["times"], rtol=1e-14, atol=0.0)
    assert len(shown["times"]) == round(END_TIME / STATE_INTERVAL) + 1
    for state, blocks in enumerate(shown["states"]):
        by_name = {block["name"].split("[")[0]: block for block in blocks}
        assert sorted(by_name) == ["shells", "solids"]
        for name, kind in (("solids", VTK_HEXAHEDRON), ("shells", VTK_QUAD)):
            block = by_name[name]
            # every node of the model, in results.h5's order, at its reference position
            assert len(block["points"]) == node_count
            assert np.array_equal(np.array(block["points"]), expected["coordinates"])
            assert np.array_equal(block["arrays"]["point:node_id"], expected["node_ids"])
            assert set(block["cell_types"]) == {kind}
            assert np.array_equal(np.array(block["cells"]), expected[name])
            assert np.array_equal(block["arrays"]["cell:part_id"], expected[name[:-1] + "_parts"])
            # the state's displacements, bit for bit (the XDMF points into results.h5)
            assert np.array_equal(np.array(block["arrays"]["point:displacement"]), expected["displacement"][state])
        assert np.array_equal(by_name["solids"]["arrays"]["cell:solid_plastic_strain"],
                              expected["solid_plastic_strain"][state])
    # the run moved and yielded: the comparison above is not one of zeros
    assert np.abs(expected["displacement"][-1][:, 2]).max() > 0.2
    assert expected["solid_plastic_strain"][-1].max() > 1e-3


def test_the_ls_dyna_reader_gives_the_mesh_times_and_displacements_of_results_h5(cantilevers):
    """The d3plot beside results.h5 (the d3plot writer, src/output/d3plot_file.f90), opened as
    ParaView opens it. Coordinates and displacements are 32-bit floats in a d3plot: they must
    equal results.h5 to single precision (8 ulp of the model's size)."""
    directory = cantilevers
    expected = reference(directory)
    d3plot = directory / "d3plot"
    assert d3plot.is_file(), f"the run wrote no d3plot: {sorted(p.name for p in directory.iterdir())}"
    shown = probe("d3plot", d3plot)
    assert shown["readable"], "vtkLSDynaReader does not recognise the file as an LS-DYNA database"

    assert shown["times"], (
        "ParaView's LS-DYNA reader finds no state in the d3plot. It reads the first file up to its "
        "end-of-file marker (-999999.0) after the geometry and part titles and then goes on in "
        "d3plot01, d3plot02, ...: states written after the titles in the first file are never seen. "
        "LS-DYNA's own first file holds the geometry and the titles only; its states start in d3plot01.")
    assert shown["nodes"] == len(expected["node_ids"])
    assert shown["solids"] == len(expected["solids"])
    assert shown["shells"] == len(expected["shells"])
    assert shown["parts"] == ["block", "plate"]          # the parts by their *PART headings
    assert np.allclose(shown["times"], expected["times"], rtol=1e-6, atol=1e-9)

    coordinates = expected["coordinates"]
    tolerance = 8 * np.finfo(np.float32).eps * np.abs(coordinates).max()
    checked_plastic_strain = 0
    for state, blocks in enumerate(shown["states"]):
        cells_of_kind = {VTK_HEXAHEDRON: [], VTK_QUAD: []}
        for block in blocks:
            points = np.array(block["points"]).reshape(-1, 3)
            if len(points) == 0:
                continue
            rows = rows_of_points(block, shown, coordinates, tolerance)
            # the deformed position of each point (the reader shows the deformed mesh) and the
            # displacement it derives from the d3plot's coordinates ("Deflection")
            displacement = expected["displacement"][state][rows]
            assert np.allclose(points, coordinates[rows] + displacement, rtol=0.0, atol=tolerance), \
                f"state {state}, block {block['name']}"
            assert np.allclose(np.array(block["arrays"]["point:Deflection"]).reshape(-1, 3), displacement,
                               rtol=0.0, atol=tolerance), f"state {state}, block {block['name']}"
            if "cell:EffPlastStrn" in block["arrays"] and set(block["cell_types"]) == {VTK_HEXAHEDRON}:
                element_row = {int(e): row for row, e in enumerate(expected["solid_ids"])}
                solid_rows = [element_row[int(e)] for e in np.ravel(block["arrays"]["cell:UserIds"])]
                assert np.allclose(block["arrays"]["cell:EffPlastStrn"],
                                   expected["solid_plastic_strain"][state][solid_rows], rtol=1e-6, atol=1e-9)
                checked_plastic_strain += 1
            for kind, cell in zip(block["cell_types"], block["cells"]):
                cells_of_kind.setdefault(kind, []).append(tuple(sorted(rows[cell])))
        # every element once, on the same nodes as in results.h5
        assert sorted(cells_of_kind[VTK_HEXAHEDRON]) == sorted(tuple(sorted(c)) for c in expected["solids"])
        assert sorted(cells_of_kind[VTK_QUAD]) == sorted(tuple(sorted(c)) for c in expected["shells"])
    # the solids' effective plastic strain at every state (the reader's "EffPlastStrn")
    assert checked_plastic_strain == len(expected["times"])


def rows_of_points(block, shown, coordinates, tolerance):
    """The results.h5 node row of each point of a d3plot part block, by its position in the
    first state (the reference coordinates). Not by the reader's point "UserID": on a 32-bit
    d3plot VTK 9.7's reader puts the next node's id into the upper half of each 64-bit value
    (node 1 followed by node 2 reads 2 * 2**32 + 1), while lasso-python reads the same section
    as 1, 2, ..."""
    first = np.array(next(b for b in shown["states"][0] if b["name"] == block["name"])["points"]).reshape(-1, 3)
    distance = np.linalg.norm(first[:, None, :] - coordinates[None, :, :], axis=2)
    rows = distance.argmin(axis=1)
    assert np.all(distance[np.arange(len(rows)), rows] <= tolerance), "a d3plot point is at no node of results.h5"
    return rows


def test_render_state_draws_the_final_state(cantilevers):
    """`make run`'s picture: render_state.py on the run's results.xdmf writes a PNG of the size
    asked for that shows the model in the colour scale (not an empty or a grey window), and
    reports the last state and the largest plastic strain of results.h5."""
    import matplotlib.image
    directory = cantilevers
    expected = reference(directory)
    picture = directory / "final.png"
    process = subprocess.run([sys.executable, str(REPOSITORY / "postproc" / "render_state.py"),
                              str(directory / "results.xdmf"), "-o", str(picture), "--size", "800x500"],
                             capture_output=True, text=True, timeout=300)
    assert process.returncode == 0, process.stderr
    assert f"t = {expected['times'][-1]:.6g}" in process.stdout
    assert f"plastic strain (largest {expected['solid_plastic_strain'][-1].max():.4g}," in process.stdout
    pixels = matplotlib.image.imread(picture)[:, :, :3]
    assert pixels.shape[:2] == (500, 800)
    # saturated colours (the colour bar and the coloured elements) against the white-to-blue-grey
    # background: more than the colour bar alone (about 2% of the window)
    saturation = pixels.max(axis=2) - pixels.min(axis=2)
    assert np.mean(saturation > 0.5) > 0.05
    # by displacement: the largest displacement magnitude of the last state (every node here
    # belongs to an element, so the drawn surfaces carry them all)
    process = subprocess.run([sys.executable, str(REPOSITORY / "postproc" / "render_state.py"),
                              str(directory / "results.xdmf"), "-o", str(picture), "--size", "800x500",
                              "--field", "displacement", "--view=-z"], capture_output=True, text=True, timeout=300)
    assert process.returncode == 0, process.stderr
    largest = np.linalg.norm(expected["displacement"][-1], axis=1).max()
    assert f"coloured by displacement (largest {largest:.4g}," in process.stdout


def test_render_state_names_what_is_wrong(cantilevers, tmp_path):
    """A missing file, a state the run does not have, a view without a direction and a picture
    that cannot be written: a message naming it and a non-zero exit, no picture."""
    script = str(REPOSITORY / "postproc" / "render_state.py")
    xdmf = str(cantilevers / "results.xdmf")
    cases = [([str(tmp_path / "none.xdmf")], f"{tmp_path / 'none.xdmf'}: no such file"),
             ([xdmf, "--state", "5"], "has 5 states; --state 5 is not one"),
             ([xdmf, "--view", "0,0,0"], "--view 0,0,0: give iso, x, y, z"),
             ([xdmf, "-o", str(tmp_path / "file" / "picture.png")], "cannot write the picture")]
    (tmp_path / "file").write_text("a file where the picture's folder should be")
    for arguments, message in cases:
        process = subprocess.run([sys.executable, script, *arguments], capture_output=True, text=True, timeout=300)
        assert process.returncode == 1 and message in process.stderr, (arguments, process.stderr)
    assert not list(tmp_path.glob("**/*.png"))


# ---------------------------------------------------------------------------------------------

if __name__ == "__main__":
    kind, path = sys.argv[1], sys.argv[2]
    print(json.dumps({"xdmf": probe_xdmf, "d3plot": probe_d3plot}[kind](path)))
