"""The embedding library (docs/embedding.md) as a host code sees it: `make examples` installs
libcrashfree_efg.a, crashfree_efg.h, crashfree_efg.mod and crashfree-efg.pc into a temporary
prefix and builds the two example host codes (examples/host_fortran, examples/host_c) against it
with pkg-config only. Their runs must show:

- the library needs no HDF5 and no METIS (the host links only what the API uses);
- the host's explicit patch test: a block of the host's own hexahedra with a meshfree region
  (irregular mesh), v = A X on every node and on the block's surface for 100 cycles: every
  node, particles through cf_efg_to_physical, still moves with A X (1e-10 relative), and the
  part's row-sum masses add up to density times its volume (1e-12);
- the host's coupled bar: a smooth pulse crosses the host-element / meshfree interface with a
  reflection below 1% of the incident amplitude;
- the part with the host's own elastic law (cf_efg_set_material_callback) passes the patch test
  and carries the same waves as with the library's law;
- the same part as a keyword deck: the solver's accelerations after its first cycle equal the
  host's -f/m from one cf_efg_internal_force call to round-off, and its step is 0.9 times the
  part's stable step;
- the C and the Fortran host give the same numbers, and one or two threads the same bits;
- calls in error through the C interface (null and destroyed handles, null arrays, a node that
  does not exist, an inside-out hexahedron, support <= 1, the wrong order) each give their
  status and a message naming the argument, with the release and the checked debug library.
"""
import os
import subprocess

import numpy as np
import pytest

from conftest import REPOSITORY
from deck_writer import efg_section, fields, nodes_card, solids_card, write_deck

HOSTS = ["host_fortran", "host_c"]


def install_and_build(prefix, mode):
    built = subprocess.run(["make", "--no-print-directory", "-s", f"MODE={mode}", "examples",
                            f"EXAMPLES_PREFIX={prefix}", f"EXAMPLES_OUT={prefix / 'bin'}"], cwd=REPOSITORY,
                           capture_output=True, text=True, timeout=1800)
    assert built.returncode == 0, built.stdout + built.stderr
    return prefix


@pytest.fixture(scope="module")
def hosts(tmp_path_factory):
    """The installed prefix (release library) and the two host programs built against it."""
    return install_and_build(tmp_path_factory.mktemp("prefix"), "release")


@pytest.fixture(scope="module")
def debug_hosts(tmp_path_factory):
    """The same with the checked library of MODE=debug (-fcheck=all, -ffpe-trap): `make test`
    has built its objects for the unit tests already."""
    return install_and_build(tmp_path_factory.mktemp("debug_prefix"), "debug")


def run_host(prefix, host, *arguments, threads=1):
    process = subprocess.run([str(prefix / "bin" / host), *map(str, arguments)], capture_output=True, text=True,
                             env=dict(os.environ, OMP_NUM_THREADS=str(threads)), timeout=120)
    assert process.returncode == 0, process.stdout + process.stderr
    return process.stdout


def rows(output):
    """The host's output lines by their first word."""
    found = {}
    for line in output.splitlines():
        words = line.split()
        found.setdefault(words[0], []).append(words[1:])
    return found


def test_library_needs_no_hdf5_or_metis(hosts):
    undefined = subprocess.run(["nm", "-u", str(hosts / "lib" / "libcrashfree_efg.a")], capture_output=True,
                               text=True, check=True).stdout.lower()
    assert "h5" not in undefined and "metis" not in undefined
    flags = subprocess.run(["pkg-config", "--cflags", "--libs", "crashfree-efg"], capture_output=True, text=True,
                           check=True, env=dict(os.environ, PKG_CONFIG_PATH=str(hosts / "lib" / "pkgconfig"))).stdout
    assert "-lcrashfree_efg" in flags and "hdf5" not in flags and "metis" not in flags
    assert (hosts / "include" / "crashfree_efg.h").is_file()
    assert (hosts / "include" / "crashfree" / "crashfree_efg.mod").is_file()


@pytest.mark.parametrize("host", HOSTS)
@pytest.mark.parametrize("support, kernel, law", [(1.5, 0, "library"), (1.01, 0, "library"), (1.2, 2, "library"),
                                                  (1.5, 0, "host-law")],
                         ids=["box-1.5", "box-1.01", "sphere-1.2", "box-1.5-host-law"])
def test_explicit_patch_test_of_the_host(hosts, host, support, kernel, law):
    # host-law: the part computes its stresses with the host's own law, through the callback
    result = rows(run_host(hosts, host, "patch", support, kernel, law))
    nodes, particles, boundary, points = map(int, result["counts"][0])
    assert particles == 32 and nodes == 144 and points == 8 * 75
    mass_error = float(result["mass_error"][0][0])
    velocity_error = float(result["velocity_error"][0][0])
    assert mass_error < 1e-12, f"sum of the part's masses off by {mass_error:.2e} of density x volume"
    assert velocity_error < 1e-10, f"velocity error {velocity_error:.2e} after 100 cycles"


def bar_figures(output):
    """Incident amplitude at the probe in the host's elements, the largest velocity there while
    a reflection from the interface could pass it, and the transmitted amplitude in the part."""
    result = rows(output)
    speed = float(result["wave_speed"][0][0])
    probe, _, interface, duration = map(float, result["probes_interface_pulse"][0])
    time, incident_probe, transmitted_probe = np.array(result["sample"], float).T
    incident = np.abs(incident_probe[time < probe / speed + duration + 0.002]).max()
    back = (2.0 * interface - probe) / speed
    reflected = np.abs(incident_probe[(time > back - 0.001) & (time < back + duration + 0.002)]).max()
    return incident, reflected, np.abs(transmitted_probe).max(), time


@pytest.mark.parametrize("host", HOSTS)
def test_wave_crosses_the_host_interface_without_reflection(hosts, host):
    output = run_host(hosts, host, "bar")
    incident, reflected, transmitted, time = bar_figures(output)
    assert time.max() > 0.022
    assert incident > 0.9, f"incident amplitude {incident:.3f} (driven with 1)"
    assert reflected < 0.01 * incident, f"reflection {100 * reflected / incident:.2f}% of the incident pulse"
    assert transmitted > 0.9 * incident, f"transmitted {transmitted:.3f} against incident {incident:.3f}"
    # the host's own elastic law through the material callback: the same waves to round-off
    library = np.array(rows(output)["sample"], float)
    host_law = np.array(rows(run_host(hosts, host, "bar", "host-law"))["sample"], float)
    assert library.shape == host_law.shape
    assert np.abs(library - host_law).max() < 1e-12


def forces_deck(path, output):
    """The host's all-meshfree block as a keyword deck: its nodes and hexahedra, the same section
    and material, its velocities as initial velocities, one cycle, every node in nodout."""
    result = rows(output)
    nodes = np.array(result["node"], float)
    coordinates, velocity = nodes[:, 1:4], nodes[:, 4:7]
    hexahedra = np.array(result["hexahedron"], int)[:, 1:] - 1
    # the host keeps coordinates and velocities short binary fractions: the cards hold them exactly
    assert all(float(f"{x:16.9e}") == x for x in coordinates.ravel())
    assert all(float(f"{v:20.13e}") == v for v in velocity.ravel())
    ids = list(range(1, len(coordinates) + 1))
    initial = ["*INITIAL_VELOCITY_NODE+"] + [f"{k + 1:20d}{v[0]:20.13e}{v[1]:20.13e}{v[2]:20.13e}"
                                             for k, v in enumerate(velocity)]
    return write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(1.0, 1),
        "*DATABASE_NODOUT\n" + fields(1.0e-9),
        "*DATABASE_HISTORY_NODE\n" + "\n".join(fields(*ids[k:k + 8]) for k in range(0, len(ids), 8)),
        "*PART\nmeshfree block\n" + fields(1, 1, 1),
        efg_section(1, 1.5, 0),
        "*MAT_ELASTIC\n" + fields(1, 7.85e-6, 210.0, 0.3),
        nodes_card(coordinates),
        solids_card(hexahedra),
        "\n".join(initial),
    ), len(ids)


def test_host_forces_equal_the_solvers(hosts, tmp_path, run_deck):
    deck, node_count = forces_deck(tmp_path / "block.k", run_host(hosts, "host_fortran", "forces", 0))
    run = run_deck(deck)
    assert run.status == 0, run.stdout + run.stderr
    with run.open() as results:
        assert results["run"].attrs["cycles"] == 1
        nodout = results["history/nodout"]
        step = float(nodout["1"]["time"][-1])
        solver = np.array([nodout[str(k)]["acceleration"][-1] for k in range(1, node_count + 1)])
    result = rows(run_host(hosts, "host_fortran", "forces", repr(step)))
    host = np.array(result["node"], float)[:, 11:14]
    assert np.abs(solver).max() > 1e3, "the block must be loaded"
    difference = np.abs(host - solver).max() / np.abs(solver).max()
    assert difference < 1e-13, f"host and solver accelerations differ by {difference:.2e}"
    part_step = float(result["stable_dt"][0][0])
    assert abs(step - 0.9 * part_step) < 1e-14 * step, f"solver step {step} against 0.9 x {part_step}"


def test_c_and_fortran_hosts_agree(hosts):
    fortran = rows(run_host(hosts, "host_fortran", "forces", 1.0e-4))
    c = rows(run_host(hosts, "host_c", "forces", 1.0e-4))
    assert fortran["counts"] == c["counts"]
    assert fortran["hexahedron"] == c["hexahedron"]
    a, b = np.array(fortran["node"], float), np.array(c["node"], float)
    assert np.abs(a - b).max() <= 1e-14 * np.abs(a).max()
    # the bar: the same host model in two languages (their element loops sum in other orders)
    fortran_bar, c_bar = bar_figures(run_host(hosts, "host_fortran", "bar")), bar_figures(run_host(hosts, "host_c", "bar"))
    assert len(fortran_bar[3]) == len(c_bar[3])
    for x, y in zip(fortran_bar[:3], c_bar[:3]):
        assert abs(x - y) < 1e-9, f"{x} against {y}"


@pytest.mark.parametrize("host", HOSTS)
def test_one_and_two_threads_give_the_same_bits(hosts, host):
    assert run_host(hosts, host, "forces", 1.0e-4, threads=1) == run_host(hosts, host, "forces", 1.0e-4, threads=2)


# host_c misuse: each call in error, the status it must give and a word its message must hold
MISUSE = {
    "null_handle": (3, "null"),
    "null_coordinates": (1, "coordinates"),
    "wrong_size": (1, "coordinates"),
    "node_out_of_range": (1, "hexahedra(3, 17)"),
    "inside_out": (4, "hexahedra(:, 5)"),
    "support_not_above_one": (1, "support(2)"),
    "kernel": (1, "kernel"),
    "create_on_live_handle": (2, "already created"),
    "mark_out_of_range": (1, "nodes(1)"),
    "force_before_set_up": (2, "cf_efg_set_up first"),
    "set_up_twice": (2, "cf_efg_set_up"),
    "force_without_law": (2, "material law"),
    "elastic_poisson": (1, "poisson"),
    "null_force": (1, "force"),
    "destroyed_handle": (3, "null"),
    "destroy_twice": (3, "null"),
}


@pytest.mark.parametrize("build", ["hosts", "debug_hosts"], ids=["release", "debug"])
def test_c_calls_in_error_give_a_status_and_a_message(request, build):
    prefix = request.getfixturevalue(build)
    found = {words[0]: (int(words[1]), " ".join(words[2:])) for words in rows(run_host(prefix, "host_c", "misuse"))["misuse"]}
    assert found.keys() == MISUSE.keys()
    for case, (status, word) in MISUSE.items():
        assert found[case][0] == status, f"{case}: status {found[case][0]} ({found[case][1]})"
        assert word in found[case][1], f"{case}: the message does not name {word!r}: {found[case][1]}"


@pytest.mark.parametrize("host", HOSTS)
def test_the_checked_library_runs_the_hosts(debug_hosts, host):
    # -fcheck=all and -ffpe-trap in the library, two threads: no bound or floating-point fault
    # in a patch test with the host's law and the bar
    result = rows(run_host(debug_hosts, host, "patch", 1.2, 2, "host-law", threads=2))
    assert float(result["velocity_error"][0][0]) < 1e-10
    incident, reflected, _, _ = bar_figures(run_host(debug_hosts, host, "bar", threads=2))
    assert reflected < 0.01 * incident
