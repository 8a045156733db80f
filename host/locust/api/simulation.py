"""``locust.simulate``: one audited simulation, kept with its rollout for traces, videos and plots."""

from __future__ import annotations

import dataclasses

from ..params import Robot
from ..sim import run as _run
from ..sim.result import SimResult


def simulate(robot: Robot, cycles: int | None = None, samples: int = 0, seed: int = 0,
             keep_states: bool = True, progress=None, sensitivity: bool | None = None) -> SimResult:
    """Settle the robot on the floor, run its hop schedule, audit the run and measure the hops.

    Parameters
    ----------
    robot : Robot
        From :func:`locust.robot`.
    cycles : int, optional
        Hop cycles (push + wait) to run; default the robot's ``schedule.cycles``.
    samples : int, default 0
        With N >= 2, also simulate N draws of the values that carry an uncertainty in the
        robot (one batched rollout): ``result.spread``, with ``outcomes`` (each outcome's
        share of the valid draws and the mean and sd of its own distance and highest nose:
        near the threshold the draws split, and one sd across both would hide it) and the
        draws themselves.
    seed : int, default 0
        Random seed of the draws.
    keep_states : bool, default True
        Keep every step's state for ``trace()`` and ``video()`` (False: the figures only, for
        runs of many cycles).
    progress : callable, optional
        ``progress(k)`` as each batch of ``k`` draws is done (``samples``).
    sensitivity : bool, optional
        Which measured values decide the outcome: each uncertain value alone at -/+ 2 sd
        (``result.sensitivity``, :func:`locust.sim.sensitivity.outcome_sensitivity`). True:
        always; False: never; None (default): when the draws of ``samples`` split between
        outcomes.

    Returns
    -------
    SimResult
        ``.valid`` (a run that breaks its own audit is never a result: ``.reasons`` says why),
        ``.outcome`` (``goes_over``, ``rears_and_returns`` or ``stays_low``), ``.distance_m``,
        ``.max_nose_height_m``, ``.hops``, ``.nose_load_kg``, ``.trace()``, ``.video(path)``,
        ``.plot()``. The same call gives the same numbers every time.

    Raises
    ------
    locust.errors.GeometryError
        The linkage cannot be assembled.
    locust.errors.ParamsError
        A value out of range for simulating.

    Examples
    --------
    >>> import locust
    >>> r = locust.simulate(locust.robot("small"), cycles=2)
    >>> r.valid, len(r.hops)
    (True, 2)
    >>> r.trace().columns[:3].tolist()
    ['t_s', 'nose_x_m', 'nose_z_m']
    """
    if samples:
        from ..sim.samples import check_draws

        check_draws(robot, samples, cycles)   # before the robot's own run
    result = dataclasses.replace(_run.run(robot, cycles=cycles, keep_states=keep_states), params=robot)
    if result.valid:
        from ..sim.statics import standing_load

        load = standing_load(robot)
        result.nose_load_kg, result.total_mass_kg = load.nose_load_kg, load.total_mass_kg
    if samples and result.valid:
        from ..sim.samples import sample

        result.spread = sample(robot, samples, cycles=cycles, seed=seed, progress=progress)
    mixed = result.spread is not None and max(o.share for o in result.spread.outcomes.values()) < 1.0
    if result.valid and (sensitivity or (sensitivity is None and mixed)):
        from ..sim.sensitivity import outcome_sensitivity

        result.sensitivity = outcome_sensitivity(robot, cycles=cycles)
    return result


__all__ = ["SimResult", "simulate"]
