"""The attack suite of issues 19 and 36 (docs/attack.md): namelist texts,
geometry files, output paths and damaged result files (`attack_inputs.py`), each run
through voiga (or `python -m post`) and judged by oracles that do not trust the
program:

- **crash**: killed by a signal, an exit code other than 0-3, a Fortran runtime error
  or backtrace, a Python traceback;
- **hang**: no end within the time limit;
- **refusal**: an input that must be refused ends with exit 2 and one `voiga: error:`
  line naming the words the attack lists;
- **destroyed**: the case file, the geometry file or a file the attack protects
  changed bytes;
- **silent wrong**: a run that exits 0 but whose result is not what the input says:
  a change of form only that does not give the base case's result bit for bit; values
  recorded in the result file (steps, Young's moduli, Poisson ratios, materials,
  prescribed displacements, contact laws) that differ from what f90nml (an independent
  namelist parser) reads in the case; a result marked converged that is not (steps
  missing, non-finite, residuals not small); a geometry accepted that fails an
  independent check of the schema (open knot vectors, multiplicities, shapes, finite
  values, positive weights, det J of one sign).

``python3 test/python/attack.py`` (``make attack``) runs every attack and prints the
counts per family and outcome; ``--reduced`` runs the subset of ``make test``
(`test_attack.py`): every example of the issue and one attack in seven.
"""
from __future__ import annotations

import argparse
import concurrent.futures
import hashlib
import math
import os
import re
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import f90nml
import h5py
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from attack_inputs import REPO, Attack, all_attacks, stage  # noqa: E402

TIMEOUT = 120.0
"""Seconds before an attack counts as a hang (the base case takes a fifth of one)."""


@dataclass
class Outcome:
    attack: Attack
    code: int | None = None
    problems: list[str] = field(default_factory=list)
    kind: str = ""  # ran | refused | failed run | other failure | crash | hang
    wall: float = 0.0
    #: the oracles that looked at the result: 'parsed' (values against f90nml),
    #: 'same' (the base case's result), 'geometry' (the independent check)
    checked: set[str] = field(default_factory=set)

    @property
    def ok(self) -> bool:
        return not self.problems


def digest(path: Path) -> str | None:
    """What `path` is, to tell whether it changed: the SHA-256 of a regular file, the
    target of a symbolic link, the kind and device numbers of a special file (never
    opened), None when nothing is there."""
    try:
        st = os.lstat(path)
    except (FileNotFoundError, NotADirectoryError):
        return None
    if stat.S_ISLNK(st.st_mode):
        return "link to " + os.readlink(path)
    if stat.S_ISREG(st.st_mode):
        return hashlib.sha256(path.read_bytes()).hexdigest()
    return f"mode {stat.S_IFMT(st.st_mode):o} device {st.st_rdev}"


def base_result(voiga: Path, work: Path) -> Path:
    """The base case run once: what the changes of form must reproduce."""
    work.mkdir(parents=True, exist_ok=True)
    case = stage(work)
    subprocess.run([str(voiga), case.name, "--quiet", "--overwrite"], cwd=work, check=True,
                   capture_output=True, timeout=TIMEOUT)
    return work / "out.h5"


def run_attack(attack: Attack, work: Path, voiga: Path, base: Path) -> Outcome:
    try:
        return _run_attack(attack, work, voiga, base)
    except Exception as err:  # noqa: BLE001 - a broken attack is reported, not fatal
        outcome = Outcome(attack, kind="oracle error")
        outcome.problems.append(f"oracle error: {type(err).__name__}: {err}")
        return outcome


def _run_attack(attack: Attack, work: Path, voiga: Path, base: Path) -> Outcome:
    outcome = Outcome(attack)
    if work.exists():
        shutil.rmtree(work)
    work.mkdir(parents=True)
    args = attack.setup(work)
    protected = ["case.nml", "geometry.h5", *attack.protect]
    before = {name: digest(work / name) for name in protected}
    if attack.family == "post":
        command = [sys.executable, "-c", "import sys; from post.__main__ import main; sys.exit(main(sys.argv[1:]))"]
        env = dict(os.environ, PYTHONPATH=str(REPO), MPLBACKEND="Agg")
    else:
        command = [str(voiga)]
        env = dict(os.environ)
    start = time.perf_counter()
    try:
        if attack.during is None:
            proc = subprocess.run(command + args, cwd=work, capture_output=True, text=True, timeout=TIMEOUT,
                                  env=env, errors="replace")
        else:
            proc = run_interfered(command + args, work, env, attack.during)
    except subprocess.TimeoutExpired:
        outcome.kind = "hang"
        outcome.problems.append(f"no end within {TIMEOUT:g} s")
        return outcome
    outcome.wall = time.perf_counter() - start
    outcome.code = code = proc.returncode
    judge_exit(outcome, proc)
    for name, value in before.items():
        if value is not None and digest(work / name) != value:
            outcome.problems.append(f"destroyed: {name} changed")
    for name in attack.absent:
        if digest(work / name) is not None:
            outcome.problems.append(f"destroyed: {name} was created (through a link)")
    for name, other in attack.same_as:
        if digest(work / name) != digest(work / other):
            outcome.problems.append(f"destroyed: {name} is not the file {other} put there")
    if attack.family == "post" or outcome.kind in ("crash",):
        return outcome
    result = result_file(work)
    if code == 0 and result is not None and "--check" not in args:
        judge_result(outcome, work, result, base)
    if attack.geometry and code in (0, 3):
        outcome.checked.add("geometry")
        problem = geometry_problem(work / "geometry.h5")
        if problem:
            outcome.problems.append(f"silent wrong: geometry accepted but {problem}")
    return outcome


def run_interfered(command: list[str], work: Path, env: dict[str, str],
                   during: Callable[[Path], None]) -> subprocess.CompletedProcess:
    """Run `command` until it has written a step, stop it (SIGSTOP), let
    `during` change its files, let it go on (SIGCONT): whatever `during` does happens
    between two of its flushes."""
    env = dict(env, GFORTRAN_UNBUFFERED_PRECONNECTED="y")
    proc = subprocess.Popen(command, cwd=work, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env, errors="replace")
    try:
        assert proc.stdout is not None
        seen = []
        for line in proc.stdout:
            seen.append(line)
            if re.match(r"step \d+/", line):     # its first step written (a restart's: the next)
                proc.send_signal(signal.SIGSTOP)
                try:
                    during(work)
                finally:
                    proc.send_signal(signal.SIGCONT)
                break
        out, err = proc.communicate(timeout=TIMEOUT)
    except BaseException:
        proc.kill()
        proc.communicate()
        raise
    return subprocess.CompletedProcess(command, proc.returncode, "".join(seen) + out, err)


def judge_exit(outcome: Outcome, proc: subprocess.CompletedProcess) -> None:
    attack, code, err = outcome.attack, proc.returncode, proc.stderr
    if code < 0 or code > 3 or "Backtrace" in err or "runtime error" in err or "Traceback" in err \
            or "Segmentation" in err or "double free" in err:
        outcome.kind = "crash"
        outcome.problems.append(f"crash: exit {code}: {err.strip()[-400:]}")
        return
    outcome.kind = {0: "ran", 2: "refused", 3: "failed run"}.get(code, "other failure")
    if code not in attack.allowed:
        outcome.problems.append(f"exit {code}, expected {sorted(attack.allowed)}: {err.strip()[-300:]}")
    if attack.family == "post":
        lines = [line for line in err.strip().splitlines() if "note:" not in line]
        if code == 2 and len(lines) != 1:
            outcome.problems.append(f"post refused in {len(lines)} lines: {err.strip()[-300:]}")
        return
    if code in (1, 2, 3) and "voiga: error:" not in err and "voiga: " not in err:
        outcome.problems.append(f"exit {code} without a message")
    if code == 2:
        errors = [line for line in err.splitlines() if line.startswith("voiga: error:")] or \
            [line for line in err.splitlines() if line.startswith("voiga: ")]
        if not errors:
            outcome.problems.append("refused without an error line")
        elif attack.words and not all(w in errors[0] for w in attack.words):
            outcome.problems.append(f"message lacks {attack.words}: {errors[0]}")


def result_file(work: Path) -> Path | None:
    """The result the run wrote: the one HDF5 file of the folder with a root
    attribute 'status' (geometry files and their copies have none)."""
    found = []
    for path in work.rglob("*"):
        if not path.is_file() or path.suffix in (".nml", ".lock", ".part"):
            continue
        try:
            with h5py.File(path, "r") as f:
                if "status" in f.attrs:
                    found.append(path)
        except OSError:
            continue
    return found[0] if len(found) == 1 else None


def judge_result(outcome: Outcome, work: Path, result: Path, base: Path) -> None:
    """A result of exit 0: converged, whole, and what the case says."""
    attack = outcome.attack
    try:
        with h5py.File(result, "r") as f:
            problems = converged_problems(f, residual_bound(work / "case.nml"))
            if attack.semantic and parsed(work / "case.nml"):
                problems += semantic_problems(f, work / "case.nml")
                outcome.checked.add("parsed")
            if attack.same:
                problems += same_problems(f, base)
                outcome.checked.add("same")
    except OSError as err:
        problems = [f"result unreadable: {err}"]
    outcome.problems += [f"silent wrong: {p}" for p in problems]


def residual_bound(case: Path) -> float:
    """How far below its first residual a converged step's residual must be: 1e-6,
    or what a looser tol_residual set in the case allows (the energy criterion
    accepts ||r|| <= sqrt(tol_residual) ||r_0||, docs/robustness.md)."""
    try:
        solver = f90nml.read(str(case)).get("solver") or {}
        tol = float(solver.get("tol_residual", 1e-10))
        energy = float(solver.get("tol_energy", 1e-20))
    except Exception:  # noqa: BLE001 - unreadable by f90nml: the default bound
        return 1e-6
    if not (math.isfinite(tol) and math.isfinite(energy)):
        return 1e-6
    return max(1e-6, math.sqrt(max(tol, 0.0)) if energy > 1e-20 or tol > 1e-10 else 0.0)


def converged_problems(f: h5py.File, bound: float = 1e-6) -> list[str]:
    if f.attrs["status"] != b"converged":
        return [f"exit 0 but status {f.attrs['status']!r}"]
    done, planned = int(f.attrs["n_steps_done"]), int(f.attrs["n_steps_planned"])
    if done != planned or len(f["steps"]) != done:
        return [f"converged with {done} of {planned} steps ({len(f['steps'])} groups)"]
    for name, step in f["steps"].items():
        u, r = step["displacement"][()], step["residual_norms"][()]
        scale = max(r[0], float(step.attrs.get("r0_max", 0.0)), 1e-300)
        if not np.all(np.isfinite(u)):
            return [f"step {name}: non-finite displacement"]
        if not (np.isfinite(r[-1]) and (r[-1] <= bound * scale or r[-1] < 1e-12)):
            return [f"step {name}: residual {r[-1]:.3g} of {scale:.3g} marked converged"]
    return []


def parsed(case: Path) -> bool:
    """Can f90nml read the case (else its values are not compared)?"""
    try:
        f90nml.read(str(case))
    except Exception:  # noqa: BLE001 - any parse failure
        return False
    return True


def semantic_problems(f: h5py.File, case: Path) -> list[str]:
    """The values the result records against f90nml's reading of the case; a case
    f90nml cannot read is not compared (another dialect, not a verdict)."""
    try:
        nml = f90nml.read(str(case))
    except Exception:  # noqa: BLE001 - any parse failure: no independent reading
        return []
    def one(group: str):
        g = nml.get(group)
        return g[0] if isinstance(g, list) else g
    problems = []
    solver, body = one("solver"), one("body")
    steps = solver.get("n_steps", 1) if solver is not None else 1
    steps = [steps] if not isinstance(steps, list) else [s for s in steps if s is not None]
    if isinstance(steps[0], int) and sum(steps) != int(f.attrs["n_steps_planned"]):
        problems.append(f"n_steps {steps} in the case, {int(f.attrs['n_steps_planned'])} steps planned")
    if body is not None and "bodies/slab" in f:
        g = f["bodies/slab"]
        for key in ("youngs_modulus", "poisson_ratio"):
            value = body.get(key)
            if isinstance(value, float) and value != float(g.attrs[key]):
                problems.append(f"{key} {value!r} in the case, {float(g.attrs[key])!r} recorded")
        material = body.get("material")
        if isinstance(material, str) and material.strip() != g.attrs["material"].decode().strip():
            problems.append(f"material {material!r} in the case, {g.attrs['material']!r} recorded")
    dirichlet = one("dirichlet")
    if dirichlet is not None and "dirichlet/1/values" in f:
        values = f["dirichlet/1/values"][()]
        for column, key in enumerate(("ux", "uy")):
            given = dirichlet.get(key)
            given = [given] if not isinstance(given, list) else given
            if all(isinstance(v, float) for v in given) and len(given) == len(values) and \
                    not np.array_equal(np.array(given, float), values[:, column]):
                problems.append(f"{key} {given} in the case, {values[:, column].tolist()} recorded")
    contact = one("contact")
    if contact is not None:
        last = f["steps"][max(f["steps"], key=int)] if len(f["steps"]) else None
        if last is not None and "contact/1" in last:
            c = last["contact/1"]
            for key, attr in (("penalty_normal", "penalty_normal"), ("friction", "friction")):
                value = contact.get(key)
                if isinstance(value, float) and value != float(c.attrs[attr]):
                    problems.append(f"{key} {value!r} in the case, {float(c.attrs[attr])!r} recorded")
    return problems


def same_problems(f: h5py.File, base: Path) -> list[str]:
    with h5py.File(base, "r") as b:
        if sorted(f["steps"]) != sorted(b["steps"]):
            return ["other steps than the base case's"]
        for k in b["steps"]:
            if not np.array_equal(f["steps"][k]["displacement"][()], b["steps"][k]["displacement"][()]):
                return [f"step {k}: displacement differs from the base case's"]
    return []


def geometry_problem(path: Path) -> str | None:
    """Why the slab's patch in `path` is not a valid body by the schema (None: it is)."""
    try:
        with np.errstate(all="ignore"):
            return _geometry_problem(path)
    except Exception as err:  # noqa: BLE001 - whatever the check cannot read is not valid
        return f"not readable as a patch ({type(err).__name__}: {err})"


def _geometry_problem(path: Path) -> str | None:
    from pre.geometry import jacobian_signs
    from pre.nurbs import Patch
    try:
        with h5py.File(path, "r") as f:
            g = f["bodies/slab"]
            data = {k: g[k][()] for k in ("degree", "knots_xi", "knots_eta", "control_points", "weights")}
            names = [g.attrs.get(f"edge_{k}") for k in ("xi0", "xi1", "eta0", "eta1")]
            kinds = {k: g[k].dtype.kind for k in data}
    except (OSError, KeyError) as err:
        return f"unreadable ({err})"
    if kinds["degree"] not in "iu" or any(kinds[k] not in "iuf" for k in data if k != "degree"):
        return f"dataset types {kinds}"
    degree = np.asarray(data["degree"]).reshape(-1).astype(np.int64)
    if degree.shape != (2,) or np.any(degree < 1) or np.any(degree > 20):
        return f"degree {degree}"
    cp, w = np.asarray(data["control_points"], float), np.asarray(data["weights"], float)
    if cp.ndim != 3 or cp.shape[2] != 2 or w.shape != cp.shape[:2]:
        return f"shapes {cp.shape}, {w.shape}"
    if not (np.all(np.isfinite(cp)) and np.all(np.isfinite(w)) and np.all(w > 0)):
        return "non-finite points or non-positive weights"
    for key, p, n in (("knots_xi", degree[0], cp.shape[1]), ("knots_eta", degree[1], cp.shape[0])):
        k = np.asarray(data[key], float)
        if k.ndim != 1 or len(k) != n + p + 1 or not np.all(np.isfinite(k)) or np.any(np.diff(k) < 0):
            return f"{key} {k}"
        if k[0] != 0 or k[-1] != 1 or np.any(k[:p + 1] != 0) or np.any(k[-p - 1:] != 1) \
                or k[p + 1] == 0 or k[-p - 2] == 1:
            return f"{key} {k} not open"
        _, counts = np.unique(k[p + 1:-p - 1], return_counts=True)
        if np.any(counts > p):
            return f"{key} {k}: interior multiplicity above {p}"
    if any(n is None for n in names) or len({str(n) for n in names}) != 4:
        return f"edge names {names}"
    patch = Patch(degree=tuple(degree), knots_xi=data["knots_xi"], knots_eta=data["knots_eta"],
                  control_points=cp, weights=w, edges={})
    det = jacobian_signs(patch, n=64)
    scale = float(np.abs(det).max())
    if not scale > 0 or not (np.all(det > 1e-10 * scale) or np.all(det < -1e-10 * scale)):
        return "det J changes sign or vanishes"
    return None


def select(attacks: list[Attack], reduced: bool) -> list[Attack]:
    """The reduced set: every example of the issue and one attack in seven."""
    if not reduced:
        return attacks
    return [a for k, a in enumerate(attacks) if a.example or k % 7 == 0]


def run_all(attacks: list[Attack], voiga: Path, work: Path, jobs: int,
            progress: bool = False) -> list[Outcome]:
    os.environ["ATTACK_VOIGA"] = str(voiga)
    base = base_result(voiga, work / "_base")
    outcomes: list[Outcome] = []
    with concurrent.futures.ThreadPoolExecutor(jobs) as pool:
        futures = [pool.submit(run_attack, a, work / f"{k:05d}", voiga, base) for k, a in enumerate(attacks)]
        for k, future in enumerate(futures):
            outcome = future.result()
            outcomes.append(outcome)
            if progress and not outcome.ok:
                print(f"FAIL {outcome.attack.name}: " + "; ".join(outcome.problems), flush=True)
            if outcome.ok:
                shutil.rmtree(work / f"{k:05d}", ignore_errors=True)
    return outcomes


def table(outcomes: list[Outcome]) -> str:
    """Markdown: per family, the inputs, how they ended (exit 0, 2, 3, other), the runs
    whose result or geometry an oracle compared, and the violations."""
    head = ["family", "inputs", "exit 0", "exit 2", "exit 3", "exit 1", "compared", "crashes", "hangs",
            "silent wrong", "destroyed", "other"]
    lines = ["| " + " | ".join(head) + " |", "|---" * len(head) + "|"]
    for fam in sorted({o.attack.family for o in outcomes}) + ["all"]:
        group = [o for o in outcomes if fam in ("all", o.attack.family)]
        count = Counter(o.kind for o in group)
        bad = Counter()
        for o in group:
            for p in o.problems:
                what = p.split(":")[0]
                bad[what if what in ("silent wrong", "destroyed", "crash") else "other"] += 1
        row = [fam, len(group), count["ran"], count["refused"], count["failed run"], count["other failure"],
               sum(bool(o.checked) for o in group), count["crash"], count["hang"], bad["silent wrong"],
               bad["destroyed"], bad["other"]]
        lines.append("| " + " | ".join(str(x) for x in row) + " |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--reduced", action="store_true", help="the subset of make test")
    p.add_argument("--family", nargs="*", help="only these families (namelist geometry output post)")
    p.add_argument("--out", type=Path, default=None, help="work folder (default: a temporary one)")
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--markdown", type=Path, default=None, help="also write the table here")
    p.add_argument("--list", action="store_true", help="list the attacks and exit")
    args = p.parse_args(argv)
    voiga = Path(os.environ.get("VOIGA_BIN", REPO / "build" / "install" / "bin" / "voiga"))
    work = (args.out or Path(tempfile.mkdtemp(prefix="voiga-attack-"))).resolve()
    start = time.perf_counter()
    base = base_result(voiga, work / "_base")
    attacks = select(all_attacks(base), args.reduced)
    if args.family:
        attacks = [a for a in attacks if a.family in args.family]
    if args.list:
        for a in attacks:
            print(f"{a.family:9s} {a.name}")
        return 0
    outcomes = run_all(attacks, voiga, work, args.jobs, progress=True)
    text = table(outcomes)
    print(f"\n{len(outcomes)} inputs, {sum(not o.ok for o in outcomes)} with a problem, "
          f"{time.perf_counter() - start:.0f} s\n")
    print(text)
    if args.markdown:
        args.markdown.parent.mkdir(parents=True, exist_ok=True)
        args.markdown.write_text(text + "\n")
    return 1 if any(not o.ok for o in outcomes) else 0


if __name__ == "__main__":
    sys.exit(main())
