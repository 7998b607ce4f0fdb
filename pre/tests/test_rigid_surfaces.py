"""Rigid surfaces of solid cases (pre/rigid_surfaces.py): the sphere cap is exact and
points out of the ball, the flat patch is the plane, and both land in the geometry file
where voiga reads them."""
from __future__ import annotations

import h5py
import numpy as np
import pytest

from pre.rigid_surfaces import add_surfaces, flat, sphere_cap
from pre.solids import box, write_volumes


def test_sphere_cap_is_exact_and_faces_outward() -> None:
    s = sphere_cap(2.0, (0.5, 0.5, 3.0), half_angle=40.0)
    rng = np.random.default_rng(1)
    for u, v in rng.uniform(0.0, 1.0, (50, 2)):
        assert abs(np.linalg.norm(s.evaluate(u, v) - [0.5, 0.5, 3.0]) - 2.0) < 1e-13
    assert np.allclose(s.evaluate(0.5, 0.5), [0.5, 0.5, 1.0], atol=1e-14)   # the lowest point
    h = 1e-6
    a1 = (s.evaluate(0.5 + h, 0.5) - s.evaluate(0.5 - h, 0.5)) / (2 * h)
    a2 = (s.evaluate(0.5, 0.5 + h) - s.evaluate(0.5, 0.5 - h)) / (2 * h)
    n = np.cross(a1, a2)
    assert n[2] < 0 and abs(n[0]) + abs(n[1]) < 1e-6 * abs(n[2])   # out of the ball, down
    with pytest.raises(ValueError, match="half_angle"):
        sphere_cap(1.0, (0, 0, 0), half_angle=60.0)


def test_flat_and_written(tmp_path) -> None:
    path = tmp_path / "geometry.h5"
    write_volumes(path, {"block": box((0.0, 1.0), (0.0, 1.0), (-1.0, 0.0))})
    add_surfaces(str(path), {"floor": flat((-1.0, 2.0), (-1.0, 2.0), 0.5), "ball": sphere_cap(1.0, (0, 0, 1))})
    with h5py.File(path) as f:
        g = f["surfaces/floor"]
        assert list(g["degree"][()]) == [1, 1] and g["control_points"].shape == (2, 2, 3)
        assert f["surfaces/ball/weights"].shape == (3, 3)
    with pytest.raises(ValueError, match="already"):
        add_surfaces(str(path), {"floor": flat((0, 1), (0, 1), 0.0)})
