"""Running voiga on (possibly modified) copies of the committed cases, timing them and
reading the per-step stage seconds of the result files."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
VOIGA = Path(os.environ.get("VOIGA_BIN", ROOT / "build" / "install" / "bin" / "voiga"))
STAGES = ("assembly", "contact", "factorization", "solve", "output")

# Ironing with the sliding phase shortened: 10 indentation steps, then 20 sliding steps
# over 0.4 (instead of 200 steps over 4.0); the step length stays the same.
IRONING_SHORT = {"n_steps": "10, 20", "ux": "0.0, 0.4"}


@dataclass
class Run:
    """One solve: wall time seen from outside, and sums over the steps of the result."""

    case: str
    wall: float
    n_dofs: int
    steps: int
    iterations: int
    seconds: dict[str, float] = field(default_factory=dict)
    result: Path | None = None
    #: GMRES iterations summed over the steps (multigrid; 0 with the direct solver)
    linear_iterations: int = 0

    @property
    def per_iteration(self) -> dict[str, float]:
        return {k: v / self.iterations for k, v in self.seconds.items()}

    @property
    def wall_per_iteration(self) -> float:
        return self.wall / self.iterations

    @property
    def staged(self) -> float:
        return sum(self.seconds.values())


def set_variable(text: str, name: str, value: str) -> str:
    """Replace ``name = ...`` (with its continuation lines) by ``name = value``."""
    pat = re.compile(rf"^(\s*){name}\s*=.*?(?=^\s*[A-Za-z_]\w*\s*=|^\s*/)", re.M | re.S)
    if not pat.search(text):
        raise KeyError(f"{name} not in case")
    return pat.sub(lambda m: f"{m.group(1)}{name} = {value}\n", text, count=1)


def add_to_group(text: str, group: str, name: str, value: str) -> str:
    """Set ``name = value`` in namelist group ``&group``: replaced if present, else added."""
    try:
        head, sep, rest = text.partition(f"&{group}")
        if not sep:
            raise KeyError(group)
        end = rest.index("\n/")
        return head + sep + set_variable(rest[:end + 1], name, value) + rest[end + 1:]
    except KeyError:
        return re.sub(rf"^&{group}\b", f"&{group}\n  {name} = {value}", text, count=1, flags=re.M)


class Workdir:
    """A scratch directory holding copies of the scenes' case files and geometry."""

    def __init__(self, path: Path):
        self.path = Path(path)
        marker = self.path / ".bench-workdir"
        if self.path.exists() and any(self.path.iterdir()):
            if not marker.exists():
                raise SystemExit(f"bench: {self.path} is not empty and not a bench work dir; "
                                 "refusing to clear it")
            shutil.rmtree(self.path)
        self.path.mkdir(parents=True, exist_ok=True)
        marker.touch()

    def case(self, scene: str, name: str, changes: dict[str, str] | None = None,
             tag: str = "", text: str | None = None, linear_solver: str | None = None) -> Path:
        """Copy cases/<scene>/<name>.nml (edited by ``changes``, and with ``&solver
        linear_solver`` when given) into <work>/<scene>/."""
        src = ROOT / "cases" / scene
        dst = self.path / scene
        if not dst.exists():
            dst.mkdir()
            shutil.copy(src / "geometry.h5", dst / "geometry.h5")
        if text is None:
            text = (src / f"{name}.nml").read_text()
        out_name = f"{name}{tag}"
        for k, v in (changes or {}).items():
            text = set_variable(text, k, v)
        text = set_variable(text, "output", f"'{out_name}.h5'")
        if linear_solver is not None:
            text = add_to_group(text, "solver", "linear_solver", f"'{linear_solver}'")
        path = dst / f"{out_name}.nml"
        path.write_text(text)
        return path


def solve(case: Path) -> Run:
    """Run ``voiga case --quiet`` once; fail loudly on a non-zero exit."""
    out = case.with_suffix(".h5")
    if out.exists():
        out.unlink()
    t0 = time.perf_counter()
    proc = subprocess.run([str(VOIGA), str(case), "--quiet"], capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RuntimeError(f"voiga {case} failed ({proc.returncode}): {proc.stdout}{proc.stderr}")
    stages = read_stages(out)
    if stages.status != "converged":
        raise RuntimeError(f"{case}: status {stages.status!r}")
    return Run(case=case.stem, wall=wall, n_dofs=stages.n_dofs, steps=stages.steps,
               iterations=stages.iterations, seconds=stages.seconds, result=out,
               linear_iterations=stages.linear_iterations)


@dataclass
class Stages:
    """What a result file says about its run's cost: the sums over its steps of the
    ``seconds_<stage>`` attributes, the Newton iterations they cover, the run's own wall
    time (``wall_time``, start-up excluded) and its status."""

    status: str
    n_dofs: int
    steps: int
    iterations: int
    linear_iterations: int
    seconds: dict[str, float]
    wall_time: float


def read_stages(path: Path) -> Stages:
    """The stage sums of the result file ``path`` (docs/hdf5.md)."""
    with h5py.File(path, "r") as f:
        status = f.attrs["status"]
        status = (status.decode() if isinstance(status, bytes) else str(status)).strip()
        secs = {s: 0.0 for s in STAGES}
        iters = 0
        linear = 0
        steps = f["steps"]
        for name in steps:
            a = steps[name].attrs
            # iterations_total (adaptive stepping) counts the Newton iterations of every
            # substep and failed attempt, which the stage seconds cover; older files
            # only have iterations
            iters += int(a["iterations_total"] if "iterations_total" in a else a["iterations"])
            for s in STAGES:
                secs[s] += float(a[f"seconds_{s}"])
            linear += int(a.get("linear_iterations", 0))
        return Stages(status=status, n_dofs=int(f.attrs["n_dofs"]), steps=len(steps),
                      iterations=iters, linear_iterations=linear, seconds=secs,
                      wall_time=float(f.attrs.get("wall_time", 0.0)))


def best_of(case: Path, repeat: int) -> Run:
    """Fastest of ``repeat`` runs (the least disturbed one on a noisy machine)."""
    return min((solve(case) for _ in range(repeat)), key=lambda r: r.wall)


def interleaved(cases: list[Path], repeat: int) -> list[Run]:
    """Best of ``repeat`` for each case, the runs interleaved (A B A B ...) so that a slow
    phase of the machine hits every case alike."""
    best: list[Run | None] = [None] * len(cases)
    for _ in range(repeat):
        for i, c in enumerate(cases):
            r = solve(c)
            if best[i] is None or r.wall < best[i].wall:
                best[i] = r
    return best  # type: ignore[return-value]


def fit_exponent(n: list[float], t: list[float]) -> float:
    """Least-squares slope of log t against log n."""
    return float(np.polyfit(np.log(n), np.log(t), 1)[0])


LINE = "-" * 100


def header(title: str) -> None:
    print(f"\n{LINE}\n{title}\n{LINE}", flush=True)


def hertz_errors(path: Path) -> dict:
    """Errors of a hertz result against analytic Hertz, as ``python -m post hertz``."""
    from post.hertz import hertz_comparison
    from post.reader import read_result
    h = hertz_comparison(read_result(path))
    return {"l2": h.l2_error, "a_error": h.a_error, "p0_error": h.p0_error}


def voiga_reference(w: Workdir, tag: str) -> dict[str, Path]:
    """The voiga runs the peers (sections 5 and 6) are timed against: hertz m4 NN2.2 as
    committed (penalty_normal = 1e3) and without penalty_normal (the automatic penalty)."""
    committed = (ROOT / "cases" / "hertz" / "m4-NN2.2.nml").read_text()
    auto = re.sub(r"^\s*penalty_normal\s*=.*\n", "", committed, flags=re.M)
    return {"penalty 1e3": w.case("hertz", "m4-NN2.2", tag=tag),
            "auto": w.case("hertz", "m4-NN2.2", tag=f"{tag}-auto", text=auto)}


def interleaved_calls(calls: dict, repeat: int) -> dict:
    """Best of ``repeat`` for every call of ``calls`` (name -> function of no argument
    returning a :class:`Run` or a dict with a "wall" entry), the calls interleaved as in
    :func:`interleaved`. An exception of a call ends the comparison (it propagates)."""
    def wall(r):
        return r.wall if isinstance(r, Run) else r["wall"]

    best: dict = {}
    for _ in range(repeat):
        for name, call in calls.items():
            r = call()
            if name not in best or wall(r) < wall(best[name]):
                best[name] = r
    return best


def reference_ratios(best: dict, cases: dict, peers: list[str]) -> dict:
    """For every voiga run of ``cases`` (:func:`voiga_reference`) in ``best``: its wall
    time, DOFs, iterations, Hertz errors and the wall-time ratio of every peer run
    ``best[p]`` (a dict with "wall") of ``peers`` to it."""
    out = {}
    for name in cases:
        v = best[name]
        out[name] = {"wall": v.wall, "dofs": v.n_dofs, "iterations": v.iterations,
                     **hertz_errors(v.result),
                     "ratio": {p: best[p]["wall"] / v.wall for p in peers}}
    return out
