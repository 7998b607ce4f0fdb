"""Error and cost measures of the benchmark scenes (definitions in docs/validation.md).

- ironing: oscillation amplitude of the die forces Px, Py over the second half of the
  sliding steps, after removing a cubic trend (the slab's finite length makes the mean
  force drift as the die approaches its end); reported as % of N2 on the same mesh.
- hertz: against analytic Hertz in the reference configuration (post.hertz: nominal
  pressure at the reference positions, relative L2 error over the union of both
  supports, largest pointwise deviation over p0, and the fitted half-width and peak as
  extras), and the relative L2 error of the normalised pressure p/p_max against the
  reference run (N2 on m6).
- rings: relative L2 errors of p_N and p_T against the reference run (N2, finer mesh).
- hertz3d (a sphere on a flat, :mod:`post.hertz3d`): against Hertz's point contact in
  the reference configuration: the relative L2 error of the nominal pressure over the
  contact disc, the fitted contact radius and peak, the largest pointwise deviation
  over p0 and the sampled largest subsurface shear (docs/validation-3d.md).
- ironing in 3D (ironing3d, :mod:`post.ironing3d`): the 2D measure on the contact
  pair's resultant, F_x along the path (suffix ``t``) and F_z (suffix ``n``).

A study may also name measures read from the result file (:func:`file_measure`).
"""

from __future__ import annotations

import re
from functools import lru_cache
from pathlib import Path

import numpy as np

from .contact import pressure_field
from .hertz import fit_hertz, hertz_comparison
from .ironing import die_forces
from .reader import Result

PRESS_STEPS = 10
"""Steps of the ironing press phase (cases/ironing: n_steps = 10, 200)."""


def detrended_amplitude(t: np.ndarray, y: np.ndarray, degree: int = 3) -> float:
    """max - min of y after subtracting a least-squares polynomial trend in t."""
    t = np.asarray(t, dtype=float)
    scaled = (t - t.mean()) / max(np.ptp(t), 1e-300)
    return float(np.ptp(y - np.polyval(np.polyfit(scaled, y, degree), scaled)))


def ironing_measures(res: Result) -> dict[str, float]:
    """Detrended oscillation amplitudes and mean forces over the second half of sliding."""
    steps, f = die_forces(res)
    sliding = np.flatnonzero(steps > PRESS_STEPS)
    if len(sliding) < 8:
        return {}
    w = sliding[len(sliding) // 2:]
    out = {"amp_px": detrended_amplitude(steps[w], f[w, 0]),
           "amp_py": detrended_amplitude(steps[w], f[w, 1]),
           "raw_amp_px": float(np.ptp(f[w, 0])), "raw_amp_py": float(np.ptp(f[w, 1])),
           "mean_px": float(f[w, 0].mean()), "mean_py": float(f[w, 1].mean())}
    # the oscillation relative to the mean force: an error measure (the continuum
    # solution of steady sliding has none), comparable across meshes
    out["osc_px"] = out["amp_px"] / abs(out["mean_px"]) if out["mean_px"] else float("nan")
    out["osc_py"] = out["amp_py"] / abs(out["mean_py"]) if out["mean_py"] else float("nan")
    return out


def profile(res: Result, pair: int = 0, which: str = "p_n") -> tuple[np.ndarray, np.ndarray]:
    """Current x and a traction of the last step's slave points, sorted in x."""
    c = res.steps[-1].contact[pair]
    x = c.x[:, 0]
    order = np.argsort(x)
    return x[order], getattr(c, which)[order]


def edge_profile(x: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The active part of a pressure profile (x increasing away from the centre) closed
    by a zero at the contact edge estimated from the last two active points, where p^2
    is close to linear in x (p ~ sqrt(a - x) at a smooth contact edge). Without this the
    profile would fall to zero at the first inactive point, whose distance from the
    edge depends on where the quadrature points happen to lie."""
    act = np.flatnonzero(p > 0)
    if len(act) < 2:
        return x[act], p[act]
    xa, pa = x[act], p[act]
    (x1, x2), (q1, q2) = xa[-2:], pa[-2:] ** 2
    edge = x2 + q2 * (x2 - x1) / (q1 - q2) if q1 > q2 else x2
    nxt = x[act[-1] + 1] if act[-1] + 1 < len(x) else edge
    edge = min(max(edge, x2), nxt)   # between the last active and the first inactive point
    return np.append(xa, edge), np.append(pa, 0.0)


def profile_error(x: np.ndarray, p: np.ndarray, xr: np.ndarray, pr: np.ndarray,
                  extent: float, scale: float) -> float:
    """Relative L2 distance of two traction profiles on [0, extent], both divided by
    ``scale``; linear interpolation between points, the first value down to x = 0 (a
    symmetry line), zero beyond the last point (for contact pressures, close the
    profiles with :func:`edge_profile` first)."""
    s = np.linspace(0.0, extent, 4001)
    # both scenes' profiles start at the symmetry line x = 0: below the first point the
    # profile keeps its first value
    a = np.interp(s, x, p, left=p[0], right=0.0) / scale
    b = np.interp(s, xr, pr, left=pr[0], right=0.0) / scale
    norm = np.sqrt(np.trapezoid(b**2, s))
    return float(np.sqrt(np.trapezoid((a - b) ** 2, s)) / norm) if norm > 0 else float("nan")


@lru_cache(maxsize=4)
def _hertz_reference(ref: Result) -> tuple[float, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """What :func:`hertz_measures` needs of the reference run, computed once per
    reference (a sweep compares every hertz run with the same one): the fitted
    half-width a, the closed point profile (x, p) and the pressure field (x, p)
    sorted in x."""
    href = hertz_comparison(ref)
    xr, pr = edge_profile(*profile(ref))
    xfr, pfr = pressure_field(ref)
    order = np.argsort(xfr[:, 0])
    return href.a, xr, pr, xfr[order, 0], pfr[order]


def hertz_measures(res: Result, ref: Result | None = None) -> dict[str, float]:
    """Comparison with analytic Hertz (:func:`post.hertz.hertz_comparison`), and with the
    reference run if given: profiles in x/a on [0, 1.2], pressures divided by the
    reference's peak."""
    h = hertz_comparison(res)
    out = {"force": h.force, "a_err": h.a_error, "p0_err": h.p0_error, "pmax_err": h.p_max / h.p0 - 1.0,
           "l2_analytic": h.l2_error, "maxdev_analytic": abs(h.error.max_deviation),
           "maxdev_interior": abs(h.error.interior_deviation)}
    if ref is not None:
        a_ref, xr, pr, xfr, pfr = _hertz_reference(ref)
        x, p = edge_profile(*profile(res))
        out["l2_ref"] = profile_error(x / a_ref, p, xr / a_ref, pr, 1.2, float(pr.max()))
        # the same distance between the continuous penalty pressure fields
        xf, pf = pressure_field(res)
        o = np.argsort(xf[:, 0])
        out["l2_ref_field"] = profile_error(xf[o, 0] / a_ref, pf[o], xfr / a_ref, pfr, 1.2,
                                            float(pfr.max()))
    return out


def hertz3d_measures(res: Result) -> dict[str, float]:
    """A 3D sphere-on-a-flat result against Hertz's point contact
    (:func:`post.hertz3d.hertz3d_comparison`; the last step, the first contact pair):
    ``l2_analytic`` (relative L2 of the pressure over the disc), ``a_err`` and
    ``p0_err`` (the fit p^2 = p0^2 (1 - r^2/a^2) over the analytic a and p0, minus 1),
    ``abs_a_err`` (|a_err|: the half-width error the accuracy/cost table ranks),
    ``maxdev_analytic`` (the largest |p - p_H| / p0), ``force`` (P of the whole
    sphere), ``a`` (Hertz's a for P) and, when the result holds the sampled stress,
    ``tau_err`` (the largest sampled shear below the contact over Hertz's, minus 1)."""
    from .hertz3d import hertz3d_comparison

    h = hertz3d_comparison(res)
    out = {"force": h.force, "a": h.a, "l2_analytic": h.error.l2, "a_err": h.a_error,
           "abs_a_err": abs(h.a_error), "p0_err": h.p0_error, "maxdev_analytic": abs(h.error.max_deviation)}
    if h.shear is not None:
        out["tau_err"] = h.shear.tau_max / h.tau_hertz - 1.0
    return out


def ironing3d_measures(res: Result) -> dict[str, float]:
    """The oscillation measures of a 3D ironing result (:func:`post.ironing3d.ironing_forces`:
    the 2D study's ``amp``, ``osc``, ``mean``, ``raw_amp`` and ``spread`` of F_x, suffix
    ``_t``, and of F_z, suffix ``_n``, and ``ratio`` = |mean F_x / mean F_z|)."""
    from .ironing3d import ironing_forces

    return dict(ironing_forces(res).measures)


def rings_measures(res: Result, ref: Result | None = None) -> dict[str, float]:
    """L2 errors of p_N and p_T against the reference run (profiles along current x)."""
    if ref is None or not res.steps or not res.steps[-1].contact:
        return {}
    out = {}
    for which, key in (("p_n", "l2_pn_ref"), ("p_t", "l2_pt_ref")):
        x, p = profile(res, which=which)
        xr, pr = profile(ref, which=which)
        keep, keep_r = p != 0, pr != 0
        x, p, xr, pr = x[keep], p[keep], xr[keep_r], pr[keep_r]
        if len(x) == 0 or len(xr) == 0:
            continue
        active = np.abs(pr) > 0
        extent = 1.2 * float(xr[active].max()) if active.any() else float(xr.max())
        out[key] = profile_error(x, p, xr, pr, extent, float(np.abs(pr).max()))
    return out


def measures_for(scene: str, res: Result, ref: Result | None = None) -> dict[str, float]:
    """The measures of ``scene`` for one converged result (empty if it has no steps)."""
    if not res.steps or not res.converged:
        return {}
    try:
        if scene.startswith("ironing"):
            return ironing_measures(res) if res.dimension == 2 else ironing3d_measures(res)
        if scene == "hertz":
            return hertz_measures(res, ref)
        if scene == "hertz3d":
            return hertz3d_measures(res)
        if scene == "rings":
            return rings_measures(res, ref)
    except (ValueError, IndexError) as err:
        return {"measure_error": str(err)}
    return {}


REDUCTIONS = {"max": np.max, "min": np.min, "mean": np.mean, "sum": np.sum,
              "absmax": lambda a: np.max(np.abs(a)), "norm": np.linalg.norm}
"""The reductions a file measure may apply to an array."""

_FILE_MEASURE = re.compile(r"^(?:(?P<fn>\w+)\((?P<inner>.*)\)|(?P<plain>.*))$")
_INDEXED = re.compile(r"^(?P<path>[\w/.-]+?)(?:\[(?P<index>[-\d\s,]+)\])?$")


def parse_file_measure(expr: str) -> tuple[str | None, str, tuple[int, ...]]:
    """``'max(steps/last/contact/1/p_n)'`` -> (reduction, HDF5 path, index); ValueError
    for a malformed one. See :func:`file_measure`."""
    m = _FILE_MEASURE.match(expr.strip())
    fn = m.group("fn") if m else None
    body = (m.group("inner") if fn else m.group("plain")).strip() if m else ""
    if fn is not None and fn not in REDUCTIONS:
        raise ValueError(f"unknown reduction {fn!r} in {expr!r} (known: {', '.join(REDUCTIONS)})")
    k = _INDEXED.match(body)
    if not k or not k.group("path").strip("/"):
        raise ValueError(f"{expr!r} is not [reduction(]path[index][)], e.g. "
                         f"'steps/last/contact/1/force[1]' or 'max(steps/last/contact/1/p_n)'")
    index = tuple(int(i) for i in k.group("index").split(",")) if k.group("index") else ()
    return fn, k.group("path").strip("/"), index


def file_measure(path: Path, expr: str) -> float:
    """A number read from a result file (docs/hdf5.md): ``[reduction(]path[index][)]``.
    ``path`` is an HDF5 dataset or attribute (the last component may name an attribute
    of the group before it), from the root; ``steps/last`` (or ``steps/-k``) is the
    last (k-th last) converged step's group. ``index`` picks an element (0-based, in
    h5py's shape: ``steps/last/reactions[0,1]`` is y of the first Dirichlet condition);
    ``reduction`` (max, min, mean, sum, absmax, norm) turns an array into a number.
    KeyError when the file has no such path, ValueError when the value is not one
    number."""
    import h5py

    fn, hpath, index = parse_file_measure(expr)
    parts = hpath.split("/")
    with h5py.File(path, "r") as f:
        if parts[0] == "steps" and len(parts) > 1 and (parts[1] == "last" or parts[1].startswith("-")):
            names = sorted(f["steps"]) if "steps" in f else []
            back = 1 if parts[1] == "last" else -int(parts[1])
            if not names or back > len(names):
                raise KeyError("no such converged step")
            parts[1] = names[-back]
        group, last = "/".join(parts[:-1]) or "/", parts[-1]
        if "/".join(parts) in f:
            value = np.asarray(f["/".join(parts)][()])
        elif group in f and last in f[group].attrs:
            value = np.asarray(f[group].attrs[last])
        else:
            raise KeyError(f"no {hpath!r} in the result")
    if value.dtype.kind in "SUO":
        raise ValueError(f"{hpath!r} is not a number")
    if index:
        value = value[index]
    if fn is not None:
        value = np.asarray(REDUCTIONS[fn](value))
    if value.size != 1:
        raise ValueError(f"{expr!r} is an array of shape {value.shape}: index or reduce it")
    return float(value.reshape(()))


__all__ = ["detrended_amplitude", "file_measure", "fit_hertz", "hertz3d_measures", "hertz_measures",
           "ironing3d_measures", "ironing_measures", "measures_for", "parse_file_measure", "profile_error",
           "rings_measures"]
