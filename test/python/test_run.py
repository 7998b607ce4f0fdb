"""``python -m post run`` (what ``make run`` calls): solves, prints what it found, writes
the figures into --out and nothing next to the case; bad input exits 2."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from conftest import REPO


def _post(*args: str, voiga: Path, cwd: Path = REPO) -> subprocess.CompletedProcess:
    env = {**os.environ, "VOIGA_BIN": str(voiga), "PYTHONPATH": str(REPO)}
    return subprocess.run([sys.executable, "-m", "post", *args], capture_output=True, text=True,
                          timeout=300, cwd=cwd, env=env, stdin=subprocess.DEVNULL)


def test_run_hertz_into_an_output_folder(voiga_bin: Path, tmp_path: Path) -> None:
    case = REPO / "cases" / "hertz" / "m1-NN2.2.nml"
    before = sorted(p.name for p in case.parent.iterdir())
    out = tmp_path / "run"
    res = _post("run", str(case), "--out", str(out), "--quiet", voiga=voiga_bin)
    assert res.returncode == 0, res.stderr
    assert sorted(p.name for p in case.parent.iterdir()) == before  # nothing next to the input
    text = res.stdout
    assert "hertz m1 NN2.2: converged, 5 of 5 steps" in text
    assert "hertz vs analytic: P = " in text and "contact cylinder -> rigid" in text
    for name in ("m1-NN2.2.h5", "m1-NN2.2-deformed-000005.png", "m1-NN2.2-history.csv",
                 "m1-NN2.2-history.png", "m1-NN2.2-contact-000005.png",
                 "m1-NN2.2-hertz-000005.png", "m1-NN2.2.pvd"):
        assert (out / name).is_file(), name
        assert str(out / name) in text, name
    assert f"paraview {out / 'm1-NN2.2.pvd'}" in text
    # the staged case points at the committed geometry
    assert "geometry = '" in (out / "m1-NN2.2.nml").read_text()


def test_run_bad_input(voiga_bin: Path, tmp_path: Path) -> None:
    res = _post("run", str(tmp_path / "none.nml"), voiga=voiga_bin)
    assert res.returncode == 2 and "no case file" in res.stderr
    bad = tmp_path / "bad.nml"
    bad.write_text("&case\n  title = 'x', output = 'x.h5'\n/\n")
    res = _post("run", str(bad), "--out", str(tmp_path / "o"), voiga=voiga_bin)
    assert res.returncode == 2 and "no geometry" in res.stderr
    res = _post("run", str(REPO / "cases" / "hertz" / "m1-NN2.2.nml"), "--binary",
                str(tmp_path / "nothing"), voiga=voiga_bin)
    assert res.returncode == 2 and "no voiga program" in res.stderr


def test_run_propagates_a_refusal_and_writes_nothing(voiga_bin: Path, tmp_path: Path) -> None:
    """voiga refuses the case (its result exists, no --overwrite): `post run` exits with
    voiga's code 2 and prints no summary of the earlier result, writes no figure
    (issue 38, item 5: it printed the old summary and 'figures and files written')."""
    import shutil
    shutil.copy(REPO / "cases" / "hertz" / "geometry.h5", tmp_path)
    case = tmp_path / "m1-NN2.2.nml"
    shutil.copy(REPO / "cases" / "hertz" / "m1-NN2.2.nml", case)
    res = subprocess.run([str(voiga_bin), str(case), "--quiet"], capture_output=True, text=True,
                         timeout=300)
    assert res.returncode == 0, res.stderr
    before = sorted(p.name for p in tmp_path.iterdir())
    res = _post("run", str(case), voiga=voiga_bin, cwd=tmp_path)
    assert res.returncode == 2, res.stdout + res.stderr
    assert "exists" in res.stderr and "--overwrite" in res.stderr      # voiga's own message
    assert "voiga exited with 2 (its message is above); no summary, no figures written" in res.stderr
    assert "converged, 5 of 5 steps" not in res.stdout and "written" not in res.stdout, res.stdout
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    # a wrong set-up refused: the same (the rigid plane's normal turned into the cylinder)
    text = case.read_text()
    assert "rigid_normal = 0.0, 1.0" in text
    case.write_text(text.replace("rigid_normal = 0.0, 1.0", "rigid_normal = 0.0, -1.0"))
    res = _post("run", str(case), "--out", str(tmp_path / "out"), voiga=voiga_bin, cwd=tmp_path)
    assert res.returncode == 2 and "rigid_normal" in res.stderr, res.stderr
    assert not list((tmp_path / "out").glob("*.png")) and not list((tmp_path / "out").glob("*.h5"))
