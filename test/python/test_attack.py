"""The reduced attack suite of issue 19 (`attack.py`; the full one is `make attack`):
every example of the issue and one attack in seven, judged by the same oracles: no
crash, no hang, refusals with exit 2 naming the cause, no input or earlier result
changed, no result that says something other than its case."""
from __future__ import annotations

from pathlib import Path

import pytest

from attack import base_result, run_attack, select
from attack_inputs import all_attacks


@pytest.fixture(scope="module")
def base(voiga_bin: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    import os
    os.environ["ATTACK_VOIGA"] = str(voiga_bin)
    return base_result(voiga_bin, tmp_path_factory.mktemp("base"))


def reduced() -> list:
    from attack_inputs import GEOMETRY
    # the post family damages a finished result; its names (not the file) decide the subset
    return select(all_attacks(GEOMETRY), reduced=True)


ATTACKS = reduced()


@pytest.mark.parametrize("index", range(len(ATTACKS)), ids=[a.name for a in ATTACKS])
def test_attack(voiga_bin: Path, base: Path, tmp_path: Path, index: int) -> None:
    attack = ATTACKS[index]
    if attack.family == "post":   # rebuilt on the real result of the base case
        attack = next(a for a in all_attacks(base) if a.name == attack.name)
    outcome = run_attack(attack, tmp_path / "work", voiga_bin, base)
    assert outcome.ok, "\n".join(outcome.problems)
