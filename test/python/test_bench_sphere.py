"""Section 7 of the bench (bench/ccx_sphere.py): the C3D20 mesh of the shell octant, the
20-node shape functions, the error measure, the CalculiX input and .dat reader. CalculiX
runs only in the last test, on the smallest mesh, and only when ``ccx`` is installed."""
from __future__ import annotations

import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import REPO

sys.path.insert(0, str(REPO))
from bench import ccx_sphere as cs  # noqa: E402
from post.lame import LameShell, hooke  # noqa: E402

OCTANT = 7 * np.pi / 6  # volume of the octant of a = 1, b = 2


@pytest.fixture(scope="module", params=[(2, 2), (3, 2)], ids=["2x2x2", "3x3x2"])
def mesh(request) -> dict:
    return cs.sphere_mesh(*request.param)


def test_shape_functions_partition_unity_and_delta() -> None:
    """N_i(xi_j) = delta_ij; sum N = 1 and sum dN = 0 anywhere; dN matches central
    differences of N."""
    N, _ = cs.shape20(cs.NODES20)
    assert np.array_equal(N, np.eye(20))
    q = np.random.default_rng(1).uniform(-1, 1, size=(50, 3))
    N, dN = cs.shape20(q)
    assert np.allclose(N.sum(axis=1), 1.0, rtol=0, atol=1e-14)
    assert np.abs(dN.sum(axis=1)).max() <= 1e-14
    h = 1e-6
    for d in range(3):
        e = np.zeros(3)
        e[d] = h
        fd = (cs.shape20(q + e)[0] - cs.shape20(q - e)[0]) / (2 * h)
        assert np.abs(fd - dN[:, :, d]).max() <= 1e-9  # truncation h^2, round-off 1e-16 / h


def test_shape_functions_interpolate_quadratics() -> None:
    """Every quadratic polynomial of (xi, eta, zeta) and its gradient are reproduced."""
    rng = np.random.default_rng(2)
    q = rng.uniform(-1, 1, size=(30, 3))
    N, dN = cs.shape20(q)
    for _ in range(5):
        c0, c1, C = rng.normal(), rng.normal(size=3), rng.normal(size=(3, 3))
        C = C + C.T

        def f(x, c0=c0, c1=c1, C=C):
            return c0 + x @ c1 + 0.5 * np.einsum("gi,ij,gj->g", x, C, x)

        assert np.allclose(N @ f(cs.NODES20), f(q), rtol=0, atol=1e-13)
        grad = np.einsum("n,gnd->gd", f(cs.NODES20), dN)
        assert np.allclose(grad, c1 + q @ C, rtol=0, atol=1e-13)


def test_nodes_on_the_spheres(mesh: dict) -> None:
    """Every node lies on one of the 2m + 1 spheres of the radial grid; the nodes of the
    elements' faces 1-2-3-4 (corners and mid-sides) of the first radial layer on r = a,
    of faces 5-6-7-8 of the last on r = b, to 1e-12."""
    x, conn = mesh["nodes"], mesh["elements"]
    n, m = mesh["n"], mesh["m"]
    r = np.linalg.norm(x, axis=1)
    grid = 1.0 + np.arange(2 * m + 1) / (2 * m)
    assert np.abs(r[:, None] - grid[None, :]).min(axis=1).max() <= 1e-12
    layer = np.tile(np.arange(m), 3 * n * n)
    bottom = conn[layer == 0][:, [0, 1, 2, 3, 8, 9, 10, 11]] - 1
    top = conn[layer == m - 1][:, [4, 5, 6, 7, 12, 13, 14, 15]] - 1
    assert np.abs(r[bottom] - 1.0).max() <= 1e-12 and np.abs(r[top] - 2.0).max() <= 1e-12
    assert np.array_equal(np.unique(bottom) + 1, mesh["sets"]["NINNER"])
    assert np.array_equal(np.unique(top) + 1, mesh["sets"]["NOUTER"])
    assert (x >= 0).all()


def test_nodes_merged_and_used(mesh: dict) -> None:
    """No two nodes coincide; every node belongs to an element; the count is that of three
    blocks with their common faces merged."""
    from scipy.spatial import cKDTree
    x, conn = mesh["nodes"], mesh["elements"]
    n, m = mesh["n"], mesh["m"]
    assert cKDTree(x).query(x, k=2)[0][:, 1].min() > 1e-3
    assert np.array_equal(np.unique(conn), np.arange(1, len(x) + 1))
    # the (2n+1)^2 (2m+1) grid less its points with two or three odd indices
    block = (2 * n + 1) ** 2 * (2 * m + 1) - n * n * (2 * m + 1) - 2 * n * (n + 1) * m
    face = (2 * n + 1) * (2 * m + 1) - n * m
    assert len(x) == 3 * block - 3 * face + (2 * m + 1)  # the diagonal's nodes: in all three


def test_symmetry_sets(mesh: dict) -> None:
    """NX0, NY0, NZ0: exactly the nodes with x, y, z = 0 (exact zeros), each set the
    quarter annulus of two blocks' faces."""
    x = mesh["nodes"]
    n, m = mesh["n"], mesh["m"]
    face = (2 * n + 1) * (2 * m + 1) - n * m
    for d, name in enumerate(("NX0", "NY0", "NZ0")):
        ids = mesh["sets"][name]
        assert np.array_equal(ids, np.flatnonzero(np.abs(x[:, d]) <= 1e-12) + 1)
        assert (x[ids - 1, d] == 0.0).all()
        assert len(ids) == 2 * face - (2 * m + 1)


def test_positive_jacobians_and_volume() -> None:
    """det J > 0 at the 27 Gauss points of every element; the elements' volumes sum to
    the octant's 7 pi / 6 up to the quadratic geometry's O(h^4) deficit: measured
    -1.18e-3 (n = 2), -7.5e-5 (n = 4), -4.7e-6 (n = 8)."""
    errors = []
    for n in (2, 4):
        mesh = cs.sphere_mesh(n, n)
        geo = cs.element_geometry(mesh["nodes"], mesh["elements"])
        assert geo["det"].min() > 0
        errors.append(geo["weights"].sum() / OCTANT - 1)
    assert -1.5e-3 < errors[0] < 0 and -1e-4 < errors[1] < 0
    assert errors[0] / errors[1] > 12  # h^4: 16


def test_linear_field_has_its_constant_stress(mesh: dict) -> None:
    """The nodal values of u = G x give the gradient G at every point of every (curved)
    element: the isoparametric patch test of field_at_points."""
    G = np.random.default_rng(3).normal(size=(3, 3))
    u = mesh["nodes"] @ G.T
    geo = cs.element_geometry(mesh["nodes"], mesh["elements"])
    uh, sh = cs.field_at_points(geo, mesh["elements"], u, 1.0, 0.3)
    assert np.allclose(uh, geo["x"] @ G.T, rtol=0, atol=1e-13)
    assert np.allclose(sh, hooke(G, 1.0, 0.3), rtol=0, atol=1e-12)


def test_interpolant_errors_converge() -> None:
    """The exact solution's nodal interpolant: e_u falls as h^3 and e_sigma as h^2 (n = 4
    to 8: measured orders 2.97 and 1.96)."""
    s = LameShell()
    e = []
    for n in (4, 8):
        mesh = cs.sphere_mesh(n, n)
        e.append(cs.field_errors(mesh["nodes"], mesh["elements"], s.displacement(mesh["nodes"]), s))
    ru, rs = np.log2(e[0][0] / e[1][0]), np.log2(e[0][1] / e[1][1])
    assert 2.8 < ru < 3.2 and 1.8 < rs < 2.2


def test_input_file(tmp_path: Path, mesh: dict) -> None:
    """The input names every node and element (20 nodes on two lines), the inner
    layer's elements carry the pressure on P1, and the symmetry sets are constrained."""
    inp = tmp_path / "s.inp"
    cs.write_input(inp, mesh)
    text = inp.read_text()
    lines = text.splitlines()
    i = lines.index("*ELEMENT, TYPE=C3D20R, ELSET=EALL")
    first = [int(v) for v in (lines[i + 1] + lines[i + 2]).split(",")]
    assert first[0] == 1 and first[1:] == list(mesh["elements"][0])
    n_el = len(mesh["elements"])
    assert lines[i + 2 * n_el + 1].startswith("*")  # the next keyword after 2 lines per element
    j = lines.index("*ELSET, ELSET=EINNER")
    inner = []
    for ln in lines[j + 1:]:
        if ln.startswith("*"):
            break
        inner += [int(v) for v in ln.split(",")]
    r = np.linalg.norm(mesh["nodes"][mesh["elements"][np.array(inner) - 1][:, :4] - 1], axis=2)
    assert len(inner) == 3 * mesh["n"] ** 2 and np.allclose(r, 1.0)
    assert "EINNER, P1, 1" in text
    for line in ("NX0, 1, 1, 0.", "NY0, 2, 2, 0.", "NZ0, 3, 3, 0."):
        assert line in lines


DAT = """
 displacements (vx,vy,vz) for set NALL and time  0.1000000E+01

         1  7.989714E-01  0.000000E+00  0.000000E+00
         2  5.451416E-01 -1.000000E-03  2.000000E+00

 stresses (elem, integ.pnt.,sxx,syy,szz,sxy,sxz,syz) for set EALL and time  0.1000000E+01

""" + "\n".join(f"         1   {k} {k}.0E+00  2.0E+00  3.0E+00  4.0E+00  5.0E+00  6.0E+00"
                for k in range(1, 9)) + "\n"


def test_dat_reader(tmp_path: Path) -> None:
    path = tmp_path / "s.dat"
    path.write_text(DAT)
    u, s = cs.parse_dat(path, 2, 1)
    assert u[1].tolist() == [0.5451416, -1e-3, 2.0]
    assert s[0, 7].tolist() == [[8.0, 4.0, 5.0], [4.0, 2.0, 6.0], [5.0, 6.0, 3.0]]
    with pytest.raises(ValueError):
        cs.parse_dat(path, 3, 1)


def test_rates_and_mesh_list() -> None:
    rows = [{"elements": 3 * 8, "e": 1.0}, {"elements": 3 * 64, "e": 0.125}]
    assert np.isnan(cs.rates(rows, "e")[0]) and cs.rates(rows, "e")[1] == pytest.approx(3.0)
    assert cs.parse_meshes("2, 4x3") == [(2, 2), (4, 3)]
    for bad in ("0", "a", "2x0"):
        with pytest.raises(SystemExit):
            cs.parse_meshes(bad)
    assert cs.parse_solvers("default, iterative  scaling,SPOOLES") == ["", "ITERATIVE SCALING", "SPOOLES"]
    with pytest.raises(SystemExit):
        cs.parse_solvers("umfpack")


def test_table_rates_per_solver() -> None:
    """The table's rates run within each solver's rows (the first row of each: nan)."""
    row = {"n": 2, "m": 2, "elements": 24, "nodes": 185, "dofs": 555, "wall": 0.1,
           "e_u": 8e-3, "e_sigma": 0.1, "e_sigma_ip": 0.01}
    rows = [{**row, "solver": s, **extra} for s in ("default", "ITERATIVE SCALING")
            for extra in ({}, {"n": 4, "m": 4, "elements": 192, "e_u": 1e-3, "e_sigma": 0.025})]
    lines = cs.table(rows)
    assert len(lines) == 5
    assert [ln.split()[-4] for ln in lines[1:]] == ["nan", "3.00"] * 2
    assert [ln.split()[-2] for ln in lines[1:]] == ["nan", "2.00"] * 2
    assert lines[3].startswith("iterative scaling 2x2x2")


@pytest.mark.skipif(shutil.which("ccx") is None, reason="ccx not installed")
def test_ccx_on_the_coarsest_mesh(tmp_path: Path) -> None:
    """ccx on 2 x 2 x 2 per block (0.1 s): the measured errors of the bench's first row
    (5.43e-3, 9.87e-2), and our stresses at ccx's 2 x 2 x 2 points are ccx's to its
    7 printed digits."""
    from bench.run import Workdir
    r = cs.run_sphere(shutil.which("ccx"), Workdir(tmp_path / "w"), 2, 2, threads=1)
    assert r["dofs"] == 555 and r["elements"] == 24
    assert r["e_u"] == pytest.approx(5.43e-3, rel=1e-2)
    assert r["e_sigma"] == pytest.approx(9.87e-2, rel=1e-2)
    assert r["ip_agreement"] < 1e-5


def test_section_7_runs_without_voiga(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                      capsys: pytest.CaptureFixture) -> None:
    """``python -m bench --only 7`` needs no voiga binary; every solver x mesh is one
    run_sphere call (a stand-in here), printed and written to the JSON figures."""
    import json

    import bench.__main__ as bm
    from bench import ccx
    calls: list[tuple] = []

    def stand_in(exe, w, n, m, threads, solver=""):
        calls.append((n, m, threads, solver))
        return {"n": n, "m": m, "elements": 3 * n * n * m, "nodes": 1, "dofs": 3, "wall": 0.5,
                "e_u": 1.0 / n**3, "e_sigma": 1.0 / n**2, "e_sigma_ip": 0.1, "ip_agreement": 1e-7,
                "solver": solver or "default", "log": []}

    monkeypatch.setattr(bm, "VOIGA", tmp_path / "no-voiga")
    monkeypatch.setattr(ccx, "ensure_ccx", lambda: "ccx")
    monkeypatch.setattr(cs, "run_sphere", stand_in)
    out = tmp_path / "f.json"
    assert bm.main(["--only", "7", "--sphere-meshes", "2,4x2", "--sphere-threads", "1",
                    "--work", str(tmp_path / "w"), "--json", str(out)]) == 0
    assert calls == [(2, 2, 1, ""), (4, 2, 1, ""), (2, 2, 1, "ITERATIVE SCALING"),
                     (4, 2, 1, "ITERATIVE SCALING")]
    rows = json.loads(out.read_text())["sphere_calculix"]["rows"]
    # e_sigma / 4 while the elements x 4 (4x4x2 against 2x2x2): h / 4^(1/3), order 3
    assert [r["rate_sigma"] for r in rows][1::2] == pytest.approx([3.0, 3.0])
    assert "iterative scaling 4x4x2" in capsys.readouterr().out
