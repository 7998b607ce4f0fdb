"""The bench harness (`python3 -m bench`): its namelist edits and a tiny scaling run."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import f90nml
import h5py
import pytest

from conftest import REPO

sys.path.insert(0, str(REPO))
from bench.run import add_to_group  # noqa: E402

CASE = """&case
  title = 't'
/
&solver
  n_steps = 5
/
&dirichlet
  body = 'b'
/
"""


def test_add_to_group_adds_and_replaces(tmp_path: Path) -> None:
    added = add_to_group(CASE, "solver", "linear_solver", "'multigrid'")
    replaced = add_to_group(added, "solver", "linear_solver", "'direct'")
    for text, value in ((added, "multigrid"), (replaced, "direct")):
        path = tmp_path / "c.nml"
        path.write_text(text)
        nml = f90nml.read(path)
        assert nml["solver"]["linear_solver"] == value
        assert nml["solver"]["n_steps"] == 5
        assert "linear_solver" not in nml["dirichlet"]
    assert replaced.count("linear_solver") == 1


def test_scaling_section_runs_both_solvers(voiga_bin: Path, tmp_path: Path) -> None:
    """Section 4 on m1..m2: one row per solver and mesh, GMRES counted for multigrid only."""
    out = tmp_path / "bench.json"
    res = subprocess.run(
        [sys.executable, "-m", "bench", "--only", "4", "--levels", "2", "--repeat", "1",
         "--work", str(tmp_path / "work"), "--json", str(out)],
        cwd=REPO, capture_output=True, text=True, timeout=300,
        env={**os.environ, "VOIGA_BIN": str(voiga_bin)},
    )
    assert res.returncode == 0, res.stdout + res.stderr
    rows = json.loads(out.read_text())["scaling"]["rows"]
    assert [r["mesh"] for r in rows["direct"]] == ["m1", "m2"]
    assert [r["mesh"] for r in rows["multigrid"]] == ["m1", "m2"]
    assert all(r["linear_iterations"] == 0 for r in rows["direct"])
    assert all(r["linear_iterations"] >= r["iterations"] for r in rows["multigrid"])
    assert "wall time per iteration, direct / multigrid" in res.stdout


def test_stages_table_of_a_run(run, tmp_path: Path) -> None:
    """`python3 -m bench.stages` on a real result: its iterations are the steps' totals and
    its stage columns their sums over those iterations; a missing file exits 2."""
    shutil.copy(REPO / "cases" / "hertz" / "geometry.h5", tmp_path / "geometry.h5")
    case = tmp_path / "case.nml"
    shutil.copy(REPO / "cases" / "hertz" / "m1-N2.nml", case)
    assert run(case, "--quiet", cwd=tmp_path).returncode == 0
    result = tmp_path / f90nml.read(case)["case"]["output"]
    with h5py.File(result, "r") as f:
        steps = [f["steps"][k].attrs for k in f["steps"]]
        iters = sum(int(a["iterations_total"]) for a in steps)
        contact_ms = 1e3 * sum(float(a["seconds_contact"]) for a in steps) / iters
    res = subprocess.run([sys.executable, "-m", "bench.stages", str(result)], cwd=REPO,
                         capture_output=True, text=True, timeout=60)
    assert res.returncode == 0, res.stderr
    row = res.stdout.splitlines()[1].split()
    assert int(row[1]) == iters
    # columns after '|': assembly, contact, factorization, solve, output, other
    assert float(row[5]) == pytest.approx(contact_ms, abs=1e-3)
    missing = subprocess.run([sys.executable, "-m", "bench.stages", str(tmp_path / "no.h5")],
                             cwd=REPO, capture_output=True, text=True, timeout=60)
    assert missing.returncode == 2 and "no such result file" in missing.stderr
