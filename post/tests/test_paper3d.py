"""The 3D study (``make paper3d``, docs/validation-3d.md): the study file, the 3D measures
in the study's summary, the ratio to N2, and the figures and tables of ``post figures``.

The engine runs two short 3D cases (about 3 CPU s): hertz3d m1 N2 (5 steps) and ironing3d
m1 N2 with 2 press and 16 slide steps (the study's cases take 10 and 40; the measures
need 8 sliding steps, and a cubic trend leaves nothing of a window shorter than 5)."""

from __future__ import annotations

import csv
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest

from post.__main__ import main
from post.figures import make_all
from post.figures3d import run_table, vo_table
from post.hertz3d import hertz3d_comparison
from post.ironing3d import ironing_forces
from post.reader import read_result
from post.study import load_study
from post.sweep import find_cases, summarize
from pre.cases import STUDIES_3D
from pre.hertz3d import Ball, write_hertz3d
from pre.ironing3d import Iron, write_ironing3d

REPO = Path(__file__).resolve().parents[2]


def test_paper3d_study_is_every_committed_3d_case() -> None:
    """cases/studies/paper3d.toml runs the committed hertz3d and ironing3d cases, the ones
    pre.cases.STUDIES_3D lists, unchanged, timing the short ones over 3 to 9 runs."""
    study = load_study(REPO / "cases" / "studies" / "paper3d.toml", Path("out"))
    runs = study.runs()
    assert sorted((r.scene, r.mesh, r.layout) for r in runs) == sorted(
        (scene, mesh, layout) for scene, cases in STUDIES_3D.items() for mesh, layout in cases)
    assert all(r.case.is_file() and r.geometry.is_file() and r.text is None and not r.changes for r in runs)
    assert sorted(r.case for r in runs) == sorted(p for scene in STUDIES_3D
                                                  for p in (REPO / "cases" / scene).glob("*.nml"))
    policy = study.policy()
    assert (policy.short_s, policy.min_repeats, policy.max_repeats) == (2.0, 3, 9)
    assert not study.figures


@pytest.fixture(scope="module")
def study3d(voiga: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A two-case 3D study run by the engine: its results folder."""
    root = tmp_path_factory.mktemp("paper3d")
    write_hertz3d(Ball(), ["m1"], ["N2"], root / "cases" / "hertz3d")
    write_ironing3d(Iron(), ["m1"], ["N2"], root / "cases" / "ironing3d", steps=(2, 16))
    (root / "cases" / "studies").mkdir()
    toml = root / "cases" / "studies" / "short3d.toml"
    toml.write_text('cases = ".."\nscenes = ["hertz3d", "ironing3d"]\nfigures = false\n')
    out = root / "results"
    code = main(["study", str(toml), "--out", str(out), "--binary", str(voiga), "--no-progress", "--jobs", "1"])
    assert code == 0
    return out


def _rows(out: Path) -> dict[str, dict[str, str]]:
    return {r["scene"]: r for r in csv.DictReader((out / "summary.csv").open())}


def test_summary_holds_the_3d_measures(study3d: Path) -> None:
    """The summary's hertz3d row carries post hertz3d's comparison, the ironing3d row post
    ironing's measures of the same result file, and ironing3d's N2 is 100 % of itself."""
    rows = _rows(study3d)
    assert {r["status"] for r in rows.values()} == {"converged"}
    hz = rows["hertz3d"]
    h = hertz3d_comparison(read_result(study3d / "hertz3d" / "m1-N2.h5"))
    assert float(hz["l2_analytic"]) == pytest.approx(h.error.l2, rel=1e-12)
    assert float(hz["a_err"]) == pytest.approx(h.a_error, rel=1e-12)
    assert float(hz["abs_a_err"]) == pytest.approx(abs(h.a_error), rel=1e-12)
    assert float(hz["p0_err"]) == pytest.approx(h.p0_error, rel=1e-12)
    assert float(hz["force"]) == pytest.approx(h.force, rel=1e-12)
    assert h.shear is not None and float(hz["tau_err"]) == pytest.approx(h.shear.tau_max / h.tau_hertz - 1,
                                                                         rel=1e-12)
    # a converged Hertz run on the coarsest mesh: an error, not zero and not nonsense
    assert 0.0 < float(hz["l2_analytic"]) < 0.5
    ir = rows["ironing3d"]
    m = ironing_forces(read_result(study3d / "ironing3d" / "m1-N2.h5")).measures
    for key in ("osc_t", "osc_n", "amp_t", "amp_n", "mean_t", "mean_n", "spread_t", "spread_n", "ratio"):
        assert float(ir[key]) == pytest.approx(m[key], rel=1e-12), key
    assert float(ir["osc_t"]) > 0 and float(ir["osc_n"]) > 0
    assert float(ir["t_pct_n2"]) == 100.0 and float(ir["n_pct_n2"]) == 100.0
    assert "px_pct_n2" not in ir or ir["px_pct_n2"] == ""
    assert all(float(r["dofs"]) > 0 and float(r["wall_s"]) > 0 for r in rows.values())


def test_oscillation_relative_to_n2(study3d: Path, tmp_path: Path) -> None:
    """A copy of the N2 result as layout NN2.1 whose forces are doubled: its oscillation
    amplitudes are 200 % of N2's on the same mesh, its relative oscillation the same."""
    cases = tmp_path / "cases" / "ironing3d"
    cases.mkdir(parents=True)
    out = tmp_path / "out"
    (out / "ironing3d").mkdir(parents=True)
    for layout in ("N2", "NN2.1"):
        shutil.copy(study3d / "ironing3d" / "m1-N2.nml", cases / f"m1-{layout}.nml")
        shutil.copy(study3d / "ironing3d" / "m1-N2.h5", out / "ironing3d" / f"m1-{layout}.h5")
    with h5py.File(out / "ironing3d" / "m1-NN2.1.h5", "r+") as f:
        for step in f["steps"].values():
            step["contact/1/force"][...] = 2.0 * step["contact/1/force"][()]
    rows = summarize(find_cases(tmp_path / "cases", out), jobs=1)
    n2, vo = rows
    assert (n2["layout"], vo["layout"]) == ("N2", "NN2.1")
    assert vo["t_pct_n2"] == pytest.approx(200.0, rel=1e-12)
    assert vo["n_pct_n2"] == pytest.approx(200.0, rel=1e-12)
    assert vo["osc_t"] == pytest.approx(n2["osc_t"], rel=1e-12)


def _row(mesh: str, layout: str, dofs: int, osc: float, cpu: tuple[float, float, float],
         wall: float, osc_n: float | None = None) -> dict[str, str]:
    return {"scene": "ironing3d", "mesh": mesh, "layout": layout, "status": "converged", "dofs": str(dofs),
            "iterations": "100", "cuts": "0", "osc_t": str(osc), "osc_n": str(osc / 2 if osc_n is None else osc_n),
            "repeats": "1",
            "cpu_s": str(cpu[0]), "cpu_lo_s": str(cpu[1]), "cpu_hi_s": str(cpu[2]),
            "wall_s": str(wall), "wall_lo_s": str(wall), "wall_hi_s": str(wall)}


def test_vo_table_ratios() -> None:
    """For each uniform run: the VO run with the fewest DOFs that reaches its error, the
    VO run with the least CPU time when that is another, the DOFs, CPU and wall ratios
    with the range the repeats allow; a uniform run no VO run reaches says so."""
    rows = [_row("m3", "N2", 5712, 0.022, (74.0, 70.0, 80.0), 188.0),
            _row("m4", "N2", 12000, 0.0040, (415.0, 415.0, 415.0), 1000.0),
            _row("m1", "NN2.2", 2730, 0.006, (30.0, 28.0, 33.0), 139.0),
            _row("m2", "NN2.1", 3840, 0.0075, (20.0, 20.0, 20.0), 42.0, osc_n=0.02),
            _row("m1", "NN2.1", 1896, 0.038, (15.0, 15.0, 15.0), 48.0)]
    text = vo_table(rows, "ironing3d", ("osc_t",))
    lines = text.splitlines()[2:]
    assert len(lines) == 3
    # m3 N2 (2.2 %): NN2.2 m1 has the fewest DOFs, NN2.1 m2 the least CPU
    assert lines[0].startswith("| m3-N2 (2.20 %) | 5,712 | m1-NN2.2 (0.60 %) | 2,730 | 2.1x |")
    assert f"{74 / 30:.2g}x [{70 / 33:.2g}-{80 / 28:.2g}]" in lines[0]
    assert f"{188 / 139:.2g}x [" in lines[0]
    assert lines[1].startswith("| m3-N2 (2.20 %) | 5,712 | m2-NN2.1 (0.75 %) | 3,840 | 1.5x |")
    assert lines[2] == "| m4-N2 (0.40 %) | 12,000 | none reaches it | | | | |"
    # both components: NN2.1 m2's osc_n 2 % is above m3 N2's 1.1 %
    both = vo_table(rows, "ironing3d", ("osc_t", "osc_n")).splitlines()[2:]
    assert both[0].startswith("| m3-N2 (2.20 %, 1.10 %) | 5,712 | m1-NN2.2 (0.60 %, 0.30 %) | 2,730 | 2.1x |")
    assert len(both) == 2 and "none reaches it" in both[1]
    table = run_table(rows, "ironing3d")
    assert table.splitlines()[2].startswith("| m3 | N2 | 5,712 | 100 | 0 | 74 [70-80] | 188 | 2.20 % |")


def test_figures_of_the_3d_study(study3d: Path, tmp_path: Path) -> None:
    """``post figures`` on 3D results: the error against DOFs, CPU and wall time, the
    force histories and pressure profiles, and the tables of the 3D scenes only (no
    section or figure of a 2D scene it has no run of)."""
    made = {p.name for p in make_all(study3d, tmp_path, jobs=1)}
    for scene, error in (("hertz3d", "l2_analytic"), ("hertz3d", "abs_a_err"),
                         ("ironing3d", "osc_t"), ("ironing3d", "osc_n")):
        assert {f"{scene}-{error}-vs-{x}.png" for x in ("dofs", "cpu", "wall")} <= made
    assert {"ironing3d-forces-m1.png", "hertz3d-pressure-m1.png"} <= made
    assert not any(name.startswith(("hertz-", "ironing-", "rings-")) for name in made)
    text = (tmp_path / "accuracy-cost.md").read_text()
    for section in ("## hertz3d: the runs", "## hertz3d: l2_analytic", "## ironing3d: osc_n",
                    "## ironing3d: VO against uniform order, osc_t and osc_n"):
        assert section in text
    assert "## hertz: " not in text and "## rings: " not in text
    # one uniform run and no VO run: the VO table says so
    assert "| m1-N2 (" in text and "none reaches it" in text
    assert np.isfinite(float(_rows(study3d)["ironing3d"]["cpu_s"]))
