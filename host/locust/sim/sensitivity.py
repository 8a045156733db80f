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

from ..params import Provenance, Robot
from .figures import RunFigures, run_figures
from .samples import MIN_FRACTION, uncertain_values

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


def end_robots(robot: Robot, k_sd: float = K_SD) -> list[Robot]:
    """``robot`` with each uncertain value alone at -``k_sd`` sd and at +``k_sd`` sd, in the
    robot file's order (two robots a value; a positive value kept above a tenth of itself, as
    the draws of ``--samples`` are).

    Parameters
    ----------
    robot : Robot
    k_sd : float

    Returns
    -------
    list of Robot
    """
    prov = Provenance(source="sensitivity", note=f"one value at -/+{k_sd:g} sd")
    out = []
    for key, sd in uncertain_values(robot).items():
        centre = robot.get(key)
        for sign in (-1.0, 1.0):
            value = centre + sign * k_sd * sd
            out.append(robot.with_values({key: max(value, MIN_FRACTION * centre) if centre > 0 else value}, prov))
    return out


def sensitivity_of(robot: Robot, nominal: str | None, ends: list[RunFigures | None],
                   k_sd: float = K_SD) -> Sensitivity:
    """The sensitivity from the runs of :func:`end_robots` (their figures, in order).

    Parameters
    ----------
    robot : Robot
    nominal : str or None
        ``robot``'s own outcome.
    ends : list of RunFigures or None
        The figures of ``end_robots(robot, k_sd)``.
    k_sd : float

    Returns
    -------
    Sensitivity
    """
    sds = uncertain_values(robot)
    robots = end_robots(robot, k_sd)
    kinds = [f.outcome if f is not None else None for f in ends]
    effects = [KeyEffect(key=key, sd=sd, low_value=robots[2 * i].get(key), low_outcome=kinds[2 * i],
                         high_value=robots[2 * i + 1].get(key), high_outcome=kinds[2 * i + 1])
               for i, (key, sd) in enumerate(sds.items())]
    return Sensitivity(nominal=nominal, k_sd=k_sd, effects=effects)


def outcome_sensitivity(robot: Robot, cycles: int | None = None, k_sd: float = K_SD,
                        progress: Callable[[int], None] | None = None) -> Sensitivity:
    """The outcome of ``robot`` and of each uncertain value moved alone to -/+ ``k_sd`` sd.

    Parameters
    ----------
    robot : Robot
        With uncertainties on the values to test (from its robot file or preset).
    cycles : int, optional
        Hop cycles; default the robot's ``schedule.cycles``.
    k_sd : float, default 2
        How far each value moves, in its standard deviations (2: its 95 % interval).
    progress : callable, optional
        ``progress(k)`` as each batch of ``k`` runs is done (:func:`.figures.run_figures`).

    Returns
    -------
    Sensitivity
        ``nominal`` (the robot's own outcome), ``effects`` (one :class:`KeyEffect` per
        uncertain value) and ``deciding`` (those whose interval holds another outcome).
        A positive value is kept above a tenth of itself, as the draws of ``--samples`` are.
    """
    figures = run_figures([robot] + end_robots(robot, k_sd), cycles, progress)
    return sensitivity_of(robot, figures[0].outcome if figures[0] is not None else None, figures[1:], k_sd)


__all__ = ["KeyEffect", "RunFigures", "Sensitivity", "end_robots", "outcome_sensitivity", "run_figures",
           "sensitivity_of", "K_SD"]
