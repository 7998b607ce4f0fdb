"""Figures of result files (``python -m post plot-deformed``).

Every body is drawn in its current configuration ``X + scale * u`` (exact
VO map of :mod:`post.field`, sampled on a parametric grid that contains every
element boundary), coloured by a quantity (:mod:`post.quantity`: the displacement
magnitude ``|u|`` by default, a component, or a sampled stress or strain field such
as the von Mises stress) with Gouraud shading, with the deformed element boundaries
as thin lines and a colour scale per body (or one shared by all). The scale is
chosen automatically when the displacements are small (:func:`auto_scale`; the
title says the factor); rigid masters (lines and curves) are drawn moved by their
prescribed motion times the same factor, so that they sit on the bodies they
touch; when bodies are in contact a second panel shows the contact zone at true
scale. A result of solids (dimension 3) is drawn by :mod:`post.plot3d` instead: a 3D
view of the bodies' boundaries.
"""

from __future__ import annotations

import textwrap
from itertools import pairwise
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.colors import Normalize  # noqa: E402

from pre.files import save_figure  # noqa: E402
from pre.nurbs import curve_to_splipy  # noqa: E402

from .field import displacement, evaluate_grid  # noqa: E402
from .naming import output_path  # noqa: E402
from .quantity import DISPLACEMENT, check_name, displacement_quantity, label, sampled_quantity, signed  # noqa: E402
from .reader import Body, ContactOutput, Result, Step, body_displacement, read_result  # noqa: E402

CMAP = "turbo"
"""Colour map of the contour plots (FE-style rainbow, perceptually ordered)."""

MIN_SAMPLES = 120
"""At least this many samples along each parametric direction of a body."""

VISIBLE = 0.02
"""Displacements below this fraction of the scene's size are magnified (auto scale)."""

TARGET = 0.1
"""The auto scale magnifies the largest displacement to about this fraction of the size."""


def breakpoints(body: Body) -> tuple[np.ndarray, ...]:
    """Distinct element boundaries of a body in each parametric direction: ``(xi
    values, eta values)``, of a solid ``(xi values, eta values, zeta values)``."""
    r = body.element_ranges
    return tuple(np.unique(r[:, 2 * d:2 * d + 2]) for d in range(r.shape[1] // 2))


def sample_parameters(breaks: np.ndarray, minimum: int = MIN_SAMPLES) -> np.ndarray:
    """Parameters that subdivide every span of ``breaks`` uniformly into the
    same number (>= 4) of parts, at least ``minimum`` in total."""
    spans = max(len(breaks) - 1, 1)
    n = max(4, int(np.ceil(minimum / spans)))
    parts = [np.linspace(a, b, n + 1)[:-1] for a, b in pairwise(breaks)]
    return np.concatenate(parts + [breaks[-1:]])


def sampled_field(body: Body, u_body: np.ndarray,
                  minimum: int = MIN_SAMPLES) -> tuple[np.ndarray, np.ndarray]:
    """``(X (n_eta, n_xi, 2), u (n_eta, n_xi, 2))``: reference points and the
    displacement field on the sampling grid (every element boundary included)."""
    bx, be = breakpoints(body)
    xi, eta = sample_parameters(bx, minimum), sample_parameters(be, minimum)
    xx, ee = np.meshgrid(xi, eta)
    return evaluate_grid(body, None, xi, eta), displacement(body, u_body, xx, ee)


def quantity_grid(body: Body, step: Step | None, u_pts: np.ndarray, name: str,
                  minimum: int = MIN_SAMPLES) -> np.ndarray:
    """The quantity ``name`` (:mod:`post.quantity`) on the sampling grid of
    :func:`sampled_field` (``u_pts``: the displacement there)."""
    if name in ("u", "ux", "uy"):
        return displacement_quantity(name, u_pts)
    if step is None:
        raise ValueError(f"--field {name}: the reference configuration (step 0) has no stress")
    bx, be = breakpoints(body)
    xx, ee = np.meshgrid(sample_parameters(bx, minimum), sample_parameters(be, minimum))
    return sampled_quantity(step, body, name, xx, ee)


def colour_norms(values: dict[str, np.ndarray], name: str, per_body: bool) -> dict[str, Normalize]:
    """The colour scale of each body: its own range (``per_body``) or the range of
    all; from 0 for a magnitude, symmetric about 0 for a quantity of both signs
    whose range holds 0 (so that 0 has one colour)."""
    def norm(vals: list[np.ndarray]) -> Normalize:
        lo = min(float(np.nanmin(v)) for v in vals)
        hi = max(float(np.nanmax(v)) for v in vals)
        if not signed(name):
            lo = 0.0
        elif lo < 0.0 < hi:
            lo, hi = -max(-lo, hi), max(-lo, hi)
        if hi <= lo:
            hi = lo + (abs(lo) if lo else 1.0)
        return Normalize(vmin=lo, vmax=hi)
    if per_body:
        return {b: norm([v]) for b, v in values.items()}
    shared = norm(list(values.values()))
    return {b: shared for b in values}


def deformed_grid(body: Body, u_body: np.ndarray, scale: float = 1.0,
                  minimum: int = MIN_SAMPLES) -> tuple[np.ndarray, np.ndarray]:
    """``(points (n_eta, n_xi, 2), |u| (n_eta, n_xi))`` on the sampling grid:
    points are ``X + scale * u``, the magnitude is of the true ``u``."""
    ref, u = sampled_field(body, u_body, minimum)
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


def figure_name(field: str) -> str:
    """The ``<what>`` of a plot-deformed file name: ``deformed`` for ``|u|``, else the
    quantity (``von_mises``: ``<result>-von_mises-<step>.png``)."""
    return "deformed" if field == "u" else field


def auto_scale(size: float, u_max: float, visible: float = VISIBLE, target: float = TARGET) -> float:
    """Displacement magnification for a scene of extent ``size`` whose largest
    displacement is ``u_max``: 1 when ``u_max >= visible * size`` (or no
    displacement), else the largest of 1, 2, 5 x 10^k that keeps
    ``scale * u_max <= target * size``."""
    if u_max <= 0.0 or size <= 0.0 or u_max >= visible * size:
        return 1.0
    raw = target * size / u_max
    k = np.floor(np.log10(raw))
    mant = max(m for m in (1.0, 2.0, 5.0) if m * 10**k <= raw * (1 + 1e-12))
    return float(max(1.0, mant * 10**k))


def rigid_lines(step: Step | None) -> list[tuple[np.ndarray, np.ndarray, str]]:
    """``(point, unit outward normal, label)`` of every rigid master line of a step
    (from the result file's contact output; none at the reference configuration)."""
    if step is None:
        return []
    out = []
    for c in step.contact:
        if c.rigid_point is not None and c.rigid_normal is not None:
            n = np.asarray(c.rigid_normal, dtype=float)
            out.append((np.asarray(c.rigid_point, dtype=float), n / np.linalg.norm(n),
                        f"rigid master of {c.slave}"))
    return out


def draw_rigid_line(ax: plt.Axes, point: np.ndarray, normal: np.ndarray, depth: float,
                    reach: float, label: str | None = None, style: str = "-") -> None:
    """A rigid line (through ``point``, outward ``normal``) as a thick line with a
    hatched band of ``depth`` on its solid side, ``reach`` long either way."""
    t = np.array([-normal[1], normal[0]])
    a, b = point - reach * t, point + reach * t
    band = np.array([a, b, b - depth * normal, a - depth * normal])
    ax.fill(band[:, 0], band[:, 1], facecolor="0.85", edgecolor="0.35", hatch="///", lw=0.0,
            zorder=0.5)
    ax.plot([a[0], b[0]], [a[1], b[1]], style, color="0.15", lw=1.6, label=label, zorder=3)


def rigid_curves(step: Step | None, n: int = 400) -> list[tuple[np.ndarray, np.ndarray, str]]:
    """``(points (n, 2), unit outward normals (n, 2), label)`` of every rigid master
    curve of a step, where it is at that step (none at the reference configuration)."""
    if step is None:
        return []
    out = []
    for c in step.contact:
        if c.rigid_curve is None:
            continue
        spline = curve_to_splipy(c.rigid_curve)
        t = np.linspace(0.0, 1.0, n)
        pts = np.asarray(spline(t))[:, :2]
        a = np.asarray(spline.derivative(t))[:, :2]
        normal = np.column_stack([a[:, 1], -a[:, 0]]) / np.linalg.norm(a, axis=1)[:, None]
        out.append((pts, normal, f"rigid master of {c.slave}"))
    return out


def draw_rigid_curve(ax: plt.Axes, points: np.ndarray, normals: np.ndarray, depth: float,
                     label: str | None = None, style: str = "-") -> None:
    """A rigid obstacle's boundary as a thick curve with a hatched band of ``depth``
    on the obstacle's side (opposite its outward ``normals``)."""
    inner = points - depth * normals
    band = np.concatenate([points, inner[::-1]])
    ax.fill(band[:, 0], band[:, 1], facecolor="0.85", edgecolor="0.35", hatch="///", lw=0.0,
            zorder=0.5)
    ax.plot(points[:, 0], points[:, 1], style, color="0.15", lw=1.6, label=label, zorder=3)


def contact_points(step: Step | None) -> list[ContactOutput]:
    """The contact pairs of a step that have points in contact."""
    return [] if step is None else [c for c in step.contact if np.any(c.active)]


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


def _draw_bodies(ax: plt.Axes, grids: dict, norms: dict[str, Normalize], scale: float, reference: bool,
                 minimum: int, names: bool = True) -> dict:
    """Every body on ``ax``: the coloured sampling grid, element edges, outline;
    returns each body's coloured mesh."""
    meshes = {}
    for name, (body, u, ref_pts, u_pts, values) in grids.items():
        pts = ref_pts + scale * u_pts
        mesh = ax.pcolormesh(pts[..., 0], pts[..., 1], values, shading="gouraud", cmap=CMAP,
                             norm=norms[name], rasterized=True)
        meshes[name] = mesh
        mesh.sticky_edges.x[:] = []  # let the margins show the outline
        mesh.sticky_edges.y[:] = []
        ax.add_collection(LineCollection(element_edges(body, u, scale), colors="k",
                                         linewidths=0.35, alpha=0.7))
        outline = [pts[0], pts[-1], pts[:, 0], pts[:, -1]]
        ax.add_collection(LineCollection(outline, colors="k", linewidths=0.9))
        if reference:
            ref = evaluate_grid(body, None, sample_parameters(np.array([0.0, 1.0]), minimum),
                                sample_parameters(np.array([0.0, 1.0]), minimum))
            ax.add_collection(LineCollection([ref[0], ref[-1], ref[:, 0], ref[:, -1]],
                                             colors="0.45", linewidths=0.8, linestyles="--"))
        if names:
            centre = pts[pts.shape[0] // 2, pts.shape[1] // 2]
            ax.annotate(name, centre, ha="center", va="center", fontsize=9,
                        bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="0.5", alpha=0.8))
    return meshes


def _zoom_window(pairs: list[ContactOutput], size: float) -> tuple[np.ndarray, np.ndarray]:
    """Centre and half-extents of a window around the points in contact."""
    pts = np.concatenate([c.x[c.active] for c in pairs])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    half = max(0.5 * float(np.max(hi - lo)) * 1.6, 0.02 * size)
    return 0.5 * (lo + hi), np.array([half, 0.6 * half])


def plot_deformed(result: Result | str | Path, step: int = -1, output: str | Path | None = None,
                  scale: float | str = "auto", length_unit: str | None = None,
                  reference: bool = False, minimum: int = MIN_SAMPLES,
                  zoom: bool = True, field: str = "u", colour_scale: str | None = None) -> Path:
    """Draw every body of ``result`` deformed at ``step`` (selection as in
    :meth:`post.reader.Result.select_step`) and write a PNG (:func:`deformed_figure`).
    ``output`` defaults to ``<result>-<deformed or the field>-<step>.png`` next to
    the result file. Returns the path written."""
    if not isinstance(result, Result):
        result = read_result(result)
    fig, _ = deformed_figure(result, step, scale, length_unit, reference, minimum, zoom, field, colour_scale)
    s = result.select_step(step)
    output = Path(output) if output is not None else \
        output_path(result.path, figure_name(field), 0 if s is None else s.step)
    output.parent.mkdir(parents=True, exist_ok=True)
    save_figure(fig, output, dpi=150)
    plt.close(fig)
    return output


def deformed_figure(result: Result, step: int = -1, scale: float | str = "auto",
                    length_unit: str | None = None, reference: bool = False, minimum: int = MIN_SAMPLES,
                    zoom: bool = True, field: str = "u",
                    colour_scale: str | None = None) -> tuple[plt.Figure, dict]:
    """The figure of every body of ``result`` deformed at ``step`` (selection as in
    :meth:`post.reader.Result.select_step`) and each body's coloured mesh on the
    main panel.

    ``scale``: displacement magnification, or ``'auto'`` (:func:`auto_scale`).
    ``length_unit``: axis unit (default: the file's, :attr:`Result.units`).
    ``reference=True`` adds the undeformed outlines (dashed). ``zoom``: when
    bodies are in contact, a second panel shows the contact zone at true scale.
    ``field``: the colouring (:data:`post.quantity.QUANTITIES`; a stress or strain
    needs a step with sampled fields). ``colour_scale``: ``'body'`` (each body its
    own range and colour bar: a body that translates far does not flatten the
    others) or ``'shared'``; default ``'body'`` for a displacement, ``'shared'``
    for a stress or strain (continuous across bodies in contact). Rigid masters (lines,
    curves) are drawn in both panels, in the first moved by their prescribed motion
    times ``scale``.
    """
    if not result.bodies:
        raise ValueError(f"{result.path}: no bodies")
    check_name(field, result.dimension)
    if result.dimension == 3:  # solids: a 3D view of the boundary (post/plot3d.py)
        from .plot3d import solid_figure

        return solid_figure(result, step, scale, length_unit, reference, field, colour_scale)
    if colour_scale is None:
        colour_scale = "body" if field in DISPLACEMENT else "shared"
    if colour_scale not in ("body", "shared"):
        raise ValueError(f"colour scale {colour_scale!r}: 'body' or 'shared'")
    s = result.select_step(step)
    number = 0 if s is None else s.step
    unit = length_unit or result.units.length

    grids = {}
    for name, body in result.bodies.items():
        u = body_displacement(result, name, number if s is not None else 0)
        ref_pts, u_pts = sampled_field(body, u, minimum)
        grids[name] = (body, u, ref_pts, u_pts, quantity_grid(body, s, u_pts, field, minimum))
    norms = colour_norms({n: g[4] for n, g in grids.items()}, field, colour_scale == "body")
    vmax = max(float(np.linalg.norm(g[3], axis=-1).max()) for g in grids.values())
    allpts = np.concatenate([(g[2] + g[3]).reshape(-1, 2) for g in grids.values()])
    lo, hi = allpts.min(axis=0), allpts.max(axis=0)
    size = float(np.max(hi - lo))
    if scale == "auto":
        scale = auto_scale(size, vmax)
    scale = float(scale)

    pairs = contact_points(s) if zoom else []
    span = np.maximum(hi - lo, 1e-12)
    width = 10.0
    height = float(np.clip(width * 0.85 * span[1] / span[0] + 1.4, 3.5, 11.0))
    if pairs:
        fig, (ax, axz) = plt.subplots(1, 2, figsize=(width * 1.45, max(height, 4.5)),
                                      layout="constrained", width_ratios=[2.0, 1.0])
    else:
        fig, ax = plt.subplots(figsize=(width, height), layout="constrained")
        axz = None
    meshes = _draw_bodies(ax, grids, norms, scale, reference, minimum)
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.margins(0.03)
    lines, curves = _draw_rigid_masters(ax, s, scale, size)
    ax.set_xlabel(f"x [{unit}]")
    ax.set_ylabel(f"y [{unit}]")
    ax.set_title(_title(result, number, None if s is None else s.time, scale), fontsize=10)
    if axz is not None:
        _draw_bodies(axz, grids, norms, 1.0, False, minimum, names=False)
        centre, half = _zoom_window(pairs, size)
        for p, n, _ in lines:
            draw_rigid_line(axz, p, n, 0.15 * half[1], 3.0 * size)
        for pts, n, _ in curves:
            draw_rigid_curve(axz, pts, n, 0.15 * half[1])
        for c in pairs:
            axz.plot(c.x[c.active, 0], c.x[c.active, 1], "o", ms=3.5, mfc="white", mec="crimson",
                     mew=0.6, label=f"{c.slave}: points in contact")
        axz.set_xlim(centre[0] - half[0], centre[0] + half[0])
        axz.set_ylim(centre[1] - half[1], centre[1] + half[1])
        axz.set_aspect("equal", adjustable="box")
        axz.set_xlabel(f"x [{unit}]")
        axz.set_title("contact zone, true scale", fontsize=10)
        axz.legend(loc="upper right", fontsize=8)
    axes = [ax] if axz is None else [ax, axz]
    text = label(field, result.units)
    if colour_scale == "shared" or len(meshes) == 1:
        cbar = fig.colorbar(next(iter(meshes.values())), ax=axes, shrink=0.9, pad=0.02)
        cbar.set_label(text)
    else:
        for name, mesh in meshes.items():
            cbar = fig.colorbar(mesh, ax=axes, shrink=0.9, pad=0.01, fraction=0.04)
            cbar.set_label(f"{name}: {text}", fontsize=8)
    return fig, meshes


def _draw_rigid_masters(ax: plt.Axes, s: Step | None, scale: float, size: float) -> tuple[list, list]:
    """The rigid masters of step ``s`` on the main panel, moved by their prescribed
    motion times ``scale`` (where the bodies drawn at that scale meet them); returns
    the lines and curves at their true positions (for the true-scale panel)."""
    lines, curves = rigid_lines(s), rigid_curves(s)
    contact = [] if s is None else s.contact
    zero = np.zeros(2)

    def offset(c: ContactOutput) -> np.ndarray:
        return zero if c.rigid_offset is None else np.asarray(c.rigid_offset, dtype=float)
    line_offsets = [offset(c) for c in contact if c.rigid_point is not None and c.rigid_normal is not None]
    curve_offsets = [offset(c) for c in contact if c.rigid_curve is not None]
    note = "" if scale == 1.0 else f" (its motion x {scale:g}, as the bodies)"
    moved_lines = [(p + (scale - 1.0) * d, n, lab) for (p, n, lab), d in zip(lines, line_offsets, strict=True)]
    if moved_lines:
        xl, yl = ax.get_xlim(), ax.get_ylim()
        for p, n, lab in moved_lines:
            draw_rigid_line(ax, p, n, 0.04 * size, 3.0 * size, lab + note)
        ax.set_xlim(min(xl[0], *(p[0] - 0.05 * size for p, _, _ in moved_lines)),
                    max(xl[1], *(p[0] + 0.05 * size for p, _, _ in moved_lines)))
        ax.set_ylim(min(yl[0], *(p[1] - 0.06 * size for p, _, _ in moved_lines)), yl[1])
    for (pts, n, lab), d in zip(curves, curve_offsets, strict=True):
        draw_rigid_curve(ax, pts + (scale - 1.0) * d, n, 0.04 * size, lab + note)
    if lines or curves:
        ax.autoscale_view()
        ax.legend(loc="upper right", fontsize=8)
    return lines, curves
