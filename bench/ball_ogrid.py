"""An O-grid hexahedral mesh of the ball octant for the peers (section 9): element edges
near the contact on circles about the vertical axis through the contact point (0, 0, -R),
the zone's edge r = a among them, as voiga's polar grid (``pre hertz3d --grid polar``).

Spec ``o<core>x<fine>x<rest>x<radial>x<edge>``, e.g. ``o4x12x6x10x2``, in a peer run of
:data:`bench.ball_section.PEER_RUNS` as ``kratos:alm:amgcl:o4x12x6x10x2`` or
``ccx:C3D8I:o4x12x6x10x2:1e5``; :func:`parse_mesh` takes it or a :class:`BallMesh` spec.

The blocks are :mod:`bench.ball_mesh`'s (a core cube ``[0, c] x [0, c] x [-c, 0]`` and
three cube-sphere shells, a shell point ``((1 - w) c + w / |v|) v``), but the z shell (the
one under the core, which holds the contact) and the core are meshed in the plane of
``t = (x, y) / |z|`` (the tangents of the shell's two angles) by an O-grid instead of a
tensor grid. A point of the z shell lies on the ray through ``v = (t, 1)``, so ``|t| =
const`` is a circle about the axis on the sphere (r = |t| / sqrt(1 + |t|^2)) and on every
layer w; ``|t| = tan(theta)``, theta the angle of the sphere point from the contact.

The O-grid of the unit square of t (three blocks, ``core`` elements along every side of
the core and over every 45 degrees of a ring):

- a core square ``[0, s]^2``, s = :data:`CORE_HALF` a_est (a_est = sqrt(R d)), nodes
  ``s (tan phi_i, tan phi_j)``, phi uniform over [0, 45] degrees;
- rings: node j of a ring on the ray at the angle phi_j (0 to 90 degrees), at the distance
  ``(1 - u) (tan theta + (1 - beta) s (1 / cos - 1)) + u / cos`` (cos of phi_j, or of
  90 - phi_j above 45 degrees). The ``fine`` rings (u = 0) are uniform in theta from the
  core's edge atan(s) to theta_c = asin(1.5 a_est); the bulge of the core's square fades
  out (beta from 0 at the core linearly in theta to 1 at :data:`TRANSITION` a_est), so
  from there on they are circles; those overlapping :data:`pre.hertz.EDGE_BAND` of a_est
  (0.9 to 1.1) are split into ``edge``. The ``rest`` rings (theta = theta_c, beta = 1) go
  from the circle to the square's outer edges t1 = 1, t2 = 1 (u from 0 to 1, graded
  geometrically from a fine ring's size).

The core cube carries the O-grid (times c) through ``core`` layers (tan of uniform angles,
z = -c tan C); the x and y shells are tensor grids of the rings' phi (as ``tan phi``)
and of the same C, so they match the core's and the z shell's faces; w has ``radial``
elements graded toward the sphere, the outer one about as thick as a fine ring. Quadratic
meshes (C3D20R) put the mid-side nodes at the midpoints of phi, theta, u, C and w and
evaluate the map there (mid-side nodes on the sphere lie on it, those of the circular
rings on their circles). Nodes shared by the blocks are merged
(:func:`bench.ball_mesh.merge`); element node order, faces and node sets are
:func:`bench.ball_mesh.ball_octant`'s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pre.hertz import EDGE_BAND
from pre.meshes import geometric_sizes, graded_angles

from .ball_mesh import (
    CORE,
    INDENT,
    RADIUS,
    THETA_C,
    BallMesh,
    ball_octant,
    grid_elements,
    grid_ids,
    merge,
    refine,
    right_handed,
)

A_EST = math.sqrt(RADIUS * INDENT)
"""Hertz's contact radius for the approach d (the runs' a is 1.8 % larger)."""
CORE_HALF = 0.4
"""The O-grid's core square's half-width over a_est (its corner at 0.57 a_est)."""
TRANSITION = 0.8
"""The rings are circles from this fraction of a_est on (below it the core's square
fades into them)."""


@dataclass(frozen=True)
class OGridMesh:
    """Elements of an O-grid mesh (module docstring)."""

    core: int
    fine: int
    rest: int
    radial: int
    edge: int = 1

    @classmethod
    def parse(cls, spec: str) -> OGridMesh:
        """``'o4x8x6x8x2'`` -> OGridMesh(4, 8, 6, 8, 2) (core x fine x rest x radial x edge)."""
        body = spec.lower()
        try:
            if not body.startswith("o"):
                raise ValueError
            c, f, r, d, e = (int(v) for v in body[1:].split("x"))
        except ValueError as err:
            raise ValueError(f"O-grid mesh {spec!r}: expected o<core>x<fine>x<rest>x<radial>x<edge>, "
                             "e.g. o4x8x6x8x2") from err
        if min(c, f, r, d, e) < 1:
            raise ValueError(f"O-grid mesh {spec!r}: every count >= 1")
        return cls(c, f, r, d, e)

    @property
    def name(self) -> str:
        return f"o{self.core}x{self.fine}x{self.rest}x{self.radial}x{self.edge}"

    @property
    def theta0(self) -> float:
        """The core square's edge on the axis's plane (atan s)."""
        return math.atan(CORE_HALF * A_EST / RADIUS)

    @property
    def ring_size(self) -> float:
        """A fine ring's size in theta (radians) before the edge split."""
        return (THETA_C - self.theta0) / self.fine

    def phi(self) -> np.ndarray:
        """Ring nodes' angles about the axis over [0, 45] degrees."""
        return np.linspace(0.0, math.pi / 4, self.core + 1)

    def fine_theta(self) -> np.ndarray:
        """The fine rings' theta from the core's edge to theta_c, those overlapping the
        edge band split into ``edge``."""
        t = np.linspace(self.theta0, THETA_C, self.fine + 1)
        lo, hi = (math.asin(f * A_EST / RADIUS) for f in EDGE_BAND)
        out = [t[0]]
        for t0, t1 in zip(t[:-1], t[1:], strict=True):
            n = self.edge if (t1 > lo and t0 < hi) else 1
            out.extend(t0 + (t1 - t0) * np.arange(1, n + 1) / n)
        return np.array(out)

    def rest_u(self) -> np.ndarray:
        """u of the rest rings, 0 (the circle theta_c) to 1 (the square's edges), the
        first step a fine ring's size along the x axis."""
        h = self.ring_size / (1.0 - math.tan(THETA_C))
        if self.rest * h >= 1.0:
            return np.linspace(0.0, 1.0, self.rest + 1)
        u = np.concatenate([[0.0], np.cumsum(geometric_sizes(self.rest, h, 1.0))])
        u[-1] = 1.0
        return u

    def rings(self) -> tuple[np.ndarray, np.ndarray]:
        """(theta, u) of every ring from the core's edge out."""
        th, u = self.fine_theta(), self.rest_u()
        return (np.concatenate([th, np.full(len(u) - 1, THETA_C)]),
                np.concatenate([np.zeros(len(th)), u[1:]]))

    def angles_c(self) -> np.ndarray:
        """The core's layers and the x and y shells' C: ``core`` uniform angles."""
        return np.linspace(0.0, math.pi / 4, self.core + 1)

    def radial_w(self) -> np.ndarray:
        """w as :meth:`BallMesh.radial_w` with the outer element a fine ring's size."""
        return _radial_w(self.radial, self.ring_size)

    def angles_ab(self) -> np.ndarray:
        """Angles from the contact with the fine rings' spacing over theta_c, growing
        beyond (the flat's grid, :func:`bench.ball_mesh.flat_grid`)."""
        n = max(1, round(THETA_C / self.ring_size))
        return np.concatenate([[0.0], graded_angles(THETA_C, n, self.rest, sweep=math.pi / 4)])


def _radial_w(radial: int, size: float) -> np.ndarray:
    h = RADIUS * size / (RADIUS - CORE)
    if radial * h >= 1.0:
        return np.linspace(0.0, 1.0, radial + 1)
    w = 1.0 - np.concatenate([[0.0], np.cumsum(geometric_sizes(radial, h, 1.0))])
    w[-1] = 0.0
    return w[::-1]


def parse_mesh(spec: str) -> BallMesh | OGridMesh:
    """An O-grid spec (``o...``) or a cube-sphere one (:meth:`BallMesh.parse`)."""
    return OGridMesh.parse(spec) if spec.lower().startswith("o") else BallMesh.parse(spec)


def octant(mesh: BallMesh | OGridMesh, quadratic: bool = False) -> dict:
    """The ball octant of either kind of mesh (:func:`bench.ball_mesh.ball_octant`'s dict)."""
    if isinstance(mesh, OGridMesh):
        return ogrid_octant(mesh, quadratic)
    return ball_octant(mesh, quadratic)


def _bulge(theta: np.ndarray) -> np.ndarray:
    """1 - beta: the share of the core's square left in a fine ring at theta."""
    t0 = math.atan(CORE_HALF * A_EST / RADIUS)
    t1 = math.asin(TRANSITION * A_EST / RADIUS)
    return np.clip((t1 - theta) / (t1 - t0), 0.0, 1.0)


def ring_block(phi: np.ndarray, theta: np.ndarray, u: np.ndarray) -> np.ndarray:
    """t (len(phi), len(theta), 2) of a ring block over phi in [0, 45] degrees: along the
    ray phi, the distance of the module docstring (rings theta, u)."""
    s = CORE_HALF * A_EST / RADIUS
    sec = 1.0 / np.cos(phi)[:, None]
    circle = np.tan(theta)[None, :] + _bulge(theta)[None, :] * s * (sec - 1.0)
    d = (1.0 - u[None, :]) * circle + u[None, :] * sec
    t = np.stack([d * np.cos(phi)[:, None], d * np.sin(phi)[:, None]], axis=-1)
    t[:, u == 1.0, 0] = 1.0  # the square's edge exactly
    t[-1, :, 1] = t[-1, :, 0]  # phi = 45 degrees: on the diagonal exactly
    return t


def ogrid_plane(mesh: OGridMesh, quadratic: bool) -> list[np.ndarray]:
    """The O-grid's three blocks as arrays (n1, n2, 2) of t: the core square and the
    ring blocks below and above the diagonal."""
    phi = refine(mesh.phi(), quadratic)
    theta, u = mesh.rings()
    theta, u = refine(theta, quadratic), refine(u, quadratic)
    s = CORE_HALF * A_EST / RADIUS
    tp = np.tan(phi)
    tp[-1] = 1.0
    g1, g2 = np.meshgrid(s * tp, s * tp, indexing="ij")
    core = np.stack([g1, g2], axis=-1)
    low = ring_block(phi, theta, u)
    high = low[..., ::-1]  # mirrored in the diagonal: t2 <-> t1 (phi -> 90 - phi)
    return [core, low, high]


def ogrid_octant(mesh: OGridMesh, quadratic: bool = False) -> dict:
    """The ball octant's O-grid mesh; the dict of :func:`bench.ball_mesh.ball_octant`."""
    w = refine(mesh.radial_w(), quadratic)
    cc = refine(mesh.angles_c(), quadratic)
    tc = np.tan(cc)
    tc[-1] = 1.0
    tp = np.tan(refine(mesh.phi(), quadratic))
    tp[-1] = 1.0
    pts, conns, shell = [], [], []
    offset = 0

    def add(points: np.ndarray, is_shell: bool) -> None:
        nonlocal offset
        ids = grid_ids(points.shape[:3], quadratic, offset)
        keep = ids >= 0
        pts.append(points[keep])
        offset += int(keep.sum())
        e = grid_elements(ids, quadratic)
        conns.append(e)
        shell.append(np.full(len(e), is_shell))

    # pole at +z (mirrored at the end); the z shell and the core over the O-grid's blocks
    for block in ogrid_plane(mesh, quadratic):
        v = np.concatenate([block, np.ones((*block.shape[:2], 1))], axis=-1)
        norm = np.linalg.norm(v, axis=-1)
        scale = (1.0 - w)[None, None, :] * CORE + w[None, None, :] * RADIUS / norm[..., None]
        add(scale[..., None] * v[:, :, None, :], True)
        core = np.empty((*block.shape[:2], len(tc), 3))
        core[..., :2] = CORE * block[:, :, None, :]
        core[..., 2] = CORE * tc[None, None, :]
        add(core, False)
    # the x and y shells: the axis component 1, tan phi and tan C
    for axis in (0, 1):
        g1, g2, g3 = np.meshgrid(tp, tc, w, indexing="ij")
        v = np.empty((*g1.shape, 3))
        v[..., axis], v[..., 1 - axis], v[..., 2] = 1.0, g1, g2
        norm = np.sqrt(1.0 + g1 * g1 + g2 * g2)
        scale = (1.0 - g3) * CORE + g3 * RADIUS / norm
        add(scale[..., None] * v, True)
    points = np.concatenate(pts)
    points[np.abs(points) < 1e-15] = 0.0
    points[:, 2] *= -1.0  # the lower hemisphere
    conn = np.concatenate(conns)
    nodes, conn = merge(points, conn)
    on_sphere = np.abs(np.linalg.norm(nodes, axis=1) - RADIUS) <= 1e-12
    nodes[on_sphere] /= np.linalg.norm(nodes[on_sphere], axis=1)[:, None]
    conn = right_handed(nodes, conn)
    is_shell = np.concatenate(shell)
    outer = is_shell & on_sphere[conn[:, 4:8]].all(axis=1)
    face_cols = [4, 5, 6, 7] + ([12, 13, 14, 15] if quadratic else [])
    return {"nodes": nodes, "elements": conn, "surface": conn[outer][:, face_cols],
            "surface_elements": np.flatnonzero(outer),
            "x0": np.flatnonzero(nodes[:, 0] == 0.0), "y0": np.flatnonzero(nodes[:, 1] == 0.0),
            "top": np.flatnonzero(nodes[:, 2] == 0.0), "sphere": np.flatnonzero(on_sphere),
            "quadratic": quadratic}
