"""3D bodies (``pre.volume``, ``pre.solids``): the builders are exact (radii, volumes
against closed forms), agree with the same bodies built by ``splipy.volume_factory``
and with splipy's refinement of them, ``check_volume`` refuses what the solver cannot
use, and ``.g2`` and geometry files of volumes round-trip."""

from __future__ import annotations

import math
from pathlib import Path

import h5py
import numpy as np
import pytest
import splipy
from splipy import curve_factory, surface_factory, volume_factory

from pre.geometry import annular_sector, polygon, rectangle
from pre.h5io import read_volumes, write_geometry
from pre.nurbs import patch_to_splipy
from pre.solids import (
    box,
    cylinder_sector,
    extrude,
    read_g2_volumes,
    revolve,
    shell_octant,
    solid,
    write_volumes,
)
from pre.volume import (
    FACE_KEYS,
    Volume,
    check_volume,
    enclosed_volume,
    evaluate,
    jacobian,
    volume_from_splipy,
    volume_to_splipy,
)

RNG = np.random.default_rng(41)
U = RNG.random((3, 100))
"""100 random parameter triples (xi, eta, zeta) in [0, 1)^3."""


def _face(key: str, n: int = 21) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Parameters of an n x n grid on one face (corners and edges included)."""
    a, b = (g.ravel() for g in np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n)))
    fixed = np.full_like(a, 1.0 if key.endswith("1") else 0.0)
    return {"xi": (fixed, a, b), "eta": (a, fixed, b), "zeta": (a, b, fixed)}[key[:-1]]


def _splipy_at(spline: splipy.Volume, order: tuple[int, int, int], backwards: bool = False) -> np.ndarray:
    """splipy's points at the random parameters, its parameter k being ours ``order[k]``
    (our xi reversed: ``backwards``, a sweep of a clockwise patch)."""
    u = U.copy()
    if backwards:
        u[0] = 1.0 - u[0]
    return np.asarray(spline(*(u[d] for d in order), tensor=False))


# -- exactness -------------------------------------------------------------------------

def test_cylinder_sector_radii_are_exact() -> None:
    vol = cylinder_sector(0.5, 1.25, (20.0, 95.0), (-1.0, 2.0), centre=(1.0, 2.0), faces={"outer": "rim"})
    check_volume("c", vol)
    assert vol.faces == {"xi0": "start", "xi1": "end", "eta0": "bottom", "eta1": "top",
                         "zeta0": "inner", "zeta1": "rim"}
    for key, r in (("zeta0", 0.5), ("zeta1", 1.25)):
        x = evaluate(vol, *_face(key))
        assert np.abs(np.hypot(x[:, 0] - 1.0, x[:, 1] - 2.0) - r).max() < 1e-12
    x = evaluate(vol, *U)
    rho = np.hypot(x[:, 0] - 1.0, x[:, 1] - 2.0)
    # zeta is the radius fraction (the radial direction is linear, the weights constant in it)
    assert np.abs(rho - (0.5 + 0.75 * U[2])).max() < 1e-12
    assert np.abs(x[:, 2] - (-1.0 + 3.0 * U[1])).max() < 1e-12
    angle = np.degrees(np.arctan2(x[:, 1] - 2.0, x[:, 0] - 1.0))
    assert angle.min() >= 20.0 - 1e-9 and angle.max() <= 95.0 + 1e-9


def test_shell_octant_radii_are_exact() -> None:
    c = np.array([0.5, -1.0, 2.0])
    vol = shell_octant(0.8, 1.5, centre=c)
    check_volume("s", vol)  # its pole face collapses onto the axis: allowed
    for key, r in (("zeta0", 0.8), ("zeta1", 1.5)):
        x = evaluate(vol, *_face(key))
        assert np.abs(np.linalg.norm(x - c, axis=1) - r).max() < 1e-12
    x = evaluate(vol, *U)
    assert np.abs(np.linalg.norm(x - c, axis=1) - (0.8 + 0.7 * U[2])).max() < 1e-12
    assert (x - c).min() > -1e-12  # the octant x, y, z >= centre
    pole = evaluate(vol, *_face("eta1"))
    assert np.abs(pole[:, :2] - c[:2]).max() < 1e-12


@pytest.mark.parametrize(("vol", "exact"), [
    (box([-1.0, 2.0], [0.5, 1.0], [0.0, 4.0]), 3.0 * 0.5 * 4.0),
    (cylinder_sector(0.5, 1.25, (20.0, 95.0), (-1.0, 2.0)), math.radians(75.0) / 2 * (1.25**2 - 0.25) * 3.0),
    (cylinder_sector(1.0, 3.0, (0.0, 90.0), (0.0, 0.5)), math.pi / 4 * 8.0 * 0.5),
    (shell_octant(0.8, 1.5), math.pi / 6 * (1.5**3 - 0.8**3)),
    (shell_octant(1.0, 2.0, centre=(3.0, 4.0, 5.0)), math.pi / 6 * 7.0),
])
def test_volumes_by_gauss_quadrature(vol: Volume, exact: float) -> None:
    check_volume("v", vol)
    assert abs(enclosed_volume(vol, 16) - exact) < 1e-10 * exact


def test_swept_volumes() -> None:
    """An annular sector extruded and revolved: the exact volumes (Pappus for the
    revolution: area times the path of its centroid)."""
    sector = annular_sector((0.0, 0.0), 1.0, 2.0, [0.0, 90.0], {"outer": "rim"})
    e = extrude(sector, (1.0, 3.5))
    check_volume("e", e)
    assert e.degree == (1, 2, 1) and e.shape == (2, 3, 2)
    # the sector runs clockwise (xi along the arcs, eta outwards): swept from z1 to z0
    assert e.faces == {"xi0": "front", "xi1": "back", "eta0": "start", "eta1": "end",
                       "zeta0": "inner", "zeta1": "rim"}
    assert np.abs(evaluate(e, *_face("xi0"))[:, 2] - 3.5).max() < 1e-12
    assert abs(enclosed_volume(e) - math.pi / 4 * 3.0 * 2.5) < 1e-10
    r = revolve(rectangle([1.0, 3.0], [0.0, 2.0]), 90.0)
    check_volume("r", r)
    assert r.degree == (2, 1, 1) and r.shape == (2, 2, 3)
    assert abs(enclosed_volume(r) - math.pi / 4 * (9.0 - 1.0) * 2.0) < 1e-10
    x = evaluate(r, *_face("xi1"))  # the rectangle turned by 90 degrees into the plane x = 0
    assert np.abs(x[:, 0]).max() < 1e-12 and x[:, 2].min() > 1.0 - 1e-12


def test_clockwise_patch_and_axis_edge() -> None:
    """A clockwise patch is swept right-handed (the sweep reversed, the patch's edges
    where they were); a patch with an edge on the axis revolves into a volume with a
    collapsed face."""
    rect = rectangle([0.0, 1.0], [0.0, 2.0])
    flipped = type(rect)(rect.degree, rect.knots_xi, rect.knots_eta, rect.control_points[:, ::-1].copy(),
                         rect.weights, {**rect.edges, "xi0": "right", "xi1": "left"})
    e = extrude(flipped, (0.0, 1.0))
    check_volume("e", e)
    assert e.faces["eta0"] == "right" and e.faces["eta1"] == "left"
    assert e.faces["xi0"] == "front" and e.faces["xi1"] == "back"
    cone = revolve(rect, 45.0, ends=("a", "b"))  # the left side x = 0 lies on the y axis
    check_volume("cone", cone)
    assert abs(enclosed_volume(cone) - math.radians(45.0) / 2 * 1.0 * 2.0) < 1e-10
    with pytest.raises(ValueError, match="both sides of the axis"):
        revolve(rectangle([-1.0, 1.0], [0.0, 1.0]), 30.0)
    with pytest.raises(ValueError, match="at most 90 degrees"):
        revolve(rect, 120.0)
    with pytest.raises(ValueError, match="at most 90 degrees"):
        cylinder_sector(1.0, 2.0, (0.0, 100.0))
    with pytest.raises(ValueError, match="end faces"):
        extrude(rect, (0.0, 1.0), ends=("top", "lid"))


# -- splipy ----------------------------------------------------------------------------

def test_evaluation_matches_splipy() -> None:
    """Our numpy evaluation and Jacobian against splipy's of the converted volume."""
    vol = shell_octant(0.7, 1.9, centre=(0.1, 0.2, 0.3))
    s = volume_to_splipy(vol)
    x, jac = jacobian(vol, *U)
    assert np.abs(x - np.asarray(s(*U, tensor=False))).max() < 1e-12
    for j, d in enumerate(((1, 0, 0), (0, 1, 0), (0, 0, 1))):
        assert np.abs(jac[:, :, j] - np.asarray(s.derivative(*U, d=d, tensor=False))).max() < 1e-12
    back = volume_from_splipy(s, vol.faces)
    for a, b in zip((back.control_points, back.weights, *back.knots),
                    (vol.control_points, vol.weights, *vol.knots), strict=True):
        assert np.array_equal(a, b) or np.abs(a - b).max() < 1e-15


def test_box_matches_splipy() -> None:
    vol = box([1.0, 3.0], [-2.0, 0.0], [0.5, 1.5])
    cube = volume_factory.cube(size=1.0)
    cube.scale(2.0, 2.0, 1.0)
    cube.translate((1.0, -2.0, 0.5))
    assert np.abs(evaluate(vol, *U) - _splipy_at(cube, (0, 1, 2))).max() < 1e-12


def test_cylinder_sector_matches_splipy() -> None:
    a0, a1, c = 20.0, 95.0, (1.0, 2.0, 0.0)
    vol = cylinder_sector(0.5, 1.25, (a0, a1), (-1.0, 2.0), centre=c[:2])
    xaxis = (math.cos(math.radians(a0)), math.sin(math.radians(a0)), 0.0)
    arcs = [curve_factory.circle_segment(math.radians(a1 - a0), r, center=c, xaxis=xaxis) for r in (0.5, 1.25)]
    s = volume_factory.extrude(surface_factory.edge_curves(*arcs), (0.0, 0.0, 3.0))
    s.translate((0.0, 0.0, -1.0))
    s.reparam()
    # splipy's (u, v, w) = (angle, radius, z) = our (xi, zeta, eta)
    assert np.abs(evaluate(vol, *U) - _splipy_at(s, (0, 2, 1))).max() < 1e-12


def test_shell_octant_matches_splipy() -> None:
    vol = shell_octant(0.8, 1.5)
    arcs = [curve_factory.circle_segment(math.pi / 2, r) for r in (0.8, 1.5)]
    section = surface_factory.edge_curves(*arcs)  # the quarter annulus in the plane z = 0
    section.set_dimension(3)
    section.rotate(math.pi / 2, (1.0, 0.0, 0.0))  # into the plane y = 0, its arcs rising to +z
    s = volume_factory.revolve(section, math.pi / 2, axis=(0.0, 0.0, 1.0))
    s.reparam()
    # splipy's (u, v, w) = (latitude, radius, longitude) = our (eta, zeta, xi)
    assert np.abs(evaluate(vol, *U) - _splipy_at(s, (1, 2, 0))).max() < 1e-12


SECTIONS = {
    "sector": annular_sector((2.0, 0.5), 0.5, 1.5, [-60.0, 30.0]),
    "polygon": polygon([[1.0, 0.0], [3.0, 0.2], [3.5, 2.0], [1.2, 1.5]], arcs={1: 2.0}),
}


@pytest.mark.parametrize("section", SECTIONS)
def test_extrude_matches_splipy(section: str) -> None:
    patch = SECTIONS[section]
    vol = extrude(patch, (-0.5, 1.0))
    check_volume(section, vol)
    s = volume_factory.extrude(patch_to_splipy(patch), (0.0, 0.0, 1.5))
    s.translate((0.0, 0.0, -0.5))
    # splipy's (u, v, w) = (patch xi, patch eta, z) = our (eta, zeta, xi)
    backwards = vol.faces["xi0"] == "front"
    assert np.abs(evaluate(vol, *U) - _splipy_at(s, (1, 2, 0), backwards)).max() < 1e-12


@pytest.mark.parametrize("section", SECTIONS)
@pytest.mark.parametrize(("angle", "point", "direction"),
                         [(90.0, (0.0, 0.0), (0.0, 1.0)), (60.0, (-1.0, 0.0), (1.0, 1.0)),
                          (30.0, (0.0, 3.0), (1.0, 0.0))])
def test_revolve_matches_splipy(section: str, angle: float, point: tuple[float, float],
                                direction: tuple[float, float]) -> None:
    patch = SECTIONS[section]
    vol = revolve(patch, angle, point, direction)
    check_volume(section, vol)
    a = np.array([*direction, 0.0]) / np.linalg.norm(direction)
    v = patch.control_points - point
    if np.all(a[0] * v[..., 1] - a[1] * v[..., 0] <= 0):  # ours rises towards +z: about -a
        a = -a
    s = patch_to_splipy(patch)
    s.set_dimension(3)
    s.translate((-point[0], -point[1], 0.0))
    s = volume_factory.revolve(s, math.radians(angle), axis=tuple(a))
    s.translate((point[0], point[1], 0.0))
    s.reparam()
    # splipy's (u, v, w) = (patch xi, patch eta, angle) = our (eta, zeta, xi)
    backwards = vol.faces["xi0"] == "turned"
    assert np.abs(evaluate(vol, *U) - _splipy_at(s, (1, 2, 0), backwards)).max() < 1e-12


@pytest.mark.parametrize("vol", [shell_octant(0.8, 1.5), cylinder_sector(1.0, 2.0, (10.0, 80.0)),
                                 revolve(SECTIONS["polygon"], 75.0)])
def test_splipy_refinement_keeps_the_map(vol: Volume) -> None:
    """splipy's knot insertion and order elevation of our volume, converted back,
    evaluate (with our code) as before, and check and measure alike."""
    s = volume_to_splipy(vol)
    s.raise_order(1, 1, 1)
    s.insert_knot([0.3, 0.7], 0)
    s.insert_knot([0.5], 1)
    s.insert_knot([0.25, 0.25], 2)
    fine = volume_from_splipy(s, vol.faces)
    assert fine.degree == tuple(p + 1 for p in vol.degree)
    assert np.abs(evaluate(fine, *U) - evaluate(vol, *U)).max() < 1e-12
    check_volume("fine", fine)
    assert abs(enclosed_volume(fine) - enclosed_volume(vol)) < 1e-10 * enclosed_volume(vol)


# -- checks ----------------------------------------------------------------------------

def test_check_volume_refuses_a_folded_volume() -> None:
    vol = box([0.0, 1.0], [0.0, 1.0], [0.0, 1.0])
    cp = vol.control_points.copy()
    cp[0, 0, [0, 1]] = cp[0, 0, [1, 0]]  # swap two control points: det J changes sign
    with pytest.raises(ValueError, match=r"body 'folded': the volume folds over itself or degenerates: "
                                         r"det J = -?[0-9.e-]+ .* at \(xi, eta, zeta\) = \(0.0625, 0.0625, 0.0625\)"):
        check_volume("folded", Volume(vol.degree, *vol.knots, cp, vol.weights, vol.faces))


def test_check_volume_refuses_an_inside_out_volume() -> None:
    vol = cylinder_sector(1.0, 2.0)
    mirrored = vol.control_points * [1.0, 1.0, -1.0]  # a mirror image: det J < 0 everywhere
    with pytest.raises(ValueError, match="body 'mirror': the volume is inside out"):
        check_volume("mirror", Volume(vol.degree, *vol.knots, mirrored, vol.weights, vol.faces))


def test_check_volume_refuses_a_flat_or_pinched_volume() -> None:
    vol = box([0.0, 1.0], [0.0, 1.0], [0.0, 1.0])
    cp = vol.control_points.copy()
    cp[1, :, :, 2] = 0.0
    with pytest.raises(ValueError, match="flat"):
        check_volume("flat", Volume(vol.degree, *vol.knots, cp, vol.weights, vol.faces))


@pytest.mark.parametrize(("change", "cause"), [
    (lambda v: v.faces.update(zeta1="top" * 11), "six different names"),
    (lambda v: v.faces.update(zeta1="bottom"), "six different names"),
    (lambda v: v.faces.pop("xi0"), "six different names"),
    (lambda v: v.weights.__setitem__((0, 0, 0), 0.0), "weights must be finite and positive"),
    (lambda v: v.control_points.__setitem__((0, 0, 0, 0), np.nan), "control points must be finite"),
    (lambda v: setattr(v, "knots_eta", np.array([0.0, 0.0, 0.5, 0.5])), "must span"),
    (lambda v: setattr(v, "knots_zeta", np.array([0.0, 0.5, 1.0, 1.0])), "must be open"),
])
def test_check_volume_names_the_cause(change: object, cause: str) -> None:
    vol = box([0.0, 1.0], [0.0, 1.0], [0.0, 1.0])
    change(vol)  # type: ignore[operator]
    with pytest.raises(ValueError, match=f"body 'b'.*{cause}"):
        check_volume("b", vol)


# -- files -----------------------------------------------------------------------------

FACES = dict(zip(FACE_KEYS, ("w", "e", "s", "n", "down", "up"), strict=True))


def test_g2_round_trip(tmp_path: Path) -> None:
    from splipy.io import G2

    vol = revolve(SECTIONS["sector"], 60.0)
    spline = volume_to_splipy(vol)
    spline.reparam((0.0, 2.0), (1.0, 4.0), (0.0, 0.5))  # solid() rescales to [0, 1]
    with G2(str(tmp_path / "v.g2")) as f:
        f.write([patch_to_splipy(SECTIONS["sector"]), spline])
    objs = read_g2_volumes(tmp_path / "v.g2")
    assert len(objs) == 1
    back = solid(objs[0], vol.faces)
    assert back.degree == vol.degree and back.faces == vol.faces
    for a, b in zip((back.control_points, back.weights, *back.knots),
                    (vol.control_points, vol.weights, *vol.knots), strict=True):
        assert a.shape == b.shape and np.abs(a - b).max() < 1e-14
    with pytest.raises(ValueError, match="missing"):
        solid(objs[0], {"xi0": "a"})


def test_geometry_file_of_volumes(tmp_path: Path) -> None:
    bodies = {"block": box([0.0, 2.0], [0.0, 1.0], [-1.0, 0.0]),
              "shell": shell_octant(0.5, 1.0, centre=(1.0, 0.5, 1.0)),
              "splipy": volume_factory.cube(0.5)}
    path = write_volumes(tmp_path / "g.h5", bodies, scene="three", faces={"splipy": FACES})
    with h5py.File(path, "r") as f:
        assert f.attrs["dimension"] == 3 and f.attrs["dimension"].dtype == np.int32
        assert f.attrs["scene"] == b"three"
        assert list(f["bodies"]) == ["block", "shell", "splipy"]
        g = f["bodies/shell"]
        assert g["degree"].dtype == np.int32 and list(g["degree"][()]) == [2, 2, 1]
        assert g["knots_xi"].shape == (6,) and g["knots_eta"].shape == (6,) and g["knots_zeta"].shape == (4,)
        assert g["control_points"].shape == (2, 3, 3, 3) and g["weights"].shape == (2, 3, 3)
        assert g["control_points"].dtype == np.float64
        assert [g.attrs[f"face_{k}"].decode() for k in FACE_KEYS] == \
            ["start", "end", "equator", "pole", "inner", "outer"]
        # xi fastest in memory: control point [k, j, i] at zeta k, eta j, xi i
        assert np.allclose(g["control_points"][1, 0, 2], [1.0, 1.5, 1.0])  # outer, equator, longitude 90
        assert "curves" not in f
    attrs, back = read_volumes(path)
    assert attrs["dimension"] == 3
    assert back["splipy"].faces == FACES
    assert np.array_equal(back["shell"].control_points, bodies["shell"].control_points)
    with pytest.raises(ValueError, match="one dimension"):
        write_geometry(tmp_path / "mixed.h5", "x", {"a": rectangle([0, 1], [0, 1]),  # type: ignore[dict-item]
                                                   "b": box([0, 1], [0, 1], [0, 1])})
    with pytest.raises(ValueError, match="inside out"):
        write_volumes(tmp_path / "bad.h5", {"m": Volume((1, 1, 1), *bodies["block"].knots,
                                                        bodies["block"].control_points[::-1].copy(),
                                                        bodies["block"].weights, bodies["block"].faces)})
    assert not (tmp_path / "bad.h5").exists()


def test_2d_files_have_no_dimension(tmp_path: Path) -> None:
    write_geometry(tmp_path / "g.h5", "flat", {"r": rectangle([0, 1], [0, 1])})
    with h5py.File(tmp_path / "g.h5", "r") as f:
        assert "dimension" not in f.attrs and set(f.attrs) == {"scene", "units", "generator"}
