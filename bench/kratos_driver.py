"""Runs one Kratos Multiphysics analysis of the Hertz problem written by bench/kratos.py.

This file is executed by the Python of Kratos's own virtual environment
(build/kratos-venv), not imported by the bench: it needs only KratosMultiphysics and the
standard library. ``python kratos_driver.py job.json`` reads the analysis parameters
(``parameters``) and the node ids to report (``slave_nodes``, ``top_nodes``) from the job
file (``dimension``: 2, the default, or 3 for the sphere of section 9; ``reaction``: the
variable summed over the top nodes, REACTION_Y unless given), runs the analysis in the
job's directory and writes ``result.json`` there: the reference coordinates,
displacements and contact variables of the slave nodes, the total reaction on the top
cut, the Newton iterations per step and the seconds spent in the analysis (import and
set-up excluded).
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import KratosMultiphysics as KM
import KratosMultiphysics.ContactStructuralMechanicsApplication as CSMA  # noqa: F401
import KratosMultiphysics.LinearSolversApplication  # noqa: F401
from KratosMultiphysics.StructuralMechanicsApplication.structural_mechanics_analysis import StructuralMechanicsAnalysis


class CountingAnalysis(StructuralMechanicsAnalysis):
    """The structural analysis, recording the Newton iterations of every step."""

    def __init__(self, model: KM.Model, parameters: KM.Parameters):
        super().__init__(model, parameters)
        self.iterations: list[int] = []

    def FinalizeSolutionStep(self) -> None:
        super().FinalizeSolutionStep()
        info = self._GetSolver().GetComputingModelPart().ProcessInfo
        self.iterations.append(int(info[KM.NL_ITERATION_NUMBER]))


def nodal(node: KM.Node, name: str) -> float | None:
    """Non-historical value of the variable ``name`` at ``node``, else its historical
    value, else None."""
    var = KM.KratosGlobals.GetVariable(name)
    if node.Has(var):
        return float(node.GetValue(var))
    if node.SolutionStepsDataHas(var):
        return float(node.GetSolutionStepValue(var))
    return None


def main(job_path: str) -> int:
    job = json.loads(Path(job_path).read_text())
    KM.Logger.GetDefaultOutput().SetSeverity(KM.Logger.Severity.WARNING)
    model = KM.Model()
    analysis = CountingAnalysis(model, KM.Parameters(json.dumps(job["parameters"])))
    t0 = time.perf_counter()
    analysis.Run()
    seconds = time.perf_counter() - t0
    part = model["Structure"]
    dim = int(job.get("dimension", 2))
    slave = []
    for i in job["slave_nodes"]:
        n = part.GetNode(i)
        row = {"id": i, "x0": n.X0, "y0": n.Y0,
               "ux": n.GetSolutionStepValue(KM.DISPLACEMENT_X),
               "uy": n.GetSolutionStepValue(KM.DISPLACEMENT_Y), "active": n.Is(KM.ACTIVE)}
        if dim == 3:
            row.update(z0=n.Z0, uz=n.GetSolutionStepValue(KM.DISPLACEMENT_Z))
        for name in job["contact_variables"]:
            row[name] = nodal(n, name)
        row["force"] = [0.0] * dim
        slave.append(row)
    # nodal forces of the elements on the slave nodes (the contact force they balance)
    index = {r["id"]: r for r in slave}
    for elem in part.Elements:
        ids = [node.Id for node in elem.GetNodes()]
        if not any(i in index for i in ids):
            continue
        rhs = KM.Vector()
        elem.CalculateRightHandSide(rhs, part.ProcessInfo)
        for k, i in enumerate(ids):
            if i in index:
                for c in range(dim):
                    index[i]["force"][c] += rhs[dim * k + c]
    var = KM.KratosGlobals.GetVariable(job.get("reaction", "REACTION_Y"))
    reaction = sum(part.GetNode(i).GetSolutionStepValue(var) for i in job["top_nodes"])
    info = part.ProcessInfo
    out = {"initial_penalty": info[KM.INITIAL_PENALTY], "scale_factor": info[KM.SCALE_FACTOR],
           "seconds": seconds, "iterations": analysis.iterations, "reaction_y": reaction, "reaction": reaction,
           "slave": slave, "time": part.ProcessInfo[KM.TIME]}
    (Path(job_path).parent / "result.json").write_text(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
