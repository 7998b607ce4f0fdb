"""Command line: ``python -m post <subcommand>``.

Subcommands:
  plot-deformed  draw every body deformed, coloured by |u| (PNG)
  plot-contact   p_N and p_T along the contact (PNG)
  hertz          compare a hertz result with the analytic line contact

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
