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
]


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
