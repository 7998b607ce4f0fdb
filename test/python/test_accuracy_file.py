"""The contact-zone indicator voiga writes (``contact/<k>/accuracy``, src/model/accuracy.f90)
against the same measures computed in Python from the slave points
(post/indicator.py): the two implementations agree on every zone and edge of every
step, on a rigid master (hertz) and between deformable bodies (rings)."""
from __future__ import annotations

import math
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import REPO
from post.indicator import measure_pair
from post.reader import read_result


def solved(voiga_bin: Path, tmp_path: Path, scene: str, case: str) -> Path:
    """The committed case ``scene/case`` (voiga's default contact settings for hertz)
    solved in ``tmp_path``; its result file."""
    for f in (REPO / "cases" / scene).glob("*.h5"):
        shutil.copy(f, tmp_path)
    text = (REPO / "cases" / scene / case).read_text()
    if scene == "hertz":
        text = re.sub(r"\n *(penalty_normal|method) = [^\n]*", "", text)
    (tmp_path / case).write_text(text)
    subprocess.run([str(voiga_bin), case, "--quiet"], cwd=tmp_path, check=True, capture_output=True, timeout=600)
    return tmp_path / Path(case).with_suffix(".h5")


@pytest.mark.parametrize(("scene", "case"), [("hertz", "m4-NN2.2.nml"), ("rings", "m1-NN2.1.nml")])
def test_recorded_equals_computed(voiga_bin: Path, tmp_path: Path, scene: str, case: str) -> None:
    result = read_result(solved(voiga_bin, tmp_path, scene, case))
    zones = 0
    for k, st in enumerate(result.steps):
        for pair, c in enumerate(st.contact):
            assert c.accuracy is not None
            recorded = measure_pair(result, k, pair)
            computed = measure_pair(result, k, pair, computed=True)
            assert len(recorded) == len(computed) == int(c.accuracy["zones"])
            for r, p in zip(recorded, computed, strict=True):
                zones += 1
                assert (r.n_points, len(r.edges)) == (p.n_points, len(p.edges))
                assert r.xi_range == pytest.approx(p.xi_range, abs=1e-14)
                assert r.half_width == pytest.approx(p.half_width, rel=1e-12)
                assert r.elements_across == pytest.approx(p.elements_across, rel=1e-12)
                for a, b in zip(r.edges, p.edges, strict=True):
                    assert a.side == b.side
                    assert a.xi == pytest.approx(b.xi, rel=1e-9, abs=1e-12)
                    assert a.h_normal == pytest.approx(b.h_normal, rel=1e-9)
                    assert a.bracket == pytest.approx(b.bracket, rel=1e-12)
                    if math.isnan(b.h_tangent) or math.isinf(b.raw):
                        assert (math.isnan(a.h_tangent), math.isinf(a.raw)) == (math.isnan(b.h_tangent),
                                                                                 math.isinf(b.raw))
                        continue
                    assert a.h_tangent == pytest.approx(b.h_tangent, rel=1e-12)
                    # a least-squares fit (QR here, SVD in numpy): equal to the round-off
                    assert a.raw == pytest.approx(b.raw, rel=1e-7, abs=1e-12)
    assert zones >= len(result.steps)


def test_face_estimate_tracks_hertz3d(voiga_bin: Path, tmp_path: Path) -> None:
    """On a face the indicator measures every line of slave points (constant eta,
    constant xi) as an edge and sums them: on the polar Hertz sphere p2 N2 the face's
    estimate at every step is within a factor 2.5 of the whole L2 error against Hertz
    (measured L2 / estimate 0.97-2.1 over the five steps; mostly above 1: the interior's
    error is in the L2, not in the estimate; docs/contact-accuracy.md); the run warns of
    step 1."""
    from post.hertz3d import hertz3d_comparison

    subprocess.run([sys.executable, "-m", "pre", "hertz3d", str(tmp_path), "--grid", "polar", "--mesh", "p2",
                    "--layout", "N2"], cwd=REPO, check=True, capture_output=True, timeout=300)
    run = subprocess.run([str(voiga_bin), "p2-N2.nml"], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    (warning,) = [line for line in run.stderr.splitlines() if "warning" in line]
    assert "estimated pressure error" in warning and "at step 1 " in warning and "knots_xi" in warning
    result = read_result(tmp_path / "p2-N2.h5")
    for st in result.steps:
        estimate = float(st.contact[0].accuracy["pair_estimate"])
        l2 = hertz3d_comparison(result, step=st.step).error.l2
        assert 0.8 * estimate < l2 < 2.5 * estimate, (st.step, estimate, l2)
    # `post indicator` prints the face's estimate from the file (step 1: the largest)
    shown = subprocess.run([sys.executable, "-m", "post", "indicator", "p2-N2.h5"], cwd=tmp_path, text=True,
                           capture_output=True, env={**os.environ, "PYTHONPATH": str(REPO)})
    first = float(result.steps[0].contact[0].accuracy["pair_estimate"])
    assert shown.returncode == 0 and f"step 1: estimated edge error {first:.2%}" in shown.stdout, shown
