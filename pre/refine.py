"""The refined discretization of a case, built with splipy
(``python -m pre refine CASE.nml -o OUT.h5``).

Per body (docs/formats.md, "Refinement order"):

* bulk, basis 'nurbs': the coarse patch order-elevated to
  ``(degree_xi, degree_eta)``, then the new interior knots inserted once;
* bulk, basis 'linear' (L1): a degree-1 patch, weights 1, whose control
  points are the exact geometry at the knot grid (coarse breakpoints plus new
  knots);
* layer (``layer_degree > 0``): the coarse contact-edge curve elevated to
  ``layer_degree``, the same new knots (along the edge) inserted once, then
  ``layer_elevations`` more order elevations (each repeats every knot once).

The bulk is written oriented so that the contact edge is ``eta = 1`` (see
:func:`orient`). DOFs are 2 per control point: interface = the layer's control
points if there is a layer, else the bulk's ``eta = 1`` row; bulk = every other
bulk control point.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from .cases import case_bodies, read_case
from .files import new_file
from .h5io import _str, attrs_dict, read_curve, read_geometry, read_patch, write_curve, write_patch
from .nurbs import (
    KNOT_TOL,
    Curve,
    Patch,
    curve_from_splipy,
    curve_to_splipy,
    eta1_curve,
    interior_breakpoints,
    patch_from_splipy,
    patch_to_splipy,
    unique_knots,
)

DOFS_PER_NODE = 2


@dataclass
class BodyDiscretization:
    """Refined bulk patch, optional layer curve and DOF counts of one body."""

    name: str
    bulk: Patch
    layer: Curve | None
    interface_dofs: int
    bulk_dofs: int

    @property
    def total_dofs(self) -> int:
        return self.interface_dofs + self.bulk_dofs


@dataclass
class Discretization:
    """All bodies of a case, plus the root attributes of the dump."""

    attrs: dict[str, str] = field(default_factory=dict)
    bodies: dict[str, BodyDiscretization] = field(default_factory=dict)


# ------------------------------------------------------------------ knots

def _as_list(value: Any) -> list[float]:
    if value is None:
        return []
    if isinstance(value, (list, tuple, np.ndarray)):
        return [float(v) for v in value]
    return [float(value)]


def new_knots(coarse_knots: np.ndarray, body: dict[str, Any], direction: str) -> np.ndarray:
    """Interior knots to insert along ``direction`` ('xi' or 'eta'): the
    explicit ``knots_<dir>`` list if given, else ``i / nel_<dir>``; values that
    are already coarse knots (within :data:`KNOT_TOL`) are skipped."""
    explicit = body.get(f"knots_{direction}")
    if explicit is not None:
        ks = np.array(_as_list(explicit))
        if ks.size and (ks.min() <= 0.0 or ks.max() >= 1.0):
            raise ValueError(f"knots_{direction}: values must lie strictly inside (0, 1)")
        if np.any(np.diff(ks) <= 0.0):
            raise ValueError(f"knots_{direction}: values must be strictly increasing")
    else:
        nel = int(body.get(f"nel_{direction}", 1) or 1)
        if nel < 1:
            raise ValueError(f"nel_{direction} must be >= 1")
        ks = np.array([i / nel for i in range(1, nel)])
    coarse = unique_knots(coarse_knots)
    keep = [k for k in ks if np.min(np.abs(coarse - k)) > KNOT_TOL]
    return np.array(keep, dtype=float)


# ------------------------------------------------------------------ bulk

def refine_bulk_nurbs(coarse: Patch, degree: tuple[int, int],
                      new_xi: np.ndarray, new_eta: np.ndarray) -> Patch:
    """k-refinement: order elevation to ``degree``, then knot insertion."""
    if degree[0] < coarse.degree[0] or degree[1] < coarse.degree[1]:
        raise ValueError(f"bulk degree {degree} below the coarse degree {coarse.degree}")
    s = patch_to_splipy(coarse)
    s.raise_order(degree[0] - coarse.degree[0], degree[1] - coarse.degree[1])
    if len(new_xi):
        s.insert_knot(list(new_xi), direction=0)
    if len(new_eta):
        s.insert_knot(list(new_eta), direction=1)
    return patch_from_splipy(s, coarse.edges)


def refine_bulk_linear(coarse: Patch, new_xi: np.ndarray, new_eta: np.ndarray) -> Patch:
    """L1: degree-1 patch interpolating the exact geometry at the knot grid."""
    grids = []
    for knots, new in ((coarse.knots_xi, new_xi), (coarse.knots_eta, new_eta)):
        inner = np.union1d(interior_breakpoints(knots), new)
        grids.append(np.concatenate([[0.0], inner, [1.0]]))
    gx, ge = grids
    pts = np.asarray(patch_to_splipy(coarse).evaluate(gx, ge))  # (n_xi, n_eta, 2)
    return Patch(degree=(1, 1),
                 knots_xi=np.concatenate([[0.0], gx, [1.0]]),
                 knots_eta=np.concatenate([[0.0], ge, [1.0]]),
                 control_points=pts.transpose(1, 0, 2).copy(),
                 weights=np.ones((len(ge), len(gx))), edges=dict(coarse.edges))


# ------------------------------------------------------------------ orientation

def _reverse_knots(knots: np.ndarray) -> np.ndarray:
    return 1.0 - knots[::-1]


def orient(patch: Patch, contact_key: str) -> Patch:
    """Re-parametrize ``patch`` so that edge ``contact_key`` becomes ``eta = 1``.

    Orientation preserving (a rotation of the parameter square):
    'eta1' identity; 'eta0' (xi, eta) -> (1 - xi, 1 - eta);
    'xi1' new eta = xi, new xi = 1 - eta; 'xi0' new eta = 1 - xi, new xi = eta.
    Reversed knot vectors are ``1 - k`` (reversed).
    """
    cp, w, e = patch.control_points, patch.weights, patch.edges
    px, pe = patch.degree
    if contact_key == "eta1":
        return patch
    if contact_key == "eta0":
        return Patch((px, pe), _reverse_knots(patch.knots_xi), _reverse_knots(patch.knots_eta),
                     cp[::-1, ::-1].copy(), w[::-1, ::-1].copy(),
                     {"xi0": e.get("xi1", ""), "xi1": e.get("xi0", ""),
                      "eta0": e.get("eta1", ""), "eta1": e.get("eta0", "")})
    if contact_key == "xi1":  # A'[a, b] = A[n_eta-1-b, a]
        return Patch((pe, px), _reverse_knots(patch.knots_eta), patch.knots_xi.copy(),
                     cp.transpose(1, 0, 2)[:, ::-1].copy(), w.T[:, ::-1].copy(),
                     {"xi0": e.get("eta1", ""), "xi1": e.get("eta0", ""),
                      "eta0": e.get("xi0", ""), "eta1": e.get("xi1", "")})
    if contact_key == "xi0":  # A'[a, b] = A[b, n_xi-1-a]
        return Patch((pe, px), patch.knots_eta.copy(), _reverse_knots(patch.knots_xi),
                     cp.transpose(1, 0, 2)[::-1, :].copy(), w.T[::-1, :].copy(),
                     {"xi0": e.get("eta0", ""), "xi1": e.get("eta1", ""),
                      "eta0": e.get("xi1", ""), "eta1": e.get("xi0", "")})
    raise ValueError(f"bad edge key {contact_key!r}")


# ------------------------------------------------------------------ layer

def build_layer(edge: Curve, new: np.ndarray, degree: int, elevations: int) -> Curve:
    """VO layer: ``edge`` elevated to ``degree``, ``new`` knots inserted once,
    then ``elevations`` more order elevations."""
    if degree < edge.degree:
        raise ValueError(f"layer_degree {degree} below the edge's degree {edge.degree}")
    if elevations < 0:
        raise ValueError("layer_elevations must be >= 0")
    c = curve_to_splipy(edge)
    c.raise_order(degree - edge.degree)
    if len(new):
        c.insert_knot(list(new))
    if elevations:
        c.raise_order(elevations)
    return curve_from_splipy(c)


def added_knots(refined: np.ndarray, coarse: np.ndarray) -> np.ndarray:
    """Breakpoints of ``refined`` that are not breakpoints of ``coarse``."""
    cu = unique_knots(coarse)
    return np.array([k for k in interior_breakpoints(refined)
                     if np.min(np.abs(cu - k)) > KNOT_TOL])


# ------------------------------------------------------------------ body / case

def discretize_body(coarse: Patch, body: dict[str, Any]) -> BodyDiscretization:
    """Refined bulk, layer and DOF counts of one &body group (plain dict,
    lower-case keys as f90nml gives them)."""
    name = str(body["name"])
    basis = str(body.get("basis", "nurbs")).lower()
    degree = (int(body.get("degree_xi", coarse.degree[0])),
              int(body.get("degree_eta", coarse.degree[1])))
    q = int(body.get("layer_degree", 0) or 0)
    k = int(body.get("layer_elevations", 0) or 0)
    contact = str(body.get("contact_edge", "") or "").strip()
    if contact:
        # like the solver: rotate first, so that every setting below refers to the
        # oriented patch (xi along the contact edge, eta across it)
        coarse = orient(coarse, coarse.edge_key(contact))

    new_xi = new_knots(coarse.knots_xi, body, "xi")
    new_eta = new_knots(coarse.knots_eta, body, "eta")
    if basis == "linear":
        if degree != (1, 1):
            raise ValueError(f"{name}: basis 'linear' needs degree_xi = degree_eta = 1")
        if q:
            raise ValueError(f"{name}: basis 'linear' has no VO layer")
        bulk = refine_bulk_linear(coarse, new_xi, new_eta)
    elif basis == "nurbs":
        bulk = refine_bulk_nurbs(coarse, degree, new_xi, new_eta)
    else:
        raise ValueError(f"{name}: unknown basis {basis!r}")

    layer = None
    if contact:
        n_eta, n_xi = bulk.shape
        if q:
            layer = build_layer(eta1_curve(coarse), added_knots(bulk.knots_xi, coarse.knots_xi), q, k)
            interface = DOFS_PER_NODE * len(layer.weights)
        else:
            interface = DOFS_PER_NODE * n_xi
        bulk_dofs = DOFS_PER_NODE * n_xi * (n_eta - 1)
    else:
        if q:
            raise ValueError(f"{name}: a layer needs a contact_edge")
        interface, bulk_dofs = 0, DOFS_PER_NODE * bulk.weights.size
    return BodyDiscretization(name, bulk, layer, interface, bulk_dofs)


def discretize_case(case_path: str | Path) -> Discretization:
    """Read a case namelist and its geometry, and refine every body."""
    case_path = Path(case_path)
    nml = read_case(case_path)
    cg = nml["case"]
    _, coarse = read_geometry(case_path.parent / str(cg["geometry"]))
    bodies = case_bodies(nml)
    n = int(cg.get("n_bodies", len(bodies)))
    if n != len(bodies):
        raise ValueError(f"n_bodies = {n} but {len(bodies)} &body groups")
    disc = Discretization(attrs={"title": str(cg.get("title", "")), "scene": str(cg.get("scene", "")),
                                 "mesh": str(cg.get("mesh", "")), "layout": str(cg.get("layout", ""))})
    for body in bodies:
        name = str(body["name"])
        if name not in coarse:
            raise KeyError(f"body {name!r} not in the geometry file")
        disc.bodies[name] = discretize_body(coarse[name], body)
    return disc


# ------------------------------------------------------------------ dump I/O

def write_dump(path: str | Path, disc: Discretization) -> None:
    """Write the discretization dump schema of docs/formats.md."""
    with new_file(path) as tmp, h5py.File(tmp, "w") as f:
        for key in ("title", "scene", "mesh", "layout"):
            f.attrs[key] = _str(disc.attrs.get(key, "") or " ")
        bodies = f.create_group("bodies")
        for name, b in disc.bodies.items():
            g = bodies.create_group(name)
            g.attrs["interface_dofs"] = np.int32(b.interface_dofs)
            g.attrs["bulk_dofs"] = np.int32(b.bulk_dofs)
            g.attrs["total_dofs"] = np.int32(b.total_dofs)
            write_patch(g.create_group("bulk"), b.bulk, with_edges=False)
            if b.layer is not None:
                write_curve(g.create_group("layer"), b.layer)


def read_dump(path: str | Path) -> Discretization:
    """Read a discretization dump (ours or voiga's)."""
    with h5py.File(path, "r") as f:
        disc = Discretization(attrs={k: str(v) for k, v in attrs_dict(f).items()})
        for name, g in f["bodies"].items():
            a = attrs_dict(g)
            layer = read_curve(g["layer"]) if "layer" in g else None
            b = BodyDiscretization(name, read_patch(g["bulk"]), layer,
                                   int(a["interface_dofs"]), int(a["bulk_dofs"]))
            if int(a["total_dofs"]) != b.total_dofs:
                raise ValueError(f"{path}: {name}: total_dofs != interface_dofs + bulk_dofs")
            disc.bodies[name] = b
        return disc
