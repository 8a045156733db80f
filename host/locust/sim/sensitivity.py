"""Which measured values decide a prediction's regime: a one-at-a-time sensitivity.

Each value of the robot that carries an uncertainty (one standard deviation, as
:func:`.samples.uncertain_values` finds them) is moved alone to its value less and plus
``k_sd`` standard deviations (2 by default: the ends of its 95 % interval), the others held,
and the run's outcome (:mod:`.outcome`) is taken at each end. A value whose interval holds
another outcome than the nominal robot's decides the regime: measuring it better is what
settles the prediction. All the runs go in one batched rollout.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass

from ..errors import GeometryError
from ..params import Provenance, Robot, problems
from .audit import audit
from .hops import summarise
from .model import BuiltModel, build
from .outcome import classify
from .rollout import available_cores, simulate_batch
from .samples import BATCH_PER_CORE, MIN_FRACTION, uncertain_values
from .schedule import control_plan

K_SD = 2.0


@dataclass(frozen=True)
class KeyEffect:
    """One value at either end of its interval, and the outcome there (None: not a valid run)."""

    key: str
    sd: float
    low_value: float
    low_outcome: str | None
    high_value: float
    high_outcome: str | None


@dataclass(frozen=True)
class Sensitivity:
    """The one-at-a-time sensitivity of a robot's outcome to its uncertain values.

    Attributes
    ----------
    nominal : str or None
        The robot's own outcome (None: not a valid run).
    k_sd : float
        The ends are each value -/+ ``k_sd`` standard deviations.
    effects : list of KeyEffect
        Every uncertain value, in the robot file's order.
    """

    nominal: str | None          # the robot's own outcome
    k_sd: float                  # the ends are the value -/+ k_sd standard deviations
    effects: list[KeyEffect]     # every uncertain value, in the robot file's order

    @property
    def deciding(self) -> list[KeyEffect]:
        """The values whose interval reaches another outcome than the nominal one."""
        return [e for e in self.effects if e.low_outcome != self.nominal or e.high_outcome != self.nominal]

    def to_json(self) -> dict:
        """The sensitivity as a JSON object, with the deciding values' keys.

        Returns
        -------
        dict
            The fields, and ``deciding``: the keys whose interval reaches another outcome.
        """
        out = dataclasses.asdict(self)
        out["deciding"] = [e.key for e in self.deciding]
        return out


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
    """

    outcome: str
    nose_rise_m: float
    distance_m: float


def run_figures(robots: list[Robot], cycles: int | None,
                progress: Callable[[int], None] | None = None) -> list[RunFigures | None]:
    """Each robot's outcome and figures, simulated in batched rollouts (one per hop schedule and
    solver among them, in chunks of :data:`~.samples.BATCH_PER_CORE` a core when ``progress``
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
                if audit(traj).valid:
                    summary = summarise(traj)
                    hops = summary.hops
                    out[i] = RunFigures(outcome=classify(hops), nose_rise_m=hops[0].nose_apex_m if hops else 0.0,
                                        distance_m=summary.distance_m)
            if progress:
                progress(len(part))
    return out


def _outcomes(robots: list[Robot], cycles: int | None) -> list[str | None]:
    """Each robot's outcome (:func:`run_figures`); None for one that cannot be run."""
    return [f.outcome if f is not None else None for f in run_figures(robots, cycles)]


def outcome_sensitivity(robot: Robot, cycles: int | None = None, k_sd: float = K_SD) -> Sensitivity:
    """The outcome of ``robot`` and of each uncertain value moved alone to -/+ ``k_sd`` sd.

    Parameters
    ----------
    robot : Robot
        With uncertainties on the values to test (from its robot file or preset).
    cycles : int, optional
        Hop cycles; default the robot's ``schedule.cycles``.
    k_sd : float, default 2
        How far each value moves, in its standard deviations (2: its 95 % interval).

    Returns
    -------
    Sensitivity
        ``nominal`` (the robot's own outcome), ``effects`` (one :class:`KeyEffect` per
        uncertain value) and ``deciding`` (those whose interval holds another outcome).
        A positive value is kept above a tenth of itself, as the draws of ``--samples`` are.
    """
    sds = uncertain_values(robot)
    ends = []
    for key, sd in sds.items():
        centre = robot.get(key)
        for sign in (-1.0, 1.0):
            value = centre + sign * k_sd * sd
            ends.append(max(value, MIN_FRACTION * centre) if centre > 0 else value)
    prov = Provenance(source="sensitivity", note=f"one value at -/+{k_sd:g} sd")
    robots = [robot] + [robot.with_values({key: ends[2 * i + j]}, prov)
                        for i, key in enumerate(sds) for j in range(2)]
    kinds = _outcomes(robots, cycles)
    effects = [KeyEffect(key=key, sd=sd, low_value=ends[2 * i], low_outcome=kinds[1 + 2 * i],
                         high_value=ends[2 * i + 1], high_outcome=kinds[2 + 2 * i])
               for i, (key, sd) in enumerate(sds.items())]
    return Sensitivity(nominal=kinds[0], k_sd=k_sd, effects=effects)


__all__ = ["KeyEffect", "RunFigures", "Sensitivity", "outcome_sensitivity", "run_figures", "K_SD"]
