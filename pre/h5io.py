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
from .volume import FACE_KEYS, Volume

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


def write_volume(group: h5py.Group, vol: Volume) -> None:
    """Write a volume (3D body) into ``group``: ``degree`` int32 (3,), the three knot
    vectors, ``control_points`` (n_zeta, n_eta, n_xi, 3), ``weights`` and the six
    ``face_<key>`` names (docs/formats.md)."""
    _dataset(group, "degree", np.asarray(vol.degree, dtype=np.int32))
    for direction, knots in zip(("xi", "eta", "zeta"), vol.knots, strict=True):
        _dataset(group, f"knots_{direction}", np.asarray(knots, dtype=np.float64))
    _dataset(group, "control_points", np.asarray(vol.control_points, dtype=np.float64))
    _dataset(group, "weights", np.asarray(vol.weights, dtype=np.float64))
    for key in FACE_KEYS:
        group.attrs[f"face_{key}"] = _str(vol.faces[key])


def read_volume(group: h5py.Group) -> Volume:
    """Read a volume written by :func:`write_volume`."""
    attrs = attrs_dict(group)
    return Volume(degree=tuple(int(d) for d in group["degree"][()]),  # type: ignore[arg-type]
                  knots_xi=group["knots_xi"][()], knots_eta=group["knots_eta"][()],
                  knots_zeta=group["knots_zeta"][()], control_points=group["control_points"][()],
                  weights=group["weights"][()],
                  faces={k: attrs[f"face_{k}"] for k in FACE_KEYS if f"face_{k}" in attrs})


def read_body(group: h5py.Group) -> Patch | Volume:
    """A body of a geometry file: a volume when its ``degree`` has 3 entries, else a patch."""
    return read_volume(group) if group["degree"].shape == (3,) else read_patch(group)


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


def write_geometry(path: str | Path, scene: str, bodies: dict[str, Patch] | dict[str, Volume],
                   units: str = UNITS, generator: str = GENERATOR,
                   curves: dict[str, Curve] | None = None) -> None:
    """Write the coarse geometry file of a scene: its bodies and (``/curves``, only
    when there are any) the curves of its rigid obstacles. The bodies are all patches
    (2D; the file as before, no ``dimension``) or all volumes (root attribute
    ``dimension = 3``; no curves)."""
    volumes = [isinstance(b, Volume) for b in bodies.values()]
    if any(volumes) and not all(volumes):
        raise ValueError("a geometry file holds bodies of one dimension: all patches or all volumes")
    if any(volumes) and curves:
        raise ValueError("rigid obstacle curves are 2D: a file of volumes has none")
    with new_file(path) as tmp, h5py.File(tmp, "w") as f:
        f.attrs["scene"] = _str(scene)
        f.attrs["units"] = _str(units)
        f.attrs["generator"] = _str(generator)
        if any(volumes):
            f.attrs["dimension"] = np.int32(3)
        g = f.create_group("bodies", track_order=True)
        for name, b in bodies.items():
            if isinstance(b, Volume):
                write_volume(g.create_group(name), b)
            else:
                write_patch(g.create_group(name), b)
        if curves:
            g = f.create_group("curves", track_order=True)
            for name, curve in curves.items():
                write_curve(g.create_group(name), curve)


def read_geometry(path: str | Path) -> tuple[dict[str, Any], dict[str, Patch]]:
    """``(root attrs, {body name: coarse patch})`` of a 2D geometry file."""
    with h5py.File(path, "r") as f:
        return attrs_dict(f), {name: read_patch(g) for name, g in f["bodies"].items()}


def read_volumes(path: str | Path) -> tuple[dict[str, Any], dict[str, Volume]]:
    """``(root attrs, {body name: volume})`` of a geometry file of volumes."""
    with h5py.File(path, "r") as f:
        bodies = {name: read_body(g) for name, g in f["bodies"].items()}
        attrs = attrs_dict(f)
    flat = sorted(n for n, b in bodies.items() if not isinstance(b, Volume))
    if flat:
        raise ValueError(f"{path}: body(ies) {flat} are 2D patches, not volumes")
    return attrs, bodies  # type: ignore[return-value]


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
