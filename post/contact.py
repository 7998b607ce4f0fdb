"""Contact measures: the Hertz line-contact reference, fits and errors of the contact
pressure, and the p_N / p_T plot along the contact (``python -m post plot-contact``)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .reader import ContactOutput, Result


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


def contact_profile(c: ContactOutput, axis: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Current position along ``axis`` (sorted), p_N and p_T of one pair's slave points."""
    order = np.argsort(c.x[:, axis])
    return c.x[order, axis], c.p_n[order], c.p_t[order]


def plot_contact(result: Result, step: int = -1, output: str | Path | None = None,
                 axis: int = 0, unit: str = "mm") -> Path:
    """p_N and p_T of every contact pair along the contact (current ``axis`` coordinate)."""
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
    ax.set_xlabel(f"{'xy'[axis]} (current) [{unit}]")
    ax.set_ylabel("contact traction [force/length]")
    ax.set_title(f"{result.title}: step {st.step} (load time {st.time:g})")
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.legend()
    out = Path(output) if output else result.path.with_name(f"{result.path.stem}-contact-{st.step}.png")
    fig.savefig(out, dpi=150)
    plt.close(fig)
    return out
