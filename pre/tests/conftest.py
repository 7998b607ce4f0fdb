"""Shared fixtures: the repo root, a freshly generated cases/ tree and the built voiga."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from pre.cases import write_cases

REPO = Path(__file__).resolve().parents[2]
CASES = REPO / "cases"


@pytest.fixture(scope="session")
def repo() -> Path:
    return REPO


@pytest.fixture(scope="session")
def generated(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``python -m pre cases`` written into a temporary folder."""
    out = tmp_path_factory.mktemp("cases")
    write_cases(out)
    return out


@pytest.fixture(scope="session")
def voiga_bin() -> Path:
    """The built ``voiga`` (``$VOIGA_BIN``, else ``build/install/bin/voiga``); the test
    is skipped without it (failed on CI, where it must be there)."""
    path = Path(os.environ.get("VOIGA_BIN", REPO / "build" / "install" / "bin" / "voiga"))
    if not (path.is_file() and os.access(path, os.X_OK)):
        if os.environ.get("CI"):
            pytest.fail(f"voiga binary not found at {path}; run `make build` first")
        pytest.skip(f"voiga binary not found at {path}; run `make build` first")
    return path
