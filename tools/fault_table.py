#!/usr/bin/env python3
"""Fault-injection table: what a crashfree binary leaves after a signal, a kill, a full disk, a
read-only or impossible output directory and a second run into the same files.

Usage: python3 tools/fault_table.py [--binary bin/crashfree] [--kills 20] [--seed 1]
                                    [--disk auto|tmpfs|shim|both] [--keep]

Each case runs the binary on a small deck (8 elastic hexahedra flying, from
tests/regression/output_faults.py) in a fresh temporary directory and is described by one row of a
Markdown table printed on stdout (progress goes to stderr): the exit status, the solver's message,
whether results.h5 opens with h5py, how many states it lists and how many of them read completely,
/run/status, whether /timing exists, whether results.xdmf parses and how many states it lists.
The SIGKILL case kills the run at --kills random moments (seeded by --seed) while states are
written densely and summarises them in one row. A full disk is a small tmpfs when running as root
(mounted inside the temporary directory and always unmounted), else the LD_PRELOAD disk shim of
output_faults.py (needs gcc); --disk chooses. docs/output.md "When things go wrong" says what the
solver is meant to do in each case.
"""
from __future__ import annotations

import argparse
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass
from pathlib import Path

import h5py

REPOSITORY = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPOSITORY / "tests" / "regression"))
from output_faults import DISK_SHIM_SOURCE, can_mount, cube_deck, tmpfs  # noqa: E402

# Longest a single solver run may take before the tool kills it (the slowest case, a dense run of
# a binary whose output cost grows with the number of states, is killed long before).
RUN_TIMEOUT_S = 300.0
# Longest the tool waits for a started run to create its results file.
START_TIMEOUT_S = 60.0
MESSAGE_LENGTH = 130


@dataclass
class Row:
    """One line of the table."""
    case: str
    exit: str = "-"
    message: str = "-"
    opens: str = "-"
    listed: str = "-"
    readable: str = "-"
    status: str = "-"
    timing: str = "-"
    xdmf_parses: str = "-"
    xdmf_states: str = "-"


COLUMNS = ("case", "exit", "message (shortened)", "h5 opens", "states listed", "states readable",
           "/run status", "/timing", "XDMF parses", "XDMF states")


class Runner:
    """Starts the binary with its own process group, output to files, and cleans up after it."""

    def __init__(self, binary: Path, scratch: Path):
        self.binary = binary
        self.scratch = scratch
        self.running: list[subprocess.Popen] = []
        self.count = 0

    def start(self, deck: Path, output: Path, environment: dict | None = None) -> subprocess.Popen:
        self.count += 1
        log = self.scratch / f"log_{self.count}"
        command = [str(self.binary), f"i={deck}", f"outdir={output}", "ncpu=1"]
        stdout = open(f"{log}.out", "w")
        stderr = open(f"{log}.err", "w")
        # SIGINT and SIGTERM at their defaults, as in a terminal: a shell's background job, and so
        # this tool when started with '&', would otherwise pass them on ignored.
        process = subprocess.Popen(
            command, stdout=stdout, stderr=stderr, stdin=subprocess.DEVNULL, start_new_session=True,
            env=dict(os.environ, OMP_NUM_THREADS="1", **(environment or {})),
            preexec_fn=lambda: (signal.signal(signal.SIGINT, signal.SIG_DFL),
                                signal.signal(signal.SIGTERM, signal.SIG_DFL)))
        stdout.close()
        stderr.close()
        process.log = log
        self.running.append(process)
        return process

    def finish(self, process: subprocess.Popen, timeout: float = RUN_TIMEOUT_S) -> tuple[str, str]:
        """Waits for the process (killing it after `timeout`): (exit column, message column)."""
        timed_out = False
        try:
            process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            timed_out = True
            self.kill(process)
        self.running.remove(process)
        stdout = Path(f"{process.log}.out").read_text(errors="replace")
        stderr = Path(f"{process.log}.err").read_text(errors="replace")
        if timed_out:
            return f"timeout ({timeout:.0f} s)", message_of(stdout, stderr, self.scratch)
        return exit_text(process.returncode), message_of(stdout, stderr, self.scratch)

    def run(self, deck: Path, output: Path, environment: dict | None = None) -> tuple[str, str]:
        return self.finish(self.start(deck, output, environment))

    @staticmethod
    def kill(process: subprocess.Popen) -> None:
        try:
            os.killpg(process.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        process.wait()

    def cleanup(self) -> None:
        for process in list(self.running):
            if process.poll() is None:
                self.kill(process)
        self.running.clear()


def exit_text(status: int) -> str:
    if status < 0:
        return f"{signal.Signals(-status).name} ({status})"
    return str(status)


def message_of(stdout: str, stderr: str, scratch: Path) -> str:
    """The line that tells the user what happened: the solver's error termination line, else its
    first line on stderr, else stdout's termination line or last line (marked so); the prefix
    "crashfree: " dropped, temporary paths shortened to TMP, and the number of further stderr
    lines (a backtrace, a summary of the files) added."""
    errors = [line.strip() for line in stderr.splitlines() if line.strip()]
    chosen = next((line for line in errors if line.startswith("crashfree: error termination")), None)
    if chosen is None and errors:
        chosen = errors[0]
    if chosen is None:
        lines = [" ".join(line.split()) for line in stdout.splitlines() if line.strip()]
        ending = [line for line in lines if line.endswith("termination")]
        if ending:
            chosen = f"stdout: {ending[-1]}"
        else:
            chosen = "nothing on stderr; stdout ends: " + (lines[-1] if lines else "(nothing)")
    chosen = chosen.removeprefix("crashfree: ").replace(str(scratch), "TMP")
    return shorten(chosen, len(errors) - 1 if errors else 0)


def shorten(text: str, extra_lines: int = 0) -> str:
    if len(text) > MESSAGE_LENGTH:
        text = text[:MESSAGE_LENGTH - 3] + "..."
    if extra_lines > 0:
        text += f" (+{extra_lines} more stderr lines)"
    return text


def wait_for(path: Path, process: subprocess.Popen, timeout: float = START_TIMEOUT_S) -> bool:
    """True once `path` exists while the process runs."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if path.exists():
            return True
        if process.poll() is not None:
            return False
        time.sleep(0.005)
    return False


@dataclass
class Files:
    """What results.h5 and results.xdmf hold after a case."""
    opens: bool = False
    open_error: str = ""
    listing_fails: bool = False
    listed: int = 0
    readable: int = 0
    status: str = "-"
    timing: bool = False
    last_time: float | None = None
    xdmf_exists: bool = False
    xdmf_parses: bool = False
    xdmf_states: int = 0
    xdmf_temporary: bool = False

    def all_readable(self) -> bool:
        return self.opens and not self.listing_fails and self.readable == self.listed


def read_state(state) -> float:
    """Reads every dataset of a state group and its time; raises when any of them fails."""
    for name in state:
        item = state[name]
        if isinstance(item, h5py.Dataset):
            item[()]
    return float(state.attrs["time"])


def inspect(output: Path, jobid: str = "results") -> Files:
    files = Files()
    h5 = output / f"{jobid}.h5"
    xdmf = output / f"{jobid}.xdmf"
    files.xdmf_temporary = (output / f"{jobid}.xdmf.tmp").exists()
    if h5.exists():
        try:
            with h5py.File(h5, "r") as results:
                files.opens = True
                inspect_results(results, files)
        except Exception as error:  # any failure to open is a row entry, not a crash of the tool
            if not files.opens:
                files.open_error = type(error).__name__
    else:
        files.open_error = "no file"
    if xdmf.exists():
        files.xdmf_exists = True
        try:
            root = ElementTree.parse(xdmf).getroot()
            files.xdmf_states = len(root.find("Domain").find("Grid").findall("Grid"))
            files.xdmf_parses = True
        except Exception:
            pass
    return files


def inspect_results(results: h5py.File, files: Files) -> None:
    try:
        run = results["run"].attrs
        status = run["status"]
        files.status = status.decode() if isinstance(status, bytes) else str(status)
    except Exception:
        files.status = "(unreadable)"
    files.timing = "timing" in results
    try:
        names = sorted(results["states"])
    except Exception:
        # A kill in the middle of linking a state can leave /states unlistable (docs/output.md):
        # the states are then opened by their names until three in a row are missing.
        files.listing_fails = True
        names = []
        index, missing = 0, 0
        while missing < 3:
            name = f"{index:06d}"
            try:
                results[f"states/{name}"]
                names.append(name)
                missing = 0
            except Exception:
                missing += 1
            index += 1
    files.listed = len(names)
    for name in names:
        try:
            files.last_time = read_state(results["states"][name])
            files.readable += 1
        except Exception:
            pass


def fill(row: Row, files: Files) -> Row:
    row.opens = "yes" if files.opens else f"no ({files.open_error})"
    if files.opens:
        row.listed = f"listing fails, {files.listed} by name" if files.listing_fails else str(files.listed)
        row.readable = str(files.readable)
        if files.last_time is not None:
            row.readable += f" (last t={files.last_time:.4g})"
        row.status = files.status
        row.timing = "yes" if files.timing else "no"
    if not files.xdmf_exists:
        row.xdmf_parses = "no file"
    else:
        row.xdmf_parses = "yes" if files.xdmf_parses else "NO"
        if files.xdmf_parses:
            row.xdmf_states = str(files.xdmf_states)
    if files.xdmf_temporary:
        row.xdmf_parses += " (+ stray .tmp)"
    return row


class Cases:
    """The cases, each returning its rows."""

    def __init__(self, runner: Runner, scratch: Path, kills: int, seed: int, disk: str):
        self.runner = runner
        self.scratch = scratch
        self.kills = kills
        self.seed = seed
        self.disk = disk
        # ~2 M cycles over 100 ms (several seconds), a state every 0.5 ms: long enough to be hit
        self.signal_deck = cube_deck(scratch / "signal.k", 200, end_time=100.0)
        # a state every 0.25 microseconds (every few cycles): the file is busy most of the time
        self.dense_deck = cube_deck(scratch / "dense.k", 8000, end_time=2.0)
        self.disk_deck = cube_deck(scratch / "disk.k", 2000)
        self.short_deck = cube_deck(scratch / "short.k", 10)
        self.long_deck = cube_deck(scratch / "long.k", 200, end_time=40.0)

    def output(self, name: str) -> Path:
        path = self.scratch / name
        path.mkdir()
        return path

    def signalled(self, name: str, signals: list[signal.Signals], gap_s: float, delay_s: float = 1.0) -> Row:
        output = self.output(name)
        process = self.runner.start(self.signal_deck, output)
        before = ""
        if wait_for(output / "results.h5", process):
            time.sleep(delay_s)
        if process.poll() is None:
            for index, number in enumerate(signals):
                if index:
                    time.sleep(gap_s)
                try:
                    os.kill(process.pid, number)
                except ProcessLookupError:
                    before = f"(ended before {number.name} #{index + 1}) "
        else:
            before = "(ended before the signal) "
        names = " then ".join(number.name for number in signals)
        gap = f" {gap_s * 1000:g} ms apart" if len(signals) > 1 else ""
        row = Row(f"{names}{gap}, {delay_s:g} s into the run (200 states over 100 ms)")
        row.exit, message = self.runner.finish(process)
        row.message = before + message
        return fill(row, inspect(output))

    def kill_nine(self) -> Row:
        rng = random.Random(self.seed)
        counts = dict(killed=0, ended=0, xdmf=0, opens=0, readable=0, running=0, timing=0, temporary=0,
                      xdmf_within=0, listing=0)
        listed_range, xdmf_range = [], []
        for attempt in range(self.kills):
            output = self.output(f"kill_{attempt}")
            process = self.runner.start(self.dense_deck, output)
            moment = rng.uniform(0.05, 2.0)
            if wait_for(output / "results.h5", process):
                time.sleep(moment)
            if process.poll() is None:
                os.kill(process.pid, signal.SIGKILL)
                counts["killed"] += 1
            else:
                counts["ended"] += 1
            self.runner.finish(process)
            files = inspect(output)
            counts["xdmf"] += files.xdmf_parses
            counts["opens"] += files.opens
            counts["readable"] += files.all_readable()
            counts["listing"] += files.listing_fails
            counts["running"] += files.status == "running"
            counts["timing"] += files.timing
            counts["temporary"] += files.xdmf_temporary
            counts["xdmf_within"] += files.xdmf_parses and files.opens and files.xdmf_states <= files.readable
            if files.opens:
                listed_range.append(files.listed)
            if files.xdmf_parses:
                xdmf_range.append(files.xdmf_states)
            print(f"  kill {attempt + 1}/{self.kills} at {moment:.2f} s: h5 opens {files.opens}, "
                  f"{files.readable}/{files.listed} readable"
                  f"{' (listing fails)' if files.listing_fails else ''}, xdmf parses "
                  f"{files.xdmf_parses} ({files.xdmf_states} states)", file=sys.stderr)
            shutil.rmtree(output, ignore_errors=True)

        def span(values: list[int]) -> str:
            return f"{min(values)} to {max(values)}" if values else "-"

        n = self.kills  # the table's n/N notation
        row = Row(f"SIGKILL at {n} random moments 0.05-2 s after results.h5 appears "
                  f"(8000 states over 2 ms, seed {self.seed})")
        row.exit = f"killed {counts['killed']}/{n}" + (f", ended first {counts['ended']}/{n}" if counts["ended"] else "")
        row.message = "-"
        row.opens = f"{counts['opens']}/{n}"
        row.listed = span(listed_range) + (f"; listing fails {counts['listing']}/{n}" if counts["listing"] else "")
        row.readable = f"all listed readable {counts['readable']}/{n}"
        row.status = f"running {counts['running']}/{n}"
        row.timing = f"{counts['timing']}/{n}"
        row.xdmf_parses = f"{counts['xdmf']}/{n}" + (f" (stray .tmp {counts['temporary']}/{n})" if counts["temporary"] else "")
        row.xdmf_states = (f"{span(xdmf_range)}; lists only readable h5 states "
                           f"{counts['xdmf_within']}/{counts['xdmf']}")
        return row

    def disk_methods(self) -> list[str]:
        if self.disk == "auto":
            return ["tmpfs" if can_mount() else "shim"]
        if self.disk == "both":
            return ["tmpfs", "shim"]
        return [self.disk]

    def full_disk(self) -> list[Row]:
        rows = []
        for method in self.disk_methods():
            if method == "tmpfs" and not can_mount():
                rows.append(Row("full disk (tmpfs): not possible, mounting needs root"))
                continue
            if method == "shim" and shutil.which("gcc") is None:
                rows.append(Row("full disk (disk shim): not possible, the shim needs gcc"))
                continue
            rows += self.full_disk_tmpfs() if method == "tmpfs" else self.full_disk_shim()
        return rows

    def full_disk_tmpfs(self) -> list[Row]:
        rows = []
        with tmpfs(self.scratch / "tmpfs_start", "size=64k") as disk:
            (disk / "filler").write_bytes(b"\0" * 65536)
            row = Row("full disk at start: tmpfs of 64 kB, filled")
            row.exit, row.message = self.runner.run(self.disk_deck, disk)
            rows.append(fill(row, inspect(disk)))
        with tmpfs(self.scratch / "tmpfs_run", "size=1m") as disk:
            row = Row("full disk during the run: tmpfs of 1 MB (2000 states over 1 ms)")
            row.exit, row.message = self.runner.run(self.disk_deck, disk)
            rows.append(fill(row, inspect(disk)))
        return rows

    def shim(self) -> Path:
        library = self.scratch / "disk_shim.so"
        if not library.exists():
            source = self.scratch / "disk_shim.c"
            source.write_text(DISK_SHIM_SOURCE)
            subprocess.run(["gcc", "-shared", "-fPIC", "-O1", "-o", str(library), str(source), "-ldl"],
                           check=True, capture_output=True, timeout=120)
        return library

    def full_disk_shim(self) -> list[Row]:
        rows = []
        output = self.output("shim_start")
        row = Row("full disk at start: disk shim (LD_PRELOAD), 0 bytes free")
        row.exit, row.message = self.runner.run(self.disk_deck, output, {
            "LD_PRELOAD": str(self.shim()), "CRASHFREE_TEST_DISK_DIR": str(output),
            "CRASHFREE_TEST_DISK_BYTES": "0"})
        rows.append(fill(row, inspect(output)))
        output = self.output("shim_run")
        row = Row("full disk during the run: disk shim (LD_PRELOAD), 250 kB, no fallocate "
                  "(2000 states over 1 ms)")
        row.exit, row.message = self.runner.run(self.disk_deck, output, {
            "LD_PRELOAD": str(self.shim()), "CRASHFREE_TEST_DISK_DIR": str(output),
            "CRASHFREE_TEST_DISK_BYTES": "250000", "CRASHFREE_TEST_NO_FALLOCATE": "1"})
        rows.append(fill(row, inspect(output)))
        return rows

    def read_only(self) -> Row:
        if can_mount():
            with tmpfs(self.scratch / "read_only", "size=64k,ro") as directory:
                row = Row("read-only output directory (read-only tmpfs)")
                row.exit, row.message = self.runner.run(self.short_deck, directory)
                return fill(row, inspect(directory))
        if os.geteuid() != 0:
            directory = self.scratch / "read_only"
            directory.mkdir(mode=0o555)
            row = Row("read-only output directory (mode 555)")
            row.exit, row.message = self.runner.run(self.short_deck, directory)
            row = fill(row, inspect(directory))
            directory.chmod(0o755)
            return row
        return Row("read-only output directory: not possible, root without mount")

    def under_a_file(self) -> Row:
        (self.scratch / "a_file").write_text("not a directory\n")
        output = self.scratch / "a_file" / "results"
        row = Row("output directory under a regular file (outdir=TMP/a_file/results)")
        row.exit, row.message = self.runner.run(self.short_deck, output)
        return fill(row, inspect(output))

    def two_runs(self) -> list[Row]:
        output = self.output("shared")
        first = self.runner.start(self.long_deck, output)
        started = wait_for(output / "results.h5", first)
        time.sleep(0.3)
        first_running = first.poll() is None
        second_row = Row("two runs, the second: 10 states, started while the first runs, same outdir")
        second_row.exit, second_row.message = self.runner.run(self.short_deck, output)
        if not (started and first_running and first.poll() is None):
            second_row.message = "(the first run had ended: case not valid) " + second_row.message
        first_row = Row("two runs, the first: 200 states over 40 ms (files checked after both ended)")
        first_row.exit, first_row.message = self.runner.finish(first)
        first_row = fill(first_row, inspect(output))
        return [first_row, second_row]

    def all(self) -> list[Row]:
        steps = [
            ("SIGINT", lambda: [self.signalled("sigint", [signal.SIGINT], 0.0)]),
            ("SIGTERM", lambda: [self.signalled("sigterm", [signal.SIGTERM], 0.0)]),
            ("SIGINT twice", lambda: [self.signalled("sigint_twice", [signal.SIGINT, signal.SIGINT], 0.001)]),
            ("SIGKILL", lambda: [self.kill_nine()]),
            ("full disk", self.full_disk),
            ("read-only", lambda: [self.read_only()]),
            ("under a file", lambda: [self.under_a_file()]),
            ("two runs", self.two_runs),
        ]
        rows = []
        for name, step in steps:
            print(f"case: {name}", file=sys.stderr)
            try:
                rows += step()
            except Exception as error:  # one broken case still gives the others' rows
                rows.append(Row(f"{name}: the tool failed", message=shorten(f"{type(error).__name__}: {error}")))
            finally:
                self.runner.cleanup()
        return rows


def markdown(rows: list[Row]) -> str:
    def cell(text: str) -> str:
        return text.replace("|", "\\|").replace("\n", " ")

    lines = ["| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    for row in rows:
        values = (row.case, row.exit, row.message, row.opens, row.listed, row.readable, row.status,
                  row.timing, row.xdmf_parses, row.xdmf_states)
        lines.append("| " + " | ".join(cell(value) for value in values) + " |")
    return "\n".join(lines)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--binary", type=Path, default=REPOSITORY / "bin" / "crashfree")
    parser.add_argument("--kills", type=int, default=20, help="SIGKILL moments (default 20)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the kill moments (default 1)")
    parser.add_argument("--disk", choices=("auto", "tmpfs", "shim", "both"), default="auto",
                        help="how the disk is filled: tmpfs (root), the LD_PRELOAD shim, or auto")
    parser.add_argument("--keep", action="store_true",
                        help="keep the temporary directory (decks, logs, results) and print its name")
    arguments = parser.parse_args()
    binary = arguments.binary.resolve()
    if not os.access(binary, os.X_OK):
        print(f"fault_table: {binary} is not an executable file", file=sys.stderr)
        return 2
    if arguments.kills < 1:
        print("fault_table: --kills must be at least 1", file=sys.stderr)
        return 2

    # SIGTERM and SIGHUP end the tool through its finally blocks (as Ctrl-C does): solver
    # processes killed, tmpfs mounts unmounted, the temporary directory removed.
    def leave(number, frame):
        raise SystemExit(f"fault_table: stopped by {signal.Signals(number).name}")

    signal.signal(signal.SIGTERM, leave)
    signal.signal(signal.SIGHUP, leave)
    scratch = Path(tempfile.mkdtemp(prefix="fault_table_"))
    runner = Runner(binary, scratch)
    try:
        cases = Cases(runner, scratch, arguments.kills, arguments.seed, arguments.disk)
        methods = ", ".join(cases.disk_methods())
        rows = cases.all()
    finally:
        runner.cleanup()
        if arguments.keep:
            print(f"fault_table: decks, logs and results kept in {scratch}", file=sys.stderr)
        else:
            shutil.rmtree(scratch, ignore_errors=True)
    print(f"binary: {binary}; full disk by: {methods}; kills: {arguments.kills}, seed {arguments.seed}")
    print()
    print(markdown(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
