"""``python3 -m bench.stages RESULT.h5 ...``: the cost of one Newton iteration of finished runs.

For each result file: its Newton iterations (substeps and failed attempts included) and,
per iteration, the milliseconds of each stage the solver times (the sums over the steps
of the ``seconds_<stage>`` attributes, docs/hdf5.md), the run's wall time and the rest
(``other`` = wall time - staged seconds: set-up, convergence checks, contact states,
step bookkeeping). It reads files, it runs nothing: time the runs themselves interleaved
(A B A B ...) on a shared machine, and compare the tables of runs made side by side.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .run import STAGES, read_stages


def table(paths: list[Path]) -> str:
    """One line per result file: iterations, wall seconds, ms per iteration by stage."""
    head = f"{'result':32s} {'iters':>6s} {'wall s':>8s} |" + "".join(f"{s[:10]:>11s}" for s in STAGES)
    lines = [head + f"{'other':>11s}   (ms per Newton iteration)"]
    for p in paths:
        st = read_stages(p)
        n = max(st.iterations, 1)
        other = st.wall_time - sum(st.seconds.values())
        cells = "".join(f"{1e3 * st.seconds[s] / n:11.3f}" for s in STAGES)
        lines.append(f"{str(p)[-32:]:32s} {st.iterations:6d} {st.wall_time:8.3f} |{cells}{1e3 * other / n:11.3f}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Print the table of the result files named on the command line."""
    ap = argparse.ArgumentParser(prog="python3 -m bench.stages", description=__doc__.split("\n")[0])
    ap.add_argument("results", nargs="+", type=Path, help="voiga result files (.h5)")
    args = ap.parse_args(argv)
    missing = [p for p in args.results if not p.is_file()]
    if missing:
        print(f"bench.stages: no such result file: {missing[0]}", file=sys.stderr)
        return 2
    print(table(args.results))
    return 0


if __name__ == "__main__":
    sys.exit(main())
