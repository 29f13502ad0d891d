"""Crush force against crush distance of the square-tube example (inputs/tube_crush), with the
mean crush force compared to the classical estimates for square tubes.

    python3 postproc/tube_crush.py results/tube_crush/results.h5 -o results/tube_crush

The crush distance is the moving wall's travel, integrated from its force history: the wall
(mass M, initial speed V0, from the deck generator's defaults or the options) slows down by the
impulse the tube gives it. The mean crush force is the absorbed energy over the crush distance.

Estimates for a square tube of side C (mid-surface) and wall t with flow stress s0 (Wierzbicki
& Abramowicz 1983, symmetric folding; Abramowicz & Jones 1984, Int. J. Impact Eng. 2, 179-208,
with the effective crushing distance 0.73 of the fold length):
    P_m = 9.56 s0 t^(5/3) C^(1/3)           (rigid-plastic, full fold length)
    P_m = 13.06 s0 t^(5/3) C^(1/3)          (effective crushing distance 0.73)
The flow stress of a hardening material is taken as the mean of its yield curve over plastic
strains 0 to 0.3 (the strains in the folds' hinges), given with --flow-stress.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import crashfree_results as cr


def crush_curve(results, wall_id: str, mass: float, speed: float):
    """Time, crush distance and force on the moving wall."""
    history = cr.read_history(results, f"rwforc/{wall_id}")
    time = np.asarray(history["time"])
    force = np.abs(np.asarray(history["force"])[:, 2])
    # force values are averages over the interval ending at each sample
    step = np.diff(np.concatenate([[0.0], time]))
    velocity = speed - np.cumsum(force * step) / mass
    distance = np.cumsum(np.concatenate([[0.0], 0.5 * (velocity[1:] + velocity[:-1]) * np.diff(time)]))
    distance += time[0] * speed
    return time, distance, force


def estimates(flow_stress: float, side: float, thickness: float):
    base = flow_stress * thickness ** (5.0 / 3.0) * side ** (1.0 / 3.0)
    return {"Wierzbicki-Abramowicz (9.56)": 9.56 * base, "Abramowicz-Jones, 0.73 crush distance (13.06)": 13.06 * base}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("results")
    parser.add_argument("-o", "--output", default=".")
    parser.add_argument("--wall", default="2", help="id of the moving wall (default 2)")
    parser.add_argument("--wall-mass", type=float, default=500.0, help="kg (default 500)")
    parser.add_argument("--speed", type=float, default=10.0, help="initial wall speed, mm/ms (default 10)")
    parser.add_argument("--side", type=float, default=50.0, help="section width C, mm")
    parser.add_argument("--thickness", type=float, default=1.5, help="wall t, mm")
    parser.add_argument("--flow-stress", type=float, default=0.361,
                        help="GPa; default: mean of the example's yield curve over plastic strain 0-0.3")
    args = parser.parse_args()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    output = Path(args.output)
    output.mkdir(parents=True, exist_ok=True)
    with cr.open_results(args.results) as results:
        time, distance, force = crush_curve(results, args.wall, args.wall_mass, args.speed)
        glstat = cr.read_history(results, "glstat")
        run = cr.read_run(results)
        timing = cr.read_timing(results)
    energy = np.sum(force[1:] * np.diff(distance))
    mean_force = energy / distance[-1]
    # after the first fold has formed (the first 10 mm): the steady part of the crush
    steady = distance > 10.0
    steady_mean = np.sum(force[1:][steady[1:]] * np.diff(distance)[steady[1:]]) / (distance[-1] - 10.0)
    predictions = estimates(args.flow_stress, args.side, args.thickness)
    figure, axes = plt.subplots(figsize=(7, 4))
    axes.plot(distance, force, lw=0.8, label="crashfree: force on the moving wall")
    axes.axhline(mean_force, color="k", lw=1.2, label=f"mean crush force {mean_force:.1f} kN")
    for (name, value), style in zip(predictions.items(), ("--", ":")):
        axes.axhline(value, color="tab:red", ls=style, label=f"{name}: {value:.1f} kN")
    axes.set_xlabel("crush distance (mm)")
    axes.set_ylabel("force (kN)")
    axes.set_title(f"square tube {args.side:g} x {args.thickness:g} mm, axial crush")
    axes.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(output / "tube_crush_force.png", dpi=120)
    internal = glstat["internal_energy"][-1]
    lines = ["| quantity | value |", "|---|---|",
             f"| status | {run['status']} |",
             f"| crush distance | {distance[-1]:.1f} mm |",
             f"| absorbed energy (wall work) | {energy:.0f} J |",
             f"| mean crush force | {mean_force:.2f} kN |",
             f"| mean crush force after the first 10 mm | {steady_mean:.2f} kN |",
             f"| peak force | {force.max():.2f} kN |"]
    for name, value in predictions.items():
        lines.append(f"| {name} | {value:.2f} kN (ratio {mean_force / value:.2f}) |")
    lines += [f"| energy ratio | {cr.energy_ratio(glstat):.4f} |",
              f"| hourglass / internal energy | {glstat['hourglass_energy'][-1] / internal:.3f} |",
              f"| contact energy / internal energy | {glstat['contact_energy'][-1] / internal:.4f} |",
              f"| cycles, wall time | {timing['cycles']}, {timing['wall_s']:.0f} s on {timing['threads']} thread(s) |",
              f"| shells: ns per element per cycle | "
              f"{1e9 * timing['fe_shell_s'] / (timing['cycles'] * timing['fe_shells']):.0f} |"]
    (output / "tube_crush.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    print(f"\nplot: {output / 'tube_crush_force.png'}\ntable: {output / 'tube_crush.md'}")


if __name__ == "__main__":
    main()
