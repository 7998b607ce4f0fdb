"""Rigid obstacle curves (``pre.geometry.obstacle*``, ``[[curve]]`` in specs): exact
shapes, the orientation the solver expects (the obstacle on the left of the curve,
outward normal ``(a_y, -a_x)/|a|``), the checks, and the geometry file's ``/curves``."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from splipy import curve_factory

from pre.__main__ import main
from pre.geometry import check_curve, obstacle, obstacle_arc, obstacle_polyline
from pre.h5io import read_curves
from pre.nurbs import Curve, curve_to_splipy

T = np.linspace(0.0, 1.0, 501)


def _points_normals(curve: Curve) -> tuple[np.ndarray, np.ndarray]:
    spline = curve_to_splipy(curve)
    x = np.asarray(spline(T))[:, :2]
    a = np.asarray(spline.derivative(T))[:, :2]
    return x, np.column_stack([a[:, 1], -a[:, 0]]) / np.linalg.norm(a, axis=1)[:, None]


@pytest.mark.parametrize("angles", [[180, 360], [240, 300], [300, 240], [-45, 45]])
@pytest.mark.parametrize("side", ["inside", "outside"])
def test_arc_on_its_circle_with_the_solver_normal(angles: list[float], side: str) -> None:
    """On the circle to 1e-12; the outward normal points away from the centre for a
    disc (``inside``) and towards it for the surrounding material (``outside``)."""
    centre = np.array([0.5, 2.0])
    c = obstacle_arc(centre, 1.5, angles, side)
    x, n = _points_normals(c)
    r = x - centre
    assert np.abs(np.linalg.norm(r, axis=1) - 1.5).max() < 1e-12
    radial = r / np.linalg.norm(r, axis=1)[:, None]
    assert np.allclose(n, radial if side == "inside" else -radial, atol=1e-12)
    assert c.knots[0] == 0.0 and c.knots[-1] == 1.0


@pytest.mark.parametrize("side, up", [("right", 1.0), ("left", -1.0)])
def test_polyline_side(side: str, up: float) -> None:
    """A flat die profile drawn left to right with rounded ends: the obstacle below it
    (``right`` of the travel) has its normal up on the flat, above it (``left``) down;
    the fillets are exact arcs."""
    pts = [[-2.0, 1.0], [-1.0, 0.0], [1.0, 0.0], [2.0, 1.0]]
    c = obstacle_polyline(pts, side, {0: -1.0, 2: -1.0})
    x, n = _points_normals(c)
    flat = np.abs(x[:, 1]) < 1e-12
    assert flat.sum() > 10
    assert np.allclose(n[flat], [0.0, up], atol=1e-12)
    # the fillets are quarter circles about (-2, 0) and (2, 0) with radius 1
    for cx in (-2.0, 2.0):
        near = np.sign(x[:, 0]) == np.sign(cx)
        near &= np.abs(x[:, 0]) > 1.0 + 1e-9
        assert np.allclose(np.hypot(x[near, 0] - cx, x[near, 1]), 1.0, atol=1e-12)


def test_splipy_curves_and_checks() -> None:
    """Any splipy curve (here a 3D line in z = 0) becomes an obstacle; a curve out of
    plane or one that stops is refused with its name."""
    line = curve_factory.line((0.0, 0.0, 0.0), (2.0, 0.0, 0.0))
    c = obstacle(line, "right")
    _, n = _points_normals(c)
    assert np.allclose(n, [0.0, 1.0])
    with pytest.raises(ValueError, match="not planar"):
        obstacle(curve_factory.line((0.0, 0.0, 0.0), (2.0, 0.0, 1.0)), "left")
    with pytest.raises(ValueError, match="side must be"):
        obstacle(line, "up")
    stopped = Curve(degree=2, knots=[0, 0, 0, 1, 1, 1], control_points=[[0, 0], [0, 0], [1, 0]],
                    weights=[1, 1, 1])
    with pytest.raises(ValueError, match="curve 'p'.*stops"):
        check_curve("p", stopped)


def test_spec_curve_written_to_the_geometry(tmp_path: Path) -> None:
    spec = tmp_path / "s.toml"
    spec.write_text("""
[[body]]
name = "block"
shape = "rectangle"
x = [0.0, 4.0]
y = [-1.0, 0.0]
contact_edge = "top"

[[curve]]
name = "roller"
shape = "arc"
centre = [2.0, 1.0]
radius = 1.0
angles = [180.0, 360.0]

[[curve]]
name = "die"
shape = "polyline"
points = [[0.0, 2.0], [1.0, 1.0], [3.0, 1.0]]
side = "left"
""")
    assert main(["geometry", str(spec)]) == 0
    curves = read_curves(tmp_path / "s-geometry.h5")
    assert list(curves) == ["roller", "die"]
    x, _ = _points_normals(curves["roller"])
    assert np.abs(np.hypot(x[:, 0] - 2.0, x[:, 1] - 1.0) - 1.0).max() < 1e-12


@pytest.mark.parametrize("text,message", [
    ("[[curve]]\nname = 'c'\nshape = 'spiral'\n", "unknown shape"),
    ("[[curve]]\nname = 'c'\nshape = 'polyline'\npoints = [[0, 0], [1, 0]]\n", "missing 'side'"),
    ("[[curve]]\nname = 'c'\nshape = 'arc'\ncentre = [0, 0]\nradius = 1\nangles = [0, 90]\nx = 1\n",
     "unknown key"),
    ("[[curve]]\nname = 'c'\nshape = 'arc'\ncentre = [0, 0]\nradius = -1\nangles = [0, 90]\n",
     "radius must be > 0"),
    ("[[curve]]\nname = 'c'\nshape = 'polyline'\npoints = [[0, 0], [0, 0]]\nside = 'left'\n",
     "coincide"),
])
def test_bad_curves_exit_2(tmp_path: Path, text: str, message: str,
                           capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "bad.toml"
    spec.write_text("[[body]]\nname = 'a'\nshape = 'rectangle'\nx = [0, 1]\ny = [0, 1]\n" + text)
    assert main(["geometry", str(spec)]) == 2
    err = capsys.readouterr().err
    assert message in err and "curve 'c'" in err and len(err.strip().splitlines()) == 1
