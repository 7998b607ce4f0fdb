"""The peers' contact output as pressure on the sphere, and the one measure of section 9.

Every code's result becomes points on the slave sphere in the reference configuration
with a nominal pressure (force per reference area) and the reference area each point
stands for; :func:`measure` then applies :func:`post.hertz3d.disc_error`, the function
behind ``python -m post hertz3d``'s L2, against Hertz for the run's own force. The
conversions, one per kind of output:

- :func:`nodal_force_points` (Kratos): the contact force f_i of slave node i (the
  elements' nodal forces there, which the mortar conditions balance) over its reference
  area ``A_i = integral of N_i`` over the slave faces; with dual Lagrange multipliers this
  is the node's multiplier (the 2D bench's :func:`bench.kratos.nodal_pressure` in 3D).
  Points: the slave nodes; weights: A_i. Bilinear faces only (A_i > 0).
  :func:`interpolated_points` also gives the same nodal pressures interpolated over the
  faces at their Gauss points (a second, finer-sampled figure).
- :func:`penalty_points` (CalculiX's surface-to-surface penalty): ``K x overclosure`` at
  the Gauss points of every slave face from the nodal displacements, the law the penalty
  applies, per reference area (times the face's current over reference Jacobian).
  Points: 3 x 3 Gauss points of every face; weights: Gauss weight x reference Jacobian.
  This is also right for quadratic faces, whose corner nodes take negative shares of a
  pressure. On bilinear faces (C3D8I) :func:`penalty_nodal_points` also gives the nodal
  measure: the law's consistent nodal forces over the nodal areas, as for Kratos. On
  quadratic faces (C3D20R) :func:`projected_points` turns the nodal forces into nodal
  pressures with the faces' Gram matrix instead (the L2 projection of the law's pressure
  onto the faces' shape functions).

The flat is the plane z = -R (its normal +z, into the ball) and the axis the z axis
through the contact point (0, 0, -R): r = sqrt(x^2 + y^2) of the reference position.
The model is a quarter: P = 4 x the quarter's force.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from post.hertz import fit_hertz
from post.hertz3d import disc_error, sphere_reference

E, NU, RADIUS = 1.0, 0.3, 1.0
SYMMETRY = 4
FLAT_Z = -RADIUS


def face_shapes(n_nodes: int, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Shape functions (g, n) and their derivatives (g, n, 2) of a bilinear (4) or
    serendipity (8) quadrilateral at natural points (g, 2); corners counter-clockwise
    from (-1, -1), then the mid-sides of edges 1-2, 2-3, 3-4, 4-1."""
    s, t = points[:, 0], points[:, 1]
    cs = np.array([-1.0, 1.0, 1.0, -1.0])
    ct = np.array([-1.0, -1.0, 1.0, 1.0])
    si, ti = s[:, None] * cs, t[:, None] * ct
    if n_nodes == 4:
        N = 0.25 * (1 + si) * (1 + ti)
        dN = np.stack([0.25 * cs * (1 + ti), 0.25 * ct * (1 + si)], axis=-1)
        return N, dN
    if n_nodes != 8:
        raise ValueError(f"faces of 4 or 8 nodes, not {n_nodes}")
    N = np.empty((len(s), 8))
    dN = np.empty((len(s), 8, 2))
    N[:, :4] = 0.25 * (1 + si) * (1 + ti) * (si + ti - 1)
    dN[:, :4, 0] = 0.25 * cs * (1 + ti) * (2 * si + ti)
    dN[:, :4, 1] = 0.25 * ct * (1 + si) * (si + 2 * ti)
    # mid-sides: t = -1 (edge 1-2), s = +1 (2-3), t = +1 (3-4), s = -1 (4-1)
    for k, (c, along_s) in enumerate(((-1.0, True), (1.0, False), (1.0, True), (-1.0, False))):
        if along_s:
            N[:, 4 + k] = 0.5 * (1 - s**2) * (1 + c * t)
            dN[:, 4 + k, 0] = -s * (1 + c * t)
            dN[:, 4 + k, 1] = 0.5 * (1 - s**2) * c
        else:
            N[:, 4 + k] = 0.5 * (1 + c * s) * (1 - t**2)
            dN[:, 4 + k, 0] = 0.5 * c * (1 - t**2)
            dN[:, 4 + k, 1] = -t * (1 + c * s)
    return N, dN


def gauss_square(n: int) -> tuple[np.ndarray, np.ndarray]:
    g, w = np.polynomial.legendre.leggauss(n)
    S, T = np.meshgrid(g, g, indexing="ij")
    return np.column_stack([S.ravel(), T.ravel()]), np.outer(w, w).ravel()


def face_points(x: np.ndarray, faces: np.ndarray, n_gauss: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points (F, g, 3), Jacobians |dx/ds x dx/dt| (F, g) and the shape functions (g, n)
    of the faces (F, n; 0-based into ``x``) at ``n_gauss`` x ``n_gauss`` Gauss points
    (their weights: :func:`gauss_square`)."""
    q, _ = gauss_square(n_gauss)
    N, dN = face_shapes(faces.shape[1], q)
    X = x[faces]  # (F, n, 3)
    pts = np.einsum("gn,fna->fga", N, X)
    d = np.einsum("gnk,fna->fgak", dN, X)
    jac = np.linalg.norm(np.cross(d[..., 0], d[..., 1]), axis=-1)
    return pts, jac, N


def nodal_areas(x: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """``A_i``: the integral of node i's shape function over the faces (reference ``x``),
    zero off the faces (exact for bilinear faces with 3 x 3 points)."""
    _, jac, N = face_points(x, faces, 3)
    _, w = gauss_square(3)
    area = np.zeros(len(x))
    np.add.at(area, faces, np.einsum("gn,fg->fn", N, jac * w))
    return area


@dataclass(frozen=True)
class Points:
    """Pressure points on the sphere (reference configuration)."""

    x: np.ndarray
    """(n, 3) reference positions."""
    p: np.ndarray
    """(n,) nominal pressure, >= 0 (0: no contact)."""
    w: np.ndarray
    """(n,) reference areas."""


def nodal_force_points(x: np.ndarray, faces: np.ndarray, nodes: np.ndarray, fz: np.ndarray,
                       active: np.ndarray) -> Points:
    """Kratos's conversion (module docstring): ``nodes`` (0-based into ``x``) the slave
    nodes, ``fz`` their elements' nodal force along z (element right-hand side: minus
    the internal force, so negative under compression), ``active`` Kratos's flag. Nodes
    not active or pulled get no pressure."""
    if faces.shape[1] != 4:
        raise ValueError("nodal forces per nodal area need bilinear faces (a quadratic "
                         "face's corners take negative shares)")
    area = nodal_areas(x, faces)[nodes]
    p = -np.asarray(fz, dtype=float) / area
    p[~np.asarray(active, dtype=bool) | (p < 0)] = 0.0
    return Points(x[nodes], p, area)


def interpolated_points(x: np.ndarray, faces: np.ndarray, nodal: Points, nodes: np.ndarray) -> Points:
    """The nodal pressures of ``nodal`` (at the slave nodes ``nodes``, 0-based into ``x``)
    interpolated by the faces' shape functions at 3 x 3 Gauss points of every face,
    weights Gauss weight x reference Jacobian: the measure at points inside the faces, as
    voiga's (a check on how much the nodes alone miss)."""
    p = np.zeros(len(x))
    p[nodes] = nodal.p
    pts, jac, N = face_points(x, faces, 3)
    _, w = gauss_square(3)
    return Points(pts.reshape(-1, 3), (p[faces] @ N.T).ravel(), (jac * w).ravel())


def penalty_points(x: np.ndarray, u: np.ndarray, faces: np.ndarray, slope: float) -> Points:
    """CalculiX's conversion (module docstring): reference node positions ``x`` (N, 3),
    displacements ``u`` (N, 3), slave faces (F, 4 or 8), contact slope K (pressure per
    overclosure) of the linear pressure-overclosure law against the flat z = -R; at
    3 x 3 Gauss points of every face."""
    ref, jac0, _ = face_points(x, faces, 3)
    cur, jac, _ = face_points(x + u, faces, 3)
    _, w = gauss_square(3)
    p = slope * np.clip(FLAT_Z - cur[..., 2], 0.0, None) * jac / jac0
    return Points(ref.reshape(-1, 3), p.ravel(), (jac0 * w).ravel())


def penalty_nodal_points(x: np.ndarray, u: np.ndarray, faces: np.ndarray, slope: float) -> Points:
    """CalculiX's nodal conversion on bilinear faces: the penalty law's consistent nodal
    forces ``f_i = integral of N_i p`` (:func:`penalty_points`' points) over the nodal
    areas, at the faces' nodes, as :func:`nodal_force_points` for Kratos."""
    if faces.shape[1] != 4:
        raise ValueError("nodal forces per nodal area need bilinear faces")
    pts = penalty_points(x, u, faces, slope)
    _, _, N = face_points(x, faces, 3)
    f = np.zeros(len(x))
    np.add.at(f, faces, np.einsum("fg,gn->fn", (pts.p * pts.w).reshape(len(faces), -1), N))
    nodes = np.unique(faces)
    return nodal_force_points(x, faces, nodes, -f[nodes], f[nodes] > 0)


def projected_points(x: np.ndarray, faces: np.ndarray, law: Points) -> Points:
    """The pressure of ``law`` (at :func:`penalty_points`' 3 x 3 points of every face)
    projected in L2 onto the faces' shape functions (``M p = f``, M the faces' Gram
    matrix ``integral N_i N_j``, f the consistent nodal forces ``integral N_i p``) and
    interpolated back at those points: on quadratic faces the nodal pressure that the
    nodal forces define (a corner's N_i integrates to a negative area, so f_i / A_i,
    the lumped form of the same system, does not exist). Only the faces with pressure at
    a point take part (the others' nodes get none): a projection over the whole sphere
    rings with small pressures out to its edge."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.linalg import spsolve
    _, _, N = face_points(x, faces, 3)
    w_all = law.w.reshape(len(faces), -1)  # (F, g): Gauss weight x reference Jacobian
    p_all = law.p.reshape(len(faces), -1)
    on = (p_all > 0).any(axis=1)
    f = np.zeros(len(x))
    np.add.at(f, faces[on], np.einsum("fg,gn->fn", p_all[on] * w_all[on], N))
    m = np.einsum("fg,gi,gj->fij", w_all[on], N, N)
    rows = np.repeat(faces[on][:, :, None], faces.shape[1], axis=2)
    cols = np.repeat(faces[on][:, None, :], faces.shape[1], axis=1)
    nodes = np.unique(faces[on])
    index = -np.ones(len(x), dtype=int)
    index[nodes] = np.arange(len(nodes))
    gram = coo_matrix((m.ravel(), (index[rows].ravel(), index[cols].ravel())),
                      shape=(len(nodes), len(nodes))).tocsc()
    p = np.zeros(len(x))
    p[nodes] = spsolve(gram, f[nodes])
    return Points(law.x, np.clip(np.einsum("fn,gn->fg", p[faces], N).ravel(), 0.0, None), law.w)


def measure(points: Points, quarter_force: float) -> dict:
    """L2 (:func:`post.hertz3d.disc_error`) of ``points`` against Hertz for P = 4 x
    ``quarter_force`` (the flat's force on the quarter model), and the fitted a, p0."""
    force = SYMMETRY * abs(float(quarter_force))
    a, p0 = sphere_reference(force, E, NU, RADIUS)
    r = np.hypot(points.x[:, 0], points.x[:, 1])
    on = points.p > 0
    err = disc_error(r, points.p, points.w, on, a, p0)
    try:
        a_fit, p0_fit = fit_hertz(r[on], points.p[on])
    except ValueError:
        a_fit = p0_fit = float("nan")
    return {"force": force, "a": a, "p0": p0, "l2": err.l2, "extent": err.extent,
            "points": err.points, "a_error": a_fit / a - 1.0, "p0_error": p0_fit / p0 - 1.0,
            "contact_force": SYMMETRY * float(points.p @ points.w)}
