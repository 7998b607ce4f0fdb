"""Issue 19, class 7: a running result is read while it grows, by `python -m post
plot-contact`, by post's reader and by plain h5py (docs/hdf5.md, "Writing and
reading a running result"); `post` refuses bad files in one line and a hertz
comparison of a run that has not converged unless asked.

No assertion depends on timing: the run is long (6000 steps) and is stopped once the
reads it is waiting for have been made while its status was 'running'; on a machine
slow enough that it ends first, the test fails naming that (it never passes
vacuously)."""
from __future__ import annotations

import os
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
from post.__main__ import main as post_main  # noqa: E402
from post.reader import read_result  # noqa: E402

CASE = """&case
  title = 'live block', geometry = 'geometry.h5', output = 'run.h5', n_bodies = 1
/
&body
  name = 'slab', material = 'neo-hookean', youngs_modulus = 1.0, poisson_ratio = 0.3,
  degree_xi = 2, degree_eta = 2, nel_xi = 4, nel_eta = 2, contact_edge = 'bottom'
/
&solver
  n_steps = 10, 5990
/
&dirichlet
  body = 'slab', edge = 'top', fix_x = .true., fix_y = .true., ux = 0.0, 2.0, uy = -0.06, -0.06
/
&contact
  slave = 'slab', master = 'rigid', rigid_point = 0.0, -3.0, rigid_normal = 0.0, 1.0,
  penalty_normal = 100.0, friction = 0.3
/
"""


@pytest.fixture()
def growing(voiga_bin: Path, tmp_path: Path):
    """A run of 6000 steps writing `run.h5`; stopped (SIGTERM) at the end of the test."""
    shutil.copy(REPO / "cases" / "ironing" / "geometry.h5", tmp_path / "geometry.h5")
    (tmp_path / "case.nml").write_text(CASE)
    proc = subprocess.Popen([str(voiga_bin), "case.nml", "--quiet"], cwd=tmp_path,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    out = tmp_path / "run.h5"
    deadline = time.monotonic() + 120
    while not out.exists():               # the file appears once its first step is in it
        assert proc.poll() is None, proc.stderr.read() if proc.stderr else ""
        assert time.monotonic() < deadline, "no result file after 120 s"
        time.sleep(0.02)
    yield proc, out
    proc.send_signal(signal.SIGTERM)
    proc.communicate(timeout=120)


def still_running(proc: subprocess.Popen) -> None:
    assert proc.poll() is None, "the run ended before the reads were made: give it more steps"


def test_post_reader_reads_a_growing_result(growing) -> None:
    """Each read sees whole steps only (all that n_steps_done counts, nothing beyond),
    and a later read sees more of them."""
    proc, out = growing
    counts = []
    while len(set(counts)) < 3:
        still_running(proc)
        r = read_result(out)
        assert r.status == "running"
        assert [s.step for s in r.steps] == list(range(1, r.n_steps_done + 1))
        assert all(np.all(np.isfinite(s.displacement)) and s.contact for s in r.steps)
        counts.append(r.n_steps_done)
    assert counts == sorted(counts)


def test_h5py_reads_a_growing_result(growing) -> None:
    """Plain h5py: the file opens between steps (HDF5's own shared lock waits for
    nothing; while voiga writes a step HDF5 says 'unable to lock file', and the read
    is tried again, as docs/hdf5.md says); every open sees whole steps."""
    proc, out = growing
    seen: set[int] = set()
    refused = 0
    while len(seen) < 3:
        still_running(proc)
        try:
            with h5py.File(out, "r") as f:
                done = int(f.attrs["n_steps_done"])
                assert f.attrs["status"] == b"running"
                for k in range(1, done + 1):
                    assert f[f"steps/{k:06d}/displacement"].shape == (int(f.attrs["n_dofs"]),)
                    assert "contact/1/p_n" in f[f"steps/{k:06d}"]
                seen.add(done)
        except OSError as err:
            assert "unable to lock file" in str(err), err
            refused += 1
            time.sleep(0.001)


def test_plot_contact_of_a_growing_result(growing, tmp_path: Path) -> None:
    proc, out = growing
    env = dict(os.environ, HDF5_USE_FILE_LOCKING="FALSE")   # post locks on its own
    for k in range(2):
        still_running(proc)
        res = subprocess.run([sys.executable, "-m", "post", "plot-contact", str(out), "--out",
                              str(tmp_path / f"figures{k}")], cwd=REPO, env=env,
                             capture_output=True, text=True, timeout=300)
        assert res.returncode == 0, res.stderr
        assert "status 'running'" in res.stderr            # the note: not the whole run
        assert list((tmp_path / f"figures{k}").glob("run-contact-*.png"))
    still_running(proc)


# --- post on files that are not (whole) results ----------------------------------------


def post(*args: str, capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    code = post_main(list(args))
    return code, capsys.readouterr().err


@pytest.fixture(scope="module")
def finished(voiga_bin: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """hertz m1 N2 run to the end."""
    folder = tmp_path_factory.mktemp("hertz")
    for name in ("geometry.h5", "m1-N2.nml"):
        shutil.copy(REPO / "cases" / "hertz" / name, folder / name)
    subprocess.run([str(voiga_bin), "m1-N2.nml", "--quiet"], cwd=folder, check=True, timeout=300,
                   capture_output=True)
    return folder / "m1-N2.h5"


@pytest.mark.parametrize("kind", ["empty", "text", "truncated", "no status", "no steps group"])
@pytest.mark.parametrize("command", ["summary", "plot-contact", "hertz", "history", "vtk"])
def test_bad_files_refused_in_one_line(finished: Path, tmp_path: Path, kind: str, command: str,
                                       capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.h5"
    data = finished.read_bytes()
    if kind == "empty":
        bad.write_bytes(b"")
    elif kind == "text":
        bad.write_text("not a result\n")
    elif kind == "truncated":
        bad.write_bytes(data[: len(data) // 2])
    else:
        bad.write_bytes(data)
        with h5py.File(bad, "r+") as f:
            if kind == "no status":
                del f.attrs["status"]
            else:
                del f["steps"]
                f.attrs["n_steps_done"] = np.int32(0)
    out = [] if command == "summary" else ["--out", str(tmp_path)]
    code, err = post(command, str(bad), *out, capsys=capsys)
    lines = [line for line in err.strip().splitlines() if "note:" not in line]
    if kind == "no steps group":      # a readable result with no step: at most said so
        assert code in (0, 1) and len(lines) <= 1 and "Traceback" not in err, err
        return
    assert code == 2, err
    assert len(lines) == 1 and str(bad) in lines[0] and "Traceback" not in err, err


def test_hertz_of_a_run_that_has_not_converged(finished: Path, tmp_path: Path,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    """It compared an earlier step silently; now refused unless --partial."""
    partial = tmp_path / "partial.h5"
    shutil.copy(finished, partial)
    with h5py.File(partial, "r+") as f:
        for k in list(f["steps"]):
            if int(k) > 3:
                del f["steps"][k]
        f.attrs["n_steps_done"] = np.int32(3)
        f.attrs["status"] = np.bytes_("running")
    code, err = post("hertz", str(partial), "--no-figure", capsys=capsys)
    assert code == 2 and "has not converged" in err and "--partial" in err, err
    code, err = post("hertz", str(partial), "--no-figure", "--partial", capsys=capsys)
    assert code == 0 and "status 'running'" in err and "3 of 5 planned steps" in err, err
    code, err = post("hertz", str(finished), "--no-figure", capsys=capsys)
    assert code == 0 and "note" not in err, err
