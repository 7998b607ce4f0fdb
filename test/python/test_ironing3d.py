"""The 3D ironing scene through the command line (``pre ironing3d``, voiga, ``post
ironing``): m1 N2 with a short sliding phase runs to the end, the die drags the slab
along its path (F_x > 0, pushed down: F_z < 0) with |F_x / F_z| near mu (every point
slips, plus the ploughing of the pile-up ahead of the die), and the measures read; a 2D
ironing result reads with the 2D study's measures."""
from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def test_ironing3d_m1_runs_and_post_reads_it(voiga_bin: Path, tmp_path: Path) -> None:
    out = tmp_path / "i"
    subprocess.run(["python3", "-m", "pre", "ironing3d", str(out), "--mesh", "m1", "--layout", "N2",
                    "--steps", "3", "10"], check=True, capture_output=True, cwd=REPO)
    res = subprocess.run([str(voiga_bin), str(out / "m1-N2.nml"), "--quiet"], capture_output=True, text=True,
                         timeout=300, env={"OMP_NUM_THREADS": "1"})
    assert res.returncode == 0, res.stderr
    post = subprocess.run(["python3", "-m", "post", "ironing", str(out / "m1-N2.h5"), "--json"],
                          capture_output=True, text=True, cwd=REPO)
    assert post.returncode == 0, post.stderr
    m = json.loads(post.stdout.splitlines()[-2])
    assert m["steps"] == 13 and m["mean_t"] > 0 > m["mean_n"]
    assert m["ratio"] == pytest.approx(0.3, abs=0.03)
    assert 0 < m["osc_n"] < 0.2 and 0 < m["osc_t"] < 0.5
    assert (out / "m1-N2-ironing.png").stat().st_size > 0


def test_post_ironing_reads_a_2d_result(voiga_bin: Path, ironing_copy: Path) -> None:
    """The committed 2D ironing m1 N2: the die's reactions, the measures of the 2D study
    (post.measures.ironing_measures) under their names with ``_t`` and ``_n``."""
    res = subprocess.run([str(voiga_bin), str(ironing_copy), "--quiet"], capture_output=True, text=True,
                         timeout=300, env={"OMP_NUM_THREADS": "1"})
    assert res.returncode == 0, res.stderr
    h5 = ironing_copy.parent / "m1-N2.h5"   # the case names its output
    post = subprocess.run(["python3", "-m", "post", "ironing", str(h5), "--json", "--no-figure"],
                          capture_output=True, text=True, cwd=REPO)
    assert post.returncode == 0, post.stderr
    m = json.loads(post.stdout.splitlines()[-1])
    from post.measures import ironing_measures
    from post.reader import read_result

    ref = ironing_measures(read_result(h5))
    assert m["osc_t"] == pytest.approx(ref["osc_px"]) and m["osc_n"] == pytest.approx(ref["osc_py"])
    assert "2D ironing" in post.stdout
