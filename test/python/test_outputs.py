"""Issue 19, classes 1, 2, 4, 5, 6 and 8: every example of the issue is refused with
exit code 2 and a message naming the real cause, or handled as described, and the
inputs and earlier results are intact afterwards (docs/files.md, "Outputs of a run")."""
from __future__ import annotations

import hashlib
import os
import shutil
import signal
import subprocess
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from conftest import REPO
from post.journal import recover

CASE = """&case
  title = 'block', geometry = 'geometry.h5', output = '{output}', n_bodies = 1
/
&body
  name = 'slab', material = 'neo-hookean', youngs_modulus = {e}, poisson_ratio = 0.3,
  degree_xi = 2, degree_eta = 2, nel_xi = 3, nel_eta = 1, contact_edge = 'bottom'
/
&solver
  n_steps = {steps}
/
&dirichlet
  body = 'slab', edge = 'top', fix_x = .true., fix_y = .true., ux = {ux}, uy = {uy}
/
&contact
  slave = 'slab', master = 'rigid', rigid_point = 0.0, -3.0, rigid_normal = 0.0, 1.0,
  penalty_normal = 100.0, friction = 0.3
/
"""


def block(tmp: Path, output: str = "out.h5", e: str = "1.0", steps: str = "2, 2",
          ux: str = "0.0, 0.3", uy: str = "-0.03, -0.03", text: str | None = None) -> Path:
    """The ironing slab pressed on a rigid plane and slid (4 steps, a second)."""
    shutil.copy(REPO / "cases" / "ironing" / "geometry.h5", tmp / "geometry.h5")
    case = tmp / "case.nml"
    case.write_text(text if text is not None else
                    CASE.format(output=output, e=e, steps=steps, ux=ux, uy=uy))
    return case


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def refused(res: subprocess.CompletedProcess, *words: str) -> None:
    """Exit 2 with one error line naming every word, and no traceback."""
    assert res.returncode == 2, (res.returncode, res.stdout, res.stderr)
    errors = [line for line in res.stderr.splitlines() if line.startswith("voiga: error:")]
    assert len(errors) == 1, res.stderr
    for word in words:
        assert word in errors[0], errors[0]
    assert "Backtrace" not in res.stderr


def displacements(path: Path) -> dict[str, np.ndarray]:
    with h5py.File(path, "r") as f:
        assert f.attrs["status"] == b"converged"
        return {k: g["displacement"][()] for k, g in f["steps"].items()}


# --- class 1: inputs destroyed by outputs -----------------------------------------


@pytest.mark.parametrize("output,words", [
    ("geometry.h5", ["&case: output", "is the geometry file"]),
    ("./sub/../geometry.h5", ["is the geometry file"]),
    ("case.nml", ["is the case file"]),
    ("link.h5", ["is the geometry file"]),
    ("./" + "/" * 243 + "geometry.h5", ["is the geometry file"]),
])
def test_output_never_replaces_an_input(run, tmp_path: Path, output: str, words: list[str]) -> None:
    case = block(tmp_path, output=output)
    (tmp_path / "sub").mkdir()
    (tmp_path / "link.h5").symlink_to("geometry.h5")
    before = digest(tmp_path / "geometry.h5"), digest(case)
    refused(run(case), *words)
    assert (digest(tmp_path / "geometry.h5"), digest(case)) == before


@pytest.mark.parametrize("dump,words", [
    ("geometry.h5", ["--dump", "is the geometry file"]),
    ("case.nml", ["--dump", "is the case file"]),
    ("out.h5", ["--dump", "is the result file"]),
])
def test_dump_never_replaces_an_input_or_the_result(run, tmp_path: Path, dump: str,
                                                    words: list[str]) -> None:
    case = block(tmp_path)
    before = digest(tmp_path / "geometry.h5"), digest(case)
    refused(run(case, "--dump", tmp_path / dump), *words)
    assert (digest(tmp_path / "geometry.h5"), digest(case)) == before
    assert not (tmp_path / "out.h5").exists()


def test_long_paths_are_not_cut(run, tmp_path: Path) -> None:
    """260 characters naming 'geometry.h5.new' through repeated '/': cut at 256 (as the
    fixed-length strings did) they named the geometry file. The result lands at the
    whole path, as it does in a folder 400 characters deep; a name longer than a path
    may be is refused, not cut."""
    output = "./" + "/" * 243 + "geometry.h5" + ".new"
    assert output[:256].endswith("geometry.h5")
    case = block(tmp_path, output=output)
    before = digest(tmp_path / "geometry.h5")
    res = run(case, "--quiet")
    assert res.returncode == 0, res.stderr
    assert digest(tmp_path / "geometry.h5") == before
    assert h5py.File(tmp_path / "geometry.h5.new").attrs["status"] == b"converged"
    deep = tmp_path / ("d" * 200) / ("e" * 200)
    deep.mkdir(parents=True)
    case = block(tmp_path, output=str(deep / "result.h5"))
    assert run(case, "--quiet").returncode == 0
    assert h5py.File(deep / "result.h5").attrs["n_steps_done"] == 4
    refused(run(block(tmp_path, output="x" * 5000)), "output is longer than 4095 characters")


# --- class 2: an earlier result destroyed before anything runs -----------------------


def test_existing_result_is_kept_unless_overwrite(run, tmp_path: Path) -> None:
    case = block(tmp_path)
    assert run(case, "--quiet").returncode == 0
    before = digest(tmp_path / "out.h5")
    res = run(case, "--quiet")
    refused(res, "out.h5' exists", "status 'converged', 4 steps", "--overwrite")
    assert digest(tmp_path / "out.h5") == before
    # the case may say so, or --overwrite
    assert run(case, "--quiet", "--overwrite").returncode == 0
    case.write_text(case.read_text().replace("n_bodies = 1", "n_bodies = 1, overwrite = .true."))
    assert run(case, "--quiet").returncode == 0
    assert not list(tmp_path.glob("*.part")) and not list(tmp_path.glob("*.lock"))


def test_run_without_a_step_keeps_the_earlier_result(run, tmp_path: Path) -> None:
    """--overwrite replaces the earlier result only with one that has a step: a run
    whose first step fails leaves the earlier file as it was."""
    case = block(tmp_path)
    assert run(case, "--quiet").returncode == 0
    before = digest(tmp_path / "out.h5")
    block(tmp_path, steps="1, 1", uy="-3.0, -3.0")
    case.write_text(case.read_text().replace("&solver", "&solver\n  max_cuts = 0"))
    res = run(case, "--quiet", "--overwrite")
    assert res.returncode == 3, res.stderr
    assert "the earlier" in res.stderr and "is kept as it was" in res.stderr
    assert digest(tmp_path / "out.h5") == before
    assert not (tmp_path / "out.h5.part").exists()


def test_a_killed_run_never_leaves_an_unreadable_file(voiga_bin: Path, tmp_path: Path) -> None:
    """Killed at any moment (here after 0 to 0.4 s, one kill per run, replacing an
    earlier result), the result path holds either the earlier result as it was or a
    readable result with at least one step: never a file h5py cannot open once the
    flush the kill interrupted is finished (``post.journal.recover``, which voiga and
    post's reader call themselves; docs/hdf5.md, "Crash safety"). The assertions hold
    whenever the kill comes."""
    case = block(tmp_path, steps="40, 40")
    out = tmp_path / "out.h5"
    for delay in [0.0, 0.005, 0.02, 0.05, 0.1, 0.2, 0.4]:
        earlier = digest(out) if out.exists() else None
        proc = subprocess.Popen([str(voiga_bin), str(case), "--quiet", "--overwrite"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(delay)
        proc.kill()
        proc.wait()
        if not out.exists() or digest(out) == earlier:
            continue
        recover(out)
        with h5py.File(out, "r") as f:
            done = int(f.attrs["n_steps_done"])
            assert done >= 1
            assert all("displacement" in f["steps"][s] for s in f["steps"] if int(s) <= done)


# --- class 3 (two writers) -----------------------------------------------------------


def test_second_writer_refused_whatever_hdf5_locking_says(voiga_bin: Path, tmp_path: Path) -> None:
    case = block(tmp_path, steps="100, 100")
    env = dict(os.environ, HDF5_USE_FILE_LOCKING="FALSE", GFORTRAN_UNBUFFERED_PRECONNECTED="y")
    first = subprocess.Popen([str(voiga_bin), str(case)], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, env=env)
    try:
        assert first.stdout is not None
        for line in first.stdout:
            if line.startswith("step 1/"):
                break
        second = subprocess.run([str(voiga_bin), str(case), "--quiet", "--overwrite"],
                                capture_output=True, text=True, env=env, timeout=120)
        refused(second, "is being written by another voiga run", f"process {first.pid}")
        restart = subprocess.run([str(voiga_bin), "--restart", str(tmp_path / "out.h5")],
                                 capture_output=True, text=True, env=env, timeout=120)
        refused(restart, "is being written by another voiga run")
        first.communicate(timeout=300)
    finally:
        first.kill()
    assert first.returncode == 0
    assert len(displacements(tmp_path / "out.h5")) == 200



def test_restart_refused_before_it_reads_a_file_being_written(voiga_bin: Path, tmp_path: Path) -> None:
    """A result another run holds the writer's lock of may be half-written at any
    moment: --restart is refused as that run's before it reads the file (it read it
    first and reported 'not a readable HDF5 file' when it caught the writer mid-step)."""
    import fcntl

    block(tmp_path)
    out = tmp_path / "out.h5"
    out.write_bytes(b"half a step" * 100)      # what a reader may meet mid-write
    with open(tmp_path / "out.h5.lock", "w") as lock:
        lock.write(f"{os.getpid()}\n")
        lock.flush()
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        res = subprocess.run([str(voiga_bin), "--restart", str(out)], capture_output=True, text=True,
                             timeout=120)
    refused(res, "is being written by another voiga run")
    assert out.read_bytes() == b"half a step" * 100

# --- class 4: geometry that is not a valid body ----------------------------------------


def edit_slab(tmp: Path, key: str, data) -> None:
    with h5py.File(tmp / "geometry.h5", "r+") as f:
        g = f["bodies/slab"]
        del g[key]
        g[key] = data


def test_folding_patch_refused(run, tmp_path: Path) -> None:
    """A control point moved across the patch: det J < 0 over part of it (the solver
    integrated |det J| and reported 'converged')."""
    case = block(tmp_path)
    with h5py.File(tmp_path / "geometry.h5", "r") as f:
        cp = f["bodies/slab/control_points"][()]
    folded = cp.copy()
    folded[0, 0] = cp[-1, -1] + (cp[-1, -1] - cp[0, 0]) * 0.5  # a corner pulled past the opposite one
    edit_slab(tmp_path, "control_points", folded)
    refused(run(case, "--check"), "slab", "folds over itself", "det J")


def test_end_knot_repeated_p_plus_2_times_refused(run, ironing_copy: Path) -> None:
    """The die's knots_xi (degree 2) with its first knot 4 times: it corrupted the heap
    ('double free or corruption', exit 134)."""
    with h5py.File(ironing_copy.parent / "geometry.h5", "r+") as f:
        g = f["bodies/die"]
        assert list(g["knots_xi"][()]) == [0, 0, 0, 0.5, 0.5, 1, 1, 1]
        del g["knots_xi"]
        g["knots_xi"] = np.array([0, 0, 0, 0, 0.5, 1, 1, 1], dtype=float)
    refused(run(ironing_copy, "--check"), "die", "knots_xi", "repeats its first or last knot")


@pytest.mark.parametrize("key,data,words", [
    ("degree", np.array([2.0, 1.0]), ["degree", "floating-point numbers, not integers"]),
    ("knots_xi", np.array([b"0", b"1"]), ["knots_xi", "strings, not numbers"]),
    ("weights", np.ones((2, 2, 2)), ["weights", "rank 3, expected 2"]),
])
def test_dataset_of_the_wrong_type_refused(run, tmp_path: Path, key: str, data, words) -> None:
    case = block(tmp_path)
    edit_slab(tmp_path, key, data)
    refused(run(case, "--check"), *words)


# --- class 5: values that mean something else ----------------------------------------


@pytest.mark.parametrize("edit,words", [
    ({"steps": "1500000000, 1500000000"}, ["n_steps", "at most 1000000", "3000000000"]),
    ({"steps": "-1"}, ["n_steps must be >= 1"]),
    ({"uy": "-1.7976931348623157e308, -0.03"}, ["uy", "1e100"]),
    ({"uy": "NaN, -0.03"}, ["uy", "finite"]),
    ({"e": "-1.7976931348623157e308"}, ["youngs_modulus"]),
])
def test_values_that_meant_something_else_refused(run, tmp_path: Path, edit: dict, words) -> None:
    refused(run(block(tmp_path, **edit), "--check"), *words)


def test_group_after_a_terminator_is_read(run, tmp_path: Path) -> None:
    """'/ &dirichlet' on one line (the group was dropped without a word): the run is
    the same as with the group on its own line, bit for bit."""
    plain = block(tmp_path)
    assert run(plain, "--quiet").returncode == 0
    reference = displacements(tmp_path / "out.h5")
    text = CASE.format(output="joined.h5", e="1.0", steps="2, 2", ux="0.0, 0.3", uy="-0.03, -0.03")
    block(tmp_path, text=text.replace("/\n&dirichlet", "/ &dirichlet"))
    assert run(plain, "--quiet").returncode == 0
    joined = displacements(tmp_path / "joined.h5")
    assert joined.keys() == reference.keys()
    assert all(np.array_equal(joined[k], reference[k]) for k in reference)


def test_two_dirichlet_groups_on_one_edge_refused(run, tmp_path: Path) -> None:
    case = block(tmp_path)
    text = case.read_text()
    i = text.index("&dirichlet")
    case.write_text(text + text[i:text.index("/", i) + 1].replace("-0.03", "-0.05") + "\n")
    refused(run(case, "--check"), "&dirichlet (1) and (2) both prescribe ux", "'top'", "'slab'")


# --- class 6: restart trusts the file --------------------------------------------------


def test_restart_with_a_changed_case_refused(run, tmp_path: Path) -> None:
    case = block(tmp_path, e="2.0")
    assert run(case, "--quiet").returncode == 0
    with h5py.File(tmp_path / "out.h5", "r+") as f:     # as if killed after step 2
        for k in list(f["steps"]):
            if int(k) > 2:
                del f["steps"][k]
        f.attrs["n_steps_done"] = np.int32(2)
        f.attrs["status"] = np.bytes_("interrupted")
        assert f.attrs["case_sha256"].decode() == digest(case)
        assert f.attrs["geometry_sha256"].decode() == digest(tmp_path / "geometry.h5")
    block(tmp_path, e="200.0")
    before = digest(tmp_path / "out.h5")
    refused(run("--restart", tmp_path / "out.h5"), "case file", "has changed",
            "youngs_modulus: 200 in the case, 2 in the result file", "--force-restart")
    assert digest(tmp_path / "out.h5") == before
    res = run("--restart", tmp_path / "out.h5", "--quiet", "--force-restart")
    assert res.returncode == 0, res.stderr
    assert "warning: --force-restart" in res.stderr
    with h5py.File(tmp_path / "out.h5", "r") as f:
        assert f.attrs["status"] == b"converged" and f.attrs["n_steps_done"] == 4
        assert "youngs_modulus" in f.attrs["restart_forced"].decode()
    refused(run("--restart", tmp_path / "out.h5"), "the run converged", "nothing to continue")


def test_restart_with_a_changed_geometry_refused(run, tmp_path: Path) -> None:
    case = block(tmp_path)
    assert run(case, "--quiet").returncode == 0
    with h5py.File(tmp_path / "out.h5", "r+") as f:
        f.attrs["status"] = np.bytes_("interrupted")
    with h5py.File(tmp_path / "geometry.h5", "r+") as f:
        f["bodies/slab"].attrs["note"] = "edited"
    refused(run("--restart", tmp_path / "out.h5"), "the geometry file", "has changed")


# --- class 8: messages that mislead -----------------------------------------------------


def test_byte_order_mark_and_single_line_file_run_as_the_plain_case(run, tmp_path: Path) -> None:
    plain = block(tmp_path)
    assert run(plain, "--quiet").returncode == 0
    reference = displacements(tmp_path / "out.h5")
    text = plain.read_text()
    for name, data in [("bom", b"\xef\xbb\xbf" + text.replace("out.h5", "bom.h5").encode()),
                       ("line", " ".join(text.replace("out.h5", "line.h5").split()).encode()),
                       ("crlf", text.replace("out.h5", "crlf.h5").replace("\n", "\r\n").encode())]:
        case = tmp_path / f"{name}.nml"
        case.write_bytes(data)
        res = run(case, "--quiet")
        assert res.returncode == 0, (name, res.stderr)
        got = displacements(tmp_path / f"{name}.h5")
        assert all(np.array_equal(got[k], reference[k]) for k in reference), name


@pytest.mark.parametrize("old,new,words", [
    ("n_steps = 2, 2", "n_steps = " + ", ".join(["1"] * 65), ["n_steps", "takes at most 64 values (65 given)"]),
    ("nel_xi = 3,", "knots_xi = " + ", ".join(["0.5"] * 100001) + ",",
     ["knots_xi", "takes at most 100000 values (100001 given)"]),
    ("output = 'out.h5'", "output = 'missing/out.h5'", ["output", "missing'", "No such file"]),
    ("output = 'out.h5'", "output = 'case.nml/out.h5'", ["output", "Not a directory"]),
    ("output = 'out.h5'", "output = '.'", ["output", "is a folder"]),
])
def test_messages_name_the_real_cause(run, tmp_path: Path, old: str, new: str, words) -> None:
    case = block(tmp_path)
    text = case.read_text()
    assert old in text
    case.write_text(text.replace(old, new))
    refused(run(case), *words)


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_unwritable_folder_named(run, tmp_path: Path) -> None:
    case = block(tmp_path, output="ro/out.h5")
    (tmp_path / "ro").mkdir()
    (tmp_path / "ro").chmod(0o555)
    try:
        refused(run(case), "lock file", "Permission denied")
    finally:
        (tmp_path / "ro").chmod(0o755)


def test_sigterm_before_the_first_step_leaves_no_result(voiga_bin: Path, tmp_path: Path) -> None:
    """An interrupted run that wrote no step leaves the folder as it was (no half file)."""
    case = block(tmp_path, steps="200, 200")
    proc = subprocess.Popen([str(voiga_bin), str(case), "--quiet"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    proc.send_signal(signal.SIGTERM)
    proc.communicate(timeout=120)
    out = tmp_path / "out.h5"
    if out.exists():  # the signal came after the first step: a readable result
        with h5py.File(out, "r") as f:
            assert f.attrs["n_steps_done"] >= 1
