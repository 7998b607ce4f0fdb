"""docs/tutorial3d.md, run as written: every fenced ``sh`` block, verbatim and in order, in
one shell in a temporary folder (with the built voiga on the PATH and this checkout's
``pre`` and ``post`` importable), then the output and files the tutorial quotes are
checked."""
from __future__ import annotations

import math
import os
import re
import subprocess
from pathlib import Path

import h5py

from conftest import REPO
from test_tutorial import sh_blocks

TUTORIAL = REPO / "docs" / "tutorial3d.md"


PLAIN = re.compile(r"^```\n(.*?)^```", re.S | re.M)


def quoted_after(text: str, marker: str, k: int = 0) -> list[str]:
    """The lines of the ``k``-th plain fenced block (no language) after ``marker``."""
    return PLAIN.findall(text[text.index(marker) + len(marker):])[k].strip().splitlines()


def test_the_3d_tutorial_runs_as_written(voiga_bin: Path, tmp_path: Path) -> None:
    text = TUTORIAL.read_text()
    blocks = sh_blocks(text)
    assert len(blocks) == 5, "the tutorial lost (or gained) commands"
    script = "set -euo pipefail\n" + "\n".join(blocks)
    env = {**os.environ, "PATH": f"{voiga_bin.parent}{os.pathsep}{os.environ['PATH']}",
           "PYTHONPATH": str(REPO)}
    run = subprocess.run(["bash", "-c", script], cwd=tmp_path, env=env, capture_output=True,
                         text=True, timeout=600, stdin=subprocess.DEVNULL)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    out = run.stdout.splitlines()
    folder = tmp_path / "shell-tutorial"
    assert "warning" not in run.stderr, run.stderr

    # section 2: the files, the &body the tutorial shows, the --check lines
    for name in ("shell-geometry.h5", "shell.nml", "shell-vo-geometry.h5", "shell-vo.nml"):
        assert (folder / name).is_file(), name
    body = "\n".join(quoted_after(text, "holds the layout and the mesh:")) + "\n"
    assert body in (folder / "shell.nml").read_text()
    for line in quoted_after(text, "per direction, 3 x 10 x 10 x 5:"):
        assert line in out, line

    # section 3: the run converged in one step and one iteration
    converged = [line for line in out if line.startswith("converged:")]
    assert len(converged) == 2 and all(line.startswith("converged: 1 steps (1 substeps, 0 cuts), 1 Newton "
                                                       "iterations,") for line in converged), converged
    for result in ("shell.h5", "shell-vo.h5"):
        with h5py.File(folder / result) as f:
            assert f.attrs["status"] == b"converged" and int(f.attrs["dimension"]) == 3

    # sections 4 and 5: the lines lame.py prints, the layer's DOFs, the contact face
    quotes = [quoted_after(text, "python3 lame.py shell.h5\n```\n"),
              quoted_after(text, "python3 lame.py shell-vo.h5\n```\n"),
              quoted_after(text, "python3 lame.py shell-vo.h5\n```\n", 1)]
    assert [len(q) for q in quotes] == [2, 1, 2], quotes
    for line in sum(quotes, []):
        assert line in out, (line, out)
    # post summary's reactions: the pressure on each quarter disc, p pi a^2 / 4, normal
    # to each plane (the quoted lines; their round-off components are not compared)
    for plane in ("start", "end", "equator"):
        line = next(x for x in out if f"reaction on shell/{plane}:" in x)
        values = [float(v) for v in line.split("(")[1].split(")")[0].split(",")]
        normal = {"start": 1, "end": 0, "equator": 2}[plane]
        assert abs(values[normal] + math.pi / 4) < 1e-5, line
    assert (folder / "shell.pvd").is_file()
    assert "contact_face = 'inner'" in (folder / "shell-vo.nml").read_text()
    assert "layer_degree = 3" in (folder / "shell-vo.nml").read_text()
