"""Coarse scene patches: exact arcs, straight edges, touching points, names."""

from __future__ import annotations

import numpy as np
import pytest

from pre.h5io import read_geometry, write_geometry
from pre.nurbs import EDGE_KEYS, Patch, evaluate_patch
from pre.scenes import HERTZ, IRONING_DIE, RINGS_LOWER, RINGS_UPPER, scene_bodies

T = np.linspace(0.0, 1.0, 1000)
ONES, ZEROS = np.ones_like(T), np.zeros_like(T)


def edge_points(patch: Patch, key: str) -> np.ndarray:
    xi, eta = {"xi0": (ZEROS, T), "xi1": (ONES, T), "eta0": (T, ZEROS), "eta1": (T, ONES)}[key]
    return evaluate_patch(patch, xi, eta)


def assert_on_circle(pts: np.ndarray, centre: tuple[float, float], r: float) -> None:
    d = np.hypot(pts[:, 0] - centre[0], pts[:, 1] - centre[1])
    assert np.abs(d - r).max() < 1e-12


def assert_straight(pts: np.ndarray, a: tuple[float, float], b: tuple[float, float]) -> None:
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = b - a
    cross = (pts[:, 0] - a[0]) * d[1] - (pts[:, 1] - a[1]) * d[0]
    assert np.abs(cross).max() < 1e-12 * np.hypot(*d)
    s = (pts - a) @ d / (d @ d)
    assert s.min() > -1e-12 and s.max() < 1 + 1e-12
    np.testing.assert_allclose(pts[[0, -1]], [a, b], atol=1e-12)


def angles(pts: np.ndarray, centre: tuple[float, float]) -> np.ndarray:
    return np.unwrap(np.arctan2(pts[:, 1] - centre[1], pts[:, 0] - centre[0]))


def test_ironing_die() -> None:
    die = scene_bodies("ironing")["die"]
    c = IRONING_DIE["centre"]
    assert die.edges == {"xi0": "left", "xi1": "right", "eta0": "inner", "eta1": "outer"}
    assert die.degree == (2, 1)
    np.testing.assert_array_equal(die.knots_xi, [0, 0, 0, .5, .5, 1, 1, 1])
    np.testing.assert_array_equal(die.knots_eta, [0, 0, 1, 1])
    assert_on_circle(edge_points(die, "eta1"), c, 3.0)
    assert_on_circle(edge_points(die, "eta0"), c, 2.0)
    p = edge_points(die, "eta1")
    # lower half circle travelled from 180 to 360 deg: x increases, y <= centre
    assert np.all(np.diff(p[:, 0]) > 0) and np.all(p[:, 1] <= c[1] + 1e-12)
    np.testing.assert_allclose(p[[0, -1]], [[-0.5, 3.0], [5.5, 3.0]], atol=1e-15)
    assert_straight(edge_points(die, "xi0"), (0.5, 3.0), (-0.5, 3.0))
    assert_straight(edge_points(die, "xi1"), (4.5, 3.0), (5.5, 3.0))
    # lowest outer point touches the slab top at (2.5, 0)
    np.testing.assert_allclose(evaluate_patch(die, [0.5], [1.0])[0], [2.5, 0.0], atol=1e-15)
    assert edge_points(die, "eta1")[:, 1].min() >= -1e-15


def test_ironing_slab() -> None:
    slab = scene_bodies("ironing")["slab"]
    assert slab.edges == {"xi0": "left", "xi1": "right", "eta0": "bottom", "eta1": "top"}
    assert slab.degree == (1, 1)
    assert_straight(edge_points(slab, "eta1"), (0, 0), (9, 0))
    assert_straight(edge_points(slab, "eta0"), (0, -3), (9, -3))
    assert_straight(edge_points(slab, "xi0"), (0, -3), (0, 0))
    assert_straight(edge_points(slab, "xi1"), (9, -3), (9, 0))


def test_hertz() -> None:
    cyl = scene_bodies("hertz")["cylinder"]
    c = HERTZ["centre"]
    assert cyl.edges == {"xi0": "symmetry", "xi1": "top", "eta0": "inner", "eta1": "outer"}
    np.testing.assert_array_equal(cyl.knots_xi, [0, 0, 0, 1, 1, 1])
    assert_on_circle(edge_points(cyl, "eta1"), c, 1.0)
    assert_on_circle(edge_points(cyl, "eta0"), c, 0.05)
    assert_straight(edge_points(cyl, "xi0"), (0, -0.05), (0, -1))
    assert_straight(edge_points(cyl, "xi1"), (0.05, 0), (1, 0))
    np.testing.assert_allclose(evaluate_patch(cyl, [0.0], [1.0])[0], [0, -1], atol=1e-15)
    assert edge_points(cyl, "eta1")[:, 1].min() >= -1 - 1e-15  # rigid flat y = -1


@pytest.mark.parametrize("name, spec", [("upper", RINGS_UPPER), ("lower", RINGS_LOWER)])
def test_rings(name: str, spec: dict) -> None:
    ring = scene_bodies("rings")[name]
    c, ri, ro = spec["centre"], spec["r_in"], spec["r_out"]
    assert ring.edges == {"xi0": "bottom", "xi1": "top", "eta0": "inner", "eta1": "outer"}
    np.testing.assert_array_equal(ring.knots_xi, [0, 0, 0, .5, .5, 1, 1, 1])
    assert_on_circle(edge_points(ring, "eta1"), c, ro)
    assert_on_circle(edge_points(ring, "eta0"), c, ri)
    a = angles(edge_points(ring, "eta1"), c)
    assert np.all(np.diff(a) > 0)
    assert a[0] == pytest.approx(-np.pi / 2) and a[-1] == pytest.approx(np.pi / 2)
    assert np.all(edge_points(ring, "eta1")[:, 0] >= -1e-15)  # right half
    assert_straight(edge_points(ring, "xi0"), (0, c[1] - ri), (0, c[1] - ro))
    assert_straight(edge_points(ring, "xi1"), (0, c[1] + ri), (0, c[1] + ro))


def test_rings_touch_at_origin() -> None:
    b = scene_bodies("rings")
    np.testing.assert_allclose(evaluate_patch(b["upper"], [0.0], [1.0])[0], [0, 0], atol=1e-15)
    np.testing.assert_allclose(evaluate_patch(b["lower"], [1.0], [1.0])[0], [0, 0], atol=1e-15)


def jacobian_sign(patch: Patch) -> np.ndarray:
    """Sign of det(dX/dxi, dX/deta) at interior points (finite differences)."""
    s = np.linspace(0.1, 0.9, 9)
    xi, eta = np.meshgrid(s, s)
    xi, eta = xi.ravel(), eta.ravel()
    h = 1e-6
    dx = evaluate_patch(patch, xi + h, eta) - evaluate_patch(patch, xi - h, eta)
    de = evaluate_patch(patch, xi, eta + h) - evaluate_patch(patch, xi, eta - h)
    return np.sign(dx[:, 0] * de[:, 1] - dx[:, 1] * de[:, 0])


@pytest.mark.parametrize("scene, body, sign", [
    ("ironing", "die", -1), ("ironing", "slab", 1), ("hertz", "cylinder", -1),
    ("rings", "upper", -1), ("rings", "lower", -1)])
def test_orientation_is_documented(scene: str, body: str, sign: int) -> None:
    """The brief's directions (xi along the contact edge as specified, eta = 1
    on it) make the arc bodies left-handed (det J < 0); docs/pre.md says so
    and the solver must use |det J|. This test pins it down."""
    assert np.all(jacobian_sign(scene_bodies(scene)[body]) == sign)


def test_geometry_file_round_trip(tmp_path) -> None:
    bodies = scene_bodies("rings")
    path = tmp_path / "g.h5"
    write_geometry(path, "rings", bodies)
    attrs, back = read_geometry(path)
    assert attrs["scene"] == "rings" and attrs["units"] == "mm, N"
    assert list(back) == ["upper", "lower"]  # creation order kept
    for name, p in bodies.items():
        q = back[name]
        assert q.degree == p.degree and q.edges == p.edges
        for key in ("knots_xi", "knots_eta", "control_points", "weights"):
            np.testing.assert_array_equal(getattr(q, key), getattr(p, key))
    assert set(EDGE_KEYS) == set(back["upper"].edges)
