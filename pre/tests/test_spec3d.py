"""``python -m pre geometry3d``: a spec of 3D bodies -> a geometry file of volumes and
the case file of the solids (docs/pre.md, "3D bodies"): each body's layout, elements
and contact face in the case's &body, the load tables on faces checked against the
volumes, the written cases run by voiga (a box pulled by a face traction: the exact
uniaxial field; the thick spherical shell: Lame's radial displacement); run again, the
files are kept, or the differences listed and nothing written without --force; bad
specs end with one line and exit code 2."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import f90nml
import h5py
import numpy as np
import pytest
from splipy import volume_factory
from splipy.io import G2

from post.lame import LameShell
from pre.__main__ import main
from pre.h5io import read_volumes
from pre.solid_case import direction_lengths
from pre.solids import box, shell_octant

REPO = Path(__file__).resolve().parents[2]

SPEC = '''units = "mm, N"
scene = "3D demo"

[[body]]
name = "block"
shape = "box"
x = [-2.0, 2.0]
y = [-2.0, 2.0]
z = [-1.0, 0.0]
faces = { top = "surface" }

[[body]]
name = "dome"
shape = "shell_octant"
r_in = 0.5
r_out = 1.0

[[body]]
name = "ring"
shape = "revolve"
angle = 90.0
section = { shape = "annular_sector", centre = [3.0, 0.0], r_in = 0.2, r_out = 0.5, angles = [0.0, 90.0] }
faces = { outer = "rim" }

[[body]]
name = "bar"
shape = "extrude"
z = [0.0, 2.0]
section = { shape = "rectangle", x = [5.0, 6.0], y = [0.0, 1.0], edges = { top = "contact" } }
ends = ["near", "far"]

[[body]]
name = "pipe"
shape = "cylinder_sector"
r_in = 1.0
r_out = 1.5
angles = [0.0, 60.0]
z = [0.0, 3.0]
centre = [10.0, 0.0]

[[body]]
name = "cube"
shape = "g2"
file = "cube.g2"
faces = { xi0 = "a", xi1 = "b", eta0 = "c", eta1 = "d", zeta0 = "e", zeta1 = "f" }
'''


def _write(tmp_path: Path, text: str) -> Path:
    with G2(str(tmp_path / "cube.g2")) as f:
        f.write(volume_factory.cube(0.5, lower_left=(20.0, 0.0, 0.0)))
    spec = tmp_path / "demo.toml"
    spec.write_text(text)
    return spec


def test_spec3d_writes_keeps_and_replaces(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = _write(tmp_path, SPEC)
    assert main(["geometry3d", str(spec)]) == 0
    assert (tmp_path / "demo.nml").is_file()
    attrs, vols = read_volumes(tmp_path / "demo-geometry.h5")
    assert attrs["dimension"] == 3 and attrs["scene"] == "3D demo"
    assert list(vols) == ["block", "dome", "ring", "bar", "pipe", "cube"]
    assert vols["block"].faces["zeta1"] == "surface"
    assert np.array_equal(vols["dome"].control_points, shell_octant(0.5, 1.0).control_points)
    assert vols["ring"].faces["zeta1"] == "rim" and vols["ring"].degree == (2, 2, 1)
    assert vols["bar"].faces == {"xi0": "near", "xi1": "far", "eta0": "left", "eta1": "right",
                                 "zeta0": "bottom", "zeta1": "contact"}
    assert vols["cube"].faces["zeta1"] == "f"
    assert main(["geometry3d", str(spec)]) == 0
    assert "kept" in capsys.readouterr().out
    spec.write_text(SPEC.replace("x = [-2.0, 2.0]", "x = [-3.0, 2.0]"))
    assert main(["geometry3d", str(spec)]) == 2
    assert "demo-geometry.h5: body 'block': its shape or faces differ" in capsys.readouterr().err
    assert main(["geometry3d", str(spec), "--force", "--out", str(tmp_path)]) == 0
    _, vols = read_volumes(tmp_path / "demo-geometry.h5")
    assert np.array_equal(vols["block"].control_points, box([-3, 2], [-2, 2], [-1, 0]).control_points)


@pytest.mark.parametrize(("change", "message"), [
    (('shape = "box"', 'shape = "sphere"'), "body 'block': unknown shape 'sphere'"),
    (("x = [-2.0, 2.0]", "x = [-2.0, 2.0]\nradius = 1.0"), "body 'block': unknown key(s) ['radius']"),
    (("x = [-2.0, 2.0]", "x = [2.0, -2.0]"), "body 'block': x: need x[0] < x[1]"),
    (("r_in = 0.5", "r_in = 1.5"), "body 'dome': shell octant: need 0 < r_in < r_out"),
    (("angle = 90.0", "angle = 120.0"), "body 'ring': angle must be at most 90"),
    (("angles = [0.0, 60.0]", "angles = [0.0, 160.0]"), "at most 90 degrees per patch"),
    (("faces = { top = \"surface\" }", "faces = { lid = \"surface\" }"), "body 'block': unknown face(s) ['lid']"),
    (('file = "cube.g2"', 'file = "cube.g2"\nindex = 3'), "the .g2 file has 1 volume(s), no index 3"),
    (('zeta1 = "f"', 'zeta1 = "a"'), "body 'cube': the six faces need six different names"),
    (("z = [0.0, 3.0]", "z = [0.0, nan]"), "is not a finite number"),
    (('name = "dome"', 'name = "block"'), "two bodies are named 'block'"),
])
def test_bad_spec3d_exits_2_with_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                         change: tuple[str, str], message: str) -> None:
    assert change[0] in SPEC
    spec = _write(tmp_path, SPEC.replace(*change, 1))
    assert main(["geometry3d", str(spec)]) == 2
    err = capsys.readouterr().err
    assert message in err, err
    assert err.count("\n") == 1
    assert not (tmp_path / "demo-geometry.h5").exists()


def _body(case: Path, name: str) -> dict:
    """The &body group of ``name`` in a written case file."""
    bodies = f90nml.read(case)["body"]
    (group,) = [dict(b) for b in (bodies if isinstance(bodies, list) else [bodies]) if b["name"] == name]
    return group


def test_case_of_the_demo_is_a_template(tmp_path: Path) -> None:
    """Without load tables the case is a template (its comments show the groups to
    add); each body gets the default layout N2 (degree 2: the octant's exact degree,
    the lowest for a box and a degree-1 .g2 cube), 8 elements along its longest
    direction, no contact face, the default material."""
    spec = _write(tmp_path, SPEC)
    assert main(["geometry3d", str(spec)]) == 0
    case = tmp_path / "demo.nml"
    text = case.read_text()
    assert "This case has no loads yet" in text and "face = 'bottom'" in text
    nml = f90nml.read(case)
    assert nml["case"]["geometry"] == "demo-geometry.h5" and nml["case"]["n_bodies"] == 6
    assert "solver" not in nml and "dirichlet" not in nml
    block = _body(case, "block")
    assert {k: block[k] for k in ("basis", "degree_xi", "degree_eta", "degree_zeta", "nel_xi", "nel_eta",
                                  "nel_zeta", "contact_face", "layer_degree", "material")} == \
        {"basis": "nurbs", "degree_xi": 2, "degree_eta": 2, "degree_zeta": 2, "nel_xi": 8, "nel_eta": 8,
         "nel_zeta": 2, "contact_face": "", "layer_degree": 0, "material": "neo-hookean"}
    dome = _body(case, "dome")  # r 0.5 .. 1: arcs pi/2 long, 0.5 across
    assert [dome[f"nel_{d}"] for d in ("xi", "eta", "zeta")] == [8, 8, 3]
    assert _body(case, "cube")["degree_xi"] == 2


def test_direction_lengths_of_the_octant() -> None:
    """The longest edge per direction: the outer equator and meridian (pi/2 r_out; the
    pole's edges have length 0), the radial edges."""
    lengths = direction_lengths(shell_octant(1.0, 2.0), n=2000)
    np.testing.assert_allclose(lengths, [np.pi, np.pi, 1.0], rtol=1e-6)


LAYOUTS = '''[defaults]
layout = "NN3.1"
element_size = 0.5
material = "linear"
youngs_modulus = 2.0

[[body]]
name = "a"
shape = "box"
x = [0.0, 4.0]
y = [0.0, 2.0]
z = [0.0, 1.0]
nel = [4, 2, 1]
contact_face = "right"

[[body]]
name = "b"
shape = "box"
x = [10.0, 14.0]
y = [0.0, 2.0]
z = [0.0, 1.0]
faces = { top = "lid" }

[[body]]
name = "c"
shape = "cylinder_sector"
r_in = 1.0
r_out = 2.0
z = [20.0, 21.0]
layout = "N3"
elements = 4
youngs_modulus = 5.0

[[body]]
name = "d"
shape = "box"
x = [30.0, 31.0]
y = [0.0, 1.0]
z = [0.0, 1.0]
layout = "L1"
nel = [2, 2, 2]
'''


def test_layouts_elements_and_contact_faces(tmp_path: Path, voiga_bin: Path) -> None:
    """The &body of each layout: NN3.1 from [defaults] (bulk degree 2, a layer of degree
    3 elevated once) on the named contact face, or on the face zeta = 1 when none is
    named; nel given along the volume's own directions and written along the patch
    voiga turns (contact face 'right' = xi1: the case's xi, eta, zeta are the volume's
    eta, zeta, xi); element_size from [defaults]; N3 with the body's own elements (along
    the longest direction) before [defaults]' element_size; L1.
    voiga --check counts the DOFs of docs/formats.md's formula for them."""
    spec = tmp_path / "layouts.toml"
    spec.write_text(LAYOUTS)
    assert main(["geometry3d", str(spec)]) == 0
    case = tmp_path / "layouts.nml"
    a, b, c, d = (_body(case, n) for n in "abcd")
    assert (a["contact_face"], a["layer_degree"], a["layer_elevations"], a["degree_xi"]) == ("right", 3, 1, 2)
    assert [a[f"nel_{k}"] for k in ("xi", "eta", "zeta")] == [2, 1, 4]
    assert (b["contact_face"], [b[f"nel_{k}"] for k in ("xi", "eta", "zeta")]) == ("lid", [8, 4, 2])
    assert (c["degree_zeta"], c["layer_degree"], c["contact_face"], c["youngs_modulus"]) == (3, 0, "", 5.0)
    # the sector's outer arc (pi/2 * 2) is its longest edge: 4 elements along it
    assert [c[f"nel_{k}"] for k in ("xi", "eta", "zeta")] == [4, 2, 2]
    assert (d["basis"], d["degree_xi"], d["layer_degree"]) == ("linear", 1, 0)
    res = subprocess.run([str(voiga_bin), str(case), "--check"], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    # a: face directions n = 2 + (2, 1), across 2 + 4; layer m = 3 + 2 (1 + 1), 3 + 1 (1 + 1)
    #    DOFs = 3 (n1 n2 (n3 - 1) + m1 m2) = 3 (4 * 3 * 5 + 7 * 5)
    assert f"dofs a interface={3 * 7 * 5} bulk={3 * 4 * 3 * 5} " in res.stdout, res.stdout
    # b: on top (zeta1, unturned): nel (8, 4, 2): n = (10, 6, 4), m = (3 + 16, 3 + 8)
    assert f"dofs b interface={3 * 19 * 11} bulk={3 * 10 * 6 * 3} " in res.stdout, res.stdout
    assert f"dofs c interface=0 bulk={3 * 7 * 5 * 5} " in res.stdout, res.stdout
    assert f"dofs d interface=0 bulk={3 * 27} " in res.stdout, res.stdout


SIGMA, E, NU = 0.02, 2.0, 0.3

BOX = f'''scene = "pulled box"

[[body]]
name = "block"
shape = "box"
x = [0.0, 3.0]
y = [0.0, 2.0]
z = [0.0, 1.0]
layout = "NN3.1"
nel = [3, 2, 2]
material = "linear"
youngs_modulus = {E}
poisson_ratio = {NU}

[solver]
n_steps = 2

[[dirichlet]]
body = "block"
face = "left"
fix_x = true

[[dirichlet]]
body = "block"
face = "front"
fix_y = true

[[dirichlet]]
body = "block"
face = "bottom"
fix_z = true

[[pressure]]
body = "block"
face = "right"
p = {-SIGMA}

[output]
samples = 2
'''


def _last(result: Path) -> tuple[np.ndarray, np.ndarray, h5py.AttributeManager]:
    """``(control points (ncp, 3), displacement (ncp, 3) of the last step, root attrs)``."""
    with h5py.File(result) as f:
        last = max(f["steps"], key=int)
        return (f["bodies"][next(iter(f["bodies"]))]["control_points"][()],
                f["steps"][last]["displacement"][()].reshape(-1, 3), dict(f.attrs))


def test_pulled_box_runs_and_is_exact(tmp_path: Path, voiga_bin: Path) -> None:
    """The box pulled by a traction sigma on x = 3, held by its symmetry planes (NN3.1 on
    the top face, the default): u = sigma/E (x, -nu y, -nu z) at every control point to
    1e-12 (the exact field lies in the NURBS space)."""
    spec = tmp_path / "box.toml"
    spec.write_text(BOX)
    assert main(["geometry3d", str(spec)]) == 0
    assert _body(tmp_path / "box.nml", "block")["contact_face"] == "top"
    res = subprocess.run([str(voiga_bin), "box.nml", "--quiet"], cwd=tmp_path, capture_output=True, text=True,
                         timeout=300)
    assert res.returncode == 0, res.stderr
    x, u, attrs = _last(tmp_path / "box.h5")
    assert attrs["status"] == b"converged" and int(attrs["dimension"]) == 3
    assert np.abs(u - SIGMA / E * x * np.array([1.0, -NU, -NU])).max() < 1e-12
    with h5py.File(tmp_path / "box.h5") as f:
        assert f["steps/000002/fields/block/stress"].shape[1] == 6


def test_the_example_of_pre_md_runs(tmp_path: Path, voiga_bin: Path) -> None:
    """The spec of docs/pre.md, "3D bodies", as written: the exact uniaxial field (E = 2,
    nu = 0.3, a pull of 0.02 on x = 3; NN3.1 on the renamed top face)."""
    text = (REPO / "docs" / "pre.md").read_text()
    block = re.search(r"^```toml\n(.*?)^```", text[text.index("## 3D bodies"):], re.S | re.M)
    assert block is not None
    spec = tmp_path / "example.toml"
    spec.write_text(block.group(1))
    assert main(["geometry3d", str(spec)]) == 0
    body = _body(tmp_path / "example.nml", "block")
    assert (body["contact_face"], body["layer_degree"], body["layer_elevations"], body["nel_xi"]) == \
        ("surface", 3, 1, 6)
    res = subprocess.run([str(voiga_bin), "example.nml", "--quiet"], cwd=tmp_path, capture_output=True,
                         text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    x, u, _ = _last(tmp_path / "example.h5")
    assert np.abs(u - 0.02 / 2.0 * x * np.array([1.0, -0.3, -0.3])).max() < 1e-12


SHELL = '''scene = "thick sphere"

[[body]]
name = "shell"
shape = "shell_octant"
r_in = 1.0
r_out = 2.0
material = "linear"
youngs_modulus = 1000.0
poisson_ratio = 0.3

[[dirichlet]]
body = "shell"
face = "start"
fix_y = true

[[dirichlet]]
body = "shell"
face = "end"
fix_x = true

[[dirichlet]]
body = "shell"
face = "equator"
fix_z = true

[[pressure]]
body = "shell"
face = "inner"
p = 1.0
'''


@pytest.mark.parametrize("extra", ["", 'layout = "NN3"\ncontact_face = "inner"\n'])
def test_shell_octant_under_inner_pressure(tmp_path: Path, voiga_bin: Path, extra: str) -> None:
    """The thick spherical shell (docs/verification.md, "Solids") from a spec, N2 and
    NN3 on the inner face, 8 x 8 x 3 elements: it converges, and the radial displacement
    at the control points on the inner and outer spheres (the patch's corners and the
    pole, where the field interpolates them) is Lame's to 0.2 % (measured 0.12 % on the
    inner sphere and 0.08 % on the outer: the mesh's error)."""
    spec = tmp_path / "shell.toml"
    spec.write_text(SHELL.replace('poisson_ratio = 0.3\n', 'poisson_ratio = 0.3\n' + extra))
    assert main(["geometry3d", str(spec)]) == 0
    res = subprocess.run([str(voiga_bin), "shell.nml"], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    assert ("interface=363 bulk=1200" if extra else "interface=0 bulk=1500") in res.stdout
    x, u, attrs = _last(tmp_path / "shell.h5")
    assert attrs["status"] == b"converged"
    r = np.linalg.norm(x, axis=1)
    u_r = np.sum(u * x, axis=1) / r
    lame = LameShell(a=1.0, b=2.0, p=1.0, E=1000.0, nu=0.3)
    for radius in (1.0, 2.0):
        on = np.abs(r - radius) < 1e-12
        assert on.sum() >= 12
        np.testing.assert_allclose(u_r[on], lame.u_r(radius), rtol=2e-3)


def test_run_again_keeps_lists_and_forces(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Run again: kept when up to date; after the spec (n_steps, the box) and the case
    (an &output removed by hand) were edited every difference is listed, exit 2, and
    both files stay as they were; --force writes them and lists what it replaced."""
    spec = tmp_path / "box.toml"
    spec.write_text(BOX)
    assert main(["geometry3d", str(spec)]) == 0
    capsys.readouterr()
    assert main(["geometry3d", str(spec)]) == 0
    assert "kept" in capsys.readouterr().out
    case, geometry = tmp_path / "box.nml", tmp_path / "box-geometry.h5"
    assert "&output\n  samples = 2\n/\n" in case.read_text()
    case.write_text(case.read_text().replace("&output\n  samples = 2\n/\n", ""))
    spec.write_text(BOX.replace("n_steps = 2", "n_steps = 4").replace("x = [0.0, 3.0]", "x = [0.0, 4.0]"))
    before = case.read_bytes(), geometry.read_bytes()
    assert main(["geometry3d", str(spec)]) == 2
    err = capsys.readouterr().err
    assert "box.nml: &solver n_steps: 2 (case file) -> 4 (spec)" in err, err
    assert "box-geometry.h5: body 'block': its shape or faces differ" in err, err
    assert "box.nml: &output: only in the spec" in err, err
    assert "nothing written; --force" in err
    assert (case.read_bytes(), geometry.read_bytes()) == before
    assert main(["geometry3d", str(spec), "--force"]) == 0
    out = capsys.readouterr().out
    assert "replaced (case file or geometry -> spec):" in out and "n_steps: 2 (case file) -> 4 (spec)" in out
    assert f90nml.read(case)["solver"]["n_steps"] == 4
    assert main(["geometry3d", str(spec)]) == 0
    assert "kept" in capsys.readouterr().out


@pytest.mark.parametrize(("change", "message"), [
    (("[output]", "[[contact]]\nslave = \"block\"\nmaster = \"rigid\"\n[output]"),
     "[[contact]]: contact between solids is not implemented yet (issue 42)"),
    (('face = "right"', 'face = "lid"'),
     "[[pressure]] (1): body 'block' has no face 'lid' (faces: ['back', 'bottom', 'front', 'left', 'right', 'top'])"),
    (('face = "bottom"\nfix_z = true', 'face = "bottom"\nfix_y = true\nuz = 0.1'),
     "[[dirichlet]] (3): uz is given but fix_z is not true"),
    (('face = "bottom"\nfix_z = true', 'face = "bottom"'), "[[dirichlet]] (3): fixes nothing"),
    (('face = "bottom"\nfix_z = true', 'face = "bottom"\nfix_z = 1'), "[[dirichlet]] (3): fix_z must be true or false"),
    (('face = "bottom"\nfix_z = true', 'face = "bottom"\nfix_z = true\nuz = [0.1, 0.2]'),
     "[[dirichlet]] (3): uz needs one number per load phase (1 in [solver] n_steps)"),
    (('face = "front"\nfix_y = true', 'face = "left"\nfix_x = true'),
     "[[dirichlet]] (2): fix_x of face 'left' of 'block' is fixed by [[dirichlet]] (1) already"),
    (('face = "left"', 'edge = "left"'),
     "[[dirichlet]] (1): ['edge'] not variable(s) of &dirichlet (known: body, face, fix_x, fix_y, fix_z, ux, uy, uz"),
    (('body = "block"\nface = "front"', 'body = "box"\nface = "front"'),
     "[[dirichlet]] (2): body 'box' is not a [[body]] of the spec"),
    ((f"p = {-SIGMA}", "q = 1.0"), "[[pressure]] (1): ['q'] not variable(s) of &pressure"),
    ((f"p = {-SIGMA}", ""), "[[pressure]] (1): p is required"),
    (("n_steps = 2", "n_step = 2"), "[solver]: ['n_step'] not variable(s) of &solver"),
    (('layout = "NN3.1"', 'layout = "NN1"'), "body 'block': layout NN1: the layer degree 1 is below the bulk degree 2"),
    (('layout = "NN3.1"', 'layout = "Q2"'), "body 'block': unknown layout 'Q2'"),
    (("nel = [3, 2, 2]", "nel = [3, 2]"), "body 'block': nel must be three integers [n_xi, n_eta, n_zeta]"),
    (("nel = [3, 2, 2]", "elements = 4\nelement_size = 0.5"), "body 'block': give elements or element_size, not both"),
    (("nel = [3, 2, 2]", "element_size = 1e-6"), "body 'block': element_size 1e-06 gives more than 100000 elements"),
    (('layout = "NN3.1"', 'contact_face = "lid"'), "body 'block': contact_face 'lid' is not one of its faces"),
    (('layout = "NN3.1"', 'contact_edge = "top"'), "body 'block': unknown key(s) ['contact_edge']"),
    (('scene = "pulled box"', 'scene = "pulled box"\n[defaults]\nnel = [1, 1, 1]'),
     "[defaults]: unknown key(s) ['nel']"),
    (('scene = "pulled box"', 'scene = "pulled box"\n[[curve]]\nname = "c"'), "unknown key(s) or table(s) ['curve']"),
    (('scene = "pulled box"', 'scene = "pulled box"\n[defaults]\nelements = 4\nelement_size = 0.5'),
     "[defaults]: give elements or element_size, not both"),
])
def test_bad_case_tables_exit_2_with_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                             change: tuple[str, str], message: str) -> None:
    assert change[0] in BOX
    spec = tmp_path / "box.toml"
    spec.write_text(BOX.replace(*change, 1))
    assert main(["geometry3d", str(spec)]) == 2
    err = capsys.readouterr().err
    assert message in err, err
    assert err.count("\n") == 1
    assert not (tmp_path / "box-geometry.h5").exists() and not (tmp_path / "box.nml").exists()


def test_octant_layout_below_its_degree_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """N1 is exact for a box (allowed) but not for the octant's arcs."""
    spec = tmp_path / "shell.toml"
    spec.write_text(SHELL.replace('poisson_ratio = 0.3\n', 'poisson_ratio = 0.3\nlayout = "N1"\n'))
    assert main(["geometry3d", str(spec)]) == 2
    assert "body 'shell': layout N1: the degree must be 2 (the geometry's) to 20" in capsys.readouterr().err
    spec.write_text(BOX.replace('layout = "NN3.1"', 'layout = "N1"'))
    assert main(["geometry3d", str(spec)]) == 0
    assert _body(tmp_path / "shell.nml", "block")["degree_zeta"] == 1
