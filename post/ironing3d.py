"""Ironing force histories and their oscillation (``python -m post ironing``), for the 2D
scene (the die's reactions Px, Py; :mod:`post.ironing`) and the 3D one of ``python -m pre
ironing3d`` (the contact pair's resultant ``/steps/<k>/contact/<pair>/force``: F_x along
the path, F_z normal to the slab).

The oscillation measure is the 2D study's (:func:`post.measures.ironing_measures`): over
the second half of the sliding phase, the amplitude (max - min) of a force after a cubic
trend in the step is removed (``amp``), over the force's mean there (``osc``). The
sliding phase of a 3D result is its steps after load time 1 (the press phase of
``&solver n_steps = press, slide`` ends at time 1); ``spread`` is the raw max - min over
the mean over the whole sliding phase, and ``ratio`` the mean F_x / |F_z| there (mu
when every point slips).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from pre.files import save_figure

from .measures import PRESS_STEPS, detrended_amplitude, ironing_measures
from .naming import output_path
from .reader import Result

MIN_SLIDING = 8
"""Sliding steps a result needs for the measures (as the 2D study's)."""
PHASE_END = 1.0 + 1e-9
"""Load time of the press phase's end (3D: steps after it slide)."""


class IroningError(ValueError):
    """A result the ironing measures cannot be taken of."""


@dataclass
class IroningForces:
    """The two force components of an ironing run per converged step and their measures."""

    source: str
    dimension: int
    labels: tuple[str, str]
    """Names of the tangential and normal components (Px, Py in 2D; F_x, F_z in 3D)."""
    steps: np.ndarray = field(repr=False)
    time: np.ndarray = field(repr=False)
    forces: np.ndarray = field(repr=False)
    """(n, 2): tangential, normal component per step."""
    sliding: np.ndarray = field(repr=False)
    """(n,) bool: the step belongs to the sliding phase."""
    measures: dict[str, float] = field(default_factory=dict)
    """amp_/osc_/mean_/raw_amp_/spread_ of each component (suffixes ``t`` tangential,
    ``n`` normal) and ``ratio``."""
    n_dofs: int = 0
    wall_time: float = 0.0
    newton: int = 0


def _measure(steps: np.ndarray, f: np.ndarray, sliding: np.ndarray) -> dict[str, float]:
    """The measures of the module docstring of the (n, 2) forces ``f``."""
    idx = np.flatnonzero(sliding)
    if len(idx) < MIN_SLIDING:
        raise IroningError(f"{len(idx)} sliding steps: the measures need {MIN_SLIDING}")
    w = idx[len(idx) // 2:]
    out: dict[str, float] = {}
    for c, key in enumerate(("t", "n")):
        mean = float(f[w, c].mean())
        whole = float(f[idx, c].mean())
        out[f"amp_{key}"] = detrended_amplitude(steps[w], f[w, c])
        out[f"raw_amp_{key}"] = float(np.ptp(f[w, c]))
        out[f"mean_{key}"] = mean
        out[f"osc_{key}"] = out[f"amp_{key}"] / abs(mean) if mean else float("nan")
        out[f"spread_{key}"] = float(np.ptp(f[idx, c])) / abs(whole) if whole else float("nan")
    out["ratio"] = abs(out["mean_t"] / out["mean_n"]) if out["mean_n"] else float("nan")
    return out


def ironing_forces(result: Result, pair: int = 1) -> IroningForces:
    """The force history of an ironing result and its measures (module docstring); a 3D
    result's contact pair ``pair`` (from 1)."""
    if not result.steps:
        raise IroningError("no converged step")
    steps = np.array([s.step for s in result.steps])
    time = np.array([s.time for s in result.steps], dtype=float)
    common = {"n_dofs": result.n_dofs, "wall_time": result.wall_time,
              "newton": int(sum(s.iterations_total if s.iterations_total is not None else s.iterations
                                  for s in result.steps))}
    if result.dimension == 2:
        from .ironing import die_forces

        try:
            steps, f = die_forces(result)
        except (KeyError, ValueError) as err:
            raise IroningError(f"no die reaction (2D ironing: body 'die', edge 'inner'): {err}") from None
        sliding = steps > PRESS_STEPS
        m = ironing_measures(result)
        if not m:
            raise IroningError(f"{int(sliding.sum())} sliding steps: the measures need {MIN_SLIDING}")
        measures = {k.replace("px", "t").replace("py", "n"): v for k, v in m.items()}
        for c, key in enumerate(("t", "n")):
            whole = float(f[sliding, c].mean())
            measures[f"spread_{key}"] = float(np.ptp(f[sliding, c])) / abs(whole) if whole else float("nan")
        measures["ratio"] = abs(measures["mean_t"] / measures["mean_n"]) if measures["mean_n"] else float("nan")
        return IroningForces(str(result.path), 2, ("Px", "Py"), steps, time, f[:, :2], sliding,
                             measures, **common)
    contacts = result.steps[0].contact
    if not 1 <= pair <= len(contacts):
        raise IroningError(f"no contact pair {pair} (the result has {len(contacts)})")
    f = np.array([s.contact[pair - 1].force for s in result.steps], dtype=float)
    f = f[:, [0, 2]]
    sliding = time > PHASE_END
    return IroningForces(str(result.path), 3, ("F_x", "F_z"), steps, time, f, sliding,
                         _measure(steps, f, sliding), **common)


def ironing_report(h: IroningForces) -> list[str]:
    """The measures in a few lines."""
    m = h.measures
    t, n = h.labels
    n_slide = int(h.sliding.sum())
    return [f"{h.source}: {h.dimension}D ironing, {len(h.steps)} steps ({n_slide} sliding), "
            f"{h.n_dofs} DOFs, {h.newton} Newton iterations, {h.wall_time:.1f} s",
            f"mean over the second half of sliding: {t} = {m['mean_t']:.6g}, {n} = {m['mean_n']:.6g}, "
            f"|{t}/{n}| = {m['ratio']:.4f}",
            f"oscillation (detrended max - min / |mean|, second half): {t} {m['osc_t']:.3%}, "
            f"{n} {m['osc_n']:.3%}",
            f"raw max - min / |mean| over the whole sliding phase: {t} {m['spread_t']:.3%}, "
            f"{n} {m['spread_n']:.3%}"]


def plot_ironing(h: IroningForces, output: str | Path) -> Path:
    """Both components against the load time (left) and F_t / |F_n| (right), the
    measured window shaded."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
    t, n = h.labels
    left.plot(h.time, h.forces[:, 0], ".-", ms=3, label=t)
    left.plot(h.time, -h.forces[:, 1] if h.measures["mean_n"] < 0 else h.forces[:, 1], ".-", ms=3,
              label=f"-{n}" if h.measures["mean_n"] < 0 else n)
    idx = np.flatnonzero(h.sliding)
    w = idx[len(idx) // 2:]
    for ax in (left, right):
        ax.axvspan(h.time[w[0]], h.time[w[-1]], color="0.9", zorder=0)
        ax.set_xlabel("load time")
    left.set_ylabel("force")
    left.legend(fontsize=8)
    left.set_title(f"{Path(h.source).stem}: osc {t} {h.measures['osc_t']:.2%}, {n} {h.measures['osc_n']:.2%}",
                   fontsize=10)
    with np.errstate(divide="ignore", invalid="ignore"):
        q = np.abs(h.forces[:, 0] / h.forces[:, 1])
    right.plot(h.time[idx], q[idx], ".-", ms=3)
    right.set_ylabel(f"|{t} / {n}|")
    right.set_title(f"mean over the window {h.measures['ratio']:.4f}", fontsize=10)
    path = save_figure(fig, output, dpi=120)
    plt.close(fig)
    return path


def ironing_figure(result: Result, h: IroningForces, out: str | Path | None = None,
                   output: str | Path | None = None) -> Path:
    """:func:`plot_ironing` into ``<result>-ironing.png`` next to the result or in ``out``."""
    return plot_ironing(h, output or output_path(result.path, "ironing", None, out))
