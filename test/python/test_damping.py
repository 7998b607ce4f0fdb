"""`&solver damping = 'natural'` (docs/robustness.md, "Natural damping"): the same
solution as the default residual damping where both converge, reached with fewer Newton
iterations and cuts on a stiff normal penalty; bad values refused."""
from __future__ import annotations

import re
import subprocess
from pathlib import Path

import h5py
import numpy as np
import pytest

from hard_cases import HardCase, contact, dirichlet, prepare, solver
from test_restart import compare, truncate

E_SLAB = 1.0

CONVERGED = re.compile(r"^converged: \d+ steps \(\d+ substeps, (\d+) cuts\), (\d+) Newton iterations", re.M)


def stiff_ironing(damping: str, *extra) -> HardCase:
    """ironing m1-NN2.2 with the normal penalty 1e4 x E (tangential 1e2 x E), pressed in
    10 steps and slid 0.6 in 30: the first 40 steps of the hard case penalty-n1e4-t1e2."""
    return HardCase(f"stiff-{damping}", "ironing", "m1-NN2.2", "",
                    (contact(penalty_normal=1e4 * E_SLAB, penalty_tangent=1e2 * E_SLAB),
                     dirichlet("die", "inner", ux=[0.0, 0.6]), solver(n_steps=[10, 30], damping=damping),
                     *extra))


def run_case(voiga_bin: Path, directory: Path, case: HardCase) -> subprocess.CompletedProcess:
    directory.mkdir()
    path = prepare(case, directory)
    return subprocess.run([str(voiga_bin), path.name], cwd=directory, capture_output=True, text=True,
                          timeout=300)


def test_natural_damping_same_solution_fewer_iterations(voiga_bin: Path, tmp_path: Path) -> None:
    """Both dampings solve the same incremental problems: every step's displacement agrees
    to 1e-8 of the largest (both to tol_residual 1e-10; measured 2.3e-10). With the stiff
    normal penalty the residual rule halves Newton steps that the simplified correction
    accepts, and cuts twice (measured: 884 Newton iterations and 2 cuts against 635 and
    0): natural damping must not take more of either."""
    counts = {}
    for damping in ("residual", "natural"):
        proc = run_case(voiga_bin, tmp_path / damping, stiff_ironing(damping))
        assert proc.returncode == 0, proc.stderr[-2000:]
        m = CONVERGED.search(proc.stdout)
        assert m, proc.stdout[-2000:]
        counts[damping] = (int(m.group(1)), int(m.group(2)))
    assert counts["natural"][0] <= counts["residual"][0], counts
    assert counts["natural"][1] < counts["residual"][1], counts
    with h5py.File(tmp_path / "residual" / "result.h5") as fr, h5py.File(tmp_path / "natural" / "result.h5") as fn:
        assert fr.attrs["damping"] == b"residual" and fn.attrs["damping"] == b"natural"
        assert fr.attrs["status"] == fn.attrs["status"] == b"converged"
        assert list(fr["steps"]) == list(fn["steps"])
        for name in fr["steps"]:
            ur = fr["steps"][name]["displacement"][()]
            un = fn["steps"][name]["displacement"][()]
            assert np.max(np.abs(un - ur)) <= 1e-8 * np.max(np.abs(ur)), name


def test_natural_damping_restart_reproduces(voiga_bin: Path, tmp_path: Path) -> None:
    """A natural-damping run continued after step 25 of its 40 (sliding, stiff penalty)
    reproduces the uninterrupted run to 1e-12: the damping keeps no state across
    substeps."""
    proc = run_case(voiga_bin, tmp_path / "run", stiff_ironing("natural"))
    assert proc.returncode == 0, proc.stderr[-2000:]
    full = tmp_path / "run" / "result.h5"
    partial = tmp_path / "run" / "partial.h5"
    partial.write_bytes(full.read_bytes())
    truncate(partial, 25)
    proc = subprocess.run([str(voiga_bin), "--restart", partial.name, "--quiet"], cwd=partial.parent,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    with h5py.File(partial) as f:
        assert f.attrs["status"] == b"converged" and f.attrs["n_steps_done"] == 40
    compare(full, partial)


@pytest.mark.parametrize("value, extra, words", [
    ("newton", (), ("damping = 'newton'", "'residual' or 'natural'")),
    ("natural", (solver(linear_solver="multigrid"),), ("damping = 'natural'", "linear_solver = 'direct'")),
])
def test_bad_damping_refused(voiga_bin: Path, tmp_path: Path, value: str, extra: tuple,
                             words: tuple[str, ...]) -> None:
    """An unknown value, and natural damping with the multigrid solver (its test solves
    with the last LU factors, which multigrid does not have): exit 2, naming &solver."""
    proc = run_case(voiga_bin, tmp_path / "case", stiff_ironing(value, *extra))
    assert proc.returncode == 2, proc.stderr
    assert "&solver" in proc.stderr
    for word in words:
        assert word in proc.stderr, proc.stderr


@pytest.mark.parametrize("damping", ["residual", "natural"])
def test_creeping_names_natural_damping(voiga_bin: Path, tmp_path: Path, damping: str) -> None:
    """A stiff penalty (1e6 x E, mortar) on the first press step without cuts: with
    residual damping Newton creeps (most steps 1/16 or shorter) and the failure message
    names natural damping; with natural damping it does not."""
    case = HardCase(f"creep-{damping}", "ironing", "m1-NN2.2", "",
                    (contact(penalty_normal=1e6 * E_SLAB, penalty_tangent=1e6 * E_SLAB, method="mortar"),
                     dirichlet("die", "inner", ux=[0.0], uy=[-0.05]),
                     solver(n_steps=[1], damping=damping, max_cuts=0)))
    proc = run_case(voiga_bin, tmp_path / "case", case)
    hint = "damping = 'natural' may pass it"
    if damping == "residual":
        assert proc.returncode == 3, proc.stderr
        assert hint in proc.stderr and "took steps of 1/16 or less" in proc.stderr, proc.stderr
    else:
        assert hint not in proc.stderr, proc.stderr
