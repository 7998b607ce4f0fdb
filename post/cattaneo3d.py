"""A sphere pressed on a flat and sheared, against Cattaneo-Mindlin's circular stick zone
(``python -m post cattaneo3d RESULT.h5``; the cases: ``python -m pre cattaneo3d``).

Cattaneo-Mindlin for a Hertz point contact (Johnson, *Contact Mechanics*, 7.2) under a
normal force P then a tangential force Q < mu P along a fixed direction: the stick zone
is the disc r < c with ``c/a = (1 - Q/(mu P))^(1/3)``, and the tangential traction along Q

    q(r) = mu p0 sqrt(1 - r^2/a^2) - (c/a) mu p0 sqrt(1 - r^2/c^2)   (r < c)
    q(r) = mu p0 sqrt(1 - r^2/a^2)                                    (c < r < a)

with Hertz's a and p0 for P (:mod:`post.hertz3d`). A small-strain result for a press that
leaves no tangential traction (similar bodies, or a frictionless press on a rigid flat as
in ``pre cattaneo3d``); Mindlin's traction parallel to Q is itself an approximation
(the exact one has a small transverse part for nu > 0).

What is compared, in Hertz's measure as :mod:`post.hertz3d` (reference configuration,
traction per reference area ``p_t_nominal`` at the slave points' reference positions,
each weighted by ``area_ref``): P, a, p0, the axis and the model's symmetry from
:func:`post.hertz3d.hertz3d_comparison`; Q the pair's tangential force times that
symmetry, its direction e_Q; q the points' traction along e_Q. Measures:

- the stick radius: the points in contact whose traction magnitude stays more than
  :data:`STICK_MARGIN` mu p0 below the slip bound mu p_n stick; c = sqrt(symmetry x their
  area / pi) (the area of the stick disc, so the points' spacing averages out);
- the relative L2 difference of q from Cattaneo-Mindlin's over the disc r <= max(a, the
  farthest point in contact), weighted by the points' areas, r measured from the
  contact's centre: the pressure's centroid along e_Q (by Hertz's symmetry the disc's
  centre). The shear carries the material under the contact along Q by the stick
  zone's displacement (0.018 a on the scene), so in the reference configuration the
  contact's centre is no longer the lowest point, and the theory's r is measured from
  that centre; the same differences about the lowest point are reported too (then a
  rigid shift of 0.02 a alone makes the traction 11 % and the pressure 5 % apart at
  the square-root edges);
- the transverse traction (perpendicular to e_Q, in the plane) relative to mu p0, rms.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .hertz import HertzError, contact_pair
from .hertz3d import Hertz3dComparison, hertz3d_comparison
from .reader import Result
from .stickslip import cattaneo_mindlin

STICK_MARGIN = 0.01
"""A point sticks when its traction is more than this fraction of mu p0 below mu p_n."""


class Cattaneo3dError(HertzError):
    """The result is not a sphere pressed and sheared on a flat (or has no friction)."""


@dataclass
class Cattaneo3dComparison:
    """One step of a pair against Cattaneo-Mindlin (:func:`cattaneo3d_comparison`)."""

    hertz: Hertz3dComparison
    friction: float
    tangential_force: float
    """Q of the whole sphere (the pair's tangential force times the symmetry)."""
    direction: np.ndarray
    """e_Q, the unit direction of Q (on the slave)."""
    ratio: float
    """Q / (mu P)."""
    stick_radius: float
    """c / a of the simulated stick zone."""
    stick_points: int
    cattaneo_radius: float
    """Cattaneo-Mindlin's c / a for the ratio."""
    l2: float
    """Relative L2 difference of q from Cattaneo-Mindlin's over the disc about the contact's centre."""
    centre_shift: float
    """The contact's centre along e_Q from the lowest point (reference positions), over a."""
    pressure_l2: float
    """Relative L2 difference of p from Hertz's about the contact's centre."""
    l2_reference: float
    """The traction's L2 difference measured about the lowest point instead."""
    transverse: float
    """rms of the transverse traction over the disc, over mu p0."""

    @property
    def stick_error(self) -> float:
        """(c - c_CM) / a."""
        return self.stick_radius - self.cattaneo_radius


def _friction(result: Result, attrs: dict, step_time: float) -> float:
    """mu at the step: the pair's ``friction`` attribute (one value, or one per phase, the
    phase being the one the step's time falls in)."""
    mu = np.atleast_1d(np.asarray(attrs.get("friction", 0.0), dtype=float))
    phase = min(max(int(math.ceil(step_time - 1e-9)) - 1, 0), len(mu) - 1)
    return float(mu[phase])


def cattaneo3d_comparison(result: Result, step: int = -1, pair: int = 0,
                          friction: float | None = None) -> Cattaneo3dComparison:
    """Compare contact pair ``pair`` (0-based) at ``step`` of a 3D result with
    Cattaneo-Mindlin (module docstring); mu the pair's at that step unless ``friction``."""
    h = hertz3d_comparison(result, step=step, pair=pair)
    st, c = contact_pair(result, step, pair)
    mu = float(friction) if friction is not None else _friction(result, c.attrs, float(st.time))
    if not mu > 0:
        raise Cattaneo3dError(f"{result.path}: step {h.step}: the pair has no friction (mu = {mu:g})")
    if c.p_t_nominal is None:
        raise Cattaneo3dError(f"{result.path}: step {h.step}: no p_t_nominal (the traction per reference area)")
    n = h.normal
    force_t = c.force - (c.force @ n) * n
    if not np.linalg.norm(force_t) > 0:
        raise Cattaneo3dError(f"{result.path}: step {h.step}: no tangential force")
    e_q = force_t / np.linalg.norm(force_t)
    q_vec = np.asarray(c.p_t_nominal, dtype=float).reshape(len(c.state), -1)
    q_vec = q_vec - np.outer(q_vec @ n, n)
    q = q_vec @ e_q
    big_q = h.symmetry * float(np.linalg.norm(force_t))
    ratio = big_q / (mu * h.force)
    c_cm = (1.0 - ratio) ** (1.0 / 3.0) if ratio < 1 else 0.0
    # the points in the hertz comparison are sorted by r: recompute r in the file's order
    rel = c.x_ref - h.centre
    rel = rel - np.outer(rel @ n, n)
    p = np.asarray(c.p_n_nominal, dtype=float)
    w = np.asarray(c.area_ref, dtype=float)
    shift = float(np.sum(w * p * (rel @ e_q)) / np.sum(w * p))
    q0 = mu * h.p0
    active = c.active
    stick = active & (np.linalg.norm(q_vec, axis=1) < mu * p - STICK_MARGIN * q0)
    c_sim = math.sqrt(h.symmetry * float(w[stick].sum()) / math.pi) / h.a
    l2_ref, _, _ = _differences(np.linalg.norm(rel, axis=1), active, q, p, w, h, c_cm, q0)
    r = np.linalg.norm(rel - shift * e_q, axis=1)
    l2, pressure_l2, disc = _differences(r, active, q, p, w, h, c_cm, q0)
    perp = q_vec[disc] - np.outer(q[disc], e_q)
    transverse = math.sqrt(float(np.sum(w[disc] * np.sum(perp**2, axis=1))) / float(np.sum(w[disc]))) / q0
    return Cattaneo3dComparison(hertz=h, friction=mu, tangential_force=big_q, direction=e_q, ratio=ratio,
                                stick_radius=c_sim, stick_points=int(stick.sum()), cattaneo_radius=c_cm,
                                l2=l2, centre_shift=shift / h.a, pressure_l2=pressure_l2, l2_reference=l2_ref,
                                transverse=transverse)


def _differences(r: np.ndarray, active: np.ndarray, q: np.ndarray, p: np.ndarray, w: np.ndarray,
                 h: Hertz3dComparison, c_cm: float, q0: float) -> tuple[float, float, np.ndarray]:
    """Relative L2 differences of the traction along Q from Cattaneo-Mindlin's and of the
    pressure from Hertz's over the disc r <= max(a, the farthest point in contact), r each
    point's distance from the centre taken; and the disc's mask."""
    disc = r <= max(h.a, float(r[active].max()))
    ref = cattaneo_mindlin(r[disc], h.a, c_cm * h.a, q0)
    l2 = math.sqrt(float(np.sum(w[disc] * (q[disc] - ref) ** 2)) / float(np.sum(w[disc] * ref**2)))
    p_h = h.p0 * np.sqrt(np.clip(1.0 - (r[disc] / h.a) ** 2, 0.0, None))
    lp = math.sqrt(float(np.sum(w[disc] * (p[disc] - p_h) ** 2)) / float(np.sum(w[disc] * p_h**2)))
    return l2, lp, disc


def cattaneo3d_report(cm: Cattaneo3dComparison) -> list[str]:
    """Lines for the terminal."""
    h = cm.hertz
    return [f"{h.source}: step {h.step} (t = {h.time:g}), {h.symmetry} x the pair's forces",
            f"P = {h.force:.6g}  Q = {cm.tangential_force:.6g}  mu = {cm.friction:g}  Q/(mu P) = {cm.ratio:.4f}",
            f"Hertz: a = {h.a:.6g}  p0 = {h.p0:.6g}  (pressure L2 {cm.pressure_l2:.2%} about the contact's "
            f"centre, {h.error.l2:.2%} about the lowest point)",
            f"contact's centre (the pressure's centroid along Q, reference positions): {cm.centre_shift:+.4f} a "
            f"from the lowest point",
            f"stick radius c/a = {cm.stick_radius:.4f} ({cm.stick_points} points; Cattaneo-Mindlin "
            f"{cm.cattaneo_radius:.4f}, difference {cm.stick_error:+.4f} a)",
            f"traction along Q: L2 difference from Cattaneo-Mindlin {cm.l2:.2%} about the contact's centre "
            f"({cm.l2_reference:.2%} about the lowest point); transverse rms {cm.transverse:.4f} mu p0"]
