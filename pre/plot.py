"""Figures of a body's discretization: control nets and the layer's basis
functions (``python -m pre plot-layout`` and ``python -m pre figures``)."""

from __future__ import annotations

import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import splipy  # noqa: E402

from .files import save_figure  # noqa: E402
from .nurbs import Curve, Patch, eta1_curve, evaluate_patch, unique_knots  # noqa: E402
from .refine import BodyDiscretization, discretize_case  # noqa: E402

FIGURE_CASES = [("ironing", "m1", "N2", "die"), ("ironing", "m1", "NN4", "die"),
                ("ironing", "m1", "NN2.1", "die"), ("ironing", "m1", "NN2.2", "die")]
"""(scene, mesh, layout, body) drawn by ``python -m pre figures``."""


def rational_basis(curve: Curve, t: np.ndarray) -> np.ndarray:
    """Univariate NURBS basis ``w_k N_k(t) / sum_j w_j N_j(t)`` -> (len(t), n)."""
    b = splipy.BSplineBasis(curve.degree + 1, curve.knots)
    n = b.evaluate(np.asarray(t, float)) * curve.weights[None, :]
    return n / n.sum(axis=1, keepdims=True)


def contact_curve(body: BodyDiscretization) -> tuple[Curve, str]:
    """The layer curve, or the bulk's eta = 1 row when there is no layer."""
    if body.layer is not None:
        return body.layer, "layer"
    return eta1_curve(body.bulk), "bulk eta = 1 row"


def _draw_geometry(ax: plt.Axes, patch: Patch, n: int = 400) -> None:
    t = np.linspace(0.0, 1.0, n)
    for xi, eta in ((t, np.zeros(n)), (t, np.ones(n)), (np.zeros(n), t), (np.ones(n), t)):
        p = evaluate_patch(patch, xi, eta)
        ax.plot(p[:, 0], p[:, 1], color="0.6", lw=0.8, zorder=1)


def _draw_net(ax: plt.Axes, cp: np.ndarray, **kw: object) -> None:
    """A control net: cp is (n_eta, n_xi, 2)."""
    color = kw.pop("color", "k")
    for row in cp:
        ax.plot(row[:, 0], row[:, 1], color=color, **kw)
    for col in cp.transpose(1, 0, 2):
        ax.plot(col[:, 0], col[:, 1], color=color, **kw)


def draw_body(fig: plt.Figure, body: BodyDiscretization, title: str) -> None:
    """Two panels: control nets (top) and contact basis functions (bottom)."""
    ax, axb = fig.subplots(2, 1, gridspec_kw={"height_ratios": [3, 2]})
    bulk = body.bulk
    _draw_geometry(ax, bulk)
    _draw_net(ax, bulk.control_points, lw=0.7, ls="-", marker="o", ms=3, zorder=2,
              color="tab:blue")
    curve, label = contact_curve(body)
    if body.layer is not None:
        lp = body.layer.control_points
        ax.plot(lp[:, 0], lp[:, 1], "-s", color="tab:red", ms=3.5, lw=1.0, zorder=3,
                label=f"layer: degree {curve.degree}, {len(lp)} control points")
    ax.plot([], [], "-o", color="tab:blue", ms=3, lw=0.7,
            label=f"bulk: degree {bulk.degree}, {bulk.shape[1]} x {bulk.shape[0]} control points")
    ax.set_aspect("equal")
    ax.set_title(f"{title}   interface {body.interface_dofs} + bulk {body.bulk_dofs} "
                 f"= {body.total_dofs} DOF", fontsize=10)
    ax.legend(fontsize=8, loc="best")
    ax.tick_params(labelsize=8)

    t = np.linspace(0.0, 1.0, 1201)
    basis = rational_basis(curve, t)
    for k in range(basis.shape[1]):
        axb.plot(t, basis[:, k], lw=1.0)
    for kn in unique_knots(curve.knots):
        axb.axvline(kn, color="0.7", lw=0.6, ls=":", zorder=0)
    axb.set_xlim(0, 1)
    axb.set_ylim(0, 1.05)
    axb.set_xlabel("xi (along the contact edge)", fontsize=9)
    axb.set_ylabel("R_k(xi)", fontsize=9)
    axb.set_title(f"contact basis ({label}): degree {curve.degree}, {basis.shape[1]} functions",
                  fontsize=9)
    axb.tick_params(labelsize=8)


def plot_layout(case_path: str | Path, body_name: str, out: str | Path) -> Path:
    """Draw one body of a case to ``out`` (PNG)."""
    disc = discretize_case(case_path)
    if body_name not in disc.bodies:
        raise KeyError(f"no body {body_name!r} in {case_path} (have {list(disc.bodies)})")
    fig = plt.figure(figsize=(8, 7.5), layout="constrained")
    draw_body(fig, disc.bodies[body_name], f"{disc.attrs.get('title', '')}: {body_name}")
    out = Path(out)
    save_figure(fig, out, dpi=130, metadata={"Software": None})
    plt.close(fig)
    return out


def plot_bases(cases: list[tuple[str, BodyDiscretization]], out: str | Path) -> Path:
    """Stacked contact-basis panels of several layouts (cf. the paper's Figs. 3-4)."""
    fig, axes = plt.subplots(len(cases), 1, figsize=(8, 1.9 * len(cases)), sharex=True,
                             layout="constrained")
    t = np.linspace(0.0, 1.0, 1201)
    for ax, (label, body) in zip(np.atleast_1d(axes), cases, strict=True):
        curve, what = contact_curve(body)
        basis = rational_basis(curve, t)
        for k in range(basis.shape[1]):
            ax.plot(t, basis[:, k], lw=1.0)
        for kn in unique_knots(curve.knots):
            ax.axvline(kn, color="0.7", lw=0.6, ls=":", zorder=0)
        ax.set_ylim(0, 1.05)
        ax.set_title(f"{label}: {what}, degree {curve.degree}, {basis.shape[1]} functions, "
                     f"interface {body.interface_dofs} DOF", fontsize=9)
        ax.tick_params(labelsize=8)
    np.atleast_1d(axes)[-1].set_xlabel("xi (along the contact edge)")
    save_figure(fig, out, dpi=130, metadata={"Software": None})
    plt.close(fig)
    return Path(out)


def write_figures(out_dir: str | Path) -> list[Path]:
    """The figures of docs/figures/ (cases generated afresh in a temp dir)."""
    from .cases import write_cases  # local: keeps plot importable on its own

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    with tempfile.TemporaryDirectory() as tmp:
        write_cases(tmp)
        stack = []
        for scene, mesh, layout, body in FIGURE_CASES:
            case = Path(tmp) / scene / f"{mesh}-{layout}.nml"
            written.append(plot_layout(case, body, out_dir / f"{scene}-{body}-{mesh}-{layout}.png"))
            stack.append((layout, discretize_case(case).bodies[body]))
        written.append(plot_bases(stack, out_dir / "ironing-die-m1-bases.png"))
    return written
