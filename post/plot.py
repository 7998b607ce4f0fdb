"""Figures of result files (``python -m post plot-deformed``).

Every body is drawn in its current configuration ``X + scale * u`` (exact
VO map of :mod:`post.field`, sampled on a parametric grid that contains every
element boundary), coloured by the displacement magnitude ``|u|`` with
Gouraud shading, with the deformed element boundaries as thin lines and one
colorbar shared by all bodies.
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.colors import Normalize  # noqa: E402

from .field import displacement, evaluate_grid  # noqa: E402
from .reader import Body, Result, body_displacement, read_result  # noqa: E402

CMAP = "turbo"
"""Colour map of the contour plots (FE-style rainbow, perceptually ordered)."""

MIN_SAMPLES = 120
"""At least this many samples along each parametric direction of a body."""


def breakpoints(body: Body) -> tuple[np.ndarray, np.ndarray]:
    """Distinct element boundaries ``(xi values, eta values)`` of a body."""
    r = body.element_ranges
    return np.unique(r[:, :2]), np.unique(r[:, 2:])


def sample_parameters(breaks: np.ndarray, minimum: int = MIN_SAMPLES) -> np.ndarray:
    """Parameters that subdivide every span of ``breaks`` uniformly into the
    same number (>= 4) of parts, at least ``minimum`` in total."""
    spans = max(len(breaks) - 1, 1)
    n = max(4, int(np.ceil(minimum / spans)))
    parts = [np.linspace(a, b, n + 1)[:-1] for a, b in zip(breaks[:-1], breaks[1:])]
    return np.concatenate(parts + [breaks[-1:]])


def deformed_grid(body: Body, u_body: np.ndarray, scale: float = 1.0,
                  minimum: int = MIN_SAMPLES) -> tuple[np.ndarray, np.ndarray]:
    """``(points (n_eta, n_xi, 2), |u| (n_eta, n_xi))`` on the sampling grid:
    points are ``X + scale * u``, the magnitude is of the true ``u``."""
    bx, be = breakpoints(body)
    xi, eta = sample_parameters(bx, minimum), sample_parameters(be, minimum)
    xx, ee = np.meshgrid(xi, eta)
    ref = evaluate_grid(body, None, xi, eta)
    u = displacement(body, u_body, xx, ee)
    return ref + scale * u, np.linalg.norm(u, axis=-1)


def element_edges(body: Body, u_body: np.ndarray, scale: float = 1.0,
                  n: int = 200) -> list[np.ndarray]:
    """Deformed element boundaries as polylines ``(n, 2)``: lines xi = const
    and eta = const at every element breakpoint."""
    bx, be = breakpoints(body)
    t = np.linspace(0.0, 1.0, n)
    u = u_body * scale
    lines = [evaluate_grid(body, u, [x], t)[:, 0] for x in bx]
    lines += [evaluate_grid(body, u, t, [e])[0] for e in be]
    return lines


def _title(result: Result, step: int, time: float | None, scale: float) -> str:
    title = result.title or result.path.name
    where = "reference configuration" if time is None else \
        f"step {step} of {result.n_steps_planned or len(result.steps)}, load time {time:g}"
    text = f"{title}: {where}"
    if scale != 1.0:
        text += f", displacement x {scale:g}"
    if not result.converged:
        status = textwrap.shorten(result.status or "unknown status", 200, placeholder=" ...")
        text += "\n" + textwrap.fill(f"[run {status}]", 110)
    return text


def plot_deformed(result: Result | str | Path, step: int = -1, output: str | Path | None = None,
                  scale: float = 1.0, length_unit: str = "mm", reference: bool = False,
                  minimum: int = MIN_SAMPLES) -> Path:
    """Draw every body of ``result`` deformed at ``step`` (selection as in
    :meth:`post.reader.Result.select_step`) and write a PNG.

    ``output`` defaults to ``<result>-deformed-<step>.png`` next to the
    result file. ``reference=True`` adds the undeformed outlines (dashed).
    Returns the path written.
    """
    if not isinstance(result, Result):
        result = read_result(result)
    if not result.bodies:
        raise ValueError(f"{result.path}: no bodies")
    s = result.select_step(step)
    number = 0 if s is None else s.step
    if output is None:
        output = result.path.with_name(f"{result.path.stem}-deformed-{number:06d}.png")
    output = Path(output)

    grids = {}
    for name, body in result.bodies.items():
        u = body_displacement(result, name, number if s is not None else 0)
        grids[name] = (body, u, *deformed_grid(body, u, scale, minimum))
    vmax = max(float(g[3].max()) for g in grids.values())
    norm = Normalize(vmin=0.0, vmax=vmax if vmax > 0 else 1.0)

    allpts = np.concatenate([g[2].reshape(-1, 2) for g in grids.values()])
    lo, hi = allpts.min(axis=0), allpts.max(axis=0)
    span = np.maximum(hi - lo, 1e-12)
    width = 10.0
    height = float(np.clip(width * 0.85 * span[1] / span[0] + 1.4, 3.5, 11.0))
    fig, ax = plt.subplots(figsize=(width, height), layout="constrained")
    mesh = None
    for name, (body, u, pts, mag) in grids.items():
        mesh = ax.pcolormesh(pts[..., 0], pts[..., 1], mag, shading="gouraud", cmap=CMAP,
                             norm=norm, rasterized=True)
        mesh.sticky_edges.x[:] = []  # let the margins show the outline
        mesh.sticky_edges.y[:] = []
        lines = element_edges(body, u, scale)
        ax.add_collection(LineCollection(lines, colors="k", linewidths=0.35, alpha=0.7))
        outline = [pts[0], pts[-1], pts[:, 0], pts[:, -1]]
        ax.add_collection(LineCollection(outline, colors="k", linewidths=0.9))
        if reference:
            ref = evaluate_grid(body, None, sample_parameters(np.array([0.0, 1.0]), minimum),
                                sample_parameters(np.array([0.0, 1.0]), minimum))
            ax.add_collection(LineCollection([ref[0], ref[-1], ref[:, 0], ref[:, -1]],
                                             colors="0.45", linewidths=0.8, linestyles="--"))
        centre = pts[pts.shape[0] // 2, pts.shape[1] // 2]
        ax.annotate(name, centre, ha="center", va="center", fontsize=9,
                    bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="0.5", alpha=0.8))
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.margins(0.03)
    ax.set_xlabel(f"x [{length_unit}]")
    ax.set_ylabel(f"y [{length_unit}]")
    ax.set_title(_title(result, number, None if s is None else s.time, scale), fontsize=10)
    cbar = fig.colorbar(mesh, ax=ax, shrink=0.9, pad=0.02)
    cbar.set_label(f"displacement magnitude |u| [{length_unit}]")
    output.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(output, dpi=150)
    plt.close(fig)
    return output
