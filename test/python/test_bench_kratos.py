"""The Kratos section of the bench (bench/kratos.py): its mesh and pressure recovery always,
and one small Kratos run when Kratos is already installed in build/kratos-venv (this test
installs nothing)."""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import REPO

sys.path.insert(0, str(REPO))
from bench import kratos  # noqa: E402


def test_q4_mesh_is_counter_clockwise_on_the_exact_arc() -> None:
    xy, conn, sym, top, outer = kratos.cylinder_q4("m2", 2)
    p = xy[conn]
    area = 0.5 * ((p[:, :, 0] * np.roll(p[:, :, 1], -1, axis=1)).sum(1)
                  - (np.roll(p[:, :, 0], -1, axis=1) * p[:, :, 1]).sum(1))
    assert (area > 0).all()
    # the quarter annulus R in [0.05, 1] has area pi (1 - 0.05^2) / 4; the chords between
    # nodes on the outer arc (up to 0.05 long on m2) leave out segments of about h^3 / 12
    exact = np.pi * (1 - 0.05**2) / 4
    assert exact * (1 - 2e-3) < area.sum() < exact
    assert np.allclose(np.hypot(*xy[outer].T), 1.0)
    assert np.allclose(xy[sym, 0], 0.0) and np.allclose(xy[top, 1], 0.0)
    assert xy[outer[0]] == pytest.approx([0.0, -1.0])


def test_master_segments_under_every_slave_segment() -> None:
    xy, _, _, _, outer = kratos.cylinder_q4("m3", 1)
    sx = xy[outer, 0]
    mx = kratos.master_x(sx)
    assert (np.diff(mx) > 0).all() and mx[0] < 0 < mx[-1] and mx[-1] >= 0.35
    near = sx[sx < 0.2]
    assert np.isin(near, mx).all()


def test_nodal_pressure_recovers_a_consistent_load() -> None:
    """Consistent nodal forces of p(s) = 1 + s on a graded polyline (the integrals of the
    linear shape functions) give back p at the nodes up to O(h^2) of the lumping, exact for a
    uniform pressure; round-off forces count as zero."""
    s = np.cumsum(np.concatenate([[0.0], np.linspace(0.01, 0.03, 20)]))
    ref = np.column_stack([s, np.zeros_like(s)])
    f = np.zeros_like(s)
    h = np.diff(s)
    f[:-1] += h / 2
    f[1:] += h / 2
    assert kratos.nodal_pressure(ref, -f) == pytest.approx(np.ones_like(s))
    lin = 1 + s
    f = np.zeros_like(s)
    f[:-1] += h * (2 * lin[:-1] + lin[1:]) / 6
    f[1:] += h * (lin[:-1] + 2 * lin[1:]) / 6
    p = kratos.nodal_pressure(ref, -f)
    assert p[1:-1] == pytest.approx(lin[1:-1], abs=1e-3)
    f[5] = 1e-20
    assert kratos.nodal_pressure(ref, -f)[5] == 0.0


@pytest.mark.skipif(not kratos.kratos_available(),
                    reason="Kratos is not installed in build/kratos-venv (make bench installs it)")
def test_kratos_hertz_m4_penalty(tmp_path: Path) -> None:
    """Kratos's mortar penalty on hertz m4 (Q4, 7,008 DOFs) against analytic Hertz, as
    measured when the section was written: L2 1.30 %, half-width and peak of the fit
    within 0.2 %; the force of the recovered pressure is the reaction."""
    from bench.run import Workdir
    r = kratos.kratos_once(kratos.venv_python(), Workdir(tmp_path / "w"), ("penalty", "m4", 1))
    assert r["dofs"] == 7008
    assert len(r["iterations"]) == kratos.N_STEPS
    assert 0.004 < r["force"] < 0.006
    assert r["contact_force"] == pytest.approx(r["force"], rel=1e-3)
    assert r["l2"] < 0.015
    assert abs(r["a_error"]) < 0.003 and abs(r["p0_error"]) < 0.003


def test_section_skipped_with_a_message_when_the_venv_cannot_be_made(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture) -> None:
    """No network needed: the venv step itself fails (its python is /bin/false)."""
    monkeypatch.setattr(kratos, "VENV", tmp_path / "venv")
    monkeypatch.setattr(kratos.sys, "executable", "/bin/false")
    assert kratos.ensure_kratos() is None
    assert "skipping Kratos" in capsys.readouterr().out
