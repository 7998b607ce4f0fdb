"""Regression of whole runs against a baseline made by an earlier binary (``make regress``).

Runs every committed 2D case (``cases/<scene>/<mesh>-<layout>.nml``; not the 3D study's
scenes, ``SCENES_3D``) and every hard case of
the suite that is expected to converge (``hard_cases.py``), and compares, per written
step, what a change of the code must not change:

- the Euclidean norm of the displacement vector,
- the resultant reaction of every Dirichlet condition (x, y),
- the resultant contact force on the slave of every pair (x, y),
- Newton iterations (of the last substep and of all attempts), substeps and cuts,

and per run the status and the number of steps written. Floating values agree when
``|a - b| <= max(atol, rtol |b|)`` with rtol = 1e-10 and atol = 1e-14 (the redesign's
acceptance: a restructuring that keeps the arithmetic gives round-off differences at
most); counts must be equal.

    python3 test/python/regress.py                 # compare with test/regress/baseline.json.gz
    python3 test/python/regress.py --write         # (re)make the baseline with this binary
    python3 test/python/regress.py --only 'hertz/*' 'penalty-1e2'

The baseline is a gzip'd JSON file, {run name: {"status", "steps": [{...}, ...]}}, its
floats kept to 13 significant digits. It was remade (``--write``, 141 runs) by the binary
of issue 35 (the touchdown of friction points, the stick predictor) on the 2-core AMD EPYC
development machine. Against a baseline made there just before by the binary of main
before it (b96b3f6), the 40 frictionless runs (every hertz case, nu-0.49-hertz,
penalty-1e6-mu0, penalty-hertz-1e9, apart-hertz) agree to 1e-10 and all 101 frictional
ones differ (step 1 already: where a point's slip starts, and the stick predictor's start;
mu-1.0-deep and penalty-1e5 now converge). Then rewritten for 17 runs: alm-1e4/1e5/1e6
(alm's tangential multipliers at a commit: at most 2.9e-9 relative, every count equal),
and the 14 runs that changed when a substep's first LU factorization began to keep an
analysis only for the same nonzeros (the stiff-penalty hard cases, penalty-1e6-mu0,
ironing-deep m1-NN6, m3-NN2.3, m4-NN6, ratio-1e3-rings, slide-off, alm-1e6: a cut or
the last iterations moved with the order of elimination; all converge; the other 127
runs equal). Runs with stiff penalties, ironing-deep,
nu-0.49 and ratio-1e3-rings, where a cut or the last Newton iteration changes with the
order of floating-point sums, are reproducible on one machine and binary, not to 1e-10
across BLAS kernels or CPUs (with OpenBLAS's Haswell kernels,
``OPENBLAS_CORETYPE=Haswell``, an older binary differed from its own baseline in the same
steps by the same amounts; docs/performance.md).
"""
from __future__ import annotations

import argparse
import fnmatch
import gzip
import json
import os
import shutil
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import hard_cases  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
BASELINE = REPO / "test" / "regress" / "baseline.json.gz"
RTOL, ATOL = 1.0e-10, 1.0e-14
#: per-step fields: floats compared with the tolerance, counts exactly
FLOATS = ("u_norm", "reactions", "contact_force")
COUNTS = ("iterations", "iterations_total", "substeps", "cuts")


@dataclass(frozen=True)
class Job:
    """One run: a name, a way to write its case into a directory."""

    name: str
    committed: Path | None = None
    hard: hard_cases.HardCase | None = None

    def prepare(self, directory: Path) -> Path:
        """Write the case (and its geometry) into `directory`; return the case file."""
        if self.hard is not None:
            return hard_cases.prepare(self.hard, directory)
        import f90nml

        directory.mkdir(parents=True, exist_ok=True)
        nml = f90nml.read(self.committed)
        shutil.copy(self.committed.parent / nml["case"]["geometry"], directory / "geometry.h5")
        nml["case"]["geometry"] = "geometry.h5"
        nml["case"]["output"] = "result.h5"
        path = directory / "case.nml"
        nml.write(path, force=True)
        return path


SCENES_3D = ("hertz3d", "ironing3d")
"""The 3D study's scenes (pre.cases.STUDIES_3D, ``make paper3d``): committed cases, not
in the regression of the 2D cases (about 20 CPU minutes; the 3D code changes yet)."""


def jobs() -> list[Job]:
    """Every committed 2D case, then the hard cases expected to converge that are not
    committed cases as they stand (the ``deep-*`` cases are ironing-deep as committed)."""
    out = [Job(f"{p.parent.name}/{p.stem}", committed=p) for p in sorted((REPO / "cases").glob("*/*.nml"))
           if p.parent.name not in SCENES_3D]
    for case in hard_cases.suite():
        if case.expect == "converges" and (case.edits or case.geometry_edits):
            out.append(Job(case.name, hard=case))
    return out


def summarize(path: Path) -> dict:
    """The compared values of a result file."""
    with h5py.File(path, "r") as f:
        status = f.attrs["status"]
        status = status.decode() if isinstance(status, bytes) else str(status)
        steps = []
        group = f.get("steps", {})
        for name in sorted(group):
            s = group[name]
            reactions = s["reactions"][()].ravel().tolist() if "reactions" in s else []
            forces = []
            for k in sorted(s.get("contact", {}), key=int):
                forces += s["contact"][k]["force"][()].ravel().tolist()
            steps.append({"step": int(s.attrs["step"]),
                          "u_norm": float(np.linalg.norm(s["displacement"][()])),
                          "reactions": reactions, "contact_force": forces,
                          **{c: int(s.attrs[c]) for c in COUNTS}})
    return {"status": status, "steps": steps}


def run(job: Job, work: Path, voiga: Path) -> dict:
    """Run one job; its summary (or its failure)."""
    directory = work / job.name.replace("/", "_")
    if directory.exists():
        shutil.rmtree(directory)
    case = job.prepare(directory)
    start = time.perf_counter()
    proc = subprocess.run([str(voiga), case.name, "--quiet"], cwd=directory, capture_output=True, text=True)
    wall = time.perf_counter() - start
    result = directory / "result.h5"
    if not result.exists():
        return {"status": f"no result (exit {proc.returncode}): {proc.stderr.strip()[-300:]}", "steps": [],
                "wall": wall}
    out = summarize(result)
    out["wall"] = wall
    shutil.rmtree(directory)
    return out


def _round(x: float | list) -> float | list:
    """`x` to 13 significant digits (what the baseline keeps)."""
    if isinstance(x, list):
        return [float(f"{v:.13g}") for v in x]
    return float(f"{x:.13g}")


def close(a: float, b: float) -> bool:
    """Whether value `a` matches the baseline value `b`."""
    return abs(a - b) <= max(ATOL, RTOL * abs(b))


def compare(name: str, got: dict, want: dict) -> list[str]:
    """What differs between a run and its baseline (empty: nothing)."""
    problems = []
    if got["status"] != want["status"]:
        problems.append(f"{name}: status {got['status']!r}, baseline {want['status']!r}")
    if len(got["steps"]) != len(want["steps"]):
        problems.append(f"{name}: {len(got['steps'])} steps written, baseline {len(want['steps'])}")
    # (a different count is a problem above; the steps both have are compared)
    for g, w in zip(got["steps"], want["steps"], strict=False):
        for key in COUNTS + ("step",):
            if g[key] != w[key]:
                problems.append(f"{name} step {w['step']}: {key} {g[key]}, baseline {w[key]}")
        for key in FLOATS:
            a, b = np.atleast_1d(g[key]), np.atleast_1d(w[key])
            if a.shape != b.shape:
                problems.append(f"{name} step {w['step']}: {key} has {a.size} values, baseline {b.size}")
                continue
            bad = [i for i in range(a.size) if not close(float(a[i]), float(b[i]))]
            if bad:
                i = bad[0]
                rel = abs(a[i] - b[i]) / max(abs(b[i]), 1e-300)
                problems.append(f"{name} step {w['step']}: {key}[{i}] {a[i]!r}, baseline {b[i]!r} "
                                f"(relative {rel:.1e})")
        if len(problems) > 20:
            break
    return problems


def main(argv: list[str] | None = None) -> int:
    """Run the regression; print one line per run and what differs; exit 1 on a difference."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="write the baseline from this binary")
    parser.add_argument("--baseline", type=Path, default=BASELINE)
    parser.add_argument("--only", nargs="*", default=None, help="run name patterns (fnmatch)")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--work", type=Path, default=REPO / "build" / "regress")
    parser.add_argument("--list", action="store_true", help="list the runs and exit")
    args = parser.parse_args(argv)
    voiga = Path(os.environ.get("VOIGA_BIN", REPO / "build" / "install" / "bin" / "voiga"))
    selected = [j for j in jobs() if args.only is None or any(fnmatch.fnmatch(j.name, p) for p in args.only)]
    if args.list:
        print("\n".join(j.name for j in selected))
        return 0
    baseline = {}
    if args.baseline.exists():
        with gzip.open(args.baseline, "rt") as f:
            baseline = json.load(f)
    if not args.write:
        missing = [j.name for j in selected if j.name not in baseline]
        if missing:
            print(f"not in the baseline: {', '.join(missing)}")
            return 1
    results: dict[str, dict] = {}
    failures = 0
    start = time.perf_counter()
    # one BLAS thread per run: the runs share the cores
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = {pool.submit(run, j, args.work, voiga): j for j in selected}
        for future in as_completed(futures):
            job = futures[future]
            got = future.result()
            results[job.name] = got
            problems = [] if args.write else compare(job.name, got, baseline[job.name])
            failures += bool(problems)
            print(f"{'ok ' if not problems else 'BAD'} {job.name:28s} {got['status'][:40]:40s} "
                  f"{len(got['steps']):4d} steps {got['wall']:8.1f} s", flush=True)
            for p in problems[:20]:
                print(f"    {p}", flush=True)
    total = time.perf_counter() - start
    if args.write:
        for got in results.values():
            got.pop("wall", None)
            # 13 significant digits: three below the comparison's 1e-10
            for rec in got["steps"]:
                for key in FLOATS:
                    rec[key] = _round(rec[key])
        baseline.update(results)
        args.baseline.parent.mkdir(parents=True, exist_ok=True)
        with gzip.open(args.baseline, "wt") as f:
            json.dump(dict(sorted(baseline.items())), f, separators=(",", ":"))
        print(f"baseline: {len(results)} runs written to {args.baseline} ({total:.0f} s)")
        return 0
    print(f"{len(selected)} runs, {failures} differ from the baseline, {total:.0f} s")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
