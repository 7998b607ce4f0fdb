"""The half-plane line-contact solution by cosine series (``post.halfplane``): Hertz's
parabola exactly, a quartic profile against its closed form, the exact circle against
the load's expansion in a/R, and the circle's pressure integrating to the load."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from post.halfplane import CircleContact, circle_contact, profile_coefficients


def test_parabola_is_hertz() -> None:
    """h' = s / R: c_1 = a / R and nothing else, p = E* sqrt(a^2 - x^2) / (2 R)."""
    a, radius, e_star = 0.3, 2.0, 5.0
    c = profile_coefficients(lambda s: s / radius, a)
    assert c[0] == pytest.approx(a / radius, rel=1e-14)
    assert np.abs(c[1:]).max() < 1e-15
    x = np.linspace(-a, a, 9)
    p = CircleContact(a=a, e_star=e_star, coefficients=c).pressure(x)
    assert p == pytest.approx(e_star * np.sqrt(a**2 - x**2) / (2 * radius), abs=1e-14)


def test_quartic_profile_closed_form() -> None:
    """h = s^4 / 4: p = E* a (a^2 + 2 x^2) sqrt(a^2 - x^2) / (4 a^2) ... from the series
    (c_1 = 3 a^3 / 4, c_3 = a^3 / 4), the closed form of a flat-ended quartic punch."""
    a, e_star = 0.7, 3.0
    c = profile_coefficients(lambda s: s**3, a)
    assert c[:2] == pytest.approx([0.75 * a**3, 0.25 * a**3], rel=1e-13)
    x = np.linspace(-a, a, 11)
    p = CircleContact(a=a, e_star=e_star, coefficients=c).pressure(x)
    assert p == pytest.approx(e_star / 4 * (a**2 + 2 * x**2) * np.sqrt(a**2 - x**2), abs=1e-13)


@pytest.mark.parametrize("a_over_r", [0.01, 0.0757, 0.2])
def test_circle_load_and_width(a_over_r: float) -> None:
    """For the circle P = pi E* a^2 / (4 R) (1 + 3/8 (a/R)^2 + O((a/R)^4)); the pressure
    integrates to P and vanishes at +-a; for small a/R it is Hertz's."""
    radius, e_star = 1.5, 2.0
    a = a_over_r * radius
    force = np.pi * e_star * a**2 / (4 * radius) * (1 + 3 / 8 * a_over_r**2)
    c = circle_contact(force, e_star, radius)
    assert c.a / a - 1 == pytest.approx(0.0, abs=2 * a_over_r**4)
    integral, _ = quad(lambda s: float(c.pressure(np.array(s))), -c.a, c.a, limit=200)
    assert integral == pytest.approx(force, rel=1e-10)
    assert c.pressure(np.array([c.a, -c.a, 1.1 * c.a])) == pytest.approx(0.0, abs=1e-12)
    a_h = np.sqrt(4 * force * radius / (np.pi * e_star))
    assert c.a / a_h - 1 == pytest.approx(-3 / 16 * a_over_r**2, abs=a_over_r**4)


def test_too_wide_is_refused() -> None:
    with pytest.raises(ValueError, match="R/2"):
        circle_contact(force=10.0, e_star=1.0, radius=1.0)
