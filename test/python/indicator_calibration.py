"""The calibration of the contact-zone indicator (post/indicator.py, docs/contact-accuracy.md):

    python test/python/indicator_calibration.py [--out DIR]

solves the Hertz cases below (a few seconds each), and prints per step the indicator's
raw estimate against the L2 error at the edge that `post hertz --reference circle`
measures (``l2_edge``: the part from |x| > 0.95 a), and the median of their ratio over
the zones with at least ``RESOLVED`` slave elements across: the constant
``post.indicator.CALIBRATION``. The cases: the committed hertz m3, m4, m5 NN2.2 with the
automatic penalty (the case's ``penalty_normal`` and ``method`` dropped: voiga's
defaults), and `pre hertz` cylinders of a/R = 0.030 and 0.015 on m4, plain and with
``--edge-refine 4 --surface-size 0.016``.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from post.hertz import hertz_comparison  # noqa: E402
from post.indicator import measure_pair  # noqa: E402
from post.reader import read_result  # noqa: E402
from post.solver import voiga_binary  # noqa: E402

RESOLVED = 10.0
"""Zones with fewer slave elements across are left out of the median (their fits are
poor and their estimates far too large: they are flagged whatever the constant)."""

CYLINDERS = (("r2", ["--radius", "2", "--youngs-modulus", "10", "--indentation", "0.00396"]),
             ("r15", ["--radius", "1.5", "--youngs-modulus", "3", "--poisson-ratio", "0.25",
                      "--indentation", "0.00086"]))


def committed(out: Path, mesh: str) -> Path:
    """The committed hertz case with voiga's default contact settings, in ``out``."""
    text = (ROOT / "cases" / "hertz" / f"{mesh}-NN2.2.nml").read_text()
    text = re.sub(r"\n *(penalty_normal|method) = [^\n]*", "", text)
    text = text.replace("geometry = 'geometry.h5'",
                        f"geometry = '{ROOT / 'cases' / 'hertz' / 'geometry.h5'}'")
    case = out / f"{mesh}-NN2.2.nml"
    case.write_text(text)
    return case


def cylinders(out: Path) -> list[Path]:
    """The `pre hertz` cases."""
    cases = []
    for name, args in CYLINDERS:
        for extra in ([], ["--edge-refine", "4", "--surface-size", "0.016"]):
            folder = out / name
            subprocess.run([sys.executable, "-m", "pre", "hertz", *args, "--mesh", "m4",
                            "--penalty-normal", "auto", *extra, "--out", str(folder), "--force"],
                           check=True, cwd=ROOT, stdout=subprocess.DEVNULL)
            cases.append(folder / ("m4-NN2.2" + ("-edge4-surf0.016" if extra else "") + ".nml"))
    return cases


def rows(result_path: Path) -> list[tuple[str, int, float, float, float]]:
    """(case, step, elements across, raw, l2_edge) per step."""
    r = read_result(result_path)
    out = []
    for k, st in enumerate(r.steps):
        zones = measure_pair(r, k, 0)
        if not zones or not zones[0].edges:
            continue
        h = hertz_comparison(r, step=st.step, reference="circle")
        out.append((f"{result_path.parent.name}/{result_path.stem}", st.step,
                    zones[0].elements_across, zones[0].edges[0].raw, h.error.l2_edge))
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="build/indicator-calibration", help="folder for the runs")
    args = parser.parse_args()
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    program = voiga_binary()
    cases = [committed(out, m) for m in ("m3", "m4", "m5")] + cylinders(out)
    table = []
    for case in cases:
        subprocess.run([str(program), str(case), "--quiet", "--overwrite"], check=True,
                       stdout=subprocess.DEVNULL)
        table += rows(case.with_suffix(".h5"))
    print(f"{'case':28s} step  across    raw  l2_edge  ratio")
    for name, step, across, raw, edge in table:
        print(f"{name:28s} {step:4d} {across:7.1f} {raw:6.3%} {edge:7.3%} {edge / raw:6.2f}")
    ratios = np.array([edge / raw for _, _, across, raw, edge in table if across >= RESOLVED])
    c = float(np.median(ratios))
    within = np.mean((c * 2 >= ratios) & (ratios >= c / 2))
    print(f"median l2_edge / raw over {len(ratios)} resolved steps: {c:.3f} "
          f"(ratios {ratios.min():.2f} .. {ratios.max():.2f}; {within:.0%} within a factor 2 of it)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
