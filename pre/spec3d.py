"""A spec of 3D bodies (TOML) -> geometry file of volumes and case file
(``python -m pre geometry3d SPEC.toml``; reference in ``docs/pre.md``, "3D bodies").

The 3D counterpart of :mod:`pre.spec`: ``units``, ``scene``, ``[defaults]`` and
``[[body]]`` tables with ``name``, ``shape`` (:data:`SHAPES`), the shape's keys,
``faces`` (renames, ``{label = "new name"}``; for ``g2`` the names of all six faces by
key) and the ``&body`` settings of a solid (``layout``, ``elements``,
``element_size`` or ``nel = [n_xi, n_eta, n_zeta]``, ``contact_face``, the material;
:mod:`pre.solid_case`). ``extrude`` and ``revolve`` take a ``section``: a 2D body
table of the 2D spec (``shape = "rectangle"``, ... with its ``edges``), built by
:func:`pre.spec.build_patch`. The case groups ``[case]``, ``[solver]``,
``[[dirichlet]]`` and ``[[pressure]]`` (on faces: ``face``, ``fix_z``, ``uz``) and
``[output]`` are checked against the variables of a solid case
(:data:`pre.namelists.SOLID`) and copied; ``[[contact]]`` is refused (contact between
solids is not implemented yet: issue 42). From ``name.toml`` it writes
``name-geometry.h5`` and the case ``name.nml`` (into ``--out`` or the spec's folder),
kept, listed or replaced as the 2D spec's (:func:`pre.spec.write_case_files`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from .cases import to_namelist_text
from .namelists import SOLID
from .solid_case import DEFAULT_KEYS, MESH_KEYS, check_loads, solid_body_group
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
from .spec import (
    SpecError,
    SpecOutcome,
    assemble_case,
    build_patch,
    check_groups,
    load_toml,
    need,
    pick,
    write_case_files,
)
from .spec_check import KEY_CHECKS, MAX_ELEMENTS, SpecCheckError, integer, number, numbers, text
from .volume import Volume, check_volume

SHAPES: dict[str, set[str]] = {
    "box": {"x", "y", "z"},
    "cylinder_sector": {"r_in", "r_out", "angles", "z", "centre"},
    "shell_octant": {"r_in", "r_out", "centre"},
    "extrude": {"section", "z", "ends"},
    "revolve": {"section", "angle", "axis_point", "axis_direction", "ends"},
    "g2": {"file", "index"},
}
"""The shapes of a ``[[body]]`` table and their keys (besides :data:`BODY_KEYS`)."""

BODY_KEYS = {"name", "shape", "faces"} | MESH_KEYS
"""Keys of every ``[[body]]``: its name, shape, face names and ``&body`` settings."""

CASE_GROUPS = ("solver", "dirichlet", "pressure", "output")
"""Spec tables copied into a solid case file, in this order (``[case]`` goes into
``&case``; no ``[[contact]]`` yet)."""

TABLES = ("units", "scene", "defaults", "body", "case", *CASE_GROUPS)
"""What a 3D spec may hold (``[[contact]]`` is named apart: not implemented yet)."""

def _fail(message: str) -> None:
    raise SpecCheckError(message)


CHECKS: dict[str, Any] = {
    "x": lambda v, w: numbers(v, w, 2), "y": lambda v, w: numbers(v, w, 2),
    "z": lambda v, w: numbers(v, w, 2), "angles": lambda v, w: numbers(v, w, 2),
    "r_in": lambda v, w: number(v, w, 0.0), "r_out": lambda v, w: number(v, w, 0.0),
    "angle": lambda v, w: number(v, w, 0.0, 90.0),
    "axis_point": lambda v, w: numbers(v, w, 2), "axis_direction": lambda v, w: numbers(v, w, 2),
    "file": text, "index": lambda v, w: integer(v, w, 0, 10**6),
    "contact_face": lambda v, w: None if v == "" else text(v, w),
    "nel": lambda v, w: [integer(n, f"{w}[{k}]", 1, MAX_ELEMENTS) for k, n in enumerate(v)]
    if isinstance(v, list) and len(v) == 3 else _fail(f"{w} must be three integers [n_xi, n_eta, n_zeta], "
                                                       f"not {v!r}"),
    **{k: KEY_CHECKS[k] for k in DEFAULT_KEYS},
}
"""How each key of a ``[[body]]`` is checked before anything is built (``centre``,
``ends``, ``faces`` and ``section`` by :func:`_check`)."""


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
    """Parse a 3D spec (tomllib) and check its tables; SpecError names the problem."""
    path = Path(path)
    data = load_toml(path)
    if "contact" in data:
        raise SpecError(f"{path}: [[contact]]: contact between solids is not implemented yet (issue 42); "
                        "a solid case has bodies and loads (docs/formats.md, \"Solids\")")
    unknown = set(data) - set(TABLES)
    if unknown:
        raise SpecError(f"{path}: unknown key(s) or table(s) {sorted(unknown)} (known: units, scene, "
                        "[defaults], [[body]], [case], [solver], [[dirichlet]], [[pressure]], [output])")
    body = data.get("body")
    if not body or not isinstance(body, list) or not all(isinstance(t, dict) for t in body):
        raise SpecError(f"{path}: no [[body]] tables")
    defaults = data.get("defaults", {})
    if isinstance(defaults, dict) and set(defaults) - DEFAULT_KEYS:
        raise SpecError(f"{path}: [defaults]: unknown key(s) {sorted(set(defaults) - DEFAULT_KEYS)} "
                        f"(known: {', '.join(sorted(DEFAULT_KEYS))})")
    if isinstance(defaults, dict) and {"elements", "element_size"} <= set(defaults):
        raise SpecError(f"{path}: [defaults]: give elements or element_size, not both")
    check_groups(path, data, CASE_GROUPS, SOLID)
    return data


def build_volumes(data: dict[str, Any], folder: Path) -> dict[str, Volume]:
    """Every body's volume, checked (``folder``: where relative files are)."""
    volumes: dict[str, Volume] = {}
    for b in data["body"]:
        vol = build_volume(b, folder)
        if b["name"] in volumes:
            raise SpecError(f"two bodies are named {b['name']!r}")
        try:
            check_volume(b["name"], vol)
        except ValueError as err:
            raise SpecError(str(err)) from None
        volumes[b["name"]] = vol
    return volumes


TEMPLATE_HELP = """
! This case has no loads yet: add the groups you need (docs/formats.md, "Solids"), e.g.
!
! &solver
!   n_steps = 1
! /
! &dirichlet
!   body = '{body}', face = '{fixed}', fix_x = .true., fix_y = .true., fix_z = .true.
! /
! &pressure
!   body = '{body}', face = '{loaded}', p = 0.01
! /
"""


def case_text3d(data: dict[str, Any], volumes: dict[str, Volume], stem: str) -> str:
    """The case file of a 3D spec (a template with comments when it has no load groups)."""
    bodies = [solid_body_group(b, volumes[b["name"]], data.get("defaults", {})) for b in data["body"]]
    text = to_namelist_text(assemble_case(data, bodies, f"{stem}-geometry.h5", stem, CASE_GROUPS))
    if not any(g in data for g in CASE_GROUPS if g != "output"):
        first = data["body"][0]["name"]
        faces = volumes[first].faces
        text += TEMPLATE_HELP.format(body=first, fixed=faces["zeta0"], loaded=faces["zeta1"])
    return text


def write_from_spec3d(spec_path: str | Path, out: str | Path | None = None,
                      force: bool = False) -> SpecOutcome:
    """Build and check every volume of the spec, its loads against them, and write
    ``<stem>-geometry.h5`` and the case ``<stem>.nml`` (into ``out``, default the
    spec's folder) as :func:`pre.spec.write_case_files` does: kept when up to date, the
    differences listed and nothing written without ``force``."""
    spec_path = Path(spec_path)
    data = read_spec3d(spec_path)
    volumes = build_volumes(data, spec_path.parent)
    check_loads(data, volumes)
    text = case_text3d(data, volumes, spec_path.stem)

    def geometry(path: Path) -> None:
        write_volumes(path, volumes, scene=str(data.get("scene", spec_path.stem)),
                      units=str(data.get("units", "mm, N")))

    return write_case_files(spec_path, out, text, geometry, force)
