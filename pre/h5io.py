"""HDF5 readers and writers for the formats of ``docs/formats.md``.

Writers are deterministic: datasets are written with ``track_times=False``
(groups carry no times in h5py's default), attributes in a fixed order, and
strings as fixed-length ASCII (simplest to read from Fortran). Readers accept
fixed- or variable-length strings and any integer width.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import h5py
import numpy as np

from .files import new_file
from .nurbs import EDGE_KEYS, Curve, Patch

UNITS = "mm, N"
GENERATOR = "voiga pre (python -m pre cases)"


def _str(value: str) -> np.bytes_:
    """A fixed-length ASCII string attribute value."""
    return np.bytes_(value.encode("ascii"))


def _decode(value: Any) -> Any:
    """Attribute value to a Python str/int/float."""
    if isinstance(value, (bytes, np.bytes_)):
        return value.decode("ascii")
    if isinstance(value, np.ndarray) and value.shape in ((), (1,)):
        return _decode(value.reshape(-1)[0])
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        return float(value)
    return value


def attrs_dict(obj: h5py.HLObject) -> dict[str, Any]:
    """All attributes of an HDF5 object, decoded."""
    return {k: _decode(v) for k, v in obj.attrs.items()}


def _dataset(group: h5py.Group, name: str, data: np.ndarray) -> None:
    group.create_dataset(name, data=data, track_times=False)


def write_patch(group: h5py.Group, patch: Patch, with_edges: bool = True) -> None:
    """Write ``patch`` into ``group`` (datasets of the geometry schema)."""
    _dataset(group, "degree", np.asarray(patch.degree, dtype=np.int32))
    _dataset(group, "knots_xi", np.asarray(patch.knots_xi, dtype=np.float64))
    _dataset(group, "knots_eta", np.asarray(patch.knots_eta, dtype=np.float64))
    _dataset(group, "control_points", np.asarray(patch.control_points, dtype=np.float64))
    _dataset(group, "weights", np.asarray(patch.weights, dtype=np.float64))
    if with_edges:
        for key in EDGE_KEYS:
            group.attrs[f"edge_{key}"] = _str(patch.edges[key])


def read_patch(group: h5py.Group) -> Patch:
    """Read a patch written by :func:`write_patch` (or by voiga)."""
    attrs = attrs_dict(group)
    edges = {k: attrs[f"edge_{k}"] for k in EDGE_KEYS if f"edge_{k}" in attrs}
    return Patch(degree=tuple(int(d) for d in group["degree"][()]),
                 knots_xi=group["knots_xi"][()], knots_eta=group["knots_eta"][()],
                 control_points=group["control_points"][()], weights=group["weights"][()],
                 edges=edges)


def write_curve(group: h5py.Group, curve: Curve) -> None:
    """Write a layer curve (dump schema: degree int32 (1,), knots, ...)."""
    _dataset(group, "degree", np.array([curve.degree], dtype=np.int32))
    _dataset(group, "knots", np.asarray(curve.knots, dtype=np.float64))
    _dataset(group, "control_points", np.asarray(curve.control_points, dtype=np.float64))
    _dataset(group, "weights", np.asarray(curve.weights, dtype=np.float64))


def read_curve(group: h5py.Group) -> Curve:
    """Read a curve written by :func:`write_curve` (or by voiga)."""
    return Curve(degree=int(np.asarray(group["degree"][()]).reshape(-1)[0]),
                 knots=group["knots"][()], control_points=group["control_points"][()],
                 weights=group["weights"][()])


def write_geometry(path: str | Path, scene: str, bodies: dict[str, Patch], units: str = UNITS,
                   generator: str = GENERATOR, curves: dict[str, Curve] | None = None) -> None:
    """Write the coarse geometry file of a scene: its bodies and (``/curves``, only
    when there are any) the curves of its rigid obstacles."""
    with new_file(path) as tmp, h5py.File(tmp, "w") as f:
        f.attrs["scene"] = _str(scene)
        f.attrs["units"] = _str(units)
        f.attrs["generator"] = _str(generator)
        g = f.create_group("bodies", track_order=True)
        for name, patch in bodies.items():
            write_patch(g.create_group(name), patch)
        if curves:
            g = f.create_group("curves", track_order=True)
            for name, curve in curves.items():
                write_curve(g.create_group(name), curve)


def read_geometry(path: str | Path) -> tuple[dict[str, Any], dict[str, Patch]]:
    """``(root attrs, {body name: coarse patch})`` of a geometry file."""
    with h5py.File(path, "r") as f:
        return attrs_dict(f), {name: read_patch(g) for name, g in f["bodies"].items()}


def read_curves(path: str | Path) -> dict[str, Curve]:
    """``{name: curve}`` of the rigid obstacles of a geometry file (empty if none)."""
    with h5py.File(path, "r") as f:
        return {name: read_curve(g) for name, g in f["curves"].items()} if "curves" in f else {}


def h5_contents(path: str | Path) -> dict[str, Any]:
    """Every dataset (as array) and attribute (decoded) of a file, keyed by
    path (``'/a/b'`` for datasets, ``'/a/b@attr'`` for attributes)."""
    out: dict[str, Any] = {}
    with h5py.File(path, "r") as f:
        for k, v in attrs_dict(f).items():
            out[f"/@{k}"] = v

        def visit(name: str, obj: h5py.HLObject) -> None:
            if isinstance(obj, h5py.Dataset):
                out[f"/{name}"] = obj[()]
            for k, v in attrs_dict(obj).items():
                out[f"/{name}@{k}"] = v
        f.visititems(visit)
    return out
