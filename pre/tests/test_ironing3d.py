"""The 3D ironing scene (``python -m pre ironing3d``, ``pre/ironing3d.py``): the die is
the sphere cap touching the slab's top at the start, the meshes refine the band of the
path, the cases name the faces and surface the geometry file has, and bad values are
refused with their cause."""

from __future__ import annotations

from pathlib import Path

import f90nml
import h5py
import numpy as np
import pytest

from pre.__main__ import main
from pre.hertz import HertzCaseError
from pre.ironing3d import BAND, DIE, LAYOUTS, MESHES, START, Iron, case_dofs, iron_case, slab_knots
from pre.rigid_surfaces import RigidSurface


def test_the_die_touches_the_slab_at_the_start(tmp_path: Path) -> None:
    assert main(["ironing3d", str(tmp_path), "--mesh", "m1", "--layout", "N2"]) == 0
    with h5py.File(tmp_path / "geometry.h5") as f:
        assert int(f.attrs["dimension"]) == 3 and "slab" in f["bodies"]
        g = f[f"surfaces/{DIE}"]
        die = RigidSurface(tuple(int(d) for d in g["degree"][()]), g["knots_xi"][()], g["knots_eta"][()],
                           g["control_points"][()], g["weights"][()])
    assert np.allclose(die.evaluate(0.5, 0.5), [START, 0.0, 0.0], atol=1e-14)   # its lowest point
    rng = np.random.default_rng(3)
    assert min(die.evaluate(u, v)[2] for u, v in rng.uniform(0.0, 1.0, (50, 2))) > 0.0


@pytest.mark.parametrize("mesh", list(MESHES))
def test_the_meshes_refine_the_band(mesh: str) -> None:
    k = slab_knots(mesh)
    nx, fine, rest, nz = MESHES[mesh]
    assert len(k["knots_xi"]) == nx - 1 and np.allclose(np.diff([0, *k["knots_xi"], 1]), 1 / nx)
    eta = np.diff([0.0, *k["knots_eta"], 1.0])
    assert len(eta) == fine + rest and np.allclose(eta[:fine], BAND / fine)
    zeta = np.diff([0.0, *k["knots_zeta"], 1.0])
    assert len(zeta) == nz and np.all(np.diff(zeta) <= 1e-12)          # graded toward the top
    assert zeta[-1] == pytest.approx(BAND / fine)


def test_finer_meshes_and_layers_have_more_dofs() -> None:
    iron = Iron()
    for layout in LAYOUTS:
        dofs = [case_dofs(iron, m, layout)["total"] for m in MESHES]
        assert dofs == sorted(dofs)
    assert case_dofs(iron, "m1", "N2")["total"] == 3 * 18 * 5 * 5


def test_the_case_names_the_die_and_the_phases(tmp_path: Path) -> None:
    assert main(["ironing3d", str(tmp_path), "--mesh", "m2", "--layout", "NN2.2", "--friction", "0.2",
                 "--steps", "5", "20"]) == 0
    nml = f90nml.read(tmp_path / "m2-NN2.2.nml")
    c = nml["contact"]
    assert (c["method"], c["rigid_surface"], c["friction"]) == ("gpts", DIE, 0.2)
    assert "n_gauss" not in c                       # voiga's default: the layer's degree + 1
    assert list(c["rigid_ux"]) == [0.0, 2.0] and list(c["rigid_uz"]) == [-0.1, -0.1]
    assert list(nml["solver"]["n_steps"]) == [5, 20]
    assert nml["body"]["layer_degree"] == 2 and nml["body"]["layer_elevations"] == 2
    assert nml["body"]["contact_face"] == "top"
    assert iron_case(Iron(), "m1", "N2", n_gauss=2)["contact"][0]["n_gauss"] == 2
    assert main(["ironing3d", str(tmp_path / "m"), "--method", "mortar"]) == 0
    assert f90nml.read(tmp_path / "m" / "m1-N2.nml")["contact"]["method"] == "mortar"


def test_existing_files_are_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["ironing3d", str(tmp_path)]) == 0
    assert main(["ironing3d", str(tmp_path)]) == 2
    assert "exist" in capsys.readouterr().err
    assert main(["ironing3d", str(tmp_path), "--force"]) == 0


@pytest.mark.parametrize(("iron", "mesh", "message"), [
    (Iron(indentation=0.3), "m1", "indentation"),
    (Iron(friction=-0.1), "m1", "friction"),
    (Iron(), "m9", "mesh"),
])
def test_bad_values_are_refused(iron: Iron, mesh: str, message: str) -> None:
    with pytest.raises(HertzCaseError, match=message):
        iron_case(iron, mesh, "N2")


def test_only_the_face_methods_are_written() -> None:
    """'gpts' and 'mortar' carry friction on faces; voiga refuses the others there."""
    assert iron_case(Iron(), "m1", "N2", method="mortar")["contact"][0]["method"] == "mortar"
    with pytest.raises(HertzCaseError, match="method 'alm'"):
        iron_case(Iron(), "m1", "N2", method="alm")
