"""``python -m post figures`` (:func:`post.figures.make_all`): the figures drawn by
several processes are the same files, byte for byte, as those drawn by one."""
from __future__ import annotations

import csv
import subprocess
import sys
from pathlib import Path

from post.figures import make_all

COLUMNS = ["scene", "mesh", "layout", "status", "wall_s", "time_norm", "l2_ref_field", "l2_ref", "l2_analytic"]


def _results(folder: Path) -> Path:
    """A results folder with a summary of six converged hertz runs and no result files."""
    folder.mkdir()
    with (folder / "summary.csv").open("w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(COLUMNS)
        for i, mesh in enumerate(("m1", "m2", "m3")):
            for layout, factor in (("N2", 1.0), ("NN2.2", 0.5)):
                error = factor * 0.1 / 4**i
                writer.writerow(["hertz", mesh, layout, "converged", 0.1 * 4**i, 0.01 * 4**i, error, error,
                                 error])
    return folder


def test_parallel_figures_equal_serial(tmp_path: Path) -> None:
    results = _results(tmp_path / "results")
    serial = make_all(results, tmp_path / "one", jobs=1)
    parallel = make_all(results, tmp_path / "two", jobs=2)
    assert [p.name for p in serial] == [p.name for p in parallel]
    # the three hertz error plots (mesh and time each) and the two pressure plots
    assert len(serial) == 8
    for a, b in zip(serial, parallel, strict=True):
        assert a.read_bytes() == b.read_bytes(), a.name
    assert (tmp_path / "one" / "accuracy-cost.md").read_text() == (tmp_path / "two" / "accuracy-cost.md").read_text()


def test_jobs_must_be_positive(tmp_path: Path) -> None:
    results = _results(tmp_path / "results")
    res = subprocess.run([sys.executable, "-m", "post", "figures", "--results", str(results), "--out",
                          str(tmp_path / "out"), "--jobs", "0"], capture_output=True, text=True, timeout=120)
    assert res.returncode == 2
    assert "--jobs must be at least 1" in res.stderr
    assert not (tmp_path / "out").exists()
