"""Fuzz (issue 6): mutated case and geometry files either run (exit 0, or 3 for a
numerical failure recorded in the result file) or are refused with exit code 2 and a
message; none crashes on a signal, hangs, or writes a result marked converged that is
not. Deterministic (seeded); 520 inputs, half of them from a base case with the
mortar-type contact penalty."""
from __future__ import annotations

import random
import shutil
import subprocess
from pathlib import Path

import h5py
import numpy as np
import pytest

from conftest import REPO

BASE = """&case
  title = 'fuzz block', geometry = 'geometry.h5', output = 'out.h5', n_bodies = 1
/
&body
  name = 'slab', material = 'neo-hookean', youngs_modulus = 1.0, poisson_ratio = 0.3,
  degree_xi = 2, degree_eta = 2, nel_xi = 3, nel_eta = 1, contact_edge = 'bottom',
  layer_degree = 2, layer_elevations = 1
/
&solver
  n_steps = 2, 2
  max_iterations = 30
  damping = 'natural'
/
&dirichlet
  body = 'slab', edge = 'top', fix_x = .true., fix_y = .true., ux = 0.0, 0.3, uy = -0.03, -0.03
/
&contact
  slave = 'slab', master = 'rigid', rigid_point = 0.0, -3.0, rigid_normal = 0.0, 1.0,
  penalty_normal = 100.0, penalty_tangent = 100.0, friction = 0.3
  method = 'gpts'
/
"""

VALUES = ["0", "-1", "1e308", "-1e308", "1e-308", "NaN", "Infinity", "-Infinity", "'text'", ".true.",
          "3.5", "2", "100000000000", "''", "1, 2, 3", "'slab'", "'rigid'", "0.5", "'mortar'"]


def mutate_case(text: str, rng: random.Random) -> str:
    """One random change of the namelist text."""
    lines = text.splitlines() or [""]
    kind = rng.randrange(6)
    i = rng.randrange(len(lines))
    if kind == 1 and not any("=" in line for line in lines):
        kind = 2
    if kind == 0:                                   # delete a line
        del lines[i]
    elif kind == 1:                                 # replace one value
        assignments = [(k, line) for k, line in enumerate(lines) if "=" in line]
        k, line = rng.choice(assignments)
        parts = line.split(",")
        j = rng.randrange(len(parts))
        if "=" in parts[j]:
            name, _ = parts[j].split("=", 1)
            parts[j] = f"{name}= {rng.choice(VALUES)}"
        lines[k] = ",".join(parts)
    elif kind == 2:                                 # duplicate a line
        lines.insert(i, lines[i])
    elif kind == 3:                                 # garbage characters
        pos = rng.randrange(len(lines[i]) + 1)
        lines[i] = lines[i][:pos] + rng.choice(["&", "/", "=", "!", "'", "@@", ",,", "\t"]) + lines[i][pos:]
    elif kind == 4:                                 # truncate the file
        lines = lines[:i]
    else:                                           # swap two lines
        j = rng.randrange(len(lines))
        lines[i], lines[j] = lines[j], lines[i]
    return "\n".join(lines) + "\n"


def mutate_geometry(path: Path, rng: random.Random) -> None:
    """One random change of the slab's patch in the geometry file."""
    with h5py.File(path, "r+") as f:
        g = f["bodies/slab"]
        key = rng.choice(["knots_xi", "knots_eta", "weights", "control_points", "degree"])
        data = g[key][()]
        kind = rng.randrange(5)
        if kind == 0:
            del g[key]
            return
        if kind == 1:
            data = data[..., :-1] if data.ndim else data
        elif kind == 2:
            flat = data.reshape(-1).astype(float)
            flat[rng.randrange(flat.size)] = rng.choice([np.nan, np.inf, -1.0, 0.0, 1e300, -5.0])
            if key == "degree":
                flat = np.clip(np.nan_to_num(flat, nan=0, posinf=99, neginf=-99), -99, 99)
            data = flat.reshape(data.shape).astype(data.dtype)
        elif kind == 3:
            data = data[::-1].copy()
        else:
            data = data * 2
        del g[key]
        g[key] = data


def check_result(path: Path) -> None:
    """A result marked converged really is: every planned step, finite, small residuals."""
    with h5py.File(path, "r") as f:
        status = f.attrs["status"].decode()
        if status != "converged":
            assert status.startswith("failed") or status in ("running", "interrupted"), status
            return
        assert f.attrs["n_steps_done"] == f.attrs["n_steps_planned"]
        for name, step in f["steps"].items():
            u = step["displacement"][()]
            assert np.all(np.isfinite(u)), name
            r = step["residual_norms"][()]
            # the step's first residual, or the run's force scale so far (r0_max: the
            # largest first residual of a substep) when the predictor started the step
            # close to equilibrium: a residual far below the force scale is converged
            scale = max(r[0], float(step.attrs.get("r0_max", 0.0)), 1e-300)
            assert np.isfinite(r[-1]) and (r[-1] <= 1e-6 * scale or r[-1] < 1e-12), (name, r, scale)


@pytest.mark.parametrize("chunk", range(4))
def test_fuzz(voiga_bin: Path, tmp_path: Path, chunk: int) -> None:
    rng = random.Random(1000 + chunk)
    geometry = REPO / "cases" / "ironing" / "geometry.h5"
    counts = {"ran": 0, "refused": 0, "failed run": 0}
    for k in range(130):
        work = tmp_path / f"{k}"
        work.mkdir()
        shutil.copy(geometry, work / "geometry.h5")
        text = BASE if chunk < 2 else BASE.replace("method = 'gpts'", "method = 'mortar'")
        if rng.random() < 0.75:
            for _ in range(1 + rng.randrange(2)):
                text = mutate_case(text, rng)
        else:
            mutate_geometry(work / "geometry.h5", rng)
        (work / "case.nml").write_text(text)
        try:
            proc = subprocess.run([str(voiga_bin), "case.nml", "--quiet"], cwd=work, capture_output=True,
                                  text=True, timeout=60)
        except subprocess.TimeoutExpired:
            pytest.fail(f"input {chunk}/{k} hangs:\n{text}")
        assert proc.returncode >= 0, f"input {chunk}/{k} died on signal {-proc.returncode}:\n{text}"
        assert proc.returncode in (0, 2, 3), (proc.returncode, proc.stderr, text)
        if proc.returncode == 2:
            counts["refused"] += 1
            assert "voiga: error:" in proc.stderr and "Backtrace" not in proc.stderr, proc.stderr
            assert not (work / "out.h5").exists() or h5py.File(work / "out.h5").attrs["status"] != b"converged"
            continue
        counts["ran" if proc.returncode == 0 else "failed run"] += 1
        # the case may name another output after a mutation: check every result file
        for p in work.glob("*.h5"):
            if p.name != "geometry.h5":
                try:
                    check_result(p)
                except AssertionError as err:
                    raise AssertionError(f"input {chunk}/{k}: {err}\n{text}") from err
        shutil.rmtree(work)
    assert counts["ran"] > 0 and counts["refused"] > 0, counts
