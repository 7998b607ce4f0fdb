"""Hertz (issue 4 acceptance): on m3, N2 and NN2.2 give the contact half-width and the peak
pressure within 2% of the analytic line contact computed from the simulated force (in the
reference configuration, post.hertz)."""
from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from conftest import REPO
from post.contact import pressure_field
from post.hertz import hertz_comparison
from post.reader import read_result


@pytest.mark.parametrize("layout", ["N2", "NN2.2"])
def test_hertz_m3(run, tmp_path: Path, layout: str) -> None:
    src = REPO / "cases" / "hertz"
    shutil.copy(src / "geometry.h5", tmp_path)
    case = tmp_path / f"m3-{layout}.nml"
    shutil.copy(src / case.name, case)
    res = run(case, "--quiet")
    assert res.returncode == 0, res.stderr
    h = hertz_comparison(read_result(tmp_path / f"m3-{layout}.h5"))
    # measured (nominal pressure at reference positions): N2 a +0.43%, p0 -0.52% (max -0.41%);
    # NN2.2 a +0.26%, p0 -0.46% (max -0.39%). In the current configuration the same runs
    # give a -1.4% / -1.5%, p0 +1.3% (the surface is compressed about 2% at the centre).
    assert abs(h.a_error) <= 0.02, h
    assert abs(h.p_max / h.p0 - 1.0) <= 0.02, h
    assert abs(h.p0_error) <= 0.02, h


def test_pressure_field_matches_gauss_points(run, tmp_path: Path) -> None:
    """The continuous penalty pressure (post, splipy) at the slave points equals the
    solver's per-point output, and it is zero where the points are not in contact."""
    src = REPO / "cases" / "hertz"
    shutil.copy(src / "geometry.h5", tmp_path)
    for layout in ("N2", "NN2.2"):
        case = tmp_path / f"m1-{layout}.nml"
        shutil.copy(src / case.name, case)
        assert run(case, "--quiet").returncode == 0
        res = read_result(tmp_path / f"m1-{layout}.h5")
        c = res.steps[-1].contact[0]
        x, p = pressure_field(res, params=c.xi_slave)
        assert np.allclose(x, c.x, rtol=0, atol=1e-12)
        assert np.allclose(p, c.p_n, rtol=1e-9, atol=1e-12 * c.p_n.max())
        assert c.p_n.max() > 0 and (p[c.state == 0] == 0).all()


@pytest.mark.parametrize("mesh", ["m1", "m2"])
def test_linear_cylinder_is_recognised_with_its_radius(run, tmp_path: Path, mesh: str) -> None:
    """A linear (L1) body's contact edge is a polygon inscribed in the cylinder: post hertz
    fits the circle through its vertices, so it recognises the cylinder and gets radius 1
    (a fit through the slave points gave 0.45 on m1 and 0.89 on m2, and on m1 refused the
    edge as 'not a cylinder', which stopped make paper's figures)."""
    src = REPO / "cases" / "hertz"
    shutil.copy(src / "geometry.h5", tmp_path)
    case = tmp_path / f"{mesh}-L1.nml"
    shutil.copy(src / case.name, case)
    assert run(case, "--quiet").returncode == 0
    h = hertz_comparison(read_result(tmp_path / f"{mesh}-L1.h5"))
    assert h.radius == pytest.approx(1.0, rel=1e-12), h
