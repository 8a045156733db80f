"""``run_sweep``: a grid of designs, checked, simulated, audited, stored as they finish.

    from locust.sweep.run import run_sweep
    summary = run_sweep(preset("seed"), [parse_axis("scale=0:0.05:30", base)], cycles=3,
                        out=Path("sweep-out"))

The folder gets ``results.csv`` (one row per design), ``sweep.json`` (the request, the best
valid design, timing) and the landscape plots. Rerunning into the same folder resumes.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import SweepError
from ..io.sweep_store import SweepStore
from ..params import Robot
from ..sim.outcome import GOES_OVER
from .design import Axis, evaluate
from .execute import default_jobs, mapper, plan_jobs, probe_dask_scheduler


@dataclass(frozen=True)
class Task:
    """One design to run: everything the worker needs, picklable.

    Attributes
    ----------
    base : Robot
        The robot the sweep starts from.
    design : int
        The design's number in the grid.
    values : tuple of (str, float)
        The design's values, in each parameter's unit (``scale``: m).
    cycles : int
        Hop cycles simulated.
    samples : int
        Draws of the uncertain values (0: the nominal run alone).
    """

    base: Robot
    design: int
    values: tuple[tuple[str, float], ...]
    cycles: int
    samples: int = 0


def run_task(task: Task) -> dict[str, Any]:
    """Evaluate one design into its row of results.csv.

    Parameters
    ----------
    task : Task
        The design.

    Returns
    -------
    dict
        ``design``, the varied values, and the fields of :func:`.design.evaluate`.
    """
    row: dict[str, Any] = {"design": task.design, **dict(task.values)}
    row.update(evaluate(task.base, dict(task.values), task.cycles, task.samples))
    return row


# the most designs one sweep may hold: its rows are kept in memory, and at a few tenths of a
# second a design it is already hours on a laptop
MAX_DESIGNS = 100_000


def grid_size(axes: list[Axis]) -> int:
    """How many designs the grid holds.

    Parameters
    ----------
    axes : list of Axis
        The sweep's axes.

    Returns
    -------
    int
        The product of the axes' sizes.

    Raises
    ------
    SweepError
        Over ``MAX_DESIGNS``.
    """
    size = math.prod(a.n for a in axes)
    if size > MAX_DESIGNS:
        raise SweepError(f"the grid holds {size:,} designs ({' x '.join(str(a.n) for a in axes)}), "
                         f"over the limit of {MAX_DESIGNS:,}",
                         "use fewer values per --vary (N), or `locust optimize` to search a large space")
    return size


def grid(axes: list[Axis]) -> list[dict[str, float]]:
    """Every combination, the last axis varying fastest; design ``i`` is the i-th.

    Parameters
    ----------
    axes : list of Axis
        The sweep's axes.

    Returns
    -------
    list of dict
        Parameter name to value, one per design.

    Raises
    ------
    SweepError
        Over ``MAX_DESIGNS`` designs.
    """
    grid_size(axes)
    names = [a.name for a in axes]
    return [dict(zip(names, combo)) for combo in itertools.product(*(a.values() for a in axes))]


def best_row(rows: list[dict[str, Any]]) -> dict[str, Any] | None:
    """The valid design that went farthest (lowest design number on a tie); never an invalid one,
    nor one that goes over onto its back.

    Parameters
    ----------
    rows : list of dict
        Rows of results.csv.

    Returns
    -------
    dict or None
        The best row, None when no row qualifies.
    """
    valid = [r for r in rows if r["valid"] and r["outcome"] != GOES_OVER and math.isfinite(r["distance_m"])]
    return max(valid, key=lambda r: (r["distance_m"], -r["design"])) if valid else None


def request(robot: Robot, axes: list[Axis], cycles: int, samples: int = 0) -> dict[str, Any]:
    """What the sweep was asked, as sweep.json stores it.

    Parameters
    ----------
    robot : Robot
        The robot the sweep starts from.
    axes : list of Axis
        The sweep's axes.
    cycles : int
        Hop cycles per design.
    samples : int, default 0
        Draws per design (stored only when not 0).

    Returns
    -------
    dict
        ``robot``, ``parameters``, ``vary``, ``cycles`` and, when given, ``samples``.
    """
    out = {"base": robot.name, "parameters": robot.flat(), "vary": [a.to_dict() for a in axes], "cycles": cycles}
    if samples:    # only when asked: the folders of plain sweeps keep their request as it was
        out["samples"] = samples
    return out


@dataclass
class SweepSummary:
    """What one call of :func:`run_sweep` did.

    Attributes
    ----------
    folder : Path
        The sweep's folder.
    rows : list of dict
        Every finished row, by design number (resumed ones included).
    best : dict or None
        The best row (:func:`best_row`).
    computed : int
        Designs computed by this call.
    resumed : int
        Designs already in the folder.
    wall_s : float
        Wall time of this call's designs [s].
    finished : bool
        Every design is done.
    plots : list of Path
        The landscape plots written.
    """

    folder: Path
    rows: list[dict[str, Any]]
    best: dict[str, Any] | None
    computed: int
    resumed: int
    wall_s: float
    finished: bool
    plots: list[Path]


def run_sweep(robot: Robot, axes: list[Axis], cycles: int, out: Path, scheduler: str = "local",
              jobs: int | None = None, progress: Callable[[int], None] | None = None,
              plots: bool = True, samples: int = 0, say: Callable[[str], None] | None = None) -> SweepSummary:
    """Run (or resume) the sweep into ``out``.

    Workers: ``jobs`` (default every core), never more than the designs left nor the cores
    (``say`` is told when fewer than asked start). An interrupt (Ctrl-C) leaves every finished
    row on disk and re-raises; a worker that dies is a :class:`SweepError`, the rows kept.

    Parameters
    ----------
    robot : Robot
        The robot the sweep starts from.
    axes : list of Axis
        The sweep's axes.
    cycles : int
        Hop cycles per design.
    out : Path
        The sweep's folder (new, or one to resume).
    scheduler : str, default "local"
        ``local`` (processes on this machine), ``dask-local`` (a Dask cluster started here)
        or a Dask scheduler's ``tcp://HOST:PORT``.
    jobs : int, optional
        Worker processes; every core by default.
    progress : callable, optional
        ``progress(n)`` as each design finishes.
    plots : bool, default True
        Draw the landscape plots.
    samples : int, default 0
        Draws of the uncertain values per design.
    say : callable, optional
        ``say(line)`` for notes to the user.

    Returns
    -------
    SweepSummary
        The rows, the best design and the timing.

    Raises
    ------
    SweepError
        Too many designs, an unknown or unreachable scheduler, a folder holding another sweep,
        or a worker that died.
    """
    designs = grid(axes)
    names = [a.name for a in axes]
    meta = {"request": request(robot, axes, cycles, samples), "designs": len(designs), "scheduler": scheduler,
            "jobs": jobs or default_jobs()}
    if scheduler.startswith("tcp://"):
        probe_dask_scheduler(scheduler)   # before the folder is touched
    store = SweepStore.open(out, meta, names)
    resumed = len(store.done)
    todo = [Task(robot, i, tuple(v.items()), cycles, samples) for i, v in enumerate(designs) if i not in store.done]
    if not scheduler.startswith("tcp://"):   # a cluster's workers are its own
        jobs, why = plan_jobs(jobs, len(todo))
        if why and say and todo:
            say(why)
    jobs = jobs or default_jobs()
    t0 = time.perf_counter()
    finished = False
    try:
        with mapper(scheduler, jobs) as run_map:
            for row in run_map(run_task, todo):
                store.append(row)
                if progress:
                    progress(1)
        finished = True
    finally:
        wall = time.perf_counter() - t0
        rows = [store.done[i] for i in sorted(store.done)]
        best = best_row(rows)
        store.close(finished, done=len(rows), finished=finished, best=best, last_run={
            "computed": len(rows) - resumed, "wall_s": wall, "scheduler": scheduler, "jobs": jobs})
    made: list[Path] = []
    if plots and rows:
        from .plot import plot_landscape

        made = plot_landscape(rows, axes, best, out, robot)
    return SweepSummary(Path(out), rows, best, len(rows) - resumed, resumed, wall, finished, made)
