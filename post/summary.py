"""What a result file says, in a few lines (``python -m post summary``; printed by
``python -m post run``): status, steps and cost, the reactions and contact forces of
the last converged step, and for the hertz scene the comparison with analytic Hertz."""

from __future__ import annotations

import numpy as np

from .reader import Result


def _vec(v: np.ndarray) -> str:
    return f"({v[0]:.6g}, {v[1]:.6g})"


def summary_lines(result: Result) -> list[str]:
    """Human-readable lines describing ``result`` (any status)."""
    u = result.units
    steps = result.steps
    iters = sum(s.iterations if s.iterations_total is None else s.iterations_total for s in steps)
    lines = [f"{result.title or result.path.name}: {result.status or 'no status'}, "
             f"{len(steps)} of {result.n_steps_planned} steps, {iters} Newton iterations, "
             f"{int(result.attrs.get('n_cuts', 0))} cuts, {result.n_dofs} DOFs, "
             f"{result.wall_time:.3g} s"]
    if not u.known:
        lines.append(f"units: the file says {result.attrs.get('units', '')!r}: "
                     "labels use 'length' and 'force'")
    if not steps:
        return lines
    last = steps[-1]
    lines.append(f"last converged step {last.step}, load time {last.time:g}:")
    for d, r in zip(result.dirichlet, last.reactions):
        lines.append(f"  reaction on {d.body}/{d.edge}: {_vec(r)} {u.line_force}")
    for c in last.contact:
        active = c.active
        line = (f"  contact {c.slave} -> {c.master}: force on {c.slave} {_vec(c.force)} "
                f"{u.line_force}, {int(active.sum())} of {len(active)} points in contact")
        if active.any():
            gap = c.gap[active]
            x = c.x[active]
            line += (f", max p_N {c.p_n.max():.4g} {u.pressure}, largest penetration "
                     f"{-gap.min():.3g} {u.length}, zone x in [{x[:, 0].min():.4g}, "
                     f"{x[:, 0].max():.4g}]")
        lines.append(line)
    if result.scene == "hertz" and last.contact:
        from .contact import format_hertz, hertz_comparison
        try:
            lines.append("hertz vs analytic: " + format_hertz(hertz_comparison(result)))
        except ValueError as err:
            lines.append(f"hertz vs analytic: not available ({err})")
    return lines
