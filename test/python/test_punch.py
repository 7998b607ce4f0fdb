"""A rigid circular punch pressed into an elastic block (issue 18, item 3): a rigid
master bounded by a curve of the geometry file (``[[curve]]`` of a ``pre geometry``
spec, ``&contact rigid_curve``), moved by its prescribed motion (``rigid_uy``).

The block (10 x 5, linear elastic, E = 1, nu = 0.3, bottom fixed) is large against the
contact zone (half-width a <= 0.44 against the punch radius R = 10 and the block's
half-height 5), so the contact is Hertz's line contact of a rigid cylinder on an
elastic half-space: a = sqrt(4 P R / (pi E*)), p0 = 2 P / (pi a), E* = E/(1 - nu^2),
with P the contact force per length. The indentation depth itself is not a local
quantity in 2D (it grows with the logarithm of the body's size), so the force law is
checked through the contact width and the peak pressure at every step.
"""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import f90nml
import h5py
import numpy as np
import pytest

from post.hertz import fit_hertz, hertz_reference
from post.reader import read_result

SPEC = """
units = "mm, N"
scene = "punch"

[defaults]
layout = "NN2.2"
material = "linear"
youngs_modulus = 1.0
poisson_ratio = 0.3

[[body]]
name = "block"
shape = "rectangle"
x = [-5.0, 5.0]
y = [-5.0, 0.0]
contact_edge = "top"
nel = [10, 5]

[[curve]]
name = "punch"
shape = "arc"
centre = [0.0, 10.0]
radius = 10.0
angles = [240.0, 300.0]

[solver]
n_steps = 4

[[dirichlet]]
body = "block"
edge = "bottom"
fix_x = true
fix_y = true

[[contact]]
slave = "block"
master = "rigid"
rigid_curve = "punch"
rigid_uy = -0.03
penalty_normal = 1000.0
"""

RADIUS, DEPTH = 10.0, 0.03


def graded(lo: float, hi: float, fine: tuple[float, float], h: float, ratio: float = 1.35) -> list[float]:
    """Interior knots of [lo, hi] mapped to [0, 1]: spacing ``h`` on ``fine``, growing
    by ``ratio`` per element outside it."""
    x = list(np.arange(fine[0], fine[1] + h / 2, h))
    for start, sign, end in ((fine[0], -1.0, lo), (fine[1], 1.0, hi)):
        p, d = start, h
        while True:
            d *= ratio
            p += sign * d
            if sign * (end - p) <= 0.5 * d:
                break
            x.append(p)
    k = (np.array(sorted(x)) - lo) / (hi - lo)
    return [float(v) for v in k if 1e-9 < v < 1.0 - 1e-9]


@pytest.fixture(scope="module")
def punch(voiga_bin: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The spec built by ``python -m pre geometry``, the block refined towards the
    contact (element size 0.04 where it is), solved; returns the result file."""
    folder = tmp_path_factory.mktemp("punch")
    spec = folder / "punch.toml"
    spec.write_text(SPEC)
    out = subprocess.run([sys.executable, "-m", "pre", "geometry", str(spec)], capture_output=True,
                         text=True)
    assert out.returncode == 0, out.stderr
    case = folder / "punch.nml"
    nml = f90nml.read(case)
    body = nml["body"]
    body["knots_xi"] = graded(-5.0, 5.0, (-1.0, 1.0), 0.04)
    body["knots_eta"] = graded(-5.0, 0.0, (-0.8, 0.0), 0.04)
    del body["nel_xi"], body["nel_eta"]
    nml.write(case, force=True)
    res = subprocess.run([str(voiga_bin), str(case), "--quiet"], capture_output=True, text=True,
                         timeout=300)
    assert res.returncode == 0, res.stderr
    return folder / "punch.h5"


def test_hertz_contact_width_and_pressure(punch: Path) -> None:
    """At every step the pressure profile's half-width and peak (least-squares fit of
    p^2 = p0^2 (1 - x^2/a^2)) agree with Hertz for the step's own force. Measured:
    a -0.1 % .. -0.8 %, p0 +0.04 % .. +0.8 %, growing with a/H (the block's finite
    depth); the largest pressure at a slave point within 0.9 % of p0."""
    result = read_result(punch)
    assert result.converged and len(result.steps) == 4
    forces = []
    for step in result.steps:
        c = step.contact[0]
        force = -float(c.force[1])
        a, p0 = hertz_reference(force, 1.0, 0.3, RADIUS)
        a_fit, p0_fit = fit_hertz(c.x[c.active, 0], c.p_n[c.active])
        assert abs(a_fit / a - 1.0) < 0.015, (step.step, a_fit, a)
        assert abs(p0_fit / p0 - 1.0) < 0.015, (step.step, p0_fit, p0)
        assert abs(c.p_n.max() / p0 - 1.0) < 0.015, (step.step, c.p_n.max(), p0)
        forces.append(force)
    # the force grows with the indentation, and faster than linearly (the zone grows)
    f = np.array(forces)
    assert np.all(np.diff(f) > 0) and np.all(np.diff(f, 2) > 0), f


def test_equilibrium_and_symmetry(punch: Path) -> None:
    """The contact force on the block equals minus the reaction of its support, there is
    no horizontal force, and the pressure is symmetric about the punch's axis (the mesh
    is symmetric: round-off)."""
    result = read_result(punch)
    for step in result.steps:
        c = step.contact[0]
        scale = abs(c.force[1])
        assert np.allclose(c.force, -step.reactions[0], rtol=0, atol=1e-9 * scale)
        assert abs(c.force[0]) <= 1e-10 * scale
        order = np.argsort(c.x_ref[:, 0])
        p = c.p_n[order]
        assert np.allclose(p, p[::-1], rtol=0, atol=1e-9 * p.max())
        assert np.allclose(c.x_ref[order, 0], -c.x_ref[order[::-1], 0], atol=1e-12)


def test_result_file_carries_the_moved_curve(punch: Path) -> None:
    """Each step holds the punch where it is: the geometry's curve translated by the
    prescribed motion at the step's load time (rigid_uy linear in the phase)."""
    with h5py.File(punch.with_name("punch-geometry.h5")) as f:
        cp0 = f["curves/punch/control_points"][()]
        w0 = f["curves/punch/weights"][()]
    result = read_result(punch)
    for step in result.steps:
        c = step.contact[0]
        assert c.rigid_curve is not None and c.rigid_point is None
        offset = np.array([0.0, -DEPTH * step.time])
        np.testing.assert_allclose(c.rigid_offset, offset, rtol=0, atol=1e-15)
        np.testing.assert_allclose(c.rigid_curve.control_points, cp0 + offset, rtol=0, atol=1e-15)
        np.testing.assert_array_equal(c.rigid_curve.weights, w0)
    assert result.units.length == "mm"


def test_post_draws_and_exports_the_punch(punch: Path, tmp_path: Path) -> None:
    """``post plot-deformed`` draws the punch; ``post vtk`` writes it as the ``rigid``
    part (VTK reads it back: the curve at its reference position, displaced by the
    translation)."""
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    from post.paraview import write_vtk
    from post.plot import plot_deformed, rigid_curves

    result = read_result(punch)
    (pts, normals, _), = rigid_curves(result.steps[-1])
    # the lowest sample of the punch (400 samples: within 1e-5 of the lowest point),
    # its normal pointing down into the block
    low = np.argmin(pts[:, 1])
    assert pts[low, 1] == pytest.approx(-DEPTH, abs=1e-4)
    assert normals[low, 1] == pytest.approx(-1.0, abs=1e-4)
    assert plot_deformed(result, output=tmp_path / "d.png").stat().st_size > 0
    pvd = write_vtk(result, out=tmp_path)
    rigid = sorted((pvd.parent / f"{pvd.stem}-vtk").glob("rigid-*.vtu"))
    assert len(rigid) == 4
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(rigid[-1]))
    reader.Update()
    grid = reader.GetOutput()
    x = vtk_to_numpy(grid.GetPoints().GetData())[:, :2]
    u = vtk_to_numpy(grid.GetPointData().GetArray("displacement"))[:, :2]
    assert np.allclose(u, [0.0, -DEPTH], atol=1e-15)
    assert np.hypot(x[:, 0], x[:, 1] - RADIUS) == pytest.approx(RADIUS, abs=1e-9)


@pytest.mark.parametrize("change, message", [
    ({"rigid_curve": "nothing"}, "no curve 'nothing'"),
    ({"master": "block2"}, "but master = 'block2' (set master = 'rigid')"),
])
def test_bad_rigid_curve_input(run, punch: Path, tmp_path: Path, change: dict, message: str) -> None:
    """A curve the geometry file lacks, or a rigid curve on a non-rigid master: exit 2,
    one message naming the group and the cause."""
    nml = f90nml.read(punch.with_suffix(".nml"))
    nml["contact"].update(change)
    nml["case"]["geometry"] = str(punch.with_name("punch-geometry.h5"))
    case = tmp_path / "bad.nml"
    nml.write(case)
    res = run(case, "--check")
    assert res.returncode == 2, res.stdout + res.stderr
    assert "&contact (1)" in res.stderr and message in res.stderr, res.stderr
