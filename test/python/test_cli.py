"""The `voiga` program: `--check` output, DOF tables, `--dump`, and refusal of bad input."""
from __future__ import annotations

import re
from pathlib import Path

import h5py
import numpy as np
import pytest

from conftest import REPO

# The paper's Table 2 (ironing, m1): die interface, die bulk, slab interface, slab bulk.
# NN6 die interface is 34 (the paper prints 24, a misprint: 34 + 36 = 70 = its total).
TABLE2 = {
    "N2": (18, 36, 20, 60),
    "N4": (26, 52, 24, 72),
    "N6": (34, 68, 28, 84),
    "NN4": (26, 36, 24, 60),
    "NN6": (34, 36, 28, 60),
    "NN2.1": (30, 36, 36, 60),
    "NN2.2": (42, 36, 52, 60),
    "NN2.3": (54, 36, 68, 60),
}

# The paper's Table 4 (hertz): interface, bulk DOFs per mesh and layout.
TABLE4 = {
    ("m1", "L1"): (20, 960), ("m1", "N2"): (22, 1056), ("m1", "NN2.1"): (40, 1056), ("m1", "NN2.2"): (58, 1056),
    ("m2", "L1"): (38, 1824), ("m2", "N2"): (40, 1920), ("m2", "NN2.1"): (76, 1920), ("m2", "NN2.2"): (112, 1920),
    ("m3", "L1"): (74, 3552), ("m3", "N2"): (76, 3648), ("m3", "NN2.1"): (148, 3648), ("m3", "NN2.2"): (220, 3648),
    ("m4", "L1"): (146, 7008), ("m4", "N2"): (148, 7104), ("m4", "NN2.1"): (292, 7104), ("m4", "NN2.2"): (436, 7104),
    ("m5", "L1"): (290, 13920), ("m5", "N2"): (292, 14016), ("m5", "NN2.1"): (580, 14016),
    ("m5", "NN2.2"): (868, 14016),
    ("m6", "N2"): (580, 27840),
}

DOFS = re.compile(r"^dofs (\S+) interface=(\d+) bulk=(\d+) total=(\d+)", re.M)


def dofs(stdout: str) -> dict[str, tuple[int, int, int]]:
    """Parse the `dofs <body> ...` lines of `--check` (the `all` line excluded)."""
    return {m[1]: (int(m[2]), int(m[3]), int(m[4])) for m in DOFS.finditer(stdout) if m[1] != "all"}


@pytest.mark.parametrize("layout", list(TABLE2))
def test_table2_ironing_m1(run, layout: str) -> None:
    res = run(REPO / "cases" / "ironing" / f"m1-{layout}.nml", "--check")
    assert res.returncode == 0, res.stderr
    got = dofs(res.stdout)
    di, db, si, sb = TABLE2[layout]
    assert got["die"] == (di, db, di + db)
    assert got["slab"] == (si, sb, si + sb)
    assert f"dofs all total={di + db + si + sb}" in res.stdout


@pytest.mark.parametrize("mesh,layout", list(TABLE4))
def test_table4_hertz(run, mesh: str, layout: str) -> None:
    res = run(REPO / "cases" / "hertz" / f"{mesh}-{layout}.nml", "--check")
    assert res.returncode == 0, res.stderr
    (body,) = dofs(res.stdout).values()
    interface, bulk = TABLE4[(mesh, layout)]
    assert body == (interface, bulk, interface + bulk)


def test_dump_schema(run, tmp_path: Path) -> None:
    out = tmp_path / "dump.h5"
    res = run(REPO / "cases" / "ironing" / "m1-NN2.2.nml", "--check", "--dump", out)
    assert res.returncode == 0, res.stderr
    with h5py.File(out, "r") as f:
        die = f["bodies/die"]
        assert die.attrs["interface_dofs"] == 42 and die.attrs["total_dofs"] == 78
        cp = die["bulk/control_points"][()]
        w = die["bulk/weights"][()]
        nxi = len(die["bulk/knots_xi"]) - die["bulk/degree"][0] - 1
        neta = len(die["bulk/knots_eta"]) - die["bulk/degree"][1] - 1
        assert cp.shape == (neta, nxi, 2) and w.shape == (neta, nxi)
        layer = die["layer"]
        assert layer["degree"][0] == 4
        n = len(layer["knots"]) - 4 - 1
        assert layer["control_points"].shape == (n, 2) and 2 * n == 42
        # layer end points are the bulk's contact-edge corners
        np.testing.assert_allclose(layer["control_points"][0], cp[-1, 0], atol=1e-14)
        np.testing.assert_allclose(layer["control_points"][-1], cp[-1, -1], atol=1e-14)


def test_variable_length_string_attributes(run, tmp_path: Path, ironing_copy: Path) -> None:
    """h5py writes str attributes as variable-length strings by default: they must read too."""
    with h5py.File(tmp_path / "geometry.h5", "r+") as f:
        for body in ("die", "slab"):
            g = f["bodies"][body]
            for key in list(g.attrs):
                value = g.attrs[key]
                del g.attrs[key]
                g.attrs[key] = value.decode() if isinstance(value, bytes) else str(value)
            assert h5py.check_string_dtype(g.attrs.get_id("edge_eta1").dtype).length is None
    res = run(ironing_copy, "--check")
    assert res.returncode == 0, res.stderr
    assert dofs(res.stdout)["die"] == (18, 36, 54)


def edit(case: Path, old: str, new: str, count: int = 1) -> None:
    """Replace `old` by `new` in the case file (`count` = -1: everywhere)."""
    text = case.read_text()
    assert old in text, f"fixture case has no {old!r}"
    case.write_text(text.replace(old, new, count))


BAD_CASES = [
    # (old text, new text, words the message must contain)
    ("nel_xi = 6", "nel_xii = 6", ["&body", "unknown variable", "nel_xii"]),
    ("nel_xi = 6", "nel_xi = 'abc'", ["&body", "nel_xi", "wrong type"]),
    ("n_bodies = 2", "n_bodies = 2.5x", ["&case", "n_bodies"]),
    ("youngs_modulus = 10.0", "youngs_modulus = -1.0", ["&body 'die'", "youngs_modulus", "> 0"]),
    ("youngs_modulus = 10.0", "youngs_modulus = 0.0", ["&body 'die'", "youngs_modulus"]),
    ("poisson_ratio = 0.3", "poisson_ratio = 0.5", ["&body 'die'", "poisson_ratio", "(-1, 0.5)"]),
    ("poisson_ratio = 0.3", "poisson_ratio = -1.0", ["&body 'die'", "poisson_ratio"]),
    ("contact_edge = 'outer'", "contact_edge = 'rim'", ["&body 'die'", "contact_edge", "'rim'"]),
    ("'die'", "'anvil'", ["geometry", "anvil"]),
    ("geometry = 'geometry.h5'", "geometry = 'missing.h5'", ["&case", "geometry", "missing.h5"]),
    ("n_bodies = 2", "n_bodies = 3", ["&case", "n_bodies = 3", "2 &body groups"]),
    ("material = 'neo-hookean'", "material = 'rubber'", ["&body 'die'", "material", "'rubber'"]),
    ("degree_xi = 2", "degree_xi = 1", ["&body 'die'", "degree_xi"]),
    ("nel_xi = 6", "nel_xi = 0", ["&body 'die'", "nel_xi"]),
    ("nel_xi = 6", "knots_xi = 0.5, 0.25", ["&body 'die'", "knots_xi", "increasing"]),
    ("nel_xi = 6", "knots_xi = 0.5, 1.5", ["&body 'die'", "knots_xi", "(0, 1)"]),
    ("layer_degree = 0", "layer_degree = 1", ["&body 'die'", "layer_degree"]),
    ("layer_elevations = 0", "layer_elevations = 2", ["&body 'die'", "layer_elevations"]),
    ("method = 'gpts'", "method = 'mortal'", ["&contact", "method = 'mortal'", "'gpts', 'mortar'"]),
    # an edge a load names is checked against the body's edges by --check too
    ("edge = 'bottom'", "edge = 'floor'", ["&dirichlet (2)", "no edge named 'floor'", "'slab'", "'bottom'"]),
    # every group is validated by --check (issue 18, item 8)
    ("&contact", "&pressure\n  body = 'slab', edge = 'side', p = 0.1, 0.1\n/\n&contact",
     ["&pressure (1)", "no edge named 'side'", "'slab'"]),
    ("slave = 'die'", "slave = 'punch'", ["&contact (1)", "slave = 'punch'", "not a body"]),
    ("master = 'slab'", "master = 'anvil2'", ["&contact (1)", "master = 'anvil2'"]),
    ("master = 'slab'", "master = 'rigid', rigid_curve = 'roller'",
     ["&contact (1)", "rigid_curve", "no curve 'roller'"]),
    ("master = 'slab'", "master = 'slab', rigid_uy = -1.0, -1.0",
     ["&contact (1)", "rigid_uy and rigid_uz move a rigid master"]),
    ("master = 'slab'", "master = 'rigid', rigid_uy = -1.0", ["&contact (1)", "rigid_uy", "one value per load phase"]),
    ("n_steps = 10, 200", "n_steps = 10, 0", ["&solver", "n_steps"]),
    ("&contact", "&output\n  fields = 'stresses'\n/\n&contact", ["&output", "'stresses'", "'von_mises'"]),
]


@pytest.mark.parametrize("old,new,words", BAD_CASES, ids=[b[1] for b in BAD_CASES])
def test_bad_case_refused(run, ironing_copy: Path, old: str, new: str, words: list[str]) -> None:
    edit(ironing_copy, old, new, -1 if old == "'die'" else 1)
    res = run(ironing_copy, "--check")
    assert res.returncode == 2, (res.stdout, res.stderr)
    message = res.stderr
    assert str(ironing_copy) in message or ironing_copy.name in message, message
    for word in words:
        assert word in message, message
    assert "Backtrace" not in message and "STOP" not in message, message


def test_missing_case_file(run, tmp_path: Path) -> None:
    res = run(tmp_path / "nothing.nml", "--check")
    assert res.returncode == 2
    assert "nothing.nml" in res.stderr and "does not exist" in res.stderr


def test_missing_group(run, ironing_copy: Path) -> None:
    ironing_copy.write_text(ironing_copy.read_text().replace("&case", "&kase"))
    res = run(ironing_copy, "--check")
    assert res.returncode == 2
    assert "&case" in res.stderr


def test_usage_errors(run) -> None:
    assert run().returncode == 2
    res = run("a.nml", "--frobnicate")
    assert res.returncode == 2 and "--frobnicate" in res.stderr


@pytest.mark.parametrize(
    "dataset,mutate,words",
    [
        ("knots_xi", lambda k: k[[0, 1, 2, 5, 3, 4, 6, 7]], ["knots_xi", "decreases"]),
        ("knots_xi", lambda k: k[:-1], ["knots_xi", "n + p + 1"]),
        ("knots_xi", lambda k: k * 2.0, ["knots_xi", "0 to 1"]),
        ("weights", lambda w: -w, ["weights", "> 0"]),
        ("weights", lambda w: w * np.nan, ["weights"]),
        ("control_points", lambda c: np.full_like(c, np.inf), ["control_points", "finite"]),
    ],
)
def test_bad_geometry_refused(run, tmp_path: Path, ironing_copy: Path, dataset, mutate, words) -> None:
    with h5py.File(tmp_path / "geometry.h5", "r+") as f:
        g = f["bodies/die"]
        data = mutate(g[dataset][()])
        del g[dataset]
        g[dataset] = data
    res = run(ironing_copy, "--check")
    assert res.returncode == 2, (res.stdout, res.stderr)
    assert "geometry.h5" in res.stderr and "die" in res.stderr
    for word in words:
        assert word in res.stderr, res.stderr


def test_not_hdf5_geometry(run, tmp_path: Path, ironing_copy: Path) -> None:
    (tmp_path / "geometry.h5").write_text("not an hdf5 file\n")
    res = run(ironing_copy, "--check")
    assert res.returncode == 2
    assert "geometry.h5" in res.stderr and "HDF5" in res.stderr


@pytest.mark.parametrize("edge", ["left", "right", "bottom", "top"])
def test_reoriented_contact_edge_matches_pre(run, tmp_path: Path, ironing_copy: Path, edge: str) -> None:
    """A contact edge on any side: voiga and `python -m pre refine` build the same nets."""
    import subprocess
    import sys

    text = ironing_copy.read_text()
    text = text.replace("contact_edge = 'top'", f"contact_edge = '{edge}'")
    text = text.replace("nel_xi = 8", "nel_xi = 3").replace("nel_eta = 2", "nel_eta = 5")
    # NN2.2 on the slab
    slab = text[text.index("name = 'slab'"):]
    slab_new = slab.replace("layer_degree = 0", "layer_degree = 2").replace(
        "layer_elevations = 0", "layer_elevations = 2")
    ironing_copy.write_text(text.replace(slab, slab_new))
    ours = tmp_path / "voiga.h5"
    # (not a contact set-up: a slab edge other than its top has the die inside it)
    res = run(ironing_copy, "--check", "--allow-overlap", "--dump", ours)
    assert res.returncode == 0, res.stderr
    theirs = tmp_path / "pre.h5"
    subprocess.run([sys.executable, "-m", "pre", "refine", str(ironing_copy), "-o", str(theirs)],
                   check=True, cwd=REPO, capture_output=True)
    with h5py.File(ours) as a, h5py.File(theirs) as b:
        for key in ("bulk/knots_xi", "bulk/knots_eta", "bulk/control_points", "bulk/weights",
                    "layer/knots", "layer/control_points", "layer/weights"):
            np.testing.assert_allclose(a["bodies/slab"][key][()], b["bodies/slab"][key][()],
                                       atol=1e-12, err_msg=key)
        for attr in ("interface_dofs", "bulk_dofs", "total_dofs"):
            assert a["bodies/slab"].attrs[attr] == b["bodies/slab"].attrs[attr]


def test_automatic_penalty_raises_no_floating_point_note(run, tmp_path: Path) -> None:
    """The automatic penalty (no penalty_normal) is marked by a NaN until the factory
    computes it; comparing that NaN raised IEEE_INVALID, which gfortran reports as
    `Note: The following floating-point exceptions are signalling` when the program
    ends (issue 35, item 4): neither --check nor a frictional run may print it."""
    import shutil
    shutil.copy(REPO / "cases" / "hertz" / "geometry.h5", tmp_path / "geometry.h5")
    case = tmp_path / "case.nml"
    shutil.copy(REPO / "cases" / "hertz" / "m1-NN2.2.nml", case)
    text = case.read_text()
    assert "penalty_normal = 1000.0" in text and "friction = 0.0" in text
    case.write_text(text.replace("penalty_normal = 1000.0", "").replace("friction = 0.0", "friction = 0.3"))
    for args in (("--check",), ("--quiet",)):
        res = run(case, *args, cwd=tmp_path)
        assert res.returncode == 0, res.stderr
        assert "floating-point" not in res.stdout + res.stderr, (args, res.stdout, res.stderr)


def test_quiet_run_prints_no_dof_lines_and_times_have_a_leading_zero(run, tmp_path: Path) -> None:
    """`--quiet` means no line per step and no DOF lines (issue 38, item 7); `--check`
    still prints them (they are its answer). A time below a second prints as `0.171 s`,
    not `.171 s`."""
    import shutil
    shutil.copy(REPO / "cases" / "hertz" / "geometry.h5", tmp_path / "geometry.h5")
    case = tmp_path / "case.nml"
    shutil.copy(REPO / "cases" / "hertz" / "m1-NN2.2.nml", case)
    res = run(case, "--quiet", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert "dofs" not in res.stdout, res.stdout
    (line,) = res.stdout.splitlines()
    assert re.fullmatch(r"converged: 5 steps \(5 substeps, 0 cuts\), \d+ Newton iterations, (0|[1-9]\d*)\.\d{3} s; "
                        r"wrote .*m1-NN2\.2\.h5", line), line
    res = run(case, "--check", "--quiet", cwd=tmp_path)
    assert res.returncode == 0 and "dofs all total=" in res.stdout, res.stdout
