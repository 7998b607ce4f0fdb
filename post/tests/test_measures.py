"""Measures, the sweep runner and the accuracy/cost table."""
from __future__ import annotations

import csv
import os
from pathlib import Path

import numpy as np
import pytest

from post.cost import RepeatPolicy
from post.engine import connect, run_all
from post.figures import accuracy_cost
from post.measures import detrended_amplitude, profile_error
from post.sweep import estimated_cost, find_cases, longest_first, previous_times, summarize, up_to_date, write_summary

REPO = Path(__file__).resolve().parents[2]


def test_detrended_amplitude_ignores_a_cubic_trend() -> None:
    t = np.linspace(0, 10, 201)
    trend = 0.3 + 0.02 * t - 0.001 * t**3
    assert detrended_amplitude(t, trend) < 1e-10
    wiggle = 0.01 * np.sin(7 * t)
    # a sine over a non-integer number of periods projects a little on the cubic: 0.0216
    assert detrended_amplitude(t, trend + wiggle) == pytest.approx(0.02, rel=0.1)


def test_profile_error() -> None:
    x = np.linspace(0, 1, 50)
    p = np.sqrt(1 - x**2)
    assert profile_error(x, p, x, p, 1.2, 1.0) == 0.0
    assert profile_error(x, 1.1 * p, x, p, 1.2, 1.0) == pytest.approx(0.1, rel=1e-3)


def test_accuracy_cost_picks_cheapest() -> None:
    rows = [
        {"scene": "s", "mesh": "m1", "layout": "N2", "status": "converged", "err": "0.2", "wall_s": "1"},
        {"scene": "s", "mesh": "m2", "layout": "N2", "status": "converged", "err": "0.05", "wall_s": "4"},
        {"scene": "s", "mesh": "m3", "layout": "N2", "status": "converged", "err": "0.02", "wall_s": "16"},
        {"scene": "s", "mesh": "m1", "layout": "NN2.2", "status": "converged", "err": "0.025", "wall_s": "2"},
    ]
    table = accuracy_cost(rows, "s", "err", (0.1, 0.03, 0.01))
    lines = table.splitlines()
    # 10%: m1-NN2.2 (2 s) is the cheapest run; the cheapest N2 reaching it is m2 (4 s)
    assert lines[2].split("|")[2].strip().startswith("m1-NN2.2") and "m2-N2" in lines[2]
    assert lines[3].split("|")[2].strip().startswith("m1-NN2.2") and "0.12" in lines[3]  # 2 / 16
    assert "none reaches it" in lines[4]


def test_sweep_runs_skips_and_summarizes(tmp_path: Path) -> None:
    binary = Path(os.environ.get("VOIGA_BIN", REPO / "build" / "install" / "bin" / "voiga"))
    if not binary.exists():
        if os.environ.get("CI"):
            pytest.fail(f"no voiga binary at {binary}")
        pytest.skip(f"no voiga binary at {binary}")
    runs = find_cases(REPO / "cases", tmp_path, ["hertz"], ["m1"], ["L1", "N2"])
    assert [r.label for r in runs] == ["hertz/m1-L1", "hertz/m1-N2"]
    policy = RepeatPolicy(short_s=3.0, min_repeats=3, max_repeats=3)
    with connect(jobs=2) as client:
        outcome = run_all(runs, binary, client, timeout=300, progress=False, policy=policy)
        assert all(o.code == 0 for o in outcome.values()), outcome
        assert all(up_to_date(r, binary) for r in runs)
        again = run_all(runs, binary, client, timeout=300, progress=False, policy=policy)
    assert all(o.message == "up to date" for o in again.values())
    serial = summarize(runs, jobs=1)
    # the result files read by two processes: the same rows, in the runs' order
    assert summarize(runs, jobs=2) == serial
    csv_path, md_path = write_summary(serial, tmp_path)
    rows = list(csv.DictReader(csv_path.open()))
    assert [int(r["dofs"]) for r in rows] == [980, 1078]
    assert all(r["status"] == "converged" for r in rows)
    # three runs each (hertz m1 takes well under 3 CPU seconds), kept through the skipped rerun
    for r in rows:
        assert r["repeats"] == "3"
        assert 0 < float(r["cpu_lo_s"]) <= float(r["cpu_s"]) <= float(r["cpu_hi_s"])
        assert 0 < float(r["wall_lo_s"]) <= float(r["wall_s"]) <= float(r["wall_hi_s"])
    assert max(float(r["time_norm"]) for r in rows) == 1.0
    assert float(rows[1]["l2_analytic"]) < 0.1 and abs(float(rows[1]["a_err"])) < 0.02
    assert "| hertz | m1 | N2 |" in md_path.read_text()


def test_contact_profile_keeps_the_contact_zone() -> None:
    """A ring-like slave edge: its far end comes back to small x with no contact; the
    profile keeps the contact zone and its neighbours only, in x order."""
    from post.contact import contact_profile
    from post.reader import ContactOutput

    theta = np.linspace(-np.pi / 2, np.pi / 2, 41)          # bottom to top of a half ring
    x = np.c_[np.cos(theta), np.sin(theta)]
    pn = np.where(theta < -np.pi / 2 + 0.2, 1.0 - (theta + np.pi / 2) / 0.2, 0.0)
    state = (pn > 0).astype(int)
    n = len(theta)
    c = ContactOutput(slave="upper", master="lower", force=np.zeros(2), xi_slave=np.linspace(0, 1, n),
                      x_ref=x, x=x, gap=-pn, p_n=pn, p_t=np.zeros(n), xi_master=np.zeros(n), state=state)
    xs, p, _ = contact_profile(c, margin=2)
    last = np.flatnonzero(state)[-1]
    assert len(xs) == last + 1 + 2                      # the zone and 2 points after it
    assert np.all(np.diff(xs) >= 0)
    assert np.array_equal(p[: last + 1], pn[: last + 1])


def test_accuracy_cost_skips_the_reference_run() -> None:
    """The reference (hertz N2 m6) has error 0 by definition and is no candidate."""
    rows = [
        {"scene": "hertz", "mesh": "m5", "layout": "N2", "status": "converged", "l2_ref_field": "0.002",
         "wall_s": "8"},
        {"scene": "hertz", "mesh": "m6", "layout": "N2", "status": "converged", "l2_ref_field": "0",
         "wall_s": "15"},
    ]
    lines = accuracy_cost(rows, "hertz", "l2_ref_field", (0.003, 0.001)).splitlines()
    assert "m5-N2" in lines[2]
    assert "none reaches it" in lines[3] and "m6-N2" not in "".join(lines)


def test_ironing_relative_oscillation(monkeypatch: pytest.MonkeyPatch) -> None:
    """osc_px / osc_py: the detrended amplitude over the second half of sliding,
    divided by |mean force| there."""
    import post.measures as measures

    steps = np.arange(1, 211)
    fx = np.where(steps > 10, 2.0 + 0.01 * np.sin(steps), 0.0)
    fy = np.where(steps > 10, -4.0 + 0.04 * np.cos(steps), 0.0)
    monkeypatch.setattr(measures, "die_forces", lambda res: (steps, np.c_[fx, fy]))
    m = measures.ironing_measures(None)  # type: ignore[arg-type]
    assert m["osc_px"] == pytest.approx(m["amp_px"] / abs(m["mean_px"]))
    assert m["osc_py"] == pytest.approx(m["amp_py"] / abs(m["mean_py"]))
    assert 0.005 < m["osc_px"] < 0.011 and 0.01 < m["osc_py"] < 0.021


def test_longest_first_from_previous_times_and_estimates(tmp_path: Path) -> None:
    """Runs are started longest first: by the wall times of a previous summary where
    it has them, else by the estimate from the case file scaled to those times."""
    runs = find_cases(REPO / "cases", tmp_path, ["ironing", "hertz"], ["m1", "m4"], ["N2", "N6"])
    labels = {r.label for r in runs}
    assert {"ironing/m4-N6", "ironing/m4-N2", "ironing/m1-N2", "hertz/m1-N2", "hertz/m4-N2"} <= labels
    cost = {r.label: estimated_cost(r.case) for r in runs}
    # more elements, higher degree and more steps cost more
    assert cost["ironing/m4-N6"] > cost["ironing/m4-N2"] > cost["ironing/m1-N2"] > cost["hertz/m1-N2"]
    assert cost["hertz/m4-N2"] > cost["hertz/m1-N2"]
    assert longest_first(runs)[0].label == "ironing/m4-N6"
    # measured times override the estimate; the others are scaled by the median ratio
    summary = tmp_path / "summary.csv"
    with summary.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=["scene", "mesh", "layout", "wall_s", "repeats", "status"])
        w.writeheader()
        w.writerow({"scene": "hertz", "mesh": "m1", "layout": "N2", "wall_s": "25", "repeats": "4",
                    "status": "converged"})
        w.writerow({"scene": "ironing", "mesh": "m1", "layout": "N2", "wall_s": "1", "status": "converged"})
        w.writerow({"scene": "hertz", "mesh": "m4", "layout": "N2", "wall_s": "5", "status": "failed: x"})
    times = previous_times(summary)
    assert times == {"hertz/m1-N2": 100.0, "ironing/m1-N2": 1.0}         # a case's time: all its runs
    order = [r.label for r in longest_first(runs, times)]
    assert order.index("hertz/m1-N2") < order.index("ironing/m1-N2")
    assert order.index("ironing/m4-N6") < order.index("ironing/m4-N2")
    assert previous_times(tmp_path / "none.csv") == {}
