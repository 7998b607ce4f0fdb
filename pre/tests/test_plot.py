"""Plot commands write readable PNGs (smoke tests)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from pre.__main__ import main
from pre.plot import rational_basis
from pre.refine import discretize_case


def test_plot_layout(generated: Path, tmp_path: Path) -> None:
    for layout in ("NN2.2", "N2"):
        out = tmp_path / f"{layout}.png"
        assert main(["plot-layout", str(generated / f"ironing/m1-{layout}.nml"),
                     "--body", "die", "-o", str(out)]) == 0
        assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out.stat().st_size > 20_000


def test_rational_basis_partition_of_unity(generated: Path) -> None:
    layer = discretize_case(generated / "hertz/m1-NN2.2.nml").bodies["cylinder"].layer
    r = rational_basis(layer, np.linspace(0, 1, 501))
    assert r.shape == (501, len(layer.weights)) and np.abs(r.sum(axis=1) - 1).max() < 1e-13
    assert r.min() >= 0.0
