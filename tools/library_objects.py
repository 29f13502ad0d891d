#!/usr/bin/env python3
"""Write the make variable that lists the objects of the embedding library.

The library for host codes (lib/libcrashfree_efg.a, docs/embedding.md) holds the API modules and
every project module they use, directly or through others, and nothing else: a host then links
no HDF5, METIS or output code. Fortran calls a module procedure only through a `use`, so the
closure over `use` statements is the closure over calls. Usage:
    library_objects.py VARIABLE OBJDIR ROOT.f90 ... -- SOURCE.f90 ... > file.mk
"""
import re
import sys
from pathlib import Path

MODULE = re.compile(r"^\s*module\s+(?!procedure\b)(\w+)", re.IGNORECASE)
USE = re.compile(r"^\s*use\s*(?:,\s*(?:non_)?intrinsic\s*::)?\s*(\w+)", re.IGNORECASE)


def main() -> None:
    variable, object_dir = sys.argv[1], sys.argv[2]
    separator = sys.argv.index("--")
    roots, sources = sys.argv[3:separator], sys.argv[separator + 1:]
    defined = {}
    uses = {}
    for source in sources:
        uses[source] = set()
        for line in Path(source).read_text(errors="replace").splitlines():
            line = line.split("!")[0]
            found = MODULE.match(line)
            if found:
                defined[found.group(1).lower()] = source
            found = USE.match(line)
            if found:
                uses[source].add(found.group(1).lower())
    needed = set()
    pending = [root for root in roots if root in uses]
    while pending:
        source = pending.pop()
        if source in needed:
            continue
        needed.add(source)
        pending.extend(defined[name] for name in uses[source] if name in defined)
    objects = sorted(f"{object_dir}/{Path(source).stem}.o" for source in needed)
    print(f"{variable} := {' '.join(objects)}")


if __name__ == "__main__":
    main()
