"""Fixtures for tests of the `voiga` program itself (its command line, messages, exit codes)."""
from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def voiga_bin() -> Path:
    """Path of the built `voiga` program (VOIGA_BIN, else build/install/bin/voiga)."""
    path = Path(os.environ.get("VOIGA_BIN", REPO / "build" / "install" / "bin" / "voiga"))
    if not path.exists():
        if os.environ.get("CI"):
            pytest.fail(f"voiga binary not found at {path}; run `make build` first")
        pytest.skip(f"voiga binary not found at {path}; run `make build` first")
    return path


@pytest.fixture()
def run(voiga_bin: Path):
    """Run voiga with arguments; returns the CompletedProcess (never raises on exit code)."""

    def _run(*args: str | Path, cwd: Path | None = None) -> subprocess.CompletedProcess:
        return subprocess.run(
            [str(voiga_bin), *map(str, args)], capture_output=True, text=True, timeout=120, cwd=cwd
        )

    return _run


@pytest.fixture()
def ironing_copy(tmp_path: Path) -> Path:
    """A scratch copy of the ironing geometry and its m1-N2 case; returns the case path."""
    shutil.copy(REPO / "cases" / "ironing" / "geometry.h5", tmp_path / "geometry.h5")
    case = tmp_path / "case.nml"
    shutil.copy(REPO / "cases" / "ironing" / "m1-N2.nml", case)
    return case
