"""Bodies for any 2D problem: exact NURBS patches from simple shapes or from splipy
objects, checked and written as a geometry file the solver reads (``docs/formats.md``).

The Python API under ``python -m pre geometry`` (``docs/pre.md``):

- shapes: :func:`rectangle`, :func:`annular_sector` (any start and end angle),
  :func:`polygon` (four sides, each a chain of straight segments and circular arcs;
  a Coons patch, exact on its boundary);
- :func:`body` turns any splipy surface (e.g. from ``splipy.surface_factory`` or a
  GoTools ``.g2`` file, :func:`read_g2`) into a :class:`pre.nurbs.Patch` with named
  edges;
- :func:`check_patch` rejects what the solver cannot use (3D control points, a
  patch that folds over or degenerates, unnamed or repeated edges);
- rigid obstacles (``&contact master = 'rigid'``, ``rigid_curve``): curves without
  DOFs from :func:`obstacle_arc` (a cylinder or a round seat),
  :func:`obstacle_polyline` (a flat punch with rounded corners, a die profile) or
  :func:`obstacle` (any splipy curve), oriented counter-clockwise around the
  obstacle as the solver expects (the obstacle on the left of the curve);
- :func:`write_bodies` writes the geometry file (bodies and obstacle curves).

Every shape names its four sides; the names map onto the patch edges ``xi0``,
``xi1``, ``eta0``, ``eta1`` that the case file refers to by name. splipy does every
spline operation (arcs, Coons patches, reparametrization, file reading); this module
only chooses the inputs and checks the result.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import splipy
from splipy import curve_factory, surface_factory

from .h5io import write_geometry
from .nurbs import (
    EDGE_KEYS,
    Curve,
    Patch,
    curve_from_splipy,
    curve_to_splipy,
    evaluate_patch,
    patch_from_splipy,
    patch_to_splipy,
)
from .scenes import annular_sector as _quarter_sector
from .scenes import rectangle as _rectangle

Point = Sequence[float]

RECTANGLE_SIDES = {"bottom": "eta0", "right": "xi1", "top": "eta1", "left": "xi0"}
"""Side labels of a rectangle: xi along x, eta along y."""

SECTOR_SIDES = {"start": "xi0", "end": "xi1", "inner": "eta0", "outer": "eta1"}
"""Side labels of an annular sector: xi along the arcs (from the start angle to the
end angle), eta from the inner to the outer arc."""


def _named(sides: dict[str, str], names: dict[str, str] | None) -> dict[str, str]:
    """Edge key -> name, from side label -> edge key and label -> name (default:
    the label itself)."""
    names = dict(names or {})
    unknown = set(names) - set(sides)
    if unknown:
        raise ValueError(f"unknown side(s) {sorted(unknown)}; the sides are {list(sides)}")
    return {key: names.get(label, label) for label, key in sides.items()}


def rectangle(x: Sequence[float], y: Sequence[float], edges: dict[str, str] | None = None) -> Patch:
    """The rectangle ``[x0, x1] x [y0, y1]`` (bilinear); ``edges`` names its sides
    ``bottom``, ``right``, ``top``, ``left`` (default: those words)."""
    (x0, x1), (y0, y1) = x, y
    if not (x1 > x0 and y1 > y0):
        raise ValueError(f"rectangle: need x0 < x1 and y0 < y1, got x = {list(x)}, y = {list(y)}")
    return _rectangle(float(x0), float(x1), float(y0), float(y1), _named(RECTANGLE_SIDES, edges))


def _arc(centre: Point, radius: float, start_deg: float, end_deg: float) -> splipy.Curve:
    """Exact rational quadratic arc (pieces of at most 90 degrees) from ``start_deg`` to
    ``end_deg`` (counter-clockwise when end > start), parameter on [0, 1]."""
    sweep = math.radians(end_deg - start_deg)
    a0 = math.radians(start_deg)
    arc = curve_factory.circle_segment(abs(sweep), radius, center=(*centre, 0.0),
                                       xaxis=(math.cos(a0), math.sin(a0), 0.0),
                                       normal=(0.0, 0.0, 1.0 if sweep > 0 else -1.0))
    arc.set_dimension(2)
    arc.reparam()
    return arc


def annular_sector(centre: Point, r_in: float, r_out: float, angles: Sequence[float],
                   edges: dict[str, str] | None = None) -> Patch:
    """The region between two concentric arcs from ``angles[0]`` to ``angles[1]``
    (degrees, counter-clockwise when the second is larger; at most 360 apart);
    ``edges`` names its sides ``start``, ``end``, ``inner``, ``outer``. ``r_in = 0``:
    the solid sector (at most 180 degrees, :func:`solid_sector`)."""
    a0, a1 = float(angles[0]), float(angles[1])
    if not 0 <= r_in < r_out:
        raise ValueError(f"annular sector: need 0 <= r_in < r_out, got {r_in}, {r_out}")
    if a0 == a1 or not abs(a1 - a0) <= 360:
        raise ValueError(f"annular sector: angles {a0:g}, {a1:g}: a sector spans more than 0 and at most "
                         f"360 degrees ({abs(a1 - a0):g} given)")
    if r_in == 0:
        return solid_sector(centre, r_out, angles, edges)
    names = _named(SECTOR_SIDES, edges)
    if a0 % 90 == 0 and a1 % 90 == 0 and a1 > a0:  # the scenes' exact construction
        return _quarter_sector(centre, r_in, r_out, list(range(int(a0), int(a1) + 1, 90)), names)
    surface = surface_factory.edge_curves(_arc(centre, r_in, a0, a1), _arc(centre, r_out, a0, a1))
    surface.reparam()
    return patch_from_splipy(surface, names)


SOLID_CORE = 0.5
"""A solid sector's ``inner`` side runs along the two radii to this fraction of the
radius from the centre (its ``start`` and ``end`` sides are the rest of the radii)."""


def solid_sector(centre: Point, radius: float, angles: Sequence[float],
                 edges: dict[str, str] | None = None) -> Patch:
    """The solid circular sector (a half-disc for 180 degrees) from ``angles[0]`` to
    ``angles[1]`` (at most 180 apart), as one patch without a degenerate point: the
    arc is one side (``outer``: a contact edge), the radii are the other three,
    ``start`` and ``end`` from the arc to ``SOLID_CORE`` of the radius and ``inner``
    through the centre between them (a corner of the body inside that side, a C0
    line of the patch). A patch whose inner edge is collapsed to the centre would
    let its coincident control points move apart (a hole opens under load)."""
    a0, a1 = float(angles[0]), float(angles[1])
    sweep = a1 - a0
    if radius <= 0 or not 0 < abs(sweep) <= 180:
        raise ValueError(f"solid sector: need a radius > 0 and angles at most 180 degrees apart, got "
                         f"{radius}, {list(angles)} (a larger one: two bodies)")
    if sweep < 0:  # counter-clockwise from the smaller angle, the sides named alike
        a0, a1 = a1, a0
        names = dict(edges or {})
        names = {"start": names.get("end", "end"), "end": names.get("start", "start"),
                 **{k: v for k, v in names.items() if k not in ("start", "end")}}
    else:
        names = dict(edges or {})
    labels = _named(SECTOR_SIDES, names)
    c = np.asarray(centre, dtype=float)
    u0 = np.array([math.cos(math.radians(a0)), math.sin(math.radians(a0))])
    u1 = np.array([math.cos(math.radians(a1)), math.sin(math.radians(a1))])
    core = SOLID_CORE * radius
    sides = [_arc(c, radius, a0, a1),
             _segment(c + radius * u1, c + core * u1, None),
             _chain([_segment(c + core * u1, c, None), _segment(c, c + core * u0, None)]),
             _segment(c + core * u0, c + radius * u0, None)]
    order = ["outer", "end", "inner", "start"]
    surface = surface_factory.edge_curves(*sides)
    surface.reparam()
    patch = patch_from_splipy(surface)
    patch.edges = _match_edges(patch, sides, [labels[SECTOR_SIDES[label]] for label in order])
    return patch


def ellipse_sector(centre: Point, semi_axes: Sequence[float], angles: Sequence[float],
                   inner: float = 0.0, edges: dict[str, str] | None = None) -> Patch:
    """The region between the ellipse of ``semi_axes = [a, b]`` (along x and y) about
    ``centre`` and the same ellipse scaled by ``inner`` (0: solid, at most 180 degrees),
    from the parametric angle ``angles[0]`` to ``angles[1]`` (the point at angle t is
    ``centre + (a cos t, b sin t)``): the annular or solid sector of the unit circle,
    stretched (an affine map keeps a NURBS exact). Sides as :func:`annular_sector`."""
    a, b = (float(v) for v in semi_axes)
    if not (a > 0 and b > 0):
        raise ValueError(f"ellipse: semi_axes must be positive, got {list(semi_axes)}")
    if not 0 <= inner < 1:
        raise ValueError(f"ellipse: inner must lie in [0, 1), got {inner}")
    patch = annular_sector((0.0, 0.0), float(inner), 1.0, angles, edges)
    patch.control_points = patch.control_points * np.array([a, b]) + np.asarray(centre, dtype=float)
    return patch


def _segment(p: np.ndarray, q: np.ndarray, radius: float | None) -> splipy.Curve:
    """From ``p`` to ``q``: straight, or a circular arc of ``|radius|`` that bulges
    to the right of the direction of travel for ``radius > 0`` (outward on a
    counter-clockwise boundary), to the left for ``radius < 0``."""
    if radius is None:
        line = curve_factory.line(tuple(p), tuple(q))
        line.raise_order(1)
        line.reparam()
        return line
    chord = float(np.linalg.norm(q - p))
    r = abs(float(radius))
    if r < chord / 2:
        raise ValueError(f"arc of radius {r} cannot join points {chord:g} apart")
    mid = 0.5 * (p + q)
    d = (q - p) / chord
    left = np.array([-d[1], d[0]])
    h = math.sqrt(max(r * r - chord * chord / 4, 0.0))
    centre = mid + (h if radius > 0 else -h) * left  # bulge away from the centre
    a0 = math.degrees(math.atan2(*(p - centre)[::-1]))
    a1 = math.degrees(math.atan2(*(q - centre)[::-1]))
    # the centre lies left of the travel for radius > 0: the short way round is then
    # counter-clockwise, and clockwise for radius < 0
    sweep = (a1 - a0) % 360.0
    if radius < 0:
        sweep -= 360.0
    return _arc(centre, r, a0, a0 + sweep)


def _chain(pieces: list[splipy.Curve]) -> splipy.Curve:
    curve = pieces[0].clone()
    for piece in pieces[1:]:
        curve.append(piece.clone())
    curve.reparam()
    return curve


def polygon(points: Sequence[Point], corners: Sequence[int] | None = None,
            arcs: dict[int, float] | None = None, edges: Sequence[str] | None = None) -> Patch:
    """A body bounded by the closed polygon ``points`` (counter-clockwise), whose
    segment ``k`` (from point ``k`` to ``k + 1``) is a circular arc of signed radius
    ``arcs[k]`` (> 0 bulges outward). ``corners`` are the indices of the four points
    where the patch has its corners (default: the points, when there are four);
    side ``i`` runs from ``corners[i]`` to ``corners[i + 1]`` and is named
    ``edges[i]`` (default ``side0`` ... ``side3``). The interior is the Coons patch
    of the four sides (exact on the boundary); :func:`check_patch` rejects a patch
    that folds over."""
    pts = np.asarray(points, dtype=float)
    n = len(pts)
    if pts.ndim != 2 or pts.shape[1] != 2 or n < 4:
        raise ValueError("polygon: need at least 4 points [x, y]")
    corners = list(range(4)) if corners is None and n == 4 else list(corners or [])
    if len(corners) != 4 or sorted(corners) != corners or len(set(corners)) != 4 \
            or min(corners) < 0 or max(corners) >= n:
        raise ValueError(f"polygon: corners must be 4 increasing point indices, got {corners}")
    arcs = {int(k): float(r) for k, r in (arcs or {}).items()}
    if any(not 0 <= k < n for k in arcs):
        raise ValueError(f"polygon: arc segments must be in 0..{n - 1}")
    if enclosed_area(pts, arcs) <= 0:
        raise ValueError("polygon: give the points counter-clockwise")
    names = list(edges) if edges is not None else [f"side{i}" for i in range(4)]
    if len(names) != 4:
        raise ValueError("polygon: give 4 edge names")
    sides = []
    for i in range(4):
        a, b = corners[i], corners[(i + 1) % 4]
        idx = list(range(a, b)) if b > a else list(range(a, n)) + list(range(0, b))
        sides.append(_chain([_segment(pts[k], pts[(k + 1) % n], arcs.get(k)) for k in idx]))
    surface = surface_factory.edge_curves(*sides)
    surface.reparam()
    patch = patch_from_splipy(surface)
    patch.edges = _match_edges(patch, sides, names)
    return patch


def enclosed_area(points: np.ndarray, arcs: dict[int, float]) -> float:
    """Signed area (counter-clockwise > 0) of the closed polygon ``points`` whose segment
    ``k`` is a circular arc of signed radius ``arcs[k]`` (> 0 bulges to the right of the
    travel: outward on a counter-clockwise boundary): the straight polygon's area plus
    each arc's circular segment, so that a half-disc (two points and one arc) has one."""
    pts = np.asarray(points, dtype=float)
    area = 0.5 * float(np.sum(pts[:, 0] * np.roll(pts[:, 1], -1) - np.roll(pts[:, 0], -1) * pts[:, 1]))
    for k, radius in arcs.items():
        chord = float(np.linalg.norm(pts[(k + 1) % len(pts)] - pts[k]))
        r = abs(radius)
        if r < chord / 2:
            continue  # _segment refuses it, naming the radius
        theta = 2.0 * math.asin(min(1.0, chord / (2.0 * r)))
        area += math.copysign(0.5 * r * r * (theta - math.sin(theta)), radius)
    return area


def _edge_points(patch: Patch, key: str, t: np.ndarray) -> np.ndarray:
    one, zero = np.ones_like(t), np.zeros_like(t)
    xi, eta = {"xi0": (zero, t), "xi1": (one, t), "eta0": (t, zero), "eta1": (t, one)}[key]
    return evaluate_patch(patch, xi, eta)


def _match_edges(patch: Patch, sides: list[splipy.Curve], names: list[str]) -> dict[str, str]:
    """Name the patch edges after the side curves they coincide with."""
    t = np.linspace(0.0, 1.0, 7)
    out = {}
    for curve, name in zip(sides, names, strict=True):
        pts = np.asarray(curve(np.linspace(curve.start(0), curve.end(0), 7)))[:, :2]
        best = min(EDGE_KEYS, key=lambda k: min(np.abs(_edge_points(patch, k, t) - pts).max(),
                                                np.abs(_edge_points(patch, k, t)[::-1] - pts).max()))
        out[best] = name
    if len(out) != 4:
        raise ValueError("polygon: could not match the four sides to the patch edges")
    return out


def body(surface: splipy.Surface, edges: dict[str, str]) -> Patch:
    """A splipy surface as a body: 2D (a z coordinate must be zero), parameters
    rescaled to [0, 1]^2, ``edges`` naming ``xi0``, ``xi1``, ``eta0``, ``eta1``."""
    s = surface.clone()
    if s.dimension > 2:
        cp = np.asarray(s.controlpoints)
        z = cp[..., 2]
        if np.abs(z).max() > 1e-12 * max(1.0, np.abs(cp[..., :2]).max()):
            raise ValueError("the surface is not planar in z = 0")
        s.set_dimension(2)
    s.reparam()
    missing = set(EDGE_KEYS) - set(edges)
    if missing:
        raise ValueError(f"name every edge: missing {sorted(missing)}")
    return patch_from_splipy(s, {k: edges[k] for k in EDGE_KEYS})


def read_g2(path: str | Path) -> list[splipy.SplineObject]:
    """Every spline object of a GoTools ``.g2`` file (splipy's reader)."""
    from splipy.io import G2

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no .g2 file {path}")
    with G2(str(path)) as f:
        return list(f.read())


def jacobian_signs(patch: Patch, n: int = 24) -> np.ndarray:
    """det(dX/dxi, dX/deta) at ``n x n`` interior points (Gauss-like, off the edges)."""
    s = patch_to_splipy(patch)
    t = (np.arange(n) + 0.5) / n
    du = np.asarray(s.derivative(t, t, d=(1, 0)))[..., :2]
    dv = np.asarray(s.derivative(t, t, d=(0, 1)))[..., :2]
    return du[..., 0] * dv[..., 1] - du[..., 1] * dv[..., 0]


def check_patch(name: str, patch: Patch) -> None:
    """Raise ValueError naming ``name`` and the cause when the solver cannot use the
    patch: knots not on [0, 1], non-positive weights, unnamed or repeated edge names,
    or a map that folds over or degenerates (det J changes sign or vanishes inside)."""
    for what, knots in (("knots_xi", patch.knots_xi), ("knots_eta", patch.knots_eta)):
        if knots[0] != 0.0 or knots[-1] != 1.0:
            raise ValueError(f"body {name!r}: {what} must span [0, 1]")
    if np.any(patch.weights <= 0):
        raise ValueError(f"body {name!r}: weights must be positive")
    names = [patch.edges.get(k, "") for k in EDGE_KEYS]
    if any(not e for e in names) or len(set(names)) != 4:
        raise ValueError(f"body {name!r}: the four edges need four different names, got {names}")
    det = jacobian_signs(patch)
    scale = float(np.abs(det).max())
    if scale == 0 or not (np.all(det > 1e-10 * scale) or np.all(det < -1e-10 * scale)):
        raise ValueError(f"body {name!r}: the patch folds over or degenerates (the Jacobian "
                         "changes sign inside); choose other corners or split the body")


def edge_length(patch: Patch, key: str, n: int = 200) -> float:
    """Length of one edge of a patch (polyline of ``n`` points)."""
    pts = _edge_points(patch, key, np.linspace(0.0, 1.0, n))
    return float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())


SIDES = ("left", "right")
"""Which side of a polyline (in the order of its points) the obstacle lies on."""


def obstacle(spline: splipy.Curve, side: str = "left") -> Curve:
    """A splipy curve (planar, any parametrization) as the boundary of a rigid
    obstacle lying on its ``side`` ("left" or "right" of the direction of travel):
    parameter rescaled to [0, 1] and the direction reversed when needed, so that the
    obstacle is on the left as the solver expects (its outward normal is then
    ``(a_y, -a_x)/|a|``, ``a = dx/dxi``; docs/formats.md)."""
    if side not in SIDES:
        raise ValueError(f"side must be one of {SIDES}, got {side!r}")
    c = spline.clone()
    if c.dimension > 2:
        cp = np.asarray(c.controlpoints)
        if np.abs(cp[:, 2]).max() > 1e-12 * max(1.0, np.abs(cp[:, :2]).max()):
            raise ValueError("the curve is not planar in z = 0")
        c.set_dimension(2)
    if side == "right":
        c.reverse()
    c.reparam()
    return curve_from_splipy(c)


def obstacle_arc(centre: Point, radius: float, angles: Sequence[float], side: str = "inside") -> Curve:
    """A circular arc from ``angles[0]`` to ``angles[1]`` (degrees, at most 360
    apart) bounding a rigid obstacle: the disc (``side = "inside"``: a cylinder or a
    round punch) or what surrounds the circle (``"outside"``: a round seat or groove).
    The contact zone should not include the ends of the arc."""
    a0, a1 = float(angles[0]), float(angles[1])
    if not radius > 0 or a0 == a1 or not abs(a1 - a0) <= 360:
        raise ValueError(f"obstacle arc: need radius > 0 and angles that differ by more than 0 and at "
                         f"most 360 degrees, got {radius}, {list(angles)}")
    if side not in ("inside", "outside"):
        raise ValueError(f"obstacle arc: side must be 'inside' or 'outside', got {side!r}")
    lo, hi = min(a0, a1), max(a0, a1)
    # counter-clockwise with the disc on the left
    return obstacle(_arc(centre, radius, lo, hi), "left" if side == "inside" else "right")


def obstacle_ellipse(centre: Point, semi_axes: Sequence[float], angles: Sequence[float],
                     side: str = "inside") -> Curve:
    """An elliptical arc (``semi_axes = [a, b]``, parametric ``angles`` in degrees as
    :func:`ellipse_sector`) bounding a rigid obstacle: the ellipse's inside (the
    default) or its outside, as :func:`obstacle_arc`."""
    a, b = (float(v) for v in semi_axes)
    if not (a > 0 and b > 0):
        raise ValueError(f"obstacle ellipse: semi_axes must be positive, got {list(semi_axes)}")
    curve = obstacle_arc((0.0, 0.0), 1.0, angles, side)
    curve.control_points = curve.control_points * np.array([a, b]) + np.asarray(centre, dtype=float)
    return curve


def obstacle_polyline(points: Sequence[Point], side: str, arcs: dict[int, float] | None = None) -> Curve:
    """An open chain of straight segments through ``points`` (segment ``k`` from point
    ``k`` to ``k + 1``), segment ``k`` a circular arc of signed radius ``arcs[k]``
    (> 0 bulges to the right of the direction of travel, < 0 to the left; as for
    :func:`polygon`), bounding a rigid obstacle on its ``side`` ("left" or "right" of
    the direction of travel). Corners between straight segments are kinks (C0 knots)."""
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 2:
        raise ValueError("obstacle polyline: need at least 2 points [x, y]")
    arcs = {int(k): float(r) for k, r in (arcs or {}).items()}
    if any(not 0 <= k < len(pts) - 1 for k in arcs):
        raise ValueError(f"obstacle polyline: arc segments must be in 0..{len(pts) - 2}")
    if np.any(np.linalg.norm(np.diff(pts, axis=0), axis=1) == 0):
        raise ValueError("obstacle polyline: two consecutive points coincide")
    pieces = [_segment(pts[k], pts[k + 1], arcs.get(k)) for k in range(len(pts) - 1)]
    return obstacle(_chain(pieces), side)


def check_curve(name: str, curve: Curve) -> None:
    """Raise ValueError naming ``name`` and the cause when the solver cannot use the
    obstacle curve: knots not on [0, 1], non-positive weights, or a curve that stops
    (dx/dxi vanishing: no normal)."""
    if curve.knots[0] != 0.0 or curve.knots[-1] != 1.0:
        raise ValueError(f"curve {name!r}: knots must span [0, 1]")
    if np.any(curve.weights <= 0):
        raise ValueError(f"curve {name!r}: weights must be positive")
    spline = curve_to_splipy(curve)
    t = np.linspace(0.0, 1.0, 200)
    speed = np.linalg.norm(np.asarray(spline.derivative(t))[:, :2], axis=1)
    size = float(np.ptp(curve.control_points, axis=0).max())
    if size == 0 or speed.min() <= 1e-10 * size:
        raise ValueError(f"curve {name!r}: the curve stops somewhere (dx/dxi = 0): no normal there")


def write_bodies(path: str | Path, bodies: dict[str, Patch | splipy.Surface],
                 scene: str = "", units: str = "mm, N",
                 edges: dict[str, dict[str, str]] | None = None,
                 curves: dict[str, Curve] | None = None) -> Path:
    """Check every body and obstacle curve and write the geometry file; splipy
    surfaces are converted with :func:`body` (their edge names from
    ``edges[name]``). Returns the path."""
    patches = {}
    for name, b in bodies.items():
        patch = b if isinstance(b, Patch) else body(b, (edges or {}).get(name, {}))
        check_patch(name, patch)
        patches[name] = patch
    for name, c in (curves or {}).items():
        check_curve(name, c)
    path = Path(path)
    write_geometry(path, scene or path.stem, patches, units=units,
                   generator="voiga pre (python -m pre geometry)", curves=curves)
    return path
