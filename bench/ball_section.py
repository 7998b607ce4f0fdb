"""Section 9: voiga, Kratos (3D mortar) and CalculiX on the 3D Hertz sphere, in one run.

The problem and measure of ``python -m pre hertz3d`` / ``python -m post hertz3d``: the
ball octant R = 1, E = 1, nu = 0.3 pressed d = 0.01 onto a rigid flat (a/R = 0.10);
relative L2 of the nominal pressure (force per reference area at reference positions)
against Hertz for the run's own P over the disc r <= max(a, the farthest loaded point).
voiga's error is ``post hertz3d``'s: its control points' pressures (weighted gap over
D_A) interpolated at the faces' quadrature points. The peers' outputs become pressure
points in :mod:`bench.ball_pressure` the same way (nodal contact force over nodal area,
interpolated at 3 x 3 points per face; C3D20R: the penalty law at those points) and go
through the same :func:`post.hertz3d.disc_error`; "L2 nodes" is the peers' error at
their nodes alone (the issue's earlier figures), which misses what lies between them.

Every run is repeated ``repeat`` times, the repeats interleaved (all runs once, then all
again), and its fastest wall time (the whole process, one thread) kept. Then, for every
peer run, the fastest voiga run at equal or better error and the ratio of the wall times.
"""

from __future__ import annotations

import subprocess
import sys
from functools import partial
from pathlib import Path

from .ball_ogrid import parse_mesh
from .ball_peers import CCX_ELEMENTS, CCX_PENALTY, run_ccx, run_kratos
from .run import ROOT, Run, Workdir, header, solve

VOIGA_RUNS = ("m1:N2,m2:N2,m3:N2,m1:NN2.2,m2:NN2.2,m3:NN2.2,"
              "p1:N2,p2:N2,p3:N2,p4:N2,p1:NN2.2,p2:NN2.2")
"""voiga's default runs, mesh:layout: m<k> on the Cartesian grid, p<k> on the polar one
(``pre hertz3d --grid polar``; knot lines on circles about the contact, split at the
zone's edge)."""
PEER_RUNS = ("kratos:alm:amgcl:6x4x3x5,kratos:alm:amgcl:8x5x3x6,kratos:alm:amgcl:12x6x4x8,"
             "kratos:alm:amgcl:16x8x5x10,ccx:C3D20R:4x3x2x3:1e3,ccx:C3D20R:6x4x3x5:1e3,ccx:C3D8I:8x5x3x6,"
             "ccx:C3D8I:12x6x4x8,"
             "kratos:alm:amgcl:o4x8x6x8x2,kratos:alm:amgcl:o4x12x6x10x2,kratos:alm:amgcl:o4x24x6x14x1,"
             "kratos:alm:amgcl:o6x20x6x12x2,ccx:C3D20R:o3x8x4x6x2:1e3,ccx:C3D8I:o4x12x6x10x2:1e5,"
             "ccx:C3D8I:o6x20x6x12x2:1e5")
"""The peers' default runs, each within a few minutes on one thread. On the cube-sphere
meshes (:class:`bench.ball_mesh.BallMesh`): four Kratos meshes (4,212 to 37,350 DOFs),
CalculiX's C3D20R on two (5,190 and 15,846) and C3D8I on two (7,338 and 17,631). C3D20R
with the contact slope 1e3 E/R, C3D8I with 1e4 (each the better of the two: C3D20R
6x4x3x5 6.5 % at 1e3 against 10.8 % at 1e4, its faces' pressure alternating from node to
node under the stiffer law; C3D8I 8x5x3x6 9.6 % at 1e3, 9.3 % at 1e4, 9.2 % at 1e5 in 1.4
times the time, docs/performance-solids.md). On the O-grid meshes
(:class:`bench.ball_ogrid.OGridMesh`, rings on circles about the contact split at the
zone's edge, as voiga's polar meshes): Kratos on four (7,806 to 27,831 DOFs), C3D20R on
one (14,925) at 1e3 (o3x8x4x6x2 5.7 % at 3e2; o3x6x3x5x1 4.5 % at 1e3, 8.1 % at 3e3,
17.5 % at 1e4), C3D8I on two (10,710 and 27,831) at 1e5 (o4x12x6x10x2 2.29 % at 1e4,
2.09 % at 1e5 in 1.3 times the time); single runs, docs/performance-solids.md. The
syntax: code:method:solver:mesh (Kratos: alm or penalty, amgcl or sparse_lu) and
code:element:mesh[:penalty] (CalculiX); a mesh ``fine x rest x outer x radial``
(cube-sphere) or ``o<core>x<fine>x<rest>x<radial>x<edge>`` (O-grid)."""


def parse_peers(spec: str) -> list[tuple]:
    """``'kratos:alm:amgcl:8x5x3x6,ccx:C3D20R:o3x8x4x6x2:1e3'`` -> [('kratos', 'alm',
    'amgcl', BallMesh), ('ccx', 'C3D20R', OGridMesh, 1e3)] (:func:`bench.ball_ogrid.parse_mesh`)."""
    out: list[tuple] = []
    for item in (s.strip() for s in spec.split(",") if s.strip()):
        parts = item.split(":")
        if parts[0] == "kratos" and len(parts) == 4 and parts[1] in ("alm", "penalty"):
            out.append(("kratos", parts[1], parts[2], parse_mesh(parts[3])))
        elif parts[0] == "ccx" and len(parts) in (3, 4) and parts[1] in CCX_ELEMENTS:
            out.append(("ccx", parts[1], parse_mesh(parts[2]),
                        float(parts[3]) if len(parts) == 4 else CCX_PENALTY))
        else:
            raise SystemExit(f"bench: peer run {item!r}: expected kratos:alm|penalty:SOLVER:MESH "
                             f"or ccx:{'|'.join(CCX_ELEMENTS)}:MESH[:PENALTY]")
    return out


def voiga_cases(w: Workdir, runs: str) -> dict[str, Path]:
    """``python -m pre hertz3d`` cases of ``runs`` (mesh:layout) in <work>/hertz3d: meshes
    m<k> on the Cartesian grid, p<k> on the polar one (``--grid polar``, in
    <work>/hertz3d-polar: each grid has its own geometry.h5)."""
    pairs = [tuple(s.strip().split(":")) for s in runs.split(",") if s.strip()]
    cases = {}
    for grid in ("cartesian", "polar"):
        mine = [(m, lay) for m, lay in pairs if (m.startswith("p") == (grid == "polar"))]
        if not mine:
            continue
        meshes = sorted({m for m, _ in mine})
        layouts = sorted({lay for _, lay in mine})
        out = w.path / ("hertz3d" if grid == "cartesian" else "hertz3d-polar")
        cmd = [sys.executable, "-m", "pre", "hertz3d", str(out), "--grid", grid, "--mesh", *meshes,
               "--layout", *layouts]
        proc = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd)} failed: {proc.stderr.strip()[-400:]}")
        for mesh, layout in mine:
            path = out / f"{mesh}-{layout}.nml"
            if not path.exists():
                raise RuntimeError(f"pre hertz3d wrote no {path}")
            cases[f"voiga {layout} {mesh}"] = path
    return cases


def voiga_run(case: Path) -> dict:
    """One voiga run (:func:`bench.run.solve`, one thread) and ``post hertz3d``'s L2."""
    from post.hertz3d import hertz3d_comparison
    from post.reader import read_result
    r: Run = solve(case)
    h = hertz3d_comparison(read_result(r.result))
    return {"code": "voiga", "wall": r.wall, "dofs": r.n_dofs, "iterations": r.iterations,
            "l2": h.error.l2, "force": h.force, "a": h.a, "a_error": h.a_error, "p0_error": h.p0_error}


def peer_call(run: tuple, kratos_py: Path | None, ccx: str | None, w: Workdir):
    if run[0] == "kratos":
        return None if kratos_py is None else partial(run_kratos, kratos_py, w, run[3], run[1], run[2])
    return None if ccx is None else partial(run_ccx, ccx, w, run[2], run[1], run[3])


def peer_name(run: tuple) -> str:
    if run[0] == "kratos":
        return f"kratos {run[1]} {run[2]} {run[3].name}"
    return f"ccx {run[1]} {run[2].name}" + ("" if run[3] == CCX_PENALTY else f" K{run[3]:g}")


def interleave(calls: dict, repeat: int) -> dict:
    """Fastest of ``repeat`` runs of every call, the repeats interleaved; a failing call
    is reported and dropped (its error kept under ``failed``)."""
    best: dict = {}
    failed: dict = {}
    for k in range(repeat):
        for name, call in calls.items():
            if name in failed:
                continue
            try:
                r = call()
            except Exception as err:  # noqa: BLE001 - report, go on with the others
                failed[name] = str(err)
                print(f"{name}: failed: {err}", flush=True)
                continue
            print(f"  [{k + 1}/{repeat}] {name:34s} {r['wall']:8.2f} s  L2 {r['l2']:.3%}", flush=True)
            if name not in best or r["wall"] < best[name]["wall"]:
                best[name] = r
    return {"runs": best, "failed": failed}


def ratios(runs: dict, key: str = "l2") -> list[dict]:
    """For every peer run: the fastest voiga run at its error ``key`` or below (voiga's
    own L2), and peer / voiga."""
    voiga = {n: r for n, r in runs.items() if r["code"] == "voiga"}
    out = []
    for name, r in runs.items():
        if r["code"] == "voiga" or not r.get(key, float("nan")) >= 0:
            continue
        ok = [(v["wall"], n) for n, v in voiga.items() if v["l2"] <= r[key]]
        row = {"peer": name, "peer_l2": r[key], "peer_wall": r["wall"]}
        if ok:
            wall, n = min(ok)
            row.update(voiga=n, voiga_l2=voiga[n]["l2"], voiga_wall=wall, ratio=r["wall"] / wall)
        out.append(row)
    return out


def section_ball(w: Workdir, voiga_runs: str = VOIGA_RUNS, peer_runs: str = PEER_RUNS,
                 repeat: int = 2) -> dict:
    """The section (module docstring); returns the figures."""
    from .ccx import ensure_ccx
    from .kratos import ensure_kratos
    header("9. The 3D Hertz sphere: voiga (pre hertz3d, mortar), Kratos (3D mortar, trilinear "
           "hexahedra) and CalculiX\n   (C3D20R / C3D8I, surface-to-surface penalty); L2 of the "
           f"nominal pressure against Hertz; best of {repeat}, interleaved, one thread")
    peers = parse_peers(peer_runs)
    kratos_py = ensure_kratos() if any(p[0] == "kratos" for p in peers) else None
    ccx = ensure_ccx() if any(p[0] == "ccx" for p in peers) else None
    calls = {name: partial(voiga_run, case) for name, case in voiga_cases(w, voiga_runs).items()}
    skipped = []
    for p in peers:
        call = peer_call(p, kratos_py, ccx, w)
        if call is None:
            skipped.append(peer_name(p))
        else:
            calls[peer_name(p)] = call
    if skipped:
        print(f"skipped (not installed): {', '.join(skipped)}")
    res = interleave(calls, repeat)
    runs = res["runs"]
    print(f"\n{'run':34s} {'DOFs':>7s} {'Newton':>6s} {'wall s':>8s} {'L2':>8s} {'L2 nodes':>8s} "
          f"{'a_fit/a-1':>10s} {'P':>10s}")
    for name, r in sorted(runs.items(), key=lambda kv: (kv[1]["code"], kv[1]["dofs"])):
        nodes = r.get("l2_nodes", float("nan"))
        print(f"{name:34s} {r['dofs']:7d} {r['iterations']:6d} {r['wall']:8.2f} {r['l2']:8.3%} "
              f"{'' if nodes != nodes else f'{nodes:.3%}':>8s} {r['a_error']:+10.2%} {r['force']:10.5f}")
    rows = {key: ratios(runs, key) for key in ("l2", "l2_nodes")}
    for key, title in (("l2", "L2"), ("l2_nodes", "L2 nodes")):
        print(f"\nevery peer run ({title}) against the fastest voiga run at equal or better L2:")
        for row in rows[key]:
            head = f"  {row['peer']:34s} {row['peer_l2']:7.2%} {row['peer_wall']:8.2f} s  /  "
            if "ratio" in row:
                print(head + f"{row['voiga']:16s} {row['voiga_l2']:7.2%} {row['voiga_wall']:8.2f} s  = "
                      f"{row['ratio']:6.1f}")
            else:
                print(head + "no voiga run this accurate")
    print("L2: voiga's post hertz3d (control-point pressures p_A = force / D_A interpolated at its "
          "points); the peers' nodal\ncontact force over its nodal area interpolated over the faces "
          "at 3 x 3 points (C3D20R: the penalty law's nodal\nforces turned into nodal pressures by "
          "the faces' Gram matrix); L2 nodes: at the nodes only, weights the nodal areas")
    print("wall: the whole process, fastest of the repeats (OMP_NUM_THREADS=1; ccx also "
          "CCX_NPROC_*=1); DOFs: 3 x the ball's nodes;\nNewton: iterations over the five steps "
          "(ccx: its log's); P: the total force (4 x the quarter's)")
    return {"repeat": repeat, "runs": runs, "failed": res["failed"], "skipped": skipped,
            "ratios": rows}
