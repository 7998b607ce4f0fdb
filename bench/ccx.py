"""Section 5: CalculiX on the same Hertz problem, for a reference point on the cost of
a classical FE code at a given contact-pressure accuracy.

Quarter cylinder (R = 1, hole R = 0.05 as in the hertz scene, E = 1, nu = 0.3), CPE8
plane strain, meshed on the same graded parameter grid as voiga's hertz mesh m<k> (the
knot spans of the case file, each cut ``split`` times as in section 6, mapped through
the exact NURBS geometry: mid-side nodes on the exact arc). The flat is a block of CPE8
whose nodes are all fixed (rigid); contact is surface-to-surface with a linear
pressure-overclosure law of slope K = penalty x E (:data:`PENALTY`). u_y = -0.01 on the
top cut (y = 0), u_x = 0 on the symmetry cut (x = 0), five increments as voiga's five
steps.

The pressure is K * overclosure at 3 Gauss points of every quadratic slave edge (what
the surface-to-surface penalty applies), from the printed nodal displacements, taken per
reference length at the reference positions; the force from the reaction on the top cut.
The same post.hertz functions as ``python -m post hertz`` give the errors.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import time
from functools import partial
from pathlib import Path

import numpy as np

from .refine import split_grid, splits
from .run import Workdir

PENALTY = 1e4
"""Contact slope / E of the runs that give none: the stiffest that is still measured
faithfully and the most accurate of 1e3, 1e4, 1e5, 1e6 (m4: L2 1.50, 0.78, 0.80,
0.99 %; m5 1e4 0.40 %, 1e5 0.92 %). 1e3 limits the accuracy (its compliance E*/(K a) is
1.5 %). From 1e5 on the error does not fall: the stiffer law's pressure deviates more at
the last active points before the zone's edge, and the overclosure is read from
displacements printed to 7 digits (ccx's .dat), which K turns into noise of K x 5e-10
(0.1 % of p0 at 1e5, 1.2 % at 1e6)."""
UY = -0.01
E, NU = 1.0, 0.3


def ensure_ccx() -> str | None:
    """Path of ccx; installs calculix-ccx with apt-get if apt offers it and it is missing."""
    exe = shutil.which("ccx")
    if exe:
        return exe
    pol = subprocess.run(["apt-cache", "policy", "calculix-ccx"], capture_output=True, text=True)
    if "Candidate:" not in pol.stdout or "Candidate: (none)" in pol.stdout:
        print("bench: apt-cache policy calculix-ccx offers no candidate; skipping CalculiX")
        return None
    sudo = [] if os.geteuid() == 0 else ["sudo"]
    print("bench: installing calculix-ccx with apt-get", flush=True)
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    install = sudo + ["apt-get", "install", "-y", "-qq", "calculix-ccx"]
    if subprocess.run(install, env=env, capture_output=True).returncode != 0:
        # stale package lists: update once and retry
        subprocess.run(sudo + ["apt-get", "update", "-qq"], env=env, capture_output=True)
        subprocess.run(install, env=env, capture_output=True)
    exe = shutil.which("ccx")
    if exe is None:
        print("bench: installing calculix-ccx failed; skipping CalculiX")
    return exe


def cylinder_mesh(mesh: str, split: str = "1"):
    """Nodes (n, 2), CPE8 connectivity (nel, 8; 1-based), node sets and the elements of
    the outer arc: one CPE8 per knot span of hertz <mesh>, every span cut as ``split``
    says (:func:`bench.refine.splits`)."""
    from pre.nurbs import evaluate_patch
    from pre.scenes import hertz
    patch = hertz()["cylinder"]
    bx, be = split_grid(mesh, split)
    # parameter grid with the span midpoints (quadratic serendipity nodes)
    gx = np.empty(2 * len(bx) - 1)
    gx[0::2], gx[1::2] = bx, 0.5 * (bx[:-1] + bx[1:])
    ge = np.empty(2 * len(be) - 1)
    ge[0::2], ge[1::2] = be, 0.5 * (be[:-1] + be[1:])
    ids = -np.ones((len(gx), len(ge)), dtype=int)
    pairs = []
    for i in range(len(gx)):
        for j in range(len(ge)):
            if i % 2 and j % 2:
                continue
            ids[i, j] = len(pairs) + 1
            pairs.append((gx[i], ge[j]))
    pairs = np.array(pairs)
    xy = evaluate_patch(patch, pairs[:, 0], pairs[:, 1])
    # exact snapping of the cuts
    xy[np.isclose(pairs[:, 0], 0.0), 0] = 0.0
    xy[np.isclose(pairs[:, 0], 1.0), 1] = 0.0
    elems = []
    for a in range(len(bx) - 1):
        for b in range(len(be) - 1):
            i0, i1, j0, j1 = 2 * a, 2 * a + 2, 2 * b, 2 * b + 2
            # (eta, xi) is right-handed in the plane: corners in that order
            c = [ids[i0, j0], ids[i0, j1], ids[i1, j1], ids[i1, j0],
                 ids[i0, j0 + 1], ids[i0 + 1, j1], ids[i1, j0 + 1], ids[i0 + 1, j0]]
            elems.append(c)
    elems = np.array(elems)
    outer = ids[:, -1][ids[:, -1] > 0]
    sets = {"NSYM": ids[0, :][ids[0, :] > 0], "NTOP": ids[-1, :][ids[-1, :] > 0],
            "NOUTER": outer}
    outer_elems = np.array([k + 1 for k, (a, b) in enumerate(
        (a, b) for a in range(len(bx) - 1) for b in range(len(be) - 1)) if b == len(be) - 2])
    return xy, elems, sets, outer_elems


def signed_area(xy: np.ndarray, conn: np.ndarray) -> float:
    p = xy[conn[:4] - 1]
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def block_mesh(first_node: int, first_elem: int, nx: int = 40, ny: int = 2,
               x0: float = -0.0525, x1: float = 0.3475, y0: float = -1.1, y1: float = -1.0):
    """Rigid flat: CPE8 block [x0, x1] x [y0, y1], top face at y = -1."""
    gx, gy = np.linspace(x0, x1, 2 * nx + 1), np.linspace(y0, y1, 2 * ny + 1)
    ids = -np.ones((len(gx), len(gy)), dtype=int)
    nodes = []
    for i in range(len(gx)):
        for j in range(len(gy)):
            if i % 2 and j % 2:
                continue
            ids[i, j] = first_node + len(nodes)
            nodes.append((gx[i], gy[j]))
    elems, top = [], []
    for a in range(nx):
        for b in range(ny):
            i0, i1, j0, j1 = 2 * a, 2 * a + 2, 2 * b, 2 * b + 2
            elems.append([ids[i0, j0], ids[i1, j0], ids[i1, j1], ids[i0, j1],
                          ids[i0 + 1, j0], ids[i1, j0 + 1], ids[i0 + 1, j1], ids[i0, j0 + 1]])
            if b == ny - 1:
                top.append(first_elem + len(elems) - 1)
    return np.array(nodes), np.array(elems), top


def write_input(path: Path, mesh: str, split: str = "1", penalty: float = PENALTY) -> dict:
    """The CalculiX input of hertz <mesh> cut ``split``, contact slope ``penalty`` x E."""
    xy, conn, sets, outer_elems = cylinder_mesh(mesh, split)
    # orientation: counter-clockwise corners; the outer face of a cylinder element is
    # between corners 2 and 3 (eta = 1) -> face S2, flipped to S4 if reordered
    face = "S2"
    if signed_area(xy, conn[0]) < 0:
        conn = conn[:, [0, 3, 2, 1, 7, 6, 5, 4]]
        face = "S3"  # corners 1 4 3 2: the old 2-3 edge is now 3-4
    assert all(signed_area(xy, c) > 0 for c in conn[:5])
    bxy, bconn, btop = block_mesh(len(xy) + 1, len(conn) + 1)
    lines = ["*HEADING", f"hertz {mesh} x{split}: CPE8 quarter cylinder on a rigid flat", "*NODE"]
    lines += [f"{k + 1}, {x:.15g}, {y:.15g}" for k, (x, y) in enumerate(xy)]
    lines += [f"{len(xy) + k + 1}, {x:.15g}, {y:.15g}" for k, (x, y) in enumerate(bxy)]
    lines.append("*ELEMENT, TYPE=CPE8, ELSET=ECYL")
    lines += [f"{k + 1}, " + ", ".join(str(int(v)) for v in c) for k, c in enumerate(conn)]
    lines.append("*ELEMENT, TYPE=CPE8, ELSET=EBLOCK")
    lines += [f"{len(conn) + k + 1}, " + ", ".join(str(int(v)) for v in c)
              for k, c in enumerate(bconn)]

    def nset(name, ids):
        out = [f"*NSET, NSET={name}"]
        ids = [int(v) for v in ids]
        out += [", ".join(str(v) for v in ids[i:i + 12]) for i in range(0, len(ids), 12)]
        return out

    for name, ids in sets.items():
        lines += nset(name, ids)
    lines += nset("NBLOCK", range(len(xy) + 1, len(xy) + len(bxy) + 1))
    lines.append("*SURFACE, NAME=SSLAVE, TYPE=ELEMENT")
    lines += [f"{e}, {face}" for e in outer_elems]
    lines.append("*SURFACE, NAME=SMASTER, TYPE=ELEMENT")
    lines += [f"{e}, S3" for e in btop]
    lines += ["*MATERIAL, NAME=CYL", "*ELASTIC", f"{E}, {NU}",
              "*MATERIAL, NAME=RIGID", "*ELASTIC", f"{1e6 * E}, {NU}",
              "*SOLID SECTION, ELSET=ECYL, MATERIAL=CYL", "1.",
              "*SOLID SECTION, ELSET=EBLOCK, MATERIAL=RIGID", "1.",
              "*SURFACE INTERACTION, NAME=SI1",
              "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR", f"{penalty * E:.6g}, 1e-9, 1e-3",
              "*CONTACT PAIR, INTERACTION=SI1, TYPE=SURFACE TO SURFACE", "SSLAVE, SMASTER",
              "*BOUNDARY", "NBLOCK, 1, 2, 0.", "NSYM, 1, 1, 0.",
              "*STEP, INC=1000", "*STATIC", "0.2, 1.0, 1e-6, 0.2",
              "*BOUNDARY", f"NTOP, 2, 2, {UY}",
              "*NODE PRINT, NSET=NOUTER", "U",
              "*NODE PRINT, NSET=NTOP, TOTALS=ONLY", "RF",
              "*END STEP"]
    path.write_text("\n".join(lines) + "\n")
    return {"nodes": len(xy) + len(bxy), "cyl_nodes": len(xy), "elements": len(conn),
            "dofs": 2 * len(xy), "outer": sets["NOUTER"], "xy": xy}


def parse_dat(path: Path, info: dict) -> tuple[np.ndarray, np.ndarray, float]:
    """Last printed displacements of the outer nodes and the total reaction on the top."""
    disp: dict[int, tuple[float, float]] = {}
    rf = np.nan
    mode = None
    for line in path.read_text().splitlines():
        s = line.strip()
        if s.startswith("displacements"):
            mode, disp = "u", {}
            continue
        if s.startswith("total force"):
            mode = "rf"
            continue
        if not s:
            continue
        parts = s.split()
        try:
            vals = [float(v) for v in parts]
        except ValueError:
            mode = None if not s.startswith(("displacements", "total")) else mode
            continue
        if mode == "u" and len(vals) >= 3:
            disp[int(vals[0])] = (vals[1], vals[2])
        elif mode == "rf" and len(vals) >= 2:
            rf = vals[1]
    ids = [int(v) for v in info["outer"]]
    u = np.array([disp[i] for i in ids])
    x = info["xy"][np.array(ids) - 1] + u
    return x, u, rf


def edge_points(xn: np.ndarray, n_gauss: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """The outer edge through nodes ``xn`` (corner, mid, corner, mid, ... in xi order) at
    ``n_gauss`` Gauss points of every quadratic element edge, the points where the
    surface-to-surface penalty evaluates the overclosure: positions and derivatives
    d x / d g, both (n, 2)."""
    g, _ = np.polynomial.legendre.leggauss(n_gauss)
    n = np.stack([0.5 * g * (g - 1.0), 1.0 - g**2, 0.5 * g * (g + 1.0)], axis=1)
    dn = np.stack([g - 0.5, -2.0 * g, g + 0.5], axis=1)
    edges = [xn[2 * k:2 * k + 3] for k in range((len(xn) - 1) // 2)]
    return np.concatenate([n @ e for e in edges]), np.concatenate([dn @ e for e in edges])


def run_ccx(exe: str, w: Workdir, mesh: str, split: str = "1",
            penalty: float = PENALTY) -> dict:
    """One analysis (the whole ccx process timed, one thread) and its Hertz errors."""
    from post.hertz import compare_profile
    d = w.path / "calculix"
    d.mkdir(exist_ok=True)
    stem = f"hertz-{mesh}-x{split}-k{penalty:g}"
    inp = d / f"{stem}.inp"
    info = write_input(inp, mesh, split, penalty)
    env = dict(os.environ, OMP_NUM_THREADS="1")
    t0 = time.perf_counter()
    proc = subprocess.run([exe, "-i", inp.stem], cwd=d, capture_output=True, text=True, env=env)
    wall = time.perf_counter() - t0
    (d / f"{stem}.log").write_text(proc.stdout + proc.stderr)
    if proc.returncode != 0 or "Job finished" not in proc.stdout:
        raise RuntimeError(f"ccx {inp} failed; see {d / f'{stem}.log'}")
    xn, u, rf = parse_dat(d / f"{stem}.dat", info)
    x, dx = edge_points(xn)
    ref, dref = edge_points(xn - u)
    p = penalty * E * np.clip(-1.0 - x[:, 1], 0.0, None)  # per current length
    # as python -m post hertz: per reference length (times the stretch of the edge) at
    # the reference positions, against Hertz for the run's own force
    nominal = p * np.linalg.norm(dx, axis=1) / np.linalg.norm(dref, axis=1)
    h = compare_profile(ref[:, 0], nominal, 2.0 * abs(rf), E, NU, 1.0, half_model=True)
    return {"mesh": mesh, "split": split, "penalty": penalty, "dofs": info["dofs"],
            "elements": info["elements"], "wall": wall, "force": h.force, "a": h.a,
            "p0": h.p0, "a_error": h.a_error, "p0_error": h.p0_error, "p_max": h.p_max,
            "l2": h.l2_error, "active_points": int(np.count_nonzero(p > 0)),
            "iterations": iterations(proc.stdout)}


def iterations(stdout: str) -> int:
    """Newton iterations of a ccx run, from its log (one "iteration" line each)."""
    return sum(1 for line in stdout.splitlines() if line.strip().startswith("iteration "))


def short(v: float) -> str:
    """1e4 for 10000.0, 3.5e4 for 35000.0, 200 for 200.0."""
    m, e = f"{v:e}".split("e")
    m = m.rstrip("0").rstrip(".")
    return f"{v:g}" if abs(int(e)) < 3 else f"{m}e{int(e)}"


def parse_runs(spec: str, penalty: float = PENALTY) -> list[tuple[str, str, float]]:
    """``'m4:1:1e3,m5:2'`` -> [('m4', '1', 1000.0), ('m5', '2', penalty)]: mesh, split
    (:func:`bench.refine.splits`) and contact slope / E (``penalty`` when left out)."""
    out = []
    for item in spec.split(","):
        mesh, split, *k = item.strip().split(":")
        splits(split)
        if len(k) > 1:
            raise SystemExit(f"bench: CalculiX run {item!r}: expected mesh:split[:penalty]")
        slope = float(k[0]) if k else penalty
        if not slope > 0:
            raise SystemExit(f"bench: CalculiX run {item!r}: penalty must be > 0")
        out.append((mesh, split, slope))
    return out


def section_calculix(w: Workdir, runs: str, match: str, penalty: float = PENALTY,
                     repeat: int = 2) -> dict:
    """CalculiX on the runs ``runs`` (mesh:split[:penalty], ``penalty`` x E when left
    out); then ``match`` and voiga's hertz m4 NN2.2 (as committed, penalty 1e3, and with
    the automatic penalty) interleaved, best of ``repeat``, for the wall-time ratios."""
    from .run import header, interleaved_calls, reference_ratios, solve, voiga_reference
    header("5. CalculiX (CPE8 plane strain, surface-to-surface linear penalty, rigid flat) "
           "against voiga hertz m4 NN2.2;\n   same measure as python -m post hertz "
           "(pressure per reference length at reference positions)")
    exe = ensure_ccx()
    if exe is None:
        return {"available": False}
    print(f"{'code':6s} {'contact':13s} {'mesh':8s} {'dofs':>6s} {'iters':>5s} {'wall s':>8s} "
          f"{'P':>9s} {'L2 (ref.)':>10s} {'a_fit/a-1':>10s} {'p0_fit/p0-1':>12s}", flush=True)
    out: dict = {"available": True, "penalty": penalty, "runs": []}

    def line(r: dict) -> str:
        return (f"{'ccx':6s} {'penalty ' + short(r['penalty']):13s} "
                f"{r['mesh'] + ' x' + r['split']:8s} {r['dofs']:6d} {r['iterations']:5d} "
                f"{r['wall']:8.3f} {r['force']:9.6f} {r['l2']:10.5f} {r['a_error']:+10.4f} "
                f"{r['p0_error']:+12.4f}")

    for mesh, split, slope in parse_runs(runs, penalty):
        try:
            r = run_ccx(exe, w, mesh, split, slope)
        except Exception as err:  # noqa: BLE001 - report and go on with the next run
            print(f"ccx    {mesh}:{split}:{slope:g} failed: {err}", flush=True)
            continue
        print(line(r), flush=True)
        out["runs"].append(r)
    (mrun,) = parse_runs(match, penalty)
    cases = voiga_reference(w, "-ccxcmp")
    calls = {name: partial(solve, case) for name, case in cases.items()}
    calls["ccx"] = partial(run_ccx, exe, w, *mrun)
    try:
        best = interleaved_calls(calls, repeat)
    except Exception as err:  # noqa: BLE001 - the section ends, the bench goes on
        print(f"{match} (voiga m4 NN2.2 or ccx) failed: {err}; no ratio", flush=True)
        return out
    out["match"] = {"repeat": repeat, "ccx": best["ccx"],
                    **reference_ratios(best, cases, ["ccx"])}
    print("matched error, interleaved:")
    for name in cases:
        m = out["match"][name]
        print(f"{'voiga':6s} {name:13s} {'m4 NN2.2':8s} {m['dofs']:6d} {m['iterations']:5d} "
              f"{m['wall']:8.3f} {'':9s} {m['l2']:10.5f} {m['a_error']:+10.4f} "
              f"{m['p0_error']:+12.4f}")
    print(line(best["ccx"]))
    print(f"\nwall ccx {match} / voiga m4 NN2.2 (interleaved, best of {repeat}):")
    for name in cases:
        m = out["match"][name]
        print(f"  ccx / voiga {name:11s}: {m['ratio']['ccx']:7.2f}  (L2 ccx "
              f"{best['ccx']['l2']:.4%}, voiga {m['l2']:.4%})")
    print("wall: the whole process; OMP_NUM_THREADS=1 for both (ccx: SPOOLES); iters: Newton "
          "iterations (ccx: its log's);\npenalty: the contact slope / E; P: the full "
          "cylinder's force per length; dofs: 2 x the cylinder's nodes")
    return out
