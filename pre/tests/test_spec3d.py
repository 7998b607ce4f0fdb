"""``python -m pre geometry3d``: a spec of 3D bodies -> a geometry file of volumes;
bad specs end with one line and exit code 2."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from splipy import volume_factory
from splipy.io import G2

from pre.__main__ import main
from pre.h5io import read_volumes
from pre.solids import box, shell_octant

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
    assert "differs" in capsys.readouterr().err
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
