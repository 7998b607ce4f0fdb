"""A solid (a volume of the geometry file) through the command line: `&body` with
`contact_face` and the zeta keys, `&dirichlet` and `&pressure` on faces with `fix_z`
and `uz`; the result file of dimension 3 holds the exact uniaxial-tension field, which
lies in the NURBS space (docs/formats.md, "Solids"). Bad 3D input is refused with its
cause named."""
from __future__ import annotations

import subprocess
from pathlib import Path

import h5py
import numpy as np

from pre.solids import box, write_volumes

SIGMA, E, NU = 0.02, 2.0, 0.3

CASE = """&case
  title = 'box', geometry = 'geometry.h5', output = 'box.h5', n_bodies = 1
/
&body
  name = 'block', material = '{material}', youngs_modulus = 2.0, poisson_ratio = 0.3,
  degree_xi = 2, degree_eta = 2, degree_zeta = 2, nel_xi = 3, nel_eta = 2, nel_zeta = 2,
  {contact} = 'top', layer_degree = 3, layer_elevations = 1
/
&solver
  n_steps = 2
  linear_solver = '{solver}'
/
&dirichlet
  body = 'block', face = 'left', fix_x = .true.
/
&dirichlet
  body = 'block', face = 'front', fix_y = .true.
/
&dirichlet
  body = 'block', face = 'bottom', fix_z = .true., uz = {uz}
/
&pressure
  body = 'block', face = 'right', p = {p}
/
"""


def solid_case(tmp: Path, material: str = "linear", contact: str = "contact_face", solver: str = "direct",
               uz: str = "0.0", p: str = f"{-SIGMA}") -> Path:
    """The box [0, 3] x [0, 2] x [0, 1] pulled by a traction on x = 3, held by its
    symmetry planes x = 0, y = 0, z = 0 (NN3.1 on the top face)."""
    write_volumes(tmp / "geometry.h5", {"block": box((0.0, 3.0), (0.0, 2.0), (0.0, 1.0))})
    case = tmp / "box.nml"
    case.write_text(CASE.format(material=material, contact=contact, solver=solver, uz=uz, p=p))
    return case


def run(voiga_bin: Path, case: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(voiga_bin), str(case), "--quiet", *args], capture_output=True, text=True,
                          timeout=300)


def test_uniaxial_tension_is_exact(voiga_bin: Path, tmp_path: Path) -> None:
    res = run(voiga_bin, solid_case(tmp_path))
    assert res.returncode == 0, res.stderr
    with h5py.File(tmp_path / "box.h5") as f:
        assert int(f.attrs["dimension"]) == 3 and f.attrs["status"] == b"converged"
        x = f["bodies/block/control_points"][()]
        u = f["steps/000002/displacement"][()].reshape(-1, 3)
        assert x.shape == u.shape and x.shape[1] == 3
        exact = SIGMA / E * x * np.array([1.0, -NU, -NU])
        assert np.abs(u - exact).max() < 1e-12
        # the face groups and the elements' three parameter ranges
        assert set(f["bodies/block/faces"]) == {"left", "right", "front", "back", "bottom", "top"}
        assert f["bodies/block/elements/range"].shape == (12, 6)
        # the reactions of the three supports balance the traction (sum over the face)
        fx = f["steps/000002/reactions"][0, 0]
        assert abs(fx + SIGMA * 2.0 * 1.0) < 1e-12


def test_fields_of_a_solid(voiga_bin: Path, tmp_path: Path) -> None:
    """&output on a solid: six components per sample (xx yy zz xy yz xz), samples^3
    per element with their (xi, eta, zeta); uniform uniaxial stress and strain."""
    case = solid_case(tmp_path)
    case.write_text(case.read_text() + "&output\n  samples = 2\n/\n")
    res = run(voiga_bin, case)
    assert res.returncode == 0, res.stderr
    with h5py.File(tmp_path / "box.h5") as f:
        g = f["steps/000002/fields/block"]
        assert g.attrs["components"] == b"xx yy zz xy yz xz"
        stress, strain = g["stress"][()], g["strain"][()]
        assert stress.shape == (12 * 8, 6) and g["zeta"].shape == (12 * 8,)
        assert np.abs(stress - [SIGMA, 0, 0, 0, 0, 0]).max() < 1e-12
        assert np.abs(strain - SIGMA / E * np.array([1, -NU, -NU, 0, 0, 0])).max() < 1e-12
        assert np.abs(g["von_mises"][()] - SIGMA).max() < 1e-12


def test_prescribed_uz_moves_the_face(voiga_bin: Path, tmp_path: Path) -> None:
    """uz on the bottom face: the whole box translates by it (a rigid motion on top
    of the tension)."""
    res = run(voiga_bin, solid_case(tmp_path, uz="0.05"))
    assert res.returncode == 0, res.stderr
    with h5py.File(tmp_path / "box.h5") as f:
        x = f["bodies/block/control_points"][()]
        u = f["steps/000002/displacement"][()].reshape(-1, 3)
        exact = SIGMA / E * x * np.array([1.0, -NU, -NU]) + np.array([0.0, 0.0, 0.05])
        assert np.abs(u - exact).max() < 1e-12


def test_restart_of_a_solid(voiga_bin: Path, tmp_path: Path) -> None:
    """A Neo-Hookean box pulled by 30 % of E in 6 steps, cut after step 3 and continued
    with --restart: the same displacements as the run that was not cut."""
    import shutil

    case = solid_case(tmp_path, material="neo-hookean", p="-0.6")
    case.write_text(case.read_text().replace("n_steps = 2", "n_steps = 6"))
    assert run(voiga_bin, case).returncode == 0
    full, partial = tmp_path / "full.h5", tmp_path / "box.h5"
    shutil.copy(partial, full)
    with h5py.File(partial, "r+") as f:
        for k in list(f["steps"]):
            if int(k) > 3:
                del f["steps"][k]
        f.attrs["n_steps_done"] = np.int32(3)
        f.attrs["status"] = np.bytes_("interrupted")
    res = run(voiga_bin, case, "--restart", str(partial))
    assert res.returncode == 0, res.stderr
    with h5py.File(full) as a, h5py.File(partial) as b:
        assert b.attrs["status"] == b"converged" and int(b.attrs["n_steps_done"]) == 6
        for k in a["steps"]:
            np.testing.assert_allclose(b["steps"][k]["displacement"][()], a["steps"][k]["displacement"][()],
                                       rtol=0, atol=1e-12, err_msg=k)
        # a large stretch: the last step's axial displacement at x = 3 is well beyond small strain
        assert a["steps/000006/displacement"][()].reshape(-1, 3)[:, 0].max() > 0.3


def refused(res: subprocess.CompletedProcess, *words: str) -> None:
    assert res.returncode == 2, (res.returncode, res.stderr)
    for word in words:
        assert word in res.stderr, (word, res.stderr)


def test_contact_edge_on_a_solid_refused(voiga_bin: Path, tmp_path: Path) -> None:
    refused(run(voiga_bin, solid_case(tmp_path, contact="contact_edge"), "--check"),
            "contact_edge = 'top'", "use contact_face")


def test_multigrid_equals_direct(voiga_bin: Path, tmp_path: Path) -> None:
    """linear_solver = 'multigrid' on a Neo-Hookean box of 12 x 8 x 6 elements with its
    bottom face clamped (a field that is not in the space) and a VO layer on top: two
    levels, the same displacements as the direct solver to 1e-8 of the largest."""
    out = {}
    for solver in ("direct", "multigrid"):
        (tmp_path / solver).mkdir()
        case = solid_case(tmp_path / solver, material="neo-hookean", solver=solver, p="-0.2")
        text = case.read_text().replace("nel_xi = 3, nel_eta = 2, nel_zeta = 2",
                                        "nel_xi = 12, nel_eta = 8, nel_zeta = 6")
        text = text.replace("face = 'bottom', fix_z", "face = 'bottom', fix_x = .true., fix_y = .true., fix_z")
        case.write_text(text)
        res = run(voiga_bin, case)
        assert res.returncode == 0, res.stderr
        out[solver] = tmp_path / solver / "box.h5"
    with h5py.File(out["direct"]) as fd, h5py.File(out["multigrid"]) as fm:
        assert fm.attrs["linear_solver"] == b"multigrid" and fm.attrs["status"] == b"converged"
        assert len(fm["multigrid_level_dofs"][()]) == 2
        assert list(fd["steps"]) == list(fm["steps"]) == ["000001", "000002"]
        for name in fd["steps"]:
            ud, um = fd["steps"][name]["displacement"][()], fm["steps"][name]["displacement"][()]
            assert np.abs(um - ud).max() <= 1e-8 * np.abs(ud).max(), name
            assert fm["steps"][name].attrs["linear_iterations"] > 0


def test_unknown_face_refused(voiga_bin: Path, tmp_path: Path) -> None:
    case = solid_case(tmp_path)
    case.write_text(case.read_text().replace("face = 'right'", "face = 'lid'"))
    refused(run(voiga_bin, case, "--check"), "no face named 'lid'")


def test_fix_z_on_a_plane_body_refused(voiga_bin: Path, tmp_path: Path) -> None:
    from test_outputs import block

    case = block(tmp_path)
    case.write_text(case.read_text().replace("fix_y = .true.,", "fix_y = .true., fix_z = .true.,"))
    refused(run(voiga_bin, case, "--check"), "fix_z on the plane body 'slab'")
