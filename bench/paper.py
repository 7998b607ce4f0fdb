"""``python3 -m bench.paper OUT``: time ``make paper`` by phase, and check its measures.

Runs ``make paper PAPER_OUT=OUT`` in a source tree (default: this repository), stamps
every line it prints (tqdm's carriage returns count as line ends) with the seconds since
the start, writes them to ``OUT.log`` and prints the wall time of each phase: the build
check, the study's runs (until its bar reaches the last case), the summary and the
figures; then the runs' work (the sum of their wall times, ``summary.csv``) and its
stages. ``--against OLD`` compares every column of ``OUT/summary.csv`` but the times with
``OLD/summary.csv`` (another run's folder) and counts the cells that differ (``--rtol
1e-9``: numbers by more than that, relative): the paper's measures must not move when
only the speed changes.

Time old against new by alternating them (``--tree`` names another checkout, e.g. a
``git worktree`` of the old commit): the machine's speed drifts, and only runs made side
by side compare. The figures go to the tree's ``docs/validation`` as ``make paper`` writes
them (``git checkout docs/validation`` to drop them).
"""
from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from post.cost import COST_COLUMNS
from post.figures import read_summary

REPO = Path(__file__).resolve().parents[1]

TIME_COLUMNS = (*COST_COLUMNS, "assembly_s", "contact_s", "factorization_s", "solve_s", "output_s", "time_norm")
"""Columns of ``summary.csv`` that are times (or scaled by them, or counted by them, as
the repeats): left out of ``--against``."""

STAGE_COLUMNS = ("assembly_s", "contact_s", "factorization_s", "solve_s", "output_s")

_BAR = re.compile(r"study:\s+100%.*?(\d+)/(\d+)")
_DONE = re.compile(r"^\d+ cases, \d+ failed; summary in ")


@dataclass
class Phases:
    """Seconds from the start of ``make paper`` at which each phase ended."""

    build: float
    """The study started drawing its bar (``make``'s build check and the study's set-up before it)."""
    runs: float
    """The bar at its last case (= ``build`` when no case ran)."""
    summary: float
    """The study's closing line (``N cases, M failed; summary in ...``)."""
    end: float
    """``make paper`` exited (the figures are written)."""


def stamped_lines(cmd: list[str], cwd: Path, log: Path) -> tuple[list[tuple[float, str]], int, float]:
    """Run ``cmd``; every line of its merged output with its time since the start, also
    written to ``log``; its exit code and the seconds until it exited."""
    start = time.perf_counter()
    lines: list[tuple[float, str]] = []
    proc = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    assert proc.stdout is not None
    buf = b""
    with log.open("w") as out:
        while chunk := proc.stdout.read(1):
            if chunk in (b"\n", b"\r"):
                stamp = (time.perf_counter() - start, buf.decode(errors="replace"))
                lines.append(stamp)
                out.write(f"{stamp[0]:.2f} {stamp[1]}\n")
                buf = b""
            else:
                buf += chunk
        code = proc.wait()
        end = time.perf_counter() - start
        if buf:
            lines.append((end, buf.decode(errors="replace")))
        out.write(f"{end:.2f} END rc={code}\n")
    return lines, code, end


def phases(lines: list[tuple[float, str]], end: float) -> Phases:
    """The phase ends of a ``make paper`` run from its stamped lines; ValueError when the
    study's closing line is missing (the study failed before it)."""
    done = next((t for t, text in lines if _DONE.match(text.strip())), None)
    if done is None:
        raise ValueError("make paper printed no study summary line (N cases, M failed; ...)")
    # a line's stamp is when it ended: a bar drawn at the study's start (after a carriage
    # return) is stamped when the next one replaces it, so the study began when the line
    # before its first one ended
    first = next(i for i, (_, text) in enumerate(lines) if "study:" in text or _DONE.match(text.strip()))
    start = lines[first - 1][0] if first > 0 else 0.0
    runs = [t for t, text in lines if (m := _BAR.search(text)) and m.group(1) == m.group(2)]
    return Phases(build=start, runs=runs[0] if runs else start, summary=done, end=end)


def work(rows: list[dict[str, str]]) -> dict[str, float]:
    """The runs' summed wall seconds (``wall_s``) and stage seconds."""
    def total(key: str) -> float:
        return sum(float(r[key]) for r in rows if r.get(key) not in (None, ""))
    return {key: total(key) for key in ("wall_s", *STAGE_COLUMNS)}


def same_cell(a: str, b: str, rtol: float) -> bool:
    """Equal text, or (``rtol`` > 0) two numbers within ``rtol`` of the larger's size."""
    if a == b:
        return True
    if rtol <= 0.0:
        return False
    try:
        x, y = float(a), float(b)
    except ValueError:
        return False
    return abs(x - y) <= rtol * max(abs(x), abs(y))


def differences(new: list[dict[str, str]], old: list[dict[str, str]], rtol: float = 0.0) -> list[str]:
    """Every cell but the times (``TIME_COLUMNS``) in which ``new`` and ``old`` differ (as
    text, or with ``rtol`` > 0 as numbers by more than ``rtol`` relative); a case only
    one of them has counts as one difference."""
    def key(r: dict[str, str]) -> tuple[str, ...]:
        return tuple(r.get(k, "") for k in ("scene", "mesh", "layout", "case"))
    def name(k: tuple[str, ...]) -> str:
        return "/".join(part for part in k if part)
    a = {key(r): r for r in new}
    b = {key(r): r for r in old}
    out = [f"{name(k)}: only in {'the new' if k in a else 'the old'} run" for k in sorted(a.keys() ^ b.keys())]
    for k in sorted(a.keys() & b.keys()):
        for col in sorted(a[k].keys() | b[k].keys()):
            if col in TIME_COLUMNS:
                continue
            if not same_cell(a[k].get(col, ""), b[k].get(col, ""), rtol):
                out.append(f"{name(k)} {col}: {a[k].get(col, '')} against {b[k].get(col, '')}")
    return out


def repeats_work(out: Path) -> dict[str, float]:
    """Every run's timing samples in a study's folder (``*/*.cost.json``, repeats
    included): their count and summed wall and CPU seconds."""
    runs, wall, cpu = 0, 0.0, 0.0
    for path in sorted(out.glob("*/*.cost.json")):
        try:
            data = json.loads(path.read_text())
            runs, wall, cpu = runs + len(data["wall_s"]), wall + sum(data["wall_s"]), cpu + sum(data["cpu_s"])
        except (OSError, ValueError, KeyError, TypeError):
            continue
    return {"runs": runs, "wall_s": wall, "cpu_s": cpu}


def report(ph: Phases, totals: dict[str, float], repeats: dict[str, float] | None = None) -> str:
    """The phases and the runs' work, as printed."""
    stages = ", ".join(f"{k[:-2]} {v:.1f}" for k, v in totals.items() if k != "wall_s")
    lines = [
        f"make paper: {ph.end:.1f} s",
        f"  build check and set-up {ph.build:.1f} s, runs {ph.runs - ph.build:.1f} s,"
        f" summary {ph.summary - ph.runs:.1f} s,"
        f" figures {ph.end - ph.summary:.1f} s",
        f"  the runs' work: {totals['wall_s']:.1f} s ({stages})",
    ]
    if repeats and repeats["runs"]:
        lines.append(f"  with the repeats: {repeats['runs']:.0f} runs of voiga, {repeats['wall_s']:.1f} s wall, "
                     f"{repeats['cpu_s']:.1f} s CPU")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Run make paper into OUT, print its phases and work; 1 when it failed or the
    measures differ from --against, 2 for bad arguments."""
    ap = argparse.ArgumentParser(prog="python3 -m bench.paper", description=__doc__.split("\n")[0])
    ap.add_argument("out", type=Path, help="PAPER_OUT: the study's folder (must not exist)")
    ap.add_argument("--tree", type=Path, default=REPO, help="source tree whose make paper runs (default: this one)")
    ap.add_argument("--against", type=Path, help="folder of another make paper run to compare the measures with")
    ap.add_argument("--rtol", type=float, default=0.0,
                    help="numbers within this relative difference count as equal (default 0: the same text)")
    args = ap.parse_args(argv)
    out = args.out.resolve()
    if out.exists():
        print(f"bench.paper: {out} exists (a previous run's results are not overwritten)", file=sys.stderr)
        return 2
    if args.against and not (args.against / "summary.csv").is_file():
        print(f"bench.paper: no summary.csv in {args.against}", file=sys.stderr)
        return 2
    if not (args.tree / "Makefile").is_file():
        print(f"bench.paper: no Makefile in {args.tree}", file=sys.stderr)
        return 2
    log = out.with_name(out.name + ".log")
    lines, code, end = stamped_lines(["make", "paper", f"PAPER_OUT={out}"], args.tree, log)
    try:
        ph = phases(lines, end)
    except ValueError as err:
        print(f"bench.paper: {err} (exit code {code}; the log: {log})", file=sys.stderr)
        return 1
    rows = read_summary(out)
    print(report(ph, work(rows), repeats_work(out)))
    status = 0 if code == 0 else 1
    if args.against:
        diff = differences(rows, read_summary(args.against), args.rtol)
        tol = f" by more than {args.rtol:g} relative" if args.rtol > 0 else ""
        print(f"  measures against {args.against}: {len(diff)} cells differ{tol}"
              + "".join(f"\n    {d}" for d in diff[:10]))
        status = status or (1 if diff else 0)
    return status


if __name__ == "__main__":
    sys.exit(main())
