"""The docs a user reads: no page in docs/ over 40 KB, every link points at a file of the
repository, every path and code name they mention exists (check_docs.py), and the
Python recipes of docs/howto.md run."""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from check_docs import pages, stale_mentions
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


def test_docs_mention_only_what_the_tree_has() -> None:
    """Every path, file and code name README.md and docs/ mention exists (the check of
    `make lint`, test/python/check_docs.py)."""
    assert stale_mentions(pages()) == []


def test_stale_mentions_are_named_with_page_and_line(tmp_path: Path) -> None:
    """A planted page: each stale mention is reported with its line, and what is not a
    repository path or code name (web addresses, generated folders, placeholders,
    mathematical subscripts, the prose "pre/post") is not. The planted names are put
    together here, so that this file does not make them exist."""
    gone = "no_such" + "_procedure"
    page = tmp_path / "planted.md"
    page.write_text("\n".join([
        "# A page",                                                                 # 1
        "The solver lives in `src/solver/newton.f90` and `src/solver/`.",          # 2
        "It moved: `src/solver/no_such_file.f90`.",                                  # 3
        "Load stepping is in src/solver/gone.f90, the tools are pre/post tools.",    # 4
        "See `no_such_file.f90` and `newton.f90`.",                                  # 5
        f"Call `tresca_fixed_point` or `{gone}()`; `pair%law%eps_n`, `{gone}%law`.",  # 6
        "(`newton.f90`, `tresca_fixed_point`) and (`outer.f90`, `tresca_fixed_point`)",  # 7
        f"`post.reader.read_result`, `post.{gone}`, `post.reader.{gone}`",           # 8
        "Cases are `cases/<scene>/<mesh>-<layout>.nml`; `cases/hertz/m9-N9.nml`.",   # 9
        "https://example.org/src/solver/x.f90, `build/run/x.h5`, `results/`, `xi_0`, `eta_j`.",  # 10
        "`src/solver/{newton,outer}.f90` and `src/solver/{newton,nothing}.f90`.",    # 11
        "`gpts_zone` in `src/contact/pair.f90`; `gpts_zone` in `src/contact/gpts.f90`.",  # 12
    ]) + "\n")
    found = stale_mentions([page])
    assert found == [
        f"{page}:3: src/solver/no_such_file.f90: no such file or folder",
        f"{page}:4: src/solver/gone.f90: no such file or folder",
        f"{page}:5: no_such_file.f90: no file of that name",
        f"{page}:6: {gone}: not in the sources",
        f"{page}:7: tresca_fixed_point: not defined in newton.f90",
        f"{page}:8: post.{gone}: post/__init__.py has no {gone}",
        f"{page}:8: post.reader.{gone}: post/reader.py has no {gone}",
        f"{page}:9: cases/hertz/m9-N9.nml: no such file or folder",
        f"{page}:11: src/solver/{{newton,nothing}}.f90: no such file or folder",
        f"{page}:12: gpts_zone: not defined in src/contact/pair.f90",
    ], found
    run = subprocess.run([sys.executable, str(REPO / "test" / "python" / "check_docs.py"), str(page)],
                         capture_output=True, text=True, timeout=60)
    assert run.returncode == 1
    assert f"{page}:3: src/solver/no_such_file.f90" in run.stdout
    assert "check_docs: 10 stale mentions" in run.stdout
