"""Small-strain line contact of a rigid flat and an elastic half-plane for a symmetric
convex profile: Hertz's parabola ``x^2 / (2 R)`` and the exact circle
``R - sqrt(R^2 - x^2)``, the second as a reference for cylinders whose a/R is not small.

For a gap profile h(x) and a frictionless contact on [-a, a] whose pressure vanishes at
both ends, the plane-strain solution is (Muskhelishvili's bounded solution)

    p(x) = E*/(2 pi) sqrt(a^2 - x^2) PV int_{-a}^{a} h'(s) / (sqrt(a^2 - s^2) (s - x)) ds.

With s = a cos(phi), x = a cos(psi) and the cosine series h'(a cos phi) = sum c_n cos(n phi)
(odd n for a symmetric profile), Glauert's integral
PV int_0^pi cos(n phi) / (cos phi - cos psi) dphi = pi sin(n psi) / sin(psi) gives

    p(a cos psi) = E*/2 sum_n c_n sin(n psi),      P = int p dx = pi E* a c_1 / 4.

Hertz's parabola has the single term c_1 = a / R: p = E* sqrt(a^2 - x^2) / (2 R),
P = pi E* a^2 / (4 R). The circle's h'(s) = s / sqrt(R^2 - s^2) adds the higher terms;
to first order P = pi E* a^2 / (4 R) (1 + 3 a^2 / (8 R^2)), so for a given P its zone is
narrower by about 3 a^2 / (16 R^2) (0.107 % at the committed a/R = 0.076).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

SERIES_POINTS = 2048
"""Midpoint points of the cosine coefficients' integrals (spectrally accurate: the
integrand is smooth and periodic for a < R)."""
SERIES_TERMS = 64
"""Odd terms kept (c_n falls like (a / 2R)^n: far below round-off for a < R / 2)."""


@dataclass(frozen=True)
class CircleContact:
    """The half-plane solution for the exact circular profile of radius ``radius``."""

    a: float
    """Half-width of the zone for the force."""
    e_star: float
    coefficients: np.ndarray
    """c_n of h'(a cos phi), n = 1, 3, 5, ..."""

    @property
    def p0(self) -> float:
        """Pressure at the centre."""
        return float(self.pressure(np.array([0.0]))[0])

    def pressure(self, x: np.ndarray) -> np.ndarray:
        """p(x) inside |x| < a, zero outside."""
        x = np.asarray(x, dtype=float)
        psi = np.arccos(np.clip(x / self.a, -1.0, 1.0))
        n = 2 * np.arange(len(self.coefficients)) + 1
        p = 0.5 * self.e_star * (self.coefficients @ np.sin(np.outer(n, psi)))
        return np.where(np.abs(x) < self.a, p, 0.0).reshape(x.shape)


def profile_coefficients(slope: Callable[[np.ndarray], np.ndarray], a: float) -> np.ndarray:
    """Cosine coefficients c_1, c_3, ... of ``slope(a cos phi)`` (an odd slope h')."""
    phi = (np.arange(SERIES_POINTS) + 0.5) * np.pi / SERIES_POINTS
    n = 2 * np.arange(SERIES_TERMS) + 1
    return 2.0 / SERIES_POINTS * (np.cos(np.outer(n, phi)) @ slope(a * np.cos(phi)))


def circle_coefficients(a: float, radius: float) -> np.ndarray:
    """:func:`profile_coefficients` of the circle, h'(s) = s / sqrt(R^2 - s^2)."""
    return profile_coefficients(lambda s: s / np.sqrt(radius**2 - s**2), a)


def circle_contact(force: float, e_star: float, radius: float) -> CircleContact:
    """The zone and pressure of the exact circle for the force per length ``force``."""
    a_hertz = np.sqrt(4.0 * force * radius / (np.pi * e_star))
    if not 0.0 < a_hertz < 0.5 * radius:
        raise ValueError(f"a = {a_hertz:.3g} is not in (0, R/2): no half-plane reference")

    def excess(a: float) -> float:
        return np.pi * e_star * a * circle_coefficients(a, radius)[0] / 4.0 - force

    a = brentq(excess, 0.5 * a_hertz, a_hertz, xtol=1e-15 * radius, rtol=4 * np.finfo(float).eps)
    return CircleContact(a=float(a), e_star=e_star, coefficients=circle_coefficients(a, radius))
