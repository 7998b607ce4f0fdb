"""post on results of solids (dimension 3), written by the voiga binary: the box of
test/python/test_solid_case.py in uniaxial tension (exact field in the NURBS space),
the same box with its contact face elsewhere (the solver turns the patch), and a
rational quarter cylinder with a layer. The reader, the exact map of post.field,
summary, history, vtk (read back with VTK's reader) and plot-deformed."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest
import vtk
from vtk.util.numpy_support import vtk_to_numpy

from post.__main__ import main
from post.field import displacement, evaluate, evaluate_grid
from post.quantity import element_of, sampled_quantity
from post.reader import Surface, body_displacement, read_result
from pre.volume import Volume

from .conftest import NU, SIGMA, exact_box
from .test_paraview import _pdata, _points, _read, _series

TOL = 1e-12
"""The box's field is in the NURBS space: only round-off (about 1e-16 of the 0.03
largest displacement, summed over some 100 functions) separates it from the exact one."""

BOX_CORNERS = np.array([[x, y, z] for z in (0.0, 1.0) for y in (0.0, 2.0) for x in (0.0, 3.0)])


def _rows(a: np.ndarray) -> set[tuple[float, ...]]:
    return {tuple(r) for r in np.asarray(a).reshape(-1, 3)}


def test_reader_reads_a_solid(box_h5: Path) -> None:
    r = read_result(box_h5)
    assert r.dimension == 3 and r.axes == ("x", "y", "z") and r.converged
    body = r.bodies["block"]
    assert body.nsd == 3 and body.boundary == "face"
    assert set(body.faces) == {"left", "right", "front", "back", "bottom", "top"}
    assert body.element_ranges.shape == (12, 6) and body.n_elements == 12
    assert body.element_vo.sum() == 6  # the slice of elements at the contact face
    assert isinstance(body.bulk, Volume) and isinstance(body.layer, Surface)
    assert body.control_points.shape == (body.ncp, 3)
    assert [d.edge for d in r.dirichlet] == ["left", "front", "bottom"]
    for s in r.steps:
        assert s.reactions.shape == (3, 3) and len(s.displacement) == 3 * body.ncp
        f = s.fields["block"]
        assert f["stress"].shape == (12 * 8, 6) and f["zeta"].shape == (12 * 8,)
        assert np.array_equal(f["element"], np.repeat(np.arange(12), 8))
        # the control points move by the exact field
        u = body_displacement(r, "block", s.step)
        assert np.abs(u - exact_box(body.control_points, s.time)).max() < TOL
    # the top face lists the layer's points, which are numbered last
    n_bulk = body.ncp - len(body.layer.weights)
    assert np.array_equal(np.sort(body.faces["top"]), np.arange(n_bulk, body.ncp))


@pytest.mark.parametrize("which", ["box_h5", "turned_box_h5"])
def test_map_reproduces_the_box(which: str, request: pytest.FixtureRequest) -> None:
    """The corners of the parameter cube are the box's corners (exactly), and the
    displacement is the exact field everywhere; for the turned box too, whose patch
    the solver rotated so that the back face is zeta = 1."""
    r = read_result(request.getfixturevalue(which))
    body = r.bodies["block"]
    corners = evaluate_grid(body, None, [0.0, 1.0], [0.0, 1.0], [0.0, 1.0])
    assert _rows(corners) == _rows(BOX_CORNERS)
    rng = np.random.default_rng(1)
    xi, eta, zeta = rng.random((3, 2000))
    x = evaluate(body, None, xi, eta, zeta)
    assert np.all((x >= 0) & (x <= [3.0, 2.0, 1.0]))
    for s in r.steps:
        u = body_displacement(r, "block", s.step)
        assert np.abs(displacement(body, u, xi, eta, zeta) - exact_box(x, s.time)).max() < TOL
        assert np.abs(evaluate(body, u, xi, eta, zeta) - x - exact_box(x, s.time)).max() < TOL
    if which == "turned_box_h5":  # the contact face (zeta = 1) is the back face y = 2
        assert np.all(evaluate(body, None, xi, eta, 1.0)[:, 1] == 2.0)


def test_map_of_a_rational_solid_with_a_layer(cylinder_h5: Path) -> None:
    """The quarter cylinder's faces zeta = 0 and 1 (inner, outer: the layer) lie on the
    cylinders r = 1 and 2, inside r is between them."""
    body = read_result(cylinder_h5).bodies["tube"]
    assert body.layer is not None and np.ptp(body.weights) > 0
    rng = np.random.default_rng(2)
    xi, eta, zeta = rng.random((3, 2000))
    for z, radius in ((0.0, 1.0), (1.0, 2.0)):
        x = evaluate(body, None, xi, eta, z)
        assert np.abs(np.hypot(x[:, 0], x[:, 1]) - radius).max() < 1e-14
    r = np.hypot(*evaluate(body, None, xi, eta, zeta)[:, :2].T)
    assert np.all((r > 1.0) & (r < 2.0))


@pytest.mark.parametrize("which", ["box_h5", "cylinder_h5"])
def test_support_matches_the_solver_connectivity(which: str, request: pytest.FixtureRequest) -> None:
    """Inside an element only its connectivity's control points act (the layer's in the
    VO elements): the numbering of post.field is the solver's."""
    r = read_result(request.getfixturevalue(which))
    body = next(iter(r.bodies.values()))
    rng = np.random.default_rng(3)
    for k in range(body.n_elements):
        lo, hi = body.element_ranges[k, ::2], body.element_ranges[k, 1::2]
        t = lo + (hi - lo) * rng.random((40, 3))
        others = np.setdiff1d(np.arange(body.ncp), body.element(k))
        u = np.zeros((body.ncp, 3))
        u[others] = rng.standard_normal((len(others), 3))
        assert np.abs(displacement(body, u, *t.T)).max() == 0.0, k
        e, *_ = element_of(body, *t.T)
        assert np.all(e == k)


def test_sampled_quantity_of_a_solid(box_h5: Path) -> None:
    r = read_result(box_h5)
    body, step = r.bodies["block"], r.steps[-1]
    rng = np.random.default_rng(4)
    xi, eta, zeta = rng.random((3, 500))
    assert np.abs(sampled_quantity(step, body, "stress_xx", xi, eta, zeta) - SIGMA).max() < TOL
    assert np.abs(sampled_quantity(step, body, "stress_yz", xi, eta, zeta)).max() < TOL
    strain = sampled_quantity(step, body, "strain_zz", xi, eta, zeta)
    assert np.abs(strain + NU * SIGMA / 2.0).max() < TOL
    # at a sample the value is the solver's, bitwise
    f = step.fields["block"]
    at = sampled_quantity(step, body, "von_mises", f["xi"], f["eta"], f["zeta"])
    assert np.array_equal(at, f["von_mises"])


def test_summary_of_a_solid(box_h5: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["summary", str(box_h5)]) == 0
    out = capsys.readouterr().out
    assert "(3D)" in out.splitlines()[0]
    r = read_result(box_h5)
    line = next(x for x in out.splitlines() if "reaction on block/left" in x)
    # three components, in force (not per thickness); the left support holds SIGMA x area
    values = [float(v) for v in line.split("(")[1].split(")")[0].split(",")]
    assert len(values) == 3 and abs(values[0] + SIGMA * 2.0) < 1e-9
    assert line.endswith(" N")
    assert np.allclose(values, r.steps[-1].reactions[0], rtol=1e-5, atol=1e-12)


def test_history_of_a_solid(box_h5: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["history", str(box_h5), "--out", str(tmp_path)]) == 0
    csv_path, png = (Path(p) for p in capsys.readouterr().out.split())
    assert png.is_file() and png.stat().st_size > 0
    with open(csv_path) as f:
        rows = list(csv.DictReader(f))
    r = read_result(box_h5)
    assert len(rows) == len(r.steps)
    for row, s in zip(rows, r.steps, strict=True):
        for k, d in enumerate(r.dirichlet):
            got = [float(row[f"reaction_{a} {d.body}/{d.edge}"]) for a in "xyz"]
            assert got == list(s.reactions[k])
        assert abs(float(row["reaction_x block/left"]) + SIGMA * 2.0 * s.time) < 1e-12


def _volumes(grid: vtk.vtkUnstructuredGrid) -> np.ndarray:
    quality = vtk.vtkMeshQuality()
    quality.SetInputData(grid)
    quality.SetHexQualityMeasureToVolume()
    quality.Update()
    return vtk_to_numpy(quality.GetOutput().GetCellData().GetArray("Quality"))


@pytest.mark.parametrize("which", ["box_h5", "turned_box_h5"])
def test_vtk_of_a_solid(which: str, request: pytest.FixtureRequest, tmp_path: Path) -> None:
    """The ParaView series read back: hexahedra of positive volume filling the box, the
    displacement the exact field at every point, the fields as hexahedra per element with
    the uniform stress and strain as symmetric tensors."""
    path = request.getfixturevalue(which)
    r = read_result(path)
    body = r.bodies["block"]
    assert main(["vtk", str(path), "--out", str(tmp_path)]) == 0
    series = _series(tmp_path / f"{path.stem}.pvd")
    bodies = [(t, p) for t, name, p in series if name == "bodies"]
    fields = [(t, p) for t, name, p in series if name == "fields"]
    assert [t for t, _ in bodies] == [0.0] + [s.time for s in r.steps]
    assert [t for t, _ in fields] == [s.time for s in r.steps]
    for time, p in bodies:
        grid = _read(p)
        x, u = _points(grid), _pdata(grid, "displacement")
        assert grid.GetCellType(0) == vtk.VTK_HEXAHEDRON
        assert grid.GetNumberOfCells() >= 16**3
        volumes = _volumes(grid)
        assert volumes.min() > 0 and abs(volumes.sum() - 6.0) < 1e-12
        assert np.abs(u - exact_box(x, time)).max() < TOL
        # the corners are sample points: the box's corners, moved as its corner control points
        corners = [int(np.flatnonzero(np.all(x == c, axis=1))[0]) for c in BOX_CORNERS]
        cp = [int(np.flatnonzero(np.all(body.control_points == c, axis=1))[0]) for c in BOX_CORNERS]
        step = r.steps[[s.time for s in r.steps].index(time)].step if time else 0
        assert np.abs(u[corners] - body_displacement(r, "block", step)[cp]).max() < 1e-15
        elem = vtk_to_numpy(grid.GetCellData().GetArray("element"))
        assert elem.min() == 0 and elem.max() == body.n_elements - 1
    samples = int(r.steps[-1].field_info["block"]["samples"])
    for (time, p), s in zip(fields, r.steps, strict=True):
        grid = _read(p)
        x = _points(grid)
        assert grid.GetNumberOfPoints() == 12 * samples**3
        assert grid.GetCellType(0) == vtk.VTK_HEXAHEDRON
        assert grid.GetNumberOfCells() == 12 * (samples - 1)**3
        volumes = _volumes(grid)
        assert volumes.min() > 0 and abs(volumes.sum() - 6.0) < 1e-12
        assert np.abs(_pdata(grid, "displacement") - exact_box(x, time)).max() < TOL
        stress = grid.GetPointData().GetArray("stress")
        assert [stress.GetComponentName(i) for i in range(6)] == ["XX", "YY", "ZZ", "XY", "YZ", "XZ"]
        assert np.abs(vtk_to_numpy(stress) - [SIGMA * time, 0, 0, 0, 0, 0]).max() < TOL
        strain = SIGMA * time / 2.0 * np.array([1.0, -NU, -NU, 0.0, 0.0, 0.0])
        assert np.abs(_pdata(grid, "strain") - strain).max() < TOL
        assert np.abs(_pdata(grid, "von_mises") - SIGMA * time).max() < TOL
        assert np.array_equal(_pdata(grid, "stress"), s.fields["block"]["stress"])


def test_plot_deformed_of_a_solid(box_h5: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    for field in ("u", "uz", "von_mises", "stress_xz"):
        assert main(["plot-deformed", str(box_h5), "--out", str(tmp_path), "--field", field,
                     "--reference"]) == 0
        png = Path(capsys.readouterr().out.strip())
        assert png.is_file() and png.stat().st_size > 10_000, field
    assert main(["plot-deformed", str(box_h5), "--out", str(tmp_path), "--step", "0"]) == 0
    assert main(["plot-deformed", str(box_h5), "--out", str(tmp_path), "--step", "0",
                 "--field", "von_mises"]) == 2
    assert "no stress" in capsys.readouterr().err


def test_plot_deformed_refuses_z_on_a_plane_result(stretch_h5: Path, tmp_path: Path,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["plot-deformed", str(stretch_h5), "--out", str(tmp_path), "--field", "uz"]) == 2
    assert "not a quantity of a plane (2D) result" in capsys.readouterr().err
