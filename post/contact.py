"""Contact measures: the Hertz line-contact reference, fits and errors of the contact
pressure, and the p_N / p_T plot along the contact (``python -m post plot-contact``)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pre.nurbs import Curve, curve_to_splipy

from .naming import output_path
from .reader import Body, ContactOutput, Result


@dataclass
class HertzComparison:
    """Simulated contact pressure against the analytic Hertz line contact."""

    force: float
    """P: total force per unit length of the full cylinder (twice the quarter model's)."""
    a: float
    """Analytic half-width sqrt(4 P R / (pi E*))."""
    p0: float
    """Analytic peak pressure 2 P / (pi a)."""
    a_fit: float
    """Half-width of the simulated pressure: least-squares fit of p^2 = p0^2 (1 - x^2/a^2)."""
    p0_fit: float
    """Peak of that fit."""
    p_max: float
    """Largest simulated pressure at a slave point."""
    l2_error: float
    """Relative L2 error of p/p_max against the analytic sqrt(1 - (x/a)^2), over x/a in [0, 1]."""

    @property
    def a_error(self) -> float:
        return self.a_fit / self.a - 1.0

    @property
    def p0_error(self) -> float:
        return self.p0_fit / self.p0 - 1.0


def hertz_reference(force: float, youngs_modulus: float, poisson_ratio: float,
                    radius: float) -> tuple[float, float]:
    """Half-width and peak pressure of the Hertz line contact of a cylinder on a rigid flat
    (plane strain: E* = E / (1 - nu^2)), for the total force per length ``force``."""
    e_star = youngs_modulus / (1.0 - poisson_ratio**2)
    a = np.sqrt(4.0 * force * radius / (np.pi * e_star))
    return float(a), float(2.0 * force / (np.pi * a))


def fit_hertz(x: np.ndarray, p: np.ndarray) -> tuple[float, float]:
    """Fit p(x)^2 = p0^2 (1 - x^2/a^2) (linear in x^2) to the active points; (a, p0)."""
    design = np.vstack([np.ones_like(x), x**2]).T
    (c0, c1), *_ = np.linalg.lstsq(design, p**2, rcond=None)
    if c0 <= 0 or c1 >= 0:
        raise ValueError("the contact pressure does not look like a Hertz profile")
    return float(np.sqrt(-c0 / c1)), float(np.sqrt(c0))


def normalized_l2_error(x: np.ndarray, p: np.ndarray, a: float) -> float:
    """Relative L2 error of p/p_max against sqrt(1 - (x/a)^2) over x/a in [0, 1].

    The simulated profile (sorted in x, linear between slave points, zero beyond the
    last one) and the reference are compared on 2001 points of x/a in [0, 1]; this is
    our form of the paper's normalised error (its Eq. 37 is lost; see docs/validation.md).
    """
    order = np.argsort(x)
    xs, ps = np.abs(x[order]) / a, p[order] / np.max(p)
    s = np.linspace(0.0, 1.0, 2001)
    sim = np.interp(s, xs, ps, left=ps[0], right=0.0)
    ref = np.sqrt(np.clip(1.0 - s**2, 0.0, None))
    return float(np.sqrt(np.trapezoid((sim - ref) ** 2, s) / np.trapezoid(ref**2, s)))


def hertz_comparison(result: Result, step: int = -1, pair: int = 0, radius: float = 1.0,
                     centre_x: float = 0.0) -> HertzComparison:
    """Compare the hertz scene's contact pressure with the analytic solution, using the
    simulated total force (doubled: the model is a quarter with a symmetry cut)."""
    st = result.steps[step]
    c = st.contact[pair]
    body = result.body(c.slave)
    e = float(body.attrs["youngs_modulus"])
    nu = float(body.attrs["poisson_ratio"])
    force = 2.0 * abs(float(c.force[1]))
    a, p0 = hertz_reference(force, e, nu, radius)
    x = c.x[c.active, 0] - centre_x
    p = c.p_n[c.active]
    a_fit, p0_fit = fit_hertz(x, p)
    return HertzComparison(force=force, a=a, p0=p0, a_fit=a_fit, p0_fit=p0_fit,
                           p_max=float(p.max()), l2_error=normalized_l2_error(x, p, a))


def slave_edge_curve(body: Body) -> tuple[Curve, np.ndarray]:
    """The slave body's contact edge as a curve in the reference configuration (the
    VO layer, else the bulk's eta = 1 row) and its control points' 0-based body ids
    (the edge in ``body.edges`` that lists them)."""
    if body.layer is not None:
        curve = body.layer
    else:
        b = body.bulk
        curve = Curve(degree=b.degree[0], knots=b.knots_xi, control_points=b.control_points[-1],
                      weights=b.weights[-1])
    for ids in body.edges.values():
        if len(ids) == len(curve.weights) and np.allclose(body.control_points[ids],
                                                          curve.control_points, atol=1e-12):
            return curve, ids
    raise ValueError(f"body {body.name!r}: no edge lists the contact edge's control points")


def pressure_field(result: Result, step: int = -1, pair: int = 0, per_span: int = 64,
                   params: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The penalty contact pressure as the continuous field it is along the slave
    curve, p = eps_N <-g>, g = (x - p0) . n, for a pair with a rigid master line:
    current points ``(m, 2)`` and pressures ``(m,)`` at ``per_span`` parameters per
    knot span of the slave's contact edge (ends included). Unlike the per-Gauss-point
    output, this does not depend on where the quadrature points lie. ``params``:
    evaluate at these parameters of the edge instead."""
    st = result.steps[step] if step != 0 else None
    if st is None:
        raise ValueError("pressure_field needs a converged step")
    c = st.contact[pair]
    if c.rigid_point is None or c.rigid_normal is None:
        raise ValueError("pressure_field: only for a rigid master line")
    eps = float(c.attrs["penalty_normal"])
    body = result.bodies[c.slave]
    curve, ids = slave_edge_curve(body)
    u = np.asarray(st.displacement[body.dofs]).reshape(-1, 2)
    moved = Curve(degree=curve.degree, knots=curve.knots,
                  control_points=curve.control_points + u[ids], weights=curve.weights)
    breaks = np.unique(curve.knots)
    t = np.unique(np.concatenate([np.linspace(a, b, per_span) for a, b in zip(breaks[:-1], breaks[1:])])) \
        if params is None else np.asarray(params, dtype=float)
    x = np.asarray(curve_to_splipy(moved)(t), dtype=float).reshape(-1, 2)
    gap = (x - c.rigid_point) @ c.rigid_normal
    return x, eps * np.maximum(0.0, -gap)


def contact_profile(c: ContactOutput, axis: int = 0,
                    margin: int = 3) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Current position along ``axis`` (sorted), p_N and p_T of one pair's slave points
    around the contact zone: in the slave parameter's order, from ``margin`` points
    before the first point in contact to ``margin`` points after the last (all points
    when none is in contact). Points elsewhere on the slave edge (e.g. the far side
    of a ring, at the same x) would otherwise interleave with the zone's."""
    along = np.argsort(c.xi_slave, kind="stable")
    act = np.flatnonzero(c.active[along])
    if act.size:
        along = along[max(0, act[0] - margin):act[-1] + margin + 1]
    order = along[np.argsort(c.x[along, axis], kind="stable")]
    return c.x[order, axis], c.p_n[order], c.p_t[order]


def plot_contact(result: Result, step: int = -1, output: str | Path | None = None,
                 axis: int = 0, out: str | Path | None = None) -> Path:
    """p_N and p_T of every contact pair along the contact (current ``axis`` coordinate);
    default file ``<result>-contact-<step>.png`` next to the result or in ``out``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    st = result.steps[step]
    fig, ax = plt.subplots(figsize=(7.0, 4.0), constrained_layout=True)
    for c in st.contact:
        x, pn, pt = contact_profile(c, axis)
        label = f"{c.slave} on {c.master}"
        ax.plot(x, pn, "o-", ms=3, label=f"$p_N$ {label}")
        if np.any(pt != 0.0):
            ax.plot(x, pt, "s--", ms=3, label=f"$p_T$ {label}")
    active = np.concatenate([c.x[c.active, axis] for c in st.contact]) if st.contact else np.zeros(0)
    if active.size:
        lo, hi = active.min(), active.max()
        pad = 0.25 * max(hi - lo, 1e-12)
        ax.set_xlim(lo - pad, hi + pad)
    units = result.units
    ax.set_xlabel(f"{'xy'[axis]} (current) [{units.length}]")
    ax.set_ylabel(f"contact traction [{units.pressure}]")
    ax.set_title(f"{result.title}: step {st.step} (load time {st.time:g})")
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.legend()
    path = Path(output) if output else output_path(result.path, "contact", st.step, out)
    fig.savefig(path, dpi=150)
    plt.close(fig)
    return path


def format_hertz(h: HertzComparison) -> str:
    """The one-line summary ``python -m post hertz`` prints."""
    return (f"P = {h.force:.6g}  a = {h.a:.6g} (fit {h.a_fit:.6g}, {h.a_error:+.2%})  "
            f"p0 = {h.p0:.6g} (fit {h.p0_fit:.6g}, {h.p0_error:+.2%}; max {h.p_max:.6g})  "
            f"L2(p/pmax) = {h.l2_error:.4g}")


def plot_hertz(result: Result, step: int = -1, output: str | Path | None = None,
               out: str | Path | None = None, radius: float = 1.0) -> Path:
    """The hertz scene's contact pressure against the analytic Hertz line contact:
    the pressure at the slave points, the continuous penalty pressure along the slave
    edge, the analytic ``p0 sqrt(1 - x^2/a^2)`` for the simulated force, and the fit
    :func:`hertz_comparison` reports; default file ``<result>-hertz-<step>.png``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    st = result.steps[step]
    h = hertz_comparison(result, step, radius=radius)
    c = st.contact[0]
    units = result.units
    fig, ax = plt.subplots(figsize=(7.5, 4.5), layout="constrained")
    s = np.linspace(0.0, 1.0, 400)
    ax.plot(h.a * s, h.p0 * np.sqrt(1.0 - s**2), "k-", lw=1.6,
            label=f"analytic Hertz: a = {h.a:.4g}, p0 = {h.p0:.4g}")
    ax.plot(h.a_fit * s, h.p0_fit * np.sqrt(1.0 - s**2), ":", color="tab:green", lw=1.4,
            label=f"fit: a {h.a_error:+.2%}, p0 {h.p0_error:+.2%}")
    if c.rigid_point is not None:
        xf, pf = pressure_field(result, step)
        order = np.argsort(xf[:, 0])
        ax.plot(xf[order, 0], pf[order], "-", color="tab:blue", lw=0.9, alpha=0.8,
                label="penalty pressure along the slave edge")
    x, pn, _ = contact_profile(c)
    ax.plot(x, pn, "o", ms=3.5, mfc="white", color="tab:red",
            label=f"slave points ({int(np.count_nonzero(c.active))} in contact)")
    ax.set_xlim(0.0, 1.5 * max(h.a, h.a_fit))
    ax.set_ylim(bottom=0.0)
    ax.set_xlabel(f"x (current) [{units.length}]")
    ax.set_ylabel(f"contact pressure p_N [{units.pressure}]")
    ax.set_title(f"{result.title}: step {st.step}, P = {h.force:.4g} {units.line_force}, "
                 f"L2(p/pmax) = {h.l2_error:.3g}", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    path = Path(output) if output else output_path(result.path, "hertz", st.step, out)
    fig.savefig(path, dpi=150)
    plt.close(fig)
    return path
