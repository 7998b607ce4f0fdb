"""``python -m post vtk``: the ParaView series read back with VTK's own XML readers
(the ones ParaView uses) and compared with the result file."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import h5py
import numpy as np
import pytest
import vtk
from vtk.util.numpy_support import vtk_to_numpy

from post.__main__ import main
from post.field import displacement
from post.reader import body_displacement, read_result

from .conftest import exact_stretch


def _read(path: Path) -> vtk.vtkUnstructuredGrid:
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    assert reader.GetErrorCode() == 0, path
    return reader.GetOutput()


def _points(grid) -> np.ndarray:
    return vtk_to_numpy(grid.GetPoints().GetData())


def _pdata(grid, name: str) -> np.ndarray:
    arr = grid.GetPointData().GetArray(name)
    assert arr is not None, name
    return vtk_to_numpy(arr)


def _string(grid, name: str) -> str:
    arr = grid.GetFieldData().GetAbstractArray(name)
    assert arr is not None, name
    return arr.GetValue(0)


def _series(pvd: Path) -> list[tuple[float, str, Path]]:
    root = ET.parse(pvd).getroot()
    return [(float(d.get("timestep")), d.get("name"), pvd.parent / d.get("file"))
            for d in root.iter("DataSet")]


def test_stretch_series_matches_the_exact_field(stretch_h5: Path, tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["vtk", str(stretch_h5), "--out", str(tmp_path)]) == 0
    pvd = tmp_path / "stretch.pvd"
    assert capsys.readouterr().out.strip() == str(pvd)
    result = read_result(stretch_h5)
    series = _series(pvd)
    assert [t for t, _, _ in series] == [0.0] + [s.time for s in result.steps]
    assert all(name == "bodies" for _, name, _ in series)  # no contact in this case
    for time, _, path in series[1:]:
        grid = _read(path)
        x, u = _points(grid)[:, :2], _pdata(grid, "displacement")
        assert np.all(_points(grid)[:, 2] == 0) and np.all(u[:, 2] == 0)
        # the sampled displacement is the exact linear field of the stretch
        assert np.abs(u[:, :2] - exact_stretch(x, time)).max() < 1e-12
        assert grid.GetNumberOfCells() > 0
        assert grid.GetCellType(0) == vtk.VTK_QUAD
        elem = vtk_to_numpy(grid.GetCellData().GetArray("element"))
        assert elem.min() == 0 and elem.max() == result.bodies["slab"].n_elements - 1
        assert _string(grid, "units") == result.attrs["units"]
        assert _string(grid, "source") == str(stretch_h5.resolve())
        assert _string(grid, "voiga_version") == result.voiga_version
        assert "VTK" in _string(grid, "writer")
        assert vtk_to_numpy(grid.GetFieldData().GetArray("time"))[0] == time
    ref = _read(series[0][2])
    assert np.abs(_pdata(ref, "displacement")).max() == 0.0


def test_two_bodies_points_and_displacement(two_h5: Path, tmp_path: Path) -> None:
    result = read_result(two_h5)
    from post.paraview import body_samples, write_vtk

    pvd = write_vtk(result, out=tmp_path, samples=3)
    grid = _read(_series(pvd)[-1][2])
    body_id = vtk_to_numpy(grid.GetCellData().GetArray("body"))
    names = grid.GetFieldData().GetAbstractArray("body_names")
    assert [names.GetValue(i) for i in range(names.GetNumberOfValues())] == list(result.bodies)
    u_all = _pdata(grid, "displacement")[:, :2]
    offset = 0
    for b, (name, body) in enumerate(result.bodies.items()):
        xx, ee, elem = body_samples(body, 3)
        u = displacement(body, body_displacement(result, name), xx, ee).reshape(-1, 2)
        assert np.abs(u_all[offset:offset + len(u)] - u).max() < 1e-13
        assert np.count_nonzero(body_id == b) == elem.size and elem.min() >= 0
        offset += len(u)
    assert offset == grid.GetNumberOfPoints()
    # every quad is counter-clockwise (positive area), the arc die's too
    pts = _points(grid)[:, :2]
    conn = vtk_to_numpy(grid.GetCells().GetConnectivityArray()).reshape(-1, 4)
    a, b, c = pts[conn[:, 0]], pts[conn[:, 1]], pts[conn[:, 2]]
    cross = (b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]
    assert np.all(cross > 0)


@pytest.mark.parametrize("which", ["hertz_h5", "press_h5"])
def test_contact_edge_fields(which: str, request: pytest.FixtureRequest, tmp_path: Path) -> None:
    path = request.getfixturevalue(which)
    result = read_result(path)
    assert main(["vtk", str(path), "--out", str(tmp_path)]) == 0
    contact = [(t, p) for t, name, p in _series(tmp_path / f"{path.stem}.pvd") if name == "contact"]
    assert len(contact) == len(result.steps)
    for (_time, vtu), step in zip(contact, result.steps, strict=True):
        grid = _read(vtu)
        c = step.contact[0]
        order = np.argsort(c.xi_slave, kind="stable")
        np.testing.assert_array_equal(_points(grid)[:, :2], c.x_ref[order])
        np.testing.assert_array_equal(_pdata(grid, "displacement")[:, :2], (c.x - c.x_ref)[order])
        for key in ("p_n", "p_t", "gap", "state"):
            np.testing.assert_array_equal(_pdata(grid, key), getattr(c, key)[order])
        tr = _pdata(grid, "traction")[:, :2]
        # |traction| = sqrt(p_n^2 + p_t^2) (normal and tangent are unit and orthogonal)
        np.testing.assert_allclose(np.linalg.norm(tr, axis=1), np.hypot(c.p_n, c.p_t)[order],
                                   rtol=1e-12, atol=1e-300)
        # the pressure pushes the slave away from the master: along the resultant force
        active = c.active[order]
        assert np.all(tr[active] @ c.force > 0)
        if c.rigid_normal is not None:
            np.testing.assert_allclose(tr @ c.rigid_normal, c.p_n[order], rtol=1e-12, atol=1e-15)
        pair = grid.GetFieldData().GetAbstractArray("pair_names")
        assert pair.GetValue(0) == f"{c.slave}->{c.master}"


def test_solver_fields_are_exported_when_present(two_h5: Path, tmp_path: Path) -> None:
    """Any field a file has under ``/steps/<k>/fields/<body>`` (here added by hand,
    without the solver's attributes: one vertex per point, arrays as they are) gets a
    ``fields`` part (the solver's own fields: test/python/test_fields.py)."""
    path = tmp_path / "two.h5"
    path.write_bytes(two_h5.read_bytes())
    xi = np.array([0.1, 0.5, 0.9])
    eta = np.array([0.2, 0.5, 0.8])
    stress = np.arange(12.0).reshape(3, 4)
    with h5py.File(path, "r+") as f:
        g = f.create_group("steps/000003/fields/slab")
        g["xi"], g["eta"], g["stress"], g["von_mises"] = xi, eta, stress, stress[:, 0]
    result = read_result(path)
    assert set(result.steps[-1].fields["slab"]) == {"xi", "eta", "stress", "von_mises"}
    assert main(["vtk", str(path)]) == 0
    parts = [(t, p) for t, name, p in _series(tmp_path / "two.pvd") if name == "fields"]
    assert len(parts) == 1 and parts[0][0] == result.steps[-1].time
    grid = _read(parts[0][1])
    np.testing.assert_array_equal(_pdata(grid, "stress"), stress)
    np.testing.assert_array_equal(_pdata(grid, "von_mises"), stress[:, 0])
    from post.field import evaluate
    np.testing.assert_allclose(_points(grid)[:, :2], evaluate(result.bodies["slab"], None, xi, eta),
                               atol=1e-14)
