"""The cases of a sweep or study and their summary table (``python -m post sweep``).

A :class:`Run` is one case: a committed case file copied into ``<out>/<scene>/``, or a
case derived from one by a study (``post/study.py``). The engine (``post/engine.py``)
solves them; a case whose result is converged and newer than its inputs and the binary
is skipped. The summary (CSV, markdown, Parquet) lists DOFs, Newton iterations,
load-step cuts, the run's CPU and wall time (median and range over its repeats,
``post/cost.py``), wall time per stage, status and the scene's error measures
(``post/measures.py``).
"""

from __future__ import annotations

import csv
import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pre.files import new_file, write_text

from .cost import COST_COLUMNS, cost_columns, read_costs

REPO = Path(__file__).resolve().parents[1]
STAGES = ("assembly", "contact", "factorization", "solve", "output")


@dataclass
class Run:
    """One case of a sweep or study."""

    scene: str
    mesh: str
    layout: str
    case: Path
    """The committed (or base) case file it comes from."""
    work: Path
    """The copy that is solved (its result is written beside it)."""
    text: str | None = None
    """The case text to solve, when it differs from ``case``'s (a derived or generated case)."""
    changes: tuple[tuple[str, Any], ...] = ()
    """The study's changes: (variable path, value)."""
    params: dict[str, Any] = field(default_factory=dict)
    """Every variable the study changes -> its value in this case."""
    geometry_file: Path | None = None
    """The geometry file, if not ``geometry.h5`` next to ``case``."""

    @property
    def result(self) -> Path:
        return self.work.with_suffix(".h5")

    @property
    def label(self) -> str:
        return f"{self.scene}/{self.work.stem}"

    @property
    def geometry(self) -> Path:
        """The geometry file (``&case geometry``)."""
        return self.geometry_file or self.case.parent / "geometry.h5"

    def case_text(self) -> str:
        """The text of the case to solve."""
        return self.text if self.text is not None else self.case.read_text()


def find_cases(cases: Path, out: Path, scenes: list[str] | None = None,
               meshes: list[str] | None = None, layouts: list[str] | None = None) -> list[Run]:
    """The committed cases ``cases/<scene>/<mesh>-<layout>.nml`` matching the filters."""
    runs = []
    for path in sorted(cases.glob("*/*.nml")):
        scene = path.parent.name
        mesh, _, layout = path.stem.partition("-")
        if scenes and scene not in scenes:
            continue
        if meshes and mesh not in meshes:
            continue
        if layouts and layout not in layouts:
            continue
        runs.append(Run(scene, mesh, layout, path, out / scene / path.name))
    return runs


def up_to_date(run: Run, binary: Path) -> bool:
    """Converged result newer than the case, the geometry and the binary."""
    if not run.result.exists():
        return False
    import h5py

    try:
        with h5py.File(run.result, "r") as f:
            status = f.attrs.get("status", b"")
            status = status.decode() if isinstance(status, bytes) else str(status)
    except OSError:
        return False
    if status != "converged":
        return False
    stamp = run.result.stat().st_mtime
    inputs = [run.case, run.geometry, run.work, binary]
    return all(stamp > p.stat().st_mtime for p in inputs if p.exists())


def estimated_cost(case: Path, text: str | None = None) -> float:
    """Relative cost of solving a case, from its case file alone: for every body its
    control points (nel_xi + p)(nel_eta + q) times the stencil (2p + 1)(2q + 1) of a
    matrix column (p, q the bulk degrees; an explicit knot vector gives nel), times
    the load steps of all phases. Within a factor of about 2 of the measured wall
    times of ``make paper`` (ironing m4 N6 / N2: 2.8 estimated, 2.7 measured); it
    only has to order the runs. ``text``: the case's text, if not the file's."""
    import f90nml

    nml = f90nml.reads(text) if text is not None else f90nml.read(str(case))
    bodies = nml.get("body", [])
    bodies = [bodies] if isinstance(bodies, dict) else list(bodies)
    work = 0.0
    for b in bodies:
        p, q = int(b.get("degree_xi", 2)), int(b.get("degree_eta", 2))

        def nel(direction: str, b: dict = b) -> int:
            knots = b.get(f"knots_{direction}")
            if knots is not None:
                return len(knots if isinstance(knots, list) else [knots]) + 1
            return int(b.get(f"nel_{direction}", 1))

        work += (nel("xi") + p) * (nel("eta") + q) * (2 * p + 1) * (2 * q + 1)
    steps = nml.get("solver", {}).get("n_steps", 1)
    return work * float(sum(steps) if isinstance(steps, list) else steps)


def previous_times(summary: Path) -> dict[str, float]:
    """label (``scene/<case>``) -> wall seconds of a previous sweep's
    ``summary.csv``, times its repeats (empty when there is none)."""
    times: dict[str, float] = {}
    if not summary.is_file():
        return times
    with summary.open(newline="") as fh:
        for row in csv.DictReader(fh):
            try:
                wall = float(row.get("wall_s") or "nan") * float(row.get("repeats") or 1)
            except ValueError:
                continue
            if wall == wall and wall > 0 and row.get("status") == "converged":
                times[f"{row['scene']}/{row.get('case') or row['mesh'] + '-' + row['layout']}"] = wall
    return times


def longest_first(runs: list[Run], times: dict[str, float] | None = None) -> list[Run]:
    """``runs`` in decreasing expected wall time: the measured time of a previous sweep
    (``times``, label -> seconds) where there is one, else :func:`estimated_cost`
    scaled to seconds by the median ratio of the runs that have both. Started in this
    order, ``jobs`` parallel runs end close together whatever the case names are.
    (The order by (mesh, layout) names used before happened to start the m4 runs
    first too: replayed with the times of the make paper run, both orders give the
    same 679 s on 2 cores, half the 1357 s of the runs.)"""
    times = times or {}
    cost = {r.label: estimated_cost(r.case, r.text) for r in runs}
    ratios = sorted(times[r.label] / cost[r.label] for r in runs if r.label in times and cost[r.label] > 0)
    scale = ratios[len(ratios) // 2] if ratios else 1.0

    def expected(r: Run) -> float:
        return times[r.label] if r.label in times else scale * cost[r.label]

    return sorted(runs, key=expected, reverse=True)


SUMMARY_COLUMNS = frozenset({"scene", "mesh", "layout", "case", "dofs", "interface_dofs", "steps", "iterations",
                             "cuts", *COST_COLUMNS, *(f"{s}_s" for s in STAGES), "status", "exit_code",
                             "error", "measure_error", "time_norm"})
"""The summary's columns that are not measures."""

REFERENCES = {"hertz": "m6-N2", "rings": "ref-N2"}
"""Reference run of each scene for the error measures."""


def summarize(runs: list[Run], measures: dict[str, str] | None = None,
              failures: dict[str, tuple[int, str]] | None = None,
              jobs: int | None = None) -> list[dict[str, object]]:
    """One row per run: scene, mesh, layout (and for a study's derived cases the case
    name and the value of every variable the study changes), DOFs, iterations, cuts,
    seconds, status, the scene's measures and the ``measures`` named by the study
    (column -> :func:`post.measures.file_measure`); ironing amplitudes as % of N2 on the
    same mesh with the same changes (2D: px_pct_n2, py_pct_n2; 3D: t_pct_n2, n_pct_n2);
    the cost (repeats, CPU and wall seconds: median,
    lo, hi; :func:`post.cost.cost_columns`) and the median CPU time normalised by the
    scene's most expensive run's (``time_norm``, the paper's Eq. 36; by the wall time
    when a run of the scene has no CPU time). ``failures``: label -> (exit code,
    message) of the runs that failed in this study, recorded in ``exit_code`` and
    ``error``. The error measures
    compare with the scene's reference run (REFERENCES) with the same changes. The
    result files are read by ``jobs`` processes (default: one per core; reading them
    is most of a summary's time: 7.7 s of 9.4 s for ``make paper``'s 113 runs on one core)."""
    refs: dict[tuple[str, object], Path] = {}
    for run in runs:
        if REFERENCES.get(run.scene) == f"{run.mesh}-{run.layout}" and run.result.exists():
            refs[(run.scene, run.changes)] = run.result
    tasks = [(run, refs.get((run.scene, run.changes)), measures or {}, (failures or {}).get(run.label, (0, "")))
             for run in runs]
    jobs = min(len(tasks), jobs or os.cpu_count() or 1)
    # references read by an earlier summary may have been rewritten since
    _REFERENCE.clear()
    if jobs > 1:
        with ProcessPoolExecutor(max_workers=jobs, mp_context=multiprocessing.get_context("fork")) as pool:
            rows = list(pool.map(_row, tasks, chunksize=4))
    else:
        rows = [_row(task) for task in tasks]
    for run, row in zip(runs, rows, strict=True):
        if not str(row["scene"]).startswith("ironing"):
            continue
        # 2D: the die's Px, Py; 3D: the pair's F_x (t), F_z (n)
        for tangential, normal, names in (("amp_px", "amp_py", ("px_pct_n2", "py_pct_n2")),
                                          ("amp_t", "amp_n", ("t_pct_n2", "n_pct_n2"))):
            if tangential not in row:
                continue
            n2 = [r for u, r in zip(runs, rows, strict=True) if u.scene == run.scene and u.mesh == run.mesh
                  and u.layout == "N2" and u.changes == run.changes and tangential in r]
            if n2:
                row[names[0]] = 100.0 * float(row[tangential]) / float(n2[0][tangential])
                row[names[1]] = 100.0 * float(row[normal]) / float(n2[0][normal])
    for scene in {str(r["scene"]) for r in rows}:
        timed = [r for r in rows if r["scene"] == scene and "wall_s" in r]
        key = "cpu_s" if all("cpu_s" in r for r in timed) else "wall_s"
        most = max((float(r[key]) for r in timed), default=0.0)
        for r in timed:
            if most > 0:
                r["time_norm"] = float(r[key]) / most
    return rows


#: The reference results read by :func:`_row` in this process during one summary.
_REFERENCE: dict[Path, Any] = {}


def _row(task: tuple[Run, Path | None, dict[str, str], tuple[int, str]]) -> dict[str, object]:
    """The summary row of one run (:func:`summarize`) from its result file, its scene's
    reference result (read once per process) and the study's measures."""
    from .measures import file_measure, measures_for
    from .reader import read_result

    run, ref_path, measures, (code, message) = task
    row: dict[str, object] = {"scene": run.scene, "mesh": run.mesh, "layout": run.layout}
    if run.changes:
        row["case"] = run.work.stem
    row.update({k: value_cell(v) for k, v in run.params.items()})
    if code:
        row["exit_code"], row["error"] = code, message
    if not run.result.exists():
        row["status"] = "no result"
        return row
    ref = None
    if ref_path is not None:
        if ref_path not in _REFERENCE:
            _REFERENCE[ref_path] = read_result(ref_path, lazy=True)
        ref = _REFERENCE[ref_path]
    res = read_result(run.result, lazy=True)
    row["dofs"] = res.n_dofs
    row["interface_dofs"] = sum(int(b.attrs.get("interface_dofs", 0)) for b in res.bodies.values())
    row["steps"] = len(res.steps)
    row["iterations"] = sum(s.iterations for s in res.steps)
    row["cuts"] = int(sum(int(getattr(s, "cuts", 0) or 0) for s in res.steps))
    samples = read_costs(run.result)
    if samples:
        row.update(cost_columns(samples))
    else:       # no times kept by the engine (a result made by hand): voiga's own clock
        row["wall_s"] = round(res.wall_time, 4)
    for stage in STAGES:
        row[f"{stage}_s"] = round(sum(s.seconds.get(stage, 0.0) for s in res.steps), 4)
    row["status"] = res.status
    row.update(measures_for(run.scene, res, ref))
    for name, expr in measures.items():
        try:
            row[name] = file_measure(run.result, expr)
        except (KeyError, ValueError, IndexError, TypeError) as err:
            row[name] = float("nan")
            row["measure_error"] = f"{name}: {err}"
    return row


def value_cell(value: Any) -> object:
    """A namelist value as a table cell: scalars as they are, arrays space-separated."""
    if isinstance(value, (list, tuple)):
        return " ".join(str(v) for v in value)
    return value


def write_summary(rows: list[dict[str, object]], out: Path) -> tuple[Path, Path]:
    """``summary.csv`` and ``summary.md`` in ``out``, and ``summary.parquet`` when
    pyarrow is installed (:func:`write_parquet`)."""
    keys: list[str] = []
    for row in rows:
        keys += [k for k in row if k not in keys]
    out.mkdir(parents=True, exist_ok=True)
    csv_path, md_path = out / "summary.csv", out / "summary.md"
    with new_file(csv_path) as tmp, tmp.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)

    def fmt(v: object) -> str:
        if isinstance(v, float):
            return f"{v:.4g}"
        return "" if v is None else str(v)

    lines = ["| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
    lines += ["| " + " | ".join(fmt(row.get(k)) for k in keys) + " |" for row in rows]
    write_text(md_path, "\n".join(lines) + "\n")
    write_parquet(rows, keys, out / "summary.parquet")
    return csv_path, md_path


def write_parquet(rows: list[dict[str, object]], keys: list[str], path: Path) -> Path | None:
    """The table as Parquet (pyarrow): a column whose values are all numbers (or
    missing) is float64 or int64, any other a string column. None without pyarrow."""
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        return None
    columns = {}
    for key in keys:
        values = [None if row.get(key) == "" else row.get(key) for row in rows]
        present = [v for v in values if v is not None]
        if present and all(isinstance(v, int) and not isinstance(v, bool) for v in present):
            columns[key] = pa.array(values, type=pa.int64())
        elif present and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in present):
            columns[key] = pa.array([None if v is None else float(v) for v in values], type=pa.float64())
        else:
            columns[key] = pa.array([None if v is None else str(v) for v in values], type=pa.string())
    with new_file(path) as tmp:
        pq.write_table(pa.table(columns), tmp)
    return path

