"""Cross-check of the Fortran refinement against splipy's, for every
committed 2D case: ``voiga CASE.nml --check --dump TMP.h5`` must give the same
knots, control points, weights and DOF counts as ``python -m pre refine``.

The binary is ``$VOIGA_BIN``, else ``build/install/bin/voiga`` under the repo
root. Without it the tests skip, except under CI (``CI`` set), where they fail.
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

from pre.cases import STUDIES_3D
from pre.refine import Discretization, discretize_case, read_dump

from .conftest import CASES, REPO

TOL = 1e-12
TIMEOUT = 60  # seconds per case; a hang fails that case and every later one at once
_hung: list[Path] = []
# the 2D scenes: pre.refine refines curves and surfaces (the 3D study's cases,
# pre.cases.STUDIES_3D, count their DOFs with pre.solid_case, checked in test_hertz3d.py)
CASE_FILES = sorted(p for p in CASES.glob("*/*.nml") if p.parent.name not in STUDIES_3D)


def _voiga_bin() -> Path | None:
    env = os.environ.get("VOIGA_BIN")
    path = Path(env) if env else REPO / "build" / "install" / "bin" / "voiga"
    return path if path.is_file() and os.access(path, os.X_OK) else None


@pytest.fixture(scope="module")
def voiga() -> Path:
    path = _voiga_bin()
    if path is None:
        where = os.environ.get("VOIGA_BIN") or "build/install/bin/voiga"
        msg = (f"voiga binary not found ({where}); build it or set VOIGA_BIN "
               "to run the Fortran/splipy refinement cross-check")
        if os.environ.get("CI"):
            pytest.fail(msg)
        pytest.skip(msg)
    return path


def _close(a: np.ndarray, b: np.ndarray, what: str) -> None:
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape, f"{what}: shape {a.shape} (voiga) != {b.shape} (splipy)"
    if a.size:
        err = np.abs(a.astype(float) - b.astype(float)).max()
        assert err <= TOL, f"{what}: max difference {err:.3e} > {TOL}"


def compare(fortran: Discretization, python: Discretization) -> None:
    """Assert that two discretizations agree (degrees, knots, points, weights,
    DOF counts, presence of the layer)."""
    assert set(fortran.bodies) == set(python.bodies)
    for name, p in python.bodies.items():
        f = fortran.bodies[name]
        assert (f.interface_dofs, f.bulk_dofs, f.total_dofs) == \
            (p.interface_dofs, p.bulk_dofs, p.total_dofs), f"{name}: DOF attrs"
        assert tuple(f.bulk.degree) == tuple(p.bulk.degree), f"{name}: bulk degree"
        _close(f.bulk.knots_xi, p.bulk.knots_xi, f"{name}/bulk/knots_xi")
        _close(f.bulk.knots_eta, p.bulk.knots_eta, f"{name}/bulk/knots_eta")
        _close(f.bulk.control_points, p.bulk.control_points, f"{name}/bulk/control_points")
        _close(f.bulk.weights, p.bulk.weights, f"{name}/bulk/weights")
        assert (f.layer is None) == (p.layer is None), f"{name}: layer present in one only"
        if p.layer is not None:
            assert f.layer.degree == p.layer.degree, f"{name}: layer degree"
            _close(f.layer.knots, p.layer.knots, f"{name}/layer/knots")
            _close(f.layer.control_points, p.layer.control_points, f"{name}/layer/control_points")
            _close(f.layer.weights, p.layer.weights, f"{name}/layer/weights")


def test_cases_exist() -> None:
    assert CASE_FILES, "no committed cases under cases/: run `python -m pre cases`"


@pytest.mark.parametrize("case", CASE_FILES, ids=[str(c.relative_to(CASES)) for c in CASE_FILES])
def test_fortran_matches_splipy(voiga: Path, case: Path, tmp_path: Path) -> None:
    if _hung:
        pytest.fail(f"not run: voiga timed out earlier on {_hung[0]}")
    dump = tmp_path / "dump.h5"
    try:
        run = subprocess.run([str(voiga), str(case), "--check", "--dump", str(dump)],
                             capture_output=True, text=True, timeout=TIMEOUT, cwd=REPO,
                             stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:
        _hung.append(case)
        pytest.fail(f"voiga did not finish within {TIMEOUT} s on {case}")
    assert run.returncode == 0, (f"voiga failed ({run.returncode}) on {case}:\n"
                                 f"{run.stdout[-2000:]}\n{run.stderr[-2000:]}")
    assert dump.is_file(), f"voiga wrote no dump for {case}"
    compare(read_dump(dump), discretize_case(case))


def test_compare_detects_differences(tmp_path: Path) -> None:
    """The comparison itself (runs without the binary): a perturbed copy fails."""
    case = CASES / "ironing" / "m1-NN2.2.nml"
    if not case.is_file():
        pytest.skip("cases/ not generated")
    a, b = discretize_case(case), discretize_case(case)
    compare(a, b)
    b.bodies["die"].layer.control_points[3, 1] += 1e-10
    with pytest.raises(AssertionError, match="layer/control_points"):
        compare(a, b)
    b = discretize_case(case)
    b.bodies["slab"].interface_dofs += 2
    with pytest.raises(AssertionError, match="DOF"):
        compare(a, b)
