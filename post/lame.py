"""Lamé's solution of a thick spherical shell under internal pressure (linear elasticity,
small strain), and the relative L2 errors of a discrete solution against it.

The shell ``a <= r <= b`` (centre at the origin) carries the pressure ``p`` on its inner
sphere; the outer sphere is free. The displacement is radial, ``u = u_r(r) x / r``, with

    u_r(r) = A r + B / r^2,
    A = p a^3 (1 - 2 nu) / (E (b^3 - a^3)),      B = p a^3 b^3 (1 + nu) / (2 E (b^3 - a^3)),

so that the strains are ``eps_rr = du_r/dr = A - 2 B / r^3`` and
``eps_tt = eps_pp = u_r / r = A + B / r^3``, and Hooke's law (bulk modulus
``K = E / (3 (1 - 2 nu))``, shear modulus ``G = E / (2 (1 + nu))``) gives

    sigma_rr(r) = 3 K A - 4 G B / r^3 = p a^3 / (b^3 - a^3) (1 - b^3 / r^3),
    sigma_tt(r) = sigma_pp(r) = 3 K A + 2 G B / r^3 = p a^3 / (b^3 - a^3) (1 + b^3 / (2 r^3)),

with ``sigma_rr(a) = -p`` and ``sigma_rr(b) = 0``. In Cartesian components, with the unit
normal ``n = x / r``: ``sigma = sigma_tt I + (sigma_rr - sigma_tt) n n^T``.

The error measures, over a domain ``Omega`` (the shell octant ``x, y, z >= 0``, or its
discrete image: a mesh's elements integrated with their own Jacobians):

    e_u = ||u_h - u||_L2 / ||u||_L2,          ||v||_L2^2 = int_Omega |v|^2 dV,
    e_sigma = ||sigma_h - sigma||_L2 / ||sigma||_L2,   ||s||_L2^2 = int_Omega s : s dV,

``s : s`` the squared Frobenius norm of the 3 x 3 tensor, ``|v|`` the Euclidean norm.
Both integrals of a ratio use the same quadrature points and weights.

Over the exact octant (solid angle ``pi / 2``) the norms of the exact solution are

    ||u||^2 = pi/2 int_a^b u_r^2 r^2 dr = pi/2 (A^2 (b^5 - a^5) / 5 + A B (b^2 - a^2) + B^2 (1/a - 1/b)),
    ||sigma||^2 = pi/2 int_a^b (sigma_rr^2 + 2 sigma_tt^2) r^2 dr
                = pi/2 (c1^2 (b^3 - a^3) + c2^2 (a^-3 - b^-3) / 2),   c1 = 3 K A, c2 = 4 G B.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

Field = Callable[[np.ndarray], np.ndarray]
"""A field given by a function of points ``(n, 3)``: vectors ``(n, 3)`` or tensors
``(n, 3, 3)``."""


@dataclass(frozen=True)
class LameShell:
    """The thick spherical shell ``a <= r <= b`` under internal pressure ``p`` (Young's
    modulus ``E``, Poisson's ratio ``nu``), centre at the origin."""

    a: float = 1.0
    b: float = 2.0
    p: float = 1.0
    E: float = 1.0
    nu: float = 0.3

    def __post_init__(self) -> None:
        if not 0 < self.a < self.b:
            raise ValueError(f"need 0 < a < b, got a = {self.a}, b = {self.b}")
        if not self.E > 0 or not -1 < self.nu < 0.5:
            raise ValueError(f"need E > 0 and -1 < nu < 0.5, got E = {self.E}, nu = {self.nu}")

    @property
    def coefficients(self) -> tuple[float, float]:
        """``(A, B)`` of ``u_r = A r + B / r^2``."""
        d = self.b**3 - self.a**3
        A = self.p * self.a**3 * (1 - 2 * self.nu) / (self.E * d)
        B = self.p * self.a**3 * self.b**3 * (1 + self.nu) / (2 * self.E * d)
        return A, B

    @property
    def moduli(self) -> tuple[float, float]:
        """``(K, G)``: bulk and shear modulus."""
        return self.E / (3 * (1 - 2 * self.nu)), self.E / (2 * (1 + self.nu))

    def u_r(self, r: np.ndarray | float) -> np.ndarray:
        """Radial displacement ``A r + B / r^2``."""
        A, B = self.coefficients
        r = np.asarray(r, dtype=float)
        return A * r + B / r**2

    def sigma_rr(self, r: np.ndarray | float) -> np.ndarray:
        """Radial stress ``3 K A - 4 G B / r^3``."""
        A, B = self.coefficients
        K, G = self.moduli
        return 3 * K * A - 4 * G * B / np.asarray(r, dtype=float)**3

    def sigma_tt(self, r: np.ndarray | float) -> np.ndarray:
        """Hoop stress (both tangential directions) ``3 K A + 2 G B / r^3``."""
        A, B = self.coefficients
        K, G = self.moduli
        return 3 * K * A + 2 * G * B / np.asarray(r, dtype=float)**3

    def displacement(self, x: np.ndarray) -> np.ndarray:
        """Cartesian displacement ``u_r(r) x / r`` at points ``x`` (..., 3)."""
        x = np.asarray(x, dtype=float)
        r = np.linalg.norm(x, axis=-1)
        return (self.u_r(r) / r)[..., None] * x

    def stress(self, x: np.ndarray) -> np.ndarray:
        """Cartesian stress ``sigma_tt I + (sigma_rr - sigma_tt) n n^T`` at points ``x``
        (..., 3): shape (..., 3, 3)."""
        x = np.asarray(x, dtype=float)
        r = np.linalg.norm(x, axis=-1)
        n = x / r[..., None]
        srr, stt = self.sigma_rr(r), self.sigma_tt(r)
        return (stt[..., None, None] * np.eye(3)
                + (srr - stt)[..., None, None] * n[..., :, None] * n[..., None, :])

    def norms(self) -> tuple[float, float]:
        """``(||u||_L2, ||sigma||_L2)`` over the exact octant, in closed form (module
        docstring)."""
        a, b = self.a, self.b
        A, B = self.coefficients
        K, G = self.moduli
        c1, c2 = 3 * K * A, 4 * G * B
        uu = A**2 * (b**5 - a**5) / 5 + A * B * (b**2 - a**2) + B**2 * (1 / a - 1 / b)
        ss = c1**2 * (b**3 - a**3) + 0.5 * c2**2 * (a**-3 - b**-3)
        return float(np.sqrt(0.5 * np.pi * uu)), float(np.sqrt(0.5 * np.pi * ss))


def hooke(grad: np.ndarray, E: float, nu: float) -> np.ndarray:
    """Stress ``lambda tr(eps) I + 2 mu eps`` of the symmetric part ``eps`` of displacement
    gradients ``grad`` (..., 3, 3)."""
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    mu = E / (2 * (1 + nu))
    eps = 0.5 * (grad + np.swapaxes(grad, -1, -2))
    tr = np.trace(eps, axis1=-2, axis2=-1)
    return lam * tr[..., None, None] * np.eye(3) + 2 * mu * eps


def octant_quadrature(a: float, b: float, n: int = 12) -> tuple[np.ndarray, np.ndarray]:
    """Points ``(n^3, 3)`` and weights ``(n^3,)`` of an ``n``-point Gauss-Legendre rule in
    each of ``r`` on [a, b], the polar angle on [0, pi/2] and the longitude on [0, pi/2]
    for the octant ``x, y, z >= 0`` of the shell (weights include ``r^2 sin(theta)``)."""
    g, w = np.polynomial.legendre.leggauss(n)
    r = 0.5 * (a + b) + 0.5 * (b - a) * g
    wr = 0.5 * (b - a) * w * r**2
    t = 0.25 * np.pi * (1 + g)
    wt = 0.25 * np.pi * w * np.sin(t)
    ph = 0.25 * np.pi * (1 + g)
    wp = 0.25 * np.pi * w
    R, T, P = np.meshgrid(r, t, ph, indexing="ij")
    x = np.stack([R * np.sin(T) * np.cos(P), R * np.sin(T) * np.sin(P), R * np.cos(T)], axis=-1)
    weights = wr[:, None, None] * wt[None, :, None] * wp[None, None, :]
    return x.reshape(-1, 3), weights.reshape(-1)


def relative_l2_error(weights: np.ndarray, f_h: np.ndarray, f: np.ndarray) -> float:
    """``sqrt(sum w |f_h - f|^2 / sum w |f|^2)`` over sampled values at points of weights
    ``weights`` (n,) (each point's share of the volume); ``f_h``, ``f`` (n, ...): vectors
    (Euclidean norm) or tensors (Frobenius norm)."""
    w = np.asarray(weights, dtype=float)
    f = np.asarray(f, dtype=float)
    d = np.asarray(f_h, dtype=float) - f
    axes = tuple(range(1, f.ndim))
    return float(np.sqrt(np.sum(w * np.sum(d**2, axis=axes)) / np.sum(w * np.sum(f**2, axis=axes))))


def relative_l2_errors(weights: np.ndarray, u_h: np.ndarray, u: np.ndarray,
                       sigma_h: np.ndarray | None = None,
                       sigma: np.ndarray | None = None) -> tuple[float, float]:
    """``(e_u, e_sigma)`` (:func:`relative_l2_error`) from sampled values at points of
    weights ``weights`` (n,): displacements ``u_h``, ``u`` (n, 3), stresses ``sigma_h``,
    ``sigma`` (n, 3, 3); ``e_sigma`` is NaN without stresses."""
    eu = relative_l2_error(weights, u_h, u)
    if sigma_h is None or sigma is None:
        return eu, float("nan")
    return eu, relative_l2_error(weights, sigma_h, sigma)


def octant_errors(shell: LameShell, u_h: Field, sigma_h: Field | None = None,
                  n: int = 12) -> tuple[float, float]:
    """``(e_u, e_sigma)`` of the fields given by the functions ``u_h`` and ``sigma_h``
    (of points (m, 3)) over the exact octant, by :func:`octant_quadrature` with ``n``
    points per direction (with n = 12 the exact solution's own norms come out as the
    closed forms to 1e-15 for b / a = 2, to 1e-6 for b / a = 6; n = 20: 3e-12)."""
    x, w = octant_quadrature(shell.a, shell.b, n)
    s_h = None if sigma_h is None else sigma_h(x)
    return relative_l2_errors(w, u_h(x), shell.displacement(x), s_h,
                              None if sigma_h is None else shell.stress(x))
