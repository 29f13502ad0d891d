"""Wall force, rear-mass velocity and energies of the vehicle front-structure example
(inputs/vehicle_front), as PNG plots and a Markdown table.

    python3 postproc/vehicle_front.py results/vehicle_front/results.h5 -o results/vehicle_front

Reads `/history/rwforc/<wall>` (the force the barrier exerts on the structure, LS-DYNA's sign, averaged over each
output interval), `/history/rbdout/<body>` (the rear mass: the nodal rigid body that carries the
lumped mass of the rest of the car), `/history/glstat` (energies, momentum) and `/timing`.

Figures in the table:
- peak wall force: the largest sample, and the largest 1 ms moving average (the first contact
  of a flat bumper face gives a spike of a few microseconds that says little about the crash);
- crush: the rear mass's travel after the bumper reached the barrier (its displacement less the
  initial gap), its largest value (dynamic crush, the intrusion of the barrier into the car) and
  its value at the end;
- impulse check: the barrier's impulse on the structure against the change of the structure's
  momentum (glstat momentum): with no other external force they are equal;
- energy balance: LS-DYNA's energy ratio, total / (initial total + external work), and the
  hourglass and contact energies against the internal energy.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import crashfree_results as cr

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "inputs" / "vehicle_front"))
from generate_vehicle import PARTS  # noqa: E402  (the part names of the example)


def wall_history(results, wall: str = "1"):
    """Time (ms) and the barrier's force on the structure (kN, (t,3)), as rwforc holds it."""
    history = cr.read_history(results, f"rwforc/{wall}")
    return np.asarray(history["time"]), np.asarray(history["force"])


def impulse(time: np.ndarray, force: np.ndarray) -> np.ndarray:
    """Impulse of an interval-averaged force history: each sample is the mean force over the
    interval ending at its time, so the sum of force x interval is exact."""
    step = np.diff(np.concatenate([[0.0], time]))
    return (force * step[:, None]).sum(axis=0)


def moving_average(time: np.ndarray, values: np.ndarray, window: float) -> np.ndarray:
    """Mean of the samples within the last `window` of each time (interval-weighted)."""
    step = np.diff(np.concatenate([[0.0], time]))
    cumulative = np.concatenate([[0.0], np.cumsum(values * step)])
    start = np.searchsorted(time, time - window, side="left")
    span = time - np.concatenate([[0.0], time])[start]
    return np.where(span > 0, (cumulative[1:] - cumulative[start]) / np.where(span > 0, span, 1.0), values)


def rear_mass(results, body: str = "200"):
    """Time, x velocity and x displacement of the rear mass (rbdout of its rigid body)."""
    history = cr.read_history(results, f"rbdout/{body}")
    return (np.asarray(history["time"]), np.asarray(history["velocity"])[:, 0],
            np.asarray(history["displacement"])[:, 0])


def summary(results, wall: str = "1", body: str = "200", gap: float = 5.0) -> dict:
    """The figures of the table, as numbers."""
    time, force = wall_history(results, wall)
    glstat = cr.read_history(results, "glstat")
    momentum = np.asarray(glstat["momentum"])
    mass_time, velocity, displacement = rear_mass(results, body)
    crush = np.maximum(-displacement - gap, 0.0)
    force_x = force[:, 0]
    averaged = moving_average(time, force_x, 1.0)
    wall_impulse = impulse(time, force)[0]
    momentum_change = momentum[-1, 0] - momentum[0, 0]
    internal = glstat["internal_energy"][-1]
    contact = np.nonzero(np.abs(force_x) > 0.0)[0]
    parts = {}
    for part in cr.list_history_groups(results):
        if part.startswith("matsum/"):
            history = cr.read_history(results, part)
            parts[int(part.split("/")[1])] = float(np.asarray(history["internal_energy"])[-1])
    return {
        "part_internal_energy": dict(sorted(parts.items())),
        "time": time, "force": force_x, "force_averaged": averaged,
        "mass_time": mass_time, "velocity": velocity, "crush": crush, "glstat": glstat,
        "end_time": float(time[-1]),
        "first_contact": float(time[contact[0]]) if contact.size else float("nan"),
        "peak_force": float(force_x.max()), "peak_force_time": float(time[np.argmax(force_x)]),
        "peak_force_averaged": float(averaged.max()),
        "crush_max": float(crush.max()), "crush_end": float(crush[-1]),
        "velocity_start": float(velocity[0]), "velocity_end": float(velocity[-1]),
        "wall_impulse": float(wall_impulse), "momentum_change": float(momentum_change),
        "energy_ratio": float(cr.energy_ratio(glstat)),
        "hourglass_ratio": float(glstat["hourglass_energy"][-1] / internal) if internal > 0 else 0.0,
        "contact_ratio": float(glstat["contact_energy"][-1] / internal) if internal > 0 else 0.0,
        "internal_energy": float(internal),
        "kinetic_start": float(glstat["kinetic_energy"][0]), "kinetic_end": float(glstat["kinetic_energy"][-1]),
    }


def table(figures: dict, run: dict, timing: dict) -> list:
    difference = figures["wall_impulse"] - figures["momentum_change"]
    lines = ["| quantity | value |", "|---|---|",
             f"| status | {run['status']} |",
             f"| end time | {figures['end_time']:.2f} ms |",
             f"| first barrier force | {figures['first_contact']:.3f} ms |",
             f"| peak barrier force (sample) | {figures['peak_force']:.0f} kN at {figures['peak_force_time']:.3f} ms |",
             f"| peak barrier force (1 ms average) | {figures['peak_force_averaged']:.0f} kN |",
             f"| rear-mass velocity, start -> end | {figures['velocity_start']:.3f} -> {figures['velocity_end']:.3f} m/s |",
             f"| crush (intrusion): largest, at the end | {figures['crush_max']:.1f} mm, {figures['crush_end']:.1f} mm |",
             f"| barrier impulse on the structure | {figures['wall_impulse']:.2f} N s |",
             f"| change of the structure's momentum | {figures['momentum_change']:.2f} N s |",
             f"| impulse - momentum change | {difference:.3g} N s "
             f"({abs(difference) / max(abs(figures['momentum_change']), 1e-30):.2e} relative) |",
             f"| kinetic energy, start -> end | {figures['kinetic_start']:.0f} -> {figures['kinetic_end']:.0f} J |",
             f"| internal energy at the end | {figures['internal_energy']:.0f} J |",
             f"| energy ratio | {figures['energy_ratio']:.4f} |",
             f"| hourglass / internal energy | {figures['hourglass_ratio']:.3f} |",
             f"| contact / internal energy | {figures['contact_ratio']:.4f} |"]
    absorbed = figures["part_internal_energy"]
    total = sum(absorbed.values())
    for part, energy in absorbed.items():
        name = PARTS.get(part, (f"part {part}",))[0]
        lines.append(f"| internal energy of {name} (part {part}) | {energy:.0f} J "
                     f"({100 * energy / total if total > 0 else 0:.1f}%) |")
    if timing:
        shells = timing.get("fe_shells", 0)
        cycles = timing["cycles"]
        lines += [f"| cycles, wall time | {cycles}, {timing['wall_s']:.0f} s on {timing['threads']} thread(s) |"]
        if shells:
            per = 1e9 / (shells * cycles)
            lines += [f"| ns per shell per cycle: shells, contact | "
                      f"{timing['fe_shell_s'] * per:.0f}, {timing['contact_s'] * per:.0f} |"]
    return lines


def plot(figures: dict, output: Path) -> list:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    paths = []
    figure, axes = plt.subplots(figsize=(7, 4))
    axes.plot(figures["time"], figures["force"], lw=0.6, color="0.6", label="barrier force (output samples)")
    axes.plot(figures["time"], figures["force_averaged"], lw=1.4, label="1 ms moving average")
    axes.set_xlabel("time (ms)")
    axes.set_ylabel("force (kN)")
    axes.set_title("barrier force on the structure")
    peak = figures["peak_force_averaged"]
    axes.set_ylim(0.0, 1.5 * peak if peak > 0 else 1.0)
    axes.legend(fontsize=8)
    figure.tight_layout()
    paths.append(output / "vehicle_force.png")
    figure.savefig(paths[-1], dpi=120)
    plt.close(figure)

    figure, axes = plt.subplots(figsize=(7, 4))
    axes.plot(figures["mass_time"], -figures["velocity"], label="rear mass speed (m/s)")
    axes.set_xlabel("time (ms)")
    axes.set_ylabel("speed towards the barrier (m/s)")
    twin = axes.twinx()
    twin.plot(figures["mass_time"], figures["crush"], color="tab:red", label="crush (mm)")
    twin.set_ylabel("crush (mm)", color="tab:red")
    axes.set_title("rear mass: speed and crush")
    figure.tight_layout()
    paths.append(output / "vehicle_rear_mass.png")
    figure.savefig(paths[-1], dpi=120)
    plt.close(figure)

    glstat = figures["glstat"]
    figure, axes = plt.subplots(figsize=(7, 4))
    for name in ("kinetic_energy", "internal_energy", "hourglass_energy", "contact_energy",
                 "rigid_wall_energy", "external_work", "total_energy"):
        if name in glstat:
            axes.plot(glstat["time"], np.asarray(glstat[name]) / 1e3, label=name.replace("_", " "))
    axes.set_xlabel("time (ms)")
    axes.set_ylabel("energy (kJ)")
    axes.set_title(f"energies (energy ratio at the end {figures['energy_ratio']:.4f})")
    axes.legend(fontsize=8)
    figure.tight_layout()
    paths.append(output / "vehicle_energies.png")
    figure.savefig(paths[-1], dpi=120)
    plt.close(figure)
    return paths


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("results")
    parser.add_argument("-o", "--output", default=".")
    parser.add_argument("--wall", default="1", help="id of the barrier (default 1)")
    parser.add_argument("--body", default="200", help="rigid body of the rear mass (default 200)")
    parser.add_argument("--gap", type=float, default=5.0, help="initial gap bumper-barrier, mm (default 5)")
    args = parser.parse_args()
    output = Path(args.output)
    output.mkdir(parents=True, exist_ok=True)
    with cr.open_results(args.results) as results:
        figures = summary(results, args.wall, args.body, args.gap)
        run = cr.read_run(results)
        timing = cr.read_timing(results) if "timing" in results else {}
    lines = table(figures, run, timing)
    paths = plot(figures, output)
    (output / "vehicle_front.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    print("\nplots: " + ", ".join(str(path) for path in paths) + f"\ntable: {output / 'vehicle_front.md'}")


if __name__ == "__main__":
    main()
