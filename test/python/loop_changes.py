"""The indicator against the change between the refinement loop's cycles, per step
(docs/verification.md, "Without an analytic answer"):

    python test/python/loop_changes.py DIR STEM [--steps]

reads the loop's results in DIR (``STEM-zone0/STEM.h5`` and ``STEM-zone<k>/STEM-zone<k>.h5``, as
`python -m post run CASE --adapt --out DIR` leaves them) and prints per cycle its DOFs,
its largest estimate and the largest change to the next cycle (``post.adapt``'s
measure: the relative L2 change of the pressure along the slave parameter), and the
ratio of each step's estimate to that step's change; ``--steps`` lists every step.
"""

from __future__ import annotations

import argparse
import math
import re
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from post.indicator import measure, nominal_pressure  # noqa: E402
from post.reader import ContactOutput, Result, read_result  # noqa: E402


def cycle_paths(folder: Path, stem: str) -> list[Path]:
    """The loop's results in cycle order."""
    refined = sorted(folder.glob(f"{stem}-zone*/{stem}-zone*.h5"),
                     key=lambda p: int(re.findall(r"zone(\d+)$", p.stem)[0]))
    # cycle 0 in STEM-zone0/ (STEM.h5 beside it is the loop's last result, a copy)
    first = folder / f"{stem}-zone0" / f"{stem}.h5"
    return [first if first.is_file() else folder / f"{stem}.h5", *refined]


def _profile(c: ContactOutput, grid: np.ndarray) -> np.ndarray:
    """The pair's pressure, the linear interpolant of its points, on ``grid`` (slave xi)."""
    order = np.argsort(c.xi_slave, kind="stable")
    return np.interp(grid, c.xi_slave[order], nominal_pressure(c)[order], left=0.0, right=0.0)


def step_change(old: Result, new: Result, step: int) -> float:
    """The largest relative L2 change of a pair's pressure from ``old`` to ``new`` at
    ``step`` (``||p_new - p_old|| / ||p_new||``, NaN when either lacks the step)."""
    a = {s.step: s for s in old.steps}.get(step)
    b = {s.step: s for s in new.steps}.get(step)
    if a is None or b is None:
        return math.nan
    worst = 0.0
    for c_old, c_new in zip(a.contact, b.contact, strict=False):
        grid = np.unique(np.concatenate([c_new.xi_slave, c_old.xi_slave]))
        p_new, p_old = _profile(c_new, grid), _profile(c_old, grid)
        norm = float(np.trapezoid(p_new**2, grid))
        if norm > 0:
            worst = max(worst, float(np.sqrt(np.trapezoid((p_new - p_old) ** 2, grid) / norm)))
    return worst


def step_estimates(result: Result) -> dict[int, float]:
    """The largest estimate over a step's pairs and zones, per step."""
    out: dict[int, float] = {}
    for m in measure(result):
        out[m.step] = max(out.get(m.step, 0.0), m.estimate)
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folder", type=Path)
    parser.add_argument("stem")
    parser.add_argument("--steps", action="store_true", help="list every step")
    args = parser.parse_args()
    results = [read_result(p) for p in cycle_paths(args.folder, args.stem)]
    for k, r in enumerate(results):
        est = step_estimates(r)
        if not est:
            print(f"cycle {k}: {r.n_dofs} DOFs, no contact")
            continue
        top = max(est, key=lambda s: est[s])
        line = f"cycle {k}: {r.n_dofs} DOFs, largest estimate {est[top]:.3%} (step {top})"
        change = {s: step_change(r, results[k + 1], s) for s in est} if k + 1 < len(results) else {}
        if change:
            line += f", largest change to cycle {k + 1} {max(change.values()):.3%}"
            ratios = np.array([est[s] / change[s] for s in est
                               if math.isfinite(est[s]) and change[s] > 0])
            if ratios.size:
                inside = np.mean((ratios >= 0.5) & (ratios <= 2.0))
                line += (f"; estimate / change per step {ratios.min():.2f} .. {ratios.max():.2f}, "
                         f"median {np.median(ratios):.2f}, {inside:.0%} of {ratios.size} within 2")
        print(line)
        if args.steps:
            for s in sorted(est):
                print(f"  step {s}: estimate {est[s]:.3%}, change {change.get(s, math.nan):.3%}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
