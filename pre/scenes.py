"""Exact coarse NURBS patches of the benchmark scenes.

Every body is one patch with its contact edge at ``eta = 1`` and ``xi`` running
along that edge; the four edges are named (see :data:`pre.nurbs.EDGE_KEYS`).
Arcs are exact rational quadratic quarter arcs (middle weight ``sqrt(1/2)``);
the radial direction of annular bodies is degree 1, so ``eta`` is the radius
fraction ``(r - r_in) / (r_out - r_in)``.

Values (``docs/pre.md`` and ``docs/benchmarks.md`` section 3):

* ironing: die = lower half annulus, R_out 3, R_in 2, centre (2.5, 3) so the
  lowest outer point is (2.5, 0); slab = [0, 9] x [-3, 0].
* hertz: quarter annulus R_out 1, R_in 0.05, centre (0, 0), from the lowest
  point (0, -1) to (1, 0).
* rings: right half rings; upper R 1 / 0.8 centre (0, 1), lower R 1.5 / 1.2
  centre (0, -1.5); they touch at (0, 0).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from itertools import pairwise

import numpy as np

from .nurbs import Patch

W45 = math.sqrt(0.5)
"""Middle weight of an exact rational quadratic 90-degree arc (cos 45 deg)."""

# Unit directions at multiples of 90 degrees, kept as exact integers.
_DIRS: dict[int, tuple[int, int]] = {0: (1, 0), 90: (0, 1), 180: (-1, 0), 270: (0, -1)}


def _direction(angle_deg: int) -> np.ndarray:
    return np.array(_DIRS[angle_deg % 360], dtype=float)


def arc_row(centre: Sequence[float], radius: float, angles_deg: Sequence[int]) -> tuple[np.ndarray, np.ndarray]:
    """Control points and weights of consecutive exact quarter arcs.

    ``angles_deg`` are the (multiple of 90) angles of the arc's breakpoints,
    consecutive entries 90 degrees apart, in the direction of travel.
    Returns ``(points (2 n + 1, 2), weights (2 n + 1,))`` for ``n`` quarters.
    """
    c = np.asarray(centre, dtype=float)
    pts: list[np.ndarray] = []
    wts: list[float] = []
    for k, (a0, a1) in enumerate(pairwise(angles_deg)):
        if abs(a1 - a0) != 90 or a0 % 90:
            raise ValueError("arc_row needs breakpoints at multiples of 90 deg, 90 deg apart")
        d0, d1 = _direction(a0), _direction(a1)
        if k == 0:
            pts.append(c + radius * d0)
            wts.append(1.0)
        pts.append(c + radius * (d0 + d1))  # corner of the control triangle
        wts.append(W45)
        pts.append(c + radius * d1)
        wts.append(1.0)
    return np.array(pts), np.array(wts)


def quarter_arc_knots(n_quarters: int) -> np.ndarray:
    """Open quadratic knot vector of ``n_quarters`` C0-joined arcs on [0, 1]."""
    inner = [k / n_quarters for k in range(1, n_quarters) for _ in range(2)]
    return np.array([0.0] * 3 + inner + [1.0] * 3)


def annular_sector(centre: Sequence[float], r_in: float, r_out: float,
                   angles_deg: Sequence[int], edges: dict[str, str]) -> Patch:
    """Annular sector: xi along the arcs (quarter arcs at ``angles_deg``),
    eta radial and degree 1, ``eta = 0`` inner arc, ``eta = 1`` outer arc."""
    p_in, w_in = arc_row(centre, r_in, angles_deg)
    p_out, w_out = arc_row(centre, r_out, angles_deg)
    return Patch(degree=(2, 1),
                 knots_xi=quarter_arc_knots(len(angles_deg) - 1),
                 knots_eta=np.array([0.0, 0.0, 1.0, 1.0]),
                 control_points=np.stack([p_in, p_out]),
                 weights=np.stack([w_in, w_out]),
                 edges=dict(edges))


def rectangle(x0: float, x1: float, y0: float, y1: float, edges: dict[str, str]) -> Patch:
    """Bilinear rectangle, xi along x, eta along y (``eta = 1`` is the top)."""
    cp = np.array([[[x0, y0], [x1, y0]], [[x0, y1], [x1, y1]]], dtype=float)
    return Patch(degree=(1, 1), knots_xi=np.array([0.0, 0.0, 1.0, 1.0]),
                 knots_eta=np.array([0.0, 0.0, 1.0, 1.0]),
                 control_points=cp, weights=np.ones((2, 2)), edges=dict(edges))


# ---------------------------------------------------------------- scenes

IRONING_DIE = {"centre": (2.5, 3.0), "r_in": 2.0, "r_out": 3.0}
IRONING_SLAB = {"x0": 0.0, "x1": 9.0, "y0": -3.0, "y1": 0.0}
HERTZ = {"centre": (0.0, 0.0), "r_in": 0.05, "r_out": 1.0}
RINGS_UPPER = {"centre": (0.0, 1.0), "r_in": 0.8, "r_out": 1.0}
RINGS_LOWER = {"centre": (0.0, -1.5), "r_in": 1.2, "r_out": 1.5}


def ironing() -> dict[str, Patch]:
    """Die (lower half annulus, two quarter arcs, 180 -> 360 deg) and slab."""
    die = annular_sector(IRONING_DIE["centre"], IRONING_DIE["r_in"], IRONING_DIE["r_out"],
                         [180, 270, 360],
                         {"xi0": "left", "xi1": "right", "eta0": "inner", "eta1": "outer"})
    slab = rectangle(**IRONING_SLAB,
                     edges={"xi0": "left", "xi1": "right", "eta0": "bottom", "eta1": "top"})
    return {"die": die, "slab": slab}


def hertz() -> dict[str, Patch]:
    """Quarter annulus from the lowest point (0, -1) to (1, 0): one exact arc."""
    cyl = annular_sector(HERTZ["centre"], HERTZ["r_in"], HERTZ["r_out"], [270, 360],
                         {"xi0": "symmetry", "xi1": "top", "eta0": "inner", "eta1": "outer"})
    return {"cylinder": cyl}


def rings() -> dict[str, Patch]:
    """Right half rings, xi from the bottom (-90 deg) to the top (+90 deg)."""
    edges = {"xi0": "bottom", "xi1": "top", "eta0": "inner", "eta1": "outer"}
    upper = annular_sector(RINGS_UPPER["centre"], RINGS_UPPER["r_in"], RINGS_UPPER["r_out"],
                           [270, 360, 450], edges)
    lower = annular_sector(RINGS_LOWER["centre"], RINGS_LOWER["r_in"], RINGS_LOWER["r_out"],
                           [270, 360, 450], edges)
    return {"upper": upper, "lower": lower}


SCENES: dict[str, Callable[[], dict[str, Patch]]] = {
    "ironing": ironing,
    "ironing-deep": ironing,
    "hertz": hertz,
    "rings": rings,
}
"""Scene name -> builder of its bodies (ordered: the case files keep this order)."""


def scene_bodies(scene: str) -> dict[str, Patch]:
    """The coarse patches of ``scene`` (a fresh copy each call)."""
    try:
        return SCENES[scene]()
    except KeyError:
        raise KeyError(f"unknown scene {scene!r}; known: {sorted(SCENES)}") from None
