"""Read crashfree results files (``results.h5``): run information, timing, mesh, states and
time histories, as plain Python values and numpy arrays.

The layout is the one of docs/contract.md (user reference: docs/output.md). Every function
takes an open ``h5py.File`` (see :func:`open_results`), so that several reads share one open::

    import crashfree_results as cr
    with cr.open_results("results.h5") as results:
        run = cr.read_run(results)                 # {'status': 'normal termination', ...}
        glstat = cr.read_history(results, "glstat")
        print(cr.energy_ratio(glstat))
        last = cr.read_state(results, -1)          # {'time': ..., 'displacement': (n, 3), ...}
"""
from __future__ import annotations

from pathlib import Path
from typing import Union

import h5py
import numpy as np

#: Energy columns of ``/history/glstat``, in the order they are plotted.
GLSTAT_ENERGIES = ("kinetic_energy", "internal_energy", "hourglass_energy", "contact_energy",
                   "external_work", "total_energy")

#: Phase times of ``/timing`` that split the run (seconds); ``wall_s`` is the whole run.
TIMING_PHASES = ("setup_s", "fe_solid_s", "fe_shell_s", "efg_s", "contact_s", "output_s")

#: Names accepted for a component of a vector column.
COMPONENTS = ("x", "y", "z", "magnitude")


class ResultsError(Exception):
    """A results file lacks what was asked for (the message says what exists instead)."""


def open_results(path: Union[str, Path]) -> h5py.File:
    """Open a results file for reading; raise ResultsError if it is missing or not HDF5."""
    path = Path(path)
    if not path.is_file():
        raise ResultsError(f"{path}: no such file")
    try:
        return h5py.File(path, "r")
    except OSError as error:
        raise ResultsError(f"{path}: not a readable HDF5 file ({error})") from error


def as_text(value) -> str:
    """A string attribute or dataset element as ``str``, whether h5py gave str or bytes."""
    if isinstance(value, (bytes, np.bytes_)):
        return value.decode("utf-8", errors="replace")
    if isinstance(value, np.ndarray) and value.shape == ():
        return as_text(value[()])
    return str(value)


def _plain(value):
    """An attribute value as a plain Python value (str, int, float) where it is a scalar."""
    if isinstance(value, (bytes, np.bytes_, str)):
        return as_text(value)
    if isinstance(value, np.generic):
        return value.item()
    return value


def read_attributes(results: h5py.File, group: str) -> dict:
    """All attributes of ``group`` as a dict of plain values; {} when the group is missing."""
    if group not in results:
        return {}
    return {name: _plain(value) for name, value in results[group].attrs.items()}


def read_run(results: h5py.File) -> dict:
    """The ``/run`` attributes: version, deck, status, message, end_time, cycles, threads."""
    return read_attributes(results, "run")


def read_timing(results: h5py.File) -> dict:
    """The ``/timing`` attributes; {} for a run that did not end (no ``/timing`` yet)."""
    return read_attributes(results, "timing")


def read_mesh(results: h5py.File) -> dict:
    """The mesh: ``node_ids`` (n), ``coordinates`` (n, 3), ``solid_ids``, ``solid_part_ids``,
    ``connectivity`` (m, 8) of node ids, and the parts (``part_ids``, ``formulations``,
    ``material_ids``)."""
    mesh = results["mesh"]
    return {
        "node_ids": mesh["nodes/ids"][()],
        "coordinates": mesh["nodes/coordinates"][()],
        "solid_ids": mesh["solids/ids"][()],
        "solid_part_ids": mesh["solids/part_ids"][()],
        "connectivity": mesh["solids/connectivity"][()],
        "part_ids": mesh["parts/ids"][()],
        "formulations": [as_text(value) for value in mesh["parts/formulation"][()]],
        "material_ids": mesh["parts/material_ids"][()],
    }


def list_states(results: h5py.File) -> list:
    """``[(name, time), ...]`` of the states, in the order they were written."""
    if "states" not in results:
        return []
    names = sorted(results["states"].keys())
    return [(name, float(results["states"][name].attrs["time"])) for name in names]


def read_state(results: h5py.File, state: Union[int, str] = -1) -> dict:
    """One state as a dict: ``name``, ``time`` and every dataset of the state group
    (``displacement`` (n, 3), ``velocity``, ``solid_stress`` (m, 6), ...). ``state`` is an
    index into :func:`list_states` (negative counts from the end) or a group name."""
    states = list_states(results)
    if not states:
        raise ResultsError(f"{results.filename}: no states written")
    if isinstance(state, str):
        names = [name for name, _ in states]
        if state not in names:
            raise ResultsError(f"{results.filename}: no state {state!r} (states: {names[0]} to "
                               f"{names[-1]})")
        name = state
    else:
        try:
            name = states[state][0]
        except IndexError:
            raise ResultsError(f"{results.filename}: no state {state} ({len(states)} states "
                               "written)") from None
    group = results["states"][name]
    values = {"name": name, "time": float(group.attrs["time"])}
    for key, dataset in group.items():
        values[key] = dataset[()]
    return values


def deformed_coordinates(results: h5py.File, state: Union[int, str] = -1) -> np.ndarray:
    """Reference coordinates plus the displacement of a state, (n, 3)."""
    return results["mesh/nodes/coordinates"][()] + read_state(results, state)["displacement"]


def list_history_groups(results: h5py.File) -> list:
    """Names of the history groups holding data, e.g. ``['glstat', 'matsum/1', 'rwforc/7']``."""
    if "history" not in results:
        return []
    groups = []

    def visit(name, item):
        if isinstance(item, h5py.Group) and any(isinstance(child, h5py.Dataset)
                                                 for child in item.values()):
            groups.append(name)

    results["history"].visititems(visit)
    return sorted(groups)


def read_history(results: h5py.File, group: str) -> dict:
    """A history group (``glstat``, ``rwforc/1``, ``nodout/5`` ...) as ``{column: array}``:
    ``time`` (t,) and the other columns, (t,) for scalars and (t, 3) for vectors."""
    path = "history/" + group.strip("/")
    if path not in results or not isinstance(results[path], h5py.Group):
        available = ", ".join(list_history_groups(results)) or "none"
        raise ResultsError(f"{results.filename}: no history {group!r} (available: {available})")
    return {name: dataset[()] for name, dataset in results[path].items()
            if isinstance(dataset, h5py.Dataset)}


def select_component(values: np.ndarray, component: str = "magnitude") -> np.ndarray:
    """One component (x, y, z) or the magnitude of a (t, 3) column; a scalar column as it is."""
    values = np.asarray(values)
    if values.ndim == 1:
        return values
    if component == "magnitude":
        return np.linalg.norm(values, axis=1)
    if component not in COMPONENTS:
        raise ResultsError(f"unknown component {component!r} (choose from {', '.join(COMPONENTS)})")
    return values[:, COMPONENTS.index(component)]


def energy_ratio(glstat: dict, index: int = -1) -> float:
    """Energy ratio at sample ``index`` (the end by default): total energy divided by the
    initial total energy plus the external work, as LS-DYNA's glstat defines it. 1 means
    balanced; NaN when the denominator is zero."""
    total = np.asarray(glstat["total_energy"], dtype=float)
    work = np.asarray(glstat["external_work"], dtype=float)
    denominator = total[0] + work[index]
    if denominator == 0.0:
        return float("nan")
    return float(total[index] / denominator)


def energy_ratio_history(glstat: dict) -> np.ndarray:
    """The energy ratio at every sample (NaN where the denominator is zero)."""
    total = np.asarray(glstat["total_energy"], dtype=float)
    work = np.asarray(glstat["external_work"], dtype=float)
    denominator = total[0] + work
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(denominator != 0.0, total / np.where(denominator != 0.0, denominator, 1.0),
                        np.nan)


def hourglass_ratio(glstat: dict, index: int = -1) -> float:
    """Hourglass energy over internal energy at sample ``index`` (NaN for zero internal energy).
    The usual rule of thumb asks for less than 0.1."""
    internal = float(np.asarray(glstat["internal_energy"])[index])
    if internal == 0.0:
        return float("nan")
    return float(np.asarray(glstat["hourglass_energy"])[index]) / internal


def run_labels(paths) -> list:
    """Short labels for several results files: file stems when they differ, else the names of
    their directories (runs kept as DIR/results.h5), else the full paths."""
    paths = [Path(path) for path in paths]
    for candidates in ([path.stem for path in paths], [path.parent.name for path in paths],
                       [str(path.with_suffix("")) for path in paths]):
        if len(set(candidates)) == len(candidates) and all(candidates):
            return candidates
    return [str(path) for path in paths]
