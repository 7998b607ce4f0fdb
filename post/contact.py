"""Contact output along the slave edge: the penalty pressure as a continuous field, the
slave edge's stretch, and the p_N / p_T plot along the contact (``python -m post
plot-contact``). The Hertz comparison is :mod:`post.hertz`."""

from __future__ import annotations

from itertools import pairwise
from pathlib import Path

import numpy as np

from pre.files import save_figure
from pre.nurbs import Curve, curve_to_splipy

from .naming import output_path
from .reader import Body, ContactOutput, Result, Step


def slave_edge_curve(body: Body) -> tuple[Curve, np.ndarray]:
    """The slave body's contact edge as a curve in the reference configuration (the
    VO layer, else the bulk's eta = 1 row) and its control points' 0-based body ids
    (the edge in ``body.edges`` that lists them)."""
    if body.layer is not None:
        curve = body.layer
    else:
        b = body.bulk
        curve = Curve(degree=b.degree[0], knots=b.knots_xi, control_points=b.control_points[-1],
                      weights=b.weights[-1])
    for ids in body.edges.values():
        if len(ids) == len(curve.weights) and np.allclose(body.control_points[ids],
                                                          curve.control_points, atol=1e-12):
            return curve, ids
    raise ValueError(f"body {body.name!r}: no edge lists the contact edge's control points")


def _slave_edges(result: Result, st: Step, pair: int) -> tuple[Curve, Curve]:
    """The contact edge of ``pair``'s slave body in the reference configuration and
    displaced by step ``st``."""
    body = result.bodies[st.contact[pair].slave]
    curve, ids = slave_edge_curve(body)
    u = np.asarray(st.displacement[body.dofs]).reshape(-1, body.nsd)
    moved = Curve(degree=curve.degree, knots=curve.knots,
                  control_points=curve.control_points + u[ids], weights=curve.weights)
    return curve, moved


def edge_stretch(result: Result, st: Step, pair: int = 0) -> np.ndarray:
    """(n,) current over reference length of ``pair``'s slave edge at its slave points,
    ``|dx/dxi| / |dX/dxi|`` from the edge curve and the step's displacement: what
    voiga writes as ``stretch`` (docs/hdf5.md), for files written before it did."""
    curve, moved = _slave_edges(result, st, pair)
    t = st.contact[pair].xi_slave
    speed = [np.linalg.norm(np.asarray(curve_to_splipy(k).derivative(t), dtype=float)
                            .reshape(-1, 2), axis=1) for k in (curve, moved)]
    return speed[1] / speed[0]


def pressure_field(result: Result, step: int = -1, pair: int = 0, per_span: int = 64,
                   params: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The penalty contact pressure as the continuous field it is along the slave
    curve, p = eps_N <-g>, g = (x - p0) . n, for a pair with a rigid master line:
    current points ``(m, 2)`` and pressures ``(m,)`` at ``per_span`` parameters per
    knot span of the slave's contact edge (ends included). Unlike the per-Gauss-point
    output, this does not depend on where the quadrature points lie. ``params``:
    evaluate at these parameters of the edge instead."""
    st = result.steps[step] if step != 0 else None
    if st is None:
        raise ValueError("pressure_field needs a converged step")
    c = st.contact[pair]
    if c.rigid_point is None or c.rigid_normal is None:
        raise ValueError("pressure_field: only for a rigid master line")
    eps = float(c.attrs["penalty_normal"])
    curve, moved = _slave_edges(result, st, pair)
    breaks = np.unique(curve.knots)
    t = np.unique(np.concatenate([np.linspace(a, b, per_span) for a, b in pairwise(breaks)])) \
        if params is None else np.asarray(params, dtype=float)
    x = np.asarray(curve_to_splipy(moved)(t), dtype=float).reshape(-1, 2)
    gap = (x - c.rigid_point) @ c.rigid_normal
    return x, eps * np.maximum(0.0, -gap)


def contact_profile(c: ContactOutput, axis: int = 0,
                    margin: int = 3) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Current position along ``axis`` (sorted), p_N and p_T of one pair's slave points
    around the contact zone: in the slave parameter's order, from ``margin`` points
    before the first point in contact to ``margin`` points after the last (all points
    when none is in contact). Points elsewhere on the slave edge (e.g. the far side
    of a ring, at the same x) would otherwise interleave with the zone's."""
    along = np.argsort(c.xi_slave, kind="stable")
    act = np.flatnonzero(c.active[along])
    if act.size:
        along = along[max(0, act[0] - margin):act[-1] + margin + 1]
    order = along[np.argsort(c.x[along, axis], kind="stable")]
    return c.x[order, axis], c.p_n[order], c.p_t[order]


def plot_contact(result: Result, step: int = -1, output: str | Path | None = None,
                 axis: int = 0, out: str | Path | None = None) -> Path:
    """p_N and p_T of every contact pair along the contact (current ``axis`` coordinate);
    default file ``<result>-contact-<step>.png`` next to the result or in ``out``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    st = result.steps[step]
    fig, ax = plt.subplots(figsize=(7.0, 4.0), constrained_layout=True)
    for c in st.contact:
        x, pn, pt = contact_profile(c, axis)
        label = f"{c.slave} on {c.master}"
        ax.plot(x, pn, "o-", ms=3, label=f"$p_N$ {label}")
        if np.any(pt != 0.0):
            ax.plot(x, pt, "s--", ms=3, label=f"$p_T$ {label}")
    active = np.concatenate([c.x[c.active, axis] for c in st.contact]) if st.contact else np.zeros(0)
    if active.size:
        lo, hi = active.min(), active.max()
        pad = 0.25 * max(hi - lo, 1e-12)
        ax.set_xlim(lo - pad, hi + pad)
    units = result.units
    ax.set_xlabel(f"{'xy'[axis]} (current) [{units.length}]")
    ax.set_ylabel(f"contact traction [{units.pressure}]")
    ax.set_title(f"{result.title}: step {st.step} (load time {st.time:g})")
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.legend()
    path = Path(output) if output else output_path(result.path, "contact", st.step, out)
    save_figure(fig, path, dpi=150)
    plt.close(fig)
    return path
