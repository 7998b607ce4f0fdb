"""A cylinder pressed on a rigid flat against the analytic Hertz line contact, in the
configuration and measure the theory assumes (``python -m post hertz``).

Hertz's line contact is a small-strain result: the pressure is a force per unit
*reference* length at *reference* positions. voiga writes that measure beside the
current one (``p_n_nominal`` at ``x_ref``, docs/hdf5.md), and this module compares it,
not the pressure per current length at current positions (the surface of the hertz
scene is compressed about 2 % at the centre, which alone shifts a current-configuration
comparison by about that much).

For the run's own force P (per unit thickness, of the full cylinder): plane strain
``E* = E / (1 - nu^2)``, half-width ``a = sqrt(4 P R / (pi E*))``, peak
``p0 = 2 P / (pi a)``, ``p(x) = p0 sqrt(1 - (x/a)^2)``. The error measure is
:func:`profile_error`; every number is absolute (nothing is normalised by the simulated
peak or fitted).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from pre.files import save_figure
from pre.nurbs import patch_to_splipy

from .contact import edge_stretch
from .halfplane import CircleContact, circle_contact
from .naming import output_path
from .reader import Body, ContactOutput, Result, Step
from .units import Units

EDGE_ZONE = 0.05
"""Points within this fraction of a from the analytic edge (|x| in [0.95 a, 1.05 a])
belong to the edge zone, closer to the centre to the interior."""
EDGE_LEVEL = 0.05
"""The pressure level, relative to p0, whose outermost crossing is the reported edge."""
GRID_POINTS = 20001
"""Uniform points of the integration grid over the union of both supports (the slave
points and +-a are added to it)."""
CIRCLE_TOLERANCE = 1e-3
"""Largest rms distance of the slave edge near the contact from the fitted circle,
relative to its radius, for the slave edge to count as a cylinder."""
HALF_MODEL_SIDE = 0.02
"""The contact zone is on one side of the centre (a half model with a symmetry cut)
when it reaches less than this fraction of its length onto the other side."""


class HertzError(ValueError):
    """The result is not a cylinder pressed on a rigid flat (or has no contact)."""


def hertz_reference(force: float, youngs_modulus: float, poisson_ratio: float,
                    radius: float) -> tuple[float, float]:
    """Half-width and peak pressure of the Hertz line contact of a cylinder on a rigid flat
    (plane strain: E* = E / (1 - nu^2)), for the total force per length ``force``."""
    e_star = youngs_modulus / (1.0 - poisson_ratio**2)
    a = np.sqrt(4.0 * force * radius / (np.pi * e_star))
    return float(a), float(2.0 * force / (np.pi * a))


def hertz_pressure(x: np.ndarray, a: float, p0: float) -> np.ndarray:
    """The analytic pressure ``p0 sqrt(1 - (x/a)^2)`` inside ``|x| < a``, zero outside."""
    x = np.asarray(x, dtype=float)
    return p0 * np.sqrt(np.clip(1.0 - (x / a) ** 2, 0.0, None))


def fit_hertz(x: np.ndarray, p: np.ndarray) -> tuple[float, float]:
    """Fit p(x)^2 = p0^2 (1 - x^2/a^2) (linear in x^2) to the active points; (a, p0)."""
    design = np.vstack([np.ones_like(x), x**2]).T
    (c0, c1), *_ = np.linalg.lstsq(design, p**2, rcond=None)
    if c0 <= 0 or c1 >= 0:
        raise ValueError("the contact pressure does not look like a Hertz profile")
    return float(np.sqrt(-c0 / c1)), float(np.sqrt(c0))


@dataclass(frozen=True)
class ProfileError:
    """How far a pressure profile is from the analytic one (see :func:`profile_error`)."""

    l2: float
    """Relative L2 error over the union of both supports."""
    lo: float
    hi: float
    """The integration interval [lo, hi] (positions from the centre)."""
    max_deviation: float
    """Signed (p - p_Hertz) / p0 of largest magnitude at a point in [lo, hi]."""
    max_deviation_at: float
    """Where: the point's |x| / a."""
    interior_deviation: float
    """The same over the interior points, |x| < (1 - EDGE_ZONE) a (NaN if none)."""
    interior_deviation_at: float
    l2_interior: float = float("nan")
    """The part of ``l2`` from the interior, |x| < (1 - EDGE_ZONE) a (the squares of the
    two parts add up to the square of ``l2``)."""
    l2_edge: float = float("nan")
    """The part of ``l2`` from the rest, the edge zone and beyond."""
    edge: float = float("nan")
    """|x| / a where the profile last falls to EDGE_LEVEL p0 (the outermost crossing;
    analytic: sqrt(1 - EDGE_LEVEL^2)). A level above zero keeps the tails of a spline
    pressure out of it."""
    edge_reference: float = float("nan")
    """The same for the reference profile (Hertz: sqrt(1 - EDGE_LEVEL^2))."""


def _largest(dev: np.ndarray, at: np.ndarray) -> tuple[float, float]:
    if not dev.size:
        return float("nan"), float("nan")
    k = int(np.argmax(np.abs(dev)))
    return float(dev[k]), float(at[k])


def profile_error(x: np.ndarray, p: np.ndarray, a: float, p0: float,
                  shape: Callable[[np.ndarray], np.ndarray] | None = None) -> ProfileError:
    """Compare point values ``p`` at positions ``x`` (from the centre of the contact;
    a half model's points mirrored to both sides) with ``p0 sqrt(1 - (x/a)^2)``.

    The simulated profile is the linear interpolant of the point values (sorted in x),
    zero beyond the outermost points. Its support ends on either side at the first point
    past the last point with p > 0 (where the interpolant reaches zero); the interval
    [lo, hi] is the union of that support and [-a, a]. The relative L2 error
    ``sqrt(int (p - p_H)^2 dx / int p_H^2 dx)`` over [lo, hi] is integrated by the
    trapezoidal rule on :data:`GRID_POINTS` uniform points plus the data points and
    +-a (so the interpolant's kinks and the analytic edge are grid points; against
    adaptive quadrature the rule's own error in the L2 value is about 2e-7). The
    pointwise deviation is taken at the data points in [lo, hi], relative to p0.
    ``shape``: another reference profile with half-width a and centre pressure p0 (the
    exact circle of :mod:`post.halfplane`) instead of Hertz's.

    The L2 error is split into its interior part (|x| < (1 - EDGE_ZONE) a) and the rest
    (their squares add up): an edge of the simulated zone a fraction delta of a off the
    analytic one alone costs about 2.8 delta in the L2 error (0.28 % for delta = 0.1 %),
    so the split and the outermost points with and without pressure (``edge_in``,
    ``edge_out``) say whether the edge or the interior limits the comparison.
    """
    order = np.argsort(x, kind="stable")
    x = np.asarray(x, dtype=float)[order]
    p = np.asarray(p, dtype=float)[order]
    on = np.flatnonzero(p > 0)
    if not on.size:
        raise HertzError("no point has a positive pressure")
    lo = min(-a, x[max(on[0] - 1, 0)])
    hi = max(a, x[min(on[-1] + 1, len(x) - 1)])
    inside = (x >= lo) & (x <= hi)
    rim = (1.0 - EDGE_ZONE) * a
    grid = np.unique(np.concatenate([np.linspace(lo, hi, GRID_POINTS), x[inside],
                                     [v for v in (-a, a, -rim, rim) if lo <= v <= hi]]))
    sim = np.interp(grid, x, p, left=0.0, right=0.0)
    shape = shape or (lambda s: hertz_pressure(s, a, p0))
    ref = shape(grid)
    norm = np.trapezoid(ref**2, grid)
    l2 = float(np.sqrt(np.trapezoid((sim - ref) ** 2, grid) / norm))
    core = np.abs(grid) <= rim  # contiguous, +-rim are grid points
    l2_interior = float(np.sqrt(np.trapezoid((sim[core] - ref[core]) ** 2, grid[core]) / norm))
    dev = (p[inside] - shape(x[inside])) / p0
    at = np.abs(x[inside]) / a
    interior = at < 1.0 - EDGE_ZONE
    return ProfileError(l2, float(lo), float(hi), *_largest(dev, at),
                        *_largest(dev[interior], at[interior]), l2_interior=l2_interior,
                        l2_edge=float(np.sqrt(max(l2**2 - l2_interior**2, 0.0))),
                        edge=_edge(grid, sim, EDGE_LEVEL * p0) / a,
                        edge_reference=_edge(grid, ref, EDGE_LEVEL * p0) / a)


def _edge(grid: np.ndarray, sim: np.ndarray, level: float) -> float:
    """|x| of the outermost crossing of ``level`` by the interpolant ``sim`` on ``grid``."""
    above = np.flatnonzero(sim >= level)
    if not above.size:
        return float("nan")
    edges = []
    for k, step in ((above[-1], 1), (above[0], -1)):
        j = k + step
        if 0 <= j < len(grid):
            edges.append(abs(grid[k] + (grid[j] - grid[k]) * (sim[k] - level) / (sim[k] - sim[j])))
        else:
            edges.append(abs(grid[k]))
    return float(max(edges))


def fit_circle(points: np.ndarray) -> tuple[np.ndarray, float, float]:
    """Least-squares circle through ``points`` (n, 2) (the algebraic fit
    x^2 + y^2 + D x + E y + F = 0): ``(centre, radius, rms distance from it)``; a sphere
    through points (n, 3) alike (``x^2 + y^2 + z^2 + D x + E y + G z + F = 0``)."""
    pts = np.asarray(points, dtype=float)
    if len(pts) < pts.shape[1] + 1:
        raise HertzError(f"fewer than {pts.shape[1] + 1} slave points to fit a "
                         f"{'circle' if pts.shape[1] == 2 else 'sphere'} to")
    design = np.column_stack([pts, np.ones(len(pts))])
    coef, *_ = np.linalg.lstsq(design, -(pts**2).sum(axis=1), rcond=None)
    centre = -0.5 * coef[:-1]
    r2 = float(centre @ centre - coef[-1])
    if not np.isfinite(r2) or r2 <= 0:
        raise HertzError("the slave points near the contact do not lie on a circle (sphere)")
    radius = float(np.sqrt(r2))
    rms = float(np.sqrt(np.mean((np.linalg.norm(pts - centre, axis=1) - radius) ** 2)))
    return centre, radius, rms


@dataclass
class HertzComparison:
    """A pressure profile against analytic Hertz (:func:`hertz_comparison` for a result
    file, :func:`compare_profile` for point values)."""

    radius: float
    youngs_modulus: float
    poisson_ratio: float
    half_model: bool
    """The contact is on one side of the centre: a half model, P twice the pair's force."""
    force: float
    """P: total force per unit thickness of the full cylinder."""
    a: float
    """Analytic half-width for P."""
    p0: float
    """Analytic peak pressure for P."""
    error: ProfileError
    a_fit: float
    """Extra: half-width of the fit p^2 = p0^2 (1 - x^2/a^2) to the points in contact."""
    p0_fit: float
    p_max: float
    """Largest compared pressure at a point."""
    x: np.ndarray = field(repr=False)
    """(n,) positions from the centre along the flat, >= 0 for a half model, sorted."""
    p: np.ndarray = field(repr=False)
    """(n,) the compared pressure at ``x``."""
    source: str = ""
    """The result file."""
    step: int = 0
    time: float = 0.0
    configuration: str = "reference"
    """``'reference'`` (the measure of the theory) or ``'current'`` (for comparison)."""
    pressure: str = "nominal pressure (force per reference length)"
    """Which pressure was compared, in words (e.g. the dataset it came from)."""
    radius_source: str = "given"
    friction: float = 0.0
    circle: CircleContact | None = field(default=None, repr=False)
    """Set when the reference is the half-plane solution for the exact circle, not Hertz's
    parabola (``a`` and ``p0`` are then that solution's)."""

    @property
    def reference_name(self) -> str:
        return ("the half-plane solution for the exact circle" if self.circle is not None
                else "analytic Hertz")

    def reference_pressure(self, x: np.ndarray) -> np.ndarray:
        """The reference pressure at ``x`` (Hertz's, or the exact circle's)."""
        if self.circle is not None:
            return self.circle.pressure(x)
        return hertz_pressure(x, self.a, self.p0)

    @property
    def e_star(self) -> float:
        return self.youngs_modulus / (1.0 - self.poisson_ratio**2)

    @property
    def l2_error(self) -> float:
        """Relative L2 error over the union of both supports."""
        return self.error.l2

    @property
    def a_error(self) -> float:
        return self.a_fit / self.a - 1.0

    @property
    def p0_error(self) -> float:
        return self.p0_fit / self.p0 - 1.0

    @property
    def label(self) -> str:
        return Path(self.source).stem


def contact_pair(result: Result, step: int, pair: int) -> tuple[Step, ContactOutput]:
    """The step and contact pair, or HertzError naming what is missing."""
    if step == 0:
        raise HertzError("step 0 is the reference configuration: no contact to compare")
    try:
        st = result.select_step(step)
    except IndexError as err:
        raise HertzError(str(err)) from None
    if st is None or not st.contact:
        raise HertzError(f"{result.path}: step {st.step if st else 0} has no contact output")
    if not -len(st.contact) <= pair < len(st.contact):
        raise HertzError(f"{result.path}: no contact pair {pair + 1} (the file has "
                         f"{len(st.contact)})")
    return st, st.contact[pair]


def _nominal_pressure(result: Result, st: Step, pair: int) -> tuple[np.ndarray, str]:
    """The pressure per reference length and where it came from."""
    c = st.contact[pair]
    if c.p_n_nominal is not None:
        return c.p_n_nominal, "p_n_nominal (force per reference length)"
    return (c.p_n * edge_stretch(result, st, pair),
            "p_n x stretch (force per reference length; this file has no p_n_nominal, "
            "written before voiga wrote it: the stretch is computed from the slave edge "
            "and the displacement)")


def _cylinder(c: ContactOutput, active: np.ndarray,
              body: Body) -> tuple[np.ndarray, float, float]:
    """Centre, radius and relative rms misfit of the circle through the slave edge around
    the contact zone (three zone lengths on either side).

    A curved (degree >= 2) edge is fitted through its slave points' reference positions:
    they lie on the edge. A linear edge (the L1 layout) is a polygon inscribed in the
    cylinder: its slave points lie on chords, and a fit through them missed the radius by
    up to a half on a coarse mesh (0.45 on hertz m1-L1); it is fitted through the
    polygon's vertices (the distinct knots at eta = 1 of the bulk patch, at least six)."""
    t = np.array([c.rigid_normal[1], -c.rigid_normal[0]])
    s = c.x_ref @ t
    lo, hi = s[active].min(), s[active].max()
    w = max(hi - lo, 1e-300)
    near = (s >= lo - 3 * w) & (s <= hi + 3 * w)
    if np.count_nonzero(near) < 6:
        near = np.ones_like(near)
    linear = (body.layer.degree if body.layer is not None else body.bulk.degree[0]) == 1
    points = _vertices(body, c.xi_slave[near]) if linear else c.x_ref[near]
    centre, radius, rms = fit_circle(points)
    return centre, radius, rms / radius


def _vertices(body: Body, xi: np.ndarray) -> np.ndarray:
    """Reference positions of the contact edge's element vertices (eta = 1 of the bulk
    patch) within the span of ``xi``, widened to the six nearest when fewer."""
    knots = np.unique(body.bulk.knots_xi)
    inside = (knots >= xi.min()) & (knots <= xi.max())
    if np.count_nonzero(inside) < 6:
        inside = np.zeros_like(inside)
        inside[np.argsort(np.abs(knots - 0.5 * (xi.min() + xi.max())))[:6]] = True
    surface = patch_to_splipy(body.bulk)
    return np.array([np.ravel(surface(float(k), 1.0)) for k in knots[inside]])


def hertz_comparison(result: Result, step: int = -1, pair: int = 0,
                     radius: float | None = None,
                     configuration: str = "reference",
                     reference: str = "hertz") -> HertzComparison:
    """Compare contact pair ``pair`` (0-based) at ``step`` (as in
    :meth:`Result.select_step`) with the Hertz line contact of a cylinder on a rigid flat.

    The cylinder is recognised from the pair: its master must be a rigid line, and the
    slave edge around the contact must lie on a circle (:func:`fit_circle`,
    misfit below :data:`CIRCLE_TOLERANCE`); the circle gives the radius (unless
    ``radius`` is given) and the centre, whose projection on the flat is the centre of
    the contact. E and nu are the slave body's. When the contact zone lies on one side
    of the centre the model is a half model with a symmetry cut and P is twice the pair's
    normal force, else P is that force.

    ``configuration='reference'`` compares the nominal pressure (force per reference
    length, ``p_n_nominal``; for older files ``p_n`` times the stretch computed from the
    edge) at the reference positions ``x_ref``: the measure of the theory.
    ``'current'`` compares ``p_n`` (per current length) at the current positions ``x``,
    only to show what that measure would report. ``reference='circle'`` compares with the
    half-plane solution for the exact circle (:mod:`post.halfplane`). HertzError (a ValueError) when the pair
    is not a cylinder on a rigid flat or has no contact.
    """
    if configuration not in ("reference", "current"):
        raise ValueError(f"configuration must be 'reference' or 'current', not {configuration!r}")
    st, c = contact_pair(result, step, pair)
    if c.rigid_point is None or c.rigid_normal is None:
        kind = "a rigid curve" if c.rigid_curve is not None else f"the body {c.master!r}"
        raise HertzError(f"{result.path}: pair {c.slave} -> {c.master} is not pressed on a rigid "
                         f"flat (its master is {kind}); post hertz compares a cylinder on a "
                         f"rigid flat with analytic Hertz")
    n = np.asarray(c.rigid_normal, float) / np.linalg.norm(c.rigid_normal)
    normal_force = abs(float(c.force @ n))
    active = c.active
    if not active.any() or normal_force <= 0:
        raise HertzError(f"{result.path}: no point of {c.slave} -> {c.master} is in contact "
                         f"at step {st.step}")
    body = result.body(c.slave)
    centre, r_fit, misfit = _cylinder(c, active, body)
    if misfit > CIRCLE_TOLERANCE or (centre - c.rigid_point) @ n <= 0:
        raise HertzError(f"{result.path}: the contact edge of {c.slave!r} is not a cylinder "
                         f"pressing on the flat (its reference points near the contact are "
                         f"{misfit:.2g} of the radius off the best circle, allowed "
                         f"{CIRCLE_TOLERANCE:g}); post hertz compares a cylinder on a rigid flat")
    e, nu = float(body.attrs["youngs_modulus"]), float(body.attrs["poisson_ratio"])
    if configuration == "reference":
        p, what = _nominal_pressure(result, st, pair)
        pts = c.x_ref
    else:
        p, what, pts = c.p_n, "p_n (force per current length) at the current positions", c.x
    t = np.array([n[1], -n[0]])
    x = (pts - centre) @ t
    xa = x[active]
    side = HALF_MODEL_SIDE * max(float(np.ptp(xa)), 1e-300)
    half = bool(xa.min() >= -side or xa.max() <= side)
    source = (f"given; the slave edge's circle fit: {r_fit:.6g}" if radius is not None
              else f"circle fit to the slave edge's reference points, misfit {misfit:.1g} R")
    return compare_profile(np.abs(x) if half else x, p, (2.0 if half else 1.0) * normal_force,
                           e, nu, float(radius) if radius is not None else r_fit, half,
                           source=str(result.path), step=st.step, time=float(st.time),
                           configuration=configuration, pressure=what, radius_source=source,
                           friction=float(c.attrs.get("friction", 0.0)), reference=reference)


def compare_profile(x: np.ndarray, p: np.ndarray, force: float, youngs_modulus: float,
                    poisson_ratio: float, radius: float, half_model: bool,
                    reference: str = "hertz", **info: object) -> HertzComparison:
    """Point values ``p`` at distances ``x`` from the centre of the contact (>= 0 for a
    half model, whose points are mirrored) against Hertz for the force ``force`` (per
    unit thickness, of the full cylinder): :func:`profile_error` and the fit.
    ``reference='circle'``: against the half-plane solution for the exact circular profile
    (:func:`post.halfplane.circle_contact`) instead of Hertz's parabola.
    ``info``: the descriptive fields of :class:`HertzComparison` (source, step, ...)."""
    if reference not in ("hertz", "circle"):
        raise ValueError(f"reference must be 'hertz' or 'circle', not {reference!r}")
    a, p0 = hertz_reference(force, youngs_modulus, poisson_ratio, radius)
    circle = None
    if reference == "circle":
        try:
            circle = circle_contact(force, youngs_modulus / (1.0 - poisson_ratio**2), radius)
        except ValueError as err:
            raise HertzError(str(err)) from None
        a, p0 = circle.a, circle.p0
    order = np.argsort(x, kind="stable")
    x, p = np.asarray(x, float)[order], np.asarray(p, float)[order]
    err = profile_error(np.concatenate([-x[::-1], x]) if half_model else x,
                        np.concatenate([p[::-1], p]) if half_model else p, a, p0,
                        circle.pressure if circle is not None else None)
    try:
        a_fit, p0_fit = fit_hertz(np.abs(x[p > 0]), p[p > 0])
    except ValueError:
        a_fit = p0_fit = float("nan")
    return HertzComparison(radius=radius, youngs_modulus=youngs_modulus,
                           poisson_ratio=poisson_ratio, half_model=half_model, force=force,
                           a=a, p0=p0, error=err, a_fit=a_fit, p0_fit=p0_fit,
                           p_max=float(p.max()), x=x, p=p, circle=circle, **info)


def _zone(at: float) -> str:
    if not np.isfinite(at):
        return "-"
    if at < 1.0 - EDGE_ZONE:
        return "interior"
    return "edge zone" if at <= 1.0 + EDGE_ZONE else "outside a"


def format_hertz(h: HertzComparison) -> str:
    """One line: P, a, p0 and the errors (``post summary``)."""
    e = h.error
    return (f"P = {h.force:.6g}  a = {h.a:.6g}  p0 = {h.p0:.6g}  L2 = {e.l2:.3%}  "
            f"max |p - p_H|/p0 = {abs(e.max_deviation):.3%} at x/a = {e.max_deviation_at:.3f} "
            f"({_zone(e.max_deviation_at)})  [{h.configuration} configuration]")


def hertz_report(h: HertzComparison) -> list[str]:
    """The lines ``python -m post hertz`` prints for one comparison."""
    e = h.error
    measure = ("reference configuration: the pressure per reference length at the slave "
               "points' reference positions, as small-strain Hertz assumes"
               if h.configuration == "reference" else
               "CURRENT configuration (not the measure of the theory; for comparison only)")
    lines = [f"{h.source}, step {h.step} (load time {h.time:g}):",
             f"  measure: {measure}",
             f"  pressure: {h.pressure}",
             f"  cylinder: R = {h.radius:.6g} ({h.radius_source}); E = {h.youngs_modulus:.6g}, "
             f"nu = {h.poisson_ratio:.6g}, E* = E/(1-nu^2) = {h.e_star:.6g} (plane strain)",
             f"  P = {h.force:.6g} per unit thickness ("
             + ("2 x the pair's normal force: half model, contact on one side of the centre"
                if h.half_model else "the pair's normal force") + ")",
             (f"  analytic: a = sqrt(4PR/(pi E*)) = {h.a:.6g} (a/R = {h.a / h.radius:.4g}), "
              f"p0 = 2P/(pi a) = {h.p0:.6g}" if h.circle is None else
              f"  reference: the half-plane solution for the exact circle R - sqrt(R^2 - x^2) "
              f"(not Hertz's parabola): a = {h.a:.6g} (a/R = {h.a / h.radius:.4g}), "
              f"p(0) = {h.p0:.6g}"),
             f"  relative L2 error over the union of both supports (|x| <= {e.hi / h.a:.4f} a): "
             f"{e.l2:.3%}",
             f"  largest |p - p_ref| / p0 at a slave point: {abs(e.max_deviation):.3%} "
             f"({'+' if e.max_deviation >= 0 else '-'}) at x/a = {e.max_deviation_at:.4f} "
             f"({_zone(e.max_deviation_at)}: within {EDGE_ZONE:.0%} of a from the edge is the "
             f"edge zone)",
             f"  interior (|x| < {1 - EDGE_ZONE:.2f} a): {abs(e.interior_deviation):.3%} at "
             f"x/a = {e.interior_deviation_at:.4f}",
             f"  L2 error split: {e.l2_interior:.3%} from |x| < {1 - EDGE_ZONE:.2f} a, "
             f"{e.l2_edge:.3%} from the edge zone and beyond (squares add up)",
             f"  edge: the profile falls to {EDGE_LEVEL:.0%} of p0 at |x| = {e.edge:.4f} a "
             f"(reference: {e.edge_reference:.4f} a)",
             f"  extra, fit p^2 = p0^2 (1 - x^2/a^2) to the points in contact: a {h.a_error:+.3%}, "
             f"p0 {h.p0_error:+.3%}; largest pressure {h.p_max / h.p0 - 1:+.3%} of p0"]
    if h.friction > 0:
        lines.append(f"  note: friction {h.friction:g}; analytic Hertz is frictionless")
    return lines


def plot_hertz(comparisons: list[HertzComparison], output: str | Path,
               units: Units | None = None) -> Path:
    """The pressure profiles over the analytic one (top) and ``(p - p_Hertz) / p0``
    (bottom). One comparison: absolute axes (``units``: length and pressure labels);
    several: each normalised by its own analytic a and p0, overlaid."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    single = len(comparisons) == 1
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7.5, 6.5), sharex=True,
                                      height_ratios=[2, 1], layout="constrained")
    s = np.linspace(0.0, 1.0, 600)
    h0 = comparisons[0]
    sx, sp = (h0.a, h0.p0) if single else (1.0, 1.0)
    shape = h0.reference_pressure(s * h0.a) / h0.p0
    top.plot(s * sx, shape * sp, "k-", lw=1.8,
             label=f"{h0.reference_name}: a = {h0.a:.4g}, p0 = {h0.p0:.4g}" if single
             else f"{h0.reference_name} (each run's own P)")
    xmax = 0.0
    for h in comparisons:
        keep = np.abs(h.x) <= max(h.error.hi, h.a) * 1.25
        x, p = h.x[keep], h.p[keep]
        xs, ps = (x, p) if single else (x / h.a, p / h.p0)
        label = (f"slave points ({h.configuration} configuration)" if single
                 else f"{h.label}: L2 {h.l2_error:.3%}")
        line, = top.plot(xs, ps, ".-", ms=3.5, lw=0.8, label=label)
        dev = (p - h.reference_pressure(x)) / h.p0
        bottom.plot(xs, 100 * dev, ".-", ms=3, lw=0.8, color=line.get_color())
        xmax = max(xmax, float(np.abs(xs).max()))
    for ax, label in ((top, f"edge zone: a +- {EDGE_ZONE:.0%}"), (bottom, None)):
        ax.axvspan((1 - EDGE_ZONE) * sx, (1 + EDGE_ZONE) * sx, color="0.9", zorder=0,
                   label=label)
        ax.grid(alpha=0.3)
    bottom.axhline(0.0, color="k", lw=0.8)
    top.set_xlim(0.0 if all(h.half_model for h in comparisons) else -xmax, xmax)
    top.set_ylim(bottom=0.0)
    length, pressure = (units or Units()).length, (units or Units()).pressure
    if single:
        top.set_ylabel(f"p per reference length [{pressure}]" if h0.configuration == "reference"
                       else f"p per current length [{pressure}]")
        bottom.set_xlabel(f"x from the centre ({h0.configuration} configuration) [{length}]")
        top.set_title(f"{h0.label}, step {h0.step}: P = {h0.force:.4g}, L2 = {h0.l2_error:.3%}, "
                      f"max dev {abs(h0.error.max_deviation):.2%} of p0", fontsize=10)
    else:
        top.set_ylabel("p / p0 (analytic p0 of each run)")
        bottom.set_xlabel(f"x / a ({h0.configuration} configuration; a analytic for each run)")
        top.set_title(f"{len(comparisons)} runs against {h0.reference_name}", fontsize=10)
    bottom.set_ylabel("(p - p_ref) / p0 [%]")
    top.legend(fontsize=8)
    path = Path(output)
    save_figure(fig, path, dpi=150)
    plt.close(fig)
    return path


def hertz_figure(result: Result, h: HertzComparison, out: str | Path | None = None,
                 output: str | Path | None = None) -> Path:
    """:func:`plot_hertz` of one comparison, by default into
    ``<result>-hertz-<step>.png`` next to the result or in ``out``."""
    return plot_hertz([h], output or output_path(result.path, "hertz", h.step, out),
                      units=result.units)
