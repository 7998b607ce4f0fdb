"""Kratos and CalculiX on the 3D Hertz sphere (section 9): the inputs, one run each, and
the measure of :mod:`bench.ball_pressure`.

Problem (voiga's ``pre hertz3d``): the ball octant x, y >= 0, z <= 0 of R = 1, E = 1,
nu = 0.3, small displacements; the top face z = 0 moves by u_z = -0.01 t (t = 0 to 1 in
five steps, voiga's five), u_x = 0 on x = 0, u_y = 0 on y = 0; the flat z = -1 is a
one-layer block of hexahedra (:func:`bench.ball_mesh.flat_block`) whose nodes are all
fixed, its top face the master. Meshes: :mod:`bench.ball_mesh` (cube-sphere) and
:mod:`bench.ball_ogrid` (O-grid).

- Kratos (:func:`run_kratos`): SmallDisplacementElement3D8N (trilinear), 3D mortar
  contact (``ALMContactFrictionless``, Kratos's augmented Lagrangian with its automatic
  parameters, or ``PenaltyContactFrictionless``) between SurfaceCondition3D4N faces; the
  force from REACTION_Z on the top face. Runs in build/kratos-venv
  (:func:`bench.kratos.ensure_kratos`) through :mod:`bench.kratos_driver`.
- CalculiX (:func:`run_ccx`): C3D20R or C3D8I, surface-to-surface contact with a linear
  pressure-overclosure law of slope K = ``penalty`` x E / R; the force from the top
  face's reaction (RF totals), the displacements of the sphere's nodes from the .dat.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import time
from pathlib import Path

import numpy as np

from .ball_mesh import BallMesh, flat_block, flat_grid
from .ball_ogrid import OGridMesh, octant
from .ball_pressure import (
    NU,
    RADIUS,
    E,
    interpolated_points,
    measure,
    nodal_force_points,
    penalty_nodal_points,
    penalty_points,
    projected_points,
)
from .kratos import _block, _sub
from .kratos import fix as fixed
from .run import Workdir

UZ = -0.01
N_STEPS = 5
CCX_PENALTY = 1e4
"""Contact slope K over E / R of the CalculiX runs that give none: the issue's earlier
runs' 1e4; the law's compliance p0 / K (p0 about 0.07 E) is 1e-3 of the indentation.
The section's C3D20R runs give 1e3 (bench.ball_section.PEER_RUNS: its faces' pressure
alternates from node to node under 1e4)."""
CCX_ELEMENTS = ("C3D20R", "C3D8I")


def kratos_model(mesh: BallMesh | OGridMesh) -> dict:
    """The ball and the flat (linear hexahedra), as :func:`write_mdpa` writes them."""
    ball = octant(mesh, quadratic=False)
    flat = flat_block(flat_grid(mesh), quadratic=False)
    return {"ball": ball, "flat": flat}


def write_mdpa(path: Path, mesh: BallMesh | OGridMesh) -> dict:
    """The Kratos model (1-based ids; the ball's nodes first) and what the run needs."""
    m = kratos_model(mesh)
    ball, flat = m["ball"], m["flat"]
    nb, eb = len(ball["nodes"]), len(ball["elements"])
    xyz = np.vstack([ball["nodes"], flat["nodes"]])
    nodes = [f"{k + 1} {x:.16g} {y:.16g} {z:.16g}" for k, (x, y, z) in enumerate(xyz)]
    elems = [f"{k + 1} 1 " + " ".join(str(v + 1) for v in c) for k, c in enumerate(ball["elements"])]
    elems += [f"{eb + k + 1} 2 " + " ".join(str(v + nb + 1) for v in c)
              for k, c in enumerate(flat["elements"])]
    slave, master = ball["surface"] + 1, flat["top"] + nb + 1
    conds = [f"{k + 1} 1 " + " ".join(map(str, c)) for k, c in enumerate(slave)]
    conds += [f"{len(slave) + k + 1} 2 " + " ".join(map(str, c)) for k, c in enumerate(master)]
    slave_nodes = np.unique(slave)
    lines = (["Begin ModelPartData", "End ModelPartData",
              "Begin Properties 1", "End Properties", "Begin Properties 2", "End Properties"]
             + _block("Nodes", nodes)
             + _block("Elements SmallDisplacementElement3D8N", elems)
             + _block("Conditions SurfaceCondition3D4N", conds)
             + _sub("Ball", range(1, nb + 1), range(1, eb + 1))
             + _sub("Flat", range(nb + 1, len(xyz) + 1), range(eb + 1, eb + len(flat["elements"]) + 1))
             + _sub("X0", ball["x0"] + 1) + _sub("Y0", ball["y0"] + 1) + _sub("Top", ball["top"] + 1)
             + _sub("Slave", slave_nodes, conds=range(1, len(slave) + 1))
             + _sub("Master", np.unique(master), conds=range(len(slave) + 1, len(conds) + 1)))
    path.write_text("\n".join(lines) + "\n")
    return {"dofs": 3 * nb, "elements": eb, "slave": slave_nodes.tolist(),
            "top": (ball["top"] + 1).tolist(), "model": m}


def kratos_parameters(stem: str, method: str, solver: str) -> dict:
    """The analysis: static, nonlinear (contact), five steps, Kratos's contact criterion."""
    from .kratos import MORTAR, analysis_settings, contact_process
    mortar, process, _ = MORTAR[method]
    props = {"model_part_name": "Structure.Ball", "properties_id": 1,
             "Material": {"constitutive_law": {"name": "LinearElastic3DLaw"},
                          "Variables": {"YOUNG_MODULUS": E, "POISSON_RATIO": NU, "DENSITY": 1.0},
                          "Tables": {}}}
    flat = json.loads(json.dumps(props))
    flat.update(model_part_name="Structure.Flat", properties_id=2)
    return {
        "materials": {"properties": [props, flat]},
        "parameters": {
            **analysis_settings(stem, mortar, solver, domain_size=3, n_steps=N_STEPS),
            "processes": {
                "constraints_process_list": [
                    fixed("Flat", [True, True, True], [0.0, 0.0, 0.0]),
                    fixed("X0", [True, False, False], [0.0, 0.0, 0.0]),
                    fixed("Y0", [False, True, False], [0.0, 0.0, 0.0]),
                    fixed("Top", [False, False, True], [0.0, 0.0, f"{UZ}*t"])],
                "loads_process_list": [],
                "contact_process_list": [contact_process(process)]},
            "output_processes": {}}}


def run_kratos(py: Path, w: Workdir, mesh: BallMesh | OGridMesh, method: str = "alm", solver: str = "amgcl") -> dict:
    """One Kratos analysis (the whole process timed, one thread) and its measure."""
    from .kratos import DRIVER, MORTAR
    stem = f"ball-{mesh.name}-{method}-{solver}"
    d = w.path / "kratos3d" / stem
    d.mkdir(parents=True, exist_ok=True)
    info = write_mdpa(d / f"{stem}.mdpa", mesh)
    setup = kratos_parameters(stem, method, solver)
    (d / "materials.json").write_text(json.dumps(setup["materials"]))
    job = {"parameters": setup["parameters"], "slave_nodes": info["slave"], "top_nodes": info["top"],
           "contact_variables": [MORTAR[method][2]], "dimension": 3, "reaction": "REACTION_Z"}
    (d / "job.json").write_text(json.dumps(job, indent=1))
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    t0 = time.perf_counter()
    proc = subprocess.run([str(py), str(DRIVER), "job.json"], cwd=d, capture_output=True, text=True, env=env)
    wall = time.perf_counter() - t0
    (d / "log.txt").write_text(proc.stdout + proc.stderr)
    if proc.returncode != 0:
        raise RuntimeError(f"Kratos {stem} failed ({proc.returncode}); see {d / 'log.txt'}")
    res = json.loads((d / "result.json").read_text())
    ball = info["model"]["ball"]
    ids = np.array([r["id"] for r in res["slave"]]) - 1
    fz = np.array([r["force"][2] for r in res["slave"]])
    active = np.array([r["active"] for r in res["slave"]]) & ~np.isin(ids, ball["top"])
    pts = nodal_force_points(ball["nodes"], ball["surface"], ids, fz, active)
    faces = measure(interpolated_points(ball["nodes"], ball["surface"], pts, ids), res["reaction"])
    nodal = measure(pts, res["reaction"])
    return {"code": "kratos", "mesh": mesh.name, "method": method, "solver": solver,
            "dofs": info["dofs"], "elements": info["elements"], "wall": wall,
            "iterations": int(sum(res["iterations"])), **faces, "l2_nodes": nodal["l2"],
            "nodal_force": nodal["contact_force"],
            "measure": "nodal force / nodal area, interpolated at the faces' points"}


def _lines(ids, per_line: int = 12) -> list[str]:
    ids = [int(v) for v in ids]
    return [", ".join(str(v) for v in ids[i:i + per_line]) for i in range(0, len(ids), per_line)]


def write_ccx(path: Path, mesh: BallMesh | OGridMesh, element: str, penalty: float = CCX_PENALTY) -> dict:
    """The CalculiX input: the ball and the flat of ``element`` (C3D20R: quadratic,
    C3D8I: linear) and the contact pair; what the run needs to read it back."""
    quadratic = element.startswith("C3D20")
    ball = octant(mesh, quadratic)
    flat = flat_block(flat_grid(mesh), quadratic)
    nb, eb = len(ball["nodes"]), len(ball["elements"])
    out = ["*HEADING", f"hertz3d ball {mesh.name} {element}: ball octant on a rigid flat", "*NODE"]
    out += [f"{k + 1}, {x:.15g}, {y:.15g}, {z:.15g}"
            for k, (x, y, z) in enumerate(np.vstack([ball["nodes"], flat["nodes"]]))]
    for name, conn, first in (("EBALL", ball["elements"] + 1, 1), ("EFLAT", flat["elements"] + nb + 1, eb + 1)):
        out.append(f"*ELEMENT, TYPE={element}, ELSET={name}")
        for k, c in enumerate(conn):
            vals = [str(first + k)] + [str(int(v)) for v in c]
            out += [", ".join(vals[:16]) + ("," if len(vals) > 16 else "")]
            if len(vals) > 16:
                out.append(", ".join(vals[16:]))
    sets = {"NX0": ball["x0"] + 1, "NY0": ball["y0"] + 1, "NTOP": ball["top"] + 1,
            "NSPHERE": ball["sphere"] + 1, "NFLAT": np.arange(nb + 1, nb + len(flat["nodes"]) + 1)}
    for name, ids in sets.items():
        out += [f"*NSET, NSET={name}", *_lines(ids)]
    out += ["*SURFACE, NAME=SSLAVE, TYPE=ELEMENT", *(f"{e + 1}, S2" for e in ball["surface_elements"])]
    out += ["*SURFACE, NAME=SMASTER, TYPE=ELEMENT", *(f"{e + eb + 1}, S2" for e in flat["top_elements"])]
    out += ["*MATERIAL, NAME=BALL", "*ELASTIC", f"{E}, {NU}",
            "*SOLID SECTION, ELSET=EBALL, MATERIAL=BALL", "*SOLID SECTION, ELSET=EFLAT, MATERIAL=BALL",
            "*SURFACE INTERACTION, NAME=SI1",
            "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR", f"{penalty * E / RADIUS:.6g}, 1e-9, 1e-3",
            "*CONTACT PAIR, INTERACTION=SI1, TYPE=SURFACE TO SURFACE", "SSLAVE, SMASTER",
            "*BOUNDARY", "NFLAT, 1, 3, 0.", "NX0, 1, 1, 0.", "NY0, 2, 2, 0.",
            "*STEP, INC=1000", "*STATIC", f"{1.0 / N_STEPS}, 1.0, 1e-6, {1.0 / N_STEPS}",
            "*BOUNDARY", f"NTOP, 3, 3, {UZ}",
            "*NODE PRINT, NSET=NSPHERE", "U",
            "*NODE PRINT, NSET=NTOP, TOTALS=ONLY", "RF", "*END STEP"]
    path.write_text("\n".join(out) + "\n")
    return {"dofs": 3 * nb, "elements": eb, "ball": ball}


def parse_dat(path: Path, n_nodes: int) -> tuple[np.ndarray, float]:
    """The last printed displacements (N, 3; NaN where not printed) and the last total
    force along z of the top face."""
    from .ccx_sphere import dat_tables
    u = np.full((n_nodes, 3), np.nan)
    tables = dat_tables(path, ("displacements", "total force"))
    for vals in tables["displacements"]:
        if len(vals) == 4 and int(vals[0]) <= n_nodes:
            u[int(vals[0]) - 1] = vals[1:]
    totals = [v for v in tables["total force"] if len(v) >= 3]
    rf = totals[-1][2] if totals else float("nan")
    return u, rf


def run_ccx(exe: str, w: Workdir, mesh: BallMesh | OGridMesh, element: str = "C3D20R",
            penalty: float = CCX_PENALTY) -> dict:
    """One CalculiX analysis (the whole process timed, one thread) and its measure."""
    from .ccx import iterations
    from .ccx_sphere import thread_environment
    d = w.path / "calculix3d"
    d.mkdir(parents=True, exist_ok=True)
    stem = f"ball-{mesh.name}-{element}-k{penalty:g}"
    info = write_ccx(d / f"{stem}.inp", mesh, element, penalty)
    t0 = time.perf_counter()
    proc = subprocess.run([exe, "-i", stem], cwd=d, capture_output=True, text=True,
                          env=thread_environment(1))
    wall = time.perf_counter() - t0
    (d / f"{stem}.log").write_text(proc.stdout + proc.stderr)
    if proc.returncode != 0 or "Job finished" not in proc.stdout:
        raise RuntimeError(f"ccx {stem} failed; see {d / f'{stem}.log'}")
    ball = info["ball"]
    u, rf = parse_dat(d / f"{stem}.dat", len(ball["nodes"]))
    faces = ball["surface"]
    if np.isnan(u[faces]).any():
        raise RuntimeError(f"ccx {stem}: displacements of slave nodes missing in the .dat")
    u = np.nan_to_num(u)
    slope = penalty * E / RADIUS
    law = measure(penalty_points(ball["nodes"], u, faces, slope), rf)
    out = {"code": "ccx", "mesh": mesh.name, "method": f"{element} K {penalty:g}", "solver": "spooles",
           "dofs": info["dofs"], "elements": info["elements"], "wall": wall,
           "iterations": iterations(proc.stdout), "l2_law": law["l2"]}
    if faces.shape[1] != 4:  # quadratic faces: no nodal areas; the Gram matrix's nodal pressures
        proj = projected_points(ball["nodes"], faces, penalty_points(ball["nodes"], u, faces, slope))
        return {**out, **measure(proj, rf), "l2_nodes": float("nan"),
                "measure": "nodal forces -> nodal pressures by the faces' Gram matrix, interpolated"}
    pts = penalty_nodal_points(ball["nodes"], u, faces, slope)
    nodes = np.unique(faces)
    return {**out, **measure(interpolated_points(ball["nodes"], faces, pts, nodes), rf),
            "l2_nodes": measure(pts, rf)["l2"],
            "measure": "nodal force / nodal area, interpolated at the faces' points"}


def short_name(r: dict) -> str:
    return re.sub(r"\s+", " ", f"{r['code']} {r['method']} {r['mesh']}")
