"""Hard cases of issue 6 (docs/robustness.md): the reduced subset of the suite in
`hard_cases.py` (the full suite is `make stress`), and the round-off floor of the
convergence test, which must accept a stiff-penalty state only when it is converged."""
from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

from hard_cases import HardCase, contact, run_case, solver, suite

REDUCED = [case for case in suite() if case.reduced]


@pytest.mark.parametrize("case", REDUCED, ids=[case.name for case in REDUCED])
def test_hard_case(voiga_bin: Path, tmp_path: Path, case: HardCase) -> None:
    """The case converges (and its result passes the case's checks), or is refused or
    fails with a message naming the reason, as the suite expects."""
    outcome = run_case(case, tmp_path, voiga_bin)
    assert outcome.ok, "\n".join(outcome.problems)


def test_floor_accepts_only_converged_steps(voiga_bin: Path, tmp_path: Path) -> None:
    """Penalty 1e9 x E: the relative tolerance 1e-10 is below the residual's round-off
    level; every step the floor accepts has a residual at least 1e-6 below the run's
    force scale r0_max (the floor's cap) and 1e-5 below its own first residual, and
    finite displacements."""
    case = HardCase("floor", "hertz", "m1-NN2.2", "", (contact(penalty_normal=1e9),))
    outcome = run_case(case, tmp_path, voiga_bin)
    assert outcome.ok, "\n".join(outcome.problems)
    with h5py.File(tmp_path / "result.h5") as f:
        assert f.attrs["status"] == b"converged"
        for name, step in f["steps"].items():
            r = step["residual_norms"][()]
            # r is the last substep's history: its first entry is that substep's r_0
            assert np.isfinite(r[-1]) and r[-1] <= 1e-6 * step.attrs["r0_max"], (name, r)
            assert r[-1] <= 1e-5 * r[0], (name, r)
            assert np.all(np.isfinite(step["displacement"][()]))


@pytest.mark.parametrize("max_iterations", [2, 4])
def test_floor_does_not_hide_an_unconverged_state(voiga_bin: Path, tmp_path: Path,
                                                  max_iterations: int) -> None:
    """Too few Newton iterations for penalty 1e9 x E and no cuts: the run must fail
    (exit 3, status failed), however stiff the penalty makes the round-off floor."""
    case = HardCase("unconverged", "hertz", "m1-NN2.2", "",
                    (contact(penalty_normal=1e9), solver(max_iterations=max_iterations, max_cuts=0)),
                    expect="fails", words=("Newton did not converge",))
    outcome = run_case(case, tmp_path, voiga_bin)
    assert outcome.ok, "\n".join(outcome.problems)
    with h5py.File(tmp_path / "result.h5") as f:
        assert f.attrs["status"].decode().startswith("failed")
        assert f.attrs["n_steps_done"] == 0


def test_suite_covers_issue_list() -> None:
    """Every item of issue 6's list has at least one case; names are unique."""
    names = [case.name for case in suite()]
    assert len(names) == len(set(names))
    for mesh in ["m1", "m2", "m3", "m4"]:
        assert sum(name.startswith(f"deep-{mesh}-") for name in names) == 8
    for prefix in ["penalty-1e1", "penalty-1e6", "ratio-1e3", "mu-1.0", "nu-0.49", "slide-off",
                   "apart-", "grazing-"]:
        assert any(name.startswith(prefix) for name in names), prefix
