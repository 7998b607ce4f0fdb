"""Command line: ``python -m post <subcommand>``.

Subcommands:
  run            solve a case with voiga, print what it found, write figures and ParaView files
  summary        what a result file says, in a few lines
  indicator      how well the mesh resolves each contact zone's edges, per pair and step
  plot-deformed  draw every body deformed, coloured by |u|, a component or a stress (PNG;
                 a solid: a 3D view of its boundary)
  plot-contact   p_N and p_T along the contact (PNG)
  history        reactions and contact forces against the load time (CSV and PNG)
  vtk            ParaView time series (.pvd + .vtu)
  hertz          a cylinder on a rigid flat against analytic Hertz in the reference
                 configuration (and the figure; several results: one overlay)
  hertz3d        a sphere on a rigid plane or a block (3D result) against Hertz's point contact:
                 pressure over the contact disc, a and p0, the subsurface shear
  ironing        an ironing run's force history (2D: the die's Px, Py; 3D: the contact
                 force's F_x, F_z) and its oscillation over the sliding phase (and a figure)
  cattaneo       a cylinder pressed and sheared against Cattaneo-Mindlin's stick zone;
                 --halfplane: the incremental half-plane reference for a rigid flat
  cattaneo3d     a sphere pressed and sheared (3D result) against Cattaneo-Mindlin's
                 circular stick zone and traction
  study          a parameter study from a study file (docs/studies.md): derived cases
                 run on Dask, one table (CSV, markdown, Parquet) and figures
  sweep          the committed cases as a study without changes (the same engine)
  figures        validation figures and accuracy/cost tables from a sweep's results

Steps (--step): N >= 1 is the step number, N < 0 counts converged steps from
the end (-1: the last one), 0 is the reference configuration.
Files are named <result stem>-<what>[-<step>].<ext> and written next to the result
file, or into --out.

A result whose run has not converged (running, failed, interrupted) is read as
far as it goes, with a note on stderr naming its status and the step shown;
`hertz`, which compares the final load, refuses it unless given --partial. A
file that is not a readable result is refused in one line (exit code 2).
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .reader import Result
    from .study import Study


def _scale(text: str) -> float | str:
    """``--scale``: a positive number or ``auto``."""
    if text == "auto":
        return text
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is neither a number nor 'auto'") from None
    if value <= 0:
        raise argparse.ArgumentTypeError("the scale must be positive")
    return value


def _read(path, command: str):
    """The result file ``path``, with a note on stderr when its run has not
    converged (the steps shown are those written so far)."""
    from .reader import read_result

    result = read_result(path)
    if not result.converged:
        last = f"the last is step {result.steps[-1].step}" if result.steps else "none yet"
        print(f"python -m post {command}: note: {path}: status {result.status!r}: "
              f"{len(result.steps)} of {result.n_steps_planned} planned steps written ({last})",
              file=sys.stderr)
    return result


def _result(args: argparse.Namespace):
    """The result file of the command (``_read``)."""
    return _read(args.result, args.command)


def _cmd_run(args: argparse.Namespace) -> int:
    from .run import run_case

    if args.adapt:
        return _run_adapt(args)

    return run_case(args.case, out=args.out, binary=args.binary, quiet=args.quiet,
                    figures=not args.no_figures, vtk=not args.no_vtk, overwrite=args.overwrite)


def _run_adapt(args: argparse.Namespace) -> int:
    """``post run CASE --adapt``: the solve-estimate-refine loop (post.adapt), then the
    summary and figures of the last result."""
    import time

    from .adapt import ACCEPT, AdaptError, accepted, adapt_case, parse_target
    from .run import make_figures
    from .summary import summary_lines

    try:
        target = parse_target(args.target)
    except ValueError as err:
        print(f"python -m post run: {err}", file=sys.stderr)
        return 2
    start = time.monotonic()
    try:
        loop = adapt_case(args.case, args.out, target, args.cycles, args.binary, quiet=True,
                          overwrite=args.overwrite)
    except AdaptError as err:
        print(f"python -m post run --adapt: {err}", file=sys.stderr)
        return 2
    cycles = loop.cycles
    if loop.result is None:
        print(f"voiga exited with {loop.code} (its message is above); no summary, no figures written"
              + (f"; the last result is {cycles[-1].result}" if cycles else ""), file=sys.stderr)
        return loop.code
    last = cycles[-1]
    total = time.monotonic() - start
    met = "met" if last.estimate <= accepted(target) else "not met"
    print(f"target {target:.2%} {met} (largest estimate {last.estimate:.3%}, accepted up to {ACCEPT:g} "
          f"times the target) after {len(cycles) - 1} refinement(s): {last.n_dofs} DOFs; "
          f"the loop took {total:.3g} s, {total / max(last.seconds, 1e-9):.3g} times the last solve "
          f"({last.seconds:.3g} s)")
    from .reader import read_result

    result = read_result(loop.result)
    print()
    for line in summary_lines(result):
        print(line)
    if not args.no_figures:
        for p in make_figures(result, vtk=not args.no_vtk):
            print(f"  {p}")
    print(f"result: {loop.result} (cycle {len(cycles) - 1}'s, a copy of {last.result})")
    return loop.code


def _cmd_summary(args: argparse.Namespace) -> int:
    from .summary import summary_lines

    for line in summary_lines(_result(args)):
        print(line)
    return 0


def _cmd_indicator(args: argparse.Namespace) -> int:
    from .indicator import face_lines, format_zone, measure

    result = _result(args)
    if result.dimension != 2:
        # a solid's faces: voiga's estimate per pair (its largest step), from the file
        lines = face_lines(result)
        for line in lines:
            print(line.strip())
        if not lines:
            print(f"python -m post indicator: {args.result}: no contact accuracy in the file (no contact, "
                  "or written before voiga measured it)", file=sys.stderr)
        return 0 if lines else 2
    zones = measure(result)
    if not zones:
        print(f"python -m post indicator: {args.result}: no contact at any converged step",
              file=sys.stderr)
        return 2
    for m in zones:
        print(format_zone(m))
    return 0


def _cmd_history(args: argparse.Namespace) -> int:
    from .history import plot_history, write_history_csv

    result = _result(args)
    if not result.steps:
        print(f"python -m post: {args.result} has no converged step", file=sys.stderr)
        return 1
    print(write_history_csv(result, out=args.out))
    print(plot_history(result, out=args.out))
    return 0


def _cmd_vtk(args: argparse.Namespace) -> int:
    from .paraview import write_vtk

    print(write_vtk(_result(args), out=args.out, samples=args.samples))
    return 0


def _cmd_plot_deformed(args: argparse.Namespace) -> int:
    from .naming import output_path
    from .plot import figure_name, plot_deformed

    result = _result(args)
    if not result.steps and args.step != 0:
        print(f"python -m post: {args.result} has no converged step (status "
              f"{result.status!r}); use --step 0 for the reference configuration",
              file=sys.stderr)
        return 1
    try:
        s = result.select_step(args.step)
        output = args.output or output_path(result.path, figure_name(args.field),
                                            0 if s is None else s.step, args.out)
        path = plot_deformed(result, step=args.step, output=output, scale=args.scale,
                             length_unit=args.unit, reference=args.reference, field=args.field,
                             colour_scale=args.colour_scale)
    except IndexError as err:
        print(f"python -m post: {err}", file=sys.stderr)
        return 1
    print(path)
    return 0


def _cmd_plot_contact(args: argparse.Namespace) -> int:
    from .contact import plot_contact

    result = _result(args)
    if not result.steps or not result.steps[-1].contact:
        print(f"python -m post: {args.result} has no converged step with contact output",
              file=sys.stderr)
        return 1
    if args.step == 0:
        print("python -m post plot-contact: step 0 is the reference configuration, which has no "
              "contact output; give a step >= 1 or -1 for the last", file=sys.stderr)
        return 1
    try:
        chosen = result.select_step(args.step)
    except IndexError as err:
        print(f"python -m post plot-contact: {err}", file=sys.stderr)
        return 1
    index = result.steps.index(chosen)
    print(plot_contact(result, step=index, output=args.output, axis=args.axis, out=args.out))
    return 0


def _cmd_hertz(args: argparse.Namespace) -> int:
    from .hertz import HertzError, hertz_comparison, hertz_figure, hertz_report, plot_hertz

    done, code = [], 0
    for path in args.result:
        try:
            result = _read(path, "hertz")
            if not result.steps:  # as every subcommand: no converged step is exit 1
                print(f"python -m post hertz: {path} has no converged step (status "
                      f"{result.status!r})", file=sys.stderr)
                code = max(code, 1)
                continue
            if not result.converged and not args.partial:
                print(f"python -m post hertz: {path}: the run has not converged (status "
                      f"{result.status!r}): the comparison is of the final load; give --partial to "
                      f"compare step {result.steps[-1].step} anyway", file=sys.stderr)
                code = 2
                continue
            h = hertz_comparison(result, step=args.step, radius=args.radius,
                                 configuration=args.configuration, reference=args.reference)
        except (HertzError, OSError, KeyError, ValueError) as err:
            print(f"python -m post hertz: {path}: {err}", file=sys.stderr)
            code = 2
            continue
        print("\n".join(hertz_report(h)))
        done.append((result, h))
    if done and not args.no_figure:
        from pathlib import Path

        first, h0 = done[0]
        if len(done) == 1:
            print(hertz_figure(first, h0, args.out, args.output))
        else:
            output = Path(args.output or Path(args.out or first.path.parent) / "hertz-profiles.png")
            output.parent.mkdir(parents=True, exist_ok=True)
            print(plot_hertz([h for _, h in done], output, units=first.units))
    return code


def _read_stepped(path: str, command: str) -> Result | None:
    """The result at ``path`` (:func:`_read`), or None after saying on stderr that it has
    no converged step."""
    result = _read(path, command)
    if not result.steps:
        print(f"python -m post {command}: {path} has no converged step (status {result.status!r})",
              file=sys.stderr)
        return None
    return result


def _cmd_hertz3d(args: argparse.Namespace) -> int:
    from .hertz import HertzError
    from .hertz3d import hertz3d_comparison, hertz3d_figure, hertz3d_report

    try:
        result = _read_stepped(args.result, "hertz3d")
        if result is None:
            return 1
        if not result.converged and not args.partial:
            print(f"python -m post hertz3d: {args.result}: the run has not converged (status "
                  f"{result.status!r}); give --partial to compare step {result.steps[-1].step} anyway",
                  file=sys.stderr)
            return 2
        h = hertz3d_comparison(result, step=args.step, radius=args.radius,
                               youngs_modulus=args.youngs_modulus, poisson_ratio=args.poisson_ratio,
                               symmetry=args.symmetry, master_youngs_modulus=args.master_youngs_modulus,
                               master_poisson_ratio=args.master_poisson_ratio)
    except (HertzError, OSError, KeyError, ValueError) as err:
        print(f"python -m post hertz3d: {args.result}: {err}", file=sys.stderr)
        return 2
    print("\n".join(hertz3d_report(h)))
    if not args.no_figure:
        print(hertz3d_figure(result, h, args.out, args.output))
    return 0


def _cmd_cattaneo3d(args: argparse.Namespace) -> int:
    from .cattaneo3d import cattaneo3d_comparison, cattaneo3d_report
    from .hertz import HertzError

    try:
        result = _read_stepped(args.result, "cattaneo3d")
        if result is None:
            return 1
        cm = cattaneo3d_comparison(result, step=args.step, friction=args.friction)
    except (HertzError, OSError, KeyError, ValueError) as err:
        print(f"python -m post cattaneo3d: {args.result}: {err}", file=sys.stderr)
        return 2
    print("\n".join(cattaneo3d_report(cm)))
    return 0


def _cmd_ironing(args: argparse.Namespace) -> int:
    import json

    from .ironing3d import IroningError, ironing_figure, ironing_forces, ironing_report

    try:
        result = _read(args.result, "ironing")
        h = ironing_forces(result, pair=args.pair)
    except (IroningError, OSError, KeyError, ValueError) as err:
        print(f"python -m post ironing: {args.result}: {err}", file=sys.stderr)
        return 2
    print("\n".join(ironing_report(h)))
    if args.json:
        print(json.dumps({"n_dofs": h.n_dofs, "wall_time": h.wall_time, "newton": h.newton,
                          "steps": len(h.steps), **h.measures}))
    if not args.no_figure:
        print(ironing_figure(result, h, args.out, args.output))
    return 0


def _cmd_cattaneo(args: argparse.Namespace) -> int:
    import json

    from .cattaneo import CattaneoError, cattaneo_comparison

    if args.halfplane:
        from .stickslip import halfplane_stick_slip

        if not (-1.0 < args.poisson_ratio < 0.5 and args.friction > 0 and 0 < args.ratio < 1):
            print("python -m post cattaneo: --halfplane needs -1 < --poisson-ratio < 0.5, "
                  "--friction > 0 and 0 < --ratio < 1", file=sys.stderr)
            return 2
        h = halfplane_stick_slip(args.poisson_ratio, args.friction, args.ratio)
        print(f"half-plane pressed by a rigid flat with friction, then sheared (nu = {h.poisson_ratio:g}, "
              f"mu = {h.friction:g}, beta = {h.beta:.4f}):")
        print(f"  after the press: stick traction up to {h.press_stick_traction:.4f} mu p0")
        print(f"  at Q/(mu P) = {h.ratio:.3f}: stick zone c/a = {h.stick_half_width:.4f} "
              f"(Cattaneo-Mindlin {h.cattaneo_half_width:.4f}); traction {100 * h.l2_from_cattaneo:.2f} % "
              f"(L2) from Cattaneo-Mindlin's")
        return 0
    if not args.result:
        print("python -m post cattaneo: give a result file, or --halfplane", file=sys.stderr)
        return 2
    code, rows = 0, []
    for path in args.result:
        try:
            result = _read(path, "cattaneo")
            if not result.steps:
                print(f"python -m post cattaneo: {path} has no converged step (status "
                      f"{result.status!r})", file=sys.stderr)
                code = max(code, 1)
                continue
            cmp = cattaneo_comparison(result, step=args.step)
        except (CattaneoError, OSError, KeyError, ValueError) as err:
            print(f"python -m post cattaneo: {path}: {err}", file=sys.stderr)
            code = 2
            continue
        if args.json:
            rows.append({k: getattr(cmp, k) for k in ("source", "step", "time", "friction", "force",
                                                      "tangential", "ratio", "a", "p0", "c_analytic",
                                                      "c_simulated", "l2", "stick_traction")})
        else:
            print("\n".join(cmp.report()))
    if rows:
        print(json.dumps(rows, indent=1))
    return code


def _positive(text: str) -> float:
    """``--radius``: a positive number."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"{text!r}: must be positive and finite")
    return value


def _at_least_one(text: str) -> int:
    """``--repeats``: a whole number, at least 1 and at most ``MAX_REPEATS``."""
    from .cost import MAX_REPEATS

    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if not 1 <= value <= MAX_REPEATS:
        raise argparse.ArgumentTypeError(f"{text!r}: must be at least 1 and at most {MAX_REPEATS}")
    return value


def _run_study(study: Study, args: argparse.Namespace, prog: str) -> int:
    """Run ``study`` as the command line asks (shared by ``study`` and ``sweep``):
    derive the cases, solve those not up to date on Dask, write the table (and the
    figures); 2 for bad input, 1 if a case failed, else 0."""
    from pathlib import Path

    from .solver import InputError, voiga_binary
    from .study import StudyError
    from .sweep import previous_times, summarize, write_summary

    problem = engine_option_problem(args)
    if problem:
        print(f"{prog}: {problem}", file=sys.stderr)
        return 2
    try:
        from .engine import connect, run_all
        if not (args.list or args.summary_only):
            import dask  # noqa: F401  (imported by the engine when it connects)
            import distributed  # noqa: F401
    except ModuleNotFoundError as err:
        print(f"{prog}: no module {err.name!r}: a study runs its cases on Dask; install the study "
              "extra: pip install 'voiga[study]' (from a checkout: pip install '.[study]')",
              file=sys.stderr)
        return 2
    try:
        binary = voiga_binary(args.binary)
    except InputError as err:
        if not (args.list or args.summary_only):
            print(f"{prog}: {err}", file=sys.stderr)
            return 2
        binary = Path(args.binary or "voiga")
    try:
        runs = study.runs()
    except StudyError as err:
        print(f"{prog}: {err}", file=sys.stderr)
        return 2
    if args.list:
        for run in runs:
            print(run.work)
        return 0
    if study.out.exists() and not study.out.is_dir():
        print(f"{prog}: {study.out} is not a folder (the study's cases, results and table go there)",
              file=sys.stderr)
        return 2
    failures: dict[str, tuple[int, str]] = {}
    if not args.summary_only:
        try:
            # the previous summary's wall times order the runs longest first
            with connect(args.scheduler, args.jobs) as client:
                outcome = run_all(runs, binary, client, args.timeout or study.timeout, args.force,
                                  progress=not args.no_progress,
                                  times=previous_times(study.out / "summary.csv"),
                                  shared=not args.no_shared_fs, policy=study.policy())
        except OSError as err:
            print(f"{prog}: {err}", file=sys.stderr)
            return 2
        failures = {label: (o.code, o.message) for label, o in outcome.items() if o.code != 0}
        for label, (code, message) in sorted(failures.items()):
            print(f"{label}: exit {code}: {message}", file=sys.stderr)
    rows = summarize(runs, study.measures, failures)
    csv_path, md_path = write_summary(rows, study.out)
    if study.figures and not getattr(args, "no_figures", False):
        from .figures import study_figures

        made = study_figures(rows, study.parameters(), study.out / "figures")
        if made:
            print(f"{len(made)} figures in {study.out / 'figures'}")
    print(f"{len(runs)} cases, {len(failures)} failed; summary in {csv_path} and {md_path}")
    return 1 if failures else 0


def max_jobs() -> int:
    """Most workers of a local cluster: 8 per core (each runs one voiga)."""
    import os

    return 8 * (os.cpu_count() or 1)


def engine_option_problem(args: argparse.Namespace) -> str | None:
    """Why the options ``study`` and ``sweep`` share cannot be used (None when they
    can): a number of workers out of range, a time limit that is not a positive
    finite number of seconds."""
    from .study import timeout_problem

    if not 0 <= args.jobs <= max_jobs():
        return (f"--jobs must be 0 (one worker per core) or 1 to {max_jobs()} "
                f"(8 per core), not {args.jobs}")
    if args.timeout:      # (0: the study file's)
        problem = timeout_problem(args.timeout)
        if problem:
            return f"--timeout {problem}"
    return None


def _cmd_study(args: argparse.Namespace) -> int:
    from pathlib import Path

    from .study import StudyError, load_study

    prog = "python -m post study"
    try:
        study = load_study(Path(args.study), Path(args.out) if args.out else None)
    except StudyError as err:
        print(f"{prog}: {err}", file=sys.stderr)
        return 2
    if args.repeats is not None:
        study.repeats = args.repeats
    for key in ("scenes", "meshes", "layouts"):
        if getattr(args, key) is not None:
            if study.base is not None:
                print(f"{prog}: --{key} selects committed cases; {args.study} has a base case",
                      file=sys.stderr)
                return 2
            setattr(study, key, getattr(args, key))
    return _run_study(study, args, prog)


def _cmd_sweep(args: argparse.Namespace) -> int:
    from pathlib import Path

    from .study import Study

    study = Study(out=Path(args.out), cases=Path(args.cases), scenes=args.scenes, meshes=args.meshes,
                  layouts=args.layouts, figures=False, repeats=args.repeats or 1)
    return _run_study(study, args, "python -m post sweep")


def _cmd_figures(args: argparse.Namespace) -> int:
    from pathlib import Path

    from .figures import make_all

    if args.jobs is not None and not 1 <= args.jobs <= max_jobs():
        print(f"python -m post figures: --jobs must be at least 1 and at most {max_jobs()} (8 per core), "
              f"not {args.jobs}", file=sys.stderr)
        return 2
    for path in make_all(Path(args.results), Path(args.out), args.jobs):
        print(path)
    return 0


def _engine_options(s: argparse.ArgumentParser, timeout_default: float) -> None:
    """The options ``study`` and ``sweep`` share."""
    s.add_argument("--scenes", nargs="*", help="scenes to run (default: all)")
    s.add_argument("--meshes", nargs="*", help="meshes to run, e.g. m1 m2 (default: all)")
    s.add_argument("--layouts", nargs="*", help="layouts to run, e.g. N2 NN2.2 (default: all)")
    s.add_argument("--jobs", type=int, default=0,
                   help="workers of the local cluster (default: number of cores)")
    s.add_argument("--scheduler", default=None,
                   help="address of a running Dask scheduler, e.g. tcp://127.0.0.1:8786 "
                        "(default: a local cluster)")
    s.add_argument("--no-shared-fs", action="store_true",
                   help="the workers do not see --out: results come back through the scheduler")
    s.add_argument("--timeout", type=float, default=timeout_default,
                   help="seconds per case (default: " + ("the study file's, else 3600)"
                                                          if not timeout_default else "3600)"))
    s.add_argument("--force", action="store_true", help="rerun up-to-date cases too")
    s.add_argument("--repeats", type=_at_least_one, default=None,
                   help="runs of each short case (under 3 CPU seconds) to time it: median and range "
                        "of their CPU and wall times in the table (default: the study file's, else 1)")
    s.add_argument("--summary-only", action="store_true", help="only (re)write the summary")
    s.add_argument("--list", action="store_true", help="only list the cases (their case files)")
    s.add_argument("--no-progress", action="store_true", help="no progress bar")
    s.add_argument("--binary", default=None,
                   help="voiga program (default: $VOIGA_BIN, voiga on the PATH, or build/install)")


def build_parser() -> argparse.ArgumentParser:
    """The argparse parser with one subparser per subcommand."""
    p = argparse.ArgumentParser(prog="python -m post", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)

    s = sub.add_parser("run", help="solve a case, print what it found, write its figures")
    s.add_argument("case", help="case namelist (.nml)")
    s.add_argument("--out", default=None,
                   help="folder for the run: the case is copied there (geometry path rewritten) "
                        "and its result and figures land there (default: the case's own folder)")
    s.add_argument("--binary", default=None,
                   help="voiga program (default: $VOIGA_BIN, voiga on the PATH, or build/install)")
    s.add_argument("--quiet", action="store_true", help="no per-step lines from voiga")
    s.add_argument("--no-figures", action="store_true", help="only solve and summarize")
    s.add_argument("--no-vtk", action="store_true", help="no ParaView files")
    s.add_argument("--overwrite", action="store_true",
                   help="replace an existing result in the case's own folder (with --adapt also an "
                        "earlier loop's <case>-zone<k> folders; with --out they are always "
                        "replaced: the folder is this tool's)")
    s.add_argument("--adapt", action="store_true",
                   help="solve, estimate the contact-zone edge error, refine the zone and solve "
                        "again until the estimate is within 0.7 times --target; the last result lands where a "
                        "plain run puts it (docs/howto.md)")
    s.add_argument("--target", default="0.2%", help="with --adapt: the edge error to reach (default 0.2%%); "
                                                    "the loop stops at an estimate of 0.7 times it")
    s.add_argument("--cycles", type=int, default=3, help="with --adapt: at most this many "
                                                         "refinements (default 3)")
    s.set_defaults(func=_cmd_run)

    s = sub.add_parser("summary", help="what a result file says, in a few lines")
    s.add_argument("result", help="result file (.h5) written by voiga")
    s.set_defaults(func=_cmd_summary)

    s = sub.add_parser("indicator", help="contact-zone accuracy per pair, step and zone (docs/contact-accuracy.md)")
    s.add_argument("result", help="result file (.h5) written by voiga")
    s.set_defaults(func=_cmd_indicator)

    s = sub.add_parser("history", help="reactions and contact forces vs load time (CSV, PNG)")
    s.add_argument("result", help="result file (.h5) written by voiga")
    s.add_argument("--out", default=None, help="folder (default: next to the result)")
    s.set_defaults(func=_cmd_history)

    s = sub.add_parser("vtk", help="ParaView time series (.pvd + .vtu)")
    s.add_argument("result", help="result file (.h5) written by voiga")
    s.add_argument("--out", default=None, help="folder (default: next to the result)")
    s.add_argument("--samples", type=int, default=2,
                   help="least subdivisions of each element per direction (default 2; at "
                        "least 48 per body and direction, 16 for a solid)")
    s.set_defaults(func=_cmd_vtk)

    s = sub.add_parser("plot-deformed", help="bodies in the current configuration, coloured by |u|, "
                                             "a displacement component or a stress or strain")
    s.add_argument("result", help="result file (.h5) written by voiga")
    s.add_argument("--step", type=int, default=-1,
                   help="step number (>= 1), -k for the k-th last, 0 = reference (default: -1)")
    s.add_argument("-o", "--output", default=None,
                   help="PNG file (default: <result>-deformed-<step>.png next to the result)")
    s.add_argument("--out", default=None, help="folder for the default file name")
    s.add_argument("--scale", type=_scale, default="auto",
                   help="displacement magnification of the drawn shape (colours: true |u|); "
                        "default auto: magnified when the displacements are small, the title "
                        "says by how much")
    s.add_argument("--unit", default=None,
                   help="length unit for the labels (default: the result file's units)")
    s.add_argument("--reference", action="store_true", help="also draw the undeformed outlines")
    s.add_argument("--field", default="u", metavar="NAME",
                   help="the colouring: u (|u|, default), ux, uy, von_mises, stress_xx, stress_yy, "
                        "stress_zz, stress_xy, strain_xx, ... (stress and strain: steps with &output "
                        "fields; a solid's also uz and the yz, xz components); files "
                        "<result>-<NAME>-<step>.png (u: -deformed-)")
    s.add_argument("--colour-scale", choices=("body", "shared"), default=None,
                   help="a colour scale per body or one shared by all bodies (default: per body "
                        "for u, ux, uy; shared for a stress or strain)")
    s.set_defaults(func=_cmd_plot_deformed)

    s = sub.add_parser("plot-contact", help="p_N and p_T along the contact")
    s.add_argument("result", help="result file (.h5) written by voiga")
    s.add_argument("--step", type=int, default=-1, help="step number (>= 1) or -k (default: -1)")
    s.add_argument("--axis", type=int, default=0, help="0: plot against x, 1: against y")
    s.add_argument("-o", "--output", default=None, help="PNG file")
    s.add_argument("--out", default=None, help="folder for the default file name")
    s.set_defaults(func=_cmd_plot_contact)

    s = sub.add_parser("study", help="a parameter study from a study file (docs/studies.md)")
    s.add_argument("study", help="study file (TOML)")
    s.add_argument("--out", default=None,
                   help="folder of the cases, results, table and figures (default: the file's "
                        "out, else results/<study name>)")
    _engine_options(s, timeout_default=0.0)
    s.add_argument("--no-figures", action="store_true", help="no figures")
    s.set_defaults(func=_cmd_study)

    s = sub.add_parser("sweep", help="run committed cases in parallel, summarize (a study without changes)")
    s.add_argument("--cases", default="cases", help="folder of committed cases (default: cases)")
    s.add_argument("--out", default="results", help="work and summary folder (default: results)")
    _engine_options(s, timeout_default=3600.0)
    s.set_defaults(func=_cmd_sweep)

    s = sub.add_parser("figures", help="validation figures and tables from a sweep")
    s.add_argument("--results", default="results", help="the sweep's folder (default: results)")
    s.add_argument("--out", default="docs/validation", help="where to write (default: docs/validation)")
    s.add_argument("--jobs", type=int, default=None,
                   help="processes drawing the figures (default: one per core)")
    s.set_defaults(func=_cmd_figures)

    s = sub.add_parser("hertz", help="cylinder on a rigid flat against analytic Hertz "
                                     "(reference configuration, nominal pressure)")
    s.add_argument("result", nargs="+",
                   help="result file(s) (.h5); several: one figure with every profile")
    s.add_argument("--step", type=int, default=-1,
                   help="step number (>= 1) or -k for the k-th last (default: -1)")
    s.add_argument("--radius", type=_positive, default=None,
                   help="cylinder radius (default: the circle through the slave edge's "
                        "reference points near the contact; 1 for the committed hertz scene)")
    s.add_argument("--reference", choices=("hertz", "circle"), default="hertz",
                   help="hertz (default): Hertz's parabolic profile; circle: the half-plane "
                        "solution for the exact circle (differs by O(a^2/R^2))")
    s.add_argument("--configuration", choices=("reference", "current"), default="reference",
                   help="reference (default): nominal pressure at reference positions, the "
                        "measure of the theory; current: per current length at current "
                        "positions, for comparison only")
    s.add_argument("-o", "--output", default=None, help="PNG file of the figure")
    s.add_argument("--out", default=None,
                   help="folder for the figure (default: next to the (first) result); one "
                        "file: <result>-hertz-<step>.png, several: hertz-profiles.png")
    s.add_argument("--no-figure", action="store_true", help="only print the comparison")
    s.add_argument("--partial", action="store_true",
                   help="compare the last written step of a run that has not converged")
    s.set_defaults(func=_cmd_hertz)

    s = sub.add_parser("hertz3d", help="a sphere on a rigid plane or a block (3D result) against Hertz's point "
                                       "contact (reference configuration, nominal pressure)")
    s.add_argument("result", help="result file (.h5) of dimension 3 (the scene of pre hertz3d)")
    s.add_argument("--step", type=int, default=-1,
                   help="step number (>= 1) or -k for the k-th last (default: -1)")
    s.add_argument("--radius", type=_positive, default=None,
                   help="sphere radius (default: the sphere through the slave face's reference "
                        "points near the contact)")
    s.add_argument("--youngs-modulus", type=_positive, default=None,
                   help="E (default: the slave body's, from the result)")
    s.add_argument("--poisson-ratio", type=float, default=None,
                   help="nu (default: the slave body's, from the result)")
    s.add_argument("--symmetry", type=int, choices=(1, 2, 4), default=None,
                   help="P over the pair's normal force: 4 a quarter model, 2 a half, 1 the whole "
                        "sphere (default: from the active points' azimuths around the axis)")
    s.add_argument("--master-youngs-modulus", type=_positive, default=None,
                   help="a body master's E (default: its own, from the result)")
    s.add_argument("--master-poisson-ratio", type=float, default=None,
                   help="a body master's nu (default: its own, from the result)")
    s.add_argument("-o", "--output", default=None, help="PNG file of the figure")
    s.add_argument("--out", default=None,
                   help="folder for the figure <result>-hertz3d-<step>.png (default: next to the result)")
    s.add_argument("--no-figure", action="store_true", help="only print the comparison")
    s.add_argument("--partial", action="store_true",
                   help="compare the last written step of a run that has not converged")
    s.set_defaults(func=_cmd_hertz3d)

    s = sub.add_parser("cattaneo3d", help="a sphere pressed and sheared (3D result) against Cattaneo-Mindlin: "
                                          "stick radius, traction along Q (docs/cattaneo3d.md)")
    s.add_argument("result", help="result file (.h5) of dimension 3 (the scene of pre cattaneo3d)")
    s.add_argument("--step", type=int, default=-1,
                   help="step number (>= 1) or -k for the k-th last (default: -1)")
    s.add_argument("--friction", type=_positive, default=None,
                   help="mu (default: the pair's at that step, from the result)")
    s.set_defaults(func=_cmd_cattaneo3d)

    s = sub.add_parser("ironing", help="an ironing run's force history and its oscillation over the "
                                       "sliding phase (2D: die reactions; 3D: contact force)")
    s.add_argument("result", help="result file (.h5): cases/ironing* (2D) or pre ironing3d (3D)")
    s.add_argument("--pair", type=int, default=1, help="3D: the contact pair (default 1)")
    s.add_argument("--json", action="store_true", help="also print the measures as one JSON line")
    s.add_argument("-o", "--output", default=None, help="PNG file of the figure")
    s.add_argument("--out", default=None,
                   help="folder for the figure <result>-ironing.png (default: next to the result)")
    s.add_argument("--no-figure", action="store_true", help="only print the measures")
    s.set_defaults(func=_cmd_ironing)

    s = sub.add_parser("cattaneo", help="a cylinder pressed and sheared against Cattaneo-Mindlin's "
                                        "stick zone (reference configuration, nominal traction)")
    s.add_argument("result", nargs="*", help="result file(s) (.h5)")
    s.add_argument("--step", type=int, default=-1,
                   help="step number (>= 1) or -k for the k-th last (default: -1)")
    s.add_argument("--json", action="store_true", help="the measures as JSON")
    s.add_argument("--halfplane", action="store_true",
                   help="instead: the incremental half-plane solution for a rigid flat pressed "
                        "with friction then sheared, against Cattaneo-Mindlin (post/stickslip.py)")
    s.add_argument("--poisson-ratio", type=float, default=0.49, help="--halfplane: nu (default 0.49)")
    s.add_argument("--friction", type=float, default=0.3, help="--halfplane: mu (default 0.3)")
    s.add_argument("--ratio", type=float, default=0.5, help="--halfplane: Q/(mu P) (default 0.5)")
    s.set_defaults(func=_cmd_cattaneo)
    return p


def main(argv: list[str] | None = None) -> int:
    """Entry point. Bad input (a missing or unreadable file, a case the tools cannot
    use) gives one line on stderr naming the cause and exit code 2."""
    from .solver import InputError

    args = build_parser().parse_args(argv)

    def note(message, category, filename, lineno, file=None, line=None) -> None:  # noqa: ANN001
        """A warning (e.g. a half-written step skipped) as one line on stderr."""
        print(f"python -m post {args.command}: note: {message}", file=sys.stderr)

    warnings.showwarning = note
    try:
        return int(args.func(args))
    except (InputError, FileNotFoundError) as err:
        print(f"python -m post {args.command}: {err}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # whoever read the output has stopped (`... | head`): nothing to say; what was
        # written stays; stdout to /dev/null so that the exit's flush does not fail too
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except OSError as err:  # h5py: not an HDF5 file, truncated, ...
        print(f"python -m post {args.command}: {getattr(args, 'result', '')}: {err}",
              file=sys.stderr)
        return 2
    except (KeyError, ValueError) as err:  # BadResultError: a file that is no readable result
        print(f"python -m post {args.command}: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
