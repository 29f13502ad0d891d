#!/usr/bin/env python3
"""Check that the folders of src/ are layers: a module may use only modules of its own folder
or of a folder in a lower layer. Folders in the same layer are siblings and may not use each
other.

    core <- model <- materials <- elements <- (efg | contact) <- api <- deck <- solver
         <- output <- static <- app

- elements sits below efg: the meshfree parts take the hexahedron geometry and the element
  time step of their background cells (efg_forces uses hex8_geometry and element_time_step);
  contact uses neither elements nor efg, and efg and contact may not use each other.
- api holds the embedding library crashfree_efg (a host code's Fortran and C interface to the
  meshfree parts): it uses efg and what efg stands on, and nothing of the program uses it (the
  solver's meshfree group calls the same efg procedures the library calls).
- deck (the starter: deck text -> checked model) uses the contact surfaces to find the element
  owning a segment.
- output is above the solver: it writes what the model and the run state hold; the solver's
  phases do not know the files (the run is driven from app/explicit_run).
- static (the linear static analysis) assembles element and EFG stiffness and writes its one
  state through output; the job (app) runs it or the explicit run.

Every `use` of every src/**/*.f90 is checked (intrinsic and library modules such as hdf5 are
not the project's and are skipped). Uses listed in ALLOWED_FOR_NOW are reported but do not fail
the check; an entry that no longer occurs fails it, so that the list only shrinks. Prints every
violation and exits with status 1 when there is one. Usage: check_layers.py [SRC_DIR]

The embedding library (src/api and every module it uses, directly or not) never prints, never
stops the process, never opens or writes files; and only the program (src/app) sets the OpenMP
thread count. Both are checked on the code (comments left out): a `stop`, `error stop`, `print`,
`write` to the terminal, `open` or C `fopen` in a module of the library's closure, or a call of
`omp_set_num_threads` outside src/app, is a violation.
"""
import re
import sys
from pathlib import Path

# Layer of each folder; equal numbers are siblings.
LAYERS = {
    "core": 0,
    "model": 1,
    "materials": 2,
    "elements": 3,
    "efg": 4,
    "contact": 4,
    "api": 5,
    "deck": 6,
    "solver": 7,
    "output": 8,
    "static": 9,
    "app": 10,
}

# Known violations, allowed until the files that hold them are rewritten (none now).
ALLOWED_FOR_NOW = set()

# What the library may not do (on the code of a line, its comment cut off).
LIBRARY_FOLDER = "api"
FORBIDDEN_IN_LIBRARY = re.compile(
    r"^\s*(error\s+)?stop\b|\bprint\s*[*'\"(]|\bwrite\s*\(\s*(\*|output_unit|error_unit)|\bopen\s*\(|c_fopen",
    re.IGNORECASE)
THREAD_COUNT = re.compile(r"\bomp_set_num_threads\b", re.IGNORECASE)

MODULE = re.compile(r"^\s*module\s+(?!procedure\b)(\w+)", re.IGNORECASE)
USE = re.compile(r"^\s*use\s*(?:,\s*(?:non_)?intrinsic\s*::)?\s*(\w+)", re.IGNORECASE)


def scan(src: Path):
    """Module -> folder, and (file, line number, module used) for every use statement."""
    defined = {}
    uses = []
    for path in sorted(src.rglob("*.f90")):
        relative = path.relative_to(src).as_posix()
        for number, line in enumerate(path.read_text(errors="replace").splitlines(), start=1):
            code = line.split("!")[0]
            found = MODULE.match(code)
            if found:
                defined[found.group(1).lower()] = relative.split("/")[0]
            found = USE.match(code)
            if found:
                uses.append((relative, number, found.group(1).lower()))
    return defined, uses


def fortran_sources(src: Path):
    """Every Fortran source of src/ (free form, preprocessed or not)."""
    return sorted([*src.rglob("*.f90"), *src.rglob("*.F90")])


def library_problems(src: Path):
    """Lines of the library's module closure that print, stop or open files; thread counts set
    outside src/app."""
    uses_of = {}
    for path in fortran_sources(src):
        for line in path.read_text(errors="replace").splitlines():
            found = USE.match(line.split("!")[0])
            if found:
                uses_of.setdefault(path, set()).add(found.group(1).lower())
    module_file = {}
    for path in fortran_sources(src):
        for line in path.read_text(errors="replace").splitlines():
            found = MODULE.match(line.split("!")[0])
            if found:
                module_file[found.group(1).lower()] = path
    closure = set()
    pending = [path for path in fortran_sources(src) if path.parent == src / LIBRARY_FOLDER]
    while pending:
        path = pending.pop()
        if path in closure:
            continue
        closure.add(path)
        pending.extend(module_file[module] for module in uses_of.get(path, ()) if module in module_file)
    problems = []
    for path in fortran_sources(src):
        relative = path.relative_to(src).as_posix()
        for number, line in enumerate(path.read_text(errors="replace").splitlines(), start=1):
            code = line.split("!")[0]
            if path in closure and FORBIDDEN_IN_LIBRARY.search(code):
                problems.append(f"src/{relative}:{number}: the embedding library (src/{LIBRARY_FOLDER}/ and the "
                                f"modules it uses) may not print, stop or open files: {code.strip()}")
            if relative.split("/")[0] != "app" and THREAD_COUNT.search(code):
                problems.append(f"src/{relative}:{number}: only the program (src/app/) sets the OpenMP thread count")
    return problems, len(closure)


def main() -> int:
    src = Path(sys.argv[1] if len(sys.argv) > 1 else "src")
    defined, uses = scan(src)
    problems = []
    allowed_seen = set()
    unknown_folders = sorted({folder for folder in defined.values() if folder not in LAYERS})
    for folder in unknown_folders:
        problems.append(f"src/{folder}/: folder has no layer in tools/check_layers.py")
    for relative, number, module in uses:
        if module not in defined:
            continue  # intrinsic or library module
        user_folder = relative.split("/")[0]
        used_folder = defined[module]
        if user_folder == used_folder or user_folder not in LAYERS or used_folder not in LAYERS:
            continue
        if LAYERS[used_folder] < LAYERS[user_folder]:
            continue
        kind = "a sibling" if LAYERS[used_folder] == LAYERS[user_folder] else "a higher layer"
        message = f"src/{relative}:{number}: uses {module} (src/{used_folder}/, {kind} of src/{user_folder}/)"
        if (relative, module) in ALLOWED_FOR_NOW:
            allowed_seen.add((relative, module))
            print(f"allowed for now: {message}")
        else:
            problems.append(message)
    for relative, module in sorted(ALLOWED_FOR_NOW - allowed_seen):
        problems.append(f"src/{relative}: allowed use of {module} no longer occurs: remove it from "
                        "ALLOWED_FOR_NOW in tools/check_layers.py")
    library, closure_size = library_problems(src)
    problems.extend(library)
    for problem in problems:
        print(problem)
    order = " <- ".join(
        "(" + " | ".join(sorted(f for f, l in LAYERS.items() if l == level)) + ")"
        if sum(1 for l in LAYERS.values() if l == level) > 1
        else next(f for f, l in LAYERS.items() if l == level)
        for level in sorted(set(LAYERS.values()))
    )
    print(f"layers: {order}")
    print(f"layers: {len(uses)} use statements checked, {len(allowed_seen)} allowed for now, "
          f"{closure_size} files of the embedding library checked for output, stops and thread counts, "
          f"{len(problems)} violations")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
