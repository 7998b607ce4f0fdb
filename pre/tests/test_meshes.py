"""Layout names, uniform and graded knots, the arc-parameter inversion."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pre.cases import RINGS_A_EXP, rings_m1_angles, rings_m1_breaks, rings_xi_knots
from pre.layouts import parse_layout
from pre.meshes import (
    HERTZ_A_EXP,
    arc_angle,
    arc_parameter,
    hertz_eta_knots,
    hertz_m1_angles,
    hertz_theta_c,
    hertz_xi_knots,
    nest,
    uniform_interior,
)
from pre.nurbs import evaluate_patch
from pre.scenes import RINGS_LOWER, RINGS_UPPER, scene_bodies


@pytest.mark.parametrize("name, expect", [
    ("N2", ("nurbs", 2, 2, 0, 0)), ("N6", ("nurbs", 6, 2, 0, 0)),
    ("NN4", ("nurbs", 2, 2, 4, 0)), ("NN2.1", ("nurbs", 2, 2, 2, 1)),
    ("NN3.2", ("nurbs", 2, 2, 3, 2)), ("L1", ("linear", 1, 1, 0, 0))])
def test_parse_layout(name: str, expect: tuple) -> None:
    lay = parse_layout(name)
    assert (lay.basis, lay.degree_xi, lay.degree_eta, lay.layer_degree, lay.layer_elevations) == expect


@pytest.mark.parametrize("bad", ["N1", "NN1", "X2", "NN2.", "L2", "n2"])
def test_parse_layout_rejects(bad: str) -> None:
    with pytest.raises(ValueError):
        parse_layout(bad)


def test_arc_parameter_inverts_the_hertz_arc() -> None:
    """Evaluate the exact arc (splipy) at arc_parameter(phi): its angle from
    the lowest point must be phi."""
    cyl = scene_bodies("hertz")["cylinder"]
    phi = np.linspace(0.0, math.pi / 2, 1000)
    t = arc_parameter(phi)
    assert t[0] == pytest.approx(0.0, abs=1e-15) and t[-1] == pytest.approx(1.0, abs=1e-15)
    p = evaluate_patch(cyl, np.clip(t, 0.0, 1.0), np.ones_like(t))
    got = np.arctan2(p[:, 0], -p[:, 1])
    assert np.abs(got - phi).max() < 1e-12
    assert np.abs(arc_angle(t) - phi).max() < 1e-12


def test_arc_parameter_other_sweeps() -> None:
    """The formula holds for any single arc of sweep < pi (checked on the
    first quarter of the die, parameter in [0, 0.5], via the general sweep)."""
    for sweep in (0.3, 1.0, math.pi / 2, 2.5):
        phi = np.linspace(0, sweep, 50)
        assert np.abs(arc_angle(arc_parameter(phi, sweep), sweep) - phi).max() < 1e-12
    die = scene_bodies("ironing")["die"]
    phi = np.linspace(0.0, math.pi / 2, 200)
    t = 0.5 * np.clip(arc_parameter(phi), 0, 1)  # first quarter is xi in [0, 0.5]
    p = evaluate_patch(die, t, np.ones_like(t)) - np.array([2.5, 3.0])
    got = np.arctan2(-p[:, 1], -p[:, 0])  # angle travelled from 180 deg
    assert np.abs(got - phi).max() < 1e-12


def test_hertz_m1_grading() -> None:
    tc = hertz_theta_c()
    assert tc == pytest.approx(math.asin(1.5 * HERTZ_A_EXP))
    ang = np.concatenate([[0.0], hertz_m1_angles(), [math.pi / 2]])
    assert len(ang) == 10  # 9 elements
    d = np.diff(ang)
    np.testing.assert_allclose(d[:5], tc / 5, rtol=1e-13)
    np.testing.assert_allclose(d[5:], (math.pi / 2 - tc) / 4, rtol=1e-13)
    # the knots are those angles in the arc's parameter
    np.testing.assert_allclose(arc_angle(hertz_xi_knots(1)), ang[1:-1], rtol=0, atol=1e-13)


@pytest.mark.parametrize("level", range(1, 7))
def test_hertz_nested(level: int) -> None:
    k = hertz_xi_knots(level)
    assert len(k) == 9 * 2 ** (level - 1) - 1
    assert np.all(np.diff(k) > 0) and k[0] > 0 and k[-1] < 1
    if level > 1:
        assert np.all(np.isin(hertz_xi_knots(level - 1), k))  # exact nesting
    # each m1 span split into equal parameter spans
    full = np.concatenate([[0.0], k, [1.0]])
    spans = np.diff(full).reshape(9, -1)
    np.testing.assert_allclose(spans, spans[:, :1].repeat(spans.shape[1], axis=1), rtol=1e-12)


@pytest.mark.parametrize("n_el", [47, 48])
def test_hertz_radial(n_el: int) -> None:
    k = hertz_eta_knots(n_el)
    assert len(k) == n_el - 1 and np.all(np.diff(k) > 0) and 0 < k[0] and k[-1] < 1
    h = np.diff(np.concatenate([[0.0], k, [1.0]])) * 0.95  # radial sizes
    assert h[-1] == pytest.approx(0.005, rel=1e-12)  # smallest, at the outer surface
    ratio = h[:-1] / h[1:]
    np.testing.assert_allclose(ratio, ratio[0], rtol=1e-9)  # geometric
    assert ratio[0] > 1


def test_uniform_and_nest() -> None:
    np.testing.assert_array_equal(uniform_interior(4), [0.25, 0.5, 0.75])
    np.testing.assert_allclose(nest(np.array([0.5]), 2), [0.25, 0.5, 0.75])


# ------------------------------------------------------------------ rings grading

def _rings_angles_from_contact(body: str, knots: np.ndarray) -> np.ndarray:
    """Angle along the half ring from the touching point of each arc knot, through the
    geometry itself (splipy evaluation of the coarse outer arc)."""
    ring = scene_bodies("rings")[body]
    c = (RINGS_UPPER if body == "upper" else RINGS_LOWER)["centre"]
    p = evaluate_patch(ring, knots, np.ones_like(knots)) - np.asarray(c)
    from_bottom = np.arctan2(p[:, 0], -p[:, 1])  # 0 at the lowest point, pi at the top
    return from_bottom if body == "upper" else math.pi - from_bottom


@pytest.mark.parametrize("body, n_el, r_out", [("upper", 12, 1.0), ("lower", 16, 1.5)])
def test_rings_m1_grading(body: str, n_el: int, r_out: float) -> None:
    """Half of the m1 arc elements uniform in angle within 1.5 x RINGS_A_EXP of the
    touching point, the rest uniform on either side of the coarse C0 knot (pi / 2)."""
    tc = math.asin(1.5 * RINGS_A_EXP / r_out)
    ang = np.concatenate([[0.0], rings_m1_angles(r_out, n_el), [math.pi]])
    assert len(ang) == n_el + 1
    d = np.diff(ang)
    half, quarter = n_el // 2, n_el // 4
    np.testing.assert_allclose(d[:half], tc / half, rtol=1e-13)
    np.testing.assert_allclose(d[half:half + quarter], (math.pi / 2 - tc) / quarter, rtol=1e-13)
    np.testing.assert_allclose(d[half + quarter:], math.pi / 2 / quarter, rtol=1e-13)
    breaks = rings_m1_breaks(body)
    assert 0.5 in breaks and np.all(np.diff(breaks) > 0)
    got = np.sort(_rings_angles_from_contact(body, breaks))
    np.testing.assert_allclose(got, ang[1:-1], rtol=0, atol=1e-12)


@pytest.mark.parametrize("body, n_el", [("upper", 12), ("lower", 16)])
@pytest.mark.parametrize("level", range(1, 5))
def test_rings_nested(body: str, n_el: int, level: int) -> None:
    k = rings_xi_knots(body, level)
    assert len(k) == n_el * 2 ** (level - 1) - 2 and 0.5 not in k
    assert np.all(np.diff(k) > 0) and k[0] > 0 and k[-1] < 1
    if level > 1:
        assert np.all(np.isin(rings_xi_knots(body, level - 1), k))  # exact nesting
    full = np.concatenate([[0.0], np.sort(np.append(k, 0.5)), [1.0]])
    spans = np.diff(full).reshape(n_el, -1)  # each m1 span split into equal spans
    np.testing.assert_allclose(spans, spans[:, :1].repeat(spans.shape[1], axis=1), rtol=1e-12)
