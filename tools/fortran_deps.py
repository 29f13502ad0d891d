#!/usr/bin/env python3
"""Write make rules for Fortran module dependencies.

For every source file, the object depends on the objects of the modules it uses that are
defined in the project (intrinsic and library modules such as hdf5 are skipped). Usage:
    fortran_deps.py OBJDIR file.f90 ... > deps.mk
"""
import re
import sys
from pathlib import Path

MODULE = re.compile(r"^\s*module\s+(?!procedure\b)(\w+)", re.IGNORECASE)
USE = re.compile(r"^\s*use\s*(?:,\s*(?:non_)?intrinsic\s*::)?\s*(\w+)", re.IGNORECASE)


def main() -> None:
    object_dir, sources = sys.argv[1], sys.argv[2:]
    defined = {}
    uses = {}
    for source in sources:
        text = Path(source).read_text(errors="replace").splitlines()
        uses[source] = set()
        for line in text:
            line = line.split("!")[0]
            found = MODULE.match(line)
            if found:
                defined[found.group(1).lower()] = source
            found = USE.match(line)
            if found:
                uses[source].add(found.group(1).lower())

    def object_of(source: str) -> str:
        return f"{object_dir}/{Path(source).stem}.o"

    for source in sources:
        needed = sorted(
            {object_of(defined[name]) for name in uses[source] if name in defined}
            - {object_of(source)}
        )
        if needed:
            print(f"{object_of(source)}: {' '.join(needed)}")


if __name__ == "__main__":
    main()
