"""Many robots run in batched rollouts, each reduced to the figures a study reads.

:func:`run_figures` builds each robot, groups them by hop schedule and solver, runs each group
in batched ``mujoco.rollout`` calls on every core (:func:`.rollout.simulate_batch`) and
audits and summarises each run: its outcome, its first hop's nose rise, its distance and its
highest nose point. The draws of ``--samples``, the ends of ``--sensitivity`` and the probes
of ``--explain`` all go through it, so they can share one batch.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ..errors import GeometryError
from ..params import Robot, problems
from .audit import audit
from .hops import summarise
from .model import BuiltModel, build
from .outcome import classify
from .rollout import Trajectory, available_cores, simulate_batch
from .schedule import control_plan

BATCH_PER_CORE = 4      # runs per core in one rollout call when progress is shown


@dataclass(frozen=True)
class RunFigures:
    """What one run of a batch gives: its outcome, its first hop's nose rise and its distance.

    Attributes
    ----------
    outcome : str
        One of :data:`~.outcome.OUTCOMES`.
    nose_rise_m : float
        The first hop's nose rise above standing [m] (``Hop.nose_apex_m``).
    distance_m : float
        The run's distance, start of the schedule to its end [m].
    max_nose_height_m : float
        The highest nose point of the run [m] (nan where not taken).
    """

    outcome: str
    nose_rise_m: float
    distance_m: float
    max_nose_height_m: float = float("nan")


def figures_of(traj: Trajectory) -> RunFigures | None:
    """A rollout's figures, or None where it fails its audit.

    Parameters
    ----------
    traj : Trajectory

    Returns
    -------
    RunFigures or None
    """
    if not audit(traj).valid:
        return None
    summary = summarise(traj)
    hops = summary.hops
    return RunFigures(outcome=classify(hops), nose_rise_m=hops[0].nose_apex_m if hops else 0.0,
                      distance_m=summary.distance_m, max_nose_height_m=summary.max_nose_height_m)


def run_figures(robots: list[Robot], cycles: int | None,
                progress: Callable[[int], None] | None = None) -> list[RunFigures | None]:
    """Each robot's outcome and figures, simulated in batched rollouts (one per hop schedule and
    solver among them, in chunks of :data:`BATCH_PER_CORE` a core when ``progress``
    is given); None for one that cannot be built or run, or fails its audit.

    Parameters
    ----------
    robots : list of Robot
        The robots, all of one structure.
    cycles : int or None
        Hop cycles (None: each robot's schedule's).
    progress : callable, optional
        ``progress(k)`` as each chunk of ``k`` robots is done.

    Returns
    -------
    list of RunFigures or None
        One per robot, in order.
    """
    out: list[RunFigures | None] = [None] * len(robots)
    builts: dict[int, BuiltModel] = {}
    groups: dict[tuple, list[int]] = {}
    for i, r in enumerate(robots):
        try:
            if not problems(r, cycles):
                builts[i] = build(r)
                groups.setdefault((r.schedule, r.solver), []).append(i)
        except GeometryError:
            pass
    if progress and len(builts) < len(robots):
        progress(len(robots) - len(builts))
    chunk = max(1, BATCH_PER_CORE * available_cores()) if progress else len(robots) or 1
    for (schedule, solver), members in groups.items():
        plan = control_plan(schedule, solver, cycles)
        for start in range(0, len(members), chunk):
            part = members[start:start + chunk]
            for i, traj in zip(part, simulate_batch([builts[i] for i in part], plan)):
                out[i] = figures_of(traj)
            if progress:
                progress(len(part))
    return out


__all__ = ["BATCH_PER_CORE", "RunFigures", "figures_of", "run_figures"]
