"""Section 6: Kratos Multiphysics on the same Hertz problem (a peer with mortar contact).

Quarter cylinder (R = 1, hole R = 0.05 as in the hertz scene, E = 1, nu = 0.3), small
displacement Q4 plane strain (SmallDisplacementElement2D4N, LinearElasticPlaneStrain2DLaw),
meshed on voiga's graded hertz parameter grid: the knot spans of cases/hertz/<mesh>-N2.nml
each cut into ``split`` Q4 (``'2'``: 2 x 2; ``'2x1'``: 2 along the arc, 1 radially) and
mapped through the exact NURBS geometry. The flat is a block of Q4 whose nodes are all
fixed (rigid); contact is Kratos's 2D mortar (``PenaltyContactFrictionless`` or
``ALMContactFrictionless``) with the outer arc as slave and the top of the block as
master, the penalty Kratos's own (stiffness_factor x E / h, see PENALTY_FACTOR). u_y =
-0.01 t on the top cut (u_x free there), u_x = 0 on the symmetry cut, five load steps as
voiga's five.

Kratos runs in its own virtual environment (build/kratos-venv, made here with pip); if
that fails, the section is skipped with a message. The pressure per reference length at
the slave nodes is their contact force over their reference length (:func:`nodal_pressure`)
at the reference positions; the force is the reaction on the top cut. The same post.hertz
functions as ``python -m post hertz`` give the errors. Kratos's own nodal variables are
kept in result.json for inspection but not used: AUGMENTED_NORMAL_CONTACT_PRESSURE
(penalty x weighted gap) integrates to 2.8 times the reaction on m5 x2 and grows away
from the centre instead of falling; the ALM multiplier is scaled by Kratos's SCALE_FACTOR.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from functools import partial
from pathlib import Path

import numpy as np

from .refine import split_grid, splits
from .run import ROOT, Workdir

UY = -0.01
E, NU = 1.0, 0.3
N_STEPS = 5
VENV = ROOT / "build" / "kratos-venv"
PACKAGES = ("KratosMultiphysics", "KratosStructuralMechanicsApplication",
            "KratosContactStructuralMechanicsApplication", "KratosLinearSolversApplication")
DRIVER = Path(__file__).resolve().parent / "kratos_driver.py"
# method -> (mortar_type, contact process, the nodal variable kept for inspection)
MORTAR = {"penalty": ("PenaltyContactFrictionless", "penalty_contact_process",
                      "AUGMENTED_NORMAL_CONTACT_PRESSURE"),
          "alm": ("ALMContactFrictionless", "alm_contact_process",
                  "LAGRANGE_MULTIPLIER_CONTACT_PRESSURE")}
IMPORT_CHECK = ("import KratosMultiphysics, KratosMultiphysics.StructuralMechanicsApplication, "
                "KratosMultiphysics.ContactStructuralMechanicsApplication, "
                "KratosMultiphysics.LinearSolversApplication")


def venv_python() -> Path:
    return VENV / "bin" / "python"


def kratos_available() -> bool:
    """Kratos imports in build/kratos-venv (nothing is installed here)."""
    py = venv_python()
    return py.exists() and subprocess.run([str(py), "-c", IMPORT_CHECK],
                                          capture_output=True).returncode == 0


def ensure_kratos() -> Path | None:
    """The venv's Python, after making the venv and pip-installing Kratos if needed."""
    if kratos_available():
        return venv_python()
    print(f"bench: installing Kratos Multiphysics into {VENV} with pip", flush=True)
    steps = [[sys.executable, "-m", "venv", str(VENV)],
             [str(venv_python()), "-m", "pip", "install", "-q", *PACKAGES, "numpy"]]
    for cmd in steps:
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0:
            print(f"bench: {' '.join(cmd[:4])} ... failed ({proc.returncode}): "
                  f"{proc.stderr.strip()[-400:]}\nbench: skipping Kratos")
            return None
    if not kratos_available():
        print(f"bench: Kratos installed in {VENV} but does not import; skipping Kratos")
        return None
    return venv_python()


def cylinder_q4(mesh: str, split: str):
    """Nodes (n, 2), counter-clockwise Q4 connectivity (nel, 4; 0-based) and the node
    index lists of the symmetry cut, the top cut and the outer arc (in xi order)."""
    from pre.nurbs import evaluate_patch
    from pre.scenes import hertz
    gx, ge = split_grid(mesh, split)
    xi, eta = np.meshgrid(gx, ge, indexing="ij")
    xy = evaluate_patch(hertz()["cylinder"], xi.ravel(), eta.ravel())
    xy[np.isclose(xi.ravel(), 0.0), 0] = 0.0
    xy[np.isclose(xi.ravel(), 1.0), 1] = 0.0
    ids = np.arange(len(gx) * len(ge)).reshape(len(gx), len(ge))
    conn = np.stack([ids[:-1, :-1], ids[1:, :-1], ids[1:, 1:], ids[:-1, 1:]], axis=-1)
    conn = conn.reshape(-1, 4)
    p = xy[conn[0]]
    if np.dot(p[:, 0], np.roll(p[:, 1], -1)) - np.dot(np.roll(p[:, 0], -1), p[:, 1]) < 0:
        conn = conn[:, ::-1]
    return xy, conn, ids[0, :], ids[-1, :], ids[:, -1]


def block_q4(top_x: np.ndarray, ny: int = 2, y0: float = -1.1, y1: float = -1.0):
    """Rigid flat: a Q4 block under y = -1 whose top nodes are at ``top_x`` (increasing);
    nodes, counter-clockwise connectivity and the top nodes from left to right."""
    gy = np.linspace(y0, y1, ny + 1)
    X, Y = np.meshgrid(top_x, gy, indexing="ij")
    ids = np.arange(X.size).reshape(X.shape)
    conn = np.stack([ids[:-1, :-1], ids[1:, :-1], ids[1:, 1:], ids[:-1, 1:]], axis=-1)
    return np.column_stack([X.ravel(), Y.ravel()]), conn.reshape(-1, 4), ids[:, -1]


def master_x(slave_x: np.ndarray, reach: float = 0.2) -> np.ndarray:
    """Top nodes of the flat: a master segment under every slave segment up to ``reach``
    (a coarser master makes Kratos's mortar pressure oscillate with the master's period;
    measured on m4 split 2: L2 13 % with 60 uniform segments), coarser beyond, and the
    same spacing mirrored a little past the symmetry cut."""
    near = np.sort(slave_x[slave_x < reach])
    h = near[1] - near[0]
    left = -h * np.arange(1, 6)[::-1]
    far = np.linspace(near[-1], 0.35, 12)[1:]
    return np.concatenate([left, near, far])


def _block(name: str, rows: list[str]) -> list[str]:
    return [f"Begin {name}", *rows, f"End {name.split()[0]}"]


def _sub(name: str, nodes=(), elems=(), conds=()) -> list[str]:
    body = (_block("SubModelPartNodes", [str(int(i)) for i in nodes])
            + _block("SubModelPartElements", [str(int(i)) for i in elems])
            + _block("SubModelPartConditions", [str(int(i)) for i in conds]))
    return [f"Begin SubModelPart {name}", *body, "End SubModelPart"]


def write_mdpa(path: Path, mesh: str, split: str) -> dict:
    """The model (1-based ids; cylinder nodes first) and what the run needs to know."""
    xy, conn, sym, top, outer = cylinder_q4(mesh, split)
    bxy, bconn, btop = block_q4(master_x(xy[outer, 0]))
    nb = len(xy)
    nodes = [f"{k + 1} {x:.16g} {y:.16g} 0.0" for k, (x, y) in enumerate(np.vstack([xy, bxy]))]
    elems = [f"{k + 1} 1 " + " ".join(str(v + 1) for v in c) for k, c in enumerate(conn)]
    elems += [f"{len(conn) + k + 1} 2 " + " ".join(str(v + nb + 1) for v in c)
              for k, c in enumerate(bconn)]
    # line conditions: the slave arc walked from the symmetry cut towards the top (the
    # body on the left: counter-clockwise... orientation is checked by Kratos's
    # NormalCheckProcess), the master top of the block from right to left
    slave = [(outer[i] + 1, outer[i + 1] + 1) for i in range(len(outer) - 1)]
    master = [(btop[i + 1] + nb + 1, btop[i] + nb + 1) for i in range(len(btop) - 1)]
    conds = [f"{k + 1} 1 {a} {b}" for k, (a, b) in enumerate(slave)]
    conds += [f"{len(slave) + k + 1} 2 {a} {b}" for k, (a, b) in enumerate(master)]
    lines = (["Begin ModelPartData", "End ModelPartData",
              "Begin Properties 1", "End Properties", "Begin Properties 2", "End Properties"]
             + _block("Nodes", nodes)
             + _block("Elements SmallDisplacementElement2D4N", elems)
             + _block("Conditions LineCondition2D2N", conds)
             + _sub("Cylinder", range(1, nb + 1), range(1, len(conn) + 1))
             + _sub("Block", range(nb + 1, nb + len(bxy) + 1),
                    range(len(conn) + 1, len(conn) + len(bconn) + 1))
             + _sub("Symmetry", sym + 1) + _sub("Top", top + 1)
             + _sub("Slave", outer + 1, conds=range(1, len(slave) + 1))
             + _sub("Master", btop + nb + 1,
                    conds=range(len(slave) + 1, len(slave) + len(master) + 1)))
    path.write_text("\n".join(lines) + "\n")
    return {"dofs": 2 * nb, "elements": len(conn), "slave": (outer + 1).tolist(),
            "top": (top + 1).tolist()}


def materials(path: Path) -> None:
    def prop(part: str, pid: int) -> dict:
        # the block is rigid through its fixed nodes; E = 1 keeps Kratos's automatic
        # penalty (a mean of E / h over the contact pair) that of the cylinder
        return {"model_part_name": f"Structure.{part}", "properties_id": pid,
                "Material": {"constitutive_law": {"name": "LinearElasticPlaneStrain2DLaw"},
                             "Variables": {"YOUNG_MODULUS": E, "POISSON_RATIO": NU,
                                           "DENSITY": 1.0, "THICKNESS": 1.0},
                             "Tables": {}}}
    path.write_text(json.dumps({"properties": [prop("Cylinder", 1), prop("Block", 2)]}))


def fix(part: str, constrained: list[bool], value: list) -> dict:
    return {"python_module": "assign_vector_variable_process", "kratos_module": "KratosMultiphysics",
            "Parameters": {"model_part_name": f"Structure.{part}", "variable_name": "DISPLACEMENT",
                           "interval": [0.0, "End"], "constrained": constrained, "value": value}}


SOLVER_SETTINGS = {"amgcl": {"tolerance": 1e-10, "max_iteration": 1000}}
"""Settings beyond the solver type. amgcl is not reliable on these meshes: on m5 1x3
(elements 1:1 at the contact) it gave L2 6.45 % at its default tolerance 1e-6 and 1.92 %
at 1e-10 (234 s), where sparse_lu gives 0.66 %; on m5 x2 and m6 x1 it agrees with
sparse_lu to 2e-6."""


def analysis_settings(stem: str, mortar: str, solver: str, domain_size: int = 2,
                      n_steps: int = N_STEPS) -> dict:
    """``problem_data`` and ``solver_settings`` of a static contact analysis of
    ``n_steps`` steps over t = 0 to 1 (shared by section 6 and the 3D sphere's section 9):
    Kratos's contact residual criterion, tolerances 1e-6 relative, 1e-12 absolute."""
    return {
        "problem_data": {"problem_name": stem, "parallel_type": "OpenMP", "echo_level": 0,
                         "start_time": 0.0, "end_time": 1.0},
        "solver_settings": {
            "model_part_name": "Structure", "domain_size": domain_size, "solver_type": "Static",
            "echo_level": 0, "analysis_type": "non_linear",
            "model_import_settings": {"input_type": "mdpa", "input_filename": stem},
            "material_import_settings": {"materials_filename": "materials.json"},
            "contact_settings": {"mortar_type": mortar},
            "time_stepping": {"time_step": 1.0 / n_steps},
            "convergence_criterion": "contact_residual_criterion",
            "displacement_relative_tolerance": 1e-6, "displacement_absolute_tolerance": 1e-12,
            "residual_relative_tolerance": 1e-6, "residual_absolute_tolerance": 1e-12,
            "max_iteration": 30,
            "linear_solver_settings": {"solver_type": solver,
                                       **SOLVER_SETTINGS.get(solver, {})}}}


def contact_process(process: str, **extra) -> dict:
    """Frictionless mortar contact of the sub-model parts Slave (the slave) and Master;
    ``extra``: more of the process's parameters."""
    return {"python_module": process,
            "kratos_module": "KratosMultiphysics.ContactStructuralMechanicsApplication",
            "Parameters": {"model_part_name": "Structure",
                           "contact_model_part": {"0": ["Slave", "Master"]},
                           "assume_master_slave": {"0": ["Slave"]},
                           "contact_type": "Frictionless", **extra}}


def parameters(stem: str, method: str, stiffness: float, solver: str) -> dict:
    mortar, process, _ = MORTAR[method]
    return {
        **analysis_settings(stem, mortar, solver),
        "processes": {
            "constraints_process_list": [
                fix("Block", [True, True, True], [0.0, 0.0, 0.0]),
                fix("Symmetry", [True, False, True], [0.0, 0.0, 0.0]),
                fix("Top", [False, True, True], [0.0, f"{UY}*t", 0.0])],
            "loads_process_list": [],
            "contact_process_list": [contact_process(
                process, advance_ALM_parameters={"stiffness_factor": stiffness})]},
        "output_processes": {}}


def run_kratos(py: Path, w: Workdir, mesh: str, split: str, method: str,
               stiffness: float = 1.0, solver: str = "sparse_lu") -> dict:
    """One analysis; its wall time (the whole process) and the Hertz errors."""
    from post.hertz import compare_profile
    stem = f"hertz-{mesh}-q{split}-{method}-k{stiffness:g}-{solver}"
    d = w.path / "kratos" / stem
    d.mkdir(parents=True, exist_ok=True)
    info = write_mdpa(d / f"{stem}.mdpa", mesh, split)
    materials(d / "materials.json")
    pressure = MORTAR[method][2]
    job = {"parameters": parameters(stem, method, stiffness, solver), "slave_nodes": info["slave"],
           "top_nodes": info["top"], "contact_variables": [pressure, "WEIGHTED_GAP"]}
    (d / "job.json").write_text(json.dumps(job, indent=1))
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    t0 = time.perf_counter()
    proc = subprocess.run([str(py), str(DRIVER), "job.json"], cwd=d, capture_output=True,
                          text=True, env=env)
    wall = time.perf_counter() - t0
    (d / "log.txt").write_text(proc.stdout + proc.stderr)
    if proc.returncode != 0:
        raise RuntimeError(f"Kratos {stem} failed ({proc.returncode}); see {d / 'log.txt'}")
    res = json.loads((d / "result.json").read_text())
    x0 = np.array([[r["x0"], r["y0"]] for r in res["slave"]])
    fy = np.array([r["force"][1] for r in res["slave"]])
    nominal = nodal_pressure(x0, fy)
    on_top = np.isin([r["id"] for r in res["slave"]], info["top"])
    # the arc's end on the top cut carries that cut's Dirichlet reaction; nodes Kratos
    # holds inactive carry only the linear solver's residual (amgcl: about 1e-6)
    active = np.array([r["active"] for r in res["slave"]]) & ~on_top
    nominal[~active] = 0.0
    force = 2.0 * abs(res["reaction_y"])
    h = compare_profile(x0[:, 0], nominal, force, E, NU, 1.0, half_model=True)
    return {"mesh": mesh, "split": split, "method": method, "solver": solver, "dofs": info["dofs"],
            "elements": info["elements"], "wall": wall, "analysis_seconds": res["seconds"],
            "iterations": res["iterations"], "force": h.force, "a": h.a, "p0": h.p0,
            "a_error": h.a_error, "p0_error": h.p0_error, "l2": h.l2_error,
            "active_nodes": int(np.count_nonzero(nominal > 0)),
            "penalty": res["initial_penalty"],
            "contact_force": -2.0 * float(fy[active].sum())}


def nodal_pressure(ref: np.ndarray, fy: np.ndarray) -> np.ndarray:
    """Pressure per reference length at the slave nodes (reference positions ``ref``, in
    order along the arc) from the y components ``fy`` of the elements' nodal forces there.

    Those forces are what the mortar contact conditions balance: with dual Lagrange
    multipliers the contact force of slave node i is D_ii lambda_i, D_ii the integral of
    its shape function over the slave edge, so lambda_i = f_i / D_ii; over the reference
    edge that is the pressure per reference length. Round-off forces of nodes out of
    contact (|f| below 1e-9 of the largest) are zero."""
    edge = np.linalg.norm(np.diff(ref, axis=0), axis=1)
    trib = np.zeros(len(ref))
    trib[:-1] += 0.5 * edge
    trib[1:] += 0.5 * edge
    p = -np.asarray(fy) / trib
    p[np.abs(fy) < 1e-9 * np.abs(fy).max()] = 0.0
    return p


PENALTY_FACTOR = 10.0
"""Kratos's stiffness_factor for the penalty runs (its automatic penalty, E / h scaled,
times this): with 1 the penalty limits the accuracy (m4 split 1: L2 1.74 % against 1.30 %
with 10, 1.31 % with 100 and 1.32 % with the augmented Lagrangian). On finer meshes the
error is not monotone in the mesh or the factor (m6 split 1: 0.53 % with 10, 0.98 % with
100, 1.08 % augmented Lagrangian; m6 split 2x1: 1.70 %; m5 split 3x1: 0.86 %; m6 split 2:
1.63 %, sparse_lu): the nodes near the edge of the zone and at the slave's end on the
symmetry cut deviate by 1-5 % of p0."""


def parse_runs(spec: str) -> list[tuple[str, str, str]]:
    """``'penalty:m6:1,alm:m6:1'`` -> [(method, mesh, split), ...]."""
    out = []
    for item in spec.split(","):
        method, mesh, split = item.strip().split(":")
        if method not in MORTAR:
            raise SystemExit(f"bench: unknown Kratos method {method!r} (known: {sorted(MORTAR)})")
        splits(split)
        out.append((method, mesh, split))
    return out


SOLVER = "sparse_lu"
"""Kratos's linear solver for the table: the direct one of those its pip build offers
(sparse_lu, skyline_lu_factorization, amgcl, sparse_cg; no pardiso, umfpack or cholmod).
The matched run is also timed with amgcl, about 3x faster where it gives the same answer
(SOLVER_SETTINGS)."""


def kratos_once(py: Path, w: Workdir, run: tuple[str, str, str],
                solver: str = SOLVER) -> dict:
    method, mesh, split = run
    return run_kratos(py, w, mesh, split, method,
                      PENALTY_FACTOR if method == "penalty" else 1.0, solver)


def section_kratos(w: Workdir, runs: str, match: str, repeat: int = 2,
                   solvers: str = f"{SOLVER},amgcl") -> dict:
    """Kratos on the meshes ``runs``; then ``match`` and voiga's hertz m4 NN2.2 (as
    committed, penalty 1e3, and with the automatic penalty) interleaved, best of
    ``repeat``, for the wall-time ratios. ``solvers``: Kratos's linear solvers, the first
    for the table, each for the matched run."""
    solver, *_ = names = [v.strip() for v in solvers.split(",")]
    from .run import header, interleaved_calls, reference_ratios, solve, voiga_reference
    header("6. Kratos Multiphysics (Q4 small-displacement plane strain, 2D mortar contact, "
           "rigid flat) against voiga hertz m4 NN2.2;\n   same measure as python -m post "
           "hertz (pressure per reference length at reference positions)")
    py = ensure_kratos()
    if py is None:
        return {"available": False}
    head = (f"{'code':9s} {'method':11s} {'mesh':9s} {'dofs':>6s} {'iters':>5s} {'wall s':>8s} "
            f"{'solve s':>8s} {'L2 (ref.)':>10s} {'a_fit/a-1':>10s} {'p0_fit/p0-1':>12s}")
    print(head, flush=True)
    out: dict = {"available": True, "penalty_factor": PENALTY_FACTOR, "solvers": names,
                 "runs": []}

    def line(r: dict) -> str:
        return (f"{'kratos':9s} {r['method']:11s} {r['mesh'] + ' x' + str(r['split']):9s} "
                f"{r['dofs']:6d} {sum(r['iterations']):5d} {r['wall']:8.3f} "
                f"{r['analysis_seconds']:8.3f} {r['l2']:10.5f} {r['a_error']:+10.4f} "
                f"{r['p0_error']:+12.4f}")

    for run in parse_runs(runs):
        try:
            r = kratos_once(py, w, run, solver)
        except Exception as err:  # noqa: BLE001 - report and go on with the next run
            print(f"kratos    {':'.join(map(str, run))} failed: {err}", flush=True)
            continue
        print(line(r), flush=True)
        out["runs"].append(r)
    (match_run,) = parse_runs(match)
    cases = voiga_reference(w, "-kratoscmp")
    calls = {name: partial(solve, case) for name, case in cases.items()}
    calls.update({n: partial(kratos_once, py, w, match_run, n) for n in names})
    try:
        best = interleaved_calls(calls, repeat)
    except Exception as err:  # noqa: BLE001 - the section ends, the bench goes on
        print(f"{match} (voiga m4 NN2.2 or Kratos) failed: {err}; no ratio", flush=True)
        return out
    out["match"] = {"repeat": repeat, **{n: best[n] for n in names},
                    **reference_ratios(best, cases, names)}
    for name in cases:
        m = out["match"][name]
        print(f"{'voiga':9s} {name:11s} {'m4 NN2.2':9s} {m['dofs']:6d} {m['iterations']:5d} "
              f"{m['wall']:8.3f} {'':8s} {m['l2']:10.5f} {m['a_error']:+10.4f} "
              f"{m['p0_error']:+12.4f}")
    for n in names:
        print(line(best[n]) + f"  {n}")
    print(f"\nwall Kratos {match} / voiga m4 NN2.2 (interleaved, best of {repeat}):")
    for name in cases:
        m = out["match"][name]
        for n in names:
            print(f"  Kratos {n:9s} / voiga {name:11s}: {m['ratio'][n]:7.2f}  (L2 Kratos "
                  f"{best[n]['l2']:.4%}, voiga {m['l2']:.4%})")
    print("wall: the whole process (Kratos: python, import, model read, analysis); solve s: "
          "Kratos's analysis.Run();\nOMP_NUM_THREADS=1 for both; Kratos's linear solver in the "
          f"table: {solver}; Kratos penalty: automatic "
          f"penalty x {PENALTY_FACTOR:g}; voiga auto: the committed case without "
          "penalty_normal (automatic penalty);\ndofs: 2 x the cylinder's nodes")
    return out
