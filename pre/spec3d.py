"""A geometry spec of 3D bodies (TOML) -> a geometry file of volumes
(``python -m pre geometry3d SPEC.toml``; reference in ``docs/pre.md``).

The 2D spec (:mod:`pre.spec`) holds a whole case, and its body tables carry the
case file's 2D ``&body`` settings (``nel = [n_xi, n_eta]``, a contact edge, the layout
of a contact curve); voiga's case file has no 3D bodies yet. So volumes have their own,
geometry-only spec: ``units``, ``scene`` and ``[[body]]`` tables with ``name``,
``shape`` (:data:`SHAPES`), the shape's keys and ``faces`` (renames, ``{label = "new
name"}``; for ``g2`` the names of all six faces by key). ``extrude`` and ``revolve``
take a ``section``: a 2D body table of the 2D spec (``shape = "rectangle"``, ... with
its ``edges``), built by :func:`pre.spec.build_patch`. From ``name.toml`` it writes
``name-geometry.h5`` (into ``--out`` or the spec's folder); a file there that differs
is replaced only with ``force``.
"""

from __future__ import annotations

import os
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .files import check_output
from .solids import (
    box,
    cylinder_sector,
    extrude,
    read_g2_volumes,
    revolve,
    shell_octant,
    solid,
    write_volumes,
)
from .spec import SpecError, build_patch, need, pick
from .spec_check import SpecCheckError, integer, non_finite, number, numbers, text
from .volume import Volume, check_volume

SHAPES: dict[str, set[str]] = {
    "box": {"x", "y", "z"},
    "cylinder_sector": {"r_in", "r_out", "angles", "z", "centre"},
    "shell_octant": {"r_in", "r_out", "centre"},
    "extrude": {"section", "z", "ends"},
    "revolve": {"section", "angle", "axis_point", "axis_direction", "ends"},
    "g2": {"file", "index"},
}
"""The shapes of a ``[[body]]`` table and their keys (besides ``name``, ``shape``, ``faces``)."""

BODY_KEYS = {"name", "shape", "faces"}

CHECKS: dict[str, Any] = {
    "x": lambda v, w: numbers(v, w, 2), "y": lambda v, w: numbers(v, w, 2),
    "z": lambda v, w: numbers(v, w, 2), "angles": lambda v, w: numbers(v, w, 2),
    "r_in": lambda v, w: number(v, w, 0.0), "r_out": lambda v, w: number(v, w, 0.0),
    "angle": lambda v, w: number(v, w, 0.0, 90.0),
    "axis_point": lambda v, w: numbers(v, w, 2), "axis_direction": lambda v, w: numbers(v, w, 2),
    "file": text, "index": lambda v, w: integer(v, w, 0, 10**6),
}
"""How each shape key is checked before anything is built (``centre``, ``ends``,
``faces`` and ``section`` by :func:`_check`)."""


def _strings(value: Any, where: str, count: int | None = None) -> None:
    items = value.values() if isinstance(value, dict) else value if isinstance(value, list) else None
    if items is None or not all(isinstance(v, str) and v for v in items) \
            or (count is not None and len(value) != count):
        n = f"{count} " if count else ""
        raise SpecCheckError(f"{where} must be {'a list' if count else 'a table'} of {n}names (strings), "
                             f"not {value!r}")


def _check(b: dict[str, Any], label: str) -> None:
    shape = b["shape"]
    for key, value in b.items():
        where = f"{label}: {key}"
        if key in CHECKS:
            CHECKS[key](value, where)
        elif key == "centre":
            numbers(value, where, 3 if shape == "shell_octant" else 2)
        elif key == "ends":
            _strings(value, where, 2)
        elif key == "faces":
            _strings(value, where)
            if not isinstance(value, dict):
                raise SpecCheckError(f"{where} must be a table of face = \"name\"")
        elif key == "section" and not isinstance(value, dict):
            raise SpecCheckError(f"{where} must be a table (a 2D body: shape = \"rectangle\", ...)")


def build_volume(b: dict[str, Any], folder: Path) -> Volume:
    """The volume of one ``[[body]]`` table (``folder``: where relative files are)."""
    name, shape = need(b, "name"), need(b, "shape")
    if not isinstance(name, str) or not name or not isinstance(shape, str):
        raise SpecError(f"body {name!r}: name and shape must be strings")
    if shape not in SHAPES:
        raise SpecError(f"body {name!r}: unknown shape {shape!r} (known: {sorted(SHAPES)})")
    unknown = set(b) - BODY_KEYS - SHAPES[shape]
    if unknown:
        raise SpecError(f"body {name!r}: unknown key(s) {sorted(unknown)} for shape {shape!r} "
                        f"(known: {sorted(BODY_KEYS | SHAPES[shape])})")
    try:
        _check(b, f"body {name!r}")
    except SpecCheckError as err:
        raise SpecError(str(err)) from None
    faces = b.get("faces")
    try:
        if shape == "box":
            return box(need(b, "x"), need(b, "y"), need(b, "z"), faces)
        if shape == "cylinder_sector":
            return cylinder_sector(need(b, "r_in"), need(b, "r_out"), b.get("angles", [0.0, 90.0]),
                                   need(b, "z"), b.get("centre", [0.0, 0.0]), faces)
        if shape == "shell_octant":
            return shell_octant(need(b, "r_in"), need(b, "r_out"), b.get("centre", [0.0, 0.0, 0.0]),
                                faces)
        if shape in ("extrude", "revolve"):
            section = build_patch({"name": f"{name} section", **need(b, "section")}, folder)
            if shape == "extrude":
                vol = extrude(section, need(b, "z"), b.get("ends", ["back", "front"]))
            else:
                vol = revolve(section, need(b, "angle"), b.get("axis_point", [0.0, 0.0]),
                              b.get("axis_direction", [0.0, 1.0]), b.get("ends", ["plane", "turned"]))
            return vol.renamed(faces)
        return solid(pick(read_g2_volumes(folder / need(b, "file")), b, "volume"), dict(faces or {}))
    except (ValueError, KeyError, TypeError) as err:
        if isinstance(err, SpecError):
            raise
        raise SpecError(f"body {name!r}: {err}") from None


def read_spec3d(path: str | Path) -> dict[str, Any]:
    """Parse a 3D spec (tomllib); SpecError names the problem."""
    path = Path(path)
    if not path.is_file():
        raise SpecError(f"no spec file {path}")
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as err:
        raise SpecError(f"{path}: not valid TOML ({err})") from None
    unknown = set(data) - {"units", "scene", "body"}
    if unknown:
        raise SpecError(f"{path}: unknown key(s) or table(s) {sorted(unknown)} (known: units, scene, "
                        "[[body]]; a 3D spec writes the geometry file only)")
    body = data.get("body")
    if not body or not isinstance(body, list) or not all(isinstance(t, dict) for t in body):
        raise SpecError(f"{path}: no [[body]] tables")
    try:
        non_finite(data, "")
        for key in ("units", "scene"):
            if key in data:
                text(data[key], key)
    except SpecCheckError as err:
        raise SpecError(f"{path}: {err}") from None
    return data


@dataclass
class Outcome3d:
    """What :func:`write_from_spec3d` did: the file, whether it was written, and
    whether it was left alone because it differs (``force`` replaces it)."""

    geometry: Path
    written: bool
    stale: bool


def write_from_spec3d(spec_path: str | Path, out: str | Path | None = None,
                      force: bool = False) -> Outcome3d:
    """Build and check every volume of the spec and write ``<stem>-geometry.h5`` (into
    ``out``, default the spec's folder). A file already there with the same bytes is
    kept; one that differs is replaced only with ``force`` (else ``stale``)."""
    spec_path = Path(spec_path)
    data = read_spec3d(spec_path)
    volumes: dict[str, Volume] = {}
    for b in data["body"]:
        vol = build_volume(b, spec_path.parent)
        if b["name"] in volumes:
            raise SpecError(f"two bodies are named {b['name']!r}")
        try:
            check_volume(b["name"], vol)
        except ValueError as err:
            raise SpecError(str(err)) from None
        volumes[b["name"]] = vol
    folder = Path(out) if out is not None else spec_path.parent
    folder.mkdir(parents=True, exist_ok=True)
    geometry = check_output(folder / f"{spec_path.stem}-geometry.h5")
    fresh = folder / f".{spec_path.stem}-geometry.h5.new"
    try:
        write_volumes(fresh, volumes, scene=str(data.get("scene", spec_path.stem)),
                      units=str(data.get("units", "mm, N")))
        if geometry.exists():
            if geometry.read_bytes() == fresh.read_bytes():
                return Outcome3d(geometry, False, False)
            if not force:
                return Outcome3d(geometry, False, True)
        os.replace(fresh, check_output(geometry))
        return Outcome3d(geometry, True, False)
    finally:
        fresh.unlink(missing_ok=True)
