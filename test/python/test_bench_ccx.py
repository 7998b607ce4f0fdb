"""The CalculiX section of the bench (bench/ccx.py) and the helpers it shares with the
Kratos section: its input (mesh, contact slope), its run list and the interleaving of the
matched runs. CalculiX itself is not run here (section 5 of `python3 -m bench` does)."""
from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import REPO

sys.path.insert(0, str(REPO))
from bench import ccx  # noqa: E402
from bench.refine import breakpoints, cut_spans, split_grid, splits  # noqa: E402
from bench.run import Run, interleaved_calls  # noqa: E402


def test_spans_cut_into_equal_parts() -> None:
    b = np.array([0.0, 0.2, 1.0])
    assert cut_spans(b, 1) == pytest.approx(b)
    assert cut_spans(b, 2) == pytest.approx([0.0, 0.1, 0.2, 0.6, 1.0])
    assert splits("3") == (3, 3) and splits("2x1") == (2, 1)
    with pytest.raises(ValueError):
        splits("0")
    bx, be = breakpoints("m2")
    gx, ge = split_grid("m2", "2x3")
    assert len(gx) == 2 * (len(bx) - 1) + 1 and len(ge) == 3 * (len(be) - 1) + 1
    assert np.isin(bx, gx).all() and np.isin(be, ge).all()


@pytest.mark.parametrize("split", ["1", "2x1"])
def test_cpe8_mesh_on_the_cut_grid(split: str) -> None:
    """One CPE8 per cell of the cut grid; corners counter-clockwise after write_input's
    reordering; the outer nodes (corners and mid-sides) on the exact unit arc."""
    xy, conn, sets, outer = ccx.cylinder_mesh("m2", split)
    gx, ge = split_grid("m2", split)
    assert conn.shape == ((len(gx) - 1) * (len(ge) - 1), 8)
    assert len(sets["NOUTER"]) == 2 * (len(gx) - 1) + 1 == 2 * len(outer) + 1
    assert np.allclose(np.hypot(*xy[sets["NOUTER"] - 1].T), 1.0)
    assert np.allclose(xy[sets["NSYM"] - 1, 0], 0.0)
    assert np.allclose(xy[sets["NTOP"] - 1, 1], 0.0)
    areas = np.array([ccx.signed_area(xy, c) for c in conn])
    assert (areas < 0).all() or (areas > 0).all()
    # the corners' polygons leave out the segments between the arcs and their chords
    # (0.5 % of the quarter annulus on m2, whose spans away from the contact are long)
    exact = np.pi * (1 - 0.05**2) / 4
    assert exact * (1 - 1e-2) < abs(areas.sum()) < exact


def test_input_carries_the_contact_slope(tmp_path: Path) -> None:
    """The slope of *SURFACE BEHAVIOR is penalty x E, the default ccx.PENALTY; the input
    names every element of the cut mesh."""
    for penalty in (None, 1e3, 3.5e4):
        inp = tmp_path / "h.inp"
        info = (ccx.write_input(inp, "m2", "2") if penalty is None
                else ccx.write_input(inp, "m2", "2", penalty))
        lines = inp.read_text().splitlines()
        i = lines.index("*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR")
        slope = float(lines[i + 1].split(",")[0])
        assert slope == pytest.approx((penalty or ccx.PENALTY) * ccx.E)
        text = "\n".join(lines)
        cyl = re.search(r"ELSET=ECYL\n(.*?)\n\*", text, re.S).group(1).splitlines()
        assert len(cyl) == info["elements"] == len(ccx.cylinder_mesh("m2", "2")[1])


def test_run_list() -> None:
    assert ccx.parse_runs("m4:1:1e3, m5:2x1", 1e5) == [("m4", "1", 1e3), ("m5", "2x1", 1e5)]
    for bad in ("m4", "m4:1:1e3:2", "m4:0", "m4:1:-1"):
        with pytest.raises((SystemExit, ValueError)):
            ccx.parse_runs(bad)


def test_iterations_from_the_log() -> None:
    log = "\n increment 1 attempt 1\n\n iteration 1\n\n no convergence\n\n iteration 2\n"
    assert ccx.iterations(log) == 2


def test_interleaved_calls_keep_the_fastest_of_each() -> None:
    """Calls run A B A B ...; of each the run with the least wall time is kept, be it a
    voiga Run or a peer's dict."""
    order: list[str] = []
    walls = {"a": iter([3.0, 1.0, 2.0]), "b": iter([0.5, 0.7, 0.4])}

    def voiga_like():
        order.append("a")
        return Run(case="a", wall=next(walls["a"]), n_dofs=1, steps=1, iterations=1)

    def peer():
        order.append("b")
        return {"wall": next(walls["b"])}

    best = interleaved_calls({"a": voiga_like, "b": peer}, 3)
    assert order == ["a", "b"] * 3
    assert best["a"].wall == 1.0 and best["b"]["wall"] == 0.4


@pytest.mark.parametrize("section", ["calculix", "kratos"])
def test_matched_comparison_with_a_stand_in_peer(
        section: str, voiga_bin: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture) -> None:
    """Sections 5 and 6 end the same way: the matched peer run and voiga hertz m4 NN2.2 (as
    committed and with the automatic penalty) interleaved, best of --repeat, and the peer's
    wall time over each voiga run's. The peer is a stand-in here (voiga runs for real);
    every call of it is counted."""
    import bench.run
    from bench import kratos
    from bench.run import Workdir
    monkeypatch.setattr(bench.run, "VOIGA", voiga_bin)
    calls: list[tuple] = []

    def peer(*args, **kwargs) -> dict:
        calls.append(args)
        return {"wall": 10.0 + len(calls), "l2": 0.004, "mesh": "m5", "split": "1",
                "penalty": 1e4, "dofs": 1, "iterations": [1] * 5 if section == "kratos" else 48,
                "force": 0.005, "a_error": 0.0, "p0_error": 0.0, "method": "penalty",
                "analysis_seconds": 1.0}

    w = Workdir(tmp_path / "w")
    if section == "calculix":
        monkeypatch.setattr(ccx, "ensure_ccx", lambda: "ccx")
        monkeypatch.setattr(ccx, "run_ccx", peer)
        out = ccx.section_calculix(w, "m4:1,m5:1:1e3", "m5:1", 1e4, repeat=2)
        assert [c[2:] for c in calls] == [("m4", "1", 1e4), ("m5", "1", 1e3),
                                          ("m5", "1", 1e4), ("m5", "1", 1e4)]
        peers = ["ccx"]
    else:
        monkeypatch.setattr(kratos, "ensure_kratos", lambda: Path("python"))
        monkeypatch.setattr(kratos, "kratos_once", peer)
        out = kratos.section_kratos(w, "penalty:m4:1", "penalty:m5:2", repeat=2,
                                    solvers="sparse_lu,amgcl")
        assert [c[2:] for c in calls] == [(("penalty", "m4", "1"), "sparse_lu")] + [
            (("penalty", "m5", "2"), s) for s in ("sparse_lu", "amgcl")] * 2
        peers = ["sparse_lu", "amgcl"]
    assert len(out["runs"]) == (2 if section == "calculix" else 1)
    match = out["match"]
    # the stand-in's wall grows with every call: the best of each peer's two matched calls
    # is its first (calculix: calls 3 and 4; kratos: sparse_lu 2 and 4, amgcl 3 and 5)
    first = {"ccx": 13.0} if section == "calculix" else {"sparse_lu": 12.0, "amgcl": 13.0}
    assert {p: match[p]["wall"] for p in peers} == first
    for name in ("penalty 1e3", "auto"):
        v = match[name]
        assert v["dofs"] == 7540 and v["wall"] > 0
        for p in peers:
            assert v["ratio"][p] == pytest.approx(match[p]["wall"] / v["wall"])
    assert match["auto"]["l2"] < match["penalty 1e3"]["l2"]
    assert "no ratio" not in capsys.readouterr().out
