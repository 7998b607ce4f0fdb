"""post.field: the exact (VO) map of a body, reference and displaced.

Synthetic bodies (built from ``pre``'s splipy refinement of committed cases,
no binary needed) check the geometry, rigid translations and, for layered
bodies, an independent construction of the displaced VO field; result files
written by voiga check the numbering against the solver's and the exact
solution of the slab stretch.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import splipy

from post.field import check_numbering, combine, displacement, evaluate, evaluate_grid
from post.reader import Body, body_displacement, read_result
from pre.nurbs import Patch, evaluate_patch

from .conftest import DIE_SHIFT, exact_stretch

TOL = 1e-12


def _params(n: int = 1000, seed: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Random parameter pairs plus the corners and edge midpoints."""
    rng = np.random.default_rng(seed)
    xi, eta = rng.random(n), rng.random(n)
    xi[:8] = [0, 1, 0, 1, 0.5, 0.5, 0, 1]
    eta[:8] = [0, 0, 1, 1, 0, 1, 0.5, 0.5]
    return xi, eta


def _last_row_start(body: Body) -> float:
    """eta where the last element row (the contact row) starts."""
    knots = np.unique(body.bulk.knots_eta)
    return float(knots[-2])


def test_synthetic_set_has_both_kinds(synthetic_bodies: dict[str, Body]) -> None:
    layered = [k for k, b in synthetic_bodies.items() if b.layer is not None]
    plain = [k for k, b in synthetic_bodies.items() if b.layer is None]
    assert len(layered) >= 4 and len(plain) >= 3, (layered, plain)


def test_zero_displacement_is_the_bulk_geometry(synthetic_bodies: dict[str, Body]) -> None:
    xi, eta = _params()
    for key, body in synthetic_bodies.items():
        check_numbering(body)
        ref = evaluate_patch(body.bulk, xi, eta)
        for u in (None, np.zeros((body.ncp, 2))):
            err = np.abs(evaluate(body, u, xi, eta) - ref).max()
            assert err <= TOL, f"{key}: {err:.3e}"


def test_rigid_translation(synthetic_bodies: dict[str, Body]) -> None:
    xi, eta = _params(seed=2)
    c = np.array([0.37, -1.25])
    for key, body in synthetic_bodies.items():
        u = np.tile(c, (body.ncp, 1))
        moved = evaluate(body, u, xi, eta) - evaluate(body, None, xi, eta)
        assert np.abs(moved - c).max() <= TOL, key
        assert np.abs(displacement(body, u, xi, eta) - c).max() <= TOL, key


def _lift_row_to_layer(body: Body, row: np.ndarray,
                       row_w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The layer-space representation (points, weights) of the bulk's last-row
    curve with control points ``row`` and weights ``row_w``: the layer is a
    refinement of that curve's space, so collocation at the layer's Greville
    points (splipy basis functions) recovers it exactly up to round-off."""
    layer = body.layer
    bh = splipy.BSplineBasis(layer.degree + 1, layer.knots)
    bn = splipy.BSplineBasis(body.bulk.degree[0] + 1, body.bulk.knots_xi)
    g = np.asarray(bh.greville())
    hom = np.concatenate([row * row_w[:, None], row_w[:, None]], axis=1)
    coef = np.linalg.solve(bh.evaluate(g), bn.evaluate(g) @ hom)
    return coef[:, :2] / coef[:, 2:], coef[:, 2]


def _layer_contains_bulk_row(body: Body) -> bool:
    """Whether the layer's spline space contains the bulk's xi space: degree
    q >= p and, at every breakpoint, continuity q - m_layer <= p - m_bulk
    (true for NN2.k; not for NN4 or NN3.2, whose layers are smoother than the
    bulk at the new knots)."""
    q, p = body.layer.degree, body.bulk.degree[0]
    if q < p:
        return False
    br, mb = np.unique(body.bulk.knots_xi, return_counts=True)
    bl, ml = np.unique(body.layer.knots, return_counts=True)
    assert np.allclose(br, bl)
    return bool(np.all(q - ml[1:-1] <= p - mb[1:-1]))


def test_vo_field_equals_an_independently_refined_bulk_field(
        synthetic_bodies: dict[str, Body]) -> None:
    """Displace every bulk control point (last row included) at random. When
    the layer's space contains the bulk's xi space, the bulk patch with those
    points is a field of the VO space: writing its last row in the layer's
    space (independent route: collocation) and evaluating the VO body must
    give the displaced bulk patch."""
    xi, eta = _params(seed=3)
    rng = np.random.default_rng(4)
    tested = []
    for key, body in synthetic_bodies.items():
        if body.layer is None or not _layer_contains_bulk_row(body):
            continue
        tested.append(key)
        bulk = body.bulk
        moved = bulk.control_points + 0.05 * rng.standard_normal(bulk.control_points.shape)
        expected = evaluate_patch(Patch(bulk.degree, bulk.knots_xi, bulk.knots_eta, moved,
                                        bulk.weights), xi, eta)
        pts, w = _lift_row_to_layer(body, moved[-1], bulk.weights[-1])
        assert np.abs(w - body.layer.weights).max() < 1e-12, key  # same weight function
        rows = bulk.shape[0] - 1
        x = np.concatenate([moved[:rows].reshape(-1, 2), pts])
        err = np.abs(evaluate(body, x - body.control_points, xi, eta) - expected).max()
        assert err <= 1e-11, f"{key}: {err:.3e}"
    assert len(tested) >= 4, tested  # ironing NN2.2 and rings NN2.1, both bodies


def test_layer_points_act_only_in_the_contact_row(synthetic_bodies: dict[str, Body]) -> None:
    xi, eta = _params(seed=5)
    for key, body in synthetic_bodies.items():
        if body.layer is None:
            continue
        rows = body.bulk.shape[0] - 1
        u = np.zeros((body.ncp, 2))
        u[rows * body.bulk.shape[1]:] = 1.0  # move the layer points only
        moved = np.linalg.norm(displacement(body, u, xi, eta), axis=-1)
        below = eta <= _last_row_start(body)
        assert np.all(moved[below] == 0.0), key
        assert np.all(moved[eta > _last_row_start(body) + 1e-6] > 0), key
        assert np.abs(moved[eta == 1.0] - np.sqrt(2)).max() <= TOL, key  # edge: layer curve


def test_shapes_and_errors(synthetic_bodies: dict[str, Body]) -> None:
    body = next(b for b in synthetic_bodies.values() if b.layer is not None)
    assert evaluate(body, None, 0.3, 0.7).shape == (2,)
    assert evaluate(body, None, np.full((4, 5), 0.2), 0.9).shape == (4, 5, 2)
    grid = evaluate_grid(body, None, np.linspace(0, 1, 7), np.linspace(0, 1, 3))
    assert grid.shape == (3, 7, 2)
    np.testing.assert_array_equal(grid[1, 2], evaluate(body, None, 2 / 6, 0.5))
    assert combine(body, np.ones((body.ncp, 3)), [0.1, 0.9], [0.5, 1.0]).shape == (2, 3)
    np.testing.assert_allclose(combine(body, np.ones((body.ncp, 1)), *_params()), 1.0, atol=TOL)
    with pytest.raises(ValueError, match="shape"):
        evaluate(body, np.zeros((body.ncp + 1, 2)), 0.5, 0.5)
    with pytest.raises(ValueError, match=r"\[0, 1\]"):
        evaluate(body, None, 1.5, 0.5)
    broken = Body(**{**body.__dict__, "control_points": body.control_points[:-1],
                     "weights": body.weights[:-1]})
    with pytest.raises(ValueError, match="control points"):
        evaluate(broken, None, 0.5, 0.5)


# ---------------------------------------------------------------- result files


def test_stretch_field_is_exact(stretch_h5: Path) -> None:
    """Deformed points = X + exact u(X) at sampled points of the layered slab."""
    r = read_result(stretch_h5)
    body = r.bodies["slab"]
    xi, eta = _params(seed=6)
    ref = evaluate(body, None, xi, eta)
    assert np.abs(ref - evaluate_patch(body.bulk, xi, eta)).max() <= TOL
    for s in r.steps:
        x = evaluate(body, body_displacement(r, "slab", s.step), xi, eta)
        err = np.abs(x - ref - exact_stretch(ref, s.time)).max()
        assert err <= TOL, f"step {s.step}: {err:.3e}"


def test_two_bodies_field(two_h5: Path) -> None:
    r = read_result(two_h5)
    xi, eta = _params(seed=7)
    die, slab = r.bodies["die"], r.bodies["slab"]
    s = r.steps[-1]
    ref = evaluate(die, None, xi, eta)
    assert np.abs(ref - evaluate_patch(die.bulk, xi, eta)).max() <= TOL
    moved = evaluate(die, body_displacement(r, "die"), xi, eta) - ref
    assert np.abs(moved - np.array(DIE_SHIFT) * s.time / 2).max() <= TOL
    ref = evaluate(slab, None, xi, eta)
    u = evaluate(slab, body_displacement(r, "slab"), xi, eta) - ref
    assert np.abs(u - exact_stretch(ref, s.time)).max() <= TOL


def test_support_matches_the_solver_connectivity(stretch_h5: Path) -> None:
    """Inside an element only the control points of its connectivity act:
    moving all others leaves the field there unchanged (checks our numbering
    against voiga's elements, VO and bulk)."""
    body = read_result(stretch_h5).bodies["slab"]
    rng = np.random.default_rng(8)
    for k in range(body.n_elements):
        a, b, c, d = body.element_ranges[k]
        xi = a + (b - a) * rng.random(50)
        eta = c + (d - c) * rng.random(50)
        others = np.setdiff1d(np.arange(body.ncp), body.element(k))
        u = np.zeros((body.ncp, 2))
        u[others] = rng.standard_normal((len(others), 2))
        assert np.abs(displacement(body, u, xi, eta)).max() <= TOL, f"element {k}"
        u = np.zeros((body.ncp, 2))
        u[body.element(k)] = 1.0
        assert np.abs(displacement(body, u, xi, eta) - 1.0).max() <= TOL, f"element {k}"
