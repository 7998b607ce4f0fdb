"""``python -m pre hertz``: the committed hertz cases come out again for the committed
cylinder, other cylinders are the committed scene scaled with the arc grading moved to
their expected half-width, bad values and existing files are refused (exit 2, nothing
written), and ``voiga --check`` accepts what is written."""

from __future__ import annotations

import math
import os
import subprocess
from itertools import pairwise
from pathlib import Path

import f90nml
import numpy as np
import pytest

from pre.__main__ import main
from pre.cases import STUDIES, hertz_case
from pre.h5io import read_geometry
from pre.hertz import Cylinder, HertzCaseError, cylinder_case, expected_half_width, grading_half_width, write_hertz_case
from pre.meshes import HERTZ_A_EXP, HERTZ_H_SURFACE, HERTZ_N_CONTACT, arc_angle, hertz_theta_c

from .conftest import CASES, REPO

STEEL = ["--radius", "2", "--youngs-modulus", "210000", "--poisson-ratio", "0.3",
         "--indentation", "0.002", "--mesh", "m2", "--layout", "NN2.2"]


def test_the_committed_cases_come_out_again() -> None:
    """R 1, E 1, nu 0.3, indentation 0.01: every committed hertz case (the title aside)."""
    for mesh, layout in STUDIES["hertz"]:
        mine, committed = cylinder_case(Cylinder(), mesh, layout), hertz_case(mesh, layout)
        assert mine["case"].pop("title").startswith(f"hertz {mesh} {layout}: R = 1")
        committed["case"].pop("title")
        assert mine == committed, (mesh, layout)


def test_the_committed_geometry_comes_out_again(tmp_path: Path) -> None:
    write_hertz_case(Cylinder(), "m1", "N2", tmp_path)
    (_, mine), (_, committed) = (read_geometry(tmp_path / "geometry.h5"),
                                 read_geometry(CASES / "hertz" / "geometry.h5"))
    np.testing.assert_array_equal(mine["cylinder"].control_points,
                                  committed["cylinder"].control_points)


def test_scaled_cylinder(tmp_path: Path) -> None:
    """The committed d/R on another cylinder: the committed knots (both directions), the
    geometry scaled by R, the flat at y = -R, u_y = -d, the penalty scaled by E / R (the
    same problem in other units)."""
    cyl = Cylinder(radius=2.5, youngs_modulus=7.0, poisson_ratio=0.2, indentation=0.025)
    groups = cylinder_case(cyl, "m3", "NN2.2")
    committed = hertz_case("m3", "NN2.2")
    assert groups["body"][0]["knots_xi"] == committed["body"][0]["knots_xi"]
    assert groups["body"][0]["knots_eta"] == committed["body"][0]["knots_eta"]
    assert (groups["body"][0]["youngs_modulus"], groups["body"][0]["poisson_ratio"]) == (7.0, 0.2)
    c = groups["contact"][0]
    assert c["rigid_point"] == [0.0, -2.5] and c["penalty_normal"] == pytest.approx(1000 * 7 / 2.5)
    # another indentation: the penalty also scales as 1/a (the committed E*/(eps a))
    c = cylinder_case(Cylinder(radius=2.5, youngs_modulus=7.0, indentation=0.005), "m1", "N2")
    a_ratio = grading_half_width(0.002) / HERTZ_A_EXP
    assert c["contact"][0]["penalty_normal"] == pytest.approx(1000 * 7 / 2.5 / a_ratio, rel=1e-14)
    assert [d.get("uy") for d in groups["dirichlet"]] == [-0.025, None]
    write_hertz_case(cyl, "m3", "NN2.2", tmp_path)
    _, bodies = read_geometry(tmp_path / "geometry.h5")
    _, ref = read_geometry(CASES / "hertz" / "geometry.h5")
    np.testing.assert_allclose(bodies["cylinder"].control_points,
                               2.5 * ref["cylinder"].control_points, rtol=0, atol=1e-15)
    nml = f90nml.read(str(tmp_path / "m3-NN2.2.nml"))
    assert nml["case"]["output"] == "m3-NN2.2.h5" and nml["case"]["geometry"] == "geometry.h5"


def test_expected_half_width() -> None:
    """The estimate solves d/R = (a/R)^2/4 (2 ln(4R/a) - 1); the committed d/R = 0.01 gives
    0.0760 (the committed runs: 0.0757 from their force) and the committed grading."""
    for d in (1e-4, 1e-3, 0.01, 0.05, 0.099):
        x = expected_half_width(d)
        assert x * x / 4 * (2 * math.log(4 / x) - 1) == pytest.approx(d, rel=1e-12)
    assert expected_half_width(0.01) == pytest.approx(0.0760, abs=5e-5)
    assert grading_half_width(0.01) == HERTZ_A_EXP
    assert np.all(np.diff([expected_half_width(d) for d in np.geomspace(1e-5, 0.09, 30)]) > 0)


@pytest.mark.parametrize("indentation", [0.0005, 0.002, 0.03])
@pytest.mark.parametrize("mesh", ["m1", "m4"])
def test_grading_covers_the_expected_half_width(indentation: float, mesh: str) -> None:
    """The fine part of the arc mesh (the first 5 x 2^(m-1) elements from the lowest
    point: 5 m1 elements uniform in angle, each split into 2^(m-1) equal parameter spans)
    reaches theta_c = asin(1.5 a_g / R) and so covers the expected contact zone with room
    to spare (a_g is 1.05 times the estimate), and its elements shrink with a."""
    radius = 3.0
    cyl = Cylinder(radius=radius, indentation=indentation * radius)
    body = cylinder_case(cyl, mesh, "N2")["body"][0]
    knots = np.asarray(body["knots_xi"])
    split = 2 ** (int(mesh[1:]) - 1)
    n_fine = HERTZ_N_CONTACT * split
    angles = arc_angle(np.concatenate([[0.0], knots]))  # from the lowest point
    a_g = grading_half_width(indentation)
    assert a_g == pytest.approx(HERTZ_A_EXP / 0.0759909 * expected_half_width(indentation),
                                rel=1e-5)
    tc = hertz_theta_c(a_g)
    assert angles[n_fine] == pytest.approx(tc, abs=1e-12)
    np.testing.assert_allclose(np.diff(angles[:n_fine + 1:split]), tc / HERTZ_N_CONTACT,
                               rtol=1e-9)
    assert np.all(np.diff(angles[:n_fine + 1]) < 1.1 * tc / n_fine)
    a = cyl.half_width
    assert radius * math.sin(tc) >= 1.5 * a
    # the zone x < a holds the expected share of the fine elements, ~ n_fine / 1.5 / 1.05
    inside = np.count_nonzero(radius * np.sin(angles[1:n_fine + 1]) <= a)
    assert inside == pytest.approx(n_fine / 1.5 / 1.0527, abs=1)
    # radially, the surface element is the committed 0.005 R scaled as a_g (the
    # annulus is 0.95 R thick; eta = 1 is the surface)
    surface = (1.0 - body["knots_eta"][-1]) * 0.95 * radius
    assert surface == pytest.approx(HERTZ_H_SURFACE * a_g / HERTZ_A_EXP * radius, rel=1e-12)


@pytest.mark.parametrize("layout", ["L1", "N2", "NN2.2"])
def test_the_largest_indentation(layout: str) -> None:
    """Just below R/10 the scaled surface element would exceed a uniform radial mesh: the
    mesh is uniform radially instead (47 or 48 equal radial elements)."""
    eta = np.asarray(cylinder_case(Cylinder(indentation=0.0999), "m1", layout)
                     ["body"][0]["knots_eta"])
    np.testing.assert_allclose(np.diff(np.concatenate([[0.0], eta, [1.0]])), 1 / (len(eta) + 1),
                               rtol=1e-9)


def test_the_command(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Writes both files, says so; a second mesh of the same cylinder keeps the geometry."""
    assert main(["hertz", *STEEL, "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert f"wrote {tmp_path / 'geometry.h5'}" in out and f"wrote {tmp_path / 'm2-NN2.2.nml'}" in out
    assert "a/R = 0.02047" in out
    before = (tmp_path / "geometry.h5").stat().st_mtime_ns
    assert main(["hertz", *STEEL[:-4], "--mesh", "m1", "--layout", "N2", "--method", "mortar",
                 "--penalty-normal", "auto", "--steps", "3", "--out", str(tmp_path)]) == 0
    assert "kept" in capsys.readouterr().out
    assert (tmp_path / "geometry.h5").stat().st_mtime_ns == before
    nml = f90nml.read(str(tmp_path / "m1-N2.nml"))
    assert nml["contact"]["method"] == "mortar" and "penalty_normal" not in nml["contact"]
    assert nml["solver"]["n_steps"] == 3


@pytest.mark.parametrize("bad, says", [
    (["--radius", "0"], "radius 0 must be > 0"),
    (["--radius", "-2"], "radius -2 must be > 0"),
    (["--youngs-modulus", "0"], "youngs modulus 0 must be > 0"),
    (["--youngs-modulus", "-1"], "youngs modulus -1 must be > 0"),
    (["--poisson-ratio", "0.5"], "poisson ratio 0.5 must be in (-1, 0.5)"),
    (["--poisson-ratio", "-1"], "poisson ratio -1 must be in (-1, 0.5)"),
    (["--indentation", "0"], "indentation 0 must be > 0"),
    (["--indentation", "-0.01"], "indentation -0.01 must be > 0"),
    (["--radius", "2", "--indentation", "0.2"], "< radius/10 = 0.2"),
    (["--radius", "nan"], "radius nan is not a finite number"),
    (["--mesh", "m9"], "mesh 'm9'"),
    (["--mesh", "fine"], "mesh name must be m<k>"),
    (["--layout", "NN1"], "NN1"),
    (["--steps", "0"], "steps 0"),
    (["--penalty-normal", "-5"], "penalty_normal"),
    (["--penalty-normal", "soft"], "penalty_normal"),
    (["--edge-refine", "0"], "edge refinement 0"),
    (["--edge-refine", "17"], "edge refinement 17"),
])
def test_bad_values_exit_2(bad: list[str], says: str, tmp_path: Path,
                           capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "never"
    assert main(["hertz", *bad, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("python -m pre hertz: ") and says in err[0]
    assert not out.exists()


def test_no_overwrite(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """An existing case file, or the geometry of another cylinder, is kept (exit 2, one
    line naming it, nothing written); --force overwrites."""
    assert main(["hertz", *STEEL, "--out", str(tmp_path)]) == 0
    case, geometry = tmp_path / "m2-NN2.2.nml", tmp_path / "geometry.h5"
    case.write_text("edited by hand\n")
    geo_bytes = geometry.read_bytes()
    capsys.readouterr()
    assert main(["hertz", *STEEL, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert str(case) in err and "--force" in err and case.read_text() == "edited by hand\n"
    other = ["--radius", "3", "--indentation", "0.01", "--mesh", "m1", "--out", str(tmp_path)]
    assert main(["hertz", *other]) == 2
    assert "another cylinder" in capsys.readouterr().err
    assert geometry.read_bytes() == geo_bytes and not (tmp_path / "m1-NN2.2.nml").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["geometry.h5", "m2-NN2.2.nml"]
    assert main(["hertz", *STEEL, "--out", str(tmp_path), "--force"]) == 0
    assert case.read_text().startswith("&case")
    with pytest.raises(HertzCaseError):
        write_hertz_case(Cylinder(radius=3.0), "m1", "N2", tmp_path)


def test_edge_refinement(tmp_path: Path) -> None:
    """--edge-refine K splits exactly the arc spans that overlap 0.9 a .. 1.1 a (a the
    expected half-width) and the first span beyond the graded zone into K equal spans,
    leaves every other knot in place, and names the case and its output
    <mesh>-<layout>-edgeK; --surface-size S sets the radial surface element to S a."""
    cyl = Cylinder(indentation=0.0025)
    plain = cylinder_case(cyl, "m3", "NN2.2")["body"][0]["knots_xi"]
    groups = cylinder_case(cyl, "m3", "NN2.2", edge_refine=3)
    fine = groups["body"][0]["knots_xi"]
    a = cyl.half_width
    angles = arc_angle(np.array([0.0, *plain, 1.0]))  # from the lowest point
    theta_c = hertz_theta_c(grading_half_width(0.0025))
    first_coarse = int(np.flatnonzero(angles[:-1] >= theta_c * (1 - 1e-12))[0])
    hit = [(lo < math.asin(1.1 * a)) and (hi > math.asin(0.9 * a)) or k == first_coarse
           for k, (lo, hi) in enumerate(pairwise(angles))]
    assert 2 <= sum(hit) <= 7 and hit[first_coarse] and not hit[first_coarse - 1]
    assert len(fine) == len(plain) + 2 * sum(hit)
    assert set(plain) <= set(fine)
    spans = np.diff([0.0, *fine, 1.0])
    full = np.diff([0.0, *plain, 1.0])
    assert np.allclose(np.sort(spans), np.sort(np.concatenate(
        [np.repeat(full[hit] / 3, 3), full[~np.array(hit)]])), rtol=1e-12)
    assert groups["case"]["output"] == "m3-NN2.2-edge3.h5"
    _, case, _ = write_hertz_case(cyl, "m3", "NN2.2", tmp_path, edge_refine=3)
    assert case.name == "m3-NN2.2-edge3.nml"
    assert f90nml.read(str(case))["body"]["knots_xi"] == pytest.approx(fine, rel=1e-15)
    surf = cylinder_case(cyl, "m3", "NN2.2", surface_size=0.02)
    eta = surf["body"][0]["knots_eta"]
    assert (1 - eta[-1]) * (1 - 0.05) == pytest.approx(0.02 * a, rel=1e-9)  # thickness 0.95 R
    assert surf["case"]["output"] == "m3-NN2.2-surf0.02.h5"
    with pytest.raises(HertzCaseError, match="surface size"):
        cylinder_case(cyl, "m3", "NN2.2", surface_size=0.0)


def _voiga() -> Path | None:
    env = os.environ.get("VOIGA_BIN")
    path = Path(env) if env else REPO / "build" / "install" / "bin" / "voiga"
    return path if path.is_file() and os.access(path, os.X_OK) else None


@pytest.mark.parametrize("mesh, layout", [("m1", "L1"), ("m2", "NN2.2"), ("m4", "NN3.2")])
def test_voiga_check_accepts_the_case(mesh: str, layout: str, tmp_path: Path) -> None:
    """``voiga CASE --check`` reads the case and geometry, builds the discretization and
    counts the committed case's DOFs (the mesh is the same in parameter space)."""
    voiga = _voiga()
    if voiga is None:
        if os.environ.get("CI"):
            pytest.fail("voiga binary not found (build it or set VOIGA_BIN)")
        pytest.skip("voiga binary not found (build it or set VOIGA_BIN)")
    write_hertz_case(Cylinder(radius=2.0, youngs_modulus=210000.0, indentation=0.002), mesh,
                     layout, tmp_path)
    mine = subprocess.run([str(voiga), f"{mesh}-{layout}.nml", "--check"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    committed = subprocess.run([str(voiga), f"{mesh}-{layout}.nml", "--check"],
                               cwd=CASES / "hertz", capture_output=True, text=True, timeout=120)
    assert mine.returncode == 0, mine.stdout + mine.stderr
    def dofs(out: str) -> list[str]:
        return [line for line in out.splitlines() if line.startswith("dofs all total=")]
    assert len(dofs(mine.stdout)) == 1 and dofs(mine.stdout) == dofs(committed.stdout)
