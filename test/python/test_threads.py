"""The thread counts of OpenBLAS and OpenMP (docs/performance.md, "Threads"): one
thread each unless the environment sets OPENBLAS_NUM_THREADS, GOTO_NUM_THREADS or
OMP_NUM_THREADS; the result file records which (root attribute ``library_threads``)."""
from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import h5py
import pytest

from conftest import REPO
from post.reader import decode

VARIABLES = ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS")


@pytest.mark.parametrize("setting, recorded", [
    ({}, "1 (voiga's default)"),
    ({"OPENBLAS_NUM_THREADS": "2"}, "OPENBLAS_NUM_THREADS=2 (environment)"),
    ({"OMP_NUM_THREADS": "1", "GOTO_NUM_THREADS": "3"},
     "GOTO_NUM_THREADS=3 OMP_NUM_THREADS=1 (environment)"),
])
def test_library_threads_recorded(voiga_bin: Path, tmp_path: Path, setting: dict[str, str],
                                  recorded: str) -> None:
    shutil.copy(REPO / "cases" / "hertz" / "geometry.h5", tmp_path)
    shutil.copy(REPO / "cases" / "hertz" / "m1-NN2.2.nml", tmp_path / "case.nml")
    env = {k: v for k, v in os.environ.items() if k not in VARIABLES} | setting
    res = subprocess.run([str(voiga_bin), "case.nml", "--quiet"], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    with h5py.File(tmp_path / "m1-NN2.2.h5", "r") as f:
        assert decode(f.attrs["library_threads"]) == recorded


def _kernels(voiga_bin: Path, tmp_path: Path, setting: dict[str, str]) -> str:
    """The root attribute ``blas_kernels`` of hertz m1 NN2.2 run under ``setting``."""
    shutil.copy(REPO / "cases" / "hertz" / "geometry.h5", tmp_path)
    shutil.copy(REPO / "cases" / "hertz" / "m1-NN2.2.nml", tmp_path / "case.nml")
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_CORETYPE"} | setting
    res = subprocess.run([str(voiga_bin), "case.nml", "--quiet", "--overwrite"], cwd=tmp_path,
                         env=env, capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    with h5py.File(tmp_path / "m1-NN2.2.h5", "r") as f:
        return decode(f.attrs["blas_kernels"])


def test_blas_kernels_recorded_and_environment_kept(voiga_bin: Path, tmp_path: Path) -> None:
    """A user's OPENBLAS_CORETYPE is what runs (and is recorded as theirs); without
    it the record says who chose the kernels: OpenBLAS, or voiga replacing OpenBLAS's
    generic Prescott kernels on a CPU OpenBLAS did not know (kernels_shim.c)."""
    forced = _kernels(voiga_bin, tmp_path, {"OPENBLAS_CORETYPE": "Prescott"})
    if forced == "not OpenBLAS":
        pytest.skip("the BLAS is not OpenBLAS")
    assert forced == "Prescott (environment: OPENBLAS_CORETYPE=Prescott)"
    chosen = _kernels(voiga_bin, tmp_path, {})
    assert chosen.endswith("(OpenBLAS)") or chosen.endswith("OpenBLAS chose Prescott)"), chosen
    assert not chosen.startswith("Prescott (voiga"), chosen
