"""The Dask engine: a study on a real scheduler with two worker processes (loopback
only) gives the results of a local run; a failing case is recorded; reruns skip."""
from __future__ import annotations

import csv
import os
import shutil
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import h5py
import numpy as np
import pytest

from post.__main__ import main
from post.cost import COST_COLUMNS

REPO = Path(__file__).resolve().parents[2]
HERTZ = REPO / "cases" / "hertz" / "m1-N2.nml"

STUDY = """# six hertz m1 cases; the last one fails (one Newton iteration, no cuts)
base = "{hertz}"
measures = {{ force_y = "steps/last/contact/1/force[1]", run_cuts = "n_cuts" }}
[[list]]
contact.penalty_normal = 1000.0
[[list]]
contact.penalty_normal = 4000.0
[[list]]
"body[cylinder]".youngs_modulus = 2.0
[[list]]
solver.n_steps = 2
[[list]]
"dirichlet[1]".uy = -0.02
[[list]]
solver = {{ max_iterations = 1, max_cuts = 0 }}
"""

TIMING = {*COST_COLUMNS, "assembly_s", "contact_s", "factorization_s", "solve_s", "output_s", "time_norm"}
"""Columns that differ between two runs of the same case (seconds)."""


def study_cli(*args: str | Path) -> subprocess.CompletedProcess[str]:
    """``python -m post study ...`` in a subprocess (its own Dask client)."""
    env = dict(os.environ, PYTHONPATH=str(REPO))
    return subprocess.run([sys.executable, "-m", "post", "study", *map(str, args), "--no-progress",
                           "--no-figures"], capture_output=True, text=True, timeout=300, cwd=REPO,
                          env=env, stdin=subprocess.DEVNULL)


@pytest.fixture()
def scheduler(tmp_path: Path) -> Iterator[str]:
    """A ``dask scheduler`` and two single-threaded ``dask worker`` processes on
    127.0.0.1 (ports chosen by the system); yields the scheduler's address."""
    from distributed import Client

    info = tmp_path / "scheduler.json"
    common = ["--host", "127.0.0.1", "--no-dashboard"]
    procs = [subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--port", "0",
                               "--scheduler-file", str(info), *common],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        deadline = time.monotonic() + 60
        while not info.exists() and time.monotonic() < deadline:
            time.sleep(0.1)
        assert info.exists(), "the scheduler did not start in 60 s"
        for k in range(2):
            procs.append(subprocess.Popen(
                [sys.executable, "-m", "distributed.cli.dask_worker", "--scheduler-file", str(info),
                 "--nthreads", "1", "--no-nanny", "--local-directory", str(tmp_path / f"w{k}"), *common],
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        with Client(scheduler_file=str(info), timeout=60) as client:
            client.wait_for_workers(2, timeout=60)
            address = client.scheduler.address
            assert address.startswith("tcp://127.0.0.1:")
            assert all(w.startswith("tcp://127.0.0.1:") for w in client.scheduler_info()["workers"])
        yield address
    finally:
        for proc in reversed(procs):
            proc.terminate()
        for proc in procs:
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                proc.kill()


def rows(out: Path) -> dict[str, dict[str, str]]:
    return {r["case"]: r for r in csv.DictReader((out / "summary.csv").open())}


def displacements(result: Path) -> list[np.ndarray]:
    """The displacement of every converged step (none for a run that failed at step 1)."""
    with h5py.File(result, "r") as f:
        steps = f.get("steps", {})
        return [steps[s]["displacement"][()] for s in sorted(steps)]


def test_cluster_run_equals_local_run(voiga: Path, scheduler: str, tmp_path: Path) -> None:
    study = tmp_path / "six.toml"
    study.write_text(STUDY.format(hertz=os.path.relpath(HERTZ, tmp_path)))
    local, remote = tmp_path / "local", tmp_path / "remote"
    run_local = study_cli(study, "--out", local, "--binary", voiga, "--jobs", "2")
    # the workers return the result files through the scheduler
    run_remote = study_cli(study, "--out", remote, "--binary", voiga, "--scheduler", scheduler,
                           "--no-shared-fs")
    for run in (run_local, run_remote):
        assert run.returncode == 1, run.stderr      # one case failed
        assert "6 cases, 1 failed" in run.stdout, run.stdout
    a, b = rows(local), rows(remote)
    assert len(a) == 6 and a.keys() == b.keys()
    failed = [k for k, r in a.items() if r["status"] != "converged"]
    assert failed == ["m1-N2+solver.max_iterations=1+solver.max_cuts=0"]
    for table in (a, b):
        bad = table[failed[0]]
        assert bad["exit_code"] == "3" and "Newton did not converge" in bad["error"]
        assert bad["status"].startswith("failed")
    assert sum(len(displacements(local / "hertz" / f"{case}.h5")) for case in a) == 5 * 5 - 3
    for case, row in a.items():
        assert {k: v for k, v in row.items() if k not in TIMING} == \
            {k: v for k, v in b[case].items() if k not in TIMING}
        for x, y in zip(displacements(local / "hertz" / f"{case}.h5"),
                        displacements(remote / "hertz" / f"{case}.h5"), strict=True):
            assert np.array_equal(x, y)
    # the stiffer penalty presses less deep: the force at the same displacement is larger
    assert float(a["m1-N2+contact.penalty_normal=4000.0"]["force_y"]) > \
        float(a["m1-N2+contact.penalty_normal=1000.0"]["force_y"]) > 0


def test_rerun_skips_up_to_date_cases(voiga: Path, tmp_path: Path) -> None:
    """A second run solves only the failed case; a newer binary reruns every case."""
    study = tmp_path / "six.toml"
    study.write_text(STUDY.format(hertz=os.path.relpath(HERTZ, tmp_path)))
    binary = tmp_path / "voiga"
    shutil.copy2(voiga, binary)
    out = tmp_path / "out"
    args = ["study", str(study), "--out", str(out), "--binary", str(binary), "--no-progress", "--no-figures"]
    assert main(args) == 1
    results = sorted((out / "hertz").glob("m1-N2+*.h5"))
    stamps = {p.name: p.stat().st_mtime_ns for p in results}
    assert len(stamps) == 6
    assert main(args) == 1
    again = {p.name: p.stat().st_mtime_ns for p in results}
    changed = [k for k in stamps if again[k] != stamps[k]]
    assert changed == ["m1-N2+solver.max_iterations=1+solver.max_cuts=0.h5"]
    os.utime(binary)                 # a rebuilt binary: every result is out of date
    assert main(args) == 1
    assert all(p.stat().st_mtime_ns != again[p.name] for p in results)
