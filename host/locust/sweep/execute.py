"""Where a sweep's designs run: this process, every local core, or a Dask cluster.

Each scheduler maps the same pure function over the same designs and yields results as they
finish; only the order differs, never the numbers.

- ``local``: a process pool with one worker per core (``--jobs``); ``--jobs 1`` runs here.
- ``dask-local``: a real ``dask.distributed.LocalCluster`` (one single-threaded worker process
  per job), the same code path a remote cluster takes.
- ``tcp://HOST:PORT``: an existing Dask scheduler; its workers need locust installed.
"""

from __future__ import annotations

import multiprocessing
import os
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from contextlib import contextmanager
from typing import Any

from ..errors import SweepError
from ..orphans import die_with_parent


def default_jobs() -> int:
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:
        return max(1, os.cpu_count() or 1)


def check_scheduler(scheduler: str) -> str:
    if scheduler in ("local", "dask-local") or scheduler.startswith("tcp://"):
        return scheduler
    raise SweepError(f"--scheduler {scheduler!r}: not understood",
                     "use local (default), dask-local, or tcp://HOST:PORT of a Dask scheduler")


def _serial(fn: Callable, items: Sequence) -> Iterator[Any]:
    for item in items:
        yield fn(item)


def _pool(fn: Callable, items: Sequence, jobs: int) -> Iterator[Any]:
    ctx = multiprocessing.get_context("fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn")
    pool = ProcessPoolExecutor(max_workers=jobs, mp_context=ctx, initializer=die_with_parent,
                               initargs=(os.getpid(),))
    pending: set[Future] = set()
    queue = list(items)[::-1]
    try:
        while queue or pending:
            while queue and len(pending) < 2 * jobs:  # keep every worker busy, submit lazily
                pending.add(pool.submit(fn, queue.pop()))
            finished, pending = wait(pending, return_when=FIRST_COMPLETED)
            for fut in finished:
                yield fut.result()
    finally:
        for fut in pending:
            fut.cancel()
        pool.shutdown(wait=True, cancel_futures=True)


def _dask(fn: Callable, items: Sequence, client) -> Iterator[Any]:
    from dask.distributed import as_completed

    futures = client.map(fn, list(items), pure=False)
    try:
        for fut in as_completed(futures):
            yield fut.result()
    finally:
        client.cancel(futures)


@contextmanager
def dask_client(scheduler: str, jobs: int):
    """A Dask client on a fresh LocalCluster or on the scheduler at ``tcp://HOST:PORT``."""
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:  # pragma: no cover - dask is a dependency
        raise SweepError("dask.distributed is not installed", "pip install 'dask[distributed]'") from None
    if scheduler == "dask-local":
        cluster = LocalCluster(n_workers=jobs, threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=40)
        client = Client(cluster)
        try:
            yield client
        finally:
            client.close()
            cluster.close()
        return
    try:
        client = Client(scheduler, timeout="15s")
    except (OSError, TimeoutError) as exc:
        raise SweepError(f"cannot reach the Dask scheduler at {scheduler}: {exc}",
                         "start one with `dask scheduler` and workers with `dask worker "
                         f"{scheduler}` (locust installed on them), or use --scheduler local") from None
    try:
        yield client
    finally:
        client.close()


@contextmanager
def mapper(scheduler: str, jobs: int):
    """``with mapper(s, jobs) as run_map: for result in run_map(fn, items): ...``"""
    check_scheduler(scheduler)
    if scheduler == "local":
        yield (lambda fn, items: _serial(fn, items)) if jobs <= 1 else (lambda fn, items: _pool(fn, items, jobs))
        return
    with dask_client(scheduler, jobs) as client:
        yield lambda fn, items: _dask(fn, items, client)
