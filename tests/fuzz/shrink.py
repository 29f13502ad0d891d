"""Delta debugging of a failing deck: remove keyword blocks, then chunks of lines, then single
lines, keeping every removal after which the deck still fails with the same signature (Zeller's
ddmin, on the lines of the main deck; include files are kept as they are)."""
from __future__ import annotations

from typing import Callable

Files = dict[str, str]


def with_main(files: Files, lines: list[str]) -> Files:
    changed = dict(files)
    changed[next(iter(files))] = "\n".join(lines) + "\n"
    return changed


def keyword_blocks(lines: list[str]) -> list[tuple[int, int]]:
    starts = [k for k, line in enumerate(lines) if line.startswith("*")]
    return list(zip(starts, starts[1:] + [len(lines)]))


def shrink(files: Files, still_fails: Callable[[Files], bool], log=print) -> Files:
    """The smallest deck found that still fails; `still_fails` runs a candidate."""
    lines = next(iter(files.values())).rstrip("\n").split("\n")
    runs = 0

    def test(candidate: list[str]) -> bool:
        nonlocal runs
        runs += 1
        return still_fails(with_main(files, candidate))

    # 1. whole keyword blocks, last first (later blocks often only refer to earlier ones)
    changed = True
    while changed:
        changed = False
        for start, end in reversed(keyword_blocks(lines)):
            candidate = lines[:start] + lines[end:]
            if candidate and test(candidate):
                lines = candidate
                changed = True
                break
    log(f"shrink: {len(lines)} lines after removing keyword blocks ({runs} runs)")

    # 2. ddmin over lines
    granularity = 2
    while len(lines) >= 2:
        chunk = max(1, len(lines) // granularity)
        removed_any = False
        start = 0
        while start < len(lines):
            candidate = lines[:start] + lines[start + chunk:]
            if candidate and test(candidate):
                lines = candidate
                removed_any = True
            else:
                start += chunk
        if removed_any:
            granularity = max(granularity - 1, 2)
        elif chunk == 1:
            break
        else:
            granularity = min(granularity * 2, len(lines))
    log(f"shrink: {len(lines)} lines after ddmin ({runs} runs)")

    # 3. trailing blanks of each card and comment lines
    for k in range(len(lines)):
        stripped = lines[k].rstrip()
        if stripped != lines[k]:
            candidate = lines[:k] + [stripped] + lines[k + 1:]
            if test(candidate):
                lines = candidate
    log(f"shrink: done after {runs} runs")
    return with_main(files, lines)
