"""Run a set of cases in parallel and summarize them (``python -m post sweep``).

Each case is copied with its scene's geometry into ``<out>/<scene>/`` and solved there by
``voiga``; a case whose result is converged and newer than the case file, the geometry
and the binary is skipped. The summary (CSV and markdown) lists DOFs, Newton
iterations, load-step cuts, wall time per stage, status and the scene's error measures
(``post/measures.py``).
"""

from __future__ import annotations

import csv
import os
import shutil
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path

from tqdm import tqdm

REPO = Path(__file__).resolve().parents[1]
STAGES = ("assembly", "contact", "factorization", "solve", "output")


@dataclass
class Run:
    """One case of a sweep."""

    scene: str
    mesh: str
    layout: str
    case: Path
    """The committed case file."""
    work: Path
    """The copy that is solved (its result is written beside it)."""

    @property
    def result(self) -> Path:
        return self.work.with_suffix(".h5")

    @property
    def label(self) -> str:
        return f"{self.scene}/{self.mesh}-{self.layout}"


def find_cases(cases: Path, out: Path, scenes: list[str] | None = None,
               meshes: list[str] | None = None, layouts: list[str] | None = None) -> list[Run]:
    """The committed cases ``cases/<scene>/<mesh>-<layout>.nml`` matching the filters."""
    runs = []
    for path in sorted(cases.glob("*/*.nml")):
        scene = path.parent.name
        mesh, layout = path.stem.split("-", 1)
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
    inputs = [run.case, run.case.parent / "geometry.h5", binary]
    return all(stamp > p.stat().st_mtime for p in inputs if p.exists())


def prepare(run: Run) -> None:
    """Copy the case and its geometry into the work folder."""
    run.work.parent.mkdir(parents=True, exist_ok=True)
    geo = run.case.parent / "geometry.h5"
    target = run.work.parent / "geometry.h5"
    if not target.exists() or target.stat().st_mtime < geo.stat().st_mtime:
        shutil.copy2(geo, target)
    text = run.case.read_text()
    # the result goes next to the work copy, named after it
    run.work.write_text(text)


def single_thread_env() -> dict[str, str]:
    """The environment with one BLAS thread per run (unless the caller set one).

    The sweep runs one case per core; OpenBLAS threads on top of that only spin
    (measured: 1.5x the CPU time on ironing m3 N6 with two threads).
    """
    env = dict(os.environ)
    env.setdefault("OPENBLAS_NUM_THREADS", "1")
    return env


def solve(run: Run, binary: Path, timeout: float) -> tuple[Run, int, str]:
    """Run voiga on one case; (run, exit code, last stderr line)."""
    prepare(run)
    try:
        # the work folder is the sweep's: a case it runs again replaces its result
        proc = subprocess.run([str(binary), str(run.work), "--quiet", "--overwrite"], capture_output=True,
                              text=True, timeout=timeout, env=single_thread_env())
    except subprocess.TimeoutExpired:
        return run, -1, f"timed out after {timeout:g} s"
    lines = (proc.stderr or "").strip().splitlines()
    return run, proc.returncode, lines[-1] if lines else ""


def estimated_cost(case: Path) -> float:
    """Relative cost of solving a case, from its case file alone: for every body its
    control points (nel_xi + p)(nel_eta + q) times the stencil (2p + 1)(2q + 1) of a
    matrix column (p, q the bulk degrees; an explicit knot vector gives nel), times
    the load steps of all phases. Within a factor of about 2 of the measured wall
    times of ``make paper`` (ironing m4 N6 / N2: 2.8 estimated, 2.7 measured); it
    only has to order the runs."""
    import f90nml

    nml = f90nml.read(str(case))
    bodies = nml.get("body", [])
    bodies = [bodies] if isinstance(bodies, dict) else list(bodies)
    work = 0.0
    for b in bodies:
        p, q = int(b.get("degree_xi", 2)), int(b.get("degree_eta", 2))

        def nel(direction: str) -> int:
            knots = b.get(f"knots_{direction}")
            if knots is not None:
                return len(knots if isinstance(knots, list) else [knots]) + 1
            return int(b.get(f"nel_{direction}", 1))

        work += (nel("xi") + p) * (nel("eta") + q) * (2 * p + 1) * (2 * q + 1)
    steps = nml.get("solver", {}).get("n_steps", 1)
    return work * float(sum(steps) if isinstance(steps, list) else steps)


def previous_times(summary: Path) -> dict[str, float]:
    """label (``scene/mesh-layout``) -> wall seconds of a previous sweep's
    ``summary.csv`` (empty when there is none)."""
    times: dict[str, float] = {}
    if not summary.is_file():
        return times
    with summary.open(newline="") as fh:
        for row in csv.DictReader(fh):
            try:
                wall = float(row.get("wall_s") or "nan")
            except ValueError:
                continue
            if wall == wall and wall > 0 and row.get("status") == "converged":
                times[f"{row['scene']}/{row['mesh']}-{row['layout']}"] = wall
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
    cost = {r.label: estimated_cost(r.case) for r in runs}
    ratios = sorted(times[r.label] / cost[r.label] for r in runs if r.label in times and cost[r.label] > 0)
    scale = ratios[len(ratios) // 2] if ratios else 1.0

    def expected(r: Run) -> float:
        return times[r.label] if r.label in times else scale * cost[r.label]

    return sorted(runs, key=expected, reverse=True)


def sweep(runs: list[Run], binary: Path, jobs: int, timeout: float, force: bool = False,
          progress: bool = True, times: dict[str, float] | None = None) -> dict[str, tuple[int, str]]:
    """Solve every run not up to date, ``jobs`` at a time, longest first
    (:func:`longest_first`; ``times``: wall seconds of a previous sweep, label ->
    seconds); label -> (exit code, message)."""
    todo = [r for r in runs if force or not up_to_date(r, binary)]
    outcome: dict[str, tuple[int, str]] = {r.label: (0, "up to date") for r in runs if r not in todo}
    # longest first keeps both cores busy until the end
    todo = longest_first(todo, times)
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = [pool.submit(solve, r, binary, timeout) for r in todo]
        bar = tqdm(total=len(futures), desc="sweep", unit="case", disable=not progress, file=sys.stderr)
        for fut in as_completed(futures):
            run, code, message = fut.result()
            outcome[run.label] = (code, message)
            bar.set_postfix_str(run.label)
            bar.update()
        bar.close()
    return outcome


REFERENCES = {"hertz": "m6-N2", "rings": "ref-N2"}
"""Reference run of each scene for the error measures."""


def summarize(runs: list[Run]) -> list[dict[str, object]]:
    """One row per run with a result file: DOFs, iterations, cuts, seconds, status,
    measures; ironing amplitudes as % of N2 on the same mesh; time normalised by the
    scene's most expensive run (the paper's Eq. 36)."""
    from .measures import measures_for
    from .reader import read_result

    refs = {}
    for scene, stem in REFERENCES.items():
        for run in runs:
            if run.scene == scene and f"{run.mesh}-{run.layout}" == stem and run.result.exists():
                refs[scene] = read_result(run.result, lazy=True)
    rows = []
    for run in runs:
        row: dict[str, object] = {"scene": run.scene, "mesh": run.mesh, "layout": run.layout}
        if not run.result.exists():
            row["status"] = "no result"
            rows.append(row)
            continue
        res = read_result(run.result, lazy=True)
        row["dofs"] = res.n_dofs
        row["interface_dofs"] = sum(int(b.attrs.get("interface_dofs", 0)) for b in res.bodies.values())
        row["steps"] = len(res.steps)
        row["iterations"] = sum(s.iterations for s in res.steps)
        row["cuts"] = int(sum(int(getattr(s, "cuts", 0) or 0) for s in res.steps))
        row["wall_s"] = round(res.wall_time, 4)
        for stage in STAGES:
            row[f"{stage}_s"] = round(sum(s.seconds.get(stage, 0.0) for s in res.steps), 4)
        row["status"] = res.status
        row.update(measures_for(run.scene, res, refs.get(run.scene)))
        rows.append(row)
    for row in rows:
        if str(row["scene"]).startswith("ironing") and "amp_px" in row:
            n2 = [r for r in rows if r["scene"] == row["scene"] and r["mesh"] == row["mesh"]
                  and r["layout"] == "N2" and "amp_px" in r]
            if n2:
                row["px_pct_n2"] = 100.0 * float(row["amp_px"]) / float(n2[0]["amp_px"])
                row["py_pct_n2"] = 100.0 * float(row["amp_py"]) / float(n2[0]["amp_py"])
    for scene in {str(r["scene"]) for r in rows}:
        times = [float(r["wall_s"]) for r in rows if r["scene"] == scene and "wall_s" in r]
        for r in rows:
            if r["scene"] == scene and "wall_s" in r and times:
                r["time_norm"] = float(r["wall_s"]) / max(times)
    return rows


def write_summary(rows: list[dict[str, object]], out: Path) -> tuple[Path, Path]:
    """``summary.csv`` and ``summary.md`` in ``out``."""
    keys: list[str] = []
    for row in rows:
        keys += [k for k in row if k not in keys]
    out.mkdir(parents=True, exist_ok=True)
    csv_path, md_path = out / "summary.csv", out / "summary.md"
    with csv_path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)

    def fmt(v: object) -> str:
        if isinstance(v, float):
            return f"{v:.4g}"
        return "" if v is None else str(v)

    lines = ["| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
    lines += ["| " + " | ".join(fmt(row.get(k)) for k in keys) + " |" for row in rows]
    md_path.write_text("\n".join(lines) + "\n")
    return csv_path, md_path


def default_binary() -> Path:
    """VOIGA_BIN, else build/install/bin/voiga."""
    return Path(os.environ.get("VOIGA_BIN", REPO / "build" / "install" / "bin" / "voiga"))
