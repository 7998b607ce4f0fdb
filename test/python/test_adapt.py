"""Issue 39: `post run CASE --adapt` from the committed hertz m2 NN2.2 mesh (voiga's
default contact settings), and a second refinement of the converged case
(docs/verification.md, "Contact-zone refinement")."""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from conftest import REPO
from post.adapt import largest_estimate, pressure_change, refine_result
from post.hertz import hertz_comparison
from post.reader import read_result


def test_adapt_hertz_m2(voiga_bin: Path, tmp_path: Path) -> None:
    shutil.copy(REPO / "cases" / "hertz" / "geometry.h5", tmp_path)
    text = (REPO / "cases" / "hertz" / "m2-NN2.2.nml").read_text()
    case = tmp_path / "m2-NN2.2.nml"
    case.write_text(re.sub(r"\n *(penalty_normal|method) = [^\n]*", "", text))
    run = subprocess.run([sys.executable, "-m", "post", "run", str(case), "--adapt", "--target", "0.2%",
                          "--no-figures", "--no-vtk"], cwd=REPO, capture_output=True, text=True,
                         timeout=600, env={**os.environ, "VOIGA_BIN": str(voiga_bin)})
    assert run.returncode == 0, run.stderr
    cycles = [line for line in run.stdout.splitlines() if line.startswith("cycle ")]
    assert 2 <= len(cycles) <= 4 and "target 0.20% met" in run.stdout, run.stdout
    # the last result lands where a plain `post run CASE` puts it, the cycles beside it
    final = read_result(tmp_path / "m2-NN2.2.h5")
    last = read_result(tmp_path / f"m2-NN2.2-zone{len(cycles) - 1}" / f"m2-NN2.2-zone{len(cycles) - 1}.h5")
    assert final.n_dofs == last.n_dofs and final.case_file == last.case_file
    assert f"result: {tmp_path / 'm2-NN2.2.h5'} " in run.stdout
    assert (tmp_path / "m2-NN2.2-zone0" / "m2-NN2.2.h5").is_file()  # cycle 0's
    assert case.read_text() == re.sub(r"\n *(penalty_normal|method) = [^\n]*", "", text)  # input untouched
    # nothing earlier is replaced in the case's own folder without --overwrite
    again_run = subprocess.run([sys.executable, "-m", "post", "run", str(case), "--adapt", "--no-figures"],
                               cwd=REPO, capture_output=True, text=True, timeout=600,
                               env={**os.environ, "VOIGA_BIN": str(voiga_bin)})
    assert again_run.returncode == 2 and "nothing solved" in again_run.stderr
    # measured: 10,708 DOFs after two refinements, every step within 0.17 % of the exact
    # circle (the loop stops at an estimate of 0.7 times the target: at the target itself
    # it made 11,392 DOFs in three and left step 2 at 0.216 %)
    assert final.n_dofs <= 12000
    for st in final.steps:
        assert hertz_comparison(final, step=st.step, reference="circle").error.l2 <= 0.002
    # a second refinement of the converged case (a tighter target) changes the pressure by
    # less than the target and about the estimate (measured 0.175 % for an estimate of
    # 0.129 %; it was 0.22 % when the loop stopped at the target)
    again = refine_result(final.path, 0.001, tmp_path / "again")
    subprocess.run([str(voiga_bin), again.case.name, "--quiet"], cwd=again.case.parent, check=True,
                   timeout=600, capture_output=True)
    change = pressure_change(final, read_result(again.case.with_suffix(".h5")))
    estimate = largest_estimate(final)
    assert estimate / 2 <= change <= 2 * estimate
    assert change < 0.002
