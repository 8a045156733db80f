"""Where a sweep's designs run: this process, every local core, or a Dask cluster.

Each scheduler maps the same pure function over the same designs and yields results as they
finish; only the order differs, never the numbers.

- ``local``: a process pool with one worker per core (``--jobs``); ``--jobs 1`` runs here.
- ``dask-local``: a real ``dask.distributed.LocalCluster`` (one single-threaded worker process
  per job), the same code path a remote cluster takes.
- ``tcp://HOST:PORT``: an existing Dask scheduler; its workers need locust installed.
"""

from __future__ import annotations

import asyncio
import multiprocessing
import os
import signal
import socket
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, ThreadPoolExecutor, wait
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
    """A ``--scheduler`` value checked.

    Parameters
    ----------
    scheduler : str
        ``local``, ``dask-local`` or ``tcp://HOST:PORT`` of a Dask scheduler.

    Returns
    -------
    str
        The same value.

    Raises
    ------
    locust.errors.SweepError
        Any other value.
    """
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


# how long a scheduler's address may take to accept, greet and say what it is before it is refused
PROBE_TIMEOUT_S = 4.0


def probe_dask_scheduler(scheduler: str, timeout_s: float = PROBE_TIMEOUT_S) -> None:
    """Refuse an address where no Dask scheduler answers within ``timeout_s``.

    Dask's own connection (``distributed.comm.connect``, which reads Dask's greeting) asks the
    peer who it is; the whole exchange runs under one deadline, because a peer that is not
    Dask (a silent server, or one whose first bytes read as a greeting of exabytes) would
    otherwise keep a ``Client`` waiting well past its ``timeout``.

    Parameters
    ----------
    scheduler : str
        ``tcp://HOST:PORT``.
    timeout_s : float
        The deadline [s] for connecting, the greeting and the answer together.

    Raises
    ------
    SweepError
        Not ``tcp://HOST:PORT``; nothing listening; no answer in time; or something other than
        a Dask scheduler answering (a worker, an HTTP or SSH server, random bytes).
    """
    where = scheduler.removeprefix("tcp://")
    host, _, port = where.rpartition(":")
    hint = ("give the address `dask scheduler` printed (tcp://HOST:PORT, workers started with `dask worker "
            f"{scheduler}` and locust installed on them), or use --scheduler local")
    if not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise SweepError(f"--scheduler {scheduler!r}: not tcp://HOST:PORT", hint)
    no_answer = SweepError(f"cannot reach the Dask scheduler at {scheduler}: no answer in {timeout_s:g} s", hint)
    try:   # nothing listening: said at once (Dask's connect would retry until its timeout)
        socket.create_connection((host.strip("[]"), int(port)), timeout=timeout_s).close()
    except TimeoutError:
        raise no_answer from None
    except OSError as exc:
        raise SweepError(f"cannot reach the Dask scheduler at {scheduler}: {exc.strerror or exc}", hint) from None
    with ThreadPoolExecutor(1) as thread:   # its own event loop, also under a running one (Jupyter)
        answer = thread.submit(asyncio.run, _identity(scheduler, timeout_s))
        try:
            identity = answer.result()
        except TimeoutError:
            raise no_answer from None
        except Exception:   # whatever a stranger's bytes make of Dask's reader (MemoryError, ValueError, ...)
            identity = None
    if not isinstance(identity, dict) or identity.get("type") != "Scheduler":
        what = f"a Dask {identity['type']}" if isinstance(identity, dict) and "type" in identity else \
            "something else (its first bytes are not a Dask greeting)"
        raise SweepError(f"cannot reach the Dask scheduler at {scheduler}: {what} answers there", hint)


async def _identity(address: str, timeout_s: float) -> object:
    """What the Dask server at ``address`` says it is (its ``identity``), within ``timeout_s``."""
    from distributed.comm import connect

    async def ask() -> object:
        comm = await connect(address, timeout=timeout_s)
        try:
            await comm.write({"op": "identity"})
            return await comm.read()
        finally:
            comm.abort()

    return await asyncio.wait_for(ask(), timeout_s)


@contextmanager
def mapper(scheduler: str, jobs: int):
    """Where designs run, as a map: ``with mapper(s, jobs) as run_map: for r in run_map(fn, items): ...``.

    Parameters
    ----------
    scheduler : str
        ``local`` (this process, or a pool of ``jobs`` processes), ``dask-local`` or a Dask
        scheduler's ``tcp://HOST:PORT``.
    jobs : int
        Workers to use.

    Yields
    ------
    callable
        ``run_map(fn, items)``, an iterator over the results ``fn(item)`` of the items.
    """
    check_scheduler(scheduler)
    if scheduler == "local":
        yield (lambda fn, items: _serial(fn, items)) if jobs <= 1 else (lambda fn, items: _pool(fn, items, jobs))
        return
    with dask_client(scheduler, jobs) as client:
        yield lambda fn, items: _dask(fn, items, client)
