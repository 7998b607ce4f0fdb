"""``python -m post history`` / ``summary`` / ``hertz`` / ``plot-contact``: tables equal
the result file, figures are written under one naming scheme, bad input exits 2."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

from post.__main__ import main
from post.plot import auto_scale
from post.reader import read_result
from post.units import Units

PNG = b"\x89PNG\r\n\x1a\n"


def _png(path: Path) -> bool:
    return path.is_file() and path.read_bytes()[:8] == PNG


def test_history_csv_equals_the_file(press_h5: Path, tmp_path: Path,
                                     capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["history", str(press_h5), "--out", str(tmp_path)]) == 0
    csv_path, png = tmp_path / "press-history.csv", tmp_path / "press-history.png"
    assert capsys.readouterr().out.split() == [str(csv_path), str(png)]
    assert _png(png)
    result = read_result(press_h5)
    with open(csv_path) as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == len(result.steps)
    for row, s in zip(rows, result.steps, strict=True):
        assert int(row["step"]) == s.step and float(row["time"]) == s.time
        for k, d in enumerate(result.dirichlet):
            assert float(row[f"reaction_x {d.body}/{d.edge}"]) == s.reactions[k, 0]
            assert float(row[f"reaction_y {d.body}/{d.edge}"]) == s.reactions[k, 1]
        c = s.contact[0]
        assert float(row["contact_x die->slab"]) == c.force[0]
        assert int(row["points_in_contact die->slab"]) == int(c.active.sum())
        assert float(row["max_p_n die->slab"]) == c.p_n.max()
    # the die's reaction balances the slab's (no other load)
    last = rows[-1]
    assert float(last["reaction_y die/inner"]) == pytest.approx(-float(last["reaction_y slab/bottom"]),
                                                                rel=1e-8)


def test_figures_next_to_the_result(hertz_h5: Path, tmp_path: Path,
                                    capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "h.h5"
    path.write_bytes(hertz_h5.read_bytes())
    assert main(["hertz", str(path)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == f"{path}, step 5 (load time 1):"
    assert any(line.strip().startswith("P = ") for line in lines)
    assert lines[-1] == str(tmp_path / "h-hertz-000005.png") and _png(Path(lines[-1]))
    assert main(["plot-contact", str(path)]) == 0
    assert capsys.readouterr().out.strip() == str(tmp_path / "h-contact-000005.png")
    assert main(["plot-deformed", str(path)]) == 0
    assert capsys.readouterr().out.strip() == str(tmp_path / "h-deformed-000005.png")
    assert main(["summary", str(path)]) == 0
    out = capsys.readouterr().out
    assert "converged, 5 of 5 steps" in out and "hertz vs analytic: P = " in out


def test_plot_contact_unknown_step(hertz_h5: Path, tmp_path: Path,
                                   capsys: pytest.CaptureFixture[str]) -> None:
    """A step the result does not have: one line naming the steps it has (issue 38,
    item 7: it was `99 is not in list`); step 0 has no contact output; -k counts back."""
    path = tmp_path / "h.h5"
    path.write_bytes(hertz_h5.read_bytes())
    assert main(["plot-contact", str(path), "--step", "99"]) == 1
    err = capsys.readouterr().err
    assert f"plot-contact: {path}: no converged step 99 (steps 1 to 5, status 'converged'; -1 is the last)" \
        in err, err
    assert main(["plot-contact", str(path), "--step", "0"]) == 1
    assert "step 0 is the reference configuration" in capsys.readouterr().err
    assert main(["plot-contact", str(path), "--step", "-9"]) == 1
    assert "step index -9 but only 5 converged step(s)" in capsys.readouterr().err
    assert main(["plot-contact", str(path), "--step", "3", "--out", str(tmp_path)]) == 0
    assert capsys.readouterr().out.strip() == str(tmp_path / "h-contact-000003.png")


def test_auto_scale() -> None:
    assert auto_scale(1.0, 0.5) == 1.0 and auto_scale(1.0, 0.0) == 1.0
    assert auto_scale(1.0, 0.01) == 10.0  # 0.1 of the size
    assert auto_scale(1.0, 0.011) == 5.0  # the largest 1-2-5 step that stays below
    assert auto_scale(9.0, 0.09) == 10.0


def test_units() -> None:
    u = Units.parse("mm, N")
    assert (u.length, u.line_force, u.pressure) == ("mm", "N/mm", "N/mm^2") and u.known
    assert not Units.parse("consistent (the scenes: mm, N)").known
    assert Units.parse("").pressure == "force/length^2"


@pytest.mark.parametrize("command", ["history", "summary", "vtk", "hertz", "plot-deformed"])
def test_bad_input_exits_2(command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main([command, str(tmp_path / "missing.h5")]) == 2
    err = capsys.readouterr().err
    assert "missing.h5" in err and len(err.strip().splitlines()) == 1
    junk = tmp_path / "junk.h5"
    junk.write_text("not hdf5")
    assert main([command, str(junk)]) == 2
    assert "junk.h5" in capsys.readouterr().err


def test_summary_warnings(press_h5: Path, tmp_path: Path) -> None:
    """The solver's warnings recorded in the file are shown (here: the die, the slave,
    is stiffer than the slab). A file without that record (written before voiga made
    one): a pair never in contact, and a penetration beyond a tenth of the slave
    element, are named (here made by editing copies of a real result)."""
    import h5py

    from post.summary import summary_lines, warnings_for

    # (the other recorded warning is the contact-zone indicator's: test_indicator.py)
    (w,) = [x for x in warnings_for(read_result(press_h5)) if "contact zone" not in x]
    assert w.startswith("warning: contact 'die' on 'slab': the slave is stiffer")
    assert w in summary_lines(read_result(press_h5))
    never = tmp_path / "never.h5"
    never.write_bytes(press_h5.read_bytes())
    with h5py.File(never, "r+") as f:
        del f.attrs["warnings"]
        for key in f["steps"]:
            f[f"steps/{key}/contact/1/state"][...] = 0
    (w,) = warnings_for(read_result(never))
    assert "die -> slab was never in contact" in w
    deep = tmp_path / "deep.h5"
    deep.write_bytes(press_h5.read_bytes())
    with h5py.File(deep, "r+") as f:
        del f.attrs["warnings"]
        g = f["steps/000002/contact/1"]
        k = int(np.flatnonzero(g["state"][()] > 0)[0])
        gap = g["gap"][()]
        gap[k] = -0.5  # the die's slave elements are about 1.57 long at m1
        g["gap"][...] = gap
    (w,) = warnings_for(read_result(deep))
    assert "largest penetration 0.5 is 33% of the slave element size 1.53" in w
    assert w in summary_lines(read_result(deep))
