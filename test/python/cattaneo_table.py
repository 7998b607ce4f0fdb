"""The Cattaneo-Mindlin table of docs/verification.md: every scene of ``python -m pre
cattaneo`` with every contact method (and the default method under refinement), solved
and compared with ``post.cattaneo``.

    python3 test/python/cattaneo_table.py OUT [--only rigid mirror] [--methods gpts mortar]

Writes OUT/<row>/ (case, geometry, result) and prints the markdown table. VOIGA_BIN
names the binary (default build/install/bin/voiga). A scene the binary refuses (an
older voiga without friction per phase) is listed as refused.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))

from post.cattaneo import CattaneoError, cattaneo_comparison  # noqa: E402
from post.reader import read_result  # noqa: E402
from pre.cattaneo import CattaneoScene, write_cattaneo  # noqa: E402

SCENES = {
    "rigid": CattaneoScene(master="rigid"),
    "rigid, frictionless press": CattaneoScene(master="rigid", press_friction=0.0),
    "mirror": CattaneoScene(master="mirror"),
    "block": CattaneoScene(master="block"),
}
"""Scene label -> scene (nu = 0.49, mu = 0.3, d = 0.01, NN2.2, h = a/20 unless a row says)."""


def rows(scenes: list[str], methods: list[str]) -> list[tuple[str, str, CattaneoScene]]:
    """(scene label, row label, scene) of the table: each method at a/20 with NN2.2,
    and the default method (gpts) at a/10 and a/40 and with N2."""
    out = []
    for label in scenes:
        base = SCENES[label]
        for m in methods:
            out.append((label, f"{m} NN2.2 a/20", replace(base, method=m)))
        out.append((label, "gpts NN2.2 a/10", replace(base, method="gpts", elements_per_a=10.0)))
        out.append((label, "gpts NN2.2 a/40", replace(base, method="gpts", elements_per_a=40.0)))
        out.append((label, "gpts N2 a/20", replace(base, method="gpts", layout="N2")))
    return out


def scatter(x: np.ndarray, q: np.ndarray, state: np.ndarray, a: float, q0: float) -> float:
    """The rms second difference of q / q0 over the sticking points with |x| < 0.9 a: a
    smooth traction gives nearly 0, a point-to-point scatter its size."""
    inner = (state == 1) & (np.abs(x) < 0.9 * a)
    s = q[inner] / q0
    return float(np.sqrt(np.mean((s[2:] - 2 * s[1:-1] + s[:-2]) ** 2))) if s.size > 3 else float("nan")


def run(binary: str, folder: Path, scene: CattaneoScene) -> str:
    """Solve and return the table row's cells."""
    case = write_cattaneo(scene, folder, force=True, stem="case")
    t0 = time.monotonic()
    proc = subprocess.run([binary, case.name, "--quiet", "--overwrite"], cwd=folder, capture_output=True,
                          text=True, timeout=3600)
    wall = time.monotonic() - t0
    if proc.returncode == 2:
        return "refused | | | | | |"
    line = next((x for x in proc.stdout.splitlines() if x.startswith("converged:")), "")
    result = read_result(folder / "case.h5")
    try:
        press = cattaneo_comparison(result, step=scene.press_steps)
        spread = scatter(press.x, press.q, press.state, press.a, press.friction * press.p0)
        residual = f"{press.stick_traction:.3f} / {spread:.3f}"
    except CattaneoError:
        residual = "(frictionless)"
    if proc.returncode != 0:
        return f"{residual} | failed (exit {proc.returncode}) | | | | |"
    c = cattaneo_comparison(result)
    cuts = line.split(" cuts)")[0].rsplit(" ", 1)[1] if line else "?"
    its = line.split(" Newton iterations")[0].rsplit(" ", 1)[1] if line else "?"
    return (f"{residual} | {c.ratio:.3f} | {c.c_simulated:.4f} ({c.c_simulated - c.c_analytic:+.4f}) | "
            f"{100 * c.l2:.1f} | {cuts} / {its} | {wall:.1f}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", help="work folder")
    ap.add_argument("--only", nargs="+", choices=list(SCENES), default=list(SCENES))
    ap.add_argument("--methods", nargs="+", default=["gpts", "mortar", "alm"])
    args = ap.parse_args(argv)
    binary = os.environ.get("VOIGA_BIN", str(REPO / "build" / "install" / "bin" / "voiga"))
    print("| scene | method, layout, h | after the press: max q_stick / scatter (mu p0) | Q/(mu P) | "
          "c/a (vs Cattaneo-Mindlin) | L2 of q, % | cuts / Newton it. | wall s |")
    print("|---|---|---|---|---|---|---|---|")
    for k, (label, row, scene) in enumerate(rows(args.only, args.methods)):
        cells = run(binary, Path(args.out) / f"{k:02d}", scene)
        print(f"| {label} | {row} | {cells} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
