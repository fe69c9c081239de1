"""Running jobs on an executor: in-process, a ``dask.distributed.Client`` or any
``concurrent.futures.Executor``, with the death of a worker turned into a retry.

A job's own failure comes back from :func:`~wavg.batch.jobs.run_job` as a result; what
reaches this layer as an exception is the infrastructure failing: a Dask worker killed
mid-task (``KilledWorker``, a closed connection) or a process pool whose process died
(``BrokenProcessPool``, which breaks the whole pool). Such jobs are submitted again, up to
``attempts`` times each; a broken ``ProcessPoolExecutor`` is replaced by a new one of the
same size (the caller's pool stays broken). Dask is imported only when a Client is given.
"""

from __future__ import annotations

import concurrent.futures as cf
import dataclasses
import uuid
from typing import Any, Callable, Sequence

from .jobs import Job, run_job

#: Default number of times a job is submitted before the death of its worker counts as
#: its failure.
ATTEMPTS = 4

Progress = Callable[[int, int, int], Any]
"""Called as ``progress(finished, total, failed)`` after each job."""


def is_dask_client(executor: Any) -> bool:
    """Whether ``executor`` is a ``dask.distributed.Client`` (without importing Dask)."""
    return type(executor).__module__.split(".")[0] == "distributed" and hasattr(executor, "scheduler")


def run_all(
    jobs: Sequence[Job],
    executor: Any = None,
    progress: Progress | None = None,
    attempts: int = ATTEMPTS,
) -> list[dict[str, Any]]:
    """Runs every job once; returns their results in job order, each with ``attempts``."""
    run = uuid.uuid4().hex
    jobs = [dataclasses.replace(j, run=run) for j in jobs]
    tracker = _Tracker(len(jobs), progress)
    if executor is None:
        results = []
        for job in jobs:
            r = run_job(job)
            r["attempts"] = 1
            tracker.finished(r)
            results.append(r)
        return results
    if is_dask_client(executor):
        return _run_dask(jobs, executor, tracker, attempts)
    if isinstance(executor, cf.Executor):
        return _run_executor(jobs, executor, tracker, attempts)
    raise TypeError(
        f"executor: expected None, a dask.distributed.Client or a concurrent.futures.Executor, got {type(executor).__name__}"
    )


class _Tracker:
    """Counts finished and failed jobs and reports them."""

    def __init__(self, total: int, progress: Progress | None):
        self.total, self.done, self.failed, self.progress = total, 0, 0, progress
        if progress is not None:
            progress(0, total, 0)

    def finished(self, result: dict[str, Any]) -> None:
        self.done += 1
        self.failed += result["status"] == "failed"
        if self.progress is not None:
            self.progress(self.done, self.total, self.failed)


def _lost(error: BaseException, tries: int, worker_died: bool = True) -> dict[str, Any]:
    """The result of a job whose worker died on each of its ``tries`` attempts (or, with
    ``worker_died=False``, that the executor could not run)."""
    why = f"{type(error).__name__}: {error}"
    return {
        "status": "failed",
        "seconds": None,
        "worker": None,
        "error": f"worker lost {tries} times; last: {why}" if worker_died else why,
        "figures": {},
        "attempts": tries,
    }


def _run_dask(jobs: Sequence[Job], client: Any, tracker: _Tracker, attempts: int) -> list[dict[str, Any]]:
    from distributed import KilledWorker, as_completed

    # What a lost worker or connection raises; anything else (the job cannot even be
    # unpickled on the worker, say) fails the job at once, with its message.
    lost = (KilledWorker, OSError, cf.CancelledError)

    run = uuid.uuid4().hex[:8]
    results: list[dict[str, Any] | None] = [None] * len(jobs)
    tries = [0] * len(jobs)

    def submit(i: int) -> Any:
        tries[i] += 1
        key = f"wavg-{jobs[i].kind}-{i}-{run}-{tries[i]}"
        return client.submit(run_job, jobs[i], key=key, pure=False)

    pending = {submit(i): i for i in range(len(jobs))}
    finished = as_completed(list(pending))
    for fut in finished:
        i = pending.pop(fut)
        try:
            r = fut.result()
        except Exception as e:
            if not isinstance(e, lost):
                r = _lost(e, tries[i], worker_died=False)
            elif tries[i] < attempts:
                again = submit(i)
                pending[again] = i
                finished.add(again)
                continue
            else:
                r = _lost(e, tries[i])
        fut.release()
        r["attempts"] = tries[i]
        results[i] = r
        tracker.finished(r)
    return [r for r in results if r is not None]


def _replacement(executor: cf.Executor) -> cf.Executor | None:
    """A new process pool like ``executor`` when that is a ``ProcessPoolExecutor``."""
    if not isinstance(executor, cf.ProcessPoolExecutor):
        return None
    return cf.ProcessPoolExecutor(
        max_workers=getattr(executor, "_max_workers", None),
        mp_context=getattr(executor, "_mp_context", None),
        initializer=getattr(executor, "_initializer", None),
        initargs=getattr(executor, "_initargs", ()),
    )


def _run_executor(jobs: Sequence[Job], executor: cf.Executor, tracker: _Tracker, attempts: int) -> list[dict[str, Any]]:
    results: list[dict[str, Any] | None] = [None] * len(jobs)
    tries = [0] * len(jobs)
    owned: list[cf.Executor] = []  # replacement pools made here, shut down at the end
    pool = executor
    try:
        pending: dict[cf.Future[dict[str, Any]], int] = {}
        for i in range(len(jobs)):
            tries[i] += 1
            pending[pool.submit(run_job, jobs[i])] = i
        while pending:
            done, _ = cf.wait(list(pending), return_when=cf.FIRST_COMPLETED)
            broken: list[tuple[int, BaseException]] = []
            for fut in done:
                i = pending.pop(fut)
                try:
                    r = fut.result()
                except cf.BrokenExecutor as e:  # a worker process died: the pool is gone
                    broken.append((i, e))
                    continue
                except Exception as e:  # the executor could not run the task
                    r = _lost(e, tries[i], worker_died=False)
                r["attempts"] = tries[i]
                results[i] = r
                tracker.finished(r)
            if not broken:
                continue
            # Every job still queued on the broken pool fails the same way: collect them all.
            for fut in list(pending):
                i = pending.pop(fut)
                try:
                    r = fut.result()
                    r["attempts"] = tries[i]
                    results[i] = r
                    tracker.finished(r)
                except Exception as e:
                    broken.append((i, e))
            new_pool = _replacement(pool)
            for i, e in sorted(broken, key=lambda b: b[0]):
                if new_pool is None or tries[i] >= attempts:
                    r = _lost(e, tries[i])
                    results[i] = r
                    tracker.finished(r)
                    continue
                tries[i] += 1
                pending[new_pool.submit(run_job, jobs[i])] = i
            if new_pool is not None:
                owned.append(new_pool)
                pool = new_pool
    finally:
        for p in owned:
            p.shutdown(wait=True, cancel_futures=True)
    return [r for r in results if r is not None]
