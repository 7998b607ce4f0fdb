"""Study files (post/study.py), file measures and the friction study (cases/studies)."""
from __future__ import annotations

import csv
import os
import re
from pathlib import Path

import f90nml
import numpy as np
import pytest

from post.__main__ import main
from post.cost import ONCE
from post.measures import file_measure, parse_file_measure
from post.reader import read_result
from post.study import NAMELISTS, Study, case_stem, load_study
from pre.cases import STUDIES_3D

REPO = Path(__file__).resolve().parents[2]
HERTZ = REPO / "cases" / "hertz" / "m1-N2.nml"


def write_study(folder: Path, text: str, name: str = "study.toml") -> Path:
    """A study file in ``folder`` (``{hertz}``: the hertz m1-N2 case, relative to it)."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_text(text.replace("{hertz}", os.path.relpath(HERTZ, folder)))
    return path


def test_namelists_are_those_of_the_solver() -> None:
    """The groups and variables a study may change are the ones the readers of
    src/io/input/case/ (one per group) read."""
    found = {}
    for path in sorted((REPO / "src" / "io" / "input").rglob("*.f90")):
        for m in re.finditer(r"namelist\s*/(\w+)/\s*((?:[^\n]*&\s*\n)*[^\n]*)", path.read_text()):
            names = re.sub(r"&\s*\n", " ", m.group(2))
            found[m.group(1)] = frozenset(v.strip() for v in names.split(",") if v.strip())
    assert found == NAMELISTS


def test_grid_times_list_derives_every_case(tmp_path: Path) -> None:
    study = load_study(write_study(tmp_path, """
base = "{hertz}"
out = "out"
[grid]
contact.penalty_normal = [1000.0, 2000.0]
[[list]]
"body[cylinder]".youngs_modulus = 2.0
[[list]]
"dirichlet[2]".fix_x = false
[[list]]
"dirichlet[1].uy" = -0.02
solver = {n_steps = 2, max_cuts = 3}
"""))
    assert study.out == tmp_path / "out"
    runs = study.runs()
    assert len(runs) == 6
    assert runs[0].work == tmp_path / "out" / "hertz" / \
        "m1-N2+body[cylinder].youngs_modulus=2.0+contact.penalty_normal=1000.0.nml"
    assert len({r.work for r in runs}) == 6
    nml = f90nml.reads(runs[5].text)
    assert nml["contact"]["penalty_normal"] == 2000.0
    assert nml["dirichlet"][0]["uy"] == -0.02 and nml["solver"]["n_steps"] == 2
    assert nml["solver"]["max_cuts"] == 3
    assert nml["case"]["output"] == runs[5].work.stem + ".h5"
    assert f90nml.reads(runs[2].text)["dirichlet"][1]["fix_x"] is False
    assert f90nml.reads(runs[0].text)["body"]["youngs_modulus"] == 2.0
    # every run's table columns: each changed variable's value in that case
    assert runs[0].params == {"contact.penalty_normal": 1000.0, "body[cylinder].youngs_modulus": 2.0,
                              "dirichlet[2].fix_x": True, "dirichlet[1].uy": -0.01,
                              "solver.n_steps": 5, "solver.max_cuts": None}
    # the rest of the case is the base's, value for value
    base = f90nml.read(str(HERTZ))
    assert nml["body"]["knots_xi"] == base["body"]["knots_xi"]


def test_long_case_names_are_hashed() -> None:
    short = case_stem("m1-N2", (("contact.friction", 0.1), ("body[slab].youngs_modulus", 2.0)))
    assert short == "m1-N2+contact.friction=0.1+body[slab].youngs_modulus=2.0"
    long = case_stem("m1-N2", (("body[slab].knots_xi", tuple(i / 100 for i in range(1, 100))),))
    other = case_stem("m1-N2", (("body[slab].knots_xi", tuple(i / 100 for i in range(2, 100))),))
    assert re.fullmatch(r"m1-N2\+[0-9a-f]{12}", long) and long != other


@pytest.mark.parametrize("text, cause", [
    ('base = "{hertz}"\n[grid]\ncontakt.friction = [0.1]\n', "no namelist group &contakt"),
    ('base = "{hertz}"\n[grid]\ncontact.frictoin = [0.1]\n', "&contact has no variable 'frictoin'"),
    ('base = "nowhere/m1-N2.nml"\n[grid]\ncontact.friction = [0.1]\n', "does not exist"),
    ('base = "{hertz}"\n[grid]\n"body[slab]".youngs_modulus = [2.0]\n', "no &body named 'slab'"),
    ('base = "{hertz}"\n[grid]\ndirichlet.fix_x = [true]\n', "2 &dirichlet groups"),
    ('base = "{hertz}"\n[grid]\ncase.output = ["x.h5"]\n', "cannot be changed"),
    ('base = "{hertz}"\n[grid]\ncontact.friction = 0.1\n', "must be a non-empty list"),
    ('base = "{hertz}"\nmeasures = ["median(n_dofs)"]\n', "unknown reduction"),
    ('base = "{hertz}"\nbogus = 1\n', "unknown key 'bogus'"),
    ('base = "{hertz}"\nmeasures = { cuts = "n_cuts" }\n', "is a column of the table already"),
    ('cases = "../.."\nscenes = ["nosuch"]\n', "no committed case"),
    ('base = "{hertz}"\n[grid\n', "not a TOML file"),
    ('base = "{hertz}"\nrepeats = 0\n', "repeats must be a whole number of runs, at least 1"),
    ('base = "{hertz}"\nrepeats = 2.5\n', "repeats must be a whole number of runs, at least 1"),
    ('base = "{hertz}"\nrepeats = 101\n', "at least 1 and at most 100"),
    ('base = "{hertz}"\nrepeat_below = -1\n', "repeat_below must be a positive number"),
    ('base = "{hertz}"\nrepeats = true\n', "repeats must be a whole number of runs, at least 1"),
    ('base = "{hertz}"\nrepeat_below = nan\n', "repeat_below must be a positive number"),
    # issue 36: values that ended in a traceback or an error per case
    ('base = "{hertz}"\ntimeout = 1e308\n', "timeout must be more than 0 and at most"),
    ('base = "{hertz}"\ntimeout = nan\n', "timeout must be more than 0 and at most"),
    ('base = "{hertz}"\ntimeout = true\n', "timeout must be a number of seconds"),
    ('base = "{hertz}"\n[grid]\ncontact.friction = [{a = 1}]\n', "is not a namelist value"),
    ('base = "{hertz}"\n[grid]\ncontact.friction = [nan]\n', "is not a namelist value"),
    ('base = "{hertz}"\n[grid]\ncontact.rigid_point = [[[0.0]]]\n', "a list inside a list"),
    ('base = "{hertz}"\n[[list]]\ncontact.friction = [{a = 1}]\n', "is not a namelist value"),
    ('base = "{hertz}"\nfigures = "yes"\n', "figures must be true or false"),
])
def test_bad_study_is_one_line_and_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                          text: str, cause: str) -> None:
    path = write_study(tmp_path, text)
    assert main(["study", str(path), "--list", "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and cause in err and "Traceback" not in err, err


@pytest.mark.parametrize("n", ["0", "101"])
def test_repeats_must_be_from_one_to_a_hundred(capsys: pytest.CaptureFixture[str], n: str) -> None:
    with pytest.raises(SystemExit) as stop:
        main(["study", str(REPO / "cases" / "studies" / "friction.toml"), "--list", "--repeats", n])
    assert stop.value.code == 2 and f"'{n}': must be at least 1 and at most 100" in capsys.readouterr().err


def test_malformed_scheduler_address(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    fake = tmp_path / "voiga"
    fake.write_text("")
    fake.chmod(0o755)  # (never run: the scheduler is refused first)
    assert main(["study", str(REPO / "cases" / "studies" / "friction.toml"), "--out", str(tmp_path / "out"),
                 "--binary", str(fake), "--scheduler", "foo"]) == 2
    err = capsys.readouterr().err
    assert "no Dask scheduler answers at foo" in err and "Traceback" not in err


@pytest.mark.parametrize("option", [["--jobs", "-1"], ["--jobs", "100000"], ["--timeout", "1e308"],
                                    ["--timeout", "nan"], ["--timeout", "-1"],
                                    ["--scheduler", "tls://127.0.0.1:1"]])
def test_bad_engine_options_refused(capsys: pytest.CaptureFixture[str], tmp_path: Path,
                                    option: list[str]) -> None:
    """Issue 36: --jobs -1 hung (a local cluster of -1 workers), --jobs 100000 ran,
    --timeout 1e308 failed every case with OverflowError, a tls:// scheduler without
    certificates ended in a TypeError traceback. Now each is one line and exit 2."""
    fake = tmp_path / "voiga"
    fake.write_text("")
    fake.chmod(0o755)  # (never run: a valid binary, so that only the option is at fault)
    code = main(["study", str(REPO / "cases" / "studies" / "friction.toml"), "--out", str(tmp_path / "out"),
                 "--binary", str(fake), "--no-progress", *option])
    err = capsys.readouterr().err
    assert code == 2, err
    lines = [line for line in err.strip().splitlines() if line.startswith("python -m post study")]
    assert len(lines) == 1 and (option[0] in lines[0] or option[1] in lines[0]), err
    assert "Traceback" not in err


def test_missing_study_file(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    assert main(["study", str(tmp_path / "none.toml")]) == 2
    assert "no study file" in capsys.readouterr().err


def test_paper_study_is_every_committed_case() -> None:
    """paper.toml: every committed 2D case (the 3D scenes are paper3d.toml's,
    post/tests/test_paper3d.py)."""
    study = load_study(REPO / "cases" / "studies" / "paper.toml", Path("out"))
    runs = study.runs()
    committed = sorted(p for p in (REPO / "cases").glob("*/*.nml") if p.parent.name not in STUDIES_3D)
    assert sorted(r.case for r in runs) == committed
    # unchanged: the committed text is solved as it is
    assert all(r.text is None and not r.changes for r in runs)
    assert {r.work.parent.name for r in runs} == {"hertz", "ironing", "ironing-deep", "rings"}
    # a run under 2 CPU seconds is timed over 3 to 9 runs, a longer one once
    policy = study.policy()
    assert (policy.short_s, policy.min_repeats, policy.max_repeats) == (2.0, 3, 9)
    # a study that names no repeats runs each case once; --repeats sets them
    plain = Study(out=Path("out"))
    assert plain.policy() == ONCE
    plain.repeats = 2
    assert plain.policy().min_repeats == 2


def test_generated_cases_where_none_is_committed(tmp_path: Path) -> None:
    path = write_study(tmp_path, 'cases = "%s"\ngenerate = true\nscenes = ["ironing"]\n'
                       'meshes = ["m1", "m5"]\nlayouts = ["N2"]\n' % (REPO / "cases"))
    runs = load_study(path).runs()
    assert [r.work.stem for r in runs] == ["m1-N2", "m5-N2"]
    assert runs[0].text is None                    # committed
    body = f90nml.reads(runs[1].text)["body"]      # built by pre.cases: 16 x m1's elements
    assert [b["nel_xi"] for b in body] == [96, 128]


def test_file_measures(stretch_h5: Path) -> None:
    res = read_result(stretch_h5)
    last = res.steps[-1]
    assert file_measure(stretch_h5, "n_dofs") == res.n_dofs
    assert file_measure(stretch_h5, "steps/last/reactions[2,0]") == last.reactions[2, 0]
    assert file_measure(stretch_h5, "steps/-2/reactions[2,0]") == res.steps[-2].reactions[2, 0]
    assert file_measure(stretch_h5, "max(steps/last/displacement)") == last.displacement.max()
    assert file_measure(stretch_h5, "steps/last/iterations") == last.iterations
    with pytest.raises(KeyError):
        file_measure(stretch_h5, "steps/last/nothing")
    with pytest.raises(ValueError, match="index or reduce"):
        file_measure(stretch_h5, "steps/last/displacement")
    assert parse_file_measure("absmax(steps/last/contact/1/p_t)") == ("absmax", "steps/last/contact/1/p_t", ())
    with pytest.raises(ValueError):
        parse_file_measure("steps/last/x[a]")


def test_relative_binary(voiga: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """``--binary bin/voiga`` is relative to where post is run, not to each case's own
    folder, where the cases run (before, every case failed: FileNotFoundError)."""
    (tmp_path / "bin").mkdir()
    (tmp_path / "bin" / "voiga").symlink_to(voiga)
    study = write_study(tmp_path, 'base = "{hertz}"\n[grid]\ncontact.friction = [0.0]\n')
    monkeypatch.chdir(tmp_path)
    code = main(["study", str(study), "--out", "out", "--binary", "bin/voiga", "--no-progress", "--no-figures"])
    assert code == 0
    rows = list(csv.DictReader((tmp_path / "out" / "summary.csv").open()))
    assert [r["status"] for r in rows] == ["converged"]


def test_friction_study(voiga: Path, tmp_path: Path) -> None:
    """cases/studies/friction.toml (ironing m1 NN2.2, mu = 0, 0.1, 0.3, 0.5): every case
    converges, mu = 0 included; the die's mean horizontal force while sliding is the
    Coulomb mu |Py| (within the few % the slab's ploughing adds) and about 0 without
    friction; the table, Parquet and the figures are written."""
    out = tmp_path / "friction"
    code = main(["study", str(REPO / "cases" / "studies" / "friction.toml"), "--out", str(out),
                 "--binary", str(voiga), "--no-progress", "--repeats", "2"])
    assert code == 0
    rows = list(csv.DictReader((out / "summary.csv").open()))
    assert [float(r["contact.friction"]) for r in rows] == [0.0, 0.1, 0.3, 0.5]
    assert all(r["status"] == "converged" for r in rows)
    # --repeats 2: each case (under 3 CPU s) at least twice, at most 6 times
    assert all(2 <= int(r["repeats"]) <= 6 for r in rows)
    assert all(float(r["cpu_lo_s"]) <= float(r["cpu_s"]) <= float(r["cpu_hi_s"]) for r in rows)
    px = np.array([float(r["mean_px"]) for r in rows])
    py = np.array([float(r["mean_py"]) for r in rows])
    assert abs(px[0]) < 0.01 * abs(py[0])
    np.testing.assert_allclose(px[1:] / (np.array([0.1, 0.3, 0.5]) * np.abs(py[1:])), 1.0, atol=0.05)
    figures = {p.name for p in (out / "figures").glob("*.png")}
    assert {"mean_px-vs-contact.friction.png", "osc_py-vs-time.png"} <= figures
    import pyarrow.parquet as pq

    table = pq.read_table(out / "summary.parquet")
    assert table.column("contact.friction").to_pylist() == [0.0, 0.1, 0.3, 0.5]
    assert table.column("mean_px").to_pylist() == pytest.approx(list(px), rel=1e-15)


def test_output_closed_by_its_reader(tmp_path: Path) -> None:
    """``post study --list | head -1``: the reader has gone before post writes; post
    stops quietly (exit 141, as a process ended by SIGPIPE; before: a garbled
    "[Errno 32] Broken pipe" line on stderr)."""
    import subprocess
    import sys

    read, write = os.pipe()
    os.close(read)
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    try:
        proc = subprocess.run([sys.executable, "-m", "post", "study", str(REPO / "cases" / "studies" / "paper.toml"),
                               "--list"], stdout=write, stderr=subprocess.PIPE, text=True, cwd=tmp_path, env=env,
                              timeout=120)
    finally:
        os.close(write)
    assert proc.returncode == 141, proc.stderr
    assert proc.stderr == "", proc.stderr
