"""``python -m post hertz3d`` (``post/hertz3d.py``) on synthetic results of dimension 3
written with h5py in the schema of docs/hdf5.md (the 2D contact datasets with nsd = 3,
plus ``area_ref``): the exact Hertz pressure at the Gauss points of a fine grid on the
ball octant's sphere gives no error and recovers a and p0; perturbed pressures give the
error computed independently; the exact subsurface field on the axis gives Hertz's
largest shear; Hertz's closed form gives Johnson's 0.31 p0 at 0.48 a for nu = 0.3."""

from __future__ import annotations

import math
from pathlib import Path

import h5py
import numpy as np
import pytest
from scipy.integrate import quad

from post.__main__ import main
from post.hertz import HertzError
from post.hertz3d import (
    FLAT_TOLERANCE,
    axis_shear,
    axis_stresses,
    effective_modulus,
    hertz3d_comparison,
    max_subsurface_shear,
    sphere_reference,
    symmetry_factor,
)
from post.reader import read_result
from post.summary import summary_lines
from pre.h5io import write_volume
from pre.meshes import arc_parameter
from pre.solids import ball_octant, box
from pre.volume import Volume, jacobian

E, NU, R = 1.0, 0.3, 1.0
A = 0.1
"""The contact radius the synthetic force gives."""
E_STAR = E / (1 - NU**2)
P = 4 * E_STAR * A**3 / (3 * R)
P0 = 3 * P / (2 * math.pi * A**2)
BLOCK = box((0.0, 1.0), (0.0, 1.0), (-2.0, -R))
"""The master of the block tests: its top z = -R, parameters (x, y)."""


def surface_points(n: int = 40, angle: float = 2.2 * A) -> tuple[np.ndarray, np.ndarray]:
    """Gauss points (4 x 4 per cell) of an n x n grid over the ball octant's sphere face
    from the lowest point to ``angle`` along both arcs: ``(x_ref (m, 3), area_ref (m,))``."""
    vol = ball_octant(R)
    g, w = np.polynomial.legendre.leggauss(4)
    edges = np.linspace(0.0, float(arc_parameter(angle)), n + 1)
    t = np.concatenate([0.5 * (a + b) + 0.5 * (b - a) * g for a, b in zip(edges[:-1], edges[1:], strict=True)])
    wt = np.concatenate([0.5 * (b - a) * w for a, b in zip(edges[:-1], edges[1:], strict=True)])
    xi, eta = (v.reshape(-1) for v in np.meshgrid(t, t, indexing="ij"))
    wx, we = (v.reshape(-1) for v in np.meshgrid(wt, wt, indexing="ij"))
    x, jac = jacobian(vol, xi, eta, np.ones_like(xi))
    area = np.linalg.norm(np.cross(jac[:, :, 0], jac[:, :, 1]), axis=1) * wx * we
    return x, area


def hertz_p(r: np.ndarray, a: float = A, p0: float = P0) -> np.ndarray:
    return p0 * np.sqrt(np.clip(1 - (r / a) ** 2, 0, None))


def _write_body(f: h5py.File, name: str, vol: Volume, offset: int, youngs_modulus: float = E,
                poisson_ratio: float = NU) -> int:
    """``/bodies/<name>``: the coarse volume as the bulk, one element, no layer; its DOFs."""
    ncp = vol.weights.size
    b = f.create_group(f"bodies/{name}")
    b.attrs.update({"material": "linear", "youngs_modulus": youngs_modulus, "poisson_ratio": poisson_ratio,
                    "dof_offset": offset})
    b["control_points"] = vol.control_points.reshape(-1, 3)
    b["weights"] = vol.weights.reshape(-1)
    b["elements/ptr"] = np.array([1, ncp + 1])
    b["elements/conn"] = np.arange(1, ncp + 1)
    b["elements/range"] = np.array([[0.0, 1.0, 0.0, 1.0, 0.0, 1.0]])
    b["elements/vo"] = np.array([0])
    write_volume(b.create_group("bulk"), vol)
    return 3 * ncp


def write_result(path: Path, x_ref: np.ndarray, p: np.ndarray, area: np.ndarray | None,
                 force_z: float, stress: dict[str, np.ndarray] | None = None,
                 master: tuple[Volume, float, float] | None = None) -> Path:
    """A converged one-step result of the ball octant (the coarse volume as the bulk, one
    element, no layer) with one contact pair and, with ``stress`` (``xi``, ``eta``,
    ``zeta``, ``stress`` (n, 6)), the body's sampled stress. The master: the rigid plane
    z = -R, or with ``master = (volume, E, nu)`` the body ``block`` (its contact face
    ``zeta = 1``; each point's ``xi_master`` its x and y, the parameters of
    :data:`BLOCK`'s top)."""
    vol = ball_octant(R)
    n = len(p)
    with h5py.File(path, "w") as f:
        dofs = _write_body(f, "ball", vol, 0)
        if master is not None:
            dofs += _write_body(f, "block", master[0], dofs, master[1], master[2])
        f.attrs.update({"status": "converged", "dimension": 3, "n_steps_done": 1, "n_steps_planned": 1,
                        "n_dofs": dofs, "title": "hertz3d synthetic", "scene": "hertz3d",
                        "units": "mm, N", "warnings": ""})
        s = f.create_group("steps/000001")
        s.attrs.update({"step": 1, "time": 1.0, "iterations": 1})
        s["displacement"] = np.zeros(dofs)
        c = s.create_group("contact/1")
        c.attrs.update({"slave": "ball", "master": "rigid" if master is None else "block",
                        "penalty_normal": 100.0, "friction": 0.0, "method": "gpts"})
        c["force"] = np.array([0.0, 0.0, force_z])
        c["x_ref"], c["x"] = x_ref, x_ref
        c["xi_slave"] = np.zeros((n, 2))
        c["xi_master"] = np.zeros((n, 2)) if master is None else x_ref[:, :2].copy()
        c["gap"], c["p_t"] = np.zeros(n), np.zeros(n)
        c["p_n"], c["p_n_nominal"] = p, p
        c["state"] = (p > 0).astype(np.int32)
        if area is not None:
            c["area_ref"] = area
        if master is None:
            c["rigid_point"], c["rigid_normal"] = np.array([0.0, 0.0, -R]), np.array([0.0, 0.0, 1.0])
        if stress is not None:
            g = s.create_group("fields/ball")
            g.attrs.update({"samples": 3, "components": "xx yy zz xy yz xz"})
            for key, value in stress.items():
                g[key] = value
            g["element"] = np.ones(len(stress["xi"]), dtype=np.int32)
    return path


@pytest.fixture(scope="module")
def points() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    x, area = surface_points()
    r = np.hypot(x[:, 0], x[:, 1])
    return x, area, r


def axis_field(depths: np.ndarray) -> dict[str, np.ndarray]:
    """Hertz's stress at the axis points (xi = eta = 0) at ``depths`` / a, and zero stress
    at as many points off the axis."""
    zeta = 1 - depths * A / R
    sr, sz = axis_stresses(depths, NU)
    on = np.zeros((len(depths), 6))
    on[:, 0] = on[:, 1] = sr * P0
    on[:, 2] = sz * P0
    n = len(depths)
    return {"xi": np.concatenate([np.zeros(n), np.full(n, 0.01)]),
            "eta": np.concatenate([np.zeros(n), np.full(n, 0.01)]),
            "zeta": np.concatenate([zeta, zeta]), "stress": np.concatenate([on, np.zeros_like(on)])}


def test_johnson_values() -> None:
    """nu = 0.3: 0.31 p0 at 0.48 a (Johnson, Contact Mechanics, fig. 4.6); at the surface
    sigma_r = -(1 + 2 nu)/2 p0, sigma_z = -p0."""
    tau, depth = max_subsurface_shear(0.3)
    assert tau == pytest.approx(0.31, abs=0.005) and depth == pytest.approx(0.48, abs=0.005)
    sr, sz = axis_stresses(np.array([1e-9]), 0.3)
    assert sr[0] == pytest.approx(-0.8, abs=1e-8) and sz[0] == pytest.approx(-1.0)
    assert axis_shear(np.array([depth]), 0.3)[0] == pytest.approx(tau)
    assert max_subsurface_shear(0.5)[0] != pytest.approx(tau, abs=1e-3)  # nu matters
    assert sphere_reference(P, E, NU, R) == pytest.approx((A, P0))


def test_exact_pressure_has_no_error(points, tmp_path: Path) -> None:  # noqa: ANN001
    x, area, r = points
    depths = np.concatenate([np.linspace(0.05, 2.9, 58), [max_subsurface_shear(NU)[1]]])
    result = read_result(write_result(tmp_path / "exact.h5", x, hertz_p(r), area, P / 4, axis_field(depths)))
    h = hertz3d_comparison(result)
    assert h.symmetry == 4 and h.force == pytest.approx(P, rel=1e-12)
    assert h.radius == pytest.approx(R, rel=1e-10) and h.misfit < 1e-10
    np.testing.assert_allclose(h.centre, [0.0, 0.0, -R], atol=1e-10)
    assert (h.a, h.p0) == pytest.approx((A, P0), rel=1e-9)
    assert h.error.l2 < 1e-9 and abs(h.error.max_deviation) < 1e-9
    assert h.error.extent == pytest.approx(A, rel=1e-12)
    assert (h.a_fit, h.p0_fit) == pytest.approx((A, P0), rel=1e-6)
    # the disc's points carry a quarter of the disc's area (the sphere's slightly more)
    assert area[r <= A].sum() == pytest.approx(math.pi * A**2 / 4, rel=2e-2)
    s = h.shear
    assert s is not None and s.axis_samples == len(depths)
    assert s.tau_max == pytest.approx(h.tau_hertz, rel=1e-9) and s.depth == pytest.approx(h.depth_hertz)
    assert s.r < 1e-9 and s.axis_deviation < 1e-9


def _expected_l2(sim, extent: float) -> float:  # noqa: ANN001
    """The relative L2 error over the disc r <= extent of the sphere (area element
    r dr / sqrt(1 - r^2/R^2)), by adaptive quadrature."""
    dens = lambda s: s / math.sqrt(1 - (s / R) ** 2)  # noqa: E731
    num = quad(lambda s: (sim(s) - hertz_p(np.array(s))) ** 2 * dens(s), 0, extent, points=[A], limit=200)[0]
    den = quad(lambda s: hertz_p(np.array(s)) ** 2 * dens(s), 0, A, limit=200)[0]
    return math.sqrt(num / den)


def test_perturbed_pressures(points, tmp_path: Path) -> None:  # noqa: ANN001
    x, area, r = points
    # 2 % more everywhere: exactly 2 %
    h = hertz3d_comparison(read_result(write_result(tmp_path / "scaled.h5", x, 1.02 * hertz_p(r), area, P / 4)))
    assert h.error.l2 == pytest.approx(0.02, rel=1e-9)
    assert h.p0_fit == pytest.approx(1.02 * P0, rel=1e-6) and h.a_fit == pytest.approx(A, rel=1e-6)
    assert h.shear is None and "&output" in h.shear_note
    # a zone 10 % too wide with the same peak: pressure beyond a counts as error
    wide = 1.1 * A
    h = hertz3d_comparison(read_result(write_result(tmp_path / "wide.h5", x, hertz_p(r, wide), area, P / 4)))
    assert wide * 0.98 < h.error.extent < wide
    expected = _expected_l2(lambda s: float(hertz_p(np.array(s), wide)), wide)
    assert h.error.l2 == pytest.approx(expected, rel=1e-2)
    assert h.a_fit == pytest.approx(wide, rel=1e-6)
    # a zone 10 % too narrow: the points within a without pressure count as error
    narrow = 0.9 * A
    h = hertz3d_comparison(read_result(write_result(tmp_path / "narrow.h5", x, hertz_p(r, narrow), area, P / 4)))
    assert h.error.extent == pytest.approx(A)
    expected = _expected_l2(lambda s: float(hertz_p(np.array(s), narrow)), A)
    assert h.error.l2 == pytest.approx(expected, rel=1e-2)


def test_symmetry_factor() -> None:
    assert symmetry_factor(np.radians([1.0, 45.0, 89.0])) == 4
    assert symmetry_factor(np.radians([-80.0, 10.0, 95.0])) == 2
    assert symmetry_factor(np.radians([0.0, 100.0, 200.0, 300.0])) == 1


def test_the_command(points, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:  # noqa: ANN001
    x, area, r = points
    depths = np.linspace(0.05, 2.9, 30)
    path = write_result(tmp_path / "run.h5", x, hertz_p(r), area, P / 4, axis_field(depths))
    assert main(["hertz3d", str(path), "--out", str(tmp_path / "fig")]) == 0
    out = capsys.readouterr().out
    assert "relative L2 error of p over the disc" in out and "quarter model" in out
    assert "0.3" in out and "sampled: largest" in out
    assert (tmp_path / "fig" / "run-hertz3d-000001.png").is_file()
    # overrides: a Poisson ratio changes E*, a and the Hertz shear
    assert main(["hertz3d", str(path), "--poisson-ratio", "0.2", "--no-figure"]) == 0
    assert "nu = 0.2" in capsys.readouterr().out
    # post summary adds one line for the scene
    lines = summary_lines(read_result(path))
    assert lines[-1].startswith("hertz3d vs analytic: P = ") and "L2 = 0.000%" in lines[-1]


def test_run_figures(points, tmp_path: Path) -> None:  # noqa: ANN001
    """``post run``'s figures of a hertz3d result: the hertz3d figure, no 2D contact
    profile (plot-contact draws contact edges)."""
    from post.run import make_figures

    x, area, r = points
    path = write_result(tmp_path / "run.h5", x, hertz_p(r), area, P / 4)
    names = [p.name for p in make_figures(read_result(path), out=tmp_path / "figs", vtk=False)]
    assert "run-hertz3d-000001.png" in names and not any("contact" in n for n in names)


def test_without_area_ref(points, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:  # noqa: ANN001
    x, _, r = points
    path = write_result(tmp_path / "noarea.h5", x, hertz_p(r), None, P / 4)
    with pytest.raises(HertzError, match="area_ref"):
        hertz3d_comparison(read_result(path))
    assert main(["hertz3d", str(path), "--no-figure"]) == 2
    assert "area_ref" in capsys.readouterr().err


def test_effective_modulus() -> None:
    """E* of a sphere on a rigid flat and on an elastic one (Johnson, eq. 4.22)."""
    assert effective_modulus(E, NU) == pytest.approx(E_STAR)
    assert effective_modulus(E, NU, (E, NU)) == pytest.approx(E_STAR / 2)
    assert effective_modulus(2.0, 0.25, (3.0, 0.0)) == pytest.approx(1 / (0.9375 / 2 + 1 / 3))
    assert effective_modulus(E, NU, (1e12, 0.3)) == pytest.approx(E_STAR, rel=1e-11)


def test_block_master(points, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:  # noqa: ANN001
    """A body master: the axis is its flat face's normal (z), E* that of both bodies
    (the master's E and nu from the result, or given); the exact pressure of that E*
    has no error, the rigid E* would miss."""
    x, area, r = points
    e_m, nu_m = 2.0, 0.2
    e_star = 1 / ((1 - NU**2) / E + (1 - nu_m**2) / e_m)
    force = 4 * e_star * A**3 / (3 * R)
    p0 = 3 * force / (2 * math.pi * A**2)
    path = write_result(tmp_path / "block.h5", x, hertz_p(r, A, p0), area, force / 4,
                        master=(BLOCK, e_m, nu_m))
    h = hertz3d_comparison(read_result(path))
    assert h.master == (e_m, nu_m) and h.e_star == pytest.approx(e_star)
    np.testing.assert_allclose(h.normal, [0.0, 0.0, 1.0], atol=1e-14)
    np.testing.assert_allclose(h.centre, [0.0, 0.0, -R], atol=1e-10)
    assert "master face" in h.axis_source
    assert (h.a, h.p0) == pytest.approx((A, p0), rel=1e-9) and h.error.l2 < 1e-9
    assert main(["hertz3d", str(path), "--no-figure"]) == 0
    out = capsys.readouterr().out
    assert f"E* = 1/((1-nu^2)/E + (1-nu_m^2)/E_m) = {e_star:.6g}" in out and "E = 2, nu = 0.2" in out
    # the master's material given: a stiffer master, a smaller a for the same P
    assert main(["hertz3d", str(path), "--no-figure", "--master-youngs-modulus", "1e9",
                 "--master-poisson-ratio", "0.3"]) == 0
    out = capsys.readouterr().out
    stiff = hertz3d_comparison(read_result(path), master_youngs_modulus=1e9, master_poisson_ratio=0.3)
    assert stiff.e_star == pytest.approx(E_STAR, rel=1e-8) and stiff.a < A and stiff.error.l2 > 0.05
    assert f"{stiff.e_star:.6g}" in out
    # summary: the same comparison
    assert "L2 = 0.000%" in summary_lines(read_result(path))[-1]


def test_a_curved_master_is_refused(points, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:  # noqa: ANN001
    """Hertz's sphere on a flat: a master whose face turns by more than FLAT_TOLERANCE
    over the zone (here a ball's sphere under the points) is refused, naming it."""
    x, area, r = points
    curved = ball_octant(2.0, centre=(0.0, 0.0, -R - 2.0))
    path = write_result(tmp_path / "curved.h5", x, hertz_p(r), area, P / 4, master=(curved, E, NU))
    with pytest.raises(HertzError, match="not flat"):
        hertz3d_comparison(read_result(path))
    assert main(["hertz3d", str(path), "--no-figure"]) == 2
    assert "not flat" in capsys.readouterr().err and FLAT_TOLERANCE < 0.01


def test_voiga_ball_on_block(voiga: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``pre hertz3d --master block`` m1 N2 run by voiga (about 2 s): it converges, the
    pair's force along z is the integral of the nominal pressure to the tilt of the
    dented block's normals, and ``post hertz3d`` compares it with the E* of both bodies
    (m1 N2: 12.2 %, docs/verification.md, "Contact on faces")."""
    import subprocess

    from pre.__main__ import main as pre_main

    assert pre_main(["hertz3d", str(tmp_path), "--master", "block", "--mesh", "m1", "--layout", "N2"]) == 0
    run = subprocess.run([str(voiga), "m1-N2.nml", "--quiet"], cwd=tmp_path, capture_output=True, text=True,
                         timeout=600)
    assert run.returncode == 0, run.stdout + run.stderr
    result = read_result(tmp_path / "m1-N2.h5")
    c = result.steps[-1].contact[0]
    assert (c.slave, c.master, c.rigid_normal) == ("ball", "block", None)
    total = float(np.sum(c.p_n_nominal * c.area_ref))
    assert c.force[2] <= total <= 1.002 * c.force[2]
    h = hertz3d_comparison(result)
    assert h.e_star == pytest.approx(1 / (2 * (1 - NU**2)), rel=1e-12) and h.symmetry == 4
    np.testing.assert_allclose(h.normal, [0.0, 0.0, 1.0], atol=1e-12)
    assert h.error.l2 < 0.15 and abs(h.a_error) < 0.2
    assert main(["hertz3d", str(tmp_path / "m1-N2.h5"), "--no-figure"]) == 0
    assert "E_m) = 0.549451" in capsys.readouterr().out
