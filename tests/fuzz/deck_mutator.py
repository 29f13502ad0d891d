"""Mutations of LS-DYNA keyword decks for the fuzzer: structure, keywords, field values and
extreme physics, all drawn from one seeded random generator, so that a mutant is reproduced
exactly from (seed deck, seed number).

A deck is a dict {relative file name: text}; the first entry is the main deck. The mutator
knows just enough of the card layouts to hit fields (fixed 10-column cards, *NODE's 8/16
columns, 8-column element cards, 20-column curve points, long format, comma-separated cards);
it never needs the deck to stay valid.
"""
from __future__ import annotations

import random
import re

# ---------------------------------------------------------------------------------------------
# Card layout

KEYWORD_OPTIONS = ["_ID", "_TITLE", "_SET", "_NODE", "_FINITE", "_MOVING", "_FORCES", "_MOTION", "_THICKNESS",
                   "_GENERATE", "_LIST", "_EFG", "_NONUNIFORM", "_ORTHO", "_MPP", "_SEGMENT", "+", "-", "%",
                   " LONG=Y", "_RIGID", "_GENERATION", "_SURFACE_TO_SURFACE", "_SINGLE_SURFACE"]

# Keywords crashfree reads (README.md, docs/keywords.md), used to replace one keyword name by
# another while its cards stay.
KNOWN_KEYWORDS = [
    "KEYWORD", "TITLE", "INCLUDE", "PARAMETER", "COMMENT", "END", "NODE", "ELEMENT_SOLID", "ELEMENT_SHELL",
    "ELEMENT_SHELL_THICKNESS", "PART", "SECTION_SOLID", "SECTION_SOLID_EFG", "SECTION_SHELL", "MAT_ELASTIC",
    "MAT_PLASTIC_KINEMATIC", "MAT_PIECEWISE_LINEAR_PLASTICITY", "MAT_NULL", "MAT_HONEYCOMB",
    "MAT_MODIFIED_HONEYCOMB", "MAT_LOW_DENSITY_FOAM", "MAT_RIGID", "MAT_001", "MAT_003", "MAT_020", "MAT_024",
    "MAT_026", "MAT_057", "MAT_126", "HOURGLASS", "CONTROL_HOURGLASS", "CONTROL_BULK_VISCOSITY",
    "CONTROL_TERMINATION", "CONTROL_TIMESTEP", "CONTROL_ENERGY", "CONTROL_CONTACT", "CONTROL_IMPLICIT_GENERAL",
    "CONTROL_IMPLICIT_SOLUTION", "SET_NODE_LIST", "SET_NODE_LIST_GENERATE", "SET_PART_LIST", "SET_SEGMENT",
    "LOAD_SEGMENT", "LOAD_SEGMENT_SET", "LOAD_SEGMENT_NONUNIFORM", "BOUNDARY_SPC_NODE", "BOUNDARY_SPC_SET",
    "BOUNDARY_PRESCRIBED_MOTION_NODE", "BOUNDARY_PRESCRIBED_MOTION_SET", "BOUNDARY_PRESCRIBED_MOTION_RIGID",
    "INITIAL_VELOCITY", "INITIAL_VELOCITY_NODE", "INITIAL_VELOCITY_GENERATION", "LOAD_NODE_POINT", "LOAD_NODE_SET",
    "DEFINE_CURVE", "RIGIDWALL_PLANAR", "RIGIDWALL_PLANAR_FINITE", "RIGIDWALL_PLANAR_MOVING",
    "RIGIDWALL_PLANAR_MOVING_FORCES", "RIGIDWALL_GEOMETRIC_CYLINDER", "RIGIDWALL_GEOMETRIC_CYLINDER_MOTION",
    "CONSTRAINED_NODAL_RIGID_BODY", "ELEMENT_MASS", "CONTACT_AUTOMATIC_NODES_TO_SURFACE",
    "CONTACT_AUTOMATIC_SURFACE_TO_SURFACE", "CONTACT_AUTOMATIC_SINGLE_SURFACE", "DATABASE_BINARY_D3PLOT",
    "DATABASE_GLSTAT", "DATABASE_MATSUM", "DATABASE_NODOUT", "DATABASE_RWFORC", "DATABASE_RCFORC",
    "DATABASE_HISTORY_NODE", "DATABASE_HISTORY_NODE_SET", "DATABASE_BINARY_D3DUMP", "DATABASE_BINARY_RUNRSF",
]

# Keywords whose _ID / _TITLE option puts one card (id and heading, or a title) before card 1.
HEADED = ("RIGIDWALL", "CONTACT", "MAT_", "SECTION_", "LOAD_SEGMENT_NONUNIFORM", "DEFINE_CURVE", "SET_",
          "CONSTRAINED_NODAL_RIGID_BODY", "HOURGLASS")


def keyword_name(line: str) -> str:
    """Upper-case keyword name of a keyword line, without the format suffix and the rest of the line."""
    name = line[1:].split()[0] if len(line) > 1 and line[1:].split() else ""
    return name.upper().rstrip("+-%")


def is_keyword(line: str) -> bool:
    return line.startswith("*")


def is_comment(line: str) -> bool:
    return line.lstrip().startswith("$")


def field_widths(keyword: str, card: int, long_format: bool) -> list[int]:
    """Column widths of the fields of data card `card` (1-based, comments not counted)."""
    wide = 20 if long_format else None
    if keyword == "NODE":
        return [wide or 8] + [wide or 16] * 3 + [wide or 8] * 2
    if keyword == "ELEMENT_MASS":
        return [wide or 8, wide or 8, wide or 16, wide or 8]
    if keyword == "ELEMENT_SHELL_THICKNESS":
        return [wide or 8] * 10 if card % 2 == 1 else [wide or 16] * 5
    if keyword.startswith("ELEMENT_"):
        return [wide or 8] * 10
    if keyword.startswith("DEFINE_CURVE"):
        offset = 1 if "TITLE" in keyword else 0
        return [wide or 10] * 8 if card <= 1 + offset else [20, 20]
    if keyword.startswith("PARAMETER"):
        return [wide or 10] * 8
    return [wide or 10] * 8


def split_fields(line: str, widths: list[int]) -> list[tuple[int, int]]:
    """(start, end) columns of each fixed field of `line`, as far as the line and widths reach."""
    spans, start = [], 0
    for width in widths:
        spans.append((start, start + width))
        start += width
    return spans


def number(text: str):
    """Value of a number in Fortran's forms (1.0-3, 2D3 ...), or None."""
    text = text.strip()
    match = re.fullmatch(r"([+-]?(?:\d+\.?\d*|\.\d+))(?:[eEdD]([+-]?\d+)|([+-]\d+))?", text)
    if not match:
        return None
    exponent = match.group(2) or match.group(3)
    try:
        return float(match.group(1)) * 10.0 ** int(exponent) if exponent else float(match.group(1))
    except OverflowError:
        return float("inf")


# ---------------------------------------------------------------------------------------------
# Values

EXTREME = ["0", "-1", "1", "2", "-0", "0.0", "1e30", "-1e30", "1e300", "9e99", "-9e99", "9.99e99", "1e99",
           "1e100", "1e-300", "1e-30", "1e-320", "NaN", "nan", "Inf", "-Inf", "Infinity", "1.0D+99", "1.0-300",
           "1.0+99", "2147483647", "2147483648", "-2147483648", "-2147483649", "99999999", "12345678901234567890",
           "0.1234567890123456789012345678901234567890", "1" * 40, "1e", "e1", ".", "-", "+", "--1", "1..0", "0x1F",
           "abc", "&", "&undefined", "1 2", "1e+", "5.", "-.5e-3", "3.0", "1.5", "0.5", "-0.0", "1e-7", "7", "8",
           "41", "-7", "100000"]

# The extremes that read as numbers in range (|x| < 1e100): they reach the solver, not the reader.
NUMERIC = [text for text in EXTREME if number(text) is not None and abs(number(text)) < 1e100]

VELOCITIES = ["1e5", "-1e5", "1e8", "1e10", "1e15", "1e20", "1e30", "-1e30", "9e99", "1e99", "3e5"]
TINY = ["1e-300", "1e-100", "1e-30", "1e-20", "1e-12", "1e-99", "2.2e-308"]
HUGE = ["1e30", "1e50", "1e99", "9e99", "9.99999e99", "1e20", "1e15"]
POISSON = ["0.5", "0.4999999", "0.49999", "0.49", "0.499", "0.7", "0.9", "1.0", "-0.99", "-0.999999", "-1", "0.0"]

# Extreme physics: (keyword prefix, card (1-based, None: any card), field (0-based), values).
PHYSICS = [
    ("INITIAL_VELOCITY_NODE", None, 1, VELOCITIES), ("INITIAL_VELOCITY_NODE", None, 2, VELOCITIES),
    ("INITIAL_VELOCITY_NODE", None, 3, VELOCITIES),
    ("INITIAL_VELOCITY_GENERATION", 1, 2, VELOCITIES + ["1e4", "1e6"]),
    ("INITIAL_VELOCITY_GENERATION", 1, 3, VELOCITIES), ("INITIAL_VELOCITY_GENERATION", 2, 3, ["0", "1e-300", "1e30"]),
    ("INITIAL_VELOCITY", 2, 0, VELOCITIES), ("INITIAL_VELOCITY", 2, 1, VELOCITIES), ("INITIAL_VELOCITY", 2, 2, VELOCITIES),
    ("CONTROL_TIMESTEP", 1, 1, ["0", "1e-300", "1e-10", "0.01", "0.9", "0.99", "1.0", "1.2", "1.5", "2", "10",
                                "1e10", "1e30", "9e99", "-1", "-0.5"]),
    ("CONTROL_TIMESTEP", 1, 0, ["1e-300", "1e-30", "1e-10", "1", "1e10", "1e30", "9e99", "-1"]),
    ("CONTROL_TIMESTEP", 1, 4, ["-1e-30", "-1e-10", "-1", "-1e10", "-9e99", "1e-3", "1", "1e30", "-1e-300", "-0.1"]),
    ("CONTROL_TERMINATION", 1, 0, ["1e-300", "1e-30", "1e-10", "1e-6", "1e10", "1e30", "9e99", "-1", "0", "-1e-300",
                                   "1e-320"]),
    ("CONTROL_TERMINATION", 1, 1, ["0", "1", "2", "3", "2147483647", "-1", "1e30", "100000000"]),
    ("MAT_", 1, 1, TINY + HUGE + ["0", "-7.85e-6"]),
    ("MAT_", 1, 2, TINY + HUGE + ["0", "-210"]),
    ("MAT_", 1, 3, POISSON),
    ("MAT_", 1, 4, TINY + HUGE + ["0", "-1"]),
    ("MAT_", 1, 5, TINY + HUGE + ["0", "1", "-1"]),
    ("MAT_", 1, 6, TINY + HUGE + ["0", "1", "2"]),
    ("MAT_", 1, 7, TINY + HUGE + ["0", "1"]),
    ("MAT_", 2, 0, TINY + HUGE + ["0", "-1"]), ("MAT_", 2, 1, TINY + HUGE + ["0"]),
    ("MAT_", 3, None, TINY + HUGE + ["0", "-1"]),
    ("SECTION_SHELL", 2, 0, TINY + HUGE + ["0", "-1"]), ("SECTION_SHELL", 2, 1, TINY + HUGE + ["0"]),
    ("SECTION_SHELL", 1, 2, ["0", "1e-30", "1e30", "-1"]), ("SECTION_SHELL", 1, 3, ["1", "10", "0", "11", "-1"]),
    ("SECTION_SOLID", 2, 0, ["1.0000001", "1.0", "1e30", "9e99", "1e-30", "100"]),
    ("SECTION_SOLID", 1, 1, ["1", "2", "41", "42", "0", "-1", "16"]),
    ("ELEMENT_SHELL_THICKNESS", 2, 0, TINY + HUGE + ["0"]),
    ("HOURGLASS", 1, 1, [str(k) for k in range(-1, 12)]), ("HOURGLASS", 1, 2, ["0", "1e30", "1e-30", "9e99"]),
    ("HOURGLASS", 1, 4, ["0", "1e30", "1e-30"]), ("HOURGLASS", 1, 5, ["0", "1e30", "1e-30"]),
    ("CONTROL_HOURGLASS", 1, 0, [str(k) for k in range(-1, 12)]), ("CONTROL_HOURGLASS", 1, 1, ["1e30", "1e-30", "9e99"]),
    ("CONTROL_BULK_VISCOSITY", 1, 0, ["1e30", "1e-30", "9e99", "1e10"]),
    ("CONTROL_BULK_VISCOSITY", 1, 1, ["1e30", "1e-30", "9e99", "1e10"]),
    ("BOUNDARY_PRESCRIBED_MOTION", None, 4, HUGE + TINY + ["-1e30"]),
    ("BOUNDARY_PRESCRIBED_MOTION", None, 6, ["-1e30", "1e-300", "1e30", "-1"]),
    ("BOUNDARY_PRESCRIBED_MOTION", None, 7, ["-1e30", "1e30", "1e-300", "9e99"]),
    ("BOUNDARY_PRESCRIBED_MOTION", None, 2, ["0", "1", "2", "3", "4"]),
    ("LOAD_", None, 3, HUGE + ["-1e30"]), ("LOAD_SEGMENT", None, 1, HUGE + ["-1e30"]),
    ("LOAD_SEGMENT", None, 2, ["1e30", "-1e30", "1e-300"]),
    ("DEFINE_CURVE", None, 1, HUGE + TINY + ["-1e30", "NaN"]), ("DEFINE_CURVE", None, 0, HUGE + ["-1e30", "1e-300"]),
    ("DEFINE_CURVE", 1, 2, HUGE + TINY), ("DEFINE_CURVE", 1, 3, HUGE + TINY), ("DEFINE_CURVE", 1, 4, HUGE + ["-1e30"]),
    ("RIGIDWALL_PLANAR", None, 0, TINY + HUGE + ["0", "-1"]), ("RIGIDWALL_PLANAR", None, 1, VELOCITIES + ["0"]),
    ("RIGIDWALL_PLANAR", None, 6, ["1", "0.999", "1e30", "2"]),
    ("RIGIDWALL_GEOMETRIC_CYLINDER", None, 0, TINY + HUGE + ["0"]),
    ("RIGIDWALL_GEOMETRIC_CYLINDER", None, 2, VELOCITIES + ["0"]),
    ("RIGIDWALL", None, 4, ["1e30", "-1e30", "1e-300"]), ("RIGIDWALL", None, 5, ["1e30", "-1e30", "1e-300", "0"]),
    ("CONTACT_", 2, 0, ["1e30", "1", "-1", "2"]), ("CONTACT_", 2, 4, ["100", "1e30", "0"]),
    ("CONTACT_", 3, 0, ["1e30", "1e-30", "9e99"]), ("CONTACT_", 3, 1, ["1e30", "1e-30"]),
    ("CONTACT_", 4, 1, ["1e30", "1e-30", "9e99"]), ("CONTROL_CONTACT", 1, 0, ["1e30", "1e-30", "9e99"]),
    ("NODE", None, 1, ["1e30", "-1e30", "1e-30", "1e20", "9e99", "NaN"]),
    ("NODE", None, 2, ["1e30", "-1e30", "1e-30", "1e20", "9e99"]),
    ("NODE", None, 3, ["1e30", "-1e30", "1e-30", "1e20", "9e99"]),
    ("ELEMENT_MASS", None, 2, ["1e30", "1e-300", "9e99", "-1", "0"]),
    ("DATABASE_", 1, 0, ["1e-300", "1e-30", "1e-9", "9e99", "-1", "0"]),
]

# Snippets added to a deck: extreme physics and odd but valid-looking keywords. {node} is a
# node id of the deck, {value}, {velocity}, {tiny}, {huge} random extremes.
SNIPPETS = [
    "*CONTROL_TIMESTEP\n{zero:>10}{tssfac:>10}{zero:>10}{zero:>10}{dt2ms:>10}",
    "*INITIAL_VELOCITY\n         0\n{velocity:>10}{velocity:>10}{velocity:>10}",
    "*INITIAL_VELOCITY_NODE\n{node:>10}{velocity:>10}{velocity:>10}{velocity:>10}",
    "*INITIAL_VELOCITY_GENERATION\n         0         2{velocity:>10}       0.0       0.0       0.0\n"
    "       0.0       0.0       0.0       0.0       0.0       1.0",
    "*CONTROL_TERMINATION\n{endtim:>10}{endcyc:>10}",
    "*DATABASE_GLSTAT\n{dt:>10}", "*DATABASE_BINARY_D3PLOT\n{dt:>10}",
    "*DATABASE_NODOUT\n{dt:>10}\n*DATABASE_HISTORY_NODE\n{node:>10}",
    "*ELEMENT_MASS\n{eid:>8}{node:>8}{mass:>16}",
    "*DEFINE_CURVE\n      9901\n{zero:>20}{value:>20}\n{huge:>20}{value:>20}\n"
    "*LOAD_NODE_POINT\n{node:>10}{dof:>10}      9901{value:>10}",
    "*DEFINE_CURVE\n      9902\n{zero:>20}{value:>20}\n{tiny:>20}{value:>20}\n"
    "*BOUNDARY_PRESCRIBED_MOTION_NODE\n{node:>10}{dof:>10}{vad:>10}      9902{value:>10}",
    "*RIGIDWALL_PLANAR\n         0\n       0.0       0.0{coordinate:>10}       0.0       0.0{normal:>10}",
    "*RIGIDWALL_PLANAR_MOVING\n         0\n       0.0       0.0{coordinate:>10}       0.0       0.0{normal:>10}\n"
    "{mass:>10}{velocity:>10}",
    "*CONTROL_HOURGLASS\n{ihq:>10}{value:>10}",
    "*CONTROL_BULK_VISCOSITY\n{value:>10}{value:>10}",
    "*CONTROL_CONTACT\n{value:>10}",
    "*SET_NODE_LIST_GENERATE\n      9903\n{node:>10}{zero:>10}",
    "*DEFINE_CURVE\n      9904\n{huge:>20}{value:>20}\n{zero:>20}{value:>20}",
    "*PARAMETER\nR tend    {value:>10}",
    "*BOUNDARY_SPC_NODE\n{node:>10}         0         1         1         1         1         1         1",
    "*CONTACT_AUTOMATIC_SINGLE_SURFACE\n         0         0         5\n{value:>10}\n{value:>10}{value:>10}",
    "*HOURGLASS\n         1{ihq:>10}{value:>10}",
]


class DeckMutator:
    """Applies random mutations to a deck (dict of file texts) with its own random generator."""

    def __init__(self, rng: random.Random, numeric_only: bool = False):
        self.rng = rng
        self.numeric_only = numeric_only

    # --- helpers ------------------------------------------------------------------------------

    def choose(self, items):
        return items[self.rng.randrange(len(items))]

    def extreme_value(self, original: str = "") -> str:
        value = number(original)
        rng = self.rng
        if value is not None and rng.random() < 0.35:
            factor = self.choose([-1.0, 0.0, 10.0, 1e3, 1e10, 1e30, 1e99, 1e-3, 1e-10, 1e-30, 1e-300, 1.0000001])
            if original.strip().lstrip("+-").isdigit() and abs(value) < 1e9:
                # ids and codes: neighbours, zero, negatives, far out of range
                return str(int(self.choose([value + 1, value - 1, -value, 0, value + 1000, 99999999, 2 ** 31])))
            try:
                return repr(value * factor)
            except OverflowError:
                return "1e308"
        if self.numeric_only:
            return self.choose(NUMERIC)
        return self.choose(EXTREME)

    def fit(self, text: str, width: int) -> str:
        """Right-justify `text` in a field of `width` columns; longer text is kept whole (it then
        shifts the following columns, which is a mutation of its own)."""
        return text.rjust(width) if len(text) <= width else text

    def structure(self, lines: list[str]):
        """Per line: (keyword, card number within the keyword, long format) for data lines, or None."""
        context, keyword, card, long_everywhere, long_here = [], "", 0, False, False
        title_next = False
        for line in lines:
            if is_keyword(line):
                keyword = keyword_name(line)
                card = 0
                head = line.split()[0] if line.split() else ""
                long_here = head.endswith("+") or (long_everywhere and not head.endswith("-"))
                if keyword == "KEYWORD" and "LONG=Y" in line.upper():
                    long_everywhere = True
                title_next = keyword == "TITLE"
                context.append(None)
            elif is_comment(line) or title_next:
                title_next = False
                context.append(None)
            else:
                card += 1
                context.append((keyword, card, long_here))
        return context

    def fields_of(self, line: str, keyword: str, card: int, long_format: bool):
        """(start, end) spans of the fields of a data line, or None for a comma-separated line."""
        if "," in line:
            return None
        return split_fields(line, field_widths(keyword, card, long_format))

    def set_field(self, line: str, keyword: str, card: int, long_format: bool, index: int, text: str) -> str:
        spans = self.fields_of(line, keyword, card, long_format)
        if spans is None:
            parts = line.split(",")
            while len(parts) <= index:
                parts.append("")
            parts[index] = text
            return ",".join(parts)
        if index >= len(spans):
            index = len(spans) - 1
        start, end = spans[index]
        padded = line.ljust(end)
        if len(text) > end - start and self.rng.random() < 0.5:
            # too long for its columns: write the card in free format instead
            values = [padded[a:b].strip() for a, b in spans]
            values[index] = text
            while values and values[-1] == "":
                values.pop()
            return ",".join(values)
        return (padded[:start] + self.fit(text, end - start) + padded[end:]).rstrip()

    def get_field(self, line: str, keyword: str, card: int, long_format: bool, index: int) -> str:
        spans = self.fields_of(line, keyword, card, long_format)
        if spans is None:
            parts = line.split(",")
            return parts[index] if index < len(parts) else ""
        if index >= len(spans):
            return ""
        start, end = spans[index]
        return line[start:end]

    def ids(self, lines: list[str], keyword_prefix: str, width: int = 8) -> list[int]:
        """First-field ids of the data lines of keywords starting with keyword_prefix."""
        found, active = [], False
        for line in lines:
            if is_keyword(line):
                active = keyword_name(line).startswith(keyword_prefix)
                continue
            if active and not is_comment(line):
                text = line.split(",")[0] if "," in line else line[:width]
                if text.strip().isdigit():
                    found.append(int(text))
        return found

    # --- mutation families --------------------------------------------------------------------

    def mutate(self, deck: dict[str, str], count: int) -> list[str]:
        """Apply `count` mutations in place; return their descriptions."""
        done = []
        if self.numeric_only:
            families = [(self.mutate_physics, 60), (self.mutate_value, 25), (self.add_snippet, 15)]
        else:
            families = [(self.mutate_value, 34), (self.mutate_physics, 26), (self.mutate_lines, 14),
                        (self.mutate_blocks, 8), (self.mutate_columns, 7), (self.mutate_keyword, 7),
                        (self.add_snippet, 8), (self.mutate_file, 3)]
        total = sum(weight for _, weight in families)
        for _ in range(count):
            pick = self.rng.uniform(0, total)
            for family, weight in families:
                pick -= weight
                if pick <= 0:
                    break
            names = list(deck)
            name = names[0] if len(names) == 1 or self.rng.random() < 0.8 else self.choose(names[1:])
            lines = deck[name].split("\n")
            description = family(lines, deck, name)
            if description:
                deck[name] = "\n".join(lines)
                done.append(f"{name}: {description}")
        return done

    def data_lines(self, lines, context, predicate=lambda c: True):
        return [k for k, c in enumerate(context) if c is not None and predicate(c)]

    def mutate_value(self, lines, deck, name):
        context = self.structure(lines)
        candidates = self.data_lines(lines, context)
        if not candidates:
            return None
        k = self.choose(candidates)
        keyword, card, long_format = context[k]
        spans = self.fields_of(lines[k], keyword, card, long_format)
        used = len(lines[k].split(",")) if spans is None else max(1, sum(1 for a, _ in spans if a < len(lines[k])))
        index = self.rng.randrange(min(used + 1, 10))
        old = self.get_field(lines[k], keyword, card, long_format, index)
        if self.rng.random() < 0.12:
            new = ""                      # a blank field takes the default
        else:
            new = self.extreme_value(old)
        lines[k] = self.set_field(lines[k], keyword, card, long_format, index, new)
        return f"line {k + 1} (*{keyword} card {card}) field {index + 1}: {old.strip()!r} -> {new!r}"

    def mutate_physics(self, lines, deck, name):
        context = self.structure(lines)
        options = []
        for k, c in enumerate(context):
            if c is None:
                continue
            keyword, card, _ = c
            headed = any(keyword.startswith(h) for h in HEADED) and ("_ID" in keyword or "_TITLE" in keyword)
            for prefix, wanted_card, field, values in PHYSICS:
                if not keyword.startswith(prefix):
                    continue
                if prefix == "NODE" and keyword != "NODE":
                    continue
                if prefix == "INITIAL_VELOCITY" and keyword != "INITIAL_VELOCITY":
                    continue
                effective = card - 1 if headed else card
                if wanted_card is not None and effective != wanted_card:
                    continue
                options.append((k, field, values))
        if not options:
            return self.add_snippet(lines, deck, name)
        k, field, values = self.choose(options)
        keyword, card, long_format = context[k]
        if field is None:
            field = self.rng.randrange(8)
        old = self.get_field(lines[k], keyword, card, long_format, field)
        new = self.choose(values)
        lines[k] = self.set_field(lines[k], keyword, card, long_format, field, new)
        return f"physics: line {k + 1} (*{keyword} card {card}) field {field + 1}: {old.strip()!r} -> {new!r}"

    def mutate_lines(self, lines, deck, name):
        if not lines:
            return None
        rng = self.rng
        k = rng.randrange(len(lines))
        action = self.choose(["drop", "duplicate", "swap", "move", "blank", "comment", "truncate", "repeat",
                              "cut_line", "long_line"])
        if action == "drop":
            del lines[k]
        elif action == "duplicate":
            lines.insert(k, lines[k])
        elif action == "swap" and len(lines) > 1:
            j = min(k + 1, len(lines) - 1) if rng.random() < 0.6 else rng.randrange(len(lines))
            lines[k], lines[j] = lines[j], lines[k]
            return f"swap lines {k + 1} and {j + 1}"
        elif action == "move":
            line = lines.pop(k)
            j = rng.randrange(len(lines) + 1)
            lines.insert(j, line)
            return f"move line {k + 1} to {j + 1}"
        elif action == "blank":
            lines[k] = ""
        elif action == "comment":
            lines[k] = "$" + lines[k]
        elif action == "truncate":
            del lines[k:]
            if lines and rng.random() < 0.5:
                lines[-1] = lines[-1][:rng.randrange(len(lines[-1]) + 1)]
            return f"truncate the file at line {k + 1}"
        elif action == "repeat":
            lines[k:k + 1] = [lines[k]] * rng.choice([3, 20, 200])
        elif action == "cut_line":
            lines[k] = lines[k][:rng.randrange(len(lines[k]) + 1)]
        elif action == "long_line":
            lines[k] = lines[k] + self.choose(["9" * 300, " " * 5000 + "1", "1e30," * 50, "x" * 100000])
        return f"{action} line {k + 1}"

    def blocks(self, lines):
        """(start, end) line ranges of the keyword blocks, the lines before the first keyword excluded."""
        starts = [k for k, line in enumerate(lines) if is_keyword(line)]
        return [(s, e) for s, e in zip(starts, starts[1:] + [len(lines)])]

    def mutate_blocks(self, lines, deck, name):
        blocks = self.blocks(lines)
        if not blocks:
            return None
        rng = self.rng
        s, e = self.choose(blocks)
        title = lines[s].strip()
        action = self.choose(["drop", "duplicate", "swap", "move", "cards_only", "drop_cards"])
        chunk = lines[s:e]
        if action == "drop":
            del lines[s:e]
        elif action == "duplicate":
            lines[e:e] = chunk
        elif action == "swap" and len(blocks) > 1:
            s2, e2 = self.choose(blocks)
            if s2 == s:
                return None
            first, second = sorted([(s, e), (s2, e2)])
            a, b = lines[first[0]:first[1]], lines[second[0]:second[1]]
            lines[first[0]:second[1]] = b + lines[first[1]:second[0]] + a
            return f"swap blocks {title} and {lines[first[0]].strip()}"
        elif action == "move":
            del lines[s:e]
            starts = [k for k, line in enumerate(lines) if is_keyword(line)] + [len(lines)]
            j = self.choose(starts)
            lines[j:j] = chunk
        elif action == "cards_only":
            # the keyword line goes: its cards join the keyword before
            del lines[s]
        elif action == "drop_cards":
            del lines[s + 1:e]
        return f"{action} block {title} (line {s + 1})"

    def mutate_columns(self, lines, deck, name):
        context = self.structure(lines)
        candidates = self.data_lines(lines, context)
        if not candidates:
            return None
        rng = self.rng
        k = self.choose(candidates)
        keyword, card, long_format = context[k]
        line = lines[k]
        action = self.choose(["shift_right", "shift_left", "insert_inside", "to_free", "to_fixed", "tab",
                              "wide_fields", "narrow_fields"])
        if action == "shift_right":
            lines[k] = " " * rng.choice([1, 2, 5, 10]) + line
        elif action == "shift_left":
            lines[k] = line[rng.choice([1, 2, 5]):]
        elif action == "insert_inside" and line:
            j = rng.randrange(len(line))
            lines[k] = line[:j] + " " * rng.choice([1, 3]) + line[j:]
        elif action == "to_free":
            spans = self.fields_of(line, keyword, card, long_format)
            if spans is None:
                return None
            values = [line[a:b].strip() for a, b in spans if a < len(line)]
            lines[k] = ",".join(values)
        elif action == "to_fixed":
            if "," not in line:
                return None
            widths = field_widths(keyword, card, long_format)
            lines[k] = "".join(v.strip().rjust(w) for v, w in zip(line.split(","), widths + [10] * 20))
        elif action == "tab":
            j = rng.randrange(len(line) + 1)
            lines[k] = line[:j] + "\t" + line[j:]
        elif action in ("wide_fields", "narrow_fields"):
            spans = self.fields_of(line, keyword, card, long_format)
            if spans is None:
                return None
            values = [line[a:b].strip() for a, b in spans if a < len(line)]
            width = 20 if action == "wide_fields" else 8
            lines[k] = "".join(v.rjust(width) for v in values)
        return f"{action} line {k + 1} (*{keyword})"

    def mutate_keyword(self, lines, deck, name):
        keyword_lines = [k for k, line in enumerate(lines) if is_keyword(line)]
        if not keyword_lines:
            return None
        rng = self.rng
        k = self.choose(keyword_lines)
        old = lines[k]
        head = old[1:].split()[0] if old[1:].split() else ""
        action = self.choose(["typo", "lower", "add_option", "drop_option", "replace", "indent", "long",
                              "truncate_name", "rest_of_line"])
        if action == "typo" and head:
            j = rng.randrange(len(head))
            letter = self.choose("ABCDEFGHIJKLMNOPQRSTUVWXYZ_0123456789*")
            kind = self.choose(["insert", "delete", "replace", "transpose"])
            if kind == "insert":
                head = head[:j] + letter + head[j:]
            elif kind == "delete":
                head = head[:j] + head[j + 1:]
            elif kind == "replace":
                head = head[:j] + letter + head[j + 1:]
            elif j + 1 < len(head):
                head = head[:j] + head[j + 1] + head[j] + head[j + 2:]
            lines[k] = "*" + head
        elif action == "lower":
            lines[k] = old.lower()
        elif action == "add_option":
            lines[k] = "*" + head + self.choose(KEYWORD_OPTIONS)
        elif action == "drop_option" and "_" in head:
            lines[k] = "*" + head.rsplit("_", 1)[0]
        elif action == "replace":
            lines[k] = "*" + self.choose(KNOWN_KEYWORDS)
        elif action == "indent":
            lines[k] = " " + old
        elif action == "long":
            if rng.random() < 0.5:
                lines[k] = "*" + head + self.choose(["+", "-", "%"])
            else:
                first = next((j for j, line in enumerate(lines) if keyword_name(line) == "KEYWORD"), None)
                if first is None:
                    lines.insert(0, "*KEYWORD LONG=Y")
                else:
                    lines[first] = "*KEYWORD " + self.choose(["LONG=Y", "I10=Y", "LONG=S", "LONG=X", "100m", "MEMORY=1e30"])
        elif action == "truncate_name":
            lines[k] = "*" + head[:rng.randrange(len(head) + 1)]
        elif action == "rest_of_line":
            lines[k] = "*" + head + self.choose([" ", " x", " 1e30", "\t", ",", " $ comment"])
        if lines[k] == old:
            return None
        return f"keyword line {k + 1}: {old!r} -> {lines[k]!r}"

    def add_snippet(self, lines, deck, name):
        rng = self.rng
        nodes = self.ids(lines, "NODE") or [1]
        elements = self.ids(lines, "ELEMENT") or [1]
        values = {
            "zero": "0.0", "node": str(self.choose(nodes + [max(nodes) + 1, 0, -1])),
            "eid": str(max(elements) + rng.choice([1, 1000])),
            "velocity": self.choose(VELOCITIES), "tssfac": self.choose(["0.9", "1.0", "1.5", "10", "9e99", "1e-300", "0"]),
            "dt2ms": self.choose(["0.0", "-1e-30", "-1", "-9e99", "1e-3"]),
            "endtim": self.choose(["1e-300", "1e30", "9e99", "-1", "0.0", "1e-10"]),
            "endcyc": self.choose(["0", "1", "2147483647", "-5"]),
            "dt": self.choose(["1e-300", "1e-30", "1e-9", "9e99", "0.0", "-1"]),
            "mass": self.choose(["1e30", "1e-300", "9e99", "0.0", "-1.0"]),
            "value": self.extreme_value(), "huge": self.choose(HUGE), "tiny": self.choose(TINY),
            "dof": str(rng.choice([1, 2, 3, 4, 5, 7, 8, -1, 0])), "vad": str(rng.choice([0, 1, 2, 3, 4])),
            "coordinate": self.choose(["0.0", "1e30", "-1e30", "5.0", "2.5"]),
            "normal": self.choose(["1.0", "0.0", "-1.0", "1e-300", "1e30"]),
            "ihq": str(rng.choice(range(-1, 12))),
        }
        snippet = self.choose(SNIPPETS).format(**values)
        starts = [k for k, line in enumerate(lines) if is_keyword(line) and keyword_name(line) != "KEYWORD"]
        position = self.choose(starts) if starts and rng.random() < 0.7 else len(lines)
        end = next((k for k, line in enumerate(lines) if keyword_name(line) == "END"), None)
        if position == len(lines) and end is not None:
            position = end
        lines[position:position] = snippet.split("\n")
        return f"add at line {position + 1}: " + " / ".join(line.strip() for line in snippet.splitlines())

    def mutate_file(self, lines, deck, name):
        rng = self.rng
        action = self.choose(["crlf", "include_self", "include_missing", "include_directory", "include_twice",
                              "bytes", "empty", "data_first", "end_early", "no_end", "parameter_undefined",
                              "parameter_duplicate", "parameter_type"])
        if action == "crlf":
            lines[:] = [line + "\r" for line in lines]
        elif action == "include_self":
            lines.insert(len(lines) - 1 if lines else 0, f"*INCLUDE\n{name.rsplit('/', 1)[-1]}")
        elif action == "include_missing":
            lines.insert(rng.randrange(len(lines) + 1), "*INCLUDE\nno_such_file.k")
        elif action == "include_directory":
            lines.insert(rng.randrange(len(lines) + 1), self.choose(["*INCLUDE\n.", "*INCLUDE\n", "*INCLUDE\n/",
                                                                    "*INCLUDE\n&undefined", "*INCLUDE\n" + "x" * 300]))
        elif action == "include_twice":
            includes = [k for k, line in enumerate(lines) if keyword_name(line) == "INCLUDE"]
            if not includes:
                return None
            k = self.choose(includes)
            lines[k:k] = lines[k:k + 2]
        elif action == "bytes" and lines:
            k = rng.randrange(len(lines))
            j = rng.randrange(len(lines[k]) + 1)
            lines[k] = lines[k][:j] + self.choose(["\x00", "\xe9", "\ufffd", "\x1b", "\x7f", "\u00a0"]) + lines[k][j:]
        elif action == "empty":
            lines[:] = [""] if rng.random() < 0.5 else ["*KEYWORD", "*END"]
        elif action == "data_first":
            lines.insert(0, "         1         2")
        elif action == "end_early":
            lines.insert(rng.randrange(len(lines) + 1), "*END")
        elif action == "no_end":
            lines[:] = [line for line in lines if keyword_name(line) != "END"]
        elif action.startswith("parameter"):
            context = self.structure(lines)
            candidates = self.data_lines(lines, context)
            if not candidates:
                return None
            if action == "parameter_undefined":
                k = self.choose(candidates)
                keyword, card, long_format = context[k]
                lines[k] = self.set_field(lines[k], keyword, card, long_format, rng.randrange(4),
                                          self.choose(["&nothere", "-&nothere", "&", "&tend", "&" + "a" * 40]))
            elif action == "parameter_duplicate":
                lines.insert(1 if lines else 0, "*PARAMETER\nR tend    " + self.extreme_value().rjust(10) +
                             "I one     " + self.choose(["0", "-1", "2147483647", "1.5"]).rjust(10))
            else:
                parameters = [k + 1 for k, line in enumerate(lines) if keyword_name(line) == "PARAMETER"]
                if not parameters or parameters[0] >= len(lines):
                    return None
                k = parameters[0]
                lines[k] = self.choose(["X", "C", "I", "R", " ", "&"]) + lines[k][1:]
        else:
            return None
        return action


def mutate_deck(deck: dict[str, str], rng: random.Random) -> list[str]:
    """1 to 6 mutations (geometric: half the mutants get one). 45% of the mutants get physics
    only (values that read as numbers, in the fields that drive the solution, and added
    keywords), so that they pass the reader and reach the time loop."""
    physics_only = rng.random() < 0.45
    count = 1
    while count < 6 and rng.random() < 0.5:
        count += 1
    done = DeckMutator(rng, numeric_only=physics_only).mutate(deck, count)
    return (["(physics only)"] if physics_only else []) + done
