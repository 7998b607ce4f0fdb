"""Layers point one way: code outside src/contact/ changes a contact pair only through
its bindings (`set_friction`, `move_master`, `set_penalties`, `set_warm`,
`set_pattern_miss`, `refit_ranges`), never by assigning its components, so that a
method owns its state and the factory is the one place a pair is built."""
from __future__ import annotations

import re

from conftest import REPO

PAIR = REPO / "src" / "contact" / "pair.f90"
# the designator an assignment starts with: parts `name` or `name(...)` joined by `%`
ARGS = r"(?:\((?:[^()]|\([^()]*\))*\))"  # `(...)`, one level of parentheses inside
DESIGNATOR = re.compile(rf"\s*((?:\w+\s*{ARGS}?\s*%\s*)*\w+)\s*{ARGS}?\s*=(?![=>])")


def statement(code: str) -> str:
    """The statement of a line without a leading one-line `if (...)` (parentheses matched)."""
    m = re.match(r"\s*if\s*\(", code)
    if not m:
        return code
    depth, i = 1, m.end()
    while i < len(code) and depth:
        depth += {"(": 1, ")": -1}.get(code[i], 0)
        i += 1
    return code[i:]


def pair_components() -> set[str]:
    """The component names of `contact_pair_t` (between its `type` line and `contains`)."""
    text = PAIR.read_text()
    body = text[text.index(":: contact_pair_t\n"):]
    body = body[:body.index("\n    contains\n")]
    names: set[str] = set()
    for line in body.splitlines():
        code = line.split("!")[0]
        if "::" not in code:
            continue
        for part in re.split(r",(?![^(]*\))", code.split("::", 1)[1]):
            name = part.split("=")[0].split("(")[0].strip()
            if name:
                names.add(name)
    return names


def writes(text: str, components: set[str]) -> list[str]:
    """Statements of `text` that assign a component of a pair (`...pair%<component>...`)."""
    found = []
    for number, line in enumerate(text.splitlines(), 1):
        m = DESIGNATOR.match(statement(line.split("!")[0]))
        if not m:
            continue
        for name in re.findall(r"\bpair\s*%\s*(\w+)", m.group(1)):
            if name in components:
                found.append(f"{number}: {line.strip()}")
    return found


def test_the_component_list_is_read() -> None:
    names = pair_components()
    assert {"law", "master", "slave", "hist", "warm", "pattern_miss", "mlo", "eps_automatic"} <= names


def test_a_write_is_found() -> None:
    """The check finds what it looks for (a planted write and a planted one-line if)."""
    names = pair_components()
    text = ("        model%pairs(k)%pair%law%mu = 0.3_dp\n"
            "        if (fit) pair%warm = .false.\n"
            "        call pair%set_warm(.true.)\n"
            "        x = pair%law%eps_n\n"
            "        if (pair%law%mu == 0.0_dp) return\n"
            "        mark(model%pairs(ip)%pair%master%all_dofs()) = .true.\n"
            "        if (any([(p(i)%pair%warm, i=1, n)])) y = 1\n"
            "        pairs(ip)%pair%mlo(3) = lo\n")
    assert [w.split(":")[0] for w in writes(text, names)] == ["1", "2", "8"]


def test_no_pair_component_written_outside_contact() -> None:
    names = pair_components()
    offenders = {}
    for path in sorted([*(REPO / "src").rglob("*.f90"), *(REPO / "app").rglob("*.f90")]):
        if (REPO / "src" / "contact") in path.parents:
            continue
        found = writes(path.read_text(), names)
        if found:
            offenders[str(path.relative_to(REPO))] = found
    assert not offenders, offenders
