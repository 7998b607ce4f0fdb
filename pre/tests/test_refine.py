"""splipy refinement: the DOF tables of docs/benchmarks.md, geometry invariance,
knot structure, orientation and the dump schema."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

from pre.__main__ import main
from pre.cases import all_cases
from pre.h5io import read_geometry
from pre.nurbs import eta1_curve, evaluate_curve, evaluate_patch, unique_knots
from pre.refine import discretize_body, discretize_case, orient, read_dump, write_dump
from pre.scenes import scene_bodies

# Table 2 (ironing, m1): die (interface, bulk, total), slab (...), total.
TABLE2 = {
    "N2": ((18, 36, 54), (20, 60, 80), 134),
    "N4": ((26, 52, 78), (24, 72, 96), 174),
    "N6": ((34, 68, 102), (28, 84, 112), 214),
    "NN4": ((26, 36, 62), (24, 60, 84), 146),
    "NN6": ((34, 36, 70), (28, 60, 88), 158),  # paper prints die interface 24: a typo
    "NN2.1": ((30, 36, 66), (36, 60, 96), 162),
    "NN2.2": ((42, 36, 78), (52, 60, 112), 190),
    "NN2.3": ((54, 36, 90), (68, 60, 128), 218),
}

# Table 4 (hertz): mesh -> layout -> (interface, bulk, total).
_T4 = {
    "m2": ((38, 40, 76, 112), (1824, 1920, 1920, 1920), (1862, 1960, 1996, 2032)),
    "m3": ((74, 76, 148, 220), (3552, 3648, 3648, 3648), (3626, 3724, 3796, 3868)),
    "m4": ((146, 148, 292, 436), (7008, 7104, 7104, 7104), (7154, 7252, 7396, 7540)),
    "m5": ((290, 292, 580, 868), (13920, 14016, 14016, 14016), (14210, 14308, 14596, 14884)),
}
TABLE4 = [("m1", "L1", 20, 960, 980), ("m1", "N2", 22, 1056, 1078),
          ("m1", "NN2.1", 40, 1056, 1096), ("m1", "NN2.2", 58, 1056, 1114),
          ("m6", "N2", 580, 27840, 28420)]
for _m, (_i, _b, _t) in _T4.items():
    for _k, _lay in enumerate(("L1", "N2", "NN2.1", "NN2.2")):
        TABLE4.append((_m, _lay, _i[_k], _b[_k], _t[_k]))


@pytest.mark.parametrize("layout", list(TABLE2))
def test_table2_ironing_m1(generated: Path, layout: str) -> None:
    disc = discretize_case(generated / f"ironing/m1-{layout}.nml")
    die, slab, total = TABLE2[layout]
    for name, want in (("die", die), ("slab", slab)):
        b = disc.bodies[name]
        assert (b.interface_dofs, b.bulk_dofs, b.total_dofs) == want, name
    assert sum(b.total_dofs for b in disc.bodies.values()) == total


def test_table2_n4_die_topology(generated: Path) -> None:
    """docs/benchmarks.md: the N4 die is 13 x 3 control points."""
    die = discretize_case(generated / "ironing/m1-N4.nml").bodies["die"]
    assert die.bulk.shape == (3, 13) and die.bulk.degree == (4, 2)


@pytest.mark.parametrize("mesh, layout, interface, bulk, total", TABLE4)
def test_table4_hertz(generated: Path, mesh: str, layout: str, interface: int, bulk: int,
                      total: int) -> None:
    b = discretize_case(generated / f"hertz/{mesh}-{layout}.nml").bodies["cylinder"]
    assert (b.interface_dofs, b.bulk_dofs, b.total_dofs) == (interface, bulk, total)
    assert b.bulk.shape[0] == 49  # fixed 49 control points across the radius


def test_geometry_invariance_all_cases(generated: Path) -> None:
    """Every committed study: the refined bulk and the layer curve reproduce
    the coarse geometry at 1000 random points to 1e-12; L1 nodes lie on it."""
    rng = np.random.default_rng(7)
    xi, eta = rng.random(1000), rng.random(1000)
    xi[:4], eta[:4] = [0, 1, 0, 1], [0, 0, 1, 1]
    coarse_by_scene = {}
    for rel in all_cases():
        scene = rel.split("/")[0]
        if scene not in coarse_by_scene:
            coarse_by_scene[scene] = read_geometry(generated / scene / "geometry.h5")[1]
        disc = discretize_case(generated / rel)
        for name, b in disc.bodies.items():
            coarse = coarse_by_scene[scene][name]
            if b.bulk.degree == (1, 1) and coarse.degree != (1, 1):  # L1
                cp = b.bulk.control_points
                gx, ge = unique_knots(b.bulk.knots_xi), unique_knots(b.bulk.knots_eta)
                X, E = np.meshgrid(gx, ge)
                exact = evaluate_patch(coarse, X.ravel(), E.ravel()).reshape(cp.shape)
                assert np.abs(cp - exact).max() < 1e-12, rel
                assert np.all(b.bulk.weights == 1.0)
                continue
            err = np.abs(evaluate_patch(b.bulk, xi, eta) - evaluate_patch(coarse, xi, eta)).max()
            assert err < 1e-12, (rel, name, err)
            if b.layer is not None:
                edge = evaluate_curve(eta1_curve(coarse), xi)
                assert np.abs(evaluate_curve(b.layer, xi) - edge).max() < 1e-12, (rel, name)
                # end control points are the bulk's corner control points
                np.testing.assert_allclose(b.layer.control_points[[0, -1]],
                                           b.bulk.control_points[-1, [0, -1]], atol=1e-13)


def _multiplicities(knots: np.ndarray) -> dict[float, int]:
    vals, counts = np.unique(knots, return_counts=True)
    return dict(zip(vals.tolist(), counts.tolist(), strict=True))


def test_knot_structure(generated: Path) -> None:
    """k-refinement: new knots single (C^(p-1)); coarse C0 knot 0.5 keeps C0;
    NNq.k layers repeat every knot k more times."""
    n2 = discretize_case(generated / "ironing/m1-N2.nml").bodies["die"].bulk
    m = _multiplicities(n2.knots_xi)
    assert m[0.5] == 2 and m[0.0] == 3 and all(m[k] == 1 for k in m if k not in (0.0, 0.5, 1.0))
    n6 = discretize_case(generated / "ironing/m1-N6.nml").bodies["die"].bulk
    m = _multiplicities(n6.knots_xi)
    assert n6.degree == (6, 2) and m[0.5] == 6 and m[0.0] == 7
    assert sum(1 for k in m if m[k] == 1) == 4
    for layout, q, k in (("NN4", 4, 0), ("NN2.1", 2, 1), ("NN2.2", 2, 2), ("NN2.3", 2, 3)):
        disc = discretize_case(generated / f"ironing/m1-{layout}.nml")
        for body, coarse_mid in (("die", True), ("slab", False)):
            layer = disc.bodies[body].layer
            assert layer.degree == q + k
            m = _multiplicities(layer.knots)
            assert m[0.0] == m[1.0] == q + k + 1
            for kn, mult in m.items():
                if kn in (0.0, 1.0):
                    continue
                want = q + k if (coarse_mid and kn == 0.5) else 1 + k
                assert mult == want, (layout, body, kn)
            # the layer's breakpoints are the bulk's
            np.testing.assert_array_equal(unique_knots(layer.knots),
                                          unique_knots(disc.bodies[body].bulk.knots_xi))


def test_hertz_explicit_knots_used(generated: Path) -> None:
    import f90nml

    nml = f90nml.read(str(generated / "hertz/m2-NN2.1.nml"))
    b = discretize_case(generated / "hertz/m2-NN2.1.nml").bodies["cylinder"]
    np.testing.assert_array_equal(unique_knots(b.bulk.knots_xi)[1:-1], nml["body"]["knots_xi"])
    np.testing.assert_array_equal(unique_knots(b.bulk.knots_eta)[1:-1], nml["body"]["knots_eta"])


@pytest.mark.parametrize("edge", ["symmetry", "top", "inner", "outer"])
def test_orientation(edge: str) -> None:
    """Any edge can be the contact edge: after orient() it is eta = 1, the
    map is the same surface, and orientation (sign of det J) is kept."""
    coarse = scene_bodies("hertz")["cylinder"]
    body = {"name": "cylinder", "basis": "nurbs", "degree_xi": 3, "degree_eta": 2,
            "nel_xi": 4, "nel_eta": 3, "contact_edge": edge, "layer_degree": 4,
            "layer_elevations": 1}
    b = discretize_body(coarse, body)
    key = coarse.edge_key(edge)
    # (xi', eta') of the oriented patch -> (xi, eta) of the coarse one
    back = {"eta1": lambda u, v: (u, v), "eta0": lambda u, v: (1 - u, 1 - v),
            "xi1": lambda u, v: (v, 1 - u), "xi0": lambda u, v: (1 - v, u)}[key]
    rng = np.random.default_rng(1)
    u, v = rng.random(1000), rng.random(1000)
    u[:2], v[:2] = 0.3, 1.0
    assert np.abs(evaluate_patch(b.bulk, u, v) - evaluate_patch(coarse, *back(u, v))).max() < 1e-12
    t = np.linspace(0, 1, 200)
    got = evaluate_patch(b.bulk, t, np.ones_like(t))
    assert np.abs(evaluate_curve(b.layer, t) - got).max() < 1e-12
    assert b.bulk.edges["eta1"] == edge
    # orientation kept: compare signs of det J
    o = orient(coarse, key)
    rng = np.random.default_rng(0)
    u, v = rng.uniform(0.1, 0.9, 50), rng.uniform(0.1, 0.9, 50)
    h = 1e-6

    def det(p, u, v):
        du = evaluate_patch(p, u + h, v) - evaluate_patch(p, u - h, v)
        dv = evaluate_patch(p, u, v + h) - evaluate_patch(p, u, v - h)
        return du[:, 0] * dv[:, 1] - du[:, 1] * dv[:, 0]
    assert np.all(np.sign(det(o, u, v)) == np.sign(det(coarse, u, v)))
    assert np.all(np.sign(det(b.bulk, u, v)) == np.sign(det(coarse, u, v)))


def test_no_contact_edge() -> None:
    coarse = scene_bodies("ironing")["slab"]
    b = discretize_body(coarse, {"name": "slab", "degree_xi": 2, "degree_eta": 2, "nel_xi": 2,
                                 "nel_eta": 2, "contact_edge": "", "layer_degree": 0})
    assert b.interface_dofs == 0 and b.bulk_dofs == 2 * 16 and b.layer is None


@pytest.mark.parametrize("body, msg", [
    ({"knots_xi": [0.5, 0.2]}, "increasing"), ({"knots_xi": [0.0, 0.2]}, "inside"),
    ({"degree_xi": 1}, "below"), ({"basis": "linear"}, "linear"),
    ({"layer_degree": 1}, "below"), ({"basis": "bezier"}, "basis")])
def test_rejects(body: dict, msg: str) -> None:
    coarse = scene_bodies("hertz")["cylinder"]
    full = {"name": "cylinder", "basis": "nurbs", "degree_xi": 2, "degree_eta": 2,
            "contact_edge": "outer", "layer_degree": 0, "layer_elevations": 0, **body}
    with pytest.raises(ValueError, match=msg):
        discretize_body(coarse, full)


def test_dump_schema_and_cli(generated: Path, tmp_path: Path) -> None:
    out = tmp_path / "d.h5"
    assert main(["refine", str(generated / "ironing/m1-NN2.2.nml"), "-o", str(out)]) == 0
    with h5py.File(out, "r") as f:
        assert {"title", "scene", "mesh", "layout"} <= set(f.attrs)
        die = f["bodies/die"]
        assert die.attrs["interface_dofs"] == 42 and die.attrs["bulk_dofs"] == 36
        assert die.attrs["total_dofs"] == 78
        bulk = die["bulk"]
        assert bulk["degree"].dtype == np.int32 and bulk["degree"].shape == (2,)
        assert bulk["control_points"].shape == (3, 9, 2) and bulk["weights"].shape == (3, 9)
        assert bulk["knots_xi"].shape == (12,) and bulk["knots_eta"].shape == (6,)
        layer = die["layer"]
        assert layer["degree"].dtype == np.int32 and layer["degree"][()].tolist() == [4]
        n = layer["weights"].shape[0]
        assert n == 21 and layer["control_points"].shape == (n, 2) and layer["knots"].shape == (n + 5,)
        assert "layer" not in f["bodies"] and set(f["bodies"]) == {"die", "slab"}
    back = read_dump(out)
    ref = discretize_case(generated / "ironing/m1-NN2.2.nml")
    for name in ("die", "slab"):
        np.testing.assert_array_equal(back.bodies[name].bulk.control_points,
                                      ref.bodies[name].bulk.control_points)
        np.testing.assert_array_equal(back.bodies[name].layer.knots, ref.bodies[name].layer.knots)
    # N2: no layer group
    write_dump(tmp_path / "n2.h5", discretize_case(generated / "ironing/m1-N2.nml"))
    with h5py.File(tmp_path / "n2.h5", "r") as f:
        assert "layer" not in f["bodies/die"]
