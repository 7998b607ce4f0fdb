"""post's figures and ParaView files (issue 36): written beside their target and
renamed onto it (pre.files), never through a link or into a FIFO; such a target is
refused with exit 2 and one line, the file a link points to untouched."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, *args], capture_output=True, text=True, timeout=120,
                          env=dict(os.environ, MPLBACKEND="Agg"))


@pytest.mark.parametrize("command", ["plot-deformed", "vtk"])
def test_post_does_not_write_through_a_link_or_a_fifo(tmp_path: Path, command: str,
                                                      stretch_h5: Path) -> None:
    """A figure or ParaView file whose name is a link to another file, or a FIFO:
    matplotlib and VTK wrote through it (or waited on the FIFO)."""
    victim = tmp_path / "victim.h5"
    victim.write_bytes(b"precious")
    name = "r-deformed-000002.png" if command == "plot-deformed" else "r.pvd"
    result = tmp_path / "r.h5"
    result.write_bytes(stretch_h5.read_bytes())
    for special in ("link", "fifo"):
        target = tmp_path / name
        target.unlink(missing_ok=True)
        if special == "link":
            target.symlink_to(victim.name)
        else:
            os.mkfifo(target)
        res = run("-m", "post", command, str(result))
        assert res.returncode == 2 and "not a regular file" in res.stderr, res.stderr
        assert res.stderr.count("\n") == 1, res.stderr
        assert victim.read_bytes() == b"precious"
