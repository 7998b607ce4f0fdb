"""A declarative geometry spec (TOML) -> geometry file and case file
(``python -m pre geometry SPEC.toml``; reference in ``docs/pre.md``).

A spec lists bodies (``[[body]]``, one patch each: ``shape = "rectangle"``,
``"annular_sector"`` (``r_in = 0``: a solid sector), ``"arc"``, ``"ellipse"``,
``"polygon"`` or ``"g2"``), rigid obstacles (``[[curve]]``: ``shape = "arc"``,
``"ellipse"``, ``"polyline"`` or ``"g2"``), the refinement and material defaults
(``[defaults]``), and the other groups of the case file (``[case]``, ``[solver]``,
``[[dirichlet]]``, ``[[pressure]]``, ``[[contact]]``, ``[output]``), written to the
case as they are after their variables are checked against those voiga reads
(:data:`pre.namelists.PLANE`): the spec holds the whole case. From ``name.toml``
it writes ``name-geometry.h5`` and the case ``name.nml`` next to it (or into
``--out``). When they exist and differ from what the spec gives now (the spec was
edited, or the case by hand), nothing is written: the differences are listed, and
``force`` writes both anew, listing what it replaced. A case written without load
groups is a template: its comments show the groups to add (``docs/formats.md``).

The spec of 3D bodies (:mod:`pre.spec3d`) shares the parts that do not depend on the
dimension: :func:`load_toml`, :func:`check_groups` (the case tables against the
variables voiga reads), :func:`assemble_case` (the case file's groups) and
:func:`write_case_files` (the two files, kept, listed or replaced).
"""

from __future__ import annotations

import math
import os
import tomllib
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .cases import to_namelist_text
from .changes import geometry_changes, namelist_changes
from .files import check_output, write_text
from .geometry import (
    annular_sector,
    body,
    check_curve,
    check_patch,
    edge_length,
    ellipse_sector,
    obstacle,
    obstacle_arc,
    obstacle_ellipse,
    obstacle_polyline,
    polygon,
    read_g2,
    rectangle,
    write_bodies,
)
from .layouts import parse_layout
from .namelists import PLANE
from .nurbs import Curve, Patch
from .spec_check import MAX_ELEMENTS, SpecCheckError, check_spec, check_table

DEFAULTS: dict[str, Any] = {
    "layout": "NN2.2",
    "elements": 8,
    "material": "neo-hookean",
    "youngs_modulus": 1.0,
    "poisson_ratio": 0.3,
}
"""Refinement and material defaults of every body (``[defaults]`` overrides them):
``layout`` (``Np``, ``NNp``, ``NNp.k``, ``L1``; docs/formats.md), ``elements`` along
the longer parametric direction of a body unless ``element_size`` is given (then
``ceil(edge length / element_size)`` in each direction) or the body sets ``nel``."""

CASE_GROUPS = ("solver", "dirichlet", "pressure", "contact", "output")
"""Spec tables copied into the case file, in this order (``[case]`` goes into
``&case``)."""

SINGLE_GROUPS = ("case", "solver", "output")
"""Groups a case has at most once: a table (``[solver]``), not an array of tables."""

CASE_BY_PRE = ("geometry", "n_bodies")
"""``&case`` variables pre writes itself (the geometry file it writes, the bodies)."""

BODY_KEYS = {"name", "shape", "edges", "contact_edge", "nel", "layout", "elements",
             "element_size", "material", "youngs_modulus", "poisson_ratio"}
SHAPE_KEYS = {
    "rectangle": {"x", "y"},
    "annular_sector": {"centre", "r_in", "r_out", "angles"},
    "arc": {"centre", "radius", "thickness", "angles"},
    "ellipse": {"centre", "semi_axes", "angles", "inner"},
    "polygon": {"points", "corners", "arcs"},
    "g2": {"file", "index"},
}


CURVE_KEYS = {"name", "shape", "side"}
CURVE_SHAPE_KEYS = {
    "arc": {"centre", "radius", "angles"},
    "ellipse": {"centre", "semi_axes", "angles"},
    "polyline": {"points", "arcs"},
    "g2": {"file", "index"},
}
"""Keys of a ``[[curve]]`` table (a rigid obstacle's boundary), per shape."""


class SpecError(ValueError):
    """A spec the tools cannot use; the message names the body and the key."""


@dataclass
class Spec:
    """A read spec: its file, the bodies' tables, defaults and case groups."""

    path: Path
    data: dict[str, Any]

    @property
    def bodies(self) -> list[dict[str, Any]]:
        return list(self.data.get("body", []))

    @property
    def curves(self) -> list[dict[str, Any]]:
        return list(self.data.get("curve", []))

    @property
    def defaults(self) -> dict[str, Any]:
        return {**DEFAULTS, **self.data.get("defaults", {})}


def load_toml(path: Path) -> dict[str, Any]:
    """The tables of a TOML spec (tomllib); SpecError when there is no such file or it
    is not TOML."""
    if not path.is_file():
        raise SpecError(f"no spec file {path}")
    try:
        return tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as err:
        raise SpecError(f"{path}: not valid TOML ({err})") from None


def check_groups(path: Path, data: dict[str, Any], groups: tuple[str, ...],
                 variables: dict[str, frozenset[str]]) -> None:
    """Every value of a spec checked (:func:`pre.spec_check.check_spec`), then its
    ``[case]`` and the case tables of ``groups`` against the ``variables`` of their
    namelist groups (:data:`pre.namelists.PLANE` or ``SOLID``)."""
    try:
        check_spec(data)
    except SpecCheckError as err:
        raise SpecError(f"{path}: {err}") from None
    for group in ("case", *groups):
        if group in data:
            check_case_tables(path, group, data[group], variables)


def read_spec(path: str | Path) -> Spec:
    """Parse a TOML spec (tomllib); SpecError names the problem."""
    path = Path(path)
    data = load_toml(path)
    unknown = set(data) - {"units", "scene", "defaults", "body", "curve", "case", *CASE_GROUPS}
    if unknown:
        raise SpecError(f"{path}: unknown table(s) {sorted(unknown)} (known: units, scene, [defaults], "
                        f"[[body]], [[curve]], [case], {', '.join(_table_name(g) for g in CASE_GROUPS)})")
    if not data.get("body"):
        raise SpecError(f"{path}: no [[body]]")
    check_groups(path, data, CASE_GROUPS, PLANE)
    return Spec(path, data)


def _table_name(group: str) -> str:
    return f"[{group}]" if group in SINGLE_GROUPS else f"[[{group}]]"


def check_case_tables(path: Path, group: str, value: Any,
                      variables: dict[str, frozenset[str]] = PLANE) -> None:
    """A case group of the spec: one table for ``[case]``, ``[solver]``, ``[output]``
    (any number for the others), each key one of the ``variables`` of that group
    (those voiga reads in a plane case, by default)."""
    tables = [value] if isinstance(value, dict) else value
    if group in SINGLE_GROUPS and not isinstance(value, dict):
        raise SpecError(f"{path}: [{group}] is one table (the case has one &{group}), not [[{group}]]")
    if not isinstance(tables, list) or not all(isinstance(t, dict) for t in tables):
        raise SpecError(f"{path}: {_table_name(group)} must be a table")
    for k, table in enumerate(tables, start=1):
        where = f"[{group}]" if isinstance(value, dict) else f"[[{group}]] ({k})"
        unknown = sorted(set(table) - variables[group])
        if unknown:
            raise SpecError(f"{path}: {where}: {unknown} not variable(s) of &{group} (known: "
                            f"{', '.join(sorted(variables[group]))}; docs/formats.md)")
        own = sorted(set(table) & set(CASE_BY_PRE)) if group == "case" else []
        if own:
            raise SpecError(f"{path}: [case]: {own} written by pre itself (the geometry file it writes, "
                            "the [[body]] tables)")


def need(b: dict[str, Any], key: str, what: str = "body") -> Any:
    """The value of ``key`` in the spec table ``b`` of a ``what`` (a body, ...), or a
    SpecError naming it."""
    if key not in b:
        raise SpecError(f"{what} {b.get('name', '?')!r}: missing {key!r}")
    return b[key]


def pick(objs: list[Any], b: dict[str, Any], what: str) -> Any:
    """The object ``index`` (default 0) of a .g2 file's ``objs`` for the body ``b``
    (``what``: 'surface' or 'volume', for the message)."""
    index = int(b.get("index", 0))
    if not 0 <= index < len(objs):
        raise SpecError(f"body {b.get('name', '?')!r}: the .g2 file has {len(objs)} {what}(s), no index {index}")
    return objs[index]


def build_patch(b: dict[str, Any], folder: Path) -> Patch:
    """The patch of one ``[[body]]`` table (``folder``: where relative files are)."""
    name = need(b, "name")
    shape = need(b, "shape")
    if not isinstance(name, str) or not isinstance(shape, str):
        raise SpecError(f"body {name!r}: name and shape must be strings")
    if shape not in SHAPE_KEYS:
        raise SpecError(f"body {name!r}: unknown shape {shape!r} (known: {sorted(SHAPE_KEYS)})")
    unknown = set(b) - BODY_KEYS - SHAPE_KEYS[shape]
    if unknown:
        raise SpecError(f"body {name!r}: unknown key(s) {sorted(unknown)} for shape {shape!r}")
    try:
        check_table(b, "body")
    except SpecCheckError as err:
        raise SpecError(str(err)) from None
    edges = b.get("edges")
    try:
        if shape == "rectangle":
            return rectangle(need(b, "x"), need(b, "y"), edges)
        if shape == "annular_sector":
            return annular_sector(need(b, "centre"), need(b, "r_in"), need(b, "r_out"),
                                  need(b, "angles"), edges)
        if shape == "arc":
            r, t = float(need(b, "radius")), float(need(b, "thickness"))
            return annular_sector(need(b, "centre"), r - t / 2, r + t / 2, need(b, "angles"), edges)
        if shape == "ellipse":
            return ellipse_sector(need(b, "centre"), need(b, "semi_axes"), need(b, "angles"),
                                  float(b.get("inner", 0.0)), edges)
        if shape == "polygon":
            arcs = {int(a["segment"]): float(a["radius"]) for a in b.get("arcs", [])}
            return polygon(need(b, "points"), b.get("corners"), arcs, edges)
        objs = [o for o in read_g2(folder / need(b, "file")) if o.pardim == 2]
        return body(pick(objs, b, "surface"), dict(edges or {}))
    except (ValueError, KeyError, TypeError) as err:
        if isinstance(err, SpecError):
            raise
        raise SpecError(f"body {name!r}: {err}") from None


def build_curve(c: dict[str, Any], folder: Path) -> Curve:
    """The obstacle curve of one ``[[curve]]`` table (``folder``: where relative files
    are): an ``arc`` or ``ellipse`` (``side`` "inside", the default: the disc is the
    obstacle, or "outside"), a ``polyline`` or the ``index``-th curve of a ``.g2``
    file (``side`` "left" or "right" of the direction of travel: required)."""
    name = need(c, "name", "curve")
    shape = need(c, "shape", "curve")
    if not isinstance(name, str) or not isinstance(shape, str):
        raise SpecError(f"curve {name!r}: name and shape must be strings")
    if shape not in CURVE_SHAPE_KEYS:
        raise SpecError(f"curve {name!r}: unknown shape {shape!r} (known: {sorted(CURVE_SHAPE_KEYS)})")
    unknown = set(c) - CURVE_KEYS - CURVE_SHAPE_KEYS[shape]
    if unknown:
        raise SpecError(f"curve {name!r}: unknown key(s) {sorted(unknown)} for shape {shape!r}")
    try:
        check_table(c, "curve")
    except SpecCheckError as err:
        raise SpecError(str(err)) from None
    try:
        if shape == "arc":
            return obstacle_arc(need(c, "centre", "curve"), float(need(c, "radius", "curve")),
                                need(c, "angles", "curve"), str(c.get("side", "inside")))
        if shape == "ellipse":
            return obstacle_ellipse(need(c, "centre", "curve"), need(c, "semi_axes", "curve"),
                                    need(c, "angles", "curve"), str(c.get("side", "inside")))
        side = str(need(c, "side", "curve"))
        if shape == "polyline":
            arcs = {int(a["segment"]): float(a["radius"]) for a in c.get("arcs", [])}
            return obstacle_polyline(need(c, "points", "curve"), side, arcs)
        objs = [o for o in read_g2(folder / need(c, "file", "curve")) if o.pardim == 1]
        index = int(c.get("index", 0))
        if not 0 <= index < len(objs):
            raise SpecError(f"curve {name!r}: the .g2 file has {len(objs)} curve(s), no index {index}")
        return obstacle(objs[index], side)
    except (ValueError, KeyError, TypeError) as err:
        if isinstance(err, SpecError):
            raise
        raise SpecError(f"curve {name!r}: {err}") from None


def _orient(patch: Patch, contact_key: str | None) -> tuple[str, str]:
    """The patch edges along which the case's ``nel_xi`` and ``nel_eta`` count: the
    solver turns the patch so that the contact edge is eta = 1 (docs/formats.md)."""
    if contact_key in ("xi0", "xi1"):
        return "xi0", "eta0"  # along the contact edge = along eta of the patch
    return "eta0", "xi0"


def body_group(b: dict[str, Any], patch: Patch, defaults: dict[str, Any]) -> dict[str, Any]:
    """The ``&body`` group of one body: layout, mesh, contact edge, material."""
    name = b["name"]
    opt = {**defaults, **{k: v for k, v in b.items() if k in DEFAULTS or k == "element_size"}}
    try:
        lay = parse_layout(str(opt["layout"]))
    except ValueError as err:
        raise SpecError(f"body {name!r}: {err}") from None
    contact = b.get("contact_edge", "")
    key = None
    if contact:
        try:
            key = patch.edge_key(contact)
        except KeyError:
            raise SpecError(f"body {name!r}: contact_edge {contact!r} is not one of its edges "
                            f"{sorted(patch.edges.values())}") from None
    along, across = _orient(patch, key)
    if "nel" in b:
        nel = [int(n) for n in b["nel"]]
        if len(nel) != 2 or min(nel) < 1:
            raise SpecError(f"body {name!r}: nel must be two positive integers [xi, eta]")
        if key in ("xi0", "xi1"):  # given along the patch's xi, eta; the case counts turned
            nel = nel[::-1]
    else:
        lengths = [edge_length(patch, along), edge_length(patch, across)]
        if "element_size" in opt:
            h = float(opt["element_size"])
            if h <= 0:
                raise SpecError(f"body {name!r}: element_size must be positive")
            nel = [max(1, math.ceil(L / h - 1e-9)) if L / h < MAX_ELEMENTS else MAX_ELEMENTS + 1
                   for L in lengths]
            if max(nel) > MAX_ELEMENTS:
                raise SpecError(f"body {name!r}: element_size {h:g} gives more than {MAX_ELEMENTS} elements "
                                f"along an edge (edges {lengths[0]:g} and {lengths[1]:g} long)")
        else:
            n = int(opt["elements"])
            h = max(lengths) / n
            nel = [max(1, math.ceil(L / h - 1e-9)) for L in lengths]
    g: dict[str, Any] = {"name": name, "basis": lay.basis,
                         "degree_xi": max(lay.degree_xi, max(patch.degree) if lay.basis == "nurbs" else 1),
                         "degree_eta": max(lay.degree_eta, max(patch.degree) if lay.basis == "nurbs" else 1),
                         "nel_xi": nel[0], "nel_eta": nel[1], "contact_edge": contact,
                         "layer_degree": lay.layer_degree if contact else 0,
                         "layer_elevations": lay.layer_elevations if contact else 0,
                         "material": str(opt["material"]),
                         "youngs_modulus": float(opt["youngs_modulus"]),
                         "poisson_ratio": float(opt["poisson_ratio"])}
    return g


TEMPLATE_HELP = """
! This case has no loads yet: add the groups you need (docs/formats.md), e.g.
!
! &solver
!   n_steps = 10
! /
! &dirichlet
!   body = '{body}', edge = '{edge}', fix_x = .true., fix_y = .true., ux = 0.0, uy = -0.1
! /
! &contact
!   slave = '{body}', master = 'rigid', rigid_point = 0.0, 0.0, rigid_normal = 0.0, 1.0,
!   penalty_normal = 100.0, friction = 0.0
! /
"""


def assemble_case(data: dict[str, Any], bodies: list[dict[str, Any]], geometry: str, stem: str,
                  groups: tuple[str, ...] = CASE_GROUPS) -> dict[str, Any]:
    """The case file's groups: ``&case`` (pre's values, then the spec's ``[case]``), the
    ``&body`` groups ``bodies``, then the spec's tables of ``groups`` as given."""
    case = {"title": data.get("scene", stem), "scene": data.get("scene", stem),
            "geometry": geometry, "output": f"{stem}.h5", "n_bodies": len(bodies)}
    case.update(data.get("case", {}))
    out: dict[str, Any] = {"case": case, "body": bodies}
    for g in groups:
        if g in data:
            value = data[g]
            out[g] = value if isinstance(value, dict) else list(value)
    return out


def case_groups(spec: Spec, patches: dict[str, Patch], geometry: str, stem: str) -> dict[str, Any]:
    """The case file's groups: ``&case`` (pre's values, then the spec's ``[case]``), one
    ``&body`` per body, then the spec's ``[solver]``, ``[[dirichlet]]``,
    ``[[pressure]]``, ``[[contact]]``, ``[output]`` as given."""
    return assemble_case(spec.data, [body_group(b, patches[b["name"]], spec.defaults) for b in spec.bodies],
                         geometry, stem)


@dataclass
class SpecOutcome:
    """What ``write_from_spec`` did: the two files, whether it wrote them, and what
    differed between the files there before and the spec (empty: new files, or the
    same values)."""

    geometry: Path
    case: Path
    written: bool
    changes: list[str] = field(default_factory=list)

    @property
    def stale(self) -> bool:
        """The files differ from the spec and were kept (no ``force``)."""
        return bool(self.changes) and not self.written


def build_all(spec: Spec) -> tuple[dict[str, Patch], dict[str, Curve]]:
    """Every body's patch and every obstacle curve of the spec, checked."""
    patches: dict[str, Patch] = {}
    curves: dict[str, Curve] = {}
    for tables, build, check, into in ((spec.bodies, build_patch, check_patch, patches),
                                       (spec.curves, build_curve, check_curve, curves)):
        for t in tables:
            obj = build(t, spec.path.parent)
            if t["name"] in patches or t["name"] in curves:
                raise SpecError(f"two bodies or curves are named {t['name']!r}")
            try:
                check(t["name"], obj)
            except ValueError as err:
                raise SpecError(str(err)) from None
            into[t["name"]] = obj
    return patches, curves


def case_text(spec: Spec, patches: dict[str, Patch], stem: str) -> str:
    """The case file of the spec (a template with comments when it has no load groups)."""
    text = to_namelist_text(case_groups(spec, patches, f"{stem}-geometry.h5", stem))
    if not any(g in spec.data for g in CASE_GROUPS if g != "output"):
        first = spec.bodies[0]["name"]
        edge = sorted(patches[first].edges.values())[0]
        text += TEMPLATE_HELP.format(body=first, edge=edge)
    return text


def write_from_spec(spec_path: str | Path, out: str | Path | None = None,
                    force: bool = False) -> SpecOutcome:
    """Build every body of the spec and write ``<stem>-geometry.h5`` and the case
    ``<stem>.nml`` (into ``out``, default the spec's folder), as
    :func:`write_case_files` does: kept when up to date, the differences listed and
    nothing written without ``force``."""
    spec = read_spec(spec_path)
    patches, curves = build_all(spec)
    text = case_text(spec, patches, spec.path.stem)

    def geometry(path: Path) -> None:
        write_bodies(path, patches, scene=str(spec.data.get("scene", spec.path.stem)),
                     units=str(spec.data.get("units", "mm, N")), curves=curves)

    return write_case_files(spec.path, out, text, geometry, force)


def write_case_files(spec_path: Path, out: str | Path | None, text: str,
                     write_geometry: Callable[[Path], None], force: bool = False) -> SpecOutcome:
    """Write the geometry file (``write_geometry(path)`` writes it) and the case
    ``text`` as ``<stem>-geometry.h5`` and ``<stem>.nml`` of the spec ``spec_path``
    (into ``out``, default the spec's folder). When the case file exists, nothing is
    written without ``force``: its values and the geometry are the spec's (the file
    keeps its comments; a missing geometry file is written), or they differ (the spec
    or the case was edited) and the outcome lists how. With ``force`` both are
    written anew, the outcome listing what was replaced."""
    folder = Path(out) if out is not None else spec_path.parent
    stem = spec_path.stem
    folder.mkdir(parents=True, exist_ok=True)
    geometry, case = folder / f"{stem}-geometry.h5", folder / f"{stem}.nml"
    # nothing is written through a link or over a special file (pre/files.py)
    check_output(geometry)
    check_output(case)
    fresh = folder / f".{stem}-geometry.h5.new"
    try:
        write_geometry(fresh)
        changes: list[str] = []
        if case.exists():
            changes = [f"{case.name}: {c}" for c in namelist_changes(case.read_text(), text)]
            changes += geometry_changes(geometry, fresh)
            if not force:
                if not changes and not geometry.exists():
                    os.replace(fresh, check_output(geometry))
                return SpecOutcome(geometry, case, False, changes)
        os.replace(fresh, check_output(geometry))
        write_text(case, text)
        return SpecOutcome(geometry, case, True, changes)
    finally:
        fresh.unlink(missing_ok=True)
