#!/usr/bin/env python3
"""Read a keyword deck larger than 2 GiB and report the reader's peak memory and time.

Writes a deck of one *NODE block (34 million nodes by default, about 2.5 GB) and three solids
into a scratch directory, runs crashfree on it under /usr/bin/time -v, checks what it says
and deletes the deck. The deck holds two deliberate mistakes near its end, beyond byte 2**31,
which the cross-check must report with their exact file:line and the values read there:
  - a node id defined twice (the second definition is the third-last node card),
  - a solid whose eighth node does not exist.
So the run ends with exit status 2 after reading and checking the whole deck (no time
integration), and its peak memory is that of the reader and the model.

    python3 tools/big_deck_check.py [--nodes N] [--binary bin/crashfree] [--directory /tmp]
                                    [--keep]

Prints one line per measurement and exits non-zero when a check fails.
"""
from __future__ import annotations

import argparse
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HEADER = """*KEYWORD
*TITLE
large deck: one *NODE block beyond 2 GiB
*CONTROL_TERMINATION
       1.0
*PART
solids
         1         1         1
*SECTION_SOLID
         1         1
*MAT_ELASTIC
         1   7.85e-6     210.0       0.3
*NODE
"""
HEADER_LINES = HEADER.count("\n")
SOLID = "%8d%8d%8d%8d%8d%8d%8d%8d%8d%8d\n"


def node_line(node: int) -> str:
    # a 100 x 100 x n lattice, 1 mm spacing; 72 characters and a line feed per card
    return "%8d%16.6f%16.6f%16.6f%8d%8d\n" % (node, node % 100, node // 100 % 100, node // 10000, 0, 0)


def write_deck(path: Path, nodes: int) -> dict:
    """Write the deck; return the line numbers and ids the messages must name."""
    duplicate_line = HEADER_LINES + nodes - 2      # the third-last node card repeats node 17
    with open(path, "w") as deck:
        deck.write(HEADER)
        batch = []
        for node in range(1, nodes + 1):
            line = node_line(17 if node == nodes - 2 else node)
            batch.append(line)
            if len(batch) == 200000:
                deck.write("".join(batch))
                batch = []
        deck.write("".join(batch))
        deck.write("*ELEMENT_SOLID\n")
        deck.write(SOLID % (1, 1, 1, 2, 102, 101, 10001, 10002, 10102, 10101))
        deck.write(SOLID % (2, 1, 2, 3, 103, 102, 10002, 10003, 10103, 10102))
        deck.write(SOLID % (3, 1, 3, 4, 104, 103, 10003, 10004, 10104, nodes + 5))
        deck.write("*END\n")
    bad_element_line = HEADER_LINES + nodes + 4
    return {"duplicate_line": duplicate_line, "bad_element_line": bad_element_line,
            "missing_node": nodes + 5}


def measure(binary: str, deck: Path, output: Path) -> tuple[subprocess.CompletedProcess, float, int]:
    command = ["/usr/bin/time", "-v", binary, f"i={deck}", f"outdir={output}", "ncpu=1"]
    started = time.monotonic()
    process = subprocess.run(command, capture_output=True, text=True)
    elapsed = time.monotonic() - started
    found = re.search(r"Maximum resident set size \(kbytes\): (\d+)", process.stderr)
    peak_kb = int(found.group(1)) if found else -1
    return process, elapsed, peak_kb


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--nodes", type=int, default=34_000_000)
    parser.add_argument("--binary", default=str(Path(__file__).resolve().parents[1] / "bin" / "crashfree"))
    parser.add_argument("--directory", default="/tmp")
    parser.add_argument("--keep", action="store_true", help="keep the deck (and reuse a kept one)")
    arguments = parser.parse_args()

    scratch = Path(arguments.directory) / f"crashfree_big_deck_{arguments.nodes}"
    scratch.mkdir(parents=True, exist_ok=True)
    deck = scratch / "big.k"
    try:
        started = time.monotonic()
        expected = write_deck(deck, arguments.nodes) if not (arguments.keep and deck.exists()) else None
        if expected is None:
            expected = {"duplicate_line": HEADER_LINES + arguments.nodes - 2,
                        "bad_element_line": HEADER_LINES + arguments.nodes + 4,
                        "missing_node": arguments.nodes + 5}
        size = deck.stat().st_size
        print(f"deck: {deck}, {size / 1e9:.2f} GB ({size / 2**30:.2f} GiB), {arguments.nodes:,} nodes, "
              f"written in {time.monotonic() - started:.0f} s")
        process, elapsed, peak_kb = measure(arguments.binary, deck, scratch / "out")
        messages = [line for line in process.stderr.splitlines() if not line.startswith("\t")]
        print(f"crashfree: exit status {process.returncode}, {elapsed:.1f} s wall, "
              f"peak resident memory {peak_kb / 1024:.0f} MB ({peak_kb / 1024 / (size / 2**20):.2f} x the deck)")
        for line in messages[:6]:
            print("  " + line[:160])
        checks = {
            "exit status 2 (deck rejected after reading all of it)": process.returncode == 2,
            "duplicate node reported at its line beyond 2 GiB":
                f"big.k:{expected['duplicate_line']}: *NODE: field NID: node id 17 is defined twice "
                f"(first at {deck}:{HEADER_LINES + 17})" in process.stderr,
            "missing node of the last solid reported at its line":
                f"big.k:{expected['bad_element_line']}: *ELEMENT_SOLID: field N8: node "
                f"{expected['missing_node']} of element 3 is not defined" in process.stderr,
        }
        failed = [name for name, passed in checks.items() if not passed]
        for name, passed in checks.items():
            print(f"  {'ok  ' if passed else 'FAIL'} {name}")
        return 1 if failed else 0
    finally:
        if not arguments.keep:
            shutil.rmtree(scratch, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
