"""Volumes (three-dimensional bodies) in the geometry file: read and checked as plane
patches are (shapes, knots, weights, names, a map that keeps its orientation). The
case here has a contact pair, which solids do not have yet, so a valid volume is then
refused for that (docs/formats.md, "Solids"): what is tested is that a bad volume is
refused for its own fault first. A solid case that runs: test_solid_case.py."""
from __future__ import annotations

import subprocess
from pathlib import Path

import h5py
import numpy as np

from test_outputs import block


def ring_block() -> dict[str, np.ndarray]:
    """A quarter of a thick ring (r 1..2, degree 1 x 2) extruded to z in [0, 1]:
    the datasets of a volume record, h5py order (n_zeta, n_eta, n_xi, 3)."""
    arc = np.array([[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    warc = np.array([1.0, 1.0 / np.sqrt(2.0), 1.0])
    cp = np.zeros((2, 3, 2, 3))
    w = np.zeros((2, 3, 2))
    for k in range(2):
        for j in range(3):
            for i in range(2):
                cp[k, j, i] = [*(float(i + 1) * arc[j]), float(k)]
                w[k, j, i] = warc[j]
    return {
        "degree": np.array([1, 2, 1], dtype=np.int32),
        "knots_xi": np.array([0.0, 0.0, 1.0, 1.0]),
        "knots_eta": np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0]),
        "knots_zeta": np.array([0.0, 0.0, 1.0, 1.0]),
        "control_points": cp,
        "weights": w,
    }


def volume_case(tmp: Path, edit=None, faces: dict[str, str] | None = None) -> Path:
    """The block case with its body 'slab' replaced by the ring block (after `edit`
    changes the datasets)."""
    case = block(tmp)
    data = ring_block()
    if edit is not None:
        edit(data)
    with h5py.File(tmp / "geometry.h5", "r+") as f:
        del f["bodies/slab"]
        g = f.create_group("bodies/slab")
        for key, value in data.items():
            g[key] = value
        for key, value in (faces or {}).items():
            g.attrs[key] = value
    return case


def check(voiga_bin: Path, case: Path) -> subprocess.CompletedProcess:
    return subprocess.run([str(voiga_bin), str(case), "--check"], capture_output=True, text=True,
                          timeout=120)


#: The block case's &contact is a plane one (a rigid line): on a solid it is refused
#: after the geometry's checks, so this message means that the volume passed them.
MIXED = "rigid_point needs 3 components"


def test_valid_volume_with_plane_contact_is_refused(voiga_bin: Path, tmp_path: Path) -> None:
    res = check(voiga_bin, volume_case(tmp_path, faces={"face_zeta1": "top"}))
    assert res.returncode == 2, res.stderr
    assert MIXED in res.stderr


def test_folded_volume_refused(voiga_bin: Path, tmp_path: Path) -> None:
    """A corner pulled past the opposite one: det J changes sign inside."""
    def fold(d: dict[str, np.ndarray]) -> None:
        cp = d["control_points"]
        cp[0, 0, 0] = cp[-1, -1, -1] + 0.5 * (cp[-1, -1, -1] - cp[0, 0, 0])
    res = check(voiga_bin, volume_case(tmp_path, fold))
    assert res.returncode == 2, res.stderr
    assert "folds over itself" in res.stderr and "(xi, eta, zeta) = (" in res.stderr
    assert "of 512 sample points" in res.stderr   # one knot span, 8 x 8 x 8


def test_inside_out_volume_is_valid(voiga_bin: Path, tmp_path: Path) -> None:
    """A left-handed parametrization (z reversed) keeps one sign of det J: it is a
    body, read like the right-handed one."""
    def mirror(d: dict[str, np.ndarray]) -> None:
        d["control_points"][..., 2] = 1.0 - d["control_points"][..., 2]
    res = check(voiga_bin, volume_case(tmp_path, mirror))
    assert res.returncode == 2 and MIXED in res.stderr, res.stderr


def test_volume_datasets_checked(voiga_bin: Path, tmp_path: Path) -> None:
    cases = {
        "shape": (lambda d: d.update(control_points=d["control_points"][..., :2]),
                  "control_points must have shape (n_zeta, n_eta, n_xi, 3)"),
        "weights": (lambda d: d["weights"].__setitem__((0, 0, 0), -1.0), "weights must be finite and > 0"),
        "knots": (lambda d: d.update(knots_zeta=np.array([0.0, 0.5, 1.0, 1.0])), "knots_zeta"),
        "degree": (lambda d: d.update(degree=np.array([1, 2, 30], dtype=np.int32)), "between 1 and 20"),
        "finite": (lambda d: d["control_points"].__setitem__((1, 1, 1, 0), np.nan),
                   "control_points must be finite"),
    }
    for name, (edit, message) in cases.items():
        sub = tmp_path / name
        sub.mkdir()
        res = check(voiga_bin, volume_case(sub, edit))
        assert res.returncode == 2, (name, res.stderr)
        assert message in res.stderr and "'slab'" in res.stderr, (name, res.stderr)


def test_face_names_checked(voiga_bin: Path, tmp_path: Path) -> None:
    res = check(voiga_bin, volume_case(tmp_path, faces={"face_xi0": "side", "face_zeta1": "side"}))
    assert res.returncode == 2 and "face name 'side' is used twice" in res.stderr, res.stderr


def test_pre_volumes_are_valid_for_voiga(voiga_bin: Path, tmp_path: Path) -> None:
    """Every body `pre` builds (box, cylinder sector, shell octant with its collapsed
    pole) passes voiga's checks: refused only for the contact pair (a plane one)."""
    from pre.solids import box, cylinder_sector, shell_octant, write_volumes

    bodies = {"slab": box((0, 2), (0, 1), (0, 0.5)), "sector": cylinder_sector(1.0, 2.0, z=(0.0, 1.0)),
              "shell": shell_octant(0.8, 1.0)}
    for name, body in bodies.items():
        sub = tmp_path / name
        sub.mkdir()
        case = block(sub)
        write_volumes(sub / "geometry.h5", {"slab": body})
        res = check(voiga_bin, case)
        assert res.returncode == 2, (name, res.stderr)
        assert MIXED in res.stderr and "folds" not in res.stderr, (name, res.stderr)
