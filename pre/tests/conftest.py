"""Shared fixtures: the repo root and a freshly generated cases/ tree."""

from __future__ import annotations

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
