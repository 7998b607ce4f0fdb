"""Solving with `voiga case.nml`: the result file, its status, and failures that keep results."""
from __future__ import annotations

import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest

from conftest import REPO

STRETCH = """&case
  title = 'slab stretch', geometry = 'geometry.h5', output = 'out/stretch.h5', n_bodies = 1
/
&body
  name = 'slab', material = '{material}', youngs_modulus = 1.0, poisson_ratio = 0.3,
  degree_xi = 2, degree_eta = 2, nel_xi = 8, nel_eta = 2, contact_edge = 'top',
  layer_degree = 2, layer_elevations = 2
/
&solver
  n_steps = {steps}
/
&dirichlet
  body = 'slab', edge = 'left', fix_x = .true., ux = {ux0}
/
&dirichlet
  body = 'slab', edge = 'bottom', fix_y = .true., uy = {uy0}
/
&dirichlet
  body = 'slab', edge = '{right}', fix_x = .true., ux = {ux}
/
"""


def write_case(tmp: Path, **kw) -> Path:
    values = dict(material="linear", steps="2", ux0="0.0", uy0="0.0", right="right", ux="0.09")
    values.update(kw)
    shutil.copy(REPO / "cases" / "ironing" / "geometry.h5", tmp / "geometry.h5")
    (tmp / "out").mkdir(exist_ok=True)
    case = tmp / "case.nml"
    case.write_text(STRETCH.format(**values))
    return case


def test_stretch_result_file(run, tmp_path: Path) -> None:
    case = write_case(tmp_path)
    res = run(case, "--quiet")
    assert res.returncode == 0, res.stderr
    with h5py.File(tmp_path / "out" / "stretch.h5") as f:
        assert f.attrs["status"] == b"converged"
        assert f.attrs["n_steps_done"] == 2 and len(f["steps"]) == 2
        # no friction, no Tresca retry
        assert f.attrs["tresca_retries"] == f.attrs["tresca_accepted"] == 0
        # linear: one Newton iteration in step 1; step 2 starts from the predictor
        # (step 1's increment), which is exact for proportional loading
        assert f["steps/000001"].attrs["iterations"] == 1
        step = f["steps/000002"]
        assert step.attrs["iterations"] == 0
        # a stable (positive definite) tangent; step 2 factorized nothing and keeps step 1's sign
        assert f["steps/000001"].attrs["tangent_det_sign"] == 1
        assert step.attrs["tangent_det_sign"] == 1
        for stage in ("assembly", "contact", "factorization", "solve", "output"):
            assert step.attrs[f"seconds_{stage}"] >= 0.0
        # plane strain, sigma_yy = 0: reaction = E/(1-nu^2) * 0.01 * height 3 on the right edge
        reactions = step["reactions"][()]
        assert reactions.shape == (3, 2)
        np.testing.assert_allclose(reactions[2, 0], 0.03 / 0.91, rtol=1e-10)
        np.testing.assert_allclose(reactions[0, 0], -0.03 / 0.91, rtol=1e-10)
        x = f["bodies/slab/control_points"][()]
        u = step["displacement"][()].reshape(-1, 2)
        np.testing.assert_allclose(u[:, 0], 0.01 * x[:, 0], atol=1e-12)
        np.testing.assert_allclose(u[:, 1], -0.3 / 0.7 * 0.01 * (x[:, 1] + 3.0), atol=1e-12)


def test_progress_lines_and_quiet(run, tmp_path: Path) -> None:
    case = write_case(tmp_path, steps="3", ux="0.03")
    loud = run(case)
    assert loud.returncode == 0, loud.stderr
    assert "step 1/3" in loud.stdout and "step 3/3" in loud.stdout and "converged" in loud.stdout
    quiet = run(case, "--quiet")
    assert "step 1/3" not in quiet.stdout


def test_unknown_dirichlet_edge_writes_no_result(run, tmp_path: Path) -> None:
    case = write_case(tmp_path, right="rightside")
    res = run(case)
    assert res.returncode == 2
    assert "&dirichlet (3)" in res.stderr and "rightside" in res.stderr and "case.nml" in res.stderr
    assert not (tmp_path / "out" / "stretch.h5").exists()


@pytest.mark.parametrize(
    "edit,words",
    [
        ({"steps": "0"}, ["&solver", "n_steps"]),
        ({"ux": "0.1, 0.2"}, ["&dirichlet (3)", "ux", "one value per load phase"]),
        ({"ux0": "'abc'"}, ["&dirichlet", "ux", "wrong type"]),
    ],
)
def test_bad_load_input(run, tmp_path: Path, edit: dict, words: list[str]) -> None:
    case = write_case(tmp_path, **edit)
    res = run(case)
    assert res.returncode == 2, (res.stdout, res.stderr)
    for word in words:
        assert word in res.stderr, res.stderr
    assert not (tmp_path / "out" / "stretch.h5").exists()


def test_unknown_group_refused(run, tmp_path: Path) -> None:
    case = write_case(tmp_path)
    case.write_text(case.read_text() + "&dirichlett\n  body = 'slab'\n/\n")
    res = run(case)
    assert res.returncode == 2
    assert "&dirichlett" in res.stderr


def test_failed_step_keeps_converged_steps(run, tmp_path: Path) -> None:
    """Crushing the slab to nothing fails in step 2; step 1 stays readable."""
    case = write_case(tmp_path, material="neo-hookean", steps="1, 1", ux="0.0, 0.0",
                      ux0="0.0, 0.0", uy0="0.0, 0.0")
    text = case.read_text().replace("edge = 'bottom', fix_y = .true., uy = 0.0, 0.0",
                                    "edge = 'bottom', fix_y = .true., uy = 0.1, 4.0")
    text = text.replace("edge = 'left', fix_x = .true., ux = 0.0, 0.0",
                        "edge = 'left', fix_x = .true., fix_y = .false., ux = 0.0, 0.0")
    case.write_text(text)
    # clamp the top too, so that lifting the bottom by 4 (the slab is 3 high) inverts it
    case.write_text(case.read_text() + "&dirichlet\n  body = 'slab', edge = 'top', fix_y = .true., "
                    "uy = 0.0, 0.0\n/\n")
    res = run(case, "--quiet")
    assert res.returncode == 3, (res.stdout, res.stderr)
    assert "step 2" in res.stderr
    with h5py.File(tmp_path / "out" / "stretch.h5") as f:
        status = f.attrs["status"].decode()
        assert status.startswith("failed: step 2"), status
        assert f.attrs["n_steps_done"] == 1
        assert list(f["steps"]) == ["000001"]
