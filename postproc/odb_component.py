#!/usr/bin/env python3
"""ODB component test (inputs/odb_component): compare the FE run and the coupled FE/EFG run.

    python3 postproc/odb_component.py FE.h5 COUPLED.h5 [-o DIR]
    python3 postproc/odb_component.py COUPLED.h5 --reference inputs/odb_component/fe_reference.npz [-o DIR]
    python3 postproc/odb_component.py FE.h5 --export-reference inputs/odb_component/fe_reference.npz

The runs are given FE first, then coupled; `--reference` puts a shipped run (an .npz written by
`--export-reference`: the force and energy histories, the summary numbers and the deformed mesh
at the deepest crush, about 0.3 MB) in front of the files, so that `make run` need not run the
FE deck. Writes into DIR (default: the directory of the last results file):

  odb_component_force.png     force on the cylinder against time, both runs (the paper's Fig. 14)
  odb_component_deformed.png  the deformed barrier at the deepest crush, one row per run (Figs. 12
                              and 13b): a slice through the cylinder axis seen from the side, with
                              tangled FE elements in red and EFG cells in orange, and the faces
                              seen from the impactor coloured by depth
  odb_component_summary.md    a table: status, cycles, CPU time and the CPU ratio coupled / FE,
                              EFG dof share, energy balance, hourglass / internal energy, force
                              mean / peak / noise, the worst FE element
and prints where they are.

CPU time: the run's user CPU seconds from `cpu_seconds.txt` beside its results file when a run
script wrote one (tools/run_default.sh, inputs/odb_component/run.sh), else the wall time of
/timing (the same on an idle machine with ncpu=1).

Force noise: the force is the crush force, minus the cylinder's rwforc z component (rwforc holds
the force the wall exerts on the structure, LS-DYNA's sign, and the cylinder pushes down); its mean and peak are taken over the
crush (from the first sample at 10% of the peak to the end). Noise is the r.m.s. of the force
minus its moving average over 1 ms, relative to the mean (content above about 1 kHz), and the
peak-to-mean ratio.

EFG dof share, two ways: /timing's dofs_efg / dofs_total (3 per EFG node over 3 per node plus 3
rotations per shell node: the model's dofs, the paper's definition) and dofs_efg over the
translational dofs only (3 per node).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import crashfree_results as cr  # noqa: E402

# hexahedron corners (0-based) and, for each corner, its three neighbours along the edges in
# the order that gives a positive Jacobian for a properly numbered element
CORNER_EDGES = np.array([[1, 3, 4], [2, 0, 5], [3, 1, 6], [0, 2, 7],
                         [7, 5, 0], [4, 6, 1], [5, 7, 2], [6, 4, 3]])
FACES = np.array([[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]])
SCALARS = ("status", "message", "cycles", "wall_s", "cpu_s", "cpu_source", "efg_s", "setup_s",
           "dofs_total", "dofs_efg", "dofs_translational", "energy_ratio", "energy_ratio_min",
           "energy_ratio_max", "internal", "hourglass", "hourglass_ratio", "external_work", "last_time",
           "added_mass", "time_step_end")


# ----------------------------------------------------------------------------------------------
# Loading: a results file or a shipped reference, into one dict
def load_run(path: Path) -> dict:
    """Everything the figures and the table need from one results.h5."""
    path = Path(path)
    with cr.open_results(path) as results:
        run_info = cr.read_run(results)
        timing = cr.read_timing(results)
        glstat = cr.read_history(results, "glstat")
        groups = [g for g in cr.list_history_groups(results) if g.startswith("rwforc/")]
        if not groups:
            raise cr.ResultsError(f"{path}: no rwforc history")
        rwforc = cr.read_history(results, groups[0])
        mesh = cr.read_mesh(results)
        states = cr.list_states(results)
        last = cr.read_state(results, len(states) - 1)
        shells = None
        if "mesh/shells/connectivity" in results:
            shells = results["mesh/shells/connectivity"][()]
    ratio_history = cr.energy_ratio_history(glstat)
    run = dict(
        path=str(path), status=cr.as_text(run_info.get("status", "?")),
        message=cr.as_text(run_info.get("message", "")),
        cycles=int(timing.get("cycles", 0)), wall_s=float(timing.get("wall_s", np.nan)),
        efg_s=float(timing.get("efg_s", 0.0)), setup_s=float(timing.get("setup_s", np.nan)),
        dofs_total=int(timing.get("dofs_total", 0)), dofs_efg=int(timing.get("dofs_efg", 0)),
        dofs_translational=3 * len(mesh["node_ids"]),
        energy_ratio=cr.energy_ratio(glstat),
        energy_ratio_min=float(np.nanmin(ratio_history[1:])), energy_ratio_max=float(np.nanmax(ratio_history[1:])),
        internal=float(glstat["internal_energy"][-1]), hourglass=float(glstat["hourglass_energy"][-1]),
        hourglass_ratio=cr.hourglass_ratio(glstat), external_work=float(glstat["external_work"][-1]),
        last_time=float(glstat["time"][-1]),
        added_mass=float(glstat["added_mass"][-1]) if "added_mass" in glstat else 0.0,
        time_step_end=float(glstat["time_step"][-1]) if "time_step" in glstat else float("nan"),
        time=np.asarray(rwforc["time"], float), force=-np.asarray(rwforc["force"], float)[:, 2],
        energy_time=np.asarray(glstat["time"], float),
        internal_history=np.asarray(glstat["internal_energy"], float),
        hourglass_history=np.asarray(glstat["hourglass_energy"], float),
        node_ids=mesh["node_ids"], coordinates=mesh["coordinates"], solid_ids=mesh["solid_ids"],
        solid_part_ids=mesh["solid_part_ids"], connectivity=mesh["connectivity"],
        part_ids=np.asarray(mesh["part_ids"]), formulations=np.asarray(mesh["formulations"]),
        shell_connectivity=shells, displacement=last["displacement"], state_time=last["time"])
    cpu_file = path.parent / "cpu_seconds.txt"
    words = cpu_file.read_text().split() if cpu_file.is_file() else []
    try:
        run.update(cpu_s=float(words[0]), cpu_source="user CPU")
    except (IndexError, ValueError):
        run.update(cpu_s=run["wall_s"], cpu_source="wall")
    return run


def export_reference(run: dict, path: Path):
    """The shipped form of a run (compressed .npz): scalars, histories, mesh and last state."""
    arrays = {key: np.asarray(run[key]) for key in SCALARS}
    for key in ("time", "force", "energy_time", "internal_history", "hourglass_history"):
        arrays[key] = np.asarray(run[key], np.float64)
    arrays.update(node_ids=np.asarray(run["node_ids"], np.int32),
                  coordinates=np.asarray(run["coordinates"], np.float32),
                  solid_ids=np.asarray(run["solid_ids"], np.int32),
                  solid_part_ids=np.asarray(run["solid_part_ids"], np.int32),
                  connectivity=np.asarray(run["connectivity"], np.int32),
                  part_ids=np.asarray(run["part_ids"], np.int32), formulations=np.asarray(run["formulations"]),
                  displacement=np.asarray(run["displacement"], np.float32),
                  state_time=np.asarray(run["state_time"]))
    if run.get("shell_connectivity") is not None:
        arrays["shell_connectivity"] = np.asarray(run["shell_connectivity"], np.int32)
    np.savez_compressed(path, **arrays)


def load_reference(path: Path) -> dict:
    with np.load(path, allow_pickle=False) as data:
        run = {key: data[key] for key in data.files}
    for key, value in list(run.items()):
        if value.ndim == 0:
            run[key] = value.item()
    for key in ("coordinates", "displacement"):
        run[key] = np.asarray(run[key], np.float64)
    run.setdefault("shell_connectivity", None)
    run["path"] = f"{path} (shipped)"
    return run


# ----------------------------------------------------------------------------------------------
# Measures
def force_statistics(time, force, window=1.0) -> dict:
    peak = float(np.max(force)) if len(force) else 0.0
    if peak <= 0.0:
        return dict(mean=0.0, peak=0.0, peak_to_mean=float("nan"), noise=float("nan"), start=0.0)
    start = int(np.argmax(force >= 0.1 * peak))
    t, f = time[start:], force[start:]
    mean = float(np.mean(f))
    dt = np.median(np.diff(t)) if len(t) > 1 else 1.0
    n = max(3, int(round(window / dt)) | 1)
    if len(f) > n:
        padded = np.pad(f, n // 2, mode="edge")
        smooth = np.convolve(padded, np.ones(n) / n, mode="valid")
        noise = float(np.sqrt(np.mean((f - smooth) ** 2)) / mean)
    else:
        noise = float("nan")
    return dict(mean=mean, peak=float(np.max(f)), peak_to_mean=float(np.max(f) / mean), noise=noise,
                start=float(t[0]))


def node_index(run: dict) -> np.ndarray:
    """Connectivity of the solids as 0-based node indices."""
    lookup = np.full(int(np.max(run["node_ids"])) + 1, -1, dtype=np.int64)
    lookup[run["node_ids"]] = np.arange(len(run["node_ids"]))
    return lookup


def corner_determinants(points, conn) -> np.ndarray:
    p = points[conn]                                      # (m, 8, 3)
    dets = np.empty(p.shape[:2])
    for c in range(8):
        a, b, d = CORNER_EDGES[c]
        e1, e2, e3 = p[:, a] - p[:, c], p[:, b] - p[:, c], p[:, d] - p[:, c]
        dets[:, c] = np.einsum("ij,ij->i", np.cross(e1, e2), e3)
    return dets


def hexahedron_volumes(points, conn) -> np.ndarray:
    """Exact volume of the trilinear hexahedra (2x2x2 Gauss points of det J)."""
    gauss = 1.0 / np.sqrt(3.0)
    signs = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                      [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], float)
    p = points[conn]
    total = np.zeros(len(p))
    for a, b, c in signs * gauss:
        dn = np.stack([signs[:, 0] * (1 + signs[:, 1] * b) * (1 + signs[:, 2] * c),
                       signs[:, 1] * (1 + signs[:, 0] * a) * (1 + signs[:, 2] * c),
                       signs[:, 2] * (1 + signs[:, 0] * a) * (1 + signs[:, 1] * b)]) / 8.0   # (3, 8)
        total += np.linalg.det(np.einsum("ak,mkj->maj", dn, p))
    return total


def fe_solid_mask(run: dict) -> np.ndarray:
    fe_parts = [int(p) for p, f in zip(run["part_ids"], run["formulations"]) if str(f) == "fe"]
    return np.isin(run["solid_part_ids"], fe_parts)


def element_quality(run: dict) -> dict:
    """Smallest relative volume V/V0 (exact volume of the trilinear map) and smallest corner
    Jacobian ratio (min corner det / max |corner det|) of the FE solids at the deepest crush, with
    the element ids, and the count of inverted corners and of elements that have one."""
    conn = node_index(run)[run["connectivity"]]
    keep = fe_solid_mask(run)
    conn, ids = conn[keep], run["solid_ids"][keep]
    x0 = run["coordinates"]
    x = x0 + run["displacement"]
    relative = hexahedron_volumes(x, conn) / hexahedron_volumes(x0, conn)
    dets = corner_determinants(x, conn)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = dets.min(1) / np.abs(dets).max(1)
    k_v, k_j = int(np.argmin(relative)), int(np.argmin(ratio))
    return dict(min_relative_volume=float(relative[k_v]), element_volume=int(ids[k_v]),
                min_jacobian_ratio=float(ratio[k_j]), element_jacobian=int(ids[k_j]),
                inverted_corners=int(np.sum(dets <= 0.0)), tangled_elements=int(np.sum(dets.min(1) <= 0.0)))


def summarize(run: dict) -> dict:
    summary = {key: run[key] for key in SCALARS}
    summary.update(path=run["path"], **force_statistics(run["time"], run["force"]), **element_quality(run))
    summary["efg_share"] = run["dofs_efg"] / run["dofs_total"] if run["dofs_total"] else 0.0
    summary["efg_share_translational"] = run["dofs_efg"] / run["dofs_translational"] if run["dofs_translational"] else 0.0
    return summary


# ----------------------------------------------------------------------------------------------
# Figures
def plot_force(runs, summaries, labels, output: Path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.2))
    for run, s, label in zip(runs, summaries, labels):
        ax.plot(run["time"], run["force"], lw=1.0,
                label=f"{label} (mean {s['mean']:.1f} kN, peak/mean {s['peak_to_mean']:.2f}, "
                      f"noise {100 * s['noise']:.1f}%)")
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("force on the cylinder (kN)")
    ax.set_title("ODB component test: cylinder force (Fig. 14 analog)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(output, dpi=130)
    plt.close(fig)


def plot_deformed(runs, labels, output: Path, section_x: float = 70.0):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection, PolyCollection
    fig, axes = plt.subplots(len(runs), 2, figsize=(11, 3.8 * len(runs)), squeeze=False,
                             gridspec_kw=dict(width_ratios=[1.0, 1.6]))
    for row, (run, label) in enumerate(zip(runs, labels)):
        lookup = node_index(run)
        conn = lookup[run["connectivity"]]
        x0 = run["coordinates"]
        x = x0 + run["displacement"]
        efg = ~fe_solid_mask(run)
        tangled = (corner_determinants(x, conn).min(1) <= 0.0) & ~efg
        # side view: the slice of elements whose reference x-range holds section_x (the
        # cylinder's axis), each drawn by its x-min face, seen along x
        ax = axes[row, 0]
        x_ref = x0[conn][:, :, 0]
        in_slice = (x_ref.min(1) <= section_x) & (x_ref.max(1) > section_x)
        polys, colours = [], []
        for e in np.nonzero(in_slice)[0]:
            polys.append(x[conn[e][[0, 3, 7, 4]]][:, [2, 1]])
            colours.append("tab:red" if tangled[e] else ("tab:orange" if efg[e] else "tab:blue"))
        ax.add_collection(PolyCollection(polys, facecolors=colours, edgecolors="k", linewidths=0.3, alpha=0.8))
        if run.get("shell_connectivity") is not None:
            shells = lookup[run["shell_connectivity"]]
            xs_ref = x0[shells][:, :, 0]
            cut = (xs_ref.min(1) <= section_x) & (xs_ref.max(1) > section_x)
            segments = []
            for s in np.nonzero(cut)[0]:
                corners = shells[s]
                at_min = corners[np.isclose(x0[corners, 0], xs_ref[s].min())]
                if len(at_min) >= 2:
                    segments.append(x[at_min[:2]][:, [2, 1]])
            ax.add_collection(LineCollection(segments, colors="k", linewidths=1.6))
        ax.set_xlim(-20, 560)
        ax.set_ylim(-20, 680)
        ax.set_aspect("equal")
        ax.set_xlabel("z (mm, impact along -z)")
        ax.set_ylabel("y (mm)")
        ax.set_title(f"{label}: slice at x = {section_x:g} mm, t = {run['state_time']:.1f} ms\n"
                     "blue FE, orange EFG, red FE with an inverted corner; black: cladding", fontsize=8)
        # front view of the outer faces facing +z, seen from the impactor, coloured by depth
        ax = axes[row, 1]
        faces_all = conn[:, FACES]
        key = np.sort(faces_all.reshape(-1, 4), axis=1)
        _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
        outer = (counts[inverse.ravel()] == 1).reshape(-1, 6)
        polys, depth = [], []
        for e, f in zip(*np.nonzero(outer)):
            quad = x[conn[e][FACES[f]]]
            normal = np.cross(quad[2] - quad[0], quad[3] - quad[1])
            if normal[2] <= 0.0:
                continue
            polys.append(quad[:, :2])
            depth.append(quad[:, 2].mean())
        order = np.argsort(depth)
        collection = PolyCollection([polys[k] for k in order], array=np.array(depth)[order], cmap="viridis",
                                    edgecolors="k", linewidths=0.2)
        ax.add_collection(collection)
        ax.set_xlim(-20, 1020)
        ax.set_ylim(-20, 680)
        ax.set_aspect("equal")
        # seen from the impactor (looking along -z, y up), +x points right: x = 0 is the left edge
        ax.set_xlabel("x (mm), seen from the impactor")
        ax.set_title(f"{label}: faces seen from the impactor, coloured by z (mm)", fontsize=8)
        fig.colorbar(collection, ax=ax, shrink=0.8)
    fig.tight_layout()
    fig.savefig(output, dpi=110)
    plt.close(fig)


# ----------------------------------------------------------------------------------------------
def table(summaries, labels) -> str:
    rows = [("status", lambda s: str(s["status"])),
            ("end time reached (ms)", lambda s: f"{s['last_time']:.2f}"),
            ("cycles", lambda s: f"{s['cycles']}"),
            ("CPU time (s)", lambda s: f"{s['cpu_s']:.1f} ({s['cpu_source']})"),
            ("EFG dofs / model dofs (/timing)", lambda s: f"{s['dofs_efg']} / {s['dofs_total']} = {100 * s['efg_share']:.2f}%"),
            ("EFG dofs / translational dofs",
             lambda s: f"{s['dofs_efg']} / {s['dofs_translational']} = {100 * s['efg_share_translational']:.2f}%"),
            ("energy ratio at the end (min, max over the run)",
             lambda s: f"{s['energy_ratio']:.4f} ({s['energy_ratio_min']:.4f}, {s['energy_ratio_max']:.4f})"),
            ("internal energy (J = kN mm)", lambda s: f"{s['internal']:.0f}"),
            ("hourglass energy (J), / internal", lambda s: f"{s['hourglass']:.0f}, {100 * s['hourglass_ratio']:.1f}%"),
            ("cylinder force mean / peak (kN)", lambda s: f"{s['mean']:.1f} / {s['peak']:.1f}"),
            ("peak / mean; noise (r.m.s. about the 1 ms average, / mean)",
             lambda s: f"{s['peak_to_mean']:.2f}; {100 * s['noise']:.1f}%"),
            ("smallest V/V0 of an FE solid (element)",
             lambda s: f"{s['min_relative_volume']:.3f} ({s['element_volume']})"),
            ("worst corner Jacobian ratio of an FE solid (element)",
             lambda s: f"{s['min_jacobian_ratio']:.2f} ({s['element_jacobian']})"),
            ("inverted corners / FE solids with one",
             lambda s: f"{s['inverted_corners']} / {s['tangled_elements']}"),
            ("time step at the end (ms)", lambda s: f"{s['time_step_end']:.3g}"),
            ("message", lambda s: str(s["message"]) or "-")]
    lines = ["| | " + " | ".join(labels) + " |", "|---|" + "---|" * len(labels)]
    for name, value in rows:
        lines.append(f"| {name} | " + " | ".join(value(s) for s in summaries) + " |")
    if len(summaries) == 2 and summaries[0]["cpu_s"] > 0:
        a, b = summaries
        per_cycle = (b["cpu_s"] / max(b["cycles"], 1)) / (a["cpu_s"] / max(a["cycles"], 1))
        lines += ["", f"CPU time ratio {labels[1]} / {labels[0]}: **{b['cpu_s'] / a['cpu_s']:.2f}** "
                      f"({b['cpu_source']} / {a['cpu_source']} seconds; per cycle {per_cycle:.2f}); "
                      f"the paper: 1.12 at 7.6% EFG dofs."]
        if "shipped" in a["path"] or "shipped" in b["path"]:
            lines.append("One run is the shipped reference, timed on the project's machine: the ratio "
                         "compares two machines unless this one is alike (run both with `ODB_FE=1 make run`).")
    return "\n".join(lines) + "\n"


def main(argv=None):
    parser = argparse.ArgumentParser(description="ODB component test: force plot, deformed barrier, summary")
    parser.add_argument("results", nargs="+", type=Path, help="results.h5 of the FE run, then the coupled run")
    parser.add_argument("--reference", type=Path, help="a shipped run (.npz) put in front of the files")
    parser.add_argument("--export-reference", type=Path, help="write the (single) run as a shipped .npz and stop")
    parser.add_argument("--labels", nargs="+", help="a label per run (default: FE, coupled)")
    parser.add_argument("-o", "--output", type=Path, help="output directory")
    parser.add_argument("--section-x", type=float, default=70.0,
                        help="x of the side-view slice (mm; default: the cylinder axis of the generator)")
    args = parser.parse_args(argv)
    if args.export_reference:
        export_reference(load_run(args.results[0]), args.export_reference)
        print(f"reference: {args.export_reference} ({args.export_reference.stat().st_size / 1e6:.2f} MB)")
        return
    runs = ([load_reference(args.reference)] if args.reference else []) + [load_run(p) for p in args.results]
    labels = args.labels or (["FE", "coupled"] if len(runs) == 2 else cr.run_labels(args.results))
    if args.reference and not args.labels and len(runs) == 2:
        labels = ["FE (shipped)", "coupled"]
    output = args.output or args.results[-1].parent
    output.mkdir(parents=True, exist_ok=True)
    summaries = [summarize(run) for run in runs]
    force_png = output / "odb_component_force.png"
    deformed_png = output / "odb_component_deformed.png"
    summary_md = output / "odb_component_summary.md"
    plot_force(runs, summaries, labels, force_png)
    plot_deformed(runs, labels, deformed_png, args.section_x)
    text = table(summaries, labels)
    summary_md.write_text("# ODB component test\n\n" + text)
    print(text)
    print(f"force plot:       {force_png}")
    print(f"deformed barrier: {deformed_png}")
    print(f"summary table:    {summary_md}")


if __name__ == "__main__":
    main()
