"""The vehicle front-structure example (inputs/vehicle_front), coarse mesh (4,136 shells), its
first 3 ms at 15 m/s into the rigid wall: the bumper, 5 mm from the wall, reaches it at
5 / 15 = 0.333 ms and is crushed for the rest of the run.

Checks:
- normal termination, energy ratio within 1 % of 1, hourglass energy below 10 % of the
  internal energy;
- the first barrier force at the time the gap closes (0.333 ms, within one output interval);
- the barrier's impulse on the structure equals the change of the structure's momentum
  (the wall is the only external force), within 1e-6 relative;
- the rear mass (the rigid body carrying the rest of the car) only slows down once the
  bumper touches the wall: its speed never rises by more than 0.1 % of the initial speed
  from one output sample to the next, and it has lost speed by the end;
- the momentum lost by the structure is at most the largest 1 ms mean barrier force times the
  contact time (a bound that catches a runaway force);
- the crush (the rear mass's travel after contact) lies between the end speed and the initial
  speed times the contact time.
"""
import subprocess
import sys
from pathlib import Path

import numpy as np

REPOSITORY = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPOSITORY / "postproc"))
from vehicle_front import summary  # noqa: E402

SPEED = 15.0      # mm/ms
GAP = 5.0         # mm, bumper front to the wall
END_TIME = 3.0    # ms


def test_coarse_vehicle_front(tmp_path, run_deck):
    deck = tmp_path / "vehicle.k"
    subprocess.run([sys.executable, str(REPOSITORY / "inputs" / "vehicle_front" / "generate_vehicle.py"),
                    "--size", "coarse", "--end-time", str(END_TIME), "--output", str(deck)],
                   check=True, capture_output=True)
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        assert results["run"].attrs["status"] == "normal termination"
        # /timing splits the time loop by the phases of the cycle; the contact's time is the
        # contact and wall phases' (bookkeeping, not a speed check)
        timing = results["timing"].attrs
        phases = {name: timing[name] for name in timing if name.startswith("phase_")}
        assert len(phases) == 13 and min(phases.values()) >= 0.0
        assert timing["contact_s"] == phases["phase_contact_s"] + phases["phase_walls_s"]
        figures = summary(results, "1", "200", GAP)
        total_mass = float(np.asarray(results["history/glstat/momentum"])[0, 0]) / -SPEED
    assert abs(figures["energy_ratio"] - 1.0) < 0.01, figures["energy_ratio"]
    assert figures["hourglass_ratio"] < 0.10, figures["hourglass_ratio"]
    assert abs(total_mass - 800.0) < 1e-6 * 800.0, total_mass
    interval = END_TIME / 800
    assert abs(figures["first_contact"] - GAP / SPEED) <= interval + 1e-9, figures["first_contact"]
    assert figures["momentum_change"] > 0.0
    assert abs(figures["wall_impulse"] - figures["momentum_change"]) <= 1e-6 * figures["momentum_change"], \
        (figures["wall_impulse"], figures["momentum_change"])
    speed = -figures["velocity"]
    in_contact = figures["mass_time"] >= figures["first_contact"]
    rises = np.diff(speed[in_contact])
    assert rises.max() <= 1e-3 * SPEED, rises.max()
    assert speed[-1] < SPEED - 0.05, speed[-1]
    bound = figures["peak_force_averaged"] * (END_TIME - figures["first_contact"])
    assert figures["momentum_change"] <= bound, (figures["momentum_change"], bound)
    # with the speed falling from SPEED to speed[-1], the travel after contact (the crush) lies
    # between the two speeds times the contact time (one glstat interval of slack)
    contact_time = END_TIME - GAP / SPEED
    slack = SPEED * END_TIME / 400
    assert speed[-1] * contact_time - slack <= figures["crush_end"] <= SPEED * contact_time + slack, \
        figures["crush_end"]
    # the plotting script's command line: three PNG files and the table
    output = tmp_path / "post"
    process = subprocess.run([sys.executable, str(REPOSITORY / "postproc" / "vehicle_front.py"), str(run.results),
                              "-o", str(output)], capture_output=True, text=True)
    assert process.returncode == 0, process.stderr
    for name in ("vehicle_force.png", "vehicle_rear_mass.png", "vehicle_energies.png"):
        assert (output / name).stat().st_size > 1000, name
    assert "| barrier impulse on the structure |" in (output / "vehicle_front.md").read_text()
