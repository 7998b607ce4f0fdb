"""The 3D Hertz scene (``python -m pre hertz3d``, ``pre/hertz3d.py``): the ball octant is
exact and regular, its meshes are graded toward the contact and have the DOFs the
formula of docs/formats.md gives (checked against splipy's refinement), and the case
files parse and name the faces the geometry has."""

from __future__ import annotations

import math
import os
import re
import subprocess
from itertools import pairwise
from pathlib import Path

import f90nml
import numpy as np
import pytest
from splipy import Surface

from pre.__main__ import main
from pre.h5io import read_volumes
from pre.hertz3d import (
    BODY,
    CONTACT_FACE,
    LAYOUTS,
    MESHES,
    Ball,
    ball_case,
    ball_geometry,
    ball_knots,
    case_dofs,
)
from pre.meshes import arc_angle
from pre.namelists import NAMELISTS
from pre.solids import ball_octant
from pre.tests.test_hertz_case import _voiga
from pre.volume import check_volume, enclosed_volume, evaluate, jacobian, jacobian_grid, volume_to_splipy

RNG = np.random.default_rng(42)
DOF_RANGE = (4000, 70000)
"""The study's NN2.2 meshes: from about 5,000 to 60,000 DOFs."""


def _random(n: int = 200) -> tuple[np.ndarray, np.ndarray]:
    return RNG.random(n), RNG.random(n)


@pytest.mark.parametrize("radius", [1.0, 2.5])
def test_the_ball_is_exact(radius: float) -> None:
    vol = ball_octant(radius)
    check_volume(BODY, vol)
    xi, eta = _random()
    sphere = evaluate(vol, xi, eta, np.ones_like(xi))
    assert np.abs(np.linalg.norm(sphere, axis=1) - radius).max() < 1e-12 * radius
    inside = evaluate(vol, xi, eta, RNG.random(len(xi)))
    assert np.linalg.norm(inside, axis=1).max() <= radius * (1 + 1e-12)
    assert inside[:, 0].min() >= 0 and inside[:, 1].min() >= 0 and inside[:, 2].max() <= 0
    zero, one = np.zeros_like(xi), np.ones_like(xi)
    zeta = RNG.random(len(xi))
    # the symmetry faces and the top are planes, the collapsed faces a line and a point
    assert np.abs(evaluate(vol, zero, eta, zeta)[:, 1]).max() < 1e-15      # symmetry_y: y = 0
    assert np.abs(evaluate(vol, one, eta, zeta)[:, 2]).max() < 1e-15       # top: z = 0
    assert np.abs(evaluate(vol, xi, zero, zeta)[:, 0]).max() < 1e-15       # symmetry_x: x = 0
    assert np.abs(evaluate(vol, xi, one, zeta)[:, 1:]).max() < 1e-15       # axis: y = z = 0
    assert np.abs(evaluate(vol, xi, eta, zero)).max() < 1e-15              # centre
    assert vol.faces == {"xi0": "symmetry_y", "xi1": "top", "eta0": "symmetry_x", "eta1": "axis",
                         "zeta0": "centre", "zeta1": CONTACT_FACE}
    np.testing.assert_allclose(evaluate(vol, [0.0], [0.0], [1.0])[0], [0.0, 0.0, -radius], atol=1e-15)
    assert enclosed_volume(vol) == pytest.approx(math.pi * radius**3 / 6, rel=1e-12)


def test_the_contact_corner_is_regular() -> None:
    """At the lowest point the map is regular: dX/dxi = (0, R pi/2 ..) along y, dX/deta
    along x, dX/dzeta = -z, right-handed with a Jacobian of the order of R^3."""
    _, jac = jacobian(ball_octant(1.0), [0.0], [0.0], [1.0])
    j = jac[0]
    assert np.linalg.det(j) > 1.0
    assert abs(j[1, 0]) > 1 and abs(j[0, 1]) > 1 and j[2, 2] == pytest.approx(-1.0)


@pytest.mark.parametrize("mesh", list(MESHES))
def test_det_j_is_positive_at_every_gauss_point(mesh: str) -> None:
    """Over the refined mesh, det J > 0 at the Gauss points (degree + 1 = 3 per
    direction) of every element, the ones next to the collapsed faces included."""
    ball = Ball()
    vol = ball_geometry(ball)[BODY]
    knots = ball_knots(ball, mesh)
    x, _ = np.polynomial.legendre.leggauss(3)
    pts = []
    for d in ("xi", "eta", "zeta"):
        breaks = np.concatenate([[0.0], knots[f"knots_{d}"], [1.0]])
        pts.append(np.concatenate([0.5 * (a + b) + 0.5 * (b - a) * x for a, b in pairwise(breaks)]))
    det = np.linalg.det(jacobian_grid(vol, *pts)[1])
    assert det.min() > 0
    assert det.min() > 1e-10 * det.max()


@pytest.mark.parametrize("mesh", list(MESHES))
def test_the_knots_are_graded_toward_the_contact(mesh: str) -> None:
    """Both angles are graded alike from the lowest point: at least 3 elements within the
    expected contact radius a = sqrt(R d), growing away from it; the surface element
    across is as long as the fine ones along."""
    ball = Ball()
    knots = ball_knots(ball, mesh)
    assert knots["knots_xi"] == knots["knots_eta"]
    angles = np.concatenate([[0.0], arc_angle(np.array(knots["knots_xi"])), [math.pi / 2]])
    sizes = np.diff(angles)
    assert np.all(sizes > 0)
    assert np.count_nonzero(angles[1:] <= math.asin(ball.half_width)) >= 3
    fine = sizes[0]
    np.testing.assert_allclose(sizes[:MESHES[mesh][0]], fine, rtol=1e-12)
    assert np.all(np.diff(sizes[MESHES[mesh][0] - 1:]) >= -1e-15)
    rho = np.concatenate([[0.0], knots["knots_zeta"], [1.0]])
    assert 1.0 - rho[-2] == pytest.approx(fine, rel=1e-9)
    assert np.all(np.diff(np.diff(rho)) < 0)  # shrinking toward the sphere


def test_dof_counts_per_mesh(capsys: pytest.CaptureFixture[str]) -> None:
    ball = Ball()
    counts = {m: {lay: case_dofs(ball, m, lay)["total"] for lay in LAYOUTS} for m in MESHES}
    with capsys.disabled():
        print("\nhertz3d DOFs: " + "; ".join(f"{m}: " + ", ".join(f"{lay} {n}" for lay, n in c.items())
                                             for m, c in counts.items()))
    nn22 = [counts[m]["NN2.2"] for m in MESHES]
    assert DOF_RANGE[0] <= nn22[0] and nn22[-1] <= DOF_RANGE[1]
    assert nn22 == sorted(nn22)
    for m, (fine, rest, radial) in MESHES.items():  # formats.md's formula, no coarse interior knots
        n = fine + rest
        assert counts[m]["N2"] == 3 * (n + 2) ** 2 * (radial + 2)
        assert counts[m]["NN2.2"] == 3 * ((n + 2) ** 2 * (radial + 1) + (2 + 3 * n) ** 2)


@pytest.mark.parametrize("layout", ["N2", "N3", "NN2.1", "NN3.2", "L1"])
def test_dof_counts_against_splipy(layout: str) -> None:
    """The counts of m1 are those of splipy's k-refinement of the volume (bulk) and of
    its sphere face (the layer)."""
    ball = Ball()
    body = ball_case(ball, "m1", layout)["body"][0]
    vol = ball_geometry(ball)[BODY]
    counts = case_dofs(ball, "m1", layout)
    spline = volume_to_splipy(vol)
    new = [body[f"knots_{d}"] for d in ("xi", "eta", "zeta")]
    if body["basis"] == "linear":
        n = [len(k) + 2 for k in new]
    else:
        p = body["degree_xi"]
        spline.raise_order(*(p - q for q in vol.degree))
        for d, k in enumerate(new):
            spline.insert_knot(k, direction=d)
        n = list(spline.shape)
    if body["layer_degree"]:
        coarse = volume_to_splipy(vol)  # its sphere face zeta = 1
        face = Surface(*coarse.bases[:2], coarse.controlpoints[:, :, -1], rational=True, raw=True)
        face.raise_order(*(body["layer_degree"] - q for q in vol.degree[:2]))
        for d, k in enumerate(new[:2]):
            face.insert_knot(k, direction=d)
        face.raise_order(body["layer_elevations"], body["layer_elevations"])
        interface = 3 * face.shape[0] * face.shape[1]
    else:
        interface = 3 * n[0] * n[1]
    assert counts == {"interface": interface, "bulk": 3 * n[0] * n[1] * (n[2] - 1),
                      "total": interface + 3 * n[0] * n[1] * (n[2] - 1)}


def test_the_command_writes_cases_that_parse(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "h3"
    assert main(["hertz3d", str(out), "--mesh", "m1", "m2", "--layout", "N2", "NN2.2"]) == 0
    printed = capsys.readouterr().out
    assert "wrote" in printed and f"{case_dofs(Ball(), 'm2', 'NN2.2')['total']} DOFs" in printed
    attrs, volumes = read_volumes(out / "geometry.h5")
    assert attrs["dimension"] == 3 and list(volumes) == [BODY]
    vol = volumes[BODY]
    np.testing.assert_array_equal(vol.control_points, ball_octant(1.0).control_points)
    faces = set(vol.faces.values())
    for stem in ("m1-N2", "m1-NN2.2", "m2-N2", "m2-NN2.2"):
        nml = f90nml.read(str(out / f"{stem}.nml"))
        for group, value in nml.items():
            for entry in value if isinstance(value, list) else [value]:
                assert set(entry) <= NAMELISTS[group], (group, set(entry) - NAMELISTS[group])
        body = nml["body"]
        assert body["name"] == BODY and body["contact_face"] == CONTACT_FACE in faces
        assert {d["face"] for d in nml["dirichlet"]} == {"top", "symmetry_x", "symmetry_y"} <= faces
        fixed = {d["face"]: [k for k in ("fix_x", "fix_y", "fix_z") if d.get(k)] for d in nml["dirichlet"]}
        assert fixed == {"top": ["fix_z"], "symmetry_x": ["fix_x"], "symmetry_y": ["fix_y"]}
        assert nml["dirichlet"][0]["uz"] == -0.01
        c = nml["contact"]
        assert (c["slave"], c["master"], c["method"]) == (BODY, "rigid", "mortar")
        assert c["rigid_point"] == [0.0, 0.0, -1.0] and c["rigid_normal"] == [0.0, 0.0, 1.0]
        assert "penalty_normal" not in c
        assert nml["case"]["output"] == f"{stem}.h5" and nml["case"]["geometry"] == "geometry.h5"
        assert (body["layer_degree"], body["layer_elevations"]) == ((2, 2) if "NN" in stem else (0, 0))
    # again: refused, nothing changed; a new mesh in the same folder keeps the geometry
    assert main(["hertz3d", str(out), "--mesh", "m1", "--layout", "N2"]) == 2
    assert "exists" in capsys.readouterr().err
    assert main(["hertz3d", str(out), "--mesh", "m3", "--layout", "N2"]) == 0
    assert "kept" in capsys.readouterr().out
    assert main(["hertz3d", str(out), "--radius", "2", "--mesh", "m4"]) == 2
    assert "another ball" in capsys.readouterr().err


@pytest.mark.parametrize("bad, says", [(["--mesh", "m5"], "m5"), (["--layout", "NN1"], "NN1"),
                                       (["--indentation", "0.2"], "indentation"),
                                       (["--poisson-ratio", "0.5"], "poisson"),
                                       (["--steps", "0"], "steps")])
def test_bad_values_exit_2(bad: list[str], says: str, tmp_path: Path,
                           capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["hertz3d", str(tmp_path / "x"), *bad]) == 2
    assert says in capsys.readouterr().err
    assert not list((tmp_path / "x").glob("*.nml")) if (tmp_path / "x").exists() else True


def test_options_reach_the_case() -> None:
    ball = Ball(radius=2.0, youngs_modulus=210.0, poisson_ratio=0.25, indentation=0.05,
                material="neo-hookean")
    groups = ball_case(ball, "m1", "NN3.1", n_steps=8, method="mortar", penalty_normal=1e4)
    body = groups["body"][0]
    assert (body["material"], body["youngs_modulus"], body["poisson_ratio"]) == ("neo-hookean", 210.0, 0.25)
    assert (body["degree_xi"], body["layer_degree"], body["layer_elevations"]) == (2, 3, 1)
    assert groups["contact"][0]["rigid_point"] == [0.0, 0.0, -2.0]
    assert groups["contact"][0]["penalty_normal"] == 1e4 and groups["contact"][0]["method"] == "mortar"
    assert groups["solver"]["n_steps"] == 8 and groups["dirichlet"][0]["uz"] == -0.05
    assert ball.half_width == pytest.approx(math.sqrt(0.1))


@pytest.mark.parametrize("mesh, layouts", [("m1", ["N2", "N3", "NN2.1", "NN2.2", "L1"]), ("m3", ["NN2.2"])])
def test_voiga_check_counts_the_same_dofs(mesh: str, layouts: list[str], tmp_path: Path) -> None:
    """``voiga CASE --check`` reads the geometry and the case and counts the DOFs
    :func:`case_dofs` gives. The &contact group is taken out first while voiga refuses
    contact on solids (issue 42; then it can stay)."""
    voiga = _voiga()
    if voiga is None:
        if os.environ.get("CI"):
            pytest.fail("voiga binary not found (build it or set VOIGA_BIN)")
        pytest.skip("voiga binary not found (build it or set VOIGA_BIN)")
    assert main(["hertz3d", str(tmp_path), "--mesh", mesh, "--layout", *layouts]) == 0
    for layout in layouts:
        case = tmp_path / f"{mesh}-{layout}.nml"
        case.write_text(re.sub(r"&contact.*?\n/\n", "", case.read_text(), flags=re.S))
        run = subprocess.run([str(voiga), case.name, "--check"], cwd=tmp_path, capture_output=True,
                             text=True, timeout=300)
        assert run.returncode == 0, run.stdout + run.stderr
        assert f"dofs all total={case_dofs(Ball(), mesh, layout)['total']}" in run.stdout.splitlines()
