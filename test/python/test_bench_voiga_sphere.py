"""Section 8 of the bench (voiga on the thick spherical shell, `bench/voiga_sphere.py`):
the case it writes solves, its error measure gives the numbers of the Fortran table
(`fpm test -- --lame-sphere-table`, docs/verification.md), and the match picks the
fastest run at or below a stress error."""
from __future__ import annotations

import math
from pathlib import Path

import pytest

from bench.voiga_sphere import cheapest_at, parse_meshes, result_errors, run_voiga, write_case


def test_parse_meshes() -> None:
    assert parse_meshes("2:4, 3:6") == [(2, 4), (3, 6)]
    with pytest.raises(ValueError):
        parse_meshes("1:4")


def test_cheapest_at() -> None:
    rows = [{"e_sigma": 1e-2, "wall": 0.1}, {"e_sigma": 1e-3, "wall": 0.5}, {"e_sigma": 5e-4, "wall": 0.3}]
    assert cheapest_at(rows, 2e-3)["wall"] == 0.3
    assert cheapest_at(rows, 1e-4) is None


def test_errors_match_the_fortran_table(voiga_bin: Path, tmp_path: Path, monkeypatch) -> None:
    """p = 2 with 2 and 4 elements per direction: the stress errors of the table
    (1.064e-1, 2.897e-2; its quadrature has one point more per direction) and the
    displacement errors (7.73e-3, 9.93e-4), to 1 %; the stress converges at about 1.9."""
    import bench.voiga_sphere as vs

    monkeypatch.setattr(vs, "VOIGA", voiga_bin)
    errors = []
    for n in (2, 4):
        case = write_case(tmp_path, 2, n)
        run_voiga(case)
        errors.append(result_errors(case.with_suffix(".h5")))
    assert errors[0]["e_sigma"] == pytest.approx(1.064e-1, rel=1e-2)
    assert errors[1]["e_sigma"] == pytest.approx(2.897e-2, rel=1e-2)
    assert errors[0]["e_u"] == pytest.approx(7.73e-3, rel=1e-2)
    assert errors[1]["e_u"] == pytest.approx(9.93e-4, rel=1e-2)
    assert math.log2(errors[0]["e_sigma"] / errors[1]["e_sigma"]) > 1.8
    assert errors[1]["dofs"] == 648
