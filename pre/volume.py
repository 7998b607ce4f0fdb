"""Trivariate NURBS bodies (volumes) in the voiga layout, their evaluation, and
:func:`check_volume`, the 3D counterpart of :func:`pre.geometry.check_patch`.

A :class:`Volume` keeps Cartesian control points ``(n_zeta, n_eta, n_xi, 3)`` and
weights ``(n_zeta, n_eta, n_xi)``: the axis order of the geometry file
(``docs/formats.md``, "Geometry HDF5"; xi fastest in memory). Its six faces are named
by the keys of :data:`FACE_KEYS`; by convention the contact face is ``zeta = 1``.

Evaluation (points and the Jacobian dX/d(xi, eta, zeta)) is numpy code on scipy's
B-spline basis, not splipy's: so that the tests' comparisons with splipy volumes (the
same body built with ``splipy.volume_factory``, and splipy's knot insertion and order
elevation of ours) check the conversion and the builders against an independent
implementation. :func:`volume_to_splipy` / :func:`volume_from_splipy` are the only
translation to and from splipy's projective ``(n_xi, n_eta, n_zeta, 4)`` control points.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

import numpy as np
import splipy
from scipy.interpolate import BSpline

FACE_KEYS: tuple[str, ...] = ("xi0", "xi1", "eta0", "eta1", "zeta0", "zeta1")
"""Face keys: ``xi = 0``, ``xi = 1``, ``eta = 0``, ``eta = 1``, ``zeta = 0``, ``zeta = 1``."""

DIRECTIONS = ("xi", "eta", "zeta")

SAMPLES_PER_SPAN = 8
"""det J is sampled at this many interior points per knot span and direction."""

DET_TOL = 1e-10
"""det J must exceed this fraction of its largest value at every sample."""

MAX_NAME = 32
"""Longest face name (characters), as for 2D edge names."""


@dataclass
class Volume:
    """A trivariate NURBS patch in the voiga layout (numpy axis order: zeta, eta, xi)."""

    degree: tuple[int, int, int]
    knots_xi: np.ndarray
    knots_eta: np.ndarray
    knots_zeta: np.ndarray
    control_points: np.ndarray  # (n_zeta, n_eta, n_xi, 3), Cartesian
    weights: np.ndarray  # (n_zeta, n_eta, n_xi)
    faces: dict[str, str] = field(default_factory=dict)  # FACE_KEYS -> name

    def __post_init__(self) -> None:
        if len(self.degree) != 3:
            raise ValueError(f"a volume has 3 degrees, got {self.degree}")
        self.degree = (int(self.degree[0]), int(self.degree[1]), int(self.degree[2]))
        self.knots_xi = np.asarray(self.knots_xi, dtype=float)
        self.knots_eta = np.asarray(self.knots_eta, dtype=float)
        self.knots_zeta = np.asarray(self.knots_zeta, dtype=float)
        self.control_points = np.asarray(self.control_points, dtype=float)
        self.weights = np.asarray(self.weights, dtype=float)
        if self.weights.ndim != 3:
            raise ValueError(f"weights must be (n_zeta, n_eta, n_xi), got shape {self.weights.shape}")
        if self.control_points.shape != (*self.weights.shape, 3):
            raise ValueError(f"control_points shape {self.control_points.shape} does not match "
                             f"weights {self.weights.shape} (need (n_zeta, n_eta, n_xi, 3))")
        n_zeta, n_eta, n_xi = self.weights.shape
        for d, (knots, n) in enumerate(zip(self.knots, (n_xi, n_eta, n_zeta), strict=True)):
            if len(knots) != n + self.degree[d] + 1:
                raise ValueError(f"knots_{DIRECTIONS[d]} length {len(knots)} != n + p + 1 = "
                                 f"{n + self.degree[d] + 1}")

    @property
    def knots(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(knots_xi, knots_eta, knots_zeta)``."""
        return self.knots_xi, self.knots_eta, self.knots_zeta

    @property
    def shape(self) -> tuple[int, int, int]:
        """``(n_zeta, n_eta, n_xi)``."""
        return self.weights.shape  # type: ignore[return-value]

    def face_key(self, name: str) -> str:
        """The face key (``'zeta1'``...) of the face called ``name``."""
        for key, value in self.faces.items():
            if value == name:
                return key
        raise KeyError(f"no face named {name!r} (faces: {self.faces})")

    def renamed(self, names: dict[str, str] | None) -> Volume:
        """The volume with faces renamed: ``names`` maps a current face name to a new
        one (a name that is not a face's is an error)."""
        names = dict(names or {})
        unknown = set(names) - set(self.faces.values())
        if unknown:
            raise ValueError(f"unknown face(s) {sorted(unknown)}; the faces are {list(self.faces.values())}")
        faces = {k: names.get(v, v) for k, v in self.faces.items()}
        return Volume(self.degree, *self.knots, self.control_points, self.weights, faces)


# -- splipy -----------------------------------------------------------------------------

def _splipy_basis(degree: int, knots: np.ndarray) -> splipy.BSplineBasis:
    return splipy.BSplineBasis(order=degree + 1, knots=np.asarray(knots, dtype=float))


def volume_to_splipy(vol: Volume) -> splipy.Volume:
    """A rational splipy volume (projective control points ``(n_xi, n_eta, n_zeta, 4)``)."""
    w = vol.weights.transpose(2, 1, 0)[..., None]
    xyz = vol.control_points.transpose(2, 1, 0, 3)
    proj = np.concatenate([xyz * w, w], axis=-1)
    bases = [_splipy_basis(p, k) for p, k in zip(vol.degree, vol.knots, strict=True)]
    return splipy.Volume(*bases, proj, rational=True, raw=True)


def volume_from_splipy(spline: splipy.Volume, faces: dict[str, str] | None = None) -> Volume:
    """Back from a splipy volume (rational or not, 3D control points) to a :class:`Volume`."""
    if spline.dimension != 3:
        raise ValueError(f"a volume needs 3D control points, the splipy volume has {spline.dimension}")
    cp = np.asarray(spline.controlpoints, dtype=float)  # (n_xi, n_eta, n_zeta, 3[+1])
    if spline.rational:
        w = cp[..., -1]
        xyz = cp[..., :3] / w[..., None]
    else:
        w = np.ones(cp.shape[:3])
        xyz = cp[..., :3]
    bases = spline.bases
    return Volume(degree=tuple(b.order - 1 for b in bases),  # type: ignore[arg-type]
                  knots_xi=np.array(bases[0].knots, dtype=float),
                  knots_eta=np.array(bases[1].knots, dtype=float),
                  knots_zeta=np.array(bases[2].knots, dtype=float),
                  control_points=xyz.transpose(2, 1, 0, 3).copy(),
                  weights=w.transpose(2, 1, 0).copy(), faces=dict(faces or {}))


# -- evaluation (numpy on scipy's B-spline basis) ---------------------------------------

def basis(degree: int, knots: np.ndarray, t: np.ndarray, nu: int = 0) -> np.ndarray:
    """B-spline basis functions (``nu``-th derivative) at the parameters ``t`` ->
    ``(len(t), n)``; ``t = 1`` (the end of an open knot vector) included."""
    knots = np.asarray(knots, dtype=float)
    n = len(knots) - degree - 1
    spline = BSpline(knots, np.eye(n), degree, extrapolate=True)
    return np.asarray(spline(np.asarray(t, dtype=float), nu=nu)).reshape(len(np.atleast_1d(t)), n)


def _homogeneous(vol: Volume) -> np.ndarray:
    """``(n_zeta, n_eta, n_xi, 4)``: ``(w x, w y, w z, w)``."""
    w = vol.weights[..., None]
    return np.concatenate([vol.control_points * w, w], axis=-1)


def _bases(vol: Volume, xi: np.ndarray, eta: np.ndarray, zeta: np.ndarray) -> list[list[np.ndarray]]:
    """Values and first derivatives of the basis of each direction at its parameters."""
    return [[basis(p, k, t, nu) for nu in (0, 1)]
            for p, k, t in zip(vol.degree, vol.knots, (xi, eta, zeta), strict=True)]


def _map(vol: Volume, b: list[list[np.ndarray]], pattern: str) -> tuple[np.ndarray, np.ndarray]:
    """Points and Jacobians from the bases ``b`` (``pattern``: einsum of one contraction,
    pointwise ``'ai,aj,ak,kjid->ad'`` or tensor ``'ci,bj,ak,kjid->abcd'``)."""
    pw = _homogeneous(vol)
    (nx, dnx), (ne, dne), (nz, dnz) = b
    s = np.einsum(pattern, nx, ne, nz, pw, optimize=True)
    ds = [np.einsum(pattern, *bs, pw, optimize=True)
          for bs in ((dnx, ne, nz), (nx, dne, nz), (nx, ne, dnz))]
    w = s[..., 3:]
    x = s[..., :3] / w
    jac = np.stack([(d[..., :3] - x * d[..., 3:]) / w for d in ds], axis=-1)  # [..., i, j] = dx_i/du_j
    return x, jac


def evaluate(vol: Volume, xi: np.ndarray, eta: np.ndarray, zeta: np.ndarray) -> np.ndarray:
    """Points of ``vol`` at the parameter triples ``(xi[i], eta[i], zeta[i])`` -> (n, 3)."""
    return jacobian(vol, xi, eta, zeta)[0]


def jacobian(vol: Volume, xi: np.ndarray, eta: np.ndarray,
             zeta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points (n, 3) and Jacobians (n, 3, 3), ``J[:, i, j] = dx_i/du_j`` with
    ``u = (xi, eta, zeta)``, at the parameter triples ``(xi[i], eta[i], zeta[i])``."""
    b = _bases(vol, *(np.atleast_1d(np.asarray(t, dtype=float)) for t in (xi, eta, zeta)))
    return _map(vol, b, "ai,aj,ak,kjid->ad")


def jacobian_grid(vol: Volume, xi: np.ndarray, eta: np.ndarray,
                  zeta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points ``(n_zeta, n_eta, n_xi, 3)`` and Jacobians ``(..., 3, 3)`` on the tensor
    grid of the three parameter lists (axis order of the file: zeta, eta, xi)."""
    b = _bases(vol, np.asarray(xi, float), np.asarray(eta, float), np.asarray(zeta, float))
    return _map(vol, b, "ci,bj,ak,kjid->abcd")


def spans(knots: np.ndarray) -> list[tuple[float, float]]:
    """The knot spans of non-zero length, ``(start, end)``."""
    u = np.unique(np.asarray(knots, dtype=float))
    return [(float(a), float(b)) for a, b in zip(u[:-1], u[1:], strict=True)]


def span_samples(knots: np.ndarray, n: int = SAMPLES_PER_SPAN) -> np.ndarray:
    """``n`` interior points ``(k + 1/2)/n`` of every knot span (never a breakpoint)."""
    frac = (np.arange(n) + 0.5) / n
    return np.concatenate([a + (b - a) * frac for a, b in spans(knots)])


def _gauss(knots: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = np.polynomial.legendre.leggauss(n)
    pts, wts = [], []
    for a, b in spans(knots):
        pts.append(0.5 * (a + b) + 0.5 * (b - a) * x)
        wts.append(0.5 * (b - a) * w)
    return np.concatenate(pts), np.concatenate(wts)


def enclosed_volume(vol: Volume, n: int = 16) -> float:
    """The body's volume: det J integrated by ``n``-point Gauss-Legendre quadrature in
    every knot span and direction."""
    (gx, wx), (ge, we), (gz, wz) = (_gauss(k, n) for k in vol.knots)
    total = 0.0
    for z, w in zip(gz, wz, strict=True):  # one zeta layer at a time (memory)
        det = np.linalg.det(jacobian_grid(vol, gx, ge, np.array([z]))[1][0])
        total += w * float(np.einsum("b,c,bc->", we, wx, det))
    return total


# -- checks -----------------------------------------------------------------------------

def check_knots(name: str, what: str, knots: np.ndarray, degree: int) -> None:
    """The rules of the geometry file for one knot vector (``docs/formats.md``): finite,
    non-decreasing, from 0 to 1, open (ends exactly ``p + 1`` times), interior knots at
    most ``p`` times."""
    k = np.asarray(knots, dtype=float)
    if not np.all(np.isfinite(k)) or np.any(np.diff(k) < 0):
        raise ValueError(f"body {name!r}: {what} must be finite and non-decreasing")
    if k[0] != 0.0 or k[-1] != 1.0:
        raise ValueError(f"body {name!r}: {what} must span [0, 1], got [{k[0]}, {k[-1]}]")
    values, counts = np.unique(k, return_counts=True)
    if counts[0] != degree + 1 or counts[-1] != degree + 1:
        raise ValueError(f"body {name!r}: {what} must be open: 0 and 1 exactly p + 1 = {degree + 1} "
                         f"times, got {counts[0]} and {counts[-1]}")
    if len(counts) > 2 and counts[1:-1].max() > degree:
        bad = values[1:-1][counts[1:-1] > degree][0]
        raise ValueError(f"body {name!r}: {what}: interior knot {bad} repeated more than p = {degree} times")


def _det_chunks(vol: Volume, n: int) -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """``(zeta values, eta, xi, det J (zeta, eta, xi))`` over the sample grid, one
    zeta span at a time (C order of the file's axes within and across chunks)."""
    sx, se = span_samples(vol.knots_xi, n), span_samples(vol.knots_eta, n)
    sz = span_samples(vol.knots_zeta, n)
    for start in range(0, len(sz), n):
        z = sz[start:start + n]
        yield z, se, sx, np.linalg.det(jacobian_grid(vol, sx, se, z)[1])


def check_volume(name: str, vol: Volume, n: int = SAMPLES_PER_SPAN) -> None:
    """Raise ValueError naming ``name`` and the cause when the solver cannot use the
    volume: degrees not 1-20, knot vectors against the file's rules, non-finite control
    points, weights not positive and finite, faces not six different names of 1-32
    ASCII characters, or a map that is not right-handed and regular: det J, sampled at
    ``n x n x n`` interior points of every knot span (collapsed boundary faces and
    edges, as at a sphere's pole, are allowed), must exceed 1e-10 of its largest
    value everywhere. The message names the first bad sample (zeta slowest, xi fastest)
    and tells a volume that folds over or degenerates from one inside out (det J < 0
    everywhere: a left-handed parametrization)."""
    if any(not 1 <= p <= 20 for p in vol.degree):
        raise ValueError(f"body {name!r}: degrees must be 1 to 20, got {list(vol.degree)}")
    for d, (knots, p) in enumerate(zip(vol.knots, vol.degree, strict=True)):
        check_knots(name, f"knots_{DIRECTIONS[d]}", knots, p)
    if not np.all(np.isfinite(vol.control_points)):
        raise ValueError(f"body {name!r}: control points must be finite")
    if not np.all(np.isfinite(vol.weights)) or np.any(vol.weights <= 0):
        raise ValueError(f"body {name!r}: weights must be finite and positive")
    names = [vol.faces.get(k, "") for k in FACE_KEYS]
    if (any(not 1 <= len(f) <= MAX_NAME or not f.isascii() for f in names) or len(set(names)) != 6):
        raise ValueError(f"body {name!r}: the six faces need six different names of 1 to {MAX_NAME} "
                         f"ASCII characters (xi0, xi1, eta0, eta1, zeta0, zeta1), got {names}")
    chunks = list(_det_chunks(vol, n))
    scale = max(float(np.abs(det).max()) for *_, det in chunks)
    if scale == 0:
        raise ValueError(f"body {name!r}: det J = 0 at every sample: the volume is flat")
    if all(float(det.max()) < -DET_TOL * scale for *_, det in chunks):
        raise ValueError(f"body {name!r}: the volume is inside out: det J < 0 at every sample (xi, eta, "
                         "zeta make a left-handed frame); reverse one parametric direction")
    for z, e, x, det in chunks:
        bad = np.argwhere(det <= DET_TOL * scale)
        if len(bad):
            k, j, i = bad[0]
            point = jacobian(vol, x[i], e[j], z[k])[0][0]
            raise ValueError(f"body {name!r}: the volume folds over itself or degenerates: det J = "
                             f"{det[k, j, i]:.3g} (largest {scale:.3g}) at (xi, eta, zeta) = "
                             f"({x[i]:.4g}, {e[j]:.4g}, {z[k]:.4g}), x = "
                             f"({point[0]:.4g}, {point[1]:.4g}, {point[2]:.4g})")
