"""The incremental half-plane stick/slip reference (post.stickslip)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from post.stickslip import cattaneo_mindlin, halfplane_stick_slip


def test_cattaneo_mindlin_carries_q() -> None:
    """int q dx = mu P (1 - c^2/a^2) (Q of Cattaneo-Mindlin) with P = pi a p0 / 2."""
    x = np.linspace(-1.0, 1.0, 200001)
    for c in (0.0, 0.4, 0.7, 1.0):
        q = cattaneo_mindlin(x, 1.0, c, 1.0)
        assert np.trapezoid(q, x) == pytest.approx(math.pi / 2 * (1 - c**2), rel=1e-6)


def test_similar_limit_is_cattaneo_mindlin() -> None:
    """beta -> 0 (nu -> 1/2): no stick traction from the press, Cattaneo-Mindlin's zone."""
    h = halfplane_stick_slip(0.4999, 0.3, 0.5, panels=200, press_steps=100)
    assert h.press_stick_traction < 2e-3
    assert abs(h.stick_half_width - h.cattaneo_half_width) <= 5e-3
    assert h.l2_from_cattaneo < 5e-3


def test_dissimilar_rigid_flat() -> None:
    """nu = 0.49 (beta = 0.0196), mu = 0.3: the press leaves a stick traction of about
    0.06 mu p0 and the sheared stick zone is wider than Cattaneo-Mindlin's (converged:
    0.731 a against 0.707 a, 11.7 % L2; this coarser grid: 0.730 a, 11.8 %)."""
    h = halfplane_stick_slip(0.49, 0.3, 0.5, panels=200, press_steps=100)
    assert h.beta == pytest.approx(0.02 / 1.02)
    assert 0.05 < h.press_stick_traction < 0.075
    assert h.stick_half_width - h.cattaneo_half_width == pytest.approx(0.023, abs=0.004)
    assert h.l2_from_cattaneo == pytest.approx(0.117, abs=0.005)


def test_bad_values() -> None:
    with pytest.raises(ValueError):
        halfplane_stick_slip(0.5, 0.3)
    with pytest.raises(ValueError):
        halfplane_stick_slip(0.3, 0.3, 1.0)
