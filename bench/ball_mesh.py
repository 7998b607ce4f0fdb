"""Hexahedral meshes of the 3D Hertz scene for the peers (section 9): the ball octant of
``python -m pre hertz3d`` (``x, y >= 0, z <= 0``, ``|X| <= R``, R = 1, the contact
point (0, 0, -1)) and the rigid flat under it as a thin block.

The octant is four blocks (no collapsed face, which neither Kratos's nor CalculiX's
hexahedra take): a core cube ``[0, c] x [0, c] x [-c, 0]`` and three "cube-sphere"
shells between a core face and the part of the sphere centrally projected onto it, one
per axis. A shell point is ``((1 - w) c + w / |v|) v`` for the direction ``v`` whose
component along the block's axis is 1 and whose other two are the tangents of the
block's two angles (in [0, 45] degrees), w in [0, 1] from the core face to the sphere.
The angles come from three 1D distributions shared by the blocks that meet: A (the
angle of x over |z| or y), B (of y over |z| or x), C (of |z| over x or y); the core's
nodes are ``c tan`` of A, B, C. A and B are graded toward the contact point as voiga's
hertz3d meshes: ``fine`` elements uniform in angle over ``theta_c = asin(1.5 a_est)``
(a_est = sqrt(R d) = 0.1), then ``rest`` growing geometrically to 45 degrees
(:func:`pre.meshes.graded_angles`); C is ``outer`` uniform elements; w has ``radial``
elements graded toward the sphere, the outer one as long as a fine element there. A and
B are fine near 0 in the x and y shells too (a strip along the symmetry planes, away
from the contact: the price of conforming blocks).

Quadratic meshes (C3D20R) put the mid-side nodes at the midpoints of the distributions'
angles and of w, so mid-side nodes on the sphere lie on it. Nodes the blocks share are
merged (:func:`merge`). Element node order is CalculiX's (Abaqus's; also Kratos's
Hexahedra3D8 for the corners): face 5-6-7-8 (zeta = +1) is the sphere's in the shells
and the flat's top in the block, counter-clockwise seen from outside.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from pre.meshes import geometric_sizes, graded_angles

from .ccx_sphere import NODES20

RADIUS = 1.0
INDENT = 0.01
THETA_C = math.asin(1.5 * math.sqrt(RADIUS * INDENT))
"""The fine zone's angle, voiga hertz3d's (:func:`pre.meshes.hertz_theta_c` for a_est)."""
CORE = 0.5
"""The core cube's edge c over R."""


@dataclass(frozen=True)
class BallMesh:
    """Elements per distribution (module docstring)."""

    fine: int
    rest: int
    outer: int
    radial: int

    @classmethod
    def parse(cls, spec: str) -> BallMesh:
        """``'8x6x4x8'`` -> BallMesh(8, 6, 4, 8) (fine x rest x outer x radial)."""
        try:
            f, r, o, d = (int(v) for v in spec.lower().split("x"))
        except ValueError as err:
            raise ValueError(f"ball mesh {spec!r}: expected fine x rest x outer x radial, e.g. 8x6x4x8") from err
        if min(f, o, d) < 1 or r < 0:
            raise ValueError(f"ball mesh {spec!r}: fine, outer, radial >= 1, rest >= 0")
        return cls(f, r, o, d)

    @property
    def name(self) -> str:
        return f"{self.fine}x{self.rest}x{self.outer}x{self.radial}"

    def angles_ab(self) -> np.ndarray:
        """The graded distribution A = B, radians, 0 to pi/4."""
        if self.rest == 0:
            return np.linspace(0.0, math.pi / 4, self.fine + 1)
        inner = graded_angles(THETA_C, self.fine, self.rest, sweep=math.pi / 4)
        return np.concatenate([[0.0], inner, [math.pi / 4]])

    def angles_c(self) -> np.ndarray:
        return np.linspace(0.0, math.pi / 4, self.outer + 1)

    def radial_w(self) -> np.ndarray:
        """w from the core (0) to the sphere (1), graded: the outer element as long as a
        fine one (R theta_c / fine) over the shell's thickness on the axis (1 - c)."""
        h = RADIUS * THETA_C / self.fine / (RADIUS - CORE)
        if self.radial * h >= 1.0:
            return np.linspace(0.0, 1.0, self.radial + 1)
        try:
            sizes = geometric_sizes(self.radial, h, 1.0)  # from the sphere inward
        except ValueError as err:  # a growth above 10 per element
            raise ValueError(f"ball mesh {self.name}: too few radial elements for the fine "
                             "size at the sphere") from err
        w = 1.0 - np.concatenate([[0.0], np.cumsum(sizes)])
        w[-1] = 0.0
        return w[::-1]


def refine(t: np.ndarray, quadratic: bool) -> np.ndarray:
    """``t`` with its interval midpoints inserted (quadratic) or as it is."""
    if not quadratic:
        return np.asarray(t, dtype=float)
    out = np.empty(2 * len(t) - 1)
    out[0::2], out[1::2] = t, 0.5 * (t[:-1] + t[1:])
    return out


def local_nodes(quadratic: bool) -> np.ndarray:
    """Grid offsets (0, 1, 2 for quadratic; 0, 1 for linear) of the element's nodes in
    CalculiX's order along (xi, eta, zeta)."""
    if quadratic:
        return NODES20.astype(int) + 1
    return ((NODES20[:8] + 1) // 2).astype(int)


def grid_elements(ids: np.ndarray, quadratic: bool) -> np.ndarray:
    """Connectivity (E, 8 or 20) of the node-index grid ``ids`` (n1, n2, n3), elements in
    (i, j, k) order with k fastest."""
    step = 2 if quadratic else 1
    n = [(s - 1) // step for s in ids.shape]
    ei, ej, ek = (v.ravel() for v in np.meshgrid(*(np.arange(m) for m in n), indexing="ij"))
    loc = local_nodes(quadratic)
    return ids[step * ei[:, None] + loc[None, :, 0], step * ej[:, None] + loc[None, :, 1],
               step * ek[:, None] + loc[None, :, 2]]


def grid_ids(shape: tuple[int, int, int], quadratic: bool, offset: int) -> np.ndarray:
    """Node numbers of a grid, -1 where a quadratic grid has no node (two or more odd
    indices: face and body centres)."""
    gi, gj, gk = np.meshgrid(*(np.arange(s) for s in shape), indexing="ij")
    keep = np.ones(shape, dtype=bool)
    if quadratic:
        keep = ((gi % 2) + (gj % 2) + (gk % 2)) <= 1
    ids = -np.ones(shape, dtype=int)
    ids[keep] = offset + np.arange(int(keep.sum()))
    return ids


def swap_xi_eta() -> np.ndarray:
    """Permutation of the 20 nodes that exchanges xi and eta (turns a left-handed
    element right-handed, keeping its zeta faces)."""
    swapped = NODES20[:, [1, 0, 2]]
    return np.array([int(np.flatnonzero((NODES20 == s).all(axis=1))[0]) for s in swapped])


def signed_volumes(nodes: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """det of d x / d (xi, eta, zeta) at every element's centre from its corners."""
    p = nodes[conn[:, :8]]
    c = NODES20[:8]
    d = np.einsum("enk,nj->ekj", p, c) / 8.0  # d x_k / d xi_j at the centre (trilinear)
    return np.linalg.det(d)


def merge(points: np.ndarray, conn: np.ndarray, tol: float = 1e-9) -> tuple[np.ndarray, np.ndarray]:
    """Points closer than ``tol`` merged (the blocks' shared faces), unused ones dropped;
    returns the points and the renumbered connectivity (0-based)."""
    pairs = cKDTree(points).query_pairs(tol, output_type="ndarray")
    rep = np.arange(len(points))
    if len(pairs):
        np.minimum.at(rep, pairs.max(axis=1), pairs.min(axis=1))
    used = np.unique(rep[conn])
    number = -np.ones(len(points), dtype=int)
    number[used] = np.arange(len(used))
    return points[used], number[rep[conn]]


def ball_octant(mesh: BallMesh, quadratic: bool = False) -> dict:
    """The ball octant's mesh: ``nodes`` (N, 3), ``elements`` (E, 8 or 20; 0-based,
    right-handed), ``surface`` (F, 4 or 8; the sphere faces' nodes, zeta = +1 of the
    shell elements ``surface_elements``, outward), ``surface_elements`` (F,) and node
    sets ``x0``, ``y0``, ``top`` (z = 0), ``sphere`` (0-based)."""
    a = refine(mesh.angles_ab(), quadratic)
    cc = refine(mesh.angles_c(), quadratic)
    w = refine(mesh.radial_w(), quadratic)
    ta, tc = np.tan(a), np.tan(cc)
    ta[-1] = tc[-1] = 1.0
    pts, conns, shell = [], [], []
    offset = 0
    # shells in the positive octant with the pole at +z (mirrored at the end): the axis
    # component, then the two angles' tangents (x: B, C; y: A, C; z: A, B)
    for axis, (t1, t2) in ((0, (ta, tc)), (1, (ta, tc)), (2, (ta, ta))):
        ids = grid_ids((len(t1), len(t2), len(w)), quadratic, offset)
        keep = ids >= 0
        g1, g2, g3 = np.meshgrid(t1, t2, w, indexing="ij")
        v = np.empty((*g1.shape, 3))
        v[..., axis] = 1.0
        others = [k for k in range(3) if k != axis]
        v[..., others[0]], v[..., others[1]] = g1, g2
        lo, hi = np.minimum(g1, g2), np.maximum(g1, g2)
        norm = np.sqrt(1.0 + lo * lo + hi * hi)
        scale = (1.0 - g3) * CORE + g3 * RADIUS / norm
        pts.append((scale[..., None] * v)[keep])
        offset += int(keep.sum())
        e = grid_elements(ids, quadratic)
        conns.append(e)
        shell.append(np.full(len(e), True))
    core_ids = grid_ids((len(ta), len(ta), len(tc)), quadratic, offset)
    keep = core_ids >= 0
    gx, gy, gz = np.meshgrid(CORE * ta, CORE * ta, CORE * tc, indexing="ij")
    pts.append(np.stack([gx, gy, gz], axis=-1)[keep])
    e = grid_elements(core_ids, quadratic)
    conns.append(e)
    shell.append(np.full(len(e), False))
    points = np.concatenate(pts)
    points[:, 2] *= -1.0  # the lower hemisphere
    conn = np.concatenate(conns)
    nodes, conn = merge(points, conn)
    on_sphere = np.abs(np.linalg.norm(nodes, axis=1) - RADIUS) <= 1e-12
    nodes[on_sphere] /= np.linalg.norm(nodes[on_sphere], axis=1)[:, None]
    conn = right_handed(nodes, conn)
    corner_face = conn[:, 4:8]
    is_shell = np.concatenate(shell)
    outer = is_shell & on_sphere[corner_face].all(axis=1)
    face_cols = [4, 5, 6, 7] + ([12, 13, 14, 15] if quadratic else [])
    return {"nodes": nodes, "elements": conn, "surface": conn[outer][:, face_cols],
            "surface_elements": np.flatnonzero(outer),
            "x0": np.flatnonzero(nodes[:, 0] == 0.0), "y0": np.flatnonzero(nodes[:, 1] == 0.0),
            "top": np.flatnonzero(nodes[:, 2] == 0.0), "sphere": np.flatnonzero(on_sphere),
            "quadratic": quadratic}


def right_handed(nodes: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """Left-handed elements reordered by :func:`swap_xi_eta` (zeta faces kept)."""
    perm = swap_xi_eta()[: conn.shape[1]]
    if conn.shape[1] == 8:
        perm = np.array([0, 3, 2, 1, 4, 7, 6, 5])  # the corners' xi <-> eta
    conn = conn.copy()
    left = signed_volumes(nodes, conn) < 0
    conn[left] = conn[left][:, perm]
    if np.any(signed_volumes(nodes, conn) <= 0):
        raise ValueError("ball mesh: a degenerate element")
    return conn


def flat_grid(mesh: BallMesh, reach: float = 2.0, size: float = 0.35) -> np.ndarray:
    """x (= y) positions of the flat's top nodes: the slave's fine spacing (sin of A) up
    to ``reach`` theta_c, then growing to ``size``, and two fine spacings mirrored past
    the symmetry plane (a master under every slave face near the zone)."""
    s = np.sin(mesh.angles_ab())
    near = s[s <= math.sin(reach * THETA_C) + 1e-12]
    h = near[1] - near[0]
    rest = size - near[-1]
    growth = 1.5
    n = max(1, int(round(math.log1p(rest * (growth - 1.0) / (growth * h)) / math.log(growth))))
    far = near[-1] + rest * (growth ** np.arange(1, n + 1) - 1.0) / (growth**n - 1.0)
    far[-1] = size
    return np.concatenate([[-2 * h, -h], near, far])


def flat_block(grid: np.ndarray, quadratic: bool = False, thickness: float = 0.05) -> dict:
    """The rigid flat: one layer of hexahedra under z = -R over ``grid`` x ``grid``;
    ``nodes``, ``elements`` (0-based, right-handed), ``top`` (F, 4 or 8: the faces at
    z = -R, outward +z) and ``top_elements``."""
    g = refine(grid, quadratic)
    z = refine(np.array([-RADIUS - thickness, -RADIUS]), quadratic)
    ids = grid_ids((len(g), len(g), len(z)), quadratic, 0)
    keep = ids >= 0
    gx, gy, gz = np.meshgrid(g, g, z, indexing="ij")
    nodes = np.stack([gx, gy, gz], axis=-1)[keep]
    conn = grid_elements(ids, quadratic)
    face_cols = [4, 5, 6, 7] + ([12, 13, 14, 15] if quadratic else [])
    return {"nodes": nodes, "elements": conn, "top": conn[:, face_cols],
            "top_elements": np.arange(len(conn))}
