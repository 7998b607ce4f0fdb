"""The figures and tables of the 3D study (``make paper3d``, docs/validation-3d.md), drawn
by ``python -m post figures`` when the results hold the 3D scenes: each error measure of
:data:`MEASURES` against the DOFs, the CPU time and the wall time of the run (one line per
layout), the ironing force histories and the Hertz pressure profiles per mesh, and the
tables: every run with its cost and measures, the accuracy/cost table of the 2D study
(:func:`post.figures.accuracy_cost`) and what VO buys (:func:`vo_table`: for every
uniform-order run, the varying-order runs that reach its error, with the ratios of
DOFs, CPU and wall time)."""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from pathlib import Path

import numpy as np

from pre.files import save_figure

from .cost import Spread
from .figures import _num, _plt, accuracy_cost, run_cost
from .reader import read_result

SCENES = ("hertz3d", "ironing3d")
"""The scenes of the 3D study."""

MEASURES: dict[str, tuple[tuple[str, str], ...]] = {
    "hertz3d": (("l2_analytic", "relative L2 error of p against Hertz"),
                ("abs_a_err", "|a_fit / a - 1| (half-width error)")),
    "ironing3d": (("osc_t", "F_x oscillation / mean F_x"),
                  ("osc_n", "F_z oscillation / |mean F_z|")),
}
"""scene -> (summary column, axis label) of the errors the figures and tables rank
(post.measures.hertz3d_measures, post.measures.ironing3d_measures)."""

VO_SETS: dict[str, tuple[tuple[str, ...], ...]] = {
    "hertz3d": (("l2_analytic",), ("abs_a_err",), ("l2_analytic", "abs_a_err")),
    "ironing3d": (("osc_t",), ("osc_n",), ("osc_t", "osc_n")),
}
"""scene -> the sets of errors :func:`vo_table` compares (a VO run reaches a uniform run
when every error of the set is at most the uniform run's)."""

RUN_COLUMNS: dict[str, tuple[tuple[str, str, str], ...]] = {
    "hertz3d": (("l2_analytic", "L2", "pct"), ("a_err", "a (fit)", "signed"), ("p0_err", "p0 (fit)", "signed"),
                ("maxdev_analytic", "max dev / p0", "pct"), ("tau_err", "tau_max", "signed")),
    "ironing3d": (("osc_t", "osc F_x", "pct"), ("osc_n", "osc F_z", "pct"), ("ratio", "F_x / F_z", "plain"),
                  ("mean_n", "mean F_z", "plain")),
}
"""scene -> the measure columns of :func:`run_table`: (summary column, header, format)."""

_UNIFORM = re.compile(r"^[LN]\d+$")


def is_vo(layout: str) -> bool:
    """A varying-order layout (``NNq.k``, ``NNq``: a contact layer over the bulk)."""
    return layout.startswith("NN")


def is_uniform(layout: str) -> bool:
    """A uniform-order layout (``Np``, ``Lp``: one degree throughout)."""
    return bool(_UNIFORM.match(layout))


def _layout_key(layout: str) -> tuple[int, str]:
    return (1 if is_vo(layout) else 0, layout)


def _mesh_key(mesh: str) -> tuple[int, str]:
    digits = mesh[1:]
    return (int(digits) if digits.isdigit() else 10**6, mesh)


def converged(rows: list[dict[str, str]], scene: str, errors: tuple[str, ...] = ()) -> list[dict[str, str]]:
    """The converged runs of ``scene`` whose ``errors`` are all finite."""
    return [r for r in rows if r.get("scene") == scene and r.get("status") == "converged"
            and all(np.isfinite(_num(r, e)) for e in errors)]


def _name(row: dict[str, str]) -> str:
    return f"{row['mesh']}-{row['layout']}"


def cost_plots(rows: list[dict[str, str]], out: Path, scene: str, error: str, label: str) -> list[Path]:
    """``error`` against the DOFs, the CPU time and the wall time of each run (log-log; one
    line per layout through its meshes, each point labelled with its mesh; bars: the
    range of the repeats; no time figure when a run has no such time).
    ``<scene>-<error>-vs-{dofs,cpu,wall}.png`` in ``out``."""
    sel = converged(rows, scene, (error,))
    if not sel:
        return []
    plt = _plt()
    layouts = sorted({r["layout"] for r in sel}, key=_layout_key)
    paths = []
    for axis, xlabel in (("dofs", "DOFs"), ("cpu", "CPU time of the run, s (median; bars: range of repeats)"),
                         ("wall", "wall time of the run, s (median; bars: range of repeats)")):
        if axis != "dofs" and any(run_cost(r, axis) is None for r in sel):
            continue        # results without the engine's times (solved by hand)
        fig, ax = plt.subplots(figsize=(6.5, 4.5), constrained_layout=True)
        for lay in layouts:
            pts = sorted((r for r in sel if r["layout"] == lay), key=lambda r: _mesh_key(r["mesh"]))
            ys = [_num(r, error) for r in pts]
            style = "s--" if is_vo(lay) else "o-"
            if axis == "dofs":
                xs = [_num(r, "dofs") for r in pts]
                ax.plot(xs, ys, style, ms=4, label=lay)
            else:
                costs = [run_cost(r, axis) for r in pts]
                xs = [c.median if c else float("nan") for c in costs]
                bars = np.array([(c.median - c.lo, c.hi - c.median) if c else (0.0, 0.0)
                                 for c in costs], dtype=float).T.reshape(2, len(pts))
                ax.errorbar(xs, ys, xerr=bars, fmt=style, ms=4, capsize=2, elinewidth=0.8, label=lay)
            for r, x, y in zip(pts, xs, ys, strict=True):
                ax.annotate(r["mesh"], (x, y), fontsize=6, xytext=(2, 2), textcoords="offset points")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(label)
        ax.set_title(f"{scene}: {label}", fontsize=10)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
        path = out / f"{scene}-{error}-vs-{axis}.png"
        save_figure(fig, path, dpi=110)
        plt.close(fig)
        paths.append(path)
    return paths


def ironing3d_forces(results: Path, out: Path, mesh: str) -> Path | None:
    """F_x and -F_z against the load time for every layout on ``mesh``
    (:func:`post.ironing3d.ironing_forces`); None without a converged result."""
    from .ironing3d import IroningError, ironing_forces

    files = sorted((results / "ironing3d").glob(f"{mesh}-*.h5"), key=lambda p: _layout_key(p.stem.split("-", 1)[1]))
    curves = []
    for path in files:
        res = read_result(path, lazy=True)
        if not res.converged:
            continue
        try:
            curves.append((path.stem.split("-", 1)[1], ironing_forces(res)))
        except IroningError:
            continue
    if not curves:
        return None
    plt = _plt()
    fig, ax = plt.subplots(2, 1, figsize=(8, 7), sharex=True, constrained_layout=True)
    for lay, h in curves:
        ax[0].plot(h.time, h.forces[:, 0], lw=0.9, label=f"{lay} (osc {h.measures['osc_t']:.2%})")
        ax[1].plot(h.time, -h.forces[:, 1], lw=0.9, label=f"{lay} (osc {h.measures['osc_n']:.2%})")
    ax[0].set_ylabel("$F_x$ on the slab")
    ax[1].set_ylabel("$-F_z$ on the slab")
    ax[1].set_xlabel("load time (0-1 press, 1-2 slide)")
    ax[0].set_title(f"ironing3d, mesh {mesh}: the contact pair's resultant")
    for a in ax:
        a.legend(ncol=2, fontsize=8)
        a.grid(alpha=0.3)
    path = out / f"ironing3d-forces-{mesh}.png"
    save_figure(fig, path, dpi=110)
    plt.close(fig)
    return path


def hertz3d_profiles(results: Path, out: Path, mesh: str) -> Path | None:
    """p / p0 against r / a at the slave points of every layout on ``mesh`` and Hertz's
    profile (:func:`post.hertz3d.hertz3d_comparison`, each run's own a and p0); None
    without a result that compares."""
    from .hertz import HertzError
    from .hertz3d import hertz3d_comparison

    files = sorted((results / "hertz3d").glob(f"{mesh}-*.h5"), key=lambda p: _layout_key(p.stem.split("-", 1)[1]))
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7, 4.5), constrained_layout=True)
    s = np.linspace(0.0, 1.0, 400)
    ax.plot(s, np.sqrt(1.0 - s**2), "k-", lw=2, label="Hertz")
    drawn = 0
    for path in files:
        res = read_result(path, lazy=True)
        if not res.converged:
            continue
        try:
            h = hertz3d_comparison(res)
        except HertzError:
            continue
        keep = h.r <= 1.4 * h.a
        ax.plot(h.r[keep] / h.a, h.p[keep] / h.p0, ".", ms=2,
                label=f"{path.stem.split('-', 1)[1]} (L2 {h.error.l2:.1%})")
        drawn += 1
    if not drawn:
        plt.close(fig)
        return None
    ax.set_xlim(0, 1.4)
    ax.set_xlabel("r / a (reference configuration)")
    ax.set_ylabel("p / p0 (per reference area)")
    ax.set_title(f"hertz3d, mesh {mesh}: nominal pressure at the slave points")
    ax.legend(fontsize=8, markerscale=4)
    path = out / f"hertz3d-pressure-{mesh}.png"
    save_figure(fig, path, dpi=110)
    plt.close(fig)
    return path


def figure_tasks(results: Path, out: Path, rows: list[dict[str, str]]) -> list[tuple[Callable[..., object],
                                                                                       tuple[object, ...]]]:
    """The figure calls for the 3D scenes in ``rows`` (:func:`post.figures.make_all` runs them)."""
    tasks: list[tuple[Callable[..., object], tuple[object, ...]]] = []
    for scene in SCENES:
        present = converged(rows, scene)
        if not present:
            continue
        for error, label in MEASURES[scene]:
            tasks.append((cost_plots, (rows, out, scene, error, label)))
        draw = ironing3d_forces if scene == "ironing3d" else hertz3d_profiles
        for mesh in sorted({r["mesh"] for r in present}, key=_mesh_key):
            tasks.append((draw, (results, out, mesh)))
    return tasks


def _pct(x: float) -> str:
    return "" if not math.isfinite(x) else f"{100 * x:.2f} %"


def _signed(x: float) -> str:
    return "" if not math.isfinite(x) else f"{100 * x:+.2f} %"


def _secs(s: Spread | None) -> str:
    if s is None:
        return ""
    if s.n <= 1 and s.lo == s.hi:
        return f"{s.median:.3g}"
    return f"{s.median:.3g} [{s.lo:.3g}-{s.hi:.3g}]"


def run_table(rows: list[dict[str, str]], scene: str) -> str:
    """Markdown: every run of ``scene`` (by layout, then mesh) with its DOFs, Newton
    iterations, cuts, CPU and wall time (median [range] of the repeats) and measures
    (:data:`RUN_COLUMNS`); a run that did not converge shows its status."""
    cols = RUN_COLUMNS[scene]
    sel = sorted((r for r in rows if r.get("scene") == scene),
                 key=lambda r: (_layout_key(r["layout"]), _mesh_key(r["mesh"])))
    head = ["mesh", "layout", "DOFs", "Newton", "cuts", "CPU s", "wall s", *(c[1] for c in cols)]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    fmt = {"pct": _pct, "signed": _signed, "plain": lambda x: "" if not math.isfinite(x) else f"{x:.4g}"}
    for r in sel:
        if r.get("status") != "converged":
            lines.append(f"| {r['mesh']} | {r['layout']} | {r.get('dofs', '')} | | | | | "
                         f"{r.get('status', '')} {r.get('error', '')}".rstrip() + " |")
            continue
        cells = [r["mesh"], r["layout"], f"{int(_num(r, 'dofs')):,}", r.get("iterations", ""),
                 r.get("cuts", ""), _secs(run_cost(r, "cpu")), _secs(run_cost(r, "wall"))]
        cells += [fmt[kind](_num(r, key)) for key, _, kind in cols]
        lines.append("| " + " | ".join(str(c) for c in cells) + " |")
    return "\n".join(lines) + "\n"


def _reaches(v: dict[str, str], u: dict[str, str], errors: tuple[str, ...]) -> bool:
    return all(_num(v, e) <= _num(u, e) for e in errors)


def _times(a: Spread | None, b: Spread | None) -> str:
    """``a / b`` as ``2.4x [1.9-3.0]`` (the range the repeats allow), or empty."""
    if a is None or b is None or b.median <= 0 or b.lo <= 0:
        return ""
    return f"{a.median / b.median:.2g}x [{a.lo / b.hi:.2g}-{a.hi / b.lo:.2g}]"


def vo_table(rows: list[dict[str, str]], scene: str, errors: tuple[str, ...]) -> str:
    """Markdown: for every uniform-order run U of ``scene`` (N2, N3, ... on each mesh),
    the varying-order run V with the fewest DOFs whose ``errors`` are all at most U's, and
    U's DOFs, CPU time and wall time over V's (above 1: V is cheaper; brackets: the range
    the repeats allow, U's lowest over V's highest to U's highest over V's lowest). When
    the VO run with the least CPU time among those that reach U is another, it gets a
    row of its own. No VO run reaching U: said so."""
    sel = converged(rows, scene, errors)
    uniform = sorted((r for r in sel if is_uniform(r["layout"])),
                     key=lambda r: (_layout_key(r["layout"]), _mesh_key(r["mesh"])))
    vo = [r for r in sel if is_vo(r["layout"])]
    what = " and ".join(errors)
    lines = [f"| uniform run ({what}) | DOFs | VO run reaching it ({what}) | DOFs | "
             "DOFs ratio | CPU ratio | wall ratio |", "|---|---|---|---|---|---|---|"]

    def errs(r: dict[str, str]) -> str:
        return ", ".join(_pct(_num(r, e)) for e in errors)

    for u in uniform:
        ok = [v for v in vo if _reaches(v, u, errors)]
        head = f"| {_name(u)} ({errs(u)}) | {int(_num(u, 'dofs')):,} |"
        if not ok:
            lines.append(head + " none reaches it | | | | |")
            continue
        fewest = min(ok, key=lambda v: (_num(v, "dofs"), _name(v)))
        picks = [fewest]
        timed = [v for v in ok if run_cost(v, "cpu") is not None]
        if timed:
            fastest = min(timed, key=lambda v: run_cost(v, "cpu").median)  # type: ignore[union-attr]
            if fastest is not fewest:
                picks.append(fastest)
        for v in picks:
            lines.append(head + f" {_name(v)} ({errs(v)}) | {int(_num(v, 'dofs')):,} | "
                         f"{_num(u, 'dofs') / _num(v, 'dofs'):.2g}x | "
                         f"{_times(run_cost(u, 'cpu'), run_cost(v, 'cpu'))} | "
                         f"{_times(run_cost(u, 'wall'), run_cost(v, 'wall'))} |")
    return "\n".join(lines) + "\n"


def tables(rows: list[dict[str, str]]) -> str:
    """The markdown sections of the 3D scenes in ``rows`` (empty without one): the runs,
    the accuracy/cost table of each measure and the VO tables."""
    text = []
    for scene in SCENES:
        if not any(r.get("scene") == scene for r in rows):
            continue
        text += [f"\n## {scene}: the runs\n\n", run_table(rows, scene)]
        for error, _ in MEASURES[scene]:
            text += [f"\n## {scene}: {error}\n\n", accuracy_cost(rows, scene, error)]
        for errors in VO_SETS[scene]:
            text += [f"\n## {scene}: VO against uniform order, {' and '.join(errors)}\n\n",
                     vo_table(rows, scene, errors)]
    return "".join(text)
