#!/usr/bin/env python3
"""Deck fuzzing harness for crashfree (docs/fuzzing.md).

Mutates the seed decks of tests/fuzz/seeds/ (structure, keywords, field values, extreme
physics) with a seeded random generator, runs every mutant with the release build and the
checked debug build, classifies each outcome (rejected, normal, error, timeout, FAILURE) and
keeps every failure's deck and output in a findings folder, deduplicated by signature.

    fuzz.py run [--decks N] [--seed S] [--jobs J] [--findings DIR] [--replay]
    fuzz.py seeds                          every seed must end normally in both builds
    fuzz.py show --seed S --index I [--write DIR]    the mutant, and the mutations that made it
    fuzz.py check DECK ... [--builds release,debug]   run decks and classify them
    fuzz.py shrink DECK --build debug [--out FILE]    delta-debug a failing deck
    fuzz.py replay [DIR]                   run the stored reproducers (tests/fuzz/findings/*.k)

Exit status: 0 when no run failed, 1 when some did, 2 on a usage error.
"""
from __future__ import annotations

import argparse
import collections
import concurrent.futures
import json
import os
import random
import re
import shutil
import sys
import tempfile
import threading
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPOSITORY = HERE.parents[1]
sys.path.insert(0, str(HERE))

from deck_mutator import mutate_deck  # noqa: E402
from outcome import Outcome, run_case  # noqa: E402
from shrink import shrink  # noqa: E402

BINARIES = {"release": REPOSITORY / "bin" / "crashfree", "debug": REPOSITORY / "build" / "debug" / "bin" / "crashfree"}
TIMEOUTS = {"release": 5.0, "debug": 12.0}
KINDS = ["rejected", "normal", "error", "timeout", "failure"]
ORDINARY_END_TIME = "time past ENDTIM within the last time step"


# ---------------------------------------------------------------------------------------------
# Seeds and mutants

def load_seeds(directory: Path) -> list[tuple[str, dict[str, str]]]:
    """(name, files) of every seed deck *.k in `directory`; files under include/ whose name starts
    with the seed's name belong to it."""
    seeds = []
    for path in sorted(directory.glob("*.k")):
        files = {path.name: path.read_text()}
        for include in sorted((directory / "include").glob(f"{path.stem}*")):
            files[f"include/{include.name}"] = include.read_text()
        seeds.append((path.stem, files))
    return seeds


def make_mutant(seeds, master_seed: int, index: int):
    """(seed name, files, mutations) of mutant `index` of run `master_seed`: the same every time."""
    rng = random.Random(f"crashfree-fuzz-{master_seed}-{index}")
    name, files = seeds[rng.randrange(len(seeds))]
    files = dict(files)
    mutations = mutate_deck(files, rng)
    return name, files, mutations


# ---------------------------------------------------------------------------------------------
# Findings

def slug(signature: str) -> str:
    return re.sub(r"[^A-Za-z0-9]+", "_", signature).strip("_")[:90]


class Findings:
    """Failures by signature (and notes), with their first examples kept on disk."""

    def __init__(self, directory: Path, keep: int):
        self.directory = directory
        self.keep = keep
        self.failures: dict[str, dict] = {}
        self.notes: dict[str, collections.Counter] = {}
        self.lock = threading.Lock()

    def add(self, label: str, build: str, files: dict[str, str], mutations: list[str], outcome: Outcome):
        with self.lock:
            for note in outcome.notes:
                self.notes.setdefault(note, collections.Counter())[build] += 1
            if outcome.kind != "failure":
                return
            entry = self.failures.setdefault(outcome.signature, {"builds": collections.Counter(), "examples": []})
            entry["builds"][build] += 1
            kept = sum(1 for example in entry["examples"] if example["build"] == build)
            example = {"label": label, "build": build, "reason": outcome.reason, "mutations": mutations}
            if kept >= self.keep:
                return
            folder = self.directory / slug(outcome.signature) / f"{label}_{build}"
            example["folder"] = str(folder)
            entry["examples"].append(example)
        if folder.exists():
            shutil.rmtree(folder)
        folder.mkdir(parents=True)
        for name, text in files.items():
            path = folder / name
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text, errors="surrogateescape")
        (folder / "stdout.txt").write_text(outcome.stdout)
        (folder / "stderr.txt").write_text(outcome.stderr)
        (folder / "reason.txt").write_text(f"{outcome.signature}\n{build}: {outcome.reason}\nexit status "
                                           f"{outcome.status}\nmutations:\n" + "".join(f"  {m}\n" for m in mutations))

    def write_summary(self):
        self.directory.mkdir(parents=True, exist_ok=True)
        summary = {signature: {"builds": dict(entry["builds"]), "examples": entry["examples"]}
                   for signature, entry in sorted(self.failures.items())}
        (self.directory / "summary.json").write_text(json.dumps(summary, indent=1))
        with open(self.directory / "summary.txt", "w") as out:
            for signature, entry in sorted(self.failures.items()):
                out.write(f"{signature}\n  runs: {dict(entry['builds'])}\n")
                for example in entry["examples"]:
                    out.write(f"  {example['label']} {example['build']}: {example['reason']}\n    {example['folder']}\n")


# ---------------------------------------------------------------------------------------------
# Running many decks

def binaries_for(arguments) -> dict[str, Path]:
    chosen = {}
    for build in arguments.builds.split(","):
        build = build.strip()
        if build not in BINARIES:
            sys.exit(f"fuzz.py: unknown build {build!r} (release, debug)")
        path = Path(getattr(arguments, f"{build}_binary") or BINARIES[build])
        if not path.exists():
            sys.exit(f"fuzz.py: {path} is missing: build it with `make` (release) or `make MODE=debug` (debug)")
        chosen[build] = path
    return chosen


def downgrade(outcome: Outcome, end_time: str) -> Outcome:
    """With --end-time step, ending within one step past ENDTIM is noted, not a failure."""
    if end_time == "step" and outcome.kind == "failure" and ORDINARY_END_TIME in outcome.signature:
        outcome.notes.append(outcome.signature)
        outcome.kind = "normal" if outcome.status == 0 else "error"
    return outcome


def run_many(cases, binaries, arguments, findings_for, scratch: Path, quiet=False):
    """Run every (label, files, mutations) case with every build; `findings_for(label)` is the
    Findings that keeps its failures. Returns {label: {build: outcome}}."""
    tasks = [(label, files, mutations, build) for label, files, mutations in cases for build in binaries]
    outcomes: dict[str, dict[str, Outcome]] = collections.defaultdict(dict)
    timeouts = {"release": arguments.timeout, "debug": arguments.timeout * arguments.debug_timeout_factor}
    started = time.monotonic()
    done = 0
    report_every = max(1, len(tasks) // 10)

    def work(task):
        label, files, mutations, build = task
        directory = scratch / f"{label}_{build}"
        # a stored reproducer may need its full time (one traps only at the 10 s progress line)
        timeout = timeouts[build] * (2.0 if label.startswith("replay-") else 1.0)
        outcome = run_case(files, binaries[build], directory, timeout)
        outcome = downgrade(outcome, arguments.end_time)
        findings_for(label).add(label, build, files, mutations, outcome)
        shutil.rmtree(directory, ignore_errors=True)
        return label, build, outcome

    with concurrent.futures.ThreadPoolExecutor(max_workers=arguments.jobs) as pool:
        for label, build, outcome in pool.map(work, tasks):
            outcome.stdout = outcome.stderr = ""          # kept on disk for failures; free the memory
            outcomes[label][build] = outcome
            done += 1
            if not quiet and done % report_every == 0:
                print(f"fuzz: {done}/{len(tasks)} runs, {time.monotonic() - started:.0f} s", flush=True)
    return outcomes


def print_table(outcomes, builds, findings: Findings, title: str):
    counts = {build: collections.Counter() for build in builds}
    for per_build in outcomes.values():
        for build, outcome in per_build.items():
            counts[build][outcome.kind] += 1
    print(f"\n{title}")
    print(f"{'class':<12}" + "".join(f"{build:>10}" for build in builds))
    for kind in KINDS:
        label = "FAILURE" if kind == "failure" else kind
        print(f"{label:<12}" + "".join(f"{counts[build][kind]:>10}" for build in builds))
    print(f"{'total':<12}" + "".join(f"{sum(counts[build].values()):>10}" for build in builds))
    if findings.failures:
        print(f"\n{len(findings.failures)} distinct failure signature(s) (runs per build; first example):")
        for signature, entry in sorted(findings.failures.items(), key=lambda item: -sum(item[1]["builds"].values())):
            builds_text = ", ".join(f"{build} {count}" for build, count in sorted(entry["builds"].items()))
            print(f"  [{builds_text}] {signature}")
            if entry["examples"]:
                example = entry["examples"][0]
                print(f"      e.g. {example['label']} ({example['build']}): {example['reason'][:200]}")
    if findings.notes:
        print(f"\nnotes (not failures): {len(findings.notes)}")
        for note, per_build in sorted(findings.notes.items()):
            print(f"  [{', '.join(f'{b} {c}' for b, c in sorted(per_build.items()))}] {note}")


def command_run(arguments) -> int:
    binaries = binaries_for(arguments)
    seeds = load_seeds(arguments.seeds)
    findings_directory = Path(arguments.findings or Path(tempfile.gettempdir()) / "crashfree-fuzz-findings" /
                              f"seed{arguments.seed}")
    if (findings_directory / "summary.json").exists():
        shutil.rmtree(findings_directory)      # the findings of an earlier run into the same folder
    findings = Findings(findings_directory, arguments.keep)
    replay_findings = Findings(findings_directory / "replay", arguments.keep)
    cases = []
    for index in range(arguments.decks):
        name, files, mutations = make_mutant(seeds, arguments.seed, index)
        cases.append((f"s{arguments.seed}-{index:05d}-{name}", files, mutations))
    replayed = []
    if arguments.replay:
        replayed = [(f"replay-{path.stem}", {path.name: path.read_text(errors="surrogateescape")}, ["stored reproducer"])
                    for path in sorted(Path(arguments.replay_directory).glob("*.k"))]
    print(f"fuzz: {len(cases)} mutants of {len(seeds)} seeds (seed {arguments.seed})"
          + (f" and {len(replayed)} stored reproducers" if replayed else "")
          + f", builds {', '.join(binaries)}, {arguments.jobs} jobs; findings in {findings_directory}", flush=True)
    started = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="crashfree-fuzz-") as scratch:
        outcomes = run_many(cases + replayed, binaries, arguments,
                            lambda label: replay_findings if label.startswith("replay-") else findings,
                            Path(scratch), arguments.quiet)
    findings.write_summary()
    if replayed:
        replay_findings.write_summary()
    mutants = {label: per_build for label, per_build in outcomes.items() if not label.startswith("replay-")}
    print_table(mutants, list(binaries), findings, f"outcomes of {len(mutants)} mutants by class and build "
                f"({time.monotonic() - started:.0f} s)")
    if replayed:
        print("\nstored reproducers (tests/fuzz/findings):")
        for label, _, _ in replayed:
            per_build = outcomes[label]
            text = ", ".join(f"{build} {outcome.kind}" + (f" ({outcome.signature})" if outcome.kind == "failure" else "")
                             for build, outcome in per_build.items())
            print(f"  {label[len('replay-'):]}: {text}")
    def failing(labels):
        return sum(1 for label in labels if any(o.kind == "failure" for o in outcomes[label].values()))

    failed = failing(outcomes)
    if replayed:
        replay_labels = [label for label, _, _ in replayed]
        print(f"\nmutants: {len(mutants) - failing(mutants)} passed, {failing(mutants)} failed; stored reproducers: "
              f"{len(replay_labels) - failing(replay_labels)} passed, {failing(replay_labels)} failed")
    print(f"\nfuzz: {len(outcomes) - failed} passed, {failed} failed")
    return 1 if failed else 0


# ---------------------------------------------------------------------------------------------
# Single decks: seeds, show, check, shrink, replay

def read_case(deck: Path) -> dict[str, str]:
    """The deck and the files under include/ beside it that it may use."""
    files = {deck.name: deck.read_text(errors="surrogateescape")}
    include = deck.parent / "include"
    if include.is_dir():
        for path in sorted(include.rglob("*")):
            if path.is_file():
                files[str(path.relative_to(deck.parent))] = path.read_text(errors="surrogateescape")
    return files


def run_cases_and_print(cases, arguments) -> int:
    binaries = binaries_for(arguments)
    failed = 0
    with tempfile.TemporaryDirectory(prefix="crashfree-fuzz-") as scratch:
        for label, files in cases:
            for build, binary in binaries.items():
                timeout = arguments.timeout * (arguments.debug_timeout_factor if build == "debug" else 1.0)
                outcome = downgrade(run_case(files, binary, Path(scratch) / "run", timeout), arguments.end_time)
                failed += outcome.kind == "failure"
                detail = outcome.signature if outcome.kind == "failure" else outcome.reason
                print(f"{label:<40} {build:<8} {outcome.kind:<9} exit {outcome.status} {outcome.seconds:5.2f} s  {detail}")
                if arguments.verbose:
                    print(outcome.stderr[-3000:])
    return 1 if failed else 0


def command_seeds(arguments) -> int:
    arguments.end_time = "step"      # a seed may end within its last step past ENDTIM (reported by run)
    seeds = load_seeds(arguments.seeds)
    return run_cases_and_print(seeds, arguments)


def command_show(arguments) -> int:
    seeds = load_seeds(arguments.seeds)
    name, files, mutations = make_mutant(seeds, arguments.seed, arguments.index)
    print(f"mutant {arguments.index} of seed {arguments.seed}: from {name}")
    for mutation in mutations:
        print(f"  {mutation}")
    if arguments.write:
        directory = Path(arguments.write)
        for file_name, text in files.items():
            path = directory / file_name
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text, errors="surrogateescape")
        print(f"written to {directory / next(iter(files))}")
    else:
        for file_name, text in files.items():
            print(f"----- {file_name}\n{text}")
    return 0


def command_check(arguments) -> int:
    return run_cases_and_print([(Path(deck).name, read_case(Path(deck))) for deck in arguments.decks], arguments)


def command_replay(arguments) -> int:
    decks = sorted(Path(arguments.directory).glob("*.k"))
    return run_cases_and_print([(deck.name, read_case(deck)) for deck in decks], arguments)


def command_shrink(arguments) -> int:
    binaries = binaries_for(arguments)
    build = next(iter(binaries))
    deck = Path(arguments.deck)
    files = read_case(deck)
    timeout = arguments.timeout * (arguments.debug_timeout_factor if build == "debug" else 1.0)
    with tempfile.TemporaryDirectory(prefix="crashfree-shrink-") as scratch:
        first = downgrade(run_case(files, binaries[build], Path(scratch) / "run", timeout), arguments.end_time)
        signature = arguments.signature or first.signature
        if first.kind != "failure" and not arguments.signature:
            print(f"{deck} does not fail with the {build} build ({first.kind}): nothing to shrink")
            return 1
        print(f"shrinking {deck} ({build}): {signature}")

        def still_fails(candidate):
            outcome = downgrade(run_case(candidate, binaries[build], Path(scratch) / "run", timeout), arguments.end_time)
            return outcome.kind == "failure" and outcome.signature == signature

        smallest = shrink(files, still_fails)
    out = Path(arguments.out or deck.with_suffix(".min.k"))
    text = next(iter(smallest.values()))
    out.write_text(text, errors="surrogateescape")
    print(f"{len(text.splitlines())} lines: {out}")
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)

    def common(p, builds="release,debug"):
        p.add_argument("--builds", default=builds, help="release, debug or both (comma separated)")
        p.add_argument("--release-binary", help=f"default {BINARIES['release']}")
        p.add_argument("--debug-binary", help=f"default {BINARIES['debug']}")
        p.add_argument("--timeout", type=float, default=TIMEOUTS["release"], help="seconds per release run")
        p.add_argument("--debug-timeout-factor", type=float, default=TIMEOUTS["debug"] / TIMEOUTS["release"],
                       help="the debug build's time limit over the release build's")
        p.add_argument("--end-time", choices=["strict", "step"], default="strict",
                       help="strict: any time past ENDTIM (relative 1e-9) is a failure; step: ending within one "
                            "time step past ENDTIM is only noted")
        p.add_argument("--seeds", type=Path, default=HERE / "seeds")
        p.add_argument("--verbose", action="store_true")

    run = sub.add_parser("run", help="mutate and run many decks")
    common(run)
    run.add_argument("--decks", type=int, default=int(os.environ.get("FUZZ_DECKS", 1000)), help="mutants (per build)")
    run.add_argument("--seed", type=int, default=int(os.environ.get("FUZZ_SEED", 1)))
    run.add_argument("--jobs", type=int, default=int(os.environ.get("FUZZ_JOBS", 2)))
    run.add_argument("--findings", help="folder for failing decks and their output (default: in the temp folder)")
    run.add_argument("--keep", type=int, default=3, help="examples kept per signature and build")
    run.add_argument("--replay", action="store_true", help="also run the stored reproducers")
    run.add_argument("--replay-directory", default=str(HERE / "findings"))
    run.add_argument("--quiet", action="store_true")
    run.set_defaults(handler=command_run)

    seeds = sub.add_parser("seeds", help="run every seed: each must end normally")
    common(seeds)
    seeds.set_defaults(handler=command_seeds)

    show = sub.add_parser("show", help="print or write one mutant")
    show.add_argument("--seed", type=int, required=True)
    show.add_argument("--index", type=int, required=True)
    show.add_argument("--write", help="folder to write the mutant's files into")
    show.add_argument("--seeds", type=Path, default=HERE / "seeds")
    show.set_defaults(handler=command_show)

    check = sub.add_parser("check", help="run and classify decks")
    common(check)
    check.add_argument("decks", nargs="+")
    check.set_defaults(handler=command_check)

    replay = sub.add_parser("replay", help="run the stored reproducers")
    common(replay)
    replay.add_argument("directory", nargs="?", default=str(HERE / "findings"))
    replay.set_defaults(handler=command_replay)

    shrink_parser = sub.add_parser("shrink", help="delta-debug a failing deck")
    common(shrink_parser, builds="debug")
    shrink_parser.add_argument("deck")
    shrink_parser.add_argument("--signature", help="the signature to keep (default: the deck's own)")
    shrink_parser.add_argument("--out", help="default: DECK.min.k")
    shrink_parser.set_defaults(handler=command_shrink)

    arguments = parser.parse_args(argv)
    return arguments.handler(arguments)


if __name__ == "__main__":
    sys.exit(main())
