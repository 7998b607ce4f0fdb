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
from pre.cattaneo3d import (
    BODY,
    CONE,
    INNER,
    PHI_ELEMENTS,
    HalfBall,
    ball_case,
    ball_geometry,
    ball_knots,
    write_cattaneo3d,
)
from pre.hertz import EDGE_BAND, HertzCaseError
from pre.hertz3d import POLAR_MESHES
from pre.meshes import arc_angle
from pre.solids import half_ball_shell, polar_half_ball
from pre.volume import check_volume, enclosed_volume, jacobian


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


def test_polar_half_ball_is_exact_and_right_handed() -> None:
    """The polar half ball: its sphere face on the sphere, y >= 0, z <= 0, det J > 0 inside,
    the plane y = 0 in two faces (x >= 0 and x <= 0), the lowest point the edge eta = 0."""
    vol = polar_half_ball(2.0)
    check_volume("ball", vol)
    rng = np.random.default_rng(4)
    xi, eta = rng.random(50), rng.random(50)
    x, jac = jacobian(vol, xi, eta, np.ones(50))
    assert np.allclose(np.linalg.norm(x, axis=1), 2.0, rtol=1e-13)
    assert np.all(x[:, 1] >= -1e-14) and np.all(x[:, 2] <= 1e-14)
    assert np.all(np.linalg.det(jacobian(vol, xi, eta, rng.random(50))[1]) > 0)
    for end, sign in ((0.0, 1.0), (1.0, -1.0)):
        side, _ = jacobian(vol, np.full(50, end), eta, rng.random(50))
        assert np.abs(side[:, 1]).max() < 1e-14 and np.all(sign * side[:, 0] >= -1e-14)
    low, _ = jacobian(vol, xi, np.zeros(50), np.ones(50))
    assert np.allclose(low, [0.0, 0.0, -2.0], atol=1e-14)
    assert enclosed_volume(vol) == pytest.approx(2.0 * math.pi * 8.0 / 6.0, rel=1e-12)


def test_polar_knots_split_both_edges() -> None:
    """On the polar grid theta's spans over 0.9 .. 1.1 of both expected edges (a, and the
    stick zone's c = a (1 - target)^(1/3)) are split; phi's C0 knot at 90 degrees is not
    inserted again (it would cut the body); the symmetry plane's two faces are held in y."""
    ball = HalfBall(grid="polar")
    knots = ball_knots(ball, "p2")
    assert 0.5 not in knots["knots_xi"] and len(knots["knots_xi"]) == 2 * PHI_ELEMENTS - 2
    theta = np.concatenate([[0.0], arc_angle(np.array(knots["knots_eta"])), [math.pi / 2]])
    sizes = np.diff(theta)
    a = ball.half_width / ball.radius
    for r in (a, a * (1 - ball.target) ** (1 / 3)):
        lo, hi = (math.asin(f * r) for f in EDGE_BAND)
        inside = (theta[1:] > lo) & (theta[:-1] < hi)
        assert inside.sum() >= 2 * POLAR_MESHES["p2"][3]
        assert sizes[inside].max() < 0.3 * sizes[: int(np.argmax(inside))].max()
    case = ball_case(ball, "p2", "N2")
    assert [d["face"] for d in case["dirichlet"] if d.get("fix_y") and not d.get("fix_z")] == \
        ["symmetry_y", "symmetry_y_back"]
    with pytest.raises(HertzCaseError, match="polar grid's meshes"):
        ball_knots(ball, "m1")
    with pytest.raises(HertzCaseError, match="cartesian grid's meshes"):
        ball_knots(HalfBall(), "p1")
