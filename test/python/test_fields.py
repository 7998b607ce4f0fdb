"""Stress, strain and von Mises fields written by the solver (issue 18, item 4;
``&output``, docs/hdf5.md "Sampled fields").

- A uniformly compressed block: every sample equals the analytic plane-strain state
  (linear law to 1e-10; Neo-Hookean with its Hencky strain against the law solved
  for the free stretch).
- ParaView: the ``fields`` part read back with VTK equals the result file.
- Only the steps ``&output`` asks for get fields; bad ``&output`` input exits 2.
- Hertz line contact, the maximum subsurface shear stress tau_1 = (sigma_1 -
  sigma_2)/2 on the axis. Plane strain, McEwen's field on the axis (zeta = z/a):
  sigma_x = -p0 ((1 + 2 zeta^2)/sqrt(1 + zeta^2) - 2 zeta), sigma_z = -p0/sqrt(1 + zeta^2),
  tau_xz = 0, so tau_1/p0 = zeta - zeta^2/sqrt(1 + zeta^2); d/dzeta = 0 gives
  zeta^4 + zeta^2 - 1 = 0: zeta* = sqrt((sqrt 5 - 1)/2) = 0.78615 and tau_1/p0 =
  0.30028. p0 and a come from the run's own contact force (twice the quarter
  model's, per reference length): a = sqrt(4 P R/(pi E*)), p0 = 2 P/(pi a).
  The hertz scene is a disc of radius R compressed between two flats (its top edge
  on rollers is the disc's plane of symmetry), so it is Hertz's half-space only as
  a/R -> 0; the diametral compression adds P/(pi (2R - z)) to tau_1 on the axis (two
  Flamant loads and the uniform tension P/(pi R) of the disc). docs/verification.md
  has the numbers.
"""
from __future__ import annotations

import shutil
from pathlib import Path

import f90nml
import h5py
import numpy as np
import pytest
from scipy.optimize import brentq

from conftest import REPO
from post.field import evaluate
from post.hertz import hertz_reference
from post.paraview import write_vtk
from post.reader import read_result
from pre.cases import to_namelist_text
from pre.geometry import rectangle, write_bodies

E, NU, DY = 1.0, 0.3, -0.01
ZETA = np.sqrt((np.sqrt(5.0) - 1.0) / 2.0)
TAU_MAX = ZETA - ZETA**2 / np.sqrt(1.0 + ZETA**2)


def compressed_block(folder: Path, material: str, dy: float = DY, output: dict | None = None) -> Path:
    """A unit block (NN2.2, 3 x 3 elements, a VO layer at the top) on rollers at its
    bottom and left edges, its top pushed down by ``dy`` in 2 steps; returns the case."""
    write_bodies(folder / "geometry.h5", {"block": rectangle([0.0, 1.0], [0.0, 1.0])}, scene="block")
    case = {
        "case": {"title": "block", "geometry": "geometry.h5", "output": "block.h5", "n_bodies": 1},
        "body": {"name": "block", "material": material, "youngs_modulus": E, "poisson_ratio": NU,
                 "degree_xi": 2, "degree_eta": 2, "nel_xi": 3, "nel_eta": 3, "contact_edge": "top",
                 "layer_degree": 2, "layer_elevations": 2},
        "solver": {"n_steps": 2},
        "dirichlet": [{"body": "block", "edge": "bottom", "fix_y": True},
                      {"body": "block", "edge": "left", "fix_x": True},
                      {"body": "block", "edge": "top", "fix_y": True, "uy": dy}],
    }
    if output is not None:
        case["output"] = output
    path = folder / "block.nml"
    path.write_text(to_namelist_text(case))
    return path


def test_uniform_compression_linear(run, tmp_path: Path) -> None:
    """Small strain, sigma_xx = 0: eps_yy = dy, eps_xx = -nu/(1 - nu) eps_yy,
    sigma_yy = E/(1 - nu^2) eps_yy, sigma_zz = nu sigma_yy, von Mises from the three;
    the displacement is linear, which the NURBS space holds exactly: round-off."""
    case = compressed_block(tmp_path, "linear", output={"samples": 3})
    res = run(case, "--quiet")
    assert res.returncode == 0, res.stderr
    result = read_result(tmp_path / "block.h5")
    for step in result.steps:
        eyy = DY * step.time
        syy = E / (1.0 - NU**2) * eyy
        want_s = np.array([0.0, syy, NU * syy, 0.0])
        want_e = np.array([-NU / (1.0 - NU) * eyy, eyy, 0.0, 0.0])
        f = step.fields["block"]
        assert f["stress"].shape == (9 * 9, 4) and f["xi"].shape == (81,)
        assert np.abs(f["stress"] - want_s).max() <= 1e-10 * abs(syy)
        assert np.abs(f["strain"] - want_e).max() <= 1e-10 * abs(eyy)
        vm = np.sqrt(0.5 * ((0 - syy) ** 2 + (syy - NU * syy) ** 2 + (NU * syy) ** 2))
        assert np.abs(f["von_mises"] - vm).max() <= 1e-10 * vm
        assert step.field_info["block"]["strain_measure"] == "small strain sym(grad u)"
        assert step.field_info["block"]["components"] == "xx yy zz xy"


def neo_hookean_state(stretch_y: float) -> tuple[np.ndarray, np.ndarray]:
    """Cauchy stress and Hencky strain [xx, yy, zz, xy] of the Neo-Hookean law of
    docs/theory.md at F = diag(lx, stretch_y, 1) with sigma_xx = 0 (lx solved for)."""
    mu, kappa = E / (2 * (1 + NU)), E / (3 * (1 - 2 * NU))

    def tau(lx: float) -> np.ndarray:
        j = lx * stretch_y
        j23 = j ** (-2.0 / 3.0)
        tr = j23 * (lx**2 + stretch_y**2 + 1.0)
        vol = 0.5 * kappa * (j**2 - 1.0)
        return np.array([mu * j23 * lx**2, mu * j23 * stretch_y**2, mu * j23]) - mu * tr / 3.0 + vol

    lx = brentq(lambda s: tau(s)[0], 0.5, 2.0, xtol=1e-15, rtol=1e-15)
    t = tau(lx) / (lx * stretch_y)
    return np.array([t[0], t[1], t[2], 0.0]), np.array([np.log(lx), np.log(stretch_y), 0.0, 0.0])


def test_uniform_compression_neo_hookean(run, tmp_path: Path) -> None:
    """Finite strain (20 % compression): the Cauchy stress and the logarithmic strain
    of every sample equal the law's homogeneous state (Newton's last residual is at
    round-off, ~1e-15 of the first: 1e-10 holds)."""
    case = compressed_block(tmp_path, "neo-hookean", dy=-0.2, output={"fields": ["stress", "strain"]})
    res = run(case, "--quiet")
    assert res.returncode == 0, res.stderr
    step = read_result(tmp_path / "block.h5").steps[-1]
    want_s, want_e = neo_hookean_state(0.8)
    f = step.fields["block"]
    assert "von_mises" not in f
    assert np.abs(f["stress"] - want_s).max() <= 1e-10 * np.abs(want_s).max()
    assert np.abs(f["strain"] - want_e).max() <= 1e-10 * np.abs(want_e).max()
    assert "Hencky" in step.field_info["block"]["strain_measure"]


def test_paraview_fields_equal_the_result_file(run, tmp_path: Path) -> None:
    """The ``fields`` part of ``post vtk``, read back with VTK: one quad per 2 x 2
    samples of an element, points at the samples' reference positions, and stress,
    strain (symmetric tensors XX YY ZZ XY YZ XZ), von Mises and displacement equal to
    the result file's."""
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    case = compressed_block(tmp_path, "neo-hookean", dy=-0.1, output={})
    assert run(case, "--quiet").returncode == 0
    result = read_result(tmp_path / "block.h5")
    pvd = write_vtk(result, out=tmp_path / "vtk")
    files = sorted((pvd.parent / f"{pvd.stem}-vtk").glob("fields-*.vtu"))
    assert [p.name for p in files] == ["fields-000001.vtu", "fields-000002.vtu"]
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(files[-1]))
    reader.Update()
    grid = reader.GetOutput()
    step = result.steps[-1]
    f = step.fields["block"]
    body = result.body("block")
    assert grid.GetNumberOfPoints() == len(f["xi"]) and grid.GetNumberOfCells() == 9 * 2 * 2

    def point(name: str) -> np.ndarray:
        return vtk_to_numpy(grid.GetPointData().GetArray(name))

    x = vtk_to_numpy(grid.GetPoints().GetData())[:, :2]
    np.testing.assert_allclose(x, evaluate(body, None, f["xi"], f["eta"]).reshape(-1, 2), atol=1e-14)
    for name in ("stress", "strain"):
        t = point(name)
        assert t.shape == (len(f["xi"]), 6)
        np.testing.assert_array_equal(t[:, [0, 1, 2, 3]], f[name])
        np.testing.assert_array_equal(t[:, 4:], 0.0)
    np.testing.assert_array_equal(point("von_mises"), f["von_mises"])
    # the displacement at a sample: the top's prescribed -0.1 at eta = 1
    u = point("displacement")[:, :2]
    top = f["eta"] == 1.0
    np.testing.assert_allclose(u[top, 1], -0.1, atol=1e-12)


def test_fields_only_where_asked(run, tmp_path: Path) -> None:
    """Without ``&output`` no step has fields; ``steps = 1`` gives step 1 only;
    ``every = 0`` the last step only."""
    for output, want in ((None, []), ({"steps": [1]}, [1]), ({"every": 0}, [2]), ({}, [1, 2])):
        case = compressed_block(tmp_path, "linear", output=output)
        # the same folder each time: the earlier result is replaced on purpose
        assert run(case, "--quiet", "--overwrite").returncode == 0
        with h5py.File(tmp_path / "block.h5") as h:
            have = [int(k) for k in h["steps"] if "fields" in h["steps"][k]]
        assert have == want, output


@pytest.mark.parametrize("output, message", [
    ({"fields": ["stress", "pressure"]}, "fields: 'pressure' is not one of"),
    ({"samples": 0}, "samples must be between 1"),
    ({"steps": [3]}, "steps must lie between 1 and the number of steps (2)"),
    ({"every": -1}, "every must be >= 0"),
    ({"sample": 2}, "&output"),
])
def test_bad_output_group(run, tmp_path: Path, output: dict, message: str) -> None:
    case = compressed_block(tmp_path, "linear", output=output)
    res = run(case, "--check")
    assert res.returncode == 2, res.stdout + res.stderr
    assert message in res.stderr, res.stderr


def axis_max_shear(path: Path) -> tuple[float, float, float, float, np.ndarray, np.ndarray]:
    """From a hertz result (quarter cylinder, radius 1, lowest point (0, -1)): P, a, p0
    of Hertz for the run's force, and tau_1 on the axis x = 0 against the reference
    depth z = y + 1, with the maximum and its depth refined by a parabola through the
    largest sample and its neighbours: (tau_max/p0, z_max/a, a/R, P, z, tau)."""
    result = read_result(path)
    step = result.steps[-1]
    force = 2.0 * abs(float(step.contact[0].force[1]))
    a, p0 = hertz_reference(force, E, NU, 1.0)
    f = step.fields["cylinder"]
    x = evaluate(result.body("cylinder"), None, f["xi"], f["eta"]).reshape(-1, 2)
    s = f["stress"]
    tau = np.hypot(0.5 * (s[:, 0] - s[:, 1]), s[:, 3])
    axis = np.abs(x[:, 0]) < 1e-12
    z, first = np.unique(np.round(x[axis, 1] + 1.0, 12), return_index=True)
    t = tau[axis][first]
    k = int(np.argmax(t))
    c2, c1, c0 = np.polyfit(z[k - 1:k + 2], t[k - 1:k + 2], 2)
    z_max, t_max = -c1 / (2 * c2), c0 - c1**2 / (4 * c2)
    return t_max / p0, z_max / a, a, force, z, t / p0


def hertz_case(folder: Path, output: dict, **change) -> Path:
    """The committed hertz m4 NN2.2 case in ``folder`` with an ``&output`` group."""
    src = REPO / "cases" / "hertz"
    shutil.copy(src / "geometry.h5", folder)
    nml = f90nml.read(src / "m4-NN2.2.nml")
    nml["output"] = output
    for group, values in change.items():
        nml[group].update(values)
    case = folder / "m4-NN2.2.nml"
    nml.write(case, force=True)
    return case


def graded(fine: float, h: float, ratio: float = 1.25) -> np.ndarray:
    """Knots in (0, 1): spacing ``h`` up to ``fine``, then growing by ``ratio``."""
    k = list(np.arange(h, fine + h / 2, h))
    d = h
    while True:
        d *= ratio
        if k[-1] + d >= 1.0 - 0.5 * d:
            return np.array(k)
        k.append(k[-1] + d)


def test_hertz_subsurface_shear_small_contact(run, tmp_path: Path) -> None:
    """In Hertz's own configuration (a << R: the hertz cylinder pressed 1/64 of the
    case's 0.01, a/R = 0.0073; a penalty of 1e5 E, whose compliance p/eps_N is then
    1e-3 of the gap profile at x = a, while the case's 1e3 E would flatten the
    pressure by some 5 %), the mesh graded to 8 elements per a near the contact: the
    maximum of tau_1 is 0.30028 p0 at 0.78615 a within 2 %. Measured: +0.47 %, -0.07 %."""
    h = 0.0009
    case = hertz_case(tmp_path, {"fields": "stress", "samples": 4, "every": 0},
                      body={"knots_xi": list(graded(0.04 / (np.pi / 2), h / (np.pi / 2))),
                            "knots_eta": list(1.0 - graded(0.04 / 0.95, h / 0.95)[::-1])},
                      contact={"penalty_normal": 1.0e5}, solver={"n_steps": 2})
    nml = f90nml.read(case)
    for d in nml["dirichlet"]:
        if "uy" in d:
            d["uy"] = -0.01 / 64
    nml.write(case, force=True)
    res = run(case, "--quiet")
    assert res.returncode == 0, res.stderr
    tau, depth, a, _, _, _ = axis_max_shear(tmp_path / "m4-NN2.2.h5")
    assert a < 0.01
    assert abs(tau / TAU_MAX - 1.0) < 0.02, tau
    assert abs(depth / ZETA - 1.0) < 0.02, depth


@pytest.fixture(scope="module")
def hertz_m4(voiga_bin: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    import subprocess

    folder = tmp_path_factory.mktemp("hertz_m4")
    case = hertz_case(folder, {"fields": "stress", "samples": 5, "every": 0})
    res = subprocess.run([str(voiga_bin), str(case), "--quiet"], capture_output=True, text=True,
                         timeout=300)
    assert res.returncode == 0, res.stderr
    return folder / "m4-NN2.2.h5"


def test_hertz_m4_is_a_compressed_disc(hertz_m4: Path) -> None:
    """hertz m4 NN2.2 as committed (a/R = 0.076): below the contact zone (z >= 1.5 a,
    where the near-surface terms of order a/R have decayed) tau_1 is Hertz's plus the
    diametral compression P/(pi (2R - z)) within 0.3 % of p0 (measured 0.1 %); the
    maximum is that sum's within 2 % (measured -1.6 %)."""
    tau, _, a, force, z, t = axis_max_shear(hertz_m4)
    _, p0 = hertz_reference(force, E, NU, 1.0)
    zeta = z / a
    disc = zeta - zeta**2 / np.sqrt(1 + zeta**2) + force / (np.pi * (2.0 - z)) / p0
    deep = (zeta >= 1.5) & (zeta <= 4.0)
    assert deep.sum() > 10
    assert np.abs(t[deep] - disc[deep]).max() < 3e-3
    zz = np.linspace(0.0, 3.0, 30001)
    ref = zz - zz**2 / np.sqrt(1 + zz**2) + force / (np.pi * (2.0 - zz * a)) / p0
    assert abs(tau / ref.max() - 1.0) < 0.02, (tau, ref.max())


@pytest.mark.xfail(strict=True, reason="hertz m4 is a disc with a/R = 0.076, not Hertz's half-space: "
                   "the maximum subsurface shear is 0.3146 p0 (+4.8 %) at 0.81 a (+3 %), converged "
                   "(m3 = m4 to 0.03 %; twice and four times finer radially: 0.3146 p0, 0.808-0.812 a); "
                   "the diametral compression adds a/(4R) p0 = 0.019 p0 (docs/verification.md)")
def test_hertz_m4_half_space_values(hertz_m4: Path) -> None:
    """The issue's acceptance line as written: on m4 NN2.2, 0.30 p0 at 0.78 a within 2 %."""
    tau, depth, _, _, _, _ = axis_max_shear(hertz_m4)
    assert abs(tau / TAU_MAX - 1.0) < 0.02 and abs(depth / ZETA - 1.0) < 0.02, (tau, depth)


@pytest.mark.parametrize("shape", ["solid sector", "polygon half-disc"])
def test_fields_at_a_degenerate_point_of_the_map(run, tmp_path: Path, shape: str) -> None:
    """A solid half-disc (its centre a corner of 180 degrees, det dX/dxi = 0 there) and a
    polygon half-disc (two such corners) moved as a whole: every sample, those at the
    degenerate points included (taken 1 % of the way into their element), has zero stress. At
    det = 0 the gradient divided by zero and the step failed as an inverted element."""
    from pre.geometry import annular_sector, polygon

    body = annular_sector((0.0, 1.0), 0.0, 1.0, [180, 360]) if shape == "solid sector" else \
        polygon([(-1.0, 1.0), (1.0, 1.0), (0.3, 1.0), (-0.3, 1.0)], arcs={0: 1.0},
                edges=["outer", "end", "inner", "start"])
    write_bodies(tmp_path / "geometry.h5", {"disc": body}, scene="disc")
    case = {"case": {"title": "disc", "geometry": "geometry.h5", "output": "disc.h5", "n_bodies": 1},
            "body": [{"name": "disc", "material": "linear", "youngs_modulus": 1.0, "poisson_ratio": 0.3,
                      "degree_xi": 2, "degree_eta": 2, "nel_xi": 6, "nel_eta": 4, "contact_edge": "outer",
                      "layer_degree": 2, "layer_elevations": 1}],
            "solver": {"n_steps": 1},
            "dirichlet": [{"body": "disc", "edge": e, "fix_x": True, "fix_y": True, "ux": 0.1, "uy": -0.2}
                          for e in ("start", "inner", "end")],
            "output": {"samples": 3}}
    path = tmp_path / "disc.nml"
    path.write_text(to_namelist_text(case))
    res = run(path, "--quiet")
    assert res.returncode == 0 and "warning" not in res.stderr, res.stderr
    step = read_result(tmp_path / "disc.h5").steps[-1]
    fields = step.fields["disc"]
    assert len(fields["von_mises"]) == 6 * 4 * 9
    # round-off of u (|u| 0.2, 2e-16 relative) is amplified by the inverse Jacobian, about
    # 1/nudge = 100 at a sample taken 1 % of the way in from a degenerate point
    stress = np.abs(fields["stress"]).max(axis=1)
    assert stress.max() < 1e-12, np.sort(stress)[-12:]
    np.testing.assert_allclose(step.displacement.reshape(-1, 2), [[0.1, -0.2]] * (step.displacement.size // 2),
                               atol=1e-12)
