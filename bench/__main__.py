"""``python3 -m bench``: voiga performance figures, all measured in this one run.

Sections (``--only 1,2,...``; 1 to 8 unless given):
  1  time per Newton iteration by stage (hertz m3 N2 / NN2.2, ironing m1 NN2.2 short)
  2  NNp against Np on the same mesh (wall time and time per iteration)
  3  NN2.2 against N2 at comparable accuracy on hertz (wall time, Hertz errors)
  4  scaling of the time per iteration with the DOFs (hertz N2), direct and multigrid
  5  CalculiX (CPE8, surface-to-surface penalty) on the same Hertz problem, if apt
     offers it
  6  Kratos Multiphysics (Q4, 2D mortar penalty / augmented Lagrangian) on the same Hertz
     problem, installed by pip into build/kratos-venv (skipped if that fails)
  7  CalculiX (C3D20R) on the thick spherical shell under internal pressure, errors against
     Lame's solution over a refinement sequence (issue 41's 3D reference; needs no voiga)
  8  voiga on the same shell (exact NURBS octant, degrees 2-4), and with section 7 in the
     same run: each CalculiX run against the fastest voiga run at its stress error or
     below, the pair re-timed interleaved
  9  the 3D Hertz sphere in one run: voiga (pre hertz3d, N2 / NN2.2), Kratos (3D mortar,
     trilinear hexahedra; skipped if pip cannot install it) and CalculiX (C3D20R, C3D8I,
     surface-to-surface penalty), the same L2 of the nominal pressure for all, the runs
     interleaved; every peer run against the fastest voiga run at equal or better error

Runs go to a scratch directory (default build/bench); every ratio compares runs made
here, interleaved and best of --repeat, never against figures from another run.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from .run import (
    IRONING_SHORT,
    ROOT,
    STAGES,
    VOIGA,
    Run,
    Workdir,
    best_of,
    fit_exponent,
    header,
    hertz_errors,
    interleaved,
)


def ms(x: float) -> str:
    return f"{1e3 * x:9.2f}"


def section_stages(w: Workdir, repeat: int) -> dict:
    header("1. Time per Newton iteration by stage (sums of the result files' seconds_<stage>)")
    cases = [w.case("hertz", "m3-N2"), w.case("hertz", "m3-NN2.2"),
             w.case("ironing", "m1-NN2.2", IRONING_SHORT, tag="-short")]
    runs = interleaved(cases, repeat)
    print(f"{'case':18s} {'dofs':>6s} {'steps':>5s} {'iters':>5s} {'wall s':>8s} | ms per iteration: "
          + " ".join(f"{s:>9.9s}" for s in STAGES) + f" {'other':>9s}")
    out = {}
    for r in runs:
        other = (r.wall - r.staged) / r.iterations
        print(f"{r.case:18s} {r.n_dofs:6d} {r.steps:5d} {r.iterations:5d} {r.wall:8.3f} | {'':17s} "
              + " ".join(ms(v) for v in r.per_iteration.values()) + ms(other))
    print("\nfractions of the wall time (other = wall - sum of the stages: start-up, set-up, "
          "writing steps, exit)")
    print(f"{'case':18s} " + " ".join(f"{s:>13.13s}" for s in STAGES) + f" {'other':>13s}")
    for r in runs:
        fr = {s: r.seconds[s] / r.wall for s in STAGES}
        fr["other"] = 1.0 - r.staged / r.wall
        print(f"{r.case:18s} " + " ".join(f"{v:13.3f}" for v in fr.values()))
        out[r.case] = {"dofs": r.n_dofs, "iterations": r.iterations, "wall": r.wall,
                       "per_iteration": r.per_iteration, "fractions": fr}
    print("\nfractions of the staged total (assembly + contact + factorization + solve + output)")
    for r in runs:
        print(f"{r.case:18s} " + " ".join(f"{r.seconds[s] / r.staged:13.3f}" for s in STAGES))
    return out


def ratio_line(a: Run, b: Run) -> str:
    return (f"{a.case:18s} {b.case:18s} {a.n_dofs:6d} {b.n_dofs:6d} {a.iterations:5d} "
            f"{b.iterations:5d} {a.wall:8.3f} {b.wall:8.3f} {a.wall / b.wall:8.3f} "
            f"{a.wall_per_iteration / b.wall_per_iteration:8.3f} "
            f"{(a.staged / a.iterations) / (b.staged / b.iterations):8.3f} "
            f"{a.per_iteration['factorization'] / b.per_iteration['factorization']:8.3f}")


RATIO_HEAD = (f"{'A':18s} {'B':18s} {'dofs A':>6s} {'dofs B':>6s} {'it A':>5s} {'it B':>5s} "
              f"{'wall A':>8s} {'wall B':>8s} {'wall A/B':>8s} {'it A/B':>8s} {'stg A/B':>8s} "
              f"{'fac A/B':>8s}")
RATIO_NOTE = ("wall A/B: ratio of wall times; it A/B: ratio of wall time per Newton iteration; "
              "stg A/B: ratio of the staged\nseconds per iteration; fac A/B: ratio of the "
              "factorization seconds per iteration")


def section_nn_vs_n(w: Workdir, repeat: int) -> dict:
    header("2. NNp against Np on the same mesh (ironing: sliding phase shortened to 20 steps "
           f"over 0.4); best of {max(repeat, 3)}, interleaved")
    pairs = []
    for mesh in ("m1", "m2"):
        for p in ("4", "6"):
            pairs.append((w.case("ironing", f"{mesh}-NN{p}", IRONING_SHORT, tag="-short"),
                          w.case("ironing", f"{mesh}-N{p}", IRONING_SHORT, tag="-short")))
    pairs.append((w.case("hertz", "m3-NN4"), w.case("hertz", "m3-N4")))
    print(RATIO_HEAD, flush=True)
    out = {}
    for a_case, b_case in pairs:
        a, b = interleaved([a_case, b_case], max(repeat, 3))
        print(ratio_line(a, b), flush=True)
        out[f"{a.case}/{b.case}"] = {"dofs": [a.n_dofs, b.n_dofs],
                                      "iterations": [a.iterations, b.iterations],
                                      "wall": [a.wall, b.wall],
                                      "wall_ratio": a.wall / b.wall,
                                      "per_iteration_ratio": a.wall_per_iteration / b.wall_per_iteration}
    print(RATIO_NOTE)
    return out


def section_accuracy(w: Workdir, repeat: int) -> dict:
    header("3. NN2.2 against N2 at comparable accuracy (hertz; errors from post.hertz."
           "hertz_comparison, last step: reference configuration)")
    pairs = [("m3-NN2.2", "m3-N2"), ("m3-NN2.2", "m4-N2"), ("m4-NN2.2", "m5-N2")]
    names = sorted({n for p in pairs for n in p})
    runs = dict(zip(names, interleaved([w.case("hertz", n) for n in names], repeat), strict=True))
    errs = {n: hertz_errors(r.result) for n, r in runs.items()}
    print(f"{'case':10s} {'dofs':>6s} {'iters':>5s} {'wall s':>8s} {'L2 (ref.)':>11s} "
          f"{'a_fit/a-1':>10s} {'p0_fit/p0-1':>12s}")
    for n in names:
        r, e = runs[n], errs[n]
        print(f"{n:10s} {r.n_dofs:6d} {r.iterations:5d} {r.wall:8.3f} {e['l2']:11.5f} "
              f"{e['a_error']:+10.4f} {e['p0_error']:+12.4f}")
    print(f"\n{'A':10s} {'B':10s} {'wall A/B':>8s} {'it A/B':>8s} {'L2 A':>9s} {'L2 B':>9s} {'L2 A/B':>8s}")
    out = {"runs": {n: {"dofs": runs[n].n_dofs, "wall": runs[n].wall, **errs[n]} for n in names}}
    for a, b in pairs:
        ra, rb = runs[a], runs[b]
        print(f"{a:10s} {b:10s} {ra.wall / rb.wall:8.3f} "
              f"{ra.wall_per_iteration / rb.wall_per_iteration:8.3f} {errs[a]['l2']:9.5f} "
              f"{errs[b]['l2']:9.5f} {errs[a]['l2'] / errs[b]['l2']:8.3f}")
        out[f"{a}/{b}"] = {"wall_ratio": ra.wall / rb.wall}
    return out


def section_scaling(w: Workdir, repeat: int, levels: int, solvers: list[str],
                    direct_levels: int) -> dict:
    from .refine import refined_hertz_text
    header(f"4. Scaling with the DOFs: hertz N2 m1..m{levels}, one load step (n_steps = 1) so "
           "that the large meshes fit;\n   m7+ generated from m6 by knot-span midpoints in xi "
           f"and eta; linear solvers: {', '.join(solvers)}")
    print(f"{'solver':9s} {'mesh':5s} {'dofs':>7s} {'iters':>5s} {'gmres/it':>8s} {'wall s':>8s} | "
          f"s per iteration: {'assembly':>9s} {'contact':>9s} {'setup':>9s} {'solve':>9s} "
          f"{'wall':>9s}", flush=True)
    print("(setup: the factorization stage, i.e. UMFPACK's LU or the multigrid set-up)")
    rows: dict[str, list[dict]] = {s: [] for s in solvers}
    for lev in range(1, levels + 1):
        name = f"m{lev}-N2"
        text = refined_hertz_text(lev) if lev > 6 else None
        for solver in solvers:
            if solver == "direct" and lev > direct_levels:
                continue
            case = w.case("hertz", name, {"n_steps": "1"}, tag=f"-1step-{solver}", text=text,
                          linear_solver=solver)
            r = best_of(case, repeat if lev <= 5 else 1)
            pi = r.per_iteration
            print(f"{solver:9s} m{lev:<4d} {r.n_dofs:7d} {r.iterations:5d} "
                  f"{r.linear_iterations / r.iterations:8.1f} {r.wall:8.2f} | {'':16s} "
                  f"{pi['assembly']:9.4f} {pi['contact']:9.4f} {pi['factorization']:9.4f} "
                  f"{pi['solve']:9.4f} {r.wall_per_iteration:9.4f}", flush=True)
            rows[solver].append({"mesh": f"m{lev}", "dofs": r.n_dofs, "iterations": r.iterations,
                                 "linear_iterations": r.linear_iterations, "wall": r.wall,
                                 **{f"{k}_per_iteration": v for k, v in pi.items()}})
    print("\nexponent e in time per iteration ~ DOFs^e")
    print(f"{'solver':9s} {'between':14s} {'assembly':>9s} {'setup':>9s} {'solve':>9s} {'wall':>9s}")
    fits: dict[str, dict] = {}
    for solver in solvers:
        srows = rows[solver]
        fits[solver] = {}
        spans = [(i, i + 1) for i in range(max(0, len(srows) - 3), len(srows) - 1)]
        spans.append((max(0, len(srows) - 3), len(srows) - 1))
        # issue 7's range: every mesh from 1e4 DOFs on (lsq), when there are at least three
        big = [i for i, r in enumerate(srows) if r["dofs"] >= 1e4]
        if len(big) >= 3 and (big[0], big[-1]) not in spans:
            spans.append((big[0], big[-1]))
        for i, j in spans:
            sel = srows[i:j + 1]
            n = [r["dofs"] for r in sel]
            e = {k: fit_exponent(n, [r[f"{k}_per_iteration"] for r in sel])
                 for k in ("assembly", "factorization", "solve")}
            e["wall"] = fit_exponent(n, [r["wall"] / r["iterations"] for r in sel])
            label = f"{sel[0]['mesh']}..{sel[-1]['mesh']}" + (" (lsq)" if len(sel) > 2 else "")
            print(f"{solver:9s} {label:14s} " + " ".join(f"{v:9.2f}" for v in e.values()))
            fits[solver][label] = e
    if "direct" in rows and "multigrid" in rows:
        print("\nwall time per iteration, direct / multigrid:")
        print("  ".join(f"{a['mesh']} {a['wall'] / a['iterations'] / (b['wall'] / b['iterations']):.2f}"
                        for a, b in zip(rows["direct"], rows["multigrid"], strict=False)))  # direct stops earlier
    return {"rows": rows, "exponents": fits}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python3 -m bench", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", default="1,2,3,4,5,6,7,8",
                    help="comma-separated sections (9 only when named: 15 to 30 minutes)")
    ap.add_argument("--repeat", type=int, default=2, help="runs per small case (best taken)")
    ap.add_argument("--levels", type=int, default=7,
                    help="largest hertz mesh of section 4 (m7 ~ 1.1e5 DOFs, m8 ~ 4.4e5)")
    ap.add_argument("--solvers", default="direct,multigrid",
                    help="section 4: linear solvers to scale (direct, multigrid)")
    ap.add_argument("--direct-levels", type=int, default=8,
                    help="section 4: largest mesh for the direct solver (m9 takes it 18 min, 18 GB)")
    ap.add_argument("--work", type=Path, default=ROOT / "build" / "bench")
    ap.add_argument("--ccx-runs", default="m4:1,m5:1:1e3,m5:1:1e4,m5:1:1e5,m6:1",
                    help="section 5: mesh:split[:penalty], the CPE8 mesh being the hertz "
                         "<mesh> knot spans cut split x split (or AxB as for Kratos), the "
                         "contact slope penalty x E (default --ccx-penalty)")
    ap.add_argument("--ccx-penalty", type=float, default=1e4,
                    help="section 5: contact slope / E of the runs that give none")
    ap.add_argument("--ccx-match", default="m5:1",
                    help="section 5: the CalculiX run timed against voiga hertz m4 NN2.2")
    ap.add_argument("--kratos-runs", default="penalty:m4:1,penalty:m5:1,penalty:m6:1,alm:m6:1",
                    help="section 6: method:mesh:split, the Q4 mesh being the hertz <mesh> "
                         "knot spans cut split x split (or AxB: A along the arc, B radially)")
    ap.add_argument("--kratos-solvers", default="sparse_lu,amgcl",
                    help="section 6: Kratos's linear solvers, the first for the table, each "
                         "timed on the matched run")
    ap.add_argument("--kratos-match", default="penalty:m5:2",
                    help="section 6: the Kratos run timed against voiga hertz m4 NN2.2")
    ap.add_argument("--sphere-meshes", default=None,
                    help="section 7: n or nxm per mesh, n x n x m C3D20R per block of the "
                         "three-block octant (n over the angles, m radially; default "
                         "bench.ccx_sphere.MESHES)")
    ap.add_argument("--sphere-threads", type=int, default=2,
                    help="section 7: ccx's threads (OMP_NUM_THREADS and CCX_NPROC_*)")
    ap.add_argument("--sphere-solvers", default=None,
                    help="section 7: ccx solvers, default (its own choice: SPOOLES) or *STATIC "
                         "SOLVER= values (default bench.ccx_sphere.SOLVERS)")
    ap.add_argument("--sphere-voiga-meshes", default=None,
                    help="section 8: p:n per run, degree p and n elements per direction "
                         "(default bench.voiga_sphere.MESHES)")
    ap.add_argument("--ball-voiga", default=None,
                    help="section 9: voiga's mesh:layout runs, m<k> Cartesian, p<k> polar grid "
                         "(default bench.ball_section.VOIGA_RUNS)")
    ap.add_argument("--ball-peers", default=None,
                    help="section 9: kratos:alm|penalty:SOLVER:MESH and ccx:C3D20R|C3D8I:MESH[:PENALTY] "
                         "runs, MESH fine x rest x outer x radial (cube-sphere) or "
                         "o<core>x<fine>x<rest>x<radial>x<edge> (O-grid) (default bench.ball_section.PEER_RUNS)")
    ap.add_argument("--json", type=Path, default=None, help="also write the figures here")
    args = ap.parse_args(argv)
    only = {s.strip() for s in args.only.split(",")}
    if not VOIGA.exists() and only - {"7"}:
        print(f"bench: {VOIGA} missing; run make build", file=sys.stderr)
        return 1
    w = Workdir(args.work)
    t0 = time.perf_counter()
    print(f"bench: voiga {VOIGA}, work dir {w.path}, best of {args.repeat} "
          f"(started {time.strftime('%Y-%m-%d %H:%M:%S %Z')})")
    figures: dict = {}
    if "1" in only:
        figures["stages"] = section_stages(w, args.repeat)
    if "2" in only:
        figures["nn_vs_n"] = section_nn_vs_n(w, args.repeat)
    if "3" in only:
        figures["accuracy"] = section_accuracy(w, args.repeat)
    if "4" in only:
        figures["scaling"] = section_scaling(w, args.repeat, args.levels,
                                              [x.strip() for x in args.solvers.split(",")],
                                              args.direct_levels)
    if "5" in only:
        from .ccx import section_calculix
        figures["calculix"] = section_calculix(w, args.ccx_runs, args.ccx_match,
                                               args.ccx_penalty, args.repeat)
    if "6" in only:
        from .kratos import section_kratos
        figures["kratos"] = section_kratos(w, args.kratos_runs, args.kratos_match, args.repeat,
                                          args.kratos_solvers)
    if "7" in only:
        from .ccx_sphere import MESHES, SOLVERS, section_sphere
        figures["sphere_calculix"] = section_sphere(w, args.sphere_meshes or MESHES, args.sphere_threads,
                                                      args.sphere_solvers or SOLVERS)
    if "8" in only:
        from .voiga_sphere import MESHES as VOIGA_MESHES
        from .voiga_sphere import section_voiga_sphere
        figures["sphere_voiga"] = section_voiga_sphere(w, args.sphere_voiga_meshes or VOIGA_MESHES,
                                                       figures.get("sphere_calculix"), args.repeat)
    if "9" in only:
        from .ball_section import PEER_RUNS, VOIGA_RUNS, section_ball
        figures["hertz3d"] = section_ball(w, args.ball_voiga or VOIGA_RUNS, args.ball_peers or PEER_RUNS,
                                          args.repeat)
    total = time.perf_counter() - t0
    print(f"\nbench: done in {total:.0f} s")
    path = args.json or (w.path / "bench.json")
    path.write_text(json.dumps(figures, indent=1, default=float))
    print(f"bench: figures written to {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
