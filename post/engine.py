"""The engine of ``post study`` and ``post sweep``: every case a Dask distributed task.

Each task runs the ``voiga`` binary on one case in a scratch folder of the worker (the
case text and its geometry travel with the task) and either moves the result file to
its place in the study's folder (``shared=True``: the workers see that folder, as on one
machine or a cluster with a shared file system) or returns its bytes through the
scheduler (``shared=False``). A case that fails (non-zero exit, timeout, a lost worker)
is recorded, never stops the others. By default the cases run on a ``LocalCluster``
with one single-threaded worker per core; ``scheduler`` connects to an existing cluster
instead (``dask scheduler``/``dask worker``, or dask-jobqueue for SLURM/PBS: docs/studies.md).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
import uuid
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from tqdm import tqdm

from pre.files import check_output, copy_file, new_file, write_bytes, write_text

from .sweep import Run, longest_first, up_to_date

CONNECT_TIMEOUT = 30.0
"""Seconds to wait for an existing scheduler."""


@dataclass(frozen=True)
class Task:
    """What a worker needs to solve one case (picklable, no paths into the study's
    folder except ``dest``)."""

    label: str
    name: str
    """File name of the case in the scratch folder (``<case>.nml``)."""
    text: str
    geometry_name: str
    geometry: bytes
    binary: str
    timeout: float
    dest: str | None
    """Where the worker moves the result file (shared file system), or None: return it."""


@dataclass
class Outcome:
    """What came of one task."""

    label: str
    code: int
    """voiga's exit code; -1 timed out, -2 the task failed around voiga, -3 lost on the cluster."""
    message: str
    """The last line voiga wrote to stderr (or what went wrong)."""
    seconds: float = 0.0
    data: bytes | None = None
    """The result file, when it is returned rather than moved."""


def single_thread_env() -> dict[str, str]:
    """The environment with one BLAS thread per run (unless the caller set one).

    The engine runs one case per core; OpenBLAS threads on top of that only spin
    (measured: 1.5x the CPU time on ironing m3 N6 with two threads).
    """
    env = dict(os.environ)
    env.setdefault("OPENBLAS_NUM_THREADS", "1")
    return env


def run_task(task: Task) -> Outcome:
    """Solve one case in a fresh scratch folder (runs on a worker). Never raises: any
    failure becomes the outcome's code and message."""
    start = time.perf_counter()
    data = None
    try:
        with tempfile.TemporaryDirectory(prefix="voiga-") as scratch:
            folder = Path(scratch)
            (folder / task.name).write_text(task.text)
            (folder / task.geometry_name).write_bytes(task.geometry)
            try:
                proc = subprocess.run([task.binary, task.name, "--quiet"], cwd=folder, capture_output=True,
                                      text=True, timeout=task.timeout, env=single_thread_env(),
                                      stdin=subprocess.DEVNULL)
                lines = (proc.stderr or "").strip().splitlines()
                code, message = proc.returncode, lines[-1] if lines else ""
            except subprocess.TimeoutExpired:
                code, message = -1, f"timed out after {task.timeout:g} s"
            result = folder / (Path(task.name).stem + ".h5")
            if not result.exists():
                if code == 0:
                    code, message = -2, f"voiga wrote no {result.name}"
            elif task.dest is None:
                data = result.read_bytes()
            else:
                dest = Path(task.dest)
                dest.parent.mkdir(parents=True, exist_ok=True)
                with new_file(dest) as part:
                    shutil.move(result, part)     # keeps voiga's modification time
    except Exception as err:  # noqa: BLE001 -- one case's trouble must not stop the study
        code, message = -2, f"{type(err).__name__}: {err}"
    return Outcome(task.label, code, message, time.perf_counter() - start, data)


def write_if_changed(path: Path, text: str) -> None:
    """Write ``text`` unless the file holds it already (its time stays that of the
    last change, which the skip rule compares with the result's)."""
    if not check_output(path).is_file() or path.read_text() != text:
        path.parent.mkdir(parents=True, exist_ok=True)
        write_text(path, text)


def prepare(run: Run) -> None:
    """The case and its geometry in the study's folder (``<out>/<scene>/``), as a
    record of what ran and to rerun it by hand."""
    write_if_changed(run.work, run.case_text())
    target = check_output(run.work.parent / run.geometry.name)
    if not target.exists() or target.stat().st_mtime < run.geometry.stat().st_mtime:
        copy_file(run.geometry, target)


def task_for(run: Run, binary: Path, timeout: float, shared: bool) -> Task:
    """The task of ``run`` (after :func:`prepare`)."""
    return Task(label=run.label, name=run.work.name, text=run.case_text(), geometry_name=run.geometry.name,
                geometry=run.geometry.read_bytes(), binary=str(binary), timeout=timeout,
                dest=str(run.result.resolve()) if shared else None)


@contextmanager
def connect(scheduler: str | None = None, jobs: int = 0) -> Iterator[object]:
    """A ``distributed.Client``: of the cluster at ``scheduler``, else of a new
    ``LocalCluster`` (``jobs`` single-threaded workers, default one per core) in this
    process (the work is in the voiga subprocesses). OSError when the scheduler does
    not answer or the address is malformed."""
    import dask
    from distributed import Client, LocalCluster

    if scheduler:
        try:
            client = Client(scheduler, timeout=CONNECT_TIMEOUT)
        # ValueError: a malformed address; TypeError: a protocol without its configuration
        # (tls:// without certificates)
        except (OSError, TimeoutError, ValueError, TypeError) as err:
            raise OSError(f"no Dask scheduler answers at {scheduler} ({err})") from None
        try:
            yield client
        finally:
            client.close()
        return
    # one task per worker at a time: the queued cases start in priority order
    with dask.config.set({"distributed.scheduler.worker-saturation": 1.0}):
        with LocalCluster(n_workers=jobs or os.cpu_count() or 1, threads_per_worker=1, processes=False,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            yield client


def run_all(runs: list[Run], binary: Path, client: object, timeout: float, force: bool = False,
            progress: bool = True, times: dict[str, float] | None = None,
            shared: bool = True) -> dict[str, Outcome]:
    """Solve every run whose result is not up to date (all with ``force``) on the
    client's cluster, longest first (:func:`post.sweep.longest_first`, ``times``: wall
    seconds of a previous summary, label -> s); label -> outcome (``'up to date'`` for
    the skipped ones). A tqdm bar shows the count, the failures so far and the ETA."""
    from distributed import as_completed

    outcome: dict[str, Outcome] = {}
    todo = []
    for run in runs:
        prepare(run)
        if not force and up_to_date(run, binary):
            outcome[run.label] = Outcome(run.label, 0, "up to date")
        else:
            check_output(run.result).unlink(missing_ok=True)     # a failed rerun leaves no stale result
            todo.append(run)
    todo = longest_first(todo, times)
    by_key, futures = {}, []
    for rank, run in enumerate(todo):
        key = f"voiga-{run.label}-{uuid.uuid4().hex[:8]}"
        by_key[key] = run
        futures.append(client.submit(run_task, task_for(run, binary, timeout, shared),  # type: ignore[attr-defined]
                                     key=key, priority=len(todo) - rank, pure=False))
    failed = 0
    with tqdm(total=len(todo), desc="study", unit="case", disable=not progress, file=sys.stderr) as bar:
        for fut in as_completed(futures):
            run = by_key[fut.key]
            try:
                out = fut.result()
            except Exception as err:  # noqa: BLE001 -- a worker lost or killed: recorded
                out = Outcome(run.label, -3, f"lost on the cluster: {type(err).__name__}: {err}")
            fut.release()
            if out.data is not None:
                write_bytes(run.result, out.data)
                out.data = None
            outcome[run.label] = out
            failed += out.code != 0
            bar.set_postfix_str(f"{failed} failed, last {run.label}")
            bar.update()
    return outcome
