"""LS-DYNA's reading conventions: a deck written for LS-DYNA runs unchanged.

- A blank line is a card: where a definition needs a card, a blank one takes the defaults of
  all its fields, also when it is the keyword's last line (the blank lines before the next
  keyword); between the data lines of a keyword whose cards repeat, blank lines define nothing.
  Checked by running a deck with blank cards and the same deck with the defaults written out:
  the results files are the same bit for bit.
- Zero means default: *SECTION_SOLID ELFORM 0 is 1, *SECTION_SHELL ELFORM 0 is 2.
- Display and bookkeeping keywords (*DATABASE_EXTENT_BINARY, *CONTROL_PARALLEL, *SENSOR_DEFINE_,
  *PART_CONTACT ...) are read, noted as not acted upon, and change no result.
- --ignore-unknown skips only keywords crashfree does not read at all, and never their cards.
- LS-DYNA's command line: a bare deck name, memory=, memory2=, d=nodump, s=, ncpu=-N.

Each run is a unit cube of one hexahedron (or a plate of four shells) of elastic steel (mm, ms,
kg, GPa) whose one face is thrown outwards at 1 m/s: it rings in its stretching mode, which
the element formulation and every default reach.
"""
import os
import subprocess
from pathlib import Path

import h5py
import numpy as np
import pytest

REPOSITORY = Path(__file__).resolve().parents[2]
BINARY = Path(os.environ.get("CRASHFREE", REPOSITORY / "bin" / "crashfree"))
DENSITY = 7.85e-6      # kg/mm^3
SPEED = 1.0            # mm/ms of the thrown face

# The unit cube; {placeholders} are filled per test. The nodes of face x = 1 (2 3 6 7) start at
# SPEED in x through *INITIAL_VELOCITY_GENERATION on a node set.
CUBE = """*KEYWORD
*TITLE
one element
*CONTROL_TERMINATION
       0.2
{timestep}{energy}*DATABASE_GLSTAT
      0.01
*DATABASE_BINARY_D3PLOT
       0.1
*PART
cube
         1         1         1
*SECTION_SOLID
{solid_section}
*MAT_ELASTIC
         1   7.85e-6     210.0       0.3
*NODE
       1             0.0             0.0             0.0
       2             1.0             0.0             0.0
       3             1.0             1.0             0.0
       4             0.0             1.0             0.0
{node_gap}       5             0.0             0.0             1.0
       6             1.0             0.0             1.0
       7             1.0             1.0             1.0
       8             0.0             1.0             1.0
{node_end}*ELEMENT_SOLID
       1       1       1       2       3       4       5       6       7       8
*SET_NODE_LIST
         1
         2         3         6         7
*INITIAL_VELOCITY_GENERATION
         1         3       0.0       1.0       0.0       0.0
{generation_card_2}{extra}*END
"""

WRITTEN_OUT = dict(
    timestep="*CONTROL_TIMESTEP\n       0.0       0.9\n",
    energy="*CONTROL_ENERGY\n         1         2\n",
    solid_section="         1         1",
    node_gap="",
    node_end="",
    generation_card_2="       0.0       0.0       0.0       0.0       0.0       0.0       0.0         0\n",
    extra="",
)

# The same cards left blank: the last card of a keyword, a keyword of one blank card, blank
# lines inside and after the *NODE lines, comment lines around them (not cards).
BLANK = dict(
    # card 1 blank in the middle (card 2, which crashfree does not read, follows)
    timestep="*CONTROL_TIMESTEP\n\n         0         0         0\n",
    energy="*CONTROL_ENERGY\n$ HGEN and RWEN: defaults\n          \n\n",
    solid_section="         1",
    node_gap="\n$ a comment\n   \n",
    node_end="\n\n",
    generation_card_2="$ card 2: no rotation, so its fields keep their defaults\n\n\n",
    extra="",
)

# Read, not acted upon: what a vehicle deck carries for LS-DYNA's own bookkeeping and output.
BOOKKEEPING = """*CONTROL_PARALLEL
         2         0         1
*CONTROL_OUTPUT
         1         3
*CONTROL_CPU
    3600.0
*CONTROL_SHELL
      20.0         1        -1         1         2         2         1
*CONTROL_SOLID
         1
*CONTROL_ACCURACY
         1         2
*DATABASE_EXTENT_BINARY
         0         0         3         1         0         0         0         0
         0         0         4         0         0         0
$ a blank third card
\x20
*DATABASE_FORMAT
         0
*DATABASE_BINARY_INTFOR
      0.01
*DATABASE_SPCFORC
      0.01
*DATABASE_SLEOUT
      0.01
*DATABASE_SECFORC
      0.01
*DATABASE_HISTORY_SOLID
         1
*CONTROL_MPP_DECOMPOSITION_AUTOMATIC
*CONTROL_MPP_IO_NODUMP
*DATABASE_RBDOUT
      0.01
*SENSOR_DEFINE_NODE_SET
         1      NODE         1         2         3
*SENSOR_DEFINE_FUNCTION
         2         1       2.0
         3         4
"""


def run(deck: Path, *arguments, directory: Path | None = None):
    """Run the solver on `deck` with `arguments` (default: i=deck outdir=<deck's dir>/out)."""
    directory = directory or deck.parent
    if not arguments:
        arguments = (f"i={deck}", f"outdir={directory / 'out'}", "ncpu=1")
    environment = dict(os.environ, OMP_NUM_THREADS="1")
    return subprocess.run([str(BINARY), *arguments], capture_output=True, text=True, timeout=120,
                          env=environment, cwd=directory)


def write(tmp_path: Path, name: str, text: str) -> Path:
    folder = tmp_path / name
    folder.mkdir()
    deck = folder / "deck.k"
    deck.write_text(text)
    return deck


def result_datasets(path: Path):
    """Every dataset of the mesh, states and histories: {name: values}."""
    found = {}
    with h5py.File(path, "r") as results:
        def keep(name, item):
            if isinstance(item, h5py.Dataset) and name.split("/")[0] in ("mesh", "states", "history"):
                found[name] = item[...]
        results.visititems(keep)
    return found


def assert_same_results(first: Path, second: Path):
    a, b = result_datasets(first), result_datasets(second)
    assert a.keys() == b.keys()
    for name in a:
        assert a[name].shape == b[name].shape, name
        if a[name].dtype.kind == "O":        # strings
            assert a[name].tolist() == b[name].tolist(), f"{name} differs"
        else:                                 # numbers: bit for bit
            assert a[name].tobytes() == b[name].tobytes(), f"{name} differs"


def check_stretching_cube(results: Path):
    """The thrown face's kinetic energy at t = 0 (half the lumped mass at SPEED) is conserved
    while the cube rings in x, and its centre of mass moves on at SPEED/2."""
    with h5py.File(results, "r") as f:
        glstat = f["history/glstat"]
        kinetic = glstat["kinetic_energy"][...]
        total = glstat["total_energy"][...]
        internal = glstat["internal_energy"][...]
        last = sorted(f["states"].keys())[-1]
        displacement = f["states"][last]["displacement"][...]
    expected = 0.5 * (DENSITY / 2.0) * SPEED ** 2
    assert kinetic[0] == pytest.approx(expected, rel=1e-12)
    assert np.max(internal) > 0.1 * expected             # it stretches ...
    assert np.allclose(total, expected, rtol=1e-3)       # ... elastically, energy conserved
    # the centre of mass moves at SPEED/2 in x: 0.1 mm at 0.2 ms (momentum is conserved)
    assert np.mean(displacement[:, 0]) == pytest.approx(0.5 * SPEED * 0.2, rel=1e-9)


def test_blank_cards_read_as_their_defaults(tmp_path):
    written = write(tmp_path, "written", CUBE.format(**WRITTEN_OUT))
    blank = write(tmp_path, "blank", CUBE.format(**BLANK))
    first, second = run(written), run(blank)
    assert first.returncode == 0, first.stderr
    assert second.returncode == 0, second.stderr
    check_stretching_cube(written.parent / "out" / "results.h5")
    assert_same_results(written.parent / "out" / "results.h5", blank.parent / "out" / "results.h5")
    # the blank lines in and after *NODE defined no node
    with h5py.File(blank.parent / "out" / "results.h5", "r") as f:
        assert list(f["mesh/nodes/ids"][...]) == list(range(1, 9))


def test_a_missing_card_is_still_reported(tmp_path):
    """Only a blank line is a card: a keyword that ends without it still lacks the card."""
    text = CUBE.format(**dict(BLANK, generation_card_2=""))
    deck = write(tmp_path, "missing", text)
    card_1 = text.splitlines().index("         1         3       0.0       1.0       0.0       0.0") + 1
    result = run(deck)
    assert result.returncode == 2
    assert f"deck.k:{card_1}: *INITIAL_VELOCITY_GENERATION: field XC: card 2" in result.stderr


def test_solid_elform_zero_is_one(tmp_path):
    decks = {name: write(tmp_path, name, CUBE.format(**dict(WRITTEN_OUT, solid_section=card)))
             for name, card in [("one", "         1         1"), ("zero", "         1         0"),
                                ("blank", "         1")]}
    for deck in decks.values():
        result = run(deck)
        assert result.returncode == 0, result.stderr
    check_stretching_cube(decks["one"].parent / "out" / "results.h5")
    for name in ("zero", "blank"):
        assert_same_results(decks["one"].parent / "out" / "results.h5", decks[name].parent / "out" / "results.h5")


PLATE = """*KEYWORD
*CONTROL_TERMINATION
       0.1
*DATABASE_GLSTAT
      0.01
*DATABASE_BINARY_D3PLOT
      0.05
*PART
plate
         1         1         1
*SECTION_SHELL
         1{elform}     0.833         3
       0.1       0.1       0.1       0.1
*MAT_ELASTIC
         1   7.85e-6     210.0       0.3
*NODE
       1             0.0             0.0             0.0
       2             1.0             0.0             0.0
       3             2.0             0.0             0.0
       4             0.0             1.0             0.0
       5             1.0             1.0             0.0
       6             2.0             1.0             0.0
       7             0.0             2.0             0.0
       8             1.0             2.0             0.0
       9             2.0             2.0             0.0
*ELEMENT_SHELL
       1       1       1       2       5       4
       2       1       2       3       6       5
       3       1       4       5       8       7
       4       1       5       6       9       8
*SET_NODE_LIST
         1
         3         6         9
*INITIAL_VELOCITY_GENERATION
         1         3       0.0       1.0       0.0       0.0

*END
"""


def test_shell_elform_zero_is_two(tmp_path):
    decks = {name: write(tmp_path, name, PLATE.format(elform=value))
             for name, value in [("zero", "         0"), ("two", "         2"), ("blank", "          ")]}
    for deck in decks.values():
        result = run(deck)
        assert result.returncode == 0, result.stderr
    results = {name: deck.parent / "out" / "results.h5" for name, deck in decks.items()}
    with h5py.File(results["two"], "r") as f:
        kinetic = f["history/glstat/kinetic_energy"][...]
        total = f["history/glstat/total_energy"][...]
    # three nodes of the plate's edge x = 2 carry a quarter of the mass (1/4, 1/2, 1/4 of the
    # lumped masses of an edge) at SPEED
    mass = DENSITY * 2.0 * 2.0 * 0.1
    assert kinetic[0] == pytest.approx(0.5 * (mass / 4.0) * SPEED ** 2, rel=1e-12)
    assert np.allclose(total, total[0], rtol=1e-3)
    assert_same_results(results["two"], results["zero"])
    assert_same_results(results["two"], results["blank"])


def test_bookkeeping_keywords_are_read_and_change_nothing(tmp_path):
    plain = write(tmp_path, "plain", CUBE.format(**WRITTEN_OUT))
    with_bookkeeping = write(tmp_path, "bookkeeping", CUBE.format(**dict(
        WRITTEN_OUT, extra=BOOKKEEPING, energy="*CONTROL_ENERGY\n         1         2         2         2\n"))
        .replace("*KEYWORD\n", "*KEYWORD 20000000 NCPU=-2\n"))
    first, second = run(plain), run(with_bookkeeping)
    assert first.returncode == 0, first.stderr
    assert second.returncode == 0, second.stderr
    assert_same_results(plain.parent / "out" / "results.h5", with_bookkeeping.parent / "out" / "results.h5")
    text = second.stdout + second.stderr
    for keyword in ["CONTROL_PARALLEL", "CONTROL_OUTPUT", "CONTROL_CPU", "CONTROL_SHELL", "CONTROL_SOLID",
                    "CONTROL_ACCURACY", "DATABASE_EXTENT_BINARY", "DATABASE_FORMAT", "DATABASE_BINARY_INTFOR",
                    "DATABASE_SPCFORC", "DATABASE_SLEOUT", "DATABASE_SECFORC", "DATABASE_HISTORY_SOLID",
                    "SENSOR_DEFINE_NODE_SET", "SENSOR_DEFINE_FUNCTION", "CONTROL_MPP_DECOMPOSITION_AUTOMATIC",
                    "CONTROL_MPP_IO_NODUMP"]:
        assert f"*{keyword}: read, not acted upon" in text, keyword
    # the fields a deck sets are named with their values
    assert "fields set, not used: NCPU=2 CONST=1" in text
    assert "THEORY=2" in text
    assert "deck.k:1: *KEYWORD: 20000000 NCPU=-2: read, not acted upon" in text
    # *CONTROL_ENERGY: HGEN and RWEN act, the flags of what crashfree always does or lacks do not
    assert "*CONTROL_ENERGY: field SLNTEN: ignored (contact energy is always computed" in text
    assert "*CONTROL_ENERGY: field RYLEN: ignored" in text


def test_part_contact_card_is_read_over(tmp_path):
    plain = write(tmp_path, "plain", CUBE.format(**WRITTEN_OUT))
    text = CUBE.format(**WRITTEN_OUT).replace("*PART\ncube\n         1         1         1\n",
                                                "*PART_CONTACT\ncube\n         1         1         1\n"
                                                "       0.3       0.2\n")
    contact = write(tmp_path, "contact", text)
    first, second = run(plain), run(contact)
    assert first.returncode == 0, first.stderr
    assert second.returncode == 0, second.stderr
    assert_same_results(plain.parent / "out" / "results.h5", contact.parent / "out" / "results.h5")
    assert "*PART_CONTACT: field FS: ignored" in second.stdout + second.stderr


def test_ignore_unknown_stops_on_a_known_keyword_with_an_unknown_option(tmp_path):
    text = CUBE.format(**WRITTEN_OUT).replace("*MAT_ELASTIC\n", "*MAT_ELASTIC_FLUID\n")
    deck = write(tmp_path, "option", text)
    result = run(deck, f"i={deck}", f"outdir={deck.parent / 'out'}", "--ignore-unknown")
    assert result.returncode == 2
    assert ("deck.k:19: *MAT_ELASTIC_FLUID: crashfree reads *MAT_ELASTIC, but not with the option FLUID"
            in result.stderr)


def test_ignore_unknown_never_reads_the_cards_of_a_skipped_block(tmp_path):
    # an unknown keyword between *NODE and *ELEMENT_SOLID whose line looks like a node card
    text = CUBE.format(**WRITTEN_OUT).replace(
        "*ELEMENT_SOLID\n", "*USER_UNKNOWN_THING\n       9             5.0             5.0             5.0\n"
        "*ELEMENT_SOLID\n")
    deck = write(tmp_path, "skipped", text)
    plain = write(tmp_path, "plain", CUBE.format(**WRITTEN_OUT))
    result = run(deck, f"i={deck}", f"outdir={deck.parent / 'out'}", "ncpu=1", "--ignore-unknown")
    assert result.returncode == 0, result.stderr
    assert "*USER_UNKNOWN_THING: unknown keyword skipped (1 data lines not read)" in result.stdout + result.stderr
    assert run(plain).returncode == 0
    assert_same_results(plain.parent / "out" / "results.h5", deck.parent / "out" / "results.h5")


def test_lsdyna_command_line(tmp_path):
    """`crashfree deck.k memory=... memory2=... d=nodump s=iff ncpu=-1` runs as
    `crashfree i=deck.k ncpu=1`, with one note per LS-DYNA argument on standard error."""
    plain = write(tmp_path, "plain", CUBE.format(**WRITTEN_OUT))
    lsdyna = write(tmp_path, "lsdyna", CUBE.format(**WRITTEN_OUT))
    assert run(plain).returncode == 0
    result = run(lsdyna, "deck.k", "memory=200m", "memory2=20m", "d=nodump", "s=iff", "ncpu=-1")
    assert result.returncode == 0, result.stderr
    notes = [line for line in result.stderr.splitlines() if line.startswith("crashfree: ")]
    assert len(notes) == 6, result.stderr
    for fragment in ["deck.k: read as the input deck (i=deck.k)", "memory=200m: ignored", "memory2=20m: ignored",
                     "d=nodump: ignored", "s=iff: ignored", "ncpu=-1: read as ncpu=1"]:
        assert any(fragment in note for note in notes), fragment
    assert_same_results(plain.parent / "out" / "results.h5", lsdyna.parent / "results.h5")


@pytest.mark.parametrize("coupling", ["       0.0       0.0       0.0", "                              ",
                                      "       1.0       0.0       0.0"])
def test_rigid_material_coupling_zero_is_none(tmp_path, coupling):
    """*MAT_RIGID N COUPLE M written as 0.0 (as public decks do) mean no coupling, as blank
    does; a nonzero N asks for MADYMO/CAL3D coupling and is refused naming the field. The rigid
    cube, thrown at SPEED, keeps its velocity exactly."""
    text = CUBE.format(**WRITTEN_OUT)
    text = text.replace("*MAT_ELASTIC\n         1   7.85e-6     210.0       0.3",
                        "*MAT_RIGID\n         1   7.85e-6     210.0       0.3" + coupling)
    deck = write(tmp_path, "rigid", text)
    shown = run(deck)
    if coupling.split() and float(coupling.split()[0]) != 0.0:
        assert shown.returncode == 2 and "field N: MADYMO/CAL3D coupling" in shown.stderr + shown.stdout
        return
    assert shown.returncode == 0, shown.stderr + shown.stdout
    with h5py.File(deck.parent / "out" / "results.h5", "r") as results:
        last = results["states"][sorted(results["states"].keys())[-1]]
        velocity = last["velocity"][...]
    # the rigid body carries the thrown face's momentum: SPEED/2 in x for every node
    assert np.abs(velocity[:, 0] - SPEED / 2).max() < 1e-9 * SPEED


def test_ignore_unknown_refuses_case_blocks(tmp_path):
    """*CASE_BEGIN_n ... *CASE_END_n hold keywords of case n only (a public projectile deck
    gives each case its own initial velocity): skipping the markers would apply every case's
    velocity in one run, so --ignore-unknown refuses them, naming the line."""
    text = CUBE.format(**WRITTEN_OUT).replace(
        "*END", "*CASE_BEGIN_2\n*INITIAL_VELOCITY_GENERATION\n         1         3       0.0       9.0"
                "       0.0       0.0\n       0.0       0.0       0.0       0.0       0.0       0.0"
                "       0.0         0\n*CASE_END_2\n*END")
    deck = write(tmp_path, "cases", text)
    shown = run(deck, f"i={deck}", f"outdir={deck.parent / 'out'}", "--ignore-unknown")
    assert shown.returncode == 2
    assert "*CASE_BEGIN_2: *CASE blocks are not available" in shown.stdout + shown.stderr
