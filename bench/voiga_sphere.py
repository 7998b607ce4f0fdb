"""Section 8: voiga on the thick spherical shell of section 7 (the exact rational NURBS
octant of ``pre.solids.shell_octant``, a = 1, b = 2, inner pressure 1, E = 1, nu = 0.3,
symmetry on the three cut planes), k-refined degree p in all directions, and the match
against CalculiX at equal stress error.

The errors are the measure of section 7 (``post.lame``): relative L2 norms of the
displacement and of the stress (Frobenius; Hooke's law of the displacement gradient)
over the reference volume, here by Gauss quadrature of p + 2 points per direction in
every knot span of the exact octant, from the result file's bulk patch and
displacements (Np layouts: the displacement field is a NURBS volume on the bulk's
knots and weights). The wall time is the voiga process's, as ccx's is.
"""

from __future__ import annotations

import subprocess
import time
from pathlib import Path

import h5py
import numpy as np

from post.lame import LameShell, hooke, relative_l2_errors
from pre.solids import shell_octant, write_volumes
from pre.volume import Volume, jacobian_grid

from .ccx_sphere import SHELL
from .run import VOIGA, Workdir

MESHES = "2:2,2:4,2:6,3:2,3:3,3:4,3:6,4:3,4:4"
"""Degree:elements per direction of the runs (p:n)."""

CASE = """&case
  title = 'sphere p{p} n{n}', geometry = 'geometry.h5', output = '{stem}.h5', n_bodies = 1
  overwrite = .true.
/
&body
  name = 'shell', material = 'linear', youngs_modulus = {E}, poisson_ratio = {nu},
  degree_xi = {p}, degree_eta = {p}, degree_zeta = {p}, nel_xi = {n}, nel_eta = {n}, nel_zeta = {n}
/
&solver
  n_steps = 1
/
&dirichlet
  body = 'shell', face = 'start', fix_y = .true.
/
&dirichlet
  body = 'shell', face = 'end', fix_x = .true.
/
&dirichlet
  body = 'shell', face = 'equator', fix_z = .true.
/
&pressure
  body = 'shell', face = 'inner', p = {pressure}
/
"""


def parse_meshes(spec: str) -> list[tuple[int, int]]:
    """``'2:4,3:6'`` -> ``[(2, 4), (3, 6)]`` (degree, elements per direction)."""
    out = []
    for item in spec.split(","):
        p, n = item.strip().split(":")
        if int(p) < 2 or int(n) < 1:
            raise ValueError(f"sphere mesh {item!r}: need degree >= 2 (the exact geometry) and n >= 1")
        out.append((int(p), int(n)))
    return out


def write_case(folder: Path, p: int, n: int, shell: LameShell = SHELL) -> Path:
    """The geometry (once) and the case of degree ``p`` with ``n`` elements per direction."""
    folder.mkdir(parents=True, exist_ok=True)
    if not (folder / "geometry.h5").exists():
        write_volumes(folder / "geometry.h5", {"shell": shell_octant(shell.a, shell.b)}, scene="sphere")
    stem = f"sphere-p{p}-n{n}"
    case = folder / f"{stem}.nml"
    case.write_text(CASE.format(p=p, n=n, stem=stem, E=shell.E, nu=shell.nu, pressure=shell.p))
    return case


def run_voiga(case: Path) -> float:
    """Run ``case`` (exit 0 asserted); the process's wall seconds."""
    t0 = time.perf_counter()
    proc = subprocess.run([str(VOIGA), str(case), "--quiet"], capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RuntimeError(f"voiga {case.name} failed: {proc.stderr.strip()}")
    return wall


def _gauss_axis(knots: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """``n`` Gauss points and weights in every knot span of ``knots``."""
    g, w = np.polynomial.legendre.leggauss(n)
    u = np.unique(knots)
    pts = [0.5 * (a + b) + 0.5 * (b - a) * g for a, b in zip(u[:-1], u[1:], strict=True)]
    wts = [0.5 * (b - a) * w for a, b in zip(u[:-1], u[1:], strict=True)]
    return np.concatenate(pts), np.concatenate(wts)


def result_errors(result: Path, shell: LameShell = SHELL) -> dict:
    """``e_u``, ``e_sigma`` and ``dofs`` of the last step of a sphere run (Np layout)."""
    with h5py.File(result, "r") as f:
        body = f["bodies/shell"]
        bulk = body["bulk"]
        degree = tuple(int(d) for d in bulk["degree"][()])
        knots = [bulk[f"knots_{d}"][()] for d in ("xi", "eta", "zeta")]
        cp, w = bulk["control_points"][()], bulk["weights"][()]
        last = max(f["steps"], key=int)
        u = f["steps"][last]["displacement"][()]
        dofs = int(f.attrs["n_dofs"])
    if "layer" in body or u.size != cp.size:
        raise ValueError(f"{result}: a VO layout; the sphere measure reads Np layouts")
    geometry = Volume(degree, *knots, cp, w)
    field = Volume(degree, *knots, u.reshape(cp.shape), w)
    axes = [_gauss_axis(k, p + 2) for k, p in zip(knots, degree, strict=True)]
    x, jac = jacobian_grid(geometry, axes[0][0], axes[1][0], axes[2][0])
    u_h, du = jacobian_grid(field, axes[0][0], axes[1][0], axes[2][0])
    weights = (axes[2][1][:, None, None] * axes[1][1][None, :, None] * axes[0][1][None, None, :]
               * np.abs(np.linalg.det(jac)))
    grad = du @ np.linalg.inv(jac)
    x, u_h, grad, weights = x.reshape(-1, 3), u_h.reshape(-1, 3), grad.reshape(-1, 3, 3), weights.ravel()
    eu, es = relative_l2_errors(weights, u_h, shell.displacement(x), hooke(grad, shell.E, shell.nu),
                                shell.stress(x))
    return {"e_u": eu, "e_sigma": es, "dofs": dofs}


def run_mesh(w: Workdir, p: int, n: int) -> dict:
    """One run and its errors: the row of the table."""
    case = write_case(w.path / "voiga-sphere", p, n)
    wall = run_voiga(case)
    row = {"p": p, "n": n, "wall": wall, **result_errors(case.with_suffix(".h5"))}
    return row


def table(rows: list[dict]) -> list[str]:
    lines = [f"{'p':>2} {'n':>3} {'DOFs':>8} {'wall s':>8} {'e_u':>10} {'e_sigma':>10}"]
    lines += [f"{r['p']:2d} {r['n']:3d} {r['dofs']:8d} {r['wall']:8.3f} {r['e_u']:10.3e} {r['e_sigma']:10.3e}"
              for r in rows]
    return lines


def cheapest_at(rows: list[dict], e_sigma: float) -> dict | None:
    """The fastest voiga row whose stress error is at most ``e_sigma``."""
    ok = [r for r in rows if r["e_sigma"] <= e_sigma]
    return min(ok, key=lambda r: r["wall"]) if ok else None


def section_voiga_sphere(w: Workdir, meshes: str = MESHES, calculix: dict | None = None,
                         repeat: int = 3) -> dict:
    """voiga on the sphere for every ``p:n`` of ``meshes``; with section 7's rows
    (``calculix``), for each CalculiX run the fastest voiga run at an equal or smaller
    stress error, the pair timed again ``repeat`` times interleaved (voiga, ccx, voiga,
    ...; medians), and the ratio."""
    from .run import header
    header("8. voiga on the thick spherical shell of section 7 (exact NURBS octant, degree p, "
           "n elements per direction),\n   the same measure; and against CalculiX at equal stress error")
    if not VOIGA.exists():
        print(f"voiga not built ({VOIGA}); skipped")
        return {"available": False}
    rows = []
    print(table([])[0], flush=True)
    for p, n in parse_meshes(meshes):
        rows.append(run_mesh(w, p, n))
        print(table(rows)[-1], flush=True)
    out: dict = {"available": True, "rows": rows, "matches": []}
    if calculix and calculix.get("available"):
        out["matches"] = match_calculix(w, rows, calculix, repeat)
    return out


def match_calculix(w: Workdir, rows: list[dict], calculix: dict, repeat: int) -> list[dict]:
    """Each CalculiX row against the fastest voiga row at its stress error or below,
    re-timed interleaved; prints the ratios."""
    from .ccx import ensure_ccx
    from .ccx_sphere import run_sphere
    exe = ensure_ccx()
    matches = []
    print(f"\n{'ccx solver':>18} {'mesh':>6} {'e_sigma':>10} {'wall s':>8} | {'voiga p:n':>9} {'e_sigma':>10} "
          f"{'wall s':>8} | {'ccx / voiga':>11}")
    for c in calculix["rows"]:
        v = cheapest_at(rows, c["e_sigma"])
        if v is None or exe is None:
            continue
        case = write_case(w.path / "voiga-sphere", v["p"], v["n"])
        tv, tc = [], []
        for _ in range(repeat):
            tv.append(run_voiga(case))
            solver = "" if c["solver"] == "default" else c["solver"]
            tc.append(run_sphere(exe, w, c["n"], c["m"], c["threads"], solver=solver)["wall"])
        m = {"ccx": c, "voiga": v, "wall_voiga": float(np.median(tv)), "wall_ccx": float(np.median(tc))}
        m["ratio"] = m["wall_ccx"] / m["wall_voiga"]
        matches.append(m)
        print(f"{c['solver']:>18} {c['n']:>3}x{c['m']:<2} {c['e_sigma']:10.3e} {m['wall_ccx']:8.2f} | "
              f"{v['p']:>5}:{v['n']:<3} {v['e_sigma']:10.3e} {m['wall_voiga']:8.3f} | {m['ratio']:11.1f}",
              flush=True)
    return matches
