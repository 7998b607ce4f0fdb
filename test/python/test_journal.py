"""Crash safety of result files (docs/hdf5.md, "Crash safety"; src/platform/journal_vfd.c):
a writer killed inside a flush, at a point chosen by the driver's test hook
(VOIGA_JOURNAL_KILL=n: SIGKILL in the n-th flush, after the first of its in-place
writes), leaves a complete journal at the end of the file; post's reader and voiga
finish the flush, and the file then holds every step it counts, and a restart
reproduces the uninterrupted run."""
from __future__ import annotations

import fcntl
import os
import shutil
import subprocess
from pathlib import Path

import h5py
import pytest

from post.journal import MAGIC, recover
from post.reader import read_result
from test_restart import compare, setup


def tail(path: Path) -> bytes:
    return path.read_bytes()[-40:-32]


@pytest.fixture(scope="module")
def full(voiga_bin: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The uninterrupted run (40 sliding steps, 43 in all)."""
    tmp = tmp_path_factory.mktemp("full")
    case = setup(tmp, 40)
    subprocess.run([str(voiga_bin), str(case), "--quiet"], check=True, capture_output=True, cwd=tmp)
    return tmp / "run.h5"


def killed(voiga_bin: Path, tmp: Path, flush: int) -> Path:
    case = setup(tmp, 40)
    env = dict(os.environ, VOIGA_JOURNAL_KILL=str(flush))
    res = subprocess.run([str(voiga_bin), str(case), "--quiet"], capture_output=True, cwd=tmp, env=env)
    assert res.returncode == -9, res.stderr
    path = tmp / "run.h5"
    assert tail(path) == MAGIC, "the kill did not leave a journal"
    return path


# flushes 1-2 write the .part file (not yet at its name); then one per step (its
# groups and the root's counters together), the last ones the final status
@pytest.mark.parametrize("flush", [3, 4, 5, 20, 40, 44])
def test_killed_in_a_flush_post_finishes_it(voiga_bin: Path, tmp_path: Path, full: Path,
                                            flush: int) -> None:
    path = killed(voiga_bin, tmp_path, flush)
    res = read_result(path)      # recovers first
    assert tail(path) != MAGIC
    assert res.status == "running" and len(res.steps) >= 1
    with h5py.File(path, "r") as f:
        done = int(f.attrs["n_steps_done"])
        assert all("displacement" in f["steps"][k] for k in f["steps"] if int(k) <= done)
    restart = subprocess.run([str(voiga_bin), "--restart", "run.h5", "--quiet"], cwd=tmp_path,
                             capture_output=True, text=True, timeout=300)
    assert restart.returncode == 0, restart.stderr
    compare(full, path)


def test_killed_in_a_flush_voiga_finishes_it(voiga_bin: Path, tmp_path: Path, full: Path) -> None:
    """--restart of a file with an unfinished flush, no Python in between."""
    path = killed(voiga_bin, tmp_path, 17)
    restart = subprocess.run([str(voiga_bin), "--restart", "run.h5", "--quiet"], cwd=tmp_path,
                             capture_output=True, text=True, timeout=300)
    assert restart.returncode == 0, restart.stderr
    compare(full, path)


def test_bytes_beyond_the_end_are_harmless(voiga_bin: Path, tmp_path: Path, full: Path) -> None:
    """Killed while it appended a journal (before its footer): the file is the one
    before plus bytes HDF5 does not read; nothing to recover, and it reads whole."""
    path = tmp_path / "run.h5"
    shutil.copy(full, path)
    before = path.read_bytes()
    with path.open("ab") as f:
        f.write(b"\x17" * 5000 + MAGIC + b"\x01" * 32)  # a footer that does not match
    assert not recover(path)
    assert path.read_bytes()[:len(before)] == before
    res = read_result(path)
    assert res.status == "converged" and len(res.steps) == 43


def test_recover_leaves_a_file_being_written(voiga_bin: Path, tmp_path: Path) -> None:
    """While another process holds the file's flock (a writer flushing), recover
    does nothing, even to a file that ends in a journal."""
    path = killed(voiga_bin, tmp_path, 9)
    before = path.read_bytes()
    fd = os.open(path, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_SH)
        assert not recover(path)
    finally:
        os.close(fd)
    assert path.read_bytes() == before
    assert recover(path) and tail(path) != MAGIC
