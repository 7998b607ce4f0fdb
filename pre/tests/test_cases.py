"""The generated case tree: committed copy up to date, namelist contents,
determinism."""

from __future__ import annotations

from pathlib import Path

import f90nml
import numpy as np
import pytest

from pre.cases import STUDIES, all_cases, case_bodies, write_cases
from pre.h5io import h5_contents
from pre.layouts import parse_layout

from .conftest import CASES


def _generated_files(root: Path) -> list[Path]:
    return sorted(p.relative_to(root) for p in root.rglob("*") if p.is_file())


def test_committed_cases_are_fresh(generated: Path) -> None:
    """Fails if cases/ is stale or incomplete: run ``python -m pre cases``."""
    hint = "cases/ is stale: regenerate with `python -m pre cases`"
    expected = _generated_files(generated)
    missing = [str(p) for p in expected if not (CASES / p).is_file()]
    assert not missing, f"{hint}; missing: {missing[:10]}"
    # .nml files that the generator no longer writes are stale too
    extra = sorted(str(p.relative_to(CASES)) for p in CASES.rglob("*.nml")
                   if not (generated / p.relative_to(CASES)).is_file())
    assert not extra, f"{hint}; not generated any more: {extra[:10]}"
    for rel in expected:
        if rel.suffix == ".nml":
            assert (CASES / rel).read_text() == (generated / rel).read_text(), f"{hint}: {rel}"
        else:
            a, b = h5_contents(CASES / rel), h5_contents(generated / rel)
            assert a.keys() == b.keys(), f"{hint}: {rel}"
            for key in a:
                assert np.array_equal(np.asarray(a[key]), np.asarray(b[key])), f"{hint}: {rel} {key}"


def test_deterministic_bytes(tmp_path: Path, generated: Path) -> None:
    write_cases(tmp_path)
    for rel in _generated_files(generated):
        assert (tmp_path / rel).read_bytes() == (generated / rel).read_bytes(), rel


def test_study_counts() -> None:
    n = {scene: len(runs) for scene, runs in STUDIES.items()}
    assert n == {"ironing": 32, "ironing-deep": 32, "hertz": 36, "rings": 13}
    assert len(all_cases()) == 113


def test_namelists(generated: Path) -> None:
    for rel in all_cases():
        path = generated / rel
        nml = f90nml.read(str(path))
        assert list(dict.fromkeys(nml.keys())) == ["case", "body", "solver", "dirichlet", "contact"]
        case = nml["case"]
        stem = path.stem
        assert case["geometry"] == "geometry.h5" and case["output"] == f"{stem}.h5"
        assert case["scene"] == path.parent.name
        bodies = case_bodies(nml)
        assert case["n_bodies"] == len(bodies)
        lay = parse_layout(case["layout"])
        assert stem.endswith(case["layout"])
        for b in bodies:
            assert (b["basis"], b["degree_xi"], b["degree_eta"], b["layer_degree"],
                    b["layer_elevations"]) == (lay.basis, lay.degree_xi, lay.degree_eta,
                                               lay.layer_degree, lay.layer_elevations)
            assert b["material"] in ("neo-hookean", "linear")
            assert b["contact_edge"] in ("outer", "top")
            for d in ("xi", "eta"):
                if f"knots_{d}" in b:
                    k = np.atleast_1d(b[f"knots_{d}"])
                    assert np.all(np.diff(k) > 0) and k[0] > 0 and k[-1] < 1
                    assert f"nel_{d}" not in b
                else:
                    assert b[f"nel_{d}"] >= 1


@pytest.mark.parametrize("rel, bodies", [
    ("ironing/m1-N2.nml", {"die": (6, 1, 10.0), "slab": (8, 2, 1.0)}),
    ("ironing/m3-NN2.2.nml", {"die": (24, 4, 10.0), "slab": (32, 8, 1.0)}),
    ("ironing-deep/m4-N6.nml", {"die": (48, 8, 1000.0), "slab": (64, 16, 1.0)}),
])
def test_uniform_meshes(generated: Path, rel: str, bodies: dict) -> None:
    got = {b["name"]: (b["nel_xi"], b["nel_eta"], b["youngs_modulus"])
           for b in case_bodies(f90nml.read(str(generated / rel)))}
    assert got == bodies


@pytest.mark.parametrize("rel, level", [("rings/m1-N2.nml", 1), ("rings/m2-NN4.nml", 2),
                                        ("rings/m3-NN2.1.nml", 3), ("rings/ref-N2.nml", 4)])
def test_rings_meshes(generated: Path, rel: str, level: int) -> None:
    """Graded arc knots (12 / 16 elements at m1, x 2^(level-1)), 2 radial elements; the
    coarse knot 0.5 is not listed (it is a knot of the geometry)."""
    bodies = {b["name"]: b for b in case_bodies(f90nml.read(str(generated / rel)))}
    for name, n_m1, e in (("upper", 12, 1.0), ("lower", 16, 2.0)):
        b = bodies[name]
        kx = np.atleast_1d(b["knots_xi"])
        assert len(kx) == n_m1 * 2 ** (level - 1) - 2 and 0.5 not in kx
        np.testing.assert_array_equal(np.atleast_1d(b["knots_eta"]), [0.5])
        assert (b["material"], b["youngs_modulus"], b["poisson_ratio"]) == ("neo-hookean", e, 0.3)


def test_hertz_knot_counts(generated: Path) -> None:
    for level in range(1, 6):
        for layout, n_eta in (("L1", 47), ("N2", 46), ("NN3.2", 46)):
            b = case_bodies(f90nml.read(str(generated / f"hertz/m{level}-{layout}.nml")))[0]
            assert len(b["knots_xi"]) == 9 * 2 ** (level - 1) - 1
            assert len(b["knots_eta"]) == n_eta
            assert (b["material"], b["youngs_modulus"], b["poisson_ratio"]) == ("linear", 1.0, 0.3)
