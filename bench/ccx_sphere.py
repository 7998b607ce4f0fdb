"""Section 7: CalculiX on the thick spherical shell under internal pressure (issue 41),
the reference for voiga's 3D solver: C3D20R hexahedra, errors against Lamé's solution.

Problem: the octant ``x, y, z >= 0`` of the shell ``a <= r <= b`` (a = 1, b = 2), pressure
p = 1 on the inner sphere, outer sphere free, E = 1, nu = 0.3, linear elasticity; the
symmetry planes carry u_x = 0 on x = 0, u_y = 0 on y = 0, u_z = 0 on z = 0. Exact
solution: :class:`post.lame.LameShell`.

Mesh (:func:`sphere_mesh`): the longitude/latitude parametrization of
:func:`pre.solids.shell_octant` collapses a face onto the pole, which a C3D20R cannot
take; so the octant is cut into three blocks, one per coordinate axis (the points whose
largest coordinate is x, y or z), each the central projection of a cube face onto the
sphere ("cube sphere"), parametrized by two angles in [0, pi/4] (the direction is
``(1, tan alpha, tan beta)`` for the x block, cyclically permuted for the others: all three
right-handed) and the radius. Each block has ``n x n`` elements over the angles (equal
angle steps) and ``m`` radially (equal steps); all 20 nodes of an element are mapped
exactly, so corner and mid-side nodes lie on the spheres; the blocks' common faces are
merged. Every element is a regular hexahedron (no collapsed face; the three blocks meet
at 120 degrees on the diagonal (1, 1, 1)).

Measure (:func:`field_errors`): the C3D20 displacement field of ccx's nodal
displacements, its stress by Hooke's law of its gradient, at 3 x 3 x 3 Gauss points of
every element with the element's own Jacobian: ``e_u = ||u_h - u|| / ||u||`` and
``e_sigma = ||sigma_h - sigma|| / ||sigma||`` (L2 over the meshed octant, Frobenius norm;
:mod:`post.lame`). ccx's own stresses at its 2 x 2 x 2 integration points are compared
with the same sums over those points (``e_sigma_ip``).
"""

from __future__ import annotations

import os
import re
import subprocess
import time
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from post.lame import LameShell, hooke, relative_l2_error, relative_l2_errors

from .run import Workdir

SHELL = LameShell(a=1.0, b=2.0, p=1.0, E=1.0, nu=0.3)
"""The benchmark problem (issue 41's acceptance problem, unit data)."""

MESHES = "2,3,4,6,8,12,16"
"""Default refinement sequence: n = m (elements per block edge over the angles and
radially); n = 16 (161,667 DOFs) takes SPOOLES about 2 minutes on 2 threads here (its
iterative solver 25 s); SPOOLES's time grew as DOFs^2.2 from n = 12 to 16."""

# Natural coordinates of the 20 nodes of a C3D20 in CalculiX's (Abaqus's) order: corners
# of zeta = -1 then zeta = +1 (counter-clockwise seen from +zeta), the mid-sides of the
# bottom edges, of the top edges, then of the edges along zeta.
NODES20 = np.array([
    [-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
    [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1],
    [0, -1, -1], [1, 0, -1], [0, 1, -1], [-1, 0, -1],
    [0, -1, 1], [1, 0, 1], [0, 1, 1], [-1, 0, 1],
    [-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], dtype=float)

INNER_FACE = "P1"
"""*DLOAD label of the face zeta = -1 (nodes 1-2-3-4), the inner sphere in this mesh."""


def shape20(xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Shape functions of the 20-node serendipity hexahedron at natural coordinates
    ``xi`` (g, 3): values (g, 20) and derivatives d N / d xi (g, 20, 3).

    Corner i (xi_i, eta_i, zeta_i in {-1, 1}):
    ``N = (1 + xi xi_i)(1 + eta eta_i)(1 + zeta zeta_i)(xi xi_i + eta eta_i + zeta zeta_i - 2) / 8``;
    mid-side node with xi_i = 0: ``N = (1 - xi^2)(1 + eta eta_i)(1 + zeta zeta_i) / 4``,
    and likewise with eta_i = 0 or zeta_i = 0."""
    xi = np.atleast_2d(np.asarray(xi, dtype=float))
    c = NODES20
    s = xi[:, None, :] * c[None, :, :]  # (g, 20, 3): xi xi_i, eta eta_i, zeta zeta_i
    lin = 1.0 + s
    N = np.empty((len(xi), 20))
    dN = np.empty((len(xi), 20, 3))
    corner = np.all(c != 0, axis=1)
    # corners
    prod = lin[:, corner].prod(axis=2)
    q = s[:, corner].sum(axis=2) - 2.0
    N[:, corner] = prod * q / 8.0
    for d in range(3):
        others = lin[:, corner][:, :, [e for e in range(3) if e != d]].prod(axis=2)
        dN[:, corner, d] = c[corner, d] * (others * q + prod) / 8.0
    # mid-sides: the zero coordinate is quadratic, the two others linear
    for k in np.flatnonzero(~corner):
        z = int(np.flatnonzero(c[k] == 0)[0])
        others = [e for e in range(3) if e != z]
        bubble = 1.0 - xi[:, z]**2
        l1, l2 = lin[:, k, others[0]], lin[:, k, others[1]]
        N[:, k] = bubble * l1 * l2 / 4.0
        dN[:, k, z] = -2.0 * xi[:, z] * l1 * l2 / 4.0
        dN[:, k, others[0]] = bubble * c[k, others[0]] * l2 / 4.0
        dN[:, k, others[1]] = bubble * l1 * c[k, others[1]] / 4.0
    return N, dN


def gauss_cube(n: int) -> tuple[np.ndarray, np.ndarray]:
    """The ``n x n x n`` Gauss-Legendre rule on [-1, 1]^3, xi fastest (CalculiX's order):
    points (n^3, 3) and weights (n^3,)."""
    g, w = np.polynomial.legendre.leggauss(n)
    Z, Y, X = np.meshgrid(g, g, g, indexing="ij")
    WZ, WY, WX = np.meshgrid(w, w, w, indexing="ij")
    return np.stack([X, Y, Z], axis=-1).reshape(-1, 3), (WX * WY * WZ).reshape(-1)


def _directions(block: int, ta: np.ndarray, tb: np.ndarray) -> np.ndarray:
    """Unit directions of block ``block`` (0: x largest, 1: y, 2: z) at the tangents
    ``ta``, ``tb`` of its two angles: component ``block`` is 1, the next (cyclically)
    ``ta``, the one after ``tb``, then normalized."""
    v = np.empty((*np.shape(ta), 3))
    v[..., block] = 1.0
    v[..., (block + 1) % 3] = ta
    v[..., (block + 2) % 3] = tb
    # the same sum in every block (1 + ta^2 + tb^2, in that order): a node on a face
    # shared by two blocks gets the same coordinates from both
    lo, hi = np.minimum(ta, tb), np.maximum(ta, tb)
    return v / np.sqrt(1.0 + lo * lo + hi * hi)[..., None]


def sphere_mesh(n: int, m: int, a: float = SHELL.a, b: float = SHELL.b) -> dict:
    """The C3D20 mesh of the shell octant: three cube-sphere blocks of ``n x n x m``
    elements (module docstring). Returns ``nodes`` (N, 3), ``elements`` (E, 20; 1-based
    node numbers in CalculiX's order, zeta radial: face 1-2-3-4 on the inner sphere),
    ``sets`` (``NX0``, ``NY0``, ``NZ0``: the nodes on the symmetry planes, exactly zero
    there; ``NINNER``, ``NOUTER``: the nodes on the spheres; 1-based) and ``blocks``
    (E,: the block of each element)."""
    if n < 1 or m < 1:
        raise ValueError(f"sphere mesh: need n, m >= 1, got {n}, {m}")
    k = np.arange(2 * n + 1)
    t = np.tan(0.25 * np.pi * k / (2 * n))
    t[0], t[-1] = 0.0, 1.0  # exact ends: the symmetry planes and the blocks' common faces
    r = a + (b - a) * np.arange(2 * m + 1) / (2 * m)
    r[-1] = b
    points, elements, blocks = [], [], []
    offset = 0
    for block in range(3):
        gi, gj, gk = np.meshgrid(k, k, np.arange(2 * m + 1), indexing="ij")
        keep = ((gi % 2) + (gj % 2) + (gk % 2)) <= 1  # no node where two indices are odd
        ids = -np.ones(gi.shape, dtype=int)
        ids[keep] = offset + np.arange(int(keep.sum()))
        offset += int(keep.sum())
        d = _directions(block, t[gi[keep]], t[gj[keep]])
        points.append(r[gk[keep]][:, None] * d)
        ei, ej, ek = np.meshgrid(np.arange(n), np.arange(n), np.arange(m), indexing="ij")
        ei, ej, ek = ei.ravel(), ej.ravel(), ek.ravel()
        loc = NODES20.astype(int) + 1  # 0, 1, 2 along each direction
        conn = ids[2 * ei[:, None] + loc[None, :, 0], 2 * ej[:, None] + loc[None, :, 1],
                   2 * ek[:, None] + loc[None, :, 2]]
        elements.append(conn)
        blocks.append(np.full(len(conn), block))
    x = np.concatenate(points)
    conn = np.concatenate(elements)
    # merge the nodes the blocks share (the same coordinates to round-off): each group of
    # coincident nodes (two, or three on the diagonal) is a clique of pairs, so every node
    # of it is given the group's lowest index directly
    pairs = cKDTree(x).query_pairs(1e-9 * b, output_type="ndarray")
    rep = np.arange(len(x))
    if len(pairs):
        np.minimum.at(rep, pairs.max(axis=1), pairs.min(axis=1))
    unique = np.unique(rep)
    number = -np.ones(len(x), dtype=int)
    number[unique] = np.arange(len(unique))
    nodes = x[unique]
    conn = number[rep[conn]] + 1
    radius = np.linalg.norm(nodes, axis=1)
    sets = {"NX0": np.flatnonzero(nodes[:, 0] == 0.0) + 1,
            "NY0": np.flatnonzero(nodes[:, 1] == 0.0) + 1,
            "NZ0": np.flatnonzero(nodes[:, 2] == 0.0) + 1,
            "NINNER": np.flatnonzero(np.abs(radius - a) <= 1e-12 * a) + 1,
            "NOUTER": np.flatnonzero(np.abs(radius - b) <= 1e-12 * b) + 1}
    return {"nodes": nodes, "elements": conn, "sets": sets, "blocks": np.concatenate(blocks),
            "n": n, "m": m}


def element_geometry(nodes: np.ndarray, elements: np.ndarray, rule: int = 3) -> dict:
    """For every element (1-based ``elements`` (E, 20) into ``nodes``) at the ``rule^3``
    Gauss points: points ``x`` (E, g, 3), the inverse Jacobians d xi / d x (E, g, 3, 3),
    ``det`` J (E, g) and the weights w det J (E, g); the shape functions ``N`` (g, 20)
    and ``dN`` (g, 20, 3)."""
    q, wq = gauss_cube(rule)
    N, dN = shape20(q)
    X = nodes[elements - 1]  # (E, 20, 3)
    J = np.einsum("ena,gnb->egab", X, dN)  # dx_a / dxi_b
    det = np.linalg.det(J)
    return {"x": np.einsum("gn,ena->ega", N, X), "jinv": np.linalg.inv(J), "det": det,
            "weights": det * wq, "N": N, "dN": dN}


def field_at_points(geo: dict, elements: np.ndarray, u: np.ndarray, E: float,
                    nu: float) -> tuple[np.ndarray, np.ndarray]:
    """The C3D20 field of nodal displacements ``u`` (N, 3) at the points of ``geo``
    (:func:`element_geometry`): displacements (E, g, 3) and Hooke's stress of their
    gradient (E, g, 3, 3)."""
    U = u[elements - 1]  # (E, 20, 3)
    uh = np.einsum("gn,ena->ega", geo["N"], U)
    dudxi = np.einsum("ena,gnb->egab", U, geo["dN"])
    grad = np.einsum("egab,egbc->egac", dudxi, geo["jinv"])
    return uh, hooke(grad, E, nu)


def field_errors(nodes: np.ndarray, elements: np.ndarray, u: np.ndarray,
                 shell: LameShell = SHELL, rule: int = 3) -> tuple[float, float]:
    """``(e_u, e_sigma)`` of the C3D20 field of nodal displacements ``u`` against
    ``shell``, by the ``rule^3`` Gauss rule of every element (module docstring)."""
    geo = element_geometry(nodes, elements, rule)
    uh, sh = field_at_points(geo, elements, u, shell.E, shell.nu)
    x = geo["x"].reshape(-1, 3)
    return relative_l2_errors(geo["weights"].ravel(), uh.reshape(-1, 3), shell.displacement(x),
                              sh.reshape(-1, 3, 3), shell.stress(x))


def _lines(ids: np.ndarray, per_line: int = 12) -> list[str]:
    ids = [int(v) for v in ids]
    return [", ".join(str(v) for v in ids[i:i + per_line]) for i in range(0, len(ids), per_line)]


def write_input(path: Path, mesh: dict, shell: LameShell = SHELL, solver: str = "") -> None:
    """The CalculiX input of ``mesh`` (:func:`sphere_mesh`): C3D20R, the symmetry
    conditions, the pressure on the inner faces (*DLOAD P1), one linear static step with
    ccx's default solver (SPOOLES in Debian's ccx) or ``solver`` (*STATIC, SOLVER=...);
    prints the nodal displacements and the integration-point stresses to the .dat."""
    nodes, conn, sets = mesh["nodes"], mesh["elements"], mesh["sets"]
    inner = np.arange(1, len(conn) + 1).reshape(3, mesh["n"], mesh["n"], mesh["m"])[..., 0].ravel()
    out = ["*HEADING", f"thick sphere octant a={shell.a:g} b={shell.b:g}: C3D20R, "
           f"{mesh['n']}x{mesh['n']}x{mesh['m']} per block, 3 blocks", "*NODE, NSET=NALL"]
    out += [f"{i + 1}, {x:.16g}, {y:.16g}, {z:.16g}" for i, (x, y, z) in enumerate(nodes)]
    out.append("*ELEMENT, TYPE=C3D20R, ELSET=EALL")
    for e, c in enumerate(conn):  # at most 16 entries per line: the element's line continues
        out.append(f"{e + 1}, " + ", ".join(str(int(v)) for v in c[:15]) + ",")
        out.append(", ".join(str(int(v)) for v in c[15:]))
    for name in ("NX0", "NY0", "NZ0"):
        out.append(f"*NSET, NSET={name}")
        out += _lines(sets[name])
    out.append("*ELSET, ELSET=EINNER")
    out += _lines(inner)
    out += ["*MATERIAL, NAME=STEEL", "*ELASTIC", f"{shell.E:.16g}, {shell.nu:.16g}",
            "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL",
            "*BOUNDARY", "NX0, 1, 1, 0.", "NY0, 2, 2, 0.", "NZ0, 3, 3, 0.",
            "*STEP", f"*STATIC, SOLVER={solver}" if solver else "*STATIC",
            "*DLOAD", f"EINNER, {INNER_FACE}, {shell.p:.16g}",
            "*NODE PRINT, NSET=NALL", "U",
            "*EL PRINT, ELSET=EALL", "S",
            "*END STEP"]
    path.write_text("\n".join(out) + "\n")


def dat_tables(path: Path, heads: tuple[str, ...]) -> dict[str, list[list[float]]]:
    """The rows of numbers under each block of a ccx .dat whose title starts with one of
    ``heads`` ("displacements", "stresses", "total force", ...), the blocks of one title
    merged in order (a later increment's row of a node comes after the earlier ones)."""
    rows: dict[str, list[list[float]]] = {h: [] for h in heads}
    mode = None
    for line in path.read_text().splitlines():
        head = line.strip()
        title = next((h for h in heads if head.startswith(h)), None)
        if title is not None:
            mode = title
            continue
        parts = head.split()
        if not parts:
            continue
        try:
            vals = [float(v) for v in parts]
        except ValueError:
            mode = None
            continue
        if mode is not None:
            rows[mode].append(vals)
    return rows


def parse_dat(path: Path, n_nodes: int, n_elements: int) -> tuple[np.ndarray, np.ndarray]:
    """The last step's nodal displacements (n_nodes, 3) and integration-point stresses
    (n_elements, 8, 3, 3) of a .dat written by :func:`write_input`'s *NODE PRINT and
    *EL PRINT (stresses in the order xx, yy, zz, xy, xz, yz)."""
    u = np.full((n_nodes, 3), np.nan)
    s = np.full((n_elements, 8, 6), np.nan)
    tables = dat_tables(path, ("displacements", "stresses"))
    for vals in tables["displacements"]:
        if len(vals) == 4:
            u[int(vals[0]) - 1] = vals[1:]
    for vals in tables["stresses"]:
        if len(vals) == 8:
            s[int(vals[0]) - 1, int(vals[1]) - 1] = vals[2:]
    if np.isnan(u).any() or np.isnan(s).any():
        raise ValueError(f"{path}: incomplete displacements or stresses")
    sig = np.empty((n_elements, 8, 3, 3))
    for (i, j), k in {(0, 0): 0, (1, 1): 1, (2, 2): 2, (0, 1): 3, (0, 2): 4, (1, 2): 5}.items():
        sig[..., i, j] = sig[..., j, i] = s[..., k]
    return u, sig


def thread_environment(threads: int) -> dict[str, str]:
    """The environment of a ccx run on ``threads`` threads: OMP_NUM_THREADS,
    CCX_NPROC_STIFFNESS, CCX_NPROC_RESULTS, CCX_NPROC_EQUATION_SOLVER and
    OPENBLAS_NUM_THREADS all set to it (ccx's log says what it used: "Using up to 2
    cpu(s) for spooles.", for the stiffness, the stresses)."""
    t = str(int(threads))
    return dict(os.environ, OMP_NUM_THREADS=t, CCX_NPROC_STIFFNESS=t, CCX_NPROC_RESULTS=t,
                CCX_NPROC_EQUATION_SOLVER=t, OPENBLAS_NUM_THREADS=t)


def solver_lines(log: str) -> list[str]:
    """The lines of a ccx log that name its equation solver and its threads there."""
    keep = re.compile(r"(?i)(solv|spooles)")
    return [ln.strip() for ln in log.splitlines() if keep.search(ln)]


def run_sphere(exe: str, w: Workdir, n: int, m: int, threads: int = 2,
               shell: LameShell = SHELL, solver: str = "") -> dict:
    """Mesh, write, run ccx (the process timed) and measure one mesh ``n x n x m`` per
    block (``solver``: as :func:`write_input`); returns the row of the table (wall
    seconds, sizes, errors)."""
    d = w.path / "calculix-sphere"
    d.mkdir(exist_ok=True)
    stem = f"sphere-n{n}-m{m}-t{threads}" + (f"-{solver.replace(' ', '_').lower()}" if solver else "")
    mesh = sphere_mesh(n, m, shell.a, shell.b)
    write_input(d / f"{stem}.inp", mesh, shell, solver)
    t0 = time.perf_counter()
    proc = subprocess.run([exe, "-i", stem], cwd=d, capture_output=True, text=True,
                          env=thread_environment(threads))
    wall = time.perf_counter() - t0
    log = proc.stdout + proc.stderr
    (d / f"{stem}.log").write_text(log)
    if proc.returncode != 0 or "Job finished" not in proc.stdout:
        raise RuntimeError(f"ccx {stem} failed; see {d / f'{stem}.log'}")
    nodes, conn = mesh["nodes"], mesh["elements"]
    u, sig_ip = parse_dat(d / f"{stem}.dat", len(nodes), len(conn))
    eu, es = field_errors(nodes, conn, u, shell)
    # ccx's own stresses at its 2 x 2 x 2 points, and ours there (the same field?)
    geo2 = element_geometry(nodes, conn, 2)
    _, sh2 = field_at_points(geo2, conn, u, shell.E, shell.nu)
    x2 = geo2["x"].reshape(-1, 3)
    exact2 = shell.stress(x2)
    w2 = geo2["weights"].ravel()
    es_ip = relative_l2_error(w2, sig_ip.reshape(-1, 3, 3), exact2)
    es_2 = relative_l2_error(w2, sh2.reshape(-1, 3, 3), exact2)
    agree = float(np.abs(sh2 - sig_ip).max() / np.abs(exact2).max())
    return {"n": n, "m": m, "elements": len(conn), "nodes": len(nodes), "dofs": 3 * len(nodes),
            "wall": wall, "threads": threads, "e_u": eu, "e_sigma": es, "e_sigma_ip": es_ip,
            "e_sigma_2x2x2": es_2, "ip_agreement": agree, "solver": solver or "default",
            "log": solver_lines(log)}


def rates(rows: list[dict], key: str) -> list[float]:
    """Observed orders between successive rows: ``-d log e / d log h`` with the mesh size
    h taken as elements^(-1/3) (= 1/n up to a constant when n = m: the order in h); NaN
    for the first row."""
    out = [float("nan")]
    for p, q in zip(rows[:-1], rows[1:], strict=True):
        out.append(-3.0 * np.log(q[key] / p[key]) / np.log(q["elements"] / p["elements"]))
    return out


def parse_meshes(spec: str) -> list[tuple[int, int]]:
    """``'2,4,8x4'`` -> [(2, 2), (4, 4), (8, 4)]: n (per block edge over the angles) and
    m (radially; n when left out)."""
    out = []
    for item in spec.split(","):
        n, _, m = item.strip().partition("x")
        try:
            nm = (int(n), int(m or n))
        except ValueError:
            raise SystemExit(f"bench: sphere mesh {item!r}: expected n or nxm") from None
        if min(nm) < 1:
            raise SystemExit(f"bench: sphere mesh {item!r}: n and m must be >= 1")
        out.append(nm)
    return out


def parse_solvers(spec: str) -> list[str]:
    """``'default,ITERATIVE SCALING'`` -> ['', 'ITERATIVE SCALING']: ccx's default solver
    ('' or 'default') or a *STATIC SOLVER= value."""
    known = ("", "SPOOLES", "ITERATIVE SCALING", "ITERATIVE CHOLESKY", "PARDISO", "PASTIX")
    out = []
    for item in spec.split(","):
        s = " ".join(item.split()).upper()
        s = "" if s == "DEFAULT" else s
        if s not in known:
            raise SystemExit(f"bench: ccx solver {item!r}: expected default or one of {known[1:]}")
        out.append(s)
    return out


def table(rows: list[dict]) -> list[str]:
    """The printed table of :func:`section_sphere`, rates between successive rows of the
    same solver."""
    lines = [f"{'solver':17s} {'mesh':10s} {'elems':>6s} {'nodes':>6s} {'DOFs':>7s} {'wall s':>7s} "
             f"{'e_u':>9s} {'rate':>5s} {'e_sigma':>9s} {'rate':>5s} {'e_sig ccx ip':>12s}"]
    for solver in dict.fromkeys(r["solver"] for r in rows):
        sel = [r for r in rows if r["solver"] == solver]
        for r, a, b in zip(sel, rates(sel, "e_u"), rates(sel, "e_sigma"), strict=True):
            mesh = f"{r['n']}x{r['n']}x{r['m']}"
            lines.append(f"{solver.lower():17s} {mesh:10s} {r['elements']:6d} "
                         f"{r['nodes']:6d} {r['dofs']:7d} {r['wall']:7.2f} {r['e_u']:9.3e} {a:5.2f} "
                         f"{r['e_sigma']:9.3e} {b:5.2f} {r['e_sigma_ip']:12.3e}")
    return lines


SOLVERS = "default,ITERATIVE SCALING"
"""Default solvers of the section: ccx's default (SPOOLES in Debian's ccx 2.20, a direct
factorization) and its preconditioned conjugate gradients with diagonal scaling, 3.5-6x
faster on the finer meshes here at the same stress error (less accurate displacements)."""


def section_sphere(w: Workdir, meshes: str = MESHES, threads: int = 2,
                   solvers: str = SOLVERS) -> dict:
    """CalculiX on the thick sphere for every solver of ``solvers`` (:func:`parse_solvers`)
    and mesh of ``meshes`` (:func:`parse_meshes`); prints the table and returns its rows
    (with the rates)."""
    from .ccx import ensure_ccx
    from .run import header
    header("7. CalculiX (C3D20R) on the thick spherical shell under internal pressure (octant, "
           f"a = {SHELL.a:g}, b = {SHELL.b:g},\n   p = {SHELL.p:g}, E = {SHELL.E:g}, nu = "
           f"{SHELL.nu:g}) against Lame; C3D20 field at 3x3x3 Gauss points, relative L2")
    exe = ensure_ccx()
    if exe is None:
        return {"available": False}
    rows: list[dict] = []
    out: dict = {"available": True, "threads": threads, "rows": rows}
    print(table([])[0], flush=True)
    for solver in parse_solvers(solvers):
        for n, m in parse_meshes(meshes):
            try:
                r = run_sphere(exe, w, n, m, threads, solver=solver)
            except Exception as err:  # noqa: BLE001 - report and go on with the next mesh
                print(f"{solver or 'default'} {n}x{n}x{m}: failed: {err}", flush=True)
                continue
            rows.append(r)
            print(table(rows)[-1], flush=True)
    for solver in dict.fromkeys(r["solver"] for r in rows):
        sel = [r for r in rows if r["solver"] == solver]
        for r, a, b in zip(sel, rates(sel, "e_u"), rates(sel, "e_sigma"), strict=True):
            r["rate_u"], r["rate_sigma"] = a, b
        print(f"{solver}: " + "; ".join(sel[-1]["log"]))
    if rows:
        print(f"\nmesh: n x n x m elements per block, 3 blocks (cube sphere); rate: -dlog e / "
              f"dlog h, h = elements^(-1/3) (quadratic\nelements: 3 for u, 2 for sigma); e_sig ccx "
              f"ip: ccx's own stresses at its 2x2x2 points (sum of w det J), not the 3x3x3 field\n"
              f"measure; wall: the ccx process, {threads} thread(s) (OMP_NUM_THREADS, CCX_NPROC_*), "
              f"one run each")
        print("max |sigma ours - sigma ccx| / max |sigma| at ccx's points: "
              + ", ".join(f"{r['ip_agreement']:.1e}" for r in rows))
    return out
