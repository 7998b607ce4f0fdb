"""The cost of a run (post/cost.py) and the accuracy/cost table built from it: repeats,
median and range, CPU time of one child, ties where the ranges overlap."""
from __future__ import annotations

import os
import sys
import threading
from pathlib import Path

import pytest

from post.cost import (
    ONCE,
    RepeatPolicy,
    Sample,
    Spread,
    cheapest,
    cost_columns,
    cost_path,
    ratio,
    read_costs,
    timed_run,
    write_costs,
)
from post.engine import Task, connect, run_all, run_task
from post.figures import accuracy_cost
from post.sweep import find_cases

BURN = "import time\nwhile time.process_time() < {0}: pass\n"
"""A child that uses ``{0}`` CPU seconds, however busy the machine is."""


def test_spread_is_median_and_range() -> None:
    s = Spread.of([0.05, 0.031, 0.032, 0.030, 0.2])
    assert (s.median, s.lo, s.hi, s.n) == (0.032, 0.030, 0.2, 5)
    assert Spread.of([1.0, 2.0]).median == 1.5          # even count: the mean of the middle two
    assert Spread.of([3.0]) == Spread(3.0, 3.0, 3.0, 1)
    with pytest.raises(ValueError):
        Spread.of([])
    assert Spread(1, 1, 2, 3).overlaps(Spread(2, 2, 3, 3)) and not Spread(1, 1, 2, 3).overlaps(Spread(3, 2.1, 4, 3))


def _samples(*cpu: float) -> list[Sample]:
    return [Sample(2 * c, c) for c in cpu]


def test_repeat_policy() -> None:
    policy = RepeatPolicy(short_s=3.0, min_repeats=3, max_repeats=9, budget_s=0.5)
    assert not policy.more([])
    assert not policy.more(_samples(3.0))                 # a long run: once
    assert policy.more(_samples(2.9)) and policy.more(_samples(2.9, 2.9))
    assert not policy.more(_samples(2.9, 2.9, 2.9))       # min_repeats, budget spent
    # a short run goes on until the budget (0.5 CPU s) is spent, at most max_repeats times
    assert policy.more(_samples(0.1, 0.1, 0.1)) and policy.more(_samples(*[0.1] * 4))
    assert not policy.more(_samples(*[0.1] * 5))
    assert policy.more(_samples(*[0.01] * 8)) and not policy.more(_samples(*[0.01] * 9))
    # the first run decides whether the case is short: a slow repeat does not stop it
    assert policy.more(_samples(0.1, 5.0)) and not policy.more(_samples(5.0, 0.1))
    assert not ONCE.more(_samples(0.01))


def test_cost_columns_and_sidecar(tmp_path: Path) -> None:
    result = tmp_path / "m1-N2.h5"
    result.write_bytes(b"result")
    samples = [Sample(0.05, 0.031), Sample(0.04, 0.030), Sample(0.06, 0.033)]
    assert write_costs(result, samples) == cost_path(result) == tmp_path / "m1-N2.cost.json"
    assert read_costs(result) == samples
    assert cost_columns(samples) == {"repeats": 3, "cpu_s": 0.031, "cpu_lo_s": 0.03, "cpu_hi_s": 0.033,
                                     "wall_s": 0.05, "wall_lo_s": 0.04, "wall_hi_s": 0.06}
    # a result rewritten since (here: another size) does not take the old times
    result.write_bytes(b"another result")
    assert read_costs(result) is None
    cost_path(result).write_text("{ not json")
    assert read_costs(result) is None
    assert read_costs(tmp_path / "none.h5") is None


def test_sidecar_is_never_written_or_read_through_a_link_or_a_fifo(tmp_path: Path) -> None:
    """The times follow the rules of every file post writes (issue 36, pre/files.py):
    a link or FIFO at the ``.cost.json`` name is refused, not written through; and one
    there is not read (a FIFO would hang the summary), nor are times no run takes."""
    from pre.files import OutputError

    result = tmp_path / "m1-N2.h5"
    result.write_bytes(b"result")
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    samples = [Sample(0.05, 0.031)]
    cost_path(result).symlink_to(victim.name)
    with pytest.raises(OutputError, match="symbolic link"):
        write_costs(result, samples)
    assert victim.read_text() == "precious" and read_costs(result) is None
    # a link to a file of the right times is not followed either
    cost_path(result).unlink()
    write_costs(result, samples)
    os.replace(cost_path(result), victim)
    cost_path(result).symlink_to(victim.name)
    assert read_costs(result) is None
    cost_path(result).unlink()
    os.mkfifo(cost_path(result))
    with pytest.raises(OutputError, match="FIFO"):
        write_costs(result, samples)
    assert read_costs(result) is None                      # at once, not waiting on the FIFO
    cost_path(result).unlink()
    for bad in (Sample(float("nan"), 0.03), Sample(0.05, -1.0), Sample(float("inf"), 0.03)):
        write_costs(result, [bad])
        assert read_costs(result) is None


def test_cheapest_orders_separated_runs_and_ties_overlapping_ones() -> None:
    separated = {"m2-N2": Spread(2.0, 1.9, 2.1, 5), "m1-NN2.2": Spread(1.0, 0.9, 1.1, 5)}
    assert cheapest(separated) == ["m1-NN2.2"]
    overlapping = {"m2-N2": Spread(1.05, 1.0, 1.2, 5), "m1-NN2.2": Spread(1.0, 0.9, 1.1, 5)}
    assert cheapest(overlapping) == ["m1-NN2.2", "m2-N2"]          # both, by median
    # a chain: A overlaps B and B overlaps C, but C lies wholly above A: not a candidate
    chain = {"C": Spread(3.0, 2.5, 4.0, 3), "B": Spread(2.0, 1.5, 3.0, 3), "A": Spread(1.5, 1.0, 2.0, 3)}
    assert cheapest(chain) == ["A", "B"]
    assert cheapest({"one": Spread(16.2, 16.2, 16.2, 1)}) == ["one"] and cheapest({}) == []


def test_ratio_range() -> None:
    n2 = {"m3-N2": Spread(4.0, 3.8, 4.4, 3), "m4-N2": Spread(16.0, 16.0, 16.0, 1)}
    vo = {"m1-NN2.2": Spread(1.0, 0.95, 1.1, 5)}
    r = ratio(vo, n2)
    assert r.median == pytest.approx(0.25) and r.lo == pytest.approx(0.95 / 4.4)
    assert r.hi == pytest.approx(1.1 / 3.8)
    # the cheapest N2 is the cheapest run: 1 (the others cannot be cheaper than itself)
    assert ratio({"m5-L1": Spread(9.0, 8.0, 10.0, 3)}, n2) == Spread(1.0, 1.0, 1.0, 0)
    assert ratio({}, n2) == Spread(1.0, 1.0, 1.0, 0)
    overlap = ratio({"m1-L1": Spread(3.9, 3.5, 4.1, 3)}, n2)        # maybe cheaper, maybe not
    assert overlap.lo == pytest.approx(3.5 / 4.4) and overlap.hi == 1.0
    with pytest.raises(ValueError):
        ratio(vo, {})


def _row(mesh: str, layout: str, err: float, cpu: tuple[float, float, float], n: int = 5) -> dict[str, str]:
    median, lo, hi = cpu
    return {"scene": "s", "mesh": mesh, "layout": layout, "status": "converged", "err": str(err),
            "repeats": str(n), "cpu_s": str(median), "cpu_lo_s": str(lo), "cpu_hi_s": str(hi),
            "wall_s": str(2 * median)}


def test_accuracy_cost_ties_overlapping_runs_and_orders_separated_ones() -> None:
    rows = [_row("m1", "N2", 0.2, (1.0, 0.9, 1.1)),
            _row("m2", "N2", 0.05, (4.0, 3.8, 4.4)),
            _row("m3", "N2", 0.02, (16.0, 16.0, 16.0), n=1),
            _row("m1", "NN2.2", 0.025, (1.0, 0.95, 1.05)),
            _row("m1", "L1", 0.06, (0.99, 0.97, 1.2)),
            _row("m2", "NN2.2", 0.008, (3.9, 3.7, 4.0))]
    lines = accuracy_cost(rows, "s", "err", (0.1, 0.03, 0.01, 0.001)).splitlines()
    assert "CPU time" in lines[0]
    cells = [[c.strip() for c in line.split("|")[1:-1]] for line in lines[2:]]
    # 10 %: m1-L1 and m1-NN2.2 overlap: a tie, both named (by median); m2-N2 lies above both
    assert cells[0][1] == "tie: m1-L1 (0.06): 0.99 s [0.97-1.2]; m1-NN2.2 (0.025): 1 s [0.95-1.05]"
    assert cells[0][2] == "m2-N2 (0.05): 4 s [3.8-4.4]"
    # the cheapest costs 0.99 (median), between 0.95 and 1.05 (the smallest low and high)
    assert cells[0][3] == "0.25 [0.22-0.28]"      # 0.99 / 4, [0.95 / 4.4, 1.05 / 3.8]
    # 3 %: m1-NN2.2 alone (separated from m2-N2's range); N2 needs m3, timed once
    assert cells[1][1] == "m1-NN2.2 (0.025): 1 s [0.95-1.05]"
    assert cells[1][2] == "m3-N2 (0.02): 16 s (1 run)"
    assert cells[1][3] == "0.062 [0.059-0.066]"
    # 1 %: only m2-NN2.2; 0.1 %: nobody
    assert cells[2][1].startswith("m2-NN2.2 (0.008)") and cells[2][3] == "N2 does not reach it"
    assert cells[3][1] == "none reaches it"


def test_accuracy_cost_without_cpu_times_uses_the_wall_time() -> None:
    rows = [{"scene": "s", "mesh": "m1", "layout": "N2", "status": "converged", "err": "0.05", "wall_s": "2"},
            {"scene": "s", "mesh": "m1", "layout": "NN2.2", "status": "converged", "err": "0.05", "wall_s": "1"}]
    lines = accuracy_cost(rows, "s", "err", (0.1,)).splitlines()
    assert "wall time" in lines[0]
    assert "m1-NN2.2 (0.05): 1 s (1 run)" in lines[2] and "| 0.50 [0.50-0.50] |" in lines[2]


def test_timed_run_counts_the_cpu_time_of_its_own_child_only(tmp_path: Path) -> None:
    """Two children at once, from two threads: each one's CPU time is its own (a
    sleeping child is not charged with its busy neighbour's time)."""
    (tmp_path / "busy").mkdir()
    (tmp_path / "idle").mkdir()
    out: dict[str, tuple[int, str, Sample]] = {}

    def busy() -> None:
        out["busy"] = timed_run([sys.executable, "-c", BURN.format(0.6)], tmp_path / "busy", dict(os.environ), 60)

    thread = threading.Thread(target=busy)
    thread.start()
    out["idle"] = timed_run(["sleep", "0.3"], tmp_path / "idle", dict(os.environ), 60)
    thread.join()
    code, _, burn = out["busy"]
    assert code == 0 and burn.cpu >= 0.6 and burn.wall >= burn.cpu * 0.9
    code, _, nap = out["idle"]
    assert code == 0 and nap.wall >= 0.3 and nap.cpu < 0.2
    code, message, _ = timed_run([sys.executable, "-c", "import sys; print('bad case', file=sys.stderr); "
                                  "sys.exit(2)"], tmp_path, dict(os.environ), 60)
    assert (code, message) == (2, "bad case")


def test_timed_run_kills_at_the_timeout(tmp_path: Path) -> None:
    code, message, sample = timed_run(["sleep", "30"], tmp_path, dict(os.environ), 0.3)
    assert code == -1 and message == "timed out after 0.3 s" and sample.wall < 20


FAKE = """#!/bin/sh
# a stand-in for voiga: logs its runs, writes the case's run number into the result
n=$(($(cat {counter}-${{1%.nml}} 2>/dev/null || echo 0) + 1))
echo $n > {counter}-${{1%.nml}}
echo "${{1%.nml}} $n" >> {log}
case "${{1%.nml}}:$n" in {fail}) exit 3;; esac
echo "run $n" > "${{1%.nml}}.h5"
"""


def _fake(tmp_path: Path, fail: str = "none") -> Path:
    """The fake binary; ``fail``: a shell pattern of ``<case>:<run number>`` that fails."""
    binary = tmp_path / "fake-voiga"
    binary.write_text(FAKE.format(counter=tmp_path / "counter", log=tmp_path / "log", fail=fail))
    binary.chmod(0o755)
    return binary


def _task(binary: Path, dest: Path | None, keep: bool = True) -> Task:
    return Task(label="s/m1-N2", name="m1-N2.nml", text="&case /\n", geometry_name="geometry.h5",
                geometry=b"", binary=str(binary), timeout=60, dest=str(dest) if dest else None, keep=keep)


def test_run_task_keeps_or_drops_the_result(tmp_path: Path) -> None:
    binary = _fake(tmp_path)
    dest = tmp_path / "out" / "m1-N2.h5"
    out = run_task(_task(binary, dest))
    assert out.code == 0 and len(out.samples) == 1 and dest.read_text() == "run 1\n"
    out = run_task(_task(binary, None))                     # returned through the scheduler
    assert out.code == 0 and out.data == b"run 2\n"                # the case's second run
    out = run_task(_task(binary, tmp_path / "other.h5", keep=False))     # a repeat: timed only
    assert out.code == 0 and out.data is None and not (tmp_path / "other.h5").exists()
    assert len(out.samples) == 1 and out.samples[0].wall > 0


def _cases(tmp_path: Path, names: list[str]) -> list:
    folder = tmp_path / "cases" / "s"
    folder.mkdir(parents=True)
    (folder / "geometry.h5").write_bytes(b"")
    for name in names:
        (folder / f"{name}.nml").write_text(f"&case output = '{name}.h5' /\n")
    return find_cases(tmp_path / "cases", tmp_path / "out")


def test_short_runs_are_repeated_in_rounds_after_the_first_runs(tmp_path: Path) -> None:
    """Every case runs once first; the repeats follow in rounds (every case's second
    run, then every case's third), each case keeps its first run's result and its
    times are kept beside it."""
    binary = _fake(tmp_path)
    runs = _cases(tmp_path, ["m1-N2", "m2-N2"])
    policy = RepeatPolicy(short_s=3.0, min_repeats=3, max_repeats=3)
    with connect(jobs=1) as client:
        outcome = run_all(runs, binary, client, timeout=60, progress=False, policy=policy)
    order = (tmp_path / "log").read_text().split()[::2]
    assert sorted(order[:2]) == ["m1-N2", "m2-N2"] and order[2:4] == order[:2] and order[4:] == order[:2]
    for run in runs:
        assert outcome[run.label].code == 0 and len(outcome[run.label].samples) == 3
        assert run.result.read_text() == "run 1\n"                     # the first run's, not a repeat's
        assert read_costs(run.result) == outcome[run.label].samples
    # each case once: no repeats, one time each
    (tmp_path / "log").unlink()
    with connect(jobs=1) as client:
        outcome = run_all(runs, binary, client, timeout=60, progress=False, force=True)
    assert len((tmp_path / "log").read_text().split()) == 4
    assert all(len(read_costs(run.result) or []) == 1 for run in runs)


def test_a_failed_repeat_ends_the_repeats(tmp_path: Path) -> None:
    """A repeat that fails times nothing (it may have stopped early): the case keeps its
    first result and the times it has. A first run that fails is not repeated."""
    runs = _cases(tmp_path, ["m1-N2", "m2-N2"])
    binary = _fake(tmp_path, fail="m1-N2:[34]|m2-N2:1")
    policy = RepeatPolicy(short_s=3.0, min_repeats=5, max_repeats=5)
    with connect(jobs=1) as client:
        outcome = run_all(runs, binary, client, timeout=60, progress=False, policy=policy)
    a, b = (outcome[run.label] for run in runs)
    assert a.code == 0 and len(a.samples) == 2 and read_costs(runs[0].result) == a.samples
    assert runs[0].result.read_text() == "run 1\n" and (tmp_path / "counter-m2-N2").read_text() == "1\n"
    assert b.code == 3 and len(b.samples) == 1 and not runs[1].result.exists()
