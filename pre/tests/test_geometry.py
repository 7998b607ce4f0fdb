"""``pre.geometry`` shapes and ``python -m pre geometry`` specs: exact boundaries,
named edges, checks, .g2 import, and files the solver reads (``voiga --check``)."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest
import splipy
from splipy import surface_factory

from pre.__main__ import main
from pre.geometry import annular_sector, check_patch, edge_length, polygon, rectangle, write_bodies
from pre.h5io import read_geometry
from pre.nurbs import evaluate_patch

REPO = Path(__file__).resolve().parents[2]
T = np.linspace(0.0, 1.0, 1001)


def _edge(patch, key: str) -> np.ndarray:
    one, zero = np.ones_like(T), np.zeros_like(T)
    xi, eta = {"xi0": (zero, T), "xi1": (one, T), "eta0": (T, zero), "eta1": (T, one)}[key]
    return evaluate_patch(patch, xi, eta)


def _voiga() -> Path | None:
    path = Path(os.environ.get("VOIGA_BIN", REPO / "build" / "install" / "bin" / "voiga"))
    return path if path.is_file() else None


@pytest.mark.parametrize("angles", [[180, 360], [200, 340], [-30, 250], [90, 45]])
def test_annular_sector_arcs_are_exact(angles: list[float]) -> None:
    p = annular_sector((1.0, 2.0), 0.5, 1.25, angles, {"outer": "rim"})
    check_patch("s", p)
    for key, r in (("eta0", 0.5), ("eta1", 1.25)):
        d = np.linalg.norm(_edge(p, key) - [1.0, 2.0], axis=1)
        assert np.abs(d - r).max() < 1e-12, key
    a = np.radians(angles)
    start = _edge(p, "eta1")[0]
    np.testing.assert_allclose(start, [1 + 1.25 * np.cos(a[0]), 2 + 1.25 * np.sin(a[0])], atol=1e-12)
    assert p.edges == {"xi0": "start", "xi1": "end", "eta0": "inner", "eta1": "rim"}
    # arc length of the rim: the exact one to the polyline's accuracy
    assert abs(edge_length(p, "eta1", 4000) - 1.25 * abs(a[1] - a[0])) < 1e-5


def test_polygon_with_arc_edges() -> None:
    pts = [[0, 0], [2, 0], [2, 1], [1, 1.5], [0, 1]]
    p = polygon(pts, corners=[0, 1, 2, 4], arcs={0: 3.0, 4: -2.0}, edges=["b", "r", "t", "l"])
    check_patch("p", p)
    assert sorted(p.edges.values()) == ["b", "l", "r", "t"]
    bottom = _edge(p, p.edge_key("b"))
    # segment 0 bulges outward (down) on the circle of radius 3 through (0,0), (2,0)
    centre = np.array([1.0, np.sqrt(9 - 1)])
    assert np.abs(np.linalg.norm(bottom - centre, axis=1) - 3.0).max() < 1e-12
    assert bottom[:, 1].min() < -0.17
    top = _edge(p, p.edge_key("t"))  # the two straight segments through (1, 1.5)
    assert np.min(np.linalg.norm(top - [1.0, 1.5], axis=1)) < 1e-12
    left = _edge(p, p.edge_key("l"))  # inward arc of radius 2 from (0, 1) to (0, 0)
    centre = np.array([-np.sqrt(4 - 0.25), 0.5])  # chord 1, radius 2, bulging to +x
    assert np.abs(np.linalg.norm(left - centre, axis=1) - 2).max() < 1e-12
    assert left[:, 0].max() == pytest.approx(2 - np.sqrt(3.75), abs=1e-6)


def test_checks_name_the_problem() -> None:
    with pytest.raises(ValueError, match="counter-clockwise"):
        polygon([[0, 0], [0, 1], [1, 1], [1, 0]])
    with pytest.raises(ValueError, match="folds over"):  # a bow tie of corners
        check_patch("x", polygon([[0, 0], [2, 0], [2, 2], [1.9, 0.1], [0, 2]], corners=[0, 1, 3, 4]))
    with pytest.raises(ValueError, match="unknown side"):
        rectangle([0, 1], [0, 1], {"up": "x"})
    with pytest.raises(ValueError, match="different names"):
        check_patch("r", rectangle([0, 1], [0, 1], {"top": "a", "bottom": "a"}))
    with pytest.raises(ValueError, match="cannot join"):
        polygon([[0, 0], [2, 0], [2, 1], [0, 1]], arcs={0: 0.5})


def test_write_bodies_from_splipy(tmp_path: Path) -> None:
    disc = surface_factory.disc(r=1.0, type="square")  # a splipy surface, any parameters
    path = write_bodies(tmp_path / "g.h5", {"disc": disc, "box": rectangle([2, 3], [0, 1])},
                        edges={"disc": {"xi0": "w", "xi1": "e", "eta0": "s", "eta1": "n"}})
    attrs, bodies = read_geometry(path)
    assert attrs["units"] == "mm, N" and list(bodies) == ["disc", "box"]
    assert bodies["disc"].knots_xi[0] == 0 and bodies["disc"].knots_xi[-1] == 1
    r = np.linalg.norm(_edge(bodies["disc"], "eta1"), axis=1)
    assert r.max() == pytest.approx(1.0, abs=1e-12)


SPEC = """
units = "mm, N"
[defaults]
layout = "NN2.2"
element_size = 0.5
[[body]]
name = "block"
shape = "rectangle"
x = [0.0, 4.0]
y = [-1.0, 0.0]
contact_edge = "top"
[[body]]
name = "arch"
shape = "arc"
centre = [2.0, 1.0]
radius = 0.8
thickness = 0.3
angles = [190, 350]
contact_edge = "outer"
[[body]]
name = "punch"
shape = "polygon"
points = [[5, 0], [6, 0], [6, 1], [5, 1]]
arcs = [{ segment = 0, radius = 1.0 }]
edges = ["face", "right", "top", "left"]
contact_edge = "face"
[[body]]
name = "part"
shape = "g2"
file = "part.g2"
edges = { xi0 = "a", xi1 = "b", eta0 = "c", eta1 = "d" }
contact_edge = "d"
nel = [3, 2]
"""


def _write_g2(path: Path) -> None:
    from splipy.io import G2

    quarter = surface_factory.edge_curves(splipy.curve_factory.circle_segment(np.pi / 2, 1.0),
                                          splipy.curve_factory.circle_segment(np.pi / 2, 2.0))
    quarter.translate((8.0, 0.0, 0.0))
    with G2(str(path)) as f:
        f.write(quarter)


def test_spec_writes_geometry_and_case(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "scene.toml").write_text(SPEC)
    _write_g2(tmp_path / "part.g2")
    assert main(["geometry", str(tmp_path / "scene.toml")]) == 0
    out = capsys.readouterr().out
    geo, case = tmp_path / "scene-geometry.h5", tmp_path / "scene.nml"
    assert str(geo) in out and str(case) in out
    attrs, bodies = read_geometry(geo)
    assert list(bodies) == ["block", "arch", "punch", "part"]
    text = case.read_text()
    assert "geometry = 'scene-geometry.h5'" in text and "n_bodies = 4" in text
    # element_size 0.5: the block is 4 x 1 -> 8 x 2
    assert "nel_xi = 8\n  nel_eta = 2" in text
    assert "! This case has no loads yet" in text
    # the case is kept on a second run, rewritten with --force
    case.write_text(text + "! edited\n")
    assert main(["geometry", str(tmp_path / "scene.toml")]) == 0
    assert "kept" in capsys.readouterr().out and case.read_text().endswith("! edited\n")
    assert main(["geometry", str(tmp_path / "scene.toml"), "--force"]) == 0
    assert not case.read_text().endswith("! edited\n")
    voiga = _voiga()
    if voiga is None:
        pytest.skip("no voiga binary for the --check part")
    run = subprocess.run([str(voiga), str(case), "--check"], capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 0, run.stdout + run.stderr
    assert all(f"dofs {b} " in run.stdout for b in bodies)


RECT = "[[body]]\nname = 'a'\nshape = 'rectangle'\nx = [0, 1]\ny = [0, 1]\n"


@pytest.mark.parametrize("text,message", [
    ("[[body]]\nname = 'a'\nshape = 'circle'\n", "unknown shape"),
    ("[[body]]\nname = 'a'\nshape = 'rectangle'\nx = [0, 1]\n", "missing 'y'"),
    ("[[body]]\nname = 'a'\nshape = 'rectangle'\nx = [0, 1]\ny = [0, 1]\nsize = 2\n", "unknown key"),
    ("[[body]]\nname = 'a'\nshape = 'rectangle'\nx = [0, 1]\ny = [0, 1]\ncontact_edge = 'up'\n",
     "not one of its edges"),
    ("[[body]]\nname = 'a'\nshape = 'rectangle'\nx = [0, 1]\ny = [1, 0]\n", "x0 < x1"),
    ("[[body]\n", "not valid TOML"),
    ("[defaults]\nlayout = 'Q7'\n[[body]]\nname = 'a'\nshape = 'rectangle'\nx = [0, 1]\ny = [0, 1]\n",
     "unknown layout"),
    # issue 36: values that ended in a traceback, ran, or were named wrongly
    (RECT + "element_size = nan\n", "element_size: nan is not a finite number"),
    (RECT + "element_size = 'x'\n", "element_size must be a number"),
    (RECT + "element_size = 1e-300\n", "more than 100000 elements"),
    (RECT + "nel = 12\n", "nel must be two integers"),
    (RECT + "nel = [1.5, 3]\n", "nel[0] must be an integer"),
    (RECT + "nel = [1000000000, 3]\n", "nel[0] must be 1 to 100000"),
    (RECT + "youngs_modulus = 'soft'\n", "youngs_modulus must be a number"),
    (RECT + "youngs_modulus = nan\n", "youngs_modulus: nan is not a finite number"),
    (RECT + "poisson_ratio = 0.5\n", "poisson_ratio must be < 0.5"),
    (RECT + "material = 5\n", "material must be a non-empty string"),
    ("[defaults]\nelements = 0\n" + RECT, "elements must be 1 to 100000"),
    (RECT.replace("x = [0, 1]", "x = [0, inf]"), "x[1]: inf is not a finite number"),
    (RECT.replace("x = [0, 1]", "x = [0, 1, 2]"), "x must have 2 numbers"),
    ("[[body]]\nname = 3\nshape = 'rectangle'\nx = [0, 1]\ny = [0, 1]\n", "name and shape must be strings"),
    ("[[body]]\nname = 'a'\nshape = 'annular_sector'\ncentre = [0, 0]\nr_in = 1\nr_out = 2\n"
     "angles = [180, 180]\n", "a sector spans more than 0 and at most 360 degrees (0 given)"),
    ("[[body]]\nname = 'a'\nshape = 'annular_sector'\ncentre = [0, 0]\nr_in = 1\nr_out = 2\n"
     "angles = [180]\n", "angles must have 2 numbers"),
    ("[[body]]\nname = 'a'\nshape = 'polygon'\npoints = [[0, 0], [1, 0], [1, nan], [0, 1]]\n",
     "nan is not a finite number"),
    ("units = 5\n" + RECT, "units must be a non-empty string"),
    (RECT + "[solver]\nn_steps = [{a = 1}]\n", "is not a namelist value"),
])
def test_bad_specs_exit_2(tmp_path: Path, text: str, message: str,
                          capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "bad.toml"
    spec.write_text(text)
    assert main(["geometry", str(spec)]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "bad.nml").exists()


def test_nel_follows_the_contact_edge(tmp_path: Path) -> None:
    """``nel = [xi, eta]`` is given along the patch's own directions; the case counts
    along the contact edge first (the solver turns the patch), so a contact edge at
    xi = 1 swaps them."""
    from pre.spec import body_group

    p = rectangle([0, 4], [0, 1])
    g = body_group({"name": "r", "contact_edge": "right", "nel": [8, 2]}, p, {"layout": "N2", "elements": 4,
                   "material": "linear", "youngs_modulus": 1.0, "poisson_ratio": 0.3})
    assert (g["nel_xi"], g["nel_eta"]) == (2, 8)
    g = body_group({"name": "r", "contact_edge": "top", "element_size": 0.5}, p, {"layout": "N2",
                   "elements": 4, "material": "linear", "youngs_modulus": 1.0, "poisson_ratio": 0.3})
    assert (g["nel_xi"], g["nel_eta"]) == (8, 2)


def test_solver_turns_a_non_square_patch(tmp_path: Path) -> None:
    """A non-square coarse patch whose contact edge is xi1 is turned by the solver (it
    aborted with 'double free or corruption' before: surface_reorient, gfortran 12)."""
    voiga = _voiga()
    if voiga is None:
        pytest.skip("no voiga binary")
    (tmp_path / "s.toml").write_text(SPEC.split("[[body]]")[0] + "[[body]]" + SPEC.split("[[body]]")[-1]
                                     .replace('contact_edge = "d"', 'contact_edge = "b"'))
    _write_g2(tmp_path / "part.g2")
    assert main(["geometry", str(tmp_path / "s.toml")]) == 0
    run = subprocess.run([str(voiga), str(tmp_path / "s.nml"), "--check"], capture_output=True,
                         text=True, timeout=120)
    assert run.returncode == 0, run.stderr[-500:]
    # 2 x 3 elements along the turned patch (nel_xi runs along the contact edge)
    assert "dofs part interface=16 bulk=32 total=48 elements=6" in run.stdout, run.stdout
