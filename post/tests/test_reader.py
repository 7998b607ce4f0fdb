"""post.reader on result files written by voiga: shapes, natural order,
0-based ids, statuses (converged, failed, running), exact step values."""

from __future__ import annotations

import concurrent.futures
import shutil
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from post.reader import STAGES, body_displacement, decode, reaction_history, read_result

from .conftest import CASES, DIE_SHIFT, NU, STRAIN, exact_stretch

TOL = 1e-12


def test_decode() -> None:
    assert decode(np.bytes_(b"converged")) == "converged"
    assert decode(b"slab   ") == "slab"  # Fortran blank padding
    assert decode("title\x00\x00") == "title"  # variable-length / NUL padding
    assert decode(np.array([7], dtype=np.int32)) == 7 and isinstance(decode(np.int32(7)), int)
    assert decode(np.float64(0.5)) == 0.5 and isinstance(decode(np.float64(0.5)), float)


def test_root_attrs_and_steps(stretch_h5: Path) -> None:
    r = read_result(stretch_h5)
    assert r.title == "slab stretch" and r.status == "converged" and r.converged
    assert not r.failed and r.failure_reason is None
    assert isinstance(r.voiga_version, str) and r.voiga_version
    assert r.case_file.endswith("case.nml")
    assert (r.n_steps_planned, r.n_steps_done, len(r.steps)) == (2, 2, 2)
    assert r.wall_time > 0 and all(isinstance(v, (str, int, float)) for v in r.attrs.values())
    assert r.n_dofs == 112
    assert [s.step for s in r.steps] == [1, 2]
    assert [s.time for s in r.steps] == pytest.approx([0.5, 1.0], abs=1e-15)
    for s in r.steps:
        assert s.displacement.shape == (112,)
        assert s.residual_norms.shape == (s.iterations + 1,)
        assert s.energy_norms.shape == (s.iterations,)
        assert s.reactions.shape == (3, 2)
        assert set(s.seconds) == set(STAGES) and min(s.seconds.values()) >= 0


def test_body_natural_order(stretch_h5: Path) -> None:
    r = read_result(stretch_h5)
    assert list(r.bodies) == ["slab"]
    b = r.bodies["slab"]
    assert (b.material, b.youngs_modulus, b.poisson_ratio, b.dof_offset) == ("linear", 1.0, NU, 0)
    # 8 x 2 quadratic elements: 10 x 4 bulk points, the last row replaced by 26 layer points
    assert b.bulk.degree == (2, 2) and b.bulk.control_points.shape == (4, 10, 2)
    assert b.bulk.weights.shape == (4, 10)
    assert b.layer is not None and b.layer.control_points.shape == (26, 2)
    assert b.layer.degree == 4
    assert b.ncp == 3 * 10 + 26 and b.control_points.shape == (56, 2) and b.weights.shape == (56,)
    assert b.dofs == slice(0, 112)
    assert b.attrs["total_dofs"] == 112 and b.attrs["n_elements"] == b.n_elements == 16
    # natural order: bulk rows xi fastest, then the layer
    np.testing.assert_array_equal(b.control_points[:30], b.bulk.control_points[:3].reshape(-1, 2))
    np.testing.assert_array_equal(b.control_points[30:], b.layer.control_points)
    np.testing.assert_array_equal(b.weights[:30], b.bulk.weights[:3].reshape(-1))
    np.testing.assert_array_equal(b.weights[30:], b.layer.weights)
    # reference slab [0, 9] x [-3, 0]: x grows along xi, y along eta
    assert b.control_points[:, 0].min() == 0 and b.control_points[:, 0].max() == 9
    assert np.all(np.diff(b.bulk.control_points[0, :, 0]) > 0)
    assert np.all(np.diff(b.bulk.control_points[:, 0, 1]) > 0)


def test_elements_and_edges_are_zero_based(stretch_h5: Path) -> None:
    b = read_result(stretch_h5).bodies["slab"]
    assert b.element_ptr[0] == 0 and b.element_ptr[-1] == len(b.element_conn)
    assert b.element_conn.min() == 0 and b.element_conn.max() == b.ncp - 1
    assert b.element_ranges.shape == (16, 4) and b.element_vo.shape == (16,)
    assert b.element_vo.dtype == bool
    # the contact row (eta in [0.5, 1]) is the VO row
    np.testing.assert_array_equal(b.element_vo, b.element_ranges[:, 2] >= 0.5)
    r0 = b.element_ranges[0]
    np.testing.assert_allclose(r0, [0.0, 0.125, 0.0, 0.5], atol=1e-15)
    assert np.all(b.element_ranges[:, 1] > b.element_ranges[:, 0])
    # first element: 3 x 3 bulk tensor products, xi fastest (ids 0, 1, 2, 10, ...)
    np.testing.assert_array_equal(b.element(0), [0, 1, 2, 10, 11, 12, 20, 21, 22])
    # a VO element: (p_xi + 1) p_eta bulk functions, then q + 1 = 5 layer functions
    k = int(np.flatnonzero(b.element_vo)[0])
    ids = b.element(k)
    assert len(ids) == 3 * 2 + 5 and np.all(ids[:6] < 30) and np.all(ids[6:] >= 30)
    assert set(b.edges) == {"left", "right", "bottom", "top"}
    np.testing.assert_array_equal(b.edges["bottom"], np.arange(10))
    np.testing.assert_array_equal(b.edges["top"], np.arange(30, 56))
    np.testing.assert_array_equal(b.edges["left"], [0, 10, 20, 30])
    np.testing.assert_array_equal(b.edges["right"], [9, 19, 29, 55])
    assert np.all(b.control_points[b.edges["left"], 0] == 0)
    assert np.all(b.control_points[b.edges["top"], 1] == 0)


def test_stretch_displacement_is_exact(stretch_h5: Path) -> None:
    """Control point displacements equal the exact linear field at the control
    points (NURBS are affinely invariant)."""
    r = read_result(stretch_h5)
    b = r.bodies["slab"]
    for k, s in enumerate(r.steps):
        u = body_displacement(r, "slab", s.step)
        assert u.shape == (56, 2)
        err = np.abs(u - exact_stretch(b.control_points, s.time)).max()
        assert err <= TOL, f"step {s.step}: {err:.3e}"
        np.testing.assert_array_equal(body_displacement(r, b, k - len(r.steps)), u)
    np.testing.assert_array_equal(body_displacement(r, "slab"), body_displacement(r, "slab", 2))
    np.testing.assert_array_equal(body_displacement(r, "slab", 0), np.zeros((56, 2)))
    with pytest.raises(IndexError):
        body_displacement(r, "slab", 3)
    with pytest.raises(IndexError):
        body_displacement(r, "slab", -3)
    with pytest.raises(KeyError):
        body_displacement(r, "die")


def test_reaction_history(stretch_h5: Path) -> None:
    """Plane strain, sigma_yy = 0: the right edge carries E/(1 - nu^2) eps_xx
    times the height 3, the left edge the opposite, the bottom nothing."""
    r = read_result(stretch_h5)
    assert [(d.body, d.edge) for d in r.dirichlet] == [("slab", "left"), ("slab", "bottom"),
                                                        ("slab", "right")]
    right = r.dirichlet_index("slab", "right")
    times, f = reaction_history(r, right)
    np.testing.assert_allclose(times, [0.5, 1.0], atol=1e-15)
    assert f.shape == (2, 2)
    expected = STRAIN * times / (1 - NU ** 2) * 3.0
    np.testing.assert_allclose(f[:, 0], expected, rtol=1e-10)
    np.testing.assert_allclose(reaction_history(r, 0)[1][:, 0], -expected, rtol=1e-10)
    assert np.abs(f[:, 1]).max() < 1e-12 and np.abs(reaction_history(r, 1)[1]).max() < 1e-12
    with pytest.raises(IndexError):
        reaction_history(r, 3)


def test_two_bodies(two_h5: Path) -> None:
    r = read_result(two_h5)
    assert (r.scene, r.mesh, r.layout) == ("ironing", "m1", "mixed")
    assert list(r.bodies) == ["die", "slab"]  # global DOF order
    die, slab = r.bodies["die"], r.bodies["slab"]
    assert die.layer is None and slab.layer is not None
    assert die.ncp == die.bulk.weights.size == 9 * 3
    np.testing.assert_array_equal(die.control_points, die.bulk.control_points.reshape(-1, 2))
    np.testing.assert_array_equal(die.weights, die.bulk.weights.reshape(-1))
    assert die.dof_offset == 0 and slab.dof_offset == 2 * die.ncp
    assert r.n_dofs == 2 * (die.ncp + slab.ncp)
    assert [s.step for s in r.steps] == [1, 2, 3]
    assert [s.time for s in r.steps] == pytest.approx([0.5, 1.0, 2.0], abs=1e-15)
    assert len(r.dirichlet) == 4 and all(s.reactions.shape == (4, 2) for s in r.steps)
    for s in r.steps:  # die: rigid translation, (0.1, -0.05) at t = 1, (0.2, -0.1) at t = 2
        u = body_displacement(r, "die", s.step)
        assert np.abs(u - np.array(DIE_SHIFT) * s.time / 2).max() <= TOL
        u = body_displacement(r, "slab", s.step)
        assert np.abs(u - exact_stretch(slab.control_points, s.time)).max() <= TOL
    # a free rigid body carries no reaction
    assert np.abs(reaction_history(r, 0)[1]).max() < 1e-10


def test_failed_run_keeps_converged_steps(crush_h5: Path) -> None:
    r = read_result(crush_h5)
    assert r.failed and not r.converged and r.status.startswith("failed: ")
    assert r.failure_reason  # the solver's message (e.g. "step 2 ...: inverted")
    assert r.n_steps_planned == 2 and r.n_steps_done == 1
    assert [s.step for s in r.steps] == [1]
    assert body_displacement(r, "slab").shape == (56, 2)


def test_running_file(running_h5: Path) -> None:
    r = read_result(running_h5)
    assert r.status == "running" and not r.converged and not r.failed
    assert [s.step for s in r.steps] == [1] and r.n_steps_done == 1


def test_read_waits_for_a_step_being_written(running_h5: Path) -> None:
    """voiga holds an exclusive flock on the file while it writes a step (docs/hdf5.md):
    a read waits for it, whatever HDF5_USE_FILE_LOCKING says, and then reads the file."""
    code = ("import fcntl, os, sys, time\n"
            "fd = os.open(sys.argv[1], os.O_RDONLY)\n"
            "fcntl.flock(fd, fcntl.LOCK_EX)\n"
            "print('locked', flush=True)\n"
            "sys.stdin.readline()\n"
            "os.close(fd)\n")
    writer = subprocess.Popen([sys.executable, "-c", code, str(running_h5)],
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert writer.stdout.readline().strip() == "locked"
        with concurrent.futures.ThreadPoolExecutor(1) as pool:
            reading = pool.submit(read_result, running_h5)
            # the read cannot finish while the writer holds the lock, however long
            # that is; it does once the writer lets go
            assert not reading.done()
            writer.stdin.write("go\n")
            writer.stdin.flush()
            r = reading.result(timeout=60)
    finally:
        writer.kill()
        writer.wait()
    assert [s.step for s in r.steps] == [1]


def test_incomplete_step_is_skipped(running_h5: Path) -> None:
    with h5py.File(running_h5, "r+") as f:
        g = f.create_group("steps/000002")
        g.attrs["step"] = np.int32(2)
    with pytest.warns(UserWarning, match="000002"):
        r = read_result(running_h5)
    assert [s.step for s in r.steps] == [1]


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError):
        read_result(tmp_path / "nothing.h5")


@pytest.fixture(scope="module")
def hertz_h5(voiga: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Result of the committed case hertz m1 N2 (rigid flat, 5 steps, contact output)."""
    folder = tmp_path_factory.mktemp("hertz")
    for name in ("geometry.h5", "m1-N2.nml"):
        shutil.copy(CASES / "hertz" / name, folder / name)
    subprocess.run([str(voiga), "m1-N2.nml", "--quiet"], cwd=folder, check=True, timeout=120,
                   capture_output=True, stdin=subprocess.DEVNULL)
    return folder / "m1-N2.h5"


@pytest.mark.parametrize("which", ["two", "hertz"])
def test_lazy_read_gives_the_same_values(which: str, request: pytest.FixtureRequest) -> None:
    """read_result(lazy=True) reads the summary's scalars and the reactions of every
    step at once and the rest of a step on first use; every value equals the eager read."""
    path = request.getfixturevalue(f"{which}_h5")
    eager, lazy = read_result(path), read_result(path, lazy=True)
    assert lazy.attrs == eager.attrs and list(lazy.bodies) == list(eager.bodies)
    assert [s.step for s in lazy.steps] == [s.step for s in eager.steps]
    assert len(eager.steps) == {"two": 3, "hertz": 5}[which]
    for a, b in zip(lazy.steps, eager.steps, strict=True):
        assert (a.iterations, a.cuts, a.seconds) == (b.iterations, b.cuts, b.seconds)
        np.testing.assert_array_equal(a.reactions, b.reactions)
        assert not a._data  # nothing else read yet
    for a, b in zip(lazy.steps, eager.steps, strict=True):
        np.testing.assert_array_equal(a.displacement, b.displacement)
        assert (a.time, a.substeps) == (b.time, b.substeps)
        np.testing.assert_array_equal(a.residual_norms, b.residual_norms)
        np.testing.assert_array_equal(a.energy_norms, b.energy_norms)
        assert len(a.contact) == len(b.contact) == {"two": 0, "hertz": 1}[which]
        for ca, cb in zip(a.contact, b.contact, strict=True):
            assert (ca.slave, ca.master, ca.attrs) == (cb.slave, cb.master, cb.attrs)
            for key in ("force", "xi_slave", "x_ref", "x", "gap", "p_n", "p_t", "xi_master", "state"):
                np.testing.assert_array_equal(getattr(ca, key), getattr(cb, key))
    for name in eager.bodies:
        np.testing.assert_array_equal(body_displacement(lazy, name), body_displacement(eager, name))
    for k in range(len(eager.dirichlet)):
        for x, y in zip(reaction_history(lazy, k), reaction_history(eager, k), strict=True):
            np.testing.assert_array_equal(x, y)


def test_lazy_read_checks_the_displacement_when_used(two_h5: Path, tmp_path: Path) -> None:
    """A lazy read defers the displacement-length check of a step to its first use."""
    path = tmp_path / "short.h5"
    shutil.copy(two_h5, path)
    with h5py.File(path, "r+") as f:
        d = f["steps/000002/displacement"][()]
        del f["steps/000002/displacement"]
        f["steps/000002/displacement"] = d[:-2]
    with pytest.raises(ValueError, match="displacement has"):
        read_result(path)
    res = read_result(path, lazy=True)
    assert len(res.steps[0].displacement) == res.n_dofs
    with pytest.raises(ValueError, match="displacement has"):
        _ = res.steps[1].displacement


def _damaged(source: Path, folder: Path, edit) -> Path:
    path = folder / "bad.h5"
    shutil.copy(source, path)
    with h5py.File(path, "r+") as f:
        edit(f)
    return path


def _poison(f: h5py.File, key: str) -> None:
    data = f[key][()].astype(float)
    data.reshape(-1)[0] = np.nan
    f[key][...] = data


@pytest.mark.parametrize("key", ["steps/000002/displacement", "steps/000002/reactions",
                                 "bodies/slab/control_points", "bodies/slab/weights"])
@pytest.mark.parametrize("command", ["summary", "vtk", "plot-deformed", "history"])
def test_non_finite_result_data_refused(two_h5: Path, tmp_path: Path, key: str, command: str) -> None:
    """Issue 36: a result whose displacements are NaN was accepted with exit 0 (vtk
    wrote NaN, plot-deformed failed with 'max() arg is an empty sequence'). voiga
    writes no such value: exit 2, one line naming the dataset, nothing written."""
    path = _damaged(two_h5, tmp_path, lambda f: _poison(f, key))
    res = subprocess.run([sys.executable, "-m", "post", command, str(path), *([] if command == "summary" else
                          ["--out", str(tmp_path / "out")])], capture_output=True, text=True, timeout=120)
    assert res.returncode == 2, res.stderr
    assert res.stderr.count("\n") == 1 and f"/{key}" in res.stderr and "non-finite" in res.stderr, res.stderr
    assert not (tmp_path / "out").exists() or not list((tmp_path / "out").iterdir())


@pytest.mark.parametrize("attr,value,words", [("n_steps_done", -5, "n_steps_done = -5: not a count"),
                                              ("n_steps_planned", -1, "n_steps_planned = -1"),
                                              ("n_dofs", -3, "n_dofs = -3"),
                                              ("n_steps_done", 99, "exceeds n_steps_planned")])
def test_impossible_counters_refused(two_h5: Path, tmp_path: Path, attr: str, value: int, words: str) -> None:
    """Issue 36: n_steps_done = -5 was read with a note, as a run with no step."""
    path = _damaged(two_h5, tmp_path, lambda f: f.attrs.__setitem__(attr, np.int32(value)))
    res = subprocess.run([sys.executable, "-m", "post", "summary", str(path)], capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 2 and words in res.stderr and res.stderr.count("\n") == 1, res.stderr


def test_dimension_from_the_file(stretch_h5: Path, tmp_path: Path) -> None:
    """Issue 37 item 5: a result carries its spatial dimension (root attribute
    ``dimension``, 2 here); a file without it (an older voiga's) is read as 2D with the
    same values; one that names no spatial dimension is refused naming it."""
    with h5py.File(stretch_h5) as f:
        assert f.attrs["dimension"] == 2 and f.attrs["dimension"].dtype.kind == "i"
    r = read_result(stretch_h5)
    assert r.dimension == 2 and r.axes == ("x", "y")
    assert all(b.nsd == 2 for b in r.bodies.values())
    older = read_result(_damaged(stretch_h5, tmp_path, lambda f: f.attrs.__delitem__("dimension")))
    assert "dimension" not in older.attrs and older.dimension == 2
    np.testing.assert_array_equal(body_displacement(older, "slab"), body_displacement(r, "slab"))
    np.testing.assert_array_equal(older.steps[-1].reactions, r.steps[-1].reactions)
    summary = subprocess.run([sys.executable, "-m", "post", "summary", str(stretch_h5)], capture_output=True,
                             text=True, timeout=120)
    assert summary.returncode == 0 and "112 DOFs (2D)" in summary.stdout, summary.stdout + summary.stderr
    path = _damaged(stretch_h5, tmp_path, lambda f: f.attrs.__setitem__("dimension", np.int32(5)))
    res = subprocess.run([sys.executable, "-m", "post", "summary", str(path)], capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 2 and "dimension = 5" in res.stderr and res.stderr.count("\n") == 1, res.stderr
