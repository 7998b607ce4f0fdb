"""A sphere pressed on a rigid plane or on an elastic body's flat face against Hertz's
point contact (``python -m post hertz3d``; the scene of ``python -m pre hertz3d``, issue 42).

What is compared, as in :mod:`post.hertz` (small-strain Hertz, the reference
configuration): the nominal pressure ``p_n_nominal`` (force per reference area) at the
slave points' reference positions ``x_ref``, each point weighted by ``area_ref``, the
reference area it integrates (Gauss weight x reference surface Jacobian), all from
``/steps/<k>/contact/<pair>`` of a result of dimension 3.

The contact axis is the line through the centre of the sphere fitted to the slave
points near the contact (:func:`post.hertz.fit_circle` in 3D) along the plane's normal:
the rigid plane's, or for a body master the reference normal of its contact face (the
bulk volume's ``zeta = 1``) at the active points' ``xi_master``, weighted by their
forces, the face flat there to :data:`FLAT_TOLERANCE` (:func:`contact_plane`); its foot
on the sphere is the contact's centre and r the distance of a point from the axis
(reference configuration). For the scene of ``pre hertz3d`` this is the lowest point
(0, 0, -R) and the z axis. The model is a quarter (or half) of the sphere
when its active points lie within 90 (180) degrees around the axis: the symmetry
planes then pass through the axis, and the total force P is 4 (2) times the pair's
force along the normal; else P is that force.

Hertz for a sphere of radius R on a flat: ``E* = E / (1 - nu^2)`` on a rigid one,
``1 / E* = (1 - nu^2) / E + (1 - nu_m^2) / E_m`` on an elastic body (the master's
``E_m``, ``nu_m``; a half-space),
``a = (3 P R / (4 E*))^(1/3)``, ``p0 = 3 P / (2 pi a^2)``, ``p(r) = p0 sqrt(1 - r^2/a^2)``.
The subsurface field on the axis (Johnson, Contact Mechanics, eq. 3.45; depth z):
``sigma_z = -p0 / (1 + z^2/a^2)``, ``sigma_r = p0 (-(1 + nu)(1 - (z/a) atan(a/z)) +
1/(2 (1 + z^2/a^2)))``; the largest shear ``(sigma_r - sigma_z)/2`` and its depth come
from maximising that expression for the case's nu (0.31 p0 at 0.48 a for nu = 0.3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.optimize import minimize_scalar

from pre.files import save_figure
from pre.volume import Volume, jacobian

from .field import evaluate
from .hertz import CIRCLE_TOLERANCE, HertzError, contact_pair, fit_circle, fit_hertz, hertz_pressure
from .naming import output_path
from .reader import ContactOutput, Result, Step
from .units import Units

NEAR = 3.0
"""The sphere is fitted to the slave points within this many active-zone extents of the
active point nearest the plane."""
SECTOR_SLACK = math.radians(2.0)
"""Angular slack of the quarter- and half-model test (the active points' azimuths)."""
DEPTH_RANGE = 3.0
"""Samples of the stress down to this many a below the contact's centre are compared."""
AXIS_TOLERANCE = 1e-6
"""A stress sample within this fraction of a from the axis is on the axis."""
FLAT_TOLERANCE = 1e-3
"""A body master's contact face is flat when its normals at the active points are within
this angle (radians) of their mean: Hertz's sphere on a flat (a curved master would add
its curvature to the sphere's)."""


def effective_modulus(youngs_modulus: float, poisson_ratio: float,
                      master: tuple[float, float] | None = None) -> float:
    """Hertz's E*: ``E / (1 - nu^2)`` on a rigid flat (``master`` None), else
    ``1 / ((1 - nu^2) / E + (1 - nu_m^2) / E_m)`` with ``master = (E_m, nu_m)``."""
    compliance = (1.0 - poisson_ratio**2) / youngs_modulus
    if master is not None:
        compliance += (1.0 - master[1] ** 2) / master[0]
    return 1.0 / compliance


def sphere_reference(force: float, youngs_modulus: float, poisson_ratio: float,
                     radius: float, master: tuple[float, float] | None = None) -> tuple[float, float]:
    """Contact radius a and peak pressure p0 of a sphere of ``radius`` pressed on a flat
    by the total force ``force`` (Hertz; E* of :func:`effective_modulus`: a rigid flat,
    or an elastic one of ``master = (E_m, nu_m)``)."""
    e_star = effective_modulus(youngs_modulus, poisson_ratio, master)
    a = (3.0 * force * radius / (4.0 * e_star)) ** (1.0 / 3.0)
    return float(a), float(3.0 * force / (2.0 * math.pi * a * a))


def axis_stresses(depth: np.ndarray, poisson_ratio: float) -> tuple[np.ndarray, np.ndarray]:
    """``(sigma_r, sigma_z) / p0`` on the axis at ``depth / a`` (> 0) below the centre of
    a Hertz point contact (module docstring)."""
    z = np.asarray(depth, dtype=float)
    q = 1.0 / (1.0 + z * z)
    with np.errstate(divide="ignore"):
        sigma_r = -(1.0 + poisson_ratio) * (1.0 - z * np.arctan2(1.0, z)) + 0.5 * q
    return sigma_r, -q


def axis_shear(depth: np.ndarray, poisson_ratio: float) -> np.ndarray:
    """The largest shear stress ``|sigma_r - sigma_z| / 2``, over p0, on the axis at
    ``depth / a``."""
    sigma_r, sigma_z = axis_stresses(depth, poisson_ratio)
    return 0.5 * np.abs(sigma_r - sigma_z)


def max_subsurface_shear(poisson_ratio: float) -> tuple[float, float]:
    """``(tau_max / p0, depth / a)`` of the largest shear below a Hertz point contact (on
    the axis), maximised for ``poisson_ratio``."""
    best = minimize_scalar(lambda z: -float(axis_shear(np.array([z]), poisson_ratio)[0]),
                           bounds=(1e-6, 3.0), method="bounded", options={"xatol": 1e-10})
    return float(-best.fun), float(best.x)


@dataclass(frozen=True)
class DiscError:
    """The pressure against Hertz's over the contact disc (:func:`disc_error`)."""

    l2: float
    """sqrt(sum w (p - p_H)^2 / sum w p_H^2) over the points with r <= ``extent``."""
    extent: float
    """The disc's radius: the larger of a and the farthest active point's r."""
    points: int
    """Points in the disc."""
    max_deviation: float
    """Signed (p - p_H) / p0 of largest magnitude at a point of the disc."""
    max_deviation_at: float
    """Where: its r / a."""


def disc_error(r: np.ndarray, p: np.ndarray, weights: np.ndarray, active: np.ndarray,
               a: float, p0: float) -> DiscError:
    """The relative L2 error of the point pressures ``p`` at distances ``r`` from the axis
    against ``p0 sqrt(1 - r^2/a^2)``, each point weighted by its area ``weights``, over
    the disc r <= max(a, the largest r of an ``active`` point): a point beyond a that
    carries pressure and a point within a that carries none both count as error."""
    r, p, w = (np.asarray(v, dtype=float) for v in (r, p, weights))
    extent = max(a, float(r[active].max()) if np.any(active) else 0.0)
    disc = r <= extent
    ref = hertz_pressure(r[disc], a, p0)
    norm = float(np.sum(w[disc] * ref**2))
    if not norm > 0:
        raise HertzError("no slave point lies within the contact radius a")
    dev = (p[disc] - ref) / p0
    k = int(np.argmax(np.abs(dev)))
    return DiscError(float(np.sqrt(np.sum(w[disc] * (p[disc] - ref) ** 2) / norm)), extent,
                     int(np.count_nonzero(disc)), float(dev[k]), float(r[disc][k] / a))


@dataclass
class SubsurfaceShear:
    """The sampled largest shear ``(sigma_1 - sigma_3) / 2`` below the contact."""

    tau_max: float
    """The largest sampled value within r <= a, depth <= DEPTH_RANGE a, over p0."""
    depth: float
    """Its depth / a."""
    r: float
    """Its r / a."""
    axis_samples: int
    """Samples on the axis within the depth range."""
    axis_deviation: float
    """Largest |tau - tau_Hertz(z)| / p0 over the axis samples (NaN without)."""
    depth_axis: np.ndarray = field(repr=False)
    """(n,) depth / a of the axis samples, sorted."""
    tau_axis: np.ndarray = field(repr=False)
    """(n,) their tau / p0."""


@dataclass
class Hertz3dComparison:
    """A 3D contact pair against Hertz's point contact (:func:`hertz3d_comparison`)."""

    radius: float
    youngs_modulus: float
    poisson_ratio: float
    symmetry: int
    """P over the pair's normal force: 4 (quarter model), 2 (half) or 1."""
    master: tuple[float, float] | None
    """The master's (E, nu); None for a rigid plane."""
    e_star: float
    """Hertz's E* (:func:`effective_modulus`)."""
    force: float
    """P, the total force of the whole sphere."""
    a: float
    p0: float
    error: DiscError
    a_fit: float
    """Of the fit p^2 = p0^2 (1 - r^2/a^2) to the points with pressure."""
    p0_fit: float
    centre: np.ndarray
    """The contact's centre (reference configuration)."""
    normal: np.ndarray
    """The plane's unit normal (the contact axis' direction, into the sphere)."""
    axis_source: str
    """Where the normal comes from (the rigid plane, or the master face and its flatness)."""
    misfit: float
    """rms distance of the fitted points from the sphere, over R."""
    tau_hertz: float
    """Hertz's largest subsurface shear / p0 for nu."""
    depth_hertz: float
    """Its depth / a."""
    shear: SubsurfaceShear | None
    shear_note: str
    """Why there is no shear comparison (empty when there is one)."""
    r: np.ndarray = field(repr=False)
    p: np.ndarray = field(repr=False)
    source: str = ""
    step: int = 0
    time: float = 0.0
    radius_source: str = ""

    @property
    def a_error(self) -> float:
        return self.a_fit / self.a - 1.0

    @property
    def p0_error(self) -> float:
        return self.p0_fit / self.p0 - 1.0


def symmetry_factor(azimuth: np.ndarray) -> int:
    """4 when the angles ``azimuth`` (radians, around the axis) lie within a quarter turn,
    2 within a half turn (:data:`SECTOR_SLACK` allowed), else 1."""
    t = np.sort(np.mod(np.asarray(azimuth, dtype=float), 2 * math.pi))
    if len(t) < 2:
        return 4
    gaps = np.diff(np.concatenate([t, [t[0] + 2 * math.pi]]))
    span = 2 * math.pi - float(gaps.max())
    if span <= math.pi / 2 + SECTOR_SLACK:
        return 4
    return 2 if span <= math.pi + SECTOR_SLACK else 1


def _axis_frame(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors completing ``normal`` to a right-handed frame."""
    helper = np.eye(3)[int(np.argmin(np.abs(normal)))]
    e1 = np.cross(normal, helper)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(normal, e1)


def fit_sphere(c: ContactOutput, normal: np.ndarray) -> tuple[np.ndarray, float, float]:
    """``(centre, radius, misfit / radius)`` of the sphere through the slave points near
    the contact (:data:`NEAR`)."""
    active = c.active
    lowest = c.x_ref[active][int(np.argmin(c.x_ref[active] @ normal))]
    dist = np.linalg.norm(c.x_ref - lowest, axis=1)
    extent = max(float(dist[active].max()), 1e-300)
    near = dist <= NEAR * extent
    if np.count_nonzero(near) < 10:
        near = np.ones_like(near)
    centre, radius, rms = fit_circle(c.x_ref[near])
    return centre, radius, rms / radius


def _contact(result: Result, step: int, pair: int) -> tuple[Step, ContactOutput]:
    if result.dimension != 3:
        raise HertzError(f"{result.path}: dimension {result.dimension}; post hertz3d compares a "
                         "solid (dimension 3), post hertz a cylinder")
    st, c = contact_pair(result, step, pair)
    missing = [k for k in ("p_n_nominal", "area_ref") if getattr(c, k) is None]
    if missing:
        raise HertzError(f"{result.path}: step {st.step}, pair {pair + 1}: no {' and no '.join(missing)} "
                         "(post hertz3d needs the nominal pressure and each point's reference area)")
    if c.master == "rigid" and (c.rigid_point is None or c.rigid_normal is None or len(c.rigid_normal) != 3):
        raise HertzError(f"{result.path}: pair {c.slave} -> {c.master} is not pressed on a rigid plane")
    return st, c


def contact_plane(result: Result, c: ContactOutput) -> tuple[np.ndarray, np.ndarray, str]:
    """``(point, unit normal, source)`` of the flat the sphere presses on: the rigid
    plane's, or a body master's contact face (its bulk volume's ``zeta = 1``, reference
    configuration) at the active points' ``xi_master``: the mean of its unit normals
    there weighted by the points' forces, and the force-weighted mean of those points.
    HertzError when the master is not a solid or its face is not flat over the zone
    (:data:`FLAT_TOLERANCE`)."""
    if c.rigid_normal is not None and c.rigid_point is not None:
        n = np.asarray(c.rigid_normal, dtype=float)
        return np.asarray(c.rigid_point, dtype=float), n / np.linalg.norm(n), "the rigid plane's normal"
    master = result.body(c.master)
    if not isinstance(master.bulk, Volume) or c.xi_master is None:
        raise HertzError(f"{result.path}: the master {c.master!r} is not a solid with xi_master")
    active = c.active
    xi = np.asarray(c.xi_master, dtype=float).reshape(len(active), -1)[active]  # (n, 2) stored flat
    x, jac = jacobian(master.bulk, xi[:, 0], xi[:, 1], np.ones(len(xi)))
    normals = np.cross(jac[:, :, 0], jac[:, :, 1])  # outward at zeta = 1 of a right-handed volume
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    w = np.asarray(c.p_n_nominal, dtype=float)[active] * np.asarray(c.area_ref, dtype=float)[active]
    w = w if w.sum() > 0 else np.ones(len(w))
    n = w @ normals
    n /= np.linalg.norm(n)
    spread = float(np.arccos(np.clip(normals @ n, -1.0, 1.0)).max())
    if spread > FLAT_TOLERANCE:
        raise HertzError(f"{result.path}: the contact face of the master {c.master!r} is not flat over the "
                         f"zone (its normals turn by {spread:.2g} rad, allowed {FLAT_TOLERANCE:g}); post "
                         "hertz3d compares a sphere on a flat")
    return w @ x / w.sum(), n, f"the master face's normal (reference, flat to {spread:.1g} rad)"


def subsurface_shear(result: Result, st: Step, body: str, centre: np.ndarray, normal: np.ndarray,
                     a: float, p0: float, poisson_ratio: float) -> tuple[SubsurfaceShear | None, str]:
    """The sampled stress of ``body`` at ``st`` below the contact, or None and why not."""
    fields = st.fields.get(body, {})
    if "stress" not in fields:
        return None, (f"no sampled stress of {body!r} at step {st.step} (the case's &output "
                      "fields = 'stress' writes it)")
    b = result.body(body)
    f = fields
    x = evaluate(b, None, f["xi"], f["eta"], f["zeta"])
    rel = x - centre
    depth = (rel @ normal) / a
    r = np.linalg.norm(rel - np.outer(rel @ normal, normal), axis=1) / a
    s = f["stress"]
    tensor = np.stack([np.stack([s[:, 0], s[:, 3], s[:, 5]], -1),
                       np.stack([s[:, 3], s[:, 1], s[:, 4]], -1),
                       np.stack([s[:, 5], s[:, 4], s[:, 2]], -1)], axis=1)
    principal = np.linalg.eigvalsh(tensor)
    tau = 0.5 * (principal[:, -1] - principal[:, 0]) / p0
    zone = (r <= 1.0) & (depth >= 0) & (depth <= DEPTH_RANGE)
    if not np.any(zone):
        return None, f"no stress sample within r <= a, depth <= {DEPTH_RANGE:g} a"
    k = int(np.flatnonzero(zone)[np.argmax(tau[zone])])
    axis = zone & (r <= AXIS_TOLERANCE)
    order = np.argsort(depth[axis])
    d_axis, t_axis = depth[axis][order], tau[axis][order]
    dev = np.abs(t_axis - axis_shear(np.maximum(d_axis, 1e-12), poisson_ratio))
    return SubsurfaceShear(float(tau[k]), float(depth[k]), float(r[k]), int(axis.sum()),
                           float(dev.max()) if dev.size else float("nan"), d_axis, t_axis), ""


def hertz3d_comparison(result: Result, step: int = -1, pair: int = 0, radius: float | None = None,
                       youngs_modulus: float | None = None, poisson_ratio: float | None = None,
                       symmetry: int | None = None, master_youngs_modulus: float | None = None,
                       master_poisson_ratio: float | None = None) -> Hertz3dComparison:
    """Compare contact pair ``pair`` (0-based) at ``step`` of a 3D result with Hertz's
    point contact (module docstring). R: the sphere fitted to the slave points near the
    contact unless ``radius``; E and nu: the slave body's unless given, and for a body
    master its own (``master_youngs_modulus``, ``master_poisson_ratio``); ``symmetry``:
    P over the pair's normal force (None: from the active points' azimuths). HertzError
    when the pair is not a sphere on a flat or has nothing to compare."""
    st, c = _contact(result, step, pair)
    active = c.active
    if not active.any():
        raise HertzError(f"{result.path}: no point of {c.slave} -> {c.master} is in contact at step {st.step}")
    plane, n, axis_source = contact_plane(result, c)
    normal_force = abs(float(c.force @ n))
    if normal_force <= 0:
        raise HertzError(f"{result.path}: no point of {c.slave} -> {c.master} is in contact at step {st.step}")
    sphere, r_fit, misfit = fit_sphere(c, n)
    if misfit > CIRCLE_TOLERANCE or (sphere - plane) @ n <= 0:
        raise HertzError(f"{result.path}: the contact face of {c.slave!r} is not a sphere pressing on "
                         f"the plane (its reference points near the contact are {misfit:.2g} of the "
                         f"radius off the best sphere, allowed {CIRCLE_TOLERANCE:g})")
    body = result.body(c.slave)
    e = float(youngs_modulus if youngs_modulus is not None else body.youngs_modulus)
    nu = float(poisson_ratio if poisson_ratio is not None else body.poisson_ratio)
    master = None
    if c.master != "rigid":
        mb = result.body(c.master)
        master = (float(master_youngs_modulus if master_youngs_modulus is not None else mb.youngs_modulus),
                  float(master_poisson_ratio if master_poisson_ratio is not None else mb.poisson_ratio))
    big_r = float(radius) if radius is not None else r_fit
    centre = sphere - r_fit * n
    rel = c.x_ref - centre
    radial = rel - np.outer(rel @ n, n)
    r = np.linalg.norm(radial, axis=1)
    e1, e2 = _axis_frame(n)
    factor = symmetry or symmetry_factor(np.arctan2(radial[active] @ e2, radial[active] @ e1))
    force = factor * normal_force
    a, p0 = sphere_reference(force, e, nu, big_r, master)
    p = np.asarray(c.p_n_nominal, dtype=float)
    err = disc_error(r, p, c.area_ref, active, a, p0)
    on = p > 0
    try:
        a_fit, p0_fit = fit_hertz(r[on], p[on])
    except ValueError:
        a_fit = p0_fit = float("nan")
    tau_h, depth_h = max_subsurface_shear(nu)
    shear, note = subsurface_shear(result, st, c.slave, centre, n, a, p0, nu)
    source = (f"given; the slave face's sphere fit: {r_fit:.6g}" if radius is not None
              else f"sphere fit to the slave face's reference points, misfit {misfit:.1g} R")
    order = np.argsort(r, kind="stable")
    return Hertz3dComparison(radius=big_r, youngs_modulus=e, poisson_ratio=nu, symmetry=factor,
                             master=master, e_star=effective_modulus(e, nu, master),
                             force=force, a=a, p0=p0, error=err, a_fit=a_fit, p0_fit=p0_fit,
                             centre=centre, normal=n, axis_source=axis_source, misfit=misfit, tau_hertz=tau_h,
                             depth_hertz=depth_h, shear=shear, shear_note=note, r=r[order],
                             p=p[order], source=str(result.path), step=st.step,
                             time=float(st.time), radius_source=source)


MODELS = {4: "a quarter model: symmetry planes through the axis, the active points within 90 degrees "
             "around it", 2: "a half model: the active points within 180 degrees around the axis",
          1: "the whole contact"}


def format_hertz3d(h: Hertz3dComparison) -> str:
    """One line: P, a, p0, the L2 error and the fit (``post summary``)."""
    shear = (f"  tau_max {h.shear.tau_max:.4f} p0 (Hertz {h.tau_hertz:.4f})" if h.shear is not None
             else "")
    return (f"P = {h.force:.6g} ({h.symmetry} x the pair's)  a = {h.a:.6g}  p0 = {h.p0:.6g}  "
            f"L2 = {h.error.l2:.3%}  fit: a {h.a_error:+.2%}, p0 {h.p0_error:+.2%}{shear}")


def _e_star_text(h: Hertz3dComparison) -> str:
    if h.master is None:
        return f"E* = E/(1-nu^2) = {h.e_star:.6g} (rigid flat)"
    e, nu = h.master
    return (f"on the master's E = {e:.6g}, nu = {nu:.6g}: E* = 1/((1-nu^2)/E + (1-nu_m^2)/E_m) = "
            f"{h.e_star:.6g} (an elastic flat, a half-space)")


def hertz3d_report(h: Hertz3dComparison) -> list[str]:
    """The lines ``python -m post hertz3d`` prints."""
    e = h.error
    c = ", ".join(f"{v:.6g}" for v in h.centre)
    lines = [f"{h.source}, step {h.step} (load time {h.time:g}):",
             "  measure: reference configuration, p_n_nominal (force per reference area) at "
             "x_ref, weighted by area_ref",
             f"  sphere: R = {h.radius:.6g} ({h.radius_source}); E = {h.youngs_modulus:.6g}, "
             f"nu = {h.poisson_ratio:.6g}, " + _e_star_text(h),
             f"  contact centre ({c}), axis along {h.axis_source}; r = distance from the axis",
             f"  P = {h.force:.6g} = {h.symmetry} x the pair's normal force ({MODELS[h.symmetry]})",
             f"  analytic: a = (3PR/(4E*))^(1/3) = {h.a:.6g} (a/R = {h.a / h.radius:.4g}), "
             f"p0 = 3P/(2 pi a^2) = {h.p0:.6g}",
             f"  relative L2 error of p over the disc r <= {e.extent / h.a:.4f} a "
             f"(max(a, the farthest active point); {e.points} points, weights area_ref): {e.l2:.3%}",
             f"  largest |p - p_H| / p0 at a point of the disc: {abs(e.max_deviation):.3%} "
             f"({'+' if e.max_deviation >= 0 else '-'}) at r/a = {e.max_deviation_at:.4f}",
             f"  fit p^2 = p0^2 (1 - r^2/a^2) to the points with pressure: a = {h.a_fit:.6g} "
             f"({h.a_error:+.3%}), p0 = {h.p0_fit:.6g} ({h.p0_error:+.3%})",
             f"  Hertz subsurface shear (sigma_1 - sigma_3)/2: {h.tau_hertz:.4f} p0 at depth "
             f"{h.depth_hertz:.4f} a on the axis (nu = {h.poisson_ratio:g})"]
    s = h.shear
    if s is None:
        lines.append(f"  sampled: skipped, {h.shear_note}")
    else:
        lines.append(f"  sampled: largest {s.tau_max:.4f} p0 ({s.tau_max / h.tau_hertz - 1:+.2%}) at "
                     f"depth {s.depth:.4f} a, r = {s.r:.4f} a (samples within r <= a, depth <= "
                     f"{DEPTH_RANGE:g} a; a maximum over samples, not of the field)")
        if s.axis_samples:
            lines.append(f"  on the axis: {s.axis_samples} samples, largest |tau - tau_H(z)| = "
                         f"{s.axis_deviation:.4f} p0")
    return lines


def plot_hertz3d(h: Hertz3dComparison, output: str | Path, units: Units | None = None) -> Path:
    """p against r with Hertz's profile (left), the sampled shear on the axis against
    Hertz's (right, when there is a shear comparison)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    units = units or Units()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5), layout="constrained")
    left, right = axes
    s = np.linspace(0.0, 1.0, 400)
    keep = h.r <= 1.5 * max(h.error.extent, h.a)
    left.plot(h.r[keep] / h.a, h.p[keep] / h.p0, ".", ms=3, label="slave points (reference configuration)")
    left.plot(s, hertz_pressure(s, 1.0, 1.0), "k-", lw=1.5,
              label=f"Hertz: a = {h.a:.4g} {units.length}, p0 = {h.p0:.4g} {units.pressure}")
    left.set_xlabel("r / a")
    left.set_ylabel("p / p0")
    left.set_title(f"{Path(h.source).stem}, step {h.step}: L2 = {h.error.l2:.3%}", fontsize=10)
    left.legend(fontsize=8)
    z = np.linspace(1e-3, 3.0, 400)
    right.plot(axis_shear(z, h.poisson_ratio), z, "k-", lw=1.5, label="Hertz on the axis")
    if h.shear is not None:
        right.plot(h.shear.tau_axis, h.shear.depth_axis, "o", ms=4, label="samples on the axis")
    right.invert_yaxis()
    right.set_xlabel("(sigma_1 - sigma_3) / 2 / p0")
    right.set_ylabel("depth / a")
    right.set_title(h.shear_note or f"largest sampled {h.shear.tau_max:.3f} p0, Hertz {h.tau_hertz:.3f} p0",
                    fontsize=9)
    right.legend(fontsize=8)
    for ax in axes:
        ax.grid(alpha=0.3)
    path = Path(output)
    save_figure(fig, path, dpi=150)
    plt.close(fig)
    return path


def hertz3d_figure(result: Result, h: Hertz3dComparison, out: str | Path | None = None,
                   output: str | Path | None = None) -> Path:
    """:func:`plot_hertz3d` into ``<result>-hertz3d-<step>.png`` next to the result or in ``out``."""
    return plot_hertz3d(h, output or output_path(result.path, "hertz3d", h.step, out), units=result.units)
