"""Rigid obstacles of a solid case: NURBS surfaces of the geometry file
(``/surfaces/<name>``, ``&contact rigid_surface``; docs/formats.md). A surface's normal
``d/dxi x d/deta`` points out of the obstacle (voiga's side convention, as a body's
contact face's points out of the body).

:func:`sphere_cap` is the exact spherical indenter around its lowest point, parametrized
as a surface of revolution about the x axis so that the contact point is regular (a
revolution about z would put a pole there); :func:`flat` a bilinear plane patch.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import h5py
import numpy as np


@dataclass(frozen=True)
class RigidSurface:
    """A NURBS surface in 3D: degrees (p, q), knot vectors, control points
    (n_eta, n_xi, 3) and weights (n_eta, n_xi), xi fastest."""

    degree: tuple[int, int]
    knots_xi: np.ndarray
    knots_eta: np.ndarray
    control_points: np.ndarray
    weights: np.ndarray

    def evaluate(self, xi: float, eta: float) -> np.ndarray:
        """The point at (xi, eta) (rational tensor product, by de Boor per direction)."""
        bu = _basis(self.knots_xi, self.degree[0], xi)
        bv = _basis(self.knots_eta, self.degree[1], eta)
        w = np.einsum("j,i,ji->ji", bv, bu, self.weights)
        return np.einsum("ji,jic->c", w, self.control_points) / w.sum()


def _basis(knots: np.ndarray, p: int, u: float) -> np.ndarray:
    """All B-spline basis values of degree p at u (Cox-de Boor, u = 1 in the last span)."""
    n = len(knots) - p - 1
    b = np.array([1.0 if (knots[i] <= u < knots[i + 1]) or (u == knots[-1] and knots[i] < u <= knots[i + 1])
                  else 0.0 for i in range(len(knots) - 1)])
    for k in range(1, p + 1):
        nb = np.zeros(len(knots) - 1 - k)
        for i in range(len(nb)):
            a = (u - knots[i]) / (knots[i + k] - knots[i]) * b[i] if knots[i + k] > knots[i] else 0.0
            c = (knots[i + k + 1] - u) / (knots[i + k + 1] - knots[i + 1]) * b[i + 1] \
                if knots[i + k + 1] > knots[i + 1] else 0.0
            nb[i] = a + c
        b = nb
    return b[:n]


def _arc(a0: float, a1: float) -> tuple[np.ndarray, np.ndarray]:
    """The unit-circle arc from angle a0 to a1 (radians, at most pi/2 apart) as a rational
    quadratic: control points (3, 2) (cos, sin) and weights (3,)."""
    if not 0 < a1 - a0 <= math.pi / 2 + 1e-12:
        raise ValueError(f"an arc of {math.degrees(a1 - a0):g} degrees: need more than 0 and at most 90")
    h = 0.5 * (a1 - a0)
    m = 0.5 * (a0 + a1)
    cp = np.array([[math.cos(a0), math.sin(a0)], [math.cos(m) / math.cos(h), math.sin(m) / math.cos(h)],
                   [math.cos(a1), math.sin(a1)]])
    return cp, np.array([1.0, math.cos(h), 1.0])


def sphere_cap(radius: float, centre: Sequence[float], half_angle: float = 30.0) -> RigidSurface:
    """The part of the sphere (``radius``, ``centre``) within ``half_angle`` degrees (in
    each of two directions, at most 45) of its lowest point ``centre - radius e_z``:
    x = c_x + R cos(theta), (y, z) = c_yz + R sin(theta) (cos(phi), sin(phi)), theta in
    90 +- half_angle, phi in -90 +- half_angle; exact, degree 2 rational. Its normal points
    out of the ball (-z at the lowest point): an indenter pressed down onto a body below."""
    if radius <= 0 or not 0 < half_angle <= 45:
        raise ValueError("sphere cap: need radius > 0 and 0 < half_angle <= 45 degrees")
    t = math.radians(half_angle)
    meridian, wm = _arc(math.pi / 2 - t, math.pi / 2 + t)        # (x, r) = (cos, sin) theta
    circle, wc = _arc(-math.pi / 2 - t, -math.pi / 2 + t)         # (y, z) / r = (cos, sin) phi
    cp = np.zeros((3, 3, 3))
    for j in range(3):        # eta: phi
        for i in range(3):    # xi: theta
            cp[j, i] = [meridian[i, 0], meridian[i, 1] * circle[j, 0], meridian[i, 1] * circle[j, 1]]
    cp = np.asarray(centre, dtype=float) + radius * cp
    knots = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])
    return RigidSurface((2, 2), knots, knots.copy(), cp, np.outer(wc, wm))


def flat(x: Sequence[float], y: Sequence[float], z: float) -> RigidSurface:
    """The rectangle [x0, x1] x [y0, y1] at height z, normal +z (an obstacle below it)."""
    cp = np.array([[[x[0], y[0], z], [x[1], y[0], z]], [[x[0], y[1], z], [x[1], y[1], z]]], dtype=float)
    knots = np.array([0.0, 0.0, 1.0, 1.0])
    return RigidSurface((1, 1), knots, knots.copy(), cp, np.ones((2, 2)))


def write_surface(group: h5py.Group, surface: RigidSurface) -> None:
    """Write ``surface`` into ``group`` (docs/formats.md, ``/surfaces/<name>``)."""
    group.create_dataset("degree", data=np.asarray(surface.degree, dtype=np.int32))
    group.create_dataset("knots_xi", data=np.asarray(surface.knots_xi, dtype=np.float64))
    group.create_dataset("knots_eta", data=np.asarray(surface.knots_eta, dtype=np.float64))
    group.create_dataset("control_points", data=np.asarray(surface.control_points, dtype=np.float64))
    group.create_dataset("weights", data=np.asarray(surface.weights, dtype=np.float64))


def add_surfaces(path: str, surfaces: dict[str, RigidSurface]) -> None:
    """Add ``surfaces`` to the geometry file of volumes at ``path`` (``/surfaces``)."""
    with h5py.File(path, "r+") as f:
        if int(f.attrs.get("dimension", 2)) != 3:
            raise ValueError(f"{path}: rigid surfaces belong to a geometry file of volumes (dimension 3)")
        g = f.require_group("surfaces")
        for name, s in surfaces.items():
            if name in g:
                raise ValueError(f"{path}: a surface {name!r} is there already")
            write_surface(g.create_group(name), s)
