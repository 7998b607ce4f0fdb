"""The bench harness (`python3 -m bench`): its namelist edits and a tiny scaling run."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import f90nml
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
