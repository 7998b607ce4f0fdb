"""The 3D Hertz scene (``python -m pre hertz3d``, ``pre/hertz3d.py``): the ball octant is
exact and regular, its meshes are graded toward the contact and have the DOFs the
formula of docs/formats.md gives (checked against splipy's refinement), and the case
files parse and name the faces the geometry has."""

from __future__ import annotations

import hashlib
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
from pre.hertz import EDGE_BAND, HertzCaseError
from pre.hertz3d import (
    BLOCK,
    BLOCK_CELL,
    BLOCK_FACE,
    BODY,
    CONTACT_FACE,
    LAYOUTS,
    MESHES,
    PHI_ELEMENTS,
    POLAR_MESHES,
    Ball,
    ball_case,
    ball_geometry,
    ball_knots,
    block_knots,
    body_dofs,
    case_dofs,
)
from pre.meshes import arc_angle
from pre.namelists import NAMELISTS
from pre.solids import ball_octant, polar_ball_octant
from pre.tests.test_hertz_case import _voiga
from pre.volume import Volume, check_volume, enclosed_volume, evaluate, jacobian, jacobian_grid, volume_to_splipy

RNG = np.random.default_rng(42)
DOF_RANGE = (4000, 70000)
"""The study's NN2.2 meshes: from about 5,000 to 60,000 DOFs."""


def _random(n: int = 200) -> tuple[np.ndarray, np.ndarray]:
    return RNG.random(n), RNG.random(n)


def _in_the_octant(vol: Volume, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Checks the volume, that its sphere face is on the sphere and that it lies in the
    ball's octant x, y >= 0, z <= 0; returns the random (xi, eta) it drew."""
    check_volume(BODY, vol)
    xi, eta = _random()
    sphere = evaluate(vol, xi, eta, np.ones_like(xi))
    assert np.abs(np.linalg.norm(sphere, axis=1) - radius).max() < 1e-12 * radius
    inside = evaluate(vol, xi, eta, RNG.random(len(xi)))
    assert np.linalg.norm(inside, axis=1).max() <= radius * (1 + 1e-12)
    assert inside[:, 0].min() >= 0 and inside[:, 1].min() >= 0 and inside[:, 2].max() <= 0
    return xi, eta


@pytest.mark.parametrize("radius", [1.0, 2.5])
def test_the_ball_is_exact(radius: float) -> None:
    vol = ball_octant(radius)
    xi, eta = _in_the_octant(vol, radius)
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


def _gauss_det(vol: Volume, knots: dict[str, list[float]]) -> np.ndarray:
    """det J at the Gauss points (3 per direction) of every element of ``vol`` refined
    by ``knots``."""
    x, _ = np.polynomial.legendre.leggauss(3)
    pts = []
    for d in ("xi", "eta", "zeta"):
        breaks = np.concatenate([[0.0], knots[f"knots_{d}"], [1.0]])
        pts.append(np.concatenate([0.5 * (a + b) + 0.5 * (b - a) * x for a, b in pairwise(breaks)]))
    return np.linalg.det(jacobian_grid(vol, *pts)[1])


@pytest.mark.parametrize("mesh", list(MESHES))
def test_det_j_is_positive_at_every_gauss_point(mesh: str) -> None:
    """Over the refined mesh, det J > 0 at the Gauss points (degree + 1 = 3 per
    direction) of every element, the ones next to the collapsed faces included."""
    ball = Ball()
    det = _gauss_det(ball_geometry(ball)[BODY], ball_knots(ball, mesh))
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


# --- the ball on an elastic block (--master block) ---------------------------------------

RIGID_M1_N2_SHA256 = "3dd2e7b051441d60ba0b6ceb2d725716984e87729b8603b6ebf46ccbc75d8880"
"""The rigid scene's m1-N2.nml as written before the block master was added."""


def _ball_y_knots(ball: Ball, mesh: str) -> np.ndarray:
    """y of the ball's knot lines along the sphere's edge on x = 0 (eta = 0): R sin of the
    angle from the lowest point."""
    return ball.radius * np.sin(arc_angle(np.array(ball_knots(ball, mesh)["knots_xi"])))


def test_the_block() -> None:
    """The block is the box [0, L]^2 x [-R - H, -R] under the ball's lowest point, with
    the ball's symmetry faces and its top as the contact face (zeta = 1)."""
    ball = Ball(radius=2.0, master="block", block_size=0.75)
    vols = ball_geometry(ball)
    assert list(vols) == [BODY, BLOCK]
    vol = vols[BLOCK]
    check_volume(BLOCK, vol)
    np.testing.assert_allclose(vol.control_points.reshape(-1, 3).min(0), [0.0, 0.0, -3.5])
    np.testing.assert_allclose(vol.control_points.reshape(-1, 3).max(0), [1.5, 1.5, -2.0])
    assert vol.faces == {"xi0": "symmetry_x", "xi1": "right", "eta0": "symmetry_y", "eta1": "back",
                         "zeta0": "bottom", "zeta1": BLOCK_FACE}
    assert list(ball_geometry(Ball())) == [BODY]


@pytest.mark.parametrize("mesh", list(MESHES))
def test_the_block_knots_are_graded_and_do_not_match(mesh: str) -> None:
    """Along x and y the block's top cells are BLOCK_CELL times the ball's fine arc over
    at least the ball's fine zone, then grow to L; across they grow from that size at
    the top; near the contact no block knot lies on a ball knot line."""
    ball = Ball(master="block")
    fine, rest, radial = MESHES[mesh]
    knots = block_knots(ball, mesh)
    assert knots["knots_xi"] == knots["knots_eta"]
    x = np.concatenate([[0.0], knots["knots_xi"], [1.0]]) * ball.block_size * ball.radius
    sizes = np.diff(x)
    theta_c = math.asin(1.5 * ball.half_width / ball.radius)
    h = BLOCK_CELL * ball.radius * theta_c / fine
    n_fine = math.ceil(ball.radius * math.sin(theta_c) / h)  # over the ball's fine zone, then rest
    assert len(sizes) == n_fine + rest and (n_fine - 1) * h < ball.radius * math.sin(theta_c) <= n_fine * h
    np.testing.assert_allclose(sizes[:n_fine + 1], h, rtol=1e-9)  # the growth starts at h
    assert np.all(np.diff(sizes) >= -1e-15) and sizes[-1] > 2 * h
    z = np.concatenate([[0.0], knots["knots_zeta"], [1.0]])
    assert len(z) - 1 == radial and 1.0 - z[-2] == pytest.approx(h / ball.block_size, rel=1e-9)
    assert np.all(np.diff(np.diff(z)) < 0)
    ball_y = _ball_y_knots(ball, mesh)
    zone = x[(x > 0) & (x <= ball.radius * math.sin(theta_c))]
    gaps = np.abs(zone[:, None] - ball_y[None, :]).min(axis=1)
    assert gaps.min() > 0.02 * h  # not matching (1.3: 13 ball cells are 10 of the block's, m4 comes closest)


def test_the_block_case() -> None:
    """Two bodies, the block's faces fixed as the ball's symmetry faces and its bottom in
    z, contact ball -> block with no rigid plane; the block takes the ball's material
    unless given."""
    groups = ball_case(Ball(master="block"), "m2", "NN2.2", method="gpts", penalty_normal=500.0)
    assert groups["case"]["n_bodies"] == 2 and [b["name"] for b in groups["body"]] == [BODY, BLOCK]
    block = groups["body"][1]
    assert block["contact_face"] == BLOCK_FACE and (block["layer_degree"], block["layer_elevations"]) == (2, 2)
    assert (block["material"], block["youngs_modulus"], block["poisson_ratio"]) == ("linear", 1.0, 0.3)
    assert groups["contact"] == [{"slave": BODY, "master": BLOCK, "method": "gpts", "penalty_normal": 500.0}]
    fixed = [(d["body"], d["face"], [k for k in ("fix_x", "fix_y", "fix_z") if d.get(k)])
             for d in groups["dirichlet"]]
    assert fixed[3:] == [(BLOCK, "bottom", ["fix_z"]), (BLOCK, "symmetry_x", ["fix_x"]),
                         (BLOCK, "symmetry_y", ["fix_y"])]
    assert all("uz" not in d for d in groups["dirichlet"][3:])
    faces = set(ball_geometry(Ball(master="block"))[BLOCK].faces.values())
    assert {d["face"] for d in groups["dirichlet"][3:]} <= faces
    other = ball_case(Ball(master="block", block_youngs_modulus=3.0, block_poisson_ratio=0.2), "m1", "N2")
    assert (other["body"][1]["youngs_modulus"], other["body"][1]["poisson_ratio"]) == (3.0, 0.2)
    assert "on a block L = H = 1, E = 3, nu = 0.2" in other["case"]["title"]


@pytest.mark.parametrize("layout", ["N2", "NN2.2"])
def test_block_dofs(layout: str) -> None:
    """The block's DOFs: formats.md's formula for a box (no coarse interior knots)."""
    ball = Ball(master="block")
    for mesh in MESHES:
        dofs = body_dofs(ball, mesh, layout)
        assert dofs[BODY] == case_dofs(Ball(), mesh, layout)["total"]
        k = block_knots(ball, mesh)
        n1, n3 = len(k["knots_xi"]) + 1, len(k["knots_zeta"]) + 1
        bulk = 3 * (n1 + 2) ** 2 * (n3 + 1)
        top = 3 * (2 + 3 * n1) ** 2 if layout == "NN2.2" else 3 * (n1 + 2) ** 2
        assert dofs[BLOCK] == bulk + top


def test_rigid_cases_are_unchanged(tmp_path: Path) -> None:
    """--master rigid (the default) writes what the scene wrote before the block: one
    body, the rigid plane, the same bytes as the Ball's defaults."""
    a, b = tmp_path / "a", tmp_path / "b"
    assert main(["hertz3d", str(a), "--mesh", "m1", "m3", "--layout", "N2", "NN2.2"]) == 0
    assert main(["hertz3d", str(b), "--mesh", "m1", "m3", "--layout", "N2", "NN2.2", "--master", "rigid",
                 "--block-size", "3"]) == 0
    for stem in ("m1-N2", "m1-NN2.2", "m3-N2", "m3-NN2.2"):
        text = (a / f"{stem}.nml").read_text()
        assert text == (b / f"{stem}.nml").read_text()
        assert "block" not in text and "n_bodies = 1" in text
    assert (a / "geometry.h5").read_bytes() == (b / "geometry.h5").read_bytes()
    assert hashlib.sha256((a / "m1-N2.nml").read_bytes()).hexdigest() == RIGID_M1_N2_SHA256


def test_the_block_command(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "blk"
    assert main(["hertz3d", str(out), "--master", "block", "--mesh", "m1", "--layout", "N2", "NN2.2"]) == 0
    printed = capsys.readouterr().out
    for layout in ("N2", "NN2.2"):
        dofs = body_dofs(Ball(master="block"), "m1", layout)
        assert f"{sum(dofs.values())} DOFs (ball {dofs[BODY]}, block {dofs[BLOCK]})" in printed
    _, volumes = read_volumes(out / "geometry.h5")
    assert list(volumes) == [BODY, BLOCK]
    nml = f90nml.read(str(out / "m1-N2.nml"))
    for group, value in nml.items():
        for entry in value if isinstance(value, list) else [value]:
            assert set(entry) <= NAMELISTS[group], (group, set(entry) - NAMELISTS[group])
    assert (nml["contact"]["slave"], nml["contact"]["master"], nml["contact"]["method"]) == (BODY, BLOCK, "mortar")
    # a rigid scene in the same folder: another geometry, refused
    assert main(["hertz3d", str(out), "--mesh", "m2", "--layout", "N2"]) == 2
    assert "another ball" in capsys.readouterr().err


@pytest.mark.parametrize("bad, says", [(["--block-size", "0.1"], "block size"),
                                       (["--block-youngs-modulus", "-1"], "block youngs"),
                                       (["--block-poisson-ratio", "0.5"], "block poisson"),
                                       (["--master", "wall"], None)])
def test_bad_block_values(bad: list[str], says: str | None, tmp_path: Path,
                          capsys: pytest.CaptureFixture[str]) -> None:
    if says is None:
        with pytest.raises(SystemExit):
            main(["hertz3d", str(tmp_path / "x"), *bad])
        return
    assert main(["hertz3d", str(tmp_path / "x"), "--master", "block", *bad]) == 2
    assert says in capsys.readouterr().err
    assert not (tmp_path / "x").exists() or not list((tmp_path / "x").glob("*.nml"))


def test_voiga_check_counts_the_block(tmp_path: Path) -> None:
    """``voiga CASE --check`` of the block scene (contact between the solids included)
    counts the DOFs :func:`body_dofs` gives, per body and in all."""
    voiga = _voiga()
    if voiga is None:
        if os.environ.get("CI"):
            pytest.fail("voiga binary not found (build it or set VOIGA_BIN)")
        pytest.skip("voiga binary not found (build it or set VOIGA_BIN)")
    assert main(["hertz3d", str(tmp_path), "--master", "block", "--mesh", "m1", "--layout", "N2", "NN2.2"]) == 0
    for layout in ("N2", "NN2.2"):
        run = subprocess.run([str(voiga), f"m1-{layout}.nml", "--check"], cwd=tmp_path, capture_output=True,
                             text=True, timeout=300)
        assert run.returncode == 0, run.stdout + run.stderr
        dofs = body_dofs(Ball(master="block"), "m1", layout)
        lines = run.stdout.splitlines()
        for name, n in dofs.items():
            assert any(line.startswith(f"dofs {name} ") and f"total={n}" in line for line in lines), lines
        assert f"dofs all total={sum(dofs.values())}" in lines


def test_block_cell_option(tmp_path: Path) -> None:
    """--block-cell sets the block's top cells over the ball's fine ones."""
    assert main(["hertz3d", str(tmp_path), "--master", "block", "--block-cell", "0.77", "--mesh", "m2",
                 "--layout", "N2"]) == 0
    nml = f90nml.read(str(tmp_path / "m2-N2.nml"))
    h = 0.77 * math.asin(0.15) / MESHES["m2"][0]
    assert nml["body"][1]["knots_xi"][0] == pytest.approx(h, rel=1e-12)
    assert block_knots(Ball(master="block", block_cell=0.77), "m2") == block_knots(Ball(master="block"), "m2", 0.77)
    assert main(["hertz3d", str(tmp_path / "x"), "--master", "block", "--block-cell", "5"]) == 2
    # a block too small for the zone's cells: refused, not graded backwards
    with pytest.raises(HertzCaseError, match="too small"):
        block_knots(Ball(master="block", block_size=0.25, indentation=0.05), "m1")
    with pytest.raises(HertzCaseError, match="too small"):
        block_knots(Ball(master="block", block_size=0.25, block_cell=4.0), "m1")
    for size, cell in [(0.5, 1.3), (2.0, 4.0), (100.0, 0.25)]:
        k = np.diff([0.0, *block_knots(Ball(master="block", block_size=size, block_cell=cell), "m4")["knots_xi"], 1.0])
        assert np.all(k > 0)


# --- the polar grid (--grid polar) ----------------------------------------------------------

POLAR = Ball(grid="polar")


@pytest.mark.parametrize("radius", [1.0, 2.5])
def test_the_polar_ball_is_exact(radius: float) -> None:
    """The polar octant is the same ball octant: its sphere face on the sphere, its faces
    the same planes, its axis face collapsed onto the vertical axis below the centre, the
    lowest point the whole edge eta = 0 of the sphere face, the volume pi R^3 / 6."""
    vol = polar_ball_octant(radius)
    xi, eta = _in_the_octant(vol, radius)
    zero, one, zeta = np.zeros_like(xi), np.ones_like(xi), RNG.random(len(xi))
    assert np.abs(evaluate(vol, zero, eta, zeta)[:, 1]).max() < 1e-15      # symmetry_y: y = 0
    assert np.abs(evaluate(vol, one, eta, zeta)[:, 0]).max() < 1e-15       # symmetry_x: x = 0
    assert np.abs(evaluate(vol, xi, zero, zeta)[:, :2]).max() < 1e-15      # axis: x = y = 0
    assert np.abs(evaluate(vol, xi, one, zeta)[:, 2]).max() < 1e-15        # top: z = 0
    assert np.abs(evaluate(vol, xi, eta, zero)).max() < 1e-15              # centre
    assert vol.faces == {"xi0": "symmetry_y", "xi1": "symmetry_x", "eta0": "axis", "eta1": "top",
                         "zeta0": "centre", "zeta1": CONTACT_FACE}
    np.testing.assert_allclose(evaluate(vol, xi, zero, one), [[0.0, 0.0, -radius]] * len(xi), atol=1e-15)
    assert enclosed_volume(vol) == pytest.approx(math.pi * radius**3 / 6, rel=1e-12)


@pytest.mark.parametrize("mesh", list(POLAR_MESHES))
def test_polar_knot_lines_are_circles_about_the_contact(mesh: str) -> None:
    """On the sphere face every theta knot line is a circle about the vertical axis through
    the lowest point (constant distance from it, constant height), and the spans over
    0.9 .. 1.1 a_est are ``edge`` times finer than the fine ones: the zone's edge runs
    along knot lines that resolve it."""
    knots = ball_knots(POLAR, mesh)
    vol = ball_geometry(POLAR)[BODY]
    phi = np.linspace(0.0, 1.0, 17)
    radii = []
    for t in knots["knots_eta"]:
        x = evaluate(vol, phi, np.full_like(phi, t), np.ones_like(phi))
        r = np.hypot(x[:, 0], x[:, 1])
        assert np.ptp(r) < 1e-13 and np.ptp(x[:, 2]) < 1e-13
        radii.append(r[0])
    r = np.concatenate([[0.0], radii])
    sizes = np.diff(np.arcsin(np.minimum(r, 1.0)))  # arc angle of each span from the lowest point
    fine, _, _, edge = POLAR_MESHES[mesh]
    theta_c = math.asin(1.5 * POLAR.half_width / POLAR.radius)
    lo, hi = (math.asin(f * POLAR.half_width) for f in EDGE_BAND)
    inside = (np.arcsin(r[1:]) > lo) & (np.arcsin(r[:-1]) < hi)
    assert inside.sum() >= 2 * edge
    # split into equal parameter spans of the rational arc: equal angles within 0.2 %
    np.testing.assert_allclose(sizes[inside], theta_c / fine / edge, rtol=2e-3)
    assert sizes[~inside][: int(np.argmax(inside))].max() == pytest.approx(theta_c / fine, rel=1e-9)
    assert knots["knots_xi"] == [k / PHI_ELEMENTS for k in range(1, PHI_ELEMENTS)]


@pytest.mark.parametrize("mesh", list(POLAR_MESHES))
def test_polar_det_j_is_positive_at_every_gauss_point(mesh: str) -> None:
    """det J > 0 at the Gauss points of every element of the polar meshes, those along the
    collapsed axis (det J ~ the distance from it) included."""
    det = _gauss_det(ball_geometry(POLAR)[BODY], ball_knots(POLAR, mesh))
    assert det.min() > 0 and det.min() > 1e-10 * det.max()


def test_polar_cases_and_meshes_per_grid(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``--grid polar`` writes the polar octant and its p meshes (default p3), the same faces
    and loads as the Cartesian grid; a mesh of the other grid is refused naming the grid's
    meshes; the polar meshes' DOFs grow from p1 to p4."""
    out = tmp_path / "p"
    assert main(["hertz3d", str(out), "--grid", "polar", "--layout", "N2"]) == 0
    assert f"{case_dofs(POLAR, 'p3', 'N2')['total']} DOFs" in capsys.readouterr().out
    _, volumes = read_volumes(out / "geometry.h5")
    np.testing.assert_array_equal(volumes[BODY].control_points, polar_ball_octant(1.0).control_points)
    nml = f90nml.read(str(out / "p3-N2.nml"))
    assert {d["face"] for d in nml["dirichlet"]} == {"top", "symmetry_x", "symmetry_y"}
    assert "polar grid" in nml["case"]["title"]
    assert main(["hertz3d", str(tmp_path / "q"), "--grid", "polar", "--mesh", "m1"]) == 2
    assert "polar grid's meshes are p1, p2, p3, p4" in capsys.readouterr().err
    assert main(["hertz3d", str(tmp_path / "r"), "--mesh", "p1"]) == 2
    assert "cartesian grid's meshes are m1" in capsys.readouterr().err
    with pytest.raises(HertzCaseError, match="grid 'radial'"):
        Ball(grid="radial").check()
    dofs = [case_dofs(POLAR, m, "NN2.2")["total"] for m in POLAR_MESHES]
    assert dofs == sorted(dofs) and dofs[-1] < 20000


@pytest.mark.parametrize("layout", ["N2", "NN2.2"])
def test_polar_dof_counts_against_splipy(layout: str) -> None:
    """The polar p1's counts are those of splipy's k-refinement of the polar volume."""
    body = ball_case(POLAR, "p1", layout)["body"][0]
    vol = ball_geometry(POLAR)[BODY]
    spline = volume_to_splipy(vol)
    spline.raise_order(*(body["degree_xi"] - q for q in vol.degree))
    new = [body[f"knots_{d}"] for d in ("xi", "eta", "zeta")]
    for d, k in enumerate(new):
        spline.insert_knot(k, direction=d)
    n = list(spline.shape)
    interface = 3 * n[0] * n[1]
    if body["layer_degree"]:
        face = Surface(*volume_to_splipy(vol).bases[:2], volume_to_splipy(vol).controlpoints[:, :, -1],
                       rational=True, raw=True)
        face.raise_order(*(body["layer_degree"] - q for q in vol.degree[:2]))
        for d, k in enumerate(new[:2]):
            face.insert_knot(k, direction=d)
        face.raise_order(body["layer_elevations"], body["layer_elevations"])
        interface = 3 * face.shape[0] * face.shape[1]
    assert case_dofs(POLAR, "p1", layout) == {"interface": interface, "bulk": 3 * n[0] * n[1] * (n[2] - 1),
                                              "total": interface + 3 * n[0] * n[1] * (n[2] - 1)}


def test_the_polar_block() -> None:
    """``--grid polar --master block``: the block is the quarter cylinder of radius L about
    the contact's axis, its top (z = -R) the contact face, its faces named as the box's;
    its r knots are the box's x knots with the band 0.9 .. 1.1 a_est split as the ball's,
    so its knot lines too are circles about the axis."""
    ball = Ball(master="block", grid="polar", block_size=0.75, radius=2.0)
    vol = ball_geometry(ball)[BLOCK]
    check_volume(BLOCK, vol)
    assert enclosed_volume(vol) == pytest.approx(math.pi * 1.5**2 / 4 * 1.5, rel=1e-12)
    xi, eta = _random()
    top = evaluate(vol, xi, eta, np.ones_like(xi))
    np.testing.assert_allclose(top[:, 2], -2.0, atol=1e-15)
    np.testing.assert_allclose(np.hypot(top[:, 0], top[:, 1]), 1.5 * xi, rtol=1e-12)  # r = xi L
    assert set(vol.faces.values()) >= {"symmetry_x", "symmetry_y", "bottom", BLOCK_FACE}
    for mesh in POLAR_MESHES:
        polar = block_knots(ball, mesh)
        assert polar["knots_eta"] == [k / PHI_ELEMENTS for k in range(1, PHI_ELEMENTS)]
        r = np.concatenate([[0.0], polar["knots_xi"], [1.0]]) * 1.5
        a = ball.half_width
        inside = (r[1:] > EDGE_BAND[0] * a) & (r[:-1] < EDGE_BAND[1] * a)
        assert inside.sum() >= POLAR_MESHES[mesh][3]
        h = BLOCK_CELL * ball.radius * math.asin(1.5 * a / ball.radius) / POLAR_MESHES[mesh][0]
        np.testing.assert_allclose(np.diff(r)[inside], h / POLAR_MESHES[mesh][3], rtol=1e-9)
        assert len(polar["knots_zeta"]) == POLAR_MESHES[mesh][2] - 1
