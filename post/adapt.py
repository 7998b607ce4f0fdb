"""Automatic refinement of the contact zone: from a result, the refined case
(``python -m pre refine RESULT.h5``), and the solve-estimate-refine loop (``python -m
post run CASE --adapt``). docs/howto.md has the recipes, docs/contact-accuracy.md the indicator and the rules.

The refined case is the result's own case (``case_file``, the provenance voiga writes)
with new explicit ``knots_xi`` and ``knots_eta`` for every slave body and every
deformable master: the result's element boundaries (the old knots, kept: the mesh
nests) plus a knot at every free edge of every zone at every converged step (where the
indicator's fit puts it) and knots around it, so that one mesh resolves the edge over
the whole load history (docs/contact-accuracy.md), and thinner element rows
at the contact surface, graded back to the old mesh (:mod:`pre.zone_refine`). Only
knots are added, so the solver's refinement of the unchanged geometry file is NURBS
knot insertion: the geometry is kept exactly. The wanted element size at an edge is the
old one times ``(SAFETY * ACCEPT * target / estimate)^(1 / RATE)``, at most ``1 /
MIN_FACTOR`` times finer per cycle; edges whose estimate is already at most ``ACCEPT *
target`` (the calibration's spread: :data:`ACCEPT`) keep their elements. The surface
row follows the finest wanted size, and no edge keeps elements much longer than the row
is thick (:func:`_requests`, :func:`refined_breaks`; docs/contact-accuracy.md says why).
"""

from __future__ import annotations

import math
import os
import re
import shutil
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from pre.cases import read_case, to_namelist_text
from pre.files import check_output, new_file, write_text
from pre.nurbs import evaluate_patch
from pre.zone_refine import SizeRequest, interior, split_breaks

from .indicator import ZoneMeasure, measure, nominal_pressure
from .plot import breakpoints
from .reader import Body, ContactOutput, Result, read_result

SAFETY = 0.9
"""The wanted estimate is this fraction of the accepted one (:func:`accepted`)."""
ACCEPT = 0.7
"""The loop stops, and an edge keeps its elements, when the estimate is at most this
fraction of the target: the calibration is the median of the measured edge error over
the raw estimate (0.65), and 29 of its 32 ratios are at most 0.94 (0.65 / 0.94 = 0.69,
``python test/python/indicator_calibration.py``): stopping at the target itself left
errors above it (docs/contact-accuracy.md)."""
RATE = 1.5
"""The edge error's order in the element size used to size the elements: the estimate
falls like ``(h / w)^RATE`` (docs/contact-accuracy.md: 1 for the singularity alone; the
cycles fall faster, as the edge's position sharpens too)."""
MIN_FACTOR = 0.125
"""No element at an edge becomes more than 1 / MIN_FACTOR times smaller in one cycle."""
DEFAULT_TARGET = 0.002
"""The default target of the estimated edge error (0.2 %)."""
NORMAL_GROWTH = 1.5
"""Largest ratio of neighbouring rows in the grading from the surface row inward."""
ROW = 1.5
"""The surface row is made (at most) this many times thicker than the finest wanted
element along an edge."""
ASPECT = 1.5
"""Largest ratio of an edge element's length along the edge to the surface row's
thickness after refinement."""
REACH = 0.015
"""The wanted size holds within this fraction of the zone's half-width of an edge (or
the distance between the points that bracket it, when larger): the edge moves a little
when the mesh is refined."""
KNOT_GAP = 0.5
"""An edge's knot is not inserted closer than this fraction of the wanted size to
another knot (it would leave a sliver of an element)."""
SAMPLES_PER_SPAN = 16
"""Points per element at which an edge's length coordinate is sampled."""


def accepted(target: float) -> float:
    """The largest estimate the loop accepts for ``target`` (``ACCEPT * target``)."""
    return ACCEPT * target


class AdaptError(ValueError):
    """A result that cannot be refined from (the message says why)."""


@dataclass
class RefinedCase:
    """What :func:`refine_result` wrote."""

    case: Path
    source: Path
    """The case the result came from."""
    n_dofs: int
    """DOFs of the refined case (pre's discretization of it)."""
    estimate: float
    """The result's largest estimated edge error (over pairs and steps)."""
    bodies: dict[str, tuple[int, int]]
    """Body -> (elements along the contact edge, element rows across) after refinement."""


def parse_target(text: str) -> float:
    """``'0.2%'`` -> 0.002, ``'0.002'`` -> 0.002; ValueError unless in (0, 1)."""
    value = float(text[:-1]) / 100 if text.strip().endswith("%") else float(text)
    if not 0.0 < value < 1.0 or not math.isfinite(value):
        raise ValueError(f"target {text!r} must be in (0, 100%)")
    return value


def _edge_length(body: Body, direction: int, at: float) -> tuple[np.ndarray, np.ndarray]:
    """``(parameters, reference length from the direction's start)`` sampled along the
    body's direction ``direction`` (0: xi on the contact edge eta = 1; 1: eta across the
    body at xi = ``at``), ``SAMPLES_PER_SPAN`` points per element (the polyline's
    length)."""
    breaks = breakpoints(body)[direction]
    t = np.unique(np.concatenate([np.linspace(a, b, SAMPLES_PER_SPAN + 1)
                                  for a, b in zip(breaks[:-1], breaks[1:], strict=True)]))
    xi, eta = (t, np.ones_like(t)) if direction == 0 else (np.full_like(t, at), t)
    pts = evaluate_patch(body.bulk, xi, eta)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    return t, s


def _factor(estimate: float, target: float) -> float:
    if not math.isfinite(estimate):
        return MIN_FACTOR
    if estimate <= accepted(target):
        return 1.0
    return float(np.clip((SAFETY * accepted(target) / estimate) ** (1.0 / RATE), MIN_FACTOR, 1.0))


@dataclass
class _Requests:
    along: list[tuple[SizeRequest, float]]
    """(wanted size around an edge, the length of the element holding it now)."""
    across: list[tuple[float, float]]
    """(xi where, wanted size of the surface row)."""


def _requests(result: Result, measures: list[ZoneMeasure], target: float) -> dict[str, _Requests]:
    """Per body (slaves and deformable masters) the wanted sizes around the edges.

    An edge above the accepted estimate wants elements ``delta = f h_along`` long (f of
    :func:`_factor`). The surface row is one for the whole body: ``ROW`` times the
    smallest delta, when thinner than it is. Every edge of the history then gets
    elements along it of at most ``ASPECT`` times the row :func:`refined_breaks` makes
    (elements longer than the row is thick placed the edge worse,
    docs/contact-accuracy.md)."""
    wanted: list[tuple[str, float, float, float, float]] = []  # body, xi, h, delta, reach
    for m in measures:
        for e in m.edges:
            f = _factor(e.estimate, target)
            delta = f * e.h_tangent if f < 1.0 else math.inf
            reach = max(REACH * e.half_width, e.bracket)
            wanted.append((m.slave, e.xi, e.h_tangent, delta, reach))
            master_xi = _master_parameter(result, m, e.xi)
            if master_xi is not None:
                wanted.append((m.master, master_xi, e.h_tangent, delta, reach))
    out: dict[str, _Requests] = {}
    for name in dict.fromkeys(w[0] for w in wanted):
        mine = [w for w in wanted if w[0] == name]
        finest = min(w[3] for w in mine)
        if not math.isfinite(finest):
            continue
        t, s = _edge_length(result.body(name), 0, 0.0)
        along = [(SizeRequest(position=float(np.interp(xi, t, s)), size=min(h, delta), reach=reach), h)
                 for _, xi, h, delta, reach in mine]
        xi_row = min(mine, key=lambda w: w[3])[1]
        out[name] = _Requests(along=along, across=[(xi_row, ROW * finest)])
    return out


def _master_parameter(result: Result, m: ZoneMeasure, xi: float) -> float | None:
    """The deformable master's edge parameter opposite the slave's edge at ``xi`` (None
    for a rigid master): that of the slave point in contact nearest to it."""
    if m.master not in result.bodies:
        return None
    st = next(s for s in result.steps if s.step == m.step)
    c = st.contact[m.pair]
    on = np.flatnonzero(c.active & np.isfinite(c.xi_master))
    if not on.size:
        return None
    return float(c.xi_master[on[np.argmin(np.abs(c.xi_slave[on] - xi))]])


def with_knots(breaks: np.ndarray, at: np.ndarray, gaps: np.ndarray) -> np.ndarray:
    """``breaks`` with the parameters ``at`` added, except those closer than their
    ``gaps`` to a break (or to one added before): no sliver of an element."""
    out = list(breaks)
    for v, gap in sorted(zip(at.tolist(), gaps.tolist(), strict=True)):
        if min(abs(v - b) for b in out) > gap:
            out.append(v)
    return np.array(sorted(out))


def refined_breaks(body: Body, req: _Requests) -> tuple[np.ndarray, np.ndarray]:
    """The body's new (xi, eta) breaks for the requests: the surface row first, then
    along the edge every request capped at ``ASPECT`` times the row's thickness as made
    (splitting an old row into whole parts can make it up to twice thinner than asked)."""
    bx, be = breakpoints(body)[:2]
    new_eta = be
    cap = math.inf
    if req.across:
        xi, size = min(req.across, key=lambda r: r[1])
        t, s = _edge_length(body, 1, xi)
        depth = s[-1] - np.interp(be, t, s)  # distance from the surface eta = 1
        # in the increasing coordinate -depth, the surface is at 0
        new_eta = split_breaks(be, -depth, [SizeRequest(position=0.0, size=size, reach=size)],
                               growth=NORMAL_GROWTH)
        cap = ASPECT * (s[-1] - float(np.interp(new_eta[-2], t, s)))
    along = [replace(r, size=min(r.size, cap)) for r, _ in req.along]
    along = [r for r, (_, h) in zip(along, req.along, strict=True) if r.size < h]
    t, s = _edge_length(body, 0, 0.0)
    at = np.array([r.position for r in along])
    speed = np.gradient(s, t)  # reference length per parameter
    gaps = KNOT_GAP * np.array([r.size for r in along]) / np.interp(np.interp(at, s, t), t, speed)
    bx = with_knots(bx, np.interp(at, s, t), gaps)
    new_xi = split_breaks(bx, np.interp(bx, t, s), along)
    return new_xi, new_eta


def next_stem(stem: str) -> str:
    """``m2-NN2.2`` -> ``m2-NN2.2-zone1``; ``m2-NN2.2-zone1`` -> ``m2-NN2.2-zone2``."""
    match = re.fullmatch(r"(.*)-zone(\d+)", stem)
    return f"{match.group(1)}-zone{int(match.group(2)) + 1}" if match else f"{stem}-zone1"


def _groups(case: Path) -> dict[str, Any]:
    """The case's namelist groups as plain dicts (repeated groups as lists)."""
    nml = read_case(case)
    out: dict[str, Any] = {}
    # the keys of a repeated group are its entries' own (f90nml); their text is the name
    for name in dict.fromkeys(str(k).lower() for k in nml.keys()):
        value = nml[name]
        out[name] = [dict(v) for v in value] if isinstance(value, list) else dict(value)
    return out


def source_case(result: Result) -> Path:
    """The case file the result came from: the root attribute ``case_path`` (absolute),
    else the file named by ``case_file`` beside the result."""
    recorded = str(result.attrs.get("case_path") or "")
    candidates = [Path(recorded)] if recorded else []
    if result.case_file:  # relative to where voiga ran: look beside the result
        candidates.append(result.path.parent / Path(result.case_file).name)
    for case in candidates:
        if case.is_file():
            return case
    raise AdaptError(f"{result.path}: the case it came from ({recorded or result.case_file or 'not recorded'}) "
                     "is not there")


def refine_result(path: str | Path | Result, target: float = DEFAULT_TARGET, out: str | Path | None = None,
                  force: bool = False, measures: list[ZoneMeasure] | None = None) -> RefinedCase:
    """Write the refined case of the result at ``path`` into ``out`` (default: a folder
    ``<next stem>`` beside the result) as ``<next stem>.nml``; its geometry path points at
    the original geometry. AdaptError when the result has no contact or its case is
    gone; an existing case file is refused unless ``force``. ``path`` may be the result
    read already, ``measures`` its :func:`~post.indicator.measure` (not measured again)."""
    result = path if isinstance(path, Result) else read_result(path)
    if not result.steps:
        raise AdaptError(f"{result.path}: no converged step to refine from")
    case = source_case(result)
    measures = measure(result) if measures is None else measures
    if not measures:
        raise AdaptError(f"{result.path}: no contact at any converged step: nothing to refine")
    groups = _groups(case)
    stem = next_stem(case.stem)
    folder = Path(out) if out is not None else result.path.parent / stem
    folder.mkdir(parents=True, exist_ok=True)
    target_case = check_output(folder / f"{stem}.nml")
    if target_case.exists() and not force:
        raise AdaptError(f"{target_case} exists; nothing written (--force to overwrite)")
    bodies = groups["body"] if isinstance(groups["body"], list) else [groups["body"]]
    sizes: dict[str, tuple[int, int]] = {}
    for name, req in _requests(result, measures, target).items():
        new_xi, new_eta = refined_breaks(result.body(name), req)
        entry = next(b for b in bodies if str(b["name"]) == name)
        for key in ("nel_xi", "nel_eta"):
            entry.pop(key, None)
        entry["knots_xi"], entry["knots_eta"] = interior(new_xi), interior(new_eta)
        sizes[name] = (len(new_xi) - 1, len(new_eta) - 1)
    cg = groups["case"]
    geometry = (case.parent / str(cg["geometry"])).resolve()
    cg["geometry"] = os.path.relpath(geometry, folder.resolve())
    cg["output"] = f"{stem}.h5"
    title = re.sub(r", contact zone refined .*$", "", str(cg.get("title", case.stem)))
    cg["title"] = f"{title}, contact zone refined ({stem.rpartition('-')[2]}, target {target:.2%})"
    write_text(target_case, to_namelist_text(groups))
    from pre.refine import discretize_case

    n_dofs = sum(b.total_dofs for b in discretize_case(target_case).bodies.values())
    estimate = max(m.estimate for m in measures)
    return RefinedCase(case=target_case, source=case, n_dofs=n_dofs, estimate=estimate, bodies=sizes)


MAX_CYCLES = 3
"""Refinement cycles of ``post run --adapt`` unless ``--cycles`` says otherwise."""


@dataclass
class Cycle:
    """One solve of the loop."""

    result: Path
    n_dofs: int
    estimate: float
    seconds: float
    """Wall time of the solve (the result file's ``wall_time``)."""
    change: float = math.nan
    """:func:`pressure_change` from the previous cycle's result (NaN for the first)."""


def pressure_change(old: Result, new: Result) -> float:
    """The largest relative L2 change of the contact pressure (per reference length)
    from ``old`` to ``new`` over the steps and pairs both have: ``||p_new - p_old|| /
    ||p_new||`` along the slave edge's parameter (the same in both: knot insertion keeps
    the parametrization), each profile the linear interpolant of its points."""
    worst = 0.0
    before = {s.step: s for s in old.steps}
    for st in new.steps:
        if st.step not in before:
            continue
        for c_new, c_old in zip(st.contact, before[st.step].contact, strict=False):
            grid = np.unique(np.concatenate([c_new.xi_slave, c_old.xi_slave]))
            p_new = _profile(c_new, grid)
            p_old = _profile(c_old, grid)
            norm = float(np.trapezoid(p_new**2, grid))
            if norm > 0:
                worst = max(worst, float(np.sqrt(np.trapezoid((p_new - p_old) ** 2, grid) / norm)))
    return worst


def _profile(c: ContactOutput, grid: np.ndarray) -> np.ndarray:
    order = np.argsort(c.xi_slave, kind="stable")
    return np.interp(grid, c.xi_slave[order], nominal_pressure(c)[order], left=0.0, right=0.0)


def largest_estimate(result: Result) -> float:
    """The largest estimated edge error over the pairs and steps (0 without contact)."""
    return max((m.estimate for m in measure(result)), default=0.0)


@dataclass
class AdaptRun:
    """What :func:`adapt_case` did."""

    cycles: list[Cycle]
    code: int
    """voiga's last exit code (0 when every solve succeeded)."""
    result: Path | None
    """Where the last cycle's result was copied: the place a plain ``post run`` of the
    case puts its result (None when no solve succeeded)."""


def loop_paths(case: Path, out: Path | None) -> tuple[Path, Path]:
    """(the result a plain ``post run CASE [--out OUT]`` writes, the folder of the loop's
    cycles: ``<stem>-zone<k>`` folders beside that result)."""
    from .solver import read_case_group

    output = read_case_group(case).get("output")
    if not output:
        raise AdaptError(f"{case}: &case has no output")
    folder = out if out is not None else case.parent
    return folder / str(output), folder


def _check_free(case: Path, result: Path, folder: Path, cycles: int) -> None:
    """AdaptError when the loop would replace an earlier result in the case's own folder:
    the plain run's result or an earlier loop's ``<stem>-zone<k>`` folders."""
    taken = [p for p in [result, *(folder / f"{case.stem}-zone{k}" for k in range(cycles + 1))]
             if p.exists()]
    if taken:
        raise AdaptError(f"{', '.join(map(str, taken))} exist(s); nothing solved (--overwrite to "
                         "replace them, or --out DIR)")


def adapt_case(case: str | Path, out: str | Path | None = None, target: float = DEFAULT_TARGET,
               cycles: int = MAX_CYCLES, binary: str | Path | None = None,
               quiet: bool = True, overwrite: bool = False) -> AdaptRun:
    """The solve-estimate-refine loop: solve ``case`` (a copy in ``<stem>-zone0``), and
    while the largest estimated edge error exceeds the accepted one (:func:`accepted`)
    and fewer than ``cycles`` refinements were made, write the refined case
    (:func:`refine_result`, in ``<stem>-zone<k>``) and solve it. The ``<stem>-zone<k>``
    folders lie in ``out`` when given, else beside the case; the last result is then
    copied to where a plain ``post run`` of the case puts its result (:func:`loop_paths`).
    In the case's own folder nothing earlier is replaced unless ``overwrite``
    (AdaptError before any solve). Prints a line per cycle; the loop stops on any
    exit code of voiga but 0."""
    from .solver import result_path, run_voiga, stage_case, voiga_binary

    program = voiga_binary(binary)
    case = Path(case)
    final, folder = loop_paths(case, Path(out) if out is not None else None)
    replace_all = out is not None or overwrite
    if not replace_all:
        _check_free(case, final, folder, cycles)
    run = stage_case(case, folder / f"{case.stem}-zone0")
    done: list[Cycle] = []
    previous: Result | None = None
    while True:
        path = result_path(run)
        code = run_voiga(program, run, quiet=quiet, overwrite=True)
        if code != 0 or not path.is_file():
            return AdaptRun(done, code or 1, None)
        result = read_result(path)
        change = pressure_change(previous, result) if previous is not None else math.nan
        measures = measure(result)
        done.append(Cycle(result=path, n_dofs=result.n_dofs,
                          estimate=max((m.estimate for m in measures), default=0.0),
                          seconds=result.wall_time, change=change))
        previous = result
        c = done[-1]
        print(f"cycle {len(done) - 1}: {c.n_dofs} DOFs, estimated edge error {c.estimate:.3%}"
              + (f", pressure change from cycle {len(done) - 2} {c.change:.3%}" if done[:-1] else "")
              + f", solve {c.seconds:.3g} s ({c.result})")
        if c.estimate <= accepted(target) or len(done) > cycles:
            break
        run = refine_result(result, target, folder / next_stem(run.stem), force=True, measures=measures).case
    with new_file(final) as tmp:
        shutil.copyfile(done[-1].result, tmp)
    return AdaptRun(done, 0, final)
