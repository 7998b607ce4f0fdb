"""What a result file says, in a few lines (``python -m post summary``; printed by
``python -m post run``): status, steps and cost, the reactions and contact forces of
the last converged step, and for the hertz (hertz3d) scene the comparison with analytic Hertz."""

from __future__ import annotations

import numpy as np

from .plot import breakpoints
from .reader import ContactOutput, Result

PENETRATION_WARNING = 0.1
"""Warn when the largest penetration exceeds this fraction of the slave element size."""


def slave_element_size(result: Result, c: ContactOutput, xi: float) -> float:
    """Length (reference configuration) of the slave's contact-edge element that holds
    the edge parameter ``xi``: the polyline through its slave points, scaled from their
    parameter range to the element's."""
    breaks = breakpoints(result.body(c.slave))[0]
    k = int(np.clip(np.searchsorted(breaks, xi, side="right") - 1, 0, len(breaks) - 2))
    a, b = breaks[k], breaks[k + 1]
    inside = np.flatnonzero((c.xi_slave >= a) & (c.xi_slave <= b))
    inside = inside[np.argsort(c.xi_slave[inside], kind="stable")]
    if len(inside) < 2:
        return float("nan")
    length = float(np.linalg.norm(np.diff(c.x_ref[inside], axis=0), axis=1).sum())
    covered = float(c.xi_slave[inside[-1]] - c.xi_slave[inside[0]])
    return length * (b - a) / covered if covered > 0 else float("nan")


def warnings_for(result: Result) -> list[str]:
    """What a result file shows that the user should know. voiga records its own
    warnings in the root attribute ``warnings`` (docs/warnings.md):
    those, when the file has the attribute. Files written before it: a contact pair
    that was never in contact at any converged step, and a penetration larger than
    ``PENETRATION_WARNING`` of the size of the slave element where it is largest
    (penalty too small, or a contact edge on the wrong side of a body)."""
    if "warnings" in result.attrs:
        text = result.attrs["warnings"]
        return [f"warning: {line}" for line in str(text).split("\n") if line.strip()]
    out: list[str] = []
    if not result.steps:
        return out
    for k, c in enumerate(result.steps[-1].contact):
        pair = f"contact {c.slave} -> {c.master}"
        ever = [s.contact[k] for s in result.steps if s.contact[k].active.any()]
        if not ever:
            out.append(f"warning: {pair} was never in contact (check the contact edges, "
                       "the loads and the rigid line's normal)")
            continue
        deepest = max(ever, key=lambda cc: float(-cc.gap[cc.active].min()))
        i = np.flatnonzero(deepest.active)[int(np.argmin(deepest.gap[deepest.active]))]
        depth = float(-deepest.gap[i])
        h = slave_element_size(result, deepest, float(deepest.xi_slave[i]))
        if h > 0 and depth > PENETRATION_WARNING * h:
            out.append(f"warning: {pair}: the largest penetration {depth:.3g} is "
                       f"{depth / h:.0%} of the slave element size {h:.3g}: raise "
                       "penalty_normal, or check that the contact edges face each other")
    return out


def _vec(v: np.ndarray) -> str:
    """A vector's components, ``(1, -2.5)``: as many as it has (the file's dimension)."""
    return "(" + ", ".join(f"{c:.6g}" for c in v) + ")"


def summary_lines(result: Result) -> list[str]:
    """Human-readable lines describing ``result`` (any status; the recorded warnings
    also when no step converged)."""
    u = result.units
    steps = result.steps
    iters = sum(s.iterations if s.iterations_total is None else s.iterations_total for s in steps)
    # voiga records the iterations of all attempts (failed ones too) when the run ends;
    # a restarted run counts its own only, the written steps count theirs
    iters = max(iters, int(result.attrs.get("newton_iterations", 0)))
    lines = [f"{result.title or result.path.name}: {result.status or 'no status'}, "
             f"{len(steps)} of {result.n_steps_planned} steps, {iters} Newton iterations, "
             f"{int(result.attrs.get('n_cuts', 0))} cuts, {result.n_dofs} DOFs ({result.dimension}D), "
             f"{result.wall_time:.3g} s"]
    if not u.known:
        lines.append(f"units: the file says {result.attrs.get('units', '')!r}: "
                     "labels use 'length' and 'force'")
    if not steps:
        return lines + warnings_for(result)
    last = steps[-1]
    lines.append(f"last converged step {last.step}, load time {last.time:g}:")
    for d, r in zip(result.dirichlet, last.reactions, strict=True):
        lines.append(f"  reaction on {d.body}/{d.edge}: {_vec(r)} {u.resultant(result.dimension)}")
    for c in last.contact:
        active = c.active
        line = (f"  contact {c.slave} -> {c.master}: force on {c.slave} {_vec(c.force)} "
                f"{u.resultant(result.dimension)}, {int(active.sum())} of {len(active)} points in contact")
        if active.any():
            gap = c.gap[active]
            x = c.x[active]
            line += (f", max p_N {c.p_n.max():.4g} {u.pressure}, largest penetration "
                     f"{-gap.min():.3g} {u.length}, zone x in [{x[:, 0].min():.4g}, "
                     f"{x[:, 0].max():.4g}]")
        lines.append(line)
    lines += warnings_for(result)
    if result.dimension == 2 and any(c.active.any() for s in steps for c in s.contact):
        from .indicator import indicator_lines
        lines += indicator_lines(result)
    if result.dimension == 3:
        from .indicator import face_lines
        lines += face_lines(result)
    if result.scene == "hertz" and last.contact:
        from .hertz import format_hertz, hertz_comparison
        try:
            lines.append("hertz vs analytic: " + format_hertz(hertz_comparison(result)))
        except ValueError as err:
            lines.append(f"hertz vs analytic: not available ({err})")
    if result.scene == "hertz3d" and last.contact:
        from .hertz3d import format_hertz3d, hertz3d_comparison
        try:
            lines.append("hertz3d vs analytic: " + format_hertz3d(hertz3d_comparison(result)))
        except ValueError as err:
            lines.append(f"hertz3d vs analytic: not available ({err})")
    return lines
