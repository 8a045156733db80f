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
import signal
import socket
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from typing import Any

from ..errors import SweepError
from ..orphans import die_with_parent
from ..sim.rollout import available_cores


def default_jobs() -> int:
    """Every core this process may use."""
    return available_cores()


def plan_jobs(jobs: int | None, designs: int) -> tuple[int, str | None]:
    """Workers to start for ``designs`` designs: ``jobs`` (default: every core), never more than
    the designs nor the cores, and why, when fewer than asked."""
    cores = default_jobs()
    wanted = jobs or cores
    used = max(1, min(wanted, designs, cores))
    if jobs is None or used == jobs:
        return used, None
    return used, f"--jobs {jobs}: starting {used} worker{'s' * (used != 1)} ({designs} designs to run, {cores} cores)"


def check_scheduler(scheduler: str) -> str:
    if scheduler in ("local", "dask-local") or scheduler.startswith("tcp://"):
        return scheduler
    raise SweepError(f"--scheduler {scheduler!r}: not understood",
                     "use local (default), dask-local, or tcp://HOST:PORT of a Dask scheduler")


def _serial(fn: Callable, items: Sequence) -> Iterator[Any]:
    for item in items:
        yield fn(item)


def _worker_start(parent_pid: int) -> None:
    """In a pool worker: die with the leader, and die plainly on SIGTERM (the pool's own way to
    stop its workers): the leader's handler, inherited by fork, would unwind a worker into
    sending its SystemExit back through a pipe no one reads any more."""
    for sig in (signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, signal.SIG_DFL)
    die_with_parent(parent_pid)


def _pool(fn: Callable, items: Sequence, jobs: int) -> Iterator[Any]:
    ctx = multiprocessing.get_context("fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn")
    pool = ProcessPoolExecutor(max_workers=jobs, mp_context=ctx, initializer=_worker_start,
                               initargs=(os.getpid(),))
    pending: set[Future] = set()
    queue = list(items)[::-1]
    try:
        while queue or pending:
            while queue and len(pending) < 2 * jobs:  # keep every worker busy, submit lazily
                pending.add(pool.submit(fn, queue.pop()))
            finished, pending = wait(pending, return_when=FIRST_COMPLETED)
            for fut in finished:
                try:
                    result = fut.result()
                except BrokenProcessPool:
                    raise SweepError("a worker process died (killed, or out of memory) before its design finished",
                                     "every finished design is kept (a sweep's results.csv, an optimize study's "
                                     "journal): rerun the same command to resume (with fewer --jobs if memory "
                                     "ran out)") from None
                yield result
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
    probe_dask_scheduler(scheduler)
    try:
        client = Client(scheduler, timeout=f"{2 * PROBE_TIMEOUT_S:g}s")
    except (OSError, TimeoutError) as exc:
        raise SweepError(f"cannot reach the Dask scheduler at {scheduler}: {exc}",
                         "start one with `dask scheduler` and workers with `dask worker "
                         f"{scheduler}` (locust installed on them), or use --scheduler local") from None
    try:
        yield client
    finally:
        client.close()


# how long a scheduler's address may take to accept and greet before it is refused
PROBE_TIMEOUT_S = 4.0
# a Dask greeting: 8 bytes (little-endian) giving the length of what follows, then 8 bytes
# giving the number of frames and 8 per frame for their lengths; it is a few dozen bytes
_GREETING_MAX_BYTES = 1 << 16


def probe_dask_scheduler(scheduler: str, timeout_s: float = PROBE_TIMEOUT_S) -> None:
    """Refuse (:class:`SweepError`) an address where no Dask scheduler answers within
    ``timeout_s``: nothing listening, a silent server, or one whose greeting is not Dask's (read
    as Dask's, its first bytes could ask for exabytes, and the client would wait forever)."""
    where = scheduler.removeprefix("tcp://")
    host, _, port = where.rpartition(":")
    hint = ("give the address `dask scheduler` printed (tcp://HOST:PORT, workers started with `dask worker "
            f"{scheduler}` and locust installed on them), or use --scheduler local")
    if not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise SweepError(f"--scheduler {scheduler!r}: not tcp://HOST:PORT", hint)
    try:
        with socket.create_connection((host.strip("[]"), int(port)), timeout=timeout_s) as sock:
            sock.settimeout(timeout_s)
            head = _receive(sock, 16)
            size = int.from_bytes(head[:8], "little")
            frames = int.from_bytes(head[8:], "little")
            if not 16 <= size <= _GREETING_MAX_BYTES or not 1 <= frames <= 64:
                raise ValueError("not a Dask greeting")
            rest = _receive(sock, size - 8)
            lengths = [int.from_bytes(rest[8 * i:8 * i + 8], "little") for i in range(frames)]
            if 8 + 8 * frames + sum(lengths) != size:
                raise ValueError("not a Dask greeting")
    except TimeoutError:
        raise SweepError(f"cannot reach the Dask scheduler at {scheduler}: no answer in {timeout_s:g} s",
                         hint) from None
    except ValueError:
        raise SweepError(f"cannot reach the Dask scheduler at {scheduler}: something else answers there "
                         "(its first bytes are not a Dask greeting)", hint) from None
    except OSError as exc:
        raise SweepError(f"cannot reach the Dask scheduler at {scheduler}: {exc.strerror or exc}", hint) from None


def _receive(sock: socket.socket, n: int) -> bytes:
    data = b""
    while len(data) < n:
        chunk = sock.recv(n - len(data))
        if not chunk:
            raise ValueError("closed before greeting")
        data += chunk
    return data


@contextmanager
def mapper(scheduler: str, jobs: int):
    """``with mapper(s, jobs) as run_map: for result in run_map(fn, items): ...``"""
    check_scheduler(scheduler)
    if scheduler == "local":
        yield (lambda fn, items: _serial(fn, items)) if jobs <= 1 else (lambda fn, items: _pool(fn, items, jobs))
        return
    with dask_client(scheduler, jobs) as client:
        yield lambda fn, items: _dask(fn, items, client)
