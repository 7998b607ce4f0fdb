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
import sys
import tempfile
import time
import uuid
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from pathlib import Path

from tqdm import tqdm

from pre.files import check_output, copy_file, new_file, write_bytes, write_text

from .cost import ONCE, RepeatPolicy, Sample, cost_path, timed_run, write_costs
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
    keep: bool = True
    """False: a repeat that only times the case (its result is dropped)."""


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
    samples: list[Sample] = field(default_factory=list)
    """Wall and CPU seconds of the run (of every run of the case, in :func:`run_all`'s
    answer)."""


def single_thread_env() -> dict[str, str]:
    """The environment with one BLAS thread per run (unless the caller set one).

    The engine runs one case per core; OpenBLAS threads on top of that only spin
    (measured: 1.5x the CPU time on ironing m3 N6 with two threads).
    """
    env = dict(os.environ)
    env.setdefault("OPENBLAS_NUM_THREADS", "1")
    return env


def run_task(task: Task) -> Outcome:
    """Solve one case in a fresh scratch folder (runs on a worker) and time it; keep
    its result (``task.keep``) or drop it (a repeat). Never raises: any failure becomes
    the outcome's code and message."""
    start = time.perf_counter()
    data, samples = None, []
    try:
        with tempfile.TemporaryDirectory(prefix="voiga-") as scratch:
            folder = Path(scratch)
            (folder / task.name).write_text(task.text)
            (folder / task.geometry_name).write_bytes(task.geometry)
            code, message, sample = timed_run([task.binary, task.name, "--quiet"], folder, single_thread_env(),
                                              task.timeout)
            samples.append(sample)
            result = folder / (Path(task.name).stem + ".h5")
            if not result.exists():
                if code == 0:
                    code, message = -2, f"voiga wrote no {result.name}"
            elif not task.keep:
                pass                          # the scratch folder goes with it
            elif task.dest is None:
                data = result.read_bytes()
            else:
                dest = Path(task.dest)
                dest.parent.mkdir(parents=True, exist_ok=True)
                with new_file(dest) as part:
                    shutil.move(result, part)     # keeps voiga's modification time
    except Exception as err:  # noqa: BLE001 -- one case's trouble must not stop the study
        code, message = -2, f"{type(err).__name__}: {err}"
    return Outcome(task.label, code, message, time.perf_counter() - start, data, samples)


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
            shared: bool = True, policy: RepeatPolicy = ONCE) -> dict[str, Outcome]:
    """Solve every run whose result is not up to date (all with ``force``) on the
    client's cluster, longest first (:func:`post.sweep.longest_first`, ``times``: wall
    seconds of a previous summary, label -> s), then repeat the short ones as
    ``policy`` says, in rounds after all first runs (round 2 of every short case, then
    round 3, ...): a case's runs are apart, with other cases run between them, rather
    than back to back, so that its range takes in more of how the machine's load
    changes (:func:`_rounds`). The times of
    every run of a case go beside its result (:func:`post.cost.write_costs`).
    Label -> outcome (``'up to date'`` for the skipped ones; ``samples``: every run's).
    A tqdm bar shows the runs done, the failures so far and the ETA."""
    outcome: dict[str, Outcome] = {}
    todo = []
    for run in runs:
        prepare(run)
        if not force and up_to_date(run, binary):
            outcome[run.label] = Outcome(run.label, 0, "up to date")
        else:
            check_output(run.result).unlink(missing_ok=True)     # a failed rerun leaves no stale result
            check_output(cost_path(run.result)).unlink(missing_ok=True)
            todo.append(run)
    outcome.update(_rounds(longest_first(todo, times), binary, client, timeout, shared, policy, progress))
    return outcome


def _rounds(todo: list[Run], binary: Path, client: object, timeout: float, shared: bool,
            policy: RepeatPolicy, progress: bool) -> dict[str, Outcome]:
    """Run every case of ``todo`` once, in this order, keeping its result; each one that
    converged and ``policy`` finds short is run again, as a repeat that only times it,
    with a priority below every first run and every repeat of an earlier round."""
    from distributed import as_completed

    width = len(todo) + 1
    rank = {run.label: k for k, run in enumerate(todo)}
    outcome: dict[str, Outcome] = {}
    tasks: dict[str, tuple[Run, Task]] = {}

    def submit(run: Run, task: Task, round_: int) -> object:
        key = f"voiga-{run.label}-{uuid.uuid4().hex[:8]}"
        tasks[key] = (run, task)
        # round 1: width - rank (1 .. width); round r > 1: below all of round r - 1
        return client.submit(run_task, task, key=key, pure=False,  # type: ignore[attr-defined]
                             priority=width - rank[run.label] - (round_ - 1) * 2 * width)

    pending = as_completed([submit(run, task_for(run, binary, timeout, shared), 1) for run in todo])
    failed = 0
    with tqdm(total=len(todo), desc="study", unit="run", disable=not progress, file=sys.stderr) as bar:
        for fut in pending:
            run, task = tasks.pop(fut.key)    # type: ignore[attr-defined]
            try:
                out = fut.result()            # type: ignore[attr-defined]
            except Exception as err:  # noqa: BLE001 -- a worker lost or killed: recorded
                out = Outcome(run.label, -3, f"lost on the cluster: {type(err).__name__}: {err}")
            fut.release()                     # type: ignore[attr-defined]
            if task.keep:
                if out.data is not None:
                    write_bytes(run.result, out.data)
                    out.data = None
                outcome[run.label] = out
                failed += out.code != 0
            elif out.code == 0:               # a failed repeat times nothing
                outcome[run.label].samples += out.samples
            first = outcome[run.label]
            again = first.code == 0 and (task.keep or out.code == 0) and policy.more(first.samples)
            if again:
                pending.add(submit(run, replace(task, keep=False, dest=None), len(first.samples) + 1))
                bar.total += 1
            elif first.samples and run.result.exists():
                write_costs(run.result, first.samples)
            bar.set_postfix_str(f"{failed} failed, last {run.label}")
            bar.update()
    return outcome
