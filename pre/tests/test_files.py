"""pre.files (issue 36): what pre and post write is written beside its target and
renamed onto it, never through a link and never over a FIFO, a device or a folder;
a write that fails leaves the earlier file as it was. The commands that write
(``pre geometry``; post's: post/tests/test_safe_outputs.py) refuse such a target
with exit 2 and one line."""
from __future__ import annotations

import os
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from pre.files import OutputError, check_output, new_file, write_text

SPEC = "[[body]]\nname = 'a'\nshape = 'rectangle'\nx = [0, 1]\ny = [0, 1]\n"


def test_regular_file_replaced_by_name(tmp_path: Path) -> None:
    """A regular file is replaced by the rename: its other names keep their bytes."""
    target = tmp_path / "out.txt"
    target.write_text("old")
    os.link(target, tmp_path / "other-name.txt")
    write_text(target, "new")
    assert target.read_text() == "new" and (tmp_path / "other-name.txt").read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["other-name.txt", "out.txt"]


@pytest.mark.parametrize("kind", ["link", "fifo", "folder"])
def test_nothing_written_through_what_is_not_a_regular_file(tmp_path: Path, kind: str) -> None:
    victim = tmp_path / "victim.h5"
    victim.write_text("precious")
    target = tmp_path / "out.png"
    if kind == "link":
        target.symlink_to(victim.name)
    elif kind == "fifo":
        os.mkfifo(target)
    else:
        target.mkdir()
    with pytest.raises(OutputError, match="not a regular file"):
        write_text(target, "new")
    assert victim.read_text() == "precious"
    assert {"link": stat.S_ISLNK, "fifo": stat.S_ISFIFO, "folder": stat.S_ISDIR}[kind](os.lstat(target).st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.png", "victim.h5"]


def test_failed_write_keeps_the_earlier_file(tmp_path: Path) -> None:
    target = tmp_path / "table.csv"
    target.write_text("earlier")
    with pytest.raises(RuntimeError):
        with new_file(target) as tmp:
            tmp.write_text("half")
            raise RuntimeError("the writer failed")
    assert target.read_text() == "earlier" and [p.name for p in tmp_path.iterdir()] == ["table.csv"]


def test_check_output_names_the_kind(tmp_path: Path) -> None:
    os.mkfifo(tmp_path / "pipe")
    with pytest.raises(OutputError, match="FIFO"):
        check_output(tmp_path / "pipe")
    assert check_output(tmp_path / "missing") == tmp_path / "missing"


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, *args], capture_output=True, text=True, timeout=120,
                          env=dict(os.environ, MPLBACKEND="Agg"))


def test_pre_geometry_does_not_write_through_a_link(tmp_path: Path) -> None:
    """The geometry file a spec writes, linked to another file: h5py wrote through the
    link (the other file became the geometry)."""
    (tmp_path / "s.toml").write_text(SPEC)
    victim = tmp_path / "victim.h5"
    victim.write_bytes(b"precious")
    (tmp_path / "s-geometry.h5").symlink_to(victim.name)
    res = run("-m", "pre", "geometry", str(tmp_path / "s.toml"))
    assert res.returncode == 2 and res.stderr.count("\n") == 1 and "symbolic link" in res.stderr, res.stderr
    assert victim.read_bytes() == b"precious" and not (tmp_path / "s.nml").exists()
