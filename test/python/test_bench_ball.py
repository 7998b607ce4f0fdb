"""Section 9 of the bench (3D Hertz sphere; bench/ball_mesh.py, ball_ogrid.py,
ball_pressure.py, ball_peers.py, ball_section.py): the hexahedral meshes of the ball
octant (cube-sphere and O-grid) and the flat,
the conversion of the peers' output to pressure points, the inputs and the .dat reader,
the pairing of peer runs with voiga runs. One small Kratos run when Kratos is installed in
build/kratos-venv (nothing is installed here)."""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import REPO

sys.path.insert(0, str(REPO))
from bench import ball_mesh as bm  # noqa: E402
from bench import ball_ogrid as bo  # noqa: E402
from bench import ball_peers as bp  # noqa: E402
from bench import ball_pressure as bpr  # noqa: E402
from bench import ball_section as bs  # noqa: E402
from bench.ccx_sphere import element_geometry  # noqa: E402
from post.hertz3d import sphere_reference  # noqa: E402

MESH = bm.BallMesh(4, 3, 2, 3)


@pytest.fixture(scope="module", params=[False, True], ids=["linear", "quadratic"])
def ball(request) -> dict:
    return bm.ball_octant(MESH, request.param)


def sphere_nodes(n_ab: int, n_c: int) -> int:
    """Nodes on the octant's sphere: three patches (n_ab+1)^2 and 2 x (n_ab+1)(n_c+1),
    less the edges they share, plus the corner all three share."""
    return (n_ab + 1) ** 2 + 2 * (n_ab + 1) * (n_c + 1) - 2 * (n_ab + 1) - (n_c + 1) + 1


def test_linear_counts() -> None:
    """Linear mesh: the core's nodes, the radial layers over the sphere's, the blocks'
    elements; the sphere's faces one per (A, B) cell of the z shell and per cell of the
    x and y shells."""
    m = bm.ball_octant(MESH, False)
    nab, nc, nd = MESH.fine + MESH.rest, MESH.outer, MESH.radial
    s = sphere_nodes(nab, nc)
    assert len(m["sphere"]) == s
    assert len(m["nodes"]) == (nab + 1) ** 2 * (nc + 1) + nd * s
    assert len(m["elements"]) == nab * nab * nc + nd * (nab * nab + 2 * nab * nc)
    assert len(m["surface"]) == nab * nab + 2 * nab * nc


def test_quadratic_counts() -> None:
    """Quadratic mesh: a sphere node at every corner and mid-side of the faces."""
    m = bm.ball_octant(MESH, True)
    nab, nc = 2 * (MESH.fine + MESH.rest), 2 * MESH.outer
    cells = (MESH.fine + MESH.rest) ** 2 + 2 * (MESH.fine + MESH.rest) * MESH.outer
    assert len(m["sphere"]) == sphere_nodes(nab, nc) - cells  # no face centres
    assert np.unique(m["elements"]).size == len(m["nodes"])  # every node used


def test_mesh_follows_the_sphere(ball: dict) -> None:
    """Sphere nodes on |X| = 1 to round-off, the faces' nodes among them, the symmetry
    and top sets exactly on their planes, every element right-handed at its centre."""
    x = ball["nodes"]
    assert np.abs(np.linalg.norm(x[ball["sphere"]], axis=1) - 1.0).max() < 1e-14
    assert np.isin(ball["surface"], ball["sphere"]).all()
    assert (x[ball["x0"], 0] == 0).all() and (x[ball["y0"], 1] == 0).all() and (x[ball["top"], 2] == 0).all()
    assert x[:, 2].max() <= 0 and x[:, :2].min() >= 0
    assert (bm.signed_volumes(x, ball["elements"]) > 0).all()
    assert np.isclose(np.linalg.norm(x[ball["sphere"]] - [0, 0, -1], axis=1).min(), 0.0)


def test_quadratic_volume_and_area() -> None:
    """The C3D20 mesh fills the octant (pi/6) and its faces cover the sphere's eighth
    (pi/2) up to the curved elements' error, which falls about 16 times (h^4) when the
    angles are halved; the Jacobian is positive at every Gauss point; the faces' normals
    point out of the ball."""
    errors = []
    for mesh in (MESH, bm.BallMesh(8, 6, 4, 6)):
        m = bm.ball_octant(mesh, True)
        geo = element_geometry(m["nodes"], m["elements"] + 1)
        assert (geo["det"] > 0).all()
        pts, jac, _ = bpr.face_points(m["nodes"], m["surface"], 3)
        _, w = bpr.gauss_square(3)
        errors.append([abs(geo["weights"].sum() / (math.pi / 6) - 1), abs((jac * w).sum() / (math.pi / 2) - 1)])
    assert max(errors[0]) < 1.5e-3
    assert errors[1][0] < errors[0][0] / 10 and errors[1][1] < errors[0][1] / 10
    q, _ = bpr.gauss_square(2)
    _, dN = bpr.face_shapes(8, q)
    X = m["nodes"][m["surface"]]
    d = np.einsum("gnk,fna->fgak", dN, X)
    normal = np.cross(d[..., 0], d[..., 1])
    centre = np.einsum("gn,fna->fga", bpr.face_shapes(8, q)[0], X)
    assert (np.einsum("fga,fga->fg", normal, centre) > 0).all()


def test_grading_follows_the_contact() -> None:
    """A = B: ``fine`` equal angles over theta_c, then growing to 45 degrees; w ends at
    the sphere with a fine element's length."""
    a = MESH.angles_ab()
    assert a[0] == 0 and a[-1] == pytest.approx(math.pi / 4) and len(a) == MESH.fine + MESH.rest + 1
    assert np.allclose(np.diff(a[:MESH.fine + 1]), bm.THETA_C / MESH.fine)
    assert (np.diff(np.diff(a[MESH.fine:])) > 0).all()
    w = MESH.radial_w()
    assert w[0] == 0 and w[-1] == 1
    assert (w[-1] - w[-2]) * (1 - bm.CORE) == pytest.approx(bm.THETA_C / MESH.fine)


def test_flat_block() -> None:
    """The flat's top at z = -1, its faces' normals +z, its grid beyond the slave's
    reach and past the symmetry planes, as fine as the slave near the contact."""
    g = bm.flat_grid(MESH)
    assert (np.diff(g) > 0).all() and g[0] < 0 and g[-1] == pytest.approx(0.35)
    h = np.sin(MESH.angles_ab()[1])
    assert np.diff(g)[:3] == pytest.approx(h, rel=1e-12)
    for quadratic in (False, True):
        f = bm.flat_block(g, quadratic)
        top = f["nodes"][f["top"]]
        assert np.allclose(top[..., 2], -1.0)
        n = np.cross(top[:, 1] - top[:, 0], top[:, 3] - top[:, 0])
        assert (n[:, 2] > 0).all()
        assert (bm.signed_volumes(f["nodes"], f["elements"]) > 0).all()


def test_parse_ball_mesh() -> None:
    assert bm.BallMesh.parse("8x6x4x8") == bm.BallMesh(8, 6, 4, 8)
    with pytest.raises(ValueError):
        bm.BallMesh.parse("8x6x4")


def test_face_shapes() -> None:
    """Partition of unity, Kronecker delta at the nodes, derivatives against differences."""
    nodes8 = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [0, -1], [1, 0], [0, 1], [-1, 0]], float)
    for n in (4, 8):
        N, _ = bpr.face_shapes(n, nodes8[:n])
        assert np.allclose(N, np.eye(n))
        q = np.random.default_rng(3).uniform(-1, 1, (20, 2))
        N, dN = bpr.face_shapes(n, q)
        assert np.allclose(N.sum(axis=1), 1.0)
        for k in range(2):
            e = np.zeros(2)
            e[k] = 1e-6
            fd = (bpr.face_shapes(n, q + e)[0] - bpr.face_shapes(n, q - e)[0]) / 2e-6
            assert np.allclose(dN[..., k], fd, atol=1e-8)


def consistent_forces(x: np.ndarray, faces: np.ndarray, p, n_gauss: int = 4) -> np.ndarray:
    """f_i = -integral of N_i p(x) over the faces (z components, as Kratos's element
    right-hand side: negative under compression), ``n_gauss`` x ``n_gauss`` points."""
    pts, jac, N = bpr.face_points(x, faces, n_gauss)
    _, w = bpr.gauss_square(n_gauss)
    f = np.zeros(len(x))
    np.add.at(f, faces, -np.einsum("gn,fg->fn", N, p(pts) * jac * w))
    return f


def test_nodal_force_points_uniform_pressure_is_exact() -> None:
    """A uniform pressure's consistent nodal forces give that pressure at every node (the
    forces integrated with the areas' 3 x 3 points)."""
    m = bm.ball_octant(MESH, False)
    f = consistent_forces(m["nodes"], m["surface"], lambda p: np.full(p.shape[:-1], 0.3), 3)
    nodes = np.unique(m["surface"])
    pts = bpr.nodal_force_points(m["nodes"], m["surface"], nodes, f[nodes], np.ones(len(nodes), bool))
    assert pts.p == pytest.approx(0.3, rel=1e-12)
    assert pts.w.sum() == pytest.approx(bpr.nodal_areas(m["nodes"], m["surface"]).sum())
    with pytest.raises(ValueError):
        q = bm.ball_octant(MESH, True)
        bpr.nodal_force_points(q["nodes"], q["surface"], nodes, f[nodes], np.ones(len(nodes), bool))


def hertz_field(force: float):
    a, p0 = sphere_reference(force, bpr.E, bpr.NU, bpr.RADIUS)
    return a, p0, lambda x: p0 * np.sqrt(np.clip(1 - (x[..., 0] ** 2 + x[..., 1] ** 2) / a**2, 0, None))


def test_measure_of_hertz_forces() -> None:
    """Consistent forces of Hertz's pressure on a fine mesh: the nodal pressures are
    within a few per cent of Hertz (the zone's edge inside elements), the L2 falls with
    the mesh, the inactive nodes carry nothing, the force of the pressures is P."""
    force = 1.6e-3
    a, p0, field = hertz_field(force)
    errors = []
    for mesh in (bm.BallMesh(8, 4, 2, 4), bm.BallMesh(16, 4, 2, 6)):
        m = bm.ball_octant(mesh, False)
        f = consistent_forces(m["nodes"], m["surface"], field)
        nodes = np.unique(m["surface"])
        pts = bpr.nodal_force_points(m["nodes"], m["surface"], nodes, f[nodes], f[nodes] < 0)
        res = bpr.measure(pts, force / 4)
        assert res["force"] == pytest.approx(force) and res["a"] == pytest.approx(a)
        assert res["contact_force"] == pytest.approx(-4 * f[nodes].sum(), rel=1e-12)
        assert res["contact_force"] == pytest.approx(force, rel=1e-2)  # the kink at a, 4 x 4 points
        errors.append(res["l2"])
    assert errors[1] < errors[0] < 0.1


def test_penalty_points_of_a_translated_sphere() -> None:
    """The ball moved down by d without deforming: K x (d - (1 + z)) where that is
    positive, at 3 x 3 Gauss points of every face, weights summing to the faces' area
    (the bilinear faces' chords below the sphere's)."""
    d, k = 0.004, 1e4
    for quadratic, n in ((False, 9), (True, 9)):
        m = bm.ball_octant(MESH, quadratic)
        u = np.zeros_like(m["nodes"])
        u[:, 2] = -d
        pts = bpr.penalty_points(m["nodes"], u, m["surface"], k)
        assert len(pts.p) == n * len(m["surface"])
        assert pts.p == pytest.approx(k * np.clip(d - 1 - pts.x[:, 2], 0, None), rel=1e-10, abs=1e-10)
        area = bpr.nodal_areas(m["nodes"], m["surface"]).sum() if not quadratic else math.pi / 2
        assert pts.w.sum() == pytest.approx(area, rel=1e-12 if not quadratic else 1e-3)


def test_penalty_nodal_points_of_a_uniform_overclosure() -> None:
    """Flat faces (the flat's top, z = -R) moved down by d: the law's pressure K d at every
    point, its consistent nodal forces over the nodal areas K d at every node, the same
    force; quadratic faces are refused."""
    f = bm.flat_block(bm.flat_grid(MESH), False)
    u = np.zeros_like(f["nodes"])
    u[:, 2] = -2e-5
    law = bpr.penalty_points(f["nodes"], u, f["top"], 1e4)
    assert law.p == pytest.approx(0.2, rel=1e-9)
    nodal = bpr.penalty_nodal_points(f["nodes"], u, f["top"], 1e4)
    assert nodal.p == pytest.approx(0.2, rel=1e-9)
    assert nodal.p @ nodal.w == pytest.approx(law.p @ law.w, rel=1e-12)
    q = bm.flat_block(bm.flat_grid(MESH), True)
    with pytest.raises(ValueError):
        bpr.penalty_nodal_points(q["nodes"], np.zeros_like(q["nodes"]), q["top"], 1e4)


def test_projected_points_keep_a_uniform_pressure() -> None:
    """The Gram-matrix projection of a uniform pressure over part of the flat's faces (the
    quadratic ones, whose corner shares are negative, and the bilinear ones) gives that
    pressure back at the loaded faces' points, and none at the faces away from them."""
    for quadratic in (False, True):
        f = bm.flat_block(bm.flat_grid(MESH), quadratic)
        u = np.zeros_like(f["nodes"])
        law = bpr.penalty_points(f["nodes"], u, f["top"], 1e4)
        centre = f["nodes"][f["top"]].mean(axis=1)
        loaded = np.repeat(np.hypot(centre[:, 0], centre[:, 1]) < 0.1, 9)
        law = bpr.Points(law.x, np.where(loaded, 0.07, 0.0), law.w)
        proj = bpr.projected_points(f["nodes"], f["top"], law)
        assert proj.p[loaded] == pytest.approx(0.07, rel=1e-9)
        far = np.repeat(np.hypot(centre[:, 0], centre[:, 1]) > 0.25, 9)
        assert (proj.p[far] == 0).all()


def test_interpolated_points() -> None:
    """Nodal pressures interpolated inside the faces: a uniform one stays uniform."""
    m = bm.ball_octant(MESH, False)
    nodes = np.unique(m["surface"])
    nodal = bpr.Points(m["nodes"][nodes], np.full(len(nodes), 2.0), np.ones(len(nodes)))
    pts = bpr.interpolated_points(m["nodes"], m["surface"], nodal, nodes)
    assert pts.p == pytest.approx(2.0)


def test_kratos_mdpa(tmp_path: Path) -> None:
    """The Kratos model: the ball's and the flat's hexahedra and faces, 3 DOFs per ball node."""
    info = bp.write_mdpa(tmp_path / "m.mdpa", MESH)
    text = (tmp_path / "m.mdpa").read_text()
    model = info["model"]
    n_nodes = len(model["ball"]["nodes"]) + len(model["flat"]["nodes"])
    body = text.split("Begin Nodes")[1].split("End Nodes")[0].strip().splitlines()
    assert len(body) == n_nodes and info["dofs"] == 3 * len(model["ball"]["nodes"])
    conds = text.split("Begin Conditions SurfaceCondition3D4N")[1].split("End Conditions")[0].strip()
    assert len(conds.splitlines()) == len(model["ball"]["surface"]) + len(model["flat"]["top"])
    assert len(info["slave"]) == len(np.unique(model["ball"]["surface"]))


def test_ccx_input_and_dat(tmp_path: Path) -> None:
    """The CalculiX input (C3D20R lines continued after 16 entries; the slave and master
    surfaces on face S2) and the .dat reader's last displacements and top force."""
    info = bp.write_ccx(tmp_path / "b.inp", MESH, "C3D20R")
    text = (tmp_path / "b.inp").read_text()
    assert "*CONTACT PAIR, INTERACTION=SI1, TYPE=SURFACE TO SURFACE" in text
    assert text.count(", S2\n") == len(info["ball"]["surface"]) + len(bm.flat_grid(MESH)) ** 2 - 2 * len(
        bm.flat_grid(MESH)) + 1
    dat = ("\n displacements (vx,vy,vz) for set NSPHERE and time  0.2\n\n"
           "      1  1.0E-03  2.0E-03 -3.0E-03\n"
           "\n total force (fx,fy,fz) for set NTOP and time  0.2\n\n  0.0 0.0 -1.0E-04\n"
           "\n displacements (vx,vy,vz) for set NSPHERE and time  1.0\n\n"
           "      1  1.5E-03  2.5E-03 -3.5E-03\n      3  0.0  0.0 -1.0E-02\n"
           "\n total force (fx,fy,fz) for set NTOP and time  1.0\n\n  0.0 0.0 -4.0E-04\n")
    (tmp_path / "b.dat").write_text(dat)
    u, rf = bp.parse_dat(tmp_path / "b.dat", 3)
    assert u[0] == pytest.approx([1.5e-3, 2.5e-3, -3.5e-3]) and np.isnan(u[1]).all()
    assert u[2, 2] == -1e-2 and rf == -4e-4


def test_parse_peers_and_ratios() -> None:
    runs = bs.parse_peers("kratos:alm:amgcl:8x5x3x6,ccx:C3D8I:4x3x2x3:1e3,kratos:alm:amgcl:o4x8x6x8x2,"
                          "ccx:C3D20R:o3x6x3x5x1:1e3")
    assert runs[0] == ("kratos", "alm", "amgcl", bm.BallMesh(8, 5, 3, 6))
    assert runs[1] == ("ccx", "C3D8I", bm.BallMesh(4, 3, 2, 3), 1e3)
    assert runs[2] == ("kratos", "alm", "amgcl", bo.OGridMesh(4, 8, 6, 8, 2))
    assert runs[3] == ("ccx", "C3D20R", bo.OGridMesh(3, 6, 3, 5, 1), 1e3)
    assert bs.peer_name(runs[2]) == "kratos alm amgcl o4x8x6x8x2"
    with pytest.raises(ValueError):
        bs.parse_peers("kratos:alm:amgcl:o4x8x6x8")
    with pytest.raises(SystemExit):
        bs.parse_peers("ccx:C3D4:4x3x2x3")
    rows = bs.ratios({"v1": {"code": "voiga", "l2": 0.05, "wall": 1.0},
                      "v2": {"code": "voiga", "l2": 0.02, "wall": 4.0},
                      "k": {"code": "kratos", "l2": 0.03, "wall": 20.0},
                      "c": {"code": "ccx", "l2": 0.01, "wall": 9.0}})
    assert rows[0] == {"peer": "k", "peer_l2": 0.03, "peer_wall": 20.0, "voiga": "v2",
                       "voiga_l2": 0.02, "voiga_wall": 4.0, "ratio": 5.0}
    assert "ratio" not in rows[1]


@pytest.mark.skipif(not __import__("bench.kratos").kratos.kratos_available(),
                    reason="Kratos is not installed in build/kratos-venv")
def test_kratos_small_run(tmp_path: Path) -> None:
    """Kratos on the smallest mesh: converges; the nodal pressures' force is the top's
    reaction (the contact forces balance it) and they are Hertz's to the coarse mesh's
    error (measured: 9.2 % at the nodes; a conversion with the wrong sign or areas is
    off by 100 % or more)."""
    from bench.kratos import venv_python
    from bench.run import Workdir
    r = bp.run_kratos(venv_python(), Workdir(tmp_path / "w"), MESH)
    assert r["nodal_force"] == pytest.approx(r["force"], rel=1e-3)
    assert r["l2_nodes"] < 0.15


OGRID = bo.OGridMesh(3, 6, 3, 4, 2)


@pytest.fixture(scope="module", params=[False, True], ids=["linear", "quadratic"])
def ogrid(request) -> dict:
    return bo.ogrid_octant(OGRID, request.param)


def test_parse_ogrid_mesh() -> None:
    assert bo.OGridMesh.parse("o4x8x6x8x2") == bo.OGridMesh(4, 8, 6, 8, 2)
    assert bo.OGridMesh(4, 8, 6, 8, 2).name == "o4x8x6x8x2"
    assert bo.parse_mesh("O4x8x6x8x2") == bo.OGridMesh(4, 8, 6, 8, 2)
    assert bo.parse_mesh("8x6x4x8") == bm.BallMesh(8, 6, 4, 8)
    for bad in ("4x8x6x8x2", "o4x8x6x8", "o0x8x6x8x2", "ox"):
        with pytest.raises(ValueError):
            bo.OGridMesh.parse(bad)


def test_ogrid_follows_the_sphere(ogrid: dict) -> None:
    """As the cube-sphere mesh: sphere nodes on |X| = 1, faces among them, the planes'
    sets on their planes, every element right-handed at its centre, the contact point a
    node; the blocks' shared nodes merged (no two nodes closer than 1e-9, every node
    used)."""
    from scipy.spatial import cKDTree
    x = ogrid["nodes"]
    assert np.abs(np.linalg.norm(x[ogrid["sphere"]], axis=1) - 1.0).max() < 1e-14
    assert np.isin(ogrid["surface"], ogrid["sphere"]).all()
    assert (x[ogrid["x0"], 0] == 0).all() and (x[ogrid["y0"], 1] == 0).all() and (x[ogrid["top"], 2] == 0).all()
    assert x[:, 2].max() <= 0 and x[:, :2].min() >= 0
    assert (bm.signed_volumes(x, ogrid["elements"]) > 0).all()
    assert np.linalg.norm(x[ogrid["sphere"]] - [0, 0, -1], axis=1).min() < 1e-15
    assert len(cKDTree(x).query_pairs(1e-9)) == 0
    assert np.unique(ogrid["elements"]).size == len(x)
    assert ogrid["elements"].shape[1] == (20 if ogrid["quadratic"] else 8)
    # the symmetry planes and the top carry nodes of every block
    assert min(len(ogrid["x0"]), len(ogrid["y0"]), len(ogrid["top"])) > 20


def test_ogrid_counts() -> None:
    """Linear O-grid: the plane's nodes (core square, two ring blocks sharing the
    diagonal) on the core's c + 1 layers and the z shell's d more; the x and y shells'
    (c + 1) (c + 1) (d + 1) less their faces on the core and on the z shell (c d left
    each per phi), the diagonal face's c d once; the sphere's faces one per plane cell
    and per (phi, C) cell of the x and y shells."""
    m = bo.ogrid_octant(OGRID, False)
    theta, _ = OGRID.rings()
    c, k, d = OGRID.core, len(theta) - 1, OGRID.radial
    plane = (c + 1) ** 2 + (2 * c + 1) * k
    assert len(m["nodes"]) == plane * (c + 1 + d) + (2 * c + 1) * c * d
    cells = c * c + 2 * c * k
    assert len(m["surface"]) == cells + 2 * c * c
    assert len(m["elements"]) == cells * c + cells * d + 2 * c * c * d


def test_ogrid_rings_are_circles(ogrid: dict) -> None:
    """Near the contact, from where the core's square has faded (0.8 a_est) to the fine
    zone's end (1.5 a_est): every node of the sphere and of the z shell lies on one of
    the rings' circles about the axis, i.e. its angle atan(r / |z|) from the axis seen
    from the centre is a ring's theta (or a mid-side one); those over 0.9..1.1 a_est are
    ``edge`` times closer than the fine ones; every sphere face there has two edges on
    circles (corners in pairs of equal r)."""
    x = ogrid["nodes"]
    theta, _ = OGRID.rings()
    theta = bm.refine(theta, ogrid["quadratic"])
    r = np.hypot(x[:, 0], x[:, 1])
    angle = np.arctan2(r, -x[:, 2])
    lo, hi = math.asin(0.8 * bo.A_EST), bm.THETA_C
    zone = (x[:, 2] <= -bm.CORE * (1 - 1e-12)) & (angle >= lo) & (angle <= hi * (1 + 1e-12))
    assert zone.sum() > 50
    assert np.abs(angle[zone][:, None] - theta[None, :]).min(axis=1).max() < 1e-12
    band = [math.asin(f * bo.A_EST) for f in (0.9, 1.1)]
    fine = np.diff(OGRID.fine_theta())
    inside = np.diff(OGRID.fine_theta())[(OGRID.fine_theta()[1:] > band[0]) & (OGRID.fine_theta()[:-1] < band[1])]
    assert inside == pytest.approx(OGRID.ring_size / OGRID.edge, rel=1e-12)
    assert fine.max() == pytest.approx(OGRID.ring_size, rel=1e-12)
    corners = x[ogrid["surface"][:, :4]]
    rc = np.hypot(corners[..., 0], corners[..., 1])
    near = (rc.min(axis=1) >= math.sin(lo)) & (rc.max(axis=1) <= math.sin(hi) * (1 + 1e-12))
    assert near.sum() >= 2 * OGRID.core * 3
    pairs = np.sort(rc[near], axis=1)
    assert np.abs(pairs[:, 1] - pairs[:, 0]).max() < 1e-12 and np.abs(pairs[:, 3] - pairs[:, 2]).max() < 1e-12


def test_ogrid_quadratic_volume_and_area() -> None:
    """The C3D20 O-grid fills the octant and its faces cover the sphere's eighth to 1e-3;
    positive Jacobian at every Gauss point; the faces' normals point out of the ball."""
    m = bo.ogrid_octant(OGRID, True)
    geo = element_geometry(m["nodes"], m["elements"] + 1)
    assert (geo["det"] > 0).all()
    assert geo["weights"].sum() == pytest.approx(math.pi / 6, rel=1e-3)
    pts, jac, _ = bpr.face_points(m["nodes"], m["surface"], 3)
    _, w = bpr.gauss_square(3)
    assert (jac * w).sum() == pytest.approx(math.pi / 2, rel=1e-3)
    q, _ = bpr.gauss_square(2)
    N, dN = bpr.face_shapes(8, q)
    X = m["nodes"][m["surface"]]
    d = np.einsum("gnk,fna->fgak", dN, X)
    normal = np.cross(d[..., 0], d[..., 1])
    assert (np.einsum("fga,fga->fg", normal, np.einsum("gn,fna->fga", N, X)) > 0).all()


def test_ogrid_resolves_hertz_better() -> None:
    """Hertz's pressure's consistent nodal forces, turned into pressures as Kratos's:
    the O-grid with its rings split at the edge (168 sphere faces) is closer to Hertz
    than a cube-sphere mesh with almost three times the faces (480; measured 3.3 %
    against 4.5 %)."""
    force = 1.6e-3
    _, _, field = hertz_field(force)
    errors = []
    for mesh in (bo.OGridMesh(4, 8, 4, 4, 2), bm.BallMesh(16, 4, 2, 6)):
        m = bo.octant(mesh, False)
        f = consistent_forces(m["nodes"], m["surface"], field)
        nodes = np.unique(m["surface"])
        pts = bpr.nodal_force_points(m["nodes"], m["surface"], nodes, f[nodes], f[nodes] < 0)
        errors.append((len(m["surface"]), bpr.measure(bpr.interpolated_points(m["nodes"], m["surface"], pts, nodes),
                                                       force / 4)["l2"]))
    assert errors[0][0] < errors[1][0] / 2
    assert errors[0][1] < errors[1][1]


def test_ogrid_inputs(tmp_path: Path) -> None:
    """The O-grid in the Kratos model and the CalculiX input (C3D8I and C3D20R): the
    flat's grid as fine as the rings near the contact, all the sphere's faces slaves."""
    info = bp.write_mdpa(tmp_path / "o.mdpa", OGRID)
    assert info["dofs"] == 3 * len(bo.ogrid_octant(OGRID, False)["nodes"])
    assert len(info["slave"]) == len(np.unique(info["model"]["ball"]["surface"]))
    g = bm.flat_grid(OGRID)
    step = bm.THETA_C / round(bm.THETA_C / OGRID.ring_size)  # whole steps over theta_c
    assert g[3] - g[2] == pytest.approx(math.sin(step)) and step == pytest.approx(OGRID.ring_size, rel=0.2)
    for element in ("C3D8I", "C3D20R"):
        ccx = bp.write_ccx(tmp_path / f"o-{element}.inp", OGRID, element)
        text = (tmp_path / f"o-{element}.inp").read_text()
        assert f"*ELEMENT, TYPE={element}, ELSET=EBALL" in text
        assert text.count(", S2\n") == len(ccx["ball"]["surface"]) + (len(g) - 1) ** 2


@pytest.mark.skipif(not __import__("bench.kratos").kratos.kratos_available(),
                    reason="Kratos is not installed in build/kratos-venv")
def test_kratos_small_ogrid_run(tmp_path: Path) -> None:
    """Kratos on a small O-grid (o3x6x3x5x1, 2,448 DOFs): converges, its contact forces
    balance the top's reaction (measured to 3e-4; 1.6e-3 on o3x4x3x4x1, whose steps end
    after one or two iterations), and its nodal pressures are Hertz's to the coarse
    mesh's error (measured 4.8 % at the nodes, 7.9 % over the faces)."""
    from bench.kratos import venv_python
    from bench.run import Workdir
    r = bp.run_kratos(venv_python(), Workdir(tmp_path / "w"), bo.OGridMesh(3, 6, 3, 5, 1))
    assert r["nodal_force"] == pytest.approx(r["force"], rel=1e-3)
    assert r["l2_nodes"] < 0.15 and r["l2"] < 0.15
