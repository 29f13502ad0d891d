#!/usr/bin/env python3
"""Side-impact dummy component test (inputs/side_impact): compare the FE run, the run with
meshfree rib foams and the coupled run (meshfree rib foams and jacket).

    python3 postproc/side_impact.py FE.h5 RIBS_EFG.h5 COUPLED.h5 [-o DIR] [--labels ...]

Any number of runs may be given (missing runs are left out). Writes into DIR (default: the
directory of the last results file's parent):

  side_impact_force.png      force between the door and the thorax against time, every run (the
                             paper's Fig. 17): the door contact's rcforc, its y component
  side_impact_sections.png   deformed sections at 20 ms and at the end of each run (60 ms for a
                             run that got there): a horizontal cut through the upper rib module
                             (z = 180 mm) and a vertical cut through the thorax's lateral axis
                             (x = 0); red: FE solids with an inverted corner, orange: meshfree
  side_impact_summary.md     the table: status, end time, CPU per simulated ms, meshfree share of
                             the dofs, energies, hourglass / internal, peak force, door impulse
                             against the door's momentum change, worst element quality, where
                             the time went (/timing phases)
and prints where they are.

CPU time: the user CPU seconds from `cpu_seconds.txt` beside a results file (written by
inputs/side_impact/run.sh), else the wall time of /timing. When the run directory's parent holds
`cpu_times.txt` (run.sh with REPEAT=n), the medians per deck are used, per simulated ms.
"""
from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import crashfree_results as cr  # noqa: E402
from odb_component import corner_determinants, hexahedron_volumes  # noqa: E402

DOOR_CONTACT = "rcforc/1"          # the generator's door contact
DOOR_BODY = "rbdout/2"             # the door's rigid body (part 2)
FOAM_PARTS = (21, 22, 23)
JACKET_PART = 3
SECTION_TIMES = (20.0, 60.0)
UPPER_RIB_Z = 180.0


def nearest_state(results, time: float) -> int:
    """Index of the state written nearest to `time` (the last one for a run that ended earlier)."""
    times = np.array([t for _, t in cr.list_states(results)])
    return int(np.argmin(np.abs(times - time)))


def read_cpu(path: Path, wall: float):
    words = (path.parent / "cpu_seconds.txt").read_text().split() if (path.parent / "cpu_seconds.txt").is_file() else []
    try:
        return float(words[0]), "user CPU"
    except (IndexError, ValueError):
        return wall, "wall"


def median_cpu(path: Path):
    """Median user CPU seconds of this deck's runs from run.sh's cpu_times.txt, and how many."""
    table = path.parent.parent / "cpu_times.txt"
    if not table.is_file():
        return None, 0
    values = [float(line.split()[1]) for line in table.read_text().splitlines()
              if line.split() and line.split()[0] == path.parent.name]
    return (statistics.median(values), len(values)) if values else (None, 0)


def load_run(path: Path) -> dict:
    path = Path(path)
    with cr.open_results(path) as results:
        info = cr.read_run(results)
        timing = cr.read_timing(results)
        glstat = cr.read_history(results, "glstat")
        contact = cr.read_history(results, DOOR_CONTACT)
        door = cr.read_history(results, DOOR_BODY)
        mesh = cr.read_mesh(results)
        shells = results["mesh/shells/connectivity"][()]
        shell_parts = results["mesh/shells/part_ids"][()]
        sections = {}
        for time in SECTION_TIMES:
            state = cr.read_state(results, nearest_state(results, time))
            sections[time] = (state["time"], state["displacement"])
        last = cr.read_state(results, -1)
    wall = float(timing.get("wall_s", np.nan))
    cpu, source = read_cpu(path, wall)
    median, repeats = median_cpu(path)
    if median is not None:
        cpu, source = median, f"median user CPU of {repeats}"
    end_time = float(glstat["time"][-1])
    ratio = cr.energy_ratio_history(glstat)
    time = np.asarray(contact["time"], float)
    force = -np.asarray(contact["force"], float)[:, 1]         # on the thorax, +: toward -y
    door_velocity = np.asarray(door["velocity"], float)[:, 1]
    return dict(path=str(path), status=cr.as_text(info.get("status", "?")), message=cr.as_text(info.get("message", "")),
                end_time=end_time, cycles=int(timing.get("cycles", 0)), cpu=cpu, cpu_source=source,
                dofs_total=int(timing.get("dofs_total", 0)), dofs_efg=int(timing.get("dofs_efg", 0)),
                timing=timing, energy_ratio_min=float(np.nanmin(ratio[1:])), energy_ratio_max=float(np.nanmax(ratio[1:])),
                energy_ratio=float(ratio[-1]), internal=float(glstat["internal_energy"][-1]),
                internal_peak=float(np.max(glstat["internal_energy"])),
                kinetic=float(glstat["kinetic_energy"][-1]), kinetic_start=float(glstat["kinetic_energy"][0]),
                hourglass=float(glstat["hourglass_energy"][-1]), contact_energy=float(glstat["contact_energy"][-1]),
                time=time, force=force, door_time=np.asarray(door["time"], float), door_velocity=door_velocity,
                mesh=mesh, shells=shells, shell_parts=shell_parts, sections=sections,
                last=(last["time"], last["displacement"]),
                worst_jacobian_run=float(info.get("worst_corner_jacobian_ratio", np.nan)))


# ----------------------------------------------------------------------------------------------
def node_lookup(mesh) -> np.ndarray:
    lookup = np.full(int(np.max(mesh["node_ids"])) + 1, -1, dtype=np.int64)
    lookup[mesh["node_ids"]] = np.arange(len(mesh["node_ids"]))
    return lookup


def quality(run: dict, displacement) -> dict:
    """Smallest V/V0 and corner Jacobian ratio of the FE foam solids, smallest area ratio of
    the jacket shells, at the given displacement."""
    mesh = run["mesh"]
    lookup = node_lookup(mesh)
    x0 = mesh["coordinates"]
    x = x0 + displacement
    fe_parts = [int(p) for p, f in zip(mesh["part_ids"], mesh["formulations"]) if f == "fe"]
    keep = np.isin(mesh["solid_part_ids"], FOAM_PARTS) & np.isin(mesh["solid_part_ids"], fe_parts)
    result = dict(min_volume=np.nan, min_volume_element=0, min_jacobian=np.nan, min_jacobian_element=0)
    if np.any(keep):
        conn = lookup[mesh["connectivity"][keep]]
        ids = mesh["solid_ids"][keep]
        relative = hexahedron_volumes(x, conn) / hexahedron_volumes(x0, conn)
        dets = corner_determinants(x, conn)
        with np.errstate(divide="ignore", invalid="ignore"):
            jacobian = dets.min(1) / np.abs(dets).max(1)
        result.update(min_volume=float(relative.min()), min_volume_element=int(ids[np.argmin(relative)]),
                      min_jacobian=float(jacobian.min()), min_jacobian_element=int(ids[np.argmin(jacobian)]))
    jacket = lookup[run["shells"][run["shell_parts"] == JACKET_PART]]

    def areas(points):
        p = points[jacket]
        return 0.5 * np.linalg.norm(np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1]), axis=1)
    result["min_jacket_area"] = float(np.min(areas(x) / areas(x0)))
    return result


def moving_mean(time, values, window: float) -> np.ndarray:
    """Centred moving mean over `window` (ms) of a uniformly sampled history."""
    step = float(np.median(np.diff(time))) if len(time) > 1 else window
    n = max(1, int(round(window / step)))
    if n < 2 or len(values) <= n:
        return np.asarray(values, float)
    padded = np.pad(np.asarray(values, float), (n // 2, n - 1 - n // 2), mode="edge")
    return np.convolve(padded, np.ones(n) / n, mode="valid")


def summarize(run: dict) -> dict:
    s = {key: run[key] for key in ("status", "message", "end_time", "cycles", "cpu", "cpu_source", "dofs_total",
                                   "dofs_efg", "energy_ratio", "energy_ratio_min", "energy_ratio_max", "internal",
                                   "internal_peak", "hourglass", "kinetic", "kinetic_start", "contact_energy",
                                   "worst_jacobian_run", "path")}
    s["cpu_per_ms"] = run["cpu"] / run["end_time"] if run["end_time"] > 0 else np.nan
    # meshfree share of the dofs, two ways: every node of a meshfree part (3 dofs, 3 more on a
    # shell node; a node of a meshfree solid and shell counted once), as the generator prints
    # it; and the interior particles only (the Gamma nodes keep FE functions)
    mesh = run["mesh"]
    efg_parts = [int(p) for p, f in zip(mesh["part_ids"], mesh["formulations"]) if f == "efg"]
    solid_nodes = set(np.unique(mesh["connectivity"][np.isin(mesh["solid_part_ids"], efg_parts)]).tolist())
    shell_nodes = set(np.unique(run["shells"][np.isin(run["shell_parts"], efg_parts)]).tolist())
    total = max(run["dofs_total"], 1)
    s["efg_share"] = (3 * len(solid_nodes | shell_nodes) + 3 * len(shell_nodes)) / total
    timing = run["timing"]
    s["particle_share"] = (3 * int(timing.get("efg_particles", 0)) + 6 * int(timing.get("efg_shell_particles", 0))) / total
    s["hourglass_ratio"] = run["hourglass"] / run["internal"] if run["internal"] else np.nan
    k = int(np.argmax(run["force"]))
    s["peak_force"], s["peak_time"] = float(run["force"][k]), float(run["time"][k])
    # the force chatters (the rigid door knocks light jacket nodes ahead of it): the peak of its
    # 1 ms moving mean is the measure to compare
    mean = moving_mean(run["time"], run["force"], 1.0)
    k = int(np.argmax(mean))
    s["peak_mean_force"], s["peak_mean_time"] = float(mean[k]), float(run["time"][k])
    # impulse of the contact on the door (trapezoidal rule) against the door's momentum change
    s["impulse"] = float(np.trapezoid(run["force"], run["time"]))
    s["door_dv"] = float(run["door_velocity"][-1] - run["door_velocity"][0])
    s.update(quality(run, run["last"][1]))
    phases = {"FE solids": timing.get("fe_solid_s", 0.0), "FE shells": timing.get("fe_shell_s", 0.0),
              "meshfree solids": timing.get("efg_s", 0.0),
              "meshfree shells": timing.get("efg_shell_s", 0.0), "contact": timing.get("contact_s", 0.0),
              "output": timing.get("output_s", 0.0)}
    wall = float(timing.get("wall_s", np.nan))
    phases["other"] = wall - sum(phases.values())
    s["phases"] = phases
    # the cycle's phases (wall seconds): internal forces, and what of it no group timer holds
    internal = float(timing.get("phase_internal_forces_s", np.nan))
    groups = sum(phases[k] for k in ("FE solids", "FE shells", "meshfree solids", "meshfree shells"))
    s["phase_internal"], s["phase_internal_untimed"] = internal, internal - groups
    s["phase_contact"] = float(timing.get("phase_contact_s", np.nan))
    s["wall"] = wall
    return s


# ----------------------------------------------------------------------------------------------
def plot_force(runs, summaries, labels, output: Path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7.5, 4.4))
    for run, s, label in zip(runs, summaries, labels):
        ending = "" if "normal" in s["status"] else f", stops at {s['end_time']:.1f} ms"
        ax.plot(run["time"], run["force"], lw=0.8, label=f"{label} (1 ms mean: peak {s['peak_mean_force']:.1f} kN "
                                                         f"at {s['peak_mean_time']:.1f} ms{ending})")
        if "normal" not in s["status"]:
            ax.plot(run["time"][-1], run["force"][-1], "x", color=ax.lines[-1].get_color(), ms=9)
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("force door - thorax (kN), samples")
    ax.set_title("Side-impact dummy component test: contact force (Fig. 17 analog)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(output, dpi=130)
    plt.close(fig)


def plot_sections(runs, labels, output: Path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection, PolyCollection
    columns = [(t, "z") for t in SECTION_TIMES] + [(t, "x") for t in SECTION_TIMES]
    fig, axes = plt.subplots(len(runs), len(columns), figsize=(4.0 * len(columns), 3.9 * len(runs)), squeeze=False)
    for row, (run, label) in enumerate(zip(runs, labels)):
        mesh = run["mesh"]
        lookup = node_lookup(mesh)
        conn = lookup[mesh["connectivity"]]
        x0 = mesh["coordinates"]
        formulation = dict(zip([int(p) for p in mesh["part_ids"]], mesh["formulations"]))
        efg_solid = np.array([formulation[int(p)] == "efg" for p in mesh["solid_part_ids"]])
        shells = lookup[run["shells"]]
        for col, (time, cut) in enumerate(columns):
            ax = axes[row, col]
            state_time, displacement = run["sections"][time]
            # seen from the spine box: its mean translation taken off (the thorax flies off)
            spine = np.unique(conn[mesh["solid_part_ids"] == 1])
            x = x0 + displacement - displacement[spine].mean(0)
            tangled = (corner_determinants(x, conn).min(1) <= 0.0) & ~efg_solid
            axis, (u, v) = (2, (0, 1)) if cut == "z" else (0, (1, 2))
            level = UPPER_RIB_Z if cut == "z" else 0.0
            level_ref = x0[conn][:, :, axis]
            inside = (level_ref.min(1) <= level) & (level_ref.max(1) > level) & (mesh["solid_part_ids"] != 1)
            polys, colours = [], []
            for e in np.nonzero(inside)[0]:
                # the face nearest the cut: z-min face (N1-N4) or the face of the x-min nodes
                corners = conn[e]
                if cut == "x":
                    # the face of its four nodes of smallest reference x, in order around it
                    face = corners[np.argsort(x0[corners, 0], kind="stable")[:4]]
                    ref = x0[face][:, [u, v]]
                    face = face[np.argsort(np.arctan2(*(ref - ref.mean(0)).T[::-1]))]
                    quad = x[face]
                else:
                    quad = x[corners[[0, 1, 2, 3]]]
                polys.append(quad[:, [u, v]])
                colours.append("tab:red" if tangled[e] else ("tab:orange" if efg_solid[e] else "tab:blue"))
            ax.add_collection(PolyCollection(polys, facecolors=colours, edgecolors="k", linewidths=0.2, alpha=0.85))
            # shells cut by the plane: the edge of their lower-coordinate nodes
            s_ref = x0[shells][:, :, axis]
            cutting = (s_ref.min(1) <= level + 1e-6) & (s_ref.max(1) > level + 1e-6)
            flat = (np.ptp(s_ref, axis=1) < 1e-6) & (np.abs(s_ref[:, 0] - level) < 1e-6)
            segments, colours = [], []
            for s in np.nonzero(cutting | flat)[0]:
                corners = shells[s]
                low = corners[np.isclose(x0[corners, axis], x0[corners, axis].min())] if not flat[s] else corners
                pts = x[low][:, [u, v]]
                if len(pts) >= 2:
                    segments.append(pts[[0, -1]] if not flat[s] else pts[[0, 1, 2, 3, 0]])
                    part = int(run["shell_parts"][s])
                    colours.append({2: "tab:gray", JACKET_PART: "tab:green"}.get(part, "k"))
            ax.add_collection(LineCollection(segments, colors=colours, linewidths=1.4))
            box = x[spine][:, [u, v]]
            ax.add_patch(plt.Rectangle(box.min(0), *np.ptp(box, axis=0), fill=False, hatch="//", color="0.4"))
            if cut == "z":
                ax.set_xlim(-220, 220)
                ax.set_ylim(-80, 220)
                ax.set_xlabel("x (mm)")
                ax.set_ylabel("y (mm, door moves in -y)")
                where = f"z = {UPPER_RIB_Z:g} (upper rib)"
            else:
                ax.set_xlim(-80, 220)
                ax.set_ylim(-70, 270)
                ax.set_xlabel("y (mm)")
                ax.set_ylabel("z (mm)")
                where = "x = 0"
            ax.set_aspect("equal")
            ax.set_title(f"{label}: {where}, t = {state_time:.1f} ms", fontsize=8)
    fig.suptitle("deformed sections relative to the spine box (hatched; blue FE foam, orange meshfree foam, red FE with an inverted corner; "
                 "black rib band, green jacket, grey door)", fontsize=9)
    fig.tight_layout()
    fig.savefig(output, dpi=100)
    plt.close(fig)


def table(summaries, labels) -> str:
    rows = [("status", lambda s: s["status"]),
            ("end time reached (ms)", lambda s: f"{s['end_time']:.2f}"),
            ("cycles", lambda s: f"{s['cycles']}"),
            ("CPU (s), per simulated ms", lambda s: f"{s['cpu']:.1f} ({s['cpu_source']}), {s['cpu_per_ms']:.2f}"),
            ("meshfree share of the dofs: nodes of meshfree parts; interior particles",
             lambda s: f"{100 * s['efg_share']:.1f}%; {100 * s['particle_share']:.1f}% (of {s['dofs_total']})"),
            ("energy ratio at the end (min, max)",
             lambda s: f"{s['energy_ratio']:.4f} ({s['energy_ratio_min']:.4f}, {s['energy_ratio_max']:.4f})"),
            ("kinetic energy start / end (J)", lambda s: f"{s['kinetic_start']:.0f} / {s['kinetic']:.0f}"),
            ("internal energy end (peak) (J)", lambda s: f"{s['internal']:.0f} ({s['internal_peak']:.0f})"),
            ("hourglass energy (J), / internal", lambda s: f"{s['hourglass']:.1f}, {100 * s['hourglass_ratio']:.1f}%"),
            ("contact energy (J)", lambda s: f"{s['contact_energy']:.1f}"),
            ("peak force (kN) at (ms): of the 1 ms mean; of the samples",
             lambda s: f"{s['peak_mean_force']:.2f} at {s['peak_mean_time']:.2f}; {s['peak_force']:.2f} at {s['peak_time']:.2f}"),
            ("contact impulse / door mass x velocity change (kN ms)",
             lambda s: f"{s['impulse']:.1f} / {s['door_mass'] * s['door_dv']:.1f}"),
            ("smallest V/V0 of an FE foam solid (element), end",
             lambda s: "-" if np.isnan(s["min_volume"]) else f"{s['min_volume']:.3f} ({s['min_volume_element']})"),
            ("worst corner Jacobian ratio, FE foam (element), end",
             lambda s: "-" if np.isnan(s["min_jacobian"]) else f"{s['min_jacobian']:.2f} ({s['min_jacobian_element']})"),
            ("worst corner Jacobian ratio over the run (solver)", lambda s: f"{s['worst_jacobian_run']:.2f}"),
            ("smallest jacket shell area A/A0, end", lambda s: f"{s['min_jacket_area']:.3f}"),
            ("seconds (/timing): FE solids / FE shells / meshfree solids / meshfree shells / contact / other",
             lambda s: " / ".join(f"{s['phases'][k]:.1f}" for k in ("FE solids", "FE shells", "meshfree solids",
                                                                      "meshfree shells", "contact"))
             + f" / {s['phases']['other'] + s['phases']['output']:.1f}"),
            ("phase seconds: internal forces (not in a group timer) / contact / wall",
             lambda s: f"{s['phase_internal']:.1f} ({s['phase_internal_untimed']:.1f}) / {s['phase_contact']:.1f} / "
                       f"{s['wall']:.1f}"),
            ("message", lambda s: s["message"] or "-")]
    lines = ["| | " + " | ".join(labels) + " |", "|---|" + "---|" * len(labels)]
    for name, value in rows:
        lines.append(f"| {name} | " + " | ".join(value(s).replace("|", "/") for s in summaries) + " |")
    if len(summaries) >= 2 and summaries[0]["cpu_per_ms"] > 0:
        fe = summaries[0]
        for s, label in zip(summaries[1:], labels[1:]):
            lines.append("")
            lines.append(f"CPU per simulated ms, {label} / {labels[0]}: **{s['cpu_per_ms'] / fe['cpu_per_ms']:.2f}** "
                         f"({s['cpu_source']} / {fe['cpu_source']}); the paper: 2.0 at 18.9% meshfree dofs.")
    return "\n".join(lines) + "\n"


def main(argv=None):
    parser = argparse.ArgumentParser(description="Side-impact dummy component test: force, sections, table")
    parser.add_argument("results", nargs="+", type=Path, help="results.h5 of the runs: FE, ribs_efg, coupled")
    parser.add_argument("--labels", nargs="+", help="a label per run (default: the run directories' names)")
    parser.add_argument("--door-mass", type=float, default=40.0, help="door mass (kg), for the momentum check")
    parser.add_argument("-o", "--output", type=Path, help="output directory")
    args = parser.parse_args(argv)
    paths = [p for p in args.results if p.is_file()]
    missing = [str(p) for p in args.results if not p.is_file()]
    if missing:
        print("left out (no results file): " + ", ".join(missing))
    if not paths:
        sys.exit("no results file to post-process")
    runs = [load_run(p) for p in paths]
    labels = args.labels[:len(paths)] if args.labels else [p.parent.name for p in paths]
    output = args.output or paths[-1].parent.parent
    output.mkdir(parents=True, exist_ok=True)
    summaries = [summarize(run) for run in runs]
    for s in summaries:
        s["door_mass"] = args.door_mass
    force_png, sections_png = output / "side_impact_force.png", output / "side_impact_sections.png"
    summary_md = output / "side_impact_summary.md"
    plot_force(runs, summaries, labels, force_png)
    plot_sections(runs, labels, sections_png)
    text = table(summaries, labels)
    summary_md.write_text("# Side-impact dummy component test\n\n" + text)
    print(text)
    print(f"force plot:     {force_png}\nsections:       {sections_png}\nsummary table:  {summary_md}")


if __name__ == "__main__":
    main()
