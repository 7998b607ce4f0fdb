"""Cattaneo-Mindlin cases (``python -m pre cattaneo``): a half cylinder pressed onto a
flat, then sheared by a tangential displacement of the flat, against the analytic stick
zone of a Hertz line contact under a tangential load (Johnson, *Contact Mechanics*, 7.2).

Geometry: the lower half of an annulus, outer radius R, inner 0.05 R, centre (0, 0), in
three exact rational quadratic arcs of 60 degrees (joined at 240 and 300 degrees, so
that no knot of the coarse patch lies in the contact zone around 270 degrees). The flat
is either the rigid line y = -R (``master = 'rigid'``) or a block of the cylinder's
material ``[-L, L] x [-R - H, -R]`` (``master = 'block'``, elastically similar bodies:
normal and tangential tractions do not couple).

Mesh: arc elements of equal length ``h`` over ``|x| <= ZONE_FACTOR a`` (a the expected
half-width of :func:`pre.hertz.expected_half_width`), growing geometrically beyond; the
radial (and the block's vertical) elements grow geometrically from ``h`` at the surface;
the block has elements of length ``h`` under the zone too.

Loads: phase 1 (``press_steps``) moves the top cut (the two straight edges at y = 0)
down by the indentation d, u_x = 0 there; phase 2 (``shear_steps``) keeps the cut where
it is and moves the flat by ``shear`` in x (the rigid line by ``rigid_ux``, the block by
u_x of its bottom). Coulomb friction mu, the automatic penalty unless given.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .cases import to_namelist_text
from .h5io import write_geometry
from .hertz import expected_half_width
from .layouts import parse_layout
from .meshes import arc_parameter_exact, geometric_sizes
from .nurbs import Patch
from .scenes import rectangle

R_IN = 0.05
"""Inner radius of the half annulus, relative to R (as the hertz scene's)."""
PIECE_ANGLES = (180.0, 240.0, 300.0, 360.0)
"""Break angles of the three arcs (degrees)."""
ZONE_FACTOR = 1.5
"""Elements of equal length cover |x| <= ZONE_FACTOR a."""
MAX_GROWTH = 1.2
"""Largest ratio of neighbouring element sizes where the mesh grades."""
BLOCK = (0.5, 0.5)
"""Half-length L and height H of the block, relative to R."""


class CattaneoCaseError(ValueError):
    """A value ``python -m pre cattaneo`` refuses."""


def arc_piece(centre: tuple[float, float], radius: float, a0: float,
              a1: float) -> tuple[np.ndarray, np.ndarray]:
    """Control points (3, 2) and weights (3,) of the exact rational quadratic arc from
    angle ``a0`` to ``a1`` (degrees, a sweep below 180)."""
    t0, t1 = math.radians(a0), math.radians(a1)
    half = 0.5 * (t1 - t0)
    mid = 0.5 * (t0 + t1)
    c = np.asarray(centre, float)
    pts = [c + radius * np.array([math.cos(t0), math.sin(t0)]),
           c + radius / math.cos(half) * np.array([math.cos(mid), math.sin(mid)]),
           c + radius * np.array([math.cos(t1), math.sin(t1)])]
    return np.array(pts), np.array([1.0, math.cos(half), 1.0])


def half_annulus(radius: float) -> Patch:
    """The lower half annulus (xi along the arcs from 180 to 360 degrees, eta radial)."""
    rows = []
    for r in (R_IN * radius, radius):
        pts, wts = [], []
        for k, (a0, a1) in enumerate(zip(PIECE_ANGLES[:-1], PIECE_ANGLES[1:])):
            p, w = arc_piece((0.0, 0.0), r, a0, a1)
            pts.extend(p if k == 0 else p[1:])
            wts.extend(w if k == 0 else w[1:])
        rows.append((np.array(pts), np.array(wts)))
    n = len(PIECE_ANGLES) - 1
    knots = [0.0] * 3 + [k / n for k in range(1, n) for _ in range(2)] + [1.0] * 3
    return Patch(degree=(2, 1), knots_xi=np.array(knots), knots_eta=np.array([0.0, 0.0, 1.0, 1.0]),
                 control_points=np.stack([rows[0][0], rows[1][0]]),
                 weights=np.stack([rows[0][1], rows[1][1]]),
                 edges={"xi0": "left", "xi1": "right", "eta0": "inner", "eta1": "outer"})


def graded_sizes(h: float, length: float) -> list[float]:
    """Sizes starting at ``h`` and growing by at most :data:`MAX_GROWTH` that fill
    ``length`` (the fewest elements that do)."""
    if length <= h:
        return [length]
    n = 1
    while h * sum(MAX_GROWTH**k for k in range(n)) < length:
        n += 1
    return [float(s) for s in geometric_sizes(n, h, length)]


def arc_knots(radius: float, h: float, zone: float) -> list[float]:
    """Interior xi knots of the half annulus: arc elements of length ``h`` over
    ``|x| <= zone`` around the lowest point, graded beyond, up to the piece breaks."""
    n_zone = max(1, math.ceil(math.asin(min(zone / radius, 1.0)) * radius / h))
    dtheta = h / radius
    inner = [dtheta * i for i in range(1, n_zone + 1)]          # from 270 degrees
    piece = math.radians(PIECE_ANGLES[2] - 270.0)
    grown = np.cumsum(graded_sizes(dtheta * 1.0, piece - inner[-1]))
    offsets = inner + [inner[-1] + float(g) for g in grown[:-1]]
    n = len(PIECE_ANGLES) - 1
    sweep = math.radians(PIECE_ANGLES[1] - PIECE_ANGLES[0])
    knots = []
    for s in (-1.0, 1.0):
        for off in offsets:
            phi = sweep / 2 + s * off       # angle from the middle piece's start
            if 0.0 < phi < sweep:
                knots.append((1 + arc_parameter_exact(phi, sweep)) / n)
    knots.append(0.5)
    # the side pieces: as many equal elements as the last graded size allows
    last = float(graded_sizes(dtheta, piece - inner[-1])[-1]) if piece > inner[-1] else dtheta
    n_side = max(1, math.ceil(sweep / last))
    for j in range(1, n_side):
        knots.append(j / n_side / n)
        knots.append((2 + j / n_side) / n)
    return sorted(k for k in knots if 0.0 < k < 1.0)


def radial_knots(thickness: float, h: float) -> list[float]:
    """Interior knots of a degree-1 direction of ``thickness`` graded from ``h`` at
    eta = 1 (the contact surface) inward."""
    sizes = graded_sizes(h, thickness)
    acc, out = 0.0, []
    for s in sizes[:-1]:
        acc += s
        out.append(1.0 - acc / thickness)
    return sorted(out)


def block_knots(half_length: float, h: float, zone: float) -> list[float]:
    """Interior x knots of the block ``[-L, L]``: length ``h`` over |x| <= zone, graded
    beyond."""
    n_zone = max(1, math.ceil(zone / h))
    pos = [h * i for i in range(1, n_zone + 1)]
    grown = np.cumsum(graded_sizes(h, half_length - pos[-1]))
    pos += [pos[-1] + float(g) for g in grown[:-1]]
    xs = sorted([-p for p in pos] + [0.0] + pos)
    return [(x + half_length) / (2 * half_length) for x in xs]


@dataclass(frozen=True)
class CattaneoScene:
    """A Cattaneo-Mindlin case (consistent units)."""

    radius: float = 1.0
    youngs_modulus: float = 1.0
    poisson_ratio: float = 0.49
    indentation: float = 0.01
    friction: float = 0.3
    press_friction: float | None = None
    elements_per_a: float = 20.0
    master: str = "rigid"
    method: str = "gpts"
    layout: str = "NN2.2"
    shear: float = 2.0e-3
    press_steps: int = 20
    shear_steps: int = 20
    penalty_normal: float | None = None
    material: str = "linear"

    @property
    def half_width(self) -> float:
        """The expected contact half-width a."""
        return self.radius * expected_half_width(self.indentation / self.radius)

    @property
    def h(self) -> float:
        return self.half_width / self.elements_per_a


def _body(name: str, layout: str, knots: tuple[list[float], list[float]], edge: str,
          scene: CattaneoScene) -> dict[str, Any]:
    lay = parse_layout(layout)
    return {"name": name, "basis": lay.basis, "degree_xi": lay.degree_xi,
            "degree_eta": lay.degree_eta, "knots_xi": knots[0], "knots_eta": knots[1],
            "contact_edge": edge, "layer_degree": lay.layer_degree,
            "layer_elevations": lay.layer_elevations, "material": scene.material,
            "youngs_modulus": float(scene.youngs_modulus),
            "poisson_ratio": float(scene.poisson_ratio)}


def cattaneo_case(scene: CattaneoScene, output: str) -> tuple[dict[str, Any], dict[str, Patch]]:
    """The namelist groups and the coarse patches of ``scene``."""
    r, h, a = scene.radius, scene.h, scene.half_width
    zone = ZONE_FACTOR * a
    bodies = {"cylinder": half_annulus(r)}
    cyl = _body("cylinder", scene.layout, (arc_knots(r, h, zone), radial_knots((1 - R_IN) * r, h)),
                "outer", scene)
    groups: dict[str, Any] = {
        "case": {"title": f"cattaneo {scene.master} {scene.layout} h = a/{scene.elements_per_a:g}",
                 "scene": "cattaneo", "geometry": "geometry.h5", "output": output,
                 "n_bodies": 1 if scene.master == "rigid" else 2},
        "body": [cyl],
        "solver": {"n_steps": [scene.press_steps, scene.shear_steps]},
        "dirichlet": [{"body": "cylinder", "edge": e, "fix_x": True, "fix_y": True,
                       "ux": [0.0, 0.0], "uy": [-scene.indentation, -scene.indentation]}
                      for e in ("left", "right")],
    }
    friction: Any = scene.friction
    if scene.press_friction is not None and scene.press_friction != scene.friction:
        friction = [float(scene.press_friction), float(scene.friction)]
    contact: dict[str, Any] = {"slave": "cylinder", "friction": friction, "method": scene.method}
    if scene.master == "rigid":
        contact.update(master="rigid", rigid_point=[0.0, -r], rigid_normal=[0.0, 1.0],
                       rigid_ux=[0.0, scene.shear], rigid_uy=[0.0, 0.0])
    elif scene.master == "block":
        length, height = BLOCK[0] * r, BLOCK[1] * r
        bodies["block"] = rectangle(-length, length, -r - height, -r,
                                    {"xi0": "left", "xi1": "right", "eta0": "bottom", "eta1": "top"})
        groups["body"].append(_body("block", scene.layout,
                                    (block_knots(length, h, zone), radial_knots(height, h)), "top", scene))
        groups["dirichlet"].append({"body": "block", "edge": "bottom", "fix_x": True, "fix_y": True,
                                    "ux": [0.0, scene.shear], "uy": [0.0, 0.0]})
        contact["master"] = "block"
    else:
        raise CattaneoCaseError(f"master {scene.master!r}: 'rigid' or 'block'")
    if scene.penalty_normal is not None:
        contact["penalty_normal"] = float(scene.penalty_normal)
    groups["contact"] = [contact]
    return groups, bodies


def write_cattaneo(scene: CattaneoScene, out: str | Path, stem: str) -> Path:
    """Write ``geometry.h5`` and ``<stem>.nml`` into ``out``; the case path."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    groups, bodies = cattaneo_case(scene, f"{stem}.h5")
    write_geometry(out / "geometry.h5", "cattaneo", bodies)
    path = out / f"{stem}.nml"
    path.write_text(to_namelist_text(groups))
    return path
