"""``post.lame``: Lamé's thick spherical shell (equilibrium, boundary values, strains
consistent with the displacement through Hooke's law, the Cartesian fields) and the
relative L2 error measures on perturbations with known errors."""

from __future__ import annotations

import numpy as np
import pytest

from post.lame import LameShell, hooke, octant_errors, octant_quadrature, relative_l2_errors

SHELLS = [LameShell(), LameShell(a=0.5, b=3.0, p=2.5, E=210.0, nu=0.25)]
H = 1e-5  # central differences: truncation h^2 ~ 1e-10 relative, round-off eps / h ~ 1e-11


def _radii(s: LameShell) -> np.ndarray:
    return np.linspace(s.a, s.b, 41)


@pytest.mark.parametrize("s", SHELLS)
def test_radial_equilibrium(s: LameShell) -> None:
    """d sigma_rr / dr + 2 (sigma_rr - sigma_tt) / r = 0, by central differences."""
    r = _radii(s)
    dsrr = (s.sigma_rr(r + H) - s.sigma_rr(r - H)) / (2 * H)
    residual = dsrr + 2 * (s.sigma_rr(r) - s.sigma_tt(r)) / r
    assert np.abs(residual).max() <= 1e-8 * s.p / s.a


@pytest.mark.parametrize("s", SHELLS)
def test_boundary_values(s: LameShell) -> None:
    assert s.sigma_rr(s.a) == pytest.approx(-s.p, rel=1e-14)
    assert abs(s.sigma_rr(s.b)) <= 1e-14 * s.p


@pytest.mark.parametrize("s", SHELLS)
def test_strains_of_the_displacement_give_the_stresses(s: LameShell) -> None:
    """eps_rr = du_r/dr (central differences), eps_tt = u_r / r; Hooke's law in the
    principal axes gives sigma_rr and sigma_tt."""
    r = _radii(s)
    err = (s.u_r(r + H) - s.u_r(r - H)) / (2 * H)
    ett = s.u_r(r) / r
    lam = s.E * s.nu / ((1 + s.nu) * (1 - 2 * s.nu))
    mu = s.E / (2 * (1 + s.nu))
    tr = err + 2 * ett
    scale = s.p
    assert np.allclose(lam * tr + 2 * mu * err, s.sigma_rr(r), rtol=0, atol=1e-8 * scale)
    assert np.allclose(lam * tr + 2 * mu * ett, s.sigma_tt(r), rtol=0, atol=1e-8 * scale)


@pytest.mark.parametrize("s", SHELLS)
def test_cartesian_fields(s: LameShell) -> None:
    """The Cartesian displacement is radial of length u_r; Hooke's law of its gradient
    (central differences) is the Cartesian stress; div sigma = 0; the traction on the
    inner sphere is -p n, on the outer sphere 0."""
    rng = np.random.default_rng(7)
    n = rng.normal(size=(20, 3))
    n = np.abs(n) / np.linalg.norm(n, axis=1, keepdims=True)
    x = n * rng.uniform(s.a, s.b, size=(20, 1))
    u = s.displacement(x)
    assert np.allclose(u, s.u_r(np.linalg.norm(x, axis=1))[:, None] * n, rtol=1e-14)
    grad = np.empty((20, 3, 3))
    div = np.zeros((20, 3))
    for j in range(3):
        e = np.zeros(3)
        e[j] = H
        grad[:, :, j] = (s.displacement(x + e) - s.displacement(x - e)) / (2 * H)
        div += (s.stress(x + e)[:, :, j] - s.stress(x - e)[:, :, j]) / (2 * H)
    assert np.allclose(hooke(grad, s.E, s.nu), s.stress(x), rtol=0, atol=1e-8 * s.p)
    assert np.abs(div).max() <= 1e-8 * s.p / s.a
    t_in = np.einsum("nij,nj->ni", s.stress(s.a * n), n)
    t_out = np.einsum("nij,nj->ni", s.stress(s.b * n), n)
    assert np.allclose(t_in, -s.p * n, rtol=0, atol=1e-14 * s.p)
    assert np.abs(t_out).max() <= 1e-14 * s.p


@pytest.mark.parametrize("s", SHELLS)
def test_quadrature_integrates_volume_and_norms(s: LameShell) -> None:
    """The octant rule's weights sum to the octant's volume pi (b^3 - a^3) / 6, and it
    integrates the exact solution's squared norms as the closed forms."""
    x, w = octant_quadrature(s.a, s.b, 20)
    assert w.sum() == pytest.approx(np.pi * (s.b**3 - s.a**3) / 6, rel=1e-13)
    assert np.all(x >= 0) and np.allclose(np.linalg.norm(x, axis=1).clip(s.a, s.b),
                                          np.linalg.norm(x, axis=1))
    nu, ns = s.norms()
    # Gauss-Legendre on the 1/r^k integrands: b/a = 2 1e-15 with 12 points, b/a = 6 3e-12
    # with 20 (7e-7 with 12)
    assert np.sqrt(np.sum(w * np.sum(s.displacement(x)**2, axis=1))) == pytest.approx(nu, rel=1e-9)
    assert np.sqrt(np.sum(w * np.sum(s.stress(x)**2, axis=(1, 2)))) == pytest.approx(ns, rel=1e-9)


def test_errors_of_known_perturbations() -> None:
    """u_h = u + d (a constant vector) and sigma_h = sigma + t I have the errors
    |d| sqrt(V) / ||u|| and t sqrt(3 V) / ||sigma||, V = 7 pi / 6 the volume of the
    octant of a = 1, b = 2; the exact fields have none; a field scaled by (1 + c) has c."""
    s = LameShell()
    volume = 7 * np.pi / 6
    nu, ns = s.norms()
    d = np.array([1e-3, -2e-3, 0.5e-3])
    t = 0.01
    eu, es = octant_errors(s, lambda x: s.displacement(x) + d, lambda x: s.stress(x) + t * np.eye(3))
    assert eu == pytest.approx(np.linalg.norm(d) * np.sqrt(volume) / nu, rel=1e-10)
    assert es == pytest.approx(t * np.sqrt(3 * volume) / ns, rel=1e-10)
    assert octant_errors(s, s.displacement, s.stress) == (0.0, 0.0)
    eu, es = octant_errors(s, lambda x: 1.02 * s.displacement(x), lambda x: 0.97 * s.stress(x))
    assert (eu, es) == pytest.approx((0.02, 0.03), rel=1e-12)
    eu, es = octant_errors(s, lambda x: 1.02 * s.displacement(x))
    assert eu == pytest.approx(0.02) and np.isnan(es)


def test_sampled_errors_weigh_the_points() -> None:
    """relative_l2_errors weighs each point's squared error by its weight."""
    w = np.array([1.0, 3.0])
    u = np.array([[1.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
    u_h = u + np.array([[0.1, 0.0, 0.0], [0.0, 0.0, 0.0]])
    eu, _ = relative_l2_errors(w, u_h, u)
    assert eu == pytest.approx(np.sqrt(0.01 / (1 + 12)))


def test_refuses_bad_shells() -> None:
    for kwargs in ({"a": 2.0, "b": 1.0}, {"a": 0.0}, {"nu": 0.5}, {"E": -1.0}):
        with pytest.raises(ValueError):
            LameShell(**kwargs)
