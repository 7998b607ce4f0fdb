"""A spec that holds the whole case (issue 38, item 4): every namelist group (``[output]``
too) checked against the variables voiga reads; the ellipse, the solid sector
(``r_in = 0``) and a polygon side of several segments as one contact edge; and a spec
edited after its case was written: ``pre geometry`` lists what differs and writes
nothing without ``--force``, which lists what it replaces."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

from pre.__main__ import main
from pre.geometry import annular_sector, check_patch, ellipse_sector, obstacle_ellipse, polygon
from pre.h5io import read_geometry
from pre.nurbs import curve_to_splipy, evaluate_patch

REPO = Path(__file__).resolve().parents[2]
T = np.linspace(0.0, 1.0, 1001)

SPEC = """
units = "mm, N"
scene = "ellipse on block"
[defaults]
layout = "NN2.2"
[[body]]
name = "block"
shape = "rectangle"
x = [0.0, 40.0]
y = [-10.0, 0.0]
contact_edge = "top"
nel = [20, 4]
[[body]]
name = "indenter"
shape = "ellipse"
centre = [20.0, 2.5]
semi_axes = [5.0, 2.5]
angles = [180.0, 360.0]
contact_edge = "outer"
youngs_modulus = 10.0
nel = [8, 2]
[solver]
n_steps = [5, 20]
[[dirichlet]]
body = "block"
edge = "bottom"
fix_x = true
fix_y = true
[[dirichlet]]
body = "indenter"
edge = "inner"
fix_x = true
fix_y = true
ux = [0.0, 2.0]
uy = [-0.5, -0.5]
[[dirichlet]]
body = "indenter"
edge = "start"
fix_x = true
fix_y = true
ux = [0.0, 2.0]
uy = [-0.5, -0.5]
[[dirichlet]]
body = "indenter"
edge = "end"
fix_x = true
fix_y = true
ux = [0.0, 2.0]
uy = [-0.5, -0.5]
[[contact]]
slave = "block"
master = "indenter"
friction = 0.2
[output]
fields = ["von_mises"]
every = 0
"""


def _voiga() -> Path | None:
    path = Path(os.environ.get("VOIGA_BIN", REPO / "build" / "install" / "bin" / "voiga"))
    return path if path.is_file() else None


def _edge(patch, key: str) -> np.ndarray:
    one, zero = np.ones_like(T), np.zeros_like(T)
    xi, eta = {"xi0": (zero, T), "xi1": (one, T), "eta0": (T, zero), "eta1": (T, one)}[key]
    return evaluate_patch(patch, xi, eta)


def _key(patch, name: str) -> str:
    return next(k for k, v in patch.edges.items() if v == name)


def _write(tmp_path: Path, text: str = SPEC, name: str = "ell.toml") -> Path:
    spec = tmp_path / name
    spec.write_text(text)
    return spec


def test_whole_case_in_the_spec(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """[output] and the load groups go into the case as given; voiga reads it (no hand
    edit of the .nml: `[output]` was refused as an unknown table)."""
    assert main(["geometry", str(_write(tmp_path))]) == 0
    text = (tmp_path / "ell.nml").read_text()
    assert "&output\n  fields = 'von_mises'\n  every = 0\n/" in text, text
    assert text.count("&dirichlet") == 4 and "&solver\n  n_steps = 5, 20\n/" in text
    assert "This case has no loads yet" not in text
    voiga = _voiga()
    if voiga is None:
        pytest.skip("no voiga binary for the --check part")
    run = subprocess.run([str(voiga), str(tmp_path / "ell.nml"), "--check"], capture_output=True,
                         text=True, timeout=120)
    assert run.returncode == 0, run.stderr


@pytest.mark.parametrize("change,message", [
    ("[solver]\nn_steps = [5, 20]\n", "[solver]\nn_steps = [5, 20]\nsteps = 3\n"),
    ("[output]\n", "[[output]]\n"),
    ('[[contact]]\nslave = "block"', '[[contact]]\nslave = "block"\nfriction_coefficient = 0.3'),
    ("[solver]\n", "[case]\ngeometry = 'x.h5'\n[solver]\n"),
    ("[solver]\n", "[loads]\nx = 1\n[solver]\n"),
])
def test_bad_case_tables_exit_2(tmp_path: Path, change: str, message: str,
                                capsys: pytest.CaptureFixture[str]) -> None:
    """A variable voiga does not read, a group given twice that the case has once, a
    &case variable pre writes itself, an unknown table: one line, exit 2, nothing written."""
    assert change in SPEC
    spec = _write(tmp_path, SPEC.replace(change, message, 1))
    assert main(["geometry", str(spec)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1, err
    expected = {"steps": "['steps'] not variable(s) of &solver",
                "[[output]]": "[output] is one table",
                "friction_coefficient": "[[contact]] (1): ['friction_coefficient'] not variable(s) of &contact",
                "geometry": "[case]: ['geometry'] written by pre itself",
                "[loads]": "unknown table(s) ['loads']"}
    assert any(key in message and text in err for key, text in expected.items()), err
    assert not (tmp_path / "ell.nml").exists()


def test_edited_spec_says_what_differs_and_writes_nothing(tmp_path: Path,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    """After the case was written: a new n_steps in the spec, a radius changed, and an
    &output added to the case by hand. `pre geometry` lists each difference and writes
    nothing (it printed `kept ... --force to overwrite` and ignored the new n_steps);
    `--force` writes the spec's and lists what it replaced (the hand-added group
    included: not dropped silently); run again, it is up to date."""
    spec = _write(tmp_path, SPEC.replace("[output]\nfields = [\"von_mises\"]\nevery = 0\n", ""))
    assert main(["geometry", str(spec)]) == 0
    capsys.readouterr()
    case, geometry = tmp_path / "ell.nml", tmp_path / "ell-geometry.h5"
    assert main(["geometry", str(spec)]) == 0
    assert f"kept {geometry} and {case} (up to date with {spec})" in capsys.readouterr().out
    case.write_text(case.read_text() + "! my note\n&output\n  fields = 'stress'\n/\n")
    spec.write_text(spec.read_text().replace("n_steps = [5, 20]", "n_steps = [10, 20]")
                    .replace("semi_axes = [5.0, 2.5]", "semi_axes = [6.0, 2.5]"))
    before = (case.read_bytes(), geometry.read_bytes())
    assert main(["geometry", str(spec)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err[0] == f"python -m pre geometry: {case} and {geometry.name} differ from what {spec} gives now:"
    assert "  ell.nml: &solver n_steps: 5, 20 (case file) -> 10, 20 (spec)" in err, err
    assert "  ell.nml: &output: only in the case file (the spec has no such [output] table)" in err, err
    assert "  ell.nml: &body 'indenter' nel_xi: 8 (case file) -> 8 (spec)" not in err
    assert "  ell-geometry.h5: body 'indenter': its shape or edges differ" in err, err
    assert err[-1].startswith("nothing written; --force writes both from the spec")
    assert (case.read_bytes(), geometry.read_bytes()) == before
    assert main(["geometry", str(spec), "--force"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[:3] == [f"wrote {geometry}", f"wrote {case}", "replaced (case file or geometry -> spec):"], out
    assert "  ell.nml: &output: only in the case file (the spec has no such [output] table)" in out, out
    assert "n_steps = 10, 20" in case.read_text() and "&output" not in case.read_text()
    _, bodies = read_geometry(geometry)
    assert np.isclose(bodies["indenter"].control_points[..., 0].max(), 26.0)
    assert main(["geometry", str(spec)]) == 0
    assert "up to date" in capsys.readouterr().out


def test_ellipse_is_exact(tmp_path: Path) -> None:
    """The ellipse shape: its outer side on (x - cx)^2/a^2 + (y - cy)^2/b^2 = 1, its inner
    side on the ellipse scaled by `inner`; the solid one (inner 0) has no degenerate
    point; the obstacle curve alike."""
    for inner in (0.0, 0.4):
        p = ellipse_sector((20.0, 2.5), (5.0, 2.5), (180.0, 360.0), inner=inner)
        check_patch("e", p)
        x = _edge(p, _key(p, "outer"))
        np.testing.assert_allclose(((x[:, 0] - 20) / 5) ** 2 + ((x[:, 1] - 2.5) / 2.5) ** 2, 1.0, atol=1e-12)
        assert np.all(x[:, 1] <= 2.5 + 1e-12)
        if inner:
            x = _edge(p, _key(p, "inner"))
            np.testing.assert_allclose(((x[:, 0] - 20) / 2) ** 2 + ((x[:, 1] - 2.5) / 1) ** 2, 1.0, atol=1e-12)
    c = obstacle_ellipse((0.0, 1.0), (3.0, 1.0), (180.0, 360.0))
    x = np.asarray(curve_to_splipy(c)(T))[:, :2]
    np.testing.assert_allclose((x[:, 0] / 3) ** 2 + (x[:, 1] - 1.0) ** 2, 1.0, atol=1e-12)
    with pytest.raises(ValueError, match="semi_axes must be positive"):
        ellipse_sector((0, 0), (1.0, 0.0), (0, 90))


@pytest.mark.parametrize("angles", [[180, 360], [200, 300], [360, 180], [0, 90]])
def test_solid_sector(angles: list[float]) -> None:
    """r_in = 0: one patch with the arc as one side (outer) on its circle, the two radii
    and the centre on the other three (start, inner, end), no degenerate point (the
    Jacobian keeps its sign); more than 180 degrees is refused."""
    p = annular_sector((1.0, 2.0), 0.0, 3.0, angles)
    check_patch("s", p)
    assert sorted(p.edges.values()) == ["end", "inner", "outer", "start"]
    x = _edge(p, _key(p, "outer"))
    np.testing.assert_allclose(np.hypot(x[:, 0] - 1.0, x[:, 1] - 2.0), 3.0, atol=1e-12)
    inner = _edge(p, _key(p, "inner"))
    assert np.min(np.hypot(inner[:, 0] - 1.0, inner[:, 1] - 2.0)) < 1e-12   # through the centre
    a0 = np.radians(angles[0])
    start = _edge(p, _key(p, "start"))
    d = start - [1.0, 2.0]
    np.testing.assert_allclose(d[:, 0] * np.sin(a0) - d[:, 1] * np.cos(a0), 0.0, atol=1e-12)
    with pytest.raises(ValueError, match="at most 180 degrees"):
        annular_sector((0, 0), 0.0, 1.0, [0, 270])


def test_polygon_side_of_several_segments_is_one_contact_edge(tmp_path: Path) -> None:
    """A flat punch with rounded corners: its bottom side runs through four points
    (arc, straight, arc) and is one edge, the contact edge; a half-disc polygon (its
    points on one line, the area from the arc) is accepted. voiga reads the punch
    case and presses it into a block."""
    half = polygon([(-1.0, 0.0), (1.0, 0.0), (0.3, 0.0), (-0.3, 0.0)], arcs={0: 1.0},
                   edges=["round", "a", "flat", "b"])
    check_patch("half", half)
    assert polygon([(0, 0), (1, 0), (1, 1), (0, 1)]) is not None
    spec = _write(tmp_path, """
[[body]]
name = "block"
shape = "rectangle"
x = [0.0, 10.0]
y = [-3.0, 0.0]
contact_edge = "top"
nel = [20, 4]
[[body]]
name = "punch"
shape = "polygon"
points = [[3.0, 1.0], [3.0, 0.5], [3.5, 0.0], [6.5, 0.0], [7.0, 0.5], [7.0, 1.0]]
corners = [0, 1, 4, 5]
arcs = [{segment = 1, radius = -0.5}, {segment = 3, radius = -0.5}]
edges = ["left", "bottom", "right", "top"]
contact_edge = "bottom"
youngs_modulus = 10.0
nel = [12, 2]
[solver]
n_steps = [3]
[[dirichlet]]
body = "block"
edge = "bottom"
fix_x = true
fix_y = true
[[dirichlet]]
body = "punch"
edge = "top"
fix_x = true
fix_y = true
uy = [-0.05]
[[contact]]
slave = "block"
master = "punch"
""", "punch.toml")
    assert main(["geometry", str(spec)]) == 0
    _, bodies = read_geometry(tmp_path / "punch-geometry.h5")
    punch = bodies["punch"]
    bottom = _edge(punch, _key(punch, "bottom"))
    assert np.isclose(bottom[:, 0].min(), 3.0) and np.isclose(bottom[:, 0].max(), 7.0)
    assert np.isclose(bottom[:, 1].min(), 0.0, atol=1e-12) and np.isclose(bottom[:, 1].max(), 0.5)
    voiga = _voiga()
    if voiga is None:
        pytest.skip("no voiga binary")
    run = subprocess.run([str(voiga), str(tmp_path / "punch.nml"), "--quiet"], capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 0, run.stderr
    # a sound set-up: no warning but the contact-zone indicator's (6 block elements under
    # the punch: too few to resolve its corners, docs/contact-accuracy.md)
    assert all("contact zone" in line for line in run.stderr.splitlines() if "warning" in line), run.stderr
