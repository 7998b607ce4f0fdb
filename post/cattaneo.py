"""A cylinder pressed and sheared, against Cattaneo-Mindlin's stick zone
(``python -m post cattaneo RESULT.h5``; the cases: ``python -m pre cattaneo``).

Cattaneo-Mindlin (Johnson, *Contact Mechanics*, 7.2) for a Hertz line contact under a
normal force P (per unit thickness) then a tangential force Q < mu P: the stick zone
is |x| < c with c/a = sqrt(1 - Q/(mu P)), the tangential traction

    q(x) = mu p0 sqrt(1 - x^2/a^2) - (c/a) mu p0 sqrt(1 - x^2/c^2)   (|x| < c)
    q(x) = mu p0 sqrt(1 - x^2/a^2)                                    (c < |x| < a)

with a = sqrt(4 P R / (pi E*)), p0 = 2 P / (pi a), 1/R = 1/R1 + 1/R2 and
1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 (a rigid body adds nothing). It is a small-strain
result for elastically similar bodies (or a press that leaves no tangential traction):
we compare the traction per *reference* length (``p_t_nominal``) at the reference
positions of the slave points, measured from the cylinder's centre (the circle through
them), with P and Q the pair's resultant on the slave at that step. Against a rigid
flat the press itself leaves a stick traction (docs/verification.md; :mod:`post.stickslip`).

Measures: c/a of the simulated stick zone (half the distance between the midpoints from
the outermost sticking points of the central zone to the first slipping ones, one on each
side, over a), the relative L2 difference of the traction from Cattaneo-Mindlin's over
the contact zone (trapezoidal rule on 20001 points of the linear interpolant), and the
largest |q| / (mu p0) of the sticking points.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from pre.nurbs import curve_to_splipy

from .contact import slave_edge_curve
from .hertz import HertzError, fit_circle
from .reader import ContactOutput, Result
from .stickslip import cattaneo_mindlin

GRID_POINTS = 20001
"""Points of the integration grid of the L2 difference."""
STICK_MARGIN = 0.01
"""The stick zone ends where the traction comes within this fraction of mu p0 of the
slip bound mu p (:func:`_stick_half_width`; Cattaneo-Mindlin's reaches 1 % of it within
5e-5 c of the zone's end)."""
FLAT = 1.0e3
"""A master whose contact edge fits a circle larger than this many slave radii is flat."""


class CattaneoError(ValueError):
    """The result is not a cylinder pressed onto a flat or a cylinder (or has no contact)."""


@dataclass
class CattaneoComparison:
    """One step of a pair against Cattaneo-Mindlin (:func:`cattaneo_comparison`)."""

    source: str
    step: int
    time: float
    friction: float
    force: float
    """P: the normal force per unit thickness on the slave."""
    tangential: float
    """Q: the tangential force per unit thickness on the slave."""
    radius: float
    """The effective radius R (1/R = 1/R1 + 1/R2)."""
    e_star: float
    a: float
    p0: float
    ratio: float
    """Q / (mu P)."""
    c_analytic: float
    """sqrt(1 - Q/(mu P)): Cattaneo-Mindlin's stick half-width over a."""
    c_simulated: float
    """The simulated stick zone's half-width over a (NaN without a sticking point)."""
    l2: float
    """Relative L2 difference of q from Cattaneo-Mindlin's (NaN at Q = 0)."""
    stick_traction: float
    """The largest |q| of the sticking points over mu p0."""
    x: np.ndarray = field(repr=False)
    """(n,) the active points' reference positions from the centre, sorted."""
    q: np.ndarray = field(repr=False)
    """(n,) their tangential traction per reference length, positive along Q."""
    state: np.ndarray = field(repr=False)

    def report(self) -> list[str]:
        """What the comparison says, a line each."""
        lines = [f"{self.source}: step {self.step} (t = {self.time:g}), mu = {self.friction:g}",
                 f"  P = {self.force:.6g}, Q = {self.tangential:.6g}, Q/(mu P) = {self.ratio:.4f}; "
                 f"R = {self.radius:.6g}, E* = {self.e_star:.6g}: a = {self.a:.6g}, p0 = {self.p0:.6g}",
                 f"  stick zone c/a: {self.c_simulated:.4f} (Cattaneo-Mindlin {self.c_analytic:.4f}, "
                 f"difference {self.c_simulated - self.c_analytic:+.4f})",
                 f"  largest |q| of the sticking points: {self.stick_traction:.4f} mu p0"]
        if math.isfinite(self.l2):
            lines.append(f"  traction: relative L2 difference from Cattaneo-Mindlin {100 * self.l2:.2f} %")
        return lines


def _effective(result: Result, c: ContactOutput, active: np.ndarray) -> tuple[float, float, float]:
    """(x of the slave's centre, R, E*) of the pair: the circle through the slave's
    reference points near the contact; a deformable master's radius from its contact
    edge there (flat beyond FLAT slave radii); the moduli of the deformable bodies."""
    s = c.x_ref[:, 0]
    lo, hi = s[active].min(), s[active].max()
    w = max(hi - lo, 1e-300)
    near = (s >= lo - 3 * w) & (s <= hi + 3 * w)
    centre, r1, rms = fit_circle(c.x_ref[near])
    if rms > 1e-3 * r1:
        raise CattaneoError(f"{result.path}: the slave {c.slave!r} is not a cylinder near the contact")
    compliance = 0.0
    inverse_radius = 1.0 / r1
    for name in (c.slave, c.master):
        if name not in result.bodies:
            continue
        body = result.bodies[name]
        compliance += (1.0 - float(body.attrs["poisson_ratio"]) ** 2) / float(body.attrs["youngs_modulus"])
        if name == c.master:
            curve, _ = slave_edge_curve(body)
            pts = np.asarray(curve_to_splipy(curve)(np.linspace(0.0, 1.0, 4001)), dtype=float).reshape(-1, 2)
            pts = pts[(pts[:, 0] >= lo - 3 * w) & (pts[:, 0] <= hi + 3 * w)]
            if not _straight(pts):
                try:
                    _, r2, _ = fit_circle(pts)
                except HertzError:
                    r2 = math.inf
                if r2 < FLAT * r1:
                    inverse_radius += 1.0 / r2
    if c.rigid_curve is not None:
        raise CattaneoError(f"{result.path}: a rigid curve master is not compared (only a rigid line, "
                            f"a flat body or a cylinder)")
    return float(centre[0]), 1.0 / inverse_radius, 1.0 / compliance


def _straight(points: np.ndarray) -> bool:
    """Whether ``points`` (n, 2) lie on a line (rms distance below 1e-9 of their extent)."""
    if len(points) < 3:
        return True
    centred = points - points.mean(axis=0)
    sv = np.linalg.svd(centred, compute_uv=False)
    return bool(sv[-1] / math.sqrt(len(points)) <= 1e-9 * max(np.ptp(points, axis=0).max(), 1e-300))


def _stick_half_width(x: np.ndarray, q: np.ndarray, slip_bound: np.ndarray, q0: float) -> float:
    """Half the width of the central stick zone, from the traction: on each side, from
    the centre outward, where the traction first comes within STICK_MARGIN q0 of the slip
    bound ``slip_bound`` = mu p (linear interpolation between the points); the mean of
    both sides (NaN when the traction stays below the bound up to the zone's end).
    Methods whose stick/slip states belong to control points (mortar) label a point
    slipping when any control point acting on it slips; the traction does not depend on
    that convention."""
    gap = (slip_bound - np.abs(q)) / q0 - STICK_MARGIN
    centre = int(np.argmin(np.abs(x)))
    ends = []
    for direction in (-1, 1):
        k = centre
        while 0 <= k + direction < len(x) and gap[k + direction] > 0.0:
            k += direction
        nxt = k + direction
        if not 0 <= nxt < len(x) or gap[k] <= 0.0:
            return math.nan
        s = gap[k] / (gap[k] - gap[nxt])
        ends.append(abs(x[k] + s * (x[nxt] - x[k])))
    return 0.5 * (ends[0] + ends[1])


def cattaneo_comparison(result: Result, step: int = -1, pair: int = 0) -> CattaneoComparison:
    """Compare pair ``pair`` (0-based) at ``step`` (as :meth:`Result.select_step`) with
    Cattaneo-Mindlin (module docstring). CattaneoError when it does not apply."""
    try:
        st = result.select_step(step)
    except IndexError as err:
        raise CattaneoError(str(err)) from None
    if st is None or not st.contact or not -len(st.contact) <= pair < len(st.contact):
        raise CattaneoError(f"{result.path}: no contact pair {pair + 1} at that step")
    c = st.contact[pair]
    mu = float(c.attrs.get("friction", 0.0))
    if mu <= 0.0:
        raise CattaneoError(f"{result.path}: pair {c.slave} -> {c.master} has no friction at step {st.step}")
    if c.p_t_nominal is None:
        raise CattaneoError(f"{result.path}: no p_t_nominal (written by an older voiga)")
    active = c.state > 0
    if not active.any():
        raise CattaneoError(f"{result.path}: no point in contact at step {st.step}")
    x0, radius, e_star = _effective(result, c, active)
    force, tangential = abs(float(c.force[1])), float(c.force[0])
    a = math.sqrt(4.0 * force * radius / (math.pi * e_star))
    p0 = 2.0 * force / (math.pi * a)
    x = c.x_ref[active, 0] - x0
    order = np.argsort(x, kind="stable")
    x, q, state = x[order], c.p_t_nominal[active][order], c.state[active][order]
    p = (c.p_n_nominal if c.p_n_nominal is not None else c.p_n)[active][order]
    # positive along Q (the traction's own sense when Q = 0)
    sense = np.sign(tangential) if tangential != 0.0 else 1.0
    q = q * (np.sign(np.trapezoid(q, x)) * sense if np.trapezoid(q, x) != 0.0 else 1.0)
    ratio = abs(tangential) / (mu * force)
    c_an = math.sqrt(max(1.0 - ratio, 0.0))
    l2 = math.nan
    if ratio > 0.0:
        lo, hi = min(-a, x[0]), max(a, x[-1])
        grid = np.unique(np.concatenate([np.linspace(lo, hi, GRID_POINTS), x, [-a, a]]))
        ref = cattaneo_mindlin(grid, a, c_an * a, mu * p0)
        sim = np.interp(grid, x, q, left=0.0, right=0.0)
        l2 = float(np.sqrt(np.trapezoid((sim - ref) ** 2, grid) / np.trapezoid(ref**2, grid)))
    stick = state == 1
    return CattaneoComparison(str(result.path), st.step, float(st.time), mu, force, abs(tangential),
                              radius, e_star, a, p0, ratio, c_an, _stick_half_width(x, q, mu * p, mu * p0) / a, l2,
                              float(np.abs(q[stick]).max() / (mu * p0)) if stick.any() else 0.0,
                              x, q, state)
