"""Exact evaluation of a body's map, reference or displaced, including the
varying-order (VO) contact row (``docs/theory.md`` section 4).

A body's control points ``X_a`` (numbering of ``docs/theory.md``: bulk rows
``j = 1..m`` of ``n_xi`` points each, xi fastest; with a layer the last row is
replaced by the layer's points, numbered after the others) and the
displacements ``u_a`` of a step give the current position

    x(xi, eta) = sum_a R_a(xi, eta) (X_a + u_a),      R_a = w_a b_a / W,

with the B-spline functions ``b_a`` of the element definition:

- without a layer, ``b_(i,j) = N_i(xi) M_j(eta)`` for every bulk point
  (the plain NURBS patch);
- with a layer, ``b_(i,j) = N_i(xi) M_j(eta)`` for the bulk points of rows
  ``j < m`` and ``b_k = Nh_k(xi) M_m(eta)`` for the layer points, and
  ``W = sum_a w_a b_a``.

``M_m`` (the last eta function of an open knot vector) is zero outside the
last eta element row, so the second formula is the bulk patch there and the
VO basis in the contact row: one expression is exact on the whole parameter
square. The univariate functions ``N_i``, ``M_j``, ``Nh_k`` are splipy's
(:class:`splipy.BSplineBasis`); only the rational combination
``sum_a w_a b_a (X_a + u_a) / sum_a w_a b_a`` is done here, with numpy, in
homogeneous coordinates.
"""

from __future__ import annotations

import numpy as np
import splipy

from .reader import Body


def _basis(degree: int, knots: np.ndarray) -> splipy.BSplineBasis:
    return splipy.BSplineBasis(order=int(degree) + 1, knots=np.asarray(knots, dtype=float))


def n_bulk_rows(body: Body) -> int:
    """Number of bulk rows whose control points are body points: ``m`` without
    a layer, ``m - 1`` with one."""
    n_eta = body.bulk.shape[0]
    return n_eta - 1 if body.layer is not None else n_eta


def check_numbering(body: Body) -> None:
    """Raise ``ValueError`` unless the body's control points and weights are
    the bulk rows (xi fastest), then the layer's, as ``docs/theory.md`` says."""
    n_eta, n_xi = body.bulk.shape
    rows = n_bulk_rows(body)
    n_layer = 0 if body.layer is None else len(body.layer.weights)
    expected = rows * n_xi + n_layer
    if body.ncp != expected:
        raise ValueError(f"body {body.name!r}: {body.ncp} control points, expected "
                         f"{rows} x {n_xi} bulk + {n_layer} layer = {expected}")


def _params(xi: np.ndarray | float,
            eta: np.ndarray | float) -> tuple[np.ndarray, np.ndarray, tuple[int, ...]]:
    xi_b, eta_b = np.broadcast_arrays(np.asarray(xi, dtype=float), np.asarray(eta, dtype=float))
    s, t = xi_b.reshape(-1), eta_b.reshape(-1)
    if s.size and (s.min() < 0 or s.max() > 1 or t.min() < 0 or t.max() > 1):
        raise ValueError("parameters must lie in [0, 1]")
    return s, t, xi_b.shape


def combine(body: Body, values: np.ndarray, xi: np.ndarray | float,
            eta: np.ndarray | float) -> np.ndarray:
    """``sum_a R_a(xi, eta) v_a`` for control point values ``values`` ``(ncp, k)``
    (``R_a``: the body's rational functions, VO in the contact row).

    ``xi`` and ``eta`` are broadcast against each other (parameter pairs in
    [0, 1]); the result has their broadcast shape plus a last axis of ``k``.
    """
    check_numbering(body)
    s, t, shape = _params(xi, eta)
    v = np.asarray(values, dtype=float)
    if v.ndim != 2 or len(v) != body.ncp:
        raise ValueError(f"values have shape {v.shape}, expected ({body.ncp}, k)")
    k = v.shape[1]
    w = body.weights
    hom = np.concatenate([v * w[:, None], w[:, None]], axis=1)  # (ncp, k + 1): w v, w

    n_xi = body.bulk.shape[1]
    rows = n_bulk_rows(body)
    bxi = _basis(body.bulk.degree[0], body.bulk.knots_xi).evaluate(s, sparse=True)  # (P, n_xi)
    beta = _basis(body.bulk.degree[1], body.bulk.knots_eta).evaluate(t)  # (P, n_eta)

    # bulk rows j < rows: sum_j M_j(eta) sum_i N_i(xi) (w v)_ij
    pw = hom[:rows * n_xi].reshape(rows, n_xi, k + 1).transpose(1, 0, 2).reshape(n_xi, -1)
    per_row = np.asarray(bxi @ pw).reshape(len(s), rows, k + 1)
    out = np.einsum("pj,pjc->pc", beta[:, :rows], per_row)
    if body.layer is not None:  # layer points: M_m(eta) sum_k Nh_k(xi) (w v)_k
        layer = body.layer
        bh = _basis(layer.degree, layer.knots).evaluate(s, sparse=True)  # (P, n_layer)
        out += beta[:, -1:] * np.asarray(bh @ hom[rows * n_xi:])
    return (out[:, :k] / out[:, k:]).reshape(*shape, k)


def evaluate(body: Body, u_body: np.ndarray | None, xi: np.ndarray | float,
             eta: np.ndarray | float) -> np.ndarray:
    """Points ``sum_a R_a(xi, eta) (X_a + u_a)`` of ``body``.

    ``u_body`` is ``(ncp, 2)`` (e.g. :func:`post.reader.body_displacement`) or
    None for the reference geometry. ``xi`` and ``eta`` are broadcast against
    each other (parameter pairs, values in [0, 1]); the result has their
    broadcast shape plus a last axis of 2.
    """
    x = body.control_points
    if u_body is not None:
        u = np.asarray(u_body, dtype=float)
        if u.shape != x.shape:
            raise ValueError(f"u_body has shape {u.shape}, expected {x.shape}")
        x = x + u
    return combine(body, x, xi, eta)


def displacement(body: Body, u_body: np.ndarray, xi: np.ndarray | float,
                 eta: np.ndarray | float) -> np.ndarray:
    """The displacement field ``u(xi, eta) = sum_a R_a u_a`` (same shapes as
    :func:`evaluate`)."""
    return combine(body, np.asarray(u_body, dtype=float).reshape(body.ncp, body.nsd), xi, eta)


def evaluate_grid(body: Body, u_body: np.ndarray | None, xi: np.ndarray,
                  eta: np.ndarray) -> np.ndarray:
    """Points on the tensor grid ``xi x eta`` -> ``(len(eta), len(xi), 2)``."""
    xx, ee = np.meshgrid(np.asarray(xi, float), np.asarray(eta, float))
    return evaluate(body, u_body, xx, ee)
