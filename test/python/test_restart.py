"""--restart (issue 6): a run continued from its result file after an interruption
reproduces the uninterrupted run to 1e-12, friction history included."""
from __future__ import annotations

import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from conftest import REPO

sys.path.insert(0, str(REPO))
from post.journal import recover  # noqa: E402
from post.reader import open_result  # noqa: E402

CASE = """&case
  title = 'restart block', geometry = 'geometry.h5', output = 'run.h5', n_bodies = 1
/
&body
  name = 'slab', material = 'neo-hookean', youngs_modulus = 1.0, poisson_ratio = 0.3,
  degree_xi = 2, degree_eta = 2, nel_xi = 4, nel_eta = 2, contact_edge = 'bottom',
  layer_degree = 2, layer_elevations = 2
/
&solver
  n_steps = 3, {slide}
/
&dirichlet
  body = 'slab', edge = 'top', fix_x = .true., fix_y = .true., ux = 0.0, 0.6, uy = -0.06, -0.06
/
&contact
  slave = 'slab', master = 'rigid', rigid_point = 0.0, -3.0, rigid_normal = 0.0, 1.0,
  penalty_normal = 100.0, penalty_tangent = 100.0, friction = 0.3, n_gauss = 8, method = '{method}'
/
"""


def setup(tmp: Path, slide: int, method: str = "gpts") -> Path:
    shutil.copy(REPO / "cases" / "ironing" / "geometry.h5", tmp / "geometry.h5")
    case = tmp / "case.nml"
    case.write_text(CASE.format(slide=slide, method=method))
    return case


def steps(path: Path) -> dict[str, dict[str, np.ndarray]]:
    with h5py.File(path, "r") as f:
        return {k: {"u": g["displacement"][()], "pn": g["contact/1/p_n"][()], "pt": g["contact/1/p_t"][()],
                    "det": g.attrs["tangent_det_sign"]}
                for k, g in f["steps"].items()}


def truncate(path: Path, keep: int) -> None:
    """Make `path` look like a run killed after `keep` steps."""
    with h5py.File(path, "r+") as f:
        for k in list(f["steps"]):
            if int(k) > keep:
                del f["steps"][k]
        f.attrs["n_steps_done"] = np.int32(keep)
        f.attrs["status"] = np.bytes_("interrupted")


def restart_after(run, folder: Path, keep: int, *args: str):  # noqa: ANN001, ANN201
    """The finished run's `run.h5` kept as `full.h5`; a copy cut after `keep` steps
    (`partial.h5`) continued with --restart (exit 0 asserted). (full, partial, the
    restart's process)."""
    full, partial = folder / "full.h5", folder / "partial.h5"
    shutil.copy(folder / "run.h5", full)
    shutil.copy(full, partial)
    truncate(partial, keep)
    res = run("--restart", partial, *args)
    assert res.returncode == 0, res.stderr
    return full, partial, res


def compare(a: Path, b: Path) -> None:
    sa, sb = steps(a), steps(b)
    assert sa.keys() == sb.keys()
    for k in sa:
        for key in ("u", "pn", "pt"):
            np.testing.assert_allclose(sb[k][key], sa[k][key], rtol=0, atol=1e-12, err_msg=f"{k} {key}")
        assert sb[k]["det"] == sa[k]["det"], k


@pytest.mark.parametrize("method", ["gpts", "mortar", "segment"])
@pytest.mark.parametrize("keep", [2, 5])
def test_restart_reproduces_uninterrupted_run(run, tmp_path: Path, keep: int, method: str) -> None:
    """The friction history is the stick anchors per slave point (GPTS) or the
    tangential tractions per slave control point (mortar, segment)."""
    case = setup(tmp_path, 6, method)
    res = run(case, "--quiet")
    assert res.returncode == 0, res.stderr
    with h5py.File(tmp_path / "run.h5") as f:
        history = f["steps"][max(f["steps"], key=int)]["contact/1/history"]
        assert ("traction" in history) == (method in ("mortar", "segment"))
        assert ("anchor" in history) == (method == "gpts")
        if method != "gpts":          # the slab slides: its control points carry mu p_A
            assert np.abs(history["traction"][()]).max() > 0.0
    # steps 1..keep; keep = 5 is in the sliding phase
    full, partial, _ = restart_after(run, tmp_path, keep, "--quiet")
    with h5py.File(partial) as f:
        assert f.attrs["status"] == b"converged" and f.attrs["n_steps_done"] == 9
    compare(full, partial)


def softened_case(tmp_path: Path, stick_predictor: bool) -> Path:
    """alm at 1e6 x E with 4 Newton iterations per attempt (the slab in contact from the
    start, friction in the press)."""
    case = setup(tmp_path, 6, "alm")
    solver = "n_steps = 3, 6, max_iterations = 4" + ("" if stick_predictor else ", stick_predictor = .false.")
    case.write_text(case.read_text()
                    .replace("penalty_normal = 100.0, penalty_tangent = 100.0",
                             "penalty_normal = 1e6, penalty_tangent = 1e6")
                    .replace("n_steps = 3, 6", solver))
    return case


@pytest.mark.parametrize("keep", [2, 5])
def test_restart_keeps_softened_penalties(run, tmp_path: Path, keep: int) -> None:
    """The softened case softens its penalties at steps 1 and 4 (docs/theory.md,
    "Softening"); a restart after step 2 or 5 goes on with the penalties of the last
    written step and reproduces the uninterrupted run. Without the stick predictor: with
    it, see the next test."""
    case = softened_case(tmp_path, stick_predictor=False)
    res = run(case)
    assert res.returncode == 0, res.stderr
    assert res.stdout.count("soften step 1 ") == 3 and res.stdout.count("soften step 4 ") == 2
    with h5py.File(tmp_path / "run.h5") as f:
        used = [f[f"steps/{k}/contact/1"].attrs["penalty_normal"] for k in sorted(f["steps"])]
    assert used[0] == pytest.approx(1e3) and used[-1] < 100.0
    full, partial, res = restart_after(run, tmp_path, keep)
    assert ("soften step 4 " in res.stdout) == (keep < 4)
    compare(full, partial)


@pytest.mark.parametrize("keep", [1, 2, 3])
def test_restart_after_stick_predictions(run, tmp_path: Path, keep: int) -> None:
    """The softened case with the stick predictor (26 predictions, most in step 1): a
    restart after step 1, 2 or 3 reproduces the run bit for bit. Two things made it
    differ before: alm's tangential multipliers went on from their last update at a
    commit but from the committed tractions after a restart (1.8e-9 in u at step 3);
    and the supernodal LU kept an analysis made for the nonzeros of earlier matrices
    (the predictor's, every point sticking), so a restart eliminated in another order
    (2.4e-12 in p_N). A substep's first factorization now keeps an analysis only for
    the same nonzeros (`renew_analysis`)."""
    res = run(softened_case(tmp_path, stick_predictor=True), "--quiet")
    assert res.returncode == 0, res.stderr
    compare(*restart_after(run, tmp_path, keep, "--quiet")[:2])


def test_restart_checks_the_dimension(run, tmp_path: Path) -> None:
    """Issue 37 item 5: a result records its spatial dimension (root attribute
    ``dimension``, 2 here). A restart from a file whose dimension is not its case's
    model's is refused, forced or not, naming both, and leaves the file as it was; a
    file without the attribute (an older voiga's: 2D) is continued and reproduces the
    run."""
    res = run(setup(tmp_path, 2), "--quiet")
    assert res.returncode == 0, res.stderr
    with h5py.File(tmp_path / "run.h5") as f:
        assert f.attrs["dimension"] == 2 and f.attrs["dimension"].dtype.kind == "i"
        assert [f["dirichlet/1"].attrs[k] for k in ("fix_x", "fix_y")] == [1, 1]
        assert "fix_z" not in f["dirichlet/1"].attrs and f["steps/000001/reactions"].shape == (1, 2)
    full = tmp_path / "full.h5"
    shutil.copy(tmp_path / "run.h5", full)
    for name in ("three.h5", "older.h5"):
        shutil.copy(full, tmp_path / name)
        truncate(tmp_path / name, 2)
    with h5py.File(tmp_path / "three.h5", "r+") as f:
        f.attrs["dimension"] = np.int32(3)
    before = (tmp_path / "three.h5").read_bytes()
    for forced in ([], ["--force-restart"]):
        res = run("--restart", tmp_path / "three.h5", "--quiet", *forced)
        assert res.returncode == 2, res.stdout + res.stderr
        assert "is of dimension 3" in res.stderr and "model is of dimension 2" in res.stderr, res.stderr
        assert (tmp_path / "three.h5").read_bytes() == before
    with h5py.File(tmp_path / "older.h5", "r+") as f:
        del f.attrs["dimension"]
    res = run("--restart", tmp_path / "older.h5", "--quiet")
    assert res.returncode == 0, res.stderr
    with h5py.File(tmp_path / "older.h5") as f:
        assert f.attrs["status"] == b"converged" and f.attrs["n_steps_done"] == 5
    compare(full, tmp_path / "older.h5")


IRONING = """&case
  title = 'restart ironing', geometry = 'geometry.h5', output = 'run.h5', n_bodies = 2
/
&body
  name = 'die', material = 'neo-hookean', youngs_modulus = 10.0, poisson_ratio = 0.3,
  degree_xi = 2, degree_eta = 2, nel_xi = 6, nel_eta = 1, contact_edge = 'outer',
  layer_degree = 2, layer_elevations = 2
/
&body
  name = 'slab', material = 'neo-hookean', youngs_modulus = 1.0, poisson_ratio = 0.3,
  degree_xi = 2, degree_eta = 2, nel_xi = 8, nel_eta = 2, contact_edge = 'top',
  layer_degree = 2, layer_elevations = 2
/
&solver
  n_steps = 3, 6
/
&dirichlet
  body = 'die', edge = 'inner', fix_x = .true., fix_y = .true., ux = 0.0, 0.6, uy = -0.3, -0.3
/
&dirichlet
  body = 'slab', edge = 'bottom', fix_x = .true., fix_y = .true.
/
&contact
  slave = 'die', master = 'slab', penalty_normal = 100.0, penalty_tangent = 100.0, friction = 0.3,
  method = 'segment'
/
"""


@pytest.mark.parametrize("keep", [2, 5])
def test_restart_segment_points(run, tmp_path: Path, keep: int) -> None:
    """The segment method's points are state: made at every converged state where the
    slab's knots project onto the die, so their number changes as the die slides (55
    points, then 60); each step writes them (history point_xi, point_w, point_element)
    and a restart continues on those of the last written step. To round-off, as the
    mortar pair here: the LU's analysis drops the entries that are zero at its first
    factorization, so the restarted run (analysed at step keep + 1) can order the
    factorization otherwise (1e-15 apart; with the structural pattern analysed, both
    methods reproduce the run to the bit)."""
    shutil.copy(REPO / "cases" / "ironing" / "geometry.h5", tmp_path / "geometry.h5")
    case = tmp_path / "case.nml"
    case.write_text(IRONING)
    res = run(case, "--quiet")
    assert res.returncode == 0, res.stderr
    with h5py.File(tmp_path / "run.h5") as f:
        counts = {k: g["contact/1/xi_slave"].shape[0] for k, g in f["steps"].items()}
        last = f["steps"][max(f["steps"], key=int)]["contact/1"]
        np.testing.assert_array_equal(last["history/point_xi"][()], last["xi_slave"][()])
    assert len(set(counts.values())) > 1, counts
    full, partial, _ = restart_after(run, tmp_path, keep, "--quiet")
    compare(full, partial)
    with h5py.File(full) as a, h5py.File(partial) as b:
        for k in a["steps"]:
            np.testing.assert_allclose(b[f"steps/{k}/contact/1/xi_slave"][()], a[f"steps/{k}/contact/1/xi_slave"][()],
                                       rtol=0, atol=1e-12, err_msg=k)


def test_restart_after_kill9(voiga_bin: Path, tmp_path: Path) -> None:
    """kill -9 at a random point: the file opens with every completed step, and a
    restart reproduces the uninterrupted results."""
    case = setup(tmp_path, 400)
    subprocess.run([str(voiga_bin), str(case), "--quiet"], check=True, capture_output=True, cwd=tmp_path)
    full = tmp_path / "full.h5"
    shutil.move(tmp_path / "run.h5", full)
    proc = subprocess.Popen([str(voiga_bin), str(case), "--quiet"], cwd=tmp_path,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 60
    done = 0
    while time.time() < deadline and proc.poll() is None:
        time.sleep(0.05)
        if not (tmp_path / "run.h5").exists():   # until its first step is written
            continue
        # a running result read the safe way (docs/hdf5.md): between steps, whole
        with open_result(tmp_path / "run.h5") as f:
            done = int(f.attrs["n_steps_done"])
        if done >= 20:
            break
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    if done < 20:
        pytest.skip("the run finished before it could be killed")
    recover(tmp_path / "run.h5")  # the flush the kill interrupted, if any (docs/hdf5.md)
    with h5py.File(tmp_path / "run.h5", "r") as f:
        kept = int(f.attrs["n_steps_done"])
        assert f.attrs["status"] == b"running" and kept >= 20
        assert all("displacement" in f["steps"][k] for k in f["steps"] if int(k) <= kept)
        extra = [k for k in f["steps"] if int(k) > kept]
    if extra:                          # a step group the kill interrupted half-written
        with h5py.File(tmp_path / "run.h5", "r+") as f:
            for k in extra:
                del f["steps"][k]
    res = subprocess.run([str(voiga_bin), "--restart", "run.h5", "--quiet"], cwd=tmp_path,
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    compare(full, tmp_path / "run.h5")
