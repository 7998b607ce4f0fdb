"""What differs between the files a spec wrote earlier and what it gives now
(``python -m pre geometry``, ``geometry3d``): the case file's groups and variables, and
the geometry file's bodies (patches or volumes) and curves. A spec edited since (a new ``n_steps``) and a case
edited by hand (an added ``&output``) both show up here, one line each, so that
nothing is replaced without saying what."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import f90nml
import h5py
import numpy as np

from .h5io import attrs_dict, read_body, read_curves
from .nurbs import Curve, Patch
from .volume import Volume

LABEL_KEYS = ("name", "slave", "body")
"""The variable that names a repeated group in a message (``&body 'block'``)."""


def _text(value: Any) -> str:
    """A namelist value as a case file shows it."""
    if isinstance(value, list):
        return ", ".join(_text(v) for v in value)
    if isinstance(value, bool):
        return ".true." if value else ".false."
    if isinstance(value, str):
        return repr(value)
    return repr(value) if isinstance(value, float) else str(value)


def _groups(nml: f90nml.Namelist, name: str) -> list[dict[str, Any]]:
    value = nml.get(name)
    if value is None:
        return []
    return [dict(g) for g in value] if isinstance(value, list) else [dict(value)]


def _label(name: str, group: dict[str, Any], k: int, count: int) -> str:
    for key in LABEL_KEYS:
        if key in group and name != "case":
            return f"&{name} {group[key]!r}" + (f" ({k + 1})" if count > 1 and name != "body" else "")
    return f"&{name}" + (f" ({k + 1})" if count > 1 else "")


def namelist_changes(old_text: str, new_text: str) -> list[str]:
    """The differences of two case files' values (comments and layout aside), one line
    each: a variable ``(case file) -> (spec)``, a group only in one of them."""
    try:
        old = f90nml.reads(old_text)
    except Exception as err:  # f90nml raises several kinds on bad text
        return [f"the case file is not a readable namelist ({err})"]
    new = f90nml.reads(new_text)
    out: list[str] = []
    names = list(new) + [n for n in old if n not in new]
    for name in names:
        olds, news = _groups(old, name), _groups(new, name)
        count = max(len(olds), len(news))
        for k in range(count):
            if k >= len(olds):
                out.append(f"{_label(name, news[k], k, count)}: only in the spec")
                continue
            if k >= len(news):
                out.append(f"{_label(name, olds[k], k, count)}: only in the case file (the spec has no "
                           f"such [{name}] table)")
                continue
            a, b = olds[k], news[k]
            for var in list(b) + [v for v in a if v not in b]:
                if var not in a:
                    out.append(f"{_label(name, b, k, count)} {var}: not in the case file -> {_text(b[var])} (spec)")
                elif var not in b:
                    out.append(f"{_label(name, a, k, count)} {var}: {_text(a[var])} (case file) -> not in the spec")
                elif a[var] != b[var]:
                    out.append(f"{_label(name, b, k, count)} {var}: {_text(a[var])} (case file) -> "
                               f"{_text(b[var])} (spec)")
    return out


def _same_patch(a: Patch | Volume | Curve, b: Patch | Volume | Curve) -> bool:
    if type(a) is not type(b):
        return False
    if isinstance(a, Volume) and isinstance(b, Volume):
        pairs = list(zip(a.knots, b.knots, strict=True))
        if a.degree != b.degree or a.faces != b.faces:
            return False
    elif isinstance(a, Patch) and isinstance(b, Patch):
        pairs = [(a.knots_xi, b.knots_xi), (a.knots_eta, b.knots_eta)]
        if a.degree != b.degree or a.edges != b.edges:
            return False
    elif isinstance(a, Curve) and isinstance(b, Curve):
        pairs = [(a.knots, b.knots)]
        if a.degree != b.degree:
            return False
    pairs += [(a.control_points, b.control_points), (a.weights, b.weights)]
    return all(np.shape(x) == np.shape(y) and np.array_equal(x, y) for x, y in pairs)


def _read_bodies(path: Path) -> tuple[dict[str, Any], dict[str, Patch | Volume]]:
    """``(root attrs, {name: patch or volume})`` of a geometry file of either dimension."""
    with h5py.File(path, "r") as f:
        return attrs_dict(f), {name: read_body(g) for name, g in f["bodies"].items()}


def geometry_changes(old: Path, new: Path) -> list[str]:
    """The differences of two geometry files: bodies and curves added, removed or
    changed (shape, mesh of the coarse patch or volume, edge or face names), the scene
    and units."""
    if not old.is_file():
        return []
    if old.read_bytes() == new.read_bytes():
        return []
    try:
        old_attrs, old_bodies = _read_bodies(old)
        old_curves = read_curves(old)
    except Exception as err:  # h5py raises several kinds on a file that is not ours
        return [f"{old.name} is not a readable geometry file ({err})"]
    new_attrs, new_bodies = _read_bodies(new)
    new_curves = read_curves(new)
    out = []
    for what, a, b in (("body", old_bodies, new_bodies), ("curve", old_curves, new_curves)):
        for name in list(b) + [n for n in a if n not in b]:
            if name not in a:
                out.append(f"{old.name}: {what} {name!r}: only in the spec")
            elif name not in b:
                out.append(f"{old.name}: {what} {name!r}: only in the geometry file")
            elif not _same_patch(a[name], b[name]):
                sides = "faces" if isinstance(b[name], Volume) else "edges"
                out.append(f"{old.name}: {what} {name!r}: its shape or {sides} differ")
        if list(a) != list(b) and set(a) == set(b):
            out.append(f"{old.name}: the {what} order differs")
    for key in ("scene", "units", "dimension"):
        if str(old_attrs.get(key, "")) != str(new_attrs.get(key, "")):
            out.append(f"{old.name}: {key} {old_attrs.get(key, '')!r} -> {new_attrs.get(key, '')!r} (spec)")
    return out or [f"{old.name}: differs (its metadata)"]
