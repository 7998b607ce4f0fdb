"""The 3D Cattaneo-Mindlin scene run end to end (``pre cattaneo3d``, voiga, ``post
cattaneo3d``; docs/cattaneo3d.md): the frictionless press leaves no tangential traction,
the shear's force grows and stays below mu P, and the stick zone shrinks as Q grows, as
Cattaneo-Mindlin's does. The accuracy against Cattaneo-Mindlin on finer meshes is
measured in docs/cattaneo3d.md (too slow for the tests)."""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

from post.cattaneo3d import Cattaneo3dError, cattaneo3d_comparison
from post.reader import read_result

PRESS, SHEAR = 3, 4


@pytest.fixture(scope="module")
def sheared(voiga_bin: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("cattaneo3d")
    subprocess.run(["python3", "-m", "pre", "cattaneo3d", str(out), "--mesh", "m1", "--layout", "N2",
                    "--steps", str(PRESS), str(SHEAR)], check=True, capture_output=True)
    res = subprocess.run([str(voiga_bin), str(out / "m1-N2.nml"), "--quiet"], capture_output=True, text=True,
                         timeout=600)
    assert res.returncode == 0, res.stderr
    return out / "m1-N2.h5"


def test_press_without_friction_leaves_no_traction(sheared: Path) -> None:
    result = read_result(sheared)
    c = result.steps[PRESS - 1].contact[0]
    assert c.attrs["method"].strip() == "mortar"   # the default on solids, with friction too
    assert np.abs(c.p_t_nominal).max() == 0.0
    assert abs(c.force[0]) < 1e-12 * abs(c.force[2])   # the half model is symmetric about x = 0
    with pytest.raises(Cattaneo3dError, match="no friction"):
        cattaneo3d_comparison(result, step=PRESS)


def test_shear_grows_and_the_stick_zone_shrinks(sheared: Path) -> None:
    result = read_result(sheared)
    steps = [cattaneo3d_comparison(result, step=PRESS + k) for k in range(1, SHEAR + 1)]
    ratios = [s.ratio for s in steps]
    assert all(0.0 < a < b < 1.0 for a, b in zip(ratios, ratios[1:], strict=False))
    radii = [s.stick_radius for s in steps]
    assert all(a > b for a, b in zip(radii, radii[1:], strict=False))
    assert all(abs(s.cattaneo_radius - (1 - s.ratio) ** (1 / 3)) < 1e-12 for s in steps)
    last = steps[-1]
    assert last.hertz.symmetry == 2 and abs(last.friction - 0.3) < 1e-15
    # the traction along Q integrates to the pair's tangential force
    c = result.steps[-1].contact[0]
    q = c.p_t_nominal.reshape(len(c.state), -1) @ last.direction
    assert abs(2 * np.sum(c.area_ref * q) - last.tangential_force) < 1e-9 * last.tangential_force


def test_cli(sheared: Path) -> None:
    res = subprocess.run(["python3", "-m", "post", "cattaneo3d", str(sheared)], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    assert "Q/(mu P)" in res.stdout and "stick radius" in res.stdout
    res = subprocess.run(["python3", "-m", "post", "cattaneo3d", str(sheared), "--step", str(PRESS)],
                         capture_output=True, text=True)
    assert res.returncode == 2 and "no friction" in res.stderr
