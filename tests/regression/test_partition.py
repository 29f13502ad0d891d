"""The domain partition for MPI runs (partition=N: computed after the set-up, reported, nothing run).

A small mixed model: a block of FE hexahedra, a meshfree (EFG) block sharing its nodes on one
face, and FE shells on its bottom face. For N = 2, 3, 4 ranks:
- every element belongs to exactly one rank (solid_rank, shell_rank in 0..N-1; the counts per
  rank add up to the model's), by METIS (on the element graph or on the blocks' graph, whichever
  leaves the smaller largest computed cost), and the same partition on a second run;
- the imbalance (largest / mean estimated cost of the owned blocks) stays below
  1.03 + largest block cost / mean rank cost: METIS balances the element costs to within its
  default 3% (UFACTOR 30), and a block (64 lanes of one part, the unit a rank computes) goes
  whole to the rank owning most of its lanes, which moves at most about one block's cost onto
  a rank beyond METIS's balance;
- node owners follow the rule: a node belongs to one of the ranks owning a block touching it, so
  on nodes only FE elements touch (their blocks' nodes are their corners) it is the rank of one
  of the elements on it, and the element's rank on nodes of one rank's elements; every rank owns
  a node;
- the interface nodes are spread over the ranks touching them so that the busiest rank's
  computed cost (owned blocks and the ghost blocks computed for its nodes) stays within 15% of
  the mean (with every interface node on the lowest touching rank, the former rule: 1.29, 1.32
  and 1.92 at N = 2, 3, 4), and every rank computes ghost blocks (the former rule left the
  highest rank none); on a slab of 128 solid blocks at 16 ranks, within 25% (before: 1.56);
- the partition is printed and recorded in results.h5 (/run/partition) and d3hsp.
Also: more ranks than blocks is refused (exit status 2, both numbers named); LS-DYNA's memory=,
memory2= and pfile= are accepted with a note; this build (without MPI) started by an MPI
launcher as several processes refuses to run (exit status 2) instead of running the job N times
into the same files.
"""
import os
import subprocess

import h5py
import numpy as np
import pytest

from conftest import BINARY
from deck_writer import block_mesh, efg_section, fields, nodes_card, shells_card, solids_card, write_deck

LANES = 64                 # block_size: lanes of one block
LARGEST_LANE_COST = 450.0  # ns per cycle of a meshfree lane, the dearest kind here (domain_partition lane_cost)


def mixed_deck(path):
    """Hexahedra 16 x 6 x 4 over 80 x 30 x 20 mm: x > 56 meshfree (part 1), the rest FE (part 2);
    shells on z = 0 under the FE cells (part 3)."""
    nodes, elements = block_mesh((16, 6, 4), (80.0, 30.0, 20.0))
    centres = nodes[elements].mean(axis=1)
    meshfree = centres[:, 0] > 56.0
    bottom = elements[~meshfree & (centres[:, 2] < 2.6)][:, :4]
    cards = solids_card(elements[meshfree], part_id=1)
    cards += "\n" + solids_card(elements[~meshfree], part_id=2, first_id=10001).split("\n", 1)[1]
    deck = write_deck(
        path,
        "*CONTROL_TERMINATION\n" + fields(1.0),
        "*PART\nmeshfree\n" + fields(1, 1, 1),
        "*PART\nfinite elements\n" + fields(2, 2, 1),
        "*PART\nshells\n" + fields(3, 3, 1),
        efg_section(1, 1.5),
        "*SECTION_SOLID\n" + fields(2, 1),
        "*SECTION_SHELL\n" + fields(3, 2) + "\n" + fields(1.0, 1.0, 1.0, 1.0),
        "*MAT_ELASTIC\n" + fields(1, 7.85e-6, 210.0, 0.3),
        nodes_card(nodes),
        cards,
        shells_card(bottom, part_id=3, first_id=20001),
    )
    return deck, nodes, elements, meshfree, bottom


def run(arguments, directory, environment=None, binary=BINARY):
    directory.mkdir(exist_ok=True)
    env = dict(os.environ if environment is None else environment, OMP_NUM_THREADS="1")
    return subprocess.run([str(binary), *arguments, f"outdir={directory}", "ncpu=1"], capture_output=True,
                          text=True, timeout=120, env=env)


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    return mixed_deck(tmp_path_factory.mktemp("partition") / "mixed.k")


@pytest.mark.parametrize("ranks", [2, 3, 4])
def test_partition_of_a_mixed_model(tmp_path, model, ranks):
    deck, nodes, elements, meshfree, bottom = model
    process = run([f"i={deck}", f"partition={ranks}"], tmp_path / "first")
    assert process.returncode == 0, process.stdout + process.stderr
    assert f"domain partition: {ranks} ranks, METIS k-way" in process.stdout
    assert "nothing was run" in process.stdout
    with h5py.File(tmp_path / "first" / "results.h5", "r") as results:
        assert results["run"].attrs["cycles"] == 0
        partition = results["run/partition"]
        assert partition.attrs["rank_count"] == ranks
        assert partition.attrs["method"] in ("metis_kway_elements", "metis_kway_blocks")
        data = {name: partition[name][()] for name in partition}
        imbalance = partition.attrs["imbalance"]
    solid_rank, shell_rank, node_rank = data["solid_rank"], data["shell_rank"], data["node_rank"]

    # every element on exactly one rank, and the counts per rank add up
    assert solid_rank.shape == (len(elements),) and shell_rank.shape == (len(bottom),)
    assert solid_rank.min() >= 0 and solid_rank.max() < ranks
    assert shell_rank.min() >= 0 and shell_rank.max() < ranks
    kinds = [name.decode() for name in data["kind_names"]]
    assert kinds == ["solid", "shell", "meshfree"]
    per_rank = data["rank_elements"]                          # (ranks, kinds)
    assert per_rank.sum(axis=0).tolist() == [int((~meshfree).sum()), len(bottom), int(meshfree.sum())]
    # the deck's solids: meshfree cells first (ids 1...), then the FE ones (10001...)
    ordered_ranks = np.concatenate([solid_rank[:meshfree.sum()], solid_rank[meshfree.sum():]])
    for rank in range(ranks):
        assert per_rank[rank].sum() == (ordered_ranks == rank).sum() + (shell_rank == rank).sum()

    # balance within METIS's tolerance plus one block
    cost = data["rank_cost"]
    bound = 1.03 + LANES * LARGEST_LANE_COST / cost.mean()
    assert imbalance == pytest.approx(cost.max() / cost.mean())
    assert imbalance < bound, f"imbalance {imbalance:.3f} above {bound:.3f}"
    assert (data["rank_blocks"] > 0).all()

    # node owners: a rank owning an element on the node where only FE elements touch it (the
    # meshfree blocks' nodes reach beyond their cells), that rank where all its elements agree
    solid_ids = np.concatenate([np.flatnonzero(meshfree), np.flatnonzero(~meshfree)])
    element_rank_of_solid = np.empty(len(elements), int)
    element_rank_of_solid[solid_ids] = solid_rank
    touching = np.zeros((len(nodes), ranks), bool)
    touched_by_meshfree = np.zeros(len(nodes), bool)
    for corners, rank, is_meshfree in zip(elements, element_rank_of_solid, meshfree):
        if is_meshfree:
            touched_by_meshfree[corners] = True
        touching[corners, rank] = True
    for corners, rank in zip(bottom, shell_rank):
        touching[corners, rank] = True
    fe_only = ~touched_by_meshfree
    assert touching[np.flatnonzero(fe_only), node_rank[fe_only]].all()
    one_rank = fe_only & (touching.sum(axis=1) == 1)
    assert (node_rank[one_rank] == touching[one_rank].argmax(axis=1)).all()

    # the ghost blocks spread: the busiest rank's computed cost near the mean, ghosts on every rank
    computed = data["rank_computed_cost"]
    assert partition_computed_imbalance(tmp_path / "first") == pytest.approx(computed.max() / computed.mean())
    assert computed.max() / computed.mean() < 1.15, f"computed imbalance {computed.max() / computed.mean():.3f}"
    assert (data["rank_ghost_blocks"] > 0).all(), data["rank_ghost_blocks"]
    assert data["rank_owned_nodes"].sum() == len(nodes)
    assert (data["rank_owned_nodes"] > 0).all()
    assert (np.bincount(node_rank, minlength=ranks) == data["rank_owned_nodes"]).all()

    # the same partition again (every rank computes it alike), and in d3hsp
    again = run([f"i={deck}", f"partition={ranks}"], tmp_path / "second")
    assert again.returncode == 0, again.stderr
    with h5py.File(tmp_path / "second" / "results.h5", "r") as results:
        for name in ["solid_rank", "shell_rank", "node_rank", "rank_blocks", "rank_ghost_blocks"]:
            assert (results["run/partition"][name][()] == data[name]).all(), name
    d3hsp = (tmp_path / "first" / "d3hsp").read_text()
    assert "d o m a i n   p a r t i t i o n" in d3hsp and f"{ranks} ranks" in d3hsp


def partition_computed_imbalance(directory):
    with h5py.File(directory / "results.h5", "r") as results:
        return results["run/partition"].attrs["computed_imbalance"]


def test_ghost_blocks_of_a_slab_spread_over_sixteen_ranks(tmp_path):
    """32 x 32 x 8 hexahedra (128 blocks of one part) over 16 ranks: every rank owns interface
    nodes and computes ghost blocks, the busiest computed cost within 25% of the mean (with the
    former lowest-rank rule 1.56: the highest rank computed no ghost block, the lowest ones most)."""
    nodes, elements = block_mesh((32, 32, 8), (320.0, 320.0, 80.0))
    deck = write_deck(tmp_path / "slab.k", "*CONTROL_TERMINATION\n" + fields(1.0), "*PART\nslab\n" + fields(1, 1, 1),
                      "*SECTION_SOLID\n" + fields(1, 1), "*MAT_ELASTIC\n" + fields(1, 7.85e-6, 210.0, 0.3),
                      nodes_card(nodes), solids_card(elements, part_id=1))
    process = run([f"i={deck}", "partition=16"], tmp_path / "slab")
    assert process.returncode == 0, process.stdout + process.stderr
    with h5py.File(tmp_path / "slab" / "results.h5", "r") as results:
        partition = results["run/partition"]
        ghosts = partition["rank_ghost_blocks"][()]
        interface = partition["rank_interface_nodes"][()]
        computed = partition["rank_computed_cost"][()]
        assert partition["rank_blocks"][()].sum() == 128
    assert (ghosts > 0).all(), ghosts
    assert (interface > 0).all()
    assert computed.max() / computed.mean() < 1.25, f"computed imbalance {computed.max() / computed.mean():.3f}"


def test_too_many_ranks_are_refused(tmp_path, model):
    deck = model[0]
    process = run([f"i={deck}", "partition=1000"], tmp_path)
    assert process.returncode == 2, process.stdout + process.stderr
    assert "1000 ranks are more than the model's" in process.stderr
    assert "element blocks" in process.stderr


def test_lsdyna_memory_and_pfile_are_accepted(tmp_path, model):
    deck = model[0]
    process = run([f"i={deck}", "partition=2", "memory=200m", "memory2=50m", "pfile=decomposition.txt"], tmp_path)
    assert process.returncode == 0, process.stdout + process.stderr
    for argument in ["memory=200m", "memory2=50m", "pfile=decomposition.txt"]:
        assert f"{argument}: ignored" in process.stderr


def serial_binary():
    """A build without MPI: bin/crashfree when it is one, else the MPI=no build if it was made."""
    for binary in (BINARY, BINARY.parents[1] / "build" / "release-serial" / "bin" / "crashfree"):
        if binary.exists():
            linked = subprocess.run(["ldd", str(binary)], capture_output=True, text=True).stdout
            if "libmpi" not in linked:
                return binary
    return None


@pytest.mark.parametrize("variable", ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE"])
def test_started_by_mpirun_without_mpi(tmp_path, model, variable):
    # (an MPI build takes the launcher's variables as MPI's own; tests/unit/test_domain_partition
    # checks the rule of check_launch for both builds)
    binary = serial_binary()
    if binary is None:
        pytest.skip("no build without MPI here (make MPI=no makes one)")
    deck = model[0]
    environment = {k: v for k, v in os.environ.items() if k not in ("OMPI_COMM_WORLD_SIZE", "PMI_SIZE")}
    process = run([f"i={deck}"], tmp_path / "several", dict(environment, **{variable: "3"}), binary)
    assert process.returncode == 2, process.stdout + process.stderr
    assert "built without MPI" in process.stderr and "3 processes" in process.stderr
    assert not (tmp_path / "several" / "results.h5").exists()
    # one process under a launcher is an ordinary run
    single = run([f"i={deck}", "partition=2"], tmp_path / "single", dict(environment, **{variable: "1"}), binary)
    assert single.returncode == 0, single.stderr
