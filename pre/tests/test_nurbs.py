"""The splipy <-> voiga conversion, checked against an independent evaluation
(scipy B-splines, rational map computed by hand from Cartesian points and
weights)."""

from __future__ import annotations

import numpy as np
from scipy.interpolate import BSpline

from pre.nurbs import (
    Curve,
    Patch,
    curve_from_splipy,
    curve_to_splipy,
    evaluate_curve,
    evaluate_patch,
    patch_from_splipy,
    patch_to_splipy,
)
from pre.scenes import scene_bodies


def _basis(knots: np.ndarray, p: int, t: np.ndarray) -> np.ndarray:
    t = np.minimum(t, np.nextafter(1.0, 0.0))  # scipy's design matrix is right-open
    return BSpline.design_matrix(t, knots, p).toarray()


def direct_patch(patch: Patch, xi: np.ndarray, eta: np.ndarray) -> np.ndarray:
    nx = _basis(patch.knots_xi, patch.degree[0], xi)  # (m, n_xi)
    ne = _basis(patch.knots_eta, patch.degree[1], eta)  # (m, n_eta)
    wn = np.einsum("mi,mj,ji->mji", nx, ne, patch.weights)
    w = wn.sum(axis=(1, 2))
    return np.einsum("mji,jik->mk", wn, patch.control_points) / w[:, None]


def _random_patch(rng: np.random.Generator) -> Patch:
    kx = np.array([0, 0, 0, 0.3, 0.3, 0.7, 1, 1, 1])
    ke = np.array([0, 0, 0.4, 1, 1])
    return Patch((2, 1), kx, ke, rng.normal(size=(3, 6, 2)), rng.uniform(0.3, 2.0, size=(3, 6)))


def test_patch_conversion_matches_direct_evaluation() -> None:
    rng = np.random.default_rng(1)
    patch = _random_patch(rng)
    xi, eta = rng.random(1000), rng.random(1000)
    xi[:3], eta[:3] = [0.0, 1.0, 0.3], [1.0, 0.0, 0.4]
    assert np.abs(evaluate_patch(patch, xi, eta) - direct_patch(patch, xi, eta)).max() < 1e-12


def test_splipy_stores_projective_points() -> None:
    """splipy's controlpoints are (w x, w y, w), axes (n_xi, n_eta, 3)."""
    patch = _random_patch(np.random.default_rng(2))
    cp = patch_to_splipy(patch).controlpoints
    assert cp.shape == (6, 3, 3)
    np.testing.assert_allclose(cp[2, 1, 2], patch.weights[1, 2])
    np.testing.assert_allclose(cp[2, 1, :2], patch.weights[1, 2] * patch.control_points[1, 2])


def test_round_trips() -> None:
    rng = np.random.default_rng(3)
    patch = _random_patch(rng)
    back = patch_from_splipy(patch_to_splipy(patch))
    np.testing.assert_allclose(back.control_points, patch.control_points, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(back.weights, patch.weights)
    np.testing.assert_array_equal(back.knots_xi, patch.knots_xi)
    curve = Curve(2, [0, 0, 0, 0.5, 1, 1, 1], rng.normal(size=(4, 2)), rng.uniform(0.5, 2, 4))
    c2 = curve_from_splipy(curve_to_splipy(curve))
    np.testing.assert_allclose(c2.control_points, curve.control_points, rtol=0, atol=1e-15)
    t = rng.random(1000)
    nb = _basis(curve.knots, 2, t) * curve.weights
    direct = nb @ curve.control_points / nb.sum(axis=1)[:, None]
    assert np.abs(evaluate_curve(curve, t) - direct).max() < 1e-12


def test_scene_patches_direct_evaluation() -> None:
    rng = np.random.default_rng(4)
    xi, eta = rng.random(1000), rng.random(1000)
    for scene in ("ironing", "hertz", "rings"):
        for patch in scene_bodies(scene).values():
            assert np.abs(evaluate_patch(patch, xi, eta) - direct_patch(patch, xi, eta)).max() < 1e-12
