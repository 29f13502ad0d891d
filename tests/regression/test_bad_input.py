"""Bad decks are the common case: each gets `file:line: *KEYWORD: field NAME: ...` on standard
error and exit status 2 before any cycle runs, never a runtime error or a backtrace."""
import re

import pytest

GOOD = """*KEYWORD
*TITLE
one element
*CONTROL_TERMINATION
       1.0
*PART
element
         1         1         1
*SECTION_SOLID
         1         1
*MAT_ELASTIC
         1   7.85e-6     210.0       0.3
*NODE
       1             0.0             0.0             0.0
       2             1.0             0.0             0.0
       3             1.0             1.0             0.0
       4             0.0             1.0             0.0
       5             0.0             0.0             1.0
       6             1.0             0.0             1.0
       7             1.0             1.0             1.0
       8             0.0             1.0             1.0
*ELEMENT_SOLID
       1       1       1       2       3       4       5       6       7       8
*END
"""

HONEYCOMB = """*MAT_HONEYCOMB
         1   6.0e-11    70000.       0.3      300.       0.2       0.0
        11                            12                                      10
     1000.      500.      500.      200.      200.      200.
       0.0
       0.0
*DEFINE_CURVE
        10
0.0,1.0
1.0,2.0
*DEFINE_CURVE
        11
0.0,0.5
1.0,0.7
*DEFINE_CURVE
        12
0.0,0.0
0.5,0.2
"""

# Part 1 made rigid, with a prescribed motion whose DOF is filled in (line 14 is its card).
RIGID_MOTION = """*MAT_RIGID
         1   7.85e-6     210.0       0.3
*BOUNDARY_PRESCRIBED_MOTION_RIGID
         1{dof:>10}         0         1
*DEFINE_CURVE
         1
0.0,1.0
1.0,1.0
"""

# A contact whose SURFB is a segment set on four nodes no element uses (line 31 is the
# segment, 33 the contact card).
LOOSE_SEGMENT_CONTACT = """*NODE
       9             0.0             0.0             2.0
      10             1.0             0.0             2.0
      11             1.0             1.0             2.0
      12             0.0             1.0             2.0
*SET_SEGMENT
         7
         9        10        11        12
*CONTACT_AUTOMATIC_NODES_TO_SURFACE
         1         7         3         0
*END"""

CASES = [
    # (description, replace this, with that, expected fragments of the message)
    ("misspelled keyword", "*MAT_ELASTIC", "*MAT_ELASTICK", ["deck.k:11:", "*MAT_ELASTICK"]),
    ("letter in a number field", "   7.85e-6", "   7.8x5-6", ["deck.k:12:", "*MAT_ELASTIC", "RO"]),
    ("missing card", "*SECTION_SOLID\n         1         1\n", "*SECTION_SOLID\n", ["deck.k:9:", "*SECTION_SOLID"]),
    ("undefined node", "       7       8\n*END", "       7      99\n*END", ["deck.k:23:", "*ELEMENT_SOLID", "99"]),
    ("duplicate node id", "       8             0.0             1.0             1.0",
     "       7             0.0             1.0             1.0", ["deck.k:21:", "*NODE", "7"]),
    ("part without material", "         1         1         1\n*SECTION", "         1         1\n*SECTION",
     ["deck.k:8:", "*PART", "MID"]),
    ("material id that does not exist", "         1         1         1\n*SECTION",
     "         1         1         5\n*SECTION", ["deck.k:8:", "*PART", "MID", "5"]),
    ("impossible material value", "     210.0       0.3", "     210.0       0.7", ["deck.k:12:", "*MAT_ELASTIC", "PR"]),
    ("inside-out element", "       1       1       1       2       3       4       5       6       7       8",
     "       1       1       5       6       7       8       1       2       3       4",
     ["deck.k:23:", "*ELEMENT_SOLID", "inside out"]),
    # found by fuzzing: a rigid motion's DOF outside 1-3, 5-7 was reported, then indexed the
    # rigid body's dofs in the cross-check (a Fortran runtime error or worse)
    ("rigid motion DOF -1", "*MAT_ELASTIC\n         1   7.85e-6     210.0       0.3\n", RIGID_MOTION.format(dof=-1),
     ["deck.k:14:", "*BOUNDARY_PRESCRIBED_MOTION_RIGID", "field DOF", "found -1"]),
    ("rigid motion DOF 8", "*MAT_ELASTIC\n         1   7.85e-6     210.0       0.3\n", RIGID_MOTION.format(dof=8),
     ["deck.k:14:", "*BOUNDARY_PRESCRIBED_MOTION_RIGID", "field DOF", "8 (motion along or about a vector"]),
    # found by fuzzing: a huge CMO / CON1 / AOPT overflowed the conversion to an integer (a
    # floating-point trap) before it could be reported
    ("rigid CMO 1e20", "*MAT_ELASTIC\n         1   7.85e-6     210.0       0.3\n",
     "*MAT_RIGID\n         1   7.85e-6     210.0       0.3\n      1e20\n",
     ["deck.k:13:", "*MAT_RIGID", "field CMO", "found 1.0e20"]),
    ("rigid CMO 0.5", "*MAT_ELASTIC\n         1   7.85e-6     210.0       0.3\n",
     "*MAT_RIGID\n         1   7.85e-6     210.0       0.3\n       0.5\n",
     ["deck.k:13:", "*MAT_RIGID", "field CMO", "found 0.5"]),
    ("rigid CON1 1e20", "*MAT_ELASTIC\n         1   7.85e-6     210.0       0.3\n",
     "*MAT_RIGID\n         1   7.85e-6     210.0       0.3\n       1.0      1e20\n",
     ["deck.k:13:", "*MAT_RIGID", "field CON1", "found 1.0e20"]),
    ("honeycomb AOPT 1e20", "*MAT_ELASTIC\n         1   7.85e-6     210.0       0.3\n",
     HONEYCOMB.replace("200.      200.      200.\n", "200.      200.      200.      1e20\n"),
     ["deck.k:14:", "*MAT_HONEYCOMB", "field AOPT", "1.0e20"]),
    # found by fuzzing: a contact segment on no element stopped the contact set-up with a
    # message naming no file or line
    ("contact segment on no element", "       7       8\n*END", "       7       8\n" + LOOSE_SEGMENT_CONTACT,
     ["deck.k:31:", "*SET_SEGMENT", "field N1-N4", "nodes 9 10 11 12", "neither a face of a solid element nor a shell",
      "deck.k:33"]),
]


# Two shells (a plate strip) in a deck without solids. Line numbers: 9 *SECTION_SHELL, 10 its
# card 1, 11 its card 2 (T1), 8 the *PART card, 22 and 23 the shells.
SHELL_GOOD = """*KEYWORD
*TITLE
two shells
*CONTROL_TERMINATION
       1.0
*PART
plate
         1         1         1
*SECTION_SHELL
         1         2
       1.0
*MAT_ELASTIC
         1   7.85e-6     210.0       0.3
*NODE
       1             0.0             0.0             0.0
       2             1.0             0.0             0.0
       3             1.0             1.0             0.0
       4             0.0             1.0             0.0
       5             2.0             0.0             0.0
       6             2.0             1.0             0.0
*ELEMENT_SHELL
       1       1       1       2       3       4
       2       1       2       5       6       3
*END
"""


SHELL_CASES = [
    # (description, replace this, with that, expected fragments of the message)
    ("unknown shell part", "       2       1       2       5", "       2       9       2       5",
     ["deck.k:23:", "*ELEMENT_SHELL", "field PID", "part 9 of shell 2 is not defined"]),
    ("shell on a solid section", "*SECTION_SHELL\n         1         2\n       1.0\n",
     "*SECTION_SOLID\n         1         1\n$ (a solid section has one card)\n",
     ["deck.k:22:", "*ELEMENT_SHELL", "field PID", "has solid section 1"]),
    ("shell without thickness", "       1.0\n*MAT_ELASTIC", "       0.0\n*MAT_ELASTIC",
     ["deck.k:22:", "*ELEMENT_SHELL", "field PID", "shell 1 has no thickness"]),
    ("ELFORM 16", "         1         2\n       1.0", "         1        16\n       1.0",
     ["deck.k:10:", "*SECTION_SHELL", "field ELFORM", "16", "ELFORM 2 (Belytschko-Tsay)"]),
    ("NIP 11", "         1         2\n       1.0", "         1         2       0.0        11\n       1.0",
     ["deck.k:10:", "*SECTION_SHELL", "field NIP", "1-10", "found 11"]),
    ("NLOC 1", "       1.0\n*MAT_ELASTIC", "       1.0                                     1.0\n*MAT_ELASTIC",
     ["deck.k:11:", "*SECTION_SHELL", "field NLOC", "found 1.0"]),
    ("N5 given", "       1       1       1       2       3       4\n",
     "       1       1       1       2       3       4       7\n",
     ["deck.k:22:", "*ELEMENT_SHELL", "field N5", "8-node shells are not available"]),
    ("honeycomb on a shell part", "*MAT_ELASTIC\n         1   7.85e-6     210.0       0.3\n", HONEYCOMB,
     ["deck.k:8:", "*PART", "field MID", "shell"]),
]


@pytest.mark.parametrize("description, old, new, fragments", SHELL_CASES, ids=[c[0] for c in SHELL_CASES])
def test_bad_shell_deck_is_rejected_with_a_clear_message(tmp_path, run_deck, description, old, new, fragments):
    assert old in SHELL_GOOD
    deck = tmp_path / "deck.k"
    deck.write_text(SHELL_GOOD.replace(old, new, 1))
    run = run_deck(deck)
    assert run.status == 2, f"{description}: exit status {run.status}\n{run.stderr}"
    for fragment in fragments:
        assert fragment in run.stderr, f"{description}: '{fragment}' not in:\n{run.stderr}"
    assert "At line" not in run.stderr, "a Fortran runtime error escaped"
    assert not run.results.exists(), "no results for a rejected deck"


@pytest.mark.parametrize("description, old, new, fragments", CASES, ids=[c[0] for c in CASES])
def test_bad_deck_is_rejected_with_a_clear_message(tmp_path, run_deck, description, old, new, fragments):
    assert old in GOOD
    deck = tmp_path / "deck.k"
    deck.write_text(GOOD.replace(old, new, 1))
    run = run_deck(deck)
    assert run.status == 2, f"{description}: exit status {run.status}\n{run.stderr}"
    for fragment in fragments:
        assert fragment in run.stderr, f"{description}: '{fragment}' not in:\n{run.stderr}"
    assert "Traceback" not in run.stderr and "Error termination" not in run.stderr
    assert "At line" not in run.stderr, "a Fortran runtime error escaped"
    assert not run.results.exists(), "no results for a rejected deck"


def test_good_deck_runs(tmp_path, run_deck):
    deck = tmp_path / "deck.k"
    deck.write_text(GOOD)
    run = run_deck(deck)
    assert run.status == 0, run.stderr


def test_unused_meshfree_part_is_accepted(tmp_path, run_deck):
    """Found by fuzzing: a *PART on an EFG section that no element uses stopped the explicit
    set-up with "EFG part 2 has no solid elements" (status 2, no deck line). An unused part has
    nothing to set up, as an unused FE part and the static analysis already treat it."""
    deck = tmp_path / "deck.k"
    deck.write_text(GOOD.replace("*END", "*PART\nunused meshfree part\n         2         2         1\n"
                                         "*SECTION_SOLID_EFG\n         2        41\n      1.01      1.01      1.01\n*END"))
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    assert "has no solid elements" not in run.stderr


def test_curve_and_set_references_are_all_listed_at_once(tmp_path, run_deck):
    deck = tmp_path / "deck.k"
    text = GOOD.replace("*END", "*BOUNDARY_PRESCRIBED_MOTION_SET\n        44         1         0        12\n"
                                "*LOAD_NODE_POINT\n         1         3        13\n*END")
    deck.write_text(text)
    run = run_deck(deck)
    assert run.status == 2
    assert re.search(r"deck\.k:25:.*\*BOUNDARY_PRESCRIBED_MOTION_SET.*44", run.stderr), run.stderr
    assert re.search(r"deck\.k:25:.*\*BOUNDARY_PRESCRIBED_MOTION_SET.*12", run.stderr), run.stderr
    assert re.search(r"deck\.k:27:.*\*LOAD_NODE_POINT.*13", run.stderr), run.stderr


def test_include_that_cannot_be_opened(tmp_path, run_deck):
    deck = tmp_path / "deck.k"
    deck.write_text(GOOD.replace("*END", "*INCLUDE\nmissing_mesh.k\n*END"))
    run = run_deck(deck)
    assert run.status == 2
    assert "deck.k:25:" in run.stderr and "missing_mesh.k" in run.stderr


def test_command_line_errors(tmp_path, run_deck):
    import subprocess
    from conftest import BINARY
    missing = subprocess.run([str(BINARY), f"i={tmp_path / 'none.k'}", f"outdir={tmp_path}"],
                             capture_output=True, text=True)
    assert missing.returncode == 2 and "none.k" in missing.stderr
    wrong = subprocess.run([str(BINARY), "i=x.k", "ncpu=two"], capture_output=True, text=True)
    assert wrong.returncode == 2 and "ncpu" in wrong.stderr
