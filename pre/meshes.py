"""Knot placement: uniform meshes, the graded Hertz mesh, and the exact
inversion of the rational quadratic circular-arc parametrization.

Arc parametrization. A rational quadratic arc of sweep ``2 a`` with middle
weight ``cos a`` maps its parameter ``t`` in [0, 1] to the angle ``theta``
(measured from the arc's middle) through

    tan(theta / 2) = tan(a / 2) * (2 t - 1),

so ``t = (1 + tan(theta / 2) / tan(a / 2)) / 2`` exactly. (Derivation: with
``u = 2 t - 1`` the Bernstein weights give ``tan theta = 2 sin a u /
((1 + cos a) - (1 - cos a) u^2)``, the tangent double-angle formula of
``tan(a/2) u``.)
"""

from __future__ import annotations

import math
from itertools import pairwise

import numpy as np
from scipy.optimize import brentq

HERTZ_A_EXP = 0.08
"""Expected Hertz contact half-width used for the grading (our choice)."""
HERTZ_R_IN = 0.05
HERTZ_R_OUT = 1.0
HERTZ_N_CONTACT = 5
"""m1 elements uniform in angle over [0, theta_c] from the lowest point."""
HERTZ_N_REST = 4
"""m1 elements uniform in angle over [theta_c, 90 deg]."""
HERTZ_RADIAL_CPS = 49
"""Control points across the radius, every mesh and layout."""
HERTZ_H_SURFACE = 0.005
"""Radial size of the element at the outer surface."""


def arc_parameter(phi: np.ndarray | float, sweep: float = math.pi / 2) -> np.ndarray:
    """Parameter of the point at angle ``phi`` from the arc's start, for one
    rational quadratic arc of angle ``sweep`` (< pi)."""
    phi = np.asarray(phi, dtype=float)
    half = sweep / 2
    return 0.5 * (1.0 + np.tan((phi - half) / 2) / math.tan(half / 2))


def arc_parameter_exact(phi: float, sweep: float = math.pi / 2) -> float:
    """Scalar :func:`arc_parameter` with Python's ``math`` (glibc libm).

    Knots written to the case files use this path: numpy may evaluate ``tan``
    with SIMD kernels whose last bit depends on the CPU, which would make the
    generated namelists differ between machines.
    """
    half = sweep / 2
    return 0.5 * (1.0 + math.tan((phi - half) / 2) / math.tan(half / 2))


def arc_angle(t: np.ndarray | float, sweep: float = math.pi / 2) -> np.ndarray:
    """Inverse of :func:`arc_parameter`: angle from the arc's start at ``t``."""
    t = np.asarray(t, dtype=float)
    half = sweep / 2
    return half + 2 * np.arctan(math.tan(half / 2) * (2 * t - 1))


def uniform_interior(n_el: int) -> np.ndarray:
    """``i / n_el`` for ``i = 1 .. n_el - 1`` (the uniform mesh's new knots)."""
    return np.array([i / n_el for i in range(1, n_el)])


def nest(breaks: np.ndarray, factor: int) -> np.ndarray:
    """Interior knots after splitting every span of ``[0, *breaks, 1]`` into
    ``factor`` equal parameter spans."""
    full = np.concatenate([[0.0], np.asarray(breaks, float), [1.0]])
    out = []
    for k0, k1 in pairwise(full):
        out.extend(k0 + (k1 - k0) * j / factor for j in range(factor))
    return np.array(out[1:])


def mesh_level(mesh: str) -> int:
    """``'m3'`` -> 3."""
    if not (mesh.startswith("m") and mesh[1:].isdigit()):
        raise ValueError(f"mesh name must be m<k>, got {mesh!r}")
    return int(mesh[1:])


def hertz_theta_c(a_exp: float = HERTZ_A_EXP) -> float:
    """Angle from the lowest point covered by the fine grading: asin(1.5 a)."""
    return math.asin(1.5 * a_exp / HERTZ_R_OUT)


def hertz_m1_angles(a_exp: float = HERTZ_A_EXP) -> np.ndarray:
    """Interior breakpoint angles (from the lowest point) of the m1 arc mesh."""
    tc = hertz_theta_c(a_exp)
    fine = [tc * i / HERTZ_N_CONTACT for i in range(1, HERTZ_N_CONTACT + 1)]
    coarse = [tc + (math.pi / 2 - tc) * j / HERTZ_N_REST for j in range(1, HERTZ_N_REST)]
    return np.array(fine + coarse)


def graded_angles(theta_c: float, n_fine: int, n_rest: int,
                  sweep: float = math.pi / 2) -> list[float]:
    """Interior breakpoint angles (from the arc's start) of an arc of ``sweep``:
    ``n_fine`` elements uniform in angle over [0, theta_c], then ``n_rest`` growing
    geometrically from that size to the arc's end (uniform when they cannot grow). The
    2D hertz mesh (:func:`hertz_m1_angles`) keeps its uniform coarse part."""
    h = theta_c / n_fine
    fine = [theta_c * i / n_fine for i in range(1, n_fine + 1)]
    rest = sweep - theta_c
    sizes = (geometric_sizes(n_rest, h, rest) if n_rest * h < rest
             else np.full(n_rest, rest / n_rest))
    coarse = [theta_c + float(s) for s in np.cumsum(sizes)[:-1]]
    return fine + coarse


def hertz_xi_knots(level: int, a_exp: float = HERTZ_A_EXP) -> np.ndarray:
    """Interior arc knots of hertz mesh m<level>: the m1 angles mapped to the
    arc parameter, every m1 span split into 2^(level-1) equal spans."""
    breaks = np.array([arc_parameter_exact(float(a)) for a in hertz_m1_angles(a_exp)])
    return nest(breaks, 2 ** (level - 1))


def geometric_sizes(n_el: int, h_min: float, length: float) -> np.ndarray:
    """Element sizes ``h_min * r^k`` (k = 0 .. n_el - 1) summing to ``length``."""
    if n_el * h_min > length:
        raise ValueError("h_min too large for a growing grading")
    if math.isclose(n_el * h_min, length):
        return np.full(n_el, length / n_el)

    def excess(r: float) -> float:
        return h_min * sum(r ** k for k in range(n_el)) - length
    r = brentq(excess, 1.0 + 1e-14, 10.0, xtol=1e-15, rtol=4 * np.finfo(float).eps)
    return np.array([h_min * r ** k for k in range(n_el)])  # Python pow: machine-independent


def hertz_eta_knots(n_el: int, h_surface: float = HERTZ_H_SURFACE,
                    thickness: float = HERTZ_R_OUT - HERTZ_R_IN) -> np.ndarray:
    """Interior radial knots: ``n_el`` elements graded geometrically toward the
    outer surface (``eta = 1``), smallest radial size ``h_surface`` across a wall of
    ``thickness`` (the hertz annulus's 0.95; a solid ball's radius: 1)."""
    sizes = geometric_sizes(n_el, h_surface / thickness, 1.0)  # parameter sizes
    # from eta = 1 inward: 1 - cumulative size; the last one (eta = 0) is dropped
    inner, acc = [], 0.0
    for h in sizes[:-1]:
        acc += float(h)
        inner.append(1.0 - acc)
    return np.array(inner[::-1])


def hertz_radial_elements(degree_eta: int) -> int:
    """Radial elements giving :data:`HERTZ_RADIAL_CPS` control points."""
    return HERTZ_RADIAL_CPS - degree_eta
