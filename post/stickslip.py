"""Incremental stick and slip of an elastic half-plane pressed by a rigid flat, then
sheared (``python -m post cattaneo --halfplane``): the small-strain reference for a
Cattaneo-Mindlin test against a rigid obstacle, where the bodies are elastically
dissimilar.

Why it is needed. Cattaneo-Mindlin's stick zone (c/a = sqrt(1 - Q / (mu P)), the
traction mu p0 (sqrt(1 - x^2/a^2) - (c/a) sqrt(1 - x^2/c^2))) assumes that the normal
press leaves no tangential traction. Against a rigid flat it does not: under a normal
pressure p the surface of an elastic half-plane slides towards the centre,
du_x/dx = -(1 - 2 nu)(1 + nu)/E p (plane strain), and friction holds it (Goodman's
problem; Spence's incremental solution). With Dundurs' beta = (1 - 2 nu) / (2 (1 - nu))
the stick traction after the press is of order beta p0, and it stays in the stick zone
when the flat is then sheared. This module solves that incremental problem numerically.

Model (uncoupled, as Goodman's: the normal pressure is Hertz's at every instant, the
tangential traction does not change it, which holds for small beta). The surface
[-L, L] is cut into panels with a constant tangential traction q_j each; the tangential
displacement of the surface at panel centres is

    u_x(x) = -(1 - 2 nu)(1 + nu)/(2 E) (int_{-inf}^x p - int_x^inf p)
             - 2 (1 - nu^2)/(pi E) int q(s) ln|x - s| ds

(Johnson 2.25 with 2.22; a constant drops out for the antisymmetric q of the press and
does not matter for the increments of the shear). The load history is discretized in
increments: the half-width grows to a, then the flat moves by equal tangential steps.
In each increment every contact panel either sticks (its increment of relative tangential
displacement is zero: the press's, or the flat's motion in the shear) or slips with
|q| = mu p opposing the slip; the active set is found by iteration (a sticking panel
over the cone slips, a slipping one whose slip reverses sticks).

Checks (``post/tests/test_stickslip.py``): with beta -> 0 it reproduces Cattaneo-Mindlin
(c/a within 1e-3, traction within 0.5 % L2); with nu = 0.49, mu = 0.3 it converges
under refinement to a stick half-width of 0.731 a at Q / (mu P) = 0.5 (Cattaneo-Mindlin:
0.707 a), a traction 11.7 % (L2) from Cattaneo-Mindlin's, and after the press a stick
traction of up to 0.060 mu p0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np


def cattaneo_mindlin(x: np.ndarray, a: float, c: float, q0: float) -> np.ndarray:
    """The Cattaneo-Mindlin traction ``q0 (sqrt(1 - x^2/a^2) - (c/a) sqrt(1 - x^2/c^2))``
    (the second term only inside |x| < c, both zero outside |x| < a); ``q0 = mu p0``."""
    x = np.asarray(x, dtype=float)
    outer = np.sqrt(np.clip(1.0 - (x / a) ** 2, 0.0, None))
    inner = np.zeros_like(x) if c <= 0 else (c / a) * np.sqrt(np.clip(1.0 - (x / c) ** 2, 0.0, None))
    return q0 * (outer - inner)


@dataclass
class HalfPlaneStickSlip:
    """The incremental solution at the end of the press and at the shear's target."""

    poisson_ratio: float
    friction: float
    beta: float
    """Dundurs' beta of an elastic body on a rigid one: (1 - 2 nu) / (2 (1 - nu))."""
    ratio: float
    """Q / (mu P) reached by the shear."""
    stick_half_width: float
    """The shear's stick zone half-width, relative to a."""
    cattaneo_half_width: float
    """Cattaneo-Mindlin's for the same Q / (mu P): sqrt(1 - ratio)."""
    l2_from_cattaneo: float
    """Relative L2 difference of the shear's traction from Cattaneo-Mindlin's."""
    press_stick_traction: float
    """The largest |q| over the sticking panels after the press, relative to mu p0."""
    x: np.ndarray = field(repr=False)
    """(n,) panel centres relative to a."""
    q_press: np.ndarray = field(repr=False)
    """(n,) traction after the press, relative to mu p0."""
    q_shear: np.ndarray = field(repr=False)
    """(n,) traction at the shear's target, relative to mu p0 (positive along Q)."""


class _Panels:
    """The discretized surface and its influence coefficients."""

    def __init__(self, nu: float, n: int, extent: float) -> None:
        self.edges = np.linspace(-extent, extent, n + 1)
        self.x = 0.5 * (self.edges[1:] + self.edges[:-1])
        self.width = self.edges[1] - self.edges[0]

        def f(t: np.ndarray) -> np.ndarray:
            return np.where(t == 0.0, 0.0, t * np.log(np.abs(t) + 1e-300) - t)
        d = self.x[:, None]
        # u_x at x_i from a unit traction on panel j (E = 1): int ln|x - s| ds over it
        self.c = -(2.0 * (1.0 - nu**2) / math.pi) * (f(d - self.edges[None, :-1]) - f(d - self.edges[None, 1:]))
        self.kp = -(1.0 - 2.0 * nu) * (1.0 + nu) / 2.0

    def hertz(self, a: float, e_star: float) -> tuple[np.ndarray, np.ndarray]:
        """Hertz's pressure of half-width ``a`` (radius 1) at the panels, and the tangential
        displacement of the surface it causes (E = 1, relative to the centre)."""
        p = a * e_star / 2.0 * np.sqrt(np.clip(1.0 - (self.x / a) ** 2, 0.0, None))
        before = np.cumsum(p) * self.width - 0.5 * p * self.width
        return p, self.kp * (before - (p.sum() * self.width - before))

    def increment(self, q: np.ndarray, target: np.ndarray, p: np.ndarray,
                  mu: float) -> tuple[np.ndarray, np.ndarray]:
        """One load increment: the traction after it and which panels stick. ``target``:
        the increment of tangential displacement a sticking panel must take from the
        traction (minus the pressure's own increment, or the flat's motion)."""
        contact = p > 0.0
        slip = np.zeros(len(q), dtype=bool)
        sign = np.zeros(len(q))
        for _ in range(200):
            stick = contact & ~slip
            dq = np.where(slip, sign * mu * p - q, 0.0)
            dq[~contact] = -q[~contact]
            idx = np.flatnonzero(stick)
            if idx.size:
                rhs = target[idx] - self.c[np.ix_(idx, np.flatnonzero(~stick))] @ dq[~stick]
                dq[idx] = np.linalg.solve(self.c[np.ix_(idx, idx)], rhs)
            new = q + dq
            moved = self.c @ dq - target          # slip increment of each panel
            over = stick & (np.abs(new) > mu * p * (1.0 + 1e-12))
            back = slip & (moved * sign > 0.0)    # the traction no longer opposes the slip
            if not over.any() and not back.any():
                return new, stick
            sign[over] = np.sign(new[over])
            slip = (slip | over) & ~back
        raise RuntimeError("the stick/slip active set did not settle")


def halfplane_stick_slip(poisson_ratio: float, friction: float, ratio: float = 0.5,
                         panels: int = 400, press_steps: int = 200,
                         shear_step: float = 2.0e-2) -> HalfPlaneStickSlip:
    """Press the half-plane (E = 1, Poisson ratio ``poisson_ratio``) with a rigid flat in
    ``press_steps`` equal increments of the half-width a = 1, with Coulomb friction
    ``friction``, then move the flat tangentially in steps of ``shear_step`` (times
    mu p0 a / E*) until Q / (mu P) reaches ``ratio``; the last step is interpolated to it.
    Lengths relative to a, tractions to mu p0."""
    if not (-1.0 < poisson_ratio < 0.5 and friction > 0.0 and 0.0 < ratio < 1.0):
        raise ValueError("need -1 < nu < 0.5, mu > 0 and 0 < ratio < 1")
    nu, mu = poisson_ratio, friction
    e_star = 1.0 / (1.0 - nu**2)
    grid = _Panels(nu, panels, 1.05)
    q = np.zeros(panels)
    _, u_prev = grid.hertz(1e-12, e_star)
    for k in range(1, press_steps + 1):
        p, u = grid.hertz(k / press_steps, e_star)
        q, stick = grid.increment(q, -(u - u_prev), p, mu)
        u_prev = u
    p0 = e_star / 2.0
    force = p.sum() * grid.width
    q_press = q / (mu * p0)
    press_max = float(np.abs(q_press[stick]).max()) if stick.any() else 0.0
    step = shear_step * mu * p0 / e_star
    q_old, r_old = q, 0.0
    for _ in range(10000):
        q_new, stick = grid.increment(q_old, np.full(panels, step), p, mu)
        r_new = abs(q_new.sum() * grid.width) / (mu * force)
        if r_new >= ratio:
            s = (ratio - r_old) / (r_new - r_old)
            q_new, stick = grid.increment(q_old, np.full(panels, s * step), p, mu)
            break
        q_old, r_old = q_new, r_new
    else:
        raise RuntimeError("the shear did not reach the ratio")
    reached = abs(q_new.sum() * grid.width) / (mu * force)
    c_cm = math.sqrt(1.0 - reached)
    q_shear = np.sign(q_new.sum()) * q_new / (mu * p0)
    cm = cattaneo_mindlin(grid.x, 1.0, c_cm, 1.0)
    l2 = float(np.sqrt(((q_shear - cm) ** 2).sum() / (cm**2).sum()))
    return HalfPlaneStickSlip(nu, mu, (1.0 - 2.0 * nu) / (2.0 * (1.0 - nu)), reached,
                              float(np.abs(grid.x[stick]).max()) if stick.any() else 0.0,
                              c_cm, l2, press_max, grid.x, q_press, q_shear)
