"""Cattaneo-Mindlin cases (``python -m pre cattaneo``): a half cylinder pressed onto a
flat or onto its mirror image, then sheared, against the analytic stick zone of a Hertz
line contact under a tangential load (Johnson, *Contact Mechanics*, 7.2; docs/verification.md).

Geometry: the lower half of an annulus, outer radius R, inner 0.05 R, centre (0, 0), in
three exact rational quadratic arcs of 60 degrees (joined at 240 and 300 degrees, so
that no knot of the coarse patch lies in the contact zone around 270 degrees). Masters:

- ``rigid``: the rigid line y = -R, moved sideways by ``rigid_ux`` in the shear phase;
- ``mirror``: the cylinder's mirror image about y = -R (the upper half of an annulus
  centred at (0, -2R)), of the same material: elastically similar bodies and, by the
  symmetry, no tangential traction from the press (normal and tangential tractions do
  not couple); its bottom cut moves sideways in the shear phase;
- ``block``: a block of the cylinder's material, ``[-L, L] x [-R - H, -R]`` with L = H =
  R/2, clamped at its bottom (also similar, but the block and the cylinder bulge
  differently under the press: a tangential traction of about 0.13 mu p0 remains after
  it, measured, docs/verification.md).

Mesh: arc elements of equal length ``h = a / elements_per_a`` over ``|x| <= 1.5 a`` (a the
expected half-width of :func:`pre.hertz.expected_half_width`), growing geometrically by
at most 1.2 beyond; the radial (and the block's vertical) elements grow from ``h`` at the
surface.

Loads: phase 1 (``press_steps``) moves the top cut (the two straight edges at y = 0)
down by the indentation d with u_x = 0 there; phase 2 (``shear_steps``) keeps it and
moves the master by ``shear`` in x. Coulomb friction ``friction`` in the shear phase and
``press_friction`` (default: the same) in the press: ``press_friction = 0`` is the
classical set-up of the test against a rigid flat, whose press with friction leaves a
stick traction no half-space theory neglects (docs/verification.md, "Cattaneo-Mindlin").
The automatic penalty unless ``penalty_normal`` is given.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from itertools import pairwise
from pathlib import Path
from typing import Any

import numpy as np

from .cases import GEOMETRY_FILE, to_namelist_text
from .files import check_output, write_text
from .h5io import write_geometry
from .hertz import MAX_INDENTATION, expected_half_width
from .layouts import parse_layout
from .meshes import arc_parameter_exact, geometric_sizes
from .nurbs import Patch
from .scenes import rectangle

R_IN = 0.05
"""Inner radius of the half annulus, relative to R (as the hertz scene's)."""
PIECE_SWEEP = 60.0
"""Sweep of each of the three arcs (degrees)."""
ZONE_FACTOR = 1.5
"""Elements of equal length cover |x| <= ZONE_FACTOR a."""
MAX_GROWTH = 1.2
"""Largest ratio of neighbouring element sizes where the mesh grades."""
BLOCK = (0.5, 0.5)
"""Half-length L and height H of the block, relative to R."""
MASTERS = ("rigid", "mirror", "block")


class CattaneoCaseError(ValueError):
    """A value ``python -m pre cattaneo`` refuses, or an output it will not overwrite."""


def arc_piece(centre: tuple[float, float], radius: float, a0: float,
              a1: float) -> tuple[np.ndarray, np.ndarray]:
    """Control points (3, 2) and weights (3,) of the exact rational quadratic arc from
    angle ``a0`` to ``a1`` (degrees, a sweep below 180): middle point at
    ``radius / cos(half sweep)`` on the bisector, weight ``cos(half sweep)``."""
    t0, t1 = math.radians(a0), math.radians(a1)
    half, mid = 0.5 * (t1 - t0), 0.5 * (t0 + t1)
    c = np.asarray(centre, float)
    pts = [c + radius * np.array([math.cos(t0), math.sin(t0)]),
           c + radius / math.cos(half) * np.array([math.cos(mid), math.sin(mid)]),
           c + radius * np.array([math.cos(t1), math.sin(t1)])]
    return np.array(pts), np.array([1.0, math.cos(half), 1.0])


def half_annulus(centre: tuple[float, float], radius: float, start: float) -> Patch:
    """Half an annulus (outer radius ``radius``, inner ``R_IN radius``) from angle
    ``start`` over 180 degrees counter-clockwise in three arcs; xi along the arcs, eta
    radial (degree 1), edges ``left`` (xi = 0), ``right``, ``inner``, ``outer``."""
    angles = [start + k * PIECE_SWEEP for k in range(4)]
    rows = []
    for r in (R_IN * radius, radius):
        pts: list[np.ndarray] = []
        wts: list[float] = []
        for k, (a0, a1) in enumerate(pairwise(angles)):
            p, w = arc_piece(centre, r, a0, a1)
            pts.extend(p if k == 0 else p[1:])
            wts.extend(w if k == 0 else w[1:])
        rows.append((np.array(pts), np.array(wts)))
    knots = [0.0] * 3 + [k / 3 for k in (1, 2) for _ in range(2)] + [1.0] * 3
    return Patch(degree=(2, 1), knots_xi=np.array(knots), knots_eta=np.array([0.0, 0.0, 1.0, 1.0]),
                 control_points=np.stack([rows[0][0], rows[1][0]]),
                 weights=np.stack([rows[0][1], rows[1][1]]),
                 edges={"xi0": "left", "xi1": "right", "eta0": "inner", "eta1": "outer"})


def graded_sizes(h: float, length: float) -> list[float]:
    """The fewest sizes that start at ``h``, grow by at most :data:`MAX_GROWTH` and fill
    ``length`` (``[length]`` when it is not longer than ``h``)."""
    if length <= h:
        return [length]
    n = 1
    while h * sum(MAX_GROWTH**k for k in range(n)) < length:
        n += 1
    return [float(s) for s in geometric_sizes(n, h, length)]


def arc_knots(radius: float, h: float, zone: float) -> list[float]:
    """Interior xi knots of :func:`half_annulus`: arc elements of length ``h`` over
    ``|x| <= zone`` around the middle of the middle arc, graded to its ends; the two
    side arcs in equal elements about as long as the middle arc's last ones."""
    sweep = math.radians(PIECE_SWEEP)
    dtheta = h / radius
    n_zone = max(1, math.ceil(math.asin(min(zone / radius, 1.0)) / dtheta))
    offsets = [dtheta * i for i in range(1, n_zone + 1)]          # from the middle
    rest = graded_sizes(dtheta, sweep / 2 - offsets[-1]) if offsets[-1] < sweep / 2 else []
    offsets += [offsets[-1] + float(g) for g in np.cumsum(rest)[:-1]]
    knots = {0.5, 1.0 / 3.0, 2.0 / 3.0}
    for off in offsets:
        for s in (-1.0, 1.0):
            phi = sweep / 2 + s * off
            if 0.0 < phi < sweep:
                knots.add((1.0 + arc_parameter_exact(phi, sweep)) / 3.0)
    n_side = max(1, math.ceil(sweep / (rest[-1] if rest else dtheta)))
    for j in range(1, n_side):
        knots.update({j / n_side / 3.0, (2.0 + j / n_side) / 3.0})
    return sorted(k for k in knots if 0.0 < k < 1.0)


def surface_graded_knots(thickness: float, h: float, surface_at_one: bool = True) -> list[float]:
    """Interior knots of a direction of length ``thickness`` (parameter proportional to
    length) graded from ``h`` at the contact surface: at eta = 1 (``surface_at_one``)
    or at eta = 0."""
    sizes = graded_sizes(h, thickness)
    cuts = list(np.cumsum(sizes)[:-1] / thickness)
    return sorted(1.0 - c for c in cuts) if surface_at_one else [float(c) for c in cuts]


def block_knots(half_length: float, h: float, zone: float) -> list[float]:
    """Interior x knots of the block ``[-L, L]``: length ``h`` over |x| <= zone, graded
    beyond."""
    n_zone = max(1, math.ceil(zone / h))
    pos = [h * i for i in range(1, n_zone + 1)]
    if pos[-1] < half_length:
        pos += [pos[-1] + float(g) for g in np.cumsum(graded_sizes(h, half_length - pos[-1]))[:-1]]
    xs = sorted({-p for p in pos if p < half_length} | {0.0} | {p for p in pos if p < half_length})
    return [(x + half_length) / (2 * half_length) for x in xs]


@dataclass(frozen=True)
class CattaneoScene:
    """A Cattaneo-Mindlin case (consistent units; see the module docstring)."""

    radius: float = 1.0
    youngs_modulus: float = 1.0
    poisson_ratio: float = 0.49
    indentation: float = 0.01
    friction: float = 0.3
    press_friction: float | None = None
    elements_per_a: float = 20.0
    master: str = "rigid"
    method: str | None = None
    layout: str = "NN2.2"
    shear: float = 3.5e-3
    press_steps: int = 20
    shear_steps: int = 20
    penalty_normal: float | None = None
    material: str = "linear"
    extra_contact: dict[str, Any] = field(default_factory=dict)

    def check(self) -> None:
        """CattaneoCaseError naming the first value out of range."""
        for name in ("radius", "youngs_modulus", "poisson_ratio", "indentation", "friction",
                     "elements_per_a", "shear"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v)):
                raise CattaneoCaseError(f"{name.replace('_', ' ')} {v!r} is not a finite number")
        if self.radius <= 0 or self.youngs_modulus <= 0:
            raise CattaneoCaseError("radius and youngs modulus must be > 0")
        if not -1.0 < self.poisson_ratio < 0.5:
            raise CattaneoCaseError(f"poisson ratio {self.poisson_ratio:g} must be in (-1, 0.5)")
        if not 0.0 < self.indentation < MAX_INDENTATION * self.radius:
            raise CattaneoCaseError(f"indentation {self.indentation:g} must be > 0 and < radius/10")
        if self.friction <= 0 or (self.press_friction is not None and not
                                  (math.isfinite(self.press_friction) and self.press_friction >= 0)):
            raise CattaneoCaseError("friction must be > 0 and press friction >= 0")
        if not 2.0 <= self.elements_per_a <= 200.0:
            raise CattaneoCaseError(f"elements per a {self.elements_per_a:g} must be in [2, 200]")
        if self.master not in MASTERS:
            raise CattaneoCaseError(f"master {self.master!r} must be one of {', '.join(MASTERS)}")
        if self.press_steps < 1 or self.shear_steps < 1:
            raise CattaneoCaseError("press and shear steps must be >= 1")
        try:
            parse_layout(self.layout)
        except ValueError as err:
            raise CattaneoCaseError(str(err)) from None

    @property
    def half_width(self) -> float:
        """The expected contact half-width a (of the rigid flat; the mirror's, whose
        two bodies share the approach, is close)."""
        return self.radius * expected_half_width(self.indentation / self.radius)

    @property
    def h(self) -> float:
        """Arc element length over the zone."""
        return self.half_width / self.elements_per_a


def _body(name: str, knots: tuple[list[float], list[float]], edge: str,
          scene: CattaneoScene) -> dict[str, Any]:
    lay = parse_layout(scene.layout)
    return {"name": name, "basis": lay.basis, "degree_xi": lay.degree_xi,
            "degree_eta": lay.degree_eta, "knots_xi": knots[0], "knots_eta": knots[1],
            "contact_edge": edge, "layer_degree": lay.layer_degree,
            "layer_elevations": lay.layer_elevations, "material": scene.material,
            "youngs_modulus": float(scene.youngs_modulus),
            "poisson_ratio": float(scene.poisson_ratio)}


def _fixed(body: str, edge: str, ux: list[float], uy: list[float]) -> dict[str, Any]:
    return {"body": body, "edge": edge, "fix_x": True, "fix_y": True, "ux": ux, "uy": uy}


def cattaneo_case(scene: CattaneoScene, output: str) -> tuple[dict[str, Any], dict[str, Patch]]:
    """The namelist groups and the coarse patches of ``scene``."""
    scene.check()
    r, h, d, s = scene.radius, scene.h, scene.indentation, scene.shear
    zone = ZONE_FACTOR * scene.half_width
    xi, eta = arc_knots(r, h, zone), surface_graded_knots((1 - R_IN) * r, h)
    bodies = {"cylinder": half_annulus((0.0, 0.0), r, 180.0)}
    groups: dict[str, Any] = {
        "case": {"title": f"cattaneo {scene.master} {scene.layout} h = a/{scene.elements_per_a:g}, "
                          f"nu = {scene.poisson_ratio:g}, mu = {scene.friction:g}",
                 "scene": "cattaneo", "geometry": GEOMETRY_FILE, "output": output,
                 "n_bodies": 1 if scene.master == "rigid" else 2},
        "body": [_body("cylinder", (xi, eta), "outer", scene)],
        "solver": {"n_steps": [scene.press_steps, scene.shear_steps]},
        "dirichlet": [_fixed("cylinder", e, [0.0, 0.0], [-d, -d]) for e in ("left", "right")],
    }
    friction: Any = float(scene.friction)
    if scene.press_friction is not None and scene.press_friction != scene.friction:
        friction = [float(scene.press_friction), float(scene.friction)]
    contact: dict[str, Any] = {"slave": "cylinder", "friction": friction}
    if scene.method is not None:
        contact["method"] = scene.method
    if scene.master == "rigid":
        contact.update(master="rigid", rigid_point=[0.0, -r], rigid_normal=[0.0, 1.0],
                       rigid_ux=[0.0, s], rigid_uy=[0.0, 0.0])
    elif scene.master == "mirror":
        bodies["mirror"] = half_annulus((0.0, -2.0 * r), r, 0.0)
        groups["body"].append(_body("mirror", (xi, eta), "outer", scene))
        groups["dirichlet"] += [_fixed("mirror", e, [0.0, s], [0.0, 0.0]) for e in ("left", "right")]
        contact["master"] = "mirror"
    else:
        length, height = BLOCK[0] * r, BLOCK[1] * r
        bodies["block"] = rectangle(-length, length, -r - height, -r,
                                    {"xi0": "left", "xi1": "right", "eta0": "bottom", "eta1": "top"})
        groups["body"].append(_body("block", (block_knots(length, h, zone),
                                              surface_graded_knots(height, h)), "top", scene))
        groups["dirichlet"].append(_fixed("block", "bottom", [0.0, s], [0.0, 0.0]))
        contact["master"] = "block"
    if scene.penalty_normal is not None:
        contact["penalty_normal"] = float(scene.penalty_normal)
    contact.update(scene.extra_contact)
    groups["contact"] = [contact]
    return groups, bodies


def case_stem(scene: CattaneoScene) -> str:
    """``rigid-NN2.2-a20``: master, layout, elements per a."""
    return f"{scene.master}-{scene.layout}-a{scene.elements_per_a:g}"


def write_cattaneo(scene: CattaneoScene, out: str | Path, force: bool = False,
                   stem: str | None = None) -> Path:
    """Write ``<stem>.nml`` and its geometry ``<stem>-geometry.h5`` into ``out`` (the
    stem: :func:`case_stem`); an existing file is refused (CattaneoCaseError) unless
    ``force``, and nothing is written then. Returns the case path."""
    stem = stem or case_stem(scene)
    folder = Path(out)
    case, geometry = folder / f"{stem}.nml", folder / f"{stem}-geometry.h5"
    for p in (case, geometry):
        check_output(p)
    clash = [str(p) for p in (case, geometry) if p.exists()]
    if clash and not force:
        raise CattaneoCaseError(" and ".join(clash) + (" exist" if len(clash) > 1 else " exists")
                                + "; nothing written (--force to overwrite)")
    groups, bodies = cattaneo_case(scene, f"{stem}.h5")
    groups["case"]["geometry"] = geometry.name
    folder.mkdir(parents=True, exist_ok=True)
    # each written beside its name and renamed in, never through a link (pre/files.py)
    write_geometry(geometry, "cattaneo", bodies, generator="voiga pre (python -m pre cattaneo)")
    write_text(case, to_namelist_text(groups))
    return case
