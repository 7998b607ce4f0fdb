"""``python -m post plot-deformed`` writes PNGs (smoke tests) and its
sampling helpers keep element boundaries."""

from __future__ import annotations

import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest

from post.__main__ import main
from post.plot import breakpoints, deformed_grid, sample_parameters
from post.reader import body_displacement, read_result

from .conftest import exact_stretch

PNG = b"\x89PNG\r\n\x1a\n"


def _is_png(path: Path) -> bool:
    return path.is_file() and path.read_bytes()[:8] == PNG and path.stat().st_size > 20_000


def test_plot_deformed_default_name(stretch_h5: Path, tmp_path: Path,
                                    capsys: pytest.CaptureFixture[str]) -> None:
    result = tmp_path / "stretch.h5"
    shutil.copy(stretch_h5, result)
    assert main(["plot-deformed", str(result)]) == 0
    out = tmp_path / "stretch-deformed-000002.png"
    assert capsys.readouterr().out.strip() == str(out) and _is_png(out)


def test_plot_deformed_options(two_h5: Path, tmp_path: Path) -> None:
    for args in (["--step", "1", "--scale", "5"], ["--step", "-2", "--reference"],
                 ["--step", "0"]):
        out = tmp_path / f"two{'_'.join(args)}.png"
        assert main(["plot-deformed", str(two_h5), "-o", str(out), *args]) == 0, args
        assert _is_png(out), args


def test_plot_failed_run(crush_h5: Path, tmp_path: Path) -> None:
    out = tmp_path / "crush.png"
    assert main(["plot-deformed", str(crush_h5), "-o", str(out)]) == 0
    assert _is_png(out)


def test_plot_without_steps(two_h5: Path, tmp_path: Path,
                            capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "empty.h5"
    shutil.copy(two_h5, path)
    with h5py.File(path, "r+") as f:
        f.attrs["status"] = np.bytes_(b"running")
        for key in list(f["steps"]):
            del f["steps"][key]
    assert main(["plot-deformed", str(path), "-o", str(tmp_path / "a.png")]) == 1
    assert "no converged step" in capsys.readouterr().err
    assert main(["plot-deformed", str(path), "-o", str(tmp_path / "b.png"), "--step", "0"]) == 0
    assert main(["plot-deformed", str(two_h5), "-o", str(tmp_path / "c.png"), "--step", "7"]) == 1


def test_sampling_contains_breakpoints() -> None:
    br = np.array([0.0, 0.1, 0.5, 1.0])
    t = sample_parameters(br, minimum=30)
    assert np.all(np.isin(br, t)) and np.all(np.diff(t) > 0) and len(t) >= 30
    assert t[0] == 0.0 and t[-1] == 1.0


def test_deformed_grid(stretch_h5: Path) -> None:
    r = read_result(stretch_h5)
    body = r.bodies["slab"]
    bx, be = breakpoints(body)
    np.testing.assert_allclose(bx, np.linspace(0, 1, 9), atol=1e-15)
    np.testing.assert_allclose(be, [0, 0.5, 1], atol=1e-15)
    u = body_displacement(r, "slab")
    pts, mag = deformed_grid(body, u, scale=3.0, minimum=40)
    ref, _ = deformed_grid(body, u, scale=0.0, minimum=40)
    exact = exact_stretch(ref, r.steps[-1].time)
    assert np.abs(pts - ref - 3.0 * exact).max() < 1e-12
    assert np.abs(mag - np.linalg.norm(exact, axis=-1)).max() < 1e-12
