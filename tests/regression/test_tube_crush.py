"""The square-tube example (inputs/tube_crush), reduced to 5 mm shells and 15 mm of crush so
that it runs in seconds: Belytschko-Tsay shells with MAT_024 folding under a moving rigid wall,
with single-surface contact.

Checks: normal termination with the energy balanced (ratio within 1%), hourglass energy below
10% of the internal energy, contact energy never below -1% of the internal energy (the penalty
springs store energy, they must not create it), and the mean force on the moving wall within
a band around the classical mean crush force of a square tube: the Abramowicz-Jones estimate
13.06 s0 t^(5/3) C^(1/3) = 34.1 kN for C = 50, t = 1.5 mm and the flow stress s0 = 0.361 GPa
(mean of the yield curve over plastic strains 0-0.3). The first 15 mm hold the first fold,
whose peak exceeds the mean: the band is 0.6 to 1.6 times the estimate.
"""
import subprocess
import sys
from pathlib import Path

import numpy as np

REPOSITORY = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPOSITORY / "postproc"))
from tube_crush import crush_curve, estimates  # noqa: E402


def test_coarse_tube_crush(tmp_path, run_deck):
    deck = tmp_path / "tube.k"
    subprocess.run([sys.executable, str(REPOSITORY / "inputs" / "tube_crush" / "generate_tube.py"),
                    "--element", "5", "--crush", "15", "--output", str(deck)], check=True, capture_output=True)
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        glstat = {name: results["history/glstat"][name][...] for name in results["history/glstat"]}
        time, distance, force = crush_curve(results, "2", 500.0, 10.0)
    ratio = glstat["total_energy"][-1] / (glstat["total_energy"][0] + glstat["external_work"][-1])
    assert abs(ratio - 1.0) < 0.01, ratio
    internal = glstat["internal_energy"]
    assert glstat["hourglass_energy"][-1] < 0.10 * internal[-1]
    assert glstat["contact_energy"].min() > -0.01 * internal[-1]
    mean_force = np.sum(force[1:] * np.diff(distance)) / distance[-1]
    reference = estimates(0.361, 50.0, 1.5)["Abramowicz-Jones, 0.73 crush distance (13.06)"]
    assert 0.6 * reference < mean_force < 1.6 * reference, (mean_force, reference)
    assert abs(distance[-1] - 15.0) < 1.0
