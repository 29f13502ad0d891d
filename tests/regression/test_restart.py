"""Restart dumps and r= (*DATABASE_BINARY_D3DUMP, _RUNRSF, the sense switches).

The bar: a run continued from a dump gives the results file of the uninterrupted run, every
dataset equal bit for bit (/timing aside), for every kind of model (solids with plasticity and
hourglass stiffness, shells with drilling, meshfree parts coupled to finite elements, contact
with friction, rigid bodies and moving rigid walls), on 1 and 2 threads and with another thread
count after the restart than before. Also: a dump written by SIGTERM (sw1) or SIGUSR1 (sw3), the
running restart file, the names with jobid=, and the dumps that are refused (another deck, a
changed include, a damaged file, another version, a missing or foreign results file) with exit
status 2 and a message saying why.
"""
from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import time
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import h5py
import numpy as np
import pytest

from conftest import BINARY
from deck_writer import (block_mesh, efg_section, fields, node_list_set, nodes_card, plate_mesh, shells_card,
                         solids_card, write_deck)

STEEL = fields(1, 7.85e-6, 200.0, 0.3, 0.3, 2.0, 1.0) + "\n" + fields(0.0, 0.0)   # MAT_003 card 1, 2 (MID 1)
DUMP_EVERY = 50      # cycles between dumps of the matrix decks (300-400 cycles each)


# ---------------------------------------------------------------------------------------------
# Decks: small, a few hundred cycles, each exercising the state of one kind of model

def solids_deck(path, cells=5, end_time=0.06):
    """A plastic block (MAT_003 with hardening) thrown at a stationary planar wall, one-point
    elements with hourglass stiffness (IHQ 5, accumulated forces), a history node."""
    nodes, elements = block_mesh((cells, cells, cells), (10.0, 10.0, 10.0), origin=(0.0, 0.0, 0.2), perturbation=0.1)
    return write_deck(
        path, "*TITLE\nsolids against a wall",
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*CONTROL_HOURGLASS\n" + fields(5, 0.1),
        "*DATABASE_GLSTAT\n" + fields(0.001), "*DATABASE_MATSUM\n" + fields(0.002),
        "*DATABASE_RWFORC\n" + fields(0.0005), "*DATABASE_NODOUT\n" + fields(0.001),
        "*DATABASE_HISTORY_NODE\n" + fields(1, 36),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.005),
        "*DATABASE_BINARY_D3DUMP\n" + fields(DUMP_EVERY),
        "*PART\nblock\n" + fields(1, 1, 1), "*SECTION_SOLID\n" + fields(1, 1), "*MAT_PLASTIC_KINEMATIC\n" + STEEL,
        "*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields(10.0, 0.0, -100.0),
        "*RIGIDWALL_PLANAR_ID\n" + fields(7) + "wall\n" + fields(0) + "\n" + fields(0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
        nodes_card(nodes), solids_card(elements))


def shells_deck(path):
    """A plate of Belytschko-Tsay shells (NIP 3, MAT_003, IHQ 4) clamped along one edge and
    struck across its face: bending, plasticity, and the drilling rates removed at every cycle."""
    nodes, shells = plate_mesh((8, 4), (40.0, 20.0), perturbation=0.1)
    root = [k + 1 for k in np.flatnonzero(np.isclose(nodes[:, 0], 0.0))]
    return write_deck(
        path, "*TITLE\nstruck plate",
        "*CONTROL_TERMINATION\n" + fields(0.24),
        "*DATABASE_GLSTAT\n" + fields(0.002), "*DATABASE_MATSUM\n" + fields(0.002),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.02),
        "*DATABASE_BINARY_D3DUMP\n" + fields(DUMP_EVERY),
        "*PART\nplate\n" + fields(1, 1, 1, 0, 1),
        "*SECTION_SHELL\n" + fields(1, 2, 0.8333, 3) + "\n" + fields(1.0, 1.0, 1.0, 1.0),
        "*MAT_PLASTIC_KINEMATIC\n" + STEEL, "*HOURGLASS\n" + fields(1, 4, 0.1),
        node_list_set(1, root), "*BOUNDARY_SPC_SET\n" + fields(1, 0, 1, 1, 1, 1, 1, 1),
        "*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields(0.0, 0.0, 20.0),
        nodes_card(nodes), shells_card(shells))


def meshfree_deck(path):
    """A bar whose front half is meshfree (EFG) and back half fully integrated finite elements,
    thrown at a wall with its EFG end first."""
    nodes, elements = block_mesh((8, 3, 3), (16.0, 6.0, 6.0), origin=(0.1, 0.0, 0.0))
    centres = nodes[elements].mean(axis=1)
    meshfree = centres[:, 0] < 8.0
    cards = solids_card(elements[meshfree], part_id=1)
    cards += "\n" + solids_card(elements[~meshfree], part_id=2, first_id=1001).split("\n", 1)[1]
    return write_deck(
        path, "*TITLE\ncoupled bar against a wall",
        "*CONTROL_TERMINATION\n" + fields(0.07),
        "*DATABASE_GLSTAT\n" + fields(0.0005), "*DATABASE_MATSUM\n" + fields(0.001),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.005),
        "*DATABASE_BINARY_D3DUMP\n" + fields(DUMP_EVERY),
        "*PART\nmeshfree\n" + fields(1, 1, 1, 0, 1), "*PART\nfinite elements\n" + fields(2, 2, 1, 0, 1),
        efg_section(1, 1.5), "*SECTION_SOLID\n" + fields(2, 2), "*HOURGLASS\n" + fields(1, 1, 0.1),
        "*MAT_PLASTIC_KINEMATIC\n" + STEEL,
        "*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields(-60.0, 5.0, 0.0),
        "*RIGIDWALL_PLANAR\n" + fields(0) + "\n" + fields(0.0, 0.0, 0.0, 1.0, 0.0, 0.0),
        nodes_card(nodes), cards)


def contact_deck(path):
    """A block sliding and bouncing on a fixed base through surface-to-surface contact with
    Coulomb friction (friction springs, search lists rebuilt as it slides), under a nodal load."""
    base_nodes, base_elements = block_mesh((6, 4, 1), (60.0, 20.0, 5.0), origin=(-10.0, -5.0, -5.0))
    slider_nodes, slider_elements = block_mesh((3, 3, 2), (10.0, 10.0, 5.0), origin=(0.0, 0.0, 0.001))
    count = len(base_nodes)
    return write_deck(
        path, "*TITLE\nsliding block",
        "*CONTROL_TERMINATION\n" + fields(0.1),
        "*DATABASE_GLSTAT\n" + fields(0.001), "*DATABASE_RCFORC\n" + fields(0.0005),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.01),
        "*DATABASE_BINARY_D3DUMP\n" + fields(DUMP_EVERY),
        "*PART\nbase\n" + fields(1, 1, 1), "*PART\nslider\n" + fields(2, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1), "*MAT_PLASTIC_KINEMATIC\n" + STEEL,
        node_list_set(1, list(range(1, count + 1))),
        node_list_set(2, list(range(count + 1, count + len(slider_nodes) + 1))),
        "*BOUNDARY_SPC_SET\n" + fields(1, 0, 1, 1, 1),
        "*INITIAL_VELOCITY\n" + fields(2) + "\n" + fields(40.0, 5.0, -1.0),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + fields(0.0, 1.0, width=20) + "\n" + fields(10.0, 1.0, width=20),
        "*LOAD_NODE_SET\n" + fields(2, 3, 1, -2.0e-2),
        "*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE_ID\n" + fields(3) + "slide\n" + fields(2, 1, 3, 3) + "\n" +
        fields(0.3, 0.2, 0.0, 0.0, 20.0) + "\n" + fields(1.0),
        nodes_card(np.vstack([base_nodes, slider_nodes])),
        solids_card(base_elements, part_id=1) + "\n" +
        "\n".join(solids_card(slider_elements, part_id=2, first_id=len(base_elements) + 1,
                              first_node_id=count + 1).splitlines()[1:]))


def rigid_deck(path):
    """A rigid pusher with a prescribed velocity (CMO constraints) drives an elastic block, which
    also rises, into a moving planar wall and under a stationary cylinder wall; a second rigid
    body tumbles freely (rbdout, rwforc)."""
    nodes, elements = block_mesh((6, 2, 2), (60.0, 20.0, 20.0))
    rigid = nodes[elements].mean(axis=1)[:, 0] < 10.0
    free_nodes, free_elements = block_mesh((1, 1, 1), (10.0, 10.0, 10.0), origin=(0.0, 40.0, 0.0))
    lines = ["*ELEMENT_SOLID"]
    for k, corners in enumerate(elements):
        lines.append(f"{k + 1:8d}{2 if rigid[k] else 1:8d}" + "".join(f"{c + 1:8d}" for c in corners))
    for k, corners in enumerate(free_elements):
        lines.append(f"{k + 101:8d}{3:8d}" + "".join(f"{c + len(nodes) + 1:8d}" for c in corners))
    return write_deck(
        path, "*TITLE\nrigid bodies and walls",
        "*CONTROL_TERMINATION\n" + fields(0.4),
        "*DATABASE_GLSTAT\n" + fields(0.004), "*DATABASE_RWFORC\n" + fields(0.002),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.05),
        "*DATABASE_BINARY_D3DUMP\n" + fields(DUMP_EVERY),
        "*PART\nblock\n" + fields(1, 1, 1), "*PART\npusher\n" + fields(2, 1, 2), "*PART\ntumbler\n" + fields(3, 1, 3),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, 7.85e-6, 210.0, 0.3),
        "*MAT_RIGID\n" + fields(2, 7.85e-6, 210.0, 0.3) + "\n" + fields(1.0, 0.0, 7.0),
        "*MAT_RIGID\n" + fields(3, 7.85e-6, 210.0, 0.3),
        "*DEFINE_CURVE\n" + fields(1) + "\n" + fields(0.0, 0.0, width=20) + "\n" +
        fields(0.1, 1.0, width=20) + "\n" + fields(10.0, 1.0, width=20),
        "*BOUNDARY_PRESCRIBED_MOTION_RIGID\n" + fields(2, 1, 0, 1, 5.0),
        "*INITIAL_VELOCITY_GENERATION\n" + fields(3, 2, 0.3, 1.0, 0.0, 0.0) + "\n" + fields(5.0, 45.0, 5.0, 1.0, 0.5, 0.3),
        "*RIGIDWALL_PLANAR_MOVING_ID\n" + fields(4) + "anvil\n" + fields(0) + "\n" +
        fields(61.0, 0.0, 0.0, -1.0, 0.0, 0.0) + "\n" + fields(0.2, 2.0),
        "*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields(0.0, 0.0, 5.0),
        "*RIGIDWALL_GEOMETRIC_CYLINDER_ID\n" + fields(5) + "bar\n" + fields(0) + "\n" +
        fields(50.0, -10.0, 24.0, 50.0, 30.0, 24.0) + "\n" + fields(3.0, 0.0),
        nodes_card(np.vstack([nodes, free_nodes])), "\n".join(lines))


MODELS = {"solids": solids_deck, "shells": shells_deck, "meshfree": meshfree_deck, "contact": contact_deck,
          "rigid_and_walls": rigid_deck}


# ---------------------------------------------------------------------------------------------
# Running and comparing

def solver(*arguments, ncpu=1, timeout=300.0):
    # passive waiting: on a loaded machine two spinning threads slow these tiny runs a
    # hundredfold (the results do not depend on it)
    environment = dict(os.environ, OMP_NUM_THREADS=str(ncpu), CRASHFREE_OVERSUBSCRIBE="1", OMP_WAIT_POLICY="passive")
    return subprocess.run([str(BINARY), *map(str, arguments), f"ncpu={ncpu}"], capture_output=True, text=True,
                          timeout=timeout, env=environment)


def run_fresh(deck, output, ncpu=1, jobid=None):
    process = solver(f"i={deck}", f"outdir={output}", *([f"jobid={jobid}"] if jobid else []), ncpu=ncpu)
    assert process.returncode == 0, process.stdout + process.stderr
    return process


def restart(dump, ncpu=1, *extra):
    return solver(f"r={dump}", *extra, ncpu=ncpu)


def contents(path):
    """Every dataset but /timing, the state times, and the /run attributes but threads and run_id."""
    found = {}
    with h5py.File(path, "r") as results:
        def visit(name, item):
            if isinstance(item, h5py.Dataset) and not name.startswith("timing"):
                found[name] = item[()]
        results.visititems(visit)
        for name, value in results["run"].attrs.items():
            if name not in ("threads", "run_id"):
                found["run@" + name] = value
        for name in results["states"]:
            found[f"states/{name}@time"] = results["states"][name].attrs["time"]
    return found


def assert_same(reference, other, what):
    assert reference.keys() == other.keys(), f"{what}: {sorted(set(reference) ^ set(other))}"
    for name, value in reference.items():
        assert np.array_equal(value, other[name]), f"{what}: {name} differs"


def assert_xdmf_lists_the_states(xdmf, h5):
    """The XDMF parses and lists exactly the states of the file, at their times."""
    tree = ElementTree.parse(xdmf)
    times = [float(element.attrib["Value"]) for element in tree.iter("Time")]
    with h5py.File(h5, "r") as results:
        states = sorted(results["states"])
        expected = [results["states"][name].attrs["time"] for name in states]
    assert len(times) == len(expected) and np.allclose(times, expected, rtol=1e-12, atol=0.0)
    referenced = {item.text.strip().split(":", 1)[1] for item in tree.iter("DataItem") if ":/states/" in (item.text or "")}
    assert {path.split("/")[2] for path in referenced} == set(states)


def copy_run(source, target):
    shutil.copytree(source, target)
    return target


# ---------------------------------------------------------------------------------------------
# The matrix

@pytest.mark.parametrize("model", MODELS)
def test_restart_reproduces_the_uninterrupted_run(tmp_path, model):
    deck = MODELS[model](tmp_path / f"{model}.k")
    run_fresh(deck, tmp_path / "one", ncpu=1)
    run_fresh(deck, tmp_path / "two", ncpu=2)
    reference = contents(tmp_path / "one" / "results.h5")
    assert_same(reference, contents(tmp_path / "two" / "results.h5"), "ncpu=2")
    # writing dumps changes nothing: the deck without them gives the same file
    plain = tmp_path / "plain.k"
    plain.write_text(deck.read_text().replace("*DATABASE_BINARY_D3DUMP\n" + fields(DUMP_EVERY) + "\n", ""))
    run_fresh(plain, tmp_path / "plain", ncpu=1)
    plain_contents = contents(tmp_path / "plain" / "results.h5")
    plain_contents.pop("run@deck")
    assert_same({k: v for k, v in reference.items() if k != "run@deck"}, plain_contents, "without dumps")

    dumps = sorted(p.name for p in (tmp_path / "one").glob("d3dump*"))
    assert dumps == [f"d3dump{k:02d}" for k in range(1, len(dumps) + 1)] and len(dumps) >= 5, dumps
    assert not list((tmp_path / "one").glob("*.tmp"))
    # every dump continued on 2 threads (the impacts, slides and spins are caught at several
    # moments), and the middle one also on the same count and from the 2-thread run on 1
    middle = dumps[len(dumps) // 2]
    cases = [("one", dump, 2) for dump in dumps] + [("one", middle, 1), ("two", middle, 1)]
    for source, dump, ncpu in cases:
        target = copy_run(tmp_path / source, tmp_path / f"restart_{source}_{dump}_{ncpu}")
        process = restart(target / dump, ncpu)
        assert process.returncode == 0, process.stdout + process.stderr
        assert f"continuing from restart dump {target / dump}" in process.stdout
        what = f"{model}: {dump} of the ncpu={1 if source == 'one' else 2} run continued on ncpu={ncpu}"
        assert_same(reference, contents(target / "results.h5"), what)
        with h5py.File(target / "results.h5", "r") as results:
            assert results["run"].attrs["threads"] == ncpu
        assert_xdmf_lists_the_states(target / "results.xdmf", target / "results.h5")


# ---------------------------------------------------------------------------------------------
# Sense switches

def long_deck(path):
    """The solids deck with 1,000 elements for 0.5 ms (about 5,000 cycles, a second or two), no
    periodic dumps: long enough for signals to find it running."""
    deck = solids_deck(path, cells=10, end_time=0.5)
    deck.write_text(deck.read_text().replace("*DATABASE_BINARY_D3DUMP\n" + fields(DUMP_EVERY) + "\n", ""))
    return deck


def test_sigusr1_and_sigterm_write_dumps_that_continue_the_run(tmp_path):
    """SIGUSR1 (sw3) writes d3dump01 and the run goes on; SIGTERM (sw1) writes d3dump02, says
    where it is and ends with error termination. Both continue to the uninterrupted run's file."""
    deck = long_deck(tmp_path / "long.k")
    environment = dict(os.environ, OMP_NUM_THREADS="1", GFORTRAN_UNBUFFERED_PRECONNECTED="y")
    reference = subprocess.Popen([str(BINARY), f"i={deck}", f"outdir={tmp_path / 'reference'}", "ncpu=1"],
                                 stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=environment)
    stopped = tmp_path / "stopped"
    process = subprocess.Popen([str(BINARY), f"i={deck}", f"outdir={stopped}", "ncpu=1"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, env=environment)
    seen = []
    for line in process.stdout:           # the progress header: the time loop (and its handlers) runs
        seen.append(line)
        if "time step" in line:
            break
    process.send_signal(signal.SIGUSR1)
    for line in process.stdout:
        seen.append(line)
        if line.startswith("restart dump"):
            break
    process.send_signal(signal.SIGTERM)
    rest, stderr = process.communicate(timeout=120)
    stdout = "".join(seen) + rest
    assert reference.wait(timeout=120) == 0, reference.stderr.read()
    assert process.returncode == 1, stdout + stderr
    assert re.search(rf"^restart dump {stopped}/d3dump01 at time \S+, cycle \d+ \(SIGUSR1\)$", stdout, re.M), stdout
    found = re.search(r"stopped by SIGTERM at time (\S+), cycle (\d+): the results hold the run up to this time; "
                      rf"restart dump ({stopped}/d3dump02) written \(bin/crashfree r=\S+ continues the run\)", stderr)
    assert found, stderr
    with h5py.File(stopped / "d3dump02", "r") as dump:
        assert dump.attrs["reason"] == b"SIGTERM" and dump.attrs["cycle"] == int(found.group(2))
    with h5py.File(stopped / "d3dump01", "r") as dump:
        assert dump.attrs["reason"] == b"SIGUSR1" and 0 < dump.attrs["cycle"] < int(found.group(2))
    with h5py.File(stopped / "results.h5", "r") as results:
        assert results["run"].attrs["status"] == "error termination"
        assert "restart dump" in results["run"].attrs["message"]
    expected = contents(tmp_path / "reference" / "results.h5")
    for dump, ncpu in (("d3dump01", 2), ("d3dump02", 1)):
        target = copy_run(stopped, tmp_path / f"from_{dump}")
        process = restart(target / dump, ncpu)
        assert process.returncode == 0, process.stdout + process.stderr
        assert_same(expected, contents(target / "results.h5"), f"continued from {dump} ({ncpu} thread(s))")
        assert_xdmf_lists_the_states(target / "results.xdmf", target / "results.h5")


# ---------------------------------------------------------------------------------------------
# Running restart files, names, where a restart finds things

def test_running_restart_files_job_names_and_directories(tmp_path):
    """*DATABASE_BINARY_RUNRSF with NR = 2 writes NAME.runrsf01 and NAME.runrsf02 in turn beside
    NAME.d3dump01 ...; a restart run from another directory finds the deck (given relative to
    the first run's directory), takes the dump's job and directory, or outdir= given."""
    deck = solids_deck(tmp_path / "solids.k")
    deck.write_text(deck.read_text().replace("*END", "*DATABASE_BINARY_RUNRSF\n" + fields(80, 2) + "\n*END"))
    environment = dict(os.environ, OMP_NUM_THREADS="1")
    process = subprocess.run([str(BINARY.resolve()), "i=solids.k", "outdir=out", "jobid=crash", "ncpu=1"], cwd=tmp_path,
                             capture_output=True, text=True, env=environment)
    assert process.returncode == 0, process.stdout + process.stderr
    out = tmp_path / "out"
    names = sorted(p.name for p in out.iterdir())
    # (and LS-DYNA's d3plot, the ASCII files of the deck's *DATABASE_ keywords, d3hsp and messag,
    # as LS-DYNA names them with a job id)
    assert names == ["crash.d3dump01", "crash.d3dump02", "crash.d3dump03", "crash.d3dump04", "crash.d3dump05",
                     "crash.d3dump06", "crash.d3hsp", "crash.d3plot", "crash.d3plot01", "crash.glstat", "crash.h5",
                     "crash.lock", "crash.matsum", "crash.messag", "crash.nodout", "crash.runrsf01", "crash.runrsf02",
                     "crash.rwforc", "crash.xdmf"]
    cycles = {}
    for name in ("crash.runrsf01", "crash.runrsf02", "crash.d3dump03"):
        with h5py.File(out / name, "r") as dump:
            cycles[name] = dump.attrs["cycle"]
            assert dump.attrs["job_id"] == b"crash" and dump.attrs["deck"] == b"solids.k"
    assert cycles == {"crash.runrsf01": 240, "crash.runrsf02": 160, "crash.d3dump03": 150}
    expected = contents(out / "crash.h5")

    # from another directory: the deck by its recorded absolute path, job and directory the dump's
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    target = copy_run(out, tmp_path / "copy")
    process = subprocess.run([str(BINARY.resolve()), f"r={target / 'crash.runrsf02'}", "ncpu=2"], cwd=elsewhere,
                             capture_output=True, text=True, env=dict(environment, OMP_WAIT_POLICY="passive"))
    assert process.returncode == 0, process.stdout + process.stderr
    assert f"{tmp_path / 'solids.k'} on 2 thread(s)" in process.stdout
    assert_same(expected, contents(target / "crash.h5"), "continued from crash.runrsf02")
    assert not list(elsewhere.iterdir())

    # outdir= and jobid= given: the results file of that name there is continued
    moved = tmp_path / "moved"
    moved.mkdir()
    shutil.copy(out / "crash.h5", moved / "other.h5")
    process = restart(out / "crash.d3dump03", 1, f"outdir={moved}", "jobid=other", f"i={deck}")
    assert process.returncode == 0, process.stdout + process.stderr
    assert_same(expected, contents(moved / "other.h5"), "continued into outdir=moved jobid=other")
    assert (moved / "other.d3dump04").exists() and not (out / "crash.d3dump07").exists()


# ---------------------------------------------------------------------------------------------
# Refused restarts and deck errors

def test_refused_restarts_say_why_and_leave_the_results_alone(tmp_path):
    nodes, elements = block_mesh((3, 3, 3), (6.0, 6.0, 6.0), origin=(0.0, 0.0, 0.1))
    (tmp_path / "mesh.k").write_text("*KEYWORD\n" + nodes_card(nodes) + "\n" + solids_card(elements) + "\n*END\n")
    deck = write_deck(tmp_path / "deck.k", "*CONTROL_TERMINATION\n" + fields(0.02),
                      "*DATABASE_BINARY_D3DUMP\n" + fields(30),
                      "*PART\nblock\n" + fields(1, 1, 1), "*SECTION_SOLID\n" + fields(1, 1),
                      "*MAT_PLASTIC_KINEMATIC\n" + STEEL,
                      "*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields(0.0, 0.0, -50.0),
                      "*RIGIDWALL_PLANAR\n" + fields(0) + "\n" + fields(0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
                      "*INCLUDE\nmesh.k")
    run_fresh(deck, tmp_path / "one")
    run_fresh(deck, tmp_path / "two")
    one = tmp_path / "one"
    original = (one / "results.h5").read_bytes()

    def refused(dump, *extra):
        process = restart(dump, 1, *extra)
        assert process.returncode == 2, process.stdout + process.stderr
        assert (one / "results.h5").read_bytes() == original
        return process.stderr

    text = deck.read_text()
    deck.write_text(text.replace(fields(0.0, 0.0, -50.0), fields(0.0, 0.0, -51.0)))
    message = refused(one / "d3dump02")
    assert f"deck {deck} is not the one restart dump {one}/d3dump02 was written with: {deck} has changed" in message
    deck.write_text(text)
    mesh = (tmp_path / "mesh.k").read_text()
    (tmp_path / "mesh.k").write_text(mesh + "$ a comment\n")
    message = refused(one / "d3dump02")
    assert f"{tmp_path / 'mesh.k'} has changed since" in message
    (tmp_path / "mesh.k").write_text(mesh)

    damaged = tmp_path / "damaged"
    damaged.write_bytes((one / "d3dump02").read_bytes()[:5000])
    assert f"restart dump {damaged} cannot be read" in refused(damaged)
    assert f"restart file {deck} is not a crashfree restart dump" in refused(deck) or \
        f"restart dump {deck} cannot be read" in refused(deck)
    assert f"restart dump {tmp_path / 'none'} does not exist" in refused(tmp_path / "none")

    older = tmp_path / "older"
    shutil.copy(one / "d3dump02", older)
    with h5py.File(older, "r+") as dump:
        del dump.attrs["version"]
        dump.attrs["version"] = np.bytes_(b"0.0.9")
    assert re.search(r"restart dump \S+older was written by crashfree 0\.0\.9; this is crashfree \S+, which reads "
                     r"only its own dumps", refused(older, f"outdir={one}"))

    # the results file: another run's, or none
    foreign = copy_run(tmp_path / "two", tmp_path / "foreign")
    shutil.copy(one / "d3dump02", foreign / "d3dump02")
    process = restart(foreign / "d3dump02", 1)
    assert process.returncode == 2
    assert f"the results file {foreign}/results.h5 is not the one of the run that wrote {foreign}/d3dump02" in \
        process.stderr
    (foreign / "results.h5").unlink()
    process = restart(foreign / "d3dump02", 1)
    assert process.returncode == 2
    assert f"the results file {foreign}/results.h5 of the interrupted run is missing" in process.stderr

    # and the untouched dump still continues the run
    process = restart(one / "d3dump02", 1)
    assert process.returncode == 0, process.stdout + process.stderr
    assert_same(contents(tmp_path / "two" / "results.h5"), contents(one / "results.h5"), "after the refusals")


@pytest.mark.parametrize("keyword,card,field,message", [
    ("D3DUMP", fields(100, 5), "LCDT", "dump intervals from a curve are not available; give CYCL"),
    ("D3DUMP", fields(-1), "CYCL", "the number of cycles between dumps must be a whole number >= 0"),
    ("D3DUMP", fields(12.5), "CYCL", "the number of cycles between dumps must be a whole number >= 0"),
    ("RUNRSF", fields(100, -2), "NR", "the number of running restart files must be >= 0"),
])
def test_dump_keyword_errors(tmp_path, keyword, card, field, message):
    deck = solids_deck(tmp_path / "solids.k")
    deck.write_text(deck.read_text().replace("*DATABASE_BINARY_D3DUMP\n" + fields(DUMP_EVERY),
                                             f"*DATABASE_BINARY_{keyword}\n" + card))
    process = solver(f"i={deck}", f"outdir={tmp_path}")
    assert process.returncode == 2
    assert re.search(rf"solids\.k:\d+: \*DATABASE_BINARY_{keyword}: field {field}: {re.escape(message)}",
                     process.stderr), process.stderr


def test_fields_of_other_binary_databases_are_read_with_a_warning(tmp_path):
    deck = solids_deck(tmp_path / "solids.k")
    deck.write_text(deck.read_text().replace("*DATABASE_BINARY_D3DUMP\n" + fields(DUMP_EVERY),
                                             "*DATABASE_BINARY_D3DUMP\n" + fields(100.0, 0, 1, 0, 3) + "\n" + fields(2)))
    process = solver(f"i={deck}", f"outdir={tmp_path / 'out'}")
    assert process.returncode == 0, process.stderr
    for field in ("BEAM", "PSETID", "IOOPT"):
        assert re.search(rf"\*DATABASE_BINARY_D3DUMP: field {field}: ignored \(", process.stderr), process.stderr
    assert "NPLTC" not in process.stderr
    assert sorted(p.name for p in (tmp_path / "out").glob("d3dump*")) == ["d3dump01", "d3dump02", "d3dump03"]
