"""Issue 36: nothing is destroyed through links, special files or files swapped under
a running writer, and geometry that claims huge sizes is refused before anything is
read (docs/files.md). Each test is one finding of the issue, reproduced: it failed on
the code before the fix (a geometry truncated to a PID, a case file holding a PID, a
dump written through a link, a device node replaced, a hang, a result lost with exit
0, a backtrace).

Device nodes are made in the test's own folder with mknod (the tests run as root);
nothing touches /dev. Every run has a time limit, so a hang fails the test."""
from __future__ import annotations

import hashlib
import os
import shutil
import signal
import stat
import subprocess
from pathlib import Path

import h5py
import pytest

from test_outputs import block, refused
from test_restart import truncate

TIMEOUT = 60


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def voiga(voiga_bin: Path, *args, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """Run voiga (in `cwd`, else in the folder of its first path argument)."""
    if cwd is None:
        cwd = next((Path(a).parent for a in args if isinstance(a, Path)), None)
    return subprocess.run([str(voiga_bin), *map(str, args)], capture_output=True, text=True,
                          timeout=TIMEOUT, cwd=cwd)


def interrupted(voiga_bin: Path, tmp: Path) -> Path:
    """A result of the block case cut back to 2 steps, as a killed run leaves it."""
    case = block(tmp)
    assert voiga(voiga_bin, case, "--quiet").returncode == 0
    truncate(tmp / "out.h5", 2)
    return tmp / "out.h5"


def char_device(path: Path) -> Path:
    """A private character device node with /dev/null's numbers (1, 3)."""
    if os.geteuid() != 0:
        pytest.skip("mknod of a device node needs root")
    os.mknod(path, stat.S_IFCHR | 0o666, os.makedev(1, 3))
    return path


# --- finding 1: the writer's lock file ---------------------------------------------------


@pytest.mark.parametrize("restart", [False, True])
def test_lock_file_linked_to_the_geometry(voiga_bin: Path, tmp_path: Path, restart: bool) -> None:
    """A lock file that is a symbolic link to the geometry: the lock was opened
    through the link and truncated to a PID (the geometry lost)."""
    args = ["--restart", interrupted(voiga_bin, tmp_path)] if restart else [block(tmp_path)]
    (tmp_path / "out.h5.lock").symlink_to("geometry.h5")
    before = digest(tmp_path / "geometry.h5")
    refused(voiga(voiga_bin, *args), "out.h5.lock", "is a symbolic link", "remove it")
    assert digest(tmp_path / "geometry.h5") == before
    assert (tmp_path / "out.h5.lock").is_symlink()


def test_lock_file_a_hard_link_of_the_case(voiga_bin: Path, tmp_path: Path) -> None:
    """A lock file that is a second name of the case file: the run exited 0 and
    the case file held a PID."""
    case = block(tmp_path)
    os.link(case, tmp_path / "out.h5.lock")
    before = digest(case)
    refused(voiga(voiga_bin, case), "out.h5.lock", "a second name of another file")
    assert digest(case) == before


@pytest.mark.parametrize("content,ok", [("4242\n", True), ("", True), ("my notes\n", False)])
def test_lock_file_left_by_a_killed_run(voiga_bin: Path, tmp_path: Path, content: str, ok: bool) -> None:
    """A lock file nobody holds that holds a process id (or nothing) is one a killed
    run left: replaced. One that holds anything else is not ours: refused, kept."""
    case = block(tmp_path)
    (tmp_path / "out.h5.lock").write_text(content)
    res = voiga(voiga_bin, case, "--quiet")
    if ok:
        assert res.returncode == 0, res.stderr
        assert not (tmp_path / "out.h5.lock").exists()
    else:
        refused(res, "out.h5.lock", "not a lock file of voiga")
        assert (tmp_path / "out.h5.lock").read_text() == content


def test_lock_file_a_fifo(voiga_bin: Path, tmp_path: Path) -> None:
    case = block(tmp_path)
    os.mkfifo(tmp_path / "out.h5.lock")
    refused(voiga(voiga_bin, case), "out.h5.lock", "FIFO")
    assert stat.S_ISFIFO(os.lstat(tmp_path / "out.h5.lock").st_mode)


# --- finding 2: --dump -----------------------------------------------------------------


def test_dump_part_linked_to_the_geometry(voiga_bin: Path, tmp_path: Path) -> None:
    """A `.part` of the dump linked to the geometry: the geometry became the dump."""
    case = block(tmp_path)
    (tmp_path / "d.h5.part").symlink_to("geometry.h5")
    before = digest(tmp_path / "geometry.h5")
    refused(voiga(voiga_bin, case, "--check", "--dump", "d.h5", cwd=tmp_path), "d.h5.part", "symbolic link")
    assert digest(tmp_path / "geometry.h5") == before


@pytest.mark.parametrize("link", [False, True])
def test_dump_replaces_nothing_without_overwrite(voiga_bin: Path, tmp_path: Path, link: bool) -> None:
    """--dump over an existing file (another run's result, or the file a link names)
    replaced it without --overwrite; with it, the dump replaces it."""
    case = block(tmp_path)
    assert voiga(voiga_bin, case, "--quiet").returncode == 0
    shutil.move(tmp_path / "out.h5", tmp_path / "other.h5")
    before = digest(tmp_path / "other.h5")
    target = "other.h5"
    if link:
        (tmp_path / "d.h5").symlink_to("other.h5")
        target = "d.h5"
    refused(voiga(voiga_bin, case, "--check", "--dump", target, cwd=tmp_path), "--dump", "exists",
            "--overwrite")
    assert digest(tmp_path / "other.h5") == before
    res = voiga(voiga_bin, case, "--check", "--dump", target, "--overwrite", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    with h5py.File(tmp_path / "other.h5", "r") as f:
        assert "status" not in f.attrs and "bodies/slab/bulk" in f
    assert not list(tmp_path.glob("*.part")) and not list(tmp_path.glob("*.lock"))


# --- findings 3 and 4: special files as outputs ------------------------------------------


@pytest.mark.parametrize("kind", ["device", "fifo"])
@pytest.mark.parametrize("via", ["name", "link"])
@pytest.mark.parametrize("overwrite", [False, True])
def test_special_files_are_never_outputs(voiga_bin: Path, tmp_path: Path, kind: str, via: str,
                                         overwrite: bool) -> None:
    """A result path that is (or links to) a device node or a FIFO: --overwrite
    replaced it with a regular file (the machine's /dev/null, when linked there);
    without it, the refusal suggested --overwrite; a FIFO hung the run (HDF5 opened
    it to say what it held)."""
    special = tmp_path / "special"
    if kind == "device":
        char_device(special)
    else:
        os.mkfifo(special)
    output = "special" if via == "name" else "out.h5"
    if via == "link":
        (tmp_path / "out.h5").symlink_to("special")
    case = block(tmp_path, output=output)
    res = voiga(voiga_bin, case, *(["--overwrite"] if overwrite else []))
    refused(res, "character device" if kind == "device" else "FIFO", "not a regular file")
    assert "--overwrite" not in res.stderr
    mode = os.lstat(special).st_mode
    assert stat.S_ISCHR(mode) if kind == "device" else stat.S_ISFIFO(mode)


def test_special_files_are_never_read_as_inputs(voiga_bin: Path, tmp_path: Path) -> None:
    """A FIFO as the case, the geometry or the restart file is refused, not waited on."""
    case = block(tmp_path)
    os.mkfifo(tmp_path / "pipe")
    refused(voiga(voiga_bin, tmp_path / "pipe"), "FIFO")
    refused(voiga(voiga_bin, "--restart", tmp_path / "pipe"), "--restart", "FIFO")
    case.write_text(case.read_text().replace("geometry = 'geometry.h5'", "geometry = 'pipe'"))
    refused(voiga(voiga_bin, case, "--check"), "geometry", "FIFO")


# --- finding 5: files swapped under a running writer ---------------------------------------


def start(voiga_bin: Path, case: Path, *args: str) -> subprocess.Popen:
    """A long run (the block pressed and slid in 400 steps), stopped (SIGSTOP) once its
    first step is written: whatever the test then does to its files happens
    between two of its flushes."""
    env = dict(os.environ, GFORTRAN_UNBUFFERED_PRECONNECTED="y")
    proc = subprocess.Popen([str(voiga_bin), str(case), *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env)
    assert proc.stdout is not None
    for line in proc.stdout:
        if line.startswith("step 1/"):
            proc.send_signal(signal.SIGSTOP)
            return proc
    proc.kill()
    raise AssertionError("the run wrote no step: " + proc.communicate()[1])


def finish(proc: subprocess.Popen) -> tuple[int, str, str]:
    proc.send_signal(signal.SIGCONT)
    out, err = proc.communicate(timeout=300)
    return proc.returncode, out, err


def test_result_replaced_under_the_writer(voiga_bin: Path, tmp_path: Path) -> None:
    """`mv other out.h5` while the run wrote out.h5: it reported 'converged ...
    wrote out.h5' (exit 0) with its steps in the deleted file. Now it stops at its
    next flush (exit 1) saying so, and the file moved there keeps its bytes."""
    case = block(tmp_path, steps="200, 200")
    shutil.copy(tmp_path / "geometry.h5", tmp_path / "other.h5")
    proc = start(voiga_bin, case)
    os.replace(tmp_path / "other.h5", tmp_path / "out.h5")
    code, out, err = finish(proc)
    assert code == 1, err
    assert "converged" not in out
    assert "moved, replaced or removed" in err and "are in" not in err
    assert digest(tmp_path / "out.h5") == digest(tmp_path / "geometry.h5")


def test_lock_removed_under_the_writer(voiga_bin: Path, tmp_path: Path) -> None:
    """out.h5.lock deleted while a run wrote out.h5: a second run with --overwrite
    started, and both ended with exit 0, the first result lost. Now the first stops
    at its next flush with exit 1, naming the lock file."""
    case = block(tmp_path, steps="200, 200")
    first = start(voiga_bin, case)
    (tmp_path / "out.h5.lock").unlink()
    second = voiga(voiga_bin, case, "--quiet", "--overwrite")
    assert second.returncode == 0, second.stderr
    code, out, err = finish(first)
    assert code == 1, err
    assert "converged" not in out
    assert "out.h5.lock' was removed or replaced" in err
    assert "readable in" not in err and "are not in" in err    # out.h5 is the second's
    with h5py.File(tmp_path / "out.h5", "r") as f:     # the second run's result, whole
        assert f.attrs["status"] == b"converged" and f.attrs["n_steps_done"] == 400


def test_folder_removed_under_the_writer(voiga_bin: Path, tmp_path: Path) -> None:
    """The result's folder removed mid-run: exit 1, but the message said the steps
    'are readable in sub/out.h5', a file that no longer exists."""
    (tmp_path / "sub").mkdir()
    case = block(tmp_path, output="sub/out.h5", steps="200, 200")
    proc = start(voiga_bin, case)
    shutil.rmtree(tmp_path / "sub")
    code, out, err = finish(proc)
    assert code == 1, err
    assert "readable in" not in err and "are in" not in err
    assert "not in" in err and "does not exist" in err


# --- finding 6: geometry that claims huge sizes ---------------------------------------------


def huge(f: h5py.File, key: str, shape: tuple[int, ...]) -> None:
    """Replace the slab's `key` by a chunked dataset of `shape` never written (the
    file stays small; reading it would fill the whole shape)."""
    g = f["bodies/slab"]
    del g[key]
    g.create_dataset(key, shape=shape, dtype="f8", chunks=(1,) * (len(shape) - 1) + (min(shape[-1], 1024),))


@pytest.mark.parametrize("key,shape", [("control_points", (31623, 31623, 2)), ("weights", (1, 2**31)),
                                       ("knots_xi", (10**9,))])
def test_huge_datasets_refused_before_they_are_read(voiga_bin: Path, tmp_path: Path, key: str,
                                                    shape: tuple[int, ...]) -> None:
    """A 0.5 MB geometry claiming 31623 x 31623 x 2 control points (2^31 weight
    columns, 1e9 knots) ended in 'Error allocating 16000226064 bytes', a backtrace
    and exit 1."""
    case = block(tmp_path)
    with h5py.File(tmp_path / "geometry.h5", "r+") as f:
        huge(f, key, shape)
    assert (tmp_path / "geometry.h5").stat().st_size < 10**6
    res = voiga(voiga_bin, case, "--check")
    refused(res, key, "more than the")
    assert "Error allocating" not in res.stderr


def test_external_storage_refused(voiga_bin: Path, tmp_path: Path) -> None:
    """A dataset whose raw storage is an external file that is a FIFO hung the run;
    values kept outside the geometry file are not read at all."""
    case = block(tmp_path)
    os.mkfifo(tmp_path / "raw")
    with h5py.File(tmp_path / "geometry.h5", "r+") as f:
        g = f["bodies/slab"]
        knots = g["knots_xi"][()]
        del g["knots_xi"]
        g.create_dataset("knots_xi", shape=knots.shape, dtype="f8",
                         external=[(str(tmp_path / "raw"), 0, h5py.h5f.UNLIMITED)])
    refused(voiga(voiga_bin, case, "--check"), "knots_xi", "external files")


def test_many_groups_capped(voiga_bin: Path, tmp_path: Path) -> None:
    """40,000 &pressure groups: read one by one in quadratic time (8.5 s with
    --check) before any was looked at; now counted and refused at once."""
    case = block(tmp_path)
    case.write_text(case.read_text() + "&pressure body = 'slab', edge = 'top', p = 0.0, 0.0 /\n" * 40000)
    refused(voiga(voiga_bin, case, "--check"), "&pressure", "at most 1000", "40000")
