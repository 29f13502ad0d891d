#!/usr/bin/env python3
"""ODB component test (inputs/odb_component): compare an FE run and a coupled FE/EFG run.

    python3 postproc/odb_component.py FE.h5 COUPLED.h5 [-o DIR] [--labels FE coupled]

Writes into DIR (default: the directory of the first file):
  odb_force.png      force on the cylinder against time, both runs (the paper's Fig. 14)
  odb_deformed.png   the deformed barrier at the deepest crush, both runs, seen from the side
                     and from the front (the paper's Figs. 12 and 13b)
  odb_summary.md     a table: status, cycles, wall time, CPU ratio, EFG dof share, energy
                     balance, hourglass / internal energy, force mean / peak / noise, the worst
                     element (smallest relative volume and Jacobian ratio)
and prints where they are. One file alone works too (its own figures and table).

Force noise: the force is the cylinder's rwforc (averaged over each output interval); its mean
and peak are taken over the crush (from the first sample at 10% of the peak to the end), the
noise is the r.m.s. of the force minus its moving average over 1 ms, relative to the mean
(high-frequency content), and the peak-to-mean ratio.
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


def cylinder_force(results) -> tuple:
    """(time, force along +z: the barrier pushes the cylinder back) of the first rigid wall (the cylinder)."""
    groups = [g for g in cr.list_history_groups(results) if g.startswith("rwforc/")]
    if not groups:
        raise cr.ResultsError(f"{results.filename}: no rwforc history")
    history = cr.read_history(results, groups[0])
    return history["time"], history["force"][:, 2]


def force_statistics(time, force, window=1.0) -> dict:
    peak = float(np.max(force)) if len(force) else 0.0
    if peak <= 0.0:
        return dict(mean=0.0, peak=0.0, peak_to_mean=float("nan"), noise=float("nan"))
    start = int(np.argmax(force >= 0.1 * peak))
    t, f = time[start:], force[start:]
    mean = float(np.mean(f))
    dt = np.median(np.diff(t)) if len(t) > 1 else 1.0
    n = max(3, int(round(window / dt)) | 1)
    if len(f) > n:
        kernel = np.ones(n) / n
        padded = np.pad(f, n // 2, mode="edge")
        smooth = np.convolve(padded, kernel, mode="valid")
        noise = float(np.sqrt(np.mean((f - smooth) ** 2)) / mean)
    else:
        noise = float("nan")
    return dict(mean=mean, peak=float(np.max(f)), peak_to_mean=float(np.max(f) / mean), noise=noise,
                start=float(t[0]))


def element_quality(results, state=-1, parts=None) -> dict:
    """Smallest relative volume V/V0 (exact volume of the trilinear map) and smallest corner Jacobian
    ratio (min corner det / max corner det) of the solid elements in a state, with the element
    ids where they occur."""
    mesh = cr.read_mesh(results)
    index = {nid: k for k, nid in enumerate(mesh["node_ids"])}
    conn = np.vectorize(index.get)(mesh["connectivity"])
    keep = np.ones(len(conn), bool) if parts is None else np.isin(mesh["solid_part_ids"], parts)
    conn, ids = conn[keep], mesh["solid_ids"][keep]
    x0 = mesh["coordinates"]
    x = cr.deformed_coordinates(results, state)

    def corner_dets(points):
        p = points[conn]                                      # (m, 8, 3)
        dets = np.empty(p.shape[:2])
        for c in range(8):
            a, b, d = CORNER_EDGES[c]
            e1, e2, e3 = p[:, a] - p[:, c], p[:, b] - p[:, c], p[:, d] - p[:, c]
            dets[:, c] = np.einsum("ij,ij->i", np.cross(e1, e2), e3)
        return dets

    gauss = 1.0 / np.sqrt(3.0)
    signs = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                      [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], float)

    def volumes(points):
        """Exact volume of the trilinear hexahedra (2x2x2 Gauss points of det J)."""
        p = points[conn]
        total = np.zeros(len(p))
        for a, b, c in signs * gauss:
            dn = np.stack([signs[:, 0] * (1 + signs[:, 1] * b) * (1 + signs[:, 2] * c),
                           signs[:, 1] * (1 + signs[:, 0] * a) * (1 + signs[:, 2] * c),
                           signs[:, 2] * (1 + signs[:, 0] * a) * (1 + signs[:, 1] * b)]) / 8.0   # (3, 8)
            jac = np.einsum("ak,mkj->maj", dn, p)
            total += np.linalg.det(jac)
        return total

    v0, v = volumes(x0), volumes(x)
    relative = v / v0
    dets = corner_dets(x)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = dets.min(1) / np.abs(dets).max(1)
    k_v, k_j = int(np.argmin(relative)), int(np.argmin(ratio))
    return dict(min_relative_volume=float(relative[k_v]), element_volume=int(ids[k_v]),
                min_jacobian_ratio=float(ratio[k_j]), element_jacobian=int(ids[k_j]),
                inverted_corners=int(np.sum(dets <= 0.0)), tangled_elements=int(np.sum(dets.min(1) <= 0.0)))


def deepest_state(results) -> int:
    """Index of the state with the largest cylinder travel (the last one)."""
    return len(cr.list_states(results)) - 1


def summarize(path: Path) -> dict:
    with cr.open_results(path) as results:
        run = cr.read_run(results)
        timing = cr.read_timing(results)
        glstat = cr.read_history(results, "glstat")
        time, force = cylinder_force(results)
        mesh = cr.read_mesh(results)
        efg_parts = [int(p) for p, f in zip(mesh["part_ids"], mesh["formulations"]) if f == "efg"]
        quality = element_quality(results, deepest_state(results),
                                  parts=[p for p, f in zip(mesh["part_ids"], mesh["formulations"]) if f == "fe"])
        internal = float(glstat["internal_energy"][-1])
        summary = dict(
            path=str(path), status=cr.as_text(run.get("status", "?")), message=cr.as_text(run.get("message", "")),
            end_time=float(run.get("end_time", np.nan)), cycles=int(timing.get("cycles", run.get("cycles", 0))),
            wall_s=float(timing.get("wall_s", np.nan)), setup_s=float(timing.get("setup_s", np.nan)),
            efg_s=float(timing.get("efg_s", 0.0)), solid_s=float(timing.get("fe_solid_s", np.nan)),
            contact_s=float(timing.get("contact_s", np.nan)),
            dofs_total=int(timing.get("dofs_total", 0)), dofs_efg=int(timing.get("dofs_efg", 0)),
            efg_parts=efg_parts,
            energy_ratio=cr.energy_ratio(glstat),
            energy_ratio_min=float(np.nanmin(cr.energy_ratio_history(glstat)[1:])),
            energy_ratio_max=float(np.nanmax(cr.energy_ratio_history(glstat)[1:])),
            hourglass_ratio=cr.hourglass_ratio(glstat), internal=internal,
            hourglass=float(glstat["hourglass_energy"][-1]),
            external_work=float(glstat["external_work"][-1]),
            last_time=float(glstat["time"][-1]),
            added_mass=float(glstat["added_mass"][-1]) if "added_mass" in glstat else 0.0,
            time=time, force=force, **force_statistics(time, force), **quality)
        summary["efg_share"] = summary["dofs_efg"] / summary["dofs_total"] if summary["dofs_total"] else 0.0
    return summary


def plot_force(summaries, labels, output: Path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.2))
    for s, label in zip(summaries, labels):
        ax.plot(s["time"], s["force"], label=f"{label} (mean {s['mean']:.1f} kN, noise {100 * s['noise']:.0f}%)")
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("force on the cylinder (kN)")
    ax.set_title("ODB component test: cylinder force (Fig. 14 analog)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(output, dpi=130)
    plt.close(fig)


def outer_faces(conn):
    """Faces (as node index quads) that belong to one element only."""
    faces = conn[:, FACES].reshape(-1, 4)
    key = np.sort(faces, axis=1)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    return faces[counts[inverse.ravel()] == 1]


def plot_deformed(paths, labels, output: Path, section_x: float = 110.0):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection
    fig, axes = plt.subplots(len(paths), 2, figsize=(11, 3.6 * len(paths)), squeeze=False,
                             gridspec_kw=dict(width_ratios=[1.0, 1.6]))
    for row, (path, label) in enumerate(zip(paths, labels)):
        with cr.open_results(path) as results:
            mesh = cr.read_mesh(results)
            index = {nid: k for k, nid in enumerate(mesh["node_ids"])}
            conn = np.vectorize(index.get)(mesh["connectivity"])
            state = cr.read_state(results, -1)
            x = mesh["coordinates"] + state["displacement"]
            formulation = dict(zip(mesh["part_ids"], mesh["formulations"]))
            strain = state.get("solid_plastic_strain")
            part_of = mesh["solid_part_ids"]
            faces_all = conn[:, FACES]                                  # (m, 6, 4)
            key = np.sort(faces_all.reshape(-1, 4), axis=1)
            _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
            outer = (counts[inverse.ravel()] == 1).reshape(-1, 6)
            # side view: the slice of elements whose reference x-range holds section_x (the
            # cylinder's axis), each drawn by its x-min face, seen along x
            ax = axes[row, 0]
            x_ref = mesh["coordinates"][conn][:, :, 0]
            in_slice = (x_ref.min(1) <= section_x) & (x_ref.max(1) > section_x)
            polys, colours = [], []
            for e in np.nonzero(in_slice)[0]:
                quad = x[conn[e][[0, 3, 7, 4]]]          # the x-min face of the element
                polys.append(quad[:, [2, 1]])
                colours.append("tab:orange" if formulation.get(part_of[e]) == "efg" else "tab:blue")
            ax.add_collection(PolyCollection(polys, facecolors=colours, edgecolors="k", linewidths=0.3, alpha=0.8))
            ax.set_xlim(-20, 560)
            ax.set_ylim(-20, 680)
            ax.set_aspect("equal")
            ax.set_xlabel("z (mm, impact along -z)")
            ax.set_ylabel("y (mm)")
            ax.set_title(f"{label}: slice at x = {section_x:g} mm (orange: EFG), t = {state['time']:.1f} ms",
                         fontsize=9)
            # front view of the outer faces facing +z, seen from the impactor, coloured by depth
            ax = axes[row, 1]
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
            ax.set_title(f"{label}: front faces, coloured by z (mm)", fontsize=9)
            fig.colorbar(collection, ax=ax, shrink=0.8)
            del strain
    fig.tight_layout()
    fig.savefig(output, dpi=130)
    plt.close(fig)


def table(summaries, labels) -> str:
    rows = [("status", lambda s: s["status"]),
            ("end time reached (ms)", lambda s: f"{s['last_time']:.2f}"),
            ("cycles", lambda s: f"{s['cycles']}"),
            ("wall time (s)", lambda s: f"{s['wall_s']:.1f}"),
            ("EFG set-up / EFG update (s)", lambda s: f"{s['setup_s']:.1f} / {s['efg_s']:.1f}"),
            ("EFG dofs / total dofs", lambda s: f"{s['dofs_efg']} / {s['dofs_total']} = {100 * s['efg_share']:.1f}%"),
            ("energy ratio at the end (min, max)",
             lambda s: f"{s['energy_ratio']:.4f} ({s['energy_ratio_min']:.4f}, {s['energy_ratio_max']:.4f})"),
            ("internal energy (J = kN mm)", lambda s: f"{s['internal']:.3f}"),
            ("hourglass energy (J), / internal", lambda s: f"{s['hourglass']:.4f}, {100 * s['hourglass_ratio']:.1f}%"),
            ("added mass (kg)", lambda s: f"{s['added_mass']:.3g}"),
            ("cylinder force mean / peak (kN)", lambda s: f"{s['mean']:.2f} / {s['peak']:.2f}"),
            ("peak / mean, noise (r.m.s. above 1 ms, / mean)",
             lambda s: f"{s['peak_to_mean']:.2f}, {100 * s['noise']:.1f}%"),
            ("smallest V/V0 of an FE solid, exact volume (element)",
             lambda s: f"{s['min_relative_volume']:.3f} ({s['element_volume']})"),
            ("smallest corner Jacobian ratio of an FE solid (element)",
             lambda s: f"{s['min_jacobian_ratio']:.3f} ({s['element_jacobian']}), {s['inverted_corners']} inverted corners in {s['tangled_elements']} elements"),
            ("message", lambda s: s["message"] or "-")]
    lines = ["| | " + " | ".join(labels) + " |", "|---|" + "---|" * len(labels)]
    for name, value in rows:
        lines.append(f"| {name} | " + " | ".join(value(s) for s in summaries) + " |")
    if len(summaries) == 2 and summaries[0]["wall_s"] > 0:
        lines.append("")
        lines.append(f"CPU time ratio {labels[1]} / {labels[0]}: "
                     f"{summaries[1]['wall_s'] / summaries[0]['wall_s']:.2f} (wall time, one thread each); "
                     f"per cycle: {(summaries[1]['wall_s'] / max(summaries[1]['cycles'], 1)) / (summaries[0]['wall_s'] / max(summaries[0]['cycles'], 1)):.2f}")
    return "\n".join(lines) + "\n"


def main(argv=None):
    parser = argparse.ArgumentParser(description="ODB component test: force plot, deformed barrier, summary")
    parser.add_argument("results", nargs="+", type=Path, help="results.h5 of the FE run, then the coupled run")
    parser.add_argument("--labels", nargs="+", help="a label per file (default: FE, coupled)")
    parser.add_argument("-o", "--output", type=Path, help="output directory")
    parser.add_argument("--section-x", type=float, default=110.0,
                        help="x of the side-view slice (mm; default: the cylinder axis of the generator)")
    args = parser.parse_args(argv)
    labels = args.labels or (["FE", "coupled"] if len(args.results) == 2 else cr.run_labels(args.results))
    output = args.output or args.results[0].parent
    output.mkdir(parents=True, exist_ok=True)
    summaries = [summarize(p) for p in args.results]
    force_png, deformed_png, summary_md = output / "odb_force.png", output / "odb_deformed.png", output / "odb_summary.md"
    plot_force(summaries, labels, force_png)
    plot_deformed(args.results, labels, deformed_png, args.section_x)
    text = table(summaries, labels)
    summary_md.write_text("# ODB component test\n\n" + text)
    print(text)
    print(f"force plot:       {force_png}")
    print(f"deformed barrier: {deformed_png}")
    print(f"summary table:    {summary_md}")


if __name__ == "__main__":
    main()
