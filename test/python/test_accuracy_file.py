"""The contact-zone indicator voiga writes (``contact/<k>/accuracy``, src/model/accuracy.f90)
against the same measures computed in Python from the slave points
(post/indicator.py): the two implementations agree on every zone and edge of every
step, on a rigid master (hertz) and between deformable bodies (rings)."""
from __future__ import annotations

import math
import re
import shutil
import subprocess
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
