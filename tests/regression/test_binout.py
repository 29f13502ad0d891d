"""binout (LS-DYNA's LSDA history file) written when *DATABASE_<name> BINARY is 2 or 3.

- lasso-python's Binout reads glstat, matsum, nodout and rwforc of a block thrown at a rigid wall
  and rcforc of two blocks in head-on contact: every value equals results.h5's /history (binout
  stores R8, so to the bit); nodout's coordinates are the mesh's plus the displacements.
- LS-DYNA's signs and physics: rwforc is the force the wall exerts on the block (positive along
  the wall normal, normal_force its normal part; at a cylinder the radial part), and its integral
  over time is the block's momentum change (1%); rcforc holds both sides of each contact, the
  primary side's force the opposite of the secondary side's, and the secondary block's impulse is
  -2 m v (the blocks exchange velocities, 2%); rbdout of a free rigid block: constant velocity,
  displacement v t.
- A run continued from a restart dump (r=) writes the binout of the uninterrupted run.
- A second, independent reader in this file walks the file's records in order (as dynareadout
  reads binout: CD and DATA records, no symbol table), checks that the record lengths chain to the
  end of the file and that every symbol-table entry points at its DATA record, and finds the same
  values as lasso-python.
- The file is named as LS-DYNA names it (binout; JOBID.binout), BINARY 1 (the default) writes
  none, and BINARY outside 0..3 is refused with the deck line.
"""
import os
import shutil
import struct
import subprocess

import numpy as np
import pytest

from conftest import BINARY
from deck_writer import block_mesh, fields, node_list_set, nodes_card, solids_card, write_deck

lasso_binout = pytest.importorskip("lasso.dyna.binout")

DENSITY, MODULUS, POISSON = 7.85e-6, 200.0, 0.3      # kg/mm^3, GPa, -
SPEED = 100.0                                        # mm/ms, the block thrown at the wall
WALL_ID = 7
HISTORY_NODES = (1, 5, 64)


def wall_deck(path, binary=(2, 3, 2, 2), title="block against a rigid wall"):
    """A 3x3x3 elastic block at 100 mm/ms in -z onto a wall z = 0 (normal +z); BINARY of
    glstat, matsum, nodout, rwforc as given (None: field blank)."""
    nodes, elements = block_mesh((3, 3, 3), (10.0, 10.0, 10.0), origin=(0.0, 0.0, 0.2))
    glstat, matsum, nodout, rwforc = ("" if value is None else value for value in binary)
    return write_deck(
        path,
        "*TITLE\n" + title,
        "*CONTROL_TERMINATION\n" + fields(0.03),
        "*DATABASE_GLSTAT\n" + fields(0.0005, glstat),
        "*DATABASE_MATSUM\n" + fields(0.0005, matsum),
        "*DATABASE_NODOUT\n" + fields(0.0005, nodout),
        "*DATABASE_HISTORY_NODE\n" + fields(*HISTORY_NODES),
        "*DATABASE_RWFORC\n" + fields(0.0005, rwforc),
        "*DATABASE_BINARY_D3PLOT\n" + fields(0.004),
        "*PART\nblock\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, MODULUS, POISSON),
        "*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields(0.0, 0.0, -SPEED),
        f"*RIGIDWALL_PLANAR_ID\n{fields(WALL_ID)}wall\n" + fields(0) + "\n" + fields(0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
        nodes_card(nodes),
        solids_card(elements),
    ), nodes


GLSTAT_NAMES = {   # LS-DYNA's name: results.h5's /history/glstat column
    "time": "time", "time_step": "time_step", "kinetic_energy": "kinetic_energy",
    "internal_energy": "internal_energy", "hourglass_energy": "hourglass_energy",
    "sliding_interface_energy": "contact_energy", "external_work": "external_work",
    "total_energy": "total_energy", "stonewall_energy": "rigid_wall_energy", "energy_ratio": "energy_ratio",
    "added_mass": "added_mass", "eroded_internal_energy": "eroded_internal_energy",
    "eroded_hourglass_energy": "eroded_hourglass_energy", "eroded_kinetic_energy": "eroded_kinetic_energy",
    "cycle": "cycle", "spring_and_damper_energy": "spring_damper_energy",
    "system_damping_energy": "system_damping_energy", "energy_ratio_wo_eroded": "energy_ratio_without_eroded",
    "percent_increase": "percent_mass_increase",
}


def test_wall_impact_histories_equal_results(tmp_path, run_deck):
    deck, _ = wall_deck(tmp_path / "wall.k")
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    binout_path = run.results.parent / "binout"
    assert binout_path.exists()
    assert not list(run.results.parent.glob(".*partial")) and not list(run.results.parent.glob("*partial"))
    binout = lasso_binout.Binout(str(binout_path))
    assert sorted(binout.read()) == ["glstat", "matsum", "nodout", "rwforc"]
    assert binout.read("glstat", "title").rstrip() == "block against a rigid wall"
    assert binout.read("glstat", "version").startswith("crashfree")
    with run.open() as results:
        history = results["history"]
        # glstat: one value per sample
        for name, column in GLSTAT_NAMES.items():
            np.testing.assert_array_equal(binout.read("glstat", name), history["glstat"][column][...], err_msg=name)
        # matsum: the part ids and titles, energies per part
        assert list(binout.read("matsum", "ids")) == [1]
        assert binout.read("matsum", "legend").rstrip() == "block"
        for name in ("time", "kinetic_energy", "internal_energy", "hourglass_energy"):
            np.testing.assert_array_equal(binout.read("matsum", name), history["matsum/1"][name][...], err_msg=name)
        # matsum's momentum per part (sum of m v over the part), equal to glstat's for one part
        for axis, letter in enumerate("xyz"):
            momentum = binout.read("matsum", f"{letter}_momentum")
            np.testing.assert_array_equal(momentum, history["matsum/1/momentum"][:, axis])
            np.testing.assert_allclose(momentum, history["glstat/momentum"][:, axis], rtol=1e-12,
                                       atol=1e-12 * np.abs(history["glstat/momentum"][...]).max())
        # nodout: arrays (samples, nodes) in the order of *DATABASE_HISTORY_NODE
        assert list(binout.read("nodout", "ids")) == list(HISTORY_NODES)
        np.testing.assert_array_equal(binout.read("nodout", "time"), history[f"nodout/{HISTORY_NODES[0]}/time"][...])
        for column in ("displacement", "velocity", "acceleration"):
            expected = np.stack([history[f"nodout/{node}/{column}"][...] for node in HISTORY_NODES], axis=1)
            for axis, letter in enumerate("xyz"):
                np.testing.assert_array_equal(binout.read("nodout", f"{letter}_{column}"), expected[:, :, axis])
        displacement = np.stack([history[f"nodout/{node}/displacement"][...] for node in HISTORY_NODES], axis=1)
        node_ids = list(results["mesh/nodes/ids"][...])
        coordinates = results["mesh/nodes/coordinates"][...]
        reference = coordinates[[node_ids.index(node) for node in HISTORY_NODES]]
        for axis, letter in enumerate("xyz"):
            np.testing.assert_allclose(binout.read("nodout", f"{letter}_coordinate"),
                                       reference[None, :, axis] + displacement[:, :, axis], rtol=0, atol=1e-12)
        # rwforc: LS-DYNA's sign, the force on the structure (as results.h5 holds it)
        wall_force = history[f"rwforc/{WALL_ID}/force"][...]
        time = history[f"rwforc/{WALL_ID}/time"][...]
        momentum = history["glstat/momentum"][...]
    assert list(binout.read("rwforc", "forces", "ids")) == [WALL_ID]
    np.testing.assert_array_equal(binout.read("rwforc", "forces", "time"), time)
    for axis, letter in enumerate("xyz"):
        np.testing.assert_array_equal(binout.read("rwforc", "forces", f"{letter}_force"), wall_force[:, axis])
    z_force = binout.read("rwforc", "forces", "z_force")
    np.testing.assert_array_equal(binout.read("rwforc", "forces", "normal_force"), z_force)
    assert z_force.min() >= 0.0 and z_force.max() > 0.0, "the wall pushes the block back along its normal"
    # forces are means over each sampling interval: their integral is the impulse exactly
    impulse = (z_force[1:] * np.diff(time)).sum()
    momentum_change = momentum[-1, 2] - momentum[0, 2]
    assert momentum_change > 0.5 * abs(momentum[0, 2]), "the block must be stopped or thrown back"
    assert abs(impulse - momentum_change) < 0.01 * momentum_change
    # the independent reader finds the same variables and values
    check_against_record_walk(binout_path, binout)


def test_cylinder_wall_normal_force(tmp_path, run_deck):
    """A block thrown in -x at an infinite cylinder along z, off-centre in y: rwforc's
    normal_force is the radial part of the force on the block, hypot(x_force, y_force)."""
    nodes, elements = block_mesh((3, 3, 3), (10.0, 10.0, 10.0))
    deck = write_deck(
        tmp_path / "post.k",
        "*CONTROL_TERMINATION\n" + fields(0.05),
        "*DATABASE_RWFORC\n" + fields(0.0005, 2),
        "*PART\nblock\n" + fields(1, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, MODULUS, POISSON),
        "*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields(-SPEED, 0.0, 0.0),
        "*RIGIDWALL_GEOMETRIC_CYLINDER_ID\n" + fields(3) + "post\n" + fields(0) + "\n" +
        fields(-3.5, 4.0, 0.0, -3.5, 4.0, 1.0) + "\n" + fields(3.0, 0.0, 0),
        nodes_card(nodes),
        solids_card(elements),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    binout = lasso_binout.Binout(str(run.results.parent / "binout"))
    x_force, y_force, z_force = (binout.read("rwforc", "forces", f"{letter}_force") for letter in "xyz")
    normal = binout.read("rwforc", "forces", "normal_force")
    assert x_force.max() > 0.0, "the post pushes the block back in +x"
    np.testing.assert_allclose(normal, np.hypot(x_force, y_force), rtol=1e-12, atol=1e-9 * normal.max())
    assert np.abs(z_force).max() < 1e-6 * normal.max()


def head_on_deck(path, end_time=0.03, speed=1.0):
    """Two 40x5x5 elastic blocks meeting head on at 1 mm/ms each (contact 5, SURFA = block 1);
    rcforc to binout and the ASCII file (BINARY 3)."""
    counts, lengths, gap = (8, 1, 1), (40.0, 5.0, 5.0), 0.01
    a_nodes, a_elements = block_mesh(counts, lengths)
    b_nodes, b_elements = block_mesh(counts, lengths, origin=(lengths[0] + gap, 0.0, 0.0))
    count = len(a_nodes)
    return write_deck(
        path,
        "*TITLE\ntwo blocks head on",
        "*CONTROL_TERMINATION\n" + fields(end_time),
        "*DATABASE_RCFORC\n" + fields(end_time / 200, 3),
        "*DATABASE_BINARY_D3PLOT\n" + fields(end_time / 4),
        "*PART\nleft\n" + fields(1, 1, 1),
        "*PART\nright\n" + fields(2, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_ELASTIC\n" + fields(1, DENSITY, MODULUS, POISSON),
        node_list_set(1, list(range(1, count + 1))),
        node_list_set(2, list(range(count + 1, 2 * count + 1))),
        "*INITIAL_VELOCITY\n" + fields(1) + "\n" + fields(speed, 0.0, 0.0),
        "*INITIAL_VELOCITY\n" + fields(2) + "\n" + fields(-speed, 0.0, 0.0),
        "*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE_ID\n" + fields(5) + "blocks\n" + fields(1, 2, 3, 3) + "\n" +
        fields(0.0) + "\n" + fields(1.0),
        nodes_card(np.vstack([a_nodes, b_nodes])),
        solids_card(a_elements, part_id=1) + "\n" +
        "\n".join(solids_card(b_elements, part_id=2, first_id=len(a_elements) + 1,
                              first_node_id=count + 1).splitlines()[1:]),
    )


def test_contact_forces_both_sides(tmp_path, run_deck):
    run = run_deck(head_on_deck(tmp_path / "head_on.k"), jobid="crash")
    assert run.status == 0, run.stderr
    directory = run.results.parent
    # named as LS-DYNA names the files of a job; glstat and matsum (BINARY blank) are not in it
    assert (directory / "crash.binout").exists() and not (directory / "binout").exists()
    binout = lasso_binout.Binout(str(directory / "crash.binout"))
    assert binout.read() == ["rcforc"]
    assert list(binout.read("rcforc", "ids")) == [5, 5]
    assert list(binout.read("rcforc", "side")) == [0, 1]
    with run.open() as results:
        force = results["history/rcforc/5/force"][...]
        time = results["history/rcforc/5/time"][...]
    np.testing.assert_array_equal(binout.read("rcforc", "time"), time)
    x_force = binout.read("rcforc", "x_force")
    np.testing.assert_array_equal(x_force[:, 0], force[:, 0])
    np.testing.assert_array_equal(x_force[:, 1], -force[:, 0])
    frame = binout.as_df("rcforc", "x_force")
    assert list(frame.columns) == ["5s", "5m"]
    # the secondary block (moving +x) is stopped and thrown back: impulse -2 m v
    mass = DENSITY * 40.0 * 5.0 * 5.0
    impulse = (x_force[1:, 0] * np.diff(time)).sum()
    assert abs(impulse + 2.0 * mass * 1.0) < 0.02 * 2.0 * mass
    check_against_record_walk(directory / "crash.binout", binout)


def test_rigid_body_motion(tmp_path, run_deck):
    """A free rigid block (*MAT_RIGID) at (3, -2, 1) mm/ms: rbdout's velocities are constant and
    its displacements v t, equal to results.h5's rbdout."""
    velocity = (3.0, -2.0, 1.0)
    nodes, elements = block_mesh((2, 2, 2), (20.0, 30.0, 50.0))
    deck = write_deck(
        tmp_path / "rigid.k",
        "*CONTROL_TERMINATION\n" + fields(2.0),
        "*DATABASE_RBDOUT\n" + fields(0.1, 2),
        "*PART\nblock\n" + fields(4, 1, 1),
        "*SECTION_SOLID\n" + fields(1, 1),
        "*MAT_RIGID\n" + fields(1, DENSITY, 210.0, POISSON) + "\n" + fields(0.0, 0.0, 0.0) + "\n" + fields(0.0),
        "*INITIAL_VELOCITY\n" + fields(0) + "\n" + fields(*velocity),
        nodes_card(nodes),
        solids_card(elements, part_id=4),
    )
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    binout = lasso_binout.Binout(str(run.results.parent / "binout"))
    assert binout.read() == ["rbdout"]
    assert list(binout.read("rbdout", "ids")) == [4]
    with run.open() as results:
        rbdout = results["history/rbdout/4"]
        time = rbdout["time"][...]
        displacement, body_velocity = rbdout["displacement"][...], rbdout["velocity"][...]
    np.testing.assert_array_equal(binout.read("rbdout", "time"), time)
    assert len(time) >= 20, "the *DATABASE_RBDOUT interval, 0.1 ms over 2 ms"
    for axis, letter in enumerate("xyz"):
        np.testing.assert_array_equal(binout.read("rbdout", f"global_d{letter}"), displacement[:, axis])
        np.testing.assert_array_equal(binout.read("rbdout", f"global_v{letter}"), body_velocity[:, axis])
        np.testing.assert_allclose(binout.read("rbdout", f"global_v{letter}"), velocity[axis], rtol=1e-12)
        np.testing.assert_allclose(binout.read("rbdout", f"global_d{letter}"), velocity[axis] * time,
                                   rtol=1e-9, atol=1e-12)
    check_against_record_walk(run.results.parent / "binout", binout)


def test_restart_writes_the_binout_of_the_uninterrupted_run(tmp_path, run_deck):
    """r= from a dump in the middle of the run: binout is written again from the histories the
    dump holds plus the rest of the run, every variable equal to the uninterrupted run's."""
    deck, _ = wall_deck(tmp_path / "dumped.k")
    deck.write_text(deck.read_text().replace("*DATABASE_BINARY_D3PLOT", "*DATABASE_BINARY_D3DUMP\n" + fields(10) +
                                             "\n*DATABASE_BINARY_D3PLOT"))
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    directory = run.results.parent
    dumps = sorted(directory.glob("d3dump*"))
    assert len(dumps) >= 2
    continued = tmp_path / "continued"
    shutil.copytree(directory, continued)
    (continued / "binout").unlink()
    dump = continued / dumps[len(dumps) // 2].name
    process = subprocess.run([str(BINARY), f"r={dump}", "ncpu=1"], capture_output=True, text=True, timeout=300,
                             env=dict(os.environ, OMP_NUM_THREADS="1"))
    assert process.returncode == 0, process.stdout + process.stderr
    reference, restarted = walk_records(directory / "binout"), walk_records(continued / "binout")
    assert reference.keys() == restarted.keys()
    for name, (type_id, values, _) in reference.items():
        assert restarted[name][:2] == (type_id, values), name


def test_no_binout_unless_asked(tmp_path, run_deck):
    deck, _ = wall_deck(tmp_path / "ascii.k", binary=(None, 1, 0, 1))
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    assert not list(run.results.parent.glob("*binout*"))


def test_binary_out_of_range_refused(tmp_path, run_deck):
    deck, _ = wall_deck(tmp_path / "bad.k", binary=(2, 4, 2, 2))
    run = run_deck(deck)
    assert run.status == 2
    line = next(number for number, text in enumerate(deck.read_text().splitlines(), 1)
                if text.startswith("*DATABASE_MATSUM")) + 1
    assert f"bad.k:{line}:" in run.stderr and "*DATABASE_MATSUM" in run.stderr and "BINARY" in run.stderr


# --- an independent reader: the records in file order -------------------------------------------

TYPES = {1: "b", 2: "h", 3: "i", 4: "q", 5: "B", 6: "H", 7: "I", 8: "Q", 9: "f", 10: "d"}
SIZES = {1: 1, 2: 2, 3: 4, 4: 8, 5: 1, 6: 2, 7: 4, 8: 8, 9: 4, 10: 8}


def walk_records(path):
    """{'/dir/name': (type id, values, offset)} from the CD and DATA records in file order;
    also checks the header, that the records fill the file exactly, and the symbol tables."""
    data = path.read_bytes()
    assert data[:8] == bytes([8, 8, 8, 1, 1, 1, 0, 0]), "header: 8-byte lengths and offsets, little endian"
    variables, tables = {}, {}
    directory = "/"
    position = 8
    while position < len(data):
        length, command = struct.unpack_from("<qB", data, position)
        assert 9 <= length <= len(data) - position, f"record at {position}: length {length}"
        body = data[position + 9:position + length]
        if command == 2:       # CD
            target = body.decode()
            directory = target if target.startswith("/") else directory.rstrip("/") + "/" + target
        elif command == 3:     # DATA
            type_id, name_length = body[0], body[1]
            name = body[2:2 + name_length].decode()
            raw = body[2 + name_length:]
            assert len(raw) % SIZES[type_id] == 0
            values = struct.unpack(f"<{len(raw) // SIZES[type_id]}{TYPES[type_id]}", raw)
            variables[directory.rstrip("/") + "/" + name] = (type_id, values, position)
        elif command == 5:     # BEGINSYMBOLTABLE: its length covers the table to its END's offset
            end = position + length
            assert struct.unpack_from("<qB", data, end - 17) == (17, 6)
            tables[position] = struct.unpack_from("<q", data, end - 8)[0]
            table_directory = "/"
            inner = position + 9
            while inner < end - 17:
                inner_length, inner_command = struct.unpack_from("<qB", data, inner)
                text = data[inner + 9:inner + inner_length]
                if inner_command == 2:
                    table_directory = text.decode()
                else:
                    assert inner_command == 4
                    name = text[:-17].decode()
                    type_id, offset, count = struct.unpack_from("<Bqq", text, len(text) - 17)
                    tables.setdefault("entries", []).append((table_directory + "/" + name, type_id, offset, count))
                inner += inner_length
            assert inner == end - 17
            length = end - position
        elif command == 7:     # SYMBOLTABLEOFFSET: the offset of the first symbol table
            tables["first"] = struct.unpack_from("<q", body)[0]
        else:
            pytest.fail(f"unexpected command {command} at {position}")
        position += length
    assert position == len(data), "the records end with the file"
    # the symbol tables form one chain from the header, and their entries point at the DATA records
    link, chained = tables["first"], 0
    while link:
        assert link in tables
        link, chained = tables[link], chained + 1
    assert chained == len([key for key in tables if isinstance(key, int)])
    assert len(tables["entries"]) == len(variables)
    for name, type_id, offset, count in tables["entries"]:
        assert variables[name][0] == type_id and variables[name][2] == offset and len(variables[name][1]) == count
    return variables


def check_against_record_walk(path, binout):
    """Every variable of the record walk equals what lasso-python reads from the same path."""
    variables = walk_records(path)
    for name, (type_id, values, _) in variables.items():
        parts = name.strip("/").split("/")
        symbol = binout.lsda_root
        for part in parts:
            # (lasso-python keys directories by str, variables by bytes)
            symbol = symbol.children[part] if part in symbol.children else symbol.children[part.encode()]
        assert tuple(symbol.read()) == values, name
    # glstat's kinetic energy over the samples, both ways (the directories in order)
    if "/glstat/d000001/kinetic_energy" in variables:
        walked = [values[0] for key, (_, values, _) in sorted(variables.items())
                  if key.startswith("/glstat/d") and key.endswith("/kinetic_energy")]
        np.testing.assert_array_equal(walked, binout.read("glstat", "kinetic_energy"))
