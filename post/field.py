"""Exact evaluation of a body's map, reference or displaced, including the
varying-order (VO) contact row or layer (``docs/theory.md`` section 4), for plane
bodies (parameters xi, eta) and solids (xi, eta, zeta) alike.

A body's control points ``X_a`` and the displacements ``u_a`` of a step give the
current position

    x(xi, ...) = sum_a R_a (X_a + u_a),      R_a = w_a b_a / W,   W = sum_a w_a b_a,

with the B-spline functions ``b_a`` of the solver's element definition. The bulk
patch (a surface, or a volume) is oriented so that the contact boundary is the end
of its last direction (eta = 1, or zeta = 1); its points are numbered in the
patch's order, direction 1 fastest (``docs/theory.md``). Let ``M_j`` be the bulk's
functions of the last direction (``j = 1..m``) and ``B_i`` the tensor products of
the other directions:

- without a layer, ``b_(i,j) = B_i M_j`` for every bulk point (the plain NURBS
  patch or volume);
- with a layer, the bulk points of the last slice (``j = m``) are replaced by the
  layer's (a curve over xi for a plane body, a surface over (xi, eta) for a
  solid), numbered after the others: ``b_(i,j) = B_i M_j`` for ``j < m`` and
  ``b_k = Bh_k M_m`` for the layer points (``Bh_k``: the layer's functions).

``M_m`` (the last function of an open knot vector) is zero outside the last slice
of elements, so the second formula is the bulk map there and the VO basis next to
the contact boundary: one expression is exact in the whole parameter box.

Evaluation is local: at each point only the ``p + 1`` nonzero univariate functions
of each direction (splipy's :class:`splipy.BSplineBasis`, whose sparse evaluation
gives them with the first one's index) enter the tensor products; the rational
combination ``sum_a w_a b_a v_a / sum_a w_a b_a`` is done with numpy in
homogeneous coordinates.
"""

from __future__ import annotations

import numpy as np
import splipy

from .reader import Body

DIRECTIONS: tuple[str, ...] = ("xi", "eta", "zeta")
"""The parametric directions, in the order of a body's arrays."""

CHUNK = 20000
"""Points evaluated at once (bounds the memory of the gathered control values)."""


def _basis(degree: int, knots: np.ndarray) -> splipy.BSplineBasis:
    return splipy.BSplineBasis(order=int(degree) + 1, knots=np.asarray(knots, dtype=float))


def bulk_bases(body: Body) -> list[tuple[int, np.ndarray]]:
    """``(degree, knots)`` of the bulk in each parametric direction (xi first)."""
    b = body.bulk
    names = DIRECTIONS[:len(b.degree)]
    return [(int(p), np.asarray(getattr(b, f"knots_{d}"), dtype=float))
            for p, d in zip(b.degree, names, strict=True)]


def layer_bases(body: Body) -> list[tuple[int, np.ndarray]]:
    """``(degree, knots)`` of the VO layer in each of its directions (the bulk's first
    ``pdim - 1``); empty without a layer."""
    layer = body.layer
    if layer is None:
        return []
    if isinstance(layer.degree, int):  # a curve (plane body)
        return [(layer.degree, np.asarray(layer.knots, dtype=float))]
    return [(int(layer.degree[0]), layer.knots_xi), (int(layer.degree[1]), layer.knots_eta)]


def _counts(bases: list[tuple[int, np.ndarray]]) -> list[int]:
    return [len(k) - p - 1 for p, k in bases]


def parametric_dimension(body: Body) -> int:
    """Number of parameters of the body's map: 2 (plane body) or 3 (solid)."""
    return len(body.bulk.degree)


def n_bulk_rows(body: Body) -> int:
    """Number of slices of the bulk across its last direction whose control points
    are body points: ``m`` without a layer, ``m - 1`` with one."""
    m = _counts(bulk_bases(body))[-1]
    return m - 1 if body.layer is not None else m


def check_numbering(body: Body) -> None:
    """Raise ``ValueError`` unless the body's control points and weights are the bulk
    slices (xi fastest), then the layer's, as ``docs/theory.md`` says."""
    counts = _counts(bulk_bases(body))
    rows = n_bulk_rows(body)
    slice_size = int(np.prod(counts[:-1]))
    n_layer = 0 if body.layer is None else len(body.layer.weights)
    expected = rows * slice_size + n_layer
    if body.ncp != expected:
        raise ValueError(f"body {body.name!r}: {body.ncp} control points, expected "
                         f"{rows} x {' x '.join(map(str, counts[:-1]))} bulk + {n_layer} layer "
                         f"= {expected}")


def _params(body: Body, params: tuple) -> tuple[np.ndarray, tuple[int, ...]]:
    """The parameter points ``(P, pdim)`` of the broadcast parameters, and their shape."""
    pdim = parametric_dimension(body)
    given = [p for p in params if p is not None]
    if len(given) != pdim or any(p is None for p in params[:pdim]):
        raise ValueError(f"body {body.name!r} has {pdim} parameters "
                         f"({', '.join(DIRECTIONS[:pdim])}); {len(given)} given")
    arrays = np.broadcast_arrays(*(np.asarray(p, dtype=float) for p in given))
    t = np.stack([a.reshape(-1) for a in arrays], axis=1)
    if t.size and (t.min() < 0 or t.max() > 1):
        raise ValueError("parameters must lie in [0, 1]")
    return t, arrays[0].shape


def local_basis(degree: int, knots: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The ``p + 1`` B-splines of a knot vector that can be nonzero at each parameter
    of ``t`` ``(P,)``: values ``(P, p + 1)`` and the index of the first ``(P,)``."""
    m = _basis(degree, knots).evaluate(t, sparse=True)
    width = int(degree) + 1
    if not np.all(np.diff(m.indptr) == width):  # not splipy's layout: from the dense matrix
        dense = np.asarray(m.todense())
        n = dense.shape[1]
        span = np.clip(np.searchsorted(knots, t, side="right") - 1, degree, n - 1)
        first = span - degree
        return np.take_along_axis(dense, first[:, None] + np.arange(width), axis=1), first
    return m.data.reshape(-1, width), m.indices[::width].astype(np.int64)


def _tensor(parts: list[tuple[np.ndarray, np.ndarray]],
            counts: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """Tensor products of local bases ``[(values (P, p_d + 1), first (P,))]`` (direction
    1 first): values ``(P, Q)`` and flat ids ``(P, Q)`` (direction 1 fastest)."""
    values = np.ones((parts[0][0].shape[0], 1))
    ids = np.zeros_like(values, dtype=np.int64)
    stride = 1
    for (v, first), n in zip(parts, counts, strict=True):
        index = first[:, None] + np.arange(v.shape[1])
        values = (v[:, :, None] * values[:, None, :]).reshape(len(v), -1)
        ids = (stride * index[:, :, None] + ids[:, None, :]).reshape(len(v), -1)
        stride *= n
    return values, ids


def _combine_points(body: Body, hom: np.ndarray, t: np.ndarray) -> np.ndarray:
    """``sum_a w_a b_a (v_a, 1)`` at the points ``t`` ``(P, pdim)`` for the homogeneous
    control values ``hom`` ``(ncp, k + 1)``."""
    bulk = bulk_bases(body)
    counts = _counts(bulk)
    parts = [local_basis(p, k, t[:, d]) for d, (p, k) in enumerate(bulk)]
    values, ids = _tensor(parts, counts)
    if body.layer is not None:
        # the bulk's last slice is not the body's: its functions are the layer's times M_m
        n_bulk = n_bulk_rows(body) * int(np.prod(counts[:-1]))
        kept = ids < n_bulk
        values, ids = np.where(kept, values, 0.0), np.where(kept, ids, 0)
        layer = layer_bases(body)
        lv, lids = _tensor([local_basis(p, k, t[:, d]) for d, (p, k) in enumerate(layer)],
                           _counts(layer))
        v_last, first_last = parts[-1]
        # M_m(t) is the last local function when the point's span is the last one, else 0
        m_last = np.where(first_last + v_last.shape[1] == counts[-1], v_last[:, -1], 0.0)
        values = np.concatenate([values, lv * m_last[:, None]], axis=1)
        ids = np.concatenate([ids, lids + n_bulk], axis=1)
    return np.einsum("pq,pqc->pc", values, hom[ids])


def combine(body: Body, values: np.ndarray, xi: np.ndarray | float, eta: np.ndarray | float,
            zeta: np.ndarray | float | None = None) -> np.ndarray:
    """``sum_a R_a v_a`` for control point values ``values`` ``(ncp, k)`` (``R_a``: the
    body's rational functions, VO next to the contact boundary).

    The parameters (``xi``, ``eta``, and ``zeta`` for a solid; values in [0, 1]) are
    broadcast against each other; the result has their broadcast shape plus a last
    axis of ``k``.
    """
    check_numbering(body)
    t, shape = _params(body, (xi, eta, zeta))
    v = np.asarray(values, dtype=float)
    if v.ndim != 2 or len(v) != body.ncp:
        raise ValueError(f"values have shape {v.shape}, expected ({body.ncp}, k)")
    k = v.shape[1]
    w = body.weights
    hom = np.concatenate([v * w[:, None], w[:, None]], axis=1)  # (ncp, k + 1): w v, w
    out = np.empty((len(t), k + 1))
    for start in range(0, len(t), CHUNK):
        out[start:start + CHUNK] = _combine_points(body, hom, t[start:start + CHUNK])
    return (out[:, :k] / out[:, k:]).reshape(*shape, k)


def evaluate(body: Body, u_body: np.ndarray | None, xi: np.ndarray | float,
             eta: np.ndarray | float, zeta: np.ndarray | float | None = None) -> np.ndarray:
    """Points ``sum_a R_a (X_a + u_a)`` of ``body``.

    ``u_body`` is ``(ncp, nsd)`` (e.g. :func:`post.reader.body_displacement`) or None
    for the reference geometry. The parameters are broadcast against each other
    (values in [0, 1]; ``zeta`` for a solid only); the result has their broadcast
    shape plus a last axis of nsd.
    """
    x = body.control_points
    if u_body is not None:
        u = np.asarray(u_body, dtype=float)
        if u.shape != x.shape:
            raise ValueError(f"u_body has shape {u.shape}, expected {x.shape}")
        x = x + u
    return combine(body, x, xi, eta, zeta)


def displacement(body: Body, u_body: np.ndarray, xi: np.ndarray | float, eta: np.ndarray | float,
                 zeta: np.ndarray | float | None = None) -> np.ndarray:
    """The displacement field ``u = sum_a R_a u_a`` (same shapes as :func:`evaluate`)."""
    return combine(body, np.asarray(u_body, dtype=float).reshape(body.ncp, body.nsd), xi, eta, zeta)


def evaluate_grid(body: Body, u_body: np.ndarray | None, xi: np.ndarray, eta: np.ndarray,
                  zeta: np.ndarray | None = None) -> np.ndarray:
    """Points on the tensor grid ``xi x eta (x zeta)`` -> ``(len(eta), len(xi), 2)``, or
    for a solid ``(len(zeta), len(eta), len(xi), 3)``."""
    if zeta is None:
        xx, ee = np.meshgrid(np.asarray(xi, float), np.asarray(eta, float))
        return evaluate(body, u_body, xx, ee)
    zz, ee, xx = np.meshgrid(np.asarray(zeta, float), np.asarray(eta, float), np.asarray(xi, float),
                             indexing="ij")
    return evaluate(body, u_body, xx, ee, zz)
