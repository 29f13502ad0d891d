"""Run one deck with one crashfree binary and classify what happened.

Classes (docs/fuzzing.md):
  rejected     exit 2, every problem reported as file:line: *KEYWORD: ...
  normal       exit 0, a readable results file, status "normal termination", finite values,
               nothing past ENDTIM
  error        exit 1 with a message that names the time and an element, node, part or body
  timeout      still running after the time limit, or stopped by the file size limit (a
               state written every cycle): killed, not a failure
  FAILURE      anything else: a signal (a floating-point trap of the debug build, a
               segmentation fault, an abort), a Fortran runtime error on any exit status, exit 0
               with non-finite values or with results past ENDTIM, a wrong status attribute, exit
               1 without a message, a message without its location, an unreadable results file.

Each failure has a signature for deduplication: the trap or runtime error location (file:line
of the first frame in the solver's sources), or the class of the message with its numbers
blanked out.
"""
from __future__ import annotations

import os
import re
import resource
import shutil
import signal
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

RELATIVE_END_TIME_TOLERANCE = 1e-9
MEMORY_LIMIT_BYTES = 3 * 1024 ** 3      # per run: a runaway allocation fails instead of swapping
FILE_SIZE_LIMIT_BYTES = 256 * 1024 ** 2  # per file written by a run (a state every cycle of a long run)
OUTPUT_KEEP_CHARACTERS = 200_000        # of stdout and stderr kept for classification and findings


@dataclass
class Outcome:
    """What one run did: the class, and for failures a one-line reason and a signature."""
    kind: str                       # rejected | normal | error | timeout | failure
    reason: str = ""
    signature: str = ""
    status: int | None = None
    seconds: float = 0.0
    stdout: str = ""
    stderr: str = ""
    notes: list[str] = field(default_factory=list)   # non-failing observations (array temporaries ...)


# ---------------------------------------------------------------------------------------------
# The deck's end time (ENDTIM, ENDCYC), read the way crashfree reads it

def parse_real(text: str):
    text = text.strip()
    match = re.fullmatch(r"([+-]?(?:\d+\.?\d*|\.\d+))(?:[eEdD]([+-]?\d+)|([+-]\d+))?", text)
    if not match:
        return None
    exponent = match.group(2) or match.group(3)
    try:
        return float(match.group(1)) * 10.0 ** int(exponent) if exponent else float(match.group(1))
    except OverflowError:
        return float("inf")


def deck_lines(main: Path, depth: int = 0):
    """(file, line text) of the deck in reading order, *INCLUDE files expanded (names may be a
    character parameter); unreadable includes are skipped."""
    if depth > 10 or not main.is_file():
        return []
    try:
        text = main.read_bytes().decode("latin-1")
    except OSError:
        return []
    lines = [line.rstrip("\r") for line in text.split("\n")]
    parameters = read_parameters(lines)
    result = []
    k = 0
    while k < len(lines):
        line = lines[k]
        if line[:1] == "*" and line[1:].split() and line[1:].split()[0].upper().rstrip("+-%") == "END":
            break
        result.append((main, line))
        if line[:1] == "*" and line[1:].split() and line[1:].split()[0].upper().rstrip("+-%") == "INCLUDE":
            j = k + 1
            while j < len(lines) and lines[j].lstrip().startswith("$"):
                j += 1
            if j < len(lines) and not lines[j].startswith("*"):
                name = lines[j].strip().strip("'\"")
                if name.startswith("&"):
                    name = str(parameters.get(name[1:].upper(), name))
                if name:
                    result += deck_lines(main.parent / name, depth + 1)
                k = j
        k += 1
    return result


def read_parameters(lines):
    """Names and values of *PARAMETER cards (R, I, C; 10+10 columns, 20+20 long, or commas)."""
    values, active, long_format = {}, False, False
    for line in lines:
        if line.startswith("*"):
            head = line[1:].split()[0].upper() if line[1:].split() else ""
            active = head.rstrip("+-%") == "PARAMETER"
            long_format = head.endswith("+")
            continue
        if not active or line.lstrip().startswith("$"):
            continue
        if "," in line:
            parts = [p.strip() for p in line.split(",")]
        else:
            width = 20 if long_format else 10
            parts = [line[j:j + width] for j in range(0, len(line), width)]
        for name, value in zip(parts[0::2], parts[1::2]):
            name = name.strip()
            if len(name) < 2:
                continue
            kind, label = name[0].upper(), name[1:].strip().upper()
            if label in values:
                continue
            values[label] = parse_real(value) if kind in "RI" else value.strip()
    return values


def termination(main: Path):
    """(ENDTIM, ENDCYC) of the last *CONTROL_TERMINATION, parameters resolved; None if unreadable."""
    lines = deck_lines(main)
    if not lines:
        return None
    parameters = read_parameters([text for _, text in lines])
    found = None
    long_everywhere = False
    for k, (_, line) in enumerate(lines):
        if not line.startswith("*"):
            continue
        words = line[1:].split()
        head = words[0].upper() if words else ""
        if head.rstrip("+-%") == "KEYWORD" and "LONG=Y" in line.upper():
            long_everywhere = True
        if head.rstrip("+-%") != "CONTROL_TERMINATION":
            continue
        card = next((text for _, text in lines[k + 1:] if not text.lstrip().startswith("$")), "")
        if card.startswith("*"):
            card = ""
        width = 20 if head.endswith("+") or (long_everywhere and not head.endswith("-")) else 10
        fields = [p for p in card.split(",")] if "," in card else [card[0:width], card[width:2 * width]]

        def value(text):
            text = text.strip()
            if not text:
                return 0.0
            negative = text.startswith("-&")
            if text.lstrip("-").startswith("&"):
                number = parameters.get(text.lstrip("-")[1:].upper())
                if not isinstance(number, float):
                    return None
                return -number if negative else number
            return parse_real(text)

        endtim = value(fields[0]) if fields else 0.0
        endcyc = value(fields[1]) if len(fields) > 1 else 0.0
        found = (endtim, endcyc)
    return found


# ---------------------------------------------------------------------------------------------
# Running

def limit_resources():
    """Child process set-up: no core files, bounded memory and file sizes, own process group."""
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT_BYTES, MEMORY_LIMIT_BYTES))
    resource.setrlimit(resource.RLIMIT_FSIZE, (FILE_SIZE_LIMIT_BYTES, FILE_SIZE_LIMIT_BYTES))


def write_case(files: dict[str, str | bytes], directory: Path) -> Path:
    """Write the deck's files under `directory`; return the main deck's path (the first file)."""
    main = None
    for name, text in files.items():
        path = directory / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(text if isinstance(text, bytes) else text.encode("utf-8", "surrogateescape"))
        main = main or path
    return main


def run_case(files: dict[str, str], binary: Path, directory: Path, timeout: float) -> Outcome:
    """Run the deck (files written into directory/deck) with `binary` on one thread, results in
    directory/out, and classify the outcome."""
    deck_directory = directory / "deck"
    output = directory / "out"
    if directory.exists():
        shutil.rmtree(directory)
    deck_directory.mkdir(parents=True)
    main = write_case(files, deck_directory)
    environment = dict(os.environ, OMP_NUM_THREADS="1", GFORTRAN_ERROR_BACKTRACE="1")
    command = [str(binary), f"i={main.name}", f"outdir={output}", "ncpu=1"]
    started = time.monotonic()
    process = subprocess.Popen(command, cwd=deck_directory, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               env=environment, preexec_fn=limit_resources, start_new_session=True)
    try:
        stdout, stderr = process.communicate(timeout=timeout)
        timed_out = False
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        stdout, stderr = process.communicate()
        timed_out = True
    seconds = time.monotonic() - started
    outcome = classify(process.returncode, stdout.decode("latin-1")[-OUTPUT_KEEP_CHARACTERS:],
                       stderr.decode("latin-1")[-OUTPUT_KEEP_CHARACTERS:], output / "results.h5", main, timed_out)
    outcome.seconds = seconds
    return outcome


# ---------------------------------------------------------------------------------------------
# Classification

FRAME = re.compile(r"^\s+at (\S+\.f90):(\d+)", re.MULTILINE)
RUNTIME_LOCATION = re.compile(r"At line (\d+) of file (\S+)(?: \(unit = \d+.*\))?\n(Fortran runtime (error|warning): .*)")
LOCATION_WORDS = re.compile(r"\b(element|elements|shell|shells|node|nodes|part|parts|body|cell|wall|contact|segment|"
                            r"particle|point|curve)\s+\d+", re.IGNORECASE)
DECK_LOCATION = re.compile(r"^\S[^\n:]*:\d+: ", re.MULTILINE)
# a problem of the whole deck (no nodes, no elements, an empty or binary file) names the file, no line
DECK_FILE_ONLY = re.compile(r"^\S[^\n:]*\.\w+: ", re.MULTILINE)
SIGNAL_NAMES = {getattr(signal, name): name for name in dir(signal) if name.startswith("SIG") and "_" not in name}


def source_location(path: str, line: str) -> str:
    """A source path as the repository names it (src/...), whatever directory it was built in."""
    marker = path.find("src/")
    return f"{path[marker:] if marker >= 0 else path}:{line}"


def normalise(message: str) -> str:
    """A message's class: numbers and quoted texts blanked, so that one cause gives one signature."""
    message = re.sub(r"[\w./-]+\.k\b", "deck.k", message)
    message = re.sub(r"'[^']*'", "'…'", message)
    message = re.sub(r'"[^"]*"', '"…"', message)
    message = re.sub(r"[-+]?(\d+\.?\d*|\.\d+)([eEdD][-+]?\d+)?", "#", message)
    message = re.sub(r"\s+", " ", message).strip()
    return message[:160]


def runtime_problem(text: str):
    """(signature, reason) of a Fortran runtime error, a signal report or a backtrace, or None."""
    for match in RUNTIME_LOCATION.finditer(text):
        if match.group(4) == "error":
            where = source_location(match.group(2), match.group(1))
            message = match.group(3).strip()
            return f"runtime error at {where}: {normalise(message)}", f"{message} (at {where})"
    if "Fortran runtime error" in text:
        line = next(l for l in text.splitlines() if "Fortran runtime error" in l)
        return f"runtime error: {normalise(line)}", line.strip()
    received = re.search(r"Program received signal (\w+)", text)
    if received or "Backtrace for this error" in text or "Error termination. Backtrace" in text:
        frames = FRAME.findall(text)
        frames = [f for f in frames if "src/" in f[0] or f[0].endswith(".f90")]
        where = source_location(*frames[0]) if frames else "unknown location"
        name = received.group(1) if received else "backtrace"
        return f"{name} at {where}", f"{name} at {where}"
    if "Operating system error" in text or "Cannot allocate memory" in text:
        line = next(l for l in text.splitlines() if "error" in l.lower())
        return f"runtime error: {normalise(line)}", line.strip()
    return None


def notes_of(text: str) -> list[str]:
    """Runtime warnings of the checked build (array temporaries), by location: not failures."""
    return sorted({f"runtime warning at {source_location(m.group(2), m.group(1))}: {normalise(m.group(3))}"
                   for m in RUNTIME_LOCATION.finditer(text) if m.group(4) == "warning"})


def error_message(stderr: str) -> str:
    """The run-time error message crashfree printed (after 'error termination:'), or ''."""
    found = re.findall(r"crashfree: error termination: (.*)", stderr)
    if found:
        return found[-1].strip()
    lines = [l for l in stderr.splitlines() if l.startswith("crashfree: ")]
    return lines[-1][len("crashfree: "):].strip() if lines else ""


def classify(status: int, stdout: str, stderr: str, results: Path, deck: Path, timed_out: bool) -> Outcome:
    """The class of a finished run from its exit status, output and results file (module doc)."""
    everything = stdout + "\n" + stderr
    notes = notes_of(everything)

    def failure(reason, signature):
        return Outcome("failure", reason, signature, status, stdout=stdout, stderr=stderr, notes=notes)

    if timed_out:
        return Outcome("timeout", "killed after the time limit", "", status, stdout=stdout, stderr=stderr, notes=notes)
    if status == -signal.SIGXFSZ:
        return Outcome("timeout", "stopped by the file size limit", "", status, stdout=stdout, stderr=stderr,
                       notes=notes)
    problem = runtime_problem(everything)
    if problem:
        return failure(problem[1], problem[0])
    if status < 0:
        name = SIGNAL_NAMES.get(-status, f"signal {-status}")
        return failure(f"killed by {name} without a backtrace", f"{name} without a backtrace")
    if status not in (0, 1, 2):
        return failure(f"exit status {status}", f"exit status {status}")
    if status == 2:
        if not DECK_LOCATION.search(stderr) and DECK_FILE_ONLY.search(stderr):
            start = DECK_FILE_ONLY.search(stderr).group(0)
            line = next(text for text in stderr.splitlines() if text.startswith(start))
            notes.append(f"rejected with file but no line: {normalise(line)}")
        elif not DECK_LOCATION.search(stderr):
            lines = [l for l in stderr.splitlines() if l.strip() and "warning" not in l.lower()]
            message = lines[0] if lines else "(no message)"
            return failure(f"exit 2 without file:line: {message}", f"rejected without file:line: {normalise(message)}")
        if results.exists():
            return failure("exit 2 (deck rejected) but a results file was written",
                           "rejected deck left a results file")
        return Outcome("rejected", "", "", status, stdout=stdout, stderr=stderr, notes=notes)
    message = error_message(stderr) if status == 1 else ""
    if status == 1:
        if not message:
            return failure("exit 1 without a message", "exit 1 without a message")
        # the linear static analysis has no time: its messages name the node or element alone
        timed = re.search(r"\btime\b", message, re.IGNORECASE) or message.startswith("static analysis")
        if not (timed and LOCATION_WORDS.search(message)):
            return failure(f"run-time message without element/node and time: {message}",
                           f"message without location: {normalise(message)}")
    checked = check_results(results, status, deck, notes)
    if checked:
        return failure(*checked)
    kind = "normal" if status == 0 else "error"
    return Outcome(kind, message, "", status, stdout=stdout, stderr=stderr, notes=notes)


def check_results(results: Path, status: int, deck: Path, notes: list[str]):
    """(reason, signature) of what is wrong with the results file of an exit 0 or 1, or None.
    A negative kinetic energy after normal termination (a wrong result, not a crash) is added
    to `notes`."""
    import h5py
    if not results.exists():
        return f"exit {status} but no results file", f"exit {status} without a results file"
    try:
        handle = h5py.File(results, "r")
    except Exception as error:      # noqa: BLE001 - any failure to open is the finding
        return f"exit {status} and h5py cannot open results.h5: {error}", f"exit {status} with an unreadable results file"
    with handle:
        try:
            run_status = handle["run"].attrs.get("status", b"")
            run_status = run_status.decode() if isinstance(run_status, bytes) else str(run_status)
            expected = "normal termination" if status == 0 else "error termination"
            if run_status != expected:
                return (f"exit {status} with status attribute {run_status!r}",
                        f"exit {status} with status attribute {run_status!r}")
            if status == 0:
                bad = non_finite(handle)
                if bad:
                    return (f"exit 0 with non-finite values in {', '.join(bad[:4])}",
                            f"exit 0 with non-finite values ({', '.join(sorted({b.split('/')[0] for b in bad}))})")
            times = last_times(handle)
            glstat = handle.get("history/glstat")
            if status == 0 and glstat is not None and "kinetic_energy" in glstat:
                kinetic = glstat["kinetic_energy"][...]
                if kinetic.size and np.nanmin(kinetic) < 0.0:
                    notes.append("exit 0 with a negative kinetic energy in history/glstat")
            steps = glstat["time_step"][...] if glstat is not None and "time_step" in glstat else None
        except Exception as error:  # noqa: BLE001
            return f"exit {status} and results.h5 cannot be read: {error}", f"exit {status} with an unreadable results file"
    return end_time_problem(times, steps, deck, status)


def non_finite(handle) -> list[str]:
    """Names (states/*/..., history/...) of datasets and attributes holding NaN or Inf."""
    found = []

    def visit(name, item):
        label = re.sub(r"states/\d+", "states/*", name)
        label = re.sub(r"/(\d+)(/|$)", r"/*\2", label)
        for attribute, value in item.attrs.items():
            array = np.asarray(value)
            if array.dtype.kind == "f" and not np.all(np.isfinite(array)):
                found.append(f"{label}@{attribute}")
        if hasattr(item, "dtype") and item.dtype.kind == "f":
            if not np.all(np.isfinite(item[...])):
                found.append(label)

    visit("run", handle["run"])
    handle.visititems(visit)
    unique = []
    for name in found:
        if name not in unique:
            unique.append(name)
    return unique


def last_times(handle) -> dict[str, float]:
    """The largest time of the states, of each history group, and /run end_time."""
    times = {}
    states = handle.get("states")
    if states is not None and len(states):
        times["states"] = max(float(states[name].attrs.get("time", -np.inf)) for name in states)
    history = handle.get("history")
    if history is not None:
        def visit(name, item):
            if hasattr(item, "dtype") and name.endswith("time") and item.shape and item.shape[0]:
                label = "history/" + re.sub(r"/(\d+)/", "/*/", name)
                times[label] = max(times.get(label, -np.inf), float(np.nanmax(item[...])))
        history.visititems(visit)
    if "end_time" in handle["run"].attrs:
        times["run@end_time"] = float(handle["run"].attrs["end_time"])
    return times


def end_time_problem(times: dict[str, float], steps, deck: Path, status: int):
    """Times past ENDTIM (relative 1e-9), in three signatures: past by less than the run's last
    time step (the last step was not cut at ENDTIM), by a last step longer than ENDTIM itself,
    or by more than one step (the run went on after ENDTIM)."""
    limits = termination(deck)
    if not limits or not times:
        return None
    endtim, endcyc = limits
    if endtim is None or not np.isfinite(endtim) or endtim <= 0.0:
        return None
    latest_name, latest = max(times.items(), key=lambda item: item[1])
    if not latest > endtim * (1.0 + RELATIVE_END_TIME_TOLERANCE):
        return None
    past = latest - endtim
    last_step = float(steps[-1]) if steps is not None and len(steps) else None
    detail = f"{latest_name} = {latest:.6g} with ENDTIM {endtim:.6g}"
    if last_step is None or not np.isfinite(last_step):
        return (f"exit {status}: {detail}", f"exit {status}: time past ENDTIM (no time step history)")
    if past > last_step * (1.0 + 1e-6):
        return (f"exit {status}: {detail}, {past / last_step:.3g} last steps ({last_step:.3g}) past it",
                f"exit {status}: time more than one time step past ENDTIM")
    if last_step > endtim:
        return (f"exit {status}: {detail}, last time step {last_step:.3g} longer than ENDTIM",
                f"exit {status}: time past ENDTIM by a time step longer than ENDTIM")
    return (f"exit {status}: {detail}, within the last time step {last_step:.3g}",
            f"exit {status}: time past ENDTIM within the last time step (the last step is not cut at ENDTIM)")
