"""Contact on a solid's face (issue 42: GPTS, mortar and ALM, with and without friction,
and frictionless segment, against a rigid plane or another solid) through the command
line. A box pressed onto a rigid plane by a uniform pressure on its top carries that
pressure uniformly (the contact patch test against a rigid flat, which every method must
pass), and slid along the plane carries mu times it (the frictional methods; a mortar run
cut and continued with --restart reproduces the uncut one); the sphere of `pre hertz3d` runs
and its result reads in `post hertz3d` with its contact force equal to the integral of
the pressure; what is not implemented on faces yet is refused with its cause named."""
from __future__ import annotations

import subprocess
from pathlib import Path

import h5py
import numpy as np
import pytest

from pre.solids import box, write_volumes
from test_restart import truncate

P = 0.01

CASE = """&case
  title = 'box on a plane', geometry = 'geometry.h5', output = 'box.h5', n_bodies = 1
/
&body
  name = 'block', material = '{material}', youngs_modulus = 1.0, poisson_ratio = 0.3,
  degree_xi = 2, degree_eta = 2, degree_zeta = 2, nel_xi = 3, nel_eta = 2, nel_zeta = 2,
  contact_face = 'bottom', layer_degree = {q}, layer_elevations = {k}
/
&solver
  n_steps = 2
/
&dirichlet
  body = 'block', face = 'left', fix_x = .true.
/
&dirichlet
  body = 'block', face = 'front', fix_y = .true.
/
&pressure
  body = 'block', face = 'top', p = {p}
/
&contact
  slave = 'block', master = 'rigid'{contact}
/
"""

PLANE = ", rigid_point = 0.0, 0.0, 0.0, rigid_normal = 0.0, 0.0, 1.0"


def box_case(tmp: Path, contact: str = PLANE + ", method = 'gpts'", material: str = "linear", q: int = 0,
             k: int = 0, p: float = P) -> Path:
    """The box [0, 2] x [0, 1] x [0, 1] on the plane z = 0, pressed by `p` on its top,
    held in x and y by its symmetry planes x = 0 and y = 0 (frictionless contact
    cannot hold it there)."""
    write_volumes(tmp / "geometry.h5", {"block": box((0.0, 2.0), (0.0, 1.0), (0.0, 1.0))})
    case = tmp / "box.nml"
    case.write_text(CASE.format(material=material, q=q, k=k, p=p, contact=contact))
    return case


def run(voiga_bin: Path, case: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(voiga_bin), str(case), "--quiet", *args], capture_output=True, text=True,
                          timeout=300)


def last_contact(path: Path) -> dict[str, np.ndarray]:
    with h5py.File(path) as f:
        step = sorted(f["steps"])[-1]
        g = f[f"steps/{step}/contact/1"]
        return {name: g[name][()] for name in g if isinstance(g[name], h5py.Dataset)}


@pytest.mark.parametrize("method", ["gpts", "mortar", "alm", "segment"])
@pytest.mark.parametrize("layer", [(0, 0), (3, 1)])
def test_uniform_pressure_on_a_plane(voiga_bin: Path, tmp_path: Path, method: str, layer: tuple[int, int]) -> None:
    """Linear: the uniform state is the discrete solution, so every point carries p to
    round-off (N2, and NN3.1 with its layer on the contact face), and the contact force
    is p times the area, along the plane's normal. ALM (frictionless on faces) closes the
    gap: below its tolerance, 1e-6 of the cells' size (1/3 is below every cell's longer
    chord), where the penalty methods leave p / penalty_normal; its multipliers (history
    `multiplier`, nominal pressures per control point) are p, one update per step."""
    res = run(voiga_bin, box_case(tmp_path, PLANE + f", method = '{method}'", q=layer[0], k=layer[1]))
    assert res.returncode == 0, res.stderr
    c = last_contact(tmp_path / "box.h5")
    p = c["p_n_nominal"]
    assert c["x_ref"].shape == (p.size, 3) and c["xi_slave"].shape == (p.size, 2)
    assert np.all(c["state"] == 1)
    assert (p.max() - p.min()) / P < 1e-10
    assert abs(p.mean() / P - 1.0) < 1e-10
    assert np.allclose(c["force"], [0.0, 0.0, 2.0 * P], atol=1e-13, rtol=1e-10)
    assert abs(c["area_ref"].sum() - 2.0) < 1e-12
    if method == "alm":
        assert np.abs(c["gap"]).max() < 1e-6 / 3
        with h5py.File(tmp_path / "box.h5") as f:
            multiplier = f[f"steps/{sorted(f['steps'])[-1]}/contact/1/history/multiplier"][()]
            assert int(f.attrs["multiplier_updates"]) == 2
        assert np.allclose(multiplier, P, rtol=1e-10, atol=0.0)
    elif method == "mortar":
        assert np.abs(c["gap"]).max() > 1e-6


@pytest.mark.parametrize("method", ["mortar", "segment"])
def test_uniform_pressure_finite_strain(voiga_bin: Path, tmp_path: Path, method: str) -> None:
    """Neo-Hookean, pressed by 20 % of E: the box spreads laterally (stretch > 1 of the
    contact face's area), the pressure per reference area stays uniform, and its
    integral is the load (a dead pressure on the top, which spreads as the bottom)."""
    res = run(voiga_bin, box_case(tmp_path, PLANE + f", method = '{method}'", material="neo-hookean", p=0.2))
    assert res.returncode == 0, res.stderr
    c = last_contact(tmp_path / "box.h5")
    p = c["p_n_nominal"]
    assert (p.max() - p.min()) / p.mean() < 1e-8
    assert abs((p * c["area_ref"]).sum() - c["force"][2]) < 1e-10
    assert abs(c["force"][2] - 0.4) < 1e-8
    assert c["stretch"].min() > 1.05


def test_default_normal_is_z(voiga_bin: Path, tmp_path: Path) -> None:
    """No rigid_normal in a solid case: the plane's outward normal is +z."""
    res = run(voiga_bin, box_case(tmp_path, ", rigid_point = 0.0, 0.0, 0.0"))
    assert res.returncode == 0, res.stderr
    assert np.allclose(last_contact(tmp_path / "box.h5")["rigid_normal"], [0.0, 0.0, 1.0])


@pytest.mark.parametrize(("contact", "message"), [
    (", rigid_point = 0.0, 0.0, 0.0, rigid_normal = 0.0, 1.0", "rigid_normal needs 3 components"),
    (", rigid_point = 0.0, 0.0", "rigid_point needs 3 components"),
    (", rigid_curve = 'arc'", "in a solid case use rigid_surface"),
    (", rigid_surface = 'arc'", "geometry.h5: no surface 'arc' (group /surfaces/arc is missing)"),
])
def test_refused_with_the_cause(voiga_bin: Path, tmp_path: Path, contact: str, message: str) -> None:
    res = run(voiga_bin, box_case(tmp_path, contact), "--check")
    assert res.returncode != 0
    assert message in res.stderr, res.stderr
    assert not (tmp_path / "box.h5").exists()


def test_rigid_uz_in_a_plane_case(voiga_bin: Path, tmp_path: Path) -> None:
    """rigid_uz moves a rigid master along z: a plane case has none."""
    case = Path(__file__).resolve().parents[2] / "cases" / "hertz" / "m1-N2.nml"
    text = case.read_text().replace("  method = 'gpts'", "  method = 'gpts'\n  rigid_uz = 0.1")
    (tmp_path / "c.nml").write_text(text.replace("geometry = 'geometry.h5'", f"geometry = '{case.parent}/geometry.h5'"))
    res = run(voiga_bin, tmp_path / "c.nml", "--check")
    assert res.returncode != 0 and "a plane case has no z" in res.stderr, res.stderr


def test_hertz3d_runs_and_reads(voiga_bin: Path, tmp_path: Path) -> None:
    """`pre hertz3d` m1 N2 with mortar: the run converges, the contact force is the
    integral of the nominal pressure over the reference area, and `post hertz3d`
    reads the result (its numbers are in docs/verification.md)."""
    out = tmp_path / "h"
    subprocess.run(["python3", "-m", "pre", "hertz3d", str(out), "--mesh", "m1", "--layout", "N2", "--method",
                    "mortar"], check=True, capture_output=True, cwd=Path(__file__).resolve().parents[2])
    case = out / "m1-N2.nml"
    res = run(voiga_bin, case)
    assert res.returncode == 0, res.stderr
    c = last_contact(out / "m1-N2.h5")
    assert abs((c["p_n_nominal"] * c["area_ref"]).sum() - c["force"][2]) < 1e-10 * c["force"][2]
    post = subprocess.run(["python3", "-m", "post", "hertz3d", str(out / "m1-N2.h5"), "--no-figure"],
                          capture_output=True, text=True, cwd=Path(__file__).resolve().parents[2])
    assert post.returncode == 0, post.stderr
    assert "relative L2 error of p" in post.stdout


@pytest.mark.parametrize("indentation, tau_tol", [(0.01, 0.05), (0.000625, 0.01)])
def test_hertz3d_polar_grid_meets_hertz(voiga_bin: Path, tmp_path: Path, indentation: float,
                                        tau_tol: float) -> None:
    """`pre hertz3d --grid polar` p4 N2 (9,576 DOFs), knot lines along the zone's edge: the
    final pressure within 1 % (L2) of Hertz and the fitted half-width within 0.5 %, issue
    42's line that the Cartesian grids miss (2.2 % at 60,000 DOFs); measured 0.47 % and
    +0.05 % at a/R = 0.10, 0.41 % and +0.07 % at 0.025 (0.41 to 0.87 % in between; p2
    gives 0.83 % at 0.10 but 1.6 % at 0.025). The subsurface shear is sampled on the collapsed axis (1 % into
    its elements, where 1e-6 gave 14 p0) and its largest value is Hertz's within 5 % at
    a/R = 0.10 and 1 % at 0.025: the finite ball's departure, -3.6 %, -1.4 %, -0.1 % at
    a/R = 0.10, 0.05, 0.025 on p4, not the mesh's (radial refinement leaves it)."""
    from post.hertz3d import hertz3d_comparison
    from post.reader import read_result

    out = tmp_path / "p"
    subprocess.run(["python3", "-m", "pre", "hertz3d", str(out), "--grid", "polar", "--mesh", "p4", "--layout",
                    "N2", "--indentation", str(indentation)],
                   check=True, capture_output=True, cwd=Path(__file__).resolve().parents[2])
    res = run(voiga_bin, out / "p4-N2.nml")
    assert res.returncode == 0, res.stderr
    h = hertz3d_comparison(read_result(out / "p4-N2.h5"))
    assert h.error.l2 < 0.01, h.error
    assert abs(h.a_error) < 0.005, h.a_error
    assert h.shear is not None and h.shear.axis_samples > 10, h.shear_note
    assert abs(h.shear.tau_max / h.tau_hertz - 1.0) < tau_tol, (h.shear.tau_max, h.tau_hertz)


def test_hertz3d_polar_alm_any_penalty(voiga_bin: Path, tmp_path: Path) -> None:
    """`pre hertz3d --grid polar` p2 N2 with ALM (frictionless on the face): the pressure
    within 1 % (L2) of Hertz (measured 0.90 %; mortar 0.83 % with the automatic penalty,
    1.55 % at a tenth of it, 0.89 % at ten times), and the same pressure, to 1e-8 p0,
    with the automatic penalty, a tenth of it and ten times it (measured 2e-10 p0),
    where the penalty method's moves by 2.5 % p0; one or two multiplier updates a step."""
    from post.hertz3d import hertz3d_comparison
    from post.reader import read_result

    root = Path(__file__).resolve().parents[2]
    pressures = []
    automatic = 0.0  # the automatic penalty, read from the first run's result
    for i, factor in enumerate([None, 0.1, 10.0]):
        out = tmp_path / f"h{i}"
        extra = [] if factor is None else ["--penalty-normal", repr(factor * automatic)]
        subprocess.run(["python3", "-m", "pre", "hertz3d", str(out), "--grid", "polar", "--mesh", "p2", "--layout",
                        "N2", "--method", "alm", *extra], check=True, capture_output=True, cwd=root)
        res = run(voiga_bin, out / "p2-N2.nml")
        assert res.returncode == 0, res.stderr
        with h5py.File(out / "p2-N2.h5") as f:
            group = f[f"steps/{sorted(f['steps'])[-1]}/contact/1"]
            if factor is None:
                automatic = float(group.attrs["penalty_normal"])
            assert group.attrs["method"].decode().strip() == "alm"
            assert 5 <= int(f.attrs["multiplier_updates"]) <= 10
        h = hertz3d_comparison(read_result(out / "p2-N2.h5"))
        assert h.error.l2 < 0.01, h.error
        pressures.append((last_contact(out / "p2-N2.h5")["p_n_nominal"], h.p0))
    for p, p0 in pressures[1:]:
        assert np.abs(p - pressures[0][0]).max() < 1e-8 * p0


def test_hertz3d_polar_ball_on_a_block(voiga_bin: Path, tmp_path: Path) -> None:
    """`pre hertz3d --grid polar --master block` p3 N2 (13,608 DOFs: the ball and a quarter
    cylinder under it, both with knot lines along the zone's edge, their faces not
    matching): the ball's pressure within 1.5 % of Hertz for two equal bodies, issue 42's
    line for the sphere on an elastic block (measured 0.73 %, a +0.11 %; the Cartesian
    grids' best was 3.9 %)."""
    from post.hertz3d import hertz3d_comparison
    from post.reader import read_result

    out = tmp_path / "b"
    subprocess.run(["python3", "-m", "pre", "hertz3d", str(out), "--grid", "polar", "--master", "block", "--mesh",
                    "p3", "--layout", "N2"], check=True, capture_output=True, cwd=Path(__file__).resolve().parents[2])
    res = run(voiga_bin, out / "p3-N2.nml")
    assert res.returncode == 0, res.stderr
    h = hertz3d_comparison(read_result(out / "p3-N2.h5"))
    assert h.master is not None and h.e_star == pytest.approx(1.0 / (2 * (1 - 0.3**2)))
    assert h.error.l2 < 0.015, h.error
    assert abs(h.a_error) < 0.005, h.a_error


BLOCKS = """&case
  title = 'blocks', geometry = 'geometry.h5', output = 'blocks.h5', n_bodies = 2
/
&body
  name = 'upper', material = 'linear', youngs_modulus = 1.0, poisson_ratio = 0.3,
  degree_xi = 2, degree_eta = 2, degree_zeta = 2, nel_xi = 3, nel_eta = 2, nel_zeta = 2,
  contact_face = 'bottom'
/
&body
  name = 'lower', material = 'linear', youngs_modulus = 1.0, poisson_ratio = 0.3,
  degree_xi = 2, degree_eta = 2, degree_zeta = 2, nel_xi = {nx}, nel_eta = {ny}, nel_zeta = 2,
  contact_face = 'top'
/
&solver
  n_steps = 1
/
&dirichlet
  body = 'upper', face = 'left', fix_x = .true.
/
&dirichlet
  body = 'upper', face = 'front', fix_y = .true.
/
&dirichlet
  body = 'lower', face = 'left', fix_x = .true.
/
&dirichlet
  body = 'lower', face = 'front', fix_y = .true.
/
&dirichlet
  body = 'lower', face = 'bottom', fix_z = .true.
/
&pressure
  body = 'upper', face = 'top', p = 0.01
/
&contact
  slave = 'upper', master = 'lower'{method}
/
"""


def blocks_spread(voiga_bin: Path, tmp: Path, nx: int, ny: int, method: str) -> tuple[float, np.ndarray]:
    """The contact patch test between solids: the block [0, 2] x [0, 1] x [0, 1] (3 x 2
    cells on its bottom face) pressed by 0.01 onto the block below it (`nx` x `ny`
    cells on its top face); (max - min) / mean of the slave points' pressure, and the
    contact force."""
    write_volumes(tmp / "geometry.h5", {"upper": box((0.0, 2.0), (0.0, 1.0), (0.0, 1.0)),
                                        "lower": box((0.0, 2.0), (0.0, 1.0), (-1.0, 0.0))})
    case = tmp / "blocks.nml"
    case.write_text(BLOCKS.format(nx=nx, ny=ny, method=method))
    res = run(voiga_bin, case)
    assert res.returncode == 0, res.stderr
    c = last_contact(tmp / "blocks.h5")
    p = c["p_n_nominal"]
    return (p.max() - p.min()) / p.mean(), c["force"]


@pytest.mark.parametrize("method", ["", ", method = 'gpts'", ", method = 'alm'", ", method = 'segment'"])
def test_blocks_matching_faces(voiga_bin: Path, tmp_path: Path, method: str) -> None:
    """Matching faces: every method (the default on solids is mortar) passes the
    contact patch test to round-off, and the force is the load; ALM closes the gap
    (below its tolerance, 1e-6 of the cells' size: 1/3 is below their longer chord)."""
    spread, force = blocks_spread(voiga_bin, tmp_path, 3, 2, method)
    assert spread < 1e-12
    assert np.allclose(force, [0.0, 0.0, 0.02], atol=1e-15, rtol=1e-12)
    if "alm" in method:
        assert np.abs(last_contact(tmp_path / "blocks.h5")["gap"]).max() < 1e-6 / 3


def test_blocks_non_matching_faces(voiga_bin: Path, tmp_path: Path) -> None:
    """Non-matching faces (3 x 2 cells on 5 x 3): GPTS and mortar carry the load, but
    their pressure is off by the quadrature error of the master's kinks inside slave
    cells, as in 2D (docs/verification-faces.md): mortar's spread is below GPTS's and
    falls with the points per cell. ALM enforces the same weighted gaps exactly, so its
    spread is that quadrature error without the penalty's compliance to smooth it
    (measured 2.3 % at 3 points where mortar's is 1.5 %) and falls with the points too
    (0.09 % at 9). Segment integrates each slave cell on the pieces
    the master's cells cut from it and passes the contact patch test (issue 42: spread
    <= 1e-6; measured 2e-14), with its default points (5 per direction, exact for
    N_A N_B) and with 3 (exact for the degree-4 functions the patch test integrates)."""
    spreads = {}
    for method, n in [("gpts", 3), ("mortar", 3), ("mortar", 6), ("mortar", 9), ("alm", 3), ("alm", 9),
                      ("segment", 0), ("segment", 3)]:
        folder = tmp_path / f"{method}{n}"
        folder.mkdir()
        extra = f", method = '{method}'" + (f", n_gauss = {n}" if n else "")
        spread, force = blocks_spread(voiga_bin, folder, 5, 3, extra)
        # the force is the load: to the penalty's residual (Newton's tolerance) for
        # the inexact methods, to round-off for segment
        assert np.allclose(force, [0.0, 0.0, 0.02], atol=1e-6, rtol=1e-10)
        if method == "segment":
            assert np.allclose(force, [0.0, 0.0, 0.02], atol=1e-15, rtol=1e-10)
        spreads[method, n] = spread
    assert spreads["mortar", 3] < spreads["gpts", 3]
    assert spreads["mortar", 9] < spreads["mortar", 6] < spreads["mortar", 3] < 0.02
    assert spreads["alm", 9] < 0.1 * spreads["alm", 3]
    assert spreads["segment", 0] <= 1e-6 and spreads["segment", 3] <= 1e-6


def test_alm_blocks_any_penalty(voiga_bin: Path, tmp_path: Path) -> None:
    """ALM on faces (non-matching blocks, 3 x 2 cells on 5 x 3): the solution does not
    depend on the penalty, which only regularizes the Newton solves between multiplier
    updates: penalty_normal 10 and 1e4 x E give the same displacement to well below the
    constraint tolerance's 1e-6 x 2/3 (measured 1.2e-9 of the 0.02 displacement), one
    multiplier update per step; the mortar-type penalty's differ by its compliance,
    p / penalty_normal ~ 1e-3."""
    u = {}
    for method in ("alm", "mortar"):
        for eps in (10.0, 1.0e4):
            folder = tmp_path / f"{method}{eps:g}"
            folder.mkdir()
            blocks_spread(voiga_bin, folder, 5, 3, f", method = '{method}', penalty_normal = {eps}")
            with h5py.File(folder / "blocks.h5") as f:
                u[method, eps] = f[f"steps/{sorted(f['steps'])[-1]}/displacement"][()]
                if method == "alm":
                    assert int(f.attrs["multiplier_updates"]) == 1
    assert np.abs(u["alm", 10.0] - u["alm", 1.0e4]).max() < 1e-6 * 2 / 3
    assert np.abs(u["mortar", 10.0] - u["mortar", 1.0e4]).max() > 1e-4


@pytest.mark.parametrize("method", ["gpts", "mortar", "segment", "alm", ""])
def test_sliding_box_carries_mu_p(voiga_bin: Path, tmp_path: Path, method: str) -> None:
    """Coulomb friction on the tangent plane, GPTS, mortar (per control point; the
    default on a solid, with friction as without), segment (mortar's law on points cut at
    the master's cells) and ALM (mortar's law with multiplier references,
    `contact/alm_faces.f90`): the box pressed by 0.01 (phase 1),
    then the plane slid 0.05 along x under it (phase 2). Every point ends slipping, the
    friction force approaches mu F_N along the sliding direction and the transverse one
    (from the press's lateral expansion, held by friction) dies out."""
    given = f", method = '{method}'" if method else ""
    case = box_case(tmp_path, PLANE + given + ", friction = 0.3, rigid_ux = 0.0, 0.05")
    text = case.read_text().replace("n_steps = 2", "n_steps = 2, 4").replace("p = 0.01", "p = 0.01, 0.01")
    case.write_text(text)
    res = run(voiga_bin, case)
    assert res.returncode == 0, res.stderr
    c = last_contact(tmp_path / "box.h5")
    assert np.all(c["state"] == 2)
    fx, fy, fz = c["force"]
    assert abs(fz - 0.02) < 1e-12
    assert abs(fx / fz - 0.3) < 1e-5 and abs(fy / fz) < 1e-3
    assert c["p_t"].shape == (c["p_n"].size, 3)
    # every point carries mu p_n: GPTS exactly; mortar's interpolated control-point vectors
    # up to their directions' spread (the transverse slip's 2e-3 of the sliding one: 6e-8)
    ratio = np.linalg.norm(c["p_t"], axis=1) / c["p_n"]
    assert np.all(ratio <= 0.3 * (1 + 1e-12)) and np.all(ratio >= 0.3 * (1 - 1e-6))
    with h5py.File(tmp_path / "box.h5") as f:
        assert f["steps/000006/contact/1"].attrs["method"].decode().strip() == (method or "mortar")


def test_alm_stick_with_symmetry_planes(voiga_bin: Path, tmp_path: Path) -> None:
    """The box pressed with mu = 2 and ALM: every control point sticks, so the bottom
    face does not spread (measured 7e-16; the penalty methods let it slip elastically by
    t / eps_T: mortar 2.3e-4); one multiplier update per step, although the symmetry planes
    fix 9 of the face's DOFs along sticking directions, which makes 9 of its 60
    constraints dependent (`outer.f90`, `dependent`: the least-squares step)."""
    slide = {}
    for method in ("alm", "mortar"):
        folder = tmp_path / method
        folder.mkdir()
        res = run(voiga_bin, box_case(folder, PLANE + f", method = '{method}', friction = 2.0"))
        assert res.returncode == 0, res.stderr
        c = last_contact(folder / "box.h5")
        assert np.all(c["state"] == 1)
        slide[method] = np.abs((c["x"] - c["x_ref"])[:, :2]).max()
        if method == "alm":
            with h5py.File(folder / "box.h5") as f:
                assert int(f.attrs["multiplier_updates"]) == 2
    # the constraints hold the weighted slips to 1e-6 of the cells' size (1/3 is below
    # their longer chord)
    assert slide["alm"] < 1e-6 / 3 and slide["mortar"] > 1e-5


@pytest.mark.parametrize("method", ["mortar", "segment", "alm"])
def test_mortar_friction_restart(voiga_bin: Path, tmp_path: Path, method: str) -> None:
    """The sliding box with mortar, segment (its points and their friction history re-cut
    at every converged state) or ALM cut after step 4 (sliding, every control point
    carrying a traction vector: the history's `traction`, `traction_y`, `traction_z`;
    ALM's tangential multipliers go on from them, its normal ones are `multiplier`)
    and continued with --restart: the same contact forces, tractions and displacements
    as the run that was not cut."""
    import shutil

    case = box_case(tmp_path, PLANE + f", method = '{method}', friction = 0.3, rigid_ux = 0.0, 0.05")
    case.write_text(case.read_text().replace("n_steps = 2", "n_steps = 2, 4").replace("p = 0.01", "p = 0.01, 0.01"))
    res = run(voiga_bin, case)
    assert res.returncode == 0, res.stderr
    full, partial = tmp_path / "full.h5", tmp_path / "box.h5"
    shutil.copy(partial, full)
    with h5py.File(partial) as f:
        history = f["steps/000004/contact/1/history"]
        assert {"traction", "traction_y", "traction_z", "eta_last"} <= set(history)
        assert np.abs(history["traction"][()]).max() > 0.0
    truncate(partial, 4)
    res = run(voiga_bin, case, "--restart", str(partial))
    assert res.returncode == 0, res.stderr
    with h5py.File(full) as a, h5py.File(partial) as b:
        assert b.attrs["status"] == b"converged" and int(b.attrs["n_steps_done"]) == 6
        for k in a["steps"]:
            for name in ("displacement", "contact/1/force", "contact/1/p_t", "contact/1/p_n"):
                np.testing.assert_allclose(b["steps"][k][name][()], a["steps"][k][name][()], rtol=0, atol=1e-12,
                                           err_msg=f"{k} {name}")


def test_alm_faces_restart(voiga_bin: Path, tmp_path: Path) -> None:
    """`pre hertz3d --grid polar` p1 N2 with ALM cut after step 3 and continued with
    --restart: the continued steps take the uncut run's Newton iterations and give its
    displacements, pressures and multipliers (history `multiplier`, one per control
    point of the face) to 1e-12. Here the multiplier step is exact from any start (a
    linear problem with a fixed active set: zeroed multipliers gave the same to 1.5e-15),
    so that alone does not show they are read back: a file without them is refused,
    naming the dataset."""
    import shutil

    out = tmp_path / "h"
    subprocess.run(["python3", "-m", "pre", "hertz3d", str(out), "--grid", "polar", "--mesh", "p1", "--layout",
                    "N2", "--method", "alm"], check=True, capture_output=True, cwd=Path(__file__).resolve().parents[2])
    case = out / "p1-N2.nml"
    res = run(voiga_bin, case)
    assert res.returncode == 0, res.stderr
    full, partial = out / "full.h5", out / "p1-N2.h5"
    shutil.copy(partial, full)
    with h5py.File(partial) as f:
        multiplier = f["steps/000003/contact/1/history/multiplier"][()]
        assert multiplier.max() > 0.0 and np.count_nonzero(multiplier) < multiplier.size
    truncate(partial, 3)
    res = run(voiga_bin, case, "--restart", str(partial))
    assert res.returncode == 0, res.stderr
    with h5py.File(full) as a, h5py.File(partial) as b:
        assert b.attrs["status"] == b"converged" and int(b.attrs["n_steps_done"]) == 5
        for k in a["steps"]:
            for name in ("displacement", "contact/1/force", "contact/1/p_n", "contact/1/history/multiplier"):
                np.testing.assert_allclose(b["steps"][k][name][()], a["steps"][k][name][()], rtol=0, atol=1e-12,
                                           err_msg=f"{k} {name}")
            for name in ("iterations_total", "cuts"):
                assert b["steps"][k].attrs[name] == a["steps"][k].attrs[name], (k, name)
    shutil.copy(full, partial)
    truncate(partial, 3)
    with h5py.File(partial, "r+") as f:
        del f["steps/000003/contact/1/history/multiplier"]
    res = run(voiga_bin, case, "--restart", str(partial))
    assert res.returncode != 0 and "steps/000003/contact/1/history/multiplier' is missing" in res.stderr, res.stderr


INDENT = """&case
  title = 'sphere into a block', geometry = 'geometry.h5', output = 'indent.h5', n_bodies = 1
/
&body
  name = 'block', material = 'linear', youngs_modulus = 1.0, poisson_ratio = 0.3,
  degree_xi = 2, degree_eta = 2, degree_zeta = 2,
  knots_xi = {knots}, knots_eta = {knots}, nel_zeta = 6, contact_face = 'top'
/
&solver
  n_steps = 4
/
&dirichlet
  body = 'block', face = 'bottom', fix_z = .true.
/
&dirichlet
  body = 'block', face = 'left', fix_x = .true.
/
&dirichlet
  body = 'block', face = 'front', fix_y = .true.
/
&contact
  slave = 'block', master = 'rigid', rigid_surface = 'ball', rigid_uz = -0.01
/
"""


def test_rigid_sphere_indents_a_block(voiga_bin: Path, tmp_path: Path) -> None:
    """A rigid sphere (R = 1, `pre.rigid_surfaces.sphere_cap`, the geometry file's
    /surfaces/ball) moved down 0.01 into a block's top face (a quarter model about the
    sphere's axis, 3.4 cells per contact radius): it converges, the pressure peaks on
    the axis, its integral is the force (less the normal's tilt), and the zone's radius fitted to
    p^2 = p0^2 (1 - r^2/a^2) is Hertz's for the run's own force to 20 % (measured: +13.5 %
    on this coarse mesh, as the sphere's m1 on a plane; verification-faces.md).
    A flat rigid surface acts as the plane to round-off: `fpm test -- rigid_surface`."""
    from pre.rigid_surfaces import add_surfaces, sphere_cap

    write_volumes(tmp_path / "geometry.h5", {"block": box((0.0, 1.0), (0.0, 1.0), (-1.0, 0.0))})
    add_surfaces(str(tmp_path / "geometry.h5"), {"ball": sphere_cap(1.0, (0.0, 0.0, 1.0), 30.0)})
    knots = ", ".join(f"{k:.4f}" for k in [0.03, 0.06, 0.09, 0.12, 0.16, 0.24, 0.4, 0.7])
    case = tmp_path / "indent.nml"
    case.write_text(INDENT.format(knots=knots))
    res = run(voiga_bin, case)
    assert res.returncode == 0, res.stderr
    c = last_contact(tmp_path / "indent.h5")
    x, p = c["x_ref"], c["p_n_nominal"]
    r = np.hypot(x[:, 0], x[:, 1])
    assert r[np.argmax(p)] < 0.03
    # the pressure's integral is the normal force; the normal tilts by up to a / R = 0.1
    assert c["force"][2] < 0.0    # the block is pushed down
    assert 0.99 < abs(c["force"][2]) / (p * c["area_ref"]).sum() <= 1.0
    load = 4.0 * abs(c["force"][2])
    a_hertz = (3.0 * load * 1.0 / (4.0 / (1.0 - 0.3**2))) ** (1.0 / 3.0)
    on = p > 0.0
    c0, c1 = np.linalg.lstsq(np.c_[np.ones(on.sum()), r[on] ** 2], p[on] ** 2, rcond=None)[0]
    assert abs(np.sqrt(-c0 / c1) / a_hertz - 1.0) < 0.2


def test_face_away_from_the_plane_warns(voiga_bin: Path, tmp_path: Path) -> None:
    """The box's top face as the slave of the plane below it: the set-up check names
    the face that faces away (as for an edge in 2D), the remedy, and the plane's side."""
    case = box_case(tmp_path, PLANE + ", method = 'mortar'")
    case.write_text(case.read_text().replace("contact_face = 'bottom'", "contact_face = 'top'")
                    .replace("rigid_point = 0.0, 0.0, 0.0", "rigid_point = 0.0, 0.0, -0.5"))
    res = run(voiga_bin, case, "--check")
    assert "faces away from it: the slave's contact_face = 'top'" in res.stderr, res.stderr
    assert "choose the face that faces it" in res.stderr


def test_mortar_closing_steps_on_a_face(voiga_bin: Path, tmp_path: Path) -> None:
    """hertz3d m1 NN2.2 (mortar): a Newton step may close control points as deep as the
    active ones are, so the zone's edge crossing many of them per load step does not
    cut every step to its first crossing (25 Newton iterations; 39 when it did)."""
    out = tmp_path / "h"
    subprocess.run(["python3", "-m", "pre", "hertz3d", str(out), "--mesh", "m1", "--layout", "NN2.2"],
                   check=True, capture_output=True, cwd=Path(__file__).resolve().parents[2])
    res = run(voiga_bin, out / "m1-NN2.2.nml")
    assert res.returncode == 0, res.stderr
    with h5py.File(out / "m1-NN2.2.h5") as f:
        assert int(f.attrs["newton_iterations"]) <= 30
