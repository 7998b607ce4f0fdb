"""Every value of a geometry spec (``pre/spec.py``) checked before anything is built:
types, finiteness and ranges, each refusal one line naming the table, the body or
curve and the key (:class:`SpecCheckError`; ``python -m pre geometry`` exits with 2).
A spec that passes builds or is refused by the geometry's own checks (a polygon that
does not close, a sector of radii in the wrong order), never by a Python error.
"""
from __future__ import annotations

import math
from typing import Any

MAX_ELEMENTS = 100000
"""Most elements along a direction of a body (the case file's limit, docs/formats.md)."""


class SpecCheckError(ValueError):
    """A spec value of the wrong type, not finite or out of range."""


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def non_finite(value: Any, where: str) -> None:
    """No NaN or infinity anywhere in ``value`` (TOML writes them ``nan``, ``inf``)."""
    if isinstance(value, float) and not math.isfinite(value):
        raise SpecCheckError(f"{where}: {value!r} is not a finite number")
    if isinstance(value, dict):
        for key, item in value.items():
            non_finite(item, f"{where}.{key}" if where else str(key))
    elif isinstance(value, list):
        for k, item in enumerate(value):
            non_finite(item, f"{where}[{k}]")


def number(value: Any, where: str, low: float | None = None, high: float | None = None,
           open_low: bool = True) -> float:
    """A number (not a boolean) in (``low``, ``high``] (``[low`` when not ``open_low``)."""
    if not _is_number(value):
        raise SpecCheckError(f"{where} must be a number, not {value!r}")
    if low is not None and (value < low or (open_low and value == low)):
        raise SpecCheckError(f"{where} must be {'>' if open_low else '>='} {low:g}, not {value!r}")
    if high is not None and value > high:
        raise SpecCheckError(f"{where} must be at most {high:g}, not {value!r}")
    return float(value)


def integer(value: Any, where: str, low: int, high: int) -> int:
    """An integer (not a boolean) in [``low``, ``high``]."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise SpecCheckError(f"{where} must be an integer, not {value!r}")
    if not low <= value <= high:
        raise SpecCheckError(f"{where} must be {low} to {high}, not {value}")
    return value


def text(value: Any, where: str) -> str:
    """A non-empty string."""
    if not isinstance(value, str) or not value.strip():
        raise SpecCheckError(f"{where} must be a non-empty string, not {value!r}")
    return value


def numbers(value: Any, where: str, count: int | None = None) -> list[float]:
    """A list of numbers (of ``count`` of them when given)."""
    if not isinstance(value, list) or not all(_is_number(v) for v in value):
        raise SpecCheckError(f"{where} must be a list of numbers, not {value!r}")
    if count is not None and len(value) != count:
        raise SpecCheckError(f"{where} must have {count} numbers, not {len(value)}")
    return [float(v) for v in value]


def points(value: Any, where: str) -> None:
    """A list of [x, y] points."""
    if not isinstance(value, list) or not value:
        raise SpecCheckError(f"{where} must be a list of [x, y] points, not {value!r}")
    for k, p in enumerate(value):
        numbers(p, f"{where}[{k}]", 2)


def arcs(value: Any, where: str) -> None:
    """A list of tables ``{segment = k, radius = r}``."""
    if not isinstance(value, list) or not all(isinstance(a, dict) for a in value):
        raise SpecCheckError(f"{where} must be a list of tables {{ segment = k, radius = r }}")
    for k, a in enumerate(value):
        unknown = set(a) - {"segment", "radius"}
        if unknown:
            raise SpecCheckError(f"{where}[{k}]: unknown key(s) {sorted(unknown)}")
        integer(a.get("segment"), f"{where}[{k}].segment", 0, 10**6)
        if number(a.get("radius"), f"{where}[{k}].radius") == 0:
            raise SpecCheckError(f"{where}[{k}].radius must not be 0 (> 0 bulges outward, < 0 inward)")


def names(value: Any, where: str) -> None:
    """A table of side -> edge name, or a list of edge names (strings)."""
    items = value.values() if isinstance(value, dict) else value if isinstance(value, list) else None
    if items is None or not all(isinstance(v, str) and v for v in items):
        raise SpecCheckError(f"{where} must be a table of side = \"name\" or a list of names (strings)")


#: How each key of a [[body]] / [[curve]] / [defaults] table is checked.
KEY_CHECKS: dict[str, Any] = {
    "name": text, "shape": text, "side": text,
    "contact_edge": lambda v, w: None if v == "" else text(v, w),
    "layout": text, "material": text, "file": text,
    "youngs_modulus": lambda v, w: number(v, w, 0.0),
    "poisson_ratio": lambda v, w: number(v, w, -1.0) < 0.5 or _fail(f"{w} must be < 0.5, not {v!r}"),
    "element_size": lambda v, w: number(v, w, 0.0),
    "elements": lambda v, w: integer(v, w, 1, MAX_ELEMENTS),
    "nel": lambda v, w: [integer(n, f"{w}[{k}]", 1, MAX_ELEMENTS) for k, n in enumerate(v)]
    if isinstance(v, list) and len(v) == 2 else _fail(f"{w} must be two integers [n_xi, n_eta], not {v!r}"),
    "x": lambda v, w: numbers(v, w, 2), "y": lambda v, w: numbers(v, w, 2),
    "centre": lambda v, w: numbers(v, w, 2), "angles": lambda v, w: numbers(v, w, 2),
    "r_in": lambda v, w: number(v, w, 0.0), "r_out": lambda v, w: number(v, w, 0.0),
    "radius": lambda v, w: number(v, w, 0.0), "thickness": lambda v, w: number(v, w, 0.0),
    "points": points, "corners": lambda v, w: [integer(c, f"{w}[{k}]", 0, 10**6) for k, c in enumerate(v)]
    if isinstance(v, list) else _fail(f"{w} must be a list of point indices, not {v!r}"),
    "arcs": arcs, "edges": names, "index": lambda v, w: integer(v, w, 0, 10**6),
}


def namelist_value(value: Any, where: str) -> None:
    """A value the case file's namelist can hold: a string, a boolean, a number or a
    (non-nested) list of them (voiga checks its meaning)."""
    for item in value if isinstance(value, list) else [value]:
        if not isinstance(item, (str, bool, int, float)):
            raise SpecCheckError(f"{where}: {item!r} is not a namelist value (strings, numbers, "
                                 "true/false, or a list of them)")


def _fail(message: str) -> None:
    raise SpecCheckError(message)


def check_table(table: Any, what: str) -> None:
    """The keys of one [[body]], [[curve]] or [defaults] table that KEY_CHECKS knows
    (unknown keys are the builders' to name)."""
    if not isinstance(table, dict):
        raise SpecCheckError(f"{what} must be a table, not {table!r}")
    label = f"{what} {table['name']!r}" if isinstance(table.get("name"), str) else what
    for key, value in table.items():
        if key in KEY_CHECKS:
            KEY_CHECKS[key](value, f"{label}: {key}")


def check_spec(data: dict[str, Any]) -> None:
    """Every value of a parsed spec: finite numbers only, strings where names are,
    tables and arrays of tables where the spec has them, namelist values in the case
    groups, each key of the defaults of its type and range (each body's and curve's
    keys: :func:`check_table`, once the builder knows them)."""
    non_finite(data, "")
    for key in ("units", "scene"):
        if key in data:
            text(data[key], key)
    for key in ("defaults", "case", "solver"):
        if key in data and not isinstance(data[key], dict):
            raise SpecCheckError(f"[{key}] must be a table, not {data[key]!r}")
    for key in ("body", "curve", "dirichlet", "pressure", "contact"):
        if key in data and not (isinstance(data[key], list) and all(isinstance(t, dict) for t in data[key])):
            raise SpecCheckError(f"{key} must be an array of tables ([[{key}]])")
    for key in ("case", "solver", "dirichlet", "pressure", "contact"):
        tables = data.get(key, [])
        for table in tables if isinstance(tables, list) else [tables]:
            for name, value in table.items():
                namelist_value(value, f"[{key}] {name}")
    check_table(data.get("defaults", {}), "[defaults]")
