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

It then checks the coarse zones (fewer than ``RESOLVED`` elements across, where the fit
takes the zone near the edge instead of the band: ``post.indicator.fit_points``) against
the whole L2 error there (on a coarse zone the edge's error spreads over the zone): the
steps of those runs with fewer elements across, the committed m1 and m2, and `pre
hertz` cylinders (the two above and R 0.5, E 70, nu 0.4, d 0.0006; R 3, E 1, nu 0.2,
d 0.0008) on m1, m2, m3; it prints the calibrated estimate over the L2 error.
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
from post.indicator import CALIBRATION, measure_pair  # noqa: E402
from post.reader import read_result  # noqa: E402
from post.solver import voiga_binary  # noqa: E402

RESOLVED = 10.0
"""Zones with fewer slave elements across are left out of the median (their fits are
poor and their estimates far too large: they are flagged whatever the constant)."""

CYLINDERS = (("r2", ["--radius", "2", "--youngs-modulus", "10", "--indentation", "0.00396"]),
             ("r15", ["--radius", "1.5", "--youngs-modulus", "3", "--poisson-ratio", "0.25",
                      "--indentation", "0.00086"]))
COARSE_CYLINDERS = CYLINDERS + (
    ("r05", ["--radius", "0.5", "--youngs-modulus", "70", "--poisson-ratio", "0.4",
             "--indentation", "0.0006"]),
    ("r3", ["--radius", "3", "--youngs-modulus", "1", "--poisson-ratio", "0.2",
            "--indentation", "0.0008"]))


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


def coarse_cylinders(out: Path) -> list[Path]:
    """The `pre hertz` cylinders on the coarse meshes m1, m2, m3."""
    cases = []
    for name, args in COARSE_CYLINDERS:
        for mesh in ("m1", "m2", "m3"):
            folder = out / "coarse" / name
            subprocess.run([sys.executable, "-m", "pre", "hertz", *args, "--mesh", mesh,
                            "--penalty-normal", "auto", "--out", str(folder), "--force"],
                           check=True, cwd=ROOT, stdout=subprocess.DEVNULL)
            cases.append(folder / f"{mesh}-NN2.2.nml")
    return cases


def solve(program: Path, cases: list[Path]) -> list[tuple[str, int, float, float, float, float]]:
    """Solve ``cases`` and return their :func:`rows`."""
    table = []
    for case in cases:
        subprocess.run([str(program), str(case), "--quiet", "--overwrite"], check=True,
                       stdout=subprocess.DEVNULL)
        table += rows(case.with_suffix(".h5"))
    return table


def rows(result_path: Path) -> list[tuple[str, int, float, float, float, float]]:
    """(case, step, elements across, raw, l2_edge, l2) per step."""
    r = read_result(result_path)
    out = []
    for k, st in enumerate(r.steps):
        zones = measure_pair(r, k, 0)
        if not zones or not zones[0].edges:
            continue
        h = hertz_comparison(r, step=st.step, reference="circle")
        out.append((f"{result_path.parent.name}/{result_path.stem}", st.step,
                    zones[0].elements_across, zones[0].edges[0].raw, h.error.l2_edge, h.error.l2))
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="build/indicator-calibration", help="folder for the runs")
    args = parser.parse_args()
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    program = voiga_binary()
    cases = [committed(out, m) for m in ("m3", "m4", "m5")] + cylinders(out)
    table = solve(program, cases)
    print(f"{'case':28s} step  across    raw  l2_edge  ratio")
    for name, step, across, raw, edge, _ in table:
        print(f"{name:28s} {step:4d} {across:7.1f} {raw:6.3%} {edge:7.3%} {edge / raw:6.2f}")
    ratios = np.array([edge / raw for _, _, across, raw, edge, _ in table if across >= RESOLVED])
    c = float(np.median(ratios))
    within = np.mean((c * 2 >= ratios) & (ratios >= c / 2))
    print(f"median l2_edge / raw over {len(ratios)} resolved steps: {c:.3f} "
          f"(ratios {ratios.min():.2f} .. {ratios.max():.2f}; {within:.0%} within a factor 2 of it)")
    coarse = table + solve(program, [committed(out, m) for m in ("m1", "m2")] + coarse_cylinders(out))
    coarse = [row for row in coarse if row[2] < RESOLVED]
    print(f"\n{'coarse case':28s} step  across estimate      l2  ratio")
    for name, step, across, raw, _, l2 in coarse:
        print(f"{name:28s} {step:4d} {across:7.1f} {CALIBRATION * raw:8.3%} {l2:7.3%} "
              f"{CALIBRATION * raw / l2:6.2f}")
    ratios = np.array([CALIBRATION * raw / l2 for _, _, _, raw, _, l2 in coarse])
    within = np.mean((ratios <= 2) & (ratios >= 0.5))
    print(f"estimate / l2 over {len(ratios)} steps with fewer than {RESOLVED:g} elements across: "
          f"median {np.median(ratios):.2f} (ratios {ratios.min():.2f} .. {ratios.max():.2f}; "
          f"{within:.0%} within a factor 2 of 1)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
