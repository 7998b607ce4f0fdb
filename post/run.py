"""Solve a case and show it (``python -m post run``, ``make run``).

Runs ``voiga`` on the case, prints what the result says (:mod:`post.summary`),
writes the figures that fit the case (deformed bodies, load history, contact
tractions when it has contact, the Hertz overlay for the hertz scene) and the
ParaView files, and says where they are. With ``--out DIR`` the case is copied
into DIR (its geometry path rewritten to point at the original) so that the
result and every figure land there and nothing is written next to the input; a
result there from an earlier run is replaced (DIR is this tool's). In the case's
own folder an existing result is replaced only with ``overwrite``.
"""

from __future__ import annotations

import sys
from pathlib import Path

from .naming import output_path
from .reader import Result, read_result
from .solver import result_path, run_voiga, stage_case, voiga_binary
from .summary import summary_lines


def make_figures(result: Result, out: Path | None = None, vtk: bool = True) -> list[Path]:
    """Every figure (and the ParaView series) that fits ``result``; returns the paths."""
    from .contact import plot_contact
    from .history import plot_history, write_history_csv
    from .plot import plot_deformed

    written: list[Path] = []
    if not result.steps:
        return written
    last = result.steps[-1]
    written.append(plot_deformed(result, output=output_path(result.path, "deformed", last.step, out)))
    if last.fields:  # the case asked for stresses (&output): the von Mises stress too
        field = "von_mises" if all("von_mises" in f for f in last.fields.values()) else "stress_yy"
        if field == "von_mises" or all("stress" in f for f in last.fields.values()):
            written.append(plot_deformed(result, output=output_path(result.path, field, last.step, out),
                                         field=field))
    written += [write_history_csv(result, out=out), plot_history(result, out=out)]
    if result.steps[-1].contact:
        if result.dimension == 2:  # plot-contact draws a contact edge; a face has no profile figure yet
            written.append(plot_contact(result, out=out))
        if result.scene == "hertz":
            from .hertz import HertzError, hertz_comparison, hertz_figure
            try:
                written.append(hertz_figure(result, hertz_comparison(result), out))
            except HertzError:
                pass  # the summary says why
        if result.scene == "hertz3d":
            from .hertz import HertzError
            from .hertz3d import hertz3d_comparison, hertz3d_figure
            try:
                written.append(hertz3d_figure(result, hertz3d_comparison(result), out))
            except HertzError:
                pass  # the summary says why
    if vtk:
        from .paraview import write_vtk
        written.append(write_vtk(result, out=out))
    return written


def _identity(path: Path) -> tuple[int, int, int] | None:
    """(inode, size, modification time in ns) of a file, None when there is none: a
    run that wrote the file changes it (voiga replaces or extends it)."""
    try:
        st = path.stat()
    except FileNotFoundError:
        return None
    return st.st_ino, st.st_size, st.st_mtime_ns


def run_case(case: str | Path, out: str | Path | None = None, binary: str | Path | None = None,
             quiet: bool = False, figures: bool = True, vtk: bool = True, overwrite: bool = False) -> int:
    """Solve ``case`` (staged into ``out`` when given), print the summary and write
    the figures; returns voiga's exit code. The figures are made of whatever
    converged, also after a failed run (exit 3); when voiga refused the case or
    stopped otherwise (any other code), or wrote no result, nothing is printed or
    written but that."""
    case = Path(case)
    program = voiga_binary(binary)
    run = stage_case(case, Path(out)) if out is not None else case
    path = result_path(run)
    before = _identity(path)
    code = run_voiga(program, run, quiet, overwrite=overwrite or out is not None)
    if code not in (0, 3):
        # refused (2: bad input, an existing result, a wrong set-up), interrupted, no
        # memory, ...: voiga said why; a result file there is not this run's
        print(f"voiga exited with {code} (its message is above); no summary, no figures written",
              file=sys.stderr)
        return code
    if not path.is_file() or _identity(path) == before:
        print(f"voiga exited with {code} and wrote no result (no step converged"
              + (f"; the earlier {path} is unchanged" if path.is_file() else "")
              + "); no summary, no figures written", file=sys.stderr)
        return code or 1
    result = read_result(path)
    print()
    for line in summary_lines(result):
        print(line)
    if figures:
        written = make_figures(result, vtk=vtk)
        if written:
            print(f"\nresult: {path}")
            print("figures and files written:")
            for p in written:
                print(f"  {p}")
            pvd = [p for p in written if p.suffix == ".pvd"]
            if pvd:
                print(f"open in ParaView: paraview {pvd[0]}")
    return code
