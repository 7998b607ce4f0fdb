"""What a run costs, measured so that a comparison survives a rerun on a busy machine.

A run's cost is the CPU time of its ``voiga`` process (user + sys, from the kernel's
accounting of that one child, ``os.wait4``): it changes far less than the wall time when
other processes share the cores (the wall time counts their turns too), though not
nothing (they share the caches and memory). Wall time (process start to exit) is kept
beside it. A short run is repeated (:class:`RepeatPolicy`) and described by the median and the
range (min, max) of its repeats (:class:`Spread`); the engine (``post/engine.py``) keeps
the first repeat's result file and writes the times of all repeats beside it
(:func:`write_costs`, ``<result stem>.cost.json``), where the summary reads them back
(:func:`read_costs`).

:func:`cheapest` decides which of several runs is the cheapest from their ranges: a
run is named unless another's range lies wholly below its own, so that runs whose
ranges overlap are a tie, and :func:`ratio` gives the cost of the cheapest run of one
set against another's with the range the measurements allow
(``post/figures.py``, ``docs/validation/accuracy-cost.md``).
"""

from __future__ import annotations

import json
import math
import os
import signal
import stat as stat_module
import statistics
import subprocess
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from pre.files import write_text

COST_SUFFIX = ".cost.json"
"""The times of a result ``<stem>.h5`` are in ``<stem>.cost.json`` beside it."""


@dataclass(frozen=True)
class Sample:
    """One run of ``voiga``: seconds from start to exit, and CPU seconds (user + sys)."""

    wall: float
    cpu: float


@dataclass(frozen=True)
class Spread:
    """Median and range (min, max) of repeated measurements of one quantity."""

    median: float
    lo: float
    hi: float
    n: int

    @classmethod
    def of(cls, values: Sequence[float]) -> Spread:
        """The spread of ``values`` (ValueError when there are none)."""
        if not values:
            raise ValueError("no values to take a median of")
        return cls(float(statistics.median(values)), float(min(values)), float(max(values)), len(values))

    def overlaps(self, other: Spread) -> bool:
        """The two ranges have a point in common."""
        return self.lo <= other.hi and other.lo <= self.hi


@dataclass(frozen=True)
class RepeatPolicy:
    """How often a run is repeated: a run whose first CPU time is ``short_s`` or more
    runs once; a shorter one is repeated until it has ``min_repeats`` runs and its runs
    together took ``budget_s`` CPU seconds, but at most ``max_repeats`` times. (The
    CPU time decides, not the wall time, so that a busy machine repeats as often as
    an idle one.)"""

    short_s: float = 3.0
    min_repeats: int = 3
    max_repeats: int = 9
    budget_s: float = 1.0

    def more(self, samples: Sequence[Sample]) -> bool:
        """Whether to run once more after ``samples``."""
        if not samples or samples[0].cpu >= self.short_s:
            return False
        if len(samples) >= self.max_repeats:
            return False
        return len(samples) < self.min_repeats or sum(s.cpu for s in samples) < self.budget_s


MAX_REPEATS = 100
"""The most runs a study may ask of each short case (``repeats``, ``--repeats``): more
tell nothing new and only take the machine."""

ONCE = RepeatPolicy(short_s=0.0)
"""Every run once."""


def timed_run(cmd: list[str], cwd: Path, env: dict[str, str], timeout: float) -> tuple[int, str, Sample]:
    """Run ``cmd`` in ``cwd`` (stdout discarded, stderr kept in ``cwd/stderr.txt``); its
    exit code (-1 when it was killed after ``timeout`` seconds), the last line it wrote
    to stderr, and its :class:`Sample`: CPU time from ``os.wait4`` of this one child, so
    that runs started by other threads of this process are not counted in."""
    err_path = cwd / "stderr.txt"
    with err_path.open("w+") as err:
        start = time.perf_counter()
        proc = subprocess.Popen(cmd, cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                stderr=err, env=env)
        lock, state = threading.Lock(), {"reaped": False, "killed": False}

        def kill() -> None:
            with lock:                       # never signal a pid that was reaped (and may be reused)
                if not state["reaped"]:
                    state["killed"] = True
                    os.kill(proc.pid, signal.SIGKILL)

        timer = threading.Timer(timeout, kill)
        timer.start()
        try:
            _, status, usage = os.wait4(proc.pid, 0)
            with lock:
                state["reaped"] = True
        finally:
            timer.cancel()
        wall = time.perf_counter() - start
        proc.returncode = os.waitstatus_to_exitcode(status)   # Popen must not wait for it again
        err.seek(0)
        lines = err.read().strip().splitlines()
    sample = Sample(wall, usage.ru_utime + usage.ru_stime)
    if state["killed"]:
        return -1, f"timed out after {timeout:g} s", sample
    return proc.returncode, lines[-1] if lines else "", sample


def cost_path(result: Path) -> Path:
    """Where the times of ``result`` are kept."""
    return result.with_name(result.stem + COST_SUFFIX)


def write_costs(result: Path, samples: Sequence[Sample]) -> Path:
    """The samples of the runs that made ``result``, with the result file's size and
    modification time (a result rewritten since, e.g. by hand, no longer matches)."""
    stat = result.stat()
    return write_text(cost_path(result),   # beside it and renamed, never through a link (pre/files.py)
                      json.dumps({"result_size": stat.st_size, "result_mtime_ns": stat.st_mtime_ns,
                                  "wall_s": [s.wall for s in samples], "cpu_s": [s.cpu for s in samples]},
                                 indent=1) + "\n")


def read_costs(result: Path) -> list[Sample] | None:
    """The samples written by :func:`write_costs` for this very result file, else None
    (no file, a malformed one, one that is not a regular file -- a link, or a FIFO that
    would hang the read --, times that are not finite and >= 0, or one written for another version of
    the result)."""
    path = cost_path(result)
    try:
        if not stat_module.S_ISREG(os.lstat(path).st_mode):   # not through a link either
            return None
        data = json.loads(path.read_text())
        stat = result.stat()
        if data["result_size"] != stat.st_size or data["result_mtime_ns"] != stat.st_mtime_ns:
            return None
        samples = [Sample(float(w), float(c)) for w, c in zip(data["wall_s"], data["cpu_s"], strict=True)]
    except (OSError, ValueError, KeyError, TypeError):
        return None
    if not all(math.isfinite(t) and t >= 0 for s in samples for t in (s.wall, s.cpu)):
        return None     # no run takes NaN or negative seconds: not the engine's file
    return samples or None


def cost_columns(samples: Sequence[Sample]) -> dict[str, float | int]:
    """The summary's cost columns of one run: repeats, CPU and wall seconds (median,
    lo = min, hi = max), rounded to 0.1 ms."""
    cpu, wall = Spread.of([s.cpu for s in samples]), Spread.of([s.wall for s in samples])
    return {"repeats": len(samples),
            "cpu_s": round(cpu.median, 4), "cpu_lo_s": round(cpu.lo, 4), "cpu_hi_s": round(cpu.hi, 4),
            "wall_s": round(wall.median, 4), "wall_lo_s": round(wall.lo, 4), "wall_hi_s": round(wall.hi, 4)}


COST_COLUMNS = ("repeats", "cpu_s", "cpu_lo_s", "cpu_hi_s", "wall_s", "wall_lo_s", "wall_hi_s")
"""The summary's columns written by :func:`cost_columns`."""


def cheapest(costs: dict[str, Spread]) -> list[str]:
    """The names that may be the cheapest: every one whose range does not lie wholly
    above another's (its lowest value is at most the smallest highest value), ordered
    by median. One name when the cheapest is clearly separated from the rest; two or
    more (a tie) when their ranges overlap."""
    if not costs:
        return []
    ceiling = min(s.hi for s in costs.values())
    names = [k for k, s in costs.items() if s.lo <= ceiling]
    return sorted(names, key=lambda k: (costs[k].median, k))


def ratio(others: dict[str, Spread], base: dict[str, Spread]) -> Spread:
    """The cost of the cheapest of all runs (``others`` and ``base``) relative to the
    cheapest of ``base`` (so at most 1): the median from the members' medians and the
    range the measurements allow, since the cheapest of a set costs between the
    smallest low and the smallest high of its members' ranges. ``n`` is 0 (a derived
    quantity, not a count of repeats). ValueError when ``base`` is empty."""
    if not base:
        raise ValueError("no run to compare with")
    a_med = min(s.median for s in base.values())
    a_lo, a_hi = min(s.lo for s in base.values()), min(s.hi for s in base.values())
    if not others:
        return Spread(1.0, 1.0, 1.0, 0)
    b_med = min(s.median for s in others.values())
    b_lo, b_hi = min(s.lo for s in others.values()), min(s.hi for s in others.values())
    return Spread(min(1.0, b_med / a_med), min(1.0, b_lo / a_hi), min(1.0, b_hi / a_lo), 0)
