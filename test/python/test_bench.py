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


def _rows(**changes: str) -> list[dict[str, str]]:
    row = {"scene": "ironing", "mesh": "m3", "layout": "NN2.2", "wall_s": "3.5", "assembly_s": "1.0",
           "contact_s": "0.8", "factorization_s": "0.9", "solve_s": "0.1", "output_s": "0.2",
           "osc_py": "0.0011"}
    row.update(changes)
    return [row, {**row, "mesh": "m4", "wall_s": "16.0", "assembly_s": "5.0"}]


def test_paper_phases_from_stamped_lines() -> None:
    """`bench.paper`'s phases: the study starts where the line before its first bar ended
    (a bar line is stamped when the next replaces it), the runs end at the bar's last case,
    the summary at the study's closing line."""
    from bench.paper import phases
    lines = [(0.2, "fpm install --profile release"), (0.4, "Project is up to date"), (2.0, ""),
             (40.0, "study:   0%|          | 0/3 [00:00<?, ?case/s]"),
             (90.0, "study:  67%|######    | 2/3 [01:28<00:44, 44.0s/case]"),
             (200.0, "study: 100%|##########| 3/3 [03:18<00:00, 66.0s/case]"),
             (204.0, "3 cases, 0 failed; summary in out/summary.csv and out/summary.md"),
             (213.0, "docs/validation/x.png")]
    ph = phases(lines, 213.5)
    assert (ph.build, ph.runs, ph.summary, ph.end) == (2.0, 200.0, 204.0, 213.5)
    with pytest.raises(ValueError, match="no study summary line"):
        phases(lines[:5], 100.0)


def test_paper_work_and_measures() -> None:
    """The runs' work sums their times; the comparison skips the time columns and reports
    a changed measure or a case only one run has."""
    from bench.paper import differences, work
    totals = work(_rows())
    assert totals["wall_s"] == pytest.approx(19.5) and totals["assembly_s"] == pytest.approx(6.0)
    assert differences(_rows(wall_s="4.0", solve_s="0.3"), _rows()) == []
    # the cost columns (CPU and wall time over the repeats, their number) are times too
    assert differences(_rows(cpu_s="1.0", cpu_hi_s="1.2", repeats="5", wall_lo_s="0.9"),
                       _rows(cpu_s="1.1", cpu_hi_s="1.3", repeats="3", wall_lo_s="1.0")) == []
    assert differences(_rows(osc_py="0.0012"), _rows()) == [
        "ironing/m3/NN2.2 osc_py: 0.0012 against 0.0011", "ironing/m4/NN2.2 osc_py: 0.0012 against 0.0011"]
    assert differences(_rows()[:1], _rows()) == ["ironing/m4/NN2.2: only in the old run"]
    # with a tolerance: a rounding-sized change passes, a larger one and changed text do not
    assert differences(_rows(osc_py="0.00110000000001"), _rows(), rtol=1e-9) == []
    assert len(differences(_rows(osc_py="0.0011001"), _rows(), rtol=1e-9)) == 2
    assert len(differences(_rows(osc_py="nan?"), _rows(), rtol=1e-9)) == 2


def test_paper_stamps_lines_and_keeps_results(tmp_path: Path) -> None:
    """Carriage returns and newlines both end a stamped line (tqdm redraws with the
    former), the log gets every line and the exit code; a PAPER_OUT that exists is
    refused with exit code 2, before anything runs."""
    from bench.paper import main, stamped_lines
    lines, code, end = stamped_lines(["sh", "-c", "printf 'a\\rb\\nc'; exit 3"], tmp_path, tmp_path / "x.log")
    assert [text for _, text in lines] == ["a", "b", "c"] and code == 3
    assert end >= lines[-1][0] >= lines[0][0] >= 0.0
    assert (tmp_path / "x.log").read_text().splitlines()[-1].endswith("END rc=3")
    (tmp_path / "done").mkdir()
    (tmp_path / "done" / "summary.csv").write_text("kept\n")
    assert main([str(tmp_path / "done")]) == 2
    assert (tmp_path / "done" / "summary.csv").read_text() == "kept\n"


def test_paper_work_of_the_repeats(tmp_path: Path) -> None:
    """Every run of voiga, the repeats included, from the times kept beside the results."""
    from bench.paper import repeats_work
    (tmp_path / "hertz").mkdir()
    (tmp_path / "hertz" / "m1-N2.cost.json").write_text('{"wall_s": [0.05, 0.04], "cpu_s": [0.03, 0.02]}')
    (tmp_path / "hertz" / "m2-N2.cost.json").write_text('{"wall_s": [1.0], "cpu_s": [0.9]}')
    (tmp_path / "hertz" / "m3-N2.cost.json").write_text("{ torn")
    totals = repeats_work(tmp_path)
    assert totals["runs"] == 3
    assert totals["wall_s"] == pytest.approx(1.09) and totals["cpu_s"] == pytest.approx(0.95)
