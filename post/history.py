"""Load history of a result (``python -m post history``): the reaction of every
Dirichlet condition and the resultant force of every contact pair against the load
time, as a CSV table and a PNG figure.

Forces are per unit thickness in 2D (plane strain): force/length in the file's units;
a solid's (3D) are forces, with a z component.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from pre.files import new_file, save_figure

from .naming import output_path
from .reader import Result


def history_table(result: Result) -> tuple[list[str], np.ndarray]:
    """``(column names, rows (n_steps, n_columns))`` of the converged steps:
    step, load time, Newton iterations, cuts; per Dirichlet condition its reaction
    (x, y, and z for a solid); per contact pair its resultant force on the slave (x,
    y), the number of points in contact, the largest pressure and the smallest gap."""
    names = ["step", "time", "iterations", "cuts"]
    for d in result.dirichlet:
        names += [f"reaction_{a} {d.body}/{d.edge}" for a in result.axes]
    pairs = result.steps[0].contact if result.steps else []
    for c in pairs:
        tag = f"{c.slave}->{c.master}"
        names += [f"contact_{a} {tag}" for a in result.axes]
        names += [f"points_in_contact {tag}", f"max_p_n {tag}", f"min_gap {tag}"]
    rows = []
    for s in result.steps:
        row = [s.step, s.time, s.iterations, s.cuts]
        row += list(np.asarray(s.reactions, dtype=float).reshape(-1))
        for c in s.contact:
            gaps = c.gap[np.isfinite(c.gap)]
            row += [*c.force[:result.dimension], int(np.count_nonzero(c.active)),
                    float(c.p_n.max()) if len(c.p_n) else 0.0,
                    float(gaps.min()) if len(gaps) else np.nan]
        rows.append(row)
    return names, np.array(rows, dtype=float).reshape(len(rows), len(names))


def write_history_csv(result: Result, output: str | Path | None = None,
                      out: str | Path | None = None) -> Path:
    """Write :func:`history_table` as CSV (default ``<result>-history.csv``)."""
    path = Path(output) if output else output_path(result.path, "history", out=out, ext="csv")
    names, rows = history_table(result)
    integer = {"step", "iterations", "cuts"}
    with new_file(path) as tmp, open(tmp, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(names)
        for row in rows:
            w.writerow([int(v) if n in integer or n.startswith("points_in_contact") else repr(float(v))
                        for n, v in zip(names, row, strict=True)])
    return path


def plot_history(result: Result, output: str | Path | None = None,
                 out: str | Path | None = None) -> Path:
    """Reactions (top) and contact forces (bottom, when the case has contact) against
    the load time; PNG, default ``<result>-history.png``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = Path(output) if output else output_path(result.path, "history", out=out)
    names, rows = history_table(result)
    col = {n: k for k, n in enumerate(names)}
    has_contact = any(n.startswith("contact_x") for n in names)
    fig, axes = plt.subplots(2 if has_contact else 1, 1, figsize=(7.5, 7.0 if has_contact else 4.2),
                             sharex=True, layout="constrained", squeeze=False)
    unit = result.units.resultant(result.dimension)
    t = rows[:, col["time"]]
    forces = [k for n, k in col.items() if n.startswith(("reaction_", "contact_"))]
    # components that are zero up to round-off of the largest force are left out
    noise = 1e-9 * (float(np.abs(rows[:, forces]).max()) if forces and len(rows) else 0.0)
    ax = axes[0, 0]
    for d in result.dirichlet:
        for comp, style in zip(result.axes, ("-", "--", ":")[:result.dimension], strict=True):
            y = rows[:, col[f"reaction_{comp} {d.body}/{d.edge}"]]
            if np.abs(y).max(initial=0.0) > noise:
                ax.plot(t, y, style, marker=".", ms=3, label=f"$R_{comp}$ {d.body}/{d.edge}")
    ax.set_ylabel(f"reaction [{unit}]")
    ax.set_title(f"{result.title or result.path.name}: load history ({result.status})", fontsize=10)
    if has_contact:
        ax2 = axes[1, 0]
        for n in names:
            if n.startswith("contact_") and np.abs(rows[:, col[n]]).max(initial=0.0) > noise:
                kind, tag = n.split(" ", 1)
                comp = kind[-1]
                ax2.plot(t, rows[:, col[n]], "-" if comp == "x" else "--", marker=".", ms=3,
                         label=f"$F_{comp}$ on {tag.split('->')[0]} ({tag})")
        ax2.set_ylabel(f"contact force on the slave [{unit}]")
    for a in axes[:, 0]:
        a.axhline(0.0, color="0.6", lw=0.6)
        if a.get_legend_handles_labels()[0]:
            a.legend(fontsize=8)
        a.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("load time (phase k ends at time k)")
    save_figure(fig, path, dpi=150)
    plt.close(fig)
    return path
