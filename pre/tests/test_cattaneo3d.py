"""The 3D Cattaneo-Mindlin scene (``python -m pre cattaneo3d``, ``pre/cattaneo3d.py``): the
half ball shell is exact and right-handed, its knots are graded toward the lowest point
and symmetric about it along x, and the case holds the two phases the test needs (a
frictionless press, then the plane moved along x with friction)."""

from __future__ import annotations

import math
from pathlib import Path

import f90nml
import numpy as np
import pytest

from pre.__main__ import main
from pre.cattaneo3d import BODY, CONE, INNER, HalfBall, ball_case, ball_geometry, ball_knots, write_cattaneo3d
from pre.hertz import HertzCaseError
from pre.meshes import arc_angle
from pre.solids import half_ball_shell
from pre.volume import check_volume, jacobian


def test_half_shell_is_exact_and_right_handed() -> None:
    vol = half_ball_shell(2.0, 0.1, CONE)
    check_volume("ball", vol)
    rng = np.random.default_rng(3)
    xi, eta = rng.random(50), rng.random(50)
    for zeta, radius in ((1.0, 2.0), (0.0, 0.1)):
        x, jac = jacobian(vol, xi, eta, np.full(50, zeta))
        assert np.allclose(np.linalg.norm(x, axis=1), radius, rtol=1e-13)
        assert np.all(np.linalg.det(jac) > 0)
        assert np.all(x[:, 1] >= -1e-14) and np.all(x[:, 2] <= 1e-14)
    x, _ = jacobian(vol, np.array([0.0]), np.array([0.5]), np.array([1.0]))
    assert np.allclose(x[0], [0.0, 0.0, -2.0], atol=1e-14)   # the lowest point: the edge's middle
    ends, _ = jacobian(vol, np.array([0.5, 0.5]), np.array([0.0, 1.0]), np.array([1.0, 1.0]))
    polar = np.degrees(np.arccos(ends[:, 0] / 2.0))
    assert np.allclose(polar, [90.0 + CONE, 90.0 - CONE], atol=1e-12)


def test_half_shell_refuses_bad_values() -> None:
    for args in ((1.0, 1.0, 60.0), (1.0, 0.0, 60.0), (1.0, 0.5, 90.0)):
        with pytest.raises(ValueError, match="half ball shell"):
            half_ball_shell(*args)


def test_knots_graded_toward_the_lowest_point_and_symmetric() -> None:
    ball = HalfBall()
    k = ball_knots(ball, "m2")
    eta = np.array(k["knots_eta"])
    assert np.allclose(eta + eta[::-1], 1.0, atol=1e-14) and 0.5 in k["knots_eta"]
    angles = np.degrees(arc_angle(eta, 2 * math.radians(CONE))) - CONE   # from the lowest point
    sizes = np.diff(angles)
    fine = sizes[np.abs(angles[:-1] + sizes / 2) < 5.0]
    assert np.allclose(fine, fine[0], rtol=1e-9) and fine[0] < sizes.max() / 3
    assert all(0 < a < b < 1 for a, b in zip(k["knots_zeta"], k["knots_zeta"][1:], strict=False))


def test_case_has_a_frictionless_press_then_the_shear() -> None:
    ball = HalfBall(shear=2e-3, press_steps=4, shear_steps=6)
    case = ball_case(ball, "m1", "NN2.2")
    contact = case["contact"][0]
    assert contact["friction"] == [0.0, 0.3] and contact["rigid_ux"] == [0.0, 2e-3]
    assert "method" not in contact   # voiga's default on solids
    assert case["solver"]["n_steps"] == [4, 6]
    top = case["dirichlet"][0]
    assert top["face"] == "top" and top["uz"] == [-0.01, -0.01] and top["fix_x"] and top["fix_y"]
    faces = set(ball_geometry(ball)[BODY].faces.values())
    assert {d["face"] for d in case["dirichlet"]} <= faces and case["body"][0]["contact_face"] in faces
    assert ball_case(HalfBall(method="gpts"), "m1", "N2")["contact"][0]["method"] == "gpts"


def test_shear_estimate_grows_with_the_target() -> None:
    ball = HalfBall()
    s = [ball.shear_for(t) for t in (0.2, 0.5, 0.8)]
    assert 0 < s[0] < s[1] < s[2]
    assert HalfBall(shear=1e-3).plane_shear == 1e-3 and ball.plane_shear == s[1]


@pytest.mark.parametrize("bad", [dict(friction=0.0), dict(target=1.0), dict(shear=-1.0),
                                 dict(poisson_ratio=0.5), dict(press_steps=0), dict(indentation=0.2)])
def test_bad_values_are_refused(bad: dict) -> None:
    with pytest.raises(HertzCaseError):
        HalfBall(**bad).check()


def test_cli_writes_cases_and_refuses_to_overwrite(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["cattaneo3d", str(tmp_path), "--mesh", "m1", "--layout", "N2"]) == 0
    nml = f90nml.read(tmp_path / "m1-N2.nml")
    assert nml["contact"]["friction"] == [0.0, 0.3] and nml["case"]["scene"] == "cattaneo3d"
    assert "DOFs" in capsys.readouterr().out
    before = (tmp_path / "m1-N2.nml").read_bytes()
    assert main(["cattaneo3d", str(tmp_path), "--mesh", "m1", "--layout", "N2", "--shear", "1e-3"]) == 2
    assert "python -m pre cattaneo3d" in capsys.readouterr().err
    assert (tmp_path / "m1-N2.nml").read_bytes() == before
    assert write_cattaneo3d(HalfBall(shear=1e-3), ["m1"], ["N2"], tmp_path, force=True)[1][0].exists()
    assert INNER < 1
