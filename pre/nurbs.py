"""NURBS containers in the voiga file layout, and conversion to/from splipy.

The containers store Cartesian control points and separate weights, with the
axis order of ``docs/formats.md`` as numpy sees it: a patch has
``control_points`` of shape ``(n_eta, n_xi, 2)`` and ``weights`` of shape
``(n_eta, n_xi)``.

splipy keeps *rational* control points in projective form: its
``controlpoints`` array is ``(n_xi, n_eta, 3)`` holding ``(w*x, w*y, w)``.
:func:`patch_to_splipy` / :func:`patch_from_splipy` (and the curve versions)
are the only places that translate between the two conventions; the test
suite checks them against an independent evaluation with scipy's B-splines.
All spline algorithms (order elevation, knot insertion, evaluation) are
splipy's.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import splipy

EDGE_KEYS: tuple[str, str, str, str] = ("xi0", "xi1", "eta0", "eta1")
"""Edge keys: ``xi = 0``, ``xi = 1``, ``eta = 0``, ``eta = 1``."""

KNOT_TOL = 1e-12
"""Two knot values closer than this are the same knot."""


@dataclass
class Patch:
    """A bivariate NURBS patch in the voiga layout (numpy axis order)."""

    degree: tuple[int, int]
    knots_xi: np.ndarray
    knots_eta: np.ndarray
    control_points: np.ndarray  # (n_eta, n_xi, 2), Cartesian
    weights: np.ndarray  # (n_eta, n_xi)
    edges: dict[str, str] = field(default_factory=dict)  # EDGE_KEYS -> name

    def __post_init__(self) -> None:
        self.degree = (int(self.degree[0]), int(self.degree[1]))
        self.knots_xi = np.asarray(self.knots_xi, dtype=float)
        self.knots_eta = np.asarray(self.knots_eta, dtype=float)
        self.control_points = np.asarray(self.control_points, dtype=float)
        self.weights = np.asarray(self.weights, dtype=float)
        n_eta, n_xi = self.weights.shape
        if self.control_points.shape != (n_eta, n_xi, 2):
            raise ValueError(f"control_points shape {self.control_points.shape} "
                             f"does not match weights {self.weights.shape}")
        if len(self.knots_xi) != n_xi + self.degree[0] + 1:
            raise ValueError("knots_xi length != n_xi + p_xi + 1")
        if len(self.knots_eta) != n_eta + self.degree[1] + 1:
            raise ValueError("knots_eta length != n_eta + p_eta + 1")

    @property
    def shape(self) -> tuple[int, int]:
        """``(n_eta, n_xi)``."""
        return self.weights.shape  # type: ignore[return-value]

    def edge_key(self, name: str) -> str:
        """The edge key (``'xi0'``...) of the edge called ``name``."""
        for key, value in self.edges.items():
            if value == name:
                return key
        raise KeyError(f"no edge named {name!r} (edges: {self.edges})")


@dataclass
class Curve:
    """A univariate NURBS curve in the voiga layout."""

    degree: int
    knots: np.ndarray
    control_points: np.ndarray  # (n, 2), Cartesian
    weights: np.ndarray  # (n,)

    def __post_init__(self) -> None:
        self.degree = int(self.degree)
        self.knots = np.asarray(self.knots, dtype=float)
        self.control_points = np.asarray(self.control_points, dtype=float)
        self.weights = np.asarray(self.weights, dtype=float)
        n = len(self.weights)
        if self.control_points.shape != (n, 2):
            raise ValueError("control_points must be (n, 2)")
        if len(self.knots) != n + self.degree + 1:
            raise ValueError("knots length != n + p + 1")


def _basis(degree: int, knots: np.ndarray) -> splipy.BSplineBasis:
    return splipy.BSplineBasis(order=degree + 1, knots=np.asarray(knots, dtype=float))


def patch_to_splipy(patch: Patch) -> splipy.Surface:
    """A rational splipy surface (projective control points) of ``patch``."""
    w = patch.weights.T[..., None]  # (n_xi, n_eta, 1)
    xy = patch.control_points.transpose(1, 0, 2)  # (n_xi, n_eta, 2)
    proj = np.concatenate([xy * w, w], axis=-1)
    return splipy.Surface(_basis(patch.degree[0], patch.knots_xi),
                          _basis(patch.degree[1], patch.knots_eta),
                          proj, rational=True, raw=True)


def patch_from_splipy(surface: splipy.Surface, edges: dict[str, str] | None = None) -> Patch:
    """Back from a splipy surface (rational or not) to a :class:`Patch`."""
    cp = np.asarray(surface.controlpoints, dtype=float)  # (n_xi, n_eta, d[+1])
    if surface.rational:
        w = cp[..., -1]
        xy = cp[..., :2] / w[..., None]
    else:
        w = np.ones(cp.shape[:2])
        xy = cp[..., :2]
    bx, be = surface.bases
    return Patch(degree=(bx.order - 1, be.order - 1),
                 knots_xi=np.array(bx.knots, dtype=float),
                 knots_eta=np.array(be.knots, dtype=float),
                 control_points=xy.transpose(1, 0, 2).copy(),
                 weights=w.T.copy(), edges=dict(edges or {}))


def curve_to_splipy(curve: Curve) -> splipy.Curve:
    """A rational splipy curve (projective control points) of ``curve``."""
    w = curve.weights[:, None]
    proj = np.concatenate([curve.control_points * w, w], axis=-1)
    return splipy.Curve(_basis(curve.degree, curve.knots), proj, rational=True, raw=True)


def curve_from_splipy(spline: splipy.Curve) -> Curve:
    """Back from a splipy curve to a :class:`Curve`."""
    cp = np.asarray(spline.controlpoints, dtype=float)
    if spline.rational:
        w = cp[:, -1]
        xy = cp[:, :2] / w[:, None]
    else:
        w = np.ones(len(cp))
        xy = cp[:, :2]
    b = spline.bases[0]
    return Curve(degree=b.order - 1, knots=np.array(b.knots, dtype=float),
                 control_points=xy.copy(), weights=w.copy())


def eta1_curve(patch: Patch) -> Curve:
    """The patch's ``eta = 1`` edge as a curve along xi (open knots: last row)."""
    return Curve(degree=patch.degree[0], knots=patch.knots_xi.copy(),
                 control_points=patch.control_points[-1].copy(),
                 weights=patch.weights[-1].copy())


def unique_knots(knots: np.ndarray, tol: float = KNOT_TOL) -> np.ndarray:
    """Distinct values of a non-decreasing knot vector (breakpoints)."""
    knots = np.asarray(knots, dtype=float)
    keep = np.concatenate([[True], np.diff(knots) > tol])
    return knots[keep]


def interior_breakpoints(knots: np.ndarray) -> np.ndarray:
    """Distinct knot values strictly inside the domain."""
    u = unique_knots(knots)
    return u[1:-1]


def evaluate_patch(patch: Patch, xi: np.ndarray, eta: np.ndarray) -> np.ndarray:
    """Points of ``patch`` at the parameter pairs ``(xi[i], eta[i])`` -> (n, 2)."""
    return np.asarray(patch_to_splipy(patch).evaluate(np.asarray(xi, float),
                                                      np.asarray(eta, float),
                                                      tensor=False))


def evaluate_curve(curve: Curve, t: np.ndarray) -> np.ndarray:
    """Points of ``curve`` at the parameters ``t`` -> (n, 2)."""
    return np.asarray(curve_to_splipy(curve).evaluate(np.asarray(t, float)))


def check_unit_domain(knots: np.ndarray, what: str = "knot vector") -> None:
    """Raise unless an open knot vector spans exactly [0, 1]."""
    if knots[0] != 0.0 or knots[-1] != 1.0:
        raise ValueError(f"{what} must span [0, 1], got [{knots[0]}, {knots[-1]}]")
