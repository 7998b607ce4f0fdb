"""ParaView export of a result (``python -m post vtk``): a ``.pvd`` time series of
``.vtu`` files written with VTK's own XML writer (the ``vtk`` package from PyPI).

Why VTK rather than meshio: it is Kitware's library, the one ParaView itself is built
on, so the files are written (and, in the tests, read back) by the same code ParaView
uses; it keeps string arrays as field data (units, provenance), which meshio's VTU
writer does not; and it is actively released. The cost is a larger wheel.

Per converged step (plus the reference configuration at load time 0) the series has
up to four parts (``<DataSet part=...>`` in the ``.pvd``; ParaView shows them as
blocks):

- ``bodies``: every body finely sampled: each element split into at least
  ``samples x samples`` bilinear quads (more on coarse meshes: at least
  ``MIN_SAMPLES`` along each direction of a body), of a solid into ``samples^3``
  trilinear hexahedra (at least ``MIN_SAMPLES_3D`` along each direction), whose
  corners are the exact VO map at reference coordinates; point data
  ``displacement`` (3 components, z = 0 in 2D: use *Warp By Vector* for the deformed
  shape); cell data ``body`` (index into the field data ``body_names``) and
  ``element`` (0-based element of that body). Linear interpolation between the
  samples is the only approximation.
- ``contact``: the slave points of every contact pair at their reference
  positions, one polyline per pair in slave-parameter order; point data
  ``displacement`` (current minus reference position), ``p_n``, ``p_t``, ``gap``
  (NaN where the point has no projection), ``state`` (0 open, 1 stick, 2 slip),
  ``traction`` (the vector ``p_n n + p_t t`` on the slave, with the master's outward
  normal ``n`` and tangent ``t``), ``pair`` (0-based, case-file order).
- ``rigid``: the rigid masters, one polyline each at its position at load time 0
  (a curve sampled finely; a line as a segment across the bodies), with point data
  ``displacement`` (its prescribed translation at the step: *Warp By Vector* puts it
  where it is) and ``normal`` (outward), cell data ``pair``.
- ``fields``: stress, strain and von Mises at the steps the result file has them
  (``/steps/<k>/fields/<body>``, written by voiga as ``&output`` asks; docs/hdf5.md):
  the sample points at their reference positions with ``displacement``, joined
  into quads (a solid's: hexahedra) within each element (one vertex per point with
  one sample per element), with ``stress`` and ``strain`` as symmetric tensors
  (``XX YY ZZ XY YZ XZ``; in 2D z out of plane, YZ = XZ = 0), ``von_mises``,
  ``element`` and ``body``; the stress and strain measures as field data.

Field data of every file: ``units``, ``title``, ``case_file``, ``voiga_version``,
``status``, ``source`` (the result file), ``writer``, ``step``, ``time``.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from itertools import pairwise
from pathlib import Path

import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray

from pre.files import new_file, write_text
from pre.nurbs import curve_to_splipy

from .field import combine, displacement, evaluate
from .naming import output_path
from .plot import breakpoints
from .quantity import element_of
from .reader import Body, ContactOutput, Result, Step, body_displacement

SAMPLES = 2
"""Default least subdivisions of every element in each parametric direction."""

MIN_SAMPLES = 48
"""Least subdivisions of a body in each parametric direction (coarse meshes)."""

MIN_SAMPLES_3D = 16
"""The same for a solid (16^3 = 4096 hexahedra at least; 48^3 would be 110 592)."""

HEXAHEDRON = (0, 1, 3, 2, 4, 5, 7, 6)
"""VTK's vertex order of a hexahedron from the corners of a cell numbered (zeta, eta,
xi) as bits (xi fastest): (0,0,0), (1,0,0), (1,1,0), (0,1,0), then the same at zeta 1."""

LEFT_HANDED_HEXAHEDRON = (0, 2, 3, 1, 4, 6, 7, 5)
"""The same with the eta and xi edges swapped: positive volume for a left-handed map."""


def element_samples(breaks: np.ndarray, samples: int, minimum: int = MIN_SAMPLES) -> np.ndarray:
    """Parameters splitting every span of ``breaks`` into the same number of equal
    parts: ``samples``, or more when needed for ``minimum`` in all."""
    spans = max(len(breaks) - 1, 1)
    n = max(samples, -(-minimum // spans))
    parts = [np.linspace(a, b, n + 1)[:-1] for a, b in pairwise(breaks)]
    return np.concatenate(parts + [breaks[-1:]])


def _string_array(name: str, values: list[str]) -> vtk.vtkStringArray:
    arr = vtk.vtkStringArray()
    arr.SetName(name)
    for v in values:
        arr.InsertNextValue(v)
    return arr


def _array(name: str, values: np.ndarray) -> vtk.vtkDataArray:
    values = np.ascontiguousarray(values)
    if values.dtype.kind in "iub":
        arr = numpy_to_vtk(values.astype(np.int32), deep=True, array_type=vtk.VTK_INT)
    else:
        arr = numpy_to_vtk(values.astype(np.float64), deep=True, array_type=vtk.VTK_DOUBLE)
    arr.SetName(name)
    return arr


def _vec3(v: np.ndarray) -> np.ndarray:
    """Vectors ``(n, 2)`` with z = 0, or ``(n, 3)``, as ``(n, 3)``."""
    v = np.asarray(v, dtype=float)
    if v.ndim == 2 and v.shape[1] == 3:
        return v
    v = v.reshape(-1, 2)
    return np.column_stack([v, np.zeros(len(v))])


def _grid(points: np.ndarray, cells: list[np.ndarray], cell_type: int) -> vtk.vtkUnstructuredGrid:
    """An unstructured grid of ``points (n, 2 or 3)`` and cells of one type."""
    grid = vtk.vtkUnstructuredGrid()
    pts = vtk.vtkPoints()
    pts.SetData(numpy_to_vtk(_vec3(points), deep=True))
    grid.SetPoints(pts)
    conn = np.concatenate(cells) if cells else np.zeros(0, dtype=np.int64)
    offsets = np.concatenate([[0], np.cumsum([len(c) for c in cells])]).astype(np.int64)
    ca = vtk.vtkCellArray()
    ca.SetData(numpy_to_vtkIdTypeArray(offsets, deep=True),
               numpy_to_vtkIdTypeArray(conn.astype(np.int64), deep=True))
    grid.SetCells(cell_type, ca)
    return grid


def _field_data(grid: vtk.vtkDataSet, result: Result, step: Step | None) -> None:
    fd = grid.GetFieldData()
    a = result.attrs
    for key in ("units", "title", "case_file", "voiga_version", "status"):
        fd.AddArray(_string_array(key, [str(a.get(key, ""))]))
    fd.AddArray(_string_array("source", [str(result.path.resolve())]))
    fd.AddArray(_string_array("writer", [f"voiga post vtk (VTK {vtk.vtkVersion.GetVTKVersion()})"]))
    fd.AddArray(_array("step", np.array([0 if step is None else step.step])))
    fd.AddArray(_array("time", np.array([0.0 if step is None else step.time])))
    fd.AddArray(_string_array("body_names", list(result.bodies)))


def body_samples(body: Body, samples: int) -> tuple[np.ndarray, ...]:
    """Sampling of one body: the parameter grids ``(xi grid, eta grid)`` (n_eta, n_xi)
    and the 0-based element of every quad ``(n_eta - 1, n_xi - 1)``; of a solid ``(xi,
    eta, zeta grids)`` (n_zeta, n_eta, n_xi) and the element of every hexahedron."""
    minimum = MIN_SAMPLES if body.nsd == 2 else MIN_SAMPLES_3D
    t = [element_samples(b, samples, minimum) for b in breakpoints(body)]
    mid = [0.5 * (a[1:] + a[:-1]) for a in t]
    grids = np.meshgrid(*t[::-1], indexing="ij")[::-1]  # xi varies along the last axis
    centres = np.meshgrid(*mid[::-1], indexing="ij")[::-1]
    elem = element_of(body, *(c.ravel() for c in centres))[0].reshape(centres[0].shape)
    return (*grids, elem.astype(np.int64))


def _cells(ids: np.ndarray, positive: bool) -> np.ndarray:
    """The cells of a structured block of point ids ``(n_eta, n_xi)`` (quads) or
    ``(n_zeta, n_eta, n_xi)`` (hexahedra) -> ``(n_cells, 4 or 8)``; ``positive``: the
    block's map is right-handed (else the vertex order is mirrored so that every cell
    keeps a positive area or volume)."""
    if ids.ndim == 2:
        quads = np.stack([ids[:-1, :-1], ids[:-1, 1:], ids[1:, 1:], ids[1:, :-1]], axis=-1)
        return (quads if positive else quads[..., ::-1]).reshape(-1, 4)
    corners = [ids[k:ids.shape[0] - 1 + k, j:ids.shape[1] - 1 + j, i:ids.shape[2] - 1 + i]
               for k in (0, 1) for j in (0, 1) for i in (0, 1)]  # bits (zeta, eta, xi)
    order = HEXAHEDRON if positive else LEFT_HANDED_HEXAHEDRON
    return np.stack([corners[c] for c in order], axis=-1).reshape(-1, 8)


def right_handed(x: np.ndarray) -> bool:
    """Whether the map sampled on a grid ``x`` ``(n_eta, n_xi, 2)`` or ``(n_zeta, n_eta,
    n_xi, 3)`` is right-handed (orientation-preserving), judged at its first cell."""
    if x.ndim == 3:
        e1, e2 = x[0, 1] - x[0, 0], x[1, 0] - x[0, 0]
        return bool(e1[0] * e2[1] - e1[1] * e2[0] >= 0)
    e1, e2, e3 = x[0, 0, 1] - x[0, 0, 0], x[0, 1, 0] - x[0, 0, 0], x[1, 0, 0] - x[0, 0, 0]
    return bool(np.dot(np.cross(e1, e2), e3) >= 0)


def bodies_grid(result: Result, step: Step | None, samples: int = SAMPLES) -> vtk.vtkUnstructuredGrid:
    """Every body sampled (see the module docstring)."""
    points, disp, cells, body_id, elem_id = [], [], [], [], []
    offset = 0
    nsd = result.dimension
    for b, (name, body) in enumerate(result.bodies.items()):
        u = body_displacement(result, name, 0 if step is None else step.step)
        *params, elem = body_samples(body, samples)
        x = evaluate(body, None, *params)
        ids = offset + np.arange(params[0].size).reshape(params[0].shape)
        # keep the cells positively oriented (the arc scenes' patches are left-handed)
        cells += list(_cells(ids, right_handed(x)))
        points.append(x.reshape(-1, nsd))
        disp.append(displacement(body, u, *params).reshape(-1, nsd))
        body_id.append(np.full(elem.size, b))
        elem_id.append(elem.reshape(-1))
        offset += params[0].size
    grid = _grid(np.concatenate(points), cells, vtk.VTK_QUAD if nsd == 2 else vtk.VTK_HEXAHEDRON)
    grid.GetPointData().AddArray(_array("displacement", _vec3(np.concatenate(disp))))
    grid.GetCellData().AddArray(_array("body", np.concatenate(body_id)))
    grid.GetCellData().AddArray(_array("element", np.concatenate(elem_id)))
    _field_data(grid, result, step)
    return grid


def master_frame(result: Result, step: Step, c: ContactOutput) -> tuple[np.ndarray, np.ndarray]:
    """Unit outward normals and tangents ``(n, 2)`` of the master at each slave point's
    projection (the directions of ``p_n`` and ``p_t``): the rigid line's, the rigid
    curve's at ``xi_master``, or the master body's contact edge (at eta = 1 of its
    oriented patch) at ``xi_master``."""
    m = len(c.p_n)
    if c.rigid_curve is not None:
        spline = curve_to_splipy(c.rigid_curve)
        xi = np.clip(np.nan_to_num(c.xi_master, nan=0.5), 0.0, 1.0)
        tangent = np.asarray(spline.derivative(xi))[:, :2].reshape(m, 2)
        tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
        return np.column_stack([tangent[:, 1], -tangent[:, 0]]), tangent
    if c.rigid_normal is not None:
        n = np.asarray(c.rigid_normal, dtype=float)
        n = n / np.linalg.norm(n)
        return np.tile(n, (m, 1)), np.tile([n[1], -n[0]], (m, 1))
    body = result.body(c.master)
    u = body_displacement(result, body.name, step.step)
    xi = np.clip(np.nan_to_num(c.xi_master, nan=0.5), 0.0, 1.0)
    h = 1e-6
    lo, hi = np.clip(xi - h, 0, 1), np.clip(xi + h, 0, 1)
    tangent = evaluate(body, u, hi, 1.0) - evaluate(body, u, lo, 1.0)
    tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
    inward = evaluate(body, u, xi, 1.0 - 1e-3) - evaluate(body, u, xi, 1.0)
    normal = np.column_stack([tangent[:, 1], -tangent[:, 0]])
    flip = np.sum(normal * inward, axis=1) > 0
    normal[flip] *= -1.0
    return normal, tangent


def contact_grid(result: Result, step: Step) -> vtk.vtkUnstructuredGrid | None:
    """Slave points of every pair (see the module docstring); None without contact."""
    if not step.contact:
        return None
    pts, cells, data = [], [], {k: [] for k in ("displacement", "p_n", "p_t", "gap", "state",
                                                "traction", "pair")}
    offset = 0
    for k, c in enumerate(step.contact):
        order = np.argsort(c.xi_slave, kind="stable")
        n, t = master_frame(result, step, c)
        pts.append(c.x_ref[order])
        cells.append(offset + np.arange(len(order)))
        data["displacement"].append(_vec3(c.x[order] - c.x_ref[order]))
        data["p_n"].append(c.p_n[order])
        data["p_t"].append(c.p_t[order])
        data["gap"].append(c.gap[order])
        data["state"].append(c.state[order])
        data["traction"].append(_vec3((c.p_n[:, None] * n + c.p_t[:, None] * t)[order]))
        data["pair"].append(np.full(len(order), k))
        offset += len(order)
    grid = _grid(np.concatenate(pts), cells, vtk.VTK_POLY_LINE)
    for key, values in data.items():
        grid.GetPointData().AddArray(_array(key, np.concatenate(values)))
    _field_data(grid, result, step)
    pairs = [f"{c.slave}->{c.master}" for c in step.contact]
    grid.GetFieldData().AddArray(_string_array("pair_names", pairs))
    return grid


def rigid_grid(result: Result, step: Step, samples: int = 400) -> vtk.vtkUnstructuredGrid | None:
    """The rigid masters of the step (see the module docstring); None without any."""
    size = max(float(np.ptp(b.control_points, axis=0).max()) for b in result.bodies.values())
    pts, disp, normals, cells, pair = [], [], [], [], []
    offset = 0
    for k, c in enumerate(step.contact):
        shift = np.zeros(2) if c.rigid_offset is None else np.asarray(c.rigid_offset, dtype=float)
        if c.rigid_curve is not None:
            spline = curve_to_splipy(c.rigid_curve)
            t = np.linspace(0.0, 1.0, samples)
            x = np.asarray(spline(t))[:, :2]
            a = np.asarray(spline.derivative(t))[:, :2]
            n = np.column_stack([a[:, 1], -a[:, 0]]) / np.linalg.norm(a, axis=1)[:, None]
        elif c.rigid_point is not None and c.rigid_normal is not None:
            n1 = np.asarray(c.rigid_normal, dtype=float) / np.linalg.norm(c.rigid_normal)
            reach = 1.5 * size * np.linspace(-1.0, 1.0, 2)[:, None]
            x = np.asarray(c.rigid_point, dtype=float) + reach * np.array([n1[1], -n1[0]])
            n = np.tile(n1, (2, 1))
        else:
            continue
        pts.append(x - shift)
        disp.append(np.tile(shift, (len(x), 1)))
        normals.append(n)
        cells.append(offset + np.arange(len(x)))
        pair.append(k)
        offset += len(x)
    if not pts:
        return None
    grid = _grid(np.concatenate(pts), cells, vtk.VTK_POLY_LINE)
    grid.GetPointData().AddArray(_array("displacement", _vec3(np.concatenate(disp))))
    grid.GetPointData().AddArray(_array("normal", _vec3(np.concatenate(normals))))
    grid.GetCellData().AddArray(_array("pair", np.array(pair)))
    _field_data(grid, result, step)
    return grid


TENSOR_COMPONENTS = ("XX", "YY", "ZZ", "XY", "YZ", "XZ")
"""ParaView's order of a symmetric tensor's six components."""


FILE_COMPONENTS = {"xx yy zz xy": 4, "xx yy zz xy yz xz": 6}
"""The result file's stress and strain components (attribute ``components``) that
:func:`symmetric_tensor` turns into ParaView's order, and their number."""


def symmetric_tensor(values: np.ndarray) -> np.ndarray:
    """(n, 4) [xx, yy, zz, xy] (the result file's plane-strain components) as (n, 6) in
    ParaView's symmetric-tensor order (yz = xz = 0); a solid's (n, 6) [xx, yy, zz, xy, yz,
    xz] are in that order already."""
    v = np.asarray(values, dtype=float)
    if v.ndim == 2 and v.shape[1] == 6:
        return v
    v = v.reshape(-1, 4)
    return np.column_stack([v[:, 0], v[:, 1], v[:, 2], v[:, 3], np.zeros(len(v)), np.zeros(len(v))])


def _sample_cells(fields: dict[str, np.ndarray], samples: int, offset: int, nsd: int = 2,
                  positive: bool = True) -> list[np.ndarray]:
    """Quads (a solid's: hexahedra) joining each element's grid of ``samples`` points
    per direction (xi fastest), or one vertex per point (one sample, or no element
    numbers); ``positive``: the body's map is right-handed (hexahedra: see
    :func:`_cells`; quads are counter-clockwise in the patch's parameters, and
    left-handed patches are fine for VTK)."""
    n = len(fields["xi"])
    per = samples**nsd
    if samples < 2 or "element" not in fields or n % per:
        return [np.array([offset + i]) for i in range(n)]
    block = _cells(np.arange(per).reshape([samples] * nsd), positive or nsd == 2)
    return [offset + e * per + c for e in range(n // per) for c in block]


def fields_grid(result: Result, step: Step) -> vtk.vtkUnstructuredGrid | None:
    """Sampled solver fields (stress, strain, von Mises) of the step, None when the
    file has none: the sample points at their reference positions with
    ``displacement``, joined into quads per element when the solver sampled a grid
    (``&output samples >= 2``; a solid's: hexahedra); ``stress`` and ``strain`` as
    symmetric tensors (``XX YY ZZ XY YZ XZ``) when the file gives their plane-strain
    components or a solid's six."""
    if not step.fields:
        return None
    pts, disp, values, body_id, cells = [], [], {}, [], []
    tensors = set()
    names = list(result.bodies)
    nsd = result.dimension
    params = ("xi", "eta", "zeta")[:nsd]
    offset = 0
    for name, fields in step.fields.items():
        body = result.body(name)
        info = step.field_info.get(name, {})
        at = [fields[p] for p in params]
        n = len(at[0])
        u = body_displacement(result, name, step.step)
        x = evaluate(body, None, *at).reshape(-1, nsd)
        pts.append(x)
        disp.append(combine(body, u, *at).reshape(-1, nsd))
        body_id.append(np.full(n, names.index(name)))
        samples = int(info.get("samples", 1))
        positive = nsd == 2 or samples < 2 or n < samples**3 or \
            right_handed(x[:samples**3].reshape(samples, samples, samples, 3))
        cells += _sample_cells(fields, samples, offset, nsd, positive)
        offset += n
        components = FILE_COMPONENTS.get(str(info.get("components", "")))
        for key, v in fields.items():
            if key in params:
                continue
            if components and key in ("stress", "strain"):
                v = symmetric_tensor(np.asarray(v).reshape(n, components))
                tensors.add(key)
            values.setdefault(key, []).append(np.asarray(v).reshape(n, -1))
    points = np.concatenate(pts)
    kind = {4: vtk.VTK_QUAD, 8: vtk.VTK_HEXAHEDRON}.get(len(cells[0]) if cells else 1, vtk.VTK_VERTEX)
    grid = _grid(points, cells, kind)
    grid.GetPointData().AddArray(_array("displacement", _vec3(np.concatenate(disp))))
    grid.GetPointData().AddArray(_array("body", np.concatenate(body_id)))
    for key, parts in values.items():
        arr = _array(key, np.concatenate(parts))
        if key in tensors:
            for i, c in enumerate(TENSOR_COMPONENTS):
                arr.SetComponentName(i, c)
        grid.GetPointData().AddArray(arr)
    _field_data(grid, result, step)
    for name, info in step.field_info.items():
        for key in ("stress_measure", "strain_measure"):
            if key in info:
                grid.GetFieldData().AddArray(_string_array(f"{name}: {key}", [str(info[key])]))
    return grid


def _write(grid: vtk.vtkUnstructuredGrid, path: Path) -> None:
    writer = vtk.vtkXMLUnstructuredGridWriter()
    writer.SetInputData(grid)
    writer.SetDataModeToAppended()
    writer.EncodeAppendedDataOff()
    writer.SetCompressorTypeToZLib()
    with new_file(path) as tmp:
        writer.SetFileName(str(tmp))
        if writer.Write() != 1:
            raise OSError(f"VTK could not write {path}")


def write_vtk(result: Result, out: str | Path | None = None, samples: int = SAMPLES,
              output: str | Path | None = None) -> Path:
    """Write the ParaView series of ``result``: ``<result stem>.pvd`` (next to the
    result, in ``out``, or at ``output``) and its ``.vtu`` files in the folder
    ``<result stem>-vtk/`` beside it. Returns the ``.pvd`` path."""
    if samples < 1:
        raise ValueError("samples must be >= 1")
    pvd = Path(output) if output else output_path(result.path, None, out=out, ext="pvd")
    folder = pvd.with_name(f"{pvd.stem}-vtk")
    folder.mkdir(parents=True, exist_ok=True)
    root = ET.Element("VTKFile", type="Collection", version="0.1")
    coll = ET.SubElement(root, "Collection")
    for step in [None, *result.steps]:
        number, time = (0, 0.0) if step is None else (step.step, step.time)
        parts = [("bodies", bodies_grid(result, step, samples))]
        if step is not None:
            parts += [("contact", contact_grid(result, step)), ("rigid", rigid_grid(result, step)),
                      ("fields", fields_grid(result, step))]
        for index, (what, grid) in enumerate(parts):
            if grid is None:
                continue
            path = folder / f"{what}-{number:06d}.vtu"
            _write(grid, path)
            ET.SubElement(coll, "DataSet", timestep=repr(float(time)), part=str(index),
                          name=what, file=f"{folder.name}/{path.name}")
    ET.indent(root)
    write_text(pvd, ET.tostring(root, encoding="unicode") + "\n")
    return pvd
