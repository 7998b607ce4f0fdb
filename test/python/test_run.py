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
