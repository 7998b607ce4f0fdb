"""Command line: ``python -m post <subcommand>``.

Subcommands:
  plot-deformed  draw every body deformed, coloured by |u| (PNG)
  plot-contact   p_N and p_T along the contact (PNG)
  hertz          compare a hertz result with the analytic line contact
  sweep          run committed cases in parallel and write a summary (CSV, markdown)
  figures        validation figures and accuracy/cost tables from a sweep's results

Steps (--step): N >= 1 is the step number, N < 0 counts converged steps from
the end (-1: the last one), 0 is the reference configuration.
"""

from __future__ import annotations

import argparse
import sys


def _cmd_plot_deformed(args: argparse.Namespace) -> int:
    from .plot import plot_deformed
    from .reader import read_result

    result = read_result(args.result)
    if not result.steps and args.step != 0:
        print(f"python -m post: {args.result} has no converged step (status "
              f"{result.status!r}); use --step 0 for the reference configuration",
              file=sys.stderr)
        return 1
    try:
        path = plot_deformed(result, step=args.step, output=args.output, scale=args.scale,
                             length_unit=args.unit, reference=args.reference)
    except IndexError as err:
        print(f"python -m post: {err}", file=sys.stderr)
        return 1
    print(path)
    return 0


def _cmd_plot_contact(args: argparse.Namespace) -> int:
    from .contact import plot_contact
    from .reader import read_result

    result = read_result(args.result)
    if not result.steps or not result.steps[-1].contact:
        print(f"python -m post: {args.result} has no converged step with contact output",
              file=sys.stderr)
        return 1
    index = args.step if args.step < 0 else [s.step for s in result.steps].index(args.step)
    print(plot_contact(result, step=index, output=args.output, axis=args.axis))
    return 0


def _cmd_hertz(args: argparse.Namespace) -> int:
    from .contact import hertz_comparison
    from .reader import read_result

    h = hertz_comparison(read_result(args.result))
    print(f"P = {h.force:.6g}  a = {h.a:.6g} (fit {h.a_fit:.6g}, {h.a_error:+.2%})  "
          f"p0 = {h.p0:.6g} (fit {h.p0_fit:.6g}, {h.p0_error:+.2%}; max {h.p_max:.6g})  "
          f"L2(p/pmax) = {h.l2_error:.4g}")
    return 0


def _cmd_sweep(args: argparse.Namespace) -> int:
    import os
    from pathlib import Path

    from .sweep import default_binary, find_cases, previous_times, summarize, sweep, write_summary

    binary = Path(args.binary) if args.binary else default_binary()
    if not binary.exists():
        print(f"python -m post sweep: no voiga binary at {binary} (run `make build`)", file=sys.stderr)
        return 2
    runs = find_cases(Path(args.cases), Path(args.out), args.scenes, args.meshes, args.layouts)
    if not runs:
        print("python -m post sweep: no case matches", file=sys.stderr)
        return 2
    failed = 0
    if not args.summary_only:
        # the previous sweep's wall times order the runs longest first
        outcome = sweep(runs, binary, args.jobs or os.cpu_count() or 1, args.timeout, args.force,
                        progress=not args.no_progress,
                        times=previous_times(Path(args.out) / "summary.csv"))
        for label, (code, message) in sorted(outcome.items()):
            if code != 0:
                failed += 1
                print(f"{label}: exit {code}: {message}", file=sys.stderr)
    csv_path, md_path = write_summary(summarize(runs), Path(args.out))
    print(f"{len(runs)} cases, {failed} failed; summary in {csv_path} and {md_path}")
    return 1 if failed else 0


def _cmd_figures(args: argparse.Namespace) -> int:
    from pathlib import Path

    from .figures import make_all

    for path in make_all(Path(args.results), Path(args.out)):
        print(path)
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The argparse parser with one subparser per subcommand."""
    p = argparse.ArgumentParser(prog="python -m post", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)

    s = sub.add_parser("plot-deformed", help="bodies in the current configuration, coloured by |u|")
    s.add_argument("result", help="result file (.h5) written by voiga")
    s.add_argument("--step", type=int, default=-1,
                   help="step number (>= 1), -k for the k-th last, 0 = reference (default: -1)")
    s.add_argument("-o", "--output", default=None,
                   help="PNG file (default: <result>-deformed-<step>.png next to the result)")
    s.add_argument("--scale", type=float, default=1.0,
                   help="displacement magnification of the drawn shape (colours: true |u|)")
    s.add_argument("--unit", default="mm", help="length unit for the labels (default: mm)")
    s.add_argument("--reference", action="store_true", help="also draw the undeformed outlines")
    s.set_defaults(func=_cmd_plot_deformed)

    s = sub.add_parser("plot-contact", help="p_N and p_T along the contact")
    s.add_argument("result", help="result file (.h5) written by voiga")
    s.add_argument("--step", type=int, default=-1, help="step number (>= 1) or -k (default: -1)")
    s.add_argument("--axis", type=int, default=0, help="0: plot against x, 1: against y")
    s.add_argument("-o", "--output", default=None, help="PNG file")
    s.set_defaults(func=_cmd_plot_contact)

    s = sub.add_parser("sweep", help="run committed cases in parallel, summarize")
    s.add_argument("--cases", default="cases", help="folder of committed cases (default: cases)")
    s.add_argument("--out", default="results", help="work and summary folder (default: results)")
    s.add_argument("--scenes", nargs="*", help="scenes to run (default: all)")
    s.add_argument("--meshes", nargs="*", help="meshes to run, e.g. m1 m2 (default: all)")
    s.add_argument("--layouts", nargs="*", help="layouts to run, e.g. N2 NN2.2 (default: all)")
    s.add_argument("--jobs", type=int, default=0, help="parallel runs (default: number of cores)")
    s.add_argument("--timeout", type=float, default=3600.0, help="seconds per case (default 3600)")
    s.add_argument("--force", action="store_true", help="rerun up-to-date cases too")
    s.add_argument("--summary-only", action="store_true", help="only (re)write the summary")
    s.add_argument("--no-progress", action="store_true", help="no progress bar")
    s.add_argument("--binary", default=None, help="voiga binary (default: $VOIGA_BIN or build/install)")
    s.set_defaults(func=_cmd_sweep)

    s = sub.add_parser("figures", help="validation figures and tables from a sweep")
    s.add_argument("--results", default="results", help="the sweep's folder (default: results)")
    s.add_argument("--out", default="docs/validation", help="where to write (default: docs/validation)")
    s.set_defaults(func=_cmd_figures)

    s = sub.add_parser("hertz", help="hertz result against the analytic line contact")
    s.add_argument("result", help="result file (.h5) of a hertz case")
    s.set_defaults(func=_cmd_hertz)
    return p


def main(argv: list[str] | None = None) -> int:
    """Entry point."""
    args = build_parser().parse_args(argv)
    return int(args.func(args))


if __name__ == "__main__":
    sys.exit(main())
