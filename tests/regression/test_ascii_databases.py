"""LS-DYNA's ASCII databases (glstat, matsum, nodout, rwforc, rcforc), d3hsp and messag
(docs/output.md, "LS-DYNA's ASCII files").

A small reader here parses each file at LS-DYNA's fixed column positions (as LS-DYNA and its
binout-to-ASCII translator write them); its values equal results.h5's to the printed
precision. Physics: matsum's momentum of each part is sum m v of its nodes (the part's mass
times its velocity for a block moving as a whole), a rigid part's rigid-body velocity is its
velocity; rwforc has LS-DYNA's sign (a block moving in -x into a wall gets a force in +x) and
its time integral is the block's momentum change; rcforc's two sides are opposite. messag has
the warnings with file:line, d3hsp the parts and masses and the deck as read; BINARY=2 writes no
ASCII file.
"""
import os
import re
import subprocess

import numpy as np
import pytest

from deck_writer import block_mesh, fields, nodes_card, shells_card, solids_card, write_deck
from test_contact import LENGTH, head_on_deck, nodal_masses

DENSITY = 7.85e-6        # kg/mm^3
SPEED = 50.0             # mm/ms
BLOCK = (6.0, 5.0, 4.0)  # mm
RIGID_SPEED = (-SPEED, 3.0, 0.0)


def wall_deck(path, binary="", extra=""):
    """A deformable block moving in -x into a planar wall at x = 0 (normal +x), and a rigid
    block far behind it that never reaches the wall."""
    block_nodes, block_elements = block_mesh((3, 2, 2), BLOCK, origin=(0.2, 0.0, 0.0))
    rigid_nodes, rigid_elements = block_mesh((1, 1, 1), (2.0, 2.0, 2.0), origin=(40.0, 0.0, 0.0))
    count = len(block_nodes)
    return write_deck(
        path,
        "*TITLE\nblock into a wall, ascii databases",
        "*CONTROL_TERMINATION\n" + fields(0.1),
        "*DATABASE_GLSTAT\n" + fields(0.002, binary),
        "*DATABASE_MATSUM\n" + fields(0.002, binary),
        "*DATABASE_RWFORC\n" + fields(0.001, binary),
        "*DATABASE_NODOUT\n" + fields(0.005, binary),
        "*DATABASE_HISTORY_NODE\n" + fields(1, count, count + 1),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.05),
        "*DATABASE_SECFORC\n" + fields(0.001),
        "*PART\nblock\n" + fields(1, 1, 1),
        "*PART\nrigid block\n" + fields(2, 1, 2),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_PLASTIC_KINEMATIC\n" + fields(1, DENSITY, 200.0, 0.3, 0.4, 1.0, 1.0) + "\n" + fields(0.0, 0.0),
        "*MAT_RIGID\n" + fields(2, DENSITY, 200.0, 0.3) + "\n" + fields(0.0, 0.0, 0.0),
        "*SET_NODE_LIST\n" + fields(1) + "\n" + "\n".join(
            fields(*range(first, min(first + 8, count + 1))) for first in range(1, count + 1, 8)),
        "*SET_NODE_LIST\n" + fields(2) + "\n" + "\n".join(
            fields(*range(first, min(first + 8, count + 9))) for first in range(count + 1, count + 9, 8)),
        "*INITIAL_VELOCITY\n" + fields(1) + "\n" + fields(-SPEED, 0.0, 0.0),
        "*INITIAL_VELOCITY\n" + fields(2) + "\n" + fields(*RIGID_SPEED),
        "*RIGIDWALL_PLANAR_ID\n" + fields(7) + "wall\n" + fields(0) + "\n" + fields(0.0, 0.0, 0.0, 1.0, 0.0, 0.0),
        extra,
        nodes_card(np.vstack([block_nodes, rigid_nodes])),
        solids_card(block_elements, part_id=1) + "\n" +
        "\n".join(solids_card(rigid_elements, part_id=2, first_id=len(block_elements) + 1,
                              first_node_id=count + 1).splitlines()[1:]),
    )


def number(text):
    return float(text.replace("D", "E"))


def close(printed, exact, digits):
    """A value printed with `digits` digits after the point of %E equals the exact one."""
    return abs(printed - exact) <= 0.51 * 10.0 ** (-digits) * abs(exact) + 1e-300


# ------------------------------------------------------------------ readers at fixed columns

def read_glstat(path):
    """[{label: value}] per sample; labels are columns 1-32 with the dots, values 33-46."""
    samples = []
    for line in path.read_text().splitlines():
        if line.startswith(" dt of cycle"):
            samples.append({"cycle": int(line[12:20])})
        elif samples and len(line) >= 46 and line[1:32].rstrip(".").strip():
            label = line[:32].rstrip(".").strip()
            samples[-1][label] = number(line[32:46])
    return samples


def read_matsum(path):
    """[(time, {part: {name: value}})]: " time =" then four lines per part."""
    samples, part = [], None
    for line in path.read_text().splitlines():
        if line.startswith(" time ="):
            samples.append((number(line[7:20]), {}))
        elif line.startswith(" mat.#="):
            part = int(line[7:15])
            samples[-1][1][part] = {"inten": number(line[31:44]), "kinen": number(line[55:68])}
        elif line.startswith(" x-mom=") or line.startswith(" x-rbv="):
            kind = line[3:6]
            samples[-1][1][part].update({"x" + kind: number(line[7:20]), "y" + kind: number(line[31:44]),
                                         "z" + kind: number(line[55:68])})
        elif line.startswith("                         hgeng="):
            samples[-1][1][part].update({"hgeng": number(line[31:44]), "mass": number(line[55:68])})
    return samples


def read_rwforc(path):
    """Rows (time, wall, normal, x, y, z) after the column header."""
    lines = path.read_text().splitlines()
    start = next(k for k, line in enumerate(lines) if line.startswith("    time       wall#")) + 1
    return [(number(line[0:12]), int(line[12:20]), number(line[20:35]), number(line[35:50]),
             number(line[50:65]), number(line[65:80])) for line in lines[start:] if line.strip()]


def read_nodout(path):
    """[(cycle, time, {node: 12 values})]: displacement, velocity, acceleration, coordinates."""
    samples = []
    for line in path.read_text().splitlines():
        if line.startswith(" n o d a l   p r i n t   o u t"):
            samples.append((int(line[58:66]), number(line[104:116]), {}))
        elif samples and len(line) >= 154 and line[:9].strip().isdigit():
            fields_at = [(9, 22)] + [(22 + 12 * k, 34 + 12 * k) for k in range(11)]
            samples[-1][2][int(line[:9])] = [number(line[a:b]) for a, b in fields_at]
    return samples


def read_rcforc(path):
    """Rows (side, contact, time, x, y, z, mass)."""
    rows = []
    for line in path.read_text().splitlines():
        if line.startswith("  slave ") or line.startswith("  master"):
            rows.append((line[2:8].strip(), int(line[8:19]), number(line[24:36]), number(line[40:52]),
                         number(line[56:68]), number(line[72:84]), number(line[90:102])))
    return rows


# ------------------------------------------------------------------ tests

def test_ascii_files_equal_results_and_physics(tmp_path, run_deck):
    run = run_deck(wall_deck(tmp_path / "wall.k"))
    assert run.status == 0, run.stdout + run.stderr
    out = run.results.parent
    with run.open() as results:
        glstat = {key: results["history/glstat"][key][...] for key in results["history/glstat"]}
        matsum = {part: {key: results[f"history/matsum/{part}"][key][...]
                         for key in results[f"history/matsum/{part}"]} for part in (1, 2)}
        wall = {key: results["history/rwforc/7"][key][...] for key in results["history/rwforc/7"]}
        nodout = {node: {key: results[f"history/nodout/{node}"][key][...]
                         for key in results[f"history/nodout/{node}"]} for node in (1,)}
        warnings = [w.decode() for w in results["run/warnings"][...]]
        coordinates = results["mesh/nodes/coordinates"][...]
        node_ids = list(results["mesh/nodes/ids"][...])

    # glstat: every sample, every line, to the printed precision
    samples = read_glstat(out / "glstat")
    assert len(samples) == len(glstat["time"])
    names = {"time": "time", "time step": "time_step", "kinetic energy": "kinetic_energy",
             "internal energy": "internal_energy", "hourglass energy": "hourglass_energy",
             "sliding interface energy": "contact_energy", "external work": "external_work",
             "total energy": "total_energy", "total energy / initial energy": "energy_ratio",
             "energy ratio w/o eroded energy": "energy_ratio_without_eroded", "stonewall energy": "rigid_wall_energy",
             "added mass": "added_mass", "percentage increase": "percent_mass_increase"}
    for k, sample in enumerate(samples):
        assert sample["cycle"] == glstat["cycle"][k]
        for label, key in names.items():
            assert close(sample[label], glstat[key][k], 5), (k, label, sample[label], glstat[key][k])
        for axis, name in enumerate("xyz"):
            assert close(sample[f"global {name} velocity"], glstat["global_velocity"][k][axis], 5)
    # the way users' scripts commonly read glstat (label, dots, last word): the same values
    loose = [dict() for _ in samples]
    block = -1
    for line in (out / "glstat").read_text().splitlines():
        if re.match(r"\s*dt of cycle\s+\d+", line):
            block += 1
        match = re.match(r"\s*(.+?)\s*\.{3,}\s*(\S+)\s*$", line)
        if match and block >= 0:
            loose[block][match.group(1).strip()] = float(match.group(2))
    # (LS-DYNA's two labels with fewer than three dots, the energy ratios, escape such scripts)
    assert all(set(loose[k]) >= set(names) - {"total energy / initial energy", "energy ratio w/o eroded energy"}
               for k in range(len(samples)))
    assert all(loose[k][label] == samples[k][label] for k in range(len(samples)) for label in loose[k])
    # global velocity is the momentum over the mass; at t = 0 the mass-weighted initial speeds
    block_mass = DENSITY * np.prod(BLOCK)
    rigid_mass = DENSITY * 8.0
    expected = (block_mass * np.array([-SPEED, 0.0, 0.0]) + rigid_mass * np.array(RIGID_SPEED)) / (block_mass + rigid_mass)
    assert np.allclose(glstat["global_velocity"][0], expected, rtol=1e-12, atol=1e-12)

    # matsum: momentum = sum m v (part 1 at t = 0: its mass times -SPEED), the rigid part's
    # rigid-body velocity is its velocity (no force acts on it), the deformable part's is 0
    assert np.isclose(matsum[1]["mass"][0], block_mass, rtol=1e-12)
    assert np.allclose(matsum[1]["momentum"][0], [-SPEED * block_mass, 0.0, 0.0], rtol=1e-12, atol=1e-15)
    assert np.allclose(matsum[2]["rigid_body_velocity"], np.array(RIGID_SPEED)[None, :], rtol=1e-12)
    assert np.allclose(matsum[2]["momentum"], rigid_mass * np.array(RIGID_SPEED)[None, :], rtol=1e-10)
    assert np.all(matsum[1]["rigid_body_velocity"] == 0.0)
    # the parts' momenta add up to glstat's
    assert np.allclose(matsum[1]["momentum"] + matsum[2]["momentum"], glstat["momentum"],
                       rtol=1e-10, atol=1e-12 * block_mass * SPEED)
    parsed = read_matsum(out / "matsum")
    assert len(parsed) == len(matsum[1]["time"])
    for k, (time, parts) in enumerate(parsed):
        assert close(time, matsum[1]["time"][k], 4)
        for part in (1, 2):
            values, exact = parts[part], matsum[part]
            assert close(values["inten"], exact["internal_energy"][k], 4)
            assert close(values["kinen"], exact["kinetic_energy"][k], 4)
            assert close(values["hgeng"], exact["hourglass_energy"][k], 4)
            assert close(values["mass"], exact["mass"][k], 4)
            for axis, name in enumerate("xyz"):
                assert close(values[name + "mom"], exact["momentum"][k][axis], 4)
                assert close(values[name + "rbv"], exact["rigid_body_velocity"][k][axis], 4)

    # rwforc: LS-DYNA's sign (the wall pushes the block in +x), normal force = x force here;
    # the impulse (forces are interval averages) is the block's momentum change
    rows = read_rwforc(out / "rwforc")
    assert len(rows) == len(wall["time"])
    for k, (time, wall_id, normal, fx, fy, fz) in enumerate(rows):
        assert wall_id == 7 and close(time, wall["time"][k], 5)
        assert close(normal, wall["normal_force"][k], 6)
        for axis, value in enumerate((fx, fy, fz)):
            assert close(value, wall["force"][k][axis], 6)
    force = wall["force"]
    assert force[:, 0].max() > 0.0 and force[:, 0].min() >= 0.0
    assert np.allclose(wall["normal_force"], force[:, 0], rtol=1e-14, atol=0.0)
    impulse = (force[1:] * np.diff(wall["time"])[:, None]).sum(axis=0)
    block_momentum_change = matsum[1]["momentum"][-1] - matsum[1]["momentum"][0]
    assert block_momentum_change[0] > 0.5 * SPEED * block_mass, "the wall must stop the block"
    print(f"wall impulse {impulse[0]:.6e}, block momentum change {block_momentum_change[0]:.6e}")
    assert abs(impulse[0] - block_momentum_change[0]) < 0.01 * abs(block_momentum_change[0])

    # nodout: node 1's displacement, velocity, acceleration and coordinates
    parsed = read_nodout(out / "nodout")
    assert len(parsed) == len(nodout[1]["time"])
    first = node_ids.index(1)
    for k, (cycle, time, nodes) in enumerate(parsed):
        assert cycle == nodout[1]["cycle"][k] and close(time, nodout[1]["time"][k], 5)
        values = nodes[1]
        exact = np.concatenate([nodout[1]["displacement"][k], nodout[1]["velocity"][k],
                                nodout[1]["acceleration"][k], coordinates[first] + nodout[1]["displacement"][k]])
        for printed, value in zip(values, exact):
            assert close(printed, value, 4), (k, printed, value)

    # messag and /run/warnings: the *DATABASE_SECFORC warning with its file:line
    messag = (out / "messag").read_text()
    line = next(k for k, text in enumerate((tmp_path / "wall.k").read_text().splitlines(), 1)
                if text.startswith("*DATABASE_SECFORC"))
    assert f"wall.k:{line}: *DATABASE_SECFORC" in messag
    assert any(f"wall.k:{line}: *DATABASE_SECFORC" in warning for warning in warnings)
    assert "N o r m a l    t e r m i n a t i o n" in messag

    # d3hsp: the parts with their masses (equal to matsum's), the total, the termination
    d3hsp = (out / "d3hsp").read_text()
    part_lines = {int(text.split()[0]): text for text in d3hsp.splitlines()
                  if text[:12].strip().isdigit() and "MAT_" in text}
    assert set(part_lines) == {1, 2}
    for part in (1, 2):
        mass = number(part_lines[part][104:118])
        assert close(mass, matsum[part]["mass"][0], 5), (part, mass)
    assert "MAT_PLASTIC_KINEMATIC" in part_lines[1] and "MAT_RIGID" in part_lines[2]
    assert "N o r m a l    t e r m i n a t i o n" in d3hsp
    # the smallest steps at cycle 0 (solids, the rigid body): TSSFAC (0.9) times the smallest
    # is the first step
    lines = d3hsp.splitlines()
    start = next(k for k, text in enumerate(lines) if "s m a l l e s t   t i m e   s t e p s   (by element kind, cycle 0)"
                 in text) + 3
    steps = []
    while lines[start].strip():
        steps.append(number(lines[start][0:17]))
        start += 1
    assert len(steps) == 2 and "rigid bodies" in lines[start - 1]
    assert abs(0.9 * min(steps) - glstat["time_step"][0]) <= 1e-5 * glstat["time_step"][0]
    # the input as read, as LS-DYNA's d3hsp echoes it: the deck's lines under its path
    echo = d3hsp.split("i n p u t   d e c k   a s   r e a d")[1]
    deck_text = (tmp_path / "wall.k").read_text()
    assert any(text.startswith(" ---- ") and text.endswith("wall.k") for text in echo.splitlines())
    assert deck_text.rstrip("\n") in echo


def test_contact_forces_both_sides(tmp_path, run_deck):
    deck, a_nodes, a_elements, _ = head_on_deck(tmp_path / "head_on.k")
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        history = {key: results["history/rcforc/5"][key][...] for key in results["history/rcforc/5"]}
    rows = read_rcforc(run.results.parent / "rcforc")
    slave = [row for row in rows if row[0] == "slave"]
    master = [row for row in rows if row[0] == "master"]
    assert len(slave) == len(master) == len(history["time"])
    for k, (s, m) in enumerate(zip(slave, master)):
        assert s[1] == m[1] == 5 and close(s[2], history["time"][k], 5)
        for axis in range(3):
            assert close(s[3 + axis], history["force"][k][axis], 5)
            assert close(m[3 + axis], history["surfb_force"][k][axis], 5)
    assert np.array_equal(history["surfb_force"], -history["force"])
    assert np.abs(history["force"][:, 0]).max() > 0.0
    # the mass in contact (LS-DYNA's rcforc mass): none before the blocks meet; pressed together
    # (identical meshes, face against face), each side's whole front face
    face_mass = nodal_masses(a_nodes, a_elements)[np.isclose(a_nodes[:, 0], LENGTH)].sum()
    for side, key in ((slave, "mass"), (master, "surfb_mass")):
        assert history[key][0] == 0.0
        assert abs(history[key].max() - face_mass) <= 1e-9 * face_mass, (key, history[key].max(), face_mass)
        assert all(close(row[6], history[key][k], 5) for k, row in enumerate(side))


def test_binary_two_writes_no_ascii_file_and_jobid_prefixes(tmp_path, run_deck):
    run = run_deck(wall_deck(tmp_path / "binout_only.k", binary=2))
    assert run.status == 0, run.stdout + run.stderr
    out = run.results.parent
    for name in ("glstat", "matsum", "rwforc", "nodout"):
        assert not (out / name).exists()
    with run.open() as results:
        assert len(results["history/glstat/time"]) > 10     # results.h5 keeps every history
    named = run_deck(wall_deck(tmp_path / "named.k", binary=3), jobid="crash")
    assert named.status == 0
    for name in ("glstat", "matsum", "rwforc", "nodout", "d3hsp", "messag"):
        assert (named.results.parent / f"crash.{name}").exists(), name
    bad = run_deck(wall_deck(tmp_path / "bad.k", binary=4))
    assert bad.status == 2
    card = next(k for k, text in enumerate((tmp_path / "bad.k").read_text().splitlines(), 1)
                if text.startswith("*DATABASE_GLSTAT")) + 1
    assert f"bad.k:{card}: *DATABASE_GLSTAT: field BINARY: must be 1 (ASCII file), 2 (binout) or 3 (both)" \
        in bad.stdout + bad.stderr


def test_log_of_both_streams_is_in_order(tmp_path):
    """stdout and stderr redirected to one file: the deck's warning comes before the model
    summary and the progress lines, as it happened."""
    from conftest import BINARY
    deck = wall_deck(tmp_path / "log.k")
    log = tmp_path / "log.txt"
    with log.open("w") as stream:
        status = subprocess.run([str(BINARY), f"i={deck}", f"outdir={tmp_path / 'out'}", "ncpu=1"],
                                stdout=stream, stderr=subprocess.STDOUT, timeout=300).returncode
    assert status == 0
    lines = log.read_text().splitlines()
    warning = next(k for k, text in enumerate(lines) if "*DATABASE_SECFORC" in text)
    summary = next(k for k, text in enumerate(lines) if text.startswith("model:"))
    progress = next(k for k, text in enumerate(lines) if text.strip().startswith("cycle"))
    assert lines[0].startswith("crashfree ") and 0 < warning < summary < progress


def peak_memory_of_run(deck, output):
    """Exit status and peak resident memory (kB) of one run of the solver on one thread, as
    GNU time measures it (a child of this process would count the test's own memory: Linux
    keeps the largest resident size of a process across exec)."""
    from conftest import BINARY
    command = ["/usr/bin/time", "-f", "peak %M", str(BINARY), f"i={deck}", f"outdir={output}", "ncpu=1"]
    process = subprocess.run(command, capture_output=True, text=True, env=dict(os.environ, OMP_NUM_THREADS="1"),
                             timeout=300)
    return process.returncode, int(process.stderr.splitlines()[-1].split()[-1])


def test_d3hsp_echoes_a_large_include_exactly_in_bounded_memory(tmp_path):
    """d3hsp echoes the deck file by file (a vehicle's deck is gigabytes) through a writer of
    bounded size: an include of 32 MiB (comment lines, the last without a new line) is in d3hsp
    byte for byte with a new line added, and the run's peak memory is that of the same deck with
    a one-line include within 16 MB (building d3hsp whole in memory took three times the
    include: 95 MB more)."""
    if not os.access("/usr/bin/time", os.X_OK):
        pytest.skip("GNU time (/usr/bin/time) measures the peak memory")
    line = "$ " + "padding " * 9 + "\n"
    padding = (line * (32 * 2**20 // len(line))).encode() + b"$ the last line, without a new line"
    (tmp_path / "large_padding.k").write_bytes(padding)
    (tmp_path / "small_padding.k").write_text("$ padding\n")
    peaks = {}
    for size in ("small", "large"):
        deck = wall_deck(tmp_path / f"{size}.k", extra=f"*INCLUDE\n{size}_padding.k")
        status, peaks[size] = peak_memory_of_run(deck, tmp_path / f"out_{size}")
        assert status == 0, size
    d3hsp = (tmp_path / "out_large" / "d3hsp").read_bytes()
    name = f" ---- {tmp_path / 'large_padding.k'}\n".encode()
    start = d3hsp.index(name, d3hsp.index(b"i n p u t   d e c k   a s   r e a d")) + len(name)
    assert d3hsp[start:start + len(padding) + 11] == padding + b"\n\n cycles: "
    assert d3hsp.endswith(b" N o r m a l    t e r m i n a t i o n\n")
    assert peaks["large"] - peaks["small"] < 16 * 1024, peaks


# ------------------------------------------------------------------ d3hsp: 100 smallest timesteps

SOLID_YOUNGS, SOLID_DENSITY, SOLID_SIZE = 210.0, 7.85e-6, 2.0                # steel cubes, nu = 0
SHELL_YOUNGS, SHELL_DENSITY, SHELL_POISSON = 70.0, 2.7e-6, 0.33              # aluminium plate
SHELL_WIDTHS, SHELL_HEIGHT = (1.2, 0.6, 1.0, 0.8), 1.5                       # columns, one row height
TIME_STEP_SCALE = 0.8


def time_step_deck(path):
    """A 3 x 3 x 3 block of steel cubes (nu = 0, where the eigenvalue bound of the exposed
    elements equals LS-DYNA's rule: every element's step is L / c, c = sqrt(E / rho)) and, far
    from it, an aluminium plate of 4 x 3 shells whose columns have the widths SHELL_WIDTHS and
    height 1.5 (L = area / longest side = the width; c = sqrt(E / (rho (1 - nu^2))))."""
    solid_nodes, solid_elements = block_mesh((3, 3, 3), (3 * SOLID_SIZE,) * 3)
    edges = np.concatenate([[0.0], np.cumsum(SHELL_WIDTHS)])
    rows = np.arange(4) * SHELL_HEIGHT
    plate_nodes = np.array([[x, y, 50.0] for x in edges for y in rows])
    shells = [[i * 4 + j, (i + 1) * 4 + j, (i + 1) * 4 + j + 1, i * 4 + j + 1]
              for i in range(len(SHELL_WIDTHS)) for j in range(3)]
    count = len(solid_nodes)
    deck = write_deck(
        path,
        "*TITLE\ntime steps by element",
        "*CONTROL_TERMINATION\n" + fields(0.002),
        "*CONTROL_TIMESTEP\n" + fields(0.0, TIME_STEP_SCALE),
        "*DATABASE_GLSTAT\n" + fields(0.001),
        "*PART\ncubes\n" + fields(1, 1, 1),
        "*PART\nplate\n" + fields(2, 2, 2),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*SECTION_SHELL\n" + fields(2, 2, 1.0, 2) + "\n" + fields(0.5, 0.5, 0.5, 0.5),
        "*MAT_ELASTIC\n" + fields(1, SOLID_DENSITY, SOLID_YOUNGS, 0.0),
        "*MAT_ELASTIC\n" + fields(2, SHELL_DENSITY, SHELL_YOUNGS, SHELL_POISSON),
        nodes_card(np.vstack([solid_nodes, plate_nodes])),
        solids_card(solid_elements, part_id=1, first_id=101),
        shells_card(np.array(shells), part_id=2, first_id=501, first_node_id=count + 1),
    )
    shell_speed = np.sqrt(SHELL_YOUNGS / (SHELL_DENSITY * (1.0 - SHELL_POISSON ** 2)))
    expected = [("shell", 501 + k, 2, SHELL_WIDTHS[k // 3] / shell_speed) for k in range(len(shells))]
    expected += [("solid", 101 + k, 1, SOLID_SIZE / np.sqrt(SOLID_YOUNGS / SOLID_DENSITY))
                 for k in range(len(solid_elements))]
    expected.sort(key=lambda row: row[3])
    return deck, expected


def read_smallest_time_steps(path):
    """d3hsp's table as LS-DYNA's readers take it: the rows start three lines below the line
    holding "100 smallest timesteps" (a rule and the column header between); each row is
    element type, number, part, time step, separated by blanks; the table ends at a blank line."""
    lines = path.read_text().splitlines()
    start = next(k for k, line in enumerate(lines) if " 100 smallest timesteps" in line) + 3
    rows = []
    for line in lines[start:]:
        if not line.strip():
            break
        words = line.split()
        rows.append((words[0], int(words[1]), int(words[-2]), float(words[-1])))
    return rows


def test_d3hsp_lists_the_smallest_element_time_steps(tmp_path, run_deck):
    deck, expected = time_step_deck(tmp_path / "time_steps.k")
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    rows = read_smallest_time_steps(run.results.parent / "d3hsp")
    # 12 shells + 27 solids: all of them, smallest first, each at its analytical step (the
    # order among analytically equal steps follows their last bits: compared as sets)
    assert len(rows) == len(expected) == 39
    assert all(rows[k][3] <= rows[k + 1][3] for k in range(len(rows) - 1))
    for step in sorted({row[3] for row in expected}):
        places = [k for k, row in enumerate(expected) if row[3] == step]
        assert {rows[k][:3] for k in places} == {expected[k][:3] for k in places}, step
        for k in places:
            assert abs(rows[k][3] - step) <= 1e-6 * step, (rows[k], step)
    # the smallest is the step the run started with, over TSSFAC
    with run.open() as results:
        first_step = results["history/glstat/time_step"][0]
    assert abs(rows[0][3] * TIME_STEP_SCALE - first_step) <= 1e-6 * first_step
    # glstat names the element that set the step: one of the smallest rows (a tie among the
    # shells of equal size), in results.h5 and on glstat's "dt of cycle" line
    smallest = {row[:3] for row in rows if abs(row[3] - rows[0][3]) <= 1e-12 * rows[0][3]}
    with run.open() as results:
        family = results["history/glstat/controlling_element_family"][0]
        element = int(results["history/glstat/controlling_element"][0])
        part = int(results["history/glstat/controlling_part"][0])
    assert family == 2 and ("shell", element, part) in smallest, (family, element, part, smallest)
    glstat = (run.results.parent / "glstat").read_text()
    assert f" dt of cycle       0 is controlled by shell     {element:10d} of part{part:10d}\n" in glstat


# ------------------------------------------------------------------ rbdout

RIGID_SIZE = 10.0                        # mm, one rigid cube
RIGID_ORIGIN = (5.0, -2.0, 1.0)
RIGID_VELOCITY = (1.0, 0.5, -0.3)        # mm/ms
RIGID_FORCE = (0.02, -0.01, 0.0)         # kN on the whole body (an eighth of it at each node)
NODAL_BODY_VELOCITY = (0.0, 0.0, 2.0)    # mm/ms, a free *CONSTRAINED_NODAL_RIGID_BODY


def rigid_body_deck(path, binary=""):
    """A rigid cube (part 4) with an initial velocity pushed by a constant force: its centre
    moves as x(t) = x0 + v0 t + F t^2 / (2 m); and far from it the eight nodes of an elastic
    cube as a free nodal rigid body 9 at a constant velocity."""
    nodes, elements = block_mesh((1, 1, 1), (RIGID_SIZE,) * 3, origin=RIGID_ORIGIN)
    free_nodes, free_elements = block_mesh((1, 1, 1), (RIGID_SIZE,) * 3, origin=(50.0, 0.0, 0.0))
    loads = "\n".join("*LOAD_NODE_SET\n" + fields(1, dof + 1, 1, RIGID_FORCE[dof] / 8.0)
                      for dof in range(3) if RIGID_FORCE[dof] != 0.0)
    return write_deck(
        path,
        "*TITLE\na pushed block",
        "*CONTROL_TERMINATION\n" + fields(1.0),
        "*DATABASE_GLSTAT\n" + fields(0.1),
        "*DATABASE_RBDOUT\n" + fields(0.1, binary),
        "*PART\nrigid cube\n" + fields(4, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_RIGID\n" + fields(1, DENSITY, 200.0, 0.3) + "\n" + fields(0.0, 0.0, 0.0),
        "*PART\nfree cube\n" + fields(5, 1, 2),
        "*MAT_ELASTIC\n" + fields(2, DENSITY, 200.0, 0.3),
        "*SET_NODE_LIST\n" + fields(3) + "\n" + fields(*range(9, 17)),
        "*CONSTRAINED_NODAL_RIGID_BODY\n" + fields(9, 0, 3),
        "*INITIAL_VELOCITY\n" + fields(3) + "\n" + fields(*NODAL_BODY_VELOCITY),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + fields(0.0, 1.0, width=20) + "\n" + fields(10.0, 1.0, width=20),
        "*SET_NODE_LIST\n" + fields(1) + "\n" + fields(*range(1, 9)),
        loads,
        "*INITIAL_VELOCITY\n" + fields(1) + "\n" + fields(*RIGID_VELOCITY),
        nodes_card(np.vstack([nodes, free_nodes])),
        solids_card(elements, part_id=4) + "\n" +
        solids_card(free_elements, part_id=5, first_id=2, first_node_id=9).split("\n", 1)[1],
    )


def read_rbdout(path):
    """[(cycle, time, {body: {label: values}})]: per sample the "r i g i d   b o d y" line
    (cycle in columns 50-57, time in 68-82), per body its id (columns 12-19 of " rigid body",
    18-25 of " nodal rigid body"),
    then lines of a label in columns 1-15 and values of 12 columns each from column 16; the
    local-axes block's labels get the prefix "local ", the direction vectors' rows "row N"."""
    samples, body, local = [], None, False
    for line in path.read_text().splitlines():
        if line.startswith("  r i g i d   b o d y   m o t i o n   a t  cycle="):
            samples.append((int(line[49:57]), number(line[67:82]), {}))
        elif line.startswith(" rigid body") or line.startswith(" nodal rigid body"):
            body, local = int(line[11:19]) if line.startswith(" rigid") else int(line[17:25]), False
            samples[-1][2][body] = {}
        elif line.startswith(" output in principal"):
            local = True
        elif body is not None and line[:15].strip().endswith(":") or line[:15].strip().startswith("row "):
            label = line[:15].strip().rstrip(":")
            values = [number(line[15 + 12 * k:27 + 12 * k]) for k in range((len(line) - 15) // 12)]
            samples[-1][2][body][("local " if local else "") + label] = np.array(values)
    return samples


def read_rbdout_by_offsets(path):
    """The 48 numbers of each body block as the public MATLAB reader lsdyna.read.rbdout
    (matlab-lsdyna) takes them: sscanf of a fixed format on the characters 91 to 1128 after the
    body's id (so the line between the id and the coordinates must be 88 characters long)."""
    text = path.read_text()
    pattern = ""
    for label, count in (("coordinates:", 3), ("displacements:", 6), ("velocities:", 6), ("accelerations:", 6),
                         ("principal or user defined local coordinate direction vectors a b c", 0),
                         ("row 1", 3), ("row 2", 3), ("row 3", 3),
                         ("output in principal or user defined local coordinate directions "
                          "a b c a-rot b-rot c-rot", 0),
                         ("displacements:", 6), ("velocities:", 6), ("accelerations:", 6)):
        pattern += r"\s*" + r"\s*".join(re.escape(word) for word in label.split())
        pattern += r"\s*([-+]?[0-9.]+(?:E[-+][0-9]+)?)" * count
    blocks = []
    for match in re.finditer(r"^ (nodal )?rigid body\s*(\d+)", text, re.M):
        found = re.match(pattern, text[match.end() + 90:match.end() + 1127])
        assert found, text[match.end():match.end() + 200]
        blocks.append(np.array([float(value) for value in found.groups()]))
    return blocks


def test_rbdout_equals_results_and_the_analytical_motion(tmp_path, run_deck):
    # BINARY 3: the ASCII file and binout
    run = run_deck(rigid_body_deck(tmp_path / "rigid.k", binary=3))
    assert run.status == 0, run.stderr
    samples = read_rbdout(run.results.parent / "rbdout")
    with run.open() as results:
        series = results["history/rbdout/4"]
        columns = {name: series[name][...] for name in series}
        free = {name: results["history/rbdout/9"][name][...] for name in ("displacement", "velocity")}
    assert len(samples) == len(columns["time"]) >= 11
    mass = DENSITY * RIGID_SIZE ** 3
    force, velocity = np.array(RIGID_FORCE), np.array(RIGID_VELOCITY)
    centre = np.array(RIGID_ORIGIN) + RIGID_SIZE / 2
    for row, (cycle, time, bodies) in enumerate(samples):
        body = bodies[4]
        # the file equals results.h5 to its printed digits
        assert cycle == columns["cycle"][row] and close(time, columns["time"][row], 7)
        exact = {"coordinates": columns["coordinates"][row],
                 "displacements": np.concatenate([columns["displacement"][row], columns["rotation"][row]]),
                 "velocities": np.concatenate([columns["velocity"][row], columns["angular_velocity"][row]]),
                 "accelerations": np.concatenate([columns["acceleration"][row],
                                                  columns["angular_acceleration"][row]])}
        for label, values in exact.items():
            assert all(close(p, e, 4) for p, e in zip(body[label], values)), (label, body[label], values)
        axes = columns["direction_cosines"][row].reshape(3, 3)
        for k in range(3):
            assert all(close(p, e, 4) for p, e in zip(body[f"row {k + 1}"], axes[k]))
        # the body does not turn: its axes stay the global ones, the local values the global
        for label in ("displacements", "velocities", "accelerations"):
            assert np.allclose(body["local " + label], exact[label], rtol=1e-4, atol=1e-12), label
        # physics: x(t) = x0 + v0 t + F t^2 / (2 m), a constant acceleration F / m, no rotation
        time = columns["time"][row]
        expected = velocity * time + force * time ** 2 / (2 * mass)
        assert np.allclose(columns["displacement"][row], expected, rtol=1e-9, atol=1e-9 * RIGID_SIZE)
        assert np.allclose(columns["coordinates"][row], centre + expected, rtol=1e-12)
        assert np.allclose(columns["velocity"][row], velocity + force * time / mass, rtol=1e-9, atol=1e-12)
        assert np.allclose(columns["acceleration"][row], force / mass, rtol=1e-9, atol=1e-12)
        assert np.abs(columns["angular_velocity"][row]).max() < 1e-12
        assert np.allclose(axes, np.eye(3), atol=1e-12)
    assert columns["time"][-1] >= 1.0 and abs(columns["displacement"][-1, 0]) > 1.0
    # the nodal rigid body: its own block, at its constant velocity
    text = (run.results.parent / "rbdout").read_text()
    assert text.count(" nodal rigid body       9") == text.count(" rigid body       4") == len(samples)
    for row, (_, _, bodies) in enumerate(samples):
        time = columns["time"][row]
        assert np.allclose(free["displacement"][row], np.array(NODAL_BODY_VELOCITY) * time, rtol=1e-9, atol=1e-9)
        assert all(close(p, e, 4) for p, e in zip(bodies[9]["displacements"][:3], free["displacement"][row]))
        assert np.abs(bodies[9]["accelerations"]).max() < 1e-9
    # a reader that counts characters finds the same numbers
    blocks = read_rbdout_by_offsets(run.results.parent / "rbdout")
    assert len(blocks) == 2 * len(samples)
    for block, (_, _, bodies) in zip(blocks[::2], samples):
        body = bodies[4]
        assert np.array_equal(block[:21], np.concatenate([body["coordinates"], body["displacements"],
                                                          body["velocities"], body["accelerations"]]))
        assert np.array_equal(block[21:30], np.concatenate([body[f"row {k}"] for k in (1, 2, 3)]))
    # binout's rbdout under LS-DYNA's names (lasso-python), the values of results.h5
    lasso_binout = pytest.importorskip("lasso.dyna.binout")
    binout = lasso_binout.Binout(str(run.results.parent / "binout"))
    assert list(binout.read("rbdout", "ids")) == [4, 9]
    for name, column in (("global_", "coordinates"), ("global_a", "acceleration"), ("global_rd", "rotation"),
                         ("global_rv", "angular_velocity"), ("global_ra", "angular_acceleration")):
        for axis, letter in enumerate("xyz"):
            np.testing.assert_array_equal(binout.read("rbdout", name + letter)[:, 0], columns[column][:, axis])
    for i in range(3):
        for j in range(3):
            np.testing.assert_array_equal(binout.read("rbdout", f"dircos_{i + 1}{j + 1}")[:, 0],
                                          columns["direction_cosines"][:, 3 * i + j])
