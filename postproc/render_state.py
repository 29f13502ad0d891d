#!/usr/bin/env python3
"""Render one state of a run as a PNG, headless, through the XDMF reader that ParaView uses
(VTK's vtkXdmfReader, from the `vtk` package of postproc/requirements.txt): the deformed mesh
(reference coordinates + displacement) with its element edges, coloured by the effective
plastic strain of the elements or by the displacement magnitude of the nodes, with a colour
bar, the time and the title of the run.

    python3 postproc/render_state.py DIR/results.xdmf [-o picture.png] [--time T | --state N]
        [--field auto|plastic_strain|displacement] [--view=iso|x|y|z|-x|-y|-z|DX,DY,DZ]
        [--up x|y|z] [--size 1600x1000]

Without -o the picture is DIR/results_final_state.png (DIR/NAME_final_state.png for
NAME.xdmf). `--field auto` (the default) colours by plastic strain when some element has
yielded (above 0.1%), else by displacement. Coloured by plastic strain, the elements of rigid
parts (results.h5 beside the .xdmf, /mesh/parts/formulation) are drawn grey. No display is needed: without $DISPLAY the
picture is rendered off screen (EGL, Mesa's software renderer on a machine without a GPU).
"""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

# Off-screen rendering without a display: VTK would try X first and print a warning before
# falling back to EGL. Set before VTK's rendering modules are loaded.
if not os.environ.get("DISPLAY"):
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")

import vtkmodules.vtkRenderingFreeType  # noqa: E402,F401  (text actors)
import vtkmodules.vtkRenderingOpenGL2  # noqa: E402,F401  (the render window's implementation)
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy  # noqa: E402
from vtkmodules.vtkCommonCore import vtkLookupTable  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkCompositeDataSet, vtkDataObject  # noqa: E402
from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline  # noqa: E402
from vtkmodules.vtkFiltersCore import vtkAppendPolyData  # noqa: E402
from vtkmodules.vtkFiltersGeometry import vtkDataSetSurfaceFilter  # noqa: E402
from vtkmodules.vtkIOImage import vtkPNGWriter  # noqa: E402
from vtkmodules.vtkIOXdmf2 import vtkXdmfReader  # noqa: E402
from vtkmodules.vtkRenderingAnnotation import vtkAxesActor, vtkScalarBarActor  # noqa: E402
from vtkmodules.vtkRenderingCore import (  # noqa: E402
    vtkActor, vtkPolyDataMapper, vtkRenderer, vtkRenderWindow, vtkTextActor, vtkWindowToImageFilter)

PLASTIC_STRAIN_ARRAYS = ("solid_plastic_strain", "shell_plastic_strain")
YIELD_THRESHOLD = 1e-3          # "some element has yielded": plastic strain above 0.1%
VIEWS = {"iso": (1.0, 0.8, 1.2), "x": (1, 0, 0), "y": (0, 1, 0), "z": (0, 0, 1),
         "-x": (-1, 0, 0), "-y": (0, -1, 0), "-z": (0, 0, -1)}
RIGID_GREY = (0.62, 0.62, 0.62)


def open_xdmf(path: Path) -> vtkXdmfReader:
    """The XDMF reader on `path`, its time steps known (ParaView's "XDMF Reader")."""
    if not path.is_file():
        raise SystemExit(f"render_state: {path}: no such file")
    reader = vtkXdmfReader()
    reader.SetFileName(str(path))
    reader.UpdateInformation()
    return reader


def time_steps(reader: vtkXdmfReader) -> list[float]:
    """The times of the states the .xdmf lists, in order."""
    information = reader.GetOutputInformation(0)
    key = vtkStreamingDemandDrivenPipeline.TIME_STEPS()
    return list(information.Get(key)) if information.Has(key) else []


def leaf_blocks(data: vtkDataObject):
    """(name, dataset) of every leaf of a multiblock ("solids", "shells"), or the dataset itself."""
    if not isinstance(data, vtkCompositeDataSet):
        yield "", data
        return
    iterator = data.NewIterator()
    iterator.InitTraversal()
    while not iterator.IsDoneWithTraversal():
        name = iterator.GetCurrentMetaData().Get(vtkCompositeDataSet.NAME()) or ""
        yield name.split("[")[0], iterator.GetCurrentDataObject()
        iterator.GoToNextItem()


def read_state(path: Path, time: float | None = None, state: int | None = None):
    """The state at `time` (the nearest one listed) or with index `state` (negative: from the
    end); the last state by default. Returns (time, its index, the number of states,
    [(block name, unstructured grid)])."""
    reader = open_xdmf(path)
    times = time_steps(reader)
    if not times:
        raise SystemExit(f"render_state: {path} lists no state")
    if time is not None:
        index = int(np.argmin(np.abs(np.array(times) - time)))
    else:
        index = -1 if state is None else state
        if not -len(times) <= index < len(times):
            raise SystemExit(f"render_state: {path} has {len(times)} states; --state {state} is not one")
        index %= len(times)
    reader.UpdateTimeStep(times[index])
    output = reader.GetOutputDataObject(0)
    blocks = []
    for name, block in leaf_blocks(output):
        copy = block.NewInstance()
        copy.DeepCopy(block)
        blocks.append((name, copy))
    return times[index], index, len(times), blocks


def deform(grid) -> None:
    """Move the grid's points by its nodal `displacement` (the XDMF carries the reference
    coordinates; ParaView's Warp By Vector with scale 1 does the same)."""
    displacement = grid.GetPointData().GetArray("displacement")
    if displacement is None:
        return
    points = vtk_to_numpy(grid.GetPoints().GetData()).astype(np.float64)
    moved = points + vtk_to_numpy(displacement)
    grid.GetPoints().SetData(numpy_to_vtk(np.ascontiguousarray(moved), deep=True))


def rigid_part_ids(xdmf_path: Path) -> set[int]:
    """Ids of the rigid parts, from the results file beside the .xdmf (empty when it or h5py
    is not there: the picture is then drawn without the grey)."""
    try:
        import h5py
    except ImportError:
        return set()
    h5_path = xdmf_path.with_suffix(".h5")
    if not h5_path.is_file():
        return set()
    with h5py.File(h5_path, "r") as results:
        parts = results.get("mesh/parts")
        if parts is None or "formulation" not in parts:
            return set()
        formulation = [(f.decode() if isinstance(f, bytes) else str(f)).strip() for f in parts["formulation"][...]]
        return {int(i) for i, kind in zip(parts["ids"][...], formulation) if kind == "rigid"}


def run_title(xdmf_path: Path) -> str:
    """The deck's *TITLE (results.h5 /run title), or the file's name."""
    try:
        import h5py
        with h5py.File(xdmf_path.with_suffix(".h5"), "r") as results:
            title = results["run"].attrs.get("title", "")
            title = title.decode() if isinstance(title, bytes) else str(title)
            if title.strip():
                return title.strip()
    except (ImportError, OSError, KeyError):
        pass
    return xdmf_path.name


def colour_values(grid, field: str, rigid: set[int]) -> np.ndarray:
    """The value drawn on each cell (plastic strain) or node (displacement magnitude) of a
    deformed grid; NaN on rigid parts' cells (drawn grey)."""
    if field == "displacement":
        displacement = grid.GetPointData().GetArray("displacement")
        if displacement is None:
            return np.zeros(grid.GetNumberOfPoints())
        return np.linalg.norm(vtk_to_numpy(displacement), axis=1)
    cells = grid.GetCellData()
    values = np.zeros(grid.GetNumberOfCells())
    for name in PLASTIC_STRAIN_ARRAYS:
        if cells.GetArray(name) is not None:
            values = vtk_to_numpy(cells.GetArray(name)).astype(np.float64).copy()
            break
    part = cells.GetArray("part_id")
    if rigid and part is not None:
        values[np.isin(vtk_to_numpy(part), list(rigid))] = np.nan
    return values


def state_surface(blocks, field: str, rigid: set[int]):
    """The outer faces of all blocks, deformed, with the colour values as the active scalars
    ("value", on cells or on points). Unconnected points of a block (the other block's nodes)
    are dropped by the surface filter."""
    append = vtkAppendPolyData()
    for _, grid in blocks:
        if grid.GetNumberOfCells() == 0:
            continue
        values = colour_values(grid, field, rigid)
        surface = vtkDataSetSurfaceFilter()
        data = numpy_to_vtk(np.ascontiguousarray(values), deep=True)
        data.SetName("value")
        if field == "displacement":
            grid.GetPointData().AddArray(data)
        else:
            grid.GetCellData().AddArray(data)
        deform(grid)
        surface.SetInputData(grid)
        surface.Update()
        polygons = surface.GetOutput()
        attributes = polygons.GetPointData() if field == "displacement" else polygons.GetCellData()
        attributes.SetActiveScalars("value")
        # one kind of scalars for the append: keep only "value"
        for other in [attributes.GetArrayName(i) for i in range(attributes.GetNumberOfArrays())]:
            if other != "value":
                attributes.RemoveArray(other)
        (polygons.GetCellData() if field == "displacement" else polygons.GetPointData()).Initialize()
        append.AddInputData(polygons)
    append.Update()
    return append.GetOutput()


def choose_field(blocks, requested: str) -> str:
    """The field to colour by: `requested`, or for "auto" plastic strain when some element has
    yielded, else displacement."""
    if requested != "auto":
        return requested
    largest = 0.0
    for _, grid in blocks:
        for name in PLASTIC_STRAIN_ARRAYS:
            array = grid.GetCellData().GetArray(name)
            if array is not None and array.GetNumberOfTuples():
                largest = max(largest, float(np.nanmax(vtk_to_numpy(array))))
    return "plastic_strain" if largest > YIELD_THRESHOLD else "displacement"


def rounded_up(value: float) -> float:
    """The top of the colour scale: `value` rounded up to two significant digits (349.5 -> 350,
    so that the five steps of the bar read 70, 140, ...); 1 for nothing to show."""
    if not value > 0.0:
        return 1.0
    unit = 10.0 ** (np.floor(np.log10(value)) - 1)
    return float(np.ceil(value / unit * (1 - 1e-12)) * unit)


def view_direction(view: str) -> np.ndarray:
    """The unit vector from the model to the camera: a named view or "DX,DY,DZ"."""
    if view in VIEWS:
        direction = np.array(VIEWS[view], dtype=float)
    else:
        try:
            direction = np.array([float(v) for v in view.split(",")])
        except ValueError:
            direction = np.zeros(0)
        if direction.shape != (3,) or not np.all(np.isfinite(direction)) or not np.any(direction):
            raise SystemExit(f"render_state: --view {view}: give iso, x, y, z, -x, -y, -z or DX,DY,DZ")
    return direction / np.linalg.norm(direction)


def render(xdmf_path: Path, output: Path, time: float | None = None, state: int | None = None,
           field: str = "auto", view: str = "iso", up: str = "y", size=(1600, 1000)) -> dict:
    """Write the picture; returns what it shows (time, field, its largest value and the
    colour scale's range, the bounds of the deformed mesh) for the caller to print or check."""
    try:
        output.parent.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise SystemExit(f"render_state: cannot write the picture {output}: {error.strerror}")
    shown_time, shown_index, state_count, blocks = read_state(xdmf_path, time, state)
    field = choose_field(blocks, field)
    rigid = rigid_part_ids(xdmf_path)
    surface = state_surface(blocks, field, rigid)
    if surface.GetNumberOfCells() == 0:
        raise SystemExit(f"render_state: {xdmf_path} has no solid or shell element to draw")
    scalars = (surface.GetPointData() if field == "displacement" else surface.GetCellData()).GetArray("value")
    values = vtk_to_numpy(scalars)
    finite = values[np.isfinite(values)]
    largest = float(finite.max()) if finite.size else 0.0
    low, high = 0.0, rounded_up(largest)

    table = vtkLookupTable()
    table.SetNumberOfTableValues(256)
    table.SetHueRange(0.667, 0.0)               # blue (low) to red (high), LS-PrePost's fringe colours
    table.SetRange(low, high)
    table.SetNanColor(*RIGID_GREY, 1.0)
    table.Build()

    mapper = vtkPolyDataMapper()
    mapper.SetInputData(surface)
    mapper.SetLookupTable(table)
    mapper.SetScalarRange(low, high)
    mapper.SetScalarModeToUsePointData() if field == "displacement" else mapper.SetScalarModeToUseCellData()
    mapper.ScalarVisibilityOn()
    actor = vtkActor()
    actor.SetMapper(mapper)
    actor.GetProperty().EdgeVisibilityOn()
    actor.GetProperty().SetEdgeColor(0.12, 0.12, 0.12)
    actor.GetProperty().SetLineWidth(1.0)
    actor.GetProperty().SetAmbient(0.25)
    actor.GetProperty().SetDiffuse(0.8)

    renderer = vtkRenderer()
    renderer.AddActor(actor)
    renderer.SetBackground(1.0, 1.0, 1.0)
    renderer.SetBackground2(0.78, 0.82, 0.90)
    renderer.GradientBackgroundOn()

    bar = vtkScalarBarActor()
    bar.SetLookupTable(table)
    bar.SetTitle("effective plastic strain" if field == "plastic_strain" else "displacement\n(magnitude)")
    bar.SetNumberOfLabels(6)
    bar.SetLabelFormat("%.3g")
    bar.SetOrientationToVertical()
    bar.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
    bar.GetPositionCoordinate().SetValue(0.87, 0.12)
    bar.SetWidth(0.11)
    bar.SetHeight(0.72)
    bar.SetBarRatio(0.3)
    bar.SetTextPositionToPrecedeScalarBar()
    for text in (bar.GetTitleTextProperty(), bar.GetLabelTextProperty()):
        text.SetColor(0.1, 0.1, 0.1)
        text.SetFontFamilyToArial()
        text.BoldOff()
        text.ItalicOff()
        text.ShadowOff()
    bar.UnconstrainedFontSizeOn()
    bar.GetTitleTextProperty().SetFontSize(22)
    bar.GetLabelTextProperty().SetFontSize(18)
    renderer.AddViewProp(bar)

    caption = vtkTextActor()
    grey = " (grey: rigid parts)" if rigid and np.isnan(values).any() else ""
    caption.SetInput(f"{run_title(xdmf_path)}\n"
                     f"state {shown_index + 1} of {state_count}, t = {shown_time:.6g} (the deck's units): "
                     f"the deformed shape, true scale{grey}")
    caption.GetTextProperty().SetFontSize(24)
    caption.GetTextProperty().SetColor(0.1, 0.1, 0.1)
    caption.GetTextProperty().SetFontFamilyToArial()
    caption.SetPosition(20, size[1] - 70)
    renderer.AddViewProp(caption)

    direction = view_direction(view)
    up_vector = np.zeros(3)
    up_vector["xyz".index(up)] = 1.0
    if abs(float(np.dot(up_vector, direction))) > 0.99:      # looking along the up axis
        up_vector = np.roll(up_vector, 1)
    bounds = np.array(surface.GetBounds())
    centre = 0.5 * (bounds[0::2] + bounds[1::2])
    camera = renderer.GetActiveCamera()
    camera.SetFocalPoint(*centre)
    camera.SetPosition(*(centre + direction * np.linalg.norm(bounds[1::2] - bounds[0::2])))
    camera.SetViewUp(*up_vector)
    renderer.ResetCamera()
    camera.Zoom(1.15)
    renderer.ResetCameraClippingRange()

    window = vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(*size)
    window.SetMultiSamples(8)
    window.AddRenderer(renderer)
    window.AddRenderer(axes_triad(camera))
    window.Render()
    grab = vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.ReadFrontBufferOff()
    grab.Update()
    writer = vtkPNGWriter()
    writer.SetFileName(str(output))
    writer.SetInputConnection(grab.GetOutputPort())
    writer.Write()
    window.Finalize()
    if writer.GetErrorCode() != 0 or not output.is_file():
        raise SystemExit(f"render_state: cannot write the picture {output}")
    return {"time": shown_time, "field": field, "largest": largest, "range": (low, high), "bounds": tuple(bounds),
            "rigid_parts": sorted(rigid)}


def axes_triad(camera) -> vtkRenderer:
    """The global x, y, z axes in the lower left corner, turned as the model is."""
    axes = vtkAxesActor()
    axes.SetShaftTypeToCylinder()
    axes.SetTotalLength(1.0, 1.0, 1.0)
    axes.SetCylinderRadius(0.03)
    axes.SetConeRadius(0.12)
    for caption in (axes.GetXAxisCaptionActor2D(), axes.GetYAxisCaptionActor2D(), axes.GetZAxisCaptionActor2D()):
        caption.GetCaptionTextProperty().SetColor(0.1, 0.1, 0.1)
        caption.GetCaptionTextProperty().ShadowOff()
        caption.GetCaptionTextProperty().ItalicOff()
        caption.GetCaptionTextProperty().BoldOn()
    corner = vtkRenderer()
    corner.SetViewport(0.0, 0.0, 0.2, 0.3)
    corner.SetLayer(0)
    corner.InteractiveOff()
    corner.AddActor(axes)
    corner.SetBackgroundAlpha(0.0)
    corner.PreserveColorBufferOn()
    corner.PreserveDepthBufferOff()
    view = corner.GetActiveCamera()
    direction = np.array(camera.GetDirectionOfProjection())
    view.SetFocalPoint(0.0, 0.0, 0.0)
    view.SetPosition(*(-4.0 * direction))
    view.SetViewUp(*camera.GetViewUp())
    corner.ResetCamera()
    return corner


def default_output(xdmf_path: Path) -> Path:
    return xdmf_path.with_name(f"{xdmf_path.stem}_final_state.png")


def main(arguments=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("xdmf", type=Path, help="results.xdmf of a run (results.h5 beside it)")
    parser.add_argument("-o", "--output", type=Path, help="the PNG (default: beside the .xdmf)")
    which = parser.add_mutually_exclusive_group()
    which.add_argument("--time", type=float, help="the state nearest this time")
    which.add_argument("--state", type=int, help="state index, 0 the first, -1 the last (default)")
    parser.add_argument("--field", choices=("auto", "plastic_strain", "displacement"), default="auto")
    parser.add_argument("--view", default="iso",
                        help="direction from the model to the camera (with a minus sign: --view=-z)")
    parser.add_argument("--up", choices=("x", "y", "z"), default="y", help="the axis that points up")
    parser.add_argument("--size", default="1600x1000", help="width x height in pixels")
    options = parser.parse_args(arguments)
    try:
        width, height = (int(v) for v in options.size.lower().split("x"))
    except ValueError:
        parser.error(f"--size {options.size}: give WIDTHxHEIGHT, e.g. 1600x1000")
    if min(width, height) < 100 or max(width, height) > 8000:
        parser.error(f"--size {options.size}: width and height from 100 to 8000 pixels")
    output = options.output or default_output(options.xdmf)
    shown = render(options.xdmf, output, options.time, options.state, options.field, options.view,
                   options.up, (width, height))
    low, high = shown["range"]
    print(f"picture of the state at t = {shown['time']:.6g}, coloured by {shown['field'].replace('_', ' ')} "
          f"(largest {shown['largest']:.4g}, scale {low:.3g} to {high:.3g}): {output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
