"""The validation figures and tables (``python -m post figures``), from a sweep's results
folder: die forces per step (paper Figs. 8-10), contact pressure against the reference
(Figs. 18, 24), error against mesh (Figs. 19-20) and against time (Figs. 13, 21),
deformed shapes (Figs. 7, 14, 23) and the accuracy/cost table."""

from __future__ import annotations

import csv
import multiprocessing
import os
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from pre.files import save_figure, write_text

from .cost import Spread, cheapest, ratio
from .reader import read_result
from .sweep import SUMMARY_COLUMNS

LAYOUT_ORDER = ["L1", "N2", "N4", "N6", "NN4", "NN6", "NN2.1", "NN2.2", "NN2.3", "NN3.2"]


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def read_summary(results: Path) -> list[dict[str, str]]:
    with (results / "summary.csv").open() as fh:
        return list(csv.DictReader(fh))


def _num(row: dict[str, str] | dict[str, object], key: str) -> float:
    """The cell as a number (NaN when empty or not a number)."""
    value = row.get(key)
    try:
        return float(value) if value not in (None, "") else float("nan")
    except (TypeError, ValueError):
        return float("nan")


def ironing_forces(results: Path, out: Path, scene: str = "ironing", mesh: str = "m1") -> Path | None:
    """Px and Py against the load step for every layout on one mesh."""
    from .ironing import die_forces

    files = {lay: results / scene / f"{mesh}-{lay}.h5" for lay in LAYOUT_ORDER}
    files = {k: v for k, v in files.items() if v.exists()}
    if not files:
        return None
    plt = _plt()
    fig, ax = plt.subplots(2, 1, figsize=(8, 7), sharex=True, constrained_layout=True)
    for lay, path in files.items():
        res = read_result(path, lazy=True)
        if not res.steps:
            continue
        steps, f = die_forces(res)
        ax[0].plot(steps, f[:, 0], lw=1.2 if lay == "N2" else 0.9, label=lay)
        ax[1].plot(steps, f[:, 1], lw=1.2 if lay == "N2" else 0.9, label=lay)
    ax[0].set_ylabel("$P_x$ on the die")
    ax[1].set_ylabel("$P_y$ on the die")
    ax[1].set_xlabel("load step (1-10 press, 11-210 slide)")
    ax[0].set_title(f"{scene}, mesh {mesh}: reaction on the die's driven edge")
    ax[0].legend(ncol=4, fontsize=8)
    path = out / f"{scene}-forces-{mesh}.png"
    save_figure(fig, path, dpi=120)
    plt.close(fig)
    return path


def hertz_pressure(results: Path, out: Path, mesh: str = "m3") -> Path | None:
    """p/p0 against x/a for the layouts on one mesh, the analytic profile and N2 on m6: the
    nominal pressure at the reference positions, each run's own analytic a and p0."""
    from .hertz import hertz_comparison

    ref_path = results / "hertz" / "m6-N2.h5"
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7, 4.5), constrained_layout=True)
    s = np.linspace(0, 1, 400)
    ax.plot(s, np.sqrt(1 - s**2), "k-", lw=2, label="analytic Hertz")
    if ref_path.exists():
        ref = read_result(ref_path, lazy=True)
        h = hertz_comparison(ref)
        ax.plot(h.x / h.a, h.p / h.p0, "k--", lw=1, label="N2 m6 (reference)")
    for lay in LAYOUT_ORDER:
        path = results / "hertz" / f"{mesh}-{lay}.h5"
        if not path.exists():
            continue
        res = read_result(path, lazy=True)
        if not res.converged:
            continue
        h = hertz_comparison(res)
        ax.plot(h.x / h.a, h.p / h.p0, ".-", ms=3, lw=0.8, label=lay)
    ax.set_xlim(0, 1.3)
    ax.set_xlabel("x / a (reference configuration)")
    ax.set_ylabel("p / p0 (per reference length)")
    ax.set_title(f"hertz, mesh {mesh}: contact pressure")
    ax.legend(fontsize=8)
    path = out / f"hertz-pressure-{mesh}.png"
    save_figure(fig, path, dpi=120)
    plt.close(fig)
    return path


def _normalised_times(rows: list[dict[str, str]], key: str) -> tuple[list[float], np.ndarray]:
    """``time_norm`` of each row and its error bars (below, above: the range of the
    repeats of ``<key>_s`` on the same scale), for ``errorbar``'s ``xerr``."""
    xs, bars = [], []
    for r in rows:
        x, cost = _num(r, "time_norm"), run_cost(r, key)
        scale = x / cost.median if cost is not None and cost.median > 0 else 0.0
        xs.append(x)
        bars.append((scale * (cost.median - cost.lo), scale * (cost.hi - cost.median)) if cost else (0.0, 0.0))
    return xs, np.array(bars, dtype=float).T.reshape(2, len(rows))


def error_plots(rows: list[dict[str, str]], out: Path, scene: str, error: str,
                label: str) -> list[Path]:
    """Error against mesh level and against normalised time, one line per layout."""
    plt = _plt()
    paths = []
    sel = [r for r in rows if r["scene"] == scene and r.get("status") == "converged"
           and np.isfinite(_num(r, error)) and r["mesh"].startswith("m")]
    if not sel:
        return paths
    key = "cpu" if all(run_cost(r, "cpu") for r in sel) else "wall"
    time_label = f"{'CPU' if key == 'cpu' else 'wall'} time / most expensive run's (bars: range of repeats)"
    for xkey, xlabel, name in (("mesh", "mesh", "mesh"), ("time_norm", time_label, "time")):
        fig, ax = plt.subplots(figsize=(6.5, 4.5), constrained_layout=True)
        for lay in LAYOUT_ORDER:
            pts = [r for r in sel if r["layout"] == lay]
            if not pts:
                continue
            pts.sort(key=lambda r: r["mesh"])
            ys = [_num(r, error) for r in pts]
            if xkey == "mesh":
                ax.plot([int(r["mesh"][1:]) for r in pts], ys, "o-", ms=4, label=lay)
                continue
            xs, bars = _normalised_times(pts, key)
            ax.errorbar(xs, ys, xerr=bars, fmt="o-", ms=4, capsize=2, elinewidth=0.8, label=lay)
        ax.set_yscale("log")
        if xkey == "time_norm":
            ax.set_xscale("log")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(label)
        ax.set_title(f"{scene}: {label} against {name}")
        ax.legend(fontsize=8)
        path = out / f"{scene}-{error}-vs-{name}.png"
        save_figure(fig, path, dpi=120)
        plt.close(fig)
        paths.append(path)
    return paths


def run_cost(row: dict[str, str] | dict[str, object], key: str = "cpu") -> Spread | None:
    """The cost of a summary row as a :class:`post.cost.Spread` of ``<key>_s`` (``key``
    ``cpu`` or ``wall``): its median and range over the repeats (a run timed once, or a
    summary without the range, has the one value as its range); None without it."""
    median = _num(row, f"{key}_s")
    if not np.isfinite(median):
        return None
    lo, hi, n = _num(row, f"{key}_lo_s"), _num(row, f"{key}_hi_s"), _num(row, "repeats")
    if not (np.isfinite(lo) and np.isfinite(hi)):
        lo = hi = median
    return Spread(median, lo, hi, int(n) if np.isfinite(n) else 1)


def _seconds(s: Spread) -> str:
    """``0.0310 s [0.0301-0.0322]``, or ``16.2 s (1 run)``."""
    if s.n <= 1 and s.lo == s.hi:
        return f"{s.median:.3g} s (1 run)"
    return f"{s.median:.3g} s [{s.lo:.3g}-{s.hi:.3g}]"


def _fraction(x: float) -> str:
    """Two decimals, or two significant digits below 0.1."""
    return f"{x:.2f}" if x >= 0.1 else f"{x:.2g}"


def _pick(names: list[str], costs: dict[str, Spread], errors: dict[str, float]) -> str:
    """The cell naming the cheapest run, or every run of a tie."""
    cells = [f"{k} ({errors[k]:.3g}): {_seconds(costs[k])}" for k in names]
    return cells[0] if len(cells) == 1 else "tie: " + "; ".join(cells)


def accuracy_cost(rows: list[dict[str, str]], scene: str, error: str,
                  levels: tuple[float, ...] = (0.10, 0.03, 0.01, 0.003, 0.001)) -> str:
    """Markdown table: for each error level, the cheapest run reaching it and the
    cheapest N2 run reaching it, by their CPU time (median [min-max] of the repeats;
    the wall time when a run has no CPU time), and the cost of the cheapest run relative
    to the cheapest N2's with its range. Runs whose ranges overlap are a tie and all of
    them are named (:func:`post.cost.cheapest`): the table says only what the repeats
    can tell apart."""
    from .sweep import REFERENCES

    ref = REFERENCES.get(scene, "")
    # the reference run has error 0 by definition: it is not a candidate
    sel = [r for r in rows if r["scene"] == scene and r.get("status") == "converged"
           and np.isfinite(_num(r, error)) and r["mesh"].startswith("m")
           and not (f"{r['mesh']}-{r['layout']}" == ref and error.endswith(("_ref", "_ref_field")))]
    key = "cpu" if all(run_cost(r, "cpu") for r in sel) else "wall"
    what = "CPU" if key == "cpu" else "wall"
    lines = [f"| {error} <= | cheapest run ({error}): {what} time, median [range] | cheapest N2 | "
             f"{what} time / N2's [range] |",
             "|---|---|---|---|"]
    for level in levels:
        ok = [r for r in sel if _num(r, error) <= level]
        if not ok:
            lines.append(f"| {level:g} | none reaches it | | |")
            continue
        costs = {f"{r['mesh']}-{r['layout']}": run_cost(r, key) for r in ok}
        costs = {k: v for k, v in costs.items() if v is not None}
        errors = {f"{r['mesh']}-{r['layout']}": _num(r, error) for r in ok}
        n2 = {k: v for k, v in costs.items() if k.endswith("-N2")}
        best = _pick(cheapest(costs), costs, errors)
        if not n2:
            lines.append(f"| {level:g} | {best} | - | N2 does not reach it |")
            continue
        r = ratio({k: v for k, v in costs.items() if k not in n2}, n2)
        lines.append(f"| {level:g} | {best} | {_pick(cheapest(n2), n2, errors)} | "
                     f"{_fraction(r.median)} [{_fraction(r.lo)}-{_fraction(r.hi)}] |")
    return "\n".join(lines) + "\n"


def deformed(results: Path, out: Path) -> list[Path]:
    """Deformed shapes of one run per scene."""
    from .plot import plot_deformed

    paths = []
    for scene, stem, step in (("ironing", "m1-N2", 110), ("hertz", "m3-NN2.2", -1), ("rings", "m1-N2", -1)):
        path = results / scene / f"{stem}.h5"
        if not path.exists():
            continue
        res = read_result(path, lazy=True)
        if not res.steps:
            continue
        if step > 0 and step > res.steps[-1].step:
            step = -1
        paths.append(plot_deformed(res, step=step, output=out / f"{scene}-{stem}-deformed.png"))
    return paths


Task = tuple[Callable[..., object], tuple[object, ...]]


SCENES_2D = ("hertz", "ironing", "ironing-deep", "rings")
"""The scenes of the 2D study (``make paper``); the 3D ones are :data:`post.figures3d.SCENES`."""


def _figure_tasks(results: Path, out: Path, rows: list[dict[str, str]]) -> list[Task]:
    """The figure calls of :func:`make_all` for the scenes ``rows`` holds, the slowest
    first (error plots and the deformed shapes take about 1 s per figure, matplotlib's
    layout and drawing)."""
    from .figures3d import figure_tasks

    scenes = {r.get("scene") for r in rows}
    tasks: list[Task] = []
    if "hertz" in scenes:
        tasks += [
            (error_plots, (rows, out, "hertz", "l2_ref_field", "L2 error of the pressure field vs N2 m6")),
            (error_plots, (rows, out, "hertz", "l2_ref", "L2 error of p/p_max vs N2 m6")),
            (error_plots, (rows, out, "hertz", "l2_analytic",
                           "L2 error vs analytic Hertz (reference configuration)"))]
    if scenes & set(SCENES_2D):
        tasks.append((deformed, (results, out)))
    if "rings" in scenes:
        tasks += [(error_plots, (rows, out, "rings", "l2_pn_ref", "L2 error of p_N vs reference")),
                  (error_plots, (rows, out, "rings", "l2_pt_ref", "L2 error of p_T vs reference"))]
    ironing = [scene for scene in ("ironing", "ironing-deep") if scene in scenes]
    for scene in ironing:
        tasks.append((error_plots, (rows, out, scene, "osc_py", "Py oscillation / mean Py")))
        tasks.append((error_plots, (rows, out, scene, "osc_px", "Px oscillation / mean Px")))
    for scene in ironing:
        for mesh in ("m1", "m2"):
            tasks.append((ironing_forces, (results, out, scene, mesh)))
    if "hertz" in scenes:
        tasks.append((hertz_pressure, (results, out, "m3")))
        tasks.append((hertz_pressure, (results, out, "m1")))
    return tasks + figure_tasks(results, out, rows)


def _run_task(task: Task) -> list[Path | None]:
    """One figure call's paths (a list whatever the call returns)."""
    function, args = task
    made = function(*args)
    return list(made) if isinstance(made, list) else [made]  # type: ignore[list-item]


def make_all(results: Path, out: Path, jobs: int | None = None) -> list[Path]:
    """Every figure and the accuracy/cost tables (``accuracy-cost.md``) of the scenes the
    results hold into ``out``: the 2D study's (``make paper``) and the 3D study's
    (``make paper3d``, :mod:`post.figures3d`). The figures are drawn by ``jobs``
    processes (default: one per core; ``make paper``'s figures take 16 s on one core of
    this machine, mostly matplotlib)."""
    from .figures3d import tables

    out.mkdir(parents=True, exist_ok=True)
    rows = read_summary(results)
    tasks = _figure_tasks(results, out, rows)
    jobs = min(len(tasks), jobs or os.cpu_count() or 1)
    if jobs > 1:
        with ProcessPoolExecutor(max_workers=jobs, mp_context=multiprocessing.get_context("fork")) as pool:
            parts = list(pool.map(_run_task, tasks))
    else:
        parts = [_run_task(task) for task in tasks]
    text = ["# What accuracy costs (generated by `python -m post figures`)\n"]
    scenes = {r.get("scene") for r in rows}
    for scene, error in (("hertz", "l2_ref_field"), ("hertz", "l2_ref"), ("hertz", "l2_analytic"),
                         ("rings", "l2_pn_ref"), ("rings", "l2_pt_ref"),
                         ("ironing", "osc_py"), ("ironing", "osc_px"),
                         ("ironing-deep", "osc_py"), ("ironing-deep", "osc_px")):
        if scene in scenes:
            text += [f"\n## {scene}: {error}\n\n", accuracy_cost(rows, scene, error)]
    text.append(tables(rows))
    write_text(out / "accuracy-cost.md", "".join(text))
    return [path for part in parts for path in part if path is not None]


def _cell(row: dict[str, object], key: str) -> object:
    value = row.get(key)
    return "" if value is None else value


def _numeric(values: list[object]) -> bool:
    try:
        [float(v) for v in values]
        return True
    except (TypeError, ValueError):
        return False


def _safe(name: str) -> str:
    return "".join(c if c.isalnum() or c in "._-" else "_" for c in name)


def study_figures(rows: list[dict[str, object]], params: list[str], out: Path) -> list[Path]:
    """For every measure (a numeric column other than SUMMARY_COLUMNS and ``params``): the
    measure against each parameter that takes more than one value (one line per
    combination of the other parameters; ``scene``, ``mesh`` and ``layout`` count as
    parameters when they vary) and against the CPU time of the run (the wall time
    when a run has none; one point per case, labelled with its parameters, with the
    range of its repeats). PNG files ``<measure>-vs-<parameter>.png`` and
    ``<measure>-vs-time.png`` in ``out``; the converged runs only."""
    ok = [r for r in rows if r.get("status") == "converged"]
    axes = [p for p in ["scene", "mesh", "layout", *params]
            if len({str(_cell(r, p)) for r in ok}) > 1]
    keys: list[str] = []
    for row in ok:
        keys += [k for k in row if k not in keys]
    measures = [k for k in keys if k not in SUMMARY_COLUMNS and k not in params
                and any(np.isfinite(_num(r, k)) for r in ok)]
    if not ok or not measures:
        return []
    out.mkdir(parents=True, exist_ok=True)
    plt = _plt()
    paths = []
    key = "cpu" if all(run_cost(r, "cpu") for r in ok) else "wall"
    what = "CPU" if key == "cpu" else "wall"

    def label(row: dict[str, object], names: list[str]) -> str:
        return ", ".join(f"{n.rsplit('.', 1)[-1]}={_cell(row, n)}" for n in names)

    for m in measures:
        for x in axes:
            others = [p for p in axes if p != x]
            fig, ax = plt.subplots(figsize=(6.5, 4.5), constrained_layout=True)
            xs_all = [_cell(r, x) for r in ok]
            numeric = _numeric(xs_all)
            order = list(dict.fromkeys(str(v) for v in xs_all))
            groups: dict[str, list[dict[str, object]]] = {}
            for r in ok:
                groups.setdefault(label(r, others), []).append(r)
            for name, pts in groups.items():
                if numeric:
                    pts = sorted(pts, key=lambda r: float(_cell(r, x)))
                    xs = [float(_cell(r, x)) for r in pts]
                else:
                    pts = sorted(pts, key=lambda r: order.index(str(_cell(r, x))))
                    xs = [order.index(str(_cell(r, x))) for r in pts]
                ax.plot(xs, [_num(r, m) for r in pts], "o-", ms=4, label=name or None)
            if not numeric:
                ax.set_xticks(range(len(order)), order)
            ax.set_xlabel(x)
            ax.set_ylabel(m)
            ax.set_title(f"{m} against {x}")
            if others:
                ax.legend(fontsize=7)
            path = out / f"{_safe(m)}-vs-{_safe(x)}.png"
            save_figure(fig, path, dpi=110)
            plt.close(fig)
            paths.append(path)
        fig, ax = plt.subplots(figsize=(6.5, 4.5), constrained_layout=True)
        costs = [run_cost(r, key) for r in ok]
        walls = [c.median if c else float("nan") for c in costs]
        bars = np.array([(c.median - c.lo, c.hi - c.median) if c else (0.0, 0.0) for c in costs]).T
        values = [_num(r, m) for r in ok]
        ax.errorbar(walls, values, xerr=bars, fmt="o", ms=5, capsize=2, elinewidth=0.8)
        for r, w, v in zip(ok, walls, values, strict=True):
            ax.annotate(label(r, axes), (w, v), fontsize=7, xytext=(3, 3), textcoords="offset points")
        if min(walls) > 0 and max(walls) > 10 * min(walls):
            ax.set_xscale("log")
        ax.set_xlabel(f"{what} time of the run, s (median; bars: range of repeats)")
        ax.set_ylabel(m)
        ax.set_title(f"{m} against the run's {what} time")
        path = out / f"{_safe(m)}-vs-time.png"
        save_figure(fig, path, dpi=110)
        plt.close(fig)
        paths.append(path)
    return paths
