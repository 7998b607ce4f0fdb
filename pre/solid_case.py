"""The case file's groups of solids (``docs/formats.md``, "Solids") from the tables of a
3D spec (:mod:`pre.spec3d`): each body's ``&body`` (layout, elements per direction,
contact face, material) and the checks of the load tables (``[[dirichlet]]`` and
``[[pressure]]`` on faces) that need the volumes: the body and face a table names, the
components it fixes and one value per load phase.

A solid's element counts and degrees run along the directions of the patch voiga
solves on: it turns a volume so that its contact face is ``zeta = 1`` (the other two
directions first, in cyclic order; ``patch_orient`` in ``src/nurbs/patch.f90``). A
spec gives ``nel`` along the volume's own directions, and :func:`solid_body_group`
reorders them.
"""

from __future__ import annotations

import math
from typing import Any, NoReturn

import numpy as np

from .layouts import solid_layout
from .nurbs import KNOT_TOL
from .spec import SpecError
from .spec_check import MAX_ELEMENTS
from .volume import DIRECTIONS, Volume, evaluate

SOLID_DEFAULTS: dict[str, Any] = {
    "elements": 8,
    "material": "neo-hookean",
    "youngs_modulus": 1.0,
    "poisson_ratio": 0.3,
}
"""Defaults of every solid (``[defaults]`` overrides them): ``elements`` along the
longest direction of a body, the material as in the 2D spec. The layout's default
depends on the geometry (:func:`pre.layouts.solid_layout`)."""

DEFAULT_KEYS = frozenset({"layout", "elements", "element_size", "material", "youngs_modulus", "poisson_ratio"})
"""Keys of ``[defaults]`` in a 3D spec (a body may set each of them too)."""

MESH_KEYS = DEFAULT_KEYS | {"nel", "contact_face"}
"""Keys of a 3D ``[[body]]`` that go into its ``&body`` group."""

COMPONENTS = ("x", "y", "z")


def _fail(message: str) -> NoReturn:
    raise SpecError(message)


def direction_lengths(vol: Volume, n: int = 200) -> tuple[float, float, float]:
    """The length of each parametric direction (xi, eta, zeta) of ``vol``: the longest
    of its four edges along that direction (polylines of ``n`` points; a face collapsed
    onto a line, as the shell octant's pole, has edges of length 0)."""
    t = np.linspace(0.0, 1.0, n)
    out = []
    for d in range(3):
        others = [e for e in range(3) if e != d]
        longest = 0.0
        for a in (0.0, 1.0):
            for b in (0.0, 1.0):
                params = [t, t, t]
                params[others[0]], params[others[1]] = np.full(n, a), np.full(n, b)
                pts = evaluate(vol, *params)
                longest = max(longest, float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum()))
        out.append(longest)
    return out[0], out[1], out[2]


def element_counts(b: dict[str, Any], defaults: dict[str, Any], vol: Volume) -> list[int]:
    """Elements along the volume's own xi, eta, zeta: the body's ``nel``, else its
    ``element_size`` or ``elements``, else those of ``[defaults]`` (``elements``: along
    the longest direction, as many of the same length along the others;
    ``element_size``: ``ceil(length / size)`` per direction)."""
    name = b["name"]
    if "nel" in b:
        return [int(n) for n in b["nel"]]
    if "element_size" in b and "elements" in b:
        _fail(f"body {name!r}: give elements or element_size, not both")
    own = b if ("element_size" in b or "elements" in b) else {**SOLID_DEFAULTS, **defaults}
    lengths = direction_lengths(vol)
    if "element_size" in own:
        h = float(own["element_size"])
        if max(lengths) / h > MAX_ELEMENTS:
            _fail(f"body {name!r}: element_size {h:g} gives more than {MAX_ELEMENTS} elements along a "
                  f"direction (lengths {', '.join(f'{L:g}' for L in lengths)})")
        return [max(1, math.ceil(L / h - 1e-9)) for L in lengths]
    h = max(lengths) / int(own["elements"])
    return [max(1, math.ceil(L / h - 1e-9)) for L in lengths]


def solid_body_group(b: dict[str, Any], vol: Volume, defaults: dict[str, Any]) -> dict[str, Any]:
    """The ``&body`` group of one solid: the layout's basis, degrees and layer, the
    element counts along the turned patch's directions, the contact face (the body's
    ``contact_face``; else, for a layout with a layer, the face ``zeta = 1``; else
    none) and the material."""
    name = b["name"]
    opt = {**SOLID_DEFAULTS, **defaults, **b}
    try:
        lay = solid_layout(opt.get("layout"), max(vol.degree))
    except ValueError as err:
        raise SpecError(f"body {name!r}: {err}") from None
    face, key = str(b.get("contact_face", "")), "zeta1"
    if face:
        try:
            key = vol.face_key(face)
        except KeyError:
            raise SpecError(f"body {name!r}: contact_face {face!r} is not one of its faces "
                            f"{sorted(vol.faces.values())}") from None
    elif lay.layer_degree:
        face = vol.faces["zeta1"]
    k = DIRECTIONS.index(key[:-1])
    nel = element_counts(b, defaults, vol)
    nel = [nel[(k + 1) % 3], nel[(k + 2) % 3], nel[k]]  # the patch voiga turns: the face at zeta = 1
    return {"name": name, "basis": lay.basis,
            "degree_xi": lay.degree, "degree_eta": lay.degree, "degree_zeta": lay.degree,
            "nel_xi": nel[0], "nel_eta": nel[1], "nel_zeta": nel[2], "contact_face": face,
            "layer_degree": lay.layer_degree, "layer_elevations": lay.layer_elevations,
            "material": str(opt["material"]), "youngs_modulus": float(opt["youngs_modulus"]),
            "poisson_ratio": float(opt["poisson_ratio"])}


def knotted_body_group(spec: dict[str, Any], vol: Volume, knots: dict[str, list[float]]) -> dict[str, Any]:
    """:func:`solid_body_group` of ``spec`` (its ``nel`` one more than the knots per
    direction) with the interior knots ``knots_xi``, ``knots_eta``, ``knots_zeta`` of
    ``knots`` in place of the element counts. The knots run along the patch voiga
    solves on: the volume's own directions when the contact face is ``zeta = 1`` (the
    scenes' bodies). SpecError as :func:`solid_body_group`."""
    spec = {**spec, "nel": [len(knots[f"knots_{d}"]) + 1 for d in DIRECTIONS]}
    return {(f"knots_{k[4:]}" if k.startswith("nel_") else k):
            (knots[f"knots_{k[4:]}"] if k.startswith("nel_") else v)
            for k, v in solid_body_group(spec, vol, {}).items()}


def load_phases(data: dict[str, Any]) -> int:
    """The number of load phases: the entries of ``[solver] n_steps`` (one without)."""
    n_steps = data.get("solver", {}).get("n_steps", 1)
    return len(n_steps) if isinstance(n_steps, list) else 1


def _phase_values(value: Any, where: str, phases: int) -> None:
    values = value if isinstance(value, list) else [value]
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values) \
            or len(values) != phases:
        _fail(f"{where} needs one number per load phase ({phases} in [solver] n_steps), not {value!r}")


def _face(t: dict[str, Any], where: str, volumes: dict[str, Volume]) -> str:
    """The face a load table names, checked against its body's faces."""
    body, face = t.get("body"), t.get("face")
    if body not in volumes:
        _fail(f"{where}: body {body!r} is not a [[body]] of the spec (bodies: {list(volumes)})")
    if face is None:
        _fail(f"{where}: face is required (faces of {body!r}: {sorted(volumes[body].faces.values())})")
    if face not in volumes[body].faces.values():
        _fail(f"{where}: body {body!r} has no face {face!r} (faces: {sorted(volumes[body].faces.values())})")
    return str(face)


def check_loads(data: dict[str, Any], volumes: dict[str, Volume]) -> None:
    """The ``[[dirichlet]]`` and ``[[pressure]]`` tables of a 3D spec: each names a body
    and one of its faces; a Dirichlet table fixes at least one component (``fix_x``,
    ``fix_y``, ``fix_z`` booleans), gives a value (``ux``, ``uy``, ``uz``) only for a
    fixed component and fixes no component another table fixes on the same face; every
    value (``p`` required) is one number per load phase."""
    phases = load_phases(data)
    fixed: dict[tuple[str, str, str], int] = {}
    for k, t in enumerate(data.get("dirichlet", []), start=1):
        where = f"[[dirichlet]] ({k})"
        face = _face(t, where, volumes)
        for c in COMPONENTS:
            flag = t.get(f"fix_{c}", False)
            if not isinstance(flag, bool):
                _fail(f"{where}: fix_{c} must be true or false, not {flag!r}")
            if f"u{c}" in t:
                if not flag:
                    _fail(f"{where}: u{c} is given but fix_{c} is not true (a value for a component "
                          "that is not fixed)")
                _phase_values(t[f"u{c}"], f"{where}: u{c}", phases)
            if flag:
                other = fixed.setdefault((t["body"], face, c), k)
                if other != k:
                    _fail(f"{where}: fix_{c} of face {face!r} of {t['body']!r} is fixed by [[dirichlet]] "
                          f"({other}) already")
        if not any(t.get(f"fix_{c}", False) for c in COMPONENTS):
            _fail(f"{where}: fixes nothing (fix_x, fix_y or fix_z must be true)")
    for k, t in enumerate(data.get("pressure", []), start=1):
        where = f"[[pressure]] ({k})"
        _face(t, where, volumes)
        if "p" not in t:
            _fail(f"{where}: p is required (force per reference area, positive into the body)")
        _phase_values(t["p"], f"{where}: p", phases)


def _direction_functions(coarse: np.ndarray, p_coarse: int, degree: int, new: np.ndarray,
                         linear: bool) -> tuple[int, int]:
    """``(functions, distinct interior knots)`` of one direction after k-refinement of
    the coarse knot vector ``coarse`` (degree ``p_coarse``) to ``degree`` with the new
    interior knots ``new`` (each inserted once); ``linear``: the L1 basis (degree 1,
    one node per breakpoint)."""
    values, counts = np.unique(np.asarray(coarse, dtype=float), return_counts=True)
    inner, mult = values[1:-1], counts[1:-1]
    fresh = [k for k in np.asarray(new, dtype=float) if not np.any(np.abs(inner - k) <= KNOT_TOL)]
    distinct = len(inner) + len(fresh)
    if linear:
        return 2 + distinct, distinct
    return degree + 1 + int(np.sum(mult + degree - p_coarse)) + len(fresh), distinct


def _new_knots(group: dict[str, Any], direction: str) -> np.ndarray:
    """The interior knots a ``&body`` inserts along ``direction``: ``knots_<dir>``, else
    ``i / nel_<dir>``."""
    explicit = group.get(f"knots_{direction}")
    if explicit is not None:
        return np.atleast_1d(np.asarray(explicit, dtype=float))
    nel = int(group.get(f"nel_{direction}", 1) or 1)
    return np.array([i / nel for i in range(1, nel)])


def solid_dofs(group: dict[str, Any], vol: Volume) -> dict[str, int]:
    """DOFs of a solid with the ``&body`` settings ``group`` on the coarse volume ``vol``
    (the counts of docs/formats.md, "Layouts in 3D"): ``interface`` (the layer's 3 m_1
    m_2, or without a layer the contact face's bulk points), ``bulk`` and ``total``.
    The group's directions are those of the patch voiga turns (contact face at zeta =
    1); a new knot within 1e-12 of a coarse interior knot of that direction is the
    coarse knot (compared in the volume's own orientation)."""
    face = str(group.get("contact_face", "") or "")
    k = DIRECTIONS.index(vol.face_key(face)[:-1]) if face else 2
    order = [(k + 1) % 3, (k + 2) % 3, k]  # the turned patch's xi, eta, zeta
    linear = group.get("basis", "nurbs") == "linear"
    n, s = [], []
    for d, direction in zip(order, DIRECTIONS, strict=True):
        degree = 1 if linear else int(group.get(f"degree_{direction}", 2))
        count, distinct = _direction_functions(vol.knots[d], vol.degree[d], degree,
                                               _new_knots(group, direction), linear)
        n.append(count)
        s.append(distinct)
    q, elevations = int(group.get("layer_degree", 0) or 0), int(group.get("layer_elevations", 0) or 0)
    if q and face:
        m = [_direction_functions(vol.knots[d], vol.degree[d], q, _new_knots(group, direction),
                                  False)[0] + elevations * (s[i] + 1)
             for i, (d, direction) in enumerate(zip(order[:2], DIRECTIONS[:2], strict=True))]
        interface, bulk = 3 * m[0] * m[1], 3 * n[0] * n[1] * (n[2] - 1)
    elif face:
        interface, bulk = 3 * n[0] * n[1], 3 * n[0] * n[1] * (n[2] - 1)
    else:
        interface, bulk = 0, 3 * n[0] * n[1] * n[2]
    return {"interface": interface, "bulk": bulk, "total": interface + bulk}
