"""What a deck file may be and what the command line may hold: anything a user (or a fuzzer)
passes gets a clear message naming the file (and line), status 2 and no results, never a hang,
a runtime error or garbage; and the forms LS-DYNA reads (byte-order mark, CRLF line ends,
decks beyond 2 GiB, LS-DYNA's own command-line arguments) are read."""
from __future__ import annotations

import gzip
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from conftest import BINARY
from test_bad_input import GOOD
from test_threads import datasets

# The include line added at the end of GOOD is line 25 (GOOD's *END is line 24).
INCLUDE_LINE = 25


def run_binary(arguments: list[str], cwd: Path | None = None, environment: dict | None = None,
               timeout: float = 60.0) -> subprocess.CompletedProcess:
    """Run the solver with `arguments`, never on more threads than the machine has unless asked."""
    env = dict(os.environ if environment is None else environment)
    env.pop("CRASHFREE_OVERSUBSCRIBE", None)
    env.setdefault("OMP_NUM_THREADS", "1")
    return subprocess.run([str(BINARY)] + arguments, capture_output=True, text=True, timeout=timeout,
                          cwd=cwd, env=env, errors="replace")


def assert_clean_rejection(process: subprocess.CompletedProcess, fragments: list[str], output: Path | None = None):
    assert process.returncode == 2, f"exit status {process.returncode}\n{process.stderr}"
    for fragment in fragments:
        assert fragment in process.stderr, f"'{fragment}' not in:\n{process.stderr}"
    assert "At line" not in process.stderr and "Fortran runtime error" not in process.stderr
    assert printable(process.stderr), repr(process.stderr)
    if output is not None:
        assert not (output / "results.h5").exists()


def printable(text: str) -> bool:
    """No control character but line feeds and tabs (no raw bytes of a damaged deck)."""
    return all(ord(character) >= 32 or character in "\n\t" for character in text)


# ---------------------------------------------------------------- what the deck file is

def special_files(tmp_path: Path) -> dict[str, tuple[Path, str]]:
    """name -> (path, what the message says about it)."""
    files = {}
    directory = tmp_path / "a_directory.k"
    directory.mkdir()
    files["directory"] = (directory, "is a directory")
    fifo = tmp_path / "pipe.k"
    os.mkfifo(fifo)
    files["fifo"] = (fifo, "is a FIFO (named pipe), not a regular file")
    files["dev_zero"] = (Path("/dev/zero"), "is a device (such as /dev/zero), not a regular file")
    files["dev_urandom"] = (Path("/dev/urandom"), "is a device (such as /dev/zero), not a regular file")
    empty = tmp_path / "empty.k"
    empty.write_text("")
    files["empty"] = (empty, "is empty")
    binary = tmp_path / "d3plot.k"
    binary.write_bytes(bytes(range(256)) * 64)
    files["binary"] = (binary, "holds NUL bytes near its start: it is a binary file")
    packed = tmp_path / "packed.k"
    packed.write_bytes(gzip.compress(GOOD.encode()))
    files["gzip"] = (packed, "is compressed (gzip); unpack it first")
    wide = tmp_path / "wide.k"
    wide.write_bytes(GOOD.encode("utf-16"))
    files["utf16"] = (wide, "is UTF-16 text")
    return files


KINDS = ["directory", "fifo", "dev_zero", "dev_urandom", "empty", "binary", "gzip", "utf16"]


@pytest.mark.parametrize("kind", KINDS)
def test_deck_that_is_no_text_file_is_rejected_naming_it(tmp_path, kind):
    """/dev/zero, FIFOs and directories used to read as empty decks (a FIFO hung until a writer
    came); each is now rejected with the file named."""
    path, what = special_files(tmp_path)[kind]
    output = tmp_path / "out"
    process = run_binary([f"i={path}", f"outdir={output}"], timeout=30)
    assert_clean_rejection(process, [f"{path}: the deck file {what}"], output)


@pytest.mark.parametrize("kind", KINDS)
def test_include_that_is_no_text_file_is_rejected_at_its_line(tmp_path, kind):
    path, what = special_files(tmp_path)[kind]
    deck = tmp_path / "deck.k"
    deck.write_text(GOOD.replace("*END", f"*INCLUDE\n{path}\n*END"))
    output = tmp_path / "out"
    process = run_binary([f"i={deck}", f"outdir={output}"], timeout=30)
    if kind == "empty":
        # an empty include is read (nothing is in it), with a warning at its *INCLUDE card
        assert process.returncode == 0, process.stderr
        assert f"deck.k:{INCLUDE_LINE}: *INCLUDE: field FILENAME: \"{path}\" is empty" in process.stderr
        return
    assert_clean_rejection(process, [f"deck.k:{INCLUDE_LINE}: *INCLUDE: field FILENAME: cannot open \"{path}\": "
                                     f"it {what}"], output)


def test_file_without_keywords_is_no_deck(tmp_path):
    deck = tmp_path / "notes.k"
    deck.write_text("$ only a comment\n\n$ and another\n")
    process = run_binary([f"i={deck}", f"outdir={tmp_path / 'out'}"])
    assert_clean_rejection(process, [f"{deck}: the file holds no keyword line"])
    assert "defines no nodes" not in process.stderr


def test_include_file_given_as_the_deck_is_named_as_such(tmp_path):
    """A mesh file (no *KEYWORD) run by mistake: the warning says what it looks like."""
    deck = tmp_path / "mesh.k"
    deck.write_text(GOOD.replace("*KEYWORD\n", ""))
    process = run_binary([f"i={deck}", f"outdir={tmp_path / 'out'}"])
    assert process.returncode == 0, process.stderr
    assert "does not start with *KEYWORD" in process.stderr and "include file" in process.stderr


# ---------------------------------------------------------------- byte-order mark, CRLF, tabs

def test_byte_order_mark_is_skipped_in_deck_and_include(tmp_path, run_deck):
    """Editors on Windows start UTF-8 files with EF BB BF; the deck read it as data before the
    first keyword."""
    body, nodes = GOOD.split("*NODE\n")
    (tmp_path / "nodes.k").write_bytes(b"\xef\xbb\xbf*NODE\n" + nodes.split("*ELEMENT_SOLID")[0].encode())
    deck = tmp_path / "deck.k"
    deck.write_bytes(b"\xef\xbb\xbf" + (body + "*INCLUDE\nnodes.k\n*ELEMENT_SOLID" +
                                        nodes.split("*ELEMENT_SOLID")[1]).encode())
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    with run.open() as results:
        assert results["mesh/nodes/ids"].shape == (8,)


def test_crlf_deck_gives_the_same_results_and_line_numbers(tmp_path, run_deck):
    """Decks written on Windows end lines with CR LF; a doubled CR read as part of the field."""
    plain = tmp_path / "plain.k"
    plain.write_text(GOOD)
    windows = tmp_path / "windows.k"
    # one line converted twice (CR CR LF), as a second unix2dos or a mixed-up checkout leaves it
    windows.write_bytes(GOOD.replace("\n", "\r\n").replace("       1.0\r\n", "       1.0\r\r\n").encode())
    runs = [run_deck(plain, jobid="plain"), run_deck(windows, jobid="windows")]
    for run in runs:
        assert run.status == 0, run.stderr
    with runs[0].open() as first, runs[1].open() as second:
        a, b = datasets(first), datasets(second)
    assert a.keys() == b.keys()
    for name in a:
        assert np.array_equal(a[name], b[name]), name
    bad = tmp_path / "bad.k"
    bad.write_bytes(GOOD.replace("   7.85e-6", "   7.8x5-6").replace("\n", "\r\n").encode())
    process = run_binary([f"i={bad}", f"outdir={tmp_path / 'out'}"])
    assert_clean_rejection(process, ["bad.k:12: *MAT_ELASTIC: field RO: \"7.8x5-6\" is not a number"])


@pytest.mark.parametrize("description, old, new, fragments", [
    ("form feed in a keyword", "*PART\n", "*PART\f\n",
     ["deck.k:6: column 6 holds the control character FF (byte 12)", "*PART<FF>"]),
    ("escape in a number", "   7.85e-6", "  \x1b7.85e-6",
     ["deck.k:12: column 13 holds the control character ESC (byte 27)", "<ESC>7.85e-6"]),
    ("carriage return inside a line", "     210.0", "  \r  210.0",
     ["deck.k:12: column 23 holds the control character CR (byte 13)"]),
    ("delete", "*SECTION_SOLID\n", "*SECTION_SOLID\x7f\n", ["deck.k:9: column 15 holds the control character DEL"]),
    ("NUL past the start of the file", "       8             0.0",
     "       8\x00            0.0", ["deck.k:121: column 9 holds the control character NUL (byte 0)"]),
], ids=["FF", "ESC", "CR", "DEL", "NUL"])
def test_control_characters_are_reported_at_their_line_and_column(tmp_path, description, old, new, fragments):
    # 100 comment lines first, so that a NUL is not within the first 8000 bytes (which would
    # make the file binary); the line numbers above are those of GOOD plus 100 for the NUL
    padding = "".join(f"$ comment line {k:4d} {'.' * 80}\n" for k in range(100)) if description.startswith("NUL") else ""
    text = GOOD.replace(old, new, 1)
    deck = tmp_path / "deck.k"
    deck.write_bytes((text.replace("*KEYWORD\n", "*KEYWORD\n" + padding, 1)).encode())
    output = tmp_path / "out"
    process = run_binary([f"i={deck}", f"outdir={output}"])
    assert_clean_rejection(process, fragments, output)


def test_tabs_in_comma_cards_and_after_the_last_field_are_read(tmp_path, run_deck):
    deck = tmp_path / "deck.k"
    deck.write_text(GOOD.replace("         1   7.85e-6     210.0       0.3", "1,\t7.85e-6,\t210.0,\t0.3")
                        .replace("       1.0\n", "       1.0\t\n"))
    run = run_deck(deck)
    assert run.status == 0, run.stderr


def test_tab_inside_a_fixed_card_names_its_column(tmp_path):
    deck = tmp_path / "deck.k"
    deck.write_text(GOOD.replace("         1   7.85e-6", "         1\t7.85e-6"))
    process = run_binary([f"i={deck}", f"outdir={tmp_path / 'out'}"])
    assert_clean_rejection(process, ["deck.k:12: *MAT_ELASTIC: the card holds a tab character (column 11)"])


def test_overlong_lines(tmp_path, run_deck):
    """A comment line of 3 MB is skipped; a data line over 1 MiB is reported, not read."""
    deck = tmp_path / "deck.k"
    deck.write_text(GOOD.replace("*PART\n", "$" + "c" * 3_000_000 + "\n*PART\n"))
    run = run_deck(deck)
    assert run.status == 0, run.stderr
    deck.write_text(GOOD.replace("*PART\n", "*PART\n" + "x" * 1_100_000 + "\n"))
    process = run_binary([f"i={deck}", f"outdir={tmp_path / 'out'}"])
    assert_clean_rejection(process, ["deck.k:7: the line is longer than 1048576 characters"])


# ---------------------------------------------------------------- keyword names

@pytest.mark.parametrize("typo, hint", [
    ("*DATABASE_RCFORK", "(did you mean *DATABASE_RCFORC?)"),
    ("*MAT_RIGIDD", "(did you mean *MAT_RIGID?)"),
    ("*SECTION_SOLID_TITEL", "(did you mean *SECTION_SOLID_TITLE?)"),
    ("*NODE_TITLE", "(crashfree reads *NODE, but not with _TITLE)"),
])
def test_misspelt_keyword_gets_the_keyword_meant(tmp_path, typo, hint):
    deck = tmp_path / "deck.k"
    deck.write_text(GOOD.replace("*END", f"{typo}\n*END"))
    process = run_binary([f"i={deck}", f"outdir={tmp_path / 'out'}"])
    assert_clean_rejection(process, [f"deck.k:24: {typo}: unknown keyword {hint}"])


# ---------------------------------------------------------------- beyond 2 GiB

def sparse_directory(tmp_path: Path) -> Path:
    """Where a file with a 2 GiB hole costs neither disk nor time: tmpfs when there is one
    (reading a hole there maps the zero page), else the test's directory."""
    shared = Path("/dev/shm")
    if shared.is_dir() and os.access(shared, os.W_OK):
        directory = shared / f"crashfree_{os.getpid()}_{tmp_path.name}"
        directory.mkdir()
        return directory
    return tmp_path


def test_deck_beyond_2_gib_reads_cards_and_lines_exactly(tmp_path, run_deck):
    """A comment line of 2 GiB (a hole of a sparse file) before the model: every card after it
    starts beyond byte 2**31. The solver refused such decks ("cannot open"); now the nodes read
    there reach the results and a warning names its exact line."""
    directory = sparse_directory(tmp_path)
    try:
        deck = directory / "deck.k"
        head = "*KEYWORD\n*TITLE\nlarge deck\n" + "".join(f"$ padding {k:4d} {'.' * 76}\n" for k in range(100))
        body = GOOD.split("one element\n", 1)[1].replace(
            "element\n         1         1         1\n",
            "element\n         1         1         1" + " " * 40 + "         7\n")
        with open(deck, "wb") as file:
            file.write(head.encode() + b"$ a comment line that runs past 2 GiB: ")
            file.seek(2**31 + 4096)
            file.write(b"\n" + body.encode())
        if deck.stat().st_blocks * 512 > 2**24:
            pytest.skip("the file system does not keep sparse files")
        run = run_deck(deck)
        assert run.status == 0, run.stderr
        # the *PART card (PID SECID MID ... TMID) is line 3 + 100 + 1 (the long comment) + 2 + 3
        assert f"deck.k:{3 + 100 + 1 + 2 + 3}: *PART: field TMID: ignored (no thermal analysis)" in run.stderr
        with run.open() as results:
            coordinates = results["mesh/nodes/coordinates"][()]
        expected = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
        assert np.array_equal(coordinates, expected)
    finally:
        if directory != tmp_path:
            shutil.rmtree(directory, ignore_errors=True)


# ---------------------------------------------------------------- command line

def test_argument_longer_than_4096_characters(tmp_path):
    """i= and a path of 4,095 characters (the longest Linux opens) is 4,097 characters: it was
    cut at 4,096 and the deck not found."""
    (tmp_path / "deck1.k").write_text(GOOD)
    path = "./" * 2044 + "deck1.k"
    assert len(path) == 4095
    process = run_binary([f"i={path}", "outdir=out"], cwd=tmp_path)
    assert process.returncode == 0, process.stderr[-400:]
    assert (tmp_path / "out" / "results.h5").exists()


def test_ls_dyna_arguments_are_accepted_and_noted(tmp_path):
    (tmp_path / "deck.k").write_text(GOOD)
    process = run_binary(["deck.k", "memory=200m", "memory2=20m", "d=nodump", "o=d3hsp", "g=d3plot",
                          "ncycle=100", "pfile=partition", "ncpu=-1", "outdir=out"], cwd=tmp_path)
    assert process.returncode == 0, process.stderr
    assert (tmp_path / "out" / "results.h5").exists()
    for argument in ["memory=200m", "memory2=20m", "d=nodump", "o=d3hsp", "g=d3plot", "ncycle=100",
                     "pfile=partition"]:
        assert f"crashfree: {argument}: ignored (" in process.stderr, process.stderr
    assert "crashfree: ncpu=-1: read as ncpu=1" in process.stderr


def test_two_decks_and_unknown_arguments_are_refused(tmp_path):
    (tmp_path / "deck.k").write_text(GOOD)
    two = run_binary(["deck.k", "i=other.k"], cwd=tmp_path)
    assert_clean_rejection(two, ["command line: two decks given: 'deck.k' and i=other.k"])
    unknown = run_binary(["i=deck.k", "memroy=20m"], cwd=tmp_path)
    assert_clean_rejection(unknown, ["command line: unknown option 'memroy='"])


@pytest.mark.parametrize("source", ["ncpu", "OMP_NUM_THREADS"])
def test_threads_are_capped_at_the_processors(tmp_path, source):
    """ncpu=1000 ran 1000 threads (77 times slower on 2 cores); now the processors available,
    with a warning naming both numbers. The deck is missing, so nothing runs."""
    processors = len(os.sched_getaffinity(0))
    environment = dict(os.environ)
    arguments = [f"i={tmp_path / 'missing.k'}"]
    if source == "ncpu":
        arguments.append("ncpu=1000")
    else:
        environment["OMP_NUM_THREADS"] = "1000"
    process = run_binary(arguments, environment=environment)
    assert process.returncode == 2
    assert (f"crashfree: warning: {source}=1000 is more than the {processors} processors available; "
            f"running on {processors} threads") in process.stderr, process.stderr
    assert f"on {processors} thread(s)" in process.stdout
