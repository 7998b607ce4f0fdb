"""Issue 19, class 3: a full disk, a file-size limit and a memory limit end the run
with a message naming the cause and leave a readable result file; a mesh that
cannot fit is refused before anything is allocated (docs/files.md,
"Resources"). No test depends on timing: the limits are set
so that the run meets them whatever the machine's speed."""
from __future__ import annotations

import os
import re
import resource
import shutil
import subprocess
from pathlib import Path

import h5py
import numpy as np
import pytest

from conftest import REPO


def ironing(tmp: Path, steps: str = "10, 200") -> Path:
    """ironing m1 N2 (two bodies, 210 steps: about 20 KB a step in the result)."""
    shutil.copy(REPO / "cases" / "ironing" / "geometry.h5", tmp / "geometry.h5")
    case = tmp / "case.nml"
    text = (REPO / "cases" / "ironing" / "m1-N2.nml").read_text()
    case.write_text(text.replace("n_steps = 10, 200", f"n_steps = {steps}"))
    return case


def readable_steps(path: Path) -> int:
    """Every step the counter covers is whole and finite; returns how many."""
    with h5py.File(path, "r") as f:
        done = int(f.attrs["n_steps_done"])
        for k in range(1, done + 1):
            u = f[f"steps/{k:06d}/displacement"][()]
            assert np.all(np.isfinite(u)) and len(u) == f.attrs["n_dofs"]
            assert "contact/1/p_n" in f[f"steps/{k:06d}"]
        return done


@pytest.fixture()
def small_tmpfs(tmp_path: Path):
    """A 2 MB tmpfs (root and a kernel that lets us mount one), else skip."""
    mount = tmp_path / "disk"
    mount.mkdir()
    res = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", str(mount)],
                         capture_output=True, text=True)
    if res.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {res.stderr.strip()}")
    try:
        yield mount
    finally:
        subprocess.run(["umount", str(mount)], capture_output=True)


def test_full_disk_ends_the_run_with_its_steps_readable(run, small_tmpfs: Path) -> None:
    """The result (about 4 MB) does not fit the 2 MB disk: the space for the next step
    cannot be reserved, the run stops before writing it (exit 1, the cause named), the
    status says why, and every step written is readable."""
    case = ironing(small_tmpfs)
    res = run(case, "--quiet")
    assert res.returncode == 1, (res.stdout, res.stderr)
    assert "No space left on device" in res.stderr and "Backtrace" not in res.stderr
    out = small_tmpfs / "m1-N2.h5"
    done = readable_steps(out)
    assert 10 < done < 210
    with h5py.File(out, "r") as f:
        assert "No space left on device" in f.attrs["status"].decode()
    assert not list(small_tmpfs.glob("*.lock"))


def test_failed_write_keeps_the_flushed_steps(voiga_bin: Path, tmp_path: Path) -> None:
    """A write that fails for a cause no reservation sees (here the file-size limit,
    `ulimit -f` 600 KB; a quota or an I/O error the same): exit 1 with the cause, and
    the steps flushed before are readable (nothing of the failed step reaches the file:
    the program leaves without HDF5's exit handlers)."""
    case = ironing(tmp_path)

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (600_000, 600_000))

    res = subprocess.run([str(voiga_bin), str(case), "--quiet"], preexec_fn=limit,
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 1, res.stderr
    assert "file-size limit" in res.stderr and "steps written before are readable" in res.stderr
    assert 10 < readable_steps(tmp_path / "m1-N2.h5") < 210


HERTZ_M6 = REPO / "cases" / "hertz" / "m6-N2.nml"


def hertz_m6(tmp: Path) -> Path:
    """hertz m6 N2: 28420 DOFs, about 200 MB at its peak."""
    shutil.copy(REPO / "cases" / "hertz" / "geometry.h5", tmp / "geometry.h5")
    case = tmp / "case.nml"
    case.write_text(HERTZ_M6.read_text())
    return case


def run_limited(voiga_bin: Path, case: Path, megabytes: int, *args: str,
                blas_threads: str | None = None) -> subprocess.CompletedProcess:
    """voiga under an address-space limit (`ulimit -v`); BLAS threads as the caller
    sets them (None: not set, as in a user's shell)."""
    env = dict(os.environ)
    env.pop("OPENBLAS_NUM_THREADS", None)
    if blas_threads is not None:
        env["OPENBLAS_NUM_THREADS"] = blas_threads

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (megabytes << 20, megabytes << 20))

    return subprocess.run([str(voiga_bin), str(case), "--quiet", *args], preexec_fn=limit, env=env,
                          capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("blas_threads", [None, "1", "2"])
def test_memory_limit_refused_before_the_run(voiga_bin: Path, tmp_path: Path,
                                             blas_threads: str | None) -> None:
    """Under `ulimit -v` 330 MB (OpenBLAS's buffer alone takes 128 MB of it) the
    estimate of hertz m6 does not fit: refused with the numbers, nothing written;
    whatever the number of BLAS threads (OpenBLAS threads that cannot map their
    buffers spin for ever: voiga runs with one under a limit)."""
    case = hertz_m6(tmp_path)
    res = run_limited(voiga_bin, case, 330, blas_threads=blas_threads)
    assert res.returncode == 2, res.stderr
    assert re.search(r"needs about [\d.]+ MB more memory \(28420 DOFs", res.stderr), res.stderr
    assert "address-space limit (ulimit -v) leaves" in res.stderr
    assert not (tmp_path / "m6-N2.h5").exists() and not list(tmp_path.glob("*.part"))


def test_memory_limit_met_during_the_run(voiga_bin: Path, tmp_path: Path) -> None:
    """Past the estimate (--no-memory-check) the allocation that fails is caught: exit
    1 naming the memory, and a readable result recording the failure."""
    case = hertz_m6(tmp_path)
    res = run_limited(voiga_bin, case, 330, "--no-memory-check")
    assert res.returncode == 1, res.stderr
    assert "out of memory" in res.stderr and "Backtrace" not in res.stderr
    with h5py.File(tmp_path / "m6-N2.h5", "r") as f:
        assert "out of memory" in f.attrs["status"].decode()
        assert int(f.attrs["n_steps_done"]) == 0


def test_too_little_address_space_for_blas(voiga_bin: Path, tmp_path: Path) -> None:
    res = run_limited(voiga_bin, hertz_m6(tmp_path), 150)
    assert res.returncode == 1, res.stderr
    assert "the BLAS library alone needs 128 MB of address space" in res.stderr


@pytest.mark.parametrize("nel,words", [
    (100000, ["too large", "DOFs", "elements", "32-bit"]),
    (2500, ["needs about", "GB more memory", "MemAvailable"]),
])
def test_mesh_that_cannot_fit_refused_at_once(run, tmp_path: Path, nel: int, words: list[str]) -> None:
    """nel_xi = nel_eta = 100000 (it ran on without a size estimate): the counts are
    taken before anything is built; 2500 x 2500 fits the integers but not the memory."""
    case = ironing(tmp_path)
    text = case.read_text().replace("nel_xi = 8", f"nel_xi = {nel}").replace("nel_eta = 2", f"nel_eta = {nel}")
    case.write_text(text)
    res = run(case, "--check")
    assert res.returncode == 2, res.stderr
    for word in words:
        assert word in res.stderr, res.stderr
