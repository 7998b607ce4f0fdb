"""How well the mesh resolves the edges of a contact zone (``python -m post summary``;
the derivation is docs/theory.md, section 8, the details docs/contact-accuracy.md).

Per contact pair and converged step, every zone (a run of slave points in contact, in
slave-parameter order) is measured on the slave's contact edge in the reference
configuration:

- ``elements_across``: slave elements the zone covers (a partly covered element counts
  with the covered fraction of its length);
- at each *free* edge (a zone that reaches the first or last slave point ends at a
  symmetry cut or at the end of the edge, not at a free edge): the tangential size of the
  slave element that holds the edge and the size of the surface element row across the
  edge, both relative to the zone's half-width ``w`` (half the zone's length between two
  free edges, its whole length from a cut to one free edge);
- an estimate of the relative L2 error of the pressure made at that edge. Near a free
  edge of a smooth contact the pressure squared is smooth, ``p^2 = c1 d + c2 d^2 + ...``
  in the distance ``d`` into the zone (Hertz: exactly so); fitted to the points between
  one edge element and ``FIT_BAND`` w from the edge, where the mesh resolves the profile
  (on a coarse zone, where that band is shorter than ``MIN_BAND_ELEMENTS`` edge elements,
  to the zone's points within that many elements of the edge: :func:`fit_points`), it
  is continued to the edge, and the L2 difference of the computed pressure from it over
  the edge's elements, relative to the L2 norm of the zone's pressure, is the raw
  estimate. ``CALIBRATION`` scales it to the L2 error the Hertz comparison measures there
  (docs/contact-accuracy.md gives the fit of the constant);
- the penalty's edge length ``E*/penalty_normal`` (:func:`penalty_length`): when it
  exceeds the edge's element the penalty, not the mesh, shapes the edge, and the summary
  says so.

A pair's estimate at a step is the root of the sum of the squares of its edges'
(the squares of an L2 split add up). The estimate is the part of the error the mesh
makes at the edges; the interior and the penalty's own compliance are not in it (a
penalty that smears the edges over more than their elements is, and is reported).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from pre.nurbs import evaluate_patch

from .plot import breakpoints
from .reader import Body, ContactOutput, Result
from .summary import slave_element_size

FIT_BAND = 0.5
"""The fit of p^2 near an edge uses the points between one edge element and this
fraction of the zone's half-width from the edge (when that band is long enough)."""
MIN_BAND_ELEMENTS = 3.0
"""A band ``FIT_BAND`` w shorter than this many edge elements h (a coarse zone: fewer
than 6 elements from a cut to the edge, 12 between two free edges) holds too few
resolved points beyond the edge element for the quadratic: the fit then takes every
point of the zone within this many edge elements of the edge, the edge element's too
(p^2 is close to a quadratic across a smooth zone; Hertz: exactly ``p0^2 (1 -
x^2/a^2)``)."""
CALIBRATION = 0.65
"""Scales the raw estimate to the measured L2 error at the edges (docs/contact-accuracy.md)."""
WARN_ESTIMATE = 0.005
"""A pair whose estimated edge error exceeds this (0.5 %) at a step is warned about."""
MIN_POINTS = 3
"""Fewer points in contact than this: the zone is not resolved at all."""
EXACT_METHODS = ("alm",)
"""Contact methods that enforce the contact exactly: no penalty compliance."""


@dataclass(frozen=True)
class EdgeMeasure:
    """One free edge of a contact zone."""

    xi: float
    """Slave-edge parameter of the edge: where the fit of p^2 reaches zero when that is
    between the last point in contact and the first one out, else midway between them."""
    side: int
    """+1: the zone lies at smaller xi (the edge is its upper end); -1: at larger xi."""
    h_tangent: float
    """Reference length of the slave element holding the edge."""
    h_normal: float
    """Reference size of the surface element row across the slave edge at the edge."""
    ratio_tangent: float
    """``h_tangent / w``."""
    ratio_normal: float
    """``h_normal / w``."""
    raw: float
    """The uncalibrated estimate (the fit's L2 residual over the edge elements)."""
    bracket: float = 0.0
    """Reference distance between the last point in contact and the first one out: how
    well the points place the edge."""
    half_width: float = math.nan
    """w of the edge's zone."""
    vanishing: bool = True
    """Does the pressure vanish towards the edge (less on average in the edge element
    than over the fitted points)? Where it does not (a punch's corner, a conforming edge: p rises
    towards the edge) the square-root model does not hold: ``raw`` is 0, not estimated."""

    @property
    def estimate(self) -> float:
        """Estimated relative L2 error of the pressure made at this edge."""
        return CALIBRATION * self.raw


@dataclass(frozen=True)
class ZoneMeasure:
    """One contact zone of a pair at a step."""

    pair: int
    slave: str
    master: str
    step: int
    time: float
    xi_range: tuple[float, float]
    """Slave-edge parameters of the zone's first and last points in contact."""
    half_width: float
    """w: the zone's reference half-width (see the module docstring)."""
    elements_across: float
    n_points: int
    """Slave points in contact."""
    edges: list[EdgeMeasure] = field(default_factory=list)
    penalty_length: float = math.nan
    """The pair's :func:`penalty_length` (0 for an exact method, NaN when unknown)."""

    @property
    def penalty_smeared(self) -> bool:
        """The penalty smears a free edge over more than the element holding it: the
        estimate then measures the penalty's profile as much as the mesh's, and refining
        the edge does not lower it (docs/contact-accuracy.md)."""
        return any(self.penalty_length > e.h_tangent for e in self.edges)

    @property
    def resolved(self) -> bool:
        """Enough points in contact to measure the zone at all."""
        return self.n_points >= MIN_POINTS

    @property
    def estimate(self) -> float:
        """Estimated relative L2 error of the zone's pressure made at its edges (inf for
        a zone of fewer than :data:`MIN_POINTS` points)."""
        if not self.resolved:
            return math.inf
        return float(np.sqrt(sum(e.estimate**2 for e in self.edges)))


def nominal_pressure(c: ContactOutput) -> np.ndarray:
    """The pressure per reference length (``p_n`` in files without it)."""
    return c.p_n_nominal if c.p_n_nominal is not None else c.p_n


def penalty_length(result: Result, c: ContactOutput) -> float:
    """``E* / penalty_normal``: the length over which the normal penalty's compliance
    smears a free edge. Under a pressure p a penalty eps lets the bodies overlap by
    ``p / eps``; the bodies' own deflection over a length l is of order ``p l / E*``;
    the two are equal at ``l = E* / eps``, so an edge resolved finer than that is the
    penalty's, not the exact contact's. E* is the plane-strain modulus of the pair in
    series, ``1/E* = sum (1 - nu^2)/E`` (the slave's alone against a rigid master), as
    voiga's automatic penalty ``10 E* q / h`` uses it (docs/theory.md), whose length is
    ``h / (10 q)``: a tenth of the element. 0 for an exact method
    (:data:`EXACT_METHODS`); NaN when the file lacks the penalty or a modulus."""
    method = str(c.attrs.get("method", "")).strip()
    if method in EXACT_METHODS:
        return 0.0
    eps = float(c.attrs.get("penalty_normal", math.nan))
    names = [c.slave] + ([c.master] if c.master in result.bodies else [])
    compliance = sum((1.0 - result.bodies[n].poisson_ratio ** 2) / result.bodies[n].youngs_modulus
                     for n in names)
    if not (eps > 0 and compliance > 0):
        return math.nan
    return float(1.0 / compliance / eps)


def arc_coordinate(x_ref: np.ndarray) -> np.ndarray:
    """(n,) reference distance along the polyline through the points (in their order)."""
    steps = np.linalg.norm(np.diff(x_ref, axis=0), axis=1)
    return np.concatenate([[0.0], np.cumsum(steps)])


def element_breaks(body: Body) -> np.ndarray:
    """The slave edge's element boundaries in its parameter (the bulk's xi breaks)."""
    return breakpoints(body)[0]


def normal_size(body: Body, xi: float) -> float:
    """Reference distance across the surface element row at the edge parameter ``xi``:
    from eta = 1 to the row's inner boundary (the bulk's last eta break)."""
    eta = breakpoints(body)[1]
    inner = float(eta[-2]) if len(eta) > 1 else 0.0
    pts = evaluate_patch(body.bulk, np.array([xi, xi]), np.array([1.0, inner]))
    return float(np.linalg.norm(pts[0] - pts[1]))


def zones(active: np.ndarray) -> list[tuple[int, int]]:
    """Index ranges ``(first, last)`` (inclusive) of the runs of True in ``active``."""
    on = np.flatnonzero(active)
    if not on.size:
        return []
    cuts = np.flatnonzero(np.diff(on) > 1)
    starts = np.concatenate([[on[0]], on[cuts + 1]])
    ends = np.concatenate([on[cuts], [on[-1]]])
    return list(zip(starts.tolist(), ends.tolist(), strict=True))


def _covered(breaks: np.ndarray, lo: float, hi: float) -> float:
    """Elements of ``breaks`` covered by [lo, hi], partly covered ones by their fraction."""
    spans = np.diff(breaks)
    overlap = np.clip(np.minimum(breaks[1:], hi) - np.maximum(breaks[:-1], lo), 0.0, None)
    return float(np.sum(overlap / spans))


def fit_points(d: np.ndarray, p: np.ndarray, h: float, band: float) -> np.ndarray:
    """The points the fit of p^2 near an edge uses (``d`` the distance into the zone,
    ``p`` the pressure, ``h`` the edge element's length, ``band`` = ``FIT_BAND`` w).
    The zone's points are those with ``d > 0`` and ``p > 0``. When ``band >=
    MIN_BAND_ELEMENTS h``: those with ``h <= d <= band``; else (a coarse zone) those
    with ``d <= MIN_BAND_ELEMENTS h``. All of the zone's points when the choice has
    fewer than three."""
    zone = (d > 0) & (p > 0)
    if band >= MIN_BAND_ELEMENTS * h:
        fit = zone & (d >= h) & (d <= band)
    else:
        fit = zone & (d <= MIN_BAND_ELEMENTS * h)
    return fit if np.count_nonzero(fit) >= 3 else zone


def _edge_residual(d: np.ndarray, p: np.ndarray, h: float, band: float) -> tuple[float, float, bool]:
    """The squared L2 residual of the computed pressure ``p`` (at distances ``d`` into
    the zone from its computed edge, midway between the last point in contact and the
    first one out) from the reference ``sqrt(c0 + c1 d + c2 d^2)``, least squares in
    p^2 over the points :func:`fit_points` chooses, and the distance of the fitted edge.

    The fitted edge is the fit's largest root below the nearest fitted point, or the
    computed edge (0) when the fit has none there (a fit that does not fall to zero
    describes no free edge: continued over the points out of contact it would count
    pressure no contact carries); the reference is zero beyond it. The residual is the
    trapezoidal integral of ``(p - ref)^2`` over the points with ``d < min(2 h, w)``,
    ``w = band / FIT_BAND`` the zone's half-width: the two edge elements and the points
    out of contact beyond them, never past the middle of a zone between two free edges
    (whose other half is the other edge's). ``(NaN, NaN)`` for fewer than three points
    in contact. Third: whether the pressure vanishes towards the edge (the points in
    contact within the edge element carry less on average than the fitted ones)."""
    fit = fit_points(d, p, h, band)
    if np.count_nonzero(fit) < 3:
        return math.nan, math.nan, True
    dd = d[fit]
    coef, *_ = np.linalg.lstsq(design_at(dd), p[fit] ** 2, rcond=None)
    ref = np.sqrt(np.clip(design_at(d) @ coef, 0.0, None))
    root = _first_root(coef, float(dd.min()))
    if not np.isfinite(root):
        root = 0.0
    # the pressure vanishes towards the edge when the edge element's points carry less
    # on average than the fitted ones (a punch's corner: a spike there)
    # (judged where the band resolves the profile: on a coarse zone the edge element's
    # pressure is the mesh's artefact as often as not)
    edge = (d >= 0) & (d < h) & (p > 0)
    vanishing = bool(p[edge].mean() < p[fit].mean()) if edge.any() and band >= MIN_BAND_ELEMENTS * h else True
    ref[d < root] = 0.0
    near = d < min(2 * h, band / FIT_BAND)
    order = np.argsort(d[near])
    x, r = d[near][order], (p[near] - ref[near])[order]
    return (float(np.trapezoid(r**2, x)) if len(x) > 1 else 0.0), root, vanishing


def design_at(d: np.ndarray) -> np.ndarray:
    """The columns ``1, d, d^2`` of the edge fit at ``d``."""
    return np.column_stack([np.ones_like(d), d, d**2])


def edge_position(d: np.ndarray, p: np.ndarray, h: float, band: float) -> float:
    """Where the edge is, as a distance into the zone from the computed one: the root
    (:func:`_first_root`) of the fit of p^2 to the points the mesh resolves, ``h <= d
    <= max(band, 2 h)`` (fewer than three: all with ``p > 0``), continued to the edge;
    -inf without one, NaN with fewer than three points. Not the residual's fit on a
    coarse zone, which takes the edge element's own points: the zone's shape needs them,
    but placed from them the first refinement's knots moved by about a third of the
    points' spacing and the committed cylinder's loop needed a third cycle
    (docs/contact-accuracy.md)."""
    fit = (d >= h) & (d <= max(band, 2 * h)) & (p > 0)
    if np.count_nonzero(fit) < 3:
        fit = p > 0
    if np.count_nonzero(fit) < 3:
        return math.nan
    coef, *_ = np.linalg.lstsq(design_at(d[fit]), p[fit] ** 2, rcond=None)
    return _first_root(coef, float(d[fit].min()))


def _first_root(coef: np.ndarray, start: float) -> float:
    """The largest root of ``c0 + c1 d + c2 d^2`` below ``start`` (-inf when none)."""
    roots = np.roots(coef[::-1]) if abs(coef[2]) > 0 else np.array([-coef[0] / coef[1]])
    real = np.real(roots[np.abs(np.imag(roots)) < 1e-12])
    below = real[real < start]
    return float(below.max()) if below.size else -math.inf


@dataclass(frozen=True)
class _Profile:
    """A pair's slave points at a step in slave-parameter order."""

    xi: np.ndarray
    s: np.ndarray
    """Reference distance along the slave edge (:func:`arc_coordinate`)."""
    p: np.ndarray
    """Nominal pressure."""


def _measure_edge(result: Result, c: ContactOutput, prof: _Profile, zone: tuple[int, int],
                  i: int, side: int, w: float, norm: float) -> EdgeMeasure:
    """The free edge of ``zone`` after its point ``i`` (``side`` +1: the zone's upper
    end, -1: its lower end); ``w`` the zone's half-width, ``norm`` its squared L2 norm."""
    xi, s, p = prof.xi, prof.s, prof.p
    j = i + side  # the first point out of contact
    xe, se = 0.5 * (xi[i] + xi[j]), 0.5 * (s[i] + s[j])
    h = slave_element_size(result, c, float(xe))
    d = side * (se - s)  # distance into the zone
    mask = np.zeros(len(xi), dtype=bool)  # the zone's points and those out within 2 h
    mask[zone[0]:zone[1] + 1] = True
    mask[(d < 0) & (d > -2 * h)] = True
    residual, _, vanishing = _edge_residual(d[mask], p[mask], h, FIT_BAND * w)
    root = edge_position(d[mask], p[mask], h, FIT_BAND * w)
    if abs(root) <= abs(s[j] - s[i]):  # the fitted edge, when between the points
        xe = float(np.interp(se - side * root, s, xi))
    hn = normal_size(result.body(c.slave), float(xe))
    raw = math.sqrt(residual / norm) if norm > 0 and np.isfinite(residual) else math.inf
    raw = raw if vanishing else 0.0
    return EdgeMeasure(xi=float(xe), side=side, h_tangent=h, h_normal=hn,
                       ratio_tangent=h / w if w > 0 else math.inf,
                       ratio_normal=hn / w if w > 0 else math.inf, raw=raw,
                       bracket=float(abs(s[j] - s[i])), half_width=float(w), vanishing=vanishing)


def _ratio(h: float, w: float) -> float:
    """``h / w`` (inf for a zone of no width)."""
    return h / w if w > 0 else math.inf


def recorded_pair(result: Result, step_index: int, pair: int) -> list[ZoneMeasure] | None:
    """The zones voiga measured and wrote for pair ``pair`` at step ``step_index`` (its
    ``accuracy`` group, the same quantities as :func:`measure_pair` computes), or None
    when the file has none (written before voiga did, or a face)."""
    st = result.steps[step_index]
    c = st.contact[pair]
    a = c.accuracy
    if a is None:
        return None
    zones: list[ZoneMeasure] = []
    owner = np.asarray(a.get("edge_zone", []), dtype=int).reshape(-1) - 1
    for z in range(int(a["zones"])):
        w = float(a["half_width"][z])
        edges = [EdgeMeasure(xi=float(a["edge_xi"][e]), side=int(a["edge_side"][e]),
                             h_tangent=float(a["edge_h_tangent"][e]), h_normal=float(a["edge_h_normal"][e]),
                             ratio_tangent=_ratio(float(a["edge_h_tangent"][e]), w),
                             ratio_normal=_ratio(float(a["edge_h_normal"][e]), w),
                             raw=float(a["edge_raw"][e]), bracket=float(a["edge_bracket"][e]), half_width=w,
                             vanishing=bool(a["edge_vanishing"][e]) if "edge_vanishing" in a else True)
                 for e in np.flatnonzero(owner == z)]
        lo, hi = (float(v) for v in np.asarray(a["xi_range"]).reshape(-1, 2)[z])
        zones.append(ZoneMeasure(pair=pair, slave=c.slave, master=c.master, step=st.step, time=st.time,
                                 xi_range=(lo, hi), half_width=w,
                                 elements_across=float(a["elements_across"][z]),
                                 n_points=int(a["n_points"][z]), edges=edges,
                                 penalty_length=penalty_length(result, c)))
    return zones


def measure_pair(result: Result, step_index: int, pair: int, computed: bool = False) -> list[ZoneMeasure]:
    """The zones of contact pair ``pair`` (0-based) at converged step ``step_index``
    (an index into ``result.steps``): those voiga wrote to the file, or (files without
    them, or ``computed``) measured here from the slave points."""
    recorded = None if computed else recorded_pair(result, step_index, pair)
    if recorded is not None:
        return recorded
    st = result.steps[step_index]
    c = st.contact[pair]
    order = np.argsort(c.xi_slave, kind="stable")
    prof = _Profile(xi=c.xi_slave[order], s=arc_coordinate(c.x_ref[order]),
                    p=nominal_pressure(c)[order])
    xi, s, p = prof.xi, prof.s, prof.p
    breaks = element_breaks(result.body(c.slave))
    delta = penalty_length(result, c)
    n = len(xi)
    out: list[ZoneMeasure] = []
    for i0, i1 in zones(c.active[order] & (p > 0)):
        free = ([(i0, -1)] if i0 > 0 else []) + ([(i1, +1)] if i1 < n - 1 else [])
        # the zone's ends midway between its outer points and the first ones out
        s_lo = 0.5 * (s[i0] + s[i0 - 1]) if i0 > 0 else s[0]
        s_hi = 0.5 * (s[i1] + s[i1 + 1]) if i1 < n - 1 else s[-1]
        w = 0.5 * (s_hi - s_lo) if len(free) == 2 else s_hi - s_lo
        xi_lo = 0.5 * (xi[i0] + xi[i0 - 1]) if i0 > 0 else breaks[0]
        xi_hi = 0.5 * (xi[i1] + xi[i1 + 1]) if i1 < n - 1 else breaks[-1]
        around = slice(max(i0 - 1, 0), min(i1 + 2, n))
        norm = float(np.trapezoid(p[around] ** 2, s[around]))
        edges = [_measure_edge(result, c, prof, (i0, i1), i, side, w, norm) for i, side in free]
        out.append(ZoneMeasure(pair=pair, slave=c.slave, master=c.master, step=st.step,
                               time=st.time, xi_range=(float(xi[i0]), float(xi[i1])),
                               half_width=float(w),
                               elements_across=_covered(breaks, xi_lo, xi_hi),
                               n_points=i1 - i0 + 1, edges=edges, penalty_length=delta))
    return out


def measure(result: Result) -> list[ZoneMeasure]:
    """Every zone of every pair at every converged step, in step then pair order."""
    out: list[ZoneMeasure] = []
    for k, st in enumerate(result.steps):
        for pair in range(len(st.contact)):
            out += measure_pair(result, k, pair)
    return out


def worst(measures: list[ZoneMeasure]) -> dict[int, ZoneMeasure]:
    """Per pair, the zone and step with the largest estimate."""
    out: dict[int, ZoneMeasure] = {}
    for m in measures:
        if m.pair not in out or m.estimate > out[m.pair].estimate:
            out[m.pair] = m
    return out


def format_zone(m: ZoneMeasure) -> str:
    """One line: elements across, h/w at each edge, the estimate."""
    if not m.resolved:
        return (f"contact {m.slave} -> {m.master}, step {m.step}: {m.n_points} point(s) in "
                f"contact, {m.elements_across:.2g} slave elements: the zone is not resolved")
    several = len(m.edges) > 1
    edges = "; ".join(f"edge at xi = {e.xi:.4g}: h/w = {e.ratio_tangent:.3g} along, "
                      f"{e.ratio_normal:.3g} across"
                      + ("" if e.vanishing else " (not estimated: the pressure rises towards it)")
                      + (f", {e.estimate:.2%}" if several and e.vanishing else "")
                      for e in m.edges) or "no free edge"
    smear = (f" (the penalty smears the edges over E*/penalty_normal = {m.penalty_length:.3g}, "
             f"{m.penalty_length / min(e.h_tangent for e in m.edges):.3g} edge elements)"
             if m.penalty_smeared else "")
    return (f"contact {m.slave} -> {m.master}, step {m.step}: {m.elements_across:.1f} slave "
            f"elements across the zone (half-width {m.half_width:.4g}); {edges}; "
            f"estimated edge error {m.estimate:.2%}{smear}")


def indicator_lines(result: Result) -> list[str]:
    """The summary's lines: per pair the step with the largest estimate (and its zone),
    a warning naming the remedy when it exceeds :data:`WARN_ESTIMATE`, and one when the
    penalty smears that zone's edges (:attr:`ZoneMeasure.penalty_smeared`)."""
    lines: list[str] = []
    # voiga warns itself when it wrote the indicator (the file's warnings, post summary's)
    own = any(c.accuracy is not None for st in result.steps for c in st.contact)
    for m in worst(measure(result)).values():
        lines.append("  accuracy: " + format_zone(m))
        if m.penalty_smeared and not own:
            lines.append(f"warning: contact {m.slave} -> {m.master}: penalty_normal smears the "
                         f"contact zone's edges over E*/penalty_normal = {m.penalty_length:.3g} "
                         f"({m.penalty_length / m.half_width:.2g} of the zone's half-width) at "
                         f"step {m.step}, more than the elements that hold them: the estimate "
                         f"includes that smearing, which refining does not remove; a stiffer "
                         f"penalty_normal (or none: voiga's automatic one) does "
                         f"(docs/contact-accuracy.md)")
        if m.estimate > WARN_ESTIMATE and not own:
            lines.append(f"warning: contact {m.slave} -> {m.master}: the mesh resolves the "
                         f"contact zone's edge poorly (estimated pressure error "
                         + (f"{m.estimate:.2%}" if math.isfinite(m.estimate) else "unbounded")
                         + f" at step {m.step}, above {WARN_ESTIMATE:.1%}): refine the zone "
                         f"with `python -m pre refine {result.path}` (docs/howto.md)")
    return lines


def face_lines(result: Result) -> list[str]:
    """The summary's lines for a solid's pairs: per pair the step with the largest
    estimate voiga wrote (on a face, along the lines of slave points; computed by voiga
    only, docs/contact-accuracy.md); voiga's own warning names a large one."""
    best: dict[int, tuple[float, int, ContactOutput]] = {}
    for st in result.steps:
        for k, c in enumerate(st.contact):
            if c.accuracy is None or "pair_estimate" not in c.accuracy:
                continue
            e = float(c.accuracy["pair_estimate"])
            if k not in best or e > best[k][0]:
                best[k] = (e, st.step, c)
    return [f"  accuracy: contact {c.slave} -> {c.master}, step {step}: estimated edge error {e:.2%} "
            f"(along the slave face's lines of points)" for e, step, c in best.values()]
