"""Size limits of the Fortran sources (issue 37): no file in src/ or app/ over 600 lines,
no procedure over 120 lines (a host counts with its internal procedures)."""
from __future__ import annotations

import re
from pathlib import Path

from conftest import REPO

FILE_LINES = 600
PROCEDURE_LINES = 120
SOURCES = sorted(p for d in ("src", "app") for p in (REPO / d).rglob("*")
                 if p.suffix in {".f90", ".c", ".h"})

_PREFIX = r"(?:pure|elemental|impure|recursive|non_recursive|module" \
          r"|(?:integer|real|logical|character|complex)(?:\s*\([^)]*\))?|(?:type|class)\s*\(\w+\))"
# a procedure's first line: its prefixes and type, then subroutine/function and its name;
# in a submodule, `module procedure name` (ended by `end procedure`)
START = re.compile(rf"^\s*(?:{_PREFIX}\s+)*(?:subroutine|function)\s+(\w+)"
                   r"|^\s*module\s+procedure\s+(\w+)\s*$", re.I)
END = re.compile(r"^\s*end\s*(?:subroutine|function|procedure)\b", re.I)


def procedure_lengths(path: Path) -> list[tuple[str, int, int]]:
    """(name, first line, lines) of every procedure of a Fortran file, interface bodies
    and internal procedures included."""
    found, open_ = [], []
    submodule = re.search(r"^\s*submodule\b", path.read_text(), re.I | re.M) is not None
    for number, line in enumerate(path.read_text().splitlines(), start=1):
        code = line.split("!")[0]
        if END.match(code):
            name, first = open_.pop()
            found.append((name, first, number - first + 1))
        elif match := START.match(code):
            if match.group(2) and not submodule:
                continue  # `module procedure` in a generic interface's list
            open_.append((match.group(1) or match.group(2), number))
    assert not open_, f"{path}: no end for {open_}"
    return found


def test_no_source_file_over_600_lines() -> None:
    long = {str(p.relative_to(REPO)): n for p in SOURCES
            if (n := len(p.read_text().splitlines())) > FILE_LINES}
    assert not long, long


def test_no_procedure_over_120_lines() -> None:
    counted = 0
    long = []
    for path in SOURCES:
        if path.suffix != ".f90":
            continue
        for name, first, lines in procedure_lengths(path):
            counted += 1
            if lines > PROCEDURE_LINES:
                long.append(f"{path.relative_to(REPO)}:{first} {name} {lines}")
    assert counted > 500, counted  # the parser found the procedures
    assert not long, long
