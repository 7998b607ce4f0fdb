"""The docs a user reads: no page in docs/ over 40 KB, every link points at a file of the
repository, and the Python recipes of docs/howto.md run."""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import REPO

PAGES = sorted([REPO / "README.md", REPO / "CHANGELOG.md", *(REPO / "docs").glob("*.md")])
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
LIMIT = 40 * 1024


def test_no_docs_page_over_40_kb() -> None:
    """Every page (text file) of docs/; the figures (PNG) are pictures, not pages."""
    big = [(p.relative_to(REPO), p.stat().st_size) for p in (REPO / "docs").rglob("*")
           if p.is_file() and p.suffix != ".png" and p.stat().st_size > LIMIT]
    assert not big, big


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(REPO)))
def test_links_stay_in_the_repository(page: Path) -> None:
    text = page.read_text()
    assert "../shared" not in text and "/work/" not in text
    for target in LINK.findall(text):
        if re.match(r"^[a-z]+://", target) or target.startswith("#"):
            continue  # a web address or an anchor of the same page
        path = (page.parent / target.split("#")[0]).resolve()
        assert path.is_relative_to(REPO), f"{page.name}: {target} leaves the repository"
        assert path.exists(), f"{page.name}: {target} does not exist"


def test_howto_python_runs(tmp_path: Path) -> None:
    blocks = re.findall(r"^```python\n(.*?)^```", (REPO / "docs" / "howto.md").read_text(),
                        re.S | re.M)
    assert blocks
    for code in blocks:
        run = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                             text=True, timeout=120, env={"PYTHONPATH": str(REPO), "PATH": ""})
        assert run.returncode == 0, run.stderr[-2000:]
    assert (tmp_path / "scene-geometry.h5").is_file()
