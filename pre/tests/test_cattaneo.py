"""The Cattaneo-Mindlin cases of ``python -m pre cattaneo``."""
from __future__ import annotations

import math
from pathlib import Path

import f90nml
import numpy as np
import pytest

from pre.cattaneo import R_IN, CattaneoCaseError, CattaneoScene, arc_knots, cattaneo_case, half_annulus, write_cattaneo
from pre.nurbs import evaluate_patch


@pytest.mark.parametrize("start, centre", [(180.0, (0.0, 0.0)), (0.0, (0.0, -2.0))])
def test_half_annulus_is_exact(start: float, centre: tuple[float, float]) -> None:
    """Both arcs of the half annulus lie on their circles to round-off, over 180 degrees."""
    patch = half_annulus(centre, 1.0, start)
    t = np.linspace(0.0, 1.0, 601)
    for eta, radius in ((1.0, 1.0), (0.0, R_IN)):
        pts = evaluate_patch(patch, t, np.full_like(t, eta)).reshape(-1, 2)
        assert np.allclose(np.linalg.norm(pts - centre, axis=1), radius, atol=1e-14)
    ends = evaluate_patch(patch, np.array([0.0, 0.5, 1.0]), np.ones(3)).reshape(-1, 2)
    angle = np.arctan2(ends[:, 1] - centre[1], ends[:, 0] - centre[0])
    want = np.radians([start, start + 90.0, start + 180.0])
    assert np.allclose(np.cos(angle), np.cos(want), atol=1e-14)
    assert np.allclose(np.sin(angle), np.sin(want), atol=1e-14)


def test_arc_elements_of_equal_length_over_the_zone() -> None:
    """Around the lowest point the arc elements are h long (to round-off) over
    |x| <= 1.5 a, symmetric about xi = 1/2, and grow by at most 1.2 beyond."""
    h, zone = 0.004, 0.12
    knots = np.array(arc_knots(1.0, h, zone))
    assert {1 / 3, 2 / 3} <= set(knots)           # the arcs' joins
    assert np.all(np.diff(knots) > 0) and 0.0 < knots[0] and knots[-1] < 1.0
    assert np.allclose(knots, 1.0 - knots[::-1], atol=1e-14)
    patch = half_annulus((0.0, 0.0), 1.0, 180.0)
    pts = evaluate_patch(patch, knots, np.ones_like(knots)).reshape(-1, 2)
    angle = np.unwrap(np.arctan2(pts[:, 1], pts[:, 0]))
    length = np.abs(np.diff(angle))          # arc length on the unit circle
    inside = np.abs(pts[:-1, 0] + pts[1:, 0]) / 2 < zone - h
    assert inside.sum() >= 2 * int(zone / h) - 2
    assert np.allclose(length[inside], h, rtol=1e-12)
    growth = length[1:] / length[:-1]
    assert np.all((growth < 1.2 * (1 + 1e-9)) & (growth > 1 / 1.2 / (1 + 1e-9)))


def test_case_groups() -> None:
    """Friction per phase when the press's differs; each master's bodies and loads."""
    groups, bodies = cattaneo_case(CattaneoScene(press_friction=0.0), "x.h5")
    assert groups["contact"][0]["friction"] == [0.0, 0.3]
    assert groups["contact"][0]["rigid_ux"] == [0.0, 3.5e-3] and list(bodies) == ["cylinder"]
    assert groups["solver"]["n_steps"] == [20, 20]
    groups, bodies = cattaneo_case(CattaneoScene(master="mirror"), "x.h5")
    assert groups["contact"][0]["friction"] == 0.3 and groups["contact"][0]["master"] == "mirror"
    assert list(bodies) == ["cylinder", "mirror"] and groups["case"]["n_bodies"] == 2
    assert [d["ux"] for d in groups["dirichlet"] if d["body"] == "mirror"] == [[0.0, 3.5e-3]] * 2
    groups, bodies = cattaneo_case(CattaneoScene(master="block", method="mortar"), "x.h5")
    assert list(bodies) == ["cylinder", "block"] and groups["contact"][0]["method"] == "mortar"


@pytest.mark.parametrize("change, words", [
    ({"poisson_ratio": 0.5}, "poisson ratio"),
    ({"master": "wall"}, "master"),
    ({"friction": 0.0}, "friction"),
    ({"press_friction": -0.1}, "press friction"),
    ({"indentation": math.nan}, "indentation"),
    ({"elements_per_a": 1.0}, "elements per a"),
    ({"layout": "NX2"}, "NX2"),
])
def test_bad_values_refused(change: dict, words: str) -> None:
    with pytest.raises(CattaneoCaseError, match=words):
        cattaneo_case(CattaneoScene(**change), "x.h5")


def test_written_case_reads_back_and_is_not_overwritten(tmp_path: Path) -> None:
    case = write_cattaneo(CattaneoScene(master="mirror", elements_per_a=10), tmp_path)
    nml = f90nml.read(case)
    assert nml["case"]["geometry"] == "mirror-NN2.2-a10-geometry.h5"
    assert (tmp_path / nml["case"]["geometry"]).is_file()
    before = case.read_bytes()
    with pytest.raises(CattaneoCaseError, match="--force"):
        write_cattaneo(CattaneoScene(master="mirror", elements_per_a=10, friction=0.5), tmp_path)
    assert case.read_bytes() == before
    write_cattaneo(CattaneoScene(master="mirror", elements_per_a=10, friction=0.5), tmp_path, force=True)
    assert f90nml.read(case)["contact"]["friction"] == 0.5
