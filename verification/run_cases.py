#!/usr/bin/env python3
"""Run the solver on every deck of one or more verification manifests.

Each case runs in its own directory (the deck's), as ``bin/crashfree i=deck.k outdir=DIR
ncpu=N``; its output goes to ``DIR/solver.log`` and the exit status, wall time and the command
to ``DIR/run.json``, which the report reads beside ``DIR/results.h5``. A failing case does not
stop the others; the exit status is 1 when any case failed.

Usage::

    python3 verification/run_cases.py results/verification/patch/manifest.json \\
        results/verification/cantilever/manifest.json --ncpu 2
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

REPOSITORY = Path(__file__).resolve().parents[1]


def run_case(binary: Path, root: Path, case: dict, ncpu: int, timeout: float) -> dict:
    """Run one case; return its run record (status, wall time, command, last message line)."""
    deck = (root / case["deck"]).resolve()
    outdir = (root / case["outdir"]).resolve()
    outdir.mkdir(parents=True, exist_ok=True)
    results = outdir / "results.h5"
    if results.exists():
        results.unlink()
    command = [str(binary), f"i={deck}", f"outdir={outdir}", f"ncpu={ncpu}"]
    environment = dict(os.environ, OMP_NUM_THREADS=str(ncpu))
    start = time.perf_counter()
    try:
        process = subprocess.run(command, capture_output=True, text=True, timeout=timeout,
                                 env=environment, cwd=outdir)
        status, output = process.returncode, process.stdout + process.stderr
    except subprocess.TimeoutExpired as expired:
        status = -1
        output = (expired.stdout or "") if isinstance(expired.stdout, str) else ""
        output += f"\ntimeout after {timeout:.0f} s"
    wall = time.perf_counter() - start
    (outdir / "solver.log").write_text(output)
    lines = [line for line in output.splitlines() if line.strip()]
    record = {"name": case["name"], "status": status, "wall_s": wall, "ncpu": ncpu,
              "command": " ".join(command), "last_line": lines[-1] if lines else ""}
    if status != 0:
        problems = [line for line in lines if "error" in line.lower() or ": *" in line]
        record["message"] = "\n".join(problems[:5]) if problems else record["last_line"]
    (outdir / "run.json").write_text(json.dumps(record, indent=1))
    return record


def main(argv=None) -> int:
    """Run every case of the manifests; exit status 1 if any failed."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("manifests", type=Path, nargs="+", help="manifest.json files")
    parser.add_argument("--ncpu", type=int, default=int(os.environ.get("NCPU", "1") or 1),
                        help="OpenMP threads per run (default: NCPU, else 1)")
    parser.add_argument("--binary", type=Path, default=REPOSITORY / "bin" / "crashfree")
    parser.add_argument("--timeout", type=float, default=900.0, help="seconds per case")
    parser.add_argument("--only", nargs="*", default=None,
                        help="run only the cases whose name contains one of these strings")
    args = parser.parse_args(argv)
    if not args.binary.exists():
        parser.error(f"{args.binary} is missing: build it with make")
    failed = 0
    total_start = time.perf_counter()
    for manifest_path in args.manifests:
        manifest = json.loads(manifest_path.read_text())
        root = manifest_path.parent
        for case in manifest["cases"]:
            if args.only and not any(part in case["name"] for part in args.only):
                continue
            record = run_case(args.binary, root, case, args.ncpu, args.timeout)
            state = "ok" if record["status"] == 0 else f"FAILED (exit {record['status']})"
            print(f"{manifest['study']:>10} {case['name']:<36} {record['wall_s']:7.2f} s  {state}",
                  flush=True)
            if record["status"] != 0:
                failed += 1
                print("           " + record.get("message", "").replace("\n", "\n           "))
    print(f"all cases: {time.perf_counter() - total_start:.1f} s, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
